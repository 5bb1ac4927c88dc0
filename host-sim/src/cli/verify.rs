//! `arc verify`: the exact check of docs/model.md, independent of the planner.

use std::path::PathBuf;

use clap::Args;

use super::common::{parse_point, MapArgs};
use super::{CliError, CliResult};
use crate::collision::verify_plan;
use crate::plan::Plan;

/// `arc verify`
#[derive(Args, Debug)]
pub struct VerifyArgs {
    #[command(flatten)]
    map: MapArgs,
    /// The plan (JSON, arc-plan/1); `-` reads it from standard input.
    #[arg(long)]
    plan: PathBuf,
    /// Where the plan must start (head x,y,z); a scenario has its own.
    #[arg(long, value_parser = parse_point, allow_hyphen_values = true)]
    start: Option<[f64; 3]>,
    /// Where the plan must end (head x,y,z); a scenario has its own.
    #[arg(long, value_parser = parse_point, allow_hyphen_values = true)]
    goal: Option<[f64; 3]>,
    /// Goal tolerance (m).
    #[arg(long, default_value_t = 0.3)]
    goal_tol: f64,
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// Runs `arc verify`: exit 0 only when every waypoint and every sampled point of
/// every edge is valid, and the plan starts and ends where asked.
pub fn run(a: VerifyArgs) -> CliResult {
    let plan = Plan::read(&a.plan).map_err(|e| CliError::input(e.to_string()))?;
    let mut map = a.map.clone();
    // The plan records what it assumed of unknown space; check it under that assumption.
    map.unknown_free |= !plan.map.unknown_is_occupied;
    let loaded = map.load()?;
    let sc = loaded.scenario.as_ref();
    let start = a.start.or(sc.map(|s| s.start));
    let goal = a.goal.or(sc.map(|s| s.goal));
    let report = verify_plan(&loaded.grid, &plan);
    println!(
        "{}: {} waypoints, {} edges ({} translations, {} shape changes), {} configurations checked exactly (unknown space {})",
        crate::fsutil::input_name(&a.plan),
        plan.waypoints.len(),
        report.edges.len(),
        report.edges.iter().filter(|e| **e == crate::collision::EdgeKind::Translation).count(),
        report.edges.iter().filter(|e| **e == crate::collision::EdgeKind::ShapeChange).count(),
        report.samples,
        if loaded.grid.unknown_is_occupied() { "occupied" } else { "free" }
    );
    if plan.map.source.differs_from(&loaded.source) {
        println!(
            "  note: the plan was made for {}; checked here against {}",
            plan.map.source, loaded.source
        );
    }
    for n in &report.notes {
        println!("  note: {n}");
    }
    match &report.min_clearance_at {
        Some((site, body)) => println!(
            "  minimum clearance {:.4} m ({body} at {site})",
            report.min_clearance
        ),
        None => println!("  minimum clearance >= {:.4} m", report.min_clearance),
    }
    if let Some(v) = &report.violation {
        return Err(CliError::failed(format!("INVALID: {v}")));
    }
    let first = plan.waypoints[0].xi();
    if let Some(s) = start {
        if dist(first, s) > 1e-6 {
            return Err(CliError::failed(format!(
                "INVALID: waypoint 0 head {first:?} is not the start {s:?}"
            )));
        }
    }
    let last = plan.waypoints[plan.waypoints.len() - 1].xi();
    if let Some(g) = goal {
        let d = dist(last, g);
        if d > a.goal_tol {
            return Err(CliError::failed(format!(
                "INVALID: last head {last:?} is {d:.3} m from the goal {g:?} (tolerance {})",
                a.goal_tol
            )));
        }
    }
    if !report.ok {
        return Err(CliError::failed("INVALID"));
    }
    println!("  VALID");
    Ok(())
}
