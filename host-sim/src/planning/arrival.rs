//! The end of a plan whose goal asks for a yaw or a shape: checked up front (the
//! configuration must be valid at the goal), and reached after post-processing (so
//! that no later stage changes the end).

use nalgebra::Point3;

use super::{PlanningError, Request};
use crate::collision::exact::check_config_exact;
use crate::goal::GoalPose;
use crate::planner::{ArcPlanner, Planner, Step};

/// Head-to-goal distances below this are the goal itself (m): no translation is added.
const AT_GOAL_M: f64 = 1e-9;

/// Where a plan must end: the goal's head position and the pose asked there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Arrival {
    /// The goal's head position.
    pub goal: Point3<f64>,
    /// The yaw and shape asked for.
    pub pose: GoalPose,
}

impl Arrival {
    /// An arrival that asks for nothing beyond the route's end (within the goal's
    /// tolerance).
    pub fn anywhere(goal: Point3<f64>) -> Self {
        Self {
            goal,
            pose: GoalPose::default(),
        }
    }

    /// Ends `steps` in the pose: a translation to the goal itself where the chain can
    /// make it in its shape, then the checked shape changes into the pose (at the
    /// goal, else where the route ended).
    pub fn extend(&self, planner: &ArcPlanner, steps: &mut Vec<Step>) -> Result<(), PlanningError> {
        let Some(last) = steps.last().copied() else {
            return Ok(());
        };
        if self.pose.is_any() {
            return Ok(());
        }
        let moved = (last.xi - self.goal).norm() > AT_GOAL_M;
        if moved
            && planner
                .context()
                .check_translation(last.xi, self.goal, &last.shape)
                .is_ok()
        {
            if let Some(changes) = planner.reach_pose(self.goal, &last.shape, &self.pose) {
                steps.push(Step {
                    xi: self.goal,
                    shape_change: false,
                    ..last
                });
                steps.extend(changes);
                return Ok(());
            }
        }
        match planner.reach_pose(last.xi, &last.shape, &self.pose) {
            Some(changes) => {
                steps.extend(changes);
                Ok(())
            }
            None => Err(PlanningError::PoseUnreachable {
                pose: self.pose.describe(None),
                at: last.xi.into(),
            }),
        }
    }
}

/// Checks that the request's pose gives a valid configuration at its goal (by the
/// exact test, at one of the `headings` the planner tries when no yaw is asked): else
/// the goal is bad input.
pub fn check_pose(request: &Request, headings: usize) -> Result<(), PlanningError> {
    let pose = &request.pose;
    if pose.is_any() {
        return Ok(());
    }
    let start = request.query.start_shape;
    let current = pose.shape.unwrap_or(start);
    let grid = request.grid();
    let mut why = String::new();
    for target in pose.targets(&current, headings) {
        let eta: Vec<f64> = target.as_slice().iter().map(|&a| a as f64).collect();
        match check_config_exact(grid, &request.params, request.query.goal, &eta, 0.0) {
            Ok(_) => return Ok(()),
            Err(v) if why.is_empty() => why = format!("{v:?}"),
            Err(_) => {}
        }
    }
    Err(PlanningError::GoalPose {
        pose: pose.describe(None),
        at: request.query.goal.into(),
        why,
    })
}
