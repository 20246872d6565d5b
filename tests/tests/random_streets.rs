//! Random streets through the whole product, CI-sized: a few streets of
//! `curbtrace simulate --scene random` (tuning seeds, each cut to a few seconds of driving)
//! through simulation, extraction with the default parameters and evaluation at the 50 mm
//! buffer (docs/spec.md §5). The robustness run (`scripts/robustness.sh`) does the same on
//! 30 full streets; this test guards that every stage keeps working on streets nobody
//! placed by hand and that the simulator stays deterministic. The floors sit just below
//! what the default parameters reach on these streets (docs/results.md): they catch a
//! stage that breaks or a fix of issue 15 that is lost, not the accuracy targets of the
//! robustness run (docs/robustness-accuracy.md).
//!
//! Run in release (`cargo test --release`).

use curbtrace_host_sim::config::Config;
use curbtrace_host_sim::eval::{evaluate, EvalParams, EvalReport};
use curbtrace_host_sim::model::read_geojson;
use curbtrace_host_sim::pipeline::extract_file;
use curbtrace_host_sim::simulate::{self, SceneSpec};
use std::path::Path;

/// Metres of driving per street (a few seconds at the streets' speeds).
const DRIVE_M: f64 = 20.0;
/// Tuning seeds (the evaluation seeds 1001–1030 stay unseen).
const SEEDS: [u64; 3] = [11, 12, 13];

fn short_street(seed: u64) -> SceneSpec {
    let mut spec = simulate::scene_for("random", seed).expect("random scene");
    spec.drive.1 = spec.drive.1.min(spec.drive.0 + DRIVE_M);
    spec
}

struct Run {
    points: usize,
    reference_m: f64,
    report: EvalReport,
}

fn run(seed: u64, dir: &Path) -> Run {
    let spec = short_street(seed);
    let sim = simulate::run(&spec, seed, None, dir, false).expect("simulation runs");
    let result = extract_file(
        &dir.join("points.laz"),
        &dir.join("trajectory.csv"),
        &Config::default(),
    )
    .expect("extraction runs");
    let (reference, _) = read_geojson(&dir.join("reference.geojson")).expect("reference");
    let report =
        evaluate(&reference, &result.edges, &EvalParams::default()).expect("evaluation runs");
    Run {
        points: sim.points,
        reference_m: sim.reference_m.iter().sum(),
        report,
    }
}

#[test]
fn random_streets_run_through_the_product_with_sane_totals() {
    let mut qualities = Vec::new();
    for seed in SEEDS {
        let dir = tempfile::tempdir().unwrap();
        let r = run(seed, dir.path());
        let spec = short_street(seed);
        let table = r.report.to_markdown();
        let what = format!("seed {seed}: {}\n{table}", spec.description);
        // Plausible scene: both curbs are long reference lines, the points are within the
        // random scenes' cap and reach what the scanner fires at the least.
        let driven = spec.drive.1 - spec.drive.0;
        assert!(
            r.reference_m > driven,
            "{what}: reference {:.1} m",
            r.reference_m
        );
        assert!(r.points <= 4_000_000, "{what}: {} points", r.points);
        let seconds = driven / (spec.speed_kmh / 3.6);
        let fired = spec.scanner.line_rate_hz * seconds * spec.scanner.pulses_per_line as f64;
        assert!(r.points as f64 > 0.2 * fired, "{what}: {} points", r.points);
        let q = r.report.total.quality_pct.unwrap_or(0.0);
        let p = r.report.total.correctness_pct.unwrap_or(0.0);
        eprintln!(
            "seed {seed}: quality {q:.1} %, correctness {p:.1} %, {} points",
            r.points
        );
        qualities.push((q, p, what));
    }
    // Just under what the defaults reach on these streets (docs/results.md).
    for (q, p, what) in &qualities {
        assert!(*q >= 60.0, "{what}: quality {q:.1} %");
        assert!(*p >= 85.0, "{what}: correctness {p:.1} %");
    }
    let qualities: Vec<f64> = qualities.iter().map(|x| x.0).collect();
    let mean = qualities.iter().sum::<f64>() / qualities.len() as f64;
    assert!(mean >= 70.0, "mean quality {mean:.1} % over {qualities:?}");
}

#[test]
fn the_same_seed_gives_the_same_street_and_another_seed_another() {
    let a = tempfile::tempdir().unwrap();
    let b = tempfile::tempdir().unwrap();
    let c = tempfile::tempdir().unwrap();
    let (s1, s2) = (short_street(21), short_street(22));
    assert_ne!(s1.description, s2.description);
    simulate::run(&s1, 21, None, a.path(), false).unwrap();
    simulate::run(&short_street(21), 21, None, b.path(), false).unwrap();
    simulate::run(&s2, 22, None, c.path(), false).unwrap();
    for f in ["points.laz", "trajectory.csv", "reference.geojson"] {
        let x = std::fs::read(a.path().join(f)).unwrap();
        let y = std::fs::read(b.path().join(f)).unwrap();
        let z = std::fs::read(c.path().join(f)).unwrap();
        assert!(x == y, "{f} differs between two runs of seed 21");
        assert!(x != z, "{f} is the same for seeds 21 and 22");
    }
}
