//! The LAZ/LAS decoder alone, for the end-to-end ratio of docs/benchmarks.md: decodes every
//! point of the given files through the `las` crate's `fill_points` (the reader `extract`
//! uses, laz-rs with its parallel decoder) in slabs of `SLAB` points and prints points,
//! seconds and points per second.
//!
//! `cargo run --release -p curbtrace-host-sim --example decode -- SLAB FILE...`

use std::time::Instant;

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let slab: u64 = args.get(1).map_or(Ok(1 << 15), |s| s.parse())?;
    let t0 = Instant::now();
    let mut total = 0u64;
    let mut sum = 0f64;
    for f in &args[2..] {
        let mut r = las::Reader::from_path(f)?;
        let header = r.header().clone();
        let mut pd = las::PointDataBuilder::new().for_header(&header).build();
        loop {
            let n = r.fill_points(slab, &mut pd)?;
            if n == 0 {
                break;
            }
            // Touch a column so the decode cannot be skipped.
            sum += pd.x().next().unwrap_or(0.0);
            total += n;
        }
    }
    let s = t0.elapsed().as_secs_f64();
    println!(
        "{total} points in {s:.3} s ({:.2} M points/s), checksum {sum:.1}",
        total as f64 / s / 1e6
    );
    Ok(())
}
