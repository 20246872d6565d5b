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
    /// The segment whose first heading h₀ (radians) and its sine and cosine were last
    /// computed: [`Self::project_f32`] turns them by the small angle to each point's heading.
    seg_trig: (usize, f64, f64, f64),
}

impl<'a> PoseCursor<'a> {
    /// A cursor at the start of `traj`.
    pub fn new(traj: &'a Trajectory) -> Self {
        Self {
            samples: &traj.samples,
            k: 0,
            sin_cos: (f64::NAN.to_bits(), f64::NAN, f64::NAN),
            turn: (usize::MAX, 0.0),
            seg_trig: (usize::MAX, f64::NAN, f64::NAN, f64::NAN),
        }
    }

    /// Scanner origin (x, y, z) and left vector (lx, ly) at time `t`, or `None` outside the
    /// trajectory. Times may go backwards (the cursor then searches again), but forward is
    /// the fast path.
    #[inline]
    pub fn frame_at(&mut self, t: f64) -> Option<([f64; 3], [f64; 2])> {
        let (q, h) = self.origin_heading(t)?;
        let (sin_h, cos_h) = self.sin_cos_of(h);
        Some((q, [-cos_h, sin_h]))
    }

    /// Scanner origin and heading (radians) at time `t`, or `None` outside the trajectory;
    /// leaves `self.k` at the segment that holds `t`.
    #[inline]
    fn origin_heading(&mut self, t: f64) -> Option<([f64; 3], f64)> {
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
        Some((
            [
                a.x + (b.x - a.x) * w,
                a.y + (b.y - a.y) * w,
                a.z + (b.z - a.z) * w,
            ],
            h,
        ))
    }

    /// libm's sine and cosine of `h`, kept for the next point of the same heading.
    #[inline]
    fn sin_cos_of(&mut self, h: f64) -> (f64, f64) {
        if h.to_bits() != self.sin_cos.0 {
            let (sin_h, cos_h) = h.sin_cos();
            self.sin_cos = (h.to_bits(), sin_h, cos_h);
        }
        let (_, sin_h, cos_h) = self.sin_cos;
        (sin_h, cos_h)
    }

    /// [`project_point`]'s (x′, z′) rounded to `f32`, the values the core takes, with the
    /// same bits, but most points without a libm sine and cosine of their own.
    ///
    /// The heading h is the same as [`Self::frame_at`]'s; its sine and cosine come from the
    /// segment's first heading h₀ turned by δ = h − h₀ (angle addition, δ's sine and cosine
    /// by their Taylor series), within [`TURN_ERROR`] of libm's. x′ computed with them is
    /// then within ε = (|Δx| + |Δy|)·[`X_ERROR`] of x′ computed with libm's, and when both
    /// ends of x′ ± ε round to the same `f32`, so does libm's x′ (rounding is monotonic).
    /// Otherwise, and whenever δ is large or a value is not finite, x′ is computed with
    /// libm's as in [`project_point`].
    #[inline]
    pub fn project_f32(&mut self, x: f64, y: f64, z: f64, t: f64) -> Option<(f32, f32)> {
        let (q, h) = self.origin_heading(t)?;
        let (dx, dy) = (x - q[0], y - q[1]);
        let z_m = (z - q[2]) as f32;
        if h.to_bits() != self.sin_cos.0 {
            if let Some((sin_h, cos_h)) = self.turned(h) {
                let v = dx * -cos_h + dy * sin_h;
                let eps = (dx.abs() + dy.abs()) * X_ERROR;
                let r = v as f32;
                if v.abs() > eps && (v - eps) as f32 == r && (v + eps) as f32 == r {
                    return Some((r, z_m));
                }
            }
        }
        let (sin_h, cos_h) = self.sin_cos_of(h);
        Some(((dx * -cos_h + dy * sin_h) as f32, z_m))
    }

    /// sin h and cos h from the current segment's first heading, within [`TURN_ERROR`] of
    /// libm's; `None` when h lies more than [`MAX_TURN_RAD`] from it.
    #[inline]
    fn turned(&mut self, h: f64) -> Option<(f64, f64)> {
        if self.seg_trig.0 != self.k {
            let h0 = self.samples[self.k].heading_deg.to_radians();
            let (s0, c0) = h0.sin_cos();
            self.seg_trig = (self.k, h0, s0, c0);
        }
        let (_, h0, s0, c0) = self.seg_trig;
        let d = h - h0;
        if !(d.abs() <= MAX_TURN_RAD) {
            return None;
        }
        let d2 = d * d;
        // sin δ − δ and cos δ − 1 to δ⁹ and δ¹⁰: the first term left out is below 10⁻¹⁸
        // for |δ| ≤ 0.1.
        let sin_m =
            -d * d2 * (1.0 / 6.0 - d2 * (1.0 / 120.0 - d2 * (1.0 / 5040.0 - d2 / 362_880.0)));
        let cos_m = -d2
            * (0.5
                - d2 * (1.0 / 24.0
                    - d2 * (1.0 / 720.0 - d2 * (1.0 / 40_320.0 - d2 / 3_628_800.0))));
        let sin_d = d + sin_m;
        Some((
            s0 + (s0 * cos_m + c0 * sin_d),
            c0 + (c0 * cos_m - s0 * sin_d),
        ))
    }
}

/// Largest turn δ (radians) from a segment's first heading that [`PoseCursor::project_f32`]
/// takes by angle addition; larger ones go to libm.
const MAX_TURN_RAD: f64 = 0.1;

/// Bound on the difference between the turned sine and cosine and libm's: libm's own error
/// (1 ulp, on sin h₀, cos h₀ and on sin h, cos h), δ = h − h₀ rounded once, the series' and
/// the sums' rounding; about 10⁻¹⁵ together, and `turned_sine_and_cosine_match_libm`
/// checks it.
const TURN_ERROR: f64 = 1e-14;

/// Bound on |x′ − x′_libm| per metre of |Δx| + |Δy|: the sine and cosine's [`TURN_ERROR`]
/// and the products' and the sum's rounding (2⁻⁵² each), with a tenfold margin.
const X_ERROR: f64 = 10.0 * TURN_ERROR;

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

    #[test]
    fn turned_sine_and_cosine_match_libm() {
        // Headings around the circle and beyond it, turned by up to the largest turn.
        let tr = Trajectory {
            samples: vec![pose(0.0, 0.0, 0.0, 0.0), pose(1.0, 1.0, 0.0, 0.0)],
        };
        let mut c = PoseCursor::new(&tr);
        let mut worst = 0f64;
        for i in 0..20_000 {
            let h0 = (i as f64 * 0.0377 - 400.0).to_radians();
            c.seg_trig = (c.k, h0, h0.sin(), h0.cos());
            for j in 0..25 {
                let h = h0 + (j as f64 - 12.0) / 12.0 * MAX_TURN_RAD * (1.0 - i as f64 * 1e-6);
                let (s, co) = c.turned(h).unwrap();
                worst = worst.max((s - h.sin()).abs()).max((co - h.cos()).abs());
            }
        }
        assert!(worst <= TURN_ERROR / 4.0, "worst {worst:e}");
        // A turn past the largest goes to libm.
        assert!(c.turned(c.seg_trig.1 + 2.0 * MAX_TURN_RAD).is_none());
    }

    #[test]
    fn projection_to_f32_is_the_libm_projection_rounded() {
        // A turning drive; points on both sides, near and far, at times within segments.
        let tr = Trajectory {
            samples: (0..200)
                .map(|k| {
                    let t = k as f64 * 0.005;
                    pose(t, 3.0e5 + t * 10.0, 4.0e6 + t * t, 350.0 + 30.0 * t)
                })
                .collect(),
        };
        let mut fast = PoseCursor::new(&tr);
        let mut plain = PoseCursor::new(&tr);
        let mut seed = 7u64;
        for k in 0..200_000 {
            seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
            let r = |sh: u32| ((seed >> sh) & 0xffff) as f64 / 65_536.0 - 0.5;
            let t = k as f64 * 0.995 / 200_000.0;
            let (x, y, z) = (
                3.0e5 + t * 10.0 + 60.0 * r(0),
                4.0e6 + 60.0 * r(16),
                3.0 * r(32),
            );
            let (xp, zp) = project_point(&mut plain, x, y, z, t).unwrap();
            let (xf, zf) = fast.project_f32(x, y, z, t).unwrap();
            assert_eq!(
                (xf.to_bits(), zf.to_bits()),
                ((xp as f32).to_bits(), (zp as f32).to_bits())
            );
        }
        assert!(fast.project_f32(0.0, 0.0, 0.0, 2.0).is_none());
    }
}
