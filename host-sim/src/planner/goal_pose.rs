//! Arriving in a goal's configuration (docs/model.md, "Goal configurations"): where the
//! head's route ends, the chain changes into the yaw and shape the goal asks for, by
//! shape changes checked as every other (limits, self-collision, the map at the
//! planner's clearance, else at its clearance floor).
//!
//! The search is small: the goal shape directly, else through one library shape (at
//! every heading) or one random shape valid there, the cheapest by `C_T` first. It
//! runs once per goal, at a point the route already reached.

use aerial_chain_core::cost::transition_cost;
use aerial_chain_core::Shape;
use nalgebra::Point3;

use super::candidates::Source;
use super::{ArcPlanner, Checker, Step};
use crate::collision::CollisionContext;
use crate::goal::GoalPose;

impl ArcPlanner {
    /// The shape changes that take the chain at `xi` in `current` into `pose`, each
    /// ending a step: none when `current` already holds it; `None` when no checked
    /// change (direct, or through one intermediate shape) reaches it.
    pub fn reach_pose(
        &self,
        xi: Point3<f64>,
        current: &Shape,
        pose: &GoalPose,
    ) -> Option<Vec<Step>> {
        let eta: Vec<f64> = current.as_slice().iter().map(|&a| a as f64).collect();
        if pose.holds(&eta) {
            return Some(Vec::new());
        }
        let targets = pose.targets(current, self.settings.n_psi);
        [&self.ctx, &self.ctx_min]
            .into_iter()
            .find_map(|ctx| self.reach_in(ctx, xi, current, &targets))
    }

    /// [`Self::reach_pose`] checked in `ctx`.
    fn reach_in(
        &self,
        ctx: &CollisionContext,
        xi: Point3<f64>,
        current: &Shape,
        targets: &[Shape],
    ) -> Option<Vec<Step>> {
        let mut checker = Checker::new(ctx.clone(), None);
        let valid: Vec<&Shape> = targets.iter().filter(|t| checker.config(xi, t)).collect();
        let step = |shape: Shape, source: Source| Step {
            xi,
            shape,
            source,
            shape_change: true,
        };
        if let Some(t) = valid.iter().find(|t| checker.shape_change(xi, current, t)) {
            return Some(vec![step(**t, Source::Goal)]);
        }
        for (mid, source) in self.intermediates(current, &valid) {
            if !checker.config(xi, &mid) || !checker.shape_change(xi, current, &mid) {
                continue;
            }
            if let Some(t) = valid.iter().find(|t| checker.shape_change(xi, &mid, t)) {
                return Some(vec![step(mid, source), step(**t, Source::Goal)]);
            }
        }
        None
    }

    /// Shapes to pass through on the way from `current` to one of `targets`: every
    /// library shape at every heading and every random shape, cheapest first by the
    /// `C_T` of the two changes.
    fn intermediates(&self, current: &Shape, targets: &[&Shape]) -> Vec<(Shape, Source)> {
        let Some(target) = targets.first() else {
            return Vec::new();
        };
        let headings = self.settings.n_psi.max(1);
        let mut out: Vec<(f32, Shape, Source)> = Vec::new();
        let mut push = |shape: Shape, source: Source| {
            let cost = transition_cost(current, &shape) + transition_cost(&shape, target);
            out.push((cost, shape, source));
        };
        for entry in &self.tables.lsc {
            for k in 0..headings {
                let d = k as f32 * std::f32::consts::TAU / headings as f32;
                push(entry.shape.rotated(d), Source::Lsc(entry.kind));
            }
        }
        for (i, shape) in self.tables.srs.iter().enumerate() {
            push(*shape, Source::Srs(i as u16));
        }
        out.sort_by(|a, b| a.0.total_cmp(&b.0));
        out.into_iter().map(|(_, s, src)| (s, src)).collect()
    }
}
