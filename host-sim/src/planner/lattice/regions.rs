//! The free regions of the map for the head's sphere, labelled once per map: a proof
//! in microseconds that start and goal are separated, whatever the map's size.
//!
//! Flooding the half-cell lattice to prove "no route" costs time in the size of the
//! region flooded (seconds for a sealed room at 0.05 m). Instead, setup labels the
//! connected regions of a coarser, RELAXED voxel set once, and a query compares labels.
//!
//! # Why a separation of voxels proves a separation of lattice points
//! Give each half-cell lattice point (index `i` per axis) to the voxel `floor(i / 2)`:
//! the voxel whose closed cube holds it, `|p - c| <= r sqrt(3) / 2` from its centre
//! `c`. A lattice point `p` free for the sphere (distance `d(p) > R` to every obstacle
//! cube) therefore lies in a voxel that
//! - is not itself an obstacle (else `d(p) = 0`), and
//! - has `d(c) > R - r sqrt(3) / 2` (the distance is 1-Lipschitz).
//!
//! Call such voxels RELAXED-FREE. Lattice neighbours differ by at most one index per
//! axis, so their voxels are equal or 26-neighbours. Hence a lattice route maps to a
//! 26-connected walk through relaxed-free voxels, and when the start's lattice
//! anchors and the goal's lie in different 26-connected regions of relaxed-free
//! voxels, no lattice route joins them. The converse does not hold (the relaxation can
//! join what the lattice keeps apart); then the lattice search decides as before.
//!
//! # How it is labelled
//! Relaxed-free voxels form runs along x in each (y, z) row. A run touches a run of a
//! neighbouring row (`dy, dz` in -1..=1) when their x-ranges overlap or meet
//! diagonally; a union-find over the runs joins them, row after row, looking back at
//! the four neighbouring rows already seen. The work and memory follow the runs, not
//! the voxels: a large open map is a few runs per row.

use rayon::prelude::*;

use super::clearance::exact_clearance;
use crate::map::distance::DistanceField;

/// Allowance for rounding in the relaxed test (m): relaxing further is always safe.
const ROUND_EPS: f64 = 1e-6;

/// Connected regions of relaxed-free voxels, labelled per run.
#[derive(Clone, Debug)]
pub struct Regions {
    dims: [usize; 3],
    /// Per row (`y + dims[1] z`), the index of its first run; one entry more at the end.
    row_start: Vec<u32>,
    /// Runs of relaxed-free voxels along x, `[x0, x1]` inclusive, local indices.
    runs: Vec<[u32; 2]>,
    /// Region of each run (the smallest run index in it).
    region: Vec<u32>,
    /// Voxels per region, indexed by the region's run index.
    size: Vec<u64>,
}

impl Regions {
    /// Labels the regions of `field`'s grid for a sphere of radius `radius` (m).
    pub fn label(field: &DistanceField, radius: f64) -> Self {
        let g = field.grid();
        let dims = g.dims();
        let r = g.resolution();
        let threshold = radius - r * 3f64.sqrt() / 2.0 - ROUND_EPS;
        // Runs of every row, rows in parallel by z-slab.
        let slabs: Vec<Vec<Vec<[u32; 2]>>> = (0..dims[2])
            .into_par_iter()
            .map(|z| {
                (0..dims[1])
                    .map(|y| row_runs(field, [y, z], threshold))
                    .collect()
            })
            .collect();
        let mut row_start = Vec::with_capacity(dims[1] * dims[2] + 1);
        let mut runs = Vec::new();
        for row in slabs.into_iter().flatten() {
            row_start.push(runs.len() as u32);
            runs.extend(row);
        }
        row_start.push(runs.len() as u32);
        let mut regions = Self {
            dims,
            row_start,
            runs,
            region: Vec::new(),
            size: Vec::new(),
        };
        regions.join_rows();
        regions
    }

    /// The runs of row `(y, z)`.
    fn row(&self, y: usize, z: usize) -> std::ops::Range<usize> {
        let k = y + self.dims[1] * z;
        self.row_start[k] as usize..self.row_start[k + 1] as usize
    }

    /// Union-find over the runs: each row is joined to the four neighbouring rows
    /// seen before it; then every run gets its region and every region its size.
    fn join_rows(&mut self) {
        let mut parent: Vec<u32> = (0..self.runs.len() as u32).collect();
        let [_, ny, nz] = self.dims;
        for z in 0..nz {
            for y in 0..ny {
                let here = self.row(y, z);
                let earlier = [(-1, 0), (-1, -1), (0, -1), (1, -1)];
                for (dy, dz) in earlier {
                    let (yy, zz) = (y as i64 + dy, z as i64 + dz);
                    if yy < 0 || zz < 0 || yy >= ny as i64 {
                        continue;
                    }
                    let there = self.row(yy as usize, zz as usize);
                    self.join_touching(&mut parent, here.clone(), there);
                }
            }
        }
        let mut size = vec![0u64; self.runs.len()];
        let region: Vec<u32> = (0..self.runs.len())
            .map(|i| {
                let root = find(&mut parent, i as u32);
                size[root as usize] += (self.runs[i][1] - self.runs[i][0] + 1) as u64;
                root
            })
            .collect();
        self.region = region;
        self.size = size;
    }

    /// Joins every run of `a` with every run of `b` it touches (x-ranges overlapping
    /// or meeting diagonally); both lists are sorted and disjoint within themselves.
    fn join_touching(
        &self,
        parent: &mut [u32],
        a: std::ops::Range<usize>,
        b: std::ops::Range<usize>,
    ) {
        let (mut i, mut j) = (a.start, b.start);
        while i < a.end && j < b.end {
            let (ra, rb) = (self.runs[i], self.runs[j]);
            if ra[0] <= rb[1] + 1 && rb[0] <= ra[1] + 1 {
                union(parent, i as u32, j as u32);
            }
            // Advance the run that ends first: it cannot touch anything further on.
            if ra[1] < rb[1] {
                i += 1;
            } else {
                j += 1;
            }
        }
    }

    /// The region holding voxel `v` (local indices), `None` when it is not
    /// relaxed-free.
    pub fn region_of(&self, v: [usize; 3]) -> Option<u32> {
        if (0..3).any(|a| v[a] >= self.dims[a]) {
            return None;
        }
        let row = self.row(v[1], v[2]);
        let runs = &self.runs[row.clone()];
        let x = v[0] as u32;
        let k = runs.partition_point(|r| r[1] < x);
        (k < runs.len() && runs[k][0] <= x).then(|| self.region[row.start + k])
    }

    /// Voxels in region `region`.
    pub fn size(&self, region: u32) -> u64 {
        self.size[region as usize]
    }

    /// Runs stored (the labelling's memory follows them).
    pub fn run_count(&self) -> usize {
        self.runs.len()
    }
}

/// The relaxed-free runs of row `(y, z)` (see the module docs).
fn row_runs(field: &DistanceField, [y, z]: [usize; 2], threshold: f64) -> Vec<[u32; 2]> {
    let g = field.grid();
    let r = g.resolution();
    let o = g.origin();
    // The field's bound is at most r (sqrt(3) - 1) / 2 below the true distance of a
    // centre (the nearest obstacle centre's cube is within sqrt(n) - 1/2 voxels).
    let slack = r * (3f64.sqrt() - 1.0) / 2.0 + ROUND_EPS;
    let mut runs = Vec::new();
    let mut open: Option<u32> = None;
    let row = g.obstacle_row(y, z).zip(field.row_bounds(y, z));
    for (x, (obstacle, &lb)) in row.enumerate() {
        let lb = lb as f64;
        let free = !obstacle
            && (lb > threshold
                || (lb + slack > threshold && {
                    let i = [o[0] + x as i32, o[1] + y as i32, o[2] + z as i32];
                    let c = g.voxel_center(i);
                    exact_clearance(field, c, threshold, threshold + r) > threshold
                }));
        match (free, open) {
            (true, None) => open = Some(x as u32),
            (false, Some(x0)) => {
                runs.push([x0, x as u32 - 1]);
                open = None;
            }
            _ => {}
        }
    }
    if let Some(x0) = open {
        runs.push([x0, g.dims()[0] as u32 - 1]);
    }
    runs
}

/// The root of `i`, halving the path on the way.
fn find(parent: &mut [u32], mut i: u32) -> u32 {
    while parent[i as usize] != i {
        let p = parent[i as usize];
        parent[i as usize] = parent[p as usize];
        i = p;
    }
    i
}

/// Joins the sets of `a` and `b`; the smaller root wins, so labels are deterministic.
fn union(parent: &mut [u32], a: u32, b: u32) {
    let (ra, rb) = (find(parent, a), find(parent, b));
    if ra != rb {
        let (lo, hi) = if ra < rb { (ra, rb) } else { (rb, ra) };
        parent[hi as usize] = lo;
    }
}
