//! Seeds on corner arcs that no track reaches: profiles turned towards the arc's
//! direction, for the intervals where [`super::seed::profile_seeds`]' profiles across the
//! driving direction find no toe.
//!
//! A track reaches a corner arc by following the curb before it round the corner. Where
//! that curb is never seen — on the near side of a yawed mount it lies in the returns the
//! vehicle's body leaves out, for tens of metres — the arc begins where the returns begin,
//! and no track comes along. The core's candidates on it give no seed either: per interval
//! RANSAC fits a line to them, and along the arc they turn too fast to lie on one. A
//! profile across the driving direction crosses the arc obliquely, so its step spreads
//! over the profile's length and its two parts tilt (`profile::Profile::toe` rejects them
//! as ramps). A profile turned by half a right angle lies across the arc where the arc
//! runs at 25–65° to the road, the part between the curb it leaves and the side street's
//! leg.

use super::params::BendParams;

/// How far the profiles are turned from the driving direction, degrees: either way, so
/// that the arc into a side street and the arc out of it are both crossed.
pub const ARC_PROFILE_TURN_DEG: f64 = 45.0;

/// Farthest a seed point may lie from the toe that an arc profile finds, metres: the toe
/// test sees ground within 0.15 m either side of the toe, and where the scanlines lie
/// 0.2 m apart the nearest return can lie just past the tracker's search radius.
pub const ARC_SEED_RADIUS_M: f64 = 0.15;

/// `params` for the arc profiles' search: a seed point within [`ARC_SEED_RADIUS_M`] of the
/// toe (at least the search radius).
pub fn arc_params(params: &BendParams) -> BendParams {
    BendParams {
        search_radius_m: params.search_radius_m.max(ARC_SEED_RADIUS_M),
        ..params.clone()
    }
}

/// The profiles' directions along the road for an arc search from a pose heading `fwd`
/// (horizontal unit vector): `fwd` turned by [`ARC_PROFILE_TURN_DEG`] to the left, then
/// to the right. Both keep a positive component along `fwd`, so a seed's direction taken
/// from them runs with the driving direction as a seed's direction must.
pub fn arc_profile_dirs(fwd: [f64; 2]) -> [[f64; 2]; 2] {
    let (s, c) = ARC_PROFILE_TURN_DEG.to_radians().sin_cos();
    [
        [c * fwd[0] - s * fwd[1], s * fwd[0] + c * fwd[1]],
        [c * fwd[0] + s * fwd[1], -s * fwd[0] + c * fwd[1]],
    ]
}

/// The first toe that `search` (an outward search of profiles along the given direction,
/// as `profile_seeds` makes it) finds along either of [`arc_profile_dirs`], with that
/// profile's direction: the seed's direction, which runs with the driving direction.
pub fn arc_seed<T>(
    fwd: [f64; 2],
    mut search: impl FnMut([f64; 2]) -> Option<T>,
) -> Option<(T, [f64; 2])> {
    arc_profile_dirs(fwd)
        .into_iter()
        .find_map(|along| search(along).map(|found| (found, along)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_arc_profiles_are_turned_either_way_and_run_forward() {
        let fwd = [0.6, 0.8];
        let [l, r] = arc_profile_dirs(fwd);
        for d in [l, r] {
            assert!((d[0] * d[0] + d[1] * d[1] - 1.0).abs() < 1e-12);
            let cos = d[0] * fwd[0] + d[1] * fwd[1];
            assert!((cos - 0.5f64.sqrt()).abs() < 1e-12, "cos {cos}");
        }
        // Left of fwd is positive cross product.
        assert!(fwd[0] * l[1] - fwd[1] * l[0] > 0.0);
        assert!(fwd[0] * r[1] - fwd[1] * r[0] < 0.0);
    }
}
