//! # curbtrace-core
//!
//! The `no_std`, allocation-free streaming kernel of curbtrace. It runs on the scanner's own
//! controller (a Cortex-M4F) and, bit for bit the same, inside `curbtrace` on a PC.
//!
//! Layers, from bytes to curb candidates (Honma et al. steps b–e):
//!
//! - [`wire`] — the scanline packet format: bytes ↔ packets, no float maths
//!   (`docs/wire-format.md` is its specification).
//! - [`scanline`] — a fixed-capacity byte [`scanline::ring::Ring`] that a producer (DMA, UART
//!   interrupt, file reader) writes into, and the [`scanline::assemble::Assembler`] that turns
//!   parsed point packets into one [`scanline::Line`] at a time.
//! - [`kernel`] — per scanline: bend angle ρ (§2.3), removal of irregular points (§2.4), Taubin
//!   smoothing (§2.5), ρ again, peaks and the first peak each side of the nadir (§2.6).
//! - [`pipeline`] — ingest and kernel together, bytes in, results out, and the encoding of
//!   a line's result as output packets.
//!
//! Every buffer is bounded by a const generic; every byte and every point that enters is
//! accounted for in counters.
//!
//! # Features
//!
//! - `libm` (default) — bit-exact maths, the same output bytes on every platform.
//! - `micromath` — fast approximate maths. **If it is on, it is the backend**, also when
//!   `libm` is on too (as with `--features micromath` and the default features); libm is
//!   then compiled only for the tests that compare the two. [`math::BACKEND`] says which
//!   backend a build uses; [`math`] explains the rule.
//! - `serde` — `Serialize`/`Deserialize` for [`kernel::KernelParams`] (no alloc).
//! - `defmt` — `defmt::Format` for logging on target.
#![no_std]
#![forbid(unsafe_code)]
#![deny(missing_docs)]

pub mod kernel;
pub mod math;
pub mod pipeline;
pub mod scanline;
pub mod wire;

pub use pipeline::{encode_output, Pipeline, PipelineCounters};
