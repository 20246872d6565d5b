//! [`StreamEncoder`]: writes whole packets and keeps the sequence numbers (no_std, no alloc).

use super::output::{emit_output_fragment, emit_output_fragment_columns};
use super::points::emit_points;
use super::{
    CandidatesRepr, ConfigRepr, EncodeError, OutputColumns, OutputHeaderRepr, OutputPointRepr,
    PointRecord, CONFIG_WORDS, MAX_OUTPUT_POINTS_PER_PACKET,
};

/// Encodes packets of one stream. Every successfully written packet takes the next sequence
/// number (wrapping at 2³²); a failed encode writes nothing usable and takes none.
#[derive(Clone, Debug, Default)]
pub struct StreamEncoder {
    seq: u32,
    link_checked: bool,
}

impl StreamEncoder {
    /// An encoder whose first packet has sequence number 0.
    pub const fn new() -> Self {
        Self {
            seq: 0,
            link_checked: false,
        }
    }

    /// This encoder, writing every packet as [`super::FLAG_LINK_CHECKED`] (version 2, CRC
    /// field zero) when `on`: for a link that checks integrity itself.
    pub const fn link_checked(self, on: bool) -> Self {
        Self {
            link_checked: on,
            ..self
        }
    }

    /// An encoder whose first packet has sequence number `seq`.
    pub const fn with_seq(seq: u32) -> Self {
        Self {
            seq,
            link_checked: false,
        }
    }

    /// The sequence number the next packet will carry.
    pub fn seq(&self) -> u32 {
        self.seq
    }

    fn bump(
        &mut self,
        r: Result<usize, EncodeError>,
        out: &mut [u8],
    ) -> Result<usize, EncodeError> {
        if r.is_ok() {
            self.seq = self.seq.wrapping_add(1);
            if self.link_checked {
                super::mark_link_checked(out);
            }
        }
        r
    }

    /// Writes a config packet carrying `words`; returns its length
    /// ([`super::CONFIG_PACKET_LEN`]).
    pub fn encode_config(
        &mut self,
        words: &[u32; CONFIG_WORDS],
        out: &mut [u8],
    ) -> Result<usize, EncodeError> {
        let r = ConfigRepr { words: *words }.emit(self.seq, out);
        self.bump(r, out)
    }

    /// Writes a candidates packet (version 2): one line's nadir and seed candidates.
    /// Returns its length ([`super::CANDIDATES_PACKET_LEN`]).
    pub fn encode_candidates(
        &mut self,
        repr: &CandidatesRepr,
        out: &mut [u8],
    ) -> Result<usize, EncodeError> {
        let r = repr.emit(self.seq, out);
        self.bump(r, out)
    }

    /// Writes a points packet: `points` (at most [`super::MAX_POINTS_PER_PACKET`]) with times
    /// `base_time_ns + dt_ns`. Rejects NaN/infinite coordinates
    /// ([`EncodeError::NonFinite`] with the point's index). Returns the packet length.
    pub fn encode_points(
        &mut self,
        base_time_ns: u64,
        points: &[PointRecord],
        out: &mut [u8],
    ) -> Result<usize, EncodeError> {
        let r = emit_points(self.seq, base_time_ns, points, out);
        self.bump(r, out)
    }

    /// Writes one output packet: `header` describes the line and `header.first` is the index
    /// of `points[0]` within it; `points` must be exactly that fragment (the capacity of a
    /// packet, or the rest of the line). Returns the packet length.
    pub fn encode_output(
        &mut self,
        header: &OutputHeaderRepr,
        points: &[OutputPointRepr],
        out: &mut [u8],
    ) -> Result<usize, EncodeError> {
        let first = usize::from(header.first);
        let expected = usize::from(header.line_len)
            .saturating_sub(first)
            .min(MAX_OUTPUT_POINTS_PER_PACKET);
        if points.len() != expected {
            return Err(EncodeError::TooManyPoints {
                count: points.len(),
                max: expected,
            });
        }
        let mut get = |i: usize| {
            i.checked_sub(first)
                .and_then(|k| points.get(k))
                .copied()
                .ok_or(EncodeError::OutOfRange { index: i })
        };
        let r = emit_output_fragment(self.seq, header, header.first, &mut get, out);
        self.bump(r, out)
    }

    /// Writes the output packet of `header`'s line that starts at point `first` (0, then
    /// steps of [`MAX_OUTPUT_POINTS_PER_PACKET`] up to `line_len`), taking point `i` of the
    /// line from `point(i)`. For RAM-tight senders: one packet buffer of
    /// [`super::MAX_PACKET_LEN`] bytes, send it, call again with the next `first`. Returns
    /// the packet length.
    pub fn encode_output_fragment(
        &mut self,
        header: &OutputHeaderRepr,
        first: u16,
        mut point: impl FnMut(usize) -> Result<OutputPointRepr, EncodeError>,
        out: &mut [u8],
    ) -> Result<usize, EncodeError> {
        let r = emit_output_fragment(self.seq, header, first, &mut point, out);
        self.bump(r, out)
    }

    /// [`Self::encode_output_fragment`] for a line held as columns (the kernel's structure
    /// of arrays): point `i` is built from `cols` in a tight loop that builds each record
    /// in registers and stores it as four words. Points it does not take —
    /// `wire_status(cols.status[i])` is `None`, a value is non-finite or large (|x′|, |z′|
    /// ≥ 1024 m, |ρ| > 180°), or a column is too short — come from `point(i)`, exactly as
    /// [`Self::encode_output_fragment`] would take them, with the same errors. For the same
    /// points the bytes are identical.
    pub fn encode_output_columns<S: Copy>(
        &mut self,
        header: &OutputHeaderRepr,
        first: u16,
        cols: &OutputColumns<'_, S>,
        wire_status: impl Fn(S) -> Option<u8>,
        mut point: impl FnMut(usize) -> Result<OutputPointRepr, EncodeError>,
        out: &mut [u8],
    ) -> Result<usize, EncodeError> {
        let r = emit_output_fragment_columns(
            self.seq,
            header,
            first,
            cols,
            wire_status,
            &mut point,
            out,
        );
        self.bump(r, out)
    }

    /// Writes all [`OutputHeaderRepr::fragments`] packets of `header`'s line back to back
    /// into `out` (a stream is a concatenation of packets), taking point `i` from `point(i)`;
    /// `header.first` is ignored. Returns the bytes written. On an error, packets already
    /// written stay written (and have used their sequence numbers).
    pub fn encode_output_line(
        &mut self,
        header: &OutputHeaderRepr,
        mut point: impl FnMut(usize) -> Result<OutputPointRepr, EncodeError>,
        out: &mut [u8],
    ) -> Result<usize, EncodeError> {
        let mut at = 0usize;
        for k in 0..header.fragments() {
            let first = OutputHeaderRepr::fragment_first(k)?;
            let dst = out.get_mut(at..).unwrap_or(&mut []);
            let n = self.encode_output_fragment(header, first, &mut point, dst)?;
            at += n;
        }
        Ok(at)
    }
}
