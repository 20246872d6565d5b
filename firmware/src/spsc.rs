//! A single-producer, single-consumer byte queue split into a producer half (an interrupt
//! handler: DMA completion, a timer standing in for one) and a consumer half (the main
//! loop), safe across the interrupt without a critical section: each half owns one index,
//! publishes it with a release store and reads the other's with an acquire load, and the
//! bytes between the two indices belong to exactly one side at a time.

use core::cell::UnsafeCell;
use core::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// The queue's storage and indices, for a `static`; [`Spsc::split`] hands out the halves.
pub struct Spsc<const CAP: usize> {
    buf: UnsafeCell<[u8; CAP]>,
    /// Bytes ever written (the producer's index; wraps).
    written: AtomicUsize,
    /// Bytes ever read (the consumer's index; wraps).
    read: AtomicUsize,
    /// The halves have been handed out.
    taken: AtomicBool,
}

// SAFETY: the producer writes only bytes outside `read..written` and the consumer reads
// only bytes inside it; the indices are atomics with release/acquire ordering.
unsafe impl<const CAP: usize> Sync for Spsc<CAP> {}

impl<const CAP: usize> Spsc<CAP> {
    /// An empty queue.
    pub const fn new() -> Self {
        Self {
            buf: UnsafeCell::new([0; CAP]),
            written: AtomicUsize::new(0),
            read: AtomicUsize::new(0),
            taken: AtomicBool::new(false),
        }
    }

    /// The two halves; `None` after the first call (one producer, one consumer).
    pub fn split(&'static self) -> Option<(Producer<CAP>, Consumer<CAP>)> {
        if self.taken.swap(true, Ordering::AcqRel) {
            return None;
        }
        Some((Producer { q: self }, Consumer { q: self }))
    }
}

impl<const CAP: usize> Default for Spsc<CAP> {
    fn default() -> Self {
        Self::new()
    }
}

/// The writing half.
pub struct Producer<const CAP: usize> {
    q: &'static Spsc<CAP>,
}

/// The reading half.
pub struct Consumer<const CAP: usize> {
    q: &'static Spsc<CAP>,
}

impl<const CAP: usize> Producer<CAP> {
    /// Fills the free space in place: `fill` gets the first contiguous free slice and
    /// returns how many bytes it wrote there; those are published. Returns that count.
    pub fn fill_with(&mut self, fill: impl FnOnce(&mut [u8]) -> usize) -> usize {
        let w = self.q.written.load(Ordering::Relaxed);
        let r = self.q.read.load(Ordering::Acquire);
        let free = CAP - w.wrapping_sub(r);
        let at = w % CAP;
        let len = free.min(CAP - at);
        // SAFETY: `at..at + len` lies outside the unread bytes, which the consumer alone
        // touches; nobody else writes.
        let slice =
            unsafe { core::slice::from_raw_parts_mut(self.q.buf.get().cast::<u8>().add(at), len) };
        let n = fill(slice).min(len);
        self.q.written.store(w.wrapping_add(n), Ordering::Release);
        n
    }

    /// Bytes that can be written now.
    pub fn free(&self) -> usize {
        CAP - self
            .q
            .written
            .load(Ordering::Relaxed)
            .wrapping_sub(self.q.read.load(Ordering::Acquire))
    }
}

impl<const CAP: usize> Consumer<CAP> {
    /// Copies up to `dst.len()` unread bytes into `dst`; returns how many.
    pub fn read(&mut self, dst: &mut [u8]) -> usize {
        let r = self.q.read.load(Ordering::Relaxed);
        let w = self.q.written.load(Ordering::Acquire);
        let at = r % CAP;
        let n = w.wrapping_sub(r).min(CAP - at).min(dst.len());
        // SAFETY: `at..at + n` holds unread bytes the producer published and does not touch
        // until `read` moves past them.
        let src = unsafe { core::slice::from_raw_parts(self.q.buf.get().cast::<u8>().add(at), n) };
        copy_words(&mut dst[..n], src);
        self.q.read.store(r.wrapping_add(n), Ordering::Release);
        n
    }

    /// Unread bytes.
    pub fn len(&self) -> usize {
        self.q
            .written
            .load(Ordering::Acquire)
            .wrapping_sub(self.q.read.load(Ordering::Relaxed))
    }

    /// True when nothing is unread.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Copies `src` into `dst` (equal lengths) eight words per round, then the rest by
/// bytes. Every byte of the stream passes through here on its way into the pipeline's
/// ring: `copy_from_slice` goes to `compiler_builtins`' `memcpy`, which moves one word per
/// five instructions (load, store, two index updates, branch); this loop moves eight per
/// eighteen. The loads and stores are single-word `LDR`/`STR`, which the Cortex-M4
/// executes unaligned, so neither side needs an alignment.
#[inline(never)]
pub fn copy_words(dst: &mut [u8], src: &[u8]) {
    const BLOCK: usize = 32;
    let n = dst.len().min(src.len());
    let (mut d, mut s) = (&mut dst[..n], &src[..n]);
    while d.len() >= BLOCK {
        let (db, dr) = core::mem::take(&mut d).split_at_mut(BLOCK);
        let (sb, sr) = s.split_at(BLOCK);
        let mut w = [0u32; BLOCK / 4];
        for (k, v) in w.iter_mut().enumerate() {
            *v = u32::from_ne_bytes([sb[4 * k], sb[4 * k + 1], sb[4 * k + 2], sb[4 * k + 3]]);
        }
        for (k, v) in w.iter().enumerate() {
            db[4 * k..4 * k + 4].copy_from_slice(&v.to_ne_bytes());
        }
        (d, s) = (dr, sr);
    }
    for (a, b) in d.iter_mut().zip(s) {
        *a = *b;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn copy_words_copies_every_length_and_offset() {
        let src: Vec<u8> = (0..200u32).map(|i| (i * 7 + 3) as u8).collect();
        for len in 0..100 {
            for (so, d_o) in [(0, 0), (1, 0), (0, 3), (2, 1), (3, 3)] {
                let mut dst = [0xEEu8; 110];
                copy_words(&mut dst[d_o..d_o + len], &src[so..so + len]);
                assert_eq!(&dst[d_o..d_o + len], &src[so..so + len], "len {len}");
                assert!(dst[..d_o]
                    .iter()
                    .chain(&dst[d_o + len..])
                    .all(|&b| b == 0xEE));
            }
        }
    }

    #[test]
    fn bytes_come_out_in_order_across_the_wrap_and_never_overwrite() {
        static Q: Spsc<10> = Spsc::new();
        let (mut p, mut c) = Q.split().unwrap();
        assert!(Q.split().is_none());
        let mut next = 0u8;
        let mut expect = 0u8;
        let mut out = [0u8; 7];
        for round in 0..50 {
            // Offer 0..=7 bytes; only the free contiguous part is taken.
            let want = round % 8;
            let mut offered = 0;
            while offered < want && p.free() > 0 {
                let n = p.fill_with(|s| {
                    let k = s.len().min(want - offered);
                    for b in &mut s[..k] {
                        *b = next;
                        next = next.wrapping_add(1);
                    }
                    k
                });
                offered += n;
            }
            assert!(c.len() <= 10);
            let n = c.read(&mut out[..(round % 5) + 1]);
            for &b in &out[..n] {
                assert_eq!(b, expect);
                expect = expect.wrapping_add(1);
            }
        }
        while !c.is_empty() {
            let n = c.read(&mut out);
            for &b in &out[..n] {
                assert_eq!(b, expect);
                expect = expect.wrapping_add(1);
            }
        }
        assert_eq!(expect, next);
    }
}
