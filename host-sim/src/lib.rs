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
//! | [`model`] | shared types: sides, categories, polylines, edges; GeoJSON in and out |
//! | `io` | LAS/LAZ reading (columns), trajectory CSV, output writers |
//! | `replay` | projection (step a), wire encoding, running the core in-process |
//! | `bend` | seeding (§2.6), tracking (§2.7), post-filters |
//! | `qiu` | the second method (Qiu et al. 2016) |
//! | `eval` | completeness, correctness, quality, RMS, gaps (SPEC §5) |
//! | `simulate` | the scene simulator |
//! | `plot` | pictures |

pub mod bend;
pub mod config;
pub mod eval;
pub mod io;
pub mod model;
pub mod output;
pub mod pipeline;
pub mod plot;
pub mod qiu;
pub mod replay;
pub mod simulate;
