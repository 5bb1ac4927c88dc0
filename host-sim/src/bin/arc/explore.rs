//! `arc explore`: fly into the unknown. The world map is read only by the units'
//! simulated sensors; the online planner plans from what they saw and the simulated
//! chain flies what it commits (docs/online.md).

use std::path::{Path, PathBuf};

use clap::Args;

use super::checks;
use super::common::{ProblemArgs, Report};
use super::plan::{check_planner, load_tables, settings_text, Given};
use super::{CliError, CliResult};
use aerial_chain::flying::FlyOptions;
use aerial_chain::map::{Grid, OcTree};
use aerial_chain::online::{
    explore, Exploration, ExploreEnd, ExploreError, ExploreSettings, ExploreSettingsFile,
    OnlineSettings, StartFree,
};
use aerial_chain::plan_file::MapSection;
use aerial_chain::sensing::{DepthSensor, Survey};
use aerial_chain::sim::FlightFile;

/// `arc explore`
#[derive(Args, Debug)]
#[command(
    after_help = "Example:\n  arc explore --scenario maze --out flight.json --plan-out flown.json --map-out seen.bt"
)]
pub struct ExploreArgs {
    /// The world (--map WORLD.bt or --scenario), the chain, start and goal. The world
    /// is the truth only the sensors read; its box bounds the planner.
    #[command(flatten)]
    problem: ProblemArgs,
    /// Write the flight (`arc-sim/1`, with the record of every replan under
    /// `explore`).
    #[arg(long)]
    out: PathBuf,
    /// Write the committed pieces joined into one plan (`arc-plan/1`), for `arc
    /// verify` and `arc view`.
    #[arg(long)]
    plan_out: Option<PathBuf>,
    /// Write the map the sensors drew (.bt).
    #[arg(long)]
    map_out: Option<PathBuf>,
    /// A map known before the flight (.bt at the world's resolution): its known voxels
    /// count as seen.
    #[arg(long)]
    known: Option<PathBuf>,
    /// Give up after this many simulated seconds.
    #[arg(long, default_value_t = 600.0)]
    time_limit: f64,
    /// Wall time each replan may take (s).
    #[arg(long, default_value_t = aerial_chain::online::DEFAULT_DEADLINE_S)]
    deadline: f64,
    /// Clearance margin added to every body's radius while planning (m).
    #[arg(long, default_value_t = aerial_chain::collision::DEFAULT_CLEARANCE)]
    clearance: f64,
    /// What the start is taken to prove free before any sensor saw it: `hull`, every
    /// point within r_u plus the clearance of the chain's units and links (the start
    /// must have that much room; checked on the world), or `bodies`, only the bodies
    /// grown by the clearance (for a start next to an obstacle: a chain that moves
    /// along itself first turns to look at its hull).
    #[arg(long, value_enum, default_value_t = StartFree::Hull)]
    start_free: StartFree,
    /// Scans per second of every unit's sensor (Hz).
    #[arg(long, default_value_t = aerial_chain::sensing::survey::DEFAULT_RATE_HZ)]
    sensor_rate: f64,
    /// Every unit's depth sensor as JSON (fields of docs/maps.md "Sensing": fov_h_deg,
    /// fov_v_deg, min_range, max_range, resolution_deg, mount, splay_deg: the turn of
    /// the sensors after the head's, alternately left and right); fields left out keep
    /// their defaults.
    #[arg(long)]
    sensor: Option<PathBuf>,
    /// Sensor range (m), overriding the sensor file's.
    #[arg(long)]
    sensor_range: Option<f64>,
    /// Keep one recorded step in this many in the flight file.
    #[arg(long, default_value_t = 10)]
    record_every: usize,
    /// Tuning from a settings file (JSON; docs/settings.md lists every setting): its
    /// planner, refine and trajectory sections plan and time every piece, its online
    /// section sets deadline_s, route_period_s and start_free. A flag given on the
    /// command line wins over the file; a flag left at its default does not.
    #[arg(long)]
    settings: Option<PathBuf>,
}

/// Checks every option before any work.
fn check(a: &ExploreArgs) -> Result<(), CliError> {
    if !(a.time_limit > 0.0 && a.time_limit <= 86_400.0) {
        return Err(checks::bad(
            "--time-limit",
            a.time_limit,
            "a positive number of simulated seconds, at most 86400",
        ));
    }
    if !(a.deadline > 0.0 && a.deadline <= 60.0) {
        return Err(checks::bad(
            "--deadline",
            a.deadline,
            "a positive number of seconds, at most 60",
        ));
    }
    checks::length("--clearance", a.clearance, false)?;
    checks::length("--goal-tol", a.problem.goal_tol, true)?;
    checks::sensor_rate(a.sensor_rate)?;
    if let Some(r) = a.sensor_range {
        checks::length("--sensor-range", r, true)?;
    }
    if a.record_every == 0 {
        return Err(checks::bad("--record-every", 0, "at least 1"));
    }
    let bt = |flag: &str, p: &Option<PathBuf>| match p {
        Some(p) if !p.extension().is_some_and(|e| e.eq_ignore_ascii_case("bt")) => Err(
            CliError::input(format!("{flag} {}: an OctoMap .bt file", p.display())),
        ),
        _ => Ok(()),
    };
    bt("--map-out", &a.map_out)?;
    bt("--known", &a.known)
}

/// The sensor settings of JSON file `p` (`--sensor`), not yet validated.
pub fn sensor_file(p: &Path) -> Result<DepthSensor, CliError> {
    let text = std::fs::read_to_string(p)
        .map_err(|e| CliError::input(format!("{}: cannot read: {e}", p.display())))?;
    serde_json::from_str::<DepthSensor>(&text)
        .map_err(|e| CliError::input(format!("{}: {e}", p.display())))
}

/// The sensors: the file's, the range flag over it, at the rate flag's rate.
fn survey(a: &ExploreArgs) -> Result<Survey, CliError> {
    let mut sensor = match &a.sensor {
        Some(p) => sensor_file(p)?,
        None => DepthSensor::default(),
    };
    if let Some(r) = a.sensor_range {
        if r <= sensor.min_range {
            return Err(checks::bad(
                "--sensor-range",
                r,
                &format!("above the sensor's min_range ({} m)", sensor.min_range),
            ));
        }
        sensor.max_range = r;
    }
    let survey = Survey {
        sensor,
        rate_hz: a.sensor_rate,
    };
    survey.validate().map_err(|e| {
        let from = a
            .sensor
            .as_ref()
            .map_or("sensor".to_string(), |p| p.display().to_string());
        CliError::input(format!("{from}: {e}"))
    })?;
    Ok(survey)
}

/// The map known before the flight.
fn known(path: &Path, world: &Grid) -> Result<Grid, CliError> {
    let bytes = std::fs::read(path)
        .map_err(|e| CliError::input(format!("{}: cannot read the file: {e}", path.display())))?;
    let tree = OcTree::from_bt_bytes(&bytes, &path.display().to_string())
        .map_err(|e| CliError::input(e.to_string()))?;
    let grid = Grid::from_octree(&tree, true)
        .map_err(|e| CliError::input(format!("{}: {e}", path.display())))?;
    if grid.resolution() != world.resolution() {
        return Err(CliError::input(format!(
            "--known {}: resolution {} m, the world's is {} m",
            path.display(),
            grid.resolution(),
            world.resolution()
        )));
    }
    Ok(grid)
}

/// The online planner's settings: a flag given on the command line (`given`), else
/// the settings file (`--settings`) where it sets the value, else the default.
fn online(a: &ExploreArgs, given: &Given) -> Result<OnlineSettings, CliError> {
    let (file, name, keys) = match settings_text(a.settings.as_ref())? {
        Some((text, name, keys)) => {
            let file = ExploreSettingsFile::parse(&text, &name)
                .map_err(|e| CliError::input(e.to_string()))?;
            (file, Some(name), keys)
        }
        None => Default::default(),
    };
    let mut s = OnlineSettings::from_file(&file, a.clearance);
    let flag = |id: &str, key: &str| given.contains(id) || !keys.contains(&format!("online.{key}"));
    if flag("deadline", "deadline_s") {
        s.deadline_s = a.deadline;
    }
    if flag("start_free", "start_free") {
        s.start_free = a.start_free;
    }
    if let Some(name) = name {
        check_planner(&s.plan.planner, &|_, field| {
            format!("{name}: planner.{field}")
        })?;
    }
    Ok(s)
}

/// Runs `arc explore`: exit 0 when the chain reached the goal, 1 when it could not.
pub fn run(a: ExploreArgs, given: &Given) -> CliResult {
    check(&a)?;
    let online = online(&a, given)?;
    let survey = survey(&a)?;
    let (loaded, params, query) = a.problem.load()?;
    let truth = loaded.grid;
    let prior = a.known.as_ref().map(|p| known(p, &truth)).transpose()?;
    let tables = load_tables(None, params, online.plan.srs, online.plan.srs_seed)?;
    // The file's trajectory section times the pieces and the flight alike.
    let fly = FlyOptions {
        timing: online.trajectory,
        ..FlyOptions::default()
    };
    let settings = ExploreSettings {
        survey,
        online,
        fly,
        time_limit_s: a.time_limit,
        ..ExploreSettings::default()
    };
    let start = aerial_chain::plan_file::Waypoint::new(query.start.into(), &query.start_shape).zeta;
    let run = explore(
        &truth,
        params,
        tables,
        &start,
        query.goal,
        query.goal_tol,
        prior.as_ref(),
        &settings,
    )
    .map_err(|e| match e {
        ExploreError::Sim(e) => CliError::failed(e.to_string()),
        e => CliError::input(e.to_string()),
    })?;
    let report = Report::new(&a.out);
    write(&a, &run, &loaded.source, &truth, &report)?;
    say(&report, &a, &run);
    match &run.end {
        ExploreEnd::Reached { .. } if run.flight.report.contact => Err(CliError::failed(format!(
            "the chain touched the map ({})",
            run.flight
                .report
                .min_clearance_at
                .clone()
                .unwrap_or_default()
        ))),
        ExploreEnd::Reached { .. } => Ok(()),
        ExploreEnd::Sealed { t, why } => Err(CliError::failed(format!(
            "the goal cannot be reached (at {t:.2} s): {why}"
        ))),
        ExploreEnd::Stuck { t, why } => Err(CliError::failed(format!(
            "the chain is stuck (at {t:.2} s): {why}"
        ))),
        ExploreEnd::TimeLimit { t, tried } => Err(CliError::failed(format!(
            "the time limit of {t} simulated s ran out: {tried}"
        ))),
        ExploreEnd::FlightFailed { t, why } => Err(CliError::failed(format!("at {t:.2} s: {why}"))),
    }
}

/// Writes the flight, the joined plan and the seen map.
fn write(
    a: &ExploreArgs,
    run: &Exploration,
    source: &aerial_chain::plan_file::MapSource,
    truth: &Grid,
    report: &Report,
) -> CliResult {
    let mut file = FlightFile::new(
        &run.flight,
        "arc explore",
        &a.problem.map.name(),
        a.record_every,
    );
    let record = run.record();
    file.explore = Some(serde_json::to_value(&record).map_err(|e| CliError::input(e.to_string()))?);
    file.write(&a.out)
        .map_err(|e| CliError::input(e.to_string()))?;
    if let Some(p) = &a.plan_out {
        let mut plan = run.plan.clone();
        plan.map = MapSection::of(truth).with_source(source.clone());
        plan.write(p).map_err(|e| CliError::input(e.to_string()))?;
        report.line(format_args!(
            "  wrote {} (the committed pieces)",
            p.display()
        ));
    }
    if let Some(p) = &a.map_out {
        run.seen
            .write_bt(p)
            .map_err(|e| CliError::input(format!("{}: {e}", p.display())))?;
        report.line(format_args!("  wrote {} (the seen map)", p.display()));
    }
    Ok(())
}

/// The report: how it ended, the flight, the replans.
fn say(report: &Report, a: &ExploreArgs, run: &Exploration) {
    let r = &run.flight.report;
    let end = run.end.headline();
    report.line(format_args!(
        "{}: explored {} with N = {}: {end}",
        a.out.display(),
        a.problem.map.name(),
        r.units
    ));
    let s = run.record().summary;
    report.line(format_args!(
        "  {} replans, pieces committed: {}, latency median {:.1} ms, p95 {:.1} ms, max {:.1} ms",
        s.replans,
        run.pieces,
        s.latency_median_s * 1e3,
        s.latency_p95_s * 1e3,
        s.latency_max_s * 1e3
    ));
    report.line(format_args!(
        "  {} scans, {} voxels seen, field update median {:.2} ms per scan",
        run.sensing.scans,
        run.sensing.known,
        s.update_median_s * 1e3
    ));
    match r.min_clearance {
        Some(c) => report.line(format_args!(
            "  smallest clearance to the world at any step: {c:.4} m{}",
            if r.contact { " (contact)" } else { "" }
        )),
        None => report.line(format_args!("  clearance not measured")),
    }
}
