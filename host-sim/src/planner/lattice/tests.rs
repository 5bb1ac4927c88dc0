//! Tests of the lattice search: narrow passages found, walls proven closed, and a
//! route exactly when a plain flood connects start and goal.

use std::collections::VecDeque;
use std::sync::Arc;

use aerial_chain_core::ChainParams;
use proptest::prelude::*;

use super::nodes::{KeySet, Nodes};
use super::search::offsets26;
use super::*;
use crate::collision::point_clearance::exact_clearance;
use crate::map::distance::DistanceField;
use crate::map::grid::{Cell, Grid};
use crate::map::random_grids::scatter;

/// A closed box of `dims` voxels at `res`, free inside a one-voxel shell.
fn boxed(res: f64, dims: [usize; 3]) -> Grid {
    let mut g = Grid::new(res, [0; 3], dims, Cell::Occupied, true).unwrap();
    let e = 1e-6;
    let hi = dims.map(|d| (d - 1) as f64 * res - e);
    g.fill_box([res + e; 3], hi, Cell::Free);
    g
}

fn ctx(g: Grid, clearance: f64) -> CollisionContext {
    let field = Arc::new(DistanceField::new(g));
    CollisionContext::new(field, ChainParams::new(4), clearance).unwrap()
}

/// A wall across x at voxel column `wx` with the voxels `hole` (y, z ranges) open.
fn wall_with_hole(g: &mut Grid, wx: i32, ys: std::ops::Range<i32>, zs: std::ops::Range<i32>) {
    let [_, ny, nz] = g.dims();
    for z in 0..nz as i32 {
        for y in 0..ny as i32 {
            if !(ys.contains(&y) && zs.contains(&z)) {
                g.set([wx, y, z], Cell::Occupied);
            }
        }
    }
}

/// A box of `dims` voxels at `res` with a wall at column `wx` holding the hole `ys`,
/// `zs` (empty ranges: sealed), its context at clearance 0 and its lattice.
fn walled(
    res: f64,
    dims: [usize; 3],
    wx: std::ops::Range<i32>,
    hole: [std::ops::Range<i32>; 2],
) -> (CollisionContext, HeadLattice) {
    let mut g = boxed(res, dims);
    for x in wx {
        wall_with_hole(&mut g, x, hole[0].clone(), hole[1].clone());
    }
    let c = ctx(g, 0.0);
    let lat = HeadLattice::new(&c, 0.0, 2.0);
    (c, lat)
}

#[test]
fn a_passage_one_voxel_wide_is_found_where_uniform_samples_miss_it() {
    // 0.35 m voxels: a one-voxel hole leaves the head's centre (r 0.15 m, no
    // clearance) a 0.05 m x 0.05 m x 0.35 m tube in a 7 x 7 x 3.5 m box.
    let res = 0.35;
    let (c, lat) = walled(res, [20, 20, 10], 10..11, [10..11, 5..6]);
    let (a, b) = ([1.5, 1.5, 1.5], [5.5, 5.5, 1.5]);
    let LatticeOutcome::Found(r) = lat.route(&c, a, b) else {
        panic!("no route");
    };
    // The route passes the hole's centre (10.5, 10.5, 5.5) voxels.
    let hole = [10.5 * res, 10.5 * res, 5.5 * res];
    assert!(dist(r.narrowest, hole) < 1e-6, "{:?}", r.narrowest);
    assert!(r.narrowest_margin > 0.0);
    // Every route point keeps the head's sphere free by the exact test.
    for &p in &r.points {
        assert!(exact_clearance(c.field(), p, 0.0, 1.0) > 0.15, "{p:?}");
    }
    // The uniform roadmap of the same size misses it: 1500 samples, not one in
    // the tube (deterministic seed).
    let mut rng = <rand_pcg::Pcg64 as rand::SeedableRng>::seed_from_u64(1);
    let map =
        super::super::roadmap::Roadmap::build(&c, 1500, (1.5, 30), (2.0, 1.0), &mut rng, None);
    let in_tube = (0..map.vertex_count())
        .filter(|&v| {
            let p = map.point(v);
            (p[0] - hole[0]).abs() < res / 2.0
                && (p[1] - hole[1]).abs() < 0.03
                && (p[2] - hole[2]).abs() < 0.03
        })
        .count();
    assert_eq!(in_tube, 0);
}

#[test]
fn a_gap_two_voxels_wide_is_found_on_its_face_centred_line() {
    // 0.2 m voxels, a 2 x 2 voxel hole (0.4 m): the head (0.15 m) fits only
    // near the hole's centre, which is on voxel faces, not on voxel centres.
    let res = 0.2;
    let (c, lat) = walled(res, [30, 20, 15], 15..16, [9..11, 7..9]);
    let (a, b) = ([1.0, 2.0, 1.5], [5.0, 2.0, 1.5]);
    let centre = [2.0, 2.0, 1.6];
    // No voxel centre in the hole is free.
    for y in [9.5, 10.5] {
        for z in [7.5, 8.5] {
            assert!(!lat.is_free(c.field(), [15.5 * res, y * res, z * res]));
        }
    }
    assert!(lat.is_free(c.field(), [15.5 * res, centre[1], centre[2]]));
    let LatticeOutcome::Found(r) = lat.route(&c, a, b) else {
        panic!("no route");
    };
    assert!((r.narrowest[1] - centre[1]).abs() < 1e-6 && (r.narrowest[2] - centre[2]).abs() < 1e-6);
    assert!(
        (r.narrowest_margin - 0.05).abs() < 1e-6,
        "{}",
        r.narrowest_margin
    );
}

#[test]
fn a_wall_without_an_opening_separates_the_regions() {
    let mut g = boxed(0.2, [30, 20, 15]);
    wall_with_hole(&mut g, 15, 0..0, 0..0);
    let c = ctx(g, 0.05);
    let lat = HeadLattice::new(&c, 0.0, 2.0);
    match lat.route(&c, [1.0, 2.0, 1.5], [5.0, 2.0, 1.5]) {
        LatticeOutcome::Separated { .. } => {}
        other => panic!("{other:?}"),
    }
}

#[test]
fn labelled_regions_refuse_a_sealed_wall_and_keep_a_one_voxel_hole() {
    let res = 0.35;
    let (a, b) = ([1.5, 1.5, 1.5], [5.5, 5.5, 1.5]);
    let (c, lat) = walled(res, [20, 20, 10], 10..11, [0..0, 0..0]);
    match lat.separation(c.field(), a, b, None) {
        Some(LatticeOutcome::Separated {
            side, size, unit, ..
        }) => {
            assert_eq!(unit, "voxels");
            // The smaller side: 8 x 18 x 8 free voxels behind the wall.
            assert_eq!((side, size), ("goal", 8 * 18 * 8));
        }
        other => panic!("not separated: {other:?}"),
    }
    let (c, lat) = walled(res, [20, 20, 10], 10..11, [10..11, 5..6]);
    assert_eq!(lat.separation(c.field(), a, b, None), None);
}

#[test]
fn labelled_regions_close_a_slit_narrower_than_the_sphere_and_keep_a_wider_one() {
    // A 0.2 m wall across x at 2.0-2.2 m; the only opening a slit 1.4 m tall. Two
    // voxels (0.2 m) hold centres 0.05 m from each side: the field's bound alone
    // cannot close it for a sphere of 0.15 m; the gap along y can.
    let (a, b) = ([1.0, 1.0, 1.0], [3.2, 1.0, 1.0]);
    let (c, lat) = walled(0.1, [40, 40, 20], 20..22, [30..32, 1..15]);
    assert!(matches!(
        lat.separation(c.field(), a, b, None),
        Some(LatticeOutcome::Separated { unit: "voxels", .. })
    ));
    // The lattice's own flood agrees.
    assert!(matches!(
        lat.route(&c, a, b),
        LatticeOutcome::Separated { .. }
    ));
    // Four voxels (0.4 m) leave room for the sphere: no proof, and a route.
    let (c, lat) = walled(0.1, [40, 40, 20], 20..22, [30..34, 1..15]);
    assert_eq!(lat.separation(c.field(), a, b, None), None);
    assert!(matches!(lat.route(&c, a, b), LatticeOutcome::Found(_)));
}

#[test]
fn regions_not_labelled_by_the_deadline_prove_nothing_and_are_labelled_later() {
    let (a, b) = ([1.5, 1.5, 1.5], [5.5, 5.5, 1.5]);
    let (c, lat) = walled(0.35, [20, 20, 10], 10..11, [0..0, 0..0]);
    let passed = Some(std::time::Instant::now());
    assert!(lat.regions(c.field(), passed).is_none());
    assert_eq!(lat.separation(c.field(), a, b, passed), None);
    assert_eq!(
        lat.guided_route(&c, a, b, usize::MAX, passed),
        LatticeOutcome::Budget
    );
    assert!(matches!(
        lat.separation(c.field(), a, b, None),
        Some(LatticeOutcome::Separated { .. })
    ));
    // Once labelled, a deadline no longer matters.
    assert!(lat.regions(c.field(), passed).is_some());
}

#[test]
fn the_coarse_guide_leads_through_the_door_not_the_wall() {
    // A 0.2 m wall across x at 2.0-2.2 m with a 0.6 m door at y 3.0-3.6 m; start and
    // goal 2 m apart on either side of the wall, 2.5 m from the door.
    let (c, lat) = walled(0.1, [40, 40, 20], 20..22, [30..36, 1..15]);
    let (a, b) = ([1.0, 1.0, 1.0], [3.2, 1.0, 1.0]);
    let mut nodes = Nodes::new(&lat, c.field());
    let starts = lat.anchors(&mut nodes, a, 1);
    let goals = lat.anchors(&mut nodes, b, 1);
    let guide = super::guide::Guide::new(
        &lat,
        lat.regions(c.field(), None).unwrap(),
        &starts,
        &goals,
        b,
    );
    let door = [2.1, 3.3, 1.0];
    let around = dist(a, door) + dist(door, b);
    let h = guide.estimate(starts[0], lat.point(starts[0]));
    // The way round (5.1 m), give or take a block, not the straight line (2.2 m).
    assert!((h - around).abs() < 0.8, "estimate {h}, way round {around}");
    // And the route takes the door.
    let LatticeOutcome::Found(r) = lat.route(&c, a, b) else {
        panic!("no route");
    };
    assert!(r
        .points
        .iter()
        .any(|p| p[1] > 2.9 && (2.0..2.2).contains(&p[0])));
}

/// Reference: a breadth-first flood over the whole lattice with the same exact
/// test, from the start's anchors to the goal's.
fn flood_connects(
    lat: &HeadLattice,
    c: &CollisionContext,
    a: [f64; 3],
    b: [f64; 3],
) -> Option<bool> {
    let mut nodes = Nodes::new(lat, c.field());
    let starts = lat.anchors(&mut nodes, a, 1);
    let goals: KeySet = lat.anchors(&mut nodes, b, 1).into_iter().collect();
    if starts.is_empty() || goals.is_empty() {
        return None;
    }
    let mut seen: KeySet = starts.iter().copied().collect();
    let mut queue: VecDeque<u64> = starts.into_iter().collect();
    while let Some(q) = queue.pop_front() {
        if goals.contains(&q) {
            return Some(true);
        }
        let i = HeadLattice::unpack(q);
        for o in offsets26() {
            if let Some(n) = lat.pack([i[0] + o[0], i[1] + o[1], i[2] + o[2]]) {
                if lat.is_free(c.field(), lat.point(n)) && seen.insert(n) {
                    queue.push_back(n);
                }
            }
        }
    }
    Some(false)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// The search finds a route exactly when the flood connects start and goal.
    #[test]
    fn route_exactly_when_the_flood_connects(
        seed in 0u64..1_000_000,
        density in 0.05f64..0.35,
        res in prop::sample::select(vec![0.1f64, 0.15, 0.2]),
    ) {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
        let mut g = boxed(res, [14, 10, 8]);
        scatter(&mut g, [1; 3], [13, 9, 7], density, &mut rng);
        let c = ctx(g, 0.0);
        let lat = HeadLattice::new(&c, 0.0, 2.0);
        let (lo, hi) = c.field().grid().bounds();
        let pick = |rng: &mut rand_pcg::Pcg64| {
            [0, 1, 2].map(|k| rng.gen_range(lo[k] + 0.2..hi[k] - 0.2))
        };
        let (a, b) = (pick(&mut rng), pick(&mut rng));
        let reference = flood_connects(&lat, &c, a, b);
        // The labelled regions only ever prove what the flood confirms.
        if let Some(sep) = lat.separation(c.field(), a, b, None) {
            prop_assert_eq!(reference, Some(false), "regions said {:?}", sep);
        }
        let got = lat.route(&c, a, b);
        match (reference, &got) {
            (None, LatticeOutcome::NoAnchor { .. }) => {}
            (Some(true), LatticeOutcome::Found(r)) => {
                prop_assert_eq!(r.points[0], a);
                prop_assert_eq!(*r.points.last().unwrap(), b);
            }
            (Some(false), LatticeOutcome::Separated { .. }) => {}
            (r, g) => prop_assert!(false, "flood {:?}, search {:?}", r, g),
        }
    }
}
