//! Point columns, a straight drive and a profile for the unit tests of the bend modules:
//! every point kept by the core with no bend angle, borrowed as a [`BendInput`] with no
//! candidates.

use super::grid::PointGrid;
use super::params::BendParams;
use super::profile::Profile;
use super::BendInput;
use crate::io::trajectory::{Pose, Trajectory};
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

/// A drive east along y = 0 at 10 m/s, 2 m up, from x = −10 to 40 m (time `t0` at x = 0).
pub(super) fn drive_along_x(t0: f64) -> Trajectory {
    let samples = (-10..=40)
        .map(|k| Pose {
            t: t0 + 0.1 * f64::from(k),
            x: f64::from(k),
            y: 0.0,
            z: 2.0,
            roll_deg: 0.0,
            pitch_deg: 0.0,
            heading_deg: 90.0,
        })
        .collect();
    Trajectory { samples }
}

/// The profile through `centre` along +y, `half_l` either side, the curb rising towards +x
/// (`up` = −1).
pub(super) fn profile_along_y<'a>(
    input: &'a BendInput<'a>,
    grid: &'a PointGrid,
    params: &'a BendParams,
    centre: [f64; 3],
    half_l: f64,
) -> Profile<'a> {
    Profile {
        input,
        grid,
        params,
        centre,
        along: [0.0, 1.0],
        up: -1.0,
        half_l,
    }
}
