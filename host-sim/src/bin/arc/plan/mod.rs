//! `arc plan`: the ARCplanner on a map file or a built-in scenario.

use std::collections::BTreeSet;
use std::path::PathBuf;
use std::sync::atomic::AtomicUsize;
use std::sync::Arc;
use std::time::Instant;

use aerial_chain_core::ChainParams;
use clap::Args;

mod mission;

use super::checks;
use super::common::{write_plan, GoalPoseArgs, ProblemArgs, Report};
use super::trajectory::TimingArgs;
use super::{CliError, CliResult};
use aerial_chain::collision::DEFAULT_CLEARANCE;
use aerial_chain::map::DistanceField;
use aerial_chain::plan_file::MapSection;
use aerial_chain::planner::{Mode, Preference, Quality, Refinement, Settings, StageReport, Unit};
use aerial_chain::planning::{
    self, PlanOptions, PlanningError, Request, SettingsFile, DEFAULT_TIME_LIMIT_S,
};
use aerial_chain::tables::{ShapeTables, TableSettings};

/// `arc plan`
#[derive(Args, Debug)]
#[command(
    after_help = "Example:\n  arc plan --scenario window --units 5 --out window.json --picture window.svg"
)]
pub struct PlanArgs {
    #[command(flatten)]
    problem: ProblemArgs,
    /// Shape sources: both (the ARCplanner), lsc or srs (the paper's ablation).
    #[arg(long, value_enum, default_value_t = defaults().mode)]
    mode: Mode,
    /// Shape preference: least (change only when needed) or coverage (PN where it fits).
    #[arg(long, value_enum, default_value_t = defaults().prefer)]
    prefer: Preference,
    /// Seed of the uniform head roadmap (a query that flies the lattice's head route
    /// alone builds none, and the seed does not change its plan).
    #[arg(long, default_value_t = defaults().seed)]
    seed: u64,
    /// Head roadmap vertices M_VT.
    #[arg(long, default_value_t = defaults().vertices)]
    vertices: usize,
    /// Head roadmap radius r_T (m).
    #[arg(long, default_value_t = defaults().r_t)]
    r_t: f64,
    /// Most neighbours per head roadmap vertex (the nearest within r_T).
    #[arg(long, default_value_t = defaults().max_neighbours)]
    max_neighbours: usize,
    /// Headings tried per shape (n_psi).
    #[arg(long, default_value_t = defaults().n_psi)]
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
    #[arg(long, default_value_t = defaults().clearance_min)]
    clearance_min: f64,
    /// Head route search over the map's half-cell lattice (off: the paper's uniform
    /// head roadmap only).
    #[arg(long, default_value_t = defaults().head_lattice, action = clap::ArgAction::Set)]
    head_lattice: bool,
    /// Step (m) of follow-the-leader motion, where the body is laid back along the
    /// head's track (long chains through windows and doors); 0 turns it off (the paper).
    #[arg(long, default_value_t = defaults().follow_step)]
    follow_step: f64,
    /// Head edges the planner may drop without progress before it grows the roadmap.
    #[arg(long, default_value_t = defaults().max_replans)]
    max_replans: usize,
    /// How strongly head paths keep away from obstacles (0: shortest, as in the paper).
    #[arg(long, default_value_t = defaults().clearance_weight)]
    clearance_weight: f64,
    /// Times a failing query may double the head roadmap and try again.
    #[arg(long, default_value_t = defaults().max_growth)]
    max_growth: usize,
    /// Keep the plan as the search made it: no shortcuts, no merged translations or
    /// dropped shape changes (see `planner::refine`).
    #[arg(long)]
    no_smooth: bool,
    /// Give up after this many seconds of search and post-processing (setup, the
    /// map and the shape tables, is not counted); at most 1e6.
    #[arg(long, default_value_t = DEFAULT_TIME_LIMIT_S)]
    time_limit: f64,
    #[command(flatten)]
    pose: GoalPoseArgs,
    /// A mission (JSON, arc-mission/1): plan from its start (or the scenario's) through
    /// its goals in order, into one plan whose waypoints mark the goals.
    #[arg(long, conflicts_with_all = ["goal_yaw_deg", "goal_shape"])]
    mission: Option<PathBuf>,
    /// Output plan (JSON, arc-plan/1); `-` writes it to standard output.
    #[arg(long)]
    out: PathBuf,
    /// Picture of the plan (.svg or .png), or an animation of its timed trajectory
    /// (.gif, one frame per --frame-step).
    #[arg(long)]
    picture: Option<PathBuf>,
    /// Seconds of the trajectory between an animation's frames [default: 0.1 s or
    /// more, for at most about 120 frames].
    #[arg(long, allow_hyphen_values = true)]
    frame_step: Option<f64>,
    /// Also write the plan's timed trajectory (CSV when the name ends in .csv, else
    /// JSON, arc-trajectory/1), checked exactly on the map.
    #[arg(long)]
    trajectory: Option<PathBuf>,
    #[command(flatten)]
    timing: TimingArgs,
    /// Tuning from a settings file (JSON, one object with the sections planner,
    /// refine and trajectory; docs/settings.md lists every setting). A flag given on
    /// the command line wins over the file; a flag left at its default does not.
    #[arg(long)]
    settings: Option<PathBuf>,
}

/// The ids of the flags given on the command line (not left at their defaults): where
/// a settings file and a flag both set a value, the flag wins.
pub type Given = BTreeSet<String>;

/// The planner's defaults, the flags' (a settings file's fields left out take the same).
fn defaults() -> Settings {
    Settings::default()
}

/// Smallest follow-the-leader step (m) other than 0 (off).
const MIN_FOLLOW_STEP: f64 = 1e-3;

/// Checks every option before any work: numbers within their limits, sizes within
/// their budgets (docs/promises.md), the picture's format. (The planner's settings are
/// checked once merged with a settings file: [`check_planner`].)
fn check(a: &PlanArgs) -> Result<(), CliError> {
    checks::length("--goal-tol", a.problem.goal_tol, false)?;
    checks::length("--clearance", a.clearance, false)?;
    checks::time_limit(Some(a.time_limit))?;
    checks::srs(a.srs)?;
    a.timing.settings()?;
    let stdout = |p: &std::path::Path| crate::fsutil::is_stdio(p);
    if stdout(&a.out) && a.trajectory.as_deref().is_some_and(stdout) {
        return Err(CliError::input(
            "--out - and --trajectory - would both write to standard output: name a file for one",
        ));
    }
    super::picture::check(a.picture.as_ref(), a.frame_step)
}

/// Checks the planner's settings that have a flag, each named `name(flag, field)`: the
/// flag where it gave the value, else the settings file's field.
pub(super) fn check_planner(
    s: &Settings,
    name: &dyn Fn(&str, &str) -> String,
) -> Result<(), CliError> {
    let n = |flag: &str, field: &str| name(flag, field);
    let growth = n("--max-growth", "max_growth");
    checks::count(&growth, s.max_growth, 0, 8, "256 times the vertices")?;
    checks::non_negative(
        &n("--clearance-weight", "clearance_weight"),
        s.clearance_weight,
    )?;
    checks::count(
        &n("--max-neighbours", "max_neighbours"),
        s.max_neighbours,
        1,
        checks::MAX_NEIGHBOURS,
        "edges per vertex",
    )?;
    let most = checks::MAX_HEAD_VERTICES >> s.max_growth;
    checks::count(
        &n("--vertices", "vertices"),
        s.vertices,
        1,
        most,
        &format!(
            "{growth} {} lets the roadmap grow to {} times this, and the budget is {} \
             vertices",
            s.max_growth,
            1usize << s.max_growth,
            checks::MAX_HEAD_VERTICES
        ),
    )?;
    checks::length(&n("--r-t", "r_t"), s.r_t, true)?;
    checks::count(
        &n("--n-psi", "n_psi"),
        s.n_psi,
        1,
        360,
        "headings per shape",
    )?;
    if let Some(d) = s.d_c {
        checks::positive(&n("--d-c", "d_c"), d as f64)?;
    }
    // A floor on the step bounds the steps of an edge (and the memory they take).
    if !(s.follow_step == 0.0 || (MIN_FOLLOW_STEP..=1.0).contains(&s.follow_step)) {
        return Err(checks::bad(
            &n("--follow-step", "follow_step"),
            s.follow_step,
            &format!("0 (off) or between {MIN_FOLLOW_STEP} and 1 m"),
        ));
    }
    checks::count(
        &n("--max-replans", "max_replans"),
        s.max_replans,
        0,
        checks::MAX_REPLANS,
        "dropped edges per query",
    )?;
    checks::length(
        &n("--clearance-min", "clearance_min"),
        s.clearance_min,
        false,
    )?;
    Ok(())
}

/// A settings file as read: its settings, its name, and the keys it sets (dotted
/// paths, such as `planner.vertices`).
struct Loaded {
    file: SettingsFile,
    name: String,
    keys: BTreeSet<String>,
}

impl Loaded {
    /// Whether the file sets `key`.
    fn sets(&self, key: &str) -> bool {
        self.keys.contains(key)
    }
}

/// The settings file of `--settings`, read and checked (its tuning settings; those
/// with a flag are checked with the flags, [`check_planner`]).
fn read_settings(path: Option<&PathBuf>) -> Result<Option<Loaded>, CliError> {
    let Some((text, name, keys)) = settings_text(path)? else {
        return Ok(None);
    };
    let file = SettingsFile::parse(&text, &name).map_err(|e| CliError::input(e.to_string()))?;
    Ok(Some(Loaded { file, name, keys }))
}

/// The text of the settings file at `path`, its name for messages and the keys it
/// sets (dotted paths); `None` without a file.
pub(super) fn settings_text(
    path: Option<&PathBuf>,
) -> Result<Option<(String, String, BTreeSet<String>)>, CliError> {
    let Some(path) = path else {
        return Ok(None);
    };
    let name = crate::fsutil::input_name(path);
    let text =
        crate::fsutil::read_input(path).map_err(|e| CliError::input(format!("{name}: {e}")))?;
    let value: serde_json::Value = serde_json::from_str(&text).unwrap_or_default();
    let mut keys = BTreeSet::new();
    key_paths(&value, "", &mut keys);
    Ok(Some((text, name, keys)))
}

/// Every key of the JSON object `v` and of the objects within, as dotted paths.
fn key_paths(v: &serde_json::Value, path: &str, out: &mut BTreeSet<String>) {
    if let serde_json::Value::Object(m) = v {
        for (k, inner) in m {
            let here = match path {
                "" => k.clone(),
                p => format!("{p}.{k}"),
            };
            key_paths(inner, &here, out);
            out.insert(here);
        }
    }
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

/// The facade's options from the command line and the settings file `file`: a value is
/// the flag's where the flag is given on the command line (`given`), else the file's
/// where the file sets it, else the flag's default (the settings' default).
fn options(a: &PlanArgs, file: Option<&Loaded>, given: &Given) -> Result<PlanOptions, CliError> {
    let base = file.map(|f| f.file.clone()).unwrap_or_default();
    let flag =
        |id: &str| given.contains(id) || !file.is_some_and(|f| f.sets(&format!("planner.{id}")));
    let mut p = base.planner;
    macro_rules! take {
        ($($field:ident),*) => {
            $(if flag(stringify!($field)) {
                p.$field = a.$field;
            })*
        };
    }
    take!(
        vertices,
        r_t,
        max_neighbours,
        n_psi,
        d_c,
        mode,
        prefer,
        seed,
        max_replans,
        max_growth,
        clearance_weight,
        follow_step,
        clearance_min,
        head_lattice
    );
    let name = |flag_name: &str, field: &str| match file {
        Some(f) if !flag(field) => format!("{}: planner.{field}", f.name),
        _ => flag_name.to_string(),
    };
    check_planner(&p, &name)?;
    Ok(PlanOptions {
        planner: p,
        refine: base.refine,
        clearance: a.clearance,
        no_smooth: a.no_smooth,
        time_limit_s: Some(a.time_limit),
        srs: a.srs,
        srs_seed: a.srs_seed,
        trajectory: match a.trajectory {
            Some(_) => Some(timing(a, file, given)?),
            None => None,
        },
    })
}

/// Where the time of `planned` went, phase by phase (ms), after `setup_s` of setup:
/// the search's structures and its two searches (the head's route over the lattice,
/// the chain's shapes along it), then post-processing and the trajectory.
fn phases(setup_s: f64, planned: &planning::Planned) -> String {
    let (p, t) = (planned.stats.phases(), &planned.timings);
    let mut parts = vec![
        ("setup", setup_s),
        ("free regions", p.regions_s),
        ("head roadmap", p.roadmap_s),
        ("head route (lattice)", p.lattice_s),
        ("shape search", p.shapes_s),
        ("post-processing", t.post_s),
    ];
    if planned.trajectory.is_some() {
        parts.push(("trajectory", t.trajectory_s));
    }
    let parts: Vec<String> = parts
        .iter()
        .map(|(name, v)| format!("{name} {:.1} ms", v * 1e3))
        .collect();
    parts.join(", ")
}

/// How the plan is timed, by the rule of [`options`]: the timing flags where given,
/// else the file's trajectory section where it sets a value, else the flags' defaults
/// (the blending tuning, which has no flag: the file's or the default).
fn timing(
    a: &PlanArgs,
    file: Option<&Loaded>,
    given: &Given,
) -> Result<aerial_chain::trajectory::Settings, CliError> {
    let flags = a.timing.settings()?;
    let Some(f) = file else {
        return Ok(flags);
    };
    let mut t = f.file.trajectory;
    let flag = |id: &str, key: &str| given.contains(id) || !f.sets(&format!("trajectory.{key}"));
    if flag("speed", "limits.speed") {
        t.limits.speed = flags.limits.speed;
    }
    if flag("accel", "limits.accel") {
        t.limits.accel = flags.limits.accel;
    }
    if flag("angular_rate_deg", "limits.angular_rate") {
        t.limits.angular_rate = flags.limits.angular_rate;
    }
    if flag("angular_accel_deg", "limits.angular_accel") {
        t.limits.angular_accel = flags.limits.angular_accel;
    }
    if flag("yaw_rate_deg", "limits.yaw_rate") {
        t.limits.yaw_rate = flags.limits.yaw_rate;
    }
    if flag("yaw_accel_deg", "limits.yaw_accel") {
        t.limits.yaw_accel = flags.limits.yaw_accel;
    }
    if flag("dt", "dt") {
        t.dt = flags.dt;
    }
    if flag("no_blend", "blend") {
        t.blend = flags.blend;
    }
    Ok(t)
}

/// Runs `arc plan`.
pub fn run(a: PlanArgs, given: &Given) -> CliResult {
    check(&a)?;
    let file = read_settings(a.settings.as_ref())?;
    let options = options(&a, file.as_ref(), given)?;
    let timing = timing(&a, file.as_ref(), given)?;
    if let Some(path) = &a.mission {
        return mission::run(&a, path, &options, &timing);
    }
    // Setup (map, distance field, shape tables) is timed apart: the time limit
    // covers what follows it (docs/promises.md).
    let setup = Instant::now();
    let (loaded, params, query) = a.problem.load()?;
    let map = MapSection::of(&loaded.grid).with_source(loaded.source.clone());
    let pose = a.pose.pose(&params)?;
    let request = Request {
        field: Arc::new(DistanceField::new(loaded.grid)),
        params,
        query,
        pose,
        map,
    };
    let tables = load_tables(a.tables.as_ref(), params, a.srs, a.srs_seed)?;
    let loading_s = setup.elapsed().as_secs_f64();
    let planned = planning::plan(&request, Some(tables), &options).map_err(|e| match e {
        PlanningError::NoPlan(mut n) => {
            n.setup_s += loading_s;
            CliError::failed(n.to_string())
        }
        e if e.is_input() => CliError::input(e.to_string()),
        e => CliError::failed(e.to_string()),
    })?;
    let setup_s = loading_s + planned.timings.setup_s;
    let plan = &planned.plan;
    let s = &planned.stats;
    let details = format!(
        "{} head edges, {} shape changes ({} LSC, {} SRS, {} yaw rotations, {} follow), {} replans",
        s.edges, s.shape_changes, s.lsc_uses, s.srs_uses, s.rotations, s.follow_uses, s.replans
    );
    let report = write_plan(plan, &a.out, "solved on", &a.problem.map, &details)?;
    report.line(format_args!(
        "  setup {:.1} ms, search structures {:.1} ms (free regions {:.1} ms, uniform roadmap of {} vertices), planning {:.1} ms ({:.1} ms in {} collision checks)",
        setup_s * 1e3,
        s.timings.roadmap_s * 1e3,
        s.regions_s * 1e3,
        s.roadmap_vertices,
        s.timings.planning_s * 1e3,
        s.timings.collision_s * 1e3,
        s.collision_checks
    ));
    report.line(format_args!("  phases: {}", phases(setup_s, &planned)));
    print_quality(&report, &planned.quality, planned.refinement.as_ref());
    match s.min_margin_at {
        Some(p) => report.line(format_args!(
            "  smallest clearance margin kept: {:.3} m (below --clearance {:.3} m from ({:.2}, {:.2}, {:.2}) on)",
            s.min_margin, a.clearance, p[0], p[1], p[2]
        )),
        None => report.line(format_args!("  smallest clearance margin kept: {:.3} m", s.min_margin)),
    }
    if s.route_points > 0 {
        report.line(format_args!(
            "  head route: {} points ({} lattice points expanded, {:.1} ms)",
            s.route_points,
            s.lattice_expanded,
            s.lattice_s * 1e3
        ));
    }
    let grid = request.grid();
    let mut timed = None;
    if let (Some(path), Some(made)) = (&a.trajectory, planned.trajectory) {
        let tr = made.map_err(|e| super::trajectory::refused(e, "the plan"))?;
        super::trajectory::write(&tr, plan, path, &report)?;
        report.line(format_args!(
            "  trajectory made and checked in {:.1} ms",
            planned.timings.trajectory_s * 1e3
        ));
        timed = Some(tr);
    }
    if let Some(pic) = &a.picture {
        let goal = Some((query.goal, query.goal_tol));
        match draw(&a, pic, grid, plan, timed, goal, &timing)? {
            Some((frames, step)) => report.line(format_args!(
                "  animation: {} ({frames} frames, one per {step} s of the trajectory)",
                pic.display()
            )),
            None => report.line(format_args!("  picture: {}", pic.display())),
        }
    }
    Ok(())
}

/// Draws the plan's picture, or animates its trajectory (made here unless given) and
/// says how many frames at what step; a still picture is coloured by the
/// trajectory's time where there is one.
fn draw(
    a: &PlanArgs,
    pic: &std::path::Path,
    grid: &aerial_chain::map::Grid,
    plan: &aerial_chain::plan_file::Plan,
    timed: Option<aerial_chain::trajectory::Trajectory>,
    goal: Option<(nalgebra::Point3<f64>, f64)>,
    timing: &aerial_chain::trajectory::Settings,
) -> Result<Option<(usize, f64)>, CliError> {
    use aerial_chain::plan_picture::{self as pp, AnimationOptions, Motion, PictureOptions};
    let title = format!("ARCplanner on {}", a.problem.map.name());
    if super::picture::is_animation(pic) {
        let tr = match timed {
            Some(t) => t,
            None => super::trajectory::make(plan, "the plan", grid, timing)?,
        };
        let opts = AnimationOptions {
            title,
            goal,
            step: a.frame_step,
            planned_label: "head path (plan)".into(),
        };
        let made = super::picture::write_animation(pic, grid, &Motion::of_trajectory(&tr), &opts)?;
        return Ok(Some(made));
    }
    // Without an admissible trajectory the picture still comes, its ramp in waypoint order.
    let tr = timed.or_else(|| aerial_chain::trajectory::build(plan, grid, timing).ok());
    let opts = PictureOptions {
        title,
        goal,
        times: tr.map(|t| pp::waypoint_times(plan, &t)),
    };
    pp::draw(grid, plan, &opts)
        .save(pic)
        .map_err(|e| CliError::input(e.to_string()))?;
    Ok(None)
}

/// Prints the plan's quality, and what refinement changed.
fn print_quality(report: &Report, q: &Quality, refinement: Option<&Refinement>) {
    report.line(format_args!(
        "  head path {:.2} m, {} shape changes, shape motion {:.2} rad (sum of C_T {:.2})",
        q.head_path_m, q.shape_changes, q.shape_motion_rad, q.shape_cost
    ));
    if let Some(r) = refinement {
        report.line(format_args!(
            "  refined in {:.1} ms ({} checks) from: head path {:.2} m, {} shape changes, shape motion {:.2} rad",
            r.time_s * 1e3,
            r.checks,
            r.before.head_path_m,
            r.before.shape_changes,
            r.before.shape_motion_rad
        ));
        let w = &r.widening;
        if w.before < aerial_chain::planner::WIDEN_CAP {
            report.line(format_args!(
                "  narrowest unit clearance {:.3} m as searched, {:.3} m post-processed ({} widening moves)",
                w.before, w.after, w.moves
            ));
        }
        if r.threaded {
            report.line(format_args!(
                "  threaded: the chain follows its head along the route, straightened through the middle of each passage"
            ));
        }
        if !r.carried.is_empty() {
            let stretches: Vec<String> = r
                .carried
                .iter()
                .map(|c| format!("{:.2} m in {}", c.head_path_m, c.kind.name()))
                .collect();
            report.line(format_args!(
                "  carried: the chain flies {} of head path, each stretch in one shape on a route of its own",
                stretches.join(", ")
            ));
        }
        print_stages(report, &r.stages);
    }
}

/// Prints what each stage of post-processing did, in the order they are declared.
fn print_stages(report: &Report, stages: &[StageReport]) {
    report.line(format_args!(
        "  post-processing stages (lane stage: time, budget used of limit, then head path, shape motion, narrowest unit clearance):"
    ));
    for s in stages {
        let b = &s.budget;
        let budget = match b.unit {
            Unit::Nothing => String::from("no budget"),
            u => format!("{} of {} {}", b.used, b.limit, u.name()),
        };
        let effect = match &s.effect {
            None => String::from("gave no plan"),
            Some(e) => format!(
                "{:.2} m, {:.2} rad, {}",
                e.head_path_m,
                e.shape_motion_rad,
                e.narrowest_m
                    .map_or(String::from("not measured"), |n| format!("{n:.3} m"))
            ),
        };
        let taken = s.taken.map_or(String::new(), |l| format!(", kept {l}"));
        let stage = match s.lane.as_str() {
            "" => s.name.to_string(),
            lane => format!("{lane} {}", s.name),
        };
        report.line(format_args!(
            "    {stage}: {:.1} ms, {budget}{taken}; {effect}",
            s.time_s * 1e3
        ));
    }
}
