//! Building an [`OcTree`] from voxels, pruned the way OctoMap's `prune` prunes: a node
//! whose 8 children are leaves of the same state becomes one leaf.

use super::error::MapFileError;
use super::header::check_resolution;
use super::tree::{OcTree, CHILD_FREE, CHILD_INNER, CHILD_OCCUPIED, TREE_DEPTH, TREE_MAX_VAL};

/// The name used in errors from [`OcTree::from_voxels`], which has no file.
const VOXELS_NAME: &str = "<from_voxels>";

/// A node while building a tree bottom-up.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Entry {
    Leaf(bool),
    Inner(u32),
}

/// The inner nodes made at one depth: per node its child codes and the index (within the
/// next deeper level) of its first inner child.
type InnerLevel = Vec<(u16, u32)>;

impl OcTree {
    /// Builds a tree from voxels `(index, occupied)`, where a voxel's centre is
    /// `(index + 0.5) * resolution` along each axis (its OctoMap key minus 32768), then
    /// prunes every node whose 8 children are leaves of the same state into one leaf, as
    /// OctoMap's `prune` does. A voxel listed more than once takes its last state.
    /// Voxels not listed are unknown. No voxels give an empty tree.
    pub fn from_voxels(
        resolution: f64,
        voxels: impl IntoIterator<Item = ([i32; 3], bool)>,
    ) -> Result<OcTree, MapFileError> {
        check_resolution(resolution, VOXELS_NAME)?;
        let leaves = sorted_leaves(voxels)?;
        if leaves.is_empty() {
            return Ok(OcTree::empty(resolution));
        }
        let (codes, first_child) = lay_out(inner_nodes_by_depth(leaves)?);
        Ok(OcTree::from_nodes(resolution, codes, first_child))
    }
}

/// The voxels as depth-16 leaves keyed by their path from the root ([`morton`]), sorted,
/// one per voxel (the last listed state).
fn sorted_leaves(
    voxels: impl IntoIterator<Item = ([i32; 3], bool)>,
) -> Result<Vec<(u64, Entry)>, MapFileError> {
    let mut cells: Vec<(u64, bool)> = Vec::new();
    for (v, occupied) in voxels {
        let mut key = [0u32; 3];
        for (k, &i) in key.iter_mut().zip(v.iter()) {
            let shifted = i64::from(i) + TREE_MAX_VAL;
            if !(0..2 * TREE_MAX_VAL).contains(&shifted) {
                return Err(MapFileError::VoxelOutOfRange {
                    file: VOXELS_NAME.to_string(),
                    voxel: v,
                });
            }
            *k = shifted as u32;
        }
        cells.push((morton(key), occupied));
    }
    // Stable: of equal keys the last listed ends last; keep that one.
    cells.sort_by_key(|c| c.0);
    let mut level: Vec<(u64, Entry)> = Vec::with_capacity(cells.len());
    for (i, &(m, occ)) in cells.iter().enumerate() {
        if cells.get(i + 1).is_some_and(|next| next.0 == m) {
            continue;
        }
        level.push((m, Entry::Leaf(occ)));
    }
    Ok(level)
}

/// Builds the tree bottom-up from its depth-16 `leaves`, one level at a time, and returns
/// its inner nodes per depth, root (depth 0) first.
fn inner_nodes_by_depth(leaves: Vec<(u64, Entry)>) -> Result<Vec<InnerLevel>, MapFileError> {
    // `level` holds the known nodes at the current depth, keyed by their path from the
    // root (3 bits per level), sorted.
    let mut level = leaves;
    let mut inner_levels: Vec<InnerLevel> = Vec::with_capacity(usize::from(TREE_DEPTH));
    let mut below: InnerLevel = Vec::new();
    for _depth in (1..=TREE_DEPTH).rev() {
        let (parents, inner_here) = parent_level(&level);
        inner_levels.push(std::mem::replace(&mut below, inner_here));
        level = parents;
    }
    // `level` now holds the root (depth 0) as the single entry.
    match level.first() {
        Some((_, Entry::Inner(_))) => {}
        _ => {
            return Err(MapFileError::WholeTree {
                file: VOXELS_NAME.to_string(),
            })
        }
    }
    // `below` holds depth 0 (the root); inner_levels holds depths 16, 15, ..., 1 with an
    // empty first entry (depth 16 has no inner nodes).
    let mut by_depth: Vec<InnerLevel> = Vec::with_capacity(usize::from(TREE_DEPTH) + 1);
    by_depth.push(below);
    by_depth.extend(inner_levels.into_iter().rev());
    Ok(by_depth)
}

/// The nodes one level up from `level` (sorted by path, as `level` is), and the inner
/// nodes made on the way: 8 equal leaves become one leaf, any other group of siblings an
/// inner node.
fn parent_level(level: &[(u64, Entry)]) -> (Vec<(u64, Entry)>, InnerLevel) {
    let mut parents: Vec<(u64, Entry)> = Vec::with_capacity(level.len() / 2 + 1);
    let mut inner_here: InnerLevel = Vec::new();
    let mut i = 0;
    while i < level.len() {
        let parent = level.get(i).map_or(0, |e| e.0 >> 3);
        let mut j = i;
        while level.get(j).is_some_and(|e| e.0 >> 3 == parent) {
            j += 1;
        }
        let group = level.get(i..j).unwrap_or(&[]);
        let collapsible = group.len() == 8
            && group.iter().all(|e| matches!(e.1, Entry::Leaf(_)))
            && group.windows(2).all(|w| matches!(w, [a, b] if a.1 == b.1));
        if let (true, Some(&(_, entry))) = (collapsible, group.first()) {
            parents.push((parent, entry));
        } else {
            let mut code = 0u16;
            let mut first = None;
            for &(m, entry) in group {
                let child = (m & 7) as u32;
                let c = match entry {
                    Entry::Leaf(true) => CHILD_OCCUPIED,
                    Entry::Leaf(false) => CHILD_FREE,
                    Entry::Inner(id) => {
                        first.get_or_insert(id);
                        CHILD_INNER
                    }
                };
                code |= c << (2 * child);
            }
            let id = u32::try_from(inner_here.len()).unwrap_or(u32::MAX);
            inner_here.push((code, first.unwrap_or(0)));
            parents.push((parent, Entry::Inner(id)));
        }
        i = j;
    }
    (parents, inner_here)
}

/// The node arrays of [`OcTree`] from the inner nodes per depth: laid out breadth-first,
/// so that each node's inner children sit next to each other in the next level.
fn lay_out(by_depth: Vec<InnerLevel>) -> (Vec<u16>, Vec<u32>) {
    let total: usize = by_depth.iter().map(Vec::len).sum();
    let mut codes = Vec::with_capacity(total);
    let mut first_child = Vec::with_capacity(total);
    let mut offset_next = 0usize;
    for nodes in &by_depth {
        offset_next += nodes.len();
        for &(code, first) in nodes {
            codes.push(code);
            first_child.push(u32::try_from(offset_next + first as usize).unwrap_or(u32::MAX));
        }
    }
    (codes, first_child)
}

/// Interleaves a key's bits: bits `3b, 3b+1, 3b+2` are bit `b` of x, y, z, so that the
/// top 3 bits are the child index at depth 1 and the bottom 3 the child index at depth 16.
fn morton(key: [u32; 3]) -> u64 {
    fn spread(v: u32) -> u64 {
        let mut x = u64::from(v & 0xffff);
        x = (x | (x << 16)) & 0x0000_ff00_00ff;
        x = (x | (x << 8)) & 0x00f0_0f00_f00f;
        x = (x | (x << 4)) & 0x0c30_c30c_30c3;
        x = (x | (x << 2)) & 0x2492_4924_9249;
        x
    }
    spread(key[0]) | (spread(key[1]) << 1) | (spread(key[2]) << 2)
}
