//! Builds a simulated campaign for the memory benchmark of docs/benchmarks.md: `COPIES`
//! copies of one simulated drive (`points.laz`, `trajectory.csv` from `curbtrace
//! simulate`), each shifted by 2 km east and by a minute in time, one LAZ file per copy,
//! and the trajectory of all of them.
//!
//! `cargo run --release -p curbtrace-host-sim --example campaign -- SRC_DIR OUT_DIR COPIES`

use std::io::Write;
use std::path::PathBuf;

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let [_, src, out, copies] = args.as_slice() else {
        anyhow::bail!("usage: campaign SRC_DIR OUT_DIR COPIES");
    };
    let (src, out) = (PathBuf::from(src), PathBuf::from(out));
    let copies: u32 = copies.parse()?;
    std::fs::create_dir_all(&out)?;
    let traj = std::fs::read_to_string(src.join("trajectory.csv"))?;
    let mut lines = traj.lines();
    let head = lines.next().unwrap_or_default();
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap_or(0.0)).collect())
        .collect();
    let t0 = rows.first().map_or(0.0, |r| r[0]);
    let t1 = rows.last().map_or(0.0, |r| r[0]);
    let dt = ((t1 - t0) / 60.0).ceil() * 60.0 + 60.0;
    let mut w = std::io::BufWriter::new(std::fs::File::create(out.join("trajectory.csv"))?);
    writeln!(w, "{head}")?;
    for k in 0..copies {
        for r in &rows {
            let mut r = r.clone();
            r[0] += f64::from(k) * dt;
            r[1] += f64::from(k) * 2000.0;
            let s: Vec<String> = r.iter().map(|v| format!("{v:.6}")).collect();
            writeln!(w, "{}", s.join(","))?;
        }
    }
    w.flush()?;
    let mut reader = las::Reader::from_path(src.join("points.laz"))?;
    let points: Vec<las::Point> = reader.read_all()?.points().collect::<Result<_, _>>()?;
    let header = reader.header().clone();
    for k in 0..copies {
        let mut b = las::Builder::from(header.clone());
        b.transforms.x.offset += f64::from(k) * 2000.0;
        let mut wr =
            las::Writer::from_path(out.join(format!("strip{k:04}.laz")), b.into_header()?)?;
        for p in &points {
            let mut p = p.clone();
            p.x += f64::from(k) * 2000.0;
            p.gps_time = p.gps_time.map(|t| t + f64::from(k) * dt);
            wr.write_point(p)?;
        }
        wr.close()?;
        eprintln!("strip {k} written");
    }
    Ok(())
}
