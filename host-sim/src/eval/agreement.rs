//! How closely two sets of edges agree, as the streaming extract is held to the whole-file
//! run (the campaign issue's ε): every vertex of one set is measured to the nearest line of
//! the same side in the other set; vertices within the match radius belong to *matched*
//! parts, and the largest of their distances, both ways, is the Hausdorff distance of the
//! matched parts. What one set has and the other lacks shows in the quality against the
//! reference, not here.

use crate::model::EdgeLine;

/// The agreement of two edge sets `a` and `b`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Agreement {
    /// Largest distance of a matched vertex to the other set's lines, both ways, metres
    /// (0 when nothing matched).
    pub matched_hausdorff_m: f64,
    /// Vertices of `a` and of `b` in all.
    pub vertices: (usize, usize),
    /// Vertices of `a` and of `b` farther than the match radius from the other set.
    pub unmatched: (usize, usize),
}

/// Compares `a` with `b`, vertices within `match_m` (horizontal) counting as matched.
pub fn agreement(a: &[EdgeLine], b: &[EdgeLine], match_m: f64) -> Agreement {
    let (ha, na, ua) = directed(a, b, match_m);
    let (hb, nb, ub) = directed(b, a, match_m);
    Agreement {
        matched_hausdorff_m: ha.max(hb),
        vertices: (na, nb),
        unmatched: (ua, ub),
    }
}

/// From `from`'s vertices to `to`'s lines: the largest matched distance, the vertex count
/// and the unmatched count.
fn directed(from: &[EdgeLine], to: &[EdgeLine], match_m: f64) -> (f64, usize, usize) {
    let (mut worst, mut n, mut unmatched) = (0.0f64, 0, 0);
    for e in from {
        for p in &e.points {
            n += 1;
            let d = to
                .iter()
                .filter(|o| o.side == e.side)
                .map(|o| distance_to_line(p, &o.points))
                .fold(f64::INFINITY, f64::min);
            if d <= match_m {
                worst = worst.max(d);
            } else {
                unmatched += 1;
            }
        }
    }
    (worst, n, unmatched)
}

/// Horizontal distance from `p` to the polyline `line`.
fn distance_to_line(p: &[f64; 3], line: &[[f64; 3]]) -> f64 {
    match line {
        [] => f64::INFINITY,
        [q] => (p[0] - q[0]).hypot(p[1] - q[1]),
        _ => line
            .windows(2)
            .map(|s| distance_to_segment(p, &s[0], &s[1]))
            .fold(f64::INFINITY, f64::min),
    }
}

fn distance_to_segment(p: &[f64; 3], a: &[f64; 3], b: &[f64; 3]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let (px, py) = (p[0] - a[0], p[1] - a[1]);
    let len2 = dx * dx + dy * dy;
    let u = if len2 > 0.0 {
        ((px * dx + py * dy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (px - u * dx).hypot(py - u * dy)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Side;

    fn line(pts: &[[f64; 2]], side: Side) -> EdgeLine {
        EdgeLine {
            points: pts.iter().map(|p| [p[0], p[1], 0.0]).collect(),
            side,
            category: None,
            method: None,
            curb_height_m: None,
            detail: None,
        }
    }

    #[test]
    fn matched_parts_are_measured_and_the_rest_counted() {
        let a = [line(&[[0.0, 0.0], [10.0, 0.0]], Side::Left)];
        // The same curb 4 mm off and cut in two, a stretch 2 m away, and a right edge on
        // the left line that must not match it.
        let b = [
            line(&[[0.0, 0.004], [5.0, 0.004]], Side::Left),
            line(&[[5.0, 0.004], [10.0, 0.004]], Side::Left),
            line(&[[0.0, 2.0], [3.0, 2.0]], Side::Left),
            line(&[[0.0, 0.0], [3.0, 0.0]], Side::Right),
        ];
        let g = agreement(&a, &b, 0.5);
        assert!((g.matched_hausdorff_m - 0.004).abs() < 1e-12, "{g:?}");
        assert_eq!(g.vertices, (2, 8));
        assert_eq!(g.unmatched, (0, 4));
    }
}
