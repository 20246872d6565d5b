//! A straight road with curbs on both sides (toe lines known): `curbtrace extract` finds both with an RMS under 20 mm and nothing else.

mod common;

use common::{Road, Y0};
use std::process::Command;

fn check_edges(geojson: &std::path::Path, road: &Road) {
    let text = std::fs::read_to_string(geojson).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(
        v["crs"]["properties"]["name"], "urn:ogc:def:crs:EPSG::6677",
        "the LAS CRS is carried"
    );
    let feats = v["features"].as_array().unwrap();
    let (left_x, right_x) = road.toe_x();
    let mut sides = Vec::new();
    let mut tops = Vec::new();
    for f in feats {
        let p = &f["properties"];
        assert_eq!(p["method"], "bend");
        // Schema 2: every stretch is a toe feature and a top-of-curb feature.
        if p["line"] == "top" {
            tops.push(p["side"].as_str().unwrap().to_string());
            continue;
        }
        assert_eq!(p["line"], "toe", "a feature is a toe or a top");
        let side = p["side"].as_str().unwrap().to_string();
        let toe = if side == "left" { left_x } else { right_x };
        let coords = f["geometry"]["coordinates"].as_array().unwrap();
        let mut sq = 0.0;
        let (mut ymin, mut ymax) = (f64::MAX, f64::MIN);
        for c in coords {
            let (x, y) = (c[0].as_f64().unwrap(), c[1].as_f64().unwrap());
            sq += (x - toe).powi(2);
            ymin = ymin.min(y);
            ymax = ymax.max(y);
        }
        let rms = (sq / coords.len() as f64).sqrt();
        let len = p["length_m"].as_f64().unwrap();
        let h = p["curb_height_m"].as_f64().unwrap();
        eprintln!(
            "{side}: {} vertices, RMS {:.4} m, y {:.2}–{:.2}, length {len} m, height {h} m",
            coords.len(),
            rms,
            ymin - Y0,
            ymax - Y0
        );
        assert!(rms < 0.020, "{side} RMS {rms} m");
        assert!(
            len > 0.8 * road.length_m,
            "{side} covers {len} of {} m",
            road.length_m
        );
        assert!((h - road.curb_m).abs() < 0.03, "{side} height {h}");
        sides.push(side);
    }
    sides.sort();
    assert_eq!(sides, vec!["left", "right"], "both toes and nothing else");
    tops.sort();
    assert_eq!(tops, sides, "a top of curb beside each toe");
}

#[test]
fn extract_finds_both_toes_of_a_straight_road() {
    let dir = tempfile::tempdir().unwrap();
    let road = Road::default();
    let las = dir.path().join("road.las");
    let traj = dir.path().join("trajectory.csv");
    let n = road.write(&las, &traj);
    assert!(n > 100_000, "{n}");
    let out = dir.path().join("edges.geojson");
    let run = Command::new(env!("CARGO_BIN_EXE_curbtrace"))
        .args(["extract"])
        .arg(&las)
        .arg("--trajectory")
        .arg(&traj)
        .arg("-o")
        .arg(&out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    eprintln!("{stderr}");
    assert!(run.status.success(), "{stderr}");
    assert!(
        stderr.contains("points read") && stderr.contains("edges"),
        "{stderr}"
    );
    check_edges(&out, &road);
}

#[test]
fn library_and_laz_give_the_same_edges() {
    let dir = tempfile::tempdir().unwrap();
    let road = Road::default();
    let las = dir.path().join("road.las");
    let laz = dir.path().join("road.laz");
    let traj = dir.path().join("trajectory.csv");
    road.write(&las, &traj);
    road.write(&laz, &traj);
    let cfg = curbtrace_host_sim::config::Config::default();
    let a = curbtrace_host_sim::pipeline::extract_file(&las, &traj, &cfg).unwrap();
    let b = curbtrace_host_sim::pipeline::extract_file(&laz, &traj, &cfg).unwrap();
    assert_eq!(a.edges, b.edges);
    assert_eq!(a.edges.len(), 2);
    // Smaller chunks (more pipelines) give the same result: output independent of chunking
    // at line starts, and so of the thread count.
    let mut small = cfg.clone();
    small.replay.chunk_points = 10_000;
    let c = curbtrace_host_sim::pipeline::extract_file(&las, &traj, &small).unwrap();
    assert_eq!(a.edges, c.edges);
    assert!(c.summary.core.scanlines == a.summary.core.scanlines);
    // One thread gives the same edges as the default pool.
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let d =
        one.install(|| curbtrace_host_sim::pipeline::extract_file(&las, &traj, &small).unwrap());
    assert_eq!(a.edges, d.edges);
}
