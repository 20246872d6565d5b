//! Where to zoom: square windows around the curb cuts, corners, bus bays and occluded
//! stretches of a reference.

use super::top_view::Window;
use crate::model::EdgeLine;

/// The point at half the 2D length of a polyline (its first vertex if it has no length).
pub(crate) fn mid_point(l: &EdgeLine) -> Option<[f64; 2]> {
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
pub(crate) fn end_direction(l: &EdgeLine, at_end: bool) -> Option<[f64; 2]> {
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
