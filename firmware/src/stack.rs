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
