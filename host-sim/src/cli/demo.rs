//! `curbtrace demo [--out DIR] [--method bend|qiu]`: simulates a scene, extracts its road
//! edges, evaluates them and writes the edges, `report.md`, `eval.json` and the pictures
//! (SPEC §4, issue 5). Needs no input files.
//!
//! The steps after extraction live in the library
//! ([`curbtrace_host_sim::eval::report::write_demo_outputs`]) so the end-to-end tests can
//! run them too; this file only strings the stages together.

use clap::ValueEnum;
use std::path::PathBuf;

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
    #[arg(long, default_value = "curbtrace-demo", value_name = "DIR")]
    pub out: PathBuf,
    /// Extraction method.
    #[arg(long, value_enum, default_value_t = MethodArg::Bend)]
    pub method: MethodArg,
}

/// Runs `curbtrace demo`.
///
/// The stages, once the simulator and the extractor are part of this build:
/// 1. `simulate` the demo scene into `--out` (`points.laz`, `trajectory.csv`,
///    `reference.geojson`);
/// 2. extract with `--method` and write `edges.geojson` (with the LAS CRS);
/// 3. take the points' x, y, z, the trajectory and one scanline's x′, z′ and ρ before and
///    after smoothing (a line crossing a curb on both sides);
/// 4. `eval::report::write_demo_outputs` (metrics, `eval.json`, pictures, `report.md`) and
///    print the metrics table and the report's path.
pub fn run(args: Args) -> anyhow::Result<()> {
    anyhow::bail!(
        "curbtrace demo (--method {}, --out {}): this build does not have the scene simulator \
         and the extractor wired in yet; run `curbtrace simulate`, `curbtrace extract` and \
         `curbtrace eval` one after the other instead",
        args.method.as_str(),
        args.out.display()
    )
}
