//! The scanner: a full-circle profiler like the RIEGL VQ-250 (Honma et al. Table 1).
//!
//! The mirror turns about an axis fixed in the vehicle body. In the body frame (forward,
//! left, up) the axis is the driving direction turned left by `yaw_deg` about the vertical,
//! then tilted down by `pitch_deg`: `a = (cos p·cos y, cos p·sin y, −sin p)`. The scan plane
//! is perpendicular to `a` through the scanner origin; with 45°/40° its lowest direction
//! points 50° below the horizon, back and to the right, so the ground trace is a line at 45°
//! to the driving direction, behind the scanner on the left and ahead on the right.
//!
//! Scan angle θ is measured in the scan plane from that lowest direction, positive towards
//! `a × down` (or the other way with `counter_clockwise = false`), in (−180°, 180°]. A line
//! starts at the top (θ = −180°) and ends at the top, so lines split at the top as docs/spec.md §2
//! expects. Pulse `j` of line `k` fires at `t = t0 + k/line_rate + j/(line_rate·pulses)`
//! with θ = −180° + 360°·(j + ½)/pulses; every pulse uses the pose interpolated at its own
//! time, so the vehicle moves during a line.
//!
//! Body rotation (docs/spec.md §2 heading; roll and pitch as in aviation): start from
//! forward `f = (sin h, cos h, 0)`, left `l = (−cos h, sin h, 0)`, up `u`; pitch (nose up
//! positive) turns `f` and `u` about `l`; roll (right side down positive) then turns `l` and
//! `u` about the new forward axis.

use super::ground::ToeCoord;
use super::prims::Material;
use super::world::World;
use crate::io::trajectory::{Pose, Trajectory};
use rand::Rng;
use rand_distr::StandardNormal;

pub use super::scene::{ScannerConfig, VehicleBody};

/// Body axes (forward, left, up) in world coordinates for a pose.
pub fn body_axes(heading_deg: f64, pitch_deg: f64, roll_deg: f64) -> [[f64; 3]; 3] {
    let (sh, ch) = heading_deg.to_radians().sin_cos();
    let (sp, cp) = pitch_deg.to_radians().sin_cos();
    let (sr, cr) = roll_deg.to_radians().sin_cos();
    let f = [sh, ch, 0.0];
    let l = [-ch, sh, 0.0];
    let u = [0.0, 0.0, 1.0];
    let f1 = add(scale(f, cp), scale(u, sp));
    let u1 = add(scale(u, cp), scale(f, -sp));
    let l2 = add(scale(l, cr), scale(u1, sr));
    let u2 = add(scale(u1, cr), scale(l, -sr));
    [f1, l2, u2]
}

fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn unit(a: [f64; 3]) -> [f64; 3] {
    scale(a, 1.0 / dot(a, a).sqrt())
}

/// The scan angle of pulse `j`, degrees in (−180, 180).
pub fn scan_angle_deg(cfg: &ScannerConfig, j: usize) -> f64 {
    -180.0 + 360.0 * (j as f64 + 0.5) / cfg.pulses_per_line as f64
}

/// Pulse directions in the body frame (forward, left, up), one per pulse of a line.
pub fn mount_directions(cfg: &ScannerConfig) -> Vec<[f64; 3]> {
    let (sy, cy) = cfg.yaw_deg.to_radians().sin_cos();
    let (sp, cp) = cfg.pitch_deg.to_radians().sin_cos();
    let a = [cp * cy, cp * sy, -sp];
    let down = [0.0, 0.0, -1.0];
    let v_down = unit(add(down, scale(a, -dot(a, down))));
    let mut v_side = cross(a, v_down);
    if !cfg.counter_clockwise {
        v_side = scale(v_side, -1.0);
    }
    (0..cfg.pulses_per_line)
        .map(|j| {
            let (s, c) = scan_angle_deg(cfg, j).to_radians().sin_cos();
            add(scale(v_down, c), scale(v_side, s))
        })
        .collect()
}

/// Whether a body-frame direction from the scanner hits the vehicle itself: such pulses
/// give no return. The body is the box of [`VehicleBody`] down to the ground; with the
/// default mount this shades a narrow strip of road about 3.5 m to the right of the path,
/// as real rigs do, and much more with a low pitch and a large yaw.
pub fn hits_own_vehicle(d: [f64; 3], height_m: f64, body: &VehicleBody) -> bool {
    let lo = [body.ahead_m.0, -body.half_width_m, -height_m];
    let hi = [body.ahead_m.1, body.half_width_m, -body.roof_below_m];
    let mut t0 = 0.0f64;
    let mut t1 = f64::INFINITY;
    for k in 0..3 {
        if d[k].abs() < 1e-12 {
            if 0.0 < lo[k] || 0.0 > hi[k] {
                return false;
            }
            continue;
        }
        let mut a = lo[k] / d[k];
        let mut b = hi[k] / d[k];
        if a > b {
            std::mem::swap(&mut a, &mut b);
        }
        t0 = t0.max(a);
        t1 = t1.min(b);
    }
    t0 <= t1
}

/// One return.
#[derive(Clone, Copy, Debug)]
pub struct Return {
    /// Scene-local position (with range noise), metres.
    pub p: [f64; 3],
    /// GPS time, seconds.
    pub t: f64,
    /// Intensity.
    pub intensity: u16,
    /// Scan angle, degrees.
    pub scan_angle_deg: f64,
    /// For ground hits near a curb toe: where the *true* hit lies relative to the toe.
    pub toe: Option<ToeCoord>,
    /// The laser's ring (0 = lowest beam) of a spinning sensor; 0 for the profiler.
    pub ring: u16,
}

/// Casts every pulse of line `k` (first pulse at `t_line`) and returns its returns in
/// time order.
pub fn cast_line<R: Rng>(
    world: &World,
    traj: &Trajectory,
    dirs: &[[f64; 3]],
    own: &[bool],
    t_line: f64,
    rng: &mut R,
) -> Vec<Return> {
    let cfg = &world.spec.scanner;
    let dt = 1.0 / (cfg.line_rate_hz * cfg.pulses_per_line as f64);
    let mut out = Vec::with_capacity(cfg.pulses_per_line);
    for (j, db) in dirs.iter().enumerate() {
        if own[j] {
            continue;
        }
        let t = t_line + j as f64 * dt;
        let Some(pose) = traj.pose_at(t) else {
            continue;
        };
        let Some(ret) = cast_pulse(world, &pose, *db, rng) else {
            continue;
        };
        out.push(Return {
            p: ret.0,
            t,
            intensity: ret.1,
            scan_angle_deg: scan_angle_deg(cfg, j),
            toe: ret.2,
            ring: 0,
        });
    }
    out
}

/// Casts one pulse from `pose` along the body-frame direction `db`: the first surface hit
/// with range noise, its intensity and, for ground hits near a toe, the toe coordinates.
pub(super) fn cast_pulse<R: Rng>(
    world: &World,
    pose: &Pose,
    db: [f64; 3],
    rng: &mut R,
) -> Option<([f64; 3], u16, Option<ToeCoord>)> {
    let cfg = &world.spec.scanner;
    let [f, l, u] = body_axes(pose.heading_deg, pose.pitch_deg, pose.roll_deg);
    let d = add(add(scale(f, db[0]), scale(l, db[1])), scale(u, db[2]));
    let o = [pose.x, pose.y, pose.z];
    let ground = if d[2] < 0.05 {
        world
            .ground
            .intersect(o, d, cfg.min_range_m, 80.0f64.min(cfg.max_range_m))
    } else {
        None
    };
    let tmax = ground.map(|g| g.0).unwrap_or(cfg.max_range_m);
    let obj = world.objects.intersect(o, d, cfg.min_range_m, tmax);
    let (t, n, mat, toe) = match (obj, ground) {
        (Some(h), _) => (h.t, h.n, h.material, None),
        (None, Some((t, toe))) => {
            let p = [o[0] + d[0] * t, o[1] + d[1] * t];
            let n = world.ground.normal(p[0], p[1]);
            let mat = match toe {
                Some(tc) if tc.s > 0.0 || -tc.s < world.ground.shape.gutter_m => Material::Concrete,
                _ => Material::Asphalt,
            };
            (t, n, mat, toe)
        }
        (None, None) => return None,
    };
    // Range noise; a few outliers (multipath, dust, mixed pixels) off by up to metres.
    let mut r = t + cfg.range_sigma_m * rng.sample::<f64, _>(StandardNormal);
    if rng.gen::<f64>() < cfg.outlier_rate {
        r += rng.gen_range(-1.5..4.0);
    }
    if r < cfg.min_range_m {
        return None;
    }
    let p = add(o, scale(d, r));
    // Intensity: Lambertian reflectance with incidence and a soft range falloff, speckle.
    let cos_inc = dot(n, d).abs();
    let raw = mat.reflectance() * (0.25 + 0.75 * cos_inc) / (1.0 + (t / 60.0).powi(2));
    let speckle: f64 = 1.0 + 0.08 * rng.sample::<f64, _>(StandardNormal);
    let intensity = (raw * speckle * 60000.0).clamp(1.0, 65535.0) as u16;
    Some((p, intensity, toe.filter(|tc| tc.s.abs() < 0.3)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn heading_90_points_east_and_left_is_north() {
        let [f, l, u] = body_axes(90.0, 0.0, 0.0);
        assert!((f[0] - 1.0).abs() < 1e-12 && f[1].abs() < 1e-12);
        assert!(l[0].abs() < 1e-12 && (l[1] - 1.0).abs() < 1e-12);
        assert_eq!(u, [0.0, 0.0, 1.0]);
        // Pitch up 10°: forward gains +sin 10° in z. Roll 10° (right down) about the pitched
        // forward axis: left rises by sin 10° · cos 10°.
        let [f, l, _] = body_axes(90.0, 10.0, 10.0);
        assert!((f[2] - 10f64.to_radians().sin()).abs() < 1e-12);
        let r = 10f64.to_radians();
        assert!((l[2] - r.sin() * r.cos()).abs() < 1e-12);
    }

    #[test]
    fn lowest_pulse_is_50_degrees_down_and_the_plane_is_yawed_45() {
        let cfg = ScannerConfig::default();
        let dirs = mount_directions(&cfg);
        // The two middle pulses straddle θ = 0 (the lowest direction).
        let d = dirs[cfg.pulses_per_line / 2];
        let elev = d[2].asin().to_degrees();
        assert!((elev + 50.0).abs() < 0.2, "{elev}");
        // Every direction is perpendicular to the mirror axis.
        let a = [
            40f64.to_radians().cos() * 45f64.to_radians().cos(),
            40f64.to_radians().cos() * 45f64.to_radians().sin(),
            -40f64.to_radians().sin(),
        ];
        for d in &dirs {
            assert!(dot(*d, a).abs() < 1e-12);
        }
        // The first pulse points (nearly) to the top of the circle: 50° above the horizon.
        assert!((dirs[0][2].asin().to_degrees() - 50.0).abs() < 0.2);
        // Horizontal directions of the plane are at 45° to the driving direction.
        let q = dirs
            .iter()
            .min_by(|a, b| a[2].abs().total_cmp(&b[2].abs()))
            .unwrap();
        let ang = q[1].atan2(q[0]).to_degrees();
        assert!(
            (ang.abs() - 135.0).abs() < 0.5 || (ang.abs() - 45.0).abs() < 0.5,
            "{ang}"
        );
    }

    #[test]
    fn own_vehicle_blocks_rays_ahead_and_down_only() {
        assert!(hits_own_vehicle(
            [0.7, 0.0, -0.7],
            2.0,
            &VehicleBody::default()
        ));
        // The lowest pulse (back and right, 50° down) clears the body.
        let cfg = ScannerConfig::default();
        let low = mount_directions(&cfg)[cfg.pulses_per_line / 2];
        assert!(!hits_own_vehicle(low, 2.0, &cfg.body));
        assert!(!hits_own_vehicle([-0.7, 0.0, -0.7], 2.0, &cfg.body));
        assert!(!hits_own_vehicle([0.0, 0.0, 1.0], 2.0, &cfg.body));
    }
}
