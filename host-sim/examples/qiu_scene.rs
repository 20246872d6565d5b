//! Measures the Qiu et al. method on a simulated scene, in memory (no LAS round trip):
//! simulate → `qiu::extract_edges` → evaluation at 50 mm and 200 mm.
//!
//! `cargo run --release -p curbtrace-host-sim --example qiu_scene -- SCENE [SEED] [OUT_DIR]`
//!
//! or, on files written by `curbtrace simulate` (the same path as `curbtrace extract`:
//! LAS/LAZ points, CSV trajectory), `… --example qiu_scene -- DIR` with `DIR/points.laz`,
//! `DIR/trajectory.csv` and `DIR/reference.geojson`; the lines go to `DIR/qiu.geojson`.
//!
//! Prints the metric tables, the per-section report and the method's throughput (points/s
//! and ms per metre of road, the paper's unit). With OUT_DIR, writes `qiu.geojson` and
//! `reference.geojson` there for QGIS or `curbtrace eval`.

use curbtrace_host_sim::eval::{evaluate, EvalParams};
use curbtrace_host_sim::io::trajectory::Trajectory;
use curbtrace_host_sim::model::{read_geojson, Crs};
use curbtrace_host_sim::output::geojson::write_geojson;
use curbtrace_host_sim::pipeline;
use curbtrace_host_sim::qiu::{extract_edges_with_report, QiuInput, QiuParams};
use curbtrace_host_sim::simulate;
use std::time::Instant;

/// CPU seconds (user + system) of this process so far, from `/proc/self/stat` (Linux);
/// on a shared machine the wall clock says little, the CPU time says what the method cost.
fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    let rest = &stat[stat.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: f64 = f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0)
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let scene = args.get(1).map(String::as_str).unwrap_or("tiny");
    let seed: u64 = args.get(2).map(|s| s.parse()).transpose()?.unwrap_or(1);
    let out = args.get(3).map(std::path::PathBuf::from);
    let params = match std::env::var("QIU_CONFIG") {
        Ok(p) => toml::from_str::<QiuParams>(&std::fs::read_to_string(&p)?)?,
        Err(_) => QiuParams::default(),
    };
    params.validate()?;

    let dir_in = std::path::Path::new(scene);
    let from_files = dir_in.join("points.laz").is_file();
    let t0 = Instant::now();
    let (x, y, z, t, traj, reference, length_m, crs) = if from_files {
        let (cols, las, traj, _, _) = pipeline::load(
            &dir_in.join("points.laz"),
            &dir_in.join("trajectory.csv"),
            &pipeline::ExtractOptions::default(),
            &pipeline::Progress::hidden(),
        )?;
        let (reference, _) = read_geojson(&dir_in.join("reference.geojson"))?;
        let length_m = traj
            .samples
            .windows(2)
            .map(|w| (w[1].x - w[0].x).hypot(w[1].y - w[0].y))
            .sum::<f64>();
        (
            cols.x, cols.y, cols.z, cols.t, traj, reference, length_m, las.crs,
        )
    } else {
        let spec = simulate::scene_by_name(scene)?;
        let sim = simulate::simulate(&spec, seed, None, false)?;
        let o = sim.world.spec.origin;
        let n = sim.returns.len();
        let (mut x, mut y, mut z, mut t) = (
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
        );
        for r in &sim.returns {
            x.push(r.p[0] + o[0]);
            y.push(r.p[1] + o[1]);
            z.push(r.p[2] + o[2]);
            t.push(r.t);
        }
        let mut traj = Trajectory {
            samples: sim.traj.samples.clone(),
        };
        for s in &mut traj.samples {
            s.x += o[0];
            s.y += o[1];
            s.z += o[2];
        }
        (
            x,
            y,
            z,
            t,
            traj,
            sim.reference,
            sim.length_m,
            Some(Crs::Epsg(spec.epsg)),
        )
    };
    let sim_s = t0.elapsed().as_secs_f64();
    let n = x.len();
    let input = QiuInput {
        x: &x,
        y: &y,
        z: &z,
        t: &t,
        trajectory: &traj,
    };
    let t0 = Instant::now();
    let c0 = cpu_seconds();
    let (lines, report) = extract_edges_with_report(&input, &params);
    let qiu_s = t0.elapsed().as_secs_f64();
    let qiu_cpu_s = c0.and_then(|c0| Some(cpu_seconds()? - c0));
    let threads = rayon::current_num_threads();
    println!(
        "scene {scene} seed {seed}: {n} points, {length_m:.1} m driven, simulated or read in {sim_s:.1} s"
    );
    println!(
        "qiu: {} lines, {:.1} m, in {qiu_s:.2} s on {threads} threads: {:.2} M points/s, {:.1} ms per metre of road (paper: 150 ms/m, one thread, C++)",
        lines.len(),
        lines.iter().map(|l| l.length_m()).sum::<f64>(),
        n as f64 / qiu_s / 1e6,
        1e3 * qiu_s / length_m
    );
    if let Some(c) = qiu_cpu_s {
        println!(
            "qiu CPU time {c:.2} s (all threads): {:.2} M points per CPU-second, {:.1} CPU-ms per metre of road",
            n as f64 / c / 1e6,
            1e3 * c / length_m
        );
    }
    for s in &report.sections {
        let sec = s.section.expect("set");
        println!(
            "  section {} [{:.0}, {:.0}] m: {} points in, {} after §3.2, β = {:?}, {} candidates, width {:?}, {} kept by width, {} chains; stage seconds {:.2?}",
            sec.index, sec.s_start, sec.s_end, s.points_in, s.points_preprocessed, s.beta_m,
            s.candidates, s.road_width_m, s.width_kept, s.chains, s.stage_s
        );
        if std::env::var("QIU_VERBOSE").is_ok() {
            println!("    energies {:?}", s.energies);
        }
    }
    for buffer in [0.05, 0.2] {
        let ev = evaluate(
            &reference,
            &lines,
            &EvalParams {
                buffer_m: buffer,
                ..EvalParams::default()
            },
        )?;
        println!(
            "\n### buffer {:.0} mm\n\n{}",
            buffer * 1e3,
            ev.to_markdown()
        );
    }
    if let Ok(dir) = std::env::var("QIU_PLOT") {
        plot_windows(
            std::path::Path::new(&dir),
            &x,
            &y,
            &z,
            &reference,
            &lines,
            &report,
        )?;
    }
    let out = out.or_else(|| from_files.then(|| dir_in.to_path_buf()));
    if let Some(dir) = out {
        std::fs::create_dir_all(&dir)?;
        write_geojson(&dir.join("qiu.geojson"), &lines, crs.as_ref())?;
        if !from_files {
            write_geojson(&dir.join("reference.geojson"), &reference, crs.as_ref())?;
        }
    }
    Ok(())
}

/// `QIU_PLOT=DIR`: top views of every intersection, bus bay, curb cut and gap, with the
/// candidates kept by the width step drawn as short dashes beside the output lines.
fn plot_windows(
    dir: &std::path::Path,
    x: &[f64],
    y: &[f64],
    z: &[f64],
    reference: &[curbtrace_host_sim::model::EdgeLine],
    lines: &[curbtrace_host_sim::model::EdgeLine],
    report: &curbtrace_host_sim::qiu::QiuReport,
) -> anyhow::Result<()> {
    use curbtrace_host_sim::model::EdgeLine;
    use curbtrace_host_sim::plot::{top_view_png, Cloud, TopView, Window};
    std::fs::create_dir_all(dir)?;
    let mut drawn: Vec<EdgeLine> = lines.to_vec();
    for s in &report.sections {
        for (p, kept) in &s.candidate_points {
            let d = if *kept { 0.06 } else { 0.02 };
            let mut l = lines
                .first()
                .cloned()
                .unwrap_or_else(|| reference[0].clone());
            l.points = vec![*p, [p[0] + d, p[1] + d, p[2]]];
            drawn.push(l);
        }
    }
    let mut wins: Vec<(String, Window)> = Vec::new();
    for (k, r) in reference.iter().enumerate() {
        if r.category.is_some_and(|c| c.as_str() != "curb") {
            let m = r.points[r.points.len() / 2];
            wins.push((
                format!("{k}_{}", r.category.unwrap().as_str()),
                Window {
                    center: [m[0], m[1]],
                    half_size_m: 12.0,
                },
            ));
        }
    }
    let cloud = Cloud { x, y, z };
    for (name, w) in wins {
        let mut v = TopView::new(name.clone(), cloud, reference, &drawn);
        v.window = Some(w);
        v.max_points = 150_000;
        v.width_px = 1000;
        top_view_png(&dir.join(format!("{name}.png")), &v)?;
    }
    Ok(())
}
