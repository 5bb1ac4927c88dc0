//! # aerial-chain: the Aerial Robotic Chain on the host
//!
//! Maps (OctoMap `.bt` files, occupancy grids, distance fields, scenario
//! generators), collision of the chain against a map, the ARCplanner, the chain's
//! simulation, plan files and pictures, and the `arc` command line.
//! The contract everything here follows is `docs/model.md`.

pub mod baseline;
pub mod collision;
mod fsutil;
pub mod map;
pub mod picture;
pub mod plan;
pub mod plan_picture;
pub mod planner;
pub mod problem;
mod shape_index;
pub mod sim;
pub mod tables;
