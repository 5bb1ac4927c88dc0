//! Tests of the conservative checker against the exact one.

use std::sync::Arc;

use aerial_chain_core::validity::{check_transition, Body};
use aerial_chain_core::{ChainParams, Shape};
use nalgebra::Vector3;
use proptest::prelude::*;

use super::exact::check_config_exact;
use super::verify::check_edge_exact;
use super::*;
use crate::map::distance::DistanceField;
use crate::map::grid::{Cell, Grid};
use crate::map::random_grids::write_cycled;

/// A free 4 x 4 x 2 m box at 0.1 m with the given occupied boxes.
fn map(boxes: &[([f64; 3], [f64; 3])], unknown_occ: bool) -> Arc<DistanceField> {
    let mut g = Grid::new(0.1, [0, 0, 0], [40, 40, 20], Cell::Free, unknown_occ).unwrap();
    for (lo, hi) in boxes {
        g.fill_box(*lo, *hi, Cell::Occupied);
    }
    Arc::new(DistanceField::new(g))
}

fn zeta(head: [f64; 3], s: &Shape) -> Vec<f64> {
    let mut z = head.to_vec();
    z.extend(s.as_slice().iter().map(|&a| a as f64));
    z
}

#[test]
fn open_space_and_a_wall() {
    // A wall of voxels with centres x in [3.05, 3.15] (cubes 3.0..3.2).
    let f = map(&[([3.05, 0.0, 0.0], [3.15, 4.0, 2.0])], true);
    let ctx = CollisionContext::new(f.clone(), ChainParams::new(4), 0.05).unwrap();
    let line = Shape::line(4, 0.0); // trails along -x
                                    // 0.35 m from the wall: accepted (the bound loses some of the 0.15 m of slack).
    assert_eq!(ctx.check_config([2.65, 1.95, 0.95], &line), Ok(()));
    // 0.25 m from the wall at voxel faces: truly free; the field's bound alone cannot
    // prove it, the exact measure of the cubes nearby does.
    assert_eq!(ctx.check_config([2.75, 2.0, 1.0], &line), Ok(()));
    // 0.19 m from the wall: below r_u + clearance (0.2 m), refused.
    assert!(ctx.check_config([2.81, 2.0, 1.0], &line).is_err());
    // Head sphere reaches the wall: 3.0 - 2.85 = 0.15 <= r_u.
    assert!(matches!(
        ctx.check_config([2.85, 2.0, 1.0], &line),
        Err(Collision::Map {
            body: Body::Unit(0),
            ..
        })
    ));
    // Behind the wall the tail would cross it.
    assert!(matches!(
        ctx.check_config([3.9, 2.0, 1.0], &line),
        Err(Collision::Map { .. })
    ));
    // Outside the bounds.
    assert!(matches!(
        ctx.check_config([2.0, -0.5, 1.0], &line),
        Err(Collision::OutOfBounds(_))
    ));
    // Translation along the wall is fine, through it is not.
    assert_eq!(
        ctx.check_translation([2.6, 0.5, 1.0], [2.6, 3.5, 1.0], &line),
        Ok(())
    );
    let e = ctx
        .check_translation([2.6, 2.0, 1.0], [3.9, 2.0, 1.0], &line)
        .unwrap_err();
    assert!(e.t > 0.0 && e.t < 0.3, "{e}");
    // Turning the tail towards the wall while the head is near it collides.
    let towards = Shape::line(4, std::f32::consts::PI); // trails along +x
    assert!(ctx
        .check_shape_change([2.5, 2.0, 1.0], &line, &towards)
        .is_err());
    // Rotating by 90 degrees away from the wall is fine.
    let side = Shape::line(4, std::f32::consts::FRAC_PI_2);
    assert_eq!(
        ctx.check_shape_change([2.5, 2.05, 1.0], &line, &side),
        Ok(())
    );
    // Head helpers.
    assert!(ctx.is_head_free([2.5, 2.0, 1.0]));
    assert!(!ctx.is_head_free([2.9, 2.0, 1.0]));
    assert!(ctx.is_head_segment_free([2.0, 0.5, 1.0], [2.0, 3.5, 1.0]));
    assert!(!ctx.is_head_segment_free([2.0, 2.0, 1.0], [3.5, 2.0, 1.0]));
    assert!((ctx.clearance([2.5, 2.0, 1.0]) - 0.5).abs() < 0.1);
    let st = ctx.stats();
    assert_eq!(st.configs, 6);
    assert_eq!(st.translations, 2);
    assert_eq!(st.shape_changes, 2);
    assert_eq!(st.head_points, 2);
    assert_eq!(st.head_segments, 2);
    ctx.reset_stats();
    assert_eq!(ctx.stats(), CheckStats::default());
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    let f = map(&[], true);
    let ctx = CollisionContext::new(f, ChainParams::new(4), 0.05).unwrap();
    let s5 = Shape::line(5, 0.0);
    let s4 = Shape::line(4, 0.0);
    assert!(matches!(
        ctx.check_config([1.0; 3], &s5),
        Err(Collision::BadInput(_))
    ));
    assert!(matches!(
        ctx.check_config([f64::NAN, 1.0, 1.0], &s4),
        Err(Collision::BadInput(_))
    ));
    assert!(ctx
        .check_translation([2.0; 3], [f64::INFINITY, 1.0, 1.0], &s4)
        .is_err());
    assert!(ctx.check_shape_change([2.0; 3], &s4, &s5).is_err());
    assert!(!ctx.is_head_free([f64::NAN; 3]));
    assert!(CollisionContext::new(map(&[], true), ChainParams::new(1), 0.0).is_err());
    assert!(CollisionContext::new(map(&[], true), ChainParams::new(4), -1.0).is_err());
}

#[test]
fn open_space_edges_are_cheap_and_pass() {
    let f = map(&[], false);
    let ctx = CollisionContext::new(f, ChainParams::new(6), 0.05).unwrap();
    let s = Shape::line(6, 0.0);
    assert_eq!(
        ctx.check_translation([3.6, 0.5, 1.0], [3.6, 3.5, 1.0], &s),
        Ok(())
    );
}

#[test]
fn exact_checker_finds_a_thin_post() {
    // A single voxel post the link passes through between units.
    let f = map(&[([1.25, 1.95, 0.0], [1.25, 1.95, 2.0])], true);
    let g = f.grid();
    let p = ChainParams::new(3);
    let s = Shape::line(3, 0.0);
    // Units at x = 1.5, 1.0, 0.5 (y 1.95): the link 1.5 -> 1.0 crosses the post at 1.25.
    let r = check_config_exact(g, &p, [1.5, 1.95, 1.0], &zeta([0.0; 3], &s)[3..], 0.5);
    assert!(
        matches!(
            r,
            Err(super::exact::ExactViolation::Map {
                body: Body::Link(0),
                ..
            })
        ),
        "{r:?}"
    );
    let ctx = CollisionContext::new(f.clone(), p, 0.0).unwrap();
    assert!(ctx.check_config([1.5, 1.95, 1.0], &s).is_err());
}

/// Random boxes inside the 4 x 4 x 2 map.
fn boxes() -> impl Strategy<Value = Vec<([f64; 3], [f64; 3])>> {
    proptest::collection::vec(
        (
            proptest::array::uniform3(0.0f64..1.0),
            proptest::array::uniform3(0.0f64..0.6),
        ),
        0..6,
    )
    .prop_map(|v| {
        v.into_iter()
            .map(|(c, s)| {
                let c = [c[0] * 4.0, c[1] * 4.0, c[2] * 2.0];
                (c, [c[0] + s[0], c[1] + s[1], c[2] + s[2]])
            })
            .collect()
    })
}

/// A random shape within the pitch limit (it may still self-collide or break the bend
/// limit: the checks must agree on that too).
/// Obstacle boxes: lower and upper corners (m).
type Boxes = Vec<([f64; 3], [f64; 3])>;

/// A random map (its obstacle boxes, whether unknown space is occupied) and chain
/// (`N`, and 31 numbers in `-1..1` for its shape: [`shape`]).
fn scene() -> impl Strategy<Value = (Boxes, bool, u8, Vec<f32>)> {
    (
        boxes(),
        any::<bool>(),
        2u8..7,
        proptest::collection::vec(-1.0f32..1.0, 31),
    )
}

/// The map and a context of chain `n` on it, with no clearance.
fn context(
    b: &[([f64; 3], [f64; 3])],
    unknown_occ: bool,
    n: u8,
) -> (Arc<DistanceField>, ChainParams, CollisionContext) {
    let f = map(b, unknown_occ);
    let p = ChainParams::new(n);
    let ctx = CollisionContext::new(f.clone(), p, 0.0).unwrap();
    (f, p, ctx)
}

/// A head position in the map's free interior from `u` in the unit cube.
fn head_at(u: [f64; 3]) -> [f64; 3] {
    [0.3 + u[0] * 3.4, 0.3 + u[1] * 3.4, 0.2 + u[2] * 1.6]
}

fn shape(n: u8, raw: &[f32]) -> Shape {
    let mut s = Shape::line(n, raw[0] * 3.1);
    for k in 0..n as usize - 1 {
        s.set_link(k, raw[1 + 2 * k] * 1.0, raw[0] * 3.1 + raw[2 + 2 * k] * 1.5);
    }
    s
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// The fast check never accepts a configuration the exact check rejects.
    #[test]
    fn fast_config_is_conservative(
        (b, unknown_occ, n, raw) in scene(),
        head in proptest::array::uniform3(0.0f64..1.0),
    ) {
        let (f, p, ctx) = context(&b, unknown_occ, n);
        let (s, h) = (shape(n, &raw), head_at(head));
        if ctx.check_config(h, &s).is_ok() {
            let z = zeta(h, &s);
            let r = check_config_exact(f.grid(), &p, h, &z[3..], 0.2);
            prop_assert!(r.is_ok(), "fast accepted, exact found {:?}", r);
        }
    }

    /// The fast edge checks never accept an edge whose exact sampling finds a problem.
    #[test]
    fn fast_edges_are_conservative(
        (b, unknown_occ, n, raw) in scene(),
        raw2 in proptest::collection::vec(-1.0f32..1.0, 31),
        head in proptest::array::uniform3(0.0f64..1.0),
        to in proptest::array::uniform3(0.0f64..1.0),
        translate in any::<bool>(),
    ) {
        let (f, p, ctx) = context(&b, unknown_occ, n);
        let (s, h) = (shape(n, &raw), head_at(head));
        if translate {
            let h2 = head_at(to);
            if ctx.check_translation(h, h2, &s).is_ok() {
                let r = check_edge_exact(f.grid(), &p, &zeta(h, &s), &zeta(h2, &s), 0.2);
                prop_assert!(r.is_ok(), "fast accepted translation, exact found {:?}", r);
            }
        } else {
            let s2 = shape(n, &raw2);
            if ctx.check_shape_change(h, &s, &s2).is_ok() {
                let r = check_edge_exact(f.grid(), &p, &zeta(h, &s), &zeta(h, &s2), 0.2);
                prop_assert!(r.is_ok(), "fast accepted shape change, exact found {:?}", r);
            }
        }
    }

    /// A shape change's answer is the map sweep's and the walk's together: looking at
    /// the shape halfway first refuses no change that both accept.
    #[test]
    fn a_shape_change_is_the_map_and_the_walk_together(
        (b, unknown_occ, n, raw) in scene(),
        raw2 in proptest::collection::vec(-1.0f32..1.0, 31),
        head in proptest::array::uniform3(0.0f64..1.0),
    ) {
        let (_, p, ctx) = context(&b, unknown_occ, n);
        let (s, s2, h) = (shape(n, &raw), shape(n, &raw2), head_at(head));
        let walk = check_transition(&p, &s, &s2, TRANSITION_MARGIN).is_ok();
        let both = walk && ctx.shape_change_map(h.into(), &s, &s2).is_ok();
        prop_assert_eq!(ctx.check_shape_change(h, &s, &s2).is_ok(), both);
    }
}

#[test]
fn contact_within_rounding_is_contact() {
    // A wall of cubes from x = 3.0; the head sphere's radius is r_u (f32 widened).
    let f = map(&[([3.05, 0.0, 0.0], [3.15, 4.0, 2.0])], true);
    let p = ChainParams::new(3);
    let eta = zeta([0.0; 3], &Shape::line(3, 0.0))[3..].to_vec();
    let r_u = p.unit_radius as f64;
    let at = |gap: f64| check_config_exact(f.grid(), &p, [3.0 - r_u - gap, 2.0, 1.0], &eta, 0.5);
    // 1e-12 m of computed clearance is rounding, not room: contact.
    assert!(
        matches!(at(1e-12), Err(super::exact::ExactViolation::Map { .. })),
        "{:?}",
        at(1e-12)
    );
    // A micrometre is room.
    let ok = at(1e-6).unwrap();
    assert!((ok.clearance - 1e-6).abs() < 1e-9, "{ok:?}");
}

/// The nearest obstacle cube by reading every voxel of the search box, in z, y, x
/// order, keeping the first of the nearest: what [`exact::nearest_obstacle`] must
/// give while it skips the blocks the grid proves empty.
fn nearest_by_every_voxel(
    grid: &Grid,
    a: Point3<f64>,
    b: Point3<f64>,
    reach: f64,
) -> Option<exact::Nearest> {
    let r = grid.resolution();
    let lo: Vec<i64> = (0..3)
        .map(|k| ((a[k].min(b[k]) - reach) / r).floor() as i64 - 1)
        .collect();
    let hi: Vec<i64> = (0..3)
        .map(|k| ((a[k].max(b[k]) + reach) / r).floor() as i64 + 1)
        .collect();
    let mut best: Option<exact::Nearest> = None;
    for z in lo[2]..=hi[2] {
        for y in lo[1]..=hi[1] {
            for x in lo[0]..=hi[0] {
                let i = [x as i32, y as i32, z as i32];
                if !grid.is_obstacle(i) {
                    continue;
                }
                let c = grid.voxel_center(i);
                let half = Vector3::repeat(0.5 * r);
                let d = match a == b {
                    true => exact::point_box_distance(a, c - half, c + half),
                    false => exact::segment_box_distance(a, b, c - half, c + half),
                };
                let limit = best.map_or(reach, |n| n.distance.min(reach));
                if d <= limit && best.is_none_or(|n| d < n.distance) {
                    best = Some(exact::Nearest {
                        distance: d,
                        voxel: c,
                    });
                }
            }
        }
    }
    best
}

/// A random small grid: dims, origin, a first fill, then one state per voxel (occupied
/// and unknown voxels each none, sparse or dense, so that whole blocks hold only one
/// kind), and the unknown rule.
fn small_grid() -> impl Strategy<Value = Grid> {
    (
        proptest::array::uniform3(1usize..14),
        proptest::array::uniform3(-6i32..6),
        proptest::collection::vec(0u16..1000, 1000),
        (0usize..3, 0usize..3),
        (any::<bool>(), 0usize..3),
    )
        .prop_map(|(dims, origin, draws, (occ, unk), (unknown_occ, fill))| {
            // Per mille of occupied and of unknown voxels.
            let (occ, unk) = ([0, 5, 100][occ], [0, 5, 100][unk]);
            let states: Vec<usize> = draws
                .iter()
                .map(|&d| match d {
                    d if d < occ => 0,
                    d if d < occ + unk => 1,
                    _ => 2,
                })
                .collect();
            // Every voxel is then written: from an unknown or occupied grid that carves
            // (and keeps the summary's counts through every change).
            let fill = [Cell::Free, Cell::Unknown, Cell::Occupied][fill];
            let mut g = Grid::new(0.1, origin, dims, fill, unknown_occ).unwrap();
            write_cycled(&mut g, &states, |s| {
                [Cell::Occupied, Cell::Unknown, Cell::Free][s]
            });
            g
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// Skipping the blocks the grid proves empty finds the same cube, at the same
    /// distance, as reading every voxel, inside the grid, across its faces and beyond.
    #[test]
    fn nearest_obstacle_skips_only_empty_blocks(
        grid in small_grid(),
        a in proptest::array::uniform3(-1.0f64..1.6),
        b in proptest::array::uniform3(-1.0f64..1.6),
        point in any::<bool>(),
        reach in 0.0f64..0.6,
    ) {
        let (a, b) = (Point3::from(a), Point3::from(if point { a } else { b }));
        let fast = exact::nearest_obstacle(&grid, a, b, reach);
        let every = nearest_by_every_voxel(&grid, a, b, reach);
        prop_assert_eq!(fast, every);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// `exact_clearance` keeps its contract against reading every voxel: the exact
    /// distance when it lies between `stop` and `cap`, else a value at or below `stop`,
    /// or at least `cap`; inside the grid, across its faces and beyond.
    #[test]
    fn exact_clearance_matches_every_voxel(
        grid in small_grid(),
        p in proptest::array::uniform3(-1.0f64..1.6),
        stop in -0.1f64..0.3,
        reach in 0.0f64..0.5,
    ) {
        let (p, cap) = (Point3::from(p), stop.max(0.0) + reach);
        let every = nearest_by_every_voxel(&grid, p, p, cap).map_or(cap, |n| n.distance);
        let fast = point_clearance::exact_clearance(&DistanceField::new(grid), p, stop, cap);
        if every <= stop {
            prop_assert!(fast <= stop, "{fast} > stop {stop} ({every})");
        } else if every >= cap {
            prop_assert!(fast >= cap, "{fast} < cap {cap} ({every})");
        } else {
            prop_assert_eq!(fast, every);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1000))]

    /// `exact_clearance_above` answers as `exact_clearance` does for the conservative
    /// checks, to the bit: its value when that is above `stop`, else `None`; inside the
    /// grid, across its faces and beyond, near `stop` and with caps past the grid.
    #[test]
    fn exact_clearance_above_is_exact_clearance(
        grid in small_grid(),
        p in proptest::array::uniform3(-1.0f64..1.6),
        stop in -0.1f64..0.4,
        reach in 0.0f64..0.8,
    ) {
        let (p, cap) = (Point3::from(p), stop.max(0.0) + reach);
        let field = DistanceField::new(grid);
        let e = point_clearance::exact_clearance(&field, p, stop, cap);
        let above = point_clearance::exact_clearance_above(&field, p, stop, cap);
        prop_assert_eq!(above.map(f64::to_bits), (e > stop).then_some(e.to_bits()));
    }

    /// `exact_distance` is `exact_clearance` with `stop` 0, to the bit, within a cube too.
    #[test]
    fn exact_distance_is_exact_clearance_from_zero(
        grid in small_grid(),
        p in proptest::array::uniform3(-1.0f64..1.6),
        cap in 0.0f64..0.8,
    ) {
        let p = Point3::from(p);
        let field = DistanceField::new(grid);
        let e = point_clearance::exact_clearance(&field, p, 0.0, cap);
        let d = point_clearance::exact_distance(&field, p, cap);
        prop_assert_eq!(d.to_bits(), e.to_bits());
    }
}

#[test]
fn exact_clearance_above_reads_rows_whose_gaps_saturate() {
    // Rows of 300 voxels at 0.01 m: a gap beyond 254 voxels saturates, and within the
    // cap such a row is read whole (by `exact_clearance`).
    let mut g = Grid::new(0.01, [0, 0, 0], [300, 3, 3], Cell::Free, false).unwrap();
    g.set([0, 1, 1], Cell::Occupied);
    g.set([299, 0, 0], Cell::Occupied);
    let field = DistanceField::new(g);
    let p = Point3::new(2.905, 0.015, 0.015);
    for (stop, cap) in [(0.0, 3.0), (0.0, 0.05), (2.9, 3.0), (0.1, 2.0)] {
        let e = point_clearance::exact_clearance(&field, p, stop, cap);
        let above = point_clearance::exact_clearance_above(&field, p, stop, cap);
        assert_eq!(above, (e > stop).then_some(e), "stop {stop} cap {cap}");
    }
    // The cube at x = 299 is 0.085 m along x and a voxel across in y and z.
    let d = point_clearance::exact_clearance_above(&field, p, 0.0, 0.2).unwrap();
    assert!(
        (d - (0.085f64.powi(2) + 2.0 * 0.005f64.powi(2)).sqrt()).abs() < 1e-12,
        "{d}"
    );
}

#[test]
fn nearest_obstacle_sees_voxels_set_after_a_search() {
    let mut g = Grid::new(0.1, [0, 0, 0], [20, 20, 20], Cell::Free, false).unwrap();
    let p = Point3::new(1.0, 1.0, 1.0);
    assert_eq!(exact::nearest_obstacle(&g, p, p, 0.3), None);
    // The summary made by that search must not hide what is set now.
    g.set([11, 10, 10], Cell::Occupied);
    let n = exact::nearest_obstacle(&g, p, p, 0.3).expect("the new voxel is 0.1 m away");
    assert!((n.distance - 0.1).abs() < 1e-12, "{n:?}");
    g.fill_box([0.5, 0.5, 0.5], [0.7, 0.7, 0.7], Cell::Occupied);
    let q = Point3::new(0.45, 0.6, 0.6);
    assert!(
        exact::nearest_obstacle(&g, q, q, 0.06).is_some_and(|n| (n.distance - 0.05).abs() < 1e-12)
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(500))]

    /// A free run is proven: all along a run that is not empty, from its start to its
    /// end, the moving point or segment keeps more than its radius from every obstacle
    /// cube (by reading every voxel), inside the grid, across its faces and beyond.
    #[test]
    fn a_free_run_keeps_the_body_clear(
        grid in small_grid(),
        a in proptest::array::uniform3(-1.0f64..1.6),
        along in proptest::array::uniform3(-0.4f64..0.4),
        point in any::<bool>(),
        dir in proptest::array::uniform3(-1.0f64..1.0),
        radius in 0.0f64..0.3,
        reach in 0.0f64..1.0,
    ) {
        let Some(dir) = Vector3::from(dir).try_normalize(1e-3) else {
            return Ok(());
        };
        let a = Point3::from(a);
        let b = if point { a } else { a + Vector3::from(along) };
        let field = DistanceField::new(grid);
        let run = sweep::free_run(&field, a, b, dir, radius, reach);
        prop_assert!((0.0..=reach).contains(&run), "{run} outside [0, {reach}]");
        for k in (0..=64).filter(|_| run > 0.0) {
            let s = run * k as f64 / 64.0;
            let hit = exact::nearest_obstacle(field.grid(), a + dir * s, b + dir * s, radius);
            prop_assert!(hit.is_none(), "at {s} of a run of {run}: {hit:?}");
        }
    }
}

#[test]
fn a_body_beside_a_wall_runs_along_it_and_stops_short_of_it() {
    // A wall of cubes x in [3.0, 3.2] across the whole box.
    let f = map(&[([3.05, 0.0, 0.0], [3.15, 4.0, 2.0])], true);
    let (along, towards) = (Vector3::y(), Vector3::x());
    let unit = Point3::new(2.75, 0.5, 1.0);
    // 0.25 m from the wall, radius 0.2: all the way along it.
    assert_eq!(sweep::free_run(&f, unit, unit, along, 0.2, 3.0), 3.0);
    // Towards it: stops where the sphere would come within 0.2 m, less rounding.
    let run = sweep::free_run(&f, unit, unit, towards, 0.2, 1.0);
    assert!((0.05 - 1e-6..0.05).contains(&run), "{run}");
    // A link parallel to the wall, 0.21 m off it, runs along it too; tilted to 0.19 m
    // at one end it is already within the radius.
    let (a, b) = (Point3::new(2.79, 0.5, 1.0), Point3::new(2.79, 0.5, 1.5));
    assert_eq!(sweep::free_run(&f, a, b, along, 0.2, 3.0), 3.0);
    let b = Point3::new(2.81, 0.5, 1.5);
    assert_eq!(sweep::free_run(&f, a, b, along, 0.2, 3.0), 0.0);
}
