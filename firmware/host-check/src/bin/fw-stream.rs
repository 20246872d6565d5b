//! `fw-stream OUT.bin [LINES] [POINTS_PER_LINE]` — a small synthetic scanline stream for
//! `firmware/check.sh` when no `curbtrace replay` output is at hand: a config packet with
//! the default kernel parameters, then LINES (default 20) revolutions of a scanner 2 m above
//! a road cross-section with a 15 cm curb and a sidewalk on each side, POINTS_PER_LINE
//! (default 2000, a VQ-250-class line) pulses per revolution, encoded with the core's own
//! `wire::StreamEncoder`. Deterministic: the same arguments give the same bytes.

use std::process::ExitCode;

use curbtrace_core::kernel::KernelParams;
use curbtrace_core::wire::{PointRecord, StreamEncoder, MAX_PACKET_LEN, MAX_POINTS_PER_PACKET};

/// A road profile z(x) in the scanner frame (x′ left positive, z′ up, scanner at 0):
/// road −2.00 m with 2 % crossfall, curb toe at |x| = 3.5 m, curb top 0.15 m higher, a
/// sidewalk out to 6 m, then a wall.
fn profile_hit(theta: f64) -> Option<(f64, f64)> {
    // Ray from the origin with direction (sin θ, −cos θ): θ = 0 points straight down.
    let (dx, dz) = (theta.sin(), -theta.cos());
    let segments: [((f64, f64), (f64, f64)); 8] = [
        ((-3.5, -2.07), (0.0, -2.0)),
        ((0.0, -2.0), (3.5, -2.07)),
        ((3.5, -2.07), (3.5, -1.92)),
        ((3.5, -1.92), (6.0, -1.87)),
        ((6.0, -1.87), (6.0, 1.0)),
        ((-3.5, -2.07), (-3.5, -1.92)),
        ((-3.5, -1.92), (-6.0, -1.87)),
        ((-6.0, -1.87), (-6.0, 1.0)),
    ];
    let mut best: Option<(f64, (f64, f64))> = None;
    for ((ax, az), (bx, bz)) in segments {
        // Solve t·d = a + s·(b − a) for t > 0, s ∈ [0, 1].
        let (ex, ez) = (bx - ax, bz - az);
        let det = dx * (-ez) - dz * (-ex);
        if det.abs() < 1e-12 {
            continue;
        }
        let t = (ax * (-ez) - az * (-ex)) / det;
        let s = (dx * az - dz * ax) / det;
        if t > 0.0 && (0.0..=1.0).contains(&s) && best.is_none_or(|(bt, _)| t < bt) {
            best = Some((t, (t * dx, t * dz)));
        }
    }
    best.map(|(_, p)| p)
}

/// Small deterministic range noise (a linear congruential generator, ±2 mm).
struct Noise(u64);
impl Noise {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 33) as f64 / (1u64 << 31) as f64 - 0.5) * 0.004
    }
}

fn stream(lines: usize, pulses: usize) -> Result<Vec<u8>, String> {
    let mut enc = StreamEncoder::new();
    let mut out = Vec::new();
    let mut buf = vec![0u8; MAX_PACKET_LEN];
    let n = enc
        .encode_config(&KernelParams::DEFAULT.to_words(), &mut buf)
        .map_err(|e| format!("config packet: {e:?}"))?;
    out.extend_from_slice(&buf[..n]);
    let mut noise = Noise(7);
    let line_period_ns: u64 = 10_000_000; // 100 Hz mirror
    let t0: u64 = 1_400_000_000_000_000_000; // GPS ns, about 2024
    let mut tag = 0u32;
    let mut pending: Vec<(u64, PointRecord)> = Vec::new();
    for line in 0..lines {
        for k in 0..pulses {
            // One revolution, starting straight up so the line's points run from one side
            // over the road to the other.
            let theta = std::f64::consts::PI * (1.0 + 2.0 * k as f64 / pulses as f64);
            let t = t0 + line as u64 * line_period_ns + (k as u64 * line_period_ns) / pulses as u64;
            let Some((x, z)) = profile_hit(theta) else {
                continue;
            };
            let r = 1.0 + noise.next() / (x * x + z * z).sqrt();
            pending.push((
                t,
                PointRecord {
                    dt_ns: 0,
                    x_m: (x * r) as f32,
                    z_m: (z * r) as f32,
                    intensity: 1000 + (k % 200) as u16,
                    line_start: pending.is_empty(),
                    tag,
                },
            ));
            tag += 1;
        }
        for chunk in pending.chunks(MAX_POINTS_PER_PACKET) {
            let base = chunk[0].0;
            let pts: Vec<PointRecord> = chunk
                .iter()
                .map(|&(t, p)| PointRecord {
                    dt_ns: u32::try_from(t - base).unwrap_or(u32::MAX),
                    ..p
                })
                .collect();
            let n = enc
                .encode_points(base, &pts, &mut buf)
                .map_err(|e| format!("points packet: {e:?}"))?;
            out.extend_from_slice(&buf[..n]);
        }
        pending.clear();
    }
    Ok(out)
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let parse = |i: usize, default: usize| -> Result<usize, String> {
        args.get(i).map_or(Ok(default), |s| {
            s.parse().map_err(|_| format!("not a count: {s}"))
        })
    };
    let run = || -> Result<(), String> {
        let path = args
            .first()
            .ok_or("usage: fw-stream OUT.bin [LINES] [POINTS_PER_LINE]")?;
        let bytes = stream(parse(1, 20)?, parse(2, 2000)?)?;
        std::fs::write(path, &bytes).map_err(|e| format!("{path}: {e}"))
    };
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("fw-stream: {e}");
            ExitCode::FAILURE
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn straight_down_hits_the_road_at_two_metres() {
        let (x, z) = profile_hit(0.0).expect("hits");
        assert!(x.abs() < 1e-12 && (z + 2.0).abs() < 1e-12, "{x} {z}");
    }

    #[test]
    fn a_ray_to_the_curb_face_hits_it() {
        // Towards (3.5, −2.0): on the curb face between −2.07 and −1.92.
        let theta = (3.5f64).atan2(2.0);
        let (x, z) = profile_hit(theta).expect("hits");
        assert!((x - 3.5).abs() < 1e-9 && (z + 2.0).abs() < 1e-9, "{x} {z}");
        // Straight up: open sky.
        assert!(profile_hit(std::f64::consts::PI).is_none());
    }
}
