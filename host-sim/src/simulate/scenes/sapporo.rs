//! Sapporo-like street.

use super::{common, cut};
use crate::model::Side;
use crate::simulate::centerline::Piece;
use crate::simulate::scene::{Intersection, SceneSpec};

/// Sapporo-like: 7.5 m wide with 80 mm curbs, then 11.5 m with 170 mm curbs; the far
/// (right) side is sparse.
pub(super) fn sapporo() -> SceneSpec {
    use Side::{Left as L, Right as R};
    SceneSpec {
        origin: [528350.0, 4767120.0, 20.0],
        heading_deg: 15.0,
        pieces: vec![
            Piece::Straight(200.0),
            Piece::Arc(300.0, -6.0),
            Piece::Straight(200.0),
        ],
        u_range: (-40.0, 370.0),
        drive: (0.0, 330.0),
        speed_kmh: 35.0,
        half_width: vec![(0.0, 3.75, 3.75), (215.0, 3.75, 3.75), (245.0, 5.75, 5.75)],
        curb_h: vec![(0.0, 0.08, 0.08), (215.0, 0.08, 0.08), (245.0, 0.17, 0.17)],
        lane_from_left_m: 1.9,
        sidewalk_m: (2.5, 2.5),
        curb_cuts: vec![
            cut(L, 35.0, 4.0),
            cut(L, 70.0, 5.0),
            cut(L, 160.0, 4.0),
            cut(L, 190.0, 3.5),
            cut(L, 265.0, 5.0),
            cut(L, 300.0, 4.0),
            cut(R, 50.0, 4.0),
            cut(R, 180.0, 5.0),
            cut(R, 310.0, 4.0),
        ],
        intersections: vec![
            Intersection {
                side: L,
                u: 120.0,
                width: 7.0,
                radius: 5.0,
                length: 25.0,
                angle_deg: 90.0,
                flare: 1.0,
            },
            Intersection {
                side: R,
                u: 275.0,
                width: 8.0,
                radius: 8.0,
                length: 25.0,
                angle_deg: 90.0,
                flare: 1.0,
            },
        ],
        bus_bays: Vec::new(),
        parked_cars: vec![(L, 245.0), (R, 95.0)],
        weeds: vec![(L, 20.0, 100.0), (R, 140.0, 240.0)],
        leaves_per_100m: 40.0,
        pole_spacing_m: 35.0,
        ..common("sapporo")
    }
}
