//! curbtrace firmware for the STM32F405 (Cortex-M4F): the QEMU build (`netduinoplus2`, the
//! default; semihosting files or, with the `usart` feature, USART links) or the board build
//! (feature `board`: clocks, pins, USART or SPI links, watchdog, defmt over RTT).
#![no_std]
#![no_main]

mod stack;

#[cfg(not(feature = "board"))]
mod qemu;
#[cfg(not(any(feature = "usart", feature = "board")))]
mod realtime;
#[cfg(not(feature = "board"))]
mod semihosting_io;

#[cfg(feature = "board")]
mod board;
#[cfg(feature = "board")]
mod panic_record;
#[cfg(feature = "spi-input")]
mod spi_slave;

#[cfg(any(feature = "usart", feature = "board"))]
mod ticks;
#[cfg(any(feature = "usart", feature = "board"))]
mod usart;
