//! Widening: post-processing moves the plan's stations (the head positions where it
//! stops, with every shape change made there) towards the middle of narrow passages,
//! so that a plan keeps as much clearance through an opening as the opening allows,
//! not just the margin the search checked at (docs/postprocessing.md, stage 4; it runs
//! on the search's plan and again after refinement and shortening).
//!
//! The search checks at the preferred clearance (`--clearance`, 0.05 m); through a
//! 0.5 m window the chain's units could keep 0.1 m, and a plan that passes 1 cm from
//! the preferred margin's edge is valid but needlessly close. Widening looks at the
//! edges whose units come within [`CAP`] of the map, narrowest first, and, where the
//! unit keeps less than `WidenSettings::centred` of what the middle of its passage would, moves a
//! station next to it (or both ends of a translation together) a small step at a
//! time, in the direction that most increases that unit's clearance, while the
//! narrowest clearance of every edge the move touches grows. A translation whose ends
//! cannot move is split. Each move passes the checks of the context it is given, so
//! the plan stays as admissible as before. Clearance is measured exactly (sphere
//! against voxel cube) at twice the verifier's sample spacing; within `r_v` of the cap
//! the distance field's bound stands in for it. A move is judged by whether the
//! edges it touches stay above their floors, which measures far less than finding
//! their narrowest (most moves fail, and a look at the unit that was narrowest
//! settles most of those); an edge no move widens is given up with the
//! edges stuck at the same pinch (`WidenSettings::same_pinch`).
//!
//! An edge is judged by its narrowest sample, which lies in one passage; a second
//! pass ([`Widener::other_passages`]) widens translations that cross another passage
//! off its middle, by moves that narrow no edge.
//!
//! The start and the goal stay where they are. Work is counted in edge measurements
//! (`WidenSettings::budget`), not time, so the result is deterministic.

use nalgebra::{Point3, Vector3};
use rayon::prelude::*;

use std::time::Instant;

use super::numeric::{DIV_GUARD, TIE};
use super::{expired, Step, WidenSettings};
use crate::collision::exact::positions_f64;
use crate::collision::verify::{classify_edge, edge_intervals, edge_sample};
use crate::collision::CollisionContext;
use measure::{fails_near, keeps_above, measure, measure_whole, narrowest_of, samples, Narrowest};
use passage::{across, below_aim, in_passage};

mod measure;
mod passage;
#[cfg(test)]
mod tests;

pub(super) use measure::{distance, distance_below, gradient, zeta};

/// Clearances at or above this (m) are wide enough: widening leaves them alone.
///
/// Tuning left a constant: it is the cap of every clearance post-processing measures
/// (widening's samples, threading's pinches, `planner::Widening` and `arc plan`'s
/// report), which the measuring functions share without a settings value; a setting
/// would have to reach each of them and the reports.
pub const CAP: f64 = 0.25;

/// A run of steps at one head position: the translation into it, its shape changes,
/// and the translation out of it move with it.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Station {
    first: usize,
    last: usize,
}

/// What widening did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Widening {
    /// The plan's narrowest unit clearance before and after (m, at most [`CAP`]).
    pub before: f64,
    /// After.
    pub after: f64,
    /// After, over the edges whose narrowest unit is in a passage (obstacles on both
    /// sides, see `passage::in_passage`); `None` when there is none, or when the plan
    /// is threaded (`super::thread`), which widening does not measure.
    pub in_passages: Option<f64>,
    /// Moves taken: stations moved, and translations split.
    pub moves: usize,
    /// Edge measurements spent, of `WidenSettings::budget` (0 for a widening not made
    /// again, or a threaded plan's figures).
    pub measured: usize,
}

/// Moves the stations of `steps` towards the middle of narrow passages (see the module
/// docs). `ctx` is the context the plan was checked in; moves must pass its checks,
/// or, for an edge that did not pass them before (where the search gave way), those of
/// `ctx_min`. Past `deadline` (the query's time limit) no move is tried: the moves
/// taken are kept, and the result is as admissible as ever (only then can two runs
/// differ).
pub(super) fn widen(
    ctx: &CollisionContext,
    ctx_min: &CollisionContext,
    steps: Vec<Step>,
    deadline: Option<Instant>,
    s: &WidenSettings,
) -> (Vec<Step>, Widening) {
    let edges = steps.len().saturating_sub(1);
    let narrow: Vec<Narrowest> = (0..edges).map(|e| measure_whole(ctx, e, &steps)).collect();
    let mut w = Widener {
        ctx,
        ctx_min,
        stuck: vec![false; edges],
        narrow,
        steps,
        spent: edges,
        splits: 0,
        deadline,
        s,
    };
    let before = w.narrowest();
    let mut moves = 0;
    while w.may_spend() {
        let Some(e) = w.worst() else { break };
        if w.improve(e) {
            moves += 1;
        } else {
            w.stuck_at_pinch(e);
        }
    }
    moves += w.other_passages();
    let after = w.narrowest();
    let in_passages = w.narrowest_in_passages();
    let measured = w.spent;
    (
        w.steps,
        Widening {
            before,
            after,
            in_passages,
            moves,
            measured,
        },
    )
}

/// The narrowest unit clearance of `steps` over every edge (m, at most [`CAP`]), as
/// widening measures it: exactly, at twice the verifier's sample spacing.
pub(super) fn narrowest(ctx: &CollisionContext, steps: &[Step]) -> f64 {
    (0..steps.len().saturating_sub(1))
        .map(|e| measure_whole(ctx, e, steps).clearance)
        .fold(CAP, f64::min)
}

struct Widener<'a> {
    ctx: &'a CollisionContext,
    ctx_min: &'a CollisionContext,
    steps: Vec<Step>,
    /// Per edge `e` (steps `e` to `e + 1`), its narrowest sample.
    narrow: Vec<Narrowest>,
    /// Edges no move widens any more.
    stuck: Vec<bool>,
    spent: usize,
    /// Translations split so far.
    splits: usize,
    /// When to stop trying moves (the query's time limit).
    deadline: Option<Instant>,
    s: &'a WidenSettings,
}

impl Widener<'_> {
    /// Whether another measurement may be spent: budget left, and the deadline not
    /// passed.
    fn may_spend(&self) -> bool {
        self.spent < self.s.budget && !expired(self.deadline)
    }

    fn narrowest(&self) -> f64 {
        self.narrow.iter().map(|n| n.clearance).fold(CAP, f64::min)
    }

    /// The narrowest clearance over the edges whose narrowest unit is in a passage.
    fn narrowest_in_passages(&self) -> Option<f64> {
        (0..self.narrow.len())
            .filter(|&e| self.narrow[e].clearance < CAP)
            .filter(|&e| in_passage(self.ctx, self.s, self.narrow[e].at, self.along(e)))
            .map(|e| self.narrow[e].clearance)
            .min_by(f64::total_cmp)
    }

    /// The direction of edge `e` when it is a translation.
    fn along(&self, e: usize) -> Option<Vector3<f64>> {
        let (xa, xb) = (self.steps[e].xi, self.steps[e + 1].xi);
        Vector3::new(xb[0] - xa[0], xb[1] - xa[1], xb[2] - xa[2]).try_normalize(TIE)
    }

    /// The narrowest edge below [`CAP`] that may still widen.
    fn worst(&self) -> Option<usize> {
        (0..self.narrow.len())
            .filter(|&e| !self.stuck[e] && self.narrow[e].clearance < CAP)
            .min_by(|&a, &b| {
                self.narrow[a]
                    .clearance
                    .total_cmp(&self.narrow[b].clearance)
            })
    }

    /// Gives up edge `e`, which no move widens, and the edges stuck at its pinch
    /// (`WidenSettings::same_pinch`).
    fn stuck_at_pinch(&mut self, e: usize) {
        let pinch = self.narrow[e];
        for (k, n) in self.narrow.iter().enumerate() {
            let near = (n.at - pinch.at).norm() <= self.s.same_pinch;
            if k == e || (near && n.clearance <= pinch.clearance + self.s.plateau) {
                self.stuck[k] = true;
            }
        }
    }

    /// The station holding step `i`.
    fn station(&self, i: usize) -> Station {
        let xi = self.steps[i].xi;
        let mut s = Station { first: i, last: i };
        while s.first > 0 && self.steps[s.first - 1].xi == xi {
            s.first -= 1;
        }
        while s.last + 1 < self.steps.len() && self.steps[s.last + 1].xi == xi {
            s.last += 1;
        }
        s
    }

    /// Whether `s` may move: the start's and the goal's stations stay.
    fn movable(&self, s: Station) -> bool {
        s.first > 0 && s.last + 1 < self.steps.len()
    }

    /// Tries to widen edge `e`: moves of the stations at its ends, in the directions
    /// that widen its narrowest sample, largest step first. Returns whether a move was
    /// taken.
    fn improve(&mut self, e: usize) -> bool {
        let (a, b) = (self.station(e), self.station(e + 1));
        let mut groups: Vec<Vec<Station>> = Vec::new();
        if a == b {
            groups.push(vec![a]);
        } else {
            groups.push(vec![a, b]);
            groups.push(vec![a]);
            groups.push(vec![b]);
        }
        groups.retain(|g| g.iter().all(|&s| self.movable(s)));
        // Along a translation, moving its stations along it changes little: only the
        // part of a move across it widens.
        let along = self.along(e);
        let narrow = self.narrow[e];
        let grad = gradient(self.ctx, narrow.at);
        if !below_aim(self.ctx, self.s, narrow.at, grad, along, narrow.clearance) {
            // Open on one side, or as wide as the passage allows.
            return false;
        }
        if !groups.is_empty() && self.try_groups(e, &groups, grad, along) {
            return true;
        }
        self.splits < self.s.max_splits && self.split(e)
    }

    /// Tries the moves of `groups` along `grad` (then other directions); whether one
    /// was taken.
    fn try_groups(
        &mut self,
        e: usize,
        groups: &[Vec<Station>],
        grad: Vector3<f64>,
        along: Option<Vector3<f64>>,
    ) -> bool {
        let dirs = self.directions(grad, along);
        let r_v = self.ctx.field().grid().resolution();
        // Along the gradient at every step length; the other directions only at the
        // smallest, where the gradient's own step has failed.
        let mut tries: Vec<(f64, &Vector3<f64>)> = self
            .s
            .steps
            .iter()
            .flat_map(|&f| dirs.first().map(|d| (f, d)))
            .collect();
        let last = self.s.steps[self.s.steps.len() - 1];
        tries.extend(dirs.iter().skip(1).map(|d| (last, d)));
        for (f, d) in tries {
            for g in groups {
                if !self.may_spend() {
                    return false;
                }
                if self.try_move(g, d * (f * r_v), e) {
                    return true;
                }
            }
        }
        false
    }

    /// Splits translation `e` around the stretch where the chain passes near the map
    /// (any unit within [`CAP`] of it, by the distance field's bound): two stations on
    /// the segment, so that the stretch can move across as one. The plan flies the
    /// same path. Whether it split.
    fn split(&mut self, e: usize) -> bool {
        let Some(_) = self.along(e) else {
            return false;
        };
        let params = self.ctx.params();
        let (l, r_u) = (params.link_length as f64, params.unit_radius as f64);
        let (a, b) = (zeta(&self.steps[e]), zeta(&self.steps[e + 1]));
        let kind = classify_edge(&a, &b);
        let field = self.ctx.field();
        let r_v = field.grid().resolution();
        let n = edge_intervals(kind, l, &a, &b, r_v).max(1);
        let near: Vec<f64> = (0..=n)
            .map(|j| j as f64 / n as f64)
            .filter(|&t| {
                let z = edge_sample(kind, &a, &b, t);
                positions_f64(l, [z[0], z[1], z[2]], &z[3..])
                    .into_iter()
                    .any(|p| field.clearance_above(p, CAP + r_u) < CAP + r_u)
            })
            .collect();
        let (Some(&lo), Some(&hi)) = (near.first(), near.last()) else {
            return false;
        };
        let len = (0..3).map(|i| (b[i] - a[i]).powi(2)).sum::<f64>().sqrt();
        let margin = (2.0 * r_v / len).min(self.s.split_margin);
        let (lo, hi) = ((lo - margin).max(margin), (hi + margin).min(1.0 - margin));
        if hi - lo < margin {
            return false;
        }
        let at = |t: f64| {
            let mut s = self.steps[e + 1];
            s.xi = Point3::from([0, 1, 2].map(|i| a[i] + t * (b[i] - a[i])));
            s.shape_change = false;
            s
        };
        let (p, q) = (at(lo), at(hi));
        self.steps.splice(e + 1..e + 1, [p, q]);
        let fresh: Vec<Narrowest> = (e..e + 3)
            .map(|k| measure_whole(self.ctx, k, &self.steps))
            .collect();
        self.spent += 3;
        self.narrow.splice(e..=e, fresh);
        self.stuck.splice(e..=e, [false; 3]);
        self.splits += 1;
        true
    }

    /// Candidate directions at `p`: the exact clearance's gradient there, then the
    /// axis and face-diagonal directions that increase it most (`WidenSettings::directions` in all).
    fn directions(&self, grad: Vector3<f64>, along: Option<Vector3<f64>>) -> Vec<Vector3<f64>> {
        let flat = |v| across(v, along);
        let mut dirs: Vec<(f64, Vector3<f64>)> = Vec::new();
        for x in -1i32..=1 {
            for y in -1i32..=1 {
                for z in -1i32..=1 {
                    let n = x.abs() + y.abs() + z.abs();
                    if n == 0 || n == 3 {
                        continue;
                    }
                    let Some(d) =
                        flat(Vector3::new(x as f64, y as f64, z as f64)).try_normalize(TIE)
                    else {
                        continue;
                    };
                    let gain = d.dot(&grad);
                    if gain > 0.0 {
                        dirs.push((gain, d));
                    }
                }
            }
        }
        dirs.sort_by(|a, b| b.0.total_cmp(&a.0));
        flat(grad)
            .try_normalize(DIV_GUARD)
            .into_iter()
            .chain(dirs.into_iter().map(|(_, d)| d))
            .take(self.s.directions)
            .collect()
    }

    /// Moves the stations of `group` by `delta` when that widens every edge it touches
    /// whose narrowest sample is below the old narrowest of them, and the moved edges
    /// pass the checks. Returns whether the move was taken.
    fn try_move(&mut self, group: &[Station], delta: Vector3<f64>, first: usize) -> bool {
        let (moved, touched) = self.moved(group, delta);
        let old = touched
            .clone()
            .map(|e| self.narrow[e].clearance)
            .fold(f64::INFINITY, f64::min);
        // The edge being widened first: most moves that fail, fail there.
        let mut order: Vec<(usize, f64)> = touched.map(|k| (k, old + self.s.gain)).collect();
        order.sort_by_key(|&(k, _)| k != first);
        self.take_if_above(moved, &order)
    }

    /// The steps with the stations of `group` moved by `delta`, and the edges the move
    /// touches.
    fn moved(
        &self,
        group: &[Station],
        delta: Vector3<f64>,
    ) -> (Vec<Step>, std::ops::RangeInclusive<usize>) {
        let mut moved = self.steps.clone();
        for s in group {
            for st in &mut moved[s.first..=s.last] {
                st.xi += delta;
            }
        }
        let lo = group.iter().map(|s| s.first).min().unwrap_or(0);
        let hi = group.iter().map(|s| s.last).max().unwrap_or(0);
        (moved, lo.saturating_sub(1)..=hi.min(self.narrow.len() - 1))
    }

    /// Takes `moved` when each edge of `floors`, measured in that order, keeps more
    /// than its floor and every one passes the checks ([`Self::admissible`]).
    fn take_if_above(&mut self, moved: Vec<Step>, floors: &[(usize, f64)]) -> bool {
        let mut judged = Vec::with_capacity(floors.len());
        for &(k, floor) in floors {
            self.spent += 1;
            // Most moves that fail, fail where the edge was narrowest: a look there
            // settles them before every sample is placed.
            if fails_near(self.ctx, k, &moved, self.narrow[k].spot, floor) {
                return false;
            }
            let s = samples(self.ctx, k, &moved, |_| true);
            if !keeps_above(self.ctx, &s, floor) {
                return false;
            }
            judged.push(s);
        }
        // Taken when every edge passes the checks: their narrowest, each edge beside
        // the others (rayon: the checks of a long translation take milliseconds).
        let verdicts: Vec<(bool, Option<Narrowest>)> = floors
            .par_iter()
            .zip(&judged)
            .map(|(&(k, floor), s)| {
                let checked = self.admissible(k, &moved);
                (checked, narrowest_of(self.ctx, s, floor))
            })
            .collect();
        if verdicts.iter().any(|(checked, n)| !checked || n.is_none()) {
            return false;
        }
        for (&(k, _), (_, n)) in floors.iter().zip(verdicts) {
            self.narrow[k] = n.expect("every edge measured");
            self.stuck[k] = false;
        }
        self.steps = moved;
        true
    }

    /// The second pass: a translation whose narrowest sample keeps its passage's
    /// share may cross another passage off its middle (a tunnel, then a door a chain
    /// length further: widening judged the edge by the tunnel). For each such
    /// translation, the narrowest samples away from its narrowest
    /// (`WidenSettings::other_candidates`, `WidenSettings::separate` apart) are measured against their own
    /// passage's middle, and the first off it is widened by moves of the edge's
    /// stations that widen it there and narrow no edge they touch. Returns the moves.
    fn other_passages(&mut self) -> usize {
        let mut moves = 0;
        for e in 0..self.narrow.len() {
            let Some(along) = self.along(e) else { continue };
            while self.may_spend() && self.narrow[e].clearance < CAP {
                let Some((target, grad, away)) = self.off_middle(e, along) else {
                    break;
                };
                let (a, b) = (self.station(e), self.station(e + 1));
                let groups: Vec<Vec<Station>> = [vec![a, b], vec![b], vec![a]]
                    .into_iter()
                    .filter(|g| g.iter().all(|&s| self.movable(s)))
                    .collect();
                let Some(d) = self.directions(grad, Some(along)).first().copied() else {
                    break;
                };
                let r_v = self.ctx.field().grid().resolution();
                let taken = self.s.steps.iter().any(|&f| {
                    groups.iter().any(|g| {
                        self.may_spend() && self.try_move_at(g, d * (f * r_v), e, target, &away)
                    })
                });
                if !taken {
                    break;
                }
                moves += 1;
            }
        }
        moves
    }

    /// The narrowest sample of translation `e` in a passage other than its
    /// narrowest's, when it keeps less than its passage's aim ([`aim`]), with the
    /// clearance's gradient there and the samples of the other passages looked at
    /// before it.
    fn off_middle(
        &mut self,
        e: usize,
        along: Vector3<f64>,
    ) -> Option<(Narrowest, Vector3<f64>, Vec<Point3<f64>>)> {
        let mut away = vec![self.narrow[e].at];
        for _ in 0..self.s.other_candidates {
            let far = |p: &Point3<f64>| away.iter().all(|q| (p - q).norm() > self.s.separate);
            self.spent += 1;
            let n = measure(self.ctx, e, &self.steps, f64::NEG_INFINITY, far)?;
            if n.clearance >= CAP {
                return None;
            }
            let grad = gradient(self.ctx, n.at);
            if below_aim(self.ctx, self.s, n.at, grad, Some(along), n.clearance) {
                return Some((n, grad, away));
            }
            away.push(n.at);
        }
        None
    }

    /// [`Self::try_move`] for a sample of another passage: the move is taken when
    /// edge `e` keeps more than `target` in that passage (within `WidenSettings::separate` of it,
    /// and nearer it than the samples of the passages `away`), no edge the move
    /// touches gets narrower, and the moved edges pass the checks.
    fn try_move_at(
        &mut self,
        group: &[Station],
        delta: Vector3<f64>,
        e: usize,
        target: Narrowest,
        away: &[Point3<f64>],
    ) -> bool {
        let (moved, touched) = self.moved(group, delta);
        let near = |p: &Point3<f64>| {
            let d = (p - target.at).norm();
            d <= self.s.separate && away.iter().all(|q| (p - q).norm() > d)
        };
        self.spent += 1;
        if measure(self.ctx, e, &moved, target.clearance + self.s.gain, near).is_none() {
            return false;
        }
        let floors: Vec<(usize, f64)> = touched
            .map(|k| (k, self.narrow[k].clearance - TIE))
            .collect();
        self.take_if_above(moved, &floors)
    }

    /// Whether edge `e` of `moved` passes the search's checks, or, where the current
    /// edge `e` does not (the search gave way there), the smallest clearance's checks.
    fn admissible(&self, e: usize, moved: &[Step]) -> bool {
        if edge_passes(self.ctx, &moved[e], &moved[e + 1]) {
            return true;
        }
        !edge_passes(self.ctx, &self.steps[e], &self.steps[e + 1])
            && edge_passes(self.ctx_min, &moved[e], &moved[e + 1])
    }
}

/// Whether the edge from `a` to `b` passes the checks of `ctx` (a translation or a
/// shape change).
fn edge_passes(ctx: &CollisionContext, a: &Step, b: &Step) -> bool {
    if a.xi != b.xi {
        ctx.check_translation(a.xi, b.xi, &b.shape).is_ok()
    } else {
        ctx.check_shape_change(a.xi, &a.shape, &b.shape).is_ok()
    }
}
