//! One output point: scaling the kernel's f32 values to the wire's integers, parsing and
//! writing a record, and the record's four little-endian words.

use super::super::{field, get_u32, get_u8, EncodeError, Error};
use super::OUTPUT_POINT_LEN;

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
pub(super) fn scale_round(v: f32, scale: f32, lo: i32, hi: i32) -> Option<i32> {
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
pub(super) fn scale_round_fast(v: f32, twice_scale: f32) -> Option<i32> {
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
        let rho_cdeg = i16::from_le_bytes(super::super::get_bytes(
            bytes,
            field::out_point::RHO_CDEG.start,
        ));
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
            x_um: i32::from_le_bytes(super::super::get_bytes(bytes, field::out_point::X_UM.start)),
            z_um: i32::from_le_bytes(super::super::get_bytes(bytes, field::out_point::Z_UM.start)),
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
    pub(super) fn words(&self, index: usize) -> Result<[u32; 4], EncodeError> {
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
pub(super) fn record_word3(rho_cdeg: i16, status: u8) -> u32 {
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
pub(super) fn put_words(out: &mut [u8; OUTPUT_POINT_LEN], words: [u32; 4]) {
    for (dst, w) in out.chunks_exact_mut(4).zip(words) {
        dst.copy_from_slice(&w.to_le_bytes());
    }
}
