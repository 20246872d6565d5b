//! The streaming extract against the whole-file one on the simulated `tiny` scene:
//! one section as long as the street gives the same bytes, the default window the same
//! edge geometry; the same points split into several files (given in any order) or stored
//! out of time order give the same edges as one ordered file.

use curbtrace_host_sim::config::Config;
use curbtrace_host_sim::model::EdgeLine;
use curbtrace_host_sim::output::geojson::lines_to_geojson;
use curbtrace_host_sim::pipeline::{self, ExtractOptions, ExtractResult, Progress};
use curbtrace_host_sim::simulate;
use curbtrace_host_sim::stream::{self, WindowParams};
use std::path::{Path, PathBuf};

fn tiny(dir: &Path) -> (PathBuf, PathBuf) {
    let spec = simulate::scene_by_name("tiny").expect("scene exists");
    simulate::run(&spec, 1, None, dir, false).expect("simulation runs");
    (dir.join("points.laz"), dir.join("trajectory.csv"))
}

fn streamed(points: &[PathBuf], traj: &Path, w: &WindowParams) -> ExtractResult {
    stream::extract(
        points,
        traj,
        &Config::default(),
        &ExtractOptions::default(),
        w,
        &Progress::hidden(),
    )
    .expect("streaming extract runs")
}

fn geojson(r: &ExtractResult) -> String {
    serde_json::to_string(&lines_to_geojson(&r.edges, r.crs.as_ref())).unwrap()
}

/// Edges in a canonical order (the stream closes them in road order, the whole-file run in
/// seed order).
fn canonical(edges: &[EdgeLine]) -> Vec<String> {
    let mut v: Vec<String> = edges
        .iter()
        .map(|e| serde_json::to_string(&lines_to_geojson(std::slice::from_ref(e), None)).unwrap())
        .collect();
    v.sort();
    v
}

/// The points of `src` rewritten as uncompressed LAS files, one per index range of the
/// points in file order, each range optionally reversed (out of time order).
fn write_parts(src: &Path, dir: &Path, cuts: &[usize], reverse: bool) -> Vec<PathBuf> {
    let mut reader = las::Reader::from_path(src).unwrap();
    let mut header = las::Builder::from(reader.header().clone());
    header.point_format.is_compressed = false;
    let header = header.into_header().unwrap();
    let points: Vec<las::Point> = reader
        .read_all()
        .unwrap()
        .points()
        .map(|p| p.unwrap())
        .collect();
    let mut bounds = vec![0];
    bounds.extend_from_slice(cuts);
    bounds.push(points.len());
    let mut out = Vec::new();
    for (k, w) in bounds.windows(2).enumerate() {
        let path = dir.join(format!("part{k}.las"));
        let mut wr = las::Writer::from_path(&path, header.clone()).unwrap();
        let mut part: Vec<las::Point> = points[w[0]..w[1]].to_vec();
        if reverse {
            part.reverse();
        }
        for p in part {
            wr.write_point(p).unwrap();
        }
        wr.close().unwrap();
        out.push(path);
    }
    out
}

#[test]
fn one_section_as_long_as_the_street_is_the_whole_file_run_byte_for_byte() {
    let dir = tempfile::tempdir().unwrap();
    let (points, traj) = tiny(dir.path());
    let whole = pipeline::extract_file(&points, &traj, &Config::default()).unwrap();
    let one = streamed(
        std::slice::from_ref(&points),
        &traj,
        &WindowParams {
            section_m: 1e9,
            margin_m: 0.0,
            ..WindowParams::default()
        },
    );
    assert!(!whole.edges.is_empty());
    assert_eq!(geojson(&one), geojson(&whole));
    // The same counts from the core; only the packets differ (more chunks, more packets).
    let (a, b) = (&one.summary.core, &whole.summary.core);
    assert_eq!(
        (
            a.points_sent,
            a.scanlines,
            a.kept,
            a.irregular,
            a.no_neighbour,
            a.truncated,
            a.lost
        ),
        (
            b.points_sent,
            b.scanlines,
            b.kept,
            b.irregular,
            b.no_neighbour,
            b.truncated,
            b.lost
        )
    );
    assert_eq!(one.summary.candidates, whole.summary.candidates);
    // The default window: the same edges, closed section by section.
    let def = streamed(
        std::slice::from_ref(&points),
        &traj,
        &WindowParams::default(),
    );
    assert_eq!(canonical(&def.edges), canonical(&whole.edges));
    // Short sections with a small margin do change edges: the window is what bounds them.
    let short = streamed(
        std::slice::from_ref(&points),
        &traj,
        &WindowParams {
            section_m: 2.0,
            margin_m: 0.5,
            ..WindowParams::default()
        },
    );
    assert_ne!(canonical(&short.edges), canonical(&whole.edges));
}

#[test]
fn several_files_in_any_order_and_out_of_order_files_give_the_same_edges() {
    let dir = tempfile::tempdir().unwrap();
    let (points, traj) = tiny(dir.path());
    let w = WindowParams::default();
    let base = streamed(std::slice::from_ref(&points), &traj, &w);
    let n = base.summary.las.points_in_file as usize;
    // Three files, cut at arbitrary points (scanlines span the cuts), named out of order.
    let parts_dir = dir.path().join("parts");
    std::fs::create_dir(&parts_dir).unwrap();
    let mut parts = write_parts(&points, &parts_dir, &[n / 3 + 17, 2 * n / 3 + 5], false);
    parts.reverse();
    let multi = streamed(&parts, &traj, &w);
    assert_eq!(geojson(&multi), geojson(&base));
    assert_eq!(multi.summary.core, base.summary.core);
    assert!(!multi.summary.las.was_reordered);
    // The directory as input reads the same files.
    let by_dir = streamed(std::slice::from_ref(&parts_dir), &traj, &w);
    assert_eq!(geojson(&by_dir), geojson(&base));
    // Each file stored backwards in time: detected, sorted through a temporary directory.
    let rev_dir = dir.path().join("rev");
    std::fs::create_dir(&rev_dir).unwrap();
    let rev = write_parts(&points, &rev_dir, &[n / 2], true);
    let sorted = streamed(&rev, &traj, &w);
    assert!(sorted.summary.las.was_reordered);
    assert_eq!(canonical(&sorted.edges), canonical(&base.edges));
}

#[test]
fn bad_inputs_name_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let (_, traj) = tiny(dir.path());
    let missing = dir.path().join("nothing-*.laz");
    let err = stream::extract(
        &[missing],
        &traj,
        &Config::default(),
        &ExtractOptions::default(),
        &WindowParams::default(),
        &Progress::hidden(),
    )
    .expect_err("no input is an error")
    .to_string();
    assert!(err.contains("nothing-*.laz"), "{err}");
    let bad = dir.path().join("bad.laz");
    std::fs::write(&bad, b"not a point file at all").unwrap();
    let err = stream::extract(
        &[bad],
        &traj,
        &Config::default(),
        &ExtractOptions::default(),
        &WindowParams::default(),
        &Progress::hidden(),
    )
    .expect_err("a bad file is an error")
    .to_string();
    assert!(err.contains("bad.laz"), "{err}");
}
