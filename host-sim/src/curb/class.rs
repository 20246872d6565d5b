//! The class of every toe vertex and the stretches of one class (docs/spec.md §2,
//! "Classes"): `intersection` where the edge turns away from the route, `bus_bay` where it
//! stands out from the line of its side's curb, then by height `curb` or `curb_cut`, and
//! `flush` for a low run longer than any curb cut.

use super::tangent;
use crate::bend::postfilter::category_runs;
use crate::bend::route::Route;
use crate::model::{Category, CurbDetail, EdgeLine, Side};

/// Angle between the edge and the route above which a vertex is on an intersection
/// (corner arc or side street), degrees.
pub const TURN_DEG: f64 = 30.0;
/// Turn rate of the edge itself (degrees per metre, the tangent's change over
/// ±[`TURN_RATE_HALF_M`]) above which a vertex next to an intersection run still belongs to
/// it: a corner arc starts tangent to the curb, so its first part turns less than
/// [`TURN_DEG`] from the route, but the edge keeps turning there. An arc of radius 57 m turns
/// 1°/m: corner arcs, also the wide first part of a flared corner, turn faster, while a
/// straight curb's tangent wanders by less than half of that. The edge's own turn, not its
/// angle to the route, so that a curb the vehicle's lane change leaves at an angle to the
/// route does not join.
pub const TURN_RATE_DEG_M: f64 = 1.0;
/// Half the reach along the edge over which its turn rate is taken, metres.
pub const TURN_RATE_HALF_M: f64 = 0.5;
/// How much wider than usual the road is at a bus bay or setback, metres.
pub const BAY_MIN_M: f64 = 0.5;
/// How far a vertex with no curb on the other side stands out from its side's usual
/// offset to be on a bus bay, metres: the bay's threshold plus a lane's slack for the
/// vehicle's wander.
pub const BAY_ALONE_M: f64 = 1.2;
/// Reach along the route within which a bus bay's curb must come back to its side's line
/// at both ends, metres: a bay is a recess, while a road that widens for good is plain curb.
pub const BAY_RETURN_M: f64 = 10.0;
/// Reach along the route within which the other side's curb counts as beside a vertex,
/// metres.
pub const PAIR_M: f64 = 1.0;
/// Distance within which the end of one edge continues another edge's end, metres (the
/// tracker ends a track where a corner arc begins and starts another on the arc).
pub const END_JOIN_M: f64 = 0.5;
/// Highest curb at a curb cut (a lowered curb's lip, a ramp), metres.
pub const CUT_MAX_M: f64 = 0.05;
/// Where the full height beside a curb cut is taken: the curb vertices this far beyond the
/// end of its low run, metres (past the longest transition, within the next driveway's
/// reach).
pub const CUT_FULL_M: (f64, f64) = (2.0, 5.0);
/// A vertex next to a curb cut belongs to its transition while it stays this much below the
/// full height beside it (a share of that height, at least [`CUT_SLACK_MIN_M`]).
pub const CUT_SLACK: f64 = 0.05;
/// The least slack below the full height, metres: the height's noise along a curb.
pub const CUT_SLACK_MIN_M: f64 = 0.01;
/// Shortest low run that is a flush edge rather than a curb cut, metres (curb cuts for
/// driveways and crossings are up to about 15 m with their transitions).
pub const FLUSH_MIN_M: f64 = 20.0;
/// Shortest stretch of one class; shorter runs join their neighbour.
pub const MIN_RUN_M: f64 = 1.0;
/// Share of the vertices (not turned) taken as the usual width or offset: the value below
/// which this share lies.
const LINE_QUANTILE: f64 = 0.2;

/// Sets the class of every vertex of `edges` (those with detail), from their heights, their
/// direction against the route and how far they stand out from the curb line.
///
/// The vehicle wanders in its lane, so a curb's offset from the route alone moves by as
/// much as a lane's slack; the road's width does not. Where the other side's curb runs
/// beside a vertex (within [`PAIR_M`] of its station), the vertex stands out by the width
/// there minus the usual width; elsewhere by its offset minus its side's usual offset,
/// against a threshold that allows for the wander.
pub fn classify(route: &Route, edges: &mut [&mut EdgeLine]) {
    // Per vertex: (angle to the route in degrees, offset from the route, station).
    let geo: Vec<Vec<(f64, f64, f64)>> = edges
        .iter()
        .map(|e| {
            (0..e.points.len())
                .map(|k| {
                    let p = e.points[k];
                    match (tangent(&e.points, k, 0.5), route.nearest(p[0], p[1])) {
                        (Some(t), Some((q, f))) => {
                            let c = (t[0] * f[0] + t[1] * f[1]).abs().min(1.0);
                            (
                                c.acos().to_degrees(),
                                (p[0] - q[0]).hypot(p[1] - q[1]),
                                route.station_near(p[0], p[1]).unwrap_or(f64::NAN),
                            )
                        }
                        _ => (0.0, f64::NAN, f64::NAN),
                    }
                })
                .collect()
        })
        .collect();
    let rate: Vec<Vec<f64>> = edges.iter().map(|e| turn_rate(&e.points)).collect();
    // Vertices running along the route, per side, by station: (station, offset).
    let mut along: [Vec<(f64, f64)>; 2] = [Vec::new(), Vec::new()];
    for (e, g) in edges.iter().zip(&geo) {
        let s = usize::from(e.side == Side::Right);
        along[s].extend(
            g.iter()
                .filter(|g| g.0 <= TURN_DEG && g.1.is_finite() && g.2.is_finite())
                .map(|g| (g.2, g.1)),
        );
    }
    for a in along.iter_mut() {
        a.sort_unstable_by(|p, q| p.0.total_cmp(&q.0));
    }
    // The other side's offset at `station`: the median within PAIR_M.
    let beside = |side: usize, station: f64| -> Option<f64> {
        let a = &along[1 - side];
        let lo = a.partition_point(|p| p.0 < station - PAIR_M);
        let hi = a.partition_point(|p| p.0 <= station + PAIR_M);
        let mut v: Vec<f64> = a[lo..hi].iter().map(|p| p.1).collect();
        super::median(&mut v)
    };
    let quantile = |mut v: Vec<f64>| -> Option<f64> {
        if v.is_empty() {
            return None;
        }
        v.sort_unstable_by(f64::total_cmp);
        Some(v[((v.len() - 1) as f64 * LINE_QUANTILE) as usize])
    };
    let width_line = quantile(
        along[0]
            .iter()
            .filter_map(|&(st, off)| beside(0, st).map(|o| o + off))
            .collect(),
    );
    let side_line = [
        quantile(along[0].iter().map(|p| p.1).collect()),
        quantile(along[1].iter().map(|p| p.1).collect()),
    ];
    for ((e, g), r) in edges.iter_mut().zip(&geo).zip(&rate) {
        let side = usize::from(e.side == Side::Right);
        let Some(d) = e.detail.as_mut() else { continue };
        d.class = g
            .iter()
            .zip(&d.height_m)
            .map(|(&(angle, off, station), &h)| {
                let stand_out = |o: f64, s: usize| side_line[s].map_or(0.0, |l| o - l);
                let out_by = match (beside(side, station), width_line) {
                    // The wider road is this side's bay when this side's curb stands out
                    // more than the other's.
                    (Some(o), Some(w)) if stand_out(off, side) >= stand_out(o, 1 - side) => {
                        off + o - w - BAY_MIN_M
                    }
                    (Some(_), Some(_)) => f64::NEG_INFINITY,
                    _ => side_line[side].map_or(f64::NEG_INFINITY, |l| off - l - BAY_ALONE_M),
                };
                if angle > TURN_DEG {
                    Category::Intersection
                } else if out_by > 0.0 {
                    Category::BusBay
                } else if h < CUT_MAX_M {
                    Category::CurbCut
                } else {
                    Category::Curb
                }
            })
            .collect();
        grow_intersections(r, &mut d.class);
    }
    // An edge that ends where another edge's intersection run ends continues the corner:
    // its end grows into the intersection too.
    let corner_ends: Vec<(Side, [f64; 3])> = edges
        .iter()
        .filter_map(|e| e.detail.as_ref().map(|d| (e, d)))
        .flat_map(|(e, d)| {
            let last = e.points.len().min(d.class.len()).saturating_sub(1);
            [0, last]
                .into_iter()
                .filter(|&k| d.class.get(k) == Some(&Category::Intersection))
                .map(|k| (e.side, e.points[k]))
                .collect::<Vec<_>>()
        })
        .collect();
    for (e, r) in edges.iter_mut().zip(&rate) {
        let side = e.side;
        let m = e.points.len();
        let near_corner = |p: [f64; 3]| {
            corner_ends
                .iter()
                .any(|(s, q)| *s == side && (p[0] - q[0]).hypot(p[1] - q[1]) <= END_JOIN_M)
        };
        let ends: Vec<usize> = [0, m.saturating_sub(1)]
            .into_iter()
            .filter(|&k| {
                r.get(k).is_some_and(|r| r.abs() >= TURN_RATE_DEG_M) && near_corner(e.points[k])
            })
            .collect();
        let Some(d) = e.detail.as_mut() else { continue };
        if ends.is_empty() || d.class.len() != m {
            continue;
        }
        for k in ends {
            d.class[k] = Category::Intersection;
        }
        grow_intersections(r, &mut d.class);
    }
    // A bus bay is a recess: its side's curb is back on its usual line within BAY_RETURN_M
    // before and after it (clearly back: within half the thresholds that make a bay). Other
    // wide runs (a road that widens for good) are curb.
    let on_line = |side: usize, off: f64, station: f64| match (beside(side, station), width_line) {
        (Some(o), Some(w)) => off + o - w < 0.5 * BAY_MIN_M,
        _ => side_line[side].is_none_or(|l| off - l < 0.5 * BAY_ALONE_M),
    };
    let mut line: [Vec<(f64, bool)>; 2] = [Vec::new(), Vec::new()];
    for (e, g) in edges.iter().zip(&geo) {
        let Some(d) = e.detail.as_ref() else { continue };
        let side = usize::from(e.side == Side::Right);
        line[side].extend(
            g.iter()
                .zip(&d.class)
                .filter(|(g, c)| {
                    g.1.is_finite() && g.2.is_finite() && **c != Category::Intersection
                })
                .map(|(g, _)| (g.2, !on_line(side, g.1, g.2))),
        );
    }
    for (e, g) in edges.iter_mut().zip(&geo) {
        let side = usize::from(e.side == Side::Right);
        let Some(d) = e.detail.as_mut() else { continue };
        let m = d.class.len().min(g.len()).min(d.height_m.len());
        for run in runs_of(&d.class, m, Category::BusBay) {
            let (a, k) = (run.start, run.end);
            let (s0, s1) = g[a..k]
                .iter()
                .map(|g| g.2)
                .filter(|s| s.is_finite())
                .fold((f64::MAX, f64::MIN), |(lo, hi), s| (lo.min(s), hi.max(s)));
            let back = |lo: f64, hi: f64| {
                line[side]
                    .iter()
                    .any(|&(s, bay)| !bay && s >= lo && s <= hi)
            };
            if !(back(s0 - BAY_RETURN_M, s0) && back(s1, s1 + BAY_RETURN_M)) {
                for j in a..k {
                    d.class[j] = if d.height_m[j] < CUT_MAX_M {
                        Category::CurbCut
                    } else {
                        Category::Curb
                    };
                }
            }
        }
    }
}

/// The run rules on closed edges ([`grow_cuts`], [`flush_runs`], then the smoothing of
/// [`category_runs`] to stretches of at least [`MIN_RUN_M`]), leaving each vertex's class
/// the class of its stretch. Edges that continue one another (the end of one within
/// [`END_JOIN_M`] of the start of the next, on the same side) are one line for these rules:
/// the tracker often ends a track where the curb drops and starts the next one there, so a
/// curb cut and its transitions, or a cut and its curb, sit on different edges.
pub fn settle_runs(edges: &mut [EdgeLine]) {
    let n = edges.len();
    let ok = |e: &EdgeLine| {
        e.detail
            .as_ref()
            .is_some_and(|d| d.class.len() == e.points.len())
            && !e.points.is_empty()
    };
    // next[i]: the edge whose start continues edge i's end (the nearest, each start once).
    let mut next: Vec<Option<usize>> = vec![None; n];
    let mut has_prev = vec![false; n];
    for i in 0..n {
        if !ok(&edges[i]) {
            continue;
        }
        let p = edges[i].points[edges[i].points.len() - 1];
        let best = (0..n)
            .filter(|&j| j != i && !has_prev[j] && ok(&edges[j]) && edges[j].side == edges[i].side)
            .map(|j| {
                (
                    j,
                    (edges[j].points[0][0] - p[0]).hypot(edges[j].points[0][1] - p[1]),
                )
            })
            .filter(|&(_, d)| d <= END_JOIN_M)
            .min_by(|a, b| a.1.total_cmp(&b.1));
        if let Some((j, _)) = best {
            next[i] = Some(j);
            has_prev[j] = true;
        }
    }
    let mut done = vec![false; n];
    // Chains from their first edge, then what is left (closed loops) from any edge.
    let starts: Vec<usize> = (0..n).filter(|&i| !has_prev[i]).chain(0..n).collect();
    for i0 in starts {
        if done[i0] || !ok(&edges[i0]) {
            continue;
        }
        let mut chain = Vec::new();
        let mut i = Some(i0);
        while let Some(k) = i {
            if done[k] {
                break;
            }
            done[k] = true;
            chain.push(k);
            i = next[k];
        }
        let mut pts: Vec<[f64; 3]> = Vec::new();
        let mut d = CurbDetail::default();
        for &k in &chain {
            let e = &edges[k];
            let Some(ed) = e.detail.as_ref() else {
                continue;
            };
            pts.extend_from_slice(&e.points);
            d.class.extend_from_slice(&ed.class);
            let mut h = ed.height_m.clone();
            h.resize(e.points.len(), 0.0);
            d.height_m.extend(h);
        }
        grow_cuts(&pts, &mut d);
        flush_runs(&pts, &mut d);
        for (a, b, cat) in category_runs(&pts, &d.class, MIN_RUN_M) {
            d.class[a..=b].fill(cat);
        }
        let mut at = 0;
        for &k in &chain {
            let m = edges[k].points.len();
            if let Some(ed) = edges[k].detail.as_mut() {
                ed.class.copy_from_slice(&d.class[at..at + m]);
            }
            at += m;
        }
    }
}

/// Extends every intersection run over the vertices beside it where the edge still turns
/// at least [`TURN_RATE_DEG_M`] (the start of a corner arc), and the same way as the run's
/// vertex beside it where that one turns as much (an S-bend is not one corner).
fn grow_intersections(rate: &[f64], class: &mut [Category]) {
    let m = rate.len().min(class.len());
    let joins = |k: usize, j: usize| {
        rate[k].abs() >= TURN_RATE_DEG_M
            && (rate[j].abs() < TURN_RATE_DEG_M || rate[k] * rate[j] > 0.0)
    };
    for k in 1..m {
        if class[k - 1] == Category::Intersection
            && class[k] != Category::Intersection
            && joins(k, k - 1)
        {
            class[k] = Category::Intersection;
        }
    }
    for k in (0..m.saturating_sub(1)).rev() {
        if class[k + 1] == Category::Intersection
            && class[k] != Category::Intersection
            && joins(k, k + 1)
        {
            class[k] = Category::Intersection;
        }
    }
}

/// The edge's own turn rate at every vertex, degrees per metre, positive to the left: the
/// change of its tangent between the vertices [`TURN_RATE_HALF_M`] before and after it,
/// over the length between them (0 where the edge is shorter than that).
fn turn_rate(pts: &[[f64; 3]]) -> Vec<f64> {
    let s = arc(pts);
    let m = pts.len();
    (0..m)
        .map(|k| {
            let mut a = k;
            while a > 0 && s[k] - s[a] < TURN_RATE_HALF_M {
                a -= 1;
            }
            let mut b = k;
            while b + 1 < m && s[b] - s[k] < TURN_RATE_HALF_M {
                b += 1;
            }
            match (
                tangent(pts, a, TURN_RATE_HALF_M),
                tangent(pts, b, TURN_RATE_HALF_M),
            ) {
                (Some(ta), Some(tb)) if s[b] - s[a] >= TURN_RATE_HALF_M => {
                    let turn = (ta[0] * tb[1] - ta[1] * tb[0]).atan2(ta[0] * tb[0] + ta[1] * tb[1]);
                    turn.to_degrees() / (s[b] - s[a])
                }
                _ => 0.0,
            }
        })
        .collect()
}

/// Extends every curb-cut run over its transitions (on the closed edge): the curb vertices
/// beside it that stay more than the slack ([`CUT_SLACK`]) below the full height, the
/// median height of the curb vertices [`CUT_FULL_M`] beyond the run's end.
pub fn grow_cuts(pts: &[[f64; 3]], d: &mut CurbDetail) {
    let s = arc(pts);
    let m = d.class.len().min(pts.len()).min(d.height_m.len());
    for run in runs_of(&d.class, m, Category::CurbCut) {
        let (a, b) = (run.start, run.end - 1);
        for forward in [true, false] {
            let end = if forward { s[b] } else { s[a] };
            let beyond = |k: usize| {
                let dist = if forward { s[k] - end } else { end - s[k] };
                dist >= CUT_FULL_M.0 && dist <= CUT_FULL_M.1
            };
            let mut full: Vec<f64> = (0..m)
                .filter(|&k| beyond(k) && d.class[k] == Category::Curb)
                .map(|k| d.height_m[k])
                .collect();
            let Some(full) = super::median(&mut full) else {
                continue;
            };
            let below = full - (CUT_SLACK * full).max(CUT_SLACK_MIN_M);
            let steps: Box<dyn Iterator<Item = usize>> = if forward {
                Box::new(b + 1..m)
            } else {
                Box::new((0..a).rev())
            };
            for k in steps {
                if d.class[k] != Category::Curb || d.height_m[k] >= below {
                    break;
                }
                d.class[k] = Category::CurbCut;
            }
        }
    }
}

/// The runs `a..b` (end exclusive) of consecutive vertices of class `cat` among the first
/// `m` of `class`.
fn runs_of(class: &[Category], m: usize, cat: Category) -> Vec<std::ops::Range<usize>> {
    let mut v = Vec::new();
    let mut k = 0;
    while k < m {
        if class[k] != cat {
            k += 1;
            continue;
        }
        let a = k;
        while k < m && class[k] == cat {
            k += 1;
        }
        v.push(a..k);
    }
    v
}

/// Arc length at each vertex.
fn arc(pts: &[[f64; 3]]) -> Vec<f64> {
    let mut s = vec![0.0; pts.len()];
    for k in 1..pts.len() {
        s[k] = s[k - 1] + (pts[k][0] - pts[k - 1][0]).hypot(pts[k][1] - pts[k - 1][1]);
    }
    s
}

/// Turns runs of curb-cut vertices longer than [`FLUSH_MIN_M`] into flush ones (on the
/// closed edge, where the whole run is known).
pub fn flush_runs(pts: &[[f64; 3]], d: &mut CurbDetail) {
    let s = arc(pts);
    let m = d.class.len().min(pts.len());
    for run in runs_of(&d.class, m, Category::CurbCut) {
        if s[run.end - 1] - s[run.start] >= FLUSH_MIN_M {
            d.class[run].fill(Category::Flush);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pts(n: usize, step: f64) -> Vec<[f64; 3]> {
        (0..n).map(|i| [i as f64 * step, 0.0, 0.0]).collect()
    }

    /// The first classes of a height profile: curb cut below `CUT_MAX_M`, curb above.
    fn by_height(h: &[f64]) -> Vec<Category> {
        h.iter()
            .map(|&h| {
                if h < CUT_MAX_M {
                    Category::CurbCut
                } else {
                    Category::Curb
                }
            })
            .collect()
    }

    #[test]
    fn short_runs_join_their_neighbours_and_runs_cover_every_vertex() {
        let p = pts(101, 0.1);
        let mut c = vec![Category::Curb; 101];
        c[40..43].fill(Category::CurbCut); // 0.2 m: absorbed
        c[60..95].fill(Category::CurbCut); // 3.4 m: kept
        let runs = category_runs(&p, &c, 1.0);
        // The last 0.5 m of curb is too short for a stretch of its own.
        assert_eq!(
            runs,
            vec![(0, 60, Category::Curb), (60, 100, Category::CurbCut)]
        );
    }

    #[test]
    fn a_curb_cut_takes_its_transitions_up_to_near_the_full_height() {
        // 0.15 m curb; lowered to 0.02 m over vertices 30..=60 (0.1 m apart) with 1 m
        // linear transitions either side.
        let p = pts(101, 0.1);
        let mut d = CurbDetail::measured(&p);
        for (k, h) in d.height_m.iter_mut().enumerate() {
            let x = (k as f64 - 45.0).abs() - 15.0; // vertices beyond the lowered part
            let f = (1.0 - x / 10.0).clamp(0.0, 1.0);
            *h = 0.15 - (0.15 - 0.02) * f;
        }
        d.class = by_height(&d.height_m);
        assert_eq!(d.class[26], Category::Curb, "0.059 m before growing");
        grow_cuts(&p, &mut d);
        // The transitions' vertices below 0.15 − max(5 % of 0.15, 1 cm) = 0.14 m join the
        // cut: 21..=69 (0.137 m at 21 and 69, 0.15 m at 20 and 70).
        for k in 0..=100 {
            let want = if d.height_m[k] < 0.14 {
                Category::CurbCut
            } else {
                Category::Curb
            };
            assert_eq!(d.class[k], want, "vertex {k} at {:.4} m", d.height_m[k]);
        }
        assert_eq!(d.class[20], Category::Curb);
        assert_eq!(d.class[21], Category::CurbCut);
    }

    #[test]
    fn an_intersection_run_takes_the_start_of_its_corner_arc() {
        // A straight curb along the route (x) for 5 m, then a flared corner's first arc:
        // radius 30 m, turning left 60°, vertices 0.1 m apart. Past 30° from the route the
        // arc is an intersection; the run takes the arc down to where it leaves the curb
        // (within the ±0.5 m the turn rate is taken over), the straight curb stays curb.
        let mut p: Vec<[f64; 3]> = (0..50).map(|i| [i as f64 * 0.1 - 5.0, 0.0, 0.0]).collect();
        let r = 30.0;
        let arc_n = (r * 60f64.to_radians() / 0.1) as usize;
        p.extend((0..=arc_n).map(|i| {
            let t = i as f64 * 0.1 / r;
            [r * t.sin(), r * (1.0 - t.cos()), 0.0]
        }));
        let s = arc(&p);
        let angle =
            |k: usize| tangent(&p, k, 0.5).map_or(0.0, |t| t[1].atan2(t[0]).to_degrees().abs());
        let mut class: Vec<Category> = (0..p.len())
            .map(|k| {
                if angle(k) > TURN_DEG {
                    Category::Intersection
                } else {
                    Category::Curb
                }
            })
            .collect();
        let first = class.iter().position(|&c| c == Category::Intersection);
        assert!(
            first.is_some_and(|k| s[k] > 15.0),
            "30° lies 15.7 m into the arc"
        );
        grow_intersections(&turn_rate(&p), &mut class);
        for (k, &c) in class.iter().enumerate() {
            // The tangent point lies at s = 5 m.
            if s[k] >= 5.0 {
                assert_eq!(c, Category::Intersection, "arc vertex at s = {:.1} m", s[k]);
            } else if s[k] <= 4.0 {
                assert_eq!(c, Category::Curb, "straight vertex at s = {:.1} m", s[k]);
            }
        }
    }

    #[test]
    fn a_straight_curb_at_an_angle_to_the_route_stays_curb_beside_a_corner() {
        // A straight curb 12° from the route (where the vehicle changes lanes) for 5 m, then
        // a side street's straight curb at 70°. Above the old 8° rule, the straight curb is
        // not a corner arc: only the vertices within the ±0.5 m of the kink, where the
        // edge turns, join the intersection.
        let dir = |deg: f64| [deg.to_radians().cos(), deg.to_radians().sin()];
        let (d1, d2) = (dir(12.0), dir(70.0));
        let mut p: Vec<[f64; 3]> = (0..=50)
            .map(|i| [d1[0] * i as f64 * 0.1, d1[1] * i as f64 * 0.1, 0.0])
            .collect();
        let kink = p[50];
        p.extend((1..=30).map(|i| {
            let t = i as f64 * 0.1;
            [kink[0] + d2[0] * t, kink[1] + d2[1] * t, 0.0]
        }));
        let mut class = vec![Category::Curb; 51];
        class.extend([Category::Intersection; 30]);
        grow_intersections(&turn_rate(&p), &mut class);
        assert!(class[..=40].iter().all(|&c| c == Category::Curb));
        assert!(class[51..].iter().all(|&c| c == Category::Intersection));
    }

    #[test]
    fn a_long_low_run_is_flush_and_a_short_one_a_curb_cut() {
        let p = pts(401, 0.1);
        let mut d = CurbDetail::measured(&p);
        d.class[0..250].fill(Category::CurbCut); // 24.9 m
        d.class[300..380].fill(Category::CurbCut); // 7.9 m
        flush_runs(&p, &mut d);
        assert_eq!(d.class[10], Category::Flush);
        assert_eq!(d.class[320], Category::CurbCut);
        assert_eq!(d.class[260], Category::Curb);
    }

    #[test]
    fn a_curb_cut_takes_its_transition_on_the_edge_before_it() {
        // Edge A: 5 m of 0.15 m curb whose last 0.5 m falls to 0.06 m (a transition, no
        // vertex below CUT_MAX_M); edge B starts where A ends: a 3 m cut at 0.02 m, then
        // 3 m of curb. Alone, A is curb to its end (no cut on it to grow); as one line the
        // cut takes A's transition.
        let line = |x0: f64, n: usize, h: &dyn Fn(usize) -> f64| {
            let p: Vec<[f64; 3]> = (0..n).map(|i| [x0 + i as f64 * 0.1, 0.0, 0.0]).collect();
            let mut d = CurbDetail::measured(&p);
            d.height_m = (0..n).map(h).collect();
            d.class = by_height(&d.height_m);
            EdgeLine {
                points: p,
                side: Side::Left,
                category: None,
                method: None,
                curb_height_m: None,
                detail: Some(Box::new(d)),
            }
        };
        let a = line(0.0, 51, &|i| {
            if i < 45 {
                0.15
            } else {
                0.15 - 0.015 * (i - 44) as f64
            }
        });
        let b = line(5.0, 61, &|i| if i <= 30 { 0.02 } else { 0.15 });
        let mut alone = vec![a.clone()];
        settle_runs(&mut alone);
        assert!(alone[0]
            .detail
            .as_ref()
            .unwrap()
            .class
            .iter()
            .all(|&c| c == Category::Curb));
        // Given in the other order: the chain follows the ends, not the list.
        let mut both = vec![b, a];
        settle_runs(&mut both);
        let ca = &both[1].detail.as_ref().unwrap().class;
        let cb = &both[0].detail.as_ref().unwrap().class;
        // A's transition below 0.14 m (vertices 45..=50) joins the cut, the rest is curb.
        for (k, &c) in ca.iter().enumerate() {
            let want = if k >= 45 {
                Category::CurbCut
            } else {
                Category::Curb
            };
            assert_eq!(c, want, "A vertex {k}");
        }
        assert_eq!(cb[0], Category::CurbCut);
        assert_eq!(cb[30], Category::CurbCut);
        assert_eq!(cb[45], Category::Curb);
    }
}
