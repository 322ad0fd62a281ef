//! The stack a firmware uses, measured by painting: the free stack is painted before the
//! work and read after it. What `table_new` reports (`stack_bytes`) and what the haptic
//! demo holds its start-up to (its `STACK` line): on the M0's 16 KiB a stack that grows
//! into `.bss` corrupts the statics below it (defmt's own state first) without a fault.

extern "C" {
    /// The top of the stack (cortex-m-rt's linker script).
    static _stack_start: u32;
    /// The end of static RAM, where the stack may grow down to (cortex-m-rt).
    static __ebss: u32;
}

/// What the free stack is painted with.
const PAINT: u32 = 0x5AFE_57AC;

/// Paints the free stack below the caller's frame (less a margin for this function's
/// own) down to the end of static RAM.
#[inline(never)]
pub fn paint() {
    // SAFETY: the words from the end of static RAM up to 256 bytes under this
    // function's stack pointer are free stack: nothing lives there now.
    unsafe {
        let sp = cortex_m::register::msp::read() as usize - 256;
        let mut p = core::ptr::addr_of!(__ebss) as usize;
        while p < sp {
            core::ptr::write_volatile(p as *mut u32, PAINT);
            p += 4;
        }
    }
}

/// The stack used since [`paint`] and the stack never reached (bytes): from its top to
/// the lowest word no longer painted, and from there down to the end of static RAM.
#[inline(never)]
pub fn used_and_free() -> (u32, u32) {
    // SAFETY: reads of the painted words, which lie in RAM.
    unsafe {
        let top = core::ptr::addr_of!(_stack_start) as usize;
        let end = core::ptr::addr_of!(__ebss) as usize;
        let mut p = end;
        while p < top && core::ptr::read_volatile(p as *const u32) == PAINT {
            p += 4;
        }
        ((top - p) as u32, (p - end) as u32)
    }
}
