//! The ground: road, curbs and sidewalks as one height field `z = h(x, y)` in scene-local
//! coordinates (metres, X east, Y north).
//!
//! The shape is analytic around every curb toe and rasterised only where it is smooth:
//!
//! - A curb is a **toe polyline** (the lower edge of the curb face, the reference line),
//!   stored with the sidewalk on the *left* of its direction of travel, with per-vertex curb
//!   height (lowered at curb cuts) and sidewalk height.
//! - Across a toe, with `s` the signed distance from the toe (positive towards the
//!   sidewalk), the surface is `base(x, y) + crown(s) + step(s)`: `crown` is the road's cross
//!   slope (falling towards the curb, capped at the crown), `step` is the curb profile — a
//!   face with a small batter (`batter_ratio` horizontal per vertical), a circular rounded
//!   top tangent to face and top, then the sidewalk (behind a lowered curb it ramps back up
//!   to the sidewalk height) with a gentle slope up away from the road.
//! - Within [`NEAR_M`] of a toe the value is computed exactly from the nearest toe segment;
//!   farther away a bilinear raster of the same function is used (there it is smooth, so
//!   the raster's error is a fraction of a millimetre).
//!
//! Rays are intersected by marching with a step that is provably safe (the surface cannot
//! rise by more than the largest curb height plus `MAX_SLOPE` per metre within a step), then
//! bisecting the sign change to 0.1 mm.

/// Distance from a toe within which the height is evaluated analytically, metres.
pub const NEAR_M: f64 = 1.6;
/// Least bound on the slope of the smooth part of the ground (grade + crown + sidewalk
/// slope); steeper scenes (grades to 6 %, gutters) raise it, see [`Ground::max_slope`].
pub const MAX_SLOPE: f64 = 0.1;
/// Raster cell size, metres.
const CELL_M: f64 = 0.25;
/// Search radius when building the raster (crowns and road/sidewalk sides), metres.
const BUILD_SEARCH_M: f64 = 14.0;

/// Shape of every curb in a scene.
#[derive(Clone, Copy, Debug)]
pub struct CurbShape {
    /// Batter of the face: horizontal run per unit of height (0.1 → 20 mm on a 200 mm curb).
    pub batter_ratio: f64,
    /// Radius of the rounded top edge, metres (reduced on low curbs).
    pub top_radius_m: f64,
    /// Length over which the sidewalk ramps back up behind a lowered curb, metres.
    pub ramp_m: f64,
    /// Sidewalk slope, rising away from the road (water runs to the gutter).
    pub walk_slope: f64,
    /// Road cross slope, falling towards the curb.
    pub cross_slope: f64,
    /// The top edge is a straight 45° chamfer of `top_radius_m` instead of a round.
    pub chamfer: bool,
    /// Width of a gutter channel in front of the curb, metres (0: none).
    pub gutter_m: f64,
    /// Cross slope of the gutter channel, falling towards the toe (steeper than the road).
    pub gutter_slope: f64,
}

impl Default for CurbShape {
    fn default() -> Self {
        CurbShape {
            batter_ratio: 0.1,
            top_radius_m: 0.015,
            ramp_m: 0.8,
            walk_slope: 0.015,
            cross_slope: 0.02,
            chamfer: false,
            gutter_m: 0.0,
            gutter_slope: 0.0,
        }
    }
}

/// Gentle large-scale terrain under everything: a plane plus a long, low undulation.
#[derive(Clone, Copy, Debug)]
pub struct Base {
    /// Grade along local X.
    pub grade_x: f64,
    /// Grade along local Y.
    pub grade_y: f64,
    /// Amplitude of the undulation, metres.
    pub wave_m: f64,
}

impl Base {
    /// Height of the base surface.
    #[inline]
    pub fn at(&self, x: f64, y: f64) -> f64 {
        self.grade_x * x
            + self.grade_y * y
            + self.wave_m
                * (x * (std::f64::consts::TAU / 173.0) + 0.7).sin()
                * (y * (std::f64::consts::TAU / 211.0)).cos()
    }
}

/// One curb, by its toe line (sidewalk on the left of the direction of travel).
#[derive(Clone, Debug)]
pub struct ToeLine {
    /// Vertices, scene-local XY.
    pub pts: Vec<[f64; 2]>,
    /// Curb height at each vertex (lowered at curb cuts), metres.
    pub h_curb: Vec<f64>,
    /// Sidewalk height behind the curb at each vertex, metres.
    pub h_walk: Vec<f64>,
    /// Category of the stretch at each vertex.
    pub category: Vec<crate::model::Category>,
    /// Distance from the toe at which the cross slope stops rising (the crown), metres.
    pub crown_m: f64,
}

/// A toe segment, flattened for the inner loop.
#[derive(Clone, Copy, Debug)]
struct Seg {
    a: [f64; 2],
    /// Unit direction.
    d: [f64; 2],
    len: f64,
    toe: u32,
    /// Index of the segment's first vertex in its toe.
    vtx: u32,
    hc: [f64; 2],
    hw: [f64; 2],
    crown_m: f64,
}

/// Where a point lies relative to its nearest toe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ToeCoord {
    /// Toe line index.
    pub toe: u32,
    /// Segment (first vertex) index within the toe.
    pub vtx: u32,
    /// Position along the segment, 0..=1.
    pub t: f64,
    /// Signed distance from the toe, positive towards the sidewalk, metres.
    pub s: f64,
}

/// The ground height field.
pub struct Ground {
    /// Curb toes.
    pub toes: Vec<ToeLine>,
    /// Curb shape.
    pub shape: CurbShape,
    /// Base surface.
    pub base: Base,
    segs: Vec<Seg>,
    x0: f64,
    y0: f64,
    nx: usize,
    ny: usize,
    /// (nx + 1) × (ny + 1) nodes: the full height (used in far cells).
    node: Vec<f32>,
    /// (nx + 1) × (ny + 1) nodes: the base surface (smooth; bilinear error ~µm).
    base_node: Vec<f32>,
    /// Per cell: u32::MAX = far (use the raster), else index into `near`.
    cell: Vec<u32>,
    /// (start, end) into `cand` per near cell.
    near: Vec<(u32, u32)>,
    cand: Vec<u32>,
    /// Largest step anywhere (max sidewalk height) plus margin, for safe marching.
    h_max: f64,
    /// Bound on the slope of the smooth ground, for safe marching.
    max_slope: f64,
}

/// The curb profile above the road at signed distance `s` (> 0) from the toe.
#[inline]
pub fn step_profile(shape: &CurbShape, s: f64, hc: f64, hw: f64) -> f64 {
    if s <= 0.0 {
        return 0.0;
    }
    if hc <= 0.0 {
        // No lip: the ramp (or flush sidewalk) rises straight from the toe, where the
        // road's cross slope meets it.
        let ramp = (s / shape.ramp_m).clamp(0.0, 1.0);
        return hw.max(0.0) * ramp + shape.walk_slope * s.min(6.0);
    }
    let b = shape.batter_ratio * hc;
    let r = shape.top_radius_m.min(0.4 * hc);
    if shape.chamfer {
        return chamfer_profile(shape, s, hc, hw, b, r);
    }
    // The face rises at angle alpha; a fillet of radius r tangent to face and top has its
    // tangent points T = r·tan(alpha/2) from the corner (b, hc) along each line, with
    // tan(alpha/2) = hc / (L + b) and cos alpha = b / L for the face length L.
    let l = (hc * hc + b * b).sqrt();
    let tt = r * hc / (l + b);
    let sc = b + tt;
    let face_end = b - tt * b / l;
    if s < face_end {
        hc * s / b
    } else if s < sc {
        let ds = s - sc;
        hc - r + (r * r - ds * ds).max(0.0).sqrt()
    } else {
        let u = s - sc;
        let ramp = (u / shape.ramp_m).clamp(0.0, 1.0);
        hc + (hw - hc).max(0.0) * ramp + shape.walk_slope * u.min(6.0)
    }
}

/// [`step_profile`] with a straight 45° chamfer of `r` at the top edge.
fn chamfer_profile(shape: &CurbShape, s: f64, hc: f64, hw: f64, b: f64, r: f64) -> f64 {
    // The face rises from (0, 0) to (b, hc); the chamfer cuts from the face point r below
    // the top to the top point r behind the corner.
    let (fs, fz) = (b * (hc - r) / hc, hc - r);
    let ts = b + r;
    if s < fs {
        hc * s / b.max(1e-12)
    } else if s < ts {
        fz + (hc - fz) * (s - fs) / (ts - fs)
    } else {
        let u = s - ts;
        let ramp = (u / shape.ramp_m).clamp(0.0, 1.0);
        hc + (hw - hc).max(0.0) * ramp + shape.walk_slope * u.min(6.0)
    }
}

impl Seg {
    /// (distance², t, signed s)
    #[inline]
    fn locate(&self, x: f64, y: f64) -> (f64, f64, f64) {
        let px = x - self.a[0];
        let py = y - self.a[1];
        let along = px * self.d[0] + py * self.d[1];
        let t = (along / self.len).clamp(0.0, 1.0);
        let qx = px - self.d[0] * t * self.len;
        let qy = py - self.d[1] * t * self.len;
        let d2 = qx * qx + qy * qy;
        // Left of the direction = sidewalk = positive.
        let cross = self.d[0] * py - self.d[1] * px;
        let s = d2.sqrt().copysign(if cross == 0.0 { 1.0 } else { cross });
        (d2, t, s)
    }

    #[inline]
    fn height_above_base(&self, shape: &CurbShape, t: f64, s: f64) -> f64 {
        if s <= 0.0 {
            let road = |d: f64| shape.cross_slope * d.min(self.crown_m);
            if -s < shape.gutter_m {
                road(shape.gutter_m) - shape.gutter_slope * (shape.gutter_m + s)
            } else {
                road(-s)
            }
        } else {
            let hc = self.hc[0] + (self.hc[1] - self.hc[0]) * t;
            let hw = self.hw[0] + (self.hw[1] - self.hw[0]) * t;
            step_profile(shape, s, hc, hw)
        }
    }
}

impl Ground {
    /// Builds the height field over the rectangle `[xmin, xmax] × [ymin, ymax]`.
    pub fn build(
        toes: Vec<ToeLine>,
        shape: CurbShape,
        base: Base,
        bounds: [f64; 4],
        off_road_h: f64,
    ) -> Ground {
        let mut segs = Vec::new();
        let mut h_max: f64 = off_road_h;
        for (ti, toe) in toes.iter().enumerate() {
            for v in 0..toe.pts.len().saturating_sub(1) {
                let a = toe.pts[v];
                let b = toe.pts[v + 1];
                let len = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
                if len < 1e-9 {
                    continue;
                }
                h_max = h_max.max(toe.h_walk[v]).max(toe.h_curb[v]);
                segs.push(Seg {
                    a,
                    d: [(b[0] - a[0]) / len, (b[1] - a[1]) / len],
                    len,
                    toe: ti as u32,
                    vtx: v as u32,
                    hc: [toe.h_curb[v], toe.h_curb[v + 1]],
                    hw: [toe.h_walk[v], toe.h_walk[v + 1]],
                    crown_m: toe.crown_m,
                });
            }
        }
        let [xmin, ymin, xmax, ymax] = bounds;
        let nx = ((xmax - xmin) / CELL_M).ceil().max(1.0) as usize;
        let ny = ((ymax - ymin) / CELL_M).ceil().max(1.0) as usize;
        // Coarse buckets for the build-time nearest-segment search.
        let bsz = 4.0;
        let bnx = ((xmax - xmin) / bsz).ceil() as usize + 1;
        let bny = ((ymax - ymin) / bsz).ceil() as usize + 1;
        let mut buckets: Vec<Vec<u32>> = vec![Vec::new(); bnx * bny];
        for (i, s) in segs.iter().enumerate() {
            let bx = [s.a[0], s.a[0] + s.d[0] * s.len];
            let by = [s.a[1], s.a[1] + s.d[1] * s.len];
            let lo_x = ((bx[0].min(bx[1]) - BUILD_SEARCH_M - xmin) / bsz)
                .floor()
                .max(0.0) as usize;
            let hi_x = (((bx[0].max(bx[1]) + BUILD_SEARCH_M - xmin) / bsz)
                .floor()
                .max(0.0) as usize)
                .min(bnx - 1);
            let lo_y = ((by[0].min(by[1]) - BUILD_SEARCH_M - ymin) / bsz)
                .floor()
                .max(0.0) as usize;
            let hi_y = (((by[0].max(by[1]) + BUILD_SEARCH_M - ymin) / bsz)
                .floor()
                .max(0.0) as usize)
                .min(bny - 1);
            for yy in lo_y..=hi_y {
                for xx in lo_x..=hi_x {
                    buckets[yy * bnx + xx].push(i as u32);
                }
            }
        }
        let bucket_of = |x: f64, y: f64| -> &[u32] {
            let bx = ((x - xmin) / bsz).floor().clamp(0.0, (bnx - 1) as f64) as usize;
            let by = ((y - ymin) / bsz).floor().clamp(0.0, (bny - 1) as f64) as usize;
            &buckets[by * bnx + bx]
        };
        let exact = |x: f64, y: f64| -> f64 {
            let mut best = (f64::INFINITY, 0.0, 0.0, usize::MAX);
            for &i in bucket_of(x, y) {
                let (d2, t, s) = segs[i as usize].locate(x, y);
                if d2 < best.0 {
                    best = (d2, t, s, i as usize);
                }
            }
            if best.3 == usize::MAX || best.0.sqrt() > BUILD_SEARCH_M {
                off_road_h
            } else {
                segs[best.3].height_above_base(&shape, best.1, best.2)
            }
        };
        use rayon::prelude::*;
        let node: Vec<f32> = (0..(ny + 1))
            .into_par_iter()
            .flat_map_iter(|j| {
                let y = ymin + j as f64 * CELL_M;
                (0..(nx + 1)).map(move |i| (xmin + i as f64 * CELL_M, y))
            })
            .map(|(x, y)| (exact(x, y) + base.at(x, y)) as f32)
            .collect();
        let base_node: Vec<f32> = (0..(ny + 1))
            .into_par_iter()
            .flat_map_iter(|j| {
                let y = ymin + j as f64 * CELL_M;
                (0..(nx + 1)).map(move |i| (xmin + i as f64 * CELL_M, y))
            })
            .map(|(x, y)| base.at(x, y) as f32)
            .collect();
        let half_diag = CELL_M * std::f64::consts::FRAC_1_SQRT_2;
        let lists: Vec<Option<Vec<u32>>> = (0..nx * ny)
            .into_par_iter()
            .map(|c| {
                let x = xmin + ((c % nx) as f64 + 0.5) * CELL_M;
                let y = ymin + ((c / nx) as f64 + 0.5) * CELL_M;
                let bucket = bucket_of(x, y);
                let mut dmin = f64::INFINITY;
                for &i in bucket {
                    dmin = dmin.min(segs[i as usize].locate(x, y).0);
                }
                let dmin = dmin.sqrt();
                if dmin >= NEAR_M {
                    return None;
                }
                // Any segment that can be the nearest for some point of the cell is within
                // dmin + 2·half_diag of the centre (triangle inequality).
                let lim = dmin + 2.0 * half_diag + 1e-9;
                Some(
                    bucket
                        .iter()
                        .copied()
                        .filter(|&i| segs[i as usize].locate(x, y).0.sqrt() <= lim)
                        .collect(),
                )
            })
            .collect();
        let mut cell = vec![u32::MAX; nx * ny];
        let mut near = Vec::new();
        let mut cand = Vec::new();
        for (c, l) in lists.into_iter().enumerate() {
            if let Some(l) = l {
                cell[c] = near.len() as u32;
                let s = cand.len() as u32;
                cand.extend(l);
                near.push((s, cand.len() as u32));
            }
        }
        Ground {
            toes,
            shape,
            base,
            segs,
            x0: xmin,
            y0: ymin,
            nx,
            ny,
            node,
            base_node,
            cell,
            near,
            cand,
            h_max: h_max + 0.05,
            max_slope: Self::max_slope(&shape, &base),
        }
    }

    /// A bound on the slope of the smooth ground for `shape` and `base`: grade, undulation,
    /// the steeper of cross slope and gutter, and the sidewalk slope; at least [`MAX_SLOPE`].
    pub fn max_slope(shape: &CurbShape, base: &Base) -> f64 {
        let grade = base.grade_x.hypot(base.grade_y);
        let wave = base.wave_m * std::f64::consts::TAU * (1.0 / 173.0 + 1.0 / 211.0);
        let across = shape.cross_slope.max(shape.gutter_slope) + shape.walk_slope;
        MAX_SLOPE.max(1.2 * (grade + wave + across))
    }

    /// Bounds `[xmin, ymin, xmax, ymax]` of the field.
    pub fn bounds(&self) -> [f64; 4] {
        [
            self.x0,
            self.y0,
            self.x0 + self.nx as f64 * CELL_M,
            self.y0 + self.ny as f64 * CELL_M,
        ]
    }

    /// Height at (x, y), with the nearest toe when within [`NEAR_M`]; `None` outside.
    #[inline]
    pub fn height(&self, x: f64, y: f64) -> Option<(f64, Option<ToeCoord>)> {
        let fx = (x - self.x0) / CELL_M;
        let fy = (y - self.y0) / CELL_M;
        if !(fx >= 0.0 && fy >= 0.0) {
            return None;
        }
        let (ix, iy) = (fx as usize, fy as usize);
        if ix >= self.nx || iy >= self.ny {
            return None;
        }
        let c = self.cell[iy * self.nx + ix];
        let (u, v) = (fx - ix as f64, fy - iy as f64);
        let w = self.nx + 1;
        let k = iy * w + ix;
        let bil = |g: &[f32]| {
            g[k] as f64 * (1.0 - u) * (1.0 - v)
                + g[k + 1] as f64 * u * (1.0 - v)
                + g[k + w] as f64 * (1.0 - u) * v
                + g[k + w + 1] as f64 * u * v
        };
        if c == u32::MAX {
            return Some((bil(&self.node), None));
        }
        let b = bil(&self.base_node);
        let (s0, s1) = self.near[c as usize];
        let mut best = (f64::INFINITY, 0.0, 0.0, 0usize);
        for &i in &self.cand[s0 as usize..s1 as usize] {
            let (d2, t, s) = self.segs[i as usize].locate(x, y);
            if d2 < best.0 {
                best = (d2, t, s, i as usize);
            }
        }
        let seg = &self.segs[best.3];
        let h = seg.height_above_base(&self.shape, best.1, best.2);
        Some((
            b + h,
            Some(ToeCoord {
                toe: seg.toe,
                vtx: seg.vtx,
                t: best.1,
                s: best.2,
            }),
        ))
    }

    /// First intersection of the ray `o + t·d` (`d` unit) with the ground for
    /// `t ∈ [t0, t1]`: `(t, toe)`.
    pub fn intersect(
        &self,
        o: [f64; 3],
        d: [f64; 3],
        t0: f64,
        t1: f64,
    ) -> Option<(f64, Option<ToeCoord>)> {
        let dxy = (d[0] * d[0] + d[1] * d[1]).sqrt();
        let descent = -d[2];
        // A ray climbing faster than the ground can never meet it once above.
        let min_step = 0.04 / dxy.max(1e-3);
        let rate = descent + self.max_slope * dxy;
        let mut t = t0;
        let g_at = |t: f64| -> Option<f64> {
            let p = [o[0] + d[0] * t, o[1] + d[1] * t, o[2] + d[2] * t];
            self.height(p[0], p[1]).map(|(h, _)| p[2] - h)
        };
        let mut g = g_at(t)?;
        if g <= 0.0 {
            return None; // starts below ground: no valid hit
        }
        loop {
            if t >= t1 {
                return None;
            }
            if rate <= 0.0 && g > self.h_max {
                return None;
            }
            let safe = if rate > 0.0 {
                (g - self.h_max) / rate
            } else {
                0.0
            };
            let step = safe.max(min_step);
            let tn = (t + step).min(t1);
            let gn = g_at(tn)?;
            if gn <= 0.0 {
                // Regula falsi (Illinois variant) on the bracketed sign change: a few
                // evaluations on smooth ground, still safe across the curb's kinks.
                let (mut lo, mut hi, mut glo, mut ghi) = (t, tn, g, gn);
                let mut side = 0i8;
                for _ in 0..60 {
                    if hi - lo < 1e-4 {
                        break;
                    }
                    let mut mid = lo + (hi - lo) * glo / (glo - ghi);
                    if !(mid > lo && mid < hi) {
                        mid = 0.5 * (lo + hi);
                    }
                    match g_at(mid) {
                        Some(v) if v > 0.0 => {
                            if v < 2e-5 {
                                lo = mid;
                                hi = mid;
                                break;
                            }
                            lo = mid;
                            glo = v;
                            if side == 1 {
                                ghi *= 0.5;
                            }
                            side = 1;
                        }
                        Some(v) => {
                            if v > -2e-5 {
                                lo = mid;
                                hi = mid;
                                break;
                            }
                            hi = mid;
                            ghi = v;
                            if side == -1 {
                                glo *= 0.5;
                            }
                            side = -1;
                        }
                        None => {
                            hi = mid;
                            ghi = -1e-3;
                        }
                    }
                }
                let th = 0.5 * (lo + hi);
                let p = [o[0] + d[0] * th, o[1] + d[1] * th];
                let toe = self.height(p[0], p[1]).and_then(|x| x.1);
                return Some((th, toe));
            }
            t = tn;
            g = gn;
        }
    }

    /// Upward unit normal at (x, y) by central differences.
    pub fn normal(&self, x: f64, y: f64) -> [f64; 3] {
        let e = 0.003;
        let h = |x: f64, y: f64| self.height(x, y).map(|v| v.0);
        match (h(x + e, y), h(x - e, y), h(x, y + e), h(x, y - e)) {
            (Some(a), Some(b), Some(c), Some(dd)) => {
                let gx = (a - b) / (2.0 * e);
                let gy = (c - dd) / (2.0 * e);
                let n = (gx * gx + gy * gy + 1.0).sqrt();
                [-gx / n, -gy / n, 1.0 / n]
            }
            _ => [0.0, 0.0, 1.0],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Category;

    fn straight_ground(h: f64) -> Ground {
        // One toe along +X at y = 0, sidewalk on the left (+Y), road at y < 0.
        let pts: Vec<[f64; 2]> = (0..=40).map(|i| [i as f64 * 0.5, 0.0]).collect();
        let n = pts.len();
        let toe = ToeLine {
            pts,
            h_curb: vec![h; n],
            h_walk: vec![h; n],
            category: vec![Category::Curb; n],
            crown_m: 3.0,
        };
        Ground::build(
            vec![toe],
            CurbShape::default(),
            Base {
                grade_x: 0.0,
                grade_y: 0.0,
                wave_m: 0.0,
            },
            [-5.0, -8.0, 25.0, 8.0],
            h,
        )
    }

    #[test]
    fn profile_is_continuous_and_reaches_the_curb_height() {
        let sh = CurbShape::default();
        let mut prev = 0.0;
        for i in 1..2000 {
            let s = i as f64 * 0.0001;
            let z = step_profile(&sh, s, 0.2, 0.2);
            assert!(
                z >= prev - 1e-9 && z - prev < 0.011,
                "s {s} z {z} prev {prev}"
            );
            prev = z;
        }
        // Batter 0.1: 20 mm run on a 200 mm face; the top is reached within ~3 cm.
        assert!((step_profile(&sh, 0.01, 0.2, 0.2) - 0.1).abs() < 1e-9);
        assert!((step_profile(&sh, 0.05, 0.2, 0.2) - 0.2).abs() < 0.002);
    }

    #[test]
    fn road_falls_towards_the_curb_and_sidewalk_is_up() {
        let g = straight_ground(0.2);
        let (road, toe) = g.height(10.0, -1.0).unwrap();
        assert!((road - 0.02).abs() < 1e-9, "{road}");
        let tc = toe.unwrap();
        assert!((tc.s + 1.0).abs() < 1e-9);
        // Far cell (raster): 5 m into the road, crown capped at 3 m → 0.06.
        let (far, toe) = g.height(10.1, -5.0).unwrap();
        assert!(toe.is_none());
        assert!((far - 0.06).abs() < 1e-4, "{far}");
        let (walk, _) = g.height(10.0, 1.0).unwrap();
        assert!(walk > 0.2 && walk < 0.22, "{walk}");
    }

    #[test]
    fn vertical_ray_hits_the_road_at_the_known_range() {
        let g = straight_ground(0.2);
        // Road at y = -2: z = 0.04. From z = 2 straight down: range 1.96 m.
        let (t, toe) = g
            .intersect([7.3, -2.0, 2.0], [0.0, 0.0, -1.0], 0.0, 50.0)
            .unwrap();
        assert!((t - 1.96).abs() < 2e-4, "{t}");
        assert!(toe.is_none() || toe.unwrap().s < 0.0);
        // A slanted ray towards the curb hits the face: the hit is between toe and top.
        let d = [0.0, 0.8f64, -0.6f64];
        let n = (d[1] * d[1] + d[2] * d[2]).sqrt();
        let d = [0.0, d[1] / n, d[2] / n];
        // Aim at the face point (y = 0.01, z = 0.1) (batter 0.1: 0.1 m up at 10 mm), from
        // 2 m back along the ray.
        let o = [5.0, 0.01 - 2.0 * d[1], 0.1 - 2.0 * d[2]];
        let (t, toe) = g.intersect(o, d, 0.0, 50.0).unwrap();
        assert!((t - 2.0).abs() < 2e-4, "{t}");
        let s = toe.unwrap().s;
        assert!((s - 0.01).abs() < 2e-4, "{s}");
    }

    #[test]
    fn upward_ray_misses() {
        let g = straight_ground(0.2);
        assert!(g
            .intersect([5.0, -2.0, 2.0], [0.0, 0.6, 0.8], 0.0, 50.0)
            .is_none());
    }

    #[test]
    fn a_cut_without_lip_starts_at_the_road_and_breaks_slope_at_the_toe() {
        let sh = CurbShape::default();
        // Continuous at the toe, then rising along the ramp to the sidewalk height.
        assert!(step_profile(&sh, 1e-6, 0.0, 0.15) < 1e-5);
        let (a, b) = (
            step_profile(&sh, 0.1, 0.0, 0.15),
            step_profile(&sh, 0.2, 0.0, 0.15),
        );
        assert!(a > 0.015 && b > a, "{a} {b}");
        assert!(
            (step_profile(&sh, sh.ramp_m, 0.0, 0.15) - 0.15 - sh.walk_slope * sh.ramp_m).abs()
                < 1e-9
        );
    }

    #[test]
    fn a_chamfer_cuts_the_top_edge_straight() {
        let sh = CurbShape {
            chamfer: true,
            top_radius_m: 0.02,
            ..CurbShape::default()
        };
        let (hc, b) = (0.15, 0.1 * 0.15);
        // Face up to 20 mm below the top, then a straight line to the top 20 mm behind.
        let fs = b * (hc - 0.02) / hc;
        assert!((step_profile(&sh, fs, hc, hc) - (hc - 0.02)).abs() < 1e-9);
        let mid = 0.5 * (fs + b + 0.02);
        assert!((step_profile(&sh, mid, hc, hc) - (hc - 0.01)).abs() < 1e-9);
        assert!((step_profile(&sh, b + 0.02, hc, hc) - hc).abs() < 1e-9);
    }

    #[test]
    fn a_gutter_falls_more_steeply_to_the_toe() {
        let pts: Vec<[f64; 2]> = (0..=40).map(|i| [i as f64 * 0.5, 0.0]).collect();
        let n = pts.len();
        let toe = ToeLine {
            pts,
            h_curb: vec![0.15; n],
            h_walk: vec![0.15; n],
            category: vec![Category::Curb; n],
            crown_m: 3.0,
        };
        let shape = CurbShape {
            gutter_m: 0.4,
            gutter_slope: 0.06,
            ..CurbShape::default()
        };
        let flat = Base {
            grade_x: 0.0,
            grade_y: 0.0,
            wave_m: 0.0,
        };
        let g = Ground::build(vec![toe], shape, flat, [-5.0, -8.0, 25.0, 8.0], 0.15);
        let at = |y: f64| g.height(10.0, y).unwrap().0;
        // Road 2 % down to the gutter's edge (8 mm at 0.4 m), then 6 %: 16 mm lower at the toe.
        assert!((at(-0.4) - 0.008).abs() < 1e-9, "{}", at(-0.4));
        assert!(
            (at(-1e-4) - (0.008 - 0.06 * 0.4)).abs() < 1e-5,
            "{}",
            at(-1e-4)
        );
        assert!(Ground::max_slope(&shape, &flat) >= 0.1);
    }
}
