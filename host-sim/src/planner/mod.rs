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
//!   `srs_connect`), then `refine`, `shorten` and `widen`;
//! - the full-state PRM baseline, [`crate::baseline::FullStatePrm`].
//!
//! Both search their roadmaps with the one lazy graph search of `graph`.

pub(crate) mod arc;
pub(crate) mod candidates;
mod checker;
pub(crate) mod connect;
pub(crate) mod construction;
mod error;
pub(crate) mod follow;
pub(crate) mod graph;
pub(crate) mod lattice;
pub(crate) mod motion;
pub(crate) mod refine;
pub(crate) mod roadmap;
mod settings;
mod shorten;
pub(crate) mod srs_connect;
mod widen;

use std::time::{Duration, Instant};

use aerial_chain_core::Shape;
use nalgebra::Point3;

pub use arc::{ArcPlanner, Stats};
pub use candidates::Source;
pub(crate) use checker::Checker;
pub use error::PlanError;
pub use motion::{annotate_quality, source_label, to_plan};
pub use refine::{Quality, Refinement};
pub use settings::{Mode, Preference, Settings};
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

    /// The head's start and goal as the arrays the collision checks and the roadmaps
    /// take.
    pub(crate) fn ends(&self) -> ([f64; 3], [f64; 3]) {
        (self.start.into(), self.goal.into())
    }
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
