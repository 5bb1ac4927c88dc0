//! The full-state PRM baseline (the paper's Table 3): a lazy probabilistic roadmap over
//! the whole configuration `zeta` of the chain, with the ARCplanner's collision checks.
//!
//! # What it samples
//! A vertex is a configuration `zeta = [xi, eta]`: the head position uniform in the
//! map's box, the head's yaw and every link's yaw uniform on the circle, every link's
//! pitch uniform in `[-theta_max, theta_max]`; it is kept when
//! [`CollisionContext::check_config`] accepts it (limits, bends, self-collision, bounds,
//! map; conservative). Plain rejection sampling: no bias towards valid shapes, as a
//! generic full-state PRM would do. The vertex budget `M_F` ([`PrmSettings::vertices`])
//! includes [`PrmSettings::goal_samples`] configurations whose head is sampled in the
//! goal ball (the goal region: head within the query's [`Query::goal_tol`] of the
//! goal, any shape), as OMPL's planners sample a goal region; sampled vertices that happen to lie
//! in the ball are goals too.
//!
//! # Edges (docs/model.md "Motion between two configurations")
//! The roadmap joins every vertex to its `k` nearest neighbours (and the relation is
//! made symmetric) in the weighted zeta metric of `metric` (RMS displacement of the
//! units, `C_T` weights, exact k-d tree), `k` by the PRM* rule
//! `ceil(e (1 + 1/d) ln n)` with `d = 2N + 2` unless set ([`PrmSettings::k`]), as OMPL's
//! LazyPRMstar. Moving along an edge `a -> b` means the paper's "change shape, then
//! translate": a shape change from `eta_a` to `eta_b` with the head at `xi_a`
//! ([`CollisionContext::check_shape_change`]), then a translation from `xi_a` to `xi_b`
//! in shape `eta_b` ([`CollisionContext::check_translation`]). So an edge's validity
//! depends on its direction, and is kept per direction.
//!
//! # Lazy evaluation (Bohlin and Kavraki 2000)
//! Edges are not checked when the roadmap is built. A query runs A* (heuristic: the
//! head's distance to the goal ball, a lower bound of the metric) over the edges not
//! known to be blocked, then checks the path's edges from the start; the first one that
//! fails is blocked and A* runs again; a path whose edges all pass is the answer. Checked
//! edges keep their verdict for later queries on the same roadmap. The query ends when a
//! path passes, when no path is left (the roadmap is too sparse: failure), or at the
//! time limit.
//!
//! The PRM is a [`Planner`]: [`Planner::setup`] builds the roadmap (`roadmap`),
//! [`Planner::solve`] runs one query (`search`) over the lazy graph of
//! `crate::planner::graph`.
//!
//! Deterministic: the same map, chain, settings and seed give the same roadmap and the
//! same answer on any machine and any number of threads (only the timings differ),
//! unless the time limit cuts a run short.

pub(crate) mod error;
pub(crate) mod metric;
pub(crate) mod roadmap;
pub(crate) mod search;
pub(crate) mod settings;
#[cfg(test)]
mod tests;

use std::time::{Duration, Instant};

use serde_json::json;

use crate::collision::CollisionContext;
use crate::plan_file::{Plan, Timings};
use crate::planner::{Planner, Query, Solution, SolutionStats, Step, Termination};
pub use error::PrmError;
use roadmap::Roadmap;
use search::LazySearch;
pub use settings::{prm_star_k, PrmSettings};

/// A solved query of the full-state PRM.
pub type PrmSolution = Solution<PrmStats>;

/// Counters and timings of a roadmap and one query.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct PrmStats {
    /// Roadmap build (sampling and neighbours), query and edge-check times.
    #[serde(skip)]
    pub timings: Timings,
    /// Vertices in the roadmap (goal samples included).
    pub vertices: usize,
    /// Of them, goal samples.
    pub goal_samples: usize,
    /// Configurations drawn to get them.
    pub sample_tries: u64,
    /// Whether the build stopped at the time limit before the budget was reached.
    pub build_capped: bool,
    /// Neighbours asked per vertex.
    pub k: usize,
    /// Undirected roadmap edges.
    pub graph_edges: usize,
    /// A* searches in the query.
    pub iterations: usize,
    /// Directed edges checked in the query.
    pub edges_checked: usize,
    /// Of them, found blocked.
    pub edges_blocked: usize,
    /// Roadmap edges on the answer.
    pub path_edges: usize,
    /// Shape-change waypoints of the answer.
    pub shape_changes: usize,
    /// Full-chain collision checks in the query (shape changes and translations).
    pub collision_checks: u64,
}

/// The full-state lazy PRM on one map and chain.
pub struct FullStatePrm {
    ctx: CollisionContext,
    settings: PrmSettings,
    roadmap: Option<Roadmap>,
    roadmap_s: f64,
}

impl FullStatePrm {
    /// A PRM for the chain and map of `ctx`.
    pub fn new(ctx: CollisionContext, settings: PrmSettings) -> Result<Self, PrmError> {
        settings.validate()?;
        Ok(Self {
            ctx,
            settings,
            roadmap: None,
            roadmap_s: 0.0,
        })
    }

    /// The settings.
    pub fn settings(&self) -> &PrmSettings {
        &self.settings
    }
}

impl Planner for FullStatePrm {
    type Stats = PrmStats;
    type Error = PrmError;

    fn context(&self) -> &CollisionContext {
        &self.ctx
    }

    /// Builds the roadmap for the query's goal (once; later calls do nothing): samples
    /// the vertex budget, then the neighbour lists. Without a time limit it runs until
    /// the budget is met (or `1000 M_F` draws have been made); with one, it stops
    /// sampling when the time is up and keeps what it has ([`PrmStats::build_capped`]).
    fn setup(&mut self, query: &Query, stop: Termination) {
        if self.roadmap.is_some() {
            return;
        }
        let began = Instant::now();
        let goal = (query.ends().1, query.goal_tol);
        let roadmap = Roadmap::build(&self.ctx, &self.settings, goal, stop.time_limit);
        self.roadmap = Some(roadmap);
        self.roadmap_s = began.elapsed().as_secs_f64();
    }

    /// Plans from the query's start to a configuration whose head is within the goal
    /// tolerance of its goal. Builds the roadmap first if needed (its time is reported
    /// apart, and capped by the same time limit).
    fn solve(&mut self, query: &Query, stop: Termination) -> Result<PrmSolution, PrmError> {
        query.check(&self.ctx)?;
        // One time limit for the roadmap and the query together (docs/promises.md).
        let solve_began = Instant::now();
        self.setup(query, stop);
        let began = Instant::now();
        let before = self.ctx.stats();
        let mut roadmap = self.roadmap.take().expect("setup built the roadmap");
        let result = LazySearch {
            ctx: &self.ctx,
            roadmap: &mut roadmap,
            began: solve_began,
            stop,
            collision: Duration::ZERO,
            stats: PrmStats::default(),
        }
        .run(query);
        let mut stats = roadmap.stats(self.roadmap_s);
        self.roadmap = Some(roadmap);
        let (steps, q) = result?;
        let after = self.ctx.stats();
        stats.timings.planning_s = began.elapsed().as_secs_f64();
        stats.timings.collision_s = q.timings.collision_s;
        stats.iterations = q.iterations;
        stats.edges_checked = q.edges_checked;
        stats.edges_blocked = q.edges_blocked;
        stats.path_edges = q.path_edges;
        stats.shape_changes = steps.iter().filter(|s| s.shape_change).count();
        stats.collision_checks = (after.translations + after.shape_changes)
            - (before.translations + before.shape_changes);
        Ok(Solution { steps, stats })
    }

    fn clear(&mut self) {
        self.roadmap = None;
    }

    fn roadmap_stats(&self) -> PrmStats {
        match &self.roadmap {
            None => PrmStats::default(),
            Some(r) => r.stats(self.roadmap_s),
        }
    }
}

impl SolutionStats for PrmStats {
    fn timings(&self) -> Timings {
        self.timings
    }

    fn rest_name(&self) -> &'static str {
        "search_s"
    }

    /// Which planner made the plan, and whether its roadmap was cut short.
    fn annotate(&self, _steps: &[Step], plan: &mut Plan) {
        plan.stats
            .insert("planner".into(), json!("full-state lazy PRM"));
        plan.stats
            .insert("build_capped".into(), json!(self.build_capped));
    }
}
