//! Writes the benchmark scene of `docs/benchmarks.md` (Host pipeline): a 500 m straight road,
//! about 7 M points, as LAS and LAZ with its trajectory. Ignored by default:
//!
//! ```sh
//! CURBTRACE_BENCH_DIR=/tmp/bench cargo test --release -p curbtrace-host-sim --test bench_scene -- --ignored
//! ```

mod common;

#[test]
#[ignore]
fn write_bench_scene() {
    let dir = std::path::PathBuf::from(
        std::env::var("CURBTRACE_BENCH_DIR").unwrap_or_else(|_| "target/bench-scene".into()),
    );
    std::fs::create_dir_all(&dir).unwrap();
    let road = common::Road {
        length_m: 500.0,
        ..Default::default()
    };
    let traj = dir.join("trajectory.csv");
    let n = road.write(&dir.join("road.las"), &traj);
    let m = road.write(&dir.join("road.laz"), &traj);
    assert_eq!(n, m);
    eprintln!("{n} points in {}", dir.display());
}
