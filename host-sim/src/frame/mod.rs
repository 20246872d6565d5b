//! Curbs in one lidar frame, in the sensor frame (docs/frames.md): the `curbtrace frame`
//! job.
//!
//! 1. [`crate::rings::half_arcs`] cuts every ring into front and rear half-arcs.
//! 2. [`run`] sends them through `curbtrace_core::Pipeline` via the wire format, with the
//!    sensor's kernel parameters ([`crate::rings::SensorModel::kernel_params`]).
//! 3. [`step`] measures the height step across every candidate on the ring's own points
//!    and rejects vehicles, walls and seams; [`column`] rejects candidates on which
//!    something stands, seen by any ring.
//! 4. [`link`] links the accepted candidates of each side, ring to ring, into polylines.
//! 5. [`write`] writes them as GeoJSON or CSV in the sensor frame.

pub mod column;
pub mod link;
pub mod run;
pub mod step;
pub mod write;

use crate::io::sweep::Sweep;
use crate::model::Side;
use crate::rings::{half_arcs, ArcCounters, ArcParams, Half, SensorModel};
use curbtrace_core::kernel::KernelParams;
use link::LinkParams;
use run::{run_arcs, FramePipeline, RunError};
use serde::{Deserialize, Serialize};
use step::{StepParams, Verdict};

/// Every parameter of the frame job (a TOML file's sections).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FrameParams {
    /// The half-arc cut.
    pub rings: ArcParams,
    /// The candidate check.
    pub step: StepParams,
    /// The linking.
    pub link: LinkParams,
    /// Kernel parameters; `None`: the sensor's ([`SensorModel::kernel_params`]).
    #[serde(skip)]
    pub kernel: Option<KernelParams>,
}

/// One candidate of one half-arc, checked.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CheckedCandidate {
    /// The sweep index of the candidate point.
    pub point: u32,
    /// Its side.
    pub side: Side,
    /// Ring and half of its arc.
    pub ring: u16,
    /// Front or rear half-arc.
    pub half: Half,
    /// The check's verdict.
    pub verdict: Verdict,
}

/// A curb polyline in the sensor frame.
#[derive(Clone, Debug, PartialEq)]
pub struct CurbLine {
    /// Side of the vehicle.
    pub side: Side,
    /// Vertices `[x, y, z]` (the candidates, toe of the curb), in order of x.
    pub points: Vec<[f64; 3]>,
    /// Median height step over the vertices, metres.
    pub height_m: f64,
    /// The step at each vertex, metres.
    pub steps_m: Vec<f64>,
}

impl CurbLine {
    /// Horizontal length, metres.
    pub fn length_m(&self) -> f64 {
        self.points
            .windows(2)
            .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
            .sum()
    }
}

/// Counts of one frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FrameCounters {
    /// Points in the sweep.
    pub points: u64,
    /// The half-arc cut's counts.
    pub arcs: ArcCounters,
    /// Points the core returned.
    pub points_kernel: u64,
    /// Points the core dropped as over an arc's capacity.
    pub truncated: u64,
    /// Candidates from the core.
    pub candidates: u32,
    /// Accepted as curbs.
    pub curbs: u32,
    /// Rejected: something too tall beyond (vehicle, wall).
    pub objects: u32,
    /// Rejected: step outside the curb range.
    pub no_step: u32,
    /// Rejected: step not measurable.
    pub unmeasured: u32,
}

/// The result of one frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrameResult {
    /// The curb polylines.
    pub lines: Vec<CurbLine>,
    /// Every candidate with its verdict.
    pub candidates: Vec<CheckedCandidate>,
    /// Counts.
    pub counters: FrameCounters,
}

/// Finds the curbs of one sweep. `pipe` is the core's pipeline, reused across frames.
pub fn extract_frame(
    s: &Sweep,
    sensor: &SensorModel,
    p: &FrameParams,
    pipe: &mut FramePipeline,
) -> Result<FrameResult, RunError> {
    let kernel = p.kernel.unwrap_or_else(|| sensor.kernel_params());
    let step_params = StepParams {
        min_step_m: p.step.min_step_m.max(step::kernel_floor_m(&kernel)),
        ..p.step
    };
    let (arcs, arc_counters) = half_arcs(s, &p.rings);
    let results = run_arcs(s, &arcs, sensor, &kernel, pipe)?;
    let mut out = FrameResult {
        counters: FrameCounters {
            points: s.len() as u64,
            arcs: arc_counters,
            ..FrameCounters::default()
        },
        ..FrameResult::default()
    };
    let c = &mut out.counters;
    for (arc, r) in arcs.iter().zip(&results) {
        c.points_kernel += u64::from(r.points_out);
        c.truncated += u64::from(r.truncated);
        for (side, k) in [(Side::Left, r.left), (Side::Right, r.right)] {
            let Some(k) = k else { continue };
            // Along the front arc y rises (right to left), along the rear one it falls.
            let outward = match (side, arc.half) {
                (Side::Left, Half::Front) | (Side::Right, Half::Rear) => 1,
                _ => -1,
            };
            let verdict = step::check(s, &arc.points, k as usize, outward, &step_params);
            out.candidates.push(CheckedCandidate {
                point: arc.points[k as usize],
                side,
                ring: arc.ring,
                half: arc.half,
                verdict,
            });
        }
    }
    // The column test on the ring's curbs, over a grid of the points that can count.
    let z_min = out
        .candidates
        .iter()
        .filter_map(|c| match c.verdict {
            Verdict::Curb { road_z, .. } => Some(road_z + step_params.max_rise_m),
            _ => None,
        })
        .fold(f32::INFINITY, f32::min);
    if z_min.is_finite() {
        let grid = column::ColumnGrid::new(
            s,
            p.rings.max_reach_m + p.rings.max_lateral_m,
            p.rings.max_lateral_m + 1.0,
            z_min,
        );
        for cand in out.candidates.iter_mut() {
            if let Verdict::Curb { road_z, .. } = cand.verdict {
                let i = cand.point as usize;
                let above = road_z + step_params.max_rise_m;
                let n = grid.count_above(s, s.x[i], s.y[i], step_params.column_radius_m, above);
                if n >= step_params.column_min_points {
                    cand.verdict = Verdict::Column { points: n as u32 };
                }
            }
        }
    }
    let c = &mut out.counters;
    for cand in &out.candidates {
        c.candidates += 1;
        match cand.verdict {
            Verdict::Curb { .. } => c.curbs += 1,
            Verdict::Object { .. } | Verdict::Column { .. } => c.objects += 1,
            Verdict::NoStep { .. } => c.no_step += 1,
            Verdict::Unmeasured => c.unmeasured += 1,
        }
    }
    for side in [Side::Left, Side::Right] {
        let acc: Vec<(u32, f32)> = out
            .candidates
            .iter()
            .filter(|c| c.side == side)
            .filter_map(|c| match c.verdict {
                Verdict::Curb { step_m, .. } => Some((c.point, step_m)),
                _ => None,
            })
            .collect();
        let xy: Vec<[f64; 2]> = acc
            .iter()
            .map(|&(i, _)| [f64::from(s.x[i as usize]), f64::from(s.y[i as usize])])
            .collect();
        for chain in link::link(&xy, &p.link) {
            let points: Vec<[f64; 3]> = chain
                .iter()
                .map(|&k| {
                    let i = acc[k].0 as usize;
                    [f64::from(s.x[i]), f64::from(s.y[i]), f64::from(s.z[i])]
                })
                .collect();
            let steps_m: Vec<f64> = chain.iter().map(|&k| f64::from(acc[k].1)).collect();
            let mut sorted = steps_m.clone();
            sorted.sort_by(f64::total_cmp);
            let height_m = sorted[sorted.len() / 2];
            out.lines.push(CurbLine {
                side,
                points,
                height_m,
                steps_m,
            });
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests;
