//! Statistics over benchmark runs: medians and quartiles per study, method, scenario
//! and chain size.

use std::collections::BTreeMap;

use super::report::{count, ms};
use super::{RunKey, RunResult};

/// Order statistics of a sample.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Spread {
    /// Number of values.
    pub n: usize,
    /// Median.
    pub median: f64,
    /// First quartile.
    pub q1: f64,
    /// Third quartile.
    pub q3: f64,
    /// Smallest.
    pub min: f64,
    /// Largest.
    pub max: f64,
}

/// Quantile `q` (0..=1) of sorted values, linear between order statistics.
pub(super) fn quantile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let h = (sorted.len() - 1) as f64 * q;
    let (lo, hi) = (h.floor() as usize, h.ceil() as usize);
    sorted[lo] + (h - lo as f64) * (sorted[hi] - sorted[lo])
}

/// Quantile `q` (0..=1) of `values` in any order, the nearest rank (0 when empty), as
/// the tables of `arc bench robust`, `limit`, `refuse` and `families` give it.
pub(super) fn nearest_rank(values: &[f64], q: f64) -> f64 {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    aerial_chain::online::quantile(&sorted, q)
}

impl Spread {
    /// The spread of `values` (NaN fields when empty).
    pub fn of(values: impl IntoIterator<Item = f64>) -> Self {
        let mut v: Vec<f64> = values.into_iter().filter(|x| x.is_finite()).collect();
        v.sort_by(f64::total_cmp);
        Self {
            n: v.len(),
            median: quantile(&v, 0.5),
            q1: quantile(&v, 0.25),
            q3: quantile(&v, 0.75),
            min: v.first().copied().unwrap_or(f64::NAN),
            max: v.last().copied().unwrap_or(f64::NAN),
        }
    }
}

/// The aggregate of the runs of one group (same study, scenario, N, planner, budgets).
#[derive(Clone, Debug, PartialEq)]
pub struct Summary {
    /// The group.
    pub key: RunKey,
    /// Time limit (s).
    pub time_limit: Option<f64>,
    /// Runs.
    pub runs: usize,
    /// Successful runs.
    pub successes: usize,
    /// Successful runs whose plan passed exact verification.
    pub verified: usize,
    /// Runs stopped by the time limit.
    pub time_limited: usize,
    /// Roadmap build, all runs (s).
    pub roadmap: Spread,
    /// Query, successful runs (s).
    pub planning: Spread,
    /// Query, all runs (s).
    pub planning_all: Spread,
    /// Build plus query, all runs (s).
    pub total_all: Spread,
    /// Build plus query, successful runs (s).
    pub total_ok: Spread,
    /// CPU time of the roadmap build, all runs (s).
    pub roadmap_cpu: Spread,
    /// CPU time of the query, successful runs (s).
    pub planning_cpu: Spread,
    /// CPU time of build plus query, all runs (s).
    pub total_cpu_all: Spread,
    /// Collision checks in the query, successful runs (s).
    pub collision: Spread,
    /// The rest of the query, successful runs (s).
    pub search: Spread,
    /// Shape changes, successful runs.
    pub shape_changes: Spread,
    /// Replans, successful runs.
    pub replans: Spread,
    /// Tables build, all runs (s).
    pub tables: Spread,
}

impl Summary {
    /// The cells every results table shares, in this order: success, verified, t_G,
    /// t_P, t_P CPU, shape changes, replans.
    pub fn outcome_cells(&self) -> String {
        format!(
            "{} | {} | {} | {} | {} | {}",
            self.success_cells(),
            ms(&self.roadmap),
            ms(&self.planning),
            ms(&self.planning_cpu),
            count(&self.shape_changes),
            count(&self.replans)
        )
    }

    /// The success and verified cells: `successes/runs | verified/successes`.
    pub fn success_cells(&self) -> String {
        let (ok, runs, verified) = (self.successes, self.runs, self.verified);
        format!("{ok}/{runs} | {verified}/{ok}")
    }

    /// Success rate (0..=1).
    pub fn success_rate(&self) -> f64 {
        if self.runs == 0 {
            0.0
        } else {
            self.successes as f64 / self.runs as f64
        }
    }
}

/// Groups results by (study, scenario, N, planner, budgets), in first-seen order.
pub fn summarize(results: &[RunResult]) -> Vec<Summary> {
    let mut order: Vec<RunKey> = Vec::new();
    let mut groups: BTreeMap<RunKey, Vec<&RunResult>> = BTreeMap::new();
    for r in results {
        let key = r.spec.key.clone();
        if !groups.contains_key(&key) {
            order.push(key.clone());
        }
        groups.entry(key).or_default().push(r);
    }
    order
        .into_iter()
        .map(|key| {
            let rs = &groups[&key];
            let ok: Vec<&&RunResult> = rs.iter().filter(|r| r.success).collect();
            Summary {
                key,
                time_limit: rs[0].spec.time_limit,
                runs: rs.len(),
                successes: ok.len(),
                verified: ok.iter().filter(|r| r.verified == Some(true)).count(),
                time_limited: rs.iter().filter(|r| r.outcome == "time_limit").count(),
                roadmap: Spread::of(rs.iter().map(|r| r.roadmap_s)),
                planning: Spread::of(ok.iter().map(|r| r.planning_s)),
                planning_all: Spread::of(rs.iter().map(|r| r.planning_s)),
                total_all: Spread::of(rs.iter().map(|r| r.total_s())),
                total_ok: Spread::of(ok.iter().map(|r| r.total_s())),
                roadmap_cpu: Spread::of(rs.iter().filter_map(|r| r.roadmap_cpu_s)),
                planning_cpu: Spread::of(ok.iter().filter_map(|r| r.planning_cpu_s)),
                total_cpu_all: Spread::of(rs.iter().filter_map(|r| r.total_cpu_s())),
                collision: Spread::of(ok.iter().filter_map(|r| r.collision_s)),
                search: Spread::of(ok.iter().filter_map(|r| r.search_s)),
                shape_changes: Spread::of(
                    ok.iter().filter_map(|r| r.shape_changes.map(|x| x as f64)),
                ),
                replans: Spread::of(ok.iter().filter_map(|r| r.replans.map(|x| x as f64))),
                tables: Spread::of(rs.iter().map(|r| r.tables_s)),
            }
        })
        .collect()
}
