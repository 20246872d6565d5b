//! LAZ specifics, checked before the `laz` crate sees the file: the `laszip encoded` VLR
//! (its items against the point record, its chunk size) and the chunk table (where it is,
//! how many chunks it claims).

use super::header::FileHead;
use super::LasError;
use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::path::Path;

/// A fixed chunk of points must fit in this much decompression buffer.
const MAX_CHUNK_BYTES: u64 = 1 << 30;

/// How many points to reserve for a LAZ file of `compressed_bytes` point bytes whose header
/// claims `count`: a LAZ point takes at least a few bytes in practice (real MLS data 5–15 B),
/// so more than 4 points per compressed byte is taken as a wrong header and the columns grow
/// with the points actually decoded instead.
pub fn laz_reserve_cap(count: u64, compressed_bytes: u64) -> u64 {
    count.min(compressed_bytes.saturating_mul(4))
}

/// The `laszip encoded` VLR among `vlrs`, if any.
pub(super) fn laszip_vlr(vlrs: &[las::raw::Vlr]) -> Option<&las::raw::Vlr> {
    vlrs.iter().find(|v| {
        v.record_id == laz::LazVlr::RECORD_ID
            && v.user_id.starts_with(laz::LazVlr::USER_ID.as_bytes())
    })
}

/// The `laszip encoded` VLR's item list, checked before the `laz` crate uses it: the items'
/// sizes must add up to the header's point record length (the crate divides by that sum,
/// and a zero sum panicked in its parallel decompressor), and a fixed chunk of points must
/// not ask for more than 1 GiB of decompression buffer.
pub(super) fn check_laszip_vlr(
    path: &Path,
    head: &FileHead,
    vlrs: &[las::raw::Vlr],
) -> Result<(), LasError> {
    if !head.compressed {
        return Ok(());
    }
    let Some(vlr) = laszip_vlr(vlrs) else {
        return Ok(()); // the `las` crate reports it missing
    };
    let Ok(laz_vlr) = laz::LazVlr::from_buffer(&vlr.data) else {
        return Ok(()); // the `las` crate reports it unreadable
    };
    let bad = |what: String| LasError::Truncated {
        path: path.to_path_buf(),
        what,
    };
    let sizes: u64 = laz_vlr.items().iter().map(|it| u64::from(it.size())).sum();
    if sizes == 0 || sizes != u64::from(head.record_len) {
        return Err(bad(format!(
            "the LAZ items describe {sizes}-byte points but the header says {}-byte records",
            head.record_len
        )));
    }
    let chunk_size = u64::from(laz_vlr.chunk_size());
    if !laz_vlr.uses_variable_size_chunks() && chunk_size * sizes > MAX_CHUNK_BYTES {
        return Err(bad(format!(
            "the LAZ chunk size of {chunk_size} points of {sizes} bytes needs more than 1 GiB per chunk"
        )));
    }
    Ok(())
}

/// LAZ: the chunk table's entry count, checked against the compressed bytes before the
/// `laz` crate reserves a `Vec` of that many 16-byte entries (a 2^32-entry claim is a 60 GB
/// allocation). Every chunk takes at least one byte between the point data start (plus its
/// 8-byte table offset) and the table, so more entries than those bytes cannot be true.
/// Locating the table mirrors `laz::laszip::ChunkTable::read_offset`: the offset at the
/// start of the point data, or, when the writer could not update it, in the file's last 8
/// bytes.
pub(super) fn check_laz_chunk_table(
    path: &Path,
    file: &mut File,
    head: &FileHead,
) -> Result<(), LasError> {
    if !head.compressed {
        return Ok(());
    }
    let file_size = head.file_size;
    let io = |source| LasError::Io {
        path: path.to_path_buf(),
        source,
    };
    let bad = |what: String| LasError::Truncated {
        path: path.to_path_buf(),
        what,
    };
    let read_u64_at = |file: &mut File, pos: u64| -> Result<u64, LasError> {
        let mut b = [0u8; 8];
        file.seek(SeekFrom::Start(pos))
            .and_then(|_| file.read_exact(&mut b))
            .map_err(io)?;
        Ok(u64::from_le_bytes(b))
    };
    let data_start = u64::from(head.offset_to_point_data);
    if data_start.saturating_add(8) > file_size || file_size < 16 {
        // No room for the table offset: the `laz` crate reports the short read itself.
        return Ok(());
    }
    let mut table = read_u64_at(file, data_start)? as i64;
    if table <= data_start as i64 {
        table = read_u64_at(file, file_size - 8)? as i64;
        if table <= data_start as i64 {
            return Ok(()); // no chunk table: `laz` reports it missing
        }
    }
    let table = table as u64;
    if table.saturating_add(8) > file_size {
        return Err(bad(format!(
            "the LAZ chunk table would start at byte {table}, past the end of the {file_size}-byte file"
        )));
    }
    let chunks = read_u64_at(file, table)? >> 32;
    let room = table.saturating_sub(data_start + 8);
    if chunks > room {
        return Err(bad(format!(
            "the LAZ chunk table claims {chunks} chunks but only {room} bytes of compressed points precede it"
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn laz_reservation_is_capped_by_the_compressed_size() {
        assert_eq!(laz_reserve_cap(1_000_000_000_000, 1000), 4000);
        assert_eq!(laz_reserve_cap(10, 1000), 10);
    }
}
