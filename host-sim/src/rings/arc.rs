//! Ring assembly, the half-arc cut and the projection of a half-arc into the kernel's
//! x′–z′ plane (docs/frames.md, *Rings as scanlines*).
//!
//! # The rule
//!
//! A ring is one laser's revolution: a closed loop on the ground around the vehicle that
//! crosses a curb beside it twice (once ahead, once behind) and has no nadir. It is cut at
//! the vehicle's lateral axis (azimuth ±90°) into two half-arcs:
//!
//! - **front** — the points with x ≥ 0, ordered by azimuth φ = atan2(y, x) from −90° (right)
//!   through 0° (ahead) to +90° (left);
//! - **rear** — the points with x < 0, ordered from +90° (left) through 180° (behind) to
//!   −90° (right).
//!
//! Each half-arc is one scanline. Its **pseudo-nadir** is its point nearest the vehicle's
//! lateral centre line (smallest |y|); from there the kernel seeks a candidate outward on
//! each side.
//!
//! # The projection
//!
//! A ring is a cone, not a plane, so a half-arc has no plane of its own to be drawn in. It
//! is projected onto the vehicle's cross-section:
//!
//! x′ = y (lateral offset, left positive), z′ = z (height relative to the sensor).
//!
//! The forward coordinate is dropped. For a curb parallel to the vehicle's axis this is the
//! curb's true cross-section, wherever along the curb the ring crosses it; a curb at an
//! angle α to the axis is seen stretched across by 1/cos α. With x′ = y the sign
//! convention is the profiler's for both half-arcs: x′ > 0 is the vehicle's left, so the
//! kernel's "left candidate" (first peak outward with x′ > 0) is on the left ahead of the
//! vehicle and behind it alike. The kernel's own nadir (smallest |x′| with z′ < 0) is the
//! pseudo-nadir.
//!
//! # What is left out
//!
//! - points nearer than [`ArcParams::min_range_m`] horizontally (the vehicle itself,
//!   missed returns reported near the origin);
//! - points farther than [`ArcParams::max_lateral_m`] to the side (the ends of the far
//!   rings' arcs, beyond any road edge sought), and points farther than
//!   [`ArcParams::max_azimuth_deg`] from straight ahead or behind (where the ring runs
//!   nearly along the vehicle's axis and crosses a curb at a grazing angle);
//! - points closer than [`ArcParams::min_separation_m`] in the x′–z′ plane to the previous
//!   point kept along the arc (piled up by the projection where the ring runs along the
//!   vehicle's axis);
//! - half-arcs that do not see the road at the centre line: fewer than
//!   [`ArcParams::min_points`] points, no point within 1 m of the centre line, the points
//!   there less than [`ArcParams::min_depth_m`] below the sensor (a vehicle, a wall or the
//!   sky ahead), or the pseudo-nadir farther than [`ArcParams::max_reach_m`] ahead or behind.

use crate::io::sweep::Sweep;
use serde::{Deserialize, Serialize};

/// Which half of the revolution.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Half {
    /// x ≥ 0, ordered right to left.
    Front,
    /// x < 0, ordered left to right.
    Rear,
}

impl Half {
    /// "front" or "rear".
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Front => "front",
            Self::Rear => "rear",
        }
    }
}

/// Parameters of the cut (`[rings]` in a config file), and the two settings of the bend
/// tracker that differ on rings (`track_*`; `stream::stage_bend` puts them in place of
/// `[bend]`'s on a ring file).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ArcParams {
    /// Points nearer than this horizontally are left out, metres. 2.5 m: the KITTI and
    /// nuScenes cars' bodies reach about 1.5 m from the sensor, and the lowest lasers meet
    /// the road 3.8–3.9 m out.
    pub min_range_m: f32,
    /// Points farther than this to either side are left out, metres.
    pub max_lateral_m: f32,
    /// Points whose azimuth lies farther than this from straight ahead (front half-arcs)
    /// or straight behind (rear ones) are left out, degrees; 90 leaves none out. A ring
    /// crosses a curb at lateral offset d at azimuth φ with sin φ = d / r, and its path
    /// there runs at 90° − |φ| to the curb: a near ring meets a curb 7.5 m to the side at
    /// |φ| ≈ 65°, crossing it at 25°, so 0.5 m across the curb are 1.1 m along it. Where
    /// the curb changes along its length (a curb cut's transition from full to lowered
    /// height) such a crossing draws a step behind the toe, and the cross-section x′ = y
    /// reads it as a toe. 60°: crossings at 30° or more to a curb along the path; chosen
    /// on simulated tuning drives (docs/results.md, *Spinning lidars*). One value for every
    /// sensor: the error follows from the crossing's angle to the curb, which neither the
    /// azimuth step nor the spacing of the rings changes.
    pub max_azimuth_deg: f32,
    /// Half-arcs whose pseudo-nadir lies farther ahead or behind than this are skipped,
    /// metres. 20 m: beyond it an HDL-64E's rings are more than 2 m apart on the road.
    pub max_reach_m: f32,
    /// The points within 1 m of the centre line must lie at least this far below the
    /// sensor (median), metres; sensors sit 1.5–2 m above the road on cars.
    pub min_depth_m: f32,
    /// Fewest points of a half-arc.
    pub min_points: usize,
    /// A point closer than this to the previous point kept, in the x′–z′ plane, is left
    /// out, metres. Where a ring runs along the vehicle's axis (near azimuth ±90°) the
    /// projection x′ = y piles its points up: hundreds within a few millimetres, which fill
    /// the kernel's neighbour windows (capped at 255 points) and cost it time while adding
    /// no cross-section. 1 cm is a third of an HDL-64E's spacing 10 m out.
    pub min_separation_m: f32,
    /// The tracker's search radius on rings (`[bend] search_radius_m` on profilers),
    /// metres. A profiler's search circle spans dozens of scanlines 1 cm apart; on rings it
    /// meets one or two ring crossings, dense across the curb (points 4–5 cm apart 12–15 m
    /// out on an HDL-64E or VLP-16), so the profilers' 0.10 m reaches two points past the
    /// prediction on either side — at a curb cut onto the ramp's top, which bends as
    /// sharply as the toe. 0.07 m is about the kernel's d_b on these sensors (0.071 m and
    /// 0.079 m, `SensorModel::kernel_params`): one point past the prediction on either side.
    pub track_search_radius_m: f32,
    /// The tracker's stop threshold on rings, degrees (`[bend] stop_rho_deg` on
    /// profilers): a step whose search circle holds no point with at least this ρ goes to
    /// the virtual profile (a step or a cut's toe in the cross-section) or counts as a gap,
    /// instead of taking the best of weak points. A ring crossing puts only a few points in
    /// the circle, so a weak pick is not outvoted by the crossings before and after it as
    /// on a profiler's dense scanlines. Measured on the tuning drives (docs/results.md,
    /// *Spinning lidars*).
    pub track_stop_rho_deg: f32,
    /// Whether the tracker tries the far leg's longer profile on rings (`bend::leg`;
    /// always on profilers). false: a ring crosses a curb every few decimetres along it
    /// wherever it sees it at all, so a profile too sparse for the ordinary test lies
    /// between two crossings, and the one four times as long reaches whatever step lies
    /// beyond them. Measured on the tuning and evaluation drives (docs/results.md,
    /// *Spinning lidars*).
    pub track_leg_toes: bool,
}

impl Default for ArcParams {
    fn default() -> Self {
        Self {
            min_range_m: 2.5,
            max_lateral_m: 12.0,
            max_azimuth_deg: 60.0,
            max_reach_m: 20.0,
            min_depth_m: 1.0,
            min_points: 20,
            min_separation_m: 0.01,
            track_search_radius_m: 0.07,
            track_stop_rho_deg: 20.0,
            track_leg_toes: false,
        }
    }
}

impl ArcParams {
    /// Every distance finite and not negative; on failure, which field and its value.
    pub fn validate(&self) -> Result<(), String> {
        for (name, v) in [
            ("min_range_m", self.min_range_m),
            ("max_lateral_m", self.max_lateral_m),
            ("max_azimuth_deg", self.max_azimuth_deg),
            ("max_reach_m", self.max_reach_m),
            ("min_depth_m", self.min_depth_m),
            ("min_separation_m", self.min_separation_m),
            ("track_search_radius_m", self.track_search_radius_m),
            ("track_stop_rho_deg", self.track_stop_rho_deg),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!("{name} = {v}: must be a finite distance ≥ 0"));
            }
        }
        Ok(())
    }

    /// tan of `max_azimuth_deg`, infinite at 90° and above: the argument of
    /// [`Self::beyond_side`], computed once per batch of points.
    pub fn max_azimuth_tan(&self) -> f32 {
        if self.max_azimuth_deg < 90.0 {
            self.max_azimuth_deg.to_radians().tan()
        } else {
            f32::INFINITY
        }
    }

    /// Whether a point at (`x`, `y`) in the vehicle frame lies beyond the side: farther
    /// than `max_lateral_m` to the side, or farther than `max_azimuth_deg` from the
    /// vehicle's axis (`tan_max` = [`Self::max_azimuth_tan`]; at infinity none is, the
    /// product with x = 0 being NaN).
    #[inline]
    pub fn beyond_side(&self, x: f32, y: f32, tan_max: f32) -> bool {
        y.abs() > self.max_lateral_m || y.abs() > x.abs() * tan_max
    }
}

/// One half of one ring, as a scanline.
#[derive(Clone, Debug, PartialEq)]
pub struct HalfArc {
    /// The ring.
    pub ring: u16,
    /// Front or rear.
    pub half: Half,
    /// Indices into the sweep's columns, in order along the arc.
    pub points: Vec<u32>,
    /// Position in `points` of the pseudo-nadir (smallest |y|).
    pub nadir: usize,
    /// |x| of the pseudo-nadir: how far ahead or behind the ring meets the centre line.
    pub reach_m: f32,
}

/// What the cut kept and left out.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ArcCounters {
    /// Rings holding at least one point.
    pub rings: u32,
    /// Half-arcs kept.
    pub arcs: u32,
    /// Half-arcs skipped: too few points.
    pub skipped_short: u32,
    /// Half-arcs skipped: no road at the centre line (nothing there, or not low enough).
    pub skipped_no_road: u32,
    /// Half-arcs skipped: pseudo-nadir beyond the reach.
    pub skipped_far: u32,
    /// Points within the reach of the sensor of half-arcs skipped beyond it, kept for the
    /// virtual profiles without a bend angle (the streaming stage only).
    pub points_far: u64,
    /// Points left out as too near.
    pub points_near: u64,
    /// Points left out as too far to the side.
    pub points_lateral: u64,
    /// Points left out as closer than the minimum separation to the previous one.
    pub points_piled: u64,
    /// Points in the half-arcs kept.
    pub points_in_arcs: u64,
}

/// The projection of a half-arc's point into the kernel's x′–z′ plane (module docs).
#[inline]
pub fn project(_x: f32, y: f32, z: f32) -> (f32, f32) {
    (y, z)
}

/// Cuts every ring of `s` into half-arcs and keeps those that see the road (module docs).
/// The arcs come ring by ring, front before rear.
pub fn half_arcs(s: &Sweep, p: &ArcParams) -> (Vec<HalfArc>, ArcCounters) {
    let rings = usize::from(s.rings.max(1));
    // (key, index) per ring and half; the key orders along the arc: sin φ = y/r rises from
    // −1 to 1 over the front half (right to left) and falls from 1 to −1 over the rear one.
    let mut buckets: Vec<Vec<(f32, u32)>> = vec![Vec::new(); 2 * rings];
    let mut c = ArcCounters::default();
    let (min2, tan_max) = (p.min_range_m * p.min_range_m, p.max_azimuth_tan());
    for i in 0..s.len() {
        let (x, y) = (s.x[i], s.y[i]);
        let r2 = x * x + y * y;
        if r2 < min2 {
            c.points_near += 1;
            continue;
        }
        if p.beyond_side(x, y, tan_max) {
            c.points_lateral += 1;
            continue;
        }
        let sin = y / r2.sqrt();
        let ring = usize::from(s.ring[i]);
        if x >= 0.0 {
            buckets[2 * ring].push((sin, i as u32));
        } else {
            buckets[2 * ring + 1].push((-sin, i as u32));
        }
    }
    c.rings = (0..rings)
        .filter(|&k| !buckets[2 * k].is_empty() || !buckets[2 * k + 1].is_empty())
        .count() as u32;
    let mut arcs = Vec::new();
    for (b, mut pts) in buckets.into_iter().enumerate() {
        if pts.is_empty() {
            continue;
        }
        let half = if b % 2 == 0 { Half::Front } else { Half::Rear };
        if pts.len() < p.min_points {
            c.skipped_short += 1;
            continue;
        }
        // Stable: points at the same azimuth keep the file's order; a file stored in
        // azimuth order (two runs, at most) sorts in linear time.
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        let points = thin(s, pts, p.min_separation_m, &mut c.points_piled);
        let Some(arc) = accept(s, points, (b / 2) as u16, half, p, &mut c) else {
            continue;
        };
        c.arcs += 1;
        c.points_in_arcs += arc.points.len() as u64;
        arcs.push(arc);
    }
    (arcs, c)
}

/// The arc's indices without the points closer than `sep` (in x′–z′) to the previous one
/// kept.
fn thin(s: &Sweep, pts: Vec<(f32, u32)>, sep: f32, piled: &mut u64) -> Vec<u32> {
    let sep2 = sep * sep;
    let mut out: Vec<u32> = Vec::with_capacity(pts.len());
    let mut last = (f32::INFINITY, f32::INFINITY);
    for (_, i) in pts {
        let (xp, zp) = project(s.x[i as usize], s.y[i as usize], s.z[i as usize]);
        let (dx, dz) = (xp - last.0, zp - last.1);
        if dx * dx + dz * dz < sep2 {
            *piled += 1;
            continue;
        }
        last = (xp, zp);
        out.push(i);
    }
    out
}

/// The pseudo-nadir and the road checks of one half-arc.
fn accept(
    s: &Sweep,
    points: Vec<u32>,
    ring: u16,
    half: Half,
    p: &ArcParams,
    c: &mut ArcCounters,
) -> Option<HalfArc> {
    let (nadir, _) = points
        .iter()
        .enumerate()
        .map(|(k, &i)| (k, s.y[i as usize].abs()))
        .min_by(|a, b| a.1.total_cmp(&b.1))?;
    let mut centre: Vec<f32> = points
        .iter()
        .filter(|&&i| s.y[i as usize].abs() <= 1.0)
        .map(|&i| s.z[i as usize])
        .collect();
    if centre.is_empty() {
        c.skipped_no_road += 1;
        return None;
    }
    let mid = centre.len() / 2;
    let (_, &mut z_mid, _) = centre.select_nth_unstable_by(mid, f32::total_cmp);
    if z_mid > -p.min_depth_m {
        c.skipped_no_road += 1;
        return None;
    }
    let reach_m = s.x[points[nadir] as usize].abs();
    if reach_m > p.max_reach_m {
        c.skipped_far += 1;
        return None;
    }
    Some(HalfArc {
        ring,
        half,
        points,
        nadir,
        reach_m,
    })
}

/// The sweep's points grouped by ring, each ring in the file's order (ring assembly).
pub fn rings_of(s: &Sweep) -> Vec<Vec<u32>> {
    let mut out = vec![Vec::new(); usize::from(s.rings)];
    for (i, &r) in s.ring.iter().enumerate() {
        out[usize::from(r)].push(i as u32);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::sweep::SweepFormat;

    /// A flat road 1.7 m below the sensor seen by `rings` lasers, ring k meeting it at
    /// 4 + 2.1k m; points every `step` degrees from 0° (ahead) anticlockwise, stored ring by
    /// ring as KITTI does.
    fn circles(rings: u16, step: f32) -> Sweep {
        let mut s = Sweep::with_capacity(SweepFormat::Kitti, 0);
        for k in 0..rings {
            let r = 4.0 + 2.1 * f32::from(k);
            let n = (360.0 / step) as usize;
            for j in 0..n {
                let a = (j as f32 * step).to_radians();
                s.push(r * a.cos(), r * a.sin(), -1.7, 0.0, k);
            }
        }
        s
    }

    #[test]
    fn each_ring_gives_a_front_and_a_rear_arc_ordered_along_the_arc() {
        let s = circles(3, 0.5);
        let p = ArcParams {
            min_separation_m: 0.0,
            max_azimuth_deg: 90.0,
            ..ArcParams::default()
        };
        let (arcs, c) = half_arcs(&s, &p);
        assert_eq!((c.rings, c.arcs, arcs.len()), (3, 6, 6));
        for a in &arcs {
            let xs: Vec<f32> = a.points.iter().map(|&i| s.x[i as usize]).collect();
            let ys: Vec<f32> = a.points.iter().map(|&i| s.y[i as usize]).collect();
            match a.half {
                // Right to left ahead: y rises; every point ahead.
                Half::Front => {
                    assert!(ys.windows(2).all(|w| w[0] <= w[1]), "ring {}", a.ring);
                    assert!(xs.iter().all(|&x| x >= 0.0));
                }
                // Left to right behind: y falls; every point behind.
                Half::Rear => {
                    assert!(ys.windows(2).all(|w| w[0] >= w[1]), "ring {}", a.ring);
                    assert!(xs.iter().all(|&x| x < 0.0));
                }
            }
            // The pseudo-nadir is on the centre line, as far out as the ring.
            let r = 4.0 + 2.1 * f32::from(a.ring);
            assert!(ys[a.nadir].abs() < 0.05 && (a.reach_m - r).abs() < 0.05);
            assert_eq!(a.points.len(), 360);
        }
        // Ring by ring, front before rear.
        let order: Vec<(u16, Half)> = arcs.iter().map(|a| (a.ring, a.half)).collect();
        assert_eq!(order[..2], [(0, Half::Front), (0, Half::Rear)]);
    }

    #[test]
    fn points_piled_up_by_the_projection_are_thinned() {
        let s = circles(3, 0.5);
        let p = ArcParams {
            max_azimuth_deg: 90.0,
            ..ArcParams::default()
        };
        let (arcs, c) = half_arcs(&s, &p);
        let kept: usize = arcs.iter().map(|a| a.points.len()).sum();
        assert_eq!(kept as u64 + c.points_piled, s.len() as u64);
        // Near ±90° a 4 m ring's points 0.5° apart are under 1 cm apart in y.
        assert!(c.points_piled > 20, "{c:?}");
        for a in &arcs {
            for w in a.points.windows(2) {
                let (i, j) = (w[0] as usize, w[1] as usize);
                assert!((s.y[i] - s.y[j]).hypot(s.z[i] - s.z[j]) >= 0.01);
            }
        }
    }

    #[test]
    fn points_far_from_the_axis_are_left_out() {
        let s = circles(3, 0.5);
        let p = ArcParams {
            min_separation_m: 0.0,
            ..ArcParams::default()
        };
        assert_eq!(p.max_azimuth_deg, 60.0);
        let (arcs, c) = half_arcs(&s, &p);
        // 0.5° steps: |φ| ≤ 60° ahead and behind keeps 241 + 241 of 720 per ring (the
        // boundary points themselves within rounding).
        let kept: usize = arcs.iter().map(|a| a.points.len()).sum();
        assert_eq!(kept as u64 + c.points_lateral, s.len() as u64);
        assert!((3 * 478..=3 * 484).contains(&kept), "{kept}");
        for a in &arcs {
            for &i in &a.points {
                let (x, y) = (s.x[i as usize], s.y[i as usize]);
                assert!(
                    y.abs() <= x.abs() * 60f32.to_radians().tan() + 1e-4,
                    "{x} {y}"
                );
            }
        }
        // 90° leaves none out.
        let all = ArcParams {
            max_azimuth_deg: 90.0,
            ..p
        };
        assert_eq!(half_arcs(&s, &all).1.points_lateral, 0);
    }

    #[test]
    fn projection_keeps_left_positive_and_height() {
        assert_eq!(project(10.0, 2.5, -1.6), (2.5, -1.6));
        assert_eq!(project(-10.0, 2.5, -1.6), (2.5, -1.6));
        assert_eq!(project(3.0, -4.0, 0.2), (-4.0, 0.2));
    }

    #[test]
    fn arcs_that_miss_the_road_are_skipped_and_counted() {
        let mut s = circles(12, 1.0);
        // Ring 0 sees a wall 0.5 m below the sensor ahead: no road at the centre line.
        for i in 0..s.len() {
            if s.ring[i] == 0 && s.x[i] > 0.0 && s.y[i].abs() < 1.5 {
                s.z[i] = -0.5;
            }
        }
        let (arcs, c) = half_arcs(&s, &ArcParams::default());
        // Ring 8 meets the road at 20.8 m, beyond the 20 m reach, and so do rings 9–11.
        assert_eq!(c.skipped_far, 8);
        assert_eq!(c.skipped_no_road, 1);
        assert_eq!(c.arcs, 24 - 9);
        assert!(!arcs.iter().any(|a| a.ring == 0 && a.half == Half::Front));
        // Points to the side beyond 12 m are left out of the far rings.
        assert!(c.points_lateral > 0);
        // Points nearer than 2.5 m: none here.
        assert_eq!(c.points_near, 0);
    }

    #[test]
    fn ring_assembly_groups_points_in_file_order() {
        let s = circles(2, 90.0);
        assert_eq!(rings_of(&s), vec![vec![0, 1, 2, 3], vec![4, 5, 6, 7]]);
    }
}
