//! Scenarios through the file format: export as `.bt`, read back, build the grid and
//! distance field, and check the start, the witness plan and the unknown-space switch.

use std::sync::Arc;

use aerial_chain::collision::{verify_plan, CollisionContext, DEFAULT_CLEARANCE};
use aerial_chain::map::DistanceField;
use aerial_chain::map::Grid;
use aerial_chain::map::OcTree;
use aerial_chain::problem::scenarios;
use aerial_chain::witness::route_plan;
use aerial_chain_core::ChainParams;

#[test]
fn exported_scenarios_fly_from_the_file() {
    let dir = tempfile::tempdir().unwrap();
    for name in scenarios::NAMES {
        let s = scenarios::build(name).unwrap();
        let path = dir.path().join(format!("{name}.bt"));
        s.octree().unwrap().write_bt(&path).unwrap();
        let tree = OcTree::read_bt(&path).unwrap();
        let (lo, hi) = tree.metric_bounds().unwrap();
        let (slo, shi) = s.grid.bounds();
        for a in 0..3 {
            assert!(
                (lo[a] - slo[a]).abs() < 1e-9 && (hi[a] - shi[a]).abs() < 1e-9,
                "{name}"
            );
        }
        for unknown_is_occupied in [true, false] {
            let grid = Grid::from_octree(&tree, unknown_is_occupied).unwrap();
            assert!(grid.cells().eq(s.grid.cells()), "{name}");
            let p = ChainParams::new(s.default_units);
            let ctx = CollisionContext::new(
                Arc::new(DistanceField::new(grid.clone())),
                p,
                DEFAULT_CLEARANCE,
            )
            .unwrap();
            let shape = s.start_shape(s.default_units).unwrap();
            assert_eq!(ctx.check_config(s.start, &shape), Ok(()), "{name}");
            let mut plan = route_plan(&s, &p, 0.1).unwrap();
            plan.map.unknown_is_occupied = unknown_is_occupied;
            let rep = verify_plan(&grid, &plan);
            assert!(rep.ok, "{name}: {:?}", rep.violation);
            assert!(rep.notes.is_empty(), "{name}: {:?}", rep.notes);
        }
    }
}

#[test]
fn unknown_space_switch_matters_for_partial_maps() {
    // Known free voxels only around x in 0..2 m; unknown beyond: with unknown space
    // occupied the chain cannot reach into it, with --unknown-free it can.
    let voxels =
        (0..40).flat_map(|x| (0..20).flat_map(move |y| (0..20).map(move |z| ([x, y, z], false))));
    let tree = OcTree::from_voxels(0.1, voxels).unwrap();
    let p = ChainParams::new(3);
    let shape = aerial_chain_core::Shape::line(3, 0.0);
    for (occ, ok) in [(true, false), (false, true)] {
        let mut grid = Grid::from_octree(&tree, occ).unwrap();
        // Make x >= 2.0 unknown inside the bounds.
        for x in 20..40 {
            for y in 0..20 {
                for z in 0..20 {
                    grid.set([x, y, z], aerial_chain::map::Cell::Unknown);
                }
            }
        }
        let ctx = CollisionContext::new(Arc::new(DistanceField::new(grid)), p, 0.05).unwrap();
        assert_eq!(
            ctx.check_config([3.5, 1.0, 1.0], &shape).is_ok(),
            ok,
            "unknown occupied: {occ}"
        );
        assert!(ctx.check_config([1.5, 1.0, 1.0], &shape).is_ok());
    }
}
