//! Tests of easing (`super`).

use std::sync::Arc;
use std::time::Instant;

use aerial_chain_core::ChainParams;
use nalgebra::{Point3, Vector3};

use super::*;
use crate::map::grid::{Cell, Grid};
use crate::map::DistanceField;

/// A 4 x 4.5 x 2 m room at 0.1 m with a 0.2 m wall from the floor of the plan (y = 0)
/// to y = 3 at x = 2: a U-turn round its end, 1.5 m of room beyond it.
fn u_turn() -> CollisionContext {
    let mut g = Grid::new(0.1, [0, 0, 0], [40, 45, 20], Cell::Free, false).unwrap();
    g.fill_box([1.91, 0.0, 0.0], [2.09, 2.99, 2.0], Cell::Occupied);
    CollisionContext::new(Arc::new(DistanceField::new(g)), ChainParams::new(6), 0.05).unwrap()
}

/// The route through `points`.
fn route_of(points: &[[f64; 3]]) -> Vec<Point3<f64>> {
    points.iter().map(|&p| p.into()).collect()
}

/// A head route hugging the wall's end (0.35 m from it), as the search finds them.
fn hugging() -> Vec<Point3<f64>> {
    route_of(&[
        [1.0, 0.5, 1.0],
        [1.6, 3.0, 1.0],
        [2.0, 3.35, 1.0],
        [2.4, 3.0, 1.0],
        [3.0, 0.5, 1.0],
    ])
}

/// Between the samples the floors are kept at (every half voxel), a segment may pass
/// up to a quarter voxel nearer (the distance is 1-Lipschitz); the follower's exact
/// checks hold the clearance margin.
const BETWEEN: f64 = 0.1 / 4.0;

/// The least distance to the map along `route`, every 1 cm.
fn nearest(ctx: &CollisionContext, route: &[Point3<f64>]) -> f64 {
    resampled(route, 0.01)
        .iter()
        .map(|&p| distance(ctx, p))
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn a_bend_round_a_walls_end_opens_and_keeps_its_clearance() {
    let ctx = u_turn();
    let route = hugging();
    let lead = Some(Vector3::new(0.6, 2.5, 0.0).normalize() * -1.0);
    let eased = eased(&ctx, &route, lead, 100, None);
    assert_eq!(eased[0], route[0]);
    assert_eq!(eased[eased.len() - 1], route[4]);
    // Round the wall's end the bend opens from a corner to a radius of the reach
    // (r_u + c + l = 0.7 m) or more, within the 1.5 m beyond it.
    let (before, after) = (tightest_bend(&route, 0.25), tightest_bend(&eased, 0.25));
    assert!(
        before < 0.3,
        "the search's route turns on corners: {before}"
    );
    assert!(after >= 0.6, "eased, the tightest bend is {after} m");
    // No point of it comes nearer the map than the route did (every 1 cm, exactly).
    assert!(nearest(&ctx, &eased) + BETWEEN >= nearest(&ctx, &route).min(0.4));
    assert!(eased.iter().all(|&p| ctx.is_head_free(p)));
}

#[test]
fn a_route_down_a_passage_keeps_to_its_middle() {
    // A 0.9 m passage between two walls: the route enters 0.1 m off its middle and
    // leaves it on the middle; eased, every point inside keeps at least what the
    // route kept, and the middle third of it keeps to within 5 cm of the middle.
    let mut g = Grid::new(0.05, [0, 0, 0], [80, 40, 40], Cell::Free, false).unwrap();
    g.fill_box([1.0, 0.0, 0.0], [3.0, 0.55, 2.0], Cell::Occupied);
    g.fill_box([1.0, 1.45, 0.0], [3.0, 2.0, 2.0], Cell::Occupied);
    let ctx =
        CollisionContext::new(Arc::new(DistanceField::new(g)), ChainParams::new(4), 0.05).unwrap();
    let route = route_of(&[[0.3, 0.9, 1.0], [3.7, 1.0, 1.0]]);
    let eased = eased(&ctx, &route, None, 100, None);
    assert!(nearest(&ctx, &eased) + BETWEEN / 2.0 >= nearest(&ctx, &route));
    for p in resampled(&eased, 0.05) {
        if (1.67..=2.33).contains(&p.x) {
            assert!((p.y - 1.0).abs() <= 0.05, "{p:?} strays from the middle");
        }
    }
}

#[test]
fn past_its_deadline_the_route_keeps_its_ends_and_its_clearance() {
    let ctx = u_turn();
    let route = hugging();
    let eased = eased(&ctx, &route, None, 100, Some(Instant::now()));
    assert_eq!(eased[0], route[0]);
    assert_eq!(eased[eased.len() - 1], route[4]);
    assert!(nearest(&ctx, &eased) + BETWEEN >= nearest(&ctx, &route).min(0.4));
}

#[test]
fn resampling_steps_evenly_and_keeps_the_ends() {
    let route = route_of(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.33, 0.0]]);
    let r = resampled(&route, 0.05);
    assert_eq!(r[0], route[0]);
    assert_eq!(r[r.len() - 1], route[2]);
    // Every sample 0.05 m along the route from the one before (the last, the goal,
    // nearer); across the corner the chord is shorter than the length along.
    assert_eq!(r.len(), 28);
    for w in r[..r.len() - 1]
        .windows(2)
        .filter(|w| w[0].x < 1.0 - 1e-9 || w[0].y > 0.0)
    {
        assert!((w[1] - w[0]).norm() <= 0.05 + 1e-12);
    }
    assert!((r[20] - Point3::new(1.0, 0.0, 0.0)).norm() < 1e-12);
}

#[test]
fn densifying_keeps_every_vertex() {
    let route = route_of(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.7, 0.0]]);
    let r = densified(&route, 0.5);
    assert_eq!(r.len(), 5);
    assert_eq!(r[2], route[1]);
    assert_eq!(r[4], route[2]);
    assert!(r.windows(2).all(|w| (w[1] - w[0]).norm() <= 0.5 + 1e-12));
}
