//! The stages of post-processing, each over the module that does its work
//! (docs/postprocessing.md describes them in the order `super::post_processing`
//! runs them).

use std::sync::Arc;

use super::{Budget, Context, Draft, Stage, Unit};
use crate::collision::CollisionContext;
use crate::planner::checker::{Checker, Counted};
use crate::planner::ease;
use crate::planner::numeric::TIE;
use crate::planner::plan_ops::Quality;
use crate::planner::thread::{Passing, Threading};
use crate::planner::widen::{widen, Widening};
use crate::planner::{carry, refine, shorten, Step};

/// Runs `f` on `draft`'s steps with checks in its context that count against the
/// budget the check-counting stages share (`RefineSettings::check_budget`): each
/// takes over the count the one before it left.
fn counted(
    mut draft: Draft,
    cx: &Context,
    f: impl FnOnce(&mut Counted, Vec<Step>) -> Vec<Step>,
) -> (Draft, Budget) {
    let spent = draft.checks;
    let limit = cx.s.check_budget;
    let mut checks = Counted::new(draft.ctx.clone(), cx.deadline, spent, limit);
    draft.steps = f(&mut checks, std::mem::take(&mut draft.steps));
    draft.checks = checks.checks;
    let budget = Budget {
        unit: Unit::Checks,
        limit: limit.saturating_sub(spent),
        used: checks.checks - spent,
    };
    (draft, budget)
}

/// Refinement's shortcuts (`refine::shortcut`).
pub(super) struct Shortcut;

impl Stage for Shortcut {
    fn name(&self) -> &'static str {
        "shortcut"
    }

    fn run(&self, draft: Draft, cx: &Context) -> (Draft, Budget) {
        counted(draft, cx, |c, steps| refine::shortcut(c, &steps))
    }
}

/// Each shape change made as small as the run after it allows
/// (`refine::shrink_changes`).
pub(super) struct ShrinkChanges;

impl Stage for ShrinkChanges {
    fn name(&self) -> &'static str {
        "shrink-changes"
    }

    fn run(&self, draft: Draft, cx: &Context) -> (Draft, Budget) {
        let shares = cx.s.partial_shares;
        counted(draft, cx, |c, steps| {
            refine::shrink_changes(c, steps, &shares)
        })
    }
}

/// The start's head yaw held through the plan (`shorten::hold_yaw`): no check, as
/// the head's yaw moves no body.
pub(super) struct HoldYaw;

impl Stage for HoldYaw {
    fn name(&self) -> &'static str {
        "hold-yaw"
    }

    fn run(&self, mut draft: Draft, _: &Context) -> (Draft, Budget) {
        draft.steps = shorten::hold_yaw(std::mem::take(&mut draft.steps));
        (draft, Budget::NONE)
    }
}

/// Each run's shape replaced by one that moves the angles less
/// (`shorten::replace_runs`).
pub(super) struct ReplaceRuns;

impl Stage for ReplaceRuns {
    fn name(&self) -> &'static str {
        "replace-runs"
    }

    fn run(&self, draft: Draft, cx: &Context) -> (Draft, Budget) {
        counted(draft, cx, |c, steps| shorten::replace_runs(c, steps, cx.s))
    }
}

/// Each run's translations straightened (`shorten::straightened`).
pub(super) struct Straighten;

impl Stage for Straighten {
    fn name(&self) -> &'static str {
        "straighten"
    }

    fn run(&self, draft: Draft, cx: &Context) -> (Draft, Budget) {
        counted(draft, cx, shorten::straightened)
    }
}

/// The budget of a widening that spent `w.measured` edge measurements.
fn measurements(cx: &Context, w: &Widening) -> Budget {
    Budget {
        unit: Unit::EdgeMeasurements,
        limit: cx.s.widen.budget as u64,
        used: w.measured as u64,
    }
}

/// Widens `draft`'s plan in its context (`super::super::widen`), notes what that did
/// on it by `note`, and gives it with the budget spent.
fn widened(
    mut draft: Draft,
    cx: &Context,
    note: impl FnOnce(&mut Draft, Widening),
) -> (Draft, Budget) {
    let steps = std::mem::take(&mut draft.steps);
    let (steps, w) = widen(&draft.ctx, cx.ctx_min, steps, cx.deadline, &cx.s.widen);
    draft.steps = steps;
    note(&mut draft, w);
    (draft, measurements(cx, &w))
}

/// The search's plan widened (`super::super::widen`), where it has the most stations
/// to move; the result is noted for `WidenAgain` and the report.
pub(super) struct WidenFirst;

impl Stage for WidenFirst {
    fn name(&self) -> &'static str {
        "widen"
    }

    fn run(&self, draft: Draft, cx: &Context) -> (Draft, Budget) {
        widened(draft, cx, |d, w| {
            d.notes.first_widening = Some(Arc::new((d.steps.clone(), w)));
        })
    }
}

/// The context the later stages of the lane check in, so that a shortcut never
/// gives back what the first widening won: a margin of the narrowest clearance it
/// left in the passages less `RefineSettings::keep_slack`, where that is
/// `keep_gain` or more above the search's. Else the lane is given up.
pub(super) struct KeepMargin;

impl Stage for KeepMargin {
    fn name(&self) -> &'static str {
        "keep-margin"
    }

    fn run(&self, mut draft: Draft, cx: &Context) -> (Draft, Budget) {
        let in_passages = draft
            .notes
            .first_widening
            .as_ref()
            .and_then(|f| f.1.in_passages);
        match kept_context(cx, in_passages) {
            Some(ctx) => draft.ctx = ctx,
            None => draft.notes.withdrawn = true,
        }
        (draft, Budget::NONE)
    }
}

/// A context at the margin `narrowest` (m) less `keep_slack`, when that is more than
/// the search's by `keep_gain` (`None`: no passage, or too little gained).
fn kept_context(cx: &Context, narrowest: Option<f64>) -> Option<CollisionContext> {
    let keep = narrowest? - cx.s.keep_slack;
    if keep < cx.ctx.clearance_margin() + cx.s.keep_gain {
        return None;
    }
    let mut c = CollisionContext::new(cx.ctx.field_arc().clone(), *cx.ctx.params(), keep).ok()?;
    c.set_min_step(cx.ctx.min_step());
    Some(c)
}

/// A stretch flown in one library shape where that moves the angles less
/// (`super::super::carry`), in the plan's context.
pub(super) struct Carry;

impl Stage for Carry {
    fn name(&self) -> &'static str {
        "carry"
    }

    fn run(&self, mut draft: Draft, cx: &Context) -> (Draft, Budget) {
        let mut checker = Checker::new(draft.ctx.clone(), cx.deadline);
        let mut spent = 0;
        let found = carry::carried(&mut checker, cx.lsc, &draft.steps, &cx.s.carry, &mut spent);
        if let Some((steps, carried)) = found {
            draft.steps = steps;
            draft.notes.carried = carried;
        }
        let budget = Budget {
            unit: Unit::Placements,
            limit: cx.s.carry.total_points as u64,
            used: spent as u64,
        };
        (draft, budget)
    }
}

/// The last widening, of the other stages' result in its context. Where the first
/// widening's lane was not kept and the plan is still the search's, it would repeat
/// the first widening move for move: that result is taken, at no cost.
pub(super) struct WidenAgain;

impl Stage for WidenAgain {
    fn name(&self) -> &'static str {
        "widen-again"
    }

    fn run(&self, mut draft: Draft, cx: &Context) -> (Draft, Budget) {
        let first = draft.notes.first_widening.clone();
        if let Some(first) = first.filter(|_| draft.notes.kept_moves.is_none()) {
            if draft.steps == cx.raw {
                draft.steps = first.0.clone();
                draft.notes.widening = first.1;
                let used = Budget {
                    used: 0,
                    ..measurements(cx, &first.1)
                };
                return (draft, used);
            }
        }
        widened(draft, cx, |d, w| d.notes.widening = w)
    }
}

/// The search's head route threaded through its pinches and followed by the chain
/// (`super::super::thread`); the lane is given up where the route has no pinch or
/// the chain cannot follow it.
pub(super) struct Thread;

impl Stage for Thread {
    fn name(&self) -> &'static str {
        "thread"
    }

    fn run(&self, mut draft: Draft, cx: &Context) -> (Draft, Budget) {
        let mut budget = Budget {
            unit: Unit::Steps,
            limit: cx.s.thread.max_steps as u64,
            used: 0,
        };
        let Some(mut threading) = Threading::of(&draft.ctx, &draft.steps, &cx.s.thread) else {
            draft.notes.withdrawn = true;
            return (draft, budget);
        };
        // Where the plan's own route cannot be followed (it wanders where the search
        // tried shape after shape, or hugs corners), the route pulled into a band.
        let start = &draft.steps[0];
        let mut r = threading.follow(&draft.ctx, start, cx.follow_step, cx.deadline);
        if r.is_err() {
            if let Some(banded) = Threading::banded(&draft.ctx, &draft.steps, &cx.s.thread) {
                let again = banded.follow(&draft.ctx, start, cx.follow_step, cx.deadline);
                if again.is_ok() {
                    (threading, r) = (banded, again);
                }
            }
        }
        let mut r = r.map(|(steps, _)| {
            let p = threading.measure(&draft.ctx, &steps, true);
            (steps, p)
        });
        if let Ok((steps, passing)) = &r {
            if let Some((t, e)) = eased_if_better(&threading, steps, passing, &draft.ctx, cx) {
                (threading, r) = (t, Ok(e));
            }
        }
        match r {
            Ok((steps, passing)) => {
                budget.used = steps.len() as u64;
                draft.notes.threading = Some(Arc::new((threading, passing)));
                draft.steps = steps;
            }
            Err(made) => {
                budget.used = made as u64;
                draft.notes.withdrawn = true;
            }
        }
        (draft, budget)
    }
}

/// The route `threading` the chain followed in `steps` (passing as `passing`), eased
/// (`super::super::ease`: its bends opened, as a follower turns every link through
/// each), and the chain following that, where: the route bends tighter than easing's
/// reach (else easing leaves it as it is); the eased route turns no more than
/// `thread.motion` beyond it, seen a link at a time (a follower turns each link by
/// about that; else it is not followed at all); and the chain following it moves its
/// angles no more, and passes the pinches and the map at least as well.
fn eased_if_better(
    threading: &Threading,
    steps: &[Step],
    passing: &Passing,
    ctx: &CollisionContext,
    cx: &Context,
) -> Option<(Threading, (Vec<Step>, Passing))> {
    let l = ctx.params().link_length as f64;
    if ease::tightest_bend(threading.route(), l) >= ease::reach(ctx) {
        return None;
    }
    let start = &steps[0];
    let eased = threading.eased(ctx, start, cx.follow_step, cx.deadline);
    if ease::turning(eased.route(), l) > ease::turning(threading.route(), l) + cx.s.thread.motion {
        return None;
    }
    let (followed, _) = eased.follow(ctx, start, cx.follow_step, cx.deadline).ok()?;
    let after = eased.measure(ctx, &followed, true);
    let motion = |s: &[Step]| Quality::of(s).shape_motion_rad;
    let better = motion(&followed) <= motion(steps) + TIE
        && after.share + TIE >= passing.share
        && after.narrowest + TIE >= passing.narrowest;
    better.then_some((eased, (followed, after)))
}
