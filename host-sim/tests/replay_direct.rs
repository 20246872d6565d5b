//! The replay feeds the core's line assembly directly by default (`[replay] wire = false`);
//! through the wire format (encoded packets, CRC, parsed back: the firmware's input) it
//! must give the same lines and the same output, bit for bit. Checked on the simulated
//! `tiny` scene, for a profiler's scanlines and for a VLP-16's half-arcs.

use curbtrace_host_sim::config::Config;
use curbtrace_host_sim::output::geojson::lines_to_geojson;
use curbtrace_host_sim::pipeline::{self, ExtractOptions, ExtractResult, Progress};
use curbtrace_host_sim::simulate::{self, spinning::SpinSensor, SpinOutput};
use curbtrace_host_sim::stream::{self, WindowParams};
use std::path::Path;

fn config(wire: bool) -> Config {
    let mut cfg = Config::default();
    cfg.replay.wire = wire;
    cfg
}

fn streamed(dir: &Path, cfg: &Config) -> ExtractResult {
    stream::extract(
        &[dir.join("points.laz")],
        &dir.join("trajectory.csv"),
        cfg,
        &ExtractOptions::default(),
        &WindowParams::default(),
        &Progress::hidden(),
    )
    .expect("streaming extract runs")
}

fn geojson(r: &ExtractResult) -> String {
    serde_json::to_string(&lines_to_geojson(&r.edges, r.crs.as_ref())).unwrap()
}

#[test]
fn scanlines_direct_and_through_the_wire_give_the_same_output() {
    let dir = tempfile::tempdir().unwrap();
    let spec = simulate::scene_by_name("tiny").expect("scene exists");
    simulate::run(&spec, 1, None, dir.path(), false).expect("simulation runs");
    let (points, traj) = (
        dir.path().join("points.laz"),
        dir.path().join("trajectory.csv"),
    );

    // The core's output per point: ρ, status, scanline, candidates, counters.
    let run = |wire: bool| {
        pipeline::replay_file(
            &points,
            &traj,
            &config(wire),
            &ExtractOptions::default(),
            &Progress::hidden(),
        )
        .expect("replay runs")
        .kernel
    };
    let (direct, mut wire) = (run(false), run(true));
    assert!(wire.counters.packets > 1 && wire.counters.bytes > 0);
    assert_eq!((direct.counters.packets, direct.counters.bytes), (0, 0));
    assert!(direct.counters.scanlines > 100 && !direct.candidates.is_empty());
    wire.counters.packets = 0;
    wire.counters.bytes = 0;
    assert!(direct == wire, "the direct replay differs from the wire's");

    // The edges of the streaming extract, byte for byte.
    let (a, b) = (
        streamed(dir.path(), &config(false)),
        streamed(dir.path(), &config(true)),
    );
    assert!(!a.edges.is_empty());
    assert_eq!(geojson(&a), geojson(&b));
}

#[test]
fn half_arcs_direct_and_through_the_wire_give_the_same_output() {
    let dir = tempfile::tempdir().unwrap();
    let mut spec = simulate::scene_by_name("tiny").expect("scene exists");
    spec.drive.1 = spec.drive.0 + 0.6 * spec.speed_kmh / 3.6;
    let spin = SpinOutput {
        sensor: &SpinSensor::VLP16,
        ring_name: Some("ring"),
    };
    simulate::run_with(&spec, 3, None, Some(spin), dir.path(), false).expect("simulation runs");
    let (a, b) = (
        streamed(dir.path(), &config(false)),
        streamed(dir.path(), &config(true)),
    );
    let (ca, cb) = (&a.summary.core, &b.summary.core);
    assert!(ca.scanlines > 50 && ca.points_sent > 10_000 && !a.edges.is_empty());
    assert!(cb.packets > 1 && ca.packets == 0);
    assert_eq!(
        (
            ca.scanlines,
            ca.kept,
            ca.irregular,
            ca.no_neighbour,
            ca.lost
        ),
        (
            cb.scanlines,
            cb.kept,
            cb.irregular,
            cb.no_neighbour,
            cb.lost
        )
    );
    assert_eq!(geojson(&a), geojson(&b));
}
