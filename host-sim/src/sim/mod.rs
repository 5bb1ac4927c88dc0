//! Chain simulation: the ARC's rigid multibody dynamics flown by its control stack
//! along a plan (docs/simulation.md).
//!
//! - `model`: bodies, actuators and their default numbers;
//! - `dynamics`: the multibody (rapier3d, spherical joints at the unit centres);
//! - `reference`(mod@reference): the plan's edges timed within speed and angular-rate limits;
//! - `mpc`: the head's position MPC (a second-order-cone QP solved by clarabel);
//! - `controller`: link controllers, mixer and unit attitude loops (paper Fig. 3);
//! - `flight`: [`simulate`], the recorded flight and its report;
//! - `run`: [`FlightRun`], one flight step by step, its reference growing if need be;
//! - `file`: [`FlightFile`], the `arc-sim/1` flight file;
//! - `clearance`: the exact clearance of the flown chain to a map.
//!
//! Drawing a flight is the picture layer's (`crate::plan_picture::flight_svg`).

mod bodies;
pub(crate) mod clearance;
pub(crate) mod controller;
pub(crate) mod dynamics;
mod file;
pub(crate) mod flight;
pub(crate) mod model;
pub(crate) mod mpc;
mod run;

/// Simulation settings (controller, MPC, limits, model, run) outside their limits.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SettingsError {
    /// A rule on the settings that does not hold; the text states the rule.
    #[error("{0}")]
    Rule(&'static str),
    /// A physics and control rate outside its range.
    #[error("rate {0} Hz must lie in [500, 20000]")]
    Rate(f64),
    /// The reference's timing limits outside their range.
    #[error(transparent)]
    Limits(#[from] crate::trajectory::LimitsError),
    /// Units too weak to hover with their share of the links.
    #[error(
        "unit thrust_max {thrust_max} N cannot lift a unit and a link ({hover:.2} N) with margin"
    )]
    ThrustMargin {
        /// The unit's largest thrust (N).
        thrust_max: f64,
        /// The weight of a unit and a link (N).
        hover: f64,
    },
}

impl SettingsError {
    /// `Ok` where the rule holds, else the rule `why` as the error.
    pub(crate) fn check(holds: bool, why: &'static str) -> Result<(), Self> {
        match holds {
            true => Ok(()),
            false => Err(Self::Rule(why)),
        }
    }
}

/// Whether every value is a finite number above zero.
pub(crate) fn all_positive(values: &[f64]) -> bool {
    values.iter().all(|v| v.is_finite() && *v > 0.0)
}

/// Whether every value is a finite number, zero or above.
pub(crate) fn all_non_negative(values: &[f64]) -> bool {
    values.iter().all(|v| v.is_finite() && *v >= 0.0)
}

pub use clearance::MapClearance;

// The type of `Sample::units` and `Sample::links`, so that users of a recorded flight
// (the Python bindings) can name it.
pub use flight::BodySample;

pub use controller::{ChainController, ControllerConfig};
pub use dynamics::{BodyState, ChainDynamics, Formulation, UnitCommand, V3};
pub use file::{FlightFile, FORMAT as FLIGHT_FORMAT};
pub use flight::{
    simulate, simulate_reference, simulate_with_progress, Flight, FlightReport, Gust, Obstacles,
    Progress, Sample, SimConfig, SimError,
};
pub use model::ChainModel;
pub use mpc::{HeadMpc, MpcConfig, MpcRef};
// The timing core lives in `crate::trajectory`; its names stay here for the
// simulation's users.
pub use crate::trajectory::{Reference, ReferenceError, ReferenceLimits};
pub use run::{FlightEnd, FlightRun};

#[cfg(test)]
mod tests;
