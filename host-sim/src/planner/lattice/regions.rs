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
//! - has `d(c) > R - r sqrt(3) / 2` (the distance is 1-Lipschitz), and
//! - lies in no gap of fewer than `2R / r` voxels between two obstacle voxels along
//!   an axis: the line through `p` along that axis meets both obstacle cubes (they
//!   share the voxel's extent across the axis), so `d(p)` is at most half the gap.
//!
//! The last rule closes the slits a unit cannot pass (a gap of 0.25 m at 0.1 m holds
//! voxel centres 0.125 m from both sides, which the second rule alone cannot rule
//! out for a sphere of 0.15 m); it is asked only of voxels whose field bound is
//! below `R`, the band where the second rule may be loose.
//!
//! The labelling only ever needs MORE free voxels than that (more voxels can only
//! join regions), so it needs no exact measure: a voxel counts as relaxed-free when it
//! is not an obstacle and the distance field's bound at its centre, plus the most the
//! bound can lose there (`r (sqrt(3) - 1) / 2`: the nearest obstacle centre's cube is
//! within `sqrt(n) - 1/2` voxels), exceeds `R - r sqrt(3) / 2`.
//!
//! Call such voxels RELAXED-FREE. Lattice neighbours differ by at most one index per
//! axis, so their voxels are equal or 26-neighbours. Hence a lattice route maps to a
//! 26-connected walk through relaxed-free voxels, and when the start's lattice
//! anchors and the goal's lie in different 26-connected regions of relaxed-free
//! voxels, no lattice route joins them. The converse does not hold (the relaxation can
//! join what the lattice keeps apart); then the lattice search decides as before.
//!
//! # How it is labelled
//! Relaxed-free voxels form runs along x in each (y, z) row, cut where they cross a
//! block boundary (see below) into SEGMENTS. A segment touches a segment of a
//! neighbouring row (`dy, dz` in -1..=1) when their x-ranges overlap or meet
//! diagonally; a union-find over the segments joins them, row after row, looking back
//! at the four neighbouring rows already seen. The work and memory follow the
//! segments, not the voxels: a large open map is a few per row and block.
//!
//! # The coarse graph
//! The same sweep builds a coarse graph for the A*'s heuristic ([`super::guide`]):
//! the box is cut into blocks of `b >= 0.4 m` (at most about 100 000 of them), and a
//! second union-find joins touching segments only within a block. Each of its sets is
//! a NODE, a connected piece of free space in one block; two nodes are joined where
//! their segments touch across a block boundary. Unlike a grid of block centres, this
//! graph sees every opening the voxels see (a door in a thin wall included) and never
//! steps through a wall: its edges are voxel adjacencies.

use std::time::Instant;

use rayon::prelude::*;

use crate::map::distance::DistanceField;
use crate::map::grid::Grid;
use crate::planner::expired;

/// Allowance for rounding in the relaxed test (m): relaxing further is always safe.
const ROUND_EPS: f64 = 1e-6;

/// Most blocks over the map's box (the block edge grows to stay below).
///
/// Tuning left a constant: it bounds the coarse graph's memory and labelling time on
/// the largest maps (docs/promises.md), which a settings file should not lift; the
/// smallest block is the setting `planner::LatticeSettings::min_block`.
const MAX_BLOCKS: f64 = 100_000.0;

/// One slab's union-find ([`Regions::join_rows`]).
struct Slab {
    /// Its first segment.
    first: usize,
    /// Parents of its segments, by index from `first`.
    parent: Vec<u32>,
    /// Touching pairs within a block that reach into the slab before.
    back: Vec<(u32, u32)>,
    /// Touching pairs across blocks.
    across: Vec<(u32, u32)>,
}

/// Connected regions of relaxed-free voxels, and the coarse graph over them.
#[derive(Clone, Debug)]
pub struct Regions {
    dims: [usize; 3],
    /// Block edge of the coarse graph, in voxels.
    block: u32,
    /// Per row (`y + dims[1] z`), the index of its first segment; one entry more.
    row_start: Vec<u32>,
    /// Segments: runs of relaxed-free voxels along x, cut where they cross a block
    /// boundary; `[x0, x1]` inclusive, local indices.
    segs: Vec<[u32; 2]>,
    /// Region of each coarse node (the smallest node index in it).
    region: Vec<u32>,
    /// Voxels per region, indexed by the region's node index.
    size: Vec<u64>,
    /// Coarse node of each segment: the segments of one block that are connected
    /// within it.
    node: Vec<u32>,
    /// The coarse graph (see [`CoarseGraph`]).
    coarse: CoarseGraph,
}

/// The coarse graph: one node per connected piece of relaxed-free voxels in a block,
/// an edge where two pieces of neighbouring blocks touch.
#[derive(Clone, Debug, Default)]
pub struct CoarseGraph {
    /// Mean position of each node's voxel centres (m).
    pub centre: Vec<[f64; 3]>,
    /// Per node, the index of its first edge in `edges`; one entry more.
    pub edge_start: Vec<u32>,
    /// Edges: the neighbour and the distance between the two centres (m).
    pub edges: Vec<(u32, f32)>,
}

impl Regions {
    /// Labels the regions of `field`'s grid for a sphere of radius `radius` (m), in
    /// blocks of at least `min_block` (m, `planner::LatticeSettings::min_block`);
    /// `None` when `deadline` passes first (checked every plane of every pass, so a
    /// labelling stops within a plane's work of it).
    pub fn label(
        field: &DistanceField,
        radius: f64,
        min_block: f64,
        deadline: Option<Instant>,
    ) -> Option<Self> {
        let g = field.grid();
        let dims = g.dims();
        let r = g.resolution();
        let volume: f64 = dims.iter().map(|&d| d as f64 * r).product();
        let block_m = min_block.max((volume / MAX_BLOCKS).cbrt());
        let block = ((block_m / r).round() as u32).max(1);
        // Segments of every row, rows in parallel by z-slab.
        let slabs: Vec<Vec<Vec<[u32; 2]>>> = (0..dims[2])
            .into_par_iter()
            .map(|z| {
                let plane = (0..dims[1]).map(|y| cut(row_runs(field, [y, z], radius), block));
                (!expired(deadline)).then(|| plane.collect())
            })
            .collect::<Option<_>>()?;
        let mut row_start = Vec::with_capacity(dims[1] * dims[2] + 1);
        let mut segs = Vec::new();
        for row in slabs.into_iter().flatten() {
            row_start.push(segs.len() as u32);
            segs.extend(row);
        }
        row_start.push(segs.len() as u32);
        let mut regions = Self {
            dims,
            block,
            row_start,
            segs,
            region: Vec::new(),
            size: Vec::new(),
            node: Vec::new(),
            coarse: CoarseGraph::default(),
        };
        let across = regions.join_rows(deadline)?;
        let voxels = regions.build_coarse(field, &across, deadline)?;
        regions.label_regions(&voxels);
        Some(regions)
    }

    /// The segments of row `(y, z)`.
    fn row(&self, y: usize, z: usize) -> std::ops::Range<usize> {
        let k = y + self.dims[1] * z;
        self.row_start[k] as usize..self.row_start[k + 1] as usize
    }

    /// Calls `f(i, j, same_block)` for every pair of touching segments, `i` in a row
    /// of plane `z` and `j` in the same row (the pieces of one run cut at a block
    /// boundary) or in one of the four neighbouring rows seen before it (`y - 1` in
    /// this plane, `y - 1..=y + 1` in plane `z - 1`), with whether the two share a
    /// block.
    ///
    /// Left out: a pair of rows in one block that meets only diagonally across a
    /// block boundary in x, where `i`'s run goes on across that boundary in its own
    /// row. The piece it goes on with shares a voxel's x with `j` in `j`'s block, so
    /// it is in `j`'s node, and the pair of pieces in `i`'s row gives the same edge
    /// of the coarse graph. A run cut into blocks would otherwise add two such pairs
    /// per boundary and neighbouring row, most of the pairs of an open map.
    fn touching_in(&self, z: usize, mut f: impl FnMut(usize, usize, bool)) {
        let (ny, b) = (self.dims[1], self.block);
        for y in 0..ny {
            let here = self.row(y, z);
            for i in here.start + 1..here.end {
                if self.segs[i - 1][1] + 1 == self.segs[i][0] {
                    f(i - 1, i, false);
                }
            }
            for (dy, dz) in [(-1, 0), (-1, -1), (0, -1), (1, -1)] {
                let (yy, zz) = (y as i64 + dy, z as i64 + dz);
                if yy < 0 || zz < 0 || yy >= ny as i64 {
                    continue;
                }
                let (yy, zz) = (yy as usize, zz as usize);
                let there = self.row(yy, zz);
                let same_rows = y as u32 / b == yy as u32 / b && z as u32 / b == zz as u32 / b;
                let (mut i, mut j) = (here.start, there.start);
                while i < here.end && j < there.end {
                    let (ra, rb) = (self.segs[i], self.segs[j]);
                    if ra[0] <= rb[1] + 1 && rb[0] <= ra[1] + 1 {
                        let same = same_rows && same_x_block(ra, rb, b);
                        // In one block's rows, a pair that is not in one block meets
                        // diagonally across an x boundary (see above).
                        if !(same_rows && !same && self.goes_on_to(here.clone(), i, rb)) {
                            f(i, j, same);
                        }
                    }
                    // Advance the segment that ends first: it touches nothing further.
                    if ra[1] < rb[1] {
                        i += 1;
                    } else {
                        j += 1;
                    }
                }
            }
        }
    }

    /// Whether segment `i` of `row` meets `other` (of a neighbouring row) only
    /// diagonally in x, and the next piece of its run in `row` starts (or the one
    /// before ends) at `other`'s voxel column where they meet.
    fn goes_on_to(&self, row: std::ops::Range<usize>, i: usize, other: [u32; 2]) -> bool {
        let s = self.segs[i];
        if other[0] == s[1] + 1 {
            i + 1 < row.end && self.segs[i + 1][0] == other[0]
        } else if other[1] + 1 == s[0] {
            i > row.start && self.segs[i - 1][1] == other[1]
        } else {
            false
        }
    }

    /// The first segment of plane `z` (`z = dims[2]`: the end).
    fn plane_start(&self, z: usize) -> usize {
        self.row_start[z * self.dims[1]] as usize
    }

    /// Union-find over the segments: a touching pair within one block joins a coarse
    /// node. Sets every segment's node; returns the touching pairs across blocks.
    ///
    /// Slabs of planes are joined in parallel, each in its own union-find; the pairs
    /// that reach back into the slab before are joined afterwards. The sets, and so
    /// the numbering (nodes in order of their first segment), are the same as a
    /// serial sweep's.
    /// `None` when `deadline` passes first.
    fn join_rows(&mut self, deadline: Option<Instant>) -> Option<Vec<Vec<(u32, u32)>>> {
        let nz = self.dims[2];
        let slab = nz.div_ceil(rayon::current_num_threads().max(1) * 4).max(1);
        let slabs: Vec<Slab> = (0..nz.div_ceil(slab))
            .into_par_iter()
            .map(|k| self.join_slab(k * slab, ((k + 1) * slab).min(nz), deadline))
            .collect::<Option<_>>()?;
        let mut parent = Vec::with_capacity(self.segs.len());
        let (mut back, mut across) = (Vec::new(), Vec::new());
        for s in slabs {
            parent.extend(s.parent.into_iter().map(|p| p + s.first as u32));
            back.extend(s.back);
            // Kept per slab: on a large map they are tens of millions of pairs.
            across.push(s.across);
        }
        for (i, j) in back {
            union(&mut parent, i, j);
        }
        // Coarse nodes: the roots, numbered in order.
        let n = self.segs.len();
        let mut number = vec![u32::MAX; n];
        let mut count = 0u32;
        self.node = (0..n)
            .map(|i| {
                let root = find(&mut parent, i as u32) as usize;
                if number[root] == u32::MAX {
                    number[root] = count;
                    count += 1;
                }
                number[root]
            })
            .collect();
        Some(across)
    }

    /// The union-find of the segments of planes `z0..z1` alone; `None` when
    /// `deadline` passes first.
    fn join_slab(&self, z0: usize, z1: usize, deadline: Option<Instant>) -> Option<Slab> {
        let (s0, s1) = (self.plane_start(z0), self.plane_start(z1));
        let mut slab = Slab {
            first: s0,
            parent: (0..(s1 - s0) as u32).collect(),
            back: Vec::new(),
            across: Vec::new(),
        };
        for z in z0..z1 {
            if expired(deadline) {
                return None;
            }
            self.touching_in(z, |i, j, same_block| match (same_block, j >= s0) {
                (false, _) => slab.across.push((i as u32, j as u32)),
                (true, true) => union(&mut slab.parent, (i - s0) as u32, (j - s0) as u32),
                (true, false) => slab.back.push((i as u32, j as u32)),
            });
        }
        Some(slab)
    }

    /// The regions: the connected components of the coarse graph (its nodes are
    /// connected pieces, its edges every adjacency between them), with their sizes.
    fn label_regions(&mut self, voxels: &[f64]) {
        let nodes = voxels.len();
        let mut parent: Vec<u32> = (0..nodes as u32).collect();
        for a in 0..nodes {
            let edges = self.coarse.edge_start[a] as usize..self.coarse.edge_start[a + 1] as usize;
            for &(b, _) in &self.coarse.edges[edges] {
                union(&mut parent, a as u32, b);
            }
        }
        let mut size = vec![0u64; nodes];
        self.region = (0..nodes)
            .map(|a| {
                let root = find(&mut parent, a as u32);
                size[root as usize] += voxels[a] as u64;
                root
            })
            .collect();
        self.size = size;
    }

    /// The coarse graph: node centres from the segments, edges where segments of two
    /// nodes touch across a block boundary. Returns the voxels of each node; `None`
    /// when `deadline` passes first.
    fn build_coarse(
        &mut self,
        field: &DistanceField,
        across: &[Vec<(u32, u32)>],
        deadline: Option<Instant>,
    ) -> Option<Vec<f64>> {
        let nodes = self.node.iter().map(|&k| k as usize + 1).max().unwrap_or(0);
        let mut sum = vec![[0f64; 3]; nodes];
        let mut count = vec![0f64; nodes];
        let [_, ny, nz] = self.dims;
        for z in 0..nz {
            if expired(deadline) {
                return None;
            }
            for y in 0..ny {
                for i in self.row(y, z) {
                    let [x0, x1] = self.segs[i];
                    let len = (x1 - x0 + 1) as f64;
                    let k = self.node[i] as usize;
                    let mid = (x0 + x1) as f64 / 2.0;
                    for (a, v) in [mid, y as f64, z as f64].into_iter().enumerate() {
                        sum[k][a] += v * len;
                    }
                    count[k] += len;
                }
            }
        }
        let g = field.grid();
        let (lo, _) = g.bounds();
        let r = g.resolution();
        let centre: Vec<[f64; 3]> = (0..nodes)
            .map(|k| [0, 1, 2].map(|a| lo[a] + (sum[k][a] / count[k] + 0.5) * r))
            .collect();
        // Neighbour lists; a node has a few dozen neighbours at most, and the same
        // pair comes up row after row, so a linear check dedups cheaply.
        let mut adjacent: Vec<Vec<u32>> = vec![Vec::new(); nodes];
        for &(i, j) in across.iter().flatten() {
            let (a, b) = (self.node[i as usize], self.node[j as usize]);
            if a == b {
                continue;
            }
            for (from, to) in [(a, b), (b, a)] {
                let list = &mut adjacent[from as usize];
                if list.last() != Some(&to) && !list.contains(&to) {
                    list.push(to);
                }
            }
        }
        let mut edge_start = Vec::with_capacity(nodes + 1);
        let mut edges = Vec::new();
        for (a, list) in adjacent.iter_mut().enumerate() {
            edge_start.push(edges.len() as u32);
            list.sort_unstable();
            for &b in list.iter() {
                let d = super::dist(centre[a], centre[b as usize]);
                edges.push((b, d as f32));
            }
        }
        edge_start.push(edges.len() as u32);
        self.coarse = CoarseGraph {
            centre,
            edge_start,
            edges,
        };
        Some(count)
    }

    /// The segment holding voxel `v` (local indices), when it is relaxed-free.
    fn segment_of(&self, v: [usize; 3]) -> Option<usize> {
        if (0..3).any(|a| v[a] >= self.dims[a]) {
            return None;
        }
        let row = self.row(v[1], v[2]);
        let segs = &self.segs[row.clone()];
        let x = v[0] as u32;
        let k = segs.partition_point(|r| r[1] < x);
        (k < segs.len() && segs[k][0] <= x).then_some(row.start + k)
    }

    /// The region holding voxel `v` (local indices), `None` when it is not
    /// relaxed-free.
    pub fn region_of(&self, v: [usize; 3]) -> Option<u32> {
        self.segment_of(v)
            .map(|i| self.region[self.node[i] as usize])
    }

    /// The coarse node holding voxel `v` (local indices), `None` when it is not
    /// relaxed-free.
    pub fn node_of(&self, v: [usize; 3]) -> Option<u32> {
        self.segment_of(v).map(|i| self.node[i])
    }

    /// The coarse graph.
    pub fn coarse(&self) -> &CoarseGraph {
        &self.coarse
    }

    /// Voxels in region `region`.
    pub fn size(&self, region: u32) -> u64 {
        self.size[region as usize]
    }
}

/// `runs` cut where they cross a multiple of `block` (a block boundary along x).
fn cut(runs: Vec<[u32; 2]>, block: u32) -> Vec<[u32; 2]> {
    let mut out = Vec::with_capacity(runs.len());
    for [mut x0, x1] in runs {
        while x0 / block != x1 / block {
            let end = (x0 / block + 1) * block - 1;
            out.push([x0, end]);
            x0 = end + 1;
        }
        out.push([x0, x1]);
    }
    out
}

/// Whether two touching segments lie in the same block along x. Each segment lies
/// in one block ([`cut`]), so two that share a voxel's x do; two that only meet
/// diagonally do when the voxels where they meet do. (This runs for every touching
/// pair of the map: a division per pair would cost most of the labelling.)
fn same_x_block(a: [u32; 2], b: [u32; 2], block: u32) -> bool {
    let (start, end) = (a[0].max(b[0]), a[1].min(b[1]));
    start <= end || end / block == start / block
}

/// The relaxed-free runs of row `(y, z)` for a sphere of radius `radius` (see the
/// module docs).
fn row_runs(field: &DistanceField, [y, z]: [usize; 2], radius: f64) -> Vec<[u32; 2]> {
    let g = field.grid();
    let r = g.resolution();
    let threshold = radius - r * 3f64.sqrt() / 2.0 - ROUND_EPS;
    // The field's bound is at most r (sqrt(3) - 1) / 2 below the true distance of a
    // centre (see the module docs): a voxel it cannot rule out counts as free.
    let bar = (threshold - r * (3f64.sqrt() - 1.0) / 2.0 - ROUND_EPS) as f32;
    // A voxel whose centre may lie closer than the radius is checked for a gap
    // too narrow along an axis; one whose centre is surely far enough never is.
    let sure = radius as f32;
    let need = gap_voxels(radius, r);
    let mut runs = Vec::new();
    let mut open: Option<u32> = None;
    let row = g.obstacle_row(y, z).zip(field.row_bounds(y, z));
    for (x, (obstacle, &lb)) in row.enumerate() {
        // The gap test (and its lattice index) only where the bound leaves doubt.
        let free = !obstacle
            && lb > bar
            && (lb >= sure || !too_narrow(g, g.index_of_local([x, y, z]), need));
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

/// The fewest voxels in a row, between two obstacle voxels, that can hold a centre
/// at distance `radius` or more from both: the gap must be wider than `2 radius`
/// (rounded toward keeping the gap, so that no gap is closed by rounding).
fn gap_voxels(radius: f64, r: f64) -> i32 {
    ((2.0 * radius - ROUND_EPS) / r).ceil().max(1.0) as i32
}

/// Whether voxel `at` (lattice indices) lies in a gap fewer than `need` voxels long
/// between two obstacle voxels along some axis (see the module docs: no centre in
/// it is far enough from both).
fn too_narrow(g: &Grid, at: [i32; 3], need: i32) -> bool {
    (0..3).any(|axis| {
        let mut len = 1;
        for dir in [-1, 1] {
            let mut i = at;
            loop {
                i[axis] += dir;
                if g.is_obstacle(i) {
                    break;
                }
                len += 1;
                if len >= need {
                    return false;
                }
            }
        }
        true
    })
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

#[cfg(test)]
mod tests {
    use std::collections::BTreeSet;

    use proptest::prelude::*;

    use super::*;
    use crate::map::grid::{Cell, Grid};
    use crate::map::random_grids::scatter;

    /// Edges between coarse nodes, both ways.
    type Edges = BTreeSet<(u32, u32)>;

    /// The coarse graph's edges, and those of a brute force over the voxels: every
    /// pair of 26-neighbouring relaxed-free voxels in different blocks joins their
    /// nodes, and voxels of one block that touch share a node.
    fn coarse_and_brute_force(g: Grid, radius: f64) -> (Edges, Edges) {
        let field = DistanceField::new(g);
        let min_block = crate::planner::LatticeSettings::default().min_block;
        let regions = Regions::label(&field, radius, min_block, None).expect("no deadline");
        let c = regions.coarse();
        let graph = (0..c.centre.len())
            .flat_map(|a| {
                let edges = c.edge_start[a] as usize..c.edge_start[a + 1] as usize;
                c.edges[edges].iter().map(move |&(b, _)| (a as u32, b))
            })
            .collect();
        let dims = regions.dims;
        let block = |v: [usize; 3]| v.map(|i| i as u32 / regions.block);
        let mut brute = BTreeSet::new();
        for z in 0..dims[2] {
            for y in 0..dims[1] {
                for x in 0..dims[0] {
                    let Some(a) = regions.node_of([x, y, z]) else {
                        continue;
                    };
                    for o in super::super::search::offsets26() {
                        let w = [x as i64 + o[0], y as i64 + o[1], z as i64 + o[2]];
                        if w.iter().any(|&i| i < 0) {
                            continue;
                        }
                        let w = w.map(|i| i as usize);
                        let Some(b) = regions.node_of(w) else {
                            continue;
                        };
                        if block([x, y, z]) == block(w) {
                            assert_eq!(a, b, "touching voxels of one block in two nodes");
                        } else if a != b {
                            brute.insert((a, b));
                        }
                    }
                }
            }
        }
        (graph, brute)
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 32, ..ProptestConfig::default() })]

        /// The coarse graph leaves out touching pairs of segments whose edge another
        /// pair gives. Its edges are adjacencies of the voxels, its regions are theirs,
        /// and an adjacency it lacks is bridged by a node next to both: the sweep
        /// never looks at a segment that only meets a neighbouring row's diagonally
        /// where the two rows' pieces before it end at the same voxel, and the piece
        /// before it, which shares that voxel's x with the neighbour, joins them.
        #[test]
        fn the_coarse_graph_holds_the_voxels_adjacencies_across_blocks(
            seed in 0u64..1_000_000,
            density in 0.0f64..0.7,
            radius in prop::sample::select(vec![0.0f64, 0.08, 0.15]),
        ) {
            use rand::SeedableRng;
            let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
            let mut g = Grid::new(0.1, [0; 3], [23, 13, 10], Cell::Free, true).unwrap();
            scatter(&mut g, [0; 3], [23, 13, 10], density, &mut rng);
            let (graph, brute) = coarse_and_brute_force(g, radius);
            // A dense map can leave no gap wide enough for the sphere: nothing to
            // compare; proptest draws another (and fails if it must draw too often).
            prop_assume!(!brute.is_empty());
            prop_assert!(graph.is_subset(&brute), "{:?}", graph.difference(&brute));
            let next = |a: u32| graph.range((a, 0)..(a + 1, 0)).map(|&(_, b)| b);
            for &(a, b) in brute.difference(&graph) {
                prop_assert!(next(a).any(|c| graph.contains(&(c, b))), "{a} to {b} not bridged");
            }
        }
    }

    /// Every pair of touching segments, each within one block: the shortcut agrees
    /// with dividing their starts.
    #[test]
    fn same_x_block_agrees_with_division_for_every_touching_pair() {
        let within = |block: u32| {
            (0..24u32).flat_map(move |x0| {
                (x0..24)
                    .filter(move |&x1| x0 / block == x1 / block)
                    .map(move |x1| [x0, x1])
            })
        };
        let mut pairs = 0;
        for block in 1..7 {
            for a in within(block) {
                for b in within(block).filter(|b| a[0] <= b[1] + 1 && b[0] <= a[1] + 1) {
                    assert_eq!(
                        same_x_block(a, b, block),
                        a[0] / block == b[0] / block,
                        "{a:?} {b:?} in blocks of {block}"
                    );
                    pairs += 1;
                }
            }
        }
        assert!(pairs > 1000);
    }
}
