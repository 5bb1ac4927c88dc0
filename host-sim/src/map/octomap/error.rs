//! [`MapFileError`]: everything that can be wrong with an OctoMap file, or with the voxels
//! a tree is built from.

use super::header::{MAX_RESOLUTION, MIN_RESOLUTION};
#[cfg(doc)]
use super::OcTree;

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
