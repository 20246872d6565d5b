//! Replay: a LAS file and its trajectory through exactly the core the scanner runs.
//!
//! - [`project`] — step (a), Eq. 1–2, in `f64`: world points to the scanner's x′–z′ plane.
//! - [`line_start`] — where scanlines start (scan angle wrapping, or time and line period).
//! - [`run`] — the points encoded into the wire format (config packet first) and pushed
//!   through the core's ingest and kernel in-process, collecting per source point the core's
//!   ρ, status and scanline, and its seed candidates.

use crate::model::Side;

pub use curbtrace_core::kernel::PointStatus;

pub mod line_start;
pub mod project;
pub mod run;

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
