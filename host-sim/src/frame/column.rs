//! Whether something stands on a candidate: the points of the whole sweep (every ring) in
//! a small column around it (docs/frames.md, *Checking a candidate*).
//!
//! The ring's own points can pass under a vehicle's body (the lowest rings meet the road
//! beneath it, 0.2–0.3 m below the sills) or beside a post, so the ring alone does not
//! show what stands on the toe. Other rings do: the sweep's points are binned in a grid of
//! [`CELL_M`] cells, and the column test counts the points within a radius of the candidate
//! that stand more than a height above the road.

use crate::io::sweep::Sweep;

/// Grid cell size, metres.
pub const CELL_M: f32 = 0.25;

/// The sweep's points binned by (x, y) in a fixed box around the sensor (compressed rows:
/// the points of cell c are `idx[start[c]..start[c + 1]]`).
pub struct ColumnGrid {
    x0: f32,
    y0: f32,
    nx: usize,
    ny: usize,
    start: Vec<u32>,
    idx: Vec<u32>,
}

impl ColumnGrid {
    /// Bins the points of `s` with |x| ≤ `half_x`, |y| ≤ `half_y` metres and z above
    /// `z_min` (the lowest height any column test will ask about: the road's points need
    /// not be binned).
    pub fn new(s: &Sweep, half_x: f32, half_y: f32, z_min: f32) -> Self {
        let nx = ((2.0 * half_x / CELL_M).ceil() as usize).max(1);
        let ny = ((2.0 * half_y / CELL_M).ceil() as usize).max(1);
        let mut g = Self {
            x0: -half_x,
            y0: -half_y,
            nx,
            ny,
            start: vec![0; nx * ny + 1],
            idx: Vec::new(),
        };
        let cells: Vec<(u32, usize)> = (0..s.len())
            .filter(|&i| s.z[i] > z_min)
            .filter_map(|i| g.cell(s.x[i], s.y[i]).map(|c| (i as u32, c)))
            .collect();
        for &(_, c) in &cells {
            g.start[c + 1] += 1;
        }
        for c in 0..nx * ny {
            g.start[c + 1] += g.start[c];
        }
        let mut fill = g.start.clone();
        g.idx = vec![0; g.start[nx * ny] as usize];
        for &(i, c) in &cells {
            g.idx[fill[c] as usize] = i;
            fill[c] += 1;
        }
        g
    }

    fn cell(&self, x: f32, y: f32) -> Option<usize> {
        let (cx, cy) = ((x - self.x0) / CELL_M, (y - self.y0) / CELL_M);
        if cx < 0.0 || cy < 0.0 {
            return None;
        }
        let (cx, cy) = (cx as usize, cy as usize);
        (cx < self.nx && cy < self.ny).then_some(cx * self.ny + cy)
    }

    /// Points of `s` within `radius` (≤ [`CELL_M`]) of (x, y) horizontally and above
    /// `z_above` (≥ the grid's `z_min`).
    pub fn count_above(&self, s: &Sweep, x: f32, y: f32, radius: f32, z_above: f32) -> usize {
        let (cx, cy) = ((x - self.x0) / CELL_M, (y - self.y0) / CELL_M);
        if cx < 0.0 || cy < 0.0 {
            return 0;
        }
        let (cx, cy) = (cx as usize, cy as usize);
        let r2 = radius * radius;
        let mut n = 0;
        for gx in cx.saturating_sub(1)..=(cx + 1).min(self.nx - 1) {
            for gy in cy.saturating_sub(1)..=(cy + 1).min(self.ny - 1) {
                let c = gx * self.ny + gy;
                for &i in &self.idx[self.start[c] as usize..self.start[c + 1] as usize] {
                    let i = i as usize;
                    let (dx, dy) = (s.x[i] - x, s.y[i] - y);
                    if dx * dx + dy * dy <= r2 && s.z[i] > z_above {
                        n += 1;
                    }
                }
            }
        }
        n
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::sweep::SweepFormat;

    #[test]
    fn counts_the_points_above_within_the_radius() {
        let mut s = Sweep::with_capacity(SweepFormat::Kitti, 0);
        for k in 0..40 {
            let a = k as f32 * 0.157;
            s.push(
                5.0 + 0.2 * a.cos(),
                2.0 + 0.2 * a.sin(),
                -1.0 + 0.05 * k as f32,
                0.0,
                0,
            );
        }
        s.push(5.0, 2.6, 1.0, 0.0, 0); // outside the radius
        s.push(30.0, 2.0, 1.0, 0.0, 0); // outside the grid
        let g = ColumnGrid::new(&s, 20.0, 10.0, -0.52);
        // Points at or below z_min are not binned: k = 10..39 are.
        assert_eq!(g.count_above(&s, 5.0, 2.0, 0.25, -5.0), 30);
        // z from −1.0 to 0.95 in steps of 0.05: 19 points above 0.01.
        assert_eq!(g.count_above(&s, 5.0, 2.0, 0.25, 0.01), 19);
        assert_eq!(g.count_above(&s, 5.0, 2.0, 0.1, 0.01), 0);
        assert_eq!(g.count_above(&s, -25.0, 2.0, 0.25, -5.0), 0);
    }
}
