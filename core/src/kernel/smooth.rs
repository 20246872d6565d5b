//! Taubin smoothing of the kept points (Honma et al. §2.5, Eq. 3; Taubin 1995).
//!
//! One step moves every interior point towards the mean of its two neighbours (w = 0.5 on
//! each, the reciprocal of the neighbour count): p ← p + a·(½(p₋ + p₊) − p), with a = λ on
//! even steps and a = μ on odd steps (λ = 0.6307, μ = −0.6732, 20 steps: ten λ/μ pairs).
//! The two end points stay fixed (SPEC §2). Where consecutive points are farther apart than
//! `smooth_gap_m`, the line is smoothed as separate pieces, each with its ends fixed (see
//! [`super::KernelParams::smooth_gap_m`]).
//!
//! Each step is evaluated as p ← (1 − a)·p + (a/2)·(p₋ + p₊) — Eq. 3 rearranged, four
//! float operations instead of five; `1 − a` and `a/2` are computed once per step kind.
//! Every value is computed by this one expression from the previous step's three values, so
//! the two evaluation orders below give the same bits (tested), and the host and the
//! Cortex-M4F agree bit for bit whichever they use:
//!
//! - **per step** (64-bit hosts): each coordinate is smoothed separately, ping-ponging
//!   between the line's own array and one scratch array, so each step is a branch-free
//!   three-point stencil over contiguous `f32` that the compiler vectorises (SSE: 4 or 8
//!   points per instruction);
//! - **fused** (the M4F, which has no SIMD float unit): [`GROUP`] steps in one pass, in
//!   place, a wavefront: reading point t feeds step 1 at t − 1, step 2 at t − 2, … and the
//!   last step's value at t − [`GROUP`] is stored. Each step keeps its last values in
//!   registers, so a point costs one load, one store and four float operations per step
//!   instead of a load, a store and loop overhead per step.

/// Steps fused into one pass by the fused form (even, so a group starts with λ): the
/// wavefront keeps 3 values of each of its steps and 4 coefficients, 16 of the M4F's 32
/// single-precision registers.
pub(crate) const GROUP: usize = 4;

/// A larger group, tried first.
pub(crate) const BIG_GROUP: usize = 8;

/// One step's coefficients: p ← keep·p + half·(p₋ + p₊), keep = 1 − a, half = a/2.
#[derive(Clone, Copy, Debug)]
struct Coef {
    keep: f32,
    half: f32,
}

impl Coef {
    fn new(a: f32) -> Self {
        Self {
            keep: 1.0 - a,
            half: 0.5 * a,
        }
    }

    /// The new value of a point `c` between `l` and `r`.
    #[inline(always)]
    fn apply(self, l: f32, c: f32, r: f32) -> f32 {
        self.keep * c + self.half * (l + r)
    }
}

/// The coefficients of step `k` (counted from 0 within the piece).
#[inline]
fn coef(k: u32, lambda: Coef, mu: Coef) -> Coef {
    if k.is_multiple_of(2) {
        lambda
    } else {
        mu
    }
}

/// One smoothing step from `src` into `dst` (same length ≥ 2), ends copied.
#[inline]
fn step(src: &[f32], dst: &mut [f32], k: Coef) {
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
        *d = k.apply(l, c, r);
    }
}

/// Per-step form: smooths one coordinate of one piece in place with `steps` steps
/// (`scratch` at least as long).
#[cfg_attr(not(any(test, target_pointer_width = "64")), allow(dead_code))]
fn smooth_piece_steps(v: &mut [f32], scratch: &mut [f32], steps: u32, lambda: Coef, mu: Coef) {
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

/// One step in place (any length; fewer than 3 points have no interior).
fn step_in_place(v: &mut [f32], k: Coef) {
    let n = v.len();
    if n < 3 {
        return;
    }
    let (mut l, mut c) = (v[0], v[1]);
    for i in 1..n - 1 {
        let r = v[i + 1];
        v[i] = k.apply(l, c, r);
        l = c;
        c = r;
    }
}

/// Fused form: smooths one coordinate of one piece in place with `steps` steps.
#[cfg_attr(all(not(test), target_pointer_width = "64"), allow(dead_code))]
fn smooth_piece_fused(v: &mut [f32], steps: u32, lambda: Coef, mu: Coef) {
    let n = v.len();
    if n < 3 || steps == 0 {
        return;
    }
    let mut k = 0;
    if n >= BIG_GROUP + 2 {
        let co: [Coef; BIG_GROUP] = core::array::from_fn(|s| coef(s as u32, lambda, mu));
        while k + BIG_GROUP as u32 <= steps {
            fused_group::<BIG_GROUP>(v, &co);
            k += BIG_GROUP as u32;
        }
    }
    if n >= GROUP + 2 {
        let co: [Coef; GROUP] = core::array::from_fn(|s| coef(s as u32, lambda, mu));
        while k + GROUP as u32 <= steps {
            fused_group::<GROUP>(v, &co);
            k += GROUP as u32;
        }
    }
    while k < steps {
        step_in_place(v, coef(k, lambda, mu));
        k += 1;
    }
}

/// One tick of the wavefront at phase `P` (0, 1, 2): `x` is input point t; step s + 1
/// computes its value at t − s − 1 from step s's values at t − s − 2, t − s − 1 (kept in
/// `w[s]` at `P` and `P + 1`, mod 3) and t − s (just computed; stored at `P + 2`). Returns
/// the last step's value at t − [`GROUP`]. Rotating the three slots instead of shifting
/// values saves a register move per step and point once the caller unrolls by 3.
#[inline(always)]
fn tick<const P: usize, const K: usize>(w: &mut [[f32; 3]; K], co: &[Coef; K], x: f32) -> f32 {
    let mut x = x;
    for s in 0..K {
        let (a, b) = (w[s][P], w[s][(P + 1) % 3]);
        w[s][(P + 2) % 3] = x;
        x = co[s].apply(a, b, x);
    }
    x
}

/// The (older, newer) values of every step after ticks ending at phase `P`.
#[inline(always)]
fn state<const P: usize, const K: usize>(w: &[[f32; 3]; K]) -> [[f32; 2]; K] {
    core::array::from_fn(|s| [w[s][P], w[s][(P + 1) % 3]])
}

/// [`GROUP`] steps with coefficients `co` over `v` in place, in one pass (`v.len()` ≥
/// [`GROUP`] + 2). Step s's value at point m is computed exactly as [`step`] computes it,
/// from step s − 1's values at m − 1, m, m + 1; only the order differs.
fn fused_group<const K: usize>(v: &mut [f32], co: &[Coef; K]) {
    let n = v.len();
    debug_assert!(n >= K + 2);
    // Start: before input point GROUP + 1, step s (0 = the input) must hold its values at
    // GROUP − s − 1 and GROUP − s. Step s's value at m depends on the input up to m + s,
    // so s steps over the first K + 2 points alone (right end held) are exact there.
    const { assert!(K <= BIG_GROUP) };
    let mut head_buf = [0f32; BIG_GROUP + 2];
    let head = &mut head_buf[..K + 2];
    head.copy_from_slice(&v[..K + 2]);
    let mut st = [[0f32; 2]; K];
    for s in 0..K {
        if s > 0 {
            step_in_place(head, co[s - 1]);
        }
        st[s] = [head[K - s - 1], head[K - s]];
    }
    let mut w: [[f32; 3]; K] = core::array::from_fn(|s| [st[s][0], st[s][1], 0.0]);

    // The wavefront over input points GROUP + 1 ..= n − 1: every step computes an interior
    // value (t − s − 1 ∈ 1..=n − 2) and the last one is stored at t − GROUP ≥ 1, behind
    // every point still to be read.
    let mut t = K + 1;
    while t + 2 < n {
        v[t - K] = tick::<0, K>(&mut w, co, v[t]);
        v[t + 1 - K] = tick::<1, K>(&mut w, co, v[t + 1]);
        v[t + 2 - K] = tick::<2, K>(&mut w, co, v[t + 2]);
        t += 3;
    }
    let st = if t < n {
        v[t - K] = tick::<0, K>(&mut w, co, v[t]);
        t += 1;
        if t < n {
            v[t - K] = tick::<1, K>(&mut w, co, v[t]);
            state::<2, K>(&w)
        } else {
            state::<1, K>(&w)
        }
    } else {
        state::<0, K>(&w)
    };

    // End: `back[e]` is the current step's value at n − 1 − e. Step s holds its values at
    // e = s + 1 and e = s; step s + 1 still lacks e = 1..=s, which follow from step s's
    // values at e − 1 ..= e + 1 with the fixed end at e = 0.
    let end = v[n - 1];
    let mut back = [0f32; BIG_GROUP + 2];
    back[0] = end;
    back[1] = st[0][0];
    for s in 0..K {
        let mut next = [0f32; BIG_GROUP + 2];
        next[0] = end;
        for e in 1..=s {
            next[e] = co[s].apply(back[e + 1], back[e], back[e - 1]);
        }
        if s + 1 < K {
            next[s + 1] = st[s + 1][1];
            next[s + 2] = st[s + 1][0];
            back = next;
        } else {
            for e in 1..=s {
                v[n - 1 - e] = next[e];
            }
        }
    }
}

/// Smooths one coordinate of one piece in place with the form for this target.
#[inline]
fn smooth_piece(v: &mut [f32], scratch: &mut [f32], steps: u32, lambda: Coef, mu: Coef) {
    if cfg!(target_pointer_width = "64") {
        smooth_piece_steps(v, scratch, steps, lambda, mu);
    } else {
        smooth_piece_fused(v, steps, lambda, mu);
    }
}

/// Taubin-smooths the line `x`, `z` in place, piece by piece (split where consecutive
/// points are more than `gap_m` apart; `gap_m` ≤ 0 never splits). `scratch` must be at
/// least as long as the line (the per-step form ping-pongs through it). Returns the number
/// of pieces.
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
    let (lambda, mu) = (Coef::new(lambda), Coef::new(mu));
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
    fn fused_and_per_step_forms_give_the_same_bits() {
        // Every length around the group size and the unrolling by 3, every step count up
        // to three groups and a remainder.
        let (lambda, mu) = (Coef::new(0.6307), Coef::new(-0.6732));
        for n in 0..40usize {
            for steps in 0..23u32 {
                let v = noisy(n.max(1), 7 * n as u64 + u64::from(steps));
                let mut a = [0.0f32; 64];
                for i in 0..n {
                    a[i] = v[i] as f32;
                }
                let mut b = a;
                let mut scratch = [0.0f32; 64];
                smooth_piece_steps(&mut a[..n], &mut scratch, steps, lambda, mu);
                smooth_piece_fused(&mut b[..n], steps, lambda, mu);
                for i in 0..n {
                    assert_eq!(a[i].to_bits(), b[i].to_bits(), "n {n} steps {steps} i {i}");
                }
            }
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
