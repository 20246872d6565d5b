//! Synthetic scanlines for the kernel's tests and `benches/kernel.rs` (which includes this
//! file with `#[path]`). Pure f64 arithmetic — no maths library, no allocation — so it
//! compiles unchanged in both places.
//!
//! The scene is a road cross-section in the x′–z′ plane with the scanner at (0, 0): a
//! crowned road with a cross slope, a vertical curb on each side, sidewalks rising away from
//! the road, and building walls. A rotating mirror sends beams at a fixed angular step; each
//! beam returns the first surface it hits (nothing from the sky), with Gaussian noise added
//! to both coordinates. Weeds: beams passing through a box on the road in front of a toe
//! return, with some probability, a point inside the box instead of the surface behind.
#![allow(dead_code)]

/// Deterministic random numbers (SplitMix64).
pub struct Rng(pub u64);

impl Rng {
    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Uniform in [a, b).
    pub fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.uniform()
    }
    /// Approximately standard normal (Irwin–Hall: sum of 12 uniforms − 6).
    pub fn normal(&mut self) -> f64 {
        let mut s = 0.0;
        for _ in 0..12 {
            s += self.uniform();
        }
        s - 6.0
    }
}

/// sin and cos by Taylor series after reduction to [−π, π] (|error| < 1e-15 there).
pub fn sin_cos(t: f64) -> (f64, f64) {
    let two_pi = 2.0 * core::f64::consts::PI;
    let mut t = t % two_pi;
    if t > core::f64::consts::PI {
        t -= two_pi;
    } else if t < -core::f64::consts::PI {
        t += two_pi;
    }
    let (mut s, mut c) = (0.0, 0.0);
    let mut term = 1.0; // t^k / k!
    for k in 0..40 {
        match k % 4 {
            0 => c += term,
            1 => s += term,
            2 => c -= term,
            _ => s -= term,
        }
        term *= t / f64::from(k + 1);
    }
    (s, c)
}

/// The scene's parameters (metres; x′ left positive, z′ up, scanner at (0, 0)).
#[derive(Clone, Copy, Debug)]
pub struct Scene {
    /// Height of the scanner above the road directly below it.
    pub scanner_h: f64,
    /// x′ of the left curb's toe (> 0).
    pub left_toe_x: f64,
    /// x′ of the right curb's toe (< 0).
    pub right_toe_x: f64,
    /// Curb height (both sides).
    pub curb_h: f64,
    /// Road cross slope from the crown (midway between the toes) down to each curb.
    pub cross_slope: f64,
    /// Sidewalk width; walls stand at its outer edge.
    pub sidewalk_w: f64,
    /// Wall height above the sidewalk.
    pub wall_h: f64,
    /// Angular step of the mirror, degrees.
    pub step_deg: f64,
    /// Standard deviation of the noise on each coordinate.
    pub noise_m: f64,
    /// Probability that a beam through a weed box returns from a weed.
    pub weed_p: f64,
    /// Weed box: width on the road in front of each toe, and height above the road.
    pub weed_w: f64,
    /// See `weed_w`.
    pub weed_h: f64,
    /// Scan direction: true for increasing angle (right side first), false for the other
    /// rotation.
    pub ccw: bool,
}

impl Scene {
    /// The test scene: scanner 2 m up, toes at +2.4 m and −4.6 m (a 7 m road, vehicle in
    /// the right lane), 150 mm curbs, 2 % cross slope, 0.123° steps (≈2000 returns),
    /// 5 mm noise, no weeds.
    pub const DEFAULT: Self = Self {
        scanner_h: 2.0,
        left_toe_x: 2.4,
        right_toe_x: -4.6,
        curb_h: 0.15,
        cross_slope: 0.02,
        sidewalk_w: 3.0,
        wall_h: 6.0,
        step_deg: 0.123,
        noise_m: 0.005,
        weed_p: 0.0,
        weed_w: 0.05,
        weed_h: 0.10,
        ccw: true,
    };

    /// Road height at x′.
    pub fn road_z(&self, x: f64) -> f64 {
        let c = 0.5 * (self.left_toe_x + self.right_toe_x);
        let zc = -self.scanner_h + self.cross_slope * c.abs();
        zc - self.cross_slope * (x - c).abs()
    }

    /// The toe corners (left, right).
    pub fn toes(&self) -> [(f64, f64); 2] {
        [
            (self.left_toe_x, self.road_z(self.left_toe_x)),
            (self.right_toe_x, self.road_z(self.right_toe_x)),
        ]
    }

    /// The surface polyline from the top of the right wall to the top of the left one.
    fn polyline(&self) -> [(f64, f64); 12] {
        let side = |toe: f64, dir: f64| {
            let zt = self.road_z(toe);
            let top = (toe, zt + self.curb_h);
            let outer_x = toe + dir * self.sidewalk_w;
            let outer = (outer_x, zt + self.curb_h + 0.02 * self.sidewalk_w);
            let wall_top = (outer_x, outer.1 + self.wall_h);
            [(toe, zt), top, outer, wall_top]
        };
        let l = side(self.left_toe_x, 1.0);
        let r = side(self.right_toe_x, -1.0);
        let c = 0.5 * (self.left_toe_x + self.right_toe_x);
        [
            r[3],
            r[2],
            r[1],
            r[0],
            (c, self.road_z(c)),
            (c, self.road_z(c)),
            l[0],
            l[1],
            l[2],
            l[3],
            l[3],
            l[3],
        ]
    }

    /// Casts one beam at `theta` (radians from straight down, positive towards +x′);
    /// returns the distance to the first hit.
    fn cast(&self, dx: f64, dz: f64) -> Option<f64> {
        let poly = self.polyline();
        let mut best: Option<f64> = None;
        for w in poly.windows(2) {
            let (p, q) = (w[0], w[1]);
            let (ex, ez) = (q.0 - p.0, q.1 - p.1);
            let den = dx * ez - dz * ex;
            if den.abs() < 1e-15 {
                continue;
            }
            // Solve u·D = P + v·E.
            let u = (p.0 * ez - p.1 * ex) / den;
            let v = (p.0 * dz - p.1 * dx) / den;
            if u > 1e-9 && (0.0..=1.0).contains(&v) && best.is_none_or(|b| u < b) {
                best = Some(u);
            }
        }
        best
    }

    /// Number of weed returns [`Scene::generate`] produces with this seed.
    pub fn count_weeds(&self, seed: u64) -> usize {
        let mut rng = Rng(seed);
        let mut buf = [(0f32, 0f32, 0u32); 1];
        self.run(&mut rng, &mut buf).1
    }

    /// Generates the line into `out` (x′, z′, beam number), returns the number of points.
    /// Points beyond `out.len()` are dropped.
    pub fn generate(&self, rng: &mut Rng, out: &mut [(f32, f32, u32)]) -> usize {
        self.run(rng, out).0
    }

    /// [`Scene::generate`], also counting weed returns.
    fn run(&self, rng: &mut Rng, out: &mut [(f32, f32, u32)]) -> (usize, usize) {
        let mut weeds = 0;
        let step = self.step_deg.to_radians();
        let beams = (360.0 / self.step_deg) as i64;
        let mut n = 0;
        for b in 0..beams {
            let k = if self.ccw { b } else { beams - 1 - b };
            // From straight up (−π) around through straight down (0).
            let theta = -core::f64::consts::PI + (k as f64 + 0.5) * step;
            let (s, c) = sin_cos(theta);
            let (dx, dz) = (s, -c);
            let Some(mut u) = self.cast(dx, dz) else {
                continue;
            };
            if self.weed_p > 0.0 {
                if let Some(w) = self.weed(dx, dz, u, rng) {
                    u = w;
                    weeds += 1;
                }
            }
            let x = u * dx + self.noise_m * rng.normal();
            let z = u * dz + self.noise_m * rng.normal();
            if n < out.len() {
                out[n] = (x as f32, z as f32, b as u32);
                n += 1;
            }
        }
        (n, weeds)
    }

    /// The weed boxes: on the road side of each toe, `weed_w` wide and `weed_h` high. A beam
    /// crossing one before its hit returns from inside it with probability `weed_p`.
    fn weed(&self, dx: f64, dz: f64, hit: f64, rng: &mut Rng) -> Option<f64> {
        for (toe, dir) in [(self.left_toe_x, 1.0), (self.right_toe_x, -1.0)] {
            let zr = self.road_z(toe);
            let (x0, x1) = if dir > 0.0 {
                (toe - self.weed_w, toe)
            } else {
                (toe, toe + self.weed_w)
            };
            let (z0, z1) = (zr - 0.01, zr + self.weed_h);
            // Slab intersection of the ray with the box.
            let (mut lo, mut hi) = (0.0f64, hit);
            for (o0, o1, d) in [(x0, x1, dx), (z0, z1, dz)] {
                if d.abs() < 1e-15 {
                    continue;
                }
                let (a, b) = (o0 / d, o1 / d);
                let (a, b) = if a < b { (a, b) } else { (b, a) };
                lo = lo.max(a);
                hi = hi.min(b);
            }
            if lo < hi && rng.uniform() < self.weed_p {
                return Some(rng.range(lo, hi));
            }
        }
        None
    }
}
