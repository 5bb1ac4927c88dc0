//! The online planner in simulation, audited: every committed piece passes the exact
//! test on the map it was committed on (unknown space occupied), the joined plan is
//! valid on the world, and the flight keeps clear of it.

use std::sync::atomic::AtomicUsize;

use super::*;
use crate::collision::verify_plan;
use crate::map::{Cell, Grid};
use crate::plan_file::Waypoint;
use crate::planning::PlanOptions;
use crate::problem::scenarios::{self, Scenario};
use crate::tables::ShapeTables;
use aerial_chain_core::ChainParams;
use nalgebra::Point3;

/// Scenario `window` for `units` units: the chain, `arc plan`'s tables, and the start
/// configuration.
fn window(units: u8) -> (Scenario, ChainParams, ShapeTables, Vec<f64>) {
    let sc = scenarios::build("window").unwrap();
    let (params, tables) = chain(units);
    let start = Waypoint::new(sc.start.into(), &sc.start_shape(units).unwrap()).zeta;
    (sc, params, tables, start)
}

/// A chain of `units` units and `arc plan`'s tables for it.
pub(super) fn chain(units: u8) -> (ChainParams, ShapeTables) {
    let params = ChainParams::new(units).validate().unwrap();
    let settings = PlanOptions::default().table_settings();
    let tables = ShapeTables::build(params, &settings, &AtomicUsize::new(0)).unwrap();
    (params, tables)
}

/// Sets the voxels of `g` whose centres lie in the box `lo..hi` to `cell` (the box
/// shrunk by a hair, so that faces on the lattice take exactly the voxels inside).
fn fill(g: &mut Grid, lo: [f64; 3], hi: [f64; 3], cell: Cell) {
    let e = 1e-6;
    g.fill_box(lo.map(|v| v + e), hi.map(|v| v - e), cell);
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
    let mut occupied = 0;
    for (i, state) in ex.seen.voxels() {
        if state == Cell::Occupied {
            assert_eq!(sc.grid.cell(i), Cell::Occupied, "{i:?}");
            occupied += 1;
        }
    }
    // The map as it grew: every occupied voxel of the end, once, in the order seen,
    // none before the first scan or after the run.
    let grew = &ex.seen_occupied;
    assert_eq!((grew.voxels.len(), grew.t.len()), (occupied, occupied));
    assert!(occupied > 1000, "{occupied}");
    let end = ex.flight.report.simulated_time + 1e-9;
    assert!(grew.t.windows(2).all(|w| w[0] <= w[1]));
    assert!(grew.t.iter().all(|t| (0.0..=end).contains(t)), "{end}");
    assert!(grew.t[occupied - 1] > 1.0, "the map grew as the chain flew");
    for v in &grew.voxels {
        assert_eq!(ex.seen.state(*v), Cell::Occupied, "{v:?}");
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
        &crate::sensing::DepthSensor::default(),
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

/// With the world known before the flight, the route is known to the goal: the chain,
/// which starts looking away from the window, commits its way there at once, with no
/// turn to look, and no replan is due until that motion ends.
#[test]
fn a_route_known_to_the_goal_is_flown_without_turning_to_look() {
    let (sc, params, tables, start) = window(4);
    let new = |prior| {
        OnlinePlanner::new(
            params,
            tables.clone(),
            &start,
            sc.goal,
            0.3,
            &sc.grid,
            prior,
            OnlineSettings::default(),
            &crate::sensing::DepthSensor::default(),
        )
        .unwrap()
    };
    let mut known = new(Some(&sc.grid));
    let first = known.replan(0.0, Trigger::Start);
    assert_eq!(first.outcome, Outcome::Committed);
    assert!(known.reached());
    assert!(known.pieces().iter().all(|p| !p.is_look()));
    let end = known.committed().duration();
    assert_eq!(known.due(end, 0.1), None);
    // From an empty map the same start turns to look first, and the next piece falls
    // due as that turn ends.
    let mut empty = new(None);
    assert_eq!(empty.replan(0.0, Trigger::Start).outcome, Outcome::Looked);
    assert_eq!(empty.due(0.0, 0.1), None);
    let end = empty.committed().duration();
    assert_eq!(empty.due(end, 0.1), Some(Trigger::CommitShort));
}

/// Two lanes 12 m long side by side behind a hall, split by a wall: lane A (y < 3)
/// ends in a wall at x = 10 that the sensors first see from 5 m; lane B (y > 3) is
/// open to the goal at its far end.
fn two_lanes() -> Grid {
    let mut g = Grid::new(0.1, [0; 3], [120, 60, 26], Cell::Occupied, true).unwrap();
    fill(&mut g, [0.1, 0.1, 0.1], [11.9, 5.9, 2.5], Cell::Free);
    fill(&mut g, [2.0, 2.9, 0.0], [12.0, 3.1, 2.6], Cell::Occupied);
    fill(&mut g, [9.8, 0.0, 0.0], [10.0, 3.0, 2.6], Cell::Occupied);
    g
}

/// Explores `world` with a chain of `units` units from `start` toward `goal` (within
/// 0.3 m) in at most `time_limit_s` simulated s, auditing every piece; checks that it
/// reached the goal without contact, every piece valid on the map it was committed on
/// and the joined plan valid on the world.
fn explore_audited(
    world: &Grid,
    units: u8,
    start: &[f64],
    goal: Point3<f64>,
    time_limit_s: f64,
    start_free: StartFree,
) -> Exploration {
    let (params, tables) = chain(units);
    let mut settings = ExploreSettings {
        time_limit_s,
        audit: true,
        ..ExploreSettings::default()
    };
    settings.online.start_free = start_free;
    let ex = explore(world, params, tables, start, goal, 0.3, None, &settings).unwrap();
    assert!(ex.end.reached(), "{:?}", ex.end);
    assert!(!ex.flight.report.contact);
    for (i, v) in ex.audit.as_ref().unwrap().iter().enumerate() {
        assert!(v.is_none(), "piece {i}: {v:?}");
    }
    assert!(verify_plan(world, &ex.plan).ok);
    ex
}

#[test]
fn a_dead_end_seen_late_is_left_the_way_the_chain_came() {
    let world = two_lanes();
    let line = aerial_chain_core::Shape::line(4, 0.0);
    let start = Waypoint::new([2.2, 1.5, 1.3], &line).zeta;
    let goal = Point3::new(11.0, 4.5, 1.3);
    let ex = explore_audited(&world, 4, &start, goal, 400.0, StartFree::Hull);
    // The route first led down lane A (unknown space is free to the route); the chain
    // went in, saw its end, and came back out to take lane B.
    let heads: Vec<[f64; 2]> = ex
        .plan
        .waypoints
        .iter()
        .map(|w| [w.zeta[0], w.zeta[1]])
        .collect();
    let deepest_in_a = heads
        .iter()
        .filter(|h| h[1] < 2.9)
        .map(|h| h[0])
        .fold(f64::NEG_INFINITY, f64::max);
    assert!(
        deepest_in_a > 4.0,
        "the chain never went down lane A: {heads:?}"
    );
    let back = heads.iter().position(|h| h[0] < 2.0 && h[1] > 3.0);
    assert!(
        back.is_some(),
        "the chain never came back to the hall: {heads:?}"
    );
}

#[test]
fn a_goal_behind_a_wall_across_the_box_is_proven_sealed_from_an_empty_map() {
    // A room 6 x 4 x 2.6 m cut by a wall at x = 4 from side to side and floor to
    // ceiling; the goal lies behind it.
    let mut world = Grid::new(0.1, [0; 3], [60, 40, 26], Cell::Occupied, true).unwrap();
    fill(&mut world, [0.1; 3], [5.9, 3.9, 2.5], Cell::Free);
    fill(&mut world, [4.0, 0.0, 0.0], [4.2, 4.0, 2.6], Cell::Occupied);
    let (params, tables) = chain(3);
    let start = Waypoint::new([2.0, 2.0, 1.3], &aerial_chain_core::Shape::line(3, 0.0)).zeta;
    let settings = ExploreSettings {
        time_limit_s: 300.0,
        ..ExploreSettings::default()
    };
    let goal = Point3::new(5.0, 2.0, 1.3);
    let ex = explore(&world, params, tables, &start, goal, 0.3, None, &settings).unwrap();
    let ExploreEnd::Sealed { t, why } = &ex.end else {
        panic!("{:?}", ex.end);
    };
    assert!(why.contains("no route"), "{why}");
    assert!(*t < 300.0);
    assert!(!ex.flight.report.contact);
}

/// A square tunnel 0.6 m across along x, from x = 0.1 to `end` m, at 0.05 m.
fn tunnel_to(end: f64) -> Grid {
    let cells = ((end + 0.1) / 0.05).round() as usize;
    let mut world = Grid::new(0.05, [0; 3], [cells, 20, 20], Cell::Occupied, true).unwrap();
    fill(&mut world, [0.1, 0.2, 0.2], [end, 0.8, 0.8], Cell::Free);
    world
}

/// A square tunnel 0.6 m across along x, from x = 0.1 to 4.9, at 0.05 m.
fn tunnel() -> Grid {
    tunnel_to(4.9)
}

/// A chain at rest whose hull is partly unseen looks at it before it searches a piece:
/// any piece would pass through that hull, so a search could only spend its deadline.
/// (A start taking only its grown bodies as free leaves the waists between the units
/// unseen.)
#[test]
fn a_chain_looks_at_its_unseen_hull_before_it_searches_a_piece() {
    let world = tunnel();
    let (params, tables) = chain(4);
    let start = Waypoint::new([2.0, 0.5, 0.5], &aerial_chain_core::Shape::line(4, 0.0)).zeta;
    let settings = OnlineSettings {
        start_free: StartFree::Bodies,
        ..OnlineSettings::default()
    };
    let mut planner = OnlinePlanner::new(
        params,
        tables,
        &start,
        Point3::new(4.2, 0.5, 0.5),
        0.3,
        &world,
        None,
        settings,
        &crate::sensing::DepthSensor::default(),
    )
    .unwrap();
    // The space ahead of the head is marked seen free, so pieces along the route could
    // be searched; the waists between the units are not seen.
    let ahead: Vec<_> = (1..=10)
        .map(|k| Point3::new(2.0 + 0.1 * f64::from(k), 0.5, 0.5))
        .collect();
    planner.observe_flown(&ahead, 0.45).unwrap();
    let first = planner.replan(0.0, Trigger::Start);
    assert_eq!(first.outcome, Outcome::Looked);
    assert_eq!(planner.pieces_searched(), 0);
    let look = &planner.pieces()[0].plan;
    assert!(look.stats.contains_key("look_at_hull"), "{:?}", look.stats);
    // The next commit turns back to the route; the hull is looked at once where the
    // chain rests, so the one after searches pieces.
    planner.replan(0.1, Trigger::CommitShort);
    let back = &planner.pieces()[1].plan;
    assert!(back.stats.contains_key("turn_to_look"), "{:?}", back.stats);
    assert_eq!(planner.pieces_searched(), 0);
    assert!(planner.pieces().iter().all(|p| p.is_look()));
    let third = planner.replan(0.2, Trigger::CommitShort);
    assert_ne!(third.outcome, Outcome::Looked);
    assert!(planner.pieces_searched() > 0);
    if third.outcome == Outcome::Committed {
        assert!(!planner.pieces()[2].is_look());
    }
}

/// The head yaw's largest turn, in absolute value, before the head first moved from
/// `x0` along x.
fn turned_before_moving(ex: &Exploration, x0: f64) -> f64 {
    let zetas: Vec<&[f64]> = ex.plan.waypoints.iter().map(|w| &w.zeta[..]).collect();
    let moved = zetas
        .iter()
        .position(|z| (z[0] - x0).abs() > 1e-3)
        .expect("the chain moved");
    zetas[..moved]
        .iter()
        .map(|z| crate::collision::verify::wrap(z[3]).abs())
        .fold(0.0, f64::max)
}

/// A straight chain at rest in a square tunnel, looking along itself, that takes only
/// its grown bodies as free cannot move its last unit through the waist ahead of it,
/// which no sensor looking forward sees: it turns to look at its own hull (back along
/// itself), then flies down the tunnel. Taking its hull as free (the default), it
/// flies at once, and reaches the goal sooner.
#[test]
fn a_chain_looking_along_itself_flies_at_once_when_its_hull_is_taken_free() {
    let world = tunnel();
    let start = Waypoint::new([2.0, 0.5, 0.5], &aerial_chain_core::Shape::line(4, 0.0)).zeta;
    let goal = Point3::new(4.2, 0.5, 0.5);
    let reached = |ex: &Exploration| match ex.end {
        ExploreEnd::Reached { t } => t,
        ref end => panic!("not reached: {end:?}"),
    };
    let bodies = explore_audited(&world, 4, &start, goal, 120.0, StartFree::Bodies);
    let turned = turned_before_moving(&bodies, 2.0);
    assert!(
        turned > 2.5,
        "the head yaw turned at most {turned} rad at rest"
    );
    // Those turns are counted as looking: 2.5 rad at the head yaw's rate limit at least,
    // and less than the whole time to the goal.
    let rate = crate::trajectory::Limits::default().yaw_rate;
    let t_bodies = reached(&bodies);
    assert!(
        bodies.looking_s >= 2.5 / rate && bodies.looking_s < t_bodies,
        "looking {} s of {t_bodies} s",
        bodies.looking_s
    );
    let hull = explore_audited(&world, 4, &start, goal, 120.0, StartFree::Hull);
    assert_eq!(turned_before_moving(&hull, 2.0), 0.0);
    assert_eq!(hull.looking_s, 0.0);
    let t_hull = reached(&hull);
    assert!(
        t_hull + 2.5 / rate < t_bodies,
        "hull {t_hull} s, bodies {t_bodies} s"
    );
}

/// A start with room for its bodies but not for its hull (an obstacle in the waist
/// between two units) is refused when the hull is taken as free, naming the obstacle
/// and the setting; taking only the bodies as free, the same start is flown.
#[test]
fn a_start_without_room_for_its_hull_is_refused_unless_only_its_bodies_are_taken_free() {
    let mut world = tunnel();
    // A block by the middle of the first link (x 1.5 to 2): 0.21 m from both unit
    // centres and 0.07 m from the link's axis, so the start is valid with the
    // clearance (0.2 m from the centres, 0.06 m from the axis) but its hull is not.
    fill(
        &mut world,
        [1.7, 0.55, 0.55],
        [1.8, 0.65, 0.65],
        Cell::Occupied,
    );
    let (params, tables) = chain(4);
    let start = Waypoint::new([2.0, 0.5, 0.5], &aerial_chain_core::Shape::line(4, 0.0)).zeta;
    let goal = Point3::new(4.2, 0.5, 0.5);
    let mut settings = ExploreSettings {
        time_limit_s: 1.0,
        ..ExploreSettings::default()
    };
    let run =
        |s: &ExploreSettings| explore(&world, params, tables.clone(), &start, goal, 0.3, None, s);
    let Err(e) = run(&settings) else {
        panic!("a start without room for its hull was flown");
    };
    let msg = e.to_string();
    assert!(matches!(e, ExploreError::StartHull { .. }), "{msg}");
    assert!(msg.contains("--start-free bodies"), "{msg}");
    assert!(msg.contains("[1.725, 0.575, 0.575]"), "{msg}");
    settings.online.start_free = StartFree::Bodies;
    let ex = run(&settings).unwrap();
    assert!(!ex.flight.report.contact);
}

/// A record written before `start_free` existed reads as a start that took only its
/// bodies as free, as those runs did; a record written now keeps its setting.
#[test]
fn an_exploration_record_without_start_free_took_the_bodies() {
    let record = ExploreRecord {
        format: "arc-explore/1".into(),
        end: ExploreEnd::Reached { t: 1.0 },
        pieces: 0,
        start_free: StartFree::Hull,
        summary: Default::default(),
        replans: Vec::new(),
        seen_occupied: None,
    };
    let mut v = serde_json::to_value(&record).unwrap();
    assert_eq!(v["start_free"], "hull");
    let back: ExploreRecord = serde_json::from_value(v.clone()).unwrap();
    assert_eq!(back, record);
    v.as_object_mut().unwrap().remove("start_free");
    let old: ExploreRecord = serde_json::from_value(v).unwrap();
    assert_eq!(old.start_free, StartFree::Bodies);
}

/// Pieces committed before the chain slows down for the end of the committed motion
/// are joined onto it in flight: at every such joint the flown reference keeps moving,
/// the joint passes the audit on its commit's map, and the flight is clear.
#[test]
fn pieces_committed_in_time_are_joined_in_flight_without_a_stop() {
    // Longer than the sensors' 5 m, so the chain flies it in pieces.
    let world = tunnel_to(11.9);
    let start = Waypoint::new([2.0, 0.5, 0.5], &aerial_chain_core::Shape::line(4, 0.0)).zeta;
    let goal = Point3::new(11.2, 0.5, 0.5);
    let ex = explore_audited(&world, 4, &start, goal, 200.0, StartFree::Hull);
    let joined: Vec<_> = ex.replans.iter().filter(|r| r.joined_moving).collect();
    assert!(
        !joined.is_empty(),
        "no piece joined in flight: {:?}",
        ex.replans
    );
    let reference = &ex.flight.reference;
    assert_eq!(ex.joints.len(), joined.len());
    let flown = ex.flight.report.simulated_time;
    for j in &ex.joints {
        let (from, to) = j.blend;
        assert!(j.take_by <= from && from < to && to <= j.until && j.until < flown);
        let slowest = (0..=20)
            .map(|k| from + (to - from) * f64::from(k) / 20.0)
            .map(|t| reference.sample(t).v.norm())
            .fold(f64::INFINITY, f64::min);
        assert!(
            slowest > 0.1,
            "the head slows to {slowest} m/s at the joint {from}..{to}"
        );
    }
}

/// Sensors that see 0.25 m find no piece from the start of `window`, and where the
/// chain rests they see nothing new: the run ends as stuck once the retries are spent
/// and a route period has passed without anything new, saying where the chain rests,
/// long before its time limit. With its sensors' full range the same run flies on
/// past that time.
#[test]
fn a_chain_that_sees_nothing_new_where_no_piece_is_found_is_stuck() {
    let (sc, params, tables, start) = window(4);
    let mut settings = ExploreSettings {
        time_limit_s: 60.0,
        ..ExploreSettings::default()
    };
    settings.survey.sensor.max_range = 0.25;
    let run = |s: &ExploreSettings| {
        explore(
            &sc.grid,
            params,
            tables.clone(),
            &start,
            sc.goal,
            0.3,
            None,
            s,
        )
        .unwrap()
    };
    let ex = run(&settings);
    let ExploreEnd::Stuck { t, why } = &ex.end else {
        panic!("{:?}", ex.end);
    };
    assert!(*t < 10.0, "stuck only at {t} s");
    assert!(why.contains("head at [2.00, 4.50, 1.50]"), "{why}");
    assert!(why.contains("nothing new"), "{why}");
    let last_failure = ex
        .replans
        .iter()
        .rev()
        .find(|r| r.outcome == Outcome::NoRoom)
        .expect("tries that failed");
    assert!(*t - last_failure.t >= settings.online.route_period_s);
    assert!(!ex.flight.report.contact);
    // The default sensor sees the way on: at the same time the run is still going.
    settings.survey.sensor = Default::default();
    settings.time_limit_s = *t + 1.0;
    let ex = run(&settings);
    assert!(
        matches!(ex.end, ExploreEnd::TimeLimit { .. }),
        "{:?}",
        ex.end
    );
}
