//! `fw-feed SOCKET STREAM.bin [BYTES_PER_S]` — feeds a scanline stream into the firmware's
//! USART3 under QEMU (`firmware/usart-test.sh`).
//!
//! QEMU serves the USART as a Unix socket (`-serial unix:SOCKET,server=on,wait=on`) and
//! starts the guest once this program connects. The feeder then waits for the firmware's
//! ready byte (0x06, sent on USART3's transmit line once its receiver is on: bytes that reach
//! QEMU's USART model before that are lost), writes the whole stream, optionally paced to
//! BYTES_PER_S, and keeps the socket open until QEMU closes it. QEMU hands the guest one byte
//! at a time and reads the socket only when the previous byte has been taken, so an
//! unpaced feed runs at the rate the guest's receive interrupt keeps up with. Prints
//! `fed_bytes`, `fed_seconds` and `fed_bytes_per_s` lines on stdout.

use std::io::{Read, Write};
use std::os::unix::net::UnixStream;
use std::process::ExitCode;
use std::time::{Duration, Instant};

/// The firmware's ready byte (ASCII ACK).
const READY: u8 = 0x06;
/// How long to keep trying to connect while QEMU starts.
const CONNECT_FOR: Duration = Duration::from_secs(30);
/// Bytes per write (and per pacing step).
const CHUNK: usize = 4096;

fn connect(path: &str) -> Result<UnixStream, String> {
    let start = Instant::now();
    loop {
        match UnixStream::connect(path) {
            Ok(s) => return Ok(s),
            // QEMU creates the socket shortly after it starts.
            Err(_) if start.elapsed() < CONNECT_FOR => {
                std::thread::sleep(Duration::from_millis(50));
            }
            Err(e) => {
                return Err(format!(
                    "{path}: cannot connect for {} s: {e}",
                    CONNECT_FOR.as_secs()
                ))
            }
        }
    }
}

fn run(socket: &str, input: &str, rate: Option<f64>) -> Result<(), String> {
    let data = std::fs::read(input).map_err(|e| format!("{input}: {e}"))?;
    let mut sock = connect(socket)?;
    let mut byte = [0u8; 1];
    loop {
        let n = sock
            .read(&mut byte)
            .map_err(|e| format!("{socket}: waiting for the ready byte: {e}"))?;
        if n == 0 {
            return Err(format!(
                "{socket}: closed before the firmware sent its ready byte"
            ));
        }
        if byte[0] == READY {
            break;
        }
    }
    let start = Instant::now();
    for (k, chunk) in data.chunks(CHUNK).enumerate() {
        if let Some(rate) = rate {
            let due = Duration::from_secs_f64((k * CHUNK) as f64 / rate);
            if let Some(wait) = due.checked_sub(start.elapsed()) {
                std::thread::sleep(wait);
            }
        }
        sock.write_all(chunk)
            .map_err(|e| format!("{socket}: writing the stream: {e}"))?;
    }
    let secs = start.elapsed().as_secs_f64();
    println!("fed_bytes: {}", data.len());
    println!("fed_seconds: {secs:.3}");
    println!("fed_bytes_per_s: {:.0}", data.len() as f64 / secs.max(1e-9));
    // Anything more from the firmware on this line is ignored; QEMU closing the socket (the
    // guest exited) ends the feeder.
    let mut sink = [0u8; 256];
    while matches!(sock.read(&mut sink), Ok(n) if n > 0) {}
    Ok(())
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let rate = match args.get(2).map(|r| r.parse::<f64>()) {
        None => None,
        Some(Ok(r)) if r > 0.0 => Some(r),
        Some(_) => {
            eprintln!("fw-feed: BYTES_PER_S must be a positive number");
            return ExitCode::from(2);
        }
    };
    if !(2..=3).contains(&args.len()) {
        eprintln!("usage: fw-feed SOCKET STREAM.bin [BYTES_PER_S]");
        return ExitCode::from(2);
    }
    match run(&args[0], &args[1], rate) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("fw-feed: {e}");
            ExitCode::FAILURE
        }
    }
}
