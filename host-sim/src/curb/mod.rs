//! The curb beside each extracted toe: the top of curb and the height at every vertex, the
//! class of every stretch and whether it was measured or bridged (docs/spec.md §2, "Curb
//! geometry" and "Classes").
//!
//! [`annotate`] runs where the points are: on the window of the stream (or the whole file)
//! right after the tracker, on the edges it returned. At every toe vertex the points of the
//! nearby scanlines within a short strip across the edge form one cross-section (as the
//! tracker's virtual profile does), fitted by [`profile::fit`]; the arris positions and
//! heights are then median-filtered along the edge and carried to the vertices where no
//! section fitted. The class of each vertex comes from its height, its direction against
//! the route and its offset from the route ([`class`]). [`finish`] runs on closed edges
//! (after the stream's merge): it cuts every edge into stretches of one class and one kind
//! of support.

pub mod class;
pub mod profile;

use crate::bend::grid::PointGrid;
use crate::bend::postfilter::category_runs;
use crate::bend::route::Route;
use crate::bend::{median, BendInput};
use crate::model::{Category, EdgeLine, BRIDGED_MIN_M};
use crate::replay::PointStatus;
use rayon::prelude::*;

/// Half length of the strip along the edge whose points form a cross-section, metres: a
/// few scanlines at mapping speeds.
pub const STRIP_HALF_M: f64 = 0.15;
/// Reach of a cross-section across the edge, metres.
const REACH_M: f64 = 0.5;
/// Height band around the toe of the points a section takes, metres (above: vehicles,
/// walls; below: noise).
const BAND_M: f64 = 0.6;
/// Half window of the median filter along the edge, metres.
const FILTER_HALF_M: f64 = 0.3;

/// Points a cross-section may use: kept by the core, with or without a bend angle.
fn usable(s: Option<PointStatus>) -> bool {
    matches!(s, Some(PointStatus::Kept | PointStatus::NoNeighbour))
}

/// Adds the top of curb, the height per vertex and the class per vertex to every edge of
/// `edges` that carries a [`CurbDetail`] (the bend method's), from `input`'s points as
/// `grid` indexes them ([`crate::bend::point_grid`], the tracker's own index: every point
/// the core processed).
pub fn annotate<'e>(
    input: &BendInput,
    grid: &PointGrid,
    route: &Route,
    edges: impl IntoIterator<Item = &'e mut EdgeLine>,
) {
    let mut edges: Vec<&mut EdgeLine> = edges
        .into_iter()
        .filter(|e| e.detail.is_some() && e.points.len() >= 2)
        .collect();
    if edges.is_empty() {
        return;
    }
    // Each edge's cross-sections read only the points and the edge itself: the edges run
    // on rayon's pool, each summed as on one thread.
    edges
        .par_iter_mut()
        .for_each(|e| sections_along(input, grid, route, e));
    class::classify(route, &mut edges);
}

/// Unit tangent at vertex `k` over the vertices within `half_m`.
pub(crate) fn tangent(p: &[[f64; 3]], k: usize, half_m: f64) -> Option<[f64; 2]> {
    let d = |a: usize, b: usize| (p[a][0] - p[b][0]).hypot(p[a][1] - p[b][1]);
    let mut a = k;
    while a > 0 && d(a - 1, k) <= half_m {
        a -= 1;
    }
    let mut b = k;
    while b + 1 < p.len() && d(b + 1, k) <= half_m {
        b += 1;
    }
    if a == b {
        a = k.saturating_sub(1);
        b = (k + 1).min(p.len() - 1);
    }
    let v = [p[b][0] - p[a][0], p[b][1] - p[a][1]];
    let l = v[0].hypot(v[1]);
    (l > 1e-9).then(|| [v[0] / l, v[1] / l])
}

/// Unit normal at vertex `k` pointing away from the route (towards the curb).
pub(crate) fn outward(route: &Route, p: [f64; 3], tan: [f64; 2]) -> [f64; 2] {
    let nrm = [-tan[1], tan[0]];
    match route.nearest(p[0], p[1]) {
        Some((q, _)) if nrm[0] * (p[0] - q[0]) + nrm[1] * (p[1] - q[1]) < 0.0 => [-nrm[0], -nrm[1]],
        _ => nrm,
    }
}

/// The cross-section at every vertex of `e`, filtered along the edge, into its detail.
fn sections_along(input: &BendInput, grid: &PointGrid, route: &Route, e: &mut EdgeLine) {
    let pts = &e.points;
    let m = pts.len();
    let mut raw: Vec<Option<profile::Section>> = Vec::with_capacity(m);
    let mut normals = Vec::with_capacity(m);
    let mut prof: Vec<(f64, f64)> = Vec::new();
    for k in 0..m {
        let Some(tan) = tangent(pts, k, 0.3) else {
            raw.push(None);
            normals.push([0.0, 0.0]);
            continue;
        };
        let nrm = outward(route, pts[k], tan);
        normals.push(nrm);
        prof.clear();
        let p = pts[k];
        grid.for_each_within(
            input.x,
            input.y,
            p[0],
            p[1],
            REACH_M.hypot(STRIP_HALF_M),
            |i| {
                if !usable(input.status[i]) {
                    return;
                }
                let dz = input.z[i] - p[2];
                if dz.abs() > BAND_M {
                    return;
                }
                let d = [input.x[i] - p[0], input.y[i] - p[1]];
                let along = d[0] * tan[0] + d[1] * tan[1];
                let across = d[0] * nrm[0] + d[1] * nrm[1];
                if along.abs() <= STRIP_HALF_M && across.abs() <= REACH_M {
                    prof.push((across, dz));
                }
            },
        );
        // The grid hands points on in an order that depends on how the window was cut;
        // sorted, the fit's sums do not, and a file cut into tasks gives the same bits.
        prof.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
        raw.push(profile::fit(&prof));
    }
    // Arc length along the edge, for the filter.
    let mut s = vec![0.0; m];
    for k in 1..m {
        s[k] = s[k - 1] + (pts[k][0] - pts[k - 1][0]).hypot(pts[k][1] - pts[k - 1][1]);
    }
    let fallback = e.curb_height_m.unwrap_or(0.0).max(0.0);
    let d = e.detail.get_or_insert_with(Default::default);
    let mut measured = std::mem::take(&mut d.measured);
    measured.resize(m, true);
    let mut top = Vec::with_capacity(m);
    let mut height = Vec::with_capacity(m);
    let mut top_measured = Vec::with_capacity(m);
    let (mut lo, mut hi) = (0usize, 0usize);
    let mut cs = Vec::new();
    let mut hs = Vec::new();
    for k in 0..m {
        // Median over the fitted sections within the filter window; widen to the nearest
        // fitted ones where the window holds none.
        while s[k] - s[lo] > FILTER_HALF_M {
            lo += 1;
        }
        while hi + 1 < m && s[hi + 1] - s[k] <= FILTER_HALF_M {
            hi += 1;
        }
        cs.clear();
        hs.clear();
        for f in raw[lo..=hi].iter().flatten() {
            cs.push(f.c_top);
            hs.push(f.height_m);
        }
        let here = raw[k].is_some();
        if cs.is_empty() {
            let before = (0..k).rev().find(|&j| raw[j].is_some());
            let after = (k + 1..m).find(|&j| raw[j].is_some());
            let near = match (before, after) {
                (Some(a), Some(b)) => Some(if s[k] - s[a] <= s[b] - s[k] { a } else { b }),
                (a, b) => a.or(b),
            };
            if let Some(f) = near.and_then(|j| raw[j]) {
                cs.push(f.c_top);
                hs.push(f.height_m);
            }
        }
        let (c, h) = match (median(&mut cs), median(&mut hs)) {
            (Some(c), Some(h)) => (c, h),
            _ => (0.0, fallback),
        };
        let p = pts[k];
        let nrm = normals[k];
        top.push([p[0] + c * nrm[0], p[1] + c * nrm[1], p[2] + h]);
        height.push(h);
        top_measured.push(here);
    }
    d.top = top;
    d.height_m = height;
    d.measured = measured;
    d.top_measured = top_measured;
    d.class = vec![e.category.unwrap_or(Category::Curb); m];
}

/// Cuts closed edges into stretches of one class and one kind of support, with their
/// height (median over the stretch), support and bridged flag. Edges without detail (the
/// plane method's) pass unchanged.
pub fn finish(mut edges: Vec<EdgeLine>) -> Vec<EdgeLine> {
    for e in edges.iter_mut() {
        let (n, cat) = (e.points.len(), e.category.unwrap_or(Category::Curb));
        if let Some(d) = e.detail.as_mut() {
            if d.class.len() != n {
                d.class = vec![cat; n];
            }
        }
    }
    class::settle_runs(&mut edges);
    let mut out = Vec::with_capacity(edges.len());
    for e in edges {
        let Some(d) = e.detail.as_ref() else {
            out.push(e);
            continue;
        };
        // The classes are settled: every run here is a stretch (or the part of one that
        // lies on this edge).
        let class = category_runs(&e.points, &d.class, 0.0);
        let measured = d.measured.clone();
        for (a, b, cat) in class {
            for (ra, rb, bridged) in bridged_runs(&e.points[a..=b], &measured[a..=b]) {
                out.push(stretch(&e, a + ra, a + rb, cat, bridged));
            }
        }
    }
    out
}

/// Vertices `a..=b` of `e` as one output stretch of class `cat`: its height is the median
/// over the stretch, its support the observed candidates per metre.
fn stretch(e: &EdgeLine, a: usize, b: usize, cat: Category, bridged: bool) -> EdgeLine {
    let mut s = e.sub(a, b + 1);
    s.category = Some(cat);
    let len = s.length_m();
    if let Some(d) = s.detail.as_mut() {
        d.bridged = bridged;
        // Each observed vertex is one scanline's candidate on the toe; the boundary vertex
        // shared with the next stretch counts for both.
        let seen = d.measured.iter().filter(|&&m| m).count();
        d.support_per_m = if len > 0.0 { seen as f64 / len } else { 0.0 };
        let mut h = d.height_m.clone();
        s.curb_height_m = median(&mut h);
    }
    s
}

/// Runs `(first, last, bridged)` over the vertices: runs of unmeasured vertices spanning at
/// least [`BRIDGED_MIN_M`] are bridged, everything else measured; consecutive runs share
/// their boundary vertex.
pub fn bridged_runs(pts: &[[f64; 3]], measured: &[bool]) -> Vec<(usize, usize, bool)> {
    let m = pts.len().min(measured.len());
    if m == 0 {
        return Vec::new();
    }
    let mut s = vec![0.0; m];
    for k in 1..m {
        s[k] = s[k - 1] + (pts[k][0] - pts[k - 1][0]).hypot(pts[k][1] - pts[k - 1][1]);
    }
    // Bridged runs: maximal runs of unmeasured vertices, extended to the measured vertex on
    // each side (the gap spans from one observation to the next).
    let mut bridged: Vec<(usize, usize)> = Vec::new();
    let mut k = 0;
    while k < m {
        if measured[k] {
            k += 1;
            continue;
        }
        let a = k;
        while k < m && !measured[k] {
            k += 1;
        }
        let (ga, gb) = (a.saturating_sub(1), k.min(m - 1));
        if s[gb] - s[ga] >= BRIDGED_MIN_M {
            bridged.push((ga, gb));
        }
    }
    let mut out = Vec::new();
    let mut at = 0;
    for (ga, gb) in bridged {
        if ga > at {
            out.push((at, ga, false));
        }
        out.push((ga, gb, true));
        at = gb;
    }
    if at < m - 1 || out.is_empty() {
        out.push((at, m - 1, false));
    }
    out
}
