//! Shape validity without a map: joint limits and self-collision (docs/model.md
//! items 1 and 2), for one shape exactly and for a straight shape transition
//! conservatively.
//!
//! Bodies are the N unit spheres (radius `r_u`) and the N-1 link capsules (radius
//! `r_l`). Bodies that share a joint are not checked against each other: a unit and
//! the links ending at it, consecutive links, and consecutive units. Touching counts
//! as a collision.

use crate::geometry::{
    point_segment_distance, point_segment_distance_squared, segment_segment_distance,
};
use nalgebra::Vector3;

use crate::kinematics::{directions, link_direction, offsets_from, Points};
use crate::params::{ChainParams, MAX_LINKS};
use crate::shape::Shape;

/// A body of the chain (0-based indices).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Body {
    /// Unit `i` (0 is the head).
    Unit(u8),
    /// Link `k`, joining unit `k` to unit `k + 1`.
    Link(u8),
}

impl core::fmt::Display for Body {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        // 1-based in messages, as in the paper.
        match self {
            Body::Unit(i) => write!(f, "unit {}", i + 1),
            Body::Link(k) => write!(f, "link {}", k + 1),
        }
    }
}

/// The first reason a shape is not valid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Violation {
    /// Link `k`'s pitch exceeds `theta_max`.
    Pitch(u8),
    /// The bend between links `k` and `k + 1` exceeds `beta_max`.
    Bend(u8),
    /// Two bodies that share no joint touch or intersect.
    SelfCollision(Body, Body),
    /// A transition needs steps too small to make progress, or more than
    /// [`MAX_TRANSITION_STEPS`] of them: it is rejected (conservatively) rather than
    /// checked for ever.
    TooManySteps,
}

/// Most samples [`check_transition`] takes before it gives up and rejects the
/// transition: every loop of the core must end, on the autopilot too.
pub const MAX_TRANSITION_STEPS: u32 = 1 << 20;

impl core::fmt::Display for Violation {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Violation::Pitch(k) => write!(f, "link {} pitch exceeds theta_max", k + 1),
            Violation::Bend(k) => write!(
                f,
                "bend between links {} and {} exceeds beta_max",
                k + 1,
                k + 2
            ),
            Violation::SelfCollision(a, b) => write!(f, "{a} touches {b}"),
            Violation::TooManySteps => write!(
                f,
                "the transition needs more than {MAX_TRANSITION_STEPS} checked steps"
            ),
        }
    }
}

/// Bend angle between links `k` and `k + 1` (rad), from their direction vectors.
pub fn bend(shape: &Shape, k: usize) -> f32 {
    let a = link_direction(shape.pitch(k), shape.yaw(k));
    let b = link_direction(shape.pitch(k + 1), shape.yaw(k + 1));
    bend_between(&a, &b)
}

/// The angle between two link directions (rad): [`bend`] from directions at hand.
fn bend_between(a: &Vector3<f32>, b: &Vector3<f32>) -> f32 {
    libm::acosf(a.dot(b).clamp(-1.0, 1.0))
}

/// Joint limits only: pitch of every link, bend between consecutive links.
pub fn check_limits(params: &ChainParams, shape: &Shape) -> Result<(), Violation> {
    limits_with(params, shape, &directions(shape))
}

/// [`check_limits`] with the link directions already computed.
fn limits_with(
    params: &ChainParams,
    shape: &Shape,
    dirs: &[Vector3<f32>; MAX_LINKS],
) -> Result<(), Violation> {
    for k in 0..shape.links() {
        if shape.pitch(k).abs() > params.theta_max {
            return Err(Violation::Pitch(k as u8));
        }
    }
    for k in 0..shape.links().saturating_sub(1) {
        if bend_between(&dirs[k], &dirs[k + 1]) > params.beta_max {
            return Err(Violation::Bend(k as u8));
        }
    }
    Ok(())
}

/// Exact validity of one shape: limits, then self-collision.
pub fn check_shape(params: &ChainParams, shape: &Shape) -> Result<(), Violation> {
    let dirs = directions(shape);
    limits_with(params, shape, &dirs)?;
    let p = offsets_from(params, &dirs, shape.links());
    self_collision(params, shape.units(), &p)
}

/// The first pair of bodies (sharing no joint) that touch: the same test as
/// [`visit_pairs`] with `gap <= 0`, on squared distances where it can.
fn self_collision(params: &ChainParams, units: usize, p: &Points) -> Result<(), Violation> {
    let (ru, rl, l) = (params.unit_radius, params.link_radius, params.link_length);
    let (uu, ul) = ((2.0 * ru) * (2.0 * ru), (ru + rl) * (ru + rl));
    for i in 0..units {
        for j in i + 2..units {
            if (p[i] - p[j]).norm_squared() <= uu {
                return Err(Violation::SelfCollision(
                    Body::Unit(i as u8),
                    Body::Unit(j as u8),
                ));
            }
        }
        for m in (0..units - 1).filter(|&m| i != m && i != m + 1) {
            if point_segment_distance_squared(&p[i], &p[m], &p[m + 1]) <= ul {
                return Err(Violation::SelfCollision(
                    Body::Unit(i as u8),
                    Body::Link(m as u8),
                ));
            }
        }
    }
    // Links whose midpoints are farther apart than l + 2 r_l cannot touch.
    let far = (l + 2.0 * rl) * (l + 2.0 * rl);
    for a in 0..units - 1 {
        for b in a + 2..units - 1 {
            let (ma, mb) = ((p[a] + p[a + 1]) * 0.5, (p[b] + p[b + 1]) * 0.5);
            if (ma - mb).norm_squared() <= far
                && segment_segment_distance(&p[a], &p[a + 1], &p[b], &p[b + 1]) <= 2.0 * rl
            {
                return Err(Violation::SelfCollision(
                    Body::Link(a as u8),
                    Body::Link(b as u8),
                ));
            }
        }
    }
    Ok(())
}

/// Calls `f(a, b, gap)` for every pair of bodies that share no joint, where `gap` is
/// their distance minus the sum of their radii (<= 0 means touching). Stops when `f`
/// returns false.
pub fn visit_pairs(
    params: &ChainParams,
    units: usize,
    p: &Points,
    mut f: impl FnMut(Body, Body, f32) -> bool,
) {
    let (ru, rl) = (params.unit_radius, params.link_radius);
    for i in 0..units {
        for j in i + 2..units {
            if !f(
                Body::Unit(i as u8),
                Body::Unit(j as u8),
                (p[i] - p[j]).norm() - 2.0 * ru,
            ) {
                return;
            }
        }
        for m in 0..units - 1 {
            if i == m || i == m + 1 {
                continue;
            }
            let gap = point_segment_distance(&p[i], &p[m], &p[m + 1]) - ru - rl;
            if !f(Body::Unit(i as u8), Body::Link(m as u8), gap) {
                return;
            }
        }
    }
    for a in 0..units - 1 {
        for b in a + 2..units - 1 {
            let gap = segment_segment_distance(&p[a], &p[a + 1], &p[b], &p[b + 1]) - 2.0 * rl;
            if !f(Body::Link(a as u8), Body::Link(b as u8), gap) {
                return;
            }
        }
    }
}

/// The unit indices a body spans: `(first, last)`.
fn span(b: Body) -> (usize, usize) {
    match b {
        Body::Unit(i) => (i as usize, i as usize),
        Body::Link(k) => (k as usize, k as usize + 1),
    }
}

/// Checks the straight transition from `a` to `b` (each angle along its shortest
/// difference) for limits and self-collision, conservatively: it may reject a valid
/// transition, never accept an invalid one. `margin` (m, and rad for bends) is the
/// least slack kept at every sample; it bounds the number of steps.
///
/// Why it is safe: a link direction moves on the unit sphere at most at rate
/// `|d theta| + |d psi|` per unit of the interpolation parameter, so the distance
/// between two bodies can only change as fast as the links between them turn
/// (`l` times the sum of their rates). Each step advances by less than the
/// smallest slack divided by its rate, so no pair can close its gap in between.
pub fn check_transition(
    params: &ChainParams,
    a: &Shape,
    b: &Shape,
    margin: f32,
) -> Result<(), Violation> {
    check_limits(params, a)?;
    check_limits(params, b)?; // pitches move linearly: the end points bound them.
    let links = a.links();
    let mut rate = [0.0f32; MAX_LINKS];
    for (k, r) in rate.iter_mut().enumerate().take(links) {
        let dp = crate::angle::diff(a.pitch(k), b.pitch(k)).abs();
        let dy = crate::angle::diff(a.yaw(k), b.yaw(k)).abs();
        *r = dp + dy;
    }
    // prefix[k] = sum of rate[..k], so links lo..hi turn at l * (prefix[hi] - prefix[lo]).
    let mut prefix = [0.0f32; MAX_LINKS + 1];
    for k in 0..links {
        prefix[k + 1] = prefix[k] + rate[k];
    }
    let margin = margin.max(1e-5);
    let mut t = 0.0f32;
    for _ in 0..MAX_TRANSITION_STEPS {
        let s = if t >= 1.0 { *b } else { a.lerp(b, t) };
        let dt = safe_step(params, &s, &rate, &prefix, margin)?;
        if t >= 1.0 {
            return Ok(());
        }
        t = advance(t, dt).ok_or(Violation::TooManySteps)?;
    }
    Err(Violation::TooManySteps)
}

/// `t + dt` capped at 1, or `None` when the step is lost in the rounding of `t` (a
/// loop on it would never end).
fn advance(t: f32, dt: f32) -> Option<f32> {
    let next = (t + dt).min(1.0);
    (next > t).then_some(next)
}

/// At shape `s`, the largest parameter step that provably keeps every gap and bend
/// slack positive; an error when some slack is already below `margin`.
fn safe_step(
    params: &ChainParams,
    s: &Shape,
    rate: &[f32; MAX_LINKS],
    prefix: &[f32; MAX_LINKS + 1],
    margin: f32,
) -> Result<f32, Violation> {
    let mut dt = f32::INFINITY;
    // Each link's direction once, for the bends and the unit centres alike.
    let dirs = directions(s);
    for k in 0..s.links().saturating_sub(1) {
        let slack = params.beta_max - bend_between(&dirs[k], &dirs[k + 1]);
        if slack < margin {
            return Err(Violation::Bend(k as u8));
        }
        let r = rate[k] + rate[k + 1];
        if r > 0.0 {
            dt = dt.min(slack / r);
        }
    }
    let p = offsets_from(params, &dirs, s.links());
    let mut err = None;
    visit_pairs(params, s.units(), &p, |x, y, gap| {
        if gap < margin {
            err = Some(Violation::SelfCollision(x, y));
            return false;
        }
        let ((lx, hx), (ly, hy)) = (span(x), span(y));
        let (lo, hi) = (lx.min(ly), hx.max(hy));
        let r = params.link_length * (prefix[hi] - prefix[lo]);
        if r > 0.0 {
            dt = dt.min(gap / r);
        }
        true
    });
    match err {
        Some(v) => Err(v),
        // Step a little short of the bound so the next sample keeps positive slack.
        None => Ok(0.9 * dt),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::angle::deg;
    use crate::kinematics::offsets;

    proptest::proptest! {
        /// The squared-distance test of `check_shape` finds a collision exactly
        /// when `visit_pairs` reports a gap <= 0 (away from rounding ties).
        #[test]
        fn fast_self_collision_agrees_with_the_gaps(eta in proptest::collection::vec(-3.0f32..3.0, 11)) {
            let p = ChainParams { beta_max: core::f32::consts::PI, ..ChainParams::new(6) };
            let s = Shape::from_slice(6, &eta).unwrap();
            let pts = offsets(&p, &s);
            let mut min_gap = f32::INFINITY;
            visit_pairs(&p, 6, &pts, |_, _, g| { min_gap = min_gap.min(g); true });
            proptest::prop_assume!(min_gap.abs() > 1e-4);
            proptest::prop_assert_eq!(self_collision(&p, 6, &pts).is_err(), min_gap <= 0.0);
        }
    }

    #[test]
    fn line_is_valid_for_every_n() {
        for n in 2..=16u8 {
            let p = ChainParams::new(n);
            assert_eq!(check_shape(&p, &Shape::line(n, 0.4)), Ok(()));
        }
    }

    #[test]
    fn pitch_limit_is_inclusive() {
        let p = ChainParams::new(2);
        let s = Shape::from_slice(2, &[0.0, p.theta_max, 0.0]).unwrap();
        assert_eq!(check_limits(&p, &s), Ok(()));
        let s = Shape::from_slice(2, &[0.0, p.theta_max + 1e-4, 0.0]).unwrap();
        assert_eq!(check_limits(&p, &s), Err(Violation::Pitch(0)));
    }

    #[test]
    fn folding_back_breaks_the_bend_limit() {
        let p = ChainParams::new(3);
        let s = Shape::from_slice(3, &[0.0, 0.0, 0.0, 0.0, deg(150.0)]).unwrap();
        assert_eq!(check_shape(&p, &s), Err(Violation::Bend(0)));
    }

    #[test]
    fn a_closed_square_collides_with_itself() {
        // Five units around a square of side l: unit 5 lands on unit 1.
        let p = ChainParams {
            beta_max: deg(100.0),
            ..ChainParams::new(5)
        };
        let s = Shape::from_slice(
            5,
            &[
                0.0,
                0.0,
                0.0,
                0.0,
                deg(90.0),
                0.0,
                deg(180.0),
                0.0,
                deg(-90.0),
            ],
        )
        .unwrap();
        assert!(matches!(
            check_shape(&p, &s),
            Err(Violation::SelfCollision(_, _))
        ));
    }

    #[test]
    fn a_step_lost_in_rounding_ends_the_walk() {
        assert_eq!(advance(0.5, 0.25), Some(0.75));
        assert_eq!(advance(0.9, 0.5), Some(1.0));
        // Below half an ulp of 0.5: t + dt == t.
        assert_eq!(advance(0.5, 1e-9), None);
    }

    #[test]
    fn a_transition_of_a_huge_chain_ends() {
        // l = 1e4 m: the safe step falls below the rounding of t; it used to loop for
        // ever, now it ends (valid or conservatively rejected).
        let p = ChainParams {
            link_length: 1e4,
            ..ChainParams::new(5)
        };
        let a = Shape::line(5, 0.0);
        let mut b = a;
        for k in 0..4 {
            b.set_link(k, 0.0, deg(30.0) * (k % 2) as f32);
        }
        let r = check_transition(&p, &a, &b, 0.0);
        assert!(matches!(r, Ok(()) | Err(Violation::TooManySteps)), "{r:?}");
    }

    #[test]
    fn transition_checks_the_path_not_only_the_ends() {
        let p = ChainParams {
            beta_max: deg(179.0),
            ..ChainParams::new(3)
        };
        let straight = Shape::line(3, 0.0);
        let bent = Shape::from_slice(3, &[0.0, 0.0, 0.0, 0.0, deg(60.0)]).unwrap();
        assert_eq!(check_transition(&p, &straight, &straight, 1e-3), Ok(()));
        assert_eq!(check_transition(&p, &straight, &bent, 1e-3), Ok(()));
        // Both ends valid, but the short way from +140 to -140 deg folds link 2
        // straight back through 180 deg, onto the head.
        let left = Shape::from_slice(3, &[0.0, 0.0, 0.0, 0.0, deg(140.0)]).unwrap();
        let right = Shape::from_slice(3, &[0.0, 0.0, 0.0, 0.0, deg(-140.0)]).unwrap();
        assert_eq!(check_shape(&p, &left), Ok(()));
        assert_eq!(check_shape(&p, &right), Ok(()));
        assert!(check_transition(&p, &left, &right, 1e-3).is_err());
    }
}
