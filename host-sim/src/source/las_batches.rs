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
        let reader = Reader::with_options(
            BufReader::with_capacity(1 << 20, file),
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
        Ok(Self {
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
            let want = self
                .slab
                .min(self.total - self.done)
                .min(max as u64 - decoded);
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
            self.take_slab(out)?;
            self.done += n;
            decoded += n;
        }
        if self.done >= self.total && decoded == 0 {
            self.finish_checks()?;
        }
        Ok(decoded)
    }

    fn take_slab(&mut self, out: &mut PointBatch) -> Result<(), LasError> {
        let raw = self.pd.raw_bytes();
        let rl = self.record_len;
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
        let sel = self.selection();
        let Some(gps_at) = self.gps_offset() else {
            return Err(LasError::NoGpsTime {
                path: self.path.clone(),
                format: self.format,
            });
        };
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
        if sel == ScannerSelection::All {
            // Every record kept: one tight pass per column.
            let recs = || raw.chunks_exact(rl);
            out.x.extend(recs().map(|r| tf.x.direct(i32_at(r, 0))));
            out.y.extend(recs().map(|r| tf.y.direct(i32_at(r, 4))));
            out.z.extend(recs().map(|r| tf.z.direct(i32_at(r, 8))));
            out.t.extend(recs().map(|r| f64_at(r, gps_at)));
            out.intensity.extend(recs().map(|r| u16_at(r, 12)));
            out.scan_angle_deg.extend(recs().map(angle));
            out.channel.extend(recs().map(channel_of));
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
                        channel_of(rec),
                    );
                }
            }
        }
        if let Some(k) = out.t[from..].iter().position(|t| !t.is_finite()) {
            // The index in the file: kept records before it, plus the skipped ones.
            let t = out.t[from + k];
            let index = raw
                .chunks_exact(rl)
                .position(|r| f64_at(r, gps_at).to_bits() == t.to_bits())
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
        r.take_slab(&mut b)?;
        Ok(b.t.first().copied())
    }
}
