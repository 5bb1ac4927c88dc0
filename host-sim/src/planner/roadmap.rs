//! The translation planner (paper Alg. 1): a probabilistic roadmap over the head's
//! position only, queried lazily.
//!
//! `M_VT` head positions are sampled uniformly in the map's box where the head's
//! sphere is free; every vertex is joined to its `k` nearest within `r_T` (points
//! binned in cubes, [`super::near`]), a query's vertices to every vertex within `r_T`
//! (a k-d tree, kiddo). Edges are NOT checked when the roadmap is built: a query runs
//! A* on the unchecked graph, then checks the edges of the path it found, marks the
//! bad ones and searches again (lazy PRM). Checked edges stay checked, so later queries on
//! the same roadmap get cheaper (multi-query).

use std::time::Instant;

use kiddo::ImmutableKdTree;
use kiddo::SquaredEuclidean;
use rand::Rng;
use rand_pcg::Pcg64;
use rayon::prelude::*;

use super::dist;
use super::graph::{Edge, EdgeState, LazyGraph};
use crate::collision::CollisionContext;

/// Vertex index in the roadmap; queries add the start and goal after the sampled ones.
pub use super::graph::VertexId;

/// The head roadmap `G_T`.
#[derive(Debug)]
pub struct Roadmap {
    points: Vec<[f64; 3]>,
    /// Proven obstacle clearance at each vertex (m).
    clearance: Vec<f64>,
    /// Edge weight factor: see [`Roadmap::build`].
    clearance_weight: f64,
    /// Clearance at which the weight factor vanishes (m).
    clearance_ref: f64,
    /// Edges weigh their length, grown near obstacles; the head's check is the same
    /// both ways, so the graph is symmetric.
    graph: LazyGraph,
    tree: ImmutableKdTree<f64, 3>,
    r_t: f64,
    sampled: usize,
}

/// How a query ended.
#[derive(Clone, Debug, PartialEq)]
pub enum RouteError {
    /// The start could not be joined to any vertex.
    StartIsolated,
    /// No path to the goal region exists in the roadmap.
    Unreachable,
}

impl Roadmap {
    /// Samples `vertices` free head positions (at most `vertices * 200` tries) and
    /// joins each to its `k` nearest within `r_t` (edges are kept both ways). Past
    /// `deadline` it stops and keeps what it has: a smaller roadmap, or vertices
    /// without their own nearest-neighbour edges.
    ///
    /// Edges weigh their length times `1 + w * max(0, 1 - c / c_ref)`, where `c` is
    /// the smaller obstacle clearance of their ends, `w` = `clearance_weight` and
    /// `c_ref` = `clearance_ref`: head paths keep to the middle of gaps and rooms,
    /// where the chain behind the head has room. With `w = 0` paths are the
    /// shortest, as in the paper. Weights are never below the length, so the
    /// Euclidean A* heuristic stays admissible.
    pub fn build(
        ctx: &CollisionContext,
        vertices: usize,
        (r_t, k): (f64, usize),
        (clearance_weight, clearance_ref): (f64, f64),
        rng: &mut Pcg64,
        deadline: Option<Instant>,
    ) -> Self {
        let points = sample(ctx, vertices, rng, deadline);
        let tree = ImmutableKdTree::new_from_slice(&points);
        // Each vertex's k nearest within r_T, then made symmetric, in vertex order for
        // determinism; past the deadline a vertex keeps only the edges the others give
        // it.
        let on_time = |_| deadline.is_none_or(|d| Instant::now() <= d);
        let nearest = super::near::nearest_within(&points, r_t, k, on_time);
        let clearance: Vec<f64> = points.par_iter().map(|&p| ctx.clearance(p)).collect();
        let weight = EdgeWeight {
            w: clearance_weight,
            r: clearance_ref.max(super::numeric::TIE),
        };
        let edges = symmetric_edges(&nearest, &points, &clearance, weight);
        let sampled = points.len();
        Self {
            points,
            clearance,
            clearance_weight,
            clearance_ref,
            graph: LazyGraph::new(edges, true),
            tree,
            r_t,
            sampled,
        }
    }

    /// Number of vertices, query vertices included.
    pub fn total_vertices(&self) -> usize {
        self.points.len()
    }

    /// Number of sampled vertices.
    pub fn vertex_count(&self) -> usize {
        self.sampled
    }

    /// Number of (undirected) candidate edges between sampled vertices.
    pub fn edge_count(&self) -> usize {
        (0..self.sampled)
            .map(|v| self.graph.edges(v).len())
            .sum::<usize>()
            / 2
    }

    /// Position of vertex `v`.
    pub fn point(&self, v: VertexId) -> [f64; 3] {
        self.points[v]
    }

    /// Adds a query vertex (start or goal) joined to the sampled vertices within
    /// `r_T`; removed again by [`Self::clear_query`].
    pub fn add_query_vertex(&mut self, p: [f64; 3]) -> VertexId {
        let id = self.push_vertex(p, f64::INFINITY);
        for (j, length) in self.sampled_within_r_t(p) {
            self.link(id, j, length, EdgeState::Unknown);
        }
        // Query vertices see each other too (a start next to the goal).
        for q in self.sampled..id {
            let length = dist(self.points[q], p);
            if length <= self.r_t {
                self.link(id, q, length, EdgeState::Unknown);
            }
        }
        id
    }

    /// Appends a vertex at `p` with obstacle clearance `c` and no edges yet.
    fn push_vertex(&mut self, p: [f64; 3], c: f64) -> VertexId {
        let id = self.points.len();
        self.points.push(p);
        self.clearance.push(c);
        self.graph.push_vertex(Vec::new());
        id
    }

    /// The sampled vertices within `r_T` of `p`, by index, with their distances.
    fn sampled_within_r_t(&self, p: [f64; 3]) -> Vec<(VertexId, f64)> {
        if self.sampled == 0 {
            return Vec::new(); // a route-only roadmap: nothing sampled to join
        }
        let mut near = self
            .tree
            .within_unsorted::<SquaredEuclidean>(&p, self.r_t * self.r_t);
        near.sort_by_key(|n| n.item);
        near.iter()
            .map(|n| (n.item as usize, n.distance.sqrt()))
            .collect()
    }

    /// Joins `a` and `b` both ways by an edge of `length` in `state`.
    fn link(&mut self, a: VertexId, b: VertexId, length: f64, state: EdgeState) {
        for (x, y) in [(a, b), (b, a)] {
            self.graph.push_edge(x, y, length, state);
        }
    }

    /// Adds a head route (from the lattice search, [`super::lattice`]) between the query
    /// vertices `from` and `to`: its inner points become query vertices chained by
    /// edges known to be free (the route was pulled taut with the head's check) that
    /// weigh their length, so the route is the cheapest way. Each route vertex is also
    /// joined to the sampled vertices within `r_T`, by edges weighted by clearance as
    /// the roadmap's own, so that replanning can leave the route. Removed by
    /// [`Self::clear_query`]. Returns the route's vertices, `from` and `to` included.
    pub fn add_route(
        &mut self,
        ctx: &CollisionContext,
        from: VertexId,
        inner: &[[f64; 3]],
        to: VertexId,
    ) -> Vec<VertexId> {
        let (w, r) = (
            self.clearance_weight,
            self.clearance_ref.max(super::numeric::TIE),
        );
        let mut ids = vec![from];
        for &p in inner {
            let c = ctx.clearance(p);
            let id = self.push_vertex(p, c);
            for (j, d) in self.sampled_within_r_t(p) {
                let cj = c.min(self.clearance[j]);
                let length = d * (1.0 + w * (1.0 - cj / r).max(0.0));
                self.link(id, j, length, EdgeState::Unknown);
            }
            ids.push(id);
        }
        ids.push(to);
        for wnd in ids.windows(2) {
            let (a, b) = (wnd[0], wnd[1]);
            let length = dist(self.points[a], self.points[b]);
            for (x, y) in [(a, b), (b, a)] {
                self.graph.set_edge(x, y, length, EdgeState::Valid);
            }
        }
        ids
    }

    /// Whether `v` is a query vertex (start, goal or route), not a sampled one.
    pub fn is_query(&self, v: VertexId) -> bool {
        v >= self.sampled
    }

    /// Removes the query vertices and their edges; the sampled roadmap and what is
    /// known about its edges stay.
    pub fn clear_query(&mut self) {
        self.points.truncate(self.sampled);
        self.clearance.truncate(self.sampled);
        self.graph.truncate(self.sampled, true);
    }

    /// The cost to reach the nearest of `goals` from every vertex over the edges not
    /// known to be blocked ([`LazyGraph::cost_to_go`]; the graph is symmetric).
    pub fn cost_to_go(&self, goals: &[VertexId]) -> Vec<f64> {
        self.graph.cost_to_go(goals)
    }

    /// The shortest head path from `from` to any vertex of `goals`, every edge on it
    /// checked for the head's sphere. `banned` edges are skipped; `h` is the
    /// heuristic, from [`Self::cost_to_go`] for these goals.
    ///
    /// Lazy Weighted A* ([`LazyGraph::lazy_astar`]): only edges leading to expanded
    /// vertices are ever checked. With the exact cost-to-go as the heuristic, a search
    /// expands little more than the path it returns.
    pub fn route(
        &self,
        ctx: &CollisionContext,
        from: VertexId,
        goals: &[VertexId],
        h: &[f64],
        banned: &dyn Fn(VertexId, VertexId) -> bool,
    ) -> Result<Vec<VertexId>, RouteError> {
        if self.graph.edges(from).is_empty() {
            return Err(RouteError::StartIsolated);
        }
        let mut is_goal = vec![false; self.points.len()];
        for &q in goals {
            is_goal[q] = true;
        }
        let points = &self.points;
        self.graph
            .lazy_astar(from, &is_goal, h, banned, |a, b| {
                ctx.is_head_segment_free(points[a], points[b])
            })
            .ok_or(RouteError::Unreachable)
    }
}

/// Up to `vertices` head positions drawn uniformly in the map's box where the head's
/// sphere is free, at most `vertices * 200` draws (at least 1000); past `deadline`, what
/// was found. (Checking the draws in batches on every thread was slower: a draw costs
/// a few hundred nanoseconds, and the sampling 0.55 -> 0.75 ms on a forest.)
fn sample(
    ctx: &CollisionContext,
    vertices: usize,
    rng: &mut Pcg64,
    deadline: Option<Instant>,
) -> Vec<[f64; 3]> {
    let (lo, hi) = ctx.field().grid().bounds();
    let mut points = Vec::with_capacity(vertices);
    let mut tries = 0usize;
    // Past the deadline the roadmap keeps what it has (checked every 256 tries).
    let late =
        |tries: usize| tries.is_multiple_of(256) && deadline.is_some_and(|d| Instant::now() > d);
    while points.len() < vertices && tries < vertices.saturating_mul(200).max(1000) {
        if late(tries) {
            break;
        }
        tries += 1;
        let p = [
            rng.gen_range(lo[0]..hi[0]),
            rng.gen_range(lo[1]..hi[1]),
            rng.gen_range(lo[2]..hi[2]),
        ];
        if ctx.is_head_free(p) {
            points.push(p);
        }
    }
    points
}

/// How an edge between sampled vertices weighs: its length grown by `w` times how far
/// the smaller clearance of its ends falls below `r` ([`Roadmap::build`]).
#[derive(Clone, Copy)]
struct EdgeWeight {
    w: f64,
    r: f64,
}

/// Every vertex's edges: to its own `nearest` and to those that count it among theirs,
/// each once, by vertex, weighed by [`EdgeWeight`]; the vertices on every thread.
fn symmetric_edges(
    nearest: &[Vec<usize>],
    points: &[[f64; 3]],
    clearance: &[f64],
    EdgeWeight { w, r }: EdgeWeight,
) -> Vec<Vec<Edge>> {
    // Who counts each vertex among its nearest, in one array (a counting sort): a
    // list per vertex cost more in allocations than the rest of the edges' work.
    let mut start = vec![0usize; points.len() + 1];
    for &j in nearest.iter().flatten() {
        start[j + 1] += 1;
    }
    for v in 1..start.len() {
        start[v] += start[v - 1];
    }
    let mut next = start.clone();
    let mut given = vec![0usize; start[points.len()]];
    for (i, near) in nearest.iter().enumerate() {
        for &j in near {
            given[next[j]] = i;
            next[j] += 1;
        }
    }
    (0..points.len())
        .into_par_iter()
        .map_init(Vec::new, |ids: &mut Vec<usize>, i| {
            ids.clear();
            ids.extend_from_slice(&nearest[i]);
            ids.extend_from_slice(&given[start[i]..start[i + 1]]);
            ids.sort_unstable();
            ids.dedup();
            let edge = |&j: &usize| {
                let c = clearance[i].min(clearance[j]);
                let cost = dist(points[i], points[j]) * (1.0 + w * (1.0 - c / r).max(0.0));
                Edge::new(j, cost, EdgeState::Unknown)
            };
            ids.iter().map(edge).collect()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use aerial_chain_core::ChainParams;
    use rand::SeedableRng;

    use super::*;
    use crate::map::distance::DistanceField;
    use crate::problem::scenarios;

    fn window_roadmap() -> (CollisionContext, Roadmap, [f64; 3], [f64; 3]) {
        let sc = scenarios::build("window").expect("built-in scenario");
        let field = Arc::new(DistanceField::new(sc.grid.clone()));
        let ctx = CollisionContext::new(field, ChainParams::new(5), 0.05).expect("context");
        let mut rng = Pcg64::seed_from_u64(3);
        let map = Roadmap::build(&ctx, 3000, (1.5, 30), (2.0, 1.0), &mut rng, None);
        (ctx, map, sc.start.into(), sc.goal.into())
    }

    /// Adds `start` and `goal` as query vertices; returns them and the cost-to-go to the
    /// goal.
    fn query(map: &mut Roadmap, start: [f64; 3], goal: [f64; 3]) -> (VertexId, VertexId, Vec<f64>) {
        let s = map.add_query_vertex(start);
        let g = map.add_query_vertex(goal);
        let h = map.cost_to_go(&[g]);
        (s, g, h)
    }

    fn cost(map: &Roadmap, path: &[VertexId]) -> f64 {
        path.windows(2)
            .map(|w| map.graph.edge(w[0], w[1]).expect("path follows edges").cost)
            .sum()
    }

    #[test]
    fn routes_are_checked_edges_and_no_cheaper_than_the_heuristic() {
        let (ctx, mut map, start, goal) = window_roadmap();
        let (s, g, h) = query(&mut map, start, goal);
        assert_eq!(h[g], 0.0);
        // The heuristic never overestimates: weights are at least the length.
        for (v, &hv) in h.iter().enumerate() {
            assert!(hv + 1e-9 >= dist(map.point(v), goal) || !hv.is_finite());
        }
        let path = map.route(&ctx, s, &[g], &h, &|_, _| false).expect("route");
        assert_eq!((path[0], path[path.len() - 1]), (s, g));
        for w in path.windows(2) {
            assert!(ctx.is_head_segment_free(map.point(w[0]), map.point(w[1])));
        }
        assert!(cost(&map, &path) + 1e-9 >= h[s]);
    }

    #[test]
    fn banned_edges_are_avoided_and_the_route_stays_optimal_among_the_rest() {
        let (ctx, mut map, start, goal) = window_roadmap();
        let (s, g, h) = query(&mut map, start, goal);
        let first = map.route(&ctx, s, &[g], &h, &|_, _| false).expect("route");
        let (a, b) = (first[0], first[1]);
        let banned = move |x: VertexId, y: VertexId| (x, y) == (a, b) || (x, y) == (b, a);
        let second = map
            .route(&ctx, s, &[g], &h, &banned)
            .expect("another route");
        assert!(second.windows(2).all(|w| !banned(w[0], w[1])));
        assert!(cost(&map, &second) + 1e-9 >= cost(&map, &first));
        // The same search without the heuristic's help finds the same cost.
        let zero = vec![0.0; map.total_vertices()];
        let plain = map
            .route(&ctx, s, &[g], &zero, &banned)
            .expect("Dijkstra route");
        assert!((cost(&map, &plain) - cost(&map, &second)).abs() < 1e-9);
    }
}
