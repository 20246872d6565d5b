//! §3.4 Refined road edge extracting: by the stable road width (Eq. 3) and by road
//! continuity (Eq. 4): Euclidean clusters, line segments fitted in each, segments joined by
//! direction and position, the longest chains kept.

use super::params::QiuParams;
use crate::model::Side;
use std::collections::HashMap;

/// A candidate road-edge point with its place relative to the trajectory.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgePoint {
    /// World x, y and the terrain height under the point (grid minimum), metres.
    pub p: [f64; 3],
    /// Station of the nearest trajectory point, metres.
    pub s: f64,
    /// Signed offset from the nearest trajectory point along its left vector, metres.
    pub d: f64,
    /// The nearest trajectory point P_i (x, y).
    pub foot: [f64; 2],
}

impl EdgePoint {
    /// Left when the offset is positive.
    pub fn side(&self) -> Side {
        if self.d > 0.0 {
            Side::Left
        } else {
            Side::Right
        }
    }
}

/// The result of the road-width refinement.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct WidthRefinement {
    /// Indices of the kept points.
    pub kept: Vec<usize>,
    /// The most frequent temporary road width over all pairs, metres (for reports).
    pub road_width_m: Option<f64>,
    /// Number of left–right pairs found.
    pub pairs: usize,
}

/// The most frequent value of `vals` on bins of `bin` (ties: the smaller value), as the
/// bin centre.
fn mode(vals: impl Iterator<Item = f64>, bin: f64) -> Option<f64> {
    let mut h: HashMap<i64, usize> = HashMap::new();
    for v in vals {
        *h.entry((v / bin).floor() as i64).or_default() += 1;
    }
    h.into_iter()
        .max_by(|a, b| a.1.cmp(&b.1).then(b.0.cmp(&a.0)))
        .map(|(k, _)| (k as f64 + 0.5) * bin)
}

fn median(v: &mut [f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_unstable_by(f64::total_cmp);
    let n = v.len();
    Some(if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    })
}

/// §3.4.1, Eq. 3. For every left candidate L_i with nearest trajectory point P_i, R_i is the
/// right candidate within `width_pair_m` of the line L_i P_i nearest to P_i; |L_i R_i| is a
/// temporary road width. The most frequent width (within `width_window_m` along the
/// trajectory, so a width change inside a section is followed) is the road width, and the
/// pairs within `width_tolerance_m` of it are road-edge points.
///
/// Where the other side's edge is hidden (a parked car) a correct point has no matching
/// pair; the paper then loses it (its Urban 3). We keep such a point when its offset agrees
/// within `width_tolerance_m` with the local trend of the offsets of the matched points of
/// its side within `offset_window_m` ([`offset_trend`]), and points of a side with no matched point nearby are kept for
/// the continuity step to judge.
pub fn refine_by_width(pts: &[EdgePoint], params: &QiuParams) -> WidthRefinement {
    let mut right: Vec<usize> = (0..pts.len()).filter(|&i| pts[i].d < 0.0).collect();
    right.sort_by(|&a, &b| pts[a].s.total_cmp(&pts[b].s).then(a.cmp(&b)));
    let right_s: Vec<f64> = right.iter().map(|&i| pts[i].s).collect();
    // Only left points near the innermost left candidate of their station bin start a
    // pair, as R_i is the right candidate nearest P_i: the width is measured between the
    // innermost edges, so a wall or fence behind a curb (as many candidates per metre as
    // the curb) cannot outvote it.
    let bin = |s: f64| (s / params.bin_m).floor() as i64;
    let mut innermost: HashMap<i64, f64> = HashMap::new();
    for p in pts.iter().filter(|p| p.d > 0.0) {
        let e = innermost.entry(bin(p.s)).or_insert(f64::INFINITY);
        *e = e.min(p.d);
    }
    // (station, width, left index, right index)
    let mut pairs: Vec<(f64, f64, usize, usize)> = Vec::new();
    for (li, l) in pts
        .iter()
        .enumerate()
        .filter(|(_, p)| p.d > 0.0 && p.d <= innermost[&bin(p.s)] + params.width_tolerance_m)
    {
        let dir = [l.foot[0] - l.p[0], l.foot[1] - l.p[1]];
        let len = dir[0].hypot(dir[1]);
        if len < 1e-9 {
            continue;
        }
        let dir = [dir[0] / len, dir[1] / len];
        // On a straight road the distance to the line L_i P_i is the station difference;
        // a wider pre-filter allows for curvature.
        let reach = 4.0 * params.width_pair_m;
        let lo = right_s.partition_point(|&s| s < l.s - reach);
        let hi = right_s.partition_point(|&s| s <= l.s + reach);
        let best = right[lo..hi]
            .iter()
            .copied()
            .filter(|&ri| {
                let r = &pts[ri];
                let v = [r.p[0] - l.p[0], r.p[1] - l.p[1]];
                (v[0] * dir[1] - v[1] * dir[0]).abs() <= params.width_pair_m
            })
            .min_by(|&a, &b| pts[a].d.abs().total_cmp(&pts[b].d.abs()).then(a.cmp(&b)));
        if let Some(ri) = best {
            let r = &pts[ri];
            pairs.push((l.s, (r.p[0] - l.p[0]).hypot(r.p[1] - l.p[1]), li, ri));
        }
    }
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.2.cmp(&b.2)));
    let road_width_m = mode(pairs.iter().map(|p| p.1), params.width_bin_m);
    // Matched points per side: (station, |offset|).
    let mut matched: [Vec<(f64, f64)>; 2] = [Vec::new(), Vec::new()];
    let half = 0.5 * params.width_window_m;
    let mut is_matched = vec![false; pts.len()];
    // The most frequent width of every pair's window: the window slides along the sorted
    // stations, so one histogram is updated as pairs enter and leave it.
    let bins: Vec<i64> = pairs
        .iter()
        .map(|p| (p.1 / params.width_bin_m).floor() as i64)
        .collect();
    let kmin = bins.iter().copied().min().unwrap_or(0);
    let kmax = bins.iter().copied().max().unwrap_or(0);
    let mut hist = vec![0usize; (kmax - kmin + 1) as usize];
    let (mut lo, mut hi) = (0, 0);
    let mut window_mode: Option<(usize, usize, f64)> = None;
    for (k, &(s, w, li, ri)) in pairs.iter().enumerate() {
        while hi < pairs.len() && pairs[hi].0 <= s + half {
            hist[(bins[hi] - kmin) as usize] += 1;
            hi += 1;
        }
        while lo < k && pairs[lo].0 < s - half {
            hist[(bins[lo] - kmin) as usize] -= 1;
            lo += 1;
        }
        let wm = match window_mode {
            Some((a, b, m)) if (a, b) == (lo, hi) => m,
            _ => {
                // Ties go to the smaller width, as in `mode`.
                let (best, _) =
                    hist.iter().enumerate().fold(
                        (0, 0),
                        |(bi, bc), (i, &c)| if c > bc { (i, c) } else { (bi, bc) },
                    );
                let m = ((best as i64 + kmin) as f64 + 0.5) * params.width_bin_m;
                window_mode = Some((lo, hi, m));
                m
            }
        };
        if (w - wm).abs() <= params.width_tolerance_m {
            is_matched[li] = true;
            is_matched[ri] = true;
        }
    }
    for (p, _) in pts.iter().zip(&is_matched).filter(|(_, &m)| m) {
        matched[usize::from(p.d < 0.0)].push((p.s, p.d.abs()));
    }
    for m in &mut matched {
        m.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    }
    let ohalf = 0.5 * params.offset_window_m;
    // Points with the same window share its trend line.
    let mut window_trend: [HashMap<(usize, usize), Option<TrendLine>>; 2] = Default::default();
    let mut kept = Vec::new();
    for (i, p) in pts.iter().enumerate() {
        if is_matched[i] {
            kept.push(i);
            continue;
        }
        let side = usize::from(p.d < 0.0);
        let m = &matched[side];
        let lo = m.partition_point(|q| q.0 < p.s - ohalf);
        let hi = m.partition_point(|q| q.0 <= p.s + ohalf);
        let line = *window_trend[side]
            .entry((lo, hi))
            .or_insert_with(|| offset_trend(&m[lo..hi]));
        match line.map(|(s0, s1, o0, slope)| o0 + (p.s.clamp(s0, s1) - s0) * slope) {
            None => kept.push(i),
            Some(e) if (p.d.abs() - e).abs() <= params.width_tolerance_m => kept.push(i),
            Some(_) => {}
        }
    }
    WidthRefinement {
        kept,
        road_width_m,
        pairs: pairs.len(),
    }
}

/// Least distance along the trajectory between the median points of a window's two halves
/// for [`offset_trend`] to draw a line through them, metres: over a shorter base the
/// offsets' scatter (a few centimetres) would tilt the line.
const TREND_MIN_BASE_M: f64 = 1.0;

/// Steepest drift of an edge's offset [`offset_trend`] follows, metres per metre: a lane
/// change on the random streets is at most 26° to the curb (0.49).
const TREND_MAX_SLOPE: f64 = 0.5;

/// (first station, second station, offset at the first, offset per metre): see
/// [`offset_trend`].
type TrendLine = (f64, f64, f64, f64);

/// The line along which a side's edge is expected, from its matched points (station,
/// |offset|, sorted by station) within a window: through the median point (median
/// station, median offset) of the first half of them and that of the second half, as
/// (first station, second station, offset at the first, offset per metre); a point is
/// compared with the line between the two stations and with the nearer median point
/// beyond them (the line is not extrapolated: a drift that starts or ends inside the
/// window would carry it off). Where the vehicle changes lanes or the road widens the
/// edge's offset drifts (5.5 m over 25 m), and a plain median of the window lags the
/// drift by more than `width_tolerance_m`; the medians keep the line clear of the odd
/// stray pair, as one median does. The slope is held to [`TREND_MAX_SLOPE`]. Over a
/// base shorter than [`TREND_MIN_BASE_M`], the window's median offset, level; `None` for
/// an empty window.
fn offset_trend(window: &[(f64, f64)]) -> Option<TrendLine> {
    let median_point = |h: &[(f64, f64)]| {
        let mut st: Vec<f64> = h.iter().map(|q| q.0).collect();
        let mut off: Vec<f64> = h.iter().map(|q| q.1).collect();
        Some((median(&mut st)?, median(&mut off)?))
    };
    let (a, b) = window.split_at(window.len() / 2);
    if let (Some(a), Some(b)) = (median_point(a), median_point(b)) {
        if b.0 - a.0 >= TREND_MIN_BASE_M {
            let slope = ((b.1 - a.1) / (b.0 - a.0)).clamp(-TREND_MAX_SLOPE, TREND_MAX_SLOPE);
            return Some((a.0, b.0, a.1, slope));
        }
    }
    median_point(window).map(|(s0, o0)| (s0, s0, o0, 0.0))
}

/// Euclidean cluster extraction (2D): points closer than `tol` (directly or through
/// others) share a cluster. Clusters are returned with their members in index order,
/// ordered by their smallest member.
pub fn euclidean_clusters(xy: &[[f64; 2]], tol: f64) -> Vec<Vec<usize>> {
    let key = |p: &[f64; 2]| ((p[0] / tol).floor() as i64, (p[1] / tol).floor() as i64);
    let mut grid: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
    for (i, p) in xy.iter().enumerate() {
        grid.entry(key(p)).or_default().push(i);
    }
    let mut parent: Vec<usize> = (0..xy.len()).collect();
    fn find(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let t2 = tol * tol;
    for (i, p) in xy.iter().enumerate() {
        let k = key(p);
        for dx in -1..=1 {
            for dy in -1..=1 {
                let Some(cell) = grid.get(&(k.0 + dx, k.1 + dy)) else {
                    continue;
                };
                for &j in cell {
                    if j > i && (xy[j][0] - p[0]).powi(2) + (xy[j][1] - p[1]).powi(2) <= t2 {
                        let (a, b) = (find(&mut parent, i), find(&mut parent, j));
                        if a != b {
                            parent[a.max(b)] = a.min(b);
                        }
                    }
                }
            }
        }
    }
    let mut by_root: HashMap<usize, Vec<usize>> = HashMap::new();
    for i in 0..xy.len() {
        let r = find(&mut parent, i);
        by_root.entry(r).or_default().push(i);
    }
    let mut out: Vec<Vec<usize>> = by_root.into_values().collect();
    out.sort_by_key(|c| c[0]);
    out
}

/// Douglas–Peucker: the indices of the vertices kept at tolerance `tol`.
pub fn douglas_peucker(pts: &[[f64; 3]], tol: f64) -> Vec<usize> {
    if pts.len() <= 2 {
        return (0..pts.len()).collect();
    }
    let mut keep = vec![false; pts.len()];
    keep[0] = true;
    keep[pts.len() - 1] = true;
    let mut stack = vec![(0, pts.len() - 1)];
    while let Some((a, b)) = stack.pop() {
        if b <= a + 1 {
            continue;
        }
        let (pa, pb) = (pts[a], pts[b]);
        let (ux, uy) = (pb[0] - pa[0], pb[1] - pa[1]);
        let len = ux.hypot(uy);
        let mut far = (a, 0.0);
        for (k, p) in pts.iter().enumerate().take(b).skip(a + 1) {
            let dist = if len < 1e-12 {
                (p[0] - pa[0]).hypot(p[1] - pa[1])
            } else {
                ((p[0] - pa[0]) * uy - (p[1] - pa[1]) * ux).abs() / len
            };
            if dist > far.1 {
                far = (k, dist);
            }
        }
        if far.1 > tol {
            keep[far.0] = true;
            stack.push((a, far.0));
            stack.push((far.0, b));
        }
    }
    (0..pts.len()).filter(|&i| keep[i]).collect()
}

/// A road-edge polyline with the station of every vertex.
#[derive(Clone, Debug, PartialEq)]
pub struct Chain {
    /// Side of the trajectory.
    pub side: Side,
    /// Vertices: world x, y and terrain z.
    pub pts: Vec<[f64; 3]>,
    /// Station of every vertex.
    pub s: Vec<f64>,
    /// Height step across the line at every vertex, metres (NaN where unknown,
    /// [`NO_GROUND`] where its raised side has no ground).
    pub h: Vec<f64>,
    /// The line runs across the trajectory (a side street's curb beyond a corner), not
    /// along it: its vertices are ordered by offset, not by station (see
    /// [`split_across`]).
    pub across: bool,
}

impl Chain {
    /// Horizontal length.
    pub fn length_m(&self) -> f64 {
        self.pts
            .windows(2)
            .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
            .sum()
    }

    fn s_range(&self) -> (f64, f64) {
        self.s
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &s| {
                (a.min(s), b.max(s))
            })
    }

    /// Unit direction of the last (`at_end`) or first segment.
    fn direction(&self, at_end: bool) -> Option<[f64; 2]> {
        let n = self.pts.len();
        if n < 2 {
            return None;
        }
        let (a, b) = if at_end {
            (self.pts[n - 2], self.pts[n - 1])
        } else {
            (self.pts[0], self.pts[1])
        };
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let len = dx.hypot(dy);
        (len > 1e-9).then(|| [dx / len, dy / len])
    }
}

/// The line segments of one cluster (§3.4.2 step 2): the cluster's points are ordered along
/// its main direction (PCA), summarised every `bin_m` by the median x, y, z and station,
/// and simplified into line segments by Douglas–Peucker. Oriented along increasing station.
///
/// `preferred` (by point index; empty: none): in a bin holding preferred points, only they
/// give the median (the points the width step kept, where a cluster was kept whole).
pub fn fit_segments(
    pts: &[EdgePoint],
    members: &[usize],
    preferred: &[bool],
    params: &QiuParams,
) -> Option<Chain> {
    let n = members.len() as f64;
    let (mx, my) = members.iter().fold((0.0, 0.0), |(a, b), &i| {
        (a + pts[i].p[0] / n, b + pts[i].p[1] / n)
    });
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for &i in members {
        let (dx, dy) = (pts[i].p[0] - mx, pts[i].p[1] - my);
        sxx += dx * dx;
        sxy += dx * dy;
        syy += dy * dy;
    }
    // Main axis of the 2×2 covariance.
    let theta = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    let u = [theta.cos(), theta.sin()];
    let mut bins: std::collections::BTreeMap<i64, Vec<usize>> = Default::default();
    for &i in members {
        let t = (pts[i].p[0] - mx) * u[0] + (pts[i].p[1] - my) * u[1];
        bins.entry((t / params.bin_m).floor() as i64)
            .or_default()
            .push(i);
    }
    let mut verts = Vec::with_capacity(bins.len());
    let mut stations = Vec::with_capacity(bins.len());
    for b in bins.values() {
        let pref: Vec<usize> = b
            .iter()
            .copied()
            .filter(|&i| preferred.get(i).copied().unwrap_or(false))
            .collect();
        let b = if pref.is_empty() { b } else { &pref };
        let col = |f: &dyn Fn(&EdgePoint) -> f64| {
            let mut v: Vec<f64> = b.iter().map(|&i| f(&pts[i])).collect();
            median(&mut v).unwrap_or(f64::NAN)
        };
        verts.push([col(&|p| p.p[0]), col(&|p| p.p[1]), col(&|p| p.p[2])]);
        stations.push(col(&|p| p.s));
    }
    let keep = douglas_peucker(&verts, params.segment_tolerance_m);
    let mut chain = Chain {
        side: pts[members[0]].side(),
        pts: keep.iter().map(|&k| verts[k]).collect(),
        s: keep.iter().map(|&k| stations[k]).collect(),
        h: vec![f64::NAN; keep.len()],
        across: false,
    };
    if chain.s.last()? < chain.s.first()? {
        chain.pts.reverse();
        chain.s.reverse();
    }
    Some(chain)
}

/// Whether chain `b` continues chain `a` (§3.4.2 step 3, Eq. 4's K < γ): the gap from `a`'s
/// end to `b`'s start is at most `join_gap_m`, `b` starts beyond `a`'s end along the
/// trajectory, the directions differ by at most γ and `b`'s start lies within
/// `join_lateral_m` of the line of `a`'s last segment. Returns the gap.
fn continues(a: &Chain, b: &Chain, params: &QiuParams) -> Option<f64> {
    continues_within(a, b, params, params.join_gap_m)
}

/// [`continues`] with a gap of at most `max_gap` metres.
fn continues_within(a: &Chain, b: &Chain, params: &QiuParams, max_gap: f64) -> Option<f64> {
    let (ea, sb) = (a.pts.last()?, b.pts.first()?);
    let gap = (sb[0] - ea[0]).hypot(sb[1] - ea[1]);
    if gap > max_gap || b.s[0] < a.s[a.s.len() - 1] - params.join_lateral_m {
        return None;
    }
    if let Some(da) = a.direction(true) {
        let lateral = ((sb[0] - ea[0]) * da[1] - (sb[1] - ea[1]) * da[0]).abs();
        if lateral > params.join_lateral_m {
            return None;
        }
        if let Some(db) = b.direction(false) {
            let cos = (da[0] * db[0] + da[1] * db[1]).clamp(-1.0, 1.0);
            if cos.acos().to_degrees() > params.join_angle_deg {
                return None;
            }
        }
    }
    Some(gap)
}

/// Joins chains of one side end to start (§3.4.2 step 3), greedily in order of their first
/// station: each chain is appended to the already built chain it continues with the
/// smallest gap, else starts a new one.
pub fn join_chains(mut pieces: Vec<Chain>, params: &QiuParams) -> Vec<Chain> {
    pieces.sort_by(|a, b| {
        a.s[0]
            .total_cmp(&b.s[0])
            .then(a.pts[0][0].total_cmp(&b.pts[0][0]))
    });
    let mut out: Vec<Chain> = Vec::new();
    for p in pieces {
        let best = out
            .iter()
            .enumerate()
            .filter(|(_, c)| c.side == p.side)
            .filter_map(|(k, c)| continues(c, &p, params).map(|g| (k, g)))
            .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
        match best {
            Some((k, _)) => {
                let c = &mut out[k];
                // Drop a duplicated vertex where two clipped pieces meet (the two
                // sections' lines agree to a few millimetres there).
                let skip = usize::from(
                    p.pts.len() > 1
                        && (c.pts[c.pts.len() - 1][0] - p.pts[0][0])
                            .hypot(c.pts[c.pts.len() - 1][1] - p.pts[0][1])
                            < 0.05,
                );
                c.pts.extend_from_slice(&p.pts[skip..]);
                c.s.extend_from_slice(&p.s[skip..]);
                c.h.extend_from_slice(&p.h[skip..]);
            }
            None => out.push(p),
        }
    }
    out
}

/// Joins chains of one side across gaps longer than the joins of [`join_chains`] bridge,
/// up to `bridge_gap_m`, where the ground says an edge runs on between them: the straight
/// line from one chain's end to the next one's start (lined up as [`continues`] asks),
/// with a vertex every `step` metres, its height steps measured by `measure`, must be
/// measured over at least half its length, step up outward by `min_step_m` to
/// `max_step_m` (length-weighted median) and nowhere above `max_step_m`. A curb cut
/// without a lip passes (its ramp rises from the toe, yet gives no candidates: no pavement
/// point beside the ramp's foot lies a β lower); an intersection's mouth is flat across
/// and a parked car's side too high. Lines across the trajectory are left as they are.
pub fn bridge_gaps(
    mut chains: Vec<Chain>,
    params: &QiuParams,
    step: f64,
    measure: &dyn Fn(&mut Chain),
) -> Vec<Chain> {
    if params.bridge_gap_m <= 0.0 {
        return chains;
    }
    chains.sort_by(|a, b| {
        a.side
            .cmp(&b.side)
            .then(a.across.cmp(&b.across))
            .then(a.s[0].total_cmp(&b.s[0]))
    });
    let mut i = 0;
    while i < chains.len() {
        if chains[i].across {
            i += 1;
            continue;
        }
        // The nearest later chain that the ground lets this one join.
        let mut options: Vec<(usize, f64)> = (i + 1..chains.len())
            .filter(|&k| chains[k].side == chains[i].side && !chains[k].across)
            .filter_map(|k| {
                continues_within(&chains[i], &chains[k], params, params.bridge_gap_m)
                    .map(|g| (k, g))
            })
            .collect();
        options.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
        let joined = options.into_iter().find_map(|(k, _)| {
            let (a, b) = (&chains[i], &chains[k]);
            let (ea, sb) = (a.pts[a.pts.len() - 1], b.pts[0]);
            let mut bridge = densify(
                &Chain {
                    side: a.side,
                    pts: vec![ea, sb],
                    s: vec![a.s[a.s.len() - 1], b.s[0]],
                    h: vec![f64::NAN; 2],
                    across: false,
                },
                step,
            );
            measure(&mut bridge);
            let (measured, wall) = measured_and_wall_shares(&bridge, params.max_step_m);
            let stepped = median_step(&bridge)
                .is_some_and(|h| (params.min_step_m..=params.max_step_m).contains(&h));
            (measured >= 0.5 && wall == 0.0 && stepped).then_some((k, bridge))
        });
        match joined {
            Some((k, bridge)) => {
                let b = chains.remove(k);
                let a = &mut chains[i];
                let inner = 1..bridge.pts.len() - 1;
                a.pts.extend_from_slice(&bridge.pts[inner.clone()]);
                a.s.extend_from_slice(&bridge.s[inner.clone()]);
                a.h.extend_from_slice(&bridge.h[inner]);
                a.pts.extend_from_slice(&b.pts);
                a.s.extend_from_slice(&b.s);
                a.h.extend_from_slice(&b.h);
            }
            None => i += 1,
        }
    }
    chains
}

/// §3.4.2 step 4: chains shorter than `min_chain_m` are dropped; of chains on the same
/// side overlapping along the trajectory by more than `max_chain_overlap` of the shorter
/// one's extent, only the longest is kept (lines across the trajectory are not compared).
pub fn keep_longest(mut chains: Vec<Chain>, params: &QiuParams) -> Vec<Chain> {
    chains.retain(|c| c.length_m() >= params.min_chain_m);
    chains.sort_by(|a, b| {
        b.length_m()
            .total_cmp(&a.length_m())
            .then(a.s[0].total_cmp(&b.s[0]))
    });
    let mut kept: Vec<Chain> = Vec::new();
    for c in chains {
        let (a0, a1) = c.s_range();
        let ext = (a1 - a0).max(1e-9);
        // A line across the trajectory has no station extent to compare.
        let overlaps = !c.across
            && kept
                .iter()
                .filter(|k| k.side == c.side && !k.across)
                .any(|k| {
                    let (b0, b1) = k.s_range();
                    (a1.min(b1) - a0.max(b0)).max(0.0) > params.max_chain_overlap * ext
                });
        if !overlaps {
            kept.push(c);
        }
    }
    kept.sort_by(|a, b| a.side.cmp(&b.side).then(a.s[0].total_cmp(&b.s[0])));
    kept
}

/// Cells carrying the local direction of a side's candidates in [`split_across`], metres.
const DIRECTION_CELL_M: f64 = 0.5;
/// The local direction is taken over this many cells either side of a point's cell
/// (2 cells of 0.5 m: a 2.5 m square, long enough for the direction of a curb, short
/// enough to follow a corner of 3 m radius).
const DIRECTION_REACH_CELLS: i64 = 2;
/// A neighbourhood is a line when its spread across its main direction is below this
/// share of its spread along it (ratio of the covariance's eigenvalues): a curb's band of
/// candidates gives under 0.01, scattered road noise near 1.
const LINE_EIGEN_RATIO: f64 = 0.2;

/// Which candidates lie on a line running across the trajectory — a side street's curb
/// beyond a corner, whose offset grows while its station stands still. Per point of
/// `members`: `true` when the candidates in the 2.5 m square around it form a line
/// ([`LINE_EIGEN_RATIO`]) within 45° of the perpendicular from the point to its nearest
/// trajectory point. Such a line is not a function of the station: summarised along the
/// cluster's main direction (as [`fit_segments`] does) it collapses into a vertex or two,
/// and the width step, which compares offsets with the road's, drops it.
pub fn split_across(pts: &[EdgePoint], members: &[usize]) -> Vec<bool> {
    let key = |p: &EdgePoint| {
        (
            (p.p[0] / DIRECTION_CELL_M).floor() as i64,
            (p.p[1] / DIRECTION_CELL_M).floor() as i64,
        )
    };
    let mut cells: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
    for &i in members {
        cells.entry(key(&pts[i])).or_default().push(i);
    }
    // Per cell: the unit main direction of its neighbourhood, when it is a line.
    let mut dir: HashMap<(i64, i64), Option<[f64; 2]>> = HashMap::new();
    for &k in cells.keys() {
        let r = DIRECTION_REACH_CELLS;
        let mut near: Vec<[f64; 2]> = Vec::new();
        for dx in -r..=r {
            for dy in -r..=r {
                if let Some(c) = cells.get(&(k.0 + dx, k.1 + dy)) {
                    near.extend(c.iter().map(|&i| [pts[i].p[0], pts[i].p[1]]));
                }
            }
        }
        dir.insert(k, line_direction(&near));
    }
    members
        .iter()
        .map(|&i| {
            let p = &pts[i];
            let n = [p.p[0] - p.foot[0], p.p[1] - p.foot[1]];
            let len = n[0].hypot(n[1]);
            match dir[&key(p)] {
                Some(u) if len > 1e-9 => {
                    (u[0] * n[0] + u[1] * n[1]).abs() / len > std::f64::consts::FRAC_1_SQRT_2
                }
                _ => false,
            }
        })
        .collect()
}

/// The unit main direction of a 2D point set when it is a line (see
/// [`LINE_EIGEN_RATIO`]); `None` for fewer than 3 points or a blob.
fn line_direction(xy: &[[f64; 2]]) -> Option<[f64; 2]> {
    if xy.len() < 3 {
        return None;
    }
    let n = xy.len() as f64;
    let (mx, my) = xy
        .iter()
        .fold((0.0, 0.0), |(a, b), p| (a + p[0] / n, b + p[1] / n));
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for p in xy {
        let (dx, dy) = (p[0] - mx, p[1] - my);
        sxx += dx * dx;
        sxy += dx * dy;
        syy += dy * dy;
    }
    let tr = sxx + syy;
    let det = sxx * syy - sxy * sxy;
    let disc = (0.25 * tr * tr - det).max(0.0).sqrt();
    let (l1, l2) = (0.5 * tr + disc, 0.5 * tr - disc);
    if !(l1 > 0.0 && l2 <= LINE_EIGEN_RATIO * l1) {
        return None;
    }
    let theta = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    Some([theta.cos(), theta.sin()])
}

/// The line of a cluster running across the trajectory ([`split_across`]): its points
/// summarised every `bin_m` of offset by their median x, y, z and station, simplified by
/// Douglas–Peucker, ordered by growing offset. Which side of it is the road is left to
/// the height step (see `qiu::extract_edges`).
pub fn fit_across(pts: &[EdgePoint], members: &[usize], params: &QiuParams) -> Option<Chain> {
    let mut bins: std::collections::BTreeMap<i64, Vec<usize>> = Default::default();
    for &i in members {
        bins.entry((pts[i].d.abs() / params.bin_m).floor() as i64)
            .or_default()
            .push(i);
    }
    let mut verts = Vec::with_capacity(bins.len());
    let mut stations = Vec::with_capacity(bins.len());
    for b in bins.values() {
        let col = |f: &dyn Fn(&EdgePoint) -> f64| {
            let mut v: Vec<f64> = b.iter().map(|&i| f(&pts[i])).collect();
            median(&mut v).unwrap_or(f64::NAN)
        };
        verts.push([col(&|p| p.p[0]), col(&|p| p.p[1]), col(&|p| p.p[2])]);
        stations.push(col(&|p| p.s));
    }
    if verts.len() < 2 {
        return None;
    }
    let keep = douglas_peucker(&verts, params.segment_tolerance_m);
    Some(Chain {
        side: pts[*members.first()?].side(),
        pts: keep.iter().map(|&k| verts[k]).collect(),
        s: keep.iter().map(|&k| stations[k]).collect(),
        h: vec![f64::NAN; keep.len()],
        across: true,
    })
}

/// §3.4.2 steps 1–3 after the width refinement (`kept`): clusters per side, line segments
/// per cluster, joined. A cluster of which at least `cluster_keep_share` was kept by the
/// width step is used whole (its kept points still place the line wherever they are, see
/// [`fit_segments`]'s `preferred`); of other clusters only the kept points count. Measured
/// on `kawasaki` (200 mm): completeness 90.1 → 93.6 % (bus bay 70 → 100 %, right-hand
/// intersection 22 → 76 %), correctness 100 % both; at 50 mm the line is less exact where
/// only unkept points place it (completeness 84 → 78 %). Candidates on lines running
/// across the trajectory ([`split_across`]) are taken out first and fitted on their own
/// ([`fit_across`]), whether the width step kept them or not: the width step judges
/// offsets from the trajectory, which such a line does not keep. Step 4
/// ([`keep_longest`]) follows once heights are known.
pub fn refine_by_continuity(pts: &[EdgePoint], kept: &[usize], params: &QiuParams) -> Vec<Chain> {
    let mut is_kept = vec![false; pts.len()];
    for &i in kept {
        is_kept[i] = true;
    }
    let mut pieces = Vec::new();
    for side in [Side::Left, Side::Right] {
        let candidates: Vec<usize> = (0..pts.len()).filter(|&i| pts[i].side() == side).collect();
        let xy_of = |ids: &[usize]| -> Vec<[f64; 2]> {
            ids.iter().map(|&i| [pts[i].p[0], pts[i].p[1]]).collect()
        };
        let mut all = Vec::new();
        let mut across = Vec::new();
        for cluster in euclidean_clusters(&xy_of(&candidates), params.cluster_tolerance_m) {
            let members: Vec<usize> = cluster.iter().map(|&k| candidates[k]).collect();
            let flags = if params.split_across {
                split_across(pts, &members)
            } else {
                vec![false; members.len()]
            };
            for (i, f) in members.into_iter().zip(flags) {
                if f {
                    across.push(i);
                } else {
                    all.push(i);
                }
            }
        }
        for c in euclidean_clusters(&xy_of(&across), params.cluster_tolerance_m) {
            if c.len() < params.min_cluster_points {
                continue;
            }
            let members: Vec<usize> = c.iter().map(|&k| across[k]).collect();
            pieces.extend(fit_across(pts, &members, params));
        }
        // Clusters of the side's other candidates; a cluster mostly kept by the width step
        // is kept whole, so a curb that turns a corner keeps its arc (whose offset leaves
        // the road's width) with the straight part it is joined to; of any other cluster
        // only the kept points count, clustered anew.
        let mut groups: Vec<Vec<usize>> = Vec::new();
        for cluster in euclidean_clusters(&xy_of(&all), params.cluster_tolerance_m) {
            let members: Vec<usize> = cluster.iter().map(|&k| all[k]).collect();
            let n_kept = members.iter().filter(|&&i| is_kept[i]).count();
            let (d_lo, d_hi) = members
                .iter()
                .fold((f64::INFINITY, 0.0f64), |(lo, hi), &i| {
                    (lo.min(pts[i].d.abs()), hi.max(pts[i].d.abs()))
                });
            if n_kept as f64 >= params.cluster_keep_share * members.len() as f64 && n_kept > 0 {
                groups.push(members);
                continue;
            }
            // A cluster that leaves the road's offsets is kept whole when it is one thin
            // line (not a patch of scattered candidates) that turns away from the road at
            // its outer end, as a corner's arc does; a curb whose offset changes because
            // the road widens or the vehicle changes lanes stays parallel to the heading.
            if params.cluster_keep_spread_m > 0.0
                && d_hi - d_lo >= params.cluster_keep_spread_m
                && members.len() >= params.min_cluster_points
            {
                if let Some(c) = fit_segments(pts, &members, &[], params) {
                    if is_thin_line(&c, pts, &members, 2.0 * params.segment_tolerance_m)
                        && turns_away(&c, pts, &members, params.cluster_keep_turn_deg)
                    {
                        pieces.push(c);
                        continue;
                    }
                }
            }
            let sub: Vec<usize> = members.into_iter().filter(|&i| is_kept[i]).collect();
            for c in euclidean_clusters(&xy_of(&sub), params.cluster_tolerance_m) {
                groups.push(c.iter().map(|&k| sub[k]).collect());
            }
        }
        for members in groups {
            if members.len() < params.min_cluster_points {
                continue;
            }
            if let Some(c) = fit_segments(pts, &members, &is_kept, params) {
                pieces.push(c);
            }
        }
    }
    join_chains(pieces, params)
}

/// Whether the chain's segment at its outer end (the end whose nearest candidate lies
/// farther from the trajectory) runs away from the trajectory at `min_deg` or more to the
/// heading there. The heading is taken square to the nearest candidate's offset vector
/// (`p − foot`).
fn turns_away(c: &Chain, pts: &[EdgePoint], members: &[usize], min_deg: f64) -> bool {
    let n = c.pts.len();
    if n < 2 {
        return false;
    }
    let nearest = |v: [f64; 3]| {
        members.iter().copied().min_by(|&a, &b| {
            let da = (pts[a].p[0] - v[0]).hypot(pts[a].p[1] - v[1]);
            let db = (pts[b].p[0] - v[0]).hypot(pts[b].p[1] - v[1]);
            da.total_cmp(&db)
        })
    };
    let (Some(first), Some(last)) = (nearest(c.pts[0]), nearest(c.pts[n - 1])) else {
        return false;
    };
    let (inner, outer, e) = if pts[last].d.abs() >= pts[first].d.abs() {
        (c.pts[n - 2], c.pts[n - 1], &pts[last])
    } else {
        (c.pts[1], c.pts[0], &pts[first])
    };
    let u = [outer[0] - inner[0], outer[1] - inner[1]];
    let nv = [e.p[0] - e.foot[0], e.p[1] - e.foot[1]];
    let (lu, ln) = (u[0].hypot(u[1]), nv[0].hypot(nv[1]));
    if lu <= 0.0 || ln <= 0.0 {
        return false;
    }
    (u[0] * nv[0] + u[1] * nv[1]) / (lu * ln) >= min_deg.to_radians().sin()
}

/// Whether at least 3 in 4 of a cluster's points lie within `tol` of the line fitted to it
/// (twice the fit's tolerance holds a curb's band of candidates; scattered candidates sit
/// up to metres off the line of their bin medians).
fn is_thin_line(c: &Chain, pts: &[EdgePoint], members: &[usize], tol: f64) -> bool {
    if c.pts.len() < 2 {
        return false;
    }
    let near = members
        .iter()
        .filter(|&&i| {
            let p = pts[i].p;
            c.pts.windows(2).any(|w| {
                let (a, b) = (w[0], w[1]);
                let (ux, uy) = (b[0] - a[0], b[1] - a[1]);
                let l2 = ux * ux + uy * uy;
                let t = if l2 > 0.0 {
                    (((p[0] - a[0]) * ux + (p[1] - a[1]) * uy) / l2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                (p[0] - a[0] - t * ux).hypot(p[1] - a[1] - t * uy) <= tol
            })
        })
        .count();
    4 * near >= 3 * members.len()
}

/// The chain with vertices inserted so that none is more than `step` from the next (the
/// line itself unchanged; stations and height steps interpolated linearly), so that the
/// height step measured at the vertices samples the whole line, not only its bends.
pub fn densify(c: &Chain, step: f64) -> Chain {
    let mut out = Chain {
        side: c.side,
        pts: Vec::with_capacity(c.pts.len()),
        s: Vec::with_capacity(c.pts.len()),
        h: Vec::with_capacity(c.pts.len()),
        across: c.across,
    };
    for k in 0..c.pts.len() {
        if k > 0 {
            let (a, b) = (c.pts[k - 1], c.pts[k]);
            let len = (b[0] - a[0]).hypot(b[1] - a[1]);
            let n = (len / step).ceil() as usize;
            for j in 1..n {
                let w = j as f64 / n as f64;
                out.pts.push([
                    a[0] + w * (b[0] - a[0]),
                    a[1] + w * (b[1] - a[1]),
                    a[2] + w * (b[2] - a[2]),
                ]);
                out.s.push(c.s[k - 1] + w * (c.s[k] - c.s[k - 1]));
                out.h.push(c.h[k - 1] + w * (c.h[k] - c.h[k - 1]));
            }
        }
        out.pts.push(c.pts[k]);
        out.s.push(c.s[k]);
        out.h.push(c.h[k]);
    }
    out
}

/// Each vertex's height step with the length of line it stands for (half of each segment
/// it ends), metres.
fn weighted_steps(c: &Chain) -> Vec<(f64, f64)> {
    let seg = |k: usize| {
        let (a, b) = (c.pts[k], c.pts[k + 1]);
        (b[0] - a[0]).hypot(b[1] - a[1])
    };
    let n = c.pts.len();
    (0..n)
        .map(|k| {
            let before = if k > 0 { seg(k - 1) } else { 0.0 };
            let after = if k + 1 < n { seg(k) } else { 0.0 };
            (c.h[k], 0.5 * (before + after))
        })
        .collect()
}

/// The median of the measured height steps of a chain's vertices (`None` where none is
/// measured), each weighted by the length of line it stands for: the line fit places few
/// vertices on a long straight curb and many on a short curb cut's bends, so the plain
/// median of the vertices would call a curb with one cut in it a cut (or no edge).
pub fn median_step(c: &Chain) -> Option<f64> {
    let mut hw: Vec<(f64, f64)> = weighted_steps(c)
        .into_iter()
        .filter(|q| q.0.is_finite())
        .collect();
    let total: f64 = hw.iter().map(|q| q.1).sum();
    if total.is_nan() || total <= 0.0 {
        let mut hs: Vec<f64> = hw.iter().map(|q| q.0).collect();
        return median(&mut hs);
    }
    hw.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
    let mut acc = 0.0;
    for &(h, w) in &hw {
        acc += w;
        if acc >= 0.5 * total {
            return Some(h);
        }
    }
    hw.last().map(|q| q.0)
}

/// The height step of a vertex with no ground on its raised side (see
/// `HeightGrid::measure_steps` in the module root): not a measured step.
pub const NO_GROUND: f64 = f64::NEG_INFINITY;

/// The share of a chain's length whose vertices have no ground on their raised side
/// ([`NO_GROUND`]); 0 for a chain without length.
pub fn no_ground_share(c: &Chain) -> f64 {
    let hw = weighted_steps(c);
    let total: f64 = hw.iter().map(|q| q.1).sum();
    if total.is_nan() || total <= 0.0 {
        return 0.0;
    }
    hw.iter()
        .filter(|q| q.0 == NO_GROUND)
        .map(|q| q.1)
        .sum::<f64>()
        / total
}

/// The shares of a chain's length whose height step is measured and whose measured step
/// is above `wall_m` (a wall or a building front, not a curb), each a fraction of the
/// whole length; `(0, 0)` for a chain without length. On a line across the trajectory a
/// step below −`wall_m` is a wall too: its road side is only the side of the larger
/// median step, and a wall on the side taken for the road is as much a wall.
pub fn measured_and_wall_shares(c: &Chain, wall_m: f64) -> (f64, f64) {
    let hw = weighted_steps(c);
    let total: f64 = hw.iter().map(|q| q.1).sum();
    if total.is_nan() || total <= 0.0 {
        return (0.0, 0.0);
    }
    let measured: f64 = hw.iter().filter(|q| q.0.is_finite()).map(|q| q.1).sum();
    let walled = |h: f64| h > wall_m || (c.across && h.is_finite() && -h > wall_m);
    let wall: f64 = hw.iter().filter(|q| walled(q.0)).map(|q| q.1).sum();
    (measured / total, wall / total)
}

/// Cuts a chain to the stations `[a, b]` (the section's core), interpolating a vertex
/// where it crosses a bound (stations vary linearly along each segment); returns the pieces
/// inside, each with at least two vertices.
pub fn clip_to_stations(c: &Chain, a: f64, b: f64) -> Vec<Chain> {
    let mut out = Vec::new();
    let mut cur: Option<Chain> = None;
    let at = |i: usize, w: f64| -> ([f64; 3], f64, f64) {
        let j = (i + 1).min(c.pts.len() - 1);
        let (p, q) = (c.pts[i], c.pts[j]);
        (
            [
                p[0] + w * (q[0] - p[0]),
                p[1] + w * (q[1] - p[1]),
                p[2] + w * (q[2] - p[2]),
            ],
            c.s[i] + w * (c.s[j] - c.s[i]),
            // A step known at one end only is carried over, not lost to NaN.
            match (c.h[i].is_finite(), c.h[j].is_finite()) {
                (true, true) => c.h[i] + w * (c.h[j] - c.h[i]),
                (true, false) => c.h[i],
                (false, _) => c.h[j],
            },
        )
    };
    let inside = |s: f64| s >= a && s <= b;
    if c.pts.len() == 1 && inside(c.s[0]) {
        return vec![c.clone()];
    }
    for i in 0..c.pts.len().saturating_sub(1) {
        let (s0, s1) = (c.s[i], c.s[i + 1]);
        // The part of the segment with a ≤ s ≤ b, as parameters w0 ≤ w1 in [0, 1].
        let (w0, w1) = if (s1 - s0).abs() < 1e-12 {
            if inside(s0) {
                (0.0, 1.0)
            } else {
                (1.0, 0.0)
            }
        } else {
            let wa = (a - s0) / (s1 - s0);
            let wb = (b - s0) / (s1 - s0);
            let (lo, hi) = if wa < wb { (wa, wb) } else { (wb, wa) };
            (lo.max(0.0), hi.min(1.0))
        };
        if w0 > w1 {
            if let Some(ch) = cur.take() {
                out.push(ch);
            }
            continue;
        }
        let (p0, st0, h0) = at(i, w0);
        let (p1, st1, h1) = at(i, w1);
        // A segment that starts outside the range (w0 > 0) starts a new piece.
        if w0 > 0.0 || cur.is_none() {
            out.extend(cur.take());
            cur = Some(Chain {
                side: c.side,
                pts: vec![p0],
                s: vec![st0],
                h: vec![h0],
                across: c.across,
            });
        }
        if let Some(ch) = cur.as_mut() {
            ch.pts.push(p1);
            ch.s.push(st1);
            ch.h.push(h1);
        }
        // A segment that ends outside the range (w1 < 1) ends the piece.
        if w1 < 1.0 {
            out.extend(cur.take());
        }
    }
    out.extend(cur);
    out.retain(|c| c.pts.len() >= 2);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ep(x: f64, y: f64) -> EdgePoint {
        // Trajectory along the x axis, left = +y.
        EdgePoint {
            p: [x, y, 0.0],
            s: x,
            d: y,
            foot: [x, 0.0],
        }
    }

    /// A curb whose offset drifts (the vehicle changing lanes: 0.25 m per metre), its
    /// partner 14 m across the road seen over 3 m in every 6 m only (and over the last 6 m).
    /// At s = 22.5 the matched points within 5 m (31, at s 17.75–21.25 and 23.75–27.5)
    /// have a median offset of 10.94 m, 0.31 m off the curb there; the trend through the
    /// two halves' medians is on it. A car's side 1.5 m inward of the curb is still
    /// dropped.
    #[test]
    fn width_refinement_follows_a_drifting_curb() {
        let p = QiuParams::default();
        let mut pts = Vec::new();
        let left = |s: f64| 5.0 + 0.25 * s;
        for k in 0..=120 {
            let s = k as f64 * 0.25;
            pts.push(ep(s, left(s)));
            if [0.0, 6.0, 12.0, 18.0, 24.0, 27.0]
                .iter()
                .any(|&a| (a..=a + 3.0).contains(&s))
            {
                pts.push(ep(s, left(s) - 14.0));
            }
        }
        let curb = pts.len();
        for k in 0..=8 {
            let s = 9.5 + k as f64 * 0.25;
            pts.push(ep(s, left(s) - 1.5));
        }
        let r = refine_by_width(&pts, &p);
        for (i, q) in pts.iter().enumerate() {
            let kept = r.kept.contains(&i);
            assert_eq!(kept, i < curb, "s {} d {}", q.s, q.d);
        }
    }

    #[test]
    fn width_refinement_keeps_the_curbs_and_drops_a_wall_base() {
        let p = QiuParams::default();
        let mut pts = Vec::new();
        // Curbs at ±5 m every 0.25 m over 20 m, a wall base at +8 m over the middle 10 m.
        for k in 0..80 {
            let x = k as f64 * 0.25;
            pts.push(ep(x, 5.0));
            pts.push(ep(x, -5.0));
        }
        for k in 0..40 {
            pts.push(ep(5.0 + k as f64 * 0.25, 8.0));
        }
        let r = refine_by_width(&pts, &p);
        // Every curb point pairs at 10 m: the histogram bin [10.0, 10.1) → centre 10.05.
        assert!((r.road_width_m.unwrap() - 10.05).abs() < 1e-9);
        assert_eq!(r.kept, (0..160).collect::<Vec<_>>());
        // A left curb point with its right partner hidden (e.g. by a car) is kept by the
        // offset agreement with its matched neighbours.
        pts.retain(|q| !(q.d < 0.0 && (8.0..9.0).contains(&q.s)));
        let r = refine_by_width(&pts, &p);
        let kept_left_hidden = r
            .kept
            .iter()
            .filter(|&&i| pts[i].d == 5.0 && (8.0..9.0).contains(&pts[i].s))
            .count();
        assert_eq!(kept_left_hidden, 4);
        assert!(r.kept.iter().all(|&i| pts[i].d != 8.0));
    }

    #[test]
    fn clusters_and_douglas_peucker() {
        let xy = [[0.0, 0.0], [0.5, 0.0], [1.0, 0.0], [3.0, 0.0], [3.4, 0.3]];
        assert_eq!(
            euclidean_clusters(&xy, 0.6),
            vec![vec![0, 1, 2], vec![3, 4]]
        );
        // An L: (0,0)–(2,0)–(2,2) sampled every 0.5 m; DP keeps the two ends and the corner.
        let mut l: Vec<[f64; 3]> = (0..=4).map(|i| [i as f64 * 0.5, 0.0, 0.0]).collect();
        l.extend((1..=4).map(|i| [2.0, i as f64 * 0.5, 0.0]));
        assert_eq!(douglas_peucker(&l, 0.1), vec![0, 4, 8]);
    }

    #[test]
    fn continuity_joins_a_gap_and_drops_short_pieces() {
        let p = QiuParams::default();
        let mut pts = Vec::new();
        // Left curb y = 5 over [0, 10] and [13, 25] (a 3 m curb cut), a 1 m piece at y = 3.
        for k in 0..=100 {
            let x = k as f64 * 0.25;
            if x <= 10.0 || x >= 13.0 {
                pts.push(ep(x, 5.0));
            }
        }
        for k in 0..=4 {
            pts.push(ep(20.0 + k as f64 * 0.25, 3.0));
        }
        let kept: Vec<usize> = (0..pts.len()).collect();
        let chains = keep_longest(refine_by_continuity(&pts, &kept, &p), &p);
        assert_eq!(chains.len(), 1, "{chains:?}");
        let c = &chains[0];
        assert_eq!(c.side, Side::Left);
        // Bins of 0.5 m: medians span x ≈ 0.125 … 24.875 along y = 5.
        assert!((c.length_m() - 24.75).abs() < 0.3, "{}", c.length_m());
        assert!(c.pts.iter().all(|q| (q[1] - 5.0).abs() < 1e-9));
    }

    /// A left curb along the trajectory (y = 5 over x ∈ [0, 20]) that turns a 5 m corner
    /// into a side street and runs away from the road along x = 25 to y = 22. The width
    /// step kept only the straight part. The side street's curb is a line of its own,
    /// across the trajectory, and every metre of it lies within 0.2 m of the output; fitted
    /// along the cluster's main direction, it collapsed into a vertex or two.
    #[test]
    fn a_side_streets_curb_running_away_from_the_road_is_a_line_of_its_own() {
        let p = QiuParams::default();
        let mut pts = Vec::new();
        for k in 0..=200 {
            pts.push(ep(k as f64 * 0.1, 5.0));
        }
        let straight = pts.len();
        for k in 1..=78 {
            let t = k as f64 / 78.0 * std::f64::consts::FRAC_PI_2;
            pts.push(ep(20.0 + 5.0 * t.sin(), 10.0 - 5.0 * t.cos()));
        }
        for k in 1..=120 {
            pts.push(ep(25.0, 10.0 + k as f64 * 0.1));
        }
        let kept: Vec<usize> = (0..straight).collect();
        let chains = keep_longest(refine_by_continuity(&pts, &kept, &p), &p);
        assert!(chains.iter().any(|c| c.across), "{chains:?}");
        let near = |x: f64, y: f64| {
            chains.iter().any(|c| {
                c.pts.windows(2).any(|w| {
                    let (a, b) = (w[0], w[1]);
                    let (ux, uy) = (b[0] - a[0], b[1] - a[1]);
                    let l2 = ux * ux + uy * uy;
                    let t = (((x - a[0]) * ux + (y - a[1]) * uy) / l2).clamp(0.0, 1.0);
                    (x - a[0] - t * ux).hypot(y - a[1] - t * uy) <= 0.2
                })
            })
        };
        for k in 11..=21 {
            assert!(near(25.0, k as f64), "side street at y = {k}: {chains:?}");
        }
        for k in 1..=19 {
            assert!(near(k as f64, 5.0), "curb at x = {k}: {chains:?}");
        }
    }

    #[test]
    fn clipping_cuts_at_the_core_bounds() {
        let c = Chain {
            side: Side::Right,
            pts: vec![[0.0, -5.0, 0.0], [10.0, -5.0, 0.0], [20.0, -5.0, 0.0]],
            s: vec![0.0, 10.0, 20.0],
            h: vec![0.1, 0.2, 0.2],
            across: false,
        };
        // A single segment crossing the whole range is cut at both ends.
        let one = Chain {
            side: Side::Right,
            pts: vec![[0.0, -5.0, 0.0], [20.0, -5.0, 0.0]],
            s: vec![0.0, 20.0],
            h: vec![0.1, 0.1],
            across: false,
        };
        let parts = clip_to_stations(&one, 5.0, 15.0);
        assert_eq!(parts.len(), 1);
        assert_eq!(parts[0].pts, vec![[5.0, -5.0, 0.0], [15.0, -5.0, 0.0]]);
        let parts = clip_to_stations(&c, 5.0, 15.0);
        assert_eq!(parts.len(), 1);
        assert_eq!(
            parts[0].pts,
            vec![[5.0, -5.0, 0.0], [10.0, -5.0, 0.0], [15.0, -5.0, 0.0]]
        );
        // The height step at the cut is interpolated: halfway from 0.1 to 0.2.
        assert!((parts[0].h[0] - 0.15).abs() < 1e-12);
        // Two neighbouring cores give pieces that join back into one chain.
        let mut pieces = clip_to_stations(&c, f64::NEG_INFINITY, 12.0);
        pieces.extend(clip_to_stations(&c, 12.0, f64::INFINITY));
        assert_eq!(pieces.len(), 2);
        let joined = join_chains(pieces, &QiuParams::default());
        assert_eq!(joined.len(), 1);
        assert!((joined[0].length_m() - 20.0).abs() < 1e-9);
        assert_eq!(joined[0].pts.len(), 4);
    }

    /// A 16 m curb (a vertex at either end, step 0.23 m) followed by a 5 m curb cut whose
    /// bends give it six vertices (step 0): the plain median of the vertices is the cut's,
    /// the length-weighted one the curb's. Densified to 1 m, the curb's stretch is
    /// sampled along its length; unmeasured (NaN) vertices do not count in the median.
    #[test]
    fn the_median_step_weighs_vertices_by_the_line_they_stand_for() {
        let xs = [0.0, 16.0, 17.0, 18.0, 19.0, 20.0, 21.0];
        let hs = [0.23, 0.23, 0.0, 0.0, 0.0, 0.0, 0.0];
        let c = Chain {
            side: Side::Left,
            pts: xs.iter().map(|&x| [x, 5.0, 0.0]).collect(),
            s: xs.to_vec(),
            h: hs.to_vec(),
            across: false,
        };
        assert_eq!(median(&mut hs.to_vec()), Some(0.0));
        assert_eq!(median_step(&c), Some(0.23));
        let d = densify(&c, 1.0);
        assert_eq!(d.pts.len(), 22);
        assert!(d.pts.windows(2).all(|w| (w[1][0] - w[0][0]) <= 1.0 + 1e-12));
        assert!((d.s[8] - 8.0).abs() < 1e-12 && (d.h[8] - 0.23).abs() < 1e-12);
        let mut unmeasured = d.clone();
        for h in &mut unmeasured.h[..14] {
            *h = f64::NAN;
        }
        // The measured vertices (x 14..21, standing for x 13.5..21: 3 m of curb, 4.5 m of
        // cut) have the cut's median.
        assert_eq!(median_step(&unmeasured), Some(0.0));
        let (measured, wall) = measured_and_wall_shares(&unmeasured, 0.2);
        assert!((measured - 7.5 / 21.0).abs() < 1e-9, "{measured}");
        assert!((wall - 3.0 / 21.0).abs() < 1e-9, "{wall}");
        // A wall on the side taken for the road: a wall across the trajectory only.
        let mut sunk = unmeasured.clone();
        for h in &mut sunk.h[14..16] {
            *h = -0.3;
        }
        sunk.h[17] = NO_GROUND;
        let wall_along = measured_and_wall_shares(&sunk, 0.2).1;
        sunk.across = true;
        let wall_across = measured_and_wall_shares(&sunk, 0.2).1;
        assert!((wall_along - 1.0 / 21.0).abs() < 1e-9, "{wall_along}");
        assert!((wall_across - 3.0 / 21.0).abs() < 1e-9, "{wall_across}");
    }

    /// Two lined-up curbs at y = 5 with a 10 m gap (x 10..20): longer than the joins
    /// bridge, so only `bridge_gaps` joins them, and only where the ground measured along
    /// the gap steps up outward as a ramp does; flat ground (an intersection's mouth), a
    /// wall-sized step or a gap longer than `bridge_gap_m` leaves two chains.
    #[test]
    fn a_gap_is_bridged_only_where_the_ground_steps_up_outward() {
        let p = QiuParams::default();
        let curb = |x0: f64, x1: f64| Chain {
            side: Side::Left,
            pts: vec![[x0, 5.0, 0.0], [x1, 5.0, 0.0]],
            s: vec![x0, x1],
            h: vec![0.15, 0.15],
            across: false,
        };
        let run = |gap_end: f64, step_m: f64| {
            let chains = vec![curb(gap_end, gap_end + 10.0), curb(0.0, 10.0)];
            bridge_gaps(chains, &p, 1.0, &|c: &mut Chain| {
                for h in &mut c.h {
                    *h = step_m;
                }
            })
        };
        let ramp = run(20.0, 0.05);
        assert_eq!(ramp.len(), 1);
        let c = &ramp[0];
        assert_eq!((c.pts[0][0], c.pts[c.pts.len() - 1][0]), (0.0, 30.0));
        assert!(c.s.windows(2).all(|w| w[1] > w[0]), "{:?}", c.s);
        // The two curbs' vertices and the bridge's nine, 1 m apart, between them.
        assert_eq!(c.pts.len(), 13);
        assert!(c.pts[1..12]
            .windows(2)
            .all(|w| (w[1][0] - w[0][0] - 1.0).abs() < 1e-9));
        assert_eq!(run(20.0, 0.0).len(), 2, "flat ground");
        assert_eq!(run(20.0, 0.8).len(), 2, "a wall");
        assert_eq!(
            run(10.0 + p.bridge_gap_m + 0.5, 0.05).len(),
            2,
            "too long a gap"
        );
        let off = QiuParams {
            bridge_gap_m: 0.0,
            ..QiuParams::default()
        };
        let chains = vec![curb(0.0, 10.0), curb(20.0, 30.0)];
        assert_eq!(bridge_gaps(chains, &off, 1.0, &|_: &mut Chain| {}).len(), 2);
    }

    /// No candidate kept by the width step: a corner's arc (offset 5 → 6.9 m, more than
    /// `cluster_keep_spread_m`) is kept as a line all the same; a patch of scattered
    /// candidates with the same spread is not, and with the rule off neither is.
    #[test]
    fn an_arc_leaving_the_road_width_is_kept_a_scattered_patch_not() {
        let mut pts = Vec::new();
        for k in 0..56 {
            let t = (k as f64 * 0.1 / 8.0).min(40f64.to_radians());
            let jitter = if k % 2 == 0 { 0.02 } else { -0.02 };
            pts.push(ep(8.0 * t.sin(), 13.0 - (8.0 + jitter) * t.cos()));
        }
        for i in 0..13 {
            for j in 0..5 {
                pts.push(ep(20.0 + i as f64 * 0.5, 5.0 + j as f64 * 0.5));
            }
        }
        let p = QiuParams::default();
        let chains = refine_by_continuity(&pts, &[], &p);
        assert_eq!(chains.len(), 1, "{chains:?}");
        let c = &chains[0];
        assert!(c.pts.iter().all(|q| q[0] < 6.0));
        assert!(c.length_m() > 4.5, "{}", c.length_m());
        let off = QiuParams {
            cluster_keep_spread_m: 0.0,
            ..QiuParams::default()
        };
        assert!(refine_by_continuity(&pts, &[], &off).is_empty());
    }

    /// A curb whose offset drifts 5 → 7 m over 25 m (the vehicle changes lanes, or the
    /// road widens) spans more than `cluster_keep_spread_m` but never turns away from the
    /// heading by `cluster_keep_turn_deg`: not kept whole. The same line turning out at
    /// 40° at its end is.
    #[test]
    fn an_offset_drift_is_not_kept_as_an_arc() {
        let drift = |turn: bool| {
            let mut pts = Vec::new();
            for k in 0..300 {
                let x = k as f64 * 0.1;
                let t = (x / 25.0).min(1.0);
                let mut y = 5.0 + 1.0 - (std::f64::consts::PI * t).cos();
                if turn && x > 25.0 {
                    y += (x - 25.0) * 40f64.to_radians().tan();
                }
                pts.push(ep(x, y + if k % 2 == 0 { 0.02 } else { -0.02 }));
            }
            pts
        };
        let p = QiuParams::default();
        assert!(refine_by_continuity(&drift(false), &[], &p).is_empty());
        assert_eq!(refine_by_continuity(&drift(true), &[], &p).len(), 1);
        let any_turn = QiuParams {
            cluster_keep_turn_deg: 0.0,
            ..QiuParams::default()
        };
        assert_eq!(refine_by_continuity(&drift(false), &[], &any_turn).len(), 1);
    }
}
