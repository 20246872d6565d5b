//! §3.3.2 Rough segmentation: a RANSAC rough plane Π₀ with threshold α (Eq. 1), refined
//! planes Π_i from its inliers with thresholds β_i, candidate road-edge points (outliers of
//! a refined plane with an inlier close by), and the choice among the candidate sets by the
//! smoothness energy E_s (Eq. 2).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::HashMap;

/// A plane n·p + c = 0 with |n| = 1 and n_z ≥ 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    /// Unit normal, pointing up.
    pub n: [f64; 3],
    /// Offset.
    pub c: f64,
}

impl Plane {
    /// Plane through three points, `None` when they are (nearly) collinear.
    pub fn through(a: &[f64; 3], b: &[f64; 3], c: &[f64; 3]) -> Option<Self> {
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let mut n = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        if len.is_nan() || len <= 1e-12 {
            return None;
        }
        let s = if n[2] < 0.0 { -1.0 } else { 1.0 } / len;
        n = [n[0] * s, n[1] * s, n[2] * s];
        Some(Self {
            n,
            c: -(n[0] * a[0] + n[1] * a[1] + n[2] * a[2]),
        })
    }

    /// Unsigned distance of a point (Eq. 1's D_i).
    pub fn distance(&self, p: &[f64; 3]) -> f64 {
        (self.n[0] * p[0] + self.n[1] * p[1] + self.n[2] * p[2] + self.c).abs()
    }
}

/// Hypotheses are scored on at most this many points (an even stride through the set);
/// the winner's inliers are then taken from all points. A section holds a few hundred
/// thousand points; a plane holding most of them is found as surely from 20 000, at a
/// tenth of the cost.
const RANSAC_SCORE_POINTS: usize = 20_000;

/// RANSAC plane (Fischler & Bolles) over `pts[idx]`: the plane through three random points
/// with the most points within `threshold`, among planes tilted at most `max_tilt_deg`.
/// Returns the plane and the indices (into `pts`) of its inliers, in `idx` order; `None`
/// with fewer than 3 points or no admissible plane.
pub fn ransac_plane(
    pts: &[[f64; 3]],
    idx: &[usize],
    threshold: f64,
    iterations: usize,
    max_tilt_deg: f64,
    rng: &mut ChaCha8Rng,
) -> Option<(Plane, Vec<usize>)> {
    if idx.len() < 3 {
        return None;
    }
    let min_nz = max_tilt_deg.to_radians().cos();
    let stride = idx.len().div_ceil(RANSAC_SCORE_POINTS);
    let mut best: Option<(Plane, usize)> = None;
    for _ in 0..iterations {
        let a = idx[rng.gen_range(0..idx.len())];
        let b = idx[rng.gen_range(0..idx.len())];
        let c = idx[rng.gen_range(0..idx.len())];
        let Some(plane) = Plane::through(&pts[a], &pts[b], &pts[c]) else {
            continue;
        };
        if plane.n[2] < min_nz {
            continue;
        }
        let count = idx
            .iter()
            .step_by(stride)
            .filter(|&&i| plane.distance(&pts[i]) < threshold)
            .count();
        if best.is_none_or(|(_, n)| count > n) {
            best = Some((plane, count));
        }
    }
    let (plane, _) = best?;
    let inliers = idx
        .iter()
        .copied()
        .filter(|&i| plane.distance(&pts[i]) < threshold)
        .collect();
    Some((plane, inliers))
}

/// "We search inliers near an outlier. If there exist an inlier, then the outlier is
/// considered to be a road edge point" (§3.3.2): of the points `rough` (the rough plane),
/// those not in the refined plane (`is_refined[i] == false`) with a refined-plane point
/// within `radius` (3D) that lies at least `min_rise` metres lower in the *un-normalised*
/// heights `z_abs` (0 gives the paper's plain rule). Returns indices into `pts`, in `rough`
/// order.
///
/// Why the rise: the grid minimum of §3.3.1 sets every cell that lies wholly on a sidewalk
/// to height 0, so sidewalk points there become refined-plane inliers, and the curb top in
/// the neighbouring cell (which holds the toe, and so the road's minimum) becomes an outlier
/// next to them — a false candidate up to one cell (0.5 m) behind the toe. An edge stands
/// *above* the pavement beside it; those points are level with their neighbour.
pub fn candidate_edge_points(
    pts: &[[f64; 3]],
    z_abs: &[f64],
    rough: &[usize],
    is_refined: &[bool],
    radius: f64,
    min_rise: f64,
) -> Vec<usize> {
    candidates_on_grid(
        &RoughGrid::new(pts, rough, radius),
        z_abs,
        rough,
        is_refined,
        min_rise,
    )
}

/// The rough plane's points hashed on cubes of the search radius, built once per section
/// and shared by all refined planes.
pub struct RoughGrid<'a> {
    pts: &'a [[f64; 3]],
    radius: f64,
    cells: HashMap<[i64; 3], Vec<usize>>,
}

impl<'a> RoughGrid<'a> {
    /// Hashes `pts[rough]` on cubes of `radius`.
    pub fn new(pts: &'a [[f64; 3]], rough: &[usize], radius: f64) -> Self {
        let mut cells: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
        for &i in rough {
            cells.entry(Self::key(&pts[i], radius)).or_default().push(i);
        }
        Self { pts, radius, cells }
    }

    fn key(p: &[f64; 3], radius: f64) -> [i64; 3] {
        [
            (p[0] / radius).floor() as i64,
            (p[1] / radius).floor() as i64,
            (p[2] / radius).floor() as i64,
        ]
    }
}

/// [`candidate_edge_points`] on a prebuilt grid.
pub fn candidates_on_grid(
    grid: &RoughGrid,
    z_abs: &[f64],
    rough: &[usize],
    is_refined: &[bool],
    min_rise: f64,
) -> Vec<usize> {
    let (pts, radius) = (grid.pts, grid.radius);
    let key = |p: &[f64; 3]| RoughGrid::key(p, radius);
    let r2 = radius * radius;
    rough
        .iter()
        .copied()
        .filter(|&i| !is_refined[i])
        .filter(|&i| {
            let p = &pts[i];
            let k = key(p);
            for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        if let Some(cell) = grid.cells.get(&[k[0] + dx, k[1] + dy, k[2] + dz]) {
                            if cell.iter().any(|&j| {
                                is_refined[j] && z_abs[i] - z_abs[j] >= min_rise && {
                                    let q = &pts[j];
                                    (q[0] - p[0]).powi(2)
                                        + (q[1] - p[1]).powi(2)
                                        + (q[2] - p[2]).powi(2)
                                        <= r2
                                }
                            }) {
                                return true;
                            }
                        }
                    }
                }
            }
            false
        })
        .collect()
}

/// Station bin over which the innermost candidate is taken for E_s, metres.
const ENERGY_BIN_M: f64 = 0.5;

/// The smoothness energy E_s of Eq. 2 per side (left, right): the variance of the distance
/// d(e_i, t_i) from candidate points to their nearest trajectory points. `pos` holds
/// (station, signed offset) per candidate. The paper leaves three readings open; they are
/// fixed here so that the energy ranks a clean edge line above road noise *reliably*:
///
/// - per side: one variance over both sides would mostly measure how far the trajectory is
///   from the road's middle (and the two sides may need different β);
/// - of the *innermost* candidate's distance per 0.5 m of station (the point Eq. 3 pairs as
///   well): over all candidates a curb with a wall behind it scores worse than the wall
///   alone (a two-valued mixture has a larger variance than either value);
/// - the variance *around the line's own course*, estimated robustly as half the median
///   squared difference between consecutive stations (von Neumann's successive-difference
///   estimator with a median). The plain variance about the mean was tried first and is
///   unstable: a clean curb interrupted by curb cuts, an intersection or a widening road
///   jumps between two or three offsets and scores 1–13 m², while road noise (β below the
///   range noise) makes the innermost point hover near the vehicle and can score less —
///   it did so on one of three RANSAC seeds on `sapporo`, and that one choice took
///   completeness at 200 mm from 68 % to 39 %. Successive differences ignore a few jumps
///   and a slow widening; noise jumps at every station.
///
/// A side's energy is `None` with fewer than 3 stations holding candidates.
pub fn smoothness_energy(pos: &[(f64, f64)]) -> [Option<f64>; 2] {
    let mut inner: [std::collections::BTreeMap<i64, f64>; 2] = Default::default();
    for &(s, d) in pos {
        let side = usize::from(d < 0.0);
        let e = inner[side]
            .entry((s / ENERGY_BIN_M).floor() as i64)
            .or_insert(f64::INFINITY);
        *e = e.min(d.abs());
    }
    inner.map(|m| {
        let v: Vec<f64> = m.values().copied().collect();
        if v.len() < 3 {
            return None;
        }
        let mut d2: Vec<f64> = v.windows(2).map(|w| (w[1] - w[0]).powi(2)).collect();
        let mid = d2.len() / 2;
        let (_, m, _) = d2.select_nth_unstable_by(mid, f64::total_cmp);
        Some(0.5 * *m)
    })
}

/// The outcome of the rough segmentation of one section.
#[derive(Clone, Debug, Default)]
pub struct Segmentation {
    /// Indices of the chosen candidate edge points (both sides).
    pub candidates: Vec<usize>,
    /// The β of the chosen set per side (left, right), metres (`None` when no set
    /// qualified).
    pub beta_m: [Option<f64>; 2],
    /// (β, number of candidates, E_s left, E_s right) for every refined plane, for reports
    /// and tests.
    pub energies: Vec<(f64, usize, Option<f64>, Option<f64>)>,
}

/// §3.3.2 as a whole on normalised points (`pts` with z replaced by height above the grid
/// minimum; `z_abs` the heights before normalisation, see [`candidate_edge_points`] with
/// `min_rise` = `min_rise_beta`·β). `position_of(i)` gives the station and signed offset of point `i` relative to
/// its nearest trajectory point. Per side, among sets with at least `min_candidates` points
/// on that side, the smallest β whose E_s is within `energy_tolerance` (relative) of the
/// smallest E_s, or whose √E_s is within `energy_slack_m` of the smallest √E_s, wins (with
/// both 0, the set with the smallest E_s as in the paper; ties go to the smaller β, which
/// sees lower curbs). `low_beta` = [corridor, window] (metres; corridor 0: off): the
/// smaller βs' candidates (those within the noise too, in a narrower corridor: see
/// `SetChoice::choose`) join the chosen set where their offset is within the corridor of
/// the median of the chosen set's innermost offsets within the window along the
/// trajectory — a curb cut's low lip beside a curb.
#[allow(clippy::too_many_arguments)]
pub fn rough_segmentation(
    pts: &[[f64; 3]],
    z_abs: &[f64],
    alpha: f64,
    betas: &[f64],
    iterations: usize,
    max_tilt_deg: f64,
    radius: f64,
    min_rise_beta: f64,
    min_candidates: usize,
    energy_tolerance: f64,
    energy_slack_m: f64,
    noise_count_ratio: f64,
    low_beta: [f64; 2],
    seed: u64,
    position_of: &dyn Fn(usize) -> Option<(f64, f64)>,
) -> Segmentation {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let all: Vec<usize> = (0..pts.len()).collect();
    let Some((_, rough)) = ransac_plane(pts, &all, alpha, iterations, max_tilt_deg, &mut rng)
    else {
        return Segmentation::default();
    };
    let mut out = Segmentation::default();
    // Per side: (E_s, β, candidates of that side).
    let mut sets: [Vec<(f64, f64, Vec<usize>)>; 2] = Default::default();
    let grid = RoughGrid::new(pts, &rough, radius);
    let mut is_refined = vec![false; pts.len()];
    for &beta in betas {
        let Some((_, refined)) =
            ransac_plane(pts, &rough, beta, iterations, max_tilt_deg, &mut rng)
        else {
            out.energies.push((beta, 0, None, None));
            continue;
        };
        is_refined.iter_mut().for_each(|f| *f = false);
        for &i in &refined {
            is_refined[i] = true;
        }
        let cand = candidates_on_grid(&grid, z_abs, &rough, &is_refined, min_rise_beta * beta);
        let placed: Vec<(usize, (f64, f64))> = cand
            .iter()
            .filter_map(|&i| position_of(i).map(|p| (i, p)))
            .collect();
        let pos: Vec<(f64, f64)> = placed.iter().map(|x| x.1).collect();
        let e = smoothness_energy(&pos);
        out.energies.push((beta, cand.len(), e[0], e[1]));
        for side in 0..2 {
            let mine: Vec<usize> = placed
                .iter()
                .filter(|(_, p)| usize::from(p.1 < 0.0) == side)
                .map(|x| x.0)
                .collect();
            if let Some(e) = e[side] {
                if mine.len() >= min_candidates {
                    sets[side].push((e, beta, mine));
                }
            }
        }
    }
    let mut in_set = vec![false; pts.len()];
    for (side, mut sets) in sets.into_iter().enumerate() {
        sets.sort_by(|a, b| a.1.total_cmp(&b.1));
        let choice = SetChoice {
            energy_tolerance,
            energy_slack_m,
            noise_count_ratio,
            low_beta,
        };
        if let Some((beta, chosen)) = choice.choose(&sets, &mut in_set, position_of) {
            out.beta_m[side] = Some(beta);
            out.candidates.extend(chosen);
        }
    }
    out.candidates.sort_unstable();
    out
}

/// The corridor's half width for the candidates of βs within the noise, metres: a cut's lip
/// lies on the curb's toe line (within the 0.1 m neighbour radius), while the road's noise
/// and a lipless ramp's rise fill the whole corridor.
const NOISY_CORRIDOR_M: f64 = 0.1;

/// How one side's candidate set is chosen among the refined planes' sets (see
/// [`rough_segmentation`]).
struct SetChoice {
    energy_tolerance: f64,
    energy_slack_m: f64,
    noise_count_ratio: f64,
    low_beta: [f64; 2],
}

impl SetChoice {
    /// Of one side's sets (E_s, β, candidates), in β order: the chosen β and its candidates
    /// with the smaller βs' candidates along its innermost line, marked in `in_set`.
    ///
    /// The smallest βs lie within the noise while their candidate count is more than
    /// `noise_count_ratio` times the next larger β's (noise outliers fill the road, an edge's
    /// candidates thin out slowly with β): they are never chosen. They still feed the
    /// corridor along the chosen line, narrowed to [`NOISY_CORRIDOR_M`]: a curb cut's low
    /// lip is often an outlier of the smallest β only, and that close to the line its
    /// candidates outnumber the road's noise.
    fn choose(
        &self,
        sets: &[(f64, f64, Vec<usize>)],
        in_set: &mut [bool],
        position_of: &dyn Fn(usize) -> Option<(f64, f64)>,
    ) -> Option<(f64, Vec<usize>)> {
        let noisy = sets
            .windows(2)
            .take_while(|w| w[0].2.len() as f64 > self.noise_count_ratio * w[1].2.len() as f64)
            .count();
        let e_min = sets[noisy..].iter().map(|s| s.0).min_by(f64::total_cmp)?;
        let limit = (e_min * (1.0 + self.energy_tolerance))
            .max((e_min.sqrt() + self.energy_slack_m).powi(2));
        let k = (noisy..sets.len())
            .filter(|&k| sets[k].0 <= limit)
            .min_by(|&a, &b| sets[a].1.total_cmp(&sets[b].1))?;
        let mut chosen = sets[k].2.clone();
        for &i in &chosen {
            in_set[i] = true;
        }
        // The smaller βs' candidates along the chosen set's innermost line.
        let [corridor, window] = self.low_beta;
        if corridor > 0.0 && k > 0 {
            let line = innermost_line(&sets[k].2, position_of);
            for (j, set) in sets[..k].iter().enumerate() {
                let reach = if j < noisy {
                    corridor.min(NOISY_CORRIDOR_M)
                } else {
                    corridor
                };
                for &i in &set.2 {
                    if in_set[i] {
                        continue;
                    }
                    if position_of(i)
                        .is_some_and(|(s, d)| along_line(&line, s, d.abs(), reach, window))
                    {
                        in_set[i] = true;
                        chosen.push(i);
                    }
                }
            }
        }
        Some((sets[k].1, chosen))
    }
}

/// Whether a point at station `s` and offset `d` (absolute) lies within `corridor` of
/// the median offset of `line` (station, offset; in station order) over `window` of
/// station centred on `s`; `false` where the window holds no part of the line.
fn along_line(line: &[(f64, f64)], s: f64, d: f64, corridor: f64, window: f64) -> bool {
    let lo = line.partition_point(|q| q.0 < s - 0.5 * window);
    let hi = line.partition_point(|q| q.0 <= s + 0.5 * window);
    let mut offs: Vec<f64> = line[lo..hi].iter().map(|q| q.1).collect();
    if offs.is_empty() {
        return false;
    }
    let mid = offs.len() / 2;
    let (_, m, _) = offs.select_nth_unstable_by(mid, f64::total_cmp);
    (d - *m).abs() <= corridor
}

/// The innermost offset (absolute) of `cand` per [`ENERGY_BIN_M`] of station, as
/// (station of the bin's start, offset), in station order.
fn innermost_line(
    cand: &[usize],
    position_of: &dyn Fn(usize) -> Option<(f64, f64)>,
) -> Vec<(f64, f64)> {
    let mut inner: std::collections::BTreeMap<i64, f64> = Default::default();
    for &i in cand {
        if let Some((s, d)) = position_of(i) {
            let e = inner
                .entry((s / ENERGY_BIN_M).floor() as i64)
                .or_insert(f64::INFINITY);
            *e = e.min(d.abs());
        }
    }
    inner
        .into_iter()
        .map(|(k, d)| (k as f64 * ENERGY_BIN_M, d))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ransac_finds_a_known_plane_among_clutter_deterministically() {
        // 400 points on z = 0.1·x + 0.05·y + 1 (grid 0.25 m over 5 m × 5 m), 100 clutter
        // points 1–3 m above it.
        let mut pts = Vec::new();
        for i in 0..20 {
            for j in 0..20 {
                let (x, y) = (i as f64 * 0.25, j as f64 * 0.25);
                pts.push([x, y, 0.1 * x + 0.05 * y + 1.0]);
            }
        }
        let mut r = ChaCha8Rng::seed_from_u64(7);
        for _ in 0..100 {
            let (x, y): (f64, f64) = (r.gen_range(0.0..5.0), r.gen_range(0.0..5.0));
            pts.push([x, y, 0.1 * x + 0.05 * y + 1.0 + r.gen_range(1.0..3.0)]);
        }
        let idx: Vec<usize> = (0..pts.len()).collect();
        let run = |seed| {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            ransac_plane(&pts, &idx, 0.01, 100, 20.0, &mut rng).unwrap()
        };
        let (plane, inl) = run(1);
        assert_eq!(inl, (0..400).collect::<Vec<_>>());
        // Normal of z = 0.1x + 0.05y + 1 is (−0.1, −0.05, 1)/√1.0125.
        let k = 1.0125f64.sqrt();
        assert!((plane.n[0] + 0.1 / k).abs() < 1e-9 && (plane.n[2] - 1.0 / k).abs() < 1e-9);
        assert!((plane.c + 1.0 / k).abs() < 1e-9);
        assert_eq!(run(1).0, plane, "same seed, same plane");
    }

    #[test]
    fn a_steep_plane_is_not_taken_for_the_road() {
        // A wall x = 0 (400 points, 1.9 m tall) beside a floor of as many points: the
        // tilt guard makes RANSAC return the floor.
        let mut pts = Vec::new();
        for i in 0..20 {
            for j in 0..20 {
                pts.push([0.0, i as f64 * 0.1, j as f64 * 0.1]);
            }
        }
        for i in 0..20 {
            for j in 0..20 {
                pts.push([0.2 + i as f64 * 0.1, j as f64 * 0.1, 0.0]);
            }
        }
        let idx: Vec<usize> = (0..pts.len()).collect();
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let (plane, inl) = ransac_plane(&pts, &idx, 0.01, 200, 20.0, &mut rng).unwrap();
        assert!(plane.n[2] > 0.999);
        // The floor's 400 points and the wall's bottom row (z = 0, 20 points).
        assert_eq!(inl.len(), 420);
    }

    #[test]
    fn candidates_are_outliers_next_to_inliers() {
        // Inliers (refined plane) at z = 0 for x = 0, 0.05, 0.10; outliers at x = 0.15
        // (z = 0.05: 0.071 m from the inlier at x = 0.10) and at x = 0.5 (far).
        let pts = [
            [0.0, 0.0, 0.0],
            [0.05, 0.0, 0.0],
            [0.10, 0.0, 0.0],
            [0.15, 0.0, 0.05],
            [0.5, 0.0, 0.15],
        ];
        let rough = [0, 1, 2, 3, 4];
        let refined = [true, true, true, false, false];
        let z: Vec<f64> = pts.iter().map(|p| p[2]).collect();
        assert_eq!(
            candidate_edge_points(&pts, &z, &rough, &refined, 0.1, 0.0),
            vec![3]
        );
        assert!(candidate_edge_points(&pts, &z, &rough, &refined, 0.05, 0.0).is_empty());
        // It rises 0.05 m above its neighbour: a candidate up to min_rise = 0.05 m.
        assert_eq!(
            candidate_edge_points(&pts, &z, &rough, &refined, 0.1, 0.05),
            vec![3]
        );
        // The curb top beside a sidewalk cell: normalised, the sidewalk point (index 1) is
        // at 0 and the top (index 0) 0.08 m above it, 0.06 m away; un-normalised both are
        // at the sidewalk's 0.08 m, so with a rise required it is no candidate.
        let pts = [[0.0, 0.0, 0.08], [0.06, 0.0, 0.0]];
        let z = [0.08, 0.08];
        let (rough, refined) = ([0, 1], [false, true]);
        assert_eq!(
            candidate_edge_points(&pts, &z, &rough, &refined, 0.1, 0.0),
            vec![0]
        );
        assert!(candidate_edge_points(&pts, &z, &rough, &refined, 0.1, 0.02).is_empty());
    }

    /// The smaller βs' candidates join along the chosen set's innermost line: in the
    /// middle of a 10 m curb cut (no line there) the curb's line on either side still
    /// places the corridor, so the lip's points (0.05 m off the line) join and road noise
    /// (3 m nearer the vehicle) or a wall (1 m behind) does not; a stretch with no line
    /// within half the window takes nothing.
    #[test]
    fn smaller_betas_join_along_the_chosen_line_across_a_cut() {
        let line: Vec<(f64, f64)> = (0..80)
            .map(|k| k as f64 * 0.5)
            .filter(|s| !(15.0..25.0).contains(s))
            .map(|s| (s, 5.0))
            .collect();
        assert!(along_line(&line, 20.0, 5.05, 0.3, 20.0));
        assert!(!along_line(&line, 20.0, 2.0, 0.3, 20.0));
        assert!(!along_line(&line, 20.0, 6.0, 0.3, 20.0));
        assert!(!along_line(&line, 70.0, 5.0, 0.3, 20.0));
        // A window shorter than the cut finds no line in its middle.
        assert!(!along_line(&line, 20.0, 5.05, 0.3, 5.0));
    }

    #[test]
    fn a_cuts_lip_seen_by_the_noisy_beta_only_joins_the_chosen_line() {
        // Stations and offsets: a curb at 5 m every 0.5 m with a cut from 15 to 25 m whose
        // lip (5.02 m) only the smallest β sees, and road noise at 1–4 m that also only the
        // smallest β sees, more than the curb.
        let mut pos: Vec<(f64, f64)> = Vec::new();
        let curb: Vec<usize> = (0..80)
            .map(|k| k as f64 * 0.5)
            .filter(|s| !(15.0..25.0).contains(s))
            .map(|s| {
                pos.push((s, 5.0));
                pos.len() - 1
            })
            .collect();
        let lip: Vec<usize> = (0..40)
            .map(|k| {
                pos.push((15.0 + k as f64 * 0.25, 5.02));
                pos.len() - 1
            })
            .collect();
        let mut noise: Vec<usize> = (0..240)
            .map(|k| {
                pos.push(((k % 80) as f64 * 0.5, 1.0 + (k / 80) as f64 * 1.5));
                pos.len() - 1
            })
            .collect();
        // A ramp's rise 0.25 m behind the cut's toe: within the corridor, beyond the lip.
        noise.extend((0..40).map(|k| {
            pos.push((15.0 + k as f64 * 0.25, 5.25));
            pos.len() - 1
        }));
        let smallest: Vec<usize> = curb.iter().chain(&lip).chain(&noise).copied().collect();
        // The noisy set has the smallest energy: it is still not chosen.
        let sets = [
            (0.001, 0.01, smallest),
            (0.002, 0.02, curb.clone()),
            (0.002, 0.04, curb.clone()),
        ];
        let choice = SetChoice {
            energy_tolerance: 0.0,
            energy_slack_m: 0.01,
            noise_count_ratio: 1.5,
            low_beta: [0.3, 20.0],
        };
        let mut in_set = vec![false; pos.len()];
        let (beta, chosen) = choice
            .choose(&sets, &mut in_set, &|i| Some(pos[i]))
            .unwrap();
        assert_eq!(beta, 0.02);
        assert!(curb.iter().chain(&lip).all(|i| chosen.contains(i)));
        assert!(noise.iter().all(|i| !chosen.contains(i)));
        assert_eq!(chosen.len(), curb.len() + lip.len());
    }

    #[test]
    fn smoothness_energy_is_the_robust_per_side_spread_of_the_innermost_line() {
        // Left innermost offsets 4, 6, 4, 4 at stations 0…3 (the extra point at 7 m lies
        // behind): squared steps 4, 4, 0 → median 4 → E_s = 2. Right: −5 three times → 0.
        let e = smoothness_energy(&[
            (0.1, 4.0),
            (0.2, 7.0),
            (1.1, 6.0),
            (2.1, 4.0),
            (3.1, 4.0),
            (0.1, -5.0),
            (1.1, -5.0),
            (2.1, -5.0),
        ]);
        assert_eq!(e, [Some(2.0), Some(0.0)]);
        // A straight curb with a wall behind it scores 0, also when a curb cut (stations
        // 4–5) lets the innermost point jump to the wall twice.
        let mut curb_wall: Vec<(f64, f64)> = (0..20)
            .flat_map(|k| [(k as f64, 5.0), (k as f64, 8.0)])
            .collect();
        assert_eq!(smoothness_energy(&curb_wall), [Some(0.0), None]);
        curb_wall.retain(|&(s, d)| !(d == 5.0 && (4.0..6.0).contains(&s)));
        assert_eq!(smoothness_energy(&curb_wall), [Some(0.0), None]);
        // Road noise hovering near the vehicle (offsets alternating 1 and 2 m) scores far
        // worse, though its plain variance (0.25) is below the curb-with-cut's (1.6).
        let noise: Vec<(f64, f64)> = (0..20).map(|k| (k as f64, 1.0 + (k % 2) as f64)).collect();
        assert_eq!(smoothness_energy(&noise), [Some(0.5), None]);
        assert_eq!(smoothness_energy(&[(0.0, 1.0), (1.0, 1.0)]), [None, None]);
    }
}
