//! Points packets: a 64-bit base time and up to [`MAX_POINTS_PER_PACKET`] point records.

use super::{
    emit_header, field, get_bytes, put_bytes, seal, EncodeError, Error, Packet, PacketKind,
    CRC_LEN, HEADER_LEN, MAX_POINTS_PER_PACKET, POINTS_PREFIX_LEN, VERSION_1,
};

/// Length of one point record in bytes.
pub const POINT_RECORD_LEN: usize = 20;
/// Bit 0 of a record's flags: this point is the first of a scanline. All other bits are
/// reserved and must be zero.
pub const POINT_FLAG_LINE_START: u16 = 1;

/// One point as a scanner front end or host-sim's replay sends it.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PointRecord {
    /// Time offset from the packet's base time, nanoseconds.
    pub dt_ns: u32,
    /// x′ in metres: signed lateral offset from the scanner, left positive (docs/spec.md §2).
    pub x_m: f32,
    /// z′ in metres: height relative to the scanner origin (docs/spec.md §2).
    pub z_m: f32,
    /// Return intensity as the source reports it.
    pub intensity: u16,
    /// This point is the first of a scanline.
    pub line_start: bool,
    /// Pass-through tag joining results back to source points (host-sim: the column index).
    pub tag: u32,
}

impl PointRecord {
    /// Parses one record from the first [`POINT_RECORD_LEN`] bytes of `bytes`. Rejects
    /// NaN/infinite coordinates and reserved flag bits; offsets in errors are within the
    /// record.
    pub fn parse(bytes: &[u8]) -> Result<Self, Error> {
        match bytes.first_chunk::<POINT_RECORD_LEN>() {
            Some(rec) => Self::parse_array(rec),
            None => Err(Error::Truncated {
                needed: POINT_RECORD_LEN,
                available: bytes.len(),
            }),
        }
    }

    /// [`Self::parse`] on exactly one record: with the length in the type, every field is
    /// one load at a constant offset (no bounds checks, no byte copies — the ingest loop
    /// parses every input point with it).
    #[inline]
    pub fn parse_array(rec: &[u8; POINT_RECORD_LEN]) -> Result<Self, Error> {
        // Field offsets (`field::point`) as constants: 0 dt, 4 x, 8 z, 12 intensity,
        // 14 flags, 16 tag.
        const _: () = assert!(
            field::point::DT_NS.start == 0
                && field::point::X.start == 4
                && field::point::Z.start == 8
                && field::point::INTENSITY.start == 12
                && field::point::FLAGS.start == 14
                && field::point::TAG.start == 16
        );
        let w = |at: usize| u32::from_le_bytes(get_bytes(rec, at));
        let h = |at: usize| u16::from_le_bytes(get_bytes(rec, at));
        let x_m = f32::from_bits(w(field::point::X.start));
        let z_m = f32::from_bits(w(field::point::Z.start));
        if !x_m.is_finite() {
            return Err(Error::NonFinite {
                offset: field::point::X.start,
            });
        }
        if !z_m.is_finite() {
            return Err(Error::NonFinite {
                offset: field::point::Z.start,
            });
        }
        let flags = h(field::point::FLAGS.start);
        if flags & !POINT_FLAG_LINE_START != 0 {
            return Err(Error::ReservedNotZero {
                offset: field::point::FLAGS.start,
            });
        }
        Ok(Self {
            dt_ns: w(field::point::DT_NS.start),
            x_m,
            z_m,
            intensity: h(field::point::INTENSITY.start),
            line_start: flags & POINT_FLAG_LINE_START != 0,
            tag: w(field::point::TAG.start),
        })
    }

    /// Writes the record into the first [`POINT_RECORD_LEN`] bytes of `out`. `index` is
    /// reported in errors.
    pub fn emit(&self, out: &mut [u8], index: usize) -> Result<(), EncodeError> {
        if out.len() < POINT_RECORD_LEN {
            return Err(EncodeError::BufferTooSmall {
                needed: POINT_RECORD_LEN,
                available: out.len(),
            });
        }
        if !self.x_m.is_finite() || !self.z_m.is_finite() {
            return Err(EncodeError::NonFinite { index });
        }
        let flags = if self.line_start {
            POINT_FLAG_LINE_START
        } else {
            0
        };
        put_bytes(out, field::point::DT_NS.start, &self.dt_ns.to_le_bytes());
        put_bytes(
            out,
            field::point::X.start,
            &self.x_m.to_bits().to_le_bytes(),
        );
        put_bytes(
            out,
            field::point::Z.start,
            &self.z_m.to_bits().to_le_bytes(),
        );
        put_bytes(
            out,
            field::point::INTENSITY.start,
            &self.intensity.to_le_bytes(),
        );
        put_bytes(out, field::point::FLAGS.start, &flags.to_le_bytes());
        put_bytes(out, field::point::TAG.start, &self.tag.to_le_bytes());
        Ok(())
    }
}

/// Total length of a points packet with `count` records.
pub const fn points_packet_len(count: usize) -> usize {
    HEADER_LEN + POINTS_PREFIX_LEN + count * POINT_RECORD_LEN + CRC_LEN
}

/// Writes a points packet; the body of [`super::StreamEncoder::encode_points`].
pub(super) fn emit_points(
    seq: u32,
    base_time_ns: u64,
    points: &[PointRecord],
    out: &mut [u8],
) -> Result<usize, EncodeError> {
    if points.len() > MAX_POINTS_PER_PACKET {
        return Err(EncodeError::TooManyPoints {
            count: points.len(),
            max: MAX_POINTS_PER_PACKET,
        });
    }
    let len = points_packet_len(points.len());
    if out.len() < len {
        return Err(EncodeError::BufferTooSmall {
            needed: len,
            available: out.len(),
        });
    }
    // Validate everything before writing anything.
    if let Some(index) = points
        .iter()
        .position(|p| !p.x_m.is_finite() || !p.z_m.is_finite())
    {
        return Err(EncodeError::NonFinite { index });
    }
    let len16 = u16::try_from(len).map_err(|_| EncodeError::TooManyPoints {
        count: points.len(),
        max: MAX_POINTS_PER_PACKET,
    })?;
    emit_header(out, VERSION_1, PacketKind::Points, len16, seq);
    put_bytes(out, field::BASE_TIME.start, &base_time_ns.to_le_bytes());
    for (i, (p, rec)) in points
        .iter()
        .zip(
            out.get_mut(field::RECORDS..len - CRC_LEN)
                .unwrap_or(&mut [])
                .chunks_exact_mut(POINT_RECORD_LEN),
        )
        .enumerate()
    {
        p.emit(rec, i)?;
    }
    seal(out, len);
    Ok(len)
}

/// A whole points packet, owned (for tests and host tools; the ingest path reads records
/// in place through [`Packet::point_bytes`]).
#[derive(Clone, Debug, PartialEq)]
pub struct PointsRepr {
    /// Absolute time of the packet, GPS nanoseconds; each record adds its `dt_ns`.
    pub base_time_ns: u64,
    /// The records.
    pub points: heapless::Vec<PointRecord, MAX_POINTS_PER_PACKET>,
}

impl PointsRepr {
    /// Parses a points packet (full check: CRC, version, kind, length, every record).
    pub fn parse<T: AsRef<[u8]>>(packet: &Packet<T>) -> Result<Self, Error> {
        let kind = packet.check()?;
        if kind != PacketKind::Points {
            return Err(Error::WrongKind { kind: kind as u8 });
        }
        let mut points = heapless::Vec::new();
        for i in 0..packet.point_count() {
            let at = field::RECORDS + i * POINT_RECORD_LEN;
            let rec = packet.point_bytes(i).ok_or(Error::Truncated {
                needed: at + POINT_RECORD_LEN,
                available: packet.length(),
            })?;
            let p = PointRecord::parse(rec).map_err(|e| match e {
                Error::NonFinite { offset } => Error::NonFinite {
                    offset: at + offset,
                },
                Error::ReservedNotZero { offset } => Error::ReservedNotZero {
                    offset: at + offset,
                },
                other => other,
            })?;
            // check() bounds the count by MAX_POINTS_PER_PACKET, so this cannot fail.
            points.push(p).map_err(|_| Error::BadLength {
                length: packet.length(),
            })?;
        }
        Ok(Self {
            base_time_ns: packet.base_time_ns(),
            points,
        })
    }

    /// Writes the packet with sequence number `seq`; returns its length.
    pub fn emit(&self, seq: u32, out: &mut [u8]) -> Result<usize, EncodeError> {
        emit_points(seq, self.base_time_ns, &self.points, out)
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::super::{crc, StreamEncoder, MAX_PACKET_LEN};
    use super::*;
    use proptest::prelude::*;

    pub(crate) fn arb_point() -> impl Strategy<Value = PointRecord> {
        (
            any::<u32>(),
            any::<f32>().prop_filter("finite", |v| v.is_finite()),
            any::<f32>().prop_filter("finite", |v| v.is_finite()),
            any::<u16>(),
            any::<bool>(),
            any::<u32>(),
        )
            .prop_map(
                |(dt_ns, x_m, z_m, intensity, line_start, tag)| PointRecord {
                    dt_ns,
                    x_m,
                    z_m,
                    intensity,
                    line_start,
                    tag,
                },
            )
    }

    /// The worked example of `docs/wire-format.md`: two points, sequence number 1.
    pub(crate) const DOC_EXAMPLE: [u8; 64] = [
        0xA5, 0xC3, 0x01, 0x01, 0x40, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, // header
        0x00, 0xCA, 0x9A, 0x3B, 0x00, 0x00, 0x00, 0x00, // base time 1 000 000 000 ns
        0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xC0, 0x3F, 0x00, 0x00, 0x00, 0xC0, 0x2C, 0x01, 0x01,
        0x00, 0x07, 0x00, 0x00, 0x00, // point 0
        0xE8, 0x03, 0x00, 0x00, 0x00, 0x00, 0x00, 0xBF, 0x00, 0x00, 0x00, 0xC0, 0x00, 0x00, 0x00,
        0x00, 0x08, 0x00, 0x00, 0x00, // point 1
        0x32, 0x98, 0xF6, 0xB6, // CRC-32
    ];

    /// Reads the hexdump between the `hexdump:points` markers of `docs/wire-format.md`.
    fn doc_hexdump() -> heapless::Vec<u8, 256> {
        let doc = include_str!("../../../docs/wire-format.md");
        let start = doc.find("<!-- hexdump:points -->").unwrap();
        let end = doc[start..].find("<!-- /hexdump -->").unwrap() + start;
        let mut out = heapless::Vec::new();
        for line in doc[start..end].lines() {
            // "0000  a5 c3 …": an offset, then hex bytes.
            let mut words = line.split_whitespace();
            let Some(off) = words.next() else { continue };
            if off.len() != 4 || usize::from_str_radix(off, 16).is_err() {
                continue;
            }
            assert_eq!(usize::from_str_radix(off, 16).unwrap(), out.len());
            for w in words {
                out.push(u8::from_str_radix(w, 16).unwrap()).unwrap();
            }
        }
        out
    }

    #[test]
    fn doc_hexdump_decodes() {
        assert_eq!(&doc_hexdump()[..], &DOC_EXAMPLE[..]);
        let p = Packet::new_checked(&DOC_EXAMPLE[..]).unwrap();
        assert_eq!(p.check(), Ok(PacketKind::Points));
        assert_eq!(p.seq(), 1);
        let r = PointsRepr::parse(&p).unwrap();
        assert_eq!(r.base_time_ns, 1_000_000_000);
        assert_eq!(
            &r.points[..],
            &[
                PointRecord {
                    dt_ns: 0,
                    x_m: 1.5,
                    z_m: -2.0,
                    intensity: 300,
                    line_start: true,
                    tag: 7
                },
                PointRecord {
                    dt_ns: 1000,
                    x_m: -0.5,
                    z_m: -2.0,
                    intensity: 0,
                    line_start: false,
                    tag: 8
                },
            ]
        );
        // And the encoder produces exactly these bytes.
        let mut enc = StreamEncoder::with_seq(1);
        let mut out = [0u8; MAX_PACKET_LEN];
        let n = enc
            .encode_points(r.base_time_ns, &r.points, &mut out)
            .unwrap();
        assert_eq!(&out[..n], &DOC_EXAMPLE[..]);
        // The CRC is the one Python's zlib.crc32 gives over bytes 0..60.
        assert_eq!(crc::crc32(&DOC_EXAMPLE[..60]), 0xB6F6_9832);
    }

    #[test]
    fn record_rejects_nan_inf_and_reserved() {
        let mut rec = [0u8; POINT_RECORD_LEN];
        let p = PointRecord {
            dt_ns: 5,
            x_m: 1.0,
            z_m: 2.0,
            intensity: 3,
            line_start: false,
            tag: 4,
        };
        p.emit(&mut rec, 0).unwrap();
        assert_eq!(PointRecord::parse(&rec), Ok(p));
        let mut b = rec;
        b[4..8].copy_from_slice(&f32::NAN.to_bits().to_le_bytes());
        assert_eq!(PointRecord::parse(&b), Err(Error::NonFinite { offset: 4 }));
        let mut b = rec;
        b[8..12].copy_from_slice(&f32::NEG_INFINITY.to_bits().to_le_bytes());
        assert_eq!(PointRecord::parse(&b), Err(Error::NonFinite { offset: 8 }));
        let mut b = rec;
        b[15] = 0x80;
        assert_eq!(
            PointRecord::parse(&b),
            Err(Error::ReservedNotZero { offset: 14 })
        );
        let nan = PointRecord {
            x_m: f32::INFINITY,
            ..p
        };
        let mut out = [0u8; 200];
        assert_eq!(
            emit_points(0, 0, &[p, nan], &mut out),
            Err(EncodeError::NonFinite { index: 1 })
        );
        assert_eq!(
            emit_points(0, 0, &[p; 65], &mut [0u8; 2000]),
            Err(EncodeError::TooManyPoints { count: 65, max: 64 })
        );
        assert_eq!(
            emit_points(0, 0, &[p; 2], &mut [0u8; 63]),
            Err(EncodeError::BufferTooSmall {
                needed: 64,
                available: 63
            })
        );
    }

    #[test]
    fn max_packet() {
        let p = PointRecord {
            dt_ns: 0,
            x_m: 0.0,
            z_m: 0.0,
            intensity: 0,
            line_start: false,
            tag: 0,
        };
        let mut out = [0u8; MAX_PACKET_LEN];
        let n = emit_points(0, 0, &[p; MAX_POINTS_PER_PACKET], &mut out).unwrap();
        assert_eq!(n, 1304);
        let r = PointsRepr::parse(&Packet::new_checked(&out[..n]).unwrap()).unwrap();
        assert_eq!(r.points.len(), 64);
    }

    proptest! {
        /// parse ∘ emit is the identity on reprs.
        #[test]
        fn points_roundtrip(base in any::<u64>(), seq in any::<u32>(),
                            pts in proptest::collection::vec(arb_point(), 0..=MAX_POINTS_PER_PACKET)) {
            let r = PointsRepr { base_time_ns: base, points: heapless::Vec::from_slice(&pts).unwrap() };
            let mut out = [0u8; MAX_PACKET_LEN];
            let n = r.emit(seq, &mut out).unwrap();
            prop_assert_eq!(n, points_packet_len(pts.len()));
            let p = Packet::new_checked(&out[..n]).unwrap();
            prop_assert_eq!(p.seq(), seq);
            let back = PointsRepr::parse(&p).unwrap();
            // Compare bitwise (−0.0 vs 0.0 must survive too).
            prop_assert_eq!(back.points.len(), r.points.len());
            for (a, b) in back.points.iter().zip(r.points.iter()) {
                prop_assert_eq!(a.x_m.to_bits(), b.x_m.to_bits());
                prop_assert_eq!(a.z_m.to_bits(), b.z_m.to_bits());
            }
            prop_assert_eq!(back, r);
        }

        /// emit ∘ parse is the identity on canonical bytes: mutate one byte, fix the CRC;
        /// whenever the result still parses, re-emitting gives the same bytes.
        #[test]
        fn points_canonical(pts in proptest::collection::vec(arb_point(), 1..8), at in 0usize..200, val in any::<u8>()) {
            let mut out = [0u8; MAX_PACKET_LEN];
            let n = emit_points(3, 42, &pts, &mut out).unwrap();
            let at = at % (n - 4);
            out[at] = val;
            let crc = crc::crc32(&out[..n - 4]);
            out[n - 4..n].copy_from_slice(&crc.to_le_bytes());
            let p = Packet::new_unchecked(&out[..n]);
            if let Ok(r) = PointsRepr::parse(&p) {
                let mut again = [0u8; MAX_PACKET_LEN];
                let m = r.emit(p.seq(), &mut again).unwrap();
                prop_assert_eq!(&again[..m], &out[..n]);
            }
        }
    }
}
