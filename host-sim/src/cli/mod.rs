//! One file per subcommand: argument struct and `run`.

pub mod demo;
pub mod eval;
pub mod extract;
pub mod frame;
pub mod kernel;
pub mod replay;
pub mod simulate;
