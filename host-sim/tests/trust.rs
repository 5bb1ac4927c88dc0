//! Regressions on trust (the checker and bad input), on the real `arc` binary: the checker's
//! assumptions come from its command line, flags are checked before any work, and
//! one exit-code table holds for every subcommand.

mod support;

use std::path::{Path, PathBuf};

use support::{expect, hover_plan};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Plans made with `--unknown-free` on the real scan, through unknown space.
fn unknown_free_fixtures() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/unknown_free");
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .collect();
    v.sort();
    v
}

#[test]
fn verify_takes_unknown_space_from_the_command_line_not_the_plan() {
    let map = repo().join("maps/geb079.bt");
    let fixtures = unknown_free_fixtures();
    assert!(fixtures.len() >= 3, "{fixtures:?}");
    for plan in fixtures {
        let base = [
            "verify",
            "--map",
            map.to_str().unwrap(),
            "--plan",
            plan.to_str().unwrap(),
        ];
        let o = expect(&base, &repo(), 1);
        assert!(o.stderr.contains("INVALID"), "{plan:?}: {o:?}");
        let with: Vec<&str> = base.iter().copied().chain(["--unknown-free"]).collect();
        let o = expect(&with, &repo(), 0);
        assert!(o.stdout.contains("VALID"), "{plan:?}: {o:?}");
    }
}

#[test]
fn a_plan_made_under_looser_assumptions_fails_and_says_why() {
    // Valid in every respect, but it records unknown space as free.
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("loose.json"), hover_plan(false)).unwrap();
    std::fs::write(d.join("strict.json"), hover_plan(true)).unwrap();
    let verify = |plan: &str, extra: &[&'static str], code| {
        let mut args = vec![
            "verify",
            "--scenario",
            "window",
            "--goal",
            "2,4.5,1.5",
            "--plan",
        ];
        args.push(plan);
        args.extend(extra);
        expect(&args, d, code)
    };
    verify("strict.json", &[], 0);
    let o = verify("loose.json", &[], 1);
    assert!(
        o.stderr.contains("INVALID") && o.stderr.contains("--unknown-free"),
        "{o:?}"
    );
    verify("loose.json", &["--unknown-free"], 0);
    let sim = |plan: &str, extra: &[&'static str], code| {
        let mut args = vec!["sim", "--scenario", "window", "--plan"];
        args.push(plan);
        args.extend(extra);
        expect(&args, d, code)
    };
    sim("strict.json", &[], 0);
    let o = sim("loose.json", &[], 1);
    assert!(o.stderr.contains("--unknown-free"), "{o:?}");
    sim("loose.json", &["--unknown-free"], 0);
}

#[test]
fn verify_checks_its_goal_tolerance() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("hover.json"), hover_plan(true)).unwrap();
    for tol in ["nan", "-1", "-0.5", "inf"] {
        let o = expect(
            &[
                "verify",
                "--scenario",
                "window",
                "--plan",
                "hover.json",
                "--goal-tol",
                tol,
            ],
            d,
            2,
        );
        assert!(o.stderr.contains("--goal-tol"), "{o:?}");
    }
}

#[test]
fn huge_time_limits_are_refused_not_panicked_on() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for args in [
        &["plan", "--scenario", "window", "--out", "p.json"][..],
        &["bench", "prm", "--scenario", "window", "--out", "q.json"][..],
        &["bench", "scale", "--quick", "--out-dir", "b"][..],
    ] {
        let args: Vec<&str> = args
            .iter()
            .copied()
            .chain(["--time-limit", "1e20"])
            .collect();
        let o = expect(&args, d, 2);
        assert!(o.stderr.contains("--time-limit"), "{o:?}");
    }
}

#[test]
fn sim_refuses_a_plan_with_huge_values_without_crashing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let huge_link = hover_plan(true).replace("\"link_length\": 0.5", "\"link_length\": 1e30");
    let huge_zeta = hover_plan(true).replacen("[2.0, 4.5", "[1e300, 4.5", 2);
    for (name, text) in [("link.json", huge_link), ("zeta.json", huge_zeta)] {
        std::fs::write(d.join(name), text).unwrap();
        let o = support::run(&["sim", "--scenario", "window", "--plan", name], d);
        assert!(!o.crashed(), "{name}: {o:?}");
        assert!(matches!(o.code, Some(1 | 2)), "{name}: {o:?}");
    }
}

#[test]
fn unsupported_pictures_are_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("hover.json"), hover_plan(true)).unwrap();
    let cases: [&[&str]; 4] = [
        &[
            "plan",
            "--scenario",
            "window",
            "--out",
            "p.json",
            "--picture",
            "x.jpg",
        ],
        &[
            "sim",
            "--scenario",
            "window",
            "--plan",
            "hover.json",
            "--picture",
            "x.bmp",
        ],
        &["shapes", "--units", "3", "--out", "x.jpg"],
        &["map", "picture", "--scenario", "window", "--out", "x"],
    ];
    for args in cases {
        let o = expect(args, d, 2);
        assert!(o.stderr.contains(".svg or .png"), "{args:?}: {o:?}");
    }
    // Nothing was planned or written.
    assert!(!d.join("p.json").exists());
    assert!(!d.join("x.bmp").exists());
}

#[test]
fn an_invalid_start_is_bad_input_for_every_planner() {
    // Inside the window scenario's dividing wall.
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let wall = ["--start", "4.1,1,1.5", "--units", "3", "--vertices", "100"];
    for cmd in [&["plan"][..], &["bench", "prm"][..]] {
        let args: Vec<&str> = cmd
            .iter()
            .copied()
            .chain(["--scenario", "window", "--out", "p.json"])
            .chain(wall)
            .collect();
        let o = expect(&args, d, 2);
        assert!(o.stderr.contains("start is invalid"), "{args:?}: {o:?}");
    }
}
