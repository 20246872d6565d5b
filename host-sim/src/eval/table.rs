//! The evaluation as a table (laid out like Honma et al.'s Tables 2 and 3) and as JSON.

use super::{EvalReport, Metrics};
use crate::model::{Category, Side};

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
        Some(Category::Flush) => "Flush",
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
