//! The street driven twice (`curbtrace simulate --passes 2`): pass 0 is the one-pass run;
//! pass 1 drives the same path back, from the drive's end to its start, [`TURN_S`] seconds
//! after pass 0 ends, so its scanner looks at every curb from the other direction (the
//! left curb of pass 0 is on pass 1's right).
//!
//! Between passes the GNSS solution moves: pass 1's points and trajectory are shifted
//! horizontally by the offset (`--pass-offset`, 0.10 m by default; 5–20 cm is usual between
//! passes of a survey-grade system), in a direction drawn from the seed. The references are
//! in the true (pass 0's) frame. Both passes are in one file, one trajectory; nothing in
//! them says where a pass begins — `curbtrace extract` finds the passes from the
//! trajectory (`stream::passes`).
//!
//! Written beside the points: `reference.geojson` (what either pass observed) and
//! `reference_pass0.geojson`, `reference_pass1.geojson` (what each observed alone); `side`
//! is relative to pass 0's direction in all three.

use super::scanner::Return;
use super::{cast_drive, drive, references, simulate, SceneSpec, SimError, SimSummary, Simulation};
use crate::io::trajectory::Trajectory;
use crate::model::EdgeLine;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::Path;
use std::time::Instant;

/// Seconds between the end of pass 0's scan and the start of pass 1's (the turn).
pub const TURN_S: f64 = 60.0;

/// Largest GNSS offset between passes the simulator accepts, metres.
pub const MAX_OFFSET_M: f64 = 1.0;

/// Seeds of pass 1's lines and drive: apart from pass 0's.
const PASS_SEED: u64 = 0x9A55_0000_0000_0001;

/// A two-pass simulation: both passes' returns and trajectories in time order, and the
/// references of what each pass observed.
pub struct TwoPasses {
    /// Both passes; the reference is what either observed.
    pub sim: Simulation,
    /// What pass 0 and pass 1 observed, each alone.
    pub reference_each: [Vec<EdgeLine>; 2],
    /// Pass 1's GNSS offset from the truth, metres east and north (scene axes).
    pub offset_m: [f64; 2],
    /// The first time of pass 1's trajectory.
    pub second_start: f64,
}

/// Simulates `spec` driven there and back, pass 1 offset by `offset_m` metres.
pub fn simulate_passes(
    spec: &SceneSpec,
    seed: u64,
    speed_kmh: Option<f64>,
    offset_m: f64,
    progress: bool,
) -> Result<TwoPasses, SimError> {
    if !(offset_m.is_finite() && (0.0..=MAX_OFFSET_M).contains(&offset_m)) {
        return Err(SimError::BadParameter(format!(
            "pass offset {offset_m} m is out of range (0–{MAX_OFFSET_M})"
        )));
    }
    let first = simulate(spec, seed, speed_kmh, progress)?;
    let world = &first.world;
    let speed = speed_kmh.unwrap_or(spec.speed_kmh);
    let back = drive::plan_pass(world, speed, seed ^ PASS_SEED, true, first.scan.1 + TURN_S);
    let (mut second, lines) = cast_drive(world, &back, seed ^ PASS_SEED, progress);
    let reference_of = |rs: &mut dyn Iterator<Item = &Return>| references(world, rs, &first.traj);
    let [ref1, _] = reference_of(&mut second.iter());
    let [either, either_strict] = reference_of(&mut first.returns.iter().chain(&second));
    let angle = ChaCha8Rng::seed_from_u64(seed ^ PASS_SEED).gen_range(0.0..std::f64::consts::TAU);
    let off = [offset_m * angle.cos(), offset_m * angle.sin()];
    for r in &mut second {
        r.p[0] += off[0];
        r.p[1] += off[1];
    }
    let mut samples = first.traj.samples.clone();
    let second_start = back.traj.samples.first().map_or(back.scan.0, |s| s.t);
    samples.extend(back.traj.samples.into_iter().map(|mut s| {
        s.x += off[0];
        s.y += off[1];
        s
    }));
    let mut returns = first.returns;
    returns.extend(second);
    Ok(TwoPasses {
        reference_each: [first.reference, ref1],
        sim: Simulation {
            returns,
            traj: Trajectory { samples },
            reference: either,
            reference_strict: either_strict,
            lines: first.lines + lines,
            length_m: first.length_m + back.length_m,
            scan: (first.scan.0, back.scan.1),
            world: first.world,
        },
        offset_m: off,
        second_start,
    })
}

/// Simulates `spec` driven twice and writes `points.laz`, `trajectory.csv`, the
/// reference, the strict reference and each pass's reference into `out_dir`.
pub fn run_passes(
    spec: &SceneSpec,
    seed: u64,
    speed_kmh: Option<f64>,
    offset_m: f64,
    out_dir: &Path,
    progress: bool,
) -> Result<SimSummary, SimError> {
    let start = Instant::now();
    std::fs::create_dir_all(out_dir).map_err(|source| SimError::Io {
        path: out_dir.display().to_string(),
        source,
    })?;
    let two = simulate_passes(spec, seed, speed_kmh, offset_m, progress)?;
    let simulate_s = start.elapsed().as_secs_f64();
    let crs = super::write::crs_for(spec.epsg);
    for (name, lines) in ["reference_pass0.geojson", "reference_pass1.geojson"]
        .into_iter()
        .zip(&two.reference_each)
    {
        super::write::write_reference(&out_dir.join(name), lines, &crs)?;
    }
    super::write_run(spec, &two.sim, None, None, out_dir, start, simulate_s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_second_pass_drives_back_later_and_offset() {
        let mut spec = super::super::scene_by_name("tiny").unwrap();
        spec.drive.1 = spec.drive.0 + 12.0;
        let two = simulate_passes(&spec, 3, None, 0.1, false).unwrap();
        let r = &two.sim.returns;
        assert!(r.windows(2).all(|w| w[0].t < w[1].t), "time order");
        let s = &two.sim.traj.samples;
        assert!(
            s.windows(2).all(|w| w[0].t < w[1].t),
            "trajectory in time order"
        );
        let k = s.partition_point(|p| p.t < two.second_start);
        assert!(k > 0 && k < s.len());
        // Pass 1 heads the other way.
        let dh = (s[k + 100].heading_deg - s[100].heading_deg).rem_euclid(360.0);
        assert!((dh - 180.0).abs() < 10.0, "{dh}");
        assert!((two.offset_m[0].hypot(two.offset_m[1]) - 0.1).abs() < 1e-12);
        let len = |ls: &[EdgeLine]| ls.iter().map(|l| l.length_m()).sum::<f64>();
        let (e0, e1, either) = (
            len(&two.reference_each[0]),
            len(&two.reference_each[1]),
            len(&two.sim.reference),
        );
        assert!(
            either + 1e-6 >= e0.max(e1) && e0 > 5.0 && e1 > 5.0,
            "{e0} {e1} {either}"
        );
        assert!(simulate_passes(&spec, 3, None, 2.0, false).is_err());
    }
}
