use std::sync::Arc;

use aerial_chain_core::lsc::library;
use aerial_chain_core::ChainParams;

use super::*;
use crate::collision::CollisionContext;
use crate::map::grid::{Cell, Grid};
use crate::map::DistanceField;

/// The default tuning.
fn d() -> CarrySettings {
    CarrySettings::default()
}

/// A free box 6 m x 4 m x 3 m at 0.1 m, with a 0.2 m wall across x at x = 3 and a
/// 0.6 m square window in it centred at y = 2, z = 1.5 (no wall when `wall` is false).
fn room(wall: bool) -> CollisionContext {
    let mut g = Grid::new(0.1, [0, 0, 0], [60, 40, 30], Cell::Free, true).unwrap();
    if wall {
        g.fill_box([3.01, 0.0, 0.0], [3.19, 4.0, 3.0], Cell::Occupied);
        g.fill_box([3.01, 1.71, 1.21], [3.19, 2.29, 1.79], Cell::Free);
    }
    let field = Arc::new(DistanceField::new(g));
    CollisionContext::new(field, ChainParams::new(4), 0.05).unwrap()
}

/// `steps` carried in `ctx` with the library of its chain and the default tuning.
fn carry_in(ctx: &CollisionContext, steps: &[Step]) -> Option<(Vec<Step>, Vec<Carried>)> {
    let lsc = library(ctx.params()).entries;
    let mut checker = Checker::new(ctx.clone(), None);
    carried(&mut checker, &lsc, steps, &d(), &mut 0)
}

fn step(x: f64, shape: Shape, shape_change: bool) -> Step {
    Step {
        xi: Point3::new(x, 2.0, 1.5),
        shape,
        source: Source::Start,
        shape_change,
    }
}

/// A line trailing along -x, its links' yaws turned by `bend` alternately.
fn wiggle(bend: f32) -> Shape {
    let mut s = Shape::line(4, 0.0);
    for k in 0..3 {
        s.set_link(k, 0.0, if k % 2 == 0 { bend } else { -bend });
    }
    s
}

/// A plan along y = 2, z = 1.5 from x = 2 to x = 5 that bends and unbends three times.
fn restless_plan() -> Vec<Step> {
    let line = Shape::line(4, 0.0);
    let mut steps = vec![step(2.0, line, false)];
    for (k, x) in [2.5, 3.5, 4.5].into_iter().enumerate() {
        let bend = 0.2 + 0.1 * k as f32;
        steps.push(step(x - 0.5, wiggle(bend), true));
        steps.push(step(x, wiggle(bend), false));
        steps.push(step(x, line, true));
        steps.push(step(x + 0.5, line, false));
    }
    steps
}

#[test]
fn a_restless_plan_in_open_space_is_flown_in_its_start_shape() {
    let steps = restless_plan();
    assert!(Quality::of(&steps).shape_changes >= d().min_changes);
    let (out, carried) = carry_in(&room(false), &steps).expect("the line flies it all");
    assert_eq!(carried.len(), 1, "one stretch: {carried:?}");
    let carried = carried[0];
    assert_eq!(carried.kind, LscKind::Li);
    // No change at all: the line is the start shape, and the goal needs none.
    assert_eq!(Quality::of(&out).shape_changes, 0);
    assert_eq!(out[0], steps[0]);
    assert_eq!(out.last().map(|s| s.xi), steps.last().map(|s| s.xi));
    // Open space: one straight translation.
    assert_eq!(out.len(), 2);
    assert!((carried.head_path_m - 3.0).abs() < 1e-9);
}

#[test]
fn a_carried_plan_passes_the_checks_through_a_window() {
    let ctx = room(true);
    let steps = restless_plan();
    let (out, _) = carry_in(&ctx, &steps).expect("a line passes the window");
    assert_carried_plan_holds(&ctx, &steps, &out);
}

/// Whether the edge from `w[0]` to `w[1]` (a shape change or a translation) passes
/// the planner's checks.
fn edge_passes(ctx: &CollisionContext, w: &[Step]) -> bool {
    if w[1].shape_change {
        ctx.check_shape_change(w[0].xi, &w[0].shape, &w[1].shape)
            .is_ok()
    } else {
        ctx.check_translation(w[0].xi, w[1].xi, &w[1].shape).is_ok()
    }
}

/// Checks what every carried plan must be, by the planner's checks: the start and the
/// goal kept, each edge a shape change in place or a translation in one shape that
/// passes, and less shape motion than the plan it replaces.
fn assert_carried_plan_holds(ctx: &CollisionContext, steps: &[Step], out: &[Step]) {
    assert_eq!(out[0], steps[0]);
    assert_eq!(out.last().map(|s| s.xi), steps.last().map(|s| s.xi));
    for w in out.windows(2) {
        if w[1].shape_change {
            assert_eq!(w[0].xi, w[1].xi);
        } else {
            assert_eq!(w[0].shape, w[1].shape);
        }
        assert!(edge_passes(ctx, w), "{w:?}");
    }
    let motion = |s: &[Step]| Quality::of(s).shape_motion_rad;
    assert!(motion(out) + d().saving < motion(steps));
}

/// A plan along `y` through the window room: from x = 2 it bends at each of `before`
/// (x, bend) in the first room, straightens at x = 2.6, flies through the window as a
/// line, and bends at each of `after` in the second room before its goal at x = 5.7.
fn bent_plan(y: f64, before: &[(f64, f32)], after: &[(f64, f32)]) -> Vec<Step> {
    let line = Shape::line(4, 0.0);
    let mut steps = vec![step(2.0, line, false)];
    let bend_at = |x: f64, shape: Shape, steps: &mut Vec<Step>| {
        let last = *steps.last().expect("a start");
        if x > last.xi.x {
            steps.push(step(x, last.shape, false));
        }
        steps.push(step(x, shape, true));
    };
    for &(x, bend) in before {
        bend_at(x, wiggle(bend), &mut steps);
    }
    bend_at(2.6, line, &mut steps);
    for &(x, bend) in after {
        bend_at(x, wiggle(bend), &mut steps);
    }
    let last = steps.last().expect("a start").shape;
    steps.push(step(5.7, last, false));
    for s in &mut steps {
        s.xi.y = y;
    }
    steps
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(24))]

    /// Plans through the window that bend and unbend the chain at random places by
    /// random amounts in either room: whatever carrying makes of those that pass the
    /// checks keeps the start and the goal, passes the checks and moves the angles less.
    #[test]
    fn carried_plans_keep_their_ends_pass_the_checks_and_move_less(
        before in proptest::collection::vec((2.0f64..2.6, -0.6f32..0.6), 1..4),
        after in proptest::collection::vec((5.0f64..5.7, -0.6f32..0.6), 1..4),
        y in 1.92f64..2.08,
    ) {
        let ctx = room(true);
        let mut before = before;
        let mut after = after;
        before.sort_by(|a, b| a.0.total_cmp(&b.0));
        after.sort_by(|a, b| a.0.total_cmp(&b.0));
        let steps = bent_plan(y, &before, &after);
        let valid = steps.windows(2).all(|w| edge_passes(&ctx, w));
        proptest::prop_assume!(valid);
        if let Some((out, carried)) = carry_in(&ctx, &steps) {
            assert_carried_plan_holds(&ctx, &steps, &out);
            proptest::prop_assert!(carried.iter().all(|c| c.head_path_m > 0.0));
        }
    }
}

#[test]
fn plans_with_few_changes_are_left_alone() {
    let line = Shape::line(4, 0.0);
    let steps = vec![
        step(2.0, line, false),
        step(2.0, wiggle(0.3), true),
        step(3.0, wiggle(0.3), false),
        step(3.0, line, true),
        step(4.0, line, false),
    ];
    assert!(carry_in(&room(false), &steps).is_none());
}

#[test]
fn a_shape_across_the_window_does_not_fit_there_and_one_along_it_does() {
    let ctx = room(true);
    let mut checker = Checker::new(ctx, None);
    let line = Shape::line(4, 0.0);
    let steps = [
        step(2.0, line, false),
        step(2.5, line, false),
        step(3.5, line, false),
        step(4.5, line, false),
    ];
    let samples = RouteSamples::along(&checker.ctx, &steps);
    // Trailing along -x passes end first; trailing along -y lies across the window,
    // whose wall (x = 3.0..3.2) the second edge crosses.
    assert_eq!(
        misfit(&mut checker, &samples, 0..3, &line, d().fit_spacing),
        None
    );
    let across = Shape::line(4, std::f32::consts::FRAC_PI_2);
    assert_eq!(
        misfit(&mut checker, &samples, 0..3, &across, d().fit_spacing),
        Some(1)
    );
    // Away from the wall it fits.
    assert_eq!(
        misfit(&mut checker, &samples, 0..1, &across, d().fit_spacing),
        None
    );
}

#[test]
fn a_shape_that_cannot_take_the_window_still_takes_over_on_either_side_of_it() {
    let ctx = room(true);
    let bends =
        |x0: f64| [0.0, 0.1, 0.2, 0.3, 0.4].map(|dx| (x0 + dx, 0.5 - (dx * 10.0 % 2.0) as f32));
    let steps = bent_plan(2.0, &bends(2.0)[..4], &bends(5.0));
    let valid = steps.windows(2).all(|w| edge_passes(&ctx, w));
    assert!(valid, "the plan passes the checks");
    let crossing = steps
        .windows(2)
        .position(|w| w[0].xi.x < 3.0 && w[1].xi.x > 3.2)
        .expect("an edge through the window");
    let mut checker = Checker::new(ctx, None);
    let lsc = library(checker.ctx.params()).entries;
    let all = takeovers(&mut checker, &lsc, &steps, &d());
    let samples = RouteSamples::along(&checker.ctx, &steps);
    let split: Vec<&Takeover> = all
        .iter()
        .filter(|t| {
            misfit(
                &mut checker,
                &samples,
                0..steps.len() - 1,
                &t.x,
                d().fit_spacing,
            )
            .is_some()
        })
        .collect();
    assert!(split.iter().any(|t| t.j <= crossing), "before the window");
    assert!(split.iter().any(|t| t.i > crossing), "after it");
}

#[test]
fn the_guide_estimates_the_way_left_within_its_tube() {
    let route = [
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(2.0, 0.0, 0.0),
        Point3::new(2.0, 2.0, 0.0),
        Point3::new(4.0, 2.0, 0.0),
    ];
    // The middle of a shape 0.5 m behind its head along -x.
    let guide = Guide::new(&route, Vector3::new(-0.5, 0.0, 0.0), d().tube);
    // The start and the goal stay; the points between follow the shape's middle.
    assert_eq!(guide.points[0], route[0]);
    assert_eq!(guide.points[3], route[3]);
    assert_eq!(guide.points[1], Point3::new(2.5, 0.0, 0.0));
    let e = |p: [f64; 3]| guide.estimate(&p.into());
    assert_eq!(e([4.0, 2.0, 0.0]), Some(0.0));
    let total = guide.rest[0];
    assert!((e([0.0, 0.0, 0.0]).unwrap() - total).abs() < 1e-12);
    // Nearer the goal along the guide, less is left.
    assert!(e([2.5, 1.0, 0.0]).unwrap() < e([1.0, 0.0, 0.0]).unwrap());
    // Off to the side by more than the tube: not searched.
    assert_eq!(e([1.0, -1.5, 0.0]), None);
    assert!(e([1.0, -0.9, 0.0]).is_some());
}

#[test]
fn lattice_keys_are_distinct_around_the_origin() {
    let mut keys: Vec<u64> = neighbours([0, 0, 0]).map(pack).collect();
    keys.push(pack([0, 0, 0]));
    keys.push(pack([-1_000, 2_000, -3_000]));
    keys.push(pack([1_000, -2_000, 3_000]));
    let n = keys.len();
    keys.sort_unstable();
    keys.dedup();
    assert_eq!(keys.len(), n);
}

#[test]
fn library_shapes_come_once_each_least_motion_first() {
    let params = ChainParams::new(4);
    let lsc = library(&params).entries;
    let start = Shape::line(4, 0.3);
    let shapes = shapes(&lsc, &start, d().headings);
    let motion: Vec<f64> = shapes.iter().map(|s| shape_motion(&start, &s.0)).collect();
    assert!(motion.windows(2).all(|w| w[0] <= w[1]));
    assert!(shapes.iter().all(|s| s.0.head_yaw() == start.head_yaw()));
    for (a, x) in shapes.iter().enumerate() {
        assert!(shapes[a + 1..]
            .iter()
            .all(|y| y.0.max_angle_diff(&x.0) > 1e-5));
    }
    assert!(shapes.len() > lsc.len());
}

/// A wall at x = 3.0..3.1 with a 0.5 m square hole whose middle (y = 2.05, z = 1.5) is
/// on the lattice through (2, 1.9, 1.5) at 0.05 m but not at 0.1 m: a unit passes it
/// only within 5 cm of the middle, at the 0.05 m margin.
fn slot() -> CollisionContext {
    let mut g = Grid::new(0.05, [0, 0, 0], [120, 80, 60], Cell::Free, true).unwrap();
    g.fill_box([3.01, 0.0, 0.0], [3.09, 4.0, 3.0], Cell::Occupied);
    g.fill_box([3.01, 1.81, 1.26], [3.09, 2.29, 1.74], Cell::Free);
    let field = Arc::new(DistanceField::new(g));
    CollisionContext::new(field, ChainParams::new(2), 0.05).unwrap()
}

#[test]
fn a_slot_between_coarse_lattice_points_is_closed_there_and_found_on_the_fine_one() {
    let ctx = slot();
    let mut checker = Checker::new(ctx.clone(), None);
    let line = Shape::line(2, 0.0);
    let route = [Point3::new(2.0, 1.9, 1.5), Point3::new(4.5, 2.05, 1.5)];
    let guide = Guide::new(&route, Vector3::zeros(), d().tube);
    let (coarse, _) = search(
        &mut checker,
        &guide,
        &line,
        0.1,
        d().search_points,
        d().greed,
    );
    assert!(matches!(coarse, Found::Closed));
    let (fine, _) = search(
        &mut checker,
        &guide,
        &line,
        0.05,
        d().search_points,
        d().greed,
    );
    let Found::Path(path) = fine else {
        panic!("the fine lattice passes the slot");
    };
    assert_eq!(path[0], route[0]);
    assert_eq!(path[path.len() - 1], route[1]);
    let path = taut(&mut checker, &path, &line).expect("its steps pass the checks");
    for w in path.windows(2) {
        assert!(ctx.check_translation(w[0], w[1], &line).is_ok());
    }
}
