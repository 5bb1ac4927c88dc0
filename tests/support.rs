//! Helpers shared by the end-to-end tests.

use std::path::PathBuf;
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
