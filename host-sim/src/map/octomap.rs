//! OctoMap occupancy trees: reading and writing OctoMap's binary tree files (`.bt`).
//!
//! The project's interchange format for maps is the file written by OctoMap's
//! `OcTree::writeBinary` (see `docs/model.md`, "Files"). This module reads and writes
//! it without linking OctoMap, and reports what OctoMap reports for the same file: leaf
//! counts, `getMetricMin`/`getMetricMax`, and `search` results. The tests in
//! `host-sim/tests/octomap_reference.rs` check that against values printed by the real
//! library (`tests/fixtures/octomap/`).
//!
//! # The `.bt` format
//!
//! A text header, then the tree:
//!
//! ```text
//! # Octomap OcTree binary file        <- the first line must start with this
//! # (any number of comment lines)
//! id OcTree
//! size 2831                            <- number of tree nodes, inner and leaves, root included
//! res 0.05                             <- edge of the smallest voxel, metres
//! data
//! <binary tree>
//! ```
//!
//! The header is read the way OctoMap reads it: whitespace-separated keywords, `#` starts a
//! comment that runs to the end of the line, unknown keywords are skipped with their line,
//! and `data` ends the header (the binary part starts after the end of that line).
//!
//! The binary part lists the inner nodes depth-first, root first. Each inner node is two
//! bytes: children 0-3 in the first, 4-7 in the second, child `i % 4` in bits `2i, 2i+1`
//! (least significant bit first). As a number `(byte >> 2i) & 3`, a child is `0` absent
//! (unknown space), `1` a free leaf, `2` an occupied leaf, `3` an inner node. After a node's
//! two bytes come the subtrees of its inner children, in child order. Child `i` of a node
//! is the half along x if `i & 1`, along y if `i & 2`, along z if `i & 4` (OctoMap's
//! `computeChildIdx`). The tree has 16 levels; a voxel's key along an axis is
//! `floor(coordinate / resolution) + 32768` (0..65536), so a leaf at depth `d` is a cube of
//! edge `resolution * 2^(16 - d)`. OctoMap prunes a node whose 8 children are identical
//! leaves into one leaf, so real maps mix leaf sizes.
//!
//! # What is accepted
//!
//! * `.bt` files with `id OcTree` (and the deprecated `id 1`, which OctoMap also treats as
//!   `OcTree`). Other tree types (`ColorOcTree`, `OcTreeStamped`, ...) are refused.
//! * Full `.ot` files (first line `# Octomap OcTree file`, `id OcTree`): each node is its
//!   log-odds occupancy (`f32`, little-endian as OctoMap writes it on every common machine)
//!   and a byte of child-exists bits. They are read into the same max-likelihood tree
//!   OctoMap would query: a leaf is occupied when its log-odds is `>= 0` (OctoMap's default
//!   occupancy threshold, probability 0.5). Inner-node values are not kept; writing such a
//!   tree gives a `.bt` file.
//! * Resolutions from [`MIN_RESOLUTION`] to [`MAX_RESOLUTION`] metres.
//!
//! Refused with a [`MapFileError`] that names the file and the problem: empty files,
//! files that are not OctoMap files, the pre-2013 headerless binary format, headers
//! without `id`, `size`, `res` or `data`, unusable resolutions, unknown ids, a `size` that
//! disagrees with the tree, truncated data, bytes after the end of the tree, inner nodes
//! without children, and nodes below depth 16. Where OctoMap itself is lenient with such a
//! file (it ignores trailing bytes, and reads a childless inner node as a free leaf), we
//! are strict: a map that was damaged should not be flown in.
//!
//! # Memory and speed
//!
//! Decoding is iterative (an explicit stack at most 16 levels deep), linear in the file
//! size and allocates only the node arrays, whose size is bounded by the number of bytes
//! in the file, never by the header's `size`. A node costs 6 bytes (its 16 child bits and
//! the index of its first inner child); leaves live in their parent's child bits.

use std::fmt;
use std::path::Path;

/// Depth of every OctoMap tree: leaves at depth 16 are voxels of edge `resolution`.
pub const TREE_DEPTH: u8 = 16;

/// Smallest resolution (metres) accepted in a file or by [`OcTree::from_voxels`].
pub const MIN_RESOLUTION: f64 = 1e-3;

/// Largest resolution (metres) accepted in a file or by [`OcTree::from_voxels`].
pub const MAX_RESOLUTION: f64 = 100.0;

/// Key of the tree's centre along each axis (OctoMap's `tree_max_val`).
const TREE_MAX_VAL: i64 = 32768;

const BT_FIRST_LINE: &[u8] = b"# Octomap OcTree binary file";
const OT_FIRST_LINE: &[u8] = b"# Octomap OcTree file";

/// Child codes, as stored in the file and in memory (2 bits per child).
const CHILD_NONE: u16 = 0;
const CHILD_FREE: u16 = 1;
const CHILD_OCCUPIED: u16 = 2;
const CHILD_INNER: u16 = 3;

/// Log-odds of an occupied leaf in the `.ot` files we write: OctoMap's default upper
/// clamping bound (probability 0.971), what a voxel seen occupied many times holds.
pub const OT_OCCUPIED_LOG_ODDS: f32 = 3.5;
/// Log-odds of a free leaf in the `.ot` files we write: OctoMap's default lower clamping
/// bound (probability 0.1192).
pub const OT_FREE_LOG_ODDS: f32 = -2.0;

/// The name used in errors from [`OcTree::from_voxels`], which has no file.
const VOXELS_NAME: &str = "<from_voxels>";

/// Longest stack the depth-first walks can need: at most 8 entries are pushed per level and
/// inner nodes exist only at depths 0..=15.
const STACK_CAPACITY: usize = 8 * TREE_DEPTH as usize + 1;

/// Something wrong with a map file (or with the voxels given to [`OcTree::from_voxels`]).
///
/// Every variant's message starts with the file's name and says what is wrong with it.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum MapFileError {
    /// The file could not be read or written.
    #[error("{file}: cannot {action} the file: {source}")]
    Io {
        /// The file.
        file: String,
        /// "read" or "write".
        action: &'static str,
        /// What the operating system said.
        #[source]
        source: std::io::Error,
    },
    /// The file has no bytes at all.
    #[error(
        "{file}: the file is empty; an OctoMap file starts with \"# Octomap OcTree binary file\""
    )]
    Empty {
        /// The file.
        file: String,
    },
    /// The first line is not an OctoMap header.
    #[error(
        "{file}: not an OctoMap file: the first line is {first_line:?}, expected \
         \"# Octomap OcTree binary file\" (.bt) or \"# Octomap OcTree file\" (.ot)"
    )]
    NotOctoMap {
        /// The file.
        file: String,
        /// The start of its first line (lossy UTF-8, shortened).
        first_line: String,
    },
    /// The outdated binary format from before OctoMap 1.4, which has no text header.
    #[error(
        "{file}: outdated OctoMap binary format without a text header (before OctoMap 1.4); \
         convert it with OctoMap's `convert_octree` tool first"
    )]
    LegacyFormat {
        /// The file.
        file: String,
    },
    /// The text header is incomplete or has a value that cannot be parsed.
    #[error("{file}: bad OctoMap header: {problem}")]
    Header {
        /// The file.
        file: String,
        /// What is wrong.
        problem: String,
    },
    /// The header's `id` is not a tree type this reader understands.
    #[error("{file}: unsupported tree type \"id {id}\": only OcTree maps can be read")]
    UnknownId {
        /// The file.
        file: String,
        /// The id found (shortened).
        id: String,
    },
    /// The resolution is not a finite number in the accepted range.
    #[error(
        "{file}: unusable resolution {resolution} m: it must be a finite number from \
         {MIN_RESOLUTION} to {MAX_RESOLUTION} m"
    )]
    BadResolution {
        /// The file.
        file: String,
        /// The resolution found.
        resolution: f64,
    },
    /// The header's `size` is more nodes than the bytes after the header can hold.
    #[error(
        "{file}: the header says the tree has {header} nodes, but only {bytes} bytes of tree \
         data follow, which can hold at most {max_nodes} nodes"
    )]
    SizeImpossible {
        /// The file.
        file: String,
        /// The node count in the header.
        header: u64,
        /// Bytes after the header.
        bytes: usize,
        /// The most nodes those bytes can encode.
        max_nodes: u64,
    },
    /// The header's `size` is not the number of nodes in the tree.
    #[error("{file}: the header says the tree has {header} nodes, but the data holds {found}")]
    SizeMismatch {
        /// The file.
        file: String,
        /// The node count in the header.
        header: u64,
        /// The node count of the tree as read.
        found: u64,
    },
    /// The data ends in the middle of the tree.
    #[error(
        "{file}: truncated: the tree data ends at byte {offset}, in the middle of the tree \
         (the file is {len} bytes long)"
    )]
    Truncated {
        /// The file.
        file: String,
        /// Where the next node should have started.
        offset: usize,
        /// The length of the file.
        len: usize,
    },
    /// The tree data is not a valid OctoMap tree.
    #[error("{file}: corrupt tree data at byte {offset}: {problem}")]
    Corrupt {
        /// The file.
        file: String,
        /// Where the offending node starts.
        offset: usize,
        /// What is wrong.
        problem: &'static str,
    },
    /// Bytes follow the end of the tree.
    #[error(
        "{file}: {count} unexpected bytes after the end of the tree (which ends at byte \
         {offset}); the file may be damaged or be two files joined"
    )]
    TrailingBytes {
        /// The file.
        file: String,
        /// Where the tree ends.
        offset: usize,
        /// How many bytes follow.
        count: usize,
    },
    /// A voxel given to [`OcTree::from_voxels`] lies outside the tree.
    #[error("{file}: voxel {voxel:?} is outside the tree: every index must be in -32768..=32767")]
    VoxelOutOfRange {
        /// `<from_voxels>`.
        file: String,
        /// The voxel's integer indices.
        voxel: [i32; 3],
    },
    /// The voxels fill the whole tree, which OctoMap cannot store (its root cannot be a leaf).
    #[error(
        "{file}: the voxels fill the whole tree; OctoMap cannot store a tree whose root is a leaf"
    )]
    WholeTree {
        /// `<from_voxels>`.
        file: String,
    },
}

/// A known leaf of the tree: a cube of free or occupied space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Leaf {
    /// Centre of the cube, metres, computed exactly as OctoMap's `keyToCoord(key, depth)`.
    pub center: [f64; 3],
    /// Edge of the cube, metres: `resolution * 2^(16 - depth)` (OctoMap's `getNodeSize`).
    pub size: f64,
    /// True when occupied, false when free.
    pub occupied: bool,
    /// Depth in the tree, 1..=16 (16 for a single voxel).
    pub depth: u8,
}

/// An OctoMap occupancy tree in max-likelihood form: every known leaf is free or occupied.
///
/// Inner nodes are stored in one compact array: per node its 16 child bits (the `.bt`
/// encoding) and the index of its first inner child; the inner children of a node sit
/// next to each other in child order. Leaves are only the codes in their parent's bits.
#[derive(Clone)]
pub struct OcTree {
    resolution: f64,
    /// Per inner node: child `i` in bits `2i, 2i+1` (0 none, 1 free, 2 occupied, 3 inner).
    codes: Vec<u16>,
    /// Per inner node: index of its first inner child (unused when it has none).
    first_child: Vec<u32>,
    stats: Stats,
}

/// Values computed once when a tree is made.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Stats {
    occupied: usize,
    free: usize,
    nodes: u64,
    bounds: Option<([f64; 3], [f64; 3])>,
}

/// Parsed text header.
struct Header {
    kind: Kind,
    size: u64,
    resolution: f64,
    data_start: usize,
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Kind {
    Binary,
    Full,
}

/// One node of the tree in depth-first order, as fed to [`OcTree::from_preorder`].
struct PreNode {
    code: u16,
    offset: usize,
}

impl OcTree {
    /// Reads a `.bt` file (or a full `.ot` file, see the module documentation).
    pub fn read_bt(path: &Path) -> Result<OcTree, MapFileError> {
        let name = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|source| MapFileError::Io {
            file: name.clone(),
            action: "read",
            source,
        })?;
        OcTree::from_bt_bytes(&bytes, &name)
    }

    /// Reads a `.bt` (or full `.ot`) file's bytes; `name` is used in error messages.
    pub fn from_bt_bytes(bytes: &[u8], name: &str) -> Result<OcTree, MapFileError> {
        let header = parse_header(bytes, name)?;
        let data = bytes.get(header.data_start..).unwrap_or(&[]);
        match header.kind {
            Kind::Binary => decode_bt(bytes, data, &header, name),
            Kind::Full => decode_ot(bytes, data, &header, name),
        }
    }

    /// The tree as a `.bt` file, byte for byte what OctoMap's `writeBinary` writes for the
    /// same tree (same header, same node order). The tree is written as it is: a tree read
    /// from a file is not pruned further.
    pub fn to_bt_bytes(&self) -> Vec<u8> {
        let header = format!(
            "# Octomap OcTree binary file\n\
             # (feel free to add / change comments, but leave the first line as it is!)\n\
             #\n\
             id OcTree\n\
             size {}\n\
             res {}\n\
             data\n",
            self.stats.nodes, self.resolution
        );
        let mut out = Vec::with_capacity(header.len() + 2 * self.codes.len());
        out.extend_from_slice(header.as_bytes());
        for code in self.preorder() {
            out.extend_from_slice(&code.to_le_bytes());
        }
        out
    }

    /// Writes the tree as a `.bt` file, atomically (a reader never sees half a file).
    pub fn write_bt(&self, path: &Path) -> Result<(), MapFileError> {
        crate::fsutil::write_atomic(path, &self.to_bt_bytes()).map_err(|source| MapFileError::Io {
            file: path.display().to_string(),
            action: "write",
            source,
        })
    }

    /// The tree as a full `.ot` file (OctoMap's `AbstractOcTree::write`): per node, in
    /// depth-first order, its log-odds occupancy (`f32`, little-endian) and a byte of
    /// child-exists bits. The tree keeps only max-likelihood states, so a leaf is written
    /// with OctoMap's default clamping bound for its state ([`OT_OCCUPIED_LOG_ODDS`],
    /// [`OT_FREE_LOG_ODDS`]) and an inner node with the largest value below it, as
    /// OctoMap's `updateInnerOccupancy` sets it. Reading the file gives this tree back.
    pub fn to_ot_bytes(&self) -> Vec<u8> {
        let header = format!(
            "# Octomap OcTree file\n\
             # (feel free to add / change comments, but leave the first line as it is!)\n\
             #\n\
             id OcTree\n\
             size {}\n\
             res {}\n\
             data\n",
            self.stats.nodes, self.resolution
        );
        let mut out = Vec::with_capacity(header.len() + 5 * self.stats.nodes as usize);
        out.extend_from_slice(header.as_bytes());
        if self.codes.is_empty() {
            return out;
        }
        let mut occupied = vec![None; self.codes.len()];
        let root_value = self.inner_log_odds(0, &mut occupied);
        self.write_ot_node(0, root_value, &mut occupied, &mut out);
        out
    }

    /// The log-odds of the inner node in `slot`: occupied when any leaf below it is
    /// (memoised in `memo`, one entry per inner node).
    fn inner_log_odds(&self, slot: usize, memo: &mut [Option<bool>]) -> f32 {
        if let Some(known) = memo[slot] {
            return if known {
                OT_OCCUPIED_LOG_ODDS
            } else {
                OT_FREE_LOG_ODDS
            };
        }
        let code = self.codes[slot];
        let mut any = false;
        for child in 0..8u32 {
            any |= match (code >> (2 * child)) & 3 {
                CHILD_OCCUPIED => true,
                CHILD_INNER => self
                    .inner_child_slot(slot, code, child)
                    .is_some_and(|s| self.inner_log_odds(s, memo) >= 0.0),
                _ => false,
            };
        }
        memo[slot] = Some(any);
        if any {
            OT_OCCUPIED_LOG_ODDS
        } else {
            OT_FREE_LOG_ODDS
        }
    }

    /// Appends the inner node in `slot` (log-odds `value`) and its subtree to `out`.
    fn write_ot_node(&self, slot: usize, value: f32, memo: &mut [Option<bool>], out: &mut Vec<u8>) {
        let code = self.codes[slot];
        let exists = (0..8u32).fold(0u8, |m, c| {
            if (code >> (2 * c)) & 3 != CHILD_NONE {
                m | (1 << c)
            } else {
                m
            }
        });
        out.extend_from_slice(&value.to_le_bytes());
        out.push(exists);
        for child in 0..8u32 {
            match (code >> (2 * child)) & 3 {
                CHILD_OCCUPIED => {
                    out.extend_from_slice(&OT_OCCUPIED_LOG_ODDS.to_le_bytes());
                    out.push(0);
                }
                CHILD_FREE => {
                    out.extend_from_slice(&OT_FREE_LOG_ODDS.to_le_bytes());
                    out.push(0);
                }
                CHILD_INNER => {
                    if let Some(s) = self.inner_child_slot(slot, code, child) {
                        let v = self.inner_log_odds(s, memo);
                        self.write_ot_node(s, v, memo, out);
                    }
                }
                _ => {}
            }
        }
    }

    /// Writes the tree as a full `.ot` file ([`OcTree::to_ot_bytes`]), atomically.
    pub fn write_ot(&self, path: &Path) -> Result<(), MapFileError> {
        crate::fsutil::write_atomic(path, &self.to_ot_bytes()).map_err(|source| MapFileError::Io {
            file: path.display().to_string(),
            action: "write",
            source,
        })
    }

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
    pub fn metric_bounds(&self) -> Option<([f64; 3], [f64; 3])> {
        self.stats.bounds
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
    pub fn query(&self, p: [f64; 3]) -> Option<bool> {
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
        drop(cells);
        if level.is_empty() {
            return Ok(OcTree::empty(resolution));
        }

        // Bottom-up, one level at a time: `level` holds the known nodes at `depth`, keyed by
        // their path from the root (3 bits per level), sorted. Inner nodes made at each
        // level are kept per level, then laid out breadth-first.
        let mut inner_levels: Vec<Vec<(u16, u32)>> = Vec::with_capacity(usize::from(TREE_DEPTH));
        let mut below: Vec<(u16, u32)> = Vec::new();
        for _depth in (1..=TREE_DEPTH).rev() {
            let mut parents: Vec<(u64, Entry)> = Vec::with_capacity(level.len() / 2 + 1);
            let mut inner_here: Vec<(u16, u32)> = Vec::new();
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
        let mut by_depth: Vec<Vec<(u16, u32)>> = Vec::with_capacity(usize::from(TREE_DEPTH) + 1);
        by_depth.push(below);
        by_depth.extend(inner_levels.into_iter().rev());
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
        let mut tree = OcTree {
            resolution,
            codes,
            first_child,
            stats: Stats {
                occupied: 0,
                free: 0,
                nodes: 0,
                bounds: None,
            },
        };
        tree.stats = tree.compute_stats();
        Ok(tree)
    }

    fn empty(resolution: f64) -> OcTree {
        OcTree {
            resolution,
            codes: Vec::new(),
            first_child: Vec::new(),
            stats: Stats {
                occupied: 0,
                free: 0,
                nodes: 0,
                bounds: None,
            },
        }
    }

    /// Slot of inner child `child` of the node in `slot` (whose bits are `code`).
    fn inner_child_slot(&self, slot: usize, code: u16, child: u32) -> Option<usize> {
        let first = *self.first_child.get(slot)? as usize;
        Some(first + inner_rank(code, child) as usize)
    }

    /// Codes of the inner nodes in depth-first order (the `.bt` order).
    fn preorder(&self) -> Preorder<'_> {
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

    /// Builds the node arrays from the inner nodes' codes in depth-first order, checking
    /// that they form a valid tree. `next` yields the nodes in order (or an error, e.g.
    /// truncation); `inner_hint` is how many inner nodes the input can hold at most.
    fn from_preorder(
        resolution: f64,
        name: &str,
        inner_hint: usize,
        mut next: impl FnMut() -> Result<PreNode, MapFileError>,
    ) -> Result<OcTree, MapFileError> {
        let mut codes: Vec<u16> = Vec::with_capacity(inner_hint.saturating_add(1));
        let mut first_child: Vec<u32> = Vec::with_capacity(inner_hint.saturating_add(1));
        codes.push(0);
        first_child.push(0);
        // (slot, depth) of inner nodes still to read, the next one on top.
        let mut stack: Vec<(usize, u8)> = Vec::with_capacity(STACK_CAPACITY);
        stack.push((0, 0));
        while let Some((slot, depth)) = stack.pop() {
            let PreNode { code, offset } = next()?;
            let corrupt = |problem| MapFileError::Corrupt {
                file: name.to_string(),
                offset,
                problem,
            };
            if code == 0 {
                return Err(corrupt(if slot == 0 {
                    "the root node has no children"
                } else {
                    "an inner node has no children"
                }));
            }
            let inner = inner_mask(code);
            let n_inner = inner.count_ones() as usize;
            if n_inner > 0 && depth + 1 >= TREE_DEPTH {
                return Err(corrupt("a node at the deepest level (16) has children"));
            }
            let first = codes.len();
            if u32::try_from(first + n_inner).is_err() {
                return Err(corrupt("too many nodes"));
            }
            if let (Some(c), Some(f)) = (codes.get_mut(slot), first_child.get_mut(slot)) {
                *c = code;
                *f = first as u32;
            }
            codes.resize(first + n_inner, 0);
            first_child.resize(first + n_inner, 0);
            // Push the inner children last-first so that the first is read next.
            for rank in (0..n_inner).rev() {
                stack.push((first + rank, depth + 1));
            }
        }
        let mut tree = OcTree {
            resolution,
            codes,
            first_child,
            stats: Stats {
                occupied: 0,
                free: 0,
                nodes: 0,
                bounds: None,
            },
        };
        tree.stats = tree.compute_stats();
        Ok(tree)
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

/// A node while building a tree bottom-up.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Entry {
    Leaf(bool),
    Inner(u32),
}

/// Inner-node codes in depth-first order.
struct Preorder<'a> {
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
                        center: cell.map(|i| cell_center(i, depth, size)),
                        size,
                        occupied: c == CHILD_OCCUPIED,
                        depth,
                    });
                }
            }
        }
    }
}

/// The 2-bit code of `child` in a node's bits.
fn child_code(code: u16, child: u32) -> u16 {
    (code >> (2 * child)) & 3
}

/// Bit `2i` set for every inner child `i`.
fn inner_mask(code: u16) -> u16 {
    code & (code >> 1) & 0x5555
}

/// How many inner children come before `child`.
fn inner_rank(code: u16, child: u32) -> u32 {
    let below = (1u32 << (2 * child)) - 1;
    (u32::from(inner_mask(code)) & below).count_ones()
}

/// Cell of child `child` of the node in cell `cell` one level up.
fn child_cell(cell: [u32; 3], child: u32) -> [u32; 3] {
    [
        (cell[0] << 1) | (child & 1),
        (cell[1] << 1) | ((child >> 1) & 1),
        (cell[2] << 1) | ((child >> 2) & 1),
    ]
}

/// OctoMap's `getNodeSize(depth)`: `resolution * double(1 << (16 - depth))`.
fn node_size(resolution: f64, depth: u8) -> f64 {
    resolution * f64::from(1u32 << (TREE_DEPTH - depth.min(TREE_DEPTH)))
}

/// OctoMap's `keyToCoord(key, depth)` for depth 1..=16, from the cell index counted from the
/// tree's minimum corner: `(floor((key - 32768) / 2^(16 - depth)) + 0.5) * size`.
fn cell_center(cell: u32, depth: u8, size: f64) -> f64 {
    let offset = 1i64 << (depth.clamp(1, TREE_DEPTH) - 1);
    ((i64::from(cell) - offset) as f64 + 0.5) * size
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

fn check_resolution(resolution: f64, name: &str) -> Result<(), MapFileError> {
    if resolution.is_finite() && (MIN_RESOLUTION..=MAX_RESOLUTION).contains(&resolution) {
        Ok(())
    } else {
        Err(MapFileError::BadResolution {
            file: name.to_string(),
            resolution,
        })
    }
}

/// At most `max` characters of `bytes`, for error messages.
fn shorten(bytes: &[u8], max: usize) -> String {
    let text = String::from_utf8_lossy(bytes);
    let mut out: String = text.chars().take(max).collect();
    if text.chars().count() > max {
        out.push_str("...");
    }
    out
}

/// C's `isspace`, which OctoMap's `>>` uses to split the header.
fn is_space(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\n' | b'\r' | 0x0b | 0x0c)
}

/// Reads the text header, the way OctoMap's `AbstractOcTree::readHeader` does.
fn parse_header(bytes: &[u8], name: &str) -> Result<Header, MapFileError> {
    if bytes.is_empty() {
        return Err(MapFileError::Empty {
            file: name.to_string(),
        });
    }
    let line_end = bytes.iter().position(|&b| b == b'\n');
    let first_line = bytes
        .get(..line_end.unwrap_or(bytes.len()))
        .unwrap_or(bytes);
    let kind = if first_line.starts_with(BT_FIRST_LINE) {
        Kind::Binary
    } else if first_line.starts_with(OT_FIRST_LINE) {
        Kind::Full
    } else if bytes.get(..4) == Some(&3i32.to_le_bytes()[..]) {
        return Err(MapFileError::LegacyFormat {
            file: name.to_string(),
        });
    } else {
        return Err(MapFileError::NotOctoMap {
            file: name.to_string(),
            first_line: shorten(first_line, 60),
        });
    };
    let header_err = |problem: String| MapFileError::Header {
        file: name.to_string(),
        problem,
    };
    let mut pos = line_end.map_or(bytes.len(), |p| p + 1);
    let skip_line = |pos: usize| -> usize {
        match bytes
            .get(pos..)
            .and_then(|rest| rest.iter().position(|&b| b == b'\n'))
        {
            Some(p) => pos + p + 1,
            None => bytes.len(),
        }
    };
    let token = |pos: usize| -> (usize, &[u8]) {
        let mut start = pos;
        while bytes.get(start).is_some_and(|&b| is_space(b)) {
            start += 1;
        }
        let mut end = start;
        while bytes.get(end).is_some_and(|&b| !is_space(b)) {
            end += 1;
        }
        (end, bytes.get(start..end).unwrap_or(&[]))
    };
    let mut id: Option<&[u8]> = None;
    let mut size: Option<u64> = None;
    let mut res: Option<f64> = None;
    let data_start = loop {
        let (after, tok) = token(pos);
        pos = after;
        match tok {
            b"" => {
                return Err(header_err(
                    "the header ends without a \"data\" line (is the file truncated?)".into(),
                ))
            }
            b"data" => break skip_line(pos),
            t if t.starts_with(b"#") => pos = skip_line(pos),
            b"id" => {
                let (after, value) = token(pos);
                pos = after;
                id = Some(value);
            }
            b"size" => {
                let (after, value) = token(pos);
                pos = after;
                let parsed = std::str::from_utf8(value)
                    .ok()
                    .filter(|s| s.bytes().all(|b| b.is_ascii_digit()))
                    .and_then(|s| s.parse::<u64>().ok());
                match parsed {
                    Some(n) => size = Some(n),
                    None => {
                        return Err(header_err(format!(
                            "\"size {}\" is not a node count",
                            shorten(value, 40)
                        )))
                    }
                }
            }
            b"res" => {
                let (after, value) = token(pos);
                pos = after;
                match std::str::from_utf8(value)
                    .ok()
                    .and_then(|s| s.parse::<f64>().ok())
                {
                    Some(r) => res = Some(r),
                    None => {
                        return Err(header_err(format!(
                            "\"res {}\" is not a number",
                            shorten(value, 40)
                        )))
                    }
                }
            }
            // OctoMap warns about unknown keywords and skips their line; so do we.
            _ => pos = skip_line(pos),
        }
    };
    let id = match id {
        None | Some(b"") => return Err(header_err("no \"id\" line".into())),
        Some(id) => id,
    };
    if id != b"OcTree" && id != b"1" {
        return Err(MapFileError::UnknownId {
            file: name.to_string(),
            id: shorten(id, 40),
        });
    }
    let Some(resolution) = res else {
        return Err(header_err("no \"res\" line".into()));
    };
    check_resolution(resolution, name)?;
    let Some(size) = size else {
        return Err(header_err("no \"size\" line".into()));
    };
    Ok(Header {
        kind,
        size,
        resolution,
        data_start,
    })
}

/// Decodes the binary part of a `.bt` file.
fn decode_bt(
    bytes: &[u8],
    data: &[u8],
    header: &Header,
    name: &str,
) -> Result<OcTree, MapFileError> {
    let start = header.data_start;
    if header.size == 0 {
        if !data.is_empty() {
            return Err(MapFileError::TrailingBytes {
                file: name.to_string(),
                offset: start,
                count: data.len(),
            });
        }
        return Ok(OcTree::empty(header.resolution));
    }
    // Each inner node takes 2 bytes and has at most 8 children.
    let inner_max = data.len() / 2;
    let max_nodes = 1 + 8 * inner_max as u64;
    if header.size > max_nodes {
        return Err(MapFileError::SizeImpossible {
            file: name.to_string(),
            header: header.size,
            bytes: data.len(),
            max_nodes,
        });
    }
    let mut pos = 0usize;
    let tree = OcTree::from_preorder(header.resolution, name, inner_max, || {
        match data.get(pos..pos + 2) {
            Some(&[a, b]) => {
                let node = PreNode {
                    code: u16::from_le_bytes([a, b]),
                    offset: start + pos,
                };
                pos += 2;
                Ok(node)
            }
            _ => Err(MapFileError::Truncated {
                file: name.to_string(),
                offset: start + pos,
                len: bytes.len(),
            }),
        }
    })?;
    finish(
        tree,
        header,
        name,
        start + pos,
        data.len() - pos.min(data.len()),
    )
}

/// Decodes the binary part of a full `.ot` file into the max-likelihood tree.
fn decode_ot(
    bytes: &[u8],
    data: &[u8],
    header: &Header,
    name: &str,
) -> Result<OcTree, MapFileError> {
    const RECORD: usize = 5; // f32 log-odds + child-exists byte
    let start = header.data_start;
    if header.size == 0 {
        if !data.is_empty() {
            return Err(MapFileError::TrailingBytes {
                file: name.to_string(),
                offset: start,
                count: data.len(),
            });
        }
        return Ok(OcTree::empty(header.resolution));
    }
    let max_nodes = (data.len() / RECORD) as u64;
    if header.size > max_nodes {
        return Err(MapFileError::SizeImpossible {
            file: name.to_string(),
            header: header.size,
            bytes: data.len(),
            max_nodes,
        });
    }
    let read = |pos: usize| -> Result<(f32, u8), MapFileError> {
        match data.get(pos..pos + RECORD) {
            Some(&[a, b, c, d, mask]) => Ok((f32::from_le_bytes([a, b, c, d]), mask)),
            _ => Err(MapFileError::Truncated {
                file: name.to_string(),
                offset: start + pos,
                len: bytes.len(),
            }),
        }
    };
    // Rewrite the nodes into `.bt` codes in depth-first order. A node's code is complete once
    // all its children have been read (each child's record tells whether it is a leaf).
    let mut codes: Vec<u16> = Vec::with_capacity(data.len() / RECORD / 2 + 1);
    let mut offsets: Vec<usize> = Vec::with_capacity(data.len() / RECORD / 2 + 1);
    // (index in codes, depth, child-exists bits, next child to read)
    let mut stack: Vec<(usize, u8, u8, u32)> = Vec::with_capacity(usize::from(TREE_DEPTH) + 1);
    let (_, root_mask) = read(0)?;
    let mut pos = RECORD;
    codes.push(0);
    offsets.push(start);
    if root_mask == 0 {
        return Err(MapFileError::Corrupt {
            file: name.to_string(),
            offset: start,
            problem: "the root node has no children",
        });
    }
    stack.push((0, 0, root_mask, 0));
    while let Some(top) = stack.last_mut() {
        let (index, depth, mask, next) = *top;
        let Some(child) = (next..8).find(|&c| mask & (1 << c) != 0) else {
            stack.pop();
            continue;
        };
        top.3 = child + 1;
        let offset = start + pos;
        let (value, child_mask) = read(pos)?;
        pos += RECORD;
        let child_depth = depth + 1;
        let code = if child_mask == 0 {
            if value.is_nan() {
                return Err(MapFileError::Corrupt {
                    file: name.to_string(),
                    offset,
                    problem: "a leaf's log-odds occupancy is not a number",
                });
            }
            // OctoMap's isNodeOccupied with the default threshold (probability 0.5).
            if value >= 0.0 {
                CHILD_OCCUPIED
            } else {
                CHILD_FREE
            }
        } else {
            if child_depth >= TREE_DEPTH {
                return Err(MapFileError::Corrupt {
                    file: name.to_string(),
                    offset,
                    problem: "a node at the deepest level (16) has children",
                });
            }
            CHILD_INNER
        };
        if let Some(c) = codes.get_mut(index) {
            *c |= code << (2 * child);
        }
        if code == CHILD_INNER {
            stack.push((codes.len(), child_depth, child_mask, 0));
            codes.push(0);
            offsets.push(offset);
        }
    }
    let mut i = 0usize;
    let tree = OcTree::from_preorder(header.resolution, name, codes.len(), || {
        let node = match (codes.get(i), offsets.get(i)) {
            (Some(&code), Some(&offset)) => PreNode { code, offset },
            _ => {
                return Err(MapFileError::Truncated {
                    file: name.to_string(),
                    offset: start + pos,
                    len: bytes.len(),
                })
            }
        };
        i += 1;
        Ok(node)
    })?;
    finish(
        tree,
        header,
        name,
        start + pos,
        data.len() - pos.min(data.len()),
    )
}

/// Final checks shared by both formats: node count and trailing bytes.
fn finish(
    tree: OcTree,
    header: &Header,
    name: &str,
    end: usize,
    trailing: usize,
) -> Result<OcTree, MapFileError> {
    if tree.stats.nodes != header.size {
        return Err(MapFileError::SizeMismatch {
            file: name.to_string(),
            header: header.size,
            found: tree.stats.nodes,
        });
    }
    if trailing > 0 {
        return Err(MapFileError::TrailingBytes {
            file: name.to_string(),
            offset: end,
            count: trailing,
        });
    }
    Ok(tree)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// SplitMix64: small deterministic random numbers for tests.
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> u64 {
            self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            z ^ (z >> 31)
        }
        fn below(&mut self, n: u64) -> u64 {
            self.next() % n
        }
        fn range(&mut self, lo: i32, hi: i32) -> i32 {
            lo + self.below((hi - lo) as u64) as i32
        }
        fn unit(&mut self) -> f64 {
            (self.next() >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    fn header(size: &str, res: &str) -> Vec<u8> {
        format!(
            "# Octomap OcTree binary file\n# comment\n#\nid OcTree\nsize {size}\nres {res}\ndata\n"
        )
        .into_bytes()
    }

    /// Root: child 0 occupied leaf, child 1 free leaf, child 7 inner; that one: child 0 free.
    fn tiny_bt() -> Vec<u8> {
        let mut b = header("5", "1");
        b.extend_from_slice(&[0x06, 0xc0, 0x01, 0x00]);
        b
    }

    fn room(res: f64) -> OcTree {
        let mut voxels = Vec::new();
        for i in -6..10 {
            for j in -3..9 {
                for k in 0..8 {
                    let wall = i == -6 || i == 9 || j == -3 || j == 8 || k == 0 || k == 7;
                    voxels.push(([i, j, k], wall));
                }
            }
        }
        for i in 16..32 {
            for j in -32..-16 {
                for k in 0..16 {
                    voxels.push(([i, j, k], false));
                }
            }
        }
        OcTree::from_voxels(res, voxels).unwrap()
    }

    fn err(bytes: &[u8]) -> MapFileError {
        match OcTree::from_bt_bytes(bytes, "test.bt") {
            Ok(t) => panic!("accepted a bad file: {t:?}"),
            Err(e) => {
                assert!(e.to_string().starts_with("test.bt: "), "{e}");
                e
            }
        }
    }

    /// OctoMap's calcMinMax, visiting every leaf.
    fn brute_bounds(tree: &OcTree) -> Option<([f64; 3], [f64; 3])> {
        let mut out: Option<([f64; 3], [f64; 3])> = None;
        for leaf in tree.leaves() {
            let (mut mn, mut mx) = out.unwrap_or(([f64::MAX; 3], [-f64::MAX; 3]));
            for a in 0..3 {
                let lo = leaf.center[a] - leaf.size / 2.0;
                mn[a] = mn[a].min(lo);
                mx[a] = mx[a].max(lo + leaf.size);
            }
            out = Some((mn, mx));
        }
        out
    }

    #[test]
    fn bit_order_and_child_order_follow_octomap() {
        let tree = OcTree::from_bt_bytes(&tiny_bt(), "tiny.bt").unwrap();
        assert_eq!(tree.counts(), (1, 2));
        assert_eq!(tree.node_count(), 5);
        let leaves: Vec<Leaf> = tree.leaves().collect();
        let h = 16384.0;
        assert_eq!(
            leaves,
            vec![
                Leaf {
                    center: [-h, -h, -h],
                    size: 32768.0,
                    occupied: true,
                    depth: 1
                },
                Leaf {
                    center: [h, -h, -h],
                    size: 32768.0,
                    occupied: false,
                    depth: 1
                },
                Leaf {
                    center: [8192.0; 3],
                    size: 16384.0,
                    occupied: false,
                    depth: 2
                },
            ]
        );
        assert_eq!(tree.query([-1.0, -1.0, -1.0]), Some(true));
        assert_eq!(tree.query([1.0, -1.0, -1.0]), Some(false));
        assert_eq!(tree.query([-1.0, 1.0, -1.0]), None);
        assert_eq!(tree.query([1.0, 1.0, 1.0]), Some(false));
        assert_eq!(tree.query([20000.0, 20000.0, 20000.0]), None);
        assert_eq!(
            tree.metric_bounds(),
            Some(([-32768.0, -32768.0, -32768.0], [32768.0, 16384.0, 16384.0]))
        );
        // The writer gives back the same tree bytes.
        assert!(tree.to_bt_bytes().ends_with(&[0x06, 0xc0, 0x01, 0x00]));
    }

    #[test]
    fn writer_header_is_octomaps() {
        let tree = OcTree::from_voxels(0.05, [([0, 0, 0], true)]).unwrap();
        let bytes = tree.to_bt_bytes();
        let text = String::from_utf8_lossy(&bytes);
        assert!(text.starts_with(
            "# Octomap OcTree binary file\n# (feel free to add / change comments, but leave the first line as it is!)\n#\nid OcTree\nsize 17\nres 0.05\ndata\n"
        ));
        // One voxel: 16 inner nodes (depths 0..=15), 2 bytes each.
        assert_eq!(tree.node_count(), 17);
        let leaves: Vec<Leaf> = tree.leaves().collect();
        assert_eq!(
            leaves,
            vec![Leaf {
                center: [0.025; 3],
                size: 0.05,
                occupied: true,
                depth: 16
            }]
        );
        assert_eq!(tree.metric_bounds(), Some(([0.0; 3], [0.05; 3])));
    }

    #[test]
    fn header_is_read_like_octomap() {
        let data = &tiny_bt()[tiny_bt().len() - 4..];
        let variants: [&[u8]; 4] = [
            b"# Octomap OcTree binary file\nid 1\nsize 5\nres 1.0\ndata\n",
            b"# Octomap OcTree binary file (trailing words are fine)\r\n# c\r\nres 1\r\nfoo bar baz\r\nsize 5\r\nid OcTree\r\ndata\r\n",
            b"# Octomap OcTree binary file\n\n  id   OcTree  size 5 res 1e0\n#data\ndata and the rest of this line\n",
            b"# Octomap OcTree binary file\nres 2\nres 1\nid OcTree\nsize 5\ndata\n",
        ];
        let reference = OcTree::from_bt_bytes(&tiny_bt(), "tiny.bt").unwrap();
        for v in variants {
            let mut b = v.to_vec();
            b.extend_from_slice(data);
            let tree = OcTree::from_bt_bytes(&b, "v.bt").unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(tree, reference, "{}", String::from_utf8_lossy(v));
        }
    }

    #[test]
    fn round_trip_of_random_trees() {
        let mut rng = Rng(7);
        for round in 0..60 {
            let res = [0.02, 0.05, 0.08, 0.1, 0.2, 0.5][round % 6];
            let mut voxels = Vec::new();
            let spread = [4, 16, 60, 300][round % 4];
            for _ in 0..rng.below(600) {
                let v = [
                    rng.range(-spread, spread),
                    rng.range(-spread, spread),
                    rng.range(-spread, spread),
                ];
                voxels.push((v, rng.below(3) == 0));
            }
            // Aligned blocks, so that pruning happens at several levels.
            for _ in 0..rng.below(4) {
                let edge = 1 << rng.below(5);
                let o = [
                    rng.range(-8, 8) * edge,
                    rng.range(-8, 8) * edge,
                    rng.range(-8, 8) * edge,
                ];
                let occ = rng.below(2) == 0;
                for i in 0..edge {
                    for j in 0..edge {
                        for k in 0..edge {
                            voxels.push(([o[0] + i, o[1] + j, o[2] + k], occ));
                        }
                    }
                }
            }
            if round == 0 {
                voxels.clear();
            }
            let tree = OcTree::from_voxels(res, voxels.clone()).unwrap();
            let bytes = tree.to_bt_bytes();
            let back = OcTree::from_bt_bytes(&bytes, "round.bt").unwrap();
            assert_eq!(back, tree);
            assert_eq!(back.to_bt_bytes(), bytes);
            assert!(back.leaves().eq(tree.leaves()));
            let (occ, free) = tree.counts();
            assert_eq!(tree.leaves().filter(|l| l.occupied).count(), occ);
            assert_eq!(tree.leaves().filter(|l| !l.occupied).count(), free);
            assert_eq!(tree.metric_bounds(), brute_bounds(&tree));
            assert_eq!(back.metric_bounds(), tree.metric_bounds());
            // Every voxel reads back as its last state.
            let mut last = std::collections::HashMap::new();
            for (v, occ) in &voxels {
                last.insert(*v, *occ);
            }
            for (v, occ) in &last {
                let c = v.map(|i| (f64::from(i) + 0.5) * res);
                assert_eq!(tree.query(c), Some(*occ), "voxel {v:?}");
            }
            // Random points agree with a brute-force search over the leaves.
            if let Some((mn, mx)) = tree.metric_bounds() {
                for _ in 0..200 {
                    let p: [f64; 3] = std::array::from_fn(|a| {
                        mn[a] - res + (mx[a] - mn[a] + 2.0 * res) * rng.unit()
                    });
                    let key = p.map(|c| ((1.0 / res) * c).floor());
                    let brute = tree
                        .leaves()
                        .find(|l| {
                            (0..3).all(|a| {
                                let lo = ((l.center[a] - l.size / 2.0) / res).round();
                                key[a] >= lo && key[a] < lo + (l.size / res).round()
                            })
                        })
                        .map(|l| l.occupied);
                    assert_eq!(tree.query(p), brute, "point {p:?}");
                }
            }
        }
    }

    #[test]
    fn eight_equal_children_are_pruned_into_their_parent() {
        let block = |o: [i32; 3], edge: i32, occ: bool| {
            let mut v = Vec::new();
            for i in 0..edge {
                for j in 0..edge {
                    for k in 0..edge {
                        v.push(([o[0] + i, o[1] + j, o[2] + k], occ));
                    }
                }
            }
            v
        };
        // Aligned 2x2x2 of one state: one leaf at depth 15; 15 inner nodes + the leaf.
        let t = OcTree::from_voxels(0.1, block([2, -4, 6], 2, true)).unwrap();
        assert_eq!(t.counts(), (1, 0));
        assert_eq!(t.node_count(), 16);
        let leaf = t.leaves().next().unwrap();
        assert_eq!((leaf.depth, leaf.size), (15, 0.2));
        // Aligned 16^3: one leaf at depth 12.
        let t = OcTree::from_voxels(0.05, block([-32, 16, 0], 16, false)).unwrap();
        assert_eq!(t.counts(), (0, 1));
        assert_eq!(t.leaves().next().unwrap().depth, 12);
        let (mn, mx) = t.metric_bounds().unwrap();
        let expected = ([-1.6, 0.8, 0.0], [-0.8, 1.6, 0.8]);
        for a in 0..3 {
            assert!((mn[a] - expected.0[a]).abs() < 1e-12, "{mn:?}");
            assert!((mx[a] - expected.1[a]).abs() < 1e-12, "{mx:?}");
        }
        // Mixed states are not pruned.
        let mut mixed = block([0, 0, 0], 2, true);
        mixed[3].1 = false;
        let t = OcTree::from_voxels(0.1, mixed).unwrap();
        assert_eq!(t.counts(), (7, 1));
        assert!(t.leaves().all(|l| l.depth == 16));
        // Not aligned: nothing to prune.
        let t = OcTree::from_voxels(0.1, block([1, 0, 0], 2, true)).unwrap();
        assert_eq!(t.counts(), (8, 0));
        // Seven of eight: not pruned.
        let mut seven = block([0, 0, 0], 2, true);
        seven.pop();
        assert_eq!(OcTree::from_voxels(0.1, seven).unwrap().counts(), (7, 0));
        // 4x4x4 of one state, aligned: pruned twice, into one depth-14 leaf.
        let t = OcTree::from_voxels(0.1, block([4, 4, 4], 4, false)).unwrap();
        assert_eq!(t.counts(), (0, 1));
        assert_eq!(t.leaves().next().unwrap().depth, 14);
    }

    #[test]
    fn from_voxels_last_state_wins_and_checks_range() {
        let t = OcTree::from_voxels(0.1, [([0, 0, 0], true), ([0, 0, 0], false)]).unwrap();
        assert_eq!(t.counts(), (0, 1));
        let t = OcTree::from_voxels(0.1, [([-32768, 32767, 0], true)]).unwrap();
        assert_eq!(t.query([-3276.75, 3276.75, 0.05]), Some(true));
        let e = OcTree::from_voxels(0.1, [([32768, 0, 0], true)]).unwrap_err();
        assert!(
            matches!(
                e,
                MapFileError::VoxelOutOfRange {
                    voxel: [32768, 0, 0],
                    ..
                }
            ),
            "{e}"
        );
        assert!(e.to_string().starts_with("<from_voxels>: "));
        let e = OcTree::from_voxels(f64::NAN, [([0, 0, 0], true)]).unwrap_err();
        assert!(matches!(e, MapFileError::BadResolution { .. }), "{e}");
    }

    #[test]
    fn empty_tree() {
        let t = OcTree::from_voxels(0.1, []).unwrap();
        assert_eq!(t.counts(), (0, 0));
        assert_eq!(t.node_count(), 0);
        assert_eq!(t.metric_bounds(), None);
        assert_eq!(t.leaves().count(), 0);
        assert_eq!(t.query([0.0; 3]), None);
        let bytes = t.to_bt_bytes();
        assert!(bytes.ends_with(b"size 0\nres 0.1\ndata\n"));
        assert_eq!(OcTree::from_bt_bytes(&bytes, "e.bt").unwrap(), t);
    }

    #[test]
    fn queries_outside_the_tree_are_unknown() {
        let t = OcTree::from_voxels(
            0.5,
            [([-32768, -32768, -32768], true), ([32767, 0, 0], false)],
        )
        .unwrap();
        let edge = 32768.0 * 0.5;
        assert_eq!(t.query([-edge, -edge, -edge]), Some(true));
        assert_eq!(t.query([edge - 0.25, 0.25, 0.25]), Some(false));
        assert_eq!(t.query([edge, 0.25, 0.25]), None);
        assert_eq!(t.query([-edge - 1e-9, -edge, -edge]), None);
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e300, -1e300] {
            assert_eq!(t.query([bad, 0.0, 0.0]), None);
            assert_eq!(t.query([0.0, 0.0, bad]), None);
        }
    }

    #[test]
    fn ot_files_we_write_read_back_as_the_same_tree() {
        let t = OcTree::from_bt_bytes(&tiny_bt(), "tiny.bt").unwrap();
        let ot = t.to_ot_bytes();
        assert!(ot.starts_with(b"# Octomap OcTree file\n"));
        assert_eq!(OcTree::from_bt_bytes(&ot, "tiny.ot").unwrap(), t);
        let empty = OcTree::empty(0.1);
        assert_eq!(
            OcTree::from_bt_bytes(&empty.to_ot_bytes(), "e.ot").unwrap(),
            empty
        );
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.ot");
        t.write_ot(&path).unwrap();
        assert_eq!(OcTree::read_bt(&path).unwrap(), t);
    }

    #[test]
    fn full_ot_files_are_read() {
        // The tiny tree as a full .ot: log-odds f32 + child-exists bits per node.
        let mut b = b"# Octomap OcTree file\n# c\nid OcTree\nsize 5\nres 1\ndata\n".to_vec();
        let rec = |b: &mut Vec<u8>, v: f32, mask: u8| {
            b.extend_from_slice(&v.to_le_bytes());
            b.push(mask);
        };
        rec(&mut b, 3.5, 0b1000_0011);
        rec(&mut b, 0.0, 0); // log-odds 0 is occupied (probability 0.5 >= threshold)
        rec(&mut b, -0.4, 0);
        rec(&mut b, 0.85, 0b0000_0001);
        rec(&mut b, -2.0, 0);
        let t = OcTree::from_bt_bytes(&b, "tiny.ot").unwrap();
        assert_eq!(t, OcTree::from_bt_bytes(&tiny_bt(), "tiny.bt").unwrap());
        // Bad .ot files.
        let mut nan = b.clone();
        let n = nan.len();
        nan[n - 5..n - 1].copy_from_slice(&f32::NAN.to_le_bytes());
        assert!(matches!(err(&nan), MapFileError::Corrupt { .. }));
        for cut in 1..b.len() - 52 {
            assert!(matches!(
                err(&b[..b.len() - cut]),
                MapFileError::Truncated { .. } | MapFileError::SizeImpossible { .. }
            ));
        }
        let mut extra = b.clone();
        extra.push(0);
        assert!(matches!(
            err(&extra),
            MapFileError::TrailingBytes { count: 1, .. }
        ));
        let mut lie = b.clone();
        let at = lie.windows(6).position(|w| w == b"size 5").unwrap();
        lie[at + 5] = b'4';
        assert!(matches!(
            err(&lie),
            MapFileError::SizeMismatch {
                header: 4,
                found: 5,
                ..
            }
        ));
        let mut color = b.clone();
        let at = color.windows(9).position(|w| w == b"id OcTree").unwrap() + 3;
        color.splice(at..at, b"Color".iter().copied());
        assert!(matches!(err(&color), MapFileError::UnknownId { .. }));
        let root_leaf =
            b"# Octomap OcTree file\nid OcTree\nsize 1\nres 1\ndata\n\0\0\0\0\0".to_vec();
        assert!(matches!(err(&root_leaf), MapFileError::Corrupt { .. }));
        // A chain 17 nodes deep: the node at depth 16 must not have children.
        let mut deep = b"# Octomap OcTree file\nid OcTree\nsize 18\nres 1\ndata\n".to_vec();
        for _ in 0..17 {
            rec(&mut deep, 1.0, 1);
        }
        rec(&mut deep, 1.0, 0);
        assert!(matches!(err(&deep), MapFileError::Corrupt { .. }));
    }

    #[test]
    fn bad_files_give_clear_errors() {
        let good = room(0.1).to_bt_bytes();
        assert!(matches!(err(b""), MapFileError::Empty { .. }));
        let e = err(b"hello world\nid OcTree\n");
        assert!(matches!(e, MapFileError::NotOctoMap { .. }));
        assert!(e.to_string().contains("hello world"), "{e}");
        let mut legacy = 3i32.to_le_bytes().to_vec();
        legacy.extend_from_slice(&0.1f64.to_le_bytes());
        assert!(matches!(err(&legacy), MapFileError::LegacyFormat { .. }));
        // Header problems.
        for (h, what) in [
            ("# Octomap OcTree binary file\nid OcTree\nsize 5\nres 1\n", "data"),
            ("# Octomap OcTree binary file\nsize 5\nres 1\ndata\n", "id"),
            ("# Octomap OcTree binary file\nid OcTree\nsize 5\ndata\n", "res"),
            ("# Octomap OcTree binary file\nid OcTree\nres 1\ndata\n", "size"),
            ("# Octomap OcTree binary file\nid OcTree\nsize -1\nres 1\ndata\n", "size"),
            ("# Octomap OcTree binary file\nid OcTree\nsize 99999999999999999999999\nres 1\ndata\n", "size"),
            ("# Octomap OcTree binary file\nid OcTree\nsize 5\nres abc\ndata\n", "res"),
            ("# Octomap OcTree binary file", "data"),
        ] {
            let e = err(h.as_bytes());
            assert!(matches!(e, MapFileError::Header { .. }), "{h}: {e}");
            assert!(e.to_string().contains(what), "{e}");
        }
        // Resolutions.
        for r in ["nan", "inf", "-inf", "-0.1", "0", "1e-9", "1e6", "0.0009"] {
            let mut b = header("5", r);
            b.extend_from_slice(&[0x06, 0xc0, 0x01, 0x00]);
            let e = err(&b);
            assert!(matches!(e, MapFileError::BadResolution { .. }), "{r}: {e}");
            assert!(e.to_string().contains("resolution"), "{e}");
        }
        // Ids.
        let e = err(&String::from_utf8_lossy(&good)
            .replace("id OcTree", "id ColorOcTree")
            .into_bytes());
        assert!(
            matches!(e, MapFileError::UnknownId { ref id, .. } if id == "ColorOcTree"),
            "{e}"
        );
        // Sizes that lie.
        let nodes = room(0.1).node_count();
        let body = &good[good.windows(5).position(|w| w == b"data\n").unwrap() + 5..];
        for (claim, expect_impossible) in [
            (nodes + 1, false),
            (nodes - 1, false),
            (0, false),
            (4_000_000_000, true),
            (u64::MAX, true),
        ] {
            let mut b = header(&claim.to_string(), "0.1");
            b.extend_from_slice(body);
            let e = err(&b);
            if expect_impossible {
                assert!(
                    matches!(e, MapFileError::SizeImpossible { .. }),
                    "{claim}: {e}"
                );
            } else if claim == 0 {
                assert!(
                    matches!(e, MapFileError::TrailingBytes { .. }),
                    "{claim}: {e}"
                );
            } else {
                assert!(
                    matches!(e, MapFileError::SizeMismatch { header, found, .. } if header == claim && found == nodes),
                    "{e}"
                );
            }
        }
        // Trailing bytes.
        let mut extra = good.clone();
        extra.extend_from_slice(b"\n");
        assert!(matches!(
            err(&extra),
            MapFileError::TrailingBytes { count: 1, .. }
        ));
        // Corrupt trees: a childless inner node, a root without children, children at depth 16.
        let mut b = header("5", "1");
        b.extend_from_slice(&[0x06, 0xc0, 0x00, 0x00]);
        assert!(matches!(err(&b), MapFileError::Corrupt { .. }));
        let mut b = header("1", "1");
        b.extend_from_slice(&[0x00, 0x00]);
        assert!(matches!(err(&b), MapFileError::Corrupt { .. }));
        let mut b = header("18", "1");
        for _ in 0..17 {
            b.extend_from_slice(&[0x03, 0x00]);
        }
        b.extend_from_slice(&[0x02, 0x00]);
        let e = err(&b);
        assert!(matches!(e, MapFileError::Corrupt { .. }), "{e}");
        assert!(e.to_string().contains("16"), "{e}");
    }

    #[test]
    fn every_truncation_is_an_error() {
        let good = room(0.2).to_bt_bytes();
        let data_start = good.windows(5).position(|w| w == b"data\n").unwrap() + 5;
        for len in 0..good.len() {
            let e = err(&good[..len]);
            if len > data_start {
                assert!(
                    matches!(
                        e,
                        MapFileError::Truncated { .. } | MapFileError::SizeImpossible { .. }
                    ),
                    "{len}: {e}"
                );
            }
        }
    }

    #[test]
    fn random_bytes_never_panic() {
        let mut rng = Rng(99);
        let good = room(0.1).to_bt_bytes();
        let data_start = good.windows(5).position(|w| w == b"data\n").unwrap() + 5;
        for round in 0..3000 {
            let mut b: Vec<u8> = if round % 3 == 0 {
                (0..rng.below(300)).map(|_| rng.next() as u8).collect()
            } else {
                good.clone()
            };
            if round % 3 == 1 {
                // Flip a few bytes of the tree.
                for _ in 0..1 + rng.below(4) {
                    let at = data_start + rng.below((good.len() - data_start) as u64) as usize;
                    b[at] = rng.next() as u8;
                }
            } else if round % 3 == 2 {
                // Valid header, random tree of a random length.
                b.truncate(data_start);
                b.extend((0..rng.below(200)).map(|_| rng.next() as u8));
            }
            if let Ok(t) = OcTree::from_bt_bytes(&b, "random.bt") {
                assert_eq!(OcTree::from_bt_bytes(&t.to_bt_bytes(), "again").unwrap(), t);
                let (o, f) = t.counts();
                assert_eq!(t.leaves().count(), o + f);
            }
        }
    }

    #[test]
    fn files_are_written_atomically_and_read_back() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("room.bt");
        let tree = room(0.05);
        tree.write_bt(&path).unwrap();
        assert_eq!(OcTree::read_bt(&path).unwrap(), tree);
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        let missing = dir.path().join("missing.bt");
        let e = OcTree::read_bt(&missing).unwrap_err();
        assert!(matches!(e, MapFileError::Io { action: "read", .. }));
        assert!(e.to_string().contains("missing.bt"), "{e}");
        let e = tree
            .write_bt(&dir.path().join("no/such/dir/x.bt"))
            .unwrap_err();
        assert!(
            matches!(
                e,
                MapFileError::Io {
                    action: "write",
                    ..
                }
            ),
            "{e}"
        );
    }
}
