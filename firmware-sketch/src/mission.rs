//! The command loop: a scripted sequence of "go to shape k" commands standing in
//! for the bus between units, in normal mode and in safe mode.
//!
//! A command moves the whole chain's shape linearly from the last commanded
//! shape to shape `k`, each angle along its shortest signed difference
//! (docs/model.md's shape-change edge), at most [`SHAPE_RATE`] on the angle that
//! moves most. Every unit knows the whole shape from its own copy of the table,
//! so every unit computes the same duration and all links arrive together
//! without talking. This unit's link reference follows its own two angles on
//! that schedule; the attitude loop tracks it at 500 Hz with rate feed-forward.
//!
//! A command has settled when the reference has arrived and the link has stayed
//! within [`TOLERANCE`] of the target direction, turning slower than
//! [`RATE_TOLERANCE`], for [`SETTLE_HOLD`] seconds; the reported time is when
//! that final stay began. It fails when that has not happened [`SETTLE_ALLOWANCE`]
//! seconds after the reference arrived.

use aerial_chain_core::angle::{diff, wrap};
use aerial_chain_core::table::{TableError, TableView};
use aerial_chain_core::Shape;

use crate::link::{setpoint, LinkLoop, DT};

/// The scripted commands: shape indices `k` over the table's LSC shapes then its
/// SRS shapes. For the default N = 6 table (6 LSC shapes) this visits LI, SE,
/// SM, SV, CA, PN, SRS shapes 0, 17, 42 and 99, and returns to LI. A `k` the
/// table does not have is refused and counts as a failure.
pub const SCRIPT: [u16; 11] = [0, 1, 2, 3, 4, 5, 6, 23, 48, 105, 0];

/// Largest angle rate of a shape change (rad/s).
pub const SHAPE_RATE: f32 = 1.0;
/// Direction tolerance of a settled link (rad): 0.5 degree.
pub const TOLERANCE: f32 = 0.5 * DEG;
/// Turn-rate tolerance of a settled link (rad/s).
pub const RATE_TOLERANCE: f32 = 0.02;
/// How long a link must stay within tolerance to count as settled (s).
pub const SETTLE_HOLD: f32 = 0.2;
/// Time allowed after the reference arrives before a command fails (s).
pub const SETTLE_ALLOWANCE: f32 = 2.0;
/// How long safe mode holds attitude per refused command (s).
pub const SAFE_HOLD: f32 = 1.0;
/// One degree in radians.
pub const DEG: f32 = core::f32::consts::PI / 180.0;

/// Index (0-based) of the link this unit leads: link `UNIT` for units
/// `1..N-1`, link `N-1` for the tail unit `N`.
pub const fn link_index(unit: u8, units: u8) -> usize {
    let lead = if unit < units { unit } else { units - 1 };
    lead as usize - 1
}

/// What the command loop did.
#[derive(Clone, Copy, Debug, defmt::Format)]
pub struct Tally {
    /// Commands issued.
    pub commands: usize,
    /// Commands whose target was reached within tolerance and time.
    pub reached: usize,
    /// Simulated time (s).
    pub time: f32,
}

/// Runs [`SCRIPT`] against a valid table: this unit's link (0-based `link`)
/// goes to each commanded shape in turn.
pub fn run(table: &TableView<'_>, link: usize, lp: &mut LinkLoop) -> Tally {
    let units = table.params().units;
    let mut tally = Tally {
        commands: 0,
        reached: 0,
        time: 0.0,
    };
    // The chain is taken to boot in the straight line LI.
    let mut last = Shape::line(units, 0.0);
    let (mut pitch, mut yaw) = lp.angles();
    for (i, &k) in SCRIPT.iter().enumerate() {
        tally.commands += 1;
        let target = match table.shape(k as usize) {
            Ok(s) => s,
            Err(e) => {
                defmt::error!(
                    "command {=usize}/{=usize}: go to shape {=u16} refused: {}",
                    i + 1,
                    SCRIPT.len(),
                    k,
                    e
                );
                continue;
            }
        };
        let (to_pitch, to_yaw) = (target.pitch(link), target.yaw(link));
        let (d_pitch, d_yaw) = (to_pitch - pitch, diff(yaw, to_yaw));
        let chain_move = last.max_angle_diff(&target);
        let own_move = libm::fabsf(d_pitch).max(libm::fabsf(d_yaw));
        let ramp = chain_move.max(own_move) / SHAPE_RATE;
        defmt::info!(
            "command {=usize}/{=usize}: go to shape {=u16} ({=str}): link {=usize} pitch {=f32} deg, yaw {=f32} deg, ramp {=f32} s",
            i + 1,
            SCRIPT.len(),
            k,
            shape_name(table, k),
            link + 1,
            to_pitch / DEG,
            to_yaw / DEG,
            ramp
        );
        let (p_rate, y_rate) = if ramp > 0.0 {
            (d_pitch / ramp, d_yaw / ramp)
        } else {
            (0.0, 0.0)
        };
        let limit = ramp + SETTLE_ALLOWANCE;
        let mut t = 0.0f32;
        let mut inside_since: Option<f32> = None;
        let mut settled = None;
        let mut error = 0.0;
        while t <= limit {
            let s = if ramp > 0.0 { (t / ramp).min(1.0) } else { 1.0 };
            let moving = s < 1.0;
            let sp = setpoint(
                pitch + s * d_pitch,
                wrap(yaw + s * d_yaw),
                if moving { p_rate } else { 0.0 },
                if moving { y_rate } else { 0.0 },
            );
            lp.step(&sp);
            t += DT;
            error = lp.direction_error(to_pitch, to_yaw);
            let inside = !moving && error < TOLERANCE && lp.turn_rate() < RATE_TOLERANCE;
            inside_since = match (inside, inside_since) {
                (false, _) => None,
                (true, None) => Some(t),
                (true, since) => since,
            };
            if let Some(since) = inside_since {
                if t - since >= SETTLE_HOLD {
                    settled = Some(since);
                    break;
                }
            }
        }
        tally.time += t;
        match settled {
            Some(at) => {
                tally.reached += 1;
                defmt::info!(
                    "settled shape {=u16} in {=f32} s, final error {=f32} deg",
                    k,
                    at,
                    error / DEG
                );
            }
            None => defmt::error!(
                "shape {=u16} NOT settled within {=f32} s: error {=f32} deg",
                k,
                limit,
                error / DEG
            ),
        }
        last = target;
        pitch = to_pitch;
        yaw = to_yaw;
    }
    tally
}

/// The LSC name of shape `k`, or "SRS".
fn shape_name(table: &TableView<'_>, k: u16) -> &'static str {
    match table.lsc(k as usize) {
        Ok(e) => e.kind.name(),
        Err(_) => "SRS",
    }
}

/// Safe mode: every scripted command is refused with `reason`; meanwhile the
/// link is held level at the heading it booted with, and how well is logged.
/// Returns the largest direction error seen after the first hold (rad).
pub fn run_safe<R: defmt::Format + Copy>(reason: R, lp: &mut LinkLoop) -> f32 {
    let (_, yaw) = lp.angles();
    let sp = setpoint(0.0, yaw, 0.0, 0.0);
    let mut worst = 0.0f32;
    for (i, &k) in SCRIPT.iter().enumerate() {
        defmt::warn!(
            "refused go to shape {=u16} (command {=usize}/{=usize}): safe mode ({})",
            k,
            i + 1,
            SCRIPT.len(),
            reason
        );
        let mut t = 0.0f32;
        while t < SAFE_HOLD {
            lp.step(&sp);
            t += DT;
        }
        let error = lp.direction_error(0.0, yaw);
        if i > 0 {
            worst = worst.max(error);
        }
        defmt::info!(
            "holding attitude: level at yaw {=f32} deg, error {=f32} deg",
            yaw / DEG,
            error / DEG
        );
    }
    worst
}

/// Shape-table errors and slot errors, for logging why safe mode was entered.
#[derive(Clone, Copy, Debug, defmt::Format)]
pub enum Refusal {
    /// The slot holds no table blob.
    Slot(crate::slot::SlotError),
    /// The blob is not a valid table for this chain.
    Table(TableError),
}
