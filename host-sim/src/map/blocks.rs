//! Which blocks of a grid may hold an obstacle: a summary that lets exact searches
//! (the verifier's nearest obstacle cube) skip empty space without reading every
//! voxel.
//!
//! The grid is cut into cubes of [`BLOCK`]^3 voxels from its first voxel. For each
//! block the summary keeps whether it holds an occupied voxel and whether it holds an
//! unknown one; whether unknown space counts as an obstacle is applied at query time,
//! so that [`super::Grid::set_unknown_is_occupied`] needs no new summary. A block that
//! reaches outside the grid holds unknown voxels too (outside the grid is unknown).
//!
//! The grid keeps the summary up to date as its voxels are written, counting the
//! occupied and the unknown voxels of every block, so that carving free space out of an
//! unknown or occupied grid (as scenarios and maps are built) leaves exact counts. It is
//! a plain field, not a lazily made one: a cell with interior mutability inside the grid
//! would keep the compiler from holding the grid's fields in registers in every hot loop
//! that reads it.

use super::grid::Cell;

/// Edge of a block (voxels).
pub(crate) const BLOCK: usize = 4;

/// Per block, how many of its voxels are occupied and how many unknown, and whether
/// it reaches beyond the grid.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct ObstacleBlocks {
    /// Blocks per axis.
    dims: [usize; 3],
    /// Occupied voxels per block, x fastest.
    occupied: Vec<u8>,
    /// Unknown voxels per block (in the grid), x fastest.
    unknown: Vec<u8>,
    /// Voxels per axis of the grid.
    grid_dims: [usize; 3],
}

impl ObstacleBlocks {
    /// The summary of a grid of `dims` voxels, every one `fill`.
    pub(crate) fn new(dims: [usize; 3], fill: Cell) -> Self {
        let bdims = dims.map(|d| d.div_ceil(BLOCK));
        let n = bdims.iter().product();
        let mut blocks = Self {
            dims: bdims,
            occupied: vec![0; n],
            unknown: vec![0; n],
            grid_dims: dims,
        };
        if fill != Cell::Free {
            let counts = if fill == Cell::Occupied {
                &mut blocks.occupied
            } else {
                &mut blocks.unknown
            };
            for bz in 0..bdims[2] {
                for by in 0..bdims[1] {
                    for bx in 0..bdims[0] {
                        // Voxels of the block inside the grid.
                        let inside: usize = [bx, by, bz]
                            .iter()
                            .zip(&dims)
                            .map(|(&b, &d)| (d - b * BLOCK).min(BLOCK))
                            .product();
                        counts[bx + bdims[0] * (by + bdims[1] * bz)] = inside as u8;
                    }
                }
            }
        }
        blocks
    }

    /// Records that voxels `x0..x0 + old.len()` (grid-local) of row `(y, z)`, whose raw
    /// states were `old`, are now `state`.
    #[inline]
    pub(crate) fn write_run(&mut self, old: &[u8], x0: usize, y: usize, z: usize, state: Cell) {
        let (by, bz) = (y / BLOCK, z / BLOCK);
        for (j, &was) in old.iter().enumerate() {
            let was = Cell::from_u8(was);
            if was == state {
                continue;
            }
            let k = (x0 + j) / BLOCK + self.dims[0] * (by + self.dims[1] * bz);
            match was {
                Cell::Occupied => self.occupied[k] -= 1,
                Cell::Unknown => self.unknown[k] -= 1,
                Cell::Free => {}
            }
            match state {
                Cell::Occupied => self.occupied[k] += 1,
                Cell::Unknown => self.unknown[k] += 1,
                Cell::Free => {}
            }
        }
    }

    /// Whether block `b` (grid-local block index, any value) may hold an obstacle, with
    /// unknown space an obstacle when `unknown_is_occupied`. Beyond the grid's faces
    /// all is unknown.
    #[inline]
    pub(crate) fn may_hold(&self, b: [i64; 3], unknown_is_occupied: bool) -> bool {
        let inside = (0..3).all(|a| b[a] >= 0 && (b[a] as usize) < self.dims[a]);
        if !inside {
            return unknown_is_occupied;
        }
        let b = b.map(|v| v as usize);
        let k = b[0] + self.dims[0] * (b[1] + self.dims[1] * b[2]);
        if self.occupied[k] > 0 {
            return true;
        }
        let sticks_out = (0..3).any(|a| (b[a] + 1) * BLOCK > self.grid_dims[a]);
        unknown_is_occupied && (self.unknown[k] > 0 || sticks_out)
    }
}

#[cfg(test)]
impl ObstacleBlocks {
    /// The summary counted afresh from a grid's raw states (x fastest): what the kept
    /// one must equal.
    pub(crate) fn count(dims: [usize; 3], cells: &[u8]) -> Self {
        let mut blocks = Self::new(dims, Cell::Free);
        for z in 0..dims[2] {
            for y in 0..dims[1] {
                let row = &cells[dims[0] * (y + dims[1] * z)..][..dims[0]];
                for (x, &v) in row.iter().enumerate() {
                    let free = [Cell::Free as u8];
                    blocks.write_run(&free, x, y, z, Cell::from_u8(v));
                }
            }
        }
        blocks
    }
}
