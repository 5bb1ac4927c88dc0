//! How far along its x-row each voxel's nearest obstacle voxel lies: what lets the exact
//! clearance of a point ([`crate::collision::point_clearance::exact_clearance`]) read one or two
//! voxels per row instead of every voxel of a ball.
//!
//! For a point `p` in voxel `x0` of a row, the distance to the row's obstacle cubes
//! grows with `|x - x0|` on either side (the gap along x is `x r - p_x` to the right,
//! `p_x - (x + 1) r` to the left, and the other two axes do not change along the row).
//! So the nearest cube of the row is at `x0 - n` or `x0 + n`, where `n` is how many
//! voxels away the nearest obstacle voxel lies either way: with `f = p_x - x0 r` in
//! `[0, r)`, a cube `n` to the left is `f + (n - 1) r` away along x and one `n + 1`
//! to the right `(n + 1) r - f`, never nearer (and the same the other way round).

use rayon::prelude::*;

use super::grid::Grid;

/// Gaps of this many voxels or more (or rows without obstacles) are stored as this.
pub(crate) const FAR: u8 = u8::MAX;

/// Per voxel (the grid's layout, x fastest): how many voxels along its row the nearest
/// obstacle voxel lies, either way (0: the voxel itself), counting the voxels beyond
/// the row's ends as obstacles when unknown space is occupied; [`FAR`] for that many
/// or more.
pub(crate) fn row_gaps(grid: &Grid) -> Vec<u8> {
    let [nx, ny, _] = grid.dims();
    let mut gaps = vec![FAR; grid.dims().iter().product()];
    if nx == 0 {
        return gaps;
    }
    gaps.par_chunks_exact_mut(nx)
        .enumerate()
        .for_each(|(k, row)| row_gaps_of(grid, k % ny, k / ny, row));
    gaps
}

/// The gaps of row `(y, z)` (local indices) into `row` (its `dims[0]` voxels), whatever
/// `row` held before: for the full build and for the rows an update changes.
pub(crate) fn row_gaps_of(grid: &Grid, y: usize, z: usize, row: &mut [u8]) {
    let walls = grid.unknown_is_occupied();
    let nx = row.len();
    // The obstacle last seen on the left (-1: beyond the row's start).
    let mut last: Option<i64> = walls.then_some(-1);
    for (x, (g, obstacle)) in row.iter_mut().zip(grid.obstacle_row(y, z)).enumerate() {
        if obstacle {
            last = Some(x as i64);
        }
        *g = last.map_or(FAR, |o| gap(x as i64 - o));
    }
    // Right to left: the obstacles are the voxels the first pass set to 0.
    let mut next: Option<i64> = walls.then_some(nx as i64);
    for x in (0..nx).rev() {
        if row[x] == 0 {
            next = Some(x as i64);
        }
        if let Some(o) = next {
            row[x] = row[x].min(gap(o - x as i64));
        }
    }
}

/// A gap of `d >= 0` voxels, saturated at [`FAR`].
fn gap(d: i64) -> u8 {
    u8::try_from(d).unwrap_or(FAR)
}

#[cfg(test)]
mod tests {
    use super::super::grid::Cell;
    use super::*;

    #[test]
    fn gaps_by_hand() {
        let mut g = Grid::new(0.1, [0, 0, 0], [8, 2, 1], Cell::Free, false).unwrap();
        g.set([2, 0, 0], Cell::Occupied);
        g.set([7, 0, 0], Cell::Unknown);
        let gaps = row_gaps(&g);
        // Row y = 0: obstacle at x = 2 only (unknown is free here).
        assert_eq!(&gaps[..8], &[2, 1, 0, 1, 2, 3, 4, 5]);
        // Row y = 1: no obstacle.
        assert!(gaps[8..].iter().all(|&v| v == FAR));
        g.set_unknown_is_occupied(true);
        let gaps = row_gaps(&g);
        // Now x = 7 and both ends (x = -1, x = 8) count.
        assert_eq!(&gaps[..8], &[1, 1, 0, 1, 2, 2, 1, 0]);
        assert_eq!(&gaps[8..], &[1, 2, 3, 4, 4, 3, 2, 1]);
    }

    #[test]
    fn long_gaps_saturate() {
        let mut g = Grid::new(0.1, [0, 0, 0], [300, 1, 1], Cell::Free, false).unwrap();
        g.set([0, 0, 0], Cell::Occupied);
        let gaps = row_gaps(&g);
        assert_eq!(gaps[254], 254);
        assert_eq!(gaps[255], FAR);
        assert_eq!(gaps[299], FAR);
    }
}
