//! `curbtrace demo [--out DIR] [--method bend|qiu]`: simulates a scene, extracts its road
//! edges, evaluates them and writes the edges, `report.md`, `eval.json` and the pictures
//! (docs/spec.md §4). Needs no input files.
//!
//! The steps after extraction live in the library
//! ([`curbtrace_host_sim::eval::report::write_demo_outputs`]) so the end-to-end tests can
//! run them too; this file strings the stages together.

use anyhow::Context;
use clap::ValueEnum;
use curbtrace_core::kernel::{Kernel, KernelParams, PointStatus};
use curbtrace_core::scanline::Line;
use curbtrace_host_sim::config::Config;
use curbtrace_host_sim::eval::report::{write_demo_outputs, DemoInputs};
use curbtrace_host_sim::model::{Crs, EdgeLine, Side};
use curbtrace_host_sim::output::geojson::write_geojson;
use curbtrace_host_sim::pipeline::{self, ExtractOptions, Method, Progress};
use curbtrace_host_sim::plot::{Cloud, CrossSection, Window};
use curbtrace_host_sim::qiu::{self, QiuInput, QiuParams};
use curbtrace_host_sim::simulate::{self, scanner::Return, Simulation};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Which method the demo runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum MethodArg {
    /// The bend-angle method of Honma et al., through the core.
    Bend,
    /// The plane-based method of Qiu et al.
    Qiu,
}

impl MethodArg {
    /// The spelling in outputs.
    pub fn as_str(self) -> &'static str {
        match self {
            MethodArg::Bend => "bend",
            MethodArg::Qiu => "qiu",
        }
    }
}

/// Arguments of `curbtrace demo`.
#[derive(clap::Args)]
pub struct Args {
    /// Directory for the simulated scene, the edges, the report and the pictures.
    #[arg(long, default_value = "demo-out", value_name = "DIR")]
    pub out: PathBuf,
    /// Extraction method.
    #[arg(long, value_enum, default_value_t = MethodArg::Bend)]
    pub method: MethodArg,
    /// Scene to simulate (`kawasaki` has every feature the pictures zoom into: curb cuts,
    /// intersections, parked cars and a bus bay; `tiny` is quickest).
    #[arg(long, default_value = "kawasaki", value_name = "NAME")]
    pub scene: String,
    /// Seed of the simulation.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

/// What the extraction step hands to the report.
struct Extracted {
    edges: Vec<EdgeLine>,
    /// (stage, seconds).
    timings: Vec<(String, f64)>,
    /// (what, value): points read, scanlines, candidates …
    facts: Vec<(String, String)>,
    /// (name, value) of the method's parameters.
    parameters: Vec<(String, String)>,
}

/// Flattens a serialised parameter struct into (dotted name, value) rows for the report.
fn parameter_rows(prefix: &str, v: &serde_json::Value, out: &mut Vec<(String, String)>) {
    match v {
        serde_json::Value::Object(m) => {
            for (k, v) in m {
                let name = if prefix.is_empty() {
                    k.clone()
                } else {
                    format!("{prefix}.{k}")
                };
                parameter_rows(&name, v, out);
            }
        }
        // Parameters are f32 in the core: print the shortest decimal that round-trips
        // through f32 (0.07, not 0.07000000029802322).
        serde_json::Value::Number(n) if n.is_f64() => {
            let v = n.as_f64().unwrap_or(f64::NAN);
            let short = if (v as f32) as f64 == v {
                format!("{}", v as f32)
            } else {
                format!("{v}")
            };
            out.push((prefix.to_string(), short))
        }
        other => out.push((prefix.to_string(), other.to_string())),
    }
}

/// Extracts the edges from the simulated files in `out` with `method`, reading them back
/// as `curbtrace extract` would (the same library calls).
fn extract(out: &Path, method: MethodArg, cfg: &Config, tty: bool) -> anyhow::Result<Extracted> {
    let points = out.join("points.laz");
    let traj = out.join("trajectory.csv");
    let progress = if tty {
        Progress::bar()
    } else {
        Progress::hidden()
    };
    let mut parameters = Vec::new();
    match method {
        MethodArg::Bend => {
            let opts = ExtractOptions {
                scanner: None,
                pass: None,
                method: Method::Bend,
            };
            let r = pipeline::extract_file_with(&points, &traj, cfg, &opts, &progress)?;
            let s = &r.summary;
            parameter_rows("", &serde_json::to_value(cfg)?, &mut parameters);
            Ok(Extracted {
                timings: vec![
                    ("extract: reading LAZ".into(), s.times.read_s),
                    ("extract: trajectory".into(), s.times.trajectory_s),
                    ("extract: projection + core".into(), s.times.core_s),
                    (
                        "extract: seeding, tracking, filters".into(),
                        s.times.edges_s,
                    ),
                    ("extract: total".into(), s.times.total_s),
                ],
                facts: vec![
                    ("points read".into(), s.points_read().to_string()),
                    ("scanlines (core)".into(), s.core.scanlines.to_string()),
                    ("seed candidates (core)".into(), s.candidates.to_string()),
                    (
                        "edges".into(),
                        format!("{}, {:.1} m", s.edges, s.total_length_m),
                    ),
                    (
                        "extraction speed".into(),
                        format!(
                            "{:.2} M points/s (this build)",
                            s.points_read() as f64 / s.times.total_s.max(1e-9) / 1e6
                        ),
                    ),
                ],
                edges: r.edges,
                parameters,
            })
        }
        MethodArg::Qiu => {
            let opts = ExtractOptions {
                scanner: None,
                pass: None,
                method: Method::Qiu,
            };
            let t = Instant::now();
            let (cols, _las, trajectory, _dropped, times) =
                pipeline::load(&points, &traj, &opts, &progress)?;
            let params = QiuParams::default();
            let t_edges = Instant::now();
            let input = QiuInput {
                x: &cols.x,
                y: &cols.y,
                z: &cols.z,
                t: &cols.t,
                trajectory: &trajectory,
            };
            let mut edges = qiu::extract_edges(&input, &params);
            for e in &mut edges {
                e.method.get_or_insert_with(|| "qiu".to_string());
            }
            let edges_s = t_edges.elapsed().as_secs_f64();
            progress.finish();
            parameter_rows("qiu", &serde_json::to_value(&params)?, &mut parameters);
            let len: f64 = edges.iter().map(|e| e.length_m()).sum();
            Ok(Extracted {
                timings: vec![
                    ("extract: reading LAZ".into(), times.read_s),
                    ("extract: trajectory".into(), times.trajectory_s),
                    ("extract: Qiu et al. method".into(), edges_s),
                    ("extract: total".into(), t.elapsed().as_secs_f64()),
                ],
                facts: vec![
                    ("points read".into(), cols.x.len().to_string()),
                    ("edges".into(), format!("{}, {len:.1} m", edges.len())),
                ],
                edges,
                parameters,
            })
        }
    }
}

/// Runs `curbtrace demo`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let start = Instant::now();
    let spec = simulate::scene_by_name(&args.scene)?;
    let out = &args.out;
    std::fs::create_dir_all(out).with_context(|| format!("{}: cannot create", out.display()))?;
    let tty = std::io::stderr().is_terminal();

    // 1. Simulate once in memory (the pictures need the points) and write the files.
    let t = Instant::now();
    let sim = simulate::simulate(&spec, args.seed, None, tty)?;
    let origin = sim.world.spec.origin;
    let crs = Crs::Epsg(spec.epsg);
    simulate::write::write_points(&out.join("points.laz"), &sim.returns, origin, spec.epsg)?;
    simulate::write::write_trajectory(&out.join("trajectory.csv"), &sim.traj, origin)?;
    write_geojson(&out.join("reference.geojson"), &sim.reference, Some(&crs))?;
    let simulate_s = t.elapsed().as_secs_f64();
    if tty {
        eprintln!(
            "simulated {}: {} points, {} scanlines, {:.0} m driven ({simulate_s:.1} s)",
            spec.name,
            sim.returns.len(),
            sim.lines,
            sim.length_m
        );
    }

    // 2. Extract.
    let cfg = Config::default();
    let ex = extract(out, args.method, &cfg, tty)?;
    write_geojson(&out.join("edges.geojson"), &ex.edges, Some(&crs))?;

    // 3. One scanline through the core, for the cross-section picture.
    let profile = scanline_profile(&sim, &cfg.kernel);

    // 4. Evaluate, draw, report.
    let [x, y, z] = sim.world_columns();
    let traj = sim.world_trajectory_xy();
    let cross_section = profile.as_ref().map(|p| CrossSection {
        title: format!(
            "scanline {} of {} ({} points): bend angles before and after Taubin smoothing",
            p.line,
            sim.lines,
            p.raw_x.len()
        ),
        raw_x_m: &p.raw_x,
        raw_z_m: &p.raw_z,
        raw_rho_deg: &p.raw_rho,
        smooth_x_m: &p.smooth_x,
        smooth_z_m: &p.smooth_z,
        smooth_rho_deg: &p.smooth_rho,
        candidates: &p.candidates,
        tau_deg: Some(p.tau_deg),
        x_range_m: p.x_range_m,
        z_range_m: p.z_range_m,
    });
    let mut facts = vec![
        ("scene".to_string(), spec.name.clone()),
        ("seed".to_string(), args.seed.to_string()),
        ("points".to_string(), sim.returns.len().to_string()),
        ("scanlines".to_string(), sim.lines.to_string()),
        ("driven".to_string(), format!("{:.1} m", sim.length_m)),
        (
            "scan duration".to_string(),
            format!("{:.1} s", sim.scan.1 - sim.scan.0),
        ),
        ("CRS".to_string(), format!("EPSG:{}", spec.epsg)),
    ];
    facts.extend(ex.facts);
    let mut timings = vec![("simulation (incl. writing LAZ)".to_string(), simulate_s)];
    timings.extend(ex.timings);
    let inputs = DemoInputs {
        scene: spec.name.clone(),
        method: args.method.as_str().to_string(),
        command: format!(
            "curbtrace demo --out {} --method {} --scene {} --seed {}",
            out.display(),
            args.method.as_str(),
            spec.name,
            args.seed
        ),
        cloud: Cloud {
            x: &x,
            y: &y,
            z: &z,
        },
        trajectory_xy: &traj,
        reference: &sim.reference,
        extracted: &ex.edges,
        cross_section,
        extra_windows: parked_car_windows(&sim),
        facts,
        parameters: ex.parameters,
        timings,
        files: vec![
            (
                "points.laz".into(),
                "simulated points (LAS 1.4, format 6)".into(),
            ),
            ("trajectory.csv".into(), "the scanner's trajectory".into()),
            (
                "reference.geojson".into(),
                "reference lines (curb toes)".into(),
            ),
            ("edges.geojson".into(), "extracted road edges".into()),
        ],
    };
    let outputs = write_demo_outputs(out, &inputs)?;
    print!("{}", outputs.eval.to_markdown());
    println!(
        "\nreport: {} ({} pictures, {:.1} s in all)",
        outputs.report.display(),
        outputs.pictures.len(),
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

/// Zoom windows on the first parked car of each side (centred on the curb beside it, world
/// coordinates), from the scene description.
fn parked_car_windows(sim: &Simulation) -> Vec<(String, String, Window)> {
    let s = &sim.world.spec;
    let o = s.origin;
    let mut out = Vec::new();
    for side in [Side::Left, Side::Right] {
        if let Some(&(_, u)) = s.parked_cars.iter().find(|(sd, _)| *sd == side) {
            let hw = s.half_width_at(side, u);
            let v = if side == Side::Left { hw } else { -hw };
            let p = sim.world.center.map(u, v);
            out.push((
                format!("parked_car_{}", side.as_str()),
                format!("Zoom: a parked car hiding the {} curb", side.as_str()),
                Window {
                    center: [p[0] + o[0], p[1] + o[1]],
                    half_size_m: curbtrace_host_sim::eval::report::ZOOM_HALF_SIZE_M,
                },
            ));
        }
    }
    out
}

/// Largest scanline the demo's cross-section takes (the simulated scanner sends 2000
/// pulses per line).
const PROFILE_CAP: usize = 4096;

/// One scanline through the core, with and without smoothing.
struct Profile {
    line: usize,
    raw_x: Vec<f64>,
    raw_z: Vec<f64>,
    raw_rho: Vec<f64>,
    smooth_x: Vec<f64>,
    smooth_z: Vec<f64>,
    smooth_rho: Vec<f64>,
    candidates: Vec<usize>,
    tau_deg: (f64, f64),
    x_range_m: Option<(f64, f64)>,
    z_range_m: Option<(f64, f64)>,
}

/// The returns of scanline `k` (time-sorted returns; line k starts at scan.0 + k / rate).
fn line_returns(sim: &Simulation, k: usize) -> &[Return] {
    let rate = sim.world.spec.scanner.line_rate_hz;
    let t0 = sim.scan.0 + k as f64 / rate;
    let t1 = sim.scan.0 + (k + 1) as f64 / rate;
    let a = sim.returns.partition_point(|r| r.t < t0);
    let b = sim.returns.partition_point(|r| r.t < t1);
    &sim.returns[a..b]
}

/// Runs the core on one scanline near the middle of the drive, twice: with `params` (ρ after
/// smoothing, candidates) and with no Taubin steps (ρ before smoothing). Picks the first
/// line from the middle on where the core finds a candidate on both sides.
fn scanline_profile(sim: &Simulation, params: &KernelParams) -> Option<Profile> {
    let raw_params = KernelParams {
        taubin_steps: 0,
        ..*params
    };
    let mut kernel: Box<Kernel<PROFILE_CAP>> = Box::new(Kernel::new(*params));
    let mut raw_kernel: Box<Kernel<PROFILE_CAP>> = Box::new(Kernel::new(raw_params));
    let mut line: Box<Line<PROFILE_CAP>> = Box::new(Line::new());
    let mid = sim.lines / 2;
    for k in (mid..sim.lines.min(mid + 200)).chain((mid.saturating_sub(200)..mid).rev()) {
        let rs = line_returns(sim, k);
        if rs.len() < 10 || rs.len() > PROFILE_CAP {
            continue;
        }
        // Step (a), Eq. 1–2 in scene-local coordinates.
        let mut xz = Vec::with_capacity(rs.len());
        for r in rs {
            let q = sim.traj.pose_at(r.t)?;
            let l = q.left();
            xz.push(((r.p[0] - q.x) * l[0] + (r.p[1] - q.y) * l[1], r.p[2] - q.z));
        }
        let fill = |line: &mut Line<PROFILE_CAP>| {
            line.clear();
            for (i, &(x, z)) in xz.iter().enumerate() {
                // Cannot fail: the length was checked against the capacity above.
                let _ = line.push(x as f32, z as f32, i as u32);
            }
        };
        fill(&mut line);
        let o = kernel.process(&mut line);
        let (Some(left), Some(right)) = (o.left, o.right) else {
            continue;
        };
        let kept = |s: &[PointStatus], i: usize| s.get(i) == Some(&PointStatus::Kept);
        let nan_unless_kept = |rho: &[f32], s: &[PointStatus]| -> Vec<f64> {
            (0..rho.len())
                .map(|i| if kept(s, i) { rho[i] as f64 } else { f64::NAN })
                .collect()
        };
        let smooth_x: Vec<f64> = o.x_m.iter().map(|&v| v as f64).collect();
        let smooth_z: Vec<f64> = o.z_m.iter().map(|&v| v as f64).collect();
        let smooth_rho = nan_unless_kept(o.rho_deg, o.status);
        let candidates = vec![left as usize, right as usize];
        fill(&mut line);
        let o = raw_kernel.process(&mut line);
        let raw_rho = nan_unless_kept(o.rho_deg, o.status);
        let reach = candidates
            .iter()
            .map(|&i| smooth_x[i].abs())
            .fold(0.0, f64::max)
            + 3.0;
        let toe_z = candidates
            .iter()
            .map(|&i| smooth_z[i])
            .fold(f64::INFINITY, f64::min);
        return Some(Profile {
            line: k,
            raw_x: xz.iter().map(|p| p.0).collect(),
            raw_z: xz.iter().map(|p| p.1).collect(),
            raw_rho,
            smooth_x,
            smooth_z,
            smooth_rho,
            candidates,
            tau_deg: (params.tau_min_deg as f64, params.tau_max_deg as f64),
            x_range_m: Some((-reach, reach)),
            // From 0.15 m below the lower curb toe to 0.6 m above it: road, curbs and
            // sidewalks, not the walls.
            z_range_m: Some((toe_z - 0.15, toe_z + 0.6)),
        });
    }
    None
}
