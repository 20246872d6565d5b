//! `curbtrace extract POINTS... --trajectory CSV -o EDGES.geojson` — the main job
//! (docs/spec.md §4). POINTS are LAS/LAZ files, directories or glob patterns, read as one
//! time-ordered stream in bounded memory (`stream`).

use anyhow::Context;
use curbtrace_host_sim::config::Config;
use curbtrace_host_sim::output::format::{resolve, OutputFormat};
use curbtrace_host_sim::output::write_edges_as;
use curbtrace_host_sim::pipeline::{self, ExtractOptions, Method, Progress};
use curbtrace_host_sim::stream::{self, WindowParams};
use std::io::IsTerminal;
use std::path::PathBuf;

/// Output format of the edges (`--format`); without it the extension of `-o` decides.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// GeoJSON FeatureCollection with the LAS CRS (docs/spec.md §3).
    Geojson,
    /// Plain vertex lists: `edge,side,vertex,x,y,z`.
    Csv,
    /// OGC GeoPackage with the LAS CRS.
    Gpkg,
    /// FlatGeobuf with the LAS CRS.
    Fgb,
    /// AutoCAD DXF, 3D polylines on one layer per class.
    Dxf,
}

impl From<Format> for OutputFormat {
    fn from(f: Format) -> Self {
        match f {
            Format::Geojson => OutputFormat::GeoJson,
            Format::Csv => OutputFormat::Csv,
            Format::Gpkg => OutputFormat::GeoPackage,
            Format::Fgb => OutputFormat::FlatGeobuf,
            Format::Dxf => OutputFormat::Dxf,
        }
    }
}

/// Method names on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum MethodArg {
    /// Bend angle of scanlines (Honma et al.), through the core.
    Bend,
    /// Plane-based (Qiu et al.).
    Qiu,
}

/// Arguments of `curbtrace extract`.
#[derive(clap::Args)]
pub struct Args {
    /// LAS or LAZ point files (formats with GPS time: 1, 3, 4, 5, 6–10), directories of
    /// them or glob patterns; one campaign, ordered by time.
    #[arg(required_unless_present = "print_config", num_args = 1..)]
    pub points: Vec<PathBuf>,
    /// Trajectory CSV: time,x,y,z,roll,pitch,heading (GPS time in the LAS time base).
    #[arg(long, required_unless_present = "print_config")]
    pub trajectory: Option<PathBuf>,
    /// Output file; its extension chooses the format: .geojson/.json, .csv, .gpkg, .fgb, .dxf
    /// (docs/output-formats.md).
    #[arg(short, long, required_unless_present = "print_config")]
    pub output: Option<PathBuf>,
    /// Method.
    #[arg(long, value_enum, default_value = "bend")]
    pub method: MethodArg,
    /// Scanner: LAS 1.4 scanner channel (when the file uses channels) or point source id.
    /// Without it every scanner is read, each through its own core and tracker, and their
    /// edges fused.
    #[arg(long)]
    pub scanner: Option<u16>,
    /// Pass: only the Nth pass (from 0) of a trajectory that drives the same road again.
    /// Without it every pass is extracted and the passes fused (docs/architecture.md, "Several passes").
    #[arg(long)]
    pub pass: Option<u16>,
    /// TOML file with the scanners' mounts (a `[scanners]` table, as `simulate --scanners 2`
    /// writes in `mounts.toml`); replaces the config's `[scanners]`.
    #[arg(long)]
    pub mounts: Option<PathBuf>,
    /// TOML file with parameters (see --print-config).
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Output format, when the extension of -o does not say it (must agree when it does).
    #[arg(long, value_enum)]
    pub format: Option<Format>,
    /// Prints the configuration in force (defaults, or --config's) as TOML and exits.
    #[arg(long)]
    pub print_config: bool,
    /// Length of the sections of road whose edges are closed together, metres.
    #[arg(long, default_value_t = WindowParams::default().section_m)]
    pub section_m: f64,
    /// Road before and after a section that its window also holds, metres (at least the
    /// tracker's reach; see docs/benchmarks.md).
    #[arg(long, default_value_t = WindowParams::default().margin_m)]
    pub margin_m: f64,
    /// Most seconds of points the window holds: a vehicle standing longer closes its
    /// section and drops its oldest points (counted in the summary). Bounds memory at this
    /// span times the point rate.
    #[arg(long, default_value_t = WindowParams::default().max_s)]
    pub window_max_s: f64,
    /// Farthest ahead of the vehicle a point near the road's level may lie and still be
    /// held for the section it lies in, metres (0: none).
    #[arg(long, default_value_t = WindowParams::default().lead_max_m)]
    pub lead_max_m: f64,
    /// Road the window waits for past a section's margin, for points lying in it that the
    /// vehicle measures later, metres (0: none).
    #[arg(long, default_value_t = WindowParams::default().lag_m)]
    pub lag_m: f64,
    /// No summary on stderr.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Runs `curbtrace extract`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let mut cfg = match &args.config {
        Some(p) => Config::read(p)?,
        None => Config::default(),
    };
    if let Some(p) = &args.mounts {
        cfg.scanners = curbtrace_host_sim::mounts::Mounts::read(p).map_err(anyhow::Error::msg)?;
    }
    if args.print_config {
        print!(
            "{}",
            toml::to_string_pretty(&cfg).context("printing the config")?
        );
        return Ok(());
    }
    let (false, Some(trajectory), Some(output)) =
        (args.points.is_empty(), &args.trajectory, &args.output)
    else {
        anyhow::bail!("POINTS, --trajectory and -o are required");
    };
    // Before the work: a bad output name fails at once.
    let format = resolve(output, args.format.map(OutputFormat::from))?;
    let opts = ExtractOptions {
        scanner: args.scanner,
        pass: args.pass,
        method: match args.method {
            MethodArg::Bend => Method::Bend,
            MethodArg::Qiu => Method::Qiu,
        },
    };
    let progress = if std::io::stderr().is_terminal() && !args.quiet {
        Progress::bar()
    } else {
        Progress::hidden()
    };
    let result = match opts.method {
        Method::Bend => {
            let window = WindowParams {
                section_m: args.section_m,
                margin_m: args.margin_m,
                max_s: args.window_max_s,
                lead_max_m: args.lead_max_m,
                lag_m: args.lag_m,
            };
            stream::extract(&args.points, trajectory, &cfg, &opts, &window, &progress)?
        }
        Method::Qiu => {
            let [points] = args.points.as_slice() else {
                anyhow::bail!("--method qiu reads one file, not {}", args.points.len());
            };
            qiu_size_check(points)?;
            pipeline::extract_file_with(points, trajectory, &cfg, &opts, &progress)?
        }
    };
    progress.finish();
    if result.crs.is_none() && format != OutputFormat::Csv {
        let why = result.summary.las.no_crs.map_or_else(
            || "the input's CRS was not kept".to_string(),
            |w| w.to_string(),
        );
        eprintln!(
            "warning: {}: the output has no CRS: {why} ({})",
            output.display(),
            result.summary.las.path.display()
        );
    }
    write_edges_as(format, output, &result.edges, result.crs.as_ref())?;
    if !args.quiet {
        eprintln!("{}", result.summary.to_text());
        eprintln!("written            {}", output.display());
    }
    Ok(())
}

/// Most points `--method qiu` takes: it holds the whole file in memory (about 60 B per
/// point at its peak).
const QIU_MAX_POINTS: u64 = 20_000_000;

/// Refuses files too large for the whole-file qiu method, naming the file and the limit.
fn qiu_size_check(points: &std::path::Path) -> anyhow::Result<()> {
    let head = curbtrace_host_sim::io::las_in::check_file(points)?;
    if head.count > QIU_MAX_POINTS {
        anyhow::bail!(
            "{}: {} points; --method qiu holds the whole file in memory and takes at most {} (the bend method streams any size)",
            points.display(),
            head.count,
            QIU_MAX_POINTS
        );
    }
    Ok(())
}
