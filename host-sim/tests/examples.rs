//! The library examples (`examples/`) run here, on the same code `cargo run --example`
//! runs: each example file is included as a module and its entry point called.

#[path = "../examples/fly.rs"]
mod fly;

// `fly` includes `plan_on_map.rs`; one copy of it serves both.
use fly::plan_on_map;

#[test]
fn plan_on_map_plans_the_real_scan_and_the_plan_verifies() {
    let map = plan_on_map::geb079();
    let problem = plan_on_map::corridor(&map);
    let (_, plan) = plan_on_map::plan_on_map(&problem).unwrap_or_else(|e| panic!("{e}"));
    let last = plan.waypoints.last().unwrap().xi();
    let d = (0..3)
        .map(|i| (last[i] - problem.goal[i]).powi(2))
        .sum::<f64>();
    assert!(d.sqrt() <= 0.3, "ends at {last:?}");
    assert!(plan.map.source.sha256.is_some(), "{:?}", plan.map.source);
}

#[test]
fn fly_writes_a_bt_plans_on_it_and_flies_the_plan() {
    let dir = tempfile::tempdir().unwrap();
    let r = fly::fly("window", dir.path()).unwrap_or_else(|e| panic!("{e}"));
    assert!(dir.path().join("window.bt").is_file());
    assert!(r.success(), "{r:?}");
    assert!(r.min_clearance.is_some_and(|c| c > 0.0), "{r:?}");
}

#[test]
fn plan_on_map_names_a_missing_map() {
    let missing = std::path::Path::new("no/such/map.bt");
    let Err(e) = plan_on_map::plan_on_map(&plan_on_map::corridor(missing)) else {
        panic!("a missing map is an error");
    };
    assert!(e.to_string().contains("no/such/map.bt"), "{e}");
}
