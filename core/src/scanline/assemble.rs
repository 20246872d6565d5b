//! Scanline assembly (docs/spec.md §2; Honma et al. §2.2 treat each revolution of the mirror as one
//! scanline): points arrive in acquisition order and are cut into lines.
//!
//! # Split rules
//!
//! A point *starts a new line* (the current, non-empty line is complete) when, checked in
//! this order:
//!
//! 1. **Line-start flag** — the point carries [`PointRecord::line_start`].
//! 2. **Time gap** — its time differs from the previous point's by more than
//!    [`SplitParams::gap_ns`] (either direction: a jump back is a new stream).
//! 3. **Side change away from the nadir** (only while geometric splitting is active, see
//!    [`GeometrySplit`]) — x′ changes sign between the last point with x′ ≠ 0 (`a`) and
//!    this one (`b`), the crossing is a *zenith crossing* (below), and the assembler is
//!    *armed*.
//!
//! A crossing from `a` to `b` (opposite signs of x′) is classified with
//! `c = x′_a·z′_b − z′_a·x′_b` (the sense of the short arc from `a` to `b` seen from the
//! scanner: `c > 0` counter-clockwise in the x′–z′ plane) and the stream's rotation sense
//! `s` (±1, the sign of a running vote of `sign(c)` over all consecutive point pairs,
//! clamped to ±[`VOTE_CLAMP`], trusted once |vote| ≥ [`VOTE_MIN`]):
//!
//! - **zenith** if `sign(c) = sign(x′_a)`: the straight chord from `a` to `b` passes
//!   *above* the scanner (z′ at x′ = 0 is `c / (x′_a − x′_b)` > 0) — there were returns
//!   up there, or the gap was shorter over the top;
//! - **zenith** if `s` is trusted, `sign(c) = −s` (the short arc runs against the rotation,
//!   so the mirror went the long way round) and the angle between `a` and `b` exceeds 90°
//!   (`a·b < 0`) — the open-sky case: the last return on one side and the first on the
//!   other are both below the scanner, but the mirror swept across the sky between them;
//! - **zenith** if `c = 0` and `s = sign(x′_a)` (exactly opposite directions: the
//!   rotation decides);
//! - otherwise **nadir**: a crossing below the scanner, which is never a split.
//!
//! The 90° condition keeps a backwards jitter of a few points under the scanner from
//! counting as a trip over the top. *Arming* adds hysteresis: a nadir crossing arms, a
//! zenith crossing disarms, so jitter among returns overhead (a wire, a branch) cannot
//! split a line twice; the stream starts armed, and a time gap, a sequence gap or the end
//! of the stream re-arm and forget the previous point.
//!
//! [`GeometrySplit::Auto`] (the default) splits geometrically until the first line-start
//! flag is seen: a source that numbers its lines is trusted from then on.
//!
//! A line longer than `N` keeps its first `N` points; the rest are counted in
//! [`Line::truncated`] (and still drive the split rules), never a panic.

use super::Line;
use crate::wire::{PointRecord, POINT_RECORD_LEN};

/// The rotation-sense vote saturates here (so a stream that changes scanners re-learns).
pub const VOTE_CLAMP: i32 = 64;
/// The rotation sense is trusted once |vote| reaches this.
pub const VOTE_MIN: i32 = 8;

/// When the geometric split rule (side change away from the nadir) is active.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum GeometrySplit {
    /// Until the stream's first line-start flag, then never.
    Auto,
    /// Always, flags or not.
    Always,
    /// Never: only flags and time gaps split.
    Never,
}

/// The parameters of line splitting.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SplitParams {
    /// A time step between consecutive points longer than this ends the line, ns. Default
    /// 5 ms: half a revolution at 100 Hz and a whole one at 200 Hz — no scanner sweeps that
    /// long without a return inside one line except across open sky, which rule 3 handles;
    /// within a revolution points come every few µs. (Not a paper parameter.)
    pub gap_ns: u64,
    /// When the side-change rule is active.
    pub geometry: GeometrySplit,
}

impl SplitParams {
    /// The defaults.
    pub const DEFAULT: Self = Self {
        gap_ns: 5_000_000,
        geometry: GeometrySplit::Auto,
    };
}

impl Default for SplitParams {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// Why a line ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum SplitReason {
    /// The next point had the line-start flag.
    LineStart,
    /// The scan crossed over the scanner (side change away from the nadir).
    Zenith,
    /// A time gap longer than [`SplitParams::gap_ns`].
    TimeGap,
    /// Packets were lost (sequence gap): a line boundary may have been lost with them.
    SeqGap,
    /// A config packet arrived (new parameters apply from the next line).
    Config,
    /// End of the stream.
    End,
}

/// What [`Assembler::offer`] did with a point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Offer {
    /// The point joined the current line (stored, or counted as truncated).
    Taken,
    /// The point starts a new line: the current line is complete and was *not* given the
    /// point. Read the line, then offer the same point again (it opens the next line).
    Split(SplitReason),
}

/// Counters of assembly.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AssembleCounters {
    /// Lines completed.
    pub lines: u64,
    /// Points stored in completed lines.
    pub points_in_lines: u64,
    /// Points of completed lines dropped because the line was over capacity.
    pub points_truncated: u64,
    /// Completed lines that were truncated.
    pub lines_truncated: u64,
    /// Lines ended by [`SplitReason::LineStart`].
    pub split_line_start: u64,
    /// Lines ended by [`SplitReason::Zenith`].
    pub split_zenith: u64,
    /// Lines ended by [`SplitReason::TimeGap`].
    pub split_time_gap: u64,
    /// Lines ended by [`SplitReason::SeqGap`].
    pub split_seq_gap: u64,
    /// Lines ended by [`SplitReason::Config`].
    pub split_config: u64,
    /// Lines ended by [`SplitReason::End`].
    pub split_end: u64,
}

/// How a side change is classified.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Crossing {
    None,
    Nadir,
    Zenith,
}

/// Cuts a stream of points into [`Line`]s of at most `N` points.
// `repr(C)`, the per-point state first and the line last (its own per-point fields lead
// it): every field the fast path of `offer` touches lies within an immediate offset of
// the assembler's start on the Cortex-M4F (see [`Line`]).
#[repr(C)]
pub struct Assembler<const N: usize> {
    /// The current line is complete (returned by a split or close) and not yet cleared.
    closed: bool,
    /// Forget the previous point before taking the next (after a gap or the end).
    reset: bool,
    /// A zenith crossing may split (see the module docs).
    armed: bool,
    /// A line-start flag has been seen in the stream.
    seen_flag: bool,
    /// Rotation-sense vote (+ = counter-clockwise in the x′–z′ plane).
    vote: i32,
    /// Previous point (x′, z′), for the rotation vote.
    last_pt: Option<(f32, f32)>,
    /// Last point with x′ ≠ 0, for side changes.
    last_side_pt: Option<(f32, f32)>,
    /// Time of the previous point.
    last_t: Option<u64>,
    params: SplitParams,
    /// Index the next line will get.
    next_index: u32,
    counters: AssembleCounters,
    line: Line<N>,
}

impl<const N: usize> Assembler<N> {
    const N_OK: () = assert!(N <= u16::MAX as usize, "point indices are u16 downstream");

    /// An assembler with [`SplitParams::DEFAULT`].
    pub const fn new() -> Self {
        let () = Self::N_OK;
        Self {
            line: Line::new(),
            params: SplitParams::DEFAULT,
            counters: AssembleCounters {
                lines: 0,
                points_in_lines: 0,
                points_truncated: 0,
                lines_truncated: 0,
                split_line_start: 0,
                split_zenith: 0,
                split_time_gap: 0,
                split_seq_gap: 0,
                split_config: 0,
                split_end: 0,
            },
            next_index: 0,
            closed: false,
            reset: false,
            last_t: None,
            last_pt: None,
            last_side_pt: None,
            vote: 0,
            armed: true,
            seen_flag: false,
        }
    }

    /// The assembler [`Assembler::new`] gives, without rewriting the line's arrays (only
    /// its first `len` points are ever read).
    pub fn restart(&mut self) {
        let Self {
            closed,
            reset,
            armed,
            seen_flag,
            vote,
            last_pt,
            last_side_pt,
            last_t,
            params,
            next_index,
            counters,
            line,
        } = self;
        (*closed, *reset, *armed, *seen_flag) = (false, false, true, false);
        *vote = 0;
        (*last_pt, *last_side_pt, *last_t) = (None, None, None);
        *params = SplitParams::DEFAULT;
        *next_index = 0;
        *counters = AssembleCounters::default();
        line.clear();
    }

    /// The split parameters in force.
    pub fn params(&self) -> SplitParams {
        self.params
    }
    /// Sets the split parameters (they apply from the next point).
    pub fn set_params(&mut self, params: SplitParams) {
        self.params = params;
    }
    /// The counters.
    pub fn counters(&self) -> AssembleCounters {
        self.counters
    }
    /// The current line (complete after [`Offer::Split`] or a successful [`Self::close`]).
    pub fn line(&self) -> &Line<N> {
        &self.line
    }
    /// The current line, mutable (the kernel processes it in place).
    pub fn line_mut(&mut self) -> &mut Line<N> {
        &mut self.line
    }
    /// Points in the open line not yet counted in a completed line (stored + truncated).
    pub fn pending_points(&self) -> u64 {
        if self.closed {
            0
        } else {
            self.line.len as u64 + u64::from(self.line.truncated)
        }
    }
    /// The learnt rotation sense: +1 counter-clockwise, −1 clockwise in the x′–z′ plane
    /// (x′ left, z′ up), 0 while not yet trusted.
    pub fn rotation_sense(&self) -> i32 {
        if self.vote.abs() >= VOTE_MIN {
            self.vote.signum()
        } else {
            0
        }
    }

    fn line_has_points(&self) -> bool {
        self.line.len > 0 || self.line.truncated > 0
    }

    fn complete(&mut self, reason: SplitReason) {
        let c = &mut self.counters;
        c.lines += 1;
        c.points_in_lines += self.line.len as u64;
        c.points_truncated += u64::from(self.line.truncated);
        c.lines_truncated += u64::from(self.line.truncated > 0);
        match reason {
            SplitReason::LineStart => c.split_line_start += 1,
            SplitReason::Zenith => c.split_zenith += 1,
            SplitReason::TimeGap => c.split_time_gap += 1,
            SplitReason::SeqGap => c.split_seq_gap += 1,
            SplitReason::Config => c.split_config += 1,
            SplitReason::End => c.split_end += 1,
        }
        self.reset |= matches!(
            reason,
            SplitReason::TimeGap | SplitReason::SeqGap | SplitReason::End
        );
        self.next_index = self.next_index.wrapping_add(1);
        self.closed = true;
    }

    /// Ends the current line from outside (sequence gap, config, end of stream). Returns
    /// true if it held points: it is then complete and readable until the next
    /// [`Self::offer`]. With [`SplitReason::SeqGap`] or [`SplitReason::End`] the next point
    /// is not compared with the previous one, even if the line was empty.
    pub fn close(&mut self, reason: SplitReason) -> bool {
        if self.closed || !self.line_has_points() {
            self.reset |= matches!(
                reason,
                SplitReason::TimeGap | SplitReason::SeqGap | SplitReason::End
            );
            return false;
        }
        self.complete(reason);
        true
    }

    /// Classifies the side change from the last side point to (x, z).
    fn crossing(&self, x: f32, z: f32) -> Crossing {
        let Some((xa, za)) = self.last_side_pt else {
            return Crossing::None;
        };
        let side_a = if xa > 0.0 { 1 } else { -1 };
        let side_b = if x > 0.0 {
            1
        } else if x < 0.0 {
            -1
        } else {
            0
        };
        if side_b == 0 || side_b == side_a {
            return Crossing::None;
        }
        let c = xa * z - za * x;
        let sense = self.rotation_sense();
        let short = if c > 0.0 {
            1
        } else if c < 0.0 {
            -1
        } else {
            0
        };
        let zenith = if short == 0 {
            sense == side_a
        } else {
            short == side_a || (sense != 0 && short == -sense && xa * x + za * z < 0.0)
        };
        if zenith {
            Crossing::Zenith
        } else {
            Crossing::Nadir
        }
    }

    /// Offers the next point (absolute time `t_ns`, finite x′/z′ — the wire guarantees it).
    #[inline(always)]
    pub fn offer(&mut self, t_ns: u64, p: &PointRecord) -> Offer {
        // The common case first, in as few instructions as it takes: a point that
        // continues an open, non-empty line within capacity, without a flag, a time gap
        // or a side change. Every rule of `offer_general` then comes out the same: no
        // split (no flag, no gap, no crossing to be a zenith), nothing to reset, no
        // arming, the line already has its index and start time; what is left is the
        // rotation vote, the previous-point state and the push (tested against the
        // general path).
        let (x, z) = (p.x_m, p.z_m);
        let len = self.line.len;
        if !self.closed && !self.reset && !p.line_start && len > 0 && len < N {
            if let (Some(lt), Some((xa, za)), Some((xs, _))) =
                (self.last_t, self.last_pt, self.last_side_pt)
            {
                // Time runs forward here (a step back, however small, takes the general
                // path): one subtraction instead of an absolute difference.
                let forward = t_ns >= lt && t_ns - lt <= self.params.gap_ns;
                if forward && (x > 0.0) == (xs > 0.0) {
                    self.vote_on(xa, za, x, z);
                    self.last_pt = Some((x, z));
                    if x != 0.0 {
                        self.last_side_pt = Some((x, z));
                    }
                    self.last_t = Some(t_ns);
                    let line = &mut self.line;
                    line.x_m[len] = x;
                    line.z_m[len] = z;
                    line.tag[len] = p.tag;
                    line.len = len + 1;
                    return Offer::Taken;
                }
            }
        }
        self.offer_general(t_ns, p)
    }

    /// [`Self::offer`] on records still in their wire form (docs/wire-format.md, points
    /// packet), all with the packet's base time `base_time_ns`: takes the leading records
    /// that are on `offer`'s common path and returns how many it took. The record after
    /// them needs the full handling — a non-finite coordinate, a flag (line start or
    /// reserved), a time overflow (the ingest's checks), or any of `offer`'s other cases.
    /// The state `offer` keeps per point (previous point, side point, time, rotation vote,
    /// line length) stays in registers for the whole run instead of going through memory
    /// at every point; the rules and the arithmetic are `offer`'s, so the lines and every
    /// counter come out the same (tested against the general path).
    #[inline]
    pub fn take_run(&mut self, base_time_ns: u64, records: &[[u8; POINT_RECORD_LEN]]) -> usize {
        let start = self.line.len;
        if self.closed || self.reset || start == 0 || start >= N {
            return 0;
        }
        let (Some(lt), Some(last), Some(side)) = (self.last_t, self.last_pt, self.last_side_pt)
        else {
            return 0;
        };
        let Some(first) = records.first() else {
            return 0;
        };
        // Times as offsets from the packet's base in u32 (the wire's `dt`). With no record
        // of the packet past u64's end, base + dt never overflows (`checked_add`). The first
        // record's time is tested against `lt` in full; after it, `t ≥ lt && t − lt ≤ gap`
        // is `dt ≥ lo && dt − lo ≤ gap` with `lo` the previous record's `dt`.
        if base_time_ns > u64::MAX - u64::from(u32::MAX) {
            return 0;
        }
        let gap = self.params.gap_ns;
        let t0 =
            base_time_ns + u64::from(u32::from_le_bytes([first[0], first[1], first[2], first[3]]));
        if t0 < lt || t0 - lt > gap {
            return 0;
        }
        // `lt` ≥ base here (else `lo` = 0, which the first record passes: it passed above).
        let lo = u32::try_from(lt.saturating_sub(base_time_ns)).unwrap_or(u32::MAX);
        let run = Run {
            lo,
            gap: u32::try_from(gap).unwrap_or(u32::MAX),
            vote: self.vote,
            last,
            side,
        };
        let cap = (N - start).min(records.len());
        let line = &mut self.line;
        let out = (
            &mut line.x_m[start..start + cap],
            &mut line.z_m[start..start + cap],
            &mut line.tag[start..start + cap],
        );
        // The side (x′ > 0 or not) a point must keep: a point that keeps it and has
        // x′ ≠ 0 becomes the side point, which therefore keeps it too.
        let (k, run) = if side.0 > 0.0 {
            run.take::<true>(&records[..cap], out)
        } else {
            run.take::<false>(&records[..cap], out)
        };
        if k > 0 {
            line.len = start + k;
            self.vote = run.vote;
            self.last_pt = Some(run.last);
            self.last_side_pt = Some(run.side);
            self.last_t = Some(base_time_ns + u64::from(run.lo));
        }
        k
    }

    /// The rotation vote of the step from (xa, za) to (x, z).
    #[inline(always)]
    fn vote_on(&mut self, xa: f32, za: f32, x: f32, z: f32) {
        let c = xa * z - za * x;
        // Usually saturated in the stream's sense: then one compare and no store.
        if c > 0.0 {
            if self.vote < VOTE_CLAMP {
                self.vote += 1;
            }
        } else if c < 0.0 && self.vote > -VOTE_CLAMP {
            self.vote -= 1;
        }
    }

    /// [`Self::offer`] in full: every split rule and every state change.
    #[inline(never)]
    fn offer_general(&mut self, t_ns: u64, p: &PointRecord) -> Offer {
        if self.closed {
            self.line.clear();
            self.closed = false;
        }
        if self.line_has_points() {
            if p.line_start {
                self.complete(SplitReason::LineStart);
                return Offer::Split(SplitReason::LineStart);
            }
            if self
                .last_t
                .is_some_and(|lt| lt.abs_diff(t_ns) > self.params.gap_ns)
            {
                self.complete(SplitReason::TimeGap);
                return Offer::Split(SplitReason::TimeGap);
            }
            let geometric = match self.params.geometry {
                GeometrySplit::Auto => !self.seen_flag,
                GeometrySplit::Always => true,
                GeometrySplit::Never => false,
            };
            if geometric && self.armed && self.crossing(p.x_m, p.z_m) == Crossing::Zenith {
                self.complete(SplitReason::Zenith);
                return Offer::Split(SplitReason::Zenith);
            }
        }
        // Take the point.
        if self.reset {
            self.reset = false;
            self.last_t = None;
            self.last_pt = None;
            self.last_side_pt = None;
            self.armed = true;
        }
        self.seen_flag |= p.line_start;
        match self.crossing(p.x_m, p.z_m) {
            Crossing::Zenith => self.armed = false,
            Crossing::Nadir => self.armed = true,
            Crossing::None => {}
        }
        if let Some((xa, za)) = self.last_pt {
            self.vote_on(xa, za, p.x_m, p.z_m);
        }
        self.last_pt = Some((p.x_m, p.z_m));
        if p.x_m != 0.0 {
            self.last_side_pt = Some((p.x_m, p.z_m));
        }
        self.last_t = Some(t_ns);
        if !self.line_has_points() {
            self.line.index = self.next_index;
            self.line.start_time_ns = t_ns;
        }
        // Over capacity: Line::push counts the point in `truncated`.
        let _ = self.line.push(p.x_m, p.z_m, p.tag);
        Offer::Taken
    }
}

/// The state [`Assembler::take_run`] carries from point to point, in registers.
struct Run {
    /// `dt` of the previous record (the lower bound of the next one's).
    lo: u32,
    /// The split parameters' time gap, in the u32 of `dt`.
    gap: u32,
    vote: i32,
    /// The previous point (x′, z′).
    last: (f32, f32),
    /// The last point with x′ ≠ 0.
    side: (f32, f32),
}

impl Run {
    /// Takes records into `out` (x′, z′, tag; as long as `records`) while each is on
    /// `offer`'s common path on the side `RIGHT` (x′ > 0); returns how many. Out of line:
    /// inlined into the ingest's loop, its state did not fit the registers left there.
    #[inline(never)]
    fn take<const RIGHT: bool>(
        mut self,
        records: &[[u8; POINT_RECORD_LEN]],
        out: (&mut [f32], &mut [f32], &mut [u32]),
    ) -> (usize, Self) {
        let (xd, zd, td) = out;
        let mut k = 0;
        for (((rec, xo), zo), to) in records.iter().zip(xd).zip(zd).zip(td) {
            let word =
                |at: usize| u32::from_le_bytes([rec[at], rec[at + 1], rec[at + 2], rec[at + 3]]);
            // Field offsets as in `PointRecord::parse_array`: 0 dt, 4 x, 8 z, 12 intensity
            // and 14 flags, 16 tag.
            let (x, z) = (f32::from_bits(word(4)), f32::from_bits(word(8)));
            let dt = word(0);
            if !x.is_finite()
                || !z.is_finite()
                || word(12) >> 16 != 0
                || dt < self.lo
                || dt - self.lo > self.gap
                || (x > 0.0) != RIGHT
            {
                break;
            }
            let (xa, za) = self.last;
            let c = xa * z - za * x;
            if c > 0.0 {
                self.vote = (self.vote + 1).min(VOTE_CLAMP);
            } else if c < 0.0 {
                self.vote = (self.vote - 1).max(-VOTE_CLAMP);
            }
            self.last = (x, z);
            if x != 0.0 {
                self.side = (x, z);
            }
            self.lo = dt;
            *xo = x;
            *zo = z;
            *to = word(16);
            k += 1;
        }
        (k, self)
    }
}

impl<const N: usize> Default for Assembler<N> {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec::Vec;

    fn pt(x: f32, z: f32, tag: u32) -> PointRecord {
        PointRecord {
            dt_ns: 0,
            x_m: x,
            z_m: z,
            intensity: 0,
            line_start: false,
            tag,
        }
    }

    /// Scanner 2 m above a flat road, optional ceiling (tunnel) 3 m above it. Returns the
    /// points of `revs` revolutions, `per_rev` mirror steps each, starting at the zenith
    /// (the line boundary) and rotating counter-clockwise (`ccw`) or clockwise in the
    /// x′–z′ plane. Only directions that hit the road (or the ceiling) give returns,
    /// ranges up to 30 m.
    fn revolutions(
        revs: usize,
        per_rev: usize,
        ccw: bool,
        ceiling: bool,
    ) -> Vec<(u64, PointRecord, usize)> {
        let mut v = Vec::new();
        let mut tag = 0;
        for r in 0..revs {
            for k in 0..per_rev {
                // Angle from the zenith, offset by half a step so no ray is exactly vertical.
                let phi = (k as f64 + 0.5) / per_rev as f64 * std::f64::consts::TAU;
                let (s, c) = phi.sin_cos();
                // Direction: up = (0, 1); ccw rotation moves from up towards −x′ first.
                let dx = if ccw { -s } else { s };
                let dz = c;
                let range = if dz < -1e-9 {
                    2.0 / -dz
                } else if ceiling && dz > 1e-9 {
                    3.0 / dz
                } else {
                    f64::INFINITY
                };
                if range <= 30.0 {
                    let t = (r * per_rev + k) as u64 * 10_000; // 10 µs per step
                    v.push((t, pt((dx * range) as f32, (dz * range) as f32, tag), r));
                    tag += 1;
                }
            }
        }
        v
    }

    /// Feeds points; returns (first tag, length, revolution of first point) of completed
    /// lines, flushing the last one.
    fn run<const N: usize>(
        a: &mut Assembler<N>,
        pts: &[(u64, PointRecord, usize)],
    ) -> Vec<(u32, usize)> {
        let mut lines = Vec::new();
        for (t, p, _) in pts {
            if let Offer::Split(_) = a.offer(*t, p) {
                lines.push((a.line().tag[0], a.line().len()));
                assert_eq!(a.offer(*t, p), Offer::Taken);
            }
        }
        if a.close(SplitReason::End) {
            lines.push((a.line().tag[0], a.line().len()));
        }
        lines
    }

    /// The fast path of `offer` decides exactly as the general rules: two assemblers fed
    /// the same odd stream (flags, time gaps both ways, side changes, x′ = 0, points over
    /// capacity, closes), one through `offer`, one through `offer_general` only, give the
    /// same answers, lines and counters.
    #[test]
    fn fast_path_is_the_general_rules() {
        let mut r = 7u64;
        let mut u = || {
            r = r
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((r >> 40) as f32) / ((1u64 << 24) as f32)
        };
        for geometry in [
            GeometrySplit::Auto,
            GeometrySplit::Always,
            GeometrySplit::Never,
        ] {
            let mut a = Assembler::<64>::new();
            let mut b = Assembler::<64>::new();
            let params = SplitParams {
                gap_ns: 5_000,
                geometry,
            };
            a.set_params(params);
            b.set_params(params);
            let mut t = 1_000_000u64;
            let (mut fast, mut splits) = (0, 0);
            for k in 0..20_000u32 {
                let v = u();
                t = if v < 0.01 {
                    t + 10_000 // gap
                } else if v < 0.015 {
                    t - 20_000 // jump back
                } else {
                    t + 1_000
                };
                let ang = u() * 6.3;
                let mut p = pt(5.0 * libm::sinf(ang), 5.0 * libm::cosf(ang), k);
                if u() < 0.05 {
                    p.x_m = 0.0;
                }
                p.line_start = u() < 0.002;
                if u() < 0.001 {
                    assert_eq!(a.close(SplitReason::SeqGap), b.close(SplitReason::SeqGap));
                }
                let before = (a.closed, a.reset, a.line.len);
                let ra = a.offer(t, &p);
                let rb = b.offer_general(t, &p);
                assert_eq!(ra, rb, "point {k}");
                if !before.0 && !before.1 && before.2 > 0 && ra == Offer::Taken {
                    fast += 1;
                }
                if let Offer::Split(_) = ra {
                    splits += 1;
                    assert_eq!(a.line.len, b.line.len);
                    assert_eq!(a.line.x_m[..a.line.len], b.line.x_m[..b.line.len]);
                    assert_eq!(a.line.tag[..a.line.len], b.line.tag[..b.line.len]);
                    assert_eq!(a.offer(t, &p), b.offer_general(t, &p));
                }
                assert_eq!(a.counters(), b.counters(), "point {k}");
                assert_eq!(a.rotation_sense(), b.rotation_sense());
            }
            assert!(
                fast > 10_000 && splits > 50,
                "{geometry:?}: {fast} {splits}"
            );
        }
    }

    /// `take_run` takes exactly the points `offer` would take on its common path, with the
    /// same state after them: two assemblers fed the same odd stream (flags, reserved
    /// flags, non-finite coordinates, time gaps both ways, side changes, x′ = 0, points over
    /// capacity, closes), one in runs of wire records through `take_run` with
    /// `offer_general` for the record a run stops at, one through `offer_general` only,
    /// give the same lines, counters and rotation sense.
    #[test]
    fn take_run_is_the_general_rules() {
        let mut r = 11u64;
        let mut u = || {
            r = r
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((r >> 40) as f32) / ((1u64 << 24) as f32)
        };
        let base = 1_000_000u64;
        let (mut in_runs, mut splits) = (0, 0);
        for geometry in [
            GeometrySplit::Auto,
            GeometrySplit::Always,
            GeometrySplit::Never,
        ] {
            let mut a = Assembler::<64>::new();
            let mut b = Assembler::<64>::new();
            let params = SplitParams {
                gap_ns: 5_000,
                geometry,
            };
            a.set_params(params);
            b.set_params(params);
            let mut dt = 0u32;
            // Records with what each means to the ingest: None = dropped before assembly.
            let mut recs: Vec<[u8; POINT_RECORD_LEN]> = Vec::new();
            let mut meaning: Vec<Option<PointRecord>> = Vec::new();
            for k in 0..20_000u32 {
                let v = u();
                dt = if v < 0.01 {
                    dt + 10_000
                } else if v < 0.015 {
                    dt.saturating_sub(20_000)
                } else {
                    dt + 1_000
                };
                let ang = u() * 6.3;
                let mut p = pt(5.0 * libm::sinf(ang), 5.0 * libm::cosf(ang), k);
                p.dt_ns = dt;
                if u() < 0.05 {
                    p.x_m = 0.0;
                }
                p.line_start = u() < 0.002;
                let mut rec = [0u8; POINT_RECORD_LEN];
                p.emit(&mut rec, 0).unwrap();
                let odd = u();
                if odd < 0.002 {
                    rec[4..8].copy_from_slice(&f32::NAN.to_le_bytes());
                } else if odd < 0.004 {
                    rec[15] = 0x80;
                } else if odd < 0.006 {
                    rec[0..4].copy_from_slice(&u32::MAX.to_le_bytes());
                }
                meaning.push(PointRecord::parse_array(&rec).ok());
                recs.push(rec);
            }
            // Near the end of u64's range the last records' times overflow.
            let base = if geometry == GeometrySplit::Never {
                u64::MAX - 15_000_000
            } else {
                base
            };
            let mut i = 0;
            while i < recs.len() {
                if u() < 0.001 {
                    assert_eq!(a.close(SplitReason::SeqGap), b.close(SplitReason::SeqGap));
                }
                let end = (i + 1 + (u() * 100.0) as usize).min(recs.len());
                let k = a.take_run(base, &recs[i..end]);
                for (j, m) in meaning[i..i + k].iter().enumerate() {
                    let p = m.expect("take_run takes only valid records");
                    let t = base.checked_add(u64::from(p.dt_ns)).expect("in range");
                    assert_eq!(b.offer_general(t, &p), Offer::Taken, "record {}", i + j);
                }
                in_runs += k;
                i += k;
                if i == end {
                    continue;
                }
                // The record the run stopped at, as the ingest handles it.
                if let Some(p) = meaning[i] {
                    if let Some(t) = base.checked_add(u64::from(p.dt_ns)) {
                        let (ra, rb) = (a.offer(t, &p), b.offer_general(t, &p));
                        assert_eq!(ra, rb, "record {i}");
                        if let Offer::Split(_) = ra {
                            splits += 1;
                            assert_eq!(a.line.len, b.line.len);
                            assert_eq!(a.line.x_m[..a.line.len], b.line.x_m[..b.line.len]);
                            assert_eq!(a.line.z_m[..a.line.len], b.line.z_m[..b.line.len]);
                            assert_eq!(a.line.tag[..a.line.len], b.line.tag[..b.line.len]);
                            assert_eq!(a.offer(t, &p), b.offer_general(t, &p));
                        }
                    }
                }
                i += 1;
                assert_eq!(a.counters(), b.counters(), "record {i}");
                assert_eq!(a.rotation_sense(), b.rotation_sense());
                assert_eq!(
                    (a.last_t, a.last_pt, a.last_side_pt),
                    (b.last_t, b.last_pt, b.last_side_pt)
                );
            }
            assert_eq!(a.close(SplitReason::End), b.close(SplitReason::End));
            assert_eq!(a.line.len, b.line.len);
            assert_eq!(a.line.tag[..a.line.len], b.line.tag[..b.line.len]);
            assert_eq!(a.counters(), b.counters());
        }
        assert!(in_runs > 15_000 && splits > 1_000, "{in_runs} {splits}");
    }

    /// Every combination of rotation direction and returns above: one line per revolution,
    /// each starting with the revolution's first return.
    #[test]
    fn splits_once_per_revolution_both_directions_with_and_without_returns_above() {
        for ccw in [true, false] {
            for ceiling in [true, false] {
                let pts = revolutions(5, 720, ccw, ceiling);
                let mut a = Assembler::<2048>::new();
                let lines = run(&mut a, &pts);
                let firsts: Vec<u32> = (0..5)
                    .map(|r| pts.iter().find(|p| p.2 == r).unwrap().1.tag)
                    .collect();
                let got: Vec<u32> = lines.iter().map(|l| l.0).collect();
                assert_eq!(got, firsts, "ccw={ccw} ceiling={ceiling}");
                assert_eq!(a.rotation_sense(), if ccw { 1 } else { -1 });
                let c = a.counters();
                assert_eq!(c.split_zenith, 4);
                assert_eq!(c.points_in_lines as usize, pts.len());
                // Without a ceiling only ±86° around the nadir return: the open-sky case.
                if !ceiling {
                    assert!(pts.iter().all(|p| p.1.z_m < 0.0));
                }
            }
        }
    }

    #[test]
    fn nadir_jitter_and_overhead_jitter_do_not_split() {
        let mut a = Assembler::<64>::new();
        // Learn clockwise rotation (left → right under the scanner).
        let mut t = 0;
        let mut feed = |a: &mut Assembler<64>, x: f32, z: f32| {
            t += 1000;
            a.offer(t, &pt(x, z, 0))
        };
        for i in 0..20 {
            assert_eq!(feed(&mut a, 2.0 - 0.1 * i as f32, -2.0), Offer::Taken);
        }
        assert_eq!(a.rotation_sense(), -1);
        // Jitter back and forth across the nadir.
        for x in [-0.05, 0.05, -0.05, 0.04, -0.1] {
            assert_eq!(feed(&mut a, x, -2.0), Offer::Taken);
        }
        // Up the right side, over the top with returns (a wire that jitters).
        for i in 0..20 {
            assert_eq!(feed(&mut a, -2.0, -2.0 + 0.3 * i as f32), Offer::Taken);
        }
        assert_eq!(feed(&mut a, -0.1, 5.0), Offer::Taken);
        assert_eq!(feed(&mut a, 0.1, 5.0), Offer::Split(SplitReason::Zenith));
        assert_eq!(feed(&mut a, 0.1, 5.0), Offer::Taken);
        assert_eq!(
            feed(&mut a, -0.1, 5.0),
            Offer::Taken,
            "back over the top: disarmed"
        );
        assert_eq!(feed(&mut a, 0.12, 5.0), Offer::Taken, "still disarmed");
        assert_eq!(a.counters().split_zenith, 1);
    }

    #[test]
    fn flags_and_time_gaps() {
        let mut a = Assembler::<8>::new();
        let mut p = pt(1.0, -2.0, 1);
        assert_eq!(a.offer(0, &p), Offer::Taken);
        assert_eq!(a.offer(1_000, &p), Offer::Taken);
        // A gap of exactly gap_ns is not a split; one more ns is.
        assert_eq!(a.offer(5_001_000, &p), Offer::Taken);
        assert_eq!(a.offer(10_001_001, &p), Offer::Split(SplitReason::TimeGap));
        assert_eq!(a.line().len(), 3);
        assert_eq!(a.line().start_time_ns, 0);
        assert_eq!(a.offer(10_001_001, &p), Offer::Taken);
        assert_eq!(a.line().index, 1);
        assert_eq!(a.line().start_time_ns, 10_001_001);
        p.line_start = true;
        assert_eq!(
            a.offer(10_002_000, &p),
            Offer::Split(SplitReason::LineStart)
        );
        assert_eq!(a.offer(10_002_000, &p), Offer::Taken);
        // After a flag, Auto mode ignores geometry: crossing over the top is no split.
        for (x, z) in [(1.0, 5.0), (-1.0, 5.0), (1.0, 5.0)] {
            assert_eq!(a.offer(10_003_000, &pt(x, z, 2)), Offer::Taken);
        }
        let c = a.counters();
        assert_eq!((c.lines, c.split_time_gap, c.split_line_start), (2, 1, 1));
    }

    #[test]
    fn line_overflow_is_counted_and_still_splits() {
        let mut a = Assembler::<4>::new();
        let mut p = pt(1.0, -2.0, 0);
        for i in 0..10 {
            p.tag = i;
            assert_eq!(a.offer(u64::from(i), &p), Offer::Taken);
        }
        assert_eq!((a.line().len(), a.line().truncated), (4, 6));
        assert_eq!(&a.line().tag[..4], &[0, 1, 2, 3]);
        assert_eq!(a.pending_points(), 10);
        p.line_start = true;
        assert_eq!(a.offer(11, &p), Offer::Split(SplitReason::LineStart));
        let c = a.counters();
        assert_eq!(
            (c.points_in_lines, c.points_truncated, c.lines_truncated),
            (4, 6, 1)
        );
        assert_eq!(a.offer(11, &p), Offer::Taken);
        assert_eq!((a.line().len(), a.line().truncated), (1, 0));
        // A zero-capacity line counts everything as truncated and never panics.
        let mut z = Assembler::<0>::new();
        assert_eq!(z.offer(0, &p), Offer::Taken);
        assert!(z.close(SplitReason::End));
        assert_eq!(z.counters().points_truncated, 1);
    }
}
