//! End to end: the planner's plans for the built-in scenarios, flown by `arc sim`
//! (multibody dynamics, head MPC, link SO(3) controllers, unit attitude loops) and
//! checked for contact with the map by the exact checker.
//!
//! Bounds, and why:
//! - the head never strays more than 0.05 m from its reference: that is the clearance
//!   margin the planner keeps around every body (`collision::DEFAULT_CLEARANCE`), so a
//!   flight within it cannot turn a planned clearance into a contact (measured: at most
//!   0.017 m on every scenario, N = 4..6);
//! - every link stays within 2 degrees of its planned direction (measured: below 1
//!   degree); with 0.5 m links that moves a unit at most 1.7 cm per link;
//! - the flown chain keeps a positive exact clearance and reaches the plan's goal.

use aerial_chain::collision::DEFAULT_CLEARANCE;
mod support;

use support::{arc_ok, plan_scenario, s};

fn plan_and_fly(scenario: &str, units: u8) {
    plan_and_fly_with(scenario, units, &[]);
}

/// Plans `scenario` for `units` with the extra `arc plan` flags, flies it, checks it;
/// returns the flight's report and the plan.
fn plan_and_fly_with(
    scenario: &str,
    units: u8,
    flags: &[&str],
) -> (serde_json::Value, serde_json::Value) {
    let dir = tempfile::tempdir().expect("temporary directory");
    let plan = dir.path().join("plan.json");
    let out = dir.path().join("sim.json");
    let pic = dir.path().join("sim.svg");
    plan_scenario(scenario, units, flags, &plan)
        .unwrap_or_else(|e| panic!("{scenario} N={units}: no plan: {e}"));
    arc_ok(&[
        "sim",
        "--scenario",
        scenario,
        "--plan",
        s(&plan),
        "--out",
        s(&out),
        "--picture",
        s(&pic),
    ])
    .unwrap_or_else(|e| panic!("{scenario} N={units}: arc sim failed: {e}"));
    let text = std::fs::read_to_string(&out).expect("sim output");
    let v: serde_json::Value = serde_json::from_str(&text).expect("sim output is JSON");
    assert_eq!(v["format"], "arc-sim/1");
    let r = &v["report"];
    let f = |k: &str| r[k].as_f64().unwrap_or_else(|| panic!("report.{k}"));
    eprintln!(
        "{scenario} N={units}: flown {:.1} s, head max {:.4} m, link max {:.3} deg, clearance {:.3} m, {:.1}x real time",
        f("simulated_time"),
        f("head_max"),
        f("link_max_deg"),
        f("min_clearance"),
        f("realtime_factor")
    );
    assert_eq!(r["reached_goal"], true);
    assert_eq!(r["contact"], false);
    assert_eq!(r["self_contact"], false);
    assert_eq!(r["diverged"], false);
    assert!(f("min_clearance") > 0.0);
    assert!(
        f("head_max") < DEFAULT_CLEARANCE,
        "{scenario} N={units}: head strayed {} m",
        f("head_max")
    );
    assert!(
        f("link_max_deg") < 2.0,
        "{scenario} N={units}: a link strayed {} deg",
        f("link_max_deg")
    );
    assert_eq!(r["mpc_failures"], 0);
    let svg = std::fs::read_to_string(&pic).expect("picture");
    assert!(svg.starts_with("<svg") && svg.contains("flown chain"));
    let plan: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&plan).expect("plan")).expect("plan JSON");
    (r.clone(), plan)
}

#[test]
fn window_n4() {
    plan_and_fly("window", 4);
}

#[test]
fn window_n6() {
    plan_and_fly("window", 6);
}

/// `arc sim` flies the blended trajectory by default: maze N = 5 arrives without
/// contact (checked above) in at most 2.25 times the time its head path takes at the
/// speed limit (0.5 m/s), the 1 s hold at the start included. Measured: 2.16, where
/// stopping at every waypoint took 3.1. The target is 2: out of reach for this
/// plan, whose shape changes alone take 32.7 s at 23 deg/s against 31.8 s of path.
#[test]
fn maze_n5_flies_its_trajectory_fast() {
    let (r, plan) = plan_and_fly_with("maze", 5, &[]);
    let path = plan["stats"]["quality"]["head_path_m"]
        .as_f64()
        .expect("stats.quality.head_path_m");
    let flown = r["time_to_complete"].as_f64().expect("time_to_complete");
    eprintln!(
        "maze N=5: flown {flown:.1} s, path {path:.2} m: {:.2} x path / speed",
        flown / (path / 0.5)
    );
    assert!(
        flown <= 2.25 * path / 0.5,
        "{flown} s for a {path} m head path"
    );
}

#[test]
fn silos_n4() {
    plan_and_fly("silos", 4);
}

#[test]
fn silos_n6() {
    plan_and_fly("silos", 6);
}

/// A 5.5 m chain snakes through the window (follow-the-leader, hundreds of short
/// steps) and flies it the same way.
#[test]
fn window_n12_snakes_through() {
    plan_and_fly_with(
        "window",
        12,
        &["--start-shape", "PN", "--start-yaw-deg", "90"],
    );
}

#[test]
fn bad_plans_are_input_errors() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let bad = dir.path().join("bad.json");
    std::fs::write(&bad, "{\"format\": \"nope\"}").unwrap();
    let e = arc_ok(&["sim", "--scenario", "window", "--plan", s(&bad)]).unwrap_err();
    assert_eq!(e.code, Some(2), "{}", e.message);
    let e = arc_ok(&[
        "sim",
        "--scenario",
        "window",
        "--plan",
        s(&dir.path().join("missing.json")),
    ])
    .unwrap_err();
    assert_eq!(e.code, Some(2));
    let e = arc_ok(&["sim", "--scenario", "nowhere", "--plan", s(&bad)]).unwrap_err();
    assert_eq!(e.code, Some(2));
}

#[test]
fn a_plan_into_a_wall_fails_with_exit_1() {
    // A straight translation of the window scenario's start chain into the wall.
    let dir = tempfile::tempdir().expect("temporary directory");
    let sc = aerial_chain::problem::scenarios::build("window").unwrap();
    let params = aerial_chain_core::ChainParams::new(4);
    let shape = sc.start_shape(4).unwrap();
    let start: [f64; 3] = sc.start.into();
    let goal = [sc.goal.x, start[1], start[2]];
    let plan = aerial_chain::plan_file::Plan {
        format: aerial_chain::plan_file::FORMAT.into(),
        chain: aerial_chain::plan_file::ChainSection::from_params(&params),
        map: aerial_chain::plan_file::MapSection::new(sc.grid.resolution(), true),
        waypoints: vec![
            aerial_chain::plan_file::Waypoint::new(start, &shape),
            aerial_chain::plan_file::Waypoint::new(goal, &shape),
        ],
        stats: Default::default(),
    };
    let path = dir.path().join("wall.json");
    plan.write(&path).unwrap();
    let e = arc_ok(&["sim", "--scenario", "window", "--plan", s(&path)]).unwrap_err();
    assert_eq!(e.code, Some(1), "{}", e.message);
    assert!(e.message.contains("touched"), "{}", e.message);
}
