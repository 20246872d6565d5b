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

/// Decompresses `$CURBTRACE_LAZ` to `$CURBTRACE_LAS` (the simulator writes LAZ only; the
/// benchmark reads both):
///
/// ```sh
/// CURBTRACE_LAZ=kawasaki/points.laz CURBTRACE_LAS=kawasaki/points.las \
///   cargo test --release -p curbtrace-host-sim --test bench_scene -- --ignored laz_to_las
/// ```
#[test]
#[ignore]
fn laz_to_las() {
    let (Ok(src), Ok(dst)) = (
        std::env::var("CURBTRACE_LAZ"),
        std::env::var("CURBTRACE_LAS"),
    ) else {
        eprintln!("set CURBTRACE_LAZ and CURBTRACE_LAS");
        return;
    };
    let mut r = las::Reader::from_path(&src).unwrap();
    let mut h = r.header().clone().into_raw().unwrap();
    h.point_data_record_format &= 0x3f;
    let mut header = las::Header::from_raw(h).unwrap();
    // Drop the LASzip VLR: the copy is uncompressed.
    let mut b = las::Builder::new(header.clone().into_raw().unwrap()).unwrap();
    b.vlrs = header
        .vlrs()
        .iter()
        .filter(|v| v.user_id != "laszip encoded")
        .cloned()
        .collect();
    b.point_format.is_compressed = false;
    header = b.into_header().unwrap();
    let mut w = las::Writer::from_path(&dst, header).unwrap();
    let mut pd = las::PointDataBuilder::new().for_header(r.header()).build();
    let mut n = 0u64;
    while r.fill_points(1 << 20, &mut pd).unwrap() > 0 {
        n += pd.len() as u64;
        let out = las::PointDataBuilder::new()
            .for_header(w.header())
            .build_from_bytes(pd.raw_bytes().to_vec())
            .unwrap();
        w.write_points(&out).unwrap();
    }
    w.close().unwrap();
    eprintln!("{n} points to {dst}");
}
