//! MotionPlan: a solution of any planner as an `arc-plan/1` file (docs/model.md
//! "Files"), and the ARC planner's waypoint labels and plan quality in it.
//!
//! Waypoint 0 is the start; each head edge becomes its shape changes (head fixed)
//! then one translation (shape fixed). Timings go under `stats.timing`, the only
//! part of a plan that differs between two runs with the same seed.

use aerial_chain_core::ChainParams;
use serde_json::Value;

use super::candidates::Source;
use super::{Quality, Refinement};
use super::{Solution, SolutionStats};
use crate::plan_file::{MapSection, Plan};

/// A short label of where a waypoint's shape came from.
pub fn source_label(s: &Source, shape_change: bool) -> String {
    match (s, shape_change) {
        (Source::Start, _) => "start".into(),
        (_, false) => "translate".into(),
        (Source::Rotation, true) => "rotation".into(),
        (Source::Lsc(k), true) => format!("LSC:{}", k.name()),
        (Source::Srs(i), true) => format!("SRS:{i}"),
        (Source::SrsTurned(i), true) => format!("SRS:{i}:turned"),
        (Source::Follow, true) => "follow".into(),
        (Source::Shrunk, true) => "shrunk".into(),
        (Source::Sampled, true) => "sampled".into(),
        (Source::Goal, true) => "goal".into(),
    }
}

/// The plan file for `solution`, of any planner, made on the map `map` describes
/// ([`MapSection::of`] a grid, with its source where it is known).
pub fn to_plan<S: SolutionStats>(
    solution: &Solution<S>,
    params: &ChainParams,
    map: MapSection,
) -> Plan {
    let st = &solution.stats;
    let steps = solution.steps.iter().map(|s| (s.xi.into(), &s.shape));
    let mut plan = Plan::from_steps(
        params,
        map,
        steps,
        st.counts(),
        (&st.timings(), st.rest_name()),
    );
    st.annotate(&solution.steps, &mut plan);
    plan
}

/// Records a plan's quality (docs/model.md, "Plan statistics") under `stats.quality`,
/// and, for a refined plan, the raw plan's quality and the refinement's cost under
/// `stats.refinement` (its time under `stats.timing.refine_s`).
pub fn annotate_quality(plan: &mut Plan, quality: &Quality, refinement: Option<&Refinement>) {
    plan.stats.insert("quality".into(), quality_json(quality));
    let Some(r) = refinement else {
        return;
    };
    let mut m = serde_json::Map::new();
    m.insert("before".into(), quality_json(&r.before));
    m.insert("checks".into(), r.checks.into());
    let w = &r.widening;
    m.insert(
        "widening".into(),
        serde_json::json!({
            "narrowest_before_m": w.before,
            "narrowest_after_m": w.after,
            "moves": w.moves,
        }),
    );
    m.insert("threaded".into(), r.threaded.into());
    let carried = r
        .carried
        .iter()
        .map(|c| serde_json::json!({ "shape": c.kind.name(), "head_path_m": c.head_path_m }));
    m.insert("carried".into(), Value::Array(carried.collect()));
    plan.stats.insert("refinement".into(), Value::Object(m));
    if let Some(Value::Object(t)) = plan.stats.get_mut("timing") {
        t.insert("refine_s".into(), r.time_s.into());
    }
}

fn quality_json(q: &Quality) -> Value {
    serde_json::json!({
        "head_path_m": q.head_path_m,
        "shape_motion_rad": q.shape_motion_rad,
        "shape_cost": q.shape_cost,
        "shape_changes": q.shape_changes,
    })
}
