//! `curbtrace eval`: scores extracted edges against reference lines (docs/spec.md §5) and prints the
//! table of Honma et al.'s Tables 2 and 3; `--json OUT` writes the same numbers as JSON;
//! `--picture PNG --points LAZ` draws the worst place (longest miss or false edge).

use anyhow::Context;
use curbtrace_host_sim::eval::{evaluate, survey, worst_place, EvalParams, WorstKind, WorstPlace};
use curbtrace_host_sim::model::{read_geojson, EdgeLine};
use curbtrace_host_sim::plot::{top_view_png, Cloud, TopView, Window};
use std::path::{Path, PathBuf};

/// Arguments of `curbtrace eval`.
#[derive(clap::Args)]
pub struct Args {
    /// Reference lines (GeoJSON; features with `side` and `category`).
    #[arg(long, value_name = "REF")]
    pub reference: PathBuf,
    /// Extracted edges (GeoJSON, as written by `curbtrace extract`).
    #[arg(long, value_name = "EDGES")]
    pub extracted: PathBuf,
    /// Buffer width in metres (Honma et al. used 0.05).
    #[arg(
        long,
        default_value_t = 0.05,
        value_name = "M",
        allow_negative_numbers = true
    )]
    pub buffer: f64,
    /// Also write the metrics as JSON to this file.
    #[arg(long, value_name = "OUT")]
    pub json: Option<PathBuf>,
    /// Also draw the worst place (the longest miss or false edge) as a PNG top view; needs
    /// `--points`.
    #[arg(long, value_name = "PNG", requires = "points")]
    pub picture: Option<PathBuf>,
    /// The point cloud (LAS/LAZ) under the picture.
    #[arg(long, value_name = "POINTS")]
    pub points: Option<PathBuf>,
    /// Title of the picture (default: what the worst place is).
    #[arg(long, value_name = "TEXT", requires = "picture")]
    pub title: Option<String>,
}

/// Runs `curbtrace eval`.
pub fn run(args: Args) -> anyhow::Result<()> {
    // read_geojson's errors already name the file; its I/O variant also carries the
    // io::Error as source, which `{:#}` would print twice, so keep only the message.
    let read = |p: &std::path::Path| read_geojson(p).map_err(|e| anyhow::anyhow!("{e}"));
    let (reference, ref_crs) = read(&args.reference)?;
    let (extracted, ext_crs) = read(&args.extracted)?;
    if let (Some(a), Some(b)) = (&ref_crs, &ext_crs) {
        if !a.same_as(b) {
            anyhow::bail!(
                "{} and {} carry different CRS ({a:?} vs {b:?}); reproject one first",
                args.reference.display(),
                args.extracted.display()
            );
        }
    }
    let params = EvalParams {
        buffer_m: args.buffer,
        ..EvalParams::default()
    };
    let report = evaluate(&reference, &extracted, &params).with_context(|| {
        format!(
            "evaluating {} against {}",
            args.extracted.display(),
            args.reference.display()
        )
    })?;
    let survey = survey(&reference, &extracted, &params)?;
    if let Some(out) = &args.json {
        let mut v: serde_json::Value = serde_json::from_str(&report.to_json())?;
        v["survey"] = serde_json::to_value(&survey)?;
        std::fs::write(out, serde_json::to_string_pretty(&v)?)
            .with_context(|| format!("{}: cannot write", out.display()))?;
    }
    print!("{}", report.to_markdown());
    print!("{}", survey.to_markdown());
    if let (Some(png), Some(points)) = (&args.picture, &args.points) {
        match worst_place(&reference, &extracted, &params)? {
            Some(w) => {
                let what = format!(
                    "{} {:.1} m{}{}",
                    match w.kind {
                        WorstKind::Missed => "missed",
                        WorstKind::False => "false edge",
                    },
                    w.length_m,
                    w.side
                        .map_or(String::new(), |s| format!(", {}", s.as_str())),
                    w.category
                        .map_or(String::new(), |c| format!(", {}", c.as_str()))
                );
                draw_worst(
                    png,
                    points,
                    &reference,
                    &extracted,
                    &w,
                    args.title.as_deref(),
                    &what,
                )?;
                println!(
                    "\nworst place: {what} at ({:.2}, {:.2}); picture {}",
                    w.center[0],
                    w.center[1],
                    png.display()
                );
            }
            None => println!("\nno worst place: everything matches"),
        }
    }
    Ok(())
}

/// Draws a top view around the worst place from the points within the window.
fn draw_worst(
    png: &Path,
    points: &Path,
    reference: &[EdgeLine],
    extracted: &[EdgeLine],
    w: &WorstPlace,
    title: Option<&str>,
    what: &str,
) -> anyhow::Result<()> {
    let half = (w.length_m / 2.0 + 4.0).clamp(8.0, 30.0);
    let mut reader = las::Reader::from_path(points)
        .with_context(|| format!("{}: cannot open as LAS/LAZ", points.display()))?;
    let (mut x, mut y, mut z) = (Vec::new(), Vec::new(), Vec::new());
    loop {
        let chunk = reader
            .read_points(1 << 20)
            .with_context(|| format!("{}: cannot read points", points.display()))?;
        if chunk.is_empty() {
            break;
        }
        for ((px, py), pz) in chunk.x().zip(chunk.y()).zip(chunk.z()) {
            if (px - w.center[0]).abs() <= half && (py - w.center[1]).abs() <= half {
                x.push(px);
                y.push(py);
                z.push(pz);
            }
        }
    }
    let title = title.map_or_else(|| what.to_string(), |t| format!("{t}: {what}"));
    let mut view = TopView::new(
        title,
        Cloud {
            x: &x,
            y: &y,
            z: &z,
        },
        reference,
        extracted,
    );
    view.window = Some(Window {
        center: w.center,
        half_size_m: half,
    });
    view.max_points = 300_000;
    view.width_px = 1000;
    top_view_png(png, &view)?;
    Ok(())
}
