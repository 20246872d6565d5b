//! The stack's bottom marker and its high-water mark.
//!
//! The stack lies below the statics (`stack.x`): it grows down from `_stack_start` towards
//! `_stack_end`, the bottom of RAM. cortex-m-rt (feature `paint-stack`) fills the whole
//! region with [`cortex_m_rt::STACK_PAINT_VALUE`] before `main`; the lowest word that no
//! longer holds the paint marks the deepest point the stack ever reached.

/// The bottom of the stack region: a zero-sized object that `stack.x` keeps at the start of
/// the `.stack` section (why it is defined here and not in the linker script: see there).
#[no_mangle]
#[used]
#[link_section = ".stack_bottom"]
static _stack_end: [u32; 0] = [];

extern "C" {
    static _stack_start: u32;
}

/// Paints the stack again from its bottom up to just below the current stack pointer, so
/// that [`high_water_mark_bytes`] then measures the deepest use from here on (the processing
/// loop) rather than start-up's. Returns the high-water mark before repainting.
#[inline(never)]
pub fn repaint() -> usize {
    let before = high_water_mark_bytes();
    let (lo, _) = bounds();
    // 64 bytes of margin for this function's own frame.
    let top = (cortex_m::register::msp::read() as usize).saturating_sub(64) & !3;
    let mut addr = lo;
    while addr < top {
        // SAFETY: 4-byte aligned, inside the reserved stack region and below the live part
        // of the stack (under the stack pointer, with margin for this frame).
        unsafe { core::ptr::write_volatile(addr as *mut u32, cortex_m_rt::STACK_PAINT_VALUE) };
        addr += 4;
    }
    before
}

/// Bytes reserved for the stack (`_stack_size` in `stack.x`).
pub fn size_bytes() -> usize {
    let (lo, hi) = bounds();
    hi - lo
}

/// Deepest stack use so far, in bytes: from the top of the stack down to the lowest word
/// whose paint was overwritten.
pub fn high_water_mark_bytes() -> usize {
    let (lo, hi) = bounds();
    let mut addr = lo;
    while addr < hi {
        // SAFETY: `addr` is a 4-byte aligned address inside the stack region the linker
        // reserved; volatile so the compiler reads the memory as it is now.
        let word = unsafe { core::ptr::read_volatile(addr as *const u32) };
        if word != cortex_m_rt::STACK_PAINT_VALUE {
            break;
        }
        addr += 4;
    }
    hi - addr
}

fn bounds() -> (usize, usize) {
    // Only the addresses of the symbols are taken, never their contents.
    (
        core::ptr::addr_of!(_stack_end) as usize,
        core::ptr::addr_of!(_stack_start) as usize,
    )
}
