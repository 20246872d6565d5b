//! Objects standing on the ground: walls and fences (boxes), parked cars (rounded boxes and
//! wheels), poles and weed stems (vertical cylinders), leaves (flat discs). A uniform 2D grid
//! over the scene lists the objects touching each cell; a ray walks the grid cells its plan
//! projection crosses (Amanatides & Woo) and stops once a hit is nearer than the next cell.

/// What an object is made of: sets the reflectance for intensity.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Material {
    /// Asphalt road.
    Asphalt,
    /// Concrete curbs and sidewalks.
    Concrete,
    /// Building walls and block walls.
    Wall,
    /// Metal fences and poles.
    Metal,
    /// Car paint.
    Car,
    /// Car glass (weak return).
    Glass,
    /// Rubber tyres.
    Tyre,
    /// Weeds and grass.
    Vegetation,
    /// Dry leaves.
    Leaf,
}

impl Material {
    /// Diffuse reflectance, 0..1.
    pub fn reflectance(self) -> f64 {
        match self {
            Material::Asphalt => 0.12,
            Material::Concrete => 0.35,
            Material::Wall => 0.4,
            Material::Metal => 0.5,
            Material::Car => 0.55,
            Material::Glass => 0.08,
            Material::Tyre => 0.05,
            Material::Vegetation => 0.45,
            Material::Leaf => 0.3,
        }
    }
}

/// A shape in scene-local coordinates.
#[derive(Clone, Copy, Debug)]
pub enum Shape {
    /// Box, vertical sides, turned by yaw about Z: centre, half extents (along, across, up),
    /// (cos, sin) of the yaw.
    Box {
        /// Centre.
        c: [f64; 3],
        /// Half extents in the box frame.
        half: [f64; 3],
        /// cos and sin of the yaw (box X axis in world XY).
        cs: [f64; 2],
    },
    /// Like [`Shape::Box`] with all edges rounded by radius `r` (inside `half`).
    RoundBox {
        /// Centre.
        c: [f64; 3],
        /// Half extents in the box frame (outer).
        half: [f64; 3],
        /// cos and sin of the yaw.
        cs: [f64; 2],
        /// Rounding radius.
        r: f64,
    },
    /// Vertical cylinder.
    Cyl {
        /// Axis position.
        c: [f64; 2],
        /// Radius.
        r: f64,
        /// Bottom and top.
        z: [f64; 2],
    },
    /// Horizontal disc.
    Disc {
        /// Centre.
        c: [f64; 3],
        /// Radius.
        r: f64,
    },
}

/// An object: shape and material.
#[derive(Clone, Copy, Debug)]
pub struct Prim {
    /// Geometry.
    pub shape: Shape,
    /// Material.
    pub material: Material,
}

/// A hit: range, unit normal, material.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    /// Range along the ray.
    pub t: f64,
    /// Unit normal at the hit.
    pub n: [f64; 3],
    /// Material.
    pub material: Material,
}

fn to_local(cs: [f64; 2], c: [f64; 3], p: [f64; 3]) -> [f64; 3] {
    let (x, y) = (p[0] - c[0], p[1] - c[1]);
    [cs[0] * x + cs[1] * y, -cs[1] * x + cs[0] * y, p[2] - c[2]]
}

fn dir_local(cs: [f64; 2], d: [f64; 3]) -> [f64; 3] {
    [
        cs[0] * d[0] + cs[1] * d[1],
        -cs[1] * d[0] + cs[0] * d[1],
        d[2],
    ]
}

fn dir_world(cs: [f64; 2], d: [f64; 3]) -> [f64; 3] {
    [
        cs[0] * d[0] - cs[1] * d[1],
        cs[1] * d[0] + cs[0] * d[1],
        d[2],
    ]
}

/// Slab test: entry and exit `t` and the entry axis.
fn slab(o: [f64; 3], d: [f64; 3], half: [f64; 3]) -> Option<(f64, f64, usize)> {
    let mut t0 = f64::NEG_INFINITY;
    let mut t1 = f64::INFINITY;
    let mut axis = 0;
    for k in 0..3 {
        if d[k].abs() < 1e-15 {
            if o[k].abs() > half[k] {
                return None;
            }
            continue;
        }
        let inv = 1.0 / d[k];
        let mut a = (-half[k] - o[k]) * inv;
        let mut b = (half[k] - o[k]) * inv;
        if a > b {
            std::mem::swap(&mut a, &mut b);
        }
        if a > t0 {
            t0 = a;
            axis = k;
        }
        t1 = t1.min(b);
    }
    (t0 <= t1).then_some((t0, t1, axis))
}

fn round_box_sdf(p: [f64; 3], inner: [f64; 3], r: f64) -> f64 {
    let q = [
        p[0].abs() - inner[0],
        p[1].abs() - inner[1],
        p[2].abs() - inner[2],
    ];
    let out = (q[0].max(0.0).powi(2) + q[1].max(0.0).powi(2) + q[2].max(0.0).powi(2)).sqrt();
    out + q[0].max(q[1]).max(q[2]).min(0.0) - r
}

impl Shape {
    /// Plan bounding box `[xmin, ymin, xmax, ymax]`.
    pub fn plan_bounds(&self) -> [f64; 4] {
        match *self {
            Shape::Box { c, half, cs } | Shape::RoundBox { c, half, cs, .. } => {
                let ex = half[0] * cs[0].abs() + half[1] * cs[1].abs();
                let ey = half[0] * cs[1].abs() + half[1] * cs[0].abs();
                [c[0] - ex, c[1] - ey, c[0] + ex, c[1] + ey]
            }
            Shape::Cyl { c, r, .. } => [c[0] - r, c[1] - r, c[0] + r, c[1] + r],
            Shape::Disc { c, r } => [c[0] - r, c[1] - r, c[0] + r, c[1] + r],
        }
    }

    /// Nearest intersection with `t ∈ (tmin, tmax)`: `(t, normal)`.
    pub fn intersect(
        &self,
        o: [f64; 3],
        d: [f64; 3],
        tmin: f64,
        tmax: f64,
    ) -> Option<(f64, [f64; 3])> {
        match *self {
            Shape::Box { c, half, cs } => {
                let lo = to_local(cs, c, o);
                let ld = dir_local(cs, d);
                let (t0, _t1, axis) = slab(lo, ld, half)?;
                if t0 <= tmin || t0 >= tmax {
                    return None;
                }
                let mut n = [0.0; 3];
                n[axis] = -ld[axis].signum();
                Some((t0, dir_world(cs, n)))
            }
            Shape::RoundBox { c, half, cs, r } => {
                let lo = to_local(cs, c, o);
                let ld = dir_local(cs, d);
                let (t0, t1, _) = slab(lo, ld, half)?;
                let inner = [half[0] - r, half[1] - r, half[2] - r];
                let mut t = t0.max(tmin);
                let end = t1.min(tmax);
                // Sphere tracing inside the bounding box: the SDF is exact, so steps are safe.
                for _ in 0..64 {
                    if t > end {
                        return None;
                    }
                    let p = [lo[0] + ld[0] * t, lo[1] + ld[1] * t, lo[2] + ld[2] * t];
                    let dist = round_box_sdf(p, inner, r);
                    if dist < 1e-5 {
                        if t <= tmin {
                            return None;
                        }
                        let e = 1e-4;
                        let g = |k: usize| {
                            let mut a = p;
                            let mut b = p;
                            a[k] += e;
                            b[k] -= e;
                            round_box_sdf(a, inner, r) - round_box_sdf(b, inner, r)
                        };
                        let n = [g(0), g(1), g(2)];
                        let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt().max(1e-12);
                        return Some((t, dir_world(cs, [n[0] / l, n[1] / l, n[2] / l])));
                    }
                    t += dist;
                }
                None
            }
            Shape::Cyl { c, r, z } => {
                let (ox, oy) = (o[0] - c[0], o[1] - c[1]);
                let a = d[0] * d[0] + d[1] * d[1];
                if a < 1e-15 {
                    return None;
                }
                let b = ox * d[0] + oy * d[1];
                let cc = ox * ox + oy * oy - r * r;
                let disc = b * b - a * cc;
                if disc < 0.0 {
                    return None;
                }
                let t = (-b - disc.sqrt()) / a;
                if t <= tmin || t >= tmax {
                    return None;
                }
                let zz = o[2] + d[2] * t;
                if zz < z[0] || zz > z[1] {
                    return None;
                }
                let nx = (ox + d[0] * t) / r;
                let ny = (oy + d[1] * t) / r;
                Some((t, [nx, ny, 0.0]))
            }
            Shape::Disc { c, r } => {
                if d[2].abs() < 1e-12 {
                    return None;
                }
                let t = (c[2] - o[2]) / d[2];
                if t <= tmin || t >= tmax {
                    return None;
                }
                let x = o[0] + d[0] * t - c[0];
                let y = o[1] + d[1] * t - c[1];
                (x * x + y * y <= r * r).then_some((t, [0.0, 0.0, 1.0]))
            }
        }
    }
}

/// All objects of a scene with a plan grid for ray walking.
pub struct Objects {
    /// The objects.
    pub prims: Vec<Prim>,
    x0: f64,
    y0: f64,
    cell: f64,
    nx: usize,
    ny: usize,
    ranges: Vec<(u32, u32)>,
    ids: Vec<u32>,
    /// Highest point of any object: rays climbing above it can stop.
    z_top: f64,
}

impl Objects {
    /// Builds the grid over `bounds` (objects outside are clipped to it).
    pub fn build(prims: Vec<Prim>, bounds: [f64; 4], cell: f64) -> Objects {
        let nx = ((bounds[2] - bounds[0]) / cell).ceil().max(1.0) as usize;
        let ny = ((bounds[3] - bounds[1]) / cell).ceil().max(1.0) as usize;
        let mut lists: Vec<Vec<u32>> = vec![Vec::new(); nx * ny];
        for (i, p) in prims.iter().enumerate() {
            let b = p.shape.plan_bounds();
            let cx = |x: f64| ((x - bounds[0]) / cell).floor().clamp(0.0, (nx - 1) as f64) as usize;
            let cy = |y: f64| ((y - bounds[1]) / cell).floor().clamp(0.0, (ny - 1) as f64) as usize;
            if b[2] < bounds[0] || b[0] > bounds[2] || b[3] < bounds[1] || b[1] > bounds[3] {
                continue;
            }
            for y in cy(b[1])..=cy(b[3]) {
                for x in cx(b[0])..=cx(b[2]) {
                    lists[y * nx + x].push(i as u32);
                }
            }
        }
        let z_top = prims
            .iter()
            .map(|p| match p.shape {
                Shape::Box { c, half, .. } | Shape::RoundBox { c, half, .. } => c[2] + half[2],
                Shape::Cyl { z, .. } => z[1],
                Shape::Disc { c, .. } => c[2],
            })
            .fold(f64::NEG_INFINITY, f64::max);
        let mut ranges = Vec::with_capacity(lists.len());
        let mut ids = Vec::new();
        for l in lists {
            let s = ids.len() as u32;
            ids.extend(l);
            ranges.push((s, ids.len() as u32));
        }
        Objects {
            prims,
            x0: bounds[0],
            y0: bounds[1],
            cell,
            nx,
            ny,
            ranges,
            ids,
            z_top,
        }
    }

    /// Nearest hit of the ray `o + t·d` with `t ∈ (tmin, tmax)`.
    pub fn intersect(&self, o: [f64; 3], d: [f64; 3], tmin: f64, tmax: f64) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        // A climbing ray above every object's top can hit nothing more.
        let tmax = if d[2] > 1e-12 {
            tmax.min((self.z_top - o[2]) / d[2])
        } else if o[2] > self.z_top {
            return None;
        } else {
            tmax
        };
        if tmax <= tmin {
            return None;
        }
        let mut tbest = tmax;
        let test_cell = |ci: usize, tb: &mut f64, best: &mut Option<Hit>| {
            let (s, e) = self.ranges[ci];
            for &id in &self.ids[s as usize..e as usize] {
                let p = &self.prims[id as usize];
                if let Some((t, n)) = p.shape.intersect(o, d, tmin, *tb) {
                    *tb = t;
                    *best = Some(Hit {
                        t,
                        n,
                        material: p.material,
                    });
                }
            }
        };
        // Clip the plan ray to the grid rectangle.
        let (x1, y1) = (
            self.x0 + self.nx as f64 * self.cell,
            self.y0 + self.ny as f64 * self.cell,
        );
        let mut ta = tmin.max(0.0);
        let mut tb_clip = tmax;
        for (oo, dd, lo, hi) in [(o[0], d[0], self.x0, x1), (o[1], d[1], self.y0, y1)] {
            if dd.abs() < 1e-15 {
                if oo < lo || oo >= hi {
                    return None;
                }
            } else {
                let a = (lo - oo) / dd;
                let b = (hi - oo) / dd;
                ta = ta.max(a.min(b));
                tb_clip = tb_clip.min(a.max(b));
            }
        }
        if ta > tb_clip {
            return None;
        }
        let px = o[0] + d[0] * ta;
        let py = o[1] + d[1] * ta;
        let mut ix = (((px - self.x0) / self.cell).floor().max(0.0) as usize).min(self.nx - 1);
        let mut iy = (((py - self.y0) / self.cell).floor().max(0.0) as usize).min(self.ny - 1);
        let step_x: i64 = if d[0] > 0.0 { 1 } else { -1 };
        let step_y: i64 = if d[1] > 0.0 { 1 } else { -1 };
        let next_t = |i: usize, dd: f64, oo: f64, lo: f64| -> f64 {
            if dd.abs() < 1e-15 {
                return f64::INFINITY;
            }
            let edge = lo + (i as f64 + if dd > 0.0 { 1.0 } else { 0.0 }) * self.cell;
            (edge - oo) / dd
        };
        let dtx = if d[0].abs() < 1e-15 {
            f64::INFINITY
        } else {
            self.cell / d[0].abs()
        };
        let dty = if d[1].abs() < 1e-15 {
            f64::INFINITY
        } else {
            self.cell / d[1].abs()
        };
        let mut tx = next_t(ix, d[0], o[0], self.x0);
        let mut ty = next_t(iy, d[1], o[1], self.y0);
        loop {
            test_cell(iy * self.nx + ix, &mut tbest, &mut best);
            let t_exit = tx.min(ty);
            if t_exit >= tbest || t_exit > tb_clip {
                break;
            }
            if tx < ty {
                let n = ix as i64 + step_x;
                if n < 0 || n >= self.nx as i64 {
                    break;
                }
                ix = n as usize;
                tx += dtx;
            } else {
                let n = iy as i64 + step_y;
                if n < 0 || n >= self.ny as i64 {
                    break;
                }
                iy = n as usize;
                ty += dty;
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_cylinder_disc_and_round_box_hits() {
        let b = Shape::Box {
            c: [10.0, 0.0, 1.0],
            half: [0.5, 2.0, 1.0],
            cs: [1.0, 0.0],
        };
        let (t, n) = b
            .intersect([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], 0.0, 100.0)
            .unwrap();
        assert!((t - 9.5).abs() < 1e-12 && n[0] == -1.0);
        // Turned 90°: the box's long side now lies along X.
        let b = Shape::Box {
            c: [10.0, 0.0, 1.0],
            half: [0.5, 2.0, 1.0],
            cs: [0.0, 1.0],
        };
        let (t, _) = b
            .intersect([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], 0.0, 100.0)
            .unwrap();
        assert!((t - 8.0).abs() < 1e-12, "{t}");
        let c = Shape::Cyl {
            c: [5.0, 0.0],
            r: 0.1,
            z: [0.0, 3.0],
        };
        let (t, _) = c
            .intersect([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], 0.0, 100.0)
            .unwrap();
        assert!((t - 4.9).abs() < 1e-12);
        assert!(c
            .intersect([0.0, 0.0, 4.0], [1.0, 0.0, 0.0], 0.0, 100.0)
            .is_none());
        let dsc = Shape::Disc {
            c: [0.0, 0.0, 0.01],
            r: 0.05,
        };
        let (t, _) = dsc
            .intersect([0.0, 0.0, 2.0], [0.0, 0.0, -1.0], 0.0, 100.0)
            .unwrap();
        assert!((t - 1.99).abs() < 1e-12);
        let rb = Shape::RoundBox {
            c: [10.0, 0.0, 1.0],
            half: [0.5, 2.0, 1.0],
            cs: [1.0, 0.0],
            r: 0.2,
        };
        // Flat part of the face: same as the box.
        let (t, _) = rb
            .intersect([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], 0.0, 100.0)
            .unwrap();
        assert!((t - 9.5).abs() < 1e-4, "{t}");
        // Near the rounded edge (z = 1.95 of 2.0): the face is set back.
        let (t, _) = rb
            .intersect([0.0, 0.0, 1.95], [1.0, 0.0, 0.0], 0.0, 100.0)
            .unwrap();
        assert!(t > 9.55, "{t}");
    }

    #[test]
    fn grid_walk_finds_the_nearest_object() {
        let prims = vec![
            Prim {
                shape: Shape::Cyl {
                    c: [20.5, 3.2],
                    r: 0.2,
                    z: [0.0, 5.0],
                },
                material: Material::Metal,
            },
            Prim {
                shape: Shape::Cyl {
                    c: [10.5, 1.6],
                    r: 0.2,
                    z: [0.0, 5.0],
                },
                material: Material::Metal,
            },
        ];
        let objs = Objects::build(prims, [0.0, -10.0, 40.0, 10.0], 1.0);
        let d = [10.5f64, 1.6, 0.0];
        let l = (d[0] * d[0] + d[1] * d[1]).sqrt();
        let d = [d[0] / l, d[1] / l, 0.0];
        let h = objs.intersect([0.0, 0.0, 1.0], d, 0.0, 100.0).unwrap();
        assert!((h.t - (l - 0.2)).abs() < 1e-9, "{}", h.t);
        // Going the other way misses everything.
        assert!(objs
            .intersect([0.0, 0.0, 1.0], [-d[0], -d[1], 0.0], 0.0, 100.0)
            .is_none());
    }
}
