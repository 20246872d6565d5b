//! `curbtrace eval` (SKELETON: not implemented yet).

/// Arguments of `curbtrace eval`.
#[derive(clap::Args)]
pub struct Args {}

/// Runs `curbtrace eval`.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("curbtrace eval is not implemented yet")
}
