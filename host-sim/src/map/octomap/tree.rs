//! [`OcTree`]'s storage: the compact node arrays, the counts and bounds computed when a
//! tree is made, the depth-first walk over the inner nodes, and the bit arithmetic on a
//! node's child codes that every other part of the module shares.

use std::fmt;

/// Depth of every OctoMap tree: leaves at depth 16 are voxels of edge `resolution`.
pub const TREE_DEPTH: u8 = 16;

/// Key of the tree's centre along each axis (OctoMap's `tree_max_val`).
pub(super) const TREE_MAX_VAL: i64 = 32768;

/// No child (unknown space). A node holds 2 bits per child, as stored in `.bt` files.
pub(super) const CHILD_NONE: u16 = 0;
/// A free leaf.
pub(super) const CHILD_FREE: u16 = 1;
/// An occupied leaf.
pub(super) const CHILD_OCCUPIED: u16 = 2;
/// An inner node.
pub(super) const CHILD_INNER: u16 = 3;

/// Longest stack the depth-first walks can need: at most 8 entries are pushed per level and
/// inner nodes exist only at depths 0..=15.
pub(super) const STACK_CAPACITY: usize = 8 * TREE_DEPTH as usize + 1;

/// An OctoMap occupancy tree in max-likelihood form: every known leaf is free or occupied.
///
/// Inner nodes are stored in one compact array: per node its 16 child bits (the `.bt`
/// encoding) and the index of its first inner child; the inner children of a node sit
/// next to each other in child order. Leaves are only the codes in their parent's bits.
#[derive(Clone)]
pub struct OcTree {
    pub(super) resolution: f64,
    /// Per inner node: child `i` in bits `2i, 2i+1` (0 none, 1 free, 2 occupied, 3 inner).
    pub(super) codes: Vec<u16>,
    /// Per inner node: index of its first inner child (unused when it has none).
    pub(super) first_child: Vec<u32>,
    pub(super) stats: Stats,
}

/// Values computed once when a tree is made.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(super) struct Stats {
    /// Occupied leaves.
    pub(super) occupied: usize,
    /// Free leaves.
    pub(super) free: usize,
    /// Nodes, inner and leaves, root included (zero for an empty tree).
    pub(super) nodes: u64,
    /// OctoMap's metric bounds of all leaves, `None` for an empty tree.
    pub(super) bounds: Option<([f64; 3], [f64; 3])>,
}

impl OcTree {
    /// The tree with the node arrays `codes` and `first_child` (laid out as the fields
    /// say), its counts and bounds computed in one walk. Every way of making a tree ends
    /// here, so the stats always match the nodes.
    pub(super) fn from_nodes(resolution: f64, codes: Vec<u16>, first_child: Vec<u32>) -> OcTree {
        let mut tree = OcTree {
            resolution,
            codes,
            first_child,
            stats: Stats::default(),
        };
        tree.stats = tree.compute_stats();
        tree
    }

    /// The tree without nodes: all space unknown.
    pub(super) fn empty(resolution: f64) -> OcTree {
        OcTree::from_nodes(resolution, Vec::new(), Vec::new())
    }

    /// Slot of inner child `child` of the node in `slot` (whose bits are `code`).
    pub(super) fn inner_child_slot(&self, slot: usize, code: u16, child: u32) -> Option<usize> {
        let first = *self.first_child.get(slot)? as usize;
        Some(first + inner_rank(code, child) as usize)
    }

    /// Codes of the inner nodes in depth-first order (the `.bt` order).
    pub(super) fn preorder(&self) -> Preorder<'_> {
        let mut stack = Vec::with_capacity(STACK_CAPACITY);
        if !self.codes.is_empty() {
            stack.push(0usize);
        }
        Preorder { tree: self, stack }
    }

    /// Counts leaves and nodes and computes OctoMap's metric bounds, in one walk.
    fn compute_stats(&self) -> Stats {
        let mut occupied = 0usize;
        let mut free = 0usize;
        let mut nodes = 0u64;
        // Per depth and axis, the smallest and largest leaf cell index (cells counted from
        // the tree's minimum corner at that depth).
        let mut lo = [[u32::MAX; 3]; TREE_DEPTH as usize + 1];
        let mut hi = [[0u32; 3]; TREE_DEPTH as usize + 1];
        let mut any = [false; TREE_DEPTH as usize + 1];
        let mut stack: Vec<(usize, u8, [u32; 3])> = Vec::with_capacity(STACK_CAPACITY);
        if !self.codes.is_empty() {
            nodes = 1;
            stack.push((0, 0, [0, 0, 0]));
        }
        while let Some((slot, depth, cell)) = stack.pop() {
            let Some(&code) = self.codes.get(slot) else {
                continue;
            };
            let child_depth = depth + 1;
            for child in 0..8u32 {
                let c = child_code(code, child);
                if c == CHILD_NONE {
                    continue;
                }
                nodes += 1;
                let ccell = child_cell(cell, child);
                match c {
                    CHILD_INNER => {
                        if let Some(s) = self.inner_child_slot(slot, code, child) {
                            stack.push((s, child_depth, ccell));
                        }
                    }
                    _ => {
                        if c == CHILD_OCCUPIED {
                            occupied += 1;
                        } else {
                            free += 1;
                        }
                        let d = usize::from(child_depth);
                        if let (Some(l), Some(h), Some(a)) =
                            (lo.get_mut(d), hi.get_mut(d), any.get_mut(d))
                        {
                            *a = true;
                            for ((lv, hv), &cv) in l.iter_mut().zip(h.iter_mut()).zip(&ccell) {
                                *lv = (*lv).min(cv);
                                *hv = (*hv).max(cv);
                            }
                        }
                    }
                }
            }
        }
        // Leaf centre, `- size/2` and `+ size` are monotonic in the cell index, so the
        // extreme cells at each depth give exactly the extreme values OctoMap finds by
        // visiting every leaf.
        let mut bounds: Option<([f64; 3], [f64; 3])> = None;
        for d in 1..=TREE_DEPTH {
            let di = usize::from(d);
            if !any.get(di).copied().unwrap_or(false) {
                continue;
            }
            let (Some(l), Some(h)) = (lo.get(di), hi.get(di)) else {
                continue;
            };
            let size = node_size(self.resolution, d);
            let half = size / 2.0;
            let (mut mn, mut mx) = bounds.unwrap_or(([f64::MAX; 3], [-f64::MAX; 3]));
            for (((mn_a, mx_a), &l_a), &h_a) in mn.iter_mut().zip(mx.iter_mut()).zip(l).zip(h) {
                // OctoMap's calcMinMax: x = centre - size/2 for the minimum, x + size for the
                // maximum.
                let low = cell_center(l_a, d, size) - half;
                let high = (cell_center(h_a, d, size) - half) + size;
                if low < *mn_a {
                    *mn_a = low;
                }
                if high > *mx_a {
                    *mx_a = high;
                }
            }
            bounds = Some((mn, mx));
        }
        Stats {
            occupied,
            free,
            nodes,
            bounds,
        }
    }
}

impl fmt::Debug for OcTree {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("OcTree")
            .field("resolution", &self.resolution)
            .field("nodes", &self.stats.nodes)
            .field("inner_nodes", &self.codes.len())
            .field("occupied_leaves", &self.stats.occupied)
            .field("free_leaves", &self.stats.free)
            .field("metric_bounds", &self.stats.bounds)
            .finish()
    }
}

/// Two trees are equal when they have the same resolution and the same nodes (however
/// they are laid out in memory).
impl PartialEq for OcTree {
    fn eq(&self, other: &OcTree) -> bool {
        self.resolution == other.resolution
            && self.codes.len() == other.codes.len()
            && self.stats == other.stats
            && self.preorder().eq(other.preorder())
    }
}

/// Inner-node codes in depth-first order.
pub(super) struct Preorder<'a> {
    tree: &'a OcTree,
    stack: Vec<usize>,
}

impl Iterator for Preorder<'_> {
    type Item = u16;

    fn next(&mut self) -> Option<u16> {
        let slot = self.stack.pop()?;
        let code = *self.tree.codes.get(slot)?;
        let first = *self.tree.first_child.get(slot)? as usize;
        let n = inner_mask(code).count_ones() as usize;
        for rank in (0..n).rev() {
            self.stack.push(first + rank);
        }
        Some(code)
    }
}

/// The 2-bit code of `child` in a node's bits.
pub(super) fn child_code(code: u16, child: u32) -> u16 {
    (code >> (2 * child)) & 3
}

/// Bit `2i` set for every inner child `i`.
pub(super) fn inner_mask(code: u16) -> u16 {
    code & (code >> 1) & 0x5555
}

/// How many inner children come before `child`.
fn inner_rank(code: u16, child: u32) -> u32 {
    let below = (1u32 << (2 * child)) - 1;
    (u32::from(inner_mask(code)) & below).count_ones()
}

/// Cell of child `child` of the node in cell `cell` one level up.
pub(super) fn child_cell(cell: [u32; 3], child: u32) -> [u32; 3] {
    [
        (cell[0] << 1) | (child & 1),
        (cell[1] << 1) | ((child >> 1) & 1),
        (cell[2] << 1) | ((child >> 2) & 1),
    ]
}

/// OctoMap's `getNodeSize(depth)`: `resolution * double(1 << (16 - depth))`.
pub(super) fn node_size(resolution: f64, depth: u8) -> f64 {
    resolution * f64::from(1u32 << (TREE_DEPTH - depth.min(TREE_DEPTH)))
}

/// OctoMap's `keyToCoord(key, depth)` for depth 1..=16, from the cell index counted from the
/// tree's minimum corner: `(floor((key - 32768) / 2^(16 - depth)) + 0.5) * size`.
pub(super) fn cell_center(cell: u32, depth: u8, size: f64) -> f64 {
    let offset = 1i64 << (depth.clamp(1, TREE_DEPTH) - 1);
    ((i64::from(cell) - offset) as f64 + 0.5) * size
}
