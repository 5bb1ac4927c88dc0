//! `arc bench flight`: how long the planner's plans take to fly, stopping at every
//! waypoint (as `arc sim --no-blend`) and along the blended trajectory (`arc sim`'s
//! default), against the head's path length over the speed limit.
//!
//! Every run plans with `arc plan`'s defaults (refinement on), checks the plan and the
//! trajectory exactly, and flies both with `arc sim`'s defaults on the scenario's map.
//! Runs are sequential: each is deterministic in its spec, timings aside.

use std::fmt::Write as _;

use aerial_chain::collision::verify_plan;
use aerial_chain::flying::{self, FlyOptions, Timed};
use aerial_chain::picture::palette;
use aerial_chain::planner::{Query, Settings};
use aerial_chain::planning::{self, PlanOptions, Request};
use aerial_chain::problem::scenarios;
use aerial_chain::sim::{FlightReport, Progress};
use aerial_chain::trajectory;

use super::report::csv_field;
use aerial_chain_core::ChainParams;

/// One run: a plan, flown both ways.
#[derive(Clone, Debug)]
pub struct FlightRun {
    /// Scenario.
    pub scenario: String,
    /// Units.
    pub units: u8,
    /// Planner and SRS seed.
    pub seed: u64,
    /// What went wrong, if anything (empty: both flights ran).
    pub error: String,
    /// Head path length of the plan (m).
    pub head_path_m: f64,
    /// Shape changes in the plan.
    pub shape_changes: usize,
    /// Corners of the plan, and how many the trajectory blends.
    pub corners: usize,
    /// Corners blended.
    pub blended: usize,
    /// Translations and shape changes merged.
    pub merged: usize,
    /// Time to post-process the plan (refinement and shortening, s).
    pub refine_s: f64,
    /// Shape motion of the plan before and after post-processing (rad).
    pub shape_motion_rad: (f64, f64),
    /// Time to make and check the trajectory (s).
    pub trajectory_s: f64,
    /// Trajectory duration (s).
    pub trajectory_duration_s: f64,
    /// Stop-at-every-waypoint flight.
    pub before: Option<Flown>,
    /// Trajectory flight.
    pub after: Option<Flown>,
}

/// What one flight measured.
#[derive(Clone, Copy, Debug)]
pub struct Flown {
    /// Time to reach the goal, from the start of the flight (s; the 1 s hold included).
    pub time_s: f64,
    /// Largest head tracking error (m).
    pub head_max_m: f64,
    /// Smallest clearance to the map (m).
    pub min_clearance_m: f64,
    /// Whether it arrived without contact.
    pub success: bool,
}

impl Flown {
    fn of(r: &FlightReport) -> Self {
        Self {
            time_s: r.time_to_complete.unwrap_or(f64::NAN),
            head_max_m: r.head_max,
            min_clearance_m: r.min_clearance.unwrap_or(f64::NAN),
            success: r.success(),
        }
    }
}

impl FlightRun {
    /// Flight time over head path / speed for one of the flights.
    pub fn ratio(&self, f: Option<Flown>, speed: f64) -> f64 {
        f.map_or(f64::NAN, |f| f.time_s / (self.head_path_m / speed))
    }
}

/// Plans `scenario` for `units` with `seed` and flies it both ways.
pub fn run_one(scenario: &str, units: u8, seed: u64) -> FlightRun {
    let mut run = FlightRun {
        scenario: scenario.into(),
        units,
        seed,
        error: String::new(),
        head_path_m: f64::NAN,
        shape_changes: 0,
        corners: 0,
        blended: 0,
        merged: 0,
        refine_s: f64::NAN,
        shape_motion_rad: (f64::NAN, f64::NAN),
        trajectory_s: f64::NAN,
        trajectory_duration_s: f64::NAN,
        before: None,
        after: None,
    };
    if let Err(e) = fly_both(&mut run) {
        run.error = e;
    }
    run
}

/// How a run's error begins where only its stop-and-go flight could not be flown.
const STOP_AND_GO_NOT_FLOWN: &str = "stop and go not flown";

fn fly_both(run: &mut FlightRun) -> Result<(), String> {
    let sc = scenarios::build(&run.scenario).map_err(|e| e.to_string())?;
    let params = ChainParams::new(run.units)
        .validate()
        .map_err(|e| e.to_string())?;
    let query = Query::new(
        sc.start,
        sc.start_shape(run.units).map_err(|e| e.to_string())?,
        sc.goal,
    );
    // `arc plan`'s defaults with the run's seeds, without a time limit (runs are
    // deterministic), and the trajectory `arc sim` flies.
    let options = PlanOptions {
        planner: Settings {
            seed: run.seed,
            ..Default::default()
        },
        srs_seed: run.seed,
        time_limit_s: None,
        trajectory: Some(trajectory::Settings::default()),
        ..Default::default()
    };
    let request = Request::new(sc.grid.clone(), params, query);
    // The planner's reason alone: the error column holds no timing.
    let planned = planning::plan(&request, None, &options).map_err(|e| match e {
        planning::PlanningError::NoPlan(n) => format!("no plan: {}", n.error),
        e => e.to_string(),
    })?;
    let refinement = planned.refinement.ok_or("post-processing was asked for")?;
    run.refine_s = refinement.time_s;
    run.shape_motion_rad = (
        refinement.before.shape_motion_rad,
        refinement.after.shape_motion_rad,
    );
    let grid = &sc.grid;
    let plan = planned.plan;
    let check = verify_plan(grid, &plan);
    if !check.ok {
        return Err(format!("plan invalid: {:?}", check.violation));
    }
    run.shape_changes = check
        .edges
        .iter()
        .filter(|e| **e == aerial_chain::collision::EdgeKind::ShapeChange)
        .count();
    let tr = match planned.trajectory {
        Some(made) => made.map_err(|e| e.to_string())?,
        None => return Err("the trajectory was asked for".into()),
    };
    run.trajectory_s = planned.timings.trajectory_s;
    run.head_path_m = tr.head_path_m();
    run.corners = tr.corners();
    run.blended = tr.blended();
    run.merged = tr.merged();
    run.trajectory_duration_s = tr.duration();
    // Both as `arc sim` flies them: the default, along the trajectory made above,
    // then `--no-blend`. A plan of many short steps can stop and go for hours, past
    // what the simulation records: its blended flight still counts.
    let blended = FlyOptions::default();
    let timed = Timed::along(tr, &blended);
    let after = flying::fly_timed(&plan, &timed, grid, &blended, &Progress::default())
        .map_err(|e| e.to_string())?;
    run.after = Some(Flown::of(&after.report));
    let stopping = FlyOptions {
        timing: trajectory::Settings {
            blend: false,
            ..Default::default()
        },
        ..Default::default()
    };
    let (before, _) = flying::fly(&plan, grid, &stopping, &Progress::default())
        .map_err(|e| format!("{STOP_AND_GO_NOT_FLOWN}: {e}"))?;
    run.before = Some(Flown::of(&before.report));
    Ok(())
}

/// The runs as CSV, one row each.
pub fn csv(runs: &[FlightRun], speed: f64) -> String {
    let mut s = String::from(
        "scenario,units,seed,head_path_m,path_over_speed_s,shape_changes,shape_motion_before_rad,shape_motion_rad,corners,blended,merged,refine_ms,trajectory_ms,trajectory_s,\
         before_s,before_ratio,before_ok,before_head_max_m,before_min_clearance_m,\
         after_s,after_ratio,after_ok,after_head_max_m,after_min_clearance_m,error\n",
    );
    for r in runs {
        let f = |x: Option<Flown>| match x {
            Some(f) => format!(
                "{:.2},{:.3},{},{:.4},{:.4}",
                f.time_s,
                r.ratio(x, speed),
                f.success,
                f.head_max_m,
                f.min_clearance_m
            ),
            None => ",,,,".into(),
        };
        let _ = writeln!(
            s,
            "{},{},{},{:.3},{:.2},{},{:.3},{:.3},{},{},{},{:.1},{:.1},{:.2},{},{},{}",
            csv_field(&r.scenario),
            r.units,
            r.seed,
            r.head_path_m,
            r.head_path_m / speed,
            r.shape_changes,
            r.shape_motion_rad.0,
            r.shape_motion_rad.1,
            r.corners,
            r.blended,
            r.merged,
            r.refine_s * 1e3,
            r.trajectory_s * 1e3,
            r.trajectory_duration_s,
            f(r.before),
            f(r.after),
            csv_field(&r.error)
        );
    }
    s
}

/// A run's row of the table: its scenario and N, or for an instance of the passages
/// family (`passage:...`) the family's one row, every N together.
fn group_of(r: &FlightRun) -> (String, String) {
    if r.scenario.starts_with("passage:") {
        (ROBUST.into(), "4-8".into())
    } else {
        (r.scenario.clone(), r.units.to_string())
    }
}

/// The table's name for the passages family.
const ROBUST: &str = "robust family";

/// The first `count` instances of `arc bench robust`'s family (its generator and
/// seed), as (scenario, N, planner seed).
pub fn robust_sample(count: usize) -> Vec<(String, u8, u64)> {
    let o = super::robust::RobustOptions {
        instances: count,
        ..super::robust::RobustOptions::full()
    };
    super::robust::draw(&o)
        .0
        .into_iter()
        .map(|s| (s.key.scenario.clone(), s.key.units, s.seed))
        .collect()
}

/// A markdown table: per scenario and N, the median over seeds of both ratios.
pub fn markdown(runs: &[FlightRun], speed: f64) -> String {
    let mut s = String::from(
        "| scenario | N | runs | head path (m) | path / speed (s) | shape motion raw -> post-processed (rad) | stop at every waypoint (s) | ratio | trajectory (s) | ratio | post-processing + trajectory (ms) | all flights without contact |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let mut keys: Vec<(String, String)> = runs.iter().map(group_of).collect();
    keys.dedup();
    // Groups of which no run flew, with the first run's reason; runs whose stop and
    // go alone was not flown, with theirs.
    let mut unflown = Vec::new();
    for key in keys {
        let members: Vec<&FlightRun> = runs.iter().filter(|r| group_of(r) == key).collect();
        let (sc, n) = key;
        let group: Vec<&FlightRun> = members
            .iter()
            .copied()
            .filter(|r| r.after.is_some())
            .collect();
        for r in group.iter().filter(|r| !r.error.is_empty()) {
            unflown.push(format!("{sc} N = {n} seed {}: {}", r.seed, r.error));
        }
        if group.is_empty() {
            let why = members.first().map_or("", |r| r.error.as_str());
            unflown.push(format!("{sc} N = {n} ({why})"));
            continue;
        }
        let med = |f: &dyn Fn(&FlightRun) -> f64| median(group.iter().map(|r| f(r)).collect());
        let ok = group
            .iter()
            .all(|r| r.before.is_none_or(|f| f.success) && r.after.is_some_and(|f| f.success));
        let row = format!(
            "| {sc} | {n} | {} | {:.1} | {:.1} | {:.1} -> {:.1} | {:.1} | {:.2} | {:.1} | {:.2} | {:.0} | {} |",
            group.len(),
            med(&|r| r.head_path_m),
            med(&|r| r.head_path_m / speed),
            med(&|r| r.shape_motion_rad.0),
            med(&|r| r.shape_motion_rad.1),
            med(&|r| r.before.map_or(f64::NAN, |f| f.time_s)),
            med(&|r| r.ratio(r.before, speed)),
            med(&|r| r.after.map_or(f64::NAN, |f| f.time_s)),
            med(&|r| r.ratio(r.after, speed)),
            med(&|r| (r.refine_s + r.trajectory_s) * 1e3),
            if ok { "yes" } else { "no" }
        );
        // A figure no run has (a stop and go not flown) is a dash, not NaN.
        let _ = writeln!(s, "{}", row.replace(" NaN ", " - "));
    }
    if !unflown.is_empty() {
        let _ = writeln!(s, "\nNot flown: {}.", unflown.join("; "));
    }
    s
}

fn median(mut v: Vec<f64>) -> f64 {
    v.retain(|x| x.is_finite());
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let m = v.len() / 2;
    if v.len() % 2 == 1 {
        v[m]
    } else {
        0.5 * (v[m - 1] + v[m])
    }
}

/// Flight time against head path / speed, both flights of every run, with the lines
/// `time = path / speed` and the target `time = 2 path / speed`.
pub fn figure(runs: &[FlightRun], speed: f64) -> String {
    let points = |pick: &dyn Fn(&FlightRun) -> Option<Flown>| -> Vec<(f64, f64)> {
        runs.iter()
            .filter_map(|r| pick(r).map(|f| (r.head_path_m / speed, f.time_s)))
            .filter(|p| p.0.is_finite() && p.1.is_finite())
            .collect()
    };
    let (before, after) = (points(&|r| r.before), points(&|r| r.after));
    let xmax = before.iter().chain(&after).map(|p| p.0).fold(1.0, f64::max) * 1.05;
    let ymax = before.iter().chain(&after).map(|p| p.1).fold(1.0, f64::max) * 1.05;
    super::plot::times_svg(
        "arc bench flight: flight time against path length",
        ("head path / speed (s)", xmax),
        ("simulated flight time (s)", ymax),
        "path / speed",
        (2.0, "target: 2 x path / speed"),
        &[
            (&before, palette::series(3), "stop at every waypoint"),
            (&after, palette::series(0), "blended trajectory"),
        ],
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(scenario: &str, seed: u64, before: f64, after: f64) -> FlightRun {
        let flown = |t: f64| Flown {
            time_s: t,
            head_max_m: 0.01,
            min_clearance_m: 0.1,
            success: true,
        };
        FlightRun {
            scenario: scenario.into(),
            units: 5,
            seed,
            error: String::new(),
            head_path_m: 10.0,
            shape_changes: 3,
            corners: 6,
            blended: 4,
            merged: 2,
            refine_s: 0.004,
            shape_motion_rad: (20.0, 12.0),
            trajectory_s: 0.01,
            trajectory_duration_s: after - 1.0,
            before: Some(flown(before)),
            after: Some(flown(after)),
        }
    }

    #[test]
    fn a_run_plans_through_the_facade_and_flies_both_ways_as_arc_sim_does() {
        let r = run_one("window", 3, 1);
        assert!(r.error.is_empty(), "{}", r.error);
        let (before, after) = (r.before.unwrap(), r.after.unwrap());
        assert!(before.success && after.success);
        // Blended, the flight ends sooner.
        assert!(
            after.time_s + 1.0 < before.time_s,
            "{} {}",
            after.time_s,
            before.time_s
        );
        // The blended flight arrives (within its goal tolerance) about when its
        // trajectory, after the hold, ends.
        let end = r.trajectory_duration_s + 1.0;
        assert!((after.time_s - end).abs() < 1.5, "{} {end}", after.time_s);
        assert!(r.shape_motion_rad.1 <= r.shape_motion_rad.0 + 1e-9);
    }

    #[test]
    fn table_csv_and_plot_of_the_runs() {
        let mut runs = vec![run("maze", 1, 60.0, 30.0), run("maze", 2, 80.0, 50.0)];
        runs.extend([
            run("passage:w=0.5,angle=45", 1, 30.0, 20.0),
            run("passage:w=0.55,angle=30,door=0.6", 2, 40.0, 30.0),
        ]);
        runs[3].units = 7;
        let md = markdown(&runs, 0.5);
        // Medians over the two seeds: 70 s and 40 s against 20 s of path.
        assert!(
            md.contains(
                "| maze | 5 | 2 | 10.0 | 20.0 | 20.0 -> 12.0 | 70.0 | 3.50 | 40.0 | 2.00 | 14 | yes |"
            ),
            "{md}"
        );
        // The family's instances make one row, whatever their N.
        assert!(
            md.contains("| robust family | 4-8 | 2 | 10.0 | 20.0 | 20.0 -> 12.0 | 35.0 | 1.75 | 25.0 | 1.25 |"),
            "{md}"
        );
        assert!(!md.contains("Not flown"), "{md}");
        // A size whose runs all failed gets no row of NaNs but a line with the reason.
        let mut failed = run("corridor:100", 1, 60.0, 30.0);
        failed.units = 8;
        failed.error = "start is invalid".into();
        (failed.before, failed.after) = (None, None);
        let md_failed = markdown(&[runs[0].clone(), failed], 0.5);
        assert!(!md_failed.contains("NaN"), "{md_failed}");
        assert!(
            md_failed.contains("Not flown: corridor:100 N = 8 (start is invalid)."),
            "{md_failed}"
        );
        // A run whose stop and go alone was not flown keeps its blended flight.
        let mut partial = run("corridor:100", 2, 60.0, 30.0);
        partial.before = None;
        partial.error = format!("{STOP_AND_GO_NOT_FLOWN}: too long");
        let md_partial = markdown(&[partial], 0.5);
        assert!(
            md_partial.contains("| corridor:100 | 5 | 1 |"),
            "{md_partial}"
        );
        assert!(
            md_partial.contains("corridor:100 N = 5 seed 2: stop and go not flown: too long"),
            "{md_partial}"
        );
        let csv = csv(&runs, 0.5);
        assert_eq!(csv.lines().count(), 5);
        // Fields, outside quotes (a passage's name holds commas).
        let fields = |l: &str| {
            1 + l
                .split('"')
                .step_by(2)
                .map(|p| p.matches(',').count())
                .sum::<usize>()
        };
        let cols = fields(csv.lines().next().unwrap());
        assert!(csv.lines().all(|l| fields(l) == cols), "{csv}");
        assert!(csv.contains("\n\"passage:w=0.5,angle=45\",5,1,"), "{csv}");
        let svg = figure(&runs, 0.5);
        assert!(svg.starts_with("<svg") && svg.contains("target: 2 x path / speed"));
        assert!(median(vec![f64::NAN]).is_nan());
    }
}
