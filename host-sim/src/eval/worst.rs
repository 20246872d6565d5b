//! Where an extraction goes most wrong, for a picture of it: the longest run of reference
//! that no extracted line comes within the buffer of (a miss), or the longest run of an
//! extracted line outside the buffer of every reference line (a false edge), whichever is
//! longer. Runs are measured on the same samples as the metrics.

use super::matching::{nearest, sample_polyline, segment_tree, to_local_pair};
use super::{check_params, EvalError, EvalParams};
use crate::model::{Category, EdgeLine, Side};

/// What the worst place is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WorstKind {
    /// Reference that no extracted line matches.
    Missed,
    /// Extraction that matches no reference line.
    False,
}

/// The worst place of an evaluation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorstPlace {
    /// Middle of the run, world coordinates.
    pub center: [f64; 2],
    /// Length of the run, metres.
    pub length_m: f64,
    /// A miss or a false edge.
    pub kind: WorstKind,
    /// Side of the reference line (of the nearest one for a false edge, if within the
    /// attribution distance).
    pub side: Option<Side>,
    /// Category of that reference line.
    pub category: Option<Category>,
}

/// The longest run of samples of `lines` farther than `buffer` from every line of
/// `other`: (line index, first and last sample, its length).
fn longest_run(
    lines: &[Vec<[f64; 2]>],
    other: &[Vec<[f64; 2]>],
    params: &EvalParams,
) -> Option<(usize, [f64; 2], [f64; 2], f64)> {
    let tree = segment_tree(other);
    let mut best: Option<(usize, [f64; 2], [f64; 2], f64)> = None;
    for (i, xy) in lines.iter().enumerate() {
        let (samples, w) = sample_polyline(xy, params.sample_step_m);
        let mut start: Option<usize> = None;
        let mut close = |from: usize, to: usize| {
            let len = (to - from) as f64 * w;
            if best.is_none_or(|b| len > b.3) {
                best = Some((i, samples[from], samples[to - 1], len));
            }
        };
        for (k, &p) in samples.iter().enumerate() {
            let far = nearest(&tree, p).is_none_or(|(_, d)| d > params.buffer_m);
            match (far, start) {
                (true, None) => start = Some(k),
                (false, Some(s)) => {
                    close(s, k);
                    start = None;
                }
                _ => {}
            }
        }
        if let Some(s) = start {
            close(s, samples.len());
        }
    }
    best
}

/// The worst place of `extracted` against `reference`, or `None` when everything matches.
pub fn worst_place(
    reference: &[EdgeLine],
    extracted: &[EdgeLine],
    params: &EvalParams,
) -> Result<Option<WorstPlace>, EvalError> {
    check_params(params)?;
    let (origin, ref_xy, ext_xy) = to_local_pair(reference, extracted)?;
    let missed = longest_run(&ref_xy, &ext_xy, params);
    let false_edge = longest_run(&ext_xy, &ref_xy, params);
    let (run, kind) = match (missed, false_edge) {
        (Some(m), Some(f)) if f.3 > m.3 => (f, WorstKind::False),
        (Some(m), _) => (m, WorstKind::Missed),
        (None, Some(f)) => (f, WorstKind::False),
        (None, None) => return Ok(None),
    };
    let (i, a, b, length_m) = run;
    let local = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
    let owner = match kind {
        WorstKind::Missed => Some(&reference[i]),
        WorstKind::False => nearest(&segment_tree(&ref_xy), local)
            .filter(|(_, d)| *d <= params.max_attribution_m)
            .map(|(j, _)| &reference[j]),
    };
    Ok(Some(WorstPlace {
        center: [local[0] + origin[0], local[1] + origin[1]],
        length_m,
        kind,
        side: owner.map(|l| l.side),
        category: owner.and_then(|l| l.category),
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(pts: &[(f64, f64)]) -> EdgeLine {
        EdgeLine {
            points: pts
                .iter()
                .map(|&(x, y)| [400_000.0 + x, 3_900_000.0 + y, 5.0])
                .collect(),
            side: Side::Left,
            category: Some(Category::CurbCut),
            method: None,
            curb_height_m: None,
            detail: None,
        }
    }

    #[test]
    fn the_longest_miss_is_found_in_its_middle() {
        // Reference 0..20 m; extraction covers 0..5 and 12..20: the miss is 5..12.
        let r = [line(&[(0.0, 0.0), (20.0, 0.0)])];
        let e = [
            line(&[(0.0, 0.01), (5.0, 0.01)]),
            line(&[(12.0, 0.01), (20.0, 0.01)]),
        ];
        let w = worst_place(&r, &e, &EvalParams::default())
            .unwrap()
            .unwrap();
        assert_eq!(w.kind, WorstKind::Missed);
        assert!((w.length_m - 7.0).abs() < 0.1, "{}", w.length_m);
        assert!((w.center[0] - 400_008.5).abs() < 0.1, "{:?}", w.center);
        assert_eq!(w.category, Some(Category::CurbCut));
    }

    #[test]
    fn a_long_false_edge_beats_a_short_miss() {
        let r = [line(&[(0.0, 0.0), (10.0, 0.0)])];
        let e = [
            line(&[(0.0, 0.0), (9.0, 0.0)]),
            line(&[(0.0, 1.0), (30.0, 1.0)]),
        ];
        let w = worst_place(&r, &e, &EvalParams::default())
            .unwrap()
            .unwrap();
        assert_eq!(w.kind, WorstKind::False);
        assert!((w.length_m - 30.0).abs() < 0.1);
        let all = [line(&[(0.0, 0.0), (10.0, 0.0)])];
        assert_eq!(
            worst_place(&all, &all, &EvalParams::default()).unwrap(),
            None
        );
    }
}
