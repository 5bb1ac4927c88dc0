//! Edges against the map: the conservative checks of a translation and of a shape
//! change by certified horizons (the module docs of `collision` give the argument).
//! Each body keeps its own horizon, the edge parameter up to which it is proven
//! free, and is measured again only where that horizon ends.

use std::sync::atomic::Ordering;

use aerial_chain_core::validity::{check_shape, check_transition, Body};
use aerial_chain_core::{Shape, MAX_UNITS};
use nalgebra::{Point3, Vector3};

use super::sweep;
use super::{
    finite3, shape_validity, Collision, CollisionContext, EdgeCollision, OutOfBounds, FK_TOLERANCE,
    TRANSITION_MARGIN,
};

impl CollisionContext {
    /// Conservative check of a translation edge: the shape stays, the head moves along
    /// the straight segment `from -> to`. Checks the shape once (limits, self-collision),
    /// the unit centres at both ends against the bounds (the box is convex), the units at
    /// the end against the map (refusing at once where one is proven inside it), and
    /// every body along the motion by certified horizons (see the module docs), run
    /// against the cubes near its path beside a wall.
    pub fn check_translation(
        &self,
        from: impl Into<Point3<f64>>,
        to: impl Into<Point3<f64>>,
        shape: &Shape,
    ) -> Result<(), EdgeCollision> {
        let (from, to) = (from.into(), to.into());
        self.counters.translations.fetch_add(1, Ordering::Relaxed);
        let at0 = |collision| EdgeCollision { t: 0.0, collision };
        self.check_input(from, shape).map_err(at0)?;
        if !finite3(&to) {
            return Err(at0(Collision::BadInput("the head position is not finite")));
        }
        shape_validity(&self.params, shape).map_err(|v| at0(Collision::Shape(v)))?;
        let n = shape.units();
        let mut p0 = [from; MAX_UNITS];
        self.points(from, shape, &mut p0);
        let delta = to - from;
        let dist = delta.norm();
        for (t, q) in [(0.0, from), (1.0, to)] {
            let off = q - from;
            for (i, u) in p0.iter().enumerate().take(n) {
                let w = u + off;
                if !self.inside(w) {
                    return Err(EdgeCollision {
                        t,
                        collision: Collision::OutOfBounds(OutOfBounds::unit(i, w)),
                    });
                }
            }
        }
        self.end_in_map(&p0[..n], delta)?;
        let dir = if dist > 0.0 {
            delta * (1.0 / dist)
        } else {
            Vector3::zeros()
        };
        // Bodies: units 0..n, then links n..2n-1. horizon[b]: proven free for displacement < horizon.
        let nb = 2 * n - 1;
        let mut horizon = [0.0f64; 2 * MAX_UNITS];
        let mut c = [0.0f64; MAX_UNITS];
        loop {
            let u = smallest(&horizon[..nb]).min(dist);
            let off = dir * u;
            let frac = if dist > 0.0 { u / dist } else { 0.0 };
            // Units first (the links use their bounds).
            for i in 0..n {
                if !needs_bound(&horizon, n, i, u) {
                    continue;
                }
                let q = p0[i] + off;
                c[i] = self.bound(q, self.unit_r + self.min_step);
                if horizon[i] <= u {
                    let m = c[i] - self.unit_r;
                    if m < self.min_step {
                        let collision = Collision::Map {
                            body: Body::Unit(i as u8),
                            point: q,
                        };
                        return Err(EdgeCollision { t: frac, collision });
                    }
                    horizon[i] = u + self.run_on(m, q, q, dir, self.unit_r, dist - u);
                }
            }
            for k in 0..n - 1 {
                if horizon[n + k] <= u {
                    let (a, b) = (p0[k] + off, p0[k + 1] + off);
                    let (m, at) = self.segment_margin(self.link(a, b, c[k], c[k + 1]));
                    if m < self.min_step {
                        let collision = Collision::Map {
                            body: Body::Link(k as u8),
                            point: at,
                        };
                        return Err(EdgeCollision { t: frac, collision });
                    }
                    horizon[n + k] = u + self.run_on(m, a, b, dir, self.link_r, dist - u);
                }
            }
            if horizon[..nb].iter().all(|&h| h > dist) {
                return Ok(());
            }
        }
    }

    /// A translation of the unit centres `p0` by `delta` that ends with a unit proven
    /// inside the map (its grown sphere meets an obstacle, by the field's bound and
    /// what that bound can lose) is refused before the walk: most refused translations
    /// end in a wall, and the walk, which would refuse it too, measures its way up to
    /// it first.
    fn end_in_map(&self, p0: &[Point3<f64>], delta: Vector3<f64>) -> Result<(), EdgeCollision> {
        for (i, u) in p0.iter().enumerate() {
            let w = u + delta;
            if self.field.clearance_above(w, self.unit_r) + self.field_loss < self.unit_r {
                let collision = Collision::Map {
                    body: Body::Unit(i as u8),
                    point: w,
                };
                return Err(EdgeCollision { t: 1.0, collision });
            }
        }
        Ok(())
    }

    /// How far a body of radius `body_r` (the segment `a b`; a unit when `a == b`) with
    /// margin `m` is proven free on a translation along `dir` with `left` (m) to go: `m`,
    /// or, where that is a small part of the way left (beside a wall), as far as the
    /// cubes near its path let it run ([`sweep::free_run`]) when that is further.
    fn run_on(
        &self,
        m: f64,
        a: Point3<f64>,
        b: Point3<f64>,
        dir: Vector3<f64>,
        body_r: f64,
        left: f64,
    ) -> f64 {
        if m * RUN_STEPS >= left {
            return m;
        }
        m.max(sweep::free_run(
            &self.field,
            a,
            b,
            dir,
            body_r + self.min_step,
            left,
        ))
    }

    /// Conservative check of a shape-change edge: the head stays at `head`, the shape
    /// moves from `from` to `to` (each angle along its shortest difference,
    /// `Shape::lerp`). Limits and self-collision by the core's `check_transition`; the
    /// bounds and the map by certified horizons using each body's speed bound (see the
    /// module docs). The shape halfway is looked at first, then the map, then the walk:
    /// the answer is the same in any order, the cost is not (the error names the first
    /// failure found in that order).
    pub fn check_shape_change(
        &self,
        head: impl Into<Point3<f64>>,
        from: &Shape,
        to: &Shape,
    ) -> Result<(), EdgeCollision> {
        let head = head.into();
        self.counters.shape_changes.fetch_add(1, Ordering::Relaxed);
        let at0 = |collision| EdgeCollision { t: 0.0, collision };
        self.check_input(head, from).map_err(at0)?;
        self.check_input(head, to).map_err(|c| EdgeCollision {
            t: 1.0,
            collision: c,
        })?;
        // The shape halfway first (one look at every pair of bodies: a change that
        // folds the chain through itself is mostly caught there), then the map (in
        // clutter it refuses most changes, for less than the walk below), then the walk
        // that proves limits and self-collision all along. `check_shape` itself, not
        // the per-thread memo of `shape_validity`: a halfway shape is seldom asked
        // twice, and would push out the shape the planner does ask again.
        check_shape(&self.params, &from.lerp(to, 0.5)).map_err(|v| EdgeCollision {
            t: 0.5,
            collision: Collision::Shape(v),
        })?;
        self.shape_change_map(head, from, to)?;
        check_transition(&self.params, from, to, TRANSITION_MARGIN)
            .map_err(|v| at0(Collision::Shape(v)))
    }

    /// The map part of [`Self::check_shape_change`]: the bounds and the obstacles along
    /// the change, by certified horizons.
    pub(super) fn shape_change_map(
        &self,
        head: Point3<f64>,
        from: &Shape,
        to: &Shape,
    ) -> Result<(), EdgeCollision> {
        let n = from.units();
        let l = self.params.link_length as f64;
        // speed[i]: bound on unit i's speed per unit of the edge parameter.
        let mut speed = [0.0f64; MAX_UNITS];
        for k in 0..n - 1 {
            let dp = aerial_chain_core::angle::diff(from.pitch(k), to.pitch(k)) as f64;
            let dy = aerial_chain_core::angle::diff(from.yaw(k), to.yaw(k)) as f64;
            // A small relative allowance for the f32 angle differences.
            speed[k + 1] = speed[k] + l * (dp * dp + dy * dy).sqrt() * (1.0 + 1e-6);
        }
        let g = self.field.grid();
        let (lo, hi) = g.bounds();
        let nb = 2 * n - 1;
        let mut horizon = [0.0f64; 2 * MAX_UNITS];
        let mut c = [0.0f64; MAX_UNITS];
        loop {
            let t = smallest(&horizon[..nb]).min(1.0);
            let s = if t >= 1.0 {
                *to
            } else {
                from.lerp(to, t as f32)
            };
            let mut p = [head; MAX_UNITS];
            self.points(head, &s, &mut p);
            for i in 0..n {
                if !needs_bound(&horizon, n, i, t) {
                    continue;
                }
                c[i] = self.bound(p[i], self.unit_r + self.min_step);
                if horizon[i] <= t {
                    // Inside-the-box margin and obstacle margin.
                    let mut inside = f64::INFINITY;
                    for a in 0..3 {
                        inside = inside.min(p[i][a] - lo[a]).min(hi[a] - p[i][a]);
                    }
                    if inside < FK_TOLERANCE {
                        let collision = Collision::OutOfBounds(OutOfBounds::unit(i, p[i]));
                        return Err(EdgeCollision { t, collision });
                    }
                    let m = c[i] - self.unit_r;
                    if m < self.min_step {
                        let collision = Collision::Map {
                            body: Body::Unit(i as u8),
                            point: p[i],
                        };
                        return Err(EdgeCollision { t, collision });
                    }
                    if speed[i] > 0.0 {
                        if inside < self.min_step {
                            let collision = Collision::OutOfBounds(OutOfBounds::unit(i, p[i]));
                            return Err(EdgeCollision { t, collision });
                        }
                        horizon[i] = t + m.min(inside) / speed[i];
                    } else {
                        horizon[i] = f64::INFINITY;
                    }
                }
            }
            for k in 0..n - 1 {
                if horizon[n + k] <= t {
                    let (m, at) = self.segment_margin(self.link(p[k], p[k + 1], c[k], c[k + 1]));
                    if m < self.min_step {
                        let collision = Collision::Map {
                            body: Body::Link(k as u8),
                            point: at,
                        };
                        return Err(EdgeCollision { t, collision });
                    }
                    let v = speed[k + 1];
                    horizon[n + k] = if v > 0.0 { t + m / v } else { f64::INFINITY };
                }
            }
            if horizon[..nb].iter().all(|&h| h > 1.0) {
                return Ok(());
            }
        }
    }
}

/// A body is run against the cubes near its path ([`sweep::free_run`]) when its margin
/// would take more than this many steps to cover the way left: below it, the walk costs
/// less than reading the cubes. It trades time only; measured on the translation bench's
/// cases (`window`, N = 5, per 200): never 795 us, 2 577 us, 3 554 us, 4 565 us, 6 592 us.
const RUN_STEPS: f64 = 3.0;

/// The smallest of `horizons` (infinity when there are none): how far every body is
/// proven free.
fn smallest(horizons: &[f64]) -> f64 {
    horizons.iter().copied().fold(f64::INFINITY, f64::min)
}

/// Whether unit `i`'s bound is needed at `u` along an edge: its own horizon or that of
/// a link it ends (`horizon`: units `0..n`, then links) is reached. The others are
/// proven free further on; measuring them anyway cost most of a translation check.
#[inline]
fn needs_bound(horizon: &[f64], n: usize, i: usize, u: f64) -> bool {
    horizon[i] <= u || (i > 0 && horizon[n + i - 1] <= u) || (i + 1 < n && horizon[n + i] <= u)
}
