//! Arbitrary bytes, in chunk sizes taken from the input, into the ring → parser → assembly →
//! kernel, with the accounting invariants of `curbtrace_fuzz::Harness` checked after every
//! step.
//!
//! Input layout: byte 0 = flags (bit 0: recompute the CRC of every candidate packet so the
//! fuzzer gets past the CRC; bits 1–7: which chunks are written without polling, so the
//! ring runs full), bytes 1–4 = chunk-size seed, the rest = the stream.
#![no_main]

use curbtrace_fuzz::{fix_crcs, run_stream, Chunks};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&flags, rest)) = data.split_first() else {
        return;
    };
    let (seed, stream) = rest.split_at(rest.len().min(4));
    let mut s = [0u8; 4];
    s[..seed.len()].copy_from_slice(seed);
    let mut stream = stream.to_vec();
    if flags & 1 != 0 {
        fix_crcs(&mut stream);
    }
    // Bits 1-7 as the lazy mask (bit 0 of the mask always polls, so progress is made).
    let lazy = flags & 0xFE;
    let h = run_stream(&stream, &mut Chunks::new(u32::from_le_bytes(s)), lazy);
    let c = h.counters();
    assert_eq!(c.bytes_in, stream.len() as u64);
});
