//! `curbtrace replay POINTS --trajectory CSV -o STREAM.bin` — writes the core's input byte
//! stream: the config packet, then the point packets, exactly as `extract` feeds the core
//! in-process (one chunk per line-aligned part of the file, each starting with its own config
//! packet; see `replay::run`).

use anyhow::Context;
use curbtrace_host_sim::config::Config;
use curbtrace_host_sim::pipeline::{self, ExtractOptions, Progress};
use curbtrace_host_sim::replay::line_start::LineRule;
use curbtrace_host_sim::replay::run;
use std::io::{IsTerminal, Write};
use std::path::PathBuf;

/// Arguments of `curbtrace replay`.
#[derive(clap::Args)]
pub struct Args {
    /// LAS or LAZ point file.
    pub points: PathBuf,
    /// Trajectory CSV.
    #[arg(long)]
    pub trajectory: PathBuf,
    /// Output byte stream.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Scanner: LAS 1.4 scanner channel or point source id.
    #[arg(long)]
    pub scanner: Option<u16>,
    /// TOML config (kernel parameters go into the config packet).
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Write every packet link-checked (wire format version 2: no CRC, for a link that
    /// checks integrity itself, such as the scanner front end's SPI with its hardware CRC).
    #[arg(long)]
    pub link_checked: bool,
}

/// Runs `curbtrace replay`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let cfg = match &args.config {
        Some(p) => Config::read(p)?,
        None => Config::default(),
    };
    let words = cfg.kernel_words().map_err(anyhow::Error::msg)?;
    let progress = if std::io::stderr().is_terminal() {
        Progress::bar()
    } else {
        Progress::hidden()
    };
    let opts = ExtractOptions {
        scanner: args.scanner,
        ..Default::default()
    };
    let (cols, las, traj, dropped, _) =
        pipeline::load(&args.points, &args.trajectory, &opts, &progress)?;
    let rule = LineRule::choose(&cols.scan_angle_deg, &cols.t, &cfg.replay.line());
    let file = std::fs::File::create(&args.output)
        .with_context(|| format!("{}: creating the stream file", args.output.display()))?;
    let mut w = std::io::BufWriter::with_capacity(1 << 20, file);
    let (mut packets, mut bytes) = (0u64, 0u64);
    progress.stage("encoding", cols.len() as u64);
    for rg in run::chunks(&cols, &rule, cfg.replay.chunk_points) {
        let end = rg.end;
        run::encode_stream(&cols, rg, &traj, &words, &rule, &mut |b: &[u8]| {
            packets += 1;
            bytes += b.len() as u64;
            if args.link_checked {
                let mut p = b.to_vec();
                curbtrace_core::wire::mark_link_checked(&mut p);
                w.write_all(&p)?;
            } else {
                w.write_all(b)?;
            }
            Ok(())
        })
        .with_context(|| format!("{}: writing the stream", args.output.display()))?;
        progress.set(end as u64);
    }
    w.flush()
        .with_context(|| format!("{}: writing the stream", args.output.display()))?;
    progress.finish();
    eprintln!(
        "points {} of {} ({} before, {} after the trajectory dropped); {packets} packets, {bytes} bytes to {}",
        cols.len(),
        las.points_in_file,
        dropped.0,
        dropped.1,
        args.output.display()
    );
    Ok(())
}
