//! The streaming extract with its default window against the whole-file run on the four
//! named scenes, within the campaign issue's ε: the matched parts of the edges within 1 cm
//! (Hausdorff, both ways) and the total quality against the reference within 0.2 pp.

use curbtrace_host_sim::config::Config;
use curbtrace_host_sim::eval::{agreement, evaluate, EvalParams};
use curbtrace_host_sim::model::read_geojson;
use curbtrace_host_sim::pipeline::{self, ExtractOptions, Progress};
use curbtrace_host_sim::simulate;
use curbtrace_host_sim::stream::{self, WindowParams};

fn within_epsilon(scene: &str) {
    let dir = tempfile::tempdir().unwrap();
    let spec = simulate::scene_by_name(scene).expect("scene exists");
    simulate::run(&spec, 1, None, dir.path(), false).expect("simulation runs");
    let (pts, traj) = (
        dir.path().join("points.laz"),
        dir.path().join("trajectory.csv"),
    );
    let whole = pipeline::extract_file(&pts, &traj, &Config::default()).unwrap();
    let streamed = stream::extract(
        std::slice::from_ref(&pts),
        &traj,
        &Config::default(),
        &ExtractOptions::default(),
        &WindowParams::default(),
        &Progress::hidden(),
    )
    .unwrap();
    assert!(!whole.edges.is_empty(), "{scene}: no edges");
    let (reference, _) = read_geojson(&dir.path().join("reference.geojson")).unwrap();
    let q = |e| {
        evaluate(&reference, e, &EvalParams::default())
            .unwrap()
            .total
            .quality_pct
            .unwrap()
    };
    let (qw, qs) = (q(&whole.edges), q(&streamed.edges));
    assert!(
        (qw - qs).abs() <= 0.2,
        "{scene}: quality {qs:.3} % streamed, {qw:.3} % whole"
    );
    let g = agreement(&whole.edges, &streamed.edges, 0.5);
    assert!(g.matched_hausdorff_m <= 0.01, "{scene}: {g:?}");
}

#[test]
fn tiny_streams_within_epsilon() {
    within_epsilon("tiny");
}

#[test]
fn curvy_streams_within_epsilon() {
    within_epsilon("curvy");
}

#[test]
fn sapporo_streams_within_epsilon() {
    within_epsilon("sapporo");
}

#[test]
fn kawasaki_streams_within_epsilon() {
    within_epsilon("kawasaki");
}
