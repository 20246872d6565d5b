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

use crate::io::las_in::{PointColumns, ScannerSelection};
use campaign::{Campaign, InputInfo, SourceError};
use external_sort::SortedRuns;

/// Points per batch handed downstream and per decoded slab: 2^17 points are a few LAZ
/// chunks for the parallel decoder and about 6 MB of columns.
pub const BATCH_POINTS: usize = 1 << 15;

/// A batch of points: the reader's columns, in time order, each point with its channel key.
pub type PointBatch = PointColumns;

/// A source of time-ordered batches: the files as they are, or their sorted runs.
pub enum Source {
    /// Files in time order.
    Files(Box<Campaign>),
    /// Files sorted through a temporary directory.
    Sorted(SortedRuns, Box<InputInfo>),
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
