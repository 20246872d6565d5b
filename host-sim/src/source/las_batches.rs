//! One LAS/LAZ file decoded in batches: the header is checked by
//! [`io::las_in::check_file`](crate::io::las_in::check_file), then the `las` crate's
//! `fill_points` decodes slabs whose columns are appended to a [`PointBatch`]. The scanner
//! selection follows `io::las_in`: without `--scanner`, a file with more than one scanner
//! channel is an error; with `--scanner ID`, ID is the channel in formats 6–10 whose
//! channels are in use (decided on the first slab), else the point source id.

use super::PointBatch;
use crate::io::las_in::{self, LasError, NoCrs, ReadOptions, ScannerSelection};
use crate::model::Crs;
use las::{PointData, PointDataBuilder, Reader, ReaderOptions};
use std::fs::File;
use std::io::BufReader;
use std::path::{Path, PathBuf};

/// Largest byte slab of one `fill_points` call (records can carry up to 64 KiB of extra
/// bytes; the slab is capped whatever the record length).
const MAX_SLAB_BYTES: u64 = 64 << 20;

/// Slabs a spinning sensor's LAZ file decodes at once. LAZ chunks (50 000 points by
/// default) are decompressed in parallel on rayon's pool only when one call spans several
/// of them, so such a file is decoded several slabs ahead and its slabs are taken from the
/// decoded records (whole slabs: those handed on are the slabs of one-slab decoding).
/// Spinning sensors' files only: they stream about a million points a second, and their
/// stage holds far more than these slabs (profilers' files keep one slab in memory).
const LAZ_AHEAD_SLABS: u64 = 8;

/// Most bytes decoded ahead ([`LAZ_AHEAD_SLABS`] fewer slabs of long records).
const MAX_AHEAD_BYTES: u64 = 16 << 20;

/// Names of an extra-bytes dimension that holds a spinning sensor's ring (laser number),
/// matched without regard to case.
pub const RING_NAMES: [&str; 3] = ["ring", "laser_id", "channel"];

/// A ring dimension found in the Extra Bytes VLR: where it sits in the point record.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RingDim {
    /// Its name as the file spells it.
    pub name: String,
    /// Byte offset in the point record.
    pub at: usize,
    /// LAS data type (1–8: unsigned and signed integers of 1, 2, 4, 8 bytes).
    pub data_type: u8,
}

impl RingDim {
    /// The dimension named ring, laser_id or channel among the Extra Bytes VLR's
    /// descriptors (LAS 1.4 R15 §2.5.7.2, 192 bytes each, the values in order after the
    /// format's own `base_len` bytes). `None` when there is none, or when a descriptor
    /// before it has a type whose size is not known (deprecated array types).
    pub fn find(header: &las::Header, base_len: usize) -> Option<Self> {
        let vlr = header
            .all_vlrs()
            .find(|v| v.user_id.trim_end_matches('\0') == "LASF_Spec" && v.record_id == 4)?;
        let mut at = base_len;
        for d in vlr.data.chunks_exact(192) {
            let (data_type, options) = (d[2], d[3]);
            let size = match data_type {
                0 => usize::from(options),
                1 | 2 => 1,
                3 | 4 => 2,
                5 | 6 | 9 => 4,
                7 | 8 | 10 => 8,
                _ => return None,
            };
            let name: String = String::from_utf8_lossy(&d[4..36])
                .trim_end_matches('\0')
                .trim()
                .to_string();
            if (1..=8).contains(&data_type)
                && RING_NAMES.iter().any(|n| name.eq_ignore_ascii_case(n))
            {
                return Some(Self {
                    name,
                    at,
                    data_type,
                });
            }
            at += size;
        }
        None
    }

    /// The ring of one point record; `None` when it is outside 0–255.
    #[inline]
    pub fn read(&self, rec: &[u8]) -> Option<u8> {
        let b = rec.get(self.at..)?;
        let v: i64 = match self.data_type {
            1 => i64::from(b[0]),
            2 => i64::from(b[0] as i8),
            3 => i64::from(u16::from_le_bytes([b[0], b[1]])),
            4 => i64::from(i16::from_le_bytes([b[0], b[1]])),
            5 => i64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            6 => i64::from(i32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            _ => i64::from_le_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]]),
        };
        u8::try_from(v).ok()
    }
}

/// A file open for batch reading.
pub struct LasBatches {
    path: PathBuf,
    reader: Reader,
    pd: PointData,
    record_len: usize,
    extended: bool,
    total: u64,
    done: u64,
    slab: u64,
    /// Records decoded at once: `slab`, or up to [`LAZ_AHEAD_SLABS`] slabs of a spinning
    /// sensor's LAZ file.
    ahead: u64,
    /// `pd`'s records not yet taken: `[next, filled)`.
    next: usize,
    filled: usize,
    scanner: Option<u16>,
    selection: Option<ScannerSelection>,
    channels_seen: [bool; 4],
    /// Bytes of the file on disk (for the progress over all inputs).
    pub file_bytes: u64,
    /// The file's CRS.
    pub crs: Option<Crs>,
    /// Why `crs` is `None`.
    pub no_crs: Option<NoCrs>,
    /// LAS version.
    pub version: (u8, u8),
    /// Point data record format.
    pub format: u8,
    /// LAZ-compressed.
    pub compressed: bool,
    /// The ring dimension of a spinning sensor's file: when present, every point's channel
    /// key is its ring (docs/spec.md, *Spinning sensors*).
    pub ring: Option<RingDim>,
}

impl LasBatches {
    /// Checks and opens `path`.
    pub fn open(path: &Path, opts: &ReadOptions) -> Result<Self, LasError> {
        let head = las_in::check_file(path)?;
        let io = |source| LasError::Io {
            path: path.to_path_buf(),
            source,
        };
        let file = File::open(path).map_err(io)?;
        let file_bytes = file.metadata().map_err(io)?.len();
        // An uncompressed file is read a slab of records at a time (most of a megabyte);
        // a read at least as large as the buffer bypasses it, so the records go from the
        // file straight into the decoder's bytes instead of through a copy in the buffer.
        // LAZ reads its chunks in small pieces and keeps the large buffer.
        let buffer = if head.compressed { 1 << 20 } else { 1 << 14 };
        let reader = Reader::with_options(
            BufReader::with_capacity(buffer, file),
            ReaderOptions::default(),
        )
        .map_err(|e| LasError::Las {
            path: path.to_path_buf(),
            what: format!("reading the header and VLRs: {e}"),
        })?;
        let header = reader.header().clone();
        let pd: PointData = PointDataBuilder::new().for_header(&header).build();
        let record_len = pd.record_len();
        let extended = header.point_format().is_extended;
        let slab = (MAX_SLAB_BYTES / record_len.max(1) as u64).clamp(1, super::BATCH_POINTS as u64);
        let base_len = record_len.saturating_sub(usize::from(header.point_format().extra_bytes));
        let ring = RingDim::find(&header, base_len)
            .filter(|r| r.at + [0, 1, 1, 2, 2, 4, 4, 8, 8][usize::from(r.data_type)] <= record_len);
        let ahead = if head.compressed && ring.is_some() {
            slab * (MAX_AHEAD_BYTES / (slab * record_len.max(1) as u64)).clamp(1, LAZ_AHEAD_SLABS)
        } else {
            slab
        };
        Ok(Self {
            ring,
            path: path.to_path_buf(),
            crs: las_in::header_crs(&header).ok(),
            no_crs: las_in::header_crs(&header).err(),
            total: header.number_of_points(),
            reader,
            pd,
            record_len,
            extended,
            done: 0,
            slab,
            ahead,
            next: 0,
            filled: 0,
            scanner: opts.scanner,
            selection: match (opts.scanner, extended) {
                (None, _) => Some(ScannerSelection::All),
                (Some(id), false) => Some(ScannerSelection::PointSourceId(id)),
                (Some(_), true) => None,
            },
            channels_seen: [false; 4],
            file_bytes,
            version: head.version,
            format: head.format,
            compressed: head.compressed,
        })
    }

    /// The file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Points in the file (header count).
    pub fn points_in_file(&self) -> u64 {
        self.total
    }

    /// Points decoded so far.
    pub fn points_decoded(&self) -> u64 {
        self.done
    }

    /// The scanner selection in force (known after the first slab).
    pub fn selection(&self) -> ScannerSelection {
        self.selection.unwrap_or(ScannerSelection::All)
    }

    /// Decodes up to `max` points (at least one slab) and appends the selected ones to `out`.
    /// Returns the number of points decoded (0 at the end of the file).
    pub fn read_into(&mut self, out: &mut PointBatch, max: usize) -> Result<u64, LasError> {
        let mut decoded = 0u64;
        while decoded < max as u64 && self.done < self.total {
            if self.next == self.filled {
                self.decode_ahead()?;
            }
            let want = self
                .slab
                .min(self.total - self.done)
                .min(max as u64 - decoded)
                .min((self.filled - self.next) as u64);
            let records = self.next..self.next + want as usize;
            self.take_slab(out, records)?;
            self.next += want as usize;
            self.done += want;
            decoded += want;
        }
        if self.done >= self.total && decoded == 0 {
            self.finish_checks()?;
        }
        Ok(decoded)
    }

    /// Decodes the next `ahead` records (fewer at the end of the file) into `pd`.
    fn decode_ahead(&mut self) -> Result<(), LasError> {
        let want = self.ahead.min(self.total - self.done);
        let n = self
            .reader
            .fill_points(want.max(1), &mut self.pd)
            .map_err(|e| LasError::Las {
                path: self.path.clone(),
                what: format!("decoding points after point {}: {e}", self.done),
            })?;
        if n == 0 {
            return Err(LasError::Truncated {
                path: self.path.clone(),
                what: format!(
                    "the header says {} points but only {} could be decoded",
                    self.total, self.done
                ),
            });
        }
        (self.next, self.filled) = (0, n as usize);
        Ok(())
    }

    /// Appends the decoded `records` of `pd` to `out`.
    fn take_slab(
        &mut self,
        out: &mut PointBatch,
        records: std::ops::Range<usize>,
    ) -> Result<(), LasError> {
        let rl = self.record_len;
        let raw = &self.pd.raw_bytes()[records.start * rl..records.end * rl];
        let Some(gps_at) = self.gps_offset() else {
            return Err(LasError::NoGpsTime {
                path: self.path.clone(),
                format: self.format,
            });
        };
        if self.selection == Some(ScannerSelection::All) && rl >= gps_at + 8 {
            // Every record kept: one pass over the records at the format's fixed offsets.
            let from = out.len();
            let tf = *self.pd.transforms();
            let (seen, finite) = if self.extended {
                append_all::<EXTENDED_HEAD>(raw, rl, &tf, out)
            } else {
                append_all::<LEGACY_HEAD>(raw, rl, &tf, out)
            };
            for c in 0..4 {
                self.channels_seen[c] |= seen >> c & 1 == 1;
            }
            if let Err(e) = self.check_channels() {
                out.keep_range(0..from);
                return Err(e);
            }
            if let Some(r) = &self.ring {
                for (k, rec) in out.channel[from..].iter_mut().zip(raw.chunks_exact(rl)) {
                    *k = r.read(rec).unwrap_or(u8::MAX);
                }
            }
            return self.check_keys_and_times(out, from, raw, finite);
        }
        // Scanner channel: bits 4–5 of the flags byte at offset 15 (formats 6–10).
        let channel_of = |rec: &[u8]| if self.extended { (rec[15] >> 4) & 3 } else { 0 };
        if self.extended {
            for rec in raw.chunks_exact(rl) {
                self.channels_seen[usize::from(channel_of(rec))] = true;
            }
        }
        if self.selection.is_none() {
            let id = self.scanner.unwrap_or(0);
            self.selection = Some(if self.channels_seen[1..].iter().any(|&c| c) {
                ScannerSelection::Channel(u8::try_from(id).ok().filter(|&c| c < 4).ok_or_else(
                    || LasError::NoPoints {
                        path: self.path.clone(),
                        what: format!("--scanner {id}: scanner channels are 0–3"),
                    },
                )?)
            } else {
                ScannerSelection::PointSourceId(id)
            });
        }
        self.check_channels()?;
        let sel = self.selection();
        // Field offsets of the point record (LAS 1.4 R15 tables 7 and 12): X, Y, Z at 0, 4,
        // 8, intensity at 12; scan angle, point source id and GPS time after the flags.
        let (sa_at, psid_at) = if self.extended { (18, 20) } else { (16, 18) };
        let tf = *self.pd.transforms();
        let i32_at = |r: &[u8], k: usize| i32::from_le_bytes([r[k], r[k + 1], r[k + 2], r[k + 3]]);
        let u16_at = |r: &[u8], k: usize| u16::from_le_bytes([r[k], r[k + 1]]);
        let f64_at = |r: &[u8], k: usize| {
            f64::from_le_bytes([
                r[k],
                r[k + 1],
                r[k + 2],
                r[k + 3],
                r[k + 4],
                r[k + 5],
                r[k + 6],
                r[k + 7],
            ])
        };
        let extended = self.extended;
        // As `las`'s `scan_angle_degrees`: 0.006° steps in formats 6–10, whole degrees before.
        let angle = move |r: &[u8]| {
            if extended {
                f32::from(i16::from_le_bytes([r[sa_at], r[sa_at + 1]])) * 0.006
            } else {
                f32::from(r[sa_at] as i8)
            }
        };
        let from = out.len();
        let ring = self.ring.clone();
        let key = |rec: &[u8]| match &ring {
            Some(r) => r.read(rec).unwrap_or(u8::MAX),
            None => channel_of(rec),
        };
        if sel == ScannerSelection::All {
            // Every record kept: one tight pass per column.
            let recs = || raw.chunks_exact(rl);
            out.x.extend(recs().map(|r| tf.x.direct(i32_at(r, 0))));
            out.y.extend(recs().map(|r| tf.y.direct(i32_at(r, 4))));
            out.z.extend(recs().map(|r| tf.z.direct(i32_at(r, 8))));
            out.t.extend(recs().map(|r| f64_at(r, gps_at)));
            out.intensity.extend(recs().map(|r| u16_at(r, 12)));
            out.scan_angle_deg.extend(recs().map(angle));
            out.channel.extend(recs().map(key));
        } else {
            for rec in raw.chunks_exact(rl) {
                let keep = match sel {
                    ScannerSelection::All => true,
                    ScannerSelection::Channel(c) => channel_of(rec) == c,
                    ScannerSelection::PointSourceId(id) => u16_at(rec, psid_at) == id,
                };
                if keep {
                    out.push(
                        tf.x.direct(i32_at(rec, 0)),
                        tf.y.direct(i32_at(rec, 4)),
                        tf.z.direct(i32_at(rec, 8)),
                        f64_at(rec, gps_at),
                        u16_at(rec, 12),
                        angle(rec),
                        key(rec),
                    );
                }
            }
        }
        self.check_keys_and_times(out, from, raw, false)
    }

    /// Without `--scanner`, a file with more than one scanner channel in the records seen
    /// so far is refused.
    fn check_channels(&self) -> Result<(), LasError> {
        if self.scanner.is_none() {
            let seen: Vec<u8> = (0u8..4)
                .filter(|&c| self.channels_seen[usize::from(c)])
                .collect();
            if seen.len() > 1 {
                return Err(LasError::SeveralScanners {
                    path: self.path.clone(),
                    channels: seen,
                });
            }
        }
        Ok(())
    }

    /// The points appended to `out` from index `from` on, decoded from `raw`: a ring that
    /// is not 0–254 and a time that is not finite are refused, with the point's index in
    /// the file. `finite`: every time is known to be finite.
    fn check_keys_and_times(
        &self,
        out: &PointBatch,
        from: usize,
        raw: &[u8],
        finite: bool,
    ) -> Result<(), LasError> {
        if let Some(r) = &self.ring {
            if let Some(k) = out.channel[from..].iter().position(|&c| c == u8::MAX) {
                return Err(LasError::NoPoints {
                    path: self.path.clone(),
                    what: format!(
                        "point {}: extra-bytes dimension {:?} is not a ring number 0–254",
                        self.done + k as u64,
                        r.name
                    ),
                });
            }
        }
        if finite {
            return Ok(());
        }
        if let Some(k) = out.t[from..].iter().position(|t| !t.is_finite()) {
            // The index in the file: kept records before it, plus the skipped ones.
            let t = out.t[from + k];
            let at = self.gps_offset().unwrap_or(0);
            let index = raw
                .chunks_exact(self.record_len)
                .position(|r| r[at..at + 8] == t.to_bits().to_le_bytes())
                .unwrap_or(k) as u64;
            return Err(LasError::BadTime {
                path: self.path.clone(),
                index: self.done + index,
                t,
            });
        }
        Ok(())
    }

    /// Offset of the GPS time in the point record, `None` for formats without one.
    fn gps_offset(&self) -> Option<usize> {
        if self.extended {
            Some(22)
        } else if self.pd.gps_time().is_some() {
            Some(20)
        } else {
            None
        }
    }

    /// At the end of the file: `--scanner ID` on a file whose channels appear only late is
    /// refused as `io::las_in` does.
    fn finish_checks(&self) -> Result<(), LasError> {
        if let (Some(id), Some(ScannerSelection::PointSourceId(_))) = (self.scanner, self.selection)
        {
            let channels: Vec<u8> = (0u8..4)
                .filter(|&c| self.channels_seen[usize::from(c)])
                .collect();
            if self.extended && channels.iter().any(|&c| c != 0) {
                return Err(LasError::NoPoints {
                    path: self.path.clone(),
                    what: format!(
                        "--scanner {id}: scanner channels {channels:?} appear only late in the file; cannot tell channel from point source id"
                    ),
                });
            }
        }
        Ok(())
    }

    /// GPS time of the first point (for ordering files), decoding one point of a fresh
    /// reader. `None` for a file without points.
    pub fn first_time(path: &Path) -> Result<Option<f64>, LasError> {
        let mut r = Self::open(path, &ReadOptions { scanner: None })?;
        r.slab = 1;
        let mut b = PointBatch::default();
        let n = r
            .reader
            .fill_points(1, &mut r.pd)
            .map_err(|e| LasError::Las {
                path: path.to_path_buf(),
                what: format!("decoding the first point: {e}"),
            })?;
        if n == 0 {
            return Ok(None);
        }
        r.selection = Some(ScannerSelection::All);
        r.scanner = Some(0);
        r.take_slab(&mut b, 0..1)?;
        Ok(b.t.first().copied())
    }
}

/// Bytes of a legacy record up to the end of its GPS time (formats 1, 3, 4, 5: X, Y, Z,
/// intensity, flags, class, scan angle rank at 16, user data, point source id, GPS time at
/// 20).
const LEGACY_HEAD: usize = 28;

/// Bytes of a format 6–10 record up to the end of its GPS time (flags with the scanner
/// channel at 15, scan angle at 18, GPS time at 22).
const EXTENDED_HEAD: usize = 30;

/// Appends every record of `raw` (records of `rl ≥ HEAD` bytes, the format's fields at
/// the offsets of [`LEGACY_HEAD`] or [`EXTENDED_HEAD`]) to `out`, with the channel key
/// the scanner channel (formats 6–10) or 0. Returns the scanner channels seen, bit `c` for
/// channel `c`, and whether every time is finite.
///
/// The values are those of the per-field decoding in `take_slab` (the `las` crate's
/// transform, its scan angle units); the columns are written in one pass over the records.
fn append_all<const HEAD: usize>(
    raw: &[u8],
    rl: usize,
    tf: &las::Vector<las::Transform>,
    out: &mut PointBatch,
) -> (u8, bool) {
    let extended = HEAD == EXTENDED_HEAD;
    let n = raw.len() / rl;
    let from = out.len();
    out.x.resize(from + n, 0.0);
    out.y.resize(from + n, 0.0);
    out.z.resize(from + n, 0.0);
    out.t.resize(from + n, 0.0);
    out.intensity.resize(from + n, 0);
    out.scan_angle_deg.resize(from + n, 0.0);
    out.channel.resize(from + n, 0);
    let cols = out.x[from..]
        .iter_mut()
        .zip(&mut out.y[from..])
        .zip(&mut out.z[from..])
        .zip(&mut out.t[from..])
        .zip(&mut out.intensity[from..])
        .zip(&mut out.scan_angle_deg[from..])
        .zip(&mut out.channel[from..]);
    let (mut seen, mut finite) = (0u8, true);
    for (((((((x, y), z), t), i), a), c), rec) in cols.zip(raw.chunks_exact(rl)) {
        let Some(r) = rec.first_chunk::<HEAD>() else {
            continue;
        };
        let i32_at = |k: usize| i32::from_le_bytes([r[k], r[k + 1], r[k + 2], r[k + 3]]);
        *x = tf.x.direct(i32_at(0));
        *y = tf.y.direct(i32_at(4));
        *z = tf.z.direct(i32_at(8));
        let mut b = [0u8; 8];
        b.copy_from_slice(&r[HEAD - 8..]);
        *t = f64::from_le_bytes(b);
        finite &= t.is_finite();
        *i = u16::from_le_bytes([r[12], r[13]]);
        if extended {
            *a = f32::from(i16::from_le_bytes([r[18], r[19]])) * 0.006;
            *c = (r[15] >> 4) & 3;
            seen |= 1 << *c;
        } else {
            *a = f32::from(r[16] as i8);
        }
    }
    (seen, finite)
}
