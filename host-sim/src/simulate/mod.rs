//! The scene simulator behind `curbtrace simulate` (docs/spec.md §4): a physically modelled mobile
//! laser scanner driving through a street, writing `points.laz`, `trajectory.csv` and
//! `reference.geojson`.
//!
//! | module | what |
//! |---|---|
//! | [`centerline`] | the road centre line and road coordinates `(u, v)` |
//! | [`scene`] | scene descriptions in road coordinates and the curb toe lines they imply |
//! | [`scenes`] | the named scenes, one file each |
//! | [`world`] | building the world: ground, walls, poles, parked cars, weeds, leaves |
//! | [`ground`] | road, curbs (batter, rounded top), curb cuts, sidewalks as an exact height field |
//! | [`prims`] | walls, fences, parked cars, poles, weeds, leaves, and the ray walk through them |
//! | [`dual`] | two profilers in an X (`--scanners 2`): the mirrored second scanner, interleaved returns, a reference per scanner |
//! | [`passes`] | the street driven twice (`--passes 2`): the second pass back the other way, offset |
//! | [`drive`] | the vehicle's path, speed and attitude → the 200 Hz trajectory |
//! | [`scanner`] | the VQ-250-like profiler: pulse directions and timing, noise, intensity |
//! | [`spinning`] | spinning multi-beam lidars (VLP-16, HDL-32E, HDL-64E, OS1-64) on the roof |
//! | [`reference`](mod@reference) | the visibility rule and the reference lines |
//! | [`write`](mod@write) | LAS 1.4 / LAZ and the trajectory CSV |
//!
//! Physics in one paragraph: a full-circle profiler (100 lines/s, 2000 pulses/line, 2 m
//! above the road, scan plane yawed 45° and tilted 40°, see [`scanner`]) fires every pulse
//! at its own time from the pose interpolated at that time; a pulse returns from the first
//! surface it meets — the exact ground with its curbs ([`ground`]) or an object
//! ([`prims`]) — with Gaussian range noise (σ 5 mm) and rare outliers (2·10⁻⁴, up to metres
//! off); pulses into the sky, nearer than 1.5 m, or into the vehicle's own body return
//! nothing. Intensity is Lambertian with material reflectance and speckle. The scan angle
//! (degrees in the scan plane from its lowest direction, −180° at the top where a line
//! starts) is stored rounded to LAS units. The reference rule is in [`reference`](mod@reference).
//!
//! Determinism: every scan line draws its noise from its own generator seeded by
//! `(seed, line number)`, and lines are gathered in order, so the output is identical for
//! any number of threads.
//!
//! Coordinates: the scene is built in local metres; files carry the scene's CRS coordinates
//! (JGD2011 / UTM zone 54N, EPSG:6691, hundreds of kilometres from the origin), GPS times are
//! adjusted standard GPS time near 4e8 s.
//!
//! ```no_run
//! let spec = curbtrace_host_sim::simulate::scene_by_name("tiny").unwrap();
//! let summary = curbtrace_host_sim::simulate::run(&spec, 1, None, std::path::Path::new("out"), false).unwrap();
//! println!("{} points", summary.points);
//! ```

pub mod centerline;
pub mod drive;
pub mod dual;
pub mod ground;
pub mod passes;
pub mod prims;
pub mod reference;
pub mod scanner;
pub mod scene;
pub mod scenes;
pub mod spinning;
pub mod world;
pub mod write;

pub use scene::SceneSpec;
pub use scenes::SCENE_NAMES;
pub use world::World;

/// The brief's name for a scene description.
pub type Scene = SceneSpec;

use crate::io::trajectory::Trajectory;
use crate::model::{Category, Crs, EdgeLine};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Errors of the simulator.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// No scene of that name.
    #[error("unknown scene {name:?}; valid scenes: {}, random", SCENE_NAMES.join(", "))]
    UnknownScene {
        /// The name asked for.
        name: String,
    },
    /// A parameter is out of range.
    #[error("{0}")]
    BadParameter(String),
    /// A file could not be written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        source: std::io::Error,
    },
    /// The LAS/LAZ or GeoJSON writer failed.
    #[error("{path}: {what}")]
    Write {
        /// The file.
        path: String,
        /// What went wrong.
        what: String,
    },
}

/// A built-in scene by name, or an error listing the valid names.
pub fn scene_by_name(name: &str) -> Result<SceneSpec, SimError> {
    SceneSpec::by_name(name).ok_or_else(|| SimError::UnknownScene { name: name.into() })
}

/// A named scene, or for `random` the random street of `seed`
/// ([`scenes::random::random`]).
pub fn scene_for(name: &str, seed: u64) -> Result<SceneSpec, SimError> {
    if name == "random" {
        Ok(scenes::random::random(seed))
    } else {
        scene_by_name(name)
    }
}

/// A finished simulation in memory (scene-local coordinates for points and trajectory).
pub struct Simulation {
    /// The world that was scanned.
    pub world: World,
    /// Returns in time order.
    pub returns: Vec<scanner::Return>,
    /// The trajectory (scene-local).
    pub traj: Trajectory,
    /// Reference lines (CRS coordinates).
    pub reference: Vec<EdgeLine>,
    /// Reference lines under the rule without joining gaps (`reference::Visibility::strict`).
    pub reference_strict: Vec<EdgeLine>,
    /// Number of scan lines.
    pub lines: usize,
    /// Driven length during the scan, metres.
    pub length_m: f64,
    /// Scan span, GPS seconds.
    pub scan: (f64, f64),
}

impl Simulation {
    /// The returns' world coordinates (the scene origin added back), as x, y, z columns.
    pub fn world_columns(&self) -> [Vec<f64>; 3] {
        let o = self.world.spec.origin;
        let col = |k: usize| self.returns.iter().map(|r| r.p[k] + o[k]).collect();
        [col(0), col(1), col(2)]
    }

    /// The trajectory's world x, y (the scene origin added back).
    pub fn world_trajectory_xy(&self) -> Vec<[f64; 2]> {
        let o = self.world.spec.origin;
        self.traj
            .samples
            .iter()
            .map(|p| [p.x + o[0], p.y + o[1]])
            .collect()
    }
}

/// What a run produced.
#[derive(Clone, Debug)]
pub struct SimSummary {
    /// Scene name.
    pub scene: String,
    /// Points written.
    pub points: usize,
    /// Scan lines.
    pub lines: usize,
    /// Driven length during the scan, metres.
    pub length_m: f64,
    /// Scan duration, seconds.
    pub duration_s: f64,
    /// Reference length per category, metres, in [`Category::REFERENCE`] order.
    pub reference_m: [f64; 4],
    /// Wall-clock seconds for the whole run.
    pub elapsed_s: f64,
    /// Of which building the world and casting the rays.
    pub simulate_s: f64,
    /// Of which writing the files.
    pub write_s: f64,
    /// `points.laz`.
    pub points_path: PathBuf,
    /// `trajectory.csv`.
    pub trajectory_path: PathBuf,
    /// `reference.geojson`.
    pub reference_path: PathBuf,
    /// The CRS written.
    pub crs: Crs,
}

impl SimSummary {
    /// The summary of `sim` of `spec` written to `[points, trajectory, reference]` in
    /// `crs`: the run started at `start`, its first `simulate_s` seconds simulating.
    pub fn of(
        spec: &SceneSpec,
        sim: &Simulation,
        start: Instant,
        simulate_s: f64,
        [points_path, trajectory_path, reference_path]: [PathBuf; 3],
        crs: Crs,
    ) -> Self {
        let mut reference_m = [0.0; 4];
        for l in &sim.reference {
            if let Some(c) = l.category {
                let i = Category::REFERENCE
                    .iter()
                    .position(|&x| x == c)
                    .unwrap_or(0);
                reference_m[i] += l.length_m();
            }
        }
        let elapsed_s = start.elapsed().as_secs_f64();
        SimSummary {
            scene: spec.name.clone(),
            points: sim.returns.len(),
            lines: sim.lines,
            length_m: sim.length_m,
            duration_s: sim.scan.1 - sim.scan.0,
            reference_m,
            elapsed_s,
            simulate_s,
            write_s: elapsed_s - simulate_s,
            points_path,
            trajectory_path,
            reference_path,
            crs,
        }
    }
}

fn line_seed(seed: u64, k: u64) -> u64 {
    // splitmix64 of the pair: independent streams per line, fixed by (seed, k) alone.
    let mut z = seed ^ k.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ 0x243F_6A88_85A3_08D3;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Simulates a scene in memory. `speed_kmh` overrides the scene's speed.
pub fn simulate(
    spec: &SceneSpec,
    seed: u64,
    speed_kmh: Option<f64>,
    progress: bool,
) -> Result<Simulation, SimError> {
    simulate_with(spec, seed, speed_kmh, None, progress)
}

/// [`simulate`] with the scene's profiler, or with the spinning `sensor` on the roof
/// instead (its revolutions are the simulation's lines).
pub fn simulate_with(
    spec: &SceneSpec,
    seed: u64,
    speed_kmh: Option<f64>,
    sensor: Option<&spinning::SpinSensor>,
    progress: bool,
) -> Result<Simulation, SimError> {
    let mut spec = spec.clone();
    if let Some(s) = sensor {
        // Whole revolutions cover the drive; the noise is the sensor's.
        spec.scanner.line_rate_hz = s.rate_hz;
        spec.scanner.range_sigma_m = s.range_sigma_m;
    }
    let spec = &spec;
    let speed = speed_kmh.unwrap_or(spec.speed_kmh);
    if !(speed.is_finite() && (1.0..=120.0).contains(&speed)) {
        return Err(SimError::BadParameter(format!(
            "speed {speed} km/h is out of range (1–120)"
        )));
    }
    let world = World::build(spec.clone(), seed);
    let drive = drive::plan(&world, speed, seed);
    if let Some(sensor) = sensor {
        return Ok(simulate_revolutions(world, drive, sensor, seed, progress));
    }
    let (returns, lines) = cast_drive(&world, &drive, seed, progress);
    let [reference, reference_strict] = references(&world, &mut returns.iter(), &drive.traj);
    Ok(Simulation {
        world,
        returns,
        traj: drive.traj,
        reference,
        reference_strict,
        lines,
        length_m: drive.length_m,
        scan: drive.scan,
    })
}

/// The reference lines of what `returns` observed, with gaps joined and without
/// (`reference::Visibility::strict`).
pub(crate) fn references(
    world: &World,
    returns: &mut dyn Iterator<Item = &scanner::Return>,
    traj: &Trajectory,
) -> [Vec<EdgeLine>; 2] {
    let mut vis = reference::Visibility::new(&world.ground);
    for r in returns {
        if let Some(tc) = &r.toe {
            vis.add(tc);
        }
    }
    let origin = world.spec.origin;
    [
        reference::reference_lines(&world.ground, &vis, traj, origin),
        reference::reference_lines(&world.ground, &vis.strict(), traj, origin),
    ]
}

/// The scene's profiler over `drive`: every line from its own generator seeded by
/// `(seed, line)`, gathered in order; the returns and the number of lines.
pub(crate) fn cast_drive(
    world: &World,
    drive: &drive::Drive,
    seed: u64,
    progress: bool,
) -> (Vec<scanner::Return>, usize) {
    let cfg = world.spec.scanner;
    let dirs = scanner::mount_directions(&cfg);
    let own: Vec<bool> = dirs
        .iter()
        .map(|&d| scanner::hits_own_vehicle(d, cfg.height_m, &cfg.body))
        .collect();
    let lines = ((drive.scan.1 - drive.scan.0) * cfg.line_rate_hz).round() as usize;
    let bar = progress.then(|| {
        let b = indicatif::ProgressBar::new(lines as u64);
        b.set_style(
            indicatif::ProgressStyle::with_template("{msg} {bar:40} {pos}/{len} lines, {eta}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        b.set_message(format!("simulating {}", world.spec.name));
        b
    });
    let per_line: Vec<Vec<scanner::Return>> = (0..lines)
        .into_par_iter()
        .map(|k| {
            let mut rng = ChaCha8Rng::seed_from_u64(line_seed(seed, k as u64));
            let t_line = drive.scan.0 + k as f64 / cfg.line_rate_hz;
            let r = scanner::cast_line(world, &drive.traj, &dirs, &own, t_line, &mut rng);
            if let Some(b) = &bar {
                b.inc(1);
            }
            r
        })
        .collect();
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    (per_line.into_iter().flatten().collect(), lines)
}

/// The revolutions of a spinning sensor over the drive, every one from its own generator
/// seeded by `(seed, revolution)`, gathered in order.
fn simulate_revolutions(
    world: World,
    drive: drive::Drive,
    sensor: &spinning::SpinSensor,
    seed: u64,
    progress: bool,
) -> Simulation {
    let revs = ((drive.scan.1 - drive.scan.0) * sensor.rate_hz).round() as usize;
    let bar = progress.then(|| {
        let b = indicatif::ProgressBar::new(revs as u64);
        b.set_message(format!(
            "simulating {} with {}",
            world.spec.name, sensor.name
        ));
        b
    });
    let per_rev: Vec<Vec<scanner::Return>> = (0..revs)
        .into_par_iter()
        .map(|k| {
            let mut rng = ChaCha8Rng::seed_from_u64(line_seed(seed, k as u64));
            let t_rev = drive.scan.0 + k as f64 / sensor.rate_hz;
            let r = spinning::cast_revolution(&world, &drive.traj, sensor, t_rev, &mut rng);
            if let Some(b) = &bar {
                b.inc(1);
            }
            r
        })
        .collect();
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let returns: Vec<scanner::Return> = per_rev.into_iter().flatten().collect();
    let [reference, reference_strict] = references(&world, &mut returns.iter(), &drive.traj);
    Simulation {
        world,
        returns,
        traj: drive.traj,
        reference,
        reference_strict,
        lines: revs,
        length_m: drive.length_m,
        scan: drive.scan,
    }
}

/// Simulates a scene and writes `points.laz`, `trajectory.csv`, `reference.geojson` and
/// `reference_strict.geojson` into `out_dir` (created if missing).
pub fn run(
    spec: &SceneSpec,
    seed: u64,
    speed_kmh: Option<f64>,
    out_dir: &Path,
    progress: bool,
) -> Result<SimSummary, SimError> {
    run_with(spec, seed, speed_kmh, None, out_dir, progress)
}

/// Writes every toe line of the street that `run` would simulate to `path` (GeoJSON, the
/// reference's format), seen or not: the reference without its visibility rule. Nothing is
/// scanned. Extracted length that lies off the reference but on these lines lies in the
/// reference's holes (docs/simulator.md).
pub fn write_whole_toes(
    spec: &SceneSpec,
    seed: u64,
    speed_kmh: Option<f64>,
    path: &Path,
) -> Result<(), SimError> {
    let world = World::build(spec.clone(), seed);
    let speed = speed_kmh.unwrap_or(spec.speed_kmh);
    let drive = drive::plan(&world, speed, seed);
    let vis = reference::Visibility::everywhere(&world.ground);
    let lines = reference::reference_lines(&world.ground, &vis, &drive.traj, world.spec.origin);
    write::write_reference(path, &lines, &write::crs_for(spec.epsg))
}

/// How a spinning sensor's run is written: the sensor, and the name of the ring's
/// extra-bytes dimension (`None`: no ring dimension, as some converters write).
#[derive(Clone, Copy, Debug)]
pub struct SpinOutput<'a> {
    /// The sensor.
    pub sensor: &'a spinning::SpinSensor,
    /// `ring`, `laser_id`, `channel`, or `None`.
    pub ring_name: Option<&'a str>,
}

/// [`run`] with the scene's profiler or a spinning sensor (`spin`).
pub fn run_with(
    spec: &SceneSpec,
    seed: u64,
    speed_kmh: Option<f64>,
    spin: Option<SpinOutput<'_>>,
    out_dir: &Path,
    progress: bool,
) -> Result<SimSummary, SimError> {
    let start = Instant::now();
    std::fs::create_dir_all(out_dir).map_err(|source| SimError::Io {
        path: out_dir.display().to_string(),
        source,
    })?;
    let sim = simulate_with(spec, seed, speed_kmh, spin.map(|s| s.sensor), progress)?;
    let simulate_s = start.elapsed().as_secs_f64();
    let ring = spin.and_then(|s| s.ring_name);
    write_run(spec, &sim, None, ring, out_dir, start, simulate_s)
}

/// Writes `sim`'s `points.laz` (return `i` on scanner channel `channels[i]` when given, the
/// ring as the extra-bytes dimension `ring` when given), `trajectory.csv`,
/// `reference.geojson` and `reference_strict.geojson` into `out_dir`, and sums the run up:
/// it started at `start` and spent its first `simulate_s` seconds simulating.
pub(crate) fn write_run(
    spec: &SceneSpec,
    sim: &Simulation,
    channels: Option<&[u8]>,
    ring: Option<&str>,
    out_dir: &Path,
    start: Instant,
    simulate_s: f64,
) -> Result<SimSummary, SimError> {
    let origin = sim.world.spec.origin;
    let points_path = out_dir.join("points.laz");
    let trajectory_path = out_dir.join("trajectory.csv");
    let reference_path = out_dir.join("reference.geojson");
    write::write_points_channels(
        &points_path,
        &sim.returns,
        channels,
        origin,
        spec.epsg,
        ring,
    )?;
    write::write_trajectory(&trajectory_path, &sim.traj, origin)?;
    let crs = write::crs_for(spec.epsg);
    write::write_reference(&reference_path, &sim.reference, &crs)?;
    let strict_path = out_dir.join("reference_strict.geojson");
    write::write_reference(&strict_path, &sim.reference_strict, &crs)?;
    Ok(SimSummary::of(
        spec,
        sim,
        start,
        simulate_s,
        [points_path, trajectory_path, reference_path],
        crs,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Side;
    use std::sync::OnceLock;

    fn tiny() -> &'static Simulation {
        static SIM: OnceLock<Simulation> = OnceLock::new();
        SIM.get_or_init(|| simulate(&scene_by_name("tiny").unwrap(), 7, None, false).unwrap())
    }

    /// A bare straight road driven due east (heading 90°), no clutter.
    fn east_spec(drive_m: f64) -> SceneSpec {
        let mut s = scene_by_name("tiny").unwrap();
        s.heading_deg = 90.0;
        s.drive = (0.0, drive_m);
        s.base.wave_m = 0.0;
        s.curb_cuts.clear();
        s.weeds.clear();
        s.leaves_per_100m = 0.0;
        s
    }

    #[test]
    fn driving_east_gives_heading_90_and_left_is_north() {
        let world = World::build(east_spec(10.0), 3);
        let d = drive::plan(&world, 30.0, 3);
        let s = &d.traj.samples;
        assert!(s.len() > 200);
        for w in s.windows(2) {
            assert!(
                (w[0].heading_deg - 90.0).abs() < 1e-6,
                "{}",
                w[0].heading_deg
            );
            assert!(w[1].x > w[0].x && (w[1].t - w[0].t - 0.005).abs() < 1e-6);
        }
        // Road half width 4 m, lane 2.3 m from the left curb: the left toe (first toe,
        // built for Side::Left) lies 2.3 m north of the path.
        let toe = &world.ground.toes[0];
        let mid = toe.pts[toe.pts.len() / 2];
        assert!(
            (mid[1] - s[0].y - 2.3).abs() < 0.05,
            "{} {}",
            mid[1],
            s[0].y
        );
        // The scanner origin is 2 m above the road (cross slope ~2 % → roll ~1°).
        let road = world.ground.height(s[0].x, s[0].y).unwrap().0;
        assert!((s[0].z - road - 2.0).abs() < 0.05);
    }

    #[test]
    fn whole_toes_hold_the_reference_and_more() {
        let sim = tiny();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("toes.geojson");
        write_whole_toes(&scene_by_name("tiny").unwrap(), 7, None, &path).unwrap();
        let (whole, _) = crate::model::read_geojson(&path).unwrap();
        let length = |ls: &[EdgeLine]| ls.iter().map(EdgeLine::length_m).sum::<f64>();
        assert!(length(&whole) > length(&sim.reference) + 1.0);
        // Every reference vertex is a vertex of a whole toe line (same world, same rule
        // for side and category, only the visibility differs).
        for line in &sim.reference {
            for p in &line.points {
                let on = whole.iter().any(|w| {
                    w.side == line.side
                        && w.points
                            .iter()
                            .any(|q| (q[0] - p[0]).hypot(q[1] - p[1]) < 1e-3)
                });
                assert!(on, "reference vertex {p:?} is on no whole toe line");
            }
        }
    }

    #[test]
    fn left_reference_lines_have_positive_x_prime() {
        let sim = tiny();
        let o = sim.world.spec.origin;
        let (mut left, mut right) = (0.0, 0.0);
        for line in &sim.reference {
            for p in &line.points {
                let (x, y) = (p[0] - o[0], p[1] - o[1]);
                let q = sim
                    .traj
                    .samples
                    .iter()
                    .min_by(|a, b| {
                        let da = (a.x - x).powi(2) + (a.y - y).powi(2);
                        let db = (b.x - x).powi(2) + (b.y - y).powi(2);
                        da.total_cmp(&db)
                    })
                    .unwrap();
                let l = q.left();
                let xp = (x - q.x) * l[0] + (y - q.y) * l[1];
                match line.side {
                    Side::Left => assert!(xp > 1.0, "left vertex at x′ = {xp}"),
                    Side::Right => assert!(xp < -1.0, "right vertex at x′ = {xp}"),
                }
            }
            match line.side {
                Side::Left => left += line.length_m(),
                Side::Right => right += line.length_m(),
            }
        }
        // Both curbs seen over about the drive (30 m) plus what the tilted plane sees
        // before the start and after the end.
        assert!(left > 28.0 && left < 45.0, "left {left}");
        assert!(right > 28.0 && right < 45.0, "right {right}");
    }

    #[test]
    fn pulses_increase_in_time_on_the_pulse_clock() {
        let sim = tiny();
        let dt = 1.0 / 200_000.0;
        for w in sim.returns.windows(2) {
            let d = w[1].t - w[0].t;
            assert!(d > 0.0, "time goes back");
            let k = (d / dt).round();
            assert!((d - k * dt).abs() < 1e-7, "off the pulse clock: {d}");
        }
        assert!(
            (sim.returns[0].t - drive::T0_GPS) >= 0.0 && sim.returns[0].t < drive::T0_GPS + 0.01
        );
    }

    #[test]
    fn tiny_counts_are_plausible() {
        let sim = tiny();
        let dur = sim.scan.1 - sim.scan.0;
        assert_eq!(sim.lines, (dur * 100.0).round() as usize);
        // 30 m at 30 km/h ± 7 %: 3.4–3.9 s.
        assert!(dur > 3.3 && dur < 3.9, "{dur}");
        let pulses = sim.lines * 2000;
        let share = sim.returns.len() as f64 / pulses as f64;
        // Half the circle looks down at the road, most of the upper half at walls; the
        // vehicle body and open sky return nothing.
        assert!(share > 0.5 && share < 0.9, "{share}");
        let cut: f64 = sim
            .reference
            .iter()
            .filter(|l| l.category == Some(Category::CurbCut))
            .map(|l| l.length_m())
            .sum();
        // 4 m lowered + two 1 m ramps.
        assert!((cut - 6.0).abs() < 0.6, "{cut}");
    }

    #[test]
    fn written_files_round_trip_with_crs_offsets() {
        let dir = tempfile::tempdir().unwrap();
        let spec = east_spec(3.0);
        let s = run(&spec, 5, None, dir.path(), false).unwrap();
        let sim = simulate(&spec, 5, None, false).unwrap();
        assert_eq!(s.points, sim.returns.len());
        let mut r = las::Reader::from_path(&s.points_path).unwrap();
        let h = r.header().clone();
        assert_eq!(h.version(), las::Version::new(1, 4));
        assert_eq!(h.point_format().to_u8().unwrap(), 6);
        assert_eq!(h.transforms().x.scale, 0.001);
        assert_eq!(h.transforms().x.offset, spec.origin[0].floor());
        assert_eq!(h.transforms().y.offset, spec.origin[1].floor());
        assert_eq!(h.number_of_points() as usize, s.points);
        let wkt = String::from_utf8_lossy(h.get_wkt_crs_bytes().unwrap()).to_string();
        assert!(wkt.contains("\"6691\""), "{wkt}");
        let pd = r.read_points(5000).unwrap();
        for (p, q) in pd.points().zip(&sim.returns) {
            let p = p.unwrap();
            let w = [
                q.p[0] + spec.origin[0],
                q.p[1] + spec.origin[1],
                q.p[2] + spec.origin[2],
            ];
            assert!((p.x - w[0]).abs() <= 0.0005 + 1e-9 && (p.y - w[1]).abs() <= 0.0005 + 1e-9);
            assert!((p.z - w[2]).abs() <= 0.0005 + 1e-9);
            assert!((p.x - 455000.0).abs() < 1000.0 && (p.y - 3951000.0).abs() < 2000.0);
            assert_eq!(p.gps_time, Some(q.t));
            assert!(q.t > 4.0e8 && q.t < 4.0001e8);
            assert!((p.scan_angle as f64 - q.scan_angle_deg).abs() <= 0.003 + 1e-6);
            assert_eq!(p.scanner_channel, 0);
            assert_eq!(p.point_source_id, 1);
        }
        let csv = std::fs::read_to_string(&s.trajectory_path).unwrap();
        let mut rows = csv.lines();
        assert_eq!(rows.next(), Some("time,x,y,z,roll,pitch,heading"));
        let first: Vec<f64> = rows
            .next()
            .unwrap()
            .split(',')
            .map(|v| v.parse().unwrap())
            .collect();
        assert!((first[0] - (drive::T0_GPS - drive::TRAJ_MARGIN_S)).abs() < 1e-6);
        assert!((first[6] - 90.0).abs() < 1e-4);
        assert!((first[1] - (sim.traj.samples[0].x + spec.origin[0])).abs() < 1e-4);
        let (refl, crs) = crate::model::read_geojson(&s.reference_path).unwrap();
        assert_eq!(crs, Some(Crs::Wkt(wkt)));
        assert_eq!(refl.len(), sim.reference.len());
    }

    #[test]
    fn output_does_not_depend_on_the_thread_count() {
        let spec = east_spec(1.0);
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let three = rayon::ThreadPoolBuilder::new()
            .num_threads(3)
            .build()
            .unwrap();
        let a = one.install(|| simulate(&spec, 11, None, false).unwrap());
        let b = three.install(|| simulate(&spec, 11, None, false).unwrap());
        assert_eq!(a.returns.len(), b.returns.len());
        for (x, y) in a.returns.iter().zip(&b.returns) {
            assert_eq!(x.p, y.p);
            assert_eq!(x.intensity, y.intensity);
        }
        let c = simulate(&spec, 12, None, false).unwrap();
        assert!(c.returns.iter().zip(&a.returns).any(|(x, y)| x.p != y.p));
    }

    #[test]
    fn unknown_scene_lists_the_valid_ones() {
        let e = scene_by_name("kawasakii").unwrap_err().to_string();
        assert!(
            e.contains("kawasakii") && e.contains("kawasaki, sapporo, curvy, tiny"),
            "{e}"
        );
        assert!(simulate(&east_spec(1.0), 1, Some(0.0), false).is_err());
    }
}

/// Pictures for a person checking the simulator by eye (`cargo test … -- --ignored`):
/// top views around a scene's features from a written `points.laz` and reference.
#[cfg(test)]
mod views {
    use super::*;
    use plotters::prelude::*;

    fn render(scene: &str, dir: &str, centers: &[(f64, f64)], half_m: f64) {
        let spec = scene_by_name(scene).unwrap();
        let world = World::build(spec.clone(), 1);
        let o = spec.origin;
        let mut r = las::Reader::from_path(format!("{dir}/points.laz")).unwrap();
        let pd = r.read_all().unwrap();
        let pts: Vec<[f64; 3]> = pd
            .x()
            .zip(pd.y())
            .zip(pd.z())
            .map(|((x, y), z)| [x - o[0], y - o[1], z - o[2]])
            .collect();
        let (refl, _) =
            crate::model::read_geojson(std::path::Path::new(&format!("{dir}/reference.geojson")))
                .unwrap();
        for (k, &(u, v)) in centers.iter().enumerate() {
            let c = world.center.map(u, v);
            let px = 800u32;
            let sc = px as f64 / (2.0 * half_m);
            let path = format!("/tmp/sim_views/{scene}_{k}_u{u:.0}.png");
            std::fs::create_dir_all("/tmp/sim_views").unwrap();
            let root = BitMapBackend::new(&path, (px, px)).into_drawing_area();
            root.fill(&BLACK).unwrap();
            let to_px = |x: f64, y: f64| {
                (
                    ((x - c[0] + half_m) * sc) as i32,
                    ((c[1] + half_m - y) * sc) as i32,
                )
            };
            for p in &pts {
                if (p[0] - c[0]).abs() > half_m || (p[1] - c[1]).abs() > half_m {
                    continue;
                }
                let h = p[2] - world.ground.base.at(p[0], p[1]);
                let f = ((h + 0.05) / 0.45).clamp(0.0, 1.0);
                let col = if h > 0.5 {
                    RGBColor(90, 90, 90)
                } else {
                    RGBColor(
                        (255.0 * f) as u8,
                        (255.0 * (1.0 - (2.0 * f - 1.0).abs())) as u8,
                        (255.0 * (1.0 - f)) as u8,
                    )
                };
                root.draw_pixel(to_px(p[0], p[1]), &col).unwrap();
            }
            for l in &refl {
                let col = if l.side == crate::model::Side::Left {
                    RED
                } else {
                    WHITE
                };
                let col = match l.category {
                    Some(Category::CurbCut) => MAGENTA,
                    Some(Category::Intersection) => YELLOW,
                    Some(Category::BusBay) => CYAN,
                    _ => col,
                };
                let pts: Vec<_> = l
                    .points
                    .iter()
                    .map(|p| to_px(p[0] - o[0], p[1] - o[1]))
                    .collect();
                root.draw(&PathElement::new(pts, col.stroke_width(1)))
                    .unwrap();
            }
            root.present().unwrap();
        }
    }

    #[test]
    #[ignore]
    fn render_views() {
        let which = std::env::var("SIM_VIEW").unwrap_or_else(|_| "tiny".into());
        let dir = format!("/tmp/sim_{which}");
        let centers: Vec<(f64, f64)> = match which.as_str() {
            "kawasaki" => vec![
                (52.0, 4.0),
                (95.0, 8.0),
                (125.0, 4.0),
                (215.0, 5.0),
                (255.0, -8.0),
                (175.0, 0.0),
            ],
            "sapporo" => vec![(120.0, 6.0), (222.0, 0.0), (275.0, -8.0), (95.0, -3.0)],
            "curvy" => vec![(120.0, 0.0), (60.0, -3.0)],
            _ => vec![(15.0, 0.0)],
        };
        render(&which, &dir, &centers, 15.0);
        if which == "kawasaki" {
            // Close-ups: weeds and leaves at the left curb; a parked car hiding the curb.
            render(&which, &dir, &[(30.0, 5.0), (68.0, 4.5)], 3.0);
        }
    }
}
