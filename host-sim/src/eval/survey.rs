//! The surveyor's checks beside §5 (docs/spec.md §5, "Curb geometry and classes"): the top
//! line's RMS against the reference top, the height along the edge against the reference
//! height, and the class of the extracted length against the reference category.

use super::matching::{nearest, sample_polyline, segment_tree, to_local_pair};
use super::{evaluate, EvalError, EvalParams, Metrics};
use crate::model::{Category, EdgeLine};
use rstar::primitives::GeomWithData;
use rstar::RTree;
use serde::Serialize;

/// Least reference curb height whose stretches the height check covers, metres.
pub const HEIGHT_MIN_M: f64 = 0.06;
/// Tolerance of the height check, metres.
pub const HEIGHT_TOL_M: f64 = 0.01;

/// The surveyor's checks of one extraction.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct SurveyReport {
    /// The §5 metrics of the top lines against the reference top lines (`None` when either
    /// side has no top lines).
    pub top: Option<Metrics>,
    /// Extracted toe length matched to reference curbs at least [`HEIGHT_MIN_M`] high,
    /// metres.
    pub height_checked_m: f64,
    /// Of that, the length whose height is within [`HEIGHT_TOL_M`] of the reference's.
    pub height_within_m: f64,
    /// Extracted length within the buffer of a reference line, with a class, metres.
    pub class_checked_m: f64,
    /// Of that, the length whose class is the reference's category.
    pub class_right_m: f64,
    /// Confusion table: `(reference category, extracted class, metres)`, every non-zero
    /// cell.
    pub confusion: Vec<(Category, Category, f64)>,
}

impl SurveyReport {
    /// Share of the checked height length within tolerance, percent.
    pub fn height_within_pct(&self) -> Option<f64> {
        (self.height_checked_m > 0.0).then(|| 100.0 * self.height_within_m / self.height_checked_m)
    }

    /// Share of the checked length with the right class, percent.
    pub fn class_right_pct(&self) -> Option<f64> {
        (self.class_checked_m > 0.0).then(|| 100.0 * self.class_right_m / self.class_checked_m)
    }

    /// The report as Markdown: the top line, the height check and the confusion table.
    pub fn to_markdown(&self) -> String {
        let pct = |v: Option<f64>| v.map_or("–".to_string(), |v| format!("{v:.1} %"));
        let mut s = String::from("\n## Curb geometry and classes\n\n");
        match &self.top {
            Some(m) => s.push_str(&format!(
                "- top of curb: RMS {} over {:.1} m matched (completeness {}, correctness {})\n",
                m.rms_mm.map_or("–".into(), |v| format!("{v:.1} mm")),
                m.tp_m,
                pct(m.completeness_pct),
                pct(m.correctness_pct)
            )),
            None => {
                s.push_str("- top of curb: – (no top lines in the reference or the extraction)\n")
            }
        }
        s.push_str(&format!(
            "- height within ±{:.0} mm on curbs ≥ {:.0} mm: {} of {:.1} m\n",
            HEIGHT_TOL_M * 1e3,
            HEIGHT_MIN_M * 1e3,
            pct(self.height_within_pct()),
            self.height_checked_m
        ));
        s.push_str(&format!(
            "- class right: {} of {:.1} m matched\n\n",
            pct(self.class_right_pct()),
            self.class_checked_m
        ));
        s.push_str("| reference \\ extracted (m) |");
        for c in Category::ALL {
            s.push_str(&format!(" {} |", c.as_str()));
        }
        s.push_str("\n|---|");
        s.push_str(&"---:|".repeat(Category::ALL.len()));
        s.push('\n');
        for r in Category::REFERENCE {
            s.push_str(&format!("| {} |", r.as_str()));
            for c in Category::ALL {
                let v: f64 = self
                    .confusion
                    .iter()
                    .filter(|x| x.0 == r && x.1 == c)
                    .map(|x| x.2)
                    .sum::<f64>()
                    + 0.0;
                s.push_str(&format!(" {v:.1} |"));
            }
            s.push('\n');
        }
        s
    }
}

/// The top lines of `lines` (those with detail) as lines of their own.
fn tops(lines: &[EdgeLine]) -> Vec<EdgeLine> {
    lines
        .iter()
        .filter_map(|l| {
            let d = l.detail.as_ref()?;
            (d.top.len() >= 2).then(|| EdgeLine {
                points: d.top.clone(),
                detail: None,
                ..l.clone()
            })
        })
        .collect()
}

/// Runs the surveyor's checks of `extracted` against `reference` (toe lines with their
/// detail: the reference's top and heights come from the simulator).
pub fn survey(
    reference: &[EdgeLine],
    extracted: &[EdgeLine],
    params: &EvalParams,
) -> Result<SurveyReport, EvalError> {
    let mut out = SurveyReport::default();
    let (rt, et) = (tops(reference), tops(extracted));
    if !rt.is_empty() && !et.is_empty() {
        out.top = Some(evaluate(&rt, &et, params)?.total);
    }
    let (_, ref_xy, ext_xy) = to_local_pair(reference, extracted)?;
    // Heights: the extracted vertex against the nearest reference vertex of the matched line.
    type V = GeomWithData<[f64; 2], (usize, usize)>;
    let verts: Vec<V> = ref_xy
        .iter()
        .enumerate()
        .filter(|(i, _)| reference[*i].detail.is_some())
        .flat_map(|(i, l)| {
            l.iter()
                .enumerate()
                .map(move |(k, p)| GeomWithData::new(*p, (i, k)))
        })
        .collect();
    let vtree: RTree<V> = RTree::bulk_load(verts);
    let ref_tree = segment_tree(&ref_xy);
    for (e, xy) in extracted.iter().zip(&ext_xy) {
        if let Some(d) = e.detail.as_ref() {
            for k in 0..xy.len().min(d.height_m.len()) {
                // The vertex stands for half of each segment beside it.
                let half = |j: usize| (xy[j][0] - xy[k][0]).hypot(xy[j][1] - xy[k][1]) / 2.0;
                let w = if k > 0 { half(k - 1) } else { 0.0 }
                    + if k + 1 < xy.len() { half(k + 1) } else { 0.0 };
                if !nearest(&ref_tree, xy[k]).is_some_and(|(_, dist)| dist <= params.buffer_m) {
                    continue;
                }
                let Some(v) = vtree.nearest_neighbor(&xy[k]) else {
                    continue;
                };
                let (i, j) = v.data;
                let Some(h_ref) = reference[i].detail.as_ref().and_then(|r| r.height_m.get(j))
                else {
                    continue;
                };
                if *h_ref >= HEIGHT_MIN_M {
                    out.height_checked_m += w;
                    if (d.height_m[k] - h_ref).abs() <= HEIGHT_TOL_M {
                        out.height_within_m += w;
                    }
                }
            }
        }
        // Classes, sampled as in §5.
        let Some(class) = e.category else { continue };
        let (samples, w) = sample_polyline(xy, params.sample_step_m);
        for p in samples {
            let Some((i, dist)) = nearest(&ref_tree, p) else {
                continue;
            };
            let Some(r) = reference[i].category.filter(|_| dist <= params.buffer_m) else {
                continue;
            };
            out.class_checked_m += w;
            if r == class {
                out.class_right_m += w;
            }
            match out.confusion.iter_mut().find(|c| c.0 == r && c.1 == class) {
                Some(c) => c.2 += w,
                None => out.confusion.push((r, class, w)),
            }
        }
    }
    out.confusion.sort_by_key(|c| (c.0, c.1));
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{CurbDetail, Side};

    fn line(x0: f64, x1: f64, y: f64, cat: Category, h: f64, top_dy: f64) -> EdgeLine {
        let points: Vec<[f64; 3]> = (0..=((x1 - x0) * 10.0) as usize)
            .map(|i| [x0 + i as f64 * 0.1, y, 0.0])
            .collect();
        let mut d = CurbDetail::measured(&points);
        d.top = points.iter().map(|p| [p[0], p[1] + top_dy, h]).collect();
        d.height_m = vec![h; points.len()];
        EdgeLine {
            points,
            side: Side::Left,
            category: Some(cat),
            method: None,
            curb_height_m: Some(h),
            detail: Some(Box::new(d)),
        }
    }

    #[test]
    fn top_rms_height_share_and_confusion() {
        let reference = vec![
            line(0.0, 10.0, 0.0, Category::Curb, 0.15, 0.015),
            line(10.0, 20.0, 0.0, Category::CurbCut, 0.02, 0.015),
        ];
        // Top 10 mm off the reference top; height 5 mm off on the first 5 m, 30 mm off on
        // the next 5 m; the curb cut called a curb on its first 4 m.
        let mut a = line(0.0, 5.0, 0.0, Category::Curb, 0.155, 0.025);
        a.method = Some("bend".into());
        let b = line(5.0, 14.0, 0.0, Category::Curb, 0.18, 0.025);
        let c = line(14.0, 20.0, 0.0, Category::CurbCut, 0.02, 0.025);
        let r = survey(&reference, &[a, b, c], &EvalParams::default()).unwrap();
        let top = r.top.clone().unwrap();
        assert!((top.rms_mm.unwrap() - 10.0).abs() < 0.5, "{top:?}");
        // Heights: only the reference curb (≥ 60 mm) counts: 10 m, half of it within.
        assert!((r.height_checked_m - 10.0).abs() < 0.15, "{r:?}");
        assert!((r.height_within_pct().unwrap() - 50.0).abs() < 2.0, "{r:?}");
        assert!((r.class_right_pct().unwrap() - 80.0).abs() < 1.0, "{r:?}");
        let wrong: f64 = r
            .confusion
            .iter()
            .filter(|c| c.0 == Category::CurbCut && c.1 == Category::Curb)
            .map(|c| c.2)
            .sum();
        assert!((wrong - 4.0).abs() < 0.1, "{r:?}");
        assert!(r.to_markdown().contains("| curb_cut |"));
    }
}
