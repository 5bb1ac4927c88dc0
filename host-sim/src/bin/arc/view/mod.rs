//! `arc view`: one self-contained HTML page with a 3D view of a plan (and a flight)
//! on its map, which opens from disk with no server and no network.

mod page;
mod scene;

use std::path::PathBuf;

use clap::Args;

use super::checks;
use super::common::{parse_point, read_plan, MapArgs};
use super::{CliError, CliResult};
use aerial_chain::online::SeenOccupied;
use scene::{FlightFile, Region, Scene};

/// `arc view`
#[derive(Args, Debug)]
#[command(
    after_help = "Examples:\n  arc view --scenario window --plan window.json --out view.html\n  arc sim --scenario window --plan window.json --out flight.json\n  arc view --scenario window --plan window.json --flight flight.json --out view.html\n  arc explore --scenario maze --out explored.json --plan-out flown.json\n  arc view --scenario maze --plan flown.json --flight explored.json --out view.html"
)]
pub struct ViewArgs {
    #[command(flatten)]
    map: MapArgs,
    /// The plan to show (JSON, arc-plan/1); `-` reads it from standard input.
    #[arg(long)]
    plan: PathBuf,
    /// A flight of the plan to show against it (the JSON of `arc sim --out`); an
    /// exploration's (`arc explore --out`) also shows the map its sensors drew, growing
    /// as the chain flies.
    #[arg(long)]
    flight: Option<PathBuf>,
    /// The HTML page to write.
    #[arg(long)]
    out: PathBuf,
    /// Goal head position x,y,z drawn as the goal region; a scenario has its own,
    /// otherwise the plan's last head position is used.
    #[arg(long, value_parser = parse_point, allow_hyphen_values = true)]
    goal: Option<[f64; 3]>,
    /// Goal tolerance: the radius of the goal region (m).
    #[arg(long, default_value_t = 0.3)]
    goal_tol: f64,
    /// Draw the obstacles within about this distance of the chain's path (m).
    #[arg(long, default_value_t = 3.0)]
    near: f64,
    /// Draw the whole map instead of the obstacles near the path.
    #[arg(long)]
    whole_map: bool,
    /// Most obstacle boxes drawn; beyond it voxels are merged into larger boxes.
    #[arg(long, default_value_t = 60_000)]
    max_boxes: usize,
}

/// Checks every option before any work.
fn check(a: &ViewArgs) -> Result<(), CliError> {
    checks::length("--goal-tol", a.goal_tol, false)?;
    checks::length("--near", a.near, true)?;
    if !(1..=1_000_000).contains(&a.max_boxes) {
        return Err(checks::bad(
            "--max-boxes",
            a.max_boxes,
            "between 1 and 1000000",
        ));
    }
    if crate::fsutil::is_stdio(&a.plan) && a.flight.as_deref().is_some_and(crate::fsutil::is_stdio)
    {
        return Err(CliError::input(
            "--plan - and --flight -: only one of them can be standard input",
        ));
    }
    Ok(())
}

/// Reads a flight file (`-`: standard input): the flown units, and the map its
/// sensors drew when it is an exploration's.
fn read_flight(
    path: &std::path::Path,
    units: usize,
) -> Result<(scene::Flown, Option<SeenOccupied>), CliError> {
    let name = crate::fsutil::input_name(path);
    let text = if crate::fsutil::is_stdio(path) {
        std::io::read_to_string(std::io::stdin())
    } else {
        std::fs::read_to_string(path)
    }
    .map_err(|e| CliError::input(format!("{name}: cannot read the file: {e}")))?;
    let file: FlightFile = serde_json::from_str(&text).map_err(|e| {
        let what = crate::fsutil::not_of_format(&text, aerial_chain::sim::FLIGHT_FORMAT, &e);
        CliError::input(format!("{name}: {what}"))
    })?;
    scene::flown(file, units).map_err(|e| CliError::input(format!("{name}: {e}")))
}

/// Runs `arc view`: writes the page, exit 0.
pub fn run(a: ViewArgs) -> CliResult {
    check(&a)?;
    let (plan, plan_name, params) = read_plan(&a.plan)?;
    let units = params.n();
    let (flight, seen) = match a.flight.as_deref() {
        Some(p) => {
            let (flown, seen) = read_flight(p, units)?;
            (Some(flown), seen)
        }
        None => (None, None),
    };
    let loaded = a.map.load()?;
    let waypoints = scene::waypoints(&plan, &loaded.grid)
        .map_err(|e| CliError::input(format!("{plan_name}: {e}")))?;
    let last = plan.waypoints[plan.waypoints.len() - 1].xi();
    let goal = a
        .goal
        .or(loaded.scenario.as_ref().map(|s| s.goal.into()))
        .unwrap_or(last);
    let mut path = scene::along(&waypoints.units, units, a.near / 2.0);
    if let Some(f) = &flight {
        path.extend(f.units.chunks_exact(3).map(|c| [c[0], c[1], c[2]]));
    }
    path.push(goal);
    let region = if a.whole_map {
        Region::Whole
    } else {
        Region::Near(&path, a.near)
    };
    let boxes = scene::boxes(&loaded.grid, &region, a.max_boxes);
    // Only a flight file holds an exploration's record.
    let flight_name = a.flight.as_deref().map(crate::fsutil::input_name);
    let seen = seen
        .map(|s| scene::seen_boxes(&loaded.grid, &s, &region, a.max_boxes))
        .transpose()
        .map_err(|e| CliError::input(format!("{}: {e}", flight_name.unwrap_or_default())))?;
    let title = match &a.flight {
        Some(f) => format!(
            "{plan_name} and flight {} on {}",
            crate::fsutil::input_name(f),
            a.map.name()
        ),
        None => format!("{plan_name} on {}", a.map.name()),
    };
    let scene = Scene {
        format: "arc-view/1",
        title,
        units,
        unit_radius: f64::from(params.unit_radius),
        link_radius: f64::from(params.link_radius),
        boxes,
        waypoints,
        goal: Some(scene::Goal {
            center: goal,
            radius: a.goal_tol,
        }),
        flight,
        seen,
    };
    let html = page::html(&scene);
    crate::fsutil::write_output(&a.out, html.as_bytes())
        .map_err(|e| CliError::input(format!("{}: {e}", crate::fsutil::output_name(&a.out))))?;
    if !crate::fsutil::is_stdio(&a.out) {
        println!(
            "{plan_name}: {} waypoints, {} obstacle boxes of {} m{}; wrote {} ({} kB)",
            plan.waypoints.len(),
            (scene.boxes.occupied.len() + scene.boxes.unknown.len()) / 3,
            scene.boxes.lattice.size,
            match (&scene.flight, &scene.seen) {
                (Some(_), Some(s)) => format!(
                    ", with the flight and the {} boxes its sensors saw as it grew",
                    s.t.len()
                ),
                (Some(_), None) => ", with the flight".to_string(),
                _ => String::new(),
            },
            a.out.display(),
            html.len().div_ceil(1000)
        );
    }
    Ok(())
}
