//! Evaluation of extracted road edges against reference lines (docs/spec.md §5): the buffer method of
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

pub mod agreement;
mod matching;
mod metrics;
pub mod report;
pub mod survey;
mod table;
pub mod worst;

pub use agreement::{agreement, Agreement};
pub use metrics::{evaluate, CategoryMetrics, EvalReport, Metrics, SideMetrics};
pub use survey::{survey, SurveyReport};
pub use table::category_title;
pub use worst::{worst_place, WorstKind, WorstPlace};

use serde::Serialize;

/// Parameters of the evaluation; [`Default`] gives docs/spec.md §5's values.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct EvalParams {
    /// Buffer width (half-width of the band around a line), metres. Honma et al. used 50 mm.
    pub buffer_m: f64,
    /// Sampling interval along every line, metres. Honma et al. used 10 mm.
    pub sample_step_m: f64,
    /// A run of unmatched reference samples (or of outside extracted samples) counts as a
    /// gap only when longer than this, metres (docs/spec.md §5: 0.1 m; the papers give no value).
    pub min_gap_m: f64,
    /// An extracted sample farther than this from every reference line is attributed to no
    /// side or category and counts as FP in the total only, metres (docs/spec.md §5: 2 m).
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

/// Checks that every parameter is a positive finite number.
pub(crate) fn check_params(p: &EvalParams) -> Result<(), EvalError> {
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

#[cfg(test)]
mod tests;
