//! Where a side street's leg may cross a line parallel to the route: a coarse raster of
//! the ground's mean height, read at a few points along the route, that tells the leg
//! search ([`super::leg_seed`]) where its profiles are worth trying.
//!
//! A leg's curb runs at a large angle to the route, so its step shows along the route's
//! direction: the mean heights just before and just after a point differ by the step, less
//! what the ground's own slope along the route gives. The raster is built once per call
//! over the band of the route that the leg search covers, one sum per cell, so that the
//! test at a point costs four lookups instead of a search of the points around it.

use super::profile::usable;
use super::BendInput;

/// Side of a raster cell, metres: a leg's toe lies within about this of the point tested,
/// and the cell must hold some returns 25 m from the scanner.
pub const CELL_M: f64 = 0.5;

/// Most cells the raster may hold: a band of the route wider than this (a trajectory that
/// spans kilometres in one window) gets no raster and no leg seeds.
const MAX_CELLS: usize = 4_000_000;

/// The ground's mean height per [`CELL_M`] cell over a rectangle of the plan.
pub struct HeightRaster {
    x0: f64,
    y0: f64,
    nx: usize,
    ny: usize,
    sum: Vec<f64>,
    count: Vec<u32>,
}

impl HeightRaster {
    /// The usable points of `input` within `[lo, hi]` (plan corners), summed per cell;
    /// `None` when the rectangle is empty, not finite or larger than [`MAX_CELLS`].
    pub fn build(input: &BendInput, lo: [f64; 2], hi: [f64; 2]) -> Option<Self> {
        if !(lo.iter().chain(&hi).all(|v| v.is_finite()) && hi[0] > lo[0] && hi[1] > lo[1]) {
            return None;
        }
        let nx = ((hi[0] - lo[0]) / CELL_M).ceil() as usize + 1;
        let ny = ((hi[1] - lo[1]) / CELL_M).ceil() as usize + 1;
        if nx.checked_mul(ny)? > MAX_CELLS {
            return None;
        }
        let mut r = HeightRaster {
            x0: lo[0],
            y0: lo[1],
            nx,
            ny,
            sum: vec![0.0; nx * ny],
            count: vec![0; nx * ny],
        };
        for i in 0..input.x.len().min(input.z.len()) {
            if !usable(input, i) || !input.z[i].is_finite() {
                continue;
            }
            if let Some(k) = r.cell(input.x[i], input.y[i]) {
                r.sum[k] += input.z[i];
                r.count[k] += 1;
            }
        }
        Some(r)
    }

    /// Index of the cell holding plan point (x, y), `None` outside the raster.
    fn cell(&self, x: f64, y: f64) -> Option<usize> {
        let (fx, fy) = ((x - self.x0) / CELL_M, (y - self.y0) / CELL_M);
        if !(fx >= 0.0 && fy >= 0.0) {
            return None;
        }
        let (ix, iy) = (fx as usize, fy as usize);
        (ix < self.nx && iy < self.ny).then_some(iy * self.nx + ix)
    }

    /// Mean height of the cell holding `p`, `None` without returns there.
    fn mean_at(&self, p: [f64; 2]) -> Option<f64> {
        let k = self.cell(p[0], p[1])?;
        (self.count[k] > 0).then(|| self.sum[k] / f64::from(self.count[k]))
    }

    /// The step in the ground's mean height across `centre` along `dir` (horizontal unit
    /// vector): the rise from one cell before to one cell after, less the rise the slope
    /// of the ground beyond them (two cells out on either side) gives over that length.
    /// `None` where any of the four cells holds no return.
    pub fn step_along(&self, centre: [f64; 2], dir: [f64; 2]) -> Option<f64> {
        let at = |k: f64| {
            self.mean_at([
                centre[0] + k * CELL_M * dir[0],
                centre[1] + k * CELL_M * dir[1],
            ])
        };
        let (b2, b1, a1, a2) = (at(-3.0)?, at(-1.0)?, at(1.0)?, at(3.0)?);
        let rise = a1 - b1;
        let slope = 0.5 * ((a2 - a1) + (b1 - b2));
        Some(rise - slope)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bend::fixture::KeptPoints;
    use crate::io::trajectory::Trajectory;

    /// Ground on a 6 % grade along +x, with a 0.1 m step up at x = 5 where `step`.
    fn ground(step: bool) -> KeptPoints {
        let (mut x, mut y, mut z) = (Vec::new(), Vec::new(), Vec::new());
        for i in 0..125 {
            for j in 0..25 {
                let px = 0.08 * f64::from(i);
                x.push(px);
                y.push(0.08 * f64::from(j));
                z.push(0.06 * px + if step && px >= 5.0 { 0.1 } else { 0.0 });
            }
        }
        KeptPoints::new(x, y, z)
    }

    #[test]
    fn a_step_shows_and_a_grade_does_not() {
        let traj = Trajectory::default();
        for (step, want) in [(true, 0.1), (false, 0.0)] {
            let pts = ground(step);
            let input = pts.input(&traj);
            let r = HeightRaster::build(&input, [0.0, 0.0], [10.0, 2.0]).expect("raster");
            let s = r.step_along([5.1, 1.0], [1.0, 0.0]).expect("returns");
            assert!((s - want).abs() < 0.02, "step {s}, want {want}");
        }
    }

    #[test]
    fn no_raster_for_a_band_too_large_or_empty() {
        let traj = Trajectory::default();
        let pts = ground(false);
        let input = pts.input(&traj);
        assert!(HeightRaster::build(&input, [0.0, 0.0], [1e5, 1e5]).is_none());
        assert!(HeightRaster::build(&input, [1.0, 0.0], [1.0, 2.0]).is_none());
        assert!(HeightRaster::build(&input, [0.0, f64::NAN], [1.0, 2.0]).is_none());
    }
}
