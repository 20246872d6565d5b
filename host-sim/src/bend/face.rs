//! The curb toe on a spinning sensor's rings where a ring slides along the face: the face
//! located in plan first, the step taken across it.
//!
//! A ring is a cone about the sensor; where a curb's face lies at nearly one range from it
//! the ring meets the face at the height that range gives and runs along it, and the rings
//! of several revolutions fill the face at every height, their returns spread across it by
//! the range noise. [`Profile::toe`]'s two-level split then falls on the face and leaves
//! face returns in both parts. Here the face is found first as the front edge, in plan, of
//! the returns raised above the road: in each strip along the profile the raised return
//! nearest the road, the strips' edges fitted by a line in the ground plane (which may run
//! at an angle to the profile's length). Across that line the road lies in front, the face
//! from the line to [`FACE_DEPTH_M`] behind it, set aside, and the top beyond; the toe is
//! accepted on the same tests as [`Profile::toe`]'s (ground-like parts, a step of at least
//! `profile_min_step_m` and under the search half-height, the parts' RMS under a quarter of
//! the step, ground within 0.15 m in front of the toe).

use super::profile::{Profile, ProfileToe};

/// Least height above the road of a return taken as raised (on the face or the top),
/// metres: above a road's unevenness and twice a spinning lidar's range noise.
const RAISED_MIN_M: f64 = 0.05;

/// Width along the profile of the strips whose raised returns nearest the road give the
/// face's front edge, metres.
const STRIP_M: f64 = 0.05;

/// Fewest strips along the profile (0.6 m): on a shorter one the outline of a single ring
/// crossing, raised returns along the ring's own path, fits a line as well as a face.
const MIN_STRIPS: usize = 12;

/// Fewest strips with a raised return, as a share of the profile's strips: the face runs
/// through the whole profile, not a few returns of an object on the road.
const MIN_STRIP_SHARE: f64 = 0.5;

/// Largest RMS across of the strips' edges about their line, metres: a face's front edge
/// with a ring's range noise, not the scattered outline of a vehicle or a bush.
const MAX_EDGE_RMS_M: f64 = 0.04;

/// Steepest angle of the face's line to the profile's length, as its tangent (45°).
const MAX_EDGE_TAN: f64 = 1.0;

/// Depth behind the face's front edge that holds the face's returns, set aside, metres: a
/// batter of 1:10 on a 0.25 m face and a ring's range noise (2 cm, one sigma) three times
/// over, spread along the beam, nearly across the face.
const FACE_DEPTH_M: f64 = 0.16;

/// Farthest in front of the toe the nearest road return may lie, metres (as
/// [`Profile::toe`]'s).
const NEAR_M: f64 = 0.15;

/// Depth in front of the face's front edge of the returns left out of the road's line,
/// metres: the face's lowest returns, spread in front of the edge by the range noise.
const FOOT_M: f64 = 0.03;

/// Fewest returns on the road and on the top.
const MIN_SIDE: usize = 4;

/// Largest share of the returns in front of the face that are raised: the road in front
/// of a curb is clear.
const MAX_RAISED_IN_FRONT: f64 = 0.1;

/// Least-squares line v = a + b·u through `pts`, with its RMS; slope 0 when every u is
/// the same.
fn fit(pts: &[(f64, f64)]) -> Option<(f64, f64, f64)> {
    let n = pts.len() as f64;
    if pts.is_empty() {
        return None;
    }
    let (su, sv) = pts
        .iter()
        .fold((0.0, 0.0), |(a, b), &(u, v)| (a + u, b + v));
    let (mu, mv) = (su / n, sv / n);
    let (mut suu, mut suv) = (0.0, 0.0);
    for &(u, v) in pts {
        suu += (u - mu) * (u - mu);
        suv += (u - mu) * (v - mv);
    }
    let b = if suu > 1e-12 { suv / suu } else { 0.0 };
    let a = mv - b * mu;
    let sse: f64 = pts.iter().map(|&(u, v)| (v - a - b * u).powi(2)).sum();
    Some((a, b, (sse / n).sqrt()))
}

/// The toe of a curb whose face a ring slides along (see the module docs), on `profile`.
pub fn face_toe(profile: &Profile) -> Option<ProfileToe> {
    let params = profile.params;
    let input = profile.input;
    // (across, height, along)
    let mut pts: Vec<(f64, f64, f64)> = Vec::new();
    profile.for_each(|i, c, a| pts.push((c, input.z[i], a)));
    if pts.len() < 2 * MIN_SIDE {
        return None;
    }
    // In one order whatever order the grid hands the points over in (it differs between a
    // whole run and a campaign's tasks), so the sums below give the same bits.
    pts.sort_by(|p, q| {
        (p.0.total_cmp(&q.0))
            .then(p.1.total_cmp(&q.1))
            .then(p.2.total_cmp(&q.2))
    });
    // The road's height: the lowest tenth of the returns.
    let mut zs: Vec<f64> = pts.iter().map(|p| p.1).collect();
    zs.sort_by(f64::total_cmp);
    let ground = zs[zs.len() / 10];
    // The face's front edge: per strip along, the raised return nearest the road.
    let strips = (2.0 * profile.half_l / STRIP_M).round() as usize;
    if strips < MIN_STRIPS {
        return None;
    }
    let mut front = vec![f64::INFINITY; strips];
    for &(c, z, a) in &pts {
        let h = z - ground;
        if h >= RAISED_MIN_M && h <= params.search_half_height_m {
            let s = (((a + profile.half_l) / STRIP_M).floor().max(0.0) as usize).min(strips - 1);
            front[s] = front[s].min(c);
        }
    }
    let mut edge: Vec<(f64, f64)> = front
        .iter()
        .enumerate()
        .filter(|(_, c)| c.is_finite())
        .map(|(s, &c)| ((s as f64 + 0.5) * STRIP_M - profile.half_l, c))
        .collect();
    if (edge.len() as f64) < MIN_STRIP_SHARE * strips as f64 || edge.len() < 3 {
        return None;
    }
    // One refit without the strips whose nearest raised return lies far off the line.
    let (c0, k, _) = fit(&edge)?;
    edge.retain(|&(a, c)| (c - c0 - k * a).abs() <= 2.0 * MAX_EDGE_RMS_M);
    if (edge.len() as f64) < MIN_STRIP_SHARE * strips as f64 || edge.len() < 3 {
        return None;
    }
    let (c0, k, rms) = fit(&edge)?;
    if rms > MAX_EDGE_RMS_M || k.abs() > MAX_EDGE_TAN {
        return None;
    }
    let norm = k.hypot(1.0);
    // Offset across the face's line, positive behind it.
    let across = |c: f64, a: f64| (c - c0 - k * a) / norm;
    let mut road: Vec<(f64, f64)> = Vec::new();
    let mut top: Vec<(f64, f64)> = Vec::new();
    let mut raised_in_front = 0usize;
    for &(c, z, a) in &pts {
        let d = across(c, a);
        if d < -FOOT_M {
            road.push((d, z));
            raised_in_front += usize::from(z - ground >= RAISED_MIN_M);
        } else if d > FACE_DEPTH_M {
            top.push((d, z));
        }
    }
    if road.len() < MIN_SIDE || top.len() < MIN_SIDE {
        return None;
    }
    if raised_in_front as f64 > MAX_RAISED_IN_FRONT * road.len() as f64 {
        return None;
    }
    if road.iter().map(|p| p.0).fold(f64::NEG_INFINITY, f64::max) < -NEAR_M {
        return None; // no road seen right in front of the face
    }
    let (ra, rb, re) = fit(&road)?;
    let (ta, tb, te) = fit(&top)?;
    let max_slope = params.profile_max_slope;
    let step = ta - ra;
    let n = (road.len() + top.len()) as f64;
    let rms = ((re * re * road.len() as f64 + te * te * top.len() as f64) / n).sqrt();
    if rb > max_slope || -rb > params.profile_max_road_fall || tb.abs() > max_slope {
        return None;
    }
    if step < params.profile_min_step_m || step > params.search_half_height_m {
        return None;
    }
    if rms > 0.25 * step {
        return None;
    }
    // The toe where the face's line crosses the middle of its strips along the profile.
    let a = edge.iter().map(|e| e.0).sum::<f64>() / edge.len() as f64;
    let [x, y] = profile.plan_at(a, c0 + k * a);
    Some(ProfileToe {
        xyz: [x, y, ra],
        step_m: step,
    })
}

/// [`face_toe`], else on the profile twice as long.
pub fn face_toe_or_longer(profile: &Profile) -> Option<ProfileToe> {
    face_toe(profile).or_else(|| face_toe(&profile.with_half_l(2.0 * profile.half_l)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bend::fixture::{profile_along_y, KeptPoints};
    use crate::bend::grid::PointGrid;
    use crate::bend::params::BendParams;
    use crate::io::trajectory::Trajectory;

    /// A 0.2 m curb whose toe runs through the origin at `angle` (radians) to +y, rising to
    /// the right; the face filled at ten heights by returns spread 0–0.14 m behind the toe
    /// (a ring sliding along it), the top from 0.16 m behind the toe; road and top every
    /// 2 cm across, everything every 5 cm along.
    fn slid_face(angle: f64) -> KeptPoints {
        let (mut x, mut y, mut z) = (Vec::new(), Vec::new(), Vec::new());
        let (s, c) = angle.sin_cos();
        // (across, along) -> (x, y): along runs at `angle` to +y, across to its right.
        let mut push = |d: f64, l: f64, h: f64| {
            x.push(d * c + l * s);
            y.push(-d * s + l * c);
            z.push(h);
        };
        for j in 0..17 {
            let l = -0.4 + 0.05 * f64::from(j);
            for i in 0..25 {
                push(-0.5 + 0.02 * f64::from(i) - 0.005, l, 0.0);
            }
            for i in 0..16 {
                push(0.165 + 0.02 * f64::from(i), l, 0.2);
            }
            for h in 0..10u32 {
                for r in 0..2u32 {
                    let d = 0.01 * f64::from((7 * h + 5 * r + 3 * j as u32) % 15);
                    push(d, l + 0.02 * f64::from(r), 0.01 + 0.02 * f64::from(h));
                }
            }
        }
        KeptPoints::new(x, y, z)
    }

    fn profile_toes(angle: f64) -> (Option<ProfileToe>, Option<ProfileToe>) {
        let points = slid_face(angle);
        let trajectory = Trajectory::default();
        let input = points.input(&trajectory);
        let grid = PointGrid::build(input.x, input.y, 0.1, |_| true);
        let params = BendParams::default();
        let profile = profile_along_y(
            &input,
            &grid,
            &params,
            [0.0, 0.0, 0.0],
            params.profile_half_length_m,
        );
        (profile.toe_or_longer(), face_toe_or_longer(&profile))
    }

    #[test]
    fn a_face_a_ring_slides_along_gives_its_toe_in_front_of_the_face() {
        for angle in [0.0f64, 20.0f64.to_radians()] {
            let (split, face) = profile_toes(angle);
            // The two-level split leaves the face in both parts: no toe.
            assert!(split.is_none(), "{angle}: {split:?}");
            let t = face.expect("the toe in front of the face");
            // On the toe's line (the origin's, at `angle` to +y), at the road's height.
            let off = t.xyz[0] * angle.cos() - t.xyz[1] * angle.sin();
            assert!(off.abs() < 0.03, "{angle}: {t:?}");
            assert!((t.step_m - 0.2).abs() < 0.02, "{angle}: {t:?}");
            assert!(t.xyz[2].abs() < 0.01, "{angle}: {t:?}");
        }
    }

    #[test]
    fn flat_road_and_a_ramp_give_no_face_toe() {
        let (mut x, mut y, mut z) = (Vec::new(), Vec::new(), Vec::new());
        for j in 0..17 {
            for i in 0..45 {
                let c = -0.45 + 0.02 * f64::from(i);
                x.push(c);
                y.push(-0.4 + 0.05 * f64::from(j));
                // A 1:2 ramp from x = 0: raised, but no level top.
                z.push(if c > 0.0 { 0.5 * c } else { 0.0 });
            }
        }
        let points = KeptPoints::new(x, y, z);
        let trajectory = Trajectory::default();
        let input = points.input(&trajectory);
        let grid = PointGrid::build(input.x, input.y, 0.1, |_| true);
        let params = BendParams::default();
        let profile = profile_along_y(
            &input,
            &grid,
            &params,
            [0.0, 0.0, 0.0],
            params.profile_half_length_m,
        );
        assert!(face_toe_or_longer(&profile).is_none());
    }
}
