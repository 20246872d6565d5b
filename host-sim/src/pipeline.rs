//! The whole job of `curbtrace extract` as a library call (the demo and the tests call it):
//! read the points (columns, sorted by time) and the trajectory, drop and count the points
//! outside the trajectory, replay the rest through the core in-process, then seed, track
//! and filter edges (Honma et al. §2.6–2.7) from the core's output as it is.

use crate::bend::{self, BendInput};
use crate::config::{Config, ConfigError};
use crate::io::las_in::{self, LasError, LasInfo, PointColumns, ReadOptions};
use crate::io::trajectory::{Trajectory, TrajectoryError};
use crate::model::{Crs, EdgeLine};
use crate::proc_stats::{peak_rss_bytes, process_cpu_s};
use crate::replay::run::{self, KernelResults, ReplayCounters, ReplayError};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Errors of the whole extraction; every message names the file and the problem.
#[derive(Debug, thiserror::Error)]
pub enum ExtractError {
    /// Reading the point file.
    #[error(transparent)]
    Las(#[from] LasError),
    /// Reading the trajectory or matching it to the points.
    #[error(transparent)]
    Trajectory(#[from] TrajectoryError),
    /// The config file.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// Replaying through the core.
    #[error("{path}: replay through the core: {source}")]
    Replay {
        /// The point file.
        path: PathBuf,
        /// The cause.
        source: ReplayError,
    },
    /// Reading the point files of a stream.
    #[error(transparent)]
    Source(crate::source::campaign::SourceError),
    /// The stream's core stage.
    #[error("{path}: {what}")]
    Stream {
        /// The (first) point file.
        path: PathBuf,
        /// The cause.
        what: String,
    },
    /// A method that is not part of this build.
    #[error("method {0:?} is not available in this build")]
    Method(String),
}

/// Which method extracts the edges.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Method {
    /// The bend-angle method (Honma et al.), through the core.
    #[default]
    Bend,
    /// The plane-based method (Qiu et al.).
    Qiu,
}

impl Method {
    /// The spelling in the output's `method` property.
    pub fn as_str(self) -> &'static str {
        match self {
            Method::Bend => "bend",
            Method::Qiu => "qiu",
        }
    }
}

/// Options of one run that are not parameters of a method.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ExtractOptions {
    /// `--scanner ID` (see `io::las_in`).
    pub scanner: Option<u16>,
    /// `--pass N`: only the Nth pass the trajectory holds (`stream::passes`, from 0);
    /// `None` extracts every pass and fuses them.
    pub pass: Option<u16>,
    /// `--method`.
    pub method: Method,
}

/// A progress display the library can drive (hidden unless the CLI makes a visible one).
#[derive(Clone, Debug, Default)]
pub struct Progress {
    bar: Option<indicatif::ProgressBar>,
}

impl Progress {
    /// No display.
    pub fn hidden() -> Self {
        Self { bar: None }
    }

    /// A bar on stderr (the CLI creates it only when stderr is a terminal).
    pub fn bar() -> Self {
        let bar = indicatif::ProgressBar::new(0);
        bar.set_style(
            indicatif::ProgressStyle::with_template(
                "{msg:>10} [{bar:40}] {human_pos}/{human_len} points ({per_sec}, {eta})",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
            .progress_chars("=> "),
        );
        Self { bar: Some(bar) }
    }

    /// Starts a stage of `total` points.
    pub fn stage(&self, name: &'static str, total: u64) {
        if let Some(b) = &self.bar {
            b.set_message(name);
            b.set_length(total);
            b.set_position(0);
        }
    }

    /// Starts a stage over `total` bytes of input, with throughput and time left.
    pub fn stage_bytes(&self, name: &'static str, total: u64) {
        if let Some(b) = &self.bar {
            b.set_style(
                indicatif::ProgressStyle::with_template(
                    "{msg:>10} [{bar:40}] {bytes}/{total_bytes} ({bytes_per_sec}, {eta} left)",
                )
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
                .progress_chars("=> "),
            );
            b.set_message(name);
            b.set_length(total);
            b.set_position(0);
        }
    }

    /// Points done in the current stage.
    pub fn set(&self, done: u64) {
        if let Some(b) = &self.bar {
            b.set_position(done);
        }
    }

    /// Removes the bar.
    pub fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}

/// CPU seconds per stage (all threads), see [`process_cpu_s`](crate::proc_stats::process_cpu_s).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StageCpu {
    /// Reading the point file.
    pub read_s: f64,
    /// Projection, encoding and the core.
    pub core_s: f64,
    /// Seeding, tracking, post-filters.
    pub edges_s: f64,
    /// Everything.
    pub total_s: f64,
    /// Peak resident memory at the end of reading, of the core, of the edges, bytes. A
    /// stream, whose stages run together, sets only the last (the first two are 0).
    pub peak_rss: [u64; 3],
}

/// Wall time per stage, seconds.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StageTimes {
    /// Reading the point file (decode, select, sort).
    pub read_s: f64,
    /// Of a stream: the reader's wait for room in its queue to the core stage (the
    /// stages after it were behind), not part of `read_s`.
    pub read_wait_s: f64,
    /// Reading the trajectory and the coverage check.
    pub trajectory_s: f64,
    /// Projection, encoding and the core.
    pub core_s: f64,
    /// Seeding, tracking, post-filters.
    pub edges_s: f64,
    /// Everything.
    pub total_s: f64,
    /// CPU time per stage.
    pub cpu: StageCpu,
}

/// What the summary at the end reports.
#[derive(Clone, Debug, PartialEq)]
pub struct Summary {
    /// The point file's header information.
    pub las: LasInfo,
    /// Points before the trajectory's first time (dropped).
    pub dropped_before_trajectory: u64,
    /// Points after the trajectory's last time (dropped).
    pub dropped_after_trajectory: u64,
    /// Points the stream's window dropped under its time cap (a standing vehicle).
    pub dropped_by_window_cap: u64,
    /// The half-arc cut's counters, for a spinning sensor's file (`stream::ring_stage`).
    pub arcs: Option<crate::rings::ArcCounters>,
    /// The core's counters.
    pub core: ReplayCounters,
    /// Seed candidates from the core.
    pub candidates: u64,
    /// Edges extracted.
    pub edges: u64,
    /// Their total horizontal length, metres.
    pub total_length_m: f64,
    /// Time per stage.
    pub times: StageTimes,
}

impl Summary {
    /// Points read from the file (after scanner selection).
    pub fn points_read(&self) -> u64 {
        self.las.points_selected
    }

    /// The summary as a few lines of text.
    pub fn to_text(&self) -> String {
        let c = &self.core;
        let pts_per_s = self.points_read() as f64 / self.times.total_s.max(1e-9);
        // An empty sum of lengths is -0.0; "-0.0 m" would read as a sign error.
        let len = if self.total_length_m == 0.0 {
            0.0
        } else {
            self.total_length_m
        };
        format!(
            "points read        {read} of {file} in {path}\n\
             dropped            {before} before and {after} after the trajectory, {trunc} in over-long lines, {lost} lost in the core, {irr} irregular (§2.4), {nn} without neighbours{cap}\n\
             scanlines          {lines}{arcs}\n\
             candidates         {cand}\n\
             edges              {edges}, total length {len:.1} m\n\
             time               {total:.2} s ({pts:.2} M points/s): read {r:.2} s{rw}, trajectory {t:.2} s, core {k:.2} s, edges {e:.2} s\n\
             cpu                {ctot:.2} s: read {cr:.2} s, core {ck:.2} s, edges {ce:.2} s\n\
             peak memory        {mem}",
            read = self.points_read(),
            file = self.las.points_in_file,
            path = self.las.path.display(),
            before = self.dropped_before_trajectory,
            after = self.dropped_after_trajectory,
            cap = if self.dropped_by_window_cap > 0 {
                format!(
                    ", {} by the window's time cap (vehicle standing)",
                    self.dropped_by_window_cap
                )
            } else {
                String::new()
            },
            trunc = c.truncated,
            lost = c.lost,
            irr = c.irregular,
            nn = c.no_neighbour,
            lines = c.scanlines,
            arcs = self.arcs.map(|a| arcs_text(&a)).unwrap_or_default(),
            cand = self.candidates,
            edges = self.edges,
            total = self.times.total_s,
            pts = pts_per_s / 1e6,
            r = self.times.read_s,
            rw = if self.times.read_wait_s > 0.0 {
                format!(" (then {:.2} s waiting for the core)", self.times.read_wait_s)
            } else {
                String::new()
            },
            t = self.times.trajectory_s,
            k = self.times.core_s,
            e = self.times.edges_s,
            ctot = self.times.cpu.total_s,
            cr = self.times.cpu.read_s,
            ck = self.times.cpu.core_s,
            ce = self.times.cpu.edges_s,
            mem = self.peak_memory_text(),
        )
    }

    /// Peak memory per stage: bytes per point read when there are enough points for the
    /// process's fixed footprint (code, libraries, thread stacks: some MiB) not to dominate
    /// the figure, MiB otherwise.
    fn peak_memory_text(&self) -> String {
        const PER_POINT_FROM: u64 = 1_000_000;
        let [m0, m1, m2] = self.times.cpu.peak_rss.map(|b| b as f64);
        let mib = f64::from(1u32 << 20);
        if m0 == 0.0 && m1 == 0.0 {
            // A stream: one figure for the whole pass, which does not grow with the points.
            return format!("{:.1} MiB (streamed: one window in memory)", m2 / mib);
        }
        if self.points_read() >= PER_POINT_FROM {
            let per = self.points_read() as f64;
            format!(
                "{:.1} B/point after reading, {:.1} after the core, {:.1} after the edges",
                m0 / per,
                m1 / per,
                m2 / per
            )
        } else {
            format!(
                "{:.1} MiB after reading, {:.1} MiB after the core, {:.1} MiB after the edges",
                m0 / mib,
                m1 / mib,
                m2 / mib
            )
        }
    }
}

/// The half-arc cut's counters after the scanline count: what became scanlines and what
/// was left out (docs/spec.md §2, *What is left out*).
fn arcs_text(a: &crate::rings::ArcCounters) -> String {
    format!(
        " (half-arcs of {rings} rings; skipped: {short} short, {road} without road at the centre line, {far} beyond the reach, their {far_pts} points within it kept for profiles only; points left out: {near} near, {lat} beyond the side, {piled} piled up)",
        rings = a.rings,
        short = a.skipped_short,
        road = a.skipped_no_road,
        far = a.skipped_far,
        far_pts = a.points_far,
        near = a.points_near,
        lat = a.points_lateral,
        piled = a.points_piled,
    )
}

/// The result of [`extract_file`].
#[derive(Clone, Debug)]
pub struct ExtractResult {
    /// The edges, in the LAS CRS.
    pub edges: Vec<EdgeLine>,
    /// The LAS file's CRS, for the output.
    pub crs: Option<Crs>,
    /// The summary.
    pub summary: Summary,
}

/// The points and the core's results, before any method runs (shared by `extract`,
/// `replay`-style tools and the demo).
pub struct Replayed {
    /// The covered points, sorted by time.
    pub columns: PointColumns,
    /// Header information.
    pub las: LasInfo,
    /// The trajectory.
    pub trajectory: Trajectory,
    /// Points dropped before / after the trajectory.
    pub dropped: (u64, u64),
    /// The core's output per point.
    pub kernel: KernelResults,
    /// Stage times so far.
    pub times: StageTimes,
}

/// What [`load`] returns: the covered points (sorted by time), the header information, the
/// trajectory, the points dropped before / after it, and the stage times so far.
pub type Loaded = (PointColumns, LasInfo, Trajectory, (u64, u64), StageTimes);

/// Reads the points and the trajectory and drops (and counts) the points outside it.
pub fn load(
    points: &Path,
    traj_path: &Path,
    opts: &ExtractOptions,
    progress: &Progress,
) -> Result<Loaded, ExtractError> {
    let mut times = StageTimes::default();
    // The trajectory first: a bad trajectory fails in milliseconds, not after decoding.
    let t0 = Instant::now();
    let trajectory = Trajectory::read_csv(traj_path)?;
    times.trajectory_s = t0.elapsed().as_secs_f64();
    let t0 = Instant::now();
    let c0 = process_cpu_s();
    progress.stage("reading", 0);
    let (mut cols, las) = las_in::read_points(
        points,
        &ReadOptions {
            scanner: opts.scanner,
        },
        &mut |done, total| {
            progress.stage("reading", total);
            progress.set(done);
        },
    )?;
    times.read_s = t0.elapsed().as_secs_f64();
    times.cpu.read_s = process_cpu_s() - c0;
    times.cpu.peak_rss[0] = peak_rss_bytes();
    let t0 = Instant::now();
    let cov = trajectory.coverage(&cols.t, traj_path, points)?;
    if cov.dropped() > 0 {
        cols.keep_range(cov.start..cov.end);
    }
    times.trajectory_s += t0.elapsed().as_secs_f64();
    Ok((
        cols,
        las,
        trajectory,
        (cov.before as u64, cov.after as u64),
        times,
    ))
}

/// [`load`], then the replay through the core.
pub fn replay_file(
    points: &Path,
    traj_path: &Path,
    cfg: &Config,
    opts: &ExtractOptions,
    progress: &Progress,
) -> Result<Replayed, ExtractError> {
    let (columns, las, trajectory, dropped, mut times) = load(points, traj_path, opts, progress)?;
    let words = cfg.kernel_words().map_err(|what| ConfigError::Kernel {
        path: PathBuf::from("(config)"),
        what,
    })?;
    let t0 = Instant::now();
    let c0 = process_cpu_s();
    progress.stage("core", columns.len() as u64);
    let kernel = run::run_kernel(&columns, &trajectory, &words, &cfg.replay, &|d| {
        progress.set(d)
    })
    .map_err(|source| ExtractError::Replay {
        path: points.to_path_buf(),
        source,
    })?;
    times.core_s = t0.elapsed().as_secs_f64();
    times.cpu.core_s = process_cpu_s() - c0;
    times.cpu.peak_rss[1] = peak_rss_bytes();
    Ok(Replayed {
        columns,
        las,
        trajectory,
        dropped,
        kernel,
        times,
    })
}

/// Extracts road edges from a LAS/LAZ file and its trajectory with the bend method and all
/// points of the file (one scanner).
pub fn extract_file(
    points: &Path,
    traj: &Path,
    cfg: &Config,
) -> Result<ExtractResult, ExtractError> {
    extract_file_with(
        points,
        traj,
        cfg,
        &ExtractOptions::default(),
        &Progress::hidden(),
    )
}

/// [`extract_file`] with a scanner, a method and a progress display.
pub fn extract_file_with(
    points: &Path,
    traj: &Path,
    cfg: &Config,
    opts: &ExtractOptions,
    progress: &Progress,
) -> Result<ExtractResult, ExtractError> {
    let start = Instant::now();
    let cpu0 = process_cpu_s();
    if opts.method == Method::Qiu {
        return extract_qiu(points, traj, cfg, opts, progress, start, cpu0);
    }
    let mut r = replay_file(points, traj, cfg, opts, progress)?;
    // The scan angle and intensity columns served the replay; free them before the
    // methods' own indexes are built (6 B per point).
    r.columns.scan_angle_deg = Vec::new();
    r.columns.intensity = Vec::new();
    let t0 = Instant::now();
    let c0 = process_cpu_s();
    progress.stage("edges", 0);
    let input = BendInput {
        x: &r.columns.x,
        y: &r.columns.y,
        z: &r.columns.z,
        t: &r.columns.t,
        rho_deg: &r.kernel.rho_deg,
        status: &r.kernel.status,
        scanline: &r.kernel.scanline,
        candidates: &r.kernel.candidates,
        trajectory: &r.trajectory,
    };
    let mut edges = crate::curb::finish(extract_and_annotate(&input, &cfg.bend));
    for e in &mut edges {
        e.method
            .get_or_insert_with(|| Method::Bend.as_str().to_string());
    }
    r.times.edges_s = t0.elapsed().as_secs_f64();
    r.times.cpu.edges_s = process_cpu_s() - c0;
    r.times.cpu.peak_rss[2] = peak_rss_bytes();
    progress.finish();
    r.times.total_s = start.elapsed().as_secs_f64();
    r.times.cpu.total_s = process_cpu_s() - cpu0;
    let summary = Summary {
        dropped_before_trajectory: r.dropped.0,
        dropped_after_trajectory: r.dropped.1,
        dropped_by_window_cap: 0,
        arcs: None,
        core: r.kernel.counters,
        candidates: r.kernel.candidates.len() as u64,
        edges: edges.len() as u64,
        total_length_m: edges.iter().map(|e| e.length_m()).sum(),
        times: r.times,
        las: r.las.clone(),
    };
    Ok(ExtractResult {
        crs: r.las.crs.clone(),
        edges,
        summary,
    })
}

/// The bend method's edges of the whole input, annotated with their curbs: one route and
/// one point index for the tracker and the annotation, as each window of the stream has.
fn extract_and_annotate(
    input: &BendInput,
    params: &bend::BendParams,
) -> Vec<crate::model::EdgeLine> {
    let route = bend::route::Route::new(input.trajectory);
    let grid = bend::point_grid(input, params);
    let mut edges: Vec<_> = bend::postfilter::remove_tall_steps(bend::extract_edges_on_grid(
        input, &grid, &route, params,
    ))
    .into_iter()
    .map(|(e, _)| e)
    .collect();
    crate::curb::annotate(input, &grid, &route, edges.iter_mut());
    edges
}

/// The second method (Qiu et al.) on the same points: it works on the world points and the
/// trajectory directly, without the core; the summary's core counters stay zero.
fn extract_qiu(
    points: &Path,
    traj: &Path,
    cfg: &Config,
    opts: &ExtractOptions,
    progress: &Progress,
    start: Instant,
    cpu0: f64,
) -> Result<ExtractResult, ExtractError> {
    let (cols, las, trajectory, dropped, mut times) = load(points, traj, opts, progress)?;
    let t0 = Instant::now();
    let c0 = process_cpu_s();
    progress.stage("edges", 0);
    let input = crate::qiu::QiuInput {
        x: &cols.x,
        y: &cols.y,
        z: &cols.z,
        t: &cols.t,
        trajectory: &trajectory,
    };
    let mut edges = crate::qiu::extract_edges(&input, &cfg.qiu);
    for e in &mut edges {
        e.method
            .get_or_insert_with(|| Method::Qiu.as_str().to_string());
    }
    times.edges_s = t0.elapsed().as_secs_f64();
    times.cpu.edges_s = process_cpu_s() - c0;
    times.cpu.peak_rss[2] = peak_rss_bytes();
    progress.finish();
    times.total_s = start.elapsed().as_secs_f64();
    times.cpu.total_s = process_cpu_s() - cpu0;
    let summary = Summary {
        dropped_before_trajectory: dropped.0,
        dropped_after_trajectory: dropped.1,
        dropped_by_window_cap: 0,
        arcs: None,
        core: ReplayCounters::default(),
        candidates: 0,
        edges: edges.len() as u64,
        total_length_m: edges.iter().map(|e| e.length_m()).sum(),
        times,
        las: las.clone(),
    };
    Ok(ExtractResult {
        crs: las.crs,
        edges,
        summary,
    })
}

/// The job of [`extract_file_with`] on points a library caller holds in memory (one
/// scanner, sorted by time): the points outside the trajectory are dropped and counted,
/// then the method runs as on a file. `points_name` and `traj_name` stand for the files in
/// messages. Returns the edges and the points dropped before / after the trajectory.
pub fn extract_columns(
    mut cols: PointColumns,
    points_name: &Path,
    trajectory: &Trajectory,
    traj_name: &Path,
    cfg: &Config,
    method: Method,
) -> Result<(Vec<EdgeLine>, (u64, u64)), ExtractError> {
    if !cols.is_time_ordered() {
        return Err(ExtractError::Stream {
            path: points_name.to_path_buf(),
            what: "points are not in time order".into(),
        });
    }
    let cov = trajectory.coverage(&cols.t, traj_name, points_name)?;
    if cov.dropped() > 0 {
        cols.keep_range(cov.start..cov.end);
    }
    let mut edges = match method {
        Method::Qiu => {
            let input = crate::qiu::QiuInput {
                x: &cols.x,
                y: &cols.y,
                z: &cols.z,
                t: &cols.t,
                trajectory,
            };
            crate::qiu::extract_edges(&input, &cfg.qiu)
        }
        Method::Bend => {
            let words = cfg.kernel_words().map_err(|what| ConfigError::Kernel {
                path: PathBuf::from("(config)"),
                what,
            })?;
            let kernel = run::run_kernel(&cols, trajectory, &words, &cfg.replay, &|_| {}).map_err(
                |source| ExtractError::Replay {
                    path: points_name.to_path_buf(),
                    source,
                },
            )?;
            let input = BendInput {
                x: &cols.x,
                y: &cols.y,
                z: &cols.z,
                t: &cols.t,
                rho_deg: &kernel.rho_deg,
                status: &kernel.status,
                scanline: &kernel.scanline,
                candidates: &kernel.candidates,
                trajectory,
            };
            crate::curb::finish(extract_and_annotate(&input, &cfg.bend))
        }
    };
    for e in &mut edges {
        e.method.get_or_insert_with(|| method.as_str().to_string());
    }
    Ok((edges, (cov.before as u64, cov.after as u64)))
}
