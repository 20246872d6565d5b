//! `curbtrace simulate` (SKELETON: not implemented yet).

/// Arguments of `curbtrace simulate`.
#[derive(clap::Args)]
pub struct Args {}

/// Runs `curbtrace simulate`.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("curbtrace simulate is not implemented yet")
}
