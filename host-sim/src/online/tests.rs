//! The online planner in simulation, audited: every committed piece passes the exact
//! test on the map it was committed on (unknown space occupied), the joined plan is
//! valid on the world, and the flight keeps clear of it.

use super::*;
use crate::collision::verify_plan;
use crate::planning::PlanOptions;
use crate::problem::scenarios;
use crate::tables::{ShapeTables, TableSettings};
use aerial_chain_core::ChainParams;

#[test]
fn the_window_from_an_empty_map_commits_only_pieces_valid_on_what_was_seen() {
    let sc = scenarios::build("window").unwrap();
    let params = ChainParams::new(4).validate().unwrap();
    let defaults = PlanOptions::default();
    let settings = TableSettings {
        srs: defaults.srs,
        seed: defaults.srs_seed,
        ..Default::default()
    };
    let tables =
        ShapeTables::build(params, &settings, &std::sync::atomic::AtomicUsize::new(0)).unwrap();
    let shape = sc.start_shape(4).unwrap();
    let mut start = vec![sc.start.x, sc.start.y, sc.start.z];
    start.extend(shape.as_slice().iter().map(|&v| v as f64));
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
    let sc = scenarios::build("window").unwrap();
    let params = ChainParams::new(3).validate().unwrap();
    let tables = ShapeTables::build(
        params,
        &TableSettings {
            srs: 0,
            ..Default::default()
        },
        &std::sync::atomic::AtomicUsize::new(0),
    )
    .unwrap();
    let shape = sc.start_shape(3).unwrap();
    let mut start = vec![sc.start.x, sc.start.y, sc.start.z];
    start.extend(shape.as_slice().iter().map(|&v| v as f64));
    let mut settings = ExploreSettings {
        time_limit_s: 10.0,
        ..ExploreSettings::default()
    };
    settings.online.deadline_s = 0.0;
    let e = explore(
        &sc.grid,
        params,
        tables.clone(),
        &start,
        sc.goal,
        0.3,
        None,
        &settings,
    )
    .unwrap_err();
    assert!(e.to_string().contains("deadline_s"), "{e}");
    settings.online.deadline_s = 0.3;
    settings.time_limit_s = -1.0;
    let e = explore(
        &sc.grid,
        params,
        tables.clone(),
        &start,
        sc.goal,
        0.3,
        None,
        &settings,
    )
    .unwrap_err();
    assert!(matches!(e, ExploreError::TimeLimit(_)), "{e}");
    // A start that touches the world is refused.
    settings.time_limit_s = 10.0;
    let mut inside = start.clone();
    inside[0] = 4.1; // in the dividing wall
    let e = explore(
        &sc.grid, params, tables, &inside, sc.goal, 0.3, None, &settings,
    )
    .unwrap_err();
    assert!(matches!(e, ExploreError::Start { .. }), "{e}");
}
