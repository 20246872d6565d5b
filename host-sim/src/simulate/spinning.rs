//! Spinning multi-beam lidars (Velodyne VLP-16, HDL-32E, HDL-64E S2, Ouster OS1-64) on the
//! roof of the vehicle, for `curbtrace simulate --sensor` (docs/simulator.md, *Spinning
//! sensors*).
//!
//! A sensor is a column of lasers at fixed elevation angles turning about the vehicle's
//! up axis, clockwise seen from above, `rate_hz` revolutions a second. A revolution holds
//! `firings` firing cycles; laser `j` fires `laser_dt_s · slot(j)` after its cycle starts
//! (its published firing order), at the azimuth the head has reached at that instant:
//!
//! φ(t) = 180° − 360° · rate · (t − t_rev)   (anticlockwise from ahead; a revolution
//! starts facing behind),
//!
//! direction (body frame: forward, left, up) = (cos e cos φ, cos e sin φ, sin e). Every
//! firing uses the pose interpolated at its own time, so the vehicle moves during a
//! revolution. A ray that meets the roof box ([`ROOF`]) returns nothing. The ring of a laser
//! is its rank by elevation, 0 the lowest beam.

use super::scanner::{cast_pulse, hits_own_vehicle, Return, VehicleBody};
use super::world::World;
use crate::io::trajectory::Trajectory;
use rand::Rng;

/// Horizontal range within which a ground return counts as evidence for the reference,
/// metres: the "curb observed within 20 m of the path".
pub const REFERENCE_RANGE_M: f64 = 20.0;

/// The roof under a roof-mounted sensor: 2 m of roof from 1.2 m behind to 0.8 m ahead,
/// 1.5 m wide, 0.3 m below the optical centre. Beams steeper than about 14° behind, 20°
/// ahead and 22° to the sides meet it (the blind circle around a car).
pub const ROOF: VehicleBody = VehicleBody {
    ahead_m: (-1.2, 0.8),
    half_width_m: 0.75,
    roof_below_m: 0.3,
};

/// A spinning sensor's published geometry and timing.
#[derive(Clone, Copy, Debug)]
pub struct SpinSensor {
    /// Command-line name.
    pub key: &'static str,
    /// Product name.
    pub name: &'static str,
    /// Elevation of each laser, degrees, in the order the lasers fire within a cycle.
    pub elevations_deg: &'static [f64],
    /// Revolutions per second.
    pub rate_hz: f64,
    /// Firing cycles per revolution (each laser fires once per cycle).
    pub firings: usize,
    /// Time between two lasers' firings within a cycle, seconds (0: all at once).
    pub laser_dt_s: f64,
    /// Lasers that fire together (HDL-64E: one of each block).
    pub group: usize,
    /// Range noise, one sigma, metres.
    pub range_sigma_m: f64,
}

const VLP16_ELEV: [f64; 16] = [
    -15.0, 1.0, -13.0, 3.0, -11.0, 5.0, -9.0, 7.0, -7.0, 9.0, -5.0, 11.0, -3.0, 13.0, -1.0, 15.0,
];

const HDL32_ELEV: [f64; 32] = [
    -30.67, -9.33, -29.33, -8.00, -28.00, -6.67, -26.67, -5.33, -25.33, -4.00, -24.00, -2.67,
    -22.67, -1.33, -21.33, 0.00, -20.00, 1.33, -18.67, 2.67, -17.33, 4.00, -16.00, 5.33, -14.67,
    6.67, -13.33, 8.00, -12.00, 9.33, -10.67, 10.67,
];

/// HDL-64E S2: upper block +2° to −8.33° in 1/3° steps, lower block −8.83° to −24.33° in
/// ½° steps; laser k of the upper block fires with laser k of the lower one.
const HDL64_ELEV: [f64; 64] = {
    let mut e = [0.0; 64];
    let mut k = 0;
    while k < 32 {
        e[2 * k] = 2.0 - k as f64 * (10.33 / 31.0);
        e[2 * k + 1] = -8.83 - k as f64 * 0.5;
        k += 1;
    }
    e
};

/// OS1-64 (uniform beams): +16.6° to −16.6°, every channel firing at the column's time.
const OS1_64_ELEV: [f64; 64] = {
    let mut e = [0.0; 64];
    let mut k = 0;
    while k < 64 {
        e[k] = 16.6 - k as f64 * (33.2 / 63.0);
        k += 1;
    }
    e
};

impl SpinSensor {
    /// Velodyne VLP-16: ±15° every 2°, 2.304 µs between lasers, a 55.296 µs cycle (0.2°
    /// at 10 Hz), ±3 cm.
    pub const VLP16: Self = Self {
        key: "vlp16",
        name: "Velodyne VLP-16",
        elevations_deg: &VLP16_ELEV,
        rate_hz: 10.0,
        firings: 1808,
        laser_dt_s: 2.304e-6,
        group: 1,
        range_sigma_m: 0.03,
    };
    /// Velodyne HDL-32E: −30.67° to +10.67° every 1.33°, 1.152 µs between lasers, a
    /// 46.08 µs cycle (0.166° at 10 Hz), ±2 cm.
    pub const HDL32: Self = Self {
        key: "hdl32",
        name: "Velodyne HDL-32E",
        elevations_deg: &HDL32_ELEV,
        rate_hz: 10.0,
        firings: 2170,
        laser_dt_s: 1.152e-6,
        group: 1,
        range_sigma_m: 0.02,
    };
    /// Velodyne HDL-64E S2: 2 000 firings per revolution at 10 Hz (0.18° per laser, as the
    /// KITTI frames hold), the 32 lasers of each block in turn, ±2 cm.
    pub const HDL64: Self = Self {
        key: "hdl64",
        name: "Velodyne HDL-64E S2",
        elevations_deg: &HDL64_ELEV,
        rate_hz: 10.0,
        firings: 2000,
        laser_dt_s: 1.0 / (10.0 * 2000.0 * 32.0),
        group: 2,
        range_sigma_m: 0.02,
    };
    /// Ouster OS1-64: 1 024 columns at 10 Hz (0.35°), ±3 cm.
    pub const OS1_64: Self = Self {
        key: "os1-64",
        name: "Ouster OS1-64",
        elevations_deg: &OS1_64_ELEV,
        rate_hz: 10.0,
        firings: 1024,
        laser_dt_s: 0.0,
        group: 64,
        range_sigma_m: 0.03,
    };

    /// Every sensor, in the command line's order.
    pub const ALL: [Self; 4] = [Self::VLP16, Self::HDL32, Self::HDL64, Self::OS1_64];

    /// The sensor named `key`.
    pub fn by_key(key: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|s| s.key == key)
    }

    /// Number of lasers.
    pub fn lasers(&self) -> usize {
        self.elevations_deg.len()
    }

    /// The ring of each laser: its rank by elevation, 0 the lowest.
    pub fn rings(&self) -> Vec<u16> {
        let e = self.elevations_deg;
        (0..e.len())
            .map(|j| e.iter().filter(|&&o| o < e[j]).count() as u16)
            .collect()
    }

    /// Duration of one firing cycle, seconds.
    pub fn cycle_s(&self) -> f64 {
        1.0 / (self.rate_hz * self.firings as f64)
    }

    /// Azimuth step between two firings of one laser, degrees.
    pub fn azimuth_step_deg(&self) -> f64 {
        360.0 / self.firings as f64
    }

    /// Time of laser `j`'s firing after its cycle starts, seconds.
    pub fn laser_offset_s(&self, j: usize) -> f64 {
        (j / self.group.max(1)) as f64 * self.laser_dt_s
    }
}

/// Casts revolution `k` (starting at `t_rev`) and returns its returns in time order. Ground
/// returns farther than [`REFERENCE_RANGE_M`] horizontally carry no toe evidence.
pub fn cast_revolution<R: Rng>(
    world: &World,
    traj: &Trajectory,
    sensor: &SpinSensor,
    t_rev: f64,
    rng: &mut R,
) -> Vec<Return> {
    let height = world.spec.scanner.height_m;
    let rings = sensor.rings();
    let (cycle, rate) = (sensor.cycle_s(), sensor.rate_hz);
    let elev: Vec<(f64, f64)> = sensor
        .elevations_deg
        .iter()
        .map(|e| e.to_radians().sin_cos())
        .collect();
    let mut order: Vec<usize> = (0..sensor.lasers()).collect();
    order.sort_by(|&a, &b| {
        sensor
            .laser_offset_s(a)
            .total_cmp(&sensor.laser_offset_s(b))
    });
    let mut out = Vec::with_capacity(sensor.firings * sensor.lasers() / 2);
    for f in 0..sensor.firings {
        let t_f = t_rev + f as f64 * cycle;
        for &j in &order {
            let t = t_f + sensor.laser_offset_s(j);
            let phi = (180.0 - 360.0 * rate * (t - t_rev)).to_radians();
            let (se, ce) = elev[j];
            let (sp, cp) = phi.sin_cos();
            let d = [ce * cp, ce * sp, se];
            if hits_own_vehicle(d, height, &ROOF) {
                continue;
            }
            let Some(pose) = traj.pose_at(t) else {
                continue;
            };
            let Some((p, intensity, toe)) = cast_pulse(world, &pose, d, rng) else {
                continue;
            };
            let near = (p[0] - pose.x).hypot(p[1] - pose.y) <= REFERENCE_RANGE_M;
            out.push(Return {
                p,
                t,
                intensity,
                scan_angle_deg: 0.0,
                toe: toe.filter(|_| near),
                ring: rings[j],
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rings_rank_the_lasers_by_elevation() {
        for s in SpinSensor::ALL {
            let r = s.rings();
            let mut sorted = r.clone();
            sorted.sort();
            assert_eq!(
                sorted,
                (0..s.lasers() as u16).collect::<Vec<_>>(),
                "{}",
                s.key
            );
            let lowest = (0..s.lasers())
                .min_by(|&a, &b| s.elevations_deg[a].total_cmp(&s.elevations_deg[b]))
                .unwrap();
            assert_eq!(r[lowest], 0);
        }
        assert_eq!(SpinSensor::VLP16.rings()[0], 0);
        assert_eq!(SpinSensor::VLP16.rings()[1], 8);
        assert!((HDL64_ELEV[62] + 8.33).abs() < 1e-9 && (HDL64_ELEV[63] + 24.33).abs() < 1e-9);
    }

    #[test]
    fn published_timing() {
        // VLP-16: 55.296 µs a cycle is 0.199° at 10 Hz; the last laser fires 34.6 µs in.
        let v = SpinSensor::VLP16;
        assert!((v.cycle_s() - 55.296e-6).abs() < 0.05e-6);
        assert!((v.laser_offset_s(15) - 34.56e-6).abs() < 1e-9);
        // HDL-64E: 0.18° per laser, 1.28 M firings a second; both blocks fire together.
        let h = SpinSensor::HDL64;
        assert!((h.azimuth_step_deg() - 0.18).abs() < 1e-12);
        assert_eq!(h.laser_offset_s(0), h.laser_offset_s(1));
        assert!(h.laser_offset_s(63) < h.cycle_s());
        assert_eq!(SpinSensor::by_key("os1-64").unwrap().lasers(), 64);
        assert!(SpinSensor::by_key("hdl65").is_none());
    }
}
