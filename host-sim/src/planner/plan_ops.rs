//! What post-processing measures and searches along a plan, written once: the plan's
//! quality, when two shapes are the same, the head's route without repeats, and the
//! farthest waypoint a straight move reaches (gallop, then bisect).
//!
//! A leaf of the planner: it uses nothing of the planner but [`Step`], so every stage,
//! the search's route pulling and the report share it without a circle.

use aerial_chain_core::angle;
use aerial_chain_core::cost::transition_cost;
use aerial_chain_core::Shape;
use nalgebra::Point3;

use super::numeric::{SAME_SHAPE, TIE};
use super::Step;

/// What a plan asks of the chain: the measures the flight time depends on.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Quality {
    /// Length of the head's path (m).
    pub head_path_m: f64,
    /// Total shape motion: over every shape change, the sum of the absolute wrapped
    /// differences of every angle of the shape (head yaw, link pitches and yaws), rad.
    pub shape_motion_rad: f64,
    /// Sum of the cost to transition `C_T` over every shape change (paper Eq. 3).
    pub shape_cost: f64,
    /// Number of shape changes.
    pub shape_changes: usize,
}

impl Quality {
    /// Adds `other`'s measures (plans flown one after the other).
    pub fn add(&mut self, other: &Quality) {
        self.head_path_m += other.head_path_m;
        self.shape_motion_rad += other.shape_motion_rad;
        self.shape_cost += other.shape_cost;
        self.shape_changes += other.shape_changes;
    }

    /// The measures of a plan's steps.
    pub fn of(steps: &[Step]) -> Self {
        let mut q = Self::default();
        for w in steps.windows(2) {
            let (a, b) = (&w[0], &w[1]);
            q.head_path_m += super::dist(a.xi, b.xi);
            if differs(&a.shape, &b.shape) {
                q.shape_changes += 1;
                q.shape_motion_rad += shape_motion(&a.shape, &b.shape);
                q.shape_cost += transition_cost(&a.shape, &b.shape) as f64;
            }
        }
        q
    }
}

/// The sum of the absolute wrapped differences of every angle from `a` to `b` (rad).
pub fn shape_motion(a: &Shape, b: &Shape) -> f64 {
    a.as_slice()
        .iter()
        .zip(b.as_slice())
        .map(|(&x, &y)| angle::diff(x, y).abs() as f64)
        .sum()
}

/// Whether changing from `a` to `b` is a shape change at all (an angle moves by more
/// than [`SAME_SHAPE`]).
pub(crate) fn differs(a: &Shape, b: &Shape) -> bool {
    a.max_angle_diff(b) > SAME_SHAPE
}

/// The head's positions along `steps`, without repeats (a shape change keeps the
/// head where it is; positions within [`TIE`] are one).
pub(crate) fn head_route(steps: &[Step]) -> Vec<Point3<f64>> {
    let mut route: Vec<Point3<f64>> = Vec::with_capacity(steps.len());
    for s in steps {
        if route.last().is_none_or(|p| (s.xi - p).norm() > TIE) {
            route.push(s.xi);
        }
    }
    route
}

/// The farthest index after `from`, up to `last`, that `reaches` accepts: gallop
/// (`from + 1`, `+ 2`, `+ 4`, ..., the last probe clipped to `last`) while it accepts,
/// then bisect between the last index accepted and the first refused. `None` when it
/// refuses `from + 1`. Probes are made in that order, so a caller that counts them
/// (a budget) or remembers what the last accepted probe built sees the same sequence
/// every time; the last index accepted is the one returned.
pub(crate) fn farthest(
    from: usize,
    last: usize,
    mut reaches: impl FnMut(usize) -> bool,
) -> Option<usize> {
    let mut good = None;
    let mut bad = None;
    let mut stride = 1;
    while good.unwrap_or(from) < last {
        let j = (from + stride).min(last);
        if !reaches(j) {
            bad = Some(j);
            break;
        }
        good = Some(j);
        stride *= 2;
    }
    let mut lo = good?;
    if let Some(mut hi) = bad {
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            if reaches(mid) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
    }
    Some(lo)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::planner::Source;

    fn step(xi: [f64; 3], yaw: f32, shape_change: bool) -> Step {
        Step {
            xi: xi.into(),
            shape: Shape::line(4, yaw),
            source: if shape_change {
                Source::Rotation
            } else {
                Source::Start
            },
            shape_change,
        }
    }

    #[test]
    fn quality_sums_path_and_wrapped_shape_motion() {
        let steps = [
            step([0.0, 0.0, 1.0], 3.0, false),
            step([0.0, 0.0, 1.0], -3.0, true),
            step([3.0, 4.0, 1.0], -3.0, false),
        ];
        let q = Quality::of(&steps);
        assert!((q.head_path_m - 5.0).abs() < 1e-12);
        assert_eq!(q.shape_changes, 1);
        // A line turned by 2 pi - 6 rad: head yaw and 3 link yaws, each wrapped.
        let d = (std::f64::consts::TAU - 6.0) as f32;
        assert!((q.shape_motion_rad - 4.0 * d as f64).abs() < 1e-4, "{q:?}");
        assert!(q.shape_cost > 0.0);
    }

    #[test]
    fn the_route_keeps_each_head_position_once() {
        let steps = [
            step([0.0, 0.0, 1.0], 0.0, false),
            step([0.0, 0.0, 1.0], 1.0, true),
            step([1.0, 0.0, 1.0], 1.0, false),
        ];
        assert_eq!(head_route(&steps).len(), 2);
    }

    /// Gallop and bisect find the last index of a monotone rule, probe the
    /// documented sequence, and give up at once when the next index is refused.
    #[test]
    fn farthest_gallops_then_bisects() {
        let mut probes = Vec::new();
        let found = farthest(0, 20, |j| {
            probes.push(j);
            j <= 11
        });
        assert_eq!(found, Some(11));
        assert_eq!(probes, [1, 2, 4, 8, 16, 12, 10, 11]);
        assert_eq!(farthest(3, 20, |j| j <= 3), None);
        assert_eq!(farthest(0, 5, |_| true), Some(5));
    }
}
