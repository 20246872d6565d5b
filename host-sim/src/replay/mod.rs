//! Replay: a LAS file and its trajectory through exactly the core the scanner runs.
//!
//! - [`project`] — step (a), Eq. 1–2, in `f64`: world points to the scanner's x′–z′ plane.
//! - [`line_start`] — where scanlines start (scan angle wrapping, or time and line period).
//! - [`run`] — the points encoded into the wire format (config packet first) and pushed
//!   through the core's ingest and kernel in-process, collecting per source point the core's
//!   ρ, status and scanline, and its seed candidates.

pub mod line_start;
pub mod project;
pub mod run;
