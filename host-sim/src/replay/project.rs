//! Step (a) of Honma et al. (§2.2, Eq. 1–2), in `f64` on the host: each point is moved into
//! the vehicle-level frame of the scanner at its own time t (docs/spec.md §2):
//!
//! x′ = (p − q(t)) · l(t),  z′ = p_z − q_z(t),  l = (−cos h, sin h, 0),
//!
//! with q(t) and h(t) interpolated from the trajectory (positions linearly, heading along
//! the shorter arc). Only the small local offsets x′, z′ go to the core as `f32`; world
//! coordinates and absolute times never do.

use crate::io::trajectory::{Pose, Trajectory};

/// Walks a trajectory forward for increasing times, so a time-sorted run of points finds its
/// segment in amortised O(1) instead of a binary search per point. Interpolates exactly as
/// [`Trajectory::pose_at`] does.
pub struct PoseCursor<'a> {
    samples: &'a [Pose],
    k: usize,
    /// The last heading (radians) and its sine and cosine: a vehicle driving straight keeps
    /// one heading over many points, and the same heading gives the same bits.
    sin_cos: (u64, f64, f64),
    /// The segment whose heading change `dh` (degrees, along the shorter arc) was last
    /// computed, and that change: points come many to a segment, and `%` is a libm call.
    turn: (usize, f64),
}

impl<'a> PoseCursor<'a> {
    /// A cursor at the start of `traj`.
    pub fn new(traj: &'a Trajectory) -> Self {
        Self {
            samples: &traj.samples,
            k: 0,
            sin_cos: (f64::NAN.to_bits(), f64::NAN, f64::NAN),
            turn: (usize::MAX, 0.0),
        }
    }

    /// Scanner origin (x, y, z) and left vector (lx, ly) at time `t`, or `None` outside the
    /// trajectory. Times may go backwards (the cursor then searches again), but forward is
    /// the fast path.
    #[inline]
    pub fn frame_at(&mut self, t: f64) -> Option<([f64; 3], [f64; 2])> {
        let s = self.samples;
        let n = s.len();
        if n < 2 || !(t >= s[0].t && t <= s[n - 1].t) {
            return None;
        }
        if t < s[self.k].t {
            self.k = s.partition_point(|p| p.t <= t).saturating_sub(1);
        }
        while self.k + 2 < n && s[self.k + 1].t <= t {
            self.k += 1;
        }
        let (a, b) = (&s[self.k], &s[self.k + 1]);
        let w = ((t - a.t) / (b.t - a.t)).clamp(0.0, 1.0);
        if self.turn.0 != self.k {
            let mut dh = (b.heading_deg - a.heading_deg) % 360.0;
            if dh > 180.0 {
                dh -= 360.0;
            } else if dh < -180.0 {
                dh += 360.0;
            }
            self.turn = (self.k, dh);
        }
        let dh = self.turn.1;
        let h = (a.heading_deg + dh * w).to_radians();
        if h.to_bits() != self.sin_cos.0 {
            let (sin_h, cos_h) = h.sin_cos();
            self.sin_cos = (h.to_bits(), sin_h, cos_h);
        }
        let (_, sin_h, cos_h) = self.sin_cos;
        Some((
            [
                a.x + (b.x - a.x) * w,
                a.y + (b.y - a.y) * w,
                a.z + (b.z - a.z) * w,
            ],
            [-cos_h, sin_h],
        ))
    }
}

/// Projects one point (Eq. 1–2): returns (x′, z′) in metres, `None` outside the trajectory.
#[inline]
pub fn project_point(
    cur: &mut PoseCursor<'_>,
    x: f64,
    y: f64,
    z: f64,
    t: f64,
) -> Option<(f64, f64)> {
    let (q, l) = cur.frame_at(t)?;
    Some(((x - q[0]) * l[0] + (y - q[1]) * l[1], z - q[2]))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pose(t: f64, x: f64, y: f64, h: f64) -> Pose {
        Pose {
            t,
            x,
            y,
            z: 2.0,
            roll_deg: 0.0,
            pitch_deg: 0.0,
            heading_deg: h,
        }
    }

    #[test]
    fn driving_north_left_is_west() {
        // Driving north along x = 100: a point at x = 97 (3 m west) is 3 m to the left.
        let tr = Trajectory {
            samples: vec![pose(0.0, 100.0, 0.0, 0.0), pose(10.0, 100.0, 100.0, 0.0)],
        };
        let mut c = PoseCursor::new(&tr);
        let (xp, zp) = project_point(&mut c, 97.0, 50.0, 0.5, 5.0).unwrap();
        assert!((xp - 3.0).abs() < 1e-12 && (zp + 1.5).abs() < 1e-12);
        // East of the track is right (negative).
        let (xp, _) = project_point(&mut c, 101.5, 50.0, 0.5, 5.0).unwrap();
        assert!((xp + 1.5).abs() < 1e-12);
        assert!(project_point(&mut c, 0.0, 0.0, 0.0, 10.5).is_none());
    }

    #[test]
    fn driving_east_left_is_north_and_position_is_interpolated() {
        // Driving east (90°) from x = 0 to x = 10 over 1 s; at t = 0.25 the scanner is at x = 2.5.
        let tr = Trajectory {
            samples: vec![pose(0.0, 0.0, 0.0, 90.0), pose(1.0, 10.0, 0.0, 90.0)],
        };
        let mut c = PoseCursor::new(&tr);
        let (xp, _) = project_point(&mut c, 2.5, 4.0, 0.0, 0.25).unwrap();
        assert!((xp - 4.0).abs() < 1e-12);
        // Along-track offset does not enter x′.
        let (xp, _) = project_point(&mut c, 7.0, -2.0, 0.0, 0.25).unwrap();
        assert!((xp + 2.0).abs() < 1e-12);
    }

    #[test]
    fn cursor_agrees_with_pose_at_forward_and_backward() {
        let tr = Trajectory {
            samples: (0..50)
                .map(|k| {
                    let t = k as f64 * 0.1;
                    pose(
                        t,
                        t * 3.0,
                        (t * 0.7).sin(),
                        (350.0 + 4.0 * k as f64) % 360.0,
                    )
                })
                .collect(),
        };
        let mut c = PoseCursor::new(&tr);
        let mut ts: Vec<f64> = (0..490).map(|k| k as f64 * 0.01 + 0.003).collect();
        ts.extend([1.234, 0.05, 4.9]);
        for t in ts {
            let p = tr.pose_at(t).unwrap();
            let (q, l) = c.frame_at(t).unwrap();
            assert!(
                (q[0] - p.x).abs() < 1e-9 && (q[1] - p.y).abs() < 1e-9,
                "t={t}"
            );
            let pl = p.left();
            assert!(
                (l[0] - pl[0]).abs() < 1e-9 && (l[1] - pl[1]).abs() < 1e-9,
                "t={t}"
            );
        }
    }
}
