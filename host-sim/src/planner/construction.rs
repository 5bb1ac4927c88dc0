//! One query's online construction (paper Alg. 4): the chain follows a head route
//! over the roadmap edge by edge; for each edge the shape connection
//! ([`super::connect`]) finds the legs that fly it, and where none does, the edge is
//! dropped and the head roadmap asked for another route (backing up along the way
//! flown where the chain is stuck).
//!
//! For each edge `v -> u` of the head path: (a) keep the current shape if the edge is
//! admissible with it; (b) else try its `n_psi` yaw rotations; (c) else the library's
//! shapes at `n_psi` headings, cheapest to reach first; (d) else SRSConnect
//! ([`super::srs_connect`]); (e) else drop the edge and ask the head roadmap for another
//! path from `v`. Every accepted step includes the shape change itself, checked at
//! `v`: a plan is "change shape, then translate".

use std::collections::BTreeSet;
use std::time::Instant;

use aerial_chain_core::Shape;
use nalgebra::Point3;

use super::arc::{ArcPlanner, Stats};
use super::candidates::{Candidate, Source};
use super::numeric::PER_MILLIMETRE;
use super::roadmap::{Roadmap, RouteError, VertexId};
use super::widen::distance_below;
use super::{Checker, PlanError, Query, Step, Termination};
use crate::collision::{CollisionContext, FK_TOLERANCE};

/// One leg of a head edge: shape changes where the head is, then a translation.
pub(super) struct Leg {
    /// Shape changes where the head is.
    pub(super) changes: Vec<Candidate>,
    /// Where the translation ends.
    pub(super) to: [f64; 3],
}

/// One query's online construction (Alg. 4).
pub(super) struct Construction<'p> {
    pub(super) planner: &'p ArcPlanner,
    pub(super) roadmap: &'p mut Roadmap,
    pub(super) checker: Checker,
    start: VertexId,
    goals: Vec<VertexId>,
    /// Cost-to-go of every vertex: the routes' heuristic.
    to_go: Vec<f64>,
    banned: BTreeSet<(VertexId, VertexId)>,
    /// The chain's shape where the head is.
    pub(super) current: Candidate,
    /// The plan so far.
    pub(super) steps: Vec<Step>,
    pub(super) stats: Stats,
    stop: Termination,
    began: Instant,
    /// Goal tolerance for the head (m).
    goal_tol: f64,
    /// Edges flown below the preferred clearance: steps before, margin, where.
    pub(super) relaxed: Vec<(usize, f64, [f64; 3])>,
    /// Replans allowed without progress (`Settings::max_replans` unless set).
    max_replans: usize,
    /// What SRSConnect learnt at the last head position it was asked from.
    pub(super) srs_memo: super::srs_connect::Memo,
    /// Whether an edge of the head route may be flown below the preferred clearance
    /// where it fails at it ([`Self::connect`]).
    pub(super) may_give_way: bool,
    /// Whether an edge no kept, turned, library or follower shape flies may ask
    /// SRSConnect (d).
    pub(super) random_shapes: bool,
    /// The margin the start's units keep, rounded down to a millimetre, where it is
    /// below the preferred clearance: an edge leaving the start may keep only that.
    start_margin: Option<f64>,
}

impl<'p> Construction<'p> {
    /// The construction of `query` over `roadmap`, which takes the query's vertices
    /// and the inner points of the head `route` (when there is one).
    pub(super) fn new(
        planner: &'p ArcPlanner,
        roadmap: &'p mut Roadmap,
        query: &Query,
        route: Option<&[[f64; 3]]>,
        stop: Termination,
        began: Instant,
    ) -> Self {
        let ((start, goal), shape) = (query.ends(), query.start_shape);
        let s = roadmap.add_query_vertex(start);
        let g = roadmap.add_query_vertex(goal);
        if let Some(inner) = route {
            roadmap.add_route(&planner.ctx, s, inner, g);
        }
        let tol = query.goal_tol;
        let mut goals = vec![g];
        goals.extend((0..roadmap.vertex_count()).filter(|&v| {
            let p = roadmap.point(v);
            (p[0] - goal[0]).powi(2) + (p[1] - goal[1]).powi(2) + (p[2] - goal[2]).powi(2)
                <= tol * tol
        }));
        let current = Candidate {
            shape,
            source: Source::Start,
        };
        let to_go = roadmap.cost_to_go(&goals);
        Self {
            planner,
            roadmap,
            checker: Checker::new(planner.ctx.clone(), stop.deadline(began)),
            start: s,
            goals,
            to_go,
            banned: BTreeSet::new(),
            current,
            steps: vec![query.start_step()],
            stats: Stats::default(),
            stop,
            began,
            goal_tol: tol,
            relaxed: Vec::new(),
            max_replans: planner.settings.max_replans,
            may_give_way: true,
            random_shapes: true,
            srs_memo: Default::default(),
            start_margin: start_margin(&planner.ctx, start, &shape),
        }
    }

    /// The same construction giving up at the first edge no shape flies: over a lone
    /// head route there is no other way to replan onto, and backing up along it only
    /// retries the same shapes.
    pub(super) fn without_replans(mut self) -> Self {
        self.max_replans = 0;
        self
    }

    /// This construction, failing at the first edge that does not pass at the
    /// preferred clearance instead of giving way on it.
    pub(super) fn without_giving_way(mut self) -> Self {
        self.may_give_way = false;
        self
    }

    /// This construction without SRSConnect: an edge that no kept, turned, library
    /// or follower shape flies fails.
    pub(super) fn without_random_shapes(mut self) -> Self {
        self.random_shapes = false;
        self
    }

    /// Where `v` is the start and the start keeps less than the preferred clearance,
    /// the margin it keeps (what an edge leaving it may give way to).
    pub(super) fn start_margin_at(&self, v: VertexId) -> Option<f64> {
        self.start_margin.filter(|_| v == self.start)
    }

    fn route(&self, from: VertexId) -> Result<Vec<VertexId>, PlanError> {
        let banned = |a: VertexId, b: VertexId| self.banned.contains(&(a.min(b), a.max(b)));
        self.roadmap
            .route(&self.planner.ctx, from, &self.goals, &self.to_go, &banned)
            .map_err(|e| match e {
                RouteError::StartIsolated | RouteError::Unreachable => {
                    PlanError::Unreachable { tol: self.goal_tol }
                }
            })
    }

    /// Flies the head route edge by edge (Alg. 4), replanning where no shape fits.
    pub(super) fn run(mut self) -> Result<(Vec<Step>, Stats), PlanError> {
        let mut path = self.route(self.start)?;
        let mut i = 0;
        // Where the chain has been: vertex, its shape there, steps up to arriving.
        let mut trail = vec![(self.start, self.current, self.steps.len())];
        // Edges that failed from each vertex, in this query.
        let mut fails = vec![0usize; self.roadmap.total_vertices()];
        // Replans since the trail was last longer than ever: the budget is per stretch
        // of the way, so long routes get as many as short ones.
        let (mut furthest, mut stuck_replans) = (1usize, 0usize);
        while i + 1 < path.len() {
            if self
                .stop
                .time_limit
                .is_some_and(|t| self.began.elapsed() > t)
            {
                return Err(PlanError::TimeLimit {
                    replans: self.stats.replans,
                });
            }
            let (v, u) = (path[i], path[i + 1]);
            if let Some(legs) = self.connect(v, u) {
                self.accept(legs);
                trail.push((u, self.current, self.steps.len()));
                if trail.len() > furthest {
                    (furthest, stuck_replans) = (trail.len(), 0);
                }
                i += 1;
                continue;
            }
            // (e) drop the edge and ask for another head path from here. Where no
            // path leaves this vertex, or edges keep failing from it (the chain's
            // shape here is the trouble, not the edge), back up along the trail:
            // flying an edge backwards with the same shape is as admissible as forwards.
            let (from, to) = (self.roadmap.point(v), self.roadmap.point(u));
            fails[v] += 1;
            let mut bad = (v, u);
            path = loop {
                self.banned.insert((bad.0.min(bad.1), bad.0.max(bad.1)));
                self.stats.replans += 1;
                stuck_replans += 1;
                if stuck_replans > self.max_replans {
                    return Err(PlanError::NoShape {
                        from: from.into(),
                        to: to.into(),
                        replans: self.stats.replans,
                        narrowest: None,
                    });
                }
                let here = trail.last().map(|t| t.0).unwrap_or(self.start);
                let stuck = fails[here] >= self.planner.settings.backtrack_after && trail.len() > 1;
                let route = if stuck {
                    Err(PlanError::Unreachable { tol: 0.0 })
                } else {
                    self.route(here)
                };
                match route {
                    Ok(p) => break p,
                    Err(_) if trail.len() > 1 => {
                        let (dead, _, _) = trail.pop().expect("trail has two entries");
                        let (back, shape, len) = *trail.last().expect("trail has an entry");
                        self.steps.truncate(len);
                        self.current = shape;
                        fails[back] += 1;
                        bad = (back, dead);
                    }
                    Err(_) => {
                        return Err(PlanError::NoShape {
                            from: from.into(),
                            to: to.into(),
                            replans: self.stats.replans,
                            narrowest: None,
                        })
                    }
                }
            };
            i = 0;
        }
        count_sources(&self.steps, &mut self.stats);
        self.stats.min_margin = self.planner.ctx.clearance_margin();
        for &(len, m, at) in &self.relaxed {
            if len < self.steps.len() && m < self.stats.min_margin {
                self.stats.min_margin = m;
                self.stats.min_margin_at = Some(at.into());
            }
        }
        self.stats.timings.collision_s = self.checker.time.as_secs_f64();
        Ok((self.steps, self.stats))
    }

    /// Appends each leg: its shape changes where the head is, then its translation.
    fn accept(&mut self, legs: Vec<Leg>) {
        for leg in legs {
            let xi = self
                .steps
                .last()
                .map(|s| s.xi)
                .expect("the start is a step");
            for c in leg.changes {
                self.steps.push(Step {
                    xi,
                    shape: c.shape,
                    source: c.source,
                    shape_change: true,
                });
                self.current = c;
            }
            let cur = self.current;
            self.steps.push(Step {
                xi: leg.to.into(),
                shape: cur.shape,
                source: cur.source,
                shape_change: false,
            });
        }
    }
}

/// Counts a plan's head edges and shape changes by where each shape came from
/// (replacing earlier counts: backing up and refinement change the steps).
pub(super) fn count_sources(steps: &[Step], stats: &mut Stats) {
    (stats.edges, stats.shape_changes) = (0, 0);
    (
        stats.rotations,
        stats.lsc_uses,
        stats.srs_uses,
        stats.follow_uses,
    ) = (0, 0, 0, 0);
    for s in &steps[1..] {
        if !s.shape_change {
            stats.edges += 1;
            continue;
        }
        stats.shape_changes += 1;
        match s.source {
            Source::Rotation => stats.rotations += 1,
            Source::Lsc(_) => stats.lsc_uses += 1,
            Source::Srs(_) | Source::SrsTurned(_) => stats.srs_uses += 1,
            Source::Follow => stats.follow_uses += 1,
            Source::Shrunk => stats.shrunk += 1,
            Source::Start | Source::Sampled | Source::Goal => {}
        }
    }
}

/// The margin the units of the chain at `head` with `shape` keep on `ctx`'s map
/// (exactly, less the checks' [`FK_TOLERANCE`], rounded down to a millimetre), where
/// it is below `ctx`'s clearance; `None` where the start keeps the clearance.
fn start_margin(ctx: &CollisionContext, head: [f64; 3], shape: &Shape) -> Option<f64> {
    let (r_u, c) = (ctx.params().unit_radius as f64, ctx.clearance_margin());
    let offsets = aerial_chain_core::kinematics::offsets(ctx.params(), shape);
    let margin = offsets
        .iter()
        .take(ctx.params().n())
        .map(|o| {
            let p = Point3::from([0, 1, 2].map(|k| head[k] + o[k] as f64));
            distance_below(ctx, p, r_u + c) - r_u
        })
        .fold(f64::INFINITY, f64::min);
    let kept = (margin - FK_TOLERANCE).max(0.0);
    let floored = (kept * PER_MILLIMETRE).floor() / PER_MILLIMETRE;
    (floored < c).then_some(floored)
}
