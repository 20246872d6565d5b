//! Kernel throughput: assembled scanline → output (`Kernel::process`), one thread.
//!
//! Lines: the synthetic scene of the kernel's tests (`src/kernel/synth.rs`): scanner 2 m
//! up, a 150 mm curb on each side, 2 % cross slope, 0.123° angular steps (≈2000 returns),
//! 5 mm noise; 16 different noise seeds, both rotation directions. Each iteration copies a
//! fresh line into the `Line` (the kernel works in place) outside the timed region.
//!
//! `cargo bench -p curbtrace-core --bench kernel`; the figures go to `docs/benchmarks.md`.
//! Besides the full kernel, two variants show where the time goes: without Taubin
//! smoothing (`taubin_steps = 0`), and the bare cost of one `atan2f` per point.

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use curbtrace_core::kernel::{Kernel, KernelParams};
use curbtrace_core::scanline::Line;

#[path = "../src/kernel/synth.rs"]
mod synth;

const N: usize = 4096;

fn lines() -> Vec<Vec<(f32, f32, u32)>> {
    let mut v = Vec::new();
    for seed in 0..16u64 {
        let scene = synth::Scene {
            ccw: seed % 2 == 0,
            ..synth::Scene::DEFAULT
        };
        let mut buf = vec![(0f32, 0f32, 0u32); N];
        let n = scene.generate(&mut synth::Rng(seed), &mut buf);
        buf.truncate(n);
        v.push(buf);
    }
    v
}

fn fill(line: &mut Line<N>, pts: &[(f32, f32, u32)]) {
    line.clear();
    for &(x, z, t) in pts {
        line.push(x, z, t).expect("fits");
    }
}

fn bench_kernel(c: &mut Criterion) {
    let lines = lines();
    let per_round: usize = lines.iter().map(Vec::len).sum();
    let mut group = c.benchmark_group("kernel");
    group.throughput(Throughput::Elements(per_round as u64));
    group.measurement_time(Duration::from_secs(8));
    for (name, params) in [
        ("process_2000pt_lines", KernelParams::DEFAULT),
        (
            "process_without_smoothing",
            KernelParams {
                taubin_steps: 0,
                ..KernelParams::DEFAULT
            },
        ),
    ] {
        let mut line = Box::new(Line::<N>::new());
        let mut kernel = Box::new(Kernel::<N>::new(params));
        group.bench_function(name, |b| {
            b.iter_custom(|iters| {
                let mut total = Duration::ZERO;
                for _ in 0..iters {
                    for pts in &lines {
                        fill(&mut line, pts);
                        let t0 = Instant::now();
                        let out = kernel.process(black_box(&mut line));
                        black_box((out.left, out.right, out.counters.peaks));
                        total += t0.elapsed();
                    }
                }
                total
            })
        });
    }
    // One atan2f per point: the floor the output ρ costs with libm.
    #[cfg(feature = "libm")]
    {
        let ys: Vec<f32> = lines.iter().flatten().map(|p| p.1).collect();
        let xs: Vec<f32> = lines.iter().flatten().map(|p| p.0).collect();
        group.bench_function("atan2f_per_point", |b| {
            b.iter(|| {
                let mut acc = 0.0f32;
                for (&y, &x) in ys.iter().zip(&xs) {
                    acc += libm::atan2f(black_box(y), black_box(x));
                }
                acc
            })
        });
    }
    group.finish();
    uncontended_estimate(&lines);
}

/// On a shared machine criterion's means include the time the thread waits for a core. A
/// 2000-point line takes tens of microseconds, far less than a scheduler time slice, so the
/// fastest of many single-line runs is the uncontended speed; print it beside criterion's
/// figures (both go to `docs/benchmarks.md`).
fn uncontended_estimate(lines: &[Vec<(f32, f32, u32)>]) {
    let mut line = Box::new(Line::<N>::new());
    let mut kernel = Box::new(Kernel::<N>::new(KernelParams::DEFAULT));
    let mut per_point: Vec<f64> = Vec::new();
    for _ in 0..200 {
        for pts in lines {
            fill(&mut line, pts);
            let t0 = Instant::now();
            let out = kernel.process(black_box(&mut line));
            black_box(out.left);
            per_point.push(t0.elapsed().as_nanos() as f64 / pts.len() as f64);
        }
    }
    per_point.sort_by(f64::total_cmp);
    let q = |f: f64| per_point[((per_point.len() - 1) as f64 * f) as usize];
    println!(
        "kernel per line, ns/point over {} runs: min {:.1} (= {:.1} M points/s), 10 % {:.1}, \
         median {:.1} (= {:.1} M points/s)",
        per_point.len(),
        q(0.0),
        1e3 / q(0.0),
        q(0.1),
        q(0.5),
        1e3 / q(0.5)
    );
}

criterion_group!(benches, bench_kernel);
criterion_main!(benches);
