//! Output packets: one fragment of one scanline's kernel result (core → host, over an
//! Ethernet-class link). A line of `line_len` points travels as
//! ⌈line_len / [`MAX_OUTPUT_POINTS_PER_PACKET`]⌉ packets (one empty packet for an empty
//! line); every fragment repeats the line header, so each packet is self-describing and a
//! lost fragment loses only its own points.
//!
//! [`MAX_OUTPUT_POINTS_PER_PACKET`]: super::MAX_OUTPUT_POINTS_PER_PACKET
//!
//! Values are scaled integers: x′/z′ in micrometres (`i32`, ±2147 m — at a scanner's
//! ranges an `f32` itself resolves about 1–8 µm), ρ in centidegrees (`i16`,
//! −17 999..=18 000 for (−180°, 180°]).
//!
//! One file per subject: `packet` — the line header, parsing a packet and writing one
//! fragment point by point; `point` — one output point, its scaling and its record words;
//! `columns` — the encoder's fast path for a line given as columns; `candidates` — the
//! version-2 packet that carries only a line's nadir and candidates.

mod candidates;
mod columns;
mod packet;
mod point;
#[cfg(test)]
mod tests;

use super::{CRC_LEN, HEADER_LEN};

pub use candidates::{CandidatesRepr, CANDIDATES_PACKET_LEN};
pub(super) use columns::emit_output_fragment_columns;
pub use columns::OutputColumns;
pub(super) use packet::emit_output_fragment;
pub use packet::{OutputHeaderRepr, OutputPoints};
pub use point::OutputPointRepr;

/// Length of the per-line header at the start of an output payload.
pub const OUTPUT_HEADER_LEN: usize = 40;
/// Length of one output point.
pub const OUTPUT_POINT_LEN: usize = 16;
/// The value of an index field meaning "none".
const NO_INDEX: u16 = 0xFFFF;

/// Total length of an output packet with `count` points.
pub const fn output_packet_len(count: usize) -> usize {
    HEADER_LEN + OUTPUT_HEADER_LEN + count * OUTPUT_POINT_LEN + CRC_LEN
}
