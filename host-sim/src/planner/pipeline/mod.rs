//! Post-processing as a pipeline: one contract for every stage, one driver, and the
//! one declared list of stages ([`post_processing`]) that fixes their order
//! (docs/postprocessing.md describes that list in that order).
//!
//! The contract, as OMPL's `PathSimplifier` or MoveIt's planning request adapters
//! have it: a stage ([`Stage`]) takes a plan on its way ([`Draft`]) and a narrow
//! [`Context`] (the contexts it checks and measures in, the library shapes, the
//! tuning, the search's plan and the deadline; never the planner), and gives back a
//! plan and its [`Budget`]: what its work counts (checks, edge measurements,
//! placements, steps), how much it may spend and how much it spent. Past the deadline
//! a stage makes no more checks and keeps what it has. A selection ([`Select`])
//! takes two plans made side by side and keeps one by its stated rule.
//!
//! The driver (`driver`) runs the list, lanes of a fork side by side (`rayon::join`,
//! on a second core where one is free; each lane works on its own copy with its own
//! budgets, so the result is the one the stages give in turn), and records per stage
//! a [`StageReport`]: its wall time, its budget, and its effect on the plan (head
//! path, shape motion, narrowest unit clearance).

mod driver;
mod select;
mod stages;

use std::sync::Arc;
use std::time::Instant;

use aerial_chain_core::lsc::LscEntry;

use super::carry::Carried;
use super::plan_ops::Quality;
use super::thread::{Passing, Threading};
use super::widen::Widening;
use super::{RefineSettings, Step};
use crate::collision::CollisionContext;
use driver::{fork, lane, stage, Node};

/// The order of post-processing, the one place it is written (docs/postprocessing.md
/// describes this list in this order). The search's plan enters a fork of two lanes:
/// `main` refines it, widens it and carries a stretch of it; `threaded` rebuilds it
/// along the search's route threaded through its pinches; `threaded-if-better` keeps
/// one. Inside `main`, the lane `widened` widens the search's plan first and then
/// shortcuts it at the margin won, beside the lane `plain` that shortcuts it at the
/// search's margin; `keep-motion` keeps one.
fn post_processing() -> Vec<Node> {
    let shortcuts = || -> Vec<Node> {
        vec![
            stage(stages::Shortcut),
            stage(stages::ShrinkChanges),
            stage(stages::HoldYaw),
            stage(stages::ReplaceRuns),
            stage(stages::Straighten),
        ]
    };
    let widened = [stage(stages::WidenFirst), stage(stages::KeepMargin)]
        .into_iter()
        .chain(shortcuts())
        .collect();
    let main = vec![
        fork(
            lane("widened", widened),
            lane("plain", shortcuts()),
            select::KeepMotion,
        ),
        stage(stages::Carry),
        stage(stages::WidenAgain),
    ];
    vec![fork(
        lane("main", main),
        lane("threaded", vec![stage(stages::Thread)]),
        select::ThreadedIfBetter,
    )]
}

/// What post-processing did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Refinement {
    /// The plan as the search made it.
    pub before: Quality,
    /// The refined plan.
    pub after: Quality,
    /// Collision checks the check-counting stages spent (refinement and shortening,
    /// in both lanes).
    pub checks: u64,
    /// What widening did: the narrowest unit clearance of the search's plan, then
    /// that of the result, and the moves that made it.
    pub widening: Widening,
    /// Whether the plan is the search's head route threaded (`super::thread`).
    pub threaded: bool,
    /// The stretches of the plan flown in one library shape each (`super::carry`), in
    /// the order they were found (a threaded plan has none).
    pub carried: Vec<Carried>,
    /// Time spent (s).
    pub time_s: f64,
    /// Every stage that ran, in the order of the declared list (a fork's first lane,
    /// its second, then its selection).
    pub stages: Vec<StageReport>,
}

/// What a stage's budget counts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unit {
    /// Collision checks (refinement and shortening share one budget).
    Checks,
    /// Measurements of an edge's narrowest unit (widening).
    EdgeMeasurements,
    /// Placements of the chain on a search lattice (carrying).
    Placements,
    /// Follow-the-leader steps made (threading).
    Steps,
    /// Nothing: the stage makes no checks, or chooses between plans already made.
    Nothing,
}

impl Unit {
    /// Its name in reports.
    pub fn name(&self) -> &'static str {
        match self {
            Unit::Checks => "checks",
            Unit::EdgeMeasurements => "edge measurements",
            Unit::Placements => "placements",
            Unit::Steps => "steps",
            Unit::Nothing => "none",
        }
    }
}

/// A stage's budget: what it counts, how much it may spend, how much it spent (it
/// may pass `limit` by the few it spends between two looks at it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Budget {
    /// What it counts.
    pub unit: Unit,
    /// How much the stage may spend (for a shared budget: what the stages before
    /// it left).
    pub limit: u64,
    /// How much it spent.
    pub used: u64,
}

impl Budget {
    /// The budget of a stage that counts nothing.
    pub const NONE: Budget = Budget {
        unit: Unit::Nothing,
        limit: 0,
        used: 0,
    };
}

/// A plan's measures, as a stage left it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Effect {
    /// Length of the head's path (m).
    pub head_path_m: f64,
    /// Total shape motion (rad, [`Quality::shape_motion_rad`]).
    pub shape_motion_rad: f64,
    /// The narrowest unit clearance over every edge, measured as widening does (m, at
    /// most [`super::WIDEN_CAP`]); `None` past the deadline, where it is not measured.
    pub narrowest_m: Option<f64>,
}

/// What one stage did.
#[derive(Clone, Debug, PartialEq)]
pub struct StageReport {
    /// The stage's name (docs/postprocessing.md).
    pub name: &'static str,
    /// The lanes it ran in, outermost first, joined by `/` (`main/plain`).
    pub lane: String,
    /// Its budget.
    pub budget: Budget,
    /// Wall time (s).
    pub time_s: f64,
    /// The plan it gave; `None` where it gave none (a lane given up, such as the
    /// threaded one where the chain cannot follow the route).
    pub effect: Option<Effect>,
    /// For a selection: the lane whose plan it kept.
    pub taken: Option<&'static str>,
}

/// What a stage reads besides its plan: never the planner itself.
pub(crate) struct Context<'a> {
    /// The search's context: its clearance margin, the map and the chain.
    pub(crate) ctx: &'a CollisionContext,
    /// The context at the smallest clearance (where the search gave way).
    pub(crate) ctx_min: &'a CollisionContext,
    /// The library shapes (carrying's candidates).
    pub(crate) lsc: &'a [LscEntry],
    /// The search's follow-the-leader step (m; threading's step).
    pub(crate) follow_step: f64,
    /// Post-processing's tuning.
    pub(crate) s: &'a RefineSettings,
    /// The search's plan, which the pipeline starts from.
    pub(crate) raw: &'a [Step],
    /// The query's time limit: past it every stage stops and keeps what it has.
    pub(crate) deadline: Option<Instant>,
}

/// A plan on its way through the stages.
#[derive(Clone)]
pub(crate) struct Draft {
    /// Its steps.
    pub(crate) steps: Vec<Step>,
    /// The context its checks are made in: the search's, or one at the margin the
    /// first widening won (`KeepMargin`).
    pub(crate) ctx: CollisionContext,
    /// Collision checks spent on it of the budget the check-counting stages share.
    pub(crate) checks: u64,
    /// What earlier stages leave for later ones and for the report.
    pub(crate) notes: Notes,
}

impl Draft {
    /// The search's plan of `cx` as the stages first take it, in the search's context.
    pub(crate) fn of(cx: &Context) -> Self {
        Draft {
            steps: cx.raw.to_vec(),
            ctx: cx.ctx.clone(),
            checks: 0,
            notes: Notes::default(),
        }
    }
}

/// What the stages record on a draft.
#[derive(Clone, Default)]
pub(crate) struct Notes {
    /// Given up by a stage: later stages of its lane leave it be, and no selection
    /// keeps it.
    pub(crate) withdrawn: bool,
    /// The search's plan widened, and what that did (`WidenFirst`).
    pub(crate) first_widening: Option<Arc<(Vec<Step>, Widening)>>,
    /// The first widening's moves, where its lane was kept (`KeepMotion`).
    pub(crate) kept_moves: Option<usize>,
    /// The stretches flown in one library shape each (`Carry`).
    pub(crate) carried: Vec<Carried>,
    /// What the last widening did (`WidenAgain`; for a threaded plan, how it passes).
    pub(crate) widening: Widening,
    /// The route the threaded plan follows and how that passes its pinches
    /// (`Thread`).
    pub(crate) threading: Option<Arc<(Threading, Passing)>>,
    /// Whether the plan is the threaded one (`ThreadedIfBetter`).
    pub(crate) threaded: bool,
}

/// A stage of post-processing (see the module docs).
pub(crate) trait Stage: Sync + Send {
    /// Its name in reports and in docs/postprocessing.md.
    fn name(&self) -> &'static str;
    /// The plan `draft` made into this stage's result, and the budget it spent;
    /// stops at `cx.deadline` and keeps what it has.
    fn run(&self, draft: Draft, cx: &Context) -> (Draft, Budget);
}

/// A choice between two plans made side by side (see the module docs).
pub(crate) trait Select: Sync + Send {
    /// Its name in reports and in docs/postprocessing.md.
    fn name(&self) -> &'static str;
    /// One of `first` and `second` (their steps as they are; notes may be carried
    /// over), and which (0 or 1).
    fn choose(&self, first: Draft, second: Draft, cx: &Context) -> (Draft, usize);
}

/// Post-processes `cx.raw` through the declared list: the plan, and what was done.
pub(crate) fn post_process(cx: &Context) -> (Vec<Step>, Refinement) {
    let began = Instant::now();
    let (out, stages) = driver::run(&post_processing(), Draft::of(cx), cx);
    let n = out.notes;
    let first = n.first_widening.map(|f| f.1).unwrap_or_default();
    let last = n.widening;
    let checks = stages
        .iter()
        .filter(|r| r.budget.unit == Unit::Checks)
        .map(|r| r.budget.used)
        .sum();
    let report = Refinement {
        before: Quality::of(cx.raw),
        after: Quality::of(&out.steps),
        checks,
        widening: Widening {
            before: first.before,
            moves: match n.threaded {
                true => last.moves,
                false => n.kept_moves.unwrap_or(0) + last.moves,
            },
            ..last
        },
        threaded: n.threaded,
        carried: n.carried,
        time_s: began.elapsed().as_secs_f64(),
        stages,
    };
    (out.steps, report)
}

#[cfg(test)]
mod tests;
