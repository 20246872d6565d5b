//! The toe of a curb cut's lip on the line a track follows: a low step between two
//! ground-like levels, where the break-of-slope fit of [`Profile::cut_toe`] finds none.
//!
//! Far from the scanner, where its lines run nearly along the curb, a virtual profile holds
//! a few scanlines, each at one offset across: the returns reach a few decimetres either
//! side of the toe, too little for [`Profile::cut_toe`]'s two lines (it wants 0.3 m of
//! ground on both sides for the slopes to mean something), while the level step of a lip
//! (0–50 mm, under the curb's least step) is plain between the scanlines. The step fit of
//! [`Profile::toe`] with a lip's least step finds it. Meant only for a track already
//! following a cut, on the line it predicts: on its own a step of a few centimetres is too
//! weak a sign of a curb (a rut, a patch, a drain cover).

use super::params::BendParams;
use super::profile::{Profile, ProfileToe};

/// Least step of a cut's lip between the road's level and the level behind, metres: the
/// least rise [`Profile::cut_toe`] takes behind a toe, over a road's ruts and patches.
const LIP_MIN_STEP_M: f64 = 0.015;

/// Farthest a lip's toe may lie across the profile from its centre, metres: a cut keeps the
/// line of the curb it interrupts (as [`Profile::cut_toe`]'s toe).
const LIP_MAX_OFFSET_M: f64 = 0.1;

impl Profile<'_> {
    /// The toe of a curb cut's lip: [`Profile::toe`] with a least step of
    /// [`LIP_MIN_STEP_M`] (every other rule as there: both parts ground-like, their RMS
    /// under a quarter of the step, ground beside the toe on both sides), within
    /// [`LIP_MAX_OFFSET_M`] of the centre.
    pub fn lip_toe(&self) -> Option<ProfileToe> {
        let params = BendParams {
            profile_min_step_m: LIP_MIN_STEP_M.min(self.params.profile_min_step_m),
            ..self.params.clone()
        };
        let toe = Profile {
            params: &params,
            ..*self
        }
        .toe()?;
        let n = [-self.along[1] * self.up, self.along[0] * self.up];
        let off = (toe.xyz[0] - self.centre[0]) * n[0] + (toe.xyz[1] - self.centre[1]) * n[1];
        (off.abs() <= LIP_MAX_OFFSET_M).then_some(toe)
    }
}

/// The toe of the curb cut a track follows on `on_line` (the profile on the track's line,
/// [`Profile::cut_toe`]'s length) where neither the break of slope nor the flush hinge
/// ([`Profile::flush_toe`]) finds one: the lip's step, on `on_line` or on the profile twice
/// as long. Where the scanner's lines run nearly along a far
/// curb its returns lie a few decimetres apart, and the profile of the default length holds
/// too few of them on one side of the toe. Meant for a track along the road only: a longer
/// profile at a corner spans the curb's turn, and a low step on a side street's line runs
/// on past its curb.
pub fn sparse_cut_toe(on_line: &Profile) -> Option<ProfileToe> {
    let long = on_line.with_half_l(2.0 * on_line.half_l);
    on_line.lip_toe().or_else(|| long.lip_toe())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bend::fixture::KeptPoints;
    use crate::bend::grid::PointGrid;
    use crate::io::trajectory::Trajectory;

    /// A profile walking along +y with the curb on the right (+x), its centre at x = 0,
    /// over scanlines along y at the offsets `xs` (points every 5 cm along), the road at
    /// z = 0 for x < `toe` and the lip's level `lip` behind it; `f` asks the profile.
    fn on_lip<T>(xs: &[f64], toe: f64, lip: f64, f: impl Fn(Profile) -> T) -> T {
        let (mut x, mut y, mut z) = (Vec::new(), Vec::new(), Vec::new());
        for &px in xs {
            for j in 0..13 {
                x.push(px);
                y.push(-0.3 + 0.05 * f64::from(j));
                z.push(if px < toe { 0.0 } else { lip });
            }
        }
        let points = KeptPoints::new(x, y, z);
        let trajectory = Trajectory::default();
        let input = points.input(&trajectory);
        let grid = PointGrid::build(input.x, input.y, 0.1, |_| true);
        let params = BendParams::default();
        f(Profile {
            input: &input,
            grid: &grid,
            params: &params,
            centre: [0.0, 0.0, 0.0],
            along: [0.0, 1.0],
            up: -1.0,
            half_l: 0.3,
        })
    }

    /// Scanlines along the curb 0.1 m apart, from 0.25 m before the toe to 0.25 m
    /// behind: too little ground either side for the break of slope.
    const SPARSE: [f64; 6] = [-0.25, -0.15, -0.05, 0.05, 0.15, 0.25];

    #[test]
    fn a_lip_between_sparse_scanlines_gives_its_toe_where_the_break_of_slope_gives_none() {
        let shifted = |d: f64| SPARSE.map(|x| x + d);
        for (d, lip) in [(0.0, 0.02), (0.04, 0.03), (-0.06, 0.025)] {
            let xs = shifted(d);
            assert!(on_lip(&xs, d, lip, |p| p.cut_toe()).is_none());
            assert!(on_lip(&xs, d, lip, |p| p.toe()).is_none());
            let toe = on_lip(&xs, d, lip, |p| p.lip_toe()).expect("a lip's toe");
            assert!(
                (toe.xyz[0] - d).abs() <= 0.051,
                "toe at {} for {d}",
                toe.xyz[0]
            );
            assert!((toe.step_m - lip).abs() < 0.002);
        }
    }

    #[test]
    fn no_lip_toe_off_the_line_on_flat_road_or_under_the_least_step() {
        assert!(on_lip(&SPARSE.map(|x| x + 0.2), 0.2, 0.03, |p| p.lip_toe()).is_none());
        assert!(on_lip(&SPARSE, 0.0, 0.0, |p| p.lip_toe()).is_none());
        assert!(on_lip(&SPARSE, 0.0, 0.01, |p| p.lip_toe()).is_none());
    }
}
