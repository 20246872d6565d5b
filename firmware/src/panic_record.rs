//! The board's last words: a panic or a HardFault writes its reason into RAM that start-up
//! leaves alone (`.uninit`), logs it over defmt if a probe listens, and resets the chip; the
//! next start logs the record and the reset's cause (watchdog, software, pin, power) and
//! clears both. A board without a probe attached thus reports why it restarted the next
//! time one is.

use core::fmt::Write;
use core::mem::MaybeUninit;
use core::ptr::addr_of_mut;

use stm32f4xx_hal::pac;

/// Marks a valid record ("PANC"); anything else in the word is power-on garbage.
const MAGIC: u32 = 0x5041_4E43;
/// Bytes of the reason kept (the panic message and its location, cut to fit).
const REASON_BYTES: usize = 160;

#[repr(C)]
struct Record {
    magic: u32,
    len: u32,
    reason: [u8; REASON_BYTES],
}

/// Not zeroed or initialised by cortex-m-rt's start-up, so it survives a reset.
#[link_section = ".uninit.curbtrace_panic_record"]
static mut RECORD: MaybeUninit<Record> = MaybeUninit::uninit();

/// Writes into the record's reason, dropping what does not fit.
struct Cursor<'a> {
    buf: &'a mut [u8; REASON_BYTES],
    len: usize,
}

impl Write for Cursor<'_> {
    fn write_str(&mut self, s: &str) -> core::fmt::Result {
        let room = REASON_BYTES - self.len;
        let n = s.len().min(room);
        self.buf[self.len..self.len + n].copy_from_slice(&s.as_bytes()[..n]);
        self.len += n;
        Ok(())
    }
}

/// Records `reason`, logs it and resets the chip.
pub fn record_and_reset(reason: core::fmt::Arguments<'_>) -> ! {
    cortex_m::interrupt::disable();
    // SAFETY: interrupts are off and this path never returns, so this is the only
    // reference; every field is written before the magic marks the record valid.
    let rec = unsafe { (*addr_of_mut!(RECORD)).as_mut_ptr() };
    let len = unsafe {
        let mut cur = Cursor {
            buf: &mut (*rec).reason,
            len: 0,
        };
        let _ = cur.write_fmt(reason);
        (*rec).len = cur.len as u32;
        (*rec).magic = MAGIC;
        cur.len
    };
    // SAFETY: `len` bytes of the reason were just written.
    let text = unsafe { &(&(*rec).reason)[..len] };
    defmt::error!(
        "fatal: {=str}; resetting",
        core::str::from_utf8(text).unwrap_or("(reason not UTF-8)")
    );
    cortex_m::peripheral::SCB::sys_reset()
}

/// Logs the previous run's record (if any) and why the chip was reset, then clears both.
/// Call once, early in start-up.
pub fn report_previous() {
    // SAFETY: runs once before anything can panic into the record; reads the words as they
    // are (garbage after power-on, which the magic rules out).
    unsafe {
        let rec = (*addr_of_mut!(RECORD)).as_mut_ptr();
        if core::ptr::read_volatile(&(*rec).magic) == MAGIC {
            let len = (core::ptr::read_volatile(&(*rec).len) as usize).min(REASON_BYTES);
            let text = &(&(*rec).reason)[..len];
            defmt::error!(
                "the previous run ended in: {=str}",
                core::str::from_utf8(text).unwrap_or("(reason not UTF-8)")
            );
            core::ptr::write_volatile(&mut (*rec).magic, 0);
        }
    }
    // SAFETY: RCC_CSR is read and its flags cleared (RMVF) once, before the clocks are set up.
    let rcc = unsafe { &*pac::RCC::ptr() };
    let csr = rcc.csr().read();
    if csr.wdgrstf().bit_is_set() {
        defmt::warn!("reset by the independent watchdog: the processing loop stalled");
    } else if csr.sftrstf().bit_is_set() {
        defmt::info!("reset by software (a recorded panic or fault, or a probe)");
    } else if csr.porrstf().bit_is_set() {
        defmt::info!("power-on reset");
    } else if csr.padrstf().bit_is_set() {
        defmt::info!("reset pin");
    }
    rcc.csr().modify(|_, w| w.rmvf().set_bit());
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    record_and_reset(format_args!("panic: {info}"))
}

#[cortex_m_rt::exception]
unsafe fn HardFault(frame: &cortex_m_rt::ExceptionFrame) -> ! {
    record_and_reset(format_args!("HardFault at pc={:#010x}", frame.pc()))
}
