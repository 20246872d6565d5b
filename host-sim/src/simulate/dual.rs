//! Two profilers in an "X" (`curbtrace simulate --scanners 2`), as survey systems carry
//! them (RIEGL VMX-2HA, Trimble MX9): scanner 0 is the scene's profiler at the
//! trajectory's reference point; scanner 1 has the mirrored yaw (its ground trace runs
//! ahead on the left and behind on the right, where scanner 0's runs behind on the left and
//! ahead on the right) and sits at [`SECOND_LEVER_ARM_M`] from it.
//!
//! Both fire at the same line and pulse rate, scanner 1 half a pulse period after scanner 0,
//! so their returns interleave in time in one LAS 1.4 file, told apart by the scanner
//! channel (0, 1) and the point source id (1, 2). Scanner 1's lines draw their noise from
//! generators of their own, so scanner 0's returns are those of the one-scanner run.
//!
//! Written beside the points: `mounts.toml` (the `[scanners]` table `curbtrace extract`
//! reads with `--mounts` or `--config`), `reference.geojson` (what either scanner
//! observed), and `reference_scanner0.geojson`, `reference_scanner1.geojson` (what each
//! observed alone).

use super::scanner::{self, Return, ScannerConfig, VehicleBody};
use super::{line_seed, references, simulate, SceneSpec, SimError, SimSummary, Simulation};
use crate::model::EdgeLine;
use crate::mounts::{Mount, Mounts};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use std::path::Path;
use std::time::Instant;

/// Scanner 1's lever arm from scanner 0 (the reference point): forward, left, up, metres.
/// Side by side on the rear platform, a little behind and above.
pub const SECOND_LEVER_ARM_M: [f64; 3] = [-0.4, -0.7, 0.05];

/// A two-scanner simulation: the returns of both in time order with their channel, and the
/// references of what each observed.
pub struct TwoScanners {
    /// Both scanners' returns in time order; the reference is what either observed.
    pub sim: Simulation,
    /// The scanner channel of each return.
    pub channel: Vec<u8>,
    /// What scanner 0 and scanner 1 observed, each alone.
    pub reference_each: [Vec<EdgeLine>; 2],
    /// The scanners' mounts relative to the trajectory (scanner 0's origin).
    pub mounts: Mounts,
}

/// The mounts of the two scanners of `cfg`: scanner 0 at the reference point with the
/// scene's yaw and tilt, scanner 1 mirrored at [`SECOND_LEVER_ARM_M`]. The angles are the
/// scan plane's yaw and tilt as the simulator defines them (docs/simulator.md).
pub fn mounts_of(cfg: &ScannerConfig) -> Mounts {
    let mut m = Mounts::default();
    m.set(
        0,
        Mount {
            yaw_deg: cfg.yaw_deg,
            pitch_deg: cfg.pitch_deg,
            ..Mount::default()
        },
    );
    m.set(
        1,
        Mount {
            lever_arm_m: SECOND_LEVER_ARM_M,
            yaw_deg: -cfg.yaw_deg,
            pitch_deg: cfg.pitch_deg,
            ..Mount::default()
        },
    );
    m
}

/// Whether a body-frame direction from a scanner at `lever` (from scanner 0) hits the
/// vehicle: the body box of [`scanner::hits_own_vehicle`] seen from the other origin.
fn hits_body(d: [f64; 3], height_m: f64, body: &VehicleBody, lever: [f64; 3]) -> bool {
    let lo = [
        body.ahead_m.0 - lever[0],
        -body.half_width_m - lever[1],
        -height_m - lever[2],
    ];
    let hi = [
        body.ahead_m.1 - lever[0],
        body.half_width_m - lever[1],
        -body.roof_below_m - lever[2],
    ];
    let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
    for k in 0..3 {
        if d[k].abs() < 1e-12 {
            if 0.0 < lo[k] || 0.0 > hi[k] {
                return false;
            }
            continue;
        }
        let (a, b) = (lo[k] / d[k], hi[k] / d[k]);
        t0 = t0.max(a.min(b));
        t1 = t1.min(a.max(b));
    }
    t0 <= t1
}

/// Seeds of scanner 1's lines: apart from scanner 0's.
const SECOND_SEED: u64 = 0x5EC0_4D00_0000_0001;

/// Simulates `spec` with two scanners in an X.
pub fn simulate_two(
    spec: &SceneSpec,
    seed: u64,
    speed_kmh: Option<f64>,
    progress: bool,
) -> Result<TwoScanners, SimError> {
    let first = simulate(spec, seed, speed_kmh, progress)?;
    let cfg0 = first.world.spec.scanner;
    let mounts = mounts_of(&cfg0);
    let m1 = mounts.get(1);
    let cfg1 = ScannerConfig {
        yaw_deg: m1.yaw_deg,
        height_m: cfg0.height_m + m1.lever_arm_m[2],
        ..cfg0
    };
    let traj1 = m1.apply(&first.traj);
    let dirs = scanner::mount_directions(&cfg1);
    let own: Vec<bool> = dirs
        .iter()
        .map(|&d| hits_body(d, cfg0.height_m, &cfg0.body, m1.lever_arm_m))
        .collect();
    let half_pulse = 0.5 / (cfg0.line_rate_hz * cfg0.pulses_per_line as f64);
    let world = &first.world;
    let second: Vec<Return> = (0..first.lines)
        .into_par_iter()
        .map(|k| {
            let mut rng = ChaCha8Rng::seed_from_u64(line_seed(seed ^ SECOND_SEED, k as u64));
            let t_line = first.scan.0 + k as f64 / cfg0.line_rate_hz + half_pulse;
            scanner::cast_line(world, &traj1, &dirs, &own, t_line, &mut rng)
        })
        .collect::<Vec<_>>()
        .into_iter()
        .flatten()
        .collect();
    let reference_of = |rs: &mut dyn Iterator<Item = &Return>| references(world, rs, &first.traj);
    let ref0 = first.reference.clone();
    let [ref1, _] = reference_of(&mut second.iter());
    let [either, either_strict] = reference_of(&mut first.returns.iter().chain(&second));
    // Both in time order; scanner 1's pulses fall between scanner 0's.
    let (a, b) = (&first.returns, &second);
    let mut returns = Vec::with_capacity(a.len() + b.len());
    let mut channel = Vec::with_capacity(a.len() + b.len());
    let (mut i, mut j) = (0, 0);
    while i < a.len() || j < b.len() {
        if j >= b.len() || (i < a.len() && a[i].t <= b[j].t) {
            returns.push(a[i]);
            channel.push(0);
            i += 1;
        } else {
            returns.push(b[j]);
            channel.push(1);
            j += 1;
        }
    }
    Ok(TwoScanners {
        sim: Simulation {
            returns,
            reference: either,
            reference_strict: either_strict,
            ..first
        },
        channel,
        reference_each: [ref0, ref1],
        mounts,
    })
}

/// Simulates `spec` with two scanners and writes `points.laz`, `trajectory.csv`,
/// `mounts.toml`, the reference, the strict reference and each scanner's reference into
/// `out_dir`.
pub fn run_two(
    spec: &SceneSpec,
    seed: u64,
    speed_kmh: Option<f64>,
    out_dir: &Path,
    progress: bool,
) -> Result<SimSummary, SimError> {
    let start = Instant::now();
    let io_err = |path: &Path| {
        let path = path.display().to_string();
        move |source| SimError::Io { path, source }
    };
    std::fs::create_dir_all(out_dir).map_err(io_err(out_dir))?;
    let two = simulate_two(spec, seed, speed_kmh, progress)?;
    let simulate_s = start.elapsed().as_secs_f64();
    let mounts_path = out_dir.join("mounts.toml");
    let text = format!(
        "# Mounts of the simulated scanners relative to the trajectory (scanner 0's origin):\n# lever arm forward, left, up in metres; the angles are the scan plane's yaw and tilt.\n{}",
        two.mounts.to_toml()
    );
    std::fs::write(&mounts_path, text).map_err(io_err(&mounts_path))?;
    let crs = super::write::crs_for(spec.epsg);
    for (name, lines) in ["reference_scanner0.geojson", "reference_scanner1.geojson"]
        .into_iter()
        .zip(&two.reference_each)
    {
        super::write::write_reference(&out_dir.join(name), lines, &crs)?;
    }
    let channels = Some(two.channel.as_slice());
    super::write_run(spec, &two.sim, channels, None, out_dir, start, simulate_s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_scanners_interleave_in_time_and_each_sees_curb_the_other_does_not() {
        let mut spec = super::super::scene_by_name("tiny").unwrap();
        spec.drive.1 = spec.drive.0 + 12.0;
        let two = simulate_two(&spec, 3, None, false).unwrap();
        let r = &two.sim.returns;
        assert_eq!(r.len(), two.channel.len());
        assert!(r.windows(2).all(|w| w[0].t < w[1].t), "time order");
        let n1 = two.channel.iter().filter(|&&c| c == 1).count();
        let n0 = r.len() - n1;
        // Both scanners return about as many points (the mirror sees the mirrored street).
        assert!(
            n1 as f64 > 0.7 * n0 as f64 && (n1 as f64) < 1.3 * n0 as f64,
            "{n0} {n1}"
        );
        // Channels alternate: most neighbours in time are of different scanners.
        let switches = two.channel.windows(2).filter(|w| w[0] != w[1]).count();
        assert!(switches as f64 > 0.5 * r.len() as f64, "{switches}");
        let len = |ls: &[EdgeLine]| ls.iter().map(|l| l.length_m()).sum::<f64>();
        let (e0, e1, either) = (
            len(&two.reference_each[0]),
            len(&two.reference_each[1]),
            len(&two.sim.reference),
        );
        // What either observed is at least what each did.
        assert!(
            either + 1e-6 >= e0.max(e1) && e0 > 5.0 && e1 > 5.0,
            "{e0} {e1} {either}"
        );
        assert_eq!(two.mounts.get(1).lever_arm_m, SECOND_LEVER_ARM_M);
        assert_eq!(two.mounts.get(1).yaw_deg, -two.mounts.get(0).yaw_deg);
    }

    #[test]
    fn the_second_scanner_sees_the_body_from_its_own_origin() {
        let b = VehicleBody::default();
        // Straight ahead and down towards the body's middle from either origin.
        assert!(hits_body([0.7, 0.0, -0.7], 2.0, &b, [0.0; 3]));
        assert!(hits_body([0.7, 0.3, -0.7], 2.0, &b, SECOND_LEVER_ARM_M));
        // Up into the sky: nothing.
        assert!(!hits_body([0.0, 0.0, 1.0], 2.0, &b, SECOND_LEVER_ARM_M));
        // The zero lever arm agrees with the one-scanner rule on every direction.
        let cfg = ScannerConfig::default();
        for d in scanner::mount_directions(&cfg) {
            assert_eq!(
                hits_body(d, cfg.height_m, &cfg.body, [0.0; 3]),
                scanner::hits_own_vehicle(d, cfg.height_m, &cfg.body)
            );
        }
    }
}
