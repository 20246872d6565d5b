//! Taubin smoothing of the kept points (Honma et al. §2.5, Eq. 3; Taubin 1995).
//!
//! One step moves every interior point towards the mean of its two neighbours (w = 0.5 on
//! each, the reciprocal of the neighbour count): p ← p + a·(½(p₋ + p₊) − p), with a = λ on
//! even steps and a = μ on odd steps (λ = 0.6307, μ = −0.6732, 20 steps: ten λ/μ pairs).
//! The two end points stay fixed (SPEC §2). Where consecutive points are farther apart than
//! `smooth_gap_m`, the line is smoothed as separate pieces, each with its ends fixed (see
//! [`super::KernelParams::smooth_gap_m`]).
//!
//! Layout for speed: each coordinate is smoothed separately, ping-ponging between the
//! line's own array and one scratch array (the kernel's ρ buffer, unused at that point), so
//! each step is a branch-free three-point stencil over contiguous `f32` that the compiler
//! vectorises. An even number of steps ends in the line's array; an odd one is copied back.

/// One smoothing step from `src` into `dst` (same length ≥ 2), ends copied.
#[inline]
fn step(src: &[f32], dst: &mut [f32], a: f32) {
    let n = src.len();
    let dst = &mut dst[..n];
    dst[0] = src[0];
    dst[n - 1] = src[n - 1];
    let inner = &mut dst[1..n - 1];
    for (((d, &l), &c), &r) in inner
        .iter_mut()
        .zip(&src[..n - 2])
        .zip(&src[1..n - 1])
        .zip(&src[2..])
    {
        *d = c + a * (0.5 * (l + r) - c);
    }
}

/// Smooths one coordinate of one piece in place with `steps` steps (`scratch` as long).
fn smooth_piece(v: &mut [f32], scratch: &mut [f32], steps: u32, lambda: f32, mu: f32) {
    let n = v.len();
    if n < 3 || steps == 0 {
        return;
    }
    let scratch = &mut scratch[..n];
    let mut k = 0;
    while k + 1 < steps {
        step(v, scratch, lambda);
        step(scratch, v, mu);
        k += 2;
    }
    if k < steps {
        // Odd count: the last step is an even-numbered one (λ).
        step(v, scratch, lambda);
        v.copy_from_slice(scratch);
    }
}

/// Taubin-smooths the line `x`, `z` in place, piece by piece (split where consecutive
/// points are more than `gap_m` apart; `gap_m` ≤ 0 never splits). `scratch` must be at
/// least as long as the line. Returns the number of pieces.
pub(crate) fn taubin_smooth(
    x: &mut [f32],
    z: &mut [f32],
    scratch: &mut [f32],
    gap_m: f32,
    steps: u32,
    lambda: f32,
    mu: f32,
) -> u32 {
    let n = x.len();
    let z = &mut z[..n];
    let gap2 = gap_m * gap_m;
    let split = gap_m > 0.0;
    let mut pieces = 0;
    let mut start = 0;
    while start < n {
        let mut end = start + 1;
        if split {
            while end < n {
                let dx = x[end] - x[end - 1];
                let dz = z[end] - z[end - 1];
                if dx * dx + dz * dz > gap2 {
                    break;
                }
                end += 1;
            }
        } else {
            end = n;
        }
        smooth_piece(&mut x[start..end], scratch, steps, lambda, mu);
        smooth_piece(&mut z[start..end], scratch, steps, lambda, mu);
        pieces += 1;
        start = end;
    }
    pieces
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Plain f64 reference: Eq. 3 with a copy per step, ends fixed.
    fn reference(v: &[f64], steps: u32, lambda: f64, mu: f64) -> [f64; 64] {
        let n = v.len();
        let mut p = [0.0f64; 64];
        p[..n].copy_from_slice(v);
        for k in 0..steps {
            let a = if k % 2 == 0 { lambda } else { mu };
            let old = p;
            for i in 1..n - 1 {
                p[i] = old[i] + a * (0.5 * (old[i - 1] - old[i]) + 0.5 * (old[i + 1] - old[i]));
            }
        }
        p
    }

    fn noisy(n: usize, seed: u64) -> [f64; 64] {
        // A ramp with a step and deterministic pseudo-noise (LCG), in metres.
        let mut s = seed;
        let mut v = [0.0f64; 64];
        for (i, p) in v.iter_mut().enumerate().take(n) {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let u = ((s >> 40) as f64) / ((1u64 << 24) as f64) - 0.5;
            *p = 3.0 + 0.01 * i as f64 + if i > n / 2 { 0.15 } else { 0.0 } + 0.01 * u;
        }
        v
    }

    #[test]
    fn matches_plain_f64_reference() {
        for (n, steps) in [(64usize, 20u32), (17, 20), (3, 20), (40, 7), (40, 0)] {
            let v = noisy(n, n as u64 + u64::from(steps));
            let want = reference(&v[..n], steps, 0.6307, -0.6732);
            let mut x = [0.0f32; 64];
            let mut z = [0.0f32; 64];
            for i in 0..n {
                x[i] = v[i] as f32;
                z[i] = -(v[i] as f32);
            }
            let mut scratch = [0.0f32; 64];
            let pieces = taubin_smooth(
                &mut x[..n],
                &mut z[..n],
                &mut scratch,
                0.0,
                steps,
                0.6307,
                -0.6732,
            );
            assert_eq!(pieces, 1);
            for i in 0..n {
                // f32 rounding of 3 m values is 2.4e-7; 20 steps stay within 2e-6.
                assert!((f64::from(x[i]) - want[i]).abs() < 2e-6, "n {n} i {i}");
                assert!((f64::from(z[i]) + want[i]).abs() < 2e-6, "n {n} i {i}");
            }
            // Ends fixed.
            assert_eq!(f64::from(x[0]), f64::from(v[0] as f32));
            assert_eq!(f64::from(x[n - 1]), f64::from(v[n - 1] as f32));
        }
    }

    #[test]
    fn one_step_by_hand() {
        // [0, 1, 0] with λ: middle → 1 + 0.6307·(0 − 1) = 0.3693.
        let mut x = [0.0f32, 1.0, 0.0];
        let mut z = [0.0f32; 3];
        let mut s = [0.0f32; 3];
        taubin_smooth(&mut x, &mut z, &mut s, 0.0, 1, 0.6307, -0.6732);
        assert!((x[1] - 0.3693).abs() < 1e-6);
        // Then μ: 0.3693 + (−0.6732)(0 − 0.3693) = 0.3693·1.6732 = 0.61791276.
        taubin_smooth(&mut x, &mut z, &mut s, 0.0, 2, 0.6307, -0.6732);
        // Two more steps from 0.3693: λ → 0.3693·0.3693 = 0.13638249, μ → ·1.6732.
        assert!((x[1] - 0.136_382_49 * 1.6732).abs() < 1e-6, "{}", x[1]);
    }

    #[test]
    fn straight_line_is_unchanged_and_gaps_split() {
        let mut x: [f32; 10] = core::array::from_fn(|i| i as f32 * 0.01);
        let mut z = [-2.0f32; 10];
        let mut s = [0.0f32; 10];
        let before = x;
        taubin_smooth(&mut x, &mut z, &mut s, 0.3, 20, 0.6307, -0.6732);
        for i in 0..10 {
            assert!((x[i] - before[i]).abs() < 1e-6);
            assert_eq!(z[i], -2.0);
        }
        // A 1 m jump after point 4: two pieces; point 4 and 5 are ends, stay fixed.
        let mut x: [f32; 10] = core::array::from_fn(|i| if i < 5 { 0.0 } else { 1.0 });
        let mut z: [f32; 10] = core::array::from_fn(|i| if i % 2 == 0 { 0.0 } else { 0.01 });
        let (x0, z0) = (x, z);
        assert_eq!(
            taubin_smooth(&mut x, &mut z, &mut s, 0.3, 20, 0.6307, -0.6732),
            2
        );
        assert_eq!(x, x0, "no point moves across the gap");
        for i in [0, 4, 5, 9] {
            assert_eq!(z[i], z0[i], "piece end {i} fixed");
        }
        assert!((z[2] - z0[2]).abs() > 1e-4, "interior smoothed");
        // Without the split the gap drags its neighbours.
        let mut x2 = x0;
        let mut z2 = z0;
        assert_eq!(
            taubin_smooth(&mut x2, &mut z2, &mut s, 0.0, 20, 0.6307, -0.6732),
            1
        );
        assert!((x2[4] - x0[4]).abs() > 1e-3);
    }
}
