//! The ARCplanner (paper Sec. 3): a head route, then per head edge the cheapest
//! shape that gets the whole chain along it.
//!
//! [`ArcPlanner`] holds the map context, the chain's shape tables, the settings, the
//! head lattice ([`super::lattice`]) and the uniform head roadmap `G_T`
//! ([`super::roadmap`]). A query ([`Planner::solve`]) runs the online construction
//! ([`super::construction`]) along the lattice's quick head route alone first; where
//! that fails, over the uniform roadmap, then with the labelled free regions' guided
//! route, then over a growing roadmap (docs/architecture.md, "How a query finds its
//! head route"). The regions and the roadmap are built by the first query that needs
//! them and shared by the later ones until [`Planner::clear`].

use std::time::Instant;

use aerial_chain_core::Shape;
use nalgebra::Point3;
use rand::SeedableRng;
use rand_pcg::Pcg64;
use serde_json::Value;

use super::construction::Construction;
use super::motion::source_label;
use super::roadmap::Roadmap;
use super::RefineSettings;
use super::{
    expired, lattice, PlanError, Planner, Query, Settings, Solution, SolutionStats, Step,
    Termination,
};
use crate::collision::CollisionContext;
use crate::plan_file::{Plan, Timings};
use crate::tables::ShapeTables;

/// Counters and timings of one query.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct Stats {
    /// Search structures built for this query (the labelled free regions and the
    /// uniform head roadmap, when it needed them and they were not built before),
    /// the query's other time, and its collision-check time.
    #[serde(skip)]
    pub timings: Timings,
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
    /// Shape changes that refinement made smaller (`super::refine`).
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
    #[serde(skip)] // not a counter: `annotate` writes it
    pub min_margin_at: Option<Point3<f64>>,
    /// Head route search (`lattice`): lattice points expanded (0: not used).
    pub lattice_expanded: usize,
    /// Head route search time (s), part of the query time.
    pub lattice_s: f64,
    /// Time (s) this query spent labelling the map's free regions (0 when it did not
    /// need them or they were labelled before), part of `timings.roadmap_s`.
    pub regions_s: f64,
    /// Points of the head route added to the roadmap (start and goal included).
    pub route_points: usize,
    /// Full-chain collision checks (configurations, translations, shape changes).
    pub collision_checks: u64,
    /// Roadmap vertices and candidate edges.
    pub roadmap_vertices: usize,
    /// Candidate edges of the roadmap.
    pub roadmap_edges: usize,
}

impl Stats {
    /// Where the query's time went, phase by phase: [`Self::timings`]' roadmap and
    /// planning times split at the free regions and the lattice route they include.
    pub fn phases(&self) -> Phases {
        Phases {
            regions_s: self.regions_s,
            roadmap_s: (self.timings.roadmap_s - self.regions_s).max(0.0),
            lattice_s: self.lattice_s,
            shapes_s: (self.timings.planning_s - self.lattice_s).max(0.0),
        }
    }
}

/// Where an ARCplanner query's time went (s), phase by phase ([`Stats::phases`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Phases {
    /// Labelling the map's free regions.
    pub regions_s: f64,
    /// Building the uniform head roadmap.
    pub roadmap_s: f64,
    /// The head route over the lattice.
    pub lattice_s: f64,
    /// The shape search along the route or roadmap (the rest of the query).
    pub shapes_s: f64,
}

/// The planner: a map context, a chain's shape tables, settings, and the roadmap.
pub struct ArcPlanner {
    /// The map and chain at the preferred clearance.
    pub(super) ctx: CollisionContext,
    /// The same map and chain at the smallest clearance (`Settings::clearance_min`).
    pub(super) ctx_min: CollisionContext,
    lattice: lattice::HeadLattice,
    /// The chain's shape library, random shapes and their adjacency.
    pub(super) tables: ShapeTables,
    /// Per SRS shape: the yaw from the head to the centroid of its units.
    pub(super) trail_yaw: Vec<f32>,
    pub(super) settings: Settings,
    /// Post-processing's tuning, and threading's, which the search uses too.
    pub(super) refine: RefineSettings,
    roadmap: Option<Roadmap>,
    roadmap_s: f64,
    /// The rule that proves where no unit holds its link, made with the planner (its
    /// stencil is setup's work, not a query's).
    links: super::linked::LinkCheck,
}

impl ArcPlanner {
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
        let lattice =
            lattice::HeadLattice::tuned(&ctx, c_min, settings.clearance_weight, settings.lattice);
        let p = ctx.params();
        let links = super::linked::LinkCheck::new(
            ctx.field().grid().resolution(),
            super::linked::LinkRule {
                link: f64::from(p.link_length),
                theta_max: f64::from(p.theta_max),
                // The regions' radius: what the planner's own checks keep at the least.
                radius: lattice.radius_min(),
            },
        );
        Ok(Self {
            ctx,
            ctx_min,
            lattice,
            tables,
            trail_yaw,
            settings,
            refine: RefineSettings::default(),
            roadmap: None,
            roadmap_s: 0.0,
            links,
        })
    }

    /// The planner with post-processing's tuning `refine` (default:
    /// `RefineSettings::default()`), which also tunes the search's threading.
    pub fn with_refine(mut self, refine: RefineSettings) -> Self {
        self.refine = refine;
        self
    }

    /// Post-processing's tuning.
    pub fn refine_settings(&self) -> &RefineSettings {
        &self.refine
    }

    /// Builds what every query needs before it starts: the uniform head roadmap
    /// when the lattice is off (the paper's planner). With the lattice on, nothing: a
    /// query first flies the lattice's head route, and only a query that needs them
    /// labels the free regions or builds the uniform roadmap (both kept until
    /// [`Planner::clear`]). Returns the time spent (s).
    fn setup_until(&mut self, deadline: Option<Instant>) -> f64 {
        if self.settings.head_lattice {
            return 0.0;
        }
        self.ensure_roadmap(deadline)
    }

    /// Builds the uniform head roadmap if there is none yet, cut short at `deadline`
    /// (the roadmap is then smaller). Returns the time spent (s).
    fn ensure_roadmap(&mut self, deadline: Option<Instant>) -> f64 {
        if self.roadmap.is_some() {
            return 0.0;
        }
        let t = Instant::now();
        self.build_roadmap(self.settings.vertices, deadline);
        let spent = t.elapsed().as_secs_f64();
        self.roadmap_s += spent;
        spent
    }

    /// Labels the map's free regions if that has not been done, unless `deadline`
    /// passes first. Returns the time spent (s).
    fn ensure_regions(&self, deadline: Option<Instant>) -> f64 {
        let t = Instant::now();
        self.lattice.regions(self.ctx.field(), deadline);
        t.elapsed().as_secs_f64()
    }

    /// (Re)builds the roadmap with `vertices` vertices, or fewer if `deadline` passes.
    /// The sampler restarts from the seed, so a larger roadmap holds every vertex of a
    /// smaller one. The radius shrinks as `(M_VT / vertices)^(1/3)`, so the number of
    /// neighbours stays the same.
    fn build_roadmap(&mut self, vertices: usize, deadline: Option<Instant>) {
        self.roadmap = Some(self.sampled_roadmap(vertices, deadline));
    }

    /// A roadmap of `vertices` uniform samples.
    fn sampled_roadmap(&self, vertices: usize, deadline: Option<Instant>) -> Roadmap {
        let r_t = self.settings.r_t * (self.settings.vertices as f64 / vertices as f64).cbrt();
        self.roadmap_of(vertices, r_t, deadline)
    }

    /// An empty roadmap, for a query over the lattice's head route alone: it samples
    /// nothing, so its radius only joins the query's start and goal when they lie
    /// within `joins` of each other.
    fn route_roadmap(&self, joins: f64) -> Roadmap {
        self.roadmap_of(0, joins, None)
    }

    fn roadmap_of(&self, vertices: usize, r_t: f64, deadline: Option<Instant>) -> Roadmap {
        let mut rng = Pcg64::seed_from_u64(self.settings.seed);
        let weight = (
            self.settings.clearance_weight,
            self.ctx.params().reach() as f64 / 2.0,
        );
        let near = (r_t, self.settings.max_neighbours);
        Roadmap::build(&self.ctx, vertices, near, weight, &mut rng, deadline)
    }

    /// The settings.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// The lattice's head route guided by the labelled regions (`Ok(None)`: the
    /// lattice cannot say within `budget`); [`PlanError::Separated`] when it proves
    /// that none exists. Adds its time to `s`.
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
            .guided_route(&self.ctx_min, start, goal, budget, deadline);
        *s += t.elapsed().as_secs_f64();
        match outcome {
            lattice::LatticeOutcome::Found(r) if r.points.len() >= 2 => Ok(Some(r)),
            separated @ lattice::LatticeOutcome::Separated { .. } => Err(self.separated(separated)),
            _ => Ok(None),
        }
    }

    /// The planning error for a lattice outcome that proves separation.
    fn separated(&self, outcome: lattice::LatticeOutcome) -> PlanError {
        match outcome {
            lattice::LatticeOutcome::Separated {
                side,
                size,
                unit,
                spacing,
            } => PlanError::Separated {
                radius: self.lattice.radius_min(),
                side,
                size,
                unit,
                spacing,
            },
            other => unreachable!("not a separation: {other:?}"),
        }
    }

    /// The proof that the chain cannot pass where its head's sphere can
    /// ([`super::linked`]): `route`, the head's way, crosses voxels where no unit holds
    /// its link within the pitch limit, and those that do leave start and goal apart.
    /// Asked where a route is found, before the chain tries it; `refine` (asked after
    /// the chain failed once: it costs a finer distance field around the route's
    /// narrowest point) lets the rule see margins finer than a coarse map's voxels.
    fn links_cut(
        &self,
        query: &Query,
        route: Option<&lattice::HeadRoute>,
        refine: bool,
        deadline: Option<Instant>,
    ) -> Option<PlanError> {
        let route = route.filter(|_| !expired(deadline))?;
        let field = self.ctx.field();
        let check = &self.links;
        let refine_at = refine.then_some(route.narrowest);
        let flood = super::linked::LinkFlood::new(field, check, refine_at);
        let proof = flood.separated(&route.points, query.ends().1, query.goal_tol, deadline)?;
        let rule = check.rule();
        Some(PlanError::LinksCut {
            from: proof.stretch.0,
            to: proof.stretch.1,
            link: rule.link,
            pitch_deg: rule.theta_max.to_degrees(),
            radius: rule.radius,
            side: proof.side,
            size: proof.cells,
            spacing: proof.cell_m,
        })
    }

    /// Full-chain checks made so far by both contexts.
    fn check_count(&self) -> u64 {
        [self.ctx.stats(), self.ctx_min.stats()]
            .iter()
            .map(|c| c.configs + c.translations + c.shape_changes)
            .sum()
    }

    /// Plans `query` ([`Planner::solve`]). With the lattice on, first the quick
    /// straight-line head route ([`lattice::HeadLattice::quick_route`]) and the online
    /// construction along it alone: where no wall stands between start and goal (open
    /// air, a corridor, a window facing the start) that is the whole query. Else the
    /// construction over the uniform head roadmap ([`Self::solve_on_roadmap`]).
    fn solve_query(
        &mut self,
        query: &Query,
        stop: Termination,
    ) -> Result<Solution<Stats>, PlanError> {
        // The time limit covers what the query builds (regions, roadmap) and growth.
        let began = Instant::now();
        let deadline = stop.deadline(began);
        let checks_before = self.check_count();
        let mut built = Built {
            roadmap_s: self.setup_until(deadline),
            ..Built::default()
        };
        query.check(&self.ctx_min)?;
        let mut on_route = None;
        if self.settings.head_lattice {
            let (start, goal) = query.ends();
            let t = Instant::now();
            built.route = self
                .lattice
                .quick_route(&self.ctx_min, start, goal, deadline);
            built.lattice_s += t.elapsed().as_secs_f64();
            if let Some(cut) = self.links_cut(query, built.route.as_ref(), false, deadline) {
                return Err(cut);
            }
            on_route = self.solve_on_route(query, stop, began, &built)?;
            if on_route.is_none() {
                on_route = self.threaded_on_route(query, &built, deadline);
            }
            // Where the chain could not fly it alone, the roadmap is tried on its own
            // first: a long chain replans better over samples than along the route's
            // free edges. The route joins the roadmap after that fails.
            if on_route.is_none() {
                built.quick = built.route.take();
            }
        }
        let (steps, mut stats) = match on_route {
            Some(solved) => solved,
            None => {
                built.roadmap_s += self.ensure_roadmap(deadline);
                self.solve_on_roadmap(query, stop, began, &mut built)?
            }
        };
        if let Some(r) = &self.roadmap {
            // Built by this query or an earlier one, whether or not the plan used it.
            (stats.roadmap_vertices, stats.roadmap_edges) = (r.vertex_count(), r.edge_count());
        }
        stats.collision_checks = self.check_count() - checks_before;
        let route = built.route.as_ref().or(built.quick.as_ref());
        stats.lattice_expanded = route.map_or(0, |r| r.expanded);
        stats.lattice_s = built.lattice_s;
        stats.route_points = route.map_or(0, |r| r.points.len());
        stats.regions_s = built.regions_s;
        stats.timings.roadmap_s = built.regions_s + built.roadmap_s;
        stats.timings.planning_s =
            (began.elapsed().as_secs_f64() - stats.timings.roadmap_s).max(0.0);
        Ok(Solution { steps, stats })
    }

    /// The online construction along the lattice's head route in `built` alone (no
    /// sampled vertices): `Ok(None)` when there is no route or the chain cannot
    /// follow it. Where the route bends, the straight edge from start to goal is tried
    /// first, without random shapes; then the route's edges. Where the head's route
    /// itself keeps the preferred clearance, the chain may not give way below it (the
    /// uniform roadmap may hold a route on which the whole chain keeps it): the
    /// construction ends at the first edge that asks, rather than flying the rest of
    /// the route for a plan that would be refused.
    fn solve_on_route(
        &self,
        query: &Query,
        stop: Termination,
        began: Instant,
        built: &Built,
    ) -> Result<Option<(Vec<Step>, Stats)>, PlanError> {
        let Some(route) = &built.route else {
            return Ok(None);
        };
        let inner = &route.points[1..route.points.len() - 1];
        let keeps_clearance = route.narrowest_margin >= self.ctx.clearance_margin();
        // Where the route bends, the straight edge from start to goal may still pass
        // the head's lazy check (the route was pulled taut by a more conservative
        // one): flown whole, or by a follower, it is the shorter plan. It is tried
        // without random shapes, whose search for one long edge the route bends away
        // from costs more than the route.
        if !inner.is_empty() {
            let mut straight = self.route_roadmap(f64::INFINITY);
            let construction = Construction::new(self, &mut straight, query, None, stop, began)
                .without_random_shapes();
            if let Some(solved) = flown_alone(construction, keeps_clearance)? {
                return Ok(Some(solved));
            }
        }
        let mut roadmap = self.route_roadmap(self.settings.r_t);
        let construction = Construction::new(self, &mut roadmap, query, Some(inner), stop, began);
        flown_alone(construction, keeps_clearance)
    }

    /// The chain following its head along the route in `built`, straightened through
    /// the axis of each pinch (`super::thread`), where the chain could not fly the
    /// route with whole shapes and the route passes an opening that leaves a unit less
    /// than `RefineSettings::thread.opening` of widening's reach (`super::widen::CAP`)
    /// in its middle (a window or a door, not a wide passage where a follower would
    /// turn through every corner of the route): at an oblique window
    /// the chain lines up with the opening and threads it, where the roadmap would
    /// sample the room for another way in. A route that has no pinch to straighten
    /// because the chain starts or ends inside the passage (a bent pipe) is followed
    /// as it is, where its head keeps less than that reach. `None` where the route has
    /// no such opening or a step fails the checks.
    fn threaded_on_route(
        &self,
        query: &Query,
        built: &Built,
        deadline: Option<Instant>,
    ) -> Option<(Vec<Step>, Stats)> {
        let route = built.route.as_ref()?;
        let points: Vec<Point3<f64>> = route.points.iter().map(|&p| p.into()).collect();
        let reach = self.refine.thread.opening * super::widen::CAP;
        let threading =
            match super::thread::Threading::along(&self.ctx, &points, &self.refine.thread) {
                Some(t) if t.narrowest_middle() < reach => t,
                Some(_) => return None,
                None if route.narrowest_margin < reach => {
                    super::thread::Threading::as_is(&points, &self.refine.thread)?
                }
                None => return None,
            };
        self.followed(&threading, query, deadline)
    }

    /// The chain following its head along `threading`'s route from the query's start,
    /// with the plan's counters; `None` where a step fails.
    fn followed(
        &self,
        threading: &super::thread::Threading,
        query: &Query,
        deadline: Option<Instant>,
    ) -> Option<(Vec<Step>, Stats)> {
        let (steps, checks) = threading
            .follow(
                &self.ctx,
                &query.start_step(),
                self.settings.follow_step,
                deadline,
            )
            .ok()?;
        let mut stats = Stats::default();
        super::construction::count_sources(&steps, &mut stats);
        stats.min_margin = self.ctx.clearance_margin();
        stats.timings.collision_s = checks.as_secs_f64();
        Some((steps, stats))
    }

    /// The last try of a query that fails for want of a shape: the chain following its
    /// head along the route the query holds (the quick route, or the lattice's guided
    /// one), threaded through the route's pinches, else as the route runs. Where the
    /// search's shapes and the roadmap found no way, a follower may still pass: a long
    /// chain that must turn right behind an opening (a door a metre behind a window and
    /// to its side) lays its body along the route where no whole shape fits the turn.
    /// Tried only where the query would fail otherwise, so every plan the search finds
    /// stays as it was.
    fn followed_anyway(
        &self,
        query: &Query,
        built: &Built,
        deadline: Option<Instant>,
    ) -> Option<(Vec<Step>, Stats)> {
        let route = built.route.as_ref().or(built.quick.as_ref())?;
        let points: Vec<Point3<f64>> = route.points.iter().map(|&p| p.into()).collect();
        let s = &self.refine.thread;
        let ways = [
            super::thread::Threading::along(&self.ctx, &points, s),
            super::thread::Threading::as_is(&points, s),
        ];
        ways.into_iter()
            .flatten()
            .find_map(|threading| self.followed(&threading, query, deadline))
    }

    /// Where the uniform roadmap failed: the quick route, if the query found one,
    /// joins the roadmap; else the lattice search guided by the labelled free regions
    /// (labelled now if need be) runs: a proof that start and goal lie in separate
    /// regions ends the query; a route found is flown alone
    /// ([`Self::solve_on_route`], else threaded: [`Self::threaded_on_route`]) and
    /// else joins the roadmap.
    fn guided_attempt(
        &self,
        query: &Query,
        stop: Termination,
        began: Instant,
        built: &mut Built,
    ) -> Result<Option<(Vec<Step>, Stats)>, PlanError> {
        if let Some(quick) = built.quick.take() {
            // Tried alone before: now it joins the roadmap. A route joins start and
            // goal, so there is no separation to look for (labelling the regions
            // would cost a flood of the whole map).
            built.route = Some(quick);
            return Ok(None);
        }
        let (start, goal) = query.ends();
        let (budget, deadline) = (self.lattice.budget, stop.deadline(began));
        built.regions_s += self.ensure_regions(deadline);
        if let Some(sep) = self
            .lattice
            .separation(self.ctx.field(), start, goal, deadline)
        {
            return Err(self.separated(sep));
        }
        // Whether the chain can pass at all, asked along a way the head finds greedily:
        // the guided route's A* prices tight stretches high, and may search a storey
        // before it enters a hatch that no chain passes anyway.
        let t = Instant::now();
        let greedy = self
            .lattice
            .greedy_route(&self.ctx_min, start, goal, deadline);
        built.lattice_s += t.elapsed().as_secs_f64();
        if let Some(cut) = self.links_cut(query, greedy.as_ref(), true, deadline) {
            return Err(cut);
        }
        built.route = self.head_route(start, goal, budget, deadline, &mut built.lattice_s)?;
        if greedy.is_none() {
            if let Some(cut) = self.links_cut(query, built.route.as_ref(), true, deadline) {
                return Err(cut);
            }
        }
        if let Some(solved) = self.solve_on_route(query, stop, began, built)? {
            return Ok(Some(solved));
        }
        // As on the quick route: where whole shapes cannot fly the route through an
        // opening, the chain follows its head along it, threading the opening.
        Ok(self.threaded_on_route(query, built, deadline))
    }

    /// The online construction over the uniform head roadmap (joined by the lattice's
    /// route when `built` holds one). Where it fails, the guided lattice search
    /// ([`Self::guided_attempt`]) runs once; then, like OMPL's PRM, the roadmap grows
    /// while the query fails and time remains; where no growth is left, the chain
    /// follows its head along the route ([`Self::followed_anyway`]) before the query
    /// fails.
    fn solve_on_roadmap(
        &mut self,
        query: &Query,
        stop: Termination,
        began: Instant,
        built: &mut Built,
    ) -> Result<(Vec<Step>, Stats), PlanError> {
        let deadline = stop.deadline(began);
        let mut guided = !self.settings.head_lattice;
        let mut growths = 0;
        loop {
            if expired(deadline) {
                return Err(PlanError::TimeLimit { replans: 0 });
            }
            let route = built.route.as_ref();
            let inner = route.map(|r| &r.points[1..r.points.len() - 1]);
            let mut roadmap = self.roadmap.take().expect("the query built the roadmap");
            let result = Construction::new(self, &mut roadmap, query, inner, stop, began).run();
            roadmap.clear_query();
            self.roadmap = Some(roadmap);
            match result {
                Ok((steps, mut stats)) => {
                    // The roadmap's size is filled in by `solve_query`.
                    stats.roadmap_growths = growths;
                    return Ok((steps, stats));
                }
                Err(PlanError::NoShape { .. } | PlanError::Unreachable { .. })
                    if !guided && !expired(deadline) =>
                {
                    guided = true;
                    if let Some(solved) = self.guided_attempt(query, stop, began, built)? {
                        return Ok(solved);
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
                    if let Some(solved) = self.followed_anyway(query, built, deadline) {
                        return Ok(solved);
                    }
                    return Err(PlanError::NoShape {
                        from,
                        to,
                        replans,
                        narrowest: route.map(|r| (r.narrowest.into(), r.narrowest_margin)),
                    });
                }
                Err(e) => return Err(e),
            }
        }
    }
}

/// `construction` run without replans (over a lone route there is none to replan
/// onto), without giving way where the route `keeps_clearance`: `Ok(None)` where no
/// shape flies an edge.
fn flown_alone(
    construction: Construction<'_>,
    keeps_clearance: bool,
) -> Result<Option<(Vec<Step>, Stats)>, PlanError> {
    let mut construction = construction.without_replans();
    if keeps_clearance {
        construction = construction.without_giving_way();
    }
    match construction.run() {
        Ok(solved) => Ok(Some(solved)),
        Err(PlanError::NoShape { .. } | PlanError::Unreachable { .. }) => Ok(None),
        Err(e) => Err(e),
    }
}

/// What a query built and searched before its construction, timed apart.
#[derive(Default)]
struct Built {
    /// The lattice's head route that joins the roadmap, if one was found.
    route: Option<lattice::HeadRoute>,
    /// The quick route, flown alone without success, kept for the roadmap's second try.
    quick: Option<lattice::HeadRoute>,
    /// Time (s) the lattice searches took.
    lattice_s: f64,
    /// Time (s) spent labelling the free regions in this query.
    regions_s: f64,
    /// Time (s) spent building the uniform roadmap in this query (not its growth).
    roadmap_s: f64,
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

impl Planner for ArcPlanner {
    type Stats = Stats;
    type Error = PlanError;

    fn context(&self) -> &CollisionContext {
        &self.ctx
    }

    /// Builds the uniform head roadmap when the lattice is off (once; later calls do
    /// nothing until [`Self::clear`]); with the lattice on, the queries build what
    /// they need. The head roadmap serves any query, so the query is not read.
    fn setup(&mut self, _query: &Query, stop: Termination) {
        self.setup_until(stop.deadline(Instant::now()));
    }

    /// Plans from the query's start to within its goal tolerance of its goal; sets up
    /// first if needed, under the same time limit.
    fn solve(&mut self, query: &Query, stop: Termination) -> Result<Solution<Stats>, PlanError> {
        self.solve_query(query, stop)
    }

    fn clear(&mut self) {
        self.roadmap = None;
        self.lattice.clear();
    }

    fn roadmap_stats(&self) -> Stats {
        let (roadmap_vertices, roadmap_edges) = self
            .roadmap
            .as_ref()
            .map_or((0, 0), |r| (r.vertex_count(), r.edge_count()));
        Stats {
            timings: Timings {
                roadmap_s: self.roadmap_s,
                ..Default::default()
            },
            roadmap_vertices,
            roadmap_edges,
            ..Default::default()
        }
    }
}

impl SolutionStats for Stats {
    fn timings(&self) -> Timings {
        self.timings
    }

    fn rest_name(&self) -> &'static str {
        "shape_search_s"
    }

    /// Where each waypoint's shape came from, and the smallest clearance margin in
    /// force and where (docs/model.md "Files").
    fn annotate(&self, steps: &[Step], plan: &mut Plan) {
        let labels: Vec<Value> = steps
            .iter()
            .map(|s| Value::String(source_label(&s.source, s.shape_change)))
            .collect();
        plan.stats
            .insert("waypoint_sources".into(), Value::Array(labels));
        plan.stats
            .insert("min_margin".into(), serde_json::json!(self.min_margin));
        if let Some(at) = self.min_margin_at {
            plan.stats.insert(
                "min_margin_at".into(),
                serde_json::json!(<[f64; 3]>::from(at)),
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use std::sync::atomic::AtomicUsize;
    use std::sync::Arc;

    use aerial_chain_core::ChainParams;

    use super::*;
    use crate::collision::DEFAULT_CLEARANCE;
    use crate::map::DistanceField;
    use crate::problem::scenarios;
    use crate::tables::TableSettings;

    /// The roadmap the route's edges are flown on (nothing sampled) joins start and
    /// goal as the uniform one does, within `r_T`: farther apart, they are joined only
    /// by the head route the query adds, so a straight edge to the goal that no shape
    /// flies cannot end the attempt before the route's own edges are tried (it took
    /// the uniform roadmap's radius scaled to one vertex, 17 m).
    #[test]
    fn an_empty_roadmap_joins_query_vertices_only_within_r_t() {
        let sc = scenarios::build("window").unwrap();
        let params = ChainParams::new(3);
        let small = TableSettings {
            srs: 60,
            ..TableSettings::default()
        };
        let tables = ShapeTables::build(params, &small, &AtomicUsize::new(0)).unwrap();
        let field = Arc::new(DistanceField::new(sc.grid.clone()));
        let ctx = CollisionContext::new(field, params, DEFAULT_CLEARANCE).unwrap();
        let planner = ArcPlanner::new(ctx, tables, Settings::default()).unwrap();
        let r_t = planner.settings.r_t;
        let mut roadmap = planner.route_roadmap(r_t);
        let start = roadmap.add_query_vertex([2.0, 1.0, 1.5]);
        let far = roadmap.add_query_vertex([2.0, 1.0 + 2.0 * r_t, 1.5]);
        let near = roadmap.add_query_vertex([2.0, 1.0 + 0.5 * r_t, 1.5]);
        assert!(roadmap.cost_to_go(&[near])[start].is_finite());
        assert!(!roadmap.cost_to_go(&[far])[start].is_finite());
    }
}
