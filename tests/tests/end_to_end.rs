//! End-to-end: simulate a scene, extract road edges through the whole product (LAZ →
//! projection → wire bytes → core → seeding/tracking/post-filters), score them against the
//! simulator's ground truth (docs/spec.md §5), and assert the accuracy targets
//! (completeness ≥ 95 %, correctness ≥ 95 %, quality ≥ 90 %, RMS ≤ 20 mm at a 50 mm buffer)
//! with the one set of default parameters. On each scene the streaming extract (the product
//! path) is also held against the whole-file run within the campaign issue's ε: the matched
//! parts of the edges within 1 cm (Hausdorff, both ways) and the total quality within
//! 0.2 pp.
//!
//! Run in release (`cargo test --release`): the larger scene has millions of points.

use curbtrace_host_sim::config::Config;
use curbtrace_host_sim::eval::{agreement, evaluate, survey, EvalParams, EvalReport};
use curbtrace_host_sim::model::{read_geojson, Category};
use curbtrace_host_sim::pipeline::{self, ExtractOptions, Progress};
use curbtrace_host_sim::simulate;
use curbtrace_host_sim::stream::{self, WindowParams};
use std::path::Path;

fn simulate_extract_eval(scene: &str, seed: u64, dir: &Path) -> EvalReport {
    let spec = simulate::scene_by_name(scene).expect("scene exists");
    let sim = simulate::run(&spec, seed, None, dir, false).expect("simulation runs");
    assert!(sim.points > 100_000, "{scene}: only {} points", sim.points);
    // The product path of `curbtrace extract`: the stream with its default window.
    let result = stream::extract(
        &[dir.join("points.laz")],
        &dir.join("trajectory.csv"),
        &Config::default(),
        &ExtractOptions::default(),
        &WindowParams::default(),
        &Progress::hidden(),
    )
    .expect("extraction runs");
    assert!(!result.edges.is_empty(), "{scene}: no edges");
    for e in &result.edges {
        assert_eq!(e.method.as_deref(), Some("bend"));
        assert!(e.points.len() >= 2);
    }
    let (reference, _) = read_geojson(&dir.join("reference.geojson")).expect("reference");
    let report = evaluate(&reference, &result.edges, &EvalParams::default()).expect("evaluation");
    // The same edges as the whole-file run, within ε.
    let whole = pipeline::extract_file(
        &dir.join("points.laz"),
        &dir.join("trajectory.csv"),
        &Config::default(),
    )
    .expect("whole-file extraction runs");
    let whole_q = evaluate(&reference, &whole.edges, &EvalParams::default())
        .expect("evaluation")
        .total
        .quality_pct
        .expect("quality");
    let stream_q = report.total.quality_pct.expect("quality");
    assert!(
        (whole_q - stream_q).abs() <= 0.2,
        "{scene}: quality {stream_q:.3} % streamed, {whole_q:.3} % whole"
    );
    let g = agreement(&whole.edges, &result.edges, 0.5);
    assert!(g.matched_hausdorff_m <= 0.01, "{scene}: {g:?}");
    // The class of every stretch (curb, curb_cut, intersection, bus_bay): at least 95 % of
    // the extracted length that lies on a reference line has the reference's category.
    let s = survey(&reference, &result.edges, &EvalParams::default()).expect("survey runs");
    let right = 100.0 * s.class_right_m / s.class_checked_m.max(1e-9);
    assert!(
        s.class_checked_m > 0.0 && right >= 95.0,
        "{scene}: {right:.1} % of {:.1} m in the right class; confusion {:?}",
        s.class_checked_m,
        s.confusion
    );
    report
}

fn assert_targets(scene: &str, r: &EvalReport) {
    let t = &r.total;
    let table = r.to_markdown();
    let c = t.completeness_pct.expect("completeness");
    let p = t.correctness_pct.expect("correctness");
    let q = t.quality_pct.expect("quality");
    let rms = t.rms_mm.expect("rms");
    assert!(c >= 95.0, "{scene}: completeness {c:.1} % < 95 %\n{table}");
    assert!(p >= 95.0, "{scene}: correctness {p:.1} % < 95 %\n{table}");
    assert!(q >= 90.0, "{scene}: quality {q:.1} % < 90 %\n{table}");
    assert!(rms <= 20.0, "{scene}: RMS {rms:.1} mm > 20 mm\n{table}");
    // Both sides found, each on its own.
    for s in &r.sides {
        let q = s.total.quality_pct.unwrap_or(0.0);
        assert!(
            q >= 80.0,
            "{scene}: side {:?} quality {q:.1} %\n{table}",
            s.side
        );
    }
}

#[test]
fn tiny_meets_the_accuracy_targets() {
    let dir = tempfile::tempdir().unwrap();
    let r = simulate_extract_eval("tiny", 1, dir.path());
    assert_targets("tiny", &r);
}

#[test]
fn curvy_meets_the_accuracy_targets() {
    let dir = tempfile::tempdir().unwrap();
    let r = simulate_extract_eval("curvy", 1, dir.path());
    assert_targets("curvy", &r);
}

#[test]
fn kawasaki_meets_the_accuracy_targets() {
    let dir = tempfile::tempdir().unwrap();
    let r = simulate_extract_eval("kawasaki", 1, dir.path());
    assert_targets("kawasaki", &r);
}

/// The larger scene with intersections: the totals, and each side's intersection corners
/// (corner arcs and the visible side-street curbs) at ≥ 80 % quality, the accuracy issue's
/// target (Honma et al. reached 62.7–73.6 %).
#[test]
fn sapporo_meets_the_accuracy_targets_including_intersections() {
    let dir = tempfile::tempdir().unwrap();
    let r = simulate_extract_eval("sapporo", 1, dir.path());
    assert_targets("sapporo", &r);
    let table = r.to_markdown();
    let mut sides_with_intersections = 0;
    for s in &r.sides {
        for c in &s.categories {
            if c.category == Some(Category::Intersection) {
                sides_with_intersections += 1;
                let q = c.metrics.quality_pct.unwrap_or(0.0);
                assert!(
                    q >= 80.0,
                    "sapporo: {:?} intersection quality {q:.1} % < 80 %\n{table}",
                    s.side
                );
            }
        }
    }
    assert_eq!(sides_with_intersections, 2, "{table}");
}

/// The newcomer's command on a small scene: it must write edges, a report and pictures and
/// print the metrics table.
#[test]
fn demo_command_writes_edges_report_and_pictures() {
    let exe = env!("CARGO_MANIFEST_DIR");
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| Path::new(exe).join("../target"));
    let profile = if cfg!(debug_assertions) {
        "debug"
    } else {
        "release"
    };
    let bin = target.join(profile).join("curbtrace");
    assert!(
        bin.exists(),
        "{} not built (cargo test --workspace builds it)",
        bin.display()
    );
    let out = tempfile::tempdir().unwrap();
    let o = std::process::Command::new(&bin)
        .args(["demo", "--scene", "tiny", "--out"])
        .arg(out.path())
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "demo failed: {}\n{stdout}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(stdout.contains("Quality"), "no metrics table:\n{stdout}");
    for f in ["report.md", "edges.geojson"] {
        let p = out.path().join(f);
        assert!(p.exists(), "{} missing", p.display());
    }
    let pngs = std::fs::read_dir(out.path())
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.path().extension().is_some_and(|x| x == "png"))
        .count();
    assert!(pngs >= 2, "only {pngs} pictures");
}
