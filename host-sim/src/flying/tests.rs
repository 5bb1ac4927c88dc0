//! Flying's tests: the clock of a plan is the motion flown, blended or not.

use aerial_chain_core::ChainParams;
use nalgebra::Vector3;

use super::*;
use crate::planner::Query;
use crate::planning::{plan, PlanOptions, Request};
use crate::problem::scenarios;
use crate::sim::ReferenceLimits;

/// The `window` scenario and a plan through it for a chain of 3, or, with `short`, a
/// plan 0.5 m straight ahead of the start (a flight of seconds).
fn window_plan(short: bool) -> (Grid, Plan) {
    let sc = scenarios::build("window").unwrap();
    let ahead = Vector3::new(sc.start_yaw.cos(), sc.start_yaw.sin(), 0.0);
    let goal = match short {
        true => sc.start + 0.5 * ahead,
        false => sc.goal,
    };
    let mut query = Query::new(sc.start, sc.start_shape(3).unwrap(), goal);
    query.goal_tol = 0.05;
    let request = Request::new(sc.grid.clone(), ChainParams::new(3), query);
    let options = PlanOptions {
        srs: 60,
        ..PlanOptions::default()
    };
    (sc.grid, plan(&request, None, &options).unwrap().plan)
}

#[test]
fn a_plan_is_timed_along_its_trajectory_and_its_waypoints_on_that_clock() {
    let (grid, plan) = window_plan(false);
    let timed = time(&plan, &grid, &FlyOptions::default()).unwrap();
    let Timing::Trajectory(tr) = &timed.timing else {
        panic!("the window plan is admissible as a trajectory");
    };
    let hold = ReferenceLimits::default().start_hold;
    assert_eq!(timed.start_hold, hold);
    assert!((timed.reference.duration() - (tr.reference().duration() + hold)).abs() < 1e-9);
    let (t, leave) = timed.waypoint_times(&plan);
    assert_eq!(t.len(), plan.waypoints.len());
    assert_eq!((t[0], leave[0]), (0.0, hold));
    assert_eq!(t[t.len() - 1], timed.reference.duration());
    assert!(t.windows(2).all(|w| w[0] <= w[1]), "{t:?}");
    // Stopping at every waypoint, the old clock, takes longer: the two are told apart.
    let options = FlyOptions {
        timing: trajectory::Settings {
            blend: false,
            ..Default::default()
        },
        ..Default::default()
    };
    let stopping = time(&plan, &grid, &options).unwrap();
    assert!(matches!(stopping.timing, Timing::StopAtWaypoints(None)));
    let (ts, _) = stopping.waypoint_times(&plan);
    assert_eq!(ts[ts.len() - 1], stopping.reference.duration());
    assert!(stopping.reference.duration() > timed.reference.duration() + 1.0);
}

#[test]
fn the_flight_flies_the_motion_it_was_timed_with() {
    let (grid, plan) = window_plan(true);
    let options = FlyOptions::default();
    let (flight, timed) = fly(&plan, &grid, &options, &Progress::default()).unwrap();
    assert!(matches!(timed.timing, Timing::Trajectory(_)));
    let r = &flight.report;
    assert_eq!(r.planned_duration, timed.reference.duration());
    assert!(r.success(), "{r:?}");
}

#[test]
fn settings_outside_their_limits_are_refused_before_any_flight() {
    let (grid, plan) = window_plan(true);
    let mut options = FlyOptions::default();
    options.sim.rate = 10.0;
    let e = fly(&plan, &grid, &options, &Progress::default()).unwrap_err();
    assert!(matches!(e, FlyError::Sim(SimError::Config(_))), "{e}");
    assert!(e.to_string().contains("rate"), "{e}");
}
