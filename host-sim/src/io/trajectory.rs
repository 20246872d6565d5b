//! The trajectory (SPEC §3): CSV `time,x,y,z,roll,pitch,heading`, GPS time in the LAS time
//! base, scanner origin in the LAS CRS, angles in degrees, heading clockwise from grid north.
//! Interpolated at a point's time: positions linearly, heading along the shorter arc.

/// One trajectory sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// GPS time, seconds.
    pub t: f64,
    /// Scanner origin, LAS CRS, metres.
    pub x: f64,
    /// Scanner origin, LAS CRS, metres.
    pub y: f64,
    /// Scanner origin, LAS CRS, metres.
    pub z: f64,
    /// Roll, degrees.
    pub roll_deg: f64,
    /// Pitch, degrees.
    pub pitch_deg: f64,
    /// Heading, degrees clockwise from grid north (0 = +Y, 90 = +X).
    pub heading_deg: f64,
}

impl Pose {
    /// Forward unit vector f = (sin h, cos h) in the horizontal plane.
    pub fn forward(&self) -> [f64; 2] {
        let h = self.heading_deg.to_radians();
        [h.sin(), h.cos()]
    }

    /// Left unit vector l = (−cos h, sin h) in the horizontal plane.
    pub fn left(&self) -> [f64; 2] {
        let h = self.heading_deg.to_radians();
        [-h.cos(), h.sin()]
    }
}

/// A trajectory: samples strictly increasing in time.
#[derive(Clone, Debug, Default)]
pub struct Trajectory {
    /// The samples, strictly increasing in `t`.
    pub samples: Vec<Pose>,
}

impl Trajectory {
    /// First and last time covered.
    pub fn time_range(&self) -> Option<(f64, f64)> {
        Some((self.samples.first()?.t, self.samples.last()?.t))
    }

    /// The pose at time `t`, interpolated (positions and roll/pitch linearly, heading along
    /// the shorter arc), or `None` outside the covered time range.
    pub fn pose_at(&self, t: f64) -> Option<Pose> {
        let s = &self.samples;
        if s.is_empty() || !t.is_finite() || t < s[0].t || t > s[s.len() - 1].t {
            return None;
        }
        let k = s.partition_point(|p| p.t <= t);
        if k == 0 {
            return Some(s[0]);
        }
        if k >= s.len() {
            return Some(s[s.len() - 1]);
        }
        let (a, b) = (&s[k - 1], &s[k]);
        let w = (t - a.t) / (b.t - a.t);
        let lerp = |u: f64, v: f64| u + (v - u) * w;
        let mut dh = (b.heading_deg - a.heading_deg) % 360.0;
        if dh > 180.0 {
            dh -= 360.0;
        } else if dh < -180.0 {
            dh += 360.0;
        }
        Some(Pose {
            t,
            x: lerp(a.x, b.x),
            y: lerp(a.y, b.y),
            z: lerp(a.z, b.z),
            roll_deg: lerp(a.roll_deg, b.roll_deg),
            pitch_deg: lerp(a.pitch_deg, b.pitch_deg),
            heading_deg: (a.heading_deg + dh * w).rem_euclid(360.0),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pose(t: f64, x: f64, h: f64) -> Pose {
        Pose {
            t,
            x,
            y: 0.0,
            z: 2.0,
            roll_deg: 0.0,
            pitch_deg: 0.0,
            heading_deg: h,
        }
    }

    #[test]
    fn heading_interpolates_along_the_shorter_arc() {
        let tr = Trajectory {
            samples: vec![pose(0.0, 0.0, 350.0), pose(1.0, 10.0, 10.0)],
        };
        let p = tr.pose_at(0.5).unwrap();
        assert!((p.x - 5.0).abs() < 1e-12);
        assert!(p.heading_deg.abs() < 1e-9 || (p.heading_deg - 360.0).abs() < 1e-9);
        assert!(tr.pose_at(1.5).is_none());
        assert!(tr.pose_at(-0.1).is_none());
    }

    #[test]
    fn left_is_minus_x_when_driving_north() {
        let p = pose(0.0, 0.0, 0.0);
        assert_eq!(p.forward(), [0.0, 1.0]);
        let l = p.left();
        assert!((l[0] + 1.0).abs() < 1e-12 && l[1].abs() < 1e-12);
        // Driving east (90°): left is north.
        let l = pose(0.0, 0.0, 90.0).left();
        assert!(l[0].abs() < 1e-12 && (l[1] - 1.0).abs() < 1e-12);
    }
}
