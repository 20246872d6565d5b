//! Input and output: LAS/LAZ point columns, the trajectory CSV, output writers.

pub mod las;
pub mod trajectory;

/// The LAS/LAZ reader under the name the rest of the workspace imports it by.
pub use self::las as las_in;
