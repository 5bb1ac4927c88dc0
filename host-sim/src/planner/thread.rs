//! Threading: the whole chain laid along its head's route, follow-the-leader from
//! start to goal, with the route straightened through the middle of every pinch.
//!
//! The search flies each head edge with the cheapest shape that passes it, so a chain
//! often crosses an opening at an angle or off its middle, and moving stations
//! (`super::widen`) cannot change the way it crosses. Threading rebuilds the plan
//! instead: through every pinch of the head's route (a stretch where the head is
//! closer than [`PINCH`] beyond its radius to the map) the route becomes the pinch's
//! own axis through its middle, and the chain follows its head along the route, so
//! every unit passes each pinch on its axis, in line with the units before it.
//!
//! Each step is still "change shape, then translate" (docs/model.md): the body is laid
//! back along the head's track ([`follow::lay_along_newest_last`]), then the chain
//! translates a short way. A translation of `ds` carries a unit whose own track turns
//! by `theta` from the head's heading `ds sin(theta)` off its track, so steps are
//! shortened while a unit is inside a pinch and the head heads elsewhere (at most
//! `ThreadSettings::off_track` of the map's resolution off). Every step passes the search's checks;
//! where one does not, threading gives up and the plan keeps the other stages'
//! result.

use std::time::{Duration, Instant};

use aerial_chain_core::kinematics::{link_direction, offsets};
use aerial_chain_core::Shape;
use nalgebra::{Point3, Vector3};
use rayon::prelude::*;

use super::candidates::Source;
use super::numeric::{TIE, TINY, TINY_F32};
use super::plan_ops::{differs, head_route};
use super::widen::{distance, gradient, zeta};
use super::{follow, Checker, Step, ThreadSettings};
use crate::collision::exact::positions_f64;
use crate::collision::point_clearance::exact_distance;
use crate::collision::verify::{classify_edge, edge_intervals, edge_sample};
use crate::collision::CollisionContext;

/// The head is in a pinch where its distance to the map is less than its radius plus
/// this (m): derived, the passages widening works on (`super::widen::CAP`).
const PINCH: f64 = super::widen::CAP;

/// Samples per link length of the elastic band handed to the follower: derived, finer
/// than the link so that the body laid along it follows the band's bends.
const BAND_SAMPLES_PER_LINK: f64 = 4.0;

/// Radians per degree, for the direction grid given in degrees.
const DEGREE: f64 = std::f64::consts::PI / 180.0;

/// A pinch of a head route: its axis, from `a` to `b` through its middle, and the
/// clearance a unit keeps in its middle.
#[derive(Clone, Copy, Debug)]
pub(super) struct Pinch {
    a: Point3<f64>,
    b: Point3<f64>,
    middle: f64,
}

/// The head route of a plan, straightened through its pinches.
pub(super) struct Threading {
    route: Vec<Point3<f64>>,
    pinches: Vec<Pinch>,
    s: ThreadSettings,
}

impl Threading {
    /// The head route of `raw` straightened through its pinches; `None` when it has
    /// no pinch.
    pub(super) fn of(ctx: &CollisionContext, raw: &[Step], s: &ThreadSettings) -> Option<Self> {
        Self::along(ctx, &head_route(raw), s)
    }

    /// The head route `route` (start first) straightened through its pinches; `None`
    /// when it has none.
    pub(super) fn along(
        ctx: &CollisionContext,
        route: &[Point3<f64>],
        s: &ThreadSettings,
    ) -> Option<Self> {
        if route.len() < 2 {
            return None;
        }
        let (route, pinches) = Router { ctx, s }.straightened(route);
        (!pinches.is_empty()).then_some(Self {
            route,
            pinches,
            s: *s,
        })
    }

    /// The head route of `raw` pulled into an elastic band (`Router::band`), then
    /// straightened through its pinches: for a plan whose own route the chain cannot
    /// follow. `None` when the band has no pinch.
    pub(super) fn banded(ctx: &CollisionContext, raw: &[Step], s: &ThreadSettings) -> Option<Self> {
        Self::along(ctx, &Router { ctx, s }.band(&head_route(raw)), s)
    }

    /// This threading with its route eased (`super::ease`) for a chain that starts as
    /// `start` does, then resampled every half `step`, so that a follower stepping
    /// `step` at most makes whole steps only.
    pub(super) fn eased(
        &self,
        ctx: &CollisionContext,
        start: &Step,
        step: f64,
        deadline: Option<Instant>,
    ) -> Self {
        let lead = offsets(ctx.params(), &start.shape)[1]
            .cast::<f64>()
            .try_normalize(TINY);
        let route = super::ease::eased(ctx, &self.route, lead, self.s.ease_rounds, deadline);
        Self {
            route: super::ease::resampled(&route, step / 2.0),
            pinches: self.pinches.clone(),
            s: self.s,
        }
    }

    /// The route the head follows (start first).
    pub(super) fn route(&self) -> &[Point3<f64>] {
        &self.route
    }

    /// The head route `route` (start first) as it is, with no pinch straightened: for a
    /// chain that starts or ends inside a passage (a pipe), whose route has no pinch
    /// with room on both sides to straighten.
    pub(super) fn as_is(route: &[Point3<f64>], s: &ThreadSettings) -> Option<Self> {
        (route.len() >= 2).then(|| Self {
            route: route.to_vec(),
            pinches: Vec::new(),
            s: *s,
        })
    }

    /// The least clearance a unit keeps in the middle of any of the route's pinches
    /// (m; at most [`PINCH`]).
    pub(super) fn narrowest_middle(&self) -> f64 {
        self.pinches.iter().map(|p| p.middle).fold(PINCH, f64::min)
    }

    /// The plan that follows the route from `start` in follow-the-leader steps of at
    /// most `step` (m), and the time its checks took; else, where any step fails the
    /// checks of `ctx`, the plan grows past `ThreadSettings::max_steps` or the checks
    /// run past `deadline` (the query's time limit), the number of steps it had made.
    pub(super) fn follow(
        &self,
        ctx: &CollisionContext,
        start: &Step,
        step: f64,
        deadline: Option<Instant>,
    ) -> Result<(Vec<Step>, Duration), usize> {
        if step <= 0.0 {
            return Err(0);
        }
        let mut f = Follower::new(ctx, start, step, deadline, &self.s);
        match f.along(&self.route) {
            Some(()) => Ok((f.steps, f.checker.time)),
            None => Err(f.steps.len()),
        }
    }

    /// How `steps` passes the pinches, over the samples of every edge at twice the
    /// verifier's spacing: the smallest share of a pinch middle's clearance that a
    /// unit alongside the pinch's axis keeps (its exact clearance over the pinch's
    /// `middle`), and, with `every_unit`, the smallest clearance of any unit, capped
    /// at [`super::widen::CAP`] (what widening reports).
    pub(super) fn measure(
        &self,
        ctx: &CollisionContext,
        steps: &[Step],
        every_unit: bool,
    ) -> Passing {
        let params = ctx.params();
        let (l, r_u) = (params.link_length as f64, params.unit_radius as f64);
        let field = ctx.field();
        let r_v = field.grid().resolution();
        let cap = r_u + super::widen::CAP.max(PINCH) + self.s.measure_slack;
        let mut out = Passing {
            share: f64::INFINITY,
            narrowest: super::widen::CAP,
        };
        for w in steps.windows(2) {
            let (za, zb) = (zeta(&w[0]), zeta(&w[1]));
            let kind = classify_edge(&za, &zb);
            let n = edge_intervals(kind, l, &za, &zb, r_v).max(1);
            for j in (0..=n).step_by(2).chain([n]) {
                let z = edge_sample(kind, &za, &zb, j as f64 / n as f64);
                for p in positions_f64(l, [z[0], z[1], z[2]], &z[3..]) {
                    let near = self.s.alongside;
                    let alongside = || self.pinches.iter().filter(move |k| k.alongside(p, near));
                    if (!every_unit && alongside().next().is_none())
                        || field.clearance_above(p, cap) >= cap
                    {
                        continue;
                    }
                    let d = exact_distance(field, p, cap).min(cap) - r_u;
                    out.narrowest = out.narrowest.min(d);
                    for k in alongside() {
                        out.share = out.share.min(d / k.middle.max(TIE));
                    }
                }
            }
        }
        out
    }
}

/// How a plan passes a route's pinches ([`Threading::measure`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct Passing {
    /// The smallest share of a pinch middle's clearance kept alongside its axis.
    pub(super) share: f64,
    /// The smallest clearance of any unit (m, capped).
    pub(super) narrowest: f64,
}

impl Pinch {
    /// Whether a unit at `p` is alongside the axis: between its ends, within `near`
    /// (m) of it.
    fn alongside(&self, p: Point3<f64>, near: f64) -> bool {
        let Some(u) = (self.b - self.a).try_normalize(TIE) else {
            return false;
        };
        let w = p - self.a;
        let along = w.dot(&u);
        (0.0..=(self.b - self.a).norm()).contains(&along) && (w - along * u).norm() <= near
    }
}

/// Pinches of a head route and their axes.
struct Router<'a> {
    ctx: &'a CollisionContext,
    s: &'a ThreadSettings,
}

impl Router<'_> {
    fn res(&self) -> f64 {
        self.ctx.field().grid().resolution()
    }

    fn r_u(&self) -> f64 {
        self.ctx.params().unit_radius as f64
    }

    /// The route with every pinch it crosses replaced by the pinch's axis, joined to
    /// the route before and after by straight lines the head can fly, or joined to
    /// the next axis (or the goal) directly where the head can fly there.
    fn straightened(&self, route: &[Point3<f64>]) -> (Vec<Point3<f64>>, Vec<Pinch>) {
        let (dense, vertex) = densify(route, self.res() / 2.0);
        let n = dense.len();
        let limit = self.r_u() + PINCH;
        let narrow: Vec<bool> = dense
            .iter()
            .map(|&p| self.ctx.clearance(p) < limit)
            .collect();
        let pinches = self.pinches(&dense, &narrow);
        let free = |r: std::ops::Range<usize>| r.filter(|&k| !narrow[k]);
        let mut out = vec![dense[0]];
        // The route's samples from `cursor` on are still to be flown (from the last
        // point of `out`, which flies to `dense[cursor]`).
        let mut cursor = 0;
        // Whether `out` ends on an axis (whose exit joins the route at `cursor`).
        let mut on_axis = false;
        let mut taken = Vec::new();
        for (i, &(first, last, pinch)) in pinches.iter().enumerate() {
            let (a, b) = (pinch.a, pinch.b);
            if first < cursor {
                continue;
            }
            let here = *out.last().expect("starts at the start");
            let direct = self.head_flies(here, a) && (a - here).dot(&(b - a)) > 0.0;
            // Where the route is left for the axis (None: from `here` directly).
            let mut left = None;
            if !direct {
                // Leaving the last axis takes the first half of the way between.
                let from = if on_axis {
                    (cursor + first) / 2
                } else {
                    cursor
                };
                let Some(k) = self.join(&dense, free(from..first).rev(), a, b - a) else {
                    continue;
                };
                left = Some(k);
            }
            let next = pinches.get(i + 1).map_or(n, |p| p.0);
            let Some(exit) = self.join(&dense, free(last + 1..(last + 1 + next) / 2 + 1), b, a - b)
            else {
                continue; // the axis cannot be left: fly the pinch as the route does.
            };
            if let Some(k) = left {
                push_route(&mut out, &dense, &vertex, cursor, k);
            }
            out.push(a);
            out.push(b);
            taken.push(pinch);
            on_axis = true;
            cursor = exit;
        }
        let here = *out.last().expect("starts at the start");
        let goal = dense[n - 1];
        if !on_axis || !self.head_flies(here, goal) {
            push_route(&mut out, &dense, &vertex, cursor, n - 1);
        } else {
            out.push(goal);
        }
        out.dedup();
        (out, taken)
    }

    /// The route as an elastic band (Quinlan and Khatib): sampled every voxel, then
    /// for `ThreadSettings::band_rounds` rounds every sample but the ends moves half
    /// way to the middle of its neighbours (which takes out the wandering of a
    /// search's route and spreads its kinks) and away from the map where a unit there
    /// would keep less than the pinch limit, by half of what it lacks (which keeps the
    /// band off the corners it would otherwise be pulled onto); a move the head could
    /// not make is not made. The band comes back sampled every quarter link: a follower
    /// lays its body along it, and its step is shorter.
    fn band(&self, route: &[Point3<f64>]) -> Vec<Point3<f64>> {
        let h = self.res();
        let (mut p, _) = densify(route, h);
        let limit = self.r_u() + PINCH;
        let n = p.len();
        for _ in 0..self.s.band_rounds {
            for k in 1..n - 1 {
                let mid = nalgebra::center(&p[k - 1], &p[k + 1]);
                let d = distance(self.ctx, p[k]);
                let push = if d < limit {
                    gradient(self.ctx, p[k]) * (limit - d)
                } else {
                    Vector3::zeros()
                };
                let q = p[k] + (mid - p[k]) * 0.5 + push * 0.5;
                if self.ctx.is_head_free(q) {
                    p[k] = q;
                }
            }
        }
        let spacing = self.ctx.params().link_length as f64 / BAND_SAMPLES_PER_LINK;
        let every = (spacing / h).round().max(1.0) as usize;
        let mut out: Vec<Point3<f64>> = p.iter().step_by(every).copied().collect();
        if out.last() != p.last() {
            out.push(p[n - 1]);
        }
        out
    }

    /// The pinches the route crosses: the first and last samples of each narrow
    /// stretch (neither the start's nor the goal's) and its axis where it has one.
    fn pinches(&self, dense: &[Point3<f64>], narrow: &[bool]) -> Vec<(usize, usize, Pinch)> {
        let n = dense.len();
        let mut stretches = Vec::new();
        let mut i = 0;
        while i < n {
            if !narrow[i] {
                i += 1;
                continue;
            }
            let first = i;
            while i < n && narrow[i] {
                i += 1;
            }
            if first == 0 || i >= n {
                continue; // the start or the goal in the pinch: leave it.
            }
            stretches.push(first..i);
        }
        // Each stretch's axis is found on its own (a millisecond or more each, on a
        // forest's route a dozen of them): on as many threads as there are, in order.
        stretches
            .into_par_iter()
            .filter_map(|r| {
                let last = r.end - 1;
                self.axis(&dense[r.clone()])
                    .map(|pinch| (r.start, last, pinch))
            })
            .collect()
    }

    /// Of the route samples `ks` (within `join_reach`, on the far side of `end` from
    /// the axis `u`), the one the head can fly to `end` from with the least turning,
    /// at the sample and at `end` together.
    fn join(
        &self,
        dense: &[Point3<f64>],
        ks: impl Iterator<Item = usize>,
        end: Point3<f64>,
        u: Vector3<f64>,
    ) -> Option<usize> {
        let angle =
            |x: Vector3<f64>, y: Vector3<f64>| match (x.try_normalize(TIE), y.try_normalize(TIE)) {
                (Some(x), Some(y)) => x.dot(&y).clamp(-1.0, 1.0).acos(),
                _ => 0.0,
            };
        let mut best: Option<(f64, usize)> = None;
        for k in ks.take(self.s.join_reach) {
            let to_end = end - dense[k];
            if to_end.dot(&u) <= 0.0 || !self.head_flies(dense[k], end) {
                continue;
            }
            // The route's own direction into k, coming from the far side.
            let from = if u.dot(&(dense.last()? - dense[0])) > 0.0 {
                k.checked_sub(1)
            } else {
                Some(k + 1).filter(|&j| j < dense.len())
            };
            let before = from.map_or(to_end, |j| dense[k] - dense[j]);
            let turn = angle(before, to_end) + angle(to_end, u);
            if best.is_none_or(|(t, _)| turn < t - TIE) {
                best = Some((turn, k));
            }
        }
        best.map(|(_, k)| k)
    }

    /// The axis of the pinch crossed by `stretch`: its middle and its direction, found
    /// from the stretch's narrowest sample, out to where the pinch ends on either side.
    /// `None` when the head cannot fly it.
    fn axis(&self, stretch: &[Point3<f64>]) -> Option<Pinch> {
        let heading = (stretch[stretch.len() - 1] - stretch[0]).try_normalize(TIE)?;
        let mut c = *stretch
            .iter()
            .min_by(|a, b| self.ctx.clearance(**a).total_cmp(&self.ctx.clearance(**b)))?;
        let mut u = heading;
        for _ in 0..self.s.axis_rounds {
            c = self.centre(c, u);
            c = self.narrowest_along(c, u);
            u = self.direction(c, u);
        }
        c = self.centre(c, u);
        (c, u) = self.through_tunnel(c, u);
        let limit = self.r_u() + PINCH;
        let reach = |sign: f64| {
            self.out_along()
                .find(|t| self.ctx.clearance(c + sign * t * u) >= limit)
        };
        let (a, b) = (c - reach(-1.0)? * u, c + reach(1.0)? * u);
        let middle = exact_distance(self.ctx.field(), c, limit).min(limit) - self.r_u();
        (middle > 0.0 && self.head_flies(a, b)).then_some(Pinch { a, b, middle })
    }

    /// The way through the pinch at `c`: the mean of the directions (within `cone_deg`
    /// of `guess`, on a grid of `grid_step_deg`) of the lines through `c` that run
    /// free for `escape` both ways. From inside an opening they form a cone about its
    /// axis.
    fn direction(&self, c: Point3<f64>, guess: Vector3<f64>) -> Vector3<f64> {
        let yaw0 = guess.y.atan2(guess.x);
        let pitch0 = guess.z.clamp(-1.0, 1.0).asin();
        let s = self.s;
        let (n, deg) = (s.grid_steps, DEGREE);
        // Every ray starts at `c`: its first step is the same for all.
        let at_c = self.ctx.clearance(c);
        let in_cone = (s.cone_deg * deg).cos();
        let yaws: Vec<(f64, f64)> = (-n..=n)
            .map(|i| (yaw0 + s.grid_step_deg * deg * i as f64).sin_cos())
            .collect();
        let mut sum = Vector3::zeros();
        for j in -n..=n {
            let pitch = pitch0 + s.grid_step_deg * deg * j as f64;
            if pitch.abs() > s.max_pitch_deg * deg {
                continue;
            }
            let (sin_p, cos_p) = (pitch.sin(), pitch.cos());
            for &(sin_y, cos_y) in &yaws {
                let u = Vector3::new(cos_y * cos_p, sin_y * cos_p, sin_p);
                if u.dot(&guess) > in_cone
                    && self.runs_free(c, u, at_c)
                    && self.runs_free(c, -u, at_c)
                {
                    // Weighted by the grid's cell size on the sphere.
                    sum += u * cos_p;
                }
            }
        }
        sum.try_normalize(TIE).unwrap_or(guess)
    }

    /// Distances out along a pinch's axis from its middle, every half voxel up to
    /// `axis_reach`: where a pinch's ends are looked for.
    fn out_along(&self) -> impl Iterator<Item = f64> {
        let (h, reach) = (self.res() / 2.0, self.s.axis_reach);
        (1..)
            .map(move |k| k as f64 * h)
            .take_while(move |t| *t < reach)
    }

    /// In a tunnel (a pinch at least `tunnel` long) the cone of free lines is
    /// narrow and the direction grid biases its mean by a degree or two, which a
    /// metre of tunnel turns into centimetres: there the axis is the line through the
    /// middles of its cross-sections near either end.
    fn through_tunnel(&self, c: Point3<f64>, u: Vector3<f64>) -> (Point3<f64>, Vector3<f64>) {
        // Inside the tunnel the distance field's bound stays within a voxel of the
        // narrowest (a tilted guess drifts towards a side by less).
        let floor = self.ctx.clearance(c) + self.res();
        let extent = |sign: f64| {
            self.out_along()
                .take_while(|t| self.ctx.clearance(c + sign * t * u) <= floor)
                .last()
                .unwrap_or(0.0)
        };
        let (back, on) = (extent(-1.0), extent(1.0));
        if back + on < self.s.tunnel {
            return (c, u);
        }
        let ends = self.s.tunnel_ends;
        let e0 = self.centre(c - ends * back * u, u);
        let e1 = self.centre(c + ends * on * u, u);
        match (e1 - e0).try_normalize(TIE) {
            Some(axis) if axis.dot(&u) > self.s.tunnel_aligned => {
                (self.centre(nalgebra::center(&e0, &e1), axis), axis)
            }
            _ => (c, u),
        }
    }

    /// The point of the line through `c` along `u`, within `narrowest_reach` half
    /// voxels, where the
    /// distance field's bound is least: inside the pinch rather than at its mouth.
    fn narrowest_along(&self, c: Point3<f64>, u: Vector3<f64>) -> Point3<f64> {
        let h = self.res() / 2.0;
        let n = self.s.narrowest_reach;
        (-n..=n)
            .map(|k| c + u * (k as f64 * h))
            .min_by(|a, b| self.ctx.clearance(*a).total_cmp(&self.ctx.clearance(*b)))
            .unwrap_or(c)
    }

    /// A ray from `c` along `u` runs `escape` without coming within half a voxel of
    /// the map (the distance field's bound, sphere tracing); `at_c` is the bound at
    /// `c`.
    fn runs_free(&self, c: Point3<f64>, u: Vector3<f64>, at_c: f64) -> bool {
        let stop = self.res() / 2.0;
        let (mut t, mut d) = (0.0, at_c);
        loop {
            if d < stop {
                return false;
            }
            t += d;
            if t >= self.s.escape {
                return true;
            }
            d = self.ctx.clearance(c + u * t);
        }
    }

    /// `c` moved across `u` (in the plane normal to it) to where the distance to the
    /// map is largest: gradient ascent with shrinking steps.
    fn centre(&self, mut c: Point3<f64>, u: Vector3<f64>) -> Point3<f64> {
        let mut d = distance(self.ctx, c);
        for step in self.s.centre_steps {
            for _ in 0..self.s.centre_rounds {
                let g = gradient(self.ctx, c);
                let Some(g) = (g - g.dot(&u) * u).try_normalize(TINY) else {
                    break;
                };
                let next = c + step * self.res() * g;
                let dn = distance(self.ctx, next);
                if dn <= d + TIE {
                    break;
                }
                (c, d) = (next, dn);
            }
        }
        c
    }

    /// The head (its sphere at the search's margin) can fly straight from `a` to `b`:
    /// the context's proven bound (exact next to the map), every half resolution.
    fn head_flies(&self, a: Point3<f64>, b: Point3<f64>) -> bool {
        let n = ((b - a).norm() / (self.res() / 2.0)).ceil().max(1.0) as usize;
        (0..=n).all(|k| self.ctx.is_head_free(a + (b - a) * (k as f64 / n as f64)))
    }
}

/// The route sampled every `h` (m) at most, each vertex kept; with each sample,
/// whether it is a vertex of the route.
pub(super) fn densify(route: &[Point3<f64>], h: f64) -> (Vec<Point3<f64>>, Vec<bool>) {
    let mut pts = vec![route[0]];
    let mut vertex = vec![true];
    for w in route.windows(2) {
        let n = ((w[1] - w[0]).norm() / h).ceil().max(1.0) as usize;
        for k in 1..=n {
            pts.push(w[0] + (w[1] - w[0]) * (k as f64 / n as f64));
            vertex.push(k == n);
        }
    }
    (pts, vertex)
}

/// Appends the route's vertices from dense sample `from` to `to` (both ends kept).
fn push_route(
    out: &mut Vec<Point3<f64>>,
    dense: &[Point3<f64>],
    vertex: &[bool],
    from: usize,
    to: usize,
) {
    for k in from..=to {
        if k == from || k == to || vertex[k] {
            out.push(dense[k]);
        }
    }
}

/// The chain following its head along a route.
struct Follower<'a> {
    ctx: &'a CollisionContext,
    checker: Checker,
    /// Head positions so far, the start's body first (newest last).
    track: Vec<Vector3<f32>>,
    steps: Vec<Step>,
    step: f64,
    head_yaw: f32,
    s: ThreadSettings,
}

impl<'a> Follower<'a> {
    fn new(
        ctx: &'a CollisionContext,
        start: &Step,
        step: f64,
        deadline: Option<Instant>,
        s: &ThreadSettings,
    ) -> Self {
        Self {
            ctx,
            checker: Checker::new(ctx.clone(), deadline),
            track: body_track(ctx.params(), start),
            steps: vec![*start],
            step,
            head_yaw: start.shape.head_yaw(),
            s: *s,
        }
    }

    /// Turns the chain about its head towards `dir` (the route's first heading) when
    /// its front link points more than `aligned` away from it: a body trailing across
    /// the route cannot be slid along it. The shares `align_shares` of the turn (the
    /// whole, three quarters, half), whichever passes the checks first; none when none
    /// does.
    fn align(&mut self, dir: Vector3<f64>) {
        let start = self.steps[0];
        let front = link_direction(start.shape.pitch(0), start.shape.yaw(0));
        if dir.xy().norm() < TINY || front.xy().norm() < TINY_F32 {
            return;
        }
        let turn =
            aerial_chain_core::angle::diff(front.y.atan2(front.x), dir.y.atan2(dir.x) as f32);
        if turn.abs() <= self.s.aligned {
            return;
        }
        for share in self.s.align_shares {
            let mut s = start.shape.rotated(turn * share);
            s.set_head_yaw(self.head_yaw);
            if self.checker.config(start.xi, &s)
                && self.checker.shape_change(start.xi, &start.shape, &s)
            {
                let turned = Step {
                    xi: start.xi,
                    shape: s,
                    source: Source::Follow,
                    shape_change: true,
                };
                self.track = body_track(self.ctx.params(), &turned);
                self.steps.push(turned);
                return;
            }
        }
    }

    /// Flies the head along `route` (which starts at the start's head), step by step;
    /// `None` where a step fails.
    fn along(&mut self, route: &[Point3<f64>]) -> Option<()> {
        self.align(route[1] - route[0]);
        for w in route.windows(2) {
            let mut p = self.head();
            while (w[1] - p).norm() > TIE {
                let shape = self.lay(p)?;
                let dir = (w[1] - p) / (w[1] - p).norm();
                let ds = self.step_length(p, &shape, dir).min((w[1] - p).norm());
                let q = if ds >= (w[1] - p).norm() {
                    w[1]
                } else {
                    p + dir * ds
                };
                if !self.checker.translation(p, q, &shape) {
                    return None;
                }
                self.steps.push(Step {
                    xi: q,
                    shape,
                    source: Source::Follow,
                    shape_change: false,
                });
                self.track.push(v32(q));
                if self.steps.len() > self.s.max_steps {
                    return None;
                }
                p = q;
            }
        }
        Some(())
    }

    fn head(&self) -> Point3<f64> {
        self.steps.last().expect("starts with the start").xi
    }

    fn shape(&self) -> Shape {
        self.steps.last().expect("starts with the start").shape
    }

    /// Lays the body along the track with the head at `p`, changing shape there when
    /// that moves it; the shape the chain then has.
    fn lay(&mut self, p: Point3<f64>) -> Option<Shape> {
        let mut laid = follow::lay_along_newest_last(self.ctx.params(), &self.track);
        // The head's yaw turns the units only: the start's is kept (`super::shorten`).
        laid.set_head_yaw(self.head_yaw);
        let shape = self.shape();
        if !differs(&laid, &shape) {
            return Some(shape);
        }
        if !(self.checker.config(p, &laid) && self.checker.shape_change(p, &shape, &laid)) {
            return None;
        }
        self.steps.push(Step {
            xi: p,
            shape: laid,
            source: Source::Follow,
            shape_change: true,
        });
        Some(laid)
    }

    /// How far the head may translate along `dir` from `p` in `shape`: the step, or
    /// less where a unit inside a pinch would be carried off its track.
    fn step_length(&self, p: Point3<f64>, shape: &Shape, dir: Vector3<f64>) -> f64 {
        let params = self.ctx.params();
        let res = self.ctx.field().grid().resolution();
        // A unit may enter a pinch during the step: it moves at most `self.step`.
        let near = params.unit_radius as f64 + self.s.in_pinch * PINCH + self.step;
        let o = offsets(params, shape);
        let mut ds = self.step;
        for (k, offset) in o.iter().enumerate().take(params.n()).skip(1) {
            if self.ctx.clearance(p + offset.cast::<f64>()) >= near {
                continue;
            }
            // The unit's track runs along the link in front of it.
            let along = link_direction(shape.pitch(k - 1), shape.yaw(k - 1)).cast::<f64>();
            let sin = along.cross(&dir).norm();
            if sin > TINY {
                ds = ds.min(self.s.off_track * res / sin);
            }
        }
        ds.max(self.s.min_step * res)
    }
}

/// The track a chain's body lays down, newest (the head) last; corners sharper
/// than 90 degrees cut, as the search's follow-the-leader does.
fn body_track(params: &aerial_chain_core::ChainParams, s: &Step) -> Vec<Vector3<f32>> {
    let head = v32(s.xi);
    let body: Vec<Vector3<f32>> = offsets(params, &s.shape)
        .iter()
        .take(params.n())
        .map(|o| head + o)
        .collect();
    let mut track = follow::cut_sharp_corners(&body, std::f32::consts::FRAC_PI_2);
    track.reverse();
    track
}

fn v32(p: Point3<f64>) -> Vector3<f32> {
    Vector3::new(p.x as f32, p.y as f32, p.z as f32)
}

#[cfg(test)]
#[path = "thread_tests.rs"]
mod tests;
