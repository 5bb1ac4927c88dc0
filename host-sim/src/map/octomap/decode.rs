//! Reading `.bt` and full `.ot` files into an [`OcTree`]: the binary tree after the
//! header, checked strictly (see the module documentation of `map::octomap` for what is
//! refused).

use std::path::Path;

use super::error::MapFileError;
use super::header::{parse_header, Header, Kind};
use super::tree::{
    inner_mask, OcTree, CHILD_FREE, CHILD_INNER, CHILD_OCCUPIED, STACK_CAPACITY, TREE_DEPTH,
};

/// Bytes per node in a full `.ot` file: its `f32` log-odds and a child-exists byte.
const OT_RECORD: usize = 5;

/// One node of the tree in depth-first order, as fed to [`tree_from_preorder`].
struct PreNode {
    code: u16,
    offset: usize,
}

/// A file being decoded: what the errors of both formats need to say where they are.
struct Input<'a> {
    /// The whole file.
    bytes: &'a [u8],
    /// The binary part, after the header.
    data: &'a [u8],
    header: Header,
    /// The file's name, for errors.
    name: &'a str,
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
        let input = Input {
            bytes,
            data: bytes.get(header.data_start..).unwrap_or(&[]),
            header,
            name,
        };
        match input.header.kind {
            Kind::Binary => decode_bt(&input),
            Kind::Full => decode_ot(&input),
        }
    }
}

impl Input<'_> {
    /// The data ends where the node at `pos` (counted from the start of the data) should be.
    fn truncated(&self, pos: usize) -> MapFileError {
        MapFileError::Truncated {
            file: self.name.to_string(),
            offset: self.header.data_start + pos,
            len: self.bytes.len(),
        }
    }

    /// The node at byte `offset` of the file is not a valid node.
    fn corrupt(&self, offset: usize, problem: &'static str) -> MapFileError {
        MapFileError::Corrupt {
            file: self.name.to_string(),
            offset,
            problem,
        }
    }

    /// The tree of a header with `size 0`: empty, and nothing may follow the header.
    fn empty_tree(&self) -> Result<OcTree, MapFileError> {
        if !self.data.is_empty() {
            return Err(MapFileError::TrailingBytes {
                file: self.name.to_string(),
                offset: self.header.data_start,
                count: self.data.len(),
            });
        }
        Ok(OcTree::empty(self.header.resolution))
    }

    /// Refuses a header `size` above `max_nodes`, the most nodes the data can hold, before
    /// anything is allocated for it.
    fn check_size_possible(&self, max_nodes: u64) -> Result<(), MapFileError> {
        if self.header.size > max_nodes {
            return Err(MapFileError::SizeImpossible {
                file: self.name.to_string(),
                header: self.header.size,
                bytes: self.data.len(),
                max_nodes,
            });
        }
        Ok(())
    }

    /// Final checks shared by both formats, for a tree whose data ended at `pos` (counted
    /// from the start of the data): node count and trailing bytes.
    fn finish(&self, tree: OcTree, pos: usize) -> Result<OcTree, MapFileError> {
        if tree.stats.nodes != self.header.size {
            return Err(MapFileError::SizeMismatch {
                file: self.name.to_string(),
                header: self.header.size,
                found: tree.stats.nodes,
            });
        }
        let trailing = self.data.len() - pos.min(self.data.len());
        if trailing > 0 {
            return Err(MapFileError::TrailingBytes {
                file: self.name.to_string(),
                offset: self.header.data_start + pos,
                count: trailing,
            });
        }
        Ok(tree)
    }
}

/// Decodes the binary part of a `.bt` file.
fn decode_bt(input: &Input) -> Result<OcTree, MapFileError> {
    if input.header.size == 0 {
        return input.empty_tree();
    }
    let data = input.data;
    // Each inner node takes 2 bytes and has at most 8 children.
    let inner_max = data.len() / 2;
    input.check_size_possible(1 + 8 * inner_max as u64)?;
    let mut pos = 0usize;
    let tree = tree_from_preorder(input, inner_max, || match data.get(pos..pos + 2) {
        Some(&[a, b]) => {
            let node = PreNode {
                code: u16::from_le_bytes([a, b]),
                offset: input.header.data_start + pos,
            };
            pos += 2;
            Ok(node)
        }
        _ => Err(input.truncated(pos)),
    })?;
    input.finish(tree, pos)
}

/// Decodes the binary part of a full `.ot` file into the max-likelihood tree.
fn decode_ot(input: &Input) -> Result<OcTree, MapFileError> {
    if input.header.size == 0 {
        return input.empty_tree();
    }
    input.check_size_possible((input.data.len() / OT_RECORD) as u64)?;
    let (codes, offsets, pos) = ot_to_bt_codes(input)?;
    let mut i = 0usize;
    let tree = tree_from_preorder(input, codes.len(), || {
        let node = match (codes.get(i), offsets.get(i)) {
            (Some(&code), Some(&offset)) => PreNode { code, offset },
            _ => return Err(input.truncated(pos)),
        };
        i += 1;
        Ok(node)
    })?;
    input.finish(tree, pos)
}

/// Rewrites the records of a full `.ot` file into the `.bt` codes of its inner nodes, in
/// depth-first order, with the file offset of each inner node's record; and where the
/// records end (counted from the start of the data). A node's code is complete once all
/// its children have been read (each child's record tells whether it is a leaf).
fn ot_to_bt_codes(input: &Input) -> Result<(Vec<u16>, Vec<usize>, usize), MapFileError> {
    let data = input.data;
    let start = input.header.data_start;
    let read = |pos: usize| -> Result<(f32, u8), MapFileError> {
        match data.get(pos..pos + OT_RECORD) {
            Some(&[a, b, c, d, mask]) => Ok((f32::from_le_bytes([a, b, c, d]), mask)),
            _ => Err(input.truncated(pos)),
        }
    };
    let mut codes: Vec<u16> = Vec::with_capacity(data.len() / OT_RECORD / 2 + 1);
    let mut offsets: Vec<usize> = Vec::with_capacity(data.len() / OT_RECORD / 2 + 1);
    // (index in codes, depth, child-exists bits, next child to read)
    let mut stack: Vec<(usize, u8, u8, u32)> = Vec::with_capacity(usize::from(TREE_DEPTH) + 1);
    let (_, root_mask) = read(0)?;
    let mut pos = OT_RECORD;
    codes.push(0);
    offsets.push(start);
    if root_mask == 0 {
        return Err(input.corrupt(start, "the root node has no children"));
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
        pos += OT_RECORD;
        let child_depth = depth + 1;
        let code = if child_mask == 0 {
            if value.is_nan() {
                return Err(input.corrupt(offset, "a leaf's log-odds occupancy is not a number"));
            }
            // OctoMap's isNodeOccupied with the default threshold (probability 0.5).
            if value >= 0.0 {
                CHILD_OCCUPIED
            } else {
                CHILD_FREE
            }
        } else {
            if child_depth >= TREE_DEPTH {
                return Err(input.corrupt(offset, "a node at the deepest level (16) has children"));
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
    Ok((codes, offsets, pos))
}

/// Builds the node arrays from the inner nodes' codes in depth-first order, checking
/// that they form a valid tree. `next` yields the nodes in order (or an error, e.g.
/// truncation); `inner_hint` is how many inner nodes the input can hold at most.
fn tree_from_preorder(
    input: &Input,
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
        if code == 0 {
            return Err(input.corrupt(
                offset,
                if slot == 0 {
                    "the root node has no children"
                } else {
                    "an inner node has no children"
                },
            ));
        }
        let n_inner = inner_mask(code).count_ones() as usize;
        if n_inner > 0 && depth + 1 >= TREE_DEPTH {
            return Err(input.corrupt(offset, "a node at the deepest level (16) has children"));
        }
        let first = codes.len();
        if u32::try_from(first + n_inner).is_err() {
            return Err(input.corrupt(offset, "too many nodes"));
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
    Ok(OcTree::from_nodes(
        input.header.resolution,
        codes,
        first_child,
    ))
}
