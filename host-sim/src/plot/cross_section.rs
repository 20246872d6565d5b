//! One scanline in the x′–z′ plane and its bend angles ρ before and after smoothing.

use super::style::*;
use super::{draw_err, draw_legend, input_err, register_font, PlotError, FONT_NAME};
use plotters::prelude::*;
use std::path::Path;

/// One scanline for [`cross_section_png`]. Indices of the raw and smoothed arrays are the
/// same points (the kernel keeps one slot per input point); use NaN where a value does not
/// exist (ρ of a point without neighbours, or of an irregular point removed before
/// smoothing).
#[derive(Clone, Debug)]
pub struct CrossSection<'a> {
    /// Title above the picture.
    pub title: String,
    /// Raw x′ per point, metres (left positive).
    pub raw_x_m: &'a [f64],
    /// Raw z′ per point, metres.
    pub raw_z_m: &'a [f64],
    /// ρ on the raw line, degrees.
    pub raw_rho_deg: &'a [f64],
    /// Smoothed x′ per point, metres.
    pub smooth_x_m: &'a [f64],
    /// Smoothed z′ per point, metres.
    pub smooth_z_m: &'a [f64],
    /// ρ on the smoothed line, degrees.
    pub smooth_rho_deg: &'a [f64],
    /// Indices of seed candidates (peaks) to mark.
    pub candidates: &'a [usize],
    /// The peak thresholds τ_min, τ_max in degrees, drawn as dashed lines.
    pub tau_deg: Option<(f64, f64)>,
    /// Horizontal range to show, metres; `None`: all points.
    pub x_range_m: Option<(f64, f64)>,
    /// Vertical range of the profile, metres; `None`: all points in the x′ range. Walls
    /// and poles reach metres above the road, so a picture of the curb wants about
    /// 1 m from the road down.
    pub z_range_m: Option<(f64, f64)>,
}

/// The smoothed profile is drawn as a line broken where consecutive points are farther
/// apart than this, metres (the sky between the two sides, occlusion shadows).
const PROFILE_BREAK_M: f64 = 0.5;

/// Draws a scanline cross-section: top panel x′–z′ (raw points grey, smoothed line blue,
/// candidates red), bottom panel ρ per point against x′ before (grey) and after (blue)
/// smoothing, with τ_min/τ_max. 1400 × 950 px.
pub fn cross_section_png(path: &Path, cs: &CrossSection) -> Result<(), PlotError> {
    register_font();
    let n = cs.raw_x_m.len();
    let lens = [
        cs.raw_z_m.len(),
        cs.raw_rho_deg.len(),
        cs.smooth_x_m.len(),
        cs.smooth_z_m.len(),
        cs.smooth_rho_deg.len(),
    ];
    if n == 0 || lens.iter().any(|&l| l != n) {
        return Err(input_err(
            path,
            format!("scanline arrays are empty or differ in length ({n} and {lens:?})"),
        ));
    }
    if let Some(&bad) = cs.candidates.iter().find(|&&i| i >= n) {
        return Err(input_err(
            path,
            format!("candidate index {bad} is beyond the {n} points"),
        ));
    }
    let finite_range = |v: &mut dyn Iterator<Item = f64>| {
        v.filter(|x| x.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
                (a.min(x), b.max(x))
            })
    };
    let (xa, xb) = match cs.x_range_m {
        Some(r) => r,
        None => finite_range(&mut cs.raw_x_m.iter().chain(cs.smooth_x_m).copied()),
    };
    if !(xa.is_finite() && xb.is_finite() && xb > xa) {
        return Err(input_err(path, "no finite x′ range to draw"));
    }
    let in_x = |x: f64| x >= xa && x <= xb;
    let (za, zb, zpad) = match cs.z_range_m {
        Some((a, b)) if a.is_finite() && b.is_finite() && b > a => (a, b, 0.0),
        _ => {
            let (mut za, mut zb) = finite_range(
                &mut (0..n)
                    .filter(|&i| in_x(cs.raw_x_m[i]))
                    .flat_map(|i| [cs.raw_z_m[i], cs.smooth_z_m[i]]),
            );
            if !(za.is_finite() && zb.is_finite()) {
                (za, zb) = (-1.0, 0.0);
            }
            (za, zb, ((zb - za) * 0.08).max(0.02))
        }
    };
    let (z_lo, z_hi) = (za - zpad, zb + zpad);
    let in_xz = |x: f64, z: f64| in_x(x) && z >= z_lo && z <= z_hi;
    let (rmin, rmax) = finite_range(
        &mut (0..n)
            .filter(|&i| in_x(cs.raw_x_m[i]))
            .flat_map(|i| [cs.raw_rho_deg[i], cs.smooth_rho_deg[i]]),
    );
    let (mut ra, mut rb) = if rmin.is_finite() {
        (rmin.min(-10.0), rmax.max(10.0))
    } else {
        (-90.0, 90.0)
    };
    if let Some((t0, t1)) = cs.tau_deg {
        ra = ra.min(t0);
        rb = rb.max(t1.min(180.0));
    }
    let rpad = (rb - ra) * 0.06;

    let err = draw_err(path);
    let root = BitMapBackend::new(path, (1400, 950)).into_drawing_area();
    root.fill(&WHITE).map_err(&err)?;
    let root = root.titled(&cs.title, (FONT_NAME, 24)).map_err(&err)?;
    let (top, bottom) = root.split_vertically(470);

    let grey = RGBColor(120, 120, 120);
    let blue = RGBColor(31, 119, 180);
    let red = RGBColor(214, 39, 40);

    // Profile.
    let mut ch = ChartBuilder::on(&top)
        .caption("profile in the scan plane", (FONT_NAME, 18))
        .margin(12)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d(xa..xb, z_lo..z_hi)
        .map_err(&err)?;
    ch.configure_mesh()
        .x_desc("x′ [m]  (left of the vehicle positive)")
        .y_desc("z′ [m]")
        .x_label_formatter(&|v| tick(*v, xb - xa))
        .y_label_formatter(&|v| tick(*v, zb - za))
        .label_style((FONT_NAME, 15))
        .axis_desc_style((FONT_NAME, 16))
        .light_line_style(WHITE.mix(0.0))
        .bold_line_style(BLACK.mix(0.08))
        .draw()
        .map_err(&err)?;
    // The smoothed line first and the raw points on top, so that both stay visible.
    let mut pieces: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
    for i in 0..n {
        let p = (cs.smooth_x_m[i], cs.smooth_z_m[i]);
        if !(p.0.is_finite() && p.1.is_finite()) {
            continue;
        }
        if let Some(cur) = pieces.last_mut() {
            if cur
                .last()
                .is_some_and(|q| (p.0 - q.0).hypot(p.1 - q.1) > PROFILE_BREAK_M)
            {
                pieces.push(Vec::new());
            }
        }
        if let Some(cur) = pieces.last_mut() {
            cur.push(p);
        }
    }
    let rect = (xa, xb, z_lo, z_hi);
    let smooth_style = blue.stroke_width(2);
    ch.draw_series(
        pieces
            .iter()
            .flat_map(|p| clip_polyline(p, rect))
            .map(|p| PathElement::new(p, smooth_style)),
    )
    .map_err(&err)?
    .label("after Taubin smoothing")
    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], blue.stroke_width(2)));
    ch.draw_series(
        (0..n)
            .filter(|&i| in_xz(cs.raw_x_m[i], cs.raw_z_m[i]))
            .map(|i| Circle::new((cs.raw_x_m[i], cs.raw_z_m[i]), 2, grey.mix(0.75).filled())),
    )
    .map_err(&err)?
    .label("raw points")
    .legend(move |(x, y)| Circle::new((x + 10, y), 3, grey.filled()));
    if !cs.candidates.is_empty() {
        ch.draw_series(
            cs.candidates
                .iter()
                .filter(|&&i| in_xz(cs.smooth_x_m[i], cs.smooth_z_m[i]))
                .map(|&i| {
                    Circle::new((cs.smooth_x_m[i], cs.smooth_z_m[i]), 7, red.stroke_width(3))
                }),
        )
        .map_err(&err)?
        .label("seed candidate")
        .legend(move |(x, y)| Circle::new((x + 10, y), 6, red.stroke_width(3)));
    }
    draw_legend(&mut ch, SeriesLabelPosition::UpperLeft, 15).map_err(&err)?;

    // Bend angles.
    let mut ch = ChartBuilder::on(&bottom)
        .caption("bend angle ρ per point", (FONT_NAME, 18))
        .margin(12)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d(xa..xb, (ra - rpad)..(rb + rpad))
        .map_err(&err)?;
    ch.configure_mesh()
        .x_desc("x′ [m]")
        .y_desc("ρ [°]")
        .x_label_formatter(&|v| tick(*v, xb - xa))
        .y_label_formatter(&|v| tick(*v, 100.0))
        .label_style((FONT_NAME, 15))
        .axis_desc_style((FONT_NAME, 16))
        .light_line_style(WHITE.mix(0.0))
        .bold_line_style(BLACK.mix(0.08))
        .draw()
        .map_err(&err)?;
    let series = |xs: &[f64], rs: &[f64]| -> Vec<Vec<(f64, f64)>> {
        // Break the line where ρ does not exist.
        let mut out = vec![Vec::new()];
        for i in 0..n {
            if xs[i].is_finite() && rs[i].is_finite() && in_x(xs[i]) {
                if let Some(v) = out.last_mut() {
                    v.push((xs[i], rs[i]));
                }
            } else if !out.last().is_some_and(|v| v.is_empty()) {
                out.push(Vec::new());
            }
        }
        out.retain(|v| !v.is_empty());
        out
    };
    let raw_style = grey.mix(0.8).stroke_width(1);
    ch.draw_series(
        series(cs.raw_x_m, cs.raw_rho_deg)
            .into_iter()
            .map(|v| PathElement::new(v, raw_style)),
    )
    .map_err(&err)?
    .label("ρ before smoothing")
    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], raw_style));
    let smooth_style = blue.stroke_width(2);
    ch.draw_series(
        series(cs.smooth_x_m, cs.smooth_rho_deg)
            .into_iter()
            .map(|v| PathElement::new(v, smooth_style)),
    )
    .map_err(&err)?
    .label("ρ after smoothing")
    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], smooth_style));
    if let Some((t0, t1)) = cs.tau_deg {
        let tau_style = RGBColor(44, 160, 44).stroke_width(2);
        let dash = (xb - xa) / 120.0;
        let lines: Vec<Vec<(f64, f64)>> = [t0, t1]
            .iter()
            .filter(|t| t.is_finite() && **t <= rb + rpad)
            .flat_map(|&t| dashes(&[(xa, t), (xb, t)], dash))
            .collect();
        ch.draw_series(lines.into_iter().map(|v| PathElement::new(v, tau_style)))
            .map_err(&err)?
            .label(format!("τ_min = {t0:.0}°, τ_max = {t1:.0}°"))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 10, y)], tau_style));
    }
    if !cs.candidates.is_empty() {
        ch.draw_series(cs.candidates.iter().filter_map(|&i| {
            let (x, r) = (cs.smooth_x_m[i], cs.smooth_rho_deg[i]);
            (in_x(x) && r.is_finite()).then(|| Circle::new((x, r), 7, red.stroke_width(3)))
        }))
        .map_err(&err)?
        .label("seed candidate")
        .legend(move |(x, y)| Circle::new((x + 10, y), 6, red.stroke_width(3)));
    }
    draw_legend(&mut ch, SeriesLabelPosition::UpperLeft, 15).map_err(&err)?;
    root.present().map_err(&err)?;
    Ok(())
}
