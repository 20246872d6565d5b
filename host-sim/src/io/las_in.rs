//! LAS/LAZ input as columns (SPEC §3): every point format with GPS time (1, 3, 4, 5, 6–10),
//! any scale and offset, points in any order (sorted here by time, stably), one scanner
//! selected, and the file's CRS kept for the output.
//!
//! Points are decoded through the `las` crate's byte-slab API (`PointDataBuilder`,
//! `Reader::fill_points`, column getters) in chunks of [`CHUNK_POINTS`], never as per-point
//! `Point` structs (TOOLCHAIN.md: 7.3 M/s that way against 65 M/s for the slab).
//!
//! # Which points are one scanner
//!
//! SPEC §3: "default: all points are one scanner unless the file says otherwise". The rule:
//!
//! - Without `--scanner`: in the LAS 1.4 formats 6–10, if the scanner channel (two bits of
//!   the flags byte) takes more than one value, the file says there are several scanners and
//!   reading stops with an error listing the channels, so the user picks one. Otherwise
//!   (legacy formats, or one channel) every point is read. Point source ids are not looked
//!   at by default: in mobile data they usually number drive lines or strips, not scanners.
//! - With `--scanner ID`: in formats 6–10 whose scanner channel is not 0 everywhere, ID is
//!   the scanner channel (0–3); otherwise ID is the point source id.
//!
//! # Memory
//!
//! Columns: x, y, z, t as `f64` (32 B), intensity `u16` (2 B), scan angle `f32` (4 B):
//! 38 B per selected point. For uncompressed LAS the header's point count is checked
//! against the file size before anything is allocated, so the columns are reserved once at
//! their final size. For LAZ the count cannot be checked that way; the reservation is capped
//! by the compressed size (see [`laz_reserve_cap`]) and the columns grow only with points
//! actually decoded. Sorting, when needed, holds a `u32` permutation and one temporary
//! column (12 B per point) on top.

use crate::model::Crs;
use las::{PointData, PointDataBuilder, Reader, ReaderOptions};
use rayon::prelude::*;
use std::fs::File;
use std::io::{BufReader, Read};
use std::path::{Path, PathBuf};

/// Points decoded per `fill_points` call: large enough for LAZ's parallel decoder (chunks of
/// typically 50 000 points spread over the cores), small enough that the byte slab (at most
/// 67 B per point for format 10 without extra bytes) stays a few tens of MB.
pub const CHUNK_POINTS: u64 = 1 << 18;

/// The byte slab of one `fill_points` call is at most this: a record can be up to 65 535
/// bytes long (extra bytes), and 2^18 of those would be 17 GB (fuzz target `host_inputs`
/// found a 2 GB slab from a 8222-byte record). Real files (20–67 B per point) never reach
/// it, so they still decode [`CHUNK_POINTS`] at a time.
const MAX_SLAB_BYTES: u64 = 64 << 20;

/// The largest number of points one file may hand to the core: the wire's tag is the `u32`
/// index into the columns and `u32::MAX` means "not processed" downstream.
pub const MAX_POINTS: u64 = u32::MAX as u64 - 1;

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
        /// The limit, [`MAX_POINTS`].
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

/// Which scanner to read.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ReadOptions {
    /// `--scanner ID`: the scanner channel (formats 6–10 with channels in use) or the point
    /// source id (see the module docs); `None` reads every point.
    pub scanner: Option<u16>,
}

/// How the points were selected (for the summary).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ScannerSelection {
    /// Every point (no `--scanner`, at most one scanner channel in the file).
    All,
    /// Points of one LAS 1.4 scanner channel.
    Channel(u8),
    /// Points of one point source id.
    PointSourceId(u16),
}

/// What the file's header says, kept beside the columns.
#[derive(Clone, Debug, PartialEq)]
pub struct LasInfo {
    /// The file.
    pub path: PathBuf,
    /// LAS version `(major, minor)`.
    pub version: (u8, u8),
    /// Point data record format (0–10).
    pub point_format: u8,
    /// LAZ-compressed.
    pub compressed: bool,
    /// Points in the file (header count).
    pub points_in_file: u64,
    /// Points kept after scanner selection (the columns' length).
    pub points_selected: u64,
    /// How the points were selected.
    pub selection: ScannerSelection,
    /// The file's CRS: EPSG from the GeoTIFF keys, or the WKT VLR; `None` when absent.
    pub crs: Option<Crs>,
    /// Whether the points had to be reordered by time.
    pub was_reordered: bool,
    /// Whether the scan angle column carries information (not all one value).
    pub has_scan_angle: bool,
}

/// The selected points as columns, sorted by GPS time (stable: equal times keep file
/// order). Index `i` of every column is point `i`, the tag the core carries.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PointColumns {
    /// World X, LAS CRS, metres.
    pub x: Vec<f64>,
    /// World Y, LAS CRS, metres.
    pub y: Vec<f64>,
    /// World Z, metres.
    pub z: Vec<f64>,
    /// GPS time, seconds, in the file's time base, non-decreasing.
    pub t: Vec<f64>,
    /// Intensity as stored.
    pub intensity: Vec<u16>,
    /// Scan angle, degrees (legacy formats: whole degrees; 6–10: 0.006° steps).
    pub scan_angle_deg: Vec<f32>,
}

impl PointColumns {
    /// Number of points.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// True when there is no point.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// First and last time, or `None` when empty.
    pub fn time_range(&self) -> Option<(f64, f64)> {
        Some((*self.t.first()?, *self.t.last()?))
    }

    fn with_capacity(n: usize) -> Self {
        Self {
            x: Vec::with_capacity(n),
            y: Vec::with_capacity(n),
            z: Vec::with_capacity(n),
            t: Vec::with_capacity(n),
            intensity: Vec::with_capacity(n),
            scan_angle_deg: Vec::with_capacity(n),
        }
    }

    fn shrink_to_fit(&mut self) {
        self.x.shrink_to_fit();
        self.y.shrink_to_fit();
        self.z.shrink_to_fit();
        self.t.shrink_to_fit();
        self.intensity.shrink_to_fit();
        self.scan_angle_deg.shrink_to_fit();
    }

    /// Keeps the points `range` (the ones the trajectory covers: contiguous, as the columns
    /// are sorted by time), in place.
    pub fn keep_range(&mut self, range: std::ops::Range<usize>) {
        fn go<T>(v: &mut Vec<T>, r: &std::ops::Range<usize>) {
            v.truncate(r.end);
            v.drain(..r.start.min(v.len()));
        }
        go(&mut self.x, &range);
        go(&mut self.y, &range);
        go(&mut self.z, &range);
        go(&mut self.t, &range);
        go(&mut self.intensity, &range);
        go(&mut self.scan_angle_deg, &range);
    }

    /// Sorts by time, stably, if not sorted already. Returns true when it reordered.
    fn sort_by_time(&mut self) -> bool {
        if self.t.windows(2).all(|w| w[0] <= w[1]) {
            return false;
        }
        // Stable sort of a u32 permutation (rayon's par_sort_by is stable); then each
        // column is gathered through it with one temporary column at a time.
        let t = &self.t;
        let mut perm: Vec<u32> = (0..t.len() as u32).collect();
        perm.par_sort_by(|&a, &b| t[a as usize].total_cmp(&t[b as usize]));
        fn gather<T: Copy + Send + Sync>(v: &mut Vec<T>, perm: &[u32]) {
            let out: Vec<T> = perm.par_iter().map(|&i| v[i as usize]).collect();
            *v = out;
        }
        gather(&mut self.x, &perm);
        gather(&mut self.y, &perm);
        gather(&mut self.z, &perm);
        gather(&mut self.t, &perm);
        gather(&mut self.intensity, &perm);
        gather(&mut self.scan_angle_deg, &perm);
        true
    }
}

/// Formats whose records carry GPS time.
pub fn format_has_gps_time(format: u8) -> bool {
    matches!(format, 1 | 3 | 4 | 5 | 6 | 7 | 8 | 9 | 10)
}

/// How many points to reserve for a LAZ file of `compressed_bytes` point bytes whose header
/// claims `count`: a LAZ point takes at least a few bytes in practice (real MLS data 5–15 B),
/// so more than 4 points per compressed byte is taken as a wrong header and the columns grow
/// with the points actually decoded instead.
pub fn laz_reserve_cap(count: u64, compressed_bytes: u64) -> u64 {
    count.min(compressed_bytes.saturating_mul(4))
}

/// The fields of the fixed LAS header that the size checks need, parsed from the first 375
/// bytes (or fewer) without the `las` crate so nothing is allocated from unchecked values.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct RawHead {
    version: (u8, u8),
    header_size: u16,
    offset_to_point_data: u32,
    format: u8,
    compressed: bool,
    record_len: u16,
    count: u64,
}

/// LAS 1.4 extended VLRs: the `las` crate sizes each EVLR's buffer by its 64-bit length
/// field before reading it, so a corrupt length would allocate up to 2⁶⁴ bytes (found by the
/// `host_inputs` fuzz target). Walk the EVLR headers first and check that every record lies
/// inside the file.
fn check_evlrs(path: &Path, file: &mut File, head: &[u8], file_size: u64) -> Result<(), LasError> {
    use std::io::{Seek, SeekFrom};
    const EVLR_HEADER_LEN: u64 = 60;
    if head.len() < 247 || (head[24], head[25]) < (1, 4) {
        return Ok(());
    }
    let mut start = [0u8; 8];
    start.copy_from_slice(&head[235..243]);
    let mut pos = u64::from_le_bytes(start);
    let count = u32::from_le_bytes([head[243], head[244], head[245], head[246]]);
    let bad = |what: String| LasError::Truncated {
        path: path.to_path_buf(),
        what,
    };
    for i in 0..count {
        if pos
            .checked_add(EVLR_HEADER_LEN)
            .is_none_or(|end| end > file_size)
        {
            return Err(bad(format!(
                "extended VLR {i} of {count} would start at byte {pos}, past the end of the {file_size}-byte file"
            )));
        }
        let mut len = [0u8; 8];
        file.seek(SeekFrom::Start(pos + 20))
            .and_then(|_| file.read_exact(&mut len))
            .map_err(|source| LasError::Io {
                path: path.to_path_buf(),
                source,
            })?;
        let len = u64::from_le_bytes(len);
        match (pos + EVLR_HEADER_LEN).checked_add(len) {
            Some(end) if end <= file_size => pos = end,
            _ => {
                return Err(bad(format!(
                    "extended VLR {i} at byte {pos} claims {len} bytes, more than the {file_size}-byte file holds"
                )))
            }
        }
    }
    file.seek(SeekFrom::Start(0))
        .map_err(|source| LasError::Io {
            path: path.to_path_buf(),
            source,
        })?;
    Ok(())
}

/// LAZ: the `laszip encoded` VLR's item list, checked before the `laz` crate uses it: the
/// items' sizes must add up to the header's point record length (the crate divides by that
/// sum, and a zero sum panicked in its parallel decompressor — fuzz target `host_inputs`),
/// and a fixed chunk of points must not ask for more than 1 GiB of decompression buffer.
fn check_laszip_vlr(
    path: &Path,
    file: &mut File,
    head_bytes: &[u8],
    head: &RawHead,
    file_size: u64,
) -> Result<(), LasError> {
    use std::io::{Seek, SeekFrom};
    const VLR_HEADER_LEN: u64 = 54;
    if !head.compressed || head_bytes.len() < 104 {
        return Ok(());
    }
    let io = |source| LasError::Io {
        path: path.to_path_buf(),
        source,
    };
    let bad = |what: String| LasError::Truncated {
        path: path.to_path_buf(),
        what,
    };
    let vlrs = u32::from_le_bytes([
        head_bytes[100],
        head_bytes[101],
        head_bytes[102],
        head_bytes[103],
    ]);
    let end = u64::from(head.offset_to_point_data);
    let mut pos = u64::from(head.header_size);
    for i in 0..vlrs {
        if pos + VLR_HEADER_LEN > end {
            break;
        }
        if pos + VLR_HEADER_LEN > file_size {
            return Err(bad(format!(
                "the file ends at byte {file_size}, inside variable-length record {i} of {vlrs}"
            )));
        }
        let mut h = [0u8; VLR_HEADER_LEN as usize];
        file.seek(SeekFrom::Start(pos))
            .and_then(|_| file.read_exact(&mut h))
            .map_err(io)?;
        let record_id = u16::from_le_bytes([h[18], h[19]]);
        let len = u64::from(u16::from_le_bytes([h[20], h[21]]));
        if h[2..18].starts_with(b"laszip encoded") && record_id == 22204 {
            let mut body = vec![0u8; len as usize]; // at most 65 535 bytes
            if pos + VLR_HEADER_LEN + len > end
                || file.read_exact(&mut body).is_err()
                || body.len() < 34
            {
                break; // the `las` crate reports the short record itself
            }
            let chunk_size = u32::from_le_bytes([body[12], body[13], body[14], body[15]]);
            let items = usize::from(u16::from_le_bytes([body[32], body[33]]));
            let sizes: u32 = body[34..]
                .chunks_exact(6)
                .take(items)
                .map(|it| u32::from(u16::from_le_bytes([it[2], it[3]])))
                .sum();
            if sizes == 0 || sizes != u32::from(head.record_len) {
                return Err(bad(format!(
                    "the LAZ items describe {sizes}-byte points but the header says {}-byte records",
                    head.record_len
                )));
            }
            if chunk_size != u32::MAX && u64::from(chunk_size) * u64::from(sizes) > 1 << 30 {
                return Err(bad(format!(
                    "the LAZ chunk size of {chunk_size} points of {sizes} bytes needs more than 1 GiB per chunk"
                )));
            }
            break;
        }
        pos += VLR_HEADER_LEN + len;
    }
    file.seek(SeekFrom::Start(0)).map_err(io)?;
    Ok(())
}

/// LAZ: the chunk table's entry count, checked against the compressed bytes before the
/// `laz` crate reserves a `Vec` of that many 16-byte entries (fuzz target `host_inputs`
/// found a 2^32-entry claim: a 60 GB allocation). Every chunk takes at least one byte
/// between the point data start (plus its 8-byte table offset) and the table, so more
/// entries than those bytes cannot be true. Locating the table mirrors
/// `laz::laszip::ChunkTable::read_offset`: the offset at the start of the point data, or,
/// when the writer could not update it, in the file's last 8 bytes.
fn check_laz_chunk_table(
    path: &Path,
    file: &mut File,
    head: &RawHead,
    file_size: u64,
) -> Result<(), LasError> {
    use std::io::{Seek, SeekFrom};
    if !head.compressed {
        return Ok(());
    }
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
            file.seek(SeekFrom::Start(0)).map_err(io)?;
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
    file.seek(SeekFrom::Start(0)).map_err(io)?;
    Ok(())
}

fn parse_raw_head(path: &Path, bytes: &[u8], file_size: u64) -> Result<RawHead, LasError> {
    let path = path.to_path_buf();
    if file_size == 0 {
        return Err(LasError::Empty { path });
    }
    if bytes.len() < 4 || &bytes[0..4] != b"LASF" {
        return Err(LasError::NotLas { path });
    }
    // LAS 1.0–1.2 headers are 227 bytes; 1.3 235; 1.4 375.
    if bytes.len() < 227 {
        return Err(LasError::Truncated {
            path,
            what: format!(
                "the file ends after {} bytes, inside the 227-byte LAS header",
                bytes.len()
            ),
        });
    }
    let u16_at = |o: usize| u16::from_le_bytes([bytes[o], bytes[o + 1]]);
    let u32_at =
        |o: usize| u32::from_le_bytes([bytes[o], bytes[o + 1], bytes[o + 2], bytes[o + 3]]);
    let version = (bytes[24], bytes[25]);
    let header_size = u16_at(94);
    let offset_to_point_data = u32_at(96);
    let format_byte = bytes[104];
    let record_len = u16_at(105);
    let legacy_count = u64::from(u32_at(107));
    let mut count = legacy_count;
    if version >= (1, 4) {
        if bytes.len() < 375 {
            return Err(LasError::Truncated {
                path,
                what: format!(
                    "the file ends after {} bytes, inside the 375-byte LAS 1.4 header",
                    bytes.len()
                ),
            });
        }
        let mut b = [0u8; 8];
        b.copy_from_slice(&bytes[247..255]);
        let large = u64::from_le_bytes(b);
        // LAS 1.4 §2.4: the legacy count is 0 or equal to the 64-bit one. The `las` crate
        // reads the legacy count first and this reader the 64-bit one, so a header where
        // they disagree would be size-checked with one and decoded with the other (fuzz
        // target `host_inputs`: 1 checked, 16 777 217 decoded).
        if legacy_count > 0 && large > 0 && legacy_count != large {
            return Err(LasError::Truncated {
                path,
                what: format!(
                    "corrupt header: the legacy point count ({legacy_count}) and the LAS 1.4 point count ({large}) disagree"
                ),
            });
        }
        if large > 0 {
            count = large;
        }
    }
    Ok(RawHead {
        version,
        header_size,
        offset_to_point_data,
        // LASzip sets bit 7 (and older writers bit 6) of the format byte.
        format: format_byte & 0x3f,
        compressed: format_byte & 0xc0 != 0,
        record_len,
        count,
    })
}

/// The CRS of a header: EPSG from the GeoTIFF projected (else geodetic) key, or the WKT VLR.
pub fn header_crs(header: &las::Header) -> Option<Crs> {
    if let Some(bytes) = header.get_wkt_crs_bytes() {
        let wkt = String::from_utf8_lossy(bytes)
            .trim_end_matches('\0')
            .trim()
            .to_string();
        if !wkt.is_empty() {
            return Some(Crs::Wkt(wkt));
        }
    }
    let gt = header.get_geotiff_crs().ok().flatten()?;
    let code = gt
        .get_projected_crs_geo_key_value()
        .filter(|c| (1024..=32766).contains(c))
        .or_else(|| {
            gt.get_geodetic_crs_geo_key_value()
                .filter(|c| (1024..=32766).contains(c))
        })?;
    Some(Crs::Epsg(u32::from(code)))
}

/// What [`check_file`] learnt from a file's raw header.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CheckedHead {
    /// LAS version `(major, minor)`.
    pub version: (u8, u8),
    /// Point data record format (0–10).
    pub format: u8,
    /// LAZ-compressed.
    pub compressed: bool,
    /// Points the header announces.
    pub count: u64,
    /// Points to reserve columns for (see [`laz_reserve_cap`]).
    pub reserve: u64,
    /// Bytes of the file.
    pub file_bytes: u64,
}

/// Checks a file's header, VLRs and (for LAZ) chunk table before the `las` crate reads it:
/// signature, sizes, offsets and counts against the file's length, and a format with GPS
/// time. Every reader of point files calls this first.
pub fn check_file(path: &Path) -> Result<CheckedHead, LasError> {
    let io = |source| LasError::Io {
        path: path.to_path_buf(),
        source,
    };
    let mut file = File::open(path).map_err(io)?;
    let file_size = file.metadata().map_err(io)?.len();
    let mut head_bytes = Vec::with_capacity(375);
    (&mut file)
        .take(375)
        .read_to_end(&mut head_bytes)
        .map_err(io)?;
    let head = parse_raw_head(path, &head_bytes, file_size)?;
    check_evlrs(path, &mut file, &head_bytes, file_size)?;
    check_laszip_vlr(path, &mut file, &head_bytes, &head, file_size)?;
    check_laz_chunk_table(path, &mut file, &head, file_size)?;
    if !format_has_gps_time(head.format) {
        return Err(LasError::NoGpsTime {
            path: path.to_path_buf(),
            format: head.format,
        });
    }
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
        laz_reserve_cap(head.count, point_bytes)
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
    if head.count > MAX_POINTS {
        return Err(LasError::TooMany {
            path: path.to_path_buf(),
            count: head.count,
            max: MAX_POINTS,
        });
    }

    Ok(CheckedHead {
        version: head.version,
        format: head.format,
        compressed: head.compressed,
        count: head.count,
        reserve,
        file_bytes: file_size,
    })
}

/// Reads the selected points of a LAS/LAZ file as columns sorted by time.
///
/// `progress` is called with (points decoded so far, points in the file) after each chunk.
pub fn read_points(
    path: &Path,
    opts: &ReadOptions,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<(PointColumns, LasInfo), LasError> {
    let checked = check_file(path)?;
    let io = |source| LasError::Io {
        path: path.to_path_buf(),
        source,
    };
    let reserve = checked.reserve;
    let file_size = checked.file_bytes;
    let head = checked;
    let file = File::open(path).map_err(io)?;
    let las_err = |e: las::Error| las_error(path, e, "reading the header and VLRs");
    let mut reader = Reader::with_options(
        BufReader::with_capacity(1 << 20, file),
        ReaderOptions::default(),
    )
    .map_err(las_err)?;
    let header = reader.header().clone();
    let crs = header_crs(&header);
    let total = header.number_of_points();
    let format = header.point_format();
    let extended = format.is_extended;

    let mut cols = PointColumns::with_capacity(usize::try_from(reserve).unwrap_or(0));
    let mut pd: PointData = PointDataBuilder::new().for_header(&header).build();
    let record_len = pd.record_len();
    // Scanner channel: bits 4–5 of the flags byte at offset 15 (formats 6–10).
    let channel_of = |rec: &[u8]| (rec[15] >> 4) & 3;
    let mut channels_seen = [false; 4];
    // The selection rule needs to know whether channels are in use before keeping points,
    // so with `--scanner` on an extended format the first chunk decides: if any point of
    // the file uses a channel other than 0 the ID is a channel. A file whose first chunk
    // is all channel 0 but later chunks are not is handled by re-checking at the end.
    let mut selection: Option<ScannerSelection> = match (opts.scanner, extended) {
        (None, _) => Some(ScannerSelection::All),
        (Some(id), false) => Some(ScannerSelection::PointSourceId(id)),
        (Some(_), true) => None,
    };
    let mut done: u64 = 0;
    let chunk = (MAX_SLAB_BYTES / record_len.max(1) as u64)
        .min(file_size / record_len.max(1) as u64 + 1)
        .clamp(1, CHUNK_POINTS);
    loop {
        let n = reader
            .fill_points(chunk.min(total.saturating_sub(done)), &mut pd)
            .map_err(|e| las_error(path, e, &format!("decoding points after point {done}")))?;
        if n == 0 {
            break;
        }
        let raw = pd.raw_bytes();
        if extended {
            for rec in raw.chunks_exact(record_len) {
                channels_seen[usize::from(channel_of(rec))] = true;
            }
        }
        if selection.is_none() {
            let id = opts.scanner.unwrap_or(0);
            selection = Some(if channels_seen[1..].iter().any(|&c| c) {
                ScannerSelection::Channel(u8::try_from(id).ok().filter(|&c| c < 4).ok_or_else(
                    || LasError::NoPoints {
                        path: path.to_path_buf(),
                        what: format!("--scanner {id}: scanner channels are 0–3"),
                    },
                )?)
            } else {
                ScannerSelection::PointSourceId(id)
            });
        }
        let sel = selection.unwrap_or(ScannerSelection::All);
        let Some(gps) = pd.gps_time() else {
            return Err(LasError::NoGpsTime {
                path: path.to_path_buf(),
                format: head.format,
            });
        };
        if sel == ScannerSelection::All {
            // Every point kept: fill the six columns in parallel straight from the slab.
            let bad_t = decode_all_parallel(raw, record_len, extended, pd.transforms(), &mut cols);
            if let Some(k) = bad_t {
                return Err(LasError::BadTime {
                    path: path.to_path_buf(),
                    index: done + k as u64,
                    t: cols.t[cols.t.len() - n as usize + k],
                });
            }
            done += n;
            progress(done, total);
            if done >= total {
                break;
            }
            continue;
        }
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
            cols.x.push(x);
            cols.y.push(y);
            cols.z.push(z);
            cols.t.push(t);
            cols.intensity.push(i);
            cols.scan_angle_deg.push(sa);
        }
        done += n;
        progress(done, total);
        if done >= total {
            break;
        }
    }
    drop(pd);
    if done < total {
        return Err(LasError::Truncated {
            path: path.to_path_buf(),
            what: format!("the header says {total} points but only {done} could be decoded"),
        });
    }
    let channels: Vec<u8> = (0u8..4)
        .filter(|&c| channels_seen[usize::from(c)])
        .collect();
    let mut selection = selection.unwrap_or(ScannerSelection::All);
    if opts.scanner.is_none() && channels.len() > 1 {
        return Err(LasError::SeveralScanners {
            path: path.to_path_buf(),
            channels,
        });
    }
    if let (Some(id), ScannerSelection::PointSourceId(_)) = (opts.scanner, selection) {
        if extended && channels.iter().any(|&c| c != 0) {
            // Channels appeared only after the first chunk: the ID meant a channel. Re-read
            // is avoided by refusing clearly instead of silently mixing the two meanings.
            return Err(LasError::NoPoints {
                path: path.to_path_buf(),
                what: format!(
                    "--scanner {id}: scanner channels {channels:?} appear only late in the file; cannot tell channel from point source id"
                ),
            });
        }
        selection = ScannerSelection::PointSourceId(id);
    }
    if cols.is_empty() {
        return Err(LasError::NoPoints {
            path: path.to_path_buf(),
            what: match selection {
                ScannerSelection::All => "no points decoded".into(),
                ScannerSelection::Channel(c) => {
                    format!("no point of scanner channel {c} (--scanner {c})")
                }
                ScannerSelection::PointSourceId(id) => {
                    format!("no point with point source id {id} (--scanner {id})")
                }
            },
        });
    }
    cols.shrink_to_fit();
    let has_scan_angle = cols
        .scan_angle_deg
        .first()
        .is_some_and(|&a| cols.scan_angle_deg.iter().any(|&b| b != a));
    let was_reordered = cols.sort_by_time();
    let info = LasInfo {
        path: path.to_path_buf(),
        version: head.version,
        point_format: head.format,
        compressed: head.compressed,
        points_in_file: total,
        points_selected: cols.len() as u64,
        selection,
        crs,
        was_reordered,
        has_scan_angle,
    };
    Ok((cols, info))
}

/// Appends the `raw` records to `cols`, one column per rayon task, decoding the fields at
/// their LAS offsets (x, y, z at 0, 4, 8; intensity at 12; legacy formats: scan angle rank
/// i8 at 16, GPS time at 20; formats 6–10: scan angle i16 × 0.006° at 18, GPS time at 22).
/// Returns the index within `raw` of the first point whose time is not finite.
fn decode_all_parallel(
    raw: &[u8],
    record_len: usize,
    extended: bool,
    tr: &las::Vector<las::Transform>,
    cols: &mut PointColumns,
) -> Option<usize> {
    let n = raw.len() / record_len;
    let base = cols.len();
    let recs = || raw.chunks_exact(record_len);
    let i32_at = |r: &[u8], o: usize| i32::from_le_bytes([r[o], r[o + 1], r[o + 2], r[o + 3]]);
    let gps_at = if extended { 22 } else { 20 };
    cols.x.resize(base + n, 0.0);
    cols.y.resize(base + n, 0.0);
    cols.z.resize(base + n, 0.0);
    cols.t.resize(base + n, 0.0);
    cols.intensity.resize(base + n, 0);
    cols.scan_angle_deg.resize(base + n, 0.0);
    let mut bad_t = None;
    let PointColumns {
        x,
        y,
        z,
        t,
        intensity,
        scan_angle_deg,
    } = cols;
    rayon::scope(|s| {
        s.spawn(|_| {
            for (v, r) in x[base..].iter_mut().zip(recs()) {
                *v = tr.x.direct(i32_at(r, 0));
            }
        });
        s.spawn(|_| {
            for (v, r) in y[base..].iter_mut().zip(recs()) {
                *v = tr.y.direct(i32_at(r, 4));
            }
        });
        s.spawn(|_| {
            for (v, r) in z[base..].iter_mut().zip(recs()) {
                *v = tr.z.direct(i32_at(r, 8));
            }
        });
        s.spawn(|_| {
            for (v, r) in intensity[base..].iter_mut().zip(recs()) {
                *v = u16::from_le_bytes([r[12], r[13]]);
            }
            for (v, r) in scan_angle_deg[base..].iter_mut().zip(recs()) {
                *v = if extended {
                    f32::from(i16::from_le_bytes([r[18], r[19]])) * 0.006
                } else {
                    f32::from(r[16] as i8)
                };
            }
        });
        let bad = &mut bad_t;
        s.spawn(move |_| {
            for (k, (v, r)) in t[base..].iter_mut().zip(recs()).enumerate() {
                let mut b = [0u8; 8];
                b.copy_from_slice(&r[gps_at..gps_at + 8]);
                *v = f64::from_le_bytes(b);
                if !v.is_finite() && bad.is_none() {
                    *bad = Some(k);
                }
            }
        });
    });
    bad_t
}

/// Maps a `las` crate error to a one-line message naming the file, the stage, and whether
/// the file looks truncated.
fn las_error(path: &Path, e: las::Error, stage: &str) -> LasError {
    // Walk the cause chain: an unexpected end of file anywhere in it (LAS read_exact, or
    // the LAZ decoder's reader) means the file is shorter than its header says.
    let mut truncated = false;
    let mut cause: Option<&(dyn std::error::Error + 'static)> = Some(&e);
    while let Some(c) = cause {
        if let Some(io) = c.downcast_ref::<std::io::Error>() {
            truncated |= io.kind() == std::io::ErrorKind::UnexpectedEof;
        }
        cause = c.source();
    }
    // The LAZ decoder flattens its io::Error into its own type without a source.
    let text = e.to_string();
    truncated |= text.contains("failed to fill whole buffer") || text.contains("UnexpectedEof");
    if truncated {
        LasError::Truncated {
            path: path.to_path_buf(),
            what: format!("unexpected end of file while {stage}"),
        }
    } else {
        LasError::Las {
            path: path.to_path_buf(),
            what: format!("{stage}: {e}"),
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use las::{Builder, Point, Writer};

    /// Writes `points` to `path` in `format` (LAZ when the path ends in .laz).
    pub(crate) fn write_las(path: &Path, format: u8, points: &[Point], epsg: Option<u16>) {
        let mut b = Builder::from((1, 4));
        b.point_format = las::point::Format::new(format).unwrap();
        b.point_format.is_compressed = path.extension().is_some_and(|e| e == "laz");
        b.transforms = las::Vector {
            x: las::Transform {
                scale: 0.001,
                offset: 500_000.0,
            },
            y: las::Transform {
                scale: 0.001,
                offset: 4_000_000.0,
            },
            z: las::Transform {
                scale: 0.001,
                offset: 0.0,
            },
        };
        if let Some(code) = epsg {
            b.vlrs.push(geokey_vlr(code));
        }
        let header = b.into_header().unwrap();
        let mut w = Writer::from_path(path, header).unwrap();
        for p in points {
            w.write_point(p.clone()).unwrap();
        }
        w.close().unwrap();
    }

    /// A GeoKeyDirectory VLR with ProjectedCRSGeoKey (3072) = `code`.
    fn geokey_vlr(code: u16) -> las::Vlr {
        let words: [u16; 8] = [1, 1, 0, 1, 3072, 0, 1, code];
        let data = words.iter().flat_map(|w| w.to_le_bytes()).collect();
        las::Vlr {
            user_id: "LASF_Projection".into(),
            record_id: 34735,
            description: "GeoKeyDirectoryTag".into(),
            data,
        }
    }

    pub(crate) fn pt(x: f64, y: f64, z: f64, t: f64) -> Point {
        Point {
            x,
            y,
            z,
            gps_time: Some(t),
            intensity: 7,
            ..Default::default()
        }
    }

    fn read(path: &Path, scanner: Option<u16>) -> Result<(PointColumns, LasInfo), LasError> {
        read_points(path, &ReadOptions { scanner }, &mut |_, _| {})
    }

    /// Ten points 1 m and 1 s apart written as `name` (LAS or LAZ by its extension) in
    /// point format `format`; the path and the points.
    fn ten_points(dir: &Path, name: &str, format: u8) -> (PathBuf, Vec<Point>) {
        let path = dir.join(name);
        let pts: Vec<Point> = (0..10)
            .map(|i| pt(500_000.0 + i as f64, 4_000_000.0, 0.0, i as f64))
            .collect();
        write_las(&path, format, &pts, None);
        (path, pts)
    }

    /// Regression (fuzz target `host_inputs`, session 2): LAZ items whose sizes add up to 0
    /// made the `laz` crate's parallel decompressor divide by zero.
    #[test]
    fn laz_items_that_do_not_describe_the_point_record_are_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let (path, _) = ten_points(dir.path(), "items.laz", 6);
        let good = std::fs::read(&path).unwrap();
        let vlr = good
            .windows(14)
            .position(|w| w == b"laszip encoded")
            .expect("a laszip VLR")
            - 2;
        let body = vlr + 54;
        let items = usize::from(u16::from_le_bytes([good[body + 32], good[body + 33]]));
        assert!(items >= 1);
        for size in [0u16, 29] {
            let mut bytes = good.clone();
            for k in 0..items {
                let at = body + 34 + 6 * k + 2;
                let v = if k == 0 { size } else { 0 };
                bytes[at..at + 2].copy_from_slice(&v.to_le_bytes());
            }
            std::fs::write(&path, &bytes).unwrap();
            let err = read(&path, None).unwrap_err().to_string();
            assert!(
                err.contains("items.laz") && err.contains(&format!("describe {size}-byte points")),
                "{err}"
            );
        }
        std::fs::write(&path, &good).unwrap();
        assert_eq!(read(&path, None).unwrap().0.t.len(), 10);
    }

    /// Regression (fuzz target `host_inputs`, session 2): a LAS 1.4 header whose legacy and
    /// 64-bit point counts disagree was size-checked with one and decoded with the other.
    #[test]
    fn disagreeing_point_counts_are_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let (path, _) = ten_points(dir.path(), "counts.las", 1);
        let mut bytes = std::fs::read(&path).unwrap();
        assert_eq!(u32::from_le_bytes(bytes[107..111].try_into().unwrap()), 10);
        bytes[107..111].copy_from_slice(&16_777_217u32.to_le_bytes());
        std::fs::write(&path, &bytes).unwrap();
        let err = read(&path, None).unwrap_err().to_string();
        assert!(
            err.contains("counts.las") && err.contains("(16777217)") && err.contains("(10)"),
            "{err}"
        );
        // Legacy count 0 with the 64-bit count set is valid LAS 1.4.
        bytes[107..111].copy_from_slice(&0u32.to_le_bytes());
        std::fs::write(&path, &bytes).unwrap();
        assert_eq!(read(&path, None).unwrap().0.t.len(), 10);
    }

    /// Regression (fuzz target `host_inputs`, session 2): a LAZ chunk table claiming 2^32
    /// chunks made the `laz` crate reserve 60 GB before decoding a single entry.
    #[test]
    fn a_laz_chunk_table_claiming_more_chunks_than_bytes_is_an_error_before_any_allocation() {
        let dir = tempfile::tempdir().unwrap();
        let (path, _) = ten_points(dir.path(), "chunks.laz", 6);
        let good = std::fs::read(&path).unwrap();
        assert_eq!(read(&path, None).unwrap().0.t.len(), 10);
        let data_start = u32::from_le_bytes(good[96..100].try_into().unwrap()) as usize;
        let table = u64::from_le_bytes(good[data_start..data_start + 8].try_into().unwrap());
        let table = usize::try_from(table).unwrap();
        let mut bytes = good.clone();
        bytes[table + 4..table + 8].copy_from_slice(&u32::MAX.to_le_bytes());
        std::fs::write(&path, &bytes).unwrap();
        let err = read(&path, None).unwrap_err().to_string();
        assert!(
            err.contains("chunks.laz") && err.contains("chunk table claims 4294967295 chunks"),
            "{err}"
        );
        // A table offset past the end of the file.
        let mut bytes = good.clone();
        bytes[data_start..data_start + 8].copy_from_slice(&(1u64 << 40).to_le_bytes());
        std::fs::write(&path, &bytes).unwrap();
        let err = read(&path, None).unwrap_err().to_string();
        assert!(err.contains("past the end"), "{err}");
    }

    /// Regression (fuzz target `host_inputs`): an EVLR whose 64-bit length exceeds the file
    /// made the `las` crate try to allocate that many bytes.
    #[test]
    fn an_extended_vlr_longer_than_the_file_is_an_error_before_any_allocation() {
        let dir = tempfile::tempdir().unwrap();
        let (path, pts) = ten_points(dir.path(), "evlr.las", 6);
        let mut bytes = std::fs::read(&path).unwrap();
        let end = bytes.len() as u64;
        // One EVLR right after the points, claiming 2^62 bytes.
        bytes[235..243].copy_from_slice(&end.to_le_bytes());
        bytes[243..247].copy_from_slice(&1u32.to_le_bytes());
        let mut evlr = vec![0u8; 60];
        evlr[20..28].copy_from_slice(&(1u64 << 62).to_le_bytes());
        bytes.extend_from_slice(&evlr);
        std::fs::write(&path, &bytes).unwrap();
        let err = read(&path, None).unwrap_err().to_string();
        assert!(
            err.contains("evlr.las") && err.contains("extended VLR"),
            "{err}"
        );
        // The same file with an honest EVLR length reads.
        bytes[end as usize + 20..end as usize + 28].copy_from_slice(&0u64.to_le_bytes());
        std::fs::write(&path, &bytes).unwrap();
        assert_eq!(read(&path, None).unwrap().0.t.len(), 10);
        // An EVLR as the `las` crate writes it, with a description (the length field is at
        // byte 20 of the EVLR header, the description after it), reads.
        let mut b = Builder::from((1, 4));
        b.point_format = las::point::Format::new(6).unwrap();
        b.transforms.x.offset = 500_000.0;
        b.transforms.y.offset = 4_000_000.0;
        b.evlrs.push(las::Vlr {
            user_id: "curbtrace".into(),
            record_id: 7,
            description: "a description of thirty-one chars"
                .chars()
                .take(31)
                .collect(),
            data: vec![0xff; 300],
        });
        let mut w = Writer::from_path(&path, b.into_header().unwrap()).unwrap();
        for p in &pts {
            w.write_point(p.clone()).unwrap();
        }
        w.close().unwrap();
        assert_eq!(read(&path, None).unwrap().0.t.len(), 10);
    }

    #[test]
    fn reads_columns_sorted_by_time_with_crs() {
        let dir = tempfile::tempdir().unwrap();
        for name in ["a.las", "a.laz"] {
            let path = dir.path().join(name);
            let pts = vec![
                pt(500_001.0, 4_000_002.0, 3.0, 10.5),
                pt(500_004.0, 4_000_005.0, 6.0, 10.25),
                pt(500_007.125, 4_000_008.0, 9.0, 10.5),
            ];
            write_las(&path, 6, &pts, Some(6677));
            let (c, info) = read(&path, None).unwrap();
            assert_eq!(c.t, vec![10.25, 10.5, 10.5]);
            // Stable: the two points at 10.5 keep file order.
            assert_eq!(c.x, vec![500_004.0, 500_001.0, 500_007.125]);
            assert_eq!(c.z, vec![6.0, 3.0, 9.0]);
            assert_eq!(c.intensity, vec![7, 7, 7]);
            assert_eq!(info.crs, Some(Crs::Epsg(6677)));
            assert!(info.was_reordered, "the file's times are 10.5, 10.25, 10.5");
            assert_eq!(info.point_format, 6);
            assert_eq!(info.compressed, name.ends_with("laz"));
            assert_eq!(info.points_selected, 3);
        }
    }

    #[test]
    fn every_format_with_gps_time_reads() {
        let dir = tempfile::tempdir().unwrap();
        for f in [1u8, 3, 4, 5, 6, 7, 8, 9, 10] {
            let path = dir.path().join(format!("f{f}.las"));
            let mut p = pt(500_000.5, 4_000_000.25, 1.0, 5.0);
            let fmt = las::point::Format::new(f).unwrap();
            if fmt.has_color {
                p.color = Some(las::Color::new(1, 2, 3));
            }
            if fmt.has_nir {
                p.nir = Some(4);
            }
            if fmt.has_waveform {
                p.waveform = Some(Default::default());
            }
            p.scan_angle = 12.0;
            write_las(&path, f, &[p], None);
            let (c, info) = read(&path, None).unwrap();
            assert_eq!(
                (c.x[0], c.y[0], c.t[0]),
                (500_000.5, 4_000_000.25, 5.0),
                "format {f}"
            );
            assert!((c.scan_angle_deg[0] - 12.0).abs() < 0.01, "format {f}");
            assert_eq!(info.point_format, f);
            assert_eq!(info.crs, None);
        }
    }

    #[test]
    fn scanner_channel_and_point_source_selection() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("two.las");
        let mut pts = Vec::new();
        for k in 0..6 {
            let mut p = pt(500_000.0 + k as f64, 4_000_000.0, 0.0, k as f64);
            p.scanner_channel = (k % 2) as u8;
            p.point_source_id = 40 + (k % 3) as u16;
            pts.push(p);
        }
        write_las(&path, 6, &pts, None);
        let err = read(&path, None).unwrap_err().to_string();
        assert!(
            err.contains("two.las") && err.contains("[0, 1]") && err.contains("--scanner"),
            "{err}"
        );
        let (c, info) = read(&path, Some(1)).unwrap();
        assert_eq!(c.t, vec![1.0, 3.0, 5.0]);
        assert_eq!(info.selection, ScannerSelection::Channel(1));

        // Format 1 has no scanner channel: the ID is the point source id.
        let path = dir.path().join("psid.las");
        for p in &mut pts {
            p.scanner_channel = 0;
        }
        write_las(&path, 1, &pts, None);
        let (c, info) = read(&path, Some(41)).unwrap();
        assert_eq!(c.t, vec![1.0, 4.0]);
        assert_eq!(info.selection, ScannerSelection::PointSourceId(41));
        assert_eq!(info.points_in_file, 6);
        let err = read(&path, Some(7)).unwrap_err().to_string();
        assert!(err.contains("point source id 7"), "{err}");
    }

    #[test]
    fn raw_head_parses_sizes() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("h.las");
        write_las(
            &path,
            1,
            &vec![pt(500_000.0, 4_000_000.0, 0.0, 1.0); 3],
            None,
        );
        let bytes = std::fs::read(&path).unwrap();
        let h = parse_raw_head(&path, &bytes[..375], bytes.len() as u64).unwrap();
        assert_eq!(h.format, 1);
        assert_eq!(h.record_len, 28);
        assert_eq!(h.count, 3);
        assert!(!h.compressed);
        assert_eq!(
            u64::from(h.offset_to_point_data) + 3 * 28,
            bytes.len() as u64
        );
    }

    #[test]
    fn laz_reservation_is_capped_by_the_compressed_size() {
        assert_eq!(laz_reserve_cap(1_000_000_000_000, 1000), 4000);
        assert_eq!(laz_reserve_cap(10, 1000), 10);
    }
}
