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

/// The flag table: subcommands, their numeric flags and the verdicts (see its header).
const TABLE: &str = include_str!("bad_input_flags.txt");

/// Largest value of a flag type, as a user would type it.
fn type_max(ty: &str) -> &'static str {
    match ty {
        "f64" => "1.7976931348623157e308",
        "f32" => "3.4028235e38",
        "usize" | "u64" => "18446744073709551615",
        "u8" => "255",
        _ => panic!("bad_input_flags.txt: unknown flag type {ty:?}"),
    }
}

/// One flag and what it does with `VALUES` then its type's maximum: `o` accepted
/// (the run ends normally), `x` refused with exit 2, `-` accepted but too costly to
/// run here (a whole study).
#[derive(Clone)]
struct Flag {
    name: &'static str,
    max: &'static str,
    verdicts: &'static str,
}

/// A subcommand: its small base command (arguments apart by spaces) and its numeric
/// flags.
struct Case {
    base: &'static str,
    flags: Vec<Flag>,
}

/// The table's commands, groups included where they are named.
fn cases() -> Vec<Case> {
    let mut groups: Vec<(&str, Vec<Flag>)> = Vec::new();
    let mut cases: Vec<Case> = Vec::new();
    // Where the lines below a header go: the last group or the last command.
    let mut into_group = false;
    for line in TABLE.lines().map(str::trim) {
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        if let Some(name) = line.strip_prefix("group ") {
            groups.push((name, Vec::new()));
            into_group = true;
        } else if let Some(base) = line.strip_prefix("command ") {
            cases.push(Case {
                base,
                flags: Vec::new(),
            });
            into_group = false;
        } else {
            let flags = match line.strip_prefix('+') {
                Some(name) => {
                    let group = groups.iter().find(|(g, _)| *g == name);
                    group
                        .unwrap_or_else(|| panic!("no group {name:?}"))
                        .1
                        .clone()
                }
                None => vec![parse_flag(line)],
            };
            let target = match into_group {
                true => &mut groups.last_mut().expect("a group").1,
                false => &mut cases.last_mut().expect("a command").flags,
            };
            target.extend(flags);
        }
    }
    cases
}

/// One flag line: name, type, verdicts.
fn parse_flag(line: &'static str) -> Flag {
    let fields: Vec<&str> = line.split_whitespace().collect();
    let [name, ty, verdicts] = fields[..] else {
        panic!("bad_input_flags.txt: {line:?} is not `--flag type verdicts`");
    };
    assert_eq!(
        verdicts.len(),
        VALUES.len() + 1,
        "{line:?}: one verdict per value"
    );
    Flag {
        name,
        max: type_max(ty),
        verdicts,
    }
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

#[test]
fn bench_online_refuses_bad_sensor_settings_before_any_run() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("splay.json"), r#"{"splay_deg": 200}"#).unwrap();
    let args = [
        "bench",
        "online",
        "--scenarios",
        "window",
        "--units",
        "4",
        "--robust",
        "0",
        "--out-dir",
        "out",
    ];
    for (file, named) in [
        ("splay.json", "splay_deg = 200"),
        ("none.json", "none.json"),
    ] {
        let o = support::expect(&[&args[..], &["--sensor", file]].concat(), d, 2);
        assert!(o.stderr.contains(named), "{o:?}");
        assert!(!d.join("out").exists(), "{file}: wrote the study");
    }
}
