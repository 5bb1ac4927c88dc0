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
//!
//! # Where things are
//!
//! * `header`: the text header, read the way OctoMap reads it and written the way
//!   OctoMap writes it.
//! * `decode`: the binary tree of `.bt` and `.ot` files into an [`OcTree`].
//! * `encode`: an [`OcTree`] into `.bt` and `.ot` files.
//! * `voxels`: building a pruned [`OcTree`] from voxels.
//! * `tree`: the compact node arrays and the walks over them.
//! * `query`: what a loaded map answers (state at a point, leaves, bounds, counts).
//! * `error`: [`MapFileError`].

mod decode;
mod encode;
mod error;
mod header;
mod query;
mod tree;
mod voxels;

#[cfg(test)]
mod tests;

pub use error::MapFileError;
pub use tree::OcTree;
