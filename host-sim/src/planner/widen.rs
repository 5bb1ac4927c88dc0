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
//! unit keeps less than [`CENTRED`] of what the middle of its passage would, moves a
//! station next to it (or both ends of a translation together) a small step at a
//! time, in the direction that most increases that unit's clearance, while the
//! narrowest clearance of every edge the move touches grows. A translation whose ends
//! cannot move is split. Each move passes the checks of the context it is given, so
//! the plan stays as admissible as before. Clearance is measured exactly (sphere
//! against voxel cube) at twice the verifier's sample spacing; within `r_v` of the cap
//! the distance field's bound stands in for it.
//!
//! An edge is judged by its narrowest sample, which lies in one passage; a second
//! pass ([`Widener::other_passages`]) widens translations that cross another passage
//! off its middle, by moves that narrow no edge.
//!
//! The start and the goal stay where they are. Work is counted in edge measurements
//! ([`BUDGET`]), not time, so the result is deterministic.

use nalgebra::{Point3, Vector3};

use super::Step;
use crate::collision::exact::{exact_clearance, positions_f64};
use crate::collision::verify::{classify_edge, edge_intervals, edge_sample};
use crate::collision::CollisionContext;

/// Clearances at or above this (m) are wide enough: widening leaves them alone.
pub const CAP: f64 = 0.25;

/// Edge measurements widening may spend on one plan.
pub const BUDGET: usize = 150;

/// Step lengths tried, as fractions of the map's resolution, largest first.
const STEPS: [f64; 3] = [0.4, 0.15, 0.05];

/// Directions tried per step: the clearance's gradient, then the nearest lattice
/// directions (axes and face diagonals) that also widen.
const DIRECTIONS: usize = 3;

/// Samples of an edge are measured at the verifier's spacing times this: no unit
/// moves more than `SAMPLE_SPACING r_v / 4` between two, so a narrowest missed in
/// between is at most that much narrower (the clearance changes no faster than the
/// unit moves); `arc verify` reports the exact figure.
const SAMPLE_SPACING: f64 = 2.0;

/// Translations widening may split into three (per plan).
const MAX_SPLITS: usize = 2;

/// An edge whose narrowest unit keeps this share of what the middle of its passage
/// would keep is wide enough. The passages issue asks for 0.9; above 0.93 widening
/// spent its budget on millimetres (0.97 kept the same openings at the target on the
/// 200 instances of `arc bench robust`, in 10 % more time).
pub(super) const CENTRED: f64 = 0.93;

/// Narrowest samples nearer than this (m) are at the same pinch: where the moves of
/// one edge's stations could not widen it, the edges whose narrowest unit is this
/// near and keeps at most [`PLATEAU`] more are given up too. Their moves push the same
/// units against the same walls: on the 20 robust instances of `arc bench flight`
/// such edges were tried a dozen times each, for about a fifth of widening's
/// measurements, and almost never widened.
const SAME_PINCH: f64 = 0.15;

/// See [`SAME_PINCH`] (m).
const PLATEAU: f64 = 0.003;

/// Smallest gain (m) that counts as widening.
const GAIN: f64 = 1e-4;

/// The share of its passage's middle the passages issue asks a plan to keep. A
/// passage matters to widening up to the width where that share of its middle is
/// [`CAP`]: a door 0.85 m wide leaves a unit 0.275 m in its middle, and 0.9 of that
/// is less than the cap.
const TARGET_SHARE: f64 = 0.9;

/// Samples farther apart than this (m) may lie in two passages: an edge crossing
/// both is judged by its narrowest sample, in one of them, and
/// [`Widener::other_passages`] looks for the other.
const SEPARATE: f64 = 0.8;

/// Samples of another passage looked at per edge, narrowest first, each at least
/// [`SEPARATE`] from the ones before (a long tunnel holds several).
const OTHER_CANDIDATES: usize = 3;

/// A run of steps at one head position: the translation into it, its shape changes,
/// and the translation out of it move with it.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Station {
    first: usize,
    last: usize,
}

/// The narrowest sample of an edge: its clearance and where (unit centre).
#[derive(Clone, Copy, Debug)]
struct Narrowest {
    clearance: f64,
    at: Point3<f64>,
}

/// The unit positions at an edge's samples, with the distance field's lower bound on
/// their distance to the map, lowest first (those within `CAP + r_u`).
struct Samples {
    bounds: Vec<(f64, Point3<f64>)>,
    /// The largest bound that may still hold the narrowest: the lowest plus what the
    /// bound can lose, `r_v sqrt(3)`.
    within: f64,
    /// The edge's first head position, where an edge wider than the cap is placed.
    start: Point3<f64>,
}

/// What widening did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Widening {
    /// The plan's narrowest unit clearance before and after (m, at most [`CAP`]).
    pub before: f64,
    /// After.
    pub after: f64,
    /// After, over the edges whose narrowest unit is in a passage (obstacles on both
    /// sides, see `Widener::middles`); `None` when there is none, or when the plan
    /// is threaded (`super::thread`), which widening does not measure.
    pub in_passages: Option<f64>,
    /// Moves taken: stations moved, and translations split.
    pub moves: usize,
}

/// Moves the stations of `steps` towards the middle of narrow passages (see the module
/// docs). `ctx` is the context the plan was checked in; moves must pass its checks,
/// or, for an edge that did not pass them before (where the search gave way), those of
/// `ctx_min`.
pub(super) fn widen(
    ctx: &CollisionContext,
    ctx_min: &CollisionContext,
    steps: Vec<Step>,
) -> (Vec<Step>, Widening) {
    let mut w = Widener {
        ctx,
        ctx_min,
        narrow: Vec::new(),
        steps,
        spent: 0,
        splits: 0,
        stuck: Vec::new(),
    };
    let start = w.steps.clone();
    w.narrow = (0..start.len().saturating_sub(1))
        .map(|e| {
            w.spent += 1;
            w.measure_whole(e, &start)
        })
        .collect();
    w.stuck = vec![false; w.narrow.len()];
    let before = w.narrowest();
    let mut moves = 0;
    while w.spent < BUDGET {
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
    (
        w.steps,
        Widening {
            before,
            after,
            in_passages,
            moves,
        },
    )
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
}

impl Widener<'_> {
    fn narrowest(&self) -> f64 {
        self.narrow.iter().map(|n| n.clearance).fold(CAP, f64::min)
    }

    /// The narrowest clearance over the edges whose narrowest unit is in a passage.
    fn narrowest_in_passages(&self) -> Option<f64> {
        (0..self.narrow.len())
            .filter(|&e| self.narrow[e].clearance < CAP)
            .filter(|&e| self.in_passage(self.narrow[e].at, self.along(e)))
            .map(|e| self.narrow[e].clearance)
            .min_by(f64::total_cmp)
    }

    /// The direction of edge `e` when it is a translation.
    fn along(&self, e: usize) -> Option<Vector3<f64>> {
        let (xa, xb) = (self.steps[e].xi, self.steps[e + 1].xi);
        Vector3::new(xb[0] - xa[0], xb[1] - xa[1], xb[2] - xa[2]).try_normalize(1e-9)
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
    /// ([`SAME_PINCH`]).
    fn stuck_at_pinch(&mut self, e: usize) {
        let pinch = self.narrow[e];
        for (k, n) in self.narrow.iter().enumerate() {
            let near = (n.at - pinch.at).norm() <= SAME_PINCH;
            if k == e || (near && n.clearance <= pinch.clearance + PLATEAU) {
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
        let grad = self.gradient(narrow.at);
        if !self.below_aim(narrow.at, grad, along, narrow.clearance) {
            // Open on one side, or as wide as the passage allows.
            return false;
        }
        if !groups.is_empty() && self.try_groups(e, &groups, grad, along) {
            return true;
        }
        self.splits < MAX_SPLITS && self.split(e)
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
        let mut tries: Vec<(f64, &Vector3<f64>)> = STEPS
            .iter()
            .flat_map(|&f| dirs.first().map(|d| (f, d)))
            .collect();
        let last = STEPS[STEPS.len() - 1];
        tries.extend(dirs.iter().skip(1).map(|d| (last, d)));
        for (f, d) in tries {
            for g in groups {
                if self.spent >= BUDGET {
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
        let margin = (2.0 * r_v / len).min(0.25);
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
            .map(|k| self.measure_whole(k, &self.steps))
            .collect();
        self.spent += 3;
        self.narrow.splice(e..=e, fresh);
        self.stuck.splice(e..=e, [false; 3]);
        self.splits += 1;
        true
    }

    /// Candidate directions at `p`: the exact clearance's gradient there, then the
    /// axis and face-diagonal directions that increase it most ([`DIRECTIONS`] in all).
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
                        flat(Vector3::new(x as f64, y as f64, z as f64)).try_normalize(1e-9)
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
            .try_normalize(1e-12)
            .into_iter()
            .chain(dirs.into_iter().map(|(_, d)| d))
            .take(DIRECTIONS)
            .collect()
    }

    /// The gradient of the distance to the map at `p`.
    fn gradient(&self, p: Point3<f64>) -> Vector3<f64> {
        gradient(self.ctx, p)
    }

    /// Whether a unit keeping `clearance` at `p` keeps less than widening aims for
    /// ([`aim`]) in the middle of the passage there ([`Self::middles`] over the
    /// projected gradient `grad` and the axes, the shortest chord counting); false where
    /// there is no passage. Stops at the first chord whose middle the unit already
    /// keeps its aim of.
    fn below_aim(
        &self,
        p: Point3<f64>,
        grad: Vector3<f64>,
        along: Option<Vector3<f64>>,
        clearance: f64,
    ) -> bool {
        let lines = across_all(&[grad, Vector3::x(), Vector3::y(), Vector3::z()], along);
        let mut middles = self.middles(p, &lines, along).peekable();
        middles.peek().is_some() && middles.all(|m| clearance < aim(m))
    }

    /// Whether `p` lies in a passage ([`Self::middles`] over the gradient there and
    /// the axes finds a chord): the axes first, the gradient only where they find none.
    fn in_passage(&self, p: Point3<f64>, along: Option<Vector3<f64>>) -> bool {
        let axes = across_all(&[Vector3::x(), Vector3::y(), Vector3::z()], along);
        if self.middles(p, &axes, along).next().is_some() {
            return true;
        }
        let grad = across_all(&[self.gradient(p)], along);
        let found = self.middles(p, &grad, along).next().is_some();
        found
    }

    /// The clearance a unit would keep in the middle of the passage at `p` along each
    /// of the unit directions `lines` (across `along`): for each line through `p` that
    /// meets obstacles on both sides within reach, the free chord halved, less the
    /// unit's radius; the passage's middle is the shortest. None where no line does:
    /// open space, or a passage wider than [`CAP`] allows to matter. Lazy: each chord
    /// costs two sphere traces.
    fn middles<'b>(
        &'b self,
        p: Point3<f64>,
        lines: &'b [Vector3<f64>],
        along: Option<Vector3<f64>>,
    ) -> impl Iterator<Item = f64> + 'b {
        let r_u = self.ctx.params().unit_radius as f64;
        // A unit about to enter an opening is narrowest in front of it: the passage's
        // cross-section lies a little further along.
        let shifts: &[f64] = match along {
            Some(_) => &[0.0, 0.05, -0.05, 0.1, -0.1, 0.2, -0.2],
            None => &[0.0],
        };
        let u_along = along.unwrap_or_else(Vector3::zeros);
        shifts
            .iter()
            .map(move |&s| p + u_along * s)
            .flat_map(move |q| lines.iter().map(move |&u| (q, u)))
            .filter_map(move |(q, u)| Some(self.free_run(q, u)? + self.free_run(q, -u)?))
            .map(move |chord| chord / 2.0 - r_u)
    }

    /// How far from `p` along `u` the first obstacle lies, within the widest passage
    /// that matters, `2 (CAP / TARGET_SHARE + r_u)`: sphere tracing, with the distance
    /// field's lower bound while it is large and the exact distance near the obstacle.
    fn free_run(&self, p: Point3<f64>, u: Vector3<f64>) -> Option<f64> {
        let f = self.ctx.field();
        let r_v = f.grid().resolution();
        let reach = 2.0 * (CAP / TARGET_SHARE + self.ctx.params().unit_radius as f64);
        let mut t = 0.0;
        while t < reach {
            let q = p + u * t;
            let mut d = f.clearance(q);
            if d < r_v {
                d = self.distance(q);
                if d < 1e-3 {
                    return Some(t);
                }
            }
            t += d.max(1e-3);
        }
        None
    }

    /// Distance from `p` to the nearest obstacle cube, capped at `CAP + r_u`.
    fn distance(&self, p: Point3<f64>) -> f64 {
        distance(self.ctx, p)
    }

    /// Distance from `p` to the nearest obstacle cube, capped at `cap`.
    fn distance_below(&self, p: Point3<f64>, cap: f64) -> f64 {
        distance_below(self.ctx, p, cap)
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
        let mut order: Vec<(usize, f64)> = touched.map(|k| (k, old + GAIN)).collect();
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
        let mut samples = Vec::with_capacity(floors.len());
        for &(k, floor) in floors {
            self.spent += 1;
            let s = self.samples(k, &moved, |_| true);
            if !self.keeps_above(&s, floor) {
                return false;
            }
            samples.push(s);
        }
        if !floors.iter().all(|&(k, _)| self.admissible(k, &moved)) {
            return false;
        }
        // Taken: the narrowest of each edge it changed.
        let mut new = Vec::with_capacity(floors.len());
        for (&(k, floor), s) in floors.iter().zip(&samples) {
            match self.narrowest_of(s, floor) {
                Some(n) => new.push((k, n)),
                None => return false,
            }
        }
        for (k, n) in new {
            self.narrow[k] = n;
            self.stuck[k] = false;
        }
        self.steps = moved;
        true
    }

    /// The second pass: a translation whose narrowest sample keeps its passage's
    /// share may cross another passage off its middle (a tunnel, then a door a chain
    /// length further: widening judged the edge by the tunnel). For each such
    /// translation, the narrowest samples away from its narrowest
    /// ([`OTHER_CANDIDATES`], [`SEPARATE`] apart) are measured against their own
    /// passage's middle, and the first off it is widened by moves of the edge's
    /// stations that widen it there and narrow no edge they touch. Returns the moves.
    fn other_passages(&mut self) -> usize {
        let mut moves = 0;
        for e in 0..self.narrow.len() {
            let Some(along) = self.along(e) else { continue };
            while self.spent < BUDGET && self.narrow[e].clearance < CAP {
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
                let taken = STEPS.iter().any(|&f| {
                    groups.iter().any(|g| {
                        self.spent < BUDGET && self.try_move_at(g, d * (f * r_v), e, target, &away)
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
        for _ in 0..OTHER_CANDIDATES {
            let far = |p: &Point3<f64>| away.iter().all(|q| (p - q).norm() > SEPARATE);
            self.spent += 1;
            let n = self.measure(e, &self.steps, f64::NEG_INFINITY, far)?;
            if n.clearance >= CAP {
                return None;
            }
            let grad = self.gradient(n.at);
            if self.below_aim(n.at, grad, Some(along), n.clearance) {
                return Some((n, grad, away));
            }
            away.push(n.at);
        }
        None
    }

    /// [`Self::try_move`] for a sample of another passage: the move is taken when
    /// edge `e` keeps more than `target` in that passage (within [`SEPARATE`] of it,
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
            d <= SEPARATE && away.iter().all(|q| (p - q).norm() > d)
        };
        self.spent += 1;
        if self
            .measure(e, &moved, target.clearance + GAIN, near)
            .is_none()
        {
            return false;
        }
        let floors: Vec<(usize, f64)> = touched
            .map(|k| (k, self.narrow[k].clearance - 1e-9))
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

    /// The narrowest unit clearance of edge `e` of `steps`, exactly, at the verifier's
    /// samples (capped at [`CAP`]): [`Self::measure`] over every sample.
    fn measure_whole(&self, e: usize, steps: &[Step]) -> Narrowest {
        self.measure(e, steps, f64::NEG_INFINITY, |_| true)
            .expect("no clearance is at or below minus infinity")
    }

    /// The narrowest unit clearance of edge `e` of `steps` over the unit positions
    /// `keep` keeps, exactly, at the verifier's samples (capped at [`CAP`]); `None` at
    /// the first sample at or below `floor`. The distance field's proven lower bound
    /// picks the samples that can hold the minimum (the exact distance exceeds the
    /// bound by at most `r_v sqrt(3)`); only those are measured exactly, lowest bound
    /// first. One measurement of widening's [`BUDGET`]; the caller counts it.
    fn measure(
        &self,
        e: usize,
        steps: &[Step],
        floor: f64,
        keep: impl Fn(&Point3<f64>) -> bool,
    ) -> Option<Narrowest> {
        self.narrowest_of(&self.samples(e, steps, keep), floor)
    }

    /// [`Self::measure`] of an edge's `samples`.
    fn narrowest_of(&self, samples: &Samples, floor: f64) -> Option<Narrowest> {
        let r_u = self.ctx.params().unit_radius as f64;
        let r_v = self.ctx.field().grid().resolution();
        let mut best = Narrowest {
            clearance: CAP,
            at: samples.start,
        };
        for &(lb, p) in &samples.bounds {
            // A bound within a micrometre of the best is as good as equal: the samples
            // along a flat face all share it.
            if lb - r_u + 1e-6 >= best.clearance || lb > samples.within {
                break;
            }
            // Near the cap the bound is close enough: the exact measure there costs
            // the most (the farthest rings) and matters the least.
            let c = if lb - r_u >= CAP - r_v {
                lb - r_u
            } else {
                // Only a distance below the best so far can matter (most samples of
                // an edge are wider).
                let below = best.clearance + r_u;
                let d = self.distance_below(p, below);
                if d >= below {
                    continue;
                }
                d - r_u
            };
            if c <= floor {
                return None;
            }
            if c < best.clearance {
                best = Narrowest {
                    clearance: c,
                    at: p,
                };
            }
        }
        Some(best)
    }

    /// Whether [`Self::narrowest_of`] finds an edge's `samples` above `floor`,
    /// without finding its narrowest: only the samples whose bound allows `floor` are
    /// measured, each only as far as `floor`. Moves are judged by this, and most fail,
    /// so the narrowest is measured only for the moves taken. (It can differ from
    /// `narrowest_of` only where a sample is within a micrometre of the narrowest,
    /// which that counts as equal.)
    fn keeps_above(&self, samples: &Samples, floor: f64) -> bool {
        let r_u = self.ctx.params().unit_radius as f64;
        let field = self.ctx.field();
        let r_v = field.grid().resolution();
        // A unit keeps at most `floor` where its centre is within `reach` of the map.
        let reach = floor + r_u;
        for &(lb, p) in &samples.bounds {
            // The bound is a lower bound: from here on every sample keeps more.
            if lb > reach || lb > samples.within {
                break;
            }
            // As `measure` takes the bound near the cap.
            if lb - r_u >= CAP - r_v || exact_clearance(field, p, reach, reach + 1e-9) <= reach {
                return false;
            }
        }
        true
    }

    /// The unit positions of edge `e` of `steps` that `keep` keeps, at the samples
    /// [`Self::measure`] looks at ([`Samples`]).
    fn samples(&self, e: usize, steps: &[Step], keep: impl Fn(&Point3<f64>) -> bool) -> Samples {
        let params = self.ctx.params();
        let (l, r_u) = (params.link_length as f64, params.unit_radius as f64);
        let (a, b) = (zeta(&steps[e]), zeta(&steps[e + 1]));
        let kind = classify_edge(&a, &b);
        let field = self.ctx.field();
        let r_v = field.grid().resolution();
        let cap = CAP + r_u;
        let n = edge_intervals(kind, l, &a, &b, SAMPLE_SPACING * r_v).max(1);
        let mut bounds: Vec<(f64, Point3<f64>)> = Vec::new();
        for j in 0..=n {
            let z = edge_sample(kind, &a, &b, j as f64 / n as f64);
            for p in positions_f64(l, [z[0], z[1], z[2]], &z[3..]) {
                let lb = field.clearance_above(p, cap);
                if lb < cap && keep(&p) {
                    bounds.push((lb, p));
                }
            }
        }
        bounds.sort_by(|x, y| x.0.total_cmp(&y.0));
        let within = bounds.first().map_or(0.0, |f| f.0 + r_v * 3f64.sqrt());
        Samples {
            bounds,
            within,
            start: Point3::from(steps[e].xi),
        }
    }
}

/// What widening aims for in a passage whose middle keeps `middle` (m): [`CENTRED`]
/// of it, below the cap.
fn aim(middle: f64) -> f64 {
    (CENTRED * middle).min(CAP - GAIN)
}

/// The directions of `vs` across `along` ([`across`]), as unit vectors, those with
/// any part across.
fn across_all(vs: &[Vector3<f64>], along: Option<Vector3<f64>>) -> Vec<Vector3<f64>> {
    vs.iter()
        .filter_map(|&v| across(v, along).try_normalize(1e-6))
        .collect()
}

/// The part of `v` across the unit direction `along` (all of it without one).
fn across(v: Vector3<f64>, along: Option<Vector3<f64>>) -> Vector3<f64> {
    match along {
        Some(u) => v - u * u.dot(&v),
        None => v,
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

/// Distance from `p` to the nearest obstacle cube, capped at `CAP + r_u`: as far as
/// a passage's middle matters to widening (and to `super::thread`).
pub(super) fn distance(ctx: &CollisionContext, p: Point3<f64>) -> f64 {
    distance_below(ctx, p, CAP + ctx.params().unit_radius as f64)
}

/// Distance from `p` to the nearest obstacle cube, capped at `cap`: the distance
/// field's bound first, and the search for the nearest cube stops at `cap`.
pub(super) fn distance_below(ctx: &CollisionContext, p: Point3<f64>, cap: f64) -> f64 {
    let f = ctx.field();
    if f.clearance_above(p, cap) >= cap {
        return cap;
    }
    exact_clearance(f, p, 0.0, cap).min(cap)
}

/// The gradient of [`distance`] at `p` (central differences, an eighth of a voxel).
pub(super) fn gradient(ctx: &CollisionContext, p: Point3<f64>) -> Vector3<f64> {
    let h = ctx.field().grid().resolution() / 8.0;
    Vector3::from_fn(|i, _| {
        let mut e = Vector3::zeros();
        e[i] = h;
        (distance(ctx, p + e) - distance(ctx, p - e)) / (2.0 * h)
    })
}

/// A step's configuration `zeta` in `f64`.
pub(super) fn zeta(s: &Step) -> Vec<f64> {
    s.xi.iter()
        .copied()
        .chain(s.shape.as_slice().iter().map(|&v| v as f64))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::grid::{Cell, Grid};
    use crate::map::DistanceField;
    use crate::planner::Source;
    use aerial_chain_core::{ChainParams, Shape};
    use std::sync::Arc;

    /// A 0.1 m wall at x = 2 with a 0.5 m square window centred at y = z = 1.
    fn window() -> CollisionContext {
        let mut g = Grid::new(0.05, [-20, 0, 0], [100, 40, 40], Cell::Free, false).unwrap();
        g.fill_box([2.01, 0.0, 0.0], [2.09, 2.0, 2.0], Cell::Occupied);
        g.fill_box([2.01, 0.76, 0.76], [2.09, 1.24, 1.24], Cell::Free);
        let field = Arc::new(DistanceField::new(g));
        CollisionContext::new(field, ChainParams::new(3), 0.05).unwrap()
    }

    fn step(xi: [f64; 3], shape: &Shape) -> Step {
        Step {
            xi: xi.into(),
            shape: *shape,
            source: Source::Follow,
            shape_change: false,
        }
    }

    /// Widens `steps` in the window and checks what every widened plan must be: the
    /// start and the goal where they were, the shapes kept, every edge admissible, and
    /// the unit sphere (0.15 m) in the 0.5 m window from below 0.065 m to above 0.09 m
    /// (0.1 m is the most it can keep). Returns the plan.
    fn widened_in_the_window(steps: &[Step]) -> Vec<Step> {
        let ctx = window();
        assert!(steps.windows(2).all(|w| edge_passes(&ctx, &w[0], &w[1])));
        let (out, report) = widen(&ctx, &ctx, steps.to_vec());
        let (first, last) = (&steps[0], &steps[steps.len() - 1]);
        assert_eq!((out[0].xi, out[out.len() - 1].xi), (first.xi, last.xi));
        assert!(out.iter().all(|s| s.shape == first.shape));
        assert!(report.before < 0.065 && report.after > 0.09, "{report:?}");
        assert!(out.windows(2).all(|w| edge_passes(&ctx, &w[0], &w[1])));
        out
    }

    /// A straight chain through the window 4 cm off its centre line in y and 3 cm in z.
    fn off_centre() -> Vec<Step> {
        let straight = Shape::from_slice(3, &[0.0; 5]).unwrap();
        let (y, z) = (1.04, 0.97);
        [[0.4, 1.0, 1.0], [1.2, y, z], [3.6, y, z], [3.8, 1.0, 1.0]]
            .map(|xi| step(xi, &straight))
            .to_vec()
    }

    #[test]
    fn an_off_centre_passage_moves_to_the_middle_and_stays_admissible() {
        let out = widened_in_the_window(&off_centre());
        assert!(out.len() >= 4);
    }

    #[test]
    fn a_passage_between_start_and_goal_is_split_and_centred() {
        let straight = Shape::from_slice(3, &[0.0; 5]).unwrap();
        // One translation from the start to the goal, both of which stay.
        let out = widened_in_the_window(&[
            step([1.2, 1.04, 1.0], &straight),
            step([3.6, 1.04, 1.0], &straight),
        ]);
        assert_eq!(out.len(), 4, "{out:?}");
        assert!(out.iter().all(|s| !s.shape_change));
    }

    /// Refinement reuses the first widening's result where the second would get the
    /// same plan in the same context: that holds only while widening is deterministic.
    #[test]
    fn the_same_plan_widens_the_same_way() {
        let ctx = window();
        let (a, ra) = widen(&ctx, &ctx, off_centre());
        let (b, rb) = widen(&ctx, &ctx, off_centre());
        assert!(ra.moves > 0);
        assert_eq!((a, ra), (b, rb));
    }

    /// A wall at x = 2 with an opening 0.5 m tall and 0.7 m wide centred at
    /// y = z = 1, and 1 m further a second wall with a door 0.7 m wide centred at
    /// y = 0.95 (z up to 1.8). A unit keeps 0.1 m in the opening's middle, and
    /// 0.1 m anywhere within 0.1 m of it across; 0.2 m in the door's middle.
    fn opening_and_door() -> CollisionContext {
        let mut g = Grid::new(0.05, [-20, 0, 0], [120, 40, 40], Cell::Free, false).unwrap();
        g.fill_box([2.01, 0.0, 0.0], [2.09, 2.0, 2.0], Cell::Occupied);
        g.fill_box([2.01, 0.66, 0.76], [2.09, 1.34, 1.24], Cell::Free);
        g.fill_box([3.01, 0.0, 0.0], [3.09, 2.0, 2.0], Cell::Occupied);
        g.fill_box([3.01, 0.61, 0.0], [3.09, 1.29, 1.79], Cell::Free);
        let field = Arc::new(DistanceField::new(g));
        CollisionContext::new(field, ChainParams::new(3), 0.05).unwrap()
    }

    /// The smallest unit clearance of `steps` where units are within 0.3 m of the
    /// wall at `x` (m), sampled every centimetre of the head's path.
    fn clearance_at_wall(ctx: &CollisionContext, steps: &[Step], x: f64) -> f64 {
        let r_u = ctx.params().unit_radius as f64;
        let mut least = f64::INFINITY;
        for w in steps.windows(2) {
            let n = ((w[1].xi - w[0].xi).norm() / 0.01).ceil().max(1.0) as usize;
            let eta: Vec<f64> = w[1].shape.as_slice().iter().map(|&v| v as f64).collect();
            for j in 0..=n {
                let head = w[0].xi + (w[1].xi - w[0].xi) * (j as f64 / n as f64);
                for p in positions_f64(0.5, head, &eta) {
                    if (p.x - x).abs() < 0.3 {
                        least = least.min(distance(ctx, p) - r_u);
                    }
                }
            }
        }
        least
    }

    /// One translation through the middle of the opening and 5 cm off the door's:
    /// the edge's narrowest is in the opening, as wide as it gets there, so only the
    /// second pass sees the door, and widens it without narrowing the opening.
    #[test]
    fn a_second_passage_on_the_same_translation_is_widened_too() {
        let ctx = opening_and_door();
        let straight = Shape::from_slice(3, &[0.0; 5]).unwrap();
        let steps: Vec<Step> = [
            [0.4, 1.0, 1.0],
            [1.2, 1.0, 1.0],
            [4.6, 1.0, 1.0],
            [4.7, 1.0, 1.0],
        ]
        .map(|xi| step(xi, &straight))
        .to_vec();
        assert!(steps.windows(2).all(|w| edge_passes(&ctx, &w[0], &w[1])));
        let door_before = clearance_at_wall(&ctx, &steps, 3.05);
        assert!(door_before < 0.16, "{door_before}");
        let (out, report) = widen(&ctx, &ctx, steps);
        assert!(out.windows(2).all(|w| edge_passes(&ctx, &w[0], &w[1])));
        let opening = clearance_at_wall(&ctx, &out, 2.05);
        let door = clearance_at_wall(&ctx, &out, 3.05);
        assert!(opening > 0.099, "opening {opening}");
        assert!(
            door >= TARGET_SHARE * 0.2,
            "door {door}, before {door_before}"
        );
        assert!(report.moves > 0);
    }

    /// Moves are judged by `keeps_above`, which must agree with `measure` at every
    /// floor: here translations through the window and past its frame, at floors
    /// just below, at and just above each one's narrowest, and further off.
    #[test]
    fn keeps_above_agrees_with_measure() {
        let ctx = window();
        let straight = Shape::from_slice(3, &[0.0; 5]).unwrap();
        let turned = Shape::from_slice(3, &[0.4, 0.0, 0.3, 0.1, -0.2]).unwrap();
        let w = Widener {
            ctx: &ctx,
            ctx_min: &ctx,
            steps: Vec::new(),
            narrow: Vec::new(),
            stuck: Vec::new(),
            spent: 0,
            splits: 0,
        };
        let mut checked = 0;
        for (k, (y, z)) in [(1.0, 1.0), (1.04, 0.97), (1.09, 1.08), (0.8, 1.3)]
            .into_iter()
            .enumerate()
        {
            let shape = if k % 2 == 0 { straight } else { turned };
            let steps = [step([1.2, y, z], &shape), step([3.6, y, z], &shape)];
            let narrowest = w.measure_whole(0, &steps).clearance;
            for floor in [-1.0, -1e-3, -1e-5, 0.0, 1e-5, 1e-3, 0.02, 1.0].map(|d| narrowest + d) {
                let measured = w.measure(0, &steps, floor, |_| true).is_some();
                assert_eq!(
                    w.keeps_above(&w.samples(0, &steps, |_| true), floor),
                    measured,
                    "{k} {floor}"
                );
                checked += 1;
            }
        }
        assert_eq!(checked, 32);
    }

    /// An edge no move widens gives up the edges at its pinch that keep about as
    /// little, and only those.
    #[test]
    fn an_edge_stuck_at_a_pinch_gives_up_its_neighbours_there() {
        let ctx = window();
        let at = |x: f64, clearance: f64| Narrowest {
            clearance,
            at: Point3::new(x, 1.0, 1.0),
        };
        let mut w = Widener {
            ctx: &ctx,
            ctx_min: &ctx,
            steps: Vec::new(),
            narrow: vec![
                at(2.0, 0.1),
                at(2.05, 0.102),
                at(2.0, 0.1 + PLATEAU + 1e-4),
                at(2.0 + SAME_PINCH + 0.01, 0.1),
                at(1.9, 0.09),
            ],
            stuck: vec![false; 5],
            spent: 0,
            splits: 0,
        };
        w.stuck_at_pinch(0);
        assert_eq!(w.stuck, [true, true, false, false, true]);
    }

    #[test]
    fn wide_plans_are_left_alone() {
        let ctx = window();
        let straight = Shape::from_slice(3, &[0.0; 5]).unwrap();
        let steps = vec![
            step([0.4, 1.0, 1.0], &straight),
            step([1.0, 1.0, 1.0], &straight),
            step([1.4, 1.0, 1.0], &straight),
        ];
        let (out, report) = widen(&ctx, &ctx, steps.clone());
        assert_eq!(out, steps);
        assert_eq!(report.moves, 0);
        assert_eq!(report.before, CAP);
    }
}
