//! The online planner in simulation, audited: every committed piece passes the exact
//! test on the map it was committed on (unknown space occupied), the joined plan is
//! valid on the world, and the flight keeps clear of it.

use std::sync::atomic::AtomicUsize;

use super::*;
use crate::collision::verify_plan;
use crate::plan_file::Waypoint;
use crate::planning::PlanOptions;
use crate::problem::scenarios::{self, Scenario};
use crate::tables::ShapeTables;
use aerial_chain_core::ChainParams;

/// Scenario `window` for `units` units: the chain, `arc plan`'s tables, and the start
/// configuration.
fn window(units: u8) -> (Scenario, ChainParams, ShapeTables, Vec<f64>) {
    let sc = scenarios::build("window").unwrap();
    let params = ChainParams::new(units).validate().unwrap();
    let settings = PlanOptions::default().table_settings();
    let tables = ShapeTables::build(params, &settings, &AtomicUsize::new(0)).unwrap();
    let start = Waypoint::new(sc.start.into(), &sc.start_shape(units).unwrap()).zeta;
    (sc, params, tables, start)
}

#[test]
fn the_window_from_an_empty_map_commits_only_pieces_valid_on_what_was_seen() {
    let (sc, params, tables, start) = window(4);
    let settings = ExploreSettings {
        time_limit_s: 300.0,
        audit: true,
        ..ExploreSettings::default()
    };
    let ex = explore(
        &sc.grid, params, tables, &start, sc.goal, 0.3, None, &settings,
    )
    .unwrap();
    assert!(ex.end.reached(), "{:?}", ex.end);
    let audit = ex.audit.as_ref().unwrap();
    assert_eq!(audit.len(), ex.pieces);
    assert!(ex.pieces >= 2, "{} pieces", ex.pieces);
    for (i, v) in audit.iter().enumerate() {
        assert!(v.is_none(), "piece {i}: {v:?}");
    }
    assert!(verify_plan(&sc.grid, &ex.plan).ok);
    assert!(!ex.flight.report.contact);
    // The seen map knows less than the world, and never an obstacle where there is none.
    for (i, state) in ex.seen.voxels() {
        if state == crate::map::Cell::Occupied {
            assert_eq!(sc.grid.cell(i), crate::map::Cell::Occupied, "{i:?}");
        }
    }
    let record = ex.record();
    assert_eq!(record.format, RECORD_FORMAT);
    assert_eq!(record.summary.replans, ex.replans.len());
    assert!(record.summary.nothing_new_max_s < 0.01);
}

#[test]
fn bad_settings_are_refused_by_name() {
    let (sc, params, tables, start) = window(3);
    let refused = |settings: &ExploreSettings, start: &[f64]| {
        explore(
            &sc.grid,
            params,
            tables.clone(),
            start,
            sc.goal,
            0.3,
            None,
            settings,
        )
        .unwrap_err()
    };
    let mut settings = ExploreSettings {
        time_limit_s: 10.0,
        ..ExploreSettings::default()
    };
    settings.online.deadline_s = 0.0;
    let e = refused(&settings, &start);
    assert!(e.to_string().contains("deadline_s"), "{e}");
    settings.online.deadline_s = 0.3;
    settings.time_limit_s = -1.0;
    let e = refused(&settings, &start);
    assert!(matches!(e, ExploreError::TimeLimit(_)), "{e}");
    // A start that touches the world is refused.
    settings.time_limit_s = 10.0;
    let mut inside = start.clone();
    inside[0] = 4.1; // in the dividing wall
    let e = refused(&settings, &inside);
    assert!(matches!(e, ExploreError::Start { .. }), "{e}");
}

#[test]
fn a_due_piece_is_tried_even_when_a_route_search_took_in_what_was_seen() {
    let (sc, params, tables, start) = window(4);
    let mut planner = OnlinePlanner::new(
        params,
        tables,
        &start,
        sc.goal,
        0.3,
        &sc.grid,
        None,
        OnlineSettings::default(),
        87.0,
    )
    .unwrap();
    planner.replan(0.0, Trigger::Start);
    // Space along the first metre of the route is seen free...
    let route = planner.route().expect("a route").points.clone();
    let from = route[0];
    let ahead: Vec<_> = route
        .iter()
        .take_while(|p| (*p - from).norm() < 1.0)
        .copied()
        .collect();
    planner.observe_flown(&ahead, 0.45).unwrap();
    // ...a route replan takes it in, and the piece that falls due just after, with
    // nothing new seen in between, is still tried.
    let rerouted = planner.replan(1.0, Trigger::Period);
    assert_eq!(rerouted.outcome, Outcome::Rerouted);
    let due = planner.replan(1.1, Trigger::CommitShort);
    assert!(
        matches!(
            due.outcome,
            Outcome::Committed | Outcome::Looked | Outcome::NoRoom
        ),
        "{:?}",
        due.outcome
    );
}
