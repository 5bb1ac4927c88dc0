//! Widening's tests: on a window and on an opening with a door behind it.

use super::measure::{distance, fails_near, keeps_above, measure, measure_whole, samples, Spot};
use super::*;
use crate::collision::exact::positions_f64;
use crate::map::grid::{Cell, Grid};
use crate::map::DistanceField;
use crate::planner::Source;
use crate::planner::WidenSettings;
use aerial_chain_core::{ChainParams, Shape};
use std::sync::Arc;

/// A 0.1 m wall at x = 2 with a 0.5 m square window centred at y = z = 1.
fn window() -> CollisionContext {
    let mut g = Grid::new(0.05, [-20, 0, 0], [100, 40, 40], Cell::Free, false).unwrap();
    g.fill_box([2.01, 0.0, 0.0], [2.09, 2.0, 2.0], Cell::Occupied);
    g.fill_box([2.01, 0.76, 0.76], [2.09, 1.24, 1.24], Cell::Free);
    let field = Arc::new(DistanceField::new(g));
    CollisionContext::new(field, ChainParams::new(3), 0.05).unwrap()
}

fn step(xi: [f64; 3], shape: &Shape) -> Step {
    Step {
        xi: xi.into(),
        shape: *shape,
        source: Source::Follow,
        shape_change: false,
    }
}

/// Widens `steps` in the window and checks what every widened plan must be: the
/// start and the goal where they were, the shapes kept, every edge admissible, and
/// the unit sphere (0.15 m) in the 0.5 m window from below 0.065 m to above 0.09 m
/// (0.1 m is the most it can keep). Returns the plan.
fn widened_in_the_window(steps: &[Step]) -> Vec<Step> {
    let ctx = window();
    assert!(steps.windows(2).all(|w| edge_passes(&ctx, &w[0], &w[1])));
    let (out, report) = widen(&ctx, &ctx, steps.to_vec(), None, &WidenSettings::default());
    let (first, last) = (&steps[0], &steps[steps.len() - 1]);
    assert_eq!((out[0].xi, out[out.len() - 1].xi), (first.xi, last.xi));
    assert!(out.iter().all(|s| s.shape == first.shape));
    assert!(report.before < 0.065 && report.after > 0.09, "{report:?}");
    assert!(out.windows(2).all(|w| edge_passes(&ctx, &w[0], &w[1])));
    out
}

/// A straight chain through the window 4 cm off its centre line in y and 3 cm in z.
fn off_centre() -> Vec<Step> {
    let straight = Shape::from_slice(3, &[0.0; 5]).unwrap();
    let (y, z) = (1.04, 0.97);
    [[0.4, 1.0, 1.0], [1.2, y, z], [3.6, y, z], [3.8, 1.0, 1.0]]
        .map(|xi| step(xi, &straight))
        .to_vec()
}

#[test]
fn an_off_centre_passage_moves_to_the_middle_and_stays_admissible() {
    let out = widened_in_the_window(&off_centre());
    assert!(out.len() >= 4);
}

#[test]
fn past_its_deadline_widening_moves_nothing_and_keeps_the_plan() {
    let ctx = window();
    let past = Some(std::time::Instant::now());
    std::thread::sleep(std::time::Duration::from_millis(2));
    let (out, report) = widen(&ctx, &ctx, off_centre(), past, &WidenSettings::default());
    assert_eq!(out, off_centre());
    assert_eq!(report.moves, 0);
    assert_eq!(report.before, report.after);
    // Without a deadline the same plan is widened (the test above): the deadline is
    // what stopped it.
    let (_, free) = widen(&ctx, &ctx, off_centre(), None, &WidenSettings::default());
    assert!(free.moves > 0);
}

#[test]
fn a_passage_between_start_and_goal_is_split_and_centred() {
    let straight = Shape::from_slice(3, &[0.0; 5]).unwrap();
    // One translation from the start to the goal, both of which stay.
    let out = widened_in_the_window(&[
        step([1.2, 1.04, 1.0], &straight),
        step([3.6, 1.04, 1.0], &straight),
    ]);
    assert_eq!(out.len(), 4, "{out:?}");
    assert!(out.iter().all(|s| !s.shape_change));
}

/// Refinement reuses the first widening's result where the second would get the
/// same plan in the same context: that holds only while widening is deterministic.
#[test]
fn the_same_plan_widens_the_same_way() {
    let ctx = window();
    let (a, ra) = widen(&ctx, &ctx, off_centre(), None, &WidenSettings::default());
    let (b, rb) = widen(&ctx, &ctx, off_centre(), None, &WidenSettings::default());
    assert!(ra.moves > 0);
    assert_eq!((a, ra), (b, rb));
}

/// A wall at x = 2 with an opening 0.5 m tall and 0.7 m wide centred at
/// y = z = 1, and 1 m further a second wall with a door 0.7 m wide centred at
/// y = 0.95 (z up to 1.8). A unit keeps 0.1 m in the opening's middle, and
/// 0.1 m anywhere within 0.1 m of it across; 0.2 m in the door's middle.
fn opening_and_door() -> CollisionContext {
    let mut g = Grid::new(0.05, [-20, 0, 0], [120, 40, 40], Cell::Free, false).unwrap();
    g.fill_box([2.01, 0.0, 0.0], [2.09, 2.0, 2.0], Cell::Occupied);
    g.fill_box([2.01, 0.66, 0.76], [2.09, 1.34, 1.24], Cell::Free);
    g.fill_box([3.01, 0.0, 0.0], [3.09, 2.0, 2.0], Cell::Occupied);
    g.fill_box([3.01, 0.61, 0.0], [3.09, 1.29, 1.79], Cell::Free);
    let field = Arc::new(DistanceField::new(g));
    CollisionContext::new(field, ChainParams::new(3), 0.05).unwrap()
}

/// The smallest unit clearance of `steps` where units are within 0.3 m of the
/// wall at `x` (m), sampled every centimetre of the head's path.
fn clearance_at_wall(ctx: &CollisionContext, steps: &[Step], x: f64) -> f64 {
    let r_u = ctx.params().unit_radius as f64;
    let mut least = f64::INFINITY;
    for w in steps.windows(2) {
        let n = ((w[1].xi - w[0].xi).norm() / 0.01).ceil().max(1.0) as usize;
        let eta: Vec<f64> = w[1].shape.as_slice().iter().map(|&v| v as f64).collect();
        for j in 0..=n {
            let head = w[0].xi + (w[1].xi - w[0].xi) * (j as f64 / n as f64);
            for p in positions_f64(0.5, head, &eta) {
                if (p.x - x).abs() < 0.3 {
                    least = least.min(distance(ctx, p) - r_u);
                }
            }
        }
    }
    least
}

/// One translation through the middle of the opening and 5 cm off the door's:
/// the edge's narrowest is in the opening, as wide as it gets there, so only the
/// second pass sees the door, and widens it without narrowing the opening.
#[test]
fn a_second_passage_on_the_same_translation_is_widened_too() {
    let ctx = opening_and_door();
    let straight = Shape::from_slice(3, &[0.0; 5]).unwrap();
    let steps: Vec<Step> = [
        [0.4, 1.0, 1.0],
        [1.2, 1.0, 1.0],
        [4.6, 1.0, 1.0],
        [4.7, 1.0, 1.0],
    ]
    .map(|xi| step(xi, &straight))
    .to_vec();
    assert!(steps.windows(2).all(|w| edge_passes(&ctx, &w[0], &w[1])));
    let door_before = clearance_at_wall(&ctx, &steps, 3.05);
    assert!(door_before < 0.16, "{door_before}");
    let (out, report) = widen(&ctx, &ctx, steps, None, &WidenSettings::default());
    assert!(out.windows(2).all(|w| edge_passes(&ctx, &w[0], &w[1])));
    let opening = clearance_at_wall(&ctx, &out, 2.05);
    let door = clearance_at_wall(&ctx, &out, 3.05);
    assert!(opening > 0.099, "opening {opening}");
    assert!(
        door >= WidenSettings::default().target_share * 0.2,
        "door {door}, before {door_before}"
    );
    assert!(report.moves > 0);
}

/// Moves are judged by `keeps_above`, which must agree with `measure` at every
/// floor: here translations through the window and past its frame, at floors
/// just below, at and just above each one's narrowest, and further off.
#[test]
fn keeps_above_agrees_with_measure() {
    let ctx = window();
    let straight = Shape::from_slice(3, &[0.0; 5]).unwrap();
    let turned = Shape::from_slice(3, &[0.4, 0.0, 0.3, 0.1, -0.2]).unwrap();
    let mut checked = 0;
    for (k, (y, z)) in [(1.0, 1.0), (1.04, 0.97), (1.09, 1.08), (0.8, 1.3)]
        .into_iter()
        .enumerate()
    {
        let shape = if k % 2 == 0 { straight } else { turned };
        let steps = [step([1.2, y, z], &shape), step([3.6, y, z], &shape)];
        let narrowest = measure_whole(&ctx, 0, &steps).clearance;
        for floor in [-1.0, -1e-3, -1e-5, 0.0, 1e-5, 1e-3, 0.02, 1.0].map(|d| narrowest + d) {
            let measured = measure(&ctx, 0, &steps, floor, |_| true).is_some();
            assert_eq!(
                keeps_above(&ctx, &samples(&ctx, 0, &steps, |_| true), floor),
                measured,
                "{k} {floor}"
            );
            checked += 1;
        }
    }
    assert_eq!(checked, 32);
}

/// `fails_near` settles a move only where `keeps_above` would fail it: translations
/// through the window moved a few centimetres each way, looked at by the unit and
/// sample where the unmoved edge was narrowest, at floors around that narrowest.
/// Most moves towards a wall fail there, so it settles some.
#[test]
fn fails_near_settles_only_moves_that_fail() {
    let ctx = window();
    let straight = Shape::from_slice(3, &[0.0; 5]).unwrap();
    let turned = Shape::from_slice(3, &[0.4, 0.0, 0.3, 0.1, -0.2]).unwrap();
    let (mut settled, mut failed) = (0, 0);
    for (k, shape) in [straight, turned].into_iter().enumerate() {
        let base = [
            step([1.2, 1.04, 0.97], &shape),
            step([3.6, 1.04, 0.97], &shape),
        ];
        let narrow = measure_whole(&ctx, 0, &base);
        for (dy, dz) in [
            (0.0, 0.0),
            (0.03, 0.0),
            (-0.03, 0.02),
            (0.0, -0.05),
            (0.06, 0.06),
        ] {
            let mut moved = base;
            moved[1].xi += Vector3::new(0.0, dy, dz);
            for floor in [-1e-3, 0.0, 1e-4, 5e-3, 0.02].map(|d| narrow.clearance + d) {
                let keeps = keeps_above(&ctx, &samples(&ctx, 0, &moved, |_| true), floor);
                let fails = fails_near(&ctx, 0, &moved, narrow.spot, floor);
                assert!(!(fails && keeps), "{k} ({dy}, {dz}) {floor}");
                failed += usize::from(!keeps);
                settled += usize::from(fails);
            }
        }
    }
    assert!(settled > 0 && failed > 0, "{settled} of {failed}");
}

/// An edge no move widens gives up the edges at its pinch that keep about as
/// little, and only those.
#[test]
fn an_edge_stuck_at_a_pinch_gives_up_its_neighbours_there() {
    let ctx = window();
    let at = |x: f64, clearance: f64| Narrowest {
        clearance,
        at: Point3::new(x, 1.0, 1.0),
        spot: Spot::default(),
    };
    let mut w = Widener {
        ctx: &ctx,
        ctx_min: &ctx,
        steps: Vec::new(),
        narrow: vec![
            at(2.0, 0.1),
            at(2.05, 0.102),
            at(2.0, 0.1 + WidenSettings::default().plateau + 1e-4),
            at(2.0 + WidenSettings::default().same_pinch + 0.01, 0.1),
            at(1.9, 0.09),
        ],
        stuck: vec![false; 5],
        deadline: None,
        spent: 0,
        splits: 0,
        s: &WidenSettings::default(),
    };
    w.stuck_at_pinch(0);
    assert_eq!(w.stuck, [true, true, false, false, true]);
}

#[test]
fn wide_plans_are_left_alone() {
    let ctx = window();
    let straight = Shape::from_slice(3, &[0.0; 5]).unwrap();
    let steps = vec![
        step([0.4, 1.0, 1.0], &straight),
        step([1.0, 1.0, 1.0], &straight),
        step([1.4, 1.0, 1.0], &straight),
    ];
    let (out, report) = widen(&ctx, &ctx, steps.clone(), None, &WidenSettings::default());
    assert_eq!(out, steps);
    assert_eq!(report.moves, 0);
    assert_eq!(report.before, CAP);
}
