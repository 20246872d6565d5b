//! Every output format, written for a few edges with and without a CRS, opens in GDAL's
//! `ogrinfo` with its own driver, the right feature count and (GeoPackage, FlatGeobuf) the
//! right CRS; the CLI chooses the format by the extension of `-o`.
//!
//! Needs `ogrinfo` (Debian package `gdal-bin`) and GDAL's GeoPackage validator (Debian package
//! `python3-gdal`), both installed by `scripts/test.sh`: the tests fail when they are missing.

use curbtrace_host_sim::model::{
    read_geojson, Category, Crs, CurbDetail, EdgeLine, Side, SCHEMA_MEMBER, SCHEMA_VERSION,
};
use curbtrace_host_sim::output::format::OutputFormat;
use curbtrace_host_sim::output::{csv, write_edges};
use std::path::Path;
use std::process::Command;

mod common;

/// WGS 84 / UTM zone 33N in WKT1 with its root EPSG authority.
const UTM33_WKT: &str = r#"PROJCS["WGS 84 / UTM zone 33N",GEOGCS["WGS 84",DATUM["WGS_1984",SPHEROID["WGS 84",6378137,298.257223563,AUTHORITY["EPSG","7030"]],AUTHORITY["EPSG","6326"]],PRIMEM["Greenwich",0,AUTHORITY["EPSG","8901"]],UNIT["degree",0.0174532925199433,AUTHORITY["EPSG","9122"]],AUTHORITY["EPSG","4326"]],PROJECTION["Transverse_Mercator"],PARAMETER["latitude_of_origin",0],PARAMETER["central_meridian",15],PARAMETER["scale_factor",0.9996],PARAMETER["false_easting",500000],PARAMETER["false_northing",0],UNIT["metre",1,AUTHORITY["EPSG","9001"]],AXIS["Easting",EAST],AXIS["Northing",NORTH],AUTHORITY["EPSG","32633"]]"#;

/// The top of curb 15 mm behind and `h` above a toe, with the heights and support.
fn detail(toe: &[[f64; 3]], h: f64, bridged: bool) -> Option<Box<CurbDetail>> {
    Some(Box::new(CurbDetail {
        top: toe.iter().map(|p| [p[0] - 0.015, p[1], p[2] + h]).collect(),
        height_m: vec![h; toe.len()],
        bridged,
        support_per_m: if bridged { 0.0 } else { 12.5 },
        ..CurbDetail::measured(toe)
    }))
}

/// Edges with their top lines: the first two of [`edges`], each with a top.
const WITH_TOP: usize = 2;

/// Four edges around (x0, y0): every class once, one without class, method or height; the
/// first two with their top of curb (the second bridged).
fn edges(x0: f64, y0: f64) -> Vec<EdgeLine> {
    let line = |dx: f64, n: usize, z: f64| -> Vec<[f64; 3]> {
        (0..n)
            .map(|k| {
                [
                    x0 + dx + 0.01 * k as f64,
                    y0 + 2.5 * k as f64,
                    z + 0.001 * k as f64,
                ]
            })
            .collect()
    };
    let (a, b) = (line(-3.5, 5, 10.0), line(3.5, 3, 10.2));
    vec![
        EdgeLine {
            detail: detail(&a, 0.148, false),
            points: a,
            side: Side::Left,
            category: Some(Category::Curb),
            method: Some("bend".into()),
            curb_height_m: Some(0.148),
        },
        EdgeLine {
            detail: detail(&b, 0.025, true),
            points: b,
            side: Side::Right,
            category: Some(Category::CurbCut),
            method: Some("bend".into()),
            curb_height_m: Some(0.025),
        },
        EdgeLine {
            points: line(8.0, 4, 10.1),
            side: Side::Right,
            category: Some(Category::Intersection),
            method: Some("qiu".into()),
            curb_height_m: Some(0.12),
            detail: None,
        },
        EdgeLine {
            points: line(-6.0, 2, 9.9),
            side: Side::Left,
            category: None,
            method: None,
            curb_height_m: None,
            detail: None,
        },
    ]
}

/// `ogrinfo -ro -al [-so] FILE`: stdout and stderr; fails the test when ogrinfo is missing.
fn ogrinfo(path: &Path, summary: bool) -> String {
    let mut cmd = Command::new("ogrinfo");
    cmd.args(["-ro", "-al"]);
    if summary {
        cmd.arg("-so");
    }
    let out = cmd.arg(path).output().unwrap_or_else(|e| {
        panic!("ogrinfo could not run ({e}): install Debian's gdal-bin (scripts/test.sh does)")
    });
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.status.success(), "ogrinfo {}:\n{text}", path.display());
    // A file GDAL reads with a warning or an error is not a clean file.
    assert!(
        !text.contains("Warning") && !text.contains("ERROR"),
        "ogrinfo {}:\n{text}",
        path.display()
    );
    text
}

/// Checks the driver and the feature count of every layer ogrinfo lists.
fn assert_opens(path: &Path, driver: &str, features: usize) -> String {
    let info = ogrinfo(path, true);
    assert!(
        info.contains(&format!("using driver `{driver}' successful")),
        "{}: driver {driver} expected:\n{info}",
        path.display()
    );
    assert!(
        info.contains(&format!("Feature Count: {features}\n")),
        "{}: {features} features expected:\n{info}",
        path.display()
    );
    info
}

/// The lines ogrinfo prints for the CRS of a layer (empty, or "(unknown)", when none).
fn srs_block(info: &str) -> String {
    info.lines()
        .skip_while(|l| !l.starts_with("Layer SRS WKT:"))
        .skip(1)
        .take_while(|l| !l.starts_with("Data axis") && !l.starts_with("FID Column"))
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn every_format_opens_in_gdal_with_its_driver_count_and_crs() {
    let dir = tempfile::tempdir().unwrap();
    // A projected WKT without a root authority: kept as WKT, no EPSG code.
    let custom = UTM33_WKT
        .replace("WGS 84 / UTM zone 33N", "site TM")
        .replace(r#",AUTHORITY["EPSG","32633"]]"#, "]");
    // (name, CRS, origin x, origin y, text the CRS block of GPKG and FGB must hold)
    type Case<'a> = (&'a str, Option<Crs>, f64, f64, Option<&'a str>);
    let cases: [Case; 4] = [
        (
            "epsg",
            Some(Crs::Epsg(6677)),
            -8_000.0,
            -38_000.0,
            Some(r#"ID["EPSG",6677]"#),
        ),
        (
            "wkt",
            Some(Crs::Wkt(UTM33_WKT.into())),
            500_000.0,
            5_000_000.0,
            Some(r#"ID["EPSG",32633]"#),
        ),
        (
            "wkt_no_code",
            Some(Crs::Wkt(custom)),
            500_000.0,
            5_000_000.0,
            Some(r#"PROJCRS["site TM""#),
        ),
        ("none", None, 1_000.0, 2_000.0, None),
    ];
    for (tag, crs, x0, y0, srs_mark) in cases {
        let lines = edges(x0, y0);
        // Each edge's toe, and the top of those that have one.
        let n = lines.len() + WITH_TOP;
        for ext in ["geojson", "csv", "gpkg", "fgb", "dxf"] {
            let path = dir.path().join(format!("edges_{tag}.{ext}"));
            write_edges(&path, &lines, crs.as_ref()).unwrap();
            let size = std::fs::metadata(&path).unwrap().len();
            eprintln!("{}: {size} bytes", path.display());
            if ext == "csv" {
                // Vertex rows, not features: checked by the header and the row count.
                let text = std::fs::read_to_string(&path).unwrap();
                let rows = lines.iter().map(|l| l.points.len()).sum::<usize>();
                assert!(text.starts_with(&format!("{}\n", csv::HEADER)));
                assert!(text.starts_with("edge,side,vertex,x,y,z,"));
                assert_eq!(text.lines().count(), rows + 1, "{tag}");
                continue;
            }
            let driver = match ext {
                "geojson" => "GeoJSON",
                "gpkg" => "GPKG",
                "fgb" => "FlatGeobuf",
                _ => "DXF",
            };
            let info = assert_opens(&path, driver, n);
            if ext == "dxf" {
                continue;
            }
            assert!(
                info.contains("Geometry: 3D Line String"),
                "{tag}.{ext}:\n{info}"
            );
            for field in [
                "side: String",
                "method: String",
                "length_m: Real",
                "curb_height_m: Real",
                "category: String",
                "line: String",
                "edge: Integer",
                "bridged: Integer(Boolean)",
                "support_per_m: Real",
            ] {
                assert!(info.contains(field), "{tag}.{ext}: {field}:\n{info}");
            }
            if ext == "geojson" {
                continue;
            }
            let srs = srs_block(&info);
            match srs_mark {
                Some(id) => assert!(srs.contains(id), "{tag}.{ext}: {id} expected:\n{info}"),
                // No CRS: GDAL prints nothing or "(unknown)".
                None => assert!(
                    !srs.contains("ID[\"EPSG\"") && !srs.contains("PROJCRS"),
                    "{tag}.{ext}: no CRS expected:\n{info}"
                ),
            }
        }
    }
}

/// The block ogrinfo prints for the feature whose line starts at `p`.
fn feature_block(info: &str, p: [f64; 3]) -> Option<&str> {
    let first = format!("LINESTRING Z ({} {} {},", p[0], p[1], p[2]);
    info.split("OGRFeature(").find(|b| b.contains(&first))
}

#[test]
fn the_binary_formats_keep_every_property_and_vertex() {
    let dir = tempfile::tempdir().unwrap();
    let lines = edges(-8_000.0, -38_000.0);
    for ext in ["gpkg", "fgb"] {
        let path = dir.path().join(format!("edges.{ext}"));
        write_edges(&path, &lines, Some(&Crs::Epsg(6677))).unwrap();
        let info = ogrinfo(&path, false);
        for (i, l) in lines.iter().enumerate() {
            let block = feature_block(&info, l.points[0])
                .unwrap_or_else(|| panic!("{ext}: edge {i} not found:\n{info}"));
            let props = [
                ("side (String)", Some(l.side.as_str().to_string())),
                ("method (String)", l.method.clone()),
                ("length_m (Real)", Some(format!("{}", l.length_m()))),
                (
                    "curb_height_m (Real)",
                    l.curb_height_m.map(|h| h.to_string()),
                ),
                ("category (String)", l.category.map(|c| c.as_str().into())),
            ];
            let shown: Vec<f64> = block
                .split_once("LINESTRING Z (")
                .and_then(|(_, rest)| rest.split_once(')'))
                .map(|(coords, _)| coords)
                .unwrap_or_default()
                .split([',', ' '])
                .map(|x| x.parse().unwrap())
                .collect();
            let want: Vec<f64> = l.points.iter().flatten().copied().collect();
            assert_eq!(shown.len(), want.len(), "{ext}: edge {i}:\n{block}");
            // GDAL prints 15 significant digits.
            for (a, b) in shown.iter().zip(&want) {
                assert!(
                    (a - b).abs() < 1e-9,
                    "{ext}: edge {i}: {a} vs {b}:\n{block}"
                );
            }
            let line_kind = block
                .lines()
                .find_map(|line| line.trim().strip_prefix("line (String) = "));
            assert_eq!(line_kind, Some("toe"), "{ext}: edge {i}:\n{block}");
            if let Some(d) = &l.detail {
                let top = feature_block(&info, d.top[0])
                    .unwrap_or_else(|| panic!("{ext}: top of edge {i} not found:\n{info}"));
                assert!(top.contains("line (String) = top"), "{ext}:\n{top}");
                assert!(
                    top.contains(&format!("edge (Integer64) = {i}")),
                    "{ext}:\n{top}"
                );
                let bridged = if d.bridged { "1" } else { "0" };
                assert!(
                    top.contains(&format!("bridged (Integer(Boolean)) = {bridged}")),
                    "{ext}:\n{top}"
                );
            }
            for (field, value) in props {
                let shown = block
                    .lines()
                    .find_map(|line| line.trim().strip_prefix(&format!("{field} = ")));
                match value {
                    // GDAL prints 12 significant digits of a Real.
                    Some(v) if field.contains("Real") => {
                        let got: f64 = shown.expect(field).parse().unwrap();
                        let want: f64 = v.parse().unwrap();
                        assert!((got - want).abs() < 1e-9, "{ext}: edge {i}: {field}");
                    }
                    Some(v) => assert_eq!(shown, Some(v.as_str()), "{ext}: edge {i}"),
                    // NULL (GeoPackage) or not set (FlatGeobuf).
                    None => assert!(
                        shown.is_none() || shown == Some("(null)"),
                        "{ext}: edge {i}: {field} must be null:\n{block}"
                    ),
                }
            }
        }
    }
}

#[test]
fn geopackages_pass_gdals_validator() {
    let dir = tempfile::tempdir().unwrap();
    let custom = Crs::Wkt(r#"LOCAL_CS["site grid",UNIT["metre",1]]"#.into());
    let cases = [
        ("epsg", edges(-8_000.0, -38_000.0), Some(Crs::Epsg(6677))),
        (
            "wkt",
            edges(500_000.0, 5_000_000.0),
            Some(Crs::Wkt(UTM33_WKT.into())),
        ),
        ("local", edges(0.0, 0.0), Some(custom)),
        ("none", edges(0.0, 0.0), None),
        ("empty", Vec::new(), Some(Crs::Epsg(6677))),
    ];
    for (tag, lines, crs) in cases {
        let path = dir.path().join(format!("{tag}.gpkg"));
        write_edges(&path, &lines, crs.as_ref()).unwrap();
        let out = Command::new("/usr/bin/python3")
            .args(["-m", "osgeo_utils.samples.validate_gpkg"])
            .args(["--extra", "--warning-as-error"])
            .arg(&path)
            .output()
            .unwrap_or_else(|e| panic!("python3 could not run ({e}): install python3-gdal"));
        assert!(
            out.status.success(),
            "{tag}: validate_gpkg (Debian package python3-gdal):\n{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

#[test]
fn dxf_puts_3d_polylines_on_one_layer_per_class_and_names_the_crs() {
    let dir = tempfile::tempdir().unwrap();
    let lines = edges(-8_000.0, -38_000.0);
    let path = dir.path().join("edges.dxf");
    write_edges(&path, &lines, Some(&Crs::Epsg(6677))).unwrap();
    let info = ogrinfo(&path, false);
    for (layer, count) in [
        ("TOE_CURB", 1),
        ("TOE_CURB_CUT", 1),
        ("TOE_INTERSECTION", 1),
        ("TOE_UNCLASSIFIED", 1),
        ("TOE_BUS_BAY", 0),
        ("TOP_CURB", 1),
        ("TOP_CURB_CUT", 1),
        ("TOP_INTERSECTION", 0),
    ] {
        let w = format!("Layer (String) = {layer}\n");
        assert_eq!(info.matches(&w).count(), count, "{layer}:\n{info}");
    }
    for l in &lines {
        let p = l.points[0];
        let first = format!("LINESTRING Z ({} {} {},", p[0], p[1], p[2]);
        assert!(info.contains(&first), "{first}:\n{info}");
    }
    // The bridged stretch's toe and top are dashed, the others continuous (by layer).
    assert_eq!(
        info.matches("Linetype (String) = DASHED\n").count(),
        2,
        "{info}"
    );
    let text = std::fs::read_to_string(&path).unwrap();
    let head: Vec<&str> = text.lines().take(4).collect();
    assert_eq!(
        head,
        [
            "999",
            &format!(
                "curbtrace road edges, {SCHEMA_MEMBER} {}.{}",
                SCHEMA_VERSION.0, SCHEMA_VERSION.1
            ),
            "999",
            "CRS EPSG:6677"
        ]
    );
}

#[test]
fn an_empty_edge_list_is_a_valid_file_in_every_format() {
    let dir = tempfile::tempdir().unwrap();
    for (ext, driver) in [
        ("geojson", "GeoJSON"),
        ("gpkg", "GPKG"),
        ("fgb", "FlatGeobuf"),
        ("dxf", "DXF"),
    ] {
        let path = dir.path().join(format!("empty.{ext}"));
        write_edges(&path, &[], Some(&Crs::Epsg(32633))).unwrap();
        assert_opens(&path, driver, 0);
    }
}

#[test]
fn writing_over_an_existing_file_replaces_it() {
    let dir = tempfile::tempdir().unwrap();
    for ext in ["gpkg", "fgb", "dxf"] {
        let path = dir.path().join(format!("edges.{ext}"));
        write_edges(&path, &edges(0.0, 0.0), None).unwrap();
        write_edges(&path, &edges(0.0, 0.0)[..2], None).unwrap();
        assert_opens(
            &path,
            OutputFormat::from_path(&path).unwrap().name(),
            2 + WITH_TOP,
        );
    }
}

#[test]
fn the_geojson_schema_version_round_trips_and_a_newer_major_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("edges.geojson");
    let lines = edges(1_000.0, 2_000.0);
    write_edges(&path, &lines, Some(&Crs::Epsg(6677))).unwrap();
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let written = format!("{}.{}", SCHEMA_VERSION.0, SCHEMA_VERSION.1);
    assert_eq!(v[SCHEMA_MEMBER], serde_json::json!(written));
    let (back, crs) = read_geojson(&path).unwrap();
    assert_eq!(back.len(), lines.len());
    assert_eq!(crs, Some(Crs::Epsg(6677)));
    // The top features come back as the detail of their toe: top, heights, support.
    for (a, b) in lines.iter().zip(&back) {
        match (&a.detail, &b.detail) {
            (Some(x), Some(y)) => {
                // GeoJSON keeps 0.1 mm.
                let near = |a: f64, b: f64| (a - b).abs() <= 0.6e-4;
                assert!(x.top.len() == y.top.len(), "{x:?} vs {y:?}");
                for (p, q) in x.top.iter().zip(&y.top) {
                    assert!((0..3).all(|k| near(p[k], q[k])), "{p:?} vs {q:?}");
                }
                assert!(x
                    .height_m
                    .iter()
                    .zip(&y.height_m)
                    .all(|(a, b)| near(*a, *b)));
                assert_eq!((x.bridged, x.support_per_m), (y.bridged, y.support_per_m));
            }
            (None, None) => {}
            other => panic!("detail lost or invented: {other:?}"),
        }
    }

    // A newer minor of the same major reads; a file without the member (other tools,
    // reference files) reads; a newer major is refused, naming the file and the version.
    let with = |version: Option<serde_json::Value>| {
        let mut v = v.clone();
        match version {
            Some(x) => v[SCHEMA_MEMBER] = x,
            None => {
                v.as_object_mut().unwrap().remove(SCHEMA_MEMBER);
            }
        }
        std::fs::write(&path, v.to_string()).unwrap();
        read_geojson(&path)
    };
    let minor = format!("{}.{}", SCHEMA_VERSION.0, SCHEMA_VERSION.1 + 7);
    assert_eq!(with(Some(minor.into())).unwrap().0.len(), lines.len());
    assert_eq!(with(None).unwrap().0.len(), lines.len());
    let major = format!("{}.0", SCHEMA_VERSION.0 + 1);
    let err = with(Some(major.clone().into())).unwrap_err().to_string();
    assert!(
        err.contains("edges.geojson") && err.contains(&major) && err.contains("newer"),
        "{err}"
    );
    let err = with(Some(serde_json::json!(1))).unwrap_err().to_string();
    assert!(err.contains("MAJOR.MINOR"), "{err}");
}

/// Runs `curbtrace extract` with extra arguments.
fn extract(points: &Path, traj: &Path, extra: &[&str]) -> (bool, String) {
    let run = Command::new(env!("CARGO_BIN_EXE_curbtrace"))
        .arg("extract")
        .arg(points)
        .arg("--trajectory")
        .arg(traj)
        .args(extra)
        .output()
        .unwrap();
    (
        run.status.success(),
        String::from_utf8_lossy(&run.stderr).into_owned(),
    )
}

#[test]
fn the_cli_refuses_an_unknown_extension_and_a_conflicting_format_before_reading() {
    let dir = tempfile::tempdir().unwrap();
    // The inputs do not exist: the output name is checked first.
    let points = dir.path().join("missing.las");
    let traj = dir.path().join("missing.csv");
    let shp = dir.path().join("edges.shp");
    let (ok, err) = extract(&points, &traj, &["-o", shp.to_str().unwrap()]);
    assert!(!ok);
    let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "{err}");
    assert!(
        lines[0].contains("edges.shp")
            && lines[0].contains("\".shp\"")
            && lines[0].contains(".gpkg, .fgb, .dxf"),
        "{err}"
    );
    assert!(!shp.exists());
    let gpkg = dir.path().join("edges.gpkg");
    let (ok, err) = extract(
        &points,
        &traj,
        &["-o", gpkg.to_str().unwrap(), "--format", "csv"],
    );
    assert!(!ok);
    assert!(
        err.contains("--format csv conflicts") && err.contains("edges.gpkg"),
        "{err}"
    );
}

#[test]
fn the_cli_writes_the_format_the_extension_names() {
    let dir = tempfile::tempdir().unwrap();
    let road = common::Road::default();
    let las = dir.path().join("road.las");
    let traj = dir.path().join("trajectory.csv");
    road.write(&las, &traj);
    let geojson = dir.path().join("edges.geojson");
    let (ok, err) = extract(&las, &traj, &["-q", "-o", geojson.to_str().unwrap()]);
    assert!(ok, "{err}");
    let (reference, _) = read_geojson(&geojson).unwrap();
    assert!(!reference.is_empty());
    let gpkg = dir.path().join("edges.gpkg");
    let (ok, err) = extract(&las, &traj, &["-q", "-o", gpkg.to_str().unwrap()]);
    assert!(ok, "{err}");
    // Every stretch of the bend method has its toe and its top of curb.
    assert!(reference.iter().all(|e| e.detail.is_some()));
    let info = assert_opens(&gpkg, "GPKG", 2 * reference.len());
    assert!(info.contains("line: String"), "{info}");
    // The compatible spelling: --format csv with any file name.
    let txt = dir.path().join("edges.txt");
    let (ok, err) = extract(
        &las,
        &traj,
        &["-q", "-o", txt.to_str().unwrap(), "--format", "csv"],
    );
    assert!(ok, "{err}");
    let text = std::fs::read_to_string(&txt).unwrap();
    assert!(text.starts_with(&format!("{}\n", csv::HEADER)), "{text}");
}
