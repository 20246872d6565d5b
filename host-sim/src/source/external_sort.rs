//! Chunk-wise external sort by GPS time, for inputs that are not in time order.
//!
//! Pass 1 reads the inputs in runs of [`RUN_POINTS`] points, sorts each run by time
//! (stable) and writes it to a temporary directory as fixed 39-byte records (x, y, z, t as
//! `f64`, intensity `u16`, scan angle `f32`, channel `u8`). Pass 2 merges the runs with a
//! heap, reading each through a small buffer; ties go to the earlier run, so the result is
//! the stable sort of the whole input. Memory: one run (about 45 B per point, 94 MB at
//! 2^21 points) in pass 1, a 256 KiB buffer per run in pass 2. Cost: the input is decoded
//! once, written once and read once (39 B per point each way) on top of the streaming run.

use super::campaign::{Campaign, SourceError};
use super::PointBatch;
use crate::io::las_in::ScannerSelection;
use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::fs::File;
use std::io::{BufReader, BufWriter, Read, Write};
use std::path::PathBuf;

/// Points per sorted run.
pub const RUN_POINTS: usize = 1 << 21;
const REC: usize = 39;

/// The inputs sorted into runs on disk, merged on reading.
pub struct SortedRuns {
    _dir: tempfile::TempDir,
    runs: Vec<(PathBuf, BufReader<File>)>,
    heads: BinaryHeap<Reverse<(u64, usize)>>,
    pending: Vec<Option<[u8; REC]>>,
    total: u64,
    done: u64,
    /// The scanner selection the reading used.
    pub selection: ScannerSelection,
}

fn io_err(path: &std::path::Path) -> impl Fn(std::io::Error) -> SourceError + '_ {
    move |source| SourceError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// A time as a key that orders like the `f64` (finite times only reach here).
fn time_key(t: f64) -> u64 {
    let b = t.to_bits();
    if b >> 63 == 1 {
        !b
    } else {
        b | (1 << 63)
    }
}

fn encode(b: &PointBatch, i: usize) -> [u8; REC] {
    let mut r = [0u8; REC];
    r[0..8].copy_from_slice(&b.x[i].to_le_bytes());
    r[8..16].copy_from_slice(&b.y[i].to_le_bytes());
    r[16..24].copy_from_slice(&b.z[i].to_le_bytes());
    r[24..32].copy_from_slice(&b.t[i].to_le_bytes());
    r[32..34].copy_from_slice(&b.intensity[i].to_le_bytes());
    r[34..38].copy_from_slice(&b.scan_angle_deg[i].to_le_bytes());
    r[38] = b.channel[i];
    r
}

fn f64_at(r: &[u8; REC], o: usize) -> f64 {
    let mut a = [0u8; 8];
    a.copy_from_slice(&r[o..o + 8]);
    f64::from_le_bytes(a)
}

fn decode_into(r: &[u8; REC], out: &mut PointBatch) {
    out.x.push(f64_at(r, 0));
    out.y.push(f64_at(r, 8));
    out.z.push(f64_at(r, 16));
    out.t.push(f64_at(r, 24));
    out.intensity.push(u16::from_le_bytes([r[32], r[33]]));
    out.scan_angle_deg
        .push(f32::from_le_bytes([r[34], r[35], r[36], r[37]]));
    out.channel.push(r[38]);
}

impl SortedRuns {
    /// Reads `campaign` (order unchecked) into sorted runs of `run_points` in a new
    /// temporary directory (in `TMPDIR`).
    pub fn build(campaign: Campaign, run_points: usize) -> Result<Self, SourceError> {
        let mut campaign = campaign.unchecked();
        let dir = tempfile::Builder::new()
            .prefix("curbtrace-sort")
            .tempdir()
            .map_err(|source| SourceError::Io {
                path: std::env::temp_dir(),
                source,
            })?;
        let mut runs = Vec::new();
        let mut total = 0u64;
        while let Some(b) = campaign.next_batch(run_points.max(1))? {
            let mut perm: Vec<u32> = (0..b.len() as u32).collect();
            perm.sort_by(|&i, &j| b.t[i as usize].total_cmp(&b.t[j as usize]));
            let path = dir.path().join(format!("run{:06}", runs.len()));
            let f = File::create(&path).map_err(io_err(&path))?;
            let mut w = BufWriter::with_capacity(1 << 18, f);
            for &i in &perm {
                w.write_all(&encode(&b, i as usize))
                    .map_err(io_err(&path))?;
            }
            w.flush().map_err(io_err(&path))?;
            total += b.len() as u64;
            runs.push(path);
        }
        let selection = campaign.selection();
        let mut s = Self {
            _dir: dir,
            runs: Vec::with_capacity(runs.len()),
            heads: BinaryHeap::new(),
            pending: Vec::new(),
            total,
            done: 0,
            selection,
        };
        for path in runs {
            let f = File::open(&path).map_err(io_err(&path))?;
            s.runs.push((path, BufReader::with_capacity(1 << 18, f)));
            s.pending.push(None);
            let k = s.runs.len() - 1;
            s.refill(k)?;
        }
        Ok(s)
    }

    fn refill(&mut self, k: usize) -> Result<(), SourceError> {
        let (path, r) = &mut self.runs[k];
        let mut rec = [0u8; REC];
        match r.read_exact(&mut rec) {
            Ok(()) => {
                self.heads.push(Reverse((time_key(f64_at(&rec, 24)), k)));
                self.pending[k] = Some(rec);
                Ok(())
            }
            Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => {
                self.pending[k] = None;
                Ok(())
            }
            Err(e) => Err(io_err(path)(e)),
        }
    }

    /// The next batch of up to `max` points in time order; `None` at the end.
    pub fn next_batch(&mut self, max: usize) -> Result<Option<PointBatch>, SourceError> {
        let mut out = PointBatch::with_capacity(max.min(1 << 20));
        while out.len() < max {
            let Some(Reverse((_, k))) = self.heads.pop() else {
                break;
            };
            if let Some(rec) = self.pending[k].take() {
                decode_into(&rec, &mut out);
            }
            self.refill(k)?;
        }
        self.done += out.len() as u64;
        Ok((!out.is_empty()).then_some(out))
    }

    /// Input bytes the merge has passed, in proportion to the points.
    pub fn bytes_done(&self, bytes_total: u64) -> u64 {
        (bytes_total as f64 * self.done as f64 / self.total.max(1) as f64) as u64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_keys_order_like_the_times() {
        let ts = [-5.0, -0.0, 0.0, 1e-9, 3.5, 4e9];
        for w in ts.windows(2) {
            assert!(time_key(w[0]) <= time_key(w[1]), "{w:?}");
        }
    }
}
