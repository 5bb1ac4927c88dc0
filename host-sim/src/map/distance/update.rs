//! Updating the distance field where voxels change state, to the bit what
//! [`DistanceField::new`] would build from the changed grid.
//!
//! # The rule
//! The squared EDT is separable (see [`crate::map::edt`]): the x pass turns each row's
//! obstacles into `g1` (squared distance along the row), the y pass turns each y column
//! of `g1` into `g2`, the z pass each z column of `g2` into the EDT. A 1D transform's
//! output depends on its input line only, so after a change:
//! - only the rows holding a voxel whose obstacle status flipped can have a new `g1`;
//! - only the y columns through a voxel whose `g1` changed can have a new `g2`;
//! - only the z columns through a voxel whose `g2` changed can have a new EDT value.
//!
//! A flipped row is swept whole, once each way (its inputs are sites or nothing, so the
//! squared distance to the nearest site is the transform's exact value). On a y column
//! the update redoes only the window of cells whose output may change (the `line`
//! module: a cell further from every changed input than its old output's distance
//! keeps it, and past the first such cell every one does), each value the exact minimum
//! the transform computes: a narrow window value by value, a wide one by the build's
//! own 1D transform of the part of the column within reach of it (sites beyond the
//! reach provably cannot lower its values; `line::window_transform`); the z columns it
//! transforms again in full, with the build's
//! own 1D transform (their old values are not kept). Changed EDT values go through the
//! build's own conversion: equal to a recomputation, which a property test checks to
//! the bit. The row gaps depend on their row only and are redone for the flipped rows;
//! the grid's block counts are kept by [`Grid::set`].
//!
//! # What is kept, and why not FIESTA's wavefronts
//! Per voxel, `g1` and `g2` (`u32` each, 8 bytes). They play the role of FIESTA's
//! per-voxel nearest obstacle and its lists of dependents: a deleted obstacle's
//! dependents are the voxels whose `g1` changes in its row, then whose `g2` changes in
//! those columns, and so on; nothing else is visited. FIESTA and voxblox propagate sites
//! between neighbours (6 or 24 of them) by breadth-first wavefronts, which is not exact
//! on a grid in general (a voxel's nearest site need not be any neighbour's nearest
//! site), and the field must equal a recomputation to the bit.
//!
//! # Cost
//! A row costs two sweeps and its row gaps (`nx` each); a y column its window and
//! the window's reach (the root of its largest value) either side; a z
//! column through a changed `g2` costs `nz`: the reach of the change along each axis
//! in turn, never the whole map unless the change reaches it (an obstacle added to an
//! otherwise empty row of an open map changes that whole row's `g1`). The grid does not
//! grow: a change outside it is an error.

use super::super::edt::{pass_x, pass_y, site, Scratch, NONE};
use super::super::grid::{Cell, Grid};
use super::super::row_gaps::row_gaps_of;
use super::{stored_bound, DistanceField};

/// Windows of a y column at least this wide are redone by transforming the part of
/// the column within their reach.
const WIDE_WINDOW: usize = 8;

/// The partial transforms an update starts from: the EDT's x and y passes over the
/// current grid (layout as the grid's cells).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Kept {
    /// The x pass: squared distance along each row to its nearest obstacle.
    g1: Vec<u32>,
    /// The y pass over `g1`.
    g2: Vec<u32>,
}

impl Kept {
    /// The passes of `grid`, computed in full.
    pub(crate) fn of(grid: &Grid) -> Self {
        let g1 = pass_x(grid);
        let mut g2 = g1.clone();
        pass_y(&mut g2, grid.dims(), grid.unknown_is_occupied());
        Self { g1, g2 }
    }

    /// Bytes held.
    pub(crate) fn memory_bytes(&self) -> usize {
        (self.g1.len() + self.g2.len()) * std::mem::size_of::<u32>()
    }
}

/// What one [`DistanceField::update`] did (callers measure its time).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct UpdateStats {
    /// Changes given (a voxel given twice counts twice).
    pub changes: usize,
    /// Changes that flipped a voxel between obstacle and not (the rest change only the
    /// grid's state, e.g. free to unknown while unknown space is free).
    pub obstacle_flips: usize,
    /// Rows along x redone (their row gaps in full).
    pub rows: usize,
    /// Columns along y redone.
    pub y_columns: usize,
    /// Columns along z transformed again, in full.
    pub z_columns: usize,
    /// Voxels whose stored bound changed.
    pub bounds_changed: usize,
    /// Values the three passes computed again: the windows of the rows and y columns
    /// where the output may change, and `nz` per z column.
    pub voxels_visited: usize,
    /// Whether this update first had to build the kept passes (a full x and y pass; see
    /// [`DistanceField::prepare_updates`]).
    pub built_kept: bool,
}

/// Why an update was refused (the field and grid are then unchanged).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum UpdateError {
    /// A change names a voxel outside the grid, which the update cannot grow.
    #[error(
        "change {change}: voxel {voxel:?} is outside the grid (lattice {lo:?} to {hi:?}); \
         the distance field does not grow its grid"
    )]
    OutsideGrid {
        /// Position of the change in the list.
        change: usize,
        /// Its lattice index.
        voxel: [i32; 3],
        /// The grid's first voxel.
        lo: [i32; 3],
        /// The grid's last voxel.
        hi: [i32; 3],
    },
}

impl DistanceField {
    /// Builds what [`Self::update`] keeps (8 bytes a voxel; see [`Self::memory_bytes`]),
    /// so that the first update costs no more than the next. Does nothing if built.
    pub fn prepare_updates(&mut self) {
        if self.kept.is_none() {
            self.kept = Some(Box::new(Kept::of(&self.grid)));
        }
    }

    /// Sets each voxel `i` to its state, in order (a voxel given twice ends in its last
    /// state), and updates the field where the change reaches: afterwards it equals, to
    /// the bit, [`DistanceField::new`] of the changed grid. Unknown space counts as the
    /// grid says. Refuses, changing nothing, a voxel outside the grid.
    pub fn update(&mut self, changes: &[([i32; 3], Cell)]) -> Result<UpdateStats, UpdateError> {
        self.check_inside(changes)?;
        let mut stats = UpdateStats {
            changes: changes.len(),
            built_kept: self.kept.is_none(),
            ..UpdateStats::default()
        };
        self.prepare_updates();
        let flipped = self.apply(changes, &mut stats);
        let g1_changed = self.redo_rows(&flipped, &mut stats);
        let z_cols = self.redo_y_columns(&g1_changed, &mut stats);
        self.redo_z_columns(&z_cols, &mut stats);
        Ok(stats)
    }

    /// `Ok` when every change is inside the grid, else the first that is not.
    fn check_inside(&self, changes: &[([i32; 3], Cell)]) -> Result<(), UpdateError> {
        let g = &self.grid;
        match changes.iter().position(|(i, _)| g.local(*i).is_none()) {
            None => Ok(()),
            Some(change) => {
                let lo = g.origin();
                let d = g.dims();
                let hi = [0, 1, 2].map(|a| (lo[a] as i64 + d[a] as i64 - 1) as i32);
                let voxel = changes[change].0;
                Err(UpdateError::OutsideGrid {
                    change,
                    voxel,
                    lo,
                    hi,
                })
            }
        }
    }

    /// Writes the changes into the grid; the voxels (linear indices) whose obstacle
    /// status flipped, sorted, once each: by row, x ascending within a row.
    fn apply(&mut self, changes: &[([i32; 3], Cell)], stats: &mut UpdateStats) -> Vec<usize> {
        let mut flipped = Vec::new();
        for &(i, state) in changes {
            let was = self.grid.is_obstacle(i);
            self.grid.set(i, state);
            if self.grid.is_obstacle(i) != was {
                stats.obstacle_flips += 1;
                let l = self.grid.local(i).expect("checked inside");
                flipped.push(self.grid.linear(l));
            }
        }
        sorted_once(flipped)
    }

    /// The x pass and the row gaps of the rows holding `flipped` voxels; the cells whose
    /// `g1` changed, as keys `(x + nx z) ny + y` (by y column, y ascending), sorted.
    fn redo_rows(&mut self, flipped: &[usize], stats: &mut UpdateStats) -> Vec<usize> {
        let [nx, ny, _] = self.grid.dims();
        let walls = self.grid.unknown_is_occupied();
        let kept = self.kept.as_mut().expect("prepared");
        let (mut sites, mut fresh) = (vec![NONE; nx], vec![NONE; nx]);
        let mut changed = Vec::new();
        for run in flipped.chunk_by(|i, j| i / nx == j / nx) {
            let row = run[0] / nx;
            let (y, z) = (row % ny, row / ny);
            for (c, obstacle) in sites.iter_mut().zip(self.grid.obstacle_row(y, z)) {
                *c = site(obstacle);
            }
            let start = row * nx;
            line::row_pass(&sites, walls, &mut fresh);
            for (x, (&new, old)) in fresh.iter().zip(&mut kept.g1[start..]).enumerate() {
                if new != *old {
                    *old = new;
                    changed.push((x + nx * z) * ny + y);
                }
            }
            row_gaps_of(&self.grid, y, z, &mut self.row_gaps[start..start + nx]);
            stats.rows += 1;
            stats.voxels_visited += nx;
        }
        changed.sort_unstable();
        changed
    }

    /// The y pass of the y columns holding `changed` cells (keys of [`Self::redo_rows`]);
    /// the z columns (`x + nx y`) whose input changed, sorted, once each.
    fn redo_y_columns(&mut self, changed: &[usize], stats: &mut UpdateStats) -> Vec<usize> {
        let [nx, ny, _] = self.grid.dims();
        let walls = self.grid.unknown_is_occupied();
        let kept = self.kept.as_mut().expect("prepared");
        let mut s = Scratch::new(ny);
        let mut next = Vec::new();
        for run in changed.chunk_by(|i, j| i / ny == j / ny) {
            let col = run[0] / ny;
            let (x, z) = (col % nx, col / nx);
            let first = x + nx * ny * z;
            let (a, b) = (run[0] % ny, run[run.len() - 1] % ny);
            let (g1, g2) = (&kept.g1, &mut kept.g2);
            let (lo, hi) = line::window(ny, a, b, |q| g2[first + nx * q]);
            // A value costs a scan as long as its distance; past a few cells a window
            // costs less as the transform of the column's part within its reach (both
            // exact: the same numbers).
            let wide = hi - lo >= WIDE_WINDOW;
            // Where the window's values start in `s.out`.
            let mut at = 0;
            if wide {
                let f = |p: usize| g1[first + nx * p];
                let old_max = (lo..=hi).map(|q| g2[first + nx * q]).max().unwrap_or(NONE);
                at = line::window_transform(&mut s, ny, walls, (lo, hi), old_max, f);
            }
            for y in lo..=hi {
                let new = if wide {
                    s.out[y - at]
                } else {
                    line::value_at(ny, walls, y, |p| g1[first + nx * p])
                };
                let old = &mut g2[first + nx * y];
                if new != *old {
                    *old = new;
                    next.push(x + nx * y);
                }
            }
            stats.y_columns += 1;
            stats.voxels_visited += hi + 1 - lo;
        }
        sorted_once(next)
    }

    /// The z pass of columns `cols` (`x + nx y`), into the stored bounds.
    fn redo_z_columns(&mut self, cols: &[usize], stats: &mut UpdateStats) {
        let [nx, ny, nz] = self.grid.dims();
        let plane = nx * ny;
        let walls = self.grid.unknown_is_occupied();
        let r = self.grid.resolution();
        let kept = self.kept.as_ref().expect("prepared");
        let mut s = Scratch::new(nz);
        for &col in cols {
            for z in 0..nz {
                s.row[z] = kept.g2[col + plane * z];
            }
            s.run(nz, walls);
            for z in 0..nz {
                let b = stored_bound(s.out[z], r);
                let old = &mut self.lb[col + plane * z];
                if b.to_bits() != old.to_bits() {
                    *old = b;
                    stats.bounds_changed += 1;
                }
            }
        }
        stats.z_columns = cols.len();
        stats.voxels_visited += cols.len() * nz;
    }
}

/// `keys` sorted, each once.
fn sorted_once(mut keys: Vec<usize>) -> Vec<usize> {
    keys.sort_unstable();
    keys.dedup();
    keys
}

mod line;
#[cfg(test)]
mod tests;
