//! The trajectory (docs/spec.md §3): CSV `time,x,y,z,roll,pitch,heading`, GPS time in the LAS time
//! base, scanner origin in the LAS CRS, angles in degrees, heading clockwise from grid north.
//! Interpolated at a point's time: positions linearly, heading along the shorter arc.

use std::path::{Path, PathBuf};

/// One trajectory sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// GPS time, seconds.
    pub t: f64,
    /// Scanner origin, LAS CRS, metres.
    pub x: f64,
    /// Scanner origin, LAS CRS, metres.
    pub y: f64,
    /// Scanner origin, LAS CRS, metres.
    pub z: f64,
    /// Roll, degrees.
    pub roll_deg: f64,
    /// Pitch, degrees.
    pub pitch_deg: f64,
    /// Heading, degrees clockwise from grid north (0 = +Y, 90 = +X).
    pub heading_deg: f64,
}

impl Pose {
    /// Forward unit vector f = (sin h, cos h) in the horizontal plane.
    pub fn forward(&self) -> [f64; 2] {
        let h = self.heading_deg.to_radians();
        [h.sin(), h.cos()]
    }

    /// Left unit vector l = (−cos h, sin h) in the horizontal plane.
    pub fn left(&self) -> [f64; 2] {
        let h = self.heading_deg.to_radians();
        [-h.cos(), h.sin()]
    }
}

/// A trajectory: samples strictly increasing in time.
#[derive(Clone, Debug, Default)]
pub struct Trajectory {
    /// The samples, strictly increasing in `t`.
    pub samples: Vec<Pose>,
}

impl Trajectory {
    /// First and last time covered.
    pub fn time_range(&self) -> Option<(f64, f64)> {
        Some((self.samples.first()?.t, self.samples.last()?.t))
    }

    /// The pose at time `t`, interpolated (positions and roll/pitch linearly, heading along
    /// the shorter arc), or `None` outside the covered time range.
    pub fn pose_at(&self, t: f64) -> Option<Pose> {
        let s = &self.samples;
        if s.is_empty() || !t.is_finite() || t < s[0].t || t > s[s.len() - 1].t {
            return None;
        }
        let k = s.partition_point(|p| p.t <= t);
        if k == 0 {
            return Some(s[0]);
        }
        if k >= s.len() {
            return Some(s[s.len() - 1]);
        }
        let (a, b) = (&s[k - 1], &s[k]);
        let w = (t - a.t) / (b.t - a.t);
        let lerp = |u: f64, v: f64| u + (v - u) * w;
        let mut dh = (b.heading_deg - a.heading_deg) % 360.0;
        if dh > 180.0 {
            dh -= 360.0;
        } else if dh < -180.0 {
            dh += 360.0;
        }
        Some(Pose {
            t,
            x: lerp(a.x, b.x),
            y: lerp(a.y, b.y),
            z: lerp(a.z, b.z),
            roll_deg: lerp(a.roll_deg, b.roll_deg),
            pitch_deg: lerp(a.pitch_deg, b.pitch_deg),
            heading_deg: (a.heading_deg + dh * w).rem_euclid(360.0),
        })
    }
}

/// Errors reading a trajectory or matching it to the points. Every message names the file
/// and the problem.
#[derive(Debug, thiserror::Error)]
pub enum TrajectoryError {
    /// The file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The header lacks a required column (or the file is empty).
    #[error("{path}: bad header: {what} (need the columns time,x,y,z,roll,pitch,heading)")]
    BadHeader {
        /// The file.
        path: PathBuf,
        /// What was wrong.
        what: String,
    },
    /// A value is missing, not a number, NaN or infinite.
    #[error("{path}: line {line}: column {column}: {what}")]
    BadValue {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// Column name.
        column: String,
        /// What was wrong.
        what: String,
    },
    /// Times do not strictly increase.
    #[error("{path}: line {line}: time {t} does not come after the previous time {prev}; times must strictly increase")]
    NotIncreasing {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// The previous time.
        prev: f64,
        /// This line's time.
        t: f64,
    },
    /// Fewer than two samples: nothing to interpolate.
    #[error("{path}: {n} trajectory sample(s); at least two are needed")]
    TooFew {
        /// The file.
        path: PathBuf,
        /// Samples found.
        n: usize,
    },
    /// (Almost) no point lies in the trajectory's time range.
    #[error("{traj}: covers GPS time {t0:.3}–{t1:.3} s but the points of {points} span {p0:.3}–{p1:.3} s; only {covered} of {n} points are covered{hint}")]
    NotCovering {
        /// The trajectory file.
        traj: PathBuf,
        /// The point file.
        points: PathBuf,
        /// Trajectory start time.
        t0: f64,
        /// Trajectory end time.
        t1: f64,
        /// First point time.
        p0: f64,
        /// Last point time.
        p1: f64,
        /// Points inside the range.
        covered: usize,
        /// Points in all.
        n: usize,
        /// A guess at the cause (time bases), or empty.
        hint: String,
    },
}

/// The columns a trajectory CSV must have (docs/spec.md §3), in the header's spelling.
pub const COLUMNS: [&str; 7] = ["time", "x", "y", "z", "roll", "pitch", "heading"];

/// Fewer than this fraction of the points inside the trajectory's time range is taken as a
/// mismatch of time bases rather than a partial overlap, and is an error.
pub const MIN_COVERED_FRACTION: f64 = 0.01;

/// Seconds in a GPS week: times below it are probably GPS week seconds.
const GPS_WEEK_S: f64 = 604_800.0;

/// Which of the (time-sorted) points the trajectory covers: the index range `start..end`
/// (points are sorted by time, so the covered ones are contiguous), and how many fell
/// before and after it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Coverage {
    /// First covered point.
    pub start: usize,
    /// One past the last covered point.
    pub end: usize,
    /// Points before the trajectory's first time.
    pub before: usize,
    /// Points after the trajectory's last time.
    pub after: usize,
}

impl Coverage {
    /// Points outside the trajectory (dropped and counted).
    pub fn dropped(&self) -> usize {
        self.before + self.after
    }
}

impl Trajectory {
    /// Reads the CSV of docs/spec.md §3: a header naming at least `time,x,y,z,roll,pitch,heading`
    /// (any order, surrounding spaces and case ignored, extra columns ignored), then one
    /// sample per line. Blank lines and lines starting with `#` are skipped.
    pub fn read_csv(path: &Path) -> Result<Trajectory, TrajectoryError> {
        let text = std::fs::read_to_string(path).map_err(|source| TrajectoryError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::parse_csv(path, &text)
    }

    /// Parses CSV text (see [`Trajectory::read_csv`]); `path` is only used in messages.
    pub fn parse_csv(path: &Path, text: &str) -> Result<Trajectory, TrajectoryError> {
        let p = || path.to_path_buf();
        let mut lines = text
            .lines()
            .enumerate()
            .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
        let Some((_, header)) = lines.next() else {
            return Err(TrajectoryError::BadHeader {
                path: p(),
                what: "the file has no header line".into(),
            });
        };
        let names: Vec<String> = header
            .trim_start_matches('\u{feff}')
            .split(',')
            .map(|s| s.trim().to_ascii_lowercase())
            .collect();
        let mut idx = [0usize; 7];
        for (k, want) in COLUMNS.iter().enumerate() {
            let found: Vec<usize> = (0..names.len()).filter(|&i| names[i] == *want).collect();
            match found.as_slice() {
                [i] => idx[k] = *i,
                [] => {
                    return Err(TrajectoryError::BadHeader {
                        path: p(),
                        what: format!("no column {want:?} in header {:?}", header.trim()),
                    })
                }
                _ => {
                    return Err(TrajectoryError::BadHeader {
                        path: p(),
                        what: format!("column {want:?} appears twice"),
                    })
                }
            }
        }
        let mut samples: Vec<Pose> = Vec::new();
        for (ln, line) in lines {
            let fields: Vec<&str> = line.split(',').collect();
            let mut v = [0f64; 7];
            for (k, &i) in idx.iter().enumerate() {
                let bad = |what: String| TrajectoryError::BadValue {
                    path: p(),
                    line: ln + 1,
                    column: COLUMNS[k].into(),
                    what,
                };
                let raw = fields.get(i).map(|s| s.trim()).ok_or_else(|| {
                    bad(format!("missing (the line has {} fields)", fields.len()))
                })?;
                let x: f64 = raw
                    .parse()
                    .map_err(|_| bad(format!("{raw:?} is not a number")))?;
                if !x.is_finite() {
                    return Err(bad(format!("{raw:?} is not a finite number")));
                }
                v[k] = x;
            }
            if let Some(prev) = samples.last() {
                if v[0] <= prev.t {
                    return Err(TrajectoryError::NotIncreasing {
                        path: p(),
                        line: ln + 1,
                        prev: prev.t,
                        t: v[0],
                    });
                }
            }
            samples.push(Pose {
                t: v[0],
                x: v[1],
                y: v[2],
                z: v[3],
                roll_deg: v[4],
                pitch_deg: v[5],
                heading_deg: v[6],
            });
        }
        if samples.len() < 2 {
            return Err(TrajectoryError::TooFew {
                path: p(),
                n: samples.len(),
            });
        }
        Ok(Trajectory { samples })
    }

    /// Which of the time-sorted point times `t` this trajectory covers. Points outside are
    /// to be dropped and counted; if fewer than [`MIN_COVERED_FRACTION`] of them (or none)
    /// are covered, the two files are taken not to belong together (typically GPS week
    /// seconds against adjusted standard GPS time) and the error names both time ranges.
    pub fn coverage(
        &self,
        t: &[f64],
        traj_path: &Path,
        points_path: &Path,
    ) -> Result<Coverage, TrajectoryError> {
        let (t0, t1) = self.time_range().unwrap_or((f64::NAN, f64::NAN));
        let start = t.partition_point(|&x| x < t0);
        let end = t.partition_point(|&x| x <= t1).max(start);
        let cov = Coverage {
            start,
            end,
            before: start,
            after: t.len() - end,
        };
        let covered = end - start;
        if t.is_empty() || (covered as f64) < MIN_COVERED_FRACTION * t.len() as f64 || covered == 0
        {
            let p0 = t.first().copied().unwrap_or(f64::NAN);
            let p1 = t.last().copied().unwrap_or(f64::NAN);
            return Err(self.not_covering(traj_path, points_path, (p0, p1), covered, t.len()));
        }
        Ok(cov)
    }

    /// The error for points (times `p0..=p1`, `covered` of `n` inside this trajectory's
    /// time range) that do not belong to this trajectory: both time ranges, and a guess at
    /// the cause when one side looks like GPS week seconds and the other does not.
    pub fn not_covering(
        &self,
        traj_path: &Path,
        points_path: &Path,
        (p0, p1): (f64, f64),
        covered: usize,
        n: usize,
    ) -> TrajectoryError {
        let (t0, t1) = self.time_range().unwrap_or((f64::NAN, f64::NAN));
        let week = |x: f64| (0.0..GPS_WEEK_S).contains(&x);
        let hint = if week(p0) && week(p1) && !week(t0) {
            "; the point times look like GPS week seconds and the trajectory's do not (convert one to the other's time base)".to_string()
        } else if week(t0) && week(t1) && !week(p0) {
            "; the trajectory times look like GPS week seconds and the points' do not (convert one to the other's time base)".to_string()
        } else {
            String::new()
        };
        TrajectoryError::NotCovering {
            traj: traj_path.to_path_buf(),
            points: points_path.to_path_buf(),
            t0,
            t1,
            p0,
            p1,
            covered,
            n,
            hint,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pose(t: f64, x: f64, h: f64) -> Pose {
        Pose {
            t,
            x,
            y: 0.0,
            z: 2.0,
            roll_deg: 0.0,
            pitch_deg: 0.0,
            heading_deg: h,
        }
    }

    #[test]
    fn heading_interpolates_along_the_shorter_arc() {
        let tr = Trajectory {
            samples: vec![pose(0.0, 0.0, 350.0), pose(1.0, 10.0, 10.0)],
        };
        let p = tr.pose_at(0.5).unwrap();
        assert!((p.x - 5.0).abs() < 1e-12);
        assert!(p.heading_deg.abs() < 1e-9 || (p.heading_deg - 360.0).abs() < 1e-9);
        assert!(tr.pose_at(1.5).is_none());
        assert!(tr.pose_at(-0.1).is_none());
    }

    #[test]
    fn left_is_minus_x_when_driving_north() {
        let p = pose(0.0, 0.0, 0.0);
        assert_eq!(p.forward(), [0.0, 1.0]);
        let l = p.left();
        assert!((l[0] + 1.0).abs() < 1e-12 && l[1].abs() < 1e-12);
        // Driving east (90°): left is north.
        let l = pose(0.0, 0.0, 90.0).left();
        assert!(l[0].abs() < 1e-12 && (l[1] - 1.0).abs() < 1e-12);
    }

    fn parse(text: &str) -> Result<Trajectory, TrajectoryError> {
        Trajectory::parse_csv(Path::new("traj.csv"), text)
    }

    #[test]
    fn csv_in_any_column_order_with_extra_columns() {
        let tr = parse(
            "heading, speed ,time,x,y,z,roll,pitch\n\
             90,11,100.0,1,2,3,0.5,0.25\n\
             # a comment\n\
             \n\
             91,12,100.5,6,2,3,0.5,0.25\n",
        )
        .unwrap();
        assert_eq!(tr.samples.len(), 2);
        assert_eq!(tr.samples[1].t, 100.5);
        assert_eq!(tr.samples[1].x, 6.0);
        assert_eq!(tr.samples[0].heading_deg, 90.0);
        assert_eq!(tr.samples[0].roll_deg, 0.5);
        assert_eq!(tr.samples[0].pitch_deg, 0.25);
        let p = tr.pose_at(100.25).unwrap();
        assert!((p.x - 3.5).abs() < 1e-12 && (p.heading_deg - 90.5).abs() < 1e-12);
    }

    #[test]
    fn csv_errors_name_file_line_and_problem() {
        let e = parse("t,x,y,z,roll,pitch,heading\n1,0,0,0,0,0,0\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("traj.csv") && e.contains("bad header") && e.contains("\"time\""),
            "{e}"
        );
        let e = parse("").unwrap_err().to_string();
        assert!(e.contains("no header"), "{e}");
        let e = parse("time,x,y,z,roll,pitch,heading\n1,0,0,0,0,0,0\n2,NaN,0,0,0,0,0\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("line 3") && e.contains("column x") && e.contains("finite"),
            "{e}"
        );
        let e = parse("time,x,y,z,roll,pitch,heading\n1,0,0,0,0,0,0\n2,abc,0,0,0,0,0\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("not a number"), "{e}");
        let e = parse("time,x,y,z,roll,pitch,heading\n2,0,0,0,0,0,0\n1,0,0,0,0,0,0\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("line 3") && e.contains("strictly increase"),
            "{e}"
        );
        let e = parse("time,x,y,z,roll,pitch,heading\n2,0,0,0,0,0,0\n2,0,0,0,0,0,0\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("strictly increase"), "{e}");
        let e = parse("time,x,y,z,roll,pitch,heading\n2,0,0,0,0,0,0\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("at least two"), "{e}");
        let e = parse("time,x,y,z,roll,pitch,heading\n1,0,0,0,0,0\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("column heading") && e.contains("missing"), "{e}");
    }

    #[test]
    fn coverage_counts_points_outside_and_rejects_other_time_bases() {
        let tr = Trajectory {
            samples: vec![pose(10.0, 0.0, 0.0), pose(20.0, 100.0, 0.0)],
        };
        let t: Vec<f64> = (0..31).map(|k| k as f64).collect(); // 0..=30
        let c = tr
            .coverage(&t, Path::new("tr.csv"), Path::new("p.las"))
            .unwrap();
        // 10..=20 covered: indices 10..21.
        assert_eq!(
            (c.start, c.end, c.before, c.after, c.dropped()),
            (10, 21, 10, 10, 20)
        );
        // GPS week seconds (~3e5) against adjusted standard time (~4e8).
        let tr = Trajectory {
            samples: vec![pose(4.0e8, 0.0, 0.0), pose(4.0e8 + 60.0, 100.0, 0.0)],
        };
        let t = [300_000.0, 300_030.0];
        let e = tr
            .coverage(&t, Path::new("tr.csv"), Path::new("p.las"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("tr.csv")
                && e.contains("p.las")
                && e.contains("400000000.000")
                && e.contains("300000.000")
                && e.contains("GPS week seconds"),
            "{e}"
        );
    }
}
