//! The curb toe on a virtual profile whose scanlines run along the curb: a step between
//! scanline levels, for the side streets of intersections where [`profile_toe`] sees too
//! few points spread across.
//!
//! Where a curb runs nearly along the scanlines (a side street's curb, the far part of a
//! corner arc) a profile across it holds a few scanlines, each at one offset across: the
//! ones on the road at road level, the ones on the sidewalk about a curb height higher,
//! perhaps one on the face between them. [`profile_toe`] fits two lines to the points and
//! asks for points right beside the toe on both sides and flat parts; with the points
//! bunched at a few offsets one scanline on the face tilts a part, or the nearest scanline
//! lies more than 0.15 m from the toe, and it sees no toe. Here each scanline is one
//! level: the scanlines sorted by offset are split into a low and a high group (one
//! scanline between them may be on the face), each group's levels are fitted by a line
//! against offset, and the toe is taken half-way between the last low and the first high
//! scanline.
//!
//! [`profile_toe`]: super::profile::profile_toe

use super::grid::PointGrid;
use super::params::BendParams;
use super::profile::{for_each_on_profile, ProfileToe};
use super::BendInput;

/// Fewest points of a scanline on the profile for it to give a level.
const MIN_LINE_POINTS: usize = 2;

/// Fewest scanlines on the road side and on the curb side of the step.
const MIN_SIDE_LINES: usize = 2;

/// Widest spread across the profile of one scanline's points, metres: a scanline that
/// spreads wider crosses the curb line, and its points are the ordinary profile's case.
const MAX_LINE_SPREAD_M: f64 = 0.12;

/// Farthest apart the last road scanline and the first curb scanline may lie, metres:
/// wider than the ordinary profile's 0.3 m, for the curb's shadow on the road when the
/// scanner looks at the curb from behind (0.3 m kept the step on no tuning street's side
/// street; docs/results.md).
const MAX_STEP_GAP_M: f64 = 0.5;

/// One scanline on the profile: its points' mean offset across, mean height, mean
/// position along, count, their spread across and their RMS about the mean height.
#[derive(Clone, Copy, Debug)]
struct Level {
    c: f64,
    z: f64,
    a: f64,
    n: usize,
    spread: f64,
    rms: f64,
}

/// Weighted least-squares line z = p + q·c through levels (weights: point counts), with
/// the largest deviation of a level from it. Slope 0 for a single offset.
fn fit(levels: &[Level]) -> (f64, f64, f64) {
    let (mut w, mut sc, mut sz, mut scc, mut scz) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for l in levels {
        let k = l.n as f64;
        w += k;
        sc += k * l.c;
        sz += k * l.z;
        scc += k * l.c * l.c;
        scz += k * l.c * l.z;
    }
    let den = w * scc - sc * sc;
    let q = if den > 1e-9 * w * w {
        (w * scz - sc * sz) / den
    } else {
        0.0
    };
    let p = (sz - q * sc) / w;
    let dev = levels
        .iter()
        .map(|l| (l.z - p - q * l.c).abs())
        .fold(0.0, f64::max);
    (p, q, dev)
}

/// The levels of the scanlines on a virtual profile (see [`sparse_toe`]), sorted by offset.
/// `None` when a scanline spreads across the profile (not the sparse case).
fn levels(
    input: &BendInput,
    grid: &PointGrid,
    centre: [f64; 3],
    along: [f64; 2],
    up: f64,
    half_l: f64,
    params: &BendParams,
) -> Option<Vec<Level>> {
    let mut pts: Vec<(u32, f64, f64, f64)> = Vec::new();
    for_each_on_profile(input, grid, centre, along, up, half_l, params, |i, c, a| {
        pts.push((input.scanline[i], c, input.z[i], a));
    });
    pts.sort_by_key(|p| p.0);
    let mut out = Vec::new();
    for run in pts.chunk_by(|p, q| p.0 == q.0) {
        if run.len() < MIN_LINE_POINTS {
            continue;
        }
        let n = run.len() as f64;
        let c = run.iter().map(|p| p.1).sum::<f64>() / n;
        let z = run.iter().map(|p| p.2).sum::<f64>() / n;
        let a = run.iter().map(|p| p.3).sum::<f64>() / n;
        let (lo, hi) = run
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p.1), hi.max(p.1))
            });
        let rms = (run.iter().map(|p| (p.2 - z).powi(2)).sum::<f64>() / n).sqrt();
        let spread = hi - lo;
        if spread > MAX_LINE_SPREAD_M {
            return None;
        }
        out.push(Level {
            c,
            z,
            a,
            n: run.len(),
            spread,
            rms,
        });
    }
    out.sort_by(|p, q| p.c.total_cmp(&q.c));
    Some(out)
}

/// Finds the curb toe on a virtual profile (the points of [`profile_toe`]'s profile, with
/// `across` from the road, negative, to the curb side) as a step between scanline levels.
/// The scanlines sorted by offset are split where two lines, one through the road
/// scanlines' levels and one through the curb scanlines' (one scanline between them may
/// be left out: the face), fit best; the toe is accepted when each side has at least
/// [`MIN_SIDE_LINES`] scanlines, both lines are ground-like (slopes under
/// `profile_max_slope`), the step between them at the toe is at least
/// `profile_min_step_m` (and under the search half-height), every level and every
/// scanline's own points lie within a quarter of the step of their side's line, the road
/// and curb scanlines beside the step are at most [`MAX_STEP_GAP_M`] apart, and the toe
/// lies within `profile_half_width_m` − 0.15 m of the centre. Meant for where
/// [`profile_toe`] finds nothing: each scanline at one offset is the case it cannot take.
///
/// [`profile_toe`]: super::profile::profile_toe
pub fn sparse_toe(
    input: &BendInput,
    grid: &PointGrid,
    centre: [f64; 3],
    along: [f64; 2],
    up: f64,
    half_l: f64,
    params: &BendParams,
) -> Option<ProfileToe> {
    let lv = levels(input, grid, centre, along, up, half_l, params)?;
    let m = lv.len();
    if m < 2 * MIN_SIDE_LINES {
        return None;
    }
    // Best split: lv[..k] road, lv[k + skip..] curb, with `skip` 0 or 1 (a face line).
    let mut best: Option<(f64, usize, usize)> = None;
    for skip in 0..=1 {
        for k in MIN_SIDE_LINES..=m - MIN_SIDE_LINES - skip {
            let (lo, hi) = (&lv[..k], &lv[k + skip..]);
            let ((lp, lq, _), (hp, hq, _)) = (fit(lo), fit(hi));
            if skip == 1 {
                // Left out only as a face: its level between the two, a quarter of the
                // step from each (leaving out a scanline always fits the rest better).
                let f = lv[k];
                let (zl, zh) = (lp + lq * f.c, hp + hq * f.c);
                let q = 0.25 * (zh - zl);
                if !(q > 0.0 && f.z >= zl + q && f.z <= zh - q) {
                    continue;
                }
            }
            let sse = |s: &[Level], p: f64, q: f64| {
                s.iter()
                    .map(|l| l.n as f64 * (l.z - p - q * l.c).powi(2))
                    .sum::<f64>()
            };
            let e = sse(lo, lp, lq) + sse(hi, hp, hq);
            if best.is_none_or(|(be, _, _)| e < be) {
                best = Some((e, k, skip));
            }
        }
    }
    let (_, k, skip) = best?;
    let (lo, hi) = (&lv[..k], &lv[k + skip..]);
    let (last_low, first_high) = (lo[k - 1], hi[0]);
    if first_high.c - last_low.c > MAX_STEP_GAP_M {
        return None;
    }
    // Half-way between the near edges of the two scanlines beside the step: where the
    // curb hides the road right before it, the road scanline lies short of the toe, and
    // where the scanner sees the face the curb scanline lies just past it.
    let toe = 0.5 * (last_low.c + 0.5 * last_low.spread + first_high.c - 0.5 * first_high.spread);
    const NEAR_M: f64 = 0.15;
    if toe.abs() > params.profile_half_width_m - NEAR_M {
        return None;
    }
    let (lp, lq, ldev) = fit(lo);
    let (hp, hq, hdev) = fit(hi);
    let max_slope = params.profile_max_slope;
    if lq.abs() > max_slope || hq.abs() > max_slope {
        return None;
    }
    let road = lp + lq * toe;
    let step = hp + hq * toe - road;
    if step < params.profile_min_step_m || step > params.search_half_height_m {
        return None;
    }
    let tol = 0.25 * step;
    if ldev.max(hdev) > tol || lo.iter().chain(hi).any(|l| l.rms > tol) {
        return None;
    }
    let a = 0.5 * (last_low.a + first_high.a);
    let n = [-along[1] * up, along[0] * up];
    Some(ProfileToe {
        xyz: [
            centre[0] + a * along[0] + toe * n[0],
            centre[1] + a * along[1] + toe * n[1],
            road,
        ],
        step_m: step,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::trajectory::Trajectory;
    use crate::replay::PointStatus;

    /// A few scanlines along a curb at x = 0 (road x < 0 at z 0, sidewalk x > 0 at z
    /// `step`), each at one offset x, its points spread along y; `face` puts one more
    /// scanline on the face at half height.
    struct Lines {
        x: Vec<f64>,
        y: Vec<f64>,
        z: Vec<f64>,
        line: Vec<u32>,
    }

    fn lines(offsets: &[f64], step: f64, ramp: f64) -> Lines {
        let mut l = Lines {
            x: Vec::new(),
            y: Vec::new(),
            z: Vec::new(),
            line: Vec::new(),
        };
        for (k, &x) in offsets.iter().enumerate() {
            for j in 0..6 {
                let y = -0.25 + 0.1 * j as f64;
                // A scanline slightly oblique to the curb: 1 cm across over its length.
                let x = x + 0.002 * j as f64;
                let z = if x < 0.0 { 0.01 * x } else { step + ramp * x };
                l.x.push(x);
                l.y.push(y);
                l.z.push(z + 0.002 * ((j * 7 + k * 3) % 5) as f64);
                l.line.push(k as u32);
            }
        }
        l
    }

    fn toe(l: &Lines) -> Option<ProfileToe> {
        let n = l.x.len();
        let status = vec![Some(PointStatus::Kept); n];
        let rho = vec![0.0f32; n];
        let t: Vec<f64> = (0..n).map(|i| i as f64 * 1e-4).collect();
        let traj = Trajectory::default();
        let input = BendInput {
            x: &l.x,
            y: &l.y,
            z: &l.z,
            t: &t,
            rho_deg: &rho,
            status: &status,
            scanline: &l.line,
            candidates: &[],
            trajectory: &traj,
        };
        let grid = PointGrid::build(input.x, input.y, 0.1, |_| true);
        let params = BendParams::default();
        // Along +y, the curb rising to the right (x > 0): up = −1.
        sparse_toe(
            &input,
            &grid,
            [0.0, 0.0, 0.0],
            [0.0, 1.0],
            -1.0,
            0.3,
            &params,
        )
    }

    #[test]
    fn a_step_between_scanline_levels_is_a_toe() {
        let offsets = [-0.38, -0.26, -0.14, -0.04, 0.07, 0.2, 0.33];
        let t = toe(&lines(&offsets, 0.12, 0.0)).expect("a toe between the levels");
        // Half-way between the road scanline at −0.04 and the curb one at 0.07.
        assert!((t.xyz[0] - 0.0175).abs() < 0.03, "toe at {:?}", t.xyz);
        assert!((t.step_m - 0.12).abs() < 0.01, "step {}", t.step_m);
        assert!(t.xyz[2].abs() < 0.01, "road height {}", t.xyz[2]);
    }

    #[test]
    fn a_face_scanline_between_the_levels_is_left_out() {
        let mut l = lines(&[-0.38, -0.26, -0.14, 0.1, 0.22, 0.34], 0.12, 0.0);
        let face = lines(&[-0.02], 0.0, 0.0);
        for j in 0..face.x.len() {
            l.x.push(face.x[j]);
            l.y.push(face.y[j]);
            l.z.push(0.06);
            l.line.push(9);
        }
        let t = toe(&l).expect("a toe across the face");
        assert!((t.xyz[0] - -0.02).abs() < 0.03, "toe at {:?}", t.xyz);
    }

    #[test]
    fn a_ramp_a_low_step_and_one_level_are_no_toe() {
        let offsets = [-0.38, -0.26, -0.14, -0.04, 0.07, 0.2, 0.33];
        // A curb cut's ramp behind the road: its scanlines rise with the offset.
        assert!(toe(&lines(&offsets, 0.02, 0.3)).is_none());
        // A step under `profile_min_step_m`.
        assert!(toe(&lines(&offsets, 0.03, 0.0)).is_none());
        // Flat road only.
        assert!(toe(&lines(&offsets, 0.0, 0.01)).is_none());
        // A single scanline on the curb side.
        assert!(toe(&lines(&[-0.38, -0.26, -0.14, -0.04, 0.07], 0.12, 0.0)).is_none());
    }
}
