//! The `arc` binary with `-` for files: `arc plan --out -` writes the plan, and only
//! the plan, to standard output (its report goes to standard error), and
//! `arc verify --plan -` reads it from standard input, so the two pipe together.

use std::io::Write;
use std::process::{Output, Stdio};
mod support;

/// Runs the `arc` binary with `args`, feeding `input` to its standard input.
fn arc(args: &[&str], input: &[u8]) -> Output {
    let mut command = support::arc(args, &std::env::temp_dir());
    let mut child = support::spawn(command.stdin(Stdio::piped()));
    child
        .stdin
        .take()
        .expect("piped")
        .write_all(input)
        .expect("arc reads its input");
    child.wait_with_output().expect("arc runs")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

#[test]
fn plan_to_stdout_pipes_into_verify_from_stdin() {
    let plan = arc(
        &["plan", "--scenario", "window", "--units", "4", "--out", "-"],
        b"",
    );
    let (out, err) = (text(&plan.stdout), text(&plan.stderr));
    assert!(plan.status.success(), "arc plan failed: {err}");
    // Standard output is the plan alone: JSON from the first byte to the last.
    let json: serde_json::Value = serde_json::from_str(&out)
        .unwrap_or_else(|e| panic!("stdout is not one JSON plan ({e}):\n{out}"));
    assert_eq!(json["format"], "arc-plan/1");
    assert_eq!(
        json["map"]["scenario"], "window",
        "the plan records its map"
    );
    assert!(
        out.contains("\"unit_radius\": 0.15,"),
        "f32 values without noise"
    );
    assert!(
        err.contains("solved on scenario window"),
        "report on stderr: {err}"
    );

    let verify = arc(
        &["verify", "--scenario", "window", "--plan", "-"],
        &plan.stdout,
    );
    let out = text(&verify.stdout);
    assert!(
        verify.status.success(),
        "arc verify failed: {out}{}",
        text(&verify.stderr)
    );
    assert!(out.contains("VALID"), "{out}");
    assert!(!out.contains("was made for"), "same map, no note: {out}");

    // Against another map the verdict is that map's, and a note says so.
    let other = arc(
        &["verify", "--scenario", "maze", "--plan", "-"],
        &plan.stdout,
    );
    let out = text(&other.stdout);
    assert!(
        out.contains(
            "note: the plan was made for scenario window; checked here against scenario maze"
        ),
        "{out}{}",
        text(&other.stderr)
    );
}

#[test]
fn a_bad_plan_on_stdin_is_named_and_refused() {
    let r = arc(
        &["verify", "--scenario", "window", "--plan", "-"],
        b"{not json",
    );
    assert_eq!(r.status.code(), Some(2));
    let err = text(&r.stderr);
    assert!(err.contains("standard input"), "{err}");
    assert_eq!(err.lines().count(), 1, "one line: {err}");
}
