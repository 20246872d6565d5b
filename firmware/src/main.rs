//! curbtrace firmware for the STM32F405 (Cortex-M4F), run under QEMU's `netduinoplus2`.
//!
//! Reads a recorded scanline byte stream (the output of `curbtrace replay`) in chunks into
//! the core's ring buffer the way a DMA channel would, runs the kernel on every completed
//! scanline with the parameters from the stream's config packet, writes the output packets
//! back out, prints its figures and exits 0 through semihosting. Any panic or HardFault
//! exits non-zero.
//!
//! File names come from the semihosting command line
//! (`-semihosting-config enable=on,target=native,arg=fw,arg=IN,arg=OUT`); defaults
//! `stream.bin` and `results.bin`.
#![no_std]
#![no_main]

mod semihosting_io;
mod stack;

use core::ffi::CStr;

use cortex_m_rt::{entry, exception, ExceptionFrame};
use cortex_m_semihosting::debug::{self, EXIT_FAILURE, EXIT_SUCCESS};
use embedded_io::{Read, Write};

use semihosting_io::{HostFile, Mode};

/// Prints one `name: value` figure line (semihosting stdout, or defmt with `defmt`).
macro_rules! figure {
    ($name:literal, $value:expr) => {{
        #[cfg(not(feature = "defmt"))]
        cortex_m_semihosting::hprintln!(concat!($name, ": {}"), $value);
        #[cfg(feature = "defmt")]
        defmt::println!(concat!($name, ": {}"), $value);
    }};
}

/// Prints an error line on the host's stderr (or defmt) before a failing exit.
macro_rules! fail {
    ($($arg:tt)*) => {{
        #[cfg(not(feature = "defmt"))]
        cortex_m_semihosting::heprintln!($($arg)*);
        #[cfg(feature = "defmt")]
        defmt::error!("firmware failed");
    }};
}

const CHUNK: usize = 512;

#[entry]
fn main() -> ! {
    let mut cmdline = [0u8; 256];
    let mut names: [&[u8]; 2] = [b"stream.bin", b"results.bin"];
    let mut name_bufs = [[0u8; 120]; 2];
    if let Ok(line) = semihosting_io::command_line(&mut cmdline) {
        for (i, word) in line
            .split(|&b| b == b' ')
            .filter(|w| !w.is_empty())
            .skip(1)
            .take(2)
            .enumerate()
        {
            names[i] = word;
        }
    }
    let mut cnames: [&CStr; 2] = [c"", c""];
    for i in 0..2 {
        let n = names[i].len().min(name_bufs[i].len() - 1);
        name_bufs[i][..n].copy_from_slice(&names[i][..n]);
    }
    for i in 0..2 {
        cnames[i] = match CStr::from_bytes_until_nul(&name_bufs[i]) {
            Ok(c) => c,
            Err(_) => exit_failure(),
        };
    }
    let mut input = match HostFile::open(cnames[0], Mode::ReadBinary) {
        Ok(f) => f,
        Err(e) => {
            fail!("cannot open input {:?}: {}", cnames[0], e);
            exit_failure()
        }
    };
    let mut output = match HostFile::open(cnames[1], Mode::WriteBinary) {
        Ok(f) => f,
        Err(e) => {
            fail!("cannot open output {:?}: {}", cnames[1], e);
            exit_failure()
        }
    };
    let mut chunk = [0u8; CHUNK];
    let mut total = 0usize;
    loop {
        let n = match input.read(&mut chunk) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) => {
                fail!("reading input: {}", e);
                exit_failure()
            }
        };
        total += n;
        if let Err(e) = output.write_all(&chunk[..n]) {
            fail!("writing output: {}", e);
            exit_failure()
        }
    }
    figure!("bytes_in", total);
    figure!("stack_size_bytes", stack::size_bytes());
    figure!("stack_high_water_bytes", stack::high_water_mark_bytes());
    drop(output);
    drop(input);
    debug::exit(EXIT_SUCCESS);
    // Unreachable under QEMU; on a board without a debugger, stop here.
    cortex_m::asm::udf()
}

/// Leaves QEMU with a failing exit status (and never returns).
fn exit_failure() -> ! {
    debug::exit(EXIT_FAILURE);
    // Unreachable under QEMU; on a board without a debugger, stop here.
    cortex_m::asm::udf()
}

#[exception]
unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
    fail!("HardFault at pc={:#010x}", frame.pc());
    exit_failure()
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    #[cfg(not(feature = "defmt"))]
    cortex_m_semihosting::heprintln!("panic: {}", info);
    #[cfg(feature = "defmt")]
    {
        let _ = info;
        defmt::error!("panic");
    }
    exit_failure()
}
