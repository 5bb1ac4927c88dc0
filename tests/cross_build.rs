//! `aerial-chain-core` must build for the units' autopilots: thumbv7em-none-eabihf
//! (Cortex-M4F/M7F), no_std, no alloc, with and without its `defmt` feature.

use arc_tests::{cargo, require_thumbv7em_target};

fn build_core(features: &[&str]) {
    require_thumbv7em_target();
    let mut c = cargo("cross");
    c.args([
        "build",
        "--release",
        "-p",
        "aerial-chain-core",
        "--target",
        "thumbv7em-none-eabihf",
    ]);
    if !features.is_empty() {
        c.args(["--features", &features.join(",")]);
    }
    let out = c.output().expect("cargo runs");
    assert!(
        out.status.success(),
        "aerial-chain-core failed to build for thumbv7em-none-eabihf (features {features:?}):\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn core_builds_for_thumbv7em() {
    build_core(&[]);
    build_core(&["defmt"]);
}
