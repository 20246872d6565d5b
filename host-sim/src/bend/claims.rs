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

/// Side of a bucket of the grid, metres, when the join distance is shorter: a bucket holds
/// the segments whose box (grown by the join distance) it touches, so buckets as small as
/// the join distance list a segment a few dozen times over.
const BUCKET_M: f64 = 0.5;

/// Most cells of the join distance's size a segment's grown box may cover; a longer
/// segment is a broken input and claims nothing.
const MAX_JOIN_CELLS: i64 = 10_000;

/// Segments of accepted tracks, bucketed for the join test: a point is on a track when it
/// lies within the join distance of one of its segments (vertices alone would miss a seed
/// on a scanline the track stepped over).
pub(super) struct Claims {
    join_m: f64,
    bucket_m: f64,
    segments: Vec<Segment>,
    /// The segments (indices into `segments`, in the order registered) whose grown box
    /// touches each bucket.
    buckets: HashMap<(i64, i64), Vec<u32>>,
    owner: HashMap<u32, usize>,
}

impl Claims {
    pub(super) fn new(join_m: f64) -> Self {
        let join_m = join_m.max(1e-3);
        Self {
            join_m,
            bucket_m: join_m.max(BUCKET_M),
            segments: Vec::new(),
            buckets: HashMap::new(),
            owner: HashMap::new(),
        }
    }

    fn cell(x: f64, y: f64, side_m: f64) -> (i64, i64) {
        ((x / side_m).floor() as i64, (y / side_m).floor() as i64)
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
            let (j0, j1) = (Self::cell(x0, y0, r), Self::cell(x1, y1, r));
            let cells = (j1.0.saturating_sub(j0.0).saturating_add(1))
                .saturating_mul(j1.1.saturating_sub(j0.1).saturating_add(1));
            if cells > MAX_JOIN_CELLS {
                continue;
            }
            let Ok(k) = u32::try_from(self.segments.len()) else {
                return;
            };
            self.segments.push((a, b, track));
            let (c0, c1) = (
                Self::cell(x0, y0, self.bucket_m),
                Self::cell(x1, y1, self.bucket_m),
            );
            for cy in c0.1..=c1.1 {
                for cx in c0.0..=c1.0 {
                    self.buckets.entry((cx, cy)).or_default().push(k);
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
        let v = self.buckets.get(&Self::cell(px, py, self.bucket_m))?;
        self.nearest(v.iter().map(|&k| &self.segments[k as usize]), px, py, own)
    }

    /// The nearest of `segments` (in the order given) of a track other than `own` within
    /// the join distance of `(px, py)`, ties to the lower track, then the earlier segment.
    fn nearest<'s>(
        &self,
        segments: impl Iterator<Item = &'s Segment>,
        px: f64,
        py: f64,
        own: usize,
    ) -> Option<Join> {
        let mut best: Option<(f64, usize, u32)> = None;
        for &(a, b, t) in segments {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The nearest segment within the join distance over every registered segment, in
    /// the order registered: what the buckets must find.
    fn near_by_scan(c: &Claims, px: f64, py: f64, own: usize) -> Option<Join> {
        c.nearest(c.segments.iter(), px, py, own)
    }

    #[test]
    fn buckets_find_the_nearest_segment_of_a_scan_over_all() {
        let mut c = Claims::new(0.05);
        // Three tracks of short steps that cross, touch and run side by side 4 cm apart,
        // the second along the first; ids 1000 and up are never asked for as vertices.
        let mut id = 1000u32;
        for (track, (x0, y0, ux, uy)) in [
            (0.0, 0.0, 0.13, 0.02),
            (0.0, 0.04, 0.13, 0.02),
            (1.0, -1.0, -0.03, 0.11),
        ]
        .into_iter()
        .enumerate()
        {
            let n = 40;
            let pts: Vec<u32> = (0..n).map(|k| id + k).collect();
            let xyz: Vec<[f64; 3]> = (0..n)
                .map(|k| [x0 + ux * f64::from(k), y0 + uy * f64::from(k), 0.0])
                .collect();
            id += n;
            c.add_track(&pts, &xyz, track);
        }
        // A lone vertex, and a diagonal segment too long to claim anything.
        c.add_track(&[2000], &[[2.0, 2.0, 0.0]], 3);
        c.add_track(&[2001, 2002], &[[-5.0, -5.0, 0.0], [5.0, 5.0, 0.0]], 4);
        assert_eq!(c.segments.len(), 39 + 39 + 39 + 1);
        let (mut hits, mut asked) = (0, 0);
        for i in -60..200 {
            for j in -120..120 {
                let (px, py) = (0.0237 * f64::from(i), 0.0191 * f64::from(j));
                for own in [0, 1, 5] {
                    let want = near_by_scan(&c, px, py, own);
                    assert_eq!(c.near(1, px, py, own), want, "({px}, {py}) own {own}");
                    hits += usize::from(want.is_some());
                    asked += 1;
                }
            }
        }
        assert!(hits > 1000 && hits < asked / 2, "{hits} of {asked}");
        // A vertex of another track is on it whatever its position.
        assert_eq!(
            c.near(1000, 50.0, 50.0, 2),
            Some(Join {
                track: 0,
                point: 1000
            })
        );
    }
}
