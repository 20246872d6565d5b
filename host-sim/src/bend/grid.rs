//! A uniform grid over world XY: the spatial index behind the local point set S of §2.7
//! and the post-filters' neighbourhood queries. Points are sorted by cell once
//! (4 bytes per point plus 12 bytes per occupied cell); a query visits only the cells the
//! disc touches, never the whole cloud.

/// Point indices bucketed by a square XY cell.
pub struct PointGrid {
    cell_m: f64,
    x0: f64,
    y0: f64,
    /// Occupied cell keys, ascending.
    keys: Vec<u64>,
    /// `starts[k]..starts[k + 1]` is cell `keys[k]`'s range in `order`.
    starts: Vec<u32>,
    /// Point indices, sorted by cell then index.
    order: Vec<u32>,
}

/// Offset that makes signed cell coordinates non-negative inside a key.
const BIAS: i64 = 1 << 31;

fn key(cx: i64, cy: i64) -> u64 {
    (((cy + BIAS) as u64) << 32) | ((cx + BIAS) as u64 & 0xffff_ffff)
}

impl PointGrid {
    /// Indexes the points `i` with `keep(i)` true, in cells of `cell_m` metres.
    pub fn build(x: &[f64], y: &[f64], cell_m: f64, keep: impl Fn(usize) -> bool) -> Self {
        let n = x.len().min(y.len());
        let mut x0 = f64::INFINITY;
        let mut y0 = f64::INFINITY;
        for i in 0..n {
            if keep(i) && x[i].is_finite() && y[i].is_finite() {
                x0 = x0.min(x[i]);
                y0 = y0.min(y[i]);
            }
        }
        let mut grid = Self {
            cell_m,
            x0: if x0.is_finite() { x0 } else { 0.0 },
            y0: if y0.is_finite() { y0 } else { 0.0 },
            keys: Vec::new(),
            starts: vec![0],
            order: Vec::new(),
        };
        let mut tagged: Vec<(u64, u32)> = (0..n)
            .filter(|&i| keep(i) && x[i].is_finite() && y[i].is_finite())
            .map(|i| {
                let (cx, cy) = grid.cell_of(x[i], y[i]);
                (key(cx, cy), i as u32)
            })
            .collect();
        tagged.sort_unstable();
        grid.order.reserve_exact(tagged.len());
        for (k, i) in tagged {
            if grid.keys.last() != Some(&k) {
                if !grid.keys.is_empty() {
                    grid.starts.push(grid.order.len() as u32);
                }
                grid.keys.push(k);
            }
            grid.order.push(i);
        }
        grid.starts.push(grid.order.len() as u32);
        if grid.keys.is_empty() {
            grid.starts = vec![0];
        }
        grid
    }

    fn cell_of(&self, x: f64, y: f64) -> (i64, i64) {
        let cx = ((x - self.x0) / self.cell_m).floor();
        let cy = ((y - self.y0) / self.cell_m).floor();
        (
            cx.clamp(-(BIAS as f64) + 1.0, BIAS as f64 - 1.0) as i64,
            cy.clamp(-(BIAS as f64) + 1.0, BIAS as f64 - 1.0) as i64,
        )
    }

    fn cell(&self, cx: i64, cy: i64) -> &[u32] {
        match self.keys.binary_search(&key(cx, cy)) {
            Ok(k) => &self.order[self.starts[k] as usize..self.starts[k + 1] as usize],
            Err(_) => &[],
        }
    }

    /// Calls `f(i)` for every indexed point within `r` (horizontal) of `(cx, cy)`, in a
    /// fixed order (cells row by row, indices ascending within a cell).
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
        let (ax, ay) = self.cell_of(px - r, py - r);
        let (bx, by) = self.cell_of(px + r, py + r);
        let r2 = r * r;
        for cy in ay..=by {
            for cx in ax..=bx {
                for &i in self.cell(cx, cy) {
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

    /// Number of indexed points.
    pub fn len(&self) -> usize {
        self.order.len()
    }

    /// Whether no point is indexed.
    pub fn is_empty(&self) -> bool {
        self.order.is_empty()
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
        got.sort();
        let want: Vec<usize> = (0..400)
            .filter(|&i| i % 7 != 3 && (x[i] - px).powi(2) + (y[i] - py).powi(2) <= r * r)
            .collect();
        assert_eq!(got, want);
        // Points at 0.12 m: a disc of that radius on a 0.05 m lattice holds about
        // π·0.12²/0.05² ≈ 18 points.
        assert!((15..=22).contains(&want.len()), "{}", want.len());
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
