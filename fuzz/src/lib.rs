//! Shared harness of the fuzz targets (`docs/robustness.md`): the byte stream → ring →
//! parser → assembly → kernel path of `curbtrace-core`, with its accounting invariants
//! asserted after every step, not just "no panic".
#![forbid(unsafe_code)]

#[cfg(feature = "host")]
pub mod host_inputs;

use curbtrace_core::kernel::{Kernel, KernelParams, PointStatus, ScanlineOutput};
use curbtrace_core::scanline::{Ingest, IngestCounters, IngestEvent};
use curbtrace_core::wire::{crc, HEADER_LEN, MAX_PACKET_LEN, MIN_PACKET_LEN, SYNC};

/// Ring of the fuzzed pipeline: small (a few packets) so the ring runs full and
/// `bytes_dropped_full` is exercised; the core requires at least `MAX_PACKET_LEN`.
pub const RING: usize = 4096;
/// Line capacity: small so over-long lines are truncated and counted.
pub const N: usize = 512;

/// Recomputes the CRC of every candidate packet in `buf` (a [`SYNC`] pair whose length
/// field is in range and whose bytes are all there), left to right, skipping over each
/// fixed packet. Random bytes almost never carry a valid CRC-32; with this the fuzzer
/// reaches the version/kind/length/point checks behind the CRC. Returns the packets fixed.
pub fn fix_crcs(buf: &mut [u8]) -> usize {
    let mut i = 0;
    let mut fixed = 0;
    while i + HEADER_LEN <= buf.len() {
        if buf[i..i + 2] != SYNC {
            i += 1;
            continue;
        }
        let len = usize::from(u16::from_le_bytes([buf[i + 4], buf[i + 5]]));
        if !(MIN_PACKET_LEN..=MAX_PACKET_LEN).contains(&len) || i + len > buf.len() {
            i += 1;
            continue;
        }
        let body = i + len - 4;
        let c = crc::crc32(&buf[i..body]);
        buf[body..i + len].copy_from_slice(&c.to_le_bytes());
        fixed += 1;
        i += len;
    }
    fixed
}

/// Tiny deterministic generator for chunk sizes (xorshift32), seeded from the input.
pub struct Chunks(u32);

impl Chunks {
    /// A generator from `seed` (0 is mapped to a fixed non-zero state).
    pub fn new(seed: u32) -> Self {
        Self(if seed == 0 { 0x9E37_79B9 } else { seed })
    }
    /// The next chunk size: mostly small (1–64), sometimes up to 4 KiB (more than the ring).
    pub fn next_len(&mut self) -> usize {
        let mut x = self.0;
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        self.0 = x;
        if x & 0xF == 0 {
            1 + (x >> 4) as usize % 4096
        } else {
            1 + (x >> 4) as usize % 64
        }
    }
}

/// What the checker saw (for the targets that want to assert more).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Seen {
    /// Lines delivered to the kernel.
    pub lines: u64,
    /// Points in those lines.
    pub points: u64,
    /// Sum of the lines' `truncated`.
    pub truncated: u64,
    /// Config events.
    pub configs: u64,
    /// Bytes offered to `write`.
    pub offered: u64,
}

/// The ingest + kernel under test, with the invariant checks.
pub struct Harness {
    ingest: Box<Ingest<RING, N>>,
    kernel: Box<Kernel<N>>,
    /// What was seen so far.
    pub seen: Seen,
}

impl Default for Harness {
    fn default() -> Self {
        Self::new()
    }
}

impl Harness {
    /// Default parameters, as `HostPipeline` starts.
    pub fn new() -> Self {
        Self {
            ingest: Box::new(Ingest::new()),
            kernel: Box::new(Kernel::new(KernelParams::DEFAULT)),
            seen: Seen::default(),
        }
    }

    /// Offers `bytes` (the ring may take fewer; the rest is counted as dropped).
    pub fn write(&mut self, bytes: &[u8]) {
        self.seen.offered += bytes.len() as u64;
        let took = self.ingest.write(bytes);
        assert!(took <= bytes.len());
        self.check_counters(false);
    }

    /// Polls until the ingest needs more bytes, running the kernel on every line.
    pub fn poll_all(&mut self) {
        let mut guard = 0u64;
        while let Some(ev) = self.ingest.poll() {
            match ev {
                IngestEvent::Config(words) => {
                    self.seen.configs += 1;
                    if let Ok(p) = KernelParams::from_words(&words) {
                        // from_words checks; set_params checks again and must agree.
                        assert!(self.kernel.set_params(p).is_ok(), "{p:?}");
                    }
                }
                IngestEvent::Line(line) => {
                    let len = line.len;
                    assert!(len <= N);
                    self.seen.lines += 1;
                    self.seen.points += len as u64;
                    self.seen.truncated += u64::from(line.truncated);
                    let out = self.kernel.process(line);
                    check_output(&out, len);
                }
            }
            guard += 1;
            // Every event consumes bytes or closes a line; the stream is finite.
            assert!(guard < 10_000_000, "poll does not terminate");
        }
        self.check_counters(false);
    }

    /// End of stream; afterwards nothing may be left buffered or pending.
    pub fn finish(&mut self) {
        self.ingest.finish();
        self.poll_all();
        self.check_counters(true);
    }

    /// The ingest counters.
    pub fn counters(&self) -> IngestCounters {
        self.ingest.counters()
    }

    fn check_counters(&self, finished: bool) {
        let c = self.ingest.counters();
        assert_eq!(c.bytes_in, self.seen.offered, "{c:?}");
        assert_eq!(
            c.bytes_in,
            c.bytes_dropped_full
                + c.bytes_garbage
                + c.bytes_rejected
                + c.bytes_packets
                + c.bytes_buffered,
            "byte accounting: {c:?}"
        );
        assert_eq!(
            c.points_in,
            c.points_non_finite
                + c.points_reserved_flags
                + c.points_time_overflow
                + c.points_in_lines
                + c.points_truncated
                + c.points_pending,
            "point accounting: {c:?}"
        );
        assert_eq!(c.points_in_lines, self.seen.points, "{c:?} {:?}", self.seen);
        assert_eq!(
            c.points_truncated, self.seen.truncated,
            "{c:?} {:?}",
            self.seen
        );
        assert_eq!(c.lines, self.seen.lines, "{c:?} {:?}", self.seen);
        assert_eq!(
            c.lines,
            c.split_line_start
                + c.split_zenith
                + c.split_time_gap
                + c.split_seq_gap
                + c.split_config
                + c.split_end,
            "every line has one reason: {c:?}"
        );
        assert!(c.bytes_buffered <= RING as u64);
        if finished {
            assert_eq!(c.bytes_buffered, 0, "bytes left after finish: {c:?}");
            assert_eq!(c.points_pending, 0, "points left after finish: {c:?}");
        }
    }
}

/// The kernel's per-line invariants (`ScanlineOutput`'s documentation).
pub fn check_output(out: &ScanlineOutput<'_>, len: usize) {
    assert_eq!(out.tag.len(), len);
    assert_eq!(out.x_m.len(), len);
    assert_eq!(out.z_m.len(), len);
    assert_eq!(out.rho_deg.len(), len);
    assert_eq!(out.status.len(), len);
    let k = out.counters;
    assert_eq!(k.points_in as usize, len, "{k:?}");
    assert_eq!(
        (k.kept + k.irregular + k.no_neighbour + k.non_finite) as usize,
        len,
        "every point has one status: {k:?}"
    );
    let mut counts = [0u32; 4];
    for (i, (&rho, &st)) in out.rho_deg.iter().zip(out.status).enumerate() {
        counts[st as usize] += 1;
        assert!(
            rho.is_finite() && rho > -180.0 && rho <= 180.0,
            "rho[{i}] = {rho} outside (-180, 180]"
        );
        if st != PointStatus::Kept {
            assert_eq!(rho, 0.0, "rho[{i}] of a {st:?} point");
        }
        if st != PointStatus::NonFinite {
            assert!(
                out.x_m[i].is_finite() && out.z_m[i].is_finite(),
                "point {i}"
            );
        }
    }
    assert_eq!(
        counts,
        [k.kept, k.irregular, k.no_neighbour, k.non_finite],
        "status counters match statuses"
    );
    if let Some(n) = out.nadir {
        assert!(usize::from(n) < len, "nadir {n} of {len}");
    }
    if let Some(l) = out.left {
        let l = usize::from(l);
        assert!(l < len, "left {l} of {len}");
        assert_eq!(out.status[l], PointStatus::Kept, "left candidate not kept");
        assert!(out.x_m[l] > 0.0, "left candidate at x' = {}", out.x_m[l]);
    }
    if let Some(r) = out.right {
        let r = usize::from(r);
        assert!(r < len, "right {r} of {len}");
        assert_eq!(out.status[r], PointStatus::Kept, "right candidate not kept");
        assert!(out.x_m[r] < 0.0, "right candidate at x' = {}", out.x_m[r]);
    }
    assert!(k.peaks as usize <= len);
}

/// Feeds `stream` in chunks from `chunks`, polling after each chunk unless `lazy_mask`
/// says to skip (so the ring fills up), then finishes.
pub fn run_stream(stream: &[u8], chunks: &mut Chunks, lazy_mask: u8) -> Harness {
    let mut h = Harness::new();
    let mut at = 0;
    let mut k = 0u32;
    while at < stream.len() {
        let n = chunks.next_len().min(stream.len() - at);
        h.write(&stream[at..at + n]);
        at += n;
        if lazy_mask & (1 << (k % 8)) == 0 {
            h.poll_all();
        }
        k += 1;
    }
    h.finish();
    h
}
