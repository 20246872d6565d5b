//! Finding packets in a byte stream (postcard's accumulator idea): look at the unread bytes,
//! say how many to skip as garbage, or that a whole CRC-checked packet starts here, or that
//! more bytes are needed. The bytes may come in two slices (the two halves of a ring), so a
//! packet that wraps around a ring's end is found without copying it.
//!
//! Resynchronisation rule (`docs/wire-format.md`, "Framing"): a candidate packet starts
//! at a [`SYNC`] pair. A candidate whose length field is outside
//! `MIN_PACKET_LEN..=MAX_PACKET_LEN`, or whose CRC fails, is not a packet: one byte is
//! skipped and the search goes on from the next byte, so a packet hidden behind a
//! false sync inside garbage (or inside a corrupted packet) is still found.

use super::crc::Crc32;
use super::{
    field, PacketKind, CRC_LEN, FLAG_LINK_CHECKED, HEADER_LEN, MAX_PACKET_LEN, MIN_PACKET_LEN,
    SYNC, VERSION,
};

/// What the start of the unread bytes holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Scan {
    /// No bytes at all.
    Empty,
    /// The first `len` bytes are a packet whose CRC checks (version, kind and contents are
    /// the caller's to validate).
    Packet {
        /// Packet length.
        len: usize,
    },
    /// The first `len` (≥ 1) bytes cannot start a packet: skip them.
    Garbage {
        /// Bytes to skip.
        len: usize,
        /// Why.
        reason: GarbageReason,
    },
    /// The bytes may start a packet that is not complete yet: wait for more. (Never
    /// returned when `at_end` is set.)
    Incomplete,
}

/// Why bytes were skipped while looking for packets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum GarbageReason {
    /// No sync word there.
    NoSync,
    /// A sync word whose length field is out of range.
    BadLength,
    /// A sync word whose packet fails the CRC.
    Crc,
    /// A sync word whose packet is cut off by the end of the stream.
    Truncated,
}

#[inline]
fn byte_at(a: &[u8], b: &[u8], i: usize) -> Option<u8> {
    match i.checked_sub(a.len()) {
        None => a.get(i).copied(),
        Some(j) => b.get(j).copied(),
    }
}

/// Copies bytes `start..start + dst.len()` of the concatenation `a ++ b` into `dst`; returns
/// false (leaving `dst` partly written) if they are not all there.
pub(crate) fn copy_from_two(a: &[u8], b: &[u8], start: usize, dst: &mut [u8]) -> bool {
    let Some(end) = start.checked_add(dst.len()) else {
        return false;
    };
    if end > a.len() + b.len() {
        return false;
    }
    let split = a.len().clamp(start, end);
    let (d1, d2) = dst.split_at_mut(split - start);
    let a_part = if split > start {
        a.get(start..split)
    } else {
        Some(&[][..])
    };
    let b_part = b.get(split.saturating_sub(a.len())..end.saturating_sub(a.len()));
    match (a_part, b_part) {
        (Some(s1), Some(s2)) => {
            d1.copy_from_slice(s1);
            d2.copy_from_slice(s2);
            true
        }
        _ => false,
    }
}

/// CRC-32 of bytes `0..end` of `a ++ b` (caller guarantees `end ≤ a.len() + b.len()`).
/// Out of line: inlined into the ingest loop, the CRC's table bases and the loop's own
/// registers compete and both spill on the M4F.
#[inline(never)]
fn crc_two(a: &[u8], b: &[u8], end: usize) -> u32 {
    let mut c = Crc32::new();
    c.update(a.get(..end.min(a.len())).unwrap_or(&[]));
    if end > a.len() {
        c.update(b.get(..end - a.len()).unwrap_or(&[]));
    }
    c.finish()
}

/// Looks at the start of `buf`; see [`scan_two`].
pub fn scan(buf: &[u8], at_end: bool) -> Scan {
    scan_two(buf, &[], at_end)
}

/// Looks at the start of the bytes `a ++ b`. With `at_end` (no more bytes will come), a
/// candidate cut off by the end is garbage instead of [`Scan::Incomplete`].
pub fn scan_two(a: &[u8], b: &[u8], at_end: bool) -> Scan {
    let total = a.len() + b.len();
    if total == 0 {
        return Scan::Empty;
    }
    // First position that could start a packet: SYNC[0] followed by SYNC[1] or by the end.
    let mut start = None;
    for (i, &x) in a.iter().chain(b.iter()).enumerate() {
        if x == SYNC[0] {
            match byte_at(a, b, i + 1) {
                Some(y) if y == SYNC[1] => {
                    start = Some(i);
                    break;
                }
                None => {
                    start = Some(i);
                    break;
                }
                Some(_) => {}
            }
        }
    }
    let wait_or_skip = || {
        if at_end {
            Scan::Garbage {
                len: 1,
                reason: GarbageReason::Truncated,
            }
        } else {
            Scan::Incomplete
        }
    };
    match start {
        None => {
            return Scan::Garbage {
                len: total,
                reason: GarbageReason::NoSync,
            }
        }
        Some(0) => {}
        Some(i) => {
            return Scan::Garbage {
                len: i,
                reason: GarbageReason::NoSync,
            }
        }
    }
    let mut len_bytes = [0u8; 2];
    if !copy_from_two(a, b, field::LENGTH.start, &mut len_bytes) {
        return wait_or_skip();
    }
    let length = usize::from(u16::from_le_bytes(len_bytes));
    if !(MIN_PACKET_LEN..=MAX_PACKET_LEN).contains(&length) {
        return Scan::Garbage {
            len: 1,
            reason: GarbageReason::BadLength,
        };
    }
    if total < length.max(HEADER_LEN) {
        return wait_or_skip();
    }
    let mut stored = [0u8; CRC_LEN];
    if !copy_from_two(a, b, length - CRC_LEN, &mut stored) {
        return wait_or_skip();
    }
    // A link-checked packet (version 2, flag set, CRC field zero) carries no CRC: the link
    // below checked it. It must then at least name a known kind of a fitting length, or a
    // false sync would make the reader skip a whole false length of real packets.
    let mut hdr = [0u8; HEADER_LEN];
    let _ = copy_from_two(a, b, 0, &mut hdr);
    let flags = u16::from_le_bytes([hdr[field::FLAGS.start], hdr[field::FLAGS.start + 1]]);
    if hdr[field::VERSION] == VERSION && flags == FLAG_LINK_CHECKED && stored == [0; CRC_LEN] {
        return match PacketKind::from_u8(hdr[field::KIND]) {
            Some(kind) if kind.length_ok(length) => Scan::Packet { len: length },
            _ => Scan::Garbage {
                len: 1,
                reason: GarbageReason::BadLength,
            },
        };
    }
    if crc_two(a, b, length - CRC_LEN) != u32::from_le_bytes(stored) {
        return Scan::Garbage {
            len: 1,
            reason: GarbageReason::Crc,
        };
    }
    Scan::Packet { len: length }
}

#[cfg(test)]
mod tests {
    use super::super::{points::tests::DOC_EXAMPLE, StreamEncoder};
    use super::*;

    /// Runs the scanner over `buf` like a reader would; returns (packets, garbage bytes).
    fn drain(mut buf: &[u8]) -> (usize, usize) {
        let (mut packets, mut garbage) = (0, 0);
        loop {
            match scan(buf, true) {
                Scan::Empty => return (packets, garbage),
                Scan::Packet { len } => {
                    packets += 1;
                    buf = &buf[len..];
                }
                Scan::Garbage { len, .. } => {
                    garbage += len;
                    buf = &buf[len..];
                }
                Scan::Incomplete => unreachable!("at_end"),
            }
        }
    }

    #[test]
    fn resync_after_garbage() {
        let mut s = [0u8; 300];
        // Garbage with false syncs (one with a huge length, one with a plausible length and
        // a wrong CRC), then the doc example, garbage again, and the example twice more.
        s[..10].copy_from_slice(&[1, 2, 0xA5, 0xC3, 0x01, 0x01, 0xFF, 0xFF, 0xA5, 9]);
        s[10..30].copy_from_slice(&[
            0xA5, 0xC3, 1, 1, 20, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
        ]);
        s[30..94].copy_from_slice(&DOC_EXAMPLE);
        s[94..100].copy_from_slice(&[0xA5, 0xA5, 0xC3, 0, 0, 0]);
        s[100..164].copy_from_slice(&DOC_EXAMPLE);
        s[164..228].copy_from_slice(&DOC_EXAMPLE);
        assert_eq!(drain(&s[..228]), (3, 228 - 3 * 64));
        // A packet cut off by the end of the stream is garbage, byte by byte.
        assert_eq!(drain(&s[..227]), (2, 227 - 2 * 64));
        // Without at_end, the cut packet waits.
        assert_eq!(scan(&s[164..227], false), Scan::Incomplete);
        assert_eq!(scan(&[0xA5], false), Scan::Incomplete);
        assert_eq!(
            scan(&[0x00, 0xA5], false),
            Scan::Garbage {
                len: 1,
                reason: GarbageReason::NoSync
            }
        );
    }

    /// The CRC over the two halves of a ring equals every form of the CRC over the joined
    /// bytes, for every split point and every end.
    #[test]
    fn crc_two_at_every_split() {
        let mut r = 7u32;
        let mut buf = [0u8; 97];
        for v in buf.iter_mut() {
            r = r.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            *v = (r >> 24) as u8;
        }
        for cut in 0..=buf.len() {
            let (a, b) = buf.split_at(cut);
            for end in [0, 1, 3, 4, 5, 17, 52, 96, 97] {
                let want = super::super::crc::crc32_bytewise(&buf[..end]);
                assert_eq!(crc_two(a, b, end), want, "cut {cut} end {end}");
                assert_eq!(super::super::crc::crc32_slice4(&buf[..end]), want);
                assert_eq!(super::super::crc::crc32_slice8(&buf[..end]), want);
            }
        }
    }

    #[test]
    fn packet_found_in_every_split_of_two_slices() {
        let mut enc = StreamEncoder::new();
        let mut buf = [0u8; 200];
        let n = enc
            .encode_config(&[5; crate::wire::CONFIG_WORDS], &mut buf)
            .unwrap();
        for cut in 0..=n {
            let (a, b) = buf[..n].split_at(cut);
            assert_eq!(scan_two(a, b, false), Scan::Packet { len: n }, "cut {cut}");
            let mut copy = [0u8; 200];
            assert!(copy_from_two(a, b, 3, &mut copy[..n - 3]));
            assert_eq!(&copy[..n - 3], &buf[3..n]);
        }
    }
}
