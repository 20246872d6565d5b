//! Which stretches are tracked already (Honma et al. §2.7): every accepted track's segments,
//! bucketed in a grid, so that a seed on a tracked curb starts nothing and a track that runs
//! into another stops there and is joined to it.

use std::collections::HashMap;

/// Where a one-directional track ended on another track.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Join {
    pub(super) track: usize,
    pub(super) point: u32,
}

/// A track segment: its two end vertices (id and horizontal position) and the track it
/// belongs to.
type Segment = ((u32, [f64; 2]), (u32, [f64; 2]), usize);

/// Segments of accepted tracks, bucketed for the join test: a point is on a track when it
/// lies within the join distance of one of its segments (vertices alone would miss a seed
/// on a scanline the track stepped over).
pub(super) struct Claims {
    join_m: f64,
    cells: HashMap<(i64, i64), Vec<Segment>>,
    owner: HashMap<u32, usize>,
}

impl Claims {
    pub(super) fn new(join_m: f64) -> Self {
        Self {
            join_m: join_m.max(1e-3),
            cells: HashMap::new(),
            owner: HashMap::new(),
        }
    }

    fn cell(&self, x: f64, y: f64) -> (i64, i64) {
        (
            (x / self.join_m).floor() as i64,
            (y / self.join_m).floor() as i64,
        )
    }

    /// Registers a track's polyline (a single vertex is a segment of length zero).
    pub(super) fn add_track(&mut self, points: &[u32], xyz: &[[f64; 3]], track: usize) {
        for &p in points {
            self.owner.insert(p, track);
        }
        let v: Vec<(u32, [f64; 2])> = points
            .iter()
            .zip(xyz)
            .map(|(&p, q)| (p, [q[0], q[1]]))
            .collect();
        let segs: Vec<_> = if v.len() == 1 {
            vec![(v[0], v[0])]
        } else {
            v.windows(2).map(|w| (w[0], w[1])).collect()
        };
        for (a, b) in segs {
            let r = self.join_m;
            let (x0, y0) = (a.1[0].min(b.1[0]) - r, a.1[1].min(b.1[1]) - r);
            let (x1, y1) = (a.1[0].max(b.1[0]) + r, a.1[1].max(b.1[1]) + r);
            let (c0, c1) = (self.cell(x0, y0), self.cell(x1, y1));
            // A segment longer than a few hundred cells is a broken input; skip the rest.
            let cells = (c1.0 - c0.0 + 1).saturating_mul(c1.1 - c0.1 + 1);
            if cells > 10_000 {
                continue;
            }
            for cy in c0.1..=c1.1 {
                for cx in c0.0..=c1.0 {
                    self.cells.entry((cx, cy)).or_default().push((a, b, track));
                }
            }
        }
    }

    /// The nearest segment of a track other than `own` within the join distance of vertex
    /// `id` at `(px, py)` (ties: lower track, then earlier registration); the join point is
    /// the segment's nearer end.
    pub(super) fn near(&self, id: u32, px: f64, py: f64, own: usize) -> Option<Join> {
        if let Some(&t) = self.owner.get(&id) {
            if t != own {
                return Some(Join {
                    track: t,
                    point: id,
                });
            }
        }
        let v = self.cells.get(&self.cell(px, py))?;
        let mut best: Option<(f64, usize, u32)> = None;
        for &(a, b, t) in v {
            if t == own {
                continue;
            }
            let (ax, ay) = (a.1[0], a.1[1]);
            let (dx, dy) = (b.1[0] - ax, b.1[1] - ay);
            let l2 = dx * dx + dy * dy;
            let u = if l2 > 0.0 {
                (((px - ax) * dx + (py - ay) * dy) / l2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let d = (ax + u * dx - px).hypot(ay + u * dy - py);
            let end = if u < 0.5 { a.0 } else { b.0 };
            if d <= self.join_m && best.is_none_or(|(bd, bt, _)| (d, t) < (bd, bt)) {
                best = Some((d, t, end));
            }
        }
        best.map(|(_, t, p)| Join { track: t, point: p })
    }
}
