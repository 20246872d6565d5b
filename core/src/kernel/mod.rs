//! The per-scanline kernel (Honma et al. §2.3–2.6): bend angle ρ, removal of irregular
//! points, Taubin smoothing, ρ again on the smoothed line, peaks, and the first peak on each
//! side of the nadir as that side's seed candidate.
//!
//! SKELETON: the interface below is fixed (host-sim and firmware build against it); the
//! bodies are filled in by the kernel work (issue 3).

use crate::scanline::Line;

mod params;
pub use params::{KernelParams, ParamsError, CONFIG_WORDS};

/// What happened to one input point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(u8)]
#[non_exhaustive]
pub enum PointStatus {
    /// Kept, smoothed, and has a bend angle on the smoothed line.
    Kept = 0,
    /// Removed as irregular (§2.4): |ρ| on the raw line above the threshold.
    Irregular = 1,
    /// Kept, but has no neighbour within d_b on one side, so no ρ (ρ reported as 0).
    NoNeighbour = 2,
}

/// Counters of one scanline (every point that entered is in exactly one of the
/// status counts).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct KernelCounters {
    /// Points that entered the kernel.
    pub points_in: u32,
    /// Points with status [`PointStatus::Kept`].
    pub kept: u32,
    /// Points with status [`PointStatus::Irregular`].
    pub irregular: u32,
    /// Points with status [`PointStatus::NoNeighbour`].
    pub no_neighbour: u32,
    /// Peaks found (§2.6).
    pub peaks: u32,
}

/// The kernel's result for one scanline, borrowed from the kernel's buffers (no copies).
/// Index `i` of every slice is input point `i` of the line.
pub struct ScanlineOutput<'a> {
    /// Scanline number in the stream.
    pub index: u32,
    /// Absolute time of the line's first point, nanoseconds.
    pub start_time_ns: u64,
    /// Hash of the [`KernelParams`] that produced this output.
    pub params_hash: u32,
    /// Per point: the pass-through tag.
    pub tag: &'a [u32],
    /// Per point: smoothed x′ in metres (raw x′ for irregular points).
    pub x_m: &'a [f32],
    /// Per point: smoothed z′ in metres (raw z′ for irregular points).
    pub z_m: &'a [f32],
    /// Per point: bend angle ρ in degrees on the smoothed line, (−180, 180]; 0 where the
    /// status is not [`PointStatus::Kept`].
    pub rho_deg: &'a [f32],
    /// Per point: what happened to it.
    pub status: &'a [PointStatus],
    /// Index of the nadir point (smallest |x′| with z′ < 0), if any.
    pub nadir: Option<u16>,
    /// Index of the left seed candidate (first peak outward from the nadir with x′ > 0).
    pub left: Option<u16>,
    /// Index of the right seed candidate (first peak outward from the nadir with x′ < 0).
    pub right: Option<u16>,
    /// Points of the line dropped by assembly because the line was over capacity.
    pub truncated: u32,
    /// Counters for this line.
    pub counters: KernelCounters,
}

/// The per-scanline kernel with its fixed-size working memory for lines of up to `N` points.
pub struct Kernel<const N: usize> {
    params: KernelParams,
    params_hash: u32,
}

impl<const N: usize> Kernel<N> {
    /// A kernel running `params`.
    pub fn new(params: KernelParams) -> Self {
        Self {
            params_hash: params.hash(),
            params,
        }
    }

    /// The parameters in force.
    pub fn params(&self) -> &KernelParams {
        &self.params
    }

    /// Processes one assembled line in place and returns the result borrowed from the
    /// kernel's buffers and the line.
    pub fn process<'a>(&'a mut self, line: &'a mut Line<N>) -> ScanlineOutput<'a> {
        let _ = (&self.params, self.params_hash, line);
        todo!("issue 3")
    }
}
