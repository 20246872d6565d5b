//! Tracking (Honma et al. §2.7, Eq. 4–8): from each seed, forward and backward, the next
//! road-edge point is the point of minimum α·E_b + β·E_h + γ·E_v in the local point set S
//! around the position one search distance ahead along the search direction; the
//! direction then follows the picked points (Eq. 8). A track ends when S is empty or holds
//! no point with ρ of at least the stop threshold.
//!
//! Every edge comes out once: a track that reaches a point of an earlier track (within
//! `join_distance_m`) stops there, a seed already on a track starts nothing, and a track
//! that meets another end to end is joined to it into one polyline.

use super::claims::{Claims, Join};
use super::climb::{climbed_toe, CLIMBED_SHARE};
use super::face::face_toe_or_longer;
use super::grid::PointGrid;
use super::hole::{resumed_past_hole, Resumed};
use super::leg::leg_toe;
use super::params::{widened, BendParams};
use super::profile::{usable, Profile, ProfileToe};
use super::seed::Seed;
use super::sparse::sparse_toe;
use super::BendInput;
use crate::model::Side;
use crate::replay::PointStatus;

/// One tracked edge: its vertices in order along the driving direction.
///
/// A vertex is either a measured point (its id is the point's index into the columns) or
/// a toe found on a virtual profile ([`Profile::toe`]) between the points (its id is at
/// least the number of points, unique within one run). `xyz` holds every vertex's
/// position, so nothing downstream needs to tell the two apart.
#[derive(Clone, Debug, PartialEq)]
pub struct Track {
    /// Vertex ids, ordered along the edge.
    pub points: Vec<u32>,
    /// Vertex positions (world X, Y, Z, metres), one per id.
    pub xyz: Vec<[f64; 3]>,
    /// Side of the trajectory.
    pub side: Side,
}

/// A run of flush crossings' toes ([`Profile::flush_toe`]) that a track ended in, held
/// apart from it until the bridges are built: the vertex of the track it follows on from
/// (`anchor`, the track's last toe with a rise) and its vertices, outward from there.
///
/// A flush crossing's toes place its curb line to a few centimetres, which is worse than a
/// bridge's arc between the curbs on either side; where no bridge continues the track, they
/// are the only line across the cut.
#[derive(Clone, Debug, PartialEq)]
pub struct FlushTail {
    pub anchor: u32,
    pub verts: Vec<(u32, [f64; 3])>,
}

impl Track {
    /// A track of measured points only.
    pub fn measured(input: &BendInput, points: Vec<u32>, side: Side) -> Self {
        let xyz = points
            .iter()
            .map(|&p| {
                let i = p as usize;
                [input.x[i], input.y[i], input.z[i]]
            })
            .collect();
        Self { points, xyz, side }
    }
}

/// Tracks every seed (in the order given) and returns the edges, each once.
pub fn track_edges(
    input: &BendInput,
    grid: &PointGrid,
    seeds: &[Seed],
    params: &BendParams,
) -> Vec<Track> {
    let (tracks, tails) = track_edges_with_tails(input, grid, seeds, params);
    attach_tails(tracks, tails)
}

/// [`track_edges`] with the runs of flush crossings' toes that tracks end in held apart
/// ([`FlushTail`]), to be put back by [`attach_tails`] where no bridge
/// continues the track.
pub fn track_edges_with_tails(
    input: &BendInput,
    grid: &PointGrid,
    seeds: &[Seed],
    params: &BendParams,
) -> (Vec<Track>, Vec<FlushTail>) {
    let mut tails: Vec<FlushTail> = Vec::new();
    let mut claims = Claims::new(params.join_distance_m);
    // Tracks by id; merged tracks leave `None` behind and point to their root.
    let mut tracks: Vec<Option<Track>> = Vec::new();
    let mut parent: Vec<usize> = Vec::new();
    fn root(parent: &[usize], mut t: usize) -> usize {
        while parent[t] != t {
            t = parent[t];
        }
        t
    }
    // Ids of virtual vertices count up from the number of points.
    let mut next_virtual = input.x.len() as u32;

    for seed in seeds {
        let s = seed.point as usize;
        // A seed from a virtual profile may sit on a point without a bend angle.
        if s >= input.x.len() || !usable(input, s) {
            continue;
        }
        let id = tracks.len();
        if claims
            .near(seed.point, input.x[s], input.y[s], id)
            .is_some()
        {
            continue; // this stretch has been tracked already
        }
        let dir = [seed.dir[0], seed.dir[1], 0.0];
        // Which side of the forward direction the curb rises on: measured at the seed, or
        // from the side of the trajectory when the seed sees no step.
        let up_fwd = up_side(input, grid, s, seed.dir).unwrap_or(match seed.side {
            Side::Left => 1.0,
            Side::Right => -1.0,
        });
        let mut one_way = |d: [f64; 3], up: f64, prior: usize| {
            track_one_way(
                input,
                grid,
                &claims,
                id,
                seed.point,
                prior,
                d,
                up,
                &mut next_virtual,
                params,
            )
        };
        let (mut fwd, mut fwd_join, mut fwd_tail) = one_way(dir, up_fwd, 0);
        let (bwd, bwd_join, mut bwd_tail) = one_way([-dir[0], -dir[1], 0.0], -up_fwd, fwd.len());
        // A seed just before a curb cut: forward, the track had too little curb behind it
        // to follow the cut; with the curb tracked backwards it has.
        if fwd_join.is_none() && fwd.len() < CUT_MIN_TRACK_STEPS && bwd.len() >= CUT_MIN_TRACK_STEPS
        {
            (fwd, fwd_join, fwd_tail) = one_way(dir, up_fwd, bwd.len());
        }
        let seed_xyz = [input.x[s], input.y[s], input.z[s]];
        let mut verts: Vec<(u32, [f64; 3])> = bwd.iter().rev().copied().collect();
        verts.push((seed.point, seed_xyz));
        verts.extend_from_slice(&fwd);
        // A track shorter than a bridge's tangent without its runs of flush toes (one that
        // starts on the cut) keeps them: its tangent is theirs.
        let length: f64 = verts
            .windows(2)
            .map(|w| (w[1].1[0] - w[0].1[0]).hypot(w[1].1[1] - w[0].1[1]))
            .sum();
        if length < FLUSH_HOLD_MIN_M {
            verts.splice(0..0, bwd_tail.iter().rev().copied());
            verts.append(&mut fwd_tail);
            bwd_tail.clear();
        }
        let points: Vec<u32> = verts.iter().map(|v| v.0).collect();
        let xyz: Vec<[f64; 3]> = verts.iter().map(|v| v.1).collect();
        claims.add_track(&points, &xyz, id);
        // The held runs claim their stretch as the track does.
        let seed_v = (seed.point, seed_xyz);
        for (run, tail) in [(&fwd, fwd_tail), (&bwd, bwd_tail)] {
            if !tail.is_empty() {
                let anchor = *run.last().unwrap_or(&seed_v);
                let (p, x): (Vec<u32>, Vec<[f64; 3]>) =
                    std::iter::once(anchor).chain(tail.iter().copied()).unzip();
                claims.add_track(&p, &x, id);
                tails.push(FlushTail {
                    anchor: anchor.0,
                    verts: tail,
                });
            }
        }
        tracks.push(Some(Track {
            points,
            xyz,
            side: seed.side,
        }));
        parent.push(id);

        // Join end to end with the tracks this one ran into.
        let fwd_end = fwd.last().map_or(seed.point, |v| v.0);
        let bwd_end = bwd.last().map_or(seed.point, |v| v.0);
        for (join, end_point) in [(fwd_join, fwd_end), (bwd_join, bwd_end)] {
            let Some(j) = join else { continue };
            let me = root(&parent, id);
            let other = root(&parent, j.track);
            if me == other {
                continue;
            }
            let (Some(a), Some(b)) = (tracks[me].as_ref(), tracks[other].as_ref()) else {
                continue;
            };
            if a.side != b.side {
                continue;
            }
            let Some(pos) = b.points.iter().position(|&p| p == j.point) else {
                continue;
            };
            // Which end of this (possibly already joined) track ran into the other one.
            let Some(my_pos) = a.points.iter().position(|&p| p == end_point) else {
                continue;
            };
            let at_end = 2 * my_pos >= a.points.len();
            const END_TOL: usize = 3;
            let at_other_start = pos <= END_TOL;
            let at_other_end = pos + 1 + END_TOL >= b.points.len();
            if !(at_other_start || at_other_end) {
                continue; // met in the middle: two edges meeting, keep both
            }
            let mut a_v: Vec<(u32, [f64; 3])> = a
                .points
                .iter()
                .copied()
                .zip(a.xyz.iter().copied())
                .collect();
            let mut b_v: Vec<(u32, [f64; 3])> = b
                .points
                .iter()
                .copied()
                .zip(b.xyz.iter().copied())
                .collect();
            // Orient so that the join is a's end and b's start.
            if !at_end {
                a_v.reverse();
            }
            if !at_other_start {
                b_v.reverse();
            }
            a_v.extend_from_slice(&b_v);
            // Keep the driving-direction order of the longer piece.
            let keep_a_order = a.points.len() >= b.points.len();
            if (keep_a_order && !at_end) || (!keep_a_order && !at_other_start) {
                a_v.reverse();
            }
            let side = a.side;
            tracks[me] = Some(Track {
                points: a_v.iter().map(|v| v.0).collect(),
                xyz: a_v.iter().map(|v| v.1).collect(),
                side,
            });
            tracks[other] = None;
            parent[other] = me;
        }
    }
    (tracks.into_iter().flatten().collect(), tails)
}

/// Whether the ground rises on the left (+1) or the right (−1) of the horizontal direction
/// `dir` at point `i`: mean heights of the strips 0.1–0.4 m either side, ±0.3 m along.
/// `None` when the two differ by less than 20 mm (no step to go by).
fn up_side(input: &BendInput, grid: &PointGrid, i: usize, dir: [f64; 2]) -> Option<f64> {
    let diff = side_step(input, grid, i, dir)?;
    (diff.abs() >= 0.02).then_some(diff.signum())
}

/// Mean height of the strip 0.1–0.4 m left of the horizontal direction `dir` at point `i`
/// less that of the strip as far right, ±0.3 m along, metres; `None` where either strip
/// holds fewer than 3 points.
fn side_step(input: &BendInput, grid: &PointGrid, i: usize, dir: [f64; 2]) -> Option<f64> {
    let l = dir[0].hypot(dir[1]);
    if l.is_nan() || l <= 1e-9 {
        return None;
    }
    let h = [dir[0] / l, dir[1] / l];
    let n = [-h[1], h[0]];
    let (px, py, pz) = (input.x[i], input.y[i], input.z[i]);
    let (mut sl, mut nl, mut sr, mut nr) = (0.0, 0usize, 0.0, 0usize);
    grid.for_each_within(input.x, input.y, px, py, 0.5, |j| {
        if !usable(input, j) || (input.z[j] - pz).abs() > 0.4 {
            return;
        }
        let d = [input.x[j] - px, input.y[j] - py];
        let along = d[0] * h[0] + d[1] * h[1];
        let across = d[0] * n[0] + d[1] * n[1];
        if along.abs() > 0.3 {
            return;
        }
        if (0.1..=0.4).contains(&across) {
            sl += input.z[j];
            nl += 1;
        } else if (-0.4..=-0.1).contains(&across) {
            sr += input.z[j];
            nr += 1;
        }
    });
    if nl < 3 || nr < 3 {
        return None;
    }
    Some(sl / nl as f64 - sr / nr as f64)
}

/// Weight of the newest step in the running turn per step (an exponential moving average
/// over about five steps: long enough to average the toe points' scatter out, short enough
/// to follow a 4 m corner radius).
const TURN_EMA: f64 = 0.2;

/// Shortest horizontal span of the difference vector of Eq. 8, metres: the vector runs to
/// the new vertex from the newest earlier vertex at least this far back (or the track's
/// start), not from the last position. Consecutive vertices lie one step (0.1–0.15 m)
/// apart and scatter across the toe by the point spacing or, on a virtual profile, by a
/// few centimetres, so a one-step vector swings the search direction by 10–20°, and
/// across a gap the track carries that swing off the curb; over half a metre the scatter
/// turns it by a few degrees, and a 3 m corner radius makes it lag by under 5°. A vector
/// from the last position would also start at an extrapolated one after a gap.
const DIR_BASE_M: f64 = 0.5;

/// Largest height difference between consecutive toes picked by ρ before the virtual
/// profile is asked instead, metres: 0.15 m apart on a 10 % grade they differ by 15 mm.
const MAX_TOE_DZ_M: f64 = 0.04;

/// Vertices a track must have before it may follow a curb cut's toe
/// ([`Profile::cut_toe`]): 1.5 m of curb, so that the break of slope is only ever followed
/// along a line already tracked.
const CUT_MIN_TRACK_STEPS: usize = 10;

/// Shortest track, without the runs of flush toes it ends in, whose runs are held apart
/// until the bridges are built ([`FlushTail`]), metres: the bridge's tangent span.
const FLUSH_HOLD_MIN_M: f64 = 2.0;

/// Shortest run on curb-cut toes kept at the end of a track, metres (see
/// [`track_one_way`]): a third of the shortest cut.
const CUT_MIN_KEEP_M: f64 = 1.0;

/// Farthest a virtual profile's toe may lie from a weak pick to confirm it, metres:
/// about the scatter of picks across the toe.
const WEAK_CONFIRM_M: f64 = 0.1;

/// Least height step across a weak pick that confirms it as a toe, metres (the ground
/// 0.1–0.4 m beside it on the curb side above that on the road side): under a 60 mm curb,
/// above a road's crossfall over that width.
const WEAK_CONFIRM_STEP_M: f64 = 0.03;

/// Length of track, metres, back from its end over which [`line_ahead`] fits the curb
/// line a cut's toe is sought along: long enough to average the ±0.1 m scatter of cut toes
/// out, short enough that a 30 m radius leaves the line by under 2 cm at its end.
const CUT_LINE_M: f64 = 2.0;

/// Fewest vertices, and shortest span in metres, of the fit of [`line_ahead`].
const CUT_LINE_MIN_VERTS: usize = 6;
const CUT_LINE_MIN_SPAN_M: f64 = 1.0;

/// The curb line a track follows into a cut: the least-squares line (orthogonal
/// distances, horizontal) through its vertices over the last [`CUT_LINE_M`] from `cur`,
/// oriented along `along`. Returns the point `d_s` past the foot of `cur` on that line,
/// and the line's unit direction; `None` when the track is too short for a fit or the
/// line turns more than 45° from `along`.
///
/// Eq. 8 turns the search direction towards every new vertex; the toes of a low-lip cut
/// scatter by up to ±0.1 m across the line over 0.15 m steps, so a track that follows
/// them walks towards the ramp behind, whose top is the next break of slope. The fitted
/// line does not follow one toe's scatter, and a cut keeps the line of the curb it
/// interrupts.
fn line_ahead(
    picked: &[(u32, [f64; 3])],
    cur: [f64; 3],
    along: [f64; 2],
    d_s: f64,
) -> Option<([f64; 2], [f64; 2])> {
    let pts: Vec<[f64; 2]> = picked
        .iter()
        .rev()
        .map(|v| [v.1[0], v.1[1]])
        .take_while(|p| (p[0] - cur[0]).hypot(p[1] - cur[1]) <= CUT_LINE_M)
        .collect();
    if pts.len() < CUT_LINE_MIN_VERTS {
        return None;
    }
    let far = pts
        .iter()
        .map(|p| (p[0] - cur[0]).hypot(p[1] - cur[1]))
        .fold(0.0, f64::max);
    if far < CUT_LINE_MIN_SPAN_M {
        return None;
    }
    let n = pts.len() as f64;
    let mx = pts.iter().map(|p| p[0]).sum::<f64>() / n;
    let my = pts.iter().map(|p| p[1]).sum::<f64>() / n;
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for p in &pts {
        let (dx, dy) = (p[0] - mx, p[1] - my);
        sxx += dx * dx;
        sxy += dx * dy;
        syy += dy * dy;
    }
    // Principal axis of the 2×2 scatter matrix.
    let theta = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    let mut a = [theta.cos(), theta.sin()];
    let dot = a[0] * along[0] + a[1] * along[1];
    if dot < 0.0 {
        a = [-a[0], -a[1]];
    }
    if dot.abs() < std::f64::consts::FRAC_1_SQRT_2 {
        return None;
    }
    let s = (cur[0] - mx) * a[0] + (cur[1] - my) * a[1] + d_s;
    Some(([mx + s * a[0], my + s * a[1]], a))
}

/// The toe of the curb cut a track is following (`cut` = (length followed, index of its
/// first vertex), the latter `None` when the last vertex is no cut toe), sought on the
/// line of the track's last metres ([`line_ahead`]) and ahead of `cur`, with that line's
/// direction; `None` off a cut, past `cut_follow_max_m`, or where the profile shows no
/// cut toe.
#[allow(clippy::too_many_arguments)]
fn cut_on_line(
    input: &BendInput,
    grid: &PointGrid,
    picked: &[(u32, [f64; 3])],
    cur: [f64; 3],
    along: [f64; 2],
    up: f64,
    cut: (f64, Option<usize>),
    params: &BendParams,
) -> Option<(ProfileToe, [f64; 2])> {
    let d_s = params.search_distance_m;
    if cut.1.is_none() || cut.0 + d_s > params.cut_follow_max_m || !params.profile_fallback {
        return None;
    }
    let (q, a) = line_ahead(picked, cur, along, d_s)?;
    let l = 2.0 * params.profile_half_length_m;
    let toe = Profile {
        input,
        grid,
        params,
        centre: [q[0], q[1], cur[2]],
        along: a,
        up,
        half_l: l,
    }
    .cut_toe()?;
    let ahead = (toe.xyz[0] - cur[0]) * along[0] + (toe.xyz[1] - cur[1]) * along[1];
    (ahead > 0.25 * d_s).then_some((toe, a))
}

/// Farthest back from the toe a track brought down from the top edge drops the vertices
/// it picked above that toe, metres: the few steps of a climb up the face.
const CLIMB_DROP_M: f64 = 1.0;

/// Largest angle between a track's search direction and the driving direction, degrees,
/// for the track to take a wide profile's toe ([`wide_toe`]): a curb along the road turns
/// from the driving direction by the road's curvature over the scanner's look-ahead (under
/// 25° at a 30 m radius), a corner's and a side street's curb by up to 60–120°.
const ALONG_ROAD_MAX_DEG: f64 = 40.0;

/// Whether the horizontal unit direction `a` runs along the road, either way: within
/// [`ALONG_ROAD_MAX_DEG`] of the driving direction when the track's newest measured vertex
/// (or `start`) was scanned. True where the trajectory does not say.
///
/// Corners and side streets keep the profiles of the default width: a wider one there
/// reaches across the mouth's fillet to other steps.
fn along_the_road(input: &BendInput, picked: &[(u32, [f64; 3])], start: u32, a: [f64; 2]) -> bool {
    let n = input.x.len();
    let i = picked
        .iter()
        .rev()
        .map(|v| v.0 as usize)
        .find(|&i| i < n)
        .unwrap_or(start as usize);
    let Some(pose) = input.t.get(i).and_then(|&t| input.trajectory.pose_at(t)) else {
        return true;
    };
    let f = pose.forward();
    (a[0] * f[0] + a[1] * f[1]).abs() >= ALONG_ROAD_MAX_DEG.to_radians().cos()
}

/// The toe on `profile` [`widened`], for a track along the road where the profiles of the
/// default width show none.
///
/// Far from the scanner, on a curb its scanlines cross at a grazing angle, the profiles of
/// the default width find no toe along stretches of a curb in plain view, and the track
/// ends in gaps there; a wider profile holds more ground on either side of the step and
/// reaches a toe farther from the search position.
fn wide_toe(profile: Profile) -> Option<ProfileToe> {
    Profile {
        params: &widened(profile.params),
        ..profile
    }
    .toe()
}

/// `v` (a unit vector) turned to the horizontal heading `a` (a unit vector), keeping its
/// vertical component.
fn with_heading(v: [f64; 3], a: [f64; 2]) -> [f64; 3] {
    let h = (1.0 - v[2] * v[2]).max(0.0).sqrt();
    [a[0] * h, a[1] * h, v[2]]
}

/// Largest vertical component of the search direction (a grade of about 15 %).
const MAX_CLIMB: f64 = 0.15;

/// `v` (a unit vector) with its vertical component clamped to ±[`MAX_CLIMB`], keeping its
/// horizontal direction.
fn clamp_climb(v: [f64; 3]) -> [f64; 3] {
    if v[2].abs() <= MAX_CLIMB {
        return v;
    }
    let h = v[0].hypot(v[1]);
    if h < 1e-9 {
        return v;
    }
    let k = (1.0 - MAX_CLIMB * MAX_CLIMB).sqrt() / h;
    [v[0] * k, v[1] * k, MAX_CLIMB.copysign(v[2])]
}

fn unit3(v: [f64; 3]) -> Option<[f64; 3]> {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    (l > 1e-9).then(|| [v[0] / l, v[1] / l, v[2] / l])
}

/// A track's vertices as (id, position) pairs.
type Vertices = Vec<(u32, [f64; 3])>;

/// Tracks from `start` along `dir0` until the stop rule of §2.7 fires or another track is
/// reached. Where S holds no point with ρ of at least the stop threshold, the toe is looked
/// for on a virtual profile across the search direction ([`Profile::toe`]; the curb rises
/// on the side `up` of the direction: +1 left, −1 right) before the step counts as a gap.
/// `prior_steps` counts the vertices the track already has behind `start` (the other
/// direction's), which count towards [`CUT_MIN_TRACK_STEPS`].
/// Returns the vertices picked (not including `start`), the join, if any, and the run of
/// flush crossings' toes the track ends in, held apart from the vertices ([`FlushTail`]).
#[allow(clippy::too_many_arguments)]
fn track_one_way(
    input: &BendInput,
    grid: &PointGrid,
    claims: &Claims,
    own: usize,
    start: u32,
    prior_steps: usize,
    dir0: [f64; 3],
    up: f64,
    next_virtual: &mut u32,
    params: &BendParams,
) -> (Vertices, Option<Join>, Vertices) {
    let s = start as usize;
    let mut cur = [input.x[s], input.y[s], input.z[s]];
    // The side the curb rises on; a track brought down from the top edge takes the side
    // the ground shows there.
    let mut up = up;
    let Some(mut v) = unit3(dir0) else {
        return (Vec::new(), None, Vec::new());
    };
    let mut prev_u = v;
    let mut picked: Vec<(u32, [f64; 3])> = Vec::new();
    let mut own_pts: std::collections::HashSet<u32> = std::collections::HashSet::new();
    own_pts.insert(start);
    let mut gap = 0u32;
    // Turn of the search direction per step (radians, left positive), averaged: carries
    // the track round a corner across a gap.
    let mut turn = 0.0f64;
    let stop_rho = params.stop_rho_deg;
    let d_s = params.search_distance_m;
    let mut set: Vec<usize> = Vec::new();
    // Length followed on curb-cut toes since the last toe with ρ or a step, metres.
    let mut cut_run_m = 0.0f64;
    // Index in `picked` of the first vertex of that run.
    let mut cut_from: Option<usize> = None;
    // Length gone on unconfirmed weak picks and gap steps since the last confirmed toe,
    // metres, and the index in `picked` where that stretch starts.
    let mut weak_run_m = 0.0f64;
    let mut weak_from: Option<usize> = None;
    // Flush crossings' toes ([`Profile::flush_toe`]) among the vertices picked.
    let mut flush_ids: std::collections::HashSet<u32> = std::collections::HashSet::new();

    for _ in 0..params.max_steps {
        // Whether this step's toe is a flush crossing's.
        let mut flush_step = false;
        // Horizontal direction of the curb line this step's toe is found along, if any (a
        // cut's toe, see [`line_ahead`], or a toe below the top edge): it replaces the
        // direction of the step to that toe.
        let mut cut_dir: Option<[f64; 2]> = None;
        // The search position (Fig. 7): one search distance ahead along v.
        let pred = [
            cur[0] + d_s * v[0],
            cur[1] + d_s * v[1],
            cur[2] + d_s * v[2],
        ];
        let vh = [v[0], v[1]];
        let vh_len = vh[0].hypot(vh[1]).max(1e-12);
        set.clear();
        grid.for_each_within(
            input.x,
            input.y,
            pred[0],
            pred[1],
            params.search_radius_m,
            |i| {
                if input.status[i] != Some(PointStatus::Kept)
                    || (input.z[i] - pred[2]).abs() > params.search_half_height_m
                    || own_pts.contains(&(i as u32))
                {
                    return;
                }
                // Only points ahead of the current position: the track must progress.
                let ahead =
                    ((input.x[i] - cur[0]) * vh[0] + (input.y[i] - cur[1]) * vh[1]) / vh_len;
                if ahead > 0.25 * d_s {
                    set.push(i);
                }
            },
        );
        let max_rho = set
            .iter()
            .map(|&i| input.rho_deg[i] as f64)
            .fold(f64::NEG_INFINITY, f64::max);
        let next: (u32, [f64; 3]) = if set.is_empty() || max_rho < stop_rho {
            // §2.7 stop rule, unless a virtual profile across the search direction shows
            // the toe; optionally bridge a few empty or weak steps.
            let along = [vh[0] / vh_len, vh[1] / vh_len];
            let found = if params.profile_fallback && *next_virtual < u32::MAX {
                // Heights are gated around the last vertex's, not the prediction's: a few
                // steps climbing a curb face tilt v upwards, and the profile must still
                // see the road.
                // Far from the scanner the points are sparse along the scanlines: a
                // profile twice as long is tried where the short one shows no toe.
                let c = [pred[0], pred[1], cur[2]];
                let l = params.profile_half_length_m;
                // A track along the road tries a wider profile next (a far curb crossed at
                // a grazing angle). Where the scanlines run along the curb, each at one
                // offset across the profile, the step between their levels shows the toe;
                // where the returns are sparse (a side street's far leg), a longer profile.
                let profile = Profile {
                    input,
                    grid,
                    params,
                    centre: c,
                    along,
                    up,
                    half_l: l,
                };
                let long = profile.with_half_l(2.0 * l);
                let toe = profile
                    .toe_or_longer()
                    .or_else(|| {
                        along_the_road(input, &picked, start, along)
                            .then(|| wide_toe(long))
                            .flatten()
                    })
                    .or_else(|| sparse_toe(&long, &picked))
                    .or_else(|| {
                        params
                            .leg_toes
                            .then(|| leg_toe(&profile, &picked))
                            .flatten()
                    })
                    // On rings (the only input with a view past the points' ends), a face
                    // a ring slides along.
                    .or_else(|| {
                        params
                            .end_view
                            .is_some()
                            .then(|| face_toe_or_longer(&profile))
                            .flatten()
                    });
                // Neither ρ nor a step: a curb cut's toe continues the curb's line as a
                // break of slope, followed for at most `cut_follow_max_m`, and only by a
                // track that has followed a curb before it.
                let cut_ok = cut_run_m + d_s <= params.cut_follow_max_m
                    && picked.len() + prior_steps >= CUT_MIN_TRACK_STEPS;
                match toe {
                    Some(t) => {
                        cut_run_m = 0.0;
                        cut_from = None;
                        Some(t)
                    }
                    None if cut_ok => {
                        // The cut's toe is sought on the line of the track's last metres,
                        // not one step along v: v follows the scatter of the toes before.
                        let line = line_ahead(&picked, cur, along, d_s);
                        let (cc, ca) = line.map_or((c, along), |(p, a)| ([p[0], p[1], cur[2]], a));
                        let on_line = Profile {
                            centre: cc,
                            along: ca,
                            ..long
                        };
                        let t = on_line.cut_toe().or_else(|| {
                            flush_step = true;
                            on_line.flush_toe()
                        });
                        if t.is_some() {
                            cut_run_m += d_s;
                            cut_from.get_or_insert(picked.len());
                            cut_dir = line.map(|(_, a)| a);
                        }
                        t
                    }
                    None => None,
                }
            } else {
                None
            };
            // A virtual toe must lie ahead, as S's points must.
            let ahead = |t: &ProfileToe| {
                (t.xyz[0] - cur[0]) * along[0] + (t.xyz[1] - cur[1]) * along[1] > 0.25 * d_s
            };
            // A track on the curb's top edge comes back down to the toe below it.
            let found = match found.filter(ahead) {
                Some(t) => Some(t),
                None if params.profile_fallback && *next_virtual < u32::MAX => {
                    flush_step = false;
                    let c = [pred[0], pred[1], cur[2]];
                    climbed_toe(input, grid, c, along, params.profile_half_length_m, params)
                        .filter(|(t, _)| ahead(t))
                        .map(|(t, side)| {
                            up = side;
                            // The search keeps its heading: the step down to the toe runs
                            // across the curb, not along it.
                            cut_dir = Some(along);
                            cut_run_m = 0.0;
                            cut_from = None;
                            // The vertices on the face and the top edge are no toes.
                            while let Some(&(_, q)) = picked.last() {
                                let near = (q[0] - t.xyz[0]).hypot(q[1] - t.xyz[1]) <= CLIMB_DROP_M;
                                if near && q[2] > t.xyz[2] + CLIMBED_SHARE * t.step_m {
                                    picked.pop();
                                } else {
                                    break;
                                }
                            }
                            t
                        })
                }
                None => None,
            };
            match found {
                Some(toe) => {
                    weak_run_m = 0.0;
                    weak_from = None;
                    let id = *next_virtual;
                    *next_virtual += 1;
                    (id, toe.xyz)
                }
                None if gap < params.max_gap_steps
                    && !(params.weak_run_max_m > 0.0
                        && weak_run_m + d_s > params.weak_run_max_m) =>
                {
                    gap += 1;
                    weak_run_m += d_s;
                    weak_from.get_or_insert(picked.len());
                    cur = pred;
                    let (c, sn) = (turn.cos(), turn.sin());
                    v = [c * v[0] - sn * v[1], sn * v[0] + c * v[1], v[2]];
                    continue;
                }
                // Where the gap steps end, a track that has followed a curb crosses a hole
                // in the returns to where they resume on its line.
                None => {
                    let z0 = picked.last().map_or(input.z[s], |q| q.1[2]);
                    let hole = (picked.len() + prior_steps >= CUT_MIN_TRACK_STEPS
                        && *next_virtual < u32::MAX)
                        .then(|| {
                            resumed_past_hole(
                                input,
                                grid,
                                [cur[0], cur[1], z0],
                                along,
                                turn,
                                up,
                                |i| own_pts.contains(&(i as u32)),
                                params,
                            )
                        })
                        .flatten();
                    let Some(hole) = hole else { break };
                    weak_run_m = 0.0;
                    weak_from = None;
                    match hole {
                        Resumed::Point(i) => (i as u32, [input.x[i], input.y[i], input.z[i]]),
                        Resumed::Toe(t) => {
                            let id = *next_virtual;
                            *next_virtual += 1;
                            (id, t.xyz)
                        }
                    }
                }
            }
        } else {
            // μ_ρ, σ_ρ over S (Eq. 5).
            let k = set.len() as f64;
            let mu = set.iter().map(|&i| input.rho_deg[i] as f64).sum::<f64>() / k;
            let var = set
                .iter()
                .map(|&i| (input.rho_deg[i] as f64 - mu).powi(2))
                .sum::<f64>()
                / k;
            let sigma = var.sqrt().max(params.min_sigma_rho_deg);
            let v_elev = v[2].atan2(vh_len);
            let mut best: Option<(f64, usize)> = None;
            for &i in &set {
                let d = [
                    input.x[i] - cur[0],
                    input.y[i] - cur[1],
                    input.z[i] - cur[2],
                ];
                let dh = d[0].hypot(d[1]);
                let e_b = -(input.rho_deg[i] as f64 - mu) / sigma;
                // Horizontal angle between v and d (Eq. 6), in [0, π].
                let cross = vh[0] * d[1] - vh[1] * d[0];
                let dot = vh[0] * d[0] + vh[1] * d[1];
                let th_h = cross.atan2(dot).abs();
                // Vertical angle between v and d (Eq. 7), in [0, π/2] after clamping.
                let th_v = (d[2].atan2(dh) - v_elev)
                    .abs()
                    .min(std::f64::consts::FRAC_PI_2);
                let e = params.alpha * e_b
                    + params.beta * th_h / std::f64::consts::PI
                    + params.gamma * 2.0 * th_v / std::f64::consts::PI;
                if best.is_none_or(|(be, bi)| e < be || (e == be && i < bi)) {
                    best = Some((e, i));
                }
            }
            let Some((_, n)) = best else { break };
            let cut_before = (cut_run_m, cut_from);
            cut_run_m = 0.0;
            cut_from = None;
            // Consecutive toes lie at nearly one height; a pick well above or below the
            // last vertex is on the curb face or top (far from the scanner, where ρ is
            // noisy), so the virtual profile's toe is taken instead when there is one.
            let jumped = (input.z[n] - cur[2]).abs() > MAX_TOE_DZ_M;
            let along = [vh[0] / vh_len, vh[1] / vh_len];
            let c = [pred[0], pred[1], cur[2]];
            let l = params.profile_half_length_m;
            let profile = Profile {
                input,
                grid,
                params,
                centre: c,
                along,
                up,
                half_l: l,
            };
            let long = profile.with_half_l(2.0 * l);
            match (jumped && params.profile_fallback && *next_virtual < u32::MAX)
                .then(|| profile.toe_or_longer())
                .flatten()
                .filter(|t| {
                    (t.xyz[0] - cur[0]) * along[0] + (t.xyz[1] - cur[1]) * along[1] > 0.25 * d_s
                }) {
                Some(toe) => {
                    weak_run_m = 0.0;
                    weak_from = None;
                    let id = *next_virtual;
                    *next_virtual += 1;
                    (id, toe.xyz)
                }
                None => {
                    let p = [input.x[n], input.y[n], input.z[n]];
                    let weak = (input.rho_deg[n] as f64) < params.weak_rho_deg;
                    // On a cut, a weak pick is road noise beside the toe: the cut's toe on
                    // the track's line is taken instead where there is one.
                    let on_line = if weak {
                        cut_on_line(input, grid, &picked, cur, along, up, cut_before, params)
                    } else {
                        None
                    };
                    if let Some((toe, a)) = on_line {
                        (cut_run_m, cut_from) = (cut_before.0 + d_s, cut_before.1);
                        cut_dir = Some(a);
                        weak_run_m = 0.0;
                        weak_from = None;
                        let id = *next_virtual;
                        *next_virtual += 1;
                        (id, toe.xyz)
                    } else {
                        // A weak pick counts as the curb only where the ground steps up beside it
                        // or a virtual profile shows a toe there; otherwise it adds to the
                        // unconfirmed stretch.
                        if weak && params.weak_run_max_m > 0.0 {
                            let near = |t: &ProfileToe| {
                                (t.xyz[0] - p[0]).hypot(t.xyz[1] - p[1]) <= WEAK_CONFIRM_M
                            };
                            let cut_ok = picked.len() + prior_steps >= CUT_MIN_TRACK_STEPS
                                && params.cut_follow_max_m > 0.0;
                            let confirmed = side_step(input, grid, n, along)
                                .is_some_and(|d| d * up >= WEAK_CONFIRM_STEP_M)
                                || long.toe().filter(near).is_some()
                                || (cut_ok && long.cut_toe().filter(near).is_some());
                            if confirmed {
                                weak_run_m = 0.0;
                                weak_from = None;
                            } else {
                                weak_run_m += (p[0] - cur[0]).hypot(p[1] - cur[1]);
                                weak_from.get_or_insert(picked.len());
                                if weak_run_m > params.weak_run_max_m {
                                    break;
                                }
                            }
                        } else {
                            weak_run_m = 0.0;
                            weak_from = None;
                        }
                        (n as u32, p)
                    }
                }
            }
        };
        let (n, p) = next;
        if let Some(j) = claims.near(n, p[0], p[1], own) {
            return (picked, Some(j), Vec::new());
        }
        let start_xyz = [input.x[s], input.y[s], input.z[s]];
        let base = picked
            .iter()
            .rev()
            .map(|v| v.1)
            .chain(std::iter::once(start_xyz))
            .find(|q| (p[0] - q[0]).hypot(p[1] - q[1]) >= DIR_BASE_M)
            .unwrap_or(start_xyz);
        let Some(u) = unit3([p[0] - base[0], p[1] - base[1], p[2] - base[2]])
            .or_else(|| unit3([p[0] - cur[0], p[1] - cur[1], p[2] - cur[2]]))
        else {
            break;
        };
        // Eq. 8: v_k = a·v_{k−1} + b·v_{k−2} over the last two difference vectors, each
        // spanning at least `DIR_BASE_M`.
        let v_new = unit3([
            params.a * u[0] + params.b * prev_u[0],
            params.a * u[1] + params.b * prev_u[1],
            params.a * u[2] + params.b * prev_u[2],
        ])
        .unwrap_or(u);
        // Roads climb at most a few per cent: a steeper v comes from points picked on a
        // curb face, and would lift the search position off the ground within a few gap
        // steps.
        let v_new = clamp_climb(v_new);
        // On a cut's toe the direction is the fitted line's, and so is the last difference
        // vector's: one toe's scatter across the line does not turn the search.
        let (v_new, u) = match cut_dir {
            Some(a) => (with_heading(v_new, a), with_heading(u, a)),
            None => (v_new, u),
        };
        if gap == 0 {
            let dturn =
                (v[0] * v_new[1] - v[1] * v_new[0]).atan2(v[0] * v_new[0] + v[1] * v_new[1]);
            turn += TURN_EMA * (dturn - turn);
        }
        v = v_new;
        prev_u = u;
        if flush_step {
            flush_ids.insert(n);
        }
        picked.push((n, p));
        own_pts.insert(n);
        cur = p;
        gap = 0;
    }
    // A short run on curb-cut toes that the track ends in is a few breaks of slope the
    // prediction happened to meet, not a cut followed: it is dropped, so that the track
    // ends where the curb did (and its end's tangent, which a bridge reads, is the curb's).
    if let Some(k) = cut_from.filter(|_| cut_run_m < CUT_MIN_KEEP_M) {
        picked.truncate(k);
    }
    // Nor does a track end in a stretch no toe confirms: it ends at its last curb.
    if let Some(k) = weak_from {
        picked.truncate(k);
    }
    // A run of flush crossings' toes the track ends in is held apart (see
    // [`attach_tails`]): the track ends at its last toe with a rise.
    let k = picked
        .iter()
        .rposition(|v| !flush_ids.contains(&v.0))
        .map_or(0, |i| i + 1);
    let tail = picked.split_off(k);
    (picked, None, tail)
}

/// Puts each held run of flush toes ([`FlushTail`]) back on the track that still ends at
/// its anchor, outward from that end; a run whose anchor is no longer an end (a bridge or a
/// join continues the track there, or the track was dropped) is dropped.
pub fn attach_tails(mut tracks: Vec<Track>, tails: Vec<FlushTail>) -> Vec<Track> {
    for tail in tails {
        let Some(t) = tracks.iter_mut().find(|t| {
            t.points.len() >= 2
                && (t.points.last() == Some(&tail.anchor) || t.points.first() == Some(&tail.anchor))
        }) else {
            continue;
        };
        if t.points.last() == Some(&tail.anchor) {
            t.points.extend(tail.verts.iter().map(|v| v.0));
            t.xyz.extend(tail.verts.iter().map(|v| v.1));
        } else {
            let (p, x): (Vec<u32>, Vec<[f64; 3]>) = tail.verts.iter().rev().copied().unzip();
            t.points.splice(0..0, p);
            t.xyz.splice(0..0, x);
        }
    }
    tracks
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::trajectory::Trajectory;

    /// A street corner seen by scanlines across x (one every 0.11 m, points every 2 cm
    /// along y): the main curb along y = 5 up to x = 7, a quarter circle of radius 3 about
    /// (7, 8), then the side street's curb along x = 10 from y = 8 to y = 14. The sidewalk
    /// is 0.15 m up. ρ = 60° · |t_x| at the last road point before each rise along a
    /// scanline (t: the curb's unit tangent), so it fades as the corner turns to run along
    /// the scanlines, and is 0 on the side street, which no scanline crosses.
    #[derive(Default)]
    struct Corner {
        x: Vec<f64>,
        y: Vec<f64>,
        z: Vec<f64>,
        t: Vec<f64>,
        rho: Vec<f32>,
        status: Vec<Option<PointStatus>>,
        scanline: Vec<u32>,
        traj: Trajectory,
    }

    impl Corner {
        /// Appends a kept point of scanline `line` at (x, y, z) with bend angle `rho`.
        fn push(&mut self, x: f64, y: f64, z: f64, rho: f32, line: u32) {
            self.x.push(x);
            self.y.push(y);
            self.z.push(z);
            self.t.push(line as f64 * 0.01 + y * 1e-5);
            self.rho.push(rho);
            self.status.push(Some(PointStatus::Kept));
            self.scanline.push(line);
        }
    }

    fn sidewalk(x: f64, y: f64) -> bool {
        let fillet = x > 7.0 && y < 8.0 && (x - 7.0).powi(2) + (y - 8.0).powi(2) > 9.0;
        y > 5.0 && x < 10.0 && !fillet
    }

    /// Distance from (x, y) to the toe line.
    fn toe_dist(x: f64, y: f64) -> f64 {
        if x <= 7.0 {
            (y - 5.0).abs()
        } else if y >= 8.0 {
            (x - 10.0).abs()
        } else {
            ((x - 7.0).hypot(y - 8.0) - 3.0).abs()
        }
    }

    fn corner() -> Corner {
        let mut c = Corner::default();
        let mut line = 0u32;
        let mut x = 0.013;
        while x < 16.0 {
            let mut y = 0.0;
            while y < 16.0 {
                let up = sidewalk(x, y);
                let next_up = sidewalk(x, y + 0.02);
                let rho = if !up && next_up {
                    // The curb's tangent where this scanline meets it.
                    let tx = if x <= 7.0 {
                        1.0
                    } else {
                        (y + 0.02 - 8.0).abs() / 3.0
                    };
                    60.0 * tx
                } else {
                    0.0
                };
                c.push(x, y, if up { 0.15 } else { 0.0 }, rho as f32, line);
                y += 0.02;
            }
            x += 0.11;
            line += 1;
        }
        c
    }

    fn input(c: &Corner) -> BendInput<'_> {
        BendInput {
            x: &c.x,
            y: &c.y,
            z: &c.z,
            t: &c.t,
            rho_deg: &c.rho,
            status: &c.status,
            scanline: &c.scanline,
            candidates: &[],
            trajectory: &c.traj,
        }
    }

    /// The track from a seed on the main curb at x ≈ 3.
    fn track(c: &Corner, params: &BendParams) -> Track {
        track_from(c, params, 3.0)
    }

    /// The track from a seed on the main curb at x ≈ `x0`, driving towards +x.
    fn track_from(c: &Corner, params: &BendParams, x0: f64) -> Track {
        let inp = input(c);
        let grid = PointGrid::build(inp.x, inp.y, 0.1, |_| true);
        let seed = (0..c.x.len())
            .filter(|&i| c.rho[i] > 10.0)
            .min_by(|&a, &b| (c.x[a] - x0).abs().total_cmp(&(c.x[b] - x0).abs()))
            .unwrap();
        let seeds = [Seed {
            point: seed as u32,
            side: Side::Left,
            dir: [1.0, 0.0],
            interval: 0,
            inlier_ratio: 1.0,
        }];
        let mut tracks = track_edges(&inp, &grid, &seeds, params);
        assert_eq!(tracks.len(), 1);
        tracks.remove(0)
    }

    #[test]
    fn the_track_follows_a_corner_into_the_side_street() {
        let c = corner();
        let params = BendParams::default();
        let t = track(&c, &params);
        assert_eq!(t.points.len(), t.xyz.len());
        // Every vertex on the toe: measured ones within the 2 cm point spacing, virtual
        // ones within half the 0.11 m scanline spacing.
        for q in &t.xyz {
            assert!(toe_dist(q[0], q[1]) < 0.06, "vertex {q:?} off the toe");
        }
        // Along the side street to within a profile length of its end (y = 14).
        let far = t.xyz.iter().map(|q| q[1]).fold(f64::MIN, f64::max);
        assert!(far > 13.3, "stopped at y = {far}");
        // The side street's vertices are virtual ones (ids past the points).
        let n = c.x.len() as u32;
        assert!(t
            .points
            .iter()
            .zip(&t.xyz)
            .filter(|(_, q)| q[1] > 9.0)
            .all(|(&p, _)| p >= n));
        // Without the virtual profile the track stops where ρ fades in the corner.
        let off = BendParams {
            profile_fallback: false,
            ..BendParams::default()
        };
        let t0 = track(&c, &off);
        let far0 = t0.xyz.iter().map(|q| q[1]).fold(f64::MIN, f64::max);
        assert!(far0 < 9.0, "without profiles: y = {far0}");
    }

    #[test]
    fn profile_finds_a_step_between_scanlines_and_rejects_a_ramp() {
        let c = corner();
        let inp = input(&c);
        let grid = PointGrid::build(inp.x, inp.y, 0.1, |_| true);
        let params = BendParams::default();
        // Across the side street's curb (x = 10) at y = 11, walking north: the curb rises
        // on the left (towards −x).
        let across = Profile {
            input: &inp,
            grid: &grid,
            params: &params,
            centre: [10.1, 11.0, 0.0],
            along: [0.0, 1.0],
            up: 1.0,
            half_l: 0.15,
        };
        let toe = across.toe().expect("a toe");
        assert!((toe.xyz[0] - 10.0).abs() < 0.06, "{toe:?}");
        assert!((toe.step_m - 0.15).abs() < 0.01, "{toe:?}");
        // With the wrong side up there is no curb (the ground falls).
        assert!(Profile { up: -1.0, ..across }.toe().is_none());
        // A flat road gives nothing.
        let flat = Profile {
            centre: [13.0, 2.0, 0.0],
            ..across
        };
        assert!(flat.toe().is_none());
        // A 20 % ramp (z = 0.2·x) is no step.
        let ramp_z: Vec<f64> = c.x.iter().map(|&x| 0.2 * x).collect();
        let ramp = BendInput {
            z: &ramp_z,
            ..input(&c)
        };
        let on_ramp = Profile {
            input: &ramp,
            centre: [13.0, 2.0, 2.6],
            ..flat
        };
        assert!(on_ramp.toe().is_none());
    }

    /// A curb along y = 5 (sidewalk 0.15 m up beyond it) from x = 0 to `curb_end`, seen by
    /// scanlines across x every 0.11 m with points every 2 cm; past its end the road is
    /// flat. Along the line y = 5 every scanline has a point with ρ = `rho_curb` while
    /// the curb lasts and ρ = 15° (road noise above the stop threshold) after it.
    fn weak_line(curb_end: f64, rho_curb: f32) -> Corner {
        let mut c = Corner::default();
        let mut line = 0u32;
        let mut x = 0.013;
        while x < 16.0 {
            let curb = x < curb_end;
            for k in 0..400 {
                let y = k as f64 * 0.02;
                let up = curb && y > 5.0;
                let on_line = (y - 4.99).abs() < 0.01;
                let rho = match (on_line, curb) {
                    (false, _) => 0.0,
                    (true, true) => rho_curb,
                    (true, false) => 15.0,
                };
                c.push(x, y, if up { 0.15 } else { 0.0 }, rho, line);
            }
            x += 0.11;
            line += 1;
        }
        c
    }

    fn farthest_x(c: &Corner, params: &BendParams) -> f64 {
        track(c, params)
            .xyz
            .iter()
            .map(|q| q[0])
            .fold(f64::MIN, f64::max)
    }

    #[test]
    fn a_track_stops_where_only_weak_unconfirmed_picks_go_on() {
        // Past the curb's end the weak line on the flat road is not followed beyond
        // `weak_run_max_m`, and the unconfirmed stretch is dropped.
        let c = weak_line(7.0, 60.0);
        let params = BendParams::default();
        let far = farthest_x(&c, &params);
        assert!((6.7..7.5).contains(&far), "stopped at x = {far}");
        // Without the limit the track walks the noise to the end of the scan.
        let off = BendParams {
            weak_run_max_m: 0.0,
            ..BendParams::default()
        };
        let far_off = farthest_x(&c, &off);
        assert!(far_off > 15.0, "without the limit: x = {far_off}");
        // A curb whose bend angle is weak all along is still followed: the step beside
        // the picks confirms them.
        let low = weak_line(12.0, 15.0);
        let far_low = farthest_x(&low, &params);
        assert!((11.7..12.5).contains(&far_low), "weak curb: x = {far_low}");
    }

    #[test]
    fn a_track_crosses_a_hole_in_the_returns_to_the_curb_beyond() {
        // The curb of `weak_line` with no return at all from x = 7 to 9 (a shadow across
        // the road and the curb): longer than the gap steps reach, so without the hole test
        // the track ends at x = 8.2 at the latest.
        let mut c = weak_line(16.0, 60.0);
        let keep: Vec<usize> = (0..c.x.len())
            .filter(|&i| !(7.0..9.0).contains(&c.x[i]))
            .collect();
        macro_rules! retain {
            ($($f:ident),*) => { $( c.$f = keep.iter().map(|&i| c.$f[i]).collect(); )* };
        }
        retain!(x, y, z, t, rho, status, scanline);
        let t = track(&c, &BendParams::default());
        let far = t.xyz.iter().map(|q| q[0]).fold(f64::MIN, f64::max);
        assert!(far > 15.0, "stopped at x = {far}");
        for q in &t.xyz {
            assert!((q[1] - 5.0).abs() < 0.06, "vertex {q:?} off the toe");
        }
        // Where the scan ends at the hole's near side, the track ends there.
        let mut end = weak_line(16.0, 60.0);
        let keep: Vec<usize> = (0..end.x.len()).filter(|&i| end.x[i] < 7.0).collect();
        let c = &mut end;
        macro_rules! retain_end {
            ($($f:ident),*) => { $( c.$f = keep.iter().map(|&i| c.$f[i]).collect(); )* };
        }
        retain_end!(x, y, z, t, rho, status, scanline);
        let far_end = farthest_x(&end, &BendParams::default());
        assert!(far_end < 7.5, "past the scan's end: x = {far_end}");
    }

    /// A toe line along y = 5 on flat ground (no step for a profile to find) seen by
    /// scanlines across x every 0.11 m with points every 2 cm: ρ = 60° at one point per
    /// scanline, 4 cm either side of the line by turns up to x = 7, none from x = 7 to
    /// x = 7.6, and on the line from there to the end of the scan.
    fn scattered_line() -> Corner {
        let mut c = Corner::default();
        let mut line = 0u32;
        let mut x = 0.013;
        while x < 16.0 {
            let toe = if line.is_multiple_of(2) { 4.96 } else { 5.04 };
            for k in 0..400 {
                let y = k as f64 * 0.02;
                let rho = if x < 7.0 {
                    if (y - toe).abs() < 0.01 {
                        60.0
                    } else {
                        0.0
                    }
                } else if x >= 7.6 && (y - 5.0).abs() < 0.01 {
                    60.0
                } else {
                    0.0
                };
                c.push(x, y, 0.0, rho, line);
            }
            x += 0.11;
            line += 1;
        }
        c
    }

    #[test]
    fn a_track_crosses_a_gap_on_the_line_of_its_toes_not_the_last_steps_scatter() {
        // The toes scatter 8 cm across the line from one scanline to the next: a
        // direction from the last step alone points up to 30° off the line, and 0.6 m on
        // it misses the toes beyond the gap; one over `DIR_BASE_M` stays on the line.
        let c = scattered_line();
        let t = track(&c, &BendParams::default());
        let far = t.xyz.iter().map(|q| q[0]).fold(f64::MIN, f64::max);
        assert!(far > 15.0, "stopped at x = {far}");
        for q in &t.xyz {
            assert!((q[1] - 5.0).abs() < 0.06, "vertex {q:?} off the line");
        }
    }

    /// A curb along y = 5 (sidewalk 0.15 m up beyond it, ρ = 60° on the toe line) with a
    /// curb cut without lip from x = 7 to x = 11: there the ground behind y = 5 ramps up
    /// at 20 % to the sidewalk and ρ is 0. Scanlines across x every 0.11 m, points every
    /// 2 cm.
    fn cut_line() -> Corner {
        let mut c = Corner::default();
        let mut line = 0u32;
        let mut x = 0.013;
        while x < 16.0 {
            let cut = (7.0..11.0).contains(&x);
            for k in 0..400 {
                let y = k as f64 * 0.02;
                let z = match (y > 5.0, cut) {
                    (false, _) => 0.0,
                    (true, false) => 0.15,
                    (true, true) => (0.2 * (y - 5.0)).min(0.15),
                };
                let on_line = !cut && (y - 4.99).abs() < 0.01;
                c.push(x, y, z, if on_line { 60.0 } else { 0.0 }, line);
            }
            x += 0.11;
            line += 1;
        }
        c
    }

    #[test]
    fn a_seed_just_before_a_cut_follows_it_with_the_curb_behind() {
        // The seed lies 0.5 m before the cut, fewer than `CUT_MIN_TRACK_STEPS` steps: the
        // 6.5 m of curb tracked backwards from it count, and the track crosses the cut on
        // its toe to the curb beyond.
        let c = cut_line();
        let t = track_from(&c, &BendParams::default(), 6.5);
        let far = t.xyz.iter().map(|q| q[0]).fold(f64::MIN, f64::max);
        assert!(far > 15.0, "stopped at x = {far}");
        for q in t.xyz.iter().filter(|q| (7.0..11.0).contains(&q[0])) {
            assert!((q[1] - 5.0).abs() < 0.06, "vertex {q:?} off the cut's toe");
        }
        // Without cut following the track ends where the curb does.
        let off = BendParams {
            cut_follow_max_m: 0.0,
            ..BendParams::default()
        };
        let t0 = track_from(&c, &off, 6.5);
        let far0 = t0.xyz.iter().map(|q| q[0]).fold(f64::MIN, f64::max);
        assert!(far0 < 8.5, "without cut following: x = {far0}");
    }

    #[test]
    fn the_line_ahead_does_not_follow_the_scatter_of_cut_toes() {
        // Toes every 0.15 m along y = 0.3·x (driving towards +x), alternately 0.08 m either
        // side of the line, the last one 0.08 m to its left.
        let len = 1.0f64.hypot(0.3);
        let (t, n) = ([1.0 / len, 0.3 / len], [-0.3 / len, 1.0 / len]);
        let picked: Vec<(u32, [f64; 3])> = (0..20)
            .map(|k| {
                let s = 0.15 * k as f64;
                let off = if k % 2 == 1 { 0.08 } else { -0.08 };
                (k, [s * t[0] + off * n[0], s * t[1] + off * n[1], 0.0])
            })
            .collect();
        let cur = picked.last().unwrap().1;
        let (p, a) = line_ahead(&picked, cur, [1.0, 0.0], 0.15).expect("a line");
        // Near the line (not 0.08 m off it, where the last toe is; the alternation
        // itself tilts the fit by about 1°), 0.15 m past that toe.
        let across = p[0] * n[0] + p[1] * n[1];
        let along = p[0] * t[0] + p[1] * t[1];
        assert!(across.abs() < 0.03, "{across}");
        assert!((along - (19.0 * 0.15 + 0.15)).abs() < 0.01, "{along}");
        assert!((a[0] * t[0] + a[1] * t[1]) > 0.999, "{a:?}");
        // Oriented along the search direction given, and refused across it.
        let (_, back) = line_ahead(&picked, cur, [-1.0, 0.0], 0.15).unwrap();
        assert!(back[0] < 0.0);
        assert!(line_ahead(&picked, cur, [-0.3, 1.0], 0.15).is_none());
        // Under 1 m of track gives no line.
        assert!(line_ahead(&picked[..6], picked[5].1, [1.0, 0.0], 0.15).is_none());
    }

    #[test]
    fn a_wide_profile_reaches_a_toe_beside_the_default_ones_reach() {
        // The main curb's toe (y = 5) 0.38 m left of the profile's centre: past the 0.30 m
        // the default profile accepts, within the wide one's 0.45 m.
        let c = corner();
        let inp = input(&c);
        let grid = PointGrid::build(inp.x, inp.y, 0.1, |_| true);
        let params = BendParams::default();
        let centre = [3.0, 5.0 - 0.38, 0.0];
        let profile = Profile {
            input: &inp,
            grid: &grid,
            params: &params,
            centre,
            along: [1.0, 0.0],
            up: 1.0,
            half_l: 0.3,
        };
        assert!(profile.toe().is_none());
        let toe = wide_toe(profile).expect("a toe");
        assert!((toe.xyz[1] - 5.0).abs() < 0.03, "{toe:?}");
        assert!((toe.step_m - 0.15).abs() < 0.01, "{toe:?}");
    }

    #[test]
    fn along_the_road_is_within_40_degrees_of_the_driving_direction() {
        let mut c = corner();
        let start = 0u32;
        // No trajectory: nothing to go by, every direction passes.
        assert!(along_the_road(&input(&c), &[], start, [0.0, 1.0]));
        // Driving towards +x (heading 90°) while the scanlines are taken.
        let pose = |t: f64, x: f64| crate::io::trajectory::Pose {
            t,
            x,
            y: 0.0,
            z: 2.0,
            roll_deg: 0.0,
            pitch_deg: 0.0,
            heading_deg: 90.0,
        };
        c.traj.samples = vec![pose(-1.0, -10.0), pose(100.0, 1000.0)];
        let inp = input(&c);
        let deg = |d: f64| [d.to_radians().cos(), d.to_radians().sin()];
        assert!(along_the_road(&inp, &[], start, deg(0.0)));
        assert!(along_the_road(&inp, &[], start, deg(180.0)));
        assert!(along_the_road(&inp, &[], start, deg(35.0)));
        assert!(!along_the_road(&inp, &[], start, deg(45.0)));
        assert!(!along_the_road(&inp, &[], start, deg(90.0)));
        assert!(!along_the_road(&inp, &[], start, deg(-60.0)));
    }

    #[test]
    fn climb_is_clamped_and_flat_directions_kept() {
        let v = clamp_climb([0.6, 0.0, 0.8]);
        assert!((v[2] - MAX_CLIMB).abs() < 1e-12);
        assert!(((v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt() - 1.0).abs() < 1e-12);
        assert_eq!(clamp_climb([1.0, 0.0, 0.0]), [1.0, 0.0, 0.0]);
    }

    #[test]
    fn a_held_run_of_flush_toes_goes_back_only_on_an_end() {
        use crate::model::Side;
        let track = |ids: &[u32]| Track {
            points: ids.to_vec(),
            xyz: ids.iter().map(|&i| [f64::from(i), 0.0, 0.0]).collect(),
            side: Side::Right,
        };
        let tail = |anchor: u32, ids: &[u32]| FlushTail {
            anchor,
            verts: ids.iter().map(|&i| (i, [f64::from(i), 0.0, 0.0])).collect(),
        };
        let out = attach_tails(
            vec![track(&[3, 4, 5]), track(&[10, 11, 12])],
            vec![tail(5, &[6, 7]), tail(10, &[9, 8]), tail(4, &[20])],
        );
        // Outward from the last vertex, outward from the first; not from the middle.
        assert_eq!(out[0].points, [3, 4, 5, 6, 7]);
        assert_eq!(out[1].points, [8, 9, 10, 11, 12]);
        assert_eq!(out[1].xyz[0], [8.0, 0.0, 0.0]);
    }
}
