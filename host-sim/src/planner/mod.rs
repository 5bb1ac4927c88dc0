//! The ARCplanner (paper Sec. 3): a head roadmap, then per head edge the cheapest
//! shape that gets the whole chain along it.
//!
//! Lifecycle, as OMPL's planners: [`Planner::new`] (map, chain, tables, settings),
//! [`Planner::setup`] (build the head roadmap `G_T`, once), [`Planner::solve`]
//! (one query, with a termination condition; many queries may share a roadmap),
//! [`Planner::clear`] (forget the roadmap).
//!
//! Online construction (paper Alg. 4), for each edge `v -> u` of the head path:
//! (a) keep the current shape if the edge is admissible with it; (b) else try its
//! `n_psi` yaw rotations; (c) else the library's shapes at `n_psi` headings, cheapest
//! to reach first; (d) else SRSConnect ([`srs_connect`]); (e) else drop the edge and
//! ask the head roadmap for another path from `v`. Every accepted step includes the
//! shape change itself, checked at `v`: a plan is "change shape, then translate".

pub mod candidates;
pub mod follow;
pub mod graph;
pub mod lattice;
pub mod motion;
pub mod refine;
pub mod roadmap;
pub mod srs_connect;

use std::collections::BTreeSet;
use std::time::{Duration, Instant};

use aerial_chain_core::lsc::LscKind;
use aerial_chain_core::Shape;
use rand::SeedableRng;
use rand_pcg::Pcg64;

use crate::collision::CollisionContext;
use crate::tables::ShapeTables;
use candidates::{Candidate, Source};
use roadmap::{Roadmap, RouteError, VertexId};

/// Which shape sources the planner may use (the paper's ablation).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Mode {
    /// Library and random shapes (the full ARCplanner).
    Both,
    /// Library shapes only.
    Lsc,
    /// Random shapes only (plus yaw rotations of the current shape).
    Srs,
}

/// What the planner prefers when several shapes fit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Preference {
    /// Keep the shape as long as it fits; cheapest change otherwise.
    Least,
    /// Fly the sensor-coverage polygon PN wherever it fits (the silo demo).
    Coverage,
}

/// Planner parameters; every one has a command-line flag.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// Head roadmap vertices `M_VT`.
    pub vertices: usize,
    /// Head roadmap connection radius `r_T` (m).
    pub r_t: f64,
    /// Most neighbours a vertex takes (the nearest within `r_T`).
    pub max_neighbours: usize,
    /// Discrete headings per library shape and rotations of the current shape.
    pub n_psi: usize,
    /// `G_Val` connection radius `d_c` (`C_T` metric); `None`: the roadmap radius
    /// `aerial_chain_core::srs::default_r_s` for the chain and the SRS size.
    pub d_c: Option<f32>,
    /// Shape sources.
    pub mode: Mode,
    /// Shape preference.
    pub prefer: Preference,
    /// Seed of the roadmap sampler.
    pub seed: u64,
    /// Replans (dropped head edges) allowed without progress (the chain reaching a
    /// vertex farther along its way than before) before the roadmap grows.
    pub max_replans: usize,
    /// Times a failing query may double the roadmap and try again.
    pub max_growth: usize,
    /// How strongly head paths avoid passing close to obstacles (0: shortest paths,
    /// as in the paper); see [`roadmap::Roadmap::build`].
    pub clearance_weight: f64,
    /// Goal tolerance for the head (m).
    pub goal_tol: f64,
    /// Step (m) of follow-the-leader motion ([`follow`]), tried after the library
    /// and before SRSConnect; 0 turns it off (the paper's planner).
    pub follow_step: f64,
    /// Smallest clearance margin (m) the planner may give way to where a passage is
    /// narrower than the context's (preferred) clearance; 0 is docs/model.md's exact
    /// contract. Values above the preferred clearance are taken as it.
    pub clearance_min: f64,
    /// Search a head route over the half-cell lattice of the map ([`lattice`]) and add
    /// it to the roadmap before each query; off: the paper's uniform roadmap only.
    pub head_lattice: bool,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            vertices: 1500,
            r_t: 1.5,
            max_neighbours: 30,
            n_psi: 8,
            d_c: None,
            mode: Mode::Both,
            prefer: Preference::Least,
            seed: 1,
            max_replans: 200,
            max_growth: 3,
            clearance_weight: 2.0,
            goal_tol: 0.3,
            follow_step: 0.1,
            clearance_min: 0.0,
            head_lattice: true,
        }
    }
}

/// When to stop a query early.
#[derive(Clone, Copy, Debug, Default)]
pub struct Termination {
    /// Give up after this long: roadmap building, growth and the query together
    /// (docs/promises.md).
    pub time_limit: Option<Duration>,
}

impl Termination {
    /// The moment to stop for work that began at `began`.
    pub fn deadline(&self, began: Instant) -> Option<Instant> {
        self.time_limit.and_then(|t| began.checked_add(t))
    }
}

/// Whether `deadline` has passed.
fn expired(deadline: Option<Instant>) -> bool {
    deadline.is_some_and(|d| Instant::now() > d)
}

/// One waypoint of a solution.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Step {
    /// Head position (m).
    pub xi: [f64; 3],
    /// Shape.
    pub shape: Shape,
    /// Where the shape came from (for translations: the shape kept).
    pub source: Source,
    /// Whether this waypoint ends a shape change (else a translation or the start).
    pub shape_change: bool,
}

/// Counters and timings of one query.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Stats {
    /// Roadmap build time (s).
    pub roadmap_s: f64,
    /// Query time (s).
    pub planning_s: f64,
    /// Of the query time, spent in collision checks (s).
    pub collision_s: f64,
    /// Head edges flown.
    pub edges: usize,
    /// Shape-change waypoints.
    pub shape_changes: usize,
    /// Yaw rotations of the current shape used.
    pub rotations: usize,
    /// Library shapes used.
    pub lsc_uses: usize,
    /// Random shapes used.
    pub srs_uses: usize,
    /// Follow-the-leader shapes used (one per short step).
    pub follow_uses: usize,
    /// Shape changes that refinement made smaller ([`refine`]).
    pub shrunk: usize,
    /// SRSConnect calls.
    pub srs_connects: usize,
    /// Head edges dropped and routes asked again (in the final roadmap).
    pub replans: usize,
    /// Times the roadmap was doubled during the query.
    pub roadmap_growths: usize,
    /// Smallest clearance margin (m) in force on any edge of the plan: every body kept
    /// at least this far from the map (the preferred clearance unless the planner gave
    /// way in a narrow passage).
    pub min_margin: f64,
    /// Head position at the start of the first edge flown at [`Self::min_margin`],
    /// when that is below the preferred clearance.
    pub min_margin_at: Option<[f64; 3]>,
    /// Head route search ([`lattice`]): lattice points expanded (0: not used).
    pub lattice_expanded: usize,
    /// Head route search time (s), part of the query time.
    pub lattice_s: f64,
    /// Points of the head route added to the roadmap (start and goal included).
    pub route_points: usize,
    /// Full-chain collision checks (configurations, translations, shape changes).
    pub collision_checks: u64,
    /// Roadmap vertices and candidate edges.
    pub roadmap_vertices: usize,
    /// Candidate edges of the roadmap.
    pub roadmap_edges: usize,
}

/// A solved query.
#[derive(Clone, Debug)]
pub struct Solution {
    /// Waypoints, the start first.
    pub steps: Vec<Step>,
    /// What it took.
    pub stats: Stats,
}

/// A point for messages: `(x, y, z)` to the millimetre.
fn point(p: &[f64; 3]) -> String {
    format!("({:.3}, {:.3}, {:.3})", p[0], p[1], p[2])
}

/// Why a query has no solution, or cannot be asked.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PlanError {
    /// The tables are for another chain than the map context.
    #[error("the shape tables are for N = {tables} units, the chain has N = {chain}")]
    TablesMismatch {
        /// Units in the tables.
        tables: u8,
        /// Units of the chain.
        chain: u8,
    },
    /// The start configuration is not valid.
    #[error("start is invalid: {0}")]
    StartInvalid(String),
    /// The goal cannot hold the head.
    #[error("goal is invalid: {0}")]
    GoalInvalid(String),
    /// The head cannot reach the goal in the roadmap at all.
    #[error("goal is not reachable by the head (no roadmap path from the start to within {tol} m of the goal)")]
    Unreachable {
        /// Goal tolerance (m).
        tol: f64,
    },
    /// The head could be routed, but the chain found no shape for some edge.
    #[error(
        "no shape fits head edge {} -> {} after {replans} replans{}",
        point(from),
        point(to),
        narrow_note(.narrowest)
    )]
    NoShape {
        /// The last edge tried.
        from: [f64; 3],
        /// Its end.
        to: [f64; 3],
        /// Replans made.
        replans: usize,
        /// The head route's narrowest point and the head's margin there (m), when the
        /// lattice found a route.
        narrowest: Option<([f64; 3], f64)>,
    },
    /// The head's sphere cannot get from the start to the goal at all: the lattice
    /// search flooded one side's free region without meeting the other.
    #[error("start and goal are in separate free regions for the head's sphere (radius {radius:.3} m, the smallest clearance included): the {side}'s region ({visited} lattice points at {spacing:.3} m) does not reach the other")]
    Separated {
        /// Sphere radius tested (m).
        radius: f64,
        /// Which side's region was flooded ("start" or "goal").
        side: &'static str,
        /// Lattice points in it.
        visited: usize,
        /// Lattice spacing (m).
        spacing: f64,
    },
    /// The termination condition stopped the query.
    #[error("time limit reached after {replans} replans")]
    TimeLimit {
        /// Replans made.
        replans: usize,
    },
}

/// The tail of [`PlanError::NoShape`]'s message: where the head route is narrowest.
fn narrow_note(n: &Option<([f64; 3], f64)>) -> String {
    match n {
        Some((p, m)) => format!(
            "; the head route is narrowest at ({:.3}, {:.3}, {:.3}), where the head keeps {:.3} m from the map",
            p[0], p[1], p[2], m
        ),
        None => String::new(),
    }
}

/// Collision checks with time and count bookkeeping.
pub struct Checker {
    ctx: CollisionContext,
    time: Duration,
    /// Past it every check fails at once, so that whatever search is under way ends
    /// and the query reports the time limit.
    deadline: Option<Instant>,
}

impl Checker {
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
    pub fn placement(&mut self, xi: [f64; 3], s: &Shape) -> bool {
        self.timed(|c| c.check_placement(xi, s).is_ok())
    }

    /// The configuration is valid (joint limits, self-collision, map).
    pub fn config(&mut self, xi: [f64; 3], s: &Shape) -> bool {
        self.timed(|c| c.check_config(xi, s).is_ok())
    }

    /// The chain in shape `s` can translate from `a` to `b`.
    pub fn translation(&mut self, a: [f64; 3], b: [f64; 3], s: &Shape) -> bool {
        self.timed(|c| c.check_translation(a, b, s).is_ok())
    }

    /// The chain can change shape from `s` to `t` with the head at `xi`.
    pub fn shape_change(&mut self, xi: [f64; 3], s: &Shape, t: &Shape) -> bool {
        self.timed(|c| c.check_shape_change(xi, s, t).is_ok())
    }
}

/// The planner: a map context, a chain's shape tables, settings, and the roadmap.
pub struct Planner {
    ctx: CollisionContext,
    /// The same map and chain at the smallest clearance (`Settings::clearance_min`).
    ctx_min: CollisionContext,
    lattice: lattice::HeadLattice,
    tables: ShapeTables,
    /// Per SRS shape: the yaw from the head to the centroid of its units.
    trail_yaw: Vec<f32>,
    settings: Settings,
    roadmap: Option<Roadmap>,
    roadmap_s: f64,
}

impl Planner {
    /// A planner for the chain of `ctx`; `tables` must be for the same chain.
    pub fn new(
        ctx: CollisionContext,
        tables: ShapeTables,
        settings: Settings,
    ) -> Result<Self, PlanError> {
        if tables.params != *ctx.params() {
            return Err(PlanError::TablesMismatch {
                tables: tables.params.units,
                chain: ctx.params().units,
            });
        }
        let trail_yaw = tables
            .srs
            .iter()
            .map(|s| trail_yaw(&tables.params, s))
            .collect();
        let c_min = settings.clearance_min.clamp(0.0, ctx.clearance_margin());
        let mut ctx_min = CollisionContext::new(ctx.field_arc().clone(), *ctx.params(), c_min)
            .map_err(|e| PlanError::StartInvalid(format!("clearance_min: {e}")))?;
        ctx_min.set_min_step(ctx.min_step());
        let lattice = lattice::HeadLattice::new(&ctx, c_min, settings.clearance_weight);
        Ok(Self {
            ctx,
            ctx_min,
            lattice,
            tables,
            trail_yaw,
            settings,
            roadmap: None,
            roadmap_s: 0.0,
        })
    }

    /// Builds the head roadmap (once; later calls do nothing).
    pub fn setup(&mut self) {
        self.setup_until(None);
    }

    /// [`Self::setup`], cut short at `deadline` (the roadmap is then smaller).
    fn setup_until(&mut self, deadline: Option<Instant>) {
        if self.roadmap.is_none() {
            let t = Instant::now();
            self.build_roadmap(self.settings.vertices, deadline);
            self.roadmap_s = t.elapsed().as_secs_f64();
        }
    }

    /// (Re)builds the roadmap with `vertices` vertices, or fewer if `deadline` passes.
    /// The sampler restarts from the seed, so a larger roadmap holds every vertex of a
    /// smaller one. The radius shrinks as `(M_VT / vertices)^(1/3)`, so the number of
    /// neighbours stays the same.
    fn build_roadmap(&mut self, vertices: usize, deadline: Option<Instant>) {
        let mut rng = Pcg64::seed_from_u64(self.settings.seed);
        let weight = (
            self.settings.clearance_weight,
            self.ctx.params().reach() as f64 / 2.0,
        );
        let r_t =
            self.settings.r_t * (self.settings.vertices as f64 / vertices.max(1) as f64).cbrt();
        let near = (r_t, self.settings.max_neighbours);
        self.roadmap = Some(Roadmap::build(
            &self.ctx, vertices, near, weight, &mut rng, deadline,
        ));
    }

    /// Forgets the roadmap.
    pub fn clear(&mut self) {
        self.roadmap = None;
    }

    /// The collision context.
    pub fn context(&self) -> &CollisionContext {
        &self.ctx
    }

    /// The settings.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// The lattice's head route (`Ok(None)`: the lattice cannot say within `budget`);
    /// [`PlanError::Separated`] when it proves that none exists. Adds its time to `s`.
    fn head_route(
        &self,
        start: [f64; 3],
        goal: [f64; 3],
        budget: usize,
        deadline: Option<Instant>,
        s: &mut f64,
    ) -> Result<Option<lattice::HeadRoute>, PlanError> {
        let t = Instant::now();
        let outcome = self
            .lattice
            .route_within(&self.ctx_min, start, goal, budget, deadline);
        *s += t.elapsed().as_secs_f64();
        match outcome {
            lattice::LatticeOutcome::Found(r) if r.points.len() >= 2 => Ok(Some(r)),
            lattice::LatticeOutcome::Separated { side, visited } => Err(PlanError::Separated {
                radius: self.lattice.radius_min(),
                side,
                visited,
                spacing: self.lattice.spacing(),
            }),
            _ => Ok(None),
        }
    }

    /// Full-chain checks made so far by both contexts.
    fn check_count(&self) -> u64 {
        [self.ctx.stats(), self.ctx_min.stats()]
            .iter()
            .map(|c| c.configs + c.translations + c.shape_changes)
            .sum()
    }

    /// The head route search.
    pub fn lattice(&self) -> &lattice::HeadLattice {
        &self.lattice
    }

    /// Plans from `start` (head position and shape) to within the goal tolerance of
    /// `goal`. Calls [`Self::setup`] if needed.
    pub fn solve(
        &mut self,
        start: [f64; 3],
        start_shape: Shape,
        goal: [f64; 3],
        stop: Termination,
    ) -> Result<Solution, PlanError> {
        // The time limit covers the roadmap too (when it is built here) and growth.
        let began = Instant::now();
        let deadline = stop.deadline(began);
        self.setup_until(deadline);
        let query_began = Instant::now();
        let checks_before = self.check_count();
        self.ctx_min
            .check_config(start, &start_shape)
            .map_err(|c| PlanError::StartInvalid(c.to_string()))?;
        if !self.ctx_min.is_head_free(goal) {
            let why = if self.ctx.field().grid().in_bounds(goal) {
                format!(
                    "the head's sphere (radius + clearance) collides at {}",
                    point(&goal)
                )
            } else {
                format!("{} is outside the map's bounds", point(&goal))
            };
            return Err(PlanError::GoalInvalid(why));
        }
        // The head route over the lattice ([`lattice`]), searched when the uniform
        // roadmap fails (where it works, it is cheaper in rooms and mazes): the route
        // joins the roadmap, and a proof that none exists ends the query.
        let mut route = None;
        let (mut lattice_expanded, mut lattice_s) = (0, 0.0);
        let mut lattice_done = !self.settings.head_lattice;
        // Like OMPL's PRM, grow the roadmap while the query fails and time remains.
        let mut growths = 0;
        let (steps, mut stats, size) = loop {
            if expired(deadline) {
                return Err(PlanError::TimeLimit { replans: 0 });
            }
            let mut roadmap = self.roadmap.take().expect("setup built the roadmap");
            let inner = route
                .as_ref()
                .map(|r: &lattice::HeadRoute| &r.points[1..r.points.len() - 1]);
            let result = Construction::new(
                self,
                &mut roadmap,
                (start, start_shape),
                (goal, inner),
                stop,
                began,
            )
            .run();
            roadmap.clear_query();
            let size = (roadmap.vertex_count(), roadmap.edge_count());
            self.roadmap = Some(roadmap);
            match result {
                Ok((steps, stats)) => break (steps, stats, size),
                Err(PlanError::NoShape { .. } | PlanError::Unreachable { .. })
                    if !lattice_done && !expired(deadline) =>
                {
                    // The roadmap alone failed: now the full lattice search.
                    lattice_done = true;
                    let budget = self.lattice.budget;
                    if let Some(r) =
                        self.head_route(start, goal, budget, deadline, &mut lattice_s)?
                    {
                        lattice_expanded = r.expanded;
                        route = Some(r);
                    }
                }
                Err(PlanError::NoShape { .. } | PlanError::Unreachable { .. })
                    if growths < self.settings.max_growth && !expired(deadline) =>
                {
                    growths += 1;
                    self.build_roadmap(self.settings.vertices << growths, deadline);
                }
                // A roadmap cut short by the deadline fails for want of time.
                Err(PlanError::NoShape { .. } | PlanError::Unreachable { .. })
                    if expired(deadline) =>
                {
                    return Err(PlanError::TimeLimit { replans: 0 })
                }
                Err(PlanError::NoShape {
                    from, to, replans, ..
                }) => {
                    return Err(PlanError::NoShape {
                        from,
                        to,
                        replans,
                        narrowest: route.map(|r| (r.narrowest, r.narrowest_margin)),
                    })
                }
                Err(e) => return Err(e),
            }
        };
        stats.roadmap_growths = growths;
        stats.collision_checks = self.check_count() - checks_before;
        stats.lattice_expanded = lattice_expanded;
        stats.lattice_s = lattice_s;
        stats.route_points = route.as_ref().map_or(0, |r| r.points.len());
        stats.roadmap_s = self.roadmap_s;
        stats.planning_s = query_began.elapsed().as_secs_f64();
        (stats.roadmap_vertices, stats.roadmap_edges) = size;
        Ok(Solution { steps, stats })
    }
}

/// Yaw of the direction from the head to the centroid of the units of `shape`.
fn trail_yaw(params: &aerial_chain_core::ChainParams, shape: &Shape) -> f32 {
    let p = aerial_chain_core::kinematics::offsets(params, shape);
    let c = p
        .iter()
        .take(shape.units())
        .fold(nalgebra::Vector3::zeros(), |a, q| a + q);
    c.y.atan2(c.x)
}

/// Counts a plan's head edges and shape changes by where each shape came from
/// (replacing earlier counts: backing up and refinement change the steps).
fn count_sources(steps: &[Step], stats: &mut Stats) {
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
            Source::Start => {}
        }
    }
}

/// A lower bound on the head unit's margin (distance to the map minus `r_u`) along
/// the segment `a b`, sampled every quarter voxel (m, at least 0).
fn head_margin(ctx: &CollisionContext, a: [f64; 3], b: [f64; 3]) -> f64 {
    let step = ctx.field().grid().resolution() / 4.0;
    let n = (roadmap::dist(a, b) / step).ceil().max(1.0) as usize;
    let r_u = ctx.params().unit_radius as f64;
    (0..=n)
        .map(|i| {
            let t = i as f64 / n as f64;
            let p = [0, 1, 2].map(|k| a[k] + t * (b[k] - a[k]));
            ctx.clearance(p) - r_u
        })
        .fold(f64::INFINITY, f64::min)
        .max(0.0)
}

/// One leg of a head edge: shape changes where the head is, then a translation.
struct Leg {
    changes: Vec<Candidate>,
    to: [f64; 3],
}

/// The yaw of the edge `a -> b`; for a vertical edge, the shape's own heading.
fn edge_yaw(a: [f64; 3], b: [f64; 3], shape: &Shape) -> f32 {
    if (b[0] - a[0]).hypot(b[1] - a[1]) > 1e-6 {
        (b[1] - a[1]).atan2(b[0] - a[0]) as f32
    } else {
        shape.head_yaw()
    }
}

/// Edges that may fail from one vertex before the chain backs up from it.
const FAILS_BEFORE_BACKING_UP: usize = 4;

/// One query's online construction (Alg. 4).
struct Construction<'p> {
    planner: &'p Planner,
    roadmap: &'p mut Roadmap,
    checker: Checker,
    start: VertexId,
    goals: Vec<VertexId>,
    /// Cost-to-go of every vertex: the routes' heuristic.
    to_go: Vec<f64>,
    banned: BTreeSet<(VertexId, VertexId)>,
    current: Candidate,
    steps: Vec<Step>,
    stats: Stats,
    stop: Termination,
    began: Instant,
    /// Edges flown below the preferred clearance: steps before, margin, where.
    relaxed: Vec<(usize, f64, [f64; 3])>,
}

impl<'p> Construction<'p> {
    fn new(
        planner: &'p Planner,
        roadmap: &'p mut Roadmap,
        (start, shape): ([f64; 3], Shape),
        (goal, route): ([f64; 3], Option<&[[f64; 3]]>),
        stop: Termination,
        began: Instant,
    ) -> Self {
        let s = roadmap.add_query_vertex(start);
        let g = roadmap.add_query_vertex(goal);
        if let Some(inner) = route {
            roadmap.add_route(&planner.ctx, s, inner, g);
        }
        let tol = planner.settings.goal_tol;
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
            checker: Checker {
                ctx: planner.ctx.clone(),
                time: Duration::ZERO,
                deadline: stop.deadline(began),
            },
            start: s,
            goals,
            to_go,
            banned: BTreeSet::new(),
            current,
            steps: vec![Step {
                xi: start,
                shape,
                source: Source::Start,
                shape_change: false,
            }],
            stats: Stats::default(),
            stop,
            began,
            relaxed: Vec::new(),
        }
    }

    fn route(&self, from: VertexId) -> Result<Vec<VertexId>, PlanError> {
        let banned = |a: VertexId, b: VertexId| self.banned.contains(&(a.min(b), a.max(b)));
        self.roadmap
            .route(&self.planner.ctx, from, &self.goals, &self.to_go, &banned)
            .map_err(|e| match e {
                RouteError::StartIsolated | RouteError::Unreachable => PlanError::Unreachable {
                    tol: self.planner.settings.goal_tol,
                },
            })
    }

    fn run(mut self) -> Result<(Vec<Step>, Stats), PlanError> {
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
                if stuck_replans > self.planner.settings.max_replans {
                    return Err(PlanError::NoShape {
                        from,
                        to,
                        replans: self.stats.replans,
                        narrowest: None,
                    });
                }
                let here = trail.last().map(|t| t.0).unwrap_or(self.start);
                let stuck = fails[here] >= FAILS_BEFORE_BACKING_UP && trail.len() > 1;
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
                            from,
                            to,
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
                self.stats.min_margin_at = Some(at);
            }
        }
        self.stats.collision_s = self.checker.time.as_secs_f64();
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
                xi: leg.to,
                shape: cur.shape,
                source: cur.source,
                shape_change: false,
            });
        }
    }

    /// The legs that take the chain from `v` to `u`, or None. On the head route (both
    /// ends query vertices) the planner gives way to the smallest clearance when the
    /// preferred one fails.
    fn connect(&mut self, v: VertexId, u: VertexId) -> Option<Vec<Leg>> {
        if let Some(legs) = self.connect_at(v, u) {
            return Some(legs);
        }
        let p = self.planner;
        let (c_min, c_pref) = (p.ctx_min.clearance_margin(), p.ctx.clearance_margin());
        if !(c_min < c_pref && self.roadmap.is_query(v) && self.roadmap.is_query(u)) {
            return None;
        }
        // Give way step by step: first to 90 % of the head's own margin along the
        // edge (what the passage leaves on its narrowest side), then to the floor.
        let (a, b) = (self.roadmap.point(v), self.roadmap.point(u));
        let head = head_margin(&p.ctx, a, b);
        let mid = ((0.9 * head * 1000.0).floor() / 1000.0).clamp(c_min, c_pref);
        let mut levels = vec![(mid, None)];
        if mid > c_min {
            levels.push((c_min, Some(p.ctx_min.clone())));
        }
        let mut legs = None;
        for (c, ctx) in levels {
            let ctx = match ctx {
                Some(x) => x,
                None => {
                    match CollisionContext::new(p.ctx.field_arc().clone(), *p.ctx.params(), c) {
                        Ok(mut x) => {
                            x.set_min_step(p.ctx.min_step());
                            x
                        }
                        Err(_) => continue,
                    }
                }
            };
            self.checker.ctx = ctx;
            legs = self.connect_at(v, u);
            if legs.is_some() {
                self.relaxed.push((self.steps.len(), c, a));
                break;
            }
        }
        self.checker.ctx = p.ctx.clone();
        legs
    }

    /// [`Self::connect`] at the checker's clearance.
    fn connect_at(&mut self, v: VertexId, u: VertexId) -> Option<Vec<Leg>> {
        let (a, b) = (self.roadmap.point(v), self.roadmap.point(u));
        if let Some(changes) = self.connect_rigid(a, b) {
            return Some(vec![Leg { changes, to: b }]);
        }
        if self.planner.settings.follow_step > 0.0 {
            if let Some(legs) = self.follow(a, b) {
                return Some(legs);
            }
        }
        self.connect_srs(a, b)
            .map(|changes| vec![Leg { changes, to: b }])
    }

    /// The shape change at `a` to a kept, turned or library shape that flies `a -> b`.
    fn connect_rigid(&mut self, a: [f64; 3], b: [f64; 3]) -> Option<Vec<Candidate>> {
        let s = &self.planner.settings;
        let cur = self.current;
        let edge_yaw = edge_yaw(a, b, &cur.shape);
        let lsc = &self.planner.tables.lsc;
        let use_lsc = s.mode != Mode::Srs;
        let is_pn = matches!(cur.source, Source::Lsc(LscKind::Pn));
        // Coverage: move into the polygon wherever it fits.
        if s.prefer == Preference::Coverage && use_lsc && !is_pn {
            let pn = candidates::library(&cur.shape, lsc, edge_yaw, s.n_psi, Some(LscKind::Pn));
            if let Some(c) = self.first_direct(a, b, &pn) {
                return Some(vec![c]);
            }
        }
        // (a) keep the shape.
        if self.checker.translation(a, b, &cur.shape) {
            return Some(Vec::new());
        }
        // (b) yaw rotations.
        let rot = candidates::rotations(&cur.shape, edge_yaw, s.n_psi);
        if let Some(c) = self.first_direct(a, b, &rot) {
            return Some(vec![c]);
        }
        // (c) library shapes, cheapest first.
        let lib = if use_lsc {
            candidates::library(&cur.shape, lsc, edge_yaw, s.n_psi, None)
        } else {
            Vec::new()
        };
        self.first_direct(a, b, &lib).map(|c| vec![c])
    }

    /// Follow-the-leader from `a` to `b` in steps of `follow_step`: before each step
    /// the body is laid back along the head's track ([`follow::lay_along_newest_last`]).
    fn follow(&mut self, a: [f64; 3], b: [f64; 3]) -> Option<Vec<Leg>> {
        let params = *self.planner.ctx.params();
        let len = roadmap::dist(a, b);
        let n = ((len / self.planner.settings.follow_step).ceil() as usize).max(1);
        // Newest point last: each step appends (inserting at the front made long
        // edges quadratic).
        let mut track = self.track(a);
        track.reverse();
        let mut shape = self.current.shape;
        let mut legs = Vec::with_capacity(n.min(1024));
        let mut p = a;
        for j in 1..=n {
            let t = j as f64 / n as f64;
            let q = [0, 1, 2].map(|i| a[i] + t * (b[i] - a[i]));
            let laid = follow::lay_along_newest_last(&params, &track);
            let mut changes = Vec::new();
            if laid.max_angle_diff(&shape) > 1e-4 {
                let ok =
                    self.checker.config(p, &laid) && self.checker.shape_change(p, &shape, &laid);
                if !ok {
                    return None;
                }
                shape = laid;
                changes.push(Candidate {
                    shape,
                    source: Source::Follow,
                });
            }
            if !self.checker.translation(p, q, &shape) {
                return None;
            }
            legs.push(Leg { changes, to: q });
            track.push(nalgebra::Vector3::new(
                q[0] as f32,
                q[1] as f32,
                q[2] as f32,
            ));
            p = q;
        }
        Some(legs)
    }

    /// The head's track behind `a`: the head positions of the follow-the-leader steps
    /// that led here (newest first), then the body of the chain where that run of
    /// steps began. A rigid body's corners sharper than 90 degrees are cut first: a
    /// zig-zag at the bend limit (the serpentines) cannot be slid along.
    fn track(&self, a: [f64; 3]) -> Vec<nalgebra::Vector3<f32>> {
        let v = |p: [f64; 3]| nalgebra::Vector3::new(p[0] as f32, p[1] as f32, p[2] as f32);
        let params = self.planner.ctx.params();
        let mut track = vec![v(a)];
        let mut length = 0.0;
        // Twice the chain's reach: a winding track takes more than one reach of chords.
        let need = 2.0 * (params.reach() as f64 + 1.0);
        for st in self.steps.iter().rev() {
            if st.source == Source::Follow && length < need {
                let last = track.last().expect("track starts at a");
                let d = (v(st.xi) - last).norm();
                if d > 1e-6 {
                    length += d as f64;
                    track.push(v(st.xi));
                }
                continue;
            }
            let body = aerial_chain_core::kinematics::offsets(params, &st.shape);
            let body: Vec<_> = body.iter().take(params.n()).map(|o| v(st.xi) + o).collect();
            if st.source == Source::Follow {
                track.extend(body);
            } else {
                track.extend(follow::cut_sharp_corners(
                    &body,
                    std::f32::consts::FRAC_PI_2,
                ));
            }
            break;
        }
        track
    }

    /// SRSConnect (d): a path through `G_Val` to a random shape that flies `a -> b`.
    fn connect_srs(&mut self, a: [f64; 3], b: [f64; 3]) -> Option<Vec<Candidate>> {
        let s = &self.planner.settings;
        if s.mode == Mode::Lsc {
            return None;
        }
        let cur = self.current;
        let edge_yaw = edge_yaw(a, b, &cur.shape);
        self.stats.srs_connects += 1;
        let srs = &self.planner.tables.srs;
        let mut pool: Vec<Candidate> = Vec::with_capacity(2 * srs.len());
        for (k, &shape) in srs.iter().enumerate() {
            pool.push(Candidate {
                shape,
                source: Source::Srs(k as u16),
            });
            // The same shape turned so that its body trails straight behind the edge.
            let turn = aerial_chain_core::angle::diff(
                self.planner.trail_yaw[k],
                edge_yaw + std::f32::consts::PI,
            );
            pool.push(Candidate {
                shape: shape.rotated(turn),
                source: Source::SrsTurned(k as u16),
            });
        }
        // G_Val holds the random shapes only, as in the paper: the library was tried in (c).
        srs_connect::connect(
            &mut self.checker,
            a,
            b,
            &cur,
            &pool,
            &self.planner.tables.adjacency,
            s.d_c.unwrap_or_else(|| {
                aerial_chain_core::srs::default_r_s(self.planner.tables.params.units, srs.len())
            }),
        )
    }

    /// The first candidate that fits at `a`, flies `a -> b`, and is reachable from the
    /// current shape by one shape change at `a`.
    fn first_direct(&mut self, a: [f64; 3], b: [f64; 3], cands: &[Candidate]) -> Option<Candidate> {
        let cur = self.current.shape;
        cands.iter().copied().find(|c| {
            self.checker.placement(a, &c.shape)
                && self.checker.translation(a, b, &c.shape)
                && self.checker.shape_change(a, &cur, &c.shape)
        })
    }
}
