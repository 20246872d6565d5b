//! The output packet: the per-line header every fragment repeats, parsing a packet into
//! header and points, and writing one fragment point by point.

use super::super::{
    emit_header, field, flags_version, get_u16, get_u32, get_u64, get_u8, put_bytes, seal,
    EncodeError, Error, Packet, PacketKind, CRC_LEN, MAX_OUTPUT_POINTS_PER_PACKET, VERSION,
    VERSION_1,
};
use super::{output_packet_len, OutputPointRepr, NO_INDEX, OUTPUT_POINT_LEN};

/// The per-line part of an output packet (repeated in every fragment).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct OutputHeaderRepr {
    /// Scanline number in the stream.
    pub index: u32,
    /// Absolute time of the line's first point, GPS nanoseconds.
    pub start_time_ns: u64,
    /// Hash of the kernel parameters that produced the output.
    pub params_hash: u32,
    /// Points of the line dropped by assembly (line over capacity).
    pub truncated: u32,
    /// Points in the whole line (all fragments).
    pub line_len: u16,
    /// Index within the line of this fragment's first point (the encoder sets it).
    pub first: u16,
    /// Index of the nadir point, if any (`< line_len`).
    pub nadir: Option<u16>,
    /// Index of the left seed candidate, if any (`< line_len`).
    pub left: Option<u16>,
    /// Index of the right seed candidate, if any (`< line_len`).
    pub right: Option<u16>,
    /// Kernel counter: points kept.
    pub kept: u16,
    /// Kernel counter: points removed as irregular.
    pub irregular: u16,
    /// Kernel counter: points without a neighbour on one side.
    pub no_neighbour: u16,
    /// Kernel counter: peaks found.
    pub peaks: u16,
    /// Points of the line outside the region of interest (not processed by the kernel).
    /// Version 2: a packet with a non-zero count is written as version 2; in version 1 the
    /// field is reserved and zero.
    pub outside: u16,
}

impl OutputHeaderRepr {
    /// Number of packets the line takes.
    pub fn fragments(&self) -> usize {
        usize::from(self.line_len)
            .div_ceil(MAX_OUTPUT_POINTS_PER_PACKET)
            .max(1)
    }

    /// The first point of fragment `k` (`k < fragments()`), as the packet carries it.
    pub(crate) fn fragment_first(k: usize) -> Result<u16, EncodeError> {
        k.checked_mul(MAX_OUTPUT_POINTS_PER_PACKET)
            .and_then(|f| u16::try_from(f).ok())
            .ok_or(EncodeError::OutOfRange { index: k })
    }

    /// The lowest format version that carries this header.
    pub fn version(&self) -> u8 {
        if self.outside != 0 {
            VERSION
        } else {
            VERSION_1
        }
    }

    /// Reads the line header of an output or candidates packet whose envelope has been
    /// checked, and checks the fields the two kinds share (the version against `outside`,
    /// the indices against `line_len`).
    pub(super) fn read(b: &[u8], version: u8) -> Result<Self, Error> {
        use field::out;
        let h = Self {
            index: get_u32(b, out::INDEX),
            start_time_ns: get_u64(b, out::START_TIME),
            params_hash: get_u32(b, out::PARAMS_HASH),
            truncated: get_u32(b, out::TRUNCATED),
            line_len: get_u16(b, out::LINE_LEN),
            first: get_u16(b, out::FIRST),
            nadir: opt_index(get_u16(b, out::NADIR)),
            left: opt_index(get_u16(b, out::LEFT)),
            right: opt_index(get_u16(b, out::RIGHT)),
            kept: get_u16(b, out::KEPT),
            irregular: get_u16(b, out::IRREGULAR),
            no_neighbour: get_u16(b, out::NO_NEIGHBOUR),
            peaks: get_u16(b, out::PEAKS),
            outside: get_u16(b, out::OUTSIDE),
        };
        if version < h.version() {
            return Err(Error::ReservedNotZero {
                offset: out::OUTSIDE.start,
            });
        }
        // One encoding per packet: an output packet takes the lowest version that carries
        // it (a candidates packet is version 2 whatever its count).
        let need = h.version().max(flags_version(get_u16(b, field::FLAGS)));
        if version > need && get_u8(b, field::KIND) == PacketKind::Output as u8 {
            return Err(Error::BadVersion { version });
        }
        if !h.indices_ok() {
            return Err(Error::OutOfRange {
                offset: out::NADIR.start,
            });
        }
        Ok(h)
    }

    /// Writes the line header (with `first`) after the packet header.
    pub(super) fn put(&self, first: u16, out: &mut [u8]) {
        use field::out as f;
        let idx = |v: Option<u16>| v.unwrap_or(NO_INDEX).to_le_bytes();
        put_bytes(out, f::INDEX.start, &self.index.to_le_bytes());
        put_bytes(out, f::START_TIME.start, &self.start_time_ns.to_le_bytes());
        put_bytes(out, f::PARAMS_HASH.start, &self.params_hash.to_le_bytes());
        put_bytes(out, f::TRUNCATED.start, &self.truncated.to_le_bytes());
        put_bytes(out, f::LINE_LEN.start, &self.line_len.to_le_bytes());
        put_bytes(out, f::FIRST.start, &first.to_le_bytes());
        put_bytes(out, f::NADIR.start, &idx(self.nadir));
        put_bytes(out, f::LEFT.start, &idx(self.left));
        put_bytes(out, f::RIGHT.start, &idx(self.right));
        put_bytes(out, f::KEPT.start, &self.kept.to_le_bytes());
        put_bytes(out, f::IRREGULAR.start, &self.irregular.to_le_bytes());
        put_bytes(out, f::NO_NEIGHBOUR.start, &self.no_neighbour.to_le_bytes());
        put_bytes(out, f::PEAKS.start, &self.peaks.to_le_bytes());
        put_bytes(out, f::OUTSIDE.start, &self.outside.to_le_bytes());
    }

    /// Checks the index fields against `line_len`.
    pub(super) fn indices_ok(&self) -> bool {
        [self.nadir, self.left, self.right]
            .iter()
            .all(|i| i.is_none_or(|v| v < self.line_len))
    }
}

fn opt_index(v: u16) -> Option<u16> {
    (v != NO_INDEX).then_some(v)
}

/// The points of a parsed output packet (already validated by [`OutputHeaderRepr::parse`]).
#[derive(Clone, Debug)]
pub struct OutputPoints<'a> {
    rest: core::slice::ChunksExact<'a, u8>,
}

impl Iterator for OutputPoints<'_> {
    type Item = OutputPointRepr;
    fn next(&mut self) -> Option<Self::Item> {
        // Validated in parse; a failure here cannot happen and ends the iteration.
        self.rest
            .next()
            .and_then(|b| OutputPointRepr::parse(b).ok())
    }
    fn size_hint(&self) -> (usize, Option<usize>) {
        self.rest.size_hint()
    }
}

impl ExactSizeIterator for OutputPoints<'_> {}

impl OutputHeaderRepr {
    /// Parses an output packet (full check: CRC, version, kind, length, header fields and
    /// every point) and returns its header and its points.
    pub fn parse<T: AsRef<[u8]>>(packet: &Packet<T>) -> Result<(Self, OutputPoints<'_>), Error> {
        let kind = packet.check()?;
        if kind != PacketKind::Output {
            return Err(Error::WrongKind { kind: kind as u8 });
        }
        let b = packet.bytes();
        use field::out;
        let h = Self::read(b, packet.version())?;
        let pts = b
            .get(out::POINTS..b.len().saturating_sub(CRC_LEN))
            .unwrap_or(&[]);
        let count = pts.len() / OUTPUT_POINT_LEN;
        // Canonical fragmentation: fragments start at multiples of the packet capacity,
        // are full except the last, and only an empty line has an empty packet.
        let first = usize::from(h.first);
        let line_len = usize::from(h.line_len);
        let expected = line_len
            .saturating_sub(first)
            .min(MAX_OUTPUT_POINTS_PER_PACKET);
        if !first.is_multiple_of(MAX_OUTPUT_POINTS_PER_PACKET)
            || (line_len > 0 && first >= line_len)
            || (line_len == 0 && first != 0)
        {
            return Err(Error::OutOfRange {
                offset: out::FIRST.start,
            });
        }
        if count != expected {
            return Err(Error::BadLength {
                length: packet.length(),
            });
        }
        for (i, rec) in pts.chunks_exact(OUTPUT_POINT_LEN).enumerate() {
            let at = out::POINTS + i * OUTPUT_POINT_LEN;
            OutputPointRepr::parse(rec).map_err(|e| match e {
                Error::OutOfRange { offset } => Error::OutOfRange {
                    offset: at + offset,
                },
                Error::ReservedNotZero { offset } => Error::ReservedNotZero {
                    offset: at + offset,
                },
                other => other,
            })?;
        }
        Ok((
            h,
            OutputPoints {
                rest: pts.chunks_exact(OUTPUT_POINT_LEN),
            },
        ))
    }
}

/// Checks `header` and `first`, writes the packet header and the line header of the
/// fragment of `header`'s line that starts at `first` (a multiple of
/// [`MAX_OUTPUT_POINTS_PER_PACKET`]); returns (points in the fragment, packet length).
pub(super) fn begin_fragment(
    seq: u32,
    header: &OutputHeaderRepr,
    first: u16,
    out: &mut [u8],
) -> Result<(usize, usize), EncodeError> {
    let line_len = usize::from(header.line_len);
    let first_us = usize::from(first);
    if !header.indices_ok() {
        return Err(EncodeError::OutOfRange { index: line_len });
    }
    if !first_us.is_multiple_of(MAX_OUTPUT_POINTS_PER_PACKET)
        || (line_len > 0 && first_us >= line_len)
        || (line_len == 0 && first_us != 0)
    {
        return Err(EncodeError::OutOfRange { index: first_us });
    }
    let count = (line_len - first_us.min(line_len)).min(MAX_OUTPUT_POINTS_PER_PACKET);
    let len = output_packet_len(count);
    if out.len() < len {
        return Err(EncodeError::BufferTooSmall {
            needed: len,
            available: out.len(),
        });
    }
    let len16 = u16::try_from(len).map_err(|_| EncodeError::TooManyPoints {
        count,
        max: MAX_OUTPUT_POINTS_PER_PACKET,
    })?;
    emit_header(out, header.version(), PacketKind::Output, len16, seq);
    header.put(first, out);
    Ok((count, len))
}

/// Writes one output packet: the fragment of `header`'s line that starts at `first` (a
/// multiple of [`MAX_OUTPUT_POINTS_PER_PACKET`]), taking point `i` of the line from
/// `point(i)`. Returns the packet length. The body of
/// [`crate::wire::StreamEncoder::encode_output_fragment`].
pub(in crate::wire) fn emit_output_fragment(
    seq: u32,
    header: &OutputHeaderRepr,
    first: u16,
    mut point: impl FnMut(usize) -> Result<OutputPointRepr, EncodeError>,
    out: &mut [u8],
) -> Result<usize, EncodeError> {
    let (_, len) = begin_fragment(seq, header, first, out)?;
    let first_us = usize::from(first);
    let recs = out
        .get_mut(field::out::POINTS..len - CRC_LEN)
        .unwrap_or(&mut [])
        .chunks_exact_mut(OUTPUT_POINT_LEN);
    for (k, rec) in recs.enumerate() {
        let i = first_us + k;
        point(i)?.emit(rec, i)?;
    }
    seal(out, len);
    Ok(len)
}
