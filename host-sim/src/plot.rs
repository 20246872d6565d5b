//! Pictures for people (issue 5): PNG files drawn with plotters and an embedded font, so they
//! need no system fonts.
//!
//! - [`top_view_png`]: points seen from above, coloured by height, with the reference lines,
//!   the extracted edges and the trajectory on top; either the whole scene or a square window
//!   (a curb cut, an intersection, a parked car, the bus bay). Axes in metres from a round
//!   local origin, equal scale on both axes.
//! - [`cross_section_png`]: one scanline in the x′–z′ plane and its bend angles ρ before and
//!   after Taubin smoothing, with the seed candidates marked (like Honma et al.'s Fig. 4
//!   and 6).
//!
//! The inputs are plain slices so callers need nothing but their own columns.

use crate::model::EdgeLine;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;
use std::sync::Once;

/// DejaVu Sans, embedded (licence in `host-sim/assets/`).
static FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");
const FONT_NAME: &str = "sans-serif";

static REGISTER: Once = Once::new();

/// Registers the embedded font once per process under the name plotters uses by default.
fn register_font() {
    REGISTER.call_once(|| {
        // The bytes are a valid TTF (checked by a unit test); plotters falls back from other
        // styles to Normal, so one registration serves all text.
        let _ = plotters::style::register_font(FONT_NAME, FontStyle::Normal, FONT);
    });
}

/// Why a picture could not be drawn.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// The input is unusable (empty, mismatched lengths, non-finite).
    #[error("{path}: {what}")]
    Input {
        /// The picture's file.
        path: String,
        /// What was wrong.
        what: String,
    },
    /// Drawing or writing the PNG failed.
    #[error("{path}: drawing failed: {what}")]
    Draw {
        /// The picture's file.
        path: String,
        /// The plotters error.
        what: String,
    },
}

fn draw_err<E: std::fmt::Display>(path: &Path) -> impl Fn(E) -> PlotError + '_ {
    move |e| PlotError::Draw {
        path: path.display().to_string(),
        what: e.to_string(),
    }
}

/// The legend box every chart here uses: white, half-transparent, thin black border.
fn draw_legend<'a, DB: DrawingBackend + 'a, CT: plotters::coord::CoordTranslate>(
    ch: &mut ChartContext<'a, DB, CT>,
    position: SeriesLabelPosition,
    font_px: u32,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    ch.configure_series_labels()
        .position(position)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK.mix(0.5))
        .label_font((FONT_NAME, font_px))
        .draw()
}

fn input_err(path: &Path, what: impl Into<String>) -> PlotError {
    PlotError::Input {
        path: path.display().to_string(),
        what: what.into(),
    }
}

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
fn above_local_ground(c: &Cloud, idx: &[usize]) -> Vec<f64> {
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

/// SplitMix64's output function: a well-mixed hash of `x`.
fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Viridis colour map (matplotlib's, 11 stops, linear in between); `t` in [0, 1].
/// Perceptually uniform and readable in grey and by most colour-blind readers.
pub fn viridis(t: f64) -> RGBColor {
    const STOPS: [(u8, u8, u8); 11] = [
        (68, 1, 84),
        (72, 36, 117),
        (65, 68, 135),
        (53, 95, 141),
        (42, 120, 142),
        (33, 145, 140),
        (34, 168, 132),
        (68, 191, 112),
        (122, 209, 81),
        (189, 223, 38),
        (253, 231, 37),
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let f = t * 10.0;
    let i = (f.floor() as usize).min(9);
    let u = f - i as f64;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    let mix = |p: u8, q: u8| (p as f64 + u * (q as f64 - p as f64)).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// The value at quantile `q` of `v` (sorted in place; `v` non-empty).
fn quantile(v: &mut [f64], q: f64) -> f64 {
    v.sort_unstable_by(|a, b| a.total_cmp(b));
    let i = ((v.len() - 1) as f64 * q).round() as usize;
    v[i.min(v.len() - 1)]
}

/// A round origin below `v` (to 10 m, or 100 m for large extents) for readable axes.
fn round_origin(v: f64, extent: f64) -> f64 {
    let step = if extent > 200.0 { 100.0 } else { 10.0 };
    (v / step).floor() * step
}

/// Thousands separated by thin spaces, for axis titles such as "E − 523 400 m".
fn group_thousands(v: f64) -> String {
    let s = format!("{}", v.abs().round() as i64);
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if i > 0 && (s.len() - i) % 3 == 0 {
            out.push('\u{2009}');
        }
        out.push(c);
    }
    if v < 0.0 {
        format!("−{out}")
    } else {
        out
    }
}

/// An axis tick label with as many decimals as the axis extent needs.
fn tick(v: f64, extent: f64) -> String {
    let d = if extent >= 20.0 {
        0
    } else if extent >= 2.0 {
        1
    } else {
        2
    };
    let s = format!("{v:.d$}");
    // "-0" reads as a mistake.
    if s.trim_start_matches('-')
        .chars()
        .all(|c| c == '0' || c == '.')
    {
        s.trim_start_matches('-').to_string()
    } else {
        s.replace('-', "−")
    }
}

/// Clips a polyline to the rectangle [x0, x1] × [y0, y1] (Liang–Barsky per segment) and
/// returns the pieces inside. plotters would otherwise pin coordinates outside the chart to
/// its border, drawing lines that are not there.
fn clip_polyline(pts: &[(f64, f64)], r: (f64, f64, f64, f64)) -> Vec<Vec<(f64, f64)>> {
    let (x0, x1, y0, y1) = r;
    let mut out: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut cur: Vec<(f64, f64)> = Vec::new();
    for w in pts.windows(2) {
        let (a, b) = (w[0], w[1]);
        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
        let (mut t0, mut t1) = (0.0f64, 1.0f64);
        let mut inside = true;
        for (p, q) in [
            (-dx, a.0 - x0),
            (dx, x1 - a.0),
            (-dy, a.1 - y0),
            (dy, y1 - a.1),
        ] {
            if p == 0.0 {
                if q < 0.0 {
                    inside = false;
                }
            } else {
                let t = q / p;
                if p < 0.0 {
                    t0 = t0.max(t);
                } else {
                    t1 = t1.min(t);
                }
            }
        }
        if !inside || t0 > t1 || !(t0.is_finite() && t1.is_finite()) {
            if cur.len() >= 2 {
                out.push(std::mem::take(&mut cur));
            }
            cur.clear();
            continue;
        }
        let pa = (a.0 + t0 * dx, a.1 + t0 * dy);
        let pb = (a.0 + t1 * dx, a.1 + t1 * dy);
        if cur.last() != Some(&pa) {
            if cur.len() >= 2 {
                out.push(std::mem::take(&mut cur));
            }
            cur.clear();
            cur.push(pa);
        }
        cur.push(pb);
        if t1 < 1.0 {
            out.push(std::mem::take(&mut cur));
        }
    }
    if cur.len() >= 2 {
        out.push(cur);
    }
    out
}

/// Splits a polyline into dashes of `dash` length (gaps of the same length), in data units.
fn dashes(pts: &[(f64, f64)], dash: f64) -> Vec<Vec<(f64, f64)>> {
    let mut out = Vec::new();
    let mut cur: Vec<(f64, f64)> = Vec::new();
    let mut on = true;
    let mut left = dash;
    for w in pts.windows(2) {
        let (a, b) = (w[0], w[1]);
        let len = (b.0 - a.0).hypot(b.1 - a.1);
        let mut s = 0.0;
        if on && cur.is_empty() {
            cur.push(a);
        }
        while len - s > left {
            s += left;
            let p = (a.0 + (b.0 - a.0) * s / len, a.1 + (b.1 - a.1) * s / len);
            if on {
                cur.push(p);
                out.push(std::mem::take(&mut cur));
            } else {
                cur.push(p);
            }
            on = !on;
            left = dash;
        }
        left -= len - s;
        if on {
            cur.push(b);
        } else {
            cur.clear();
        }
    }
    if cur.len() >= 2 {
        out.push(cur);
    }
    out
}

/// The point at half the 2D length of a polyline (its first vertex if it has no length).
fn mid_point(l: &EdgeLine) -> Option<[f64; 2]> {
    let half = l.length_m() / 2.0;
    let mut s = 0.0;
    for w in l.points.windows(2) {
        let len = (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]);
        if s + len >= half && len > 0.0 {
            let t = (half - s) / len;
            return Some([
                w[0][0] + t * (w[1][0] - w[0][0]),
                w[0][1] + t * (w[1][1] - w[0][1]),
            ]);
        }
        s += len;
    }
    l.points.first().map(|p| [p[0], p[1]])
}

/// Unit direction of a line at one end, pointing out of the line (`at_end`: the last
/// vertex, else the first), from the end vertex and the vertex about 1 m inside.
fn end_direction(l: &EdgeLine, at_end: bool) -> Option<[f64; 2]> {
    let pts: Vec<&[f64; 3]> = if at_end {
        l.points.iter().rev().collect()
    } else {
        l.points.iter().collect()
    };
    let e = pts.first()?;
    let inner = pts
        .iter()
        .find(|p| (p[0] - e[0]).hypot(p[1] - e[1]) >= 1.0)
        .or(pts.last())?;
    let (dx, dy) = (e[0] - inner[0], e[1] - inner[1]);
    let n = dx.hypot(dy);
    (n > 0.0).then(|| [dx / n, dy / n])
}

/// Zoom windows at the places people want to see, found from the reference lines:
/// the longest curb cut, intersection and bus bay (centred on the middle of the line) and the
/// longest *occlusion*: a hole of 2–15 m between two free ends (meeting no other line of
/// their side) of curb or curb-cut lines of one side that continue each other straight
/// (within 20°), which is where the reference leaves out what the
/// scanner never saw — usually a parked car. Returns (name, window) pairs; names are
/// `curb_cut`, `intersection`, `bus_bay`, `occlusion`.
pub fn windows_of_interest(reference: &[EdgeLine], half_size_m: f64) -> Vec<(String, Window)> {
    use crate::model::Category;
    let mut out = Vec::new();
    for cat in [Category::CurbCut, Category::Intersection, Category::BusBay] {
        // The longest line of the category shows it best.
        let best = reference
            .iter()
            .filter(|l| l.category == Some(cat))
            .max_by(|a, b| a.length_m().total_cmp(&b.length_m()));
        if let Some(c) = best.and_then(mid_point) {
            out.push((
                cat.as_str().to_string(),
                Window {
                    center: c,
                    half_size_m,
                },
            ));
        }
    }
    let straight = |l: &&EdgeLine| matches!(l.category, Some(Category::Curb | Category::CurbCut));
    let ends: Vec<(usize, [f64; 2], [f64; 2])> = reference
        .iter()
        .enumerate()
        .filter(|(_, l)| straight(l))
        .flat_map(|(i, l)| {
            [false, true].into_iter().filter_map(move |at_end| {
                let p = if at_end {
                    l.points.last()
                } else {
                    l.points.first()
                }?;
                Some((i, [p[0], p[1]], end_direction(l, at_end)?))
            })
        })
        .collect();
    // An end that meets another line of its side (a curb running on as a curb cut) is no
    // hole.
    let meets_another = |i: usize, p: [f64; 2]| {
        reference.iter().enumerate().any(|(j, l)| {
            j != i
                && l.side == reference[i].side
                && [l.points.first(), l.points.last()]
                    .into_iter()
                    .flatten()
                    .any(|q| (q[0] - p[0]).hypot(q[1] - p[1]) < 0.5)
        })
    };
    let ends: Vec<_> = ends
        .into_iter()
        .filter(|&(i, p, _)| !meets_another(i, p))
        .collect();
    let cos20 = 20f64.to_radians().cos();
    let mut hole: Option<(f64, [f64; 2])> = None;
    for (a, &(ia, pa, da)) in ends.iter().enumerate() {
        for &(ib, pb, db) in &ends[a + 1..] {
            if ia == ib || reference[ia].side != reference[ib].side {
                continue;
            }
            let (dx, dy) = (pb[0] - pa[0], pb[1] - pa[1]);
            let gap = dx.hypot(dy);
            if !(2.0..=15.0).contains(&gap) {
                continue;
            }
            let (ux, uy) = (dx / gap, dy / gap);
            // a's end points towards b, b's end points back towards a.
            if da[0] * ux + da[1] * uy >= cos20
                && -(db[0] * ux + db[1] * uy) >= cos20
                && hole.is_none_or(|(g, _)| gap > g)
            {
                hole = Some((gap, [pa[0] + dx / 2.0, pa[1] + dy / 2.0]));
            }
        }
    }
    if let Some((_, c)) = hole {
        out.push((
            "occlusion".to_string(),
            Window {
                center: c,
                half_size_m,
            },
        ));
    }
    out
}

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
    let ext_style = ShapeStyle {
        color: BLACK.to_rgba(),
        filled: false,
        stroke_width: 2,
    };
    if !view.extracted.is_empty() {
        chart
            .draw_series(
                view.extracted
                    .iter()
                    .flat_map(local)
                    .map(|v| PathElement::new(v, ext_style)),
            )
            .map_err(&err)?
            .label("extracted")
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], ext_style));
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
        let dash = 12.0 / px_per_m; // 12 px dashes
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

/// The extent of the whole scene: reference, extracted and trajectory, widened to the
/// 0.5–99.5 % quantiles of the points (so a few outliers do not shrink the road to a line),
/// with a 2 m margin.
fn scene_extent(view: &TopView) -> Option<(f64, f64, f64, f64)> {
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
fn draw_colour_bar(
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Category, Side};

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
}
