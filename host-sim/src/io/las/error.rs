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
    /// The LAS version is not one this reader knows.
    #[error("{path}: LAS version {major}.{minor} is not supported; curbtrace reads LAS 1.0–1.4")]
    UnsupportedVersion {
        /// The file.
        path: PathBuf,
        /// Major version.
        major: u8,
        /// Minor version.
        minor: u8,
    },
    /// The header's point format byte names no LAS point format.
    #[error("{path}: the header's point format byte {byte} names no LAS point format (0–10, plus 128 for LAZ)")]
    BadFormat {
        /// The file.
        path: PathBuf,
        /// The point data record format byte.
        byte: u8,
    },
    /// The point records are shorter than their format's fields.
    #[error("{path}: point records of {record_len} bytes are too short for point format {format}, which needs {need} bytes")]
    ShortRecords {
        /// The file.
        path: PathBuf,
        /// The point data record format.
        format: u8,
        /// Record length in the header.
        record_len: u16,
        /// The format's length without extra bytes.
        need: u16,
    },
    /// A scale factor that is not a positive finite number, or an offset that is not finite.
    #[error("{path}: the header's {axis} {field} is {value}; {rule}")]
    BadTransform {
        /// The file.
        path: PathBuf,
        /// `x`, `y` or `z`.
        axis: char,
        /// `scale` or `offset`.
        field: &'static str,
        /// The value.
        value: f64,
        /// What it must be.
        rule: &'static str,
    },
    /// Fields that contradict each other, or data that does not decode.
    #[error("{path}: corrupt file: {what}")]
    Corrupt {
        /// The file.
        path: PathBuf,
        /// What contradicts what, and where.
        what: String,
    },
    /// A valid file that uses something this reader does not decode.
    #[error("{path}: {what}")]
    Unsupported {
        /// The file.
        path: PathBuf,
        /// What, and what to do about it.
        what: String,
    },
    /// The file is shorter than its header says: it ends inside the header, the VLRs, the
    /// point records or the extended VLRs.
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
