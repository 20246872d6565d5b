//! The fixed LAS header, read through `las::raw::Header`, and the checks of its fields
//! against each other and against the file's size, made before anything is allocated from
//! them.

use super::LasError;
use std::fs::File;
use std::io::{BufReader, Read, Seek, SeekFrom};
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
    /// The point data record format byte as stored (bit 7 set for LAZ).
    pub format_byte: u8,
    /// Point data record format (the byte without its LAZ bits).
    pub format: u8,
    /// LAZ-compressed (bit 7 of the format byte).
    pub compressed: bool,
    /// Bytes per point record.
    pub record_len: u16,
    /// The legacy 32-bit point count.
    pub legacy_count: u64,
    /// The LAS 1.4 64-bit point count.
    pub large_count: Option<u64>,
    /// Points in the file: the LAS 1.4 64-bit count when set, else the legacy one.
    pub count: u64,
    /// Scale factors x, y, z.
    pub scale: [f64; 3],
    /// Offsets x, y, z.
    pub offset: [f64; 3],
    /// LAS 1.4 extended VLRs: (start of the first, how many).
    pub evlrs: Option<(u64, u32)>,
    /// Bytes in the file.
    pub file_size: u64,
}

/// Formats whose records carry GPS time.
pub fn format_has_gps_time(format: u8) -> bool {
    matches!(format, 1 | 3 | 4 | 5 | 6 | 7 | 8 | 9 | 10)
}

/// The two fields read before the `las` crate parses the header, so that a file is refused
/// for the first reason a reader would want to hear: not LAS at all, then a version this
/// reader does not know (the crate would read past the fields of an unknown version's
/// header and then report the end of the file instead).
mod field {
    use std::ops::Range;
    /// `LASF`.
    pub const SIGNATURE: Range<usize> = 0..4;
    /// Major and minor version.
    pub const VERSION: Range<usize> = 24..26;
}

/// Reads the fixed header at the start of `file` (`file_size` bytes): the signature, the
/// version, then the whole header through `las::raw::Header`.
pub(super) fn read_head(
    path: &Path,
    file: &mut File,
    file_size: u64,
) -> Result<FileHead, LasError> {
    let path_buf = || path.to_path_buf();
    let io = |source| LasError::Io {
        path: path_buf(),
        source,
    };
    if file_size == 0 {
        return Err(LasError::Empty { path: path_buf() });
    }
    let mut start = Vec::with_capacity(field::VERSION.end);
    file.seek(SeekFrom::Start(0)).map_err(io)?;
    (&mut *file)
        .take(field::VERSION.end as u64)
        .read_to_end(&mut start)
        .map_err(io)?;
    if start.get(field::SIGNATURE) != Some(b"LASF".as_slice()) {
        return Err(LasError::NotLas { path: path_buf() });
    }
    let version = start
        .get(field::VERSION)
        .map(|v| las::Version::new(v[0], v[1]));
    if let Some(v) = version {
        if v.major != 1 || v.minor > 4 {
            return Err(LasError::UnsupportedVersion {
                path: path_buf(),
                major: v.major,
                minor: v.minor,
            });
        }
    }
    file.seek(SeekFrom::Start(0)).map_err(io)?;
    let raw = match las::raw::Header::read_from(BufReader::new(&mut *file)) {
        Ok(raw) => raw,
        Err(las::Error::Io(e)) if e.kind() == std::io::ErrorKind::UnexpectedEof => {
            let size = match version {
                Some(v) => format!("{}-byte LAS {v}", v.header_size()),
                None => "LAS".into(),
            };
            return Err(LasError::Truncated {
                path: path_buf(),
                what: format!("the file ends after {file_size} bytes, inside the {size} header"),
            });
        }
        Err(las::Error::Io(source)) => return Err(io(source)),
        Err(e) => {
            return Err(LasError::Las {
                path: path_buf(),
                what: format!("reading the header: {e}"),
            })
        }
    };
    let legacy_count = u64::from(raw.number_of_point_records);
    let large_count = raw.large_file.map(|l| l.number_of_point_records);
    Ok(FileHead {
        version: (raw.version.major, raw.version.minor),
        header_size: raw.header_size,
        offset_to_point_data: raw.offset_to_point_data,
        vlr_count: raw.number_of_variable_length_records,
        format_byte: raw.point_data_record_format,
        format: raw.point_data_record_format & 0x3f,
        compressed: raw.point_data_record_format & 0x80 != 0,
        record_len: raw.point_data_record_length,
        legacy_count,
        large_count,
        count: match large_count {
            Some(large) if large > 0 => large,
            _ => legacy_count,
        },
        scale: [raw.x_scale_factor, raw.y_scale_factor, raw.z_scale_factor],
        offset: [raw.x_offset, raw.y_offset, raw.z_offset],
        evlrs: raw.evlr.map(|e| (e.start_of_first_evlr, e.number_of_evlrs)),
        file_size,
    })
}

/// The point format and what it lacks: a format number LAS defines, GPS time in its
/// records, and records at least as long as its fields.
pub(super) fn check_format(path: &Path, head: &FileHead) -> Result<las::point::Format, LasError> {
    let format = las::point::Format::new(head.format_byte)
        .ok()
        .filter(|f| f.to_u8().is_ok_and(|n| n == head.format))
        .ok_or(LasError::BadFormat {
            path: path.to_path_buf(),
            byte: head.format_byte,
        })?;
    if !format.has_gps_time {
        return Err(LasError::NoGpsTime {
            path: path.to_path_buf(),
            format: head.format,
        });
    }
    if head.record_len < format.len() {
        return Err(LasError::ShortRecords {
            path: path.to_path_buf(),
            format: head.format,
            record_len: head.record_len,
            need: format.len(),
        });
    }
    Ok(format)
}

/// The header's fields against each other: the two LAS 1.4 point counts, the scale and
/// offset of each axis, the point data after the header.
pub(super) fn check_consistency(path: &Path, head: &FileHead) -> Result<(), LasError> {
    // LAS 1.4 §2.4: the legacy count is 0 or equal to the 64-bit one. The `las` crate
    // decodes by the legacy count when it is not 0 and this reader sizes by the 64-bit one,
    // so a header where they disagree would be size-checked with one and decoded with the
    // other.
    if let Some(large) = head.large_count {
        if head.legacy_count > 0 && large > 0 && head.legacy_count != large {
            return Err(LasError::Corrupt {
                path: path.to_path_buf(),
                what: format!(
                    "the legacy point count ({}) and the LAS 1.4 point count ({large}) disagree",
                    head.legacy_count
                ),
            });
        }
    }
    for (k, axis) in ['x', 'y', 'z'].into_iter().enumerate() {
        let bad = |field, value, rule| LasError::BadTransform {
            path: path.to_path_buf(),
            axis,
            field,
            value,
            rule,
        };
        let scale = head.scale[k];
        if !(scale.is_finite() && scale > 0.0) {
            return Err(bad(
                "scale",
                scale,
                "a scale must be a positive finite number (every point would land on the offset or be undefined)",
            ));
        }
        if !head.offset[k].is_finite() {
            return Err(bad(
                "offset",
                head.offset[k],
                "an offset must be a finite number",
            ));
        }
    }
    if u32::from(head.header_size) > head.offset_to_point_data {
        return Err(LasError::Corrupt {
            path: path.to_path_buf(),
            what: format!(
                "the header puts the point data at byte {}, inside the {}-byte header",
                head.offset_to_point_data, head.header_size
            ),
        });
    }
    Ok(())
}

/// Where the point records lie against the file's size: the point data inside the file, at
/// least one point and at most [`MAX_POINTS`](super::MAX_POINTS), and (uncompressed) every
/// record the header counts inside the file.
/// Returns the number of bytes of point data (compressed for LAZ).
pub(super) fn check_point_data_bounds(path: &Path, head: &FileHead) -> Result<u64, LasError> {
    let file_size = head.file_size;
    if u64::from(head.offset_to_point_data) > file_size {
        return Err(LasError::Truncated {
            path: path.to_path_buf(),
            what: format!(
                "the header puts the point data at byte {} but the file ends at byte {file_size}",
                head.offset_to_point_data
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
    if !head.compressed {
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
    }
    if head.count > super::MAX_POINTS {
        return Err(LasError::TooMany {
            path: path.to_path_buf(),
            count: head.count,
            max: super::MAX_POINTS,
        });
    }
    Ok(point_bytes)
}
