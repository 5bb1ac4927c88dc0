//! The scenarios are well formed, can be flown, and cannot be flown without changing shape.

use std::sync::Arc;

use aerial_chain_core::validity::Body;
use aerial_chain_core::ChainParams;

use super::*;
use crate::collision::exact::check_config_exact;
use crate::collision::{verify_plan, CollisionContext, EdgeKind, DEFAULT_CLEARANCE};
use crate::map::distance::DistanceField;

fn all() -> Vec<Scenario> {
    vec![
        window(),
        maze(),
        silos(),
        corridor(10.0).unwrap(),
        corridor(DEFAULT_CORRIDOR_LENGTH).unwrap(),
    ]
}

#[test]
fn names_build() {
    for n in NAMES {
        assert_eq!(build(n).unwrap().name, *n);
    }
    assert_eq!(build("corridor:35").unwrap().name, "corridor:35");
    assert!(build("corridor:5").is_err());
    assert!(build("corridor:x").is_err());
    assert!(build("nope").unwrap_err().to_string().contains("window"));
    assert!(corridor(100.0).is_ok() && corridor(100.5).is_err() && corridor(f64::NAN).is_err());
}

/// Every voxel in the box is known, and no occupied voxel is a one-voxel sliver
/// between free voxels along any axis.
#[test]
fn walls_are_thick_and_space_is_known() {
    for s in all() {
        let g = &s.grid;
        assert_eq!(g.counts().unknown, 0, "{}", s.name);
        let o = g.origin();
        let [nx, ny, nz] = g.dims();
        for z in 0..nz as i32 {
            for y in 0..ny as i32 {
                for x in 0..nx as i32 {
                    let i = [o[0] + x, o[1] + y, o[2] + z];
                    if g.cell(i) != Cell::Occupied {
                        continue;
                    }
                    for a in 0..3 {
                        let (mut lo, mut hi) = (i, i);
                        lo[a] -= 1;
                        hi[a] += 1;
                        let thin = g.cell(lo) == Cell::Free && g.cell(hi) == Cell::Free;
                        assert!(!thin, "{}: one-voxel wall at {i:?} along axis {a}", s.name);
                    }
                }
            }
        }
    }
}

#[test]
fn octree_export_round_trips() {
    for s in [window(), silos()] {
        let t = s.octree().unwrap();
        let g = Grid::from_octree(&t, true).unwrap();
        assert_eq!(g.dims(), s.grid.dims(), "{}", s.name);
        assert_eq!(g.origin(), s.grid.origin());
        assert!(g.cells().eq(s.grid.cells()), "{}", s.name);
    }
}

/// The start configuration and the goal are valid for the default chain.
#[test]
fn start_and_goal_are_free() {
    for s in all() {
        let p = ChainParams::new(s.default_units);
        let f = Arc::new(DistanceField::new(s.grid.clone()));
        let ctx = CollisionContext::new(f, p, DEFAULT_CLEARANCE).unwrap();
        let shape = s.start_shape(s.default_units).unwrap();
        assert_eq!(ctx.check_config(s.start, &shape), Ok(()), "{}", s.name);
        assert!(ctx.is_head_free(s.goal), "{}", s.name);
    }
}

/// The follow-the-leader plan along the route passes the exact verifier with clearance
/// to spare, and the planner's conservative checks accept every one of its edges.
#[test]
fn scenarios_can_be_flown() {
    for s in all() {
        let p = ChainParams::new(s.default_units);
        let plan = crate::witness::route_plan(&s, &p, 0.05).unwrap();
        let rep = verify_plan(&s.grid, &plan);
        assert!(rep.ok, "{}: {:?}", s.name, rep.violation);
        assert!(
            rep.min_clearance > DEFAULT_CLEARANCE,
            "{}: min clearance {}",
            s.name,
            rep.min_clearance
        );
        let f = Arc::new(DistanceField::new(s.grid.clone()));
        let ctx = CollisionContext::new(f, p, DEFAULT_CLEARANCE).unwrap();
        for (e, w) in plan.waypoints.windows(2).enumerate() {
            let (a, b) = (&w[0], &w[1]);
            let sa = aerial_chain_core::Shape::from_slice(
                p.units,
                &a.eta().iter().map(|&v| v as f32).collect::<Vec<_>>(),
            )
            .unwrap();
            let sb = aerial_chain_core::Shape::from_slice(
                p.units,
                &b.eta().iter().map(|&v| v as f32).collect::<Vec<_>>(),
            )
            .unwrap();
            let r = match rep.edges[e] {
                EdgeKind::Translation => ctx.check_translation(a.xi(), b.xi(), &sa),
                EdgeKind::ShapeChange => ctx.check_shape_change(a.xi(), &sa, &sb),
                k => panic!("{}: edge {e} is {k}", s.name),
            };
            assert!(
                r.is_ok(),
                "{}: edge {e} ({}) rejected by the fast check: {:?}",
                s.name,
                rep.edges[e],
                r
            );
        }
        let last = plan.waypoints.last().unwrap().xi();
        assert!(super::dist(last, s.goal.into()) < 1e-9);
    }
}

/// A set of head positions that every start-to-goal motion of the straight chain at the
/// start yaw must pass through (see each case), sampled every 0.05 m: the chain collides
/// at every one of them, by the exact test.
#[test]
fn the_straight_chain_cannot_get_through() {
    // (scenario, x range of the cut for the HEAD).
    // window, maze, silos: the chain lies along y at the start yaw (90 deg), so all its
    // units share the head's x; any motion from start (west) to goal (east) passes a
    // moment where the head, hence every unit, is inside the wall's slab (or at the
    // silos' axis x = 7), where the opening (0.8, 1.2, 0.8 m) is narrower than the chain.
    // corridor: the chain lies along x; when the head is inside door 2's slab, the
    // fourth link's end (unit 5, 2 m behind) is inside door 1's slab, and the doors'
    // openings do not overlap in y, but every unit shares the head's y.
    let cases: Vec<(Scenario, f64, f64)> = vec![
        (window(), 4.0, 4.2),
        (maze(), 2.7, 2.9),
        (silos(), 6.95, 7.05),
        (corridor(10.0).unwrap(), 6.5, 6.7),
    ];
    for (s, x0, x1) in cases {
        let p = ChainParams::new(s.default_units);
        let shape = s.start_shape(s.default_units).unwrap();
        let eta: Vec<f64> = shape.as_slice().iter().map(|&a| a as f64).collect();
        let (lo, hi) = s.grid.bounds();
        let mut count = 0;
        let mut x = x0;
        while x <= x1 + 1e-9 {
            let mut y = lo[1];
            while y <= hi[1] {
                let mut z = lo[2];
                while z <= hi[2] {
                    let r = check_config_exact(&s.grid, &p, [x, y, z], &eta, 0.0);
                    assert!(r.is_err(), "{}: LI valid at ({x}, {y}, {z})", s.name);
                    count += 1;
                    z += 0.05;
                }
                y += 0.05;
            }
            x += 0.05;
        }
        assert!(count > 1000);
    }
}

/// The window is narrow: the head's sphere passes, but not with much room.
#[test]
fn window_is_a_bit_larger_than_a_unit() {
    let s = window();
    let f = Arc::new(DistanceField::new(s.grid.clone()));
    let ctx = CollisionContext::new(f, ChainParams::new(5), DEFAULT_CLEARANCE).unwrap();
    assert!(ctx.is_head_segment_free([3.5, 3.0, 1.5], [4.7, 3.0, 1.5]));
    assert!(!ctx.is_head_segment_free([3.5, 3.2, 1.5], [4.7, 3.2, 1.5]));
    let _ = Body::Unit(0);
}
