//! `arc bench online`: flying into the unknown from an empty map (docs/online.md), on
//! the built-in scenarios and a sample of the passage family, against the flight of
//! the same query on the finished map (`arc bench flight`'s trajectory flight).
//!
//! Every run uses `arc explore`'s defaults and audits every committed piece by the
//! exact test on the map it was committed on. Runs are sequential.

use std::fmt::Write as _;

use aerial_chain::online::{explore, quantile, ExploreEnd, ExploreSettings};
use aerial_chain::picture::palette;
use aerial_chain::plan_file::Waypoint;
use aerial_chain::planning::PlanOptions;
use aerial_chain::problem::scenarios;
use aerial_chain::sensing::DepthSensor;
use aerial_chain::tables::ShapeTables;
use aerial_chain_core::ChainParams;
use std::sync::atomic::AtomicUsize;

use super::report::{csv_field, csv_table, Column};

/// One run: an exploration and the finished-map flight of the same query.
#[derive(Clone, Debug, Default)]
pub struct OnlineRun {
    /// Scenario.
    pub scenario: String,
    /// Units.
    pub units: u8,
    /// How the exploration ended (`reached`, `sealed`, `time_limit`, `flight_failed`,
    /// or the error).
    pub end: String,
    /// Time to the goal (s; NaN when not reached).
    pub time_s: f64,
    /// The finished-map flight of the same query (s; NaN when it failed).
    pub finished_s: f64,
    /// Of the time to goal, the turns in place to look (s).
    pub looking_s: f64,
    /// Replans.
    pub replans: usize,
    /// Pieces committed.
    pub pieces: usize,
    /// Pieces joined onto the committed motion in flight, without a stop.
    pub joined: usize,
    /// Pieces (or their joints) that fail the exact test on the map they were
    /// committed on.
    pub pieces_invalid: usize,
    /// Replan wall time: median, 95th percentile, largest (s).
    pub latency_s: [f64; 3],
    /// Largest wall time of a replan that found nothing new (s).
    pub nothing_new_max_s: f64,
    /// Median time to update both fields after one cloud (s).
    pub update_s: f64,
    /// Time to build both fields from scratch on the final map (s).
    pub rebuild_s: f64,
    /// Voxels seen.
    pub known: usize,
    /// Smallest clearance to the world at any physics step (m).
    pub min_clearance_m: f64,
    /// Whether any body touched the world.
    pub contact: bool,
}

impl OnlineRun {
    /// Time to goal over the finished-map flight.
    pub fn ratio(&self) -> f64 {
        self.time_s / self.finished_s
    }

    /// Time to goal less the turns in place to look, over the finished-map flight:
    /// what the flying costs, apart from looking.
    pub fn ratio_without_looks(&self) -> f64 {
        (self.time_s - self.looking_s) / self.finished_s
    }

    /// How many times cheaper the median update of both fields was than rebuilding
    /// both.
    pub fn speedup(&self) -> f64 {
        self.rebuild_s / self.update_s
    }

    /// Whether the run reached the goal without contact and committed only valid
    /// pieces.
    pub fn success(&self) -> bool {
        self.end == "reached" && !self.contact && self.pieces_invalid == 0
    }
}

/// Explores `scenario` with `units` from an empty map, and flies the finished-map
/// plan of the same query.
pub fn run_one(scenario: &str, units: u8, time_limit_s: f64, sensor: &DepthSensor) -> OnlineRun {
    let mut run = OnlineRun {
        scenario: scenario.into(),
        units,
        ..OnlineRun::default()
    };
    if let Err(e) = explore_one(&mut run, time_limit_s, sensor) {
        run.end = e;
    }
    let finished = super::flight::run_one(scenario, units, 1);
    run.finished_s = finished.after.map_or(f64::NAN, |f| f.time_s);
    run
}

fn explore_one(run: &mut OnlineRun, time_limit_s: f64, sensor: &DepthSensor) -> Result<(), String> {
    let sc = scenarios::build(&run.scenario).map_err(|e| e.to_string())?;
    let params = ChainParams::new(run.units)
        .validate()
        .map_err(|e| e.to_string())?;
    let table_settings = PlanOptions::default().table_settings();
    let tables = ShapeTables::build(params, &table_settings, &AtomicUsize::new(0))
        .map_err(|e| e.to_string())?;
    let shape = sc.start_shape(run.units).map_err(|e| e.to_string())?;
    let start = Waypoint::new(sc.start.into(), &shape).zeta;
    let mut settings = ExploreSettings {
        time_limit_s,
        audit: true,
        ..ExploreSettings::default()
    };
    settings.survey.sensor = sensor.clone();
    let tol = aerial_chain::planner::Query::DEFAULT_GOAL_TOL;
    let ex = explore(
        &sc.grid, params, tables, &start, sc.goal, tol, None, &settings,
    )
    .map_err(|e| e.to_string())?;
    let record = ex.record();
    let s = record.summary;
    run.end = match &ex.end {
        ExploreEnd::Reached { t } => {
            run.time_s = *t;
            "reached".into()
        }
        ExploreEnd::Sealed { .. } => "sealed".into(),
        ExploreEnd::Stuck { .. } => "stuck".into(),
        ExploreEnd::TimeLimit { .. } => "time_limit".into(),
        ExploreEnd::FlightFailed { .. } => "flight_failed".into(),
    };
    if !ex.end.reached() {
        run.time_s = f64::NAN;
    }
    run.looking_s = ex.looking_s;
    run.replans = s.replans;
    run.pieces = ex.pieces;
    run.joined = ex.joints.len();
    run.pieces_invalid = ex
        .audit
        .as_ref()
        .map_or(0, |a| a.iter().filter(|v| v.is_some()).count());
    run.latency_s = [s.latency_median_s, s.latency_p95_s, s.latency_max_s];
    run.nothing_new_max_s = s.nothing_new_max_s;
    run.update_s = s.update_median_s;
    run.rebuild_s = ex.rebuild_s.unwrap_or(f64::NAN);
    run.known = s.known;
    run.min_clearance_m = ex.flight.report.min_clearance.unwrap_or(f64::NAN);
    run.contact = ex.flight.report.contact;
    Ok(())
}

/// The CSV's columns.
const CSV_COLUMNS: [Column<OnlineRun>; 22] = [
    ("scenario", |r| csv_field(&r.scenario)),
    ("units", |r| r.units.to_string()),
    ("end", |r| csv_field(&r.end)),
    ("time_to_goal_s", |r| format!("{:.2}", r.time_s)),
    ("finished_map_s", |r| format!("{:.2}", r.finished_s)),
    ("ratio", |r| format!("{:.3}", r.ratio())),
    ("looking_s", |r| format!("{:.2}", r.looking_s)),
    ("ratio_without_looks", |r| {
        format!("{:.3}", r.ratio_without_looks())
    }),
    ("replans", |r| r.replans.to_string()),
    ("pieces", |r| r.pieces.to_string()),
    ("joined_in_flight", |r| r.joined.to_string()),
    ("pieces_invalid", |r| r.pieces_invalid.to_string()),
    ("latency_median_ms", |r| {
        format!("{:.2}", r.latency_s[0] * 1e3)
    }),
    ("latency_p95_ms", |r| format!("{:.2}", r.latency_s[1] * 1e3)),
    ("latency_max_ms", |r| format!("{:.2}", r.latency_s[2] * 1e3)),
    ("nothing_new_max_ms", |r| {
        format!("{:.4}", r.nothing_new_max_s * 1e3)
    }),
    ("update_median_ms", |r| format!("{:.3}", r.update_s * 1e3)),
    ("rebuild_ms", |r| format!("{:.2}", r.rebuild_s * 1e3)),
    ("update_speedup", |r| format!("{:.1}", r.speedup())),
    ("voxels_seen", |r| r.known.to_string()),
    ("min_clearance_m", |r| format!("{:.4}", r.min_clearance_m)),
    ("contact", |r| r.contact.to_string()),
];

/// One line per run, under a line of the column names.
pub fn csv(runs: &[OnlineRun]) -> String {
    csv_table(&CSV_COLUMNS, runs)
}

/// The summary table: success, ratios and latencies over all runs.
pub fn markdown(runs: &[OnlineRun]) -> String {
    let sorted = |f: &dyn Fn(&OnlineRun) -> f64| {
        let mut v: Vec<f64> = runs.iter().map(f).filter(|x| x.is_finite()).collect();
        v.sort_by(f64::total_cmp);
        v
    };
    let ok = runs.iter().filter(|r| r.success()).count();
    let ratios = sorted(&|r| r.ratio());
    let flying = sorted(&|r| r.ratio_without_looks());
    let p95 = sorted(&|r| r.latency_s[1]);
    let max = sorted(&|r| r.latency_s[2]);
    let speedup = sorted(&|r| r.speedup());
    let mut md = String::from(
        "| scenario | N | end | time to goal (s) | finished map (s) | ratio | looking (s) | ratio without looks | replans | pieces (joined in flight, invalid) | latency median / p95 / max (ms) | update (ms) | rebuild / update | min clearance (m) |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in runs {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {:.1} | {:.1} | {:.2} | {:.1} | {:.2} | {} | {} ({}, {}) | {:.1} / {:.1} / {:.1} | {:.2} | {:.0}x | {:.3} |",
            r.scenario,
            r.units,
            r.end,
            r.time_s,
            r.finished_s,
            r.ratio(),
            r.looking_s,
            r.ratio_without_looks(),
            r.replans,
            r.pieces,
            r.joined,
            r.pieces_invalid,
            r.latency_s[0] * 1e3,
            r.latency_s[1] * 1e3,
            r.latency_s[2] * 1e3,
            r.update_s * 1e3,
            r.speedup(),
            r.min_clearance_m
        );
    }
    let _ = writeln!(
        md,
        "\n{ok} of {} runs reached the goal without contact, every piece valid on its map; \
         time to goal over the finished-map flight: median {:.2}, largest {:.2} (less the \
         turns in place to look: median {:.2}, largest {:.2}); replan \
         latency p95 over runs: median {:.1} ms, largest {:.1} ms; largest replan {:.1} ms; \
         update of both fields against rebuilding both: median {:.0}x cheaper, least \
         {:.0}x.",
        runs.len(),
        quantile(&ratios, 0.5),
        ratios.last().copied().unwrap_or(f64::NAN),
        quantile(&flying, 0.5),
        flying.last().copied().unwrap_or(f64::NAN),
        quantile(&p95, 0.5) * 1e3,
        p95.last().copied().unwrap_or(f64::NAN) * 1e3,
        max.last().copied().unwrap_or(f64::NAN) * 1e3,
        quantile(&speedup, 0.5),
        speedup.first().copied().unwrap_or(f64::NAN)
    );
    md
}

/// Time to goal against the finished-map flight, with the lines `y = x` and the
/// target `y = 1.5 x`.
pub fn figure(runs: &[OnlineRun]) -> String {
    let pts: Vec<(f64, f64)> = runs
        .iter()
        .map(|r| (r.finished_s, r.time_s))
        .filter(|p| p.0.is_finite() && p.1.is_finite())
        .collect();
    let xmax = pts.iter().map(|p| p.0).fold(1.0, f64::max) * 1.1;
    let ymax = pts.iter().map(|p| p.1).fold(1.0, f64::max).max(1.5 * xmax) * 1.05;
    super::plot::times_svg(
        "arc bench online: flying into the unknown",
        ("flight on the finished map (s)", xmax),
        ("time to goal from an empty map (s)", ymax),
        "as fast as on the finished map",
        (1.5, "target: 1.5 x"),
        &[(&pts, palette::series(0), "a run that reached the goal")],
    )
}
