//! Sensing: depth sensors on the units, exact ray casting into the true map, and the
//! map that grows from what they see (OctoMap's occupancy model).
//!
//! - [`sensor`]: [`DepthSensor`] settings (field of view, ranges, angular resolution,
//!   mounting pose), its rays in the body frame and in W for a [`UnitPose`];
//! - [`raycast`]: [`raycast::scan`], every ray of a sensor cast into a [`crate::map::Grid`]
//!   exactly (the first obstacle cube entered);
//! - [`cloud`]: [`PointCloud`], a scan as the point cloud OctoMap's `insertPointCloud`
//!   takes;
//! - [`ray_keys`]: OctoMap's keys and its ray traversal (`computeRayKeys`), to the bit;
//! - [`occupancy`]: [`OccupancyMap`], log-odds per voxel fused as OctoMap fuses them,
//!   with the voxels each insertion changed, exported as a grid or a `.bt`;
//! - [`survey`]: [`Survey`], every unit's sensor scanning at its rate along a recorded
//!   flight, and the map it draws.
//!
//! The rules are in docs/maps.md ("Sensing") and the contract bits in docs/model.md.

pub mod cloud;
pub mod occupancy;
pub mod ray_keys;
pub mod raycast;
pub mod sensor;
pub mod survey;

pub use cloud::PointCloud;
pub use occupancy::{OccupancyMap, OccupancyParams, VoxelChange};
pub use raycast::{RayReturn, Scan};
pub use sensor::{DepthSensor, Mount, SensorError, UnitPose};
pub use survey::{Survey, SurveyError, SurveyStats};
