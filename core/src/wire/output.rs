//! Output packets: one fragment of one scanline's kernel result (core → host, over an
//! Ethernet-class link). A line of `line_len` points travels as
//! ⌈line_len / [`MAX_OUTPUT_POINTS_PER_PACKET`]⌉ packets (one empty packet for an empty
//! line); every fragment repeats the line header, so each packet is self-describing and a
//! lost fragment loses only its own points.
//!
//! Values are scaled integers: x′/z′ in micrometres (`i32`, ±2147 m — at a scanner's
//! ranges an `f32` itself resolves about 1–8 µm), ρ in centidegrees (`i16`,
//! −17 999..=18 000 for (−180°, 180°]).

use super::{
    emit_header, field, get_u16, get_u32, get_u64, get_u8, put_bytes, seal, EncodeError, Error,
    Packet, PacketKind, CRC_LEN, HEADER_LEN, MAX_OUTPUT_POINTS_PER_PACKET,
};

/// Length of the per-line header at the start of an output payload.
pub const OUTPUT_HEADER_LEN: usize = 40;
/// Length of one output point.
pub const OUTPUT_POINT_LEN: usize = 16;
/// The value of an index field meaning "none".
const NO_INDEX: u16 = 0xFFFF;

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

    /// Checks the index fields against `line_len`.
    fn indices_ok(&self) -> bool {
        [self.nadir, self.left, self.right]
            .iter()
            .all(|i| i.is_none_or(|v| v < self.line_len))
    }
}

fn opt_index(v: u16) -> Option<u16> {
    (v != NO_INDEX).then_some(v)
}

/// One point of an output packet.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct OutputPointRepr {
    /// The pass-through tag of the input point.
    pub tag: u32,
    /// Smoothed x′, micrometres.
    pub x_um: i32,
    /// Smoothed z′, micrometres.
    pub z_um: i32,
    /// Bend angle ρ, centidegrees, −17 999..=18 000.
    pub rho_cdeg: i16,
    /// Point status, opaque to the wire (the kernel's `PointStatus` as `u8`).
    pub status: u8,
}

/// Rounds `v · scale` half away from zero into `lo..=hi`; `None` if non-finite or out of
/// range. f32 multiplication is correctly rounded (IEEE 754), so host and M4F agree.
fn scale_round(v: f32, scale: f32, lo: i32, hi: i32) -> Option<i32> {
    if !v.is_finite() {
        return None;
    }
    let s = v * scale;
    // 2^31 is exact in f32; anything outside (−2^31, 2^31) cannot be an i32.
    if !(s > -2_147_483_648.0 && s < 2_147_483_648.0) {
        return None;
    }
    // In range, `as` truncates toward zero without saturating; the remainder is exact
    // (Sterbenz), so the rounding below is exact too.
    let t = s as i32;
    let frac = s - t as f32;
    let r = if frac >= 0.5 {
        t.checked_add(1)?
    } else if frac <= -0.5 {
        t.checked_sub(1)?
    } else {
        t
    };
    (lo..=hi).contains(&r).then_some(r)
}

/// [`scale_round`] for the common case, in fewer instructions (the output encodes three
/// values per point): `None` whenever |v · scale| ≥ 2^30 or `v` is NaN, and then the caller
/// takes [`scale_round`]; otherwise the same value (tested against it).
///
/// Why it is the same: 2·(v·scale) = v·(2·scale) exactly (doubling is exact, and rounding
/// commutes with it), so q = trunc(2s) = 2·trunc(s) + trunc(2·frac) with trunc(2·frac) ∈
/// {−1, 0, 1} of the sign of s — 1 exactly when frac ≥ 0.5, −1 exactly when frac ≤ −0.5.
/// Then (q + 1) / 2 for q ≥ 0 and (q − 1) / 2 for q < 0 (integer division truncates) is
/// s rounded half away from zero. |q| < 2^31: no overflow anywhere.
#[inline(always)]
fn scale_round_fast(v: f32, twice_scale: f32) -> Option<i32> {
    let s2 = v * twice_scale;
    // |s2| < 2^31 (bit pattern of 2^31 is 0x4F00_0000); false for NaN and ±inf.
    if s2.to_bits() & 0x7FFF_FFFF >= 0x4F00_0000 {
        return None;
    }
    let q = s2 as i32; // truncates; exact in range
    Some((q + ((q >> 31) | 1)) / 2)
}

impl OutputPointRepr {
    /// Builds a point from the kernel's f32 values: x′, z′ in metres (rounded to µm), ρ in
    /// degrees (rounded to centidegrees; −180.00 becomes +180.00). `index` is reported in
    /// errors: [`EncodeError::NonFinite`] or [`EncodeError::OutOfRange`] (|x′|, |z′| ≥ 2147 m,
    /// ρ outside [−180, 180]).
    pub fn from_f32(
        tag: u32,
        x_m: f32,
        z_m: f32,
        rho_deg: f32,
        status: u8,
        index: usize,
    ) -> Result<Self, EncodeError> {
        if let (Some(x_um), Some(z_um), Some(rho)) = (
            scale_round_fast(x_m, 2e6),
            scale_round_fast(z_m, 2e6),
            scale_round_fast(rho_deg, 200.0),
        ) {
            // |x_um|, |z_um| ≤ 2^30: in range of the i32 fields; ρ needs its own range.
            if (-18_000..=18_000).contains(&rho) {
                return Ok(Self {
                    tag,
                    x_um,
                    z_um,
                    rho_cdeg: if rho == -18_000 { 18_000 } else { rho as i16 },
                    status,
                });
            }
        }
        // Large, non-finite or out-of-range values: the general path and its errors.
        if !(x_m.is_finite() && z_m.is_finite() && rho_deg.is_finite()) {
            return Err(EncodeError::NonFinite { index });
        }
        let oor = EncodeError::OutOfRange { index };
        let x_um = scale_round(x_m, 1e6, i32::MIN, i32::MAX).ok_or(oor)?;
        let z_um = scale_round(z_m, 1e6, i32::MIN, i32::MAX).ok_or(oor)?;
        let mut rho = scale_round(rho_deg, 100.0, -18_000, 18_000).ok_or(oor)?;
        if rho == -18_000 {
            rho = 18_000;
        }
        let rho_cdeg = i16::try_from(rho).map_err(|_| oor)?;
        Ok(Self {
            tag,
            x_um,
            z_um,
            rho_cdeg,
            status,
        })
    }

    /// x′ in metres.
    pub fn x_m(&self) -> f64 {
        f64::from(self.x_um) * 1e-6
    }
    /// z′ in metres.
    pub fn z_m(&self) -> f64 {
        f64::from(self.z_um) * 1e-6
    }
    /// ρ in degrees.
    pub fn rho_deg(&self) -> f64 {
        f64::from(self.rho_cdeg) * 1e-2
    }

    /// Parses one output point from the first [`OUTPUT_POINT_LEN`] bytes of `bytes`
    /// (offsets in errors are within the record).
    pub fn parse(bytes: &[u8]) -> Result<Self, Error> {
        if bytes.len() < OUTPUT_POINT_LEN {
            return Err(Error::Truncated {
                needed: OUTPUT_POINT_LEN,
                available: bytes.len(),
            });
        }
        let rho_cdeg =
            i16::from_le_bytes(super::get_bytes(bytes, field::out_point::RHO_CDEG.start));
        if !(-17_999..=18_000).contains(&rho_cdeg) {
            return Err(Error::OutOfRange {
                offset: field::out_point::RHO_CDEG.start,
            });
        }
        if get_u8(bytes, field::out_point::RESERVED) != 0 {
            return Err(Error::ReservedNotZero {
                offset: field::out_point::RESERVED,
            });
        }
        Ok(Self {
            tag: get_u32(bytes, field::out_point::TAG),
            x_um: i32::from_le_bytes(super::get_bytes(bytes, field::out_point::X_UM.start)),
            z_um: i32::from_le_bytes(super::get_bytes(bytes, field::out_point::Z_UM.start)),
            rho_cdeg,
            status: get_u8(bytes, field::out_point::STATUS),
        })
    }

    /// Writes the point into the first [`OUTPUT_POINT_LEN`] bytes of `out`.
    pub fn emit(&self, out: &mut [u8], index: usize) -> Result<(), EncodeError> {
        if out.len() < OUTPUT_POINT_LEN {
            return Err(EncodeError::BufferTooSmall {
                needed: OUTPUT_POINT_LEN,
                available: out.len(),
            });
        }
        let words = self.words(index)?;
        if let Some((rec, _)) = out.split_first_chunk_mut::<OUTPUT_POINT_LEN>() {
            put_words(rec, words);
        }
        Ok(())
    }

    /// The record as four little-endian words (what [`Self::emit`] writes), or
    /// [`EncodeError::OutOfRange`] with `index` if ρ is outside −17 999..=18 000.
    fn words(&self, index: usize) -> Result<[u32; 4], EncodeError> {
        if !(-17_999..=18_000).contains(&self.rho_cdeg) {
            return Err(EncodeError::OutOfRange { index });
        }
        // x_um, z_um: the i32's two's-complement bits; ρ: its i16 bits in the low half of
        // the last word, the status above them, the reserved byte 0.
        Ok([
            self.tag,
            u32::from_le_bytes(self.x_um.to_le_bytes()),
            u32::from_le_bytes(self.z_um.to_le_bytes()),
            record_word3(self.rho_cdeg, self.status),
        ])
    }
}

/// The last word of a record: ρ (bytes 12–13), status (14), reserved 0 (15).
#[inline(always)]
fn record_word3(rho_cdeg: i16, status: u8) -> u32 {
    u32::from(u16::from_le_bytes(rho_cdeg.to_le_bytes())) | u32::from(status) << 16
}

const _: () = assert!(
    field::out_point::TAG.start == 0
        && field::out_point::X_UM.start == 4
        && field::out_point::Z_UM.start == 8
        && field::out_point::RHO_CDEG.start == 12
        && field::out_point::STATUS == 14
        && field::out_point::RESERVED == 15
        && OUTPUT_POINT_LEN == 16
);

/// Writes a record's four words into the first 16 bytes of `out` (callers check the
/// length; four word stores on the M4F).
#[inline(always)]
fn put_words(out: &mut [u8; OUTPUT_POINT_LEN], words: [u32; 4]) {
    for (dst, w) in out.chunks_exact_mut(4).zip(words) {
        dst.copy_from_slice(&w.to_le_bytes());
    }
}

/// x′ or z′ in metres → micrometres on the fast path: `Some` exactly when |v| < 1024 m
/// (bit test; false for NaN and ±inf), and then |v · 2·10⁶| < 2^31, where
/// [`scale_round_fast`]'s rounding is [`scale_round`]'s (tested) and fits an i32.
#[inline(always)]
fn fast_um(v: f32) -> Option<i32> {
    // |v| < 1024 on the bits without the sign: (bits << 1) < 0x8900_0000, an immediate.
    if v.to_bits() << 1 >= 1024f32.to_bits() << 1 {
        return None;
    }
    Some(round_twice(v * 2e6))
}

/// s2 = 2·(v · scale) (exactly, see [`scale_round_fast`]), |s2| < 2^31 → v · scale rounded
/// half away from zero. q = trunc(s2); for q ≥ 0 the result is (q + 1) / 2, for q < 0 it
/// is (q − 1) / 2 truncated, which is ⌊q / 2⌋: both are (q + 1 + (q >> 31)) >> 1
/// (arithmetic shifts), three instructions on the M4F.
#[inline(always)]
fn round_twice(s2: f32) -> i32 {
    let q = s2 as i32;
    (q + 1 + (q >> 31)) >> 1
}

/// The record words of a point taken straight from the kernel's f32 values — the same
/// words as [`OutputPointRepr::from_f32`] followed by [`OutputPointRepr::emit`] (tested
/// bit for bit) — or `None` when the point needs that general path: |x′| or |z′| ≥ 1024 m,
/// ρ outside (−179.99°, 180°], or anything non-finite. In that range ρ·200 lies in
/// (−35 998, 36 000], so ρ rounds to −17 999..=18 000 centidegrees: no range test and no
/// −180.00 → +180.00 remapping of its own (ρ near −180° takes the general path, which
/// does both).
#[inline(always)]
fn fast_words(tag: u32, x_m: f32, z_m: f32, rho_deg: f32, status: u8) -> Option<[u32; 4]> {
    let x_um = fast_um(x_m)?;
    let z_um = fast_um(z_m)?;
    // Two FPU compares against constant registers; false for NaN. (|ρ| ≤ 180° as one bit
    // test kept an integer constant in a register and needed the remapping: 4 instructions
    // per point more, measured.)
    let in_range = rho_deg > -179.99 && rho_deg <= 180.0;
    if !in_range {
        return None;
    }
    let rho = round_twice(rho_deg * 200.0);
    // |rho| ≤ 18 000: the cast keeps the value.
    let rho_cdeg = rho as i16;
    Some([
        tag,
        u32::from_le_bytes(x_um.to_le_bytes()),
        u32::from_le_bytes(z_um.to_le_bytes()),
        record_word3(rho_cdeg, status),
    ])
}

/// A line's output points as the kernel leaves them, one slice per field (structure of
/// arrays): point `i` is `(tag[i], x_m[i], z_m[i], rho_deg[i], status[i])`, values as
/// [`OutputPointRepr::from_f32`] takes them. `S` is the caller's status type; the encoder
/// asks the caller for its wire byte.
#[derive(Clone, Copy, Debug)]
pub struct OutputColumns<'a, S> {
    /// Pass-through tags.
    pub tag: &'a [u32],
    /// x′ in metres.
    pub x_m: &'a [f32],
    /// z′ in metres.
    pub z_m: &'a [f32],
    /// ρ in degrees.
    pub rho_deg: &'a [f32],
    /// Statuses.
    pub status: &'a [S],
}

/// Total length of an output packet with `count` points.
pub const fn output_packet_len(count: usize) -> usize {
    HEADER_LEN + OUTPUT_HEADER_LEN + count * OUTPUT_POINT_LEN + CRC_LEN
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
        };
        if get_u16(b, out::RESERVED) != 0 {
            return Err(Error::ReservedNotZero {
                offset: out::RESERVED.start,
            });
        }
        if !h.indices_ok() {
            return Err(Error::OutOfRange {
                offset: out::NADIR.start,
            });
        }
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
fn begin_fragment(
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
    emit_header(out, PacketKind::Output, len16, seq);
    use field::out as f;
    let idx = |v: Option<u16>| v.unwrap_or(NO_INDEX).to_le_bytes();
    put_bytes(out, f::INDEX.start, &header.index.to_le_bytes());
    put_bytes(
        out,
        f::START_TIME.start,
        &header.start_time_ns.to_le_bytes(),
    );
    put_bytes(out, f::PARAMS_HASH.start, &header.params_hash.to_le_bytes());
    put_bytes(out, f::TRUNCATED.start, &header.truncated.to_le_bytes());
    put_bytes(out, f::LINE_LEN.start, &header.line_len.to_le_bytes());
    put_bytes(out, f::FIRST.start, &first.to_le_bytes());
    put_bytes(out, f::NADIR.start, &idx(header.nadir));
    put_bytes(out, f::LEFT.start, &idx(header.left));
    put_bytes(out, f::RIGHT.start, &idx(header.right));
    put_bytes(out, f::KEPT.start, &header.kept.to_le_bytes());
    put_bytes(out, f::IRREGULAR.start, &header.irregular.to_le_bytes());
    put_bytes(
        out,
        f::NO_NEIGHBOUR.start,
        &header.no_neighbour.to_le_bytes(),
    );
    put_bytes(out, f::PEAKS.start, &header.peaks.to_le_bytes());
    put_bytes(out, f::RESERVED.start, &0u16.to_le_bytes());
    Ok((count, len))
}

/// Writes one output packet: the fragment of `header`'s line that starts at `first` (a
/// multiple of [`MAX_OUTPUT_POINTS_PER_PACKET`]), taking point `i` of the line from
/// `point(i)`. Returns the packet length. The body of
/// [`super::StreamEncoder::encode_output_fragment`].
pub(super) fn emit_output_fragment(
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

/// [`emit_output_fragment`] for a line given as columns: a tight loop ([`fast_run`])
/// builds each record in registers from the columns ([`fast_words`]) and stores it as four
/// words, then [`seal`] computes the CRC over the finished packet. A point the fast path
/// does not take — `wire_status(status)` is `None`, or a value is large, non-finite or out
/// of range — comes from `point(i)` as in [`emit_output_fragment`], with the same errors
/// and indices; so does every point if a column is shorter than the fragment. The bytes
/// are [`emit_output_fragment`]'s with `point` (tested bit for bit). The body of
/// [`super::StreamEncoder::encode_output_columns`].
///
/// Why the CRC is not fed from the registers as each record is built: on the M4F that
/// loop needs the four CRC table bases, the five column pointers, the record pointer and
/// the CRC at once, more than the 13 registers, and its spills cost more than the four
/// loads per record the separate CRC pass makes (measured: 127.4 against 124.9
/// instructions per point for output and its CRC, `docs/benchmarks.md`).
pub(super) fn emit_output_fragment_columns<S: Copy>(
    seq: u32,
    header: &OutputHeaderRepr,
    first: u16,
    cols: &OutputColumns<'_, S>,
    wire_status: impl Fn(S) -> Option<u8>,
    mut point: impl FnMut(usize) -> Result<OutputPointRepr, EncodeError>,
    out: &mut [u8],
) -> Result<usize, EncodeError> {
    let (count, len) = begin_fragment(seq, header, first, out)?;
    let first_us = usize::from(first);
    let (recs, _) = out
        .get_mut(field::out::POINTS..field::out::POINTS + count * OUTPUT_POINT_LEN)
        .unwrap_or(&mut [])
        .as_chunks_mut::<OUTPUT_POINT_LEN>();
    let end = first_us + count;
    let cols = Columns {
        tag: cols.tag.get(first_us..end).unwrap_or(&[]),
        x_m: cols.x_m.get(first_us..end).unwrap_or(&[]),
        z_m: cols.z_m.get(first_us..end).unwrap_or(&[]),
        rho_deg: cols.rho_deg.get(first_us..end).unwrap_or(&[]),
        status: cols.status.get(first_us..end).unwrap_or(&[]),
    };
    fill_records(first_us, &cols, &wire_status, &mut point, recs)?;
    seal(out, len);
    Ok(len)
}

/// The fragment's slices of the columns (empty where a column is too short).
struct Columns<'a, S> {
    tag: &'a [u32],
    x_m: &'a [f32],
    z_m: &'a [f32],
    rho_deg: &'a [f32],
    status: &'a [S],
}

/// Record `k` of the fragment from point `first + k`: [`fast_run`] for runs of ordinary
/// points, [`general`] for the others (or for all of them if a column is shorter than
/// `recs`).
fn fill_records<S: Copy>(
    first: usize,
    c: &Columns<'_, S>,
    wire_status: &impl Fn(S) -> Option<u8>,
    point: &mut impl FnMut(usize) -> Result<OutputPointRepr, EncodeError>,
    recs: &mut [[u8; OUTPUT_POINT_LEN]],
) -> Result<(), EncodeError> {
    let n = recs.len();
    let long_enough = c.tag.len() >= n
        && c.x_m.len() >= n
        && c.z_m.len() >= n
        && c.rho_deg.len() >= n
        && c.status.len() >= n;
    let mut k = 0;
    loop {
        // The fast loop runs up to the first point it cannot take; that point takes the
        // general path here, outside the loop (a call inside it would leave the loop only
        // the callee-saved registers).
        if long_enough {
            k = fast_run(c, wire_status, recs, k);
        }
        let Some(rec) = recs.get_mut(k) else {
            return Ok(());
        };
        put_words(rec, general(first + k, point)?);
        k += 1;
    }
}

/// Records `start..` from the columns (all at least as long as `recs`) on the fast path,
/// up to the first point the fast path does not take; returns its index (`recs.len()` if
/// none). Out of line, so that the loop has the registers to itself (inlined into the
/// firmware's line handler it spilled the column pointers and the constants).
#[inline(never)]
fn fast_run<S: Copy>(
    c: &Columns<'_, S>,
    wire_status: &impl Fn(S) -> Option<u8>,
    recs: &mut [[u8; OUTPUT_POINT_LEN]],
    start: usize,
) -> usize {
    let n = recs.len();
    let (Some(tag), Some(x), Some(z), Some(rho), Some(st)) = (
        c.tag.get(..n),
        c.x_m.get(..n),
        c.z_m.get(..n),
        c.rho_deg.get(..n),
        c.status.get(..n),
    ) else {
        return start;
    };
    for k in start..n {
        let (Some(rec), Some(&t), Some(&xv), Some(&zv), Some(&rv), Some(&sv)) = (
            recs.get_mut(k),
            tag.get(k),
            x.get(k),
            z.get(k),
            rho.get(k),
            st.get(k),
        ) else {
            return k;
        };
        let Some(words) = wire_status(sv).and_then(|b| fast_words(t, xv, zv, rv, b)) else {
            return k;
        };
        put_words(rec, words);
    }
    n
}

/// Point `i` from `point(i)` as record words (the general path of
/// [`emit_output_fragment_columns`]); kept out of line, off the fast loop.
#[inline(never)]
fn general(
    i: usize,
    point: &mut impl FnMut(usize) -> Result<OutputPointRepr, EncodeError>,
) -> Result<[u32; 4], EncodeError> {
    point(i)?.words(i)
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::super::{crc, StreamEncoder, MAX_PACKET_LEN};
    use super::*;
    use proptest::prelude::*;
    use std::{vec, vec::Vec};

    fn arb_point() -> impl Strategy<Value = OutputPointRepr> {
        (
            any::<u32>(),
            any::<i32>(),
            any::<i32>(),
            -17_999i16..=18_000,
            any::<u8>(),
        )
            .prop_map(|(tag, x_um, z_um, rho_cdeg, status)| OutputPointRepr {
                tag,
                x_um,
                z_um,
                rho_cdeg,
                status,
            })
    }

    fn header(line_len: u16) -> OutputHeaderRepr {
        OutputHeaderRepr {
            index: 12,
            start_time_ns: 1_000_000_000,
            params_hash: 0xDEAD_BEEF,
            truncated: 0,
            line_len,
            first: 0,
            nadir: line_len.checked_sub(1),
            left: None,
            right: Some(0).filter(|_| line_len > 0),
            kept: line_len,
            irregular: 0,
            no_neighbour: 0,
            peaks: 1,
        }
    }

    #[test]
    fn scaling_rounds_half_away_and_wraps_minus_180() {
        let p = OutputPointRepr::from_f32(1, 1.2345675, -0.0000005, -180.0, 2, 0).unwrap();
        assert_eq!(p.x_um, 1_234_568); // f32(1.2345675) * 1e6 = 1234567.5 → away from zero
        assert_eq!(p.z_um, -1); // −0.5 µm → −1
        assert_eq!(p.rho_cdeg, 18_000);
        let p = OutputPointRepr::from_f32(1, -3.0, 0.0, 90.004, 0, 0).unwrap();
        assert_eq!((p.x_um, p.rho_cdeg), (-3_000_000, 9_000));
        assert_eq!(
            OutputPointRepr::from_f32(1, f32::NAN, 0.0, 0.0, 0, 4),
            Err(EncodeError::NonFinite { index: 4 })
        );
        assert_eq!(
            OutputPointRepr::from_f32(1, 3000.0, 0.0, 0.0, 0, 5),
            Err(EncodeError::OutOfRange { index: 5 })
        );
        assert_eq!(
            OutputPointRepr::from_f32(1, 0.0, 0.0, 180.01, 0, 6),
            Err(EncodeError::OutOfRange { index: 6 })
        );
    }

    #[test]
    fn golden_output_packet() {
        let h = header(1);
        let p = OutputPointRepr {
            tag: 7,
            x_um: 1_500_000,
            z_um: -2_000_000,
            rho_cdeg: 9_000,
            status: 0,
        };
        let mut enc = StreamEncoder::with_seq(2);
        let mut out = [0u8; MAX_PACKET_LEN];
        let n = enc.encode_output(&h, &[p], &mut out).unwrap();
        #[rustfmt::skip]
        let golden: [u8; 72] = [
            0xA5, 0xC3, 0x01, 0x03, 0x48, 0x00, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00,
            0x0C, 0x00, 0x00, 0x00, // index 12
            0x00, 0xCA, 0x9A, 0x3B, 0x00, 0x00, 0x00, 0x00, // start time 1e9 ns
            0xEF, 0xBE, 0xAD, 0xDE, // params hash
            0x00, 0x00, 0x00, 0x00, // truncated
            0x01, 0x00, 0x00, 0x00, // line_len 1, first 0
            0x00, 0x00, 0xFF, 0xFF, 0x00, 0x00, // nadir 0, left none, right 0
            0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x01, 0x00, // kept 1, irregular, no_neighbour, peaks 1
            0x00, 0x00, // reserved
            0x07, 0x00, 0x00, 0x00, 0x60, 0xE3, 0x16, 0x00, 0x80, 0x7B, 0xE1, 0xFF,
            0x28, 0x23, 0x00, 0x00, // point
            0, 0, 0, 0, // CRC, filled below
        ];
        let mut golden = golden;
        let crc = crc::crc32_bytewise(&golden[..68]);
        golden[68..].copy_from_slice(&crc.to_le_bytes());
        assert_eq!(&out[..n], &golden[..]);
        let pk = Packet::new_checked(&golden[..]).unwrap();
        let (hh, pts) = OutputHeaderRepr::parse(&pk).unwrap();
        assert_eq!(hh, h);
        let pts: heapless::Vec<_, 4> = pts.collect();
        assert_eq!(&pts[..], &[p]);
        assert_eq!(pts[0].rho_deg(), 90.0);
    }

    #[test]
    fn fragmentation_of_a_long_line() {
        // 2000 points → ⌈2000/88⌉ = 23 packets, the last with 2000 − 22·88 = 64 points.
        let h = header(2000);
        let mut enc = StreamEncoder::new();
        let mut buf = [0u8; 40_000];
        let n = enc
            .encode_output_line(
                &h,
                |i| {
                    OutputPointRepr::from_f32(
                        u32::try_from(i).unwrap(),
                        i as f32 * 0.01,
                        -2.0,
                        0.0,
                        0,
                        i,
                    )
                },
                &mut buf,
            )
            .unwrap();
        assert_eq!(MAX_OUTPUT_POINTS_PER_PACKET, 88);
        assert_eq!(h.fragments(), 23);
        assert_eq!(n, 22 * output_packet_len(88) + output_packet_len(64));
        let mut at = 0;
        let mut next_tag = 0u32;
        let mut packets = 0;
        while at < n {
            let pk = Packet::new_checked(&buf[at..n]).unwrap();
            assert_eq!(pk.seq(), packets);
            assert!(pk.length() <= MAX_PACKET_LEN);
            let (hh, pts) = OutputHeaderRepr::parse(&pk).unwrap();
            assert_eq!(usize::from(hh.first), usize::try_from(next_tag).unwrap());
            for p in pts {
                assert_eq!(p.tag, next_tag);
                assert_eq!(p.x_um, (next_tag as f32 * 0.01 * 1e6).round() as i32);
                next_tag += 1;
            }
            at += pk.length();
            packets += 1;
        }
        assert_eq!((next_tag, packets), (2000, 23));
        // An empty line is one packet with no points.
        let n = enc
            .encode_output_line(&header(0), |_| unreachable!(), &mut buf)
            .unwrap();
        assert_eq!(n, output_packet_len(0));
        let pk = Packet::new_checked(&buf[..n]).unwrap();
        let (hh, mut pts) = OutputHeaderRepr::parse(&pk).unwrap();
        assert_eq!((hh.line_len, pts.next()), (0, None));
    }

    #[test]
    fn encoder_rejects_bad_headers() {
        let mut enc = StreamEncoder::new();
        let mut buf = [0u8; MAX_PACKET_LEN];
        let mut h = header(3);
        h.left = Some(3);
        assert!(enc
            .encode_output(&h, &[OutputPointRepr::default(); 3], &mut buf)
            .is_err());
        let h = header(3);
        // Wrong number of points for the fragment.
        assert!(enc
            .encode_output(&h, &[OutputPointRepr::default(); 2], &mut buf)
            .is_err());
        assert_eq!(
            enc.seq(),
            0,
            "failed encodes do not consume sequence numbers"
        );
    }

    #[test]
    fn fast_rounding_is_the_general_one() {
        // Halves, neighbours of halves, the 2^30 edge, huge, non-finite, signed zeros.
        let mut vals = std::vec![
            0.0f32,
            -0.0,
            0.5e-6,
            -0.5e-6,
            1.5e-6,
            -2.5e-6,
            1e-45,
            -1e-45,
            0.004_999_999,
            0.005,
            -0.005,
            179.995,
            -179.995,
            180.0,
            -180.0,
            180.004,
            3000.0,
            f32::MAX,
            f32::MIN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
        ];
        // Around 2^30 µm (the fast path's edge) and 2^31 µm (the i32 edge), ± a few ulps.
        for edge in [1_073_741_824.0f32 * 1e-6, 2_147_483_648.0 * 1e-6] {
            for k in 0..8u32 {
                let up = f32::from_bits(edge.to_bits() + k);
                let down = f32::from_bits(edge.to_bits() - k);
                vals.extend([up, down, -up, -down]);
            }
        }
        let mut r = 99u64;
        for _ in 0..200_000 {
            r = r
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let v = f32::from_bits((r >> 32) as u32);
            vals.push(v);
            vals.push(f32::from_bits(((r >> 40) as u32 & 0x00FF_FFFF) | 0x4000_0000) - 3.0);
            // k + 0.5 µm exactly and one ulp either side.
            let h = ((r >> 44) as i32 - (1 << 19)) as f32 + 0.5;
            for w in [
                h,
                f32::from_bits(h.to_bits() + 1),
                f32::from_bits(h.to_bits() - 1),
            ] {
                vals.push(w * 1e-6);
                vals.push(w * 1e-2);
            }
        }
        for v in vals {
            for (scale, lo, hi) in [(1e6f32, i32::MIN, i32::MAX), (100.0, -18_000, 18_000)] {
                let general = scale_round(v, scale, lo, hi);
                if let Some(f) = scale_round_fast(v, 2.0 * scale) {
                    let f = (lo..=hi).contains(&f).then_some(f);
                    assert_eq!(f, general, "{v:e} × {scale}");
                } else {
                    assert!(!(v * scale).is_finite() || (v * scale).abs() >= 1073741824.0);
                }
            }
        }
    }

    /// A value for the columns test: ordinary, on a rounding half, at the fast path's edges
    /// (1024 m, ±180°), beyond them, huge, non-finite or any bit pattern.
    fn arb_value() -> impl Strategy<Value = f32> {
        prop_oneof![
            4 => -3.0f32..3.0,
            2 => -200.0f32..200.0,
            1 => (-2_000_000i32..2_000_000).prop_map(|k| (k as f32 + 0.5) * 1e-6),
            1 => (-36_000i32..36_000).prop_map(|k| (k as f32 + 0.5) * 0.005),
            1 => prop_oneof![
                Just(180.0f32), Just(-180.0), Just(179.995), Just(-179.995), Just(-179.997),
                Just(180.004), Just(-180.004), Just(1024.0), Just(-1024.0),
                Just(f32::from_bits(1024f32.to_bits() - 1)), Just(2147.48), Just(3000.0),
                Just(f32::MAX), Just(f32::NAN), Just(f32::INFINITY), Just(f32::NEG_INFINITY),
                Just(0.0), Just(-0.0),
            ],
            1 => any::<u32>().prop_map(f32::from_bits),
        ]
    }

    /// The general path the columns encoder must equal: `from_f32` on each point, status 3
    /// (the pipeline's NonFinite) sent at x′ = z′ = 0.
    fn general_point(
        tag: &[u32],
        x: &[f32],
        z: &[f32],
        rho: &[f32],
        st: &[u8],
        i: usize,
    ) -> Result<OutputPointRepr, EncodeError> {
        let g = |s: &[f32]| s.get(i).copied().unwrap_or(0.0);
        let s = *st.get(i).ok_or(EncodeError::OutOfRange { index: i })?;
        let (xv, zv) = if s == 3 { (0.0, 0.0) } else { (g(x), g(z)) };
        OutputPointRepr::from_f32(tag.get(i).copied().unwrap_or(0), xv, zv, g(rho), s, i)
    }

    #[test]
    fn columns_fast_path_edges() {
        // Points on the fast path's edges, one per line, against the general path.
        let edges = [
            (0.0f32, 0.0f32, -180.0f32),
            (0.0, 0.0, 180.0),
            (0.0, 0.0, -179.997), // rounds to −18 000 → +18 000
            (0.0, 0.0, -179.99),  // the fast path's lower edge and its neighbours
            (0.0, 0.0, f32::from_bits((-179.99f32).to_bits() - 1)),
            (0.0, 0.0, f32::from_bits((-179.99f32).to_bits() + 1)),
            (0.0, 0.0, -179.995), // −17 999.5 centidegrees → −18 000 → +18 000
            (0.0, 0.0, f32::from_bits(180f32.to_bits() - 1)),
            (0.0, 0.0, f32::from_bits(180f32.to_bits() + 1)),
            (f32::from_bits(1024f32.to_bits() - 1), -1023.9999, 0.0),
            (1024.0, 0.0, 0.0),
            (-1024.0, 0.0, 0.0),
            (2147.4836, 0.0, 0.0),
            (1.2345675, -0.0000005, 0.004_999_999),
            (f32::NAN, 0.0, 0.0),
            (0.0, f32::INFINITY, 0.0),
            (0.0, 0.0, f32::NEG_INFINITY),
        ];
        for (k, &(x, z, r)) in edges.iter().enumerate() {
            for st in 0u8..=4 {
                let cols = OutputColumns {
                    tag: &[k as u32][..],
                    x_m: &[x][..],
                    z_m: &[z][..],
                    rho_deg: &[r][..],
                    status: &[st][..],
                };
                let h = header(1);
                let mut a = [0u8; MAX_PACKET_LEN];
                let mut b = [0u8; MAX_PACKET_LEN];
                let ra = StreamEncoder::new().encode_output_fragment(
                    &h,
                    0,
                    |i| general_point(cols.tag, cols.x_m, cols.z_m, cols.rho_deg, cols.status, i),
                    &mut a,
                );
                let rb = StreamEncoder::new().encode_output_columns(
                    &h,
                    0,
                    &cols,
                    |s: u8| (s != 3).then_some(s),
                    |i| general_point(cols.tag, cols.x_m, cols.z_m, cols.rho_deg, cols.status, i),
                    &mut b,
                );
                assert_eq!(ra, rb, "{x:e} {z:e} {r:e} status {st}");
                if let Ok(n) = ra {
                    assert_eq!(a[..n], b[..n], "{x:e} {z:e} {r:e} status {st}");
                }
            }
        }
    }

    proptest! {
        /// The columns encoder (fast path, fused CRC) writes the bytes of the general
        /// encoder, or fails with the same error, for every fragment of a random line with
        /// NaN, ±inf, huge values, ρ = ±180°, every status and short columns.
        #[test]
        fn columns_equal_general(
            pts in proptest::collection::vec(
                (any::<u32>(), arb_value(), arb_value(), arb_value(), 0u8..=4), 0..200),
            short in proptest::option::of((0usize..5, 0usize..200)),
            seq in any::<u32>(),
        ) {
            let tag: Vec<u32> = pts.iter().map(|p| p.0).collect();
            let mut x: Vec<f32> = pts.iter().map(|p| p.1).collect();
            let mut z: Vec<f32> = pts.iter().map(|p| p.2).collect();
            let rho: Vec<f32> = pts.iter().map(|p| p.3).collect();
            let st: Vec<u8> = pts.iter().map(|p| p.4).collect();
            // Sometimes one column is cut short: every point then takes the general path,
            // which reads the missing values as 0.
            if let Some((col, at)) = short {
                match col {
                    0 => x.truncate(at),
                    1 => z.truncate(at),
                    _ => {}
                }
            }
            let cols = OutputColumns { tag: &tag[..], x_m: &x[..], z_m: &z[..], rho_deg: &rho[..], status: &st[..] };
            let h = header(u16::try_from(pts.len()).unwrap());
            for k in 0..h.fragments() {
                let first = u16::try_from(k * MAX_OUTPUT_POINTS_PER_PACKET).unwrap();
                let mut a = vec![0u8; MAX_PACKET_LEN];
                let mut b = vec![0u8; MAX_PACKET_LEN];
                let mut ea = StreamEncoder::with_seq(seq);
                let mut eb = StreamEncoder::with_seq(seq);
                let gp = |i| general_point(&tag, &x, &z, &rho, &st, i);
                let ra = ea.encode_output_fragment(&h, first, gp, &mut a);
                let rb = eb.encode_output_columns(&h, first, &cols, |s: u8| (s != 3).then_some(s), gp, &mut b);
                prop_assert_eq!(ra, rb);
                prop_assert_eq!(ea.seq(), eb.seq());
                if let Ok(n) = ra {
                    prop_assert_eq!(&a[..n], &b[..n]);
                }
            }
        }

        /// parse ∘ emit is the identity on reprs (every fragment of a random line).
        #[test]
        fn output_roundtrip(pts in proptest::collection::vec(arb_point(), 0..300),
                            index in any::<u32>(), t in any::<u64>(), hash in any::<u32>(),
                            trunc in any::<u32>(), nadir in any::<u16>(), left in any::<u16>(),
                            counts in proptest::array::uniform4(any::<u16>())) {
            let line_len = u16::try_from(pts.len()).unwrap();
            let pick = |v: u16| if line_len == 0 || v.is_multiple_of(3) { None } else { Some(v % line_len) };
            let h = OutputHeaderRepr {
                index, start_time_ns: t, params_hash: hash, truncated: trunc, line_len, first: 0,
                nadir: pick(nadir), left: pick(left), right: pick(nadir.wrapping_add(left)),
                kept: counts[0], irregular: counts[1], no_neighbour: counts[2], peaks: counts[3],
            };
            let mut enc = StreamEncoder::new();
            let mut buf = vec![0u8; 8000];
            let n = enc.encode_output_line(&h, |i| Ok(pts[i]), &mut buf).unwrap();
            let mut at = 0;
            let mut got = Vec::new();
            while at < n {
                let pk = Packet::new_checked(&buf[at..n]).unwrap();
                let (hh, ps) = OutputHeaderRepr::parse(&pk).unwrap();
                prop_assert_eq!(hh, OutputHeaderRepr { first: hh.first, ..h });
                prop_assert_eq!(usize::from(hh.first), got.len());
                got.extend(ps);
                at += pk.length();
            }
            prop_assert_eq!(got, pts);
        }

        /// emit ∘ parse is the identity on canonical bytes.
        #[test]
        fn output_canonical(pts in proptest::collection::vec(arb_point(), 1..5), at in 0usize..200, val in any::<u8>()) {
            let h = header(u16::try_from(pts.len()).unwrap());
            let mut enc = StreamEncoder::new();
            let mut b = [0u8; MAX_PACKET_LEN];
            let n = enc.encode_output(&h, &pts, &mut b).unwrap();
            let at = at % (n - 4);
            b[at] = val;
            let crc = crc::crc32(&b[..n - 4]);
            b[n - 4..n].copy_from_slice(&crc.to_le_bytes());
            let pk = Packet::new_unchecked(&b[..n]);
            if let Ok((hh, ps)) = OutputHeaderRepr::parse(&pk) {
                let ps: Vec<_> = ps.collect();
                let mut again = [0u8; MAX_PACKET_LEN];
                let mut e2 = StreamEncoder::with_seq(pk.seq());
                let m = e2.encode_output(&hh, &ps, &mut again).unwrap();
                prop_assert_eq!(&again[..m], &b[..n]);
            }
        }
    }
}
