//! `curbtrace kernel STREAM.bin -o RESULTS.bin` — runs the host build of the core (ingest +
//! kernel, `curbtrace_core::Pipeline`) over a byte stream and writes its output packets,
//! one line after another (`docs/wire-format.md`), then prints the core's counters.

use anyhow::Context;
use curbtrace_core::encode_output;
use curbtrace_core::kernel::ScanlineOutput;
use curbtrace_core::wire::{StreamEncoder, MAX_PACKET_LEN};
use curbtrace_host_sim::replay::run::{HostPipeline, LINE_CAPACITY, PIPELINE_STACK};
use std::io::{Read, Write};
use std::path::PathBuf;

/// Arguments of `curbtrace kernel`.
#[derive(clap::Args)]
pub struct Args {
    /// Input byte stream (e.g. from `curbtrace replay`).
    pub stream: PathBuf,
    /// Output packets.
    #[arg(short, long)]
    pub output: PathBuf,
}

/// Runs `curbtrace kernel`.
pub fn run(args: Args) -> anyhow::Result<()> {
    // The pipeline's fixed buffers are large for a default main-thread stack in debug builds.
    std::thread::Builder::new()
        .stack_size(PIPELINE_STACK)
        .spawn(move || run_inner(args))
        .context("starting the kernel thread")?
        .join()
        .map_err(|_| anyhow::anyhow!("the kernel thread panicked"))?
}

fn run_inner(args: Args) -> anyhow::Result<()> {
    let input = std::fs::File::open(&args.stream)
        .with_context(|| format!("{}: opening the stream", args.stream.display()))?;
    let mut input = std::io::BufReader::with_capacity(1 << 20, input);
    let out_file = std::fs::File::create(&args.output)
        .with_context(|| format!("{}: creating the output", args.output.display()))?;
    let mut out = std::io::BufWriter::with_capacity(1 << 20, out_file);
    let mut pipe: Box<HostPipeline> = Box::default();
    let mut enc = StreamEncoder::new();
    // A full line: ceil(N / points per packet) packets of at most MAX_PACKET_LEN bytes.
    let mut buf = vec![0u8; LINE_CAPACITY.div_ceil(64) * MAX_PACKET_LEN + MAX_PACKET_LEN];
    let mut err: Option<anyhow::Error> = None;
    let (mut lines, mut out_bytes, mut candidates) = (0u64, 0u64, 0u64);
    let mut on_line = |o: &ScanlineOutput<'_>| {
        if err.is_some() {
            return;
        }
        lines += 1;
        candidates += u64::from(o.left.is_some()) + u64::from(o.right.is_some());
        match encode_output(o, &mut enc, &mut buf) {
            Ok(n) => {
                out_bytes += n as u64;
                if let Err(e) = out.write_all(&buf[..n]) {
                    err = Some(
                        anyhow::Error::new(e)
                            .context(format!("{}: writing the output", args.output.display())),
                    );
                }
            }
            Err(e) => {
                err = Some(anyhow::anyhow!(
                    "{}: line {}: encoding its output failed: {e:?}",
                    args.stream.display(),
                    o.index
                ))
            }
        }
    };
    let mut chunk = vec![0u8; 1 << 16];
    loop {
        let n = input
            .read(&mut chunk)
            .with_context(|| format!("{}: reading the stream", args.stream.display()))?;
        if n == 0 {
            break;
        }
        let mut off = 0;
        while off < n {
            let w = pipe.write(&chunk[off..n]);
            off += w;
            pipe.run(&mut on_line);
            if w == 0 {
                // The ring refused bytes (and counted them). After processing every line it
                // has room again unless it is jammed; then the rest of this read is given up
                // (the ingest's counters say how many bytes were refused).
                let w2 = pipe.write(&chunk[off..n]);
                if w2 == 0 {
                    break;
                }
                off += w2;
                pipe.run(&mut on_line);
            }
        }
    }
    pipe.finish(&mut on_line);
    if let Some(e) = err {
        return Err(e);
    }
    out.flush()
        .with_context(|| format!("{}: writing the output", args.output.display()))?;
    let pc = pipe.counters();
    let c = pc.ingest;
    eprintln!(
        "{}: {} bytes, {} points packets, {} config packets ({} refused), {} CRC errors, {} sequence gaps, {} garbage bytes",
        args.stream.display(),
        c.bytes_in,
        c.packets_points,
        c.packets_config,
        pc.configs_rejected,
        c.crc_errors,
        c.seq_gaps,
        c.bytes_garbage
    );
    eprintln!(
        "points {} in, {} in lines, {} truncated, {} non-finite; {lines} lines, {candidates} candidates",
        c.points_in, c.points_in_lines, c.points_truncated, c.points_non_finite
    );
    if let Some(e) = pc.last_config_error {
        eprintln!("last refused config packet: {e}");
    }
    eprintln!(
        "written {out_bytes} bytes of output packets to {} (core maths: {})",
        args.output.display(),
        curbtrace_core::math::BACKEND
    );
    Ok(())
}
