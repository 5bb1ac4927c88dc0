//! Helpers shared by the end-to-end tests.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The workspace root.
pub fn workspace_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tests/ has a parent")
        .to_path_buf()
}

/// A `cargo` command that uses the same toolchain as the running tests, with its own
/// target directory so it never waits on the lock of the build that runs the tests.
pub fn cargo(target_subdir: &str) -> Command {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let mut c = Command::new(cargo);
    c.current_dir(workspace_root());
    c.env(
        "CARGO_TARGET_DIR",
        workspace_root().join("target").join(target_subdir),
    );
    c
}

/// Fails the calling test when `tool` (run with `args`) does not start and succeed,
/// naming the Debian package to install. No test passes without running: a green
/// run in which the tool never ran would be a lie (`./test` installs the package).
pub fn require_tool(tool: &str, args: &[&str], package: &str) {
    let ok = Command::new(tool)
        .args(args)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    assert!(
        ok,
        "{tool} not found: install it (apt-get install -y {package}), or run ./test, which does"
    );
}

/// Fails the calling test, saying how to add it, when the Rust standard library for
/// the units' target (thumbv7em-none-eabihf) is not installed: otherwise the build
/// fails with a bare "can't find crate for `core`" (E0463).
pub fn require_thumbv7em_target() {
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    let sysroot = Command::new(rustc)
        .current_dir(workspace_root())
        .args(["--print", "sysroot"])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| PathBuf::from(String::from_utf8_lossy(&o.stdout).trim()));
    let installed = sysroot
        .as_ref()
        .is_some_and(|s| s.join("lib/rustlib/thumbv7em-none-eabihf").is_dir());
    assert!(
        installed,
        "the Rust target thumbv7em-none-eabihf is not installed (sysroot {sysroot:?}): \
         rustup target add thumbv7em-none-eabihf, or run ./test, which does"
    );
}

/// Runs the `arc` command line in-process with `args` (the program name is added).
pub fn arc(args: &[&str]) -> Result<(), aerial_chain::cli::CliError> {
    let mut v = vec!["arc"];
    v.extend_from_slice(args);
    aerial_chain::cli::run(v)
}

/// A path as the `&str` a command line takes.
pub fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

/// Plans `scenario` for `units` with `arc plan`'s defaults into `dir`, checks the plan
/// with the exact verifier (never the planner's own checks) and that its head ends
/// within 0.3 m of the goal; returns the plan and the scenario.
pub fn plan_verified(
    scenario: &str,
    units: u8,
    dir: &Path,
) -> (
    aerial_chain::plan::Plan,
    aerial_chain::problem::scenarios::Scenario,
) {
    let out = dir.join(format!("{scenario}-{units}.json"));
    let n = units.to_string();
    arc(&[
        "plan",
        "--scenario",
        scenario,
        "--units",
        &n,
        "--out",
        s(&out),
    ])
    .unwrap_or_else(|e| panic!("{scenario} N={units}: no plan: {e}"));
    let plan = aerial_chain::plan::Plan::read(&out).expect("plan file reads back");
    let sc = aerial_chain::problem::scenarios::build(scenario).expect("scenario");
    let report = aerial_chain::collision::verify_plan(&sc.grid, &plan);
    assert!(report.ok, "{scenario} N={units}: {:?}", report.violation);
    let last = plan.waypoints[plan.waypoints.len() - 1].xi();
    let d = ((0..3).map(|k| (last[k] - sc.goal[k]).powi(2)).sum::<f64>()).sqrt();
    assert!(
        d <= 0.3 + 1e-9,
        "{scenario} N={units}: ends {d} m from the goal"
    );
    (plan, sc)
}

/// A map of two sealed rooms: free inside, walls around and between.
pub fn sealed_rooms(dir: &Path) -> PathBuf {
    let mut g = aerial_chain::map::grid::Grid::new(
        0.1,
        [0, 0, 0],
        [80, 40, 30],
        aerial_chain::map::grid::Cell::Free,
        true,
    )
    .unwrap();
    let wall = |g: &mut aerial_chain::map::grid::Grid, lo: [f64; 3], hi: [f64; 3]| {
        g.fill_box(lo, hi, aerial_chain::map::grid::Cell::Occupied)
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
