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

use std::collections::{BinaryHeap, HashMap};

use aerial_chain_core::cost::transition_cost;
use aerial_chain_core::Shape;

use super::candidates::{Candidate, Source};
use super::graph::{path_to, Open};
use super::Checker;

/// A shape change whose answer [`Memo`] keeps: from the current shape to a random
/// shape, or between two random shapes (SRS indices).
#[derive(Clone, Copy)]
enum Change {
    FromCurrent(usize),
    Between(u16, u16),
}

/// The answers one call learns at `xi_i` that do not depend on the edge, kept for
/// the next call from the same head position, shape and clearance: where edge after
/// edge fails from one vertex (a chain boxed in at its start), every call would
/// otherwise check the same placements of the random shapes and the same changes
/// between them. Answers about turned shapes depend on the edge and are not kept.
#[derive(Debug, Default)]
pub(super) struct Memo {
    /// The head position and the clearance (their bits) the answers hold at.
    at: Option<([u64; 3], u64)>,
    /// Placement of each random shape (by SRS index).
    valid: Vec<Option<bool>>,
    /// Shape changes between random shapes (SRS indices, from and to).
    changes: HashMap<(u16, u16), bool>,
    /// The shape the changes from the current shape start from, and their answers.
    current: Option<Shape>,
    from_current: Vec<Option<bool>>,
}

impl Memo {
    /// Keeps what holds at `from` with `clearance` and shape `current`; forgets the rest.
    fn prepare(&mut self, from: [f64; 3], clearance: f64, current: &Shape, shapes: usize) {
        let at = (from.map(f64::to_bits), clearance.to_bits());
        if self.at != Some(at) || self.valid.len() != shapes {
            *self = Memo {
                at: Some(at),
                valid: vec![None; shapes],
                from_current: vec![None; shapes],
                ..Memo::default()
            };
        }
        if self.current.as_ref() != Some(current) {
            self.current = Some(*current);
            self.from_current = vec![None; shapes];
        }
    }

    /// The kept answer to the change `key`, if any.
    fn change(&self, key: Change) -> Option<bool> {
        match key {
            Change::FromCurrent(to) => self.from_current[to],
            Change::Between(from, to) => self.changes.get(&(from, to)).copied(),
        }
    }

    /// Keeps the answer `ok` to the change `key`.
    fn remember(&mut self, key: Change, ok: bool) {
        match key {
            Change::FromCurrent(to) => self.from_current[to] = Some(ok),
            Change::Between(from, to) => {
                self.changes.insert((from, to), ok);
            }
        }
    }
}

/// The SRS index of a node whose answers [`Memo`] keeps (an unturned random shape).
fn kept(nodes: &[Candidate], v: usize) -> Option<usize> {
    match nodes[v].source {
        Source::Srs(k) if v > 0 => Some(k as usize),
        _ => None,
    }
}

/// Lazy answers to "is shape `v` valid at `xi_i`" and "is it admissible along the
/// edge": each asked at most once, and only for shapes the search reaches.
struct Oracle<'c> {
    checker: &'c mut Checker,
    memo: &'c mut Memo,
    from: [f64; 3],
    to: [f64; 3],
    valid: Vec<Option<bool>>,
    admissible: Vec<Option<bool>>,
}

impl Oracle<'_> {
    fn valid(&mut self, v: usize, nodes: &[Candidate]) -> bool {
        if self.valid[v].is_none() {
            let k = kept(nodes, v);
            let known = k.and_then(|k| self.memo.valid[k]);
            let ok = match known {
                Some(ok) if !self.checker.expired() => ok,
                _ => self.checker.placement(self.from, &nodes[v].shape),
            };
            if let Some(k) = k {
                self.memo.valid[k] = Some(ok);
            }
            self.valid[v] = Some(ok);
        }
        self.valid[v] == Some(true)
    }

    /// The shape change from node `via` to node `v` at `xi_i` passes.
    fn change(&mut self, via: usize, v: usize, nodes: &[Candidate]) -> bool {
        let key = kept(nodes, v).and_then(|to| match via {
            0 => Some(Change::FromCurrent(to)),
            _ => kept(nodes, via).map(|from| Change::Between(from as u16, to as u16)),
        });
        let known = key.and_then(|k| self.memo.change(k));
        if let Some(ok) = known.filter(|_| !self.checker.expired()) {
            return ok;
        }
        let ok = self
            .checker
            .shape_change(self.from, &nodes[via].shape, &nodes[v].shape);
        if let Some(k) = key {
            self.memo.remember(k, ok);
        }
        ok
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
#[allow(clippy::too_many_arguments)]
pub(super) fn connect(
    checker: &mut Checker,
    memo: &mut Memo,
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
    memo.prepare(
        from,
        checker.ctx.clearance_margin(),
        &current.shape,
        srs_adjacency.len(),
    );
    let mut oracle = Oracle {
        checker,
        memo,
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
        if via != usize::MAX && !oracle.change(via, v, nodes) {
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

#[cfg(test)]
mod tests {
    use std::f64::consts::TAU;
    use std::sync::atomic::AtomicUsize;
    use std::sync::Arc;

    use aerial_chain_core::ChainParams;

    use super::*;
    use crate::collision::{CollisionContext, DEFAULT_CLEARANCE};
    use crate::map::DistanceField;
    use crate::problem::scenarios;
    use crate::tables::{ShapeTables, TableSettings};

    /// Edge after edge from one head position (the start of `window`, where the
    /// chain lies across the room), a call that keeps what the last one learnt
    /// answers as a fresh one does, with fewer placements and shape changes checked
    /// (here 438 against 795 over twelve edges).
    #[test]
    fn a_kept_memo_answers_as_a_fresh_one() {
        let sc = scenarios::build("window").unwrap();
        let params = ChainParams::new(5);
        let settings = TableSettings {
            srs: 120,
            ..TableSettings::default()
        };
        let tables = ShapeTables::build(params, &settings, &AtomicUsize::new(0)).unwrap();
        let field = Arc::new(DistanceField::new(sc.grid.clone()));
        let ctx = CollisionContext::new(field, params, DEFAULT_CLEARANCE).unwrap();
        let current = Candidate {
            shape: sc.start_shape(5).unwrap(),
            source: Source::Start,
        };
        let from: [f64; 3] = sc.start.into();
        let d_c = aerial_chain_core::srs::default_r_s(params.units, tables.srs.len());
        let (mut fresh_checks, mut kept_checks, mut found) = (0, 0, 0);
        let mut kept = Memo::default();
        for k in 0..12 {
            let yaw = TAU * k as f64 / 12.0;
            let to = [from[0] + yaw.cos(), from[1] + yaw.sin(), from[2]];
            let pool: Vec<Candidate> = tables
                .srs
                .iter()
                .enumerate()
                .flat_map(|(i, &shape)| {
                    let turned = shape.rotated(yaw as f32);
                    [
                        Candidate {
                            shape,
                            source: Source::Srs(i as u16),
                        },
                        Candidate {
                            shape: turned,
                            source: Source::SrsTurned(i as u16),
                        },
                    ]
                })
                .collect();
            let run = |memo: &mut Memo| {
                ctx.reset_stats();
                let mut checker = Checker::new(ctx.clone(), None);
                let path = connect(
                    &mut checker,
                    memo,
                    from,
                    to,
                    &current,
                    &pool,
                    &tables.adjacency,
                    d_c,
                );
                let s = ctx.stats();
                (
                    path.map(|p| p.iter().map(|c| c.shape).collect::<Vec<_>>()),
                    s.configs + s.shape_changes,
                )
            };
            let (want, n) = run(&mut Memo::default());
            let (got, m) = run(&mut kept);
            assert_eq!(got, want, "edge {k}");
            // The same search, with some answers known: never more checks.
            assert!(m <= n, "edge {k}: {m} checks with the memo, {n} without");
            found += usize::from(want.is_some());
            fresh_checks += n;
            kept_checks += m;
        }
        assert!(found > 0, "some edge connects, so the paths are compared");
        assert!(
            kept_checks < fresh_checks,
            "{kept_checks} of {fresh_checks}"
        );
    }
}
