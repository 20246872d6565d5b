//! A track that has climbed the curb face onto its top edge, brought back down to the toe.
//!
//! At the end of a corner arc ρ is weak and the picks of Eq. 4 may lie on the curb's face,
//! its rounded arris or an object beside the toe; a few such picks lift the track onto the
//! top edge, or start it there with the rising side the wrong way round. From there the
//! profiles across the search position see the road a curb height below and show no toe
//! where the track expects it, and the gap rule ends the track on a curb in plain view. The
//! ground beside the search position tells the case: on one side it lies a curb height
//! below the last vertex, on the other it does not. The toe is then sought on a profile
//! moved towards the low side and at its level, with the curb rising away from it.

use super::grid::PointGrid;
use super::params::BendParams;
use super::profile::{usable, Profile, ProfileToe};
use super::BendInput;

/// Strips either side of the search position whose ground tells a climbed track: from
/// `STRIP_NEAR_M` to `STRIP_FAR_M` across, ±`STRIP_ALONG_M` along, metres. Past the 40 mm
/// of a face and the arris, within the reach of the profile moved towards the road.
const STRIP_NEAR_M: f64 = 0.1;
const STRIP_FAR_M: f64 = 0.4;
const STRIP_ALONG_M: f64 = 0.3;

/// Fewest points a strip needs to give its ground level.
const STRIP_MIN_POINTS: usize = 3;

/// How far the profile is moved from the search position towards the low side, metres:
/// with the toe accepted within `profile_half_width_m` − 0.15 m of the profile's centre,
/// it reaches toes from the search position itself to twice as far.
const SHIFT_M: f64 = 0.3;

/// Least height of the last vertex above the toe found below it, as a share of that
/// toe's step: half-way up the face or higher, the track is on the top edge; lower, it is
/// a face pick that the next toe corrects. The tracker drops the vertices it picked that
/// high above the toe.
pub(super) const CLIMBED_SHARE: f64 = 0.5;

/// The toe below a track that has climbed onto the curb's top edge, with the side the curb
/// rises on as seen there (+1 left of `along`, −1 right); `None` when the track has not
/// climbed or no profile shows the toe.
///
/// `centre` is the search position at the last vertex's height, `along` the horizontal
/// unit direction of the search. The track has climbed where the ground of one strip
/// beside `centre` ([`STRIP_NEAR_M`]–[`STRIP_FAR_M`] across) lies at least
/// `profile_min_step_m` below `centre` while the other strip's does not (or holds too
/// few points: an object or its shadow beside the top edge). The toe is then sought by
/// [`Profile::toe_or_longer`] on the profile `half_l` long, centred [`SHIFT_M`]
/// towards the low side at the low strip's height, the curb rising away from the low
/// side, whatever side the track assumed before; it is taken where `centre` lies at least
/// [`CLIMBED_SHARE`] of its step above it.
pub fn climbed_toe(
    input: &BendInput,
    grid: &PointGrid,
    centre: [f64; 3],
    along: [f64; 2],
    half_l: f64,
    params: &BendParams,
) -> Option<(ProfileToe, f64)> {
    let left = strip_level(input, grid, centre, along, 1.0, params);
    let right = strip_level(input, grid, centre, along, -1.0, params);
    let below = |z: Option<f64>| z.is_some_and(|z| centre[2] - z >= params.profile_min_step_m);
    // The side the ground falls to, and its level.
    let (low_side, low_z) = match (below(left), below(right)) {
        (true, false) => (1.0, left?),
        (false, true) => (-1.0, right?),
        _ => return None, // level on both sides, or below on both: on an object, not a curb
    };
    let up = -low_side;
    // The left normal of `along`, times the low side's sign: towards the road.
    let to_road = [-along[1] * low_side, along[0] * low_side];
    let c = [
        centre[0] + SHIFT_M * to_road[0],
        centre[1] + SHIFT_M * to_road[1],
        low_z,
    ];
    let toe = Profile {
        input,
        grid,
        params,
        centre: c,
        along,
        up,
        half_l,
    }
    .toe_or_longer()?;
    // The track is on the top edge, not a pick or two up the face: at least half the
    // toe's step above it.
    (centre[2] - toe.xyz[2] >= CLIMBED_SHARE * toe.step_m).then_some((toe, up))
}

/// Median height of the usable points in the strip [`STRIP_NEAR_M`]–[`STRIP_FAR_M`] on
/// the side `side` (+1 left of `along`, −1 right) of `centre`, ±[`STRIP_ALONG_M`] along and
/// within the search half-height of `centre`'s height; `None` with fewer than
/// [`STRIP_MIN_POINTS`].
fn strip_level(
    input: &BendInput,
    grid: &PointGrid,
    centre: [f64; 3],
    along: [f64; 2],
    side: f64,
    params: &BendParams,
) -> Option<f64> {
    let n = [-along[1] * side, along[0] * side];
    let mut z = Vec::new();
    grid.for_each_within(
        input.x,
        input.y,
        centre[0],
        centre[1],
        STRIP_FAR_M.hypot(STRIP_ALONG_M),
        |j| {
            if !usable(input, j) || (input.z[j] - centre[2]).abs() > params.search_half_height_m {
                return;
            }
            let d = [input.x[j] - centre[0], input.y[j] - centre[1]];
            let a = d[0] * along[0] + d[1] * along[1];
            let c = d[0] * n[0] + d[1] * n[1];
            if a.abs() <= STRIP_ALONG_M && (STRIP_NEAR_M..=STRIP_FAR_M).contains(&c) {
                z.push(input.z[j]);
            }
        },
    );
    if z.len() < STRIP_MIN_POINTS {
        return None;
    }
    z.sort_by(f64::total_cmp);
    Some(z[z.len() / 2])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::trajectory::Trajectory;
    use crate::replay::PointStatus;

    /// A straight curb along y = 5: road (z = 0) for y < 5, sidewalk 0.15 m up beyond it,
    /// scanlines across x every 0.11 m with points every 2 cm (a profile across the curb).
    struct Street {
        x: Vec<f64>,
        y: Vec<f64>,
        z: Vec<f64>,
        t: Vec<f64>,
        rho: Vec<f32>,
        status: Vec<Option<PointStatus>>,
        line: Vec<u32>,
        traj: Trajectory,
    }

    fn street() -> Street {
        let mut s = Street {
            x: Vec::new(),
            y: Vec::new(),
            z: Vec::new(),
            t: Vec::new(),
            rho: Vec::new(),
            status: Vec::new(),
            line: Vec::new(),
            traj: Trajectory::default(),
        };
        for l in 0..40u32 {
            let x = 0.013 + 0.11 * l as f64;
            for k in 0..200 {
                let y = 3.0 + 0.02 * k as f64;
                s.x.push(x);
                s.y.push(y);
                s.z.push(if y > 5.0 { 0.15 } else { 0.0 });
                s.t.push(l as f64 * 0.01);
                s.rho.push(0.0);
                s.status.push(Some(PointStatus::Kept));
                s.line.push(l);
            }
        }
        s
    }

    fn input(s: &Street) -> BendInput<'_> {
        BendInput {
            x: &s.x,
            y: &s.y,
            z: &s.z,
            t: &s.t,
            rho_deg: &s.rho,
            status: &s.status,
            scanline: &s.line,
            candidates: &[],
            trajectory: &s.traj,
        }
    }

    #[test]
    fn a_track_on_the_top_edge_comes_down_to_the_toe() {
        let s = street();
        let inp = input(&s);
        let grid = PointGrid::build(inp.x, inp.y, 0.1, |_| true);
        let params = BendParams::default();
        let l = params.profile_half_length_m;
        // Driving towards +x on the top edge, 0.2 m behind the toe: the road lies 0.15 m
        // below on the right, the sidewalk level on the left, so the curb rises on the
        // left (+1).
        let (toe, up) =
            climbed_toe(&inp, &grid, [2.0, 5.2, 0.15], [1.0, 0.0], l, &params).expect("a toe");
        assert_eq!(up, 1.0);
        assert!((toe.xyz[1] - 5.0).abs() < 0.03, "{toe:?}");
        assert!(toe.xyz[2].abs() < 0.01, "{toe:?}");
        assert!((toe.step_m - 0.15).abs() < 0.01, "{toe:?}");
        // Driving the other way the curb rises on the right: the side comes from the
        // ground, not from the track.
        let (toe, up) =
            climbed_toe(&inp, &grid, [2.0, 5.2, 0.15], [-1.0, 0.0], l, &params).expect("a toe");
        assert_eq!(up, -1.0);
        assert!((toe.xyz[1] - 5.0).abs() < 0.03, "{toe:?}");
    }

    #[test]
    fn a_track_on_the_toe_or_on_level_ground_has_not_climbed() {
        let s = street();
        let inp = input(&s);
        let grid = PointGrid::build(inp.x, inp.y, 0.1, |_| true);
        let params = BendParams::default();
        let l = params.profile_half_length_m;
        // On the toe: the sidewalk rises on one side, the road is level on the other.
        assert!(climbed_toe(&inp, &grid, [2.0, 5.0, 0.0], [1.0, 0.0], l, &params).is_none());
        // On the road and on the sidewalk, away from the curb.
        assert!(climbed_toe(&inp, &grid, [2.0, 4.0, 0.0], [1.0, 0.0], l, &params).is_none());
        assert!(climbed_toe(&inp, &grid, [2.0, 6.0, 0.15], [1.0, 0.0], l, &params).is_none());
        // A pick a third of the way up the face is no climb: the next toe corrects it.
        assert!(climbed_toe(&inp, &grid, [2.0, 5.1, 0.05], [1.0, 0.0], l, &params).is_none());
        // Above both sides (on an object's base over the road): no curb to come down to.
        assert!(climbed_toe(&inp, &grid, [2.0, 4.0, 0.12], [1.0, 0.0], l, &params).is_none());
    }
}
