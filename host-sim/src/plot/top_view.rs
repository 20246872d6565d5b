//! The top view: points seen from above, coloured by height, with the reference lines, the
//! extracted edges and the trajectory on top.

use super::style::*;
use super::{draw_err, draw_legend, input_err, register_font, PlotError, FONT_NAME};
use crate::model::{Category, EdgeLine};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// A point cloud as columns in world coordinates (metres).
#[derive(Clone, Copy, Debug)]
pub struct Cloud<'a> {
    /// Easting.
    pub x: &'a [f64],
    /// Northing.
    pub y: &'a [f64],
    /// Height.
    pub z: &'a [f64],
}

/// A square window of a top view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Window {
    /// Centre, world coordinates.
    pub center: [f64; 2],
    /// Half the side of the square, metres.
    pub half_size_m: f64,
}

/// What [`top_view_png`] draws.
#[derive(Clone, Debug)]
pub struct TopView<'a> {
    /// Title above the picture.
    pub title: String,
    /// The points, coloured by height.
    pub cloud: Cloud<'a>,
    /// Reference lines (drawn as a wide translucent red band, about the buffer's width
    /// at zoom).
    pub reference: &'a [EdgeLine],
    /// Extracted edges (drawn as thin black lines).
    pub extracted: &'a [EdgeLine],
    /// Trajectory (scanner origin) as (x, y), drawn dashed; may be empty.
    pub trajectory: &'a [[f64; 2]],
    /// `None`: the whole scene; `Some`: this square.
    pub window: Option<Window>,
    /// At most about this many points are drawn (an even random-looking subsample of those
    /// in view, the same on every run).
    pub max_points: usize,
    /// What the colour shows.
    pub colouring: Colouring,
    /// Range of the colour scale, metres; `None`: from the 2nd percentile of the values in
    /// view up to the 98th, at most [`AUTO_Z_SPAN_M`] above it.
    pub z_range_m: Option<(f64, f64)>,
    /// Width of the PNG in pixels (the height follows from the view's shape).
    pub width_px: u32,
}

impl<'a> TopView<'a> {
    /// A view with the usual settings: 400 000 points at most, 1600 px wide, no window.
    pub fn new(
        title: impl Into<String>,
        cloud: Cloud<'a>,
        reference: &'a [EdgeLine],
        extracted: &'a [EdgeLine],
    ) -> Self {
        Self {
            title: title.into(),
            cloud,
            reference,
            extracted,
            trajectory: &[],
            window: None,
            max_points: 400_000,
            colouring: Colouring::AboveLocalGround,
            z_range_m: None,
            width_px: 1600,
        }
    }
}

/// What the colour of a point shows in a top view.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Colouring {
    /// Its height z.
    Height,
    /// Its height above the local ground: z minus the lowest 5th-percentile height of the
    /// 2 m cells within ±5 m. A road's grade then no longer swamps the colour scale, and
    /// road, curb and sidewalk read the same everywhere along a long street.
    AboveLocalGround,
}

/// Ground cells of [`Colouring::AboveLocalGround`], metres.
const GROUND_CELL_M: f64 = 2.0;
/// Neighbourhood of [`Colouring::AboveLocalGround`], in cells each way (±5 m with 2 m cells,
/// wide enough that a sidewalk cell sees the road beside it).
const GROUND_REACH: i64 = 2;

/// Heights above the local ground for the points `idx` (see [`Colouring::AboveLocalGround`]).
pub(crate) fn above_local_ground(c: &Cloud, idx: &[usize]) -> Vec<f64> {
    use std::collections::HashMap;
    let key = |i: usize| {
        (
            (c.x[i] / GROUND_CELL_M).floor() as i64,
            (c.y[i] / GROUND_CELL_M).floor() as i64,
        )
    };
    let mut cells: HashMap<(i64, i64), Vec<f64>> = HashMap::new();
    for &i in idx {
        cells.entry(key(i)).or_default().push(c.z[i]);
    }
    // The 5th percentile, not the minimum: a few low outliers must not sink a cell.
    let low: HashMap<(i64, i64), f64> = cells
        .into_iter()
        .map(|(k, mut v)| (k, quantile(&mut v, 0.05)))
        .collect();
    // Ground at each cell's centre: the lowest cell low within the neighbourhood.
    let mut ground: HashMap<(i64, i64), f64> = HashMap::new();
    let mut ground_at = |k: (i64, i64)| -> Option<f64> {
        if !low.contains_key(&k) {
            return None;
        }
        Some(*ground.entry(k).or_insert_with(|| {
            let mut g = f64::INFINITY;
            for dx in -GROUND_REACH..=GROUND_REACH {
                for dy in -GROUND_REACH..=GROUND_REACH {
                    if let Some(&l) = low.get(&(k.0 + dx, k.1 + dy)) {
                        g = g.min(l);
                    }
                }
            }
            g
        }))
    };
    // Bilinear between the four surrounding cell centres (those with points), so that the
    // ground has no steps at cell borders, which would show as squares on the road.
    idx.iter()
        .map(|&i| {
            let fx = c.x[i] / GROUND_CELL_M - 0.5;
            let fy = c.y[i] / GROUND_CELL_M - 0.5;
            let (i0, j0) = (fx.floor() as i64, fy.floor() as i64);
            let (tx, ty) = (fx - i0 as f64, fy - j0 as f64);
            let (mut sum, mut wsum) = (0.0, 0.0);
            for (di, dj, w) in [
                (0, 0, (1.0 - tx) * (1.0 - ty)),
                (1, 0, tx * (1.0 - ty)),
                (0, 1, (1.0 - tx) * ty),
                (1, 1, tx * ty),
            ] {
                if let Some(g) = ground_at((i0 + di, j0 + dj)) {
                    sum += w * g;
                    wsum += w;
                }
            }
            let g = if wsum > 1e-12 {
                sum / wsum
            } else {
                ground_at(key(i)).unwrap_or(c.z[i])
            };
            c.z[i] - g
        })
        .collect()
}

/// What [`top_view_png`] did, for logs and tests.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TopViewStats {
    /// Points inside the view.
    pub points_in_view: usize,
    /// Points drawn (after subsampling).
    pub points_drawn: usize,
    /// Picture size in pixels.
    pub size_px: (u32, u32),
    /// Range of the colour scale, metres.
    pub z_range_m: (f64, f64),
}

/// The automatic colour scale spans at most this much height above its low end (the 2nd
/// percentile), metres: curbs (0.02–0.2 m) must stay visible beside walls and cars several
/// metres high, which saturate at the top colour.
pub const AUTO_Z_SPAN_M: f64 = 0.5;

/// Draws a top view of `view` into the PNG `path` and returns what it drew.
///
/// The picture has equal scale on both axes; its height follows from the view's shape
/// (between 320 px and 1.25 × the width — the range is widened on the short axis to fit).
/// Points are drawn lowest first so that walls and cars cover the ground beneath them, as
/// seen from above; the colour scale spans the 2nd to 98th percentile of the heights in view.
pub fn top_view_png(path: &Path, view: &TopView) -> Result<TopViewStats, PlotError> {
    register_font();
    let c = view.cloud;
    if c.x.len() != c.y.len() || c.x.len() != c.z.len() {
        return Err(input_err(
            path,
            format!(
                "point columns differ in length (x {}, y {}, z {})",
                c.x.len(),
                c.y.len(),
                c.z.len()
            ),
        ));
    }
    if view.width_px < 400 {
        return Err(input_err(path, "picture narrower than 400 px"));
    }

    // The extent in world coordinates.
    let (mut x0, mut x1, mut y0, mut y1) = match view.window {
        Some(w) => {
            if !(w.half_size_m.is_finite()
                && w.half_size_m > 0.0
                && w.center.iter().all(|v| v.is_finite()))
            {
                return Err(input_err(
                    path,
                    "window centre or size is not finite and positive",
                ));
            }
            (
                w.center[0] - w.half_size_m,
                w.center[0] + w.half_size_m,
                w.center[1] - w.half_size_m,
                w.center[1] + w.half_size_m,
            )
        }
        None => scene_extent(view).ok_or_else(|| input_err(path, "nothing to draw"))?,
    };

    // Layout: plot area + colour bar; equal scale.
    const BAR_W: u32 = 120;
    const LEFT: u32 = 80; // y labels
    const BOTTOM: u32 = 60; // x labels
    const TOP: u32 = 50; // caption
    const MARGIN: u32 = 15;
    let w_px = view.width_px;
    let plot_w = (w_px - BAR_W - LEFT - 2 * MARGIN) as f64;
    let (dx, dy) = (x1 - x0, y1 - y0);
    let mut plot_h = plot_w * dy / dx;
    let (min_h, max_h) = (320.0, 1.25 * w_px as f64);
    if plot_h < min_h {
        // Widen the y range so that the scale stays equal.
        let extra = (dx * min_h / plot_w - dy) / 2.0;
        y0 -= extra;
        y1 += extra;
        plot_h = min_h;
    } else if plot_h > max_h {
        let extra = (dy * plot_w / max_h - dx) / 2.0;
        x0 -= extra;
        x1 += extra;
        plot_h = max_h;
    }
    let h_px = plot_h.round() as u32 + TOP + BOTTOM + 2 * MARGIN;

    // Points in view, subsampled evenly, lowest first.
    let in_view: Vec<usize> = (0..c.x.len())
        .filter(|&i| {
            let (x, y) = (c.x[i], c.y[i]);
            x >= x0 && x <= x1 && y >= y0 && y <= y1 && c.z[i].is_finite()
        })
        .collect();
    // Keep each point with probability max_points / in view, decided by a hash of its
    // index: an even thinning that does not alias with the scan pattern as a stride would
    // (every k-th point of a regular pattern draws stripes), and the same on every run.
    let keep = if in_view.len() > view.max_points {
        (view.max_points as f64 / in_view.len() as f64 * u64::MAX as f64) as u64
    } else {
        u64::MAX
    };
    let drawn: Vec<usize> = in_view
        .iter()
        .copied()
        .filter(|&i| splitmix64(i as u64) <= keep)
        .collect();
    // Colour values, indexed like `drawn`; drawn lowest first.
    let values: Vec<f64> = match view.colouring {
        Colouring::Height => drawn.iter().map(|&i| c.z[i]).collect(),
        Colouring::AboveLocalGround => above_local_ground(&c, &drawn),
    };
    let z_range = match view.z_range_m {
        Some(r) if r.0.is_finite() && r.1.is_finite() && r.1 > r.0 => r,
        _ if drawn.is_empty() => (0.0, 1.0),
        _ => {
            let mut zs = values.clone();
            let lo = quantile(&mut zs, 0.02);
            let hi = quantile(&mut zs, 0.98).min(lo + AUTO_Z_SPAN_M);
            (lo, if hi > lo { hi } else { lo + 0.1 })
        }
    };
    let mut order: Vec<usize> = (0..drawn.len()).collect();
    order.sort_unstable_by(|&a, &b| values[a].total_cmp(&values[b]));

    // Local axes from a round origin.
    let ox = round_origin(x0, dx);
    let oy = round_origin(y0, dy);
    let (lx0, lx1, ly0, ly1) = (x0 - ox, x1 - ox, y0 - oy, y1 - oy);
    let px_per_m = plot_w / (lx1 - lx0);
    // Marker size from the spacing of the drawn points on screen, over the area they
    // cover (8 px cells holding a point), not the whole plot: a street is a thin band.
    let covered_px = {
        let mut cells = std::collections::HashSet::new();
        for &i in &drawn {
            cells.insert((
                ((c.x[i] - x0) * px_per_m / 8.0) as i64,
                ((c.y[i] - y0) * px_per_m / 8.0) as i64,
            ));
        }
        cells.len() as f64 * 64.0
    };
    let spacing_px = if drawn.is_empty() {
        1.0
    } else {
        (covered_px / drawn.len() as f64).sqrt()
    };
    let radius = (spacing_px * 0.6).clamp(1.0, 4.0).round() as i32;

    let err = draw_err(path);
    let root = BitMapBackend::new(path, (w_px, h_px)).into_drawing_area();
    root.fill(&WHITE).map_err(&err)?;
    let (main, bar) = root.split_horizontally(w_px - BAR_W);
    let mut chart = ChartBuilder::on(&main)
        .caption(&view.title, (FONT_NAME, 24))
        .margin(MARGIN)
        .x_label_area_size(BOTTOM)
        .y_label_area_size(LEFT)
        .build_cartesian_2d(lx0..lx1, ly0..ly1)
        .map_err(&err)?;
    chart
        .configure_mesh()
        .x_desc(format!("East − {} m  [m]", group_thousands(ox)))
        .x_label_formatter(&|v| tick(*v, lx1 - lx0))
        .y_label_formatter(&|v| tick(*v, ly1 - ly0))
        .y_desc(format!("North − {} m  [m]", group_thousands(oy)))
        .label_style((FONT_NAME, 15))
        .axis_desc_style((FONT_NAME, 16))
        .light_line_style(WHITE.mix(0.0))
        .bold_line_style(BLACK.mix(0.08))
        .draw()
        .map_err(&err)?;

    let (zlo, zhi) = z_range;
    chart
        .draw_series(order.iter().map(|&k| {
            let i = drawn[k];
            let col = viridis((values[k] - zlo) / (zhi - zlo));
            Circle::new((c.x[i] - ox, c.y[i] - oy), radius, col.filled())
        }))
        .map_err(&err)?;

    let rect = (lx0, lx1, ly0, ly1);
    let local = |l: &EdgeLine| -> Vec<Vec<(f64, f64)>> {
        let v: Vec<(f64, f64)> = l.points.iter().map(|p| (p[0] - ox, p[1] - oy)).collect();
        clip_polyline(&v, rect)
    };
    // Reference: a translucent red band, as wide as the 2 × 50 mm buffer when zoomed in
    // (at least 5 px so it shows in the overview).
    let ref_w = ((0.1 * px_per_m).round() as u32).clamp(5, 14);
    let ref_style = ShapeStyle {
        color: RGBColor(228, 26, 28).mix(0.55),
        filled: false,
        stroke_width: ref_w,
    };
    if !view.reference.is_empty() {
        chart
            .draw_series(
                view.reference
                    .iter()
                    .flat_map(local)
                    .map(|v| PathElement::new(v, ref_style)),
            )
            .map_err(&err)?
            .label("reference")
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], ref_style));
    }
    // Extracted toes: colour by class, solid where measured, dashed where bridged; the top
    // of curb beside them as a thin blue line.
    let dash = 12.0 / px_per_m; // 12 px dashes
    let top_style = ShapeStyle {
        color: RGBColor(30, 110, 220).to_rgba(),
        filled: false,
        stroke_width: 1,
    };
    let tops: Vec<Vec<(f64, f64)>> = view
        .extracted
        .iter()
        .filter_map(|l| l.detail.as_ref())
        .flat_map(|d| {
            let v: Vec<(f64, f64)> = d.top.iter().map(|p| (p[0] - ox, p[1] - oy)).collect();
            clip_polyline(&v, rect)
        })
        .collect();
    if !tops.is_empty() {
        chart
            .draw_series(tops.into_iter().map(|v| PathElement::new(v, top_style)))
            .map_err(&err)?
            .label("top of curb")
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], top_style));
    }
    let bridged = |l: &EdgeLine| l.detail.as_ref().is_some_and(|d| d.bridged);
    for class in Category::ALL.map(Some).into_iter().chain([None]) {
        let lines: Vec<&EdgeLine> = view
            .extracted
            .iter()
            .filter(|l| l.category == class || (class.is_none() && l.detail.is_none()))
            .filter(|l| class.is_none() || l.detail.is_some())
            .collect();
        if lines.is_empty() {
            continue;
        }
        let style = ShapeStyle {
            color: class_colour(class).to_rgba(),
            filled: false,
            stroke_width: 2,
        };
        let mut paths: Vec<Vec<(f64, f64)>> = Vec::new();
        for l in lines {
            if bridged(l) {
                let v: Vec<(f64, f64)> = l.points.iter().map(|p| (p[0] - ox, p[1] - oy)).collect();
                paths.extend(dashes(&v, dash).iter().flat_map(|d| clip_polyline(d, rect)));
            } else {
                paths.extend(local(l));
            }
        }
        let label = match class {
            Some(c) => format!("toe: {}", c.as_str()),
            None => "extracted".to_string(),
        };
        chart
            .draw_series(paths.into_iter().map(|v| PathElement::new(v, style)))
            .map_err(&err)?
            .label(label)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], style));
    }
    if view.extracted.iter().any(bridged) {
        let style = ShapeStyle {
            color: BLACK.to_rgba(),
            filled: false,
            stroke_width: 2,
        };
        // A legend entry only: bridged stretches are the dashed ones.
        chart
            .draw_series(std::iter::empty::<PathElement<(f64, f64)>>())
            .map_err(&err)?
            .label("bridged (dashed)")
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 8, y)], style));
    }
    if view.trajectory.len() >= 2 {
        let t: Vec<(f64, f64)> = view
            .trajectory
            .iter()
            .map(|p| (p[0] - ox, p[1] - oy))
            .collect();
        let traj_style = ShapeStyle {
            color: RGBColor(230, 90, 0).to_rgba(),
            filled: false,
            stroke_width: 2,
        };
        chart
            .draw_series(
                dashes(&t, dash)
                    .iter()
                    .flat_map(|d| clip_polyline(d, rect))
                    .map(|d| PathElement::new(d, traj_style)),
            )
            .map_err(&err)?
            .label("trajectory")
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 10, y)], traj_style));
    }
    draw_legend(&mut chart, SeriesLabelPosition::UpperRight, 16).map_err(&err)?;

    let bar_title = match view.colouring {
        Colouring::Height => "height [m]",
        Colouring::AboveLocalGround => "height above local ground [m]",
    };
    draw_colour_bar(&bar, z_range, bar_title, TOP + MARGIN, BOTTOM + MARGIN).map_err(&err)?;
    root.present().map_err(&err)?;
    Ok(TopViewStats {
        points_in_view: in_view.len(),
        points_drawn: drawn.len(),
        size_px: (w_px, h_px),
        z_range_m: z_range,
    })
}

/// The colour of an extracted toe of class `c` (black where unclassified or plain curb).
fn class_colour(c: Option<Category>) -> RGBColor {
    match c {
        Some(Category::Curb) | None => RGBColor(0, 0, 0),
        Some(Category::CurbCut) => RGBColor(0, 150, 60),
        Some(Category::Intersection) => RGBColor(170, 0, 170),
        Some(Category::BusBay) => RGBColor(0, 170, 190),
        Some(Category::Flush) => RGBColor(150, 100, 0),
    }
}

/// The extent of the whole scene: reference, extracted and trajectory, widened to the
/// 0.5–99.5 % quantiles of the points (so a few outliers do not shrink the road to a line),
/// with a 2 m margin.
pub(crate) fn scene_extent(view: &TopView) -> Option<(f64, f64, f64, f64)> {
    let mut xs: Vec<f64> = Vec::new();
    let mut ys: Vec<f64> = Vec::new();
    for l in view.reference.iter().chain(view.extracted) {
        for p in &l.points {
            xs.push(p[0]);
            ys.push(p[1]);
        }
    }
    for p in view.trajectory {
        xs.push(p[0]);
        ys.push(p[1]);
    }
    let c = view.cloud;
    let n = c.x.len().min(c.y.len());
    if n > 0 {
        let stride = (n / 100_000).max(1);
        let mut px: Vec<f64> = (0..n).step_by(stride).map(|i| c.x[i]).collect();
        let mut py: Vec<f64> = (0..n).step_by(stride).map(|i| c.y[i]).collect();
        px.retain(|v| v.is_finite());
        py.retain(|v| v.is_finite());
        if !px.is_empty() && !py.is_empty() {
            xs.push(quantile(&mut px, 0.005));
            xs.push(quantile(&mut px, 0.995));
            ys.push(quantile(&mut py, 0.005));
            ys.push(quantile(&mut py, 0.995));
        }
    }
    xs.retain(|v| v.is_finite());
    ys.retain(|v| v.is_finite());
    let min = |v: &[f64]| v.iter().copied().fold(f64::INFINITY, f64::min);
    let max = |v: &[f64]| v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if xs.is_empty() || ys.is_empty() {
        return None;
    }
    let (mut x0, mut x1, mut y0, mut y1) = (min(&xs), max(&xs), min(&ys), max(&ys));
    // Keep a degenerate extent (one point, a straight east–west line) drawable.
    if x1 - x0 < 1.0 {
        x0 -= 0.5;
        x1 += 0.5;
    }
    if y1 - y0 < 1.0 {
        y0 -= 0.5;
        y1 += 0.5;
    }
    Some((x0 - 2.0, x1 + 2.0, y0 - 2.0, y1 + 2.0))
}

/// A vertical colour bar for heights `z_range` in `area`, aligned with the plot's top and
/// bottom padding.
pub(crate) fn draw_colour_bar(
    area: &DrawingArea<BitMapBackend, Shift>,
    z_range: (f64, f64),
    title: &str,
    top: u32,
    bottom: u32,
) -> Result<(), DrawingAreaErrorKind<<BitMapBackend<'static> as DrawingBackend>::ErrorType>> {
    let (zlo, zhi) = z_range;
    let mut bar = ChartBuilder::on(area)
        .margin_top(top)
        .margin_bottom(bottom.saturating_sub(10))
        .margin_left(10)
        .margin_right(5)
        .right_y_label_area_size(80)
        .build_cartesian_2d(0.0..1.0, zlo..zhi)?;
    bar.configure_mesh()
        .disable_x_axis()
        .disable_x_mesh()
        .disable_y_mesh()
        .y_desc(title)
        .y_labels(8)
        .y_label_formatter(&|v| tick(*v, zhi - zlo))
        .label_style((FONT_NAME, 14))
        .axis_desc_style((FONT_NAME, 15))
        .draw()?;
    const STEPS: usize = 100;
    bar.draw_series((0..STEPS).map(|k| {
        let a = zlo + (zhi - zlo) * k as f64 / STEPS as f64;
        let b = zlo + (zhi - zlo) * (k + 1) as f64 / STEPS as f64;
        Rectangle::new(
            [(0.0, a), (1.0, b)],
            viridis((k as f64 + 0.5) / STEPS as f64).filled(),
        )
    }))?;
    Ok(())
}
