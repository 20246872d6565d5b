//! The variable-length records: every VLR between the header and the point data, read
//! through `las::raw::Vlr`, and the LAS 1.4 extended VLRs after the points, whose bounds
//! are checked without reading them.

use super::header::FileHead;
use super::LasError;
use std::fs::File;
use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::Path;

/// Bytes of a VLR's header (LAS 1.4 R15, Table 15).
const VLR_HEADER_LEN: u64 = 54;

/// An extended VLR's header (LAS 1.4 R15, Table 21): 60 bytes, its 64-bit record length at
/// bytes 20..28. The `las` crate sizes an EVLR's buffer by that field before reading it, so
/// the field is read here on its own.
mod evlr_field {
    pub const HEADER_LEN: u64 = 60;
    pub const RECORD_LEN: std::ops::Range<usize> = 20..28;
}

/// Reads the header's VLRs, in file order. Each must lie between the header and the point
/// data: one that reaches into the point data means the VLR count or a record length is
/// wrong (the file is corrupt, not short: the point data offset was checked against the
/// file's size before).
pub(super) fn read_vlrs(
    path: &Path,
    file: &mut File,
    head: &FileHead,
) -> Result<Vec<las::raw::Vlr>, LasError> {
    let io = |source| LasError::Io {
        path: path.to_path_buf(),
        source,
    };
    let end = u64::from(head.offset_to_point_data);
    let count = head.vlr_count;
    let corrupt = |i: u32, pos: u64| {
        LasError::Corrupt {
        path: path.to_path_buf(),
        what: format!(
            "the header counts {count} VLRs but VLR {i} at byte {pos} reaches past the start of the point data at byte {end}"
        ),
    }
    };
    let mut pos = u64::from(head.header_size);
    file.seek(SeekFrom::Start(pos)).map_err(io)?;
    let mut read = BufReader::new(&mut *file);
    let mut vlrs = Vec::new();
    for i in 0..count {
        if pos + VLR_HEADER_LEN > end {
            return Err(corrupt(i, pos));
        }
        // A record is at most 65 535 bytes; one that the file cannot hold reaches past the
        // point data too.
        let vlr = las::raw::Vlr::read_from(&mut read, false).map_err(|_| corrupt(i, pos))?;
        let vlr_end = pos + VLR_HEADER_LEN + u64::from(vlr.record_length_after_header);
        if vlr_end > end {
            return Err(corrupt(i, pos));
        }
        pos = vlr_end;
        vlrs.push(vlr);
    }
    Ok(vlrs)
}

/// LAS 1.4 extended VLRs: walks their headers and checks that every record lies inside the
/// file, before the `las` crate allocates a buffer of each record's claimed length.
pub(super) fn check_evlrs(path: &Path, file: &mut File, head: &FileHead) -> Result<(), LasError> {
    let Some((mut pos, count)) = head.evlrs else {
        return Ok(());
    };
    let file_size = head.file_size;
    let bad = |what: String| LasError::Truncated {
        path: path.to_path_buf(),
        what,
    };
    for i in 0..count {
        if pos
            .checked_add(evlr_field::HEADER_LEN)
            .is_none_or(|end| end > file_size)
        {
            return Err(bad(format!(
                "extended VLR {i} of {count} would start at byte {pos}, past the end of the {file_size}-byte file"
            )));
        }
        let mut h = [0u8; evlr_field::HEADER_LEN as usize];
        file.seek(SeekFrom::Start(pos))
            .and_then(|_| file.read_exact(&mut h))
            .map_err(|source| LasError::Io {
                path: path.to_path_buf(),
                source,
            })?;
        let mut len = [0u8; 8];
        len.copy_from_slice(&h[evlr_field::RECORD_LEN]);
        let len = u64::from_le_bytes(len);
        match (pos + evlr_field::HEADER_LEN).checked_add(len) {
            Some(end) if end <= file_size => pos = end,
            _ => {
                return Err(bad(format!(
                    "extended VLR {i} at byte {pos} claims {len} bytes, more than the {file_size}-byte file holds"
                )))
            }
        }
    }
    Ok(())
}
