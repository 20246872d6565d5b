//! Many LAS/LAZ files as one time-ordered stream of batches.
//!
//! The files are ordered by the GPS time of their first point and read one after the
//! other; the stream is continuous, so a scanline that a writer split between two files is
//! one scanline downstream. The reader checks the order as it goes: a point earlier than
//! the one before it (a file not sorted by time, or files that overlap in time) ends the
//! stream with [`SourceError::OutOfOrder`], and the caller starts again on
//! [`external_sort::SortedRuns`](super::external_sort::SortedRuns), which sorts chunk-wise
//! through a temporary directory in bounded memory.

use super::files::{self, FilesError};
use super::las_batches::LasBatches;
use super::PointBatch;
use crate::io::las_in::{LasError, LasInfo, NoCrs, ReadOptions, ScannerSelection};
use crate::model::Crs;
use std::path::{Path, PathBuf};

/// Errors of a point source; every message names the file and the problem.
#[derive(Debug, thiserror::Error)]
pub enum SourceError {
    /// Reading one of the files.
    #[error(transparent)]
    Las(#[from] LasError),
    /// Expanding the inputs.
    #[error(transparent)]
    Files(#[from] FilesError),
    /// The temporary files of the external sort.
    #[error("{path}: {source}")]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// A point earlier than the one before it.
    #[error(
        "{path}: point at GPS time {t} s comes after one at {before} s (input not in time order)"
    )]
    OutOfOrder {
        /// The file.
        path: PathBuf,
        /// The earlier time that came second.
        t: f64,
        /// The time before it.
        before: f64,
    },
    /// Files in different coordinate reference systems.
    #[error(
        "{path}: its CRS {crs:?} differs from {first_path}'s {first:?}; one run needs one CRS"
    )]
    Crs {
        /// The file that differs.
        path: PathBuf,
        /// Its CRS.
        crs: Option<Crs>,
        /// The first file.
        first_path: PathBuf,
        /// The first file's CRS.
        first: Option<Crs>,
    },
}

/// The header facts of the inputs, for the summary and the output.
#[derive(Clone, Debug)]
pub struct InputInfo {
    /// The files in stream order.
    pub files: Vec<PathBuf>,
    /// Bytes of all files.
    pub bytes: u64,
    /// Points in all files (header counts).
    pub points_in_files: u64,
    /// The CRS shared by every file.
    pub crs: Option<Crs>,
    /// Why `crs` is `None` (from the first file).
    pub no_crs: Option<NoCrs>,
    /// First file's LAS version, format and compression.
    pub version: (u8, u8),
    /// Point data record format of the first file.
    pub format: u8,
    /// LAZ.
    pub compressed: bool,
    /// The name of the first file's ring dimension (a spinning sensor's file; every
    /// point's channel key is its ring).
    pub ring: Option<String>,
}

impl InputInfo {
    /// A [`LasInfo`] for the summary: the path is the file, or "N files from FIRST".
    pub fn las_info(&self, selected: u64, selection: ScannerSelection, reordered: bool) -> LasInfo {
        let path = match self.files.as_slice() {
            [one] => one.clone(),
            [first, ..] => PathBuf::from(format!(
                "{} files from {}",
                self.files.len(),
                first.display()
            )),
            [] => PathBuf::new(),
        };
        LasInfo {
            path,
            version: self.version,
            point_format: self.format,
            compressed: self.compressed,
            points_in_file: self.points_in_files,
            points_selected: selected,
            selection,
            crs: self.crs.clone(),
            no_crs: self.no_crs,
            was_reordered: reordered,
            has_scan_angle: true,
        }
    }
}

/// The inputs, ordered by time, read batch by batch.
pub struct Campaign {
    info: InputInfo,
    opts: ReadOptions,
    next_file: usize,
    current: Option<LasBatches>,
    bytes_done_files: u64,
    last_t: f64,
    check_order: bool,
    selection: ScannerSelection,
}

impl Campaign {
    /// Expands the inputs, checks every header, orders the files by their first GPS time.
    pub fn open(inputs: &[PathBuf], opts: &ReadOptions) -> Result<Self, SourceError> {
        let paths = files::expand(inputs)?;
        let mut keyed = Vec::with_capacity(paths.len());
        let mut first: Option<(PathBuf, Option<Crs>)> = None;
        let mut no_crs = None;
        let (mut bytes, mut points) = (0u64, 0u64);
        let mut head = ((1, 2), 0, false);
        let mut ring = None;
        for p in paths {
            let r = LasBatches::open(&p, opts)?;
            match &first {
                None => {
                    first = Some((p.clone(), r.crs.clone()));
                    no_crs = r.no_crs;
                    head = (r.version, r.format, r.compressed);
                    ring = r.ring.as_ref().map(|d| d.name.clone());
                }
                Some((fp, fc)) => {
                    let same = match (fc, &r.crs) {
                        (Some(a), Some(b)) => a.same_as(b),
                        (None, None) => true,
                        _ => false,
                    };
                    if !same {
                        return Err(SourceError::Crs {
                            path: p,
                            crs: r.crs.clone(),
                            first_path: fp.clone(),
                            first: fc.clone(),
                        });
                    }
                }
            }
            bytes += r.file_bytes;
            points += r.points_in_file();
            drop(r);
            let t0 = LasBatches::first_time(&p)?.unwrap_or(f64::INFINITY);
            keyed.push((t0, p));
        }
        // Stable: files starting at the same time keep their argument order.
        keyed.sort_by(|a, b| a.0.total_cmp(&b.0));
        Ok(Self {
            info: InputInfo {
                files: keyed.into_iter().map(|k| k.1).collect(),
                bytes,
                points_in_files: points,
                crs: first.and_then(|f| f.1),
                no_crs,
                version: head.0,
                format: head.1,
                compressed: head.2,
                ring,
            },
            opts: *opts,
            next_file: 0,
            current: None,
            bytes_done_files: 0,
            last_t: f64::NEG_INFINITY,
            check_order: true,
            selection: ScannerSelection::All,
        })
    }

    /// The inputs' header facts.
    pub fn info(&self) -> &InputInfo {
        &self.info
    }

    /// The same files read without the time-order check (the external sort's input).
    pub fn unchecked(mut self) -> Self {
        self.check_order = false;
        self
    }

    /// The scanner selection in force (of the file read last).
    pub fn selection(&self) -> ScannerSelection {
        self.selection
    }

    /// Bytes of the inputs read so far (whole files done plus the share of the current one).
    pub fn bytes_done(&self) -> u64 {
        self.bytes_done_files
            + self.current.as_ref().map_or(0, |c| {
                let total = c.points_in_file().max(1);
                (c.file_bytes as f64 * c.points_decoded() as f64 / total as f64) as u64
            })
    }

    /// The next batch of up to about `max` points in time order; `None` at the end.
    pub fn next_batch(&mut self, max: usize) -> Result<Option<PointBatch>, SourceError> {
        let mut out = PointBatch::with_capacity(max);
        while out.len() < max {
            if self.current.is_none() {
                let Some(p) = self.info.files.get(self.next_file) else {
                    break;
                };
                self.current = Some(LasBatches::open(p, &self.opts)?);
                self.next_file += 1;
            }
            let Some(cur) = self.current.as_mut() else {
                break;
            };
            let before = out.len();
            let room = max - before;
            let n = cur.read_into(&mut out, room)?;
            self.selection = cur.selection();
            let path = cur.path().to_path_buf();
            self.check_order(&out, before, &path)?;
            if n == 0 {
                let cur = self.current.as_ref().map_or(0, |c| c.file_bytes);
                self.bytes_done_files += cur;
                self.current = None;
            }
        }
        Ok((!out.is_empty()).then_some(out))
    }

    fn check_order(&mut self, b: &PointBatch, from: usize, path: &Path) -> Result<(), SourceError> {
        if !self.check_order {
            return Ok(());
        }
        for &t in &b.t[from..] {
            if t < self.last_t {
                return Err(SourceError::OutOfOrder {
                    path: path.to_path_buf(),
                    t,
                    before: self.last_t,
                });
            }
            self.last_t = t;
        }
        Ok(())
    }
}
