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
//! follow-the-leader steps becomes as few steps as stay admissible.
//!
//! The look-ahead gallops (2, 4, 8, ... poses ahead, then bisects back), so a pose
//! costs a few checks; a budget of checks bounds the whole pass. Refinement counts
//! checks, not time, so it is deterministic: the same plan gives the same result.

use nalgebra::Point3;
use std::time::Instant;

use aerial_chain_core::angle;
use aerial_chain_core::cost::transition_cost;
use aerial_chain_core::lsc::LscEntry;
use aerial_chain_core::Shape;

use super::candidates::Source;
use super::widen::Widening;
use super::{ArcPlanner, Checker, Solution, Stats, Step};
use crate::collision::CollisionContext;

use super::numeric::{SAME_SHAPE, TIE, TINY};
use super::RefineSettings;

/// What a plan asks of the chain: the measures the flight time depends on.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Quality {
    /// Length of the head's path (m).
    pub head_path_m: f64,
    /// Total shape motion: over every shape change, the sum of the absolute wrapped
    /// differences of every angle of the shape (head yaw, link pitches and yaws), rad.
    pub shape_motion_rad: f64,
    /// Sum of the cost to transition `C_T` over every shape change (paper Eq. 3).
    pub shape_cost: f64,
    /// Number of shape changes.
    pub shape_changes: usize,
}

impl Quality {
    /// Adds `other`'s measures (plans flown one after the other).
    pub fn add(&mut self, other: &Quality) {
        self.head_path_m += other.head_path_m;
        self.shape_motion_rad += other.shape_motion_rad;
        self.shape_cost += other.shape_cost;
        self.shape_changes += other.shape_changes;
    }

    /// The measures of a plan's steps.
    pub fn of(steps: &[Step]) -> Self {
        let mut q = Self::default();
        for w in steps.windows(2) {
            let (a, b) = (&w[0], &w[1]);
            q.head_path_m += super::dist(a.xi, b.xi);
            if differs(&a.shape, &b.shape) {
                q.shape_changes += 1;
                q.shape_motion_rad += shape_motion(&a.shape, &b.shape);
                q.shape_cost += transition_cost(&a.shape, &b.shape) as f64;
            }
        }
        q
    }
}

/// What refinement did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Refinement {
    /// The plan as the search made it.
    pub before: Quality,
    /// The refined plan.
    pub after: Quality,
    /// Collision checks spent (before widening).
    pub checks: u64,
    /// What widening did (`super::widen`), the last stage.
    pub widening: Widening,
    /// Whether the plan is the search's head route threaded (`super::thread`).
    pub threaded: bool,
    /// The stretch of the plan flown in one library shape (`super::carry`), if any
    /// (a threaded plan has none).
    pub carried: Option<super::carry::Carried>,
    /// Time spent (s).
    pub time_s: f64,
}

/// The sum of the absolute wrapped differences of every angle from `a` to `b` (rad).
pub fn shape_motion(a: &Shape, b: &Shape) -> f64 {
    a.as_slice()
        .iter()
        .zip(b.as_slice())
        .map(|(&x, &y)| angle::diff(x, y).abs() as f64)
        .sum()
}

pub(super) fn differs(a: &Shape, b: &Shape) -> bool {
    a.max_angle_diff(b) > SAME_SHAPE
}

impl ArcPlanner {
    /// Refines a solved query's plan (see the module docs), then shortens its shape
    /// motion (`super::shorten`), both within `RefineSettings::check_budget` checks,
    /// then flies a
    /// stretch of it in one library shape where that moves the angles less
    /// (`super::carry`), then widens its narrow passages (`super::widen`), and takes
    /// the search's route threaded instead where that passes them nearer their middle
    /// (`super::thread`). The result starts and ends where the solution does and
    /// passes the same checks. Past `deadline` (the
    /// query's time limit) refinement stops and keeps what it has; only then can two
    /// runs differ.
    pub fn refine(
        &self,
        solution: &Solution<Stats>,
        deadline: Option<Instant>,
    ) -> (Solution<Stats>, Refinement) {
        let began = Instant::now();
        let raw = &solution.steps;
        let post = Post {
            ctx: &self.ctx,
            ctx_min: &self.ctx_min,
            lsc: &self.tables.lsc,
            follow_step: self.settings.follow_step,
            s: &self.refine,
        };
        // Threading depends on the search's plan alone until it is compared with the
        // other stages' result, so it is made beside them (rayon: on another core
        // where one is free). Made whether or not it will be compared: the result is
        // the same, and the wait is shorter.
        let ((chosen, steps, last), threading) = rayon::join(
            || {
                let mut chosen = post.refined_and_carried(raw, deadline);
                let (steps, last) = post.widened_again(&mut chosen, raw, deadline);
                (chosen, steps, last)
            },
            || post.threading(raw, deadline),
        );
        let first = chosen.first;
        let (steps, last, threaded) = post.threaded_if_better(threading, steps, last);
        let mut stats = solution.stats.clone();
        super::construction::count_sources(&steps, &mut stats);
        let report = Refinement {
            before: Quality::of(&solution.steps),
            after: Quality::of(&steps),
            checks: chosen.checks,
            widening: Widening {
                before: first.before,
                moves: if threaded {
                    last.moves
                } else {
                    chosen.first_moves.unwrap_or(0) + last.moves
                },
                ..last
            },
            threaded,
            carried: chosen.carried.filter(|_| !threaded),
            time_s: began.elapsed().as_secs_f64(),
        };
        (Solution { steps, stats }, report)
    }
}

/// What post-processing reads of the planner (which itself is not shared between
/// threads): the contexts it checks in, the library shapes, the follow step, the
/// tuning.
struct Post<'a> {
    ctx: &'a CollisionContext,
    ctx_min: &'a CollisionContext,
    lsc: &'a [LscEntry],
    follow_step: f64,
    s: &'a RefineSettings,
}

impl Post<'_> {
    /// Refinement's shortcuts and smaller changes, then shortening, over `poses`, with
    /// the checks of `ctx`; the steps and the checks spent.
    fn shortcut(
        &self,
        ctx: &CollisionContext,
        poses: &[Step],
        deadline: Option<Instant>,
    ) -> (Vec<Step>, u64) {
        let mut pass = Pass {
            checker: Checker::new(ctx.clone(), deadline),
            poses,
            checks: 0,
            s: self.s,
        };
        let steps = pass.run();
        let steps = pass.shrink_changes(steps);
        let steps = super::shorten::shorten(&mut pass, steps, self.s);
        (steps, pass.checks)
    }

    /// Refinement's shortcuts at the search's margin, beside widening the search's
    /// plan first (where it has the most stations to move) and then refining and
    /// shortening it without giving back what that won (`keep_margin`); the widened
    /// result is taken unless it asks for more shape motion (where a narrow door keeps
    /// the margin up, fewer shortcuts may pass). Then a stretch flown in one library
    /// shape, where that moves the angles less (`super::carry`).
    fn refined_and_carried(&self, raw: &[Step], deadline: Option<Instant>) -> Chosen {
        // The longer first: the plain shortcuts wait to be taken by a core that is
        // free (or run after it).
        let ((widened, first, kept), (plain, mut checks)) = rayon::join(
            || {
                let (widened, first) = super::widen::widen(
                    self.ctx,
                    self.ctx_min,
                    raw.to_vec(),
                    deadline,
                    &self.s.widen,
                );
                let kept = self.keep_margin(first.in_passages).map(|ctx| {
                    let (steps, spent) = self.shortcut(&ctx, &widened, deadline);
                    (steps, spent, ctx)
                });
                (widened, first, kept)
            },
            || self.shortcut(self.ctx, raw, deadline),
        );
        let mut chosen = (plain, self.ctx.clone(), None);
        if let Some((kept, spent, ctx)) = kept {
            checks += spent;
            let motion = |s: &[Step]| Quality::of(s).shape_motion_rad;
            if motion(&kept) <= motion(&chosen.0) * self.s.keep_motion + TIE {
                chosen = (kept, ctx, Some(first.moves));
            }
        }
        let mut carrier = Checker::new(chosen.1.clone(), deadline);
        let carried = super::carry::carried(&mut carrier, self.lsc, &chosen.0, &self.s.carry).map(
            |(steps, carried)| {
                chosen.0 = steps;
                carried
            },
        );
        let (steps, ctx, first_moves) = chosen;
        Chosen {
            steps,
            ctx,
            first_moves,
            widened,
            first,
            carried,
            checks,
        }
    }

    /// The last widening, of the other stages' result (taking its steps): where
    /// neither the widened plan was taken nor refinement changed the search's plan
    /// `raw`, it would repeat the first move for move, whose result is taken.
    fn widened_again(
        &self,
        chosen: &mut Chosen,
        raw: &[Step],
        deadline: Option<Instant>,
    ) -> (Vec<Step>, Widening) {
        let steps = std::mem::take(&mut chosen.steps);
        if chosen.first_moves.is_none() && steps == raw {
            (std::mem::take(&mut chosen.widened), chosen.first)
        } else {
            super::widen::widen(&chosen.ctx, self.ctx_min, steps, deadline, &self.s.widen)
        }
    }

    /// The search's head route threaded (`super::thread`) and how the threaded plan
    /// passes the route's pinches; `None` where the route has no pinch or the chain
    /// cannot follow it.
    fn threading(&self, raw: &[Step], deadline: Option<Instant>) -> Option<Threaded> {
        let threading = super::thread::Threading::of(self.ctx, raw, &self.s.thread)?;
        let (steps, _) = threading.follow(self.ctx, &raw[0], self.follow_step, deadline)?;
        let passing = threading.measure(self.ctx, &steps, true);
        Some(Threaded {
            threading,
            steps,
            passing,
        })
    }

    /// The threaded plan, where `steps` passes some pinch of the route off its middle
    /// (below the share widening aims for) and the threaded plan passes every pinch
    /// nearer its middle (`ThreadSettings::gain`, `share`) for little more shape
    /// motion (`motion`); else `steps`. Whether the threaded plan was taken
    /// is the last of the three.
    fn threaded_if_better(
        &self,
        threaded: Option<Threaded>,
        steps: Vec<Step>,
        widening: Widening,
    ) -> (Vec<Step>, Widening, bool) {
        let Some(Threaded {
            threading,
            steps: t,
            passing,
        }) = threaded
        else {
            return (steps, widening, false);
        };
        let share = threading.measure(self.ctx, &steps, false).share;
        if share >= self.s.widen.centred {
            return (steps, widening, false);
        }
        let links = self.ctx.params().links() as f64;
        let motion = |s: &[Step]| Quality::of(s).shape_motion_rad;
        let th = &self.s.thread;
        let affordable = motion(&t) <= motion(&steps) + links * th.motion;
        if passing.share >= th.share && passing.share > share + th.gain && affordable {
            // Widening the threaded plan gained one instance of 200 in `arc bench
            // robust` for a third more time: its units already pass in the middle.
            let tw = Widening {
                before: widening.before,
                after: passing.narrowest,
                in_passages: None,
                moves: 0,
            };
            (t, tw, true)
        } else {
            (steps, widening, false)
        }
    }

    /// The context post-processing checks in after the search's plan was widened to
    /// keep `narrowest` (m) through every passage (`None`: it passes none): where
    /// that is more than the preferred clearance (by `RefineSettings::keep_gain`), a
    /// context at that margin less `keep_slack`, so that a shortcut never passes an opening closer
    /// than the plan already does; else `None`, the search's own.
    fn keep_margin(&self, narrowest: Option<f64>) -> Option<CollisionContext> {
        let keep = narrowest? - self.s.keep_slack;
        if keep < self.ctx.clearance_margin() + self.s.keep_gain {
            return None;
        }
        let mut c =
            CollisionContext::new(self.ctx.field_arc().clone(), *self.ctx.params(), keep).ok()?;
        c.set_min_step(self.ctx.min_step());
        Some(c)
    }
}

/// The other stages' result, before the last widening: the steps and the context
/// they were checked in, with what led to them.
struct Chosen {
    /// Taken by the last widening (`Post::widened_again`), as is `widened`.
    steps: Vec<Step>,
    ctx: CollisionContext,
    /// The first widening's moves, when its plan was taken.
    first_moves: Option<usize>,
    /// The search's plan widened, and what that did.
    widened: Vec<Step>,
    first: Widening,
    carried: Option<super::carry::Carried>,
    /// Collision checks the shortcuts spent.
    checks: u64,
}

/// The search's head route threaded (`super::thread`): the route, the plan that
/// follows it, and how that plan passes the route's pinches.
struct Threaded {
    threading: super::thread::Threading,
    steps: Vec<Step>,
    passing: super::thread::Passing,
}

/// One refinement pass over a plan's poses.
struct Pass<'a> {
    checker: Checker,
    poses: &'a [Step],
    checks: u64,
    s: &'a RefineSettings,
}

impl Pass<'_> {
    fn run(&mut self) -> Vec<Step> {
        let last = self.poses.len() - 1;
        let mut out = vec![self.poses[0]];
        let mut i = 0;
        while i < last {
            match self.farthest(i) {
                Some((j, steps)) => {
                    out.extend(steps);
                    i = j;
                }
                None => {
                    out.push(self.poses[i + 1]);
                    i += 1;
                }
            }
        }
        out
    }

    fn exhausted(&self) -> bool {
        self.checks >= self.s.check_budget || super::expired(self.checker.deadline)
    }

    /// The farthest pose (beyond the next) reachable from pose `i` directly, with
    /// the steps that reach it: gallop ahead while jumps succeed, then bisect
    /// between the last success and the first failure.
    fn farthest(&mut self, i: usize) -> Option<(usize, Vec<Step>)> {
        let last = self.poses.len() - 1;
        if i + 2 > last || self.exhausted() {
            return None;
        }
        // A straight run to the end is the best there is; open space often allows it.
        if let Some(s) = self.jump(i, last) {
            return Some((last, s));
        }
        let mut best: Option<(usize, Vec<Step>)> = None;
        let mut k = 2;
        let mut fail = last;
        while i + k < last {
            match self.jump(i, i + k) {
                Some(s) => best = Some((i + k, s)),
                None => {
                    fail = i + k;
                    break;
                }
            }
            k *= 2;
        }
        let mut lo = best.as_ref().map_or(i + 1, |b| b.0);
        let mut hi = fail;
        while hi - lo > 1 && !self.exhausted() {
            let mid = lo + (hi - lo) / 2;
            match self.jump(i, mid) {
                Some(s) => {
                    best = Some((mid, s));
                    lo = mid;
                }
                None => hi = mid,
            }
        }
        best
    }

    /// The steps that take the chain from pose `i` to pose `j` directly, if any.
    fn jump(&mut self, i: usize, j: usize) -> Option<Vec<Step>> {
        if self.exhausted() {
            return None;
        }
        let (a, b) = (self.poses[i], self.poses[j]);
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
            return (change && self.shape_change(a.xi, &a.shape, &b.shape))
                .then(|| vec![change_at(a.xi)]);
        }
        // Keep the shape, translate, then change (or not) at the far end.
        if self.translation(a.xi, b.xi, &a.shape)
            && (!change || self.shape_change(b.xi, &a.shape, &b.shape))
        {
            let mut s = vec![translate(a.shape, a.source)];
            if change {
                s.push(change_at(b.xi));
            }
            return Some(s);
        }
        // Change here, then translate with the new shape.
        if change
            && self.shape_change(a.xi, &a.shape, &b.shape)
            && self.translation(a.xi, b.xi, &b.shape)
        {
            return Some(vec![change_at(a.xi), translate(b.shape, b.source)]);
        }
        None
    }

    /// Makes each shape change as small as the run of translations after it allows:
    /// a change `a -> b` followed by translations with `b` (and then, maybe, a change
    /// `b -> c`) becomes `a -> b'` with `b'` a share of the way from `a` to `b`
    /// (`RefineSettings::partial_shares`, the first that flies the whole run), when
    /// that moves the chain's angles less in total.
    fn shrink_changes(&mut self, mut steps: Vec<Step>) -> Vec<Step> {
        let mut k = 1;
        while k < steps.len() && !self.exhausted() {
            if steps[k].shape_change && !steps[k - 1].shape_change {
                let end = run_end(&steps, k);
                if let Some(shape) = self.smaller_change(&steps, k, end) {
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
    fn smaller_change(&mut self, steps: &[Step], k: usize, end: usize) -> Option<Shape> {
        let (a, b) = (steps[k - 1].shape, steps[k].shape);
        let next = steps.get(end + 1).map(|s| s.shape);
        let motion = |x: &Shape| shape_motion(&a, x) + next.map_or(0.0, |c| shape_motion(x, &c));
        let whole = motion(&b);
        for t in self.s.partial_shares {
            let c = a.lerp(&b, t);
            if motion(&c) + TINY >= whole || !self.flies_run(steps, k, end, &c) {
                continue;
            }
            return Some(c);
        }
        None
    }

    /// Whether `c` can replace the shape of steps `k..=end` (the change into it at
    /// step `k`, every translation of the run, and the change out of it after `end`).
    fn flies_run(&mut self, steps: &[Step], k: usize, end: usize, c: &Shape) -> bool {
        let prev = steps[k - 1].shape;
        if !self.shape_change(steps[k].xi, &prev, c) {
            return false;
        }
        for w in k..end {
            if !self.translation(steps[w].xi, steps[w + 1].xi, c) {
                return false;
            }
        }
        match steps.get(end + 1) {
            Some(n) => self.shape_change(steps[end].xi, c, &n.shape),
            None => true,
        }
    }

    fn translation(&mut self, a: Point3<f64>, b: Point3<f64>, s: &Shape) -> bool {
        self.checks += 1;
        self.checker.translation(a, b, s)
    }

    fn shape_change(&mut self, xi: Point3<f64>, s: &Shape, t: &Shape) -> bool {
        self.checks += 1;
        self.checker.shape_change(xi, s, t)
    }
}

impl super::shorten::Checks for Pass<'_> {
    fn translation(&mut self, a: Point3<f64>, b: Point3<f64>, s: &Shape) -> bool {
        Pass::translation(self, a, b, s)
    }

    fn shape_change(&mut self, xi: Point3<f64>, s: &Shape, t: &Shape) -> bool {
        Pass::shape_change(self, xi, s, t)
    }

    fn exhausted(&self) -> bool {
        Pass::exhausted(self)
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

#[cfg(test)]
mod tests {
    use super::*;

    fn step(xi: [f64; 3], yaw: f32, shape_change: bool) -> Step {
        Step {
            xi: xi.into(),
            shape: Shape::line(4, yaw),
            source: if shape_change {
                Source::Rotation
            } else {
                Source::Start
            },
            shape_change,
        }
    }

    #[test]
    fn quality_sums_path_and_wrapped_shape_motion() {
        let steps = [
            step([0.0, 0.0, 1.0], 3.0, false),
            step([0.0, 0.0, 1.0], -3.0, true),
            step([3.0, 4.0, 1.0], -3.0, false),
        ];
        let q = Quality::of(&steps);
        assert!((q.head_path_m - 5.0).abs() < 1e-12);
        assert_eq!(q.shape_changes, 1);
        // A line turned by 2 pi - 6 rad: head yaw and 3 link yaws, each wrapped.
        let d = (std::f64::consts::TAU - 6.0) as f32;
        assert!((q.shape_motion_rad - 4.0 * d as f64).abs() < 1e-4, "{q:?}");
        assert!(q.shape_cost > 0.0);
    }
}
