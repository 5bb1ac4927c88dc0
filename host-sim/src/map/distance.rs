//! A Euclidean distance field over a [`Grid`]'s obstacles, with queries that are a
//! PROVEN LOWER BOUND on the distance from a point to the nearest obstacle cube.
//!
//! # What is computed
//! Obstacles are the closed voxel cubes (edge `r`, the resolution) of occupied voxels
//! and, when unknown space counts as occupied, of unknown voxels, including every
//! voxel outside the grid. The exact squared Euclidean distance transform (EDT) between
//! voxel CENTRES is computed in linear time by the separable algorithm of Felzenszwalb
//! and Huttenlocher ("Distance Transforms of Sampled Functions", 2012): one 1D
//! lower-envelope-of-parabolas pass per axis. With unknown space occupied, the space
//! outside the grid enters each 1D pass as two virtual obstacle sites just outside the
//! row, which is exact: the nearest outside voxel to any grid voxel is the one straight
//! across the nearest face.
//!
//! # From centre distances to a bound on cube distances
//! Let `c` be a voxel centre and `n` the EDT value at `c` in voxel units: every obstacle
//! centre `o` has `o - c = r k` with integer `k`, `|k|^2 >= n`. The distance from `c` to
//! the cube around `o` is exactly `r g(k)`, `g(k) = sqrt(sum over k_i != 0 of (|k_i| - 1/2)^2)`
//! (per axis, the nearest point of the cube is its face half a voxel towards `c`). So
//!
//! `d(c, obstacles) >= r G(n)`, `G(n) = min { g(k) : k integer, |k|^2 >= n }`,
//!
//! the best bound that knowing only `n` allows. `G` is tabulated once for `n < 4096` by
//! enumerating `k` (with `|k_i| <= 65`, enough: a `k` with a larger component has
//! `g >= 65.5`, above `G(n) <= ceil(sqrt(n)) - 1/2 <= 63.5`); above the table,
//! `G(n) >= sqrt(n) - sqrt(3)/2` (triangle inequality: `|k| <= g(k) + |(1/2, 1/2, 1/2)|`).
//! This improves on the plain `sqrt(n) - sqrt(3)/2` near obstacles, where it matters:
//! `G(1) = 0.5` instead of `0.13`, `G(4) = 1.5` instead of `1.13`.
//!
//! The field stores `r G(n)` per voxel, rounded DOWN to `f32`. The distance to the
//! obstacle set is 1-Lipschitz, so for any point `p` and any voxel centre `c`:
//!
//! `d(p, obstacles) >= r G(n_c) - |p - c|`,
//!
//! and [`DistanceField::clearance`] takes the best of this over the eight voxel centres
//! around `p` (clamped into the grid for points outside it), minus a `1e-9` m rounding
//! allowance. In the worst case this is `EDT - r sqrt(3)/2 - r sqrt(3)/2`, the bound of
//! the issue; in front of a flat wall it is exact. The property test `lower_bound_holds_against_brute_force` checks it.
//!
//! # Outside the grid
//! With unknown space occupied, a point outside the grid is inside an obstacle: its
//! clearance is 0. With unknown space free, outside is free and the bound above still
//! holds with the nearest grid voxel's centre (the triangle inequality works with any
//! centre). Unit centres must be inside the bounding box anyway (checked separately).
//!
//! # Updates
//! [`DistanceField::update`] changes voxels of the grid and redoes the transform only
//! on the lines the change reaches, keeping the x and y passes for that (see the
//! `update` module and docs/maps.md); the result equals [`DistanceField::new`] of the
//! changed grid to the bit.

use std::sync::OnceLock;

use nalgebra::Point3;

use super::edt::{squared_edt, NONE};
use super::grid::Grid;

mod update;
pub use update::{UpdateError, UpdateStats};

/// Size of the exact `G(n)` table.
const G_TABLE: usize = 4096;
/// Largest |k_i| enumerated to fill the table (see the module docs).
const G_ENUM: i64 = 65;
/// Allowance for `f64` rounding in the point-to-centre distance (m).
const ROUND_EPS: f64 = 1e-9;

/// `G(n)` for `n < G_TABLE` (voxel units), see the module docs.
fn g_table() -> &'static [f64] {
    static TABLE: OnceLock<Vec<f64>> = OnceLock::new();
    TABLE.get_or_init(|| {
        let max_s = (3 * G_ENUM * G_ENUM) as usize;
        let mut best = vec![f64::INFINITY; max_s + 1];
        for a in 0..=G_ENUM {
            for b in 0..=a {
                for c in 0..=b {
                    let s = (a * a + b * b + c * c) as usize;
                    let h = |k: i64| {
                        if k == 0 {
                            0.0
                        } else {
                            (k as f64 - 0.5).powi(2)
                        }
                    };
                    let g = (h(a) + h(b) + h(c)).sqrt();
                    if g < best[s] {
                        best[s] = g;
                    }
                }
            }
        }
        // Suffix minimum: G(n) = min over s >= n.
        for s in (0..max_s).rev() {
            best[s] = best[s].min(best[s + 1]);
        }
        best.truncate(G_TABLE);
        best
    })
}

/// Lower bound `G(n)` (voxel units) on the distance from a voxel centre whose squared
/// EDT value is `n` to the nearest obstacle cube.
pub fn cube_distance_bound(n: u64) -> f64 {
    if (n as usize) < G_TABLE {
        g_table()[n as usize]
    } else {
        ((n as f64).sqrt() - 0.5 * 3f64.sqrt()).max(0.0)
    }
}

/// `floor(rel)` clamped to `0..=dims - 1` (`dims >= 1`), NaN giving 0, as a local
/// index (a grid spans fewer than 2^32 voxels along every axis). The cast to `u32`
/// saturates (below 0 and NaN give 0, beyond `u32::MAX` gives that) and truncates,
/// which is the floor from 0 up: one conversion where rounding, clamping and
/// converting in `f64` took three, at a tenth of a placement's time.
#[inline]
fn clamped_floor(rel: f64, dims: usize) -> u32 {
    (rel as u32).min(dims as u32 - 1)
}

/// Rounds a non-negative `f64` down to an `f32`.
fn f32_down(v: f64) -> f32 {
    let f = v as f32;
    if (f as f64) > v && f > 0.0 {
        f32::from_bits(f.to_bits() - 1)
    } else {
        f
    }
}

/// A grid with its distance field: per voxel, a lower bound on the distance from the
/// voxel's centre to the nearest obstacle cube (see the module docs).
#[derive(Clone, Debug)]
pub struct DistanceField {
    grid: Grid,
    /// `r G(n)` per voxel (m), rounded down; `f32::INFINITY` when there is no obstacle.
    lb: Vec<f32>,
    /// Per voxel, how far along its row the nearest obstacle voxel lies
    /// ([`super::row_gaps`]): for exact distances.
    row_gaps: Vec<u8>,
    /// The grid's dimensions as `f64`, which every query compares against (the
    /// conversion costs more than the comparison).
    extent: [f64; 3],
    /// `1 / r`, which every query multiplies by: a division costs several times a
    /// product, and a coordinate a rounding apart only picks a neighbouring centre,
    /// whose bound holds as well.
    inv_r: f64,
    /// What [`Self::update`] keeps between updates (the EDT's x and y passes), built on
    /// the first update or by [`Self::prepare_updates`]; `None` until then, since it
    /// takes 8 bytes a voxel that a finished map never needs.
    kept: Option<Box<update::Kept>>,
}

/// The stored bound of a voxel whose squared EDT value is `n` at resolution `r`: the
/// one conversion both the full build and the update use, so that they agree to the bit.
#[inline]
fn stored_bound(n: u32, r: f64) -> f32 {
    if n == NONE {
        f32::INFINITY
    } else {
        f32_down(r * cube_distance_bound(n as u64))
    }
}

impl DistanceField {
    /// Builds the field of `grid` (which it keeps) in time linear in its voxels.
    pub fn new(grid: Grid) -> DistanceField {
        let r = grid.resolution();
        let d = squared_edt(&grid);
        let lb: Vec<f32> = d.into_iter().map(|n| stored_bound(n, r)).collect();
        let row_gaps = super::row_gaps::row_gaps(&grid);
        let extent = grid.dims().map(|d| d as f64);
        DistanceField {
            grid,
            lb,
            row_gaps,
            extent,
            inv_r: 1.0 / r,
            kept: None,
        }
    }

    /// The grid the field was built from.
    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// Lower bound on the distance from the centre of lattice voxel `i` to the nearest
    /// obstacle cube (m); 0 for obstacle voxels and, with unknown space occupied, outside
    /// the grid.
    pub fn voxel_clearance(&self, i: [i32; 3]) -> f64 {
        match self.grid.local(i) {
            Some(l) => self.lb[self.grid.linear(l)] as f64,
            None if self.grid.unknown_is_occupied() => 0.0,
            None => {
                let c = self.grid.voxel_center(i);
                self.clearance(c)
            }
        }
    }

    /// Coordinate `x` along axis `a` in voxels from the grid's lower face
    /// (`x (1 / r) - origin`), or `None` where the clearance is 0: `x` is NaN, or outside
    /// the grid while unknown space is occupied.
    #[inline]
    fn grid_coordinate(&self, x: f64, a: usize) -> Option<f64> {
        let (rel, open) = self.axis_coordinate(x, a);
        open.then_some(rel)
    }

    /// [`Self::grid_coordinate`] without the branch: the coordinate, and whether the
    /// clearance there may be above 0.
    #[inline]
    fn axis_coordinate(&self, x: f64, a: usize) -> (f64, bool) {
        let q = x * self.inv_r;
        let rel = q - self.grid.origin()[a] as f64;
        // For the integer bound `dims`, `rel` and `rel.floor()` fall on the same side, so
        // the fine and the coarse query agree on what is outside.
        let inside = (rel >= 0.0) & (rel < self.extent[a]);
        (
            rel,
            !q.is_nan() & (inside | !self.grid.unknown_is_occupied()),
        )
    }

    /// Squared distance along axis `a` from coordinate `x` to the centre of the voxel with
    /// local index `li` (m^2).
    #[inline]
    fn centre_gap_sq(&self, x: f64, li: f64, a: usize) -> f64 {
        let c = (self.grid.origin()[a] as f64 + li + 0.5) * self.grid.resolution();
        (x - c) * (x - c)
    }

    /// A PROVEN lower bound on the Euclidean distance from `p` to the nearest obstacle
    /// cube (m), `>= 0`; `f64::INFINITY` when the map has no obstacle. NaN input gives 0.
    ///
    /// The bound `r G(n_c) - |p - c|` holds for every voxel centre `c`; this takes the
    /// best of the eight centres around `p` (the 2 x 2 x 2 block whose centres bracket
    /// `p`, clamped into the grid), which is exact for a point between two voxel centres
    /// facing a flat wall, where a single centre would lose up to `r sqrt(3) / 2`.
    #[inline]
    pub fn clearance(&self, p: impl Into<Point3<f64>>) -> f64 {
        let p = p.into();
        self.grid_coordinates(&p)
            .map_or(0.0, |rel| self.clearance_at::<false>(&p, &rel))
    }

    /// [`Self::grid_coordinate`] of every axis of `p`; `None` where the clearance is 0.
    #[inline]
    fn grid_coordinates(&self, p: &Point3<f64>) -> Option<[f64; 3]> {
        Some([
            self.grid_coordinate(p[0], 0)?,
            self.grid_coordinate(p[1], 1)?,
            self.grid_coordinate(p[2], 2)?,
        ])
    }

    /// [`Self::clearance`] of `p`, whose grid coordinates are `rel`. With `SKIP`, a
    /// centre whose stored bound cannot beat the best so far is passed over without
    /// its square root: the same value, cheaper where the coarse query already fell
    /// short ([`Self::clearance_above`]); dearer where every centre is read
    /// ([`Self::clearance`]), as the skips branch unpredictably.
    #[inline]
    fn clearance_at<const SKIP: bool>(&self, p: &Point3<f64>, rel: &[f64; 3]) -> f64 {
        let dims = self.grid.dims();
        let mut idx = [[0usize; 2]; 3];
        let mut d2 = [[0f64; 2]; 3];
        for a in 0..3 {
            // Centres bracketing p: local indices floor(rel - 0.5) and + 1, clamped. Below
            // 0 that floor is -1 or less, and both clamp to 0.
            let x = rel[a] - 0.5;
            let lo = clamped_floor(x, dims[a]);
            let hi = if x < 0.0 {
                0
            } else {
                lo.saturating_add(1).min(dims[a] as u32 - 1)
            };
            for (j, li) in [lo, hi].into_iter().enumerate() {
                idx[a][j] = li as usize;
                d2[a][j] = self.centre_gap_sq(p[a], li as f64, a);
            }
        }
        let (sx, sxy) = (1, dims[0]);
        let sxyz = dims[0] * dims[1];
        if !SKIP {
            // The eight centres side by side (centre `c` is `i, j, k` = its bits), so
            // that their square roots pair up in vector lanes; the best of them is the
            // same in any order (no value is NaN: `p` is a number).
            let mut v = [0f64; 8];
            let mut s = [0f64; 8];
            for c in 0..8 {
                let (i, j, k) = (c & 1, (c >> 1) & 1, c >> 2);
                v[c] = self.lb[idx[0][i] * sx + idx[1][j] * sxy + idx[2][k] * sxyz] as f64;
                s[c] = d2[0][i] + (d2[1][j] + d2[2][k]);
            }
            let r = s.map(f64::sqrt);
            let best = (0..8).fold(f64::NEG_INFINITY, |b, c| b.max(v[c] - r[c]));
            return (best - ROUND_EPS).max(0.0);
        }
        let mut best = f64::NEG_INFINITY;
        for k in 0..2 {
            for j in 0..2 {
                let base = idx[1][j] * sxy + idx[2][k] * sxyz;
                let dyz = d2[1][j] + d2[2][k];
                for i in 0..2 {
                    let v = self.lb[base + idx[0][i] * sx] as f64;
                    // `v` bounds what this centre can give.
                    if SKIP && v <= best {
                        continue;
                    }
                    let b = v - (d2[0][i] + dyz).sqrt();
                    if b > best {
                        best = b;
                    }
                }
            }
        }
        (best - ROUND_EPS).max(0.0)
    }

    /// A cheaper, looser PROVEN lower bound than [`Self::clearance`]: the bound from the
    /// centre of the voxel holding `p` only (one lookup). Use it first and fall back to
    /// [`Self::clearance`] when it is not enough.
    #[inline]
    pub fn clearance_coarse(&self, p: impl Into<Point3<f64>>) -> f64 {
        let p = p.into();
        self.grid_coordinates(&p)
            .map_or(0.0, |rel| self.coarse_at(&p, &rel))
    }

    /// [`Self::clearance_coarse`] of every point of `ps`, into `out` (to the bit): the
    /// points side by side, without a branch per point, so that their lookups overlap
    /// (a placement reads one per unit).
    #[inline]
    pub fn clearance_coarse_each(&self, ps: &[Point3<f64>], out: &mut [f64]) {
        for (p, o) in ps.iter().zip(out.iter_mut()) {
            let mut open = true;
            let mut rel = [0.0; 3];
            for a in 0..3 {
                let (r, ok) = self.axis_coordinate(p[a], a);
                (rel[a], open) = (r, open & ok);
            }
            // A NaN coordinate reads voxel 0 (`clamped_floor`); its value is dropped.
            let c = self.coarse_at(p, &rel);
            *o = if open { c } else { 0.0 };
        }
    }

    /// [`Self::clearance_coarse`] of `p`, whose grid coordinates are `rel`.
    #[inline]
    fn coarse_at(&self, p: &Point3<f64>, rel: &[f64; 3]) -> f64 {
        let dims = self.grid.dims();
        let mut l = [0usize; 3];
        let mut d2 = 0.0;
        for a in 0..3 {
            let li = clamped_floor(rel[a], dims[a]);
            l[a] = li as usize;
            d2 += self.centre_gap_sq(p[a], li as f64, a);
        }
        let v = self.lb[l[0] + dims[0] * (l[1] + dims[1] * l[2])] as f64;
        (v - d2.sqrt() - ROUND_EPS).max(0.0)
    }

    /// [`Self::clearance_coarse`] when it exceeds `need`, else [`Self::clearance`]: a
    /// proven lower bound, as tight as the fine query wherever it matters for `need`.
    /// Both read the grid coordinates of `p`, computed once.
    #[inline]
    pub fn clearance_above(&self, p: impl Into<Point3<f64>>, need: f64) -> f64 {
        let p = p.into();
        // Where a coordinate says 0, both queries say 0.
        let Some(rel) = self.grid_coordinates(&p) else {
            return 0.0;
        };
        let c = self.coarse_at(&p, &rel);
        if c > need {
            c
        } else {
            self.clearance_at::<true>(&p, &rel)
        }
    }

    /// The bounds of [`Self::voxel_clearance`] along row `(y, z)` (local indices), x first.
    pub(crate) fn row_bounds(&self, y: usize, z: usize) -> &[f32] {
        let start = self.grid.linear([0, y, z]);
        &self.lb[start..start + self.grid.dims()[0]]
    }

    /// For each voxel of the row starting at `start` ([`Grid::row_start`]), how many
    /// voxels along the row its nearest obstacle voxel lies, either way
    /// ([`super::row_gaps`]; [`super::row_gaps::FAR`]: that many or more, or none).
    #[inline]
    pub(crate) fn row_gaps_at(&self, start: usize) -> &[u8] {
        &self.row_gaps[start..start + self.grid.dims()[0]]
    }

    /// [`Self::row_gaps_at`] of every voxel (the grid's layout, x fastest).
    #[inline]
    pub(crate) fn row_gaps(&self) -> &[u8] {
        &self.row_gaps
    }

    /// Bytes held by the grid and the field, with what updates keep once built.
    pub fn memory_bytes(&self) -> usize {
        let kept = self.kept.as_ref().map_or(0, |k| k.memory_bytes());
        self.lb.len() * 4 + self.row_gaps.len() + self.grid.dims().iter().product::<usize>() + kept
    }
}

#[cfg(test)]
mod tests {
    use super::super::grid::{Cell, Grid};
    use super::super::random_grids::grids;
    use super::*;
    use proptest::prelude::*;

    /// Exact distance from `p` to the closed cube of edge `r` centred at `c`.
    fn point_cube(p: [f64; 3], c: Point3<f64>, r: f64) -> f64 {
        let mut s = 0.0;
        for a in 0..3 {
            let d = ((p[a] - c[a]).abs() - 0.5 * r).max(0.0);
            s += d * d;
        }
        s.sqrt()
    }

    #[test]
    fn g_table_known_values() {
        assert_eq!(cube_distance_bound(0), 0.0);
        assert!((cube_distance_bound(1) - 0.5).abs() < 1e-12);
        assert!((cube_distance_bound(2) - 0.5f64.sqrt()).abs() < 1e-12);
        assert!((cube_distance_bound(3) - 0.75f64.sqrt()).abs() < 1e-12);
        assert!((cube_distance_bound(4) - 1.5).abs() < 1e-12);
        // Monotone, and above the generic bound.
        for n in 1..G_TABLE as u64 + 100 {
            if (n as usize) < G_TABLE {
                assert!(cube_distance_bound(n) >= cube_distance_bound(n - 1));
            }
            assert!(cube_distance_bound(n) >= (n as f64).sqrt() - 0.5 * 3f64.sqrt() - 1e-12);
        }
    }

    fn brute_edt(g: &Grid) -> Vec<u32> {
        let [nx, ny, nz] = g.dims();
        let o = g.origin();
        let mut obs = Vec::new();
        // Include a one-voxel shell outside when unknown counts as occupied.
        for z in -1..=nz as i32 {
            for y in -1..=ny as i32 {
                for x in -1..=nx as i32 {
                    if g.is_obstacle([o[0] + x, o[1] + y, o[2] + z]) {
                        obs.push([x, y, z]);
                    }
                }
            }
        }
        let mut out = Vec::new();
        for z in 0..nz as i32 {
            for y in 0..ny as i32 {
                for x in 0..nx as i32 {
                    let best = obs
                        .iter()
                        .map(|c| {
                            let d = [c[0] - x, c[1] - y, c[2] - z];
                            (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) as u32
                        })
                        .min()
                        .unwrap_or(NONE);
                    out.push(best);
                }
            }
        }
        out
    }

    /// A tenth of the voxels occupied, a tenth unknown.
    fn sparse(v: u8) -> Cell {
        match v % 10 {
            0 => Cell::Occupied,
            1 => Cell::Unknown,
            _ => Cell::Free,
        }
    }

    #[test]
    fn empty_map_is_infinite_or_walled() {
        let g = Grid::new(0.1, [0; 3], [5, 4, 3], Cell::Free, false).unwrap();
        let f = DistanceField::new(g.clone());
        assert_eq!(f.clearance([0.25, 0.25, 0.15]), f64::INFINITY);
        let mut g = g;
        g.set_unknown_is_occupied(true);
        let f = DistanceField::new(g);
        // Centre of voxel (2,1,1): nearest outside cube is across the x=0..? faces:
        // distances to faces: x: 0.25/0.25, y: 0.15/0.25, z: 0.15/0.15 -> 0.15.
        let c = f.clearance([0.25, 0.15, 0.15]);
        assert!(c <= 0.15 + 1e-9 && c > 0.14, "{c}");
        assert_eq!(f.clearance([-1.0, 0.1, 0.1]), 0.0);
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// The FH transform equals brute force on random small grids.
        #[test]
        fn edt_matches_brute_force(g in grids(1..9, sparse)) {
            prop_assert_eq!(squared_edt(&g), brute_edt(&g));
        }

        /// The clearance query never exceeds the true distance to the nearest obstacle cube.
        #[test]
        fn lower_bound_holds_against_brute_force(
            g in grids(1..8, sparse),
            pts in proptest::collection::vec(proptest::array::uniform3(-0.5f64..1.2), 1..40),
        ) {
            let dims = g.dims();
            let f = DistanceField::new(g.clone());
            let o = g.origin();
            let r = g.resolution();
            // Obstacle cubes: inside the grid, plus a shell wide enough to hold the
            // nearest outside cube for every test point.
            let mut cubes = Vec::new();
            for z in -8..dims[2] as i32 + 8 {
                for y in -8..dims[1] as i32 + 8 {
                    for x in -8..dims[0] as i32 + 8 {
                        let i = [o[0] + x, o[1] + y, o[2] + z];
                        if g.is_obstacle(i) {
                            cubes.push(g.voxel_center(i));
                        }
                    }
                }
            }
            for p in pts {
                let p = [p[0] + o[0] as f64 * r, p[1] + o[1] as f64 * r, p[2] + o[2] as f64 * r];
                let truth = cubes.iter().map(|&c| point_cube(p, c, r)).fold(f64::INFINITY, f64::min);
                let lb = f.clearance(p);
                prop_assert!(lb <= truth, "p {:?}: bound {} > true {}", p, lb, truth);
                let coarse = f.clearance_coarse(p);
                prop_assert!(coarse <= lb + 1e-12, "p {:?}: coarse {} > fine {}", p, coarse, lb);
                if truth.is_finite() && g.local(g.lattice_index(p)).is_some() {
                    // And it is not useless: within the worst-case slack.
                    prop_assert!(lb >= truth - 3f64.sqrt() * r - 1e-6, "p {:?}: bound {} true {}", p, lb, truth);
                }
            }
        }

        /// The queries pick their centres by integer casts; they give, to the bit, what
        /// rounding down and clamping in `f64` picks, and the batched coarse query gives
        /// what the one-point query gives, out of the grid and for NaN too.
        #[test]
        fn queries_pick_the_centres_floor_and_clamp_pick(
            g in grids(1..8, sparse),
            pts in proptest::collection::vec(proptest::array::uniform3(-0.5f64..1.2), 1..40),
            odd in proptest::array::uniform3(prop_oneof![
                Just(f64::NAN), Just(1e12), Just(-1e12), Just(0.0), -0.2f64..0.2
            ]),
        ) {
            let f = DistanceField::new(g.clone());
            let o = g.origin();
            let r = g.resolution();
            let mut ps: Vec<Point3<f64>> = pts
                .iter()
                .map(|p| Point3::from([0, 1, 2].map(|a| p[a] + o[a] as f64 * r)))
                .collect();
            ps.push(Point3::from(odd));
            // Within half a voxel of the grid's faces, where the clamps decide.
            let dims = g.dims();
            for (i, p) in pts.iter().enumerate() {
                let face = |a: usize| {
                    let low = (i >> a) & 1 == 0;
                    let side = if low { o[a] } else { o[a] + dims[a] as i32 } as f64;
                    (side + (p[a] - 0.35) / 1.7) * r
                };
                ps.push(Point3::from([0, 1, 2].map(face)));
            }
            let mut each = vec![0.0; ps.len()];
            f.clearance_coarse_each(&ps, &mut each);
            for (p, e) in ps.iter().zip(&each) {
                let (coarse, fine) = floor_and_clamp(&f, p);
                let (one, fine_q) = (f.clearance_coarse(*p), f.clearance(*p));
                prop_assert_eq!(one.to_bits(), coarse.to_bits(), "coarse at {:?}", p);
                prop_assert_eq!(e.to_bits(), coarse.to_bits(), "batched at {:?}", p);
                prop_assert_eq!(fine_q.to_bits(), fine.to_bits(), "fine at {:?}", p);
            }
        }
    }

    /// The coarse and the fine query of `p` with their centres picked by `f64::floor`
    /// and `clamp`, the sums and differences as the queries take them.
    fn floor_and_clamp(f: &DistanceField, p: &Point3<f64>) -> (f64, f64) {
        let Some(rel) = f.grid_coordinates(p) else {
            return (0.0, 0.0);
        };
        let dims = f.grid.dims();
        let at = |l: [f64; 3]| {
            let l = l.map(|v| v as usize);
            f.lb[l[0] + dims[0] * (l[1] + dims[1] * l[2])] as f64
        };
        let clamp = |v: f64, a: usize| v.clamp(0.0, f.extent[a] - 1.0);
        let l = [0, 1, 2].map(|a| clamp(rel[a].floor(), a));
        let d2 = (0..3).fold(0.0, |s, a| s + f.centre_gap_sq(p[a], l[a], a));
        let coarse = (at(l) - d2.sqrt() - ROUND_EPS).max(0.0);
        let lo = [0, 1, 2].map(|a| (rel[a] - 0.5).floor());
        let pick = |a: usize, j: usize| clamp(lo[a] + j as f64, a);
        let mut best = f64::NEG_INFINITY;
        for k in 0..2 {
            for j in 0..2 {
                let dyz =
                    f.centre_gap_sq(p[1], pick(1, j), 1) + f.centre_gap_sq(p[2], pick(2, k), 2);
                for i in 0..2 {
                    let v = at([pick(0, i), pick(1, j), pick(2, k)]);
                    best = best.max(v - (f.centre_gap_sq(p[0], pick(0, i), 0) + dyz).sqrt());
                }
            }
        }
        (coarse, (best - ROUND_EPS).max(0.0))
    }
}
