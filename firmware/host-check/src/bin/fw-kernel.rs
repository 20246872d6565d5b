//! `fw-kernel STREAM.bin OUT.bin` — the firmware's processing loop (`curbtrace_firmware::app`,
//! the same code the STM32F405 runs) on the host, over files. `firmware/check.sh` compares the
//! firmware's output with this when the host program has no `curbtrace kernel` yet, and
//! always reports it: a difference here is arithmetic (Cortex-M4F against x86-64), not
//! a different processing loop.

use std::process::ExitCode;

use curbtrace_core::wire::MAX_PACKET_LEN;
use curbtrace_firmware::app::{self, Node};

/// `std::io` behind `embedded_io` (what a UART driver is on the board).
struct Io<T>(T);

#[derive(Debug)]
struct IoError(std::io::Error);
impl std::fmt::Display for IoError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}
impl std::error::Error for IoError {}
impl embedded_io::Error for IoError {
    fn kind(&self) -> embedded_io::ErrorKind {
        embedded_io::ErrorKind::Other
    }
}
impl<T> embedded_io::ErrorType for Io<T> {
    type Error = IoError;
}
impl<T: std::io::Read> embedded_io::Read for Io<T> {
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, IoError> {
        self.0.read(buf).map_err(IoError)
    }
}
impl<T: std::io::Write> embedded_io::Write for Io<T> {
    fn write(&mut self, buf: &[u8]) -> Result<usize, IoError> {
        self.0.write(buf).map_err(IoError)
    }
    fn flush(&mut self) -> Result<(), IoError> {
        self.0.flush().map_err(IoError)
    }
}

fn run(input: &str, output: &str) -> Result<(), String> {
    let inf = std::fs::File::open(input).map_err(|e| format!("{input}: {e}"))?;
    let outf = std::fs::File::create(output).map_err(|e| format!("{output}: {e}"))?;
    let mut node: Box<Node> = Box::default();
    let mut packet = [0u8; MAX_PACKET_LEN];
    let sum = app::run(
        &mut node,
        &mut Io(std::io::BufReader::new(inf)),
        &mut Io(std::io::BufWriter::new(outf)),
        &mut packet,
    )
    .map_err(|e| format!("{input} → {output}: {e:?}"))?;
    eprintln!(
        "fw-kernel: {} lines, {} points, {} output packets",
        sum.counters.kernel_lines, sum.counters.ingest.points_in, sum.packets_out
    );
    Ok(())
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let r = match args.as_slice() {
        [a, b] => run(a, b),
        _ => Err("usage: fw-kernel STREAM.bin OUT.bin".into()),
    };
    match r {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("fw-kernel: {e}");
            ExitCode::FAILURE
        }
    }
}
