//! `curbtrace demo` (SKELETON: not implemented yet).

/// Arguments of `curbtrace demo`.
#[derive(clap::Args)]
pub struct Args {}

/// Runs `curbtrace demo`.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("curbtrace demo is not implemented yet")
}
