//! Half-arcs through the core: run through `curbtrace_core::Pipeline` in-process, the code
//! the firmware runs — the sensor's kernel parameters first, then the points. The
//! single-frame job (`frame::run`) and the stream's ring stage (`stream::ring_stage`) both
//! send their arcs through [`run_arcs`].
//!
//! - [`Feed::Direct`] hands each point straight to the core's line assembly
//!   (`Pipeline::push_point`); [`Feed::Wire`] encodes them into the wire format (a config
//!   packet, then point packets) for the core to parse back, CRC and all. The lines and
//!   their output are the same either way (`replay::run`'s module docs).
//! - Each half-arc is one line: its first point carries the line-start flag, and the
//!   parameters split lines on nothing else (see [`super::SensorModel::kernel_params`]).
//! - Wire times are nominal: point k of arc a is at a·T + k·δt (T the revolution, δt the
//!   time between two firings of one laser). The core uses time only to split lines, which
//!   the flags do here.

use super::SensorModel;
use curbtrace_core::kernel::{KernelParams, ScanlineOutput};
use curbtrace_core::wire::{
    EncodeError, PointRecord, StreamEncoder, MAX_PACKET_LEN, MAX_POINTS_PER_PACKET,
};
use curbtrace_core::Pipeline;

/// Capacity of the pipeline's byte ring.
pub const RING: usize = 1 << 16;
/// Longest half-arc the pipeline holds (more points are counted as truncated by the core).
/// A half revolution of one laser is 512–1 100 points on the sensors of docs/simulator.md;
/// an HDL-64E half-arc holds about 1 000 points, a 2048-column sensor's 1 024.
pub const ARC_CAPACITY: usize = 4096;
/// The pipeline half-arcs run through.
pub type ArcPipeline = Pipeline<RING, ARC_CAPACITY>;

/// One point of a half-arc as the wire carries it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ArcPoint {
    /// x′, metres ([`super::project`]).
    pub x_m: f32,
    /// z′, metres.
    pub z_m: f32,
    /// Intensity.
    pub intensity: u16,
    /// The caller's tag, handed back with the core's output for this point.
    pub tag: u32,
}

/// Why the core could not be run.
#[derive(Debug, thiserror::Error)]
pub enum ArcRunError {
    /// The encoder refused a packet (a bug, reported rather than hidden).
    #[error("encoding a packet failed: {0:?}")]
    Encode(EncodeError),
    /// The pipeline stopped accepting bytes.
    #[error("the core's ring accepted no bytes after processing every line (stalled)")]
    Stalled,
}

/// What went over the wire.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WireCounts {
    /// Packets, the config packet included.
    pub packets: u64,
    /// Bytes.
    pub bytes: u64,
    /// Points.
    pub points: u64,
}

/// How points reach the core (module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Feed {
    /// Straight to the core's line assembly.
    #[default]
    Direct,
    /// Encoded into wire packets and parsed back by the core.
    Wire,
}

/// Runs `arcs` through `pipe` (restarted first): the config with `kernel`, then each arc as one
/// line, in order. Arc a's wire time is (`first_arc` + a)·T (module docs). Every line the
/// core completes goes to `on_line`. With [`Feed::Direct`] the counts' packets and bytes
/// stay 0.
pub fn run_arcs<A, I>(
    pipe: &mut ArcPipeline,
    kernel: &KernelParams,
    sensor: &SensorModel,
    first_arc: u64,
    arcs: A,
    feed_by: Feed,
    on_line: &mut impl FnMut(&ScanlineOutput<'_>),
) -> Result<WireCounts, ArcRunError>
where
    A: IntoIterator<Item = I>,
    I: IntoIterator<Item = ArcPoint>,
{
    pipe.restart();
    if feed_by == Feed::Direct {
        return Ok(run_direct(pipe, kernel, sensor, first_arc, arcs, on_line));
    }
    let mut enc = StreamEncoder::new();
    let mut buf = vec![0u8; MAX_PACKET_LEN];
    let mut sent = WireCounts::default();
    let n = enc
        .encode_config(&kernel.to_words(), &mut buf)
        .map_err(ArcRunError::Encode)?;
    feed(pipe, &buf[..n], on_line)?;
    sent.packets += 1;
    sent.bytes += n as u64;
    let (period_ns, step_ns) = arc_timing(sensor);
    let mut recs: Vec<PointRecord> = Vec::with_capacity(MAX_POINTS_PER_PACKET);
    for (a, arc) in arcs.into_iter().enumerate() {
        let t_arc = (first_arc + a as u64) * period_ns;
        // Points of this arc so far; the first of the packet being filled.
        let (mut k, mut k0) = (0u32, 0u32);
        let mut send = |recs: &mut Vec<PointRecord>, k0: u32, sent: &mut WireCounts| {
            let t0 = t_arc + u64::from(k0) * u64::from(step_ns);
            let m = enc
                .encode_points(t0, recs, &mut buf)
                .map_err(ArcRunError::Encode)?;
            feed(pipe, &buf[..m], on_line)?;
            sent.packets += 1;
            sent.bytes += m as u64;
            sent.points += recs.len() as u64;
            recs.clear();
            Ok::<(), ArcRunError>(())
        };
        for p in arc {
            recs.push(PointRecord {
                dt_ns: (k - k0) * step_ns,
                x_m: p.x_m,
                z_m: p.z_m,
                intensity: p.intensity,
                line_start: k == 0,
                tag: p.tag,
            });
            k += 1;
            if recs.len() == MAX_POINTS_PER_PACKET {
                send(&mut recs, k0, &mut sent)?;
                k0 = k;
            }
        }
        if !recs.is_empty() {
            send(&mut recs, k0, &mut sent)?;
        }
        pipe.run(&mut *on_line);
    }
    pipe.finish(&mut *on_line);
    Ok(sent)
}

/// [`run_arcs`] with [`Feed::Direct`]: each point at the time the wire path gives it.
fn run_direct<A, I>(
    pipe: &mut ArcPipeline,
    kernel: &KernelParams,
    sensor: &SensorModel,
    first_arc: u64,
    arcs: A,
    on_line: &mut impl FnMut(&ScanlineOutput<'_>),
) -> WireCounts
where
    A: IntoIterator<Item = I>,
    I: IntoIterator<Item = ArcPoint>,
{
    let mut sent = WireCounts::default();
    pipe.push_config(&kernel.to_words(), &mut *on_line);
    let (period_ns, step_ns) = arc_timing(sensor);
    for (a, arc) in arcs.into_iter().enumerate() {
        let t_arc = (first_arc + a as u64) * period_ns;
        for (k, p) in arc.into_iter().enumerate() {
            let rec = PointRecord {
                dt_ns: 0,
                x_m: p.x_m,
                z_m: p.z_m,
                intensity: p.intensity,
                line_start: k == 0,
                tag: p.tag,
            };
            pipe.push_point(t_arc + k as u64 * u64::from(step_ns), &rec, &mut *on_line);
            sent.points += 1;
        }
    }
    pipe.finish(&mut *on_line);
    sent
}

/// The revolution T and the time δt between two firings of one laser, ns (module docs).
fn arc_timing(sensor: &SensorModel) -> (u64, u32) {
    let rate_hz = sensor.rate_hz.max(0.1);
    let period_ns = (1e9 / rate_hz) as u64;
    let step_ns = ((sensor.azimuth_step_deg / 360.0) * 1e9 / rate_hz).max(1.0) as u32;
    (period_ns, step_ns)
}

/// Writes `b` into the pipeline, processing complete lines whenever the ring is full.
fn feed(
    pipe: &mut ArcPipeline,
    b: &[u8],
    on_line: &mut impl FnMut(&ScanlineOutput<'_>),
) -> Result<(), ArcRunError> {
    let mut off = 0;
    while off < b.len() {
        let w = pipe.write(&b[off..]);
        off += w;
        if w == 0 {
            pipe.run(&mut *on_line);
            let w2 = pipe.write(&b[off..]);
            if w2 == 0 {
                return Err(ArcRunError::Stalled);
            }
            off += w2;
        }
    }
    Ok(())
}
