//! Writes a LAS/LAZ file as uncompressed LAS, for the LAS throughput of docs/benchmarks.md
//! (the simulator writes LAZ only): header, VLRs and points copied through the `las` crate.
//!
//! `cargo run --release -p curbtrace-host-sim --example laz2las -- IN.laz OUT.las`

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    anyhow::ensure!(args.len() == 3, "usage: laz2las IN OUT.las");
    let mut r = las::Reader::from_path(&args[1])?;
    let header = r.header().clone();
    let mut pd = las::PointDataBuilder::new().for_header(&header).build();
    let mut w = las::Writer::from_path(&args[2], header)?;
    while r.fill_points(1 << 16, &mut pd)? > 0 {
        w.write_points(&pd)?;
    }
    w.close()?;
    Ok(())
}
