//! `--realtime=BYTES_PER_S IN OUT` (QEMU build): the stream arrives at the scanner's rate
//! instead of as fast as the loop asks. A SysTick interrupt at [`TICK_HZ`] plays the front
//! end's DMA: each tick it reads the bytes due by then from the host file into the producer
//! half of a [`Spsc`] queue; bytes that do not fit are read, discarded and counted, as a
//! real link would lose them. The main loop — the same `app::run` as every other build —
//! reads the consumer half and sleeps (`WFI`) when it is empty. Under QEMU's `-icount`
//! the guest's clock advances with the instructions it executes, so a run with no dropped
//! byte shows the loop keeping up at that rate (`firmware/realtime.sh`).

use core::cell::RefCell;
use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};

use cortex_m::interrupt::Mutex;
use cortex_m::peripheral::{syst::SystClkSource, SYST};
use cortex_m_rt::exception;
use curbtrace_firmware::spsc::{Consumer, Producer, Spsc};
use embedded_io::Read;

use crate::semihosting_io::{HostFile, SemihostingError};

/// The core clock QEMU's `netduinoplus2` runs SysTick from, Hz.
pub const CORE_HZ: u32 = 168_000_000;
/// Deliveries per second.
pub const TICK_HZ: u32 = 10_000;
/// The queue between the interrupt and the loop: it holds what arrives while the kernel
/// works on a line (a 2000-point line at 200 000 points/s is 10 ms, 41 KB of packets).
/// The RAM the part has left: the QEMU builds' pipeline ring is small (`app::RING`), so
/// the buffering is here, as the board's is in its ring.
pub const QUEUE: usize = 60 * 1024;

static QUEUE_MEM: Spsc<QUEUE> = Spsc::new();
static DONE: AtomicBool = AtomicBool::new(false);
static TICKS: AtomicU32 = AtomicU32::new(0);

/// The interrupt's state.
struct Feed {
    file: HostFile,
    producer: Producer<QUEUE>,
    bytes_per_s: u32,
    /// Remainder of bytes due, in 1/TICK_HZ bytes.
    acc: u32,
    dropped: u64,
    delivered: u64,
    /// Most bytes waiting in the queue at a tick.
    high_water: usize,
    scratch: [u8; 1024],
}

static FEED: Mutex<RefCell<Option<Feed>>> = Mutex::new(RefCell::new(None));

/// What the run counted on the producer side.
pub struct FeedFigures {
    /// Bytes delivered into the queue.
    pub delivered: u64,
    /// Bytes lost because the queue was full.
    pub dropped: u64,
    /// Ticks until the file ended.
    pub ticks: u32,
    /// Most bytes waiting in the queue at a tick.
    pub high_water: usize,
}

/// Starts delivering `file` at `bytes_per_s`; returns the consumer half as the loop's input.
pub fn start(mut syst: SYST, file: HostFile, bytes_per_s: u32) -> Option<Input> {
    let (producer, consumer) = QUEUE_MEM.split()?;
    cortex_m::interrupt::free(|cs| {
        FEED.borrow(cs).replace(Some(Feed {
            file,
            producer,
            bytes_per_s,
            acc: 0,
            dropped: 0,
            delivered: 0,
            high_water: 0,
            scratch: [0; 1024],
        }))
    });
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(CORE_HZ / TICK_HZ - 1);
    syst.clear_current();
    syst.enable_interrupt();
    syst.enable_counter();
    Some(Input { consumer })
}

/// The producer side's figures (after the run).
pub fn figures() -> FeedFigures {
    cortex_m::interrupt::free(|cs| {
        let f = FEED.borrow(cs).borrow();
        FeedFigures {
            delivered: f.as_ref().map_or(0, |f| f.delivered),
            dropped: f.as_ref().map_or(0, |f| f.dropped),
            ticks: TICKS.load(Ordering::Relaxed),
            high_water: f.as_ref().map_or(0, |f| f.high_water),
        }
    })
}

#[exception]
fn SysTick() {
    if DONE.load(Ordering::Relaxed) {
        return;
    }
    TICKS.fetch_add(1, Ordering::Relaxed);
    cortex_m::interrupt::free(|cs| {
        let mut cell = FEED.borrow(cs).borrow_mut();
        let Some(f) = cell.as_mut() else { return };
        f.acc += f.bytes_per_s;
        let mut due = (f.acc / TICK_HZ) as usize;
        f.acc %= TICK_HZ;
        f.high_water = f.high_water.max(QUEUE - f.producer.free());
        let mut end = false;
        while due > 0 && !end {
            let Feed { file, producer, .. } = f;
            let mut got = 0;
            let took = producer.fill_with(|s| {
                let k = s.len().min(due);
                got = file.read(&mut s[..k]).unwrap_or(0);
                got
            });
            if took == 0 {
                // Queue full: the bytes due are lost.
                let k = due.min(f.scratch.len());
                got = f.file.read(&mut f.scratch[..k]).unwrap_or(0);
                f.dropped += got as u64;
            } else {
                f.delivered += took as u64;
            }
            end = got == 0;
            due -= got.min(due);
        }
        if end {
            DONE.store(true, Ordering::Release);
        }
    });
}

/// The loop's input: the consumer half, sleeping until the next tick when it is empty.
pub struct Input {
    consumer: Consumer<QUEUE>,
}

impl embedded_io::ErrorType for Input {
    type Error = SemihostingError;
}

impl Read for Input {
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, Self::Error> {
        loop {
            let n = self.consumer.read(buf);
            if n > 0 || buf.is_empty() {
                return Ok(n);
            }
            if DONE.load(Ordering::Acquire) {
                // The producer's last bytes were published before DONE.
                return Ok(self.consumer.read(buf));
            }
            cortex_m::asm::wfi();
        }
    }
}
