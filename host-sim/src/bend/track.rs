//! Tracking (Honma et al. §2.7, Eq. 4–8): from each seed, forward and backward, the next
//! road-edge point is the point of minimum α·E_b + β·E_h + γ·E_v in the local point set S
//! around the position one search distance ahead along the search direction; the
//! direction then follows the picked points (Eq. 8). A track ends when S is empty or holds
//! no point with ρ of at least the stop threshold.
//!
//! Every edge comes out once: a track that reaches a point of an earlier track (within
//! `join_distance_m`) stops there, a seed already on a track starts nothing, and a track
//! that meets another end to end is joined to it into one polyline.

use std::collections::HashMap;

use super::grid::PointGrid;
use super::params::BendParams;
use super::seed::Seed;
use super::{BendInput, STATUS_KEPT};
use crate::model::Side;

/// One tracked edge: point indices in order along the driving direction.
#[derive(Clone, Debug, PartialEq)]
pub struct Track {
    /// Point indices (into the columns), ordered along the edge.
    pub points: Vec<u32>,
    /// Side of the trajectory.
    pub side: Side,
}

/// Where a one-directional track ended on another track.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Join {
    track: usize,
    point: u32,
}

/// Segments of accepted tracks, bucketed for the join test: a point is on a track when it
/// lies within the join distance of one of its segments (vertices alone would miss a seed
/// on a scanline the track stepped over).
/// A track segment: its two end points and the track it belongs to.
type Segment = (u32, u32, usize);

struct Claims {
    join_m: f64,
    cells: HashMap<(i64, i64), Vec<Segment>>,
    owner: HashMap<u32, usize>,
}

impl Claims {
    fn new(join_m: f64) -> Self {
        Self {
            join_m: join_m.max(1e-3),
            cells: HashMap::new(),
            owner: HashMap::new(),
        }
    }

    fn cell(&self, x: f64, y: f64) -> (i64, i64) {
        (
            (x / self.join_m).floor() as i64,
            (y / self.join_m).floor() as i64,
        )
    }

    /// Registers a track's polyline (a single point is a segment of length zero).
    fn add_track(&mut self, input: &BendInput, points: &[u32], track: usize) {
        for &p in points {
            self.owner.insert(p, track);
        }
        let segs: Vec<(u32, u32)> = if points.len() == 1 {
            vec![(points[0], points[0])]
        } else {
            points.windows(2).map(|w| (w[0], w[1])).collect()
        };
        for (a, b) in segs {
            let (ia, ib) = (a as usize, b as usize);
            let r = self.join_m;
            let (x0, y0) = (
                input.x[ia].min(input.x[ib]) - r,
                input.y[ia].min(input.y[ib]) - r,
            );
            let (x1, y1) = (
                input.x[ia].max(input.x[ib]) + r,
                input.y[ia].max(input.y[ib]) + r,
            );
            let (c0, c1) = (self.cell(x0, y0), self.cell(x1, y1));
            // A segment longer than a few hundred cells is a broken input; skip the rest.
            let cells = (c1.0 - c0.0 + 1).saturating_mul(c1.1 - c0.1 + 1);
            if cells > 10_000 {
                continue;
            }
            for cy in c0.1..=c1.1 {
                for cx in c0.0..=c1.0 {
                    self.cells.entry((cx, cy)).or_default().push((a, b, track));
                }
            }
        }
    }

    /// The nearest segment of a track other than `own` within the join distance of point
    /// `i` (ties: lower track, then earlier registration); the join point is the
    /// segment's nearer end.
    fn near(&self, input: &BendInput, i: usize, own: usize) -> Option<Join> {
        if let Some(&t) = self.owner.get(&(i as u32)) {
            if t != own {
                return Some(Join {
                    track: t,
                    point: i as u32,
                });
            }
        }
        let (px, py) = (input.x[i], input.y[i]);
        let v = self.cells.get(&self.cell(px, py))?;
        let mut best: Option<(f64, usize, u32)> = None;
        for &(a, b, t) in v {
            if t == own {
                continue;
            }
            let (ia, ib) = (a as usize, b as usize);
            let (ax, ay) = (input.x[ia], input.y[ia]);
            let (dx, dy) = (input.x[ib] - ax, input.y[ib] - ay);
            let l2 = dx * dx + dy * dy;
            let u = if l2 > 0.0 {
                (((px - ax) * dx + (py - ay) * dy) / l2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let d = (ax + u * dx - px).hypot(ay + u * dy - py);
            let end = if u < 0.5 { a } else { b };
            if d <= self.join_m && best.is_none_or(|(bd, bt, _)| (d, t) < (bd, bt)) {
                best = Some((d, t, end));
            }
        }
        best.map(|(_, t, p)| Join { track: t, point: p })
    }
}

/// Tracks every seed (in the order given) and returns the edges, each once.
pub fn track_edges(
    input: &BendInput,
    grid: &PointGrid,
    seeds: &[Seed],
    params: &BendParams,
) -> Vec<Track> {
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

    for seed in seeds {
        let s = seed.point as usize;
        if s >= input.x.len() || input.status.get(s) != Some(&STATUS_KEPT) {
            continue;
        }
        let id = tracks.len();
        if claims.near(input, s, id).is_some() {
            continue; // this stretch has been tracked already
        }
        let dir = [seed.dir[0], seed.dir[1], 0.0];
        let (fwd, fwd_join) = track_one_way(input, grid, &claims, id, seed.point, dir, params);
        let (bwd, bwd_join) = track_one_way(
            input,
            grid,
            &claims,
            id,
            seed.point,
            [-dir[0], -dir[1], 0.0],
            params,
        );
        let mut points: Vec<u32> = bwd.iter().rev().copied().collect();
        points.push(seed.point);
        points.extend_from_slice(&fwd);
        claims.add_track(input, &points, id);
        tracks.push(Some(Track {
            points,
            side: seed.side,
        }));
        parent.push(id);

        // Join end to end with the tracks this one ran into.
        let fwd_end = fwd.last().copied().unwrap_or(seed.point);
        let bwd_end = bwd.last().copied().unwrap_or(seed.point);
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
            let mut a_pts = a.points.clone();
            let mut b_pts = b.points.clone();
            // Orient so that the join is a's end and b's start.
            if !at_end {
                a_pts.reverse();
            }
            if !at_other_start {
                b_pts.reverse();
            }
            a_pts.extend_from_slice(&b_pts);
            // Keep the driving-direction order of the longer piece.
            let keep_a_order = a.points.len() >= b.points.len();
            if (keep_a_order && !at_end) || (!keep_a_order && !at_other_start) {
                a_pts.reverse();
            }
            let side = a.side;
            tracks[me] = Some(Track {
                points: a_pts,
                side,
            });
            tracks[other] = None;
            parent[other] = me;
        }
    }
    tracks.into_iter().flatten().collect()
}

/// Weight of the newest step in the running turn per step (an exponential moving average
/// over about five steps: long enough to average the toe points' scatter out, short enough
/// to follow a 4 m corner radius).
const TURN_EMA: f64 = 0.2;

fn unit3(v: [f64; 3]) -> Option<[f64; 3]> {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    (l > 1e-9).then(|| [v[0] / l, v[1] / l, v[2] / l])
}

/// Tracks from `start` along `dir0` until the stop rule of §2.7 fires or another track is
/// reached. Returns the points picked (not including `start`) and the join, if any.
fn track_one_way(
    input: &BendInput,
    grid: &PointGrid,
    claims: &Claims,
    own: usize,
    start: u32,
    dir0: [f64; 3],
    params: &BendParams,
) -> (Vec<u32>, Option<Join>) {
    let s = start as usize;
    let mut cur = [input.x[s], input.y[s], input.z[s]];
    let Some(mut v) = unit3(dir0) else {
        return (Vec::new(), None);
    };
    let mut prev_u = v;
    let mut picked: Vec<u32> = Vec::new();
    let mut own_pts: std::collections::HashSet<u32> = std::collections::HashSet::new();
    own_pts.insert(start);
    let mut gap = 0u32;
    // Turn of the search direction per step (radians, left positive), averaged: carries
    // the track round a corner across a gap.
    let mut turn = 0.0f64;
    let stop_rho = params.stop_rho_deg;
    let d_s = params.search_distance_m;
    let mut set: Vec<usize> = Vec::new();

    for _ in 0..params.max_steps {
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
                if input.status[i] != STATUS_KEPT
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
        if set.is_empty() || max_rho < stop_rho {
            // §2.7 stop rule; optionally bridge a few empty or weak steps.
            if gap < params.max_gap_steps {
                gap += 1;
                cur = pred;
                let (c, sn) = (turn.cos(), turn.sin());
                v = [c * v[0] - sn * v[1], sn * v[0] + c * v[1], v[2]];
                continue;
            }
            break;
        }
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
        if let Some(j) = claims.near(input, n, own) {
            return (picked, Some(j));
        }
        let p = [input.x[n], input.y[n], input.z[n]];
        let Some(u) = unit3([p[0] - cur[0], p[1] - cur[1], p[2] - cur[2]]) else {
            break;
        };
        // Eq. 8: v_k = a·v_{k−1} + b·v_{k−2} over the last two difference vectors.
        let v_new = unit3([
            params.a * u[0] + params.b * prev_u[0],
            params.a * u[1] + params.b * prev_u[1],
            params.a * u[2] + params.b * prev_u[2],
        ])
        .unwrap_or(u);
        if gap == 0 {
            let dturn =
                (v[0] * v_new[1] - v[1] * v_new[0]).atan2(v[0] * v_new[0] + v[1] * v_new[1]);
            turn += TURN_EMA * (dturn - turn);
        }
        v = v_new;
        prev_u = u;
        picked.push(n as u32);
        own_pts.insert(n as u32);
        cur = p;
        gap = 0;
    }
    (picked, None)
}
