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
//!   family of hard cases; [`witness`]: plans made from their own geometry (the
//!   witness that an instance can be flown);
//! - [`collision`]: [`collision::CollisionContext`] (conservative checks for planners) and
//!   [`collision::verify_plan`] (the exact test);
//! - [`tables`]: [`tables::ShapeTables`], the LSC, SRS and G_SRS of a chain;
//! - [`planner`]: [`planner::Planner`], [`planner::Query`], [`planner::ArcPlanner`],
//!   [`planner::to_plan`]; [`baseline`]: [`baseline::FullStatePrm`];
//! - [`plan_file`]: [`plan_file::Plan`], the `arc-plan/1` file;
//! - [`goal`]: [`goal::GoalPose`], the yaw and shape a goal may ask for; [`mission`]:
//!   [`mission::Mission`], an ordered list of goals (`arc-mission/1`);
//! - [`sim`]: [`sim::simulate`] (stopping at every waypoint), [`sim::Flight`];
//! - [`flying`]: [`flying::fly`], a plan flown as `arc sim` flies it (along its
//!   blended trajectory), and [`flying::time`], the clock of that flight;
//! - [`trajectory`]: [`trajectory::build`], a plan timed and blended into a
//!   trajectory, its exact check and its file;
//! - [`picture`]: figures, plan and map pictures (SVG, PNG);
//! - [`export`]: a trajectory or flight as a ROS 2 bag (MCAP) or per-unit MAVLink
//!   setpoints (`.tlog`);
//! - [`planning`]: [`planning::plan`], the facade: plan as `arc plan` does (search,
//!   post-processing, the plan file, optionally its trajectory) under one
//!   [`planning::PlanOptions`];
//! - [`sensing`]: [`sensing::DepthSensor`] on the units, exact ray casting into the true
//!   map ([`sensing::raycast::scan`]) and the map that grows,
//!   [`sensing::OccupancyMap`] (OctoMap's occupancy model).
//!
//! Plan through the `window` scenario as `arc plan --scenario window --units 5` does,
//! then check the plan with the exact verifier rather than trust the planner:
//!
//! ```
//! use aerial_chain::collision::verify_plan;
//! use aerial_chain::planner::Query;
//! use aerial_chain::planning::{plan, PlanOptions, Request};
//! use aerial_chain::problem::scenarios;
//! use aerial_chain_core::ChainParams;
//!
//! let scenario = scenarios::build("window")?;
//! let query = Query::new(scenario.start, scenario.start_shape(5)?, scenario.goal);
//! let request = Request::new(scenario.grid.clone(), ChainParams::new(5), query);
//! // `arc plan`'s defaults: shape tables built here, post-processing, 60 s at most.
//! let planned = plan(&request, None, &PlanOptions::default())?;
//! assert!(verify_plan(request.grid(), &planned.plan).ok);
//! println!("{} waypoints, {:.2} m of head path", planned.plan.waypoints.len(),
//!          planned.quality.head_path_m);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![deny(missing_docs)]

pub mod baseline;
pub mod collision;
pub mod export;
pub mod flying;
mod fsutil;
pub mod goal;
pub mod map;
pub mod mission;
pub mod online;
pub mod picture;
pub mod plan_file;
pub mod plan_picture;
pub mod planner;
pub mod planning;
pub mod problem;
pub mod sensing;
mod shape_index;
pub mod sim;
pub mod tables;
pub mod trajectory;
pub mod witness;
