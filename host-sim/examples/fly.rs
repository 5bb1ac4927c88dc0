//! Write a built-in scenario as an OctoMap `.bt` file, plan through it from the file,
//! verify the plan exactly and fly it with the chain's dynamics and control stack, as
//! `arc sim` flies it.
//!
//! ```sh
//! cargo run --example fly            # the `window` scenario, N = 5
//! ```

use std::error::Error;
use std::path::Path;

use aerial_chain::flying::{fly as fly_plan, FlyOptions};
use aerial_chain::problem::scenarios;
use aerial_chain::sim::{FlightReport, Progress};

#[path = "plan_on_map.rs"]
pub mod plan_on_map;

use plan_on_map::{plan_on_map, Problem};

/// Writes `scenario` as `<dir>/<scenario>.bt`, plans and verifies on that file, flies
/// the plan on the map read back and returns the flight's report.
pub fn fly(scenario: &str, dir: &Path) -> Result<FlightReport, Box<dyn Error>> {
    let sc = scenarios::build(scenario)?;
    let map = dir.join(format!("{scenario}.bt"));
    sc.grid.to_octree()?.write_bt(&map)?;

    let (grid, plan) = plan_on_map(&Problem {
        map: &map,
        unknown_free: false,
        units: sc.default_units,
        start: sc.start,
        yaw: sc.start_yaw as f32,
        goal: sc.goal,
    })?;

    // As `arc sim` flies it: along the plan's blended trajectory, after a rest.
    let (flight, _) = fly_plan(&plan, &grid, &FlyOptions::default(), &Progress::default())?;
    let r = flight.report;
    println!(
        "flown {:.1} s: head RMS error {:.3} m, minimum clearance {} m, {}",
        r.simulated_time,
        r.head_rms,
        r.min_clearance.map_or("?".into(), |c| format!("{c:.3}")),
        if r.success() {
            "arrived without contact"
        } else {
            "FAILED"
        }
    );
    if !r.success() {
        return Err("the flight did not arrive without contact".into());
    }
    Ok(r)
}

#[allow(dead_code)] // tests/examples.rs includes this file and calls `fly`.
fn main() -> Result<(), Box<dyn Error>> {
    let dir = tempfile::tempdir()?;
    fly("window", dir.path())?;
    Ok(())
}
