//! Colours, axis ticks and line clipping shared by the pictures.

use plotters::prelude::*;

/// SplitMix64's output function: a well-mixed hash of `x`.
pub(crate) fn splitmix64(x: u64) -> u64 {
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
pub(crate) fn quantile(v: &mut [f64], q: f64) -> f64 {
    v.sort_unstable_by(|a, b| a.total_cmp(b));
    let i = ((v.len() - 1) as f64 * q).round() as usize;
    v[i.min(v.len() - 1)]
}

/// A round origin below `v` (to 10 m, or 100 m for large extents) for readable axes.
pub(crate) fn round_origin(v: f64, extent: f64) -> f64 {
    let step = if extent > 200.0 { 100.0 } else { 10.0 };
    (v / step).floor() * step
}

/// Thousands separated by thin spaces, for axis titles such as "E − 523 400 m".
pub(crate) fn group_thousands(v: f64) -> String {
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
pub(crate) fn tick(v: f64, extent: f64) -> String {
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
pub(crate) fn clip_polyline(pts: &[(f64, f64)], r: (f64, f64, f64, f64)) -> Vec<Vec<(f64, f64)>> {
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
pub(crate) fn dashes(pts: &[(f64, f64)], dash: f64) -> Vec<Vec<(f64, f64)>> {
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
