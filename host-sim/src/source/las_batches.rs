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
        let Some(gps) = self.pd.gps_time() else {
            return Err(LasError::NoGpsTime {
                path: self.path.clone(),
                format: self.format,
            });
        };
        let iter = raw
            .chunks_exact(rl)
            .zip(self.pd.point_source_id())
            .zip(self.pd.x().zip(self.pd.y()).zip(self.pd.z()))
            .zip(
                gps.zip(self.pd.intensity())
                    .zip(self.pd.scan_angle_degrees()),
            );
        for (k, (((rec, psid), ((x, y), z)), ((t, i), sa))) in iter.enumerate() {
            let ch = channel_of(rec);
            let keep = match sel {
                ScannerSelection::All => true,
                ScannerSelection::Channel(c) => ch == c,
                ScannerSelection::PointSourceId(id) => psid == id,
            };
            if !keep {
                continue;
            }
            if !t.is_finite() {
                return Err(LasError::BadTime {
                    path: self.path.clone(),
                    index: self.done + k as u64,
                    t,
                });
            }
            out.push(x, y, z, t, i, sa, ch);
        }
        Ok(())
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
