//! From bytes to scanlines: the byte ring and scanline assembly.
//!
//! [`Line`] is the hand-over point between assembly and the kernel: the assembler fills it
//! (structure of arrays, so the kernel can work in place and vectorise), the kernel
//! processes it in place.
//!
//! ```
//! use curbtrace_core::scanline::{Ingest, IngestEvent};
//! use curbtrace_core::wire::{PointRecord, StreamEncoder, MAX_PACKET_LEN};
//!
//! let mut enc = StreamEncoder::new();
//! let mut buf = [0u8; MAX_PACKET_LEN];
//! let pts: Vec<PointRecord> = (0..6)
//!     .map(|i| PointRecord {
//!         dt_ns: i * 1000,
//!         x_m: 1.0 - 0.1 * i as f32,
//!         z_m: -2.0,
//!         intensity: 0,
//!         line_start: i % 3 == 0, // two lines of three points
//!         tag: i,
//!     })
//!     .collect();
//! let n = enc.encode_points(1_000_000_000, &pts, &mut buf).unwrap();
//!
//! let mut ingest = Ingest::<2048, 256>::new();
//! assert_eq!(ingest.write(&buf[..n]), n); // a producer: DMA, UART, file reader
//! ingest.finish(); // end of stream: the last line becomes pollable
//! let mut lines = Vec::new();
//! while let Some(ev) = ingest.poll() {
//!     if let IngestEvent::Line(line) = ev {
//!         lines.push((line.index, line.start_time_ns, line.tag[..line.len()].to_vec()));
//!     }
//! }
//! assert_eq!(lines, [(0, 1_000_000_000, vec![0, 1, 2]), (1, 1_000_003_000, vec![3, 4, 5])]);
//! assert_eq!(ingest.counters().points_in_lines, 6);
//! ```

pub mod assemble;
mod ingest;
pub mod ring;

pub use assemble::{GeometrySplit, SplitParams, SplitReason};
pub use ingest::{Ingest, IngestCounters, IngestEvent};

/// One assembled scanline in structure-of-arrays form (docs/spec.md §2: points in
/// acquisition order, one revolution of the mirror). Filled by [`assemble::Assembler`], processed in place by
/// [`crate::kernel::Kernel`].
///
/// Capacity `N` is the largest number of points one line can hold (`MAX_POINTS`); points
/// beyond it are counted in [`Line::truncated`], never stored.
// `repr(C)` with the arrays last: the per-point fields (`len`, `truncated`) then sit at
// small offsets from the line's start, which a Cortex-M4F load or store reaches with an
// immediate offset; behind 24 KiB of arrays each access needs an extra instruction.
#[repr(C)]
pub struct Line<const N: usize> {
    /// Number of valid points (`0..=N`).
    pub len: usize,
    /// Scanline number in the stream (0, 1, 2, … in order of completion).
    pub index: u32,
    /// Points of this line that did not fit into `N` and were dropped (counted, not stored).
    pub truncated: u32,
    /// Absolute time of the first point, nanoseconds (the wire's time base).
    pub start_time_ns: u64,
    /// x′ in metres (signed lateral offset from the scanner, left positive).
    pub x_m: [f32; N],
    /// z′ in metres (height relative to the scanner origin).
    pub z_m: [f32; N],
    /// Pass-through tags from the wire, one per point, joining results to source points.
    pub tag: [u32; N],
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
        // `len` read once: re-read after each store (it might alias them, for all the
        // compiler knows once this is inlined) it cost a load and a bounds check each.
        let i = self.len;
        if i >= N {
            self.truncated = self.truncated.saturating_add(1);
            return Err((x_m, z_m, tag));
        }
        self.x_m[i] = x_m;
        self.z_m[i] = z_m;
        self.tag[i] = tag;
        self.len = i + 1;
        Ok(())
    }
}

impl<const N: usize> Default for Line<N> {
    fn default() -> Self {
        Self::new()
    }
}
