//! A campaign cut into independent tasks of whole sections, for runs spread over several
//! processes or machines (the Python package's Dask driver).
//!
//! The route's sections (see [`window`](super::window)) are split into runs of consecutive
//! sections, one per task. A task reads only the points measured while the vehicle was
//! within its sections' windows plus [`PAD_M`] of road on either side (a scanline cut at
//! the task's first or last point lies in that pad, outside every window the task keeps),
//! runs the core and the section window exactly as `extract` does, and keeps the pieces of
//! its own sections unmerged. [`merge`] feeds every section's pieces, in section order,
//! through the [`Merge`] that `extract` uses, so the edges are those of one `extract` run.
//!
//! A spinning sensor's file (one with a ring dimension) runs through the ring stage as in
//! `extract`: the task reads the arcs' reach more road on either side, its window holds
//! that much more, and its arcs are cut with the sensor `extract` estimates from the
//! stream's first points.

use super::merge::{Merge, Piece};
use super::ring_stage;
use super::window::{SectionWindow, WindowParams};
use super::STREAM_BATCH_POINTS;
use super::{stage_bend, stage_window, Stage};
use crate::bend::route::Route;
use crate::bend::BendParams;
use crate::config::{Config, ConfigError};
use crate::io::las_in::ReadOptions;
use crate::io::trajectory::Trajectory;
use crate::model::EdgeLine;
use crate::pipeline::{ExtractError, ExtractOptions, Method};
use crate::rings::SensorModel;
use crate::source::campaign::Campaign;
use crate::source::las_batches::LasBatches;
use crate::source::PointBatch;
use std::ops::Range;
use std::path::PathBuf;

/// Road read before and after a task's windows, metres: more than the vehicle covers in
/// one scanline.
pub const PAD_M: f64 = 5.0;

/// One task: the sections whose pieces it keeps and the GPS times of the points it reads.
#[derive(Clone, Debug, PartialEq)]
pub struct TaskSpec {
    /// Section indices, `[k0, k1)`.
    pub sections: Range<i64>,
    /// Points with `times.0 <= t < times.1` are read.
    pub times: (f64, f64),
}

/// What one task produced.
pub struct TaskOutput {
    /// Each kept section's pieces, in section order.
    pub pieces: Vec<(i64, Vec<Piece>)>,
    /// Points that went through the core.
    pub points: u64,
}

/// Cuts the route of `traj` into at most `tasks` tasks of consecutive sections. A route
/// shorter than one section is one task (the window is then the whole input).
pub fn plan(traj: &Trajectory, window: &WindowParams, tasks: usize) -> Vec<TaskSpec> {
    let route = Route::new(traj);
    let l = window.section_m.max(1.0);
    let m = window.margin_m.max(0.0);
    // A task reads from as far before its first section as the side store reaches back.
    let lead = window.lead_max_m.max(0.0);
    let length = route.length_m();
    // `SectionWindow` runs sections 0, 1, … while k·l ≤ the route's length.
    let sections = if l > length {
        1
    } else {
        (length / l).floor() as i64 + 1
    };
    let n = (tasks.max(1) as i64).min(sections);
    let times: Vec<f64> = traj.samples.iter().map(|p| p.t).collect();
    let arc: Vec<f64> = times
        .iter()
        .map(|&t| route.arc_at(t).unwrap_or(0.0))
        .collect();
    // The latest sample time at or before station `s`, and the earliest at or after it.
    let before = |s: f64| {
        let i = arc.partition_point(|&a| a <= s);
        times
            .get(i.saturating_sub(1))
            .copied()
            .unwrap_or(f64::NEG_INFINITY)
    };
    let after = |s: f64| {
        let i = arc.partition_point(|&a| a < s);
        times.get(i).copied().unwrap_or(f64::INFINITY)
    };
    (0..n)
        .map(|i| {
            let k0 = sections * i / n;
            let k1 = sections * (i + 1) / n;
            let t0 = if i == 0 {
                f64::NEG_INFINITY
            } else {
                before(k0 as f64 * l - m - lead - PAD_M)
            };
            let t1 = if i == n - 1 {
                f64::INFINITY
            } else {
                after(k1 as f64 * l + m + PAD_M)
            };
            TaskSpec {
                sections: k0..k1,
                times: (t0, t1),
            }
        })
        .collect()
}

/// Runs one task: the points of `task.times` from the campaign `inputs` through the core
/// and the section window, keeping the pieces of `task.sections`.
pub fn run(
    inputs: &[PathBuf],
    traj: &Trajectory,
    cfg: &Config,
    opts: &ExtractOptions,
    window: &WindowParams,
    task: &TaskSpec,
) -> Result<TaskOutput, ExtractError> {
    if opts.method != Method::Bend {
        return Err(ExtractError::Method(opts.method.as_str().into()));
    }
    let words = cfg.kernel_words().map_err(|what| ConfigError::Kernel {
        path: PathBuf::from("(config)"),
        what,
    })?;
    let read = ReadOptions {
        scanner: opts.scanner,
    };
    let rings = Campaign::open(inputs, &read)
        .map_err(ExtractError::Source)?
        .info()
        .ring
        .is_some();
    let times = if rings {
        ring_times(traj, task.times, f64::from(cfg.rings.max_reach_m))
    } else {
        task.times
    };
    let files = files_in(inputs, &read, times)?;
    let first = files.first().cloned().unwrap_or_default();
    let stream_err = |what: String| ExtractError::Stream {
        path: first.clone(),
        what,
    };
    let mut core = Stage::new(traj, &words, cfg, rings);
    if let Stage::Rings(stage) = &mut core {
        if let Some(s) = stream_sensor(inputs, &read, traj).map_err(stream_err)? {
            stage.set_sensor(s);
        }
    }
    let mut source = Campaign::open(&files, &read).map_err(ExtractError::Source)?;
    let window = stage_window(window, cfg, rings);
    let mut win =
        SectionWindow::new(traj, window, stage_bend(cfg, rings)).keeping(task.sections.clone());
    let (t0, t1) = times;
    let mut whole = Vec::new();
    loop {
        let b = source
            .next_batch(STREAM_BATCH_POINTS)
            .map_err(ExtractError::Source)?;
        let Some(b) = b else { break };
        let lo = b.t.partition_point(|&t| t < t0);
        let hi = b.t.partition_point(|&t| t < t1);
        // The source's batches go to the core as they are (only cut to the task's times):
        // the core's work is cut at batch boundaries, so these are `extract`'s batches.
        if lo == 0 && hi == b.len() {
            for c in core.push(b).map_err(|e| stream_err(e.to_string()))? {
                whole.extend(win.push(c));
            }
            continue;
        }
        let mut part = PointBatch::with_capacity(hi - lo);
        part.extend_from(&b, lo..hi);
        let past = hi < b.len();
        if !part.is_empty() {
            for c in core.push(part).map_err(|e| stream_err(e.to_string()))? {
                whole.extend(win.push(c));
            }
        }
        if past {
            break;
        }
    }
    if let Some(c) = core.finish().map_err(|e| stream_err(e.to_string()))? {
        whole.extend(win.push(c));
    }
    whole.extend(win.finish());
    let mut pieces = win.take_pieces();
    if win.is_single() {
        // One section holds the whole route: its edges are whole pieces.
        pieces = vec![(
            0,
            whole
                .into_iter()
                .map(|e| {
                    let n = e.points.len();
                    Piece::whole(e, vec![None; n])
                })
                .collect(),
        )];
    }
    Ok(TaskOutput {
        pieces,
        points: core.points(),
    })
}

/// A spinning sensor's task reads `times` widened by the arcs' reach: its sections'
/// curbs are seen from stations up to `reach_m` before and after them (as
/// [`stage_window`] widens the window).
fn ring_times(traj: &Trajectory, times: (f64, f64), reach_m: f64) -> (f64, f64) {
    let route = Route::new(traj);
    let t: Vec<f64> = traj.samples.iter().map(|p| p.t).collect();
    let arc: Vec<f64> = t.iter().map(|&s| route.arc_at(s).unwrap_or(0.0)).collect();
    // The stations of the samples at or before and at or after a time (the wider side).
    let station_before = |time: f64| {
        let i = t.partition_point(|&s| s <= time).saturating_sub(1);
        arc.get(i).copied().unwrap_or(0.0)
    };
    let station_after = |time: f64| {
        let i = t
            .partition_point(|&s| s < time)
            .min(t.len().saturating_sub(1));
        arc.get(i).copied().unwrap_or(0.0)
    };
    let t0 = if times.0.is_finite() {
        let s = station_before(times.0) - reach_m;
        let i = arc.partition_point(|&a| a <= s);
        t.get(i.saturating_sub(1))
            .copied()
            .unwrap_or(f64::NEG_INFINITY)
            .min(times.0)
    } else {
        times.0
    };
    let t1 = if times.1.is_finite() {
        let s = station_after(times.1) + reach_m;
        let i = arc.partition_point(|&a| a < s);
        t.get(i).copied().unwrap_or(f64::INFINITY).max(times.1)
    } else {
        times.1
    };
    (t0, t1)
}

/// The sensor `extract` estimates from the stream's first points (a task starting within
/// the stream would estimate it from its own, and cut its arcs with other parameters).
/// Only those points are read, and none runs through the core.
fn stream_sensor(
    inputs: &[PathBuf],
    read: &ReadOptions,
    traj: &Trajectory,
) -> Result<Option<SensorModel>, String> {
    let mut source = Campaign::open(inputs, read).map_err(|e| e.to_string())?;
    let batches = std::iter::from_fn(|| source.next_batch(STREAM_BATCH_POINTS).transpose());
    ring_stage::stream_sensor(traj, batches).map_err(|e| e.to_string())
}

/// The campaign's files (in time order) that can hold points of `times`: a file spans from
/// its first point to the next file's first point.
fn files_in(
    inputs: &[PathBuf],
    read: &ReadOptions,
    times: (f64, f64),
) -> Result<Vec<PathBuf>, ExtractError> {
    let campaign = Campaign::open(inputs, read).map_err(ExtractError::Source)?;
    let files = campaign.info().files.clone();
    let mut first = Vec::with_capacity(files.len());
    for f in &files {
        let t = LasBatches::first_time(f)
            .map_err(|e| ExtractError::Source(e.into()))?
            .unwrap_or(f64::INFINITY);
        first.push(t);
    }
    let kept: Vec<PathBuf> = files
        .iter()
        .enumerate()
        .filter(|&(i, _)| {
            let next = first.get(i + 1).copied().unwrap_or(f64::INFINITY);
            first[i] < times.1 && next >= times.0
        })
        .map(|(_, f)| f.clone())
        .collect();
    Ok(if kept.is_empty() { files } else { kept })
}

/// The edges of the tasks' pieces: every section from the first to the last, in order,
/// through the merge `extract` uses (a section no task lists has no pieces).
pub fn merge(mut sections: Vec<(i64, Vec<Piece>)>, bend: &BendParams) -> Vec<EdgeLine> {
    sections.sort_by_key(|s| s.0);
    let mut m: Merge = SectionWindow::merge_for(bend);
    let mut edges = Vec::new();
    let mut next = sections.first().map_or(0, |s| s.0);
    for (k, pieces) in sections {
        while next < k {
            edges.extend(m.push(Vec::new(), 0.0, 0.0));
            next += 1;
        }
        edges.extend(m.push(pieces, 0.0, 0.0));
        next = k + 1;
    }
    edges.extend(m.close_all());
    // As `extract` does after its merge: stretches of one class and one kind of support.
    let mut edges = crate::curb::finish(edges);
    for e in &mut edges {
        e.method
            .get_or_insert_with(|| Method::Bend.as_str().to_string());
    }
    edges
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    /// 100 m due north at 10 m/s from t = 0, a sample every second.
    fn straight() -> Trajectory {
        let mut csv = String::from("time,x,y,z,roll,pitch,heading\n");
        for k in 0..=10 {
            csv.push_str(&format!("{k},0,{},0,0,0,0\n", 10 * k));
        }
        Trajectory::parse_csv(Path::new("t.csv"), &csv).expect("trajectory parses")
    }

    #[test]
    fn a_ring_task_reads_the_reach_more_on_either_side() {
        let traj = straight();
        // 20 m of reach at 10 m/s is 2 s before and after, to the samples outside.
        assert_eq!(ring_times(&traj, (4.0, 6.0), 20.0), (2.0, 8.0));
        assert_eq!(ring_times(&traj, (4.5, 6.5), 20.0), (2.0, 9.0));
        // Open ends stay open; a reach past the route's ends reads from or to its end.
        assert_eq!(
            ring_times(&traj, (f64::NEG_INFINITY, 6.0), 20.0),
            (f64::NEG_INFINITY, 8.0)
        );
        assert_eq!(
            ring_times(&traj, (1.0, f64::INFINITY), 20.0).1,
            f64::INFINITY
        );
        assert_eq!(ring_times(&traj, (1.0, 9.0), 20.0), (0.0, f64::INFINITY));
        // No reach: the times are the task's.
        assert_eq!(ring_times(&traj, (4.0, 6.0), 0.0), (4.0, 6.0));
    }
}
