//! Chain simulation: the ARC's rigid multibody dynamics flown by its control stack
//! along a plan. See `README.md` beside this file.
//!
//! - [`model`]: bodies, actuators and their default numbers;
//! - [`dynamics`]: the multibody (rapier3d, spherical joints at the unit centres);
//! - [`reference`](mod@reference): the plan's edges timed within speed and angular-rate limits;
//! - [`mpc`]: the head's position MPC (a second-order-cone QP solved by clarabel);
//! - [`controller`]: link controllers, mixer and unit attitude loops (paper Fig. 3);
//! - [`flight`]: [`simulate`], the recorded flight and its report;
//! - [`clearance`]: the exact clearance of the flown chain to a map;
//! - [`plot`]: SVG plots of a flight.

pub mod clearance;
pub mod controller;
pub mod dynamics;
pub mod flight;
pub mod model;
pub mod mpc;
pub mod plot;
pub mod reference;

pub use controller::{ChainController, ControllerConfig};
pub use dynamics::{BodyState, ChainDynamics, V3};
pub use flight::{simulate, Flight, FlightReport, Gust, Obstacles, SimConfig, SimError};
pub use model::ChainModel;
pub use reference::{Reference, ReferenceLimits};

#[cfg(test)]
mod tests;
