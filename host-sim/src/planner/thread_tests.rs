//! Tests of threading (`super::thread`).

use super::*;
use crate::collision::verify::check_edge_exact;
use crate::map::grid::{Cell, Grid};
use crate::map::DistanceField;
use aerial_chain_core::ChainParams;
use std::sync::Arc;

/// A 0.15 m wall at x = 2 with a 0.5 m square window centred at y = z = 1.
fn window() -> (Grid, CollisionContext) {
    let mut g = Grid::new(0.05, [-20, -10, 0], [100, 60, 40], Cell::Free, false).unwrap();
    g.fill_box([2.01, -0.5, 0.0], [2.14, 2.5, 2.0], Cell::Occupied);
    g.fill_box([2.01, 0.76, 0.76], [2.14, 1.24, 1.24], Cell::Free);
    (g.clone(), context(g))
}

/// The context of a chain of 4 units at 0.05 m of clearance on `g`.
fn context(g: Grid) -> CollisionContext {
    CollisionContext::new(Arc::new(DistanceField::new(g)), ChainParams::new(4), 0.05).unwrap()
}

/// The head `route` with its pinches' axes put in, and the pinches.
fn straightened(ctx: &CollisionContext, route: &[[f64; 3]]) -> (Vec<Point3<f64>>, Vec<Pinch>) {
    let route: Vec<Point3<f64>> = route.iter().map(|&p| p.into()).collect();
    let s = ThreadSettings::default();
    Router { ctx, s: &s }.straightened(&route)
}

#[test]
fn an_oblique_crossing_is_threaded_through_the_middle() {
    let (grid, ctx) = window();
    // The head crosses the window 4 cm off its middle, 25 degrees off its axis
    // and turning there; the chain trails straight behind the first heading.
    let route = [[0.6, 0.4, 1.0], [2.07, 1.04, 1.02], [3.6, 1.8, 1.0]];
    let yaw = (0.64f32).atan2(1.47);
    let start = Shape::line(4, yaw);
    let raw: Vec<Step> = route
        .iter()
        .map(|&xi| Step {
            xi: xi.into(),
            shape: start,
            source: Source::Start,
            shape_change: false,
        })
        .collect();
    let threading = Threading::of(&ctx, &raw, &ThreadSettings::default()).expect("a pinch");
    let (out, _) = threading
        .follow(&ctx, &raw[0], 0.1, None)
        .expect("the window can be threaded");
    assert_eq!(out[0], raw[0]);
    assert_eq!(out[out.len() - 1].xi, raw[2].xi);
    // Every edge one kind, valid by the exact test, and every body keeps 90 % of
    // what the window's middle leaves a unit: (0.5 - 0.3) / 2 = 0.1 m.
    let params = *ctx.params();
    let narrowest = out
        .windows(2)
        .map(|w| check_edge_exact(&grid, &params, &zeta(&w[0]), &zeta(&w[1]), 1.0))
        .map(|r| r.expect("admissible"))
        .fold(f64::INFINITY, f64::min);
    assert!(narrowest >= 0.09, "narrowest {narrowest}");
    // The raw route passes 4 cm off the middle: its own share is well below.
    assert!(threading.measure(&ctx, &out, false).share >= 0.9);
    assert!(threading.measure(&ctx, &raw, false).share < 0.7);
}

#[test]
fn a_unit_about_to_enter_a_pinch_shortens_the_step() {
    let (_, ctx) = window();
    // The head in the window, the second unit 0.3 m before the wall: outside the
    // pinch, but a step of 0.1 m brings it in. The head turns 30 degrees off the
    // chain's axis, so a full step would carry that unit 5 cm off its track.
    let start = Step {
        xi: Point3::new(2.2, 1.0, 1.0),
        shape: Shape::line(4, 0.0),
        source: Source::Start,
        shape_change: false,
    };
    let f = Follower::new(&ctx, &start, 0.1, None, &ThreadSettings::default());
    let dir = Vector3::new(30f64.to_radians().cos(), 30f64.to_radians().sin(), 0.0);
    let ds = f.step_length(start.xi, &start.shape, dir);
    assert!(
        ds <= ThreadSettings::default().off_track * 0.05 / 0.5 + 1e-9,
        "step {ds}"
    );
    // Heading along the chain, nobody leaves their track: the whole step.
    let ds = f.step_length(start.xi, &start.shape, Vector3::x());
    assert_eq!(ds, 0.1);
}

#[test]
fn a_tunnel_axis_runs_through_the_middles_of_its_ends() {
    // A 1 m wall with a 0.55 m square tunnel, its axis at y = 0.975, z = 1.025,
    // entered 25 degrees off its axis and 8 cm off its middle.
    let mut g = Grid::new(0.05, [-20, -10, 0], [120, 60, 40], Cell::Free, false).unwrap();
    g.fill_box([2.01, -0.5, 0.0], [2.99, 2.5, 2.0], Cell::Occupied);
    g.fill_box([2.01, 0.71, 0.76], [2.99, 1.24, 1.29], Cell::Free);
    let route = [[0.6, 0.2, 1.0], [2.5, 1.05, 1.04], [4.4, 1.9, 1.0]];
    let (_, pinches) = straightened(&context(g), &route);
    assert_eq!(pinches.len(), 1);
    let p = pinches[0];
    // Both ends on the tunnel's axis, outside its mouths: a degree off over the
    // 2 m between them would put an end 2 cm off.
    for end in [p.a, p.b] {
        let off = ((end.y - 0.975).powi(2) + (end.z - 1.025).powi(2)).sqrt();
        assert!(off < 0.004, "{end:?} is {off} m off the axis");
    }
    assert!(p.a.x < 2.0 && p.b.x > 3.0, "{p:?}");
    assert!((p.middle - 0.125).abs() < 0.005, "{p:?}");
}

#[test]
fn a_pinch_becomes_its_axis_through_the_middle() {
    let (_, ctx) = window();
    let route = [[0.6, 0.4, 1.0], [2.07, 1.04, 1.02], [3.6, 1.8, 1.0]];
    let (out, pinches) = straightened(&ctx, &route);
    assert_eq!(pinches.len(), 1);
    assert!((pinches[0].middle - 0.1).abs() < 0.01, "{pinches:?}");
    let ends = (out[0], out[out.len() - 1]);
    assert_eq!(ends, (route[0].into(), route[2].into()));
    // Two points on the window's axis (y = z = 1), one on each side of the wall.
    let on_axis: Vec<_> = out
        .iter()
        .filter(|p| (p.y - 1.0).abs() < 0.02 && (p.z - 1.0).abs() < 0.02)
        .collect();
    assert_eq!(on_axis.len(), 2, "{out:?}");
    assert!(on_axis[0].x < 2.0 && on_axis[1].x > 2.15, "{on_axis:?}");
}

#[test]
fn a_wandering_route_pulled_into_a_band_is_smooth_free_and_keeps_its_ends() {
    let (_, ctx) = window();
    // Up and down by 0.2 m every 0.1 m, as a search's route wanders, but level
    // through the window (x = 2.0 .. 2.2).
    let route: Vec<Point3<f64>> = (0..=30)
        .map(|k| {
            let x = 0.6 + 0.1 * k as f64;
            let up = k % 2 == 1 && !(14..=16).contains(&k);
            Point3::new(x, 1.0, if up { 1.2 } else { 1.0 })
        })
        .collect();
    let s = ThreadSettings::default();
    let band = Router { ctx: &ctx, s: &s }.band(&route);
    assert_eq!(band[0], route[0]);
    assert_eq!(band.last(), route.last());
    assert!(band.iter().all(|p| ctx.is_head_free(*p)));
    // Total turning along the way: the band's is a small part of the route's.
    let turning = |r: &[Point3<f64>]| {
        r.windows(3)
            .filter_map(|w| {
                let (a, b) = (
                    (w[1] - w[0]).try_normalize(TIE)?,
                    (w[2] - w[1]).try_normalize(TIE)?,
                );
                Some(a.dot(&b).clamp(-1.0, 1.0).acos())
            })
            .sum::<f64>()
    };
    assert!(
        turning(&band) < 0.2 * turning(&route),
        "{} against {}",
        turning(&band),
        turning(&route)
    );
}
