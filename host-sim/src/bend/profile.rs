//! The curb toe on a virtual profile across the direction of travel, gathered from the
//! points of several scanlines, where the per-scanline bend angle sees no toe.

use super::grid::PointGrid;
use super::params::BendParams;
use super::BendInput;
use crate::replay::PointStatus;

/// Points a virtual profile may use: kept by the core, with or without a bend angle.
pub(super) fn usable(input: &BendInput, i: usize) -> bool {
    matches!(
        input.status[i],
        Some(PointStatus::Kept | PointStatus::NoNeighbour)
    )
}

/// A curb toe found on a virtual profile.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProfileToe {
    /// Toe position: horizontal on the profile line, height of the road beside it.
    pub xyz: [f64; 3],
    /// Height step from the road to the curb top, metres.
    pub step_m: f64,
}

/// Finds the curb toe on a *virtual profile*: the points (of any scanline) within
/// `half_l` of the line through `centre` across the horizontal unit
/// direction `along`, taken as one cross-section with `across` running from the road
/// (negative) to the curb side (positive, `up` = +1 for the left of `along`, −1 for the
/// right).
///
/// The per-scanline bend angle (Honma et al. §2.3) sees a curb only where the scanline
/// crosses it; where a curb turns to run along the scanlines (the side streets of
/// intersections, the far part of corner arcs) every scanline runs beside the toe and ρ
/// stays flat, while the height step is still there *between* scanlines. The profile
/// gathers it from several scanlines: the points sorted by `across` are split in two at
/// the place that minimises the squared deviation from two levels (a least-squares step
/// fit), and the toe is half-way between the last point of the low part and the first of
/// the high part. Each part, without the 40 mm next to the toe (the face), is then fitted
/// by a line, and the toe is accepted only as a curb: a step of at least
/// `profile_min_step_m` (and under the search half-height) between the two lines at the
/// toe, both parts ground-like (slopes under `profile_max_slope`, so a curb cut's ramp is
/// no step), the lines' RMS under a quarter of the step, ground within 0.15 m on both
/// sides of the toe, and the toe within `profile_half_width_m` − 0.15 m of the centre.
pub fn profile_toe(
    input: &BendInput,
    grid: &PointGrid,
    centre: [f64; 3],
    along: [f64; 2],
    up: f64,
    half_l: f64,
    params: &BendParams,
) -> Option<ProfileToe> {
    let half_w = params.profile_half_width_m;
    let n = [-along[1] * up, along[0] * up];
    // (across, z, along) per point.
    let mut prof: Vec<(f64, f64, f64)> = Vec::new();
    grid.for_each_within(
        input.x,
        input.y,
        centre[0],
        centre[1],
        half_w.hypot(half_l),
        |i| {
            if !usable(input, i) || (input.z[i] - centre[2]).abs() > params.search_half_height_m {
                return;
            }
            let d = [input.x[i] - centre[0], input.y[i] - centre[1]];
            let a = d[0] * along[0] + d[1] * along[1];
            let c = d[0] * n[0] + d[1] * n[1];
            if a.abs() <= half_l && c.abs() <= half_w {
                prof.push((c, input.z[i], a));
            }
        },
    );
    const MIN_SIDE: usize = 4;
    if prof.len() < 2 * MIN_SIDE {
        return None;
    }
    prof.sort_by(|p, q| p.0.total_cmp(&q.0).then(p.1.total_cmp(&q.1)));
    // Prefix sums of 1, c, c², z, c·z, z² (heights relative to the first point, for
    // precision): a least-squares line over any run of the sorted points in O(1).
    let z0 = prof[0].1;
    let m = prof.len();
    let mut acc = vec![[0.0f64; 6]; m + 1];
    for (k, p) in prof.iter().enumerate() {
        let (c, z) = (p.0, p.1 - z0);
        let t = [1.0, c, c * c, z, c * z, z * z];
        for j in 0..6 {
            acc[k + 1][j] = acc[k][j] + t[j];
        }
    }
    // Line z = a + b·c over prof[lo..hi]: (a, b, sse). Slope 0 when the run has a single
    // position (one scanline beside a side street's curb).
    let line = |lo: usize, hi: usize| -> (f64, f64, f64) {
        let s: Vec<f64> = (0..6).map(|j| acc[hi][j] - acc[lo][j]).collect();
        let (n, sc, scc, sz, scz, szz) = (s[0], s[1], s[2], s[3], s[4], s[5]);
        let den = n * scc - sc * sc;
        let b = if den > 1e-9 * n * n {
            (n * scz - sc * sz) / den
        } else {
            0.0
        };
        let a = (sz - b * sc) / n;
        // Σ(z − a − b·c)² expanded.
        let sse = szz - 2.0 * a * sz - 2.0 * b * scz + n * a * a + 2.0 * a * b * sc + b * b * scc;
        (a, b, sse.max(0.0))
    };
    // Σ(z − mean)² over prof[lo..hi].
    let level_sse = |lo: usize, hi: usize| {
        let (n, sz, szz) = (
            (hi - lo) as f64,
            acc[hi][3] - acc[lo][3],
            acc[hi][5] - acc[lo][5],
        );
        (szz - sz * sz / n).max(0.0)
    };
    // Best split k: prof[..k] road, prof[k..] curb, each part one level. Points on the curb
    // face go to the nearer level, so the split falls at the face's middle.
    let mut best: Option<(f64, usize)> = None;
    for k in MIN_SIDE..=m - MIN_SIDE {
        if prof[k].0 - prof[k - 1].0 <= 0.0 {
            continue; // a split must fall between two distinct positions
        }
        let e = level_sse(0, k) + level_sse(k, m);
        if best.is_none_or(|(be, _)| e < be) {
            best = Some((e, k));
        }
    }
    let (_, k) = best?;
    let toe = 0.5 * (prof[k - 1].0 + prof[k].0);
    const NEAR_M: f64 = 0.15;
    if prof[k].0 - prof[k - 1].0 > 2.0 * NEAR_M || toe.abs() > half_w - NEAR_M {
        return None;
    }
    // The two parts without the face (FACE_M either side of the toe), each fitted by a
    // line (road cross slope, sidewalk fall).
    const FACE_M: f64 = 0.04;
    let lo = prof.partition_point(|p| p.0 < toe - FACE_M);
    let hi = prof.partition_point(|p| p.0 <= toe + FACE_M);
    if lo < MIN_SIDE || m - hi < MIN_SIDE {
        return None;
    }
    if prof[lo - 1].0 < toe - NEAR_M || prof[hi].0 > toe + NEAR_M {
        return None; // no ground seen right beside the toe
    }
    let (la, lb, le) = line(0, lo);
    let (ha, hb, he) = line(hi, m);
    let step = (ha + hb * toe) - (la + lb * toe);
    let rms = ((le + he) / (lo + m - hi) as f64).sqrt();
    // Both parts must be ground, not a ramp or a car's flank.
    let max_slope = params.profile_max_slope;
    if lb.abs() > max_slope || hb.abs() > max_slope {
        return None;
    }
    if step < params.profile_min_step_m || step > params.search_half_height_m {
        return None;
    }
    if rms > 0.25 * step {
        return None;
    }
    // The road height at the toe: the low points within NEAR_M of it.
    let near_low: Vec<f64> = prof[..k]
        .iter()
        .filter(|p| toe - p.0 <= NEAR_M)
        .map(|p| p.1)
        .collect();
    let z = near_low.iter().sum::<f64>() / near_low.len().max(1) as f64;
    // Along the profile the toe sits among the points beside it, not at the centre: where
    // the scanned area ends, the centre lies past the last scanline.
    let near: Vec<f64> = prof
        .iter()
        .filter(|p| (p.0 - toe).abs() <= NEAR_M)
        .map(|p| p.2)
        .collect();
    let a = near.iter().sum::<f64>() / near.len().max(1) as f64;
    Some(ProfileToe {
        xyz: [
            centre[0] + a * along[0] + toe * n[0],
            centre[1] + a * along[1] + toe * n[1],
            z,
        ],
        step_m: step,
    })
}
