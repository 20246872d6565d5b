//! Scene descriptions: what a street holds, in road coordinates.
//!
//! A scene is laid out in *road coordinates* `(u, v)`: `u` metres along the road centre
//! line (a chain of straight and circular pieces), `v` metres to its left. Everything —
//! curb toes, corner arcs, bus bays, cars, walls, the vehicle's lane — is placed in `(u, v)`
//! and mapped to scene-local XY through the centre line, so curved roads bend everything
//! consistently. Scene-local XY is the CRS minus [`SceneSpec::origin`]; nothing is aligned
//! with the grid axes (each scene starts at its own compass heading).
//!
//! This module holds the description ([`SceneSpec`] and the features placed along the road)
//! and the curb toe lines it implies; [`super::world`] builds the geometry from it and
//! [`super::scenes`] holds the named scenes.

use super::centerline::Piece;
use super::ground::{Base, CurbShape};
use crate::model::{Category, Side};
use std::f64::consts::PI;

/// A lowered curb (driveway or crossing).
#[derive(Clone, Copy, Debug)]
pub struct CurbCut {
    /// Side of the road.
    pub side: Side,
    /// Centre, metres along the road.
    pub u: f64,
    /// Length of the lowered part, metres.
    pub len: f64,
    /// Lowered curb height (the lip), metres; 0 for a cut flush with the road.
    pub h: f64,
    /// Length of the linear transition either side of the lowered part, metres.
    pub transition_m: f64,
    /// The sidewalk behind is lowered to the lip over the cut (a flush crossing) instead of
    /// ramping back up to its height.
    pub flush: bool,
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
    /// Angle between the main road (direction of increasing `u`) and the side street,
    /// degrees, 90 for a right angle.
    pub angle_deg: f64,
    /// Flare of the corners: 1 for a plain circular corner; above 1 the curb first turns
    /// on a radius `flare · radius` (a third of the turn, at most 20°), then on `radius`.
    pub flare: f64,
}

/// What a parked vehicle is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ParkedKind {
    /// A car, 4.4 × 1.7 m, 1.5 m high.
    Car,
    /// A van, 5.2 × 2.0 m, 2.3 m high.
    Van,
}

impl ParkedKind {
    /// Length and width, metres.
    pub fn size(self) -> (f64, f64) {
        match self {
            ParkedKind::Car => (4.4, 1.7),
            ParkedKind::Van => (5.2, 2.0),
        }
    }
}

/// A parked vehicle placed exactly (no jitter from the seed).
#[derive(Clone, Copy, Debug)]
pub struct Parked {
    /// Side of the road.
    pub side: Side,
    /// Centre, metres along the road.
    pub u: f64,
    /// Distance between the curb toe and the vehicle's side, metres.
    pub gap_m: f64,
    /// Car or van.
    pub kind: ParkedKind,
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
    /// Lane changes `(u, new distance from the left curb)`, each over 25 m.
    pub lane_changes: Vec<(f64, f64)>,
    /// What was drawn, for a random street (one line); empty for the named scenes.
    pub description: String,
    /// Sidewalk widths (left, right), metres.
    pub sidewalk_m: (f64, f64),
    /// Curb cuts.
    pub curb_cuts: Vec<CurbCut>,
    /// Side streets.
    pub intersections: Vec<Intersection>,
    /// Bus bays.
    pub bus_bays: Vec<BusBay>,
    /// Parked cars: side and centre `u` (jittered by the seed, 0.3 m from the curb).
    pub parked_cars: Vec<(Side, f64)>,
    /// Parked cars and vans placed exactly.
    pub parked: Vec<Parked>,
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

/// Scanner parameters.
#[derive(Clone, Copy, Debug)]
pub struct ScannerConfig {
    /// Scan lines (mirror revolutions) per second.
    pub line_rate_hz: f64,
    /// Pulses per line.
    pub pulses_per_line: usize,
    /// Height of the scanner origin above the road, metres.
    pub height_m: f64,
    /// Yaw of the scan plane from the driving direction, degrees (to the left).
    pub yaw_deg: f64,
    /// Tilt of the scan plane from the vertical, degrees.
    pub pitch_deg: f64,
    /// Direction of rotation.
    pub counter_clockwise: bool,
    /// Range noise, one sigma, metres.
    pub range_sigma_m: f64,
    /// Fraction of returns that are outliers (range off by up to metres).
    pub outlier_rate: f64,
    /// Minimum range: nearer echoes are suppressed, metres.
    pub min_range_m: f64,
    /// Maximum range, metres.
    pub max_range_m: f64,
    /// The scanning vehicle's body, which pulses cannot pass.
    pub body: VehicleBody,
}

/// The scanning vehicle's body relative to the scanner, a box in the body frame (forward,
/// left, up): the head sits on a rear platform behind the body and above its roof.
#[derive(Clone, Copy, Debug)]
pub struct VehicleBody {
    /// The body spans from `.0` to `.1` metres ahead of the scanner.
    pub ahead_m: (f64, f64),
    /// Half the body's width, metres.
    pub half_width_m: f64,
    /// How far the roof lies below the scanner origin, metres.
    pub roof_below_m: f64,
}

impl Default for VehicleBody {
    fn default() -> Self {
        VehicleBody {
            ahead_m: (0.3, 4.8),
            half_width_m: 0.95,
            roof_below_m: 0.5,
        }
    }
}

impl Default for ScannerConfig {
    fn default() -> Self {
        ScannerConfig {
            line_rate_hz: 100.0,
            pulses_per_line: 2000,
            height_m: 2.0,
            yaw_deg: 45.0,
            pitch_deg: 40.0,
            counter_clockwise: true,
            range_sigma_m: 0.005,
            outlier_rate: 2e-4,
            min_range_m: 1.5,
            max_range_m: 120.0,
            body: VehicleBody::default(),
        }
    }
}

pub(super) fn interp(table: &[(f64, f64, f64)], u: f64, side: Side) -> f64 {
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

pub(super) fn smooth01(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    0.5 - 0.5 * (PI * x).cos()
}

impl SceneSpec {
    /// Half width of the road on `side` at `u` without bus bays.
    pub fn base_half_width(&self, side: Side, u: f64) -> f64 {
        interp(&self.half_width, u, side)
    }

    /// Extra width of bus bays at `u` on `side`.
    pub(super) fn bay_depth(&self, side: Side, u: f64) -> f64 {
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

    /// (curb height, sidewalk height, category) at `u` on `side` along the main road.
    pub(super) fn curb_at(&self, side: Side, u: f64) -> (f64, f64, Category) {
        let nominal = interp(&self.curb_h, u, side);
        let mut h = nominal;
        let mut walk = nominal;
        let mut cat = Category::Curb;
        for c in self.curb_cuts.iter().filter(|c| c.side == side) {
            // Linear transitions either side of the lowered part.
            let x = (u - c.u).abs() - c.len / 2.0;
            let f = (1.0 - x / c.transition_m).clamp(0.0, 1.0);
            if f > 0.0 {
                let lowered = nominal - (nominal - c.h) * f;
                h = h.min(lowered);
                if c.flush {
                    walk = walk.min(lowered);
                }
                cat = Category::CurbCut;
            }
        }
        if self.bay_depth(side, u) > 1e-6 {
            cat = Category::BusBay;
        }
        (h, walk, cat)
    }

    /// The toe lines in road coordinates `(u, e)` with `e` measured outward on `side`,
    /// in the direction of increasing `u`; each vertex with (h_curb, h_walk, category).
    pub(super) fn toe_pieces(&self, side: Side) -> Vec<Vec<ToeVertex>> {
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
            if x.angle_deg != 90.0 || x.flare != 1.0 {
                u = self.oblique_corners(side, x, u, &mut cur, &mut out);
                continue;
            }
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

    /// A side street at any angle and flare (see [`Intersection`]): continues `cur` on the
    /// main curb from `u` up to the first corner, round it and up the side street, pushes
    /// that piece to `out`, starts the next piece at the side street's far end, back
    /// round the second corner; returns where the main curb resumes.
    fn oblique_corners(
        &self,
        side: Side,
        x: &Intersection,
        u: f64,
        cur: &mut Vec<ToeVertex>,
        out: &mut Vec<Vec<ToeVertex>>,
    ) -> f64 {
        const STEP: f64 = 0.25;
        let phi = x.angle_deg.to_radians();
        let (sn, cs) = phi.sin_cos();
        let a = x.width / 2.0;
        let w = self.half_width_at(side, x.u);
        let (_, hn, _) = self.curb_at(side, x.u);
        let cat = Category::Intersection;
        // Side street direction and the normal towards increasing u, in (u, e).
        let d = [cs, sn];
        let n = [sn, -cs];
        let p1 = [x.u - a * n[0], w - a * n[1]];
        let p2 = [x.u + a * n[0], w + a * n[1]];
        let beta = if x.flare > 1.0 {
            (phi / 3.0).min(20f64.to_radians())
        } else {
            0.0
        };
        // Corner 1: from heading 0 turning left by phi; its start on the main curb is
        // where the end lands on curb line 1.
        let arcs1 = [(x.flare * x.radius, beta), (x.radius, phi - beta)];
        let (pts1, e1) = turtle(0.0, &arcs1);
        let u1 = p1[0] - e1[0] + (w + e1[1] - p1[1]) * cs / sn;
        let straight_to = |cur: &mut Vec<ToeVertex>, u0: f64, u1: f64| {
            let k = ((u1 - u0) / STEP).ceil().max(1.0) as usize;
            for i in 0..=k {
                let uu = u0 + (u1 - u0) * i as f64 / k as f64;
                let (h, hw, c) = self.curb_at(side, uu);
                cur.push(([uu, self.half_width_at(side, uu)], h, hw, c));
            }
        };
        straight_to(cur, u, u1);
        for p in &pts1 {
            cur.push(([u1 + p[0], w + p[1]], hn, hn, cat));
        }
        let end1 = [u1 + e1[0], w + e1[1]];
        let t1 = (w + x.length - end1[1]) / sn;
        let m1 = (t1 / STEP).ceil().max(1.0) as usize;
        for i in 1..=m1 {
            let t = t1 * i as f64 / m1 as f64;
            cur.push(([end1[0] + d[0] * t, end1[1] + d[1] * t], hn, hn, cat));
        }
        out.push(std::mem::take(cur));
        // Corner 2, built from the main curb backwards (heading pi, turning right by
        // pi - phi), emitted from the side street's far end.
        let psi = PI - phi;
        let beta2 = if x.flare > 1.0 {
            (psi / 3.0).min(20f64.to_radians())
        } else {
            0.0
        };
        let arcs2 = [(x.flare * x.radius, -beta2), (x.radius, -(psi - beta2))];
        let (pts2, e2) = turtle(PI, &arcs2);
        let u2 = p2[0] - e2[0] + (w + e2[1] - p2[1]) * cs / sn;
        let end2 = [u2 + e2[0], w + e2[1]];
        let t2 = (w + x.length - end2[1]) / sn;
        let m2 = (t2 / STEP).ceil().max(1.0) as usize;
        for i in 0..m2 {
            let t = t2 * (m2 - i) as f64 / m2 as f64;
            cur.push(([end2[0] + d[0] * t, end2[1] + d[1] * t], hn, hn, cat));
        }
        // The arc's points run from the main curb outwards: reversed, without the point on
        // the main curb (the straight that follows starts there).
        cur.push((end2, hn, hn, cat));
        for p in pts2.iter().rev().skip(1) {
            cur.push(([u2 + p[0], w + p[1]], hn, hn, cat));
        }
        u2
    }

    /// Where the curbs of side street `x` leave the main curb, `u` either side: the
    /// extent of the mouth including the corners.
    pub fn mouth(&self, x: &Intersection) -> (f64, f64) {
        let sn = x.angle_deg.to_radians().sin();
        let reach = x.width / 2.0 / sn + self.corner_reach(x) + 1.0;
        (x.u - reach, x.u + reach)
    }

    /// How far the corners of side street `x` reach from where its curb lines meet the
    /// main curb line, metres (a bound, the same on both corners).
    pub fn corner_reach(&self, x: &Intersection) -> f64 {
        let sn = x.angle_deg.to_radians().sin();
        let cot = x.angle_deg.to_radians().cos() / sn;
        // The flared part turns at most 20° on its larger radius before the corner proper.
        let flare = (x.flare - 1.0).max(0.0) * x.radius * 20f64.to_radians().sin();
        (x.radius + flare) * (1.0 + cot.abs())
    }
}

/// Points every 0.1 m along a chain of circular arcs `(radius, signed turn in radians,
/// positive to the left)` starting at the origin with heading `h0` (radians from +u
/// towards +e); the start itself is not included. Returns the points and the end.
fn turtle(h0: f64, arcs: &[(f64, f64)]) -> (Vec<[f64; 2]>, [f64; 2]) {
    let (mut p, mut h) = ([0.0, 0.0], h0);
    let mut pts = Vec::new();
    for &(r, turn) in arcs {
        if turn == 0.0 || r <= 0.0 {
            continue;
        }
        let s = turn.signum();
        let c = [p[0] - s * r * h.sin(), p[1] + s * r * h.cos()];
        let k = ((r * turn.abs()) / 0.1).ceil().max(1.0) as usize;
        for i in 1..=k {
            let a = h + turn * i as f64 / k as f64;
            pts.push([c[0] + s * r * a.sin(), c[1] - s * r * a.cos()]);
        }
        h += turn;
        p = *pts.last().unwrap_or(&p);
    }
    (pts, p)
}

/// A toe vertex in road coordinates `(u, e)` with curb height, sidewalk height, category.
pub(super) type ToeVertex = ([f64; 2], f64, f64, Category);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn corner_arcs_have_the_given_radius_and_categories() {
        let mut s = crate::simulate::scene_by_name("tiny").unwrap();
        s.intersections.push(Intersection {
            side: Side::Right,
            u: 20.0,
            width: 8.0,
            radius: 6.0,
            length: 20.0,
            angle_deg: 90.0,
            flare: 1.0,
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
    fn an_oblique_flared_side_street_leaves_at_its_angle_without_jumps() {
        let mut s = crate::simulate::scene_by_name("tiny").unwrap();
        let x = Intersection {
            side: Side::Left,
            u: 20.0,
            width: 8.0,
            radius: 6.0,
            length: 20.0,
            angle_deg: 60.0,
            flare: 2.0,
        };
        s.intersections.push(x);
        let pieces = s.toe_pieces(Side::Left);
        assert_eq!(pieces.len(), 2);
        for piece in &pieces {
            for w in piece.windows(2) {
                let d = (w[1].0[0] - w[0].0[0]).hypot(w[1].0[1] - w[0].0[1]);
                assert!(d < 0.3, "step of {d} m at {:?}", w[0].0);
            }
        }
        // The side street's curbs run at 60° and end 20 m out.
        for (piece, end) in [(&pieces[0], pieces[0].len() - 1), (&pieces[1], 0)] {
            let (p, q) = (piece[end].0, piece[if end == 0 { 1 } else { end - 1 }].0);
            let ang = (p[1] - q[1]).atan2(p[0] - q[0]).to_degrees();
            assert!((ang - 60.0).abs() < 1e-6, "{ang}");
            assert!((p[1] - 4.0 - 20.0).abs() < 1e-9);
        }
        // Both curb lines are 8 m apart across the street.
        let (a, b) = (pieces[0].last().unwrap().0, pieces[1][0].0);
        let (sn, cs) = 60f64.to_radians().sin_cos();
        assert!(((b[0] - a[0]) * sn - (b[1] - a[1]) * cs - 8.0).abs() < 1e-6);
        let (m0, m1) = s.mouth(&x);
        assert!(
            m0 < pieces[0]
                .iter()
                .rev()
                .find(|v| v.3 == Category::Curb)
                .unwrap()
                .0[0]
        );
        assert!(m1 > pieces[1].iter().find(|v| v.3 == Category::Curb).unwrap().0[0]);
    }
}
