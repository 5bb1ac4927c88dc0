//! Plans made from a problem's own geometry rather than by a planner: the route plan
//! of a scenario (the chain laid along its centre line, follow-the-leader fashion),
//! the witness that an instance can be flown (that plan, passed by the exact
//! verifier), and how a plan passes each opening of a `passage:` instance.
//!
//! A plan file is made from the problem and checked by the collision layer, so this
//! sits above `problem`, `collision` and `plan_file` (docs/architecture.md, "Module:
//! may use").

use aerial_chain_core::ChainParams;

use crate::collision::{verify_plan, verify_plan_with, VerifyOptions};
use crate::plan_file::{ChainSection, MapSection, MapSource, Plan, Waypoint, FORMAT};
use crate::problem::passages::PassageSpec;
use crate::problem::scenarios::Scenario;
use crate::problem::ProblemError;

/// The route plan of `sc` for a chain of `params`: the chain follows the scenario's
/// route like a snake, translations of the head by at most `step` metres between
/// shape changes that put the units back on it ([`Scenario::route_poses`]).
pub fn route_plan(sc: &Scenario, params: &ChainParams, step: f64) -> Result<Plan, ProblemError> {
    let route = sc.route_poses(params, step)?;
    Ok(Plan {
        format: FORMAT.into(),
        chain: ChainSection::from_params(&route.params),
        map: MapSection::of(&sc.grid).with_source(MapSource::scenario(&sc.name)),
        waypoints: route
            .poses
            .iter()
            .map(|(head, shape)| Waypoint::new(*head, shape))
            .collect(),
        stats: Default::default(),
    })
}

/// The witness of an instance for a chain: its route plan ([`route_plan`], steps of
/// a quarter voxel), checked by the EXACT verifier. `Err` says why there is none.
pub fn witness(sc: &Scenario, params: &ChainParams) -> Result<Plan, ProblemError> {
    let plan = route_plan(sc, params, sc.grid.resolution())?;
    let report = verify_plan(&sc.grid, &plan);
    if !report.ok {
        return Err(ProblemError::InvalidWitness(report.violation));
    }
    Ok(plan)
}

/// The clearance a plan keeps through one opening of an instance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OpeningClearance {
    /// `window` or `door`.
    pub name: &'static str,
    /// The opening's width as built (m).
    pub width: f64,
    /// The smallest clearance the plan keeps from the wall holding it (m).
    pub clearance: f64,
    /// What the passages issue asks: `0.9 (width - 2 r_u) / 2` (m).
    pub target: f64,
}

/// How much clearance `plan` keeps through each opening of `spec`, against what the
/// passages issue asks: `0.9 (w - 2 r_u) / 2` for an opening `w` wide (its narrower
/// side as built). Each opening's clearance is measured exactly, by the verifier,
/// against a map that holds only the wall around it
/// ([`PassageSpec::opening_walls`]), so the rest of the room does not count. `Err`
/// when the instance does not build.
pub fn opening_clearances(
    spec: &PassageSpec,
    plan: &Plan,
    params: &ChainParams,
) -> Result<Vec<OpeningClearance>, ProblemError> {
    let opts = VerifyOptions { horizon: 1.0 };
    let r_u = params.unit_radius as f64;
    Ok(spec
        .opening_walls()?
        .into_iter()
        .map(|w| OpeningClearance {
            name: w.name,
            width: w.width,
            clearance: verify_plan_with(&w.grid, plan, &opts).min_clearance,
            target: 0.9 * (w.width - 2.0 * r_u) / 2.0,
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_witness_flies_every_chain_through_the_default_window() {
        let sc = PassageSpec::default().build().unwrap();
        for n in [4u8, 6, 8] {
            witness(&sc, &ChainParams::new(n)).unwrap();
        }
    }

    #[test]
    fn the_witness_turns_right_behind_the_window_to_a_door_to_the_side() {
        // 1.8 m behind the window, 2.5 m to either side: the head turns while the
        // tail is still in the window.
        for side in [2.5, -2.5] {
            let s = PassageSpec::parse(&format!(
                "w=0.5,angle=17,door=0.8,door_offset={side},gap=1.8"
            ))
            .unwrap();
            let sc = s.build().unwrap();
            for n in [4u8, 6, 8] {
                witness(&sc, &ChainParams::new(n)).unwrap_or_else(|e| panic!("{side} N={n}: {e}"));
            }
        }
    }

    #[test]
    fn the_centred_witness_keeps_the_opening_target_and_a_plan_off_centre_does_not() {
        let s = PassageSpec::parse("w=0.5,angle=30,door=0.7").unwrap();
        let sc = s.build().unwrap();
        let params = ChainParams::new(4);
        let mut plan = witness(&sc, &params).unwrap();
        let o = opening_clearances(&s, &plan, &params).unwrap();
        assert_eq!(o.len(), 2);
        for c in &o {
            // Centred: (w - 2 r_u) / 2 less a little for the turn onto the normal.
            assert!(c.clearance >= c.target, "{c:?}");
        }
        assert!((o[0].width - 0.5).abs() < 1e-9 && (o[1].width - 0.7).abs() < 1e-9);
        // The same plan 4 cm off centre in y keeps less than the target in the window.
        for w in &mut plan.waypoints {
            w.zeta[1] += 0.04;
        }
        let o = opening_clearances(&s, &plan, &params).unwrap();
        assert!(o[0].clearance < o[0].target, "{:?}", o[0]);
    }
}
