//! `arc bench`: the paper's evaluation, the scaling study, and single full-state PRM plans.

mod prm;

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::{Args, Subcommand};

use super::checks;
use super::{CliError, CliResult};
use crate::study::paper::PaperOptions;
use crate::study::scale::ScaleOptions;
use crate::study::{self, paper, robust, scale, Budgets, RunResult, RunSpec, Summary};
use aerial_chain::sensing::DepthSensor;
use prm::{run_prm, PrmArgs};

/// `arc bench ...`
#[derive(Subcommand, Debug)]
pub enum BenchCommand {
    /// The paper's Tables 1-3 (window, maze; LSC / SRS / both; full-state PRM), paper
    /// numbers beside ours; markdown on stdout, CSV and markdown in --out-dir.
    #[command(after_help = "Example:\n  arc bench paper --quick --out-dir out/paper")]
    Paper(PaperArgs),
    /// Planning time and success against N (window, N = 3..16) and map size
    /// (corridor:10..100), with a plot (SVG and PNG).
    #[command(after_help = "Example:\n  arc bench scale --quick --out-dir out/scale")]
    Scale(ScaleArgs),
    /// Robustness on the hard-case family (`passage:`): random instances with
    /// witnesses, N = 4..8, `arc plan`'s defaults; CSV, markdown and a plot.
    Robust(RobustArgs),
    /// Flight time of the planner's plans (window, maze, silos, corridor; N = 4..6;
    /// a sample of the robust family): stopping at every waypoint against the blended trajectory, simulated; CSV,
    /// markdown and a plot of flight time against head path / speed.
    #[command(after_help = "Example:\n  arc bench flight --seeds 2 --out-dir out/flight")]
    Flight(FlightArgs),
    /// Flying into the unknown from an empty map (`arc explore`'s defaults; window,
    /// maze, silos, corridor, N = 4..6, and a sample of the robust family), against the
    /// finished-map flight of the same query; CSV, markdown and a plot.
    #[command(
        after_help = "Example:\n  RAYON_NUM_THREADS=2 arc bench online --out-dir docs/bench"
    )]
    Online(OnlineArgs),
    /// The time limit's promise: `arc plan --trajectory --time-limit T` on every
    /// built-in scenario and a sample of the hard-case family, T = 1, 10 and 50 ms by
    /// default; time after setup against 1.1 T + 50 ms; CSV and markdown.
    #[command(after_help = "Example:\n  arc bench limit --robust 50 --out-dir docs/bench")]
    Limit(LimitArgs),
    /// Refusals: slits narrower than a unit and sealed windows at 0.025-0.1 m, and the
    /// large maps with their goals walled in, N = 4, 6, 8, `arc plan`'s defaults; time
    /// after setup against 1 s; CSV and markdown.
    #[command(after_help = "Example:\n  arc bench refuse --out-dir docs/bench")]
    Refuse(RefuseArgs),
    /// The forest, tilted-slot and pipe families (`forest:`, `slot:`, `pipe:`): random
    /// forests at N = 5..8 and slots at N = 4..6, 24 pipes at N = 4, 6, 8, `arc plan`'s
    /// defaults; plans verified, query time after setup, pipe clearance against the
    /// witness's; CSV and markdown.
    #[command(after_help = "Example:\n  arc bench families --instances 12 --out-dir docs/bench")]
    Families(FamiliesArgs),
    /// One plan by the full-state lazy PRM baseline (arc-plan/1, verified exactly).
    #[command(
        after_help = "Example:\n  arc bench prm --scenario window --units 4 --vertices 15000 --out prm.json"
    )]
    Prm(Box<PrmArgs>),
}

/// Options shared by the studies.
#[derive(Args, Debug)]
pub struct StudyArgs {
    /// Smoke run: few seeds, small budgets, short time limits (seconds in all).
    #[arg(long)]
    quick: bool,
    /// Seeds per configuration (default: 20, or the quick run's).
    #[arg(long)]
    seeds: Option<u64>,
    /// Time limit per run in seconds; 0 for none (default: 60, or 2 with --quick).
    #[arg(long)]
    time_limit: Option<f64>,
    /// Where CSV, markdown and plots go.
    #[arg(long, default_value = "bench-out")]
    out_dir: PathBuf,
    /// Worker threads (default: RAYON_NUM_THREADS, else every core).
    #[arg(long)]
    threads: Option<usize>,
    /// Head roadmap vertices M_VT (default 1500, quick 300).
    #[arg(long)]
    vertices: Option<usize>,
    /// Random shapes N_SRS (default 500, quick 100).
    #[arg(long)]
    srs: Option<usize>,
}

/// `arc bench paper`
#[derive(Args, Debug)]
pub struct PaperArgs {
    #[command(flatten)]
    study: StudyArgs,
    /// Vertex budgets M_F of the full-state PRM, comma-separated (default 1500,15000).
    #[arg(long, value_delimiter = ',')]
    prm_vertices: Option<Vec<usize>>,
    /// Chain sizes of Table 3, comma-separated (default 5).
    #[arg(long, value_delimiter = ',')]
    prm_units: Option<Vec<u8>>,
    /// Tables to run, comma-separated (default 1,2,3).
    #[arg(long, value_delimiter = ',')]
    tables: Option<Vec<u8>>,
    /// Openings (m) of the widened-window variants of Table 3, where the full-state PRM
    /// can pass, comma-separated; 0 for none (default 1.0,1.2,1.4,1.6).
    #[arg(long, value_delimiter = ',')]
    wide_window: Option<Vec<f64>>,
}

/// `arc bench scale`
#[derive(Args, Debug)]
pub struct ScaleArgs {
    #[command(flatten)]
    study: StudyArgs,
    /// Chain sizes in window, comma-separated (default 3..16).
    #[arg(long, value_delimiter = ',')]
    units: Option<Vec<u8>>,
    /// Corridor lengths in metres, comma-separated (default 10,20,...,100).
    #[arg(long, value_delimiter = ',')]
    lengths: Option<Vec<f64>>,
    /// Head roadmap vertices per metre of corridor; 0 for --vertices at every length
    /// (default 100).
    #[arg(long)]
    corridor_density: Option<f64>,
}

/// `arc bench robust`
#[derive(Args, Debug)]
pub struct RobustArgs {
    /// Instances.
    #[arg(long, default_value_t = 200)]
    instances: usize,
    /// Seed of the instance generator.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Time limit per query in seconds; 0 for none.
    #[arg(long, default_value_t = 30.0)]
    time_limit: f64,
    /// Where CSV, markdown and the plot go.
    #[arg(long, default_value = "bench-out")]
    out_dir: PathBuf,
    /// Worker threads (default: RAYON_NUM_THREADS, else every core).
    #[arg(long)]
    threads: Option<usize>,
    /// Draw instances of an opening, then a turn (a door 1-3 m on and 1-3 m to the
    /// side); the files are named turns* instead of robust*.
    #[arg(long)]
    turns: bool,
}

/// The runs of `arc bench flight` and `arc bench online`: scenarios times chain sizes,
/// and the first instances of the robust family.
#[derive(Args, Debug)]
pub struct Runs {
    /// Scenarios, comma-separated.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "window,maze,silos,corridor"
    )]
    scenarios: Vec<String>,
    /// Chain sizes, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "4,5,6")]
    units: Vec<u8>,
    /// Also run this many instances of `arc bench robust`'s family (its first ones,
    /// each with its own N and planner seed); 0: none.
    #[arg(long, default_value_t = 20)]
    robust: usize,
}

impl Runs {
    /// Checks the sizes, the scenarios and the instance count.
    fn check(&self) -> CliResult {
        for n in &self.units {
            checks::count("--units", *n as usize, 2, 16, "units")?;
        }
        for s in &self.scenarios {
            aerial_chain::problem::scenarios::build(s)
                .map_err(|e| CliError::input(e.to_string()))?;
        }
        checks::count("--robust", self.robust, 0, 200, "instances")
    }
}

/// `arc bench flight`
#[derive(Args, Debug)]
pub struct FlightArgs {
    #[command(flatten)]
    runs: Runs,
    /// Seeds per scenario and size (1, 2, ...).
    #[arg(long, default_value_t = 2)]
    seeds: u64,
    /// Where CSV, markdown and the plot go.
    #[arg(long, default_value = "bench-out")]
    out_dir: PathBuf,
}

/// `arc bench online`
#[derive(Args, Debug)]
pub struct OnlineArgs {
    #[command(flatten)]
    runs: Runs,
    /// Simulated seconds an exploration may take.
    #[arg(long, default_value_t = 600.0)]
    time_limit: f64,
    /// The units' sensor settings (JSON, as `arc explore --sensor`); default the
    /// default sensor.
    #[arg(long)]
    sensor: Option<PathBuf>,
    /// Where CSV, markdown and the plot go.
    #[arg(long, default_value = "bench-out")]
    out_dir: PathBuf,
}

/// `arc bench families`
#[derive(Args, Debug)]
pub struct FamiliesArgs {
    /// Forests and slots drawn, 1 to 1000 (the 24 pipes are fixed).
    #[arg(long, default_value_t = 12)]
    instances: usize,
    /// Seed of the instance generator.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Where CSV and markdown go.
    #[arg(long, default_value = "bench-out")]
    out_dir: PathBuf,
}

/// `arc bench refuse`
#[derive(Args, Debug)]
pub struct RefuseArgs {
    /// Where CSV and markdown go.
    #[arg(long, default_value = "bench-out")]
    out_dir: PathBuf,
}

/// Hard-case instances `arc bench limit` draws at most: each is built, witnessed and
/// planned at every limit.
const MAX_LIMIT_INSTANCES: usize = 1000;

/// `arc bench limit`
#[derive(Args, Debug)]
pub struct LimitArgs {
    /// Time limits to try (ms), comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "1,10,50")]
    limits_ms: Vec<f64>,
    /// Built-in scenarios, each at its default N (default: all of them).
    #[arg(long, value_delimiter = ',')]
    scenarios: Option<Vec<String>>,
    /// Instances of the hard-case family (`arc bench robust`'s first ones), at most
    /// 1000.
    #[arg(long, default_value_t = 50)]
    robust: usize,
    /// Where CSV and markdown go.
    #[arg(long, default_value = "bench-out")]
    out_dir: PathBuf,
}

/// Most seeds per configuration of a study: every run is held in memory.
const MAX_SEEDS: u64 = 100_000;

/// Most worker threads of a study.
const MAX_THREADS: usize = 1024;

fn check_study(a: &StudyArgs) -> Result<(), CliError> {
    if let Some(s) = a.seeds {
        if !(1..=MAX_SEEDS).contains(&s) {
            return Err(checks::bad(
                "--seeds",
                s,
                &format!("between 1 and {MAX_SEEDS} (every run is kept in memory)"),
            ));
        }
    }
    if let Some(t) = a.time_limit {
        // 0 means none here.
        if t != 0.0 {
            checks::time_limit(Some(t))?;
        }
    }
    if let Some(t) = a.threads {
        checks::count("--threads", t, 1, MAX_THREADS, "worker threads")?;
    }
    if let Some(v) = a.vertices {
        checks::count(
            "--vertices",
            v,
            1,
            checks::MAX_HEAD_VERTICES >> 3,
            "a run's roadmap may grow to 8 times this",
        )?;
    }
    if let Some(s) = a.srs {
        checks::count(
            "--srs",
            s,
            0,
            u16::MAX as usize,
            "the table's index is 16 bits",
        )?;
    }
    Ok(())
}

/// A study's defaults: its smoke run's with `--quick`, else the full study's.
fn defaults<O>(a: &StudyArgs, quick: fn() -> O, full: fn() -> O) -> O {
    if a.quick {
        quick()
    } else {
        full()
    }
}

/// The study's budgets: `base`, with what the command line sets instead (a time limit
/// of 0: none).
fn budgets(a: &StudyArgs, base: Budgets) -> Budgets {
    Budgets {
        seeds: a.seeds.unwrap_or(base.seeds),
        vertices: a.vertices.unwrap_or(base.vertices),
        srs: a.srs.unwrap_or(base.srs),
        time_limit: match a.time_limit {
            Some(0.0) => None,
            Some(t) => Some(t),
            None => base.time_limit,
        },
    }
}

fn meta(a: &StudyArgs, runs: usize) -> String {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into());
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let threads = a
        .threads
        .or_else(|| {
            std::env::var("RAYON_NUM_THREADS")
                .ok()
                .and_then(|v| v.parse().ok())
        })
        .unwrap_or(cores);
    format!(
        "`arc bench` {} ({} runs; {} worker threads on {} cores, {cpu}; {} build).",
        if a.quick { "--quick" } else { "full" },
        runs,
        threads,
        cores,
        if cfg!(debug_assertions) {
            "debug"
        } else {
            "release"
        }
    )
}

/// Runs a study's `specs` (`what` names it in the progress display) and groups the
/// results; also gives the report's header line, with the study's wall time.
fn run_study(
    a: &StudyArgs,
    specs: &[RunSpec],
    what: &str,
) -> Result<(Vec<RunResult>, Vec<Summary>, String), CliError> {
    let envs = study::Envs::for_specs(specs)?;
    let t = Instant::now();
    let results = study::run_all(&envs, specs, a.threads, what, true)?;
    let sums = study::summarize(&results);
    let header = format!(
        "{} Wall time of the whole study: {:.0} s.",
        meta(a, specs.len()),
        t.elapsed().as_secs_f64()
    );
    Ok((results, sums, header))
}

/// Writes each `(name, bytes)` of `files` into `dir`, then prints the report `md` and
/// where every file went.
fn publish(dir: &Path, md: &str, files: &[(&str, &[u8])]) -> CliResult {
    let mut written = Vec::new();
    for (name, bytes) in files {
        written.push(study::write_out(dir, name, bytes)?);
    }
    println!("{md}");
    for f in written {
        println!("wrote {}", f.display());
    }
    Ok(())
}

fn run_paper(a: PaperArgs) -> CliResult {
    check_study(&a.study)?;
    let base = defaults(&a.study, PaperOptions::quick, PaperOptions::full);
    let o = PaperOptions {
        budgets: budgets(&a.study, base.budgets),
        prm_vertices: a.prm_vertices.clone().unwrap_or(base.prm_vertices),
        prm_units: a.prm_units.clone().unwrap_or(base.prm_units),
        tables: a.tables.clone().unwrap_or(base.tables),
        wide_windows: match &a.wide_window {
            Some(v) if v.as_slice() == [0.0] => Vec::new(),
            Some(v) => v.clone(),
            None => base.wide_windows,
        },
    };
    for &w in &o.wide_windows {
        if !(0.8..=2.4).contains(&w) {
            return Err(CliError::input(format!(
                "--wide-window {w}: every opening must be 0.8 to 2.4 m (or 0 alone for none)"
            )));
        }
    }
    if let Some(t) = o.tables.iter().find(|t| !(1..=3).contains(*t)) {
        return Err(CliError::input(format!(
            "--tables {t}: tables are 1, 2 and 3"
        )));
    }
    for &v in &o.prm_vertices {
        checks::count(
            "--prm-vertices",
            v,
            1,
            checks::MAX_PRM_VERTICES,
            "each holds a full configuration and its edges",
        )?;
    }
    if let Some(n) = o.prm_units.iter().find(|n| !(2..=16).contains(*n)) {
        return Err(CliError::input(format!(
            "--prm-units {n}: must be within 2..=16"
        )));
    }
    let specs = paper::specs(&o);
    let (results, sums, header) = run_study(&a.study, &specs, "arc bench paper")?;
    let md = paper::markdown(&sums, &o, &header);
    let (runs, summary) = (study::runs_csv(&results), study::summary_csv(&sums));
    let files: [(&str, &[u8]); 3] = [
        ("paper_runs.csv", runs.as_bytes()),
        ("paper_summary.csv", summary.as_bytes()),
        ("paper.md", md.as_bytes()),
    ];
    publish(&a.study.out_dir, &md, &files)
}

fn run_scale(a: ScaleArgs) -> CliResult {
    check_study(&a.study)?;
    let base = defaults(&a.study, ScaleOptions::quick, ScaleOptions::full);
    let o = ScaleOptions {
        budgets: budgets(&a.study, base.budgets),
        units: a.units.clone().unwrap_or(base.units),
        lengths: a.lengths.clone().unwrap_or(base.lengths),
        corridor_units: base.corridor_units,
        corridor_vertices_per_m: match a.corridor_density {
            Some(0.0) => None,
            Some(d) => Some(d),
            None => base.corridor_vertices_per_m,
        },
    };
    if let Some(n) = o.units.iter().find(|n| !(2..=16).contains(*n)) {
        return Err(CliError::input(format!(
            "--units {n}: must be within 2..=16"
        )));
    }
    if let Some(d) = o.corridor_vertices_per_m {
        // The longest corridor is 100 m.
        let most = (checks::MAX_HEAD_VERTICES >> 3) as f64 / 100.0;
        if !(d.is_finite() && d > 0.0 && d <= most) {
            return Err(checks::bad(
                "--corridor-density",
                d,
                &format!(
                    "a positive number of vertices per metre up to {most} (or 0 for --vertices)"
                ),
            ));
        }
    }
    let (specs, starts) = scale::specs(&o)?;
    let (results, sums, header) = run_study(&a.study, &specs, "arc bench scale")?;
    let md = scale::markdown(&sums, &results, &o, &starts, &header);
    let svg = scale::figure(&sums, o.corridor_units);
    let png =
        aerial_chain::picture::rasterise(&svg).map_err(|e| CliError::failed(e.to_string()))?;
    let (runs, summary) = (study::runs_csv(&results), study::summary_csv(&sums));
    let files: [(&str, &[u8]); 5] = [
        ("scale_runs.csv", runs.as_bytes()),
        ("scale_summary.csv", summary.as_bytes()),
        ("scale.md", md.as_bytes()),
        ("scale.svg", svg.as_bytes()),
        ("scale.png", &png),
    ];
    publish(&a.study.out_dir, &md, &files)
}

fn run_robust(a: RobustArgs) -> CliResult {
    if a.instances == 0 {
        return Err(CliError::input("--instances 0: must be at least 1"));
    }
    if !(a.time_limit.is_finite() && a.time_limit >= 0.0) {
        return Err(CliError::input(format!(
            "--time-limit {}: must be a number of seconds >= 0",
            a.time_limit
        )));
    }
    let family = match a.turns {
        true => robust::Family::Turns,
        false => robust::Family::Openings,
    };
    let o = robust::RobustOptions {
        family,
        instances: a.instances,
        seed: a.seed,
        time_limit: (a.time_limit > 0.0).then_some(a.time_limit),
        ..robust::RobustOptions::full()
    };
    let t = Instant::now();
    let (specs, redrawn) = robust::draw(&o);
    eprintln!(
        "arc bench {}: {} instances with witnesses ({redrawn} redrawn) in {:.0} s",
        family.stem(),
        specs.len(),
        t.elapsed().as_secs_f64()
    );
    let results = robust::run(&specs, a.threads, 10)?;
    let md = robust::markdown(
        &results,
        family,
        redrawn,
        &format!(
            "Seed {}, {} instances; wall time of the whole study {:.0} s.",
            a.seed,
            specs.len(),
            t.elapsed().as_secs_f64()
        ),
    );
    let svg = robust::figure(&results);
    let runs = study::runs_csv(&results);
    publish_runs(&a.out_dir, family.stem(), &md, &runs, Some(&svg))
}

fn run_flight(a: FlightArgs) -> CliResult {
    checks::count("--seeds", a.seeds as usize, 1, 1000, "seeds")?;
    a.runs.check()?;
    let speed = aerial_chain::trajectory::Limits::default().speed;
    let t = Instant::now();
    let mut jobs = Vec::new();
    for sc in &a.runs.scenarios {
        for &n in &a.runs.units {
            jobs.extend((1..=a.seeds).map(|seed| (sc.clone(), n, seed)));
        }
    }
    jobs.extend(study::flight::robust_sample(a.runs.robust));
    let mut runs = Vec::new();
    for (sc, n, seed) in jobs {
        let r = study::flight::run_one(&sc, n, seed);
        eprintln!(
            "{sc} N = {n} seed {seed}: path {:.1} m, stop-go {:.1} s, trajectory {:.1} s ({} of {} corners blended, {} merged, made in {:.0} ms){}",
            r.head_path_m,
            r.before.map_or(f64::NAN, |f| f.time_s),
            r.after.map_or(f64::NAN, |f| f.time_s),
            r.blended,
            r.corners,
            r.merged,
            r.trajectory_s * 1e3,
            if r.error.is_empty() { String::new() } else { format!(": {}", r.error) }
        );
        runs.push(r);
    }
    let robust = match a.runs.robust {
        0 => String::new(),
        k => format!(" (the robust family: over its first {k} instances, N = 4..8 as drawn)"),
    };
    let md = format!(
        "{}\nMedians over seeds 1..={}{robust}; flight time from the start of the flight (1 s hold included) to arrival; {} build; whole study {:.0} s.\n",
        study::flight::markdown(&runs, speed),
        a.seeds,
        if cfg!(debug_assertions) { "debug" } else { "release" },
        t.elapsed().as_secs_f64()
    );
    let csv = study::flight::csv(&runs, speed);
    let svg = study::flight::figure(&runs, speed);
    publish_runs(&a.out_dir, "flight", &md, &csv, Some(&svg))
}

fn run_families(a: FamiliesArgs) -> CliResult {
    if !(1..=MAX_LIMIT_INSTANCES).contains(&a.instances) {
        return Err(checks::bad("--instances", a.instances, "1 to 1000"));
    }
    let began = Instant::now();
    let runs = study::families::run(a.instances, a.seed)?;
    let what = format!(
        "`arc plan`'s defaults through the library's facade, {} forests and {} slots (seed {}) and the 24 pipes",
        a.instances, a.instances, a.seed
    );
    let md = study_page(&study::families::markdown(&runs), &what, began);
    publish_runs(
        &a.out_dir,
        "families",
        &md,
        &study::families::csv(&runs),
        None,
    )
}

/// A study's markdown page: its table, then what ran, the build, the worker threads
/// and how long the whole study took.
fn study_page(table: &str, what: &str, began: Instant) -> String {
    format!(
        "{table}\n{what}; {} build, {} worker threads; whole study {:.0} s.\n",
        if cfg!(debug_assertions) {
            "debug"
        } else {
            "release"
        },
        std::env::var("RAYON_NUM_THREADS").unwrap_or_else(|_| "every core's".into()),
        began.elapsed().as_secs_f64()
    )
}

/// Publishes a study's runs `{stem}_runs.csv`, its page `{stem}.md` (also printed)
/// and, for a study that draws one, its figure `{stem}.svg`.
fn publish_runs(dir: &Path, stem: &str, md: &str, csv: &str, svg: Option<&str>) -> CliResult {
    let names = ["_runs.csv", ".md", ".svg"].map(|end| format!("{stem}{end}"));
    let mut files: Vec<(&str, &[u8])> =
        vec![(&names[0], csv.as_bytes()), (&names[1], md.as_bytes())];
    files.extend(svg.map(|svg| (names[2].as_str(), svg.as_bytes())));
    publish(dir, md, &files)
}

fn run_refuse(a: RefuseArgs) -> CliResult {
    let began = Instant::now();
    let runs = study::refuse::run()?;
    let what = "`arc plan`'s defaults through the library's facade";
    let md = study_page(&study::refuse::markdown(&runs), what, began);
    publish_runs(&a.out_dir, "refuse", &md, &study::refuse::csv(&runs), None)
}

fn run_limit(a: LimitArgs) -> CliResult {
    for &t in &a.limits_ms {
        if !(t > 0.0 && t <= 1e6) {
            return Err(checks::bad(
                "--limits-ms",
                t,
                "positive milliseconds, at most 1e6",
            ));
        }
    }
    if a.robust > MAX_LIMIT_INSTANCES {
        return Err(checks::bad(
            "--robust",
            a.robust,
            "at most 1000 (each instance is drawn, witnessed and planned at every limit)",
        ));
    }
    let began = Instant::now();
    let names = a
        .scenarios
        .unwrap_or_else(|| study::limit::BUILT_IN.map(String::from).to_vec());
    let mut jobs = Vec::new();
    for name in names {
        let units = aerial_chain::problem::scenarios::build(&name)
            .map_err(|e| CliError::input(format!("--scenarios: {e}")))?
            .default_units;
        jobs.push((name, units));
    }
    jobs.extend(
        study::flight::robust_sample(a.robust)
            .into_iter()
            .map(|(sc, n, _)| (sc, n)),
    );
    let limits: Vec<f64> = a.limits_ms.iter().map(|t| t / 1e3).collect();
    let runs = study::limit::run(&jobs, &limits)?;
    let what = format!(
        "`arc plan --trajectory --time-limit T`'s defaults through the library's facade, {} queries a limit",
        jobs.len()
    );
    let md = study_page(&study::limit::markdown(&runs), &what, began);
    publish_runs(&a.out_dir, "limit", &md, &study::limit::csv(&runs), None)
}

/// The sensor settings of `--sensor`'s file (validated), or the default sensor.
fn online_sensor(path: Option<&Path>) -> Result<DepthSensor, CliError> {
    let Some(p) = path else {
        return Ok(DepthSensor::default());
    };
    let sensor = super::explore::sensor_file(p)?;
    sensor
        .validate()
        .map_err(|e| CliError::input(format!("{}: {e}", p.display())))?;
    Ok(sensor)
}

fn run_online(a: OnlineArgs) -> CliResult {
    a.runs.check()?;
    if !(a.time_limit > 0.0 && a.time_limit <= 86_400.0) {
        return Err(checks::bad(
            "--time-limit",
            a.time_limit,
            "a positive number of simulated seconds, at most 86400",
        ));
    }
    let sensor = online_sensor(a.sensor.as_deref())?;
    let t = Instant::now();
    let mut jobs: Vec<(String, u8)> = Vec::new();
    for sc in &a.runs.scenarios {
        jobs.extend(a.runs.units.iter().map(|&n| (sc.clone(), n)));
    }
    jobs.extend(
        study::flight::robust_sample(a.runs.robust)
            .into_iter()
            .map(|(sc, n, _)| (sc, n)),
    );
    let mut runs = Vec::new();
    for (sc, n) in jobs {
        let r = study::online::run_one(&sc, n, a.time_limit, &sensor);
        eprintln!(
            "{sc} N = {n}: {} in {:.1} s (finished map {:.1} s), {} replans, p95 {:.1} ms, max {:.1} ms",
            r.end,
            r.time_s,
            r.finished_s,
            r.replans,
            r.latency_s[1] * 1e3,
            r.latency_s[2] * 1e3
        );
        runs.push(r);
    }
    let md = format!(
        "{}\n`arc explore`'s defaults from an empty map{}; the finished-map flight is `arc bench flight`'s trajectory flight of the same query (seed 1); {} build, {} worker threads; whole study {:.0} s.\n",
        study::online::markdown(&runs),
        a.sensor
            .as_ref()
            .map_or(String::new(), |p| format!(", the sensors of {}", p.display())),
        if cfg!(debug_assertions) { "debug" } else { "release" },
        std::env::var("RAYON_NUM_THREADS").unwrap_or_else(|_| "every core's".into()),
        t.elapsed().as_secs_f64()
    );
    let csv = study::online::csv(&runs);
    let svg = study::online::figure(&runs);
    publish_runs(&a.out_dir, "online", &md, &csv, Some(&svg))
}

/// Runs `arc bench ...`.
pub fn run(c: BenchCommand) -> CliResult {
    match c {
        BenchCommand::Paper(a) => run_paper(a),
        BenchCommand::Scale(a) => run_scale(a),
        BenchCommand::Robust(a) => run_robust(a),
        BenchCommand::Flight(a) => run_flight(a),
        BenchCommand::Online(a) => run_online(a),
        BenchCommand::Limit(a) => run_limit(a),
        BenchCommand::Refuse(a) => run_refuse(a),
        BenchCommand::Families(a) => run_families(a),
        BenchCommand::Prm(a) => run_prm(*a),
    }
}
