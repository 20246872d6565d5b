//! Tests of the pictures: colours, ticks, clipping, windows, and PNGs written.

use super::style::*;
use super::top_view::*;
use super::windows::*;
use super::*;
use crate::model::{Category, EdgeLine, Side};

/// Where the tests' pictures go: `CURBTRACE_PLOT_DIR` if set (to look at them), else a
/// temporary directory.
fn out_dir() -> (Option<tempfile::TempDir>, std::path::PathBuf) {
    match std::env::var_os("CURBTRACE_PLOT_DIR") {
        Some(d) => (None, d.into()),
        None => {
            let t = tempfile::tempdir().unwrap();
            let p = t.path().to_path_buf();
            (Some(t), p)
        }
    }
}

#[test]
fn embedded_font_is_a_valid_ttf() {
    assert!(plotters::style::register_font(FONT_NAME, FontStyle::Normal, FONT).is_ok());
}

#[test]
fn viridis_ends_and_middle() {
    assert_eq!(viridis(0.0), RGBColor(68, 1, 84));
    assert_eq!(viridis(1.0), RGBColor(253, 231, 37));
    assert_eq!(viridis(0.5), RGBColor(33, 145, 140));
    assert_eq!(viridis(-3.0), viridis(0.0));
    assert_eq!(viridis(f64::NAN), viridis(0.0));
}

#[test]
fn dashes_alternate_along_the_line() {
    let d = dashes(&[(0.0, 0.0), (10.0, 0.0)], 1.0);
    assert_eq!(d.len(), 5);
    assert_eq!(d[0], vec![(0.0, 0.0), (1.0, 0.0)]);
    assert_eq!(d[1], vec![(2.0, 0.0), (3.0, 0.0)]);
    // Across a vertex the dash keeps its length.
    let d = dashes(&[(0.0, 0.0), (0.5, 0.0), (0.5, 2.0)], 1.0);
    assert_eq!(d[0], vec![(0.0, 0.0), (0.5, 0.0), (0.5, 0.5)]);
    assert_eq!(d[1], vec![(0.5, 1.5), (0.5, 2.0)]);
}

#[test]
fn windows_of_interest_find_categories_and_the_occlusion() {
    let l = |pts: &[(f64, f64)], side, cat| EdgeLine {
        points: pts.iter().map(|&(x, y)| [x, y, 0.0]).collect(),
        side,
        category: Some(cat),
        method: None,
        curb_height_m: None,
        detail: None,
    };
    let refs = vec![
        l(&[(0.0, 5.0), (40.0, 5.0)], Side::Left, Category::Curb),
        // A 6 m hole (parked car), then the curb goes on straight.
        l(&[(46.0, 5.0), (60.0, 5.0)], Side::Left, Category::Curb),
        l(&[(60.0, 5.0), (66.0, 5.0)], Side::Left, Category::CurbCut),
        // An intersection corner turning away: its 10 m hole to the next curb is not
        // straight, so it is no occlusion.
        l(
            &[(66.0, 5.0), (70.0, 9.0)],
            Side::Left,
            Category::Intersection,
        ),
        l(
            &[(80.0, 9.0), (84.0, 5.0), (120.0, 5.0)],
            Side::Left,
            Category::Curb,
        ),
        l(&[(0.0, -5.0), (20.0, -5.0)], Side::Right, Category::Curb),
        l(&[(20.0, -5.0), (40.0, -7.0)], Side::Right, Category::BusBay),
    ];
    let w = windows_of_interest(&refs, 8.0);
    let names: Vec<&str> = w.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["curb_cut", "intersection", "bus_bay", "occlusion"]);
    assert_eq!(w[0].1.center, [63.0, 5.0]);
    assert_eq!(w[3].1.center, [43.0, 5.0]);
    assert!((w[2].1.center[0] - 30.0).abs() < 1e-9);
    assert_eq!(w[3].1.half_size_m, 8.0);
    assert!(windows_of_interest(&refs[..1], 8.0).is_empty());
}

#[test]
fn height_above_local_ground_removes_the_grade() {
    // A road rising 5 % eastwards over 100 m, 8 m wide, with 0.15 m sidewalks 3 m wide.
    let (mut x, mut y, mut z) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..500 {
        for j in 0..70 {
            let (px, py) = (i as f64 * 0.2, -7.0 + j as f64 * 0.2);
            x.push(1000.0 + px);
            y.push(2000.0 + py);
            z.push(50.0 + 0.05 * px + if py.abs() > 4.0 { 0.15 } else { 0.0 });
        }
    }
    let c = Cloud {
        x: &x,
        y: &y,
        z: &z,
    };
    let idx: Vec<usize> = (0..x.len()).collect();
    let h = above_local_ground(&c, &idx);
    // The lowest cell within ±5 m lies up to 2 cells (4 m + a cell) downhill: at most
    // 0.05 × 6 m = 0.3 m; the step between road and sidewalk stays 0.15 m everywhere.
    for i in (0..x.len()).step_by(997) {
        let road = (y[i] - 2000.0).abs() <= 4.0;
        assert!(h[i] >= -1e-9 && h[i] <= 0.3 + if road { 0.0 } else { 0.15 } + 1e-9);
    }
    // Same place along the road, road and sidewalk: differ by the curb.
    let at = |px: usize, py: usize| h[px * 70 + py];
    assert!((at(250, 60) - at(250, 40) - 0.15).abs() < 1e-9);
    // And the values do not grow along the road as z does (25 m apart: 1.25 m in z).
    assert!((at(300, 40) - at(175, 40)).abs() < 0.1);
}

#[test]
fn clipping_keeps_only_what_is_inside() {
    let r = (0.0, 10.0, 0.0, 10.0);
    // Entirely outside (below): nothing, not a line along the border.
    assert!(clip_polyline(&[(-5.0, -1.0), (15.0, -1.0)], r).is_empty());
    // Crossing: cut at the borders.
    assert_eq!(
        clip_polyline(&[(-5.0, 5.0), (15.0, 5.0)], r),
        vec![vec![(0.0, 5.0), (10.0, 5.0)]]
    );
    // In, out, in again: two pieces.
    let v = clip_polyline(&[(2.0, 2.0), (2.0, 12.0), (4.0, 12.0), (4.0, 2.0)], r);
    assert_eq!(
        v,
        vec![vec![(2.0, 2.0), (2.0, 10.0)], vec![(4.0, 10.0), (4.0, 2.0)]]
    );
    // Inside: unchanged.
    let inner = [(1.0, 1.0), (2.0, 3.0), (5.0, 5.0)];
    assert_eq!(clip_polyline(&inner, r), vec![inner.to_vec()]);
}

#[test]
fn thousands_are_grouped() {
    assert_eq!(group_thousands(523_400.0), "523\u{2009}400");
    assert_eq!(group_thousands(4_000_000.0), "4\u{2009}000\u{2009}000");
    assert_eq!(group_thousands(-120.0), "−120");
}

/// A small synthetic street: road at z = 10, curbs 0.15 m high at y = ±4, walls.
type Street = (Vec<f64>, Vec<f64>, Vec<f64>, Vec<EdgeLine>, Vec<EdgeLine>);

fn street() -> Street {
    let (x0, y0) = (523_456.0, 4_012_345.0);
    let (mut xs, mut ys, mut zs) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..400 {
        for j in 0..120 {
            let (x, y) = (i as f64 * 0.1, -6.0 + j as f64 * 0.1);
            let z = if y.abs() > 4.0 {
                10.15
            } else {
                10.0 - 0.02 * y.abs()
            } + if y.abs() > 5.8 { 2.0 } else { 0.0 };
            xs.push(x0 + x);
            ys.push(y0 + y);
            zs.push(z);
        }
    }
    let l = |y: f64, side, cat, method: Option<&str>| EdgeLine {
        points: vec![[x0, y0 + y, 10.0], [x0 + 40.0, y0 + y, 10.0]],
        side,
        category: cat,
        method: method.map(str::to_string),
        curb_height_m: None,
        detail: None,
    };
    let refs = vec![
        l(4.0, Side::Left, Some(Category::Curb), None),
        l(-4.0, Side::Right, Some(Category::Curb), None),
    ];
    let mut ext = vec![l(4.02, Side::Left, None, Some("bend"))];
    ext[0].points[1][0] -= 10.0;
    (xs, ys, zs, refs, ext)
}

#[test]
fn top_view_and_window_write_pngs() {
    let (xs, ys, zs, refs, ext) = street();
    let (_keep, dir) = out_dir();
    let traj = [[xs[0], ys[0] + 6.0], [xs[0] + 40.0, ys[0] + 6.0]];
    let mut v = TopView::new(
        "street",
        Cloud {
            x: &xs,
            y: &ys,
            z: &zs,
        },
        &refs,
        &ext,
    );
    v.trajectory = &traj;
    v.max_points = 20_000;
    v.colouring = Colouring::Height;
    let p = dir.join("top.png");
    let s = top_view_png(&p, &v).unwrap();
    assert_eq!(s.points_in_view, xs.len());
    // A hashed thinning to 20 000 of 48 000: binomial, σ ≈ 108.
    assert!((19_500..=20_500).contains(&s.points_drawn), "{s:?}");
    // From the 2 % quantile (road, 9.92 m) up by the automatic span, not to the walls.
    assert!((s.z_range_m.0 - 9.922).abs() < 0.01, "{s:?}");
    assert!(
        (s.z_range_m.1 - s.z_range_m.0 - AUTO_Z_SPAN_M).abs() < 1e-9,
        "{s:?}"
    );
    assert!(std::fs::metadata(&p).unwrap().len() > 10_000);

    v.window = Some(Window {
        center: [xs[0] + 30.0, ys[0] + 10.0],
        half_size_m: 2.0,
    });
    let p = dir.join("zoom.png");
    let s = top_view_png(&p, &v).unwrap();
    // 4 m × 4 m at 0.1 m spacing, edges inclusive: 41 × 41 (less rounding at edges).
    assert!((1600..=1700).contains(&s.points_in_view), "{s:?}");
    assert_eq!(s.size_px.0, 1600);
}

#[test]
fn top_view_rejects_bad_input_naming_the_file() {
    let (xs, ys, zs, refs, ext) = street();
    let mut v = TopView::new(
        "x",
        Cloud {
            x: &xs,
            y: &ys[..10],
            z: &zs,
        },
        &refs,
        &ext,
    );
    let err = top_view_png(Path::new("/tmp/bad-top.png"), &v).unwrap_err();
    assert!(err.to_string().contains("bad-top.png"), "{err}");
    v.cloud.y = &ys;
    v.window = Some(Window {
        center: [0.0, f64::NAN],
        half_size_m: 1.0,
    });
    assert!(top_view_png(Path::new("/tmp/bad-top.png"), &v).is_err());
}

#[test]
fn cross_section_writes_a_png_and_checks_lengths() {
    let n: usize = 200;
    let x: Vec<f64> = (0..n).map(|i| -6.0 + i as f64 * 0.06).collect();
    let z: Vec<f64> = x
        .iter()
        .map(|&x| if x > 4.0 { -1.85 } else { -2.0 } + 0.003 * (x * 37.0).sin())
        .collect();
    let rho: Vec<f64> = x
        .iter()
        .map(|&x| {
            if (x - 4.0).abs() < 0.05 {
                85.0
            } else {
                2.0 * (x * 37.0).sin()
            }
        })
        .collect();
    // "Smoothing": a 5-point running mean of z and a damped ρ.
    let zs: Vec<f64> = (0..n)
        .map(|i| {
            let (a, b) = (i.saturating_sub(2usize), (i + 3).min(n));
            z[a..b].iter().sum::<f64>() / (b - a) as f64
        })
        .collect();
    let mut rho_s: Vec<f64> = rho
        .iter()
        .zip(&x)
        .map(|(r, &x)| {
            if (x - 4.0).abs() < 0.2 {
                60.0 + *r * 0.3
            } else {
                r * 0.3
            }
        })
        .collect();
    rho_s[0] = f64::NAN;
    let cand = [167usize];
    let cs = CrossSection {
        title: "scanline 42".into(),
        raw_x_m: &x,
        raw_z_m: &z,
        raw_rho_deg: &rho,
        smooth_x_m: &x,
        smooth_z_m: &zs,
        smooth_rho_deg: &rho_s,
        candidates: &cand,
        tau_deg: Some((30.0, 150.0)),
        x_range_m: None,
        z_range_m: None,
    };
    let (_keep, dir) = out_dir();
    let p = dir.join("cs.png");
    cross_section_png(&p, &cs).unwrap();
    assert!(std::fs::metadata(&p).unwrap().len() > 10_000);
    let bad = CrossSection {
        candidates: &[999],
        ..cs.clone()
    };
    let e = cross_section_png(&p, &bad).unwrap_err().to_string();
    assert!(e.contains("cs.png") && e.contains("999"), "{e}");
    let bad = CrossSection {
        raw_z_m: &z[..3],
        ..cs
    };
    assert!(cross_section_png(&p, &bad).is_err());
}
