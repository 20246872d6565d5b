//! One edge per curb from several observations of it, end to end on a few seconds of
//! kawasaki (a parked car at the left curb):
//! - two scanners in an X: `simulate --scanners 2` writes one file of two channels; extract
//!   reads both by default, each through its own core and tracker, and fuses them into one
//!   edge per curb that covers at least what either scanner alone covers;
//! - two passes: `simulate --passes 2` drives the street back with a GNSS offset; extract
//!   finds the passes from the trajectory, turns and shifts the second onto the first and
//!   fuses them, with no parallel copies and at least the better pass's quality.

use curbtrace_host_sim::config::Config;
use curbtrace_host_sim::eval::{evaluate, EvalParams};
use curbtrace_host_sim::model::{read_geojson, EdgeLine};
use curbtrace_host_sim::mounts::Mounts;
use curbtrace_host_sim::pipeline::{ExtractOptions, Progress};
use curbtrace_host_sim::stream::{self, WindowParams};

/// Toe length lying within 0.3 m and 15° of another stretch of the same side, away from
/// that stretch's ends (where consecutive stretches of one edge meet).
fn doubled_m(lines: &[EdgeLine]) -> f64 {
    let dist = |q: [f64; 2], a: [f64; 3], b: [f64; 3]| {
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let l2 = dx * dx + dy * dy;
        let t = if l2 > 0.0 {
            (((q[0] - a[0]) * dx + (q[1] - a[1]) * dy) / l2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (q[0] - a[0] - t * dx).hypot(q[1] - a[1] - t * dy)
    };
    let mut doubled = 0.0;
    for (i, l) in lines.iter().enumerate() {
        for w in l.points.windows(2) {
            let m = [(w[0][0] + w[1][0]) / 2.0, (w[0][1] + w[1][1]) / 2.0];
            let ang = (w[1][1] - w[0][1]).atan2(w[1][0] - w[0][0]);
            let hit = lines.iter().enumerate().any(|(j, o)| {
                let ends = [o.points[0], o.points[o.points.len() - 1]];
                j != i
                    && o.side == l.side
                    && ends.iter().all(|e| (e[0] - m[0]).hypot(e[1] - m[1]) >= 0.6)
                    && o.points.windows(2).any(|v| {
                        let a2 = (v[1][1] - v[0][1]).atan2(v[1][0] - v[0][0]);
                        let da = ((ang - a2 + std::f64::consts::FRAC_PI_2)
                            .rem_euclid(std::f64::consts::PI)
                            - std::f64::consts::FRAC_PI_2)
                            .abs();
                        da < 15f64.to_radians() && dist(m, v[0], v[1]) < 0.3
                    })
            });
            if hit {
                doubled += (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]);
            }
        }
    }
    doubled
}

/// The strict reference is written beside `reference` in `dir`, and joining only adds length.
fn assert_strict_within(reference: &[EdgeLine], dir: &std::path::Path) {
    let (strict, _) = read_geojson(&dir.join("reference_strict.geojson")).unwrap();
    let length = |lines: &[EdgeLine]| lines.iter().map(EdgeLine::length_m).sum::<f64>();
    assert!(!strict.is_empty());
    assert!(length(&strict) <= length(reference) + 1e-9);
}

#[test]
fn two_scanners_fused_cover_what_either_covers_once() {
    let dir = tempfile::tempdir().unwrap();
    let mut spec = curbtrace_host_sim::simulate::scene_by_name("kawasaki").unwrap();
    spec.drive = (56.0, 80.0);
    let s = curbtrace_host_sim::simulate::dual::run_two(&spec, 5, None, dir.path(), false).unwrap();
    let cfg = Config {
        scanners: Mounts::read(&dir.path().join("mounts.toml")).unwrap(),
        ..Config::default()
    };
    assert_eq!(cfg.scanners.get(1).yaw_deg, -cfg.scanners.get(0).yaw_deg);
    let (reference, _) = read_geojson(&s.reference_path).unwrap();
    assert_strict_within(&reference, dir.path());
    let run = |scanner: Option<u16>| {
        let opts = ExtractOptions {
            scanner,
            ..ExtractOptions::default()
        };
        stream::extract(
            std::slice::from_ref(&s.points_path),
            &s.trajectory_path,
            &cfg,
            &opts,
            &WindowParams::default(),
            &Progress::hidden(),
        )
        .unwrap()
        .edges
    };
    let score = |edges: &[EdgeLine]| {
        let r = evaluate(&reference, edges, &EvalParams::default()).unwrap();
        (
            r.total.completeness_pct.unwrap(),
            r.total.correctness_pct.unwrap(),
        )
    };
    let (s0, s1, fused) = (run(Some(0)), run(Some(1)), run(None));
    let (c0, p0) = score(&s0);
    let (c1, p1) = score(&s1);
    let (cf, pf) = score(&fused);
    eprintln!(
        "scanner 0 C {c0:.1} P {p0:.1}; scanner 1 C {c1:.1} P {p1:.1}; fused C {cf:.1} P {pf:.1}"
    );
    // One scanner alone names no scanners; fused stretches name theirs, both appear.
    assert!(s0
        .iter()
        .all(|e| e.detail.as_ref().unwrap().scanner.is_empty()));
    let mut named: Vec<u16> = fused
        .iter()
        .flat_map(|e| e.detail.as_ref().unwrap().scanners())
        .collect();
    named.sort_unstable();
    named.dedup();
    assert_eq!(named, vec![0, 1]);
    // Fused covers at least what the better scanner covers, and is about as correct.
    assert!(cf >= c0.max(c1), "fused C {cf} < single {c0} / {c1}");
    assert!(pf >= p0.min(p1) - 1.0, "fused P {pf} vs {p0} / {p1}");
    // One edge per curb: no parallel copies.
    let d = doubled_m(&fused);
    assert!(d < 0.5, "{d} m of fused toe beside another stretch");
}

#[test]
fn two_passes_fused_give_one_edge_per_curb_at_least_as_good_as_either() {
    let dir = tempfile::tempdir().unwrap();
    let mut spec = curbtrace_host_sim::simulate::scene_by_name("kawasaki").unwrap();
    spec.drive = (56.0, 90.0);
    let s =
        curbtrace_host_sim::simulate::passes::run_passes(&spec, 5, None, 0.1, dir.path(), false)
            .unwrap();
    let (reference, _) = read_geojson(&s.reference_path).unwrap();
    assert_strict_within(&reference, dir.path());
    let run = |pass: Option<u16>| {
        let opts = ExtractOptions {
            pass,
            ..ExtractOptions::default()
        };
        stream::extract(
            std::slice::from_ref(&s.points_path),
            &s.trajectory_path,
            &Config::default(),
            &opts,
            &WindowParams::default(),
            &Progress::hidden(),
        )
        .unwrap()
        .edges
    };
    let quality = |edges: &[EdgeLine]| {
        evaluate(&reference, edges, &EvalParams::default())
            .unwrap()
            .total
            .quality_pct
            .unwrap()
    };
    let (p0, p1, fused) = (run(Some(0)), run(Some(1)), run(None));
    let (q0, q1, qf) = (quality(&p0), quality(&p1), quality(&fused));
    eprintln!("pass 0 Q {q0:.1}; pass 1 Q {q1:.1}; fused Q {qf:.1}");
    // Both passes placed stretches of the fused edges, and the fused edges score at least
    // what the better pass alone does (pass 1 alone still carries its 0.1 m offset).
    let mut named: Vec<u16> = fused
        .iter()
        .flat_map(|e| e.detail.as_ref().unwrap().passes())
        .collect();
    named.sort_unstable();
    named.dedup();
    assert_eq!(named, vec![0, 1]);
    assert!(qf >= q0.max(q1), "fused Q {qf} < single pass {q0} / {q1}");
    let d = doubled_m(&fused);
    assert!(d < 0.5, "{d} m of fused toe beside another stretch");
}
