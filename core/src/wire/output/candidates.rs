//! The candidates packet (kind 4, version 2): one scanline's line header and the output
//! records of its nadir and its two seed candidates only — the per-line result a host that
//! recomputes per-point values itself needs, in a fixed 104 bytes instead of 16 bytes per
//! point.

use super::super::{
    emit_header, field, seal, EncodeError, Error, Packet, PacketKind, CRC_LEN, HEADER_LEN, VERSION,
};
use super::{OutputHeaderRepr, OutputPointRepr, OUTPUT_HEADER_LEN, OUTPUT_POINT_LEN};

/// Length of a candidates packet (fixed): header, line header, three records, CRC.
pub const CANDIDATES_PACKET_LEN: usize =
    HEADER_LEN + OUTPUT_HEADER_LEN + 3 * OUTPUT_POINT_LEN + CRC_LEN;

/// One scanline's nadir and seed candidates. `header.first` is 0; each record is present
/// exactly when its index in `header` is (an absent one is 16 zero bytes on the wire).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CandidatesRepr {
    /// The line header, as an output packet's (`first` = 0).
    pub header: OutputHeaderRepr,
    /// The nadir point's output record.
    pub nadir: Option<OutputPointRepr>,
    /// The left seed candidate's output record.
    pub left: Option<OutputPointRepr>,
    /// The right seed candidate's output record.
    pub right: Option<OutputPointRepr>,
}

impl CandidatesRepr {
    /// The three records in packet order with their indices.
    fn slots(&self) -> [(Option<u16>, Option<OutputPointRepr>); 3] {
        let h = &self.header;
        [
            (h.nadir, self.nadir),
            (h.left, self.left),
            (h.right, self.right),
        ]
    }

    /// Parses a candidates packet (full check: CRC, version, kind, length, header fields,
    /// records, absent records zero).
    pub fn parse<T: AsRef<[u8]>>(packet: &Packet<T>) -> Result<Self, Error> {
        let kind = packet.check()?;
        if kind != PacketKind::Candidates {
            return Err(Error::WrongKind { kind: kind as u8 });
        }
        let b = packet.bytes();
        let header = OutputHeaderRepr::read(b, packet.version())?;
        if header.first != 0 {
            return Err(Error::OutOfRange {
                offset: field::out::FIRST.start,
            });
        }
        let mut recs = [None; 3];
        let idx = [header.nadir, header.left, header.right];
        for (k, (slot, i)) in recs.iter_mut().zip(idx).enumerate() {
            let at = field::out::POINTS + k * OUTPUT_POINT_LEN;
            let bytes = b.get(at..at + OUTPUT_POINT_LEN).unwrap_or(&[]);
            if i.is_some() {
                *slot = Some(OutputPointRepr::parse(bytes).map_err(|e| match e {
                    Error::OutOfRange { offset } => Error::OutOfRange {
                        offset: at + offset,
                    },
                    Error::ReservedNotZero { offset } => Error::ReservedNotZero {
                        offset: at + offset,
                    },
                    other => other,
                })?);
            } else if let Some(o) = bytes.iter().position(|&v| v != 0) {
                return Err(Error::ReservedNotZero { offset: at + o });
            }
        }
        let [nadir, left, right] = recs;
        Ok(Self {
            header,
            nadir,
            left,
            right,
        })
    }

    /// Writes the packet with sequence number `seq` into `out`; returns its length
    /// ([`CANDIDATES_PACKET_LEN`]). Rejects a record whose presence does not match its
    /// index, and indices not below `line_len`.
    pub fn emit(&self, seq: u32, out: &mut [u8]) -> Result<usize, EncodeError> {
        let len = CANDIDATES_PACKET_LEN;
        if out.len() < len {
            return Err(EncodeError::BufferTooSmall {
                needed: len,
                available: out.len(),
            });
        }
        if !self.header.indices_ok() {
            return Err(EncodeError::OutOfRange {
                index: usize::from(self.header.line_len),
            });
        }
        let slots = self.slots();
        let mut words = [[0u32; 4]; 3];
        for (w, (i, rec)) in words.iter_mut().zip(slots) {
            match (i, rec) {
                (Some(i), Some(r)) => *w = r.words(usize::from(i))?,
                (None, None) => {}
                (i, _) => {
                    return Err(EncodeError::OutOfRange {
                        index: usize::from(i.unwrap_or(self.header.line_len)),
                    })
                }
            }
        }
        let len16 = u16::try_from(len).map_err(|_| EncodeError::OutOfRange { index: 0 })?;
        emit_header(out, VERSION, PacketKind::Candidates, len16, seq);
        self.header.put(0, out);
        let (recs, _) = out
            .get_mut(field::out::POINTS..field::out::POINTS + 3 * OUTPUT_POINT_LEN)
            .unwrap_or(&mut [])
            .as_chunks_mut::<OUTPUT_POINT_LEN>();
        for (rec, w) in recs.iter_mut().zip(words) {
            super::point::put_words(rec, w);
        }
        seal(out, len);
        Ok(len)
    }
}
