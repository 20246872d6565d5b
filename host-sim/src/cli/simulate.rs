//! `curbtrace simulate --scene NAME -o DIR [--seed N] [--speed KMH] [--sensor SENSOR]
//! [--duration S]`: simulates a mobile laser scanning scene and writes `points.laz`,
//! `trajectory.csv`, `reference.geojson` and `reference_strict.geojson` (docs/simulator.md).

use anyhow::Context;
use curbtrace_host_sim::simulate::{self, spinning::SpinSensor, SpinOutput};
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
    /// A spinning multi-beam lidar on the roof instead of the scene's profiler: vlp16,
    /// hdl32, hdl64 or os1-64. The LAS carries each point's ring as an extra-bytes
    /// dimension (docs/simulator.md).
    #[arg(long)]
    pub sensor: Option<String>,
    /// Name of the ring dimension written with --sensor: ring, laser_id, channel, or none
    /// (no ring dimension, as some converters write).
    #[arg(long, default_value = "ring", requires = "sensor")]
    pub ring_name: String,
    /// Seconds of driving from the scene's start (default: the scene's whole drive).
    #[arg(long)]
    pub duration: Option<f64>,
    /// Profilers on the vehicle: 1, or 2 in an X (the second mirrored, with a lever arm;
    /// channels 0 and 1 in one file, `mounts.toml` and a reference per scanner beside it).
    #[arg(long, default_value_t = 1, conflicts_with = "sensor")]
    pub scanners: u8,
    /// Passes: 1, or 2 (the street driven back the other way after the first pass, its
    /// GNSS solution offset by --pass-offset; a reference per pass beside it).
    #[arg(long, default_value_t = 1, conflicts_with_all = ["sensor", "scanners"])]
    pub passes: u8,
    /// The second pass's GNSS offset from the first, metres (direction from the seed).
    #[arg(long, default_value_t = 0.10, requires = "passes")]
    pub pass_offset: f64,
    /// Also writes every toe line, seen or not (the reference without its visibility
    /// rule), to this GeoJSON file: where extracted length off the reference lies in the
    /// reference's holes. One profiler and one pass only.
    #[arg(long, conflicts_with_all = ["sensor", "scanners", "passes"])]
    pub whole_toes: Option<PathBuf>,
}

/// Runs `curbtrace simulate`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let mut spec = simulate::scene_for(&args.scene, args.seed)?;
    if let Some(d) = args.duration {
        anyhow::ensure!(
            d.is_finite() && d > 0.0,
            "--duration {d}: seconds of driving must be positive"
        );
        // Road length at the nominal speed (the drive's speed varies by a few per cent).
        let v = args.speed.unwrap_or(spec.speed_kmh) / 3.6;
        spec.drive.1 = spec.drive.1.min(spec.drive.0 + d * v);
    }
    let sensor = match &args.sensor {
        None => None,
        Some(k) => Some(SpinSensor::by_key(k).with_context(|| {
            let keys: Vec<&str> = SpinSensor::ALL.iter().map(|s| s.key).collect();
            format!("unknown sensor {k:?}; valid sensors: {}", keys.join(", "))
        })?),
    };
    let ring_name = match args.ring_name.as_str() {
        "none" => None,
        n @ ("ring" | "laser_id" | "channel") => Some(n),
        n => anyhow::bail!("--ring-name {n:?}: one of ring, laser_id, channel, none"),
    };
    let spin = sensor
        .as_ref()
        .map(|sensor| SpinOutput { sensor, ring_name });
    if !spec.description.is_empty() {
        println!("{}", spec.description);
    }
    let progress = std::io::stderr().is_terminal();
    let s = match (args.scanners, args.passes) {
        (1, 1) => simulate::run_with(&spec, args.seed, args.speed, spin, &args.out, progress),
        (2, 1) => simulate::dual::run_two(&spec, args.seed, args.speed, &args.out, progress),
        (1, 2) => simulate::passes::run_passes(
            &spec,
            args.seed,
            args.speed,
            args.pass_offset,
            &args.out,
            progress,
        ),
        (n, 1) => anyhow::bail!("--scanners {n}: 1 or 2"),
        (_, n) => anyhow::bail!("--passes {n}: 1 or 2"),
    }
    .with_context(|| format!("simulating scene {}", args.scene))?;
    if let Some(path) = &args.whole_toes {
        simulate::write_whole_toes(&spec, args.seed, args.speed, path)
            .with_context(|| format!("writing {}", path.display()))?;
    }
    let [curb, cut, inter, bay] = s.reference_m;
    println!(
        "{}{}: {} points, {} lines, {:.1} m driven in {:.1} s, reference {:.1} m (curb {:.1}, curb_cut {:.1}, intersection {:.1}, bus_bay {:.1}); {:.1} s wall ({:.1} s simulating, {:.1} s writing)",
        s.scene,
        sensor.map(|x| format!(" ({})", x.name)).unwrap_or_default(),
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
    let strict = s.reference_path.with_file_name("reference_strict.geojson");
    println!(
        "wrote {}, {}, {}, {}",
        s.points_path.display(),
        s.trajectory_path.display(),
        s.reference_path.display(),
        strict.display()
    );
    Ok(())
}
