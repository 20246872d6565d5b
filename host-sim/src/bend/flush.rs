//! The toe of a flush crossing on a virtual profile: the line where the road's crossfall
//! meets the lowered sidewalk's slope, found by a hinge fit.
//!
//! Where a curb cut has no lip (or a few millimetres) and the sidewalk behind it is lowered
//! to the road instead of ramping up, the ground behind the toe rises only by the road's
//! crossfall and the sidewalk's slope, a few millimetres at a quarter metre: under
//! [`Profile::cut_toe`]'s least rise. The bend in slope is still there, but two free lines
//! place it loosely, since a free step between them trades against the break's place. Here
//! the two lines meet at the toe up to a step of a few millimetres (a hinge with a lip: the
//! road's line and the sidewalk's, the step between them at the break held to the lips of
//! flush crossings), which pins the break by all the points of both parts; a continuous
//! hinge would draw the break towards the road by the lip over the turn in slope. Meant
//! only for a track already following a cut, on the line it predicts.

use std::cmp::Ordering;

use super::profile::{Profile, ProfileToe, Sums};

/// Farthest the hinge may lie across the profile from its centre, metres: a cut keeps the
/// line of the curb it interrupts, so the toe stays near where the track predicts it.
const FLUSH_MAX_OFFSET_M: f64 = 0.15;

/// Step of the hinge positions tried across the profile, metres.
const FLUSH_STEP_M: f64 = 0.005;

/// Least turn upwards of the slope at the hinge (the sidewalk's slope less the road's):
/// a road's crossfall and a sidewalk's fall together give 2–5.5 %, a road's crown or rut
/// over a metre far less.
const FLUSH_MIN_BEND: f64 = 0.015;

/// Least turn upwards at the hinge in standard errors of that turn: on noisy or sparse
/// points a turn of a few per cent is no sign of a toe.
const FLUSH_MIN_SE: f64 = 5.0;

/// Steepest ground behind a flush toe, as a slope: a lowered sidewalk falls to the road at
/// a few per cent; steeper is a ramp, which [`Profile::cut_toe`] takes.
const FLUSH_MAX_BACK_SLOPE: f64 = 0.1;

/// Largest RMS of the hinge about its points, metres: twice the largest range noise of the
/// scanners simulated and modelled.
const FLUSH_MAX_RMS_M: f64 = 0.02;

/// Fewest points on each side of the hinge.
const FLUSH_MIN_SIDE: usize = 8;

/// Least reach of the points on each side of the hinge, metres: both slopes need a base.
const FLUSH_MIN_REACH_M: f64 = 0.3;

/// Largest lip a flush crossing's hinge takes as a step at the toe, metres: a lowered curb
/// of a few millimetres, under [`Profile::cut_toe`]'s least rise.
const FLUSH_MAX_LIP_M: f64 = 0.01;

/// A hinge fit with a step, `z = a + b1·min(c − t, 0) + b2·max(c − t, 0) + h·[c ≥ t]` at
/// the hinge `t`: the road's height at the hinge, both slopes, the step (the lip), the
/// residual sum of squares and the standard error of `b2 − b1` (heights relative to the
/// profile's first point, as [`Sums`] keeps them).
#[derive(Clone, Copy, Debug)]
struct Hinge {
    a: f64,
    b1: f64,
    b2: f64,
    h: f64,
    sse: f64,
    se_bend: f64,
}

/// Sums 1, c − t, (c − t)², z, z·(c − t), z² over `lo..hi` of the sorted profile, with
/// `h` taken off every height.
fn part(sums: &Sums, lo: usize, hi: usize, t: f64, h: f64) -> [f64; 6] {
    let mut s = [0.0; 6];
    for (j, v) in s.iter_mut().enumerate() {
        *v = sums.acc[hi][j] - sums.acc[lo][j];
    }
    let [n, sc, scc, sz, scz, szz] = s;
    let (c1, c2) = (sc - t * n, scc - 2.0 * t * sc + t * t * n);
    let z1 = sz - h * n;
    let zc = scz - t * sz - h * c1;
    let zz = szz - 2.0 * h * sz + h * h * n;
    [n, c1, c2, z1, zc, zz]
}

/// The hinge fit at `t` with the step `h` held, over the sorted profile whose points `..k`
/// lie before `t` and `k..` after it; `None` when the normal equations are singular.
fn hinge_at(sums: &Sums, k: usize, t: f64, h: f64) -> Option<Hinge> {
    let m = sums.acc.len() - 1;
    let (l, r) = (part(sums, 0, k, t, 0.0), part(sums, k, m, t, h));
    let (n, sz, szz) = (l[0] + r[0], l[3] + r[3], l[5] + r[5]);
    let (a1, b1q, a2, b2q) = (l[1], l[2], r[1], r[2]);
    // Normal matrix [[n, a1, a2], [a1, b1q, 0], [a2, 0, b2q]] and its right-hand side.
    let rhs = [sz, l[4], r[4]];
    let det = n * b1q * b2q - a1 * a1 * b2q - a2 * a2 * b1q;
    if det.abs().partial_cmp(&(1e-12 * n.powi(3).max(1.0))) != Some(Ordering::Greater) {
        return None;
    }
    // The inverse by cofactors (symmetric).
    let i00 = b1q * b2q / det;
    let i01 = -a1 * b2q / det;
    let i02 = -a2 * b1q / det;
    let i11 = (n * b2q - a2 * a2) / det;
    let i12 = a1 * a2 / det;
    let i22 = (n * b1q - a1 * a1) / det;
    let a = i00 * rhs[0] + i01 * rhs[1] + i02 * rhs[2];
    let b1 = i01 * rhs[0] + i11 * rhs[1] + i12 * rhs[2];
    let b2 = i02 * rhs[0] + i12 * rhs[1] + i22 * rhs[2];
    let sse = (szz - a * rhs[0] - b1 * rhs[1] - b2 * rhs[2]).max(0.0);
    let var = sse / (n - 3.0).max(1.0);
    let se_bend = (var * (i11 + i22 - 2.0 * i12)).max(0.0).sqrt();
    Some(Hinge {
        a,
        b1,
        b2,
        h,
        sse,
        se_bend,
    })
}

/// The hinge fit at `t` with its step fitted within 0..=[`FLUSH_MAX_LIP_M`]: the least
/// squares step of two free lines split at `t`, held to that range. Where the step lies
/// inside it, the fit is the two free lines' and the bend's standard error theirs (the
/// step is a fourth parameter); at the range's ends, the hinge's with that step held.
fn stepped_hinge_at(sums: &Sums, k: usize, t: f64) -> Option<Hinge> {
    let m = sums.acc.len() - 1;
    let (l, r) = (part(sums, 0, k, t, 0.0), part(sums, k, m, t, 0.0));
    // A free line z = a + b·(c − t) on each side.
    let line = |s: &[f64; 6]| -> Option<(f64, f64, f64)> {
        let den = s[0] * s[2] - s[1] * s[1];
        if den.partial_cmp(&(1e-12 * s[0] * s[0])) != Some(Ordering::Greater) {
            return None;
        }
        let b = (s[0] * s[4] - s[1] * s[3]) / den;
        let a = (s[3] - b * s[1]) / s[0];
        Some((a, b, den / s[0]))
    };
    let ((la, _, lsxx), (ra, _, rsxx)) = (line(&l)?, line(&r)?);
    let free = ra - la;
    let h = free.clamp(0.0, FLUSH_MAX_LIP_M);
    let mut fit = hinge_at(sums, k, t, h)?;
    if h == free {
        let var = fit.sse / (l[0] + r[0] - 4.0).max(1.0);
        fit.se_bend = (var * (1.0 / lsxx + 1.0 / rsxx)).sqrt();
    }
    Some(fit)
}

impl Profile<'_> {
    /// Finds the toe of a *flush crossing* on the profile (the same points as
    /// [`Profile::toe`]): the hinge (two lines meeting at the toe, up to a step of 0 to
    /// [`FLUSH_MAX_LIP_M`]) that fits the points best, tried every [`FLUSH_STEP_M`] within [`FLUSH_MAX_OFFSET_M`] of the centre. It is
    /// accepted as the toe when it lies inside that reach (not at its end), the road's slope
    /// is ground-like (under `profile_max_slope`), the slope behind is under
    /// [`FLUSH_MAX_BACK_SLOPE`] and turns upwards from the road's by at least
    /// [`FLUSH_MIN_BEND`] and [`FLUSH_MIN_SE`] standard errors, the hinge fits within
    /// [`FLUSH_MAX_RMS_M`], and both parts hold [`FLUSH_MIN_SIDE`] points reaching
    /// [`FLUSH_MIN_REACH_M`] from the toe with ground within 0.15 m of it. Like
    /// [`Profile::cut_toe`], only for continuing a track along a curb line.
    pub fn flush_toe(&self) -> Option<ProfileToe> {
        const NEAR_M: f64 = 0.15;
        let params = self.params;
        let prof = self.gather();
        let m = prof.len();
        if m < 2 * FLUSH_MIN_SIDE {
            return None;
        }
        let sums = Sums::new(&prof);
        let steps = (FLUSH_MAX_OFFSET_M / FLUSH_STEP_M).round() as i32;
        // The best hinge without a step and the best with one.
        let mut best: [Option<(Hinge, f64, usize)>; 2] = [None, None];
        for j in -steps..=steps {
            let t = f64::from(j) * FLUSH_STEP_M;
            let k = prof.partition_point(|p| p.0 < t);
            if k < FLUSH_MIN_SIDE || m - k < FLUSH_MIN_SIDE {
                continue;
            }
            let fits = [hinge_at(&sums, k, t, 0.0), stepped_hinge_at(&sums, k, t)];
            for (b, h) in best.iter_mut().zip(fits) {
                let Some(h) = h else { continue };
                if b.is_none_or(|(b, _, _)| h.sse < b.sse) {
                    *b = Some((h, t, k));
                }
            }
        }
        // The step is taken only where it fits the points better by more than a parameter
        // of noise is worth (the Bayesian information criterion): on noisy points a free
        // step of a millimetre or two trades against centimetres of the break's place.
        let (h, t, k) = match best {
            [Some(plain), Some(stepped)] => {
                let var = stepped.0.sse / (m as f64 - 4.0).max(1.0);
                if plain.0.sse - stepped.0.sse > (m as f64).ln() * var {
                    stepped
                } else {
                    plain
                }
            }
            [plain, stepped] => plain.or(stepped)?,
        };
        if t.abs() >= FLUSH_MAX_OFFSET_M - 0.5 * FLUSH_STEP_M {
            return None; // the best hinge lies at the reach's end: the break may lie beyond
        }
        if prof[k].0 - t > NEAR_M || t - prof[k - 1].0 > NEAR_M {
            return None; // no ground seen right beside the toe
        }
        if t - prof[0].0 < FLUSH_MIN_REACH_M || prof[m - 1].0 - t < FLUSH_MIN_REACH_M {
            return None;
        }
        let bend = h.b2 - h.b1;
        let rms = (h.sse / m as f64).sqrt();
        if h.b1.abs() > params.profile_max_slope
            || h.b2.abs() > FLUSH_MAX_BACK_SLOPE
            || bend < FLUSH_MIN_BEND
            || bend < FLUSH_MIN_SE * h.se_bend
            || rms > FLUSH_MAX_RMS_M
        {
            return None;
        }
        let near = prof.iter().filter(|p| (p.0 - t).abs() <= NEAR_M);
        let a = near.clone().map(|p| p.2).sum::<f64>() / near.count().max(1) as f64;
        let [x, y] = self.plan_at(a, t);
        Some(ProfileToe {
            xyz: [x, y, prof[0].1 + h.a],
            step_m: h.h,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bend::fixture::{profile_along_y, KeptPoints};
    use crate::bend::grid::PointGrid;
    use crate::bend::params::BendParams;
    use crate::io::trajectory::Trajectory;

    /// Points every `dx` across and 9 cm along about a curb line along y at x = `toe`, the
    /// road (x < toe) falling 2 % towards it and the ground behind stepping up by `lip` and
    /// rising at `back`, with a deterministic noise of ±`noise` (a hash of the point's index, about uniform).
    fn ground(toe: f64, back: f64, lip: f64, noise: f64, dx: f64) -> KeptPoints {
        let (mut x, mut y, mut z) = (Vec::new(), Vec::new(), Vec::new());
        let n = (0.9 / dx) as u32;
        for j in 0..7u32 {
            for i in 0..n {
                let k = j * n + i;
                let px = -0.45 + dx * (f64::from(i) + 0.5) + 0.003 * f64::from(j);
                let e = f64::from(k.wrapping_mul(2_654_435_761) % 1000) / 500.0 - 1.0;
                let d = px - toe;
                let h = if d < 0.0 { -0.02 * d } else { lip + back * d };
                x.push(px);
                y.push(-0.27 + 0.09 * f64::from(j));
                z.push(h + noise * e);
            }
        }
        KeptPoints::new(x, y, z)
    }

    fn flush(points: &KeptPoints, params: &BendParams) -> Option<ProfileToe> {
        let trajectory = Trajectory::default();
        let input = points.input(&trajectory);
        let grid = PointGrid::build(input.x, input.y, 0.1, |_| true);
        // Walking along +y with the curb on the right (+x).
        Profile {
            input: &input,
            grid: &grid,
            params,
            centre: [0.0, 0.0, 0.0],
            along: [0.0, 1.0],
            up: -1.0,
            half_l: 0.3,
        }
        .flush_toe()
    }

    #[test]
    fn a_flush_toe_is_placed_where_crossfall_meets_the_sidewalk_slope() {
        let params = BendParams::default();
        for toe in [-0.06, 0.0, 0.04] {
            // 2 % crossfall meeting a 2 % sidewalk: a rise of 10 mm at 0.25 m, under
            // the free two-line fit's 15 mm; noise ±12 mm (7 mm RMS).
            let p = ground(toe, 0.02, 0.0, 0.012, 0.015);
            let t = flush(&p, &params).expect("a flush toe");
            assert!((t.xyz[0] - toe).abs() < 0.03, "toe at {toe}: {t:?}");
            // The free two-line fit of a cut's toe does not see it.
            let trajectory = Trajectory::default();
            let input = p.input(&trajectory);
            let grid = PointGrid::build(input.x, input.y, 0.1, |_| true);
            let prof = profile_along_y(&input, &grid, &params, [0.0, 0.0, 0.0], 0.3);
            assert!(prof.cut_toe().is_none());
        }
    }

    #[test]
    fn plain_road_a_steep_ramp_or_a_toe_out_of_reach_give_no_flush_toe() {
        let params = BendParams::default();
        // The road's crossfall runs on behind the line: no bend.
        assert!(flush(&ground(0.0, -0.02, 0.0, 0.012, 0.015), &params).is_none());
        // A bend of 1 % is within a road's crown or rut.
        assert!(flush(&ground(0.0, -0.01, 0.0, 0.002, 0.015), &params).is_none());
        // A ramp behind (20 %) is the cut toe's case.
        assert!(flush(&ground(0.0, 0.2, 0.0, 0.005, 0.015), &params).is_none());
        // The break 0.2 m off the prediction.
        assert!(flush(&ground(0.2, 0.02, 0.0, 0.005, 0.015), &params).is_none());
    }

    #[test]
    fn a_lip_of_a_few_millimetres_does_not_draw_the_flush_toe_towards_the_road() {
        let params = BendParams::default();
        for lip in [0.004, 0.008] {
            for toe in [-0.05, 0.0, 0.05] {
                // A hinge without a step would meet the lip 0.1–0.2 m on the road side:
                // the lip over the 4 % turn in slope.
                let p = ground(toe, 0.02, lip, 0.006, 0.015);
                let t = flush(&p, &params).expect("a flush toe");
                assert!(
                    (t.xyz[0] - toe).abs() < 0.03,
                    "lip {lip}, toe at {toe}: {t:?}"
                );
                assert!((t.step_m - lip).abs() < 0.004, "lip {lip}: {t:?}");
            }
        }
    }
}
