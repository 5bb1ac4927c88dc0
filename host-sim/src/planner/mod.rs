//! Motion planning for the chain: one interface for every planner, and the
//! ARCplanner's parts.
//!
//! The interface follows OMPL's `Planner`: a planner is made for one map and chain with
//! its settings; [`Planner::setup`] builds what queries can share (a roadmap),
//! [`Planner::solve`] answers one [`Query`] under a [`Termination`] condition (setting
//! up first if needed), [`Planner::clear`] forgets the roadmap. A [`Solution`] is the
//! waypoints ([`Step`]) and the planner's counters ([`SolutionStats`]);
//! [`motion::to_plan`] writes any planner's solution as a plan file. The benchmarks run
//! every planner through this trait alike.
//!
//! Two planners implement it:
//! - [`ArcPlanner`], the paper's ARCplanner (`arc`): a lazy head roadmap
//!   (`roadmap`, `lattice`) and, per head edge, the cheapest shape that gets the
//!   chain along it (`construction`, `connect`, `candidates`, `follow`,
//!   `srs_connect`), then post-processing: the stages of `pipeline` over `refine`,
//!   `shorten`, `carry`, `widen` and `thread`, sharing `plan_ops`;
//! - the full-state PRM baseline, [`crate::baseline::FullStatePrm`].
//!
//! Both search their roadmaps with the one lazy graph search of `graph`.

pub(crate) mod arc;
pub(crate) mod candidates;
mod carry;
mod checker;
pub(crate) mod connect;
pub(crate) mod construction;
mod ease;
mod error;
pub(crate) mod follow;
mod goal_pose;
pub(crate) mod graph;
pub(crate) mod lattice;
mod linked;
pub(crate) mod motion;
mod near;
mod numeric;
mod pipeline;
pub(crate) mod plan_ops;
pub(crate) mod refine;
mod refine_settings;
pub(crate) mod roadmap;
mod settings;
mod shorten;
pub(crate) mod srs_connect;
mod thread;
mod widen;

use std::time::{Duration, Instant};

use aerial_chain_core::Shape;
use nalgebra::Point3;

pub use arc::{ArcPlanner, Phases, Stats};
pub use candidates::Source;
pub use carry::Carried;
pub(crate) use checker::Checker;
pub use error::PlanError;
pub use motion::{annotate_quality, source_label, to_plan};
pub use pipeline::{Budget, Effect, Refinement, StageReport, Unit};
pub use plan_ops::Quality;
pub use refine_settings::{
    CarrySettings, RefineSettings, ShortenSettings, ThreadSettings, WidenSettings,
};
pub use settings::{LatticeSettings, Mode, Preference, SettingError, Settings};
pub use widen::{Widening, CAP as WIDEN_CAP};

use crate::collision::CollisionContext;
use crate::plan_file::{Plan, Timings};

/// What a planner is asked: from a start configuration of the chain to a goal region
/// for the head.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Query {
    /// Head start position (m).
    pub start: Point3<f64>,
    /// Start shape.
    pub start_shape: Shape,
    /// Head goal position (m).
    pub goal: Point3<f64>,
    /// Goal tolerance: the head ends within this distance of the goal (m).
    pub goal_tol: f64,
}

impl Query {
    /// The goal tolerance of the command line and the benchmarks (m).
    pub const DEFAULT_GOAL_TOL: f64 = 0.3;

    /// A query from `start` in `start_shape` to `goal`, at the default tolerance.
    pub fn new(start: Point3<f64>, start_shape: Shape, goal: Point3<f64>) -> Self {
        Self {
            start,
            start_shape,
            goal,
            goal_tol: Self::DEFAULT_GOAL_TOL,
        }
    }

    /// Refuses a query that cannot be asked in `ctx`: a start shape of another chain,
    /// a start configuration that is not valid, a goal where the head's sphere does
    /// not fit, or a goal tolerance that is not a finite number `>= 0`.
    pub fn check(&self, ctx: &CollisionContext) -> Result<(), QueryError> {
        let n = ctx.params().n();
        if self.start_shape.units() != n {
            let units = self.start_shape.units();
            let why = format!("the start shape has {units} units, the chain {n}");
            return Err(QueryError::Start(why));
        }
        ctx.check_config(self.start, &self.start_shape)
            .map_err(|c| QueryError::Start(c.to_string()))?;
        if !ctx.is_head_free(self.goal) {
            let at = error::point(&self.goal);
            let why = match ctx.field().grid().in_bounds(self.goal) {
                true => format!("the head's sphere (radius + clearance) collides at {at}"),
                false => format!("{at} is outside the map's bounds"),
            };
            return Err(QueryError::Goal(why));
        }
        if !(self.goal_tol.is_finite() && self.goal_tol >= 0.0) {
            let why = format!(
                "goal tolerance {} must be a finite number >= 0",
                self.goal_tol
            );
            return Err(QueryError::Goal(why));
        }
        Ok(())
    }

    /// The plan's first step: the head at the start in the start shape.
    pub(crate) fn start_step(&self) -> Step {
        Step {
            xi: self.start,
            shape: self.start_shape,
            source: Source::Start,
            shape_change: false,
        }
    }

    /// The head's start and goal as the arrays the collision checks and the roadmaps
    /// take.
    pub(crate) fn ends(&self) -> ([f64; 3], [f64; 3]) {
        (self.start.into(), self.goal.into())
    }
}

/// Why a query cannot be asked of a planner (both planners refuse the same queries).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum QueryError {
    /// The start configuration is not valid, or not of the planner's chain.
    #[error("start is invalid: {0}")]
    Start(String),
    /// The goal cannot hold the head, or its tolerance is no finite number `>= 0`.
    #[error("goal is invalid: {0}")]
    Goal(String),
}

/// When to stop a query early.
#[derive(Clone, Copy, Debug, Default)]
pub struct Termination {
    /// Give up after this long: roadmap building, growth and the query together
    /// (docs/promises.md).
    pub time_limit: Option<Duration>,
}

impl Termination {
    /// The moment to stop for work that began at `began`.
    pub fn deadline(&self, began: Instant) -> Option<Instant> {
        self.time_limit.and_then(|t| began.checked_add(t))
    }
}

/// Euclidean distance between two points, arrays or points (m).
pub(crate) fn dist(a: impl Into<Point3<f64>>, b: impl Into<Point3<f64>>) -> f64 {
    nalgebra::distance(&a.into(), &b.into())
}

/// Whether `deadline` has passed.
pub(crate) fn expired(deadline: Option<Instant>) -> bool {
    deadline.is_some_and(|d| Instant::now() > d)
}

/// One waypoint of a solution (of either planner).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Step {
    /// Head position (m).
    pub xi: Point3<f64>,
    /// Shape.
    pub shape: Shape,
    /// Where the shape came from (for translations: the shape kept).
    pub source: Source,
    /// Whether this waypoint ends a shape change (else a translation or the start).
    pub shape_change: bool,
}

/// A solved query.
#[derive(Clone, Debug)]
pub struct Solution<S> {
    /// Waypoints, the start first.
    pub steps: Vec<Step>,
    /// What it took.
    pub stats: S,
}

/// A planner's counters and timings of one query, as a plan file holds them.
///
/// Its counters are its fields that serialize as unsigned integers ([`Self::counts`]);
/// timings and everything else go through [`Self::timings`] and [`Self::annotate`].
pub trait SolutionStats: serde::Serialize {
    /// The counters: every field that serializes as an unsigned integer, by name.
    fn counts(&self) -> Vec<(String, u64)> {
        let Ok(serde_json::Value::Object(fields)) = serde_json::to_value(self) else {
            return Vec::new();
        };
        let counter = |(k, v): (String, serde_json::Value)| v.as_u64().map(|v| (k, v));
        fields.into_iter().filter_map(counter).collect()
    }
    /// Where the time went.
    fn timings(&self) -> Timings;
    /// The name of the query's time outside collision checks in the plan file.
    fn rest_name(&self) -> &'static str;
    /// Adds what else this planner records about the solution `steps` to `plan`.
    fn annotate(&self, steps: &[Step], plan: &mut Plan);
}

/// Why a planner gave no plan, in a word for result tables.
pub trait Failure: std::error::Error {
    /// A short label: `time_limit`, `no_path`, `start_invalid`, ...
    fn outcome(&self) -> &'static str;
}

/// A motion planner for the chain on one map (OMPL's `Planner`).
pub trait Planner {
    /// Counters and timings of a query.
    type Stats: SolutionStats;
    /// Why a query has no solution, or cannot be asked.
    type Error: Failure;

    /// The map and chain it plans for.
    fn context(&self) -> &CollisionContext;

    /// Builds what queries share (the roadmap), once: later calls do nothing until
    /// [`Self::clear`]. Cut short by `stop`'s time limit (the roadmap is then smaller).
    fn setup(&mut self, query: &Query, stop: Termination);

    /// Plans `query`, setting up first if needed; `stop`'s time limit covers both.
    fn solve(
        &mut self,
        query: &Query,
        stop: Termination,
    ) -> Result<Solution<Self::Stats>, Self::Error>;

    /// Forgets the roadmap.
    fn clear(&mut self);

    /// The counters of the roadmap alone (after [`Self::setup`]; zeros before).
    fn roadmap_stats(&self) -> Self::Stats;
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use aerial_chain_core::ChainParams;

    use super::*;
    use crate::collision::DEFAULT_CLEARANCE;
    use crate::map::distance::DistanceField;
    use crate::problem::scenarios;

    #[test]
    fn queries_that_cannot_be_asked_are_refused_by_what_is_wrong() {
        let sc = scenarios::build("window").unwrap();
        let params = ChainParams::new(3);
        let field = Arc::new(DistanceField::new(sc.grid.clone()));
        let ctx = CollisionContext::new(field, params, DEFAULT_CLEARANCE).unwrap();
        let shape = sc.start_shape(3).unwrap();
        let ok = Query::new(sc.start, shape, sc.goal);
        assert_eq!(ok.check(&ctx), Ok(()));
        let other_chain = Query::new(sc.start, sc.start_shape(4).unwrap(), sc.goal);
        let in_wall = Query::new(Point3::new(4.1, 1.0, 1.5), shape, sc.goal);
        for q in [other_chain, in_wall] {
            assert!(matches!(q.check(&ctx), Err(QueryError::Start(_))));
        }
        let outside = Query::new(sc.start, shape, Point3::new(100.0, 0.0, 0.0));
        let e = outside.check(&ctx).unwrap_err().to_string();
        assert!(
            e.contains("(100.000, 0.000, 0.000) is outside the map's bounds"),
            "{e}"
        );
        let nan_goal = Query::new(sc.start, shape, Point3::new(f64::NAN, 0.0, 0.0));
        let nan_tol = Query {
            goal_tol: f64::NAN,
            ..ok
        };
        for q in [nan_goal, nan_tol] {
            assert!(matches!(q.check(&ctx), Err(QueryError::Goal(_))));
        }
    }
}
