//! The curb toe on a side street's leg far from the scanner, where the returns are too
//! sparse for the ordinary virtual profiles: the same step test on a profile reaching
//! farther along the curb, held to the track that reaches it.
//!
//! Twenty metres and more beside the drive a profiler's returns on a side street's leg lie
//! 0.15–0.4 m apart, and the profiles of the tracker ([`Profile::toe_or_longer`], 0.3 m and
//! 0.6 m along) hold too few points on a side, so a track along a leg in plain view stops
//! on the gap rule. A leg is straight, so a profile several times as long still sees one
//! toe; what it adds is the risk of a step that is not the curb. The toe is therefore
//! taken only where the profile is sparse (the case the shorter ones cannot take), where
//! its step is the track's own curb height ([`track_curb_height`]) and where it lies on the
//! track's line (within [`MAX_OFF_LINE_M`] across of the search position).

use super::profile::{Profile, ProfileToe};
use super::sparse::track_curb_height;

/// Half-length along the curb of the far profile, as a multiple of the ordinary one's.
const REACH: f64 = 4.0;

/// Most points the ordinary long profile (twice the ordinary half-length) may hold for the
/// far profile to be tried: with more, the returns are dense enough for the ordinary test.
const SPARSE_MAX_POINTS: usize = 24;

/// Largest difference between the step and the track's curb height, as a share of the
/// latter.
const CURB_MATCH_SHARE: f64 = 0.35;

/// Farthest along the curb from the toe that the ground beside it must be seen, metres.
const BESIDE_ALONG_M: f64 = 0.5;

/// Farthest across from the toe that the ground beside it must be seen, on each side, metres.
const BESIDE_ACROSS_M: f64 = 0.15;

/// Widest gap across between the nearest road and the nearest curb return beside the toe,
/// metres: across a wider one (the curb's shadow, a gap in the returns) the toe half-way
/// between them is placed no better than the gap's half.
const MAX_GAP_M: f64 = 0.2;

/// Whether the ground beside `toe` is seen on `far`: among its points within
/// [`BESIDE_ALONG_M`] along of the toe, the nearest on the road side and the nearest on the
/// curb side each within [`BESIDE_ACROSS_M`] across of it and at most [`MAX_GAP_M`] apart.
fn ground_beside(far: &Profile, toe: &ProfileToe) -> bool {
    let n = [-far.along[1] * far.up, far.along[0] * far.up];
    let d = [toe.xyz[0] - far.centre[0], toe.xyz[1] - far.centre[1]];
    let (tc, ta) = (
        d[0] * n[0] + d[1] * n[1],
        d[0] * far.along[0] + d[1] * far.along[1],
    );
    let (mut road, mut curb) = (f64::NEG_INFINITY, f64::INFINITY);
    far.for_each(|_, c, a| {
        if (a - ta).abs() <= BESIDE_ALONG_M {
            if c < tc {
                road = road.max(c);
            } else if c > tc {
                curb = curb.min(c);
            }
        }
    });
    road >= tc - BESIDE_ACROSS_M && curb <= tc + BESIDE_ACROSS_M && curb - road <= MAX_GAP_M
}

/// Farthest the toe may lie across from the search position, metres.
const MAX_OFF_LINE_M: f64 = 0.15;

/// The toe of a far leg (see the module docs): `profile` is the tracker's ordinary profile
/// at the search position (its `centre` on the track's line carried one step on), `picked`
/// the track's vertices before it.
pub fn leg_toe(profile: &Profile, picked: &[(u32, [f64; 3])]) -> Option<ProfileToe> {
    let long = profile.with_half_l(2.0 * profile.half_l);
    let mut n = 0usize;
    long.for_each(|_, _, _| n += 1);
    if n > SPARSE_MAX_POINTS {
        return None;
    }
    let far = profile.with_half_l(REACH * profile.half_l);
    let toe = far.toe()?;
    let off = (toe.xyz[0] - profile.centre[0]) * -profile.along[1]
        + (toe.xyz[1] - profile.centre[1]) * profile.along[0];
    if off.abs() > MAX_OFF_LINE_M {
        return None;
    }
    if !ground_beside(&far, &toe) {
        return None;
    }
    let h = track_curb_height(
        profile.input,
        profile.grid,
        picked,
        profile.up,
        profile.params,
    )?;
    if (toe.step_m - h).abs() > CURB_MATCH_SHARE * h {
        return None;
    }
    Some(toe)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bend::fixture::{profile_along_y, KeptPoints};
    use crate::bend::grid::PointGrid;
    use crate::bend::params::BendParams;
    use crate::io::trajectory::Trajectory;

    /// A curb along +y at x = 0, rising `step` to the right (x > 0). Up to y = −0.5 the
    /// returns are dense (every 5 cm) and the track's vertices run along the toe there, its
    /// curb `track_step` high; beyond, one return every 0.14 m across in rows 0.4 m apart
    /// (y = −0.1, 0.3, 0.7, 1.1), with three returns on the face where `face`.
    fn leg(step: f64, track_step: f64, face: bool) -> (KeptPoints, Vec<(u32, [f64; 3])>) {
        let (mut x, mut y, mut z) = (Vec::new(), Vec::new(), Vec::new());
        for r in 0..56 {
            for q in 0..24 {
                let xq = -0.575 + 0.05 * q as f64;
                x.push(xq);
                y.push(-3.3 + 0.05 * r as f64);
                z.push(if xq < 0.0 { 0.0 } else { track_step });
            }
        }
        for row in 0..4 {
            let yr = -0.1 + 0.4 * row as f64;
            for k in 1..=3 {
                let c = 0.14 * k as f64 - 0.01;
                x.extend([-c, c]);
                y.extend([yr, yr]);
                z.extend([0.0, step]);
            }
            if face {
                for (c, h) in [(-0.01, 0.25), (0.0, 0.5), (0.01, 0.75)] {
                    x.push(c);
                    y.push(yr);
                    z.push(h * step);
                }
            }
        }
        let picked = (0..17)
            .map(|k| (0, [0.0, -3.0 + 0.15 * k as f64, 0.0]))
            .collect();
        (KeptPoints::new(x, y, z), picked)
    }

    /// The tracker's ordinary profile at (0, 0.3) along +y, and the leg's toe there.
    fn toes(step: f64, track_step: f64, face: bool) -> (Option<ProfileToe>, Option<ProfileToe>) {
        let (pts, picked) = leg(step, track_step, face);
        let traj = Trajectory::default();
        let input = pts.input(&traj);
        let grid = PointGrid::build(input.x, input.y, 0.1, |_| true);
        let params = BendParams::default();
        let profile = profile_along_y(
            &input,
            &grid,
            &params,
            [0.0, 0.3, 0.0],
            params.profile_half_length_m,
        );
        (profile.toe_or_longer(), leg_toe(&profile, &picked))
    }

    #[test]
    fn a_sparse_leg_shows_its_toe_on_a_longer_profile() {
        let (ordinary, far) = toes(0.12, 0.12, true);
        assert!(ordinary.is_none(), "the ordinary profiles see {ordinary:?}");
        let t = far.expect("the leg's toe");
        assert!(t.xyz[0].abs() < 0.03, "toe at {:?}", t.xyz);
        assert!((t.step_m - 0.12).abs() < 0.01, "step {}", t.step_m);
    }

    #[test]
    fn a_leg_toe_needs_the_tracks_curb_and_the_ground_beside_it() {
        // A step twice the track's curb height is something else.
        assert!(toes(0.25, 0.12, true).1.is_none());
        // No returns on the face: 0.26 m between the road and the curb returns.
        assert!(toes(0.12, 0.12, false).1.is_none());
    }
}
