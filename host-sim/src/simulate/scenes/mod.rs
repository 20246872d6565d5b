//! The named scenes, one file each, and what they share.

mod curvy;
mod kawasaki;
pub mod random;
mod sapporo;
mod tiny;

use super::ground::{Base, CurbShape};
use super::scene::{CurbCut, ScannerConfig, SceneSpec};
use crate::model::Side;

/// Names of the built-in scenes.
pub const SCENE_NAMES: [&str; 4] = ["kawasaki", "sapporo", "curvy", "tiny"];

impl SceneSpec {
    /// A built-in scene by name.
    pub fn by_name(name: &str) -> Option<SceneSpec> {
        match name {
            "kawasaki" => Some(kawasaki::kawasaki()),
            "sapporo" => Some(sapporo::sapporo()),
            "curvy" => Some(curvy::curvy()),
            "tiny" => Some(tiny::tiny()),
            _ => None,
        }
    }
}

pub(super) fn common(name: &str) -> SceneSpec {
    SceneSpec {
        name: name.into(),
        epsg: 6691,
        origin: [0.0; 3],
        heading_deg: 0.0,
        pieces: Vec::new(),
        u_range: (-40.0, 0.0),
        drive: (0.0, 0.0),
        speed_kmh: 30.0,
        half_width: vec![(0.0, 5.0, 5.0)],
        curb_h: vec![(0.0, 0.2, 0.2)],
        lane_from_left_m: 2.5,
        lane_changes: Vec::new(),
        description: String::new(),
        sidewalk_m: (3.0, 3.0),
        curb_cuts: Vec::new(),
        intersections: Vec::new(),
        bus_bays: Vec::new(),
        parked_cars: Vec::new(),
        parked: Vec::new(),
        weeds: Vec::new(),
        leaves_per_100m: 60.0,
        pole_spacing_m: 30.0,
        shape: CurbShape::default(),
        base: Base {
            grade_x: 0.004,
            grade_y: -0.006,
            wave_m: 0.3,
        },
        scanner: ScannerConfig::default(),
    }
}

pub(super) fn cut(side: Side, u: f64, len: f64) -> CurbCut {
    CurbCut {
        side,
        u,
        len,
        h: 0.025,
        transition_m: 1.0,
        flush: false,
    }
}
