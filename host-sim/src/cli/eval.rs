//! `curbtrace eval`: scores extracted edges against reference lines (docs/spec.md §5) and prints the
//! table of Honma et al.'s Tables 2 and 3; `--json OUT` writes the same numbers as JSON.

use anyhow::Context;
use curbtrace_host_sim::eval::{evaluate, EvalParams};
use curbtrace_host_sim::model::read_geojson;
use std::path::PathBuf;

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
    if let Some(out) = &args.json {
        std::fs::write(out, report.to_json())
            .with_context(|| format!("{}: cannot write", out.display()))?;
    }
    print!("{}", report.to_markdown());
    Ok(())
}
