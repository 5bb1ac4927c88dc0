//! What a loaded [`OcTree`] answers: the state of the space at a point, its leaves, its
//! bounds and its counts, each as OctoMap answers it for the same file.

use nalgebra::Point3;

use super::tree::{
    cell_center, child_cell, child_code, node_size, OcTree, CHILD_FREE, CHILD_INNER, CHILD_NONE,
    CHILD_OCCUPIED, TREE_DEPTH, TREE_MAX_VAL,
};

/// A known leaf of the tree: a cube of free or occupied space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Leaf {
    /// Centre of the cube, metres, computed exactly as OctoMap's `keyToCoord(key, depth)`.
    pub center: Point3<f64>,
    /// Edge of the cube, metres: `resolution * 2^(16 - depth)` (OctoMap's `getNodeSize`).
    pub size: f64,
    /// True when occupied, false when free.
    pub occupied: bool,
    /// Depth in the tree, 1..=16 (16 for a single voxel).
    pub depth: u8,
}

impl OcTree {
    /// Edge of the smallest voxel, metres.
    pub fn resolution(&self) -> f64 {
        self.resolution
    }

    /// Every known leaf (occupied and free), depth-first in child order: the order of
    /// OctoMap's `leaf_iterator`.
    pub fn leaves(&self) -> impl Iterator<Item = Leaf> + '_ {
        Leaves::new(self)
    }

    /// The box around all known leaves, `(min, max)`, computed exactly as OctoMap's
    /// `getMetricMin`/`getMetricMax` (for each leaf, `centre - size/2` and that plus `size`).
    /// `None` for an empty tree (where OctoMap reports zeros).
    pub fn metric_bounds(&self) -> Option<(Point3<f64>, Point3<f64>)> {
        self.stats.bounds.map(|(lo, hi)| (lo.into(), hi.into()))
    }

    /// `(occupied leaves, free leaves)`.
    pub fn counts(&self) -> (usize, usize) {
        (self.stats.occupied, self.stats.free)
    }

    /// Number of nodes, inner and leaves, root included: OctoMap's `size()`, the header's
    /// `size`. Zero for an empty tree.
    pub fn node_count(&self) -> u64 {
        self.stats.nodes
    }

    /// The state of the space at `p`: `Some(true)` occupied, `Some(false)` free, `None`
    /// unknown or outside the tree. Same as OctoMap's `search(x, y, z)` (in doubles)
    /// followed by `isNodeOccupied`: the key along each axis is
    /// `floor((1 / resolution) * p) + 32768`, and points whose key falls outside 0..65536
    /// (or that are not finite) are outside.
    pub fn query(&self, p: impl Into<Point3<f64>>) -> Option<bool> {
        let p = p.into();
        let factor = 1.0 / self.resolution;
        let mut key = [0u32; 3];
        for (k, &c) in key.iter_mut().zip(p.iter()) {
            let scaled = (factor * c).floor();
            if !(scaled >= -(TREE_MAX_VAL as f64) && scaled < TREE_MAX_VAL as f64) {
                return None;
            }
            *k = (scaled as i64 + TREE_MAX_VAL) as u32;
        }
        let mut slot = 0usize;
        for depth in 0..TREE_DEPTH {
            let code = *self.codes.get(slot)?;
            let bit = u32::from(TREE_DEPTH - 1 - depth);
            let child =
                ((key[0] >> bit) & 1) | (((key[1] >> bit) & 1) << 1) | (((key[2] >> bit) & 1) << 2);
            match child_code(code, child) {
                CHILD_FREE => return Some(false),
                CHILD_OCCUPIED => return Some(true),
                CHILD_INNER => slot = self.inner_child_slot(slot, code, child)?,
                _ => return None,
            }
        }
        None
    }
}

/// One level of the leaf walk.
#[derive(Clone, Copy, Default)]
struct Frame {
    slot: usize,
    depth: u8,
    next_child: u8,
    cell: [u32; 3],
}

/// Depth-first walk over the known leaves, without allocating.
struct Leaves<'a> {
    tree: &'a OcTree,
    stack: [Frame; TREE_DEPTH as usize + 1],
    len: usize,
}

impl<'a> Leaves<'a> {
    fn new(tree: &'a OcTree) -> Leaves<'a> {
        Leaves {
            tree,
            stack: [Frame::default(); TREE_DEPTH as usize + 1],
            len: usize::from(!tree.codes.is_empty()),
        }
    }
}

impl Iterator for Leaves<'_> {
    type Item = Leaf;

    fn next(&mut self) -> Option<Leaf> {
        loop {
            let top_index = self.len.checked_sub(1)?;
            let top = self.stack.get_mut(top_index)?;
            if top.next_child >= 8 {
                self.len -= 1;
                continue;
            }
            let child = u32::from(top.next_child);
            top.next_child += 1;
            let frame = *top;
            let code = *self.tree.codes.get(frame.slot)?;
            let depth = frame.depth + 1;
            let cell = child_cell(frame.cell, child);
            match child_code(code, child) {
                CHILD_NONE => {}
                CHILD_INNER => {
                    let slot = self.tree.inner_child_slot(frame.slot, code, child)?;
                    let pushed = self.stack.get_mut(self.len)?;
                    *pushed = Frame {
                        slot,
                        depth,
                        next_child: 0,
                        cell,
                    };
                    self.len += 1;
                }
                c => {
                    let size = node_size(self.tree.resolution, depth);
                    return Some(Leaf {
                        center: cell.map(|i| cell_center(i, depth, size)).into(),
                        size,
                        occupied: c == CHILD_OCCUPIED,
                        depth,
                    });
                }
            }
        }
    }
}
