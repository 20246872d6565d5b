//! The streaming extract against the whole-file run on a simulated scene directory
//! (`curbtrace simulate --scene S -o DIR`): quality of each against the reference, the
//! Hausdorff distance of their matched parts, CPU of each run. For choosing the window
//! (docs/benchmarks.md).
//!
//! `cargo run --release -p curbtrace-host-sim --example stream_epsilon -- DIR SECTION_M MARGIN_M`

use curbtrace_host_sim::config::Config;
use curbtrace_host_sim::eval::{agreement, evaluate, EvalParams};
use curbtrace_host_sim::model::read_geojson;
use curbtrace_host_sim::pipeline::{self, ExtractOptions, Progress};
use curbtrace_host_sim::proc_stats::process_cpu_s;
use curbtrace_host_sim::stream::{self, WindowParams};
use std::path::PathBuf;

fn main() -> anyhow::Result<()> {
    let a: Vec<String> = std::env::args().collect();
    let dir = PathBuf::from(&a[1]);
    let w = WindowParams {
        section_m: a[2].parse()?,
        margin_m: a[3].parse()?,
        ..WindowParams::default()
    };
    let (pts, traj) = (dir.join("points.laz"), dir.join("trajectory.csv"));
    let c0 = process_cpu_s();
    let whole = pipeline::extract_file(&pts, &traj, &Config::default())?;
    let c1 = process_cpu_s();
    let s = stream::extract(
        std::slice::from_ref(&pts),
        &traj,
        &Config::default(),
        &ExtractOptions::default(),
        &w,
        &Progress::hidden(),
    )?;
    let c2 = process_cpu_s();
    let (reference, _) = read_geojson(&dir.join("reference.geojson"))?;
    let q = |e| {
        evaluate(&reference, e, &EvalParams::default()).map(|r| r.total.quality_pct.unwrap_or(0.0))
    };
    let (qw, qs) = (q(&whole.edges)?, q(&s.edges)?);
    let g = agreement(&whole.edges, &s.edges, 0.5);
    println!(
        "{} L {} M {}: quality whole {qw:.3} stream {qs:.3} diff {:.3} pp; matched Hausdorff {:.4} m; unmatched {:?} of {:?}; cpu whole {:.2} s stream {:.2} s (read {:.2} core {:.2} edges {:.2})",
        dir.display(),
        w.section_m,
        w.margin_m,
        qs - qw,
        g.matched_hausdorff_m,
        g.unmatched,
        g.vertices,
        c1 - c0,
        c2 - c1,
        s.summary.times.cpu.read_s,
        s.summary.times.cpu.core_s,
        s.summary.times.cpu.edges_s,
    );
    Ok(())
}
