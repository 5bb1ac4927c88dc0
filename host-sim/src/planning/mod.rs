//! The facade: plan as `arc plan` does, in one call.
//!
//! [`plan`] takes a map, a chain and a query ([`Request`]), shape tables (given, or
//! built from the options) and one [`PlanOptions`] (`arc plan`'s flags and
//! defaults), and runs what `arc plan` runs: the ARCplanner's search, post-processing
//! (`ArcPlanner::refine`, unless `no_smooth`), the plan file (`planner::to_plan`)
//! with its quality annotated, and, when asked, the plan timed into a trajectory.
//! The time limit ([`DEFAULT_TIME_LIMIT_S`] unless given) covers the search,
//! post-processing and the trajectory's blending rounds; setup is timed apart. [`finish`] is the second half alone, for
//! callers that ran the search themselves (the benchmarks measure search apart).
//!
//! The `arc plan` command, the Python package, the examples and the benchmarks plan
//! through this module; none of them refines or annotates a plan itself.

mod arrival;
mod error;
mod mission;
mod options;
mod settings_file;

use std::sync::atomic::AtomicUsize;
use std::sync::Arc;
use std::time::Instant;

use aerial_chain_core::ChainParams;

pub use arrival::Arrival;
pub use error::{NoPlan, PlanningError};
pub use mission::{plan_mission, LegError, MissionPlanned};
pub use options::{PlanOptions, DEFAULT_TIME_LIMIT_S, MAX_TIME_LIMIT_S};
pub(crate) use settings_file::unknown_key;
pub use settings_file::{SettingsFile, SettingsFileError, ONLINE_SECTION};

use crate::collision::CollisionContext;
use crate::goal::GoalPose;
use crate::map::{DistanceField, Grid};
use crate::plan_file::{MapSection, Plan};
use crate::planner::{
    annotate_quality, to_plan, ArcPlanner, PlanError, Planner, Quality, Query, Refinement,
    Solution, Stats,
};
use crate::tables::ShapeTables;
use crate::trajectory::{Trajectory, TrajectoryError};

/// What to plan: a map (its distance field), a chain, a query (with the goal's yaw and
/// shape, when it asks for them), and how the plan file records the map.
#[derive(Clone, Debug)]
pub struct Request {
    /// The map's distance field (it keeps the grid).
    pub field: Arc<DistanceField>,
    /// The chain.
    pub params: ChainParams,
    /// Start, start shape, goal and its tolerance.
    pub query: Query,
    /// The yaw and shape the chain should arrive in (default: any).
    pub pose: GoalPose,
    /// The plan file's map section ([`MapSection::of`] the grid, with its source).
    pub map: MapSection,
}

impl Request {
    /// A request on `grid` (its distance field built here), recording the map as
    /// [`MapSection::of`] the grid (no source).
    pub fn new(grid: Grid, params: ChainParams, query: Query) -> Self {
        let map = MapSection::of(&grid);
        Self {
            field: Arc::new(DistanceField::new(grid)),
            params,
            query,
            pose: GoalPose::default(),
            map,
        }
    }

    /// The request with the goal's yaw and shape `pose`.
    pub fn with_pose(mut self, pose: GoalPose) -> Self {
        self.pose = pose;
        self
    }

    /// The map's grid.
    pub fn grid(&self) -> &Grid {
        self.field.grid()
    }
}

/// A plan as `arc plan` makes it, and what it took.
#[derive(Debug)]
pub struct Planned {
    /// The plan file, its quality and post-processing recorded in `stats`.
    pub plan: Plan,
    /// The search's counters and timings (shape sources counted again after
    /// post-processing).
    pub stats: Stats,
    /// What the plan asks of the chain.
    pub quality: Quality,
    /// What post-processing did (`None` with `no_smooth`).
    pub refinement: Option<Refinement>,
    /// Where the time went.
    pub timings: PlanTimings,
    /// The plan timed into a trajectory, when the options ask for one; a plan whose
    /// trajectory cannot be made is still a plan, so the error is kept here.
    pub trajectory: Option<Result<Trajectory, TrajectoryError>>,
}

/// Where a plan's time went (s).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PlanTimings {
    /// Collision context, shape tables (when built here) and planner.
    pub setup_s: f64,
    /// The search (the query), from its start.
    pub search_s: f64,
    /// Post-processing, plan file and annotation.
    pub post_s: f64,
    /// Making and checking the trajectory (0 without one).
    pub trajectory_s: f64,
}

/// A solved query made into an annotated plan file: [`finish`]'s result.
#[derive(Debug)]
pub struct Finished {
    /// The plan file.
    pub plan: Plan,
    /// The solution's counters, shape sources counted again after post-processing.
    pub stats: Stats,
    /// What the plan asks of the chain.
    pub quality: Quality,
    /// What post-processing did (`None` when it was not asked for).
    pub refinement: Option<Refinement>,
}

/// Plans `request` as `arc plan` does (see the module docs): with `tables` (built
/// from the options when `None`) and `options`. Fails with bad input
/// ([`PlanningError::is_input`]) or when the query finds no plan
/// ([`PlanningError::NoPlan`]).
pub fn plan(
    request: &Request,
    tables: Option<ShapeTables>,
    options: &PlanOptions,
) -> Result<Planned, PlanningError> {
    let stop = options.termination()?;
    options.validate_tuning()?;
    arrival::check_pose(request, options.planner.n_psi)?;
    let setup = Instant::now();
    let mut planner = planner(request, tables, options)?;
    let setup_s = setup.elapsed().as_secs_f64();
    let began = Instant::now();
    let solution = planner
        .solve(&request.query, stop)
        .map_err(|e| no_plan(e, &planner, began, setup_s, options))?;
    let search_s = began.elapsed().as_secs_f64();
    let post = Instant::now();
    let smooth = !options.no_smooth;
    let arrive = arrival::Arrival {
        goal: request.query.goal,
        pose: request.pose,
    };
    let deadline = stop.deadline(began);
    let done = finish(
        &planner,
        solution,
        request.map.clone(),
        smooth,
        deadline,
        &arrive,
    )?;
    let post_s = post.elapsed().as_secs_f64();
    let made = Instant::now();
    let trajectory = options
        .trajectory
        .map(|s| crate::trajectory::build_until(&done.plan, request.grid(), &s, deadline));
    let trajectory_s = match trajectory {
        Some(_) => made.elapsed().as_secs_f64(),
        None => 0.0,
    };
    Ok(Planned {
        plan: done.plan,
        stats: done.stats,
        quality: done.quality,
        refinement: done.refinement,
        timings: PlanTimings {
            setup_s,
            search_s,
            post_s,
            trajectory_s,
        },
        trajectory,
    })
}

/// The planner of `request` at the options' clearance, with `tables` or tables built
/// from the options.
fn planner(
    request: &Request,
    tables: Option<ShapeTables>,
    options: &PlanOptions,
) -> Result<ArcPlanner, PlanningError> {
    let clearance = options.clearance;
    let ctx = CollisionContext::new(request.field.clone(), request.params, clearance)
        .map_err(|source| PlanningError::Context { clearance, source })?;
    let tables = match tables {
        Some(t) => t,
        None => {
            let settings = options.table_settings();
            ShapeTables::build(request.params, &settings, &AtomicUsize::new(0)).map_err(
                |source| PlanningError::Tables {
                    srs: settings.srs,
                    source,
                },
            )?
        }
    };
    ArcPlanner::new(ctx, tables, options.planner.clone())
        .map(|p| p.with_refine(options.refine.clone()))
        .map_err(PlanningError::Refused)
}

/// Why the query that began at `began` gave no plan: a query that cannot be asked is
/// bad input; else what it tried.
fn no_plan(
    error: PlanError,
    planner: &ArcPlanner,
    began: Instant,
    setup_s: f64,
    options: &PlanOptions,
) -> PlanningError {
    if let PlanError::TablesMismatch { .. }
    | PlanError::StartInvalid(_)
    | PlanError::GoalInvalid(_) = error
    {
        return PlanningError::Refused(error);
    }
    let checks = planner.context().stats();
    PlanningError::NoPlan(Box::new(NoPlan {
        error,
        planning_s: began.elapsed().as_secs_f64(),
        setup_s,
        time_limit_s: options.time_limit_s,
        roadmap_vertices: planner.roadmap_stats().roadmap_vertices,
        collision_checks: checks.configs + checks.translations + checks.shape_changes,
    }))
}

/// Makes `solution` (of `planner`'s last query) the plan file `arc plan` writes:
/// post-processed when `smooth` (stopping at `deadline` with what it has), then
/// ending in the goal's yaw and shape (`arrive`), on the map `map` describes, its
/// quality and post-processing recorded. Fails only when no checked shape change
/// reaches the goal's configuration.
pub fn finish(
    planner: &ArcPlanner,
    solution: Solution<Stats>,
    map: MapSection,
    smooth: bool,
    deadline: Option<Instant>,
    arrive: &arrival::Arrival,
) -> Result<Finished, PlanningError> {
    let (mut solution, refinement) = match smooth {
        true => {
            let (refined, r) = planner.refine(&solution, deadline);
            (refined, Some(r))
        }
        false => (solution, None),
    };
    arrive.extend(planner, &mut solution.steps)?;
    let quality = Quality::of(&solution.steps);
    let mut plan = to_plan(&solution, planner.context().params(), map);
    annotate_quality(&mut plan, &quality, refinement.as_ref());
    Ok(Finished {
        plan,
        stats: solution.stats,
        quality,
        refinement,
    })
}

#[cfg(test)]
mod tests;
