//! The vehicle: its path (the lane, swerving around parked cars), its speed (the scene's
//! speed with a slow ±5 % and a faster ±2 % variation) and its attitude (roll and pitch
//! from the road under its wheels plus a little body sway), sampled into a trajectory.
//!
//! The trajectory holds the scanner origin: the ground point under the vehicle plus the
//! scanner height along the body's up axis.

use super::scanner::body_axes;
use super::world::World;
use crate::io::trajectory::{Pose, Trajectory};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::TAU;

/// Trajectory sample rate, Hz.
pub const TRAJ_HZ: f64 = 200.0;
/// Trajectory margin before the first and after the last pulse, seconds.
pub const TRAJ_MARGIN_S: f64 = 0.5;
/// GPS time (adjusted standard, s) of the first pulse.
pub const T0_GPS: f64 = 400_001_234.5;

/// The drive: trajectory (scene-local coordinates) and the scanning time span.
pub struct Drive {
    /// 200 Hz trajectory covering the scan with [`TRAJ_MARGIN_S`] either side.
    pub traj: Trajectory,
    /// First pulse time and end of the last line.
    pub scan: (f64, f64),
    /// Length of the driven path during the scan, metres.
    pub length_m: f64,
}

/// Plans the drive at `speed_kmh`.
pub fn plan(world: &World, speed_kmh: f64, seed: u64) -> Drive {
    plan_pass(world, speed_kmh, seed, false, T0_GPS)
}

/// Plans a drive along the scene's path at `speed_kmh` whose first pulse fires at `t0`:
/// from the drive's start to its end, or with `reverse` from its end back to its start
/// (the same path, driven the other way).
pub fn plan_pass(world: &World, speed_kmh: f64, seed: u64, reverse: bool, t0: f64) -> Drive {
    let spec = &world.spec;
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0xD81E_0000_0000_0002);
    let ph = [
        rng.gen_range(0.0..TAU),
        rng.gen_range(0.0..TAU),
        rng.gen_range(0.0..TAU),
        rng.gen_range(0.0..TAU),
    ];
    let v0 = speed_kmh / 3.6;
    let margin_u = 3.0 * v0 + 10.0;
    let du = 0.05;
    let (u0, u1) = (spec.drive.0 - margin_u, spec.drive.1 + margin_u);
    // `a` runs along the drive: u itself, or −u when driven back.
    let sgn = if reverse { -1.0 } else { 1.0 };
    let (a0, a1) = if reverse { (-u1, -u0) } else { (u0, u1) };
    let (start, end) = if reverse {
        (-spec.drive.1, -spec.drive.0)
    } else {
        spec.drive
    };
    let n = ((a1 - a0) / du).ceil() as usize;
    let mut xy = Vec::with_capacity(n + 1);
    let mut us = Vec::with_capacity(n + 1);
    for i in 0..=n {
        let a = a0 + (a1 - a0) * i as f64 / n as f64;
        us.push(a);
        let u = sgn * a;
        xy.push(world.center.map(u, world.lane_v(u)));
    }
    let mut s = vec![0.0; xy.len()];
    for i in 1..xy.len() {
        s[i] = s[i - 1]
            + ((xy[i][0] - xy[i - 1][0]).powi(2) + (xy[i][1] - xy[i - 1][1]).powi(2)).sqrt();
    }
    let speed = |s: f64| {
        v0 * (1.0 + 0.05 * (TAU * s / 80.0 + ph[0]).sin() + 0.02 * (TAU * s / 17.0 + ph[1]).sin())
    };
    let mut t = vec![0.0; xy.len()];
    for i in 1..xy.len() {
        t[i] = t[i - 1] + (s[i] - s[i - 1]) / speed(0.5 * (s[i] + s[i - 1]));
    }
    let t_at_u = |u: f64| {
        let k = us.partition_point(|&x| x <= u).clamp(1, us.len() - 1);
        let w = (u - us[k - 1]) / (us[k] - us[k - 1]);
        t[k - 1] + (t[k] - t[k - 1]) * w
    };
    // Shift so the first pulse fires at t0; lines cover the drive.
    let shift = t0 - t_at_u(start);
    let lines = ((t_at_u(end) - t_at_u(start)) * spec.scanner.line_rate_hz).ceil();
    let scan = (t0, t0 + lines / spec.scanner.line_rate_hz);
    let length_m = {
        let sa = |u: f64| {
            let k = us.partition_point(|&x| x <= u).clamp(1, us.len() - 1);
            s[k - 1]
        };
        sa(end) - sa(start)
    };
    // Position along the path by time.
    let at_time = |tt: f64| -> ([f64; 2], [f64; 2]) {
        let tl = tt - shift;
        let k = t.partition_point(|&x| x <= tl).clamp(1, t.len() - 1);
        let w = (tl - t[k - 1]) / (t[k] - t[k - 1]);
        let p = [
            xy[k - 1][0] + (xy[k][0] - xy[k - 1][0]) * w,
            xy[k - 1][1] + (xy[k][1] - xy[k - 1][1]) * w,
        ];
        // Direction from a ±0.5 m chord, smooth along the path.
        let sk = s[k - 1] + (s[k] - s[k - 1]) * w;
        let ia = s.partition_point(|&x| x < sk - 0.5).min(s.len() - 1);
        let ib = s.partition_point(|&x| x < sk + 0.5).min(s.len() - 1);
        let d = [xy[ib][0] - xy[ia][0], xy[ib][1] - xy[ia][1]];
        (p, d)
    };
    let g = &world.ground;
    let gz = |x: f64, y: f64| g.height(x, y).map(|h| h.0).unwrap_or(0.0);
    let n_s = ((scan.1 - scan.0 + 2.0 * TRAJ_MARGIN_S) * TRAJ_HZ).ceil() as usize;
    let mut samples = Vec::with_capacity(n_s + 1);
    for i in 0..=n_s {
        let tt = scan.0 - TRAJ_MARGIN_S + i as f64 / TRAJ_HZ;
        let (p, d) = at_time(tt);
        let heading = d[0].atan2(d[1]).to_degrees().rem_euclid(360.0);
        let hr = heading.to_radians();
        let (f, l) = ([hr.sin(), hr.cos()], [-hr.cos(), hr.sin()]);
        // Attitude from the road under the wheels (track 1.6 m, wheelbase 2.6 m).
        let h_left = gz(p[0] + 0.8 * l[0], p[1] + 0.8 * l[1]);
        let h_right = gz(p[0] - 0.8 * l[0], p[1] - 0.8 * l[1]);
        let h_front = gz(p[0] + 1.3 * f[0], p[1] + 1.3 * f[1]);
        let h_back = gz(p[0] - 1.3 * f[0], p[1] - 1.3 * f[1]);
        let sway = |a: f64, hz: f64, k: usize| a * (TAU * hz * (tt - T0_GPS) + ph[k]).sin();
        let roll = ((h_left - h_right) / 1.6).atan().to_degrees() + sway(0.25, 0.9, 2);
        let pitch = ((h_front - h_back) / 2.6).atan().to_degrees() + sway(0.15, 1.3, 3);
        let [_, _, up] = body_axes(heading, pitch, roll);
        let z0 = 0.5 * (h_left + h_right);
        let hs = spec.scanner.height_m;
        samples.push(Pose {
            t: tt,
            x: p[0] + up[0] * hs,
            y: p[1] + up[1] * hs,
            z: z0 + up[2] * hs,
            roll_deg: roll,
            pitch_deg: pitch,
            heading_deg: heading,
        });
    }
    Drive {
        traj: Trajectory { samples },
        scan,
        length_m,
    }
}
