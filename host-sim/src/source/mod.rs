//! Sources: time-ordered batches of points, each point with its channel key, from one or
//! many LAS/LAZ files read as one continuous stream.
//!
//! - [`files`] — the inputs of `curbtrace extract`: files, directories and glob patterns,
//!   expanded to a list of LAS/LAZ files.
//! - [`las_batches`] — one file decoded in batches through the `las` crate's byte-slab API
//!   (`fill_points` and the column getters), with the scanner selection of `io::las_in`.
//! - [`campaign`] — many files as one stream: ordered by their first GPS time, checked to
//!   stay in time order, and sorted chunk-wise through a temporary directory
//!   ([`external_sort`]) when they do not.
//!
//! A scanline that spans two files is one scanline: the stream is continuous and the core
//! sees no file boundary.

pub mod campaign;
pub mod external_sort;
pub mod files;
pub mod las_batches;

use crate::io::las_in::ScannerSelection;
use campaign::{Campaign, InputInfo, SourceError};
use external_sort::SortedRuns;

/// Points per batch handed downstream and per decoded slab: 2^17 points are a few LAZ
/// chunks for the parallel decoder and about 6 MB of columns.
pub const BATCH_POINTS: usize = 1 << 15;

/// A batch of points as columns, in time order. Index `i` of every column is point `i`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PointBatch {
    /// World X, LAS CRS, metres.
    pub x: Vec<f64>,
    /// World Y, LAS CRS, metres.
    pub y: Vec<f64>,
    /// World Z, metres.
    pub z: Vec<f64>,
    /// GPS time, seconds.
    pub t: Vec<f64>,
    /// Intensity as stored.
    pub intensity: Vec<u16>,
    /// Scan angle, degrees.
    pub scan_angle_deg: Vec<f32>,
    /// Channel key: the LAS 1.4 scanner channel (0 in legacy formats).
    pub channel: Vec<u8>,
}

impl PointBatch {
    /// An empty batch with room for `n` points.
    pub fn with_capacity(n: usize) -> Self {
        Self {
            x: Vec::with_capacity(n),
            y: Vec::with_capacity(n),
            z: Vec::with_capacity(n),
            t: Vec::with_capacity(n),
            intensity: Vec::with_capacity(n),
            scan_angle_deg: Vec::with_capacity(n),
            channel: Vec::with_capacity(n),
        }
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// True when there is no point.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// Appends point `i` of `o`.
    pub fn push_from(&mut self, o: &PointBatch, i: usize) {
        self.x.push(o.x[i]);
        self.y.push(o.y[i]);
        self.z.push(o.z[i]);
        self.t.push(o.t[i]);
        self.intensity.push(o.intensity[i]);
        self.scan_angle_deg.push(o.scan_angle_deg[i]);
        self.channel.push(o.channel[i]);
    }

    /// Appends the points `range` of `o`.
    pub fn extend_from(&mut self, o: &PointBatch, range: std::ops::Range<usize>) {
        self.x.extend_from_slice(&o.x[range.clone()]);
        self.y.extend_from_slice(&o.y[range.clone()]);
        self.z.extend_from_slice(&o.z[range.clone()]);
        self.t.extend_from_slice(&o.t[range.clone()]);
        self.intensity
            .extend_from_slice(&o.intensity[range.clone()]);
        self.scan_angle_deg
            .extend_from_slice(&o.scan_angle_deg[range.clone()]);
        self.channel.extend_from_slice(&o.channel[range]);
    }

    /// Removes the first `n` points.
    pub fn drain_front(&mut self, n: usize) {
        self.x.drain(..n);
        self.y.drain(..n);
        self.z.drain(..n);
        self.t.drain(..n);
        self.intensity.drain(..n);
        self.scan_angle_deg.drain(..n);
        self.channel.drain(..n);
    }

    /// True when the times never decrease.
    pub fn is_time_ordered(&self) -> bool {
        self.t.windows(2).all(|w| w[0] <= w[1])
    }
}

/// A source of time-ordered batches: the files as they are, or their sorted runs.
pub enum Source {
    /// Files in time order.
    Files(Box<Campaign>),
    /// Files sorted through a temporary directory.
    Sorted(SortedRuns, InputInfo),
}

impl Source {
    /// The next batch of up to about `max` points; `None` at the end.
    pub fn next_batch(&mut self, max: usize) -> Result<Option<PointBatch>, SourceError> {
        match self {
            Source::Files(c) => c.next_batch(max),
            Source::Sorted(s, _) => s.next_batch(max),
        }
    }

    /// Bytes of the inputs consumed so far (for the progress bar).
    pub fn bytes_done(&self) -> u64 {
        match self {
            Source::Files(c) => c.bytes_done(),
            Source::Sorted(s, info) => s.bytes_done(info.bytes),
        }
    }

    /// The inputs' header facts.
    pub fn info(&self) -> &InputInfo {
        match self {
            Source::Files(c) => c.info(),
            Source::Sorted(_, info) => info,
        }
    }

    /// The scanner selection in force.
    pub fn selection(&self) -> ScannerSelection {
        match self {
            Source::Files(c) => c.selection(),
            Source::Sorted(s, _) => s.selection,
        }
    }
}
