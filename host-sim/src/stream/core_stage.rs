//! The core stage of the stream: batches of points in time order in, the core's output per
//! point out. Points outside the trajectory's time range are dropped and counted. Each
//! batch is cut at its last line start; the partial line is carried into the next batch,
//! so every scanline reaches the core whole and the output is the one of the whole-file
//! replay (`replay::run`: a pipeline started at a line start behaves as one that has been
//! running). The line-start rule is chosen on the first batch and kept.
//!
//! Without line starts (no scan angle, no `[replay] line_period_s`) the core splits lines
//! itself, which needs the stream uncut: the points are then held until the end, up to
//! [`UNCUT_MAX_POINTS`].

use crate::io::trajectory::Trajectory;
use crate::replay::line_start::LineRule;
use crate::replay::run::{self, ReplayCounters, ReplayError, ReplayParams};
use crate::replay::{Candidate, PointStatus};
use crate::source::PointBatch;
use curbtrace_core::kernel::CONFIG_WORDS;

/// Most points held for a stream without line starts.
pub const UNCUT_MAX_POINTS: usize = 20_000_000;

/// Largest chunk of a batch run through one pipeline: a batch of
/// [`STREAM_BATCH_POINTS`](super::STREAM_BATCH_POINTS) is cut (at line starts) into about
/// two, so both cores run the core while the tracker waits for points. The cuts depend
/// only on the points, and a pipeline started at a line start behaves as one that has been
/// running, so the output does not depend on this size.
pub const STREAM_CHUNK_POINTS: usize = super::STREAM_BATCH_POINTS / 2;

/// Errors of the core stage.
#[derive(Debug, thiserror::Error)]
pub enum CoreError {
    /// The replay through the core.
    #[error("replay through the core: {0}")]
    Replay(#[from] ReplayError),
    /// A stream without line starts larger than the core stage may hold.
    #[error("the points carry no scan angle to find scanline starts and the stream passed {UNCUT_MAX_POINTS} points; set [replay] line_period_s in the config")]
    Uncut,
}

/// The core's output for a run of consecutive points of the stream.
#[derive(Debug, Default)]
pub struct CoreBatch {
    /// Stream index of the first point.
    pub base: u64,
    /// Points at the front of `x`, `y`, `z` and `t` that are not this batch's (they went
    /// in the batch before it): a reader's batch is handed on whole rather than copied
    /// without them. The batch's points are `x[skip..]`; `rho_deg`, `status` and
    /// `scanline` hold only them.
    pub skip: usize,
    /// World X.
    pub x: Vec<f64>,
    /// World Y.
    pub y: Vec<f64>,
    /// World Z.
    pub z: Vec<f64>,
    /// GPS time.
    pub t: Vec<f64>,
    /// ρ, degrees.
    pub rho_deg: Vec<f32>,
    /// Status per point.
    pub status: Vec<Option<PointStatus>>,
    /// Stream-wide scanline number, meaningful where the status is `Some`.
    pub scanline: Vec<u32>,
    /// Candidates; `point` is relative to `base`.
    pub candidates: Vec<Candidate>,
}

/// What both core stages (this one and `ring_stage`'s) count as batches come in: the
/// span of times read, and the points outside the trajectory's time range, dropped.
#[derive(Clone, Copy, Debug)]
pub struct Intake {
    t_range: (f64, f64),
    /// Points before / after the trajectory.
    pub dropped: (u64, u64),
    /// Times of the first and the last point read, before the trajectory's cut.
    pub time_span: Option<(f64, f64)>,
}

impl Intake {
    /// Counting against `traj`'s time range.
    pub fn new(traj: &Trajectory) -> Self {
        Self {
            t_range: traj
                .time_range()
                .unwrap_or((f64::INFINITY, f64::NEG_INFINITY)),
            dropped: (0, 0),
            time_span: None,
        }
    }

    /// Counts `b` (in time order) and returns the range of its points within the
    /// trajectory's time range.
    pub fn admit(&mut self, b: &PointBatch) -> std::ops::Range<usize> {
        if let (Some(&first), Some(&last)) = (b.t.first(), b.t.last()) {
            let (a, z) = self.time_span.get_or_insert((first, last));
            *a = a.min(first);
            *z = z.max(last);
        }
        let (t0, t1) = self.t_range;
        let lo = b.t.partition_point(|&t| t < t0);
        let hi = b.t.partition_point(|&t| t <= t1).max(lo);
        self.dropped.0 += lo as u64;
        self.dropped.1 += (b.len() - hi) as u64;
        lo..hi
    }
}

/// The core stage's state between batches.
pub struct CoreStage<'a> {
    traj: &'a Trajectory,
    words: [u32; CONFIG_WORDS],
    params: ReplayParams,
    rule: Option<LineRule>,
    carry: PointBatch,
    next_base: u64,
    lines: u32,
    /// Counters summed over the stream.
    pub counters: ReplayCounters,
    /// Points dropped outside the trajectory, times read.
    pub intake: Intake,
    /// Points kept.
    pub points: u64,
}

impl<'a> CoreStage<'a> {
    /// A stage for `traj` with the core's config `words`.
    pub fn new(traj: &'a Trajectory, words: [u32; CONFIG_WORDS], params: ReplayParams) -> Self {
        Self {
            traj,
            words,
            params: ReplayParams {
                chunk_points: params.chunk_points.min(STREAM_CHUNK_POINTS),
                ..params
            },
            rule: None,
            carry: PointBatch::default(),
            next_base: 0,
            lines: 0,
            counters: ReplayCounters::default(),
            intake: Intake::new(traj),
            points: 0,
        }
    }

    /// Takes a batch; returns the core's output for the whole lines it completes.
    ///
    /// The line carried from the batch before is completed with the points of `b` up to
    /// its first line start and run on its own; the whole lines of `b` after it are run in
    /// `b`'s own columns, so only the carried line and the new partial line are copied.
    pub fn push(&mut self, b: PointBatch) -> Result<Vec<CoreBatch>, CoreError> {
        let kept = self.intake.admit(&b);
        let first = match self.rule {
            Some(rule) if rule.flags_lines() && !self.carry.is_empty() && !kept.is_empty() => {
                self.first_start(&rule, &b, kept.clone())
            }
            _ => None,
        };
        let Some(f) = first else {
            if self.carry.is_empty() && kept == (0..b.len()) {
                self.carry = b;
            } else {
                self.carry.extend_from(&b, kept);
            }
            return Ok(self.run_carry()?.into_iter().collect());
        };
        // The carried line ends where `b`'s first line starts.
        self.carry.extend_from(&b, kept.start..f);
        let head = self.run(self.carry.len())?;
        self.carry = b;
        self.carry.keep_range(0..kept.end);
        let mut out = vec![head];
        let rule = self.rule.unwrap_or(LineRule::None);
        let c = &self.carry;
        let last = (f + 1..c.len())
            .rev()
            .find(|&i| rule.is_start(i, &c.scan_angle_deg, &c.t));
        match last {
            Some(cut) => out.push(self.run_from(f, cut)?),
            None => self.carry.drain_front(f),
        }
        Ok(out)
    }

    /// The first point of `b`'s `kept` that starts a line, the first one judged against the
    /// carried line's last point.
    fn first_start(
        &self,
        rule: &LineRule,
        b: &PointBatch,
        kept: std::ops::Range<usize>,
    ) -> Option<usize> {
        let c = &self.carry;
        let last = c.len().checked_sub(1)?;
        let a = [c.scan_angle_deg[last], b.scan_angle_deg[kept.start]];
        let t = [c.t[last], b.t[kept.start]];
        if rule.is_start(1, &a, &t) {
            return Some(kept.start);
        }
        (kept.start + 1..kept.end).find(|&i| rule.is_start(i, &b.scan_angle_deg, &b.t))
    }

    /// Chooses the line rule on the first points and runs the whole lines carried.
    fn run_carry(&mut self) -> Result<Option<CoreBatch>, CoreError> {
        if self.carry.is_empty() {
            return Ok(None);
        }
        let rule = *self.rule.get_or_insert_with(|| {
            LineRule::choose(
                &self.carry.scan_angle_deg,
                &self.carry.t,
                &self.params.line(),
            )
        });
        if !rule.flags_lines() {
            if self.carry.len() > UNCUT_MAX_POINTS {
                return Err(CoreError::Uncut);
            }
            return Ok(None);
        }
        // The last line start after the first point: everything before it is whole lines.
        let c = &self.carry;
        let cut = (1..c.len())
            .rev()
            .find(|&i| rule.is_start(i, &c.scan_angle_deg, &c.t));
        match cut {
            Some(i) => self.run(i).map(Some),
            None => Ok(None),
        }
    }

    /// Runs what is left at the end of the stream.
    pub fn finish(&mut self) -> Result<Option<CoreBatch>, CoreError> {
        if self.carry.is_empty() {
            return Ok(None);
        }
        let n = self.carry.len();
        self.run(n).map(Some)
    }

    /// Runs the first `n` carried points through the core.
    fn run(&mut self, n: usize) -> Result<CoreBatch, CoreError> {
        self.run_from(0, n)
    }

    /// Runs the carried points `from..n` (`from` a line start) through the core; the
    /// points after them stay carried, those before them go with the batch as its `skip`.
    fn run_from(&mut self, from: usize, n: usize) -> Result<CoreBatch, CoreError> {
        let rest = if n < self.carry.len() {
            // Room for the line's rest from the next batch; a batch without a line start
            // is appended whole and grows it.
            let mut r = PointBatch::with_capacity(2 * (self.carry.len() - n));
            r.extend_from(&self.carry, n..self.carry.len());
            r
        } else {
            PointBatch::default()
        };
        let mut cols = std::mem::replace(&mut self.carry, rest);
        cols.keep_range(0..n);
        let rule = self.rule.unwrap_or(LineRule::None);
        let k = run::run_kernel_on(
            &cols,
            from..n,
            self.traj,
            &self.words,
            &self.params,
            &rule,
            &|_| {},
        )?;
        let n = n - from;
        let base = self.next_base;
        let lines = self.lines;
        self.next_base += n as u64;
        self.lines = self.lines.saturating_add(k.lines);
        self.points += n as u64;
        self.counters.add(&k.counters);
        let mut scanline = k.scanline;
        if lines > 0 {
            scanline.iter_mut().for_each(|s| *s += lines);
        }
        Ok(CoreBatch {
            base,
            skip: from,
            x: cols.x,
            y: cols.y,
            z: cols.z,
            t: cols.t,
            rho_deg: k.rho_deg,
            status: k.status,
            scanline,
            candidates: k
                .candidates
                .into_iter()
                .map(|c| Candidate {
                    scanline: c.scanline + lines,
                    ..c
                })
                .collect(),
        })
    }
}
