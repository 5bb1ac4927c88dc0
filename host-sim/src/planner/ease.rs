//! Easing a route the chain follows: its bends opened as wide as the space round it
//! lets them.
//!
//! When the chain follows its head (threading), every link turns through every bend of
//! the head's route, at `v / R` for a bend of radius `R` flown at speed `v`. The
//! trajectory keeps each angle's rate under the angular-rate limit `omega`, so a bend
//! tighter than `v / omega` (1.25 m at 0.5 m/s and 0.4 rad/s) slows the whole chain
//! for as long as any link is in it. A route found by the search hugs the corners it
//! turns round (`maze`: 0.5-0.65 m round each wall's end, where the maze has room for
//! 1.25 m and more), so eight units flew it at 2.5x head path / speed.
//!
//! Easing moves the route's points in two ways, level by level:
//! - **out from the map**, to a reach `r_u + c + l` from it where the space allows (a
//!   link's length beyond a unit's grown radius), each point also pulled toward its
//!   neighbours' middle: in a passage narrower than twice the reach the route runs
//!   down its middle, and round a wall's end it bends at the reach or wider;
//! - **to a lower bending energy** (the sum of squared second differences, whose
//!   minimiser spreads each bend as wide as it can be).
//!
//! Every move keeps a floor: no point comes nearer the map than the route it stands for
//! did, except down to [`CAP`](super::widen::CAP) where that kept more (clearance
//! beyond it is wide enough, as widening counts it), and no segment does either at its
//! samples every half voxel (between them it may pass up to a quarter voxel nearer;
//! the follower checks every step of the chain exactly); so passages and pinches keep
//! the clearance the route had. Coarse to fine: a bend
//! relaxes in rounds that grow with the fourth power of the points it spans, so the
//! points start two links apart and every segment is halved twice, down to half a
//! link. The start stays, and the route leaves it along the body's direction; the goal
//! stays. `maze` at N = 8: 78.2 and 81.4 s of flight became 51.9 and 53.6 s
//! (docs/postprocessing.md).

use std::time::Instant;

use nalgebra::{Point3, Vector3};

use super::numeric::TIE;
use super::widen::distance;
use crate::collision::CollisionContext;

/// The gradient step of the bending energy: its stable bound (the fourth difference's
/// largest eigenvalue is 16).
const STEP: f64 = 1.0 / 16.0;

/// The spacing of the coarsest level, in link lengths: derived, two links, so that a
/// bend of a few metres spans a few points and relaxes in tens of rounds.
const COARSEST: f64 = 2.0;

/// Levels, each with its segments halved: from two links to half a link.
const LEVELS: usize = 3;

/// A level's rounds of a kind stop once no point moves this share of a voxel:
/// derived, a hundredth, far below what the field resolves.
const SETTLED: f64 = 0.01;

/// The route `route` (start first) eased, for a chain whose link next to the head
/// points along `lead` at the start (a unit vector from the head back along the body:
/// the route leaves the start the other way); at most `rounds` rounds of each kind at
/// each level. Easing stops where `deadline` passes.
pub(super) fn eased(
    ctx: &CollisionContext,
    route: &[Point3<f64>],
    lead: Option<Vector3<f64>>,
    rounds: usize,
    deadline: Option<Instant>,
) -> Vec<Point3<f64>> {
    let l = ctx.params().link_length as f64;
    let late = || deadline.is_some_and(|d| Instant::now() >= d);
    let mut band = Band::along(ctx, route, COARSEST * l, lead);
    let settled = ctx.field().grid().resolution() * SETTLED;
    for level in 0..LEVELS {
        if level > 0 {
            band.halve();
        }
        for _ in 0..rounds {
            if late() {
                return band.p;
            }
            if band.spread() < settled {
                break;
            }
        }
        for _ in 0..rounds {
            if late() || band.relax() < settled {
                break;
            }
        }
    }
    band.p
}

/// How far from the map easing pushes a route where the space allows: a link's
/// length beyond a unit's grown radius, `r_u + c + l` (m). Round a wall's end the
/// eased route bends at about that or wider, so a route whose bends are all at least
/// this wide is left as it is.
pub(super) fn reach(ctx: &CollisionContext) -> f64 {
    let params = ctx.params();
    params.unit_radius as f64 + ctx.clearance_margin() + params.link_length as f64
}

/// How much `route` turns, seen a link at a time: the sum of the angles between the
/// consecutive segments of the route resampled every link length `l` (rad; a follower
/// turns each link by about that, and wiggles shorter than a link turn no link).
pub(super) fn turning(route: &[Point3<f64>], l: f64) -> f64 {
    let dirs: Vec<Vector3<f64>> = resampled(route, l)
        .windows(2)
        .filter_map(|w| (w[1] - w[0]).try_normalize(TIE))
        .collect();
    dirs.windows(2)
        .map(|d| d[0].dot(&d[1]).clamp(-1.0, 1.0).acos())
        .sum()
}

/// The tightest bend of `route` seen a link at a time: the least radius of the circles
/// through three consecutive points of the route resampled every link length `l` (m;
/// infinite for a straight route).
pub(super) fn tightest_bend(route: &[Point3<f64>], l: f64) -> f64 {
    resampled(route, l)
        .windows(3)
        .map(|w| {
            let (u, v) = (w[0] - w[1], w[2] - w[1]);
            let area2 = u.cross(&v).norm();
            match area2 > TIE {
                true => u.norm() * v.norm() * (u - v).norm() / (2.0 * area2),
                false => f64::INFINITY,
            }
        })
        .fold(f64::INFINITY, f64::min)
}

/// Points of a route being eased, each with its clearance floor.
struct Band<'a> {
    ctx: &'a CollisionContext,
    p: Vec<Point3<f64>>,
    /// The least distance to the map each point must keep (m, at most the cap of
    /// [`distance`]).
    floor: Vec<f64>,
    /// The body's direction back from the start (a unit vector; `None`: the start's
    /// direction is free).
    lead: Option<Vector3<f64>>,
    /// The spacing of the distance samples along a segment (m).
    spacing: f64,
    /// How far from the map the route is pushed where the space allows (m).
    reach: f64,
}

impl<'a> Band<'a> {
    /// The route's points at about `h` apart along it, with the floors of the route
    /// they stand for; where a segment between them would come nearer the map than
    /// that, it is split at the route's point halfway (down to the route's own
    /// samples).
    fn along(
        ctx: &'a CollisionContext,
        route: &[Point3<f64>],
        h: f64,
        lead: Option<Vector3<f64>>,
    ) -> Self {
        let spacing = ctx.field().grid().resolution() / 2.0;
        let dense = densified(route, spacing);
        let floors: Vec<f64> = dense.iter().map(|&q| distance(ctx, q)).collect();
        let stride = ((h / spacing).round() as usize).max(1);
        let reach = reach(ctx);
        let mut band = Band {
            ctx,
            p: vec![dense[0]],
            floor: vec![floors[0]],
            lead,
            spacing,
            reach,
        };
        let least = |a: usize, b: usize| floors[a..=b].iter().copied().fold(f64::MAX, f64::min);
        let mut from = 0;
        while from + 1 < dense.len() {
            let mut to = (from + stride).min(dense.len() - 1);
            while to > from + 1 && !band.segment_keeps(dense[from], dense[to], least(from, to)) {
                to = (from + to) / 2;
            }
            band.p.push(dense[to]);
            band.floor.push(least(from, to));
            from = to;
        }
        band
    }

    /// Every segment split at its middle; the new point keeps the lower floor of the
    /// segment's ends (the segment was checked against it).
    fn halve(&mut self) {
        let mut p = vec![self.p[0]];
        let mut floor = vec![self.floor[0]];
        for k in 1..self.p.len() {
            p.push(nalgebra::center(&self.p[k - 1], &self.p[k]));
            floor.push(self.floor[k - 1].min(self.floor[k]));
            p.push(self.p[k]);
            floor.push(self.floor[k]);
        }
        self.p = p;
        self.floor = floor;
    }

    /// One round out from the map: every point but the ends moves half way to its
    /// neighbours' middle and half of what it lacks of the reach along the field's
    /// gradient (the field's bound, capped at the reach: a push, not a measurement),
    /// where the move keeps the floors. The largest move made (m).
    fn spread(&mut self) -> f64 {
        let h = self.ctx.field().grid().resolution();
        let reach = self.reach;
        let bound = |x: Point3<f64>| self.ctx.clearance(x).min(reach);
        let mut largest = 0.0f64;
        for k in 1..self.p.len().saturating_sub(1) {
            let at = self.p[k];
            let d = bound(at);
            let push = if d < reach {
                let gradient = Vector3::from_fn(|i, _| {
                    let e = Vector3::ith(i, h);
                    (bound(at + e) - bound(at - e)) / (2.0 * h)
                });
                gradient * (reach - d)
            } else {
                Vector3::zeros()
            };
            let mid = nalgebra::center(&self.p[k - 1], &self.p[k + 1]);
            let q = at + (mid - at) * 0.5 + push * 0.5;
            if self.keeps_floor(k, q) {
                self.p[k] = q;
                largest = largest.max((q - at).norm());
            }
        }
        largest
    }

    /// Point `j` (before the start: along the body, at the spacing of the first
    /// segment), or `None` past the goal.
    fn at(&self, j: isize) -> Option<Point3<f64>> {
        if j < 0 {
            let h = (self.p.get(1)? - self.p[0]).norm();
            return self.lead.map(|d| self.p[0] + d * (h * (-j) as f64));
        }
        self.p.get(j as usize).copied()
    }

    /// The second difference centred on point `j`: `None` where a neighbour is
    /// missing (that term of the energy is left out, so the goal's direction is free).
    fn second_difference(&self, j: isize) -> Option<Vector3<f64>> {
        let (a, m, b) = (self.at(j - 1)?, self.at(j)?, self.at(j + 1)?);
        Some(a - m * 2.0 + b.coords)
    }

    /// One gradient step of the bending energy over every point but the ends; a move
    /// is kept where it keeps the floors, else tried at half its length once. The
    /// largest move made (m).
    fn relax(&mut self) -> f64 {
        let mut largest = 0.0f64;
        for i in 1..self.p.len().saturating_sub(1) {
            let d = |j: isize| self.second_difference(j).unwrap_or_else(Vector3::zeros);
            let j = i as isize;
            let mut delta = -(d(j - 1) - d(j) * 2.0 + d(j + 1)) * STEP;
            for _ in 0..2 {
                if delta.norm() < TIE {
                    break;
                }
                let q = self.p[i] + delta;
                if self.keeps_floor(i, q) {
                    self.p[i] = q;
                    largest = largest.max(delta.norm());
                    break;
                }
                delta *= 0.5;
            }
        }
        largest
    }

    /// Whether point `i` at `q` and the segments from its neighbours to it keep the
    /// floors: the point its own; a segment the lower of its ends'.
    fn keeps_floor(&self, i: usize, q: Point3<f64>) -> bool {
        self.ctx.is_head_free(q)
            && self.keeps(q, self.floor[i])
            && [i - 1, i + 1]
                .into_iter()
                .all(|j| self.segment_keeps(self.p[j], q, self.floor[i].min(self.floor[j])))
    }

    /// Whether every distance sample between `a` and `b` (ends left out) keeps `floor`.
    fn segment_keeps(&self, a: Point3<f64>, b: Point3<f64>, floor: f64) -> bool {
        let k = ((b - a).norm() / self.spacing).ceil() as usize;
        (1..k).all(|s| self.keeps(a + (b - a) * (s as f64 / k as f64), floor))
    }

    /// Whether `x` is at least `floor` from the map: the field's bound first (one
    /// lookup, enough almost everywhere), the distance measured where it falls short.
    fn keeps(&self, x: Point3<f64>, floor: f64) -> bool {
        self.ctx.clearance(x) + TIE >= floor || distance(self.ctx, x) + TIE >= floor
    }
}

/// `route` sampled every `h` at most, its vertices kept (threading's densifying),
/// with repeated points (a route's zero-length segments) left out.
fn densified(route: &[Point3<f64>], h: f64) -> Vec<Point3<f64>> {
    let (mut out, _) = super::thread::densify(route, h);
    out.dedup();
    out
}

/// `route` resampled every `h` along its length, its ends kept: a follower that
/// steps `2 h` at most then makes whole steps only (a remainder at every vertex makes
/// a short step that the trajectory cannot join to the steps beside it).
pub(super) fn resampled(route: &[Point3<f64>], h: f64) -> Vec<Point3<f64>> {
    let mut out = vec![route[0]];
    // How far past the last sample the current segment starts.
    let mut carried = 0.0;
    for w in route.windows(2) {
        let len = (w[1] - w[0]).norm();
        let mut s = h - carried;
        while s <= len {
            out.push(w[0] + (w[1] - w[0]) * (s / len));
            s += h;
        }
        carried = len - (s - h);
    }
    let goal = route[route.len() - 1];
    if (out[out.len() - 1] - goal).norm() > TIE {
        out.push(goal);
    }
    out
}

#[cfg(test)]
mod tests;
