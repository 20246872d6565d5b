//! The geometry of matching: lines shifted to a local origin, sampled into equal pieces,
//! and the nearest line to a sample through an R-tree of segments.

use super::EvalError;
use crate::model::EdgeLine;
use rstar::primitives::{GeomWithData, Line};
use rstar::{PointDistance, RTree};

/// Returns the sample points and the common piece length (0 samples for a line of zero
/// length).
pub(super) fn sample_polyline(points: &[[f64; 2]], step: f64) -> (Vec<[f64; 2]>, f64) {
    let seg_len: Vec<f64> = points
        .windows(2)
        .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
        .collect();
    let total: f64 = seg_len.iter().sum();
    if total <= 0.0 {
        return (Vec::new(), 0.0);
    }
    // The small tolerance keeps a line of exactly k steps at k pieces.
    let n = ((total / step) - 1e-9).ceil().max(1.0) as usize;
    let piece = total / n as f64;
    let mut out = Vec::with_capacity(n);
    let mut seg = 0;
    let mut seg_start = 0.0; // arc length at the start of segment `seg`
    for k in 0..n {
        let s = (k as f64 + 0.5) * piece;
        while seg + 1 < seg_len.len() && seg_start + seg_len[seg] < s {
            seg_start += seg_len[seg];
            seg += 1;
        }
        let l = seg_len[seg];
        let t = if l > 0.0 {
            ((s - seg_start) / l).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let (a, b) = (points[seg], points[seg + 1]);
        out.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
    }
    (out, piece)
}

pub(super) type Seg = GeomWithData<Line<[f64; 2]>, usize>;

pub(super) fn segment_tree(lines: &[Vec<[f64; 2]>]) -> RTree<Seg> {
    let segs: Vec<Seg> = lines
        .iter()
        .enumerate()
        .flat_map(|(i, l)| {
            l.windows(2)
                // A zero-length segment has no direction (rstar would divide by zero).
                .filter(|w| w[0] != w[1])
                .map(move |w| GeomWithData::new(Line::new(w[0], w[1]), i))
        })
        .collect();
    RTree::bulk_load(segs)
}

/// Nearest line to `p`: (line index, distance), or `None` for an empty tree.
pub(super) fn nearest(tree: &RTree<Seg>, p: [f64; 2]) -> Option<(usize, f64)> {
    // rstar's dedicated nearest-neighbour search prunes better than the sorted iterator.
    tree.nearest_neighbor(&p)
        .map(|s| (s.data, s.distance_2(&p).sqrt()))
}

/// Both line sets in horizontal coordinates relative to their first finite vertex (so the
/// sums stay exact far from the CRS origin): (origin, reference, extracted).
pub(super) type LocalPair = ([f64; 2], Vec<Vec<[f64; 2]>>, Vec<Vec<[f64; 2]>>);

/// [`to_local`] for a reference and an extraction about one shared origin.
pub(super) fn to_local_pair(
    reference: &[EdgeLine],
    extracted: &[EdgeLine],
) -> Result<LocalPair, EvalError> {
    let origin = reference
        .iter()
        .chain(extracted)
        .find_map(|l| l.points.first())
        .map(|p| [p[0], p[1]])
        .filter(|o| o[0].is_finite() && o[1].is_finite())
        .unwrap_or([0.0, 0.0]);
    Ok((
        origin,
        to_local(reference, origin, "reference")?,
        to_local(extracted, origin, "extracted")?,
    ))
}

pub(super) fn to_local(
    lines: &[EdgeLine],
    origin: [f64; 2],
    which: &'static str,
) -> Result<Vec<Vec<[f64; 2]>>, EvalError> {
    lines
        .iter()
        .enumerate()
        .map(|(index, l)| {
            l.points
                .iter()
                .map(|p| {
                    if p[0].is_finite() && p[1].is_finite() {
                        Ok([p[0] - origin[0], p[1] - origin[1]])
                    } else {
                        Err(EvalError::NonFinite { which, index })
                    }
                })
                .collect()
        })
        .collect()
}
