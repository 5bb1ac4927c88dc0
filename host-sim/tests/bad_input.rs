//! The bad-input battery: every numeric flag of every subcommand at 0, -1, NaN, inf,
//! 1e20 and its type's largest value, on the real `arc` binary under hang and memory
//! guards (tests/support). A value the flag accepts ends the run normally (0, or 1
//! when the job's answer is no); any other ends it with exit 2 and one line naming
//! the flag and the value. Never a panic, an abort or a hang.

mod support;

use std::path::Path;

use support::{hover_plan, run, Outcome};

/// The values every numeric flag is tried with.
const VALUES: [&str; 5] = ["0", "-1", "nan", "inf", "1e20"];

/// Largest value of each flag type, as a user would type it.
const F64_MAX: &str = "1.7976931348623157e308";
const F32_MAX: &str = "3.4028235e38";
const USIZE_MAX: &str = "18446744073709551615";
const U8_MAX: &str = "255";

/// One flag and what it does with `VALUES` then its type's maximum: `o` accepted
/// (the run ends normally), `x` refused with exit 2, `-` accepted but too costly to
/// run here (a whole study).
struct Flag {
    name: &'static str,
    max: &'static str,
    verdicts: &'static str,
}

const fn flag(name: &'static str, max: &'static str, verdicts: &'static str) -> Flag {
    Flag {
        name,
        max,
        verdicts,
    }
}

/// The chain flags every chain-making subcommand shares (`--units` is set apart).
const CHAIN: [Flag; 5] = [
    flag("--link-length", F32_MAX, "xxxxxx"),
    flag("--unit-radius", F32_MAX, "xxxxxx"),
    flag("--link-radius", F32_MAX, "xxxxxx"),
    flag("--theta-max-deg", F32_MAX, "xxxxxx"),
    flag("--beta-max-deg", F32_MAX, "xxxxxx"),
];

/// A subcommand: its small base command (arguments apart by spaces) and its numeric
/// flags.
struct Case {
    base: &'static str,
    flags: Vec<Flag>,
}

fn cases() -> Vec<Case> {
    let mut plan = vec![
        flag("--units", U8_MAX, "xxxxxx"),
        flag("--goal-tol", F64_MAX, "oxxxxx"),
        flag("--seed", "18446744073709551615", "oxxxxo"),
        flag("--vertices", USIZE_MAX, "xxxxxx"),
        flag("--r-t", F64_MAX, "xxxxxx"),
        flag("--max-neighbours", USIZE_MAX, "xxxxxx"),
        flag("--n-psi", USIZE_MAX, "xxxxxx"),
        flag("--d-c", F32_MAX, "xxxxoo"),
        flag("--srs", USIZE_MAX, "oxxxxx"),
        flag("--srs-seed", "18446744073709551615", "oxxxxo"),
        flag("--clearance", F64_MAX, "oxxxxx"),
        flag("--follow-step", F64_MAX, "oxxxxx"),
        flag("--max-replans", USIZE_MAX, "oxxxxx"),
        flag("--clearance-weight", F64_MAX, "oxxxoo"),
        flag("--max-growth", USIZE_MAX, "oxxxxx"),
        flag("--time-limit", F64_MAX, "xxxxxx"),
        flag("--start-yaw-deg", F64_MAX, "ooxxox"),
    ];
    plan.extend(CHAIN);
    let mut prm = vec![
        flag("--units", U8_MAX, "xxxxxx"),
        flag("--goal-tol", F64_MAX, "oxxxxx"),
        flag("--vertices", USIZE_MAX, "xxxxxx"),
        flag("--k", USIZE_MAX, "xxxxxx"),
        flag("--goal-samples", USIZE_MAX, "xxxxxx"),
        flag("--seed", "18446744073709551615", "oxxxxo"),
        flag("--clearance", F64_MAX, "oxxxxx"),
        flag("--time-limit", F64_MAX, "xxxxxx"),
    ];
    prm.extend(CHAIN);
    let mut build = vec![
        flag("--units", U8_MAX, "xxxxxx"),
        flag("--srs", USIZE_MAX, "oxxxxx"),
        flag("--seed", "18446744073709551615", "oxxxxo"),
        flag("--r-s", F32_MAX, "xxxxoo"),
    ];
    build.extend(CHAIN);
    let mut shapes = vec![flag("--units", U8_MAX, "xxxxxx")];
    shapes.extend(CHAIN);
    let study = || {
        vec![
            flag("--seeds", "18446744073709551615", "xxxxxx"),
            flag("--time-limit", F64_MAX, "-xxxxx"),
            flag("--threads", USIZE_MAX, "xxxxxx"),
            flag("--vertices", USIZE_MAX, "xxxxxx"),
            flag("--srs", USIZE_MAX, "-xxxxx"),
        ]
    };
    let mut paper = study();
    paper.push(flag("--prm-vertices", USIZE_MAX, "xxxxxx"));
    paper.push(flag("--prm-units", U8_MAX, "xxxxxx"));
    paper.push(flag("--wide-window", F64_MAX, "-xxxxx"));
    let mut scale = study();
    scale.push(flag("--units", U8_MAX, "xxxxxx"));
    scale.push(flag("--corridor-density", F64_MAX, "-xxxxx"));
    vec![
        Case {
            base: "plan --scenario window --units 3 --vertices 600 --srs 50 --max-growth 0 --time-limit 20 --out p.json",
            flags: plan,
        },
        Case {
            base: "verify --scenario window --plan hover.json --goal 2,4.5,1.5",
            flags: vec![flag("--goal-tol", F64_MAX, "oxxxxx")],
        },
        Case {
            base: "sim --scenario window --plan hover.json --settle-time 2",
            flags: vec![
                flag("--rate", F64_MAX, "xxxxxx"),
                flag("--speed", F64_MAX, "xxxxoo"),
                flag("--accel", F64_MAX, "xxxxoo"),
                flag("--angular-rate-deg", F64_MAX, "xxxxoo"),
                flag("--goal-tol", F64_MAX, "xxxxoo"),
                flag("--settle-time", F64_MAX, "xxxxxx"),
                flag("--record-every", USIZE_MAX, "xxxxxo"),
            ],
        },
        Case {
            base: "view --scenario window --plan hover.json --out v.html",
            flags: vec![
                flag("--goal-tol", F64_MAX, "oxxxxx"),
                flag("--near", F64_MAX, "xxxxxx"),
                flag("--max-boxes", USIZE_MAX, "xxxxxx"),
            ],
        },
        Case {
            base: "bench prm --scenario window --units 3 --vertices 200 --start 2,4.5,1.5 --goal 2.6,4.5,1.5 --time-limit 20 --out q.json",
            flags: prm,
        },
        Case {
            base: "tables build --units 3 --srs 20 --out t.arct",
            flags: build,
        },
        Case {
            base: "shapes --units 3 --out s.svg",
            flags: shapes,
        },
        Case {
            base: "map picture --scenario window --out m.svg",
            flags: vec![
                flag("--band-min", F64_MAX, "ooxxxx"),
                flag("--band-max", F64_MAX, "xxxxoo"),
                flag("--slices", F64_MAX, "ooxxoo"),
            ],
        },
        Case {
            base: "bench paper --quick",
            flags: paper,
        },
        Case {
            base: "bench scale --quick",
            flags: scale,
        },
    ]
}

/// The base command with `flag` set to `value` (replacing the base's own value).
fn with(base: &'static str, flag: &'static str, value: &'static str) -> Vec<&'static str> {
    let mut args: Vec<&str> = base.split_whitespace().collect();
    match args.iter().position(|a| *a == flag) {
        Some(i) => args[i + 1] = value,
        None => args.extend([flag, value]),
    }
    args
}

/// What is wrong with a refused run, if anything.
fn refusal_problem(o: &Outcome, flag: &str, value: &str) -> Option<String> {
    if o.code != Some(2) {
        return Some(format!("exit {:?}, expected 2", o.code));
    }
    let lines: Vec<&str> = o.stderr.lines().filter(|l| !l.trim().is_empty()).collect();
    if lines.len() != 1 {
        return Some(format!("{} lines of error, expected one", lines.len()));
    }
    let line = lines[0].to_ascii_lowercase();
    // The value as typed, or as Rust prints the number it parsed to.
    let shown = value
        .parse::<f64>()
        .map(|v| v.to_string().to_ascii_lowercase())
        .unwrap_or_default();
    if !line.contains(flag) {
        return Some("the message does not name the flag".into());
    }
    if !(line.contains(value) || (!shown.is_empty() && line.contains(&shown))) {
        return Some("the message does not show the value".into());
    }
    if line.contains("some(") {
        return Some("the message shows Rust Debug text".into());
    }
    None
}

#[test]
fn every_numeric_flag_at_every_extreme_is_accepted_or_refused_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("hover.json"), hover_plan(true)).unwrap();
    let mut failures = Vec::new();
    let mut runs = 0;
    for case in cases() {
        for f in &case.flags {
            let values = VALUES.iter().copied().chain([f.max]);
            for (value, verdict) in values.zip(f.verdicts.chars()) {
                if verdict == '-' {
                    continue;
                }
                let args = with(case.base, f.name, value);
                let o = run(&args, dir.path());
                runs += 1;
                let problem = if o.crashed() {
                    Some("crashed".to_string())
                } else if verdict == 'o' {
                    (!matches!(o.code, Some(0 | 1))).then(|| format!("exit {:?}", o.code))
                } else {
                    refusal_problem(&o, f.name, value)
                };
                if let Some(p) = problem {
                    failures.push(format!("arc {}: {p}: {}", args.join(" "), o.stderr.trim()));
                }
            }
        }
    }
    assert!(runs > 300, "only {runs} runs");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn a_closed_stdout_ends_arc_quietly() {
    use std::os::fd::{FromRawFd, OwnedFd};
    use std::process::Stdio;
    let dir = tempfile::tempdir().unwrap();
    let o = run(
        &[
            "tables", "build", "--units", "3", "--srs", "20", "--out", "t.arct",
        ],
        dir.path(),
    );
    assert_eq!(o.code, Some(0), "{o:?}");
    for args in [
        &["tables", "inspect", "t.arct"][..],
        &["map", "info", "/nonexistent.bt"][..],
        &["--help"][..],
    ] {
        // A pipe whose reading end is closed before arc writes: as `arc ... | head -0`.
        let mut fds = [0; 2];
        // SAFETY: pipe fills two fresh descriptors, owned here from then on.
        let (read, write) = unsafe {
            assert_eq!(libc::pipe(fds.as_mut_ptr()), 0);
            (OwnedFd::from_raw_fd(fds[0]), OwnedFd::from_raw_fd(fds[1]))
        };
        drop(read);
        let child = support::arc(args, dir.path())
            .stdout(Stdio::from(write))
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let o = support::wait(child, args);
        assert!(!o.stderr.contains("panicked"), "arc {args:?}: {o:?}");
        assert_ne!(o.code, Some(101), "arc {args:?}: {o:?}");
        // Ended by SIGPIPE, as `cat` is, or done before writing anything.
        assert!(
            o.signal == Some(libc::SIGPIPE) || matches!(o.code, Some(0 | 2)),
            "arc {args:?}: {o:?}"
        );
    }
}

/// Sizes a user can type that would take more memory than the budgets allow are
/// refused before anything is allocated.
#[test]
fn sizes_beyond_the_budgets_are_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // A 0.6 m translation: the flight's length follows from the speed.
    let plan =
        hover_plan(true).replacen("{\"zeta\": [2.0, 4.5, 1.5", "{\"zeta\": [2.6, 4.5, 1.5", 2);
    let plan = plan.replacen("{\"zeta\": [2.6", "{\"zeta\": [2.0", 1);
    std::fs::write(d.join("move.json"), plan).unwrap();
    let sim = ["sim", "--scenario", "window", "--plan", "move.json"];
    for (extra, names) in [
        (&["--speed", "1e-9"][..], "--speed"),
        (&["--settle-time", "1e12"][..], "--settle-time"),
    ] {
        let args: Vec<&str> = sim.iter().chain(extra).copied().collect();
        let o = support::expect(&args, d, 2);
        assert!(
            o.stderr.contains(names) && o.stderr.contains("budget"),
            "{o:?}"
        );
    }
    let o = support::expect(
        &[
            "plan",
            "--scenario",
            "window",
            "--vertices",
            "100000000",
            "--out",
            "p.json",
        ],
        d,
        2,
    );
    assert!(o.stderr.contains("--vertices"), "{o:?}");
    let o = support::expect(
        &[
            "bench",
            "prm",
            "--scenario",
            "window",
            "--vertices",
            "1000000000",
            "--out",
            "q.json",
        ],
        d,
        2,
    );
    assert!(o.stderr.contains("--vertices"), "{o:?}");
    assert!(!Path::new(&d.join("p.json")).exists());
}
