//! Maps: OctoMap files, occupancy grids and distance fields.
pub mod distance;
pub mod grid;
pub mod octomap;
pub mod picture;
