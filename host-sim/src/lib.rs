//! # aerial-chain: the Aerial Robotic Chain on the host
//!
//! Maps, collision of the chain against a map, the ARCplanner and a full-state PRM
//! behind one [`planner::Planner`] trait, plan files and their exact verifier, the
//! chain's simulation, and pictures. The `arc` command line is a separate binary built
//! on this library's face; the contract everything here follows is `docs/model.md`.
//!
//! Each family is a module with a small face (the names below are the common ones):
//! - [`map`]: [`map::OcTree`] (OctoMap `.bt`/`.ot`), [`map::Grid`], [`map::DistanceField`];
//! - [`problem`]: built-in scenarios ([`problem::scenarios::build`]) and the `passage:`
//!   family of hard cases;
//! - [`collision`]: [`collision::CollisionContext`] (conservative checks for planners) and
//!   [`collision::verify_plan`] (the exact test);
//! - [`tables`]: [`tables::ShapeTables`], the LSC, SRS and G_SRS of a chain;
//! - [`planner`]: [`planner::Planner`], [`planner::Query`], [`planner::ArcPlanner`],
//!   [`planner::to_plan`]; [`baseline`]: [`baseline::FullStatePrm`];
//! - [`plan_file`]: [`plan_file::Plan`], the `arc-plan/1` file;
//! - [`sim`]: [`sim::simulate`], [`sim::Flight`];
//! - [`trajectory`]: [`trajectory::build`], a plan timed and blended into a
//!   trajectory, its exact check and its file;
//! - [`picture`]: figures, plan and map pictures (SVG, PNG);
//! - [`export`]: a trajectory or flight as a ROS 2 bag (MCAP) or per-unit MAVLink
//!   setpoints (`.tlog`).
//!
//! ```
//! use std::sync::atomic::AtomicUsize;
//! use std::sync::Arc;
//!
//! use aerial_chain::collision::{verify_plan, CollisionContext, DEFAULT_CLEARANCE};
//! use aerial_chain::map::DistanceField;
//! use aerial_chain::plan_file::MapSection;
//! use aerial_chain::planner::{to_plan, ArcPlanner, Planner, Query, Settings, Termination};
//! use aerial_chain::problem::scenarios;
//! use aerial_chain::tables::{ShapeTables, TableSettings};
//! use aerial_chain_core::ChainParams;
//!
//! let scenario = scenarios::build("window")?;
//! let params = ChainParams::new(5);
//! let field = Arc::new(DistanceField::new(scenario.grid.clone()));
//! let ctx = CollisionContext::new(field, params, DEFAULT_CLEARANCE)?;
//! let progress = AtomicUsize::new(0); // shapes sampled so far, for a progress display
//! let tables = ShapeTables::build(params, &TableSettings::default(), &progress)?;
//! let mut planner = ArcPlanner::new(ctx, tables, Settings::default())?;
//! let query = Query::new(scenario.start, scenario.start_shape(5)?, scenario.goal);
//! let solution = planner.solve(&query, Termination::default())?;
//! let grid = &scenario.grid;
//! let plan = to_plan(&solution, &params, MapSection::of(grid));
//! assert!(verify_plan(grid, &plan).ok);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![deny(missing_docs)]

pub mod baseline;
pub mod collision;
pub mod export;
mod fsutil;
pub mod map;
pub mod picture;
pub mod plan_file;
pub mod plan_picture;
pub mod planner;
pub mod problem;
mod shape_index;
pub mod sim;
pub mod tables;
pub mod trajectory;
