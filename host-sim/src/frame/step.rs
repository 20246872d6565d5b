//! The height step across a candidate, measured on the ring's own points, and the test
//! that tells a curb from a vehicle or a wall (docs/frames.md, *Checking a candidate*).
//!
//! From the candidate the ring is walked along the arc, outward and inward, while
//! consecutive points are within [`StepParams::max_gap_m`] of each other in 3-D and the
//! path is at most [`StepParams::max_walk_m`] (so points far ahead whose projection falls
//! at the same lateral offset are never mixed in). Then:
//!
//! - **road** — the median z of the inward points [`StepParams::band_m`] to the side of the
//!   candidate (laterally, in y);
//! - **top** — the median z of the outward points in the same band beyond it;
//! - **step** = top − road;
//! - **rise** — the highest point beside the candidate, above the road: the arc is
//!   followed both ways (across breaks) while it stays within
//!   [`StepParams::object_window_m`] of the candidate laterally, and points within
//!   [`OBJECT_REACH_M`] of it horizontally count.
//!
//! A curb has a step of [`StepParams::min_step_m`] (at least [`kernel_floor_m`])…
//! [`StepParams::max_step_m`], and nothing beside it rises more than
//! [`StepParams::max_rise_m`] above the road within the window (a toe has road on one side
//! and the kerb top on the other): a vehicle's flank, a wall or a pole rises higher, a road
//! seam or a gutter has no step.

use crate::io::sweep::Sweep;
use serde::{Deserialize, Serialize};

/// Parameters of the check (`[step]` in a config file).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StepParams {
    /// Lateral band beside the candidate where road and top heights are taken, metres:
    /// past the toe's rounding, within the width of a kerb stone's top.
    pub band_m: [f32; 2],
    /// The walk along the ring stops at a 3-D gap longer than this, metres (a break in
    /// the ring: occlusion, a kerb face seen edge-on).
    pub max_gap_m: f32,
    /// The walk along the ring stops after this path length, metres.
    pub max_walk_m: f32,
    /// Smallest step of a curb, metres. The frame job raises it to the kernel's floor
    /// ([`kernel_floor_m`]): a candidate across a smaller step was not made by a step.
    pub min_step_m: f32,
    /// Largest step of a curb, metres.
    pub max_step_m: f32,
    /// Window beside the candidate (both sides) where nothing may rise above
    /// [`Self::max_rise_m`], metres.
    pub object_window_m: f32,
    /// Highest rise above the road within the window of a curb, metres: the tallest
    /// kerbs are about 0.3 m.
    pub max_rise_m: f32,
    /// Radius of the column around the candidate in which the points of every ring are
    /// counted (`frame::column`), metres.
    pub column_radius_m: f32,
    /// Points of the column standing more than [`Self::max_rise_m`] above the road that
    /// make the candidate a vehicle, wall or post (one or two may be a stray return).
    pub column_min_points: usize,
}

impl Default for StepParams {
    fn default() -> Self {
        Self {
            band_m: [0.1, 0.4],
            max_gap_m: 0.3,
            max_walk_m: 3.0,
            min_step_m: 0.03,
            max_step_m: 0.30,
            object_window_m: 0.6,
            max_rise_m: 0.35,
            column_radius_m: 0.25,
            column_min_points: 3,
        }
    }
}

/// Horizontal distance from the candidate within which the rise is sought, metres: a
/// vehicle parked at the kerb, not a facade farther out that the ring reaches at the same
/// lateral offset.
pub const OBJECT_REACH_M: f32 = 3.0;

/// The smallest sharp step the kernel marks as a peak: d_b · sin τ_min (a step of height h
/// seen with d_b > h bends by asin(h / d_b)), metres.
pub fn kernel_floor_m(k: &curbtrace_core::kernel::KernelParams) -> f32 {
    k.d_b_m * k.tau_min_deg.to_radians().sin()
}

/// What the check found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Verdict {
    /// A curb: step and road height, metres.
    Curb {
        /// Top minus road.
        step_m: f32,
        /// Road height beside the toe (sensor frame z).
        road_z: f32,
    },
    /// Something rises more than `max_rise_m` beyond: a vehicle, a wall, a pole.
    Object {
        /// The rise, metres.
        rise_m: f32,
    },
    /// Something stands on the candidate: points of the sweep in the column around it
    /// more than `max_rise_m` above the road (`frame::column`).
    Column {
        /// How many.
        points: u32,
    },
    /// The step is outside the curb range (a seam, a gutter, a dip, a ledge).
    NoStep {
        /// The step, metres.
        step_m: f32,
    },
    /// No points in one of the bands: the step cannot be measured.
    Unmeasured,
}

/// Checks the candidate at position `k` of the arc `points`; `outward` is +1 when the
/// side's outward direction runs to higher positions along the arc, else −1.
pub fn check(s: &Sweep, points: &[u32], k: usize, outward: isize, p: &StepParams) -> Verdict {
    let c = points[k] as usize;
    let yc = s.y[c];
    let mut top = Vec::new();
    let mut road = Vec::new();
    let mut rise = s.z[c];
    walk(s, points, k, outward, p, |i| {
        let o = (s.y[i] - yc).abs();
        if o >= p.band_m[0] && o <= p.band_m[1] {
            top.push(s.z[i]);
        }
    });
    walk(s, points, k, -outward, p, |i| {
        let o = (s.y[i] - yc).abs();
        if o >= p.band_m[0] && o <= p.band_m[1] {
            road.push(s.z[i]);
        }
    });
    // The rise ignores breaks in the ring: a vehicle's flank or a wall is usually met
    // across one (the beam jumps from the road to the nearer surface). It follows the arc
    // both ways until it leaves the lateral window, and takes the points within
    // `OBJECT_REACH_M` of the candidate horizontally.
    for dir in [outward, -outward] {
        let mut j = k;
        while let Some(n) = j.checked_add_signed(dir).filter(|&n| n < points.len()) {
            let i = points[n] as usize;
            if (s.y[i] - yc).abs() > p.object_window_m {
                break;
            }
            if (s.x[i] - s.x[c]).hypot(s.y[i] - yc) <= OBJECT_REACH_M {
                rise = rise.max(s.z[i]);
            }
            j = n;
        }
    }
    let Some(r) = median(&mut road) else {
        return Verdict::Unmeasured;
    };
    if rise - r > p.max_rise_m {
        return Verdict::Object { rise_m: rise - r };
    }
    let Some(t) = median(&mut top) else {
        return Verdict::Unmeasured;
    };
    let step = t - r;
    if step < p.min_step_m || step > p.max_step_m {
        return Verdict::NoStep { step_m: step };
    }
    Verdict::Curb {
        step_m: step,
        road_z: r,
    }
}

/// Calls `f` with every point (sweep index) met walking from position `k` in direction
/// `dir` while the ring stays unbroken (module docs).
fn walk(s: &Sweep, points: &[u32], k: usize, dir: isize, p: &StepParams, mut f: impl FnMut(usize)) {
    let (mut j, mut path) = (k, 0.0f32);
    while let Some(next) = j.checked_add_signed(dir).filter(|&n| n < points.len()) {
        let (a, b) = (points[j] as usize, points[next] as usize);
        let d = ((s.x[a] - s.x[b]).powi(2) + (s.y[a] - s.y[b]).powi(2) + (s.z[a] - s.z[b]).powi(2))
            .sqrt();
        path += d;
        if d > p.max_gap_m || path > p.max_walk_m {
            break;
        }
        f(b);
        j = next;
    }
}

/// The median (upper of the two middle values), `None` when empty.
fn median(v: &mut [f32]) -> Option<f32> {
    if v.is_empty() {
        return None;
    }
    let m = v.len() / 2;
    Some(*v.select_nth_unstable_by(m, f32::total_cmp).1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::sweep::SweepFormat;

    /// A line of points across y from −1 to +1 m at x = 10, 2 cm apart, road at z = −1.7
    /// for y < 0, then `profile(y)` above it.
    fn line(profile: impl Fn(f32) -> f32) -> (Sweep, Vec<u32>) {
        let mut s = Sweep::with_capacity(SweepFormat::Kitti, 0);
        for j in 0..=100 {
            let y = -1.0 + 0.02 * j as f32;
            let z = if y < 0.0 { -1.7 } else { -1.7 + profile(y) };
            s.push(10.0, y, z, 0.0, 0);
        }
        let pts = (0..s.len() as u32).collect();
        (s, pts)
    }

    #[test]
    fn a_kerb_is_a_curb_with_its_height() {
        let (s, pts) = line(|_| 0.12);
        match check(&s, &pts, 50, 1, &StepParams::default()) {
            Verdict::Curb { step_m, road_z } => {
                assert!((step_m - 0.12).abs() < 1e-5 && (road_z + 1.7).abs() < 1e-5)
            }
            v => panic!("{v:?}"),
        }
    }

    #[test]
    fn a_car_flank_or_a_wall_is_an_object() {
        // 0.12 m kerb, then a wall 0.3 m behind its toe.
        let (s, pts) = line(|y| if y < 0.3 { 0.12 } else { 2.0 });
        assert!(matches!(
            check(&s, &pts, 50, 1, &StepParams::default()),
            Verdict::Object { rise_m } if (rise_m - 2.0).abs() < 1e-5
        ));
    }

    #[test]
    fn a_seam_has_no_step_and_a_gap_cannot_be_measured() {
        let (s, pts) = line(|_| 0.01);
        assert!(matches!(
            check(&s, &pts, 50, 1, &StepParams::default()),
            Verdict::NoStep { .. }
        ));
        // Everything beyond the toe is 1 m farther ahead: the ring is broken there.
        let (mut s, pts) = line(|_| 0.12);
        for i in 51..s.len() {
            s.x[i] += 1.0;
        }
        assert_eq!(
            check(&s, &pts, 50, 1, &StepParams::default()),
            Verdict::Unmeasured
        );
    }
}
