//! `curbtrace replay` (SKELETON: not implemented yet).

/// Arguments of `curbtrace replay`.
#[derive(clap::Args)]
pub struct Args {}

/// Runs `curbtrace replay`.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("curbtrace replay is not implemented yet")
}
