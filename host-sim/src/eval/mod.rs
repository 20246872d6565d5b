//! Evaluation of extracted road edges against reference lines (SPEC §5): the buffer method of
//! Heipke et al. (1997) as used by Honma et al. (§3, Eq. 9–12, Tables 2 and 3).
//!
//! # What is measured, exactly
//!
//! Every line is cut into pieces of at most [`EvalParams::sample_step_m`] (10 mm, as in Honma
//! et al. §3) of equal length; each piece is represented by its midpoint and carries its
//! length as weight, so the weights of a line add up to its 2D length exactly. Heights are
//! ignored (2D, horizontal).
//!
//! - An **extracted** sample whose distance to the nearest reference line is at most the
//!   buffer width ([`EvalParams::buffer_m`], 50 mm) is *TP*, otherwise *FP*.
//! - A **reference** sample whose distance to the nearest extracted line is at most the
//!   buffer width is *matched*, otherwise *FN*.
//!
//! From the lengths (sums of weights):
//!
//! - completeness = matched reference length / reference length (Eq. 9);
//! - correctness = TP extracted length / extracted length (Eq. 10);
//! - quality = TP / (TP + FP + FN) (Eq. 11) with **TP = TP extracted length**, FP = FP
//!   extracted length, FN = unmatched reference length. This is Heipke's own reading
//!   (Wiedemann et al. 1998: "length of matched extraction / (length of extracted data +
//!   length of unmatched reference)"): the numerator and FP are measured on the extraction,
//!   FN on the reference, so each length is counted once.
//! - RMS difference (Eq. 12) = root of the length-weighted mean of the squared distances of
//!   the TP extracted samples to the nearest reference line;
//! - gaps (Heipke): maximal runs of consecutive unmatched samples along one reference line
//!   whose length exceeds [`EvalParams::min_gap_m`] (0.1 m); their number and total length.
//!   A run ends at the end of its reference line (two reference features that meet are two
//!   lines);
//! - outside pieces (Honma et al.'s wording of "gaps": "the number of extracted lines outside
//!   the buffer" and "the extracted line length outside the buffer"): maximal runs of
//!   consecutive FP samples along one extracted line, with the same minimum length, so that
//!   a line wavering at the buffer's rim does not count as hundreds of pieces.
//!
//! # Totals, sides, categories
//!
//! Reference samples belong to their line's side and category. An extracted sample takes the
//! side and category of its nearest reference line; one farther than
//! [`EvalParams::max_attribution_m`] (2 m) from every reference line is FP in the total only
//! (it belongs to no side). Reference lines without a category are counted in their side's
//! total and in an "other" column. A run of outside samples is split where the attribution of
//! its samples changes, separately for each column.
//!
//! Both sets of lines go into R-trees of their segments (rstar), so a query costs about
//! log(segments); kilometres of lines at 10 mm sampling take about a second. Coordinates are
//! shifted to a local origin first so that squared distances keep their precision with large
//! CRS offsets.

pub mod report;

use crate::model::{Category, EdgeLine, Side};
use rayon::prelude::*;
use rstar::primitives::{GeomWithData, Line};
use rstar::{PointDistance, RTree};
use serde::Serialize;

/// Parameters of the evaluation; [`Default`] gives SPEC §5's values.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct EvalParams {
    /// Buffer width (half-width of the band around a line), metres. Honma et al. used 50 mm.
    pub buffer_m: f64,
    /// Sampling interval along every line, metres. Honma et al. used 10 mm.
    pub sample_step_m: f64,
    /// A run of unmatched reference samples (or of outside extracted samples) counts as a
    /// gap only when longer than this, metres (SPEC §5: 0.1 m; the papers give no value).
    pub min_gap_m: f64,
    /// An extracted sample farther than this from every reference line is attributed to no
    /// side or category and counts as FP in the total only, metres (SPEC §5: 2 m).
    pub max_attribution_m: f64,
}

impl Default for EvalParams {
    fn default() -> Self {
        Self {
            buffer_m: 0.05,
            sample_step_m: 0.01,
            min_gap_m: 0.1,
            max_attribution_m: 2.0,
        }
    }
}

/// Why an evaluation could not be made.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum EvalError {
    /// A parameter is not a positive finite number.
    #[error("evaluation parameter {name} must be a positive finite number, found {value}")]
    BadParam {
        /// The parameter's name.
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// A line has a coordinate that is NaN or infinite.
    #[error("{which} line {index} has a non-finite coordinate")]
    NonFinite {
        /// `reference` or `extracted`.
        which: &'static str,
        /// Index of the line in its slice.
        index: usize,
    },
}

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
// 1 + 6s + 1 + c = category c (0..4 as in Category::ALL, 4 = none).

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
        None => 4,
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

/// Samples a 2D polyline at the midpoints of `n` equal pieces of at most `step` each.
/// Returns the sample points and the common piece length (0 samples for a line of zero
/// length).
fn sample_polyline(points: &[[f64; 2]], step: f64) -> (Vec<[f64; 2]>, f64) {
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

type Seg = GeomWithData<Line<[f64; 2]>, usize>;

fn segment_tree(lines: &[Vec<[f64; 2]>]) -> RTree<Seg> {
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
fn nearest(tree: &RTree<Seg>, p: [f64; 2]) -> Option<(usize, f64)> {
    // rstar's dedicated nearest-neighbour search prunes better than the sorted iterator.
    tree.nearest_neighbor(&p)
        .map(|s| (s.data, s.distance_2(&p).sqrt()))
}

fn check_params(p: &EvalParams) -> Result<(), EvalError> {
    for (name, value) in [
        ("buffer_m", p.buffer_m),
        ("sample_step_m", p.sample_step_m),
        ("min_gap_m", p.min_gap_m),
        ("max_attribution_m", p.max_attribution_m),
    ] {
        if !(value.is_finite() && value > 0.0) {
            return Err(EvalError::BadParam { name, value });
        }
    }
    Ok(())
}

fn to_local(
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

/// Scores `extracted` against `reference` (SPEC §5; see the module docs for the exact
/// definitions). Only `side` and `category` of the reference lines are used; the extracted
/// lines' own side and category are ignored (each sample takes its nearest reference's).
pub fn evaluate(
    reference: &[EdgeLine],
    extracted: &[EdgeLine],
    params: &EvalParams,
) -> Result<EvalReport, EvalError> {
    check_params(params)?;
    let origin = reference
        .iter()
        .chain(extracted)
        .find_map(|l| l.points.first())
        .map(|p| [p[0], p[1]])
        .filter(|o| o[0].is_finite() && o[1].is_finite())
        .unwrap_or([0.0, 0.0]);
    let ref_xy = to_local(reference, origin, "reference")?;
    let ext_xy = to_local(extracted, origin, "extracted")?;
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
                category: Category::ALL.get(c).copied(),
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

fn side_title(s: Side) -> &'static str {
    match s {
        Side::Left => "Left",
        Side::Right => "Right",
    }
}

/// The column title of a category as in the paper's tables.
pub fn category_title(c: Option<Category>) -> &'static str {
    match c {
        Some(Category::Curb) => "Curb",
        Some(Category::CurbCut) => "Curb cut",
        Some(Category::Intersection) => "Intersection",
        Some(Category::BusBay) => "Bus bay",
        None => "Other",
    }
}

impl EvalReport {
    /// The columns in table order: (title, metrics).
    pub fn columns(&self) -> Vec<(String, &Metrics)> {
        let mut cols = vec![("Total".to_string(), &self.total)];
        for s in &self.sides {
            let t = side_title(s.side);
            cols.push((format!("{t}: Total"), &s.total));
            for c in &s.categories {
                cols.push((format!("{t}: {}", category_title(c.category)), &c.metrics));
            }
        }
        cols
    }

    /// A Markdown table laid out like Honma et al.'s Tables 2 and 3 (metrics as rows;
    /// columns Total, then per side its total and categories), followed by a note on the
    /// parameters and the unattributed extraction. Readable as plain text too.
    pub fn to_markdown(&self) -> String {
        let cols = self.columns();
        let pct = |v: Option<f64>| v.map_or("–".to_string(), |v| format!("{v:.1}"));
        type Row<'a> = (&'a str, Box<dyn Fn(&Metrics) -> String>);
        let rows: Vec<Row> = vec![
            (
                "Completeness [%]",
                Box::new(move |m| pct(m.completeness_pct)),
            ),
            ("Correctness [%]", Box::new(move |m| pct(m.correctness_pct))),
            ("Quality [%]", Box::new(move |m| pct(m.quality_pct))),
            ("RMS difference [mm]", Box::new(move |m| pct(m.rms_mm))),
            ("Number of gaps (Heipke)", Box::new(|m| m.gaps.to_string())),
            (
                "Total gap length [m]",
                Box::new(|m| format!("{:.2}", m.gap_length_m)),
            ),
            (
                "Extracted pieces outside buffer (Honma)",
                Box::new(|m| m.outside_pieces.to_string()),
            ),
            (
                "Their length [m]",
                Box::new(|m| format!("{:.2}", m.outside_length_m)),
            ),
            (
                "Reference length [m]",
                Box::new(|m| format!("{:.2}", m.reference_m)),
            ),
            (
                "Extracted length [m]",
                Box::new(|m| format!("{:.2}", m.extracted_m)),
            ),
        ];
        let mut cells: Vec<Vec<String>> = Vec::new();
        let mut header = vec!["Index".to_string()];
        header.extend(cols.iter().map(|c| c.0.clone()));
        cells.push(header);
        for (name, f) in &rows {
            let mut r = vec![name.to_string()];
            r.extend(cols.iter().map(|c| f(c.1)));
            cells.push(r);
        }
        let widths: Vec<usize> = (0..cells[0].len())
            .map(|j| {
                cells
                    .iter()
                    .map(|r| r[j].chars().count())
                    .max()
                    .unwrap_or(0)
            })
            .collect();
        let fmt_row = |r: &[String]| {
            let mut s = String::from("|");
            for (j, c) in r.iter().enumerate() {
                let pad = widths[j] - c.chars().count();
                if j == 0 {
                    s.push_str(&format!(" {c}{} |", " ".repeat(pad)));
                } else {
                    s.push_str(&format!(" {}{c} |", " ".repeat(pad)));
                }
            }
            s.push('\n');
            s
        };
        let mut out = fmt_row(&cells[0]);
        out.push('|');
        for (j, w) in widths.iter().enumerate() {
            if j == 0 {
                out.push_str(&format!(":{}|", "-".repeat(w + 1)));
            } else {
                out.push_str(&format!("{}:|", "-".repeat(w + 1)));
            }
        }
        out.push('\n');
        for r in &cells[1..] {
            out.push_str(&fmt_row(r));
        }
        let p = &self.params;
        out.push_str(&format!(
            "\nBuffer {:.0} mm, samples every {:.0} mm, gaps longer than {:.2} m. \
             Extracted length farther than {:.1} m from every reference line \
             (FP in the total only): {:.2} m.\n",
            p.buffer_m * 1000.0,
            p.sample_step_m * 1000.0,
            p.min_gap_m,
            p.max_attribution_m,
            self.extracted_unattributed_m
        ));
        out
    }

    /// The report as pretty-printed JSON.
    pub fn to_json(&self) -> String {
        // Serialising plain numbers, strings and options cannot fail.
        serde_json::to_string_pretty(self).unwrap_or_else(|e| format!("{{\"error\":\"{e}\"}}"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // Large CRS offsets, as real data has: the local origin must keep precision.
    const X0: f64 = 500_000.0;
    const Y0: f64 = 4_000_000.0;

    fn line(pts: &[(f64, f64)], side: Side, cat: Option<Category>) -> EdgeLine {
        EdgeLine {
            points: pts.iter().map(|&(x, y)| [X0 + x, Y0 + y, 10.0]).collect(),
            side,
            category: cat,
            method: None,
            curb_height_m: None,
        }
    }

    fn curb(pts: &[(f64, f64)]) -> EdgeLine {
        line(pts, Side::Left, Some(Category::Curb))
    }

    fn eval(r: &[EdgeLine], e: &[EdgeLine]) -> EvalReport {
        evaluate(r, e, &EvalParams::default()).unwrap()
    }

    fn close(a: Option<f64>, b: f64, tol: f64) -> bool {
        a.is_some_and(|a| (a - b).abs() <= tol)
    }

    #[test]
    fn sampling_weights_add_up_to_the_length() {
        let (s, w) = sample_polyline(&[[0.0, 0.0], [3.0, 4.0], [3.0, 4.003]], 0.01);
        assert_eq!(s.len(), 501); // 5.003 m in pieces of at most 10 mm
        assert!((w * s.len() as f64 - 5.003).abs() < 1e-12);
        // First sample at half a piece along the first segment (direction 0.6, 0.8).
        assert!((s[0][0] - 0.6 * w / 2.0).abs() < 1e-12);
        let (s, _) = sample_polyline(&[[0.0, 0.0], [1.0, 0.0]], 0.01);
        assert_eq!(s.len(), 100); // exactly 100 steps stays 100
        assert!(sample_polyline(&[[1.0, 1.0], [1.0, 1.0]], 0.01)
            .0
            .is_empty());
    }

    #[test]
    fn identical_lines_score_100_percent_and_rms_zero() {
        let r = curb(&[(0.0, 0.0), (10.0, 0.0), (20.0, 5.0)]);
        let rep = eval(std::slice::from_ref(&r), std::slice::from_ref(&r));
        let t = &rep.total;
        assert!(close(t.completeness_pct, 100.0, 1e-9));
        assert!(close(t.correctness_pct, 100.0, 1e-9));
        assert!(close(t.quality_pct, 100.0, 1e-9));
        assert!(close(t.rms_mm, 0.0, 1e-6));
        assert_eq!((t.gaps, t.outside_pieces), (0, 0));
        let len = 10.0 + 125f64.sqrt();
        assert!((t.reference_m - len).abs() < 1e-9 && (t.extracted_m - len).abs() < 1e-9);
    }

    #[test]
    fn offset_30_mm_is_inside_the_buffer_with_rms_30_mm() {
        let r = curb(&[(0.0, 0.0), (10.0, 0.0)]);
        let e = curb(&[(0.0, 0.03), (10.0, 0.03)]);
        let t = eval(&[r], &[e]).total;
        assert!(close(t.completeness_pct, 100.0, 1e-9));
        assert!(close(t.correctness_pct, 100.0, 1e-9));
        assert!(close(t.quality_pct, 100.0, 1e-9));
        assert!(close(t.rms_mm, 30.0, 1e-6), "{:?}", t.rms_mm);
    }

    #[test]
    fn offset_80_mm_is_outside_the_buffer() {
        let r = curb(&[(0.0, 0.0), (10.0, 0.0)]);
        let e = curb(&[(0.0, -0.08), (10.0, -0.08)]);
        let t = eval(&[r], &[e]).total;
        assert!(close(t.completeness_pct, 0.0, 1e-9));
        assert!(close(t.correctness_pct, 0.0, 1e-9));
        assert!(close(t.quality_pct, 0.0, 1e-9));
        assert_eq!(t.rms_mm, None);
        // The whole reference is one gap, the whole extraction one outside piece.
        assert_eq!((t.gaps, t.outside_pieces), (1, 1));
        assert!((t.gap_length_m - 10.0).abs() < 1e-9);
        assert!((t.outside_length_m - 10.0).abs() < 1e-9);
    }

    #[test]
    fn half_the_length_gives_half_completeness_and_full_correctness() {
        let r = curb(&[(0.0, 0.0), (10.0, 0.0)]);
        let e = curb(&[(0.0, 0.0), (5.0, 0.0)]);
        let t = eval(&[r], &[e]).total;
        // The buffer reaches 50 mm past the extracted end: 5.05 m of 10 m are matched.
        assert!(
            close(t.completeness_pct, 50.5, 1e-6),
            "{:?}",
            t.completeness_pct
        );
        assert!(close(t.correctness_pct, 100.0, 1e-9));
        // Quality = TP / (extracted + FN) = 5 / (5 + 4.95).
        assert!(
            close(t.quality_pct, 500.0 / 9.95, 1e-6),
            "{:?}",
            t.quality_pct
        );
        assert_eq!(t.gaps, 1);
        assert!((t.gap_length_m - 4.95).abs() < 1e-6);
    }

    #[test]
    fn a_spurious_line_lowers_correctness_by_its_share() {
        let r = curb(&[(0.0, 0.0), (10.0, 0.0)]);
        let good = curb(&[(0.0, 0.0), (10.0, 0.0)]);
        // 2.5 m long, 1 m off the reference: attributed to the left curb, FP.
        let bad = curb(&[(2.0, 1.0), (4.5, 1.0)]);
        let rep = eval(&[r], &[good, bad]);
        for m in [
            &rep.total,
            &rep.sides[0].total,
            &rep.sides[0].categories[0].metrics,
        ] {
            assert!(
                close(m.correctness_pct, 80.0, 1e-6),
                "{:?}",
                m.correctness_pct
            );
            assert!(close(m.completeness_pct, 100.0, 1e-9));
            assert!(close(m.quality_pct, 80.0, 1e-6));
            assert_eq!(m.outside_pieces, 1);
            assert!((m.outside_length_m - 2.5).abs() < 1e-9);
        }
        assert_eq!(rep.extracted_unattributed_m, 0.0);
    }

    #[test]
    fn lines_farther_than_2_m_count_as_fp_in_the_total_only() {
        let r = curb(&[(0.0, 0.0), (10.0, 0.0)]);
        let good = curb(&[(0.0, 0.0), (10.0, 0.0)]);
        let far = curb(&[(0.0, 2.5), (10.0, 2.5)]);
        let rep = eval(&[r], &[good, far]);
        assert!(close(rep.total.correctness_pct, 50.0, 1e-6));
        assert!((rep.extracted_unattributed_m - 10.0).abs() < 1e-9);
        assert_eq!(rep.total.outside_pieces, 1);
        assert_eq!(rep.sides.len(), 1);
        let left = &rep.sides[0].total;
        assert!(close(left.correctness_pct, 100.0, 1e-9));
        assert_eq!(left.outside_pieces, 0);
        assert!((left.extracted_m - 10.0).abs() < 1e-9);
    }

    #[test]
    fn samples_take_side_and_category_of_the_nearest_reference() {
        // Left: a curb (0–10 m) then a curb cut (10–14 m) along y = 0.
        // Right: a curb along y = -8 from 0 to 10 m, and a bus bay from 10 to 20 m.
        let refs = vec![
            line(&[(0.0, 0.0), (10.0, 0.0)], Side::Left, Some(Category::Curb)),
            line(
                &[(10.0, 0.0), (14.0, 0.0)],
                Side::Left,
                Some(Category::CurbCut),
            ),
            line(
                &[(0.0, -8.0), (10.0, -8.0)],
                Side::Right,
                Some(Category::Curb),
            ),
            line(
                &[(10.0, -8.0), (20.0, -9.0)],
                Side::Right,
                Some(Category::BusBay),
            ),
        ];
        // One extracted line along the whole left edge, labelled "right" on purpose: its
        // own side must be ignored. Right side: only the curb, 20 mm off.
        let exts = vec![
            line(&[(0.0, 0.0), (14.0, 0.0)], Side::Right, None),
            line(&[(0.0, -7.98), (10.0, -7.98)], Side::Left, None),
        ];
        let rep = eval(&refs, &exts);
        assert_eq!(rep.sides.len(), 2);
        let left = &rep.sides[0];
        assert_eq!(left.side, Side::Left);
        let cats: Vec<_> = left.categories.iter().map(|c| c.category).collect();
        assert_eq!(cats, [Some(Category::Curb), Some(Category::CurbCut)]);
        assert!((left.categories[0].metrics.extracted_m - 10.0).abs() < 1e-6);
        assert!((left.categories[1].metrics.extracted_m - 4.0).abs() < 1e-6);
        assert!(close(left.total.completeness_pct, 100.0, 1e-9));
        let right = &rep.sides[1];
        let cats: Vec<_> = right.categories.iter().map(|c| c.category).collect();
        assert_eq!(cats, [Some(Category::Curb), Some(Category::BusBay)]);
        let curb_r = &right.categories[0].metrics;
        assert!(close(curb_r.completeness_pct, 100.0, 1e-9));
        assert!(close(curb_r.rms_mm, 20.0, 1e-6));
        let bay = &right.categories[1].metrics;
        // The buffer of the curb's extracted end reaches 50 mm into the bus bay (almost
        // along it): ~0.05 m of its 10.05 m are matched.
        // Solving |bay(s) − (10, −7.98)| = 0.05 gives s = 0.044 m of 10.05 m: 0.44 %, to
        // within one 10 mm sample (0.1 %).
        assert!(
            close(bay.completeness_pct, 0.438, 0.1),
            "{:?}",
            bay.completeness_pct
        );
        assert_eq!(bay.extracted_m, 0.0);
        assert_eq!(bay.correctness_pct, None);
        assert_eq!(bay.gaps, 1);
        // Total RMS: 14 m at 0 mm and 10 m at 20 mm.
        assert!(close(
            rep.total.rms_mm,
            (10.0 * 400.0 / 24.0f64).sqrt(),
            1e-6
        ));
        // The sides' columns add up to the total.
        let sum: f64 = rep.sides.iter().map(|s| s.total.reference_m).sum();
        assert!((sum - rep.total.reference_m).abs() < 1e-9);
    }

    #[test]
    fn gaps_shorter_than_a_decimetre_do_not_count() {
        let r = curb(&[(0.0, 0.0), (10.0, 0.0)]);
        // Holes of 0.5 m and 0.15 m in the extraction: the buffer shortens each by 2 × 50 mm,
        // leaving unmatched runs of 0.40 m (a gap) and 0.05 m (not a gap).
        let e = vec![
            curb(&[(0.0, 0.0), (4.0, 0.0)]),
            curb(&[(4.5, 0.0), (7.0, 0.0)]),
            curb(&[(7.15, 0.0), (10.0, 0.0)]),
        ];
        let t = eval(&[r], &e).total;
        assert_eq!(t.gaps, 1);
        assert!((t.gap_length_m - 0.40).abs() < 1e-6, "{}", t.gap_length_m);
        assert!((t.fn_m - 0.45).abs() < 1e-6, "{}", t.fn_m);
    }

    #[test]
    fn an_extracted_line_leaving_the_buffer_is_one_outside_piece() {
        let r = curb(&[(0.0, 0.0), (10.0, 0.0)]);
        // Leaves the buffer between x = 4 and x = 6 at 0.2 m.
        let e = curb(&[
            (0.0, 0.0),
            (4.0, 0.0),
            (4.0, 0.2),
            (6.0, 0.2),
            (6.0, 0.0),
            (10.0, 0.0),
        ]);
        let t = eval(&[r], &[e]).total;
        assert_eq!(t.outside_pieces, 1);
        // 2 m at 0.2 m plus 2 × 0.15 m of the vertical legs beyond 50 mm.
        assert!(
            (t.outside_length_m - 2.3).abs() < 0.011,
            "{}",
            t.outside_length_m
        );
        // The reference between the legs is more than 50 mm from the extraction except
        // within 50 mm of each leg: 1.9 m unmatched, one gap.
        assert!(
            close(t.completeness_pct, 81.0, 1e-6),
            "{:?}",
            t.completeness_pct
        );
        assert_eq!(t.gaps, 1);
        assert!((t.gap_length_m - 1.9).abs() < 1e-6);
    }

    #[test]
    fn empty_inputs_and_bad_parameters() {
        let r = curb(&[(0.0, 0.0), (10.0, 0.0)]);
        let t = eval(std::slice::from_ref(&r), &[]).total;
        assert!(close(t.completeness_pct, 0.0, 1e-9));
        assert_eq!(t.correctness_pct, None);
        let rep = eval(&[], std::slice::from_ref(&r));
        assert!(close(rep.total.correctness_pct, 0.0, 1e-9));
        assert!(rep.sides.is_empty());
        let bad = EvalParams {
            buffer_m: 0.0,
            ..Default::default()
        };
        assert!(matches!(
            evaluate(std::slice::from_ref(&r), std::slice::from_ref(&r), &bad),
            Err(EvalError::BadParam {
                name: "buffer_m",
                ..
            })
        ));
        let mut nan = r.clone();
        nan.points[1][1] = f64::NAN;
        assert_eq!(
            evaluate(&[r], &[nan], &EvalParams::default()),
            Err(EvalError::NonFinite {
                which: "extracted",
                index: 0
            })
        );
    }

    #[test]
    fn markdown_table_has_the_papers_rows_and_columns() {
        let refs = vec![
            line(&[(0.0, 0.0), (10.0, 0.0)], Side::Left, Some(Category::Curb)),
            line(
                &[(0.0, -8.0), (10.0, -8.0)],
                Side::Right,
                Some(Category::Intersection),
            ),
        ];
        let rep = eval(&refs, &refs[..1]);
        let md = rep.to_markdown();
        let header = md.lines().next().unwrap();
        assert!(header.contains("Total") && header.contains("Left: Curb"));
        assert!(header.contains("Right: Intersection"), "{md}");
        assert!(!header.contains("Bus bay"));
        let comp = md
            .lines()
            .find(|l| l.starts_with("| Completeness"))
            .unwrap();
        let cells: Vec<&str> = comp.split('|').map(str::trim).collect();
        // Total 50 %, Left total 100 %, Left curb 100 %, Right total 0 %, Right inter. 0 %.
        assert_eq!(&cells[2..7], &["50.0", "100.0", "100.0", "0.0", "0.0"]);
        let corr = md.lines().find(|l| l.starts_with("| Correctness")).unwrap();
        assert!(corr.contains('–')); // no extraction on the right
        let json: serde_json::Value = serde_json::from_str(&rep.to_json()).unwrap();
        assert_eq!(json["total"]["completeness_pct"], 50.0);
        assert_eq!(json["sides"][1]["side"], "right");
        assert_eq!(
            json["sides"][1]["categories"][0]["category"],
            "intersection"
        );
    }

    #[test]
    fn kilometres_of_lines_are_fast() {
        // 2 km of reference and extraction (200 000 samples each) in a wiggly line.
        let pts: Vec<(f64, f64)> = (0..=2000)
            .map(|i| (i as f64, (i as f64 * 0.01).sin() * 5.0))
            .collect();
        let r = curb(&pts);
        let start = std::time::Instant::now();
        let t = eval(std::slice::from_ref(&r), std::slice::from_ref(&r)).total;
        assert!(close(t.completeness_pct, 100.0, 1e-9));
        assert!(start.elapsed().as_secs_f64() < 20.0);
    }
}
