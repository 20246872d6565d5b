//! A millisecond clock from SysTick: the links' idle timeout and the board's periodic status
//! log. The tick's interrupt also wakes a read that sleeps waiting for bytes.

use core::sync::atomic::{AtomicU32, Ordering};

use cortex_m::peripheral::{syst::SystClkSource, SYST};
use cortex_m_rt::exception;

static MS: AtomicU32 = AtomicU32::new(0);

/// Starts SysTick at 1 kHz from the core clock `core_hz`.
pub fn start(mut syst: SYST, core_hz: u32) {
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(core_hz / 1000 - 1);
    syst.clear_current();
    syst.enable_interrupt();
    syst.enable_counter();
}

/// Milliseconds since [`start`] (wraps after 49 days; compare with `wrapping_sub`).
pub fn now_ms() -> u32 {
    MS.load(Ordering::Relaxed)
}

#[exception]
fn SysTick() {
    MS.fetch_add(1, Ordering::Relaxed);
}
