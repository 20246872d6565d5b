//! Half-arcs through the core: encoded into the wire format (a config packet with the
//! sensor's kernel parameters first, then point packets) and run through
//! `curbtrace_core::Pipeline` in-process, the code the firmware runs.
//!
//! - Each half-arc is one line: its first point carries the line-start flag, and the
//!   parameters split lines on nothing else (see `rings::SensorModel::kernel_params`).
//! - x′, z′ are [`crate::rings::project`]'s.
//! - Wire times are nominal: point k of arc a is at a·T + k·δt (T the revolution, δt the
//!   time between two firings of one laser). The core uses time only to split lines, which
//!   the flags do here; the frame's files carry no per-point time.
//! - The tag is (arc << 16) | k, so every output point is mapped back to its arc and place
//!   without a lookup.

use crate::io::sweep::Sweep;
use crate::rings::{project, HalfArc, SensorModel};
use curbtrace_core::kernel::{KernelParams, ScanlineOutput};
use curbtrace_core::wire::{
    EncodeError, PointRecord, StreamEncoder, MAX_PACKET_LEN, MAX_POINTS_PER_PACKET,
};
use curbtrace_core::Pipeline;

/// Capacity of the pipeline's byte ring.
pub const RING: usize = 1 << 16;
/// Longest half-arc the pipeline holds (more points are counted as truncated by the core).
/// An HDL-64E half-arc holds about 1 000 points, a 2048-column sensor's 1 024.
pub const ARC_CAPACITY: usize = 4096;
/// The pipeline type the frames run through.
pub type FramePipeline = Pipeline<RING, ARC_CAPACITY>;

/// The kernel's verdict on one half-arc: its candidates as positions along the arc.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ArcResult {
    /// Position in the arc of the left candidate (first peak outward with x′ > 0).
    pub left: Option<u32>,
    /// Position in the arc of the right candidate.
    pub right: Option<u32>,
    /// Points the kernel returned for this arc.
    pub points_out: u32,
    /// Points of this arc dropped as over capacity.
    pub truncated: u32,
}

/// Why the core could not be run.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The encoder refused a packet (a bug, reported rather than hidden).
    #[error("encoding a packet failed: {0:?}")]
    Encode(EncodeError),
    /// The pipeline stopped accepting bytes.
    #[error("the core's ring accepted no bytes after processing every line (stalled)")]
    Stalled,
    /// More half-arcs than the tag can number.
    #[error("{0} half-arcs in one frame; at most 65536")]
    TooManyArcs(usize),
}

/// Runs `arcs` of `s` through a fresh pipeline configured with `params`; one result per
/// arc, in order. `pipe` is reused across frames (it is large).
pub fn run_arcs(
    s: &Sweep,
    arcs: &[HalfArc],
    sensor: &SensorModel,
    params: &KernelParams,
    pipe: &mut FramePipeline,
) -> Result<Vec<ArcResult>, RunError> {
    if arcs.len() > 1 << 16 {
        return Err(RunError::TooManyArcs(arcs.len()));
    }
    *pipe = FramePipeline::new();
    let mut out = vec![ArcResult::default(); arcs.len()];
    let mut collect = |o: &ScanlineOutput<'_>| {
        let Some(&first) = o.tag.first() else { return };
        let Some(r) = out.get_mut((first >> 16) as usize) else {
            return;
        };
        r.points_out += o.tag.len() as u32;
        r.truncated += o.truncated;
        let at = |k: Option<u16>| {
            k.and_then(|k| o.tag.get(usize::from(k)))
                .map(|t| t & 0xFFFF)
        };
        r.left = at(o.left);
        r.right = at(o.right);
    };
    let mut enc = StreamEncoder::new();
    let mut buf = vec![0u8; MAX_PACKET_LEN];
    let n = enc
        .encode_config(&params.to_words(), &mut buf)
        .map_err(RunError::Encode)?;
    feed(pipe, &buf[..n], &mut collect)?;
    let period_ns = (1e9 / sensor.rate_hz) as u64;
    let step_ns = ((sensor.azimuth_step_deg / 360.0) * 1e9 / sensor.rate_hz).max(1.0) as u32;
    let mut recs: Vec<PointRecord> = Vec::with_capacity(MAX_POINTS_PER_PACKET);
    for (a, arc) in arcs.iter().enumerate() {
        let base = a as u64 * period_ns;
        for (c, chunk) in arc.points.chunks(MAX_POINTS_PER_PACKET).enumerate() {
            recs.clear();
            let k0 = c * MAX_POINTS_PER_PACKET;
            for (j, &i) in chunk.iter().enumerate() {
                let i = i as usize;
                let (xp, zp) = project(s.x[i], s.y[i], s.z[i]);
                let k = (k0 + j) as u32;
                recs.push(PointRecord {
                    dt_ns: j as u32 * step_ns,
                    x_m: xp,
                    z_m: zp,
                    intensity: s.intensity[i].clamp(0.0, 65535.0) as u16,
                    line_start: k == 0,
                    tag: ((a as u32) << 16) | (k & 0xFFFF),
                });
            }
            let t0 = base + u64::from(k0 as u32) * u64::from(step_ns);
            let m = enc
                .encode_points(t0, &recs, &mut buf)
                .map_err(RunError::Encode)?;
            feed(pipe, &buf[..m], &mut collect)?;
        }
        pipe.run(&mut collect);
    }
    pipe.finish(&mut collect);
    Ok(out)
}

/// Writes `b` into the pipeline, processing complete lines whenever the ring is full.
fn feed(
    pipe: &mut FramePipeline,
    b: &[u8],
    on_line: &mut impl FnMut(&ScanlineOutput<'_>),
) -> Result<(), RunError> {
    let mut off = 0;
    while off < b.len() {
        let w = pipe.write(&b[off..]);
        off += w;
        if w == 0 {
            pipe.run(&mut *on_line);
            let w2 = pipe.write(&b[off..]);
            if w2 == 0 {
                return Err(RunError::Stalled);
            }
            off += w2;
        }
    }
    Ok(())
}
