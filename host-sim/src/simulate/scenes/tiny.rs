//! The small test scene.

use super::{common, cut};
use crate::model::Side;
use crate::simulate::centerline::Piece;
use crate::simulate::scene::SceneSpec;

/// 30 m straight for tests: 8 m wide, 150 mm curbs, one curb cut, a pole, leaves, weeds.
pub(super) fn tiny() -> SceneSpec {
    use Side::Left as L;
    SceneSpec {
        origin: [455120.5, 3951870.25, 8.0],
        heading_deg: 100.0,
        pieces: vec![Piece::Straight(100.0)],
        u_range: (-25.0, 55.0),
        drive: (0.0, 30.0),
        speed_kmh: 30.0,
        half_width: vec![(0.0, 4.0, 4.0)],
        curb_h: vec![(0.0, 0.15, 0.15)],
        lane_from_left_m: 2.3,
        sidewalk_m: (2.5, 2.5),
        curb_cuts: vec![cut(L, 16.0, 4.0)],
        weeds: vec![(L, 0.0, 12.0)],
        leaves_per_100m: 60.0,
        pole_spacing_m: 25.0,
        ..common("tiny")
    }
}
