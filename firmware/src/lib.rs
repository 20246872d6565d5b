//! The target-independent part of the curbtrace firmware: the command line and the
//! processing loop, written against `embedded-io` traits so that they run (and are tested)
//! on the host as well. `main.rs` adds what is specific to the STM32F405 under QEMU:
//! start-up, semihosting files, fault handlers, the stack measurement.
#![cfg_attr(not(test), no_std)]
#![deny(missing_docs)]

pub mod app;
pub mod args;
pub mod spsc;
