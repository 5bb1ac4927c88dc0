//! The exact squared Euclidean distance transform between voxel centres, by the
//! separable algorithm of Felzenszwalb and Huttenlocher: one 1D lower envelope of
//! parabolas per line, along x, then y, then z (see [`super::distance`]). Each pass is
//! its own function so that [`super::distance::DistanceField::update`] can run the
//! same 1D transforms on the few lines a change reaches and get the same bits.

use rayon::prelude::*;

use super::grid::Grid;

/// The squared-EDT value meaning "no obstacle at all".
pub(crate) const NONE: u32 = u32::MAX;

/// One Felzenszwalb-Huttenlocher pass over a row `f` (squared distances, `NONE` for
/// infinity) with optional virtual obstacle sites just outside its start and its end
/// (`walls`). Writes the result into `out`. `v`, `z` are scratch of length `f.len() + 3`.
fn edt_1d(f: &[u32], walls: [bool; 2], out: &mut [u32], v: &mut [i64], z: &mut [f64]) {
    let n = f.len() as i64;
    // Sites are positions q in -1..=n (the ends only with walls) and f(q) finite.
    let wall = |w: bool| if w { 0 } else { NONE };
    let fq = |q: i64| -> u32 {
        if q < 0 {
            wall(walls[0])
        } else if q >= n {
            wall(walls[1])
        } else {
            f[q as usize]
        }
    };
    let mut k: usize = 0;
    let mut have = false;
    for q in -1..=n {
        let fv = fq(q);
        if fv == NONE {
            continue;
        }
        if !have {
            v[0] = q;
            z[0] = f64::NEG_INFINITY;
            z[1] = f64::INFINITY;
            have = true;
            continue;
        }
        let val = fv as f64 + (q * q) as f64;
        let s = loop {
            let p = v[k];
            let s = (val - (fq(p) as f64 + (p * p) as f64)) / (2 * (q - p)) as f64;
            // z[0] is -infinity, so this stops at k = 0 at the latest.
            if s <= z[k] {
                k -= 1;
            } else {
                break s;
            }
        };
        k += 1;
        v[k] = q;
        z[k] = s;
        z[k + 1] = f64::INFINITY;
    }
    if !have {
        out.fill(NONE);
        return;
    }
    let mut k = 0usize;
    for q in 0..n {
        while z[k + 1] < q as f64 {
            k += 1;
        }
        let p = v[k];
        let d = (q - p) * (q - p) + fq(p) as i64;
        out[q as usize] = d.min(NONE as i64 - 1) as u32;
    }
}

/// Exact squared EDT (voxel units) of the grid's obstacles, `NONE` where there is no
/// obstacle at all. Layout as the grid's cells (x fastest).
pub(crate) fn squared_edt(grid: &Grid) -> Vec<u32> {
    let walls = grid.unknown_is_occupied();
    let mut d = pass_x(grid);
    pass_y(&mut d, grid.dims(), walls);
    pass_z(&mut d, grid.dims(), walls);
    d
}

/// The 1D input of a voxel: 0 for an obstacle, `NONE` otherwise.
#[inline]
pub(crate) fn site(obstacle: bool) -> u32 {
    if obstacle {
        0
    } else {
        NONE
    }
}

/// The x pass: per voxel, the squared distance along its row to the row's nearest
/// obstacle voxel (or wall). The passes are separable, so each runs its 1D transforms
/// in parallel (rayon), every thread with its own scratch.
pub(crate) fn pass_x(grid: &Grid) -> Vec<u32> {
    let [nx, ny, nz] = grid.dims();
    let walls = grid.unknown_is_occupied();
    let mut d: Vec<u32> = vec![NONE; nx * ny * nz];
    d.par_chunks_exact_mut(nx).enumerate().for_each_init(
        || Scratch::new(nx),
        |s, (k, r)| {
            for (c, obstacle) in r.iter_mut().zip(grid.obstacle_row(k % ny, k / ny)) {
                *c = site(obstacle);
            }
            s.transform(r, walls);
        },
    );
    d
}

/// The y pass over the x pass's output `d` (grid of `dims`), in place: stride nx inside
/// each z slab; slabs in parallel.
pub(crate) fn pass_y(d: &mut [u32], dims: [usize; 3], walls: bool) {
    let [nx, ny, _] = dims;
    d.par_chunks_exact_mut(nx * ny).for_each_init(
        || Scratch::new(ny),
        |s, slab| {
            for x in 0..nx {
                s.transform_strided(slab, x, nx, ny, walls);
            }
        },
    );
}

/// The z pass over the y pass's output `d`, in place: stride nx * ny. Columns of
/// different y never share a cell, so each y is a task writing only its own cells
/// (see `Columns`); 64 columns at a time, copied out by rows, for locality.
pub(crate) fn pass_z(d: &mut [u32], dims: [usize; 3], walls: bool) {
    let [nx, ny, nz] = dims;
    let plane = nx * ny;
    let cols = Columns(d.as_mut_ptr(), d.len());
    (0..ny).into_par_iter().for_each_init(
        || (Scratch::new(nz), vec![0u32; nz * BLOCK]),
        |(s, block), y| {
            for x0 in (0..nx).step_by(BLOCK) {
                let w = BLOCK.min(nx - x0);
                // SAFETY: cells `x + nx y + plane z` for this task's `y` are written
                // by this task only, and every index is below `d.len()`.
                unsafe { cols.transform_block(s, block, x0 + nx * y, w, plane, nz, walls) };
            }
        },
    );
}

/// Scratch space of the 1D transform for lines of up to `n` cells.
pub(crate) struct Scratch {
    /// The input line.
    pub(crate) row: Vec<u32>,
    /// The transformed line.
    pub(crate) out: Vec<u32>,
    v: Vec<i64>,
    z: Vec<f64>,
}

impl Scratch {
    pub(crate) fn new(n: usize) -> Self {
        Self {
            row: vec![0; n],
            out: vec![0; n],
            v: vec![0; n + 3],
            z: vec![0.0; n + 4],
        }
    }

    /// The 1D transform of `row[..n]` into `out[..n]`.
    pub(crate) fn run(&mut self, n: usize, walls: bool) {
        self.run_part(n, [walls; 2]);
    }

    /// [`Self::run`] of a part of a line: a wall just before its start and just after
    /// its end only where `walls` says (the part reaches that end of the line, whose
    /// walls are on).
    pub(crate) fn run_part(&mut self, n: usize, walls: [bool; 2]) {
        let (row, out) = (&self.row[..n], &mut self.out[..n]);
        edt_1d(row, walls, out, &mut self.v, &mut self.z);
    }

    /// The 1D transform of the contiguous line `line`, in place.
    fn transform(&mut self, line: &mut [u32], walls: bool) {
        let n = line.len();
        self.row[..n].copy_from_slice(line);
        self.run(n, walls);
        line.copy_from_slice(&self.out[..n]);
    }

    /// The 1D transform of the `n` cells `first + k stride` of `cells`, in place.
    fn transform_strided(
        &mut self,
        cells: &mut [u32],
        first: usize,
        stride: usize,
        n: usize,
        walls: bool,
    ) {
        for k in 0..n {
            self.row[k] = cells[first + k * stride];
        }
        self.run(n, walls);
        for k in 0..n {
            cells[first + k * stride] = self.out[k];
        }
    }
}

/// The field's cells, shared by the z pass's tasks, each of which touches only the
/// columns of its own y.
#[derive(Clone, Copy)]
struct Columns(*mut u32, usize);

// SAFETY: the tasks that share it write disjoint cells (see `pass_z`).
unsafe impl Send for Columns {}
unsafe impl Sync for Columns {}

/// Columns the z pass copies out together.
const BLOCK: usize = 64;

impl Columns {
    /// The 1D transforms of the `w` columns starting at `first` (cells
    /// `first + j + k stride`, `j < w`, `k < n`), in place, through `block`.
    ///
    /// # Safety
    /// No other thread may touch these cells meanwhile, and they must all be below
    /// the length.
    #[allow(clippy::too_many_arguments)]
    unsafe fn transform_block(
        &self,
        s: &mut Scratch,
        block: &mut [u32],
        first: usize,
        w: usize,
        stride: usize,
        n: usize,
        walls: bool,
    ) {
        debug_assert!(n == 0 || first + w - 1 + (n - 1) * stride < self.1);
        for k in 0..n {
            let src = std::slice::from_raw_parts(self.0.add(first + k * stride), w);
            block[k * BLOCK..k * BLOCK + w].copy_from_slice(src);
        }
        for j in 0..w {
            for k in 0..n {
                s.row[k] = block[k * BLOCK + j];
            }
            s.run(n, walls);
            for k in 0..n {
                block[k * BLOCK + j] = s.out[k];
            }
        }
        for k in 0..n {
            let dst = std::slice::from_raw_parts_mut(self.0.add(first + k * stride), w);
            dst.copy_from_slice(&block[k * BLOCK..k * BLOCK + w]);
        }
    }
}
