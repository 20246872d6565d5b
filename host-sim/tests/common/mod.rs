//! Test support: a synthetic straight road scanned by a rotating profiler, written as LAS/LAZ
//! with its trajectory CSV, and the known curb toe lines.
#![allow(dead_code)]

use las::{Builder, Point, Writer};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::io::Write;
use std::path::{Path, PathBuf};

/// World origin of the scenes (a projected CRS, large coordinates as in real data).
pub const X0: f64 = 500_000.0;
/// World origin.
pub const Y0: f64 = 4_000_000.0;
/// GPS time at the start (adjusted standard GPS time, about 4e8 s).
pub const T0: f64 = 400_000_000.0;

/// A straight road along +Y (heading 0): road surface at z = 0 for |x| < half_width, curbs
/// of `curb_m` height, sidewalks to |x| = 6 m, walls up to 8 m; the scanner at 2 m height
/// drives along x = X0.
#[derive(Clone, Copy, Debug)]
pub struct Road {
    /// Length driven, metres.
    pub length_m: f64,
    /// Speed, m/s.
    pub speed_mps: f64,
    /// Scanner revolutions per second.
    pub line_rate_hz: f64,
    /// Angular step, degrees.
    pub step_deg: f64,
    /// Half the road width: the toes are at x = ±half_width.
    pub half_width_m: f64,
    /// Curb height, metres.
    pub curb_m: f64,
    /// Range noise (σ), metres.
    pub noise_m: f64,
    /// Random seed.
    pub seed: u64,
}

impl Default for Road {
    fn default() -> Self {
        Self {
            length_m: 30.0,
            speed_mps: 8.0,
            line_rate_hz: 100.0,
            step_deg: 0.25,
            half_width_m: 3.5,
            curb_m: 0.15,
            noise_m: 0.002,
            seed: 7,
        }
    }
}

const SCANNER_H: f64 = 2.0;
const SIDEWALK_END: f64 = 6.0;
const WALL_TOP: f64 = 8.0;

impl Road {
    /// The profile as segments in the x′–z (world height) plane, left positive.
    fn segments(&self) -> Vec<[(f64, f64); 2]> {
        let (w, c) = (self.half_width_m, self.curb_m);
        let mut s = vec![[(-w, 0.0), (w, 0.0)]];
        for sg in [1.0, -1.0] {
            s.push([(sg * w, 0.0), (sg * w, c)]);
            s.push([(sg * w, c), (sg * SIDEWALK_END, c)]);
            s.push([(sg * SIDEWALK_END, c), (sg * SIDEWALK_END, WALL_TOP)]);
        }
        s
    }

    /// Range along the ray at angle θ from nadir (left positive) to the first hit.
    fn cast(&self, segs: &[[(f64, f64); 2]], theta: f64) -> Option<f64> {
        let (dx, dz) = (theta.sin(), -theta.cos());
        let mut best: Option<f64> = None;
        for s in segs {
            let (ax, az) = (s[0].0, s[0].1 - SCANNER_H);
            let (ex, ez) = (s[1].0 - s[0].0, s[1].1 - s[0].1);
            // Solve r·d = a + u·e.
            let den = dx * (-ez) - dz * (-ex);
            if den.abs() < 1e-12 {
                continue;
            }
            let r = (ax * (-ez) - az * (-ex)) / den;
            let u = (dx * az - dz * ax) / den;
            if r > 0.05 && (-1e-9..=1.0 + 1e-9).contains(&u) && best.is_none_or(|b| r < b) {
                best = Some(r);
            }
        }
        best
    }

    /// Writes `points` (LAS or LAZ by extension, format 6, EPSG 6677) and the trajectory
    /// CSV; returns the number of points.
    pub fn write(&self, points: &Path, trajectory: &Path) -> u64 {
        let segs = self.segments();
        let mut rng = ChaCha8Rng::seed_from_u64(self.seed);
        let mut b = Builder::from((1, 4));
        b.point_format = las::point::Format::new(6).unwrap();
        b.point_format.is_compressed = points.extension().is_some_and(|e| e == "laz");
        let t = |offset: f64| las::Transform {
            scale: 0.0001,
            offset,
        };
        b.transforms = las::Vector {
            x: t(X0),
            y: t(Y0),
            z: t(0.0),
        };
        let words: [u16; 8] = [1, 1, 0, 1, 3072, 0, 1, 6677];
        b.vlrs.push(las::Vlr {
            user_id: "LASF_Projection".into(),
            record_id: 34735,
            description: "GeoKeyDirectoryTag".into(),
            data: words.iter().flat_map(|w| w.to_le_bytes()).collect(),
        });
        let mut w = Writer::from_path(points, b.into_header().unwrap()).unwrap();
        let duration = self.length_m / self.speed_mps;
        let lines = (duration * self.line_rate_hz) as usize;
        let per_line = (360.0 / self.step_deg) as usize;
        let mut n = 0u64;
        for k in 0..lines {
            for j in 0..per_line {
                // One revolution from −180° (top) through 0° (nadir) to +180°.
                let deg = -180.0 + (j as f64 + 0.5) * self.step_deg;
                let tt = (k as f64 + (j as f64 + 0.5) / per_line as f64) / self.line_rate_hz;
                let Some(r) = self.cast(&segs, deg.to_radians()) else {
                    continue;
                };
                let r = r + self.noise_m * rng.sample::<f64, _>(rand_distr::StandardNormal);
                let th = deg.to_radians();
                let (xp, zp) = (r * th.sin(), -r * th.cos());
                // Heading 0 (north): left is −X.
                let steps = (deg / 0.006).round();
                w.write_point(Point {
                    x: X0 - xp,
                    y: Y0 + self.speed_mps * tt,
                    z: SCANNER_H + zp,
                    gps_time: Some(T0 + tt),
                    intensity: 100,
                    // las 0.11 truncates deg / 0.006 when writing: nudge away from zero.
                    scan_angle: ((steps + 0.25 * steps.signum()) * 0.006) as f32,
                    ..Default::default()
                })
                .unwrap();
                n += 1;
            }
        }
        w.close().unwrap();
        let mut f = std::fs::File::create(trajectory).unwrap();
        writeln!(f, "time,x,y,z,roll,pitch,heading").unwrap();
        let samples = (duration * 10.0).ceil() as usize + 1;
        for s in 0..=samples {
            let tt = s as f64 * 0.1 - 0.05;
            writeln!(
                f,
                "{:.4},{:.4},{:.4},{:.4},0,0,0",
                T0 + tt,
                X0,
                Y0 + self.speed_mps * tt,
                SCANNER_H
            )
            .unwrap();
        }
        n
    }

    /// The known toe lines in world X: (left, right).
    pub fn toe_x(&self) -> (f64, f64) {
        (X0 - self.half_width_m, X0 + self.half_width_m)
    }
}

/// Runs `curbtrace extract` and returns (success, stderr).
pub fn extract(points: &Path, traj: &Path, out: &Path) -> (bool, String) {
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_curbtrace"))
        .arg("extract")
        .arg(points)
        .arg("--trajectory")
        .arg(traj)
        .arg("-o")
        .arg(out)
        .output()
        .unwrap();
    (
        run.status.success(),
        String::from_utf8_lossy(&run.stderr).into_owned(),
    )
}

/// The `realdata` folder, if present: `$CURBTRACE_REALDATA`, else `shared/realdata` in the
/// parent of the workspace root or one of its next two ancestors (worktrees may sit one or
/// two levels deeper than the main checkout).
pub fn realdata_dir() -> Option<PathBuf> {
    if let Some(d) = std::env::var_os("CURBTRACE_REALDATA") {
        let d = PathBuf::from(d);
        return d.is_dir().then_some(d);
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).parent()?;
    root.ancestors()
        .skip(1)
        .take(3)
        .map(|a| a.join("shared/realdata"))
        .find(|d| d.is_dir())
}

/// The sub-folder `sub` of the data, or `None` after printing why the test is skipped.
pub fn data(sub: &str, test: &str) -> Option<PathBuf> {
    let found = realdata_dir().map(|d| d.join(sub)).filter(|d| d.is_dir());
    if found.is_none() {
        eprintln!(
            "skipped: {test}: {sub} not found (looked in $CURBTRACE_REALDATA and in \
             shared/realdata beside {}/.. and its parents)",
            env!("CARGO_MANIFEST_DIR")
        );
    }
    found
}
