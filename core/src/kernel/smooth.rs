//! Taubin smoothing of the kept points (Honma et al. §2.5, Eq. 3; Taubin 1995).
//!
//! One step moves every interior point towards the mean of its two neighbours (w = 0.5 on
//! each, the reciprocal of the neighbour count): p ← p + a·(½(p₋ + p₊) − p), with a = λ on
//! even steps and a = μ on odd steps (λ = 0.6307, μ = −0.6732, 20 steps: ten λ/μ pairs).
//! The two end points stay fixed (docs/spec.md §2). Where consecutive points are farther apart than
//! `smooth_gap_m`, the line is smoothed as separate pieces, each with its ends fixed (see
//! [`super::KernelParams::smooth_gap_m`]).
//!
//! # Scaled steps: three float operations per point and step
//!
//! Eq. 3 rearranged is p′ = k·p + h·(p₋ + p₊) with k = 1 − a and h = a/2: four float
//! operations. Divided by h it is p′/h = (p₋ + p₊) + (k/h)·p, three. So the steps run on
//! scaled values u_s = p_s / G_s, G_s = h₀·h₁·…·h_{s−1}:
//!
//! u_{s+1} = (u₋ + u₊) + r_s·u,   r_s = k_s / h_s,
//!
//! and the true values come back as p = G·u. The steps are taken in *blocks* of
//! [`BLOCK`] steps (the last block shorter): each block starts from true values (u₀ = p,
//! G₀ = 1) and ends with one multiplication by G of its length, so the scale stays within
//! a factor of about 10⁴ for the default λ, μ however many steps there are (200 unscaled
//! steps would overflow f32). λ, μ so near zero that G would underflow take Eq. 3 as
//! written instead, on every target alike (`Block::scaled_ok`). A fixed end keeps its true
//! value p_e, so in step s of a block its scaled value is p_e·(1/G_s). The scaled form rounds differently from Eq. 3 as written, by a few ulp
//! (tested against an f64 reference); every value is computed by this one expression from
//! the previous step's three values, so the two evaluation orders below give the same bits
//! (tested), and the host and the Cortex-M4F agree bit for bit whichever they use:
//!
//! - **per step** (64-bit hosts): each coordinate is smoothed separately, ping-ponging
//!   between the line's own array and one scratch array, so each step is a branch-free
//!   three-point stencil over contiguous `f32` that the compiler vectorises (SSE: 4 or 8
//!   points per instruction);
//! - **fused** (the M4F, which has no SIMD float unit): a whole block in one pass, in
//!   place, a wavefront: reading point t feeds step 1 at t − 1, step 2 at t − 2, … and the
//!   block's last value at t − K is stored. Each step keeps its last values in registers,
//!   so a point costs one load, one store and three float operations per step (and one
//!   multiplication per block) instead of a load, a store and loop overhead per step.

use crate::math;

/// Steps per block (see the module docs); even, so every block starts with λ. The fused
/// wavefront of a full block keeps 3 values of each of its 8 steps and 8 factors r_s in
/// registers: 32, all of the M4F's single-precision registers.
pub(crate) const BLOCK: usize = 8;

/// A shorter block that also runs fused (the default 20 steps are 8 + 8 + 4).
pub(crate) const SHORT_BLOCK: usize = 4;

/// The constants of a block of `BLOCK` steps alternating λ, μ (a shorter block uses the
/// first `k` of them).
#[derive(Clone, Copy, Debug)]
struct Block {
    /// r_s = k_s / h_s for the λ steps (even s) and the μ steps (odd s): two values, so
    /// the fused form keeps two registers for them, not one per step.
    r: [f32; 2],
    /// 1 / G_s for s = 0..=BLOCK (the scale of a fixed end in step s).
    inv_g: [f32; BLOCK + 1],
    /// G_s for s = 0..=BLOCK (the factor that ends a block of s steps).
    g: [f32; BLOCK + 1],
}

impl Block {
    fn new(lambda: f32, mu: f32) -> Self {
        let mut b = Self {
            r: [0.0; 2],
            inv_g: [1.0; BLOCK + 1],
            g: [1.0; BLOCK + 1],
        };
        for s in 0..BLOCK {
            let a = if s % 2 == 0 { lambda } else { mu };
            let (keep, half) = (1.0 - a, 0.5 * a);
            b.r[s % 2] = keep / half;
            b.g[s + 1] = b.g[s] * half;
            b.inv_g[s + 1] = 1.0 / b.g[s + 1];
        }
        b
    }

    /// Whether the scaled form is safe for these λ, μ: every G_s of a block at least
    /// [`MIN_SCALE`] in magnitude. Then the scaled values, and r_s times them, stay below
    /// about 4·10³⁵ for coordinates the kernel keeps (≤ 2000 m, grown at most 3× per μ
    /// step within a block: 81×), inside f32's 3.4·10³⁸. With |λ·μ| below about 4·10⁻⁸
    /// (valid in a config packet, useless as smoothing) G would underflow and 1/G
    /// overflow; [`taubin_smooth`] then takes the plain form, on every target alike.
    fn scaled_ok(&self) -> bool {
        self.g.iter().all(|g| math::abs(*g) >= MIN_SCALE) && self.r.iter().all(|r| r.is_finite())
    }

    /// r_s of step `s`.
    #[inline(always)]
    fn r(&self, s: usize) -> f32 {
        self.r[s % 2]
    }
}

/// Smallest |G_s| the scaled form accepts (2⁻¹⁰⁰ ≈ 7.9·10⁻³¹, a normal f32; see
/// [`Block::scaled_ok`]).
const MIN_SCALE: f32 = 1.0 / (1u128 << 100) as f32;

/// Eq. 3 as written, p ← p + a·(½(p₋ + p₊) − p), one step in place with the ends fixed:
/// the form for parameters outside the scaled form's range ([`Block::scaled_ok`]).
fn plain_step_in_place(v: &mut [f32], a: f32) {
    let n = v.len();
    if n < 3 {
        return;
    }
    let (mut l, mut c) = (v[0], v[1]);
    for i in 1..n - 1 {
        let r = v[i + 1];
        v[i] = c + a * (0.5 * (l + r) - c);
        l = c;
        c = r;
    }
}

/// One scaled step's value of a point `c` between `l` and `r`.
#[inline(always)]
fn apply(r_s: f32, l: f32, c: f32, r: f32) -> f32 {
    (l + r) + r_s * c
}

/// Scaled step `s` of a block from `src` into `dst` (same length ≥ 2); the ends of `dst`
/// get the fixed ends `(first, last)` scaled for step s + 1.
#[inline]
fn step(src: &[f32], dst: &mut [f32], b: &Block, s: usize, ends: (f32, f32)) {
    let n = src.len();
    let dst = &mut dst[..n];
    dst[0] = ends.0 * b.inv_g[s + 1];
    dst[n - 1] = ends.1 * b.inv_g[s + 1];
    let r_s = b.r(s);
    let inner = &mut dst[1..n - 1];
    for (((d, &l), &c), &r) in inner
        .iter_mut()
        .zip(&src[..n - 2])
        .zip(&src[1..n - 1])
        .zip(&src[2..])
    {
        *d = apply(r_s, l, c, r);
    }
}

/// Ends a block of `k` steps: the interior back to true values, the ends restored.
fn unscale(v: &mut [f32], g: f32, ends: (f32, f32)) {
    let n = v.len();
    for u in &mut v[1..n - 1] {
        *u *= g;
    }
    v[0] = ends.0;
    v[n - 1] = ends.1;
}

/// Per-step form: smooths one coordinate of one piece in place with `steps` steps
/// (`scratch` at least as long).
#[cfg_attr(not(any(test, target_pointer_width = "64")), allow(dead_code))]
fn smooth_piece_steps(v: &mut [f32], scratch: &mut [f32], steps: u32, b: &Block) {
    let n = v.len();
    if n < 3 {
        return;
    }
    let ends = (v[0], v[n - 1]);
    let scratch = &mut scratch[..n];
    let mut left = steps as usize;
    while left > 0 {
        let k = left.min(BLOCK);
        let mut s = 0;
        while s + 1 < k {
            step(v, scratch, b, s, ends);
            step(scratch, v, b, s + 1, ends);
            s += 2;
        }
        if s < k {
            step(v, scratch, b, s, ends);
            v.copy_from_slice(scratch);
        }
        unscale(v, b.g[k], ends);
        left -= k;
    }
}

/// Scaled step `s` in place (`v[0]` holds the left end scaled for step s; any length,
/// fewer than 3 points have no interior); the left end is then scaled for step s + 1.
/// The last point is left as it is (the caller holds it).
fn step_in_place(v: &mut [f32], b: &Block, s: usize, first: f32) {
    let n = v.len();
    if n < 3 {
        return;
    }
    let r_s = b.r(s);
    let (mut l, mut c) = (v[0], v[1]);
    for i in 1..n - 1 {
        let r = v[i + 1];
        v[i] = apply(r_s, l, c, r);
        l = c;
        c = r;
    }
    v[0] = first * b.inv_g[s + 1];
}

/// A block of `k` steps in place, step by step (for pieces too short for the wavefront
/// and block lengths without a fused form).
fn block_in_place(v: &mut [f32], k: usize, b: &Block) {
    let n = v.len();
    let ends = (v[0], v[n - 1]);
    for s in 0..k {
        step_in_place(v, b, s, ends.0);
        v[n - 1] = ends.1 * b.inv_g[s + 1];
    }
    unscale(v, b.g[k], ends);
}

/// Fused form: smooths one coordinate of one piece in place with `steps` steps.
#[cfg_attr(all(not(test), target_pointer_width = "64"), allow(dead_code))]
fn smooth_piece_fused(v: &mut [f32], steps: u32, b: &Block) {
    let n = v.len();
    if n < 3 {
        return;
    }
    let mut left = steps as usize;
    while left > 0 {
        let k = left.min(BLOCK);
        if k == BLOCK && n >= BLOCK + 2 {
            fused_block::<BLOCK>(v, b);
        } else if k == SHORT_BLOCK && n >= SHORT_BLOCK + 2 {
            fused_block::<SHORT_BLOCK>(v, b);
        } else {
            block_in_place(v, k, b);
        }
        left -= k;
    }
}

/// One tick of the wavefront at phase `P` (0, 1, 2): `x` is input point t; step s + 1
/// computes its value at t − s − 1 from step s's values at t − s − 2, t − s − 1 (kept in
/// `w[s]` at `P` and `P + 1`, mod 3) and t − s (just computed; stored at `P + 2`). Returns
/// the last step's (scaled) value at t − K. Rotating the three slots instead of shifting
/// values saves a register move per step and point once the caller unrolls by 3.
#[inline(always)]
fn tick<const P: usize, const K: usize>(w: &mut [[f32; 3]; K], r: &[f32; K], x: f32) -> f32 {
    let mut x = x;
    for s in 0..K {
        let (a, c) = (w[s][P], w[s][(P + 1) % 3]);
        w[s][(P + 2) % 3] = x;
        x = apply(r[s], a, c, x);
    }
    x
}

/// Ramp-up tick `T` of [`fused_block`] (no-op for `T` > `K`): reads input point `T`,
/// which gives step s its value at T − s for s < T, and step s + 1 its value at T − s − 1
/// from step s's (older, newer) and that value (the value for step T, whose point 0 is
/// its fixed end, is not used). `older`, `newer` hold each step's last two values.
#[inline(always)]
fn ramp_up<const T: usize, const K: usize>(
    older: &mut [f32; K],
    newer: &mut [f32; K],
    r: &[f32; K],
    v: &[f32],
) {
    if T > K {
        return;
    }
    let mut x = v[T];
    for s in 0..T {
        let next = apply(r[s], older[s], newer[s], x);
        older[s] = newer[s];
        newer[s] = x;
        x = next;
    }
}

/// Ramp-down tick `U` of [`fused_block`] (no-op for `U` ≥ `K`): `x` is step U's value at
/// its fixed end e = 0; step s ≥ U moves on to e = s − U, step s + 1 to e = s − U + 1 from
/// step s's (older, newer) and that value; the last step's value lands in `out[K − U]`.
#[inline(always)]
fn ramp_down<const U: usize, const K: usize>(
    older: &mut [f32; K],
    newer: &mut [f32; K],
    r: &[f32; K],
    x: f32,
    out: &mut [f32; BLOCK],
) {
    if U >= K {
        return;
    }
    let mut x = x;
    for s in U..K {
        let next = apply(r[s], older[s], newer[s], x);
        older[s] = newer[s];
        newer[s] = x;
        x = next;
    }
    out[K - U] = x;
}

/// The (older, newer) values of every step after ticks ending at phase `P`.
#[inline(always)]
fn state<const P: usize, const K: usize>(w: &[[f32; 3]; K]) -> [[f32; 2]; K] {
    core::array::from_fn(|s| [w[s][P], w[s][(P + 1) % 3]])
}

/// A block of `K` steps over `v` in place, in one pass (`v.len()` ≥ K + 2). Step s's value
/// at point m is computed exactly as [`step`] computes it, from step s − 1's values at
/// m − 1, m, m + 1; only the order differs.
fn fused_block<const K: usize>(v: &mut [f32], b: &Block) {
    // The ramps below are written out for blocks of up to 8 steps.
    const { assert!(K <= BLOCK && BLOCK == 8) };
    let n = v.len();
    debug_assert!(n >= K + 2);
    let r: [f32; K] = core::array::from_fn(|s| b.r(s));
    let g = b.g[K];
    let (first, last) = (v[0], v[n - 1]);
    // Start: before input point K + 1, step s (0 = the input) must hold its values at
    // K − s − 1 and K − s. The wavefront ramps up to that ([`ramp_up`]): every step's
    // value at 0 is its fixed end (first·(1/G_s)), and reading input point t = 1..=K
    // moves steps 0..t on by one point.
    let mut newer: [f32; K] =
        core::array::from_fn(|s| if s == 0 { first } else { first * b.inv_g[s] });
    let mut older = [0f32; K];
    ramp_up::<1, K>(&mut older, &mut newer, &r, v);
    ramp_up::<2, K>(&mut older, &mut newer, &r, v);
    ramp_up::<3, K>(&mut older, &mut newer, &r, v);
    ramp_up::<4, K>(&mut older, &mut newer, &r, v);
    ramp_up::<5, K>(&mut older, &mut newer, &r, v);
    ramp_up::<6, K>(&mut older, &mut newer, &r, v);
    ramp_up::<7, K>(&mut older, &mut newer, &r, v);
    ramp_up::<8, K>(&mut older, &mut newer, &r, v);
    let mut w: [[f32; 3]; K] = core::array::from_fn(|s| [older[s], newer[s], 0.0]);

    // The wavefront over input points K + 1 ..= n − 1: every step computes an interior
    // value (t − s − 1 ∈ 1..=n − 2) and the last one is stored at t − K ≥ 1, behind every
    // point still to be read.
    let mut t = K + 1;
    while t + 2 < n {
        // One window per three points: reads at K.., writes at 0..3, one bounds check.
        let win = &mut v[t - K..t + 3];
        win[0] = g * tick::<0, K>(&mut w, &r, win[K]);
        win[1] = g * tick::<1, K>(&mut w, &r, win[K + 1]);
        win[2] = g * tick::<2, K>(&mut w, &r, win[K + 2]);
        t += 3;
    }
    let st = if t < n {
        v[t - K] = g * tick::<0, K>(&mut w, &r, v[t]);
        t += 1;
        if t < n {
            v[t - K] = g * tick::<1, K>(&mut w, &r, v[t]);
            state::<2, K>(&w)
        } else {
            state::<1, K>(&w)
        }
    } else {
        state::<0, K>(&w)
    };

    // End: step s holds its values at n − 1 − e for e = s + 1 and e = s; step s + 1
    // still lacks e = 1..=s. The wavefront ramps down ([`ramp_down`]): step u's next value
    // is its fixed end at e = 0, which moves steps u + 1..=K on by one point, down to the
    // last step's value at e = K − u.
    let [mut older, mut newer] = [0, 1].map(|k| core::array::from_fn::<f32, K, _>(|s| st[s][k]));
    let mut out = [0f32; BLOCK];
    ramp_down::<1, K>(&mut older, &mut newer, &r, last * b.inv_g[1], &mut out);
    ramp_down::<2, K>(&mut older, &mut newer, &r, last * b.inv_g[2], &mut out);
    ramp_down::<3, K>(&mut older, &mut newer, &r, last * b.inv_g[3], &mut out);
    ramp_down::<4, K>(&mut older, &mut newer, &r, last * b.inv_g[4], &mut out);
    ramp_down::<5, K>(&mut older, &mut newer, &r, last * b.inv_g[5], &mut out);
    ramp_down::<6, K>(&mut older, &mut newer, &r, last * b.inv_g[6], &mut out);
    ramp_down::<7, K>(&mut older, &mut newer, &r, last * b.inv_g[7], &mut out);
    // out[e] is the last step's value at e = 1..K.
    let tail = &mut v[n - K..n - 1];
    for (e, p) in (1..K).zip(tail.iter_mut().rev()) {
        *p = g * out[e];
    }
    // The ends were never written: they keep their true values.
}

/// Smooths one coordinate of one piece in place with the form for this target.
#[inline]
fn smooth_piece(v: &mut [f32], scratch: &mut [f32], steps: u32, b: &Block) {
    if cfg!(target_pointer_width = "64") {
        smooth_piece_steps(v, scratch, steps, b);
    } else {
        smooth_piece_fused(v, steps, b);
    }
}

/// The end of the piece that starts at `start` (< `x.len()`): the first point more than
/// the gap (`gap2`, squared) from its predecessor, or the line's length.
#[inline(always)]
fn piece_end(x: &[f32], z: &[f32], start: usize, gap2: f32) -> usize {
    let n = x.len();
    let z = &z[..n];
    let apart = |(ax, az): (f32, f32), (bx, bz): (f32, f32)| {
        let (dx, dz) = (bx - ax, bz - az);
        dx * dx + dz * dz > gap2
    };
    // Two points per round, so that the previous point stays in its registers (two
    // loads per point, no moves).
    let mut p = (x[start], z[start]);
    let mut e = start + 1;
    while e + 1 < n {
        let c = (x[e], z[e]);
        if apart(p, c) {
            return e;
        }
        let q = (x[e + 1], z[e + 1]);
        if apart(c, q) {
            return e + 1;
        }
        p = q;
        e += 2;
    }
    if e < n && apart(p, (x[e], z[e])) {
        return e;
    }
    n
}

/// Taubin-smooths the line `x`, `z` in place, piece by piece (split where consecutive
/// points are more than `gap_m` apart; `gap_m` ≤ 0 never splits). `scratch` must be at
/// least as long as the line (the per-step form ping-pongs through it). Returns the number
/// of pieces.
#[allow(clippy::neg_cmp_op_on_partial_ord)] // a NaN distance does not split, as before
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
    let b = Block::new(lambda, mu);
    let scaled = b.scaled_ok();
    let mut pieces = 0;
    let mut start = 0;
    while start < n {
        let end = if split {
            piece_end(x, z, start, gap2)
        } else {
            n
        };
        if scaled {
            smooth_piece(&mut x[start..end], scratch, steps, &b);
            smooth_piece(&mut z[start..end], scratch, steps, &b);
        } else {
            for v in [&mut x[start..end], &mut z[start..end]] {
                for k in 0..steps {
                    plain_step_in_place(v, if k % 2 == 0 { lambda } else { mu });
                }
            }
        }
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
        let b = Block::new(0.6307, -0.6732);
        for n in 0..40usize {
            for steps in 0..35u32 {
                let v = noisy(n.max(1), 7 * n as u64 + u64::from(steps));
                let mut a = [0.0f32; 64];
                for i in 0..n {
                    a[i] = v[i] as f32;
                }
                let mut f = a;
                let mut scratch = [0.0f32; 64];
                smooth_piece_steps(&mut a[..n], &mut scratch, steps, &b);
                smooth_piece_fused(&mut f[..n], steps, &b);
                for i in 0..n {
                    assert_eq!(a[i].to_bits(), f[i].to_bits(), "n {n} steps {steps} i {i}");
                }
            }
        }
    }

    #[test]
    fn parameters_near_zero_take_the_plain_form_and_stay_finite() {
        // λ = 10⁻²⁰ underflows G (and 1/G overflows): the scaled form would give inf.
        for (lambda, mu, steps) in [(1e-20f32, -1e-20f32, 20u32), (1e-9, -1e-9, 200)] {
            assert!(!Block::new(lambda, mu).scaled_ok(), "{lambda} {mu}");
            let n = 40;
            let v = noisy(n, 3);
            let want = reference(&v[..n], steps, f64::from(lambda), f64::from(mu));
            let mut x = [0.0f32; 64];
            let mut z = [0.0f32; 64];
            for i in 0..n {
                x[i] = v[i] as f32;
                z[i] = 2.0 * v[i] as f32;
            }
            let mut scratch = [0.0f32; 64];
            taubin_smooth(
                &mut x[..n],
                &mut z[..n],
                &mut scratch,
                0.0,
                steps,
                lambda,
                mu,
            );
            for i in 0..n {
                assert!(x[i].is_finite() && z[i].is_finite(), "{lambda} {mu} i {i}");
                assert!(
                    (f64::from(x[i]) - want[i]).abs() < 1e-4,
                    "{lambda} {mu} i {i}"
                );
            }
        }
        // The defaults and the ends of the documented ranges stay on the scaled form.
        for (lambda, mu) in [
            (0.6307f32, -0.6732f32),
            (1.0, -1.0),
            (1e-3, -1e-3),
            (1.0, -1e-6),
        ] {
            assert!(Block::new(lambda, mu).scaled_ok(), "{lambda} {mu}");
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
