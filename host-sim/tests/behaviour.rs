//! The behaviour snapshot: what planning, post-processing, the exact verifier, the
//! trajectory and the simulation do on a dozen scenarios, family instances, a real scan,
//! a goal pose and two missions, held against the committed record
//! `tests/snapshots/behaviour.json`. Any change of a plan, a verdict, a trajectory or a
//! flight fails here. To record a deliberate change, run
//! `ARC_REFRESH_SNAPSHOT=1 cargo test -p aerial-chain --test behaviour`, read the diff
//! of the record, and commit it with the reason.
//!
//! Timings are left out (the only part of a plan that differs between runs with the
//! same seed); long arrays (waypoints, samples) are recorded by their SHA-256, next to
//! readable counts and measures.

use std::path::{Path, PathBuf};

use aerial_chain::collision::verify_plan;
use aerial_chain::flying::{fly, FlyOptions};
use aerial_chain::goal::{parse_shape, GoalPose};
use aerial_chain::map::{Grid, OcTree};
use aerial_chain::mission::Mission;
use aerial_chain::plan_file::Plan;
use aerial_chain::planner::{Preference, Query};
use aerial_chain::planning::{plan, plan_mission, PlanOptions, Request};
use aerial_chain::problem::scenarios;
use aerial_chain::sim::Progress;
use aerial_chain::trajectory;
use aerial_chain_core::ChainParams;
use serde_json::{json, Map, Value};
use sha2::{Digest, Sha256};

/// The record, in the repository.
fn record_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/snapshots/behaviour.json")
}

/// SHA-256 of `f64`s, bit for bit, as hex.
fn digest(values: impl IntoIterator<Item = f64>) -> String {
    let mut h = Sha256::new();
    for v in values {
        h.update(v.to_bits().to_le_bytes());
    }
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

/// `v` without timings: keys `timing`, `wall_seconds`, `realtime_factor` and every key
/// ending in `_s`.
fn strip(v: &Value) -> Value {
    match v {
        Value::Object(m) => Value::Object(
            m.iter()
                .filter(|(k, _)| {
                    !(k.as_str() == "timing"
                        || k.as_str() == "wall_seconds"
                        || k.as_str() == "realtime_factor"
                        || k.ends_with("_s"))
                })
                .map(|(k, v)| (k.clone(), strip(v)))
                .collect(),
        ),
        Value::Array(a) => Value::Array(a.iter().map(strip).collect()),
        other => other.clone(),
    }
}

/// What a plan is and does: its waypoints (hashed), marks, stats without timings, the
/// exact verdict and its trajectory (hashed).
fn describe(plan: &Plan, grid: &Grid) -> Value {
    let zetas = plan.waypoints.iter().flat_map(|w| w.zeta.iter().copied());
    let marks: Vec<Value> = plan
        .waypoints
        .iter()
        .enumerate()
        .filter(|(_, w)| w.goal.is_some())
        .map(|(i, w)| json!([i, w.goal, w.hold_s]))
        .collect();
    let report = verify_plan(grid, plan);
    let tr = trajectory::build(plan, grid, &trajectory::Settings::default());
    let timed = match &tr {
        Ok(t) => json!({
            "duration": t.duration(),
            "samples": t.times().len(),
            "blended": t.blended(),
            "merged": t.merged(),
            "sha256": digest(t.times().iter().copied().chain(t.zetas().iter().flatten().copied())),
        }),
        Err(e) => json!({"error": e.to_string()}),
    };
    json!({
        "waypoints": plan.waypoints.len(),
        "waypoints_sha256": digest(zetas),
        "goals": marks,
        "stats": strip(&Value::Object(plan.stats.clone())),
        "verify": {"ok": report.ok, "samples": report.samples,
                   "min_clearance": format!("{:.9}", report.min_clearance)},
        "trajectory": timed,
    })
}

/// A scenario's query for `units` units (its start, yaw, LI and goal).
fn scenario(name: &str, units: u8) -> (Grid, ChainParams, Query) {
    let sc = scenarios::build(name).unwrap();
    let query = Query::new(sc.start, sc.start_shape(units).unwrap(), sc.goal);
    (sc.grid, ChainParams::new(units), query)
}

/// A plan as `arc plan` makes it with its defaults and `change`'s options.
fn planned(
    grid: Grid,
    params: ChainParams,
    query: Query,
    pose: GoalPose,
    change: impl Fn(&mut PlanOptions),
) -> (Plan, Grid) {
    let mut options = PlanOptions::default();
    change(&mut options);
    let request = Request::new(grid, params, query).with_pose(pose);
    let plan = plan(&request, None, &options).unwrap().plan;
    (plan, request.grid().clone())
}

/// The flight of `plan`, as `arc sim` flies it: its report without timings and every
/// 50th record (time and unit centres) hashed.
fn flown(plan: &Plan, grid: &Grid) -> Value {
    let (flight, _) = fly(plan, grid, &FlyOptions::default(), &Progress::default()).unwrap();
    let report = strip(&serde_json::to_value(&flight.report).unwrap());
    let values =
        flight.samples.iter().step_by(50).flat_map(|s| {
            std::iter::once(s.t).chain(s.units.iter().flat_map(|u| u.p.map(f64::from)))
        });
    json!({"report": report, "samples_sha256": digest(values)})
}

/// Every case of the record, by name.
fn cases() -> Map<String, Value> {
    let mut out = Map::new();
    let none = GoalPose::default();
    for (name, units) in [
        ("window", 3),
        ("window", 5),
        ("maze", 5),
        ("silos", 5),
        ("corridor", 5),
        ("passage:w=0.5,angle=30", 5),
        ("passage:w=0.55,angle=45,offset=0.1", 6),
    ] {
        let (g, p, q) = scenario(name, units);
        let (plan, grid) = planned(g, p, q, none, |_| {});
        let mut d = describe(&plan, &grid);
        if matches!((name, units), ("window", 3) | ("maze", 5)) {
            d["flight"] = flown(&plan, &grid);
        }
        out.insert(format!("{name} N={units}"), d);
    }
    let (g, p, q) = scenario("silos", 5);
    let (plan, grid) = planned(g, p, q, none, |o| o.planner.prefer = Preference::Coverage);
    out.insert("silos N=5 coverage".into(), describe(&plan, &grid));
    let (g, p, q) = scenario("window", 5);
    let pose = GoalPose {
        yaw: Some(45f32.to_radians()),
        shape: Some(parse_shape(&p, "PN").unwrap()),
    };
    let (plan, grid) = planned(g, p, q, pose, |_| {});
    out.insert("window N=5 goal PN yaw 45".into(), describe(&plan, &grid));
    let scan = Path::new(env!("CARGO_MANIFEST_DIR")).join("../maps/geb079.bt");
    let tree = OcTree::read_bt(&scan).unwrap();
    let grid = Grid::from_octree(&tree, false).unwrap();
    let p = ChainParams::new(5);
    let q = Query::new(
        [-3.0, 0.0, 1.0].into(),
        aerial_chain_core::Shape::line(5, 0.0),
        [25.0, 0.0, 1.0].into(),
    );
    let (plan, grid) = planned(grid, p, q, none, |_| {});
    out.insert("geb079 N=5".into(), describe(&plan, &grid));
    for (name, file) in [("silos", "silos.json"), ("maze", "maze.json")] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../missions")
            .join(file);
        let mission = Mission::read(&path).unwrap();
        let (g, p, q) = scenario(name, 5);
        let base = Request::new(g, p, q);
        let planned = plan_mission(&base, &mission, None, &PlanOptions::default()).unwrap();
        out.insert(
            format!("mission {file}"),
            describe(&planned.plan, base.grid()),
        );
    }
    out
}

#[test]
fn behaviour_matches_the_record() {
    let now = Value::Object(cases());
    let path = record_path();
    if std::env::var_os("ARC_REFRESH_SNAPSHOT").is_some() {
        let text = serde_json::to_string_pretty(&now).unwrap() + "\n";
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, text).unwrap();
        return;
    }
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| {
        panic!(
            "{}: {e}; record it with ARC_REFRESH_SNAPSHOT=1",
            path.display()
        )
    });
    let record: Value = serde_json::from_str(&text).unwrap();
    let (want, got) = (record.as_object().unwrap(), now.as_object().unwrap());
    let mut changed = Vec::new();
    for (case, value) in got {
        match want.get(case) {
            Some(v) if v == value => {}
            Some(v) => changed.push(format!(
                "{case}:\n  recorded {}\n  now      {}",
                serde_json::to_string(v).unwrap(),
                serde_json::to_string(value).unwrap()
            )),
            None => changed.push(format!("{case}: not in the record")),
        }
    }
    for case in want.keys().filter(|k| !got.contains_key(*k)) {
        changed.push(format!("{case}: recorded, no longer run"));
    }
    assert!(
        changed.is_empty(),
        "behaviour changed (ARC_REFRESH_SNAPSHOT=1 records a deliberate change):\n{}",
        changed.join("\n")
    );
}
