//! [`Ingest`]: ring + packet parser + assembler — bytes in, scanlines and config blocks out.
//!
//! Packets are parsed where they lie in the ring (two-slice aware, no linearisation
//! buffer): the CRC runs over the two halves, the header and each 20-byte point record are
//! copied out one at a time. A points packet stays in the ring until its last record has
//! been assembled, so the point that starts the next line simply waits there while the
//! caller holds the completed line.

use super::assemble::{AssembleCounters, Assembler, Offer, SplitParams, SplitReason};
use super::ring::Ring;
use super::Line;
use crate::wire::{
    config_version, flags_version, scan_two, Error as WireError, GarbageReason, Packet, PacketKind,
    PointRecord, Scan, CONFIG_WORDS, FLAG_LINK_CHECKED, HEADER_LEN, MAX_PACKET_LEN,
    POINTS_PREFIX_LEN, POINT_RECORD_LEN, VERSION, VERSION_1,
};

/// What [`Ingest::poll`] produced.
pub enum IngestEvent<'a, const N: usize> {
    /// A config packet's parameter words (the kernel gives them meaning). Any line in
    /// progress was completed and delivered before this event.
    Config([u32; CONFIG_WORDS]),
    /// A complete scanline. It stays valid (and may be processed in place) until the next
    /// call of [`Ingest::poll`].
    Line(&'a mut Line<N>),
}

impl<const N: usize> core::fmt::Debug for IngestEvent<'_, N> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Config(w) => f.debug_tuple("Config").field(w).finish(),
            Self::Line(l) => f
                .debug_struct("Line")
                .field("index", &l.index)
                .field("len", &l.len)
                .field("truncated", &l.truncated)
                .finish(),
        }
    }
}

/// Every byte and every point that entered, accounted for.
///
/// - bytes: `bytes_in = bytes_dropped_full + bytes_garbage + bytes_rejected +
///   bytes_packets + bytes_buffered`;
/// - points: `points_in = points_non_finite + points_reserved_flags +
///   points_time_overflow + points_in_lines + points_truncated + points_pending`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct IngestCounters {
    /// Bytes offered to [`Ingest::write`] (or committed after a DMA fill).
    pub bytes_in: u64,
    /// Bytes refused because the ring was full.
    pub bytes_dropped_full: u64,
    /// Bytes skipped while resynchronising (no sync word, bad length, CRC failure, cut off
    /// at the end of the stream).
    pub bytes_garbage: u64,
    /// Bytes of CRC-valid packets that were rejected (version, kind, length for the kind,
    /// reserved flags) or are not for the core (output packets).
    pub bytes_rejected: u64,
    /// Bytes of accepted points and config packets.
    pub bytes_packets: u64,
    /// Bytes in the ring, not yet parsed.
    pub bytes_buffered: u64,
    /// Sync words whose packet failed the CRC.
    pub crc_errors: u64,
    /// Sync words with a length field outside `MIN_PACKET_LEN..=MAX_PACKET_LEN`.
    pub bad_length: u64,
    /// Sync words whose packet was cut off by the end of the stream.
    pub cut_at_end: u64,
    /// CRC-valid packets of another version.
    pub bad_version: u64,
    /// CRC-valid packets of an unknown kind.
    pub bad_kind: u64,
    /// CRC-valid packets whose length does not fit their kind.
    pub bad_kind_length: u64,
    /// CRC-valid packets with reserved header flags set.
    pub reserved_flags: u64,
    /// Output packets in the input stream (ignored).
    pub output_ignored: u64,
    /// Points packets accepted.
    pub packets_points: u64,
    /// Config packets accepted.
    pub packets_config: u64,
    /// Sequence-number discontinuities (forward jumps and restarts).
    pub seq_gaps: u64,
    /// Packets missing according to forward sequence jumps.
    pub packets_missing: u64,
    /// Point records read from accepted packets.
    pub points_in: u64,
    /// Records dropped: x′ or z′ NaN or infinite.
    pub points_non_finite: u64,
    /// Records dropped: reserved flag bits set.
    pub points_reserved_flags: u64,
    /// Records dropped: base time + dt overflows 64 bits.
    pub points_time_overflow: u64,
    /// Points in the line being assembled.
    pub points_pending: u64,
    /// Points stored in completed lines.
    pub points_in_lines: u64,
    /// Points dropped because their line was over capacity.
    pub points_truncated: u64,
    /// Lines completed.
    pub lines: u64,
    /// Lines completed with truncated points.
    pub lines_truncated: u64,
    /// Line ends by reason (flag, zenith crossing, time gap, sequence gap, config, end).
    pub split_line_start: u64,
    /// See `split_line_start`.
    pub split_zenith: u64,
    /// See `split_line_start`.
    pub split_time_gap: u64,
    /// See `split_line_start`.
    pub split_seq_gap: u64,
    /// See `split_line_start`.
    pub split_config: u64,
    /// See `split_line_start`.
    pub split_end: u64,
}

impl IngestCounters {
    /// All zero (`const`, unlike `Default::default`).
    pub const ZERO: Self = IngestCounters {
        bytes_in: 0,
        bytes_dropped_full: 0,
        bytes_garbage: 0,
        bytes_rejected: 0,
        bytes_packets: 0,
        bytes_buffered: 0,
        crc_errors: 0,
        bad_length: 0,
        cut_at_end: 0,
        bad_version: 0,
        bad_kind: 0,
        bad_kind_length: 0,
        reserved_flags: 0,
        output_ignored: 0,
        packets_points: 0,
        packets_config: 0,
        seq_gaps: 0,
        packets_missing: 0,
        points_in: 0,
        points_non_finite: 0,
        points_reserved_flags: 0,
        points_time_overflow: 0,
        points_pending: 0,
        points_in_lines: 0,
        points_truncated: 0,
        lines: 0,
        lines_truncated: 0,
        split_line_start: 0,
        split_zenith: 0,
        split_time_gap: 0,
        split_seq_gap: 0,
        split_config: 0,
        split_end: 0,
    };
}

/// The points packet being read at the front of the ring.
#[derive(Clone, Copy, Debug)]
struct Current {
    len: usize,
    base_time_ns: u64,
    count: usize,
    next: usize,
}

/// One step of the state machine behind [`Ingest::poll`].
enum Step {
    Continue,
    Idle,
    Line,
    Config([u32; CONFIG_WORDS]),
}

/// Ring of `RING` bytes + parser + assembler of lines of up to `N` points.
// `repr(C)`, the small state first, then the assembler (its per-point state leads it),
// the ring's bytes last: the per-point path reaches every field it touches with an
// immediate offset on the Cortex-M4F instead of building each offset first.
#[repr(C)]
pub struct Ingest<const RING: usize, const N: usize> {
    cur: Option<Current>,
    next_seq: Option<u32>,
    finishing: bool,
    pending_config: Option<[u32; CONFIG_WORDS]>,
    c: IngestCounters,
    asm: Assembler<N>,
    ring: Ring<RING>,
}

impl<const RING: usize, const N: usize> Ingest<RING, N> {
    const RING_OK: () = assert!(
        RING >= MAX_PACKET_LEN,
        "the ring must hold the largest packet"
    );

    /// An empty ingest with [`SplitParams::DEFAULT`].
    pub const fn new() -> Self {
        let () = Self::RING_OK;
        Self {
            ring: Ring::new(),
            asm: Assembler::new(),
            cur: None,
            pending_config: None,
            next_seq: None,
            finishing: false,
            c: IngestCounters::ZERO,
        }
    }

    /// The ingest [`Ingest::new`] gives, without rewriting the ring's bytes or the line's
    /// arrays.
    pub fn restart(&mut self) {
        let Self {
            cur,
            next_seq,
            finishing,
            pending_config,
            c,
            asm,
            ring,
        } = self;
        (*cur, *next_seq, *finishing, *pending_config) = (None, None, false, None);
        *c = IngestCounters::ZERO;
        asm.restart();
        ring.restart();
    }

    /// Sets the line-splitting parameters (from the next point on).
    pub fn set_split_params(&mut self, params: SplitParams) {
        self.asm.set_params(params);
    }
    /// The line-splitting parameters in force.
    pub fn split_params(&self) -> SplitParams {
        self.asm.params()
    }

    /// Appends bytes of the stream; returns how many were accepted. When the ring is full,
    /// the rest is counted in `bytes_dropped_full` (poll, then offer them again if the
    /// source can repeat them).
    pub fn write(&mut self, bytes: &[u8]) -> usize {
        self.c.bytes_in += bytes.len() as u64;
        self.ring.write(bytes)
    }

    /// The ring's free space for a DMA engine or a `read()` call; follow with
    /// [`Self::commit`].
    pub fn free_slices_mut(&mut self) -> (&mut [u8], &mut [u8]) {
        self.ring.free_slices_mut()
    }

    /// Marks `n` bytes written through [`Self::free_slices_mut`] as received; returns the
    /// bytes that fit.
    pub fn commit(&mut self, n: usize) -> usize {
        self.c.bytes_in += n as u64;
        self.ring.commit(n)
    }

    /// Bytes in the ring.
    pub fn buffered(&self) -> usize {
        self.ring.len()
    }

    /// End of stream: the following polls deliver what is complete, skip a cut-off last
    /// packet as garbage and then deliver the partial last line. Afterwards the ingest
    /// accepts a new stream (the next point is not compared with the last one).
    pub fn finish(&mut self) {
        self.finishing = true;
    }

    /// All counters.
    pub fn counters(&self) -> IngestCounters {
        let a: AssembleCounters = self.asm.counters();
        IngestCounters {
            bytes_dropped_full: self.ring.dropped(),
            bytes_buffered: self.ring.len() as u64,
            points_pending: self.asm.pending_points(),
            points_in_lines: a.points_in_lines,
            points_truncated: a.points_truncated,
            lines: a.lines,
            lines_truncated: a.lines_truncated,
            split_line_start: a.split_line_start,
            split_zenith: a.split_zenith,
            split_time_gap: a.split_time_gap,
            split_seq_gap: a.split_seq_gap,
            split_config: a.split_config,
            split_end: a.split_end,
            ..self.c
        }
    }

    /// A point given directly instead of in a points packet (at absolute time `t_ns`; its
    /// `dt_ns` is not read): counted and assembled as a parsed record of the ring is, a
    /// non-finite x′ or z′ counted and dropped. Returns the line the point completes, which
    /// stays valid until the next call; offer the same point again until it returns `None`
    /// (the point then opens or continues the next line). The ring must be empty, with
    /// no packet being read: a stream is fed either as bytes or point by point.
    #[inline]
    pub fn offer_point(&mut self, t_ns: u64, p: &PointRecord) -> Option<&mut Line<N>> {
        debug_assert!(self.cur.is_none() && self.ring.is_empty());
        if !p.x_m.is_finite() || !p.z_m.is_finite() {
            self.c.points_in += 1;
            self.c.points_non_finite += 1;
            return None;
        }
        match self.asm.offer(t_ns, p) {
            Offer::Taken => {
                self.c.points_in += 1;
                None
            }
            Offer::Split(_) => Some(self.asm.line_mut()),
        }
    }

    /// Ends the line being assembled from outside (as a config packet does, for
    /// [`Self::offer_point`]'s callers); returns it if it held points.
    pub fn close_line(&mut self, reason: SplitReason) -> Option<&mut Line<N>> {
        if self.asm.close(reason) {
            Some(self.asm.line_mut())
        } else {
            None
        }
    }

    /// The next event: a complete line, a config block, or `None` when more bytes are
    /// needed (or, after [`Self::finish`], when everything has been delivered).
    pub fn poll(&mut self) -> Option<IngestEvent<'_, N>> {
        loop {
            match self.step() {
                Step::Continue => {}
                Step::Idle => return None,
                Step::Config(w) => return Some(IngestEvent::Config(w)),
                Step::Line => break,
            }
        }
        Some(IngestEvent::Line(self.asm.line_mut()))
    }

    fn step(&mut self) -> Step {
        if let Some(mut cur) = self.cur {
            // The ring does not change while its records are assembled: split it once.
            // `points_in` counts every record taken off (`cur.next` advanced), added up
            // once at the end of the loop rather than per point.
            let (a, b) = self.ring.as_slices();
            let first = cur.next;
            while cur.next < cur.count {
                let at = HEADER_LEN + POINTS_PREFIX_LEN + cur.next * POINT_RECORD_LEN;
                // Most records continue the open line: the assembler takes those in runs
                // straight from the ring; the one a run stops at goes the full way below.
                if let Some(tail) = a.get(at..) {
                    let (records, _) = tail.as_chunks::<POINT_RECORD_LEN>();
                    let records = &records[..records.len().min(cur.count - cur.next)];
                    let taken = self.asm.take_run(cur.base_time_ns, records);
                    if taken > 0 {
                        cur.next += taken;
                        continue;
                    }
                }
                // Parse in place when the record is contiguous; copy it out only when it
                // straddles the ring's seam. The scanner checked the packet is all there.
                let parsed = match a.get(at..).and_then(|r| r.first_chunk()) {
                    Some(rec) => PointRecord::parse_array(rec),
                    None => {
                        let mut rec = [0u8; POINT_RECORD_LEN];
                        let _ = crate::wire::copy_from_two(a, b, at, &mut rec);
                        PointRecord::parse_array(&rec)
                    }
                };
                let p = match parsed {
                    Ok(p) => p,
                    Err(e) => {
                        cur.next += 1;
                        match e {
                            WireError::NonFinite { .. } => self.c.points_non_finite += 1,
                            _ => self.c.points_reserved_flags += 1,
                        }
                        continue;
                    }
                };
                let Some(t) = cur.base_time_ns.checked_add(u64::from(p.dt_ns)) else {
                    cur.next += 1;
                    self.c.points_time_overflow += 1;
                    continue;
                };
                match self.asm.offer(t, &p) {
                    Offer::Taken => cur.next += 1,
                    Offer::Split(_) => {
                        self.c.points_in += (cur.next - first) as u64;
                        self.cur = Some(cur);
                        return Step::Line;
                    }
                }
            }
            self.c.points_in += (cur.next - first) as u64;
            self.ring.consume(cur.len);
            self.c.bytes_packets += cur.len as u64;
            self.cur = None;
        }
        if let Some(w) = self.pending_config.take() {
            return Step::Config(w);
        }
        let (a, b) = self.ring.as_slices();
        match scan_two(a, b, self.finishing) {
            Scan::Empty | Scan::Incomplete => {
                if self.finishing {
                    self.finishing = false;
                    self.next_seq = None;
                    if self.asm.close(SplitReason::End) {
                        return Step::Line;
                    }
                }
                Step::Idle
            }
            Scan::Garbage { len, reason } => {
                let n = self.ring.consume(len);
                self.c.bytes_garbage += n as u64;
                match reason {
                    GarbageReason::NoSync => {}
                    GarbageReason::BadLength => self.c.bad_length += 1,
                    GarbageReason::Crc => self.c.crc_errors += 1,
                    GarbageReason::Truncated => self.c.cut_at_end += 1,
                }
                Step::Continue
            }
            Scan::Packet { len } => self.accept(len),
        }
    }

    /// Handles a CRC-valid packet of `len` bytes at the front of the ring.
    fn accept(&mut self, len: usize) -> Step {
        let mut hdr = [0u8; HEADER_LEN + POINTS_PREFIX_LEN];
        let _ = self.ring.peek(0, &mut hdr[..HEADER_LEN.min(len)]);
        let view = Packet::new_unchecked(&hdr[..]);
        let kind = view.kind();
        let reject = |s: &mut Self, counter: fn(&mut IngestCounters)| {
            s.ring.consume(len);
            s.c.bytes_rejected += len as u64;
            counter(&mut s.c);
            Step::Continue
        };
        let version = view.version();
        if version.wrapping_sub(VERSION_1) > VERSION - VERSION_1 {
            return reject(self, |c| c.bad_version += 1);
        }
        let Some(kind) = kind else {
            return reject(self, |c| c.bad_kind += 1);
        };
        let flags_v = flags_version(view.flags());
        if !(kind.min_version().max(flags_v)..=kind.max_version().max(flags_v)).contains(&version) {
            return reject(self, |c| c.bad_version += 1);
        }
        if !kind.length_ok(len) {
            return reject(self, |c| c.bad_kind_length += 1);
        }
        if view.flags() & !FLAG_LINK_CHECKED != 0 {
            return reject(self, |c| c.reserved_flags += 1);
        }
        // Sequence numbers: a discontinuity may have swallowed a line boundary.
        let seq = view.seq();
        let mut gap = false;
        if let Some(expected) = self.next_seq {
            if seq != expected {
                gap = true;
                self.c.seq_gaps += 1;
                let missing = seq.wrapping_sub(expected);
                if missing < 0x8000_0000 {
                    self.c.packets_missing += u64::from(missing);
                }
            }
        }
        self.next_seq = Some(seq.wrapping_add(1));
        match kind {
            PacketKind::Points => {
                let _ = self.ring.peek(0, &mut hdr);
                let view = Packet::new_unchecked(&hdr[..]);
                self.c.packets_points += 1;
                self.cur = Some(Current {
                    len,
                    base_time_ns: view.base_time_ns(),
                    count: (len - HEADER_LEN - POINTS_PREFIX_LEN - crate::wire::CRC_LEN)
                        / POINT_RECORD_LEN,
                    next: 0,
                });
                if gap && self.asm.close(SplitReason::SeqGap) {
                    return Step::Line;
                }
                Step::Continue
            }
            PacketKind::Config => {
                let mut words = [0u32; CONFIG_WORDS];
                for (i, w) in words.iter_mut().enumerate() {
                    let mut b = [0u8; 4];
                    let _ = self.ring.peek(HEADER_LEN + 4 * i, &mut b);
                    *w = u32::from_le_bytes(b);
                }
                if version != config_version(&words).max(flags_v) {
                    return reject(self, |c| c.bad_version += 1);
                }
                self.ring.consume(len);
                self.c.bytes_packets += len as u64;
                self.c.packets_config += 1;
                // A gap closes the line (or, if it is empty, makes the next point start
                // afresh); otherwise the config does.
                if (gap && self.asm.close(SplitReason::SeqGap))
                    || self.asm.close(SplitReason::Config)
                {
                    self.pending_config = Some(words);
                    return Step::Line;
                }
                Step::Config(words)
            }
            PacketKind::Output | PacketKind::Candidates => {
                self.ring.consume(len);
                self.c.bytes_rejected += len as u64;
                self.c.output_ignored += 1;
                if gap && self.asm.close(SplitReason::SeqGap) {
                    return Step::Line;
                }
                Step::Continue
            }
        }
    }
}

impl<const RING: usize, const N: usize> Default for Ingest<RING, N> {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::wire::{OutputHeaderRepr, StreamEncoder, CONFIG_PACKET_LEN, MAX_POINTS_PER_PACKET};
    use std::vec::Vec;

    fn pt(i: u32, line_start: bool) -> PointRecord {
        PointRecord {
            dt_ns: i * 1000,
            x_m: 1.0 + i as f32 * 0.01,
            z_m: -2.0,
            intensity: 0,
            line_start,
            tag: i,
        }
    }

    /// A stream: config, then `lines` flagged lines of `per_line` points in packets of
    /// `per_packet`, 1 ms base-time steps per packet.
    fn stream(lines: u32, per_line: u32, per_packet: usize) -> Vec<u8> {
        let mut enc = StreamEncoder::new();
        let mut out = Vec::new();
        let mut buf = [0u8; MAX_PACKET_LEN];
        let n = enc.encode_config(&[9; CONFIG_WORDS], &mut buf).unwrap();
        out.extend_from_slice(&buf[..n]);
        let pts: Vec<PointRecord> = (0..lines * per_line)
            .map(|i| PointRecord {
                tag: i,
                ..pt(i % per_line, i % per_line == 0)
            })
            .collect();
        for (k, chunk) in pts.chunks(per_packet).enumerate() {
            let n = enc
                .encode_points(k as u64 * 1_000_000, chunk, &mut buf)
                .unwrap();
            out.extend_from_slice(&buf[..n]);
        }
        out
    }

    /// Drains all events: (config blocks seen, lines as (index, first tag, len, truncated)).
    fn drain<const R: usize, const N: usize>(
        ing: &mut Ingest<R, N>,
    ) -> (usize, Vec<(u32, u32, usize, u32)>) {
        let mut configs = 0;
        let mut lines = Vec::new();
        while let Some(ev) = ing.poll() {
            match ev {
                IngestEvent::Config(w) => {
                    assert_eq!(w, [9; CONFIG_WORDS]);
                    configs += 1;
                }
                IngestEvent::Line(l) => {
                    lines.push((l.index, l.tag[0], l.len(), l.truncated));
                    // The kernel may scribble on the line in place.
                    l.x_m[0] = f32::NAN;
                }
            }
        }
        (configs, lines)
    }

    fn check_balance<const R: usize, const N: usize>(ing: &Ingest<R, N>) {
        let c = ing.counters();
        assert_eq!(
            c.bytes_in,
            c.bytes_dropped_full
                + c.bytes_garbage
                + c.bytes_rejected
                + c.bytes_packets
                + c.bytes_buffered,
            "{c:?}"
        );
        assert_eq!(
            c.points_in,
            c.points_non_finite
                + c.points_reserved_flags
                + c.points_time_overflow
                + c.points_in_lines
                + c.points_truncated
                + c.points_pending,
            "{c:?}"
        );
    }

    #[test]
    fn whole_stream_in_one_write() {
        let s = stream(3, 100, 30);
        let mut ing = Ingest::<4096, 128>::new();
        let mut fed = 0;
        let mut all = (0, Vec::new());
        while fed < s.len() {
            fed += ing.write(&s[fed..]);
            let (c, l) = drain(&mut ing);
            all.0 += c;
            all.1.extend(l);
            check_balance(&ing);
        }
        ing.finish();
        all.1.extend(drain(&mut ing).1);
        check_balance(&ing);
        assert_eq!(all.0, 1);
        assert_eq!(all.1, [(0, 0, 100, 0), (1, 100, 100, 0), (2, 200, 100, 0)]);
        let c = ing.counters();
        assert_eq!((c.split_line_start, c.split_end), (2, 1));
        assert_eq!((c.bytes_garbage, c.seq_gaps, c.points_in), (0, 0, 300));
        assert_eq!(c.bytes_packets, s.len() as u64);
        // After the end, nothing more.
        assert!(ing.poll().is_none());
    }

    /// Frames cut at every possible byte across the ring's wrap: the ring's read position
    /// is moved to every offset before a stream of packets arrives, and the stream is fed in
    /// pieces of every size from 1 byte up.
    #[test]
    fn frames_cut_at_every_byte_across_the_wrap() {
        let s = stream(2, 40, 20); // config 80 B + 4 packets of 424 B
        const R: usize = 1500;
        let expected = [(0, 0, 40, 0), (1, 40, 40, 0)];
        for offset in 0..R {
            for piece in [1usize, 3, 13, 424, 1499] {
                let mut ing = Ingest::<R, 64>::new();
                // Garbage without sync bytes moves the read position to `offset`.
                let filler = std::vec![0u8; offset];
                assert_eq!(ing.write(&filler), offset);
                assert!(ing.poll().is_none());
                assert_eq!(ing.buffered(), 0);
                let mut lines = Vec::new();
                let mut configs = 0;
                let mut fed = 0;
                while fed < s.len() {
                    let end = (fed + piece).min(s.len());
                    fed += ing.write(&s[fed..end]);
                    let (c, l) = drain(&mut ing);
                    configs += c;
                    lines.extend(l);
                }
                ing.finish();
                lines.extend(drain(&mut ing).1);
                assert_eq!(
                    (configs, &lines[..]),
                    (1, &expected[..]),
                    "offset {offset} piece {piece}"
                );
                let c = ing.counters();
                assert_eq!(c.bytes_garbage, offset as u64);
                assert_eq!(c.bytes_dropped_full, 0);
                check_balance(&ing);
            }
        }
    }

    #[test]
    fn resync_after_garbage_and_crc_errors() {
        let s = stream(2, 64, 64); // config + 2 packets
        let mut bad = Vec::new();
        bad.extend_from_slice(&[0xA5, 0xC3, 1, 1, 0xFF, 0xFF, 0xA5]); // sync, bad length
        bad.extend_from_slice(&s[..CONFIG_PACKET_LEN]);
        // First points packet with one payload byte flipped: CRC error, lost packet.
        let p1 = CONFIG_PACKET_LEN..CONFIG_PACKET_LEN + 1304;
        let mut corrupted = s[p1.clone()].to_vec();
        corrupted[100] ^= 0x10;
        bad.extend_from_slice(&corrupted);
        bad.extend_from_slice(b"noise noise");
        bad.extend_from_slice(&s[p1.end..]);
        let mut ing = Ingest::<4096, 128>::new();
        assert_eq!(ing.write(&bad), bad.len());
        ing.finish();
        let (configs, lines) = drain(&mut ing);
        assert_eq!(configs, 1);
        // Only the second line survives; the sequence gap (packet 1 lost) was counted.
        assert_eq!(lines, [(0, 64, 64, 0)]);
        let c = ing.counters();
        assert_eq!(c.crc_errors, 1);
        assert_eq!(c.bad_length, 1);
        assert_eq!((c.seq_gaps, c.packets_missing), (1, 1));
        assert_eq!(c.bytes_garbage, 7 + 1304 + 11);
        check_balance(&ing);
    }

    #[test]
    fn ring_overflow_is_counted_never_overwritten() {
        let s = stream(4, 64, 64); // config + 4 packets of 1304 B
        let mut ing = Ingest::<2000, 128>::new();
        // Write everything without polling: only what fits is accepted.
        let accepted = ing.write(&s);
        assert_eq!(accepted, 2000);
        assert_eq!(ing.counters().bytes_dropped_full, (s.len() - 2000) as u64);
        // The first packets are intact; the partial third one is garbage at the end.
        ing.finish();
        let (configs, lines) = drain(&mut ing);
        assert_eq!(configs, 1);
        assert_eq!(lines, [(0, 0, 64, 0)]);
        let c = ing.counters();
        assert_eq!(c.bytes_garbage, (2000 - 80 - 1304) as u64);
        check_balance(&ing);
    }

    #[test]
    fn line_overflow_truncates_and_counts() {
        let s = stream(2, 300, 64);
        let mut ing = Ingest::<4096, 256>::new();
        let mut fed = 0;
        let mut lines = Vec::new();
        while fed < s.len() {
            fed += ing.write(&s[fed..]);
            lines.extend(drain(&mut ing).1);
        }
        ing.finish();
        lines.extend(drain(&mut ing).1);
        assert_eq!(lines, [(0, 0, 256, 44), (1, 300, 256, 44)]);
        let c = ing.counters();
        assert_eq!((c.points_truncated, c.lines_truncated), (88, 2));
        check_balance(&ing);
    }

    #[test]
    fn sequence_gap_closes_the_line() {
        let s = stream(1, 192, 64); // config + 3 packets of one line
        let mut ing = Ingest::<8192, 256>::new();
        let p = 80 + 1304;
        ing.write(&s[..p]); // config + packet 1
        ing.write(&s[p + 1304..]); // packet 3 (packet 2 lost)
        ing.finish();
        let (_, lines) = drain(&mut ing);
        assert_eq!(lines, [(0, 0, 64, 0), (1, 128, 64, 0)]);
        let c = ing.counters();
        assert_eq!((c.seq_gaps, c.packets_missing, c.split_seq_gap), (1, 1, 1));
        check_balance(&ing);
    }

    #[test]
    fn bad_points_are_dropped_by_reason() {
        let mut enc = StreamEncoder::new();
        let mut buf = [0u8; MAX_PACKET_LEN];
        let n = enc
            .encode_points(
                u64::MAX - 1500,
                &[pt(0, false), pt(1, false), pt(2, false), pt(3, false)],
                &mut buf,
            )
            .unwrap();
        let rec = |i: usize| HEADER_LEN + POINTS_PREFIX_LEN + i * POINT_RECORD_LEN;
        buf[rec(1) + 4..rec(1) + 8].copy_from_slice(&f32::NAN.to_bits().to_le_bytes());
        buf[rec(2) + 15] = 0x40; // reserved flag bit
        let crc = crate::wire::crc::crc32(&buf[..n - 4]);
        buf[n - 4..n].copy_from_slice(&crc.to_le_bytes());
        // Point 3 (dt 3000 ns) overflows u64 time; point 0 survives.
        let mut ing = Ingest::<2048, 16>::new();
        ing.write(&buf[..n]);
        ing.finish();
        let (_, lines) = drain(&mut ing);
        assert_eq!(lines, [(0, 0, 1, 0)]);
        let c = ing.counters();
        assert_eq!(
            (
                c.points_in,
                c.points_non_finite,
                c.points_reserved_flags,
                c.points_time_overflow
            ),
            (4, 1, 1, 1)
        );
        check_balance(&ing);
    }

    #[test]
    fn rejected_packets_and_output_in_input() {
        let mut enc = StreamEncoder::new();
        let mut buf = [0u8; MAX_PACKET_LEN];
        let mut s = Vec::new();
        let n = enc.encode_points(0, &[pt(0, true)], &mut buf).unwrap();
        s.extend_from_slice(&buf[..n]);
        // Version 3 with a valid CRC.
        let mut v2 = buf[..n].to_vec();
        v2[2] = 3;
        v2[8] = 1;
        let crc = crate::wire::crc::crc32(&v2[..n - 4]);
        v2[n - 4..].copy_from_slice(&crc.to_le_bytes());
        s.extend_from_slice(&v2);
        enc = StreamEncoder::with_seq(1);
        let h = OutputHeaderRepr::default();
        let m = enc
            .encode_output_line(&h, |_| unreachable!(), &mut buf)
            .unwrap();
        s.extend_from_slice(&buf[..m]);
        let n = enc.encode_points(0, &[pt(1, false)], &mut buf).unwrap();
        s.extend_from_slice(&buf[..n]);
        let mut ing = Ingest::<2048, 16>::new();
        ing.write(&s);
        ing.finish();
        let (_, lines) = drain(&mut ing);
        assert_eq!(lines, [(0, 0, 2, 0)]);
        let c = ing.counters();
        assert_eq!((c.bad_version, c.output_ignored, c.seq_gaps), (1, 1, 0));
        check_balance(&ing);
    }

    #[test]
    fn config_mid_line_delivers_the_line_first() {
        let mut enc = StreamEncoder::new();
        let mut buf = [0u8; MAX_PACKET_LEN];
        let mut ing = Ingest::<2048, 16>::new();
        let n = enc
            .encode_points(0, &[pt(0, true), pt(1, false)], &mut buf)
            .unwrap();
        ing.write(&buf[..n]);
        let n = enc.encode_config(&[9; CONFIG_WORDS], &mut buf).unwrap();
        ing.write(&buf[..n]);
        assert!(matches!(ing.poll(), Some(IngestEvent::Line(l)) if l.len() == 2));
        assert!(matches!(ing.poll(), Some(IngestEvent::Config(_))));
        assert!(ing.poll().is_none());
        assert_eq!(ing.counters().split_config, 1);
        let _ = MAX_POINTS_PER_PACKET;
    }

    /// The memory of ingest state for the firmware budget (128 KiB in all): the ring, the
    /// line (12 B/point) and under 640 B of parser/assembler state and counters.
    #[test]
    fn memory_footprint() {
        use core::mem::size_of;
        const R: usize = 40 * 1024; // one 2000-point line of packets (40 768 B) in flight
        for (n, size, line) in [
            (2048, size_of::<Ingest<R, 2048>>(), size_of::<Line<2048>>()),
            (4096, size_of::<Ingest<R, 4096>>(), size_of::<Line<4096>>()),
        ] {
            std::println!(
                "Ingest<{R}, {n}> = {size} B (ring {R}, Line {line}, rest {})",
                size - R - line
            );
            assert_eq!(line, 12 * n + 24);
            assert!(size - R - line < 640, "{size}");
        }
        assert_eq!(size_of::<crate::scanline::ring::Ring<R>>(), R + 24);
    }

    proptest::proptest! {
        /// Random lines, random packet sizes, random garbage between packets, random write
        /// sizes: every line comes out whole (or truncated at N), the garbage is counted
        /// byte for byte and every byte and point is accounted for.
        #[test]
        fn random_streams_with_garbage(
            line_lens in proptest::collection::vec(1u32..300, 1..6),
            packet_sizes in proptest::collection::vec(1usize..=64, 1..8),
            garbage in proptest::collection::vec(proptest::collection::vec(proptest::prelude::any::<u8>(), 0..40), 1..8),
            writes in proptest::collection::vec(1usize..700, 1..8),
        ) {
            let mut enc = StreamEncoder::new();
            let mut buf = [0u8; MAX_PACKET_LEN];
            let mut s = Vec::new();
            let mut garbage_total = 0usize;
            let mut pts = Vec::new();
            for &len in &line_lens {
                for k in 0..len {
                    pts.push(PointRecord { tag: pts.len() as u32, ..pt(k, k == 0) });
                }
            }
            let mut at = 0;
            let mut k = 0;
            while at < pts.len() {
                let g = &garbage[k % garbage.len()];
                // Garbage must not end in a sync byte run that merges with the packet's.
                s.extend_from_slice(g);
                garbage_total += g.len();
                let n = packet_sizes[k % packet_sizes.len()].min(pts.len() - at);
                let m = enc.encode_points(0, &pts[at..at + n], &mut buf).unwrap();
                s.extend_from_slice(&buf[..m]);
                at += n;
                k += 1;
            }
            let mut ing = Ingest::<2048, 128>::new();
            let mut lines = Vec::new();
            let mut fed = 0;
            let mut w = 0;
            while fed < s.len() {
                let end = (fed + writes[w % writes.len()]).min(s.len());
                w += 1;
                fed += ing.write(&s[fed..end]);
                lines.extend(drain(&mut ing).1);
            }
            ing.finish();
            lines.extend(drain(&mut ing).1);
            let mut expected = Vec::new();
            let mut first = 0;
            for (i, &len) in line_lens.iter().enumerate() {
                expected.push((i as u32, first, (len as usize).min(128), len.saturating_sub(128)));
                first += len;
            }
            proptest::prop_assert_eq!(lines, expected);
            let c = ing.counters();
            proptest::prop_assert_eq!(c.bytes_garbage, garbage_total as u64);
            proptest::prop_assert_eq!(c.seq_gaps, 0);
            check_balance(&ing);
        }

        /// Any bytes: no panic, and every byte and point accounted for (a valid stream
        /// with random bytes overwritten, so packets, false syncs and CRC failures mix).
        #[test]
        fn mutated_streams_never_panic(
            edits in proptest::collection::vec((0usize..20_000, proptest::prelude::any::<u8>()), 0..40),
            cut in 0usize..20_000,
            writes in 1usize..3000,
        ) {
            let mut s = stream(3, 200, 37);
            for (at, v) in edits {
                let n = s.len();
                s[at % n] = v;
            }
            s.truncate(cut.max(1).min(s.len()));
            let mut ing = Ingest::<2048, 128>::new();
            for chunk in s.chunks(writes) {
                let mut fed = 0;
                while fed < chunk.len() {
                    fed += ing.write(&chunk[fed..]);
                    while let Some(ev) = ing.poll() {
                        let _ = ev;
                    }
                }
            }
            ing.finish();
            while ing.poll().is_some() {}
            check_balance(&ing);
            let c = ing.counters();
            proptest::prop_assert_eq!(c.bytes_buffered, 0);
            proptest::prop_assert_eq!(c.points_pending, 0);
        }
    }
}

#[cfg(test)]
mod link_checked_tests {
    extern crate std;
    use super::{Ingest, IngestEvent};

    /// Link-checked packets (version 2, flag 1, CRC field zero) of every kind are read without
    /// a CRC, by `Packet::check`, the scanner and ingest; a non-zero CRC field, a version-1
    /// label or another flag bit is refused.
    #[test]
    fn link_checked_packets_are_read_without_a_crc() {
        use crate::wire::{
            mark_link_checked, scan, ConfigRepr, Packet, PointRecord, PointsRepr, Scan,
            StreamEncoder, FLAG_LINK_CHECKED, MAX_PACKET_LEN,
        };
        use std::vec::Vec;
        let mut enc = StreamEncoder::new().link_checked(true);
        let mut buf = [0u8; MAX_PACKET_LEN];
        let mut stream = Vec::new();
        let n = enc.encode_config(&[0; 16], &mut buf).unwrap();
        assert_eq!(
            ConfigRepr::parse(&Packet::new_checked(&buf[..n]).unwrap())
                .unwrap()
                .words,
            [0; 16]
        );
        let pts: Vec<PointRecord> = (0..40)
            .map(|i| PointRecord {
                dt_ns: 1000 * i,
                x_m: -0.2 + 0.01 * i as f32,
                z_m: -2.0,
                intensity: 0,
                line_start: i == 0,
                tag: i,
            })
            .collect();
        let n = enc.encode_points(5, &pts, &mut buf).unwrap();
        let pk = Packet::new_checked(&buf[..n]).unwrap();
        assert_eq!(
            (pk.version(), pk.flags(), pk.crc()),
            (2, FLAG_LINK_CHECKED, 0)
        );
        assert!(pk.link_checked());
        assert_eq!(PointsRepr::parse(&pk).unwrap().points.len(), 40);
        assert_eq!(scan(&buf[..n], true), Scan::Packet { len: n });
        stream.extend_from_slice(&buf[..n]);
        // The same packet with a CRC in its field, or labelled version 1, is refused.
        let mut bad = buf[..n].to_vec();
        bad[n - 1] = 1;
        assert!(PointsRepr::parse(&Packet::new_checked(&bad[..]).unwrap()).is_err());
        assert!(matches!(scan(&bad, true), Scan::Garbage { .. }));
        let mut v1 = buf[..n].to_vec();
        v1[2] = 1;
        assert!(PointsRepr::parse(&Packet::new_checked(&v1[..]).unwrap()).is_err());
        // Marking a packet written with a CRC gives the encoder's bytes.
        let mut plain = [0u8; MAX_PACKET_LEN];
        let m = StreamEncoder::with_seq(1)
            .encode_points(5, &pts, &mut plain)
            .unwrap();
        mark_link_checked(&mut plain[..m]);
        assert_eq!(plain[..m], buf[..n]);
        let mut ing = Ingest::<4096, 64>::new();
        assert_eq!(ing.write(&stream), stream.len());
        ing.finish();
        let mut points = 0;
        while let Some(ev) = ing.poll() {
            if let IngestEvent::Line(l) = ev {
                points += l.len();
            }
        }
        let c = ing.counters();
        assert_eq!(
            (points, c.crc_errors, c.bad_version, c.reserved_flags),
            (40, 0, 0, 0)
        );
    }
}
