//! Flying into the unknown with the real `arc` binary (docs/online.md): from an empty
//! map to the goal on a maze, the flown plan valid on the world and on the map the
//! sensors drew, the flight clear at every step; a map known before the flight; a
//! sealed goal; a sensor that sees nearly nothing; bad sensor settings.

mod support;

use std::path::Path;

use support::{arc, s, spawn, wait_at_most, words, Outcome};

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

/// Every output `arc explore` writes, into the test's directory: the flight, the
/// flown plan and the seen map.
const OUTPUTS: [&str; 6] = [
    "--out",
    "f.json",
    "--plan-out",
    "p.json",
    "--map-out",
    "seen.bt",
];

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Explores `world` (`--scenario NAME` or `--map FILE` and the query), then checks
/// that the goal was reached without contact, that the flown plan is valid on the
/// world and on the map the sensors drew (unknown space occupied: nothing was flown
/// through space never seen free), and returns the flight file.
fn explore_to_goal(world: &[&str], dir: &Path) -> serde_json::Value {
    expect(&[&["explore"][..], world, &OUTPUTS].concat(), dir, 0);
    let flight = json(&dir.join("f.json"));
    assert_eq!(flight["format"], "arc-sim/1");
    assert_eq!(flight["explore"]["format"], "arc-explore/1");
    assert_eq!(flight["explore"]["end"]["kind"], "reached");
    assert_eq!(flight["explore"]["start_free"], "hull");
    assert_eq!(flight["report"]["contact"], false);
    assert!(flight["report"]["min_clearance"].as_f64().unwrap() > 0.0);
    // The world is the first two arguments: --map FILE or --scenario NAME.
    let map_args = &world[..2];
    let o = expect(
        &[&["verify"][..], map_args, &["--plan", "p.json"]].concat(),
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

/// With the world known before the flight, the chain flies the window as on a finished
/// map, and the record counts what was known.
#[test]
fn a_known_map_is_flown_as_known() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    expect(&words("map export --scenario window --out window.bt"), d, 0);
    let query = words(
        "--map window.bt --known window.bt --units 4 \
         --start 2,4.5,1.5 --start-yaw-deg 90 --goal 6.6,3,1.5",
    );
    let flight = explore_to_goal(&query, d);
    let summary = &flight["explore"]["summary"];
    assert!(summary["known"].as_u64().unwrap() > 100_000, "{summary}");
}

/// From an empty map, the chain sees the wall between the rooms and the seams where it
/// meets the others, and that proves the goal out of reach; the run ends with the
/// reason.
#[test]
fn a_sealed_goal_ends_the_run_with_the_reason() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let world = support::sealed_rooms(d);
    let args = [
        "explore",
        "--map",
        s(&world),
        "--time-limit",
        "300",
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
    ];
    let o = expect(&args, d, 1);
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
    let run = words("explore --scenario window --units 4 --sensor-range 0.25 --time-limit 15");
    let o = expect(&[&run[..], &OUTPUTS].concat(), d, 1);
    assert!(o.stderr.contains("the chain is stuck"), "{o:?}");
    assert!(o.stderr.contains("nothing new"), "{o:?}");
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
    assert_eq!(flight["explore"]["end"]["kind"], "stuck");
    assert!(flight["explore"]["end"]["t"].as_f64().unwrap() < 15.0);
}

/// A run whose time budget ends first exits 1 saying so, with what it tried; its
/// flight is written.
#[test]
fn a_run_out_of_time_ends_with_what_it_tried() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let run = words("explore --scenario window --units 4 --time-limit 3 --out f.json");
    let o = expect(&run, d, 1);
    assert!(
        o.stderr.contains("the time limit of 3 simulated s ran out"),
        "{o:?}"
    );
    assert!(o.stderr.contains("replans"), "{o:?}");
    let flight = json(&d.join("f.json"));
    assert_eq!(flight["explore"]["end"]["kind"], "time_limit");
}

#[test]
fn bad_sensor_and_start_settings_are_refused_naming_them() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("wide.json"), r#"{"fov_h_deg": 200}"#).unwrap();
    std::fs::write(d.join("typo.json"), r#"{"fov_h": 60}"#).unwrap();
    std::fs::write(d.join("splay.json"), r#"{"splay_deg": -10}"#).unwrap();
    let base = ["explore", "--scenario", "window", "--out", "f.json"];
    let cases: [(&[&str], &str); 7] = [
        (&["--start-free", "all"], "--start-free"),
        (&["--sensor", "wide.json"], "fov_h_deg"),
        (&["--sensor", "typo.json"], "fov_h"),
        (&["--sensor", "splay.json"], "splay_deg = -10"),
        (&["--sensor-rate", "0"], "--sensor-rate"),
        (&["--sensor-range", "0.1"], "--sensor-range"),
        (&["--deadline", "-1"], "--deadline"),
    ];
    for (flags, named) in cases {
        let o = expect(&[&base[..], flags].concat(), d, 2);
        assert!(o.stderr.contains(named), "{flags:?}: {o:?}");
        assert!(!d.join("f.json").exists(), "{flags:?} wrote the flight");
    }
}

/// `--settings FILE`: its online section sets the route period and what the start
/// proves free; a flag given on the command line wins over the file; a bad file is
/// refused naming the file and the key, before anything is flown.
#[test]
fn a_settings_file_tunes_the_online_planner_and_a_flag_wins_over_it() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let file = r#"{"online": {"route_period_s": 0.5, "start_free": "bodies"}}"#;
    std::fs::write(d.join("s.json"), file).unwrap();
    let run = words("explore --scenario window --units 3 --time-limit 2.2 --settings s.json");
    let periods = |flight: &serde_json::Value| -> Vec<f64> {
        let replans = flight["explore"]["replans"].as_array().unwrap();
        replans
            .iter()
            .filter(|r| r["trigger"] == "period")
            .map(|r| r["t"].as_f64().unwrap())
            .collect()
    };
    expect(&[&run[..], &["--out", "f.json"]].concat(), d, 1);
    let flight = json(&d.join("f.json"));
    assert_eq!(flight["explore"]["start_free"], "bodies");
    assert_eq!(periods(&flight)[..4], [0.5, 1.0, 1.5, 2.0]);
    let hull = ["--start-free", "hull", "--out", "g.json"];
    expect(&[&run[..], &hull].concat(), d, 1);
    let flight = json(&d.join("g.json"));
    assert_eq!(flight["explore"]["start_free"], "hull");
    expect(
        &words("explore --scenario window --units 3 --time-limit 2.2 --out h.json"),
        d,
        1,
    );
    let flight = json(&d.join("h.json"));
    assert_eq!(periods(&flight)[..2], [1.0, 2.0]);

    std::fs::write(d.join("typo.json"), r#"{"online": {"deadline": 1}}"#).unwrap();
    std::fs::write(d.join("zero.json"), r#"{"online": {"route_period_s": 0}}"#).unwrap();
    std::fs::write(d.join("few.json"), r#"{"planner": {"vertices": 0}}"#).unwrap();
    for (file, named) in [
        ("typo.json", "typo.json: unknown key `online.deadline`"),
        ("zero.json", "zero.json: online.route_period_s = 0"),
        ("few.json", "few.json: planner.vertices"),
    ] {
        let args = [
            "explore",
            "--scenario",
            "window",
            "--out",
            "x.json",
            "--settings",
            file,
        ];
        let o = expect(&args, d, 2);
        assert!(o.stderr.contains(named), "{file}: {o:?}");
        assert!(!d.join("x.json").exists(), "{file} wrote the flight");
    }
}
