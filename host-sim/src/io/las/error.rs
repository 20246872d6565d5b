//! What can be wrong with a point file, one variant per reason, each message one line
//! naming the file.

use std::path::PathBuf;

/// Errors reading a point file. Every message names the file and the problem.
#[derive(Debug, thiserror::Error)]
pub enum LasError {
    /// The file could not be opened or read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The file is zero bytes long.
    #[error("{path}: empty file (0 bytes), not a LAS/LAZ file")]
    Empty {
        /// The file.
        path: PathBuf,
    },
    /// The file does not start with the LAS signature `LASF`.
    #[error("{path}: not a LAS/LAZ file (no 'LASF' signature at the start)")]
    NotLas {
        /// The file.
        path: PathBuf,
    },
    /// The file ends inside the header, the VLRs, or the point records.
    #[error("{path}: truncated file: {what}")]
    Truncated {
        /// The file.
        path: PathBuf,
        /// Where it ends and what was expected.
        what: String,
    },
    /// The header's point count and offsets need more bytes than the file has.
    #[error("{path}: header says {count} points of {record_len} bytes from offset {offset} ({need} bytes), but the file has {size} bytes: truncated or corrupt header")]
    SizeMismatch {
        /// The file.
        path: PathBuf,
        /// Point count in the header.
        count: u64,
        /// Record length in the header.
        record_len: u16,
        /// Offset to the point data in the header.
        offset: u32,
        /// Bytes the header implies.
        need: u64,
        /// Bytes in the file.
        size: u64,
    },
    /// The point format has no GPS time, so points cannot be placed on the trajectory.
    #[error("{path}: point format {format} has no GPS time; curbtrace needs it to place points on the trajectory (use formats 1, 3, 4, 5 or 6–10)")]
    NoGpsTime {
        /// The file.
        path: PathBuf,
        /// The point data record format.
        format: u8,
    },
    /// The header says there are no points, or none is left after scanner selection.
    #[error("{path}: {what}")]
    NoPoints {
        /// The file.
        path: PathBuf,
        /// Which of the two.
        what: String,
    },
    /// More points than the core's `u32` tags can address.
    #[error("{path}: {count} points is more than the {max} one run can address; split the file")]
    TooMany {
        /// The file.
        path: PathBuf,
        /// Point count.
        count: u64,
        /// The limit, [`MAX_POINTS`](super::MAX_POINTS).
        max: u64,
    },
    /// Several scanner channels and no `--scanner`.
    #[error(
        "{path}: the file holds points of scanner channels {channels:?}; choose one with --scanner"
    )]
    SeveralScanners {
        /// The file.
        path: PathBuf,
        /// The channels present.
        channels: Vec<u8>,
    },
    /// A point has a non-finite GPS time.
    #[error("{path}: point {index} has GPS time {t}, not a finite number")]
    BadTime {
        /// The file.
        path: PathBuf,
        /// Index of the point in the file.
        index: u64,
        /// The time.
        t: f64,
    },
    /// The `las` crate rejected the header or the point data.
    #[error("{path}: {what}")]
    Las {
        /// The file.
        path: PathBuf,
        /// The crate's message with context.
        what: String,
    },
}
