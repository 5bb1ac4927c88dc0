//! Collision of the chain against a map (docs/model.md "Validity of one configuration",
//! "Motion between two configurations").
//!
//! Two checkers:
//! - the FAST, CONSERVATIVE one in this module ([`CollisionContext`]; its edge checks in
//!   `edges`), built on the distance field's proven lower bounds, for the planner: it
//!   may reject a valid configuration or edge, never accept an invalid one;
//! - the EXACT one (`exact`, `verify`), independent of the distance field, for
//!   verifying plans: exact point/segment-to-voxel-cube distances and docs/model.md's
//!   edge sampling rule.
//!
//! # Conservative checks
//! Every body's radius is grown by the user's clearance margin (`--clearance`, default
//! [`DEFAULT_CLEARANCE`]) and by [`FK_TOLERANCE`], which covers the difference between
//! the core's `f32` kinematics used here and the `f64` kinematics of the exact checker.
//! A unit sphere is free when the field's lower bound at its centre exceeds its grown
//! radius. A link capsule is certified by the 1-Lipschitz property of the distance: a
//! lower bound `c` at a point `s` of the segment proves every point within `c - r` of
//! `s` free, so the segment is walked in steps of the proven free distance ("sphere
//! tracing"), starting and ending where the unit spheres' bounds already cover it.
//!
//! Edges use the same argument in time. For each body we know how fast its points can
//! move along the edge: on a translation every point moves exactly as fast as the head;
//! on a shape change the head stays, and a link direction `d(theta, psi)` moves on the
//! unit sphere at speed `sqrt(theta'^2 + cos^2(theta) psi'^2) <= sqrt(dtheta^2 + dpsi^2)`
//! per unit of the edge parameter (the two partial derivatives of `d` are orthogonal),
//! so unit `i` moves at most at `l * sum_{k<i} sqrt(dtheta_k^2 + dpsi_k^2)` and a link's
//! points at most as fast as its back unit. A body with free margin `m` (a proven lower
//! bound on `distance - grown radius` over all its points) cannot touch anything before
//! the edge parameter has advanced by `m / speed`. Each body keeps its own certified
//! horizon, and the edge is evaluated only where some horizon ends (and only for the
//! bodies whose horizon ends there, with the units at the ends of such a link), so
//! open space is crossed in a few samples and no collision is ever skipped. A body
//! whose margin falls below [`CollisionContext::min_step`] is reported as colliding
//! (conservatively), which also bounds the work per edge. On a translation a body whose
//! margin is a small part of the way left (sliding beside a wall, where each bound proves
//! only a thin ball) is moved against the obstacle cubes near its path instead (`sweep`:
//! each cube grown by the body's radius into a box), which proves the rest of its way in
//! one reading where the walk would measure it again every few millimetres. Limits and
//! self-collision along a shape change come from
//! `aerial_chain_core::validity::check_transition`.

mod edges;
pub(crate) mod exact;
pub(crate) mod point_clearance;
mod sweep;
pub(crate) mod verify;

use std::cell::RefCell;
use std::fmt;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

use aerial_chain_core::kinematics::positions_into;
use aerial_chain_core::validity::{check_shape, Body, Violation};
use aerial_chain_core::{ChainParams, Shape, MAX_UNITS};

use nalgebra::{Point3, Vector3};

use crate::map::distance::DistanceField;

pub use verify::{
    verify_plan, verify_plan_with, EdgeKind, Verifiable, VerifyOptions, VerifyReport,
    SAMPLES_PER_VOXEL,
};

/// Default clearance margin added to every body's radius by the planner's checks (m).
pub const DEFAULT_CLEARANCE: f64 = 0.05;

/// Added to every radius in the conservative checks (m): covers the `f32` forward
/// kinematics (error well below 1e-5 m for 16 units of 0.5 m) against the exact `f64` test.
pub const FK_TOLERANCE: f64 = 1e-4;

/// Slack kept by `check_transition` for self-collision along shape changes (m, rad).
const TRANSITION_MARGIN: f32 = 1e-4;

/// A unit centre outside the map's bounding box (docs/model.md "Validity of one
/// configuration", item 4): how both checkers report it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OutOfBounds {
    /// The unit.
    pub body: Body,
    /// Its centre (m).
    pub point: Point3<f64>,
}

impl OutOfBounds {
    /// Unit `i` (0-based) with its centre at `point`.
    pub fn unit(i: usize, point: Point3<f64>) -> Self {
        Self {
            body: Body::Unit(i as u8),
            point,
        }
    }
}

impl fmt::Display for OutOfBounds {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let p = self.point;
        write!(
            f,
            "{} centre ({:.3}, {:.3}, {:.3}) is outside the map's bounds",
            self.body, p.x, p.y, p.z
        )
    }
}

/// Why the conservative checker rejected a configuration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Collision {
    /// Limits or self-collision (exact, from the core).
    Shape(Violation),
    /// A unit centre is outside the map's bounding box.
    OutOfBounds(OutOfBounds),
    /// A body may touch an obstacle (conservative: its proven free margin is not positive).
    Map {
        /// The body.
        body: Body,
        /// Where its margin was lowest: the unit centre, or the point of the link (m).
        point: Point3<f64>,
    },
    /// Bad input: non-finite numbers, or shapes of another chain size.
    BadInput(&'static str),
}

impl fmt::Display for Collision {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Collision::Shape(v) => write!(f, "{v}"),
            Collision::OutOfBounds(o) => write!(f, "{o}"),
            Collision::Map { body, point } => {
                write!(
                    f,
                    "{body} near ({:.3}, {:.3}, {:.3}) may touch an obstacle",
                    point[0], point[1], point[2]
                )
            }
            Collision::BadInput(w) => write!(f, "bad input: {w}"),
        }
    }
}

impl std::error::Error for Collision {}

/// A rejected edge: what, and where along it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgeCollision {
    /// Fraction of the edge (0..=1) at which it was found; 0 for problems not tied to a
    /// place (self-collision along a shape change is reported at 0).
    pub t: f64,
    /// What was found there.
    pub collision: Collision,
}

impl fmt::Display for EdgeCollision {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "at {:.3} of the edge: {}", self.t, self.collision)
    }
}

impl std::error::Error for EdgeCollision {}

/// Counts of checks performed, for plan statistics.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CheckStats {
    /// Full-chain configuration checks.
    pub configs: u64,
    /// Translation edges checked.
    pub translations: u64,
    /// Shape-change edges checked.
    pub shape_changes: u64,
    /// Head-only point checks.
    pub head_points: u64,
    /// Head-only segment checks.
    pub head_segments: u64,
}

#[derive(Debug, Default)]
struct Counters {
    configs: AtomicU64,
    translations: AtomicU64,
    shape_changes: AtomicU64,
    head_points: AtomicU64,
    head_segments: AtomicU64,
}

/// What the conservative checks need: the map's distance field, the chain, the
/// clearance margin. Cheap to clone; clones share the map and the counters.
#[derive(Clone, Debug)]
pub struct CollisionContext {
    field: Arc<DistanceField>,
    params: ChainParams,
    clearance: f64,
    min_step: f64,
    unit_r: f64,
    /// Most the distance field's bound can lose near obstacles, `r_v sqrt(3)` (m).
    field_loss: f64,
    link_r: f64,
    counters: Arc<Counters>,
}

/// A chain, a shape and the answer of `check_shape` for them.
type ShapeAnswer = (ChainParams, Shape, Result<(), Violation>);

thread_local! {
    /// The last shape checked for limits and self-collision on this thread, with its
    /// chain and result: the planner checks the same shape at many head positions.
    static LAST_SHAPE: RefCell<Option<ShapeAnswer>> = const { RefCell::new(None) };
}

/// `aerial_chain_core::validity::check_shape`, remembering the last answer per thread (an exact
/// repeat of the same chain and shape gets the same answer without the work).
fn shape_validity(params: &ChainParams, shape: &Shape) -> Result<(), Violation> {
    LAST_SHAPE.with(|c| {
        if let Some((p, s, r)) = &*c.borrow() {
            if p == params && s == shape {
                return *r;
            }
        }
        let r = check_shape(params, shape);
        *c.borrow_mut() = Some((*params, *shape, r));
        r
    })
}

/// A body swept along a segment: the capsule of radius `r` around `a b`, with the
/// distance field's proven bounds `ca`, `cb` at its ends.
#[derive(Clone, Copy)]
struct Capsule {
    a: Point3<f64>,
    b: Point3<f64>,
    r: f64,
    ca: f64,
    cb: f64,
}

/// Unit centres in the world frame (f64 head + f32 core offsets), head first.
type WorldPoints = [Point3<f64>; MAX_UNITS];

fn finite3(a: &Point3<f64>) -> bool {
    a.iter().all(|v| v.is_finite())
}

/// Why a collision context cannot be made.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ContextError {
    /// The chain's parameters are out of range.
    #[error("chain: {0}")]
    Chain(aerial_chain_core::ParamError),
    /// The clearance is negative or not a number.
    #[error("clearance {0} must be a finite number >= 0")]
    Clearance(f64),
}

impl CollisionContext {
    /// A context for chain `params` (validated here) on `field`, growing every radius by
    /// `clearance` (m, finite and `>= 0`).
    pub fn new(
        field: Arc<DistanceField>,
        params: ChainParams,
        clearance: f64,
    ) -> Result<Self, ContextError> {
        let params = params.validate().map_err(ContextError::Chain)?;
        if !(clearance.is_finite() && clearance >= 0.0) {
            return Err(ContextError::Clearance(clearance));
        }
        let min_step = field.grid().resolution() / 64.0;
        Ok(Self {
            unit_r: params.unit_radius as f64 + clearance + FK_TOLERANCE,
            field_loss: field.grid().resolution() * 3f64.sqrt(),
            link_r: params.link_radius as f64 + clearance + FK_TOLERANCE,
            field,
            params,
            clearance,
            min_step,
            counters: Arc::default(),
        })
    }

    /// The distance field (and through it the grid).
    pub fn field(&self) -> &DistanceField {
        &self.field
    }

    /// The shared distance field.
    pub fn field_arc(&self) -> &Arc<DistanceField> {
        &self.field
    }

    /// The chain.
    pub fn params(&self) -> &ChainParams {
        &self.params
    }

    /// The clearance margin added to every radius (m).
    pub fn clearance_margin(&self) -> f64 {
        self.clearance
    }

    /// Smallest free margin (m) a body may have and still be accepted on an edge
    /// (default `r_v / 64`); smaller margins are rejected conservatively.
    pub fn min_step(&self) -> f64 {
        self.min_step
    }

    /// Sets [`Self::min_step`] (clamped to at least 1e-6 m).
    pub fn set_min_step(&mut self, m: f64) {
        self.min_step = if m.is_finite() {
            m.max(1e-6)
        } else {
            self.min_step
        };
    }

    /// Counts of checks performed so far (by this context and its clones).
    pub fn stats(&self) -> CheckStats {
        let c = &self.counters;
        CheckStats {
            configs: c.configs.load(Ordering::Relaxed),
            translations: c.translations.load(Ordering::Relaxed),
            shape_changes: c.shape_changes.load(Ordering::Relaxed),
            head_points: c.head_points.load(Ordering::Relaxed),
            head_segments: c.head_segments.load(Ordering::Relaxed),
        }
    }

    /// Sets every counter back to zero.
    pub fn reset_stats(&self) {
        let c = &self.counters;
        for a in [
            &c.configs,
            &c.translations,
            &c.shape_changes,
            &c.head_points,
            &c.head_segments,
        ] {
            a.store(0, Ordering::Relaxed);
        }
    }

    /// Proven lower bound on the distance from `p` to the nearest obstacle cube (m).
    #[inline]
    pub fn clearance(&self, p: impl Into<Point3<f64>>) -> f64 {
        self.field.clearance(p)
    }

    /// A proven lower bound at `p`, from one lookup when that already exceeds `need`.
    /// Where the field's bound falls short of `need` by less than what it can lose
    /// (`r_v sqrt(3)` next to obstacles), the obstacle cubes nearby are measured one by
    /// one: at a coarse resolution a unit centred in an opening is otherwise refused
    /// although it is clear of both sides.
    #[inline]
    fn bound(&self, p: Point3<f64>, need: f64) -> f64 {
        self.refined(p, need, self.field.clearance_above(p, need))
    }

    /// [`Self::bound`] from the field's bound `c` at `p` (as tight as
    /// `clearance_above`'s where it matters for `need`): `c`, or the cubes nearby
    /// measured where `c` falls just short.
    #[inline]
    fn refined(&self, p: Point3<f64>, need: f64, c: f64) -> f64 {
        if c > need || c + self.field_loss < need {
            return c;
        }
        self.measured_bound(p, need, c)
    }

    /// [`Self::bound`] where the field's bound `c` falls just short of `need`: the
    /// obstacle cubes nearby measured. Kept out of line (it is rare next to the
    /// one-lookup common case, and its frame would burden every call).
    #[cold]
    #[inline(never)]
    fn measured_bound(&self, p: Point3<f64>, need: f64, c: f64) -> f64 {
        let r_v = self.field.grid().resolution();
        // Below `need`, `exact_clearance` may give a cube that is not the nearest: only
        // a value above `need` is a proven distance.
        point_clearance::exact_clearance_above(&self.field, p, need, need + r_v).unwrap_or(c)
    }

    /// Whether the head's unit sphere (grown by the clearance margin) is free at `p`
    /// and `p` is inside the map's bounds. Conservative.
    pub fn is_head_free(&self, p: impl Into<Point3<f64>>) -> bool {
        let p = p.into();
        self.counters.head_points.fetch_add(1, Ordering::Relaxed);
        self.inside(p) && self.bound(p, self.unit_r) > self.unit_r
    }

    /// Whether the head's unit sphere can move along the straight segment `a b` (both
    /// ends inside the bounds, the swept sphere free). Conservative.
    pub fn is_head_segment_free(
        &self,
        a: impl Into<Point3<f64>>,
        b: impl Into<Point3<f64>>,
    ) -> bool {
        let (a, b) = (a.into(), b.into());
        self.counters.head_segments.fetch_add(1, Ordering::Relaxed);
        if !(self.inside(a) && self.inside(b)) {
            return false;
        }
        let (ca, cb) = (self.bound(a, self.unit_r), self.bound(b, self.unit_r));
        ca > self.unit_r
            && cb > self.unit_r
            && self
                .segment_free(Capsule {
                    a,
                    b,
                    r: self.unit_r,
                    ca,
                    cb,
                })
                .is_none()
    }

    /// Whether `p` is inside the map's bounds by at least [`FK_TOLERANCE`] (so that the
    /// exact `f64` kinematics agree).
    #[inline]
    fn inside(&self, p: Point3<f64>) -> bool {
        let (lo, hi) = self.field.grid().bounds();
        (0..3).all(|a| p[a] >= lo[a] + FK_TOLERANCE && p[a] <= hi[a] - FK_TOLERANCE)
    }

    /// Unit centres for `head` and `shape`, written into `p` (the caller's array: one
    /// returned by value was copied, at a twentieth of a placement's time).
    #[inline]
    fn points(&self, head: Point3<f64>, shape: &Shape, p: &mut WorldPoints) {
        // `kinematics::offsets`, in place for the same reason.
        let mut o = [Vector3::zeros(); MAX_UNITS];
        let z = Vector3::zeros();
        positions_into(self.params.link_length, z, shape.as_slice(), &mut o);
        for (q, v) in p.iter_mut().zip(o.iter()).take(shape.units()) {
            *q = head + v.cast::<f64>();
        }
    }

    fn check_input(&self, head: Point3<f64>, shape: &Shape) -> Result<(), Collision> {
        if shape.units() != self.params.n() {
            return Err(Collision::BadInput(
                "the shape is for another number of units",
            ));
        }
        if !finite3(&head) {
            return Err(Collision::BadInput("the head position is not finite"));
        }
        if shape.as_slice().iter().any(|a| !a.is_finite()) {
            return Err(Collision::BadInput("the shape has a non-finite angle"));
        }
        Ok(())
    }

    /// Conservative validity of one configuration: limits and self-collision (exact,
    /// core), every unit centre inside the bounds, and every body clear of obstacles by
    /// its radius plus the clearance margin (distance-field lower bounds).
    pub fn check_config(
        &self,
        head: impl Into<Point3<f64>>,
        shape: &Shape,
    ) -> Result<(), Collision> {
        // The map first: in clutter it rejects most configurations, and cheaply.
        self.check_placement(head, shape)?;
        shape_validity(&self.params, shape).map_err(Collision::Shape)
    }

    /// [`Self::check_config`] without the limits and self-collision part, for shapes
    /// already known to be valid (library and SRS shapes).
    pub fn check_placement(
        &self,
        head: impl Into<Point3<f64>>,
        shape: &Shape,
    ) -> Result<(), Collision> {
        let head = head.into();
        self.counters.configs.fetch_add(1, Ordering::Relaxed);
        self.check_input(head, shape)?;
        let n = shape.units();
        let mut p = [head; MAX_UNITS];
        self.points(head, shape, &mut p);
        let mut c = [0.0f64; MAX_UNITS];
        // Every unit's one-lookup bound first, side by side; the units it leaves short
        // get the fine query's, as `bound` would (`clearance_above` gives the fine
        // query's value where the coarse one falls short), without its coarse lookup.
        self.field.clearance_coarse_each(&p[..n], &mut c[..n]);
        for i in 0..n {
            if !self.inside(p[i]) {
                return Err(Collision::OutOfBounds(OutOfBounds::unit(i, p[i])));
            }
            if c[i] <= self.unit_r {
                c[i] = self.refined(p[i], self.unit_r, self.field.clearance(p[i]));
            }
            if c[i] <= self.unit_r {
                return Err(Collision::Map {
                    body: Body::Unit(i as u8),
                    point: p[i],
                });
            }
        }
        for k in 0..n - 1 {
            if let Some(at) = self.segment_free(self.link(p[k], p[k + 1], c[k], c[k + 1])) {
                return Err(Collision::Map {
                    body: Body::Link(k as u8),
                    point: at,
                });
            }
        }
        Ok(())
    }

    /// A link's capsule between unit centres `a` and `b`, whose bounds are `ca` and `cb`.
    fn link(&self, a: Point3<f64>, b: Point3<f64>, ca: f64, cb: f64) -> Capsule {
        let r = self.link_r;
        Capsule { a, b, r, ca, cb }
    }

    /// Sphere tracing of `capsule`. `None` when proven free, else the point where the
    /// proof failed.
    fn segment_free(&self, capsule: Capsule) -> Option<Point3<f64>> {
        let Capsule { a, b, r, ca, cb } = capsule;
        let len = (b - a).norm();
        // Points within ca - r of a (and cb - r of b) are proven free by the ends' bounds.
        let mut t = ca - r;
        let end = len - (cb - r);
        if t > end {
            return None;
        }
        if len <= 0.0 {
            return if ca > r { None } else { Some(a) };
        }
        let dir = (b - a) * (1.0 / len);
        loop {
            let s = a + dir * t.min(len);
            let m = self.bound(s, r + self.min_step) - r;
            if m < self.min_step {
                return Some(s);
            }
            t += m;
            if t > end {
                return None;
            }
        }
    }

    /// A proven lower bound on `distance - r` over `capsule`, from the bounds at its ends
    /// and at the centres of pieces, halving pieces until the Lipschitz loss is at most
    /// half the local bound (or the piece is tiny).
    fn segment_margin(&self, capsule: Capsule) -> (f64, Point3<f64>) {
        let Capsule { a, b, r, ca, cb } = capsule;
        let len = (b - a).norm();
        let wmin = self.field.grid().resolution() / 16.0;
        // Iterative refinement over a small stack of pieces [t0, t1] (in metres).
        let mut stack = [(0.0f64, 0.0f64); 48];
        let mut top = 1;
        stack[0] = (0.0, len);
        let mut best = (f64::INFINITY, a);
        while top > 0 {
            top -= 1;
            let (t0, t1) = stack[top];
            let w = 0.5 * (t1 - t0);
            let tm = t0 + w;
            let s = if len > 0.0 {
                a + (b - a) * (tm / len)
            } else {
                a
            };
            // A piece longer than two voxels is split rather than measured where the
            // field's bound falls short: its `need` reaches far, and measuring the cubes
            // within it reads many rows, where its two halves cost two lookups (a piece
            // of two voxels or less is measured). On the same 2000 cases, per 200:
            // translations 460 -> 387 us, shape changes 1.62 -> 1.47 ms (splitting
            // pieces longer than one voxel: 410 us, 1.56 ms; than four: 400 us, 1.55 ms).
            let raw = if w > self.field.grid().resolution() {
                self.field.clearance_above(s, r + 2.0 * w)
            } else {
                self.bound(s, r + 2.0 * w)
            };
            // Bounds for the piece: from its centre, and from both ends of the link.
            let m = (raw - w).max(ca - t1).max(cb - (len - t0)) - r;
            let good_enough = m >= 0.5 * (raw - r) || m >= 0.5 * (ca.min(cb) - r);
            if good_enough || w <= wmin || top + 2 > stack.len() {
                if m < best.0 {
                    best = (m, s);
                }
                if best.0 < self.min_step {
                    return best;
                }
            } else {
                stack[top] = (t0, tm);
                stack[top + 1] = (tm, t1);
                top += 2;
            }
        }
        best
    }
}

/// [`CollisionContext::check_config`] as a free function.
pub fn check_config(
    ctx: &CollisionContext,
    head: impl Into<Point3<f64>>,
    shape: &Shape,
) -> Result<(), Collision> {
    ctx.check_config(head, shape)
}

/// [`CollisionContext::check_translation`] as a free function.
pub fn check_translation(
    ctx: &CollisionContext,
    from: impl Into<Point3<f64>>,
    to: impl Into<Point3<f64>>,
    shape: &Shape,
) -> Result<(), EdgeCollision> {
    ctx.check_translation(from, to, shape)
}

/// [`CollisionContext::check_shape_change`] as a free function.
pub fn check_shape_change(
    ctx: &CollisionContext,
    head: impl Into<Point3<f64>>,
    from: &Shape,
    to: &Shape,
) -> Result<(), EdgeCollision> {
    ctx.check_shape_change(head, from, to)
}

#[cfg(test)]
mod tests;
