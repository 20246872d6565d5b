//! The board build (feature `board`) for an Adafruit Feather STM32F405 Express: STM32F405RG,
//! 12 MHz crystal, SWD pads for a debug probe.
//!
//! | what | pin (Feather label) | peripheral |
//! |---|---|---|
//! | scanner stream in | PB11 (RX) | USART3 RX, AF7, [`INPUT_BAUD`] 8N1 |
//! | (unused transmit) | PB10 (TX) | USART3 TX, AF7 |
//! | output packets out | PC6 (D6) | USART6 TX, AF8, [`OUTPUT_BAUD`] 8N1 |
//! | scanner stream in, feature `spi-input` | PB13 (SCK), PB15 (MO) | SPI2 slave, AF5 |
//! | activity LED (toggles per scanline) | PC1 (D13, red LED) | GPIO output |
//!
//! Clocks: the 12 MHz crystal through the PLL to 168 MHz (AHB 168, APB1 42, APB2 84 MHz).
//! The independent watchdog resets the chip when the processing loop stops feeding it for
//! [`WATCHDOG_MS`]; a panic or HardFault records its reason and resets (`panic_record`). The
//! counters go out over defmt (RTT) every [`STATUS_EVERY_MS`].

use core::ptr::addr_of_mut;

use cortex_m_rt::entry;
use embedded_hal::digital::OutputPin;
use stm32f4xx_hal::{
    pac,
    prelude::*,
    rcc::{Config, Enable},
    watchdog::IndependentWatchdog,
};

use curbtrace_core::wire::MAX_PACKET_LEN;
use curbtrace_firmware::app::{self, Node, Summary};

use crate::{panic_record, stack, ticks, usart};

// The defmt global logger: frames go into an RTT buffer that the probe reads.
use defmt_rtt as _;

/// The Feather's crystal.
pub const HSE_HZ: u32 = 12_000_000;
/// The core clock.
pub const SYSCLK_HZ: u32 = 168_000_000;
#[cfg(not(feature = "spi-input"))]
/// Input link speed (USART3): about 92 kB/s, some 4 500 points/s of today's 20.4-byte point
/// records.
pub const INPUT_BAUD: u32 = 921_600;
/// Output link speed (USART6, on APB2).
pub const OUTPUT_BAUD: u32 = 921_600;
/// The watchdog's period: far above one line's kernel time (about 16 ms for 2 000 points).
pub const WATCHDOG_MS: u32 = 500;
/// How often the counters are logged.
pub const STATUS_EVERY_MS: u32 = 5_000;

#[entry]
fn main() -> ! {
    panic_record::report_previous();
    let (Some(dp), Some(cp)) = (pac::Peripherals::take(), cortex_m::Peripherals::take()) else {
        panic_record::record_and_reset(format_args!("peripherals taken twice"))
    };
    let mut rcc = dp
        .RCC
        .freeze(Config::hse(HSE_HZ.Hz()).sysclk(SYSCLK_HZ.Hz()));
    let clocks = rcc.clocks;
    defmt::info!(
        "curbtrace firmware: sysclk {} Hz, pclk1 {} Hz, pclk2 {} Hz",
        clocks.sysclk().raw(),
        clocks.pclk1().raw(),
        clocks.pclk2().raw()
    );
    ticks::start(cp.SYST, clocks.sysclk().raw());

    let mut watchdog = IndependentWatchdog::new(dp.IWDG);
    watchdog.start(WATCHDOG_MS.millis());

    let gpiob = dp.GPIOB.split(&mut rcc);
    let gpioc = dp.GPIOC.split(&mut rcc);
    let mut led = gpioc.pc1.into_push_pull_output();
    let _output_tx = gpioc.pc6.into_alternate::<8>();
    pac::USART6::enable(&mut rcc);
    let mut output = usart::TxLink::usart6(usart::brr(clocks.pclk2().raw(), OUTPUT_BAUD));

    let (node, packet) = working_memory();
    let stack_init = stack::repaint();
    defmt::info!(
        "stack: {} of {} bytes used by start-up",
        stack_init,
        stack::size_bytes()
    );

    #[cfg(not(feature = "spi-input"))]
    let mut input = {
        let _tx = gpiob.pb10.into_alternate::<7>();
        let _rx = gpiob.pb11.into_alternate::<7>();
        pac::USART3::enable(&mut rcc);
        let brr = usart::brr(clocks.pclk1().raw(), INPUT_BAUD);
        let Some(rx) = usart::RxLink::usart3(brr, usart::EndOfStream::Never, feed_watchdog) else {
            panic_record::record_and_reset(format_args!("USART3 set up twice"))
        };
        rx
    };
    #[cfg(feature = "spi-input")]
    let mut input = {
        let _sck = gpiob.pb13.into_alternate::<5>();
        let _mosi = gpiob.pb15.into_alternate::<5>();
        pac::SPI2::enable(&mut rcc);
        pac::DMA1::enable(&mut rcc);
        crate::spi_slave::SpiSlaveRx::spi2(feed_watchdog)
    };
    defmt::info!("links up: waiting for the scanner stream");

    let mut last_status = ticks::now_ms();
    let mut last_lines = 0;
    let result = app::run_observed(node, &mut input, &mut output, packet, |pipeline, sum| {
        feed_watchdog();
        let counters = pipeline.counters();
        if counters.kernel_lines != last_lines {
            last_lines = counters.kernel_lines;
            blink(&mut led, last_lines);
        }
        let now = ticks::now_ms();
        if now.wrapping_sub(last_status) >= STATUS_EVERY_MS {
            last_status = now;
            status(&counters, sum);
            #[cfg(not(feature = "spi-input"))]
            defmt::info!("usart3: {}", usart::rx_counters());
            #[cfg(feature = "spi-input")]
            defmt::info!("spi2: {}", crate::spi_slave::counters());
        }
    });
    // The links never end, so `run` returns only on an error.
    match result {
        Ok(summary) => panic_record::record_and_reset(format_args!(
            "the input link ended after {} lines",
            summary.counters.kernel_lines
        )),
        Err(e) => panic_record::record_and_reset(format_args!("processing failed: {e:?}")),
    }
}

/// Feeds the independent watchdog (its key register; safe from any context).
fn feed_watchdog() {
    // SAFETY: writing the reload key 0xAAAA to IWDG_KR only restarts the countdown.
    unsafe { (*pac::IWDG::ptr()).kr().write(|w| w.bits(0xAAAA)) };
}

/// The LED follows the parity of the line count: it toggles once per scanline.
fn blink(led: &mut impl OutputPin, lines: u64) {
    // A GPIO write on this part cannot fail (the error type is Infallible).
    let _ = if lines.is_multiple_of(2) {
        led.set_low()
    } else {
        led.set_high()
    };
}

/// Logs the counters to watch (docs/flashing.md, "Counters").
fn status(c: &curbtrace_core::pipeline::PipelineCounters, sum: &Summary) {
    let i = &c.ingest;
    defmt::info!(
        "lines {} points {} | ring drops {} crc {} seq gaps {} garbage {} truncated {} | configs {} rejected {} | packets out {} bytes out {} | stack {} B",
        c.kernel_lines,
        i.points_in,
        i.bytes_dropped_full,
        i.crc_errors,
        i.seq_gaps,
        i.bytes_garbage,
        i.points_truncated,
        c.configs_applied,
        c.configs_rejected,
        sum.packets_out,
        sum.bytes_out,
        stack::high_water_mark_bytes()
    );
}

/// The core's working memory as statics (see the QEMU build); called once.
fn working_memory() -> (&'static mut Node, &'static mut [u8; MAX_PACKET_LEN]) {
    static mut NODE: Node = Node::new();
    static mut PACKET: [u8; MAX_PACKET_LEN] = [0; MAX_PACKET_LEN];
    // SAFETY: called once from main and no interrupt touches these.
    unsafe { (&mut *addr_of_mut!(NODE), &mut *addr_of_mut!(PACKET)) }
}
