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
//! goal ball (the goal region: head within [`PrmSettings::goal_tol`] of the goal, any
//! shape), as OMPL's planners sample a goal region; sampled vertices that happen to lie
//! in the ball are goals too.
//!
//! # Edges (docs/model.md "Motion between two configurations")
//! The roadmap joins every vertex to its `k` nearest neighbours (and the relation is
//! made symmetric) in the weighted zeta metric of [`metric`] (RMS displacement of the
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
//! Deterministic: the same map, chain, settings and seed give the same roadmap and the
//! same answer on any machine and any number of threads (only the timings differ),
//! unless the time limit cuts a run short.

pub mod metric;
#[cfg(test)]
mod tests;

use std::time::{Duration, Instant};

use aerial_chain_core::{ChainParams, Shape};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use serde_json::json;

use crate::collision::CollisionContext;
use crate::plan::{Plan, Timing};
use crate::planner::graph::{Edge, EdgeState, LazyGraph, LazyOutcome};
use crate::planner::Termination;
use metric::{embed, embedding_dim, Neighbours};

/// Settings of the full-state PRM.
#[derive(Clone, Debug, PartialEq)]
pub struct PrmSettings {
    /// Vertex budget `M_F` (sampled configurations, goal samples included).
    pub vertices: usize,
    /// Neighbours per vertex; `None`: the PRM* rule ([`prm_star_k`]).
    pub k: Option<usize>,
    /// Configurations sampled in the goal ball; `None`: 1% of the budget, at least 10.
    pub goal_samples: Option<usize>,
    /// Seed of the sampler.
    pub seed: u64,
    /// Goal tolerance for the head (m).
    pub goal_tol: f64,
}

impl Default for PrmSettings {
    fn default() -> Self {
        Self {
            vertices: 1500,
            k: None,
            goal_samples: None,
            seed: 1,
            goal_tol: 0.3,
        }
    }
}

impl PrmSettings {
    /// Checks the numbers (a vertex budget of at least 1, a finite tolerance `>= 0`,
    /// `k >= 1`).
    pub fn validate(&self) -> Result<(), PrmError> {
        if self.vertices == 0 {
            return Err(PrmError::BadSettings("vertices must be at least 1".into()));
        }
        if self.k == Some(0) {
            return Err(PrmError::BadSettings("k must be at least 1".into()));
        }
        if !(self.goal_tol.is_finite() && self.goal_tol >= 0.0) {
            return Err(PrmError::BadSettings(format!(
                "goal tolerance {} must be a finite number >= 0",
                self.goal_tol
            )));
        }
        Ok(())
    }

    fn goal_count(&self) -> usize {
        self.goal_samples
            .unwrap_or((self.vertices / 100).max(10))
            .min(self.vertices)
    }
}

/// The PRM* neighbour count `ceil(e (1 + 1/d) ln n)` for `n` vertices in dimension `d`
/// (at least 1).
pub fn prm_star_k(n: usize, d: usize) -> usize {
    let n = n.max(2) as f64;
    let d = d.max(1) as f64;
    ((std::f64::consts::E * (1.0 + 1.0 / d) * n.ln()).ceil() as usize).max(1)
}

/// Counters and timings of a roadmap and one query.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PrmStats {
    /// Roadmap build time: sampling and neighbours (s).
    pub roadmap_s: f64,
    /// Query time (s).
    pub planning_s: f64,
    /// Of the query time, spent in edge checks (s).
    pub collision_s: f64,
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

/// One waypoint of an answer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrmStep {
    /// Head position (m).
    pub xi: [f64; 3],
    /// Shape.
    pub shape: Shape,
    /// Whether this waypoint ends a shape change (else a translation or the start).
    pub shape_change: bool,
}

/// A solved query.
#[derive(Clone, Debug)]
pub struct PrmSolution {
    /// Waypoints, the start first.
    pub steps: Vec<PrmStep>,
    /// What it took.
    pub stats: PrmStats,
}

/// Why a query has no answer, or cannot be asked.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PrmError {
    /// Settings out of range.
    #[error("settings: {0}")]
    BadSettings(String),
    /// The start configuration is not valid (or not of this chain).
    #[error("start is invalid: {0}")]
    StartInvalid(String),
    /// The goal cannot hold the head.
    #[error("goal is invalid: {0}")]
    GoalInvalid(String),
    /// The roadmap has no collision-free path (too few vertices for this problem).
    #[error("no path in the roadmap ({vertices} vertices) after {iterations} lazy searches")]
    NoPath {
        /// Roadmap vertices.
        vertices: usize,
        /// A* searches made.
        iterations: usize,
    },
    /// The time limit stopped the query.
    #[error("time limit reached after {iterations} lazy searches")]
    TimeLimit {
        /// A* searches made.
        iterations: usize,
    },
}

/// The roadmap: vertices, their embeddings and neighbour lists.
struct Graph {
    xi: Vec<[f64; 3]>,
    shapes: Vec<Shape>,
    index: Neighbours,
    /// Directed: an edge's validity depends on its direction.
    adj: LazyGraph,
    goal_samples: usize,
    tries: u64,
    capped: bool,
    k: usize,
}

/// The full-state lazy PRM on one map and chain.
pub struct FullStatePrm {
    ctx: CollisionContext,
    settings: PrmSettings,
    graph: Option<Graph>,
    roadmap_s: f64,
}

/// A uniformly random shape: head yaw and link yaws on the circle, pitches in the limits.
fn random_shape(params: &ChainParams, rng: &mut Pcg64) -> Shape {
    let pi = std::f32::consts::PI;
    let mut s = Shape::line(params.units, 0.0);
    s.set_head_yaw(aerial_chain_core::angle::wrap(rng.gen_range(-pi..pi)));
    let t = params.theta_max;
    for k in 0..s.links() {
        let pitch = rng.gen_range(-t..=t);
        let yaw = aerial_chain_core::angle::wrap(rng.gen_range(-pi..pi));
        s.set_link(k, pitch, yaw);
    }
    s
}

fn dist3(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

impl FullStatePrm {
    /// A PRM for the chain and map of `ctx`.
    pub fn new(ctx: CollisionContext, settings: PrmSettings) -> Result<Self, PrmError> {
        settings.validate()?;
        Ok(Self {
            ctx,
            settings,
            graph: None,
            roadmap_s: 0.0,
        })
    }

    /// The collision context.
    pub fn context(&self) -> &CollisionContext {
        &self.ctx
    }

    /// The settings.
    pub fn settings(&self) -> &PrmSettings {
        &self.settings
    }

    /// Forgets the roadmap.
    pub fn clear(&mut self) {
        self.graph = None;
    }

    /// Builds the roadmap for `goal` (once; later calls do nothing): samples the vertex
    /// budget, then the neighbour lists. Without a time limit it runs until the budget
    /// is met (or `1000 M_F` draws have been made); with one, it stops sampling when the
    /// time is up and keeps what it has ([`PrmStats::build_capped`]).
    pub fn setup(&mut self, goal: [f64; 3], limit: Option<Duration>) {
        if self.graph.is_some() {
            return;
        }
        let began = Instant::now();
        let params = *self.ctx.params();
        let s = &self.settings;
        let mut rng = Pcg64::seed_from_u64(s.seed);
        let (lo, hi) = self.ctx.field().grid().bounds();
        let want_goal = if self.ctx.is_head_free(goal) {
            s.goal_count()
        } else {
            0
        };
        let max_tries = (s.vertices as u64).saturating_mul(1000).max(10_000);
        let mut xi = Vec::with_capacity(s.vertices);
        let mut shapes = Vec::with_capacity(s.vertices);
        let mut tries = 0u64;
        let mut capped = false;
        let out_of_time =
            |tries: u64| tries.is_multiple_of(256) && limit.is_some_and(|l| began.elapsed() > l);
        // Goal samples first: the head uniform in the goal ball, any shape.
        let tol = s.goal_tol;
        while xi.len() < want_goal && tries < max_tries {
            tries += 1;
            if out_of_time(tries) {
                capped = true;
                break;
            }
            let mut d = [0.0; 3];
            for c in d.iter_mut() {
                *c = if tol > 0.0 {
                    rng.gen_range(-tol..=tol)
                } else {
                    0.0
                };
            }
            if d[0] * d[0] + d[1] * d[1] + d[2] * d[2] > tol * tol {
                continue;
            }
            let p = [goal[0] + d[0], goal[1] + d[1], goal[2] + d[2]];
            let shape = random_shape(&params, &mut rng);
            if self.ctx.check_config(p, &shape).is_ok() {
                xi.push(p);
                shapes.push(shape);
            }
        }
        let goal_samples = xi.len();
        while !capped && xi.len() < s.vertices && tries < max_tries {
            tries += 1;
            if out_of_time(tries) {
                capped = true;
                break;
            }
            let p = [
                rng.gen_range(lo[0]..hi[0]),
                rng.gen_range(lo[1]..hi[1]),
                rng.gen_range(lo[2]..hi[2]),
            ];
            let shape = random_shape(&params, &mut rng);
            if self.ctx.check_config(p, &shape).is_ok() {
                xi.push(p);
                shapes.push(shape);
            }
        }
        let n = xi.len();
        let dim = embedding_dim(params.n());
        let mut emb = Vec::with_capacity(n * dim);
        for (p, sh) in xi.iter().zip(&shapes) {
            embed(&params, *p, sh, &mut emb);
        }
        let index = Neighbours::new(dim, emb);
        let k = s.k.unwrap_or_else(|| prm_star_k(n, params.shape_dim() + 3));
        let mut pairs: Vec<Vec<(u32, f64)>> = vec![Vec::new(); n];
        for i in 0..n {
            if out_of_time(i as u64) {
                capped = true;
                break; // later vertices keep only the edges found so far
            }
            for (j, d) in index.nearest(index.point(i), k + 1) {
                if j as usize != i {
                    pairs[i].push((j, d));
                    pairs[j as usize].push((i as u32, d));
                }
            }
        }
        let adj = pairs
            .into_iter()
            .map(|mut v| {
                v.sort_by_key(|x| x.0);
                v.dedup_by_key(|x| x.0);
                v.into_iter()
                    .map(|(to, cost)| Edge::new(to as usize, cost, EdgeState::Unknown))
                    .collect()
            })
            .collect();
        let adj = LazyGraph::new(adj, false);
        self.graph = Some(Graph {
            xi,
            shapes,
            index,
            adj,
            goal_samples,
            tries,
            capped,
            k,
        });
        self.roadmap_s = began.elapsed().as_secs_f64();
    }

    /// Plans from `start` (head position and shape) to a configuration whose head is
    /// within the goal tolerance of `goal`. Builds the roadmap first if needed (its time
    /// is reported apart, and capped by the same time limit).
    pub fn solve(
        &mut self,
        start: [f64; 3],
        start_shape: Shape,
        goal: [f64; 3],
        stop: Termination,
    ) -> Result<PrmSolution, PrmError> {
        if start_shape.units() != self.ctx.params().n() {
            return Err(PrmError::StartInvalid(format!(
                "the start shape has {} units, the chain {}",
                start_shape.units(),
                self.ctx.params().n()
            )));
        }
        self.ctx
            .check_config(start, &start_shape)
            .map_err(|c| PrmError::StartInvalid(c.to_string()))?;
        if !goal.iter().all(|v| v.is_finite()) || !self.ctx.is_head_free(goal) {
            return Err(PrmError::GoalInvalid(format!(
                "the head's sphere (radius + clearance) does not fit at {goal:?}"
            )));
        }
        // One time limit for the roadmap and the query together (docs/promises.md).
        let solve_began = Instant::now();
        self.setup(goal, stop.time_limit);
        let began = Instant::now();
        let before = self.ctx.stats();
        let params = *self.ctx.params();
        let tol = self.settings.goal_tol;
        let mut graph = self.graph.take().expect("setup built the roadmap");
        let result = Query {
            ctx: &self.ctx,
            graph: &mut graph,
            began: solve_began,
            stop,
            collision: Duration::ZERO,
            stats: PrmStats::default(),
        }
        .run(&params, start, start_shape, goal, tol);
        let mut stats_base = PrmStats {
            roadmap_s: self.roadmap_s,
            vertices: graph.xi.len(),
            goal_samples: graph.goal_samples,
            sample_tries: graph.tries,
            build_capped: graph.capped,
            k: graph.k,
            graph_edges: edge_count(&graph.adj),
            ..Default::default()
        };
        self.graph = Some(graph);
        let (steps, q) = result?;
        let after = self.ctx.stats();
        stats_base.planning_s = began.elapsed().as_secs_f64();
        stats_base.collision_s = q.collision_s;
        stats_base.iterations = q.iterations;
        stats_base.edges_checked = q.edges_checked;
        stats_base.edges_blocked = q.edges_blocked;
        stats_base.path_edges = q.path_edges;
        stats_base.shape_changes = steps.iter().filter(|s| s.shape_change).count();
        stats_base.collision_checks = (after.translations + after.shape_changes)
            - (before.translations + before.shape_changes);
        Ok(PrmSolution {
            steps,
            stats: stats_base,
        })
    }

    /// Statistics of the roadmap alone (after [`Self::setup`]; zeros before).
    pub fn roadmap_stats(&self) -> PrmStats {
        match &self.graph {
            None => PrmStats::default(),
            Some(g) => PrmStats {
                roadmap_s: self.roadmap_s,
                vertices: g.xi.len(),
                goal_samples: g.goal_samples,
                sample_tries: g.tries,
                build_capped: g.capped,
                k: g.k,
                graph_edges: edge_count(&g.adj),
                ..Default::default()
            },
        }
    }
}

/// One query's lazy search.
struct Query<'a> {
    ctx: &'a CollisionContext,
    graph: &'a mut Graph,
    began: Instant,
    stop: Termination,
    collision: Duration,
    stats: PrmStats,
}

impl Query<'_> {
    fn run(
        mut self,
        params: &ChainParams,
        start: [f64; 3],
        start_shape: Shape,
        goal: [f64; 3],
        tol: f64,
    ) -> Result<(Vec<PrmStep>, PrmStats), PrmError> {
        let first = PrmStep {
            xi: start,
            shape: start_shape,
            shape_change: false,
        };
        if dist3(start, goal) <= tol {
            return Ok((vec![first], self.stats));
        }
        let n = self.graph.xi.len();
        // The start joins the roadmap as vertex n, with edges out only (A* never
        // comes back to its source).
        let mut e = Vec::new();
        embed(params, start, &start_shape, &mut e);
        let k = self.graph.k;
        let out: Vec<Edge> = self
            .graph
            .index
            .nearest(&e, k)
            .into_iter()
            .map(|(to, cost)| Edge::new(to as usize, cost, EdgeState::Unknown))
            .collect();
        self.graph.xi.push(start);
        self.graph.shapes.push(start_shape);
        self.graph.adj.push_vertex(out);
        let result = self.search(n, goal, tol).map(|path| {
            let mut steps = vec![first];
            for w in path.windows(2) {
                let (a, b) = (w[0], w[1]);
                let sb = self.graph.shapes[b];
                if self.graph.shapes[a] != sb {
                    steps.push(PrmStep {
                        xi: self.graph.xi[a],
                        shape: sb,
                        shape_change: true,
                    });
                }
                steps.push(PrmStep {
                    xi: self.graph.xi[b],
                    shape: sb,
                    shape_change: false,
                });
            }
            (steps, path.len() - 1)
        });
        self.graph.xi.truncate(n);
        self.graph.shapes.truncate(n);
        self.graph.adj.truncate(n, false);
        let (steps, path_edges) = result?;
        self.stats.path_edges = path_edges;
        self.stats.collision_s = self.collision.as_secs_f64();
        Ok((steps, self.stats))
    }

    /// Lazy PRM ([`LazyGraph::lazy_prm`]): A* over the edges not known blocked, then
    /// check the path's edges from the start; block the first bad one and search again.
    fn search(&mut self, from: usize, goal: [f64; 3], tol: f64) -> Result<Vec<usize>, PrmError> {
        let g = &*self.graph;
        let n = g.xi.len();
        let is_goal: Vec<bool> = g
            .xi
            .iter()
            .enumerate()
            .map(|(i, p)| i != from && dist3(*p, goal) <= tol)
            .collect();
        let sampled = n - 1;
        let (ctx, stop, began) = (self.ctx, self.stop, self.began);
        let (stats, collision) = (&mut self.stats, &mut self.collision);
        // Moving along `a -> b`: change shape at `xi_a`, then translate.
        let check = |a: usize, b: usize| {
            let t = Instant::now();
            let (xa, xb) = (g.xi[a], g.xi[b]);
            let (sa, sb) = (g.shapes[a], g.shapes[b]);
            let free = (sa == sb || ctx.check_shape_change(xa, &sa, &sb).is_ok())
                && (xa == xb || ctx.check_translation(xa, xb, &sb).is_ok());
            *collision += t.elapsed();
            stats.edges_checked += 1;
            if !free {
                stats.edges_blocked += 1;
            }
            free
        };
        let h = |v: usize| (dist3(g.xi[v], goal) - tol).max(0.0);
        let stopped = || stop.time_limit.is_some_and(|t| began.elapsed() > t);
        let (outcome, iterations) = g.adj.lazy_prm(from, &is_goal, h, check, stopped);
        self.stats.iterations += iterations;
        match outcome {
            LazyOutcome::Found(path) => Ok(path),
            LazyOutcome::NoPath => Err(PrmError::NoPath {
                vertices: sampled,
                iterations: self.stats.iterations,
            }),
            LazyOutcome::Stopped => Err(PrmError::TimeLimit {
                iterations: self.stats.iterations,
            }),
        }
    }
}

/// Undirected edges of a roadmap whose edges are kept both ways.
fn edge_count(g: &LazyGraph) -> usize {
    (0..g.len()).map(|v| g.edges(v).len()).sum::<usize>() / 2
}

/// The plan file (`arc-plan/1`) for an answer of the full-state PRM.
pub fn to_plan(
    solution: &PrmSolution,
    params: &ChainParams,
    resolution: f64,
    unknown_is_occupied: bool,
) -> Plan {
    let st = &solution.stats;
    let counts = [
        ("vertices", st.vertices as u64),
        ("goal_samples", st.goal_samples as u64),
        ("sample_tries", st.sample_tries),
        ("k", st.k as u64),
        ("graph_edges", st.graph_edges as u64),
        ("iterations", st.iterations as u64),
        ("edges_checked", st.edges_checked as u64),
        ("edges_blocked", st.edges_blocked as u64),
        ("path_edges", st.path_edges as u64),
        ("shape_changes", st.shape_changes as u64),
        ("collision_checks", st.collision_checks),
    ];
    let timing = Timing {
        roadmap_s: st.roadmap_s,
        planning_s: st.planning_s,
        collision_s: st.collision_s,
        rest: "search_s",
    };
    let steps = solution.steps.iter().map(|s| (s.xi, &s.shape));
    let mut plan = Plan::from_steps(
        params,
        (resolution, unknown_is_occupied),
        steps,
        &counts,
        &timing,
    );
    plan.stats
        .insert("planner".into(), json!("full-state lazy PRM"));
    plan.stats
        .insert("build_capped".into(), json!(st.build_capped));
    plan
}
