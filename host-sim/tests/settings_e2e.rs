//! End to end: `arc plan --settings FILE.json` on the real binary (docs/model.md,
//! "Settings files"): a file of defaults plans as no file does, an unknown key or a
//! value out of range is refused with exit 2 naming the file and the key (or the field
//! and the value), a tuning setting changes what it trades, and a flag given on the
//! command line wins over the file.

mod support;

use std::path::Path;

use aerial_chain::planning::SettingsFile;
use serde_json::Value;
use support::{expect, s};

/// The small plan of these tests: `window`, N = 3.
const BASE: [&str; 6] = ["plan", "--scenario", "window", "--units", "3", "--out"];

/// Runs `arc plan` on the base problem with `extra` arguments, writing `out` in `dir`,
/// and returns the plan file as JSON.
fn plan(dir: &Path, out: &str, extra: &[&str]) -> Value {
    let mut args: Vec<&str> = BASE.to_vec();
    args.push(out);
    args.extend_from_slice(extra);
    expect(&args, dir, 0);
    let text = std::fs::read_to_string(dir.join(out)).expect("plan written");
    serde_json::from_str(&text).expect("plan is JSON")
}

/// The plan without its timings (the only part that differs between runs).
fn untimed(v: &Value) -> Value {
    match v {
        Value::Object(m) => Value::Object(
            m.iter()
                .filter(|(k, _)| !(k.as_str() == "timing" || k.ends_with("_s")))
                .map(|(k, v)| (k.clone(), untimed(v)))
                .collect(),
        ),
        Value::Array(a) => Value::Array(a.iter().map(untimed).collect()),
        other => other.clone(),
    }
}

#[test]
fn a_file_of_the_defaults_plans_as_no_file_does() {
    let dir = tempfile::tempdir().unwrap();
    let defaults = serde_json::to_string_pretty(&SettingsFile::default()).unwrap();
    std::fs::write(dir.path().join("d.json"), defaults).unwrap();
    std::fs::write(dir.path().join("e.json"), "{}").unwrap();
    let none = plan(dir.path(), "none.json", &[]);
    let full = plan(dir.path(), "full.json", &["--settings", "d.json"]);
    let empty = plan(dir.path(), "empty.json", &["--settings", "e.json"]);
    assert_eq!(untimed(&none), untimed(&full));
    assert_eq!(untimed(&none), untimed(&empty));
}

#[test]
fn an_unknown_key_is_refused_naming_the_file_and_the_key() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("typo.json");
    std::fs::write(&file, r#"{"refine": {"widen": {"budgte": 10}}}"#).unwrap();
    let mut args: Vec<&str> = BASE.to_vec();
    args.extend(["p.json", "--settings", s(&file)]);
    let o = expect(&args, dir.path(), 2);
    assert!(o.stderr.contains(s(&file)), "{}", o.stderr);
    assert!(o.stderr.contains("refine.widen.budgte"), "{}", o.stderr);
    assert_eq!(o.stderr.trim().lines().count(), 1, "{}", o.stderr);
    assert!(!dir.path().join("p.json").exists(), "no plan for bad input");
    // A section that is not one is refused alike.
    std::fs::write(&file, r#"{"planer": {}}"#).unwrap();
    let o = expect(&args, dir.path(), 2);
    assert!(o.stderr.contains("`planer`"), "{}", o.stderr);
}

#[test]
fn a_value_out_of_range_is_refused_naming_the_field_and_the_value() {
    let dir = tempfile::tempdir().unwrap();
    for (text, field, value) in [
        (
            r#"{"refine": {"widen": {"centred": 1.5}}}"#,
            "refine.widen.centred",
            "1.5",
        ),
        (r#"{"planner": {"vertices": 0}}"#, "planner.vertices", "0"),
        (r#"{"trajectory": {"dt": 0.5}}"#, "trajectory.dt", "0.5"),
        (r#"{"refine": {"check_budget": "many"}}"#, "many", "string"),
    ] {
        std::fs::write(dir.path().join("bad.json"), text).unwrap();
        let o = expect(
            &[&BASE[..], &["p.json", "--settings", "bad.json"]].concat(),
            dir.path(),
            2,
        );
        assert!(o.stderr.contains("bad.json: "), "{text}: {}", o.stderr);
        assert!(
            o.stderr.contains(field) && o.stderr.contains(value),
            "{text}: {}",
            o.stderr
        );
    }
}

#[test]
fn a_tuning_setting_changes_what_it_trades() {
    let dir = tempfile::tempdir().unwrap();
    let checks = |v: &Value| v["stats"]["refinement"]["checks"].as_u64().expect("checks");
    let default = plan(dir.path(), "d.json", &[]);
    std::fs::write(
        dir.path().join("s.json"),
        r#"{"refine": {"check_budget": 3}}"#,
    )
    .unwrap();
    let tight = plan(dir.path(), "t.json", &["--settings", "s.json"]);
    // Refinement stops at its budget: each of its two passes (at the search's margin
    // and at the widened plan's) spends at most the budget and the check crossing it.
    assert!(checks(&default) > 20, "{}", checks(&default));
    assert!(checks(&tight) <= 2 * (3 + 1), "{}", checks(&tight));
}

#[test]
fn a_flag_given_on_the_command_line_wins_over_the_file() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("s.json"), r#"{"planner": {"vertices": 0}}"#).unwrap();
    // The file alone is refused (its value is out of range) ...
    let o = expect(
        &[&BASE[..], &["p.json", "--settings", "s.json"]].concat(),
        dir.path(),
        2,
    );
    assert!(
        o.stderr.contains("s.json: planner.vertices 0"),
        "{}",
        o.stderr
    );
    // ... and the flag replaces it.
    plan(
        dir.path(),
        "p.json",
        &["--settings", "s.json", "--vertices", "600"],
    );
    // A flag left at its default does not override the file: the file's n_psi stands
    // beside a flag given.
    std::fs::write(dir.path().join("seed.json"), r#"{"planner": {"n_psi": 0}}"#).unwrap();
    let o = expect(
        &[
            &BASE[..],
            &["p.json", "--settings", "seed.json", "--seed", "1"],
        ]
        .concat(),
        dir.path(),
        2,
    );
    assert!(
        o.stderr.contains("seed.json: planner.n_psi 0"),
        "{}",
        o.stderr
    );
}
