//! Benchmark runs: the paper's evaluation (Tables 1-3) and scaling studies, as
//! independent seeded runs spread over all cores.
//!
//! A run ([`RunSpec`]) is one planner on one query: the ARCplanner in one of its modes
//! ([`Method::Arc`]) or the full-state PRM baseline ([`Method::FullPrm`],
//! [`aerial_chain::baseline`]), on a built-in scenario, for one chain size, budget and seed.
//! Every run builds its own collision context (its own counters), its own shape tables
//! (SRS seeded with the run's seed) and its own roadmap (seeded with the run's seed),
//! so a run's outcome depends on its spec alone: [`run_all`] may spread runs over any
//! number of threads and returns the same results in the same order, timings aside
//! (and unless a run is cut by its time limit, which depends on the machine's speed).
//! Successful plans are checked with the exact verifier
//! ([`aerial_chain::collision::verify_plan`]).
//!
//! Times are wall-clock per run. With several runs in parallel on a loaded machine they
//! include some contention; both planners of a study run in the same batch, so their
//! ratio is fair.

mod error;
pub mod families;
pub mod flight;
pub mod limit;
pub mod online;
pub mod paper;
pub mod plot;
pub mod refuse;
mod report;
pub mod robust;
pub mod scale;
mod spec;
mod statistics;

pub use error::StudyError;
pub use report::{fmt_ms, ms, runs_csv, summary_csv, write_out};
pub use spec::{ArcMode, Budgets, Method, RunKey, RunSpec};
pub use statistics::{summarize, Spread, Summary};

use std::collections::BTreeMap;
use std::io::IsTerminal;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use aerial_chain_core::lsc::{library, LscKind};
use aerial_chain_core::ChainParams;
use rayon::prelude::*;

use aerial_chain::baseline::{FullStatePrm, PrmError, PrmSettings};
use aerial_chain::collision::{verify_plan, CollisionContext, DEFAULT_CLEARANCE};
use aerial_chain::map::DistanceField;
use aerial_chain::plan_file::MapSection;
use aerial_chain::planner::{
    to_plan, ArcPlanner, Failure, Phases, Planner, Settings, Solution, SolutionStats, Termination,
};
use aerial_chain::planning;
use aerial_chain::problem::passages::PassageSpec;
use aerial_chain::problem::scenarios::{self, Scenario};
use aerial_chain::tables::{ShapeTables, TableSettings};
use aerial_chain::witness::{opening_clearances, OpeningClearance};

/// Start and goal of a query (at the default goal tolerance).
pub use aerial_chain::planner::Query;

/// What a run gave.
#[derive(Clone, Debug, PartialEq)]
pub struct RunResult {
    /// The run.
    pub spec: RunSpec,
    /// Whether a plan was found.
    pub success: bool,
    /// `solved`, `time_limit`, `no_shape`, `unreachable`, `no_path`, `start_invalid`,
    /// `goal_invalid`, `error`.
    pub outcome: String,
    /// The planner's message when it failed.
    pub message: String,
    /// Shape tables build (offline, not part of `t_G`) (s).
    pub tables_s: f64,
    /// The planner's setup before the query, `t_G` (s): the roadmap build for the
    /// planners that build one up front.
    pub roadmap_s: f64,
    /// Query `t_P` (s).
    pub planning_s: f64,
    /// CPU time of the roadmap build on its thread (s; Linux, `None` elsewhere).
    pub roadmap_cpu_s: Option<f64>,
    /// CPU time of the query on its thread (s; Linux, `None` elsewhere).
    pub planning_cpu_s: Option<f64>,
    /// Of the query, full-chain collision checks (s; successful runs).
    pub collision_s: Option<f64>,
    /// Of the query, the rest: shape search, head routing, lazy search (s; successful runs).
    pub search_s: Option<f64>,
    /// Shape changes of the plan.
    pub shape_changes: Option<usize>,
    /// Edges of the plan (head edges, or PRM roadmap edges).
    pub edges: Option<usize>,
    /// Head edges dropped and rerouted (ARCplanner).
    pub replans: Option<usize>,
    /// SRSConnect calls (ARCplanner).
    pub srs_connects: Option<usize>,
    /// Lazy A* searches (PRM).
    pub iterations: Option<usize>,
    /// Full-chain collision checks in the query.
    pub collision_checks: Option<u64>,
    /// Roadmap vertices actually built.
    pub roadmap_vertices: usize,
    /// Whether the PRM's roadmap build was cut by the time limit.
    pub build_capped: bool,
    /// Plan waypoints.
    pub waypoints: Option<usize>,
    /// Exact verification of the plan (`None` without a plan).
    pub verified: Option<bool>,
    /// For an instance of the hard-case family (`passage:`), what post-processing
    /// made of the plan and the clearance it keeps through the openings.
    pub passage: Option<PassageResult>,
    /// Where an ARCplanner query's time went, for a successful run.
    pub phases: Option<Phases>,
}

/// The plan of a `passage:` instance after `arc plan`'s post-processing, and the
/// clearance the raw and the post-processed plan keep through its openings.
#[derive(Clone, Debug, PartialEq)]
pub struct PassageResult {
    /// Post-processing time (s), not part of the planning time.
    pub post_s: f64,
    /// Exact verification of the post-processed plan.
    pub verified: bool,
    /// Per opening, the raw plan's and the post-processed plan's clearance.
    pub openings: Vec<(OpeningClearance, OpeningClearance)>,
}

impl PassageResult {
    /// The smallest ratio of clearance to target over the openings, raw and
    /// post-processed.
    pub fn worst_ratio(&self) -> (f64, f64) {
        self.openings
            .iter()
            .fold((f64::INFINITY, f64::INFINITY), |(a, b), (r, p)| {
                (a.min(r.clearance / r.target), b.min(p.clearance / p.target))
            })
    }
}

impl RunResult {
    fn failed(spec: &RunSpec, outcome: &str, message: String) -> Self {
        Self {
            spec: spec.clone(),
            success: false,
            outcome: outcome.into(),
            message,
            tables_s: 0.0,
            roadmap_s: 0.0,
            planning_s: 0.0,
            roadmap_cpu_s: None,
            planning_cpu_s: None,
            collision_s: None,
            search_s: None,
            shape_changes: None,
            edges: None,
            replans: None,
            srs_connects: None,
            iterations: None,
            collision_checks: None,
            roadmap_vertices: 0,
            build_capped: false,
            waypoints: None,
            verified: None,
            passage: None,
            phases: None,
        }
    }

    /// Everything but the timings: equal for equal specs on any thread count (unless
    /// the time limit cut a run).
    #[cfg(test)]
    pub fn fingerprint(&self) -> String {
        format!(
            "{:?}|{}|{}|{:?}|{:?}|{:?}|{:?}|{:?}|{:?}|{}|{}|{:?}|{:?}",
            self.spec,
            self.success,
            self.outcome,
            self.shape_changes,
            self.edges,
            self.replans,
            self.srs_connects,
            self.iterations,
            self.collision_checks,
            self.roadmap_vertices,
            self.build_capped,
            self.waypoints,
            self.verified
        )
    }

    /// Roadmap build plus query (s).
    pub fn total_s(&self) -> f64 {
        self.roadmap_s + self.planning_s
    }

    /// CPU time of roadmap build plus query (s), when measured.
    pub fn total_cpu_s(&self) -> Option<f64> {
        Some(self.roadmap_cpu_s? + self.planning_cpu_s?)
    }
}

/// CPU time this thread has run so far (s), from `clock_gettime(CLOCK_THREAD_CPUTIME_ID)`
/// (Unix; `None` elsewhere or on error). Unlike wall-clock time it leaves out the time a
/// run waits for a core on a loaded machine.
#[cfg(unix)]
pub fn thread_cpu_s() -> Option<f64> {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec; the call only writes into it.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    (rc == 0).then_some(ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9)
}

/// CPU time this thread has run so far: unavailable off Unix.
#[cfg(not(unix))]
pub fn thread_cpu_s() -> Option<f64> {
    None
}

/// Wall-clock and CPU time of `f`.
fn timed<T>(f: impl FnOnce() -> T) -> (T, f64, Option<f64>) {
    let c0 = thread_cpu_s();
    let t = Instant::now();
    let r = f();
    let wall = t.elapsed().as_secs_f64();
    let cpu = c0.and_then(|a| thread_cpu_s().map(|b| (b - a).max(0.0)));
    (r, wall, cpu)
}

/// A scenario's map, ready for runs (shared read-only between threads).
pub struct Env {
    /// The scenario.
    pub scenario: Scenario,
    /// Its distance field.
    pub field: Arc<DistanceField>,
}

/// Prefix of the bench-only variant of `window` with a wider opening.
pub const WIDE_WINDOW: &str = "window-wide:";

/// A built-in scenario ([`scenarios::build`]), or the bench-only variant
/// `window-wide:W`: `window` with its opening widened to `W` x `W` metres (`0.8..=2.4`,
/// same centre), where a full-state PRM has a chance (see [`paper`]).
pub fn build_scenario(name: &str) -> Result<Scenario, StudyError> {
    let Some(w) = name.strip_prefix(WIDE_WINDOW) else {
        return Ok(scenarios::build(name)?);
    };
    let wide = |why: String| StudyError::WideWindow {
        name: name.into(),
        why,
    };
    let w: f64 = w
        .parse()
        .map_err(|_| wide(format!("the opening {w:?} is not a number")))?;
    if !(0.8..=2.4).contains(&w) {
        return Err(wide("the opening must be 0.8 to 2.4 m".into()));
    }
    let mut sc = scenarios::window();
    let (h, e) = (0.5 * w, 1e-6);
    sc.grid.fill_box(
        [4.0 + e, 3.0 - h + e, 1.5 - h + e],
        [4.2 - e, 3.0 + h - e, 1.5 + h - e],
        aerial_chain::map::Cell::Free,
    );
    sc.name = name.to_string();
    sc.description = format!(
        "window with its opening widened from 0.8 m x 0.8 m to {w} m x {w} m (bench-only variant)"
    );
    Ok(sc)
}

/// Scenarios by name, each built once.
pub struct Envs(BTreeMap<String, Env>);

impl Envs {
    /// Builds every scenario the specs name.
    pub fn for_specs(specs: &[RunSpec]) -> Result<Self, StudyError> {
        let mut m = BTreeMap::new();
        for s in specs {
            let name = &s.key.scenario;
            if !m.contains_key(name) {
                let scenario = build_scenario(name)?;
                let field = Arc::new(DistanceField::new(scenario.grid.clone()));
                m.insert(name.clone(), Env { scenario, field });
            }
        }
        Ok(Self(m))
    }

    /// The environment of `name`, if built.
    pub fn get(&self, name: &str) -> Option<&Env> {
        self.0.get(name)
    }
}

/// A collision context of its own (fresh counters) for a run.
pub fn context(env: &Env, units: u8) -> Result<CollisionContext, StudyError> {
    let params = ChainParams::new(units)
        .validate()
        .map_err(|why| StudyError::Chain { units, why })?;
    Ok(CollisionContext::new(
        env.field.clone(),
        params,
        DEFAULT_CLEARANCE,
    )?)
}

/// The scenario's own query for `units`: its start, LI at its start yaw, its goal.
pub fn default_query(sc: &Scenario, units: u8) -> Result<Query, StudyError> {
    Ok(Query::new(sc.start, sc.start_shape(units)?, sc.goal))
}

/// A query for a chain that may not fit at the scenario's start as a straight line
/// (long chains): the first of, in this order, the scenario's start with LI at its start
/// yaw; the start with each library shape (LI, then PN, then SE, SM, SV, CA) at the
/// start yaw plus `j * 45` degrees, `j = 0..8`; the same at the lattice points (0.1 m,
/// at the start's height) within 1.5 m of the start, nearest first; whose configuration
/// is valid. The goal is the scenario's. PN comes second because its body bends
/// evenly, so the chain can slide along it (follow-the-leader); the serpentines are
/// zig-zags at the bend limit, along which no unit can slide.
pub fn fitting_query(sc: &Scenario, ctx: &CollisionContext) -> Result<Query, StudyError> {
    let params = *ctx.params();
    let lib = library(&params);
    let start: [f64; 3] = sc.start.into();
    let mut positions = vec![start];
    let mut ring = Vec::new();
    for i in -15i32..=15 {
        for j in -15i32..=15 {
            let d = (i * i + j * j) as f64;
            if d > 0.0 && d <= 225.0 {
                ring.push((d, i, j));
            }
        }
    }
    ring.sort_by(|a, b| a.0.total_cmp(&b.0).then((a.1, a.2).cmp(&(b.1, b.2))));
    positions.extend(ring.iter().map(|&(_, i, j)| {
        [
            start[0] + 0.1 * i as f64,
            start[1] + 0.1 * j as f64,
            start[2],
        ]
    }));
    let yaw0 = sc.start_yaw as f32;
    let rank = |k: LscKind| match k {
        LscKind::Li => 0,
        LscKind::Pn => 1,
        _ => 2,
    };
    let mut entries: Vec<_> = lib.entries.iter().collect();
    entries.sort_by_key(|e| rank(e.kind));
    for p in positions {
        for e in entries.iter() {
            for j in 0..8 {
                let yaw = yaw0 + j as f32 * std::f32::consts::FRAC_PI_4;
                let shape = e
                    .shape
                    .rotated(aerial_chain_core::angle::diff(e.shape.head_yaw(), yaw));
                if ctx.check_config(p, &shape).is_ok() {
                    return Ok(Query::new(p.into(), shape, sc.goal));
                }
            }
        }
    }
    Err(StudyError::NoFittingStart {
        units: params.units,
        scenario: sc.name.clone(),
    })
}

/// Runs one spec.
pub fn run_one(envs: &Envs, spec: &RunSpec) -> RunResult {
    let key = &spec.key;
    let Some(env) = envs.get(&key.scenario) else {
        let e = StudyError::NotBuilt(key.scenario.clone());
        return RunResult::failed(spec, "error", e.to_string());
    };
    let ctx = match context(env, key.units) {
        Ok(c) => c,
        Err(e) => return RunResult::failed(spec, "error", e.to_string()),
    };
    let query = match spec.query {
        Some(q) => q,
        None => match default_query(&env.scenario, key.units) {
            Ok(q) => q,
            Err(e) => return RunResult::failed(spec, "error", e.to_string()),
        },
    };
    let stop = Termination {
        // Checked by the command line; a limit no Duration holds is no limit.
        time_limit: spec
            .time_limit
            .and_then(|t| Duration::try_from_secs_f64(t).ok()),
    };
    match key.method {
        Method::Arc(mode) => run_arc(env, ctx, spec, mode, query, stop),
        Method::FullPrm => run_prm(env, ctx, spec, query, stop),
    }
}

/// Sets up and solves `q` with `planner` (the setup under `setup_stop`, the query
/// under `stop`), timing both; a solution is written as a plan and verified. The
/// result's planner-specific counters are left to the caller.
fn run_planner<P: Planner>(
    env: &Env,
    spec: &RunSpec,
    planner: &mut P,
    q: &Query,
    (setup_stop, stop): (Termination, Termination),
) -> (RunResult, Result<Solution<P::Stats>, P::Error>) {
    let params = *planner.context().params();
    let ((), roadmap_s, roadmap_cpu_s) = timed(|| planner.setup(q, setup_stop));
    let (res, planning_s, planning_cpu_s) = timed(|| planner.solve(q, stop));
    let mut r = RunResult::failed(spec, "solved", String::new());
    r.roadmap_s = roadmap_s;
    r.planning_s = planning_s;
    r.roadmap_cpu_s = roadmap_cpu_s;
    r.planning_cpu_s = planning_cpu_s;
    match &res {
        Err(e) => {
            r.outcome = e.outcome().into();
            r.message = e.to_string();
        }
        Ok(sol) => {
            let t = sol.stats.timings();
            r.success = true;
            r.collision_s = Some(t.collision_s);
            r.search_s = Some(t.rest_s());
            let g = &env.scenario.grid;
            let plan = to_plan(sol, &params, MapSection::of(g));
            r.waypoints = Some(plan.waypoints.len());
            r.verified = Some(verify_plan(g, &plan).ok);
        }
    }
    (r, res)
}

fn run_arc(
    env: &Env,
    ctx: CollisionContext,
    spec: &RunSpec,
    mode: ArcMode,
    q: Query,
    stop: Termination,
) -> RunResult {
    let params = *ctx.params();
    let t = Instant::now();
    let tables = ShapeTables::build(
        params,
        &TableSettings {
            srs: spec.key.srs,
            seed: spec.seed,
            ..Default::default()
        },
        &AtomicUsize::new(0),
    );
    let tables_s = t.elapsed().as_secs_f64();
    let tables = match tables {
        Ok(t) => t,
        Err(e) => return RunResult::failed(spec, "error", e.to_string()),
    };
    let settings = Settings {
        vertices: spec.key.vertices,
        mode: mode.mode(),
        follow_step: mode.follow_step(),
        seed: spec.seed,
        ..Default::default()
    };
    let mut planner = match ArcPlanner::new(ctx, tables, settings) {
        Ok(p) => p,
        Err(e) => return RunResult::failed(spec, "error", e.to_string()),
    };
    // The head roadmap is built without a time limit: it is shared by queries, and the
    // limit is the query's (the PRM's roadmap is per goal, so its build is capped).
    let stops = (Termination::default(), stop);
    let (mut r, res) = run_planner(env, spec, &mut planner, &q, stops);
    r.tables_s = tables_s;
    r.roadmap_vertices = spec.key.vertices;
    r.phases = res.as_ref().ok().map(|sol| sol.stats.phases());
    if let Ok(sol) = res {
        if let Some(p) = spec.key.scenario.strip_prefix("passage:") {
            r.passage = passage_result(env, &planner, &sol, p);
        }
        let s = &sol.stats;
        r.roadmap_vertices = s.roadmap_vertices;
        r.shape_changes = Some(s.shape_changes);
        r.edges = Some(s.edges);
        r.replans = Some(s.replans);
        r.srs_connects = Some(s.srs_connects);
        r.collision_checks = Some(s.collision_checks);
    }
    r
}

/// Post-processes `sol` as `arc plan` does and measures the clearance through the
/// openings of the `passage:` instance `name` (`None` when the name does not parse).
fn passage_result(
    env: &Env,
    planner: &ArcPlanner,
    sol: &Solution<aerial_chain::planner::Stats>,
    name: &str,
) -> Option<PassageResult> {
    let spec = PassageSpec::parse(name).ok()?;
    let params = *planner.context().params();
    let g = &env.scenario.grid;
    let raw = to_plan(sol, &params, MapSection::of(g));
    let t = Instant::now();
    let end = planning::Arrival::anywhere(env.scenario.goal);
    let post = planning::finish(planner, sol.clone(), MapSection::of(g), true, None, &end)
        .ok()?
        .plan;
    let post_s = t.elapsed().as_secs_f64();
    let raw_o = opening_clearances(&spec, &raw, &params).ok()?;
    let post_o = opening_clearances(&spec, &post, &params).ok()?;
    Some(PassageResult {
        post_s,
        verified: verify_plan(g, &post).ok,
        openings: raw_o.into_iter().zip(post_o).collect(),
    })
}

fn run_prm(
    env: &Env,
    ctx: CollisionContext,
    spec: &RunSpec,
    q: Query,
    stop: Termination,
) -> RunResult {
    let settings = PrmSettings {
        vertices: spec.key.vertices,
        seed: spec.seed,
        ..Default::default()
    };
    let mut prm = match FullStatePrm::new(ctx, settings) {
        Ok(p) => p,
        Err(e) => return RunResult::failed(spec, "error", e.to_string()),
    };
    let (mut r, res) = run_planner(env, spec, &mut prm, &q, (stop, stop));
    let rs = prm.roadmap_stats();
    r.roadmap_vertices = rs.vertices;
    r.build_capped = rs.build_capped;
    match res {
        Err(PrmError::NoPath { iterations, .. } | PrmError::TimeLimit { iterations }) => {
            r.iterations = Some(iterations);
        }
        Err(_) => {}
        Ok(sol) => {
            let s = &sol.stats;
            r.shape_changes = Some(s.shape_changes);
            r.edges = Some(s.path_edges);
            r.iterations = Some(s.iterations);
            r.collision_checks = Some(s.collision_checks);
        }
    }
    r
}

/// Runs every spec, in parallel over `threads` threads (`None`: rayon's default, which
/// follows `RAYON_NUM_THREADS`), showing a progress bar on a terminal (and a line every
/// tenth of the runs otherwise, when `log` is set). Results come back in spec order.
pub fn run_all(
    envs: &Envs,
    specs: &[RunSpec],
    threads: Option<usize>,
    what: &str,
    log: bool,
) -> Result<Vec<RunResult>, StudyError> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()?;
    let total = specs.len();
    let bar = if log && std::io::stderr().is_terminal() {
        let b = indicatif::ProgressBar::new(total as u64);
        b.set_style(
            indicatif::ProgressStyle::with_template(
                "{msg} [{bar:40}] {pos}/{len} runs ({elapsed}, eta {eta})",
            )?
            .progress_chars("=> "),
        );
        b.set_message(what.to_string());
        Some(b)
    } else {
        None
    };
    let done = AtomicUsize::new(0);
    let began = Instant::now();
    let results = pool.install(|| {
        specs
            .par_iter()
            .map(|s| {
                let r = run_one(envs, s);
                let k = done.fetch_add(1, Ordering::Relaxed) + 1;
                if let Some(b) = &bar {
                    b.inc(1);
                } else if log
                    && (k * 10 / total.max(1) != (k - 1) * 10 / total.max(1) || k == total)
                {
                    eprintln!(
                        "{what}: {k}/{total} runs done ({:.0} s)",
                        began.elapsed().as_secs_f64()
                    );
                }
                r
            })
            .collect()
    });
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    Ok(results)
}

#[cfg(test)]
mod tests {
    use super::report::csv_field;
    use super::*;

    #[test]
    fn quantiles() {
        let s = Spread::of([4.0, 1.0, 3.0, 2.0, f64::NAN]);
        assert_eq!(s.n, 4);
        assert_eq!(s.median, 2.5);
        assert_eq!(s.min, 1.0);
        assert_eq!(s.max, 4.0);
        assert_eq!(s.q1, 1.75);
        let e = Spread::of([]);
        assert_eq!(e.n, 0);
        assert!(e.median.is_nan());
        assert_eq!(ms(&e), "-");
    }

    #[test]
    fn thread_cpu_time_is_fine_grained() {
        let Some(a) = thread_cpu_s() else {
            return;
        };
        let mut x = 0u64;
        let t = Instant::now();
        while t.elapsed() < Duration::from_millis(20) {
            x = x.wrapping_mul(6364136223846793005).wrapping_add(1);
        }
        std::hint::black_box(x);
        let b = thread_cpu_s().unwrap();
        assert!(b - a > 1e-3, "20 ms of busy work took {} s of CPU", b - a);
        let c = thread_cpu_s().unwrap();
        assert!(c - b < 1e-3, "two reads in a row: {} s apart", c - b);
    }

    #[test]
    fn csv_quotes() {
        assert_eq!(csv_field("a,b"), "\"a,b\"");
        assert_eq!(csv_field("say \"x\""), "\"say \"\"x\"\"\"");
        assert_eq!(csv_field("plain"), "plain");
    }

    #[test]
    fn long_chains_get_a_start_that_fits() {
        let sc = scenarios::build("window").unwrap();
        let field = Arc::new(DistanceField::new(sc.grid.clone()));
        let env = Env {
            scenario: sc,
            field,
        };
        for n in [3u8, 12, 16] {
            let ctx = context(&env, n).unwrap();
            let q = fitting_query(&env.scenario, &ctx).unwrap();
            assert!(ctx.check_config(q.start, &q.start_shape).is_ok());
        }
        // A short chain keeps the scenario's own start.
        let ctx = context(&env, 4).unwrap();
        let q = fitting_query(&env.scenario, &ctx).unwrap();
        assert_eq!(q, default_query(&env.scenario, 4).unwrap());
    }

    #[test]
    fn unknown_scenario_is_an_error() {
        let spec = RunKey::new("t", "nowhere", 4, Method::FullPrm, (10, 0)).run(1, None);
        assert!(Envs::for_specs(std::slice::from_ref(&spec)).is_err());
        let envs = Envs(BTreeMap::new());
        let r = run_one(&envs, &spec);
        assert!(!r.success);
        assert_eq!(r.outcome, "error");
    }
}

#[cfg(test)]
mod quick_tests;
