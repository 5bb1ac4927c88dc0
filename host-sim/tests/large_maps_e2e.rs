//! End to end on a large generated map: the 60 x 40 x 10 m office hall at 0.1 m
//! (24 million cells), a hop in its corridor and the crossing from a room at one end to
//! a room at the other, each plan checked by the exact verifier.

mod support;

use aerial_chain::plan_file::Plan;
use aerial_chain::problem::scenarios;
use support::{assert_verified_to_goal, plan_scenario, plan_verified};

#[test]
fn hall_crossing_and_corridor_hop_plan_with_defaults() {
    let dir = tempfile::tempdir().unwrap();
    // The long crossing: out of a room, 54 m down the corridor, into another room.
    let (plan, sc) = plan_verified("hall", 5, dir.path());
    let path = plan.stats["quality"]["head_path_m"].as_f64().unwrap();
    assert!(path > 54.0, "the crossing is {path} m");
    // A 5 m hop along the corridor.
    let out = dir.path().join("hop.json");
    let flags = [
        "--start",
        "20,20,1.3",
        "--start-yaw-deg",
        "0",
        "--goal",
        "25,20,1.3",
    ];
    plan_scenario("hall", 5, &flags, &out).unwrap_or_else(|e| panic!("hop: {e}"));
    let hop = Plan::read(&out).unwrap();
    let mut at = sc.clone();
    at.goal = nalgebra::Point3::new(25.0, 20.0, 1.3);
    assert_verified_to_goal(&at, &hop, "hall hop");
}

#[test]
fn large_map_names_check_their_resolution() {
    assert!(scenarios::build("campus:0.05").is_err());
    assert!(scenarios::build("hall:x").is_err());
    let sc = scenarios::build("campus:0.4").unwrap();
    assert_eq!(sc.grid.dims(), [250, 250, 50]);
}
