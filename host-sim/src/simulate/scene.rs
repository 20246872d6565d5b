//! Scene descriptions and how they become geometry.
//!
//! A scene is laid out in *road coordinates* `(u, v)`: `u` metres along the road centre
//! line (a chain of straight and circular pieces), `v` metres to its left. Everything —
//! curb toes, corner arcs, bus bays, cars, walls, the vehicle's lane — is placed in `(u, v)`
//! and mapped to scene-local XY through the centre line, so curved roads bend everything
//! consistently. Scene-local XY is the CRS minus [`SceneSpec::origin`]; nothing is aligned
//! with the grid axes (each scene starts at its own compass heading).
//!
//! The seed varies the details (weeds, leaves, wall types, small jitter of cars and poles),
//! the scene name fixes the layout.

use super::ground::{Base, CurbShape, Ground, ToeLine};
use super::prims::{Material, Objects, Prim, Shape};
use super::scanner::ScannerConfig;
use crate::model::{Category, Side};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::PI;

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

/// A lowered curb (driveway or crossing).
#[derive(Clone, Copy, Debug)]
pub struct CurbCut {
    /// Side of the road.
    pub side: Side,
    /// Centre, metres along the road.
    pub u: f64,
    /// Length of the lowered part, metres.
    pub len: f64,
    /// Lowered curb height, metres (20–30 mm).
    pub h: f64,
}

/// A side street.
#[derive(Clone, Copy, Debug)]
pub struct Intersection {
    /// Side of the road.
    pub side: Side,
    /// Centre of the side street, metres along the road.
    pub u: f64,
    /// Width of the side street between its curbs, metres.
    pub width: f64,
    /// Corner radius, metres.
    pub radius: f64,
    /// How far the side street's curbs run, from the main road's curb line, metres.
    pub length: f64,
}

/// A bus bay: the curb swings out by `depth` over smooth tapers.
#[derive(Clone, Copy, Debug)]
pub struct BusBay {
    /// Side of the road.
    pub side: Side,
    /// Start of the entry taper, metres along the road.
    pub u0: f64,
    /// Entry taper, stop, exit taper lengths, metres.
    pub lens: [f64; 3],
    /// How far the curb moves out, metres.
    pub depth: f64,
}

/// Everything that defines a scene.
#[derive(Clone, Debug)]
pub struct SceneSpec {
    /// Name.
    pub name: String,
    /// EPSG code of the CRS.
    pub epsg: u32,
    /// CRS coordinates of scene-local (0, 0, 0).
    pub origin: [f64; 3],
    /// Compass heading of the road at its start, degrees.
    pub heading_deg: f64,
    /// Centre line pieces starting at `u_range.0`.
    pub pieces: Vec<Piece>,
    /// Extent of the built road, metres along the centre line.
    pub u_range: (f64, f64),
    /// Where the scanner runs: start and end, metres along the centre line.
    pub drive: (f64, f64),
    /// Default speed, km/h.
    pub speed_kmh: f64,
    /// Road half widths `(u, left, right)`, smooth (cosine) transitions between rows.
    pub half_width: Vec<(f64, f64, f64)>,
    /// Curb heights `(u, left, right)`, smooth (cosine) transitions between rows.
    pub curb_h: Vec<(f64, f64, f64)>,
    /// Distance of the vehicle's path from the left curb, metres (left-hand traffic).
    pub lane_from_left_m: f64,
    /// Sidewalk widths (left, right), metres.
    pub sidewalk_m: (f64, f64),
    /// Curb cuts.
    pub curb_cuts: Vec<CurbCut>,
    /// Side streets.
    pub intersections: Vec<Intersection>,
    /// Bus bays.
    pub bus_bays: Vec<BusBay>,
    /// Parked cars: side and centre `u`.
    pub parked_cars: Vec<(Side, f64)>,
    /// Stretches with weeds at the curb: side, from, to.
    pub weeds: Vec<(Side, f64, f64)>,
    /// Leaves per 100 m of curb.
    pub leaves_per_100m: f64,
    /// Pole spacing along each side, metres.
    pub pole_spacing_m: f64,
    /// Curb shape.
    pub shape: CurbShape,
    /// Terrain.
    pub base: Base,
    /// The scanner.
    pub scanner: ScannerConfig,
}

/// Names of the built-in scenes.
pub const SCENE_NAMES: [&str; 4] = ["kawasaki", "sapporo", "curvy", "tiny"];

fn interp(table: &[(f64, f64, f64)], u: f64, side: Side) -> f64 {
    let pick = |r: &(f64, f64, f64)| if side == Side::Left { r.1 } else { r.2 };
    let k = table.partition_point(|r| r.0 <= u);
    if k == 0 {
        return pick(&table[0]);
    }
    if k >= table.len() {
        return pick(&table[table.len() - 1]);
    }
    let (a, b) = (&table[k - 1], &table[k]);
    // Smooth (cosine) transitions: real tapers have no kinks, and the lane that follows
    // them must not make the vehicle jerk.
    let w = smooth01((u - a.0) / (b.0 - a.0));
    pick(a) + (pick(b) - pick(a)) * w
}

fn smooth01(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    0.5 - 0.5 * (PI * x).cos()
}

impl SceneSpec {
    /// A built-in scene by name.
    pub fn by_name(name: &str) -> Option<SceneSpec> {
        match name {
            "kawasaki" => Some(kawasaki()),
            "sapporo" => Some(sapporo()),
            "curvy" => Some(curvy()),
            "tiny" => Some(tiny()),
            _ => None,
        }
    }

    /// Half width of the road on `side` at `u` without bus bays.
    pub fn base_half_width(&self, side: Side, u: f64) -> f64 {
        interp(&self.half_width, u, side)
    }

    /// Extra width of bus bays at `u` on `side`.
    fn bay_depth(&self, side: Side, u: f64) -> f64 {
        let mut d: f64 = 0.0;
        for b in self.bus_bays.iter().filter(|b| b.side == side) {
            let [ti, l, to] = b.lens;
            let x = u - b.u0;
            let f = if x < 0.0 || x > ti + l + to {
                0.0
            } else if x < ti {
                smooth01(x / ti)
            } else if x <= ti + l {
                1.0
            } else {
                1.0 - smooth01((x - ti - l) / to)
            };
            d = d.max(b.depth * f);
        }
        d
    }

    /// Half width including bus bays.
    pub fn half_width_at(&self, side: Side, u: f64) -> f64 {
        self.base_half_width(side, u) + self.bay_depth(side, u)
    }

    /// (curb height, nominal height, category) at `u` on `side` along the main road.
    fn curb_at(&self, side: Side, u: f64) -> (f64, f64, Category) {
        let nominal = interp(&self.curb_h, u, side);
        let mut h = nominal;
        let mut cat = Category::Curb;
        for c in self.curb_cuts.iter().filter(|c| c.side == side) {
            // 1 m linear ramps either side of the lowered part.
            let x = (u - c.u).abs() - c.len / 2.0;
            let f = (1.0 - x).clamp(0.0, 1.0);
            if f > 0.0 {
                h = h.min(nominal - (nominal - c.h) * f);
                cat = Category::CurbCut;
            }
        }
        if self.bay_depth(side, u) > 1e-6 {
            cat = Category::BusBay;
        }
        (h, nominal, cat)
    }

    /// The toe lines in road coordinates `(u, e)` with `e` measured outward on `side`,
    /// in the direction of increasing `u`; each vertex with (h_curb, h_walk, category).
    fn toe_pieces(&self, side: Side) -> Vec<Vec<ToeVertex>> {
        const STEP: f64 = 0.25;
        let mut xs: Vec<Intersection> = self
            .intersections
            .iter()
            .filter(|i| i.side == side)
            .copied()
            .collect();
        xs.sort_by(|a, b| a.u.total_cmp(&b.u));
        let mut out = Vec::new();
        let mut cur: Vec<ToeVertex> = Vec::new();
        let straight = |cur: &mut Vec<_>, u0: f64, u1: f64| {
            let n = ((u1 - u0) / STEP).ceil().max(1.0) as usize;
            for i in 0..=n {
                let u = u0 + (u1 - u0) * i as f64 / n as f64;
                let (h, hw, cat) = self.curb_at(side, u);
                cur.push(([u, self.half_width_at(side, u)], h, hw, cat));
            }
        };
        let mut u = self.u_range.0;
        for x in &xs {
            let a = x.width / 2.0;
            let r = x.radius;
            let u_end = x.u - a - r;
            let w = self.half_width_at(side, u_end);
            let (_, hn, _) = self.curb_at(side, x.u);
            straight(&mut cur, u, u_end);
            // Corner 1: centre (u_end, w + r), from −90° to 0°; then up the side street.
            let n = ((r * PI / 2.0) / 0.1).ceil() as usize;
            for i in 1..=n {
                let ph = -PI / 2.0 + PI / 2.0 * i as f64 / n as f64;
                cur.push((
                    [u_end + r * ph.cos(), w + r + r * ph.sin()],
                    hn,
                    hn,
                    Category::Intersection,
                ));
            }
            let m = ((x.length - r) / STEP).ceil().max(1.0) as usize;
            for i in 1..=m {
                let e = w + r + (x.length - r) * i as f64 / m as f64;
                cur.push(([x.u - a, e], hn, hn, Category::Intersection));
            }
            out.push(std::mem::take(&mut cur));
            // The far side of the side street, coming back, corner 2 from 180° to 270°.
            let u2 = x.u + a + r;
            let w2 = self.half_width_at(side, u2);
            for i in 0..m {
                let e = w2 + x.length - (x.length - r) * i as f64 / m as f64;
                cur.push(([x.u + a, e], hn, hn, Category::Intersection));
            }
            for i in 0..n {
                let ph = PI + PI / 2.0 * i as f64 / n as f64;
                cur.push((
                    [u2 + r * ph.cos(), w2 + r + r * ph.sin()],
                    hn,
                    hn,
                    Category::Intersection,
                ));
            }
            u = u2;
        }
        straight(&mut cur, u, self.u_range.1);
        out.push(cur);
        out
    }
}

/// A toe vertex in road coordinates `(u, e)` with curb height, sidewalk height, category.
type ToeVertex = ([f64; 2], f64, f64, Category);

/// The built world: ground, objects, centre line and lane.
pub struct World {
    /// The scene's description.
    pub spec: SceneSpec,
    /// Road centre line.
    pub center: Centerline,
    /// Ground height field with the curb toes.
    pub ground: Ground,
    /// Objects.
    pub objects: Objects,
}

const CAR_LEN: f64 = 4.4;
const CAR_W: f64 = 1.7;
const CAR_GAP: f64 = 0.3;
/// Half width of the scanning vehicle plus the clearance a driver keeps, metres.
const PASS_CLEARANCE_M: f64 = 0.95 + 0.6;

impl World {
    /// Lateral position `v` of the vehicle's path at `u`: its lane, swerving out around
    /// parked cars on its own side with smooth 20 m transitions (a calm lane change).
    pub fn lane_v(&self, u: f64) -> f64 {
        let s = &self.spec;
        let lane = s.base_half_width(Side::Left, u) - s.lane_from_left_m;
        let mut v = lane;
        for &(side, uc) in &s.parked_cars {
            if side != Side::Left {
                continue;
            }
            let outer = s.base_half_width(Side::Left, uc) - CAR_GAP - CAR_W;
            let need = outer - PASS_CLEARANCE_M;
            if need >= lane {
                continue;
            }
            let x = (u - uc).abs() - CAR_LEN / 2.0 - 2.0;
            let f = if x <= 0.0 {
                1.0
            } else {
                1.0 - smooth01(x / 20.0)
            };
            v = v.min(lane + (need - lane) * f);
        }
        v
    }

    /// Builds a scene's world.
    pub fn build(spec: SceneSpec, seed: u64) -> World {
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5CE0_E5EE_D000_0001);
        let center = Centerline::new(spec.heading_deg, spec.u_range.0, spec.pieces.clone());
        // Toe lines, mapped to XY, stored with the sidewalk on their left.
        let mut toes = Vec::new();
        let crown_cap = spec
            .half_width
            .iter()
            .map(|r| r.1.max(r.2))
            .fold(0.0, f64::max);
        for side in [Side::Left, Side::Right] {
            let sgn = if side == Side::Left { 1.0 } else { -1.0 };
            for piece in spec.toe_pieces(side) {
                let mut t = ToeLine {
                    pts: Vec::new(),
                    h_curb: Vec::new(),
                    h_walk: Vec::new(),
                    category: Vec::new(),
                    crown_m: 0.0,
                };
                for (ue, hc, hw, cat) in piece {
                    t.pts.push(center.map(ue[0], sgn * ue[1]));
                    t.h_curb.push(hc);
                    t.h_walk.push(hw);
                    t.category.push(cat);
                }
                // One crown cap for the whole scene: the road surface, the minimum over
                // all toes of `cross_slope · min(distance, cap)`, stays continuous where
                // the nearest toe changes (intersection mouths); on a road narrower than
                // twice the cap the crown is simply its centre line.
                t.crown_m = crown_cap;
                if side == Side::Right {
                    t.pts.reverse();
                    t.h_curb.reverse();
                    t.h_walk.reverse();
                    t.category.reverse();
                }
                toes.push(t);
            }
        }
        let mut b = [
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
        ];
        for p in toes.iter().flat_map(|t| t.pts.iter()) {
            b = [
                b[0].min(p[0]),
                b[1].min(p[1]),
                b[2].max(p[0]),
                b[3].max(p[1]),
            ];
        }
        let margin = 12.0;
        let bounds = [b[0] - margin, b[1] - margin, b[2] + margin, b[3] + margin];
        let off_road = spec.curb_h.iter().map(|r| r.1.max(r.2)).fold(0.0, f64::max);
        let ground = Ground::build(toes, spec.shape, spec.base, bounds, off_road);
        let gz = |p: [f64; 2]| ground.height(p[0], p[1]).map(|h| h.0).unwrap_or(0.0);
        let mut prims: Vec<Prim> = Vec::new();

        let in_side_street = |side: Side, u: f64, pad: f64| {
            spec.intersections
                .iter()
                .any(|x| x.side == side && (u - x.u).abs() < x.width / 2.0 + pad)
        };
        // Walls along each side: building fronts, block walls, or open lots.
        for side in [Side::Left, Side::Right] {
            let sgn = if side == Side::Left { 1.0 } else { -1.0 };
            let sw = if side == Side::Left {
                spec.sidewalk_m.0
            } else {
                spec.sidewalk_m.1
            };
            let mut u = spec.u_range.0;
            while u < spec.u_range.1 {
                let block = rng.gen_range(8.0..22.0);
                let kind = rng.gen_range(0..10);
                let (height, thick, mat) = match kind {
                    0..=4 => (rng.gen_range(6.0..16.0), 0.3, Material::Wall),
                    5..=7 => (rng.gen_range(1.2..1.8), 0.15, Material::Wall),
                    8 => (1.2, 0.05, Material::Metal),
                    _ => (0.0, 0.0, Material::Wall),
                };
                let mut a = u;
                while a < u + block && a < spec.u_range.1 {
                    let e = (a + 2.0).min(u + block);
                    let mid = 0.5 * (a + e);
                    let blocked = spec.intersections.iter().any(|x| {
                        x.side == side
                            && mid > x.u - x.width / 2.0 - sw - 1.0
                            && mid < x.u + x.width / 2.0 + sw + 1.0
                    });
                    if height > 0.0 && !blocked {
                        let off = (spec.base_half_width(side, mid) + sw)
                            .max(spec.half_width_at(side, mid) + 1.5)
                            + thick / 2.0;
                        let p0 = center.map(a, sgn * off);
                        let p1 = center.map(e, sgn * off);
                        prims.push(wall_box(
                            p0,
                            p1,
                            thick,
                            gz(center.map(mid, sgn * off)) - 0.3,
                            height + 0.3,
                            mat,
                        ));
                    }
                    a = e;
                }
                u += block;
            }
            // Walls along the side streets.
            for x in spec.intersections.iter().filter(|x| x.side == side) {
                let w = spec.base_half_width(side, x.u);
                for du in [-(x.width / 2.0 + sw + 0.15), x.width / 2.0 + sw + 0.15] {
                    let mut e0 = w + sw;
                    while e0 < w + x.length {
                        let e1 = e0 + 2.0;
                        let p0 = center.map(x.u + du, sgn * e0);
                        let p1 = center.map(x.u + du, sgn * e1);
                        let mid = center.map(x.u + du, sgn * 0.5 * (e0 + e1));
                        prims.push(wall_box(p0, p1, 0.3, gz(mid) - 0.3, 8.3, Material::Wall));
                        e0 = e1;
                    }
                }
            }
            // Poles on the sidewalk near the curb, away from side streets and curb cuts.
            let mut u = spec.u_range.0 + rng.gen_range(0.0..spec.pole_spacing_m);
            while u < spec.u_range.1 {
                let near_cut = spec
                    .curb_cuts
                    .iter()
                    .any(|c| c.side == side && (u - c.u).abs() < c.len / 2.0 + 2.0);
                let near_car = spec
                    .parked_cars
                    .iter()
                    .any(|c| c.0 == side && (u - c.1).abs() < 3.0);
                if !in_side_street(side, u, 8.0) && !near_cut && !near_car {
                    let e = spec.half_width_at(side, u) + rng.gen_range(0.35..0.6);
                    let p = center.map(u, sgn * e);
                    let (r, h) = if rng.gen_bool(0.6) {
                        (0.17, 9.0)
                    } else {
                        (0.04, 2.8)
                    };
                    let z = gz(p);
                    prims.push(Prim {
                        shape: Shape::Cyl {
                            c: p,
                            r,
                            z: [z - 0.2, z + h],
                        },
                        material: Material::Metal,
                    });
                }
                u += spec.pole_spacing_m * rng.gen_range(0.7..1.3);
            }
        }

        // Parked cars at the curb.
        for &(side, uc) in &spec.parked_cars {
            let sgn = if side == Side::Left { 1.0 } else { -1.0 };
            let uc = uc + rng.gen_range(-0.5..0.5);
            let gap = CAR_GAP + rng.gen_range(-0.1..0.1);
            let e = spec.half_width_at(side, uc) - gap - CAR_W / 2.0;
            let c = center.map(uc, sgn * e);
            let (_, dir) = center.pose(uc);
            let cs = [dir.cos(), dir.sin()];
            let at = |du: f64, dv: f64| {
                [
                    c[0] + du * cs[0] - dv * cs[1],
                    c[1] + du * cs[1] + dv * cs[0],
                ]
            };
            let mut z = f64::INFINITY;
            for (du, dv) in [(1.35, 0.75), (1.35, -0.75), (-1.35, 0.75), (-1.35, -0.75)] {
                z = z.min(gz(at(du, dv)));
            }
            prims.push(Prim {
                shape: Shape::RoundBox {
                    c: [c[0], c[1], z + 0.2 + 0.38],
                    half: [CAR_LEN / 2.0, CAR_W / 2.0, 0.38],
                    cs,
                    r: 0.15,
                },
                material: Material::Car,
            });
            let cab = at(-0.3, 0.0);
            prims.push(Prim {
                shape: Shape::RoundBox {
                    c: [cab[0], cab[1], z + 0.95 + 0.26],
                    half: [1.2, 0.76, 0.28],
                    cs,
                    r: 0.2,
                },
                material: Material::Glass,
            });
            for (du, dv) in [(1.35, 0.72), (1.35, -0.72), (-1.35, 0.72), (-1.35, -0.72)] {
                let p = at(du, dv);
                prims.push(Prim {
                    shape: Shape::Box {
                        c: [p[0], p[1], z + 0.3],
                        half: [0.31, 0.1, 0.31],
                        cs,
                    },
                    material: Material::Tyre,
                });
            }
        }

        // Weeds: clumps of thin stems growing in the joint at the curb toe.
        for &(side, u0, u1) in &spec.weeds {
            let sgn = if side == Side::Left { 1.0 } else { -1.0 };
            let mut u = u0;
            while u < u1 {
                u += rng.gen_range(1.0..6.0);
                if in_side_street(side, u, 6.0) {
                    continue;
                }
                let e = spec.half_width_at(side, u) + rng.gen_range(-0.12..0.04);
                let stems = rng.gen_range(15..60);
                let spread = rng.gen_range(0.05..0.3);
                let tall = rng.gen_range(0.08..0.45);
                for _ in 0..stems {
                    let p = center.map(
                        u + rng.gen_range(-spread..spread),
                        sgn * (e + rng.gen_range(-0.06..0.06)),
                    );
                    let z = gz(p);
                    prims.push(Prim {
                        shape: Shape::Cyl {
                            c: p,
                            r: rng.gen_range(0.003..0.008),
                            z: [z - 0.02, z + tall * rng.gen_range(0.3..1.0)],
                        },
                        material: Material::Vegetation,
                    });
                }
            }
        }

        // Leaves in the gutter and a few on the sidewalk.
        for side in [Side::Left, Side::Right] {
            let sgn = if side == Side::Left { 1.0 } else { -1.0 };
            let len = spec.u_range.1 - spec.u_range.0;
            let n = (spec.leaves_per_100m * len / 100.0) as usize;
            for _ in 0..n {
                let u = rng.gen_range(spec.u_range.0..spec.u_range.1);
                if in_side_street(side, u, 6.0) {
                    continue;
                }
                let e = spec.half_width_at(side, u)
                    + if rng.gen_bool(0.8) {
                        -rng.gen_range(0.02..0.6)
                    } else {
                        rng.gen_range(0.1..1.5)
                    };
                let p = center.map(u, sgn * e);
                let z = gz(p) + rng.gen_range(0.003..0.012);
                prims.push(Prim {
                    shape: Shape::Disc {
                        c: [p[0], p[1], z],
                        r: rng.gen_range(0.02..0.05),
                    },
                    material: Material::Leaf,
                });
            }
        }

        let ob = ground.bounds();
        let objects = Objects::build(
            prims,
            [ob[0] - 5.0, ob[1] - 5.0, ob[2] + 5.0, ob[3] + 5.0],
            1.0,
        );
        World {
            spec,
            center,
            ground,
            objects,
        }
    }
}

fn wall_box(p0: [f64; 2], p1: [f64; 2], thick: f64, z0: f64, h: f64, mat: Material) -> Prim {
    let dx = p1[0] - p0[0];
    let dy = p1[1] - p0[1];
    let len = (dx * dx + dy * dy).sqrt().max(1e-6);
    Prim {
        shape: Shape::Box {
            c: [0.5 * (p0[0] + p1[0]), 0.5 * (p0[1] + p1[1]), z0 + h / 2.0],
            // A little overlap so consecutive pieces on a bend leave no slits.
            half: [len / 2.0 + 0.02, thick / 2.0, h / 2.0],
            cs: [dx / len, dy / len],
        },
        material: mat,
    }
}

fn common(name: &str) -> SceneSpec {
    SceneSpec {
        name: name.into(),
        epsg: 6691,
        origin: [0.0; 3],
        heading_deg: 0.0,
        pieces: Vec::new(),
        u_range: (-40.0, 0.0),
        drive: (0.0, 0.0),
        speed_kmh: 30.0,
        half_width: vec![(0.0, 5.0, 5.0)],
        curb_h: vec![(0.0, 0.2, 0.2)],
        lane_from_left_m: 2.5,
        sidewalk_m: (3.0, 3.0),
        curb_cuts: Vec::new(),
        intersections: Vec::new(),
        bus_bays: Vec::new(),
        parked_cars: Vec::new(),
        weeds: Vec::new(),
        leaves_per_100m: 60.0,
        pole_spacing_m: 30.0,
        shape: CurbShape::default(),
        base: Base {
            grade_x: 0.004,
            grade_y: -0.006,
            wave_m: 0.3,
        },
        scanner: ScannerConfig::default(),
    }
}

fn cut(side: Side, u: f64, len: f64) -> CurbCut {
    CurbCut {
        side,
        u,
        len,
        h: 0.025,
    }
}

/// Kawasaki-like: 2 lanes, 10 m wide, 200 mm curbs, curb cuts, 2 intersections, parked
/// cars, weeds, a bus bay (Honma et al. §3.1).
fn kawasaki() -> SceneSpec {
    use Side::{Left as L, Right as R};
    SceneSpec {
        origin: [382417.25, 3930168.5, 12.0],
        heading_deg: 62.0,
        pieces: vec![
            Piece::Straight(190.0),
            Piece::Arc(400.0, 8.0),
            Piece::Straight(250.0),
        ],
        u_range: (-40.0, 390.0),
        drive: (0.0, 350.0),
        speed_kmh: 30.0,
        half_width: vec![(0.0, 5.0, 5.0)],
        curb_h: vec![(0.0, 0.2, 0.2)],
        lane_from_left_m: 2.6,
        sidewalk_m: (3.0, 2.5),
        curb_cuts: vec![
            cut(L, 28.0, 4.0),
            cut(L, 52.0, 5.5),
            cut(L, 148.0, 3.5),
            cut(L, 178.0, 6.0),
            cut(L, 282.0, 4.0),
            cut(L, 318.0, 5.0),
            cut(R, 38.0, 4.5),
            cut(R, 140.0, 5.0),
            cut(R, 300.0, 4.0),
            CurbCut {
                side: R,
                u: 338.0,
                len: 3.0,
                h: 0.03,
            },
        ],
        intersections: vec![
            Intersection {
                side: L,
                u: 95.0,
                width: 8.0,
                radius: 6.0,
                length: 25.0,
            },
            Intersection {
                side: R,
                u: 255.0,
                width: 7.0,
                radius: 5.0,
                length: 25.0,
            },
        ],
        bus_bays: vec![BusBay {
            side: L,
            u0: 200.0,
            lens: [12.0, 16.0, 10.0],
            depth: 2.8,
        }],
        parked_cars: vec![
            (L, 68.0),
            (L, 122.0),
            (L, 128.5),
            (L, 258.0),
            (R, 110.0),
            (R, 185.0),
            (R, 322.0),
        ],
        weeds: vec![
            (L, 10.0, 80.0),
            (L, 155.0, 195.0),
            (R, 90.0, 220.0),
            (R, 280.0, 350.0),
        ],
        leaves_per_100m: 80.0,
        pole_spacing_m: 30.0,
        ..common("kawasaki")
    }
}

/// Sapporo-like: 7.5 m wide with 80 mm curbs, then 11.5 m with 170 mm curbs; the far
/// (right) side is sparse.
fn sapporo() -> SceneSpec {
    use Side::{Left as L, Right as R};
    SceneSpec {
        origin: [528350.0, 4767120.0, 20.0],
        heading_deg: 15.0,
        pieces: vec![
            Piece::Straight(200.0),
            Piece::Arc(300.0, -6.0),
            Piece::Straight(200.0),
        ],
        u_range: (-40.0, 370.0),
        drive: (0.0, 330.0),
        speed_kmh: 35.0,
        half_width: vec![(0.0, 3.75, 3.75), (215.0, 3.75, 3.75), (245.0, 5.75, 5.75)],
        curb_h: vec![(0.0, 0.08, 0.08), (215.0, 0.08, 0.08), (245.0, 0.17, 0.17)],
        lane_from_left_m: 1.9,
        sidewalk_m: (2.5, 2.5),
        curb_cuts: vec![
            cut(L, 35.0, 4.0),
            cut(L, 70.0, 5.0),
            cut(L, 160.0, 4.0),
            cut(L, 190.0, 3.5),
            cut(L, 265.0, 5.0),
            cut(L, 300.0, 4.0),
            cut(R, 50.0, 4.0),
            cut(R, 180.0, 5.0),
            cut(R, 310.0, 4.0),
        ],
        intersections: vec![
            Intersection {
                side: L,
                u: 120.0,
                width: 7.0,
                radius: 5.0,
                length: 25.0,
            },
            Intersection {
                side: R,
                u: 275.0,
                width: 8.0,
                radius: 8.0,
                length: 25.0,
            },
        ],
        bus_bays: Vec::new(),
        parked_cars: vec![(L, 245.0), (R, 95.0)],
        weeds: vec![(L, 20.0, 100.0), (R, 140.0, 240.0)],
        leaves_per_100m: 40.0,
        pole_spacing_m: 35.0,
        ..common("sapporo")
    }
}

/// A 60 m radius bend with 150 mm curbs.
fn curvy() -> SceneSpec {
    use Side::{Left as L, Right as R};
    SceneSpec {
        origin: [401234.0, 3940500.0, 35.0],
        heading_deg: 200.0,
        pieces: vec![
            Piece::Straight(80.0),
            Piece::Arc(60.0, 90.0),
            Piece::Straight(80.0),
        ],
        u_range: (-40.0, 230.0),
        drive: (0.0, 195.0),
        speed_kmh: 25.0,
        half_width: vec![(0.0, 4.5, 4.5)],
        curb_h: vec![(0.0, 0.15, 0.15)],
        lane_from_left_m: 2.3,
        sidewalk_m: (2.5, 3.0),
        curb_cuts: vec![
            cut(L, 25.0, 4.0),
            cut(L, 95.0, 4.0),
            cut(R, 120.0, 5.0),
            cut(L, 170.0, 4.0),
        ],
        parked_cars: vec![(R, 60.0), (L, 150.0)],
        weeds: vec![(L, 60.0, 140.0)],
        ..common("curvy")
    }
}

/// 30 m straight for tests: 8 m wide, 150 mm curbs, one curb cut, a pole, leaves, weeds.
fn tiny() -> SceneSpec {
    use Side::Left as L;
    SceneSpec {
        origin: [455120.5, 3951870.25, 8.0],
        heading_deg: 100.0,
        pieces: vec![Piece::Straight(100.0)],
        u_range: (-25.0, 55.0),
        drive: (0.0, 30.0),
        speed_kmh: 30.0,
        half_width: vec![(0.0, 4.0, 4.0)],
        curb_h: vec![(0.0, 0.15, 0.15)],
        lane_from_left_m: 2.3,
        sidewalk_m: (2.5, 2.5),
        curb_cuts: vec![cut(L, 16.0, 4.0)],
        weeds: vec![(L, 0.0, 12.0)],
        leaves_per_100m: 60.0,
        pole_spacing_m: 25.0,
        ..common("tiny")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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

    #[test]
    fn corner_arcs_have_the_given_radius_and_categories() {
        let mut s = tiny();
        s.intersections.push(Intersection {
            side: Side::Right,
            u: 20.0,
            width: 8.0,
            radius: 6.0,
            length: 20.0,
        });
        let pieces = s.toe_pieces(Side::Right);
        assert_eq!(pieces.len(), 2);
        // Corner 1 centre: (20 - 4 - 6, 4 + 6) in (u, e).
        let arc: Vec<_> = pieces[0]
            .iter()
            .filter(|p| p.3 == Category::Intersection && p.0[0] < 16.0 - 1e-9)
            .collect();
        assert!(arc.len() > 10);
        for p in arc {
            let r = ((p.0[0] - 10.0).powi(2) + (p.0[1] - 10.0).powi(2)).sqrt();
            assert!((r - 6.0).abs() < 1e-9, "{r}");
        }
        // The last vertex of the first piece is at the side street's end.
        let last = pieces[0].last().unwrap();
        assert!((last.0[0] - 16.0).abs() < 1e-9 && (last.0[1] - 24.0).abs() < 1e-9);
    }

    #[test]
    fn weeds_stand_at_the_curb_toe_and_stop_rays() {
        let w = World::build(tiny(), 1);
        let stems: Vec<_> = w
            .objects
            .prims
            .iter()
            .filter(|p| p.material == Material::Vegetation)
            .collect();
        assert!(stems.len() > 20, "{}", stems.len());
        let Shape::Cyl { c, r, z } = stems[0].shape else {
            panic!("weeds are cylinders")
        };
        // Near the left toe: |s| < 0.25 m.
        let (_, toe) = w.ground.height(c[0], c[1]).unwrap();
        assert!(toe.unwrap().s.abs() < 0.25);
        // A level ray at mid-height 1 m away hits the stem (or a stem in front of it).
        let o = [c[0] - 1.0, c[1], 0.5 * (z[0] + z[1])];
        let h = w.objects.intersect(o, [1.0, 0.0, 0.0], 0.0, 2.0).unwrap();
        assert!(h.t <= 1.0 - r + 1e-9 && h.material == Material::Vegetation);
    }

    #[test]
    fn the_vehicle_swerves_around_a_parked_car_on_its_side() {
        let mut s = tiny();
        s.parked_cars.push((Side::Left, 15.0));
        let w = World::build(s, 1);
        let lane = 4.0 - 2.3;
        assert!((w.lane_v(-10.0) - lane).abs() < 1e-12);
        let at_car = w.lane_v(15.0);
        // Car's outer side at 4 - 0.3 - 1.7 = 2.0 m; with clearance the path is at ≤ 0.45 m.
        assert!(at_car <= 2.0 - PASS_CLEARANCE_M + 1e-9, "{at_car}");
    }
}
