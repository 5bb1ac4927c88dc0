//! Plan refinement: after a query is solved, shortcut its waypoints where the chain
//! can still pass, so that plans fly with fewer and smaller shape changes.
//!
//! The planner's plans are sequences of poses (head position, shape) where each
//! step either changes the shape or translates the head (docs/model.md, "Motion
//! between two configurations"). Refinement walks the poses and, from the pose it
//! stands at, looks ahead for the farthest pose it can reach directly, in one of two
//! ways:
//! - keep the current shape, translate straight to the later pose's head position,
//!   then change to its shape there;
//! - change to the later pose's shape here, then translate there with it.
//!
//! Both are checked with the planner's conservative checks (the same clearance
//! margin as the search), so a refined plan is as admissible as the raw one and
//! keeps the same clearance from walls. Skipped poses take their shape changes with
//! them: a detour through another shape and back becomes one direct change or none,
//! consecutive translations with one shape become one, and a run of short
//! follow-the-leader steps becomes as few steps as stay admissible. Then each change
//! is made as small as the run of translations after it allows ([`shrink_changes`]).
//!
//! The look-ahead gallops (2, 4, 8, ... poses ahead, then bisects back), so a pose
//! costs a few checks; a budget of checks bounds the whole pass. Refinement counts
//! checks, not time, so it is deterministic: the same plan gives the same result.
//! Both passes are stages of post-processing (`super::pipeline`).

use std::time::Instant;

use nalgebra::Point3;

use aerial_chain_core::Shape;

use super::candidates::Source;
use super::checker::Checks;
use super::numeric::TINY;
use super::pipeline::{self, Refinement};
use super::plan_ops::{differs, farthest, shape_motion};
use super::{ArcPlanner, Solution, Stats, Step};

impl ArcPlanner {
    /// Post-processes a solved query's plan: the stages of `super::pipeline` in their
    /// declared order (shortcuts, smaller shape changes, shortening, carrying,
    /// widening, threading, and the choices between their results). The result
    /// starts and ends where the solution does and passes the same checks. Past
    /// `deadline` (the query's time limit) every stage stops and keeps what it has;
    /// only then can two runs differ.
    pub fn refine(
        &self,
        solution: &Solution<Stats>,
        deadline: Option<Instant>,
    ) -> (Solution<Stats>, Refinement) {
        let (steps, report) = pipeline::post_process(&self.post_context(&solution.steps, deadline));
        let mut stats = solution.stats.clone();
        super::construction::count_sources(&steps, &mut stats);
        (Solution { steps, stats }, report)
    }

    /// What post-processing's stages read of the planner, for the search's plan `raw`.
    pub(super) fn post_context<'a>(
        &'a self,
        raw: &'a [Step],
        deadline: Option<Instant>,
    ) -> pipeline::Context<'a> {
        pipeline::Context {
            ctx: &self.ctx,
            ctx_min: &self.ctx_min,
            lsc: &self.tables.lsc,
            follow_step: self.settings.follow_step,
            s: &self.refine,
            raw,
            deadline,
        }
    }
}

/// Refinement's shortcuts over `poses` (see the module docs), by `checks`.
pub(super) fn shortcut(checks: &mut impl Checks, poses: &[Step]) -> Vec<Step> {
    let last = poses.len() - 1;
    let mut out = vec![poses[0]];
    let mut i = 0;
    while i < last {
        match farthest_jump(checks, poses, i) {
            Some((j, steps)) => {
                out.extend(steps);
                i = j;
            }
            None => {
                out.push(poses[i + 1]);
                i += 1;
            }
        }
    }
    out
}

/// The farthest pose (beyond the next) reachable from pose `i` directly, with the
/// steps that reach it.
fn farthest_jump(checks: &mut impl Checks, poses: &[Step], i: usize) -> Option<(usize, Vec<Step>)> {
    let last = poses.len() - 1;
    if i + 2 > last || checks.exhausted() {
        return None;
    }
    // A straight run to the end is the best there is; open space often allows it.
    if let Some(s) = jump(checks, poses[i], poses[last]) {
        return Some((last, s));
    }
    // The next pose is reached anyway (the step to it is the plan's), and the last
    // was just refused.
    let mut best = None;
    let reaches = |j: usize| {
        if j == i + 1 || j == last {
            return j == i + 1;
        }
        let steps = jump(checks, poses[i], poses[j]);
        let ok = steps.is_some();
        if let Some(s) = steps {
            best = Some((j, s));
        }
        ok
    };
    farthest(i, last, reaches)?;
    best
}

/// The steps that take the chain from pose `a` to pose `b` directly, if any.
fn jump(checks: &mut impl Checks, a: Step, b: Step) -> Option<Vec<Step>> {
    if checks.exhausted() {
        return None;
    }
    let moved = super::dist(a.xi, b.xi) > 0.0;
    let change = differs(&a.shape, &b.shape);
    let translate = |shape: Shape, source: Source| Step {
        xi: b.xi,
        shape,
        source,
        shape_change: false,
    };
    let change_at = |xi: Point3<f64>| Step {
        xi,
        shape: b.shape,
        source: b.source,
        shape_change: true,
    };
    if !moved {
        return (change && checks.shape_change(a.xi, &a.shape, &b.shape))
            .then(|| vec![change_at(a.xi)]);
    }
    // Keep the shape, translate, then change (or not) at the far end.
    if checks.translation(a.xi, b.xi, &a.shape)
        && (!change || checks.shape_change(b.xi, &a.shape, &b.shape))
    {
        let mut s = vec![translate(a.shape, a.source)];
        if change {
            s.push(change_at(b.xi));
        }
        return Some(s);
    }
    // Change here, then translate with the new shape.
    if change
        && checks.shape_change(a.xi, &a.shape, &b.shape)
        && checks.translation(a.xi, b.xi, &b.shape)
    {
        return Some(vec![change_at(a.xi), translate(b.shape, b.source)]);
    }
    None
}

/// Makes each shape change as small as the run of translations after it allows:
/// a change `a -> b` followed by translations with `b` (and then, maybe, a change
/// `b -> c`) becomes `a -> b'` with `b'` a share of the way from `a` to `b`
/// (`shares`, the first that flies the whole run), when that moves the chain's
/// angles less in total.
pub(super) fn shrink_changes(
    checks: &mut impl Checks,
    mut steps: Vec<Step>,
    shares: &[f32],
) -> Vec<Step> {
    let mut k = 1;
    while k < steps.len() && !checks.exhausted() {
        if steps[k].shape_change && !steps[k - 1].shape_change {
            let end = run_end(&steps, k);
            if let Some(shape) = smaller_change(checks, &steps, k, end, shares) {
                for s in &mut steps[k..=end] {
                    (s.shape, s.source) = (shape, Source::Shrunk);
                }
            }
        }
        k += 1;
    }
    steps
}

/// For the change at `k` whose shape is flown up to step `end`, the smallest
/// partial change that flies the run and reaches the next shape (if any) with
/// less total motion.
fn smaller_change(
    checks: &mut impl Checks,
    steps: &[Step],
    k: usize,
    end: usize,
    shares: &[f32],
) -> Option<Shape> {
    let (a, b) = (steps[k - 1].shape, steps[k].shape);
    let next = steps.get(end + 1).map(|s| s.shape);
    let motion = |x: &Shape| shape_motion(&a, x) + next.map_or(0.0, |c| shape_motion(x, &c));
    let whole = motion(&b);
    for &t in shares {
        let c = a.lerp(&b, t);
        if motion(&c) + TINY >= whole || !flies_run(checks, steps, k, end, &c) {
            continue;
        }
        return Some(c);
    }
    None
}

/// Whether `c` can replace the shape of steps `k..=end` (the change into it at
/// step `k`, every translation of the run, and the change out of it after `end`).
fn flies_run(checks: &mut impl Checks, steps: &[Step], k: usize, end: usize, c: &Shape) -> bool {
    let prev = steps[k - 1].shape;
    if !checks.shape_change(steps[k].xi, &prev, c) {
        return false;
    }
    for w in k..end {
        if !checks.translation(steps[w].xi, steps[w + 1].xi, c) {
            return false;
        }
    }
    match steps.get(end + 1) {
        Some(n) => checks.shape_change(steps[end].xi, c, &n.shape),
        None => true,
    }
}

/// The last step of the run that flies the shape changed into at step `k`: the
/// translations after it, up to the next shape change or the end.
fn run_end(steps: &[Step], k: usize) -> usize {
    let mut end = k;
    while end + 1 < steps.len() && !steps[end + 1].shape_change {
        end += 1;
    }
    end
}
