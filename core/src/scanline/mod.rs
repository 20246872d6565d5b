//! From bytes to scanlines: the byte ring and scanline assembly.
//!
//! [`Line`] is the hand-over point between assembly and the kernel: the assembler fills it
//! (structure of arrays, so the kernel can work in place and vectorise), the kernel
//! processes it in place.

pub mod assemble;
mod ingest;
pub mod ring;

pub use assemble::{GeometrySplit, SplitParams, SplitReason};
pub use ingest::{Ingest, IngestCounters, IngestEvent};

/// One assembled scanline in structure-of-arrays form (SPEC §2: points in acquisition order,
/// one revolution of the mirror). Filled by [`assemble::Assembler`], processed in place by
/// [`crate::kernel::Kernel`].
///
/// Capacity `N` is the largest number of points one line can hold (`MAX_POINTS`); points
/// beyond it are counted in [`Line::truncated`], never stored.
pub struct Line<const N: usize> {
    /// x′ in metres (signed lateral offset from the scanner, left positive).
    pub x_m: [f32; N],
    /// z′ in metres (height relative to the scanner origin).
    pub z_m: [f32; N],
    /// Pass-through tags from the wire, one per point, joining results to source points.
    pub tag: [u32; N],
    /// Number of valid points (`0..=N`).
    pub len: usize,
    /// Scanline number in the stream (0, 1, 2, … in order of completion).
    pub index: u32,
    /// Absolute time of the first point, nanoseconds (the wire's time base).
    pub start_time_ns: u64,
    /// Points of this line that did not fit into `N` and were dropped (counted, not stored).
    pub truncated: u32,
}

impl<const N: usize> Line<N> {
    /// An empty line.
    pub const fn new() -> Self {
        Self {
            x_m: [0.0; N],
            z_m: [0.0; N],
            tag: [0; N],
            len: 0,
            index: 0,
            start_time_ns: 0,
            truncated: 0,
        }
    }

    /// Removes all points and resets the metadata.
    pub fn clear(&mut self) {
        self.len = 0;
        self.index = 0;
        self.start_time_ns = 0;
        self.truncated = 0;
    }

    /// Number of points held.
    pub fn len(&self) -> usize {
        self.len
    }

    /// True when the line holds no point.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Appends a point; hands it back when the line is full (and counts it as truncated).
    pub fn push(&mut self, x_m: f32, z_m: f32, tag: u32) -> Result<(), (f32, f32, u32)> {
        if self.len >= N {
            self.truncated = self.truncated.saturating_add(1);
            return Err((x_m, z_m, tag));
        }
        self.x_m[self.len] = x_m;
        self.z_m[self.len] = z_m;
        self.tag[self.len] = tag;
        self.len += 1;
        Ok(())
    }
}

impl<const N: usize> Default for Line<N> {
    fn default() -> Self {
        Self::new()
    }
}
