use super::*;
use crate::sensing::{raycast, DepthSensor, UnitPose};

fn cloud(origin: [f32; 3], points: &[[f32; 3]]) -> PointCloud {
    PointCloud {
        origin,
        points: points.to_vec(),
    }
}

#[test]
fn packed_keys_keep_their_order() {
    let keys = [
        [-32768, 5, -1],
        [-1, 32767, 0],
        [0, -32768, 7],
        [0, 0, -32768],
        [32767; 3],
    ];
    for w in keys.windows(2) {
        assert!(pack(w[0]) < pack(w[1]), "{w:?}");
    }
    for k in keys {
        assert_eq!(unpack(pack(k)), k);
    }
}

#[test]
fn defaults_are_octomaps_in_log_odds() {
    let p = OccupancyParams::default().log_odds().unwrap();
    assert!((p.hit - 0.847_298).abs() < 1e-5);
    assert!((p.miss + 0.405_465).abs() < 1e-5);
    assert!((p.min + 1.999_9).abs() < 1e-3);
    assert!((p.max - 3.511_0).abs() < 1e-3);
    assert_eq!(p.threshold, 0.0);
}

#[test]
fn one_ray_frees_its_path_and_occupies_its_end() {
    let mut m = OccupancyMap::new(0.1).unwrap();
    let changes = m
        .insert(&cloud([0.05, 0.05, 0.05], &[[0.55, 0.05, 0.05]]), 5.0)
        .unwrap();
    assert_eq!(changes.len(), 6);
    for x in 0..5 {
        assert_eq!(m.state([x, 0, 0]), Cell::Free);
        assert_eq!(m.log_odds([x, 0, 0]), Some(m.params().miss));
    }
    assert_eq!(m.state([5, 0, 0]), Cell::Occupied);
    assert_eq!(m.state([6, 0, 0]), Cell::Unknown);
    assert!(changes.iter().all(|c| c.old == Cell::Unknown));
    // Again: nothing changes state, the values move on.
    assert!(m
        .insert(&cloud([0.05, 0.05, 0.05], &[[0.55, 0.05, 0.05]]), 5.0)
        .unwrap()
        .is_empty());
    assert_eq!(m.log_odds([5, 0, 0]), Some(m.params().hit + m.params().hit));
}

#[test]
fn occupied_wins_within_a_cloud_and_clamping_bounds_the_values() {
    let mut m = OccupancyMap::new(0.1).unwrap();
    let o = [0.05, 0.05, 0.05];
    // The second ray passes through the first one's end voxel: occupied only.
    let c = cloud(o, &[[0.35, 0.05, 0.05], [0.75, 0.05, 0.05]]);
    m.insert(&c, 5.0).unwrap();
    assert_eq!(m.log_odds([3, 0, 0]), Some(m.params().hit));
    for _ in 0..20 {
        m.insert(&c, 5.0).unwrap();
    }
    assert_eq!(m.log_odds([3, 0, 0]), Some(m.params().max));
    assert_eq!(m.log_odds([1, 0, 0]), Some(m.params().min));
    // A miss beyond the range clears up to it, with no end point; it takes several
    // misses to turn an occupied voxel (clamped high) free.
    let far = cloud(o, &[[100.05, 0.05, 0.05]]);
    let mut n = 0;
    while m.state([3, 0, 0]) == Cell::Occupied {
        let ch = m.insert(&far, 1.0).unwrap();
        n += 1;
        if m.state([3, 0, 0]) == Cell::Free {
            assert!(ch.contains(&VoxelChange {
                voxel: [3, 0, 0],
                old: Cell::Occupied,
                new: Cell::Free
            }));
        }
    }
    assert_eq!(n, 9, "3.51 / 0.405 misses");
    assert_eq!(m.state([9, 0, 0]), Cell::Free);
    assert_eq!(
        m.state([10, 0, 0]),
        Cell::Unknown,
        "the cut end's voxel is not freed"
    );
}

#[test]
fn bad_arguments_are_errors() {
    assert_eq!(
        OccupancyMap::new(0.0).unwrap_err().to_string(),
        "resolution = 0.0: must be a positive number of metres"
    );
    let bad = OccupancyParams {
        prob_hit: 0.3,
        ..Default::default()
    };
    assert!(OccupancyMap::with_params(0.1, bad)
        .unwrap_err()
        .to_string()
        .starts_with("prob_hit = 0.3"));
    let mut m = OccupancyMap::new(0.1).unwrap();
    assert!(m
        .insert(&cloud([0.0; 3], &[]), f64::NAN)
        .unwrap_err()
        .to_string()
        .starts_with("max_range = NaN"));
    assert!(m.mark_free_sphere([0.0, 0.0, f64::NAN], 0.2).is_err());
    assert!(m
        .mark_free_sphere([0.0; 3], -1.0)
        .unwrap_err()
        .to_string()
        .starts_with("radius = -1.0"));
    assert!(m.mark_free_sphere([0.0; 3], 1000.0).is_err());
}

#[test]
fn a_sphere_frees_the_cubes_inside_it() {
    let mut m = OccupancyMap::new(0.1).unwrap();
    m.insert(&cloud([0.05, 0.05, 0.05], &[[0.05, 0.05, 0.05]]), 5.0)
        .unwrap();
    assert_eq!(m.state([0, 0, 0]), Cell::Occupied);
    // Radius 0.2 around a lattice point: the 8 cubes around it (corner at 0.173) only.
    let changes = m.mark_free_sphere([0.0, 0.0, 0.0], 0.2).unwrap();
    assert_eq!(m.known(), 8);
    assert_eq!(changes.len(), 8);
    assert!(changes.contains(&VoxelChange {
        voxel: [0, 0, 0],
        old: Cell::Occupied,
        new: Cell::Free
    }));
    assert_eq!(m.log_odds([-1, -1, -1]), Some(m.params().min));
    // Exactly on the boundary counts as inside: a cube of corner distance 0.1 * sqrt(3).
    let mut m = OccupancyMap::new(0.1).unwrap();
    m.mark_free_sphere([0.0, 0.0, 0.0], 0.1f64 * 3f64.sqrt() + 1e-12)
        .unwrap();
    assert_eq!(m.known(), 8);
    let mut m = OccupancyMap::new(0.1).unwrap();
    m.mark_free_sphere([0.05, 0.05, 0.05], 0.08).unwrap();
    assert_eq!(
        m.known(),
        0,
        "no cube fits in a ball smaller than its half-diagonal"
    );
}

#[test]
fn the_seen_map_becomes_a_grid_and_a_tree() {
    let mut g = Grid::new(0.1, [0, 0, 0], [12, 12, 12], Cell::Free, true).unwrap();
    g.fill_box([0.95, 0.0, 0.0], [1.2, 1.2, 1.2], Cell::Occupied);
    let pose = UnitPose::level([0.3, 0.6, 0.6], 0.0);
    let s = raycast::scan(&g, &DepthSensor::default(), &pose);
    let mut m = OccupancyMap::new(0.1).unwrap();
    let changes = m
        .insert(&PointCloud::from_scan(&s, 0.1), s.max_range)
        .unwrap();
    assert_eq!(changes.len(), m.known());
    let seen = m.to_grid(true).unwrap();
    let c = seen.counts();
    assert!(c.occupied > 50 && c.free > 100, "{c:?}");
    // Every occupied voxel seen is occupied in the truth; every free one free.
    for (i, state) in m.voxels() {
        assert_eq!(seen.cell(i), state);
        if i.iter().all(|&v| (0..12).contains(&v)) {
            assert_eq!(g.cell(i), state, "{i:?}");
        }
    }
    let tree = m.to_octree().unwrap();
    assert!(tree.counts().0 > 0 && tree.counts().1 > 0);
    let back = Grid::from_octree(&tree, true).unwrap();
    assert!(back.cells().eq(seen.cells()));
    assert!(matches!(
        OccupancyMap::new(0.1).unwrap().to_grid(true),
        Err(GridError::Empty)
    ));
}

/// Every state of every voxel the map knows, unknown ones left out.
fn snapshot(m: &OccupancyMap) -> std::collections::BTreeMap<[i32; 3], Cell> {
    m.voxels().collect()
}

/// The changes an operation reports are exactly the voxels whose state differs.
fn assert_changes_are_the_difference(
    before: &std::collections::BTreeMap<[i32; 3], Cell>,
    m: &OccupancyMap,
    changes: &[VoxelChange],
) -> Result<(), proptest::test_runner::TestCaseError> {
    let after = snapshot(m);
    let mut expected: Vec<VoxelChange> = after
        .iter()
        .filter_map(|(&voxel, &new)| {
            let old = before.get(&voxel).copied().unwrap_or(Cell::Unknown);
            (old != new).then_some(VoxelChange { voxel, old, new })
        })
        .collect();
    expected.sort_unstable_by_key(|c| c.voxel);
    prop_assert!(
        before.keys().all(|k| after.contains_key(k)),
        "a voxel became unknown"
    );
    prop_assert_eq!(changes, &expected[..]);
    Ok(())
}

use proptest::prelude::*;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// Insertions and free spheres report exactly the voxels whose state they changed.
    #[test]
    fn changes_are_exactly_the_state_differences(
        steps in proptest::collection::vec(
            (
                proptest::array::uniform3(-0.5f32..0.5),
                proptest::collection::vec(proptest::array::uniform3(-1.5f32..1.5), 1..12),
                0.2f64..2.0,
                proptest::option::of((proptest::array::uniform3(-1.0f64..1.0), 0.0f64..0.4)),
            ),
            1..12,
        ),
        res in prop_oneof![Just(0.1f64), Just(0.087), Just(0.2)],
    ) {
        let mut m = OccupancyMap::new(res).unwrap();
        for (origin, points, max_range, sphere) in steps {
            let before = snapshot(&m);
            let changes = m.insert(&cloud(origin, &points), max_range).unwrap();
            assert_changes_are_the_difference(&before, &m, &changes)?;
            if let Some((c, r)) = sphere {
                let before = snapshot(&m);
                let changes = m.mark_free_sphere(c, r).unwrap();
                assert_changes_are_the_difference(&before, &m, &changes)?;
            }
        }
    }
}
