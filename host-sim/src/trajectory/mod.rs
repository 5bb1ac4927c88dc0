//! Timed trajectories: a plan's waypoints turned into a motion in time that the chain
//! can fly without stopping at every waypoint (docs/model.md, "Trajectories").
//!
//! Every edge of the plan is timed as `arc sim` times it (a smoothstep speed ramp, a
//! cruise at the limit, the mirror ramp), and then consecutive edges are blended: the
//! next edge starts while the one before is still ramping down, so a corner is rounded
//! and a shape change runs while the head slows down or speeds up; a translation and the
//! shape change beside it may also be merged into one move, and a turn of the head yaw
//! alone runs during the motion before it (the yaw moves no body). A blend or merge is kept
//! only where the motion is admissible, checked exactly as `arc verify` checks edges,
//! and keeps the planner's clearance margin; elsewhere the trajectory keeps the plan's
//! "finish one edge, then start the next". The result is sampled on a uniform time grid, and the samples are the
//! trajectory: [`check_samples`] checks them independently of how they were made.
//!
//! - `build`: [`build`] and [`Trajectory`], the generator ([`build_until`]: within a
//!   deadline);
//! - `clock`: [`Trajectory::waypoint_times`], when it passes the plan's waypoints;
//! - `check`: [`check_samples`], the exact check of sampled motion and its limits;
//! - `group`: which edges fly together as one motion, and how a merge gives way;
//! - `legs`: a mission's plan timed leg by leg, with the holds at its goals;
//! - `splice`: [`splice()`], a trajectory joined onto a motion in flight without a stop;
//! - `turns`: a turn of the head yaw alone flown during the motion before it;
//! - `merge`: what a merged motion demands of the limits, and which edges lie on a line;
//! - `file`: [`TrajectoryFile`], the `arc-trajectory/1` JSON file and its CSV form.

mod build;
mod check;
mod clock;
mod file;
mod group;
mod legs;
mod merge;
pub(crate) mod reference;
mod splice;
mod stages;
#[cfg(test)]
mod tests;
mod turns;

// The one place this module names the plan file's types: the other files take them
// from here.
use crate::plan_file::{ChainSection, FormatError, MapSection, Plan};

pub use build::{build, build_until, Trajectory};
pub use check::{check_samples, CheckReport, Peaks, Problem, Violation, LIMIT_TOLERANCE};
pub use file::{FileError, SampleError, SampleRow, TrajectoryFile, TrajectoryStats, FORMAT};
pub use reference::{
    LimitsError, Reference, ReferenceError, ReferenceLimits, DEFAULT_YAW_ACCEL,
    DEFAULT_YAW_ACCEL_DEG, DEFAULT_YAW_RATE, DEFAULT_YAW_RATE_DEG,
};
pub use splice::{check_joint, lead as splice_lead, splice, Joint, NoSplice, Splice};
pub use stages::{Stage, StageReport, Stages};

use serde::{Deserialize, Serialize};

/// Sample spacing of a trajectory by default (s): 50 Hz.
pub const DEFAULT_DT: f64 = 0.02;

/// Largest sample spacing (s): the settings' contract (docs/model.md, "Trajectories").
pub const MAX_DT: f64 = 0.1;

/// Floating-point guard of sample times (a share of a sample): a time that is a whole
/// number of samples up to rounding counts as whole. Not tuning.
pub(crate) const TICK_GUARD: f64 = 1e-9;

/// The defaults of the blending tuning, one per field of [`Settings`].
mod defaults {
    pub const RUN_TOLERANCE: f64 = 0.02;
    pub const STEP_RUN_TOLERANCE: f64 = 0.06;
    pub const SHORT_STEP: f64 = 0.2;
    pub const MAX_RUN: usize = 64;
    pub const MIN_PIECE: f64 = 0.1;
    pub const SHRINKS: u8 = 2;
    pub const FIT_ROUNDS: usize = 200;
}

/// The limits a trajectory keeps at every sample (docs/model.md, "Trajectories").
/// The defaults are `arc sim`'s.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Limits {
    /// Largest speed of any unit centre (m/s).
    pub speed: f64,
    /// Largest acceleration of the head (m/s^2).
    pub accel: f64,
    /// Largest rate of any link angle of `eta`, pitch or yaw (rad/s).
    pub angular_rate: f64,
    /// Largest angular acceleration of any link angle of `eta` (rad/s^2).
    pub angular_accel: f64,
    /// Largest rate of the head yaw (rad/s); in a file written before it was a limit
    /// of its own, the default.
    #[serde(default = "default_yaw_rate")]
    pub yaw_rate: f64,
    /// Largest angular acceleration of the head yaw (rad/s^2); as `yaw_rate`.
    #[serde(default = "default_yaw_accel")]
    pub yaw_accel: f64,
}

fn default_yaw_rate() -> f64 {
    reference::DEFAULT_YAW_RATE
}

fn default_yaw_accel() -> f64 {
    reference::DEFAULT_YAW_ACCEL
}

impl Default for Limits {
    fn default() -> Self {
        let r = crate::trajectory::ReferenceLimits::default();
        Self {
            speed: r.speed,
            accel: r.accel,
            angular_rate: r.angular_rate,
            angular_accel: r.angular_accel,
            yaw_rate: r.yaw_rate,
            yaw_accel: r.yaw_accel,
        }
    }
}

impl Limits {
    /// Checks that every limit is a finite positive number.
    pub fn validate(&self) -> Result<(), TrajectoryError> {
        for (name, v) in [
            ("speed", self.speed),
            ("accel", self.accel),
            ("angular_rate", self.angular_rate),
            ("angular_accel", self.angular_accel),
            ("yaw_rate", self.yaw_rate),
            ("yaw_accel", self.yaw_accel),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(TrajectoryError::Limit { name, value: v });
            }
        }
        Ok(())
    }

    /// The same limits for `arc sim`'s reference, without a hold at the start.
    pub fn to_reference(&self) -> crate::trajectory::ReferenceLimits {
        crate::trajectory::ReferenceLimits {
            speed: self.speed,
            accel: self.accel,
            angular_rate: self.angular_rate,
            angular_accel: self.angular_accel,
            yaw_rate: self.yaw_rate,
            yaw_accel: self.yaw_accel,
            start_hold: 0.0,
        }
    }
}

/// How a trajectory is made: the limits and sampling (`arc`'s flags), and the tuning of
/// blends and merges (docs/settings.md), which trades flight time against work and
/// how far a merged move may leave the plan's path (the exact check still holds every
/// sample to the clearance). In a file (serde), a field left out takes its default.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Settings {
    /// The limits.
    /// Higher limits: faster flights, harder to track.
    pub limits: Limits,
    /// Sample spacing (s), in `(0, 0.1]`.
    /// Smaller: finer samples, more of them to check and store.
    pub dt: f64,
    /// Blend consecutive edges where admissible (false: stop at every waypoint).
    /// Off: every waypoint a stop, the slowest flight, nothing to check beyond the
    /// plan.
    pub blend: bool,
    /// Clearance (m) every body keeps from the map wherever the motion is not the
    /// plan's own (a blend, a merge), so that a controller's tracking error cannot turn
    /// a shortcut into a contact; the planner's default margin. Where the plan's own
    /// edges there keep less, the motion keeps what they keep: no closer than the plan.
    /// Larger: fewer blends and merges pass, longer flights.
    pub clearance: f64,
    /// How far (m) a run's straight move may carry any unit from where the plan has it
    /// at the run's inner waypoints: a fraction of the planner's clearance margin
    /// (0.05 m), which the check then asks of the whole move. Larger: more corners
    /// merged, shorter flights, farther from the plan's path.
    pub run_tolerance: f64,
    /// The same for a run of short steps only (translations none longer than
    /// `short_step`, and shape changes): a follow-the-leader path's corners are where
    /// its steps cut one motion, not places the plan chose. Measured on `corridor` N = 6
    /// (seed 2, threaded): 55 s of flight where `run_tolerance` gave 94 s.
    pub step_run_tolerance: f64,
    /// Longest translation (m) of a run of short steps (threading's steps are 2-4 cm).
    /// Longer: more runs take the larger tolerance.
    pub short_step: f64,
    /// Most edges one run joins. More: longer merged moves, more work per run.
    pub max_run: usize,
    /// Shortest part of a translation (m) a pair is made with, or shrunk to.
    /// Smaller: pairs made with shorter pieces, more of them tried.
    pub min_piece: f64,
    /// How often a failed pair flies half as much of its translation before it gives
    /// up. More: more pairs kept, more checks.
    pub shrinks: u8,
    /// Rounds of lowering cruise rates until every edge's ramps fit; a plan whose ramps
    /// still do not fit is timed without blends there.
    pub fit_rounds: usize,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            limits: Limits::default(),
            dt: DEFAULT_DT,
            blend: true,
            clearance: crate::collision::DEFAULT_CLEARANCE,
            run_tolerance: defaults::RUN_TOLERANCE,
            step_run_tolerance: defaults::STEP_RUN_TOLERANCE,
            short_step: defaults::SHORT_STEP,
            max_run: defaults::MAX_RUN,
            min_piece: defaults::MIN_PIECE,
            shrinks: defaults::SHRINKS,
            fit_rounds: defaults::FIT_ROUNDS,
        }
    }
}

/// Largest value of a blending setting (m, or a count): beyond any map, and it bounds
/// the work of a run. The settings' contract, not tuning.
const MAX_TUNING: f64 = 1e4;

/// Most samples one trajectory may have (a 5.5-hour flight at 50 Hz).
pub const MAX_SAMPLES: usize = 1_000_000;

/// Why a trajectory cannot be made.
#[derive(Debug, thiserror::Error)]
pub enum TrajectoryError {
    /// The plan breaks the plan format.
    #[error("plan: {0}")]
    Plan(#[from] FormatError),
    /// A limit (or a blending setting) that is not a positive number (at most 1e4 for a
    /// blending setting).
    #[error("limit {name} = {value} must be a positive number")]
    Limit {
        /// The limit's name.
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// A sample spacing outside `(0, 0.1]` s.
    #[error("sample spacing dt = {0} s must lie in (0, 0.1]")]
    Dt(f64),
    /// The plan cannot be timed (an edge that changes both head and shape).
    #[error("plan: {0}")]
    Timing(#[from] crate::trajectory::ReferenceError),
    /// The flight would need more samples than [`MAX_SAMPLES`].
    #[error("the trajectory would take {0} samples, more than {MAX_SAMPLES}")]
    TooLong(usize),
    /// Even without blends the sampled motion is not admissible: the plan itself fails
    /// the exact check between its samples.
    #[error("the plan is not admissible as a trajectory: {0}")]
    Inadmissible(Violation),
}

impl Settings {
    /// Checks the limits and the sample spacing.
    pub fn validate(&self) -> Result<(), TrajectoryError> {
        self.limits.validate()?;
        if !(self.dt.is_finite() && self.dt > 0.0 && self.dt <= MAX_DT) {
            return Err(TrajectoryError::Dt(self.dt));
        }
        if !(self.clearance.is_finite() && self.clearance >= 0.0) {
            return Err(TrajectoryError::Limit {
                name: "clearance",
                value: self.clearance,
            });
        }
        for (name, value) in [
            ("run_tolerance", self.run_tolerance),
            ("step_run_tolerance", self.step_run_tolerance),
            ("short_step", self.short_step),
            ("max_run", self.max_run as f64),
            ("min_piece", self.min_piece),
            ("shrinks", self.shrinks as f64),
            ("fit_rounds", self.fit_rounds as f64),
        ] {
            if !(value.is_finite() && value > 0.0 && value <= MAX_TUNING) {
                return Err(TrajectoryError::Limit { name, value });
            }
        }
        Ok(())
    }
}
