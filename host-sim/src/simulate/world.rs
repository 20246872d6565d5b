//! The built world: the ground height field with its curb toes, and the objects standing
//! on it (walls, poles, parked cars, weeds, leaves), all placed in road coordinates and
//! mapped through the centre line. The seed varies the details (weeds, leaves, wall types,
//! small jitter of cars and poles); the scene description fixes the layout.

use super::centerline::Centerline;
use super::ground::{Ground, ToeLine};
use super::prims::{Material, Objects, Prim, Shape};
use super::scene::{smooth01, ParkedKind, SceneSpec};
use crate::model::Side;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

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
        let lane = s.base_half_width(Side::Left, u) - self.lane_from_left(u);
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
        if s.parked.is_empty() {
            return v;
        }
        // Vehicles on either side push the path away from them; between two it takes the
        // middle; it never comes nearer than 1.2 m to a curb.
        let mut lo = f64::NEG_INFINITY;
        for p in &s.parked {
            let (len, wid) = p.kind.size();
            let x = (u - p.u).abs() - len / 2.0 - 2.0;
            let f = if x <= 0.0 {
                1.0
            } else {
                1.0 - smooth01(x / 20.0)
            };
            if f <= 0.0 {
                continue;
            }
            match p.side {
                Side::Left => {
                    let need =
                        s.base_half_width(Side::Left, p.u) - p.gap_m - wid - PASS_CLEARANCE_M;
                    if need < lane {
                        v = v.min(lane + (need - lane) * f);
                    }
                }
                Side::Right => {
                    let need =
                        -(s.base_half_width(Side::Right, p.u) - p.gap_m - wid) + PASS_CLEARANCE_M;
                    if need > lane {
                        lo = lo.max(lane + (need - lane) * f);
                    }
                }
            }
        }
        let v = if lo > v { 0.5 * (lo + v) } else { v };
        let (l, r) = (
            s.base_half_width(Side::Left, u) - 1.2,
            -(s.base_half_width(Side::Right, u) - 1.2),
        );
        v.clamp(r.min(l), l)
    }

    /// The lane's distance from the left curb at `u`, with the scene's lane changes.
    fn lane_from_left(&self, u: f64) -> f64 {
        let s = &self.spec;
        let mut l = s.lane_from_left_m;
        for &(uc, to) in &s.lane_changes {
            l += (to - l) * smooth01((u - uc) / 25.0);
        }
        l
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
            spec.intersections.iter().any(|x| {
                x.side == side
                    && if x.angle_deg == 90.0 && x.flare == 1.0 {
                        (u - x.u).abs() < x.width / 2.0 + pad
                    } else {
                        let (a, b) = spec.mouth(x);
                        u > a - pad && u < b + pad
                    }
            })
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
                            && if x.angle_deg == 90.0 && x.flare == 1.0 {
                                mid > x.u - x.width / 2.0 - sw - 1.0
                                    && mid < x.u + x.width / 2.0 + sw + 1.0
                            } else {
                                let (a, b) = spec.mouth(x);
                                mid > a - sw - 1.0 && mid < b + sw + 1.0
                            }
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
                if x.angle_deg != 90.0 || x.flare != 1.0 {
                    let (sn, cs) = x.angle_deg.to_radians().sin_cos();
                    for k in [-(x.width / 2.0 + sw + 0.15), x.width / 2.0 + sw + 0.15] {
                        let base = [x.u + k * sn, w - k * cs];
                        let at = |t: f64| center.map(base[0] + cs * t, sgn * (base[1] + sn * t));
                        // Behind the corners: on an acute corner the line through the
                        // main sidewalk's back edge would cross the corner arc.
                        let e0 = w + sw + spec.corner_reach(x) * sn;
                        let mut t0 = (e0 - base[1]) / sn;
                        let t_end = (w + x.length - base[1]) / sn;
                        while t0 < t_end {
                            let t1 = t0 + 2.0;
                            let mid = at(0.5 * (t0 + t1));
                            prims.push(wall_box(
                                at(t0),
                                at(t1),
                                0.3,
                                gz(mid) - 0.3,
                                8.3,
                                Material::Wall,
                            ));
                            t0 = t1;
                        }
                    }
                    continue;
                }
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

        // Parked cars at the curb, then the exactly placed cars and vans.
        for &(side, uc) in &spec.parked_cars {
            let uc = uc + rng.gen_range(-0.5..0.5);
            let gap = CAR_GAP + rng.gen_range(-0.1..0.1);
            parked_prims(
                &spec,
                &center,
                &gz,
                side,
                uc,
                gap,
                ParkedKind::Car,
                &mut prims,
            );
        }
        for p in &spec.parked {
            parked_prims(
                &spec, &center, &gz, p.side, p.u, p.gap_m, p.kind, &mut prims,
            );
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

/// The primitives of a parked vehicle on `side` centred at `uc`, `gap` from the curb.
#[allow(clippy::too_many_arguments)]
fn parked_prims(
    spec: &SceneSpec,
    center: &Centerline,
    gz: &dyn Fn([f64; 2]) -> f64,
    side: Side,
    uc: f64,
    gap: f64,
    kind: ParkedKind,
    prims: &mut Vec<Prim>,
) {
    let sgn = if side == Side::Left { 1.0 } else { -1.0 };
    let (len, w) = kind.size();
    let e = spec.half_width_at(side, uc) - gap - w / 2.0;
    let c = center.map(uc, sgn * e);
    let (_, dir) = center.pose(uc);
    let cs = [dir.cos(), dir.sin()];
    let at = |du: f64, dv: f64| {
        [
            c[0] + du * cs[0] - dv * cs[1],
            c[1] + du * cs[1] + dv * cs[0],
        ]
    };
    if kind == ParkedKind::Van {
        let mut z = f64::INFINITY;
        for (du, dv) in [(1.9, 0.9), (1.9, -0.9), (-1.9, 0.9), (-1.9, -0.9)] {
            z = z.min(gz(at(du, dv)));
        }
        prims.push(Prim {
            shape: Shape::RoundBox {
                c: [c[0], c[1], z + 0.22 + 0.98],
                half: [len / 2.0, w / 2.0, 0.98],
                cs,
                r: 0.12,
            },
            material: Material::Car,
        });
        for (du, dv) in [(1.9, 0.92), (1.9, -0.92), (-1.9, 0.92), (-1.9, -0.92)] {
            let p = at(du, dv);
            prims.push(Prim {
                shape: Shape::Box {
                    c: [p[0], p[1], z + 0.33],
                    half: [0.34, 0.11, 0.33],
                    cs,
                },
                material: Material::Tyre,
            });
        }
        return;
    }
    let mut z = f64::INFINITY;
    for (du, dv) in [(1.35, 0.75), (1.35, -0.75), (-1.35, 0.75), (-1.35, -0.75)] {
        z = z.min(gz(at(du, dv)));
    }
    prims.push(Prim {
        shape: Shape::RoundBox {
            c: [c[0], c[1], z + 0.2 + 0.38],
            half: [len / 2.0, w / 2.0, 0.38],
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

#[cfg(test)]
mod tests {
    use super::*;

    fn tiny() -> SceneSpec {
        crate::simulate::scene_by_name("tiny").unwrap()
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
    fn walls_along_an_acute_side_street_stand_behind_its_corner_arcs() {
        let mut s = tiny();
        s.intersections = vec![crate::simulate::scene::Intersection {
            side: Side::Left,
            u: 20.0,
            width: 8.0,
            radius: 10.0,
            length: 30.0,
            angle_deg: 60.0,
            flare: 1.0,
        }];
        let w = World::build(s, 1);
        let toe_pts: Vec<[f64; 2]> = w.ground.toes.iter().flat_map(|t| t.pts.clone()).collect();
        let mut walls = 0;
        for p in &w.objects.prims {
            if let (Shape::Box { c, .. }, Material::Wall) = (&p.shape, p.material) {
                walls += 1;
                let near = toe_pts
                    .iter()
                    .map(|q| (q[0] - c[0]).hypot(q[1] - c[1]))
                    .fold(f64::INFINITY, f64::min);
                assert!(
                    near > 1.0,
                    "a wall piece at {c:?} stands {near:.2} m from a toe"
                );
            }
        }
        assert!(walls > 0);
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
