//! `arc bench refuse`: queries with no plan, refused with `arc plan`'s defaults, and
//! how long after setup the refusal takes (docs/promises.md: a refusal on the family
//! and the large maps ends within 1 s after setup, with a proof).
//!
//! The queries: hard-case instances whose only opening is one or three slits
//! narrower than a unit (`passage:slit=W,slits=K`, at 0.025-0.1 m, straight on and 30
//! degrees off), sealed windows, shafts a unit fits but no link can leave (`shaft:`,
//! hatches of 0.4 and 0.45 m through floors 1 and 1.5 m thick, where the hatch as
//! built is narrow enough: `ShaftSpec::closed`), and the goal of each
//! large generated map walled into a box (0.2 m walls, 1 m clear inside). Each is
//! planned through the library's facade at N = 4, 6 and 8.

use aerial_chain::map::Cell;
use aerial_chain::planning::PlanOptions;
use aerial_chain::problem::scenarios::{self, Scenario};
use aerial_chain::problem::shafts::ShaftSpec;
use aerial_chain::problem::spec::Family;
use aerial_chain_core::ChainParams;

use super::limit::{field_of, request, tables_for, timed};
use super::report::{csv_table, missed, Column};
use super::statistics::nearest_rank;
use super::StudyError;

/// Chain sizes every query is asked at.
pub const UNITS: [u8; 3] = [4, 6, 8];

/// What a refusal must take at most after setup (s).
pub const TARGET_S: f64 = 1.0;

/// One refused (or not) query.
#[derive(Clone, Debug)]
pub struct Refusal {
    /// The scenario's name (`+box`: its goal walled in).
    pub scenario: String,
    /// Chain size.
    pub units: u8,
    /// Wall time after setup (s).
    pub after_setup_s: f64,
    /// `no plan`, `plan` (a wrong answer) or the error's text.
    pub outcome: String,
    /// The proof or reason the refusal gave, in short.
    pub reason: &'static str,
}

impl Refusal {
    /// A refusal with a proof, within [`TARGET_S`].
    pub fn kept(&self) -> bool {
        self.outcome == "no plan" && PROOFS.contains(&self.reason) && self.after_setup_s <= TARGET_S
    }
}

/// The reasons that prove a query has no plan (the others give up).
const PROOFS: [&str; 2] = ["separate regions", "no unit holds its link"];

/// The study's scenario names: slits and sealed windows of the family, shafts, then
/// the large maps (whose goals are walled in by [`walled_goal`]).
pub fn names() -> Vec<String> {
    let mut out = Vec::new();
    for res in [0.025, 0.05, 0.087, 0.1] {
        for angle in [0, 30] {
            for (w, k) in [(0.1, 1), (0.2, 3), (0.25, 3)] {
                out.push(format!(
                    "passage:w=0.5,angle={angle},offset=0,wall=0.2,res={res},slit={w},slits={k}"
                ));
            }
            out.push(format!(
                "passage:w=0.5,angle={angle},offset=0,wall=0.2,res={res},sealed=1"
            ));
        }
        // Only shafts no chain passes (as built: the hatch widens to whole voxels).
        for (w, depth) in [(0.4, 1.0), (0.45, 1.5)] {
            let spec = ShaftSpec { w, depth, res };
            if spec.closed(&ChainParams::new(UNITS[0])) {
                out.push(spec.name());
            }
        }
    }
    out.extend(["campus".to_string(), "hall".to_string()]);
    out
}

/// `sc` with its goal inside a closed box: 0.2 m walls around a 2 m cube of free
/// space centred on the goal (the large maps' stand-in for a room with no door).
pub fn walled_goal(mut sc: Scenario) -> Scenario {
    let g = sc.goal;
    let (inner, wall) = (1.0, 0.2);
    let (lo, hi) = (
        [g.x - inner - wall, g.y - inner - wall, g.z - inner - wall],
        [g.x + inner + wall, g.y + inner + wall, g.z + inner + wall],
    );
    sc.grid.fill_box(lo, hi, Cell::Occupied);
    sc.grid.fill_box(
        [g.x - inner, g.y - inner, g.z - inner],
        [g.x + inner, g.y + inner, g.z + inner],
        Cell::Free,
    );
    sc.name += "+box";
    sc
}

/// Plans every scenario of [`names`] at every N of [`UNITS`] with `arc plan`'s
/// defaults.
pub fn run() -> Result<Vec<Refusal>, StudyError> {
    let tables = tables_for(UNITS)?;
    let mut out = Vec::new();
    for name in names() {
        let mut sc = scenarios::build(&name)?;
        if !name.contains(':') {
            sc = walled_goal(sc);
        }
        let field = field_of(&sc);
        for n in UNITS {
            let request = request(&sc, &field, n)?;
            let t = timed(&request, &tables[&n], &PlanOptions::default());
            out.push(Refusal {
                scenario: sc.name.clone(),
                units: n,
                after_setup_s: t.after_setup_s,
                outcome: t.outcome,
                reason: reason(&t.why),
            });
        }
    }
    Ok(out)
}

/// The kind of a refusal's message.
fn reason(why: &str) -> &'static str {
    if why.contains("separate free regions") {
        "separate regions"
    } else if why.contains("no unit can hold its link") {
        "no unit holds its link"
    } else if why.contains("no shape fits") {
        "no shape fits the narrowest stretch"
    } else if why.contains("time limit") {
        "time limit"
    } else if why.is_empty() {
        "-"
    } else {
        "other"
    }
}

/// Whether a scenario's name is of a group of the summary.
type Kind = fn(&str) -> bool;

/// The markdown summary: per group of scenarios, the refusals, their reasons and
/// times; then every run that missed the target.
pub fn markdown(runs: &[Refusal]) -> String {
    let mut s = String::from(
        "| queries | runs | refused with a proof within 1 s | reasons | after setup: median / max (ms) |\n|---|---|---|---|---|\n",
    );
    let groups: [(&str, Kind); 4] = [
        ("slits narrower than a unit", |n| n.contains("slit=")),
        ("sealed windows", |n| n.contains("sealed=1")),
        ("shafts a unit fits, no link", |n| n.starts_with("shaft:")),
        ("large maps, goal walled in", |n| n.ends_with("+box")),
    ];
    for (label, is) in groups {
        let at: Vec<&Refusal> = runs.iter().filter(|r| is(&r.scenario)).collect();
        let times: Vec<f64> = at.iter().map(|r| r.after_setup_s).collect();
        let mut reasons: Vec<&str> = at.iter().map(|r| r.reason).collect();
        reasons.sort_unstable();
        reasons.dedup();
        let count = |k: &str| at.iter().filter(|r| r.reason == k).count();
        let listed: Vec<String> = reasons
            .iter()
            .map(|k| format!("{k} {}", count(k)))
            .collect();
        s += &format!(
            "| {label} | {} | {} | {} | {:.1} / {:.1} |\n",
            at.len(),
            at.iter().filter(|r| r.kept()).count(),
            listed.join(", "),
            nearest_rank(&times, 0.5) * 1e3,
            nearest_rank(&times, 1.0) * 1e3,
        );
    }
    s += &missed("Missed", &MISSED_COLUMNS, runs, Refusal::kept);
    s
}

/// The columns of the runs that missed the target.
const MISSED_COLUMNS: [Column<Refusal>; 5] = [
    ("scenario", |r| format!("`{}`", r.scenario)),
    ("N", |r| r.units.to_string()),
    ("after setup (ms)", |r| {
        format!("{:.1}", r.after_setup_s * 1e3)
    }),
    ("outcome", |r| r.outcome.clone()),
    ("reason", |r| r.reason.to_string()),
];

/// The CSV's columns.
const CSV_COLUMNS: [Column<Refusal>; 6] = [
    ("scenario", |r| format!("\"{}\"", r.scenario)),
    ("units", |r| r.units.to_string()),
    ("after_setup_s", |r| format!("{:.6}", r.after_setup_s)),
    ("outcome", |r| {
        format!("\"{}\"", r.outcome.replace('"', "'"))
    }),
    ("reason", |r| format!("\"{}\"", r.reason)),
    ("kept", |r| r.kept().to_string()),
];

/// Every run as CSV.
pub fn csv(runs: &[Refusal]) -> String {
    csv_table(&CSV_COLUMNS, runs)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_name_builds_and_the_walled_goal_is_closed() {
        for name in names().iter().filter(|n| n.contains(':')) {
            scenarios::build(name).unwrap_or_else(|e| panic!("{name}: {e}"));
        }
        let sc = walled_goal(scenarios::build("window").unwrap());
        let g = sc.goal;
        assert!(!sc.grid.is_obstacle_at(g));
        for d in [[1.1, 0.0, 0.0], [0.0, -1.1, 0.0], [0.0, 0.0, 1.1]] {
            assert!(sc.grid.is_obstacle_at([g.x + d[0], g.y + d[1], g.z + d[2]]));
        }
        assert!(sc.name.ends_with("+box"));
    }

    #[test]
    fn a_refusal_counts_only_with_a_proof_in_time() {
        let r = |outcome: &str, reason: &'static str, t: f64| Refusal {
            scenario: "passage:slit=0.2".into(),
            units: 4,
            after_setup_s: t,
            outcome: outcome.into(),
            reason,
        };
        assert!(r("no plan", "separate regions", 0.02).kept());
        assert!(!r("no plan", "time limit", 0.5).kept());
        assert!(r("no plan", "no unit holds its link", 0.3).kept());
        assert!(!r("no plan", "no shape fits the narrowest stretch", 0.3).kept());
        assert!(!r("no plan", "separate regions", 1.5).kept());
        assert!(!r("plan", "-", 0.1).kept());
        let md = markdown(&[r("no plan", "separate regions", 0.02), r("plan", "-", 0.1)]);
        assert!(
            md.contains("| slits narrower than a unit | 2 | 1 |"),
            "{md}"
        );
        assert!(md.contains("Missed"), "{md}");
        assert_eq!(
            reason("no plan: time limit reached after 0 replans"),
            "time limit"
        );
    }
}
