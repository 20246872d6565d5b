//! Point decoding: the `las` crate's byte-slab API (`PointDataBuilder`,
//! `Reader::fill_points`, column getters) in batches of at most [`CHUNK_POINTS`] points,
//! never per-point `Point` structs (the slab path is about nine times faster).

use super::columns::{decode_all_parallel, PointColumns};
use super::header::FileHead;
use super::scanner::{channel_of, ScannerSelection, Selector};
use super::LasError;
use las::{PointData, PointDataBuilder, Reader, ReaderOptions};
use std::fs::File;
use std::io::BufReader;
use std::path::Path;

/// Points decoded per `fill_points` call: large enough for LAZ's parallel decoder (chunks of
/// typically 50 000 points spread over the cores), small enough that the byte slab (at most
/// 67 B per point for format 10 without extra bytes) stays a few tens of MB.
pub const CHUNK_POINTS: u64 = 1 << 18;

/// The byte slab of one `fill_points` call is at most this: a record can be up to 65 535
/// bytes long (extra bytes), and 2^18 of those would be 17 GB. Real files (20–67 B per
/// point) never reach it, so they still decode [`CHUNK_POINTS`] at a time.
const MAX_SLAB_BYTES: u64 = 64 << 20;

/// Opens the `las` crate's reader on a file whose header passed the checks.
pub(super) fn open_reader(path: &Path, head: &FileHead) -> Result<Reader, LasError> {
    let file = File::open(path).map_err(|source| LasError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    Reader::with_options(
        BufReader::with_capacity(1 << 20, file),
        ReaderOptions::default(),
    )
    .map_err(|e| las_error(path, head, e, "reading the header and VLRs"))
}

/// Decodes every point of `reader` and appends the ones `selector` keeps to `cols`;
/// `progress` is called with (points decoded so far, points in the file) after each batch.
/// Returns the number of points decoded.
pub(super) fn decode_points(
    path: &Path,
    head: &FileHead,
    reader: &mut Reader,
    selector: &mut Selector,
    cols: &mut PointColumns,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<u64, LasError> {
    let header = reader.header().clone();
    let total = header.number_of_points();
    let extended = header.point_format().is_extended;
    let mut pd: PointData = PointDataBuilder::new().for_header(&header).build();
    let record_len = pd.record_len();
    let mut done: u64 = 0;
    let batch = (MAX_SLAB_BYTES / record_len.max(1) as u64)
        .min(head.file_size / record_len.max(1) as u64 + 1)
        .clamp(1, CHUNK_POINTS);
    loop {
        let n = reader
            .fill_points(batch.min(total.saturating_sub(done)), &mut pd)
            .map_err(|e| {
                let stage = format!(
                    "decoding points {done}–{}",
                    done + batch.min(total.saturating_sub(done))
                );
                las_error(path, head, e, &stage)
            })?;
        if n == 0 {
            break;
        }
        let raw = pd.raw_bytes();
        let sel = selector.observe(path, raw, record_len)?;
        let Some(gps) = pd.gps_time() else {
            return Err(LasError::NoGpsTime {
                path: path.to_path_buf(),
                format: head.format,
            });
        };
        if sel == ScannerSelection::All {
            // Every point kept: fill the six columns in parallel straight from the slab.
            if let Some(k) = decode_all_parallel(raw, record_len, extended, pd.transforms(), cols) {
                return Err(LasError::BadTime {
                    path: path.to_path_buf(),
                    index: done + k as u64,
                    t: cols.t[cols.t.len() - n as usize + k],
                });
            }
        } else {
            let keep_rec = |rec: &[u8], psid: u16| match sel {
                ScannerSelection::All => true,
                ScannerSelection::Channel(c) => channel_of(rec) == c,
                ScannerSelection::PointSourceId(id) => psid == id,
            };
            let iter = raw
                .chunks_exact(record_len)
                .zip(pd.point_source_id())
                .zip(pd.x().zip(pd.y()).zip(pd.z()))
                .zip(gps.zip(pd.intensity()).zip(pd.scan_angle_degrees()));
            for (k, (((rec, psid), ((x, y), z)), ((t, i), sa))) in iter.enumerate() {
                if !keep_rec(rec, psid) {
                    continue;
                }
                if !t.is_finite() {
                    return Err(LasError::BadTime {
                        path: path.to_path_buf(),
                        index: done + k as u64,
                        t,
                    });
                }
                let ch = if extended { channel_of(rec) } else { 0 };
                cols.push(x, y, z, t, i, sa, ch);
            }
        }
        done += n;
        progress(done, total);
        if done >= total {
            break;
        }
    }
    if done < total {
        return Err(LasError::Corrupt {
            path: path.to_path_buf(),
            what: format!("the header says {total} points but the point data holds only {done}"),
        });
    }
    Ok(done)
}

/// Maps a `las` crate error while `stage` to a one-line message naming the file.
///
/// The checks before decoding have placed every byte the header promises inside the file:
/// the uncompressed records, or the LAZ chunk table after the compressed ones. So a LAZ
/// decoder error is corrupt data, named with the points it was decoding, and only an
/// uncompressed file can still end early (if it shrinks while being read).
fn las_error(path: &Path, head: &FileHead, e: las::Error, stage: &str) -> LasError {
    let path = path.to_path_buf();
    match e {
        las::Error::LasZipError(lz) => LasError::Corrupt {
            path,
            what: format!(
                "LAZ point data while {stage}: {}",
                super::laz::laz_reason(&lz)
            ),
        },
        las::Error::Io(io) if io.kind() == std::io::ErrorKind::UnexpectedEof => {
            if head.compressed {
                LasError::Corrupt {
                    path,
                    what: format!(
                        "LAZ point data while {stage}: the compressed data ends before the points it should hold"
                    ),
                }
            } else {
                LasError::Truncated {
                    path,
                    what: format!("the file ends while {stage}"),
                }
            }
        }
        las::Error::Io(source) => LasError::Io { path, source },
        e => LasError::Las {
            path,
            what: format!("{stage}: {e}"),
        },
    }
}
