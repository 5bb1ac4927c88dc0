//! The shape-table slot in flash, found through linker symbols.
//!
//! `memory.x` (top level) reserves the last two 128 KiB flash sectors for the
//! table and exports their bounds as `__arc_tables_start` / `__arc_tables_end`.
//! The slot holds a little-endian `u32` length `L` followed by `L` bytes of
//! table. The table is read in place: nothing here copies it into RAM.

/// Why the slot holds no usable table blob (before the table's own checks).
#[derive(Clone, Copy, Debug, PartialEq, Eq, defmt::Format)]
pub enum SlotError {
    /// The length word is erased flash (0xFFFF_FFFF) or zero: nothing was flashed.
    Empty,
    /// The length word claims more bytes than the slot holds.
    Overrun {
        /// The length word.
        claimed: u32,
        /// Bytes available after the length word.
        capacity: u32,
    },
}

/// The whole slot as a byte slice in flash.
pub fn slot() -> &'static [u8] {
    extern "C" {
        // First byte of the table slot (memory.x).
        static __arc_tables_start: u8;
        // One past the last byte of the table slot (memory.x).
        static __arc_tables_end: u8;
    }
    // SAFETY: memory.x defines both symbols as the bounds of the TABLES
    // flash region, which is always mapped, readable and never written while
    // the program runs, so a shared `'static` slice over it is sound.
    unsafe {
        let start = core::ptr::addr_of!(__arc_tables_start);
        let end = core::ptr::addr_of!(__arc_tables_end);
        core::slice::from_raw_parts(start, end as usize - start as usize)
    }
}

/// The table blob that the slot's length word announces.
pub fn table_blob(slot: &'static [u8]) -> Result<&'static [u8], SlotError> {
    let (len, rest) = slot.split_at(4);
    let len = u32::from_le_bytes([len[0], len[1], len[2], len[3]]);
    if len == 0 || len == u32::MAX {
        return Err(SlotError::Empty);
    }
    rest.get(..len as usize).ok_or(SlotError::Overrun {
        claimed: len,
        capacity: rest.len() as u32,
    })
}
