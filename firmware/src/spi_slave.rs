//! The scanner front end's stream on SPI2 as a receive-only slave, moved by DMA1 stream 3
//! (channel 0) into a circular buffer, behind `embedded_io::Read` — the input for a scanner
//! at full rate, where a byte interrupt per byte would not keep up.
//!
//! The DMA's half-transfer and transfer-complete interrupts count the half buffers it has
//! filled; the reader tracks which half it is in. When the DMA has filled two halves more than
//! the reader has passed, it has written over bytes the reader had not taken: the reader jumps
//! to where the DMA is and counts what it skipped ([`SpiCounters::overrun_bytes`]); the
//! stream's packet CRCs and sequence numbers then show the gap downstream.
//!
//! SPI2 is a slave with software NSS (always selected: the front end is the only master),
//! mode 0, 8-bit frames, MSB first. Its clock may run up to half of APB1 (21 MHz at 168 MHz).

use core::convert::Infallible;
use core::ptr::addr_of;
use core::sync::atomic::{AtomicU32, Ordering};

use stm32f4xx_hal::pac::{self, interrupt, Interrupt, NVIC};

/// The DMA buffer: two halves, each a few milliseconds of stream at a 2 MB/s link.
pub const DMA_BYTES: usize = 16384;
const HALF: usize = DMA_BYTES / 2;

/// DMA1 stream 3 is SPI2_RX on channel 0 (RM0090 table 42).
const STREAM: usize = 3;
// LISR/LIFCR bits of stream 3.
const TCIF3: u32 = 1 << 27;
const HTIF3: u32 = 1 << 26;
const TEIF3: u32 = 1 << 25;
const DMEIF3: u32 = 1 << 24;
const FEIF3: u32 = 1 << 22;
// DMA stream CR bits.
const CR_EN: u32 = 1 << 0;
const CR_TEIE: u32 = 1 << 2;
const CR_HTIE: u32 = 1 << 3;
const CR_TCIE: u32 = 1 << 4;
const CR_CIRC: u32 = 1 << 8;
const CR_MINC: u32 = 1 << 10;
// SPI CR1/CR2 bits.
const SPI_CR1_SPE: u16 = 1 << 6;
const SPI_CR1_SSM: u16 = 1 << 9;
const SPI_CR1_RXONLY: u16 = 1 << 10;
const SPI_CR2_RXDMAEN: u16 = 1 << 0;

#[repr(align(4))]
struct Buffer([u8; DMA_BYTES]);
static mut BUFFER: Buffer = Buffer([0; DMA_BYTES]);

/// Half buffers the DMA has filled since start.
static HALVES: AtomicU32 = AtomicU32::new(0);
static DMA_ERRORS: AtomicU32 = AtomicU32::new(0);
static TAKEN: AtomicU32 = AtomicU32::new(0);
static OVERRUN_BYTES: AtomicU32 = AtomicU32::new(0);

/// What the SPI input counted (wrapping 32-bit counts).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, defmt::Format)]
pub struct SpiCounters {
    /// Bytes handed to the processing loop.
    pub taken: u32,
    /// Bytes the DMA wrote over before the reader took them (skipped).
    pub overrun_bytes: u32,
    /// DMA transfer or FIFO errors.
    pub dma_errors: u32,
}

/// The counters so far (from any context: the input may be borrowed by the processing loop).
pub fn counters() -> SpiCounters {
    SpiCounters {
        taken: TAKEN.load(Ordering::Relaxed),
        overrun_bytes: OVERRUN_BYTES.load(Ordering::Relaxed),
        dma_errors: DMA_ERRORS.load(Ordering::Relaxed),
    }
}

/// The SPI2 slave input.
pub struct SpiSlaveRx {
    read_pos: usize,
    halves_passed: u32,
    on_wait: fn(),
}

impl SpiSlaveRx {
    /// Starts SPI2 as a receive-only slave with circular DMA. The caller has enabled the
    /// clocks of SPI2 and DMA1 and put SCK (PB13) and MOSI (PB15) on alternate function 5.
    /// `on_wait` runs each time a read finds no new byte, before it sleeps.
    pub fn spi2(on_wait: fn()) -> Self {
        // SAFETY: SPI2, DMA1 stream 3 and the buffer are used only by this input and its
        // interrupt; the buffer's address is handed to the DMA once, here.
        let (spi, dma) = unsafe { (&*pac::SPI2::ptr(), &*pac::DMA1::ptr()) };
        let st = dma.st(STREAM);
        st.cr().write(|w| unsafe { w.bits(0) });
        while st.cr().read().bits() & CR_EN != 0 {}
        dma.lifcr()
            .write(|w| unsafe { w.bits(TCIF3 | HTIF3 | TEIF3 | DMEIF3 | FEIF3) });
        st.par()
            .write(|w| unsafe { w.bits(spi.dr().as_ptr() as u32) });
        st.m0ar()
            .write(|w| unsafe { w.bits(addr_of!(BUFFER) as u32) });
        st.ndtr().write(|w| unsafe { w.bits(DMA_BYTES as u32) });
        // Channel 0, byte to byte, peripheral to memory, circular, memory increment.
        st.cr()
            .write(|w| unsafe { w.bits(CR_MINC | CR_CIRC | CR_TCIE | CR_HTIE | CR_TEIE) });
        st.cr().modify(|r, w| unsafe { w.bits(r.bits() | CR_EN) });
        spi.cr2().write(|w| unsafe { w.bits(SPI_CR2_RXDMAEN) });
        // Slave (MSTR = 0), mode 0, 8-bit, software NSS held low (SSI = 0), receive only.
        spi.cr1()
            .write(|w| unsafe { w.bits(SPI_CR1_SSM | SPI_CR1_RXONLY | SPI_CR1_SPE) });
        // SAFETY: the handler only counts halves and clears the stream's flags.
        unsafe { NVIC::unmask(Interrupt::DMA1_STREAM3) };
        Self {
            read_pos: 0,
            halves_passed: 0,
            on_wait,
        }
    }

    /// Where the DMA writes next and how many halves it has filled, read consistently.
    fn producer() -> (usize, u32) {
        // SAFETY: NDTR of stream 3 is only read here.
        let st = unsafe { (*pac::DMA1::ptr()).st(STREAM) };
        loop {
            let before = HALVES.load(Ordering::Acquire);
            let left = st.ndtr().read().bits() as usize;
            if HALVES.load(Ordering::Acquire) == before {
                return ((DMA_BYTES - left) % DMA_BYTES, before);
            }
        }
    }
}

impl embedded_io::ErrorType for SpiSlaveRx {
    type Error = Infallible;
}

impl embedded_io::Read for SpiSlaveRx {
    /// Blocks (sleeping between interrupts) until the DMA has written past the read position,
    /// then copies what it can. The stream never ends.
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, Infallible> {
        if buf.is_empty() {
            return Ok(0);
        }
        loop {
            let (write_pos, halves) = Self::producer();
            let ahead = halves.wrapping_sub(self.halves_passed);
            if ahead >= 2 {
                // The DMA went round and over unread bytes: skip to where it is.
                let skipped = (ahead - 1).wrapping_mul(HALF as u32);
                OVERRUN_BYTES.fetch_add(skipped, Ordering::Relaxed);
                self.read_pos = write_pos;
                self.halves_passed = halves;
                continue;
            }
            let available = if ahead == 0 && write_pos >= self.read_pos {
                write_pos - self.read_pos
            } else {
                (write_pos + DMA_BYTES - self.read_pos) % DMA_BYTES
            };
            if available == 0 {
                (self.on_wait)();
                cortex_m::asm::wfi();
                continue;
            }
            // Up to the end of the current half, so that crossing a half is one step.
            let half_end = (self.read_pos / HALF + 1) * HALF;
            let n = buf.len().min(available).min(half_end - self.read_pos);
            // SAFETY: these bytes lie behind the DMA's write position, in a half it will not
            // write again before the reader passes it (checked above).
            // Read through a raw pointer: the DMA, not the program, writes the buffer.
            unsafe {
                let src = addr_of!(BUFFER.0).cast::<u8>().add(self.read_pos);
                core::ptr::copy_nonoverlapping(src, buf.as_mut_ptr(), n);
            }
            self.read_pos += n;
            if self.read_pos == half_end {
                self.halves_passed = self.halves_passed.wrapping_add(1);
                self.read_pos %= DMA_BYTES;
            }
            TAKEN.fetch_add(n as u32, Ordering::Relaxed);
            return Ok(n);
        }
    }
}

#[interrupt]
fn DMA1_STREAM3() {
    // SAFETY: reads and clears only stream 3's flags.
    let dma = unsafe { &*pac::DMA1::ptr() };
    let isr = dma.lisr().read().bits();
    let mut halves = 0;
    if isr & HTIF3 != 0 {
        halves += 1;
    }
    if isr & TCIF3 != 0 {
        halves += 1;
    }
    if isr & (TEIF3 | DMEIF3 | FEIF3) != 0 {
        DMA_ERRORS.fetch_add(1, Ordering::Relaxed);
    }
    dma.lifcr()
        .write(|w| unsafe { w.bits(isr & (TCIF3 | HTIF3 | TEIF3 | DMEIF3 | FEIF3)) });
    HALVES.fetch_add(halves, Ordering::Release);
}
