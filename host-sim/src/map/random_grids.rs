//! Random small grids for the property tests: every voxel's state drawn from a list,
//! or obstacles scattered at a density.

use proptest::prelude::*;

use super::grid::{Cell, Grid};

/// Writes every voxel of `g` (x fastest, then y, then z) with the states of `draws`
/// in turn, cycled, each through `state`.
pub(crate) fn write_cycled<T: Copy>(g: &mut Grid, draws: &[T], state: impl Fn(T) -> Cell) {
    let (o, dims) = (g.origin(), g.dims());
    let mut k = 0;
    for z in 0..dims[2] as i32 {
        for y in 0..dims[1] as i32 {
            for x in 0..dims[0] as i32 {
                g.set(
                    [o[0] + x, o[1] + y, o[2] + z],
                    state(draws[k % draws.len()]),
                );
                k += 1;
            }
        }
    }
}

/// Grids of 0.1 m at origin `(-3, 2, -1)`, a side of `sides` voxels, free or not as
/// `state` turns the draws of a byte per voxel (cycled), unknown space occupied or not.
pub(crate) fn grids(
    sides: std::ops::Range<usize>,
    state: fn(u8) -> Cell,
) -> impl Strategy<Value = Grid> {
    (
        proptest::array::uniform3(sides),
        proptest::collection::vec(any::<u8>(), 1..200),
        any::<bool>(),
    )
        .prop_map(move |(dims, cells, unknown_occ)| {
            let mut g = Grid::new(0.1, [-3, 2, -1], dims, Cell::Free, unknown_occ).unwrap();
            write_cycled(&mut g, &cells, state);
            g
        })
}

/// Occupies every voxel of the lattice box `lo..hi` (z slowest, x fastest) with
/// probability `density`, drawn from `rng`.
pub(crate) fn scatter(
    g: &mut Grid,
    lo: [i32; 3],
    hi: [i32; 3],
    density: f64,
    rng: &mut impl rand::Rng,
) {
    for z in lo[2]..hi[2] {
        for y in lo[1]..hi[1] {
            for x in lo[0]..hi[0] {
                if rng.gen_bool(density) {
                    g.set([x, y, z], Cell::Occupied);
                }
            }
        }
    }
}
