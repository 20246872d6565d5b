//! Holes in the returns: a stretch of a curb with no kept return on the track's line nor
//! beside it (a shadow, or points the kernel drops), after which the returns resume on the
//! curb's line.
//!
//! A track ends where its search finds no toe for `max_gap_steps`. Most ends are where the
//! curb ends (a corner, a cut: the road beside the line is still scanned) or where the scan
//! ends (the drive's end, the sensor's range: nothing resumes). A hole is neither: across
//! the line, on the road side and on the curb side alike, no kept return, and within
//! [`HOLE_MAX_M`] on, on the track's path, a return with a strong bend angle on the line.
//! The track crosses to that return.

use super::grid::PointGrid;
use super::params::{widened, BendParams};
use super::profile::{Profile, ProfileToe};
use super::BendInput;
use crate::replay::PointStatus;

/// Where the returns resume past a hole: a measured point (its index) or a virtual
/// profile's toe.
#[derive(Clone, Copy, Debug)]
pub(super) enum Resumed {
    Point(usize),
    Toe(ProfileToe),
}

/// Longest hole crossed, metres, from where the track's gap steps end: a corner's or a
/// parked car's shadow on a side street's leg, or a stretch whose returns the kernel drops
/// as too sparse, is 1–2 m long.
pub(super) const HOLE_MAX_M: f64 = 2.5;

/// Shortest stretch without kept returns before they resume, metres: a return a step or
/// two on that the search disc missed is the track drifting off its line, not a hole.
const HOLE_MIN_M: f64 = 0.45;

/// Half-width across the track's path of the strip that must hold no kept return, metres:
/// the road beside the toe and the curb's top behind it.
const SIDE_M: f64 = 0.5;

/// Farthest across the track's path a resumed return may lie, metres: the path extrapolated
/// over [`HOLE_MAX_M`] at the running turn rate drifts from a curb's line by about this.
const LINE_M: f64 = 0.25;

/// Where the returns resume past a hole ahead of `cur`, for a track at `cur` heading `dir`
/// (horizontal, unit), turning by `turn` radians per search step, with the curb rising on
/// the side `up` (+1 left, −1 right): the toe a virtual profile across the path shows there
/// (ground on both sides of a step), or else the kept return with ρ of at least
/// `weak_rho_deg` on the line; `None` when there is no hole (kept returns beside the line
/// and no toe) or nothing resumes within [`HOLE_MAX_M`].
///
/// The path is walked in search steps; each step's strip, one step long and [`SIDE_M`]
/// either side of the path, holds either no kept return (the hole goes on), or kept
/// returns only within [`LINE_M`] of the path (the curb's face or top edge seen across a
/// hole in the ground's returns: the hole goes on unless they resume there), or kept
/// returns beside the line (the ground is scanned: the returns resume there, or the curb
/// has ended). Heights are gated around `z0`, the track's last vertex's.
#[allow(clippy::too_many_arguments)]
pub(super) fn resumed_past_hole(
    input: &BendInput,
    grid: &PointGrid,
    cur: [f64; 3],
    dir: [f64; 2],
    turn: f64,
    up: f64,
    skip: impl Fn(usize) -> bool,
    params: &BendParams,
) -> Option<Resumed> {
    let d_s = params.search_distance_m;
    if d_s <= 0.0 || !d_s.is_finite() {
        return None;
    }
    let steps = (HOLE_MAX_M / d_s).ceil() as usize;
    let z0 = cur[2];
    let (mut p, mut h) = ([cur[0], cur[1]], dir);
    let mut empty_m = 0.0f64;
    for _ in 0..steps {
        p = [p[0] + d_s * h[0], p[1] + d_s * h[1]];
        let n = [-h[1], h[0]];
        let (mut other, mut line, mut best): (bool, bool, Option<(f64, usize)>) =
            (false, false, None);
        let r = SIDE_M.hypot(0.5 * d_s);
        grid.for_each_within(input.x, input.y, p[0], p[1], r, |i| {
            if input.status[i] != Some(PointStatus::Kept)
                || (input.z[i] - z0).abs() > params.search_half_height_m
                || skip(i)
            {
                return;
            }
            let d = [input.x[i] - p[0], input.y[i] - p[1]];
            let along = d[0] * h[0] + d[1] * h[1];
            let across = d[0] * n[0] + d[1] * n[1];
            if along.abs() > 0.5 * d_s || across.abs() > SIDE_M {
                return;
            }
            if across.abs() > LINE_M {
                other = true;
                return;
            }
            line = true;
            if f64::from(input.rho_deg[i]) >= params.weak_rho_deg
                && best.is_none_or(|(b, _)| across.abs() < b)
            {
                best = Some((across.abs(), i));
            }
        });
        if other || line {
            if empty_m < HOLE_MIN_M {
                return None;
            }
            if let Some(toe) = toe_at(input, grid, [p[0], p[1], z0], h, up, params) {
                return Some(Resumed::Toe(toe));
            }
            if let Some((_, i)) = best {
                return Some(Resumed::Point(i));
            }
            if other {
                return None;
            }
        }
        empty_m += d_s;
        let (c, s) = (turn.cos(), turn.sin());
        h = [c * h[0] - s * h[1], s * h[0] + c * h[1]];
    }
    None
}

/// The toe on a virtual profile across the path at `c` heading `h`, within [`LINE_M`] of
/// the path: the default profile, one twice as long, or a wider one (the returns beside a
/// hole are often sparse or grazing).
fn toe_at(
    input: &BendInput,
    grid: &PointGrid,
    c: [f64; 3],
    h: [f64; 2],
    up: f64,
    params: &BendParams,
) -> Option<ProfileToe> {
    let profile = Profile {
        input,
        grid,
        params,
        centre: c,
        along: h,
        up,
        half_l: params.profile_half_length_m,
    };
    let wide = widened(params);
    let long = Profile {
        params: &wide,
        ..profile.with_half_l(2.0 * params.profile_half_length_m)
    };
    let near = |t: &ProfileToe| {
        let d = [t.xyz[0] - c[0], t.xyz[1] - c[1]];
        (d[0] * h[1] - d[1] * h[0]).abs() <= LINE_M
    };
    profile
        .toe_or_longer()
        .filter(near)
        .or_else(|| long.toe().filter(near))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::trajectory::Trajectory;

    /// Kept points every 0.05 m on a grid over x in [0, 10), y in [3, 7), flat (the road
    /// and the curb's top alike at z = 0), with ρ = 60° on the line y = 5 and 0 elsewhere;
    /// none where `hole` says.
    struct Scene {
        x: Vec<f64>,
        y: Vec<f64>,
        z: Vec<f64>,
        t: Vec<f64>,
        rho: Vec<f32>,
        status: Vec<Option<PointStatus>>,
        scanline: Vec<u32>,
        traj: Trajectory,
    }

    fn scene(hole: impl Fn(f64, f64) -> bool) -> Scene {
        let mut s = Scene {
            x: vec![],
            y: vec![],
            z: vec![],
            t: vec![],
            rho: vec![],
            status: vec![],
            scanline: vec![],
            traj: Trajectory::default(),
        };
        for i in 0..200 {
            for j in 0..80 {
                let (x, y) = (0.025 + 0.05 * f64::from(i), 3.0 + 0.05 * f64::from(j));
                if hole(x, y) {
                    continue;
                }
                s.x.push(x);
                s.y.push(y);
                s.z.push(0.0);
                s.t.push(0.0);
                s.rho.push(if (y - 5.0).abs() < 0.01 { 60.0 } else { 0.0 });
                s.status.push(Some(PointStatus::Kept));
                s.scanline.push(i as u32);
            }
        }
        s
    }

    fn resumed(s: &Scene) -> Option<[f64; 2]> {
        let input = BendInput {
            x: &s.x,
            y: &s.y,
            z: &s.z,
            t: &s.t,
            rho_deg: &s.rho,
            status: &s.status,
            scanline: &s.scanline,
            candidates: &[],
            trajectory: &s.traj,
        };
        let grid = PointGrid::build(&s.x, &s.y, 0.1, |_| true);
        let params = BendParams::default();
        // A track at x = 4 on the line, heading +x, turning slightly left.
        match resumed_past_hole(
            &input,
            &grid,
            [4.0, 5.0, 0.0],
            [1.0, 0.0],
            0.01,
            1.0,
            |_| false,
            &params,
        )? {
            Resumed::Point(i) => Some([s.x[i], s.y[i]]),
            Resumed::Toe(t) => Some([t.xyz[0], t.xyz[1]]),
        }
    }

    #[test]
    fn a_track_crosses_a_hole_only_where_the_returns_resume_on_its_line() {
        // No return across the line from x = 4 to 5.5: the returns resume on the line at
        // the hole's far side, within the path's drift.
        let hole = scene(|x, _| (4.0..5.5).contains(&x));
        let p = resumed(&hole).expect("a hole");
        assert!(
            (5.5..5.6).contains(&p[0]) && (p[1] - 5.0).abs() < 0.01,
            "{p:?}"
        );
        // The road beside the line is scanned (only the line has no return): the curb has
        // ended, no hole.
        let line_only = scene(|x, y| (4.0..5.5).contains(&x) && (y - 5.0).abs() < 0.1);
        assert!(resumed(&line_only).is_none());
        // The scan ends: nothing resumes.
        assert!(resumed(&scene(|x, _| x >= 4.0)).is_none());
        // Longer than the longest hole.
        assert!(resumed(&scene(|x, _| (4.0..7.0).contains(&x))).is_none());
        // A gap shorter than a hole: the track drifting off its line, not a hole.
        assert!(resumed(&scene(|x, _| (4.0..4.3).contains(&x))).is_none());
    }
}
