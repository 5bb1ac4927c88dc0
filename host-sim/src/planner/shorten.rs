//! Shortening a plan's shape motion, after refinement has cut its waypoints.
//!
//! A plan is read as a sequence of runs: a shape, changed into where the run begins
//! (head fixed), then flown by the run's translations. Each run's shape (the start
//! run's aside) may be replaced by another that moves the chain's angles less in
//! total, `motion(prev, x) + motion(x, next)`, when the change into `x`, every
//! translation of the run with `x`, and the change out of `x` pass the planner's
//! checks (the same conservative checks and clearance as the search). The
//! replacements, cheapest in motion first:
//! - **drop**: `x` is the previous run's shape; the change into the run disappears
//!   (for the last run: a change the goal does not need);
//! - **merge**: `x` is the next run's shape; `prev -> cur -> next` becomes one direct
//!   change `prev -> next` where the run begins;
//! - **clamp**: every angle of `cur` clamped between its values in `prev` and `next`
//!   (the component-wise median): a back-and-forth of an angle across two changes
//!   becomes a monotone one, the least motion that still reaches `next`;
//! - **middle**: half way from `prev` to `next`, another shape of least motion;
//! - **relax**: a quarter, half or three quarters of the way from `cur` towards the
//!   clamped shape (or, for the last run, towards `prev`): as far back towards the
//!   neighbours as the passage allows.
//!
//! Before all that, the head's yaw is held at the start's through the whole plan: it
//! turns the units but moves no body and enters no limit (docs/model.md), so holding
//! it is as admissible as turning it, and saves that motion.
//!
//! The drop and merge of a run with no translation of its own merge consecutive shape
//! changes into one; together they replace chains of small follow-the-leader changes
//! by the fewest that stay admissible. Passes repeat while one improves the plan,
//! then the translations of each run are straightened where a direct one passes.
//! Everything is decided by checks in a fixed order, so it is deterministic.

use aerial_chain_core::{angle, Shape, MAX_SHAPE_DIM};
use nalgebra::Point3;

use super::candidates::Source;
use super::checker::Checks;
use super::plan_ops::{differs, shape_motion};
use super::{RefineSettings, Step};

/// One shape of the plan and where it is flown: changed into at `pts[0]` (the end of
/// the run before), then translated through `pts[1..]`.
#[derive(Clone, Debug, PartialEq)]
struct Run {
    shape: Shape,
    source: Source,
    pts: Vec<Point3<f64>>,
    /// The pass that last changed it (0: none).
    changed: usize,
}

/// The plan's steps with every shape's head yaw held at the start's (see
/// [`hold_head_yaw`]); makes no check.
pub(super) fn hold_yaw(steps: Vec<Step>) -> Vec<Step> {
    if steps.len() < 2 {
        return steps;
    }
    to_steps(&hold_head_yaw(to_runs(&steps)))
}

/// The plan's steps with less shape motion: each run's shape replaced (see the module
/// docs) in passes while one improves the plan. The start and the goal stay, and the
/// result passes the same checks as the input. Tuned by `s.shorten` and the shares
/// `s.partial_shares` (tried largest first).
pub(super) fn replace_runs(
    checks: &mut impl Checks,
    steps: Vec<Step>,
    s: &RefineSettings,
) -> Vec<Step> {
    if steps.len() < 2 {
        return steps;
    }
    let mut runs = to_runs(&steps);
    for pass in 1..=s.shorten.max_passes {
        let mut improved = false;
        let mut i = 1;
        while i < runs.len() && !checks.exhausted() {
            // Only where something changed in the pass before can a new replacement pass.
            let lo = i - 1;
            let hi = (i + 1).min(runs.len() - 1);
            if runs[lo..=hi].iter().all(|r| r.changed + 1 < pass) {
                i += 1;
                continue;
            }
            if let Some(x) = replacement(checks, &runs, i, s) {
                improved = true;
                // A drop or a merge joins two runs: look at the new run i again.
                if apply(&mut runs, i, x, pass) {
                    continue;
                }
            }
            i += 1;
        }
        if !improved {
            break;
        }
    }
    to_steps(&runs)
}

/// The plan's steps with the translations of each run straightened where a direct one
/// passes (see [`straighten`]).
pub(super) fn straightened(checks: &mut impl Checks, steps: Vec<Step>) -> Vec<Step> {
    if steps.len() < 2 {
        return steps;
    }
    let mut runs = to_runs(&steps);
    for r in &mut runs {
        straighten(checks, r);
    }
    to_steps(&runs)
}

/// The plan's steps as runs.
fn to_runs(steps: &[Step]) -> Vec<Run> {
    let mut runs = vec![Run {
        shape: steps[0].shape,
        source: steps[0].source,
        pts: vec![steps[0].xi],
        changed: 0,
    }];
    for s in &steps[1..] {
        if s.shape_change {
            let at = *runs
                .last()
                .and_then(|r| r.pts.last())
                .expect("runs hold points");
            runs.push(Run {
                shape: s.shape,
                source: s.source,
                pts: vec![at],
                changed: 0,
            });
        } else if let Some(r) = runs.last_mut() {
            r.pts.push(s.xi);
        }
    }
    runs
}

/// Runs back to steps: each run's change (the first run's start) then its translations.
fn to_steps(runs: &[Run]) -> Vec<Step> {
    let mut steps = Vec::new();
    for (k, r) in runs.iter().enumerate() {
        for (j, &xi) in r.pts.iter().enumerate() {
            if j == 0 && k > 0 {
                steps.push(Step {
                    xi,
                    shape: r.shape,
                    source: r.source,
                    shape_change: true,
                });
            } else if j > 0 || k == 0 {
                steps.push(Step {
                    xi,
                    shape: r.shape,
                    source: r.source,
                    shape_change: false,
                });
            }
        }
    }
    steps
}

/// Every run's head yaw set to the start's, and the changes that then change
/// nothing dropped. The head's yaw enters neither the bodies' positions nor the
/// limits (docs/model.md, "Configuration"): every check passes or fails alike with it
/// held, so none is repeated.
fn hold_head_yaw(runs: Vec<Run>) -> Vec<Run> {
    let yaw = runs[0].shape.head_yaw();
    let mut out: Vec<Run> = Vec::with_capacity(runs.len());
    for mut r in runs {
        r.shape.set_head_yaw(yaw);
        match out.last_mut() {
            Some(last) if !differs(&last.shape, &r.shape) => {
                last.pts.extend_from_slice(&r.pts[1..]);
            }
            _ => out.push(r),
        }
    }
    out
}

/// What the shape of run `i` is replaced by.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Replacement {
    /// The previous run's shape: the runs join.
    Drop,
    /// The next run's shape: the runs join.
    Merge,
    /// A new shape.
    Shape(Shape),
}

/// The first admissible replacement of run `i`'s shape, cheapest in motion first, if
/// any saves motion.
fn replacement(
    checks: &mut impl Checks,
    runs: &[Run],
    i: usize,
    s: &RefineSettings,
) -> Option<Replacement> {
    let saving = s.shorten.saving;
    let prev = runs[i - 1].shape;
    let cur = runs[i].shape;
    let next = runs.get(i + 1).map(|r| r.shape);
    let motion = |x: &Shape| shape_motion(&prev, x) + next.map_or(0.0, |n| shape_motion(x, &n));
    let now = motion(&cur);
    let target = match next {
        Some(n) => clamped(&cur, &prev, &n),
        None => prev,
    };
    let mut options = vec![(motion(&prev), Replacement::Drop)];
    let mut shapes = Vec::new();
    if let Some(n) = next {
        options.push((motion(&n), Replacement::Merge));
        shapes.extend([target, prev.lerp(&n, 0.5)]);
    }
    shapes.extend(s.partial_shares.iter().rev().map(|&t| cur.lerp(&target, t)));
    for mut x in shapes {
        // The head's yaw is held (see `hold_head_yaw`).
        x.set_head_yaw(prev.head_yaw());
        options.push((motion(&x), Replacement::Shape(x)));
    }
    // Stable, and motion equal within rounding counts as equal: ties keep the order
    // above (fewer changes first, then the shape nearest the current one).
    options.sort_by_key(|o| (o.0 / saving).round() as i64);
    for (m, r) in options {
        if m + saving > now || checks.exhausted() {
            break;
        }
        let x = match r {
            Replacement::Drop => prev,
            Replacement::Merge => next.expect("merge needs a next run"),
            Replacement::Shape(x) => x,
        };
        if flies(checks, runs, i, &x) {
            return Some(r);
        }
    }
    None
}

/// Whether `x` can be run `i`'s shape: the change into it (none if it is the previous
/// shape), every translation, and the change out (none if it is the next shape).
fn flies(checks: &mut impl Checks, runs: &[Run], i: usize, x: &Shape) -> bool {
    let r = &runs[i];
    let prev = &runs[i - 1].shape;
    // Changes first: a run's translations are most of its checks' cost.
    if differs(prev, x) && !checks.shape_change(r.pts[0], prev, x) {
        return false;
    }
    if let Some(n) = runs.get(i + 1) {
        let end = *r.pts.last().expect("runs hold points");
        if differs(x, &n.shape) && !checks.shape_change(end, x, &n.shape) {
            return false;
        }
    }
    r.pts.windows(2).all(|w| checks.translation(w[0], w[1], x))
}

/// Replaces run `i`'s shape in pass `pass`; true when it joined a neighbour whose
/// shape it takes.
fn apply(runs: &mut Vec<Run>, i: usize, x: Replacement, pass: usize) -> bool {
    match x {
        Replacement::Drop => {
            let r = runs.remove(i);
            runs[i - 1].pts.extend_from_slice(&r.pts[1..]);
            runs[i - 1].changed = pass;
            true
        }
        Replacement::Merge => {
            let n = runs.remove(i + 1);
            runs[i].pts.extend_from_slice(&n.pts[1..]);
            (runs[i].shape, runs[i].source) = (n.shape, n.source);
            runs[i].changed = pass;
            true
        }
        Replacement::Shape(s) => {
            (runs[i].shape, runs[i].source) = (s, Source::Shrunk);
            runs[i].changed = pass;
            false
        }
    }
}

/// Every angle of `cur` clamped between its values in `prev` and `next` (on the
/// shorter way round from `cur`): the median of the three, angle by angle.
fn clamped(cur: &Shape, prev: &Shape, next: &Shape) -> Shape {
    let mut eta = [0f32; MAX_SHAPE_DIM];
    let c = cur.as_slice();
    for (k, e) in eta.iter_mut().take(c.len()).enumerate() {
        let dp = angle::diff(c[k], prev.as_slice()[k]);
        let dn = angle::diff(c[k], next.as_slice()[k]);
        // The median of (dp, 0, dn): zero unless both lie on one side.
        let d = if dp > 0.0 && dn > 0.0 {
            dp.min(dn)
        } else if dp < 0.0 && dn < 0.0 {
            dp.max(dn)
        } else {
            0.0
        };
        *e = angle::wrap(c[k] + d);
    }
    Shape::from_slice(cur.units() as u8, &eta[..c.len()]).expect("same size as cur")
}

/// Drops the inner points of a run's translations where the chain can go straight
/// from the point before to the point after.
fn straighten(checks: &mut impl Checks, r: &mut Run) {
    let mut k = 1;
    while k + 1 < r.pts.len() && !checks.exhausted() {
        if checks.translation(r.pts[k - 1], r.pts[k + 1], &r.shape) {
            r.pts.remove(k);
        } else {
            k += 1;
        }
    }
}

#[cfg(test)]
#[path = "shorten_tests.rs"]
mod tests;
