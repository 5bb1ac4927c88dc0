//! `arc verify`: the exact check of docs/model.md, independent of the planner.

use std::path::Path;

use clap::Args;

use super::checks;
use super::common::{
    looser_assumption, parse_point, GoalPoseArgs, MapArgs, MotionArgs, MotionFile,
};
use super::trajectory::{read_trajectory, LimitArgs};
use super::{CliError, CliResult};
use aerial_chain::collision::{verify_plan, VerifyOptions};
use aerial_chain::mission::Mission;
use aerial_chain::plan_file::Plan;
use aerial_chain::trajectory::check_samples;

/// `arc verify`
#[derive(Args, Debug)]
#[command(
    after_help = "Examples:\n  arc verify --scenario window --plan window.json\n  arc verify --scenario window --trajectory window-t.json"
)]
pub struct VerifyArgs {
    #[command(flatten)]
    map: MapArgs,
    #[command(flatten)]
    motion: MotionArgs,
    #[command(flatten)]
    limits: LimitArgs,
    /// Where the plan must start (head x,y,z); a scenario has its own.
    #[arg(long, value_parser = parse_point, allow_hyphen_values = true)]
    start: Option<[f64; 3]>,
    /// Where the plan must end (head x,y,z); a scenario has its own.
    #[arg(long, value_parser = parse_point, allow_hyphen_values = true)]
    goal: Option<[f64; 3]>,
    /// Goal tolerance (m).
    #[arg(long, default_value_t = 0.3)]
    goal_tol: f64,
    /// The yaw and shape the plan must end in (within 1e-6 rad, docs/model.md).
    #[command(flatten)]
    pose: GoalPoseArgs,
    /// A mission (arc-mission/1): the plan must reach its goals in order, each within
    /// its tolerance and, where asked, in its yaw and shape; its last goal replaces
    /// the scenario's.
    #[arg(long, conflicts_with_all = ["goal", "goal_yaw_deg", "goal_shape"])]
    mission: Option<std::path::PathBuf>,
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
    let path = match a.motion.file()? {
        MotionFile::Plan(p) => p,
        MotionFile::Trajectory(t) => return run_trajectory(&a, t),
    };
    let plan = Plan::read(path).map_err(|e| CliError::input(e.to_string()))?;
    // What unknown space is comes from the command line only, never from the plan
    // under test (docs/model.md, Interpretations).
    let looser = looser_assumption(&plan, &a.map);
    let loaded = a.map.load()?;
    let sc = loaded.scenario.as_ref();
    let mission = match &a.mission {
        Some(p) => Some(Mission::read(p).map_err(|e| CliError::input(e.to_string()))?),
        None => None,
    };
    let start = match mission.as_ref().and_then(|m| m.start.as_ref()) {
        Some(s) => Some(s.position),
        None => a.start.or(sc.map(|s| s.start.into())),
    };
    let goal = match &mission {
        Some(_) => None,
        None => a.goal.or(sc.map(|s| s.goal.into())),
    };
    let report = verify_plan(&loaded.grid, &plan);
    println!(
        "{}: {} waypoints, {} edges ({} translations, {} shape changes), {} configurations checked exactly (unknown space {})",
        crate::fsutil::input_name(path),
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
    let last = plan.waypoints[plan.waypoints.len() - 1].xi();
    ends_where_asked(
        plan.waypoints[0].xi(),
        last,
        start,
        goal,
        a.goal_tol,
        "waypoint 0",
    )?;
    if !report.ok {
        return Err(CliError::failed("INVALID"));
    }
    ends_in_pose(&plan, &a.pose)?;
    if let Some(m) = &mission {
        reaches_in_order(&plan, m)?;
    }
    println!("  VALID");
    Ok(())
}

/// Checks that the plan reaches the mission's goals in order: for each goal, a later
/// waypoint than the one that reached the goal before whose head is within the goal's
/// tolerance and whose shape is the goal's yaw and shape where asked. The plan's own
/// goal marks are not trusted; they are checked against what is found.
fn reaches_in_order(plan: &Plan, mission: &Mission) -> CliResult {
    let params = plan.check().map_err(|e| CliError::input(e.to_string()))?;
    let mut from = 0;
    for (k, g) in mission.goals.iter().enumerate() {
        let pose = mission.pose(k, &params).map_err(CliError::input)?;
        let found = plan.waypoints[from..]
            .iter()
            .position(|w| dist(w.xi(), g.position) <= g.tolerance && pose.holds(w.eta()));
        let Some(i) = found.map(|i| i + from) else {
            return Err(CliError::failed(format!(
                "INVALID: goals[{k}] at {} (tolerance {} m{}) is not reached after waypoint {from}",
                point(g.position),
                g.tolerance,
                match pose.is_any() {
                    true => String::new(),
                    false => format!(
                        ", {}",
                        pose.describe(g.shape.as_ref().and_then(|s| s.name()))
                    ),
                }
            )));
        };
        println!("  goals[{k}] reached at waypoint {i}");
        from = i;
    }
    Ok(())
}

/// Checks that the plan's last configuration is the yaw and shape asked for, where
/// asked (docs/model.md, "Goal configurations").
fn ends_in_pose(plan: &Plan, args: &GoalPoseArgs) -> CliResult {
    let params = plan.check().map_err(|e| CliError::input(e.to_string()))?;
    let pose = args.pose(&params)?;
    let last = plan.waypoints[plan.waypoints.len() - 1].eta();
    if pose.holds(last) {
        return Ok(());
    }
    Err(CliError::failed(format!(
        "INVALID: the last configuration (head yaw {:.4} rad) is not the goal's {} within {} rad",
        last[0],
        pose.describe(args.goal_shape.as_deref()),
        aerial_chain::goal::POSE_TOLERANCE
    )))
}

/// Checks that the head starts at `start` (within 1e-6 m) and ends within `tol` of
/// `goal`, where given; `what` names the first configuration.
fn ends_where_asked(
    first: [f64; 3],
    last: [f64; 3],
    start: Option<[f64; 3]>,
    goal: Option<[f64; 3]>,
    tol: f64,
    what: &str,
) -> CliResult {
    if let Some(s) = start {
        if dist(first, s) > 1e-6 {
            return Err(CliError::failed(format!(
                "INVALID: {what} head {} is not the start {}",
                point(first),
                point(s)
            )));
        }
    }
    if let Some(g) = goal {
        let d = dist(last, g);
        // A NaN distance fails too.
        if d.is_nan() || d > tol {
            return Err(CliError::failed(format!(
                "INVALID: last head {} is {d:.3} m from the goal {} (tolerance {} m)",
                point(last),
                point(g),
                tol
            )));
        }
    }
    Ok(())
}

/// `arc verify --trajectory`: every limit at every sample and every configuration
/// between samples exactly (docs/model.md, "Trajectories").
fn run_trajectory(a: &VerifyArgs, path: &Path) -> CliResult {
    let limits = a.limits.limits()?;
    let (file, name, params) = read_trajectory(path)?;
    let looser = (!file.map.unknown_is_occupied && !a.map.unknown_free).then(|| {
        "the trajectory was made with unknown space free; check it with --unknown-free".to_string()
    });
    let loaded = a.map.load()?;
    let sc = loaded.scenario.as_ref();
    let (times, zetas) = (file.times(), file.zetas());
    let rep = check_samples(
        &loaded.grid,
        &params,
        &limits,
        &times,
        &zetas,
        VerifyOptions::default().horizon,
    );
    println!(
        "{name}: {} samples over {:.2} s, {} configurations checked exactly (unknown space {})",
        times.len(),
        times.last().copied().unwrap_or(0.0),
        rep.configurations,
        if loaded.grid.unknown_is_occupied() {
            "occupied"
        } else {
            "free"
        }
    );
    if file.map.source.differs_from(&loaded.source) {
        println!(
            "  note: the trajectory was made for {}; checked here against {}",
            file.map.source, loaded.source
        );
    }
    let p = &rep.peaks;
    println!(
        "  peaks: speed {:.4} m/s, head acceleration {:.4} m/s^2, link angle rate {:.4} rad/s, \
         link angular acceleration {:.4} rad/s^2, head yaw rate {:.4} rad/s, head yaw \
         acceleration {:.4} rad/s^2",
        p.speed, p.accel, p.angular_rate, p.angular_accel, p.yaw_rate, p.yaw_accel
    );
    if let Some((t, body)) = rep.min_clearance_at {
        println!(
            "  minimum clearance {:.4} m ({body} at t = {t:.3} s)",
            rep.min_clearance
        );
    }
    if let Some(v) = &rep.violation {
        return Err(CliError::failed(format!("INVALID: {v}")));
    }
    if let Some(why) = looser {
        return Err(CliError::failed(format!("INVALID: {why}")));
    }
    let head = |z: &[f64]| [z[0], z[1], z[2]];
    let last = head(&zetas[zetas.len() - 1]);
    let start = a.start.or(sc.map(|s| s.start.into()));
    let goal = a.goal.or(sc.map(|s| s.goal.into()));
    ends_where_asked(head(&zetas[0]), last, start, goal, a.goal_tol, "sample 0")?;
    println!("  VALID");
    Ok(())
}
