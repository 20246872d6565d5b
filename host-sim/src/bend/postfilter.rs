//! Post-filters (end of Honma et al. §2.7) and the output properties of an edge.
//!
//! 1. Short edges are removed.
//! 2. Edges with points in a height band above them are removed: they run along the foot
//!    of a vehicle (or another object standing on the road), not along a curb.
//!    Then edges along the border of a gap in the returns (the ground beside them on one
//!    side unseen, on the other flat) are removed: the scanlines end there, at the
//!    vehicle's own body or a dropout, not at a curb ([`remove_at_return_gaps`]).
//! 3. Edges outside the roadway are removed: if the segment from an end of an edge to its
//!    nearest trajectory point crosses another edge of the same side, the edge lies behind
//!    that other edge (e.g. the foot of a wall behind the curb).
//!
//! Then each edge gets its height step (median of the per-point steps across it) and a
//! category per stretch (curb, curb cut by a small step, intersection by turning away
//! from the trajectory's heading).
//!
//! 4. Stretches whose height step is taller than any curb are removed (see
//!    [`remove_tall_steps`]).

use super::grid::PointGrid;
use super::params::BendParams;
use super::route::Route;
use super::track::Track;
use super::{median, BendInput};
use crate::model::{Category, CurbDetail, EdgeLine};
use crate::replay::PointStatus;

fn pos(input: &BendInput, p: u32) -> [f64; 3] {
    let i = p as usize;
    [input.x[i], input.y[i], input.z[i]]
}

/// Horizontal length of a track, metres.
pub fn track_length_m(_input: &BendInput, t: &Track) -> f64 {
    t.xyz
        .windows(2)
        .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
        .sum()
}

/// Filter 1: removes tracks shorter than `min_edge_length_m`.
pub fn remove_short(input: &BendInput, tracks: Vec<Track>, params: &BendParams) -> Vec<Track> {
    tracks
        .into_iter()
        .filter(|t| track_length_m(input, t) >= params.min_edge_length_m)
        .collect()
}

/// Whether the cloud has at least two points in the height band
/// `[vehicle_band_low_m, vehicle_band_high_m]` above `q` within `vehicle_radius_m`.
fn covered(input: &BendInput, grid: &PointGrid, q: [f64; 3], params: &BendParams) -> bool {
    let mut n = 0;
    grid.for_each_within(input.x, input.y, q[0], q[1], params.vehicle_radius_m, |i| {
        let dz = input.z[i] - q[2];
        if dz >= params.vehicle_band_low_m && dz <= params.vehicle_band_high_m {
            n += 1;
        }
    });
    n >= 2
}

/// Share of a track's points that are covered (see [`covered`]).
pub fn covered_share(input: &BendInput, grid: &PointGrid, t: &Track, params: &BendParams) -> f64 {
    if t.xyz.is_empty() {
        return 0.0;
    }
    let n = t
        .xyz
        .iter()
        .filter(|&&q| covered(input, grid, q, params))
        .count();
    n as f64 / t.xyz.len() as f64
}

/// Shortest uncovered stretch of a covered track that filter 2 keeps, metres: twice the
/// shortest edge, so that the few uncovered vertices at a vehicle's ends never stay.
const UNCOVERED_KEEP_M: f64 = 2.0;

/// Filter 2: removes tracks under vehicles. A track with at least `vehicle_share` of its
/// points covered (see [`covered`]) runs along a vehicle's foot, or along a curb beside
/// parked vehicles that overhang it: its covered points go, and its uncovered stretches of
/// at least [`UNCOVERED_KEEP_M`] stay as tracks of their own (the curb between the
/// vehicles).
pub fn remove_under_objects(
    input: &BendInput,
    grid: &PointGrid,
    tracks: Vec<Track>,
    params: &BendParams,
) -> Vec<Track> {
    let mut out = Vec::with_capacity(tracks.len());
    for t in tracks {
        let cov: Vec<bool> = t
            .xyz
            .iter()
            .map(|&q| covered(input, grid, q, params))
            .collect();
        keep_unflagged(input, t, &cov, params.vehicle_share, &mut out);
    }
    out
}

/// Pushes `t` onto `out` whole when under `share` of its vertices are flagged, and
/// otherwise its unflagged stretches of at least [`UNCOVERED_KEEP_M`] as tracks of their
/// own.
fn keep_unflagged(input: &BendInput, t: Track, flags: &[bool], share: f64, out: &mut Vec<Track>) {
    let n = flags.len();
    let flagged = flags.iter().filter(|&&c| c).count() as f64 / n.max(1) as f64;
    if flagged < share {
        out.push(t);
        return;
    }
    let mut k = 0;
    while k < n {
        if flags[k] {
            k += 1;
            continue;
        }
        let start = k;
        while k < n && !flags[k] {
            k += 1;
        }
        let piece = Track {
            points: t.points[start..k].to_vec(),
            xyz: t.xyz[start..k].to_vec(),
            side: t.side,
        };
        if track_length_m(input, &piece) >= UNCOVERED_KEEP_M {
            out.push(piece);
        }
    }
}

/// Distance across the track from a vertex to the centres of the two discs that
/// [`at_return_gap`] looks into, metres: past the curb's face and batter, within a curb
/// top's width.
const GAP_SIDE_OFFSET_M: f64 = 0.3;
/// Radius of those discs, metres: at the far side's sparsest lines and point spacing
/// (0.15 m each way) a disc this size on returned ground holds a few points.
const GAP_SIDE_RADIUS_M: f64 = 0.15;
/// How far across the track, metres, the first returns past an empty disc are looked for:
/// the body's gap before a near curb hides its face and top over a metre or so, while the
/// border of a gap wider than this has nothing but its own flat ground to show.
const GAP_LOOK_M: f64 = 1.5;
/// Fewest points in the disc on the seen side for the other, empty side to count as a gap
/// in the returns rather than a place the scanner barely reached.
const GAP_SEEN_MIN_POINTS: usize = 3;
/// Vertices on each side of a vertex whose chord gives the track's direction there.
const GAP_TANGENT_VERTICES: usize = 3;
/// Share of a track's vertices at a gap in the returns from which filter 2b cuts them out.
const GAP_SHARE: f64 = 0.3;
/// Length of a run of vertices at a gap in the returns that filter 2b cuts out of a track
/// under [`GAP_SHARE`], metres: a track that comes off the border of the body's gap onto
/// a curb (the whole file in one window) carries the border along, too short a share of
/// it to go by the share alone.
const GAP_RUN_M: f64 = 2.0;
/// Most vertices not at a gap that a run of vertices at a gap spans (a vertex whose disc
/// catches a stray return).
const GAP_RUN_HOLE: usize = 2;

/// Whether vertex `k` of `t` lies at the edge of a gap in the returns: across the track,
/// the disc on one side holds no point while the disc on the other side holds some, their
/// median height does not rise above the vertex by half a curb step, neither do the
/// points between the vertex and the empty disc, and the first returns past the empty disc
/// (within [`GAP_LOOK_M`]) lie at the vertex's height, or there are none.
///
/// A curb toe has returns on both sides (the road before it, the curb's top behind it);
/// where the curb hides the road behind it in its shadow, the seen side is the curb top,
/// which rises; where the vehicle's body hides the curb's top, the face rises between the
/// toe and the gap, or the top shows past it. What is left is the border of an area the
/// scanner never reached (the vehicle's own body in the way, a dropout), where the
/// scanlines end on flat ground.
fn at_return_gap(
    input: &BendInput,
    grid: &PointGrid,
    t: &Track,
    k: usize,
    params: &BendParams,
) -> bool {
    let m = t.xyz.len();
    let (a, b) = (
        t.xyz[k.saturating_sub(GAP_TANGENT_VERTICES)],
        t.xyz[(k + GAP_TANGENT_VERTICES).min(m - 1)],
    );
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let len = dx.hypot(dy);
    if len.is_nan() || len <= 1e-6 {
        return false;
    }
    let n = [-dy / len, dx / len];
    let q = t.xyz[k];
    let disc = |sign: f64, offset: f64| {
        let c = [q[0] + sign * offset * n[0], q[1] + sign * offset * n[1]];
        let mut z: Vec<f64> = Vec::new();
        grid.for_each_within(input.x, input.y, c[0], c[1], GAP_SIDE_RADIUS_M, |i| {
            if input.z[i].is_finite() {
                z.push(input.z[i]);
            }
        });
        z
    };
    let rise = 0.5 * params.profile_min_step_m;
    // Second highest of the points within the discs' offset of the vertex on the side
    // `sign` (one outlier does not make a face).
    let rises_towards = |sign: f64| {
        let mut top = [f64::NEG_INFINITY; 2];
        grid.for_each_within(input.x, input.y, q[0], q[1], GAP_SIDE_OFFSET_M, |i| {
            let c = (input.x[i] - q[0]) * n[0] + (input.y[i] - q[1]) * n[1];
            let z = input.z[i];
            if sign * c > 0.0 && z.is_finite() {
                if z > top[0] {
                    top = [z, top[0]];
                } else if z > top[1] {
                    top[1] = z;
                }
            }
        });
        top[1] - q[2] >= rise
    };
    let (mut left, mut right) = (disc(1.0, GAP_SIDE_OFFSET_M), disc(-1.0, GAP_SIDE_OFFSET_M));
    // Whether the first returns past the empty disc, within `GAP_LOOK_M`, lie a curb step
    // above or below the vertex: the gap then hides a step (the curb's face and top in
    // the body's way), and the vertex is its toe.
    let step_across_gap = |sign: f64| {
        let discs = (GAP_LOOK_M / GAP_SIDE_OFFSET_M).round() as u32;
        for j in 2..=discs {
            let mut z = disc(sign, j as f64 * GAP_SIDE_OFFSET_M);
            if let Some(zs) = median(&mut z) {
                return (zs - q[2]).abs() >= rise;
            }
        }
        false
    };
    let flat_beside_gap = |empty: &[f64], seen: &mut [f64], towards_empty: f64| {
        empty.is_empty()
            && seen.len() >= GAP_SEEN_MIN_POINTS
            && median(seen).is_some_and(|zs| zs - q[2] < rise)
            && !rises_towards(towards_empty)
            && !step_across_gap(towards_empty)
    };
    flat_beside_gap(&left, &mut right, 1.0) || flat_beside_gap(&right, &mut left, -1.0)
}

/// Filter 2b: removes tracks along the border of a gap in the returns (see
/// [`at_return_gap`]): where at least [`GAP_SHARE`] of a track's vertices lie there, those
/// vertices go and its other stretches of at least [`UNCOVERED_KEEP_M`] stay as tracks of
/// their own. Each vertex reads the points within [`GAP_LOOK_M`] and a disc's radius of it.
pub fn remove_at_return_gaps(
    input: &BendInput,
    grid: &PointGrid,
    tracks: Vec<Track>,
    params: &BendParams,
) -> Vec<Track> {
    let mut out = Vec::with_capacity(tracks.len());
    for t in tracks {
        let gap: Vec<bool> = (0..t.xyz.len())
            .map(|k| at_return_gap(input, grid, &t, k, params))
            .collect();
        let share = gap.iter().filter(|&&g| g).count() as f64 / gap.len().max(1) as f64;
        if share >= GAP_SHARE {
            keep_unflagged(input, t, &gap, GAP_SHARE, &mut out);
            continue;
        }
        let runs = long_gap_runs(&t, &gap);
        if runs.contains(&true) {
            keep_unflagged(input, t, &runs, 0.0, &mut out);
        } else {
            out.push(t);
        }
    }
    out
}

/// The vertices of `t` in runs of vertices at a gap (`gap`) of at least [`GAP_RUN_M`],
/// a run spanning at most [`GAP_RUN_HOLE`] vertices not at a gap between two that are.
fn long_gap_runs(t: &Track, gap: &[bool]) -> Vec<bool> {
    let mut runs = vec![false; gap.len()];
    let mut k = 0;
    while k < gap.len() {
        if !gap[k] {
            k += 1;
            continue;
        }
        let (start, mut end) = (k, k);
        let mut j = k + 1;
        while j < gap.len() && j - end <= GAP_RUN_HOLE + 1 {
            if gap[j] {
                end = j;
            }
            j += 1;
        }
        let length: f64 = t.xyz[start..=end]
            .windows(2)
            .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
            .sum();
        if length >= GAP_RUN_M {
            runs[start..=end].iter_mut().for_each(|r| *r = true);
        }
        k = end + 1;
    }
    runs
}

/// Whether segments ab and cd cross (touching at an end point does not count).
fn segments_cross(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]) -> bool {
    let orient = |p: [f64; 2], q: [f64; 2], r: [f64; 2]| {
        (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])
    };
    let d1 = orient(c, d, a);
    let d2 = orient(c, d, b);
    let d3 = orient(a, b, c);
    let d4 = orient(a, b, d);
    ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
}

/// Filter 3: removes tracks that lie behind another track of the same side, seen from
/// the trajectory. The paper tests the segment from an end of the edge to its nearest
/// trajectory point for a crossing with another edge; here that test is made at the ends
/// and every `ROADWAY_SAMPLE_M` along the edge, and the edge goes when more than half of
/// those segments cross another edge. With the ends alone, two edges that overlap by a few
/// centimetres where a track stopped and the next one started (at a curb cut, say) would
/// remove each other's neighbour. All tests are made against the tracks as they came in,
/// so the result does not depend on their order.
pub fn remove_outside_roadway(_input: &BendInput, route: &Route, tracks: Vec<Track>) -> Vec<Track> {
    const ROADWAY_SAMPLE_M: f64 = 1.0;
    let polys: Vec<Vec<[f64; 2]>> = tracks
        .iter()
        .map(|t| t.xyz.iter().map(|q| [q[0], q[1]]).collect())
        .collect();
    let bbox = |poly: &[[f64; 2]]| {
        poly.iter().fold(
            [
                f64::INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::NEG_INFINITY,
            ],
            |b, p| {
                [
                    b[0].min(p[0]),
                    b[1].min(p[1]),
                    b[2].max(p[0]),
                    b[3].max(p[1]),
                ]
            },
        )
    };
    let boxes: Vec<[f64; 4]> = polys.iter().map(|p| bbox(p)).collect();
    let outside: Vec<bool> = (0..tracks.len())
        .map(|k| {
            let poly = &polys[k];
            if poly.is_empty() {
                return false;
            }
            // Sample vertices: the ends and one every ROADWAY_SAMPLE_M in between.
            let mut samples = vec![poly[0]];
            let mut since = 0.0;
            for w in poly.windows(2) {
                since += (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]);
                if since >= ROADWAY_SAMPLE_M {
                    samples.push(w[1]);
                    since = 0.0;
                }
            }
            if poly.len() > 1 {
                samples.push(poly[poly.len() - 1]);
            }
            let crossing = samples
                .iter()
                .filter(|&&e| {
                    let Some((q, _)) = route.nearest(e[0], e[1]) else {
                        return false;
                    };
                    let sb = [
                        e[0].min(q[0]),
                        e[1].min(q[1]),
                        e[0].max(q[0]),
                        e[1].max(q[1]),
                    ];
                    (0..tracks.len()).any(|o| {
                        let b = boxes[o];
                        o != k
                            && tracks[o].side == tracks[k].side
                            && !(b[0] > sb[2] || b[2] < sb[0] || b[1] > sb[3] || b[3] < sb[1])
                            && polys[o]
                                .windows(2)
                                .any(|w| segments_cross(e, q, w[0], w[1]))
                    })
                })
                .count();
            2 * crossing > samples.len()
        })
        .collect();
    tracks
        .into_iter()
        .zip(outside)
        .filter(|(_, out)| !out)
        .map(|(t, _)| t)
        .collect()
}

/// Unit tangent of a track at vertex `k`, over the vertices within `half_span_m` of it.
pub(super) fn tangent(xy: &[[f64; 2]], k: usize, half_span_m: f64) -> Option<[f64; 2]> {
    let mut a = k;
    while a > 0 && (xy[a - 1][0] - xy[k][0]).hypot(xy[a - 1][1] - xy[k][1]) <= half_span_m {
        a -= 1;
    }
    let mut b = k;
    while b + 1 < xy.len()
        && (xy[b + 1][0] - xy[k][0]).hypot(xy[b + 1][1] - xy[k][1]) <= half_span_m
    {
        b += 1;
    }
    if a == b {
        a = k.saturating_sub(1);
        b = (k + 1).min(xy.len() - 1);
    }
    let d = [xy[b][0] - xy[a][0], xy[b][1] - xy[a][1]];
    let l = d[0].hypot(d[1]);
    (l > 1e-9).then(|| [d[0] / l, d[1] / l])
}

/// Height step across a track at each vertex: median height of the strip outside (away
/// from the trajectory) minus the median height of the strip inside, metres.
pub fn height_steps(
    input: &BendInput,
    grid: &PointGrid,
    route: &Route,
    t: &Track,
    params: &BendParams,
) -> Vec<Option<f64>> {
    let xy: Vec<[f64; 2]> = t.xyz.iter().map(|q| [q[0], q[1]]).collect();
    let (g, w) = (params.step_gap_m, params.step_strip_m);
    let along_max = 0.15;
    let step_at = |k: usize| -> Option<f64> {
        let tan = tangent(&xy, k, 0.3)?;
        let mut nrm = [-tan[1], tan[0]];
        let (q, _) = route.nearest(xy[k][0], xy[k][1])?;
        if nrm[0] * (xy[k][0] - q[0]) + nrm[1] * (xy[k][1] - q[1]) < 0.0 {
            nrm = [-nrm[0], -nrm[1]];
        }
        let mut inner = Vec::new();
        let mut outer = Vec::new();
        let r = (g + w).hypot(along_max);
        grid.for_each_within(input.x, input.y, xy[k][0], xy[k][1], r, |i| {
            if input.status[i].is_none() {
                return;
            }
            let d = [input.x[i] - xy[k][0], input.y[i] - xy[k][1]];
            let along = d[0] * tan[0] + d[1] * tan[1];
            let across = d[0] * nrm[0] + d[1] * nrm[1];
            if along.abs() > along_max {
                return;
            }
            if across >= g && across <= g + w {
                outer.push(input.z[i]);
            } else if across <= -g && across >= -g - w {
                inner.push(input.z[i]);
            }
        });
        Some(median(&mut outer)? - median(&mut inner)?)
    };
    // Measured every STEP_SPACING_M along the edge (the strips are 0.3 m long, so closer
    // samples would mostly repeat each other); vertices in between take the last value.
    const STEP_SPACING_M: f64 = 0.25;
    let mut out = Vec::with_capacity(xy.len());
    let mut last: Option<f64> = None;
    let mut since = f64::INFINITY;
    for k in 0..xy.len() {
        if k > 0 {
            since += (xy[k][0] - xy[k - 1][0]).hypot(xy[k][1] - xy[k - 1][1]);
        }
        if since >= STEP_SPACING_M {
            last = step_at(k);
            since = 0.0;
        }
        out.push(last);
    }
    out
}

/// Turns tracks into output edges: height steps, categories per stretch (an edge is cut
/// where its category changes), `method = "bend"`.
pub fn to_edge_lines(
    input: &BendInput,
    grid: &PointGrid,
    route: &Route,
    tracks: &[Track],
    params: &BendParams,
) -> Vec<EdgeLine> {
    to_edge_lines_with_steps(input, grid, route, tracks, params)
        .into_iter()
        .map(|(e, _)| e)
        .collect()
}

/// [`to_edge_lines`], with each line's height step per vertex (the samples its
/// `curb_height_m` is the median of), so that pieces of a line joined later get the
/// median of all their samples.
pub fn to_edge_lines_with_steps(
    input: &BendInput,
    grid: &PointGrid,
    route: &Route,
    tracks: &[Track],
    params: &BendParams,
) -> Vec<(EdgeLine, Vec<Option<f64>>)> {
    let mut out = Vec::new();
    for t in tracks {
        // Virtual vertices (ids past the points) have no scanline neighbours to refine on.
        let raw: Vec<[f64; 3]> = t
            .points
            .iter()
            .zip(&t.xyz)
            .map(|(&p, &q)| {
                if params.refine_peak && (p as usize) < input.x.len() {
                    refined_pos(input, p)
                } else {
                    q
                }
            })
            .collect();
        let xy: Vec<[f64; 2]> = raw.iter().map(|p| [p[0], p[1]]).collect();
        let xyz = smooth(&raw, params.smooth_half_window as usize);
        let steps = height_steps(input, grid, route, t, params);
        let cats: Vec<Category> = (0..xy.len())
            .map(|k| {
                let turned = tangent(&xy, k, 0.5)
                    .zip(route.nearest(xy[k][0], xy[k][1]))
                    .map(|(tan, (_, f))| {
                        let c = (tan[0] * f[0] + tan[1] * f[1]).abs().min(1.0);
                        c.acos().to_degrees() > params.intersection_angle_deg
                    })
                    .unwrap_or(false);
                if turned {
                    Category::Intersection
                } else if steps[k].is_some_and(|s| s < params.curb_cut_max_step_m) {
                    Category::CurbCut
                } else {
                    Category::Curb
                }
            })
            .collect();
        let runs = category_runs(&raw, &cats, params.min_category_run_m);
        for (a, b, cat) in runs {
            let mut st: Vec<f64> = steps[a..=b].iter().flatten().copied().collect();
            out.push((
                EdgeLine {
                    points: xyz[a..=b].to_vec(),
                    side: t.side,
                    category: Some(cat),
                    method: Some("bend".to_string()),
                    curb_height_m: median(&mut st),
                    // Measured vertices are observed points; virtual ones (ids past the
                    // points) were placed by the tracker.
                    detail: Some(Box::new(CurbDetail {
                        measured: t.points[a..=b]
                            .iter()
                            .map(|&p| (p as usize) < input.x.len())
                            .collect(),
                        ..CurbDetail::measured(&xyz[a..=b])
                    })),
                },
                steps[a..=b].to_vec(),
            ));
        }
    }
    out
}

/// Tallest median height step of an output stretch, metres: above every curb (the random
/// streets' reach 0.25 m, high curbs 0.3 m), below the roof of a car beside its side.
pub const MAX_CURB_STEP_M: f64 = 0.5;

/// Filter 4: removes the stretches (whole output lines of [`to_edge_lines_with_steps`]) whose
/// median height step exceeds [`MAX_CURB_STEP_M`]. Such a line follows the side of a
/// vehicle the scanner sees from above (the road up to its foot, its roof beyond, its side
/// hidden, so filter 2 finds nothing above the line), not a curb. Lines without a measured
/// step stay.
pub fn remove_tall_steps(
    lines: Vec<(EdgeLine, Vec<Option<f64>>)>,
) -> Vec<(EdgeLine, Vec<Option<f64>>)> {
    lines.into_iter().filter(|(e, _)| !tall_step(e)).collect()
}

/// Whether `e`'s median height step exceeds [`MAX_CURB_STEP_M`] (filter 4). A piece of an
/// edge cut at a section's bound is judged only once joined: its own median may be
/// another stretch's.
pub fn tall_step(e: &EdgeLine) -> bool {
    matches!(e.curb_height_m, Some(h) if h > MAX_CURB_STEP_M)
}

/// The position of the ρ peak at point `p`: the vertex of the parabola through ρ of `p`
/// and its neighbours on the same scanline (adjacent in time order), at most half-way to
/// a neighbour; `p` itself where that is not defined.
fn refined_pos(input: &BendInput, p: u32) -> [f64; 3] {
    let i = p as usize;
    let here = pos(input, p);
    if i == 0 || i + 1 >= input.x.len() {
        return here;
    }
    let ok = |j: usize| {
        input.status[j] == Some(PointStatus::Kept) && input.scanline[j] == input.scanline[i]
    };
    if !(ok(i - 1) && ok(i + 1)) {
        return here;
    }
    let (r0, r1, r2) = (
        input.rho_deg[i - 1] as f64,
        input.rho_deg[i] as f64,
        input.rho_deg[i + 1] as f64,
    );
    let denom = r0 - 2.0 * r1 + r2;
    if denom >= -1e-9 {
        return here;
    }
    let delta = (0.5 * (r0 - r2) / denom).clamp(-0.5, 0.5);
    let j = if delta > 0.0 { i + 1 } else { i - 1 };
    let q = pos(input, j as u32);
    let w = delta.abs();
    [
        here[0] + w * (q[0] - here[0]),
        here[1] + w * (q[1] - here[1]),
        here[2] + w * (q[2] - here[2]),
    ]
}

/// Moving average over ±`k` vertices, the window shrinking symmetrically at the ends.
fn smooth(p: &[[f64; 3]], k: usize) -> Vec<[f64; 3]> {
    let n = p.len();
    (0..n)
        .map(|i| {
            let h = k.min(i).min(n - 1 - i);
            let w = (2 * h + 1) as f64;
            let mut acc = [0.0; 3];
            // Sum offsets from p[i], not absolute world coordinates, to keep precision.
            for q in &p[i - h..=i + h] {
                for c in 0..3 {
                    acc[c] += q[c] - p[i][c];
                }
            }
            [
                p[i][0] + acc[0] / w,
                p[i][1] + acc[1] / w,
                p[i][2] + acc[2] / w,
            ]
        })
        .collect()
}

/// Runs `(first, last, category)` of equal category over the vertices (consecutive runs
/// share their boundary vertex); runs shorter than `min_run_m` (horizontal arc length) are
/// absorbed by the neighbour before them (or after, for the first run), shortest first.
/// Vertices past the shorter of the two slices are ignored. The one rule for cutting an
/// edge into category runs: the tracker's first classes here, the curb's settled classes
/// in `curb::class`.
pub fn category_runs(
    pts: &[[f64; 3]],
    cats: &[Category],
    min_run_m: f64,
) -> Vec<(usize, usize, Category)> {
    let m = pts.len().min(cats.len());
    if m == 0 {
        return Vec::new();
    }
    let mut s = vec![0.0; m];
    for k in 1..m {
        s[k] = s[k - 1] + (pts[k][0] - pts[k - 1][0]).hypot(pts[k][1] - pts[k - 1][1]);
    }
    let mut runs: Vec<(usize, usize, Category)> = Vec::new();
    for (k, &c) in cats[..m].iter().enumerate() {
        match runs.last_mut() {
            Some(r) if r.2 == c => r.1 = k,
            Some(r) => {
                r.1 = k;
                runs.push((k, k, c));
            }
            None => runs.push((k, k, c)),
        }
    }
    // A run holding only the boundary vertex of a final change: fold it back (the run
    // before already ends on that vertex).
    if runs.len() > 1 && runs.last().is_some_and(|r| r.0 == r.1) {
        runs.pop();
    }
    // Absorb short runs, shortest first, until every run is long enough or one is left.
    while runs.len() > 1 {
        let Some((k, _)) = runs
            .iter()
            .enumerate()
            .map(|(k, r)| (k, s[r.1] - s[r.0]))
            .filter(|&(_, l)| l < min_run_m)
            .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)))
        else {
            break;
        };
        if k == 0 {
            runs[1].0 = runs[0].0;
            runs.remove(0);
        } else {
            runs[k - 1].1 = runs[k].1;
            runs.remove(k);
        }
        // Neighbours of equal category become one run.
        let mut merged: Vec<(usize, usize, Category)> = Vec::new();
        for r in runs.drain(..) {
            match merged.last_mut() {
                Some(q) if q.2 == r.2 => q.1 = r.1,
                _ => merged.push(r),
            }
        }
        runs = merged;
    }
    runs
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bend::fixture::KeptPoints;
    use crate::model::Side;

    #[test]
    fn crossing_segments() {
        assert!(segments_cross(
            [0.0, 0.0],
            [2.0, 2.0],
            [0.0, 2.0],
            [2.0, 0.0]
        ));
        assert!(!segments_cross(
            [0.0, 0.0],
            [1.0, 0.0],
            [0.0, 1.0],
            [1.0, 1.0]
        ));
        // Touching at an end point is not a crossing.
        assert!(!segments_cross(
            [0.0, 0.0],
            [1.0, 0.0],
            [1.0, 0.0],
            [1.0, 1.0]
        ));
    }

    #[test]
    fn short_category_runs_are_absorbed() {
        // 21 vertices 0.1 m apart: curb, 3 vertices (0.2–0.3 m) of curb cut, curb.
        let xy: Vec<[f64; 3]> = (0..21).map(|k| [k as f64 * 0.1, 0.0, 0.0]).collect();
        let mut cats = vec![Category::Curb; 21];
        for c in &mut cats[8..11] {
            *c = Category::CurbCut;
        }
        let runs = category_runs(&xy, &cats, 1.0);
        assert_eq!(runs, vec![(0, 20, Category::Curb)]);
        // With a 0.1 m minimum the cut stays, sharing its boundary vertices.
        let runs = category_runs(&xy, &cats, 0.1);
        assert_eq!(
            runs,
            vec![
                (0, 8, Category::Curb),
                (8, 11, Category::CurbCut),
                (11, 20, Category::Curb)
            ]
        );
    }

    #[test]
    fn smoothing_averages_inside_and_keeps_the_ends() {
        let p: Vec<[f64; 3]> = (0..6)
            .map(|k| [k as f64, if k % 2 == 0 { 0.0 } else { 0.03 }, 1.0])
            .collect();
        let s = smooth(&p, 2);
        assert_eq!(s[0], p[0]);
        assert_eq!(s[5], p[5]);
        // Vertex 1: window 0..=2 → y = 0.01; vertex 2: window 0..=4 → y = 0.012.
        assert!((s[1][1] - 0.01).abs() < 1e-12 && (s[1][0] - 1.0).abs() < 1e-12);
        assert!((s[2][1] - 0.012).abs() < 1e-12);
        assert_eq!(smooth(&p, 0), p);
    }

    #[test]
    fn peak_refinement_moves_to_the_parabola_vertex() {
        use crate::io::trajectory::Trajectory;
        // ρ = 60, 90, 80 at x = 0, 0.02, 0.04: parabola vertex at δ = 0.5·(60 − 80)/
        // (60 − 180 + 80) = 0.25 points towards the third, x = 0.025.
        let traj = Trajectory::default();
        let input = BendInput {
            x: &[0.0, 0.02, 0.04],
            y: &[0.0; 3],
            z: &[1.0; 3],
            t: &[0.0; 3],
            rho_deg: &[60.0, 90.0, 80.0],
            status: &[Some(PointStatus::Kept); 3],
            scanline: &[4; 3],
            candidates: &[],
            trajectory: &traj,
        };
        let q = refined_pos(&input, 1);
        assert!((q[0] - 0.025).abs() < 1e-12, "{q:?}");
        // Another scanline next door: no refinement.
        let input = BendInput {
            scanline: &[4, 4, 5],
            ..input
        };
        assert_eq!(refined_pos(&input, 1), [0.02, 0.0, 1.0]);
    }

    fn line(step: Option<f64>) -> (EdgeLine, Vec<Option<f64>>) {
        let e = EdgeLine {
            points: vec![[0.0, 0.0, 0.0], [3.0, 0.0, 0.0]],
            side: Side::Right,
            category: Some(Category::Curb),
            method: Some("bend".to_string()),
            curb_height_m: step,
            detail: None,
        };
        (e, vec![step, step])
    }

    #[test]
    fn a_step_taller_than_any_curb_is_not_a_curb() {
        let kept = remove_tall_steps(vec![
            line(Some(0.29)),
            line(Some(1.42)),
            line(None),
            line(Some(MAX_CURB_STEP_M + 0.01)),
        ]);
        let steps: Vec<Option<f64>> = kept.iter().map(|(e, _)| e.curb_height_m).collect();
        assert_eq!(steps, vec![Some(0.29), None]);
    }

    #[test]
    fn tracks_along_a_gap_in_the_returns_go_and_curb_toes_stay() {
        use crate::io::trajectory::Trajectory;
        // A grid of returns 5 cm apart over 15 m along x. Across it (y): a curb top at
        // 0.12 m for y < -2, the road from -2 to 1, no returns from 1 to 4 (the vehicle's
        // body in the way), from 4 to 6 the top of a curb at 0.15 m whose toe at y = 4 the
        // curb's shadow hides the road before; then, past 4 m without returns, road from
        // 10 to 10.5 and a curb whose face and top the body hides up to 11.5.
        let (mut x, mut y, mut z) = (Vec::new(), Vec::new(), Vec::new());
        let rows: Vec<i32> = (-60..=20)
            .chain(80..=120)
            .chain(200..=210)
            .chain(230..=240)
            .collect();
        for &iy in &rows {
            for ix in 0..=300 {
                x.push(ix as f64 * 0.05);
                y.push(iy as f64 * 0.05);
                z.push(if iy < -40 {
                    0.12
                } else if iy > 80 && iy <= 120 {
                    0.15
                } else if iy >= 230 {
                    0.2
                } else {
                    0.0
                });
            }
        }
        let points = KeptPoints::new(x, y, z);
        let traj = Trajectory::default();
        let input = points.input(&traj);
        let grid = PointGrid::build(input.x, input.y, 0.1, |_| true);
        let id = |row: i32, ix: u32| rows.iter().position(|&r| r == row).unwrap() as u32 * 301 + ix;
        let along = |row: i32| {
            Track::measured(
                &input,
                (0..=100).map(|ix| id(row, ix)).collect(),
                Side::Left,
            )
        };
        let (border, toe, shadowed, hidden) = (along(20), along(-40), along(80), along(210));
        let p = BendParams::default();
        let kept = remove_at_return_gaps(
            &input,
            &grid,
            vec![border, toe.clone(), shadowed.clone(), hidden.clone()],
            &p,
        );
        assert_eq!(kept, vec![toe, shadowed, hidden]);
        // A track along the gap's border for 3 m that comes off it onto the curb toe and
        // follows that for 12 m: a fifth of its vertices at the gap, all in one run.
        let joined = Track::measured(
            &input,
            (0..=60)
                .map(|ix| id(20, ix))
                .chain((60..=300).map(|ix| id(-40, ix)))
                .collect(),
            Side::Left,
        );
        let kept = remove_at_return_gaps(&input, &grid, vec![joined], &p);
        assert_eq!(kept.len(), 1);
        // The border goes but for the vertices whose direction spans the step onto the toe.
        assert!(kept[0].xyz.iter().all(|q| q[1] == -2.0 || q[0] >= 2.7));
        assert!(track_length_m(&input, &kept[0]) > 11.5);
    }
}
