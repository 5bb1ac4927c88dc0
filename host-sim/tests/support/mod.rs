//! Running the real `arc` binary as a user would, under hang and memory guards.
//!
//! The guards are not timings: a child gets `GUARD_SECONDS` of wall time and
//! `GUARD_BYTES` of address space, far beyond what any run here needs, so that a
//! hang or a runaway allocation is seen as a failure instead of stalling CI.

#![allow(dead_code)] // each test file uses a part

use std::io::Read;
use std::os::unix::process::{CommandExt, ExitStatusExt};
use std::path::Path;
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

/// Runs `arc args` in `dir` and waits, killing it after [`GUARD_SECONDS`].
pub fn run(args: &[&str], dir: &Path) -> Outcome {
    let child = arc(args, dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn arc");
    wait(child, args)
}

/// Waits for `child` under the hang guard and collects its output.
pub fn wait(mut child: Child, args: &[&str]) -> Outcome {
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
        if began.elapsed() > Duration::from_secs(GUARD_SECONDS) {
            let _ = child.kill();
            let _ = child.wait();
            panic!("arc {args:?} hung (over {GUARD_SECONDS} s)");
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
