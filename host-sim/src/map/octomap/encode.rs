//! Writing an [`OcTree`] as the files OctoMap writes: `.bt` (`writeBinary`) and full
//! `.ot` (`AbstractOcTree::write`), byte for byte, and atomically on disk.

use std::path::Path;

use super::error::MapFileError;
use super::header::{header_text, Kind};
use super::tree::{child_code, OcTree, CHILD_FREE, CHILD_INNER, CHILD_NONE, CHILD_OCCUPIED};

/// Log-odds of an occupied leaf in the `.ot` files we write: OctoMap's default upper
/// clamping bound (probability 0.971), what a voxel seen occupied many times holds.
pub const OT_OCCUPIED_LOG_ODDS: f32 = 3.5;
/// Log-odds of a free leaf in the `.ot` files we write: OctoMap's default lower clamping
/// bound (probability 0.1192).
pub const OT_FREE_LOG_ODDS: f32 = -2.0;

/// The log-odds written for a node in state `occupied`.
fn log_odds(occupied: bool) -> f32 {
    if occupied {
        OT_OCCUPIED_LOG_ODDS
    } else {
        OT_FREE_LOG_ODDS
    }
}

/// Appends one `.ot` node record: its log-odds and its child-exists bits.
fn push_record(out: &mut Vec<u8>, value: f32, exists: u8) {
    out.extend_from_slice(&value.to_le_bytes());
    out.push(exists);
}

/// Writes `bytes` to `path` atomically (a reader never sees half a file).
fn write_file(path: &Path, bytes: &[u8]) -> Result<(), MapFileError> {
    crate::fsutil::write_atomic(path, bytes).map_err(|source| MapFileError::Io {
        file: path.display().to_string(),
        action: "write",
        source,
    })
}

impl OcTree {
    /// The tree as a `.bt` file, byte for byte what OctoMap's `writeBinary` writes for the
    /// same tree (same header, same node order). The tree is written as it is: a tree read
    /// from a file is not pruned further.
    pub fn to_bt_bytes(&self) -> Vec<u8> {
        let header = header_text(Kind::Binary, self.stats.nodes, self.resolution);
        let mut out = Vec::with_capacity(header.len() + 2 * self.codes.len());
        out.extend_from_slice(header.as_bytes());
        out.extend_from_slice(&self.to_binary_stream());
        out
    }

    /// The tree's nodes as OctoMap's `writeBinaryData` writes them: a `.bt` file
    /// without its header, what an `octomap_msgs/Octomap` with `binary = true` carries.
    pub fn to_binary_stream(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(2 * self.codes.len());
        for code in self.preorder() {
            out.extend_from_slice(&code.to_le_bytes());
        }
        out
    }

    /// Writes the tree as a `.bt` file, atomically (a reader never sees half a file).
    pub fn write_bt(&self, path: &Path) -> Result<(), MapFileError> {
        write_file(path, &self.to_bt_bytes())
    }

    /// The tree as a full `.ot` file (OctoMap's `AbstractOcTree::write`): per node, in
    /// depth-first order, its log-odds occupancy (`f32`, little-endian) and a byte of
    /// child-exists bits. The tree keeps only max-likelihood states, so a leaf is written
    /// with OctoMap's default clamping bound for its state (`OT_OCCUPIED_LOG_ODDS`,
    /// `OT_FREE_LOG_ODDS`) and an inner node with the largest value below it, as
    /// OctoMap's `updateInnerOccupancy` sets it. Reading the file gives this tree back.
    pub fn to_ot_bytes(&self) -> Vec<u8> {
        let header = header_text(Kind::Full, self.stats.nodes, self.resolution);
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

    /// Writes the tree as a full `.ot` file ([`OcTree::to_ot_bytes`]), atomically.
    pub fn write_ot(&self, path: &Path) -> Result<(), MapFileError> {
        write_file(path, &self.to_ot_bytes())
    }

    /// The log-odds of the inner node in `slot`: occupied when any leaf below it is
    /// (memoised in `memo`, one entry per inner node).
    fn inner_log_odds(&self, slot: usize, memo: &mut [Option<bool>]) -> f32 {
        if let Some(known) = memo[slot] {
            return log_odds(known);
        }
        let code = self.codes[slot];
        let mut any = false;
        for child in 0..8u32 {
            any |= match child_code(code, child) {
                CHILD_OCCUPIED => true,
                CHILD_INNER => self
                    .inner_child_slot(slot, code, child)
                    .is_some_and(|s| self.inner_log_odds(s, memo) >= 0.0),
                _ => false,
            };
        }
        memo[slot] = Some(any);
        log_odds(any)
    }

    /// Appends the inner node in `slot` (log-odds `value`) and its subtree to `out`.
    fn write_ot_node(&self, slot: usize, value: f32, memo: &mut [Option<bool>], out: &mut Vec<u8>) {
        let code = self.codes[slot];
        let exists = (0..8u32).fold(0u8, |m, c| {
            if child_code(code, c) != CHILD_NONE {
                m | (1 << c)
            } else {
                m
            }
        });
        push_record(out, value, exists);
        for child in 0..8u32 {
            match child_code(code, child) {
                CHILD_OCCUPIED => push_record(out, OT_OCCUPIED_LOG_ODDS, 0),
                CHILD_FREE => push_record(out, OT_FREE_LOG_ODDS, 0),
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
}
