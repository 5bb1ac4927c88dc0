//! Full-chain collision checks as the ARC planner's searches make them: timed, and
//! failing at once past the query's deadline.

use std::time::{Duration, Instant};

use aerial_chain_core::Shape;
use nalgebra::Point3;

use super::expired;
use crate::collision::CollisionContext;

/// Collision checks with time and count bookkeeping.
pub struct Checker {
    /// The context checks are made in (the clearance in force).
    pub(super) ctx: CollisionContext,
    /// Time spent in checks.
    pub(super) time: Duration,
    /// Past it every check fails at once, so that whatever search is under way ends
    /// and the query reports the time limit.
    pub(super) deadline: Option<Instant>,
}

impl Checker {
    /// A checker in `ctx` that fails every check past `deadline`.
    pub fn new(ctx: CollisionContext, deadline: Option<Instant>) -> Self {
        Self {
            ctx,
            time: Duration::ZERO,
            deadline,
        }
    }

    /// Whether the deadline has passed (every check fails from then on).
    pub(super) fn expired(&self) -> bool {
        expired(self.deadline)
    }

    fn timed(&mut self, f: impl FnOnce(&CollisionContext) -> bool) -> bool {
        if expired(self.deadline) {
            return false;
        }
        let t = Instant::now();
        let r = f(&self.ctx);
        self.time += t.elapsed();
        r
    }

    /// The shape is collision-free with the head at `xi` (shape known valid).
    pub fn placement(&mut self, xi: impl Into<Point3<f64>>, s: &Shape) -> bool {
        let xi = xi.into();
        self.timed(|c| c.check_placement(xi, s).is_ok())
    }

    /// The configuration is valid (joint limits, self-collision, map).
    pub fn config(&mut self, xi: impl Into<Point3<f64>>, s: &Shape) -> bool {
        let xi = xi.into();
        self.timed(|c| c.check_config(xi, s).is_ok())
    }

    /// The chain in shape `s` can translate from `a` to `b`.
    pub fn translation(
        &mut self,
        a: impl Into<Point3<f64>>,
        b: impl Into<Point3<f64>>,
        s: &Shape,
    ) -> bool {
        let (a, b) = (a.into(), b.into());
        self.timed(|c| c.check_translation(a, b, s).is_ok())
    }

    /// The chain can change shape from `s` to `t` with the head at `xi`.
    pub fn shape_change(&mut self, xi: impl Into<Point3<f64>>, s: &Shape, t: &Shape) -> bool {
        let xi = xi.into();
        self.timed(|c| c.check_shape_change(xi, s, t).is_ok())
    }
}

/// The checks the check-counting stages of post-processing ask for (refinement's
/// shortcuts, shortening), and whether they may still ask (a budget or a deadline).
pub(super) trait Checks {
    /// The chain in shape `s` can translate from `a` to `b`.
    fn translation(&mut self, a: Point3<f64>, b: Point3<f64>, s: &Shape) -> bool;
    /// The chain can change shape from `s` to `t` with the head at `xi`.
    fn shape_change(&mut self, xi: Point3<f64>, s: &Shape, t: &Shape) -> bool;
    /// No more checks may be made.
    fn exhausted(&self) -> bool;
}

/// A [`Checker`] whose checks count against a budget that several stages share: each
/// takes over the count the one before left.
pub(super) struct Counted {
    checker: Checker,
    /// Checks made so far, the earlier stages' included.
    pub(super) checks: u64,
    budget: u64,
}

impl Counted {
    /// Checks in `ctx` until `deadline`, `spent` of `budget` already made.
    pub(super) fn new(
        ctx: CollisionContext,
        deadline: Option<Instant>,
        spent: u64,
        budget: u64,
    ) -> Self {
        Self {
            checker: Checker::new(ctx, deadline),
            checks: spent,
            budget,
        }
    }
}

impl Checks for Counted {
    fn translation(&mut self, a: Point3<f64>, b: Point3<f64>, s: &Shape) -> bool {
        self.checks += 1;
        self.checker.translation(a, b, s)
    }

    fn shape_change(&mut self, xi: Point3<f64>, s: &Shape, t: &Shape) -> bool {
        self.checks += 1;
        self.checker.shape_change(xi, s, t)
    }

    fn exhausted(&self) -> bool {
        self.checks >= self.budget || expired(self.checker.deadline)
    }
}
