//! Maps: OctoMap files, occupancy grids and distance fields.
pub(crate) mod blocks;
pub(crate) mod distance;
pub(crate) mod edt;
pub(crate) mod grid;
pub(crate) mod octomap;
#[cfg(test)]
pub(crate) mod random_grids;
pub(crate) mod row_gaps;

pub use distance::{DistanceField, UpdateError, UpdateStats};
pub use grid::{Cell, Grid, GridError, FACE_NEIGHBOURS};
pub use octomap::{MapFileError, OcTree};
