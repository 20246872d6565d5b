//! `curbtrace extract` as one stream in bounded memory:
//!
//! ```text
//! source (reader thread) ──► core (thread; chunks in parallel) ──► window + tracker ──► merge ──► edges
//! LAS/LAZ files in time      projection, wire, Pipeline;           sections along the    pieces joined
//! order, batches of points   whole lines only, the partial         route, closed as the  across section
//! with their channel key     last line carried on                  vehicle passes them   boundaries
//! ```
//!
//! The stages are joined by bounded channels (a batch from the reader, a few batches'
//! points from the core stage, [`queue`]), so decoding and the core run beside the
//! tracker, and memory holds a few batches and one window:
//! it does not grow with the input. Inputs not in time order are detected by the source
//! and the run starts again on a chunk-wise external sort (see `source::external_sort`).
//!
//! - [`core_stage`] — the core stage (batches cut at line starts).
//! - [`ring_stage`] — the core stage of a spinning sensor's file (every ring a channel,
//!   every half revolution of a ring a scanline).
//! - [`window`] — sections along the route, the bend method per window.
//! - [`merge`] — joining pieces at section boundaries.
//! - [`passes`] — a trajectory that drives the same road again cut into passes.
//! - [`fuse`] — the edges of several scanners (channels) and passes made one edge per curb.
//! - [`tasks`] — the campaign cut into independent tasks of whole sections, merged after.
//! - [`queue`] — a channel bounded by the points it holds.

pub mod core_stage;
pub mod fuse;
pub mod malloc;
pub mod merge;
pub mod passes;
pub mod queue;
pub mod ring_stage;
pub mod tasks;
pub mod window;

use crate::config::{Config, ConfigError};
use crate::io::las_in::ReadOptions;
use crate::io::trajectory::{Trajectory, MIN_COVERED_FRACTION};
use crate::model::EdgeLine;
use crate::pipeline::{
    ExtractError, ExtractOptions, ExtractResult, Method, Progress, StageCpu, StageTimes, Summary,
};
use crate::proc_stats::{named_threads_cpu_s, peak_rss_bytes, process_cpu_s, thread_cpu_s};
use crate::replay::run::ReplayCounters;
use crate::source::campaign::{Campaign, SourceError};
use crate::source::external_sort::{SortedRuns, RUN_POINTS};
use crate::source::Source;
use crate::source::{PointBatch, BATCH_POINTS};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::sync_channel;
use std::time::Instant;
pub use window::WindowParams;

/// Points per batch the reader hands to the core stage.
pub const STREAM_BATCH_POINTS: usize = BATCH_POINTS;

/// Batches the reader may decode ahead of the core stage (about 1.3 MB each). The reader
/// keeps pace with the core stage; the room for the decoder to run on while the window
/// runs a section is after the core ([`WINDOW_QUEUE_POINTS`]).
const READ_AHEAD_BATCHES: usize = 1;

/// Points the core stage may run ahead of the window (about 41 B each). The window runs a
/// section at a time, and the parts of a section that run on one thread held up the core
/// stage and, through it, the reader: with room for the core's output the decoder and
/// the core keep running beside a section, and a batch waiting there has had both the
/// decoder's and the core's work done (docs/benchmarks.md).
const WINDOW_QUEUE_POINTS: usize = 5 * STREAM_BATCH_POINTS;

/// What one pass over a source produced.
struct Pass {
    edges: Vec<EdgeLine>,
    counters: ReplayCounters,
    arcs: Option<crate::rings::ArcCounters>,
    dropped: (u64, u64),
    points: u64,
    time_span: Option<(f64, f64)>,
    candidates: u64,
    capped_points: u64,
    times: StageTimes,
}

/// Extracts road edges with the bend method from one or many LAS/LAZ files (files,
/// directories or glob patterns) and their trajectory, streaming in bounded memory.
///
/// The trajectory is the vehicle's reference point; each scanner's origin is it moved by
/// the scanner's mount (`[scanners]` in `cfg`, zero where none is given). Points of several
/// scanners (LAS 1.4 scanner channels) without `opts.scanner` are extracted scanner by
/// scanner, each through a core and a tracker of its own, and fused ([`fuse`]).
pub fn extract(
    inputs: &[PathBuf],
    traj_path: &Path,
    cfg: &Config,
    opts: &ExtractOptions,
    window: &WindowParams,
    progress: &Progress,
) -> Result<ExtractResult, ExtractError> {
    if opts.method != Method::Bend {
        return Err(ExtractError::Method(opts.method.as_str().into()));
    }
    let traj = Trajectory::read_csv(traj_path)?;
    let all_passes = passes::passes(&traj);
    let passes: Vec<usize> = match opts.pass {
        None => (0..all_passes.len()).collect(),
        Some(k) if usize::from(k) < all_passes.len() => vec![usize::from(k)],
        Some(k) => {
            return Err(ExtractError::Stream {
                path: traj_path.to_path_buf(),
                what: format!(
                    "--pass {k}: the trajectory holds {} pass(es), numbered from 0",
                    all_passes.len()
                ),
            })
        }
    };
    if all_passes.len() > 1 || opts.pass.is_some() {
        let keys = match opts.scanner {
            Some(k) => vec![k],
            None => scanner_channels(inputs)?,
        };
        let r = extract_fused(
            inputs,
            &all_passes,
            &passes,
            &keys,
            traj_path,
            cfg,
            opts,
            window,
            progress,
        )?;
        return Ok(finish(r));
    }
    let origin = cfg.scanners.get(opts.scanner.unwrap_or(0)).apply(&traj);
    let result = match extract_channel(
        inputs, &origin, traj_path, cfg, opts, window, progress, true,
    ) {
        Err(ExtractError::Source(SourceError::Las(
            crate::io::las_in::LasError::SeveralScanners { channels, .. },
        ))) if opts.scanner.is_none() => {
            let keys: Vec<u16> = channels.into_iter().map(u16::from).collect();
            extract_fused(
                inputs,
                &all_passes,
                &[0],
                &keys,
                traj_path,
                cfg,
                opts,
                window,
                progress,
            )?
        }
        other => other?,
    };
    Ok(finish(result))
}

/// The closed edges of `result` cut into stretches, its summary's edge count and length.
fn finish(mut result: ExtractResult) -> ExtractResult {
    // The closed edges, cut into stretches of one class and one kind of support.
    result.edges = crate::curb::finish(std::mem::take(&mut result.edges));
    for e in &mut result.edges {
        e.method
            .get_or_insert_with(|| Method::Bend.as_str().to_string());
    }
    result.summary.edges = result.edges.len() as u64;
    result.summary.total_length_m = result.edges.iter().map(|e| e.length_m()).sum();
    result
}

/// The scanner channels of the input: `[0]` when it holds one scanner's points (or reads
/// them by point source id), the channels in use otherwise.
fn scanner_channels(inputs: &[PathBuf]) -> Result<Vec<u16>, ExtractError> {
    let read = ReadOptions { scanner: None };
    let mut c = Campaign::open(inputs, &read).map_err(ExtractError::Source)?;
    match c.next_batch(STREAM_BATCH_POINTS) {
        Err(SourceError::Las(crate::io::las_in::LasError::SeveralScanners {
            channels, ..
        })) => Ok(channels.into_iter().map(u16::from).collect()),
        _ => Ok(vec![0]),
    }
}

/// Every scanner of `keys` in the passes `which` of `passes` through a core and a tracker
/// of its own; the edges of a later pass turned to the first pass's direction where it
/// drove against it and shifted onto the first pass's edges (the GNSS drift between
/// passes, [`passes::shift_onto`]); all fused ([`fuse`]). The summary adds up the runs'; a
/// point outside the passes' trajectories is counted once, before the first or after the
/// last.
#[allow(clippy::too_many_arguments)]
fn extract_fused(
    inputs: &[PathBuf],
    passes: &[Trajectory],
    which: &[usize],
    keys: &[u16],
    traj_path: &Path,
    cfg: &Config,
    opts: &ExtractOptions,
    window: &WindowParams,
    progress: &Progress,
) -> Result<ExtractResult, ExtractError> {
    let mut per = Vec::with_capacity(keys.len() * passes.len());
    let mut all: Option<ExtractResult> = None;
    let mut kept = 0u64;
    let (mut read, mut before) = (0u64, 0u64);
    // The first pass's edges of every scanner, to shift later passes onto.
    let mut first_edges: Vec<EdgeLine> = Vec::new();
    for (n, &k) in which.iter().enumerate() {
        let pass = &passes[k];
        let turn = (k > 0).then(|| passes::Orientation::new(&passes[0], pass));
        let mut this: Vec<(fuse::Source, Vec<EdgeLine>)> = Vec::new();
        for &key in keys {
            let one = ExtractOptions {
                scanner: (keys.len() > 1 || opts.scanner.is_some()).then_some(key),
                ..*opts
            };
            let origin = cfg.scanners.get(key).apply(pass);
            let alone = which.len() == 1 && passes.len() == 1;
            let r = extract_channel(
                inputs, &origin, traj_path, cfg, &one, window, progress, alone,
            )?;
            let s = &r.summary;
            let points =
                s.las.points_selected - s.dropped_before_trajectory - s.dropped_after_trajectory;
            kept += points;
            if n == 0 {
                read += s.las.points_selected;
                before += s.dropped_before_trajectory;
            }
            let edges = match &turn {
                None => r.edges.clone(),
                Some(o) => r
                    .edges
                    .iter()
                    .map(|e| {
                        let mid = e.points[e.points.len() / 2];
                        if o.reversed_at([mid[0], mid[1]]) {
                            e.reversed()
                        } else {
                            e.clone()
                        }
                    })
                    .collect(),
            };
            let src = fuse::Source {
                scanner: key,
                pass: k as u16,
            };
            this.push((src, edges));
            all = Some(match all {
                None => r,
                Some(a) => fuse::add_summaries(a, &r),
            });
        }
        if k == 0 {
            first_edges = this.iter().flat_map(|(_, e)| e.iter().cloned()).collect();
        } else if which.len() > 1 {
            let mine: Vec<EdgeLine> = this.iter().flat_map(|(_, e)| e.iter().cloned()).collect();
            if let Some(t) = passes::shift_onto(&first_edges, &mine) {
                for (_, e) in &mut this {
                    passes::shifted(e, t);
                }
            }
        }
        per.extend(this);
    }
    let mut r = all.ok_or_else(|| ExtractError::Stream {
        path: inputs.first().cloned().unwrap_or_default(),
        what: "no scanner channel to read".into(),
    })?;
    if which.len() > 1 || passes.len() > 1 {
        // Every pass read every point: count each point once.
        let s = &mut r.summary;
        s.las.points_selected = read;
        s.dropped_before_trajectory = before;
        s.dropped_after_trajectory = read.saturating_sub(kept + before);
        if which.len() == passes.len()
            && (kept == 0 || (kept as f64) < MIN_COVERED_FRACTION * read as f64)
        {
            let first = inputs.first().cloned().unwrap_or_default();
            let full = Trajectory::read_csv(traj_path)?;
            return Err(ExtractError::Trajectory(full.not_covering(
                traj_path,
                &first,
                (f64::NAN, f64::NAN),
                kept as usize,
                read as usize,
            )));
        }
    }
    let params = fuse::FuseParams {
        min_length_m: cfg.bend.min_edge_length_m,
        ..fuse::FuseParams::default()
    };
    r.edges = if per.len() == 1 {
        per.pop().map(|(_, e)| e).unwrap_or_default()
    } else {
        fuse::fuse(per, &params)
    };
    Ok(r)
}

/// [`extract`] of one channel (or of every point, one scanner) with the scanner origin's
/// trajectory `traj`: the closed edges before they are cut into stretches. `whole`: `traj`
/// is the whole trajectory, which must cover most points (a pass's covers its own).
#[allow(clippy::too_many_arguments)]
fn extract_channel(
    inputs: &[PathBuf],
    traj: &Trajectory,
    traj_path: &Path,
    cfg: &Config,
    opts: &ExtractOptions,
    window: &WindowParams,
    progress: &Progress,
    whole: bool,
) -> Result<ExtractResult, ExtractError> {
    // laz-rs decompresses on rayon's global pool, which nothing else in the stream uses
    // (the window runs on its own pool): its threads are named for the reader when the
    // process has not built it yet.
    let _ = rayon::ThreadPoolBuilder::new()
        .thread_name(|i| format!("{READ_THREADS}-{i}"))
        .build_global();
    let start = Instant::now();
    let cpu0 = process_cpu_s();
    let words = cfg.kernel_words().map_err(|what| ConfigError::Kernel {
        path: PathBuf::from("(config)"),
        what,
    })?;
    let read = ReadOptions {
        scanner: opts.scanner,
    };
    let mut campaign = Campaign::open(inputs, &read).map_err(ExtractError::Source)?;
    let info = campaign.info().clone();
    let first = info.files.first().cloned().unwrap_or_default();
    if info.ring.is_none() {
        // A spinning sensor's points without their ring cannot be cut into scanlines. A
        // first batch out of time order is read again without the order check (the check
        // puts it in time order itself).
        let head = match campaign.next_batch(STREAM_BATCH_POINTS) {
            Err(SourceError::OutOfOrder { .. }) => Campaign::open(inputs, &read)
                .and_then(|c| c.unchecked().next_batch(STREAM_BATCH_POINTS))
                .map_err(ExtractError::Source)?,
            other => other.map_err(ExtractError::Source)?,
        };
        if let Some(b) = head {
            if ring_stage::looks_spinning(&b, traj) {
                return Err(ExtractError::Stream {
                    path: first,
                    what: format!(
                        "the points look like a spinning multi-beam lidar's (many beams fired at once) but carry no ring: add the laser number as an extra-bytes dimension named {} (docs/spec.md, Spinning sensors)",
                        crate::source::las_batches::RING_NAMES.join(", ")
                    ),
                });
            }
        }
    }
    drop(campaign);
    let rings = info.ring.is_some();
    let window = &stage_window(window, cfg, rings);
    let mut sorted: Option<SortedRuns> = None;
    let mut reordered = false;
    let pass = loop {
        // The `las` reader is not `Send`: the reader thread opens the files itself.
        let spec = match sorted.take() {
            Some(runs) => SourceSpec::Sorted(runs, info.clone()),
            None => SourceSpec::Files(inputs.to_vec(), read),
        };
        match run_pass(spec, traj, &words, cfg, window, progress, info.bytes, rings) {
            Ok((pass, sel)) => break (pass, sel),
            Err(PassError::Source(SourceError::OutOfOrder { .. })) if !reordered => {
                // Start again on the sorted runs.
                reordered = true;
                progress.stage("sorting", 0);
                let c = Campaign::open(inputs, &read).map_err(ExtractError::Source)?;
                sorted = Some(SortedRuns::build(c, RUN_POINTS).map_err(ExtractError::Source)?);
            }
            Err(PassError::Source(e)) => return Err(ExtractError::Source(e)),
            Err(PassError::Core(e)) => {
                return Err(ExtractError::Stream {
                    path: first,
                    what: e.to_string(),
                })
            }
        }
    };
    let (pass, selection) = pass;
    let read = pass.points + pass.dropped.0 + pass.dropped.1;
    if whole && (pass.points == 0 || (pass.points as f64) < MIN_COVERED_FRACTION * read as f64) {
        let span = pass.time_span.unwrap_or((f64::NAN, f64::NAN));
        return Err(ExtractError::Trajectory(traj.not_covering(
            traj_path,
            &first,
            span,
            pass.points as usize,
            read as usize,
        )));
    }
    progress.finish();
    let mut times = pass.times;
    times.total_s = start.elapsed().as_secs_f64();
    times.cpu.total_s = process_cpu_s() - cpu0;
    times.cpu.peak_rss = [0, 0, peak_rss_bytes()];
    let selected = pass.points + pass.dropped.0 + pass.dropped.1;
    let summary = Summary {
        las: info.las_info(selected, selection, reordered),
        dropped_before_trajectory: pass.dropped.0,
        dropped_after_trajectory: pass.dropped.1,
        dropped_by_window_cap: pass.capped_points,
        arcs: pass.arcs,
        core: pass.counters,
        candidates: pass.candidates,
        edges: pass.edges.len() as u64,
        total_length_m: pass.edges.iter().map(|e| e.length_m()).sum(),
        times,
    };
    Ok(ExtractResult {
        crs: info.crs.clone(),
        edges: pass.edges,
        summary,
    })
}

/// The section window for a stage's output. Curbs within the arcs' reach ahead and behind
/// are seen from the vehicle's stations that far away: with `rings` the window holds that
/// much more road.
pub(super) fn stage_window(window: &WindowParams, cfg: &Config, rings: bool) -> WindowParams {
    WindowParams {
        margin_m: window.margin_m
            + if rings {
                f64::from(cfg.rings.max_reach_m)
            } else {
                0.0
            },
        // The arcs' reach covers what the rings see ahead: no side store.
        lead_max_m: if rings { 0.0 } else { window.lead_max_m },
        ..*window
    }
}

/// The bend method's parameters for a stage's output: `[bend]`, with, when `rings`, the
/// tracker's search radius, stop threshold and far-leg toes from `[rings]` (`track_*`) and
/// the view past the points' ends from the half-arc cut's limits (`bend::seed::end_seeds`).
pub(super) fn stage_bend(cfg: &Config, rings: bool) -> crate::bend::BendParams {
    let mut bend = cfg.bend.clone();
    if rings {
        bend.search_radius_m = f64::from(cfg.rings.track_search_radius_m);
        bend.stop_rho_deg = f64::from(cfg.rings.track_stop_rho_deg);
        bend.leg_toes = cfg.rings.track_leg_toes;
        bend.end_view = Some(crate::bend::EndView {
            near_m: f64::from(cfg.rings.min_range_m),
            reach_m: f64::from(cfg.rings.max_reach_m),
            max_azimuth_deg: f64::from(cfg.rings.max_azimuth_deg),
        });
    }
    bend
}

/// What a core stage counted: its counters, points dropped before / after the trajectory,
/// points kept, the time span read, the half-arc cut's counters (rings only).
type StageTotals = (
    ReplayCounters,
    (u64, u64),
    u64,
    Option<(f64, f64)>,
    Option<crate::rings::ArcCounters>,
);

/// The core stage: scanlines of a profiler, or rings of a spinning sensor.
pub(super) enum Stage<'a> {
    Lines(Box<core_stage::CoreStage<'a>>),
    Rings(Box<ring_stage::RingStage<'a>>),
}

impl<'a> Stage<'a> {
    /// The stage for `traj`: rings of a spinning sensor when `rings`, scanlines otherwise.
    pub(super) fn new(
        traj: &'a Trajectory,
        words: &[u32; curbtrace_core::kernel::CONFIG_WORDS],
        cfg: &Config,
        rings: bool,
    ) -> Self {
        if rings {
            Stage::Rings(Box::new(
                ring_stage::RingStage::new(traj, cfg.rings, None).through_wire(cfg.replay.wire),
            ))
        } else {
            Stage::Lines(Box::new(core_stage::CoreStage::new(
                traj, *words, cfg.replay,
            )))
        }
    }

    /// Points kept so far.
    pub(super) fn points(&self) -> u64 {
        match self {
            Stage::Lines(s) => s.points,
            Stage::Rings(s) => s.points,
        }
    }

    pub(super) fn push(
        &mut self,
        b: PointBatch,
    ) -> Result<Vec<core_stage::CoreBatch>, core_stage::CoreError> {
        match self {
            Stage::Lines(s) => s.push(b),
            Stage::Rings(s) => s.push(b).map(|o| o.into_iter().collect()),
        }
    }

    pub(super) fn finish(
        &mut self,
    ) -> Result<Option<core_stage::CoreBatch>, core_stage::CoreError> {
        match self {
            Stage::Lines(s) => s.finish(),
            Stage::Rings(s) => s.finish(),
        }
    }

    /// Counters, points dropped before / after the trajectory, points kept, time span,
    /// the half-arc cut's counters.
    fn totals(&self) -> StageTotals {
        match self {
            Stage::Lines(s) => (
                s.counters,
                s.intake.dropped,
                s.points,
                s.intake.time_span,
                None,
            ),
            Stage::Rings(s) => (
                s.counters,
                s.intake.dropped,
                s.points,
                s.intake.time_span,
                Some(s.arc_counters()),
            ),
        }
    }
}

/// What the reader thread opens.
enum SourceSpec {
    Files(Vec<PathBuf>, ReadOptions),
    Sorted(SortedRuns, crate::source::campaign::InputInfo),
}

impl SourceSpec {
    fn open(self) -> Result<Source, SourceError> {
        Ok(match self {
            SourceSpec::Files(inputs, read) => {
                Source::Files(Box::new(Campaign::open(&inputs, &read)?))
            }
            SourceSpec::Sorted(runs, info) => Source::Sorted(runs, Box::new(info)),
        })
    }
}

enum PassError {
    Source(SourceError),
    Core(core_stage::CoreError),
}

/// Name of the reader thread and the prefix of its decoder pool's threads.
const READ_THREADS: &str = "ct-read";

/// Prefix of the threads of the pool the window's sections run on.
const EDGES_THREADS: &str = "ct-edges";

/// The pool the window runs its sections on (the profile seeds and the cross-sections
/// spread over its threads), built once per process, so that its threads' CPU counts as
/// the edges' and not as the decoder's on rayon's global pool. `None` when no pool could
/// be built: the window then runs on the calling thread and the global pool.
fn edges_pool() -> Option<&'static rayon::ThreadPool> {
    static POOL: std::sync::OnceLock<Option<rayon::ThreadPool>> = std::sync::OnceLock::new();
    POOL.get_or_init(|| {
        rayon::ThreadPoolBuilder::new()
            .thread_name(|i| format!("{EDGES_THREADS}-{i}"))
            .stack_size(16 << 20)
            .build()
            .ok()
    })
    .as_ref()
}

/// `f` on the [`edges_pool`].
fn on_edges_pool<T: Send>(f: impl FnOnce() -> T + Send) -> T {
    match edges_pool() {
        Some(p) => p.install(f),
        None => f(),
    }
}

/// One pass: reader thread → core thread → window on this thread. CPU per stage: the
/// reader's is its thread's and the decoder's (rayon's global pool, threads named
/// [`READ_THREADS`] when the stream named them), the
/// edges' this thread's while it tracks and the [`edges_pool`]'s, the core's the rest of
/// the process's during the pass (the core thread and its pipeline pool).
#[allow(clippy::too_many_arguments)]
fn run_pass(
    spec: SourceSpec,
    traj: &Trajectory,
    words: &[u32; curbtrace_core::kernel::CONFIG_WORDS],
    cfg: &Config,
    window: &WindowParams,
    progress: &Progress,
    bytes_total: u64,
    rings: bool,
) -> Result<(Pass, crate::io::las_in::ScannerSelection), PassError> {
    progress.stage_bytes("extract", bytes_total);
    let cpu0 = process_cpu_s();
    let bytes_done = AtomicU64::new(0);
    let read_s = AtomicU64::new(0);
    let read_wait_s = AtomicU64::new(0);
    let core_s = AtomicU64::new(0);
    let read_thread_cpu = AtomicU64::new(0);
    std::thread::scope(|s| {
        let (tx_b, rx_b) = sync_channel::<Result<PointBatch, SourceError>>(READ_AHEAD_BATCHES);
        let (tx_c, rx_c) =
            queue::channel::<Result<core_stage::CoreBatch, PassError>>(WINDOW_QUEUE_POINTS);
        let bytes_done = &bytes_done;
        let (read_s, core_s, read_thread_cpu) = (&read_s, &core_s, &read_thread_cpu);
        let read_wait_s = &read_wait_s;
        let reader = std::thread::Builder::new()
            .name(READ_THREADS.into())
            .spawn_scoped(s, move || {
                let (mut busy, mut waiting) = (0.0, 0.0);
                let mut source = match spec.open() {
                    Ok(s) => s,
                    Err(e) => {
                        let _ = tx_b.send(Err(e));
                        return crate::io::las_in::ScannerSelection::All;
                    }
                };
                loop {
                    let t0 = Instant::now();
                    let b = source.next_batch(STREAM_BATCH_POINTS);
                    busy += t0.elapsed().as_secs_f64();
                    bytes_done.store(source.bytes_done(), Ordering::Relaxed);
                    let stop = !matches!(b, Ok(Some(_)));
                    let msg = match b {
                        Ok(Some(b)) => Ok(b),
                        Ok(None) => break,
                        Err(e) => Err(e),
                    };
                    let t0 = Instant::now();
                    let sent = tx_b.send(msg);
                    waiting += t0.elapsed().as_secs_f64();
                    if sent.is_err() || stop {
                        break;
                    }
                }
                read_s.store(busy.to_bits(), Ordering::Relaxed);
                read_wait_s.store(waiting.to_bits(), Ordering::Relaxed);
                read_thread_cpu.store(thread_cpu_s().to_bits(), Ordering::Relaxed);
                source.selection()
            })
            .expect("the reader thread starts");
        let core = std::thread::Builder::new()
            .name("ct-core".into())
            .spawn_scoped(s, move || {
                let mut stage = Stage::new(traj, words, cfg, rings);
                let mut busy = 0.0;
                for b in rx_b {
                    let b = match b {
                        Ok(b) => b,
                        Err(e) => {
                            let _ = tx_c.send(Err(PassError::Source(e)), 0);
                            return None;
                        }
                    };
                    let t0 = Instant::now();
                    let out = stage.push(b);
                    busy += t0.elapsed().as_secs_f64();
                    match out {
                        Ok(cs) => {
                            for c in cs {
                                let n = c.t.len();
                                if tx_c.send(Ok(c), n).is_err() {
                                    return None;
                                }
                            }
                        }
                        Err(e) => {
                            let _ = tx_c.send(Err(PassError::Core(e)), 0);
                            return None;
                        }
                    }
                }
                let t0 = Instant::now();
                match stage.finish() {
                    Ok(Some(c)) => {
                        let n = c.t.len();
                        let _ = tx_c.send(Ok(c), n);
                    }
                    Ok(None) => {}
                    Err(e) => {
                        let _ = tx_c.send(Err(PassError::Core(e)), 0);
                        return None;
                    }
                }
                busy += t0.elapsed().as_secs_f64();
                core_s.store(busy.to_bits(), Ordering::Relaxed);
                Some(stage.totals())
            })
            .expect("the core thread starts");
        // A spinning sensor's window is the arcs' reach wider, so a drive's last sections
        // (on a short drive, every one) wait for the end of the stream: they are extracted
        // side by side then, when the reader and the core have nothing left to do.
        let threads = if rings {
            std::thread::available_parallelism().map_or(1, |n| n.get())
        } else {
            1
        };
        let mut win =
            window::SectionWindow::new(traj, *window, stage_bend(cfg, rings)).finishing_on(threads);
        let mut edges = Vec::new();
        let mut candidates = 0u64;
        let mut err = None;
        let mut edges_s = 0.0;
        let mut edges_cpu = 0.0;
        let edges_pool_cpu0 = named_threads_cpu_s(EDGES_THREADS);
        for c in rx_c {
            progress.set(bytes_done.load(Ordering::Relaxed));
            match c {
                Ok(c) => {
                    candidates += c.candidates.len() as u64;
                    let (t0, c0) = (Instant::now(), thread_cpu_s());
                    edges.extend(on_edges_pool(|| win.push(c)));
                    edges_s += t0.elapsed().as_secs_f64();
                    edges_cpu += thread_cpu_s() - c0;
                }
                Err(e) => {
                    err = Some(e);
                    break;
                }
            }
        }
        // The reader thread has ended; its pool's threads still run.
        let selection = reader
            .join()
            .unwrap_or_else(|p| std::panic::resume_unwind(p));
        let core_out = core.join().unwrap_or_else(|p| std::panic::resume_unwind(p));
        if let Some(e) = err {
            return Err(e);
        }
        let Some((counters, dropped, points, time_span, arcs)) = core_out else {
            return Err(PassError::Core(core_stage::CoreError::Replay(
                crate::replay::run::ReplayError::Stalled,
            )));
        };
        let (t0, c0) = (Instant::now(), thread_cpu_s());
        edges.extend(on_edges_pool(|| win.finish()));
        edges_s += t0.elapsed().as_secs_f64();
        edges_cpu += thread_cpu_s() - c0 + named_threads_cpu_s(EDGES_THREADS) - edges_pool_cpu0;
        progress.set(bytes_total);
        let read_cpu = named_threads_cpu_s(READ_THREADS)
            + f64::from_bits(read_thread_cpu.load(Ordering::Relaxed));
        let total_cpu = process_cpu_s() - cpu0;
        let times = StageTimes {
            read_s: f64::from_bits(read_s.load(Ordering::Relaxed)),
            read_wait_s: f64::from_bits(read_wait_s.load(Ordering::Relaxed)),
            core_s: f64::from_bits(core_s.load(Ordering::Relaxed)),
            edges_s,
            cpu: StageCpu {
                read_s: read_cpu,
                core_s: (total_cpu - read_cpu - edges_cpu).max(0.0),
                edges_s: edges_cpu,
                ..StageCpu::default()
            },
            ..StageTimes::default()
        };
        Ok((
            Pass {
                edges,
                counters,
                arcs,
                dropped,
                points,
                time_span,
                candidates,
                capped_points: win.capped_points,
                times,
            },
            selection,
        ))
    })
}

#[cfg(test)]
mod stage_tests {
    use super::*;

    #[test]
    fn rings_take_the_trackers_radius_and_stop_from_the_rings_table() {
        let mut cfg = Config::default();
        cfg.rings.track_search_radius_m = 0.06;
        cfg.rings.track_stop_rho_deg = 22.5;
        // A profiler's file keeps `[bend]` as it is.
        assert_eq!(stage_bend(&cfg, false), cfg.bend);
        let b = stage_bend(&cfg, true);
        assert!(
            (b.search_radius_m - 0.06).abs() < 1e-6,
            "{}",
            b.search_radius_m
        );
        assert_eq!(b.stop_rho_deg, 22.5);
        assert!(
            cfg.bend.leg_toes && !b.leg_toes,
            "far-leg toes on profilers only"
        );
        let view = b.end_view.expect("rings see past the points' ends");
        assert_eq!(view.reach_m, f64::from(cfg.rings.max_reach_m));
        assert_eq!(view.max_azimuth_deg, f64::from(cfg.rings.max_azimuth_deg));
        // Nothing else changes.
        let back = crate::bend::BendParams {
            search_radius_m: cfg.bend.search_radius_m,
            stop_rho_deg: cfg.bend.stop_rho_deg,
            leg_toes: cfg.bend.leg_toes,
            end_view: None,
            ..b
        };
        assert_eq!(back, cfg.bend);
    }
}
