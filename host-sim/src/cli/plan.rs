//! `arc plan`: the ARCplanner on a map file or a built-in scenario.

use std::path::PathBuf;
use std::sync::atomic::AtomicUsize;
use std::time::Duration;

use arc_core::ChainParams;
use clap::Args;

use super::common::{ChainArgs, MapArgs, Query, QueryArgs};
use super::{CliError, CliResult};
use crate::collision::{CollisionContext, DEFAULT_CLEARANCE};
use crate::planner::{motion, Mode, Planner, Preference, Settings, Termination};
use crate::tables::{ShapeTables, TableSettings};

/// `arc plan`
#[derive(Args, Debug)]
pub struct PlanArgs {
    #[command(flatten)]
    map: MapArgs,
    #[command(flatten)]
    chain: ChainArgs,
    #[command(flatten)]
    query: QueryArgs,
    /// Goal tolerance for the head (m).
    #[arg(long, default_value_t = 0.3)]
    goal_tol: f64,
    /// Shape sources: both (the ARCplanner), lsc or srs (the paper's ablation).
    #[arg(long, value_enum, default_value_t = Mode::Both)]
    mode: Mode,
    /// Shape preference: least (change only when needed) or coverage (PN where it fits).
    #[arg(long, value_enum, default_value_t = Preference::Least)]
    prefer: Preference,
    /// Seed of the head roadmap.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Head roadmap vertices M_VT.
    #[arg(long, default_value_t = 1500)]
    vertices: usize,
    /// Head roadmap radius r_T (m).
    #[arg(long, default_value_t = 1.5)]
    r_t: f64,
    /// Most neighbours per head roadmap vertex (the nearest within r_T).
    #[arg(long, default_value_t = 30)]
    max_neighbours: usize,
    /// Headings tried per shape (n_psi).
    #[arg(long, default_value_t = 8)]
    n_psi: usize,
    /// G_Val connection radius d_c (C_T metric) [default: r_S for N and N_SRS].
    #[arg(long)]
    d_c: Option<f32>,
    /// Random shapes N_SRS (when the tables are generated).
    #[arg(long, default_value_t = 500)]
    srs: usize,
    /// Seed of the random shapes (when the tables are generated).
    #[arg(long, default_value_t = 1)]
    srs_seed: u64,
    /// Shape tables from `arc tables build` (instead of generating them).
    #[arg(long)]
    tables: Option<PathBuf>,
    /// Clearance margin added to every body's radius (m): plans keep this far from walls.
    #[arg(long, default_value_t = DEFAULT_CLEARANCE)]
    clearance: f64,
    /// Smallest clearance margin (m) the planner may give way to, only along a passage
    /// narrower than --clearance allows (0: the exact contract of docs/model.md).
    #[arg(long, default_value_t = 0.0)]
    clearance_min: f64,
    /// Head route search over the map's half-cell lattice (off: the paper's uniform
    /// head roadmap only).
    #[arg(long, default_value_t = true, action = clap::ArgAction::Set)]
    head_lattice: bool,
    /// Step (m) of follow-the-leader motion, where the body is laid back along the
    /// head's track (long chains through windows and doors); 0 turns it off (the paper).
    #[arg(long, default_value_t = 0.1)]
    follow_step: f64,
    /// Head edges the planner may drop without progress before it grows the roadmap.
    #[arg(long, default_value_t = 200)]
    max_replans: usize,
    /// How strongly head paths keep away from obstacles (0: shortest, as in the paper).
    #[arg(long, default_value_t = 2.0)]
    clearance_weight: f64,
    /// Times a failing query may double the head roadmap and try again.
    #[arg(long, default_value_t = 3)]
    max_growth: usize,
    /// Give up after this many seconds.
    #[arg(long)]
    time_limit: Option<f64>,
    /// Output plan (JSON, arc-plan/1).
    #[arg(long)]
    out: PathBuf,
    /// Picture of the plan (.svg or .png).
    #[arg(long)]
    picture: Option<PathBuf>,
}

/// Checks the numeric options.
fn check(a: &PlanArgs) -> Result<(), CliError> {
    let bad = |flag: &str, v: String, want: &str| {
        Err(CliError::input(format!("{flag} {v}: must be {want}")))
    };
    if a.max_growth > 8 {
        return bad(
            "--max-growth",
            a.max_growth.to_string(),
            "at most 8 (256 times the vertices)",
        );
    }
    if !(a.clearance_weight.is_finite() && a.clearance_weight >= 0.0) {
        return bad(
            "--clearance-weight",
            a.clearance_weight.to_string(),
            "a number >= 0",
        );
    }
    if a.max_neighbours == 0 {
        return bad(
            "--max-neighbours",
            a.max_neighbours.to_string(),
            "at least 1",
        );
    }
    if a.vertices == 0 {
        return bad("--vertices", a.vertices.to_string(), "at least 1");
    }
    if !(a.r_t.is_finite() && a.r_t > 0.0) {
        return bad("--r-t", a.r_t.to_string(), "a positive number");
    }
    if a.n_psi == 0 || a.n_psi > 360 {
        return bad("--n-psi", a.n_psi.to_string(), "between 1 and 360");
    }
    if a.d_c.is_some_and(|d| !(d.is_finite() && d > 0.0)) {
        return bad("--d-c", format!("{:?}", a.d_c), "a positive number");
    }
    if !(a.follow_step.is_finite() && (0.0..=1.0).contains(&a.follow_step)) {
        return bad(
            "--follow-step",
            a.follow_step.to_string(),
            "between 0 (off) and 1 m",
        );
    }
    if !(a.goal_tol.is_finite() && a.goal_tol >= 0.0) {
        return bad("--goal-tol", a.goal_tol.to_string(), "a number >= 0");
    }
    if !(a.clearance.is_finite() && a.clearance >= 0.0) {
        return bad("--clearance", a.clearance.to_string(), "a number >= 0");
    }
    if !(a.clearance_min.is_finite() && a.clearance_min >= 0.0) {
        return bad(
            "--clearance-min",
            a.clearance_min.to_string(),
            "a number >= 0",
        );
    }
    if a.time_limit.is_some_and(|t| !(t.is_finite() && t > 0.0)) {
        return bad(
            "--time-limit",
            format!("{:?}", a.time_limit),
            "a positive number of seconds",
        );
    }
    if a.srs > u16::MAX as usize {
        return bad("--srs", a.srs.to_string(), "at most 65535");
    }
    Ok(())
}

/// The tables: read from `--tables` (and checked against the chain) or generated.
pub fn load_tables(
    path: Option<&PathBuf>,
    params: ChainParams,
    srs: usize,
    seed: u64,
) -> Result<ShapeTables, CliError> {
    match path {
        Some(p) => {
            let t = ShapeTables::read(p).map_err(|e| CliError::input(e.to_string()))?;
            if t.params != params {
                return Err(CliError::input(format!(
                    "{}: the table is for another chain (N = {}, l = {}) than asked (N = {}, l = {})",
                    p.display(),
                    t.params.units,
                    t.params.link_length,
                    params.units,
                    params.link_length
                )));
            }
            Ok(t)
        }
        None => {
            let s = TableSettings {
                srs,
                seed,
                ..Default::default()
            };
            ShapeTables::build(params, &s, &AtomicUsize::new(0))
                .map_err(|e| CliError::failed(e.to_string()))
        }
    }
}

/// Runs `arc plan`.
pub fn run(a: PlanArgs) -> CliResult {
    check(&a)?;
    let loaded = a.map.load()?;
    let Query {
        params,
        start,
        shape,
        goal,
    } = a.query.resolve(&a.chain, loaded.scenario.as_ref())?;
    let tables = load_tables(a.tables.as_ref(), params, a.srs, a.srs_seed)?;
    let (resolution, unknown_occ) = (loaded.grid.resolution(), loaded.grid.unknown_is_occupied());
    let (field, _) = loaded.into_field();
    let ctx = CollisionContext::new(field, params, a.clearance).map_err(CliError::input)?;
    let settings = Settings {
        vertices: a.vertices,
        r_t: a.r_t,
        max_neighbours: a.max_neighbours,
        n_psi: a.n_psi,
        d_c: a.d_c,
        mode: a.mode,
        prefer: a.prefer,
        seed: a.seed,
        max_replans: a.max_replans,
        max_growth: a.max_growth,
        clearance_weight: a.clearance_weight,
        goal_tol: a.goal_tol,
        follow_step: a.follow_step,
        clearance_min: a.clearance_min,
        head_lattice: a.head_lattice,
    };
    let mut planner =
        Planner::new(ctx, tables, settings).map_err(|e| CliError::input(e.to_string()))?;
    let stop = Termination {
        time_limit: a.time_limit.map(Duration::from_secs_f64),
    };
    let solution = planner
        .solve(start, shape, goal, stop)
        .map_err(|e| CliError::failed(format!("no plan: {e}")))?;
    let plan = motion::to_plan(&solution, &params, resolution, unknown_occ);
    plan.write(&a.out)
        .map_err(|e| CliError::input(e.to_string()))?;
    let s = &solution.stats;
    println!(
        "{}: solved on {} with N = {}: {} waypoints, {} head edges, {} shape changes ({} LSC, {} SRS, {} yaw rotations, {} follow), {} replans",
        a.out.display(),
        a.map.name(),
        params.units,
        plan.waypoints.len(),
        s.edges,
        s.shape_changes,
        s.lsc_uses,
        s.srs_uses,
        s.rotations,
        s.follow_uses,
        s.replans
    );
    println!(
        "  roadmap {:.1} ms ({} vertices), planning {:.1} ms ({:.1} ms in {} collision checks)",
        s.roadmap_s * 1e3,
        s.roadmap_vertices,
        s.planning_s * 1e3,
        s.collision_s * 1e3,
        s.collision_checks
    );
    match s.min_margin_at {
        Some(p) => println!(
            "  smallest clearance margin kept: {:.3} m (below --clearance {:.3} m from ({:.2}, {:.2}, {:.2}) on)",
            s.min_margin, a.clearance, p[0], p[1], p[2]
        ),
        None => println!("  smallest clearance margin kept: {:.3} m", s.min_margin),
    }
    if s.route_points > 0 {
        println!(
            "  head route: {} points ({} lattice points expanded, {:.1} ms)",
            s.route_points,
            s.lattice_expanded,
            s.lattice_s * 1e3
        );
    }
    if let Some(pic) = &a.picture {
        let grid = planner.context().field().grid();
        crate::plan_picture::draw(
            grid,
            &plan,
            &format!("ARCplanner on {}", a.map.name()),
            Some(goal),
        )
        .save(pic)
        .map_err(CliError::input)?;
        println!("  picture: {}", pic.display());
    }
    Ok(())
}
