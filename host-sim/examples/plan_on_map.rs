//! Plan a chain through an OctoMap `.bt` map with the `arc plan` defaults, then check
//! the plan with the exact verifier (docs/model.md) rather than trust the planner.
//!
//! ```sh
//! cargo run --example plan_on_map                  # the real scan maps/geb079.bt, N = 5
//! cargo run --example plan_on_map -- corridor.json # ... and write the plan there
//! ```
//!
//! `fly` builds on [`plan_on_map`] and flies the plan in the simulation.

use std::error::Error;
use std::path::{Path, PathBuf};

use aerial_chain::collision::verify_plan;
use aerial_chain::map::{Grid, OcTree};
use aerial_chain::plan_file::{MapSection, MapSource, Plan};
use aerial_chain::planner::Query;
use aerial_chain::planning::{self, PlanOptions, Request};
use aerial_chain_core::{ChainParams, Shape};
use nalgebra::Point3;

/// A planning problem on a map file.
pub struct Problem<'a> {
    /// The OctoMap binary tree.
    pub map: &'a Path,
    /// Whether space the map never observed counts as free (else occupied).
    pub unknown_free: bool,
    /// Units N of the chain.
    pub units: u8,
    /// Head start (m); the chain starts straight, trailing behind the head along `-yaw`.
    pub start: Point3<f64>,
    /// Start yaw (rad).
    pub yaw: f32,
    /// Head goal (m).
    pub goal: Point3<f64>,
}

/// Reads the map, plans with the defaults of `arc plan` and verifies the plan exactly:
/// the map's grid and a plan that passed the verifier.
pub fn plan_on_map(p: &Problem) -> Result<(Grid, Plan), Box<dyn Error>> {
    // Read once: the bytes give both the tree and the hash the plan records.
    let bytes = std::fs::read(p.map).map_err(|e| format!("{}: {e}", p.map.display()))?;
    let tree = OcTree::from_bt_bytes(&bytes, &p.map.display().to_string())?;
    let grid = Grid::from_octree(&tree, !p.unknown_free)?;

    let params = ChainParams::new(p.units)
        .validate()
        .map_err(|e| format!("units = {}: {e}", p.units))?;
    let query = Query::new(p.start, Shape::line(p.units, p.yaw), p.goal);
    let mut request = Request::new(grid.clone(), params, query);
    request.map = MapSection::of(&grid).with_source(MapSource::file(p.map, &bytes));
    // Search, post-processing and the plan file, as `arc plan` makes them.
    let plan = planning::plan(&request, None, &PlanOptions::default())?.plan;

    // The planner's checks are conservative shortcuts; the verifier is the contract.
    let report = verify_plan(&grid, &plan);
    if let Some(v) = &report.violation {
        return Err(format!("the plan is INVALID: {v}").into());
    }
    if !report.ok {
        return Err("the plan is INVALID".into());
    }
    println!(
        "{}: {} waypoints, {} configurations checked exactly, minimum clearance {:.3} m",
        p.map.display(),
        plan.waypoints.len(),
        report.samples,
        report.min_clearance
    );
    Ok((grid, plan))
}

/// The real building scan shipped with the repository.
pub fn geb079() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../maps/geb079.bt")
}

/// Along the corridor of `geb079.bt`, 28 m; much of it was never observed, so unknown
/// space is taken as free (maps/README.md).
pub fn corridor(map: &Path) -> Problem<'_> {
    Problem {
        map,
        unknown_free: true,
        units: 5,
        start: Point3::new(-3.0, 0.0, 1.0),
        yaw: 0.0,
        goal: Point3::new(25.0, 0.0, 1.0),
    }
}

#[allow(dead_code)] // `fly` includes this file for `plan_on_map` and has its own main.
fn main() -> Result<(), Box<dyn Error>> {
    let map = geb079();
    let (_, plan) = plan_on_map(&corridor(&map))?;
    if let Some(out) = std::env::args_os().nth(1) {
        plan.write(Path::new(&out))?;
        println!("wrote {}", Path::new(&out).display());
    }
    Ok(())
}
