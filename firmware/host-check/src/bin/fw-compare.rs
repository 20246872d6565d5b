//! `fw-compare [--approx] HOST.bin FIRMWARE.bin` — compares two streams of output packets
//! and prints `name: value` lines for `firmware/check.sh`.
//!
//! Exact (default): byte-for-byte per scanline, ending with `identical: yes` or
//! `identical: no (N of M scanlines differ)`. `--approx` (micromath against libm): largest ρ
//! difference, points and candidates that differ, share of scanlines whose candidates agree.
//! Exit status 0 when both streams could be read (the verdict is in the output), 1 otherwise.

use std::process::ExitCode;

use curbtrace_firmware_host_check::{compare_approx, compare_exact, read_lines, LineResult};

fn read(path: &str) -> Result<(Vec<u8>, Vec<LineResult>), String> {
    let bytes = std::fs::read(path).map_err(|e| format!("{path}: {e}"))?;
    let lines = read_lines(&bytes).map_err(|e| format!("{path}: {e}"))?;
    Ok((bytes, lines))
}

fn run(args: &[String]) -> Result<(), String> {
    let (approx, files) = match args {
        [flag, a, b] if flag == "--approx" => (true, [a, b]),
        [a, b] => (false, [a, b]),
        _ => return Err("usage: fw-compare [--approx] HOST.bin FIRMWARE.bin".into()),
    };
    let (bytes_a, a) = read(files[0])?;
    let (bytes_b, b) = read(files[1])?;
    if approx {
        let c = compare_approx(&a, &b);
        println!("scanlines: {}", c.scanlines);
        println!("points_compared: {}", c.points);
        println!("status_differ_points: {}", c.status_differ);
        println!("rho_differ_points: {}", c.rho_differ);
        println!("rho_max_diff_deg: {:.2}", c.rho_max_diff_deg);
        println!("candidates: {}", c.candidates);
        println!("candidates_differ: {}", c.candidates_differ);
        println!("candidates_agree_percent: {:.2}", c.agree_percent());
    } else {
        let c = compare_exact(&a, &b);
        println!("output_bytes: {}", bytes_b.len());
        if bytes_a == bytes_b {
            println!("identical: yes");
        } else {
            // Same lines but different bytes elsewhere cannot happen (streams are lines
            // back to back); say so rather than claim 0 differing lines.
            println!(
                "identical: no ({} of {} scanlines differ)",
                c.differ.max(1),
                c.scanlines
            );
        }
    }
    Ok(())
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match run(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("fw-compare: {e}");
            ExitCode::FAILURE
        }
    }
}
