//! Flying into the unknown with the real `arc` binary (docs/online.md): from an empty
//! map to the goal on a maze and a passage of the family, every committed piece in
//! space the sensors had seen free and the flight clear at every step; a dead end
//! that forces the chain back; a sealed goal; a sensor that sees nearly nothing; bad
//! sensor settings.

mod support;

use std::path::Path;

use aerial_chain::map::{Cell, Grid};
use support::{arc, s, spawn, wait_at_most, Outcome};

/// Wall time an exploration may take before it counts as hung: a maze flight of about
/// 100 simulated seconds takes about a minute on one core.
const GUARD_S: u64 = 900;

/// Runs `arc args` in `dir` under the exploration guard and checks its exit code.
fn expect(args: &[&str], dir: &Path, code: i32) -> Outcome {
    let o = wait_at_most(spawn(&mut arc(args, dir)), args, GUARD_S);
    assert!(!o.crashed(), "arc {args:?} crashed: {o:?}");
    assert_eq!(o.code, Some(code), "arc {args:?}: {o:?}");
    o
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Explores `world` (`--scenario NAME` or `--map FILE` and the query), then checks
/// that the goal was reached without contact, that the flown plan is valid on the
/// world and on the map the sensors drew (unknown space occupied: nothing was flown
/// through space never seen free), and returns the flight file.
fn explore_to_goal(world: &[&str], dir: &Path) -> serde_json::Value {
    let out = [
        "--out",
        "f.json",
        "--plan-out",
        "p.json",
        "--map-out",
        "seen.bt",
    ];
    expect(&[&["explore"][..], world, &out].concat(), dir, 0);
    let flight = json(&dir.join("f.json"));
    assert_eq!(flight["format"], "arc-sim/1");
    assert_eq!(flight["explore"]["format"], "arc-explore/1");
    assert_eq!(flight["explore"]["end"]["kind"], "reached");
    assert_eq!(flight["report"]["contact"], false);
    assert!(flight["report"]["min_clearance"].as_f64().unwrap() > 0.0);
    let map_args: Vec<&str> = world
        .iter()
        .take_while(|a| !a.starts_with("--units") && !a.starts_with("--start"))
        .copied()
        .collect();
    let o = expect(
        &[&["verify"][..], &map_args, &["--plan", "p.json"]].concat(),
        dir,
        0,
    );
    assert!(o.stdout.contains("VALID"), "{o:?}");
    let o = expect(&["verify", "--map", "seen.bt", "--plan", "p.json"], dir, 0);
    assert!(o.stdout.contains("VALID"), "{o:?}");
    let replans = flight["explore"]["replans"].as_array().unwrap();
    assert!(replans.iter().any(|r| r["outcome"]["kind"] == "committed"));
    flight
}

#[test]
fn a_maze_from_an_empty_map() {
    let dir = tempfile::tempdir().unwrap();
    explore_to_goal(&["--scenario", "maze"], dir.path());
}

#[test]
fn a_passage_of_the_family_from_an_empty_map() {
    let dir = tempfile::tempdir().unwrap();
    explore_to_goal(
        &[
            "--scenario",
            "passage:w=0.5,angle=30,offset=0.1",
            "--units",
            "5",
        ],
        dir.path(),
    );
}

/// A room split by a wall with two openings: the near one leads into a pocket whose
/// far end and side wall the sensors cannot see from the start; the far one leads to
/// the goal.
fn pocket_world(dir: &Path) -> std::path::PathBuf {
    let mut g = Grid::new(0.1, [0, 0, 0], [100, 60, 30], Cell::Free, true).unwrap();
    let mut wall = |lo: [f64; 3], hi: [f64; 3]| g.fill_box(lo, hi, Cell::Occupied);
    wall([0.0, 0.0, 0.0], [10.0, 6.0, 0.2]);
    wall([0.0, 0.0, 2.8], [10.0, 6.0, 3.0]);
    wall([0.0, 0.0, 0.0], [0.2, 6.0, 3.0]);
    wall([9.8, 0.0, 0.0], [10.0, 6.0, 3.0]);
    wall([0.0, 0.0, 0.0], [10.0, 0.2, 3.0]);
    wall([0.0, 5.8, 0.0], [10.0, 6.0, 3.0]);
    // The dividing wall, openings at y 0.6-1.6 (the pocket's) and 4.4-5.4.
    wall([4.0, 0.0, 0.0], [4.2, 0.6, 3.0]);
    wall([4.0, 1.6, 0.0], [4.2, 4.4, 3.0]);
    wall([4.0, 5.4, 0.0], [4.2, 6.0, 3.0]);
    for (lo, hi) in [([0.6, 1.0], [1.6, 2.0]), ([4.4, 1.0], [5.4, 2.0])] {
        wall([4.0, lo[0], 0.0], [4.2, hi[0], lo[1]]);
        wall([4.0, lo[0], hi[1]], [4.2, hi[0], 3.0]);
    }
    // The pocket: a side wall at y 2.2-2.4 and an end wall at x 8.5-8.7.
    wall([4.2, 2.2, 0.0], [8.7, 2.4, 3.0]);
    wall([8.5, 0.0, 0.0], [8.7, 2.4, 3.0]);
    let path = dir.join("pocket.bt");
    g.to_octree().unwrap().write_bt(&path).unwrap();
    path
}

#[test]
fn a_dead_end_sends_the_chain_back() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let world = pocket_world(d);
    let query = [
        "--map",
        s(&world),
        "--units",
        "3",
        "--start",
        "2,1.1,1.5",
        "--start-yaw-deg",
        "0",
        "--goal",
        "8,4,1.5",
    ];
    let flight = explore_to_goal(&query, d);
    let heads = flight["samples"].as_array().unwrap().iter().map(|s| {
        let p = &s["units"][0]["p"];
        (p[0].as_f64().unwrap(), p[1].as_f64().unwrap())
    });
    let in_pocket = heads.clone().any(|(x, y)| x > 5.0 && y < 2.2);
    assert!(in_pocket, "the chain never entered the pocket");
    let replans = flight["explore"]["replans"].as_array().unwrap();
    assert!(replans.iter().any(|r| r["trigger"] == "route_cut"));
}

#[test]
fn a_sealed_goal_ends_the_run_with_the_reason() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let world = support::sealed_rooms(d);
    let o = expect(
        &[
            "explore",
            "--map",
            s(&world),
            "--units",
            "3",
            "--start",
            "2,2,1.5",
            "--start-yaw-deg",
            "0",
            "--goal",
            "6,2,1.5",
            "--out",
            "f.json",
        ],
        d,
        1,
    );
    assert!(o.stderr.contains("the goal cannot be reached"), "{o:?}");
    assert!(o.stderr.contains("even with unknown space free"), "{o:?}");
    let flight = json(&d.join("f.json"));
    assert_eq!(flight["explore"]["end"]["kind"], "sealed");
    assert_eq!(flight["report"]["contact"], false);
}

#[test]
fn a_sensor_that_sees_almost_nothing_keeps_the_chain_in_known_space() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let o = expect(
        &[
            "explore",
            "--scenario",
            "window",
            "--units",
            "4",
            "--sensor-range",
            "0.25",
            "--time-limit",
            "15",
            "--out",
            "f.json",
            "--plan-out",
            "p.json",
            "--map-out",
            "seen.bt",
        ],
        d,
        1,
    );
    assert!(o.stderr.contains("time limit"), "{o:?}");
    let o = expect(&["verify", "--map", "seen.bt", "--plan", "p.json"], d, 0);
    assert!(o.stdout.contains("VALID"), "{o:?}");
    let flight = json(&d.join("f.json"));
    let start = &flight["samples"][0]["units"][0]["p"];
    for sample in flight["samples"].as_array().unwrap() {
        let p = &sample["units"][0]["p"];
        let d: f64 = (0..3)
            .map(|a| (p[a].as_f64().unwrap() - start[a].as_f64().unwrap()).powi(2))
            .sum::<f64>()
            .sqrt();
        assert!(
            d < 1.0,
            "the head went {d} m from its start, past what it saw"
        );
    }
}

#[test]
fn bad_sensor_settings_are_refused_naming_them() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("wide.json"), r#"{"fov_h_deg": 200}"#).unwrap();
    std::fs::write(d.join("typo.json"), r#"{"fov_h": 60}"#).unwrap();
    let base = ["explore", "--scenario", "window", "--out", "f.json"];
    let cases: [(&[&str], &str); 5] = [
        (&["--sensor", "wide.json"], "fov_h_deg"),
        (&["--sensor", "typo.json"], "fov_h"),
        (&["--sensor-rate", "0"], "rate_hz"),
        (&["--sensor-range", "0.1"], "max_range"),
        (&["--deadline", "-1"], "--deadline"),
    ];
    for (flags, named) in cases {
        let o = expect(&[&base[..], flags].concat(), d, 2);
        assert!(o.stderr.contains(named), "{flags:?}: {o:?}");
        assert!(!d.join("f.json").exists(), "{flags:?} wrote the flight");
    }
}
