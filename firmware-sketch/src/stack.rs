//! Stack high-water mark by painting.
//!
//! cortex-m-rt's `paint-stack` feature fills all RAM between the end of the
//! static data (`_stack_end`) and the top of the stack (`_stack_start`) with
//! [`cortex_m_rt::STACK_PAINT_VALUE`] before `main` runs. Whatever the program
//! has since pushed has scrubbed the paint off; the lowest scrubbed word is the
//! deepest the stack has ever reached.

/// The stack as the linker laid it out, and how deep it has been used.
#[derive(Clone, Copy, Debug, defmt::Format)]
pub struct StackUse {
    /// Bytes between the end of static RAM and the top of RAM (stack + free).
    pub reserved: u32,
    /// Deepest use so far, in bytes from the top of the stack.
    pub peak: u32,
}

/// Measures the stack high-water mark so far.
pub fn high_water_mark() -> StackUse {
    extern "C" {
        // Lowest address the stack may grow to (end of .bss/.data/.uninit),
        // from cortex-m-rt's link.x.
        static _stack_end: u32;
        // Initial stack pointer (top of RAM), from cortex-m-rt's link.x.
        static _stack_start: u32;
    }
    // Only the addresses of the two linker symbols are taken (safe since Rust
    // 1.82); nothing is read through them.
    let (bottom, top) = (
        core::ptr::addr_of!(_stack_end) as usize,
        core::ptr::addr_of!(_stack_start) as usize,
    );
    let mut addr = bottom;
    while addr < top {
        // SAFETY: `addr` is a word-aligned address inside RAM between the end
        // of static data and the initial stack pointer, which cortex-m-rt
        // painted at reset. Below the live stack pointer nothing else owns
        // that memory; a volatile read neither creates a reference nor lets
        // the compiler assume anything about its contents.
        let word = unsafe { core::ptr::read_volatile(addr as *const u32) };
        if word != cortex_m_rt::STACK_PAINT_VALUE {
            break;
        }
        addr += 4;
    }
    StackUse {
        reserved: (top - bottom) as u32,
        peak: (top - addr) as u32,
    }
}
