//! `curbtrace kernel` (SKELETON: not implemented yet).

/// Arguments of `curbtrace kernel`.
#[derive(clap::Args)]
pub struct Args {}

/// Runs `curbtrace kernel`.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("curbtrace kernel is not implemented yet")
}
