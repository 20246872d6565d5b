//! The fixed LAS header, read through `las::raw::Header`, and the checks of its fields
//! against each other and against the file's size, made before anything is allocated from
//! them.

use super::LasError;
use std::fs::File;
use std::io::{BufReader, Seek, SeekFrom};
use std::path::Path;

/// The header fields the reader uses, from `las::raw::Header`, with the LAS 1.4 point
/// count resolved.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct FileHead {
    /// LAS version `(major, minor)`.
    pub version: (u8, u8),
    /// Bytes of the fixed header (with any padding after it).
    pub header_size: u16,
    /// Where the point records start.
    pub offset_to_point_data: u32,
    /// Variable-length records in the header.
    pub vlr_count: u32,
    /// Point data record format, 0–10 (without the LAZ bits).
    pub format: u8,
    /// LAZ-compressed (bit 7, or bit 6 from older writers, of the format byte).
    pub compressed: bool,
    /// Bytes per point record.
    pub record_len: u16,
    /// Points in the file: the LAS 1.4 64-bit count, or the legacy one.
    pub count: u64,
    /// LAS 1.4 extended VLRs: (start of the first, how many).
    pub evlrs: Option<(u64, u32)>,
    /// Bytes in the file.
    pub file_size: u64,
}

/// Formats whose records carry GPS time.
pub fn format_has_gps_time(format: u8) -> bool {
    matches!(format, 1 | 3 | 4 | 5 | 6 | 7 | 8 | 9 | 10)
}

/// Reads the fixed header at the start of `file` (`file_size` bytes).
pub(super) fn read_head(
    path: &Path,
    file: &mut File,
    file_size: u64,
) -> Result<FileHead, LasError> {
    let path_buf = || path.to_path_buf();
    if file_size == 0 {
        return Err(LasError::Empty { path: path_buf() });
    }
    file.seek(SeekFrom::Start(0))
        .map_err(|source| LasError::Io {
            path: path_buf(),
            source,
        })?;
    let raw = match las::raw::Header::read_from(BufReader::new(&mut *file)) {
        Ok(raw) => raw,
        Err(las::Error::InvalidFileSignature(_)) => {
            return Err(LasError::NotLas { path: path_buf() })
        }
        Err(las::Error::Io(e)) if e.kind() == std::io::ErrorKind::UnexpectedEof => {
            // `read_from` checks the signature as soon as it has four bytes.
            if file_size < 4 {
                return Err(LasError::NotLas { path: path_buf() });
            }
            return Err(LasError::Truncated {
                path: path_buf(),
                what: format!("the file ends after {file_size} bytes, inside the LAS header"),
            });
        }
        Err(las::Error::Io(source)) => {
            return Err(LasError::Io {
                path: path_buf(),
                source,
            })
        }
        Err(e) => {
            return Err(LasError::Las {
                path: path_buf(),
                what: format!("reading the header: {e}"),
            })
        }
    };
    let version = (raw.version.major, raw.version.minor);
    let legacy_count = u64::from(raw.number_of_point_records);
    let mut count = legacy_count;
    if let Some(large) = raw.large_file {
        let large = large.number_of_point_records;
        // LAS 1.4 §2.4: the legacy count is 0 or equal to the 64-bit one. The `las` crate
        // decodes by the legacy count when it is not 0 and this reader sizes by the 64-bit
        // one, so a header where they disagree would be size-checked with one and decoded
        // with the other.
        if legacy_count > 0 && large > 0 && legacy_count != large {
            return Err(LasError::Truncated {
                path: path_buf(),
                what: format!(
                    "corrupt header: the legacy point count ({legacy_count}) and the LAS 1.4 point count ({large}) disagree"
                ),
            });
        }
        if large > 0 {
            count = large;
        }
    }
    let format_byte = raw.point_data_record_format;
    Ok(FileHead {
        version,
        header_size: raw.header_size,
        offset_to_point_data: raw.offset_to_point_data,
        vlr_count: raw.number_of_variable_length_records,
        // LASzip sets bit 7 (and older writers bit 6) of the format byte.
        format: format_byte & 0x3f,
        compressed: format_byte & 0xc0 != 0,
        record_len: raw.point_data_record_length,
        count,
        evlrs: raw.evlr.map(|e| (e.start_of_first_evlr, e.number_of_evlrs)),
        file_size,
    })
}

/// Where the point records lie against the file's size: the point data inside the file,
/// after the header, and (uncompressed) every record the header counts inside the file.
/// Returns how many points may be reserved before decoding.
pub(super) fn check_point_data_bounds(path: &Path, head: &FileHead) -> Result<u64, LasError> {
    let file_size = head.file_size;
    if u64::from(head.offset_to_point_data) > file_size
        || u64::from(head.header_size) > u64::from(head.offset_to_point_data)
    {
        return Err(LasError::Truncated {
            path: path.to_path_buf(),
            what: format!(
                "the header puts the point data at byte {} (header {} bytes) but the file has {} bytes",
                head.offset_to_point_data, head.header_size, file_size
            ),
        });
    }
    if head.count == 0 {
        return Err(LasError::NoPoints {
            path: path.to_path_buf(),
            what: "the header says the file holds no points".into(),
        });
    }
    let point_bytes = file_size - u64::from(head.offset_to_point_data);
    let reserve = if head.compressed {
        super::laz::laz_reserve_cap(head.count, point_bytes)
    } else {
        let need = head.count.saturating_mul(u64::from(head.record_len));
        if need > point_bytes {
            return Err(LasError::SizeMismatch {
                path: path.to_path_buf(),
                count: head.count,
                record_len: head.record_len,
                offset: head.offset_to_point_data,
                need: need.saturating_add(u64::from(head.offset_to_point_data)),
                size: file_size,
            });
        }
        head.count
    };
    if head.count > super::MAX_POINTS {
        return Err(LasError::TooMany {
            path: path.to_path_buf(),
            count: head.count,
            max: super::MAX_POINTS,
        });
    }
    Ok(reserve)
}
