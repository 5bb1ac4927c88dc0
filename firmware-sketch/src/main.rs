//! # arc-firmware: an ARC unit's autopilot sketch
//!
//! Boots on an STM32F405-class flight controller (or QEMU's netduinoplus2),
//! finds the shape table in its own flash slot, validates it (magic, version,
//! CRC, the chain this unit was built for, every shape), then answers a
//! scripted sequence of "go to shape k" commands by looking up the direction
//! of the link this unit leads in the table, read in place from flash, and
//! running the core's SO(3) attitude controller at 500 Hz against an on-board
//! rigid-body model. A table that fails validation puts the unit in safe
//! mode: shape commands are refused and the link is held level.
//!
//! The run ends through semihosting under QEMU: success only when every
//! commanded target was reached within tolerance and time. See `README.md`
//! beside this crate for the design, the features and the budgets.
#![no_std]
#![no_main]
#![deny(missing_docs)]

mod config;
mod link;
mod mission;
mod platform;
mod slot;
mod stack;

use aerial_chain_core::table::TableView;
use aerial_chain_core::ChainParams;
use cortex_m_rt::entry;

use mission::{Refusal, DEG};
use platform::Outcome;

/// The table image linked into the table slot (`.arc_tables`, memory.x). It is
/// never read through this name: the program finds the slot through the
/// linker symbols, exactly as it would a table flashed on its own. Feature
/// `external-table` leaves it out so the ELF does not touch the slot.
#[cfg(not(feature = "external-table"))]
#[used]
#[link_section = ".arc_tables"]
static TABLE_IMAGE: [u8; config::TABLE_IMAGE_LEN] =
    *include_bytes!(concat!(env!("OUT_DIR"), "/arc_table.bin"));

/// Where the link this unit leads is at power-up: a little off the straight
/// line LI, at rest (pitch, yaw in rad).
const BOOT_DIRECTION: (f32, f32) = (5.0 * DEG, -3.0 * DEG);

/// Boot, validate the table, run the command script, report and exit.
#[entry]
fn main() -> ! {
    let expected = ChainParams::new(config::UNITS);
    let link = mission::link_index(config::UNIT, config::UNITS);
    defmt::info!(
        "ARC unit {=u8} of {=u8} up: steers link {=usize}, table {=str} ({=u32} SRS requested)",
        config::UNIT,
        config::UNITS,
        link + 1,
        config::TABLE_SOURCE,
        config::N_SRS_BUILT
    );
    let mut lp = link::LinkLoop::new(expected.link_length, BOOT_DIRECTION.0, BOOT_DIRECTION.1);
    let slot = slot::slot();
    let opened = slot::table_blob(slot)
        .map_err(Refusal::Slot)
        .and_then(|blob| TableView::open(blob, Some(&expected)).map_err(Refusal::Table));
    let outcome = match opened {
        Ok(table) => {
            log_summary(&table, slot.len());
            let tally = mission::run(&table, link, &mut lp);
            report_stack();
            if tally.reached == tally.commands {
                defmt::info!(
                    "all {=usize} targets reached in {=f32} s simulated: exit success",
                    tally.commands,
                    tally.time
                );
                Outcome::Success
            } else {
                defmt::error!(
                    "{=usize} of {=usize} targets reached: exit failure",
                    tally.reached,
                    tally.commands
                );
                Outcome::Failure
            }
        }
        Err(reason) => {
            defmt::error!("SAFE MODE: table rejected: {}", reason);
            let worst = mission::run_safe(reason, &mut lp);
            defmt::warn!(
                "safe mode: {=usize} shape commands refused, attitude held within {=f32} deg",
                mission::SCRIPT.len(),
                worst / DEG
            );
            report_stack();
            defmt::error!("safe mode: no target reached: exit failure");
            Outcome::Failure
        }
    };
    platform::finish(outcome)
}

/// Logs what the validated table holds.
fn log_summary(table: &TableView<'_>, slot_len: usize) {
    let h = table.header();
    defmt::info!(
        "table valid: format v{=u16}, chain N={=u8} l={=f32} m, {=u8} LSC + {=u16} SRS shapes, max degree {=u8}, {=u32} bytes of {=usize} in slot, CRC {=u32:#010x}",
        h.version,
        h.params.units,
        h.params.link_length,
        h.lsc_count,
        h.srs_count,
        h.max_degree,
        h.total_len + 4,
        slot_len,
        table.crc()
    );
    for i in 0..h.lsc_count as usize {
        if let Ok(e) = table.lsc(i) {
            defmt::info!("  shape {=usize}: LSC {=str}", i, e.kind.name());
        }
    }
}

/// Logs the stack high-water mark.
fn report_stack() {
    let s = stack::high_water_mark();
    defmt::info!(
        "stack peak {=u32} bytes (of {=u32} between static RAM and the top of RAM)",
        s.peak,
        s.reserved
    );
}
