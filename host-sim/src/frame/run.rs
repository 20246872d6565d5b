//! A frame's half-arcs through the core ([`crate::rings::run`]), each arc's candidates
//! read back as positions along the arc.
//!
//! - x′, z′ are [`crate::rings::project`]'s.
//! - The tag is (arc << 16) | k, so every output point is mapped back to its arc and place
//!   without a lookup.

use crate::io::sweep::Sweep;
use crate::rings::run::{self as arc_run, ArcPipeline, ArcPoint, ArcRunError, Feed};
use crate::rings::{project, HalfArc, SensorModel};
use curbtrace_core::kernel::{KernelParams, ScanlineOutput};

/// The pipeline type the frames run through.
pub type FramePipeline = ArcPipeline;

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
    /// Encoding or feeding the pipeline failed.
    #[error("{0}")]
    Core(#[from] ArcRunError),
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
    let points = arcs.iter().enumerate().map(|(a, arc)| {
        arc.points.iter().enumerate().map(move |(k, &i)| {
            let i = i as usize;
            let (x_m, z_m) = project(s.x[i], s.y[i], s.z[i]);
            ArcPoint {
                x_m,
                z_m,
                intensity: s.intensity[i].clamp(0.0, 65535.0) as u16,
                tag: ((a as u32) << 16) | (k as u32 & 0xFFFF),
            }
        })
    });
    arc_run::run_arcs(pipe, params, sensor, 0, points, Feed::Direct, &mut collect)?;
    Ok(out)
}
