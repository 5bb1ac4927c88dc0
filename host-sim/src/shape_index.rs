//! A k-d tree over chain shapes in the `C_T` metric, for building `G_SRS` without
//! comparing every pair of shapes.
//!
//! Each shape is a point of its `2N - 1` wrapped angles; `C_T^2` weighs the head yaw by
//! `N` and link `k`'s pitch and yaw by `N - 1 - k`. A node's box gives a lower bound of
//! `C_T^2` to every shape inside it (each angle's circular distance to the box, squared
//! and weighted), so a search skips whole boxes that cannot hold a neighbour. The
//! shapes it does reach are measured with the core's own
//! [`transition_cost_sq_within`], and ranked by `(C_T^2, index)`: the answer is the
//! core's [`nearest_later`](aerial_chain_core::srs::nearest_later) over every later
//! shape, bit for bit, whatever order the tree visits them in.

use std::f32::consts::{PI, TAU};

use aerial_chain_core::angle::wrap;
use aerial_chain_core::cost::transition_cost_sq_within;
use aerial_chain_core::srs::Candidates;
use aerial_chain_core::Shape;

/// Most shapes in one leaf. In the 2N - 1 dimensions of a shape boxes prune little;
/// large leaves, whose shapes are screened by a cheap weighted distance, are faster
/// than deep trees (measured for N = 3 and 6).
const LEAF: usize = 128;

/// One node: the box of its shapes' angles and where they are.
#[derive(Clone, Debug)]
struct Node {
    /// Smallest wrapped angle of the node's shapes, per coordinate.
    lo: Vec<f32>,
    /// Largest wrapped angle, per coordinate.
    hi: Vec<f32>,
    /// Largest shape index inside: a search for shapes after `i` skips nodes whose
    /// largest index is `i` or less.
    max_index: usize,
    /// A leaf's shapes (`order[start..end]`), or an inner node's children.
    kind: NodeKind,
    /// The coordinate an inner node splits.
    axis: usize,
    /// The angle it splits at: the left child's shapes are at or below it, the right
    /// child's at or above.
    split: f32,
}

#[derive(Clone, Debug)]
enum NodeKind {
    Leaf { start: usize, end: usize },
    Inner { left: usize, right: usize },
}

/// A k-d tree of shapes (all of one chain), searched for roadmap candidates.
#[derive(Clone, Debug)]
pub struct ShapeIndex {
    /// Angles per coordinate.
    dim: usize,
    /// `C_T^2` weight of each coordinate.
    weight: Vec<f32>,
    /// Wrapped angles of shape `i` at `coords[i * dim..(i + 1) * dim]`.
    coords: Vec<f32>,
    /// Shape indices, grouped by leaf, ascending within a leaf (so a search skips a
    /// leaf's shapes at or before its own with one binary search).
    order: Vec<usize>,
    /// The same angles leaf by leaf, coordinate-major: the leaf of `order[start..end]`
    /// holds coordinate `c` of its shapes at `start * dim + c * (end - start)..`, so
    /// a leaf is screened one coordinate at a time over contiguous memory.
    leaf_coords: Vec<f32>,
    nodes: Vec<Node>,
}

/// The circular distance from angle `q` to the arc `[lo, hi]` (all wrapped, `lo <= hi`).
fn arc_gap(q: f32, lo: f32, hi: f32) -> f32 {
    if (lo..=hi).contains(&q) {
        return 0.0;
    }
    let circ = |a: f32, b: f32| {
        let d = (a - b).abs();
        d.min(TAU - d)
    };
    circ(q, lo).min(circ(q, hi))
}

/// A bound a little above `bound`, so that no rounding of the box bounds (against the
/// core's exact `C_T^2`) can prune a shape that is within `bound`.
fn loosened(bound: f32) -> f32 {
    bound * (1.0 + 1e-4) + 1e-3
}

impl ShapeIndex {
    /// The index of `shapes` (all with the same number of units; none if empty).
    pub fn new(shapes: &[Shape]) -> Self {
        let dim = shapes.first().map_or(0, |s| s.as_slice().len());
        let units = shapes.first().map_or(0, |s| s.units()) as f32;
        // The weights of `aerial_chain_core::cost`: head yaw N, link k's angles N - 1 - k.
        let weight = (0..dim)
            .map(|c| {
                if c == 0 {
                    units
                } else {
                    units - ((c - 1) / 2) as f32 - 1.0
                }
            })
            .collect();
        let coords = shapes
            .iter()
            .flat_map(|s| s.as_slice().iter().map(|&a| wrap(a)))
            .collect();
        let mut index = Self {
            dim,
            weight,
            coords,
            order: (0..shapes.len()).collect(),
            leaf_coords: vec![0.0; shapes.len() * dim],
            nodes: Vec::new(),
        };
        if !shapes.is_empty() {
            index.build(0, shapes.len());
        }
        index
    }

    fn coord(&self, i: usize, c: usize) -> f32 {
        self.coords[i * self.dim + c]
    }

    /// Builds the node of `order[start..end]`; returns its position in `nodes`.
    fn build(&mut self, start: usize, end: usize) -> usize {
        let (mut lo, mut hi) = (vec![PI; self.dim], vec![-PI; self.dim]);
        for &i in &self.order[start..end] {
            for c in 0..self.dim {
                lo[c] = lo[c].min(self.coord(i, c));
                hi[c] = hi[c].max(self.coord(i, c));
            }
        }
        let max_index = self.order[start..end].iter().copied().max().unwrap_or(0);
        let at = self.nodes.len();
        self.nodes.push(Node {
            lo,
            hi,
            max_index,
            kind: NodeKind::Leaf { start, end },
            axis: 0,
            split: 0.0,
        });
        if end - start <= LEAF {
            self.lay_out_leaf(start, end);
            return at;
        }
        // Split the coordinate that spreads the most in the metric, at its median.
        let node = &self.nodes[at];
        let axis = (0..self.dim)
            .max_by(|&a, &b| {
                let spread = |c: usize| self.weight[c] * (node.hi[c] - node.lo[c]).powi(2);
                spread(a).total_cmp(&spread(b))
            })
            .unwrap_or(0);
        let mid = start + (end - start) / 2;
        let (dim, coords) = (self.dim, &self.coords);
        self.order[start..end].select_nth_unstable_by(mid - start, |&a, &b| {
            coords[a * dim + axis].total_cmp(&coords[b * dim + axis])
        });
        let split = self.coord(self.order[mid], axis);
        let left = self.build(start, mid);
        let right = self.build(mid, end);
        let node = &mut self.nodes[at];
        node.kind = NodeKind::Inner { left, right };
        (node.axis, node.split) = (axis, split);
        at
    }

    /// Sorts the leaf `order[start..end]` by index and copies its angles into
    /// `leaf_coords`, coordinate-major.
    fn lay_out_leaf(&mut self, start: usize, end: usize) {
        self.order[start..end].sort_unstable();
        let (dim, len) = (self.dim, end - start);
        for (k, &i) in self.order[start..end].iter().enumerate() {
            for c in 0..dim {
                self.leaf_coords[start * dim + c * len + k] = self.coords[i * dim + c];
            }
        }
    }

    /// Whether a shape in `node` may lie within `limit` in `C_T^2` of the shape with
    /// angles `q`: the box's lower bound, summed heaviest coordinates first until it
    /// exceeds `limit`.
    fn box_within(&self, node: &Node, q: &[f32], limit: f32) -> bool {
        let mut sum = 0.0;
        let boxes = node.lo.iter().zip(&node.hi).zip(&self.weight);
        for (&qc, ((&lo, &hi), &w)) in q.iter().zip(boxes) {
            let g = arc_gap(qc, lo, hi);
            sum += w * g * g;
            if sum > limit {
                return false;
            }
        }
        true
    }

    /// Offers to `near` the shapes of the leaf `order[start..end]` after the query's
    /// that may lie within its bound: each shape's weighted circular distances to
    /// the query, summed over all coordinates at once (a loop the compiler
    /// vectorises), without the core's exact wrapping (the core then measures the
    /// shapes this lets through).
    fn screen_leaf<const DEG: usize>(
        &self,
        (start, end): (usize, usize),
        search: &Search<'_>,
        near: &mut Candidates<DEG>,
    ) {
        let ids = &self.order[start..end];
        let first = ids.partition_point(|&j| j <= search.i);
        let len = end - start;
        let block = &self.leaf_coords[start * self.dim..end * self.dim];
        let mut sums = [0.0f32; LEAF];
        let sums = &mut sums[..len - first];
        for (c, (&w, &q)) in self.weight.iter().zip(search.q).enumerate() {
            let xs = &block[c * len + first..(c + 1) * len];
            for (sum, &x) in sums.iter_mut().zip(xs) {
                let d = (q - x).abs();
                let g = if d > PI { TAU - d } else { d };
                *sum += w * g * g;
            }
        }
        for (&sum, &j) in sums.iter().zip(&ids[first..]) {
            if sum <= loosened(search.bound(near)) {
                search.offer(j, near);
            }
        }
    }

    /// The roadmap candidates of `shapes[i]` (the shapes this index was built from):
    /// the `DEG` nearest shapes after `i` within `r_s` in `C_T`, nearest first, as
    /// `(C_T^2, index)`; of equally near shapes the lower index. The same list as the
    /// core's `nearest_later(shapes, i, r_s, i + 1..shapes.len())`.
    pub fn nearest_later<const DEG: usize>(
        &self,
        shapes: &[Shape],
        i: usize,
        r_s: f32,
    ) -> Candidates<DEG> {
        let mut near = Candidates::new();
        if self.nodes.is_empty() || DEG == 0 {
            return near;
        }
        let q = &self.coords[i * self.dim..(i + 1) * self.dim];
        let search = Search {
            shapes,
            i,
            r2: r_s * r_s,
            q,
        };
        self.visit(0, &search, &mut near);
        near
    }

    fn visit<const DEG: usize>(&self, at: usize, search: &Search<'_>, near: &mut Candidates<DEG>) {
        let node = &self.nodes[at];
        if node.max_index <= search.i {
            return;
        }
        match node.kind {
            NodeKind::Leaf { start, end } => self.screen_leaf((start, end), search, near),
            NodeKind::Inner { left, right } => {
                // The child on the query's side of the split first: it likely holds
                // the nearest shapes, which shrink the bound for the other.
                let (axis, split) = (node.axis, node.split);
                let (first, second) = if search.q[axis] <= split {
                    (left, right)
                } else {
                    (right, left)
                };
                for child in [first, second] {
                    let limit = loosened(search.bound(near));
                    if self.box_within(&self.nodes[child], search.q, limit) {
                        self.visit(child, search, near);
                    }
                }
            }
        }
    }
}

/// One search's fixed inputs.
struct Search<'a> {
    shapes: &'a [Shape],
    i: usize,
    r2: f32,
    q: &'a [f32],
}

impl Search<'_> {
    /// The largest `C_T^2` a shape may have and still enter `near`.
    fn bound<const DEG: usize>(&self, near: &Candidates<DEG>) -> f32 {
        match near.last() {
            Some(&(last, _)) if near.is_full() => last.min(self.r2),
            _ => self.r2,
        }
    }

    /// Keeps `j` in `near` if it is among the `DEG` nearest by `(C_T^2, index)`.
    fn offer<const DEG: usize>(&self, j: usize, near: &mut Candidates<DEG>) {
        let Some(d) =
            transition_cost_sq_within(&self.shapes[self.i], &self.shapes[j], self.bound(near))
        else {
            return;
        };
        let key = (d, j as u16);
        let before = |e: &(f32, u16)| e.0 < key.0 || (e.0 == key.0 && e.1 < key.1);
        if near.is_full() {
            if near.last().is_some_and(|e| !before(e)) {
                near.pop();
            } else {
                return;
            }
        }
        let at = near.iter().position(|e| !before(e)).unwrap_or(near.len());
        let _ = near.insert(at, key);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use aerial_chain_core::srs::{nearest_later, Sampler};
    use aerial_chain_core::ChainParams;

    fn shapes(units: u8, count: usize, seed: u64) -> Vec<Shape> {
        let mut s = Sampler::new(ChainParams::new(units), seed, 100_000);
        (0..count).map(|_| s.next_shape().expect("shape")).collect()
    }

    #[test]
    fn the_tree_finds_the_cores_candidates() {
        for (units, count, r_s) in [(2, 300, 0.6), (3, 600, 0.9), (5, 400, 3.0), (8, 200, 9.0)] {
            let s = shapes(units, count, 7);
            let index = ShapeIndex::new(&s);
            for i in 0..s.len() {
                assert_eq!(
                    index.nearest_later::<12>(&s, i, r_s),
                    nearest_later::<12>(&s, i, r_s, i + 1..s.len()),
                    "N = {units}, shape {i}"
                );
            }
        }
    }

    #[test]
    fn ties_go_to_the_lower_index() {
        // Copies of one shape are all at C_T = 0 from it: the first ones are kept.
        let one = shapes(4, 1, 3)[0];
        let s = vec![one; 40];
        let index = ShapeIndex::new(&s);
        let near = index.nearest_later::<5>(&s, 0, 1.0);
        assert_eq!(
            near.iter().map(|e| e.1).collect::<Vec<_>>(),
            [1, 2, 3, 4, 5]
        );
        assert!(ShapeIndex::new(&[])
            .nearest_later::<5>(&[], 0, 1.0)
            .is_empty());
    }

    #[test]
    fn arc_gaps_go_round_the_circle() {
        assert_eq!(arc_gap(0.5, 0.0, 1.0), 0.0);
        assert!((arc_gap(3.0, -3.0, -2.0) - (TAU - 6.0)).abs() < 1e-6);
        assert!((arc_gap(1.5, 0.0, 1.0) - 0.5).abs() < 1e-6);
    }
}
