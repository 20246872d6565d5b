//! Input and output: LAS/LAZ point columns, the trajectory CSV, output writers.

pub mod las_in;
pub mod trajectory;
