//! A mission planned leg by leg through the facade (docs/model.md, "Missions"): each
//! leg from where the one before ended to its goal, in the goal's yaw and shape, with
//! the goal's shape preference; post-processing runs per leg (so it never removes a
//! goal's waypoint), and the legs are joined into one `arc-plan/1` whose waypoints
//! mark the goals they reach.

use std::sync::atomic::AtomicUsize;
use std::time::Instant;

use aerial_chain_core::Shape;
use nalgebra::Point3;
use serde_json::Value;

use super::{plan, PlanOptions, Planned, PlanningError, Request};
use crate::mission::Mission;
use crate::plan_file::Plan;
use crate::planner::{annotate_quality, Quality, Query};
use crate::tables::ShapeTables;
use crate::trajectory::{Trajectory, TrajectoryError};

/// A mission planned: the joined plan, and every leg as the facade planned it.
#[derive(Debug)]
pub struct MissionPlanned {
    /// The whole plan: its waypoints mark the goals (`goal`, `hold_s`); its
    /// `stats.quality` sums the legs', `stats.legs` holds every leg's statistics.
    pub plan: Plan,
    /// Every leg, in order (each plan's waypoints from the leg's start to its goal).
    pub legs: Vec<Planned>,
    /// The whole plan timed, when the options ask for a trajectory.
    pub trajectory: Option<Result<Trajectory, TrajectoryError>>,
}

/// Why a mission has no plan: the leg that failed (the goal it leads to) and why.
#[derive(Debug, thiserror::Error)]
#[error("leg {leg} (to goals[{leg}] at ({x}, {y}, {z})): {error}", x = goal[0], y = goal[1], z = goal[2])]
pub struct LegError {
    /// The leg, which is the index of its goal.
    pub leg: usize,
    /// The goal's head position.
    pub goal: [f64; 3],
    /// Why.
    pub error: Box<PlanningError>,
}

impl LegError {
    /// Whether the input is at fault rather than the leg having no plan.
    pub fn is_input(&self) -> bool {
        self.error.is_input()
    }
}

/// Plans `mission` on `base`'s map and chain from `base`'s start and start shape (its
/// goal is not used), with `tables` (built once from the options when `None`) and
/// `options` (the time limit applies to each leg, and to the joined plan's trajectory;
/// the leg's preference is the goal's).
pub fn plan_mission(
    base: &Request,
    mission: &Mission,
    tables: Option<ShapeTables>,
    options: &PlanOptions,
) -> Result<MissionPlanned, LegError> {
    let fail = |leg: usize, error: PlanningError| LegError {
        leg,
        goal: mission.goals[leg].position,
        error: Box::new(error),
    };
    let tables = match tables {
        Some(t) => t,
        None => {
            let settings = options.table_settings();
            ShapeTables::build(base.params, &settings, &AtomicUsize::new(0)).map_err(|source| {
                fail(
                    0,
                    PlanningError::Tables {
                        srs: settings.srs,
                        source,
                    },
                )
            })?
        }
    };
    let (mut at, mut shape) = (base.query.start, base.query.start_shape);
    let mut legs: Vec<Planned> = Vec::with_capacity(mission.goals.len());
    for (k, goal) in mission.goals.iter().enumerate() {
        let pose = mission
            .pose(k, &base.params)
            .map_err(|what| fail(k, PlanningError::Mission(what)))?;
        let mut leg_options = options.clone();
        leg_options.planner.prefer = goal.prefer;
        leg_options.trajectory = None;
        let request = Request {
            query: Query {
                start: at,
                start_shape: shape,
                goal: goal.position.into(),
                goal_tol: goal.tolerance,
            },
            pose,
            ..base.clone()
        };
        let planned = plan(&request, Some(tables.clone()), &leg_options).map_err(|e| fail(k, e))?;
        (at, shape) = end_of(&planned.plan, &base.params).map_err(|e| fail(k, e))?;
        legs.push(planned);
    }
    let plan = join(mission, &legs);
    // The joined plan's trajectory is one more piece of work with a time limit of its
    // own (the legs were checked, so the termination is).
    let deadline = options
        .termination()
        .ok()
        .and_then(|t| t.deadline(Instant::now()));
    let trajectory = options
        .trajectory
        .map(|s| crate::trajectory::build_until(&plan, base.grid(), &s, deadline));
    Ok(MissionPlanned {
        plan,
        legs,
        trajectory,
    })
}

/// Where a leg's plan ends: its last head position and shape.
fn end_of(
    plan: &Plan,
    params: &aerial_chain_core::ChainParams,
) -> Result<(Point3<f64>, Shape), PlanningError> {
    let last = &plan.waypoints[plan.waypoints.len() - 1];
    let eta: Vec<f32> = last.eta().iter().map(|&a| a as f32).collect();
    let shape = Shape::from_slice(params.units, &eta).map_err(|e| {
        PlanningError::Mission(format!("a leg ended in no shape of the chain: {e:?}"))
    })?;
    Ok((last.xi().into(), shape))
}

/// The legs' plans as one: every leg's waypoints after its first (which is the one
/// before's last), its last marked with its goal and hold.
fn join(mission: &Mission, legs: &[Planned]) -> Plan {
    let mut plan = legs[0].plan.clone();
    plan.waypoints.truncate(1);
    let mut quality = Quality::default();
    for (k, leg) in legs.iter().enumerate() {
        let tail = &leg.plan.waypoints[1..];
        match tail.is_empty() {
            // A goal reached where the leg starts still gets a waypoint of its own (an
            // edge that changes nothing), so that every goal is marked.
            true => plan.waypoints.push(leg.plan.waypoints[0].clone()),
            false => plan.waypoints.extend(tail.iter().cloned()),
        }
        if let Some(w) = plan.waypoints.last_mut() {
            w.goal = Some(k);
            w.hold_s = Some(mission.goals[k].hold_s).filter(|h| *h > 0.0);
        }
        quality.add(&leg.quality);
    }
    let leg_stats: Vec<Value> = legs
        .iter()
        .map(|l| Value::Object(l.plan.stats.clone()))
        .collect();
    plan.stats = serde_json::Map::new();
    plan.stats.insert("legs".into(), Value::Array(leg_stats));
    annotate_quality(&mut plan, &quality, None);
    plan
}
