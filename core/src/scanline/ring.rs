//! A fixed-capacity byte ring: a producer (DMA, UART interrupt, file reader) writes, the
//! packet parser reads. When the ring is full the producer learns how many bytes were
//! accepted and the rest are counted as dropped — unread bytes are never overwritten
//! (smoltcp's `RingBuffer`, heapless's const-generic capacity).
//!
//! Unread bytes may wrap around the end of the storage; [`Ring::as_slices`] gives them as
//! two slices in order, and the wire scanner ([`crate::wire::scan_two`]) parses packets
//! across the seam without copying.

/// A byte ring of capacity `CAP`.
#[derive(Clone)]
#[repr(C)] // the indices first, the bytes last (immediate offsets on the M4F)
pub struct Ring<const CAP: usize> {
    /// Index of the oldest unread byte (`< CAP`, or 0 when `CAP` is 0).
    head: usize,
    /// Unread bytes (`≤ CAP`).
    len: usize,
    /// Bytes refused by [`Ring::write`] / [`Ring::commit`] because the ring was full.
    dropped: u64,
    buf: [u8; CAP],
}

impl<const CAP: usize> Ring<CAP> {
    const CAP_OK: () = assert!(CAP > 0, "a ring needs a capacity");

    /// An empty ring.
    pub const fn new() -> Self {
        let () = Self::CAP_OK;
        Self {
            buf: [0; CAP],
            head: 0,
            len: 0,
            dropped: 0,
        }
    }

    /// Empties the ring as [`Ring::new`] leaves it, without rewriting its bytes (no byte
    /// is read before it is written again).
    pub fn restart(&mut self) {
        let Self {
            head,
            len,
            dropped,
            buf: _,
        } = self;
        (*head, *len, *dropped) = (0, 0, 0);
    }

    /// The capacity in bytes.
    pub const fn capacity(&self) -> usize {
        CAP
    }
    /// Unread bytes.
    pub fn len(&self) -> usize {
        self.len
    }
    /// True when nothing is unread.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
    /// Bytes that can be written now.
    pub fn free(&self) -> usize {
        CAP - self.len
    }
    /// Bytes dropped so far because the ring was full.
    pub fn dropped(&self) -> u64 {
        self.dropped
    }

    /// Index of the first free byte.
    fn tail(&self) -> usize {
        let t = self.head + self.len;
        if t >= CAP {
            t - CAP
        } else {
            t
        }
    }

    /// Appends as many bytes of `bytes` as fit; returns how many. The rest is counted in
    /// [`Ring::dropped`] (the producer decides whether to retry them).
    pub fn write(&mut self, bytes: &[u8]) -> usize {
        let n = bytes.len().min(self.free());
        let (s1, s2) = self.free_slices_mut();
        let k = n.min(s1.len());
        s1[..k].copy_from_slice(&bytes[..k]);
        s2[..n - k].copy_from_slice(&bytes[k..n]);
        self.len += n;
        self.dropped += (bytes.len() - n) as u64;
        n
    }

    /// The free space as two slices in write order (for a DMA engine or a `read()` call
    /// that fills memory directly); follow with [`Ring::commit`].
    pub fn free_slices_mut(&mut self) -> (&mut [u8], &mut [u8]) {
        let tail = self.tail();
        let free = CAP - self.len;
        let (before, from_tail) = self.buf.split_at_mut(tail);
        if tail + free <= CAP {
            (&mut from_tail[..free], &mut [])
        } else {
            let wrapped = tail + free - CAP;
            (from_tail, &mut before[..wrapped])
        }
    }

    /// Marks `n` bytes written through [`Ring::free_slices_mut`] as readable; more than the
    /// free space is clamped (the excess counted as dropped). Returns the bytes committed.
    pub fn commit(&mut self, n: usize) -> usize {
        let k = n.min(self.free());
        self.len += k;
        self.dropped += (n - k) as u64;
        k
    }

    /// The unread bytes as two slices in order (the second is empty unless they wrap).
    pub fn as_slices(&self) -> (&[u8], &[u8]) {
        let end = self.head + self.len;
        if end <= CAP {
            (&self.buf[self.head..end], &[])
        } else {
            (&self.buf[self.head..], &self.buf[..end - CAP])
        }
    }

    /// Copies unread bytes `offset..offset + dst.len()` into `dst` without consuming them;
    /// false if they are not all there.
    pub fn peek(&self, offset: usize, dst: &mut [u8]) -> bool {
        let (a, b) = self.as_slices();
        crate::wire::copy_from_two(a, b, offset, dst)
    }

    /// Drops up to `n` unread bytes from the front; returns how many.
    pub fn consume(&mut self, n: usize) -> usize {
        let k = n.min(self.len);
        self.head += k;
        if self.head >= CAP {
            self.head -= CAP;
        }
        self.len -= k;
        k
    }

    /// Copies up to `dst.len()` unread bytes into `dst` and consumes them; returns how many.
    pub fn read(&mut self, dst: &mut [u8]) -> usize {
        let n = dst.len().min(self.len);
        let ok = self.peek(0, &mut dst[..n]);
        debug_assert!(ok);
        self.consume(n)
    }
}

impl<const CAP: usize> Default for Ring<CAP> {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fills_refuses_and_counts_the_rest() {
        let mut r = Ring::<8>::new();
        assert_eq!(r.write(&[1, 2, 3, 4, 5]), 5);
        assert_eq!(r.write(&[6, 7, 8, 9, 10]), 3);
        assert_eq!(r.dropped(), 2);
        assert_eq!((r.len(), r.free()), (8, 0));
        // Unread bytes are never overwritten.
        assert_eq!(r.as_slices(), (&[1, 2, 3, 4, 5, 6, 7, 8][..], &[][..]));
        assert_eq!(r.write(&[11]), 0);
        assert_eq!(r.dropped(), 3);
        assert_eq!(r.consume(3), 3);
        assert_eq!(r.write(&[12, 13, 14, 15]), 3);
        assert_eq!(r.dropped(), 4);
        assert_eq!(r.as_slices(), (&[4, 5, 6, 7, 8][..], &[12, 13, 14][..]));
        let mut out = [0u8; 6];
        assert!(r.peek(2, &mut out));
        assert_eq!(out, [6, 7, 8, 12, 13, 14]);
        assert!(!r.peek(3, &mut out));
        let mut all = [0u8; 10];
        assert_eq!(r.read(&mut all), 8);
        assert_eq!(&all[..8], &[4, 5, 6, 7, 8, 12, 13, 14]);
        assert!(r.is_empty());
        assert_eq!(r.consume(5), 0);
    }

    #[test]
    fn dma_style_fill() {
        let mut r = Ring::<6>::new();
        r.write(&[0; 4]);
        r.consume(4);
        let (a, b) = r.free_slices_mut();
        assert_eq!((a.len(), b.len()), (2, 4));
        a.copy_from_slice(&[1, 2]);
        b[..1].copy_from_slice(&[3]);
        assert_eq!(r.commit(3), 3);
        assert_eq!(r.as_slices(), (&[1, 2][..], &[3][..]));
        assert_eq!(r.commit(10), 3);
        assert_eq!(r.dropped(), 7);
    }

    #[test]
    fn every_wrap_position_round_trips() {
        for start in 0..7 {
            let mut r = Ring::<7>::new();
            r.write(&[0; 7][..start]);
            r.consume(start);
            assert_eq!(r.write(&[1, 2, 3, 4, 5, 6, 7]), 7);
            let (a, b) = r.as_slices();
            let mut v = [0u8; 7];
            v[..a.len()].copy_from_slice(a);
            v[a.len()..].copy_from_slice(b);
            assert_eq!(v, [1, 2, 3, 4, 5, 6, 7]);
        }
    }
}
