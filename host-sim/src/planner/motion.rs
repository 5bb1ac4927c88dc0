//! MotionPlan: a solution as an `arc-plan/1` file (docs/model.md "Files").
//!
//! Waypoint 0 is the start; each head edge becomes its shape changes (head fixed)
//! then one translation (shape fixed). Timings go under `stats.timing`, the only
//! part of a plan that differs between two runs with the same seed.

use aerial_chain_core::ChainParams;
use serde_json::Value;

use super::candidates::Source;
use super::refine::{Quality, Refinement};
use super::Solution;
use crate::plan::{Plan, Timing};

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
    }
}

/// The plan file for `solution`.
pub fn to_plan(
    solution: &Solution,
    params: &ChainParams,
    resolution: f64,
    unknown_is_occupied: bool,
) -> Plan {
    let st = &solution.stats;
    let counts = [
        ("edges", st.edges as u64),
        ("shape_changes", st.shape_changes as u64),
        ("rotations", st.rotations as u64),
        ("lsc_uses", st.lsc_uses as u64),
        ("srs_uses", st.srs_uses as u64),
        ("follow_uses", st.follow_uses as u64),
        ("shrunk", st.shrunk as u64),
        ("srs_connects", st.srs_connects as u64),
        ("replans", st.replans as u64),
        ("roadmap_growths", st.roadmap_growths as u64),
        ("collision_checks", st.collision_checks),
        ("roadmap_vertices", st.roadmap_vertices as u64),
        ("roadmap_edges", st.roadmap_edges as u64),
        ("lattice_expanded", st.lattice_expanded as u64),
        ("route_points", st.route_points as u64),
    ];
    let timing = Timing {
        roadmap_s: st.roadmap_s,
        planning_s: st.planning_s,
        collision_s: st.collision_s,
        rest: "shape_search_s",
    };
    let steps = solution.steps.iter().map(|s| (s.xi, &s.shape));
    let mut plan = Plan::from_steps(
        params,
        (resolution, unknown_is_occupied),
        steps,
        &counts,
        &timing,
    );
    let labels: Vec<Value> = solution
        .steps
        .iter()
        .map(|s| Value::String(source_label(&s.source, s.shape_change)))
        .collect();
    plan.stats
        .insert("waypoint_sources".into(), Value::Array(labels));
    // The smallest clearance margin in force, and where (docs/model.md "Files").
    plan.stats
        .insert("min_margin".into(), serde_json::json!(st.min_margin));
    if let Some(at) = st.min_margin_at {
        plan.stats
            .insert("min_margin_at".into(), serde_json::json!(at));
    }
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
