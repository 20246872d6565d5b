//! Bend angle ρ (Honma et al. §2.3, SPEC §2) and the removal of irregular points (§2.4).
//!
//! # Neighbours: one two-index sweep per side
//!
//! SPEC §2: walk outward from i while points stay within d_b of p_i; s and t are the last
//! points reached. The kernel finds them with monotone pointers, O(n) per line:
//!
//! - left, a forward sweep: s(i) is the first index j ≥ max(s(i−1), i − [`MAX_SIDE`]) with
//!   |p_j − p_i| ≤ d_b;
//! - right, the mirror image as a backward sweep: t(i) is the last index
//!   j ≤ min(t(i+1), i + [`MAX_SIDE`]) with |p_j − p_i| ≤ d_b.
//!
//! Wherever the distance from p_i grows along the line away from i (a profile that does not
//! fold back on itself within d_b) this is exactly the SPEC walk; where noise folds the line
//! back (a return nearer to p_i than its predecessor), the sweep may reach one point past
//! the excursion. The two rules are mirror images, so reversing the line (the other
//! rotation direction) swaps s and t exactly. [`MAX_SIDE`] bounds the work and the
//! peak search's deque for degenerate input (hundreds of returns on one spot); real lines
//! need at most d_b / spacing ≈ 30 points per side.
//!
//! Distances are compared squared (no square root).
//!
//! # Sign rule (SPEC §2)
//!
//! With a = p_i − p_s, b = p_t − p_i, c = a × b and d = a · b, the unsigned angle between
//! s→i and i→t is atan2(|c|, d). ρ is positive when i and the scanner (0, 0) lie on
//! opposite sides of the chord s–t. Since a × b = −(t − s) × (i − s), i's side of the chord
//! has the sign of −c, and the scanner's side is the sign of s × t; so ρ = atan2(c · sgn(s × t), d).
//! A scanner exactly on the chord (s × t = 0) counts as "not opposite" (ρ ≤ 0). Nothing
//! here depends on the order of s and t, so the sign does not depend on the rotation.

use super::PointStatus;
use crate::math::{self, Backend};

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

/// Backward sweep: stores t(i) − i in `t_off[i]` for every point; returns how many windows
/// stopped at [`MAX_SIDE`] with the next point still within d_b.
pub(crate) fn right_windows(x: &[f32], z: &[f32], d2: f32, t_off: &mut [u8]) -> u32 {
    let n = x.len();
    let (z, t_off) = (&z[..n], &mut t_off[..n]);
    let mut capped = 0u32;
    let mut t = n.saturating_sub(1);
    for i in (0..n).rev() {
        let hi = i + MAX_SIDE;
        if t > hi {
            t = hi;
            if !beyond(x, z, t + 1, i, d2) {
                capped += 1;
            }
        }
        while t > i && beyond(x, z, t, i, d2) {
            t -= 1;
        }
        t_off[i] = (t - i) as u8;
    }
    capped
}

/// The forward sweep's left neighbour of `i`, given the previous one.
#[inline(always)]
pub(crate) fn left_neighbour(x: &[f32], z: &[f32], d2: f32, s_prev: usize, i: usize) -> usize {
    let mut s = s_prev.max(i.saturating_sub(MAX_SIDE));
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
}

impl Threshold {
    /// The threshold `deg` degrees (0 < deg ≤ 180).
    pub(crate) fn new(deg: f32) -> Self {
        let r = deg / RAD_TO_DEG;
        Self {
            cos: math::cos(r),
            sin: math::sin(r),
        }
    }
}

/// §2.4 on the raw line: marks each point [`PointStatus::Irregular`] when |ρ| exceeds the
/// threshold, [`PointStatus::NonFinite`] when a coordinate is NaN or infinite, and
/// provisionally [`PointStatus::Kept`] otherwise (also when it has no neighbour on one side:
/// no ρ, nothing to judge). A point with no neighbour on *either* side is judged with its
/// two adjacent points as s and t: a lone spike taller than d_b would otherwise survive
/// §2.4 and cut the smoothed line in three. `t_off` comes from [`right_windows`]. Returns the number of
/// irregular and non-finite points.
///
/// No atan2: with φ = atan2(|c|, d) ∈ [0, π] and θ the threshold, φ > θ ⟺ sin(φ − θ) > 0
/// ⟺ |c|·cos θ − d·sin θ > 0 (both sides scaled by |a||b| > 0).
pub(crate) fn mark_irregular(
    x: &[f32],
    z: &[f32],
    t_off: &[u8],
    d2: f32,
    thr: Threshold,
    status: &mut [PointStatus],
) -> (u32, u32) {
    let n = x.len();
    let (z, t_off, status) = (&z[..n], &t_off[..n], &mut status[..n]);
    let (mut irregular, mut non_finite) = (0u32, 0u32);
    let mut s = 0;
    for i in 0..n {
        s = left_neighbour(x, z, d2, s, i);
        let t = i + usize::from(t_off[i]);
        let (xi, zi) = (x[i], z[i]);
        if !(xi.is_finite() && zi.is_finite()) {
            status[i] = PointStatus::NonFinite;
            non_finite += 1;
            continue;
        }
        // An isolated point (nothing within d_b on either side: a spike taller than d_b)
        // is judged by its adjacent points instead, or it could never be removed.
        let (sj, tj) = if s == i && t == i && i > 0 && i + 1 < n {
            (i - 1, i + 1)
        } else {
            (s, t)
        };
        let (ax, az) = (xi - x[sj], zi - z[sj]);
        let (bx, bz) = (x[tj] - xi, z[tj] - zi);
        let c = ax * bz - az * bx;
        let d = ax * bx + az * bz;
        // With s == i or t == i, c = d = 0 and the test is false: kept.
        if math::abs(c) * thr.cos - d * thr.sin > 0.0 {
            status[i] = PointStatus::Irregular;
            irregular += 1;
        } else {
            status[i] = PointStatus::Kept;
        }
    }
    (irregular, non_finite)
}

/// The signed bend angle at `i` with neighbours `s` and `t`, degrees in (−180, 180]
/// (SPEC §2 sign rule; see the module docs).
#[inline(always)]
pub(crate) fn bend_angle_deg<M: Backend>(
    x: &[f32],
    z: &[f32],
    s: usize,
    i: usize,
    t: usize,
) -> f32 {
    let (xs, zs, xi, zi, xt, zt) = (x[s], z[s], x[i], z[i], x[t], z[t]);
    let (ax, az) = (xi - xs, zi - zs);
    let (bx, bz) = (xt - xi, zt - zi);
    let c = ax * bz - az * bx;
    let d = ax * bx + az * bz;
    if c == 0.0 && d == 0.0 {
        // A neighbour coincides with p_i: no direction, no bend.
        return 0.0;
    }
    let side_o = xs * zt - zs * xt;
    let cs = if side_o > 0.0 {
        c
    } else if side_o < 0.0 {
        -c
    } else {
        -math::abs(c)
    };
    let r = M::atan2(cs, d) * RAD_TO_DEG;
    // (−180, 180]; also clamps an approximate backend's overshoot.
    if r <= -180.0 || r > 180.0 {
        180.0
    } else {
        r
    }
}

/// ρ on the (smoothed) line for every point, with `t_off` from [`right_windows`]; 0 where a
/// side has no neighbour.
pub(crate) fn bend_angles<M: Backend>(
    x: &[f32],
    z: &[f32],
    t_off: &[u8],
    d2: f32,
    rho: &mut [f32],
) {
    let n = x.len();
    let (z, t_off, rho) = (&z[..n], &t_off[..n], &mut rho[..n]);
    let mut s = 0;
    for i in 0..n {
        s = left_neighbour(x, z, d2, s, i);
        let t = i + usize::from(t_off[i]);
        rho[i] = if s == i || t == i {
            0.0
        } else {
            bend_angle_deg::<M>(x, z, s, i, t)
        };
    }
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
    #[allow(clippy::needless_range_loop)]
    fn windows_on_a_uniform_line() {
        // Points every 0.03 m; d_b = 0.1 m reaches 3 points each side.
        let n = 20;
        let x: [f32; 20] = core::array::from_fn(|i| 1.0 + 0.03 * i as f32);
        let z = [-2.0f32; 20];
        let mut t_off = [0u8; 20];
        assert_eq!(right_windows(&x, &z, 0.01, &mut t_off), 0);
        for i in 0..n {
            assert_eq!(usize::from(t_off[i]), 3.min(n - 1 - i), "t at {i}");
        }
        let mut s = 0;
        for i in 0..n {
            s = left_neighbour(&x, &z, 0.01, s, i);
            assert_eq!(s, i.saturating_sub(3), "s at {i}");
        }
    }

    #[test]
    fn windows_are_capped() {
        // 600 coincident points: every window would span the whole line.
        let x = [1.0f32; 600];
        let z = [-2.0f32; 600];
        let mut t_off = [0u8; 600];
        let capped = right_windows(&x, &z, 0.01, &mut t_off);
        assert_eq!(usize::from(t_off[0]), MAX_SIDE);
        assert_eq!(usize::from(t_off[599 - 10]), 10);
        // Points 0..=599-256 have more than MAX_SIDE points after them.
        assert_eq!(capped as usize, 600 - MAX_SIDE - 1);
        let s = left_neighbour(&x, &z, 0.01, 0, 400);
        assert_eq!(s, 400 - MAX_SIDE);
    }

    #[test]
    fn irregular_test_matches_the_angle() {
        // A spike on a flat road: |ρ| at the spike is 180 − 2·atan(0.1/0.05)... computed
        // directly: a = (0.05, 0.1), b = (0.05, −0.1) → angle between = 2·atan2(0.1, 0.05)
        // = 126.87°.
        let x = [1.0f32, 1.05, 1.1];
        let z = [-2.0f32, -1.9, -2.0];
        let t_off = [1u8, 1, 0];
        let mut st = [PointStatus::Kept; 3];
        for (thr, expect) in [(120.0, true), (126.0, true), (127.5, false), (150.0, false)] {
            let (irr, nf) = mark_irregular(&x, &z, &t_off, 1.0, Threshold::new(thr), &mut st);
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
        let mut t_off = [0u8; 5];
        right_windows(&x, &z, 0.01, &mut t_off);
        let mut st = [PointStatus::Kept; 5];
        let (_, nf) = mark_irregular(&x, &z, &t_off, 0.01, Threshold::new(120.0), &mut st);
        assert_eq!(nf, 3);
        assert_eq!(st[1], PointStatus::NonFinite);
        assert_eq!(st[3], PointStatus::NonFinite);
        assert_eq!(st[4], PointStatus::NonFinite);
    }
}
