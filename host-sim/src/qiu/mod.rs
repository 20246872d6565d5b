//! The plane-based road-edge method of Qiu et al. (2016), "A fast and robust algorithm for
//! road edges extraction from LiDAR data" (`papers/002_ce63f0f98c12cff3.txt`), on
//! unorganised points, all on the host.
//!
//! | paper | module |
//! |---|---|
//! | §3.1 partition by GPS time and trajectory | [`partition`] |
//! | §3.2 outlier removal, down-sampling | [`preprocess`] |
//! | §3.3.1 grid minimum-z normalisation | [`normalise`] |
//! | §3.3.2 rough plane α, refined planes β_i, candidates, E_s | [`segment`] |
//! | §3.4 refinement by road width and by continuity | [`refine`] |
//! | §4.2 parameters | [`params`] |
//!
//! Sections are processed in parallel (rayon); each section's RANSAC draws come from a
//! seed mixed with the section index and results are collected in section order, so the
//! output does not depend on the number of threads. Each section keeps only its *core*
//! stations (see [`partition`]) and the pieces are joined across section boundaries, so
//! an edge seen by two overlapping sections is output once.

pub mod normalise;
pub mod params;
pub mod partition;
pub mod preprocess;
pub mod refine;
pub mod segment;

pub use params::{QiuParams, QiuParamsError};

use crate::io::trajectory::Trajectory;
use crate::model::{Category, EdgeLine, Side};
use partition::{plan_sections, stations, Section, SectionTrack};
use rayon::prelude::*;
use refine::{Chain, EdgePoint};
use std::collections::HashMap;

/// What the method reads: world point columns (all the same length) and the trajectory.
#[derive(Clone, Copy)]
pub struct QiuInput<'a> {
    /// World X, metres.
    pub x: &'a [f64],
    /// World Y, metres.
    pub y: &'a [f64],
    /// World Z, metres.
    pub z: &'a [f64],
    /// GPS time, seconds (any order).
    pub t: &'a [f64],
    /// The trajectory, in the same CRS and time base.
    pub trajectory: &'a Trajectory,
}

/// What happened in one section (for reports and tests).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SectionReport {
    /// The section.
    pub section: Option<Section>,
    /// Points inside the section's time interval and width.
    pub points_in: usize,
    /// Points after outlier removal and down-sampling.
    pub points_preprocessed: usize,
    /// Per side (left, right): the β whose candidate set had the smallest E_s.
    pub beta_m: [Option<f64>; 2],
    /// (β, candidates, E_s left, E_s right) per refined plane.
    pub energies: Vec<(f64, usize, Option<f64>, Option<f64>)>,
    /// Candidate edge points of the chosen set.
    pub candidates: usize,
    /// The most frequent road width of the section (Eq. 3).
    pub road_width_m: Option<f64>,
    /// Points kept by the road-width refinement.
    pub width_kept: usize,
    /// Chains kept by the continuity refinement (before clipping to the core).
    pub chains: usize,
    /// The chosen candidates (world x, y, terrain z) and whether the road-width refinement
    /// kept them, for plots.
    pub candidate_points: Vec<([f64; 3], bool)>,
    /// Wall seconds per stage: partition (§3.1), pre-processing (§3.2), normalisation
    /// (§3.3.1), rough segmentation (§3.3.2), refinement and heights (§3.4).
    pub stage_s: [f64; 5],
}

/// What happened overall.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct QiuReport {
    /// Points given.
    pub points_total: usize,
    /// Points dropped for a non-finite coordinate or time.
    pub points_not_finite: usize,
    /// Per section, in order.
    pub sections: Vec<SectionReport>,
}

/// Extracts road edges with the method of Qiu et al. (2016). Lines carry `method` = "qiu",
/// their side of the trajectory, the median height step across them and, from it, a
/// category (`curb` at 50 mm or more, `curb_cut` from 10 mm).
pub fn extract_edges(points: &QiuInput, params: &QiuParams) -> Vec<EdgeLine> {
    extract_edges_with_report(points, params).0
}

/// [`extract_edges`] with a report of every section. Invalid parameters give no lines
/// (check them first with [`QiuParams::validate`]).
pub fn extract_edges_with_report(
    input: &QiuInput,
    params: &QiuParams,
) -> (Vec<EdgeLine>, QiuReport) {
    let n = input
        .x
        .len()
        .min(input.y.len())
        .min(input.z.len())
        .min(input.t.len());
    let mut report = QiuReport {
        points_total: n,
        ..Default::default()
    };
    if params.validate().is_err() {
        return (Vec::new(), report);
    }
    // Points ordered by GPS time, so a section's points are one slice (§3.1).
    let mut order: Vec<usize> = (0..n)
        .filter(|&i| {
            input.x[i].is_finite()
                && input.y[i].is_finite()
                && input.z[i].is_finite()
                && input.t[i].is_finite()
        })
        .collect();
    report.points_not_finite = n - order.len();
    if !order.windows(2).all(|w| input.t[w[0]] <= input.t[w[1]]) {
        order.par_sort_by(|&a, &b| input.t[a].total_cmp(&input.t[b]).then(a.cmp(&b)));
    }
    let times: Vec<f64> = order.iter().map(|&i| input.t[i]).collect();
    let st = stations(input.trajectory);
    let sections = plan_sections(input.trajectory, params);
    let results: Vec<(Vec<Chain>, SectionReport)> = sections
        .par_iter()
        .map(|sec| process_section(input, &order, &times, &st, sec, params))
        .collect();
    let mut pieces = Vec::new();
    for (chains, rep) in results {
        pieces.extend(chains);
        report.sections.push(rep);
    }
    // The joined chains again: a join across sections must not bring back an obstacle.
    let mut chains = refine::join_chains(pieces, params);
    chains.retain(|c| is_edge_step(c, params));
    let chains = refine::keep_longest(chains, params);
    let lines = chains
        .into_iter()
        .map(|c| {
            let curb_height_m = refine::median_step(&c);
            let category = curb_height_m.and_then(|h| {
                if h >= 0.05 {
                    Some(Category::Curb)
                } else if h >= 0.01 {
                    Some(Category::CurbCut)
                } else {
                    None
                }
            });
            EdgeLine {
                points: c.pts,
                side: c.side,
                category,
                method: Some("qiu".into()),
                curb_height_m,
                detail: None,
            }
        })
        .collect();
    (lines, report)
}

/// A road edge has ground on both sides and a step between `min_step_m` and `max_step_m`,
/// has ground on its raised side over more than `1 − NO_GROUND_SHARE_MAX` of its length,
/// and is no wall joined to a curb: a chain whose measured part steps above `max_step_m`
/// over `WALL_SHARE_MAX` of its measured length, or that is mostly unmeasured and steps
/// above `max_step_m` anywhere, is a wall with a little curb (or ground) at its foot.
fn is_edge_step(c: &Chain, params: &QiuParams) -> bool {
    let in_range = refine::median_step(c)
        .is_some_and(|h| (params.min_step_m..=params.max_step_m).contains(&h));
    let (measured, wall) = refine::measured_and_wall_shares(c, params.max_step_m);
    let walled = wall > WALL_SHARE_MAX * measured || (measured < 0.5 && wall > 0.0);
    in_range && !walled && refine::no_ground_share(c) < NO_GROUND_SHARE_MAX
}

/// Share of a line's length with no ground on its raised side (see
/// [`HeightGrid::measure_steps`]) from which it is no road edge: the border of the returns
/// (a shadow's edge, the first or last scan lines) has none along nearly all of it.
const NO_GROUND_SHARE_MAX: f64 = 0.5;

/// Most share of a road edge's measured length whose step may be wall-sized: the corner
/// of a curb at a building front picks up a few wall-height steps.
const WALL_SHARE_MAX: f64 = 0.25;

/// Most distance between the vertices at which a line's height step is measured, metres:
/// the line fit leaves long straight stretches with a vertex at either end only. Lines
/// across the trajectory too: a border of the returns across it (behind a side street's
/// curb) is otherwise measured at its two ends only, where it meets the curb's returns.
const STEP_SAMPLE_M: f64 = 1.0;

/// Seconds of trajectory added before and after a section for nearest-trajectory-point
/// queries, so points seen ahead of or behind the vehicle still find their foot point.
const TRACK_PAD_S: f64 = 5.0;

fn process_section(
    input: &QiuInput,
    order: &[usize],
    times: &[f64],
    st: &[f64],
    sec: &Section,
    params: &QiuParams,
) -> (Vec<Chain>, SectionReport) {
    let mut rep = SectionReport {
        section: Some(*sec),
        ..Default::default()
    };
    let traj = input.trajectory;
    let Some(origin) = traj.pose_at(sec.t_start) else {
        return (Vec::new(), rep);
    };
    let o = [origin.x, origin.y, origin.z];
    let mut clock = std::time::Instant::now();
    let mut lap = |k: usize, rep: &mut SectionReport| {
        rep.stage_s[k] = clock.elapsed().as_secs_f64();
        clock = std::time::Instant::now();
    };
    // §3.1: the section's GPS time interval, then its width across the trajectory.
    let lo = times.partition_point(|&t| t < sec.t_start);
    let hi = times.partition_point(|&t| t <= sec.t_end);
    let half_w = 0.5 * params.section_width_m;
    let raw: Vec<[f64; 3]> = order[lo..hi]
        .par_iter()
        .filter_map(|&i| {
            let q = traj.pose_at(input.t[i])?;
            let l = q.left();
            let d = (input.x[i] - q.x) * l[0] + (input.y[i] - q.y) * l[1];
            (d.abs() <= half_w).then(|| [input.x[i] - o[0], input.y[i] - o[1], input.z[i] - o[2]])
        })
        .collect();
    rep.points_in = raw.len();
    lap(0, &mut rep);
    // §3.2.
    let pts = if params.sor_after_voxel {
        let v = preprocess::voxel_downsample(&raw, params.voxel_m);
        preprocess::statistical_outlier_removal(
            &v,
            params.sor_k,
            params.sor_std_mul,
            2.0 * params.voxel_m,
        )
    } else {
        let s = preprocess::statistical_outlier_removal(
            &raw,
            params.sor_k,
            params.sor_std_mul,
            2.0 * params.voxel_m,
        );
        preprocess::voxel_downsample(&s, params.voxel_m)
    };
    drop(raw);
    rep.points_preprocessed = pts.len();
    lap(1, &mut rep);
    // §3.3.1.
    let norm = normalise::normalise_to_grid_min(&pts, params.grid_cell_m);
    let pts_norm: Vec<[f64; 3]> = pts
        .iter()
        .zip(&norm.z_norm)
        .map(|(p, &z)| [p[0], p[1], z])
        .collect();
    lap(2, &mut rep);
    // §3.3.2.
    let track = SectionTrack::new(traj, st, sec.t_start - TRACK_PAD_S, sec.t_end + TRACK_PAD_S);
    let locate = |i: usize| track.locate(pts[i][0] + o[0], pts[i][1] + o[1]);
    let z_abs: Vec<f64> = pts.iter().map(|p| p[2]).collect();
    let seg = segment::rough_segmentation(
        &pts_norm,
        &z_abs,
        params.alpha_m,
        &params.betas_m,
        params.ransac_iterations,
        params.ransac_max_tilt_deg,
        params.neighbour_radius_m,
        params.min_rise_beta,
        params.min_candidates,
        params.energy_tolerance,
        params.energy_slack_m,
        params.noise_count_ratio,
        [params.low_beta_corridor_m, params.low_beta_window_m],
        params.seed ^ (sec.index as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15),
        &|i| locate(i).map(|p| (p.s, p.d)),
    );
    rep.beta_m = seg.beta_m;
    rep.energies = seg.energies.clone();
    rep.candidates = seg.candidates.len();
    lap(3, &mut rep);
    let edge_pts: Vec<EdgePoint> = seg
        .candidates
        .iter()
        .filter_map(|&i| {
            let tp = locate(i)?;
            Some(EdgePoint {
                p: [pts[i][0] + o[0], pts[i][1] + o[1], norm.ground_z[i] + o[2]],
                s: tp.s,
                d: tp.d,
                foot: tp.foot,
            })
        })
        .collect();
    // §3.4.
    let width = refine::refine_by_width(&edge_pts, params);
    rep.road_width_m = width.road_width_m;
    rep.width_kept = width.kept.len();
    let mut kept_flag = vec![false; edge_pts.len()];
    for &i in &width.kept {
        kept_flag[i] = true;
    }
    rep.candidate_points = edge_pts
        .iter()
        .zip(kept_flag)
        .map(|(e, k)| (e.p, k))
        .collect();
    let mut chains = refine::refine_by_continuity(&edge_pts, &width.kept, params);
    let grid = HeightGrid::new(&pts, o);
    for c in &mut chains {
        *c = refine::densify(c, STEP_SAMPLE_M);
        let unmeasured = c.across.then(|| c.clone());
        grid.measure_steps(c, params.height_band_m);
        if let Some(mut r) = unmeasured {
            // A line across the trajectory is ordered by offset; which of its sides is the
            // road is not known from that: the one the other side stands above.
            r.pts.reverse();
            r.s.reverse();
            grid.measure_steps(&mut r, params.height_band_m);
            let step = |c: &Chain| refine::median_step(c).unwrap_or(f64::NEG_INFINITY);
            if step(&r) > step(c) {
                *c = r;
            }
        }
    }
    // Ground on both sides (see `QiuParams::min_step_m`), then §3.4.2 step 4.
    chains.retain(|c| is_edge_step(c, params));
    let chains = refine::bridge_gaps(chains, params, STEP_SAMPLE_M, &|c| {
        grid.measure_steps(c, params.height_band_m)
    });
    let chains = refine::keep_longest(chains, params);
    rep.chains = chains.len();
    let clipped: Vec<Chain> = chains
        .iter()
        .flat_map(|c| refine::clip_to_stations(c, sec.core_start, sec.core_end))
        .collect();
    lap(4, &mut rep);
    (clipped, rep)
}

/// The section's pre-processed points on a 2D grid, for the height step across a line.
struct HeightGrid<'a> {
    pts: &'a [[f64; 3]],
    origin: [f64; 3],
    cells: HashMap<(i64, i64), Vec<u32>>,
}

const HEIGHT_CELL_M: f64 = 0.5;

/// Either band of a measured height step holds at least 1/this of the other band's
/// points: both bands are as large and as far from the scanner within 0.75 m, and the
/// raised side of a curb is seen at least as densely as the road before it.
const BAND_SHARE_MIN_INV: usize = 10;

impl<'a> HeightGrid<'a> {
    fn new(pts: &'a [[f64; 3]], origin: [f64; 3]) -> Self {
        let mut cells: HashMap<(i64, i64), Vec<u32>> = HashMap::new();
        for (i, p) in pts.iter().enumerate() {
            let k = (
                (p[0] / HEIGHT_CELL_M).floor() as i64,
                (p[1] / HEIGHT_CELL_M).floor() as i64,
            );
            cells.entry(k).or_default().push(i as u32);
        }
        Self { pts, origin, cells }
    }

    /// For every vertex: the median z of points `band` metres outward (away from the
    /// trajectory) minus the median z of points as far inward, within half a metre along
    /// the line. The vertex z becomes the inward (road) median: the toe's height. A band
    /// holds ground when it has 3 points or more and at least 1/[`BAND_SHARE_MIN_INV`] of
    /// the other band's; it is bare when it has fewer than 1/[`BAND_SHARE_MIN_INV`] of the
    /// other band's and that band has 3 or more. Where the outward band is bare, the step
    /// is [`refine::NO_GROUND`]: a line along the border of the returns (a shadow's edge,
    /// the first or last scan lines) has only a few stray points beyond it, which would
    /// measure a step that is not there. (A sparse inward band is measured: the road beside
    /// a near curb lies partly in the vehicle's shadow.) A band with too few points to
    /// measure that is not bare leaves the step unknown: where both bands are sparse (a
    /// side street's curb far from the scanner) one or two points on the raised side are
    /// as many as the road side's density allows. A line across the trajectory, whose road
    /// side is not known, is measured where both bands hold ground and has no ground where
    /// either band is bare.
    fn measure_steps(&self, c: &mut Chain, band: [f64; 2]) {
        let n = c.pts.len();
        for k in 0..n {
            let (a, b) = (c.pts[k.saturating_sub(1)], c.pts[(k + 1).min(n - 1)]);
            let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
            let len = dx.hypot(dy);
            if len < 1e-9 {
                continue;
            }
            let u = [dx / len, dy / len];
            // Left of the driving direction is (−u_y, u_x); outward is left on the left.
            let sgn = if c.side == Side::Left { 1.0 } else { -1.0 };
            let nout = [-u[1] * sgn, u[0] * sgn];
            let q = [c.pts[k][0] - self.origin[0], c.pts[k][1] - self.origin[1]];
            let r = band[1] + 0.5;
            let (kx0, kx1) = (
                ((q[0] - r) / HEIGHT_CELL_M).floor() as i64,
                ((q[0] + r) / HEIGHT_CELL_M).floor() as i64,
            );
            let (ky0, ky1) = (
                ((q[1] - r) / HEIGHT_CELL_M).floor() as i64,
                ((q[1] + r) / HEIGHT_CELL_M).floor() as i64,
            );
            let (mut outer, mut inner) = (Vec::new(), Vec::new());
            for kx in kx0..=kx1 {
                for ky in ky0..=ky1 {
                    for &i in self.cells.get(&(kx, ky)).map(Vec::as_slice).unwrap_or(&[]) {
                        let p = self.pts[i as usize];
                        let (px, py) = (p[0] - q[0], p[1] - q[1]);
                        if (px * u[0] + py * u[1]).abs() > 0.5 {
                            continue;
                        }
                        let across = px * nout[0] + py * nout[1];
                        if (band[0]..=band[1]).contains(&across) {
                            outer.push(p[2]);
                        } else if (band[0]..=band[1]).contains(&-across) {
                            inner.push(p[2]);
                        }
                    }
                }
            }
            let ground = |a: usize, b: usize| a >= 3 && a * BAND_SHARE_MIN_INV >= b;
            let bare = |a: usize, b: usize| b >= 3 && a * BAND_SHARE_MIN_INV < b;
            let (inner_ground, outer_ground) = (
                ground(inner.len(), outer.len()),
                ground(outer.len(), inner.len()),
            );
            if inner.len() >= 3 {
                inner.sort_unstable_by(f64::total_cmp);
                let zi = inner[inner.len() / 2];
                c.pts[k][2] = zi + self.origin[2];
                if outer_ground && (inner_ground || !c.across) {
                    outer.sort_unstable_by(f64::total_cmp);
                    c.h[k] = outer[outer.len() / 2] - zi;
                }
            }
            if bare(outer.len(), inner.len()) || (c.across && bare(inner.len(), outer.len())) {
                c.h[k] = refine::NO_GROUND;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::trajectory::Pose;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    const X0: f64 = 500_000.0;
    const Y0: f64 = 4_000_000.0;
    const T0: f64 = 4.0e8;

    /// A straight road along +x (driving east, left = +y), 10 m wide between curb toes at
    /// y = ±5, 150 mm curbs with vertical faces, 3 m sidewalks, and 1 m walls at their
    /// back (y = ±8), over x ∈ [0, `len`]; points on a 5 cm jittered grid with 3 mm height
    /// noise, a few isolated outliers; time = when the vehicle (10 m/s) passed x. The
    /// vehicle drives down the middle, 0.2 m left of it (so the toes do not fall exactly
    /// on the boundaries of the 0.5 m normalisation grid, which starts at the vehicle).
    fn synthetic_road(len: f64, seed: u64) -> (Vec<[f64; 4]>, Trajectory) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut pts = Vec::new();
        let step = 0.05;
        let nx = (len / step) as i64;
        let mut push = |rng: &mut ChaCha8Rng, x: f64, y: f64, z: f64| {
            let z = z + rng.gen_range(-0.003..0.003);
            pts.push([X0 + x, Y0 + y, 10.0 + z, T0 + x / 10.0]);
        };
        for ix in 0..=nx {
            for iy in -160..=160 {
                let x = ix as f64 * step + rng.gen_range(-0.01..0.01);
                let y = iy as f64 * step + rng.gen_range(-0.01..0.01);
                let z = if y.abs() < 5.0 { 0.0 } else { 0.15 };
                push(&mut rng, x, y, z);
            }
            let x = ix as f64 * step;
            for side in [-1.0, 1.0] {
                for k in 1..8 {
                    push(&mut rng, x, side * 5.0, k as f64 * 0.02);
                }
                for k in 1..20 {
                    push(&mut rng, x, side * 8.0, 0.15 + k as f64 * 0.05);
                }
            }
        }
        for k in 0..20 {
            push(&mut rng, k as f64 * 2.5, 0.0, 3.0);
        }
        let samples = (0..=((len + 10.0) * 10.0) as usize)
            .map(|k| {
                let x = -5.0 + k as f64 * 0.1;
                Pose {
                    t: T0 + x / 10.0,
                    x: X0 + x,
                    y: Y0 + 0.2,
                    z: 12.0,
                    roll_deg: 0.0,
                    pitch_deg: 0.0,
                    heading_deg: 90.0,
                }
            })
            .collect();
        (pts, Trajectory { samples })
    }

    fn seg_dist(p: [f64; 2], a: [f64; 3], b: [f64; 3]) -> f64 {
        let (ux, uy) = (b[0] - a[0], b[1] - a[1]);
        let l2 = ux * ux + uy * uy;
        let w = if l2 > 0.0 {
            (((p[0] - a[0]) * ux + (p[1] - a[1]) * uy) / l2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (p[0] - a[0] - w * ux).hypot(p[1] - a[1] - w * uy)
    }

    fn near_any(p: [f64; 2], lines: &[EdgeLine], buf: f64) -> bool {
        lines.iter().any(|l| {
            l.points.windows(2).any(|w| seg_dist(p, w[0], w[1]) <= buf)
                || (l.points.len() == 1 && seg_dist(p, l.points[0], l.points[0]) <= buf)
        })
    }

    #[test]
    fn finds_both_curbs_of_a_synthetic_road() {
        let len = 50.0;
        let (pts, traj) = synthetic_road(len, 11);
        let col = |k: usize| pts.iter().map(|p| p[k]).collect::<Vec<f64>>();
        let (x, y, z, t) = (col(0), col(1), col(2), col(3));
        let input = QiuInput {
            x: &x,
            y: &y,
            z: &z,
            t: &t,
            trajectory: &traj,
        };
        // 30 m sections with 10 m overlap over the 60 m drive: [0,30], [20,50], [40,60].
        let params = QiuParams {
            section_length_m: 30.0,
            section_overlap_m: 10.0,
            ..QiuParams::default()
        };
        let (lines, rep) = extract_edges_with_report(&input, &params);
        assert_eq!(rep.sections.len(), 3);
        for s in &rep.sections {
            // The curb face is 150 mm: any β up to 0.08 m leaves part of it outside.
            assert!(s.beta_m.iter().all(Option::is_some), "{s:?}");
            // Curb to curb: 10 m (bin [10.0, 10.1)).
            assert!((s.road_width_m.unwrap() - 10.05).abs() < 0.11, "{s:?}");
        }
        // Score: reference samples every 0.1 m on y = ±5 within 0.2 m of an output line.
        for side in [Side::Left, Side::Right] {
            let y_ref = if side == Side::Left {
                Y0 + 5.0
            } else {
                Y0 - 5.0
            };
            let mine: Vec<EdgeLine> = lines.iter().filter(|l| l.side == side).cloned().collect();
            let n = (len * 10.0) as usize;
            let hit = (0..=n)
                .filter(|&k| near_any([X0 + k as f64 * 0.1, y_ref], &mine, 0.2))
                .count();
            let completeness = hit as f64 / (n + 1) as f64;
            assert!(
                completeness >= 0.85,
                "{side:?}: completeness {completeness}"
            );
            // Correctness: output vertices within 0.2 m of the reference line.
            let verts: Vec<&[f64; 3]> = mine.iter().flat_map(|l| l.points.iter()).collect();
            let ok = verts.iter().filter(|p| (p[1] - y_ref).abs() <= 0.2).count();
            assert!(
                ok as f64 >= 0.9 * verts.len() as f64,
                "{side:?}: {ok}/{}",
                verts.len()
            );
        }
        for l in &lines {
            assert_eq!(l.method.as_deref(), Some("qiu"));
            let h = l.curb_height_m.unwrap();
            assert!((h - 0.15).abs() < 0.03, "height {h}");
            assert_eq!(l.category, Some(Category::Curb));
            // z is the road surface at the toe (10 m ± noise).
            assert!(
                l.points.iter().all(|p| (p[2] - 10.0).abs() < 0.02),
                "{:?}",
                l.points
            );
        }
        // The same result with one thread and with many.
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let again = one.install(|| extract_edges(&input, &params));
        assert_eq!(again, lines);
    }

    /// The steps `measure_steps` gives a two-vertex chain along x (at 0.5 and 1.5 m, its
    /// road side at negative y) on a grid of `pts`.
    fn measure(pts: &[[f64; 3]], across: bool) -> Vec<f64> {
        let grid = HeightGrid::new(pts, [0.0; 3]);
        let mut c = Chain {
            side: Side::Left,
            pts: vec![[0.5, 0.0, 0.0], [1.5, 0.0, 0.0]],
            s: vec![0.5, 1.5],
            h: vec![f64::NAN; 2],
            across,
        };
        grid.measure_steps(&mut c, [0.15, 0.6]);
        c.h
    }

    /// The height step of a line with ground on both sides is measured; a line along the
    /// border of the returns (nothing on its raised side but a few stray points) has no
    /// ground there. A sparse road side is measured along the trajectory (the vehicle's
    /// shadow beside a near curb), not across it, where either side may be the road.
    #[test]
    fn a_step_needs_ground_on_its_raised_side() {
        let mut pts = Vec::new();
        for ix in 0..=40 {
            for iy in -20..=20 {
                let (x, y) = (ix as f64 * 0.05, iy as f64 * 0.05);
                if y < 0.0 {
                    pts.push([x, y, 0.0]);
                } else if y > 0.0 {
                    pts.push([x, y, 0.15]);
                }
            }
        }
        for across in [false, true] {
            for h in measure(&pts, across) {
                assert!((h - 0.15).abs() < 1e-9, "{h}");
            }
        }
        // One side gone but for a few stray points 30 mm up on every metre.
        let sparse = |raised_gone: bool| {
            let mut v: Vec<[f64; 3]> = pts
                .iter()
                .copied()
                .filter(|p| (p[1] < 0.0) == raised_gone)
                .collect();
            let stray_y = if raised_gone { 0.3 } else { -0.3 };
            for k in 0..8 {
                v.push([k as f64 * 0.25, stray_y, 0.03]);
            }
            v
        };
        let no_ground = |h: Vec<f64>| h.iter().all(|&h| h == refine::NO_GROUND);
        assert!(no_ground(measure(&sparse(true), false)));
        assert!(no_ground(measure(&sparse(true), true)));
        assert!(no_ground(measure(&sparse(false), true)));
        for h in measure(&sparse(false), false) {
            assert!((h - 0.12).abs() < 1e-9, "{h}");
        }
    }

    /// Where both bands are sparse, one point on the raised side against ten on the road
    /// side leaves the step unknown (a far curb's sidewalk, not the border of the returns);
    /// none against ten is the border.
    #[test]
    fn a_sparse_raised_side_is_unknown_and_an_empty_one_bare() {
        let mut pts = Vec::new();
        for ix in 0..=8 {
            for y in [-0.5, -0.25] {
                pts.push([ix as f64 * 0.25, y, 0.0]);
            }
        }
        let mut sparse = pts.clone();
        sparse.push([0.4, 0.3, 0.15]);
        sparse.push([1.6, 0.3, 0.15]);
        for across in [false, true] {
            assert!(measure(&sparse, across).iter().all(|h| h.is_nan()));
            let bare = measure(&pts, across);
            assert!(bare.iter().all(|&h| h == refine::NO_GROUND), "{bare:?}");
        }
    }

    #[test]
    fn no_points_or_no_trajectory_gives_no_lines() {
        let traj = Trajectory::default();
        let input = QiuInput {
            x: &[],
            y: &[],
            z: &[],
            t: &[],
            trajectory: &traj,
        };
        assert!(extract_edges(&input, &QiuParams::default()).is_empty());
        let (_, traj) = synthetic_road(5.0, 1);
        let input = QiuInput {
            trajectory: &traj,
            ..input
        };
        assert!(extract_edges(&input, &QiuParams::default()).is_empty());
    }

    /// The whole `--method qiu` path from files, as `curbtrace extract` runs it: the `tiny`
    /// scene written as LAZ (1 mm quantised, UTM-sized coordinates, GPS times near 4e8 s)
    /// with its trajectory CSV, read back, extracted and scored against its reference at
    /// the paper's 200 mm buffer (measured: 99.4 % / 99.2 %).
    #[test]
    fn tiny_scene_through_laz_file_reaches_the_targets() {
        use crate::config::Config;
        use crate::eval::{evaluate, EvalParams};
        use crate::pipeline::{extract_file_with, ExtractOptions, Method, Progress};
        let dir = tempfile::tempdir().unwrap();
        let spec = crate::simulate::scene_by_name("tiny").unwrap();
        crate::simulate::run(&spec, 1, None, dir.path(), false).unwrap();
        let opts = ExtractOptions {
            method: Method::Qiu,
            ..ExtractOptions::default()
        };
        let r = extract_file_with(
            &dir.path().join("points.laz"),
            &dir.path().join("trajectory.csv"),
            &Config::default(),
            &opts,
            &Progress::hidden(),
        )
        .unwrap();
        assert!(r.edges.iter().all(|e| e.method.as_deref() == Some("qiu")));
        let (reference, _) =
            crate::model::read_geojson(&dir.path().join("reference.geojson")).unwrap();
        let ev = evaluate(
            &reference,
            &r.edges,
            &EvalParams {
                buffer_m: 0.2,
                ..EvalParams::default()
            },
        )
        .unwrap();
        let c = ev.total.completeness_pct.unwrap();
        let p = ev.total.correctness_pct.unwrap();
        assert!(
            c >= 95.0 && p >= 95.0,
            "completeness {c} %, correctness {p} %"
        );
    }

    /// A 10 m curb cut with a 30 mm lip in a 150 mm curb, on a road with 9 mm of height
    /// noise, where the chosen β is 0.03 m or more (the lip at the edge of its reach) and
    /// the cut is longer than the joins bridge (`join_gap_m`): with the smaller βs'
    /// candidates along the curb's line (`low_beta_corridor_m`) joined in, the cut is
    /// still one line over 90 % of its length. (The lip's noise reaches β = 0.03 m here,
    /// so the cut is found without them too; `segment`'s
    /// `smaller_betas_join_along_the_chosen_line_across_a_cut` holds the rule itself.)
    #[test]
    fn a_long_low_lip_cut_in_a_noisy_scan_is_found() {
        let len = 40.0;
        let (mut pts, traj) = synthetic_road(len, 5);
        let mut rng = ChaCha8Rng::seed_from_u64(17);
        for p in &mut pts {
            let g: f64 = (0..3).map(|_| rng.gen_range(-0.009..0.009)).sum();
            p[2] += g;
            let (x, y) = (p[0] - X0, p[1] - Y0);
            if (15.0..25.0).contains(&x) && y > 5.0 - 0.02 && y < 7.9 {
                p[2] = p[2].min(10.03 + g);
            }
        }
        let col = |k: usize| pts.iter().map(|p| p[k]).collect::<Vec<f64>>();
        let (x, y, z, t) = (col(0), col(1), col(2), col(3));
        let input = QiuInput {
            x: &x,
            y: &y,
            z: &z,
            t: &t,
            trajectory: &traj,
        };
        let cut_found = |params: &QiuParams| {
            let (lines, rep) = extract_edges_with_report(&input, params);
            let beta = rep.sections[0].beta_m[0].unwrap();
            let left: Vec<EdgeLine> = lines
                .iter()
                .filter(|l| l.side == Side::Left)
                .cloned()
                .collect();
            let hit = (0..=100)
                .filter(|&k| near_any([X0 + 15.0 + k as f64 * 0.1, Y0 + 5.0], &left, 0.2))
                .count();
            (beta, hit as f64 / 101.0)
        };
        let (beta, with) = cut_found(&QiuParams::default());
        assert!(
            beta >= 0.03,
            "β {beta}: the lip is within the chosen β's reach"
        );
        assert!(with >= 0.9, "cut found over {with}");
    }

    /// The regression behind sapporo's 39 % (file path) against 72 % (in memory): not the
    /// file, but the choice among the refined planes. With the plain variance as E_s, a
    /// different RANSAC draw (a new seed, or 1 mm quantisation of the same points) could let
    /// road noise (β = 0.01 m, below the range noise) win a whole section. Here the road has
    /// range-like noise (σ ≈ 5 mm, so β = 0.01 m leaves noise outliers all over it) and a
    /// curb cut on the left; every seed must choose a β that sees the curb, not the noise,
    /// and find both curbs.
    #[test]
    fn the_choice_of_beta_does_not_depend_on_the_ransac_draw() {
        let len = 40.0;
        let (mut pts, traj) = synthetic_road(len, 3);
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        for p in &mut pts {
            // Roughly Gaussian (sum of three uniforms), σ ≈ 5 mm, on top of the 3 mm jitter.
            let g: f64 = (0..3).map(|_| rng.gen_range(-0.0087..0.0087)).sum();
            p[2] += g;
            // A curb cut: the left curb lowered to 25 mm over x ∈ [15, 19].
            let (x, y) = (p[0] - X0, p[1] - Y0);
            if (15.0..19.0).contains(&x) && y > 5.0 - 0.02 && y < 7.9 {
                p[2] = p[2].min(10.025 + g);
            }
        }
        let col = |k: usize| pts.iter().map(|p| p[k]).collect::<Vec<f64>>();
        let (x, y, z, t) = (col(0), col(1), col(2), col(3));
        let input = QiuInput {
            x: &x,
            y: &y,
            z: &z,
            t: &t,
            trajectory: &traj,
        };
        for seed in [1, 2, 3, 2016] {
            let params = QiuParams {
                seed,
                ..QiuParams::default()
            };
            let (lines, rep) = extract_edges_with_report(&input, &params);
            assert_eq!(rep.sections.len(), 1);
            let s = &rep.sections[0];
            for b in s.beta_m {
                let b = b.unwrap();
                assert!(
                    (0.015..0.1).contains(&b),
                    "seed {seed}: β {b}: {:?}",
                    s.energies
                );
            }
            // β = 0.01 m is noise: its spread (√E_s) is beyond the slack above the chosen
            // one's (measured 17 and 31 mm against 0).
            for side in 0..2 {
                let e = |k: usize| {
                    let r = &s.energies[k];
                    if side == 0 {
                        r.2.unwrap()
                    } else {
                        r.3.unwrap()
                    }
                };
                let k = s
                    .energies
                    .iter()
                    .position(|r| Some(r.0) == s.beta_m[side])
                    .unwrap();
                assert!(
                    e(0).sqrt() > e(k).sqrt() + params.energy_slack_m,
                    "side {side}: {:?}",
                    s.energies
                );
            }
            for side in [Side::Left, Side::Right] {
                let y_ref = Y0 + if side == Side::Left { 5.0 } else { -5.0 };
                let mine: Vec<EdgeLine> =
                    lines.iter().filter(|l| l.side == side).cloned().collect();
                let n = (len * 10.0) as usize;
                let hit = (0..=n)
                    .filter(|&k| near_any([X0 + k as f64 * 0.1, y_ref], &mine, 0.2))
                    .count();
                assert!(
                    hit as f64 >= 0.85 * (n + 1) as f64,
                    "seed {seed} {side:?}: {hit} of {}",
                    n + 1
                );
            }
        }
    }
}
