//! `curbtrace frame FILE… [-o OUT.geojson|OUT.csv] [--format kitti|nuscenes|pcd]` — curb
//! polylines per lidar frame, in the sensor frame (docs/frames.md).

use anyhow::Context;
use curbtrace_host_sim::frame::run::FramePipeline;
use curbtrace_host_sim::frame::{extract_frame, write, CurbLine, FrameParams};
use curbtrace_host_sim::io::sweep::{Sweep, SweepError};
use curbtrace_host_sim::io::{kitti, nuscenes, pcd};
use curbtrace_host_sim::model::Side;
use curbtrace_host_sim::rings::SensorModel;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Input formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// KITTI `.bin` (HDL-64E; x, y, z, reflectance as float32).
    Kitti,
    /// nuScenes `.pcd.bin` (HDL-32E; x, y, z, intensity, ring as float32).
    Nuscenes,
    /// PCD with a `ring` (or `laser_id`, `channel`) field, ASCII or binary.
    Pcd,
}

/// Arguments of `curbtrace frame`.
#[derive(clap::Args)]
pub struct Args {
    /// Lidar frames (one revolution each).
    #[arg(required_unless_present = "print_config")]
    pub files: Vec<PathBuf>,
    /// Output: `.geojson` (or `.json`) or `.csv`; without it, only the summary is printed.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Input format; by default from the extension (`.pcd.bin` nuscenes, `.bin` kitti,
    /// `.pcd` pcd).
    #[arg(long, value_enum)]
    pub format: Option<Format>,
    /// Parameters as TOML (`[rings]`, `[step]`, `[link]`; see `--print-config`).
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Prints the default parameters as TOML and exits.
    #[arg(long)]
    pub print_config: bool,
}

/// The format of `path`: the one given, else from its extension.
pub fn format_of(path: &Path, given: Option<Format>) -> anyhow::Result<Format> {
    if let Some(f) = given {
        return Ok(f);
    }
    let name = path
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    if name.ends_with(".pcd.bin") {
        Ok(Format::Nuscenes)
    } else if name.ends_with(".bin") {
        Ok(Format::Kitti)
    } else if name.ends_with(".pcd") {
        Ok(Format::Pcd)
    } else {
        anyhow::bail!(
            "{}: cannot tell the format from the extension (.bin KITTI, .pcd.bin nuScenes, .pcd PCD); give --format",
            path.display()
        )
    }
}

/// Reads one frame in `format`.
pub fn read(path: &Path, format: Format) -> Result<Sweep, SweepError> {
    match format {
        Format::Kitti => kitti::read_kitti(path),
        Format::Nuscenes => nuscenes::read_nuscenes(path),
        Format::Pcd => pcd::read_pcd(path),
    }
}

/// Runs `curbtrace frame`.
pub fn run(args: Args) -> anyhow::Result<()> {
    if args.print_config {
        let mut v = toml::Value::try_from(FrameParams::default())?;
        shortest_f32(&mut v);
        print!("{}", toml::to_string(&v)?);
        return Ok(());
    }
    let params: FrameParams = match &args.config {
        Some(p) => {
            let text = std::fs::read_to_string(p)
                .with_context(|| format!("{}: reading the config", p.display()))?;
            toml::from_str(&text).map_err(|e| {
                anyhow::anyhow!("{}: {}", p.display(), e.to_string().replace('\n', " "))
            })?
        }
        None => FrameParams::default(),
    };
    let formats: Vec<Format> = args
        .files
        .iter()
        .map(|f| format_of(f, args.format))
        .collect::<anyhow::Result<_>>()?;
    let mut pipe = Box::new(FramePipeline::new());
    let mut frames: Vec<(String, Vec<CurbLine>)> = Vec::new();
    for (path, format) in args.files.iter().zip(formats) {
        let t0 = Instant::now();
        let sweep = read(path, format)?;
        let t_read = t0.elapsed();
        let sensor = SensorModel::for_sweep(&sweep);
        let r = extract_frame(&sweep, &sensor, &params, &mut pipe)
            .with_context(|| format!("{}: running the core", path.display()))?;
        let t_all = t0.elapsed();
        let c = &r.counters;
        let per_side = |s: Side| {
            let v: Vec<String> = r
                .lines
                .iter()
                .filter(|l| l.side == s)
                .map(|l| format!("{:.0} cm over {:.1} m", 100.0 * l.height_m, l.length_m()))
                .collect();
            if v.is_empty() {
                "none".to_string()
            } else {
                v.join(", ")
            }
        };
        eprintln!(
            "{}: {} ({}), {} points{}; {} half-arcs of {} rings ({} points) through the core; {} candidates: {} curb, {} vehicle/wall, {} without curb step, {} unmeasured; left {}; right {}; {:.1} ms (read {:.1} ms)",
            path.display(),
            format_name(format),
            sensor.name,
            c.points,
            if sweep.dropped_non_finite > 0 {
                format!(" ({} non-finite dropped)", sweep.dropped_non_finite)
            } else {
                String::new()
            },
            c.arcs.arcs,
            c.arcs.rings,
            c.points_kernel,
            c.candidates,
            c.curbs,
            c.objects,
            c.no_step,
            c.unmeasured,
            per_side(Side::Left),
            per_side(Side::Right),
            t_all.as_secs_f64() * 1e3,
            t_read.as_secs_f64() * 1e3,
        );
        frames.push((path.display().to_string(), r.lines));
    }
    if let Some(out) = &args.output {
        write::write(out, &frames).with_context(|| format!("{}: writing", out.display()))?;
        eprintln!("written            {}", out.display());
    }
    Ok(())
}

fn format_name(f: Format) -> &'static str {
    match f {
        Format::Kitti => "KITTI",
        Format::Nuscenes => "nuScenes",
        Format::Pcd => "PCD",
    }
}

/// Writes every float of `v` (all `f32` parameters) with the fewest digits that read back
/// to the same `f32` (0.01, not 0.009999999776482582).
fn shortest_f32(v: &mut toml::Value) {
    match v {
        toml::Value::Float(f) => {
            if let Ok(g) = format!("{}", *f as f32).parse::<f64>() {
                *f = g;
            }
        }
        toml::Value::Table(t) => t.iter_mut().for_each(|(_, x)| shortest_f32(x)),
        toml::Value::Array(a) => a.iter_mut().for_each(shortest_f32),
        _ => {}
    }
}
