//! Maps: OctoMap files, occupancy grids, distance fields and scenario generators.
pub mod distance;
pub mod grid;
pub mod octomap;
pub mod passages;
pub mod picture;
pub mod scenarios;
