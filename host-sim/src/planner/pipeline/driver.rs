//! The driver: runs a declared list of stages and forks, and reports on each.

use std::time::Instant;

use super::{Budget, Context, Draft, Effect, Select, Stage, StageReport};
use crate::planner::expired;
use crate::planner::plan_ops::Quality;
use crate::planner::widen;

/// An entry of the list: a stage, or a fork of two lanes and the choice between them.
pub(super) enum Node {
    /// One stage.
    Stage(Box<dyn Stage>),
    /// Two lanes run side by side on copies of the plan, then one result kept.
    Fork(Box<Fork>),
}

/// Two lanes and the selection that keeps one of their plans.
pub(super) struct Fork {
    lanes: [Lane; 2],
    select: Box<dyn Select>,
}

/// A named list of entries run one after the other.
pub(super) struct Lane {
    name: &'static str,
    nodes: Vec<Node>,
}

/// An entry for stage `s`.
pub(super) fn stage(s: impl Stage + 'static) -> Node {
    Node::Stage(Box::new(s))
}

/// A lane named `name`.
pub(super) fn lane(name: &'static str, nodes: Vec<Node>) -> Lane {
    Lane { name, nodes }
}

/// An entry that runs `first` and `second` side by side (the first is taken by this
/// core; the second waits for a free one, or runs after) and keeps one by `select`.
pub(super) fn fork(first: Lane, second: Lane, select: impl Select + 'static) -> Node {
    Node::Fork(Box::new(Fork {
        lanes: [first, second],
        select: Box::new(select),
    }))
}

/// Runs `nodes` on `draft`: the result, and a report per stage run, in list order.
pub(super) fn run(nodes: &[Node], draft: Draft, cx: &Context) -> (Draft, Vec<StageReport>) {
    let effect = Some(measure(&draft, cx));
    let (out, _, reports) = run_lane(nodes, "", draft, effect, cx);
    (out, reports)
}

/// A lane's result, its effect, and its reports.
type LaneResult = (Draft, Option<Effect>, Vec<StageReport>);

/// Runs `nodes` of the lane `path` on `draft`, whose effect is `effect`.
fn run_lane(
    nodes: &[Node],
    path: &str,
    mut draft: Draft,
    mut effect: Option<Effect>,
    cx: &Context,
) -> LaneResult {
    let mut reports = Vec::new();
    for node in nodes {
        // A lane given up has nothing more to do.
        if draft.notes.withdrawn {
            break;
        }
        match node {
            Node::Stage(s) => {
                let began = Instant::now();
                let before = draft.steps.clone();
                let (out, budget) = s.run(draft, cx);
                let time_s = began.elapsed().as_secs_f64();
                if out.notes.withdrawn {
                    effect = None;
                } else if out.steps != before {
                    effect = Some(measure(&out, cx));
                }
                reports.push(report(s.name(), path, budget, time_s, effect, None));
                draft = out;
            }
            Node::Fork(f) => {
                let lane_path = |l: &Lane| match path {
                    "" => l.name.to_string(),
                    p => format!("{p}/{}", l.name),
                };
                let copy = draft.clone();
                let [first, second] = &f.lanes;
                let (a, b) = rayon::join(
                    || run_lane(&first.nodes, &lane_path(first), copy, effect, cx),
                    || run_lane(&second.nodes, &lane_path(second), draft, effect, cx),
                );
                let chose = Instant::now();
                let (out, k) = f.select.choose(a.0, b.0, cx);
                effect = [a.1, b.1][k];
                // The lanes' time is theirs; the selection's is its own.
                let time_s = chose.elapsed().as_secs_f64();
                reports.extend(a.2);
                reports.extend(b.2);
                let taken = Some(f.lanes[k].name);
                reports.push(report(
                    f.select.name(),
                    path,
                    Budget::NONE,
                    time_s,
                    effect,
                    taken,
                ));
                draft = out;
            }
        }
    }
    (draft, effect, reports)
}

fn report(
    name: &'static str,
    lane: &str,
    budget: Budget,
    time_s: f64,
    effect: Option<Effect>,
    taken: Option<&'static str>,
) -> StageReport {
    StageReport {
        name,
        lane: lane.to_string(),
        budget,
        time_s,
        effect,
        taken,
    }
}

/// The measures of `draft`'s plan; its narrowest clearance only before the deadline.
fn measure(draft: &Draft, cx: &Context) -> Effect {
    let q = Quality::of(&draft.steps);
    let narrowest_m = (!expired(cx.deadline)).then(|| widen::narrowest(cx.ctx, &draft.steps));
    Effect {
        head_path_m: q.head_path_m,
        shape_motion_rad: q.shape_motion_rad,
        narrowest_m,
    }
}
