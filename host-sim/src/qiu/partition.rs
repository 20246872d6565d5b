//! §3.1 Point clouds partition: consecutive, overlapping sections along the trajectory,
//! chosen by GPS time and position, so that a road driven twice is never mixed in one
//! section (the two passes have different times).
//!
//! Stations: every trajectory sample gets its arc length `s` from the start of the drive
//! (horizontal). A section is a station interval `[s_start, s_end]` and the matching time
//! interval; its *core* is the part it owns when results of overlapping sections are merged
//! (half an overlap in from each end, open towards the ends of a run), so every station is
//! owned by exactly one section and nothing is output twice.

use super::params::QiuParams;
use crate::io::trajectory::{Pose, Trajectory};
use rstar::primitives::GeomWithData;
use rstar::RTree;

/// One section of the partition.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Section {
    /// Position in the partition (also mixed into the RANSAC seed).
    pub index: usize,
    /// GPS time interval of the section's points, seconds.
    pub t_start: f64,
    /// End of the time interval, seconds.
    pub t_end: f64,
    /// Station interval, metres of trajectory arc length.
    pub s_start: f64,
    /// End of the station interval.
    pub s_end: f64,
    /// The stations this section owns in the merge: `[core_start, core_end)`.
    pub core_start: f64,
    /// End of the owned stations.
    pub core_end: f64,
}

/// Horizontal arc length at every trajectory sample (0 at the first one).
pub fn stations(traj: &Trajectory) -> Vec<f64> {
    let mut s = Vec::with_capacity(traj.samples.len());
    let mut acc = 0.0;
    for (i, p) in traj.samples.iter().enumerate() {
        if i > 0 {
            let q = &traj.samples[i - 1];
            acc += (p.x - q.x).hypot(p.y - q.y);
        }
        s.push(acc);
    }
    s
}

/// Time at which the trajectory reaches station `s` within samples `lo..=hi` (first such
/// time when the vehicle stood still).
fn time_at_station(traj: &Trajectory, st: &[f64], lo: usize, hi: usize, s: f64) -> f64 {
    let k = lo + st[lo..=hi].partition_point(|&v| v < s);
    if k <= lo {
        return traj.samples[lo].t;
    }
    if k > hi {
        return traj.samples[hi].t;
    }
    let (a, b) = (k - 1, k);
    let ds = st[b] - st[a];
    let w = if ds > 0.0 { (s - st[a]) / ds } else { 0.0 };
    traj.samples[a].t + w * (traj.samples[b].t - traj.samples[a].t)
}

/// Plans the sections: the trajectory is cut into runs at time gaps longer than
/// `max_time_gap_s`, and each run into sections of `section_length_m` starting every
/// `section_length_m − section_overlap_m` metres. A run shorter than one section is one
/// section.
pub fn plan_sections(traj: &Trajectory, params: &QiuParams) -> Vec<Section> {
    let n = traj.samples.len();
    if n < 2 {
        return Vec::new();
    }
    let st = stations(traj);
    let step = params.section_length_m - params.section_overlap_m;
    let half_overlap = 0.5 * params.section_overlap_m;
    let mut out = Vec::new();
    let mut run_start = 0;
    for i in 1..=n {
        let gap = i == n || traj.samples[i].t - traj.samples[i - 1].t > params.max_time_gap_s;
        if !gap {
            continue;
        }
        let (lo, hi) = (run_start, i - 1);
        run_start = i;
        if hi == lo {
            continue;
        }
        let (s0, s1) = (st[lo], st[hi]);
        let first = out.len();
        let mut a = s0;
        loop {
            let b = (a + params.section_length_m).min(s1);
            out.push(Section {
                index: out.len(),
                t_start: time_at_station(traj, &st, lo, hi, a),
                t_end: if b >= s1 {
                    traj.samples[hi].t
                } else {
                    time_at_station(traj, &st, lo, hi, b)
                },
                s_start: a,
                s_end: b,
                core_start: a + half_overlap,
                core_end: b - half_overlap,
            });
            if b >= s1 {
                break;
            }
            a += step;
        }
        // The ends of a run belong to its first and last section.
        out[first].core_start = f64::NEG_INFINITY;
        let last = out.len() - 1;
        out[last].core_end = f64::INFINITY;
        // Stations of different runs never overlap (arc length only grows), so open ends
        // cannot claim another run's stations: a point's station comes from its own
        // section's trajectory.
    }
    out
}

/// The trajectory of one section, densified, for "nearest trajectory point" queries
/// (Eq. 2, Eq. 3): station and signed offset of a world position.
pub struct SectionTrack {
    poses: Vec<Pose>,
    st: Vec<f64>,
    tree: RTree<GeomWithData<[f64; 2], usize>>,
}

/// Where a position lies relative to the trajectory.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrackPosition {
    /// Station of the nearest trajectory point, metres.
    pub s: f64,
    /// Signed offset along `Pose::left()` of the nearest pose, metres (left positive).
    pub d: f64,
    /// The nearest trajectory point (foot of the perpendicular), x and y.
    pub foot: [f64; 2],
}

/// Densification step of [`SectionTrack`], metres: fine enough that the heading of the
/// nearest pose is the heading at the foot of the perpendicular.
const TRACK_STEP_M: f64 = 0.25;

impl SectionTrack {
    /// Builds the densified trajectory of the time interval `[t0, t1]`.
    pub fn new(traj: &Trajectory, st: &[f64], t0: f64, t1: f64) -> Self {
        let s = &traj.samples;
        let lo = s.partition_point(|p| p.t < t0).saturating_sub(1);
        let hi = (s.partition_point(|p| p.t <= t1)).min(s.len().saturating_sub(1));
        let mut poses = Vec::new();
        let mut stn = Vec::new();
        for k in lo..=hi {
            if k > lo {
                let (a, b) = (&s[k - 1], &s[k]);
                let len = st[k] - st[k - 1];
                let n = (len / TRACK_STEP_M).ceil() as usize;
                for j in 1..n {
                    let w = j as f64 / n as f64;
                    if let Some(p) = traj.pose_at(a.t + w * (b.t - a.t)) {
                        poses.push(p);
                        stn.push(st[k - 1] + w * len);
                    }
                }
            }
            poses.push(s[k]);
            stn.push(st[k]);
        }
        let tree = RTree::bulk_load(
            poses
                .iter()
                .enumerate()
                .map(|(i, p)| GeomWithData::new([p.x, p.y], i))
                .collect(),
        );
        Self {
            poses,
            st: stn,
            tree,
        }
    }

    /// Station and signed offset of a world position relative to the nearest pose.
    pub fn locate(&self, x: f64, y: f64) -> Option<TrackPosition> {
        let i = self.tree.nearest_neighbor(&[x, y])?.data;
        let p = &self.poses[i];
        let (dx, dy) = (x - p.x, y - p.y);
        let f = p.forward();
        let l = p.left();
        let along = dx * f[0] + dy * f[1];
        Some(TrackPosition {
            s: self.st[i] + along,
            d: dx * l[0] + dy * l[1],
            foot: [p.x + along * f[0], p.y + along * f[1]],
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A straight drive east at 10 m/s, one sample per second, `n` samples, optionally
    /// with a pause (time gap) after sample `gap_after`.
    fn drive_east(n: usize, gap_after: Option<usize>) -> Trajectory {
        let mut t = 100.0;
        let samples = (0..n)
            .map(|i| {
                if i > 0 {
                    t += if Some(i - 1) == gap_after { 30.0 } else { 1.0 };
                }
                Pose {
                    t,
                    x: 1000.0 + 10.0 * i as f64,
                    y: 5000.0,
                    z: 2.0,
                    roll_deg: 0.0,
                    pitch_deg: 0.0,
                    heading_deg: 90.0,
                }
            })
            .collect();
        Trajectory { samples }
    }

    #[test]
    fn sections_overlap_and_cores_tile_the_drive() {
        // 500 m drive; 200 m sections every 180 m: [0,200], [180,380], [360,500].
        let tr = drive_east(51, None);
        let p = QiuParams::default();
        let secs = plan_sections(&tr, &p);
        assert_eq!(secs.len(), 3);
        let want = [(0.0, 200.0), (180.0, 380.0), (360.0, 500.0)];
        for (s, (a, b)) in secs.iter().zip(want) {
            assert!(
                (s.s_start - a).abs() < 1e-9 && (s.s_end - b).abs() < 1e-9,
                "{s:?}"
            );
            // 10 m/s from t = 100 s.
            assert!((s.t_start - (100.0 + a / 10.0)).abs() < 1e-9);
            assert!((s.t_end - (100.0 + b / 10.0)).abs() < 1e-9);
        }
        // Cores: (-inf, 190), [190, 370), [370, +inf): every station owned once.
        assert_eq!(secs[0].core_start, f64::NEG_INFINITY);
        assert!((secs[0].core_end - 190.0).abs() < 1e-9);
        assert!((secs[1].core_start - 190.0).abs() < 1e-9);
        assert!((secs[1].core_end - 370.0).abs() < 1e-9);
        assert!((secs[2].core_start - 370.0).abs() < 1e-9);
        assert_eq!(secs[2].core_end, f64::INFINITY);
    }

    #[test]
    fn a_time_gap_starts_a_new_run() {
        // 11 samples (100 m), a 30 s pause, 11 more: two runs of one section each.
        let tr = drive_east(22, Some(10));
        let secs = plan_sections(&tr, &QiuParams::default());
        assert_eq!(secs.len(), 2);
        assert!((secs[0].t_end - 110.0).abs() < 1e-9);
        assert!((secs[1].t_start - 140.0).abs() < 1e-9);
        assert!(secs[0].core_end.is_infinite() && secs[1].core_start.is_infinite());
    }

    #[test]
    fn locate_gives_station_and_signed_offset() {
        let tr = drive_east(11, None);
        let st = stations(&tr);
        let track = SectionTrack::new(&tr, &st, 100.0, 110.0);
        // Driving east, left is north: 3 m north of the point 42.5 m along.
        let p = track.locate(1042.5, 5003.0).unwrap();
        assert!(
            (p.s - 42.5).abs() < 1e-9 && (p.d - 3.0).abs() < 1e-9,
            "{p:?}"
        );
        assert!((p.foot[0] - 1042.5).abs() < 1e-9 && (p.foot[1] - 5000.0).abs() < 1e-9);
        let p = track.locate(1042.5, 4995.0).unwrap();
        assert!((p.d + 5.0).abs() < 1e-9);
    }
}
