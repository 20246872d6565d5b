//! The curb on one cross-section: road, face and top fitted by lines, the arris and the
//! foot of the face where they meet (docs/spec.md §2, "Curb geometry").

/// Road points used for the road line: `ROAD_FROM_M..ROAD_TO_M` across the toe, metres
/// (negative = road side).
const ROAD_FROM_M: f64 = -0.45;
const ROAD_TO_M: f64 = -0.04;
/// Top points used for the top line, metres behind the toe: past a rounded or chamfered
/// arris (a few centimetres), before the back of a narrow curb stone.
const TOP_FROM_M: f64 = 0.06;
const TOP_TO_M: f64 = 0.30;
/// Face points: within this band across the toe, metres.
const FACE_FROM_M: f64 = -0.06;
const FACE_TO_M: f64 = 0.12;
/// A step lower than this has no face to fit: the height is the top line's rise over the
/// road line at the toe and the top is the toe.
pub const LOW_STEP_M: f64 = 0.015;
/// Steepest road and top lines taken as ground (a ramp behind a lowered curb rises at up
/// to about 1 : 3).
const MAX_SLOPE: f64 = 0.4;
/// Least points on the road and on the top.
const MIN_POINTS: usize = 4;

/// What a cross-section gives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Section {
    /// Horizontal position of the arris across the section, metres from the toe vertex
    /// (positive towards the curb).
    pub c_top: f64,
    /// Curb height: arris height above the foot of the face, metres.
    pub height_m: f64,
}

/// Least-squares line `v = a + b·u` over `(u, v)`; `None` for fewer than two points or a
/// single `u`.
fn line(p: impl Iterator<Item = (f64, f64)>) -> Option<(f64, f64, usize)> {
    let (mut n, mut su, mut sv, mut suu, mut suv) = (0usize, 0.0, 0.0, 0.0, 0.0);
    for (u, v) in p {
        n += 1;
        su += u;
        sv += v;
        suu += u * u;
        suv += u * v;
    }
    if n < 2 {
        return None;
    }
    let nf = n as f64;
    let den = nf * suu - su * su;
    if den <= 1e-12 * nf * nf {
        return None;
    }
    let b = (nf * suv - su * sv) / den;
    Some(((sv - b * su) / nf, b, n))
}

/// Line fit with one pass of outlier removal: points farther than `tol` from the first
/// fit are left out of the second.
fn robust_line(p: &[(f64, f64)], tol: f64) -> Option<(f64, f64, usize)> {
    let (a, b, _) = line(p.iter().copied())?;
    line(
        p.iter()
            .copied()
            .filter(|&(u, v)| (v - a - b * u).abs() <= tol),
    )
}

/// Fits the curb on a cross-section `pts` of `(c, z)`: `c` across the toe (0 at the toe
/// vertex, positive towards the curb), `z` heights (any common origin).
///
/// The road line is fitted on the road side, the top line on the curb top, both as ground
/// (slopes under 0.4). Their rise at the toe is the step; under [`LOW_STEP_M`] the section
/// is a flush edge or a lowered curb's lip without a face to fit, and the result is the
/// step at the toe. Otherwise the face is fitted by a line `c = f0 + f1·z` through the
/// points between a fifth and four fifths of the step (the straight part of the face, below
/// a rounded arris, above a fillet at the foot); the arris is where the face line meets the
/// top line (the intersection of their tangent planes for a rounded arris), the foot where
/// it meets the road line, and the height is the arris's height over the foot.
pub fn fit(pts: &[(f64, f64)]) -> Option<Section> {
    let road: Vec<(f64, f64)> = pts
        .iter()
        .copied()
        .filter(|p| (ROAD_FROM_M..=ROAD_TO_M).contains(&p.0))
        .collect();
    let top: Vec<(f64, f64)> = pts
        .iter()
        .copied()
        .filter(|p| (TOP_FROM_M..=TOP_TO_M).contains(&p.0))
        .collect();
    let (ra, rb, rn) = robust_line(&road, 0.02)?;
    let (ta, tb, tn) = robust_line(&top, 0.02)?;
    if rn < MIN_POINTS || tn < MIN_POINTS || rb.abs() > MAX_SLOPE || tb.abs() > MAX_SLOPE {
        return None;
    }
    let step = ta - ra;
    if step < LOW_STEP_M {
        return Some(Section {
            c_top: 0.0,
            height_m: step.max(0.0),
        });
    }
    let face: Vec<(f64, f64)> = pts
        .iter()
        .copied()
        .filter(|&(c, z)| {
            let h = z - (ra + rb * c);
            (FACE_FROM_M..=FACE_TO_M).contains(&c) && h >= 0.2 * step && h <= 0.8 * step
        })
        .map(|(c, z)| (z, c))
        .collect();
    // The face as c = f0 + f1·z; nearly vertical, so regressed on z. Too few or too close
    // face points: a vertical face through their mean (or at the toe).
    let (f0, f1) = match line(face.iter().copied()) {
        Some((f0, f1, n)) if n >= 3 && (-0.1..=0.6).contains(&f1) => (f0, f1),
        _ if !face.is_empty() => (
            face.iter().map(|p| p.1).sum::<f64>() / face.len() as f64,
            0.0,
        ),
        _ => (0.0, 0.0),
    };
    // c = f0 + f1·(ta + tb·c) and c = f0 + f1·(ra + rb·c).
    let meet = |a: f64, b: f64| -> Option<(f64, f64)> {
        let den = 1.0 - f1 * b;
        if den.abs() < 1e-6 {
            return None;
        }
        let c = (f0 + f1 * a) / den;
        Some((c, a + b * c))
    };
    let (c_top, z_top) = meet(ta, tb)?;
    let (_, z_foot) = meet(ra, rb)?;
    if !(-0.1..=0.2).contains(&c_top) {
        return None;
    }
    Some(Section {
        c_top,
        height_m: z_top - z_foot,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A curb of height `h` with the face from c = 0 rising at batter `b` (run per rise),
    /// a road falling 2 % towards it and a top rising 2 % away, sampled every millimetre, with a
    /// rounded arris of radius 15 mm approximated by dropping the points within it.
    fn section(h: f64, batter: f64) -> Vec<(f64, f64)> {
        let run = batter * h;
        (-450..=350)
            .map(|i| i as f64 * 0.001)
            .filter_map(|c: f64| {
                let z = if c <= 0.0 {
                    -0.02 * c
                } else if c < run {
                    h * c / run
                } else {
                    h + 0.02 * (c - run)
                };
                // The rounding takes the corner off: no points within 15 mm of it.
                let near_corner = (c - run).hypot(z - h) < 0.015 && c > run - 0.015;
                (!near_corner).then_some((c, z))
            })
            .collect()
    }

    #[test]
    fn arris_is_where_face_and_top_meet() {
        let s = fit(&section(0.15, 0.1)).unwrap();
        assert!((s.c_top - 0.015).abs() < 0.004, "{s:?}");
        assert!((s.height_m - 0.15).abs() < 0.003, "{s:?}");
    }

    #[test]
    fn a_lowered_curb_has_its_small_height() {
        let s = fit(&section(0.025, 0.1)).unwrap();
        assert!((s.height_m - 0.025).abs() < 0.004, "{s:?}");
        let flush = fit(&section(0.0, 0.1)).unwrap();
        assert!(flush.height_m.abs() < 0.004, "{flush:?}");
    }

    #[test]
    fn no_road_points_no_section() {
        let pts: Vec<(f64, f64)> = section(0.15, 0.1)
            .into_iter()
            .filter(|p| p.0 > -0.03)
            .collect();
        assert!(fit(&pts).is_none());
    }
}
