//! Bad input: each one gives a one-line error naming the file and the problem,
//! never a panic. Small LAS/LAZ files are built here with the `las` writer.

use curbtrace_host_sim::io::las_in::{read_points, ReadOptions};
use curbtrace_host_sim::io::trajectory::Trajectory;
use las::{Builder, Point, Writer};
use std::path::{Path, PathBuf};

fn write_las(path: &Path, format: u8, n: usize) {
    let mut b = Builder::from((1, 4));
    b.point_format = las::point::Format::new(format).unwrap();
    b.point_format.is_compressed = path.extension().is_some_and(|e| e == "laz");
    let header = b.into_header().unwrap();
    let mut w = Writer::from_path(path, header).unwrap();
    for k in 0..n {
        let fmt = las::point::Format::new(format).unwrap();
        w.write_point(Point {
            color: fmt.has_color.then_some(las::Color::new(1, 2, 3)),
            x: k as f64 * 0.01,
            y: (k % 7) as f64,
            z: 1.0,
            gps_time: fmt.has_gps_time.then_some(k as f64 * 1e-4),
            intensity: k as u16,
            ..Default::default()
        })
        .unwrap();
    }
    w.close().unwrap();
}

fn read_err(path: &Path) -> String {
    let e = read_points(path, &ReadOptions::default(), &mut |_, _| {})
        .expect_err("bad input must be an error")
        .to_string();
    assert!(!e.contains('\n'), "one line: {e}");
    assert!(
        e.contains(&path.display().to_string()),
        "names the file: {e}"
    );
    e
}

fn tmp(name: &str) -> (tempfile::TempDir, PathBuf) {
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join(name);
    (d, p)
}

#[test]
fn not_a_las_file() {
    let (_d, p) = tmp("notes.las");
    std::fs::write(&p, "time,x,y,z\n1,2,3,4\n").unwrap();
    let e = read_err(&p);
    assert!(e.contains("not a LAS/LAZ file"), "{e}");
}

#[test]
fn empty_file() {
    let (_d, p) = tmp("empty.las");
    std::fs::write(&p, b"").unwrap();
    let e = read_err(&p);
    assert!(e.contains("empty file"), "{e}");
}

#[test]
fn missing_file() {
    let (_d, p) = tmp("nowhere.las");
    let e = read_err(&p);
    assert!(e.contains("No such file"), "{e}");
}

#[test]
fn las_without_gps_time() {
    for f in [0u8, 2] {
        let (_d, p) = tmp(&format!("f{f}.las"));
        write_las(&p, f, 10);
        let e = read_err(&p);
        assert!(
            e.contains(&format!("point format {f} has no GPS time")),
            "{e}"
        );
    }
}

#[test]
fn las_with_no_points() {
    let (_d, p) = tmp("none.las");
    write_las(&p, 6, 0);
    let e = read_err(&p);
    assert!(e.contains("no points"), "{e}");
}

#[test]
fn truncated_las_header() {
    let (_d, p) = tmp("cut.las");
    write_las(&p, 6, 100);
    let bytes = std::fs::read(&p).unwrap();
    std::fs::write(&p, &bytes[..150]).unwrap();
    let e = read_err(&p);
    assert!(e.contains("truncated") && e.contains("header"), "{e}");
}

#[test]
fn truncated_las_points_are_caught_before_allocating() {
    let (_d, p) = tmp("cut.las");
    write_las(&p, 6, 100);
    let bytes = std::fs::read(&p).unwrap();
    std::fs::write(&p, &bytes[..bytes.len() - 45]).unwrap();
    let e = read_err(&p);
    // 100 points of 30 bytes after a 375-byte header: 3375 bytes needed.
    assert!(
        e.contains("header says 100 points of 30 bytes")
            && e.contains("3375 bytes")
            && e.contains("3330 bytes"),
        "{e}"
    );
}

#[test]
fn header_count_larger_than_the_file_is_caught_before_allocating() {
    let (_d, p) = tmp("lie.las");
    write_las(&p, 6, 10);
    let mut bytes = std::fs::read(&p).unwrap();
    // LAS 1.4 64-bit point count at byte 247: claim 10^12 points. Were it trusted, the
    // columns alone would take 38 TB.
    // The legacy count 0, as LAS 1.4 wants for format 6 (a legacy count that disagrees
    // with the 64-bit one is an error of its own, tested in `io::las`).
    bytes[107..111].copy_from_slice(&0u32.to_le_bytes());
    bytes[247..255].copy_from_slice(&1_000_000_000_000u64.to_le_bytes());
    std::fs::write(&p, &bytes).unwrap();
    let e = read_err(&p);
    assert!(
        e.contains("header says 1000000000000 points") && e.contains("truncated or corrupt header"),
        "{e}"
    );
}

#[test]
fn offset_to_points_beyond_the_file() {
    let (_d, p) = tmp("off.las");
    write_las(&p, 6, 10);
    let mut bytes = std::fs::read(&p).unwrap();
    bytes[96..100].copy_from_slice(&1_000_000u32.to_le_bytes());
    std::fs::write(&p, &bytes).unwrap();
    let e = read_err(&p);
    assert!(e.contains("point data at byte 1000000"), "{e}");
}

#[test]
fn truncated_laz() {
    let (_d, p) = tmp("cut.laz");
    write_las(&p, 6, 200_000);
    let bytes = std::fs::read(&p).unwrap();
    for keep in [bytes.len() / 2, bytes.len() - 100, 400] {
        std::fs::write(&p, &bytes[..keep]).unwrap();
        let e = read_err(&p);
        assert!(e.contains("truncated file"), "{keep}: {e}");
    }
}

#[test]
fn laz_with_inflated_count_does_not_allocate_for_it() {
    let (_d, p) = tmp("lie.laz");
    write_las(&p, 6, 1000);
    let mut bytes = std::fs::read(&p).unwrap();
    bytes[107..111].copy_from_slice(&0u32.to_le_bytes()); // legacy count 0, as LAS 1.4 allows
    bytes[247..255].copy_from_slice(&1_000_000_000_000u64.to_le_bytes());
    std::fs::write(&p, &bytes).unwrap();
    let e = read_err(&p);
    assert!(!e.is_empty());
}

fn traj_err(text: &str) -> String {
    let (_d, p) = tmp("trajectory.csv");
    std::fs::write(&p, text).unwrap();
    let e = Trajectory::read_csv(&p)
        .expect_err("bad trajectory")
        .to_string();
    assert!(e.contains("trajectory.csv") && !e.contains('\n'), "{e}");
    e
}

#[test]
fn trajectory_bad_header() {
    let e = traj_err("gps_time,x,y,z,roll,pitch,heading\n1,0,0,0,0,0,0\n2,0,0,0,0,0,0\n");
    assert!(e.contains("bad header") && e.contains("\"time\""), "{e}");
}

#[test]
fn trajectory_nan() {
    let e = traj_err("time,x,y,z,roll,pitch,heading\n1,0,0,0,0,0,0\n2,0,0,nan,0,0,0\n");
    assert!(e.contains("line 3") && e.contains("column z"), "{e}");
}

#[test]
fn trajectory_times_going_backwards() {
    let e =
        traj_err("time,x,y,z,roll,pitch,heading\n1,0,0,0,0,0,0\n3,0,0,0,0,0,0\n2,0,0,0,0,0,0\n");
    assert!(
        e.contains("line 4") && e.contains("strictly increase"),
        "{e}"
    );
}

mod common;

#[test]
fn cli_bad_inputs_exit_non_zero_with_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let road = common::Road {
        length_m: 4.0,
        ..Default::default()
    };
    let las = dir.path().join("road.las");
    let traj = dir.path().join("trajectory.csv");
    road.write(&las, &traj);
    let out = dir.path().join("edges.geojson");
    let junk = dir.path().join("junk.las");
    std::fs::write(&junk, "hello").unwrap();
    let bad_traj = dir.path().join("bad.csv");
    std::fs::write(&bad_traj, "time,x,y\n1,2,3\n").unwrap();
    // Trajectory in GPS week seconds against points in adjusted standard time.
    let week = dir.path().join("week.csv");
    std::fs::write(
        &week,
        "time,x,y,z,roll,pitch,heading\n300000,500000,4000000,2,0,0,0\n300010,500000,4000080,2,0,0,0\n",
    )
    .unwrap();
    for (p, t, want) in [
        (&junk, &traj, "not a LAS/LAZ file"),
        (&las, &bad_traj, "bad header"),
        (&las, &week, "GPS week seconds"),
    ] {
        let (ok, err) = common::extract(p, t, &out);
        assert!(!ok, "{err}");
        assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
        assert!(err.contains(want), "{err}");
    }
}

#[test]
fn points_partly_outside_the_trajectory_are_dropped_and_counted() {
    use curbtrace_host_sim::pipeline::{load, ExtractOptions, Progress};
    let dir = tempfile::tempdir().unwrap();
    let road = common::Road {
        length_m: 8.0,
        ..Default::default()
    };
    let las = dir.path().join("road.las");
    let traj = dir.path().join("trajectory.csv");
    road.write(&las, &traj);
    // Keep only the trajectory samples between 0.2 s and 0.7 s of the 1 s drive (samples
    // are at 0.05 + 0.1 k s, so 0.25 … 0.65 s remain).
    let text = std::fs::read_to_string(&traj).unwrap();
    let mut lines = text.lines();
    let mut cut = String::from(lines.next().unwrap());
    cut.push('\n');
    for l in lines {
        let t: f64 = l.split(',').next().unwrap().parse().unwrap();
        if (common::T0 + 0.2..=common::T0 + 0.7).contains(&t) {
            cut.push_str(l);
            cut.push('\n');
        }
    }
    std::fs::write(&traj, cut).unwrap();
    let (all, _) = read_points(&las, &ReadOptions::default(), &mut |_, _| {}).unwrap();
    let (t0, t1) = (common::T0 + 0.25, common::T0 + 0.65);
    let before = all.t.iter().filter(|&&t| t < t0).count() as u64;
    let after = all.t.iter().filter(|&&t| t > t1).count() as u64;
    assert!(before > 0 && after > 0);
    let (cols, info, _, dropped, _) =
        load(&las, &traj, &ExtractOptions::default(), &Progress::hidden()).unwrap();
    assert_eq!(dropped, (before, after));
    assert_eq!(cols.len() as u64 + before + after, info.points_selected);
    assert!(cols.t.iter().all(|&t| (t0..=t1).contains(&t)));
}

/// Output into a pipe whose reader has gone (`curbtrace … | head`) ends the program
/// quietly, as other command-line tools do: no panic message, no exit code 101.
#[test]
fn output_into_a_closed_pipe_ends_quietly() {
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_curbtrace"))
        .args(["extract", "--print-config"])
        .stdout(writer)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_ne!(out.status.code(), Some(101), "{stderr}");
}
