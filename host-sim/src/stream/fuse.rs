//! Fusion: the closed edges of several channels (scanners) and passes made one edge per
//! curb.
//!
//! Fusion is late: each scanner's scanlines run through a core and a tracker of their own
//! (as each scanner's controller would), and the closed edges are fused here. Early
//! fusion — one tracker over both scanners' candidates — would mix scanlines that cross a
//! curb at mirrored angles and at different times in one track, whose step-by-step search
//! (Eq. 4–8) expects one scanline after another of one profiler; late fusion keeps each
//! tracker on the data it was made for and decides between whole observed stretches.
//!
//! The rule: every edge is cut into its observed runs (vertices resting on candidates) and
//! its bridged runs (placed by the tracker over at least `model::BRIDGED_MIN_M`). Observed runs
//! come first, those of the first pass before later passes', longest first, then bridged
//! runs in the same order. A run's vertex is a
//! duplicate when an already kept line of the same side passes within [`FuseParams::near_m`]
//! of it in a direction within [`FuseParams::max_angle_deg`]; the vertices that are not
//! duplicates are kept, in runs, each with the duplicate vertex beside it so it meets the
//! kept line. Then kept runs whose ends meet within the stitch distance, in directions that
//! agree, are joined end to start. So the better-observed stretch is kept, the other
//! bridges what it missed, and no stretch lies beside another of the same curb.

use crate::model::EdgeLine;
use crate::pipeline::ExtractResult;
use std::collections::HashMap;

/// Parameters of the fusion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FuseParams {
    /// Distance within which two lines of one side are the same curb, metres.
    pub near_m: f64,
    /// Largest angle between two lines of the same curb, degrees.
    pub max_angle_deg: f64,
    /// Largest gap between the end of a kept run and the start of the next joined to it,
    /// metres.
    pub stitch_m: f64,
    /// Shortest run kept on its own (not joined to another), metres.
    pub min_length_m: f64,
}

impl Default for FuseParams {
    fn default() -> Self {
        Self {
            near_m: 0.3,
            max_angle_deg: 15.0,
            stitch_m: 0.6,
            min_length_m: 1.0,
        }
    }
}

/// The summary of `a`'s run and `b`'s (another channel of the same files): points, drops,
/// the core's counters, candidates and times added; the file's description is `a`'s.
pub fn add_summaries(mut a: ExtractResult, b: &ExtractResult) -> ExtractResult {
    let (s, o) = (&mut a.summary, &b.summary);
    s.las.points_selected += o.las.points_selected;
    s.dropped_before_trajectory += o.dropped_before_trajectory;
    s.dropped_after_trajectory += o.dropped_after_trajectory;
    s.dropped_by_window_cap += o.dropped_by_window_cap;
    s.core.add(&o.core);
    s.candidates += o.candidates;
    let (t, u) = (&mut s.times, &o.times);
    t.read_s += u.read_s;
    t.read_wait_s += u.read_wait_s;
    t.trajectory_s += u.trajectory_s;
    t.core_s += u.core_s;
    t.edges_s += u.edges_s;
    t.total_s += u.total_s;
    t.cpu.read_s += u.cpu.read_s;
    t.cpu.core_s += u.cpu.core_s;
    t.cpu.edges_s += u.cpu.edges_s;
    t.cpu.total_s += u.cpu.total_s;
    for (p, q) in t.cpu.peak_rss.iter_mut().zip(u.cpu.peak_rss) {
        *p = (*p).max(q);
    }
    a
}

/// A run of an edge in the order fusion looks at it.
struct Run {
    line: EdgeLine,
    observed: bool,
    pass: u16,
}

/// A source of edges: a scanner (channel key) in a pass.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Source {
    /// The scanner's channel key.
    pub scanner: u16,
    /// The pass (`stream::passes`), 0 for the first.
    pub pass: u16,
}

/// Fuses the edges of several sources, each `(source, its closed edges)`, the edges of
/// later passes already turned to the first pass's direction. Every vertex of the result
/// records the scanner and the pass whose tracker placed it (`CurbDetail::scanner`,
/// `CurbDetail::pass`).
pub fn fuse(channels: Vec<(Source, Vec<EdgeLine>)>, p: &FuseParams) -> Vec<EdgeLine> {
    let mut runs = Vec::new();
    for (src, edges) in channels {
        for mut e in edges {
            let n = e.points.len();
            if n < 2 {
                continue;
            }
            let measured = match e.detail.as_mut() {
                Some(d) => {
                    d.scanner = vec![src.scanner; n];
                    d.pass = vec![src.pass; n];
                    d.measured.clone()
                }
                None => vec![true; n],
            };
            for (a, b, bridged) in crate::curb::bridged_runs(&e.points, &measured) {
                if b > a {
                    runs.push(Run {
                        line: e.sub(a, b + 1),
                        observed: !bridged,
                        pass: src.pass,
                    });
                }
            }
        }
    }
    // Observed before bridged, the first pass before later ones (its geometry is the
    // frame the others were shifted onto), longer before shorter; ties in input order.
    runs.sort_by(|a, b| {
        b.observed
            .cmp(&a.observed)
            .then(a.pass.cmp(&b.pass))
            .then(b.line.length_m().total_cmp(&a.line.length_m()))
    });
    let mut kept: Vec<EdgeLine> = Vec::new();
    let mut grid = SegmentGrid::new(p.near_m.max(0.05));
    let cos_max = p.max_angle_deg.to_radians().cos();
    for r in runs {
        let pts = &r.line.points;
        let dup: Vec<bool> = (0..pts.len())
            .map(|i| {
                let d = direction(pts, i);
                grid.near(pts[i], d, p.near_m, cos_max, r.line.side, &kept)
            })
            .collect();
        for (a, b) in fresh_runs(&dup) {
            let piece = r.line.sub(a, b + 1);
            if piece.points.len() >= 2 {
                grid.add(kept.len(), &piece);
                kept.push(piece);
            }
        }
    }
    let joined = stitch(kept, p, cos_max);
    joined
        .into_iter()
        .filter(|e| e.length_m() >= p.min_length_m)
        .collect()
}

/// Runs `(a, b)` of vertices to keep: each maximal run of non-duplicates with the duplicate
/// vertex before and after it, where there is one.
fn fresh_runs(dup: &[bool]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut k = 0;
    while k < dup.len() {
        if dup[k] {
            k += 1;
            continue;
        }
        let a = k;
        while k < dup.len() && !dup[k] {
            k += 1;
        }
        let (a, b) = (a.saturating_sub(1), k.min(dup.len() - 1));
        if b > a {
            out.push((a, b));
        }
    }
    out
}

/// The unit horizontal direction of the line at vertex `i` (from its neighbours).
fn direction(pts: &[[f64; 3]], i: usize) -> [f64; 2] {
    let a = pts[i.saturating_sub(1)];
    let b = pts[(i + 1).min(pts.len() - 1)];
    unit([b[0] - a[0], b[1] - a[1]])
}

fn unit(d: [f64; 2]) -> [f64; 2] {
    let n = d[0].hypot(d[1]);
    if n > 0.0 {
        [d[0] / n, d[1] / n]
    } else {
        [0.0, 0.0]
    }
}

/// Kept lines' segments by grid cell, for the duplicate test.
struct SegmentGrid {
    cell_m: f64,
    cells: HashMap<(i64, i64), Vec<(usize, usize)>>,
}

impl SegmentGrid {
    fn new(cell_m: f64) -> Self {
        Self {
            cell_m,
            cells: HashMap::new(),
        }
    }

    fn cell(&self, x: f64, y: f64) -> (i64, i64) {
        (
            (x / self.cell_m).floor() as i64,
            (y / self.cell_m).floor() as i64,
        )
    }

    /// Registers line `id`'s segments in every cell their bounding box touches.
    fn add(&mut self, id: usize, line: &EdgeLine) {
        for (s, w) in line.points.windows(2).enumerate() {
            let (c0, c1) = (
                self.cell(w[0][0].min(w[1][0]), w[0][1].min(w[1][1])),
                self.cell(w[0][0].max(w[1][0]), w[0][1].max(w[1][1])),
            );
            // A segment longer than a few cells is registered at its ends only (a long
            // bridged chord); its middle is then found from them up to `near_m` away.
            if (c1.0 - c0.0 + 1) * (c1.1 - c0.1 + 1) > 64 {
                for q in [w[0], w[1]] {
                    let c = self.cell(q[0], q[1]);
                    self.cells.entry(c).or_default().push((id, s));
                }
                continue;
            }
            for i in c0.0..=c1.0 {
                for j in c0.1..=c1.1 {
                    self.cells.entry((i, j)).or_default().push((id, s));
                }
            }
        }
    }

    /// Whether a kept line of `side` passes within `near_m` of `q` in a direction within
    /// the angle whose cosine is `cos_max` of `d` (either way along it).
    fn near(
        &self,
        q: [f64; 3],
        d: [f64; 2],
        near_m: f64,
        cos_max: f64,
        side: crate::model::Side,
        kept: &[EdgeLine],
    ) -> bool {
        let (ci, cj) = self.cell(q[0], q[1]);
        let r = (near_m / self.cell_m).ceil() as i64;
        for i in ci - r..=ci + r {
            for j in cj - r..=cj + r {
                let Some(segs) = self.cells.get(&(i, j)) else {
                    continue;
                };
                for &(id, s) in segs {
                    let line = &kept[id];
                    if line.side != side {
                        continue;
                    }
                    let (a, b) = (line.points[s], line.points[s + 1]);
                    let e = unit([b[0] - a[0], b[1] - a[1]]);
                    if (e[0] * d[0] + e[1] * d[1]).abs() < cos_max {
                        continue;
                    }
                    if segment_distance(q, a, b) <= near_m {
                        return true;
                    }
                }
            }
        }
        false
    }
}

/// Horizontal distance from `q` to the segment `a`–`b`.
fn segment_distance(q: [f64; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let l2 = dx * dx + dy * dy;
    let t = if l2 > 0.0 {
        (((q[0] - a[0]) * dx + (q[1] - a[1]) * dy) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (q[0] - a[0] - t * dx).hypot(q[1] - a[1] - t * dy)
}

/// Joins kept runs end to start: the end of one and the start of another of the same side
/// within `stitch_m`, the directions at the two ends within the fusion's angle. The
/// closest pair is joined first; a vertex the two share is kept once.
fn stitch(mut lines: Vec<EdgeLine>, p: &FuseParams, cos_max: f64) -> Vec<EdgeLine> {
    loop {
        let mut best: Option<(usize, usize, f64)> = None;
        for (i, a) in lines.iter().enumerate() {
            let end = a.points[a.points.len() - 1];
            let da = direction(&a.points, a.points.len() - 1);
            for (j, b) in lines.iter().enumerate() {
                if i == j || a.side != b.side {
                    continue;
                }
                let start = b.points[0];
                let gap = (start[0] - end[0]).hypot(start[1] - end[1]);
                if gap > p.stitch_m || best.is_some_and(|x| x.2 <= gap) {
                    continue;
                }
                let db = direction(&b.points, 0);
                if da[0] * db[0] + da[1] * db[1] < cos_max {
                    continue;
                }
                best = Some((i, j, gap));
            }
        }
        let Some((i, j, gap)) = best else {
            return lines;
        };
        let b = lines.swap_remove(j);
        let i = if i == lines.len() { j } else { i };
        let b = if gap < 1e-9 && b.points.len() > 1 {
            b.sub(1, b.points.len())
        } else {
            b
        };
        let a = &lines[i];
        lines[i] = EdgeLine {
            curb_height_m: a.curb_height_m,
            ..a.joined(&b)
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{CurbDetail, Side};

    /// Scanner `k` of the first pass.
    fn ch(k: u16) -> Source {
        Source {
            scanner: k,
            pass: 0,
        }
    }

    /// An edge along y = `y` from x0 to x1 with vertices every 0.1 m; `measured` says
    /// which x ranges rest on candidates (all when empty).
    fn edge(x0: f64, x1: f64, y: f64, unmeasured: &[(f64, f64)]) -> EdgeLine {
        let n = ((x1 - x0) / 0.1).round() as usize;
        let pts: Vec<[f64; 3]> = (0..=n).map(|k| [x0 + k as f64 * 0.1, y, 0.0]).collect();
        let measured = pts
            .iter()
            .map(|p| !unmeasured.iter().any(|&(a, b)| p[0] > a && p[0] < b))
            .collect();
        EdgeLine {
            detail: Some(Box::new(CurbDetail {
                measured,
                ..CurbDetail::measured(&pts)
            })),
            points: pts,
            side: Side::Left,
            category: None,
            method: Some("bend".into()),
            curb_height_m: Some(0.12),
        }
    }

    /// Length of `lines` within `d` metres of another line's vertex (parallel copies).
    fn doubled_m(lines: &[EdgeLine], d: f64) -> f64 {
        let mut total = 0.0;
        for (i, a) in lines.iter().enumerate() {
            for w in a.points.windows(2) {
                let near = lines.iter().enumerate().any(|(j, b)| {
                    j != i
                        && b.points
                            .windows(2)
                            .any(|v| segment_distance(w[0], v[0], v[1]) < d)
                });
                if near {
                    total += (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]);
                }
            }
        }
        total
    }

    #[test]
    fn two_scanners_on_one_curb_give_one_edge_that_bridges_the_first_ones_gap() {
        // Scanner 0 sees 0–10 m and 15–30 m (a parked car hides 10–15 m); scanner 1 sees
        // 8–17 m, 0.04 m off.
        let s0 = vec![edge(0.0, 10.0, 0.0, &[]), edge(15.0, 30.0, 0.0, &[])];
        let s1 = vec![edge(8.0, 17.0, 0.04, &[])];
        let out = fuse(vec![(ch(0), s0), (ch(1), s1)], &FuseParams::default());
        assert_eq!(out.len(), 1, "{out:?}");
        let e = &out[0];
        assert!((e.length_m() - 30.0).abs() < 0.3, "{}", e.length_m());
        let d = e.detail.as_ref().unwrap();
        assert_eq!(d.scanners(), vec![0, 1]);
        // The gap is scanner 1's, the rest scanner 0's.
        let from1: f64 = e
            .points
            .windows(2)
            .zip(d.scanner.windows(2))
            .filter(|(_, s)| s[0] == 1 && s[1] == 1)
            .map(|(w, _)| w[1][0] - w[0][0])
            .sum();
        assert!((4.5..=5.5).contains(&from1), "{from1}");
        assert!(doubled_m(&out, 0.3) < 0.5);
    }

    #[test]
    fn an_observed_stretch_replaces_a_bridged_one_and_a_sparse_channel_adds_nothing_twice() {
        // Scanner 0 bridges 8–16 m without observation; scanner 1 observes all of it but
        // only as short pieces.
        let s0 = vec![edge(0.0, 30.0, 0.0, &[(8.0, 16.0)])];
        let s1 = vec![edge(7.0, 12.0, -0.05, &[]), edge(12.2, 17.0, -0.05, &[])];
        let out = fuse(vec![(ch(0), s0), (ch(1), s1)], &FuseParams::default());
        assert_eq!(out.len(), 1, "{out:?}");
        let d = out[0].detail.as_ref().unwrap();
        // Between 8 and 16 m the vertices are scanner 1's observed ones, except the 0.2 m
        // between its two pieces that scanner 0's bridge fills.
        let bridged_kept = out[0]
            .points
            .iter()
            .zip(&d.measured)
            .filter(|(p, m)| p[0] > 8.3 && p[0] < 15.7 && !**m)
            .count();
        assert!(bridged_kept <= 3, "{bridged_kept}");
        assert!(doubled_m(&out, 0.3) < 0.5);
        assert!((out[0].length_m() - 30.0).abs() < 0.5);
    }

    #[test]
    fn lines_apart_or_across_stay_apart() {
        // A curb 2 m away and a line crossing at 90° are other curbs.
        let a = vec![edge(0.0, 10.0, 0.0, &[])];
        let mut across = edge(-5.0, 5.0, 0.0, &[]);
        for q in &mut across.points {
            *q = [5.0, q[0], 0.0];
        }
        let b = vec![edge(0.0, 10.0, 2.0, &[]), across];
        let out = fuse(vec![(ch(0), a), (ch(1), b)], &FuseParams::default());
        let total: f64 = out.iter().map(|e| e.length_m()).sum();
        assert!((total - 30.0).abs() < 0.5, "{total}");
        // The other side is never a duplicate.
        let mut r = edge(0.0, 10.0, 0.0, &[]);
        r.side = Side::Right;
        let out = fuse(
            vec![(ch(0), vec![edge(0.0, 10.0, 0.0, &[])]), (ch(1), vec![r])],
            &FuseParams::default(),
        );
        assert_eq!(out.len(), 2);
    }

    #[test]
    fn a_scanner_dropping_out_leaves_the_other_whole() {
        // Scanner 1 drops out from 12 m on; scanner 0 has everything.
        let s0 = vec![edge(0.0, 40.0, 0.0, &[])];
        let s1 = vec![edge(0.0, 12.0, 0.02, &[])];
        let out = fuse(vec![(ch(0), s0), (ch(1), s1)], &FuseParams::default());
        assert_eq!(out.len(), 1);
        assert!((out[0].length_m() - 40.0).abs() < 1e-6);
        assert_eq!(out[0].detail.as_ref().unwrap().scanners(), vec![0]);
    }

    #[test]
    fn two_passes_in_opposite_directions_give_one_edge_in_the_first_pass_frame() {
        // Pass 0 drives east and sees the left curb at y = 0 over 0–12 m and 18–40 m (a
        // parked car hides 12–18 m). Pass 1 drives back west, 0.1 m off (GNSS drift): it
        // sees the same curb on its right over 5–30 m.
        let p0 = vec![edge(0.0, 12.0, 0.0, &[]), edge(18.0, 40.0, 0.0, &[])];
        let mut back = edge(5.0, 30.0, 0.1, &[]).reversed();
        back.side = Side::Right;
        // As extract does: turned to pass 0's direction, shifted onto its edges.
        let mut p1 = vec![back.reversed()];
        assert_eq!(p1[0].side, Side::Left);
        let t = crate::stream::passes::shift_onto(&p0, &p1).expect("a shift");
        assert!((t[1] + 0.1).abs() < 0.01 && t[0].abs() < 0.01, "{t:?}");
        crate::stream::passes::shifted(&mut p1, t);
        let pass = |k: u16| Source {
            scanner: 0,
            pass: k,
        };
        let out = fuse(vec![(pass(0), p0), (pass(1), p1)], &FuseParams::default());
        assert_eq!(out.len(), 1, "{out:?}");
        let e = &out[0];
        assert!((e.length_m() - 40.0).abs() < 0.3, "{}", e.length_m());
        assert!(
            e.points.windows(2).all(|w| w[1][0] > w[0][0]),
            "pass 0's direction"
        );
        assert!(e.points.iter().all(|p| p[1].abs() < 0.02), "on the curb");
        let d = e.detail.as_ref().unwrap();
        assert_eq!(d.passes(), vec![0, 1]);
        // Pass 1 fills the 6 m pass 0 missed, nothing more.
        let from1: f64 = e
            .points
            .windows(2)
            .zip(d.pass.windows(2))
            .filter(|(_, s)| s[0] == 1 && s[1] == 1)
            .map(|(w, _)| w[1][0] - w[0][0])
            .sum();
        assert!((5.0..=6.5).contains(&from1), "{from1}");
        assert!(doubled_m(&out, 0.3) < 0.5);
    }

    #[test]
    fn two_overlapping_sections_give_one_edge() {
        // Two sections of a campaign overlap over 20–30 m of one curb.
        let a = vec![edge(0.0, 30.0, 0.0, &[])];
        let b = vec![edge(20.0, 50.0, 0.01, &[])];
        let sec = |k: u16| Source {
            scanner: 0,
            pass: k,
        };
        let out = fuse(vec![(sec(0), a), (sec(1), b)], &FuseParams::default());
        assert_eq!(out.len(), 1, "{out:?}");
        assert!(
            (out[0].length_m() - 50.0).abs() < 0.1,
            "{}",
            out[0].length_m()
        );
        assert!(doubled_m(&out, 0.3) < 0.5);
        assert_eq!(out[0].detail.as_ref().unwrap().passes(), vec![0, 1]);
    }
}
