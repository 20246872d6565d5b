//! The features every format writes: per extracted stretch its toe line and, where the
//! curb beside it was surveyed, its top-of-curb line (`docs/output-formats.md`).

use crate::model::EdgeLine;

/// Which line of a stretch a feature is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LineKind {
    /// The toe (bottom of the curb face): the extracted edge itself.
    Toe,
    /// The top of curb (the arris) beside the toe.
    Top,
}

impl LineKind {
    /// The spelling in the files (`line` property, DXF layer prefix in upper case).
    pub fn as_str(self) -> &'static str {
        match self {
            LineKind::Toe => "toe",
            LineKind::Top => "top",
        }
    }
}

/// One feature: a line of stretch `edge` with the stretch's properties.
#[derive(Clone, Copy, Debug)]
pub struct Feature<'a> {
    /// Index of the stretch in the output (toe and top share it).
    pub edge: usize,
    /// Toe or top.
    pub kind: LineKind,
    /// The stretch (its properties).
    pub stretch: &'a EdgeLine,
    /// The line's vertices.
    pub points: &'a [[f64; 3]],
}

impl Feature<'_> {
    /// Horizontal length of this line, metres.
    pub fn length_m(&self) -> f64 {
        self.points
            .windows(2)
            .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
            .sum()
    }

    /// Whether the stretch was bridged; `None` where unknown (no survey detail).
    pub fn bridged(&self) -> Option<bool> {
        self.stretch.detail.as_ref().map(|d| d.bridged)
    }

    /// The scanners that contributed to a fused stretch, ascending, as `0;1`; `None` where
    /// the edges were not fused (one scanner, one pass).
    pub fn scanners(&self) -> Option<String> {
        self.stretch
            .detail
            .as_ref()
            .and_then(|d| joined(&d.scanners()))
    }

    /// The passes that contributed to a fused stretch, ascending, as `0;1`; `None` where
    /// the edges were not fused.
    pub fn passes(&self) -> Option<String> {
        self.stretch
            .detail
            .as_ref()
            .and_then(|d| joined(&d.passes()))
    }

    /// Observed candidates per metre of the stretch; `None` where unknown.
    pub fn support_per_m(&self) -> Option<f64> {
        self.stretch.detail.as_ref().map(|d| d.support_per_m)
    }
}

/// `ids` as `0;1`, `None` when empty.
fn joined(ids: &[u16]) -> Option<String> {
    (!ids.is_empty()).then(|| ids.iter().map(u16::to_string).collect::<Vec<_>>().join(";"))
}

/// The features of `edges` in file order: each stretch's toe, then its top where it has
/// one.
pub fn features(edges: &[EdgeLine]) -> Vec<Feature<'_>> {
    let mut out = Vec::with_capacity(2 * edges.len());
    for (k, e) in edges.iter().enumerate() {
        out.push(Feature {
            edge: k,
            kind: LineKind::Toe,
            stretch: e,
            points: &e.points,
        });
        if let Some(d) = e.detail.as_ref().filter(|d| d.top.len() >= 2) {
            out.push(Feature {
                edge: k,
                kind: LineKind::Top,
                stretch: e,
                points: &d.top,
            });
        }
    }
    out
}
