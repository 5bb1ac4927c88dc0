//! One query of the full-state PRM: the start joins the roadmap, the lazy PRM search
//! ([`crate::planner::graph::LazyGraph::lazy_prm`]) finds a path whose edges all pass, and the path becomes
//! waypoints ("change shape, then translate" per edge).

use std::time::{Duration, Instant};

use aerial_chain_core::Shape;

use super::metric::embed;
use super::roadmap::Roadmap;
use super::{PrmError, PrmStats};
use crate::collision::CollisionContext;
use crate::planner::graph::{Edge, EdgeState, LazyOutcome, VertexId};
use crate::planner::{dist, Query, Source, Step, Termination};

/// One query's lazy search.
pub(super) struct LazySearch<'a> {
    pub(super) ctx: &'a CollisionContext,
    pub(super) roadmap: &'a mut Roadmap,
    /// When the query (its roadmap build included) began: the time limit counts
    /// from here.
    pub(super) began: Instant,
    pub(super) stop: Termination,
    pub(super) collision: Duration,
    pub(super) stats: PrmStats,
}

impl LazySearch<'_> {
    /// Plans `query` over the roadmap: the waypoints and the query's counters.
    pub(super) fn run(mut self, query: &Query) -> Result<(Vec<Step>, PrmStats), PrmError> {
        let (start, goal) = query.ends();
        let (start_shape, tol) = (query.start_shape, query.goal_tol);
        let first = Step {
            xi: start.into(),
            shape: start_shape,
            source: Source::Start,
            shape_change: false,
        };
        if dist(start, goal) <= tol {
            return Ok((vec![first], self.stats));
        }
        let n = self.roadmap.xi.len();
        self.add_start(start, start_shape);
        let result = self.search(n, goal, tol).map(|path| {
            let mut steps = vec![first];
            steps.extend(self.waypoints(&path));
            (steps, path.len() - 1)
        });
        let r = &mut *self.roadmap;
        r.xi.truncate(n);
        r.shapes.truncate(n);
        r.graph.truncate(n, false);
        let (steps, path_edges) = result?;
        self.stats.path_edges = path_edges;
        self.stats.timings.collision_s = self.collision.as_secs_f64();
        Ok((steps, self.stats))
    }

    /// The start joins the roadmap as the last vertex, with edges out only (A* never
    /// comes back to its source).
    fn add_start(&mut self, start: [f64; 3], start_shape: Shape) {
        let r = &mut *self.roadmap;
        let mut e = Vec::new();
        embed(self.ctx.params(), start, &start_shape, &mut e);
        let out: Vec<Edge> = r
            .index
            .nearest(&e, r.k)
            .into_iter()
            .map(|(to, cost)| Edge::new(to as usize, cost, EdgeState::Unknown))
            .collect();
        r.xi.push(start);
        r.shapes.push(start_shape);
        r.graph.push_vertex(out);
    }

    /// The waypoints of a path after its first vertex: per edge, the shape change at
    /// its start (where the shape changes), then the translation.
    fn waypoints(&self, path: &[VertexId]) -> Vec<Step> {
        let r = &*self.roadmap;
        let mut steps = Vec::new();
        for w in path.windows(2) {
            let (a, b) = (w[0], w[1]);
            let sb = r.shapes[b];
            if r.shapes[a] != sb {
                steps.push(Step {
                    xi: r.xi[a].into(),
                    shape: sb,
                    source: Source::Sampled,
                    shape_change: true,
                });
            }
            steps.push(Step {
                xi: r.xi[b].into(),
                shape: sb,
                source: Source::Sampled,
                shape_change: false,
            });
        }
        steps
    }

    /// Lazy PRM ([`crate::planner::graph::LazyGraph::lazy_prm`]): A* over the edges not known blocked, then
    /// check the path's edges from the start; block the first bad one and search again.
    fn search(&mut self, from: usize, goal: [f64; 3], tol: f64) -> Result<Vec<usize>, PrmError> {
        let r = &*self.roadmap;
        let n = r.xi.len();
        let is_goal: Vec<bool> =
            r.xi.iter()
                .enumerate()
                .map(|(i, p)| i != from && dist(*p, goal) <= tol)
                .collect();
        let sampled = n - 1;
        let (ctx, stop, began) = (self.ctx, self.stop, self.began);
        let (stats, collision) = (&mut self.stats, &mut self.collision);
        // Moving along `a -> b`: change shape at `xi_a`, then translate.
        let check = |a: usize, b: usize| {
            let t = Instant::now();
            let (xa, xb) = (r.xi[a], r.xi[b]);
            let (sa, sb) = (r.shapes[a], r.shapes[b]);
            let free = (sa == sb || ctx.check_shape_change(xa, &sa, &sb).is_ok())
                && (xa == xb || ctx.check_translation(xa, xb, &sb).is_ok());
            *collision += t.elapsed();
            stats.edges_checked += 1;
            if !free {
                stats.edges_blocked += 1;
            }
            free
        };
        let h = |v: usize| (dist(r.xi[v], goal) - tol).max(0.0);
        let stopped = || stop.time_limit.is_some_and(|t| began.elapsed() > t);
        let (outcome, iterations) = r.graph.lazy_prm(from, &is_goal, h, check, stopped);
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
