//! The USART links of the STM32F405 behind `embedded_io::{Read, Write}`: the scanline stream
//! comes in on USART3, received byte by byte in its interrupt into a queue that the
//! processing loop drains into the core's ring; the output packets leave on USART6 with a
//! blocking transmit.
//!
//! The receive interrupt never waits: a byte that finds the queue full is counted
//! ([`RxCounters::dropped_full`]), and so is a byte the hardware lost because the interrupt
//! came too late (an overrun, [`RxCounters::overruns`]). The driver touches only the USART's
//! own registers (SR, DR, BRR, CR1): clocks and pins are the caller's (the board sets them
//! up; QEMU's model needs neither).
// The QEMU test's end of stream, ready byte and progress are unused by the board build.
#![cfg_attr(not(feature = "usart"), allow(dead_code))]

use core::convert::Infallible;
use core::ptr::addr_of_mut;
use core::sync::atomic::{AtomicU32, Ordering};

use heapless::spsc::{Consumer, Producer, Queue};
use stm32f4xx_hal::pac::{self, interrupt, usart1::RegisterBlock, Interrupt, NVIC};

use crate::ticks;

/// Bytes the receive queue holds between the interrupt and the processing loop: what arrives
/// while the kernel works on one line (at 921 600 baud, 92 bytes per millisecond).
pub const RX_QUEUE_BYTES: usize = 8192;

/// The byte [`RxLink::announce_ready`] sends in the QEMU test (ASCII ACK).
pub const READY: u8 = 0x06;

// SR bits (RM0090 §30.6.1).
const SR_PE: u16 = 1 << 0;
const SR_FE: u16 = 1 << 1;
const SR_NF: u16 = 1 << 2;
const SR_ORE: u16 = 1 << 3;
const SR_RXNE: u16 = 1 << 5;
const SR_TC: u16 = 1 << 6;
const SR_TXE: u16 = 1 << 7;
// CR1 bits.
const CR1_RE: u16 = 1 << 2;
const CR1_TE: u16 = 1 << 3;
const CR1_RXNEIE: u16 = 1 << 5;
const CR1_UE: u16 = 1 << 13;

/// The queue from the receive interrupt to the processing loop (one slot stays free).
static mut RX_QUEUE: Queue<u8, { RX_QUEUE_BYTES + 1 }> = Queue::new();
/// The producer half, used only by the USART3 interrupt once [`RxLink::usart3`] has set it.
static mut RX_PRODUCER: Option<Producer<'static, u8>> = None;

static RX_BYTES: AtomicU32 = AtomicU32::new(0);
static RX_DROPPED_FULL: AtomicU32 = AtomicU32::new(0);
static RX_OVERRUNS: AtomicU32 = AtomicU32::new(0);
static RX_LINE_ERRORS: AtomicU32 = AtomicU32::new(0);
static RX_QUEUE_HIGH_WATER: AtomicU32 = AtomicU32::new(0);

/// The receive counters so far (from any context: the link itself may be borrowed by the
/// processing loop).
pub fn rx_counters() -> RxCounters {
    RxCounters {
        received: RX_BYTES.load(Ordering::Relaxed),
        dropped_full: RX_DROPPED_FULL.load(Ordering::Relaxed),
        overruns: RX_OVERRUNS.load(Ordering::Relaxed),
        line_errors: RX_LINE_ERRORS.load(Ordering::Relaxed),
        queue_high_water: RX_QUEUE_HIGH_WATER.load(Ordering::Relaxed),
    }
}

/// What the receive side counted.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "board", derive(defmt::Format))]
pub struct RxCounters {
    /// Bytes the interrupt put into the queue.
    pub received: u32,
    /// Bytes lost because the queue was full (the processing loop fell behind).
    pub dropped_full: u32,
    /// Overruns: a byte arrived before the interrupt read the previous one (one or more
    /// bytes lost in the hardware).
    pub overruns: u32,
    /// Bytes with a framing, noise or parity error (kept: the packet CRC judges them).
    pub line_errors: u32,
    /// Most bytes seen waiting in the queue when the processing loop came to drain it.
    pub queue_high_water: u32,
}

/// The BRR value for `baud` on a USART clocked at `pclk_hz` (16× oversampling, rounded to
/// the nearest sixteenth; BRR is a 16-bit register, so at most 65 535).
pub const fn brr(pclk_hz: u32, baud: u32) -> u16 {
    let v = (pclk_hz + baud / 2) / baud;
    if v > u16::MAX as u32 {
        u16::MAX
    } else {
        v as u16
    }
}

/// When a blocking read gives up waiting and reports the end of the stream.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EndOfStream {
    /// Never: a board's link is open for ever.
    #[cfg_attr(not(feature = "board"), allow(dead_code))]
    Never,
    /// After this many bytes in all, or when no byte came for `idle_ms` milliseconds
    /// ([`RxLink::timed_out`] tells which).
    After {
        /// Bytes the stream has.
        bytes: u64,
        /// Longest silence before the link is taken as stalled.
        idle_ms: u32,
    },
}

/// The receive side of USART3.
pub struct RxLink {
    regs: &'static RegisterBlock,
    queue: Consumer<'static, u8>,
    end: EndOfStream,
    taken: u64,
    timed_out: bool,
    on_wait: fn(),
}

impl RxLink {
    /// Sets USART3 up at `brr` (see [`brr`]) for 8N1 receive and transmit, and enables its
    /// receive interrupt. `on_wait` runs each time a read finds the queue empty and before
    /// it sleeps (the board feeds its watchdog there). Returns `None` if called twice.
    pub fn usart3(brr: u16, end: EndOfStream, on_wait: fn()) -> Option<Self> {
        // SAFETY: runs before the USART3 interrupt is unmasked, so nothing else touches the
        // queue or the producer slot; `RX_PRODUCER.is_some()` guards a second call.
        let consumer = unsafe {
            let producer = &mut *addr_of_mut!(RX_PRODUCER);
            if producer.is_some() {
                return None;
            }
            let (p, c) = (*addr_of_mut!(RX_QUEUE)).split();
            *producer = Some(p);
            c
        };
        // SAFETY: USART3's registers are used only by this link and its interrupt.
        let regs = unsafe { &*pac::USART3::ptr() };
        regs.cr1().write(|w| unsafe { w.bits(0) });
        regs.brr().write(|w| unsafe { w.bits(brr) });
        regs.cr1()
            .write(|w| unsafe { w.bits(CR1_UE | CR1_RE | CR1_TE | CR1_RXNEIE) });
        // SAFETY: the handler below only uses the producer set above.
        unsafe { NVIC::unmask(Interrupt::USART3) };
        Some(Self {
            regs,
            queue: consumer,
            end,
            taken: 0,
            timed_out: false,
            on_wait,
        })
    }

    /// Sends one byte back on the input link's transmit line (QEMU's test feeder waits for
    /// it: bytes that reach QEMU's USART model before the receiver is enabled are lost).
    pub fn announce_ready(&mut self, byte: u8) {
        while self.regs.sr().read().bits() & SR_TXE == 0 {}
        self.regs.dr().write(|w| unsafe { w.bits(u16::from(byte)) });
    }

    /// Bytes handed to the processing loop so far.
    pub fn taken(&self) -> u64 {
        self.taken
    }

    /// Whether the stream ended because the line went silent rather than after all its bytes.
    pub fn timed_out(&self) -> bool {
        self.timed_out
    }
}

impl embedded_io::ErrorType for RxLink {
    type Error = Infallible;
}

impl embedded_io::Read for RxLink {
    /// Blocks (sleeping between interrupts) until at least one byte is there, then hands over
    /// as many as fit; `Ok(0)` is the end of the stream ([`EndOfStream`]).
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, Infallible> {
        let mut want = buf.len();
        if let EndOfStream::After { bytes, .. } = self.end {
            let left = bytes.saturating_sub(self.taken);
            want = want.min(usize::try_from(left).unwrap_or(usize::MAX));
        }
        if want == 0 {
            return Ok(0);
        }
        let waiting_since_ms = ticks::now_ms();
        loop {
            RX_QUEUE_HIGH_WATER.fetch_max(self.queue.len() as u32, Ordering::Relaxed);
            let mut n = 0;
            while n < want {
                match self.queue.dequeue() {
                    Some(b) => {
                        buf[n] = b;
                        n += 1;
                    }
                    None => break,
                }
            }
            if n > 0 {
                self.taken += n as u64;
                return Ok(n);
            }
            (self.on_wait)();
            if let EndOfStream::After { idle_ms, .. } = self.end {
                if ticks::now_ms().wrapping_sub(waiting_since_ms) >= idle_ms {
                    self.timed_out = true;
                    return Ok(0);
                }
            }
            // Sleep until the next interrupt (a byte or the tick). Interrupts are masked
            // across the check so one that lands between the check and WFI still wakes it.
            cortex_m::interrupt::free(|_| {
                if self.queue.is_empty() {
                    cortex_m::asm::wfi();
                }
            });
        }
    }
}

#[interrupt]
fn USART3() {
    // SAFETY: this handler is the only user of the producer and of USART3's DR once the link
    // is set up; it is never re-entered (one priority).
    let (regs, producer) = unsafe { (&*pac::USART3::ptr(), &mut *addr_of_mut!(RX_PRODUCER)) };
    let Some(producer) = producer.as_mut() else {
        return;
    };
    loop {
        let sr = regs.sr().read().bits();
        if sr & (SR_RXNE | SR_ORE) == 0 {
            break;
        }
        if sr & SR_ORE != 0 {
            RX_OVERRUNS.fetch_add(1, Ordering::Relaxed);
        }
        if sr & (SR_PE | SR_FE | SR_NF) != 0 {
            RX_LINE_ERRORS.fetch_add(1, Ordering::Relaxed);
        }
        // Reading DR after SR clears RXNE and the error flags.
        let byte = regs.dr().read().bits() as u8;
        match producer.enqueue(byte) {
            Ok(()) => RX_BYTES.fetch_add(1, Ordering::Relaxed),
            Err(_) => RX_DROPPED_FULL.fetch_add(1, Ordering::Relaxed),
        };
    }
}

/// The transmit side of USART6: each byte waits for the data register to empty.
pub struct TxLink {
    regs: &'static RegisterBlock,
}

impl TxLink {
    /// Sets USART6 up at `brr` (see [`brr`]) for 8N1 transmit only.
    pub fn usart6(brr: u16) -> Self {
        // SAFETY: USART6's registers are used only by this link.
        let regs = unsafe { &*pac::USART6::ptr() };
        regs.cr1().write(|w| unsafe { w.bits(0) });
        regs.brr().write(|w| unsafe { w.bits(brr) });
        regs.cr1().write(|w| unsafe { w.bits(CR1_UE | CR1_TE) });
        Self { regs }
    }
}

impl embedded_io::ErrorType for TxLink {
    type Error = Infallible;
}

impl embedded_io::Write for TxLink {
    fn write(&mut self, buf: &[u8]) -> Result<usize, Infallible> {
        for &b in buf {
            while self.regs.sr().read().bits() & SR_TXE == 0 {}
            self.regs.dr().write(|w| unsafe { w.bits(u16::from(b)) });
        }
        Ok(buf.len())
    }

    /// Waits until the last byte has left the shift register.
    fn flush(&mut self) -> Result<(), Infallible> {
        while self.regs.sr().read().bits() & SR_TC == 0 {}
        Ok(())
    }
}
