//! Goal configurations and missions with the real `arc` binary (docs/model.md, "Goal
//! configurations", "Missions"): plans verified exactly and by the goals they must
//! reach in order, trajectories that rest at every goal for its hold, flights without
//! contact, and the refusals: bad files, goals and legs (exit 2, naming them).

mod support;

use std::path::{Path, PathBuf};

use support::expect;

/// The repository's missions directory.
fn missions() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../missions")
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Plans `mission` on `scenario`, verifies it against the mission, checks that its
/// trajectory rests at every goal for the goal's hold, and flies it.
fn plan_verify_fly(scenario: &str, mission: &str) {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let m = missions().join(mission);
    let m = m.to_str().unwrap();
    let base = ["--scenario", scenario];
    expect(
        &[
            &["plan"][..],
            &base,
            &["--mission", m, "--out", "p.json", "--trajectory", "t.json"],
        ]
        .concat(),
        d,
        0,
    );
    let o = expect(
        &[
            &["verify"][..],
            &base,
            &["--plan", "p.json", "--mission", m],
        ]
        .concat(),
        d,
        0,
    );
    let goals = json(Path::new(m))["goals"].as_array().unwrap().len();
    assert_eq!(
        o.stdout.matches(" reached at waypoint ").count(),
        goals,
        "{}",
        o.stdout
    );
    let plan = json(&d.join("p.json"));
    let marked: Vec<(usize, f64)> = plan["waypoints"]
        .as_array()
        .unwrap()
        .iter()
        .enumerate()
        .filter(|(_, w)| w.get("goal").is_some())
        .map(|(i, w)| (i, w.get("hold_s").and_then(|h| h.as_f64()).unwrap_or(0.0)))
        .collect();
    assert_eq!(marked.len(), goals);
    rests_at_goals(&plan, &json(&d.join("t.json")), &marked);
    expect(
        &[&["verify"][..], &base, &["--trajectory", "t.json"]].concat(),
        d,
        0,
    );
    let o = expect(&[&["sim"][..], &base, &["--plan", "p.json"]].concat(), d, 0);
    assert!(o.stdout.contains("reached the goal"), "{}", o.stdout);
}

/// Every marked waypoint is held in the trajectory at rest for at least its hold.
fn rests_at_goals(plan: &serde_json::Value, tr: &serde_json::Value, marked: &[(usize, f64)]) {
    let samples = tr["samples"].as_array().unwrap();
    let zeta = |v: &serde_json::Value| -> Vec<f64> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    let dt = tr["dt"].as_f64().unwrap();
    for &(i, hold) in marked {
        let want = zeta(&plan["waypoints"][i]["zeta"]);
        let at: Vec<f64> = samples
            .iter()
            .filter(|s| {
                let z = zeta(&s["zeta"]);
                // The head exactly, the angles up to whole turns (trajectories unwrap).
                z[..3].iter().zip(&want).all(|(a, b)| (a - b).abs() < 1e-9)
                    && z[3..].iter().zip(&want[3..]).all(|(a, b)| {
                        let d = (a - b).rem_euclid(std::f64::consts::TAU);
                        d.min(std::f64::consts::TAU - d) < 1e-6
                    })
            })
            .map(|s| s["t"].as_f64().unwrap())
            .collect();
        assert!(
            !at.is_empty(),
            "waypoint {i} is never at rest in the trajectory"
        );
        let rest = at.last().unwrap() - at.first().unwrap();
        assert!(
            rest >= hold - dt - 1e-9,
            "waypoint {i}: rests {rest} s, hold {hold} s"
        );
    }
}

#[test]
fn the_silo_inspection_plans_verifies_rests_and_flies() {
    plan_verify_fly("silos", "silos.json");
}

#[test]
fn a_six_goal_maze_mission_plans_verifies_rests_and_flies() {
    plan_verify_fly("maze", "maze.json");
}

#[test]
fn a_goal_shape_and_yaw_end_the_plan_and_verify_checks_them() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let pose = ["--goal-shape", "PN", "--goal-yaw-deg", "45"];
    let base = ["--scenario", "window", "--units", "5"];
    expect(
        &[&["plan"][..], &base, &pose, &["--out", "p.json"]].concat(),
        d,
        0,
    );
    expect(
        &[&["verify"][..], &base[..2], &pose, &["--plan", "p.json"]].concat(),
        d,
        0,
    );
    let o = expect(
        &[
            &["verify"][..],
            &base[..2],
            &["--goal-shape", "SE", "--plan", "p.json"],
        ]
        .concat(),
        d,
        1,
    );
    assert!(o.stderr.contains("shape SE"), "{}", o.stderr);
    // Any heading: the plan ends in PN turned, which PN without a yaw accepts.
    expect(
        &[
            &["verify"][..],
            &base[..2],
            &["--goal-shape", "pn", "--plan", "p.json"],
        ]
        .concat(),
        d,
        0,
    );
}

#[test]
fn bad_missions_and_goals_are_refused_and_a_failed_leg_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let write = |name: &str, text: &str| std::fs::write(d.join(name), text).unwrap();
    write(
        "typo.json",
        r#"{"format": "arc-mission/1", "goals": [{"position": [9, 3.5, 1.4], "hold": 1}]}"#,
    );
    let o = expect(
        &[
            "plan",
            "--scenario",
            "maze",
            "--mission",
            "typo.json",
            "--out",
            "p.json",
        ],
        d,
        2,
    );
    assert!(
        o.stderr.contains("typo.json") && o.stderr.contains("hold"),
        "{}",
        o.stderr
    );
    // Goal 1 lies inside the maze's middle wall: the leg is refused, by name.
    write(
        "wall.json",
        r#"{"format": "arc-mission/1", "goals": [{"position": [1.45, 1.2, 1.4]},
            {"position": [5.3, 3.0, 1.4], "tolerance": 0.05}]}"#,
    );
    let o = expect(
        &[
            "plan",
            "--scenario",
            "maze",
            "--mission",
            "wall.json",
            "--out",
            "p.json",
        ],
        d,
        2,
    );
    assert!(o.stderr.contains("leg 1"), "{}", o.stderr);
    assert!(!d.join("p.json").exists());
    // A configuration valid nowhere at the goal: PN trailing west of a head 0.4 m from
    // the west wall (its polygon reaches 0.85 m behind the head).
    let o = expect(
        &[
            "plan",
            "--scenario",
            "maze",
            "--goal",
            "0.6,3.0,1.4",
            "--goal-shape",
            "PN",
            "--goal-yaw-deg",
            "0",
            "--out",
            "p.json",
        ],
        d,
        2,
    );
    assert!(o.stderr.contains("goal configuration"), "{}", o.stderr);
}
