//! LAZ specifics, checked before the `laz` crate sees the file: the `laszip encoded` VLR
//! (its compressor, its items against the point record, its chunk size) and the chunk table
//! (where it is, how many chunks it claims), and the crate's errors as sentences.

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

/// What the `laszip encoded` VLR says, as far as the checks need it.
pub(super) struct LazLayout {
    /// Points per chunk; `None` for variable-size chunks.
    fixed_chunk_points: Option<u64>,
}

/// The `laszip encoded` VLR, checked before the `laz` crate uses it: present, a compressor
/// the crate decodes (the chunked ones, LASzip 2.0 and later), items whose sizes add up to
/// the header's point record length (the crate divides by that sum, and a zero sum panicked
/// in its parallel decompressor), and a fixed chunk of points that needs at most 1 GiB of
/// decompression buffer.
pub(super) fn check_laszip_vlr(
    path: &Path,
    head: &FileHead,
    vlrs: &[las::raw::Vlr],
) -> Result<LazLayout, LasError> {
    let corrupt = |what: String| LasError::Corrupt {
        path: path.to_path_buf(),
        what,
    };
    let unsupported = |what: String| LasError::Unsupported {
        path: path.to_path_buf(),
        what,
    };
    let Some(vlr) = laszip_vlr(vlrs) else {
        return Err(corrupt(
            "the point format says LAZ but the header has no 'laszip encoded' VLR".into(),
        ));
    };
    // The VLR's first field is the compressor type; the `laz` crate keeps it private and
    // refuses type 1 only when decoding starts, after reading a chunk table that type 1
    // files do not have.
    match vlr.data.get(..2).map(|b| u16::from_le_bytes([b[0], b[1]])) {
        Some(2 | 3) => {}
        Some(1) => {
            return Err(unsupported(
                "LAZ pointwise compression (LASzip 1.x) is not supported; recompress with laszip or PDAL"
                    .into(),
            ))
        }
        Some(0) => {
            return Err(corrupt(
                "the 'laszip encoded' VLR names compressor 0 (no compression) in a LAZ file".into(),
            ))
        }
        Some(t) => {
            return Err(corrupt(format!(
                "the 'laszip encoded' VLR names compressor type {t}, which LASzip does not define"
            )))
        }
        None => return Err(corrupt("the 'laszip encoded' VLR is empty".into())),
    }
    let laz_vlr = laz::LazVlr::from_buffer(&vlr.data).map_err(|e| match e {
        laz::LasZipError::UnsupportedLazItemVersion(item, version) => unsupported(format!(
            "LAZ item {item:?} compressed with version {version} is not supported"
        )),
        laz::LasZipError::IoError(_) => {
            corrupt("the 'laszip encoded' VLR ends before its item list does".into())
        }
        e => corrupt(format!(
            "the 'laszip encoded' VLR cannot be read: {}",
            laz_reason(&e)
        )),
    })?;
    let sizes: u64 = laz_vlr.items().iter().map(|it| u64::from(it.size())).sum();
    if sizes == 0 || sizes != u64::from(head.record_len) {
        return Err(corrupt(format!(
            "the LAZ items describe {sizes}-byte points but the header says {}-byte records",
            head.record_len
        )));
    }
    let fixed_chunk_points =
        (!laz_vlr.uses_variable_size_chunks()).then(|| u64::from(laz_vlr.chunk_size()));
    if let Some(chunk) = fixed_chunk_points {
        if chunk * sizes > MAX_CHUNK_BYTES {
            return Err(unsupported(format!(
                "LAZ chunks of {chunk} points of {sizes} bytes need more than 1 GiB each to decompress; recompress with smaller chunks (laszip -chunk_size)"
            )));
        }
    }
    Ok(LazLayout { fixed_chunk_points })
}

/// LAZ: the chunk table, checked before the `laz` crate reads it. The crate reserves a
/// `Vec` of as many 16-byte entries as the table claims (a 2^32-entry claim is a 60 GB
/// allocation); every chunk takes at least one byte between the point data start (plus its
/// 8-byte table offset) and the table, so more entries than those bytes cannot be true.
/// With fixed-size chunks the table must also hold the header's point count.
///
/// Locating the table mirrors `laz::laszip::ChunkTable::read_offset`: the offset at the
/// start of the point data, or, when the writer could not update it, in the file's last 8
/// bytes.
pub(super) fn check_laz_chunk_table(
    path: &Path,
    file: &mut File,
    head: &FileHead,
    layout: &LazLayout,
) -> Result<(), LasError> {
    let file_size = head.file_size;
    let io = |source| LasError::Io {
        path: path.to_path_buf(),
        source,
    };
    let corrupt = |what: String| LasError::Corrupt {
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
    if data_start.saturating_add(8) > file_size {
        return Err(LasError::Truncated {
            path: path.to_path_buf(),
            what: format!(
                "the file ends at byte {file_size}, before the LAZ chunk table offset at byte {data_start}"
            ),
        });
    }
    let mut table = read_u64_at(file, data_start)? as i64;
    if table <= data_start as i64 {
        table = read_u64_at(file, file_size - 8)? as i64;
        if table <= data_start as i64 {
            return Err(corrupt(
                "no LAZ chunk table: neither the start of the point data nor the end of the file gives its offset"
                    .into(),
            ));
        }
    }
    let table = table as u64;
    if table.saturating_add(8) > file_size {
        // Compressed points never take more room than uncompressed ones (plus the offset):
        // a table beyond that is not where a cut file lost it.
        let uncompressed_end = head
            .count
            .saturating_mul(u64::from(head.record_len))
            .saturating_add(data_start + 8);
        return Err(if table <= uncompressed_end {
            LasError::Truncated {
                path: path.to_path_buf(),
                what: format!(
                    "the file ends at byte {file_size}, before the LAZ chunk table at byte {table}"
                ),
            }
        } else {
            corrupt(format!(
                "the LAZ chunk table offset (byte {table}) lies past the end of the {file_size}-byte file and past where even uncompressed points would end"
            ))
        });
    }
    let chunks = read_u64_at(file, table)? >> 32;
    let room = table.saturating_sub(data_start + 8);
    if chunks > room {
        return Err(corrupt(format!(
            "the LAZ chunk table claims {chunks} chunks but only {room} bytes of compressed points precede it"
        )));
    }
    if let Some(per_chunk) = layout.fixed_chunk_points {
        let holds = chunks.saturating_mul(per_chunk);
        if holds < head.count {
            return Err(corrupt(format!(
                "the header says {} points but the LAZ chunk table's {chunks} chunks of {per_chunk} points hold at most {holds}",
                head.count
            )));
        }
    }
    Ok(())
}

/// A `laz` crate error as a sentence without the crate's type names.
pub(super) fn laz_reason(e: &laz::LasZipError) -> String {
    use laz::LasZipError as E;
    match e {
        E::UnknownLazItem(t) => format!("an item of unknown type {t}"),
        E::UnsupportedLazItemVersion(item, v) => {
            format!("item {item:?} compressed with version {v}, which is not supported")
        }
        E::UnknownCompressorType(t) => format!("unknown compressor type {t}"),
        E::UnsupportedCompressorType(c) => format!("compressor {c:?} is not supported"),
        E::UnsupportedPointFormat(f) => format!("point format {f} is not supported by LAZ"),
        E::MissingChunkTable => "the chunk table is missing".into(),
        E::IoError(io) if io.to_string().contains("no chunks available") => {
            "the chunk table lists fewer points than the header".into()
        }
        E::IoError(io) if io.kind() == std::io::ErrorKind::UnexpectedEof => {
            "the compressed data ends before the points it should hold".into()
        }
        E::IoError(io) => io.to_string(),
        e => e.to_string(),
    }
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
