//! The lazy roadmap graph both planners search: vertices by index, weighted edges
//! whose validity is unknown until a search needs it, and the two lazy searches
//! over them.
//!
//! An edge starts [`EdgeState::Unknown`]; the first time a search needs it, the
//! planner's check decides it [`EdgeState::Valid`] or [`EdgeState::Invalid`], and the
//! verdict is kept for later searches and later queries on the same roadmap
//! (multi-query). Where validity does not depend on the direction (the head's sphere
//! on a segment), one check settles both directions (a symmetric [`LazyGraph`]).
//!
//! The searches:
//! - [`LazyGraph::lazy_astar`], Lazy Weighted A* (Cohen, Phillips, Likhachev 2014):
//!   a vertex enters the open list with the edge that reached it unchecked, and the
//!   edge is checked when that entry is popped; one search returns a checked path.
//! - [`LazyGraph::lazy_prm`], lazy PRM (Bohlin and Kavraki 2000): A* over the edges not
//!   known to be invalid, then the path's edges are checked from the start; the first
//!   invalid one is marked and A* runs again.
//!
//! Open lists break ties by vertex id (then by the vertex reached from), so the same
//! graph gives the same path on any machine.

use std::cell::Cell;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// Vertex index in a roadmap.
pub type VertexId = usize;

/// No vertex: the parent of a search's source.
const NONE: VertexId = VertexId::MAX;

/// What is known about one directed edge.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EdgeState {
    /// Not checked yet.
    Unknown,
    /// Checked, or known by construction, to be flyable.
    Valid,
    /// Checked and found blocked.
    Invalid,
}

/// One directed edge.
#[derive(Clone, Debug)]
pub struct Edge {
    /// The vertex it leads to.
    pub to: VertexId,
    /// Its weight (a length, or a metric's distance).
    pub cost: f64,
    /// What is known about it (a cell: searches learn while they read the graph).
    state: Cell<EdgeState>,
}

impl Edge {
    /// An edge to `to` of weight `cost`, in `state`.
    pub fn new(to: VertexId, cost: f64, state: EdgeState) -> Self {
        Self {
            to,
            cost,
            state: Cell::new(state),
        }
    }

    /// What is known about the edge.
    pub fn state(&self) -> EdgeState {
        self.state.get()
    }

    /// Records what is known about the edge.
    pub fn set_state(&self, s: EdgeState) {
        self.state.set(s);
    }
}

/// Adjacency lists with lazy edge states.
#[derive(Clone, Debug)]
pub struct LazyGraph {
    edges: Vec<Vec<Edge>>,
    /// Whether an edge's validity is the same both ways, so that one check settles
    /// the edge and its reverse.
    symmetric: bool,
}

/// How a lazy PRM search ended.
#[derive(Clone, Debug, PartialEq)]
pub enum LazyOutcome {
    /// A path whose every edge is valid, the source first.
    Found(Vec<VertexId>),
    /// No path is left over the edges not known to be invalid.
    NoPath,
    /// The stop condition ended the search.
    Stopped,
}

impl LazyGraph {
    /// A graph with these adjacency lists.
    pub fn new(edges: Vec<Vec<Edge>>, symmetric: bool) -> Self {
        Self { edges, symmetric }
    }

    /// Number of vertices.
    pub fn len(&self) -> usize {
        self.edges.len()
    }

    /// The edges leaving `v`.
    pub fn edges(&self, v: VertexId) -> &[Edge] {
        &self.edges[v]
    }

    /// The edge `a -> b`, if there is one.
    pub fn edge(&self, a: VertexId, b: VertexId) -> Option<&Edge> {
        self.edges[a].iter().find(|e| e.to == b)
    }

    /// Appends a vertex with these out-edges; returns its id.
    pub fn push_vertex(&mut self, out: Vec<Edge>) -> VertexId {
        self.edges.push(out);
        self.edges.len() - 1
    }

    /// Adds the edge `a -> b`.
    pub fn push_edge(&mut self, a: VertexId, b: VertexId, cost: f64, state: EdgeState) {
        self.edges[a].push(Edge::new(b, cost, state));
    }

    /// Sets the edge `a -> b` to `cost` and `state`, adding it if missing.
    pub fn set_edge(&mut self, a: VertexId, b: VertexId, cost: f64, state: EdgeState) {
        match self.edges[a].iter_mut().find(|e| e.to == b) {
            Some(e) => {
                e.cost = cost;
                e.state.set(state);
            }
            None => self.push_edge(a, b, cost, state),
        }
    }

    /// Keeps the first `n` vertices and drops every other vertex's edges; with
    /// `edges_into` also the edges of the kept vertices that lead past them.
    pub fn truncate(&mut self, n: usize, edges_into: bool) {
        self.edges.truncate(n);
        if edges_into {
            for e in self.edges.iter_mut() {
                e.retain(|x| x.to < n);
            }
        }
    }

    /// Whether the edge `a -> b` is valid: what is known, or else `check()` (made once
    /// and recorded, for both directions in a symmetric graph). `None`: no such edge.
    /// The flag says whether `check` ran.
    pub fn evaluate(
        &self,
        a: VertexId,
        b: VertexId,
        check: impl FnOnce() -> bool,
    ) -> Option<(bool, bool)> {
        let e = self.edge(a, b)?;
        match e.state() {
            EdgeState::Valid => return Some((true, false)),
            EdgeState::Invalid => return Some((false, false)),
            EdgeState::Unknown => {}
        }
        let valid = check();
        let s = if valid {
            EdgeState::Valid
        } else {
            EdgeState::Invalid
        };
        e.set_state(s);
        if self.symmetric {
            if let Some(r) = self.edge(b, a) {
                r.set_state(s);
            }
        }
        Some((valid, true))
    }

    /// The cost to reach the nearest of `goals` from every vertex over the edges not
    /// known to be invalid (reverse Dijkstra: for a graph whose edges weigh the same
    /// both ways); infinite where no goal can be reached. Marking edges invalid only
    /// raises true costs, so this stays a consistent A* heuristic afterwards.
    pub fn cost_to_go(&self, goals: &[VertexId]) -> Vec<f64> {
        let mut cost = vec![f64::INFINITY; self.edges.len()];
        let mut open = BinaryHeap::new();
        for &q in goals {
            cost[q] = 0.0;
            open.push(Open {
                f: 0.0,
                g: 0.0,
                v: q,
                via: NONE,
            });
        }
        while let Some(Open { g, v, .. }) = open.pop() {
            if g > cost[v] {
                continue;
            }
            for e in &self.edges[v] {
                let ng = g + e.cost;
                if e.state() != EdgeState::Invalid && ng < cost[e.to] {
                    cost[e.to] = ng;
                    open.push(Open {
                        f: ng,
                        g: ng,
                        v: e.to,
                        via: v,
                    });
                }
            }
        }
        cost
    }

    /// Lazy Weighted A* from `from` to any vertex where `is_goal` holds, with the
    /// heuristic `h` (vertices where it is infinite are never entered), skipping
    /// `banned` edges; an edge is checked with `check` when the entry it leads to is
    /// popped. Returns a path of valid edges, or `None`.
    pub fn lazy_astar(
        &self,
        from: VertexId,
        is_goal: &[bool],
        h: &[f64],
        banned: &dyn Fn(VertexId, VertexId) -> bool,
        mut check: impl FnMut(VertexId, VertexId) -> bool,
    ) -> Option<Vec<VertexId>> {
        let n = self.edges.len();
        let mut closed = vec![false; n];
        let mut parent = vec![NONE; n];
        // Best cost at which a vertex is queued through an edge known to be valid:
        // a costlier entry can never be needed (an unknown edge may still fail, so
        // entries through those are always queued).
        let mut best_valid = vec![f64::INFINITY; n];
        let mut open = BinaryHeap::new();
        open.push(Open {
            f: h[from],
            g: 0.0,
            v: from,
            via: NONE,
        });
        while let Some(Open { g, v, via, .. }) = open.pop() {
            if closed[v] {
                continue;
            }
            if via != NONE && !self.evaluate(via, v, || check(via, v)).is_some_and(|e| e.0) {
                continue;
            }
            closed[v] = true;
            parent[v] = via;
            if is_goal[v] {
                return Some(path_to(&parent, v));
            }
            for e in &self.edges[v] {
                let state = e.state();
                if closed[e.to] || state == EdgeState::Invalid || !h[e.to].is_finite() {
                    continue;
                }
                let ng = g + e.cost;
                if ng >= best_valid[e.to] || banned(v, e.to) {
                    continue;
                }
                if state == EdgeState::Valid {
                    best_valid[e.to] = ng;
                }
                open.push(Open {
                    f: ng + h[e.to],
                    g: ng,
                    v: e.to,
                    via: v,
                });
            }
        }
        None
    }

    /// Lazy PRM from `from` to any vertex where `is_goal` holds: A* (heuristic `h`)
    /// over the edges not known to be invalid, then the path's edges are checked with
    /// `check` from the start; the first invalid one is marked and A* runs again.
    /// `stopped` is asked before each search and after each edge checked. Returns how
    /// it ended and the number of A* searches.
    pub fn lazy_prm(
        &self,
        from: VertexId,
        is_goal: &[bool],
        h: impl Fn(VertexId) -> f64,
        mut check: impl FnMut(VertexId, VertexId) -> bool,
        stopped: impl Fn() -> bool,
    ) -> (LazyOutcome, usize) {
        let mut searches = 0;
        loop {
            if stopped() {
                return (LazyOutcome::Stopped, searches);
            }
            searches += 1;
            let Some(path) = self.astar(from, is_goal, &h) else {
                return (LazyOutcome::NoPath, searches);
            };
            let mut all_valid = true;
            for w in path.windows(2) {
                let (a, b) = (w[0], w[1]);
                if !self.evaluate(a, b, || check(a, b)).is_some_and(|e| e.0) {
                    all_valid = false;
                    break;
                }
                if stopped() {
                    return (LazyOutcome::Stopped, searches);
                }
            }
            if all_valid {
                return (LazyOutcome::Found(path), searches);
            }
        }
    }

    /// A* from `from` to any goal vertex over the edges not known to be invalid.
    fn astar(
        &self,
        from: VertexId,
        is_goal: &[bool],
        h: &impl Fn(VertexId) -> f64,
    ) -> Option<Vec<VertexId>> {
        let n = self.edges.len();
        let mut best = vec![f64::INFINITY; n];
        let mut parent = vec![NONE; n];
        let mut closed = vec![false; n];
        let mut open = BinaryHeap::new();
        best[from] = 0.0;
        // The parent is kept per vertex, not per entry: entries leave `via` unset, so
        // that ties order by vertex alone.
        open.push(Open {
            f: h(from),
            g: 0.0,
            v: from,
            via: NONE,
        });
        while let Some(Open { g: gv, v, .. }) = open.pop() {
            if closed[v] {
                continue;
            }
            closed[v] = true;
            if is_goal[v] {
                return Some(path_to(&parent, v));
            }
            for e in &self.edges[v] {
                let u = e.to;
                if closed[u] || e.state() == EdgeState::Invalid {
                    continue;
                }
                let ng = gv + e.cost;
                if ng < best[u] {
                    best[u] = ng;
                    parent[u] = v;
                    open.push(Open {
                        f: ng + h(u),
                        g: ng,
                        v: u,
                        via: NONE,
                    });
                }
            }
        }
        None
    }
}

/// The path of parents from a search's source to `v`, the source first (the source's
/// parent is `usize::MAX`).
pub fn path_to(parent: &[VertexId], v: VertexId) -> Vec<VertexId> {
    let mut path = vec![v];
    while parent[path[path.len() - 1]] != NONE {
        path.push(parent[path[path.len() - 1]]);
    }
    path.reverse();
    path
}

/// A path cost the open lists can order: compared by IEEE total order.
pub trait Cost: Copy + PartialEq {
    /// [`f64::total_cmp`] for the type.
    fn total_cmp(&self, other: &Self) -> Ordering;
}

impl Cost for f64 {
    fn total_cmp(&self, other: &Self) -> Ordering {
        f64::total_cmp(self, other)
    }
}

impl Cost for f32 {
    fn total_cmp(&self, other: &Self) -> Ordering {
        f32::total_cmp(self, other)
    }
}

/// Open-list entry: vertex `v` reached from `via` at cost `g`, ordered by `f`; lowest
/// `f` first, ties broken by vertex id, then by `via`, for determinism.
#[derive(PartialEq)]
pub struct Open<C: Cost = f64> {
    /// The key: cost so far plus the heuristic.
    pub f: C,
    /// Cost so far.
    pub g: C,
    /// The vertex reached.
    pub v: VertexId,
    /// The vertex it was reached from (`usize::MAX` for a source).
    pub via: VertexId,
}

impl<C: Cost> Eq for Open<C> {}

impl<C: Cost> Ord for Open<C> {
    fn cmp(&self, o: &Self) -> Ordering {
        o.f.total_cmp(&self.f)
            .then_with(|| o.v.cmp(&self.v))
            .then_with(|| o.via.cmp(&self.via))
    }
}

impl<C: Cost> PartialOrd for Open<C> {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
