//! The core stage for spinning multi-beam lidars (docs/spec.md, *Spinning sensors*): every
//! ring is a channel of its own, every half revolution of a ring a scanline.
//!
//! 1. Each point is brought into the vehicle frame of its own time (forward, left, up from
//!    the trajectory's origin and heading at t): x_b, y_b, z_b. The projection to the
//!    kernel's plane is the profiler's, x′ = y_b, z′ = z_b ([`crate::rings::project`]).
//! 2. Per ring, in time order, the points form runs of one half (front: x_b ≥ 0, rear:
//!    x_b < 0); a run ends when the half changes or the ring is silent for a quarter
//!    revolution. A run is a half-arc ([`crate::rings::arc`]'s rule, cut in time instead
//!    of per frame): points nearer than `min_range_m`, farther than `max_lateral_m` to the
//!    side or `max_azimuth_deg` from the vehicle's axis, or piled up closer than `min_separation_m` in x′–z′ are left out, and arcs that
//!    do not see the road at the centre line or reach farther than `max_reach_m` are
//!    skipped.
//! 3. The arcs run through the core, one line each, with the sensor's kernel parameters
//!    ([`crate::rings::SensorModel::kernel_params`], the azimuth step and rate estimated
//!    from the first points: [`estimate_sensor`]).
//! 4. The output is a [`CoreBatch`] in stream order, as for profilers: world coordinates,
//!    ρ and status per point (`None` for points left out), the arc's number as the
//!    scanline, the candidates. The window, tracker and merge downstream are the
//!    profilers'.
//!
//! A batch is cut before the earliest run still open, so no arc is split between batches.

use super::core_stage::{CoreBatch, CoreError, Intake};
use crate::io::trajectory::Trajectory;
use crate::model::Side;
use crate::replay::project::PoseCursor;
use crate::replay::run::{ReplayCounters, ReplayError};
use crate::replay::{Candidate, PointStatus};
use crate::rings::run::{self as arc_run, ArcPipeline, ArcPoint, ArcRunError, Feed};
use crate::rings::{project, ArcCounters, ArcParams, SensorModel};
use crate::source::PointBatch;
use curbtrace_core::kernel::{KernelParams, ScanlineOutput};

/// Points of the first batches the sensor's azimuth step and rate are estimated from.
const ESTIMATE_POINTS: usize = 20_000;

/// Median angular speed of the beam between consecutive returns above which a stream is a
/// multi-beam sensor's, degrees per second (`looks_spinning`): a profiler's mirror turns
/// at most 2.5 · 10⁵ °/s (250 lines/s), consecutive lasers of a spinning head are one to
/// tens of degrees apart within microseconds (10⁶–10⁷ °/s) or fire at the same instant.
const SPINNING_DEG_PER_S: f64 = 1.0e6;

/// One point in the vehicle frame of its time.
#[derive(Clone, Copy)]
struct Body {
    x: f32,
    y: f32,
    z: f32,
}

fn body_of(cur: &mut PoseCursor<'_>, x: f64, y: f64, z: f64, t: f64) -> Option<Body> {
    cur.frame_at(t).map(|f| body_in(f, x, y, z))
}

/// A point in the vehicle frame `(q, l)` (origin, left vector).
#[inline]
fn body_in((q, l): Frame, x: f64, y: f64, z: f64) -> Body {
    let (dx, dy) = (x - q[0], y - q[1]);
    Body {
        x: (dx * l[1] - dy * l[0]) as f32,
        y: (dx * l[0] + dy * l[1]) as f32,
        z: (z - q[2]) as f32,
    }
}

/// A vehicle frame: the scanner origin and the left vector ([`PoseCursor::frame_at`]).
type Frame = ([f64; 3], [f64; 2]);

/// The vehicle frames of points taken in time order: the trajectory's cursor, and the
/// frame of the last time asked for, which the next point often shares (a spinning head
/// fires its lasers in blocks at one instant). A frame depends on its time alone, so the
/// frame kept is the one the cursor would give again.
struct Frames<'a> {
    cur: PoseCursor<'a>,
    /// The bits of the last time and its frame (`None` outside the trajectory).
    last: (u64, Option<Frame>),
}

impl<'a> Frames<'a> {
    fn new(traj: &'a Trajectory) -> Self {
        let mut cur = PoseCursor::new(traj);
        let nan = f64::NAN;
        Self {
            last: (nan.to_bits(), cur.frame_at(nan)),
            cur,
        }
    }

    /// The point (`x`, `y`, `z`) at time `t` in the vehicle frame of `t`.
    #[inline]
    fn body(&mut self, x: f64, y: f64, z: f64, t: f64) -> Option<Body> {
        if t.to_bits() != self.last.0 {
            self.last = (t.to_bits(), self.cur.frame_at(t));
        }
        self.last.1.map(|f| body_in(f, x, y, z))
    }
}

/// Whether the points of `b` come from a spinning multi-beam sensor (module constant
/// [`SPINNING_DEG_PER_S`]): the median angle between the directions of consecutive
/// returns, seen from the trajectory's origin at their times, per second between them.
/// The points need not be in time order: they are taken in time order here.
pub fn looks_spinning(b: &PointBatch, traj: &Trajectory) -> bool {
    let mut cur = PoseCursor::new(traj);
    let n = b.len().min(ESTIMATE_POINTS);
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&i, &j| b.t[i].total_cmp(&b.t[j]));
    let mut speeds = Vec::with_capacity(n);
    let mut prev: Option<([f64; 3], f64)> = None;
    for i in order {
        let Some(p) = body_of(&mut cur, b.x[i], b.y[i], b.z[i], b.t[i]) else {
            prev = None;
            continue;
        };
        let v = [f64::from(p.x), f64::from(p.y), f64::from(p.z)];
        let r = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        if r < 0.5 {
            continue;
        }
        let u = [v[0] / r, v[1] / r, v[2] / r];
        if let Some((w, t0)) = prev {
            let c = (u[0] * w[0] + u[1] * w[1] + u[2] * w[2]).clamp(-1.0, 1.0);
            let ang = c.acos().to_degrees();
            let dt = b.t[i] - t0;
            speeds.push(if dt > 0.0 {
                ang / dt
            } else if ang > 0.1 {
                f64::INFINITY
            } else {
                0.0
            });
        }
        prev = Some((u, b.t[i]));
    }
    if speeds.len() < 100 {
        return false;
    }
    let m = speeds.len() / 2;
    *speeds.select_nth_unstable_by(m, f64::total_cmp).1 > SPINNING_DEG_PER_S
}

/// The sensor's azimuth step (median azimuth between consecutive points of one ring less
/// than 2 ms apart) and rate (median azimuth speed over those pairs), and its ring count;
/// `None` with fewer than 100 such pairs.
pub fn estimate_sensor(b: &PointBatch, traj: &Trajectory) -> Option<SensorModel> {
    let mut cur = PoseCursor::new(traj);
    let mut last: Vec<Option<(f64, f64)>> = vec![None; 256];
    let (mut steps, mut speeds) = (Vec::new(), Vec::new());
    let mut rings = 0u16;
    for i in 0..b.len().min(4 * ESTIMATE_POINTS) {
        let Some(p) = body_of(&mut cur, b.x[i], b.y[i], b.z[i], b.t[i]) else {
            continue;
        };
        let ring = usize::from(b.channel[i]);
        rings = rings.max(ring as u16 + 1);
        let az = f64::from(p.y).atan2(f64::from(p.x)).to_degrees();
        if let Some((a0, t0)) = last[ring] {
            let d = (az - a0 + 540.0).rem_euclid(360.0) - 180.0;
            let dt = b.t[i] - t0;
            if dt > 0.0 && dt < 2e-3 && d.abs() > 1e-3 && d.abs() < 5.0 {
                steps.push(d.abs());
                speeds.push(d.abs() / dt);
            }
        }
        last[ring] = Some((az, b.t[i]));
    }
    if steps.len() < 100 {
        return None;
    }
    let med = |v: &mut Vec<f64>| {
        let m = v.len() / 2;
        *v.select_nth_unstable_by(m, f64::total_cmp).1
    };
    let step = med(&mut steps);
    let rate = med(&mut speeds) / 360.0;
    Some(SensorModel {
        name: "spinning lidar",
        rings,
        rate_hz: rate as f32,
        azimuth_step_deg: step as f32,
    })
}

/// What [`RingStage::accept`] keeps of a run.
enum Accepted {
    /// A half-arc for the core.
    Arc(Vec<RunPoint>),
    /// The points within `max_reach_m` of the sensor of a half-arc that meets the centre
    /// line beyond it.
    Far(Vec<RunPoint>),
}

/// The carried index of a run's last point.
fn last_index(r: &Run) -> usize {
    r.points.last().map_or(0, |q| q.i as usize)
}

/// The sensor of a stream whose first kept points are `first`: estimated once they are
/// [`ESTIMATE_POINTS`] or more, or at the end of the stream (`last`) from those there are;
/// without enough of them for [`estimate_sensor`], a 10 Hz sensor with the coarsest step of
/// docs/simulator.md's sensors (0.35°, so d_b errs towards having neighbours).
fn sensor_when_ready(first: &PointBatch, traj: &Trajectory, last: bool) -> Option<SensorModel> {
    if first.len() < ESTIMATE_POINTS && !last {
        return None;
    }
    Some(estimate_sensor(first, traj).unwrap_or(SensorModel {
        name: "spinning lidar",
        rings: 64,
        rate_hz: 10.0,
        azimuth_step_deg: 0.35,
    }))
}

/// The sensor [`RingStage`] estimates from the first points of `batches` (the stream's
/// batches in order), taking them as its intake does but running nothing through the
/// core; `None` for a stream without points on the trajectory.
pub fn stream_sensor<E>(
    traj: &Trajectory,
    batches: impl IntoIterator<Item = Result<PointBatch, E>>,
) -> Result<Option<SensorModel>, E> {
    let mut intake = Intake::new(traj);
    let mut first = PointBatch::default();
    for b in batches {
        let b = b?;
        let kept = intake.admit(&b);
        first.extend_from(&b, kept);
        if let Some(s) = sensor_when_ready(&first, traj, false) {
            return Ok(Some(s));
        }
    }
    Ok(if first.is_empty() {
        None
    } else {
        sensor_when_ready(&first, traj, true)
    })
}

/// A run of one ring in one half.
struct Run {
    front: bool,
    points: Vec<RunPoint>,
    last_t: f64,
}

/// A point of a run: its index in the carried points, with what the half-arc cut and the
/// core read of it, copied as the point is sorted into its run (the scan is in time order;
/// a run's points lie one ring's stride apart in the carry, so reading them there again
/// would miss the cache at every point).
#[derive(Clone, Copy)]
struct RunPoint {
    i: u32,
    b: Body,
    intensity: u16,
}

/// The ring stage's state between batches.
pub struct RingStage<'a> {
    traj: &'a Trajectory,
    arc: ArcParams,
    kernel: Option<KernelParams>,
    sensor: Option<SensorModel>,
    carry: PointBatch,
    /// The vehicle frames of the carried points, in time order.
    frames: Frames<'a>,
    /// Carried points already sorted into runs (each point is looked at once).
    scanned: usize,
    /// The points' buffers of runs already sent, kept for new runs.
    spare: Vec<Vec<RunPoint>>,
    /// Each ring's open run, by ring number.
    open: Vec<Option<Run>>,
    /// Runs ended but not yet sent: they reach past the cut of an earlier batch.
    ended: Vec<Run>,
    /// Per scanned point: 1 too near, 2 too far to the side; counted once the point
    /// leaves the carry.
    left_out: Vec<u8>,
    next_base: u64,
    lines: u32,
    pipe: Box<ArcPipeline>,
    /// How the half-arcs reach the core.
    feed: Feed,
    /// Counters summed over the stream.
    pub counters: ReplayCounters,
    /// The half-arc cut's counters summed over the stream.
    pub arcs: ArcCounters,
    /// Rings seen, one bit each.
    rings_seen: [u64; 4],
    /// Points dropped outside the trajectory, times read.
    pub intake: Intake,
    /// Points kept.
    pub points: u64,
}

impl<'a> RingStage<'a> {
    /// A stage for `traj`; `kernel` overrides the sensor's parameters.
    pub fn new(traj: &'a Trajectory, arc: ArcParams, kernel: Option<KernelParams>) -> Self {
        Self {
            traj,
            arc,
            kernel,
            sensor: None,
            carry: PointBatch::default(),
            frames: Frames::new(traj),
            scanned: 0,
            spare: Vec::new(),
            open: (0..256).map(|_| None).collect(),
            ended: Vec::new(),
            left_out: Vec::new(),
            next_base: 0,
            lines: 0,
            pipe: Box::new(ArcPipeline::new()),
            feed: Feed::Direct,
            counters: ReplayCounters::default(),
            arcs: ArcCounters::default(),
            rings_seen: [0; 4],
            intake: Intake::new(traj),
            points: 0,
        }
    }

    /// Sends the half-arcs through the wire format ([`Feed::Wire`]) when `wire`, straight
    /// to the core's line assembly otherwise (the default); the output is the same.
    pub fn through_wire(mut self, wire: bool) -> Self {
        self.feed = if wire { Feed::Wire } else { Feed::Direct };
        self
    }

    /// The half-arc cut's counters so far, with the rings seen.
    pub fn arc_counters(&self) -> ArcCounters {
        ArcCounters {
            rings: self.rings_seen.iter().map(|w| w.count_ones()).sum(),
            ..self.arcs
        }
    }

    /// The sensor estimated from the first points (or the fallback), once known.
    pub fn sensor(&self) -> Option<SensorModel> {
        self.sensor
    }

    /// Uses `sensor` rather than the one estimated from the first points (a task that
    /// starts within the stream takes the stream's).
    pub fn set_sensor(&mut self, sensor: SensorModel) {
        self.sensor = Some(sensor);
    }

    /// Takes a batch; returns the core's output for the points of the arcs it completes.
    pub fn push(&mut self, b: PointBatch) -> Result<Option<CoreBatch>, CoreError> {
        let kept = self.intake.admit(&b);
        self.carry.extend_from(&b, kept);
        if self.sensor.is_none() {
            // Nothing is sent on before the sensor is known: the carry starts at the
            // stream's first point.
            self.sensor = sensor_when_ready(&self.carry, self.traj, false);
            if self.sensor.is_none() {
                return Ok(None);
            }
        }
        self.run(false)
    }

    /// Runs what is left at the end of the stream.
    pub fn finish(&mut self) -> Result<Option<CoreBatch>, CoreError> {
        if self.carry.is_empty() {
            return Ok(None);
        }
        if self.sensor.is_none() {
            self.sensor = sensor_when_ready(&self.carry, self.traj, true);
        }
        self.run(true)
    }

    /// Cuts the carried points into runs, runs the closed ones through the core and
    /// returns the points before the earliest open run.
    fn run(&mut self, last: bool) -> Result<Option<CoreBatch>, CoreError> {
        let sensor = self.sensor.unwrap_or(SensorModel::VLP16);
        let period = 1.0 / f64::from(sensor.rate_hz.max(0.1));
        let gap = 0.25 * period;
        let c = &self.carry;
        let n = c.len();
        // Runs carry over between batches: only the points new since the last batch are
        // sorted into them, each brought into its vehicle frame as it is looked at.
        let (min2, tan_max) = (self.arc.min_range_m.powi(2), self.arc.max_azimuth_tan());
        self.left_out.resize(n, 0);
        for i in self.scanned..n {
            let Some(p) = self.frames.body(c.x[i], c.y[i], c.z[i], c.t[i]) else {
                continue;
            };
            if p.x.is_nan() {
                continue;
            }
            if p.x * p.x + p.y * p.y < min2 {
                self.left_out[i] = 1;
                continue;
            }
            if self.arc.beyond_side(p.x, p.y, tan_max) {
                self.left_out[i] = 2;
                continue;
            }
            let ring = c.channel[i];
            self.rings_seen[usize::from(ring >> 6)] |= 1 << (ring & 63);
            let front = p.x >= 0.0;
            let q = RunPoint {
                i: i as u32,
                b: p,
                intensity: c.intensity[i],
            };
            let slot = &mut self.open[usize::from(ring)];
            match slot {
                Some(r) if r.front == front && c.t[i] - r.last_t <= gap => {
                    r.points.push(q);
                    r.last_t = c.t[i];
                }
                _ => {
                    if let Some(r) = slot.take() {
                        self.ended.push(r);
                    }
                    let mut points = self.spare.pop().unwrap_or_default();
                    points.push(q);
                    *slot = Some(Run {
                        front,
                        points,
                        last_t: c.t[i],
                    });
                }
            }
        }
        self.scanned = n;
        // A run silent for more than the gap has ended: the ring's next point (later in
        // time) starts a new one.
        let t_end = c.t.last().copied().unwrap_or(f64::NEG_INFINITY);
        for slot in self.open.iter_mut() {
            if slot
                .as_ref()
                .is_some_and(|r| last || t_end - r.last_t > gap)
            {
                self.ended.extend(slot.take());
            }
        }
        // The cut: before every open run, and before every ended run that reaches it.
        let mut cut = self
            .open
            .iter()
            .flatten()
            .map(|r| r.points[0].i as usize)
            .min()
            .unwrap_or(n);
        loop {
            let c2 = self
                .ended
                .iter()
                .filter(|r| last_index(r) >= cut)
                .map(|r| r.points[0].i as usize)
                .min()
                .unwrap_or(cut)
                .min(cut);
            if c2 == cut {
                break;
            }
            cut = c2;
        }
        if cut == 0 {
            return Ok(None);
        }
        // Ended runs before the cut go now; the rest wait, renumbered from the cut.
        let (mut closed, mut wait): (Vec<Run>, Vec<Run>) = std::mem::take(&mut self.ended)
            .into_iter()
            .partition(|r| last_index(r) < cut);
        let shift = cut as u32;
        for r in wait.iter_mut().chain(self.open.iter_mut().flatten()) {
            for q in r.points.iter_mut() {
                q.i -= shift;
            }
        }
        self.ended = std::mem::take(&mut wait);
        closed.sort_by_key(|r| r.points[0].i);
        let left_out = std::mem::take(&mut self.left_out);
        self.arcs.points_near += left_out[..cut].iter().filter(|&&f| f == 1).count() as u64;
        self.arcs.points_lateral += left_out[..cut].iter().filter(|&&f| f == 2).count() as u64;
        let mut arcs: Vec<Vec<RunPoint>> = Vec::with_capacity(closed.len());
        let mut far: Vec<Vec<RunPoint>> = Vec::new();
        for r in closed {
            match self.accept(r) {
                Ok(Accepted::Arc(a)) => arcs.push(a),
                Ok(Accepted::Far(a)) => far.push(a),
                Err(mut spare) => {
                    spare.clear();
                    self.spare.push(spare);
                }
            }
        }
        let kernel = self.kernel.unwrap_or_else(|| sensor.kernel_params());
        let out = self.run_core(&arcs, &far, &sensor, &kernel, cut)?;
        self.spare.extend(arcs.into_iter().chain(far).map(|mut a| {
            a.clear();
            a
        }));
        self.left_out = left_out;
        self.left_out.drain(..cut);
        self.scanned -= cut;
        Ok(Some(out))
    }

    /// Thinning and the road checks of one run (`rings::arc`'s rule): the arc's points, or
    /// for an arc that sees the road at the centre line beyond `max_reach_m`, its points
    /// within `max_reach_m` of the sensor ([`Accepted::Far`]); the run's buffer back when
    /// the run is skipped.
    fn accept(&mut self, r: Run) -> Result<Accepted, Vec<RunPoint>> {
        let p = &self.arc;
        let c = &mut self.arcs;
        if r.points.len() < p.min_points {
            c.skipped_short += 1;
            return Err(r.points);
        }
        let sep2 = p.min_separation_m * p.min_separation_m;
        let mut pts = r.points;
        let mut lastp = (f32::INFINITY, f32::INFINITY);
        pts.retain(|q| {
            let (xp, zp) = project(q.b.x, q.b.y, q.b.z);
            let (dx, dz) = (xp - lastp.0, zp - lastp.1);
            if dx * dx + dz * dz < sep2 {
                c.points_piled += 1;
                return false;
            }
            lastp = (xp, zp);
            true
        });
        let Some(nadir) = pts
            .iter()
            .min_by(|a, b| a.b.y.abs().total_cmp(&b.b.y.abs()))
        else {
            return Err(pts);
        };
        let nadir = nadir.b;
        let mut centre: Vec<f32> = pts
            .iter()
            .filter(|q| q.b.y.abs() <= 1.0)
            .map(|q| q.b.z)
            .collect();
        if centre.is_empty() {
            c.skipped_no_road += 1;
            return Err(pts);
        }
        let mid = centre.len() / 2;
        let z_mid = *centre.select_nth_unstable_by(mid, f32::total_cmp).1;
        if z_mid > -p.min_depth_m {
            c.skipped_no_road += 1;
            return Err(pts);
        }
        if nadir.x.abs() > p.max_reach_m {
            c.skipped_far += 1;
            let reach2 = p.max_reach_m * p.max_reach_m;
            pts.retain(|q| q.b.x * q.b.x + q.b.y * q.b.y <= reach2);
            if pts.is_empty() {
                return Err(pts);
            }
            c.points_far += pts.len() as u64;
            return Ok(Accepted::Far(pts));
        }
        c.arcs += 1;
        c.points_in_arcs += pts.len() as u64;
        Ok(Accepted::Arc(pts))
    }

    /// Runs `arcs` through a fresh pipeline (`rings::run`: config packet first, one line
    /// per arc) and returns the first `cut` carried points with the core's output; the
    /// points of the `far` arcs follow, one line each, kept without a bend angle.
    fn run_core(
        &mut self,
        arcs: &[Vec<RunPoint>],
        far: &[Vec<RunPoint>],
        sensor: &SensorModel,
        kernel: &KernelParams,
        cut: usize,
    ) -> Result<CoreBatch, CoreError> {
        let mut rho = vec![0.0f32; cut];
        let mut status: Vec<Option<PointStatus>> = vec![None; cut];
        let mut scanline = vec![0u32; cut];
        let mut cands: Vec<Candidate> = Vec::new();
        let base_line = self.lines;
        let mut counters = ReplayCounters::default();
        let mut line_no = 0u32;
        let mut collect = |o: &ScanlineOutput<'_>| {
            let line = base_line + line_no;
            line_no += 1;
            counters.scanlines += 1;
            counters.truncated += u64::from(o.truncated);
            for (k, &tag) in o.tag.iter().enumerate() {
                let j = tag as usize;
                if j >= cut {
                    continue;
                }
                rho[j] = o.rho_deg[k];
                status[j] = Some(o.status[k]);
                scanline[j] = line;
                match o.status[k] {
                    PointStatus::Kept => counters.kept += 1,
                    PointStatus::Irregular => counters.irregular += 1,
                    PointStatus::NoNeighbour => counters.no_neighbour += 1,
                    _ => {}
                }
            }
            for (side, k) in [(Side::Left, o.left), (Side::Right, o.right)] {
                if let Some(&tag) = k.and_then(|k| o.tag.get(usize::from(k))) {
                    cands.push(Candidate {
                        point: tag,
                        side,
                        scanline: line,
                    });
                }
            }
        };
        let points = arcs.iter().map(|arc| {
            arc.iter().map(|q| {
                let (x_m, z_m) = project(q.b.x, q.b.y, q.b.z);
                ArcPoint {
                    x_m,
                    z_m,
                    intensity: q.intensity,
                    tag: q.i,
                }
            })
        });
        let sent = arc_run::run_arcs(
            &mut self.pipe,
            kernel,
            sensor,
            u64::from(base_line) + 1,
            points,
            self.feed,
            &mut collect,
        )
        .map_err(|e| match e {
            ArcRunError::Encode(e) => CoreError::Replay(ReplayError::Encode(e)),
            ArcRunError::Stalled => CoreError::Replay(ReplayError::Stalled),
        })?;
        // A far arc's bend angles would be read on pieces of a ring cut off at the reach,
        // without the road at the centre line the outward search starts from: its points
        // serve the virtual profiles only (`bend::profile::usable`).
        for arc in far {
            let line = base_line + line_no;
            line_no += 1;
            for q in arc {
                let j = q.i as usize;
                if j < cut {
                    status[j] = Some(PointStatus::NoNeighbour);
                    scanline[j] = line;
                }
            }
        }
        counters.packets += sent.packets;
        counters.bytes += sent.bytes;
        counters.points_sent += sent.points;
        self.lines = self.lines.saturating_add(line_no);
        let rest = {
            let mut r =
                PointBatch::with_capacity(self.carry.len() - cut + super::STREAM_BATCH_POINTS);
            r.extend_from(&self.carry, cut..self.carry.len());
            r
        };
        let mut cols = std::mem::replace(&mut self.carry, rest);
        cols.keep_range(0..cut);
        let base = self.next_base;
        self.next_base += cut as u64;
        self.points += cut as u64;
        self.counters.add(&counters);
        Ok(CoreBatch {
            skip: 0,
            base,
            x: cols.x,
            y: cols.y,
            z: cols.z,
            t: cols.t,
            rho_deg: rho,
            status,
            scanline,
            candidates: cands,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::{BTreeMap, BTreeSet};
    use std::path::Path;

    /// A sensor 1.8 m above a road, standing at the origin facing north (heading 0°: left
    /// is west, −x), 10 Hz, 0.2° between firings, 8 lasers meeting the road 5–15 m out.
    /// A 0.15 m kerb on the left 3 m out (x < −3 is higher), none on the right.
    const H: f64 = 1.8;
    const RINGS: usize = 8;

    fn traj() -> Trajectory {
        let csv = "time,x,y,z,roll,pitch,heading\n100,0,0,1.8,0,0,0\n101,0,0,1.8,0,0,0\n";
        Trajectory::parse_csv(Path::new("t.csv"), csv).expect("trajectory parses")
    }

    /// `revs` revolutions from t = 100.05 s, firings in time order, clockwise from behind.
    fn stream(revs: usize) -> PointBatch {
        let firings = 1800;
        let mut b = PointBatch::default();
        for f in 0..revs * firings {
            let t = 100.05 + f as f64 / (10.0 * firings as f64);
            let phi = (180.0 - 0.2 * f as f64).to_radians();
            for k in 0..RINGS {
                let r = 5.0 + 10.0 * k as f64 / (RINGS - 1) as f64;
                let (yb, xb) = (r * phi.sin(), r * phi.cos());
                // Body (forward, left) to world for heading 0: x = −left, y = forward.
                let (x, y) = (-yb, xb);
                let z = if x < -3.0 { 0.15 } else { 0.0 };
                let _ = H;
                b.push(x, y, z, t + k as f64 * 1e-6, 100, 0.0, k as u8);
            }
        }
        b
    }

    fn run_all(b: &PointBatch, batch: usize) -> (Vec<CoreBatch>, RingStage<'static>) {
        let tr: &'static Trajectory = Box::leak(Box::new(traj()));
        let mut st = RingStage::new(tr, ArcParams::default(), None);
        let mut out = Vec::new();
        let mut i = 0;
        while i < b.len() {
            let j = (i + batch).min(b.len());
            let mut part = PointBatch::default();
            part.extend_from(b, i..j);
            out.extend(st.push(part).expect("stage runs"));
            i = j;
        }
        out.extend(st.finish().expect("stage finishes"));
        (out, st)
    }

    #[test]
    fn every_scanline_is_one_ring_in_one_half_and_the_batches_do_not_matter() {
        let b = stream(3);
        let (out, st) = run_all(&b, 32_768);
        let n: usize = out.iter().map(|c| c.t.len()).sum();
        assert_eq!(n, b.len(), "every point comes out once");
        // Scanline → (ring, front) of its points.
        let mut lines: BTreeMap<u32, BTreeSet<(u8, bool)>> = BTreeMap::new();
        for c in &out {
            for (k, s) in c.status.iter().enumerate() {
                if s.is_some() {
                    let g = (c.base as usize) + k;
                    lines
                        .entry(c.scanline[k])
                        .or_default()
                        .insert((b.channel[g], b.y[g] >= 0.0));
                }
            }
        }
        assert!(lines.values().all(|v| v.len() == 1), "{lines:?}");
        // Three revolutions: the first and last half revolution of each ring are cut
        // short by the stream's ends; at least 5 whole halves per ring.
        assert!(lines.len() >= RINGS * 5, "{} scanlines", lines.len());
        assert_eq!(st.counters.scanlines as usize, lines.len());
        // The sensor is estimated from the data: 0.2° at 10 Hz.
        let s = st.sensor().expect("estimated");
        assert!((s.azimuth_step_deg - 0.2).abs() < 0.01, "{s:?}");
        assert!((s.rate_hz - 10.0).abs() < 0.2, "{s:?}");
        assert_eq!(s.rings as usize, RINGS);
        // Cut into other batch sizes, the output is the same.
        let cands = |o: &[CoreBatch]| -> Vec<(u64, Side)> {
            o.iter()
                .flat_map(|c| {
                    c.candidates
                        .iter()
                        .map(|k| (c.base + u64::from(k.point), k.side))
                })
                .collect()
        };
        let (other, _) = run_all(&b, 5_000);
        assert_eq!(cands(&out), cands(&other));
    }

    #[test]
    fn the_left_kerb_gives_left_candidates_ahead_and_behind() {
        let b = stream(2);
        let (out, _) = run_all(&b, 32_768);
        let (mut left, mut right) = (0, 0);
        let (mut ahead, mut behind) = (0, 0);
        for c in &out {
            for k in &c.candidates {
                let g = c.base as usize + k.point as usize;
                match k.side {
                    Side::Left => {
                        left += 1;
                        // The toe: the last road point before x = −3 (west is left).
                        assert!(
                            (b.x[g] + 3.0).abs() < 0.1,
                            "left candidate at x = {}",
                            b.x[g]
                        );
                        if b.y[g] > 0.0 {
                            ahead += 1;
                        } else {
                            behind += 1;
                        }
                    }
                    Side::Right => right += 1,
                }
            }
        }
        assert!(
            ahead >= RINGS && behind >= RINGS,
            "{ahead} ahead, {behind} behind"
        );
        assert!(
            left >= 2 * RINGS && right == 0,
            "{left} left, {right} right"
        );
    }

    #[test]
    fn frames_give_the_cursors_bits_for_repeated_and_earlier_times() {
        let csv = "time,x,y,z,roll,pitch,heading\n100,0,0,1.8,0,0,0\n101,3,4,1.9,0,0,30\n102,5,9,2.0,0,0,75\n";
        let tr = Trajectory::parse_csv(Path::new("t.csv"), csv).expect("trajectory parses");
        let mut frames = Frames::new(&tr);
        let bits = |b: Option<Body>| b.map(|b| [b.x.to_bits(), b.y.to_bits(), b.z.to_bits()]);
        for &t in &[
            100.25,
            100.25,
            100.25,
            101.5,
            100.75,
            100.75,
            99.0,
            99.0,
            101.5,
            f64::NAN,
        ] {
            let (x, y, z) = (7.0 + t, -2.0, 0.5);
            let mut cur = PoseCursor::new(&tr);
            let fresh = body_of(&mut cur, x, y, z, t);
            assert_eq!(bits(frames.body(x, y, z, t)), bits(fresh), "t = {t}");
        }
        assert!(frames.body(1.0, 1.0, 1.0, 99.0).is_none());
    }

    #[test]
    fn a_far_arc_keeps_its_points_within_the_reach_for_profiles_only() {
        // The fixture's outermost laser meets the road 15 m out; on the left beyond the
        // kerb (x < −3) it meets the raised ground 11 m out. With a 14 m reach its
        // half-arcs reach the centre line beyond it.
        let mut b = stream(2);
        let far = (RINGS - 1) as u8;
        for i in 0..b.len() {
            if b.channel[i] == far && b.x[i] < -3.0 {
                let k = 11.0 / b.x[i].hypot(b.y[i]);
                b.x[i] *= k;
                b.y[i] *= k;
            }
        }
        let tr: &'static Trajectory = Box::leak(Box::new(traj()));
        let arc = ArcParams {
            max_reach_m: 14.0,
            ..ArcParams::default()
        };
        let mut st = RingStage::new(tr, arc, None);
        let mut out = Vec::new();
        out.extend(st.push(b.clone()).expect("stage runs"));
        out.extend(st.finish().expect("stage finishes"));
        let (mut kept_far, mut beyond) = (0, 0);
        for c in &out {
            for (k, s) in c.status.iter().enumerate() {
                let g = c.base as usize + k;
                if b.channel[g] != far {
                    continue;
                }
                if b.x[g].hypot(b.y[g]) <= 14.0 {
                    // Kept without a bend angle, never a candidate.
                    if s.is_some() {
                        assert_eq!(*s, Some(PointStatus::NoNeighbour));
                        kept_far += 1;
                    }
                } else {
                    assert!(s.is_none(), "a point beyond the reach is kept");
                    beyond += 1;
                }
            }
            for k in &c.candidates {
                assert_ne!(b.channel[c.base as usize + k.point as usize], far);
            }
        }
        assert!(
            kept_far > 100 && beyond > 100,
            "{kept_far} kept, {beyond} beyond"
        );
        assert!(st.arc_counters().skipped_far >= 2);
        assert_eq!(st.arc_counters().points_far, kept_far);
    }

    #[test]
    fn a_spinning_stream_looks_spinning_and_a_profile_does_not() {
        let tr = traj();
        assert!(looks_spinning(&stream(1), &tr));
        // A profiler: one plane across the road, 2 000 pulses per line, 100 lines/s.
        let mut p = PointBatch::default();
        for line in 0..10 {
            for j in 0..2000 {
                let t = 100.05 + line as f64 / 100.0 + j as f64 / 200_000.0;
                let a = (-180.0 + 360.0 * (j as f64 + 0.5) / 2000.0_f64).to_radians();
                let (x, z) = (10.0 * a.sin(), H - 10.0 * a.cos());
                p.push(x, 0.0, z, t, 100, 0.0, 0);
            }
        }
        assert!(!looks_spinning(&p, &tr));
    }
}
