//! The stages held to the exact verifier (`collision::verify_plan`), not to the checks
//! they make themselves, and the driver held to its declared list and the deadline.

use std::sync::atomic::AtomicUsize;
use std::time::{Duration, Instant};

use aerial_chain_core::ChainParams;

use super::*;
use crate::collision::verify_plan;
use crate::map::Grid;
use crate::plan_file::MapSection;
use crate::planner::{to_plan, ArcPlanner, Planner, Query, Settings, Solution, Termination};
use crate::problem::scenarios;
use crate::tables::{ShapeTables, TableSettings};

/// The planner and the search's plan for `scenario` with a chain of `units`, with
/// small tables (fast), and the scenario's grid.
fn solved(scenario: &str, units: u8) -> (ArcPlanner, Vec<Step>, Grid) {
    let sc = scenarios::build(scenario).unwrap();
    let params = ChainParams::new(units);
    let table_settings = TableSettings {
        srs: 60,
        ..TableSettings::default()
    };
    let tables = ShapeTables::build(params, &table_settings, &AtomicUsize::new(0)).unwrap();
    let field = std::sync::Arc::new(crate::map::DistanceField::new(sc.grid.clone()));
    let ctx = CollisionContext::new(field, params, crate::collision::DEFAULT_CLEARANCE).unwrap();
    let mut planner = ArcPlanner::new(ctx, tables, Settings::default()).unwrap();
    let query = Query::new(sc.start, sc.start_shape(units).unwrap(), sc.goal);
    let raw = planner.solve(&query, Termination::default()).unwrap().steps;
    (planner, raw, sc.grid)
}

/// Whether the exact verifier passes `steps` on `grid`, and, if not, why.
fn verified(grid: &Grid, params: &ChainParams, steps: &[Step]) -> Result<(), String> {
    let solution = Solution {
        steps: steps.to_vec(),
        stats: crate::planner::Stats::default(),
    };
    let plan = to_plan(&solution, params, MapSection::of(grid));
    let report = verify_plan(grid, &plan);
    match report.ok {
        true => Ok(()),
        false => Err(format!("{:?}", report.violation)),
    }
}

/// Runs `list` one stage after the other from the search's plan, holding every
/// plan a stage gives to the exact verifier, its start to the search's start and its
/// head's end to the search's; the last draft (where a stage gives its lane up, as
/// the driver would, the draft it gave up).
fn each_verified(planner: &ArcPlanner, raw: &[Step], grid: &Grid, list: &[&dyn Stage]) -> Draft {
    let cx = planner.post_context(raw, None);
    let params = *cx.ctx.params();
    let mut d = Draft::of(&cx);
    for s in list {
        let (out, _) = s.run(d, &cx);
        d = out;
        if d.notes.withdrawn {
            break;
        }
        let name = s.name();
        verified(grid, &params, &d.steps).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(d.steps[0], raw[0], "{name} keeps the start");
        let end = |s: &[Step]| s.last().unwrap().xi;
        assert_eq!(end(&d.steps), end(raw), "{name} keeps the end");
    }
    d
}

/// The stages of the main lane, in the plain lane's order.
const MAIN_LANE: [&dyn Stage; 7] = [
    &stages::Shortcut,
    &stages::ShrinkChanges,
    &stages::HoldYaw,
    &stages::ReplaceRuns,
    &stages::Straighten,
    &stages::Carry,
    &stages::WidenAgain,
];

/// The widened lane's own stages (widening, the margin it won) and the shortcuts
/// that keep to that margin.
const WIDENED_LANE: [&dyn Stage; 4] = [
    &stages::WidenFirst,
    &stages::KeepMargin,
    &stages::Shortcut,
    &stages::ReplaceRuns,
];

/// The main lane on the maze (where the search's plan bends round every wall end and
/// carrying takes over).
#[test]
fn every_main_lane_stage_gives_a_plan_the_exact_verifier_passes() {
    let (planner, raw, grid) = solved("maze", 4);
    let out = each_verified(&planner, &raw, &grid, &MAIN_LANE);
    assert!(
        !out.notes.withdrawn && !out.notes.carried.is_empty(),
        "the maze is carried"
    );
    assert!(Quality::of(&out.steps).shape_motion_rad < Quality::of(&raw).shape_motion_rad);
}

/// The widened lane's stages (widening, the margin it won, the shortcuts at that
/// margin) and threading, on the window, whose opening the search's plan passes off
/// its middle.
#[test]
fn widening_keeping_its_margin_and_threading_give_plans_the_exact_verifier_passes() {
    let (planner, raw, grid) = solved("window", 3);
    let out = each_verified(&planner, &raw, &grid, &WIDENED_LANE);
    assert!(
        !out.notes.withdrawn,
        "the window keeps the margin widening won"
    );
    let first = out.notes.first_widening.as_ref().expect("widened").1;
    assert!(first.moves > 0 && first.in_passages.is_some(), "{first:?}");
    let out = each_verified(&planner, &raw, &grid, &[&stages::Thread]);
    assert!(
        !out.notes.withdrawn,
        "the window's route has a pinch to thread"
    );
}

/// The driver runs the declared list: every stage once per lane, in list order, a
/// fork's lanes before its selection; the report's checks are the check-counting
/// stages' own; and the plan passes the exact verifier.
#[test]
fn the_driver_reports_each_stage_in_the_declared_order() {
    let (planner, raw, grid) = solved("window", 3);
    let (steps, r) = post_process(&planner.post_context(&raw, None));
    verified(&grid, planner.context().params(), &steps).unwrap();
    let at = |lane: &str, name: &str| match lane {
        "" => name.to_string(),
        l => format!("{l} {name}"),
    };
    let names: Vec<String> = r.stages.iter().map(|s| at(&s.lane, s.name)).collect();
    let shortcuts = [
        "shortcut",
        "shrink-changes",
        "hold-yaw",
        "replace-runs",
        "straighten",
    ];
    let mut expected = vec![
        at("main/widened", "widen"),
        at("main/widened", "keep-margin"),
    ];
    // The widened lane goes on only where keeping its margin gave a plan.
    if r.stages[1].effect.is_some() {
        expected.extend(shortcuts.map(|s| at("main/widened", s)));
    }
    expected.extend(shortcuts.map(|s| at("main/plain", s)));
    expected.extend(["keep-motion", "carry", "widen-again"].map(|s| at("main", s)));
    expected.extend([at("threaded", "thread"), at("", "threaded-if-better")]);
    assert_eq!(names, expected);
    let checks: u64 = r
        .stages
        .iter()
        .filter(|s| s.budget.unit == Unit::Checks)
        .map(|s| s.budget.used)
        .sum();
    assert_eq!(r.checks, checks);
    assert!(checks > 0);
    let last = r.stages.last().unwrap();
    assert!(last.taken.is_some());
    let effect = last.effect.expect("a plan");
    assert_eq!(
        effect.shape_motion_rad,
        Quality::of(&steps).shape_motion_rad
    );
}

/// Past the deadline no stage makes a check and the search's plan, widened no
/// further than its first measurement, still passes the exact verifier.
#[test]
fn past_the_deadline_every_stage_keeps_what_it_has() {
    let (planner, raw, grid) = solved("window", 3);
    let past = Instant::now() - Duration::from_millis(1);
    let (steps, r) = post_process(&planner.post_context(&raw, Some(past)));
    verified(&grid, planner.context().params(), &steps).unwrap();
    for s in &r.stages {
        if s.budget.unit == Unit::Checks {
            assert_eq!(s.budget.used, 0, "{} {}", s.lane, s.name);
        }
        if let Some(e) = s.effect {
            assert_eq!(e.narrowest_m, None, "not measured past the deadline");
        }
    }
    assert_eq!(r.widening.moves, 0);
}
