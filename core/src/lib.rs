//! # aerial-chain-core: what runs on every unit of the Aerial Robotic Chain
//!
//! The Aerial Robotic Chain (ARC) is N quadrotors ("units") joined by rigid links
//! through 3-DoF joints at the unit centres. This crate holds the parts of the
//! project that must run on a unit's autopilot and on the host alike:
//!
//! - [`params`]: chain parameters (N, link length, radii, joint limits), validated;
//! - [`angle`]: angle wrapping and shortest signed differences;
//! - [`shape`]: the shape `eta` and configuration `zeta` types, rotation and interpolation;
//! - [`kinematics`]: forward kinematics (paper Eq. 2);
//! - [`geometry`]: point/segment distances used by the collision tests;
//! - [`validity`]: joint limits and exact self-collision;
//! - [`cost`]: the cost to transition `C_T` (paper Eq. 3);
//! - [`lsc`]: the library of shape configurations (LI, SE, SM, SV, CA, PN);
//! - [`srs`]: the set of random shapes and its roadmap `G_SRS`;
//! - [`table`]: the postcard shape-table format shared by host and units;
//! - [`so3`]: rotations, the exponential map, attitude errors, desired attitudes;
//! - [`control`]: the geometric SO(3) attitude controller.
//!
//! Everything is plain data and pure functions in `f32`: no I/O, no clocks, no
//! allocation, no globals. The contract all of it follows is `docs/model.md`.
#![no_std]
#![deny(missing_docs)]
#![forbid(unsafe_code)]

pub mod angle;
pub mod control;
pub mod cost;
pub mod geometry;
pub mod kinematics;
pub mod lsc;
pub mod params;
pub mod shape;
pub mod so3;
pub mod srs;
pub mod table;
pub mod validity;

pub use params::{ChainParams, ParamError, MAX_LINKS, MAX_SHAPE_DIM, MAX_UNITS};
pub use shape::{Config, Shape};
