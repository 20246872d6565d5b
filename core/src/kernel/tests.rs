//! Tests of the whole kernel: geometry by hand, accounting, the synthetic curb scanline
//! (with and without weeds, both rotation directions), the differential test against the
//! plain f64 reference, micromath against libm, and the memory budget.
extern crate std;

use super::synth::{Rng, Scene};
use super::*;
use std::vec::Vec;

const N: usize = 4096;

fn line_from(points: &[(f32, f32, u32)]) -> Line<N> {
    let mut line = Line::<N>::new();
    for &(x, z, t) in points {
        line.push(x, z, t).unwrap();
    }
    line
}

fn check_accounting(out: &ScanlineOutput<'_>) {
    let c = out.counters;
    assert_eq!(c.points_in as usize, out.status.len());
    assert_eq!(
        c.kept + c.irregular + c.no_neighbour + c.non_finite + c.outside_roi,
        c.points_in
    );
    let count = |s: PointStatus| out.status.iter().filter(|&&x| x == s).count() as u32;
    assert_eq!(count(PointStatus::Kept), c.kept);
    assert_eq!(count(PointStatus::Irregular), c.irregular);
    assert_eq!(count(PointStatus::NoNeighbour), c.no_neighbour);
    assert_eq!(count(PointStatus::NonFinite), c.non_finite);
    assert_eq!(count(PointStatus::OutsideRoi), c.outside_roi);
    for (i, (&s, &r)) in out.status.iter().zip(out.rho_deg).enumerate() {
        if s != PointStatus::Kept {
            assert_eq!(r, 0.0, "point {i} with status {s:?} has ρ");
        }
        assert!(r > -180.0 && r <= 180.0, "ρ out of range at {i}: {r}");
    }
    for o in [out.nadir, out.left, out.right].into_iter().flatten() {
        assert!(matches!(
            out.status[usize::from(o)],
            PointStatus::Kept | PointStatus::NoNeighbour
        ));
    }
}

#[test]
fn empty_and_tiny_lines() {
    let mut k = Kernel::<16>::new(KernelParams::DEFAULT);
    let mut line = Line::<16>::new();
    let out = k.process(&mut line);
    assert_eq!(out.status.len(), 0);
    assert_eq!((out.nadir, out.left, out.right), (None, None, None));
    line.push(0.5, -2.0, 7).unwrap();
    let out = k.process(&mut line);
    assert_eq!(out.status, &[PointStatus::NoNeighbour]);
    assert_eq!(out.nadir, Some(0));
    assert_eq!(out.tag, &[7]);
    line.push(0.55, -2.0, 8).unwrap();
    let out = k.process(&mut line);
    assert_eq!(out.status, &[PointStatus::NoNeighbour; 2]);
    assert_eq!(out.counters.no_neighbour, 2);
}

#[test]
fn straight_line_gives_zero_and_no_peak() {
    let pts: Vec<(f32, f32, u32)> = (0..200)
        .map(|i| (-1.0 + 0.01 * i as f32, -2.0 - 0.001 * i as f32, i))
        .collect();
    let mut line = line_from(&pts);
    let mut k = Kernel::<N>::new(KernelParams::DEFAULT);
    let out = k.process(&mut line);
    check_accounting(&out);
    assert_eq!(out.counters.peaks, 0);
    assert_eq!(out.counters.no_neighbour, 2, "only the two ends");
    for &r in out.rho_deg {
        assert!(r.abs() < 0.01, "{r}");
    }
    // Nadir: x = 0 is point 100.
    assert_eq!(out.nadir, Some(100));
    assert_eq!(out.tag[57], 57);
}

/// An ideal step: road at z = −2 from x = 0 to 1 (every 10 mm), face up to −1.85 at x = 1
/// (every 10 mm), top from 1 to 1.5.
fn ideal_curb(reverse: bool, mirror: bool) -> Vec<(f32, f32, u32)> {
    let mut v = Vec::new();
    for i in 0..100 {
        v.push((0.01 * i as f32, -2.0));
    }
    for i in 0..15 {
        v.push((1.0, -2.0 + 0.01 * i as f32));
    }
    for i in 0..=50 {
        v.push((1.0 + 0.01 * i as f32, -1.85));
    }
    if mirror {
        v.iter_mut().for_each(|p| p.0 = -p.0);
    }
    if reverse {
        v.reverse();
    }
    v.into_iter()
        .enumerate()
        .map(|(i, (x, z))| (x, z, i as u32))
        .collect()
}

#[test]
fn ideal_curb_toe_is_plus_90_top_minus_90_in_all_orientations() {
    let params = KernelParams {
        taubin_steps: 0,
        ..KernelParams::DEFAULT
    };
    let mut k = Kernel::<N>::new(params);
    for reverse in [false, true] {
        for mirror in [false, true] {
            let pts = ideal_curb(reverse, mirror);
            let mut line = line_from(&pts);
            let out = k.process(&mut line);
            check_accounting(&out);
            let find = |x: f32, z: f32| {
                pts.iter()
                    .position(|p| (p.0.abs() - x).abs() < 1e-4 && (p.1 - z).abs() < 1e-4)
                    .unwrap()
            };
            let toe = find(1.0, -2.0);
            let top = find(1.0, -1.85);
            let (rt, rp) = (out.rho_deg[toe], out.rho_deg[top]);
            assert!((rt - 90.0).abs() < 0.2, "toe {reverse} {mirror}: {rt}");
            assert!((rp + 90.0).abs() < 0.2, "top {reverse} {mirror}: {rp}");
            let flat = find(0.5, -2.0);
            assert!(out.rho_deg[flat].abs() < 1e-3);
            // The toe is the only peak: the candidate on its side, nothing on the other.
            assert_eq!(out.counters.peaks, 1);
            let (cand, other) = if mirror {
                (out.right, out.left)
            } else {
                (out.left, out.right)
            };
            assert_eq!(cand, Some(toe as u16), "{reverse} {mirror}");
            assert_eq!(other, None);
            assert_eq!(out.nadir, Some(find(0.0, -2.0) as u16));
        }
    }
}

/// The edge of the shadow the vehicle's body casts, as a yawed scanline running along the
/// travel direction gives it in x′: returns piling up within millimetres of x′ with the
/// range noise in z′, then a gap of 2 m. The points next to the gap have a large ρ (their
/// window's arm ends at the last return) but give no candidate; the curb beyond does.
#[test]
fn a_peak_at_the_edge_of_a_gap_is_no_candidate() {
    let mut rng = Rng(7);
    let mut v: Vec<(f32, f32)> = Vec::new();
    for i in 0..200 {
        v.push((0.005 * i as f32, -2.0));
    }
    // The pile-up before the shadow: x′ grows by 0.5 mm a return, z′ noisy by ±5 mm.
    for i in 0..60 {
        let noise = rng.range(-0.005, 0.005) as f32;
        v.push((1.0 + 0.0005 * i as f32, -2.0 + noise));
    }
    // 2 m gap, then road out to a 0.15 m curb at x = 4.
    for i in 0..=100 {
        v.push((3.03 + 0.01 * i as f32, -2.0));
    }
    for i in 1..=15 {
        v.push((4.03, -2.0 + 0.01 * i as f32));
    }
    for i in 1..=50 {
        v.push((4.03 + 0.01 * i as f32, -1.85));
    }
    let pts: Vec<(f32, f32, u32)> = v
        .into_iter()
        .enumerate()
        .map(|(i, (x, z))| (x, z, i as u32))
        .collect();
    let mut k = Kernel::<N>::new(KernelParams::DEFAULT);
    let mut line = line_from(&pts);
    let out = k.process(&mut line);
    check_accounting(&out);
    let left = usize::from(out.left.expect("a left candidate"));
    assert!(
        (out.x_m[left] - 4.03).abs() < 0.03,
        "candidate at x′ = {}",
        out.x_m[left]
    );
}

#[test]
fn spikes_are_removed_non_finite_set_aside_and_order_restored() {
    let mut pts = ideal_curb(false, false);
    // A spike 0.12 m above the road at x = 0.3 (point 30) and a NaN at point 60.
    pts[30].1 += 0.12;
    pts[60].0 = f32::NAN;
    let mut line = line_from(&pts);
    let mut k = Kernel::<N>::new(KernelParams::DEFAULT);
    let out = k.process(&mut line);
    check_accounting(&out);
    assert_eq!(
        out.status[30],
        PointStatus::Irregular,
        "{:?}",
        &out.status[25..35]
    );
    assert_eq!(out.status[60], PointStatus::NonFinite);
    // Raw coordinates back for the removed points, tags untouched and in order.
    assert_eq!(out.z_m[30], pts[30].1);
    assert_eq!(out.x_m[30], pts[30].0);
    assert!(out.x_m[60].is_nan());
    for (i, &t) in out.tag.iter().enumerate() {
        assert_eq!(t, i as u32);
    }
    // Smoothed neighbours stay where they were (within smoothing).
    for i in [29usize, 31, 59, 61] {
        assert!((out.x_m[i] - pts[i].0).abs() < 0.01, "x at {i}");
        assert!((out.z_m[i] - pts[i].1).abs() < 0.01, "z at {i}");
        assert_eq!(out.status[i], PointStatus::Kept);
    }
    // The candidate is still the toe (point 100).
    assert_eq!(out.left, Some(100));
}

/// A candidate's raw and smoothed (x′, z′).
type Cand = Option<((f32, f32), (f32, f32))>;

/// Runs the synthetic scene; returns the candidates' raw and smoothed positions and the
/// number of points.
fn run_scene(scene: &Scene, seed: u64) -> ([Cand; 2], usize) {
    run_scene_with(scene, seed, KernelParams::DEFAULT)
}

/// [`run_scene`] with given parameters.
fn run_scene_with(scene: &Scene, seed: u64, params: KernelParams) -> ([Cand; 2], usize) {
    let mut buf = std::vec![(0f32, 0f32, 0u32); N];
    let n = scene.generate(&mut Rng(seed), &mut buf);
    let mut line = line_from(&buf[..n]);
    let mut k = Kernel::<N>::new(params);
    let out = k.process(&mut line);
    check_accounting(&out);
    let pick = |c: Option<u16>| {
        c.map(|i| {
            let i = usize::from(i);
            ((buf[i].0, buf[i].1), (out.x_m[i], out.z_m[i]))
        })
    };
    ([pick(out.left), pick(out.right)], n)
}

fn dist(a: (f32, f32), b: (f64, f64)) -> f64 {
    let (dx, dz) = (f64::from(a.0) - b.0, f64::from(a.1) - b.1);
    libm::sqrt(dx * dx + dz * dz)
}

#[test]
fn synthetic_scanline_candidates_within_20_mm_of_both_toes() {
    // The candidate's position as the kernel outputs it (smoothed x′, z′) must be within
    // 20 mm of the toe; the raw point behind it carries its own 5 mm noise per coordinate
    // on top (≈7 mm RMS in 2D), so it gets 30 mm.
    let (mut worst_s, mut worst_r) = (0.0f64, 0.0f64);
    for seed in 0..8u64 {
        for ccw in [true, false] {
            let scene = Scene {
                ccw,
                ..Scene::DEFAULT
            };
            let (c, n) = run_scene(&scene, seed);
            assert!((1900..=2100).contains(&n), "{n} points");
            for (side, (cand, toe)) in c.iter().zip(scene.toes()).enumerate() {
                let (raw, smooth) = cand.unwrap_or_else(|| panic!("seed {seed} side {side}"));
                let (dr, ds) = (dist(raw, toe), dist(smooth, toe));
                worst_s = worst_s.max(ds);
                worst_r = worst_r.max(dr);
                assert!(
                    ds < 0.020,
                    "seed {seed} ccw {ccw} side {side}: smoothed {ds} m"
                );
                assert!(dr < 0.030, "seed {seed} ccw {ccw} side {side}: raw {dr} m");
            }
        }
    }
    std::println!(
        "150 mm curbs: worst candidate distance to its toe {:.1} mm (raw point {:.1} mm)",
        worst_s * 1e3,
        worst_r * 1e3
    );
}

#[test]
fn low_curbs_still_give_candidates_near_the_toe() {
    // 80 mm curbs (Sapporo, paper §3.1): d_b = 0.07 m keeps the toe a sharp peak.
    let mut worst = 0.0f64;
    for seed in 0..8u64 {
        for ccw in [true, false] {
            let scene = Scene {
                curb_h: 0.08,
                ccw,
                ..Scene::DEFAULT
            };
            let (c, _) = run_scene(&scene, seed);
            for (cand, toe) in c.iter().zip(scene.toes()) {
                let (_, smooth) = cand.expect("candidate on an 80 mm curb");
                worst = worst.max(dist(smooth, toe));
            }
        }
    }
    std::println!(
        "80 mm curbs: worst candidate distance {:.1} mm",
        worst * 1e3
    );
    assert!(worst < 0.025, "{worst}");
}

#[test]
fn weeds_move_the_candidate_by_at_most_30_mm() {
    // Grass in the joint: a 30 mm × 100 mm box on the road against each toe, 30 % of the
    // beams through it return from a blade at a random depth inside it.
    let mut worst = 0.0f64;
    let mut weed_points = 0usize;
    for seed in 0..8u64 {
        for ccw in [true, false] {
            let clean_scene = Scene {
                ccw,
                ..Scene::DEFAULT
            };
            let weedy_scene = Scene {
                weed_p: 0.3,
                weed_w: 0.03,
                weed_h: 0.10,
                ..clean_scene
            };
            let clean = run_scene(&clean_scene, seed).0;
            let weedy = run_scene(&weedy_scene, seed).0;
            weed_points += weedy_scene.count_weeds(seed);
            for side in 0..2 {
                let (_, a) = clean[side].unwrap();
                let (_, b) = weedy[side].unwrap_or_else(|| panic!("seed {seed} side {side}"));
                let moved = dist(a, (f64::from(b.0), f64::from(b.1)));
                worst = worst.max(moved);
                assert!(
                    moved < 0.030,
                    "seed {seed} ccw {ccw} side {side}: moved {moved} m"
                );
            }
        }
    }
    std::println!(
        "weeds ({weed_points} weed returns in 16 lines) moved the candidate by at most {:.1} mm",
        worst * 1e3
    );
    assert!(
        weed_points >= 16 * 4,
        "too few weed returns to test anything: {weed_points}"
    );
}

#[test]
fn sweep_windows_equal_the_spec_walk_on_synthetic_scanlines() {
    // docs/spec.md §2 walks outward from each point; the kernel sweeps. They differ only
    // where the line folds back within d_b — on raw lines with 5 mm noise at 4 mm spacing
    // that is common, on the smoothed line (where the output ρ comes from) rare. This test
    // counts both and bounds them.
    let p = KernelParams::DEFAULT;
    let d_b = f64::from(p.d_b_m);
    let (mut raw_same, mut raw_total, mut same, mut total) = (0usize, 0usize, 0usize, 0usize);
    let mut max_drho = 0.0f64;
    for seed in 0..4u64 {
        for ccw in [true, false] {
            let scene = Scene {
                ccw,
                ..Scene::DEFAULT
            };
            let mut buf = std::vec![(0f32, 0f32, 0u32); N];
            let n = scene.generate(&mut Rng(seed), &mut buf);
            let xs: Vec<f64> = buf[..n].iter().map(|p| f64::from(p.0)).collect();
            let zs: Vec<f64> = buf[..n].iter().map(|p| f64::from(p.1)).collect();
            let mut margin = f64::INFINITY;
            let walk = reference::windows_walk(&xs, &zs, d_b);
            let sweep = reference::windows(&xs, &zs, d_b, &mut margin);
            raw_total += n;
            raw_same += (0..n)
                .filter(|&i| walk.0[i] == sweep.0[i] && walk.1[i] == sweep.1[i])
                .count();
            // The smoothed kept points, in order.
            let mut line = line_from(&buf[..n]);
            let mut k = Kernel::<N>::new(p);
            let out = k.process(&mut line);
            let kept: Vec<usize> = (0..n)
                .filter(|&i| out.status[i] != PointStatus::Irregular)
                .collect();
            let xs: Vec<f64> = kept.iter().map(|&i| f64::from(out.x_m[i])).collect();
            let zs: Vec<f64> = kept.iter().map(|&i| f64::from(out.z_m[i])).collect();
            let walk = reference::windows_walk(&xs, &zs, d_b);
            let sweep = reference::windows(&xs, &zs, d_b, &mut margin);
            for j in 0..kept.len() {
                total += 1;
                if walk.0[j] == sweep.0[j] && walk.1[j] == sweep.1[j] {
                    same += 1;
                } else if walk.0[j] < j && walk.1[j] > j {
                    let a = reference::rho(&xs, &zs, walk.0[j], j, walk.1[j]);
                    let b = reference::rho(&xs, &zs, sweep.0[j], j, sweep.1[j]);
                    max_drho = max_drho.max((a - b).abs());
                }
            }
        }
    }
    let frac = same as f64 / total as f64;
    std::println!(
        "sweep = walk for {:.2} % of raw windows and {:.2} % of smoothed ones; where they \
         differ on the smoothed line, ρ differs by at most {max_drho:.2}°",
        raw_same as f64 / raw_total as f64 * 100.0,
        frac * 100.0
    );
    assert!(frac > 0.99, "{frac}");
}

#[test]
fn memory_budget() {
    use core::mem::size_of;
    fn check<const M: usize>() -> (usize, usize) {
        let k = size_of::<Kernel<M>>();
        let l = size_of::<Line<M>>();
        assert!(k + l <= 20 * M + 2048, "N = {M}: kernel {k} + line {l}");
        (k, l)
    }
    for (m, (k, l)) in [
        (2048, check::<2048>()),
        (4096, check::<4096>()),
        (8192, check::<8192>()),
    ] {
        std::println!(
            "N = {m}: Kernel {k} B, Line {l} B, together {} B = {:.2} B/point + {} B",
            k + l,
            (k + l) as f64 / m as f64,
            k + l - 19 * m
        );
    }
}

/// Random scanline-like profiles for the differential test: road with slopes, vertical
/// steps up and down, ramps, spikes (irregular), gaps; under the scanner, either direction.
/// Coordinates on a 2⁻¹⁰ m grid, so raw distances and products are exact in f32.
fn random_profile(rng: &mut Rng) -> Vec<(f64, f64)> {
    let q = |v: f64| (v * 1024.0).round() / 1024.0;
    let mut v = Vec::new();
    let mut x = -1.6f64;
    let mut z = -2.0f64;
    let mut slope = rng.range(-0.05, 0.05);
    while x < 1.6 && v.len() < 400 {
        let r = rng.uniform();
        if r < 0.02 {
            // Vertical step of 20–200 mm, up or down.
            let h = rng.range(0.02, 0.2) * if rng.uniform() < 0.5 { 1.0 } else { -1.0 };
            let m = (h.abs() / rng.range(0.008, 0.025)).ceil() as usize;
            for k in 1..m {
                v.push((
                    q(x + rng.range(-0.001, 0.001)),
                    q(z + h * k as f64 / m as f64),
                ));
            }
            z += h;
        } else if r < 0.035 {
            // Spike.
            v.push((q(x), q(z + rng.range(0.03, 0.15))));
            x += rng.range(0.006, 0.025);
            continue;
        } else if r < 0.045 {
            // Gap.
            x += rng.range(0.35, 0.8);
        } else if r < 0.07 {
            slope = rng.range(-1.0, 1.0) * if rng.uniform() < 0.7 { 0.05 } else { 0.6 };
        }
        let dx = rng.range(0.006, 0.025);
        x += dx;
        z += slope * dx;
        v.push((q(x), q(z + rng.range(-0.001, 0.001))));
    }
    if rng.uniform() < 0.5 {
        v.iter_mut().for_each(|p| p.0 = -p.0);
    }
    if rng.uniform() < 0.5 {
        v.reverse();
    }
    v
}

/// ρ tolerance of the kernel against the f64 reference, degrees: smoothed coordinates agree
/// within about 1.5e-6 m, neighbours are at least 6 mm away, so
/// 1.5e-6 / 6e-3 rad ≈ 0.015°.
#[cfg(not(feature = "micromath"))]
const RHO_TOL_DEG: f64 = 0.02;
/// micromath's atan2 is within about 0.16°.
#[cfg(feature = "micromath")]
const RHO_TOL_DEG: f64 = 0.2;

#[test]
fn differential_against_f64_reference() {
    let seed: u64 = std::env::var("CURBTRACE_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0x5eed_c0de);
    let profiles = 300;
    let p = KernelParams::DEFAULT;
    let mut rng = Rng(seed);
    let (mut compared, mut skipped, mut points, mut skip_m) = (0, 0, 0usize, 0usize);
    let (mut max_drho, mut max_dxz) = (0.0f64, 0.0f64);
    let (mut peaks, mut cands) = (0usize, 0usize);
    let mut k = Kernel::<N>::new(p);
    for prof in 0..profiles {
        let v = random_profile(&mut rng);
        let xs: Vec<f64> = v.iter().map(|p| p.0).collect();
        let zs: Vec<f64> = v.iter().map(|p| p.1).collect();
        let r = reference::run(&xs, &zs, &p);
        // Skip profiles where an f32 rounding could decide differently from f64 (smoothed
        // window ends within 5 µm of d_b — the smoothed points agree within 1.5 µm —,
        // angles within 0.05° of a threshold or of a rival in a peak window; 0.35° with
        // micromath, twice its atan2 error).
        let deg_margin = if cfg!(feature = "micromath") {
            0.35
        } else {
            0.05
        };
        if r.margin_m < 5e-6 || r.margin_deg < deg_margin {
            skipped += 1;
            skip_m += usize::from(r.margin_m < 5e-6);
            continue;
        }
        compared += 1;
        let pts: Vec<(f32, f32, u32)> = v
            .iter()
            .enumerate()
            .map(|(i, p)| (p.0 as f32, p.1 as f32, i as u32))
            .collect();
        let mut line = line_from(&pts);
        let out = k.process(&mut line);
        check_accounting(&out);
        points += pts.len();
        let ctx = || std::format!("seed {seed} profile {prof}");
        assert_eq!(out.status, &r.status[..], "{}", ctx());
        for i in 0..pts.len() {
            let drho = (f64::from(out.rho_deg[i]) - r.rho[i]).abs();
            max_drho = max_drho.max(drho);
            assert!(
                drho <= RHO_TOL_DEG,
                "{}: ρ at {i}: {} vs {}",
                ctx(),
                out.rho_deg[i],
                r.rho[i]
            );
            let dxz = (f64::from(out.x_m[i]) - r.x[i])
                .abs()
                .max((f64::from(out.z_m[i]) - r.z[i]).abs());
            max_dxz = max_dxz.max(dxz);
            assert!(dxz < 3e-6, "{}: smoothed point {i} off by {dxz}", ctx());
        }
        let u = |o: Option<u16>| o.map(usize::from);
        assert_eq!(u(out.nadir), r.nadir, "{}", ctx());
        assert_eq!(u(out.left), r.left, "{}", ctx());
        assert_eq!(u(out.right), r.right, "{}", ctx());
        assert_eq!(out.counters.peaks as usize, r.peaks, "{}", ctx());
        peaks += r.peaks;
        cands += usize::from(r.left.is_some()) + usize::from(r.right.is_some());
    }
    std::println!(
        "differential (seed {seed:#x}): {compared} profiles compared ({points} points, \
         {peaks} peaks, {cands} candidates), {skipped} skipped as near-ties ({skip_m} on distance); \
         max |Δρ| {max_drho:.2e}°, max |Δx|,|Δz| {max_dxz:.2e} m"
    );
    assert!(
        compared >= profiles / 3,
        "too many near-ties: {skipped} skipped ({skip_m} on distance)"
    );
    assert!(peaks > 0 && cands > 0, "profiles too tame to test peaks");
}

/// The micromath build's ρ against libm's on the same lines (both backends in one build).
#[cfg(all(feature = "libm", feature = "micromath"))]
#[test]
fn micromath_rho_within_tolerance_of_libm() {
    use crate::math::{Libm, Micromath};
    /// Stated tolerance: micromath's atan2 error (0.162°) plus margin for f32 rounding.
    const TOL_DEG: f32 = 0.17;
    let mut worst = 0.0f32;
    for seed in 0..4u64 {
        let scene = Scene::DEFAULT;
        let mut buf = std::vec![(0f32, 0f32, 0u32); N];
        let n = scene.generate(&mut Rng(seed), &mut buf);
        let mut la = line_from(&buf[..n]);
        let mut lb = line_from(&buf[..n]);
        let mut ka = Kernel::<N>::new(KernelParams::DEFAULT);
        let mut kb = Kernel::<N>::new(KernelParams::DEFAULT);
        let a = ka.process_with::<Libm>(&mut la);
        let b = kb.process_with::<Micromath>(&mut lb);
        assert_eq!(a.status, b.status, "removal and windows do not use atan2");
        for i in 0..n {
            let d = (a.rho_deg[i] - b.rho_deg[i]).abs();
            worst = worst.max(d);
            assert!(
                d <= TOL_DEG,
                "seed {seed} point {i}: {} vs {}",
                a.rho_deg[i],
                b.rho_deg[i]
            );
        }
        // Candidates: the same points, or within 20 mm of each other.
        for (ca, cb) in [(a.left, b.left), (a.right, b.right)] {
            let (ia, ib) = (usize::from(ca.unwrap()), usize::from(cb.unwrap()));
            let d = libm::hypotf(a.x_m[ia] - b.x_m[ib], a.z_m[ia] - b.z_m[ib]);
            assert!(
                d < 0.02,
                "seed {seed}: candidates {ia} vs {ib}, {d} m apart"
            );
        }
    }
    std::println!("micromath vs libm: max |Δρ| = {worst:.4}° (tolerance {TOL_DEG}°)");
}

/// The study behind the defaults of d_b (see `KernelParams::d_b_m`): worst and RMS distance
/// of the candidates to their toes over 80 synthetic lines, for a given d_b (env `DB`),
/// curb height (`H`), weed probability and box width (`WEED`, `WW`). Run with
/// `cargo test -p curbtrace-core --lib parameter_study -- --ignored --nocapture`.
#[test]
#[ignore]
fn parameter_study() {
    let env = |k: &str, d: f64| std::env::var(k).map_or(d, |s| s.parse().unwrap_or(d));
    let params = KernelParams {
        d_b_m: env("DB", f64::from(KernelParams::DEFAULT.d_b_m)) as f32,
        ..KernelParams::DEFAULT
    };
    for side in 0..2 {
        let (mut worst, mut sum2, mut cnt, mut missing) = (0.0f64, 0.0f64, 0usize, 0usize);
        for seed in 0..40u64 {
            for ccw in [true, false] {
                let scene = Scene {
                    ccw,
                    curb_h: env("H", 0.15),
                    weed_p: env("WEED", 0.0),
                    weed_w: env("WW", 0.03),
                    ..Scene::DEFAULT
                };
                match run_scene_with(&scene, seed, params).0[side] {
                    Some((_, sm)) => {
                        let d = dist(sm, scene.toes()[side]);
                        worst = worst.max(d);
                        sum2 += d * d;
                        cnt += 1;
                    }
                    None => missing += 1,
                }
            }
        }
        std::println!(
            "side {side}: worst {:.1} mm, RMS {:.1} mm, missing {missing}",
            worst * 1e3,
            libm::sqrt(sum2 / cnt.max(1) as f64) * 1e3
        );
    }
}

/// Minimum and median of per-call wall times, ns per point.
fn min_med(n: usize, reps: usize, mut f: impl FnMut()) -> (f64, f64) {
    let mut v: Vec<f64> = (0..reps)
        .map(|_| {
            let t0 = std::time::Instant::now();
            f();
            t0.elapsed().as_nanos() as f64 / n as f64
        })
        .collect();
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    (v[0], v[reps / 2])
}

/// Where the time goes: each stage on one synthetic 2000-point line, minimum and median of
/// 2000 runs (the minimum is the uncontended speed on a shared machine). Run with
/// `cargo test --release -p curbtrace-core --lib stage_timings -- --ignored --nocapture`.
#[test]
#[ignore]
fn stage_timings() {
    let mut buf = std::vec![(0f32, 0f32, 0u32); N];
    let n = Scene::DEFAULT.generate(&mut Rng(1), &mut buf);
    let x: Vec<f32> = buf[..n].iter().map(|p| p.0).collect();
    let z: Vec<f32> = buf[..n].iter().map(|p| p.1).collect();
    let (mut s_off, mut t_off) = (std::vec![0u8; n], std::vec![0u8; n]);
    let d2 = 0.07f32 * 0.07;
    let r = min_med(n, 2000, || {
        bend::windows(core::hint::black_box(&x), &z, d2, &mut s_off, &mut t_off);
    });
    std::println!("windows (raw line): {r:.1?} ns/pt");
    let (mut xs1, mut zs1) = (x.clone(), z.clone());
    let mut scratch = std::vec![0f32; n];
    smooth::taubin_smooth(&mut xs1, &mut zs1, &mut scratch, 0.3, 20, 0.6307, -0.6732);
    let r = min_med(n, 2000, || {
        bend::windows(
            core::hint::black_box(&xs1),
            &zs1,
            d2,
            &mut s_off,
            &mut t_off,
        );
    });
    std::println!("windows (smoothed line): {r:.1?} ns/pt");
    let mut rho = std::vec![0f32; n];
    let r = min_med(n, 2000, || {
        bend::bend_angles::<crate::math::Selected, false>(
            core::hint::black_box(&x),
            &z,
            &s_off,
            &t_off,
            &mut rho,
            bend::LowCut::NONE,
        );
    });
    std::println!("bend_angles: {r:.1?} ns/pt");
    let (mut xs, mut zs) = (x.clone(), z.clone());
    let r = min_med(n, 2000, || {
        smooth::taubin_smooth(
            core::hint::black_box(&mut xs),
            &mut zs,
            &mut rho,
            0.3,
            20,
            0.6307,
            -0.6732,
        );
    });
    std::println!("taubin: {r:.1?} ns/pt");
    let mut acc = 0.0f32;
    let r = min_med(n, 2000, || {
        for (a, b) in core::hint::black_box(&x).iter().zip(&z) {
            acc += a * b;
        }
    });
    std::println!("plain dependent add (latency reference): {r:.2?} ns/pt {acc}");
    let mut lines: Vec<Line<N>> = (0..400).map(|_| line_from(&buf[..n])).collect();
    let mut k = Kernel::<N>::new(KernelParams::DEFAULT);
    let mut it = lines.iter_mut();
    let r = min_med(n, 400, || {
        let out = k.process(it.next().unwrap());
        core::hint::black_box(out.left);
    });
    std::println!("whole process: {r:.1?} ns/pt");
}

/// Finite but huge coordinates would overflow in smoothing and give non-finite smoothed
/// points: the kernel sets them aside as non-finite, and every output value stays finite.
#[test]
fn huge_finite_coordinates_are_set_aside_and_every_output_stays_finite() {
    let mut pts = ideal_curb(false, false);
    pts[10].0 = f32::MAX;
    pts[11].1 = -3.0e38;
    pts[12].0 = 2000.5;
    let mut line = line_from(&pts);
    let mut k = Kernel::<N>::new(KernelParams::DEFAULT);
    let out = k.process(&mut line);
    check_accounting(&out);
    for i in [10usize, 11, 12] {
        assert_eq!(out.status[i], PointStatus::NonFinite, "point {i}");
    }
    for i in 0..out.tag.len() {
        if out.status[i] != PointStatus::NonFinite {
            assert!(
                out.x_m[i].is_finite() && out.z_m[i].is_finite(),
                "point {i}"
            );
            assert!(out.rho_deg[i].is_finite(), "rho at {i}");
        }
    }
}

/// With a region of interest, the points inside come first and get exactly what the kernel
/// gives a line of those points alone, the points outside follow with their raw
/// coordinates and tags, ρ = 0 and status OutsideRoi, and the candidates are the same.
#[test]
fn region_of_interest_is_the_kernel_on_the_points_inside() {
    let scene = Scene::DEFAULT;
    let roi = Roi {
        x_min: -6.0,
        x_max: 3.5,
        z_min: -2.5,
        z_max: -1.7,
    };
    let params = KernelParams {
        roi_x_min_m: roi.x_min,
        roi_x_max_m: roi.x_max,
        roi_z_min_m: roi.z_min,
        roi_z_max_m: roi.z_max,
        ..KernelParams::DEFAULT
    };
    assert_eq!(params.validate(), Ok(()));
    let mut checked_outside = 0;
    for seed in 0..20u64 {
        let mut buf = std::vec![(0f32, 0f32, 0u32); N];
        let n = scene.generate(&mut Rng(seed), &mut buf);
        let all = &buf[..n];
        let inside: Vec<(f32, f32, u32)> = all
            .iter()
            .copied()
            .filter(|&(x, z, _)| roi.contains(x, z))
            .collect();
        assert!(inside.len() < n && !inside.is_empty(), "seed {seed}");
        let mut k_roi = Kernel::<N>::new(params);
        let mut line = line_from(all);
        let out = k_roi.process(&mut line);
        check_accounting(&out);
        assert_eq!(out.counters.outside_roi as usize, n - inside.len());
        let mut k_sub = Kernel::<N>::new(KernelParams::DEFAULT);
        let mut sub_line = line_from(&inside);
        let sub = k_sub.process(&mut sub_line);
        let m = inside.len();
        assert_eq!(out.tag[..m], sub.tag[..]);
        assert_eq!(out.status[..m], sub.status[..]);
        for j in 0..m {
            assert_eq!(out.x_m[j].to_bits(), sub.x_m[j].to_bits(), "x at {j}");
            assert_eq!(out.z_m[j].to_bits(), sub.z_m[j].to_bits(), "z at {j}");
            assert_eq!(
                out.rho_deg[j].to_bits(),
                sub.rho_deg[j].to_bits(),
                "ρ at {j}"
            );
        }
        let mut outside: Vec<(u32, u32, u32)> = all
            .iter()
            .filter(|&&(x, z, _)| !roi.contains(x, z))
            .map(|&(x, z, t)| (t, x.to_bits(), z.to_bits()))
            .collect();
        let mut got: Vec<(u32, u32, u32)> = (m..n)
            .map(|i| (out.tag[i], out.x_m[i].to_bits(), out.z_m[i].to_bits()))
            .collect();
        outside.sort_unstable();
        got.sort_unstable();
        assert_eq!(got, outside);
        assert!(out.status[m..]
            .iter()
            .all(|&s| s == PointStatus::OutsideRoi));
        assert!(out.rho_deg[m..].iter().all(|&r| r == 0.0));
        checked_outside += n - m;
        assert_eq!(
            (out.nadir, out.left, out.right),
            (sub.nadir, sub.left, sub.right),
            "seed {seed}"
        );
        let c = sub.counters;
        assert_eq!(
            (
                out.counters.kept,
                out.counters.irregular,
                out.counters.peaks
            ),
            (c.kept, c.irregular, c.peaks)
        );
    }
    assert!(checked_outside > 100);
}

/// A region that holds every point changes nothing but the parameters' hash.
#[test]
fn a_region_holding_every_point_changes_nothing() {
    let mut buf = std::vec![(0f32, 0f32, 0u32); N];
    let n = Scene::DEFAULT.generate(&mut Rng(3), &mut buf);
    let params = KernelParams {
        roi_x_min_m: -100.0,
        roi_x_max_m: 100.0,
        roi_z_min_m: -100.0,
        roi_z_max_m: 100.0,
        ..KernelParams::DEFAULT
    };
    let mut a = Kernel::<N>::new(params);
    let mut b = Kernel::<N>::new(KernelParams::DEFAULT);
    let (mut la, mut lb) = (line_from(&buf[..n]), line_from(&buf[..n]));
    let (oa, ob) = (a.process(&mut la), b.process(&mut lb));
    assert_eq!(oa.counters, ob.counters);
    assert_eq!((oa.nadir, oa.left, oa.right), (ob.nadir, ob.left, ob.right));
    assert_eq!(oa.status, ob.status);
    assert_eq!(oa.rho_deg, ob.rho_deg);
    assert_ne!(oa.params_hash, ob.params_hash);
}

/// The lean pass changes nothing a candidates packet carries (nadir, candidates and
/// their values, every count), skips the arctangent on most points, and is off in points
/// mode; with and without a region of interest.
#[test]
fn lean_pass_keeps_the_candidates_packet() {
    let candidates = KernelParams {
        output_mode: 1,
        ..KernelParams::DEFAULT
    };
    let roi = KernelParams {
        roi_x_min_m: -6.0,
        roi_x_max_m: 3.5,
        roi_z_min_m: -2.5,
        roi_z_max_m: -1.7,
        ..candidates
    };
    let points = KernelParams {
        output_mode: 0,
        ..roi
    };
    let mut skipped = 0usize;
    for (params, lean_applies) in [(candidates, true), (roi, true), (points, false)] {
        for seed in 0..16u64 {
            let mut buf = std::vec![(0f32, 0f32, 0u32); N];
            let n = Scene::DEFAULT.generate(&mut Rng(seed), &mut buf);
            // A spike and a non-finite point, so the kept points' partition moves points
            // (a region may hold them outside).
            buf[n / 3].1 += 0.1;
            buf[n / 2].0 = f32::NAN;
            let mut full = Kernel::<N>::new(params);
            let mut lean = Kernel::<N>::new(params);
            lean.set_lean_rho(true);
            let (mut la, mut lb) = (line_from(&buf[..n]), line_from(&buf[..n]));
            let (a, b) = (full.process(&mut la), lean.process(&mut lb));
            let set_aside = a.counters.irregular + a.counters.non_finite;
            assert!(set_aside >= 2 || params.roi().is_some(), "seed {seed}");
            assert_eq!(a.counters, b.counters, "seed {seed}");
            assert_eq!((a.nadir, a.left, a.right), (b.nadir, b.left, b.right));
            assert!(a.left.is_some() && a.right.is_some(), "seed {seed}");
            for k in [a.nadir, a.left, a.right].into_iter().flatten() {
                let k = usize::from(k);
                let at = |o: &ScanlineOutput<'_>| {
                    (
                        o.tag[k],
                        o.x_m[k].to_bits(),
                        o.z_m[k].to_bits(),
                        o.rho_deg[k].to_bits(),
                        o.status[k],
                    )
                };
                assert_eq!(at(&a), at(&b), "seed {seed} point {k}");
            }
            if !lean_applies {
                let bits = |v: &[f32]| v.iter().map(|f| f.to_bits()).collect::<Vec<u32>>();
                assert_eq!(bits(a.rho_deg), bits(b.rho_deg));
                assert_eq!(bits(a.x_m), bits(b.x_m));
                assert_eq!(a.status, b.status);
            }
            skipped += b
                .rho_deg
                .iter()
                .filter(|&&r| r == params.tau_min_deg)
                .count();
        }
    }
    assert!(skipped > 16 * 1000, "{skipped}");
}
