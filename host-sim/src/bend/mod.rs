//! The bend-angle method's host half (Honma et al. §2.6–2.7): seeding by RANSAC per
//! interval, tracking by the energy of Eq. 4–8, post-filters. SKELETON: filled in by
//! issue 4.

use crate::io::trajectory::Trajectory;
use crate::model::Side;

/// A seed candidate from the core: the first peak outward from the nadir on one side of
/// one scanline.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Candidate {
    /// Index into the point columns (the tag sent through the core).
    pub point: u32,
    /// Which side of the trajectory.
    pub side: Side,
    /// Scanline number.
    pub scanline: u32,
}

/// Status value meaning "kept, with a bend angle" (mirrors `curbtrace_core::kernel::PointStatus::Kept`).
pub const STATUS_KEPT: u8 = 0;
/// Status value for points that never reached the kernel (outside the trajectory, dropped).
pub const STATUS_NOT_PROCESSED: u8 = 255;

/// Everything the host half of the bend method reads. All slices are indexed by point
/// (the columns of `io::las_in`, sorted by time).
pub struct BendInput<'a> {
    /// World X, metres.
    pub x: &'a [f64],
    /// World Y, metres.
    pub y: &'a [f64],
    /// World Z, metres.
    pub z: &'a [f64],
    /// GPS time, seconds.
    pub t: &'a [f64],
    /// Bend angle on the smoothed scanline from the core, degrees (0 unless kept).
    pub rho_deg: &'a [f32],
    /// `PointStatus as u8` from the core, or [`STATUS_NOT_PROCESSED`].
    pub status: &'a [u8],
    /// Scanline number per point (`u32::MAX` when not processed).
    pub scanline: &'a [u32],
    /// The core's seed candidates.
    pub candidates: &'a [Candidate],
    /// The trajectory.
    pub trajectory: &'a Trajectory,
}
