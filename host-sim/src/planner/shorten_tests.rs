use super::*;
use crate::planner::plan_ops::Quality;
use nalgebra::Point3;

/// Checks from two rules, one for translations (by where they begin along x and the
/// shape flown) and one for
/// shape changes (by the shapes at both ends); every check is counted.
struct Rule<T: Fn(f64, &Shape) -> bool, C: Fn(&Shape, &Shape) -> bool> {
    translation: T,
    change: C,
    checks: usize,
}

impl<T: Fn(f64, &Shape) -> bool, C: Fn(&Shape, &Shape) -> bool> Checks for Rule<T, C> {
    fn translation(&mut self, a: Point3<f64>, _: Point3<f64>, s: &Shape) -> bool {
        self.checks += 1;
        (self.translation)(a[0], s)
    }
    fn shape_change(&mut self, _: Point3<f64>, s: &Shape, t: &Shape) -> bool {
        self.checks += 1;
        (self.change)(s, t)
    }
    fn exhausted(&self) -> bool {
        false
    }
}

/// Shortening's three stages in their pipeline order.
fn shorten(checks: &mut impl Checks, steps: Vec<Step>, s: &RefineSettings) -> Vec<Step> {
    let steps = replace_runs(checks, hold_yaw(steps), s);
    straightened(checks, steps)
}

fn rule(
    translation: impl Fn(f64, &Shape) -> bool,
    change: impl Fn(&Shape, &Shape) -> bool,
) -> Rule<impl Fn(f64, &Shape) -> bool, impl Fn(&Shape, &Shape) -> bool> {
    Rule {
        translation,
        change,
        checks: 0,
    }
}

/// A 4-unit shape with the given first and second link yaws (pitches 0, head yaw 0,
/// last link yaw 0).
fn bent(y0: f32, y1: f32) -> Shape {
    let mut s = Shape::line(4, 0.0);
    s.set_link(0, 0.0, y0);
    s.set_link(1, 0.0, y1);
    s
}

fn step(x: f64, shape: Shape, shape_change: bool) -> Step {
    Step {
        xi: Point3::new(x, 0.0, 1.0),
        shape,
        source: if shape_change {
            Source::Rotation
        } else {
            Source::Start
        },
        shape_change,
    }
}

/// A plan through `shapes` from x = 0: each a change where the head is, then a
/// translation 1 m along x (only the last one's when not `translate_between`).
fn plan(shapes: &[Shape], translate_between: bool) -> Vec<Step> {
    let mut x = 0.0;
    let mut out = vec![step(x, shapes[0], false)];
    for (k, &s) in shapes.iter().enumerate().skip(1) {
        out.push(step(x, s, true));
        if translate_between || k + 1 == shapes.len() {
            x += 1.0;
            out.push(step(x, s, false));
        }
    }
    out
}

fn motion(steps: &[Step]) -> f64 {
    Quality::of(steps).shape_motion_rad
}

/// The steps keep their ends and alternate sensibly: translations move the head,
/// changes do not.
fn well_formed(before: &[Step], after: &[Step]) {
    assert_eq!(after[0], before[0]);
    assert_eq!(after.last().unwrap().xi, before.last().unwrap().xi);
    for w in after.windows(2) {
        if w[1].shape_change {
            assert_eq!(w[0].xi, w[1].xi);
        } else {
            assert_eq!(w[0].shape.as_slice(), w[1].shape.as_slice());
        }
    }
}

#[test]
fn a_change_the_rest_of_the_plan_does_not_need_is_dropped() {
    let a = bent(0.0, 0.0);
    let b = bent(0.8, -0.8);
    let steps = plan(&[a, b], true);
    let mut checks = rule(|_, _| true, |_, _| true);
    let out = shorten(&mut checks, steps.clone(), &RefineSettings::default());
    well_formed(&steps, &out);
    assert!(motion(&steps) > 1.5);
    assert_eq!(motion(&out), 0.0);
    assert!(out.iter().all(|s| !s.shape_change));
}

#[test]
fn changes_at_one_point_merge_into_one_direct_change() {
    let (a, b, c) = (bent(0.0, 0.0), bent(1.0, 0.5), bent(0.3, 0.2));
    let steps = plan(&[a, b, c], false);
    // Only `c` flies the translation, and any change is admissible.
    let mut checks = rule(move |_, s| s.max_angle_diff(&c) < 1e-6, |_, _| true);
    let out = shorten(&mut checks, steps.clone(), &RefineSettings::default());
    well_formed(&steps, &out);
    assert_eq!(out.iter().filter(|s| s.shape_change).count(), 1);
    assert!((motion(&out) - shape_motion(&a, &c)).abs() < 1e-6);
    assert!(motion(&out) < motion(&steps));
}

#[test]
fn a_back_and_forth_is_clamped_between_its_neighbours() {
    // Link 0 yaw goes 0 -> 0.6 -> 0.3, link 1 yaw 0 -> 0.2 -> 0.5; the middle run
    // flies only with link 1 yaw in [0.1, 0.3], so neither neighbour's shape will do;
    // the last run flies only its own shape.
    let (a, b, c) = (bent(0.0, 0.0), bent(0.6, 0.2), bent(0.3, 0.5));
    let steps = plan(&[a, b, c], true);
    let mut checks = rule(
        move |x, s| match x < 0.5 {
            true => (0.1..=0.3).contains(&s.yaw(1)),
            false => s.max_angle_diff(&c) < 1e-6,
        },
        |_, _| true,
    );
    let out = shorten(&mut checks, steps.clone(), &RefineSettings::default());
    well_formed(&steps, &out);
    let mid = out[1].shape;
    assert!((mid.yaw(0) - 0.3).abs() < 1e-6 && (mid.yaw(1) - 0.2).abs() < 1e-6);
    assert!((motion(&out) - shape_motion(&a, &c)).abs() < 1e-5);
    assert!((motion(&steps) - 1.4).abs() < 1e-5 && motion(&out) < 0.81);
}

#[test]
fn the_last_shape_relaxes_back_as_far_as_the_passage_allows() {
    let (a, b) = (bent(0.0, 0.0), bent(1.0, 0.0));
    let steps = plan(&[a, b], true);
    // The translation needs link 0 turned by at least 0.4 rad.
    let mut checks = rule(|_, s| s.yaw(0) >= 0.4, |_, _| true);
    let out = shorten(&mut checks, steps.clone(), &RefineSettings::default());
    well_formed(&steps, &out);
    assert!(
        (out[1].shape.yaw(0) - 0.5).abs() < 1e-6,
        "{:?}",
        out[1].shape
    );
    assert!(motion(&out) < 0.51 && motion(&steps) > 0.99);
}

#[test]
fn the_head_yaw_is_held_and_a_turn_of_it_alone_disappears() {
    let a = bent(0.0, 0.0);
    let mut b = a;
    b.set_head_yaw(1.2);
    let mut c = bent(0.5, 0.5);
    c.set_head_yaw(-0.7);
    let steps = plan(&[a, b, c], true);
    // Every change rejected: only the hold, which needs no check, can act.
    let mut checks = rule(|_, s| s.yaw(0) > 0.25, |_, _| false);
    let out = shorten(&mut checks, steps.clone(), &RefineSettings::default());
    well_formed(&steps, &out);
    assert!(out.iter().all(|s| s.shape.head_yaw() == 0.0));
    assert_eq!(out.iter().filter(|s| s.shape_change).count(), 1);
    assert!((motion(&out) - 1.0).abs() < 1e-6);
}

#[test]
fn nothing_changes_where_no_check_passes() {
    let (a, b) = (bent(0.0, 0.0), bent(1.0, 0.0));
    let steps = plan(&[a, b], true);
    let mut checks = rule(|_, _| false, |_, _| false);
    let out = shorten(&mut checks, steps.clone(), &RefineSettings::default());
    let key = |s: &Step| (s.xi, s.shape, s.shape_change);
    assert_eq!(
        out.iter().map(key).collect::<Vec<_>>(),
        steps.iter().map(key).collect::<Vec<_>>()
    );
}
