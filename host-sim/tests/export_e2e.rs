//! `arc export` as a user runs it: the files it writes, and what it refuses (exit 2,
//! one line naming the file, flag or field, and no file left behind). The files'
//! contents are decoded field by field by independent readers in python/tests.

mod support;

use support::{expect, hover_plan};

#[test]
fn a_plan_exports_to_both_formats_and_a_flight_to_a_log() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("hover.json"), hover_plan(true)).unwrap();
    let base = ["export", "--scenario", "window", "--plan", "hover.json"];
    let o = expect(&[&base[..], &["--to", "h.mcap"]].concat(), d, 0);
    assert!(o.stdout.contains("/tf (1)"), "{}", o.stdout);
    assert!(std::fs::read(d.join("h.mcap"))
        .unwrap()
        .starts_with(b"\x89MCAP0\r\n"));
    let o = expect(&[&base[..], &["--to", "h.tlog", "--arm"]].concat(), d, 0);
    assert!(
        o.stdout.contains("10 commands") || o.stdout.contains("6 commands"),
        "{}",
        o.stdout
    );
    expect(
        &[
            "sim",
            "--scenario",
            "window",
            "--plan",
            "hover.json",
            "--settle-time",
            "1",
            "--out",
            "f.json",
        ],
        d,
        0,
    );
    let o = expect(
        &[
            "export",
            "--scenario",
            "window",
            "--flight",
            "f.json",
            "--to",
            "f.tlog",
        ],
        d,
        0,
    );
    // A flight records its commands: an attitude setpoint beside every position one.
    let count = |what: &str| -> usize {
        let words: Vec<&str> = o.stdout.split_whitespace().collect();
        let at = words.iter().position(|w| *w == what).expect(what);
        words[at - 1].parse().unwrap()
    };
    assert!(count("position") > 0);
    assert_eq!(count("position"), count("attitude"), "{}", o.stdout);
}

#[test]
fn bad_sources_and_outputs_are_refused_without_a_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("hover.json"), hover_plan(true)).unwrap();
    let cases: [(&[&str], &str); 4] = [
        (&["--flight", "hover.json", "--to", "x.tlog"], "hover.json"),
        (&["--plan", "hover.json", "--to", "x.bag"], "--to"),
        (
            &[
                "--plan",
                "hover.json",
                "--flight",
                "hover.json",
                "--to",
                "x.tlog",
            ],
            "--flight",
        ),
        (
            &["--trajectory", "missing.json", "--to", "x.mcap"],
            "missing.json",
        ),
    ];
    for (args, names) in cases {
        let all = [&["export", "--scenario", "window"][..], args].concat();
        let o = expect(&all, d, 2);
        let lines: Vec<&str> = o.stderr.lines().collect();
        assert_eq!(lines.len(), 1, "{all:?}: {}", o.stderr);
        assert!(lines[0].contains(names), "{all:?}: {}", o.stderr);
        for out in ["x.tlog", "x.bag", "x.mcap"] {
            assert!(!d.join(out).exists(), "{all:?} wrote {out}");
        }
    }
}
