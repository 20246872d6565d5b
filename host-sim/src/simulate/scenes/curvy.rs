//! A bend.

use super::{common, cut};
use crate::model::Side;
use crate::simulate::centerline::Piece;
use crate::simulate::scene::SceneSpec;

/// A 60 m radius bend with 150 mm curbs.
pub(super) fn curvy() -> SceneSpec {
    use Side::{Left as L, Right as R};
    SceneSpec {
        origin: [401234.0, 3940500.0, 35.0],
        heading_deg: 200.0,
        pieces: vec![
            Piece::Straight(80.0),
            Piece::Arc(60.0, 90.0),
            Piece::Straight(80.0),
        ],
        u_range: (-40.0, 230.0),
        drive: (0.0, 195.0),
        speed_kmh: 25.0,
        half_width: vec![(0.0, 4.5, 4.5)],
        curb_h: vec![(0.0, 0.15, 0.15)],
        lane_from_left_m: 2.3,
        sidewalk_m: (2.5, 3.0),
        curb_cuts: vec![
            cut(L, 25.0, 4.0),
            cut(L, 95.0, 4.0),
            cut(R, 120.0, 5.0),
            cut(L, 170.0, 4.0),
        ],
        parked_cars: vec![(R, 60.0), (L, 150.0)],
        weeds: vec![(L, 60.0, 140.0)],
        ..common("curvy")
    }
}
