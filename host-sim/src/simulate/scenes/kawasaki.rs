//! Kawasaki-like street.

use super::{common, cut};
use crate::model::Side;
use crate::simulate::centerline::Piece;
use crate::simulate::scene::{BusBay, CurbCut, Intersection, SceneSpec};

/// Kawasaki-like: 2 lanes, 10 m wide, 200 mm curbs, curb cuts, 2 intersections, parked
/// cars, weeds, a bus bay (Honma et al. §3.1).
pub(super) fn kawasaki() -> SceneSpec {
    use Side::{Left as L, Right as R};
    SceneSpec {
        origin: [382417.25, 3930168.5, 12.0],
        heading_deg: 62.0,
        pieces: vec![
            Piece::Straight(190.0),
            Piece::Arc(400.0, 8.0),
            Piece::Straight(250.0),
        ],
        u_range: (-40.0, 390.0),
        drive: (0.0, 350.0),
        speed_kmh: 30.0,
        half_width: vec![(0.0, 5.0, 5.0)],
        curb_h: vec![(0.0, 0.2, 0.2)],
        lane_from_left_m: 2.6,
        sidewalk_m: (3.0, 2.5),
        curb_cuts: vec![
            cut(L, 28.0, 4.0),
            cut(L, 52.0, 5.5),
            cut(L, 148.0, 3.5),
            cut(L, 178.0, 6.0),
            cut(L, 282.0, 4.0),
            cut(L, 318.0, 5.0),
            cut(R, 38.0, 4.5),
            cut(R, 140.0, 5.0),
            cut(R, 300.0, 4.0),
            CurbCut {
                side: R,
                u: 338.0,
                len: 3.0,
                h: 0.03,
                transition_m: 1.0,
                flush: false,
            },
        ],
        intersections: vec![
            Intersection {
                side: L,
                u: 95.0,
                width: 8.0,
                radius: 6.0,
                length: 25.0,
                angle_deg: 90.0,
                flare: 1.0,
            },
            Intersection {
                side: R,
                u: 255.0,
                width: 7.0,
                radius: 5.0,
                length: 25.0,
                angle_deg: 90.0,
                flare: 1.0,
            },
        ],
        bus_bays: vec![BusBay {
            side: L,
            u0: 200.0,
            lens: [12.0, 16.0, 10.0],
            depth: 2.8,
        }],
        parked_cars: vec![
            (L, 68.0),
            (L, 122.0),
            (L, 128.5),
            (L, 258.0),
            (R, 110.0),
            (R, 185.0),
            (R, 322.0),
        ],
        weeds: vec![
            (L, 10.0, 80.0),
            (L, 155.0, 195.0),
            (R, 90.0, 220.0),
            (R, 280.0, 350.0),
        ],
        leaves_per_100m: 80.0,
        pole_spacing_m: 30.0,
        ..common("kawasaki")
    }
}
