//! The ring-to-scanline rule for spinning multi-beam lidars (docs/frames.md, *Rings as
//! scanlines*): every ring (one laser's revolution) is cut into a front and a rear
//! half-arc, each ordered along the arc and projected into the kernel's x′–z′ plane, so the
//! same core kernel that reads a profiler's scanline reads it.
//!
//! - [`sensor`] — per-sensor facts (rings, rate, azimuth step) and the kernel parameters
//!   set from them.
//! - [`arc`] — ring assembly, the half-arc cut with its pseudo-nadir, and the projection.
//! - [`run`] — half-arcs through the core, one line each.

pub mod arc;
pub mod run;
pub mod sensor;

pub use arc::{half_arcs, project, ArcCounters, ArcParams, Half, HalfArc};
pub use sensor::SensorModel;
