//! Reference lines: the curb toes the scanner saw.
//!
//! Honma et al. drew their reference by hand and left out what could not be seen, e.g.
//! behind vehicles (§3.2). Here the rule is mechanical and uses only the *true* (noise-free)
//! positions of ground returns:
//!
//! **A toe vertex is kept when, within ±[`WINDOW_M`] along the toe, at least one ground
//! return fell on the road side within [`BAND_M`] of the toe and at least one fell on the
//! curb side (face, top or the ramp behind a lowered curb) within [`BAND_M`].** Returns on
//! cars, weeds, leaves or poles do not count. A segment between two kept vertices is kept;
//! kept segments are joined into lines split where the category or the side changes. So
//! stretches hidden behind parked cars or never reached (far down a side street) drop out,
//! and stretches seen before the start or after the end of the drive stay in.
//!
//! **Two observed stretches of one toe at most [`JOIN_M`] apart are joined**, as a surveyor
//! draws one line through a curb sampled every metre: scanlines that cross a far curb at a
//! grazing angle, or a spinning sensor's rings crossing it once per revolution, observe the
//! toe in short pieces that the window alone would leave apart. Longer gaps (a parked car
//! is 4–5 m long) stay holes. [`Visibility::strict`] gives the rule without joining, written
//! beside the reference as `reference_strict.geojson`.
//!
//! A segment's category is its vertices' category, or the special one (curb cut,
//! intersection, bus bay) when they differ. Intersection covers the corner arcs and the
//! side street's curbs. The side is the sign of the segment midpoint's lateral offset x′
//! from the nearest trajectory sample (docs/spec.md §2: left positive).

use super::ground::ToeLine;
use super::ground::{Ground, ToeCoord};
use crate::io::trajectory::Trajectory;
use crate::model::{Category, CurbDetail, EdgeLine, Side};

/// Half window along the toe, metres.
pub const WINDOW_M: f64 = 0.15;
/// Distance band across the toe, metres.
pub const BAND_M: f64 = 0.15;
/// Longest gap between two observed stretches of one toe that the reference joins, metres.
pub const JOIN_M: f64 = 1.0;
const BIN_M: f64 = 0.05;

/// Evidence per toe: counts of road-side and curb-side returns in 5 cm bins along it.
#[derive(Clone)]
pub struct Visibility {
    along: Vec<Vec<f64>>,
    road: Vec<Vec<u32>>,
    curb: Vec<Vec<u32>>,
    join_m: f64,
}

impl Visibility {
    /// Empty evidence for the toes of `ground`.
    pub fn new(ground: &Ground) -> Self {
        let along: Vec<Vec<f64>> = ground
            .toes
            .iter()
            .map(|t| {
                let mut a = vec![0.0; t.pts.len()];
                for i in 1..t.pts.len() {
                    let (p, q) = (t.pts[i - 1], t.pts[i]);
                    a[i] = a[i - 1] + ((q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2)).sqrt();
                }
                a
            })
            .collect();
        let bins =
            |a: &Vec<f64>| vec![0u32; (a.last().copied().unwrap_or(0.0) / BIN_M) as usize + 2];
        Visibility {
            road: along.iter().map(bins).collect(),
            curb: along.iter().map(bins).collect(),
            along,
            join_m: JOIN_M,
        }
    }

    /// The same evidence under the rule without joining gaps: each observed stretch alone.
    pub fn strict(mut self) -> Self {
        self.join_m = 0.0;
        self
    }

    /// Evidence on both sides of every bin: every toe vertex is kept. The reference
    /// without its visibility rule (`simulate --whole-toes`), against which extracted
    /// length in the reference's holes is measured.
    pub fn everywhere(ground: &Ground) -> Self {
        let mut v = Visibility::new(ground);
        for bins in v.road.iter_mut().chain(v.curb.iter_mut()) {
            bins.fill(1);
        }
        v
    }

    /// Records one ground return at a true position with toe coordinates `tc`.
    pub fn add(&mut self, tc: &ToeCoord) {
        let (ti, v) = (tc.toe as usize, tc.vtx as usize);
        let Some(a) = self.along.get(ti) else { return };
        if v + 1 >= a.len() {
            return;
        }
        let pos = a[v] + (a[v + 1] - a[v]) * tc.t;
        let b = ((pos / BIN_M) as usize).min(self.road[ti].len() - 1);
        // The side is the surface the true hit lies on (`ground`: road for s ≤ 0, the curb's
        // face, top or ramp for s > 0). The face's foot counts: a ring meeting a face at a
        // shallow elevation climbs it slowly along the toe, and its lowest face returns are
        // the only curb-side ones beside its road returns.
        if (-BAND_M..0.0).contains(&tc.s) {
            self.road[ti][b] += 1;
        } else if tc.s > 0.0 && tc.s <= BAND_M {
            self.curb[ti][b] += 1;
        }
    }

    /// Whether each vertex of toe `ti` is kept by the rule.
    pub fn kept(&self, ti: usize) -> Vec<bool> {
        let prefix = |c: &Vec<u32>| {
            let mut p = vec![0u32; c.len() + 1];
            for i in 0..c.len() {
                p[i + 1] = p[i] + c[i];
            }
            p
        };
        let (pr, pc) = (prefix(&self.road[ti]), prefix(&self.curb[ti]));
        let n = self.road[ti].len();
        let along = &self.along[ti];
        let mut kept: Vec<bool> = along
            .iter()
            .map(|&a| {
                let lo = (((a - WINDOW_M) / BIN_M).floor().max(0.0) as usize).min(n);
                let hi = ((((a + WINDOW_M) / BIN_M).floor() as usize) + 1).min(n);
                pr[hi] > pr[lo] && pc[hi] > pc[lo]
            })
            .collect();
        join_gaps(&mut kept, along, self.join_m);
        kept
    }
}

/// Marks kept every vertex between two kept vertices at most `join_m` apart along the toe.
fn join_gaps(kept: &mut [bool], along: &[f64], join_m: f64) {
    let mut last: Option<usize> = None;
    for v in 0..kept.len() {
        if !kept[v] {
            continue;
        }
        if let Some(u) = last {
            if v > u + 1 && along[v] - along[u] <= join_m {
                kept[u + 1..v].fill(true);
            }
        }
        last = Some(v);
    }
}

/// The true top of curb beside toe vertex `i` at `toe_xyz` (CRS coordinates): the corner
/// of the face and the top (docs/spec.md §2, "Curb geometry"), the face's batter run
/// behind the toe and the curb height above it; the toe itself where there is no lip.
fn top_of_curb(ground: &Ground, toe: &ToeLine, i: usize, toe_xyz: [f64; 3]) -> [f64; 3] {
    let hc = toe.h_curb[i].max(0.0);
    let (a, b) = (i.saturating_sub(1), (i + 1).min(toe.pts.len() - 1));
    let d = [toe.pts[b][0] - toe.pts[a][0], toe.pts[b][1] - toe.pts[a][1]];
    let l = d[0].hypot(d[1]);
    if l <= 0.0 {
        return [toe_xyz[0], toe_xyz[1], toe_xyz[2] + hc];
    }
    // The sidewalk lies left of the toe's direction (`ground::ToeLine`).
    let run = ground.shape.batter_ratio * hc;
    [
        toe_xyz[0] - run * d[1] / l,
        toe_xyz[1] + run * d[0] / l,
        toe_xyz[2] + hc,
    ]
}

/// Builds the reference lines (CRS coordinates: local + `origin`), each with its true top
/// of curb and curb height per vertex in its [`CurbDetail`].
pub fn reference_lines(
    ground: &Ground,
    vis: &Visibility,
    traj: &Trajectory,
    origin: [f64; 3],
) -> Vec<EdgeLine> {
    let poses: Vec<_> = traj.samples.iter().step_by(4).collect();
    let side_of = |p: [f64; 2]| -> Side {
        let mut best = (f64::INFINITY, 0usize);
        for (i, q) in poses.iter().enumerate() {
            let d2 = (p[0] - q.x).powi(2) + (p[1] - q.y).powi(2);
            if d2 < best.0 {
                best = (d2, i);
            }
        }
        let q = poses[best.1];
        let l = q.left();
        if (p[0] - q.x) * l[0] + (p[1] - q.y) * l[1] >= 0.0 {
            Side::Left
        } else {
            Side::Right
        }
    };
    let mut out = Vec::new();
    for (ti, toe) in ground.toes.iter().enumerate() {
        let kept = vis.kept(ti);
        let mut cur: Option<(Side, Category, Vec<usize>)> = None;
        let flush = |cur: &mut Option<(Side, Category, Vec<usize>)>, out: &mut Vec<EdgeLine>| {
            if let Some((side, cat, idx)) = cur.take() {
                if idx.len() >= 2 {
                    let mut hs: Vec<f64> = idx.iter().map(|&i| toe.h_curb[i]).collect();
                    let heights = hs.clone();
                    hs.sort_by(f64::total_cmp);
                    let points: Vec<[f64; 3]> = idx
                        .iter()
                        .map(|&i| {
                            let p = toe.pts[i];
                            [
                                p[0] + origin[0],
                                p[1] + origin[1],
                                ground.base.at(p[0], p[1]) + origin[2],
                            ]
                        })
                        .collect();
                    let top = idx
                        .iter()
                        .zip(&points)
                        .map(|(&i, p)| top_of_curb(ground, toe, i, *p))
                        .collect();
                    out.push(EdgeLine {
                        side,
                        category: Some(cat),
                        method: None,
                        curb_height_m: Some(hs[hs.len() / 2]),
                        detail: Some(Box::new(CurbDetail {
                            top,
                            height_m: heights,
                            ..CurbDetail::measured(&points)
                        })),
                        points,
                    });
                }
            }
        };
        for v in 0..toe.pts.len().saturating_sub(1) {
            if !(kept[v] && kept[v + 1]) {
                flush(&mut cur, &mut out);
                continue;
            }
            let (ca, cb) = (toe.category[v], toe.category[v + 1]);
            let cat = if ca == cb || cb == Category::Curb {
                ca
            } else {
                cb
            };
            let mid = [
                0.5 * (toe.pts[v][0] + toe.pts[v + 1][0]),
                0.5 * (toe.pts[v][1] + toe.pts[v + 1][1]),
            ];
            let side = side_of(mid);
            match &mut cur {
                Some((s, c, idx)) if *s == side && *c == cat => idx.push(v + 1),
                _ => {
                    flush(&mut cur, &mut out);
                    cur = Some((side, cat, vec![v, v + 1]));
                }
            }
        }
        flush(&mut cur, &mut out);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::{join_gaps, Visibility, BIN_M};
    use crate::simulate::ground::ToeCoord;

    /// No evidence yet on one straight toe 2 m long, vertices every 0.25 m, not joined.
    fn straight_toe() -> Visibility {
        let along: Vec<f64> = (0..9).map(|i| i as f64 * 0.25).collect();
        let bins = (2.0 / BIN_M) as usize + 2;
        Visibility {
            along: vec![along],
            road: vec![vec![0; bins]],
            curb: vec![vec![0; bins]],
            join_m: 0.0,
        }
    }

    /// Vertex 4's window holding one return at each signed distance `s` from the toe.
    fn kept_with(s: &[f64]) -> bool {
        let mut v = straight_toe();
        for &s in s {
            v.add(&ToeCoord {
                toe: 0,
                vtx: 4,
                t: 0.1,
                s,
            });
        }
        v.kept(0)[4]
    }

    #[test]
    fn a_return_on_the_faces_foot_is_curb_side_evidence() {
        // A road return and one 1 cm up the face (s = 1 mm at a batter of 0.1), as a ring
        // leaves where it starts to climb the face.
        assert!(kept_with(&[-0.05, 0.001]));
        // The road's last millimetre before the toe is the road side.
        assert!(kept_with(&[-0.001, 0.05]));
        // One side alone is not enough, nor a return beyond the band.
        assert!(!kept_with(&[-0.05, -0.001]));
        assert!(!kept_with(&[0.001, 0.05]));
        assert!(!kept_with(&[-0.05, 0.2]));
    }

    /// Vertices every 0.1 m; `holes` are `(first, end)` index ranges left unobserved.
    fn joined(holes: &[(usize, usize)], join_m: f64) -> Vec<bool> {
        let along: Vec<f64> = (0..100).map(|i| i as f64 * 0.1).collect();
        let mut kept = vec![true; along.len()];
        for &(a, b) in holes {
            kept[a..b].fill(false);
        }
        join_gaps(&mut kept, &along, join_m);
        kept
    }

    #[test]
    fn gaps_up_to_the_join_length_are_joined_and_longer_ones_stay() {
        // A hole of 8 vertices lies 0.9 m between its kept neighbours; one of 20, 2.1 m.
        let k = joined(&[(10, 18), (40, 60)], 1.0);
        assert!(k[10..18].iter().all(|&b| b), "a 0.9 m gap is joined");
        assert!(k[40..60].iter().all(|&b| !b), "a 2.1 m gap stays a hole");
        // The ends of the toe are not gaps: nothing observed before the first kept vertex.
        let k = joined(&[(0, 5), (95, 100)], 1.0);
        assert!(k[0..5].iter().chain(&k[95..100]).all(|&b| !b));
    }

    #[test]
    fn the_strict_rule_joins_nothing() {
        let k = joined(&[(10, 12)], 0.0);
        assert!(k[10..12].iter().all(|&b| !b));
    }
}
