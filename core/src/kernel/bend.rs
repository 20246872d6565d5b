//! Bend angle ρ (Honma et al. §2.3, docs/spec.md §2) and the removal of irregular points (§2.4).
//!
//! # Neighbours: one two-index sweep per side
//!
//! docs/spec.md §2: walk outward from i while points stay within d_b of p_i; s and t are the last
//! points reached. The kernel finds them with monotone pointers, O(n) per line:
//!
//! - left, a forward sweep: s(i) is the first index j ≥ max(s(i−1), i − [`MAX_SIDE`]) with
//!   |p_j − p_i| ≤ d_b;
//! - right, the mirror image as a backward sweep: t(i) is the last index
//!   j ≤ min(t(i+1), i + [`MAX_SIDE`]) with |p_j − p_i| ≤ d_b.
//!
//! Wherever the distance from p_i grows along the line away from i (a profile that does not
//! fold back on itself within d_b) this is exactly the walk of docs/spec.md §2; where noise
//! folds the line back (a return nearer to p_i than its predecessor), the sweep may reach
//! one point past the excursion. The two rules are mirror images, so reversing the line (the other
//! rotation direction) swaps s and t exactly. [`MAX_SIDE`] bounds the work and the
//! peak search's deque for degenerate input (hundreds of returns on one spot); real lines
//! need at most d_b / spacing ≈ 30 points per side.
//!
//! Distances are compared squared (no square root).
//!
//! # Sign rule (docs/spec.md §2)
//!
//! With a = p_i − p_s, b = p_t − p_i, c = a × b and d = a · b, the unsigned angle between
//! s→i and i→t is atan2(|c|, d). ρ is positive when i and the scanner (0, 0) lie on
//! opposite sides of the chord s–t. Since a × b = −(t − s) × (i − s), i's side of the chord
//! has the sign of −c, and the scanner's side is the sign of s × t; so ρ = atan2(c · sgn(s × t), d).
//! A scanner exactly on the chord (s × t = 0) counts as "not opposite" (ρ ≤ 0). Nothing
//! here depends on the order of s and t, so the sign does not depend on the rotation.

use super::PointStatus;
use crate::math::{self, Maths};

/// Largest number of points a neighbour window reaches on one side of its point.
pub const MAX_SIDE: usize = 255;

/// Radians to degrees.
const RAD_TO_DEG: f32 = 180.0 / core::f32::consts::PI;

/// Squared distance between points `a` and `b`.
#[inline(always)]
fn dist2(x: &[f32], z: &[f32], a: usize, b: usize) -> f32 {
    let dx = x[a] - x[b];
    let dz = z[a] - z[b];
    dx * dx + dz * dz
}

/// Whether point `a` is beyond d_b of point `b`. NaN (a non-finite coordinate) counts as
/// beyond, so a non-finite point is never anyone's neighbour and never stops a sweep.
#[inline(always)]
#[allow(clippy::neg_cmp_op_on_partial_ord)] // the NaN case is the point
fn beyond(x: &[f32], z: &[f32], a: usize, b: usize, d2: f32) -> bool {
    !(dist2(x, z, a, b) <= d2)
}

/// Both neighbour windows of every point: i − s(i) into `s_off[i]`, t(i) − i into
/// `t_off[i]`. Returns how many windows stopped at [`MAX_SIDE`] with the next point still
/// within d_b (either side).
///
/// Two forms, the same windows (tested): on 64-bit hosts [`windows_interleaved`], tuned
/// for an out-of-order CPU; elsewhere (the M4F, in order, no branch predictor to speak of)
/// [`windows_sweeps`], which takes fewer instructions there (docs/benchmarks.md).
pub(crate) fn windows(x: &[f32], z: &[f32], d2: f32, s_off: &mut [u8], t_off: &mut [u8]) -> u32 {
    if cfg!(target_pointer_width = "64") {
        windows_interleaved(x, z, d2, s_off, t_off)
    } else {
        windows_sweeps(x, z, d2, s_off, t_off)
    }
}

/// [`windows`] as two plain sweeps, one after the other: per point, p_i is loaded once and
/// the walk tests each candidate once (two distance tests when the window moves by one
/// point, one when it stays) — the interleaved form tests one position twice.
#[cfg_attr(all(not(test), target_pointer_width = "64"), allow(dead_code))]
#[allow(clippy::neg_cmp_op_on_partial_ord)] // NaN counts as beyond, as in `beyond`
fn windows_sweeps(x: &[f32], z: &[f32], d2: f32, s_off: &mut [u8], t_off: &mut [u8]) -> u32 {
    let n = x.len();
    let (z, s_off, t_off) = (&z[..n], &mut s_off[..n], &mut t_off[..n]);
    let mut capped = forward_sweep(x, z, d2, s_off);
    // Backward: t(j) is the last index ≤ min(t(j + 1), j + MAX_SIDE) within d_b; j ≤ t < n.
    let mut t = n.saturating_sub(1);
    for j in (0..n).rev() {
        back_walk(x, z, d2, j, &mut t, &mut capped);
        t_off[j] = (t - j) as u8;
    }
    capped
}

/// The forward sweep of [`windows_sweeps`]: i − s(i) into `s_off`; returns the windows
/// capped on the left.
#[inline(always)]
#[allow(clippy::neg_cmp_op_on_partial_ord)] // NaN counts as beyond, as in `beyond`
fn forward_sweep(x: &[f32], z: &[f32], d2: f32, s_off: &mut [u8]) -> u32 {
    let n = x.len();
    let (z, s_off) = (&z[..n], &mut s_off[..n]);
    let mut capped = 0u32;
    // Forward: s(i) is the first j ≥ max(s(i − 1), i − MAX_SIDE) within d_b; s ≤ i < n.
    let mut s = 0usize;
    for i in 0..n {
        let (xi, zi) = (x[i], z[i]);
        let far = |j: usize| {
            let (dx, dz) = (x[j] - xi, z[j] - zi);
            !(dx * dx + dz * dz <= d2)
        };
        while s < i && far(s) {
            s += 1;
        }
        let off = i - s;
        s_off[i] = off as u8;
        if off == MAX_SIDE {
            capped += fwd_capped(x, z, d2, s, i);
            // The next point's window starts at max(s, i + 1 − MAX_SIDE) = s + 1: the cap
            // taken here, where the window is known to be full, rather than tested for
            // at every point.
            s += 1;
        }
    }
    capped
}

/// Whether the forward window of `i`, stopped at s = i − [`MAX_SIDE`], is capped: 1 if
/// the point before s is still within d_b of p_i, else 0. Out of line (rare).
#[cold]
#[inline(never)]
#[allow(clippy::neg_cmp_op_on_partial_ord)] // NaN counts as beyond, as in `beyond`
fn fwd_capped(x: &[f32], z: &[f32], d2: f32, s: usize, i: usize) -> u32 {
    if s == 0 {
        return 0;
    }
    let (dx, dz) = (x[s - 1] - x[i], z[s - 1] - z[i]);
    u32::from(dx * dx + dz * dz <= d2)
}

/// One step of the backward sweep: moves `t` from t(j + 1) down to t(j) (capped at
/// j + [`MAX_SIDE`], counted in `capped`) and returns p_t − p_j from the walk's last
/// distance test — b of the §2.4 test and of ρ, the same bits they would compute; (0, 0)
/// when t = j, as x_j − x_j.
#[inline(always)]
fn back_walk(
    x: &[f32],
    z: &[f32],
    d2: f32,
    j: usize,
    t: &mut usize,
    capped: &mut u32,
) -> (f32, f32) {
    let (xj, zj) = (x[j], z[j]);
    if *t - j > MAX_SIDE {
        let (cap, stopped) = back_cap(x, z, d2, j);
        *t = cap;
        *capped += stopped;
    }
    while *t > j {
        let (dx, dz) = (x[*t] - xj, z[*t] - zj);
        if dx * dx + dz * dz <= d2 {
            return (dx, dz);
        }
        *t -= 1;
    }
    (0.0, 0.0)
}

/// [`back_walk`] over the candidates j + 1 ..= t as slices, walked from t down: one
/// bounds check per point rather than one per step. The same result; fewer instructions
/// in the raw line's sweep, more in the smoothed one's (registers), so each takes its own.
#[inline(always)]
fn back_walk_sliced(
    x: &[f32],
    z: &[f32],
    d2: f32,
    j: usize,
    t: &mut usize,
    capped: &mut u32,
) -> (f32, f32) {
    let (xj, zj) = (x[j], z[j]);
    if *t - j > MAX_SIDE {
        let (cap, stopped) = back_cap(x, z, d2, j);
        *t = cap;
        *capped += stopped;
    }
    let hi = *t;
    let (xs, zs) = (&x[j + 1..=hi], &z[j + 1..=hi]);
    let zs = &zs[..xs.len()];
    for k in (0..xs.len()).rev() {
        let (dx, dz) = (xs[k] - xj, zs[k] - zj);
        if dx * dx + dz * dz <= d2 {
            *t = j + 1 + k;
            return (dx, dz);
        }
    }
    *t = j;
    (0.0, 0.0)
}

/// The backward window's cap at point `j`, out of line (rare: runs of returns on one
/// spot): t = j + [`MAX_SIDE`], and 1 if the next point is still within d_b (a capped
/// window), else 0.
#[cold]
#[inline(never)]
#[allow(clippy::neg_cmp_op_on_partial_ord)] // NaN counts as beyond, as in `beyond`
fn back_cap(x: &[f32], z: &[f32], d2: f32, j: usize) -> (usize, u32) {
    let t = j + MAX_SIDE;
    let (dx, dz) = (x[t + 1] - x[j], z[t + 1] - z[j]);
    (t, u32::from(dx * dx + dz * dz <= d2))
}

/// [`windows`] with the forward and the backward sweep in one loop.
///
/// Each sweep is a serial chain (the next position depends on the last comparison: load,
/// subtract, square, add, compare ≈ 20 cycles per step); running the forward and the
/// backward sweep in the same loop gives the CPU two independent chains to overlap.
#[cfg_attr(all(not(test), not(target_pointer_width = "64")), allow(dead_code))]
fn windows_interleaved(x: &[f32], z: &[f32], d2: f32, s_off: &mut [u8], t_off: &mut [u8]) -> u32 {
    let n = x.len();
    let (z, s_off, t_off) = (&z[..n], &mut s_off[..n], &mut t_off[..n]);
    let mut capped = 0u32;
    let mut s = 0usize;
    let mut t = n.saturating_sub(1);
    for k in 0..n {
        // Forward: s(i) for i = k.
        let i = k;
        s = left_neighbour(x, z, d2, s, i);
        s_off[i] = (i - s) as u8;
        if s + MAX_SIDE == i && s > 0 && !beyond(x, z, s - 1, i, d2) {
            capped += 1;
        }
        // Backward: t(j) for j = n − 1 − k.
        let j = n - 1 - k;
        let hi = j + MAX_SIDE;
        if t > hi {
            t = hi;
            if !beyond(x, z, t + 1, j, d2) {
                capped += 1;
            }
        }
        // As in `left_neighbour`: the usual step of 0 or 1 without a branch.
        t -= usize::from((t > j) & beyond(x, z, t, j, d2));
        while t > j && beyond(x, z, t, j, d2) {
            t -= 1;
        }
        t_off[j] = (t - j) as u8;
    }
    capped
}

/// The forward sweep's left neighbour of `i`, given the previous one.
#[inline(always)]
#[cfg_attr(all(not(test), not(target_pointer_width = "64")), allow(dead_code))]
fn left_neighbour(x: &[f32], z: &[f32], d2: f32, s_prev: usize, i: usize) -> usize {
    let mut s = s_prev.max(i.saturating_sub(MAX_SIDE));
    // s usually moves by 0 or 1 per point: take that step without a branch, loop only for
    // longer moves. (Testing two or four positions at once, branch-free, is no faster:
    // each step is a serial chain — load, subtract, square, add, compare — either way.)
    s += usize::from((s < i) & beyond(x, z, s, i, d2));
    while s < i && beyond(x, z, s, i, d2) {
        s += 1;
    }
    s
}

/// Cosine and sine of the irregular-point threshold, precomputed once per parameter set.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Threshold {
    cos: f32,
    sin: f32,
    /// A d at least this large is certainly not irregular (see [`irregular_test`]): 0 when
    /// cos ≤ 0 ≤ sin (a threshold of 90° or more), else +∞.
    d_kept: f32,
}

impl Threshold {
    /// A placeholder before the parameters' threshold is computed.
    pub(crate) const PENDING: Self = Self {
        cos: 0.0,
        sin: 0.0,
        d_kept: f32::INFINITY,
    };

    /// The threshold `deg` degrees (0 < deg ≤ 180).
    pub(crate) fn new(deg: f32) -> Self {
        let r = deg / RAD_TO_DEG;
        let (cos, sin) = (math::cos(r), math::sin(r));
        Self {
            cos,
            sin,
            d_kept: if cos <= 0.0 && sin >= 0.0 {
                0.0
            } else {
                f32::INFINITY
            },
        }
    }
}

/// Largest |x′| or |z′| the kernel accepts, metres; farther points get
/// [`PointStatus::NonFinite`]. Beyond any lidar's range (a VQ-250 reaches about 500 m) and
/// inside what an output packet can carry (±2147 m).
pub const MAX_COORD_M: f32 = 2000.0;

/// §2.4 on the raw line: marks each point [`PointStatus::Irregular`] when |ρ| exceeds the
/// threshold, [`PointStatus::NonFinite`] when a coordinate is NaN, infinite or beyond
/// ±[`MAX_COORD_M`], and
/// provisionally [`PointStatus::Kept`] otherwise (also when it has no neighbour on one side:
/// no ρ, nothing to judge). A point with no neighbour on *either* side is judged with its
/// two adjacent points as s and t: a lone spike taller than d_b would otherwise survive
/// §2.4 and cut the smoothed line in three. The offsets come from [`windows`]. Returns the
/// number of irregular and non-finite points.
///
/// No atan2: with φ = atan2(|c|, d) ∈ [0, π] and θ the threshold, φ > θ ⟺ sin(φ − θ) > 0
/// ⟺ |c|·cos θ − d·sin θ > 0 (both sides scaled by |a||b| > 0).
#[inline(never)] // its own registers: inlined into `process`, it rematerialised addresses
pub(crate) fn mark_irregular(
    x: &[f32],
    z: &[f32],
    s_off: &[u8],
    t_off: &[u8],
    thr: Threshold,
    status: &mut [PointStatus],
) -> (u32, u32) {
    let n = x.len();
    let (z, s_off, t_off, status) = (&z[..n], &s_off[..n], &t_off[..n], &mut status[..n]);
    let (mut irregular, mut non_finite) = (0u32, 0u32);
    // Iterators rather than indices for the per-point arrays: each gets its own pointer
    // (on the M4F, indexing them from one base rematerialised large offsets every point).
    let per_point = status.iter_mut().zip(s_off.iter().zip(t_off));
    for (i, (st, (&so, &to))) in per_point.enumerate() {
        *st = judge(x, z, i, usize::from(so), usize::from(to), thr);
        irregular += u32::from(*st == PointStatus::Irregular);
        non_finite += u32::from(*st == PointStatus::NonFinite);
    }
    (irregular, non_finite)
}

/// [`mark_irregular`]'s verdict on point `i` (< `x.len()`) with window offsets `so`, `to`.
#[inline(always)]
fn judge(x: &[f32], z: &[f32], i: usize, so: usize, to: usize, thr: Threshold) -> PointStatus {
    let n = x.len();
    let z = &z[..n];
    let (xi, zi) = (x[i], z[i]);
    // Out of range counts as non-finite: the wire carries any finite f32, but squares of
    // coordinates near f32::MAX overflow in the bend angle and in smoothing, and output
    // packets hold |x′|, |z′| < 2147 m.
    // |v| ≤ MAX_COORD_M compared on the bit patterns of |x′| and |z′| (monotone for
    // non-negative floats; NaN and ±inf lie above): the same test as
    // `(-MAX..=MAX).contains(&v)` on both, in integer instructions.
    let mag = (xi.to_bits() & 0x7FFF_FFFF).max(zi.to_bits() & 0x7FFF_FFFF);
    if mag > MAX_COORD_BITS {
        return PointStatus::NonFinite;
    }
    // An isolated point (nothing within d_b on either side: a spike taller than d_b)
    // is judged by its adjacent points instead, or it could never be removed. Rare: out
    // of line, so the common path keeps its registers.
    if so | to == 0 {
        return judge_isolated(x, z, i, thr);
    }
    judge_with(x, z, i, i - so, i + to, thr)
}

/// [`judge`] with b = p_t − p_i already computed (by the backward sweep); with `IN_RANGE`
/// the point is known to be finite and within ±[`MAX_COORD_M`].
#[inline(always)]
fn judge_b<const IN_RANGE: bool>(
    x: &[f32],
    z: &[f32],
    i: usize,
    so: usize,
    to: usize,
    b: (f32, f32),
    thr: Threshold,
) -> PointStatus {
    let (xi, zi) = (x[i], z[i]);
    let mag = (xi.to_bits() & 0x7FFF_FFFF).max(zi.to_bits() & 0x7FFF_FFFF);
    if !IN_RANGE && mag > MAX_COORD_BITS {
        return PointStatus::NonFinite;
    }
    if so | to == 0 {
        return judge_isolated(x, z, i, thr);
    }
    let sj = i - so;
    let (ax, az) = (xi - x[sj], zi - z[sj]);
    irregular_test(ax, az, b.0, b.1, thr)
}

/// The irregular test on a = p_i − p_s, b = p_t − p_i (see [`mark_irregular`]).
///
/// d first: with cos θ ≤ 0 ≤ sin θ, a d ≥ 0 makes |c|·cos θ ≤ 0 and d·sin θ ≥ 0 (or NaN
/// from an infinite factor), so the test is false whatever c is; and d = +∞ makes it false
/// for any θ (−∞ or NaN). So where d ≥ `thr.d_kept` the point is kept without computing c.
#[inline(always)]
fn irregular_test(ax: f32, az: f32, bx: f32, bz: f32, thr: Threshold) -> PointStatus {
    let d = ax * bx + az * bz;
    if d >= thr.d_kept {
        return PointStatus::Kept;
    }
    let c = ax * bz - az * bx;
    // With s == i or t == i, c = d = 0 and the test is false: kept.
    if math::abs(c) * thr.cos - d * thr.sin > 0.0 {
        PointStatus::Irregular
    } else {
        PointStatus::Kept
    }
}

/// [`judge`] of a point with no neighbour within d_b on either side (already known to be
/// in range): by its adjacent points, if it has both.
#[cold]
#[inline(never)]
fn judge_isolated(x: &[f32], z: &[f32], i: usize, thr: Threshold) -> PointStatus {
    if i > 0 && i + 1 < x.len() {
        judge_with(x, z, i, i - 1, i + 1, thr)
    } else {
        PointStatus::Kept
    }
}

/// The irregular test of point `i` (in range) with neighbours `sj` and `tj`.
#[inline(always)]
fn judge_with(x: &[f32], z: &[f32], i: usize, sj: usize, tj: usize, thr: Threshold) -> PointStatus {
    let n = x.len();
    let z = &z[..n];
    let (xi, zi) = (x[i], z[i]);
    let (ax, az) = (xi - x[sj], zi - z[sj]);
    let (bx, bz) = (x[tj] - xi, z[tj] - zi);
    irregular_test(ax, az, bx, bz, thr)
}

/// [`windows`] and then [`mark_irregular`] on the raw line: returns (capped windows,
/// irregular, non-finite). On the M4F the judgement runs inside the backward sweep, while
/// the point and its window are still in registers; elsewhere it is the two calls.
/// `in_range`: the caller knows every point to be finite and within ±[`MAX_COORD_M`]
/// (inside a region of interest that lies within it), so the sweep skips that test; the
/// verdicts are the same.
#[allow(clippy::too_many_arguments)]
pub(crate) fn windows_marked(
    x: &[f32],
    z: &[f32],
    d2: f32,
    s_off: &mut [u8],
    t_off: &mut [u8],
    thr: Threshold,
    status: &mut [PointStatus],
    in_range: bool,
) -> (u32, u32, u32) {
    if cfg!(target_pointer_width = "64") {
        let capped = windows(x, z, d2, s_off, t_off);
        let (irr, nf) = mark_irregular(x, z, s_off, t_off, thr, status);
        (capped, irr, nf)
    } else if in_range {
        windows_sweeps_marked::<true>(x, z, d2, s_off, t_off, thr, status)
    } else {
        windows_sweeps_marked::<false>(x, z, d2, s_off, t_off, thr, status)
    }
}

/// [`windows_sweeps`] with [`judge`] in the backward sweep; `IN_RANGE` as `in_range` of
/// [`windows_marked`].
#[inline(never)] // its own registers (see `mark_irregular`)
#[cfg_attr(all(not(test), target_pointer_width = "64"), allow(dead_code))]
#[allow(clippy::neg_cmp_op_on_partial_ord)] // NaN counts as beyond, as in `beyond`
fn windows_sweeps_marked<const IN_RANGE: bool>(
    x: &[f32],
    z: &[f32],
    d2: f32,
    s_off: &mut [u8],
    t_off: &mut [u8],
    thr: Threshold,
    status: &mut [PointStatus],
) -> (u32, u32, u32) {
    let n = x.len();
    let (z, s_off, t_off, status) = (&z[..n], &mut s_off[..n], &mut t_off[..n], &mut status[..n]);
    let mut capped = forward_sweep(x, z, d2, s_off);
    let (mut irregular, mut non_finite) = (0u32, 0u32);
    let mut t = n.saturating_sub(1);
    for j in (0..n).rev() {
        let (bx, bz) = back_walk_sliced(x, z, d2, j, &mut t, &mut capped);
        t_off[j] = (t - j) as u8;
        let st = judge_b::<IN_RANGE>(x, z, j, usize::from(s_off[j]), t - j, (bx, bz), thr);
        status[j] = st;
        // Set-aside points are rare: a branch, not two branch-free counts per point.
        if st != PointStatus::Kept {
            irregular += u32::from(st == PointStatus::Irregular);
            non_finite += u32::from(st == PointStatus::NonFinite);
        }
    }
    (capped, irregular, non_finite)
}

/// [`windows`] and then [`bend_angles`] on the (smoothed) line: returns the capped
/// windows. On the M4F ρ is computed inside the backward sweep, while p_j and its window
/// are still in registers; elsewhere it is the two calls. The same values either way
/// (tested). With `LEAN`, a ρ that [`LowCut::below`] puts below τ_min is not computed:
/// the point gets τ_min itself (see [`LowCut`]); and on the M4F the sweep also finds the
/// nadir (`seed::nadir`), returned as `Some(nadir)` (`None`: not searched), and lists
/// the points whose ρ it computed (every point with ρ above τ_min among them) in
/// `exact`, highest index first: their number, `None` when not listed or when `exact`
/// was too short. The third value is the number of points without a neighbour on a side
/// (ρ = 0).
#[allow(clippy::too_many_arguments)]
pub(crate) fn windows_angles<M: Maths, const LEAN: bool>(
    x: &[f32],
    z: &[f32],
    d2: f32,
    s_off: &mut [u8],
    t_off: &mut [u8],
    rho: &mut [f32],
    cut: LowCut,
    exact: &mut [u16],
) -> (u32, Option<Option<usize>>, u32, Option<usize>) {
    if cfg!(target_pointer_width = "64") {
        let capped = windows(x, z, d2, s_off, t_off);
        let lone = bend_angles::<M, LEAN>(x, z, s_off, t_off, rho, cut);
        (capped, None, lone, None)
    } else {
        windows_sweeps_angles::<M, LEAN>(x, z, d2, s_off, t_off, rho, cut, exact)
    }
}

/// [`windows_sweeps`] with [`bend_angles`] in the backward sweep.
#[inline(never)] // its own registers (see `mark_irregular`)
#[cfg_attr(all(not(test), target_pointer_width = "64"), allow(dead_code))]
#[allow(clippy::neg_cmp_op_on_partial_ord)] // NaN counts as beyond, as in `beyond`
#[allow(clippy::too_many_arguments)]
fn windows_sweeps_angles<M: Maths, const LEAN: bool>(
    x: &[f32],
    z: &[f32],
    d2: f32,
    s_off: &mut [u8],
    t_off: &mut [u8],
    rho: &mut [f32],
    cut: LowCut,
    exact: &mut [u16],
) -> (u32, Option<Option<usize>>, u32, Option<usize>) {
    let n = x.len();
    let (z, s_off, t_off, rho) = (&z[..n], &mut s_off[..n], &mut t_off[..n], &mut rho[..n]);
    let mut capped = forward_sweep(x, z, d2, s_off);
    let mut t = n.saturating_sub(1);
    // The nadir (`seed::nadir`: smallest |x′| with z′ < 0, the first on a tie): walking
    // backwards, a tie replaces, so the lowest index wins. Compared as bit patterns: for
    // |x′| (sign cleared) they order as the floats do, and z′ < 0 is a pattern above
    // −0's. The points are finite here (the kernel set the others aside), so no |x′| has
    // the key u32::MAX that stands for "not below the scanner" and for "none yet"; a point
    // not below the scanner may take `nadir` while `best` is still u32::MAX, and the first
    // point below it takes it back.
    let (mut best, mut nadir) = (u32::MAX, usize::MAX);
    let mut lone = 0u32;
    let mut listed = 0usize;
    for j in (0..n).rev() {
        let (bx, bz) = back_walk(x, z, d2, j, &mut t, &mut capped);
        t_off[j] = (t - j) as u8;
        if LEAN {
            let below = z[j].to_bits() > 0x8000_0000;
            let key = if below {
                x[j].to_bits() & 0x7FFF_FFFF
            } else {
                u32::MAX
            };
            if key <= best {
                (best, nadir) = (key, j);
            }
        }
        let s = j - usize::from(s_off[j]);
        rho[j] = if s == j || t == j {
            lone += 1;
            0.0
        } else if LEAN {
            match lean_rho::<M>(x, z, s, j, t, (bx, bz), cut) {
                Some(r) => {
                    if let Some(e) = exact.get_mut(listed) {
                        *e = j as u16;
                    }
                    listed += 1;
                    r
                }
                None => cut.floor,
            }
        } else {
            bend_angle_deg_b::<M>(x, z, s, j, t, (bx, bz))
        };
    }
    (
        capped,
        LEAN.then_some((best != u32::MAX).then_some(nadir)),
        lone,
        (LEAN && listed <= exact.len()).then_some(listed),
    )
}

/// Where a lean ρ pass ([`windows_angles`] with `LEAN`) may skip the arctangent: the
/// bend angle is certainly below τ_min, so the exact value cannot make a peak nor stop
/// one (a peak's ρ is above τ_min and only larger values in its window count), and the
/// point gets τ_min itself. The test leaves a margin of 1° below τ_min, far more than the
/// arctangent's error (libm 2 ulp, micromath 0.16°) and the test's own rounding, so every
/// ρ within 1° of τ_min or above is computed exactly.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LowCut {
    /// tan(min(τ_min, 90°) − 1°).
    tan: f32,
    /// τ_min, degrees: the value a skipped point gets.
    floor: f32,
}

impl LowCut {
    /// A cut that skips nothing.
    pub(crate) const NONE: Self = Self {
        tan: f32::NEG_INFINITY,
        floor: 0.0,
    };

    /// The cut for τ_min = `tau_min_deg`; [`LowCut::NONE`] when τ_min ≤ 1° (no margin).
    #[allow(clippy::neg_cmp_op_on_partial_ord)] // NaN takes NONE too
    pub(crate) fn new(tau_min_deg: f32) -> Self {
        if !(tau_min_deg > 1.0) {
            return Self::NONE;
        }
        let a = (tau_min_deg.min(90.0) - 1.0) / RAD_TO_DEG;
        Self {
            tan: math::sin(a) / math::cos(a),
            floor: tau_min_deg,
        }
    }

    /// Whether atan2(`cs`, `d`) is certainly more than 1° below τ_min: d > 0 (the angle
    /// lies in (−90°, 90°)) and cs / d < tan(τ_min − 1°). NaN never is.
    #[inline(always)]
    fn below(&self, cs: f32, d: f32) -> bool {
        d > 0.0 && cs < d * self.tan
    }
}

/// Whether the d_b window [s, t] of a point is cut short by the end of its piece of line: the
/// point before s or after t is missing (the line's end) or lies across a gap (more than the
/// smoothing gap from the window's end; `gap2` is its square, 0 for no gaps). There the
/// window's arm ends where the returns end, not where d_b ends, and the bend angle measures
/// the direction to an arbitrary last return — at the edge of the shadow the vehicle's own
/// body casts, where the scanline runs along the travel direction and the projected points
/// pile up within millimetres, it reaches 90°.
pub(crate) fn window_cut(x: &[f32], z: &[f32], gap2: f32, s: usize, t: usize) -> bool {
    let n = x.len();
    let gap = |a: usize, b: usize| gap2 > 0.0 && dist2(x, z, a, b) > gap2;
    s == 0 || t + 1 >= n || gap(s - 1, s) || gap(t, t + 1)
}

/// Bit pattern of [`MAX_COORD_M`].
const MAX_COORD_BITS: u32 = 0x44FA_0000;
const _: () = assert!(MAX_COORD_M.to_bits() == MAX_COORD_BITS);

/// The signed bend angle at `i` with neighbours `s` and `t`, degrees in (−180, 180]
/// (the sign rule of docs/spec.md §2; see the module docs).
#[inline(always)]
pub(crate) fn bend_angle_deg<M: Maths>(x: &[f32], z: &[f32], s: usize, i: usize, t: usize) -> f32 {
    bend_angle_deg_b::<M>(x, z, s, i, t, (x[t] - x[i], z[t] - z[i]))
}

/// [`bend_angle_deg`] with b = p_t − p_i already computed (by the backward sweep).
#[inline(always)]
fn bend_angle_deg_b<M: Maths>(
    x: &[f32],
    z: &[f32],
    s: usize,
    i: usize,
    t: usize,
    b: (f32, f32),
) -> f32 {
    let (cs, d) = bend_cs_d(x, z, s, i, t, b);
    rho_deg::<M>(cs, d)
}

/// ρ at `i` with neighbours `s`, `t` and b = p_t − p_i, or with `LEAN` τ_min where `cut`
/// puts it certainly below (see [`LowCut`]). The sign rule makes the arctangent's first
/// argument ±c or −|c|, never more than |c|: so |c| < d·tan is tested first, before the
/// side of the chord is known, and ±c itself after.
#[inline(always)]
fn lean_or_exact<M: Maths, const LEAN: bool>(
    x: &[f32],
    z: &[f32],
    s: usize,
    i: usize,
    t: usize,
    b: (f32, f32),
    cut: LowCut,
) -> f32 {
    if LEAN {
        lean_rho::<M>(x, z, s, i, t, b, cut).unwrap_or(cut.floor)
    } else {
        bend_angle_deg_b::<M>(x, z, s, i, t, b)
    }
}

/// The lean half of [`lean_or_exact`]: ρ, or `None` where `cut` puts it certainly below
/// τ_min.
#[inline(always)]
fn lean_rho<M: Maths>(
    x: &[f32],
    z: &[f32],
    s: usize,
    i: usize,
    t: usize,
    b: (f32, f32),
    cut: LowCut,
) -> Option<f32> {
    let (ax, az) = (x[i] - x[s], z[i] - z[s]);
    let (bx, bz) = b;
    let (c, d) = (ax * bz - az * bx, ax * bx + az * bz);
    if cut.below(math::abs(c), d) {
        return None;
    }
    let (cs, d) = bend_cs_d(x, z, s, i, t, b);
    if cut.below(cs, d) {
        return None;
    }
    Some(rho_deg::<M>(cs, d))
}

/// The arguments of the bend angle's arctangent at `i` with neighbours `s` and `t` and
/// b = p_t − p_i: (c with the sign rule applied, d).
#[inline(always)]
fn bend_cs_d(x: &[f32], z: &[f32], s: usize, i: usize, t: usize, b: (f32, f32)) -> (f32, f32) {
    let (xs, zs, xi, zi, xt, zt) = (x[s], z[s], x[i], z[i], x[t], z[t]);
    let (ax, az) = (xi - xs, zi - zs);
    let (bx, bz) = b;
    let c = ax * bz - az * bx;
    let d = ax * bx + az * bz;
    // c = d = 0 (a neighbour coincides with p_i: no direction) gives ρ = 0: every
    // backend's atan2(±0, ±0) is +0 (see `math::Maths`).
    let side_o = xs * zt - zs * xt;
    let cs = if side_o > 0.0 {
        c
    } else if side_o < 0.0 {
        -c
    } else {
        -math::abs(c)
    };
    (cs, d)
}

/// The bend angle in degrees, (−180, 180], from [`bend_cs_d`]'s arguments.
#[inline(always)]
fn rho_deg<M: Maths>(cs: f32, d: f32) -> f32 {
    let r = M::atan2(cs, d) * RAD_TO_DEG;
    // (−180, 180]; also clamps an approximate backend's overshoot.
    if r <= -180.0 || r > 180.0 {
        180.0
    } else {
        r
    }
}

/// ρ on the (smoothed) line for every point, with the offsets from [`windows`]; 0 where a
/// side has no neighbour (returns how many). `LEAN` and `cut` as in [`windows_angles`].
#[inline(never)] // its own registers (see `mark_irregular`)
pub(crate) fn bend_angles<M: Maths, const LEAN: bool>(
    x: &[f32],
    z: &[f32],
    s_off: &[u8],
    t_off: &[u8],
    rho: &mut [f32],
    cut: LowCut,
) -> u32 {
    let n = x.len();
    let (z, s_off, t_off, rho) = (&z[..n], &s_off[..n], &t_off[..n], &mut rho[..n]);
    let mut lone = 0u32;
    for i in 0..n {
        let s = i - usize::from(s_off[i]);
        let t = i + usize::from(t_off[i]);
        rho[i] = if s == i || t == i {
            lone += 1;
            0.0
        } else {
            lean_or_exact::<M, LEAN>(x, z, s, i, t, (x[t] - x[i], z[t] - z[i]), cut)
        };
    }
    lone
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Selected;

    /// ρ at point 1 of a three-point line.
    fn rho3(p: [(f32, f32); 3]) -> f32 {
        let x = [p[0].0, p[1].0, p[2].0];
        let z = [p[0].1, p[1].1, p[2].1];
        bend_angle_deg::<Selected>(&x, &z, 0, 1, 2)
    }

    fn rev(p: [(f32, f32); 3]) -> [(f32, f32); 3] {
        [p[2], p[1], p[0]]
    }

    fn mirror(p: [(f32, f32); 3]) -> [(f32, f32); 3] {
        p.map(|(x, z)| (-x, z))
    }

    fn close(a: f32, b: f32, tol: f32) -> bool {
        (a - b).abs() <= tol
    }

    #[test]
    fn right_angle_step_toe_is_plus_90_top_is_minus_90() {
        // Scanner at (0, 0), road 2 m below, curb toe at x = 3, face 0.1 m high.
        let toe = [(2.9, -2.0), (3.0, -2.0), (3.0, -1.9)];
        let top = [(3.0, -2.0), (3.0, -1.9), (3.1, -1.9)];
        // Tolerance covers micromath (0.162°); libm is within 1e-4°.
        for p in [toe, rev(toe), mirror(toe), rev(mirror(toe))] {
            assert!(close(rho3(p), 90.0, 0.2), "toe {p:?}: {}", rho3(p));
        }
        for p in [top, rev(top), mirror(top), rev(mirror(top))] {
            assert!(close(rho3(p), -90.0, 0.2), "top {p:?}: {}", rho3(p));
        }
    }

    #[test]
    fn straight_line_is_zero_and_fold_back_is_180() {
        assert!(close(
            rho3([(1.0, -2.0), (1.1, -2.0), (1.2, -2.0)]),
            0.0,
            1e-3
        ));
        // Sloped straight line: still 0 (in either direction).
        let sl = [(1.0, -2.0), (1.1, -1.95), (1.2, -1.9)];
        assert!(close(rho3(sl), 0.0, 1e-3));
        assert!(close(rho3(rev(sl)), 0.0, 1e-3));
        // Folding back on itself: 180 (the range is (−180, 180]).
        let r = rho3([(1.0, -2.0), (1.1, -2.0), (1.0, -2.0)]);
        assert!(close(r, 180.0, 0.2), "{r}");
        // Coincident neighbour: no direction, 0.
        assert_eq!(rho3([(1.0, -2.0), (1.0, -2.0), (1.2, -2.0)]), 0.0);
    }

    #[test]
    fn forty_five_degree_bend_hand_checked() {
        // Road then a 45° ramp up away from the scanner: concave towards it, +45°.
        let p = [(2.0, -2.0), (2.1, -2.0), (2.2, -1.9)];
        assert!(close(rho3(p), 45.0, 0.2));
        assert!(close(rho3(rev(p)), 45.0, 0.2));
        // Crest of the ramp: convex, −45°.
        let q = [(2.0, -2.0), (2.1, -1.9), (2.2, -1.9)];
        assert!(close(rho3(q), -45.0, 0.2));
        assert!(close(rho3(mirror(rev(q))), -45.0, 0.2));
    }

    #[test]
    fn windows_on_a_uniform_line() {
        // Points every 0.03 m; d_b = 0.1 m reaches 3 points each side.
        let n = 20;
        let x: [f32; 20] = core::array::from_fn(|i| 1.0 + 0.03 * i as f32);
        let z = [-2.0f32; 20];
        let (mut s_off, mut t_off) = ([0u8; 20], [0u8; 20]);
        assert_eq!(windows(&x, &z, 0.01, &mut s_off, &mut t_off), 0);
        for i in 0..n {
            assert_eq!(usize::from(t_off[i]), 3.min(n - 1 - i), "t at {i}");
            assert_eq!(usize::from(s_off[i]), 3.min(i), "s at {i}");
        }
    }

    #[test]
    fn both_window_forms_agree() {
        // Noisy profiles with folds, runs of coincident points longer than MAX_SIDE,
        // gaps and non-finite points (a deterministic LCG).
        let mut r = 12345u64;
        let mut u = || {
            r = r
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((r >> 40) as f32) / ((1u64 << 24) as f32)
        };
        const N: usize = 900;
        for case in 0..24 {
            let mut x = [0f32; N];
            let mut z = [0f32; N];
            let n = [N, 1, 2, 3, 300, 599][case % 6];
            let mut px = 1.0f32;
            for i in 0..n {
                let kind = u();
                px += if case % 4 == 0 && (300..600).contains(&i) {
                    0.0 // a run of coincident points
                } else if kind < 0.05 {
                    -0.02 // fold back
                } else if kind < 0.08 {
                    0.3 // gap
                } else {
                    0.01 * u()
                };
                x[i] = px;
                z[i] = -2.0 + 0.02 * u();
                if case % 3 == 1 && kind > 0.99 {
                    x[i] = f32::NAN;
                }
                if case % 4 != 0 && case % 5 == 2 && kind > 0.985 {
                    z[i] += if kind > 0.995 { 3000.0 } else { 0.5 }; // out of range, spike
                }
            }
            for d2 in [0.0025f32, 0.01, 0.0] {
                let (mut s1, mut t1) = ([0u8; N], [0u8; N]);
                let (mut s2, mut t2) = ([0u8; N], [0u8; N]);
                let c1 = windows_interleaved(&x[..n], &z[..n], d2, &mut s1, &mut t1);
                let c2 = windows_sweeps(&x[..n], &z[..n], d2, &mut s2, &mut t2);
                assert_eq!(c1, c2, "case {case} d2 {d2}");
                assert_eq!(s1, s2, "case {case} d2 {d2}");
                assert_eq!(t1, t2, "case {case} d2 {d2}");
                // The fused judgement gives what the separate pass gives.
                let thr = Threshold::new(120.0);
                let mut st1 = [PointStatus::Kept; N];
                let (i1, n1) = mark_irregular(&x[..n], &z[..n], &s1, &t1, thr, &mut st1);
                let (mut s3, mut t3) = ([0u8; N], [0u8; N]);
                let mut st3 = [PointStatus::Kept; N];
                let r3 = windows_sweeps_marked::<false>(
                    &x[..n],
                    &z[..n],
                    d2,
                    &mut s3,
                    &mut t3,
                    thr,
                    &mut st3,
                );
                assert_eq!(r3, (c1, i1, n1), "case {case} d2 {d2}");
                assert_eq!((s3, t3), (s1, t1));
                assert_eq!(st3[..n], st1[..n], "case {case} d2 {d2}");
                // Without the range test, the same verdicts where every point is in range.
                let in_range = x[..n].iter().chain(&z[..n]).all(|v| v.abs() <= MAX_COORD_M);
                if in_range {
                    let mut st4 = [PointStatus::Kept; N];
                    let (mut s4, mut t4) = ([0u8; N], [0u8; N]);
                    let r4 = windows_sweeps_marked::<true>(
                        &x[..n],
                        &z[..n],
                        d2,
                        &mut s4,
                        &mut t4,
                        thr,
                        &mut st4,
                    );
                    assert_eq!((r4, st4), (r3, st3), "case {case} d2 {d2}");
                }
                // The fused angles give what the separate pass gives.
                let mut rho1 = [0f32; N];
                let lone1 = bend_angles::<Selected, false>(
                    &x[..n],
                    &z[..n],
                    &s1,
                    &t1,
                    &mut rho1[..n],
                    LowCut::NONE,
                );
                let (mut s4, mut t4, mut rho4) = ([0u8; N], [0u8; N], [0f32; N]);
                let (c4, _, lone4, _) = windows_sweeps_angles::<Selected, false>(
                    &x[..n],
                    &z[..n],
                    d2,
                    &mut s4,
                    &mut t4,
                    &mut rho4[..n],
                    LowCut::NONE,
                    &mut [],
                );
                assert_eq!(c4, c1, "case {case} d2 {d2}");
                assert_eq!(lone4, lone1, "case {case} d2 {d2}");
                assert_eq!((s4, t4), (s1, t1));
                for i in 0..n {
                    let (a, b) = (rho1[i], rho4[i]);
                    assert!(
                        a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()),
                        "case {case} d2 {d2} i {i}: {a} {b}"
                    );
                }
                // The lean pass: the same ρ wherever it computes one, τ_min where it
                // skips one more than 1° below τ_min; both forms alike.
                let cut = LowCut::new(30.0);
                let mut rho5 = [0f32; N];
                bend_angles::<Selected, true>(&x[..n], &z[..n], &s1, &t1, &mut rho5[..n], cut);
                let (mut s6, mut t6, mut rho6) = ([0u8; N], [0u8; N], [0f32; N]);
                let mut exact = [0u16; N];
                let (_, nd, _, listed) = windows_sweeps_angles::<Selected, true>(
                    &x[..n],
                    &z[..n],
                    d2,
                    &mut s6,
                    &mut t6,
                    &mut rho6[..n],
                    cut,
                    &mut exact,
                );
                // The list holds every point with ρ above τ_min, highest index first.
                let listed = &exact[..listed.expect("a list as long as the line")];
                assert!(listed.windows(2).all(|w| w[0] > w[1]), "case {case}");
                for (i, r) in rho6[..n].iter().enumerate() {
                    if *r > cut.floor {
                        assert!(listed.contains(&(i as u16)), "case {case} i {i}");
                    }
                }
                // A list too short says so.
                if listed.len() > 1 {
                    let mut short = [0u16; 1];
                    let (mut s7, mut t7, mut rho7) = ([0u8; N], [0u8; N], [0f32; N]);
                    let r = windows_sweeps_angles::<Selected, true>(
                        &x[..n],
                        &z[..n],
                        d2,
                        &mut s7,
                        &mut t7,
                        &mut rho7[..n],
                        cut,
                        &mut short,
                    );
                    assert_eq!(r.3, None, "case {case}");
                }
                if case % 3 != 1 && !(case % 4 != 0 && case % 5 == 2) {
                    // Finite points in range only: the sweep's nadir is `seed::nadir`'s.
                    assert_eq!(nd, Some(super::super::seed::nadir(&x[..n], &z[..n])));
                }
                // A skipped point's exact angle is below 29°; the backend's own ρ of it
                // is within the arctangent's error of that (micromath 0.162°).
                let below = match crate::math::BACKEND {
                    crate::math::Backend::Micromath => 29.0 + 0.162,
                    _ => 29.0,
                };
                for i in 0..n {
                    let (a, b, c) = (rho1[i], rho5[i], rho6[i]);
                    assert!(b.to_bits() == c.to_bits() || (b.is_nan() && c.is_nan()));
                    let same = a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan());
                    assert!(
                        same || (b == 30.0 && a < below),
                        "case {case} d2 {d2} i {i}: {a} {b}"
                    );
                }
                if case % 3 == 1 && n == N {
                    assert!(n1 > 0, "NaN points are marked");
                }
                if case % 4 == 0 && n == N && d2 > 0.0 {
                    assert!(c1 > 0, "the run of coincident points caps windows");
                }
            }
        }
    }

    /// The test that skips c where d decides is the full test, for any threshold and any
    /// a, b (zeros of both signs, infinities and NaN included).
    #[test]
    fn irregular_test_skipping_c_is_the_full_test() {
        let mut r = 99u64;
        let mut u = || {
            r = r
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((r >> 40) as f32) / ((1u64 << 24) as f32) - 0.5
        };
        let special = [
            0.0f32,
            -0.0,
            1e-30,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
        ];
        for deg in [1.0f32, 45.0, 89.9, 90.0, 90.1, 120.0, 179.0, 180.0] {
            let thr = Threshold::new(deg);
            let full = |ax: f32, az: f32, bx: f32, bz: f32| {
                let c = ax * bz - az * bx;
                let d = ax * bx + az * bz;
                if math::abs(c) * thr.cos - d * thr.sin > 0.0 {
                    PointStatus::Irregular
                } else {
                    PointStatus::Kept
                }
            };
            for k in 0..20_000 {
                let mut v = [u(), u(), u(), u()];
                if k % 7 == 0 {
                    v[k % 4] = special[k / 7 % special.len()];
                }
                if k % 11 == 0 {
                    v[(k + 1) % 4] = special[k / 11 % special.len()];
                }
                let [ax, az, bx, bz] = v;
                assert_eq!(
                    irregular_test(ax, az, bx, bz, thr),
                    full(ax, az, bx, bz),
                    "{deg} {v:?}"
                );
            }
        }
    }

    #[test]
    fn windows_are_capped() {
        // 600 coincident points: every window would span the whole line.
        let x = [1.0f32; 600];
        let z = [-2.0f32; 600];
        let (mut s_off, mut t_off) = ([0u8; 600], [0u8; 600]);
        let capped = windows(&x, &z, 0.01, &mut s_off, &mut t_off);
        assert_eq!(usize::from(t_off[0]), MAX_SIDE);
        assert_eq!(usize::from(t_off[599 - 10]), 10);
        assert_eq!(usize::from(s_off[400]), MAX_SIDE);
        assert_eq!(usize::from(s_off[10]), 10);
        // Points 0..=599-256 have more than MAX_SIDE points after them, points 256..=599
        // more than MAX_SIDE before them.
        assert_eq!(capped as usize, 2 * (600 - MAX_SIDE - 1));
    }

    #[test]
    fn irregular_test_matches_the_angle() {
        // A spike on a flat road: |ρ| at the spike is 180 − 2·atan(0.1/0.05)... computed
        // directly: a = (0.05, 0.1), b = (0.05, −0.1) → angle between = 2·atan2(0.1, 0.05)
        // = 126.87°.
        let x = [1.0f32, 1.05, 1.1];
        let z = [-2.0f32, -1.9, -2.0];
        let (s_off, t_off) = ([0u8, 1, 1], [1u8, 1, 0]);
        let mut st = [PointStatus::Kept; 3];
        for (thr, expect) in [(120.0, true), (126.0, true), (127.5, false), (150.0, false)] {
            let (irr, nf) = mark_irregular(&x, &z, &s_off, &t_off, Threshold::new(thr), &mut st);
            assert_eq!(nf, 0);
            assert_eq!(irr == 1, expect, "threshold {thr}");
            assert_eq!(st[1] == PointStatus::Irregular, expect);
            // End points have no neighbour on one side: never irregular.
            assert_eq!(st[0], PointStatus::Kept);
            assert_eq!(st[2], PointStatus::Kept);
        }
        let r = bend_angle_deg::<Selected>(&x, &z, 0, 1, 2);
        assert!(close(r, -126.87, 0.2), "{r}");
    }

    #[test]
    fn non_finite_points_are_marked_and_do_not_hang() {
        let x = [1.0f32, f32::NAN, 1.1, f32::INFINITY, 1.2];
        let z = [-2.0f32, -2.0, -2.0, -2.0, f32::NEG_INFINITY];
        let (mut s_off, mut t_off) = ([0u8; 5], [0u8; 5]);
        windows(&x, &z, 0.01, &mut s_off, &mut t_off);
        // The finite points 0 and 2 are 0.1 apart, beyond d_b = 0.1 (squared: 0.01 vs the
        // rounded 0.1f32²): no one has a neighbour across the NaN.
        assert_eq!((s_off, t_off), ([0; 5], [0; 5]));
        let mut st = [PointStatus::Kept; 5];
        let (_, nf) = mark_irregular(&x, &z, &s_off, &t_off, Threshold::new(120.0), &mut st);
        assert_eq!(nf, 3);
        assert_eq!(st[1], PointStatus::NonFinite);
        assert_eq!(st[3], PointStatus::NonFinite);
        assert_eq!(st[4], PointStatus::NonFinite);
    }
}
