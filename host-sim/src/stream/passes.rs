//! Passes: a trajectory that drives the same road again is cut into passes, found from the
//! trajectory alone — where the vehicle comes back onto road it has driven in this pass,
//! heading the other way (a turn at the end of the street) or the same way (a loop round
//! the block). Each pass runs through the core and tracker on its own (a section of the
//! route must not hold two passes over one curb), and the fusion makes one edge per curb
//! of all of them, with the lines of a pass that drove the other way turned to the first
//! pass's direction and their `side` taken relative to it.
//!
//! Stations every [`STATION_M`] of travel carry the direction of travel (from the
//! neighbouring stations, so the heading column is not needed). A station revisits an
//! earlier station of its pass when it lies within [`BACK_M`] of it heading back (the
//! other lane, the other side of the street) or within [`AGAIN_M`] of it heading the same
//! way, and the two lie at least [`MIN_APART_M`] apart along the route, so a bend or a turn
//! at a junction is not a revisit. A pass that turned back ends where its direction of
//! travel had turned by 90° from that of the station it revisits; a loop ends at the
//! revisiting station.

use crate::io::trajectory::Trajectory;
use crate::model::EdgeLine;
use std::collections::HashMap;

/// Travel between stations, metres.
pub const STATION_M: f64 = 0.5;
/// Largest distance to a station of the pass heading back, metres (across the street).
pub const BACK_M: f64 = 10.0;
/// Largest distance to a station of the pass heading the same way, metres (the same lane).
pub const AGAIN_M: f64 = 2.0;
/// Shortest route between a station and one it revisits, metres.
pub const MIN_APART_M: f64 = 40.0;
/// Cosine of the largest angle between directions counted as the same (or opposite) way:
/// 30°.
const COS_SAME: f64 = 0.866;

/// A station: trajectory sample index, position, arc length, unit direction of travel.
#[derive(Clone, Copy)]
struct Station {
    sample: usize,
    xy: [f64; 2],
    s: f64,
    dir: [f64; 2],
}

fn stations(traj: &Trajectory) -> Vec<Station> {
    let mut out: Vec<Station> = Vec::new();
    let mut s = 0.0;
    for (i, p) in traj.samples.iter().enumerate() {
        let xy = [p.x, p.y];
        match out.last() {
            None => {}
            Some(last) => {
                let d = (xy[0] - last.xy[0]).hypot(xy[1] - last.xy[1]);
                if d < STATION_M {
                    continue;
                }
                s += d;
            }
        }
        out.push(Station {
            sample: i,
            xy,
            s,
            dir: [0.0, 0.0],
        });
    }
    for i in 0..out.len() {
        let a = out[i.saturating_sub(1)].xy;
        let b = out[(i + 1).min(out.len() - 1)].xy;
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let n = dx.hypot(dy);
        if n > 0.0 {
            out[i].dir = [dx / n, dy / n];
        }
    }
    out
}

/// The sample indices where passes after the first begin, ascending (empty: one pass).
pub fn split(traj: &Trajectory) -> Vec<usize> {
    let st = stations(traj);
    let cell = BACK_M;
    let key = |xy: [f64; 2]| ((xy[0] / cell).floor() as i64, (xy[1] / cell).floor() as i64);
    let mut grid: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
    let mut starts = Vec::new();
    let mut i = 0;
    while i < st.len() {
        let q = st[i];
        let (ci, cj) = key(q.xy);
        let mut found: Option<(usize, bool)> = None;
        'look: for a in ci - 1..=ci + 1 {
            for b in cj - 1..=cj + 1 {
                for &j in grid.get(&(a, b)).map(Vec::as_slice).unwrap_or(&[]) {
                    let p = st[j];
                    if q.s - p.s < MIN_APART_M {
                        continue;
                    }
                    let d = (q.xy[0] - p.xy[0]).hypot(q.xy[1] - p.xy[1]);
                    let cos = q.dir[0] * p.dir[0] + q.dir[1] * p.dir[1];
                    if d <= BACK_M && cos <= -COS_SAME {
                        found = Some((j, true));
                        break 'look;
                    }
                    if d <= AGAIN_M && cos >= COS_SAME {
                        found = Some((j, false));
                        break 'look;
                    }
                }
            }
        }
        match found {
            None => {
                grid.entry((ci, cj)).or_default().push(i);
                i += 1;
            }
            Some((j, back)) => {
                // Where the pass turned back: the first station after `j` whose direction
                // has turned by 90° from `j`'s.
                let k = if back {
                    let d = st[j].dir;
                    (j + 1..=i)
                        .find(|&k| st[k].dir[0] * d[0] + st[k].dir[1] * d[1] <= 0.0)
                        .unwrap_or(i)
                } else {
                    i
                };
                starts.push(st[k].sample);
                grid.clear();
                i = k;
                let (ci, cj) = key(st[i].xy);
                grid.entry((ci, cj)).or_default().push(i);
                i += 1;
            }
        }
    }
    starts
}

/// The trajectory of each pass: `traj` cut before every start of [`split`].
pub fn passes(traj: &Trajectory) -> Vec<Trajectory> {
    let mut out = Vec::new();
    let mut a = 0;
    for b in split(traj).into_iter().chain([traj.samples.len()]) {
        if b > a {
            out.push(Trajectory {
                samples: traj.samples[a..b].to_vec(),
            });
        }
        a = b;
    }
    out
}

/// Whether pass `other` drives the other way from `first` where it saw a line: the
/// direction of travel at `other`'s station nearest to the line against `first`'s at its
/// station nearest to that one, when `first` came within [`BACK_M`] of it (a side
/// street's curb lies far from both routes; the vehicle's places decide).
pub struct Orientation {
    first: Vec<Station>,
    other: Vec<Station>,
}

impl Orientation {
    /// The stations of `first` and `other`.
    pub fn new(first: &Trajectory, other: &Trajectory) -> Self {
        Self {
            first: stations(first),
            other: stations(other),
        }
    }

    /// Whether `other` heads against `first` where it saw `xy` (false where `first` did
    /// not come within [`BACK_M`] of `other` there).
    pub fn reversed_at(&self, xy: [f64; 2]) -> bool {
        let near = |st: &[Station], xy: [f64; 2]| {
            st.iter()
                .map(|p| ((p.xy[0] - xy[0]).hypot(p.xy[1] - xy[1]), *p))
                .min_by(|a, b| a.0.total_cmp(&b.0))
        };
        let Some((_, b)) = near(&self.other, xy) else {
            return false;
        };
        match near(&self.first, b.xy) {
            Some((d, a)) if d <= BACK_M => a.dir[0] * b.dir[0] + a.dir[1] * b.dir[1] < 0.0,
            _ => false,
        }
    }
}

/// Farthest a vertex of a later pass is matched to the first pass's line when the shift
/// between them is estimated, metres: the 5–20 cm of GNSS drift between passes and more.
pub const MATCH_M: f64 = 0.5;
/// Largest shift applied, metres; a larger estimate is taken for a mismatch and ignored.
pub const MAX_SHIFT_M: f64 = 1.0;

/// The horizontal shift that lays `other`'s observed toe vertices best onto `first`'s
/// lines of the same side (least squares over the distances across the lines, so a shift
/// along straight curbs, which nothing observes, stays zero), or `None` with too few
/// matches. Two rounds: matches within [`MATCH_M`], then within a fifth of it after the
/// first shift.
pub fn shift_onto(first: &[EdgeLine], other: &[EdgeLine]) -> Option<[f64; 2]> {
    let cell = MATCH_M;
    let key = |x: f64, y: f64| ((x / cell).floor() as i64, (y / cell).floor() as i64);
    let mut grid: HashMap<(i64, i64), Vec<(usize, usize)>> = HashMap::new();
    for (i, e) in first.iter().enumerate() {
        for (k, w) in e.points.windows(2).enumerate() {
            let m = key(0.5 * (w[0][0] + w[1][0]), 0.5 * (w[0][1] + w[1][1]));
            grid.entry(m).or_default().push((i, k));
        }
    }
    let mut t = [0.0, 0.0];
    for radius in [MATCH_M, 0.2 * MATCH_M] {
        // Normal equations of Σ (n·t − d)².
        let (mut a, mut b, mut n_used) = ([[0.0f64; 2]; 2], [0.0f64; 2], 0usize);
        for e in other {
            let measured = e.detail.as_ref().map(|d| d.measured.as_slice());
            for (v, q) in e.points.iter().enumerate() {
                if measured.is_some_and(|m| !m.get(v).copied().unwrap_or(true)) {
                    continue;
                }
                let q = [q[0] + t[0], q[1] + t[1]];
                let (ci, cj) = key(q[0], q[1]);
                let mut best: Option<(f64, [f64; 2])> = None;
                for gi in ci - 2..=ci + 2 {
                    for gj in cj - 2..=cj + 2 {
                        for &(i, k) in grid.get(&(gi, gj)).map(Vec::as_slice).unwrap_or(&[]) {
                            let f = &first[i];
                            if f.side != e.side {
                                continue;
                            }
                            let (p0, p1) = (f.points[k], f.points[k + 1]);
                            let (dx, dy) = (p1[0] - p0[0], p1[1] - p0[1]);
                            let l = dx.hypot(dy);
                            if l <= 0.0 {
                                continue;
                            }
                            let u = ((q[0] - p0[0]) * dx + (q[1] - p0[1]) * dy) / (l * l);
                            if !(0.0..=1.0).contains(&u) {
                                continue;
                            }
                            let n = [-dy / l, dx / l];
                            let d = (q[0] - p0[0]) * n[0] + (q[1] - p0[1]) * n[1];
                            if d.abs() <= radius && !best.is_some_and(|b| d.abs() >= b.0.abs()) {
                                best = Some((d, n));
                            }
                        }
                    }
                }
                if let Some((d, n)) = best {
                    // The shift moves q by −d along n.
                    for r in 0..2 {
                        for c in 0..2 {
                            a[r][c] += n[r] * n[c];
                        }
                        b[r] -= n[r] * d;
                    }
                    n_used += 1;
                }
            }
        }
        if n_used < 50 {
            return None;
        }
        // A small ridge keeps the direction along the curbs at zero when nothing
        // observes it.
        let ridge = 1e-3 * (a[0][0] + a[1][1]);
        let (a00, a11, a01) = (a[0][0] + ridge, a[1][1] + ridge, a[0][1]);
        let det = a00 * a11 - a01 * a01;
        let dt = [
            (a11 * b[0] - a01 * b[1]) / det,
            (a00 * b[1] - a01 * b[0]) / det,
        ];
        t = [t[0] + dt[0], t[1] + dt[1]];
    }
    (t[0].hypot(t[1]) <= MAX_SHIFT_M).then_some(t)
}

/// `lines` moved horizontally by `t` (toe and top of curb).
pub fn shifted(lines: &mut [EdgeLine], t: [f64; 2]) {
    for e in lines {
        for p in &mut e.points {
            p[0] += t[0];
            p[1] += t[1];
        }
        if let Some(d) = e.detail.as_mut() {
            for p in &mut d.top {
                p[0] += t[0];
                p[1] += t[1];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::trajectory::Pose;

    /// Samples every 0.01 s at 10 m/s through `pts` (straight legs between them), with a
    /// time gap of `gap_s` before leg `gap_leg`.
    fn drive(pts: &[[f64; 2]], gap_leg: usize, gap_s: f64) -> Trajectory {
        let mut samples = Vec::new();
        let mut t = 0.0;
        for (k, w) in pts.windows(2).enumerate() {
            if k == gap_leg {
                t += gap_s;
            }
            let (dx, dy) = (w[1][0] - w[0][0], w[1][1] - w[0][1]);
            let n = (dx.hypot(dy) / 0.1).ceil() as usize;
            let h = dx.atan2(dy).to_degrees().rem_euclid(360.0);
            for i in 0..n {
                let f = i as f64 / n as f64;
                samples.push(Pose {
                    t,
                    x: w[0][0] + f * dx,
                    y: w[0][1] + f * dy,
                    z: 2.0,
                    roll_deg: 0.0,
                    pitch_deg: 0.0,
                    heading_deg: h,
                });
                t += 0.01;
            }
        }
        Trajectory { samples }
    }

    #[test]
    fn a_street_driven_there_and_back_is_two_passes_cut_at_the_turn() {
        // 200 m east, a gap (the turn off the data), 200 m back west 3.5 m to the north.
        let t = drive(
            &[[0.0, 0.0], [200.0, 0.0], [200.0, 3.5], [0.0, 3.5]],
            1,
            60.0,
        );
        let p = passes(&t);
        assert_eq!(p.len(), 2);
        let (a, b) = (&p[0].samples, &p[1].samples);
        // The cut lies in the turn: after every eastward sample, before every westward one.
        assert!(a.iter().all(|s| s.y < STATION_M), "{:?}", a.last());
        assert!(b.iter().all(|s| s.y >= STATION_M), "{:?}", b.first());
        let o = Orientation::new(&p[0], &p[1]);
        assert!(o.reversed_at([100.0, 1.7]));
        // A side street's curb 40 m off: seen from where both passes drove.
        assert!(o.reversed_at([100.0, 40.0]));
        // A pass on another street is not turned.
        let elsewhere = drive(&[[0.0, 50.0], [200.0, 50.0]], 99, 0.0);
        let o = Orientation::new(&p[0], &elsewhere);
        assert!(!o.reversed_at([100.0, 48.0]));
    }

    #[test]
    fn a_loop_round_the_block_is_two_passes_and_bends_are_one() {
        let block = [
            [0.0, 0.0],
            [100.0, 0.0],
            [100.0, 100.0],
            [0.0, 100.0],
            [0.0, 0.0],
            [100.0, 0.0],
        ];
        let p = passes(&drive(&block, 99, 0.0));
        assert_eq!(p.len(), 2);
        // The second begins where the first started.
        let s = p[1].samples[0];
        assert!(s.x.hypot(s.y) < AGAIN_M, "{s:?}");
        // A street with a right-angle bend and a hairpin-free S: one pass.
        let s_curve = [[0.0, 0.0], [100.0, 0.0], [100.0, 100.0], [200.0, 100.0]];
        assert_eq!(passes(&drive(&s_curve, 99, 0.0)).len(), 1);
    }
}
