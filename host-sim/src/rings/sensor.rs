//! Per-sensor facts and the kernel parameters that follow from them (docs/frames.md,
//! *Per-sensor kernel defaults*).
//!
//! The bend angle of a point needs a neighbour within d_b on each side along the line. On a
//! ring, consecutive points of one laser are Δφ apart in azimuth, so at horizontal range r
//! they are r·Δφ apart, and in the half-arc's x′ = y projection at most that (a ring
//! crossing a curb ahead of the car at forward distance x has its points x·Δφ apart across
//! the curb). d_b is therefore set from the sensor's azimuth step alone:
//!
//! d_b = max(0.07 m, 1.5 · Δφ · 15 m)
//!
//! — the profiler default (0.07 m) unless the sensor's points at 15 m ahead (the middle of
//! the half-arcs' reach, [`super::ArcParams::max_reach_m`]) are farther apart than 0.07 / 1.5;
//! 1.5 spacings leave half a spacing for the jitter between firings. Nothing here is fitted
//! to a scene.

use crate::io::sweep::{Sweep, SweepFormat};
use curbtrace_core::kernel::KernelParams;

/// Range at which d_b must still span 1.5 point spacings, metres.
pub const D_B_RANGE_M: f32 = 15.0;
/// Spacings d_b spans at [`D_B_RANGE_M`].
pub const D_B_SPACINGS: f32 = 1.5;
/// τ_ρmin on rings, degrees: above the profiler default. A profiler's candidates at a low
/// step (d_b·sin τ_min high) are confirmed by tracking over hundreds of scanlines; a ring
/// frame crosses a curb with a handful of half-arcs, so a peak must be a step of at least
/// d_b·sin 35° (40 mm at d_b = 0.07 m) to count.
pub const RING_TAU_MIN_DEG: f32 = 35.0;

/// A spinning lidar: what the ring-to-scanline rule needs to know about it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SensorModel {
    /// Name for messages and outputs.
    pub name: &'static str,
    /// Number of lasers (rings).
    pub rings: u16,
    /// Revolutions per second.
    pub rate_hz: f32,
    /// Azimuth between consecutive points of one laser, degrees.
    pub azimuth_step_deg: f32,
}

impl SensorModel {
    /// Velodyne HDL-64E S2 as KITTI recorded it: 10 Hz, 0.18° between consecutive points of
    /// one laser in the stored frames (median over every laser of the four sample frames;
    /// the spec sheet's 0.08–0.09° counts both laser blocks together).
    pub const HDL64: Self = Self {
        name: "HDL-64E",
        rings: 64,
        rate_hz: 10.0,
        azimuth_step_deg: 0.18,
    };
    /// Velodyne HDL-32E as nuScenes runs it: 20 Hz, 1 084 firings per revolution (0.33°).
    pub const HDL32: Self = Self {
        name: "HDL-32E",
        rings: 32,
        rate_hz: 20.0,
        azimuth_step_deg: 0.33,
    };
    /// Velodyne VLP-16 at its default 10 Hz: 0.2° (spec sheet).
    pub const VLP16: Self = Self {
        name: "VLP-16",
        rings: 16,
        rate_hz: 10.0,
        azimuth_step_deg: 0.2,
    };

    /// The sensor a sweep's format implies; for PCD, the one with the sweep's ring count
    /// (16, 32 or 64 lasers at 10 Hz), else a generic sensor with that many rings and the
    /// coarsest of the three steps (0.33°), so d_b errs towards having neighbours.
    pub fn for_sweep(s: &Sweep) -> Self {
        match s.format {
            SweepFormat::Kitti => Self::HDL64,
            SweepFormat::NuScenes => Self::HDL32,
            SweepFormat::Pcd => match s.rings {
                0..=16 => Self::VLP16,
                17..=32 => Self {
                    rate_hz: 10.0,
                    azimuth_step_deg: 0.16,
                    ..Self::HDL32
                },
                33..=64 => Self {
                    azimuth_step_deg: 0.09,
                    ..Self::HDL64
                },
                n => Self {
                    name: "spinning lidar",
                    rings: n,
                    rate_hz: 10.0,
                    azimuth_step_deg: 0.33,
                },
            },
        }
    }

    /// Spacing of consecutive points of one laser at horizontal range `r_m`, metres.
    pub fn spacing_m(&self, r_m: f32) -> f32 {
        r_m * self.azimuth_step_deg.to_radians()
    }

    /// The kernel parameters for this sensor: the defaults with d_b from the azimuth step
    /// (module docs), τ_ρmin at [`RING_TAU_MIN_DEG`], the line split left to the half-arcs' line-start flags (no split on
    /// time gaps shorter than a revolution: a half-arc may skip the sector the vehicle
    /// hides) and never on geometry.
    pub fn kernel_params(&self) -> KernelParams {
        let d = KernelParams::DEFAULT;
        let d_b = d.d_b_m.max(D_B_SPACINGS * self.spacing_m(D_B_RANGE_M));
        KernelParams {
            d_b_m: round_mm(d_b),
            tau_min_deg: RING_TAU_MIN_DEG,
            split_gap_ns: (1e9 / self.rate_hz) as u32,
            split_geometry: 2,
            ..d
        }
    }

    /// Time of a point relative to the instant the sensor faced straight ahead, seconds.
    /// Velodyne sensors turn clockwise seen from above, so a point at azimuth φ = atan2(y, x)
    /// (counter-clockwise from ahead) was measured −φ/360° of a revolution from then: the
    /// left side (φ = 90°) a quarter turn before, the right side a quarter turn after.
    pub fn time_from_ahead_s(&self, x: f32, y: f32) -> f32 {
        -y.atan2(x).to_degrees() / 360.0 / self.rate_hz
    }
}

fn round_mm(v: f32) -> f32 {
    (v * 1000.0).round() / 1000.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn d_b_follows_the_azimuth_step() {
        // 0.18° at 15 m is 47 mm; 1.5 spacings 71 mm.
        assert_eq!(SensorModel::HDL64.kernel_params().d_b_m, 0.071);
        // 0.33° at 15 m is 86 mm; 1.5 spacings 130 mm.
        assert_eq!(SensorModel::HDL32.kernel_params().d_b_m, 0.130);
        // 0.2° at 15 m is 52 mm; 1.5 spacings 79 mm.
        assert_eq!(SensorModel::VLP16.kernel_params().d_b_m, 0.079);
        // A fine sensor keeps the profiler default.
        let fine = SensorModel {
            azimuth_step_deg: 0.05,
            ..SensorModel::HDL64
        };
        assert_eq!(fine.kernel_params().d_b_m, KernelParams::DEFAULT.d_b_m);
        for s in [SensorModel::HDL64, SensorModel::HDL32, SensorModel::VLP16] {
            let p = s.kernel_params();
            p.validate().unwrap();
            assert_eq!(p.split_geometry, 2);
            assert!(u64::from(p.split_gap_ns) >= 50_000_000, "{}", s.name);
        }
    }

    #[test]
    fn time_runs_clockwise_from_ahead() {
        let s = SensorModel::HDL64;
        assert!((s.time_from_ahead_s(0.0, 5.0) + 0.025).abs() < 1e-6);
        assert!((s.time_from_ahead_s(0.0, -5.0) - 0.025).abs() < 1e-6);
        assert_eq!(s.time_from_ahead_s(5.0, 0.0), 0.0);
    }
}
