//! Fuzz target: a plan file (`arc-plan/1` JSON) from arbitrary bytes, read as
//! `arc verify` and `arc sim` read it, then verified exactly on a small room. Nothing
//! may panic, hang or allocate without bound: a plan the reader accepts is checked in
//! full, whatever its numbers.
#![no_main]

use std::sync::OnceLock;

use aerial_chain::collision::verify_plan;
use aerial_chain::map::{Cell, Grid};
use aerial_chain::plan_file::Plan;
use libfuzzer_sys::fuzz_target;

/// A free 2 x 2 x 1 m room at 0.1 m with one occupied box, built once.
fn room() -> &'static Grid {
    static ROOM: OnceLock<Grid> = OnceLock::new();
    ROOM.get_or_init(|| {
        let mut g = Grid::new(0.1, [0, 0, 0], [20, 20, 10], Cell::Free, true)
            .expect("a small room");
        g.fill_box([0.9, 0.9, 0.0], [1.1, 1.1, 1.0], Cell::Occupied);
        g
    })
}

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(plan) = Plan::parse(text, "fuzz") else {
        return;
    };
    let params = plan.check().expect("a parsed plan passes its own check");
    assert_eq!(params.units as usize * 2 + 2, plan.waypoints[0].zeta.len());
    let report = verify_plan(room(), &plan);
    assert_eq!(report.ok, report.violation.is_none());
});
