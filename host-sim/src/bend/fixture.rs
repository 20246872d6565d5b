//! Point columns for the unit tests of the bend modules: every point kept by the core with
//! no bend angle, borrowed as a [`BendInput`] with no candidates.

use super::BendInput;
use crate::io::trajectory::Trajectory;
use crate::replay::PointStatus;

/// The columns a test's [`BendInput`] borrows. `t` and `scanline` are zero unless a test
/// sets them (`KeptPoints { t, ..KeptPoints::new(x, y, z) }`).
pub(super) struct KeptPoints {
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    pub z: Vec<f64>,
    pub t: Vec<f64>,
    pub rho_deg: Vec<f32>,
    pub status: Vec<Option<PointStatus>>,
    pub scanline: Vec<u32>,
}

impl KeptPoints {
    /// Points at `x`, `y`, `z` (cut to the shortest), each kept, ρ = 0, at time 0 on
    /// scanline 0.
    pub fn new(mut x: Vec<f64>, mut y: Vec<f64>, mut z: Vec<f64>) -> Self {
        let n = x.len().min(y.len()).min(z.len());
        x.truncate(n);
        y.truncate(n);
        z.truncate(n);
        Self {
            x,
            y,
            z,
            t: vec![0.0; n],
            rho_deg: vec![0.0; n],
            status: vec![Some(PointStatus::Kept); n],
            scanline: vec![0; n],
        }
    }

    /// The points as the bend method's input along `trajectory`.
    pub fn input<'a>(&'a self, trajectory: &'a Trajectory) -> BendInput<'a> {
        BendInput {
            x: &self.x,
            y: &self.y,
            z: &self.z,
            t: &self.t,
            rho_deg: &self.rho_deg,
            status: &self.status,
            scanline: &self.scanline,
            candidates: &[],
            trajectory,
        }
    }
}
