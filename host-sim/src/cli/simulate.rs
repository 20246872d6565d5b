//! `curbtrace simulate --scene NAME -o DIR [--seed N] [--speed KMH]`: simulates a mobile
//! laser scanning scene and writes `points.laz`, `trajectory.csv`, `reference.geojson`.

use anyhow::Context;
use curbtrace_host_sim::simulate;
use std::io::IsTerminal;
use std::path::PathBuf;

/// Arguments of `curbtrace simulate`.
#[derive(clap::Args)]
pub struct Args {
    /// Scene: kawasaki, sapporo, curvy, tiny, or random (a street drawn from the seed).
    #[arg(long)]
    pub scene: String,
    /// Output directory (created if missing).
    #[arg(short = 'o', long = "out")]
    pub out: PathBuf,
    /// Seed for noise and scene details (weeds, leaves, walls, jitter); for `random`, the
    /// whole street.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Vehicle speed in km/h (default: the scene's).
    #[arg(long)]
    pub speed: Option<f64>,
}

/// Runs `curbtrace simulate`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let spec = simulate::scene_for(&args.scene, args.seed)?;
    if !spec.description.is_empty() {
        println!("{}", spec.description);
    }
    let progress = std::io::stderr().is_terminal();
    let s = simulate::run(&spec, args.seed, args.speed, &args.out, progress)
        .with_context(|| format!("simulating scene {}", args.scene))?;
    let [curb, cut, inter, bay] = s.reference_m;
    println!(
        "{}: {} points, {} lines, {:.1} m driven in {:.1} s, reference {:.1} m (curb {:.1}, curb_cut {:.1}, intersection {:.1}, bus_bay {:.1}); {:.1} s wall ({:.1} s simulating, {:.1} s writing)",
        s.scene,
        s.points,
        s.lines,
        s.length_m,
        s.duration_s,
        curb + cut + inter + bay,
        curb,
        cut,
        inter,
        bay,
        s.elapsed_s,
        s.simulate_s,
        s.write_s
    );
    println!(
        "wrote {}, {}, {}",
        s.points_path.display(),
        s.trajectory_path.display(),
        s.reference_path.display()
    );
    Ok(())
}
