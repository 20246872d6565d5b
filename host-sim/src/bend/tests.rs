//! Synthetic scenes built directly as [`BendInput`] (no core needed): a road driven at
//! 11 m/s with 100 scanlines/s (0.11 m apart, as in the paper's Table 1), points every
//! 1–3 cm along each scanline, ρ ≈ +peak at the curb toe falling linearly to 0 over d_b =
//! 0.1 m on the road side and ≈ −90° on the curb top, Gaussian ρ noise (σ = 2°) everywhere,
//! and one candidate per side and scanline at the road-side point nearest the toe, with
//! every tenth candidate moved to a random road point (outliers for RANSAC).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

use super::*;
use crate::io::trajectory::Pose;
use crate::model::Category;
use crate::model::Side;
use crate::replay::{Candidate, PointStatus};

const X0: f64 = 500_000.0;
const Y0: f64 = 4_000_000.0;
const Z0: f64 = 30.0;
const T0: f64 = 400_000_000.0;
const SPEED: f64 = 11.0;
const LINE_DT: f64 = 0.01;

/// The toe on one side at arc length s: lateral offset (signed, left positive), curb height
/// and peak ρ; `None` where there is no curb.
type ToeFn = fn(f64) -> Option<(f64, f64, f64)>;

struct SceneCfg {
    length_m: f64,
    /// Radius of a left-hand bend, or `None` for a straight road heading east.
    radius_m: Option<f64>,
    /// Yaw of the scan plane: points at lateral u lie u·tan(yaw) ahead of the vehicle.
    yaw_deg: f64,
    left: ToeFn,
    right: ToeFn,
    /// A parked car on the left: arc range and lateral offset of its side.
    car: Option<(f64, f64, f64)>,
    seed: u64,
}

struct Scene {
    traj: Trajectory,
    x: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
    t: Vec<f64>,
    rho: Vec<f32>,
    status: Vec<Option<PointStatus>>,
    scanline: Vec<u32>,
    candidates: Vec<Candidate>,
    /// Dense toe polylines (left, right) where there is a curb, one per continuous piece.
    toes: Vec<(Side, Vec<[f64; 2]>)>,
}

impl Scene {
    fn input(&self) -> BendInput<'_> {
        BendInput {
            x: &self.x,
            y: &self.y,
            z: &self.z,
            t: &self.t,
            rho_deg: &self.rho,
            status: &self.status,
            scanline: &self.scanline,
            candidates: &self.candidates,
            trajectory: &self.traj,
        }
    }
}

/// Position and heading (degrees clockwise from north) at arc length s.
fn pose_at(cfg: &SceneCfg, s: f64) -> ([f64; 2], f64) {
    match cfg.radius_m {
        None => ([X0 + s, Y0], 90.0),
        Some(r) => {
            // Starts heading east at (X0, Y0) and turns left around (X0, Y0 + r).
            let phi = s / r;
            let p = [X0 + r * phi.sin(), Y0 + r - r * phi.cos()];
            (p, phi.cos().atan2(phi.sin()).to_degrees().rem_euclid(360.0))
        }
    }
}

fn left_of(h_deg: f64) -> [f64; 2] {
    let h = h_deg.to_radians();
    [-h.cos(), h.sin()]
}

fn make_scene(cfg: &SceneCfg) -> Scene {
    let mut rng = ChaCha8Rng::seed_from_u64(cfg.seed);
    let noise = Normal::new(0.0, 2.0).unwrap();
    let znoise = Normal::new(0.0, 0.003).unwrap();
    let n_lines = (cfg.length_m / (SPEED * LINE_DT)) as usize;
    let mut samples = Vec::new();
    // Trajectory 1 s beyond both ends, sampled at 100 Hz.
    for k in -100..(n_lines as i64 + 100) {
        let s = k as f64 * SPEED * LINE_DT;
        let (p, h) = pose_at(cfg, s);
        samples.push(Pose {
            t: T0 + k as f64 * LINE_DT,
            x: p[0],
            y: p[1],
            z: Z0 + 2.0,
            roll_deg: 0.0,
            pitch_deg: 0.0,
            heading_deg: h,
        });
    }
    let mut sc = Scene {
        traj: Trajectory { samples },
        x: Vec::new(),
        y: Vec::new(),
        z: Vec::new(),
        t: Vec::new(),
        rho: Vec::new(),
        status: Vec::new(),
        scanline: Vec::new(),
        candidates: Vec::new(),
        toes: Vec::new(),
    };
    let tan_yaw = cfg.yaw_deg.to_radians().tan();
    for line in 0..n_lines {
        let s_line = line as f64 * SPEED * LINE_DT;
        let t_line = T0 + line as f64 * LINE_DT;
        // (index of best road-side point, its distance to the toe) per side
        let mut best: [Option<(usize, f64)>; 2] = [None, None];
        let mut road_pts: [Vec<usize>; 2] = [Vec::new(), Vec::new()];
        let mut u: f64 = -6.5 + rng.gen_range(0.0..0.02);
        while u < 7.0 {
            let spacing = 0.01 + 0.004 * u.abs();
            let s = s_line + u * tan_yaw;
            let side_k = if u >= 0.0 { 0 } else { 1 };
            let toe = if u >= 0.0 {
                (cfg.left)(s)
            } else {
                (cfg.right)(s)
            };
            let (p, h) = pose_at(cfg, s);
            let l = left_of(h);
            let mut z = Z0;
            let mut rho = noise.sample(&mut rng);
            let mut occluded = false;
            let mut car_body = false;
            let mut toe_dist = None;
            if let Some((c0, c1, cu)) = cfg.car {
                if u >= 0.0 && s >= c0 && s <= c1 && u >= cu {
                    occluded = true;
                    // The car's side: a column of body points just outside its foot.
                    if u < cu + spacing {
                        car_body = true;
                    }
                } else if u >= 0.0 && s >= c0 && s <= c1 && u > cu - 0.1 {
                    // Road points approaching the car's foot bend up like a curb toe.
                    rho += 80.0 * (1.0 - (cu - u) / 0.1);
                    toe_dist = Some(cu - u);
                }
            }
            if !occluded && toe_dist.is_none() {
                if let Some((ut, height, peak)) = toe {
                    let d = u.abs() - ut.abs();
                    if d < 0.0 {
                        rho += peak * (1.0 + d / 0.1).max(0.0);
                        toe_dist = Some(-d);
                    } else {
                        z += height;
                        rho += -90.0 * (1.0 - d / 0.1).max(0.0);
                    }
                }
            }
            let idx = sc.x.len();
            if car_body {
                for k in 0..12 {
                    let zz = Z0 + 0.35 + 0.1 * k as f64;
                    let q = [p[0] + (u + 0.05) * l[0], p[1] + (u + 0.05) * l[1]];
                    sc.x.push(q[0]);
                    sc.y.push(q[1]);
                    sc.z.push(zz);
                    sc.t.push(t_line);
                    sc.rho.push(-30.0);
                    sc.status.push(Some(PointStatus::Kept));
                    sc.scanline.push(line as u32);
                }
            } else if !occluded {
                sc.x.push(p[0] + u * l[0]);
                sc.y.push(p[1] + u * l[1]);
                sc.z.push(z + znoise.sample(&mut rng));
                sc.t.push(t_line + (u + 6.5) * 1e-5);
                sc.rho.push(rho as f32);
                // A few points removed as irregular by the core: no ρ.
                let irregular = rng.gen_range(0..50) == 0;
                sc.status.push(Some(if irregular {
                    PointStatus::Irregular
                } else {
                    PointStatus::Kept
                }));
                if irregular {
                    *sc.rho.last_mut().unwrap() = 0.0;
                }
                sc.scanline.push(line as u32);
                if let Some(d) = toe_dist {
                    if !irregular && best[side_k].is_none_or(|(_, bd)| d < bd) {
                        best[side_k] = Some((idx, d));
                    }
                } else if toe.is_some() && u.abs() > 1.0 && z == Z0 {
                    road_pts[side_k].push(idx);
                }
            }
            u += spacing;
        }
        for (k, side) in [Side::Left, Side::Right].into_iter().enumerate() {
            if let Some((i, _)) = best[k] {
                let point = if rng.gen_range(0..10) == 0 && !road_pts[k].is_empty() {
                    road_pts[k][rng.gen_range(0..road_pts[k].len())]
                } else {
                    i
                };
                sc.candidates.push(Candidate {
                    point: point as u32,
                    side,
                    scanline: line as u32,
                });
            }
        }
    }
    // Reference toe polylines, every 1 cm, where there is a curb, no car, and a scanline.
    let s_last = (n_lines - 1) as f64 * SPEED * LINE_DT;
    for (side, f) in [(Side::Left, cfg.left), (Side::Right, cfg.right)] {
        let mut piece: Vec<[f64; 2]> = Vec::new();
        let mut s = -10.0;
        while s <= cfg.length_m + 10.0 {
            let hidden = side == Side::Left
                && cfg
                    .car
                    .is_some_and(|(c0, c1, _)| s >= c0 - 0.05 && s <= c1 + 0.05);
            let seen = |ut: f64| (0.0..=s_last).contains(&(s - ut * tan_yaw));
            match f(s) {
                Some((ut, _, _)) if !hidden && seen(ut) => {
                    let (p, h) = pose_at(cfg, s);
                    let l = left_of(h);
                    piece.push([p[0] + ut * l[0], p[1] + ut * l[1]]);
                }
                _ => {
                    if piece.len() > 1 {
                        sc.toes.push((side, std::mem::take(&mut piece)));
                    }
                    piece.clear();
                }
            }
            s += 0.01;
        }
        if piece.len() > 1 {
            sc.toes.push((side, piece));
        }
    }
    sc
}

/// Distance from a point to the nearest reference toe of that side (brute force: tests only).
fn dist_to_toe(sc: &Scene, side: Side, p: [f64; 3]) -> f64 {
    sc.toes
        .iter()
        .filter(|(s, _)| *s == side)
        .flat_map(|(_, poly)| poly.windows(2))
        .map(|w| {
            let (a, b) = (w[0], w[1]);
            let d = [b[0] - a[0], b[1] - a[1]];
            let l2 = d[0] * d[0] + d[1] * d[1];
            let u = (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / l2).clamp(0.0, 1.0);
            (p[0] - a[0] - u * d[0]).hypot(p[1] - a[1] - u * d[1])
        })
        .fold(f64::INFINITY, f64::min)
}

fn rms_mm(sc: &Scene, edges: &[EdgeLine]) -> f64 {
    let r = rms_mm_inner(sc, edges);
    eprintln!("RMS {r:.2} mm over {} edges", edges.len());
    r
}

fn rms_mm_inner(sc: &Scene, edges: &[EdgeLine]) -> f64 {
    let d: Vec<f64> = edges
        .iter()
        .flat_map(|e| e.points.iter().map(move |&p| dist_to_toe(sc, e.side, p)))
        .collect();
    1000.0 * (d.iter().map(|v| v * v).sum::<f64>() / d.len() as f64).sqrt()
}

fn side_length(edges: &[EdgeLine], side: Side) -> f64 {
    edges
        .iter()
        .filter(|e| e.side == side)
        .map(|e| e.length_m())
        .sum()
}

fn straight_left(_: f64) -> Option<(f64, f64, f64)> {
    Some((5.0, 0.15, 90.0))
}

fn straight_right(_: f64) -> Option<(f64, f64, f64)> {
    Some((-4.5, 0.15, 90.0))
}

fn straight(seed: u64) -> SceneCfg {
    SceneCfg {
        length_m: 30.0,
        radius_m: None,
        yaw_deg: 45.0,
        left: straight_left,
        right: straight_right,
        car: None,
        seed,
    }
}

#[test]
fn straight_road_gives_one_edge_per_side_on_the_toes() {
    let sc = make_scene(&straight(1));
    let edges = extract_edges(&sc.input(), &BendParams::default());
    let left: Vec<_> = edges.iter().filter(|e| e.side == Side::Left).collect();
    let right: Vec<_> = edges.iter().filter(|e| e.side == Side::Right).collect();
    assert_eq!((left.len(), right.len()), (1, 1), "{edges:#?}");
    // The scanlines cover s = 0 … 29.81 m (272 lines); with the 45° yaw the left toe is
    // seen at s = 5 … 34.81 m, the right one at s = −4.5 … 25.31 m: 29.81 m each.
    for e in [left[0], right[0]] {
        let l = e.length_m();
        // A polyline through measured toe points zigzags by their ~1 cm scatter, which
        // adds up to about 1 % of length.
        assert!(l > 29.0 && l < 30.2, "{:?} length {l}", e.side);
        assert_eq!(e.method.as_deref(), Some("bend"));
        assert_eq!(e.category, Some(Category::Curb));
        let h = e.curb_height_m.unwrap();
        assert!((h - 0.15).abs() < 0.01, "height step {h}");
    }
    let rms = rms_mm(&sc, &edges);
    assert!(rms < 20.0, "RMS {rms} mm");
    // Every vertex near its toe: no jumps onto the road or the curb top.
    for e in &edges {
        for &p in &e.points {
            assert!(dist_to_toe(&sc, e.side, p) < 0.05);
        }
    }
}

/// A curb the core gave no candidate for (a far curb crossed at a grazing angle, or returns
/// sparser than d_b) is still found: the profile seeds start its track from the height
/// step across the scanlines. Without them that side has no edge.
#[test]
fn a_curb_without_candidates_is_seeded_from_profiles() {
    let mut sc = make_scene(&straight(3));
    sc.candidates.retain(|c| c.side == Side::Right);
    let off = BendParams {
        profile_seed_reach_m: 0.0,
        ..BendParams::default()
    };
    let without = extract_edges(&sc.input(), &off);
    assert_eq!(side_length(&without, Side::Left), 0.0, "{without:#?}");
    let with = extract_edges(&sc.input(), &BendParams::default());
    let l = side_length(&with, Side::Left);
    assert!(l > 25.0, "left edge {l:.2} m of 29.81 m");
    for e in with.iter().filter(|e| e.side == Side::Left) {
        for &p in &e.points {
            assert!(dist_to_toe(&sc, Side::Left, p) < 0.05, "{p:?} off the toe");
        }
    }
}

#[test]
fn output_is_deterministic() {
    let sc = make_scene(&straight(2));
    let a = extract_edges(&sc.input(), &BendParams::default());
    let b = extract_edges(&sc.input(), &BendParams::default());
    assert_eq!(a, b);
    // Candidates in another order give the same edges.
    let mut sc2 = make_scene(&straight(2));
    sc2.candidates.reverse();
    assert_eq!(extract_edges(&sc2.input(), &BendParams::default()), a);
}

fn bend_left(_: f64) -> Option<(f64, f64, f64)> {
    Some((4.0, 0.15, 90.0))
}

fn bend_right(_: f64) -> Option<(f64, f64, f64)> {
    Some((-3.5, 0.15, 90.0))
}

#[test]
fn a_60_m_bend_is_followed() {
    let cfg = SceneCfg {
        length_m: 40.0,
        radius_m: Some(60.0),
        yaw_deg: 0.0,
        left: bend_left,
        right: bend_right,
        car: None,
        seed: 3,
    };
    let sc = make_scene(&cfg);
    let edges = extract_edges(&sc.input(), &BendParams::default());
    for side in [Side::Left, Side::Right] {
        assert_eq!(
            edges.iter().filter(|e| e.side == side).count(),
            1,
            "{side:?}"
        );
        // The toe arcs are (60 ∓ offset)/60 of the 39.93 m driven.
        let want = 39.93 * if side == Side::Left { 56.0 } else { 63.5 } / 60.0;
        let got = side_length(&edges, side);
        assert!(
            got > 0.95 * want && got < 1.01 * want,
            "{side:?}: {got} of {want}"
        );
    }
    let rms = rms_mm(&sc, &edges);
    assert!(rms < 20.0, "RMS {rms} mm");
}

/// A curb cut from s = 12 to 16 m on the left: 25 mm step, peak ρ only 25°.
fn cut_left(s: f64) -> Option<(f64, f64, f64)> {
    if (12.0..16.0).contains(&s) {
        Some((5.0, 0.025, 25.0))
    } else {
        Some((5.0, 0.15, 90.0))
    }
}

#[test]
fn a_curb_cut_is_tracked_through_and_labelled() {
    let cfg = SceneCfg {
        left: cut_left,
        ..straight(4)
    };
    let sc = make_scene(&cfg);
    let edges = extract_edges(&sc.input(), &BendParams::default());
    let left: Vec<&EdgeLine> = edges.iter().filter(|e| e.side == Side::Left).collect();
    // One track through the cut, cut into curb / curb cut / curb by the height step.
    let cats: Vec<_> = left.iter().map(|e| e.category).collect();
    assert_eq!(
        cats,
        vec![
            Some(Category::Curb),
            Some(Category::CurbCut),
            Some(Category::Curb)
        ],
        "{left:#?}"
    );
    // The pieces share their end vertices: one continuous line.
    assert_eq!(left[0].points.last(), left[1].points.first());
    assert_eq!(left[1].points.last(), left[2].points.first());
    let cut = left[1];
    let h = cut.curb_height_m.unwrap();
    assert!((h - 0.025).abs() < 0.01, "{h}");
    // The cut piece spans about s = 12 … 16 (x = X0 + s).
    let (x0, x1) = (cut.points[0][0] - X0, cut.points.last().unwrap()[0] - X0);
    assert!(
        (x0 - 12.0).abs() < 0.7 && (x1 - 16.0).abs() < 0.7,
        "{x0} {x1}"
    );
    assert!(side_length(&edges, Side::Left) > 29.0);
    assert!(rms_mm(&sc, &edges) < 20.0);
}

#[test]
fn a_parked_car_edge_is_removed_and_the_curb_kept() {
    let cfg = SceneCfg {
        car: Some((12.0, 17.0, 2.5)),
        ..straight(5)
    };
    let sc = make_scene(&cfg);
    // The car's foot gives candidates, so without the vehicle filter it is tracked.
    // Filter 4 (a step taller than any curb) is left out here, as it removes the foot too.
    let no_filter = BendParams {
        vehicle_share: 2.0,
        ..BendParams::default()
    };
    let input = sc.input();
    let route = route::Route::new(input.trajectory);
    let without_filter_4 = |p: &BendParams| -> Vec<EdgeLine> {
        extract_edges_on_grid(&input, &point_grid(&input, p), &route, p)
            .into_iter()
            .map(|(e, _)| e)
            .collect()
    };
    let unfiltered = without_filter_4(&no_filter);
    // On the car's foot: most of its points within 0.1 m of the foot line (a track may
    // start with a hop onto it).
    let on_car = |e: &EdgeLine| {
        let n = e
            .points
            .iter()
            .filter(|p| (p[1] - Y0 - 2.5).abs() < 0.1)
            .count();
        5 * n >= 4 * e.points.len()
    };
    // (It may come out in more than one piece: the precondition is only that it is there.)
    assert!(unfiltered.iter().any(on_car));
    let edges = without_filter_4(&BendParams::default());
    assert!(!edges.iter().any(on_car), "{edges:#?}");
    // Filter 4 alone removes it as well: the car's side is taller than any curb.
    let tall = extract_edges(&input, &no_filter);
    assert!(!tall.iter().any(on_car), "{tall:#?}");
    // The curb before and after the car is still there, on its toe.
    let left: Vec<_> = edges.iter().filter(|e| e.side == Side::Left).collect();
    assert_eq!(left.len(), 2, "{left:#?}");
    assert!(rms_mm(&sc, &edges) < 20.0);
}

#[test]
fn duplicate_seeds_give_one_edge() {
    let sc = make_scene(&straight(6));
    let input = sc.input();
    let route = route::Route::new(&sc.traj);
    let p = BendParams::default();
    let grid = grid::PointGrid::build(input.x, input.y, 0.1, |_| true);
    let seeds = seed::seed_points(&input, &route, &p);
    // About 12 intervals of 2 m per side give seeds.
    let left: Vec<i64> = seeds
        .iter()
        .filter(|s| s.side == Side::Left)
        .map(|s| s.interval)
        .collect();
    // The trajectory starts 11 m before the first scanline: arc lengths 11.0 … 40.81 m.
    assert_eq!(left, (5..=20).collect::<Vec<i64>>());
    // Every seed three times, in both orders: still one track per side.
    let mut many: Vec<seed::Seed> = seeds.iter().chain(&seeds).chain(&seeds).copied().collect();
    let tracks = track::track_edges(&input, &grid, &many, &p);
    assert_eq!(tracks.len(), 2);
    many.reverse();
    let tracks = track::track_edges(&input, &grid, &many, &p);
    assert_eq!(tracks.len(), 2);
    // Seeds taken from the far end first: tracks meet end to end and are joined.
    let sides: Vec<Side> = tracks.iter().map(|t| t.side).collect();
    assert!(sides.contains(&Side::Left) && sides.contains(&Side::Right));
}

#[test]
fn an_edge_behind_another_is_outside_the_roadway() {
    let sc = make_scene(&straight(7));
    let input = sc.input();
    let route = route::Route::new(&sc.traj);
    // Two hand-made tracks on the left: one on the toe (y = 5 m), one 2 m behind it.
    let pick = |y_off: f64| -> Vec<u32> {
        let mut v: Vec<u32> = (0..input.x.len() as u32)
            .filter(|&i| {
                let i = i as usize;
                (input.y[i] - Y0 - y_off).abs() < 0.02 && (input.x[i] - X0 - 15.0).abs() < 3.0
            })
            .collect();
        v.sort_by(|&a, &b| input.x[a as usize].total_cmp(&input.x[b as usize]));
        v
    };
    let front = track::Track::measured(&input, pick(4.98), Side::Left);
    let behind = track::Track::measured(&input, pick(6.5), Side::Left);
    assert!(front.points.len() > 10 && behind.points.len() > 10);
    // The back one is shorter so its ends look at the trajectory across the front one.
    let behind = track::Track::measured(
        &input,
        behind.points[5..behind.points.len() - 5].to_vec(),
        Side::Left,
    );
    let kept = postfilter::remove_outside_roadway(&input, &route, vec![front.clone(), behind]);
    assert_eq!(kept, vec![front]);
}

#[test]
fn bad_input_gives_nothing_and_does_not_panic() {
    let traj = Trajectory::default();
    let input = BendInput {
        x: &[1.0, 2.0],
        y: &[1.0],
        z: &[],
        t: &[0.0],
        rho_deg: &[90.0],
        status: &[Some(PointStatus::Kept)],
        scanline: &[0],
        candidates: &[Candidate {
            point: 7,
            side: Side::Left,
            scanline: 0,
        }],
        trajectory: &traj,
    };
    assert!(extract_edges(&input, &BendParams::default()).is_empty());
}

/// Timing on a 300 m road (about 1.5 M points): `cargo test --release -p
/// curbtrace-host-sim bend::tests::timing -- --ignored --nocapture`.
#[test]
#[ignore]
fn timing_300_m() {
    let cfg = SceneCfg {
        length_m: 300.0,
        ..straight(8)
    };
    let sc = make_scene(&cfg);
    let input = sc.input();
    let p = BendParams::default();
    let t0 = std::time::Instant::now();
    let route = route::Route::new(&sc.traj);
    let grid = grid::PointGrid::build(input.x, input.y, 0.1, |i| input.status[i].is_some());
    let t1 = t0.elapsed().as_secs_f64();
    let seeds = seed::seed_points(&input, &route, &p);
    let t2 = t0.elapsed().as_secs_f64();
    let tracks = track::track_edges(&input, &grid, &seeds, &p);
    let t3 = t0.elapsed().as_secs_f64();
    let tracks = postfilter::remove_under_objects(&input, &grid, tracks, &p);
    let t4 = t0.elapsed().as_secs_f64();
    let _ = postfilter::to_edge_lines(&input, &grid, &route, &tracks, &p);
    let t5 = t0.elapsed().as_secs_f64();
    eprintln!(
        "index {t1:.3} seeds {:.3} track {:.3} vehicle {:.3} lines {:.3}",
        t2 - t1,
        t3 - t2,
        t4 - t3,
        t5 - t4
    );
    let t0 = std::time::Instant::now();
    let edges = extract_edges(&sc.input(), &BendParams::default());
    let dt = t0.elapsed().as_secs_f64();
    eprintln!(
        "{} points, {} edges, {:.3} s, {:.1} M points/s",
        sc.x.len(),
        edges.len(),
        dt,
        sc.x.len() as f64 / dt / 1e6
    );
    assert_eq!(edges.len(), 2);
}

/// A curb cut with no lip at the end of the drive, from s = 22 m on the left: the toe is
/// only the break of slope between the flat road and a ramp behind it (rising at `slope`
/// up to `height`), ρ has no peak and the core gives no candidate there, and no track waits
/// past the cut to bridge to.
fn cut_at_end_scene(slope: f64, height: f64) -> Scene {
    fn cut_at_end(s: f64) -> Option<(f64, f64, f64)> {
        if s >= 22.0 {
            Some((5.0, 0.0, 0.0))
        } else {
            Some((5.0, 0.15, 90.0))
        }
    }
    let mut sc = make_scene(&SceneCfg {
        left: cut_at_end,
        ..straight(6)
    });
    // The ramp behind the toe (the road heads east: x = X0 + s, y = Y0 + u).
    for i in 0..sc.x.len() {
        let (s, u) = (sc.x[i] - X0, sc.y[i] - Y0);
        if s >= 22.0 && u > 5.0 {
            sc.z[i] += (slope * (u - 5.0)).min(height);
        }
    }
    let x = sc.x.clone();
    sc.candidates
        .retain(|c| c.side == Side::Right || x[c.point as usize] - X0 < 22.0);
    sc
}

/// The farthest s reached by a left edge.
fn left_reach(edges: &[EdgeLine]) -> f64 {
    edges
        .iter()
        .filter(|e| e.side == Side::Left)
        .flat_map(|e| e.points.iter().map(|p| p[0] - X0))
        .fold(f64::MIN, f64::max)
}

/// The track along the curb follows a lipless cut's break of slope (a 1:5 ramp) to the end
/// of the scanned stretch (the left toe is seen up to s = 34.81 m); without cut following it
/// stops within a few gap steps of the cut's start.
#[test]
fn a_curb_cut_without_lip_is_followed_to_the_end_of_the_drive() {
    let sc = cut_at_end_scene(0.2, 0.15);
    let off = BendParams {
        cut_follow_max_m: 0.0,
        ..BendParams::default()
    };
    let without = extract_edges(&sc.input(), &off);
    assert!(
        left_reach(&without) < 23.5,
        "without: to s = {}",
        left_reach(&without)
    );
    let with = extract_edges(&sc.input(), &BendParams::default());
    assert!(
        left_reach(&with) > 33.5,
        "with: to s = {}",
        left_reach(&with)
    );
    for e in with.iter().filter(|e| e.side == Side::Left) {
        for &p in &e.points {
            assert!(dist_to_toe(&sc, Side::Left, p) < 0.05, "{p:?} off the toe");
        }
    }
}

/// A cut in a high curb whose ramp climbs the full 0.25 m over 0.5 m (1:2) is followed as
/// well: the break of slope is the toe however steep the ramp behind it.
#[test]
fn a_curb_cut_with_a_steep_ramp_is_followed() {
    let sc = cut_at_end_scene(0.5, 0.25);
    let with = extract_edges(&sc.input(), &BendParams::default());
    assert!(left_reach(&with) > 33.5, "to s = {}", left_reach(&with));
    for e in with.iter().filter(|e| e.side == Side::Left) {
        for &p in &e.points {
            assert!(dist_to_toe(&sc, Side::Left, p) < 0.05, "{p:?} off the toe");
        }
    }
}

#[test]
fn median_of_even_and_odd() {
    assert_eq!(super::median(&mut [3.0, 1.0, 2.0]), Some(2.0));
    assert_eq!(super::median(&mut [4.0, 1.0, 2.0, 3.0]), Some(2.5));
    assert_eq!(super::median(&mut []), None);
}
