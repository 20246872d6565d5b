//! Input and output: LAS/LAZ point columns, the trajectory CSV, single lidar frames
//! (KITTI, nuScenes, PCD) as [`sweep::Sweep`]s, output writers.

pub mod kitti;
pub mod las;
pub mod nuscenes;
pub mod pcd;
pub mod sweep;
pub mod trajectory;

/// The LAS/LAZ reader under the name the rest of the workspace imports it by.
pub use self::las as las_in;
