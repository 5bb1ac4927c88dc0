//! `arc verify`: the exact check of docs/model.md, independent of the planner.

use std::path::PathBuf;

use clap::Args;

use super::checks;
use super::common::{looser_assumption, parse_point, MapArgs};
use super::{CliError, CliResult};
use aerial_chain::collision::verify_plan;
use aerial_chain::plan_file::Plan;

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

/// A point for messages: `(x, y, z)`.
fn point(p: [f64; 3]) -> String {
    format!("({}, {}, {})", p[0], p[1], p[2])
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// Runs `arc verify`: exit 0 only when every waypoint and every sampled point of
/// every edge is valid, and the plan starts and ends where asked.
pub fn run(a: VerifyArgs) -> CliResult {
    checks::length("--goal-tol", a.goal_tol, false)?;
    let plan = Plan::read(&a.plan).map_err(|e| CliError::input(e.to_string()))?;
    // What unknown space is comes from the command line only, never from the plan
    // under test (docs/model.md, Interpretations).
    let looser = looser_assumption(&plan, &a.map);
    let loaded = a.map.load()?;
    let sc = loaded.scenario.as_ref();
    let start = a.start.or(sc.map(|s| s.start.into()));
    let goal = a.goal.or(sc.map(|s| s.goal.into()));
    let report = verify_plan(&loaded.grid, &plan);
    println!(
        "{}: {} waypoints, {} edges ({} translations, {} shape changes), {} configurations checked exactly (unknown space {})",
        crate::fsutil::input_name(&a.plan),
        plan.waypoints.len(),
        report.edges.len(),
        report.edges.iter().filter(|e| **e == aerial_chain::collision::EdgeKind::Translation).count(),
        report.edges.iter().filter(|e| **e == aerial_chain::collision::EdgeKind::ShapeChange).count(),
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
    if let Some(why) = looser {
        return Err(CliError::failed(format!("INVALID: {why}")));
    }
    let first = plan.waypoints[0].xi();
    if let Some(s) = start {
        if dist(first, s) > 1e-6 {
            return Err(CliError::failed(format!(
                "INVALID: waypoint 0 head {} is not the start {}",
                point(first),
                point(s)
            )));
        }
    }
    let last = plan.waypoints[plan.waypoints.len() - 1].xi();
    if let Some(g) = goal {
        let d = dist(last, g);
        // A NaN distance fails too.
        if d.is_nan() || d > a.goal_tol {
            return Err(CliError::failed(format!(
                "INVALID: last head {} is {d:.3} m from the goal {} (tolerance {} m)",
                point(last),
                point(g),
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
