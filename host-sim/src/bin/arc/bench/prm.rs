//! `arc bench prm`: one plan by the full-state PRM baseline, verified exactly.

use std::path::PathBuf;
use std::time::Duration;

use clap::Args;

use super::super::checks;
use super::super::common::{write_plan, ProblemArgs};
use super::super::{CliError, CliResult};
use aerial_chain::baseline::{FullStatePrm, PrmError, PrmSettings};
use aerial_chain::collision::{verify_plan, DEFAULT_CLEARANCE};
use aerial_chain::planner::{to_plan, Planner, Termination};

/// `arc bench prm`
#[derive(Args, Debug)]
pub struct PrmArgs {
    #[command(flatten)]
    problem: ProblemArgs,
    /// Vertex budget M_F.
    #[arg(long, default_value_t = 1500)]
    vertices: usize,
    /// Neighbours per vertex (default: the PRM* rule).
    #[arg(long)]
    k: Option<usize>,
    /// Configurations sampled in the goal ball (default: 1% of M_F, at least 10).
    #[arg(long)]
    goal_samples: Option<usize>,
    /// Seed of the sampler.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Clearance margin added to every body's radius (m).
    #[arg(long, default_value_t = DEFAULT_CLEARANCE)]
    clearance: f64,
    /// Give up after this many seconds (roadmap build and query each).
    #[arg(long)]
    time_limit: Option<f64>,
    /// Output plan (JSON, arc-plan/1); `-` writes it to standard output.
    #[arg(long)]
    out: PathBuf,
}

/// Checks every option of `arc bench prm` before any work (docs/promises.md).
fn check_prm(a: &PrmArgs) -> Result<Option<Duration>, CliError> {
    checks::length("--clearance", a.clearance, false)?;
    checks::length("--goal-tol", a.problem.goal_tol, false)?;
    checks::count(
        "--vertices",
        a.vertices,
        1,
        checks::MAX_PRM_VERTICES,
        "each holds a full configuration and its edges",
    )?;
    if let Some(k) = a.k {
        checks::count("--k", k, 1, checks::MAX_NEIGHBOURS, "edges per vertex")?;
    }
    if let Some(g) = a.goal_samples {
        checks::count(
            "--goal-samples",
            g,
            1,
            a.vertices,
            "part of the --vertices budget",
        )?;
    }
    checks::time_limit(a.time_limit)
}

pub fn run_prm(a: PrmArgs) -> CliResult {
    let time_limit = check_prm(&a)?;
    let (ctx, params, query, map) = a.problem.context(a.clearance)?;
    let settings = PrmSettings {
        vertices: a.vertices,
        k: a.k,
        goal_samples: a.goal_samples,
        seed: a.seed,
    };
    let mut prm = FullStatePrm::new(ctx, settings).map_err(|e| CliError::input(e.to_string()))?;
    let stop = Termination { time_limit };
    let sol = prm.solve(&query, stop).map_err(|e| match e {
        PrmError::BadSettings(_) | PrmError::StartInvalid(_) | PrmError::GoalInvalid(_) => {
            CliError::input(e.to_string())
        }
        _ => {
            let r = prm.roadmap_stats();
            CliError::failed(format!(
                "no plan: {e} (roadmap {} vertices, {} edges, built in {:.1} ms{})",
                r.vertices,
                r.graph_edges,
                r.timings.roadmap_s * 1e3,
                if r.build_capped {
                    ", cut by the time limit"
                } else {
                    ""
                }
            ))
        }
    })?;
    let grid = prm.context().field().grid();
    let plan = to_plan(&sol, &params, map);
    let report = verify_plan(grid, &plan);
    let s = &sol.stats;
    let details = format!(
        "{} roadmap edges, {} shape changes",
        s.path_edges, s.shape_changes
    );
    let solved = "full-state PRM solved";
    let lines = write_plan(&plan, &a.out, solved, &a.problem.map, &details)?;
    lines.line(format_args!(
        "  roadmap {:.1} ms ({} vertices, k = {}, {} edges), planning {:.1} ms ({} lazy searches, {} edges checked, {} blocked; {:.1} ms in checks)",
        s.timings.roadmap_s * 1e3,
        s.vertices,
        s.k,
        s.graph_edges,
        s.timings.planning_s * 1e3,
        s.iterations,
        s.edges_checked,
        s.edges_blocked,
        s.timings.collision_s * 1e3
    ));
    if report.ok {
        lines.line(format_args!("  exact verification: ok"));
        Ok(())
    } else {
        let why = report
            .violation
            .as_ref()
            .map_or_else(|| "a problem".to_string(), |v| v.to_string());
        Err(CliError::failed(format!(
            "the plan fails exact verification: {why}"
        )))
    }
}
