//! SRS-based edge connection (paper Alg. 3).
//!
//! For a head edge `xi_i -> xi_j` and the chain's current shape:
//! 1. ValidShapes: the SRS shapes (and the library's shapes at every heading)
//!    that are collision-free with the head at `xi_i`;
//! 2. AdmissibleShapes: those that stay collision-free along the whole edge;
//! 3. ConstructGraph `G_Val` over the current shape and the valid shapes: two valid
//!    random shapes are joined when `G_SRS` joins them (within `r_S`, and known
//!    offline to change into each other without self-collision); the current shape
//!    and the library shapes are joined to every valid shape within `d_c` in the
//!    `C_T` metric; a random shape turned to trail behind the edge is joined to
//!    its unturned self and to those. Neighbour lists are made when a vertex is first expanded, so
//!    the parts of `G_Val` the search never reaches cost nothing;
//! 4. OptAdmissibleTransition: Dijkstra by `C_T` from the current shape to the
//!    nearest admissible one;
//! 5. CollisionFreeE: every shape change on that path is checked at `xi_i`
//!    (limits, self-collision, map), and failing edges are pruned from `G_Val`
//!    until a path holds or none is left. Steps 4 and 5 are one lazy search: a
//!    change is checked when the search pops the shape it leads to, so no edge is
//!    checked twice and no search is repeated.

use std::collections::BinaryHeap;

use aerial_chain_core::cost::transition_cost;

use super::candidates::{Candidate, Source};
use super::graph::{path_to, Open};
use super::Checker;

/// Lazy answers to "is shape `v` valid at `xi_i`" and "is it admissible along the
/// edge": each asked at most once, and only for shapes the search reaches.
struct Oracle<'c> {
    checker: &'c mut Checker,
    from: [f64; 3],
    to: [f64; 3],
    valid: Vec<Option<bool>>,
    admissible: Vec<Option<bool>>,
}

impl Oracle<'_> {
    fn valid(&mut self, v: usize, nodes: &[Candidate]) -> bool {
        if self.valid[v].is_none() {
            self.valid[v] = Some(self.checker.placement(self.from, &nodes[v].shape));
        }
        self.valid[v] == Some(true)
    }

    fn admissible(&mut self, v: usize, nodes: &[Candidate]) -> bool {
        if self.admissible[v].is_none() {
            self.admissible[v] = Some(self.checker.translation(
                self.from,
                self.to,
                &nodes[v].shape,
            ));
        }
        self.admissible[v] == Some(true)
    }
}

/// What SRSConnect found: the shapes to pass through at `xi_i` (the last one
/// admissible along the edge), or nothing.
///
/// ValidShapes and AdmissibleShapes are evaluated lazily inside the search: a shape's
/// placement is checked when the search first reaches it, its admissibility when
/// it is the nearest open shape. The answer is the one the eager sets would give.
pub fn connect(
    checker: &mut Checker,
    from: [f64; 3],
    to: [f64; 3],
    current: &Candidate,
    pool: &[Candidate],
    srs_adjacency: &[Vec<u16>],
    d_c: f32,
) -> Option<Vec<Candidate>> {
    // Vertex 0 of G_Val is the current shape: valid here, not admissible (else
    // the edge would not have come to SRSConnect).
    let mut nodes = vec![*current];
    nodes.extend_from_slice(pool);
    let n = nodes.len();
    let mut oracle = Oracle {
        checker,
        from,
        to,
        valid: vec![None; n],
        admissible: vec![None; n],
    };
    oracle.valid[0] = Some(true);
    oracle.admissible[0] = Some(false);
    let mut graph = Graph::new(&nodes, srs_adjacency, d_c);
    let path = cheapest(&mut graph, &mut oracle)?;
    Some(path[1..].iter().map(|&i| nodes[i]).collect())
}

/// `G_Val` with neighbour lists made on first use.
struct Graph<'a> {
    nodes: &'a [Candidate],
    /// Node index of each valid SRS shape (by SRS index), and of its turned copy.
    srs_node: Vec<Option<usize>>,
    turned_node: Vec<Option<usize>>,
    srs_adjacency: &'a [Vec<u16>],
    /// The current shape and the library shapes: joined by `d_c`.
    hubs: Vec<usize>,
    d_c: f32,
    lists: Vec<Option<Vec<(usize, f32)>>>,
}

impl<'a> Graph<'a> {
    fn new(nodes: &'a [Candidate], srs_adjacency: &'a [Vec<u16>], d_c: f32) -> Self {
        let mut srs_node = vec![None; srs_adjacency.len()];
        let mut turned_node = vec![None; srs_adjacency.len()];
        let mut hubs = Vec::new();
        for (i, c) in nodes.iter().enumerate() {
            match c.source {
                Source::Srs(k) if i > 0 => srs_node[k as usize] = Some(i),
                Source::SrsTurned(k) if i > 0 => turned_node[k as usize] = Some(i),
                _ => hubs.push(i),
            }
        }
        Self {
            nodes,
            srs_node,
            turned_node,
            srs_adjacency,
            hubs,
            d_c,
            lists: vec![None; nodes.len()],
        }
    }

    fn cost(&self, v: usize, u: usize) -> f32 {
        transition_cost(&self.nodes[v].shape, &self.nodes[u].shape)
    }

    fn within(&self, v: usize, u: usize) -> Option<(usize, f32)> {
        let c = self.cost(v, u);
        (u != v && c <= self.d_c).then_some((u, c))
    }

    /// Neighbours of `v` with their `C_T`.
    fn neighbours(&mut self, v: usize) -> &[(usize, f32)] {
        if self.lists[v].is_none() {
            let list: Vec<(usize, f32)> = match self.nodes[v].source {
                Source::Srs(k) if v > 0 => {
                    let mut l: Vec<(usize, f32)> = self.srs_adjacency[k as usize]
                        .iter()
                        .filter_map(|&j| self.srs_node[j as usize])
                        .map(|u| {
                            (
                                u,
                                transition_cost(&self.nodes[v].shape, &self.nodes[u].shape),
                            )
                        })
                        .collect();
                    l.extend(self.turned_node[k as usize].map(|u| (u, self.cost(v, u))));
                    l.extend(self.hubs.iter().filter_map(|&u| self.within(v, u)));
                    l
                }
                Source::SrsTurned(k) if v > 0 => {
                    let mut l: Vec<(usize, f32)> = self.srs_node[k as usize]
                        .map(|u| (u, self.cost(v, u)))
                        .into_iter()
                        .collect();
                    l.extend(self.hubs.iter().filter_map(|&u| self.within(v, u)));
                    l
                }
                _ => (0..self.nodes.len())
                    .filter_map(|u| self.within(v, u))
                    .collect(),
            };
            self.lists[v] = Some(list);
        }
        self.lists[v].as_deref().unwrap_or(&[])
    }
}

/// Lazy Dijkstra over `G_Val` from vertex 0 to the nearest admissible vertex.
///
/// OptAdmissibleTransition, CollisionFreeE and the pruning of Alg. 3 in one search:
/// a shape enters the open list with the shape change that reaches it unchecked;
/// the change is checked (at `xi_i`: limits, self-collision, map) when that entry
/// is popped, and a failed one is dropped, which prunes that edge. So each edge is
/// checked at most once and the path returned is checked throughout.
fn cheapest(graph: &mut Graph<'_>, oracle: &mut Oracle<'_>) -> Option<Vec<usize>> {
    let n = graph.nodes.len();
    let nodes = graph.nodes;
    let mut parent = vec![usize::MAX; n];
    let mut done = vec![false; n];
    let mut open = BinaryHeap::new();
    open.push(Open::<f32> {
        f: 0.0,
        g: 0.0,
        v: 0,
        via: usize::MAX,
    });
    while let Some(Open { g: d, v, via, .. }) = open.pop() {
        if done[v] {
            continue;
        }
        if via != usize::MAX
            && !oracle
                .checker
                .shape_change(oracle.from, &nodes[via].shape, &nodes[v].shape)
        {
            continue;
        }
        done[v] = true;
        parent[v] = via;
        if v != 0 && oracle.admissible(v, nodes) {
            return Some(path_to(&parent, v));
        }
        for &(u, c) in graph.neighbours(v) {
            if !done[u] && oracle.valid(u, nodes) {
                open.push(Open {
                    f: d + c,
                    g: d + c,
                    v: u,
                    via: v,
                });
            }
        }
    }
    None
}
