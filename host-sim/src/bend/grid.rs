//! A uniform grid over world XY: the spatial index behind the local point set S of §2.7
//! and the post-filters' neighbourhood queries. Points are bucketed by a counting sort
//! (two passes, no comparison sort): 4 bytes per point for the sorted indices plus 4
//! bytes per cell, with the cell grown (never below the requested size) until there are at
//! most half as many cells as points — about 6 bytes per point in all, and a bit per point
//! and 4 bytes per indexed point (its cell) while it is built. A query visits only the
//! cells the disc touches, never the whole cloud.
//!
//! A stream's windows overlap: each holds the margin of road the window before it held
//! too. The grid is therefore made of *slabs*, each indexing a run of consecutive points
//! in a box of its own; [`slide`](PointGrid::slide) keeps the slabs a new window still
//! holds, drops the others and indexes only the points not yet in a slab, so each point
//! is bucketed once however many windows hold it.

/// Point indices bucketed by square XY cells, slab by slab.
pub struct PointGrid {
    /// Stream index of index 0 of the slices the grid was last given.
    origin: u64,
    /// Slabs in order of their first point; together they cover the slices given.
    slabs: Vec<Slab>,
    /// Slabs no longer held, kept for their arrays.
    spare: Vec<Slab>,
}

/// One slab: the points of a run of consecutive stream indices, bucketed by a square cell
/// over their bounding box.
#[derive(Default)]
struct Slab {
    /// Stream index of the run's first point; `order` counts from it.
    start: u64,
    /// Points in the run, indexed or not.
    span: usize,
    /// Cell size asked for (the one in use may be larger).
    asked_m: f64,
    cell_m: f64,
    x0: f64,
    y0: f64,
    /// Far corner of the indexed points' box, for a quick miss.
    x1: f64,
    y1: f64,
    nx: usize,
    ny: usize,
    /// `starts[c]..starts[c + 1]` is cell `c`'s range in `order` (`c = cy·nx + cx`).
    starts: Vec<u32>,
    /// Point indices from `start`, sorted by cell then index.
    order: Vec<u32>,
}

impl PointGrid {
    /// Indexes the points `i` with `keep(i)` true (and finite coordinates), in cells of at
    /// least `cell_m` metres.
    ///
    /// `keep` is asked once per point; the answers are kept as a bitmap (one bit per point)
    /// for the two passes of the counting sort.
    pub fn build(x: &[f64], y: &[f64], cell_m: f64, keep: impl Fn(usize) -> bool + Sync) -> Self {
        let mut g = Self {
            origin: 0,
            slabs: Vec::new(),
            spare: Vec::new(),
        };
        g.rebuild(x, y, cell_m, keep);
        g
    }

    /// [`build`](Self::build) in place: the same index, in the cell and order arrays this
    /// grid already holds (one slab over every point).
    pub fn rebuild(
        &mut self,
        x: &[f64],
        y: &[f64],
        cell_m: f64,
        keep: impl Fn(usize) -> bool + Sync,
    ) {
        let n = x.len().min(y.len()).min(u32::MAX as usize - 1);
        self.origin = 0;
        self.retire(|_| true);
        self.add_slab(&x[..n], &y[..n], 0, n, cell_m, &keep);
    }

    /// The index of the points `i` with `keep(i)` true (and finite coordinates) of slices
    /// `x`, `y` whose index 0 is point `origin` of a stream: the slabs that lie within the
    /// slices are kept, the others dropped, and the points no slab holds are indexed in new
    /// slabs, cut at `cut` (an index into the slices) when it falls among them. A caller
    /// that gives the index where its next slices will begin as `cut` has every point
    /// bucketed once. `keep` must give a point the same answer on every call.
    ///
    /// Queries visit the slabs in turn, so the order of their points depends on where the
    /// slabs were cut, not only on the points.
    pub fn slide(
        &mut self,
        x: &[f64],
        y: &[f64],
        origin: u64,
        cut: Option<usize>,
        cell_m: f64,
        keep: impl Fn(usize) -> bool + Sync,
    ) {
        let n = x.len().min(y.len()).min(u32::MAX as usize - 1);
        let (x, y) = (&x[..n], &y[..n]);
        let end = origin + n as u64;
        self.origin = origin;
        self.retire(|s| s.start < origin || s.start + s.span as u64 > end || s.asked_m != cell_m);
        let held: Vec<(usize, usize)> = self
            .slabs
            .iter()
            .map(|s| {
                let a = (s.start - origin) as usize;
                (a, a + s.span)
            })
            .collect();
        let mut from = 0;
        for (a, b) in held.into_iter().chain([(n, n)]) {
            if a > from {
                match cut {
                    Some(c) if c > from && c < a => {
                        self.add_slab(x, y, from, c, cell_m, &keep);
                        self.add_slab(x, y, c, a, cell_m, &keep);
                    }
                    _ => self.add_slab(x, y, from, a, cell_m, &keep),
                }
            }
            from = from.max(b);
        }
        self.slabs.sort_unstable_by_key(|s| s.start);
    }

    /// Moves the slabs for which `drop` holds to the spares.
    fn retire(&mut self, drop: impl Fn(&Slab) -> bool) {
        let mut k = 0;
        while k < self.slabs.len() {
            if drop(&self.slabs[k]) {
                let s = self.slabs.swap_remove(k);
                self.spare.push(s);
            } else {
                k += 1;
            }
        }
        self.slabs.sort_unstable_by_key(|s| s.start);
    }

    /// Indexes the points `lo..hi` of the slices in a new slab, in the arrays of the spare
    /// that holds the most.
    fn add_slab(
        &mut self,
        x: &[f64],
        y: &[f64],
        lo: usize,
        hi: usize,
        cell_m: f64,
        keep: &(impl Fn(usize) -> bool + Sync),
    ) {
        let best = (0..self.spare.len()).max_by_key(|&k| self.spare[k].order.capacity());
        let mut s = best.map_or_else(Slab::default, |k| self.spare.swap_remove(k));
        s.start = self.origin + lo as u64;
        s.span = hi - lo;
        s.asked_m = cell_m;
        s.index(&x[lo..hi], &y[lo..hi], cell_m, |i| keep(lo + i));
        self.slabs.push(s);
        // A spare beyond the two a window's slide reuses only holds memory.
        self.spare.truncate(2);
    }

    /// Calls `f(i)` for every indexed point within `r` (horizontal) of `(px, py)`, in a
    /// fixed order (slab by slab, cells row by row, indices ascending within a cell).
    pub fn for_each_within(
        &self,
        x: &[f64],
        y: &[f64],
        px: f64,
        py: f64,
        r: f64,
        mut f: impl FnMut(usize),
    ) {
        if !(px.is_finite() && py.is_finite() && r >= 0.0) {
            return;
        }
        for s in &self.slabs {
            if s.order.is_empty()
                || px + r < s.x0
                || px - r > s.x1
                || py + r < s.y0
                || py - r > s.y1
            {
                continue;
            }
            let off = (s.start - self.origin) as usize;
            s.for_each_within(&x[off..], &y[off..], px, py, r, |i| f(off + i));
        }
    }

    /// Calls `f(i, c, a)` for every indexed point within `r` (horizontal) of `centre`
    /// that lies on the rectangle around it of half-length `half_a` along the unit vector
    /// `along` and half-width `half_c` along the unit vector `n`, with `a` and `c` its
    /// offsets along `along` and `n` (`a = dx·along₀ + dy·along₁`, `c = dx·n₀ + dy·n₁`).
    /// The points are those of [`for_each_within`](Self::for_each_within) with
    /// `|a| ≤ half_a` and `|c| ≤ half_c`, in the same order; only the cells the rectangle
    /// touches are visited, not all those of the disc around it.
    #[allow(clippy::too_many_arguments)]
    pub fn for_each_in_rect(
        &self,
        x: &[f64],
        y: &[f64],
        centre: [f64; 2],
        along: [f64; 2],
        n: [f64; 2],
        half_a: f64,
        half_c: f64,
        r: f64,
        mut f: impl FnMut(usize, f64, f64),
    ) {
        let [px, py] = centre;
        if !(px.is_finite() && py.is_finite() && r >= 0.0) {
            return;
        }
        // The corners: the offsets whose (a, c) are (±half_a, ±half_c).
        let det = along[0] * n[1] - along[1] * n[0];
        let corner = |a: f64, c: f64| {
            [
                px + (n[1] * a - along[1] * c) / det,
                py + (along[0] * c - n[0] * a) / det,
            ]
        };
        let mut rect = Rect {
            corners: [
                corner(half_a, half_c),
                corner(half_a, -half_c),
                corner(-half_a, -half_c),
                corner(-half_a, half_c),
            ],
        };
        if !rect.corners.iter().flatten().all(|v| v.is_finite()) {
            // No rectangle to scan (a degenerate direction): the disc's square.
            rect.corners = [
                [px + r, py + r],
                [px + r, py - r],
                [px - r, py - r],
                [px - r, py + r],
            ];
        }
        for s in &self.slabs {
            if s.order.is_empty()
                || px + r < s.x0
                || px - r > s.x1
                || py + r < s.y0
                || py - r > s.y1
            {
                continue;
            }
            let off = (s.start - self.origin) as usize;
            let (x, y) = (&x[off..], &y[off..]);
            let r2 = r * r;
            s.for_each_in_rows(px, py, r, &rect, |i| {
                let dx = x[i] - px;
                let dy = y[i] - py;
                if dx * dx + dy * dy > r2 {
                    return;
                }
                let a = dx * along[0] + dy * along[1];
                let c = dx * n[0] + dy * n[1];
                if a.abs() <= half_a && c.abs() <= half_c {
                    f(off + i, c, a);
                }
            });
        }
    }

    /// Number of indexed points.
    pub fn len(&self) -> usize {
        self.slabs.iter().map(|s| s.order.len()).sum()
    }

    /// Whether no point is indexed.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Cell size in use, metres (at least the one asked for; the first slab's).
    pub fn cell_m(&self) -> f64 {
        self.slabs.first().map_or(1.0, |s| s.cell_m)
    }

    /// Number of slabs (for tests).
    #[cfg(test)]
    fn slab_count(&self) -> usize {
        self.slabs.len()
    }
}

impl Slab {
    /// Indexes the points `i` of `x`, `y` with `keep(i)` true and finite coordinates.
    ///
    /// A slab of [`HALVES_MIN_POINTS`] or more is indexed in two halves on two threads
    /// (rayon's pool): each half of the points finds its box and its points' cells, and
    /// each half of the cells takes its points in one walk over all of them in order, so
    /// the index is the one a single thread builds.
    fn index(&mut self, x: &[f64], y: &[f64], cell_m: f64, keep: impl Fn(usize) -> bool + Sync) {
        let halves = x.len().min(y.len()) >= HALVES_MIN_POINTS;
        self.index_in(x, y, cell_m, keep, halves);
    }

    /// [`index`](Self::index), in two halves when `halves`.
    fn index_in(
        &mut self,
        x: &[f64],
        y: &[f64],
        cell_m: f64,
        keep: impl Fn(usize) -> bool + Sync,
        halves: bool,
    ) {
        let n = x.len().min(y.len());
        let (x, y) = (&x[..n], &y[..n]);
        let mut kept = vec![0u64; n.div_ceil(64)];
        // The second half's points start at a word of the bitmap.
        let mid_w = if halves { kept.len() / 2 } else { kept.len() };
        let (ka, kb) = kept.split_at_mut(mid_w);
        let (a, b) = both(
            halves,
            || Bounds::scan(x, y, 0, ka, &keep),
            || Bounds::scan(x, y, mid_w * 64, kb, &keep),
        );
        let (x0, y0, x1, y1) = (
            a.x0.min(b.x0),
            a.y0.min(b.y0),
            a.x1.max(b.x1),
            a.y1.max(b.y1),
        );
        let count = a.count + b.count;
        let mut cell = if cell_m.is_finite() && cell_m > 0.0 {
            cell_m
        } else {
            1.0
        };
        self.starts.clear();
        self.order.clear();
        if count == 0 {
            self.cell_m = cell;
            (self.x0, self.y0, self.x1, self.y1, self.nx, self.ny) = (0.0, 0.0, 0.0, 0.0, 0, 0);
            self.starts.push(0);
            return;
        }
        let max_cells = (count / 2).max(1024) as f64;
        let dims = |c: f64| (((x1 - x0) / c).floor() + 1.0, ((y1 - y0) / c).floor() + 1.0);
        while {
            let (a, b) = dims(cell);
            a * b > max_cells
        } {
            cell *= 1.5;
        }
        let (a_n, b_n) = dims(cell);
        let (nx, ny) = (a_n as usize, b_n as usize);
        (self.cell_m, self.x0, self.y0, self.nx, self.ny) = (cell, x0, y0, nx, ny);
        (self.x1, self.y1) = (x1, y1);
        self.starts.resize(nx * ny + 1, 0);
        // Each kept point's cell, found once for the count and kept for the scatter (4
        // bytes a kept point while the grid is built).
        let cells = CellOf::new(self);
        let mut cell_of = vec![0u32; count];
        {
            let (ca, cb) = cell_of.split_at_mut(a.count);
            let (ka, kb) = kept.split_at(mid_w);
            let cells = &cells;
            both(
                halves,
                || cells.of_set(x, y, 0, ka, ca),
                || cells.of_set(x, y, mid_w * 64, kb, cb),
            );
        }
        let starts = &mut self.starts;
        for &c in &cell_of {
            starts[c as usize + 1] += 1;
        }
        // Prefix sums: `starts[c + 1]` is where cell c + 1 begins. The scatter moves each
        // cell's start on to its end; one shift back gives the starts again.
        let ncell = nx * ny;
        for c in 0..ncell {
            starts[c + 1] += starts[c];
        }
        self.order.resize(count, 0);
        // The cells below `cm` take the first part of `order`, the others the rest.
        let cm = if halves {
            starts
                .partition_point(|&s| (s as usize) < count / 2)
                .min(ncell)
        } else {
            ncell
        };
        let base = starts[cm] as usize;
        let (oa, ob) = self.order.split_at_mut(base);
        let (sa, sb) = starts.split_at_mut(cm);
        let (kept, cell_of) = (&kept, &cell_of);
        both(
            halves,
            || scatter(kept, cell_of, 0..cm, sa, oa, 0),
            || scatter(kept, cell_of, cm..ncell, sb, ob, base),
        );
        starts.copy_within(0..ncell, 1);
        starts[0] = 0;
    }

    /// The cells `lo..=hi` (offsets from the slab's origin, metres) cover along an axis of
    /// `n` cells, clamped to it; `None` where the span misses the axis.
    #[inline]
    fn span(&self, lo: f64, hi: f64, n: usize) -> Option<(usize, usize)> {
        let a = floor(lo / self.cell_m);
        let b = floor(hi / self.cell_m);
        if b < 0.0 || a >= n as f64 {
            return None;
        }
        Some((a.max(0.0) as usize, (b as usize).min(n - 1)))
    }

    /// Calls `f(i)` for the points of the cells that the disc of `r` around `(px, py)`
    /// and `rect` both touch, row by row (each row's cells from the rectangle's extent in
    /// that row's band, a micrometre wider either way than the float cell bounds need).
    fn for_each_in_rows(&self, px: f64, py: f64, r: f64, rect: &Rect, mut f: impl FnMut(usize)) {
        const SLACK_M: f64 = 1e-6;
        let span = |lo: f64, hi: f64, n: usize| self.span(lo, hi, n);
        let Some((ax, bx)) = span(px - r - self.x0, px + r - self.x0, self.nx) else {
            return;
        };
        let Some((ay, by)) = span(py - r - self.y0, py + r - self.y0, self.ny) else {
            return;
        };
        for cy in ay..=by {
            let band0 = self.y0 + cy as f64 * self.cell_m - SLACK_M;
            let band1 = self.y0 + (cy + 1) as f64 * self.cell_m + SLACK_M;
            let Some((x_lo, x_hi)) = rect.x_range(band0, band1) else {
                continue;
            };
            let Some((rx, sx)) = span(x_lo - SLACK_M - self.x0, x_hi + SLACK_M - self.x0, self.nx)
            else {
                continue;
            };
            let (lo_c, hi_c) = (rx.max(ax), sx.min(bx));
            if lo_c > hi_c {
                continue;
            }
            let row = cy * self.nx;
            let (lo, hi) = (
                self.starts[row + lo_c] as usize,
                self.starts[row + hi_c + 1] as usize,
            );
            for &i in &self.order[lo..hi] {
                f(i as usize);
            }
        }
    }

    /// [`PointGrid::for_each_within`] on this slab, `x`, `y` starting at its first point.
    fn for_each_within(
        &self,
        x: &[f64],
        y: &[f64],
        px: f64,
        py: f64,
        r: f64,
        mut f: impl FnMut(usize),
    ) {
        let span = |lo: f64, hi: f64, n: usize| self.span(lo, hi, n);
        let Some((ax, bx)) = span(px - r - self.x0, px + r - self.x0, self.nx) else {
            return;
        };
        let Some((ay, by)) = span(py - r - self.y0, py + r - self.y0, self.ny) else {
            return;
        };
        let r2 = r * r;
        for cy in ay..=by {
            let row = cy * self.nx;
            let (lo, hi) = (
                self.starts[row + ax] as usize,
                self.starts[row + bx + 1] as usize,
            );
            for &i in &self.order[lo..hi] {
                let i = i as usize;
                let dx = x[i] - px;
                let dy = y[i] - py;
                if dx * dx + dy * dy <= r2 {
                    f(i);
                }
            }
        }
    }
}

/// A convex quadrilateral (corners in order around it) for row-by-row cell ranges.
struct Rect {
    corners: [[f64; 2]; 4],
}

impl Rect {
    /// The extent in x of the part of the rectangle with `y` in `[y0, y1]`; `None` when
    /// that part is empty. Exact up to rounding: the part's corners are the rectangle's
    /// corners in the band and the points where its edges cross the band's lines.
    fn x_range(&self, y0: f64, y1: f64) -> Option<(f64, f64)> {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for k in 0..4 {
            let (p, q) = (self.corners[k], self.corners[(k + 1) % 4]);
            let (p, q) = if p[1] <= q[1] { (p, q) } else { (q, p) };
            if q[1] < y0 || p[1] > y1 {
                continue;
            }
            let dy = q[1] - p[1];
            let at = |v: f64| {
                if dy > 0.0 {
                    p[0] + (q[0] - p[0]) * ((v - p[1]) / dy).clamp(0.0, 1.0)
                } else {
                    p[0]
                }
            };
            for v in [at(p[1].max(y0)), at(q[1].min(y1))] {
                lo = lo.min(v);
                hi = hi.max(v);
            }
            if dy <= 0.0 {
                lo = lo.min(q[0]);
                hi = hi.max(q[0]);
            }
        }
        (lo <= hi).then_some((lo, hi))
    }
}

/// `v.floor()` without the libm call (x86-64 has no rounding instruction in its baseline):
/// the same value for every `v` (−0 comes back as +0), through an integer where `v` fits
/// one exactly.
fn floor(v: f64) -> f64 {
    if v.abs() < 4.0e15 {
        let t = v as i64 as f64;
        if t > v {
            t - 1.0
        } else {
            t
        }
    } else {
        v.floor()
    }
}

/// Calls `f(i)` for every bit `i` set in `bits`, ascending.
fn for_each_set(bits: &[u64], mut f: impl FnMut(usize)) {
    for (w, &word) in bits.iter().enumerate() {
        let mut b = word;
        while b != 0 {
            f(w * 64 + b.trailing_zeros() as usize);
            b &= b - 1;
        }
    }
}

/// Slabs of at least this many points are indexed on two threads: below it the second
/// thread's start costs more than it saves.
const HALVES_MIN_POINTS: usize = 1 << 16;

/// `(a(), b())`, side by side on rayon's pool when `two`.
fn both<A: Send, B: Send>(
    two: bool,
    a: impl FnOnce() -> A + Send,
    b: impl FnOnce() -> B + Send,
) -> (A, B) {
    if two {
        rayon::join(a, b)
    } else {
        (a(), b())
    }
}

/// The box and number of a run of points kept for a slab.
struct Bounds {
    x0: f64,
    y0: f64,
    x1: f64,
    y1: f64,
    count: usize,
}

impl Bounds {
    /// Marks in `bits` (the bitmap's words from point `from` on) the points of `x`, `y`
    /// from `from` with `keep(i)` true and finite coordinates, and returns their box.
    fn scan(
        x: &[f64],
        y: &[f64],
        from: usize,
        bits: &mut [u64],
        keep: impl Fn(usize) -> bool,
    ) -> Self {
        let mut b = Self {
            x0: f64::INFINITY,
            y0: f64::INFINITY,
            x1: f64::NEG_INFINITY,
            y1: f64::NEG_INFINITY,
            count: 0,
        };
        let n = x.len().min(y.len());
        let (from, to) = (from.min(n), (from + bits.len() * 64).min(n));
        for (j, (&px, &py)) in x[from..to].iter().zip(&y[from..to]).enumerate() {
            let i = from + j;
            if px.is_finite() && py.is_finite() && keep(i) {
                bits[(i - from) >> 6] |= 1 << (i & 63);
                // Finite values: a comparison and a select (one instruction each on
                // x86-64), where `f64::min` and `max` also handle NaN.
                b.x0 = if px < b.x0 { px } else { b.x0 };
                b.y0 = if py < b.y0 { py } else { b.y0 };
                b.x1 = if px > b.x1 { px } else { b.x1 };
                b.y1 = if py > b.y1 { py } else { b.y1 };
                b.count += 1;
            }
        }
        b
    }
}

/// Places every kept point (in `bits`, ascending; `cell_of` its cell) whose cell lies in
/// `cells`: at `at[c − cells.start]` in `order`, which begins at `base` of the whole
/// order, moving that position on.
fn scatter(
    bits: &[u64],
    cell_of: &[u32],
    cells: std::ops::Range<usize>,
    at: &mut [u32],
    order: &mut [u32],
    base: usize,
) {
    if cells.is_empty() {
        return;
    }
    let mut k = 0;
    for_each_set(bits, |i| {
        let c = cell_of[k] as usize;
        k += 1;
        if cells.contains(&c) {
            let p = &mut at[c - cells.start];
            order[*p as usize - base] = i as u32;
            *p += 1;
        }
    });
}

/// The cell of a point inside the grid's box: `⌊(v − v0) / cell⌋` on each axis, clamped to
/// the last cell. A multiplication by the reciprocal gives the same floor unless the
/// quotient lies within 10⁻⁶ of an integer (product and quotient differ by a few ulp,
/// far below that on any grid of fewer than 10⁹ cells a side); only then is the division
/// done, so every point lands in the cell the division puts it in.
struct CellOf {
    x0: f64,
    y0: f64,
    cell: f64,
    inv: f64,
    nx: usize,
    ny: usize,
}

impl CellOf {
    fn new(g: &Slab) -> Self {
        Self {
            x0: g.x0,
            y0: g.y0,
            cell: g.cell_m,
            inv: 1.0 / g.cell_m,
            nx: g.nx,
            ny: g.ny,
        }
    }

    /// `d ≥ 0` (inside the box), so truncation is the floor. Through `i64`, whose
    /// conversions to and from `f64` are single instructions (those of `u64` are not on
    /// x86-64); a quotient this large would be no grid's cell anyway.
    #[inline]
    fn axis(&self, d: f64, n: usize) -> usize {
        let q = d * self.inv;
        let k = q as i64;
        let frac = q - k as f64;
        let k = if frac > 1e-6 && frac < 1.0 - 1e-6 {
            k as usize
        } else {
            self.divided(d)
        };
        k.min(n - 1)
    }

    /// The division near a cell boundary, out of line: inlined, the compiler computes it
    /// for every point and selects the result (a `divsd` per axis and pass).
    #[cold]
    #[inline(never)]
    fn divided(&self, d: f64) -> usize {
        (d / self.cell) as usize
    }

    fn at(&self, x: f64, y: f64) -> usize {
        self.axis(y - self.y0, self.ny) * self.nx + self.axis(x - self.x0, self.nx)
    }

    /// The cell of every point set in `bits` (the bitmap's words from point `from` on),
    /// in order, into `out`.
    fn of_set(&self, x: &[f64], y: &[f64], from: usize, bits: &[u64], out: &mut [u32]) {
        let mut k = 0;
        for_each_set(bits, |j| {
            let i = from + j;
            out[k] = self.at(x[i], y[i]) as u32;
            k += 1;
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn disc_query_matches_brute_force() {
        // A 20 × 20 lattice at 0.05 m spacing, far from the origin as world data is.
        let mut x = Vec::new();
        let mut y = Vec::new();
        for j in 0..20 {
            for i in 0..20 {
                x.push(500_000.0 + i as f64 * 0.05);
                y.push(4_000_000.0 + j as f64 * 0.05);
            }
        }
        let g = PointGrid::build(&x, &y, 0.1, |i| i % 7 != 3);
        assert_eq!(g.len(), 400 - 57);
        let (px, py, r) = (500_000.33, 4_000_000.41, 0.12);
        let mut got = Vec::new();
        g.for_each_within(&x, &y, px, py, r, |i| got.push(i));
        let first = got.clone();
        got.sort();
        let want: Vec<usize> = (0..400)
            .filter(|&i| i % 7 != 3 && (x[i] - px).powi(2) + (y[i] - py).powi(2) <= r * r)
            .collect();
        assert_eq!(got, want);
        assert_eq!(g.cell_m(), 0.1);
        // The same order on every call.
        let mut again = Vec::new();
        g.for_each_within(&x, &y, px, py, r, |i| again.push(i));
        assert_eq!(again, first);
        // Points at 0.12 m: a disc of that radius on a 0.05 m lattice holds about
        // π·0.12²/0.05² ≈ 18 points.
        assert!((15..=22).contains(&want.len()), "{}", want.len());
    }

    #[test]
    fn cells_grow_when_the_box_is_large_and_answers_stay_exact() {
        // Two clusters 10 km apart: 0.1 m cells would be 10^10 cells.
        let x = vec![0.0, 0.05, 10_000.0, 10_000.05];
        let y = vec![0.0, 0.0, 10_000.0, 10_000.0];
        let g = PointGrid::build(&x, &y, 0.1, |_| true);
        assert!(g.cell_m() > 100.0);
        let mut got = Vec::new();
        g.for_each_within(&x, &y, 10_000.0, 10_000.0, 0.06, |i| got.push(i));
        assert_eq!(got, vec![2, 3]);
        got.clear();
        g.for_each_within(&x, &y, -5.0, 0.0, 1.0, |i| got.push(i));
        assert!(got.is_empty());
    }

    #[test]
    fn points_on_cell_boundaries_fall_where_the_division_puts_them() {
        // Coordinates at multiples of 0.1 m (0.1 is not exact in binary: k·0.1 lands a few
        // ulp either side of a boundary) far from the origin, and a scatter between them.
        let mut x = Vec::new();
        let mut y = Vec::new();
        for k in 0..400u32 {
            x.push(300_000.0 + f64::from(k % 20) * 0.1);
            y.push(5_000_000.0 + f64::from(k / 20) * 0.1);
            x.push(300_000.0 + f64::from(k.wrapping_mul(2_654_435_761) % 1_900) * 1e-3);
            y.push(5_000_000.0 + f64::from(k.wrapping_mul(40_503) % 1_900) * 1e-3);
        }
        let g = PointGrid::build(&x, &y, 0.1, |_| true);
        assert_eq!(g.cell_m(), 0.1);
        let (x0, y0) = (300_000.0, 5_000_000.0);
        let last = |v: &[f64], v0: f64| {
            let v1 = v.iter().copied().fold(v0, f64::max);
            ((v1 - v0) / 0.1).floor() as usize
        };
        let (lx, ly) = (last(&x, x0), last(&y, y0));
        let cell = |v: f64, v0: f64, l: usize| (((v - v0) / 0.1) as usize).min(l);
        // Every cell of the box in turn, row by row, indices ascending within a cell.
        let mut want: Vec<usize> = (0..x.len()).collect();
        want.sort_by_key(|&i| (cell(y[i], y0, ly), cell(x[i], x0, lx), i));
        let mut got = Vec::new();
        g.for_each_within(&x, &y, x0 + 1.0, y0 + 1.0, 5.0, |i| got.push(i));
        assert_eq!(got, want);
    }

    #[test]
    fn floor_is_the_floor() {
        for v in [
            -2.5,
            -1.0,
            -0.999,
            -1e-300,
            0.0,
            1e-300,
            0.5,
            1.0,
            7.999_999_999,
            4.5e15,
            -4.5e15,
            1e300,
            -1e300,
        ] {
            assert_eq!(floor(v), v.floor(), "{v}");
        }
        assert!(floor(f64::NAN).is_nan());
        assert_eq!(floor(f64::NEG_INFINITY), f64::NEG_INFINITY);
    }

    #[test]
    fn a_rebuilt_grid_is_the_grid_built_afresh() {
        // One grid rebuilt over clouds larger, smaller and empty in turn answers every
        // query as a grid built for that cloud alone, in the same order.
        let cloud = |n: u32, seed: u32| -> (Vec<f64>, Vec<f64>) {
            let x = (0..n)
                .map(|k| 600_000.0 + f64::from(k.wrapping_mul(seed) % 4_001) * 1e-3)
                .collect();
            let y = (0..n)
                .map(|k| 4_000_000.0 + f64::from(k.wrapping_mul(40_503 ^ seed) % 2_999) * 1e-3)
                .collect();
            (x, y)
        };
        let mut g = PointGrid::build(&[], &[], 0.1, |_| true);
        for (n, seed) in [(5_000, 2_654_435_761), (700, 97), (0, 1), (12_000, 31_337)] {
            let (x, y) = cloud(n, seed);
            let keep = |i: usize| i % 5 != 2;
            g.rebuild(&x, &y, 0.1, keep);
            let fresh = PointGrid::build(&x, &y, 0.1, keep);
            assert_eq!(g.len(), fresh.len());
            assert_eq!(g.cell_m(), fresh.cell_m());
            for q in 0..20u32 {
                let (px, py) = (
                    600_000.0 + f64::from(q) * 0.2,
                    4_000_000.0 + f64::from(q % 7) * 0.4,
                );
                let (mut a, mut b) = (Vec::new(), Vec::new());
                g.for_each_within(&x, &y, px, py, 0.3, |i| a.push(i));
                fresh.for_each_within(&x, &y, px, py, 0.3, |i| b.push(i));
                assert_eq!(a, b);
                assert!(a.iter().all(|&i| keep(i)));
                assert!(n < 5_000 || !a.is_empty());
            }
        }
    }

    #[test]
    fn a_slid_grid_answers_as_a_grid_built_afresh() {
        // A stream of points along x (10 per metre, two lanes), seen through overlapping
        // windows of 80 points that start 60 points apart, every third point left out.
        let n = 400usize;
        let x: Vec<f64> = (0..n).map(|k| 700_000.0 + k as f64 * 0.1).collect();
        let y: Vec<f64> = (0..n)
            .map(|k| 3_000_000.0 + (k % 2) as f64 * 0.07)
            .collect();
        let keep = |g: usize| g % 3 != 1;
        let mut g = PointGrid::build(&[], &[], 0.1, |_| false);
        let mut lo = 0;
        while lo < n {
            let hi = (lo + 80).min(n);
            let next = lo + 60;
            g.slide(
                &x[lo..hi],
                &y[lo..hi],
                lo as u64,
                Some(next - lo),
                0.1,
                |i| keep(lo + i),
            );
            // The shared 20 points stay in the slab the window before indexed.
            assert!(g.slab_count() <= 3, "{}", g.slab_count());
            let fresh = PointGrid::build(&x[lo..hi], &y[lo..hi], 0.1, |i| keep(lo + i));
            assert_eq!(g.len(), fresh.len());
            for q in (lo..hi).step_by(7) {
                let (mut a, mut b) = (Vec::new(), Vec::new());
                g.for_each_within(&x[lo..hi], &y[lo..hi], x[q], y[q], 0.35, |i| a.push(i));
                fresh.for_each_within(&x[lo..hi], &y[lo..hi], x[q], y[q], 0.35, |i| b.push(i));
                a.sort_unstable();
                b.sort_unstable();
                assert_eq!(a, b);
                assert!(!a.is_empty());
            }
            lo = next;
        }
        // A rebuild after a slide is one slab again.
        g.rebuild(&x, &y, 0.1, |_| true);
        assert_eq!((g.slab_count(), g.len()), (1, n));
    }

    #[test]
    fn a_rectangle_query_is_the_disc_query_cut_to_the_rectangle() {
        // A scatter around a point far from the origin; rectangles turned by many angles,
        // across cell sizes, in the disc query's order.
        let (x0, y0) = (455_000.0, 3_951_000.0);
        let mut x = Vec::new();
        let mut y = Vec::new();
        for k in 0..6_000u32 {
            x.push(x0 + f64::from(k.wrapping_mul(2_654_435_761) % 3_001) * 1e-3);
            y.push(y0 + f64::from(k.wrapping_mul(40_503) % 2_003) * 1e-3);
        }
        for cell in [0.1, 0.15, 0.37] {
            let g = PointGrid::build(&x, &y, cell, |i| i % 11 != 4);
            for q in 0..40u32 {
                let th = f64::from(q) * 0.157;
                let along = [th.cos(), th.sin()];
                let n = [-along[1], along[0]];
                let centre = [x0 + 1.5 + f64::from(q % 5) * 0.1, y0 + 1.0];
                let (ha, hc) = (0.3, 0.45);
                let r = f64::hypot(ha, hc);
                let mut want = Vec::new();
                g.for_each_within(&x, &y, centre[0], centre[1], r, |i| {
                    let d = [x[i] - centre[0], y[i] - centre[1]];
                    let a = d[0] * along[0] + d[1] * along[1];
                    let c = d[0] * n[0] + d[1] * n[1];
                    if a.abs() <= ha && c.abs() <= hc {
                        want.push((i, c, a));
                    }
                });
                let mut got = Vec::new();
                g.for_each_in_rect(&x, &y, centre, along, n, ha, hc, r, |i, c, a| {
                    got.push((i, c, a))
                });
                assert_eq!(got, want, "cell {cell}, angle {th}");
                assert!(want.len() > 50, "{}", want.len());
            }
        }
    }

    #[test]
    fn a_slab_indexed_in_halves_is_the_slab_indexed_on_one_thread() {
        // A scatter over a street's width with points left out and non-finite ones, so
        // that the halves' boxes and counts differ; odd lengths cut the bitmap's last word.
        for n in [HALVES_MIN_POINTS + 37, 3 * HALVES_MIN_POINTS + 1] {
            let x: Vec<f64> = (0..n as u32)
                .map(|k| 455_000.0 + f64::from(k.wrapping_mul(2_654_435_761) % 60_001) * 1e-3)
                .collect();
            let mut y: Vec<f64> = (0..n as u32)
                .map(|k| 3_951_000.0 + f64::from(k) * 1e-4 + f64::from(k % 7) * 0.3)
                .collect();
            y[n / 3] = f64::NAN;
            let keep = |i: usize| i % 13 != 5;
            let (mut one, mut two) = (Slab::default(), Slab::default());
            one.index_in(&x, &y, 0.1, keep, false);
            two.index_in(&x, &y, 0.1, keep, true);
            let kept = (0..n).filter(|&i| keep(i) && i != n / 3).count();
            assert_eq!(one.order.len(), kept);
            assert_eq!(one.order, two.order);
            assert_eq!(one.starts, two.starts);
            assert_eq!(
                (one.cell_m, one.x0, one.y0, one.x1, one.y1, one.nx, one.ny),
                (two.cell_m, two.x0, two.y0, two.x1, two.y1, two.nx, two.ny)
            );
            // Cells ascending, indices ascending within a cell.
            assert!(one.starts.windows(2).all(|w| w[0] <= w[1]));
            assert!(one.nx * one.ny > 1_000);
        }
    }

    #[test]
    fn empty_grid_answers_nothing() {
        let g = PointGrid::build(&[], &[], 0.1, |_| true);
        let mut n = 0;
        g.for_each_within(&[], &[], 0.0, 0.0, 1.0, |_| n += 1);
        assert_eq!(n, 0);
        assert_eq!(g.len(), 0);
    }
}
