//! `arc bench families`: the forest, tilted-slot and pipe families
//! ([`aerial_chain::problem::families`], [`aerial_chain::problem::pipes`]) with `arc
//! plan`'s defaults: how often a plan comes, whether the exact verifier accepts it, and
//! what the query costs after setup (its structures and both searches: the planner's
//! own query time, against the targets of 10 ms for a forest at N = 7 and 5 ms for a
//! slot). In a pipe the plan's clearance is held against the witness's (a chain
//! following its head along the axis): where the witness keeps the default clearance
//! the plan must keep it too, elsewhere 0.9 of the witness's.
//!
//! Instances are drawn from a seeded generator: forests of spacing 1-1.5 m at 0.1 m or
//! 0.05 m; slots tilted 15-60 degrees, approached 0-45 degrees off the normal either way,
//! at 0.05 m. Pipes are every bore of 0.6, 0.76, 0.9 and 1.2 m, round and square,
//! straight, with an elbow and with an S-bend, at 0.05 m.

use rand::{Rng, SeedableRng};

use aerial_chain::collision::verify_plan;
use aerial_chain::collision::DEFAULT_CLEARANCE;
use aerial_chain::planning::{self, PlanOptions};
use aerial_chain::problem::families::{ForestSpec, SlotSpec};
use aerial_chain::problem::pipes::PipeSpec;
use aerial_chain::problem::scenarios::{self, Scenario};
use aerial_chain::problem::spec::Family;
use aerial_chain::witness::witness;
use aerial_chain_core::ChainParams;

use super::limit::{field_of, request, tables_for};
use super::StudyError;

/// One query of a family.
#[derive(Clone, Debug)]
pub struct FamilyRun {
    /// `forest` or `slot`.
    pub family: &'static str,
    /// The instance's name.
    pub scenario: String,
    /// Chain size.
    pub units: u8,
    /// A plan came and the exact verifier accepts it.
    pub verified: bool,
    /// Whether a plan came at all.
    pub planned: bool,
    /// Structures and search of the query (s): the facade's search time.
    pub query_s: f64,
    /// Post-processing (s).
    pub post_s: f64,
    /// In a pipe: the plan's smallest clearance (m) and what it must keep (m).
    pub clearance: Option<(f64, f64)>,
}

impl FamilyRun {
    /// Whether a pipe's plan keeps its clearance target (`None` elsewhere, or
    /// without a plan).
    pub fn at_target(&self) -> Option<bool> {
        self.clearance.map(|(c, t)| c >= t - 1e-9)
    }
}

/// The drawn instances: `count` forests and `count` slots, with their chain sizes.
pub fn instances(count: usize, seed: u64) -> Vec<(&'static str, String, Vec<u8>)> {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let mut out = Vec::new();
    for k in 0..count {
        let f = ForestSpec {
            spacing: (rng.gen_range(1.0f64..=1.5) * 100.0).round() / 100.0,
            seed: k as u64 + 1,
            res: if k % 2 == 0 { 0.1 } else { 0.05 },
        };
        out.push(("forest", f.name(), vec![5, 6, 7, 8]));
    }
    for _ in 0..count {
        let sign = if rng.gen_bool(0.5) { 1.0 } else { -1.0 };
        let s = SlotSpec {
            tilt_deg: rng.gen_range(15.0f64..=60.0).round(),
            angle_deg: sign * rng.gen_range(0.0f64..=45.0).round(),
            res: 0.05,
        };
        out.push(("slot", s.name(), vec![4, 5, 6]));
    }
    for d in [0.6, 0.76, 0.9, 1.2] {
        for square in [false, true] {
            for bends in 0..=2 {
                let p = PipeSpec {
                    d,
                    square,
                    bends,
                    ..PipeSpec::default()
                };
                out.push(("pipe", p.name(), vec![4, 6, 8]));
            }
        }
    }
    out
}

/// What a plan in a pipe must keep: the default clearance where the witness keeps it,
/// else 0.9 of the witness's clearance; `None` without a witness.
fn pipe_target(sc: &Scenario, params: &ChainParams) -> Option<f64> {
    let plan = witness(sc, params).ok()?;
    let kept = verify_plan(&sc.grid, &plan).min_clearance;
    Some(if kept >= DEFAULT_CLEARANCE {
        DEFAULT_CLEARANCE
    } else {
        0.9 * kept
    })
}

/// Plans every instance of [`instances`] at each of its chain sizes.
pub fn run(count: usize, seed: u64) -> Result<Vec<FamilyRun>, StudyError> {
    run_on(instances(count, seed))
}

/// Plans every `(family, name, chain sizes)` at each of its chain sizes.
fn run_on(jobs: Vec<(&'static str, String, Vec<u8>)>) -> Result<Vec<FamilyRun>, StudyError> {
    let tables = tables_for(jobs.iter().flat_map(|(_, _, units)| units.iter().copied()))?;
    let mut out = Vec::new();
    for (family, name, units) in jobs {
        let sc = scenarios::build(&name)?;
        let field = field_of(&sc);
        for n in units {
            let request = request(&sc, &field, n)?;
            let result =
                planning::plan(&request, Some(tables[&n].clone()), &PlanOptions::default());
            let mut run = FamilyRun {
                family,
                scenario: name.clone(),
                units: n,
                verified: false,
                planned: false,
                query_s: 0.0,
                post_s: 0.0,
                clearance: None,
            };
            match result {
                Ok(p) => {
                    run.planned = true;
                    let report = verify_plan(&sc.grid, &p.plan);
                    run.verified = report.ok;
                    if family == "pipe" {
                        run.clearance = pipe_target(&sc, &ChainParams::new(n))
                            .map(|t| (report.min_clearance, t));
                    }
                    run.query_s = p.timings.search_s;
                    run.post_s = p.timings.post_s;
                }
                Err(planning::PlanningError::NoPlan(np)) => run.query_s = np.planning_s,
                Err(e) => {
                    return Err(StudyError::Refused {
                        scenario: name.clone(),
                        why: e.to_string(),
                    })
                }
            }
            out.push(run);
        }
    }
    Ok(out)
}

/// The median of `v`, 0 when empty.
fn median(v: Vec<f64>) -> f64 {
    super::statistics::nearest_rank(&v, 0.5)
}

/// The markdown summary: per family and N.
pub fn markdown(runs: &[FamilyRun]) -> String {
    let mut s = String::from(
        "| family | N | queries | plans | verified | structures + search: median / max (ms) | post-processing median (ms) | at the clearance target |\n|---|---|---|---|---|---|---|---|\n",
    );
    let mut keys: Vec<(&str, u8)> = runs.iter().map(|r| (r.family, r.units)).collect();
    keys.sort_unstable();
    keys.dedup();
    for (family, n) in keys {
        let at: Vec<&FamilyRun> = runs
            .iter()
            .filter(|r| r.family == family && r.units == n)
            .collect();
        let q: Vec<f64> = at.iter().map(|r| r.query_s).collect();
        let max = q.iter().copied().fold(0.0, f64::max);
        let judged: Vec<bool> = at.iter().filter_map(|r| r.at_target()).collect();
        let target = match family {
            "pipe" => format!(
                "{} of {}",
                judged.iter().filter(|&&k| k).count(),
                judged.len()
            ),
            _ => "-".into(),
        };
        s += &format!(
            "| {family} | {n} | {} | {} | {} | {:.1} / {:.1} | {:.1} | {target} |\n",
            at.len(),
            at.iter().filter(|r| r.planned).count(),
            at.iter().filter(|r| r.verified).count(),
            median(q) * 1e3,
            max * 1e3,
            median(at.iter().map(|r| r.post_s).collect()) * 1e3,
        );
    }
    s
}

/// Every run as CSV.
pub fn csv(runs: &[FamilyRun]) -> String {
    let mut s = String::from(
        "family,scenario,units,planned,verified,query_s,post_s,clearance_m,target_m\n",
    );
    for r in runs {
        let (c, t) = match r.clearance {
            Some((c, t)) => (format!("{c:.4}"), format!("{t:.4}")),
            None => (String::new(), String::new()),
        };
        s += &format!(
            "{},\"{}\",{},{},{},{:.6},{:.6},{c},{t}\n",
            r.family, r.scenario, r.units, r.planned, r.verified, r.query_s, r.post_s
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn instances_build_and_one_of_each_plans_and_verifies() {
        let drawn = instances(2, 1);
        assert_eq!(drawn.len(), 4 + 24);
        for (_, name, _) in &drawn {
            scenarios::build(name).unwrap_or_else(|e| panic!("{name}: {e}"));
        }
        let jobs = instances(1, 1)
            .into_iter()
            .filter(|(f, name, _)| *f != "pipe" || name.contains("d=1.2,square=0,bends=0"))
            .collect();
        let runs = run_on(jobs).unwrap();
        assert_eq!(runs.len(), 4 + 3 + 3);
        let md = markdown(&runs);
        assert!(md.contains("| forest | 7 | 1 |"), "{md}");
        assert!(md.contains("| slot | 4 | 1 |"), "{md}");
        // A slot's 0.5 m side lets a chain in a line through: every N plans.
        assert!(runs
            .iter()
            .filter(|r| r.family == "slot")
            .all(|r| r.verified));
        // A wide straight pipe: the plan keeps the clearance, as the witness does.
        assert!(runs
            .iter()
            .filter(|r| r.family == "pipe")
            .all(|r| r.at_target() == Some(true)));
        assert_eq!(csv(&runs).lines().count(), 11);
    }
}
