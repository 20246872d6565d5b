//! The QEMU build (`netduinoplus2`): the test harness's firmware.
//!
//! Reads a recorded scanline byte stream (the output of `curbtrace replay`) from a host file
//! in chunks into the core's ring buffer the way a DMA channel would, runs the kernel on
//! every completed scanline with the parameters from the stream's config packet, writes the
//! output packets to another host file, prints its figures and exits 0 through semihosting.
//! With `--usart=BYTES` (feature `usart`) the stream comes in on USART3 and the packets go out
//! on USART6 instead, and semihosting carries only the command line and the figures. Any
//! panic or HardFault exits non-zero.
//!
//! File names come from the semihosting command line
//! (`-semihosting-config enable=on,target=native,arg=fw,arg=IN,arg=OUT`); defaults
//! `stream.bin` and `results.bin`.

use crate::semihosting_io::{self, HostFile, Mode};
use crate::stack;
use curbtrace_firmware::args::{self, Command};

use core::ffi::CStr;
use core::ptr::addr_of_mut;
use cortex_m_rt::{entry, exception, ExceptionFrame};
use cortex_m_semihosting::debug::{self, EXIT_FAILURE, EXIT_SUCCESS};

use curbtrace_core::wire::MAX_PACKET_LEN;
use curbtrace_firmware::app::{self, Node, Summary, MAX_POINTS, RING};

// The defmt global logger: frames go to the host's stdout over semihosting.
#[cfg(feature = "defmt")]
use defmt_semihosting as _;

/// Prints one `name: value` figure line (semihosting stdout, or defmt with `defmt`).
macro_rules! figure {
    ($name:literal, $value:expr) => {{
        #[cfg(not(feature = "defmt"))]
        cortex_m_semihosting::hprintln!(concat!($name, ": {}"), $value);
        #[cfg(feature = "defmt")]
        defmt::println!("{=str}: {}", $name, $value);
    }};
}

/// Prints an error line on the host's stderr before a failing exit (with `defmt`: the
/// message's format string as a defmt error; the values need semihosting's formatter).
macro_rules! fail {
    ($fmt:literal $(, $arg:expr)* $(,)?) => {{
        #[cfg(not(feature = "defmt"))]
        cortex_m_semihosting::heprintln!($fmt $(, $arg)*);
        #[cfg(feature = "defmt")]
        {
            $(let _ = &$arg;)*
            defmt::error!("{=str}", $fmt);
        }
    }};
}

#[entry]
fn main() -> ! {
    let mut cmdline = [0u8; 512];
    let len = match semihosting_io::command_line(&mut cmdline[..511]) {
        Ok(line) => line.len(),
        Err(_) => 0,
    };
    let (input_name, output_name) = match args::parse(&mut cmdline, len) {
        Ok(Command::Process { input, output }) => (input, output),
        Ok(Command::Usart { bytes }) => over_usarts(bytes),
        Ok(Command::Realtime {
            bytes_per_s,
            input,
            output,
        }) => realtime_run(bytes_per_s, input, output),
        Ok(Command::SelfTestOverflow) => {
            let mut seed = [0u8; 64];
            figure!("never_printed", selftest::overflow(&mut seed, u32::MAX));
            exit_failure()
        }
        Ok(Command::SelfTestHardFault) => {
            figure!("never_printed", selftest::hardfault());
            exit_failure()
        }
        Ok(Command::SelfTestPanic) => selftest::panic(),
        Err(e) => {
            fail!("bad command line: {:?}", e);
            exit_failure()
        }
    };
    over_files(input_name, output_name)
}

/// Processes the host file `input_name` into `output_name` and exits. Not inlined, so that
/// its frame and the `--usart` path's are not both on the stack.
#[inline(never)]
fn over_files(input_name: &CStr, output_name: &CStr) -> ! {
    let mut input = match HostFile::open(input_name, Mode::ReadBinary) {
        Ok(f) => f,
        Err(e) => {
            fail!("cannot open input {:?}: {}", input_name, e);
            exit_failure()
        }
    };
    let mut output = match HostFile::open(output_name, Mode::WriteBinary) {
        Ok(f) => f,
        Err(e) => {
            fail!("cannot open output {:?}: {}", output_name, e);
            exit_failure()
        }
    };
    let (node, packet) = working_memory();
    // Measure the processing loop's stack on its own from here (start-up: opening files).
    let stack_init = stack::repaint();
    let summary = match app::run(node, &mut input, &mut output, packet) {
        Ok(s) => s,
        Err(e) => {
            fail!("processing failed: {:?}", e);
            exit_failure()
        }
    };
    figures(&summary, stack_init);
    drop(output);
    drop(input);
    debug::exit(EXIT_SUCCESS);
    // Unreachable under QEMU; on a board without a debugger, stop here.
    cortex_m::asm::udf()
}

/// `--realtime=BYTES_PER_S IN OUT`: `over_files` with the input delivered by a timer
/// interrupt at that rate (`realtime.rs`); the figures add the delivery's.
#[cfg(not(any(feature = "usart", feature = "board")))]
#[inline(never)]
fn realtime_run(bytes_per_s: u32, input_name: &CStr, output_name: &CStr) -> ! {
    use crate::realtime;
    let (Ok(file), Ok(mut output)) = (
        HostFile::open(input_name, Mode::ReadBinary),
        HostFile::open(output_name, Mode::WriteBinary),
    ) else {
        fail!("cannot open {:?} or {:?}", input_name, output_name);
        exit_failure()
    };
    let Some(p) = cortex_m::Peripherals::take() else {
        fail!("core peripherals already taken");
        exit_failure()
    };
    let (node, packet) = working_memory();
    let stack_init = stack::repaint();
    let Some(mut input) = realtime::start(p.SYST, file, bytes_per_s) else {
        fail!("the delivery queue is already in use");
        exit_failure()
    };
    let summary = match app::run(node, &mut input, &mut output, packet) {
        Ok(s) => s,
        Err(e) => {
            fail!("processing failed: {:?}", e);
            exit_failure()
        }
    };
    figures(&summary, stack_init);
    let f = realtime::figures();
    figure!("realtime_bytes_per_s", bytes_per_s);
    figure!("realtime_tick_hz", realtime::TICK_HZ);
    figure!("realtime_ticks", f.ticks);
    figure!("realtime_delivered_bytes", f.delivered);
    figure!("realtime_dropped_bytes", f.dropped);
    figure!("realtime_queue_bytes", realtime::QUEUE);
    figure!("realtime_queue_high_water_bytes", f.high_water);
    drop(output);
    debug::exit(EXIT_SUCCESS);
    cortex_m::asm::udf()
}

/// `--realtime` needs SysTick, which the USART and board builds use for their clock.
#[cfg(any(feature = "usart", feature = "board"))]
fn realtime_run(_: u32, _: &CStr, _: &CStr) -> ! {
    fail!("--realtime is in the plain QEMU build only (no `usart` feature)");
    exit_failure()
}

/// All the core's working memory, a `static` built by the core's `const fn` `Pipeline::new`
/// (its initial image is part of .data): it never passes through the stack. Called once.
fn working_memory() -> (&'static mut Node, &'static mut [u8; MAX_PACKET_LEN]) {
    static mut NODE: Node = Node::new();
    static mut PACKET: [u8; MAX_PACKET_LEN] = [0; MAX_PACKET_LEN];
    // SAFETY: called once from main and no interrupt touches these; these are the only
    // references.
    unsafe { (&mut *addr_of_mut!(NODE), &mut *addr_of_mut!(PACKET)) }
}

/// The run's figures, one `name: value` line each (firmware/check.sh reads them). Not inlined:
/// its formatting frames stay off the stack of the processing loop's caller.
#[inline(never)]
fn figures(summary: &Summary, stack_init: usize) {
    let c = &summary.counters.ingest;
    figure!("bytes_in", c.bytes_in);
    figure!("bytes_dropped_full", c.bytes_dropped_full);
    figure!("bytes_garbage", c.bytes_garbage);
    figure!("crc_errors", c.crc_errors);
    figure!("seq_gaps", c.seq_gaps);
    figure!("points_in", c.points_in);
    figure!("points_truncated", c.points_truncated);
    figure!("lines", summary.counters.kernel_lines);
    figure!("configs", summary.counters.configs_applied);
    figure!("configs_rejected", summary.counters.configs_rejected);
    figure!("kept", summary.kernel.kept);
    figure!("irregular", summary.kernel.irregular);
    figure!("no_neighbour", summary.kernel.no_neighbour);
    figure!("peaks", summary.kernel.peaks);
    figure!("outside_roi", summary.kernel.outside_roi);
    figure!("packets_out", summary.packets_out);
    figure!("bytes_out", summary.bytes_out);
    figure!("ring_bytes", RING);
    figure!("max_points", MAX_POINTS);
    figure!("stack_size_bytes", stack::size_bytes());
    figure!("stack_high_water_startup_bytes", stack_init);
    figure!("stack_high_water_run_bytes", stack::high_water_mark_bytes());
    figure!(
        "stack_high_water_bytes",
        stack_init.max(stack::high_water_mark_bytes())
    );
}

/// `--usart=BYTES`: the stream of `bytes` bytes in on USART3 (QEMU's fourth `-serial`, index
/// 2), the packets out on USART6 (index 5); the figures add the receive counters. Fails if
/// the stream stalls (no byte for [`USART_IDLE_MS`]) before all its bytes arrived.
#[cfg(feature = "usart")]
#[inline(never)]
fn over_usarts(bytes: u64) -> ! {
    use crate::{ticks, usart};
    use usart::{EndOfStream, RxLink, TxLink};

    // The clocks stay at reset (QEMU models no RCC): QEMU's USARTs ignore the baud rate and
    // its SysTick counts at the 168 MHz it gives the core.
    const QEMU_CORE_HZ: u32 = 168_000_000;
    const USART_IDLE_MS: u32 = 10_000;
    const BAUD_BRR: u16 = usart::brr(16_000_000, 921_600);
    let Some(cp) = cortex_m::Peripherals::take() else {
        fail!("core peripherals taken twice");
        exit_failure()
    };
    ticks::start(cp.SYST, QEMU_CORE_HZ);
    let end = EndOfStream::After {
        bytes,
        idle_ms: USART_IDLE_MS,
    };
    let Some(mut rx) = RxLink::usart3(BAUD_BRR, end, || {}) else {
        fail!("USART3 set up twice");
        exit_failure()
    };
    let mut tx = TxLink::usart6(BAUD_BRR);
    rx.announce_ready(usart::READY);
    let (node, packet) = working_memory();
    let stack_init = stack::repaint();
    let summary = match app::run(node, &mut rx, &mut tx, packet) {
        Ok(s) => s,
        Err(e) => {
            fail!("processing failed: {:?}", e);
            exit_failure()
        }
    };
    figures(&summary, stack_init);
    usart_figures();
    if rx.timed_out() {
        fail!(
            "USART3 went silent for {} ms after {} of {} bytes",
            USART_IDLE_MS,
            rx.taken(),
            bytes
        );
        exit_failure()
    }
    debug::exit(EXIT_SUCCESS);
    cortex_m::asm::udf()
}

/// The receive side's figures (see [`figures`] for why not inlined).
#[cfg(feature = "usart")]
#[inline(never)]
fn usart_figures() {
    use crate::{ticks, usart};
    let c = usart::rx_counters();
    figure!("usart_rx_bytes", c.received);
    figure!("usart_rx_dropped_full", c.dropped_full);
    figure!("usart_rx_overruns", c.overruns);
    figure!("usart_rx_line_errors", c.line_errors);
    figure!("usart_rx_queue_bytes", usart::RX_QUEUE_BYTES);
    figure!("usart_rx_queue_high_water", c.queue_high_water);
    figure!("usart_run_ms", ticks::now_ms());
}

#[cfg(not(feature = "usart"))]
fn over_usarts(_bytes: u64) -> ! {
    fail!("--usart needs the firmware built with the `usart` feature");
    exit_failure()
}

/// Failures provoked on request (`--selftest=…`), so scripts can check each one ends the
/// run with a non-zero exit status.
mod selftest {
    /// Recurses with 64-byte frames until the stack runs off the bottom of RAM.
    #[inline(never)]
    pub fn overflow(seed: &mut [u8; 64], n: u32) -> u32 {
        let mut frame = *seed;
        frame[(n % 64) as usize] = n as u8;
        if n == 0 {
            return 0;
        }
        // black_box keeps the frame alive across the call, so the recursion is not elided.
        overflow(&mut frame, n - 1) + u32::from(core::hint::black_box(frame)[3])
    }

    /// Reads from an address in the STM32F405's reserved gap between SRAM and the peripherals (BusFault → HardFault).
    pub fn hardfault() -> u32 {
        // SAFETY: deliberately faulting read; the HardFault handler ends the run.
        unsafe { core::ptr::read_volatile(0x3000_0000 as *const u32) }
    }

    pub fn panic() -> ! {
        panic!("self-test panic");
    }
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
