//! The points, projected and run through `curbtrace_core::Pipeline` in-process: the
//! kernel's parameter words first, then every point with its absolute GPS time in ns and
//! the column index as its tag.
//!
//! # Direct or through the wire
//!
//! By default ([`ReplayParams::wire`] off) each point goes straight to the core's line
//! assembly (`Pipeline::push_config`, `Pipeline::push_point`): the assembler, its split
//! rules and the kernel are the code the firmware runs, without the bytes. With `wire` on,
//! the points are encoded into the wire format the firmware reads (a config packet, then
//! point packets with the first point's GPS time in ns as each packet's base) and the core
//! parses them back, CRC and all ([`encode_stream`]). Both give the same lines and the
//! same output bit for bit (`tests/replay_direct.rs`); the direct path saves the encoding,
//! the CRC and the parse (docs/benchmarks.md).
//!
//! # Parallel replay, identical output
//!
//! The core is a sequential stream. The points are cut into chunks of about
//! [`ReplayParams::chunk_points`] points, each cut placed at a flagged line start (so no
//! line is split between chunks), and each chunk runs through its own `Pipeline` with its own
//! encoder. The cuts depend only on the data and the parameters, never on the number of
//! threads; the scanline numbers of chunk c are offset by the lines of chunks 0..c. A
//! pipeline starting at a flagged line start behaves as one that has been running (the
//! kernel holds no state across lines), so the output is the same whatever the thread
//! count. Without line flags ([`LineRule::None`]) the core's own split rule needs the
//! previous line, so the stream runs as one chunk.

use super::line_start::{LineRule, LineStartParams};
use super::project::{project_point, PoseCursor};
use super::{Candidate, PointStatus};
use crate::io::las_in::PointColumns;
use crate::io::trajectory::Trajectory;
use crate::model::Side;
use curbtrace_core::kernel::{ScanlineOutput, CONFIG_WORDS};
use curbtrace_core::wire::{PointRecord, StreamEncoder, MAX_PACKET_LEN, MAX_POINTS_PER_PACKET};
use curbtrace_core::Pipeline;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::ops::Range;

/// Capacity of the host pipeline's byte ring.
pub const RING: usize = 1 << 16;
/// Largest number of points of one scanline the host pipeline holds; more are counted as
/// truncated by the core. A 360° scanner at 1 M pulses/s and 100 lines/s gives 10 000
/// pulses per line; the simulator's VQ-250-like scanner 2 000.
pub const LINE_CAPACITY: usize = 16_384;

/// Stack size of the threads that run pipelines.
pub const PIPELINE_STACK: usize = 64 << 20;

/// The host's build of the core: `curbtrace_core::Pipeline` (ingest + kernel), the same
/// code the firmware's main loop runs.
pub type HostPipeline = Pipeline<RING, LINE_CAPACITY>;

/// Parameters of the replay (`[replay]` in the config file).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ReplayParams {
    /// Smallest backward jump of the scan angle taken as the wrap between two lines,
    /// degrees (see [`LineStartParams::wrap_min_deg`]).
    pub wrap_min_deg: f32,
    /// Line period in seconds for files without scan angles (0 = unknown: the core splits).
    pub line_period_s: f64,
    /// Points per chunk for the parallel replay (cut at the next line start). Larger
    /// chunks mean fewer pipelines; smaller ones balance threads better. 2^18 keeps the
    /// two cores here busy on 5 M points with 20 chunks.
    pub chunk_points: usize,
    /// Send the points through the wire format (encoded, CRC, parsed back) instead of
    /// straight to the core's line assembly; the output is the same (module docs).
    pub wire: bool,
}

impl Default for ReplayParams {
    fn default() -> Self {
        let l = LineStartParams::default();
        Self {
            wrap_min_deg: l.wrap_min_deg,
            line_period_s: l.line_period_s,
            chunk_points: 1 << 18,
            wire: false,
        }
    }
}

impl ReplayParams {
    /// The line-start part.
    pub fn line(&self) -> LineStartParams {
        LineStartParams {
            wrap_min_deg: self.wrap_min_deg,
            line_period_s: self.line_period_s,
        }
    }
}

/// Errors of the replay.
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    /// A point lies outside the trajectory (the caller drops those first).
    #[error("point {index} at GPS time {t} s is outside the trajectory")]
    Uncovered {
        /// Column index.
        index: usize,
        /// Its time.
        t: f64,
    },
    /// Negative GPS times cannot be carried as the wire's unsigned ns.
    #[error(
        "point {index} has a negative GPS time {t} s; the wire carries GPS time as unsigned ns"
    )]
    NegativeTime {
        /// Column index.
        index: usize,
        /// Its time.
        t: f64,
    },
    /// The core's encoder refused a packet (a bug, reported rather than hidden).
    #[error("encoding a packet failed: {0:?}")]
    Encode(curbtrace_core::wire::EncodeError),
    /// The pipeline stopped accepting bytes.
    #[error("the core's ring accepted no bytes after processing every line (stalled)")]
    Stalled,
    /// The output writer failed.
    #[error("{0}")]
    Io(#[from] std::io::Error),
}

/// Counters over the whole replay, summed over chunks.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ReplayCounters {
    /// Points sent to the core.
    pub points_sent: u64,
    /// Scanlines the core completed.
    pub scanlines: u64,
    /// Points with status Kept.
    pub kept: u64,
    /// Points removed as irregular (§2.4).
    pub irregular: u64,
    /// Points without a neighbour on one side.
    pub no_neighbour: u64,
    /// Points dropped because their line was over [`LINE_CAPACITY`].
    pub truncated: u64,
    /// Points sent that never came back from the core (ingest drops: counted by the core).
    pub lost: u64,
    /// Wire packets sent (config packets included).
    pub packets: u64,
    /// Bytes sent.
    pub bytes: u64,
}

impl ReplayCounters {
    /// Adds `o`'s counts to these.
    pub fn add(&mut self, o: &ReplayCounters) {
        self.points_sent += o.points_sent;
        self.scanlines += o.scanlines;
        self.kept += o.kept;
        self.irregular += o.irregular;
        self.no_neighbour += o.no_neighbour;
        self.truncated += o.truncated;
        self.lost += o.lost;
        self.packets += o.packets;
        self.bytes += o.bytes;
    }
}

/// The core's results per source point, and its seed candidates.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct KernelResults {
    /// ρ on the smoothed line, degrees (0 unless kept).
    pub rho_deg: Vec<f32>,
    /// The core's status per point; `None` for points it never returned.
    pub status: Vec<Option<PointStatus>>,
    /// Global scanline number, meaningful where the status is `Some`.
    pub scanline: Vec<u32>,
    /// Seed candidates, in scanline order.
    pub candidates: Vec<Candidate>,
    /// Scanlines numbered (the next run's numbers start here).
    pub lines: u32,
    /// Counters.
    pub counters: ReplayCounters,
}

/// The chunk ranges (cut at line starts, independent of the thread count).
pub fn chunks(cols: &PointColumns, rule: &LineRule, chunk_points: usize) -> Vec<Range<usize>> {
    chunks_in(cols, 0..cols.len(), rule, chunk_points)
}

/// [`chunks`] of the points `range` of `cols` (`range.start` taken as a line start).
fn chunks_in(
    cols: &PointColumns,
    range: Range<usize>,
    rule: &LineRule,
    chunk_points: usize,
) -> Vec<Range<usize>> {
    let n = range.end.min(cols.len());
    if !rule.flags_lines() || range.start >= n {
        return std::iter::once(range.start..n.max(range.start)).collect();
    }
    let mut out = Vec::new();
    let mut a = range.start;
    while a < n {
        let mut b = (a + chunk_points.max(1)).min(n);
        while b < n && !rule.is_start(b, &cols.scan_angle_deg, &cols.t) {
            b += 1;
        }
        out.push(a..b);
        a = b;
    }
    out
}

fn ns_of(t: f64, index: usize) -> Result<u64, ReplayError> {
    if t < 0.0 {
        return Err(ReplayError::NegativeTime { index, t });
    }
    Ok((t * 1e9).round() as u64)
}

/// Encodes the points `range` into the wire stream: a config packet with `words`, then
/// point packets of up to `MAX_POINTS_PER_PACKET` points. Each packet's base time is its
/// first point's GPS time in ns; a packet is closed early when the next point's offset would
/// not fit `dt_ns: u32` (4.29 s). Calls `sink` with every packet's bytes.
pub fn encode_stream(
    cols: &PointColumns,
    range: Range<usize>,
    traj: &Trajectory,
    words: &[u32; CONFIG_WORDS],
    rule: &LineRule,
    sink: &mut dyn FnMut(&[u8]) -> Result<(), ReplayError>,
) -> Result<(), ReplayError> {
    let mut enc = StreamEncoder::new();
    let mut buf = vec![0u8; MAX_PACKET_LEN];
    let n = enc
        .encode_config(words, &mut buf)
        .map_err(ReplayError::Encode)?;
    sink(&buf[..n])?;
    let mut cur = PoseCursor::new(traj);
    let mut recs: Vec<PointRecord> = Vec::with_capacity(MAX_POINTS_PER_PACKET);
    let mut base_ns = 0u64;
    for i in range {
        let t = cols.t[i];
        let t_ns = ns_of(t, i)?;
        let (xp, zp) = project_point(&mut cur, cols.x[i], cols.y[i], cols.z[i], t)
            .ok_or(ReplayError::Uncovered { index: i, t })?;
        let dt = t_ns
            .checked_sub(base_ns)
            .and_then(|d| u32::try_from(d).ok());
        let dt = match dt {
            Some(d) if !recs.is_empty() && recs.len() < MAX_POINTS_PER_PACKET => d,
            _ => {
                if !recs.is_empty() {
                    let m = enc
                        .encode_points(base_ns, &recs, &mut buf)
                        .map_err(ReplayError::Encode)?;
                    sink(&buf[..m])?;
                    recs.clear();
                }
                base_ns = t_ns;
                0
            }
        };
        recs.push(PointRecord {
            dt_ns: dt,
            x_m: xp as f32,
            z_m: zp as f32,
            intensity: cols.intensity[i],
            line_start: rule.is_start(i, &cols.scan_angle_deg, &cols.t),
            tag: i as u32,
        });
    }
    if !recs.is_empty() {
        let m = enc
            .encode_points(base_ns, &recs, &mut buf)
            .map_err(ReplayError::Encode)?;
        sink(&buf[..m])?;
    }
    Ok(())
}

std::thread_local! {
    /// The pipeline this thread ran its last chunk through: a stream runs a chunk every
    /// 2^14 points, and a fresh allocation per chunk has the kernel map and zero its few
    /// MB again each time (restarting it rewrites no buffer either).
    static PIPELINE: std::cell::Cell<Option<Box<HostPipeline>>> =
        const { std::cell::Cell::new(None) };
}

/// A pipeline in its starting state: this thread's last one, reset, or a new one.
fn take_pipeline() -> Box<HostPipeline> {
    match PIPELINE.take() {
        Some(mut p) => {
            p.restart();
            p
        }
        None => Box::default(),
    }
}

/// One chunk's results, before the scanline numbers are made global.
struct ChunkOut {
    lines: u32,
    candidates: Vec<Candidate>,
    counters: ReplayCounters,
}

/// A chunk's share of the per-point outputs.
struct ChunkSlices<'a> {
    rho: &'a mut [f32],
    status: &'a mut [Option<PointStatus>],
    line: &'a mut [u32],
}

/// Point `i` as the core's assembler takes it on the direct path: its time in ns and the
/// record [`encode_stream`] would have sent (`dt_ns` unused). A coordinate that is not
/// finite as `f32` is the error the encoder gives on the wire path.
#[inline]
fn direct_point(
    cols: &PointColumns,
    i: usize,
    cur: &mut PoseCursor<'_>,
    rule: &LineRule,
) -> Result<(u64, PointRecord), ReplayError> {
    let t = cols.t[i];
    let t_ns = ns_of(t, i)?;
    let (xp, zp) = project_point(cur, cols.x[i], cols.y[i], cols.z[i], t)
        .ok_or(ReplayError::Uncovered { index: i, t })?;
    let (x_m, z_m) = (xp as f32, zp as f32);
    if !x_m.is_finite() || !z_m.is_finite() {
        return Err(ReplayError::Encode(
            curbtrace_core::wire::EncodeError::NonFinite { index: i },
        ));
    }
    Ok((
        t_ns,
        PointRecord {
            dt_ns: 0,
            x_m,
            z_m,
            intensity: cols.intensity[i],
            line_start: rule.is_start(i, &cols.scan_angle_deg, &cols.t),
            tag: i as u32,
        },
    ))
}

fn run_chunk(
    cols: &PointColumns,
    range: Range<usize>,
    traj: &Trajectory,
    words: &[u32; CONFIG_WORDS],
    rule: &LineRule,
    wire: bool,
    slices: ChunkSlices<'_>,
) -> Result<ChunkOut, ReplayError> {
    let ChunkSlices { rho, status, line } = slices;
    let start = range.start;
    let mut pipe = take_pipeline();
    let mut out = ChunkOut {
        lines: 0,
        candidates: Vec::new(),
        counters: ReplayCounters::default(),
    };
    let mut collect = |o: &ScanlineOutput<'_>, out: &mut ChunkOut| {
        out.lines = out.lines.max(o.index.saturating_add(1));
        out.counters.scanlines += 1;
        out.counters.truncated += u64::from(o.truncated);
        for (k, &tag) in o.tag.iter().enumerate() {
            let Some(j) = (tag as usize).checked_sub(start).filter(|&j| j < rho.len()) else {
                continue;
            };
            rho[j] = o.rho_deg[k];
            status[j] = Some(o.status[k]);
            line[j] = o.index;
        }
        out.counters.kept += u64::from(o.counters.kept);
        out.counters.irregular += u64::from(o.counters.irregular);
        out.counters.no_neighbour += u64::from(o.counters.no_neighbour);
        for (idx, side) in [(o.left, Side::Left), (o.right, Side::Right)] {
            if let Some(&tag) = idx.and_then(|k| o.tag.get(usize::from(k))) {
                out.candidates.push(Candidate {
                    point: tag,
                    side,
                    scanline: o.index,
                });
            }
        }
    };
    if wire {
        let mut packets = 0u64;
        let mut bytes = 0u64;
        encode_stream(cols, range.clone(), traj, words, rule, &mut |b: &[u8]| {
            packets += 1;
            bytes += b.len() as u64;
            let mut off = 0;
            while off < b.len() {
                let w = pipe.write(&b[off..]);
                off += w;
                pipe.run(|o| collect(o, &mut out));
                if w == 0 && off < b.len() {
                    // The ring is full and processing every complete line freed nothing.
                    let w2 = pipe.write(&b[off..]);
                    if w2 == 0 {
                        return Err(ReplayError::Stalled);
                    }
                    off += w2;
                }
            }
            Ok(())
        })?;
        out.counters.packets = packets;
        out.counters.bytes = bytes;
    } else {
        pipe.push_config(words, |o| collect(o, &mut out));
        let mut cur = PoseCursor::new(traj);
        for i in range.clone() {
            let p = direct_point(cols, i, &mut cur, rule)?;
            pipe.push_point(p.0, &p.1, |o| collect(o, &mut out));
        }
    }
    pipe.finish(|o| collect(o, &mut out));
    PIPELINE.set(Some(pipe));
    out.counters.points_sent = range.len() as u64;
    Ok(out)
}

/// The pool that runs pipelines, built once per process: a stream calls
/// [`run_kernel_with_rule`] once per batch, and a pool per call started and ended its
/// threads every 2^15 points. A pool of our own, not rayon's global one: a pipeline holds a
/// few MB of fixed buffers, more than rayon's default 2 MiB worker stacks take in a debug
/// build.
fn pipeline_pool() -> Result<&'static rayon::ThreadPool, ReplayError> {
    static POOL: std::sync::OnceLock<Result<rayon::ThreadPool, String>> =
        std::sync::OnceLock::new();
    POOL.get_or_init(|| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(rayon::current_num_threads())
            .stack_size(PIPELINE_STACK)
            .thread_name(|i| format!("ct-core-{i}"))
            .build()
            .map_err(|e| e.to_string())
    })
    .as_ref()
    .map_err(|e| ReplayError::Io(std::io::Error::other(e.clone())))
}

/// Runs every point of `cols` (all inside `traj`'s time range) through the core and
/// collects its results per point. `progress` is called with points done so far.
pub fn run_kernel(
    cols: &PointColumns,
    traj: &Trajectory,
    words: &[u32; CONFIG_WORDS],
    params: &ReplayParams,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<KernelResults, ReplayError> {
    let rule = LineRule::choose(&cols.scan_angle_deg, &cols.t, &params.line());
    run_kernel_with_rule(cols, traj, words, params, &rule, progress)
}

/// [`run_kernel`] with the line-start rule given (a stream chooses it once, on its first
/// batch, and keeps it).
pub fn run_kernel_with_rule(
    cols: &PointColumns,
    traj: &Trajectory,
    words: &[u32; CONFIG_WORDS],
    params: &ReplayParams,
    rule: &LineRule,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<KernelResults, ReplayError> {
    run_kernel_on(cols, 0..cols.len(), traj, words, params, rule, progress)
}

/// [`run_kernel_with_rule`] on the points `range` of `cols` (`range.start` a line start):
/// the results are indexed from `range.start`, candidates included. A stream runs the
/// reader's columns in place this way instead of copying the points it runs.
pub fn run_kernel_on(
    cols: &PointColumns,
    range: Range<usize>,
    traj: &Trajectory,
    words: &[u32; CONFIG_WORDS],
    params: &ReplayParams,
    rule: &LineRule,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<KernelResults, ReplayError> {
    let rule = *rule;
    let ranges = chunks_in(cols, range.clone(), &rule, params.chunk_points);
    let n = ranges.iter().map(|r| r.len()).sum();
    let first = u32::try_from(range.start).unwrap_or(u32::MAX);
    let mut rho = vec![0f32; n];
    let mut status = vec![None; n];
    let mut scanline = vec![0u32; n];
    // Disjoint output slices per chunk.
    let mut parts = Vec::with_capacity(ranges.len());
    {
        let (mut r, mut s, mut l) = (&mut rho[..], &mut status[..], &mut scanline[..]);
        for rg in &ranges {
            let (r1, r2) = r.split_at_mut(rg.len());
            let (s1, s2) = s.split_at_mut(rg.len());
            let (l1, l2) = l.split_at_mut(rg.len());
            parts.push((rg.clone(), r1, s1, l1));
            (r, s, l) = (r2, s2, l2);
        }
    }
    let done = std::sync::atomic::AtomicU64::new(0);
    let pool = pipeline_pool()?;
    let outs: Vec<Result<ChunkOut, ReplayError>> = pool.install(|| {
        parts
            .into_par_iter()
            .map(|(rg, r, s, l)| {
                let len = rg.len() as u64;
                let o = run_chunk(
                    cols,
                    rg,
                    traj,
                    words,
                    &rule,
                    params.wire,
                    ChunkSlices {
                        rho: r,
                        status: s,
                        line: l,
                    },
                );
                let d = done.fetch_add(len, std::sync::atomic::Ordering::Relaxed) + len;
                progress(d);
                o
            })
            .collect()
    });
    let mut counters = ReplayCounters::default();
    let mut candidates = Vec::new();
    let mut bases = Vec::with_capacity(outs.len());
    let mut base = 0u32;
    for o in outs {
        let o = o?;
        bases.push(base);
        counters.add(&o.counters);
        candidates.extend(o.candidates.into_iter().map(|c| Candidate {
            scanline: c.scanline + base,
            point: c.point - first,
            ..c
        }));
        base = base.saturating_add(o.lines);
    }
    // Make the per-point scanline numbers global, chunk by chunk.
    let mut rest = &mut scanline[..];
    let mut slices = Vec::with_capacity(ranges.len());
    for rg in &ranges {
        let (a, b) = rest.split_at_mut(rg.len());
        slices.push(a);
        rest = b;
    }
    slices
        .into_par_iter()
        .zip(bases.par_iter())
        .for_each(|(sl, &b)| {
            if b > 0 {
                sl.iter_mut().for_each(|v| *v += b);
            }
        });
    let returned = status.iter().filter(|s| s.is_some()).count() as u64;
    counters.lost =
        counters.points_sent - returned - counters.truncated.min(counters.points_sent - returned);
    Ok(KernelResults {
        rho_deg: rho,
        status,
        scanline,
        candidates,
        lines: base,
        counters,
    })
}
