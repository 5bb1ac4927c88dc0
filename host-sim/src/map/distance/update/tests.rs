//! The update against a recomputation, to the bit.

use proptest::prelude::*;

use super::super::super::random_grids::grids;
use super::super::super::row_gaps::FAR;
use super::*;

/// Three tenths of the voxels occupied, two unknown.
fn state(v: u8) -> Cell {
    match v % 10 {
        0..=2 => Cell::Occupied,
        3 | 4 => Cell::Unknown,
        _ => Cell::Free,
    }
}

/// Fails, saying which, unless `f` equals a field built afresh from its grid in every
/// stored value and kept array, and the grid's block counts equal a recount.
fn assert_same_as_rebuilt(f: &DistanceField) -> Result<(), TestCaseError> {
    let fresh = DistanceField::new(f.grid().clone());
    let bits = |v: &[f32]| v.iter().map(|b| b.to_bits()).collect::<Vec<_>>();
    prop_assert_eq!(bits(&f.lb), bits(&fresh.lb), "stored bounds");
    prop_assert_eq!(&f.row_gaps, &fresh.row_gaps, "row gaps");
    prop_assert_eq!(f.extent, fresh.extent);
    prop_assert!(f.grid().blocks_match_cells(), "block counts");
    let kept = f.kept.as_deref().expect("an update keeps its passes");
    prop_assert_eq!(kept, &Kept::of(f.grid()), "kept passes");
    Ok(())
}

/// Turns raw draws into changes inside a grid of `dims`: `mode` 0 scatters, 1 puts the
/// voxel on a face of the grid, 2 next to the previous change (clusters). Each batch
/// ends by changing its first voxel a second time, to another state.
fn changes_of(dims: [usize; 3], raw: &[(u8, [u8; 3], u8)], g: &Grid) -> Vec<([i32; 3], Cell)> {
    let mut out: Vec<([i32; 3], Cell)> = Vec::new();
    let mut prev = [0usize; 3];
    for &(mode, p, s) in raw {
        let mut l = [0, 1, 2].map(|a| p[a] as usize % dims[a]);
        match mode % 3 {
            1 => {
                let a = p[0] as usize % 3;
                l[a] = if p[1] % 2 == 0 { 0 } else { dims[a] - 1 };
            }
            2 => {
                l = [0, 1, 2].map(|a| {
                    (prev[a] + p[a] as usize % 3)
                        .saturating_sub(1)
                        .min(dims[a] - 1)
                });
            }
            _ => {}
        }
        prev = l;
        out.push((g.index_of_local(l), state(s)));
    }
    if let Some(&(i, s)) = out.first() {
        let again = match s {
            Cell::Free => Cell::Occupied,
            Cell::Occupied => Cell::Unknown,
            Cell::Unknown => Cell::Free,
        };
        out.push((i, again));
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// After every batch of random insertions and deletions the field equals a
    /// recomputation, to the bit.
    #[test]
    fn updates_equal_a_recomputation(
        // Up to 12 a side: y columns wider than `WIDE_WINDOW` take the other path.
        grid in grids(1..13, state),
        prepared in any::<bool>(),
        batches in proptest::collection::vec(
            proptest::collection::vec((0u8..3, any::<[u8; 3]>(), any::<u8>()), 1..12),
            1..5,
        ),
    ) {
        let dims = grid.dims();
        let mut f = DistanceField::new(grid);
        if prepared {
            f.prepare_updates();
        }
        for (k, raw) in batches.iter().enumerate() {
            let changes = changes_of(dims, raw, f.grid());
            let stats = f.update(&changes).unwrap();
            prop_assert_eq!(stats.built_kept, k == 0 && !prepared);
            prop_assert_eq!(stats.changes, changes.len());
            assert_same_as_rebuilt(&f)?;
        }
    }
}

#[test]
fn a_change_outside_the_grid_is_refused_and_changes_nothing() {
    let g = Grid::new(0.1, [-3, 2, -1], [4, 5, 6], Cell::Free, true).unwrap();
    let mut f = DistanceField::new(g);
    let before = f.lb.clone();
    let changes = [([-3, 2, -1], Cell::Occupied), ([1, 2, -1], Cell::Occupied)];
    let e = f.update(&changes).unwrap_err();
    assert_eq!(
        e,
        UpdateError::OutsideGrid {
            change: 1,
            voxel: [1, 2, -1],
            lo: [-3, 2, -1],
            hi: [0, 6, 4]
        }
    );
    let msg = e.to_string();
    assert!(
        msg.contains("change 1") && msg.contains("[1, 2, -1]"),
        "{msg}"
    );
    assert_eq!(f.grid().cell([-3, 2, -1]), Cell::Free, "nothing applied");
    assert_eq!(f.lb, before);
    assert!(f.kept.is_none());
}

/// In a map of walls every fourth voxel along x, one voxel changed reaches one row and
/// a few columns, not the map.
#[test]
fn a_local_change_visits_little() {
    let dims = [60, 60, 20];
    let mut g = Grid::new(0.1, [0, 0, 0], dims, Cell::Free, true).unwrap();
    g.fill_where(Cell::Occupied, |p| (p.x / 0.1).floor() as i64 % 4 == 0);
    let mut f = DistanceField::new(g);
    f.prepare_updates();
    let stats = f.update(&[([30, 30, 10], Cell::Occupied)]).unwrap();
    assert_eq!((stats.obstacle_flips, stats.rows), (1, 1));
    let total: usize = dims.iter().product();
    assert!(stats.voxels_visited * 50 < total, "{stats:?}");
    assert!(
        stats.bounds_changed > 0 && stats.bounds_changed < 50,
        "{stats:?}"
    );
    assert_eq!(f.row_gaps[30 + 60 * (30 + 60 * 10)], 0);
    assert_ne!(f.row_gaps[31 + 60 * (30 + 60 * 10)], FAR);
    // And back: the voxel freed again restores the original field.
    f.update(&[([30, 30, 10], Cell::Free)]).unwrap();
    assert_same_as_rebuilt(&f).unwrap();
}

/// A change that flips no obstacle (free to unknown while unknown space is free)
/// writes the grid and transforms nothing.
#[test]
fn a_state_change_that_flips_no_obstacle_transforms_nothing() {
    let g = Grid::new(0.1, [0, 0, 0], [5, 5, 5], Cell::Free, false).unwrap();
    let mut f = DistanceField::new(g);
    let stats = f.update(&[([2, 2, 2], Cell::Unknown)]).unwrap();
    assert_eq!(f.grid().cell([2, 2, 2]), Cell::Unknown);
    assert_eq!((stats.obstacle_flips, stats.voxels_visited), (0, 0));
    assert_same_as_rebuilt(&f).unwrap();
}

/// The memory the kept passes add: 8 bytes a voxel.
#[test]
fn kept_passes_cost_eight_bytes_a_voxel() {
    let g = Grid::new(0.1, [0, 0, 0], [10, 20, 30], Cell::Free, true).unwrap();
    let mut f = DistanceField::new(g);
    let before = f.memory_bytes();
    assert_eq!(before, 6000 * 6);
    f.prepare_updates();
    assert_eq!(f.memory_bytes() - before, 6000 * 8);
}
