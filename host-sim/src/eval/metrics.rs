//! The metrics: per column (total, side, side and category) sums of matched, TP and FP
//! lengths, gaps and outside pieces, and [`evaluate`], which fills them.

use super::matching::{nearest, sample_polyline, segment_tree, to_local_pair};
use super::{check_params, EvalError, EvalParams};
use crate::model::{Category, EdgeLine, Side};
use rayon::prelude::*;
use serde::Serialize;

/// The metrics of one column of the table (total, one side, or one side and category).
///
/// Ratios are `None` where their denominator is zero (e.g. correctness without extracted
/// lines): the table shows "–" there, as the paper does.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Metrics {
    /// Reference length, metres.
    pub reference_m: f64,
    /// Matched reference length (within the buffer of an extracted line), metres.
    pub matched_m: f64,
    /// Unmatched reference length (FN), metres.
    pub fn_m: f64,
    /// Extracted length, metres.
    pub extracted_m: f64,
    /// Extracted length within the buffer of a reference line (TP), metres.
    pub tp_m: f64,
    /// Extracted length outside the buffer (FP), metres.
    pub fp_m: f64,
    /// Completeness, percent (Eq. 9).
    pub completeness_pct: Option<f64>,
    /// Correctness, percent (Eq. 10).
    pub correctness_pct: Option<f64>,
    /// Quality, percent (Eq. 11, TP measured on the extraction).
    pub quality_pct: Option<f64>,
    /// RMS distance of the TP samples to the reference, millimetres (Eq. 12).
    pub rms_mm: Option<f64>,
    /// Heipke's gaps: runs of unmatched reference longer than `min_gap_m`.
    pub gaps: usize,
    /// Total length of Heipke's gaps, metres.
    pub gap_length_m: f64,
    /// Honma et al.'s wording: extracted pieces outside the buffer longer than `min_gap_m`.
    pub outside_pieces: usize,
    /// Total length of those pieces, metres.
    pub outside_length_m: f64,
}

/// One category's column within a side.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CategoryMetrics {
    /// The category; `None` for reference lines without one ("other").
    pub category: Option<Category>,
    /// Its metrics.
    pub metrics: Metrics,
}

/// One side's columns.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SideMetrics {
    /// The side.
    pub side: Side,
    /// The side's total.
    pub total: Metrics,
    /// The categories present on this side (reference or attributed extraction), in table
    /// order: curb, curb cut, intersection, bus bay, other.
    pub categories: Vec<CategoryMetrics>,
}

/// The result of [`evaluate`]: what the table and the JSON output show.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EvalReport {
    /// The parameters used.
    pub params: EvalParams,
    /// All lines together.
    pub total: Metrics,
    /// The sides present (left first).
    pub sides: Vec<SideMetrics>,
    /// Extracted length farther than `max_attribution_m` from every reference line, metres
    /// (part of the total's FP, of no side).
    pub extracted_unattributed_m: f64,
}

// ---------------------------------------------------------------------------------------
// Columns ("buckets"): 0 = total; per side s (0 = left, 1 = right): 1 + 6s = side total,
// 1 + 6s + 1 + c = category c (0..4 as in Category::REFERENCE, 4 = none).

const N_BUCKETS: usize = 13;
const N_CAT_SLOTS: usize = 5;

fn side_index(s: Side) -> usize {
    match s {
        Side::Left => 0,
        Side::Right => 1,
    }
}

fn cat_index(c: Option<Category>) -> usize {
    match c {
        Some(Category::Curb) => 0,
        Some(Category::CurbCut) => 1,
        Some(Category::Intersection) => 2,
        Some(Category::BusBay) => 3,
        Some(Category::Flush) | None => 4,
    }
}

fn bucket_side(s: Side) -> usize {
    1 + 6 * side_index(s)
}

fn bucket_cat(s: Side, c: Option<Category>) -> usize {
    bucket_side(s) + 1 + cat_index(c)
}

/// Sums of weights per column; merged across lines and threads.
#[derive(Clone, Copy, Debug, Default)]
struct Acc {
    reference: f64,
    matched: f64,
    extracted: f64,
    tp: f64,
    tp_d2: f64,
    gaps: usize,
    gap_len: f64,
    outside: usize,
    outside_len: f64,
}

impl Acc {
    fn add(&mut self, o: &Acc) {
        self.reference += o.reference;
        self.matched += o.matched;
        self.extracted += o.extracted;
        self.tp += o.tp;
        self.tp_d2 += o.tp_d2;
        self.gaps += o.gaps;
        self.gap_len += o.gap_len;
        self.outside += o.outside;
        self.outside_len += o.outside_len;
    }

    fn metrics(&self) -> Metrics {
        let ratio = |num: f64, den: f64| (den > 0.0).then(|| 100.0 * num / den);
        let fn_m = (self.reference - self.matched).max(0.0);
        let fp_m = (self.extracted - self.tp).max(0.0);
        Metrics {
            reference_m: self.reference,
            matched_m: self.matched,
            fn_m,
            extracted_m: self.extracted,
            tp_m: self.tp,
            fp_m,
            completeness_pct: ratio(self.matched, self.reference),
            correctness_pct: ratio(self.tp, self.extracted),
            quality_pct: ratio(self.tp, self.extracted + fn_m),
            rms_mm: (self.tp > 0.0).then(|| 1000.0 * (self.tp_d2 / self.tp).sqrt()),
            gaps: self.gaps,
            gap_length_m: self.gap_len,
            outside_pieces: self.outside,
            outside_length_m: self.outside_len,
        }
    }

    fn is_empty(&self) -> bool {
        self.reference <= 0.0 && self.extracted <= 0.0
    }
}

type Accs = [Acc; N_BUCKETS];

fn merge(mut a: Accs, b: Accs) -> Accs {
    for (x, y) in a.iter_mut().zip(b.iter()) {
        x.add(y);
    }
    a
}

/// Scores `extracted` against `reference` (docs/spec.md §5; see the module docs for the exact
/// definitions). Only `side` and `category` of the reference lines are used; the extracted
/// lines' own side and category are ignored (each sample takes its nearest reference's).
pub fn evaluate(
    reference: &[EdgeLine],
    extracted: &[EdgeLine],
    params: &EvalParams,
) -> Result<EvalReport, EvalError> {
    check_params(params)?;
    let (_, ref_xy, ext_xy) = to_local_pair(reference, extracted)?;
    let ref_tree = segment_tree(&ref_xy);
    let ext_tree = segment_tree(&ext_xy);
    // Lengths are counted in samples per line and multiplied by the line's piece length once,
    // so that a 28 m reference reads 28.000 m and not the sum of 2800 rounded increments.
    // "Longer than": a run of exactly min_gap_m samples is not a gap.
    let min_gap = params.min_gap_m + 1e-9;
    let buffer = params.buffer_m;

    // Reference samples: matched or FN, and Heipke's gaps along each reference line.
    let ref_accs = ref_xy
        .par_iter()
        .zip(reference.par_iter())
        .map(|(xy, line)| {
            let mut accs: Accs = Default::default();
            let (samples, w) = sample_polyline(xy, params.sample_step_m);
            let buckets = [
                0,
                bucket_side(line.side),
                bucket_cat(line.side, line.category),
            ];
            let (mut matched, mut run, mut gaps, mut gap_samples) = (0usize, 0usize, 0, 0);
            let mut close = |run: &mut usize| {
                if *run as f64 * w > min_gap {
                    gaps += 1;
                    gap_samples += *run;
                }
                *run = 0;
            };
            for &p in &samples {
                if nearest(&ext_tree, p).is_some_and(|(_, d)| d <= buffer) {
                    matched += 1;
                    close(&mut run);
                } else {
                    run += 1;
                }
            }
            close(&mut run);
            let acc = Acc {
                reference: samples.len() as f64 * w,
                matched: matched as f64 * w,
                gaps,
                gap_len: gap_samples as f64 * w,
                ..Acc::default()
            };
            for b in buckets {
                accs[b].add(&acc);
            }
            accs
        })
        .reduce(Default::default, merge);

    // Extracted samples: TP or FP, attribution, RMS, and outside pieces per column.
    let max_attr = params.max_attribution_m;
    let ext_accs = ext_xy
        .par_iter()
        .map(|xy| {
            let (samples, w) = sample_polyline(xy, params.sample_step_m);
            let mut unattributed = 0usize;
            // Per column: extracted, TP and outside-piece sample counts, open run, TP d².
            let mut n_ext = [0usize; N_BUCKETS];
            let mut n_tp = [0usize; N_BUCKETS];
            let mut n_out = [0usize; N_BUCKETS];
            let mut pieces = [0usize; N_BUCKETS];
            let mut runs = [0usize; N_BUCKETS];
            let mut d2 = [0.0f64; N_BUCKETS];
            let mut close = |b: usize, runs: &mut [usize; N_BUCKETS]| {
                if runs[b] as f64 * w > min_gap {
                    pieces[b] += 1;
                    n_out[b] += runs[b];
                }
                runs[b] = 0;
            };
            for &p in &samples {
                let (d, attributed) = match nearest(&ref_tree, p) {
                    Some((i, d)) if d <= max_attr => {
                        let l = &reference[i];
                        (
                            d,
                            Some((bucket_side(l.side), bucket_cat(l.side, l.category))),
                        )
                    }
                    Some((_, d)) => (d, None),
                    None => (f64::INFINITY, None),
                };
                let tp = d <= buffer;
                let mut member = [false; N_BUCKETS];
                member[0] = true;
                if let Some((bs, bc)) = attributed {
                    member[bs] = true;
                    member[bc] = true;
                } else {
                    unattributed += 1;
                }
                for b in 0..N_BUCKETS {
                    if member[b] {
                        n_ext[b] += 1;
                        if tp {
                            n_tp[b] += 1;
                            d2[b] += d * d;
                        }
                    }
                    if member[b] && !tp {
                        runs[b] += 1;
                    } else {
                        close(b, &mut runs);
                    }
                }
            }
            for b in 0..N_BUCKETS {
                close(b, &mut runs);
            }
            let mut accs: Accs = Default::default();
            for b in 0..N_BUCKETS {
                accs[b] = Acc {
                    extracted: n_ext[b] as f64 * w,
                    tp: n_tp[b] as f64 * w,
                    tp_d2: d2[b] * w,
                    outside: pieces[b],
                    outside_len: n_out[b] as f64 * w,
                    ..Acc::default()
                };
            }
            (accs, unattributed as f64 * w)
        })
        .reduce(
            || (Default::default(), 0.0),
            |a, b| (merge(a.0, b.0), a.1 + b.1),
        );

    let accs = merge(ref_accs, ext_accs.0);
    let mut sides = Vec::new();
    for side in [Side::Left, Side::Right] {
        let bs = bucket_side(side);
        if accs[bs].is_empty() {
            continue;
        }
        let categories = (0..N_CAT_SLOTS)
            .filter(|c| !accs[bs + 1 + c].is_empty())
            .map(|c| CategoryMetrics {
                category: Category::REFERENCE.get(c).copied(),
                metrics: accs[bs + 1 + c].metrics(),
            })
            .collect();
        sides.push(SideMetrics {
            side,
            total: accs[bs].metrics(),
            categories,
        });
    }
    Ok(EvalReport {
        params: *params,
        total: accs[0].metrics(),
        sides,
        extracted_unattributed_m: ext_accs.1,
    })
}
