//! `arc bench families`: the forest and tilted-slot families
//! ([`aerial_chain::problem::families`]) with `arc plan`'s defaults: how often a plan
//! comes, whether the exact verifier accepts it, and what the query costs after setup
//! (its structures and both searches: the planner's own query time, against the
//! targets of 10 ms for a forest at N = 7 and 5 ms for a slot).
//!
//! Instances are drawn from a seeded generator: forests of spacing 1-1.5 m at 0.1 m or
//! 0.05 m; slots tilted 15-60 degrees, approached 0-45 degrees off the normal either way,
//! at 0.05 m.

use rand::{Rng, SeedableRng};

use aerial_chain::collision::verify_plan;
use aerial_chain::planner::Query;
use aerial_chain::planning::{self, PlanOptions, Request};
use aerial_chain::problem::families::{ForestSpec, SlotSpec};
use aerial_chain::problem::scenarios;
use aerial_chain::tables::ShapeTables;
use aerial_chain_core::ChainParams;

use super::limit::default_tables;
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
    out
}

/// Plans every instance at each of its chain sizes.
pub fn run(count: usize, seed: u64) -> Result<Vec<FamilyRun>, StudyError> {
    let mut tables: Vec<(u8, ShapeTables)> = Vec::new();
    let mut out = Vec::new();
    for (family, name, units) in instances(count, seed) {
        let sc = scenarios::build(&name)?;
        for n in units {
            if !tables.iter().any(|(m, _)| *m == n) {
                tables.push((n, default_tables(n)?));
            }
            let t = &tables.iter().find(|(m, _)| *m == n).expect("built above").1;
            let query = Query::new(sc.start, sc.start_shape(n)?, sc.goal);
            let request = Request::new(sc.grid.clone(), ChainParams::new(n), query);
            let result = planning::plan(&request, Some(t.clone()), &PlanOptions::default());
            let mut run = FamilyRun {
                family,
                scenario: name.clone(),
                units: n,
                verified: false,
                planned: false,
                query_s: 0.0,
                post_s: 0.0,
            };
            match result {
                Ok(p) => {
                    run.planned = true;
                    run.verified = verify_plan(&sc.grid, &p.plan).ok;
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
fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// The markdown summary: per family and N.
pub fn markdown(runs: &[FamilyRun]) -> String {
    let mut s = String::from(
        "| family | N | queries | plans | verified | structures + search: median / max (ms) | post-processing median (ms) |\n|---|---|---|---|---|---|---|\n",
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
        s += &format!(
            "| {family} | {n} | {} | {} | {} | {:.1} / {:.1} | {:.1} |\n",
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
    let mut s = String::from("family,scenario,units,planned,verified,query_s,post_s\n");
    for r in runs {
        s += &format!(
            "{},\"{}\",{},{},{},{:.6},{:.6}\n",
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
        assert_eq!(drawn.len(), 4);
        for (_, name, _) in &drawn {
            scenarios::build(name).unwrap_or_else(|e| panic!("{name}: {e}"));
        }
        let runs = run(1, 1).unwrap();
        assert_eq!(runs.len(), 4 + 3);
        let md = markdown(&runs);
        assert!(md.contains("| forest | 7 | 1 |"), "{md}");
        assert!(md.contains("| slot | 4 | 1 |"), "{md}");
        // A slot's 0.5 m side lets a chain in a line through: every N plans.
        assert!(runs
            .iter()
            .filter(|r| r.family == "slot")
            .all(|r| r.verified));
        assert_eq!(csv(&runs).lines().count(), 8);
    }
}
