//! `curbtrace` — road edges from mobile laser scanning point clouds (docs/spec.md §4).
//!
//! Each subcommand lives in its own file under `host-sim/src/cli/`.

use clap::{Parser, Subcommand};

mod cli;

#[derive(Parser)]
#[command(
    name = "curbtrace",
    version,
    about = "Road edges (curb toes) from MLS point clouds"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Simulates the default scene, extracts, evaluates, writes edges, report and plots.
    Demo(cli::demo::Args),
    /// Extracts road edges from a LAS/LAZ file and its trajectory (the main job).
    Extract(cli::extract::Args),
    /// Curb polylines per lidar frame (KITTI, nuScenes, PCD with rings), in the sensor frame.
    Frame(cli::frame::Args),
    /// Simulates a mobile laser scanning scene: points.laz, trajectory.csv, reference.geojson.
    Simulate(cli::simulate::Args),
    /// Scores extracted edges against reference lines (Heipke et al. 1997, docs/spec.md §5).
    Eval(cli::eval::Args),
    /// Writes the core's input byte stream for a LAS/LAZ file and its trajectory.
    Replay(cli::replay::Args),
    /// Runs the host build of the core over a byte stream and writes its output packets.
    Kernel(cli::kernel::Args),
}

fn main() {
    // Output piped into a reader that stops early (`curbtrace eval … | head`) ends the
    // program quietly, as other command-line tools do, instead of a panic on EPIPE.
    // SAFETY: resets one signal's disposition before any thread starts.
    unsafe { libc::signal(libc::SIGPIPE, libc::SIG_DFL) };
    curbtrace_host_sim::stream::malloc::one_arena();
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Demo(a) => cli::demo::run(a),
        Command::Extract(a) => cli::extract::run(a),
        Command::Frame(a) => cli::frame::run(a),
        Command::Simulate(a) => cli::simulate::run(a),
        Command::Eval(a) => cli::eval::run(a),
        Command::Replay(a) => cli::replay::run(a),
        Command::Kernel(a) => cli::kernel::run(a),
    };
    if let Err(e) = result {
        // One line: the cause chain joined, so scripts and people see file and problem.
        eprintln!("curbtrace: error: {e:#}");
        std::process::exit(1);
    }
}
