//! A dense occupancy grid over a map's bounding box, aligned to OctoMap's voxel lattice.
//!
//! The lattice: voxel index `i` (per axis, an `i32`, OctoMap's key minus 32768) is the
//! closed cube of edge `r_v` around the centre `(i + 0.5) * r_v`, i.e. it spans
//! `[i * r_v, (i + 1) * r_v]`. The grid stores one byte per voxel ([`Cell`]) for the
//! voxels of the map's bounding box (docs/model.md validity item 4: the metric bounds of
//! all known leaves, as OctoMap's `getMetricMin`/`getMetricMax` report them). A 100 m x
//! 20 m x 5 m map at 0.1 m is 10^7 voxels, 10 MB.
//!
//! Everything outside the grid is unknown space. Whether unknown space is an obstacle
//! is the user's choice ([`Grid::unknown_is_occupied`], `--unknown-free` sets it false);
//! the grid keeps the three states so either choice can be made later.

use nalgebra::Point3;

use super::blocks::ObstacleBlocks;

/// Largest number of voxels a grid may hold (400 M: 400 MB of cells, 1.6 GB of distance
/// field). Larger maps are refused with [`GridError::TooLarge`] rather than exhausting memory.
pub const MAX_CELLS: usize = 400_000_000;

/// The six face neighbours of a voxel, as lattice index steps.
pub const FACE_NEIGHBOURS: [[i32; 3]; 6] = [
    [1, 0, 0],
    [-1, 0, 0],
    [0, 1, 0],
    [0, -1, 0],
    [0, 0, 1],
    [0, 0, -1],
];

/// The state of one voxel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum Cell {
    /// Known free (OctoMap max-likelihood free).
    Free = 0,
    /// Known occupied (OctoMap max-likelihood occupied).
    Occupied = 1,
    /// No node in the tree.
    Unknown = 2,
}

impl Cell {
    pub(crate) fn from_u8(v: u8) -> Cell {
        match v {
            0 => Cell::Free,
            1 => Cell::Occupied,
            _ => Cell::Unknown,
        }
    }
}

/// Why a grid cannot be built.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum GridError {
    /// The resolution is not a finite positive number.
    #[error("resolution {0} is not a positive number")]
    Resolution(f64),
    /// The map has no known voxel, so it has no bounding box.
    #[error("the map has no known (occupied or free) voxel")]
    Empty,
    /// The bounds are not finite or are inverted.
    #[error("bounds {0:?} .. {1:?} are not a finite box")]
    Bounds([f64; 3], [f64; 3]),
    /// The bounding box holds more than `MAX_CELLS` voxels at this resolution.
    #[error(
        "the bounding box needs {} x {} x {} voxels, more than {MAX_CELLS}",
        .dims[0], .dims[1], .dims[2]
    )]
    TooLarge {
        /// Voxels per axis that the box would need.
        dims: [u64; 3],
    },
}

/// `Ok` when `resolution` is a finite positive voxel edge.
fn check_resolution(resolution: f64) -> Result<(), GridError> {
    if resolution.is_finite() && resolution > 0.0 {
        Ok(())
    } else {
        Err(GridError::Resolution(resolution))
    }
}

/// Per-state voxel counts of a grid (inside its bounds).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CellCounts {
    /// Occupied voxels.
    pub occupied: usize,
    /// Free voxels.
    pub free: usize,
    /// Unknown voxels.
    pub unknown: usize,
}

/// A dense three-state occupancy grid on OctoMap's voxel lattice.
#[derive(Clone, Debug)]
pub struct Grid {
    resolution: f64,
    origin: [i32; 3],
    dims: [usize; 3],
    bounds: ([f64; 3], [f64; 3]),
    cells: Vec<u8>,
    unknown_is_occupied: bool,
    /// Which blocks may hold an obstacle, kept up to date by every write to `cells`.
    blocks: ObstacleBlocks,
}

impl Grid {
    /// An all-`fill` grid whose voxel `(0, 0, 0)` has lattice index `origin` and which
    /// has `dims` voxels per axis. Its bounds are the voxels' outer faces.
    pub fn new(
        resolution: f64,
        origin: [i32; 3],
        dims: [usize; 3],
        fill: Cell,
        unknown_is_occupied: bool,
    ) -> Result<Grid, GridError> {
        check_resolution(resolution)?;
        let total = dims
            .iter()
            .try_fold(1usize, |acc, &d| acc.checked_mul(d))
            .filter(|&t| t <= MAX_CELLS && t > 0);
        let Some(total) = total else {
            return Err(GridError::TooLarge {
                dims: dims.map(|d| d as u64),
            });
        };
        for a in 0..3 {
            if (origin[a] as i64 + dims[a] as i64) > i32::MAX as i64 {
                return Err(GridError::TooLarge {
                    dims: dims.map(|d| d as u64),
                });
            }
        }
        let lo = [0, 1, 2].map(|a| origin[a] as f64 * resolution);
        let hi = [0, 1, 2].map(|a| (origin[a] as i64 + dims[a] as i64) as f64 * resolution);
        Ok(Grid {
            resolution,
            origin,
            dims,
            bounds: (lo, hi),
            cells: vec![fill as u8; total],
            blocks: ObstacleBlocks::new(dims, fill),
            unknown_is_occupied,
        })
    }

    /// A grid covering the metric box `lo..hi` (snapped outwards to the lattice), every
    /// voxel unknown, then filled from `leaves`: `(centre, edge, occupied)` cubes, which
    /// may be larger than one voxel (pruned OctoMap leaves) and are expanded. The grid's
    /// reported bounds are `lo..hi` exactly as given (OctoMap's metric bounds).
    pub fn from_leaves(
        resolution: f64,
        lo: [f64; 3],
        hi: [f64; 3],
        leaves: impl IntoIterator<Item = ([f64; 3], f64, bool)>,
        unknown_is_occupied: bool,
    ) -> Result<Grid, GridError> {
        check_resolution(resolution)?;
        if (0..3).any(|a| !(lo[a].is_finite() && hi[a].is_finite() && lo[a] < hi[a])) {
            return Err(GridError::Bounds(lo, hi));
        }
        // Snap outwards, tolerating rounding in bounds that sit on the lattice.
        let snap = |v: f64, up: bool| -> f64 {
            let q = v / resolution;
            let r = q.round();
            if (q - r).abs() < 1e-6 {
                r
            } else if up {
                q.ceil()
            } else {
                q.floor()
            }
        };
        let mut origin = [0i32; 3];
        let mut dims = [0usize; 3];
        let mut raw = [0u64; 3];
        for a in 0..3 {
            let (i0, i1) = (snap(lo[a], false), snap(hi[a], true));
            let n = i1 - i0;
            raw[a] = if n.is_finite() && n > 0.0 {
                n.min(u64::MAX as f64) as u64
            } else {
                0
            };
            if !(i0 >= i32::MIN as f64 && i1 <= i32::MAX as f64) || raw[a] == 0 {
                return Err(GridError::TooLarge { dims: raw });
            }
            origin[a] = i0 as i32;
            dims[a] = raw[a] as usize;
        }
        if raw
            .iter()
            .try_fold(1u64, |acc, &d| acc.checked_mul(d))
            .is_none_or(|t| t > MAX_CELLS as u64)
        {
            return Err(GridError::TooLarge { dims: raw });
        }
        let mut g = Grid::new(resolution, origin, dims, Cell::Unknown, unknown_is_occupied)?;
        g.bounds = (lo, hi);
        for (c, size, occ) in leaves {
            g.fill_cube(c, size, if occ { Cell::Occupied } else { Cell::Free });
        }
        Ok(g)
    }

    /// The grid of an OctoMap tree: its metric bounds at its resolution, pruned leaves
    /// expanded, nodes absent from the tree unknown.
    pub fn from_octree(
        tree: &super::octomap::OcTree,
        unknown_is_occupied: bool,
    ) -> Result<Grid, GridError> {
        let (lo, hi) = tree.metric_bounds().ok_or(GridError::Empty)?;
        Grid::from_leaves(
            tree.resolution(),
            lo.into(),
            hi.into(),
            tree.leaves().map(|l| (l.center.into(), l.size, l.occupied)),
            unknown_is_occupied,
        )
    }

    /// The known voxels as an OctoMap tree (pruned), for writing a `.bt` file.
    pub fn to_octree(&self) -> Result<super::octomap::OcTree, super::octomap::MapFileError> {
        super::octomap::OcTree::from_voxels(self.resolution, self.known_voxels())
    }

    /// Sets every voxel of the cube of edge `size` centred at `c` (a lattice-aligned
    /// OctoMap leaf) to `state`, clipped to the grid.
    fn fill_cube(&mut self, c: [f64; 3], size: f64, state: Cell) {
        if !(size.is_finite() && size > 0.0) || c.iter().any(|v| !v.is_finite()) {
            return;
        }
        let mut lo = [0i64; 3];
        let mut hi = [0i64; 3];
        for a in 0..3 {
            // Voxel indices whose centres lie inside the cube.
            let l = ((c[a] - 0.5 * size) / self.resolution).round() as i64;
            let h = ((c[a] + 0.5 * size) / self.resolution).round() as i64;
            lo[a] = (l - self.origin[a] as i64).max(0);
            hi[a] = (h - self.origin[a] as i64).min(self.dims[a] as i64);
            if lo[a] >= hi[a] {
                return;
            }
        }
        for z in lo[2]..hi[2] {
            for y in lo[1]..hi[1] {
                let row = self.dims[0] * (y as usize + self.dims[1] * z as usize);
                let (x0, x1) = (lo[0] as usize, hi[0] as usize);
                let run = &mut self.cells[row + x0..row + x1];
                self.blocks
                    .write_run(run, x0, y as usize, z as usize, state);
                run.fill(state as u8);
            }
        }
    }

    /// Voxel edge `r_v` (m).
    pub fn resolution(&self) -> f64 {
        self.resolution
    }

    /// Lattice index of the grid's voxel `(0, 0, 0)`.
    pub fn origin(&self) -> [i32; 3] {
        self.origin
    }

    /// Voxels per axis.
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// The map's bounding box `(min, max)` (m): unit centres must lie inside it.
    pub fn bounds(&self) -> (Point3<f64>, Point3<f64>) {
        (self.bounds.0.into(), self.bounds.1.into())
    }

    /// Whether `p` lies in the bounding box (closed).
    pub fn in_bounds(&self, p: impl Into<Point3<f64>>) -> bool {
        let p = p.into();
        let (lo, hi) = self.bounds;
        (0..3).all(|a| p[a] >= lo[a] && p[a] <= hi[a])
    }

    /// Whether unknown space (inside and outside the grid) counts as an obstacle.
    pub fn unknown_is_occupied(&self) -> bool {
        self.unknown_is_occupied
    }

    /// Changes whether unknown space counts as an obstacle (rebuild any distance field).
    pub fn set_unknown_is_occupied(&mut self, v: bool) {
        self.unknown_is_occupied = v;
    }

    /// The lattice index of the voxel containing `p` (a point on a face belongs to the
    /// voxel above it). Saturates far outside the `i32` range.
    pub fn lattice_index(&self, p: impl Into<Point3<f64>>) -> [i32; 3] {
        let p = p.into();
        [p.x, p.y, p.z]
            .map(|v| floor(v / self.resolution).clamp(i32::MIN as f64, i32::MAX as f64) as i32)
    }

    /// Centre of the voxel with lattice index `i` (m).
    #[inline]
    pub fn voxel_center(&self, i: [i32; 3]) -> Point3<f64> {
        i.map(|v| (v as f64 + 0.5) * self.resolution).into()
    }

    /// The grid-local index of lattice voxel `i`, if it is inside the grid.
    #[inline]
    pub fn local(&self, i: [i32; 3]) -> Option<[usize; 3]> {
        let mut l = [0usize; 3];
        for a in 0..3 {
            let d = i[a] as i64 - self.origin[a] as i64;
            if d < 0 || d >= self.dims[a] as i64 {
                return None;
            }
            l[a] = d as usize;
        }
        Some(l)
    }

    /// The lattice index of grid-local voxel `l` ([`Self::local`]'s inverse).
    #[inline]
    pub fn index_of_local(&self, l: [usize; 3]) -> [i32; 3] {
        [0, 1, 2].map(|a| self.origin[a] + l[a] as i32)
    }

    /// Linear index of a grid-local voxel (x fastest).
    #[inline]
    pub fn linear(&self, l: [usize; 3]) -> usize {
        l[0] + self.dims[0] * (l[1] + self.dims[1] * l[2])
    }

    /// State of lattice voxel `i`; [`Cell::Unknown`] outside the grid.
    #[inline]
    pub fn cell(&self, i: [i32; 3]) -> Cell {
        match self.local(i) {
            Some(l) => Cell::from_u8(self.cells[self.linear(l)]),
            None => Cell::Unknown,
        }
    }

    /// Sets lattice voxel `i`; ignored outside the grid.
    pub fn set(&mut self, i: [i32; 3], state: Cell) {
        if let Some(l) = self.local(i) {
            let k = self.linear(l);
            self.blocks
                .write_run(&self.cells[k..=k], l[0], l[1], l[2], state);
            self.cells[k] = state as u8;
        }
    }

    /// Whether lattice voxel `i` is an obstacle: occupied, or unknown when unknown
    /// space counts as occupied. Outside the grid is unknown.
    #[inline]
    pub fn is_obstacle(&self, i: [i32; 3]) -> bool {
        match self.cell(i) {
            Cell::Occupied => true,
            Cell::Free => false,
            Cell::Unknown => self.unknown_is_occupied,
        }
    }

    /// Whether grid-local block `b` (voxels `BLOCK * b` to `BLOCK * b + BLOCK - 1` per
    /// axis, any index: beyond the grid is unknown) may hold an obstacle. `false` proves
    /// that none of its voxels is one.
    pub(crate) fn block_may_hold_obstacle(&self, b: [i64; 3]) -> bool {
        self.blocks.may_hold(b, self.unknown_is_occupied)
    }

    /// Whether the block summary equals a recount of the cells (for tests of code
    /// that writes the grid).
    #[cfg(test)]
    pub(crate) fn blocks_match_cells(&self) -> bool {
        self.blocks == ObstacleBlocks::count(self.dims, &self.cells)
    }

    /// Whether the voxel containing `p` is an obstacle.
    pub fn is_obstacle_at(&self, p: impl Into<Point3<f64>>) -> bool {
        self.is_obstacle(self.lattice_index(p))
    }

    /// Where the row of lattice voxels `(y, z)` starts in the grid's layout (x
    /// fastest, as [`Self::linear`]); `None` when the row lies outside the grid (all
    /// unknown). Its first voxel is at lattice x `origin()[0]`.
    #[inline]
    pub(crate) fn row_start(&self, y: i32, z: i32) -> Option<usize> {
        self.local([self.origin[0], y, z]).map(|l| self.linear(l))
    }

    /// The raw states of every voxel (the grid's layout, x fastest). Read with
    /// [`Self::is_obstacle_raw`].
    #[inline]
    pub(crate) fn raw_cells(&self) -> &[u8] {
        &self.cells
    }

    /// The raw states of the row starting at `start` ([`Self::row_start`]). Read with
    /// [`Self::is_obstacle_raw`].
    #[inline]
    pub(crate) fn raw_row_at(&self, start: usize) -> &[u8] {
        &self.cells[start..start + self.dims[0]]
    }

    /// Whether a voxel of raw state `v` (from [`Self::raw_row_at`]; `None`: outside
    /// the grid) is an obstacle.
    #[inline]
    pub(crate) fn is_obstacle_raw(&self, v: Option<u8>) -> bool {
        match v.map(Cell::from_u8) {
            Some(Cell::Occupied) => true,
            Some(Cell::Free) => false,
            Some(Cell::Unknown) | None => self.unknown_is_occupied,
        }
    }

    /// Whether each voxel of row `(y, z)` (local indices) is an obstacle, x first.
    pub(crate) fn obstacle_row(&self, y: usize, z: usize) -> impl Iterator<Item = bool> + '_ {
        let start = self.linear([0, y, z]);
        let unknown = self.unknown_is_occupied;
        self.cells[start..start + self.dims[0]]
            .iter()
            .map(move |&v| match Cell::from_u8(v) {
                Cell::Occupied => true,
                Cell::Free => false,
                Cell::Unknown => unknown,
            })
    }

    /// The raw states, x fastest, then y, then z.
    pub fn cells(&self) -> impl ExactSizeIterator<Item = Cell> + '_ {
        self.cells.iter().map(|&v| Cell::from_u8(v))
    }

    /// Counts of occupied, free and unknown voxels inside the grid.
    pub fn counts(&self) -> CellCounts {
        let mut n = [0usize; 3];
        for &v in &self.cells {
            n[(v as usize).min(2)] += 1;
        }
        CellCounts {
            free: n[0],
            occupied: n[1],
            unknown: n[2],
        }
    }

    /// Sets every voxel whose centre lies in the closed metric box `lo..hi` to `state`
    /// (clipped to the grid). Used by the scenario generators.
    pub fn fill_box(
        &mut self,
        lo: impl Into<Point3<f64>>,
        hi: impl Into<Point3<f64>>,
        state: Cell,
    ) {
        let (lo, hi) = (lo.into(), hi.into());
        let mut a0 = [0usize; 3];
        let mut a1 = [0usize; 3];
        for a in 0..3 {
            // centre (i + 0.5) r in [lo, hi]  <=>  i in [lo/r - 0.5, hi/r - 0.5]
            let i0 = (lo[a] / self.resolution - 0.5 - 1e-9).ceil() as i64 - self.origin[a] as i64;
            let i1 =
                (hi[a] / self.resolution - 0.5 + 1e-9).floor() as i64 - self.origin[a] as i64 + 1;
            let (i0, i1) = (i0.max(0), i1.min(self.dims[a] as i64));
            if i0 >= i1 {
                return;
            }
            a0[a] = i0 as usize;
            a1[a] = i1 as usize;
        }
        for z in a0[2]..a1[2] {
            for y in a0[1]..a1[1] {
                let row = self.dims[0] * (y + self.dims[1] * z);
                let run = &mut self.cells[row + a0[0]..row + a1[0]];
                self.blocks.write_run(run, a0[0], y, z, state);
                run.fill(state as u8);
            }
        }
    }

    /// Calls `f(lattice index, centre)` for every voxel of the grid whose centre
    /// satisfies `inside`; sets those voxels to `state`. Used by the scenario generators
    /// for curved shapes (cylinders).
    pub fn fill_where(&mut self, state: Cell, mut inside: impl FnMut(Point3<f64>) -> bool) {
        for z in 0..self.dims[2] {
            for y in 0..self.dims[1] {
                for x in 0..self.dims[0] {
                    let i = [
                        self.origin[0] + x as i32,
                        self.origin[1] + y as i32,
                        self.origin[2] + z as i32,
                    ];
                    if inside(self.voxel_center(i)) {
                        let k = self.linear([x, y, z]);
                        self.blocks.write_run(&self.cells[k..=k], x, y, z, state);
                        self.cells[k] = state as u8;
                    }
                }
            }
        }
    }

    /// Every known voxel as `(lattice index, occupied)`, for writing an OctoMap.
    pub fn known_voxels(&self) -> impl Iterator<Item = ([i32; 3], bool)> + '_ {
        let [nx, ny, _] = self.dims;
        self.cells
            .iter()
            .enumerate()
            .filter(|(_, &v)| v != Cell::Unknown as u8)
            .map(move |(k, &v)| {
                let (x, y, z) = (k % nx, (k / nx) % ny, k / (nx * ny));
                (
                    [
                        self.origin[0] + x as i32,
                        self.origin[1] + y as i32,
                        self.origin[2] + z as i32,
                    ],
                    v == Cell::Occupied as u8,
                )
            })
    }
}

/// `v.floor()`, exactly, without a library call: the baseline x86-64 target has no
/// rounding instruction, so `f64::floor` is a call there, and the lattice lookups of
/// the distance field and the exact searches make millions of them. Where `floor`
/// gives `-0.0` this may give `+0.0`; every caller casts the result to an integer or
/// adds to it, which cannot tell them apart.
#[inline]
pub(crate) fn floor(v: f64) -> f64 {
    // Below 2^52 in magnitude the cast truncates exactly; truncation is the floor
    // except below zero off the integers.
    if v.abs() < 4_503_599_627_370_496.0 {
        let t = v as i64 as f64;
        if t > v {
            t - 1.0
        } else {
            t
        }
    } else {
        v.floor()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `floor` is `f64::floor` up to the sign of a zero, everywhere.
    #[test]
    fn floor_matches_the_library() {
        let same = |v: f64| {
            let (a, b) = (floor(v), v.floor());
            assert!(a == b || (a.is_nan() && b.is_nan()), "{v}: {a} vs {b}");
        };
        let big = 4_503_599_627_370_496.0f64;
        for v in [
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            -1e-300,
            1e-300,
            2.5,
            -2.5,
            big,
            -big,
            big - 0.5,
            -(big - 0.5),
            big * 4.0,
            f64::MAX,
            f64::MIN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            -0.999_999_999_999_999_9,
            1.0 - f64::EPSILON,
        ] {
            same(v);
        }
        let mut x = 0x2545_f491_4f6c_dd1du64;
        for _ in 0..100_000 {
            // xorshift: bit patterns of every magnitude and sign.
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            same(f64::from_bits(x));
            same((x % 2_000_001) as f64 / 1000.0 - 1000.0);
        }
    }

    #[test]
    fn the_obstacle_summary_counts_every_write() {
        let mut g = Grid::new(0.1, [-3, 2, 0], [13, 9, 7], Cell::Unknown, true).unwrap();
        let recount = |g: &Grid| ObstacleBlocks::count(g.dims, &g.cells);
        assert_eq!(g.blocks, recount(&g));
        g.fill_box([-0.2, 0.3, 0.0], [0.8, 1.0, 0.6], Cell::Free);
        assert_eq!(g.blocks, recount(&g));
        g.fill_where(Cell::Occupied, |p| p.x > 0.5 && p.z < 0.3);
        g.set([0, 4, 3], Cell::Occupied);
        g.set([0, 4, 3], Cell::Free);
        g.set([-3, 2, 0], Cell::Free);
        assert_eq!(g.blocks, recount(&g));
        // Carved free and cleared again, a block inside the grid proves itself empty.
        g.fill_box([-0.3, 0.2, 0.0], [1.0, 1.1, 0.7], Cell::Free);
        assert_eq!(g.blocks, recount(&g));
        assert!(!g.block_may_hold_obstacle([0, 0, 0]));
        assert!(
            g.block_may_hold_obstacle([3, 0, 0]),
            "it reaches beyond the grid"
        );
        assert!(
            g.block_may_hold_obstacle([-1, 0, 0]),
            "beyond the grid is unknown"
        );
    }

    #[test]
    fn lattice_and_bounds() {
        let g = Grid::new(0.1, [-5, 0, 2], [10, 4, 3], Cell::Free, true).unwrap();
        let (lo, hi) = g.bounds();
        assert!((lo[0] + 0.5).abs() < 1e-12 && (hi[0] - 0.5).abs() < 1e-12);
        assert!((lo[2] - 0.2).abs() < 1e-12 && (hi[2] - 0.5).abs() < 1e-12);
        assert_eq!(g.lattice_index([-0.45, 0.05, 0.25]), [-5, 0, 2]);
        let c = g.voxel_center([-5, 0, 2]);
        assert!((c[0] + 0.45).abs() < 1e-12 && (c[2] - 0.25).abs() < 1e-12);
        assert_eq!(g.cell([-6, 0, 2]), Cell::Unknown);
        assert!(g.is_obstacle([-6, 0, 2]));
        assert!(!g.is_obstacle([-5, 0, 2]));
    }

    #[test]
    fn pruned_leaves_expand() {
        // One 0.4 m free leaf (4x4x4 voxels) and one occupied voxel inside the box.
        let leaves = vec![
            ([0.2, 0.2, 0.2], 0.4, false),
            ([0.55, 0.05, 0.05], 0.1, true),
        ];
        let g = Grid::from_leaves(0.1, [0.0; 3], [0.6, 0.4, 0.4], leaves, true).unwrap();
        assert_eq!(g.dims(), [6, 4, 4]);
        let c = g.counts();
        assert_eq!(c.free, 64);
        assert_eq!(c.occupied, 1);
        assert_eq!(c.unknown, 6 * 16 - 64 - 1);
        assert_eq!(g.cell([5, 0, 0]), Cell::Occupied);
        assert_eq!(g.cell([3, 3, 3]), Cell::Free);
        assert_eq!(g.cell([4, 3, 3]), Cell::Unknown);
    }

    #[test]
    fn octree_round_trip() {
        let mut g = Grid::new(0.1, [-3, 0, 1], [7, 5, 4], Cell::Free, true).unwrap();
        g.fill_box([-0.3, 0.0, 0.1], [0.05, 0.2, 0.3], Cell::Occupied);
        g.set([0, 4, 4], Cell::Unknown);
        g.set([3, 4, 4], Cell::Unknown);
        let t = g.to_octree().unwrap();
        let h = Grid::from_octree(&t, true).unwrap();
        assert_eq!(h.origin(), g.origin());
        assert_eq!(h.dims(), g.dims());
        assert!(h.cells().eq(g.cells()));
        let (lo, hi) = h.bounds();
        assert!((lo[0] + 0.3).abs() < 1e-9 && (hi[2] - 0.5).abs() < 1e-9);
    }

    #[test]
    fn bad_input_is_an_error() {
        assert!(matches!(
            Grid::new(0.0, [0; 3], [1; 3], Cell::Free, true),
            Err(GridError::Resolution(_))
        ));
        assert!(matches!(
            Grid::new(0.1, [0; 3], [0, 1, 1], Cell::Free, true),
            Err(GridError::TooLarge { .. })
        ));
        assert!(matches!(
            Grid::from_leaves(0.1, [0.0; 3], [1e9, 1e9, 1e9], Vec::new(), true),
            Err(GridError::TooLarge { .. })
        ));
        assert!(matches!(
            Grid::from_leaves(0.1, [0.0; 3], [f64::NAN, 1.0, 1.0], Vec::new(), true),
            Err(GridError::Bounds(..))
        ));
    }

    #[test]
    fn error_messages_say_what_is_wrong() {
        assert_eq!(
            GridError::Resolution(-1.5).to_string(),
            "resolution -1.5 is not a positive number"
        );
        assert_eq!(
            GridError::Empty.to_string(),
            "the map has no known (occupied or free) voxel"
        );
        assert_eq!(
            GridError::Bounds([0.0; 3], [1.0, 2.0, f64::NAN]).to_string(),
            "bounds [0.0, 0.0, 0.0] .. [1.0, 2.0, NaN] are not a finite box"
        );
        assert_eq!(
            GridError::TooLarge { dims: [1, 2, 3] }.to_string(),
            format!("the bounding box needs 1 x 2 x 3 voxels, more than {MAX_CELLS}")
        );
    }

    #[test]
    fn fill_box_uses_centres() {
        let mut g = Grid::new(0.1, [0; 3], [10, 10, 10], Cell::Free, true).unwrap();
        g.fill_box([0.2, 0.0, 0.0], [0.4, 1.0, 1.0], Cell::Occupied);
        // Centres 0.25 and 0.35 are inside [0.2, 0.4].
        assert_eq!(g.counts().occupied, 200);
        assert_eq!(g.cell([2, 0, 0]), Cell::Occupied);
        assert_eq!(g.cell([4, 0, 0]), Cell::Free);
        let known: Vec<_> = g.known_voxels().filter(|v| v.1).collect();
        assert_eq!(known.len(), 200);
    }
}
