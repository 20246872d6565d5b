//! Every LAS/LAZ file is read or refused with one true sentence: one test per reason, on
//! small files written here with the `las` writer and patched byte by byte where the
//! writer cannot produce the fault.

use curbtrace_host_sim::io::las::{read_points, NoCrs, ReadOptions};
use las::{Builder, Point, Writer};
use std::path::{Path, PathBuf};

mod common;

/// Byte offsets of LAS header fields (LAS 1.4 R15, Table 3), for patching.
mod at {
    pub const VERSION_MAJOR: usize = 24;
    pub const OFFSET_TO_POINTS: usize = 96;
    pub const VLR_COUNT: usize = 100;
    pub const FORMAT: usize = 104;
    pub const RECORD_LEN: usize = 105;
    pub const LEGACY_COUNT: usize = 107;
    pub const SCALE_X: usize = 131;
    pub const OFFSET_X: usize = 155;
    pub const COUNT_64: usize = 247;
}

/// `n` points in `format`, LAS `version`, LAZ when the path ends in .laz, with an optional
/// GeoTIFF projected-CRS key.
fn write(path: &Path, version: (u8, u8), format: u8, n: usize, epsg: Option<u16>) {
    let mut b = Builder::from(version);
    b.point_format = las::point::Format::new(format).unwrap();
    b.point_format.is_compressed = path.extension().is_some_and(|e| e == "laz");
    if let Some(code) = epsg {
        let words: [u16; 8] = [1, 1, 0, 1, 3072, 0, 1, code];
        b.vlrs.push(las::Vlr {
            user_id: "LASF_Projection".into(),
            record_id: 34735,
            description: "GeoKeyDirectoryTag".into(),
            data: words.iter().flat_map(|w| w.to_le_bytes()).collect(),
        });
    }
    let fmt = b.point_format;
    let mut w = Writer::from_path(path, b.into_header().unwrap()).unwrap();
    for k in 0..n {
        w.write_point(Point {
            x: k as f64 * 0.01,
            y: (k % 7) as f64,
            z: 1.0,
            gps_time: fmt.has_gps_time.then_some(k as f64 * 1e-4),
            color: fmt.has_color.then_some(las::Color::new(1, 2, 3)),
            intensity: k as u16,
            ..Default::default()
        })
        .unwrap();
    }
    w.close().unwrap();
}

fn tmp(name: &str) -> (tempfile::TempDir, PathBuf) {
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join(name);
    (d, p)
}

fn read(path: &Path) -> Result<u64, String> {
    read_points(path, &ReadOptions::default(), &mut |_, _| {})
        .map(|(c, _)| c.len() as u64)
        .map_err(|e| e.to_string())
}

/// The error for `bytes` written to `path`: one line, naming the file, without the
/// decoders' internal type names.
fn refused(path: &Path, bytes: &[u8]) -> String {
    std::fs::write(path, bytes).unwrap();
    let e = read(path).expect_err("must be refused");
    eprintln!("{e}");
    assert!(!e.contains('\n'), "one line: {e}");
    assert!(
        e.contains(&path.display().to_string()),
        "names the file: {e}"
    );
    for internal in [
        "IoError",
        "LasZipError",
        "Error(",
        "Io(",
        "format point format",
    ] {
        assert!(!e.contains(internal), "no internal names: {e}");
    }
    e
}

fn put(bytes: &mut [u8], at: usize, v: &[u8]) {
    bytes[at..at + v.len()].copy_from_slice(v);
}

/// The byte where the `laszip encoded` VLR's data starts.
fn laszip_data(bytes: &[u8]) -> usize {
    bytes
        .windows(14)
        .position(|w| w == b"laszip encoded")
        .expect("a laszip VLR")
        - 2
        + 54
}

#[test]
fn laz_pointwise_compression_is_named_and_comes_after_the_format_check() {
    let (_d, p) = tmp("pointwise.laz");
    write(&p, (1, 4), 6, 100, None);
    let mut bytes = std::fs::read(&p).unwrap();
    assert_eq!(read(&p), Ok(100));
    let vlr = laszip_data(&bytes);
    put(&mut bytes, vlr, &1u16.to_le_bytes());
    // Pointwise files have no chunk table: their first 8 point bytes are compressed data.
    let data = u32::from_le_bytes(bytes[at::OFFSET_TO_POINTS..][..4].try_into().unwrap());
    put(
        &mut bytes,
        data as usize,
        &364_654_882_546_516_200u64.to_le_bytes(),
    );
    let e = refused(&p, &bytes);
    assert!(
        e.ends_with(
            "LAZ pointwise compression (LASzip 1.x) is not supported; recompress with laszip or PDAL"
        ),
        "{e}"
    );
    // The same in format 0: the missing GPS time is the first reason.
    let (_d0, p0) = tmp("pointwise0.laz");
    write(&p0, (1, 2), 0, 100, None);
    let mut bytes = std::fs::read(&p0).unwrap();
    let vlr = laszip_data(&bytes);
    put(&mut bytes, vlr, &1u16.to_le_bytes());
    let e = refused(&p0, &bytes);
    assert!(e.contains("point format 0 has no GPS time"), "{e}");
}

#[test]
fn a_wrong_vlr_count_is_corrupt_not_truncated() {
    let (_d, p) = tmp("vlrs.las");
    write(&p, (1, 4), 6, 10, Some(6677));
    let mut bytes = std::fs::read(&p).unwrap();
    let n = u32::from_le_bytes(bytes[at::VLR_COUNT..][..4].try_into().unwrap());
    put(&mut bytes, at::VLR_COUNT, &(n + 1).to_le_bytes());
    let e = refused(&p, &bytes);
    assert!(
        e.contains("corrupt file")
            && e.contains(&format!("counts {} VLRs", n + 1))
            && !e.contains("truncated"),
        "{e}"
    );
}

#[test]
fn laz_with_more_points_than_its_chunk_table_is_corrupt() {
    let (_d, p) = tmp("count.laz");
    write(&p, (1, 4), 6, 1000, None);
    let mut bytes = std::fs::read(&p).unwrap();
    put(&mut bytes, at::LEGACY_COUNT, &0u32.to_le_bytes());
    put(&mut bytes, at::COUNT_64, &1_000_000u64.to_le_bytes());
    let e = refused(&p, &bytes);
    assert!(
        e.contains("corrupt file")
            && e.contains("header says 1000000 points")
            && e.contains("1 chunks of 50000 points"),
        "{e}"
    );
}

#[test]
fn damaged_laz_data_is_corrupt_with_where_and_a_cut_file_is_truncated() {
    let (_d, p) = tmp("flips.laz");
    write(&p, (1, 4), 6, 120_000, None);
    let good = std::fs::read(&p).unwrap();
    let data = u32::from_le_bytes(good[at::OFFSET_TO_POINTS..][..4].try_into().unwrap()) as usize;
    let table = u64::from_le_bytes(good[data..data + 8].try_into().unwrap()) as usize;
    // The chunk table's entries are arithmetic-coded byte counts: garbage there sends the
    // decoder past its chunks' data.
    let mut bytes = good.clone();
    for b in &mut bytes[table + 8..] {
        *b ^= 0x5a;
    }
    let e = refused(&p, &bytes);
    assert!(
        e.contains("corrupt file")
            && e.contains("LAZ point data while decoding points 0–")
            && !e.contains("truncated"),
        "{e}"
    );
    // Bit flips inside the compressed points: read with wrong values or refused as
    // corrupt, never called truncated.
    for k in 1..8 {
        let mut bytes = good.clone();
        let at = data + 8 + k * (table - data) / 9;
        for b in &mut bytes[at..at + 16] {
            *b ^= 0xa5;
        }
        std::fs::write(&p, &bytes).unwrap();
        if let Err(e) = read(&p) {
            assert!(!e.contains("truncated"), "flip at {at}: {e}");
        }
    }
    // A file cut short loses its chunk table: truncated.
    let e = refused(&p, &good[..good.len() / 2]);
    assert!(
        e.contains("truncated file") && e.contains("chunk table"),
        "{e}"
    );
}

#[test]
fn scale_zero_negative_or_nan_is_refused_naming_the_axis() {
    let (_d, p) = tmp("scale.las");
    write(&p, (1, 2), 1, 10, None);
    let good = std::fs::read(&p).unwrap();
    for (axis, v) in [('x', 0.0), ('y', -0.01), ('z', f64::NAN)] {
        let k = (axis as u8 - b'x') as usize;
        let mut bytes = good.clone();
        put(&mut bytes, at::SCALE_X + 8 * k, &v.to_le_bytes());
        let e = refused(&p, &bytes);
        assert!(
            e.contains(&format!("the header's {axis} scale is {v}"))
                && e.contains("positive finite"),
            "{e}"
        );
    }
    let mut bytes = good.clone();
    put(&mut bytes, at::OFFSET_X + 8, &f64::INFINITY.to_le_bytes());
    let e = refused(&p, &bytes);
    assert!(e.contains("the header's y offset is inf"), "{e}");
}

#[test]
fn records_too_short_for_their_format_say_so_once() {
    let (_d, p) = tmp("short.las");
    write(&p, (1, 4), 7, 10, None);
    let mut bytes = std::fs::read(&p).unwrap();
    put(&mut bytes, at::RECORD_LEN, &30u16.to_le_bytes());
    let e = refused(&p, &bytes);
    assert!(
        e.ends_with(
            "point records of 30 bytes are too short for point format 7, which needs 36 bytes"
        ),
        "{e}"
    );
}

#[test]
fn versions_1_0_to_1_4_read_and_others_are_refused() {
    for minor in 0..=4u8 {
        let (_d, p) = tmp(&format!("v1{minor}.las"));
        write(&p, (1, minor), 1, 5, None);
        assert_eq!(read(&p), Ok(5), "LAS 1.{minor}");
    }
    let (_d, p) = tmp("v20.las");
    write(&p, (1, 4), 6, 5, None);
    let mut bytes = std::fs::read(&p).unwrap();
    put(&mut bytes, at::VERSION_MAJOR, &[2, 0]);
    let e = refused(&p, &bytes);
    assert!(
        e.contains("LAS version 2.0 is not supported; curbtrace reads LAS 1.0–1.4"),
        "{e}"
    );
    // The version is the reason even when the rest of the header is missing.
    let e = refused(&p, &bytes[..40]);
    assert!(e.contains("LAS version 2.0"), "{e}");
}

#[test]
fn a_format_byte_that_names_no_format_is_refused() {
    let (_d, p) = tmp("f11.las");
    write(&p, (1, 4), 6, 5, None);
    let mut bytes = std::fs::read(&p).unwrap();
    for byte in [11u8, 0x8b, 0x46] {
        bytes[at::FORMAT] = byte;
        let e = refused(&p, &bytes);
        assert!(
            e.contains(&format!(
                "point format byte {byte} names no LAS point format"
            )),
            "{e}"
        );
    }
}

#[test]
fn the_reason_for_a_missing_crs_is_kept() {
    let (_d, p) = tmp("crs.las");
    for (epsg, crs, why) in [
        (Some(6677), true, None),
        (None, false, Some(NoCrs::Absent)),
        (Some(32767), false, Some(NoCrs::UserDefined)),
        (Some(7), false, Some(NoCrs::Unrecognised)),
    ] {
        write(&p, (1, 4), 6, 3, epsg);
        let (_, info) = read_points(&p, &ReadOptions::default(), &mut |_, _| {}).unwrap();
        assert_eq!((info.crs.is_some(), info.no_crs), (crs, why), "{epsg:?}");
    }
}

#[test]
fn extract_warns_when_the_output_has_no_crs_and_its_summary_suits_a_small_file() {
    let dir = tempfile::tempdir().unwrap();
    let road = common::Road {
        length_m: 4.0,
        ..Default::default()
    };
    let las = dir.path().join("road.las");
    let traj = dir.path().join("trajectory.csv");
    let points = road.write(&las, &traj);
    assert!(points < 1_000_000);
    let out = dir.path().join("edges.geojson");
    let warnings = |err: &str| -> Vec<String> {
        err.lines()
            .filter(|l| l.starts_with("warning"))
            .map(String::from)
            .collect()
    };
    // The road's file has an EPSG code: no warning.
    let (ok, err) = common::extract(&las, &traj, &out);
    assert!(ok && warnings(&err).is_empty(), "{err}");
    let memory = err.lines().find(|l| l.starts_with("peak memory")).unwrap();
    assert!(
        memory.contains(" MiB") && !memory.contains("B/point"),
        "{memory}"
    );
    // The same file with its GeoTIFF VLR renamed has no CRS record.
    let mut bytes = std::fs::read(&las).unwrap();
    let id = bytes
        .windows(15)
        .position(|w| w == b"LASF_Projection")
        .unwrap();
    bytes[id..id + 15].copy_from_slice(b"not_a_crs_vlr__");
    std::fs::write(&las, &bytes).unwrap();
    let (ok, err) = common::extract(&las, &traj, &out);
    let w = warnings(&err);
    assert!(ok && w.len() == 1, "{err}");
    assert!(
        w[0].contains("edges.geojson")
            && w[0].contains("the output has no CRS")
            && w[0].contains("the input has no CRS record"),
        "{err}"
    );
    // A drive too short for an edge: total length 0.0 m, not -0.0 m.
    let short = common::Road {
        length_m: 0.3,
        ..Default::default()
    };
    short.write(&las, &traj);
    let (ok, err) = common::extract(&las, &traj, &out);
    assert!(
        ok && err.contains("edges              0, total length 0.0 m"),
        "{err}"
    );
}
