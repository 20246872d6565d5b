//! `curbtrace._native`: the workspace's library calls behind a Python module. The Python
//! package (`curbtrace/`) turns numpy, laspy and pandas objects into the byte columns and
//! CSV text these functions take, and their results back into numpy arrays and dicts; the
//! work is the Rust code of `curbtrace-host-sim` and `curbtrace-core`, with the GIL
//! released while it runs.

use curbtrace_core::kernel::{Kernel, KernelParams};
use curbtrace_core::scanline::Line;
use curbtrace_host_sim::config::Config;
use curbtrace_host_sim::eval::{self, EvalParams};
use curbtrace_host_sim::io::las_in::PointColumns;
use curbtrace_host_sim::io::trajectory::Trajectory;
use curbtrace_host_sim::model::{self, Category, Crs, CurbDetail, EdgeLine, Side};
use curbtrace_host_sim::output::format::resolve;
use curbtrace_host_sim::output::geojson::lines_to_geojson;
use curbtrace_host_sim::output::write_edges_as;
use curbtrace_host_sim::pipeline::{self, ExtractOptions, Method, Progress};
use curbtrace_host_sim::replay::run::LINE_CAPACITY;
use curbtrace_host_sim::source::campaign::Campaign;
use curbtrace_host_sim::stream::merge::Piece;
use curbtrace_host_sim::stream::tasks::{self, TaskSpec};
use curbtrace_host_sim::stream::{self, WindowParams};
use pyo3::create_exception;
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

create_exception!(
    _native,
    CurbtraceError,
    pyo3::exceptions::PyException,
    "A curbtrace error: the one-line message the command line prints after `curbtrace: error:`."
);

/// Any error as a Python exception with the CLI's one-line message (the error and its causes
/// joined by ": ", as `curbtrace` prints them).
fn err<E: Into<anyhow::Error>>(e: E) -> PyErr {
    CurbtraceError::new_err(format!("{:#}", e.into()))
}

/// The run's parameters: defaults, a TOML file, or the same tables as JSON text.
fn config(path: Option<&str>, json: Option<&str>) -> PyResult<Config> {
    match (path, json) {
        (Some(p), _) => Config::read(Path::new(p)).map_err(err),
        (None, Some(j)) => {
            let cfg: Config = serde_json::from_str(j)
                .map_err(|e| CurbtraceError::new_err(format!("config: {e}")))?;
            cfg.kernel_words()
                .map_err(|e| CurbtraceError::new_err(format!("config: [kernel]: {e}")))?;
            Ok(cfg)
        }
        (None, None) => Ok(Config::default()),
    }
}

fn method(name: &str) -> PyResult<Method> {
    match name {
        "bend" => Ok(Method::Bend),
        "qiu" => Ok(Method::Qiu),
        other => Err(CurbtraceError::new_err(format!(
            "method {other:?} is not one of \"bend\", \"qiu\""
        ))),
    }
}

fn crs(epsg: Option<u32>, wkt: Option<String>) -> Option<Crs> {
    epsg.map(Crs::Epsg).or(wkt.map(Crs::Wkt))
}

/// Native-endian numbers from the bytes of a contiguous numpy array.
fn column<T, const W: usize>(name: &str, b: &[u8], from: fn([u8; W]) -> T) -> PyResult<Vec<T>> {
    if !b.len().is_multiple_of(W) {
        return Err(CurbtraceError::new_err(format!(
            "column {name}: {} bytes is not a whole number of {W}-byte values",
            b.len()
        )));
    }
    Ok(b.chunks_exact(W)
        .map(|c| from(c.try_into().unwrap_or([0; W])))
        .collect())
}

fn geojson_text(edges: &[EdgeLine], crs: Option<&Crs>) -> String {
    lines_to_geojson(edges, crs).to_string()
}

/// Road edges from point columns in memory (sorted by time, one scanner).
///
/// Returns the FeatureCollection as GeoJSON text and the points dropped before and after
/// the trajectory.
#[pyfunction]
#[pyo3(signature = (x, y, z, t, intensity, scan_angle_deg, trajectory_csv, method_name, config_path=None, config_json=None, crs_epsg=None, crs_wkt=None, points_name="points".to_string(), trajectory_name="trajectory".to_string()))]
#[allow(clippy::too_many_arguments)]
fn extract_columns(
    py: Python<'_>,
    x: &[u8],
    y: &[u8],
    z: &[u8],
    t: &[u8],
    intensity: Option<&[u8]>,
    scan_angle_deg: Option<&[u8]>,
    trajectory_csv: &str,
    method_name: &str,
    config_path: Option<&str>,
    config_json: Option<&str>,
    crs_epsg: Option<u32>,
    crs_wkt: Option<String>,
    points_name: String,
    trajectory_name: String,
) -> PyResult<(String, u64, u64)> {
    let cfg = config(config_path, config_json)?;
    let m = method(method_name)?;
    let mut cols = PointColumns {
        x: column("x", x, f64::from_ne_bytes)?,
        y: column("y", y, f64::from_ne_bytes)?,
        z: column("z", z, f64::from_ne_bytes)?,
        t: column("gps_time", t, f64::from_ne_bytes)?,
        ..PointColumns::default()
    };
    let n = cols.t.len();
    if cols.x.len() != n || cols.y.len() != n || cols.z.len() != n {
        return Err(CurbtraceError::new_err(format!(
            "{points_name}: columns x, y, z, gps_time differ in length ({}, {}, {}, {n})",
            cols.x.len(),
            cols.y.len(),
            cols.z.len()
        )));
    }
    cols.intensity = match intensity {
        Some(b) => column("intensity", b, u16::from_ne_bytes)?,
        None => vec![0; n],
    };
    cols.scan_angle_deg = match scan_angle_deg {
        Some(b) => column("scan_angle", b, f32::from_ne_bytes)?,
        None => vec![0.0; n],
    };
    cols.channel = vec![0; n];
    if cols.intensity.len() != n || cols.scan_angle_deg.len() != n {
        return Err(CurbtraceError::new_err(format!(
            "{points_name}: columns intensity and scan_angle must have {n} values like gps_time"
        )));
    }
    let points_path = PathBuf::from(points_name);
    let traj_path = PathBuf::from(trajectory_name);
    let traj = Trajectory::parse_csv(&traj_path, trajectory_csv).map_err(err)?;
    let crs = crs(crs_epsg, crs_wkt);
    py.allow_threads(move || {
        let (edges, (before, after)) =
            pipeline::extract_columns(cols, &points_path, &traj, &traj_path, &cfg, m)
                .map_err(err)?;
        Ok((geojson_text(&edges, crs.as_ref()), before, after))
    })
}

/// `curbtrace extract`'s job on files: one campaign of LAS/LAZ files, directories or glob
/// patterns. Returns the FeatureCollection as GeoJSON text and the CLI's summary; writes
/// `output` (its extension chooses the format) when given.
#[pyfunction]
#[pyo3(signature = (paths, trajectory, method_name="bend", config_path=None, config_json=None, scanner=None, section_m=None, margin_m=None, output=None))]
#[allow(clippy::too_many_arguments)]
fn extract_files(
    py: Python<'_>,
    paths: Vec<PathBuf>,
    trajectory: PathBuf,
    method_name: &str,
    config_path: Option<&str>,
    config_json: Option<&str>,
    scanner: Option<u16>,
    section_m: Option<f64>,
    margin_m: Option<f64>,
    output: Option<PathBuf>,
) -> PyResult<(String, String)> {
    let cfg = config(config_path, config_json)?;
    let opts = ExtractOptions {
        scanner,
        pass: None,
        method: method(method_name)?,
    };
    let window = window(section_m, margin_m);
    let format = match &output {
        Some(o) => Some(resolve(o, None).map_err(err)?),
        None => None,
    };
    py.allow_threads(move || {
        let progress = Progress::hidden();
        let result = match opts.method {
            Method::Bend => stream::extract(&paths, &trajectory, &cfg, &opts, &window, &progress)
                .map_err(err)?,
            Method::Qiu => {
                let [points] = paths.as_slice() else {
                    return Err(CurbtraceError::new_err(format!(
                        "--method qiu reads one file, not {}",
                        paths.len()
                    )));
                };
                pipeline::extract_file_with(points, &trajectory, &cfg, &opts, &progress)
                    .map_err(err)?
            }
        };
        if let (Some(o), Some(f)) = (&output, format) {
            write_edges_as(f, o, &result.edges, result.crs.as_ref()).map_err(err)?;
        }
        Ok((
            geojson_text(&result.edges, result.crs.as_ref()),
            result.summary.to_text(),
        ))
    })
}

fn window(section_m: Option<f64>, margin_m: Option<f64>) -> WindowParams {
    let d = WindowParams::default();
    WindowParams {
        section_m: section_m.unwrap_or(d.section_m),
        margin_m: margin_m.unwrap_or(d.margin_m),
        ..d
    }
}

/// The core's kernel on one scanline (x′, z′ in metres, f32): ρ in degrees, the status per
/// point (0 kept, 1 irregular, 2 no neighbour, 3 non-finite), the smoothed x′ and z′ as
/// native-endian bytes, and the nadir and the left and right seed candidates.
#[pyfunction]
#[pyo3(signature = (x, z, params_json=None))]
#[allow(clippy::type_complexity)]
fn bend_angles<'py>(
    py: Python<'py>,
    x: &[u8],
    z: &[u8],
    params_json: Option<&str>,
) -> PyResult<(
    Bound<'py, PyBytes>,
    Bound<'py, PyBytes>,
    Bound<'py, PyBytes>,
    Bound<'py, PyBytes>,
    Option<u16>,
    Option<u16>,
    Option<u16>,
)> {
    let x = column("line_x", x, f32::from_ne_bytes)?;
    let z = column("line_z", z, f32::from_ne_bytes)?;
    if x.len() != z.len() {
        return Err(CurbtraceError::new_err(format!(
            "line_x has {} points and line_z {}",
            x.len(),
            z.len()
        )));
    }
    if x.len() > LINE_CAPACITY {
        return Err(CurbtraceError::new_err(format!(
            "a scanline of {} points is longer than the kernel's {LINE_CAPACITY}",
            x.len()
        )));
    }
    let params: KernelParams = match params_json {
        Some(j) => {
            serde_json::from_str(j).map_err(|e| CurbtraceError::new_err(format!("params: {e}")))?
        }
        None => KernelParams::DEFAULT,
    };
    let mut kernel: Box<Kernel<LINE_CAPACITY>> = Box::new(Kernel::new(KernelParams::DEFAULT));
    kernel
        .set_params(params)
        .map_err(|e| CurbtraceError::new_err(format!("params: {e}")))?;
    let mut line: Box<Line<LINE_CAPACITY>> = Box::new(Line::new());
    for (i, (&a, &b)) in x.iter().zip(&z).enumerate() {
        // Cannot fail: the length was checked against the capacity above.
        let _ = line.push(a, b, i as u32);
    }
    let o = kernel.process(&mut line);
    let f32s = |v: &[f32]| v.iter().flat_map(|f| f.to_ne_bytes()).collect::<Vec<u8>>();
    let status: Vec<u8> = o.status.iter().map(|s| *s as u8).collect();
    Ok((
        PyBytes::new(py, &f32s(o.rho_deg)),
        PyBytes::new(py, &status),
        PyBytes::new(py, &f32s(o.x_m)),
        PyBytes::new(py, &f32s(o.z_m)),
        o.nadir,
        o.left,
        o.right,
    ))
}

/// `curbtrace eval`: the metrics of `extracted` against `reference` (GeoJSON texts) as JSON
/// text, the layout of `--json`.
#[pyfunction]
#[pyo3(signature = (reference, extracted, buffer_m, reference_name="reference".to_string(), extracted_name="extracted".to_string()))]
fn evaluate(
    py: Python<'_>,
    reference: &str,
    extracted: &str,
    buffer_m: f64,
    reference_name: String,
    extracted_name: String,
) -> PyResult<String> {
    // As `curbtrace eval`: the reader's message names the input; different CRS are refused.
    let read = |name: &str, text: &str| {
        model::parse_geojson(name, text).map_err(|e| CurbtraceError::new_err(e.to_string()))
    };
    let (r, ref_crs) = read(&reference_name, reference)?;
    let (e, ext_crs) = read(&extracted_name, extracted)?;
    if let (Some(a), Some(b)) = (&ref_crs, &ext_crs) {
        if !a.same_as(b) {
            return Err(CurbtraceError::new_err(format!(
                "{reference_name} and {extracted_name} carry different CRS ({a:?} vs {b:?}); reproject one first"
            )));
        }
    }
    let params = EvalParams {
        buffer_m,
        ..EvalParams::default()
    };
    py.allow_threads(move || {
        let report = eval::evaluate(&r, &e, &params).map_err(|e| {
            CurbtraceError::new_err(format!(
                "evaluating {extracted_name} against {reference_name}: {e}"
            ))
        })?;
        // The CLI's `--json`: the report with the survey section beside it.
        let survey = eval::survey(&r, &e, &params).map_err(|e| {
            CurbtraceError::new_err(format!(
                "evaluating {extracted_name} against {reference_name}: {e}"
            ))
        })?;
        let mut v: Value = serde_json::from_str(&report.to_json()).map_err(err)?;
        v["survey"] = serde_json::to_value(&survey).map_err(err)?;
        Ok(v.to_string())
    })
}

/// Cuts a campaign along its route into at most `tasks` tasks of whole sections: per task
/// its first and last section (`[k0, k1)`) and the GPS time range of the points it reads.
#[pyfunction]
#[pyo3(signature = (trajectory, tasks, section_m=None, margin_m=None))]
fn plan_tasks(
    trajectory: PathBuf,
    tasks: usize,
    section_m: Option<f64>,
    margin_m: Option<f64>,
) -> PyResult<Vec<(i64, i64, f64, f64)>> {
    let traj = Trajectory::read_csv(&trajectory).map_err(err)?;
    Ok(tasks::plan(&traj, &window(section_m, margin_m), tasks)
        .into_iter()
        .map(|t| (t.sections.start, t.sections.end, t.times.0, t.times.1))
        .collect())
}

/// Runs one task of [`plan_tasks`]: its sections' edge pieces, unmerged, as JSON text, and
/// the points that went through the core.
#[pyfunction]
#[pyo3(signature = (paths, trajectory, k0, k1, t0, t1, config_path=None, config_json=None, scanner=None, section_m=None, margin_m=None))]
#[allow(clippy::too_many_arguments)]
fn run_task(
    py: Python<'_>,
    paths: Vec<PathBuf>,
    trajectory: PathBuf,
    k0: i64,
    k1: i64,
    t0: f64,
    t1: f64,
    config_path: Option<&str>,
    config_json: Option<&str>,
    scanner: Option<u16>,
    section_m: Option<f64>,
    margin_m: Option<f64>,
) -> PyResult<(String, u64)> {
    let cfg = config(config_path, config_json)?;
    let window = window(section_m, margin_m);
    let opts = ExtractOptions {
        scanner,
        pass: None,
        method: Method::Bend,
    };
    let spec = TaskSpec {
        sections: k0..k1,
        times: (t0, t1),
    };
    py.allow_threads(move || {
        let traj = Trajectory::read_csv(&trajectory).map_err(err)?;
        let out = tasks::run(&paths, &traj, &cfg, &opts, &window, &spec).map_err(err)?;
        let sections: Vec<Value> = out
            .pieces
            .iter()
            .map(|(k, ps)| json!({"section": k, "pieces": ps.iter().map(piece_json).collect::<Vec<_>>()}))
            .collect();
        Ok((Value::Array(sections).to_string(), out.points))
    })
}

/// The tasks' pieces (the JSON texts of [`run_task`]) merged as `curbtrace extract` merges
/// its sections; the campaign's CRS is read from the files' headers. Returns GeoJSON text.
#[pyfunction]
#[pyo3(signature = (paths, parts, config_path=None, config_json=None, scanner=None))]
fn merge_tasks(
    py: Python<'_>,
    paths: Vec<PathBuf>,
    parts: Vec<String>,
    config_path: Option<&str>,
    config_json: Option<&str>,
    scanner: Option<u16>,
) -> PyResult<String> {
    let cfg = config(config_path, config_json)?;
    let mut sections = Vec::new();
    for p in &parts {
        let v: Value = serde_json::from_str(p).map_err(err)?;
        for s in v.as_array().into_iter().flatten() {
            let k = s["section"]
                .as_i64()
                .ok_or_else(|| CurbtraceError::new_err("task pieces: a section without index"))?;
            let pieces = s["pieces"]
                .as_array()
                .into_iter()
                .flatten()
                .map(piece_from)
                .collect::<PyResult<Vec<_>>>()?;
            sections.push((k, pieces));
        }
    }
    let read = curbtrace_host_sim::io::las_in::ReadOptions { scanner };
    py.allow_threads(move || {
        let info = Campaign::open(&paths, &read).map_err(err)?.info().clone();
        let edges = tasks::merge(sections, &cfg.bend);
        Ok(geojson_text(&edges, info.crs.as_ref()))
    })
}

// Pieces travel between processes as JSON with every f64 as its bit pattern (a u64), so
// that the merge sees exactly the numbers the task computed.
fn bits(v: f64) -> u64 {
    v.to_bits()
}

fn piece_json(p: &Piece) -> Value {
    let l = p.line();
    let (open_start, open_end, cut) = p.ends();
    let points: Vec<[u64; 3]> = l.points.iter().map(|q| q.map(bits)).collect();
    let steps: Vec<Option<u64>> = p.steps().iter().map(|s| s.map(bits)).collect();
    json!({
        "points": points,
        "side": l.side.as_str(),
        "category": l.category.map(|c| c.as_str()),
        "method": l.method,
        "curb_height_m": l.curb_height_m.map(bits),
        "detail": l.detail.as_deref().map(detail_json),
        "steps": steps,
        "open_start": open_start,
        "open_end": open_end,
        "cut": cut,
    })
}

fn detail_json(d: &CurbDetail) -> Value {
    let top: Vec<[u64; 3]> = d.top.iter().map(|q| q.map(bits)).collect();
    let height: Vec<u64> = d.height_m.iter().map(|&h| bits(h)).collect();
    let class: Vec<&str> = d.class.iter().map(|c| c.as_str()).collect();
    json!({
        "top": top,
        "height_m": height,
        "measured": d.measured,
        "top_measured": d.top_measured,
        "class": class,
        "bridged": d.bridged,
        "support_per_m": bits(d.support_per_m),
    })
}

fn detail_from(v: &Value) -> Option<CurbDetail> {
    let top: Vec<[u64; 3]> = serde_json::from_value(v["top"].clone()).ok()?;
    let height: Vec<u64> = serde_json::from_value(v["height_m"].clone()).ok()?;
    let class: Vec<String> = serde_json::from_value(v["class"].clone()).ok()?;
    Some(CurbDetail {
        top: top.into_iter().map(|q| q.map(f64::from_bits)).collect(),
        height_m: height.into_iter().map(f64::from_bits).collect(),
        measured: serde_json::from_value(v["measured"].clone()).ok()?,
        top_measured: serde_json::from_value(v["top_measured"].clone()).ok()?,
        class: class
            .iter()
            .map(|c| Category::parse(c))
            .collect::<Option<Vec<_>>>()?,
        bridged: v["bridged"].as_bool()?,
        support_per_m: f64::from_bits(v["support_per_m"].as_u64()?),
        scanner: Vec::new(),
        pass: Vec::new(),
    })
}

fn piece_from(v: &Value) -> PyResult<Piece> {
    let bad = || CurbtraceError::new_err("task pieces: a piece is malformed");
    let points: Vec<[u64; 3]> = serde_json::from_value(v["points"].clone()).map_err(|_| bad())?;
    let steps: Vec<Option<u64>> = serde_json::from_value(v["steps"].clone()).map_err(|_| bad())?;
    let side = match v["side"].as_str() {
        Some("left") => Side::Left,
        Some("right") => Side::Right,
        _ => return Err(bad()),
    };
    let category = match v["category"].as_str() {
        Some(c) => Some(Category::parse(c).ok_or_else(bad)?),
        None => None,
    };
    let line = EdgeLine {
        points: points.into_iter().map(|q| q.map(f64::from_bits)).collect(),
        side,
        category,
        method: v["method"].as_str().map(str::to_string),
        curb_height_m: v["curb_height_m"].as_u64().map(f64::from_bits),
        detail: match &v["detail"] {
            Value::Null => None,
            d => Some(Box::new(detail_from(d).ok_or_else(bad)?)),
        },
    };
    let steps = steps.into_iter().map(|s| s.map(f64::from_bits)).collect();
    let flag = |k: &str| v[k].as_bool().ok_or_else(bad);
    Ok(if flag("cut")? {
        Piece::cut(line, steps, flag("open_start")?, flag("open_end")?)
    } else {
        Piece::whole(line, steps)
    })
}

/// The default parameters as TOML (`curbtrace extract --print-config`).
#[pyfunction]
fn default_config_toml() -> String {
    Config::default_toml()
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("CurbtraceError", m.py().get_type::<CurbtraceError>())?;
    m.add("LINE_CAPACITY", LINE_CAPACITY)?;
    m.add_function(wrap_pyfunction!(extract_columns, m)?)?;
    m.add_function(wrap_pyfunction!(extract_files, m)?)?;
    m.add_function(wrap_pyfunction!(bend_angles, m)?)?;
    m.add_function(wrap_pyfunction!(evaluate, m)?)?;
    m.add_function(wrap_pyfunction!(plan_tasks, m)?)?;
    m.add_function(wrap_pyfunction!(run_task, m)?)?;
    m.add_function(wrap_pyfunction!(merge_tasks, m)?)?;
    m.add_function(wrap_pyfunction!(default_config_toml, m)?)?;
    Ok(())
}
