//! Seeds on side streets' legs: virtual profiles laid along a curb that runs away from
//! the route, where a coarse raster of the ground's height shows such a curb.
//!
//! The core's candidates come from bend angles along the scanlines, and a scanline that
//! runs beside a side street's curb bends nowhere at its toe; the profile seeds
//! ([`super::seed::profile_seeds`]) are profiles across the driving direction, which see a
//! curb parallel to the route and not one at a large angle to it. A leg left unseeded is
//! never tracked, unless a track comes round its corner and follows it all the way. Here,
//! on lines parallel to the route at a few distances aside, the raster
//! ([`super::leg_screen`]) tells where the ground rises along the route by about a curb
//! and more than it rises across it (a curb within half a right angle of the normal); only
//! there does a profile look for the leg's toe, its length along the curb's direction that
//! the rise gives and its curb side up the rise. The first toe found at each distance gives
//! a seed, so a leg that a track leaves at a hole in the returns is seeded again beyond it.
//! Only the stretch of route the input's points cover is searched (a streaming window
//! seeds its own stretch), and the seeds come last in tracking, after the profile seeds:
//! they start tracks only where no other track has claimed the curb.

use rayon::prelude::*;

use super::grid::PointGrid;
use super::leg_screen::HeightRaster;
use super::params::BendParams;
use super::profile::{usable, Profile};
use super::route::Route;
use super::seed::{finite_range, nearest_usable, Seed};
use super::BendInput;
use crate::model::Side;

/// Nearest distance aside of the route at which a leg is looked for, metres: nearer lie
/// the vehicle's lane and the corner's arc, which the other seeds reach.
const LEG_NEAR_M: f64 = 2.0;

/// Farthest distance aside of the route at which a leg is looked for, metres: a profiler
/// sees side streets' legs 10–25 m aside in plain view, farther than the profile seeds'
/// reach (`profile_seed_reach_m`) across the road.
const LEG_REACH_M: f64 = 30.0;

/// Step between the distances aside that are searched, metres: a seed anywhere on a leg is
/// enough for the tracker to follow it, so the lines need not cover the leg.
const LEG_STEP_ASIDE_M: f64 = 1.5;

/// Step between profiles along the route on one line, metres: a profile finds a toe within
/// 0.3 m of its centre (`profile_half_width_m` less the 0.15 m kept clear), so 0.5 m steps
/// leave no leg crossing the line unseen.
const LEG_STEP_ALONG_M: f64 = 0.5;

/// Turns of the profiles' length from the curb's direction that the raster's rise gives,
/// degrees, in order: that direction comes from cells half a metre wide, and a profile
/// 0.6 m long sees a toe only on a curb within about 10° of its length.
const LEG_TURNS_DEG: [f64; 3] = [0.0, 15.0, -15.0];

/// Least step in the ground's mean height along the route ([`HeightRaster::step_along`])
/// where the profiles are tried, as a share of the least curb step: the cells either side
/// of a toe hold parts of the step's two levels.
const SCREEN_MIN_SHARE: f64 = 0.4;

/// Greatest such step, metres: more is a wall, a vehicle or a drop, not a curb.
const SCREEN_MAX_M: f64 = 0.4;

/// The [`HeightRaster`] over the band of the route from arc length `s0` to `s1` and
/// [`LEG_REACH_M`] (and the screen's reach) either side.
fn band_raster(input: &BendInput, route: &Route, s0: f64, s1: f64) -> Option<HeightRaster> {
    let margin = LEG_REACH_M + 4.0 * super::leg_screen::CELL_M;
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    let mut s = s0;
    loop {
        if let Some((p, _)) = route.pose_at_arc(s.min(s1)) {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k] - margin);
                hi[k] = hi[k].max(p[k] + margin);
            }
        }
        if s >= s1 {
            break;
        }
        s += 1.0;
    }
    HeightRaster::build(input, lo, hi)
}

/// The ground height at `centre` for a leg's profile: the median height of the usable
/// points within the profile's half-width, `None` with fewer than 8 of them or where
/// their 5th and 95th percentile heights lie less than half the least curb step apart
/// (no step within reach: the profiles are not tried). The heights are gathered in `z`.
fn stepped_ground(
    input: &BendInput,
    grid: &PointGrid,
    centre: [f64; 2],
    params: &BendParams,
    z: &mut Vec<f64>,
) -> Option<f64> {
    z.clear();
    let r = params.profile_half_width_m;
    grid.for_each_within(input.x, input.y, centre[0], centre[1], r, |i| {
        if usable(input, i) && input.z[i].is_finite() {
            z.push(input.z[i]);
        }
    });
    if z.len() < 8 {
        return None;
    }
    let mut at = |q: f64| {
        let k = ((z.len() - 1) as f64 * q).round() as usize;
        *z.select_nth_unstable_by(k, f64::total_cmp).1
    };
    let (low, high) = (at(0.05), at(0.95));
    (high - low >= 0.5 * params.profile_min_step_m).then(|| at(0.5))
}

/// Seeds on legs (see the module docs), in interval order, left before right.
///
/// For each interval of L_s along the route and each side, at [`LEG_STEP_ALONG_M`] along
/// the interval and [`LEG_STEP_ASIDE_M`] aside from [`LEG_NEAR_M`] to [`LEG_REACH_M`],
/// where the raster's rise along the route lies between [`SCREEN_MIN_SHARE`] of the least
/// curb step and [`SCREEN_MAX_M`] and exceeds the rise along the normal, and where the
/// points there show a step ([`stepped_ground`]), profiles centred on the ground (the
/// median height within the profile's half-width) along the curb's direction that the two
/// rises give, turned by [`LEG_TURNS_DEG`], the curb side up the rise, are tried
/// (`Profile::toe`); the first toe on a line gives a seed on the usable point nearest to
/// it, its direction the route's normal, inlier share 0.
pub fn leg_seeds(
    input: &BendInput,
    grid: &PointGrid,
    route: &Route,
    params: &BendParams,
) -> Vec<Seed> {
    let reach = LEG_REACH_M;
    let Some((t0, t1)) = finite_range(input.t) else {
        return Vec::new();
    };
    let (Some(s0), Some(s1)) = (route.arc_at(t0), route.arc_at(t1)) else {
        return Vec::new();
    };
    let l_s = params.seed_interval_m.max(1e-3);
    let half_l = 2.0 * params.profile_half_length_m;
    let per_interval = (l_s / LEG_STEP_ALONG_M).ceil().max(1.0) as usize;
    let intervals: Vec<i64> = ((s0 / l_s).floor() as i64..=(s1 / l_s).floor() as i64).collect();
    let Some(raster) = band_raster(input, route, s0, s1) else {
        return Vec::new();
    };
    let min_rise = SCREEN_MIN_SHARE * params.profile_min_step_m;
    let sides = [(Side::Left, 1.0), (Side::Right, -1.0)];
    let mut out: Vec<Seed> = intervals
        .par_iter()
        .flat_map_iter(|&interval| sides.iter().map(move |&s| (interval, s)))
        .flat_map_iter(|(interval, (side, sign))| {
            // The poses along the interval, within the stretch the points cover.
            let poses: Vec<([f64; 2], [f64; 2])> = (0..per_interval)
                .filter_map(|k| {
                    let s = interval as f64 * l_s + (k as f64 + 0.5) * LEG_STEP_ALONG_M;
                    if s < s0 || s > s1 || s >= (interval + 1) as f64 * l_s {
                        return None;
                    }
                    route.pose_at_arc(s)
                })
                .collect();
            let mut seeds = Vec::new();
            let mut z = Vec::new();
            let mut c = LEG_NEAR_M;
            while c <= reach {
                let found = poses.iter().find_map(|&(p, fwd)| {
                    let n = [-fwd[1] * sign, fwd[0] * sign];
                    let centre = [p[0] + c * n[0], p[1] + c * n[1]];
                    let rise = raster.step_along(centre, fwd)?;
                    if !(min_rise..=SCREEN_MAX_M).contains(&rise.abs()) {
                        return None;
                    }
                    // A curb within half a right angle of the normal rises more along
                    // the route than across it; its direction is across the rise.
                    let rise_n = raster.step_along(centre, n).unwrap_or(0.0);
                    if rise_n.abs() > rise.abs() {
                        return None;
                    }
                    let g = [rise * fwd[0] + rise_n * n[0], rise * fwd[1] + rise_n * n[1]];
                    let norm = g[0].hypot(g[1]);
                    let curb = [-g[1] / norm, g[0] / norm];
                    let ground = stepped_ground(input, grid, centre, params, &mut z)?;
                    let toe = LEG_TURNS_DEG.iter().find_map(|&turn| {
                        let (sin, cos) = f64::to_radians(turn).sin_cos();
                        let along = [curb[0] * cos - curb[1] * sin, curb[0] * sin + curb[1] * cos];
                        // The curb side lies right of `along`, up the rise.
                        Profile {
                            input,
                            grid,
                            params,
                            centre: [centre[0], centre[1], ground],
                            along,
                            up: -1.0,
                            half_l,
                        }
                        .toe()
                    })?;
                    nearest_usable(input, grid, toe.xyz, params.search_radius_m)
                        .map(|point| (point, n))
                });
                if let Some((point, n)) = found {
                    seeds.push(Seed {
                        point,
                        side,
                        dir: n,
                        interval,
                        inlier_ratio: 0.0,
                    });
                }
                c += LEG_STEP_ASIDE_M;
            }
            seeds
        })
        .collect();
    out.dedup_by_key(|s| s.point);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bend::fixture::{drive_along_x, KeptPoints};
    use crate::bend::seed::profile_seeds;

    /// A side street's leg left of a drive east along y = 0: the road level west of
    /// x = 10 m, the sidewalk 0.12 m up east of it, from y = 3 m to 12 m aside, sampled on a
    /// 0.08 m grid. The leg's curb runs along the route's normal: the profile seeds see no
    /// toe there, the leg seeds put one on it.
    #[test]
    fn a_leg_at_right_angles_to_the_route_is_seeded() {
        const T0: f64 = 400_000_000.0;
        let (mut x, mut y, mut z, mut t) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for i in 0..250 {
            let px = 0.08 * f64::from(i);
            for j in 0..113 {
                let py = 3.0 + 0.08 * f64::from(j);
                x.push(px);
                y.push(py);
                z.push(if px < 10.0 {
                    0.0
                } else {
                    0.12 + 0.02 * (px - 10.0)
                });
                t.push(T0 + px / 10.0);
            }
        }
        let points = KeptPoints {
            t,
            ..KeptPoints::new(x, y, z)
        };
        let trajectory = drive_along_x(T0);
        let input = points.input(&trajectory);
        let params = BendParams::default();
        let grid = PointGrid::build(input.x, input.y, params.search_radius_m, |_| true);
        let route = Route::new(&trajectory);
        let across = profile_seeds(&input, &grid, &route, &params);
        assert!(across.is_empty(), "{} profile seeds", across.len());
        let seeds = leg_seeds(&input, &grid, &route, &params);
        assert!(seeds.len() >= 4, "{} leg seeds", seeds.len());
        for s in &seeds {
            let i = s.point as usize;
            assert_eq!(s.side, Side::Left);
            assert!(
                (input.x[i] - 10.0).abs() <= 0.1,
                "seed at x = {:.3}",
                input.x[i]
            );
            assert!(
                s.dir[0].abs() < 1e-6 && (s.dir[1] - 1.0).abs() < 1e-6,
                "{:?}",
                s.dir
            );
        }
    }
}
