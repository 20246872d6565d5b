//! `fw-head STREAM.bin OUT.bin BYTES` — the first whole packets of a scanline stream, at most
//! BYTES bytes: a shorter stream for a slow link (QEMU's emulated USART moves a few tens of
//! kB/s), cut at a packet boundary so that no packet is torn. The last line may be cut short;
//! the firmware and the host core then both process it as the stream's last, partial line.

use std::process::ExitCode;

use curbtrace_core::wire::Packet;

fn run(input: &str, output: &str, max: usize) -> Result<usize, String> {
    let data = std::fs::read(input).map_err(|e| format!("{input}: {e}"))?;
    let mut at = 0;
    while at < data.len() {
        let len = Packet::new_checked(&data[at..])
            .map_err(|e| format!("{input}: no valid packet at byte {at}: {e:?}"))?
            .length();
        if len == 0 || at + len > max {
            break;
        }
        at += len;
    }
    std::fs::write(output, &data[..at]).map_err(|e| format!("{output}: {e}"))?;
    Ok(at)
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [input, output, max] = args.as_slice() else {
        eprintln!("usage: fw-head STREAM.bin OUT.bin BYTES");
        return ExitCode::from(2);
    };
    let Ok(max) = max.parse::<usize>() else {
        eprintln!("fw-head: BYTES must be a whole number, not {max:?}");
        return ExitCode::from(2);
    };
    match run(input, output, max) {
        Ok(n) => {
            eprintln!("fw-head: wrote {n} bytes of {input} to {output}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("fw-head: {e}");
            ExitCode::FAILURE
        }
    }
}
