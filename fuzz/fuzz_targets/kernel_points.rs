//! Structure-aware: valid packets (correct CRCs, sequence numbers, finite coordinates)
//! carrying extreme point sequences — duplicates, zero spacing, huge and tiny coordinates,
//! very long lines, time going backwards — and optionally a config packet, through the
//! whole ingest + kernel path with the same invariants as the `ingest` target.
#![no_main]

use arbitrary::{Arbitrary, Unstructured};
use curbtrace_core::kernel::KernelParams;
use curbtrace_core::wire::{PointRecord, StreamEncoder, MAX_PACKET_LEN, MAX_POINTS_PER_PACKET};
use curbtrace_fuzz::{run_stream, Chunks};
use libfuzzer_sys::fuzz_target;

/// A coordinate: mostly ordinary, often one of the awkward values.
#[derive(Debug, Clone, Copy)]
struct Coord(f32);

impl<'a> Arbitrary<'a> for Coord {
    fn arbitrary(u: &mut Unstructured<'a>) -> arbitrary::Result<Self> {
        const SPECIAL: [f32; 14] = [
            0.0,
            -0.0,
            f32::MIN_POSITIVE,
            -f32::MIN_POSITIVE,
            1e-45,
            1e-30,
            f32::MAX,
            f32::MIN,
            1e30,
            -1e30,
            1e19,
            0.07,
            -0.07,
            3.4e38,
        ];
        Ok(Coord(match u.int_in_range(0u8..=3)? {
            0 => SPECIAL[u.choose_index(SPECIAL.len())?],
            1 => {
                let v = f32::from_bits(u.arbitrary()?);
                if v.is_finite() {
                    v
                } else {
                    0.0
                }
            }
            _ => f32::from(u.int_in_range(-20_000i16..=20_000)?) * 1e-3,
        }))
    }
}

/// A run of points.
#[derive(Debug, Arbitrary)]
enum Run {
    /// The same point `n` times (zero spacing).
    Dup { x: Coord, z: Coord, n: u16 },
    /// `n` points on a line from (x, z) in steps (dx, dz).
    Ramp {
        x: Coord,
        z: Coord,
        dx: Coord,
        dz: Coord,
        n: u16,
    },
    /// A ground profile with a curb step (an ordinary scanline, so peaks are found).
    Profile {
        half_width_mm: u16,
        step_mm: u16,
        spacing_mm: u8,
    },
    /// Single points as given.
    Points(Vec<(Coord, Coord)>),
    /// The next point starts a new line (flag).
    LineStart,
    /// Time jumps by `dt` ns (may be backwards: wrapping, or huge).
    Time(i64),
    /// A config packet with these parameter words (mostly valid ones, perturbed).
    Config { perturb: Option<(u8, u32)> },
    /// A sequence-number gap.
    SeqGap(u8),
}

#[derive(Debug, Arbitrary)]
struct Input {
    runs: Vec<Run>,
    dt_step_ns: u16,
    chunk_seed: u32,
    lazy: u8,
}

struct Builder {
    stream: Vec<u8>,
    enc: StreamEncoder,
    pending: Vec<PointRecord>,
    base: u64,
    t: u64,
    dt: u64,
    line_start: bool,
    tag: u32,
}

/// Stream size cap (about 6500 points, 13 lines of capacity `N`): long enough for
/// truncated lines, short enough for a few hundred executions per second.
const MAX_STREAM: usize = 128 << 10;

impl Builder {
    fn full(&self) -> bool {
        self.stream.len() + self.pending.len() * 20 > MAX_STREAM
    }

    fn flush(&mut self) {
        if self.pending.is_empty() {
            return;
        }
        let mut out = [0u8; MAX_PACKET_LEN];
        let n = self
            .enc
            .encode_points(self.base, &self.pending, &mut out)
            .expect("finite points in range encode");
        self.stream.extend_from_slice(&out[..n]);
        self.pending.clear();
    }

    fn point(&mut self, x: f32, z: f32) {
        if self.full() || !x.is_finite() || !z.is_finite() {
            return; // keep executions fast; the wire carries finite coordinates only
        }
        // dt_ns is u32 relative to the packet's base time.
        if self.pending.is_empty() {
            self.base = self.t;
        }
        let Some(dt) = self
            .t
            .checked_sub(self.base)
            .filter(|&d| d <= u64::from(u32::MAX))
        else {
            self.flush();
            return self.point(x, z);
        };
        self.pending.push(PointRecord {
            dt_ns: dt as u32,
            x_m: x,
            z_m: z,
            intensity: 0,
            line_start: std::mem::take(&mut self.line_start),
            tag: self.tag,
        });
        self.tag = self.tag.wrapping_add(1);
        self.t = self.t.wrapping_add(self.dt);
        if self.pending.len() == MAX_POINTS_PER_PACKET {
            self.flush();
        }
    }
}

fn build(input: &Input) -> Vec<u8> {
    let mut b = Builder {
        stream: Vec::new(),
        enc: StreamEncoder::new(),
        pending: Vec::new(),
        base: 0,
        t: 1_000_000_000,
        dt: u64::from(input.dt_step_ns),
        line_start: false,
        tag: 0,
    };
    for run in &input.runs {
        match *run {
            Run::Dup { x, z, n } => {
                for _ in 0..n.min(4096) {
                    if b.full() {
                        break;
                    }
                    b.point(x.0, z.0);
                }
            }
            Run::Ramp { x, z, dx, dz, n } => {
                for i in 0..n.min(4096) {
                    if b.full() {
                        break;
                    }
                    let k = f32::from(i);
                    b.point(x.0 + k * dx.0, z.0 + k * dz.0);
                }
            }
            Run::Profile {
                half_width_mm,
                step_mm,
                spacing_mm,
            } => {
                let hw = f32::from(half_width_mm.max(1)) * 1e-3;
                let sp = f32::from(spacing_mm.max(1)) * 1e-3;
                let step = f32::from(step_mm % 500) * 1e-3;
                let mut x = hw;
                while x > -hw && !b.full() {
                    let z = if x.abs() > hw * 0.6 {
                        -2.0 + step
                    } else {
                        -2.0
                    };
                    b.point(x, z);
                    x -= sp;
                }
            }
            Run::Points(ref v) => {
                for &(x, z) in v {
                    b.point(x.0, z.0);
                }
            }
            Run::LineStart => {
                b.flush();
                b.line_start = true;
            }
            Run::Time(dt) => {
                b.flush();
                b.t = b.t.wrapping_add(dt as u64);
            }
            Run::Config { perturb } => {
                b.flush();
                let mut w = KernelParams::DEFAULT.to_words();
                if let Some((i, v)) = perturb {
                    w[usize::from(i) % w.len()] = v;
                }
                let mut out = [0u8; MAX_PACKET_LEN];
                let n = b.enc.encode_config(&w, &mut out).unwrap();
                b.stream.extend_from_slice(&out[..n]);
            }
            Run::SeqGap(k) => {
                b.flush();
                b.enc = StreamEncoder::with_seq(b.enc.seq().wrapping_add(u32::from(k) + 1));
            }
        }
    }
    b.flush();
    b.stream
}

fuzz_target!(|input: Input| {
    let stream = build(&input);
    let h = run_stream(
        &stream,
        &mut Chunks::new(input.chunk_seed),
        input.lazy & 0xFE,
    );
    let c = h.counters();
    // Valid packets only: nothing is garbage or rejected; every packet is a points or
    // config packet (ring-full drops may cut packets, which then become garbage).
    if c.bytes_dropped_full == 0 {
        assert_eq!(c.bytes_garbage, 0, "{c:?}");
        assert_eq!(c.bytes_rejected, 0, "{c:?}");
        assert_eq!(c.bytes_packets, stream.len() as u64, "{c:?}");
        assert_eq!(c.points_non_finite + c.points_reserved_flags, 0, "{c:?}");
    }
});
