//! Seeding (Honma et al. §2.6): the core's seed candidates are split into left and right,
//! each side is cut into intervals of L_s along the trajectory, a 2D line is fitted to each
//! interval by RANSAC, and the candidate closest to the line becomes a seed whose initial
//! search direction is the line direction oriented with the driving direction. The line's
//! direction is not constrained, so curbs that are not parallel to the trajectory (bus
//! bays, intersection corners) still get seeds.

use rand::Rng;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use super::arc_seed::{arc_params, arc_seed};
use super::face::face_toe_or_longer;
use super::grid::PointGrid;
use super::params::{widened, BendParams};
use super::profile::{usable, Profile, ProfileToe};
use super::route::Route;
use super::BendInput;
use crate::model::Side;

/// A seed: a candidate point and its initial search direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Seed {
    /// Index of the seed point in the point columns.
    pub point: u32,
    /// Side of the trajectory.
    pub side: Side,
    /// Initial search direction (horizontal unit vector, along the driving direction).
    pub dir: [f64; 2],
    /// Interval number along the trajectory (for ordering).
    pub interval: i64,
    /// Share of the interval's candidates that are RANSAC inliers.
    pub inlier_ratio: f64,
}

/// Extracts the seeds of both sides, ordered by side, then interval.
pub fn seed_points(input: &BendInput, route: &Route, params: &BendParams) -> Vec<Seed> {
    let n = input.x.len();
    // (side, interval, point) for every usable candidate, sorted: deterministic whatever
    // order the candidates came in.
    let mut keyed: Vec<(Side, i64, u32)> = input
        .candidates
        .iter()
        .filter_map(|c| {
            let i = c.point as usize;
            if i >= n || !(input.x[i].is_finite() && input.y[i].is_finite()) {
                return None;
            }
            let s = route.arc_at(*input.t.get(i)?)?;
            let interval = (s / params.seed_interval_m.max(1e-3)).floor() as i64;
            Some((c.side, interval, c.point))
        })
        .collect();
    keyed.sort_unstable();
    keyed.dedup();

    let mut seeds = Vec::new();
    let mut start = 0;
    while start < keyed.len() {
        let (side, interval, _) = keyed[start];
        let mut end = start;
        while end < keyed.len() && keyed[end].0 == side && keyed[end].1 == interval {
            end += 1;
        }
        let pts: Vec<u32> = keyed[start..end].iter().map(|k| k.2).collect();
        let side_bit = matches!(side, Side::Right) as u64;
        let rng_seed = params.ransac_seed
            ^ (interval as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15)
            ^ (side_bit << 63);
        if let Some(fit) = ransac_line(input.x, input.y, &pts, params, rng_seed) {
            let i = fit.closest as usize;
            if let Some(fwd) = route.forward_at(input.t[i]) {
                let mut dir = fit.dir;
                if dir[0] * fwd[0] + dir[1] * fwd[1] < 0.0 {
                    dir = [-dir[0], -dir[1]];
                }
                seeds.push(Seed {
                    point: fit.closest,
                    side,
                    dir,
                    interval,
                    inlier_ratio: fit.inliers as f64 / pts.len() as f64,
                });
            }
        }
        start = end;
    }
    seeds
}

/// Nearest distance from the trajectory at which [`profile_seeds`] looks for a toe, metres:
/// inside it lie the vehicle's own lane and the returns its body leaves out.
const PROFILE_SEED_NEAR_M: f64 = 1.0;

/// Step between the profiles [`profile_seeds`] tries outward, metres: a profile finds a toe
/// within 0.3 m of its centre (`profile_half_width_m` less the 0.15 m kept clear), so 0.5 m
/// steps leave no stretch unseen.
const PROFILE_SEED_STEP_M: f64 = 0.5;

/// How many times longer along the road the last outward search's profiles are than the
/// first two's in [`profile_seeds`].
const SPARSE_LENGTH_FACTOR: f64 = 2.0;

/// Seeds from virtual profiles (`profile::Profile::toe`), one per interval and side at most.
///
/// At the middle of each interval of L_s along the route, profiles across the driving
/// direction are tried outward from [`PROFILE_SEED_NEAR_M`] to `profile_seed_reach_m`
/// every [`PROFILE_SEED_STEP_M`]; the first toe found, as the core's candidate is the
/// first peak outward from the nadir, gives a seed on the point nearest to it. The
/// profiles are centred on the height of the ground there (the median of the points within
/// the profile's half-width), so a road's crossfall does not push the curb out of their
/// height band. These seeds come last in tracking (inlier share 0): they start tracks only
/// on curbs no seed of the core's candidates has reached — also in intervals that have
/// such a seed, whose track may lie on something else or end before the interval does.
///
/// Where no profile finds a toe on a side, the search is made again with profiles
/// [`widened`]: on a far curb that its scanlines cross at a grazing angle, where the core
/// has no candidates, the profiles of the default width find no toe in most intervals
/// (see `track::wide_toe`), and a curb without a seed is never tracked.
///
/// Where neither finds a toe, the search is made once more with profiles
/// [`SPARSE_LENGTH_FACTOR`] times as long along the road: on a far curb the returns lie
/// decimetres apart across, and a short profile has no ground right beside the toe on one
/// side (the tracker's `profile::Profile::toe_or_longer` does the same). Short stretches
/// of curb seen between parked vehicles are then seeded as well.
///
/// Where none finds a toe, the first toe the three searches find with the points on the
/// curb's face left out (`profile::Profile::toe_or_past_face`, on the points each profile
/// gathered) gives the seed: on a far curb the returns lie a decimetre or two apart
/// across, and one on the face, half-way up the step, tilts the road's or the top's line
/// so that no profile shows the curb.
///
/// Where none finds a toe either, profiles turned towards a corner arc's direction are
/// tried ([`arc_seed`]): an arc whose curb before it is never seen is reached by no track.
///
/// Only the interval range the input's points cover is searched, so a streaming window
/// seeds its own stretch.
pub fn profile_seeds(
    input: &BendInput,
    grid: &PointGrid,
    route: &Route,
    params: &BendParams,
) -> Vec<Seed> {
    let reach = params.profile_seed_reach_m;
    let mut out = Vec::new();
    if reach.is_nan() || reach < PROFILE_SEED_NEAR_M {
        return out;
    }
    let Some((t0, t1)) = finite_range(input.t) else {
        return out;
    };
    let (Some(s0), Some(s1)) = (route.arc_at(t0), route.arc_at(t1)) else {
        return out;
    };
    let l_s = params.seed_interval_m.max(1e-3);
    let half_l = 2.0 * params.profile_half_length_m;
    let wide = widened(params);
    let arc = arc_params(params);
    // Every interval and side is searched on its own, on rayon's pool; the seeds come
    // back in interval order, left before right, whatever the threads.
    let lines: Vec<(i64, [f64; 2], [f64; 2])> = ((s0 / l_s).floor() as i64
        ..=(s1 / l_s).floor() as i64)
        .filter_map(|interval| {
            let mid = (interval as f64 + 0.5) * l_s;
            if mid < s0 || mid > s1 {
                return None;
            }
            let (p, fwd) = route.pose_at_arc(mid)?;
            Some((interval, p, fwd))
        })
        .collect();
    let sides = [(Side::Left, 1.0), (Side::Right, -1.0)];
    out.par_extend(
        lines
            .par_iter()
            .flat_map_iter(|&l| sides.iter().map(move |&s| (l, s)))
            .filter_map(|((interval, p, fwd), (side, up))| {
                let n = [-fwd[1] * up, fwd[0] * up];
                let mut heights = Heights::default();
                let mut first = |params: &BendParams, half_l: f64, along: [f64; 2], toe: ToeOn| {
                    let h = &mut heights;
                    let range = (PROFILE_SEED_NEAR_M, reach);
                    first_toe_outward(input, grid, p, along, n, up, half_l, range, toe, params, h)
                };
                let seed = |point| Seed {
                    point,
                    side,
                    dir: fwd,
                    interval,
                    inlier_ratio: 0.0,
                };
                // The default, widened and longer searches in turn; the first toe past a
                // face (in the same order) where none finds a toe.
                let past_face: ToeOn = |profile| profile.toe_or_past_face();
                let long = SPARSE_LENGTH_FACTOR * half_l;
                let (mut found, mut face) = (None, None);
                for (params, half_l) in [(params, half_l), (&wide, half_l), (params, long)] {
                    let (toe, past) = first(params, half_l, fwd, past_face);
                    if toe.is_some() {
                        found = toe;
                        break;
                    }
                    face = face.or(past);
                }
                let toe: ToeOn = |profile| (profile.toe(), None);
                found.or(face).map(seed).or_else(|| {
                    arc_seed(fwd, |along| first(&arc, half_l, along, toe).0).map(
                        |(point, along)| Seed {
                            dir: along,
                            ..seed(point)
                        },
                    )
                })
            }),
    );
    out
}

/// The smallest and the largest finite value of `t`, `None` where none is finite.
pub(super) fn finite_range(t: &[f64]) -> Option<(f64, f64)> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for &v in t {
        if v.is_finite() {
            lo = if v < lo { v } else { lo };
            hi = if v > hi { v } else { hi };
        }
    }
    (lo <= hi).then_some((lo, hi))
}

/// The ground heights ([`ground_height`]) at the centres of one side's outward search,
/// kept for the searches after it: the centres are the same in every search, and each
/// radius (the default profiles' and the longer ones', the widened ones', the turned ones')
/// has its own heights.
#[derive(Default)]
struct Heights {
    /// By radius (its bits), then by centre counted outward: `None` where not yet computed.
    z: Vec<(u64, Vec<Option<Option<f64>>>)>,
    /// The heights within the radius, kept from one centre to the next.
    scratch: Vec<i64>,
}

impl Heights {
    /// [`ground_height`] at centre `k` (counted outward) within `r` of `centre`.
    fn at(
        &mut self,
        k: usize,
        input: &BendInput,
        grid: &PointGrid,
        centre: [f64; 2],
        r: f64,
    ) -> Option<f64> {
        let bits = r.to_bits();
        let slot = match self.z.iter().position(|s| s.0 == bits) {
            Some(slot) => slot,
            None => {
                self.z.push((bits, Vec::new()));
                self.z.len() - 1
            }
        };
        let (z, scratch) = (&mut self.z[slot].1, &mut self.scratch);
        if z.len() <= k {
            z.resize(k + 1, None);
        }
        *z[k].get_or_insert_with(|| ground_height(input, grid, centre, r, scratch))
    }
}

/// A toe search on one profile: its toe, else a fallback toe of a lower rank (one found
/// past the curb's face).
type ToeOn = fn(&Profile) -> (Option<ProfileToe>, Option<ProfileToe>);

/// The seed point of the first toe that profiles across `fwd` find outward along `n` from
/// `p`, from `near` to `reach` every [`PROFILE_SEED_STEP_M`] (see [`profile_seeds`]), by
/// `toe_on` on each profile: the usable point nearest to it, `None` where the first toe has
/// none within the search radius, or there is no toe; and where there is no toe, the seed
/// point of the first fallback toe the same way. The ground heights come from `heights`.
#[allow(clippy::too_many_arguments)]
fn first_toe_outward(
    input: &BendInput,
    grid: &PointGrid,
    p: [f64; 2],
    fwd: [f64; 2],
    n: [f64; 2],
    up: f64,
    half_l: f64,
    (near, reach): (f64, f64),
    toe_on: ToeOn,
    params: &BendParams,
    heights: &mut Heights,
) -> (Option<u32>, Option<u32>) {
    let mut fallback = None;
    let mut c = near;
    let mut k = 0;
    while c <= reach {
        let centre = [p[0] + c * n[0], p[1] + c * n[1]];
        c += PROFILE_SEED_STEP_M;
        k += 1;
        let Some(z) = heights.at(k - 1, input, grid, centre, params.profile_half_width_m) else {
            continue;
        };
        let at = [centre[0], centre[1], z];
        let profile = Profile {
            input,
            grid,
            params,
            centre: at,
            along: fwd,
            up,
            half_l,
        };
        let (toe, past) = toe_on(&profile);
        if let Some(toe) = toe {
            let point = nearest_usable(input, grid, toe.xyz, params.search_radius_m);
            return (point, None);
        }
        fallback = fallback.or(past);
    }
    let point = fallback.and_then(|t| nearest_usable(input, grid, t.xyz, params.search_radius_m));
    (None, point)
}

/// Seeds from radial profiles at the two ends of the input's points, for a spinning
/// sensor (`params.end_view`; none without it), one per ray at most.
///
/// A ring is a cone about the sensor: where a curb's face lies at nearly one range from it
/// (a side street's far corner ahead, convex towards the sensor) the ring meets the face at
/// the height that range gives and runs along it, so no ring crosses that curb, no bend
/// angle peaks and the core gives no candidate. Within the route a later station passes
/// such a curb and its rings cross it from beside; past the last point's station (and
/// behind the first's) none does, and [`profile_seeds`] looks only across the driving
/// direction between them. There the direction from the sensor crosses the face: from the
/// route's pose at the last point's time, rays ahead within `max_azimuth_deg` of the axis
/// (behind it at the first point's), [`radial_step_deg`] apart, are searched outward from
/// `near_m` to `reach_m` by profiles across the ray every [`PROFILE_SEED_STEP_M`]
/// (`Profile::toe`, else `face::face_toe_or_longer`, as a ring slides along that face); the first
/// toe on a ray gives a seed on the point nearest to it, its
/// direction the profile's length oriented with the driving direction, its side the side
/// of the axis it lies on. These seeds come last in tracking, as the profile seeds.
pub fn end_seeds(
    input: &BendInput,
    grid: &PointGrid,
    route: &Route,
    params: &BendParams,
) -> Vec<Seed> {
    let Some(view) = params.end_view else {
        return Vec::new();
    };
    let finite_t = || input.t.iter().copied().filter(|t| t.is_finite());
    let (Some(t0), Some(t1)) = (finite_t().reduce(f64::min), finite_t().reduce(f64::max)) else {
        return Vec::new();
    };
    let (Some(s0), Some(s1)) = (route.arc_at(t0), route.arc_at(t1)) else {
        return Vec::new();
    };
    let l_s = params.seed_interval_m.max(1e-3);
    let half_l = 2.0 * params.profile_half_length_m;
    let step = radial_step_deg(half_l, view.reach_m);
    if !(step > 0.0 && view.max_azimuth_deg.is_finite() && view.near_m <= view.reach_m) {
        return Vec::new();
    }
    let k_max = (view.max_azimuth_deg.clamp(0.0, 90.0) / step).floor() as i64;
    // (station, −1 behind the first point's, +1 ahead of the last point's)
    let mut rays = Vec::new();
    for (s, look) in [(s0, -1.0), (s1, 1.0)] {
        let Some((p, fwd)) = route.pose_at_arc(s) else {
            continue;
        };
        let interval = (s / l_s).floor() as i64;
        for k in -k_max..=k_max {
            let (sin, cos) = (k as f64 * step).to_radians().sin_cos();
            let axis = [look * fwd[0], look * fwd[1]];
            let ray = [axis[0] * cos - axis[1] * sin, axis[0] * sin + axis[1] * cos];
            rays.push((p, fwd, ray, interval));
        }
    }
    rays.par_iter()
        .filter_map(|&(p, fwd, ray, interval)| {
            // Across the profile runs along the ray, away from the sensor (`up` = +1).
            let along = [ray[1], -ray[0]];
            let range = (view.near_m, view.reach_m);
            let h = &mut Heights::default();
            let toe: ToeOn =
                |profile| (profile.toe().or_else(|| face_toe_or_longer(profile)), None);
            let point = first_toe_outward(
                input, grid, p, along, ray, 1.0, half_l, range, toe, params, h,
            )
            .0?;
            let i = point as usize;
            let (dx, dy) = (input.x[i] - p[0], input.y[i] - p[1]);
            let side = if fwd[0] * dy - fwd[1] * dx >= 0.0 {
                Side::Left
            } else {
                Side::Right
            };
            let dir = if along[0] * fwd[0] + along[1] * fwd[1] < 0.0 {
                [-along[0], -along[1]]
            } else {
                along
            };
            Some(Seed {
                point,
                side,
                dir,
                interval,
                inlier_ratio: 0.0,
            })
        })
        .collect()
}

/// Azimuth between the rays of [`end_seeds`], degrees: profiles `half_l` long either side
/// of their ray touch their neighbours' at `reach_m`, so no stretch within the reach lies
/// between two rays; 0 where that has no meaning.
pub fn radial_step_deg(half_l: f64, reach_m: f64) -> f64 {
    let step = (2.0 * half_l / reach_m).to_degrees();
    if step.is_finite() && step > 0.0 {
        step
    } else {
        0.0
    }
}

/// Median height of the usable points within `r` (horizontal) of `centre`; `None` with
/// fewer than 8 of them. The heights are gathered in `z` as [`total_order`] keys.
fn ground_height(
    input: &BendInput,
    grid: &PointGrid,
    centre: [f64; 2],
    r: f64,
    z: &mut Vec<i64>,
) -> Option<f64> {
    z.clear();
    grid.for_each_within(input.x, input.y, centre[0], centre[1], r, |i| {
        if usable(input, i) && input.z[i].is_finite() {
            z.push(total_order(input.z[i]));
        }
    });
    if z.len() < 8 {
        return None;
    }
    let k = z.len() / 2;
    Some(from_total_order(*z.select_nth_unstable(k).1))
}

/// The key of `v` whose integer order is `f64::total_cmp`'s (the key `total_cmp` itself
/// compares): the k-th key is the k-th height's, and keys compare in one instruction.
fn total_order(v: f64) -> i64 {
    let b = v.to_bits() as i64;
    b ^ (((b >> 63) as u64) >> 1) as i64
}

/// The height whose [`total_order`] key is `k` (the map is its own inverse: it keeps the
/// sign bit that decides it).
fn from_total_order(k: i64) -> f64 {
    f64::from_bits(total_order(f64::from_bits(k as u64)) as u64)
}

/// The usable point nearest (horizontally) to `at` within `r`, lowest index on ties.
pub(super) fn nearest_usable(
    input: &BendInput,
    grid: &PointGrid,
    at: [f64; 3],
    r: f64,
) -> Option<u32> {
    let mut best: Option<(f64, usize)> = None;
    grid.for_each_within(input.x, input.y, at[0], at[1], r, |i| {
        if !usable(input, i) {
            return;
        }
        let d = (input.x[i] - at[0]).hypot(input.y[i] - at[1]);
        if best.is_none_or(|(bd, bi)| d < bd || (d == bd && i < bi)) {
            best = Some((d, i));
        }
    });
    best.map(|(_, i)| i as u32)
}

/// A RANSAC line fit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LineFit {
    /// A point on the line (centroid of the inliers).
    pub origin: [f64; 2],
    /// Unit direction.
    pub dir: [f64; 2],
    /// Number of inliers.
    pub inliers: usize,
    /// The inlier closest to the refined line.
    pub closest: u32,
}

/// Fits a 2D line to the points `pts` (indices into `x`, `y`) by RANSAC (Fischler and
/// Bolles 1981): pairs drawn with a ChaCha8 generator seeded by `rng_seed` (all pairs when
/// there are no more than `ransac_iterations`), the pair with most inliers wins (ties: the
/// smaller sum of inlier distances, then the earlier draw), then a total-least-squares
/// refit on its inliers. `None` when too few inliers (`ransac_min_inliers`,
/// `ransac_min_inlier_ratio`).
pub fn ransac_line(
    x: &[f64],
    y: &[f64],
    pts: &[u32],
    params: &BendParams,
    rng_seed: u64,
) -> Option<LineFit> {
    let m = pts.len();
    if m < 2 || m < params.ransac_min_inliers as usize {
        return None;
    }
    // Local coordinates about the first point: world coordinates are ~1e6 m.
    let (ox, oy) = (x[pts[0] as usize], y[pts[0] as usize]);
    let p: Vec<[f64; 2]> = pts
        .iter()
        .map(|&i| [x[i as usize] - ox, y[i as usize] - oy])
        .collect();
    let eps = params.ransac_inlier_m;
    let score = |a: [f64; 2], b: [f64; 2]| -> Option<(usize, f64)> {
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let l = dx.hypot(dy);
        if l < 1e-6 {
            return None;
        }
        let (nx, ny) = (-dy / l, dx / l);
        let mut count = 0;
        let mut sum = 0.0;
        for q in &p {
            let d = ((q[0] - a[0]) * nx + (q[1] - a[1]) * ny).abs();
            if d <= eps {
                count += 1;
                sum += d;
            }
        }
        Some((count, sum))
    };
    let mut best: Option<(usize, f64, usize, usize)> = None;
    let mut consider = |i: usize, j: usize| {
        if let Some((c, s)) = score(p[i], p[j]) {
            if best.is_none_or(|(bc, bs, _, _)| c > bc || (c == bc && s < bs)) {
                best = Some((c, s, i, j));
            }
        }
    };
    let pairs = m * (m - 1) / 2;
    if pairs <= params.ransac_iterations as usize {
        for i in 0..m {
            for j in i + 1..m {
                consider(i, j);
            }
        }
    } else {
        let mut rng = ChaCha8Rng::seed_from_u64(rng_seed);
        for _ in 0..params.ransac_iterations {
            let i = rng.gen_range(0..m);
            let mut j = rng.gen_range(0..m - 1);
            if j >= i {
                j += 1;
            }
            consider(i, j);
        }
    }
    let (_, _, bi, bj) = best?;
    let (a, b) = (p[bi], p[bj]);
    let l = (b[0] - a[0]).hypot(b[1] - a[1]);
    let (nx, ny) = (-(b[1] - a[1]) / l, (b[0] - a[0]) / l);
    let inl: Vec<usize> = (0..m)
        .filter(|&k| ((p[k][0] - a[0]) * nx + (p[k][1] - a[1]) * ny).abs() <= eps)
        .collect();
    if inl.len() < params.ransac_min_inliers as usize
        || (inl.len() as f64) < params.ransac_min_inlier_ratio * m as f64
    {
        return None;
    }
    // Total least squares on the inliers: direction of the covariance's major axis.
    let k = inl.len() as f64;
    let cx = inl.iter().map(|&i| p[i][0]).sum::<f64>() / k;
    let cy = inl.iter().map(|&i| p[i][1]).sum::<f64>() / k;
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for &i in &inl {
        let (dx, dy) = (p[i][0] - cx, p[i][1] - cy);
        sxx += dx * dx;
        sxy += dx * dy;
        syy += dy * dy;
    }
    let theta = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    let dir = [theta.cos(), theta.sin()];
    let (nx, ny) = (-dir[1], dir[0]);
    let closest = inl
        .iter()
        .map(|&i| (((p[i][0] - cx) * nx + (p[i][1] - cy) * ny).abs(), i))
        .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))
        .map(|(_, i)| pts[i])?;
    Some(LineFit {
        origin: [cx + ox, cy + oy],
        dir,
        inliers: inl.len(),
        closest,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bend::fixture::{drive_along_x, KeptPoints};

    #[test]
    fn end_rays_leave_no_stretch_within_the_reach_unseen() {
        // Profiles 0.3 m either side of their ray touch at 20 m: 0.6 m of arc, 1.72°.
        let step = radial_step_deg(0.3, 20.0);
        assert!((step - 1.7189).abs() < 1e-3, "{step}");
        let arc_at_reach = step.to_radians() * 20.0;
        assert!((arc_at_reach - 0.6).abs() < 1e-9);
        assert_eq!(radial_step_deg(0.3, 0.0), 0.0);
        assert_eq!(radial_step_deg(0.0, 20.0), 0.0);
    }

    /// 30 points on y = 0.5·x + 3 (x from 0 to 2.9 m, far from the origin), every third
    /// one moved 0.3–1.2 m off the line.
    fn line_with_outliers() -> (Vec<f64>, Vec<f64>) {
        let mut x = Vec::new();
        let mut y = Vec::new();
        for k in 0..30 {
            let xx = k as f64 * 0.1;
            let off = if k % 3 == 1 {
                0.3 + 0.03 * k as f64
            } else {
                0.0
            };
            x.push(600_000.0 + xx);
            y.push(4_000_000.0 + 0.5 * xx + 3.0 + off);
        }
        (x, y)
    }

    #[test]
    fn ransac_finds_the_line_through_outliers() {
        let (x, y) = line_with_outliers();
        let pts: Vec<u32> = (0..30).collect();
        let p = BendParams::default();
        let fit = ransac_line(&x, &y, &pts, &p, 7).unwrap();
        assert_eq!(fit.inliers, 20);
        // Slope 0.5: direction (2, 1)/√5 up to sign.
        let slope = fit.dir[1] / fit.dir[0];
        assert!((slope - 0.5).abs() < 1e-9, "{slope}");
        // Every inlier lies on the line, so the closest point is one of them.
        assert_ne!(fit.closest % 3, 1);
    }

    #[test]
    fn ransac_is_deterministic_for_a_seed() {
        let (x, y) = line_with_outliers();
        let pts: Vec<u32> = (0..30).collect();
        let p = BendParams {
            ransac_iterations: 12,
            ..BendParams::default()
        };
        let a = ransac_line(&x, &y, &pts, &p, 99);
        let b = ransac_line(&x, &y, &pts, &p, 99);
        assert_eq!(a, b);
        assert!(a.is_some());
    }

    /// A far curb 8 m left of a drive east along y = 0 (the road level below y = 8 m, the
    /// sidewalk 0.12 m up beyond it): scanlines every 0.1 m along, their returns 0.45 m
    /// apart across, each line's offset 2.25 cm past the one before, as on a curb its
    /// scanlines cross at a grazing angle. A profile 0.6 m long holds no return right beside
    /// the toe on one side; one 1.2 m long does.
    #[test]
    fn a_sparse_far_curb_is_seeded_from_longer_profiles() {
        const T0: f64 = 400_000_000.0;
        let (mut x, mut y, mut z, mut t) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for k in 0..300 {
            let px = 0.1 * f64::from(k);
            let mut py = 6.0 + (0.05 * f64::from(k)).fract() * 0.45;
            while py < 10.0 {
                x.push(px);
                y.push(py);
                z.push(if py < 8.0 {
                    0.0
                } else {
                    0.12 + 0.02 * (py - 8.0)
                });
                t.push(T0 + px / 10.0);
                py += 0.45;
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
        // Neither the default nor the widened profiles find the toe anywhere.
        let half_l = 2.0 * params.profile_half_length_m;
        for p in [&params, &widened(&params)] {
            for c in 0..15 {
                let at = [1.0 + 2.0 * f64::from(c), 0.0];
                let toe = first_toe_outward(
                    &input,
                    &grid,
                    at,
                    [1.0, 0.0],
                    [0.0, 1.0],
                    1.0,
                    half_l,
                    (PROFILE_SEED_NEAR_M, 15.0),
                    |profile| (profile.toe(), None),
                    p,
                    &mut Heights::default(),
                )
                .0;
                assert_eq!(toe, None, "a toe at {at:?}");
            }
        }
        let seeds = profile_seeds(&input, &grid, &route, &params);
        let left: Vec<&Seed> = seeds.iter().filter(|s| s.side == Side::Left).collect();
        assert!(left.len() >= 12, "{} left seeds", left.len());
        for s in left {
            let i = s.point as usize;
            assert!(
                (input.y[i] - 8.0).abs() <= 0.1,
                "seed at y = {:.3}",
                input.y[i]
            );
        }
    }

    #[test]
    fn a_corner_arc_whose_curb_before_it_is_unseen_is_seeded_by_turned_profiles() {
        const T0: f64 = 400_000_000.0;
        // The arc's middle: a curb at 45° to the route, y = x − 7 (toe), returns only
        // within 1.5 m of it (the curb before it lies where the vehicle's body hides it);
        // the curb top 0.15 m up, on the side away from the route.
        let (mut x, mut y, mut z, mut t) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for i in 0..400 {
            for j in 0..300 {
                let (px, py) = (5.0 + 0.05 * f64::from(i), 0.05 * f64::from(j));
                let off = (py - px + 7.0) / 2f64.sqrt();
                if off.abs() > 1.5 {
                    continue;
                }
                x.push(px);
                y.push(py);
                z.push(if off > 0.0 { 0.15 } else { 0.0 });
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
        // Profiles across the route see the step spread along their length: no toe.
        let half_l = 2.0 * params.profile_half_length_m;
        for (p, l) in [
            (&params, half_l),
            (&widened(&params), half_l),
            (&params, SPARSE_LENGTH_FACTOR * half_l),
        ] {
            for c in 0..10 {
                let at = [9.0 + 2.0 * f64::from(c), 0.0];
                let toe = first_toe_outward(
                    &input,
                    &grid,
                    at,
                    [1.0, 0.0],
                    [0.0, 1.0],
                    1.0,
                    l,
                    (PROFILE_SEED_NEAR_M, 15.0),
                    |profile| (profile.toe(), None),
                    p,
                    &mut Heights::default(),
                )
                .0;
                assert_eq!(toe, None, "a toe at {at:?}");
            }
        }
        let seeds = profile_seeds(&input, &grid, &route, &params);
        let left: Vec<&Seed> = seeds.iter().filter(|s| s.side == Side::Left).collect();
        assert!(left.len() >= 4, "{} left seeds", left.len());
        for s in left {
            let i = s.point as usize;
            let off = (input.y[i] - input.x[i] + 7.0) / 2f64.sqrt();
            assert!(off.abs() <= 0.15, "seed {off:.3} m off the toe");
            assert!((s.dir[0] - s.dir[1]).abs() < 1e-9, "direction {:?}", s.dir);
        }
    }

    #[test]
    fn total_order_keys_order_heights_as_total_cmp() {
        let v = [
            -f64::INFINITY,
            -1.5,
            -f64::MIN_POSITIVE,
            -0.0,
            0.0,
            5e-324,
            0.25,
            0.25 + f64::EPSILON,
            3.0e8,
            f64::INFINITY,
        ];
        for a in v {
            assert_eq!(from_total_order(total_order(a)).to_bits(), a.to_bits());
            for b in v {
                assert_eq!(
                    total_order(a).cmp(&total_order(b)),
                    a.total_cmp(&b),
                    "{a} {b}"
                );
            }
        }
    }

    #[test]
    fn too_few_inliers_give_no_seed() {
        // Points scattered on a circle of radius 1 m: no three collinear within 40 mm.
        let x: Vec<f64> = (0..12)
            .map(|k| (k as f64 * std::f64::consts::FRAC_PI_6).cos())
            .collect();
        let y: Vec<f64> = (0..12)
            .map(|k| (k as f64 * std::f64::consts::FRAC_PI_6).sin())
            .collect();
        let pts: Vec<u32> = (0..12).collect();
        assert_eq!(ransac_line(&x, &y, &pts, &BendParams::default(), 1), None);
    }
}
