//! The encoder's fast path for a line given as columns (structure of arrays): records built
//! in registers straight from the kernel's f32 values, and the general path for the points
//! it does not take.

use super::super::{field, seal, EncodeError};
use super::packet::begin_fragment;
use super::point::{put_words, record_word3};
use super::{OutputHeaderRepr, OutputPointRepr, OUTPUT_POINT_LEN};

/// x′ or z′ in metres → micrometres on the fast path: `Some` exactly when |v| < 1024 m
/// (bit test; false for NaN and ±inf), and then |v · 2·10⁶| < 2^31, where
/// [`scale_round_fast`]'s rounding is [`scale_round`]'s (tested) and fits an i32.
///
/// [`scale_round_fast`]: super::point::scale_round_fast
/// [`scale_round`]: super::point::scale_round
#[inline(always)]
fn fast_um(v: f32) -> Option<i32> {
    // |v| < 1024 on the bits without the sign: (bits << 1) < 0x8900_0000, an immediate.
    if v.to_bits() << 1 >= 1024f32.to_bits() << 1 {
        return None;
    }
    Some(round_twice(v * 2e6))
}

/// s2 = 2·(v · scale) (exactly, see `point::scale_round_fast`), |s2| < 2^31 → v · scale
/// rounded half away from zero. q = trunc(s2); for q ≥ 0 the result is (q + 1) / 2, for q < 0 it
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
    // test would keep an integer constant in a register and need the remapping.)
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

/// [`emit_output_fragment`] for a line given as columns: a tight loop ([`fast_run`])
/// builds each record in registers from the columns ([`fast_words`]) and stores it as four
/// words, then [`seal`] computes the CRC over the finished packet. A point the fast path
/// does not take — `wire_status(status)` is `None`, or a value is large, non-finite or out
/// of range — comes from `point(i)` as in [`emit_output_fragment`], with the same errors
/// and indices; so does every point if a column is shorter than the fragment. The bytes
/// are [`emit_output_fragment`]'s with `point` (tested bit for bit). The body of
/// [`crate::wire::StreamEncoder::encode_output_columns`].
///
/// Why the CRC is not fed from the registers as each record is built: on the M4F that
/// loop needs the four CRC table bases, the five column pointers, the record pointer and
/// the CRC at once, more than the 13 registers, and its spills cost more than the four
/// loads per record the separate CRC pass makes (`docs/benchmarks.md`).
///
/// [`emit_output_fragment`]: super::packet::emit_output_fragment
pub(in crate::wire) fn emit_output_fragment_columns<S: Copy>(
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
/// firmware's line handler it spills the column pointers and the constants).
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
