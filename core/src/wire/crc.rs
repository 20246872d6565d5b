//! CRC-32/ISO-HDLC — the "IEEE" CRC-32 of Ethernet, zlib, PNG and Python's `zlib.crc32`:
//! reflected polynomial 0xEDB88320 (normal form 0x04C11DB7), initial value and final XOR
//! 0xFFFFFFFF. Check value of `b"123456789"`: 0xCBF43926.
//!
//! Why this CRC and not CRC-32C: the STM32F405's CRC peripheral computes exactly this
//! polynomial (on 32-bit words, unreflected, no final XOR — with `RBIT` on each input word
//! and on the result, then inverting, it yields this CRC; every region the format protects
//! is a multiple of 4 bytes long), and
//! every host language has it in its standard library, so a stream can be checked with
//! one line of Python. Error detection for packets of at most [`super::MAX_PACKET_LEN`]
//! bytes (< 12 000 bits): every burst of up to 32 bits and every 3-bit error is caught
//! (Hamming distance 4 up to 91 607 bits, Koopman 2002). CRC-32C detects somewhat more on
//! long packets, but the target has no hardware for it.
//!
//! Three software forms, bit-identical (tested): byte-at-a-time with one 256-entry table
//! (1 KiB), slicing-by-4 (the first 4 KiB of the tables; one 32-bit load and four
//! lookups per 4 bytes, 16 bytes per loop iteration — the form for the M4F, fewer
//! instructions per byte there than byte-at-a-time, `docs/benchmarks.md`) and
//! slicing-by-8 (8 KiB of tables, several times faster on a host CPU). On the M4F
//! slicing-by-8 cannot win: per 8 bytes it needs the same 2 loads, 8 byte extractions,
//! 8 lookups and 8 XORs as two slicing-by-4 steps, and its 8 table bases do not fit the
//! registers beside the loop's own, so it spills. [`Crc32`] uses slicing-by-8
//! on targets with 64-bit pointers and slicing-by-4 elsewhere.
//!
//! The STM32F405's CRC unit would do a 32-bit word per bus write (see above), but QEMU
//! 7.2's `netduinoplus2` does not emulate it (its STM32F405 model maps the CRC unit's
//! address range as an unimplemented device), so nothing here could be counted or tested
//! on it; the published instruction counts are this software CRC's.

/// Reflected CRC-32 polynomial (IEEE 802.3).
const POLY: u32 = 0xEDB8_8320;

/// The 8 tables of slicing-by-8; `TABLES[0]` is the classic byte-at-a-time table.
static TABLES: [[u32; 256]; 8] = make_tables();

const fn make_tables() -> [[u32; 256]; 8] {
    let mut t = [[0u32; 256]; 8];
    let mut i = 0;
    while i < 256 {
        let mut c = i as u32; // i < 256: lossless
        let mut k = 0;
        while k < 8 {
            c = if c & 1 != 0 { (c >> 1) ^ POLY } else { c >> 1 };
            k += 1;
        }
        t[0][i] = c;
        i += 1;
    }
    let mut s = 1;
    while s < 8 {
        let mut i = 0;
        while i < 256 {
            let prev = t[s - 1][i];
            t[s][i] = (prev >> 8) ^ t[0][(prev & 0xFF) as usize];
            i += 1;
        }
        s += 1;
    }
    t
}

/// Index of the table entry for the low byte of `x`.
#[inline(always)]
fn lo(x: u32) -> usize {
    usize::from(x.to_le_bytes()[0])
}

/// Byte-at-a-time update of a raw (pre-inverted) CRC register.
#[inline]
fn update_bytewise(mut c: u32, data: &[u8]) -> u32 {
    for &b in data {
        c = (c >> 8) ^ TABLES[0][lo(c ^ u32::from(b))];
    }
    c
}

/// Slicing-by-8 update of a raw CRC register (Intel's algorithm, Kounavis & Berry 2005).
#[inline]
fn update_slice8(mut c: u32, data: &[u8]) -> u32 {
    let mut chunks = data.chunks_exact(8);
    for ch in &mut chunks {
        let mut w = [0u8; 8];
        w.copy_from_slice(ch);
        let a = c ^ u32::from_le_bytes([w[0], w[1], w[2], w[3]]);
        let b = u32::from_le_bytes([w[4], w[5], w[6], w[7]]);
        c = TABLES[7][lo(a)]
            ^ TABLES[6][lo(a >> 8)]
            ^ TABLES[5][lo(a >> 16)]
            ^ TABLES[4][lo(a >> 24)]
            ^ TABLES[3][lo(b)]
            ^ TABLES[2][lo(b >> 8)]
            ^ TABLES[1][lo(b >> 16)]
            ^ TABLES[0][lo(b >> 24)];
    }
    update_bytewise(c, chunks.remainder())
}

/// One slicing-by-4 step: the CRC register after the 4 bytes of `w` (little-endian).
#[inline(always)]
fn step4(c: u32, w: u32) -> u32 {
    let a = c ^ w;
    TABLES[3][lo(a)] ^ TABLES[2][lo(a >> 8)] ^ TABLES[1][lo(a >> 16)] ^ TABLES[0][lo(a >> 24)]
}

/// Slicing-by-4 update of a raw CRC register: one 32-bit load and four lookups (tables 0–3
/// of the slicing-by-8 set) per 4 bytes, 16 bytes per loop iteration.
#[inline]
fn update_slice4(mut c: u32, data: &[u8]) -> u32 {
    let (blocks, rest) = data.as_chunks::<16>();
    for b in blocks {
        let [w0, w1, w2, w3] = [0, 4, 8, 12].map(|i| u32::from_le_bytes(get4(b, i)));
        c = step4(c, w0);
        c = step4(c, w1);
        c = step4(c, w2);
        c = step4(c, w3);
    }
    let (words, rest) = rest.as_chunks::<4>();
    for w in words {
        c = step4(c, u32::from_le_bytes(*w));
    }
    update_bytewise(c, rest)
}

/// Bytes `i..i + 4` of a 16-byte block (`i` ≤ 12; constant after inlining).
#[inline(always)]
fn get4(b: &[u8; 16], i: usize) -> [u8; 4] {
    let mut w = [0u8; 4];
    if let Some(s) = b.get(i..i + 4) {
        w.copy_from_slice(s);
    }
    w
}

/// An incremental CRC-32 (IEEE), so a packet split over the two halves of a ring can be
/// checked without copying it.
#[derive(Clone, Copy, Debug)]
pub struct Crc32 {
    reg: u32,
}

impl Crc32 {
    /// A fresh computation.
    pub const fn new() -> Self {
        Self { reg: 0xFFFF_FFFF }
    }

    /// Feeds `data`.
    #[inline]
    pub fn update(&mut self, data: &[u8]) {
        self.reg = if cfg!(target_pointer_width = "64") {
            update_slice8(self.reg, data)
        } else {
            update_slice4(self.reg, data)
        };
    }

    /// The CRC of everything fed so far.
    pub fn finish(&self) -> u32 {
        !self.reg
    }
}

impl Default for Crc32 {
    fn default() -> Self {
        Self::new()
    }
}

/// CRC-32 (IEEE) of `data` with the form [`Crc32`] picks for this target.
pub fn crc32(data: &[u8]) -> u32 {
    let mut c = Crc32::new();
    c.update(data);
    c.finish()
}

/// CRC-32 (IEEE) of `data`, byte at a time with one 1 KiB table (the M4F form).
pub fn crc32_bytewise(data: &[u8]) -> u32 {
    !update_bytewise(0xFFFF_FFFF, data)
}

/// CRC-32 (IEEE) of `data`, slicing-by-4 (the M4F form).
pub fn crc32_slice4(data: &[u8]) -> u32 {
    !update_slice4(0xFFFF_FFFF, data)
}

/// CRC-32 (IEEE) of `data`, slicing-by-8 (the host form).
pub fn crc32_slice8(data: &[u8]) -> u32 {
    !update_slice8(0xFFFF_FFFF, data)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn check_value() {
        // The catalogue check value of CRC-32/ISO-HDLC.
        assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
        assert_eq!(crc32_bytewise(b"123456789"), 0xCBF4_3926);
        assert_eq!(crc32_slice8(b"123456789"), 0xCBF4_3926);
        assert_eq!(crc32_slice4(b"123456789"), 0xCBF4_3926);
        assert_eq!(crc32(b""), 0);
        // Python: zlib.crc32(b"The quick brown fox jumps over the lazy dog") == 0x414FA339
        assert_eq!(
            crc32(b"The quick brown fox jumps over the lazy dog"),
            0x414F_A339
        );
    }

    proptest! {
        #[test]
        fn forms_agree_and_split_anywhere(data in proptest::collection::vec(any::<u8>(), 0..300), cut in 0usize..300) {
            let cut = cut.min(data.len());
            let a = crc32_bytewise(&data);
            prop_assert_eq!(a, crc32_slice8(&data));
            prop_assert_eq!(a, crc32_slice4(&data));
            let mut c = Crc32::new();
            c.update(&data[..cut]);
            c.update(&data[cut..]);
            prop_assert_eq!(a, c.finish());
        }
    }
}
