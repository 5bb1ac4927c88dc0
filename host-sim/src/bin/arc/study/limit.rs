//! `arc bench limit`: whether `arc plan --time-limit T` keeps its promise
//! (docs/promises.md, "The time limit"): the search, post-processing and the trajectory
//! end within `1.1 T + 50 ms` after setup, plan or no plan.
//!
//! Every built-in scenario (the large generated maps included) and a sample of the
//! hard-case family are planned through the library's facade, exactly as `arc plan
//! --trajectory` plans them, at each limit. The time after setup is the facade's wall
//! time less its own setup (collision context and planner); the map's distance field
//! and the shape tables are built once per scenario and chain before the clock starts,
//! as `arc plan` times them apart.

use std::collections::btree_map::Entry;
use std::collections::BTreeMap;
use std::sync::atomic::AtomicUsize;
use std::sync::Arc;
use std::time::Instant;

use aerial_chain::goal::GoalPose;
use aerial_chain::map::DistanceField;
use aerial_chain::plan_file::MapSection;
use aerial_chain::planner::Query;
use aerial_chain::planning::{self, PlanOptions, PlanningError, Request};
use aerial_chain::problem::scenarios::{self, Scenario};
use aerial_chain::tables::{ShapeTables, TableSettings};
use aerial_chain_core::ChainParams;

use super::report::{csv_table, missed, Column};
use super::statistics::nearest_rank;
use super::StudyError;

/// The built-in scenarios, each at its default chain size.
pub const BUILT_IN: [&str; 7] = [
    "window",
    "maze",
    "silos",
    "corridor",
    "corridor:100",
    "campus",
    "hall",
];

/// The promise's allowance past the limit (s).
pub const SLACK_S: f64 = 0.05;

/// The bound the promise puts on the time after setup at limit `t` (s).
pub fn bound(t: f64) -> f64 {
    1.1 * t + SLACK_S
}

/// One query at one limit.
#[derive(Clone, Debug)]
pub struct LimitRun {
    /// The scenario's name.
    pub scenario: String,
    /// Chain size.
    pub units: u8,
    /// The time limit (s).
    pub limit_s: f64,
    /// Wall time after setup (s).
    pub after_setup_s: f64,
    /// `plan`, `no plan` or the error's text.
    pub outcome: String,
    /// The trajectory's blending rounds were stopped by the limit.
    pub cut_short: bool,
}

impl LimitRun {
    /// Whether the run kept the promise.
    pub fn kept(&self) -> bool {
        self.after_setup_s <= bound(self.limit_s)
    }
}

/// Runs every `(scenario, units)` job at every limit in `limits_s` (s).
pub fn run(jobs: &[(String, u8)], limits_s: &[f64]) -> Result<Vec<LimitRun>, StudyError> {
    let tables = tables_for(jobs.iter().map(|(_, n)| *n))?;
    let mut out = Vec::with_capacity(jobs.len() * limits_s.len());
    for (name, units) in jobs {
        let sc = scenarios::build(name)?;
        let request = request(&sc, &field_of(&sc), *units)?;
        for &limit_s in limits_s {
            out.push(one(name, &request, &tables[units], limit_s));
        }
    }
    Ok(out)
}

/// Every chain size of `units` once, with its default shape tables.
pub(super) fn tables_for(
    units: impl IntoIterator<Item = u8>,
) -> Result<BTreeMap<u8, ShapeTables>, StudyError> {
    let mut out = BTreeMap::new();
    for n in units {
        if let Entry::Vacant(e) = out.entry(n) {
            e.insert(default_tables(n)?);
        }
    }
    Ok(out)
}

/// `sc`'s distance field, built once for every chain size that plans on it.
pub(super) fn field_of(sc: &Scenario) -> Arc<DistanceField> {
    Arc::new(DistanceField::new(sc.grid.clone()))
}

/// `sc`'s query for a chain of `units` on `field`, as `Request::new` makes it.
pub(super) fn request(
    sc: &Scenario,
    field: &Arc<DistanceField>,
    units: u8,
) -> Result<Request, StudyError> {
    let query = Query::new(sc.start, sc.start_shape(units)?, sc.goal);
    Ok(Request {
        field: field.clone(),
        params: ChainParams::new(units),
        query,
        pose: GoalPose::default(),
        map: MapSection::of(&sc.grid),
    })
}

/// The shape tables `arc plan` builds by default for a chain of `units`.
pub(super) fn default_tables(units: u8) -> Result<ShapeTables, StudyError> {
    let params = ChainParams::new(units);
    ShapeTables::build(params, &TableSettings::default(), &AtomicUsize::new(0)).map_err(|e| {
        StudyError::Tables {
            units,
            why: e.to_string(),
        }
    })
}

/// `request` planned as `arc plan --trajectory --time-limit limit_s` plans it.
fn one(name: &str, request: &Request, tables: &ShapeTables, limit_s: f64) -> LimitRun {
    let options = PlanOptions {
        time_limit_s: Some(limit_s),
        trajectory: Some(Default::default()),
        ..PlanOptions::default()
    };
    let t = timed(request, tables, &options);
    LimitRun {
        scenario: name.to_string(),
        units: request.params.units,
        limit_s,
        after_setup_s: t.after_setup_s,
        outcome: t.outcome,
        cut_short: t.cut_short,
    }
}

/// One query through the facade, timed after its setup.
pub struct Timed {
    /// Wall time after setup (s).
    pub after_setup_s: f64,
    /// `plan`, `no plan` or the error's text.
    pub outcome: String,
    /// Why there is no plan (the message `arc plan` prints), or empty.
    pub why: String,
    /// The trajectory's blending rounds were stopped by the limit.
    pub cut_short: bool,
}

/// `request` planned through the facade with `tables` and `options`, the time after
/// the facade's own setup measured.
pub fn timed(request: &Request, tables: &ShapeTables, options: &PlanOptions) -> Timed {
    let began = Instant::now();
    let result = planning::plan(request, Some(tables.clone()), options);
    let wall = began.elapsed().as_secs_f64();
    let (setup_s, outcome, why, cut_short) = match &result {
        Ok(p) => {
            let cut = matches!(&p.trajectory, Some(Ok(t)) if t.cut_short());
            (p.timings.setup_s, "plan".into(), String::new(), cut)
        }
        Err(PlanningError::NoPlan(np)) => (np.setup_s, "no plan".into(), np.to_string(), false),
        Err(e) => (0.0, e.to_string(), e.to_string(), false),
    };
    Timed {
        after_setup_s: wall - setup_s,
        outcome,
        why,
        cut_short,
    }
}

/// The markdown summary: per limit, the runs, their outcomes and the time after setup
/// against the bound; then every run that broke the promise.
pub fn markdown(runs: &[LimitRun]) -> String {
    let mut s = String::from(
        "| limit T (ms) | bound 1.1 T + 50 ms | runs | plans | no plan | trajectories cut short | after setup: median / p95 / max (ms) | largest / bound | over the bound |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    let mut limits: Vec<f64> = runs.iter().map(|r| r.limit_s).collect();
    limits.sort_by(f64::total_cmp);
    limits.dedup();
    for t in limits {
        let at: Vec<&LimitRun> = runs.iter().filter(|r| r.limit_s == t).collect();
        let times: Vec<f64> = at.iter().map(|r| r.after_setup_s).collect();
        let count = |f: &dyn Fn(&LimitRun) -> bool| at.iter().filter(|r| f(r)).count();
        let max = nearest_rank(&times, 1.0);
        s += &format!(
            "| {:.0} | {:.1} | {} | {} | {} | {} | {:.1} / {:.1} / {:.1} | {:.2} | {} |\n",
            t * 1e3,
            bound(t) * 1e3,
            at.len(),
            count(&|r| r.outcome == "plan"),
            count(&|r| r.outcome == "no plan"),
            count(&|r| r.cut_short),
            nearest_rank(&times, 0.5) * 1e3,
            nearest_rank(&times, 0.95) * 1e3,
            max * 1e3,
            max / bound(t),
            count(&|r| !r.kept()),
        );
    }
    s += &missed("Over the bound", &OVER_COLUMNS, runs, LimitRun::kept);
    s
}

/// The columns of the runs over the bound.
const OVER_COLUMNS: [Column<LimitRun>; 5] = [
    ("scenario", |r| format!("`{}`", r.scenario)),
    ("N", |r| r.units.to_string()),
    ("limit (ms)", |r| format!("{:.0}", r.limit_s * 1e3)),
    ("after setup (ms)", |r| {
        format!("{:.1}", r.after_setup_s * 1e3)
    }),
    ("outcome", |r| r.outcome.clone()),
];

/// The CSV's columns.
const CSV_COLUMNS: [Column<LimitRun>; 8] = [
    ("scenario", |r| format!("\"{}\"", r.scenario)),
    ("units", |r| r.units.to_string()),
    ("limit_s", |r| r.limit_s.to_string()),
    ("after_setup_s", |r| format!("{:.6}", r.after_setup_s)),
    ("bound_s", |r| format!("{:.6}", bound(r.limit_s))),
    ("kept", |r| r.kept().to_string()),
    ("outcome", |r| {
        format!("\"{}\"", r.outcome.replace('"', "'"))
    }),
    ("cut_short", |r| r.cut_short.to_string()),
];

/// Every run as CSV.
pub fn csv(runs: &[LimitRun]) -> String {
    csv_table(&CSV_COLUMNS, runs)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_run_is_judged_against_its_bound_and_summarised() {
        let run = |after: f64, outcome: &str| LimitRun {
            scenario: "window".into(),
            units: 5,
            limit_s: 0.01,
            after_setup_s: after,
            outcome: outcome.into(),
            cut_short: false,
        };
        let fast = LimitRun {
            limit_s: 0.001,
            ..run(0.001, "plan")
        };
        let runs = [run(0.02, "plan"), fast, run(0.07, "no plan")];
        assert!(runs[0].kept() && runs[1].kept());
        assert!(
            !runs[2].kept(),
            "0.07 s is past 1.1 x 0.01 + 0.05 = 0.061 s"
        );
        let md = markdown(&runs);
        assert!(md.contains("| 10 | 61.0 | 2 | 1 | 1 | 0 |"), "{md}");
        assert!(md.contains("| 1 | 51.1 | 1 | 1 | 0 | 0 |"), "{md}");
        assert_eq!(
            md.matches("| 10 | 61.0 |").count(),
            1,
            "one row a limit: {md}"
        );
        assert!(md.contains("Over the bound"), "{md}");
        assert_eq!(csv(&runs).lines().count(), 4);
    }

    #[test]
    fn the_facade_is_timed_after_its_setup_on_a_built_in_scenario() {
        let runs = run(&[("window".into(), 3)], &[0.01]).unwrap();
        assert_eq!(runs.len(), 1);
        let r = &runs[0];
        assert!(
            r.outcome == "plan" || r.outcome == "no plan",
            "{}",
            r.outcome
        );
        assert!(r.after_setup_s > 0.0 && r.after_setup_s.is_finite());
    }
}
