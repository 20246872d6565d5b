//! The processing loop, the same on the board and in host tests: bytes from a byte link
//! into the core's ring the way a DMA channel fills it, the core's
//! [`Pipeline`](curbtrace_core::Pipeline) on every completed scanline, each line's output
//! packets out through another byte link, one packet at a time.
//!
//! The links are `embedded_io::{Read, Write}` (embedded-hal 1.0 has no serial traits), so
//! a UART, SPI or DMA driver replaces the semihosting files of the QEMU build without this
//! loop changing. Everything between the links is the core's: `Pipeline::run` (ingest,
//! config packets, kernel) and `pipeline::{output_header, encode_output_fragment}` (the
//! bytes `encode_output` writes), so `firmware/check.sh` compares the same code on two CPUs.

use curbtrace_core::kernel::{KernelCounters, OutputMode, ScanlineOutput};
use curbtrace_core::pipeline::{self, Pipeline, PipelineCounters};
use curbtrace_core::wire::{
    EncodeError, StreamEncoder, MAX_OUTPUT_POINTS_PER_PACKET, MAX_PACKET_LEN,
    MAX_POINTS_PER_PACKET, POINTS_PREFIX_LEN, POINT_RECORD_LEN,
};

use embedded_io::{Read, Write};

/// Largest line the firmware holds: a VQ-250-class line is 2000 pulses.
pub const MAX_POINTS: usize = 2048;

/// Bytes of one points packet with [`MAX_POINTS_PER_PACKET`] points.
const FULL_POINTS_PACKET: usize = curbtrace_core::wire::HEADER_LEN
    + POINTS_PREFIX_LEN
    + MAX_POINTS_PER_PACKET * POINT_RECORD_LEN
    + curbtrace_core::wire::CRC_LEN;

/// One full line of [`MAX_POINTS`] points in packets (the next line keeps arriving while
/// the kernel works on the last one), plus one packet that may sit half-parsed when the
/// line is handed over: 32 × 1304 + 1472 = 43 200 bytes.
pub const LINE_RING: usize =
    MAX_POINTS.div_ceil(MAX_POINTS_PER_PACKET) * FULL_POINTS_PACKET + MAX_PACKET_LEN;

/// The ring on the board, where the front end's DMA writes into it: [`LINE_RING`].
#[cfg(feature = "board")]
pub const RING: usize = LINE_RING;

/// The ring in the QEMU builds: their bytes reach it through the loop's reads (a file, or
/// the queue an interrupt fills: `--realtime`, `--usart`), one [`DMA_CHUNK`] at a time,
/// so it holds one transfer and a packet left half-parsed; what arrives while the kernel
/// works waits in the queue, which gets the RAM instead (`realtime::QUEUE`).
#[cfg(not(feature = "board"))]
pub const RING: usize = 16 * 1024;
const _: () = assert!(RING >= DMA_CHUNK + MAX_PACKET_LEN);

/// Bytes moved per transfer into the ring (a DMA half-transfer, a `read()` call).
pub const DMA_CHUNK: usize = 4096;

/// The firmware's pipeline: ring, parser, assembly and kernel for its line size.
pub type Node = Pipeline<RING, MAX_POINTS>;

/// What a run did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Summary {
    /// The pipeline's counters at the end (ingest, kernel sums, config packets).
    pub counters: PipelineCounters,
    /// Kernel counters summed over all lines (as the host's `curbtrace kernel` prints them).
    pub kernel: KernelCounters,
    /// Output packets written.
    pub packets_out: u32,
    /// Output bytes written.
    pub bytes_out: u64,
}

/// Why a run stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Error<R, W> {
    /// The input link failed.
    Read(R),
    /// The output link failed.
    Write(W),
    /// A line's output could not be encoded (line index, encoder error).
    Encode(u32, EncodeError),
    /// The ring had no free space although every complete packet had been taken out
    /// (cannot happen with `RING` ≥ `MAX_PACKET_LEN`; reported rather than looping).
    RingStuck,
}

/// Runs the whole input stream through `pipeline`, writing every line's output packets to
/// `output`; `packet` is the one output packet buffer.
pub fn run<R: Read, W: Write, const RING: usize, const N: usize>(
    pipeline: &mut Pipeline<RING, N>,
    input: &mut R,
    output: &mut W,
    packet: &mut [u8; MAX_PACKET_LEN],
) -> Result<Summary, Error<R::Error, W::Error>> {
    run_observed(pipeline, input, output, packet, |_, _| {})
}

/// [`run`], calling `observe` with the pipeline and the running summary after every transfer
/// into the ring has been processed (a board feeds its watchdog, blinks and logs there; it
/// reads the pipeline's counters only when it needs them).
pub fn run_observed<R: Read, W: Write, const RING: usize, const N: usize>(
    pipeline: &mut Pipeline<RING, N>,
    input: &mut R,
    output: &mut W,
    packet: &mut [u8; MAX_PACKET_LEN],
    mut observe: impl FnMut(&Pipeline<RING, N>, &Summary),
) -> Result<Summary, Error<R::Error, W::Error>> {
    // The firmware sends only what the output mode asks for: in candidates mode the
    // kernel computes ρ only where the candidates packet depends on it (same packets).
    pipeline.set_lean_rho(true);
    let mut sink = Sink {
        enc: StreamEncoder::new(),
        packet,
        output,
        sum: Summary::default(),
        failed: None,
    };
    loop {
        // Fill the ring's free space in place, as a DMA channel would (no copy).
        let (free, _) = pipeline.free_slices_mut();
        let want = free.len().min(DMA_CHUNK);
        if want == 0 {
            return Err(Error::RingStuck);
        }
        let n = input.read(&mut free[..want]).map_err(Error::Read)?;
        if n == 0 {
            break;
        }
        pipeline.commit(n);
        pipeline.run(|out| sink.line(out));
        if let Some(e) = sink.failed.take() {
            return Err(e);
        }
        observe(pipeline, &sink.sum);
    }
    pipeline.finish(|out| sink.line(out));
    if let Some(e) = sink.failed.take() {
        return Err(e);
    }
    sink.output.flush().map_err(Error::Write)?;
    sink.sum.counters = pipeline.counters();
    Ok(sink.sum)
}

/// Where `Pipeline::run` hands each line: encodes and writes it, keeps the first error
/// (the closure cannot return one) and writes nothing after it.
struct Sink<'a, W: Write, E> {
    enc: StreamEncoder,
    packet: &'a mut [u8; MAX_PACKET_LEN],
    output: &'a mut W,
    sum: Summary,
    failed: Option<Error<E, W::Error>>,
}

impl<W: Write, E> Sink<'_, W, E> {
    fn line(&mut self, out: &ScanlineOutput<'_>) {
        add_counters(&mut self.sum.kernel, &out.counters);
        if self.failed.is_none() {
            if let Err(e) = emit_line(out, &mut self.enc, self.packet, self.output, &mut self.sum) {
                self.failed = Some(e);
            }
        }
    }
}

fn add_counters(total: &mut KernelCounters, c: &KernelCounters) {
    total.points_in += c.points_in;
    total.kept += c.kept;
    total.irregular += c.irregular;
    total.no_neighbour += c.no_neighbour;
    total.non_finite += c.non_finite;
    total.peaks += c.peaks;
    total.capped_windows += c.capped_windows;
    total.smooth_pieces += c.smooth_pieces;
    total.outside_roi += c.outside_roi;
}

/// Writes one line's output packets, one packet buffer at a time (a whole 2048-point line
/// would need 34 KiB at once), or its one candidates packet; the bytes are
/// `pipeline::encode_output`'s.
fn emit_line<W: Write, E>(
    out: &ScanlineOutput<'_>,
    enc: &mut StreamEncoder,
    packet: &mut [u8; MAX_PACKET_LEN],
    output: &mut W,
    sum: &mut Summary,
) -> Result<(), Error<E, W::Error>> {
    if out.output_mode == OutputMode::Candidates {
        let n = pipeline::encode_candidates(out, enc, packet)
            .map_err(|e| Error::Encode(out.index, e))?;
        output.write_all(&packet[..n]).map_err(Error::Write)?;
        sum.packets_out += 1;
        sum.bytes_out += n as u64;
        return Ok(());
    }
    let header = pipeline::output_header(out).map_err(|e| Error::Encode(out.index, e))?;
    for k in 0..header.fragments() {
        let first = u16::try_from(k * MAX_OUTPUT_POINTS_PER_PACKET)
            .map_err(|_| Error::Encode(out.index, EncodeError::OutOfRange { index: k }))?;
        let n = pipeline::encode_output_fragment(out, &header, first, enc, packet)
            .map_err(|e| Error::Encode(out.index, e))?;
        output.write_all(&packet[..n]).map_err(Error::Write)?;
        sum.packets_out += 1;
        sum.bytes_out += n as u64;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use curbtrace_core::kernel::KernelParams;
    use curbtrace_core::wire::{OutputHeaderRepr, Packet, PointRecord, CONFIG_WORDS};

    /// A reader that hands out at most `step` bytes per call (a slow link).
    struct Trickle<'a> {
        data: &'a [u8],
        step: usize,
    }
    impl embedded_io::ErrorType for Trickle<'_> {
        type Error = core::convert::Infallible;
    }
    impl Read for Trickle<'_> {
        fn read(&mut self, buf: &mut [u8]) -> Result<usize, Self::Error> {
            let n = self.step.min(buf.len()).min(self.data.len());
            buf[..n].copy_from_slice(&self.data[..n]);
            self.data = &self.data[n..];
            Ok(n)
        }
    }
    struct Sink(Vec<u8>);
    impl embedded_io::ErrorType for Sink {
        type Error = core::convert::Infallible;
    }
    impl Write for Sink {
        fn write(&mut self, buf: &[u8]) -> Result<usize, Self::Error> {
            self.0.extend_from_slice(buf);
            Ok(buf.len())
        }
        fn flush(&mut self) -> Result<(), Self::Error> {
            Ok(())
        }
    }

    /// A config packet, then `lines` lines of `n` points on a V-shaped profile (a bend at
    /// the nadir), each line starting with the line-start flag.
    fn stream(config: &[u32; CONFIG_WORDS], lines: usize, n: usize) -> Vec<u8> {
        let mut enc = StreamEncoder::new();
        let mut out = Vec::new();
        let mut buf = [0u8; MAX_PACKET_LEN];
        let k = enc.encode_config(config, &mut buf).unwrap();
        out.extend_from_slice(&buf[..k]);
        let mut tag = 0;
        for l in 0..lines {
            let pts: Vec<PointRecord> = (0..n)
                .map(|i| {
                    let x = -2.0 + 4.0 * i as f32 / n as f32;
                    tag += 1;
                    PointRecord {
                        dt_ns: i as u32 * 1000,
                        x_m: x,
                        z_m: -2.0 + 0.1 * x.abs(),
                        intensity: 0,
                        line_start: i == 0,
                        tag,
                    }
                })
                .collect();
            for (c, chunk) in pts.chunks(MAX_POINTS_PER_PACKET).enumerate() {
                let base =
                    1_000_000_000 * (l as u64 + 1) + (c * MAX_POINTS_PER_PACKET) as u64 * 1000;
                let k = enc.encode_points(base, chunk, &mut buf).unwrap();
                out.extend_from_slice(&buf[..k]);
            }
        }
        out
    }

    fn run_all(input: &[u8], step: usize) -> (Summary, Vec<u8>) {
        let mut node: Box<Pipeline<RING, 512>> = Box::default();
        let mut packet = [0u8; MAX_PACKET_LEN];
        let mut out = Sink(Vec::new());
        let sum = run(
            &mut node,
            &mut Trickle { data: input, step },
            &mut out,
            &mut packet,
        )
        .expect("runs");
        (sum, out.0)
    }

    #[test]
    fn chunking_does_not_change_the_output() {
        let input = stream(&KernelParams::DEFAULT.to_words(), 3, 300);
        let (sum, whole) = run_all(&input, usize::MAX);
        assert_eq!(sum.counters.kernel_lines, 3);
        assert_eq!(sum.counters.configs_applied, 1);
        assert_eq!(sum.counters.ingest.points_in, 900);
        assert_eq!(sum.counters.ingest.bytes_dropped_full, 0);
        assert_eq!(sum.kernel.points_in, 900);
        // 300 points = 4 output packets of ≤ 88 points ((1472 − 56) / 16) per line.
        assert_eq!(MAX_OUTPUT_POINTS_PER_PACKET, 88);
        assert_eq!(sum.packets_out, 12);
        assert_eq!(sum.bytes_out, whole.len() as u64);
        for step in [1, 7, 1000] {
            let (s, out) = run_all(&input, step);
            assert_eq!(out, whole, "step {step}");
            assert_eq!(s.counters.kernel_lines, 3);
        }
        // Every packet is a valid output packet of a line with the nadir at its V.
        let mut at = 0;
        while at < whole.len() {
            let p = Packet::new_checked(&whole[at..]).unwrap();
            let len = p.length();
            let p = Packet::new_unchecked(&whole[at..at + len]);
            let (h, _) = OutputHeaderRepr::parse(&p).unwrap();
            assert_eq!(h.line_len, 300);
            assert!(
                h.nadir.is_some_and(|i| (145..=155).contains(&i)),
                "{:?}",
                h.nadir
            );
            at += len;
        }
    }

    #[test]
    fn the_observer_sees_every_transfer_and_the_lines_so_far() {
        let input = stream(&KernelParams::DEFAULT.to_words(), 3, 300);
        // A ring larger than the input: every transfer is a whole `step`, none cut at
        // the wrap.
        assert!(LINE_RING > input.len());
        let mut node: Box<Pipeline<LINE_RING, 512>> = Box::default();
        let mut packet = [0u8; MAX_PACKET_LEN];
        let mut out = Sink(Vec::new());
        let step = 500;
        let (mut calls, mut last_lines, mut last_packets) = (0usize, 0, 0);
        let sum = run_observed(
            &mut node,
            &mut Trickle { data: &input, step },
            &mut out,
            &mut packet,
            |p, s| {
                calls += 1;
                let lines = p.counters().kernel_lines;
                assert!(lines >= last_lines && s.packets_out >= last_packets);
                (last_lines, last_packets) = (lines, s.packets_out);
            },
        )
        .expect("runs");
        assert_eq!(calls, input.len().div_ceil(step));
        // The last line is handed over by `finish`, after the last transfer.
        assert_eq!(last_lines, 2);
        assert_eq!(sum.counters.kernel_lines, 3);
    }

    #[test]
    fn a_bad_config_is_counted_and_the_defaults_stay() {
        let mut words = KernelParams::DEFAULT.to_words();
        words[0] = f32::NAN.to_bits(); // d_b
        let (sum, _) = run_all(&stream(&words, 1, 100), 64);
        assert_eq!(sum.counters.configs_applied, 0);
        assert_eq!(sum.counters.configs_rejected, 1);
        assert_eq!(sum.counters.kernel_lines, 1);
    }
}
