//! `arc plan --mission FILE`: a mission planned leg by leg into one plan
//! (docs/model.md, "Missions").

use std::path::Path;
use std::sync::Arc;

use super::super::common::{write_plan, QueryArgs};
use super::super::{CliError, CliResult};
use super::{draw, load_tables, print_quality, PlanArgs};
use aerial_chain::goal::GoalPose;
use aerial_chain::map::DistanceField;
use aerial_chain::mission::Mission;
use aerial_chain::plan_file::MapSection;
use aerial_chain::planner::Query;
use aerial_chain::planning::{plan_mission, PlanOptions, Request};

/// Runs `arc plan --mission path`.
pub fn run(
    a: &PlanArgs,
    path: &Path,
    options: &PlanOptions,
    timing: &aerial_chain::trajectory::Settings,
) -> CliResult {
    let mission = Mission::read(path).map_err(|e| CliError::input(e.to_string()))?;
    if a.problem.query.goal.is_some() {
        return Err(CliError::input(
            "--goal with --mission: the mission's goals are the goals",
        ));
    }
    let loaded = a.problem.map.load()?;
    let sc = loaded.scenario.as_ref();
    let units = match (a.problem.chain.units, mission.units) {
        (Some(u), Some(m)) if u != m => {
            return Err(CliError::input(format!(
                "--units {u}, but the mission {} is for units = {m}",
                path.display()
            )))
        }
        (u, m) => u.or(m).or(sc.map(|s| s.default_units)).ok_or_else(|| {
            CliError::input("--units (or the mission's units) is required with --map")
        })?,
    };
    let params = a.problem.chain.params(units)?;
    let query = start(a, &mission, sc, &params)?;
    let map = MapSection::of(&loaded.grid).with_source(loaded.source.clone());
    let base = Request {
        field: Arc::new(DistanceField::new(loaded.grid)),
        params,
        query,
        pose: GoalPose::default(),
        map,
    };
    let tables = load_tables(a.tables.as_ref(), params, a.srs, a.srs_seed)?;
    let began = std::time::Instant::now();
    let planned = plan_mission(&base, &mission, Some(tables), options).map_err(|e| {
        let text = format!("{}: {e}", path.display());
        match e.is_input() {
            true => CliError::input(text),
            false => CliError::failed(text),
        }
    })?;
    let plan = &planned.plan;
    let details = format!(
        "{} goals reached in order ({:.1} ms of planning over {} legs)",
        mission.goals.len(),
        began.elapsed().as_secs_f64() * 1e3,
        planned.legs.len()
    );
    let report = write_plan(plan, &a.out, "mission planned on", &a.problem.map, &details)?;
    for (k, leg) in planned.legs.iter().enumerate() {
        let q = &leg.quality;
        report.line(format_args!(
            "  leg {k}: {} waypoints, head path {:.2} m, {} shape changes, search {:.1} ms, post-processing {:.1} ms",
            leg.plan.waypoints.len(),
            q.head_path_m,
            q.shape_changes,
            leg.timings.search_s * 1e3,
            leg.timings.post_s * 1e3
        ));
    }
    let mut quality = aerial_chain::planner::Quality::default();
    for leg in &planned.legs {
        quality.add(&leg.quality);
    }
    print_quality(&report, &quality, None);
    let grid = base.grid();
    let mut timed = None;
    if let (Some(out), Some(made)) = (&a.trajectory, planned.trajectory) {
        let tr = made.map_err(|e| super::super::trajectory::refused(e, "the plan"))?;
        super::super::trajectory::write(&tr, plan, out, &report)?;
        timed = Some(tr);
    }
    if let Some(pic) = &a.picture {
        let last = mission
            .goals
            .last()
            .map(|g| (g.position.into(), g.tolerance));
        draw(a, pic, grid, plan, timed, last, timing)?;
        report.line(format_args!("  picture: {}", pic.display()));
    }
    Ok(())
}

/// The mission's start: the file's, else the command line's or the scenario's start,
/// yaw and start shape.
fn start(
    a: &PlanArgs,
    mission: &Mission,
    sc: Option<&aerial_chain::problem::scenarios::Scenario>,
    params: &aerial_chain_core::ChainParams,
) -> Result<Query, CliError> {
    let first = &mission.goals[0];
    if let Some((at, shape)) = mission.start_of(params).map_err(CliError::input)? {
        return Ok(Query {
            start: at,
            start_shape: shape,
            goal: first.position.into(),
            goal_tol: first.tolerance,
        });
    }
    // The query's rules for the start, with the first goal as its goal.
    let args = QueryArgs {
        goal: Some(first.position),
        ..a.problem.query.clone()
    };
    let mut chain = a.problem.chain.clone();
    chain.units = Some(params.units);
    let (_, query) = args.resolve(&chain, sc, first.tolerance)?;
    Ok(query)
}
