//! The road centre line: a chain of straight and circular pieces, and the map from road
//! coordinates `(u, v)` (along, to the left) to scene-local XY.

/// One piece of the road centre line.
#[derive(Clone, Copy, Debug)]
pub enum Piece {
    /// Straight, length in metres.
    Straight(f64),
    /// Circular arc: radius (m) and turn angle (degrees, positive = to the left).
    Arc(f64, f64),
}

/// The road centre line: start point, start direction, pieces. Beyond its ends it
/// continues straight.
#[derive(Clone, Debug)]
pub struct Centerline {
    /// Start direction, radians counter-clockwise from +X.
    pub start_dir: f64,
    /// The pieces.
    pub pieces: Vec<Piece>,
    /// Start `u` of the centre line (may be negative).
    pub u_start: f64,
    starts: Vec<(f64, [f64; 2], f64)>,
}

impl Centerline {
    /// A centre line starting at local (0, 0) at `u = u_start`, compass heading `heading_deg`.
    pub fn new(heading_deg: f64, u_start: f64, pieces: Vec<Piece>) -> Self {
        let start_dir = (90.0 - heading_deg).to_radians();
        let mut starts = Vec::new();
        let (mut u, mut p, mut a) = (u_start, [0.0, 0.0], start_dir);
        for pc in &pieces {
            starts.push((u, p, a));
            match *pc {
                Piece::Straight(l) => {
                    p = [p[0] + l * a.cos(), p[1] + l * a.sin()];
                    u += l;
                }
                Piece::Arc(r, ang) => {
                    let th = ang.to_radians();
                    let s = th.signum();
                    let c = [p[0] - s * r * a.sin(), p[1] + s * r * a.cos()];
                    let a2 = a + th;
                    p = [c[0] + s * r * a2.sin(), c[1] - s * r * a2.cos()];
                    u += r * th.abs();
                    a = a2;
                }
            }
        }
        starts.push((u, p, a));
        Centerline {
            start_dir,
            pieces,
            u_start,
            starts,
        }
    }

    /// End `u` of the pieces.
    pub fn u_end(&self) -> f64 {
        self.starts.last().map(|s| s.0).unwrap_or(self.u_start)
    }

    /// Position and direction (radians from +X) at `u`.
    pub fn pose(&self, u: f64) -> ([f64; 2], f64) {
        if u <= self.u_start || self.pieces.is_empty() {
            let (u0, p, a) = self.starts[0];
            let l = u - u0;
            return ([p[0] + l * a.cos(), p[1] + l * a.sin()], a);
        }
        let k = self.starts.partition_point(|s| s.0 <= u);
        if k >= self.starts.len() {
            let (u0, p, a) = *self.starts.last().unwrap_or(&(0.0, [0.0, 0.0], 0.0));
            let l = u - u0;
            return ([p[0] + l * a.cos(), p[1] + l * a.sin()], a);
        }
        let (u0, p, a) = self.starts[k - 1];
        let l = u - u0;
        match self.pieces[k - 1] {
            Piece::Straight(_) => ([p[0] + l * a.cos(), p[1] + l * a.sin()], a),
            Piece::Arc(r, ang) => {
                let s = ang.signum();
                let c = [p[0] - s * r * a.sin(), p[1] + s * r * a.cos()];
                let a2 = a + s * l / r;
                ([c[0] + s * r * a2.sin(), c[1] - s * r * a2.cos()], a2)
            }
        }
    }

    /// Road coordinates to scene-local XY.
    pub fn map(&self, u: f64, v: f64) -> [f64; 2] {
        let (p, a) = self.pose(u);
        [p[0] - v * a.sin(), p[1] + v * a.cos()]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn centerline_arc_ends_where_geometry_says() {
        // Heading 90° (east), 10 m straight, then a 90° left turn of radius 10: ends at
        // (20, 10) heading north.
        let c = Centerline::new(
            90.0,
            0.0,
            vec![Piece::Straight(10.0), Piece::Arc(10.0, 90.0)],
        );
        let (p, a) = c.pose(10.0 + 10.0 * PI / 2.0);
        assert!(
            (p[0] - 20.0).abs() < 1e-9 && (p[1] - 10.0).abs() < 1e-9,
            "{p:?}"
        );
        assert!((a - PI / 2.0).abs() < 1e-12);
        // Left of an eastward road is north.
        let q = c.map(5.0, 2.0);
        assert!((q[0] - 5.0).abs() < 1e-12 && (q[1] - 2.0).abs() < 1e-12);
        // Beyond the end it continues straight.
        let (p, _) = c.pose(10.0 + 10.0 * PI / 2.0 + 3.0);
        assert!((p[0] - 20.0).abs() < 1e-9 && (p[1] - 13.0).abs() < 1e-9);
    }
}
