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
