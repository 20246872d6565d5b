//! Window and tracker of the stream: sections along the route.
//!
//! The trajectory is small (a pose per few milliseconds of driving) and stays whole, so a
//! point's *station* — the route's arc length at the point's time — is absolute, and the
//! seed intervals of §2.6 (keyed to the station) line up with those of a whole-file run.
//! The route is cut into sections of `section_m`; section k is `[s_k, s_k+1)`. Its window
//! holds the points whose station lies in `[s_k − margin_m, s_k+1 + margin_m)`; seeding,
//! tracking and the post-filters run on the window as on a whole file, and the parts of the
//! edges whose vertices lie in the section (by the station of the nearest route point) are
//! kept. Points arrive in time order, so stations never decrease: section k runs once a
//! point passes `s_k+1 + margin_m`, and afterwards the points before `s_k+1 − margin_m` are
//! evicted. Memory is the window: `section_m + 2 margin_m` metres of road.
//!
//! A scanner yawed from across the road measures a curb `l` metres aside about `l ·
//! tan(yaw)` ahead of the vehicle, farther than the margin on a side street's leg. The
//! window therefore also holds, in a *side store* at the front of its columns, the evicted
//! points near the road's level (at most [`LOW_ABOVE_M`] above the trajectory) that lie,
//! by their own station, in a section still to run; each is released when the sections it
//! lies in have run. Only points up to `lead_max_m` ahead of the vehicle are stored, so the
//! store holds at most that much road's low points.
//!
//! Pieces cut at a section boundary are joined by the [`Merge`](super::merge::Merge).
//! A section as long as the route gives one window holding every point, and the edges of
//! the whole-file run unchanged.

use super::core_stage::CoreBatch;
use super::merge::{Merge, Piece};
use crate::bend::grid::PointGrid;
use crate::bend::route::Route;
use crate::bend::{self, BendInput, BendParams};
use crate::curb;
use crate::io::trajectory::Trajectory;
use crate::model::EdgeLine;
use crate::replay::{Candidate, PointStatus};
use serde::{Deserialize, Serialize};

/// Parameters of the window (`[stream]` in the config file).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct WindowParams {
    /// Length of a section of road whose edges are closed together, metres. Memory grows
    /// with `section_m + 2 margin_m`, tracking work with `(section_m + 2 margin_m) /
    /// section_m`.
    pub section_m: f64,
    /// Road before and after a section that its window also holds, metres. The window
    /// selects points by the station of the vehicle when they were measured, the cut keeps
    /// edge vertices by the station nearest to them; the two differ by up to the lateral
    /// range times the tangent of the scanner's yaw and on curves. The margin covers that
    /// difference plus the reach of a track from its seed and of the post-filters, so that
    /// an edge inside the section sees what it would see in a whole-file run (the default
    /// window and its cost against others: docs/benchmarks.md).
    pub margin_m: f64,
    /// Most seconds of points the window holds. A vehicle that stands or creeps does not
    /// advance the route, so its points would pile up in one section: past this span the
    /// window closes the section at the vehicle's station and drops the oldest points it
    /// still holds (counted), so memory is bounded by this span times the point rate.
    pub max_s: f64,
    /// Farthest ahead of the vehicle, metres, that an evicted point near the road's level
    /// may lie and still be held for the section it lies in (0: no side store). A mount
    /// yawed from across the road measures a side street's leg `l` metres aside about `l ·
    /// tan(yaw)` ahead of the vehicle (docs/results.md).
    pub lead_max_m: f64,
    /// Road the window waits for past a section's margin before it runs the section,
    /// metres (0: none): a mount yawed the other way measures a side street's leg that far
    /// behind the vehicle, after the vehicle has passed the section. While it waits, the
    /// points only this section needs are thinned to those near the road's level, so the
    /// wait costs little memory.
    pub lag_m: f64,
}

impl Default for WindowParams {
    fn default() -> Self {
        Self {
            section_m: 60.0,
            margin_m: 10.0,
            max_s: 20.0,
            lead_max_m: 40.0,
            lag_m: 10.0,
        }
    }
}

/// The points of the window and their core output: first the side store (points kept past
/// their eviction, with their own stations `side_sp`), then the points from stream index
/// `base` on. The store's points are numbered just before `base`, so the window's points
/// have consecutive indices (the store's are renumbered as it changes).
#[derive(Default)]
struct Columns {
    base: u64,
    side_sp: Vec<f32>,
    x: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
    t: Vec<f64>,
    rho: Vec<f32>,
    status: Vec<Option<PointStatus>>,
    scanline: Vec<u32>,
    /// Candidates with the indices above.
    candidates: Vec<(u64, Candidate)>,
}

/// The points of a window's front to keep in its side store: a bit per point and the own
/// station of each kept point, in order.
struct Keep {
    bits: Vec<u64>,
    sp: Vec<f32>,
}

impl Keep {
    fn new(n: usize) -> Self {
        Self {
            bits: vec![0; n.div_ceil(64)],
            sp: Vec::new(),
        }
    }

    /// Keeps point `i` (above every point kept so far), lying at station `sp`.
    fn push(&mut self, i: usize, sp: f64) {
        if let Some(w) = self.bits.get_mut(i / 64) {
            *w |= 1 << (i % 64);
            self.sp.push(sp as f32);
        }
    }

    fn has(&self, i: usize) -> bool {
        self.bits
            .get(i / 64)
            .is_some_and(|w| w >> (i % 64) & 1 == 1)
    }

    /// The runs of consecutive kept points among the first `n`, in order.
    fn runs(&self, n: usize) -> Vec<std::ops::Range<usize>> {
        let bits_from = |i: usize| self.bits.get(i / 64).map_or(0, |w| w >> (i % 64));
        let mut runs = Vec::new();
        let mut i = 0;
        while i < n {
            let w = bits_from(i);
            if w == 0 {
                // No kept point in the rest of this word.
                i = (i / 64 + 1) * 64;
                continue;
            }
            i += w.trailing_zeros() as usize;
            let start = i;
            // A run that fills the rest of its word goes on into the next.
            loop {
                let ones = bits_from(i).trailing_ones() as usize;
                i += ones;
                if ones == 0 || i % 64 != 0 {
                    break;
                }
            }
            if start < n {
                runs.push(start..i.min(n));
            }
        }
        runs
    }
}

impl Columns {
    fn len(&self) -> usize {
        self.t.len()
    }

    /// Points in the side store, at the front of the columns.
    fn side(&self) -> usize {
        self.side_sp.len()
    }

    /// Index of the point at `i`.
    fn gid(&self, i: usize) -> u64 {
        (self.base + i as u64).saturating_sub(self.side() as u64)
    }

    fn append(&mut self, b: CoreBatch) {
        if self.t.len() == self.side() {
            // The store's points are numbered just before the first of the rest.
            let old = self.base;
            self.base = b.base;
            for (g, _) in &mut self.candidates {
                *g = (*g + b.base).saturating_sub(old);
            }
        }
        let s = b.skip.min(b.t.len());
        // Grow by a 32nd at a time, not by doubling: the window's columns are most of the
        // stream's memory, and evicting from the front keeps their capacity. Columns this
        // large are mapped (`stream::malloc::one_arena`), so growing one remaps it without a copy.
        let need = self.t.len() + b.t.len() - s;
        if need > self.t.capacity() {
            let cap = need + need / 32;
            grow(&mut self.x, cap);
            grow(&mut self.y, cap);
            grow(&mut self.z, cap);
            grow(&mut self.t, cap);
            grow(&mut self.rho, cap);
            grow(&mut self.status, cap);
            grow(&mut self.scanline, cap);
        }
        let base = b.base;
        self.candidates.extend(
            b.candidates
                .into_iter()
                .map(|c| (base + u64::from(c.point), c)),
        );
        self.x.extend_from_slice(&b.x[s..]);
        self.y.extend_from_slice(&b.y[s..]);
        self.z.extend_from_slice(&b.z[s..]);
        self.t.extend_from_slice(&b.t[s..]);
        self.rho.extend(b.rho_deg);
        self.status.extend(b.status);
        self.scanline.extend(b.scanline);
    }

    fn evict(&mut self, n: usize) {
        self.evict_keeping(n, Keep::new(0));
    }

    /// Evicts the first `n` points but those `keep` holds, which join the side store
    /// before the store's points at or after `n`.
    fn evict_keeping(&mut self, n: usize, mut keep: Keep) {
        let n = n.min(self.len());
        let side = self.side();
        let old_front = self.gid(0);
        // Rank of each kept point: the kept points before each word of the bitmap.
        let mut before = Vec::with_capacity(keep.bits.len());
        let mut c = 0u32;
        for w in &keep.bits {
            before.push(c);
            c += w.count_ones();
        }
        let kept = keep.sp.len();
        // The store's stations in a buffer of their exact size: it is held while the
        // next sections run, and the kept points' buffer grew by doubling.
        let rest = &self.side_sp[n.min(side)..];
        let mut sp = Vec::with_capacity(kept + rest.len());
        sp.extend_from_slice(&keep.sp);
        sp.extend_from_slice(rest);
        keep.sp = Vec::new();
        let runs = keep.runs(n);
        compact(&mut self.x, &runs, n);
        compact(&mut self.y, &runs, n);
        compact(&mut self.z, &runs, n);
        compact(&mut self.t, &runs, n);
        compact(&mut self.rho, &runs, n);
        compact(&mut self.status, &runs, n);
        compact(&mut self.scanline, &runs, n);
        self.base += n.saturating_sub(side) as u64;
        self.side_sp = sp;
        let new_front = self.gid(0);
        self.candidates.retain_mut(|(g, _)| {
            let Some(i) = g
                .checked_sub(old_front)
                .and_then(|i| usize::try_from(i).ok())
            else {
                return false;
            };
            let at = if i >= n {
                kept + (i - n)
            } else if keep.has(i) {
                let w = keep.bits[i / 64] & ((1u64 << (i % 64)) - 1);
                before[i / 64] as usize + w.count_ones() as usize
            } else {
                return false;
            };
            *g = new_front + at as u64;
            true
        });
    }
}

/// Moves the runs `runs` of the first `n` points of `v` (in order, within `0..n`) to the
/// front, in order, and drops the rest of those `n`.
fn compact<T: Copy>(v: &mut Vec<T>, runs: &[std::ops::Range<usize>], n: usize) {
    let mut w = 0;
    for r in runs {
        v.copy_within(r.clone(), w);
        w += r.len();
    }
    v.drain(w..n);
}

fn grow<T>(v: &mut Vec<T>, cap: usize) {
    v.reserve_exact(cap.saturating_sub(v.len()));
}

/// The section window and the bend method's tracker over it.
pub struct SectionWindow<'a> {
    traj: &'a Trajectory,
    route: Route,
    params: WindowParams,
    bend: BendParams,
    cols: Columns,
    /// Station where the next section starts.
    start: f64,
    /// Station up to which the points only the next section needs are thinned.
    thinned: f64,
    merge: Merge,
    /// Sections whose pieces are kept for a merge elsewhere instead of merged here.
    keep: Option<std::ops::Range<i64>>,
    /// The kept sections' pieces, in section order.
    kept: Vec<(i64, Vec<Piece>)>,
    /// Most points the window held at once.
    pub peak_points: usize,
    /// Points dropped by the time cap (`max_s`).
    pub capped_points: u64,
    /// The point grid of the section last run, slid on to the next (its slabs of the
    /// margin they share are kept).
    grid: PointGrid,
    /// Threads the sections left at the end of the stream are extracted on.
    finish_threads: usize,
}

/// Least progress along the route, metres, for which the time cap closes a section early;
/// below it (a standing vehicle) the cap only drops the oldest points.
const CAP_MIN_SECTION_M: f64 = 1.0;

/// Highest above the trajectory (the scanner) a point is still near the road's level for
/// the side store, metres: curbs lie a metre or more below a scanner on a vehicle's roof,
/// building fronts and tops reach far above it.
pub(super) const LOW_ABOVE_M: f64 = 0.5;

/// Farthest aside of the route a point is held in the side store, metres: the side
/// streets' legs a track follows lie within it.
const SIDE_ASIDE_M: f64 = 30.0;

impl<'a> SectionWindow<'a> {
    /// A window over `traj`'s route.
    pub fn new(traj: &'a Trajectory, params: WindowParams, bend: BendParams) -> Self {
        Self {
            traj,
            route: Route::new(traj),
            merge: Self::merge_for(&bend),
            bend,
            params,
            cols: Columns::default(),
            start: 0.0,
            thinned: f64::NEG_INFINITY,
            keep: None,
            kept: Vec::new(),
            peak_points: 0,
            capped_points: 0,
            grid: PointGrid::build(&[], &[], 1.0, |_| false),
            finish_threads: 1,
        }
    }

    /// A window that extracts the sections left at the end of the stream (every point
    /// read: they no longer wait for one another) on up to `threads` threads, each with a
    /// grid of its own, and merges them in order as one thread would.
    pub fn finishing_on(mut self, threads: usize) -> Self {
        self.finish_threads = threads.max(1);
        self
    }

    /// The merge a window with `bend`'s parameters joins its pieces with.
    pub fn merge_for(bend: &BendParams) -> Merge {
        // Two pieces of one curb meet within a few search steps of each other.
        let stitch = (3.0 * bend.search_distance_m).max(bend.join_distance_m);
        Merge::new(stitch, bend.min_edge_length_m)
    }

    /// A window that merges nothing: the pieces of the sections in `sections` are kept
    /// (see [`take_pieces`](Self::take_pieces)), those of other sections dropped. One task of
    /// a campaign cut into independent runs (`stream::tasks`).
    pub fn keeping(mut self, sections: std::ops::Range<i64>) -> Self {
        self.keep = Some(sections);
        self
    }

    /// The kept sections' pieces, in section order (a section without pieces is listed).
    pub fn take_pieces(&mut self) -> Vec<(i64, Vec<Piece>)> {
        std::mem::take(&mut self.kept)
    }

    /// True when the whole route is one section (the window is the whole input).
    pub fn is_single(&self) -> bool {
        self.single()
    }

    fn section_m(&self) -> f64 {
        self.params.section_m.max(1.0)
    }

    fn margin_m(&self) -> f64 {
        self.params.margin_m.max(0.0)
    }

    fn lag_m(&self) -> f64 {
        self.params.lag_m.max(0.0)
    }

    /// Moves the points only the section ending at `s1` needs (measured before its end
    /// less the margin) near the road's level into the side store and drops the others.
    fn thin(&mut self, s1: f64) {
        let upto = self
            .cols
            .t
            .partition_point(|&t| self.station(t) < s1 - self.margin_m());
        let keep = self.keep_low(upto, f64::NEG_INFINITY, f64::INFINITY);
        self.cols.evict_keeping(upto, keep);
        self.thinned = s1;
    }

    /// [`keep_low`] on this window's points.
    fn keep_low(&self, n: usize, from: f64, lead_max: f64) -> Keep {
        keep_low(&self.cols, self.traj, &self.route, n, from, lead_max)
    }

    fn station(&self, t: f64) -> f64 {
        self.route.arc_at(t).unwrap_or(0.0)
    }

    /// True when the whole route is one section: the window is the whole input.
    fn single(&self) -> bool {
        self.section_m() > self.route.length_m()
    }

    /// Takes the core's output for the next points and runs every section they complete.
    pub fn push(&mut self, b: CoreBatch) -> Vec<EdgeLine> {
        self.cols.append(b);
        self.peak_points = self.peak_points.max(self.cols.len());
        let mut out = Vec::new();
        let (Some(&t_first), Some(&t_last)) = (self.cols.t.first(), self.cols.t.last()) else {
            return out;
        };
        let s_last = self.station(t_last);
        if self.single() {
            // A section longer than the route asks for the whole input in one window.
            return out;
        }
        let (l, m, lag) = (self.section_m(), self.margin_m(), self.lag_m());
        loop {
            let s1 = self.start + l;
            if s1 + m + lag <= s_last {
                out.extend(self.run_section(s1));
            } else {
                if lag > 0.0 && s1 + m <= s_last && self.thinned < s1 {
                    self.thin(s1);
                }
                break;
            }
        }
        // The side store is older than the rest; the cap counts the time the rest spans.
        let t_first = self
            .cols
            .t
            .get(self.cols.side())
            .copied()
            .unwrap_or(t_first);
        if t_last - t_first > self.params.max_s.max(0.0) {
            out.extend(self.cap(t_last, s_last));
        }
        out
    }

    /// The time cap: closes the section at the vehicle's station `s_last` when the vehicle
    /// has moved on since the section started, then drops the points older than `max_s`
    /// before `t_last`.
    fn cap(&mut self, t_last: f64, s_last: f64) -> Vec<EdgeLine> {
        let out = if s_last >= self.start + CAP_MIN_SECTION_M {
            self.run_section(s_last)
        } else {
            Vec::new()
        };
        let cut = t_last - self.params.max_s.max(0.0);
        let n = self.cols.t.partition_point(|&t| t <= cut);
        if n > 0 {
            self.capped_points += n as u64;
            self.cols.evict(n);
        }
        out
    }

    /// Runs the remaining sections and closes every edge.
    pub fn finish(&mut self) -> Vec<EdgeLine> {
        if self.single() {
            return self
                .extract_range(0, self.cols.len(), None)
                .into_iter()
                .map(|(e, _)| e)
                .collect();
        }
        let mut out = Vec::new();
        let l = self.section_m();
        let end = self.route.length_m();
        if self.finish_threads > 1 {
            out.extend(self.run_sections_at_end(l, end));
        }
        while self.start <= end && !self.cols.t.is_empty() {
            out.extend(self.run_section(self.start + l));
        }
        if self.keep.is_none() {
            out.extend(self.merge.close_all());
        }
        out
    }

    /// The sections [`finish`](Self::finish) runs one by one, extracted on
    /// `finish_threads` threads and then cut, merged and evicted in order as
    /// [`run_section`](Self::run_section) does.
    fn run_sections_at_end(&mut self, l: f64, end: f64) -> Vec<EdgeLine> {
        let m = self.margin_m();
        // The sections and their points `lo..hi` in the window as it is now: a section
        // runs while it starts on the route and its predecessor's eviction (of the points
        // before its start less the margin) leaves points. Only the first takes the side
        // store; the others begin after it.
        let mut sections = Vec::new();
        let n = self.cols.len();
        let mut s0 = self.start;
        let mut from = 0;
        while s0 <= end && from < n {
            let s1 = s0 + l;
            let (mut lo, hi, next) = self.section_points(s0, s1);
            if !sections.is_empty() {
                lo = self.cols.t.partition_point(|&t| self.station(t) < s0 - m);
            }
            from = next;
            sections.push((s0, s1, lo, hi, from));
            s0 = s1;
        }
        let mut out = Vec::new();
        for group in sections.chunks(self.finish_threads) {
            let mut found: Vec<Vec<(EdgeLine, Vec<Option<f64>>)>> = Vec::new();
            std::thread::scope(|scope| {
                let (cols, traj, route, bend) = (&self.cols, self.traj, &self.route, &self.bend);
                let others: Vec<_> = group[1..]
                    .iter()
                    .map(|&(_, _, lo, hi, _)| {
                        scope.spawn(move || {
                            if hi <= lo {
                                return Vec::new();
                            }
                            let mut grid = PointGrid::build(&[], &[], 1.0, |_| false);
                            extract_on(cols, traj, route, bend, &mut grid, lo, hi, None)
                        })
                    })
                    .collect();
                let (_, _, lo, hi, next) = group[0];
                found.push(if hi > lo {
                    let cut = next.checked_sub(lo);
                    extract_on(cols, traj, route, bend, &mut self.grid, lo, hi, cut)
                } else {
                    Vec::new()
                });
                for h in others {
                    found.push(h.join().unwrap_or_else(|p| std::panic::resume_unwind(p)));
                }
            });
            for (&(s0, s1, _, _, _), edges) in group.iter().zip(found) {
                out.extend(self.close_section(edges, s0, s1));
            }
        }
        if let Some(&(_, s1, _, _, _)) = sections.last() {
            self.start = s1;
            let keep_from = self.cols.t.partition_point(|&t| self.station(t) < s1 - m);
            self.cols.evict(keep_from);
        }
        out
    }

    /// The points `lo..hi` of the section `[s0, s1)` in the window as it is now, and where
    /// the next section's points begin (`keep_from`: the grid's new slabs are cut there).
    /// The section takes the whole side store: the store holds the points lying in its
    /// window that were measured before it, and, while it waits, its own points thinned.
    fn section_points(&self, s0: f64, s1: f64) -> (usize, usize, usize) {
        let m = self.margin_m();
        let lo = if self.cols.side() > 0 {
            0
        } else {
            self.cols.t.partition_point(|&t| self.station(t) < s0 - m)
        };
        let hi = self
            .cols
            .t
            .partition_point(|&t| self.station(t) < s1 + m + self.lag_m());
        let keep_from = self.cols.t.partition_point(|&t| self.station(t) < s1 - m);
        (lo, hi, keep_from)
    }

    /// Runs the section `[start, s1)`, then evicts the points the next section does not
    /// need.
    fn run_section(&mut self, s1: f64) -> Vec<EdgeLine> {
        let s0 = self.start;
        let (lo, hi, keep_from) = self.section_points(s0, s1);
        // The route's last section: no later section reads the side store.
        let last = s1 > self.route.length_m();
        let (from, lead_max) = (s1 - self.margin_m(), self.params.lead_max_m);
        // The points to keep in the side store depend on the window's points alone, not
        // on the section's edges: they are found beside the section's parts that run on
        // one thread (the grid's slide, the tracker).
        let (cols, traj, route, bend) = (&self.cols, self.traj, &self.route, &self.bend);
        let grid = &mut self.grid;
        let (edges, keep) = rayon::join(
            || {
                if hi > lo {
                    let cut = keep_from.checked_sub(lo);
                    extract_on(cols, traj, route, bend, grid, lo, hi, cut)
                } else {
                    Vec::new()
                }
            },
            || (!last).then(|| keep_low(cols, traj, route, keep_from, from, lead_max)),
        );
        let closed = self.close_section(edges, s0, s1);
        self.start = s1;
        match keep {
            Some(keep) => self.cols.evict_keeping(keep_from, keep),
            None => self.cols.evict(keep_from),
        }
        closed
    }

    /// The pieces of the edges `edges` of the section `[s0, s1)`, merged (or kept for a
    /// merge elsewhere).
    fn close_section(
        &mut self,
        edges: Vec<(EdgeLine, Vec<Option<f64>>)>,
        s0: f64,
        s1: f64,
    ) -> Vec<EdgeLine> {
        let mut pieces = Vec::new();
        for (e, steps) in edges {
            pieces.extend(cut_to_section(&self.route, e, steps, s0, s1));
        }
        match &self.keep {
            None => self.merge.push(pieces, s0, s1),
            Some(keep) => {
                // A section closed early by the time cap keeps the index of the
                // section it starts in.
                let k = ((s0 + 1e-9) / self.section_m()).floor() as i64;
                if keep.contains(&k) {
                    self.kept.push((k, pieces));
                }
                Vec::new()
            }
        }
    }

    /// The bend method on the window's points `lo..hi`; the next section's points begin
    /// `cut` points after `lo`.
    fn extract_range(
        &mut self,
        lo: usize,
        hi: usize,
        cut: Option<usize>,
    ) -> Vec<(EdgeLine, Vec<Option<f64>>)> {
        extract_on(
            &self.cols,
            self.traj,
            &self.route,
            &self.bend,
            &mut self.grid,
            lo,
            hi,
            cut,
        )
    }
}

/// The first `n` points of `c` to keep in the side store: those of the store that lie at or
/// after station `from`, and the others near the road's level (at most
/// [`LOW_ABOVE_M`] above the trajectory) within [`SIDE_ASIDE_M`] aside of the vehicle,
/// at most `lead_max` ahead of it, that lie at or after `from` (the vehicle's station
/// and how far ahead of it the point lies).
fn keep_low(
    c: &Columns,
    traj: &Trajectory,
    route: &Route,
    n: usize,
    from: f64,
    lead_max: f64,
) -> Keep {
    let n = n.min(c.len());
    let mut keep = Keep::new(n);
    for (i, &sp) in c.side_sp.iter().enumerate().take(n) {
        if f64::from(sp) >= from {
            keep.push(i, f64::from(sp));
        }
    }
    if lead_max.is_nan() || lead_max <= 0.0 {
        return keep;
    }
    let samples = &traj.samples;
    let mut k = 0;
    // The forward vector of sample `k`, computed once per sample (a sine and a cosine).
    let mut forward: Option<(usize, [f64; 2])> = None;
    for i in c.side()..n {
        // The trajectory's sample at or before the point's time (points come in time
        // order, so the cursor only moves on).
        let t = c.t[i];
        while k + 1 < samples.len() && samples[k + 1].t <= t {
            k += 1;
        }
        let Some(p) = samples.get(k) else { break };
        let above = c.z[i] - p.z;
        if above.is_nan() || above > LOW_ABOVE_M {
            continue;
        }
        let [fx, fy] = match forward {
            Some((j, f)) if j == k => f,
            _ => {
                let f = p.forward();
                forward = Some((k, f));
                f
            }
        };
        let (dx, dy) = (c.x[i] - p.x, c.y[i] - p.y);
        let ahead = dx * fx + dy * fy;
        let aside = dx * fy - dy * fx;
        if ahead <= lead_max && aside.abs() <= SIDE_ASIDE_M {
            let sp = route.arc_at_sample(t, k).unwrap_or(0.0) + ahead;
            if sp >= from {
                keep.push(i, sp);
            }
        }
    }
    keep
}

/// The bend method on the points `lo..hi` of `c`, indexed by `grid`: its slabs that lie in
/// `lo..hi` are kept, the rest of the points indexed in new slabs cut `cut` points after
/// `lo`, where the next section begins.
#[allow(clippy::too_many_arguments)]
fn extract_on(
    c: &Columns,
    traj: &Trajectory,
    route: &Route,
    bend: &BendParams,
    grid: &mut PointGrid,
    lo: usize,
    hi: usize,
    cut: Option<usize>,
) -> Vec<(EdgeLine, Vec<Option<f64>>)> {
    if c.side() > 0 && lo == 0 {
        // The section takes the side store: the store's points come first.
        let cut = cut.and_then(|k| k.checked_sub(c.side()));
        return extract_with_side(c, traj, route, bend, grid, hi, cut);
    }
    let cands = candidates_in(c, lo, hi);
    let input = input_of(c, traj, lo, hi, &cands);
    // One index for the tracker and the curb annotation.
    bend::point_grid_slide(grid, &input, c.gid(lo), cut, bend);
    let mut edges = bend::extract_edges_on_grid(&input, grid, route, bend);
    curb::annotate(&input, grid, route, edges.iter_mut().map(|(e, _)| e));
    edges
}

/// The bend method on the side store and the points after it up to `hi`: the grid slides
/// on over the points after the store as in [`extract_on`] (so its slabs below them are
/// dropped), then indexes the store in a slab of its own just before them.
#[allow(clippy::too_many_arguments)]
fn extract_with_side(
    c: &Columns,
    traj: &Trajectory,
    route: &Route,
    bend: &BendParams,
    grid: &mut PointGrid,
    hi: usize,
    cut: Option<usize>,
) -> Vec<(EdgeLine, Vec<Option<f64>>)> {
    let side = c.side();
    let glo = c.base;
    let main_cands = candidates_in(c, side, hi);
    bend::point_grid_slide(
        grid,
        &input_of(c, traj, side, hi, &main_cands),
        glo,
        cut,
        bend,
    );
    let cands = candidates_in(c, 0, hi);
    let input = input_of(c, traj, 0, hi, &cands);
    bend::point_grid_slide(grid, &input, c.gid(0), None, bend);
    let mut edges = bend::extract_edges_on_grid(&input, grid, route, bend);
    curb::annotate(&input, grid, route, edges.iter_mut().map(|(e, _)| e));
    edges
}

/// The candidates among the points `lo..hi` of `c`, indexed from `lo`.
fn candidates_in(c: &Columns, lo: usize, hi: usize) -> Vec<Candidate> {
    let (glo, ghi) = (c.gid(lo), c.gid(hi));
    c.candidates
        .iter()
        .filter(|(g, _)| (glo..ghi).contains(g))
        .map(|(g, cand)| Candidate {
            point: (g - glo) as u32,
            ..*cand
        })
        .collect()
}

/// The bend method's input over the points `lo..hi` of `c`.
fn input_of<'c>(
    c: &'c Columns,
    traj: &'c Trajectory,
    lo: usize,
    hi: usize,
    cands: &'c [Candidate],
) -> BendInput<'c> {
    BendInput {
        x: &c.x[lo..hi],
        y: &c.y[lo..hi],
        z: &c.z[lo..hi],
        t: &c.t[lo..hi],
        rho_deg: &c.rho[lo..hi],
        status: &c.status[lo..hi],
        scanline: &c.scanline[lo..hi],
        candidates: cands,
        trajectory: traj,
    }
}

/// The runs of an edge's vertices whose station lies in `[s0, s1)`, each as a piece.
fn cut_to_section(
    route: &Route,
    e: EdgeLine,
    steps: Vec<Option<f64>>,
    s0: f64,
    s1: f64,
) -> Vec<Piece> {
    let st: Vec<f64> = e
        .points
        .iter()
        .map(|p| route.station_near(p[0], p[1]).unwrap_or(f64::NAN))
        .collect();
    let inside = |s: f64| s >= s0 && s < s1;
    if st.iter().all(|&s| inside(s)) {
        return vec![Piece::whole(e, steps)];
    }
    let mut out = Vec::new();
    let mut k = 0;
    while k < st.len() {
        if !inside(st[k]) {
            k += 1;
            continue;
        }
        let a = k;
        while k < st.len() && inside(st[k]) {
            k += 1;
        }
        out.push(Piece::cut(
            e.sub(a, k),
            steps[a..k].to_vec(),
            a > 0,
            k < st.len(),
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    /// A drive along x: 10 m/s for 5 s, standing for 200 s, 10 m/s for 5 s more.
    fn stop_and_go() -> Trajectory {
        let mut csv = String::from("time,x,y,z,roll,pitch,heading\n");
        let mut x = 0.0;
        for k in 0..=2100 {
            let t = k as f64 * 0.1;
            if !(5.0..205.0).contains(&t) && k > 0 {
                x += 1.0;
            }
            csv.push_str(&format!("{t},{x},0,2,0,0,90\n"));
        }
        Trajectory::parse_csv(Path::new("stop.csv"), &csv).expect("trajectory parses")
    }

    /// One second of points from `t0`: 20 000 points a second, none processed by the core.
    fn second(base: u64, t0: f64) -> CoreBatch {
        let n = 20_000;
        let t: Vec<f64> = (0..n).map(|i| t0 + i as f64 / n as f64).collect();
        CoreBatch {
            base,
            skip: 0,
            x: vec![0.0; n],
            y: vec![3.0; n],
            z: vec![0.0; n],
            t,
            rho_deg: vec![0.0; n],
            status: vec![None; n],
            scanline: vec![0; n],
            candidates: Vec::new(),
        }
    }

    #[test]
    fn kept_runs_are_the_kept_points() {
        let n = 300;
        // Runs inside a word, across word boundaries, to the last point, and one point.
        let kept = |i: usize| (3..9).contains(&i) || (60..200).contains(&i) || i == 250 || i >= 298;
        let mut keep = Keep::new(n);
        for i in (0..n).filter(|&i| kept(i)) {
            keep.push(i, 0.0);
        }
        let runs = keep.runs(n);
        assert_eq!(runs, vec![3..9, 60..200, 250..251, 298..300]);
        assert_eq!(keep.runs(100), vec![3..9, 60..100]);
        assert_eq!(Keep::new(0).runs(n), vec![]);
        let mut v: Vec<usize> = (0..n + 5).collect();
        compact(&mut v, &runs, n);
        let want: Vec<usize> = (0..n).filter(|&i| kept(i)).chain(n..n + 5).collect();
        assert_eq!(v, want);
    }

    fn drive(max_s: f64) -> SectionWindow<'static> {
        let traj = Box::leak(Box::new(stop_and_go()));
        let params = WindowParams {
            max_s,
            ..WindowParams::default()
        };
        let mut w = SectionWindow::new(traj, params, BendParams::default());
        for s in 0..209 {
            w.push(second(s * 20_000, s as f64));
        }
        w.finish();
        w
    }

    #[test]
    fn a_standing_vehicle_does_not_grow_the_window_past_its_time_cap() {
        let capped = drive(20.0);
        // At most the cap's 20 s and the batch that passed it (and a point at the cap's
        // edge, as the times round).
        assert!(
            capped.peak_points <= 21 * 20_000 + 1,
            "{}",
            capped.peak_points
        );
        assert!(
            capped.capped_points >= 150 * 20_000,
            "{}",
            capped.capped_points
        );
        // Without the cap the window holds the whole stop.
        let open = drive(f64::INFINITY);
        assert!(open.peak_points >= 200 * 20_000, "{}", open.peak_points);
        assert_eq!(open.capped_points, 0);
    }

    /// A drive along x at 10 m/s for 20 s, the scanner 2 m up.
    fn straight() -> Trajectory {
        let mut csv = String::from("time,x,y,z,roll,pitch,heading\n");
        for k in 0..=200 {
            let t = k as f64 * 0.1;
            csv.push_str(&format!("{t},{},0,2,0,0,90\n", 10.0 * t));
        }
        Trajectory::parse_csv(Path::new("straight.csv"), &csv).expect("trajectory parses")
    }

    /// A tenth of a second of `straight` from `t0`: per instant a ground point 25 m ahead
    /// of the vehicle (8 m to its left), one 25 m behind (8 m to its right), one beside it
    /// and one 10 m up beside it.
    fn tenth(base: u64, t0: f64) -> CoreBatch {
        let mut b = second(base, 0.0);
        let n = 400;
        let t: Vec<f64> = (0..n).map(|i| t0 + (i / 4) as f64 / 1000.0).collect();
        let (ahead, aside, z) = (
            [25.0, -25.0, 0.0, 0.0],
            [8.0, -8.0, 3.0, 3.0],
            [0.0, 0.0, 0.0, 12.0],
        );
        b.x = t
            .iter()
            .enumerate()
            .map(|(i, &t)| 10.0 * t + ahead[i % 4])
            .collect();
        b.y = (0..n).map(|i| aside[i % 4]).collect();
        b.z = (0..n).map(|i| z[i % 4]).collect();
        b.rho_deg.truncate(n);
        b.status.truncate(n);
        b.scanline.truncate(n);
        b.t = t;
        b
    }

    /// The points of `w` measured in `[t0, t1)` that lie (by x) in `[x0, x1)` at height `z`.
    fn held(w: &SectionWindow, t: (f64, f64), x: (f64, f64), z: f64) -> usize {
        held_in(w, 0..w.cols.len(), t, x, z)
    }

    /// [`held`] among the window's points `range`.
    fn held_in(
        w: &SectionWindow,
        range: std::ops::Range<usize>,
        t: (f64, f64),
        x: (f64, f64),
        z: f64,
    ) -> usize {
        let c = &w.cols;
        range
            .filter(|&i| (t.0..t.1).contains(&c.t[i]) && (x.0..x.1).contains(&c.x[i]))
            .filter(|&i| c.z[i] == z)
            .count()
    }

    #[test]
    fn a_section_gets_the_road_level_points_that_lie_in_it_whenever_they_were_measured() {
        let traj = straight();
        let mut w = SectionWindow::new(&traj, WindowParams::default(), BendParams::default());
        let feed = |w: &mut SectionWindow, from: usize, to: usize| {
            for k in from..to {
                w.push(tenth(k as u64 * 400, k as f64 / 10.0));
            }
        };
        // The vehicle at 75 m: past section 0's end and margin (70 m), not past the wait
        // for points lying behind it (80 m), so section 0 has not run. Its own points
        // measured before the next window (50 m) are thinned to the road's level.
        feed(&mut w, 0, 76);
        assert_eq!(w.start, 0.0);
        assert_eq!(held(&w, (0.0, 4.0), (0.0, 40.0), 12.0), 0);
        assert!(held(&w, (0.0, 4.0), (0.0, 40.0), 0.0) >= 300);
        // Points lying at 45-55 m, measured behind the vehicle at 70-75 m, are in the
        // window when section 0 runs.
        assert!(held(&w, (7.0, 7.6), (45.0, 55.0), 0.0) >= 100);
        feed(&mut w, 76, 81);
        assert_eq!(w.start, 60.0);
        // After section 0: the ground points lying in section 1's window (from 50 m) that
        // the vehicle measured 25 m behind them, before that window, are held for it...
        assert!(held(&w, (2.5, 5.0), (50.0, 75.0), 0.0) >= 900);
        // ...and the points that lie only in section 0 are released.
        assert_eq!(held(&w, (0.0, 5.0), (0.0, 49.0), 0.0), 0);
        assert_eq!(held(&w, (0.0, 5.0), (0.0, 200.0), 12.0), 0);
        // The vehicle at 135 m: section 1 waits, its own points thinned into the store
        // after those held for it, and it runs on both.
        feed(&mut w, 81, 136);
        assert_eq!(w.start, 60.0);
        assert!(w.thinned >= 120.0);
        let (lo, hi, _) = w.section_points(60.0, 120.0);
        assert!(held_in(&w, lo..hi, (2.5, 5.0), (50.0, 75.0), 0.0) >= 900);
        assert!(held_in(&w, lo..hi, (6.0, 11.0), (50.0, 120.0), 0.0) >= 900);
        // Without the side store and the wait, the window is cut by the vehicle's station.
        let params = WindowParams {
            lead_max_m: 0.0,
            lag_m: 0.0,
            ..WindowParams::default()
        };
        let mut v = SectionWindow::new(&traj, params, BendParams::default());
        feed(&mut v, 0, 81);
        assert_eq!(held(&v, (2.5, 5.0), (50.0, 75.0), 0.0), 0);
    }
}
