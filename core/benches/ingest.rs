//! Ingest throughput on one thread: bytes in → assembled scanlines (ring → CRC → parse →
//! assembly), with realistic 2000-point lines, and the two CRC forms.
//!
//! Run: `cargo bench -p curbtrace-core --bench ingest`. Results: `docs/benchmarks.md`.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use curbtrace_core::scanline::{Ingest, IngestEvent};
use curbtrace_core::wire::{
    crc, PointRecord, StreamEncoder, CONFIG_WORDS, MAX_PACKET_LEN, MAX_POINTS_PER_PACKET,
};
use std::hint::black_box;

const POINTS_PER_LINE: usize = 2000;
const LINES: usize = 50;
/// Holds one 2000-point line of packets in flight (32 packets, 40 768 bytes).
const RING: usize = 40 * 1024;
const N: usize = 2048;

/// `LINES` revolutions of a scanner 2 m above a road with walls 8 m to each side; points
/// 10 µs apart, 100 lines/s. With `flags`, the first point of each line is flagged;
/// without, the assembler splits geometrically.
fn stream(flags: bool) -> Vec<u8> {
    let mut enc = StreamEncoder::new();
    let mut out = Vec::new();
    let mut buf = [0u8; MAX_PACKET_LEN];
    let n = enc.encode_config(&[0; CONFIG_WORDS], &mut buf).unwrap();
    out.extend_from_slice(&buf[..n]);
    let mut pts = Vec::new();
    for line in 0..LINES {
        for k in 0..POINTS_PER_LINE {
            // Angle from the zenith, 300° of returns around the nadir (none in the sky).
            let phi =
                30f64.to_radians() + (k as f64 / POINTS_PER_LINE as f64) * 300f64.to_radians();
            let (s, c) = phi.sin_cos();
            let (dx, dz) = (s, c);
            let t_road = if dz < 0.0 { 2.0 / -dz } else { f64::INFINITY };
            let t_wall = 8.0 / dx.abs();
            let r = t_road.min(t_wall);
            let t = (line * POINTS_PER_LINE + k) as u64 * 10_000 + 1_400_000_000_000_000_000;
            pts.push((
                t,
                PointRecord {
                    dt_ns: 0,
                    x_m: (dx * r) as f32,
                    z_m: (dz * r) as f32,
                    intensity: 100,
                    line_start: flags && k == 0,
                    tag: (line * POINTS_PER_LINE + k) as u32,
                },
            ));
        }
    }
    for chunk in pts.chunks(MAX_POINTS_PER_PACKET) {
        let base = chunk[0].0;
        let recs: Vec<PointRecord> = chunk
            .iter()
            .map(|(t, p)| PointRecord {
                dt_ns: (t - base) as u32,
                ..*p
            })
            .collect();
        let n = enc.encode_points(base, &recs, &mut buf).unwrap();
        out.extend_from_slice(&buf[..n]);
    }
    out
}

/// Feeds `bytes` in 1 KiB writes (like a UART/DMA or file reader) and polls all lines;
/// returns (lines, points) so nothing is optimised away.
fn ingest(ing: &mut Ingest<RING, N>, bytes: &[u8]) -> (usize, usize) {
    let (mut lines, mut points) = (0, 0);
    for chunk in bytes.chunks(1024) {
        let mut fed = 0;
        while fed < chunk.len() {
            fed += ing.write(&chunk[fed..]);
            while let Some(ev) = ing.poll() {
                if let IngestEvent::Line(l) = ev {
                    lines += 1;
                    points += l.len();
                    black_box(&l.x_m[..l.len()]);
                }
            }
        }
    }
    ing.finish();
    while let Some(ev) = ing.poll() {
        if let IngestEvent::Line(l) = ev {
            lines += 1;
            points += l.len();
        }
    }
    (lines, points)
}

fn bench_ingest(c: &mut Criterion) {
    println!(
        "size_of Ring<{RING}> = {}, Ingest<{RING}, 2048> = {}, Ingest<{RING}, 4096> = {}, Line<2048> = {}, Line<4096> = {}",
        std::mem::size_of::<curbtrace_core::scanline::ring::Ring<RING>>(),
        std::mem::size_of::<Ingest<RING, 2048>>(),
        std::mem::size_of::<Ingest<RING, 4096>>(),
        std::mem::size_of::<curbtrace_core::scanline::Line<2048>>(),
        std::mem::size_of::<curbtrace_core::scanline::Line<4096>>(),
    );
    for flags in [true, false] {
        let s = stream(flags);
        let total_points = (LINES * POINTS_PER_LINE) as u64;
        // Sanity: every line comes out whole.
        let mut ing: Box<Ingest<RING, N>> = Box::new(Ingest::new());
        assert_eq!(ingest(&mut ing, &s), (LINES, LINES * POINTS_PER_LINE));
        let name = if flags { "flags" } else { "geometric" };
        let mut g = c.benchmark_group("ingest_points");
        g.throughput(Throughput::Elements(total_points));
        g.bench_function(name, |b| {
            b.iter(|| {
                let mut ing: Box<Ingest<RING, N>> = Box::new(Ingest::new());
                black_box(ingest(&mut ing, black_box(&s)))
            })
        });
        g.finish();
        let mut g = c.benchmark_group("ingest_bytes");
        g.throughput(Throughput::Bytes(s.len() as u64));
        g.bench_function(name, |b| {
            b.iter(|| {
                let mut ing: Box<Ingest<RING, N>> = Box::new(Ingest::new());
                black_box(ingest(&mut ing, black_box(&s)))
            })
        });
        g.finish();
    }
}

fn bench_crc(c: &mut Criterion) {
    let data: Vec<u8> = (0..1300u32).map(|i| (i * 31 + 7) as u8).collect();
    let mut g = c.benchmark_group("crc32_1300B");
    g.throughput(Throughput::Bytes(data.len() as u64));
    g.bench_function("bytewise_1KiB_table", |b| {
        b.iter(|| crc::crc32_bytewise(black_box(&data)))
    });
    g.bench_function("slice8_8KiB_tables", |b| {
        b.iter(|| crc::crc32_slice8(black_box(&data)))
    });
    g.finish();
}

criterion_group!(benches, bench_ingest, bench_crc);
criterion_main!(benches);
