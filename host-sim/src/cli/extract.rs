//! `curbtrace extract` (SKELETON: not implemented yet).

/// Arguments of `curbtrace extract`.
#[derive(clap::Args)]
pub struct Args {}

/// Runs `curbtrace extract`.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("curbtrace extract is not implemented yet")
}
