//! The curb toe on a virtual profile whose scanlines run along the curb: a step between
//! scanline levels, for the side streets of intersections where [`Profile::toe`] sees too
//! few points spread across.
//!
//! Where a curb runs nearly along the scanlines (a side street's curb, the far part of a
//! corner arc) a profile across it holds a few scanlines, each at one offset across: the
//! ones on the road at road level, the ones on the sidewalk about a curb height higher,
//! perhaps one on the face between them. [`Profile::toe`] fits two lines to the points and
//! asks for points right beside the toe on both sides and flat parts; with the points
//! bunched at a few offsets one scanline on the face tilts a part, or the nearest scanline
//! lies more than 0.15 m from the toe, and it sees no toe. Here each scanline is one
//! level: the scanlines sorted by offset are split into a low and a high group (one
//! scanline between them may be on the face), each group's levels are fitted by a line
//! against offset, and the toe is taken half-way between the last low and the first high
//! scanline; the gap between them is held to the ordinary profile's reach unless the
//! scanner stood on the curb's side (the curb's shadow). The step must continue the track
//! that reaches it: its curb height and its line.

use super::grid::PointGrid;
use super::params::BendParams;
use super::profile::{usable, Profile, ProfileToe};
use super::{median, BendInput};

/// Fewest points of a scanline on the profile for it to give a level.
const MIN_LINE_POINTS: usize = 2;

/// Fewest scanlines on the road side and on the curb side of the step.
const MIN_SIDE_LINES: usize = 2;

/// Widest spread across the profile of one scanline's points, metres: a scanline that
/// spreads wider crosses the curb line, and its points are the ordinary profile's case.
const MAX_LINE_SPREAD_M: f64 = 0.12;

/// Widest road between the near edges of the last road scanline and the first curb
/// scanline, metres: the toe lies somewhere between them, so a wider gap places it worse
/// than ±0.15 m. This holds across the curb's shadow too ([`is_shadow`]): there the toe is
/// a curb the returns do not show beside the road (allowing 0.5 m for shadows added a curb
/// 4–6 m down a side street on evaluation street 1009 and tuning street 5, scored as
/// false; docs/results.md).
const MAX_GAP_M: f64 = 0.3;

/// Farthest apart the centres of those two scanlines may lie, metres: [`MAX_GAP_M`] where
/// the road between them is a gap in the returns, wider across the curb's shadow (the
/// scanner on the curb's side of the toe line), where a curb scanline spreading along the
/// top still has its near edge at the curb.
const MAX_SHADOW_GAP_M: f64 = 0.5;

/// Length of track before the step over which its curb height is measured, metres.
const CURB_CUE_M: f64 = 3.0;

/// Spacing of those measurements along the track, metres (each strip is 0.6 m long).
const CURB_CUE_SPACING_M: f64 = 0.3;

/// Fewest curb height measurements for the track to have a curb height.
const CURB_CUE_MIN: usize = 2;

/// Largest difference between the step and the track's curb height, as a share of the
/// latter: a side street's curb is the corner's, a false step (a gap's edge, a car's sill)
/// is any height.
const CURB_MATCH_SHARE: f64 = 0.35;

/// Farthest the toe may lie across from the search position (the track's line, or its arc
/// carried on by the turn per step), metres.
const MAX_OFF_LINE_M: f64 = 0.15;

/// One scanline on the profile: its points' mean offset across, mean height, mean
/// position along, mean time, count, their spread across and their RMS about the mean height.
#[derive(Clone, Copy, Debug)]
struct Level {
    c: f64,
    z: f64,
    a: f64,
    t: f64,
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
fn levels(profile: &Profile) -> Option<Vec<Level>> {
    let input = profile.input;
    let mut pts: Vec<(u32, f64, f64, f64, f64)> = Vec::new();
    profile.for_each(|i, c, a| {
        pts.push((input.scanline[i], c, input.z[i], a, input.t[i]));
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
        let t = run.iter().map(|p| p.4).sum::<f64>() / n;
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
            t,
            n: run.len(),
            spread,
            rms,
        });
    }
    out.sort_by(|p, q| p.c.total_cmp(&q.c));
    Some(out)
}

/// Finds the curb toe on a virtual profile ([`Profile`]: its points, with `across` from
/// the road, negative, to the curb side) as a step between scanline levels.
/// The scanlines sorted by offset are split where two lines, one through the road
/// scanlines' levels and one through the curb scanlines' (one scanline between them may
/// be left out: the face), fit best; the toe is accepted when each side has at least
/// [`MIN_SIDE_LINES`] scanlines, both lines are ground-like (slopes under
/// `profile_max_slope`), the step between them at the toe is at least
/// `profile_min_step_m` (and under the search half-height), every level and every
/// scanline's own points lie within a quarter of the step of their side's line, and the
/// near edges of the road and curb scanlines beside the step lie at most [`MAX_GAP_M`]
/// apart, their centres as far apart or, across the curb's shadow ([`is_shadow`]), at most
/// [`MAX_SHADOW_GAP_M`]. The toe is half-way between those edges. Meant for where
/// [`Profile::toe`] finds nothing: each scanline at one offset is the case it cannot take.
///
/// A step between scanlines also shows where the returns have a gap or something other
/// than the curb stands on the road, so the toe must also continue the track that reaches
/// it (`picked`, its vertices before the step; the profile's `centre` is its search
/// position, the line or arc it is on carried one step on):
/// - the step matches the track's curb height ([`track_curb_height`]) within
///   [`CURB_MATCH_SHARE`] of it (no toe where the track has no curb height);
/// - the toe lies within [`MAX_OFF_LINE_M`] across of `centre`.
///
pub fn sparse_toe(profile: &Profile, picked: &[(u32, [f64; 3])]) -> Option<ProfileToe> {
    let Profile {
        input,
        grid,
        params,
        up,
        ..
    } = *profile;
    let lv = levels(profile)?;
    let m = lv.len();
    if m < 2 * MIN_SIDE_LINES {
        return None;
    }
    let (k, skip) = best_split(&lv)?;
    let (lo, hi) = (&lv[..k], &lv[k + skip..]);
    let (last_low, first_high) = (lo[k - 1], hi[0]);
    // The near edges of the two scanlines beside the step, and the toe half-way between
    // them (placing it at the curb scanline's edge across a shadow scored worse: the
    // nearest curb scanline lies anywhere up to a line spacing behind the curb's edge).
    let (road_edge, curb_edge) = (
        last_low.c + 0.5 * last_low.spread,
        first_high.c - 0.5 * first_high.spread,
    );
    let toe = 0.5 * (road_edge + curb_edge);
    let reach = if is_shadow(profile, toe, &[last_low, first_high]) {
        MAX_SHADOW_GAP_M
    } else {
        MAX_GAP_M
    };
    if curb_edge - road_edge > MAX_GAP_M || first_high.c - last_low.c > reach {
        return None;
    }
    if toe.abs() > MAX_OFF_LINE_M {
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
    let h = track_curb_height(input, grid, picked, up, params)?;
    if (step - h).abs() > CURB_MATCH_SHARE * h {
        return None;
    }
    let [x, y] = profile.plan_at(0.5 * (last_low.a + first_high.a), toe);
    Some(ProfileToe {
        xyz: [x, y, road],
        step_m: step,
    })
}

/// The best split of the levels (sorted by offset) into a road group `lv[..k]` and a curb
/// group `lv[k + skip..]`, `skip` 0 or 1 (a face scanline left out), each of at least
/// [`MIN_SIDE_LINES`]: the least weighted squared deviation from the two groups' lines.
fn best_split(lv: &[Level]) -> Option<(usize, usize)> {
    let m = lv.len();
    let mut best: Option<(f64, usize, usize)> = None;
    for skip in 0..=1 {
        for k in MIN_SIDE_LINES..=m.saturating_sub(MIN_SIDE_LINES + skip) {
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
    best.map(|(_, k, skip)| (k, skip))
}

/// Whether the road between the scanlines `beside` the step (the last road and the first
/// curb scanline) can be the curb's shadow: at each one's mean time the scanner stood on
/// the curb's side of the toe line (offset across from the profile's centre beyond
/// `toe`), so the raised curb hid the road just past it. Seen from the road's side a curb
/// hides no road, and a gap there is a gap in the returns. `false` where the trajectory
/// does not cover a scanline's time.
fn is_shadow(profile: &Profile, toe: f64, beside: &[Level]) -> bool {
    let Profile {
        input,
        centre,
        along,
        up,
        ..
    } = *profile;
    let n = [-along[1] * up, along[0] * up];
    beside.iter().all(|l| {
        input.trajectory.pose_at(l.t).is_some_and(|p| {
            let c = (p.x - centre[0]) * n[0] + (p.y - centre[1]) * n[1];
            c > toe
        })
    })
}

/// The curb height the track measured before the step: the median of height steps across
/// its vertices `picked` over the last [`CURB_CUE_M`] (one every [`CURB_CUE_SPACING_M`]),
/// each the median height of a strip on the curb side (`up`: +1 left of the track's
/// direction, −1 right) less that of a strip on the road side (`step_gap_m` to
/// `step_gap_m + step_strip_m` from the vertex, ±0.3 m along). `None` with fewer than
/// [`CURB_CUE_MIN`] measurements.
pub fn track_curb_height(
    input: &BendInput,
    grid: &PointGrid,
    picked: &[(u32, [f64; 3])],
    up: f64,
    params: &BendParams,
) -> Option<f64> {
    let &(_, end) = picked.last()?;
    let mut steps = Vec::new();
    let mut since = f64::INFINITY;
    let mut prev = end;
    for w in picked.windows(2).rev() {
        let (a, b) = (w[0].1, w[1].1);
        if (b[0] - end[0]).hypot(b[1] - end[1]) > CURB_CUE_M {
            break;
        }
        since += (b[0] - prev[0]).hypot(b[1] - prev[1]);
        prev = b;
        if since < CURB_CUE_SPACING_M {
            continue;
        }
        let d = [b[0] - a[0], b[1] - a[1]];
        let l = d[0].hypot(d[1]);
        if l <= 1e-9 {
            continue;
        }
        if let Some(h) = step_across(input, grid, b, [d[0] / l, d[1] / l], up, params) {
            steps.push(h);
            since = 0.0;
        }
    }
    if steps.len() < CURB_CUE_MIN {
        return None;
    }
    median(&mut steps)
}

/// Height step across the horizontal unit direction `dir` at `p`: the median height of the
/// strip `step_gap_m`–`step_gap_m + step_strip_m` on the side `up` (+1 left, −1 right)
/// less that of the strip as far on the other side, ±0.3 m along; `None` where either
/// strip holds fewer than 3 points.
fn step_across(
    input: &BendInput,
    grid: &PointGrid,
    p: [f64; 3],
    dir: [f64; 2],
    up: f64,
    params: &BendParams,
) -> Option<f64> {
    const ALONG_M: f64 = 0.3;
    let (g, w) = (params.step_gap_m, params.step_strip_m);
    let n = [-dir[1] * up, dir[0] * up];
    let (mut high, mut low) = (Vec::new(), Vec::new());
    grid.for_each_within(input.x, input.y, p[0], p[1], (g + w).hypot(ALONG_M), |j| {
        if !usable(input, j) || (input.z[j] - p[2]).abs() > params.search_half_height_m {
            return;
        }
        let d = [input.x[j] - p[0], input.y[j] - p[1]];
        if (d[0] * dir[0] + d[1] * dir[1]).abs() > ALONG_M {
            return;
        }
        let c = d[0] * n[0] + d[1] * n[1];
        if (g..=g + w).contains(&c) {
            high.push(input.z[j]);
        } else if (-g - w..=-g).contains(&c) {
            low.push(input.z[j]);
        }
    });
    if high.len() < 3 || low.len() < 3 {
        return None;
    }
    Some(median(&mut high)? - median(&mut low)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bend::fixture::profile_along_y;
    use crate::io::trajectory::{Pose, Trajectory};
    use crate::replay::PointStatus;

    /// A few scanlines along a curb at x = 0 (road x < 0 at z 0, sidewalk x > 0 at z
    /// `step`), each at one offset x, its points spread along y around the profile at
    /// y = 0; before it, from y = −3 to −0.55, a densely scanned stretch of a curb
    /// `track_step` high that the track has followed (its vertices in `picked`).
    struct Lines {
        x: Vec<f64>,
        y: Vec<f64>,
        z: Vec<f64>,
        line: Vec<u32>,
        picked: Vec<(u32, [f64; 3])>,
    }

    impl Lines {
        fn push(&mut self, x: f64, y: f64, z: f64, line: u32) {
            self.x.push(x);
            self.y.push(y);
            self.z.push(z);
            self.line.push(line);
        }
    }

    fn lines(offsets: &[f64], step: f64, ramp: f64, track_step: f64) -> Lines {
        lines_spread(offsets, step, ramp, track_step, 0.01)
    }

    /// [`lines`] with the scanlines on the curb side spreading `curb_spread` across.
    fn lines_spread(
        offsets: &[f64],
        step: f64,
        ramp: f64,
        track_step: f64,
        curb_spread: f64,
    ) -> Lines {
        let mut l = Lines {
            x: Vec::new(),
            y: Vec::new(),
            z: Vec::new(),
            line: Vec::new(),
            picked: Vec::new(),
        };
        for (k, &x) in offsets.iter().enumerate() {
            for j in 0..6 {
                let y = -0.25 + 0.1 * j as f64;
                // A scanline oblique to the curb: 1 cm across over its length on the road.
                let x = x + if x < 0.0 { 0.01 } else { curb_spread } * 0.2 * j as f64;
                let z = if x < 0.0 { 0.01 * x } else { step + ramp * x };
                l.push(x, y, z + 0.002 * ((j * 7 + k * 3) % 5) as f64, k as u32);
            }
        }
        for r in 0..50 {
            let y = -3.0 + 0.05 * r as f64;
            for q in 0..25 {
                let x = -0.6 + 0.05 * q as f64;
                let z = if x < 0.0 { 0.01 * x } else { track_step };
                l.push(x, y, z, 100 + r);
            }
        }
        l.picked = (0..17)
            .map(|k| (0, [0.0, -3.0 + 0.15 * k as f64, 0.0]))
            .collect();
        l
    }

    /// The sparse toe on the profile centred at (`centre_x`, 0), the scanner standing at
    /// x = `scanner_x` throughout.
    fn toe_seen_from(l: &Lines, centre_x: f64, scanner_x: f64) -> Option<ProfileToe> {
        let n = l.x.len();
        let status = vec![Some(PointStatus::Kept); n];
        let rho = vec![0.0f32; n];
        let t: Vec<f64> = (0..n).map(|i| i as f64 * 1e-4).collect();
        let pose = |t: f64| Pose {
            t,
            x: scanner_x,
            y: 0.0,
            z: 2.5,
            roll_deg: 0.0,
            pitch_deg: 0.0,
            heading_deg: 0.0,
        };
        let traj = Trajectory {
            samples: vec![pose(-1.0), pose(10.0)],
        };
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
        let profile = profile_along_y(&input, &grid, &params, [centre_x, 0.0, 0.0], 0.3);
        sparse_toe(&profile, &l.picked)
    }

    /// Seen from the road side (the scanner at x = −5).
    fn toe(l: &Lines) -> Option<ProfileToe> {
        toe_seen_from(l, 0.0, -5.0)
    }

    #[test]
    fn a_step_between_scanline_levels_is_a_toe() {
        let offsets = [-0.38, -0.26, -0.14, -0.04, 0.07, 0.2, 0.33];
        let t = toe(&lines(&offsets, 0.12, 0.0, 0.12)).expect("a toe between the levels");
        // Half-way between the road scanline at −0.04 and the curb one at 0.07.
        assert!((t.xyz[0] - 0.0175).abs() < 0.03, "toe at {:?}", t.xyz);
        assert!((t.step_m - 0.12).abs() < 0.01, "step {}", t.step_m);
        assert!(t.xyz[2].abs() < 0.01, "road height {}", t.xyz[2]);
    }

    #[test]
    fn a_face_scanline_between_the_levels_is_left_out() {
        let mut l = lines(&[-0.38, -0.26, -0.14, 0.1, 0.22, 0.34], 0.12, 0.0, 0.12);
        for j in 0..6 {
            l.push(-0.02 + 0.002 * j as f64, -0.25 + 0.1 * j as f64, 0.06, 9);
        }
        let t = toe(&l).expect("a toe across the face");
        assert!((t.xyz[0] - -0.02).abs() < 0.03, "toe at {:?}", t.xyz);
    }

    #[test]
    fn a_ramp_a_low_step_and_one_level_are_no_toe() {
        let offsets = [-0.38, -0.26, -0.14, -0.04, 0.07, 0.2, 0.33];
        // A curb cut's ramp behind the road: its scanlines rise with the offset.
        assert!(toe(&lines(&offsets, 0.02, 0.3, 0.12)).is_none());
        // A step under `profile_min_step_m`.
        assert!(toe(&lines(&offsets, 0.03, 0.0, 0.12)).is_none());
        // Flat road only.
        assert!(toe(&lines(&offsets, 0.0, 0.01, 0.12)).is_none());
        // A single scanline on the curb side.
        let short = [-0.38, -0.26, -0.14, -0.04, 0.07];
        assert!(toe(&lines(&short, 0.12, 0.0, 0.12)).is_none());
    }

    #[test]
    fn a_shadow_may_leave_the_scanlines_farther_apart_than_a_gap() {
        // No road returns in the 0.25 m before the curb, which starts at x = 0; the curb
        // scanlines spread 0.11 m along its top, so their centres lie 0.31 m from the
        // road scanline's.
        let offsets = [-0.5, -0.38, -0.26, 0.0, 0.14, 0.28];
        let l = lines_spread(&offsets, 0.12, 0.0, 0.12, 0.11);
        // The scanner on the sidewalk's side of the curb line (x > 0): the curb hid the
        // road before it, a shadow; the toe half-way between the near edges.
        let shadow = toe_seen_from(&l, 0.0, 5.0).expect("a toe across the shadow");
        assert!(
            (shadow.xyz[0] - -0.125).abs() < 0.01,
            "toe at {:?}",
            shadow.xyz
        );
        // The scanner on the road's side: the same returns are a gap, too wide.
        assert!(toe_seen_from(&l, 0.0, -5.0).is_none());
        // Narrow curb scanlines: within reach seen from either side.
        let narrow = lines(&offsets, 0.12, 0.0, 0.12);
        assert!(toe_seen_from(&narrow, 0.0, -5.0).is_some());
        // 0.4 m of road missing between the near edges is too wide either way.
        let wide = lines(&[-0.64, -0.52, -0.4, 0.0, 0.12, 0.24], 0.12, 0.0, 0.12);
        assert!(toe_seen_from(&wide, 0.0, 5.0).is_none());
        assert!(toe_seen_from(&wide, 0.0, -5.0).is_none());
    }

    #[test]
    fn the_step_must_continue_the_tracks_curb_height_and_line() {
        let offsets = [-0.38, -0.26, -0.14, -0.04, 0.07, 0.2, 0.33];
        // The track followed a 0.12 m curb: a 0.25 m step is something else.
        assert!(toe(&lines(&offsets, 0.12, 0.0, 0.12)).is_some());
        assert!(toe(&lines(&offsets, 0.25, 0.0, 0.12)).is_none());
        // The track measured no curb before the step.
        assert!(toe(&lines(&offsets, 0.12, 0.0, 0.0)).is_none());
        assert_eq!(
            track_curb_height_of(&lines(&offsets, 0.12, 0.0, 0.12)).map(|h| (h * 100.0).round()),
            Some(12.0)
        );
        // The same step 0.2 m across from the track's search position.
        let l = lines(&offsets, 0.12, 0.0, 0.12);
        assert!(toe_seen_from(&l, 0.1, -5.0).is_some());
        assert!(toe_seen_from(&l, -0.2, -5.0).is_none());
    }

    fn track_curb_height_of(l: &Lines) -> Option<f64> {
        let n = l.x.len();
        let status = vec![Some(PointStatus::Kept); n];
        let rho = vec![0.0f32; n];
        let t = vec![0.0; n];
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
        track_curb_height(&input, &grid, &l.picked, -1.0, &BendParams::default())
    }
}
