//! `arc bench` smoke runs: the quick paper and scaling studies write their files, the
//! full-state PRM writes plans that pass exact verification, results do not depend on
//! the number of threads, and bad flags are input errors (exit code 2).

use std::path::PathBuf;

use crate::study::{self as bench, ArcMode, Method, RunKey};
use crate::CliError;
use aerial_chain::collision::verify_plan;
use aerial_chain::plan_file::Plan;
use aerial_chain::problem::scenarios;

/// Runs the command line in-process with `args` (the program name is added).
fn arc(args: &[&str]) -> Result<(), CliError> {
    let mut v = vec!["arc"];
    v.extend_from_slice(args);
    crate::run(v)
}

/// A fresh scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("arc-bench-quick-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn quick_paper_writes_tables_and_csv() {
    let d = scratch("paper");
    let out = d.to_str().unwrap();
    arc(&[
        "bench",
        "paper",
        "--quick",
        "--out-dir",
        out,
        "--threads",
        "2",
    ])
    .unwrap();
    let md = std::fs::read_to_string(d.join("paper.md")).unwrap();
    for want in [
        "Table 1",
        "Table 2",
        "Table 3",
        "full-state PRM",
        "window-wide:1.6",
        "Profile",
        "Both+follow",
    ] {
        assert!(md.contains(want), "paper.md lacks {want}");
    }
    let runs = std::fs::read_to_string(d.join("paper_runs.csv")).unwrap();
    let header = runs.lines().next().unwrap();
    assert!(header.starts_with("study,scenario,units,method"));
    let cols = header.split(',').count();
    // Quick: 16 ablation groups (4 chains x LSC, SRS, Both, Both+follow) x 2 seeds;
    // Table 3: window (its ARCplanner runs are Table 1's) with 2 PRM budgets x 2 seeds,
    // the wide window with 2 ARCplanner variants + 2 PRM budgets.
    assert_eq!(runs.lines().count(), 1 + 16 * 2 + 2 * 2 + 4 * 2);
    for line in runs.lines().skip(1) {
        if !line.contains('"') {
            assert_eq!(line.split(',').count(), cols, "{line}");
        }
    }
    // Every plan found passes exact verification, and the ARCplanner solves something.
    let names: Vec<&str> = header.split(',').collect();
    let col = |n: &str| names.iter().position(|c| *c == n).unwrap();
    let (ok, verified) = (col("success"), col("verified"));
    let mut solved = 0;
    for line in runs.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        if f[ok] == "true" {
            solved += 1;
            assert_eq!(f[verified], "true", "{line}");
        }
    }
    assert!(solved > 0);
    let summary = std::fs::read_to_string(d.join("paper_summary.csv")).unwrap();
    assert_eq!(summary.lines().count(), 1 + 16 + 2 + 4);
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn quick_scale_writes_the_plot() {
    let d = scratch("scale");
    let out = d.to_str().unwrap();
    arc(&["bench", "scale", "--quick", "--out-dir", out]).unwrap();
    let svg = std::fs::read_to_string(d.join("scale.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("units N"));
    let png = std::fs::read(d.join("scale.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    let md = std::fs::read_to_string(d.join("scale.md")).unwrap();
    assert!(md.contains("Against the number of units") && md.contains("corridor"));
    assert!(d.join("scale_runs.csv").exists() && d.join("scale_summary.csv").exists());
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    let mut specs = Vec::new();
    for seed in 1..=3 {
        for (method, vertices, srs) in [
            (Method::Arc(ArcMode::Both), 300, 100),
            (Method::Arc(ArcMode::Lsc), 300, 0),
            (Method::FullPrm, 200, 0),
        ] {
            let key = RunKey::new("determinism", "window", 4, method, (vertices, srs));
            specs.push(key.run(seed, None));
        }
    }
    let envs = bench::Envs::for_specs(&specs).unwrap();
    let one = bench::run_all(&envs, &specs, Some(1), "t1", false).unwrap();
    let two = bench::run_all(&envs, &specs, Some(2), "t2", false).unwrap();
    let three = bench::run_all(&envs, &specs, Some(3), "t3", false).unwrap();
    assert_eq!(one.len(), specs.len());
    for ((a, b), c) in one.iter().zip(&two).zip(&three) {
        assert_eq!(a.fingerprint(), b.fingerprint());
        assert_eq!(a.fingerprint(), c.fingerprint());
    }
    assert!(one.iter().any(|r| r.success));
    assert!(one.iter().all(|r| r.verified != Some(false)));
}

#[test]
fn full_state_prm_plans_pass_exact_verification() {
    let d = scratch("prm");
    let plan = d.join("prm.json");
    // An easy query inside the first room of `window`, and N = 3.
    arc(&[
        "bench",
        "prm",
        "--scenario",
        "window",
        "-n",
        "3",
        "--start",
        "2.0,4.0,1.5",
        "--goal",
        "2.5,2.0,1.5",
        "--vertices",
        "600",
        "--seed",
        "4",
        "--out",
        plan.to_str().unwrap(),
    ])
    .unwrap();
    let p = Plan::read(&plan).unwrap();
    assert_eq!(p.chain.units, 3);
    assert!(p.waypoints.len() >= 2);
    let grid = scenarios::build("window").unwrap().grid;
    assert!(verify_plan(&grid, &p).ok);
    // And the independent checker agrees on the command line.
    arc(&[
        "verify",
        "--scenario",
        "window",
        "--plan",
        plan.to_str().unwrap(),
        "--start",
        "2.0,4.0,1.5",
        "--goal",
        "2.5,2.0,1.5",
    ])
    .unwrap();
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn bad_flags_are_input_errors() {
    for args in [
        vec!["bench", "paper", "--quick", "--seeds", "0"],
        vec!["bench", "paper", "--quick", "--tables", "4"],
        vec!["bench", "paper", "--quick", "--time-limit", "-1"],
        vec!["bench", "paper", "--quick", "--prm-vertices", "0"],
        vec!["bench", "paper", "--quick", "--wide-window", "9"],
        vec!["bench", "scale", "--quick", "--units", "17"],
        vec!["bench", "scale", "--quick", "--corridor-density", "-3"],
        vec![
            "bench",
            "prm",
            "--scenario",
            "nowhere",
            "--out",
            "/nonexistent/x.json",
        ],
        vec![
            "bench",
            "prm",
            "--scenario",
            "window",
            "--vertices",
            "0",
            "--out",
            "x.json",
        ],
        vec![
            "bench",
            "prm",
            "--scenario",
            "window",
            "--goal",
            "100,0,0",
            "--out",
            "x.json",
        ],
    ] {
        let e = arc(&args).expect_err(&format!("{args:?} must fail"));
        assert_eq!(e.code, 2, "{args:?}: {}", e.message);
    }
}
