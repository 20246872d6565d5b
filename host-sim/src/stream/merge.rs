//! Merge: edge pieces cut at section boundaries joined into one edge per curb.
//!
//! A piece that lies wholly inside its section is final as it is. A piece cut at the end
//! of its section waits for the next section: a piece of the same side and category whose
//! first vertex lies within the stitch distance of its last vertex continues it (the two
//! were tracked over the same margin, so they meet within a vertex spacing). A waiting
//! piece that nothing continues is closed. Pieces carry the height step per vertex, so a
//! joined edge's curb height is the median over all of it, as in a whole-file run. The
//! short-edge filter of §2.7 runs again on joined edges: a stub left at a boundary is as
//! short as it looks. Filter 4 (an edge whose median height step is taller than any curb,
//! `bend::postfilter::tall_step`) runs here on every closed edge, on that whole median.

use crate::bend::median;
use crate::bend::postfilter::tall_step;
use crate::model::EdgeLine;

/// An edge piece from one section.
#[derive(Clone, Debug)]
pub struct Piece {
    line: EdgeLine,
    steps: Vec<Option<f64>>,
    open_start: bool,
    open_end: bool,
    cut: bool,
}

impl Piece {
    /// An edge wholly inside its section.
    pub fn whole(line: EdgeLine, steps: Vec<Option<f64>>) -> Self {
        Self {
            line,
            steps,
            open_start: false,
            open_end: false,
            cut: false,
        }
    }

    /// Part of an edge, cut at its start and/or end by the section's bounds.
    pub fn cut(line: EdgeLine, steps: Vec<Option<f64>>, open_start: bool, open_end: bool) -> Self {
        Self {
            line,
            steps,
            open_start,
            open_end,
            cut: true,
        }
    }

    /// The piece's line.
    pub fn line(&self) -> &EdgeLine {
        &self.line
    }

    /// The height step at each vertex, where measured.
    pub fn steps(&self) -> &[Option<f64>] {
        &self.steps
    }

    /// Whether the piece is cut at its start, at its end, and at all ([`Piece::cut`]) —
    /// with the line and steps, what rebuilds it elsewhere.
    pub fn ends(&self) -> (bool, bool, bool) {
        (self.open_start, self.open_end, self.cut)
    }
}

/// Pieces waiting for the next section.
pub struct Merge {
    stitch_m: f64,
    min_length_m: f64,
    waiting: Vec<Piece>,
}

impl Merge {
    /// A merge joining ends within `stitch_m` and dropping joined edges shorter than
    /// `min_length_m`.
    pub fn new(stitch_m: f64, min_length_m: f64) -> Self {
        Self {
            stitch_m,
            min_length_m,
            waiting: Vec::new(),
        }
    }

    /// Takes the pieces of the next section; returns the edges closed by it.
    pub fn push(&mut self, pieces: Vec<Piece>, _s0: f64, _s1: f64) -> Vec<EdgeLine> {
        let mut closed = Vec::new();
        let waiting = std::mem::take(&mut self.waiting);
        let mut used = vec![false; waiting.len()];
        for p in pieces {
            let mut p = p;
            if p.open_start {
                let first = p.line.points[0];
                let best = waiting
                    .iter()
                    .enumerate()
                    .filter(|(i, w)| {
                        !used[*i]
                            && w.open_end
                            && w.line.side == p.line.side
                            && w.line.category == p.line.category
                    })
                    .map(|(i, w)| {
                        let l = w.line.points[w.line.points.len() - 1];
                        (i, (l[0] - first[0]).hypot(l[1] - first[1]))
                    })
                    .filter(|&(_, d)| d <= self.stitch_m)
                    .min_by(|a, b| a.1.total_cmp(&b.1));
                if let Some((i, _)) = best {
                    used[i] = true;
                    let w = &waiting[i];
                    p = join(w, &p);
                }
            }
            if p.open_end {
                self.waiting.push(p);
            } else {
                closed.extend(self.close(p));
            }
        }
        for (w, u) in waiting.into_iter().zip(used) {
            if !u {
                closed.extend(self.close(w));
            }
        }
        closed
    }

    /// Closes every waiting piece (end of the stream).
    pub fn close_all(&mut self) -> Vec<EdgeLine> {
        let w = std::mem::take(&mut self.waiting);
        w.into_iter().filter_map(|p| self.close(p)).collect()
    }

    fn close(&self, p: Piece) -> Option<EdgeLine> {
        if !p.cut {
            return (!tall_step(&p.line)).then_some(p.line);
        }
        if p.line.length_m() < self.min_length_m {
            return None;
        }
        let mut st: Vec<f64> = p.steps.iter().flatten().copied().collect();
        let line = EdgeLine {
            curb_height_m: median(&mut st),
            ..p.line
        };
        (!tall_step(&line)).then_some(line)
    }
}

/// `a` continued by `b`: the vertices and height samples of both.
fn join(a: &Piece, b: &Piece) -> Piece {
    let mut steps = a.steps.clone();
    steps.extend_from_slice(&b.steps);
    Piece {
        line: a.line.joined(&b.line),
        steps,
        open_start: a.open_start,
        open_end: b.open_end,
        cut: true,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Side;

    fn piece(x0: f64, x1: f64, side: Side, h: f64, open: (bool, bool)) -> Piece {
        Piece::cut(line(x0, x1, side), vec![Some(h); 2], open.0, open.1)
    }

    fn line(x0: f64, x1: f64, side: Side) -> EdgeLine {
        EdgeLine {
            points: vec![[x0, 0.0, 0.0], [x1, 0.0, 0.0]],
            side,
            category: None,
            method: None,
            curb_height_m: Some(0.1),
            detail: None,
        }
    }

    #[test]
    fn pieces_meeting_at_a_boundary_become_one_edge_and_others_stay_apart() {
        let mut m = Merge::new(0.3, 3.0);
        let a = piece(0.0, 9.9, Side::Left, 0.10, (false, true));
        let r = piece(0.0, 9.9, Side::Right, 0.10, (false, true));
        assert!(m.push(vec![a, r], 0.0, 10.0).is_empty());
        // The left one continues 0.2 m on; the right one's continuation is 2 m away.
        let b = piece(10.1, 20.0, Side::Left, 0.14, (true, false));
        let c = piece(12.0, 12.5, Side::Right, 0.10, (true, false));
        let out = m.push(vec![b, c], 10.0, 20.0);
        assert_eq!(out.len(), 2, "{out:?}");
        let left = out.iter().find(|e| e.side == Side::Left).unwrap();
        assert_eq!(left.points.len(), 4);
        assert!((left.length_m() - 20.0).abs() < 1e-9);
        // The median of the four samples 0.10, 0.10, 0.14, 0.14.
        assert!((left.curb_height_m.unwrap() - 0.12).abs() < 1e-12);
        // The right stub of 0.5 m is under the minimum length and dropped; the 9.9 m
        // right piece is closed on its own.
        let right = out.iter().find(|e| e.side == Side::Right).unwrap();
        assert!((right.length_m() - 9.9).abs() < 1e-9);
        assert!(m.close_all().is_empty());
    }
}
