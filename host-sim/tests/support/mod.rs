//! Running the real `arc` binary as a user would, under hang and memory guards.
//!
//! The guards are not timings: a child gets `GUARD_SECONDS` of wall time and
//! `GUARD_BYTES` of address space, far beyond what any run here needs, so that a
//! hang or a runaway allocation is seen as a failure instead of stalling CI.

#![allow(dead_code)] // each test file uses a part

use std::io::Read;
use std::os::unix::process::{CommandExt, ExitStatusExt};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// Wall time a child may take before it counts as hung.
pub const GUARD_SECONDS: u64 = 60;
/// Address space a child may map before its allocations fail (2 GiB).
pub const GUARD_BYTES: u64 = 2 << 30;

/// How a run of `arc` ended.
#[derive(Debug)]
pub struct Outcome {
    /// The exit code, `None` when a signal ended it.
    pub code: Option<i32>,
    /// The signal that ended it, if one did.
    pub signal: Option<i32>,
    /// Standard output.
    pub stdout: String,
    /// Standard error.
    pub stderr: String,
}

impl Outcome {
    /// Whether the run panicked or aborted (what a user must never see).
    pub fn crashed(&self) -> bool {
        self.code == Some(101)
            || self.signal.is_some()
            || self.stderr.contains("panicked")
            || self.stderr.contains("memory allocation")
    }
}

/// The `arc` command, with the guards set on the child.
pub fn arc(args: &[&str], dir: &Path) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_arc"));
    c.args(args).current_dir(dir).stdin(Stdio::null());
    // SAFETY: setrlimit is async-signal-safe, as pre_exec requires.
    unsafe {
        c.pre_exec(|| {
            let lim = libc::rlimit {
                rlim_cur: GUARD_BYTES,
                rlim_max: GUARD_BYTES,
            };
            if libc::setrlimit(libc::RLIMIT_AS, &lim) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
    c
}

/// Starts the command `c` (an [`arc`] command) with its standard output and error piped.
pub fn spawn(c: &mut Command) -> Child {
    c.stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn arc")
}

/// The words of a command line written as one string, for `arc`'s arguments.
pub fn words(line: &str) -> Vec<&str> {
    line.split_whitespace().collect()
}

/// Runs `arc args` in `dir` and waits, killing it after [`GUARD_SECONDS`].
pub fn run(args: &[&str], dir: &Path) -> Outcome {
    wait(spawn(&mut arc(args, dir)), args)
}

/// Waits for `child` under the hang guard and collects its output.
pub fn wait(child: Child, args: &[&str]) -> Outcome {
    wait_at_most(child, args, GUARD_SECONDS)
}

/// Waits for `child` at most `seconds` and collects its output.
pub fn wait_at_most(mut child: Child, args: &[&str], seconds: u64) -> Outcome {
    // Drain the pipes on threads, so a chatty child cannot block on a full pipe.
    let drain = |r: Option<Box<dyn Read + Send>>| {
        std::thread::spawn(move || {
            let mut s = String::new();
            if let Some(mut r) = r {
                let _ = r.read_to_string(&mut s);
            }
            s
        })
    };
    let out = drain(
        child
            .stdout
            .take()
            .map(|r| Box::new(r) as Box<dyn Read + Send>),
    );
    let err = drain(
        child
            .stderr
            .take()
            .map(|r| Box::new(r) as Box<dyn Read + Send>),
    );
    let began = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().expect("wait for arc") {
            break s;
        }
        if began.elapsed() > Duration::from_secs(seconds) {
            let _ = child.kill();
            let _ = child.wait();
            panic!("arc {args:?} hung (over {seconds} s)");
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    Outcome {
        code: status.code(),
        signal: status.signal(),
        stdout: out.join().unwrap_or_default(),
        stderr: err.join().unwrap_or_default(),
    }
}

/// Runs `arc args` and asserts it ended with `code` and did not crash.
pub fn expect(args: &[&str], dir: &Path, code: i32) -> Outcome {
    let o = run(args, dir);
    assert!(!o.crashed(), "arc {args:?} crashed: {o:?}");
    assert_eq!(o.code, Some(code), "arc {args:?}: {o:?}");
    o
}

/// A hover plan for scenario `window`: the chain (N = 3, a line looking along +y)
/// at the scenario's start; `unknown_is_occupied` as given.
pub fn hover_plan(unknown_is_occupied: bool) -> String {
    let zeta = [2.0, 4.5, 1.5, 0.0, 0.0, 0.0, 0.0, 0.0];
    format!(
        r#"{{"format": "arc-plan/1",
 "chain": {{"units": 3, "link_length": 0.5, "unit_radius": 0.15, "link_radius": 0.01,
            "theta_max": 1.0471976, "beta_max": 2.0943952}},
 "map": {{"resolution": 0.1, "unknown_is_occupied": {unknown_is_occupied}}},
 "waypoints": [{{"zeta": {zeta:?}}}, {{"zeta": {zeta:?}}}],
 "stats": {{}}}}"#
    )
}

/// Wall time an end-to-end run (a plan on a large scenario, a whole flight) may take
/// before it counts as hung; a guard, not a timing.
pub const E2E_GUARD_SECONDS: u64 = 900;

/// How a run of `arc` that should have succeeded failed: its exit code and what it
/// printed.
#[derive(Debug)]
pub struct Failure {
    /// The exit code (`None`: ended by a signal).
    pub code: Option<i32>,
    /// Standard error, then standard output.
    pub message: String,
}

impl std::fmt::Display for Failure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "exit {:?}: {}", self.code, self.message)
    }
}

/// Runs the real `arc` binary with `args` (paths absolute) and tells whether it
/// exited 0; a crash fails the test.
pub fn arc_ok(args: &[&str]) -> Result<(), Failure> {
    let o = wait_at_most(
        spawn(&mut arc(args, &std::env::temp_dir())),
        args,
        E2E_GUARD_SECONDS,
    );
    assert!(!o.crashed(), "arc {args:?} crashed: {o:?}");
    if o.code == Some(0) {
        Ok(())
    } else {
        Err(Failure {
            code: o.code,
            message: format!("{}{}", o.stderr, o.stdout),
        })
    }
}

/// A path as the `&str` a command line takes.
pub fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

/// Runs `arc plan --scenario scenario --units units` with the extra `flags`, writing
/// the plan to `out`.
pub fn plan_scenario(scenario: &str, units: u8, flags: &[&str], out: &Path) -> Result<(), Failure> {
    let n = units.to_string();
    let mut args = vec!["plan", "--scenario", scenario, "--units", &n];
    args.extend_from_slice(flags);
    args.extend_from_slice(&["--out", s(out)]);
    arc_ok(&args)
}

/// Checks `plan` for `sc` with the exact verifier (never the planner's own checks) and
/// that its head ends within 0.3 m of the goal; `label` names the case in failures.
pub fn assert_verified_to_goal(
    sc: &aerial_chain::problem::scenarios::Scenario,
    plan: &aerial_chain::plan_file::Plan,
    label: &str,
) {
    let report = aerial_chain::collision::verify_plan(&sc.grid, plan);
    assert!(report.ok, "{label}: {:?}", report.violation);
    let last = plan.waypoints[plan.waypoints.len() - 1].xi();
    let d = ((0..3).map(|k| (last[k] - sc.goal[k]).powi(2)).sum::<f64>()).sqrt();
    assert!(d <= 0.3 + 1e-9, "{label}: ends {d} m from the goal");
}

/// Plans `scenario` for `units` with `arc plan`'s defaults into `dir`, checks the plan
/// with [`assert_verified_to_goal`]; returns the plan and the scenario.
pub fn plan_verified(
    scenario: &str,
    units: u8,
    dir: &Path,
) -> (
    aerial_chain::plan_file::Plan,
    aerial_chain::problem::scenarios::Scenario,
) {
    let out = dir.join(format!("{scenario}-{units}.json"));
    plan_scenario(scenario, units, &[], &out)
        .unwrap_or_else(|e| panic!("{scenario} N={units}: no plan: {e}"));
    let plan = aerial_chain::plan_file::Plan::read(&out).expect("plan file reads back");
    let sc = aerial_chain::problem::scenarios::build(scenario).expect("scenario");
    assert_verified_to_goal(&sc, &plan, &format!("{scenario} N={units}"));
    (plan, sc)
}

/// Runs `arc plan` from one of the [`sealed_rooms`] into the other, with the extra
/// `flags`; returns how it failed and the plan file it must not have written.
pub fn plan_across_sealed_rooms(dir: &Path, flags: &[&str]) -> (Failure, PathBuf) {
    let map = sealed_rooms(dir);
    let out = dir.join("p.json");
    let mut args = vec![
        "plan",
        "--map",
        s(&map),
        "--units",
        "4",
        "--start",
        "3,2,1.5",
        "--start-yaw-deg",
        "0",
        "--goal",
        "6,2,1.5",
    ];
    args.extend_from_slice(flags);
    args.extend_from_slice(&["--out", s(&out)]);
    let failure = arc_ok(&args).expect_err("no plan between sealed rooms");
    (failure, out)
}

/// A map of two sealed rooms: free inside, walls around and between.
pub fn sealed_rooms(dir: &Path) -> PathBuf {
    let mut g = aerial_chain::map::Grid::new(
        0.1,
        [0, 0, 0],
        [80, 40, 30],
        aerial_chain::map::Cell::Free,
        true,
    )
    .unwrap();
    let wall = |g: &mut aerial_chain::map::Grid, lo: [f64; 3], hi: [f64; 3]| {
        g.fill_box(lo, hi, aerial_chain::map::Cell::Occupied)
    };
    wall(&mut g, [0.0, 0.0, 0.0], [8.0, 4.0, 0.2]);
    wall(&mut g, [0.0, 0.0, 2.8], [8.0, 4.0, 3.0]);
    wall(&mut g, [0.0, 0.0, 0.0], [0.2, 4.0, 3.0]);
    wall(&mut g, [7.8, 0.0, 0.0], [8.0, 4.0, 3.0]);
    wall(&mut g, [0.0, 0.0, 0.0], [8.0, 0.2, 3.0]);
    wall(&mut g, [0.0, 3.8, 0.0], [8.0, 4.0, 3.0]);
    wall(&mut g, [3.9, 0.0, 0.0], [4.1, 4.0, 3.0]);
    let path = dir.join("sealed.bt");
    g.to_octree().unwrap().write_bt(&path).unwrap();
    path
}

/// `src` (C++ against OctoMap's library) compiled with g++ into the tests' temporary
/// directory as `name`, unless a build newer than the source is there; or why it cannot
/// be: g++ or the OctoMap library missing, named with the package to install (`./test`
/// installs both). A program that does not compile is a bug: it panics.
pub fn octomap_program(src: &Path, name: &str) -> Result<PathBuf, String> {
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let fresh = match (std::fs::metadata(&out), std::fs::metadata(src)) {
        (Ok(o), Ok(s)) => matches!((o.modified(), s.modified()), (Ok(o), Ok(s)) if o > s),
        _ => false,
    };
    if fresh {
        return Ok(out);
    }
    let tmp = out.with_extension(format!("tmp{}", std::process::id()));
    let output = Command::new("g++")
        .args(["-O1", "-std=c++17", "-o"])
        .arg(&tmp)
        .arg(src)
        .args(["-loctomap", "-loctomath"])
        .output()
        .map_err(|e| {
            format!("cannot run g++ ({e}): install it (apt-get install -y g++), or run ./test, which does")
        })?;
    if !output.status.success() {
        let stderr = String::from_utf8_lossy(&output.stderr);
        if stderr.contains("octomap/") || stderr.contains("-loctoma") {
            return Err(format!(
                "the OctoMap library is not installed (apt-get install -y liboctomap-dev, or run ./test, which does): {}",
                stderr.lines().find(|l| l.contains("octom")).unwrap_or("")
            ));
        }
        panic!("g++ failed on {}:\n{stderr}", src.display());
    }
    std::fs::rename(&tmp, &out).map_err(|e| format!("{}: {e}", out.display()))?;
    Ok(out)
}
