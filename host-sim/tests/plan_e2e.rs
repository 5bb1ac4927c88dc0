//! End to end: `arc plan` on every built-in scenario, checked by the exact validity
//! test of docs/model.md (`arc verify` and `verify_plan`), never by the planner's own
//! conservative shortcuts; failures and bad input give the right exit codes.

use std::path::Path;

use aerial_chain::collision::verify_plan;
use aerial_chain::plan_file::Plan;
use aerial_chain::planner::Query;
use aerial_chain::planning::{self, PlanOptions, Request};
use aerial_chain::problem::scenarios;
use aerial_chain_core::ChainParams;
mod support;

use support::{
    arc_ok, assert_verified_to_goal, plan_across_sealed_rooms, plan_scenario, plan_verified, s,
};

fn tmp() -> tempfile::TempDir {
    tempfile::tempdir().expect("temporary directory")
}

/// Plans `scenario` with `units`, verifies it exactly (through `arc verify` too),
/// returns the plan.
fn plan_and_verify(scenario: &str, units: u8, dir: &Path) -> Plan {
    let (plan, sc) = plan_verified(scenario, units, dir);
    let out = dir.join(format!("{scenario}-{units}.json"));
    arc_ok(&["verify", "--scenario", scenario, "--plan", s(&out)])
        .unwrap_or_else(|e| panic!("{scenario} N={units}: arc verify: {e}"));
    let report = verify_plan(&sc.grid, &plan);
    assert!(report.min_clearance > 0.0);
    // Starts at the scenario's start, in the start shape.
    let first = plan.waypoints[0].xi();
    assert!((0..3).all(|k| (first[k] - sc.start[k]).abs() <= 1e-6));
    let start_shape = sc.start_shape(units).expect("start shape");
    for (a, b) in plan.waypoints[0].eta().iter().zip(start_shape.as_slice()) {
        assert!((a - *b as f64).abs() < 1e-6, "start shape differs");
    }
    let changes = plan.stats["shape_changes"]
        .as_u64()
        .expect("shape_changes in stats");
    eprintln!(
        "{scenario} N={units}: {} waypoints, {changes} shape changes, min clearance {:.3} m",
        plan.waypoints.len(),
        report.min_clearance
    );
    assert!(
        changes > 0,
        "the scenarios are built so that the chain must change shape"
    );
    // Post-processing (the default) moves the chain's angles no more than the raw plan.
    let motion = |q: &serde_json::Value| q["shape_motion_rad"].as_f64().expect("shape motion");
    assert!(
        motion(&plan.stats["quality"]) <= motion(&plan.stats["refinement"]["before"]) + 1e-9,
        "{scenario} N={units}: post-processing added shape motion"
    );
    plan
}

/// Plans and verifies `scenario` for N = 4, 5 and 6.
fn plans_verify_for_4_to_6_units(scenario: &str) {
    let dir = tmp();
    for n in [4, 5, 6] {
        plan_and_verify(scenario, n, dir.path());
    }
}

#[test]
fn window_plans_verify() {
    plans_verify_for_4_to_6_units("window");
}

#[test]
fn maze_plans_verify() {
    plans_verify_for_4_to_6_units("maze");
}

#[test]
fn silos_plans_verify() {
    plans_verify_for_4_to_6_units("silos");
}

#[test]
fn corridor_plans_verify() {
    plans_verify_for_4_to_6_units("corridor");
}

#[test]
fn same_seed_same_plan_byte_for_byte() {
    let dir = tmp();
    // The maze's walls stand between start and goal, so the query needs the
    // uniform roadmap, whose samples the seed draws.
    let run = |name: &str, seed: &str| -> String {
        let out = dir.path().join(name);
        plan_scenario("maze", 5, &["--seed", seed], &out).expect("plan");
        let mut v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
        // Wall-clock timings are the one part that differs between runs.
        v["stats"].as_object_mut().unwrap().remove("timing");
        serde_json::to_string_pretty(&v).unwrap()
    };
    assert_eq!(run("a.json", "7"), run("b.json", "7"));
    assert_ne!(
        run("c.json", "7"),
        run("d.json", "8"),
        "another seed, another roadmap"
    );
}

/// The library's facade makes the plan `arc plan` writes with its defaults: the same
/// waypoints, the same quality, and the exact verifier accepts it.
#[test]
fn the_facade_plans_what_arc_plan_writes() {
    let dir = tmp();
    let (cli, sc) = plan_verified("maze", 5, dir.path());
    let query = Query::new(sc.start, sc.start_shape(5).expect("start shape"), sc.goal);
    let request = Request::new(sc.grid.clone(), ChainParams::new(5), query);
    let planned = planning::plan(&request, None, &PlanOptions::default()).expect("a plan");
    let zetas =
        |p: &Plan| -> Vec<Vec<f64>> { p.waypoints.iter().map(|w| w.zeta.clone()).collect() };
    assert_eq!(zetas(&planned.plan), zetas(&cli));
    assert_eq!(planned.plan.stats["quality"], cli.stats["quality"]);
    assert_eq!(
        planned.plan.stats["refinement"]["widening"],
        cli.stats["refinement"]["widening"]
    );
    let report = verify_plan(&sc.grid, &planned.plan);
    assert!(report.ok, "{:?}", report.violation);
}

/// `arc plan` has a documented default time limit, and a query it stops says what
/// was tried and how to give it longer.
#[test]
fn the_time_limit_has_a_default_and_its_failure_says_what_was_tried() {
    let help = support::run(&["plan", "--help"], Path::new("."));
    assert!(help.stdout.contains("[default: 60]"), "{help:?}");
    let dir = tmp();
    let out = dir.path().join("p.json");
    let e = plan_scenario("maze", 5, &["--time-limit", "1e-6"], &out).unwrap_err();
    assert_eq!(e.code, Some(1), "{e}");
    for says in [
        "time limit reached",
        "time limit stopped it after trying",
        "--time-limit",
    ] {
        assert!(e.message.contains(says), "{e}");
    }
    assert!(!out.exists(), "no plan file without a plan");
}

#[test]
fn unreachable_goal_exits_1_with_the_reason() {
    let dir = tmp();
    let (e, out) =
        plan_across_sealed_rooms(dir.path(), &["--vertices", "300", "--max-growth", "1"]);
    assert_eq!(e.code, Some(1), "{e}");
    assert!(
        e.message.contains("not reachable") || e.message.contains("separate free regions"),
        "{e}"
    );
    assert!(
        !out.exists(),
        "no plan file is written when there is no plan"
    );
}

#[test]
fn start_in_collision_names_the_body() {
    let dir = tmp();
    let out = dir.path().join("p.json");
    // Window scenario: the dividing wall stands at x = 4.0..4.2; unit 3 lands in it.
    let start = ["--start", "5.1,1,1.5", "--start-yaw-deg", "0"];
    let e = plan_scenario("window", 4, &start, &out).unwrap_err();
    // A start in collision is bad input (2), in `arc plan` as in `arc bench prm`.
    assert_eq!(e.code, Some(2), "{e}");
    assert!(
        e.message.contains("start is invalid") && e.message.contains("unit"),
        "{e}"
    );
}

#[test]
fn malformed_input_exits_2() {
    let dir = tmp();
    let out = dir.path().join("p.json");
    let o = s(&out);
    let garbage = dir.path().join("garbage.bt");
    std::fs::write(
        &garbage,
        b"# Octomap OcTree binary file\nid OcTree\nsize 99\nres 0.1\ndata\n\x03",
    )
    .unwrap();
    let mut cases: Vec<Vec<&str>> = vec![
        vec!["plan", "--scenario", "window", "--out"],
        vec!["plan", "--scenario", "window", "--start", "1,2", "--out", o],
        vec!["plan", "--scenario", "window", "--units", "40", "--out", o],
        vec!["plan", "--scenario", "nowhere", "--out", o],
        vec![
            "plan",
            "--scenario",
            "window",
            "--vertices",
            "0",
            "--out",
            o,
        ],
        vec![
            "plan",
            "--scenario",
            "window",
            "--start-shape",
            "XX",
            "--out",
            o,
        ],
        vec![
            "plan",
            "--scenario",
            "window",
            "--tables",
            s(&garbage),
            "--out",
            o,
        ],
        vec!["verify", "--scenario", "window", "--plan", s(&garbage)],
        vec!["tables", "inspect", s(&garbage)],
        vec!["frobnicate"],
    ];
    // A map file that is missing, and one that is no octree.
    for map in ["/no/such/map.bt", s(&garbage)] {
        let query = ["--units", "4", "--start", "1,1,1", "--goal", "2,2,2"];
        cases.push([&["plan", "--map", map], &query[..], &["--out", o]].concat());
    }
    for c in cases {
        let e = arc_ok(&c).expect_err(&format!("{c:?} must fail"));
        assert_eq!(e.code, Some(2), "{c:?}: {e}");
        assert!(!e.message.is_empty(), "{c:?}: an error names the problem");
    }
}

#[test]
fn a_tampered_plan_fails_verification() {
    let dir = tmp();
    let plan = plan_and_verify("window", 4, dir.path());
    // Push one waypoint's head into the dividing wall.
    let mut bad = plan.clone();
    let k = bad.waypoints.len() / 2;
    bad.waypoints[k].zeta[0] = 4.1;
    bad.waypoints[k].zeta[1] = 1.0;
    let path = dir.path().join("bad.json");
    bad.write(&path).unwrap();
    let e = arc_ok(&["verify", "--scenario", "window", "--plan", s(&path)]).unwrap_err();
    assert_eq!(e.code, Some(1), "{e}");
    assert!(e.message.contains("INVALID"), "{e}");
}

#[test]
fn plans_from_a_table_file_match_generated_tables() {
    let dir = tmp();
    let table = dir.path().join("t5.arct");
    arc_ok(&[
        "tables",
        "build",
        "--units",
        "5",
        "--srs",
        "500",
        "--seed",
        "1",
        "--out",
        s(&table),
    ])
    .unwrap();
    arc_ok(&["tables", "inspect", s(&table)]).unwrap();
    let (a, b) = (dir.path().join("a.json"), dir.path().join("b.json"));
    plan_scenario("maze", 5, &[], &a).unwrap();
    plan_scenario("maze", 5, &["--tables", s(&table)], &b).unwrap();
    let (pa, pb) = (Plan::read(&a).unwrap(), Plan::read(&b).unwrap());
    assert_eq!(
        pa.waypoints, pb.waypoints,
        "the file holds the very shapes the generator makes"
    );
    // A table for another chain is refused.
    let e = plan_scenario("maze", 6, &["--tables", s(&table)], &a).unwrap_err();
    assert_eq!(e.code, Some(2));
    assert!(e.message.contains("another chain"), "{e}");
}

/// Chains far longer than the room behind the window (N = 12: 5.5 m, N = 16: 7.5 m,
/// room 3.8 m deep) cannot pass it as rigid shapes: the search snakes them through
/// (follow-the-leader; seen in the raw plan, as refinement may merge those steps), and
/// every step of the raw and the refined plan passes the exact check.
#[test]
fn long_chains_snake_through_the_window() {
    let dir = tmp();
    let sc = scenarios::build("window").expect("built-in scenario");
    for units in [12u8, 16] {
        for smooth in [false, true] {
            let out = dir.path().join(format!("window-{units}-{smooth}.json"));
            let mut flags = vec!["--start-shape", "PN", "--start-yaw-deg", "90"];
            if !smooth {
                flags.push("--no-smooth");
            }
            plan_scenario("window", units, &flags, &out)
                .unwrap_or_else(|e| panic!("window N={units}: no plan: {e}"));
            let plan = Plan::read(&out).expect("plan file reads back");
            assert_verified_to_goal(&sc, &plan, &format!("window N={units}"));
            if !smooth {
                let follow = plan.stats["follow_uses"].as_u64().expect("follow_uses");
                assert!(follow > 0, "window N={units}: no follow-the-leader step");
            }
        }
    }
}

/// `--follow-step 0` is the paper's planner (rigid shapes only): it still plans the
/// window for N = 5, without a single follow-the-leader step.
#[test]
fn follow_step_zero_is_the_papers_planner() {
    let dir = tmp();
    let out = dir.path().join("window-5-paper.json");
    plan_scenario("window", 5, &["--follow-step", "0"], &out)
        .expect("window N=5 plans without follow-the-leader");
    let plan = Plan::read(&out).expect("plan file reads back");
    let sc = scenarios::build("window").expect("built-in scenario");
    assert!(verify_plan(&sc.grid, &plan).ok);
    assert_eq!(plan.stats["follow_uses"].as_u64(), Some(0));
    let sources = plan.stats["waypoint_sources"]
        .as_array()
        .expect("waypoint_sources");
    assert!(sources.iter().all(|w| w.as_str() != Some("follow")));
}

/// In the maze and the corridor the search's plans bend and unbend the chain round
/// every wall end and through every door; post-processing flies most of the way in
/// one compact library shape instead (carrying), with at most half the raw plan's
/// shape motion (the flight issue's target), and the plan passes the exact verifier.
#[test]
fn maze_and_corridor_plans_are_carried_with_half_the_shape_motion() {
    let dir = tmp();
    for (scenario, units) in [("maze", 4), ("maze", 6), ("corridor", 5), ("corridor", 6)] {
        let (plan, _) = plan_verified(scenario, units, dir.path());
        let refinement = &plan.stats["refinement"];
        let carried = &refinement["carried"][0];
        let shape = carried["shape"].as_str().unwrap_or_else(|| {
            panic!("{scenario} N={units}: not carried: {refinement}");
        });
        let motion = |q: &serde_json::Value| q["shape_motion_rad"].as_f64().expect("motion");
        let (raw, after) = (
            motion(&refinement["before"]),
            motion(&plan.stats["quality"]),
        );
        eprintln!(
            "{scenario} N={units}: carried first in {shape} for {:.2} m, shape motion {raw:.2} -> {after:.2} rad",
            carried["head_path_m"].as_f64().unwrap_or(f64::NAN)
        );
        assert!(after <= 0.5 * raw, "{scenario} N={units}: {raw} -> {after}");
    }
}

/// Refinement (the default) and `--no-smooth` both give plans the exact verifier
/// accepts; the refined plan asks no more of the chain than the raw one and records
/// the raw plan's quality beside its own.
#[test]
fn refined_plans_verify_and_ask_less_of_the_chain() {
    let dir = tmp();
    for (scenario, units) in [("window", 5), ("maze", 5), ("corridor", 4)] {
        let sc = scenarios::build(scenario).expect("built-in scenario");
        let plan = |name: &str, extra: &[&str]| -> Plan {
            let out = dir.path().join(name);
            plan_scenario(scenario, units, extra, &out)
                .unwrap_or_else(|e| panic!("{scenario}: {e}"));
            let plan = Plan::read(&out).expect("plan file reads back");
            let report = verify_plan(&sc.grid, &plan);
            assert!(report.ok, "{scenario} {name}: {:?}", report.violation);
            plan
        };
        let raw = plan(&format!("{scenario}-raw.json"), &["--no-smooth"]);
        let refined = plan(&format!("{scenario}-refined.json"), &[]);
        let q = |p: &Plan, key: &str| p.stats["quality"][key].as_f64().expect(key);
        assert!(raw.stats.get("refinement").is_none());
        for key in ["head_path_m", "shape_motion_rad", "shape_changes"] {
            assert_eq!(
                q(&raw, key),
                refined.stats["refinement"]["before"][key].as_f64().unwrap(),
                "{scenario}: the refined plan records the raw plan's {key}"
            );
        }
        // A stretch flown in one shape (carrying, docs/postprocessing.md) may take the
        // head round a wall end wider, by at most a quarter of its route and 1 m.
        assert!(q(&refined, "head_path_m") <= 1.25 * q(&raw, "head_path_m") + 1.0);
        assert!(q(&refined, "shape_changes") <= q(&raw, "shape_changes"));
        assert!(
            refined.waypoints.len() < raw.waypoints.len(),
            "{scenario}: refinement removed no waypoint"
        );
        eprintln!(
            "{scenario} N={units}: path {:.2} -> {:.2} m, shape motion {:.2} -> {:.2} rad, {} -> {} waypoints",
            q(&raw, "head_path_m"),
            q(&refined, "head_path_m"),
            q(&raw, "shape_motion_rad"),
            q(&refined, "shape_motion_rad"),
            raw.waypoints.len(),
            refined.waypoints.len()
        );
    }
}

/// `arc plan` says where its time went, phase by phase, the trajectory included.
#[test]
fn arc_plan_reports_every_phase() {
    let dir = tmp();
    let o = support::run(
        &[
            "plan",
            "--scenario",
            "window",
            "-n",
            "4",
            "--out",
            "p.json",
            "--trajectory",
            "t.json",
        ],
        dir.path(),
    );
    assert_eq!(o.code, Some(0), "{o:?}");
    let line = o
        .stdout
        .lines()
        .find(|l| l.trim_start().starts_with("phases: "))
        .unwrap_or_else(|| panic!("no phases line: {}", o.stdout));
    for phase in [
        "setup",
        "free regions",
        "head roadmap",
        "head route (lattice)",
        "shape search",
        "post-processing",
        "trajectory",
    ] {
        assert!(line.contains(&format!("{phase} ")), "{phase}: {line}");
    }
}
