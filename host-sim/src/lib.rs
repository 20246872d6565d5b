//! # curbtrace-host-sim
//!
//! The `std` half of curbtrace: reads LAS/LAZ and trajectories, projects points into the
//! scanner's x′–z′ plane (Honma et al. step a), replays them through exactly the
//! `curbtrace-core` kernel the scanner runs, then seeds, tracks and filters road edges
//! (steps e–f). Beside it: the plane-based method of Qiu et al., the evaluation of
//! Heipke et al., a scene simulator and plots.
//!
//! Module map (one folder per concern):
//!
//! | module | what |
//! |---|---|
//! | [`model`] | shared types: sides, categories, polylines, edges; reading GeoJSON lines |
//! | `io` | LAS/LAZ reading (columns), trajectory CSV, lidar frames (KITTI, nuScenes, PCD) |
//! | `mounts` | where each scanner sits on the vehicle: lever arm and angles, the scanner origin's trajectory |
//! | `replay` | projection (step a), wire encoding, running the core in-process; candidates and per-point status |
//! | `rings` | spinning lidars: rings cut into half-arcs as scanlines, per-sensor kernel defaults |
//! | `frame` | curbs in one lidar frame: half-arcs through the core, step check, linking, output |
//! | `bend` | seeding (§2.6), tracking (§2.7), post-filters |
//! | `curb` | the curb beside each toe: top of curb, height per vertex, class and support of every stretch |
//! | `output` | sinks: GeoJSON and CSV writers of the edges |
//! | `proc_stats` | CPU time and peak memory of this process, from `/proc` |
//! | `qiu` | the second method (Qiu et al. 2016) |
//! | `eval` | completeness, correctness, quality, RMS, gaps (docs/spec.md §5) |
//! | `simulate` | the scene simulator |
//! | `plot` | pictures |

pub mod bend;
pub mod config;
pub mod curb;
pub mod eval;
pub mod frame;
pub mod io;
pub mod model;
pub mod mounts;
pub mod output;
pub mod pipeline;
pub mod plot;
pub mod proc_stats;
pub mod qiu;
pub mod replay;
pub mod rings;
pub mod simulate;
pub mod source;
pub mod stream;
