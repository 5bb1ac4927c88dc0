//! Head routes complete at the map's resolution: a search over the half-cell lattice.
//!
//! The head roadmap samples the map's box uniformly, and a narrow opening is a tiny
//! target for uniform samples (a 0.1 m x 0.1 m x 0.2 m tube for the head's centre in a
//! 0.5 m window). This module searches a LATTICE instead: the points `lo + k h` of the
//! map's box with `h = r_v / 2`, so it holds every voxel centre (odd `k`), every face,
//! edge and corner centre (even `k`): a gap an even number of voxels wide is centred on
//! a voxel face, and a gap an odd number wide on a voxel centre, so both are on it.
//!
//! A lattice point is FREE for a sphere of radius `R` (the unit radius plus the
//! clearance in force, see below) when it is inside the map's box and the sphere
//! touches no obstacle voxel cube, by the exact sphere-against-cube test of
//! docs/model.md: the distance field's proven lower bound decides where it exceeds
//! `R`, and only where it does not are the obstacle cubes near the point measured one
//! by one ([`exact_clearance`]). Points are 26-connected.
//!
//! [`exact_clearance`]: crate::collision::point_clearance::exact_clearance
//!
//! Once per map, setup labels the free regions of a relaxed voxel set
//! ([`Regions`]): a query whose start and goal lie in different regions is refused at
//! once (no lattice route can exist), whatever the map's size. The same sweep builds a
//! coarse graph of free-space pieces per block, and a Dijkstra over it from the goal
//! ([`guide`]) gives the A* a heuristic that knows the way through doors, where the
//! straight line would flood every room that faces the goal across a wall.
//!
//! A query is an A* from the lattice points next to the start to those next to the
//! goal. Each step costs its length times `1 + w max(0, 1 - (c - r_u) / c_ref)`, `c`
//! the clearance of the point it enters, plus a surcharge where `c` is below the
//! PREFERRED radius (unit radius plus `--clearance`): routes keep to the middle of
//! openings and rooms, and go below the preferred clearance only where no other way
//! exists. Beside the A*, a breadth-first flood from the goal runs one expansion per
//! A* expansion: whichever of the two runs out first proves that start and goal lie in
//! separate free regions of the lattice, so a sealed-off goal pocket is refused after
//! flooding the pocket, not the map. All state lives in hash maps keyed by lattice
//! point, so the work and memory follow the free space the query explores, never the
//! map's box.
//!
//! The lattice path is then pulled taut ([`HeadLattice::simplify`]): a run of lattice
//! points is replaced by one segment only when the head's sphere can fly it (by the
//! planner's conservative check at the smallest clearance) and the segment keeps as
//! much clearance as the points it replaces (up to a cap): in open space the route
//! becomes a few long segments, in a narrow passage it keeps the centred points.
//!
//! The route is a GUIDE for the chain, not a proof of anything: every edge the chain
//! flies is still checked by the planner's conservative checks. What the lattice
//! proves is the negative: when the search and the flood find no connection, no
//! lattice route exists for the head's sphere at that radius.

mod clearance;
mod flood;
mod guide;
mod nodes;
mod pull;
mod regions;
mod search;
#[cfg(test)]
mod tests;

pub(in crate::planner) use nodes::KeyHasher;
pub use regions::Regions;
pub(in crate::planner) use search::offsets26;

use std::time::Instant;

use super::dist;
use crate::collision::{CollisionContext, FK_TOLERANCE};
use crate::map::distance::DistanceField;
use nodes::Nodes;
use search::{Limit, Search};

/// Bits per axis in a packed lattice key.
const AXIS_BITS: u32 = 21;
const AXIS_MASK: u64 = (1 << AXIS_BITS) - 1;

/// How the lattice search ended.
#[derive(Clone, Debug, PartialEq)]
pub enum LatticeOutcome {
    /// A route from the start to the goal.
    Found(HeadRoute),
    /// Start and goal are in separate free regions of the lattice: no route exists for
    /// the head's sphere at the smallest clearance.
    Separated {
        /// Which side's region was measured whole ("start" or "goal").
        side: &'static str,
        /// Its size, in `unit`s.
        size: u64,
        /// What `size` counts: "lattice points" (a flood) or "voxels" (the labelled
        /// regions, [`Regions`]).
        unit: &'static str,
        /// Spacing of what was counted (m).
        spacing: f64,
    },
    /// No free lattice point next to the start (or the goal): the lattice cannot say.
    NoAnchor {
        /// "start" or "goal".
        side: &'static str,
    },
    /// The search visited its budget of lattice points, or reached its deadline,
    /// without an answer.
    Budget,
}

/// A head route: a polyline from the start to the goal.
#[derive(Clone, Debug, PartialEq)]
pub struct HeadRoute {
    /// The polyline, the start first and the goal last.
    pub points: Vec<[f64; 3]>,
    /// The route's narrowest lattice point.
    pub narrowest: [f64; 3],
    /// The head's margin there: distance to the nearest obstacle cube minus `r_u` (m;
    /// a proven lower bound).
    pub narrowest_margin: f64,
    /// Lattice points the A* expanded.
    pub expanded: usize,
}

/// The half-cell lattice of a map, for one chain and two clearances.
#[derive(Clone, Debug)]
pub struct HeadLattice {
    lo: [f64; 3],
    hi: [f64; 3],
    h: f64,
    /// Largest lattice index per axis (`2 dims`).
    n: [i64; 3],
    /// Unit radius `r_u` (m).
    unit_r: f64,
    /// Sphere radius that must be free: `r_u` + smallest clearance + FK tolerance.
    r_min: f64,
    /// Preferred radius: `r_u` + preferred clearance + FK tolerance.
    r_pref: f64,
    /// Clearance weight `w` of the step cost.
    weight: f64,
    /// Most lattice points a query may visit.
    pub budget: usize,
    /// The search's tuning (`planner::LatticeSettings`).
    pub(super) tuning: super::LatticeSettings,
    /// Expansions of the last strided search.
    searched: std::cell::Cell<Option<usize>>,
    /// The map's free regions for the sphere of radius `r_min`, labelled on first use.
    regions: std::sync::OnceLock<Regions>,
}

impl HeadLattice {
    /// The lattice of `ctx`'s map for the head's sphere: it must be free at clearance
    /// `clearance_min`, and prefers `ctx`'s clearance; tuned by the defaults.
    #[cfg(test)]
    pub fn new(ctx: &CollisionContext, clearance_min: f64, weight: f64) -> Self {
        Self::tuned(
            ctx,
            clearance_min,
            weight,
            super::LatticeSettings::default(),
        )
    }

    /// [`HeadLattice::new`] with the search's tuning `tuning`.
    pub fn tuned(
        ctx: &CollisionContext,
        clearance_min: f64,
        weight: f64,
        tuning: super::LatticeSettings,
    ) -> Self {
        let g = ctx.field().grid();
        let (lo, hi) = g.bounds();
        let h = g.resolution() / 2.0;
        let dims = g.dims();
        let unit_r = ctx.params().unit_radius as f64;
        let pref = ctx.clearance_margin();
        Self {
            lo: lo.into(),
            hi: hi.into(),
            h,
            n: dims.map(|d| 2 * d as i64),
            unit_r,
            r_min: unit_r + clearance_min.min(pref) + FK_TOLERANCE,
            r_pref: unit_r + pref + FK_TOLERANCE,
            weight,
            budget: tuning.budget,
            tuning,
            searched: std::cell::Cell::new(None),
            regions: std::sync::OnceLock::new(),
        }
    }

    /// The map's free regions for the head's sphere ([`Regions`]), labelled on the
    /// first call (its cost follows the map's size); `None` when `deadline` passes
    /// before they are (the next call labels them again).
    pub fn regions(&self, field: &DistanceField, deadline: Option<Instant>) -> Option<&Regions> {
        if let Some(r) = self.regions.get() {
            return Some(r);
        }
        let labelled = Regions::label(field, self.r_min, self.tuning.min_block, deadline)?;
        Some(self.regions.get_or_init(|| labelled))
    }

    /// Forgets the labelled regions (the next query that needs them labels them
    /// again).
    pub fn clear(&mut self) {
        self.regions = std::sync::OnceLock::new();
    }

    /// [`LatticeOutcome::Separated`] when the labelled regions prove that no lattice
    /// route joins `start` and `goal`; `None` when they cannot tell (or are not
    /// labelled by `deadline`).
    pub fn separation(
        &self,
        field: &DistanceField,
        start: [f64; 3],
        goal: [f64; 3],
        deadline: Option<Instant>,
    ) -> Option<LatticeOutcome> {
        let regions = self.regions(field, deadline)?;
        let mut nodes = Nodes::new(self, field);
        let mut sides = [("start", start), ("goal", goal)].map(|(side, p)| {
            let mut found: Vec<u32> = self
                .anchors(&mut nodes, p, 1)
                .into_iter()
                .filter_map(|k| regions.region_of(self.voxel_of(k)))
                .collect();
            found.sort_unstable();
            found.dedup();
            (side, found)
        });
        if sides.iter().any(|(_, f)| f.is_empty())
            || sides[0].1.iter().any(|r| sides[1].1.contains(r))
        {
            return None;
        }
        let total = |f: &[u32]| f.iter().map(|&r| regions.size(r)).sum::<u64>();
        sides.sort_by_key(|(_, f)| total(f));
        Some(LatticeOutcome::Separated {
            side: sides[0].0,
            size: total(&sides[0].1),
            unit: "voxels",
            spacing: 2.0 * self.h,
        })
    }

    /// The voxel (local indices) whose closed cube holds lattice point `k`.
    pub(super) fn voxel_of(&self, k: u64) -> [usize; 3] {
        let i = Self::unpack(k);
        [0, 1, 2].map(|a| ((i[a] / 2).min(self.n[a] / 2 - 1)).max(0) as usize)
    }

    /// Radius (m) of the sphere that must be free at lattice points: `r_u` plus the
    /// smallest clearance (plus the FK tolerance).
    pub fn radius_min(&self) -> f64 {
        self.r_min
    }

    pub(super) fn pack(&self, i: [i64; 3]) -> Option<u64> {
        if (0..3).all(|a| i[a] >= 0 && i[a] <= self.n[a])
            && self.n.iter().all(|&n| n < (1 << AXIS_BITS))
        {
            Some(i[0] as u64 | (i[1] as u64) << AXIS_BITS | (i[2] as u64) << (2 * AXIS_BITS))
        } else {
            None
        }
    }

    pub(super) fn unpack(k: u64) -> [i64; 3] {
        [
            (k & AXIS_MASK) as i64,
            ((k >> AXIS_BITS) & AXIS_MASK) as i64,
            ((k >> (2 * AXIS_BITS)) & AXIS_MASK) as i64,
        ]
    }

    /// Position of lattice point `k`.
    pub(super) fn point(&self, k: u64) -> [f64; 3] {
        let i = Self::unpack(k);
        [0, 1, 2].map(|a| self.lo[a] + i[a] as f64 * self.h)
    }

    /// Step cost factor for entering a point of clearance `c`.
    pub(super) fn factor(&self, c: f64) -> f64 {
        let mut f =
            1.0 + self.weight * (1.0 - (c - self.unit_r) / self.tuning.clearance_ref).max(0.0);
        if c <= self.r_pref {
            // Below the preferred clearance: the more so the narrower, so routes
            // through tight openings keep to their middle.
            let span = (self.r_pref - self.r_min).max(crate::planner::numeric::TINY);
            f += self.tuning.narrow_surcharge * (0.5 + (self.r_pref - c) / span);
        }
        f
    }

    /// Searches a lattice route from `start` to `goal` and pulls it taut with
    /// `ctx_min`'s conservative head-segment check (`ctx_min`: the smallest clearance).
    ///
    /// First over the voxel centres (an eighth of the points), which finds a route in
    /// all but the tightest passages; then, when that fails, over the whole half-cell
    /// lattice, with the floods that prove a failure.
    #[cfg(test)]
    pub fn route(
        &self,
        ctx_min: &CollisionContext,
        start: [f64; 3],
        goal: [f64; 3],
    ) -> LatticeOutcome {
        match self.quick_route(ctx_min, start, goal, None) {
            Some(route) => LatticeOutcome::Found(route),
            None => self.guided_route(ctx_min, start, goal, self.budget, None),
        }
    }

    /// The straight line as the heuristic, within a small budget and without the
    /// labelled regions: where no wall stands in the way (a corridor, open air, a
    /// window facing the start) it finds the route at once, for less than labelling
    /// the map's regions would cost. `None`: not found within the budget (which
    /// proves nothing).
    pub fn quick_route(
        &self,
        ctx_min: &CollisionContext,
        start: [f64; 3],
        goal: [f64; 3],
        deadline: Option<std::time::Instant>,
    ) -> Option<HeadRoute> {
        let mut nodes = Nodes::new(self, ctx_min.field());
        let quick = Limit {
            budget: self.tuning.quick_budget.min(self.budget),
            deadline,
        };
        let straight = guide::Guide::straight(self, goal);
        self.centres_route(ctx_min, &mut nodes, (start, goal), &quick, &straight)
    }

    /// One search over the voxel centres, the route it finds pulled taut; `None` where
    /// it finds none (which proves nothing).
    fn centres_route(
        &self,
        ctx_min: &CollisionContext,
        nodes: &mut Nodes,
        (start, goal): ([f64; 3], [f64; 3]),
        limit: &Limit,
        guide: &guide::Guide<'_>,
    ) -> Option<HeadRoute> {
        let found = self.search(nodes, start, goal, 2, limit, guide);
        self.searched.take();
        match found {
            Search::Found(keys, n) => match self.finish(ctx_min, nodes, start, goal, keys, n) {
                LatticeOutcome::Found(route) => Some(route),
                _ => None,
            },
            _ => None,
        }
    }

    /// A way for the head found greedily over the voxel centres: the regions' guide
    /// alone orders the search (its estimate weighted far above any path's cost), so it
    /// walks straight through the openings the guide points to, however narrow. Not a
    /// route to fly (it ignores the preference for room, which can make the A* of
    /// [`Self::guided_route`] search a whole storey before it enters a tight hatch): a
    /// head path to prove things along (`planner::linked`). Labels the regions first
    /// if that has not been done; `None`: not found within the budget.
    pub fn greedy_route(
        &self,
        ctx_min: &CollisionContext,
        start: [f64; 3],
        goal: [f64; 3],
        deadline: Option<Instant>,
    ) -> Option<HeadRoute> {
        /// The heuristic's weight: path costs are metres, so this leaves them to break
        /// ties only.
        const GREEDY: f64 = 1e6;
        let field = ctx_min.field();
        let (mut nodes, guide) = self.guided_by(field, self.regions(field, deadline)?, start, goal);
        let guide = guide.weighted(GREEDY);
        let limit = Limit {
            budget: self.budget,
            deadline,
        };
        self.centres_route(ctx_min, &mut nodes, (start, goal), &limit, &guide)
    }

    /// A search's points and the regions' guide from `start` to `goal`.
    fn guided_by<'a>(
        &'a self,
        field: &'a DistanceField,
        regions: &'a Regions,
        start: [f64; 3],
        goal: [f64; 3],
    ) -> (Nodes<'a>, guide::Guide<'a>) {
        let mut nodes = Nodes::new(self, field);
        let starts = self.anchors(&mut nodes, start, 1);
        let goals = self.anchors(&mut nodes, goal, 1);
        let guide = guide::Guide::new(self, regions, &starts, &goals, goal);
        (nodes, guide)
    }

    /// The search guided by the labelled regions' coarse graph ([`guide`]): first
    /// over the voxel centres, then over the whole half-cell lattice with the floods
    /// that prove a failure. Labels the regions first if that has not been done.
    pub fn guided_route(
        &self,
        ctx_min: &CollisionContext,
        start: [f64; 3],
        goal: [f64; 3],
        budget: usize,
        deadline: Option<Instant>,
    ) -> LatticeOutcome {
        let limit = Limit { budget, deadline };
        let field = ctx_min.field();
        let Some(regions) = self.regions(field, deadline) else {
            return LatticeOutcome::Budget;
        };
        let (mut nodes, guide) = self.guided_by(field, regions, start, goal);
        match self.search(&mut nodes, start, goal, 2, &limit, &guide) {
            Search::Found(keys, n) => {
                return self.finish(ctx_min, &mut nodes, start, goal, keys, n)
            }
            Search::Budget => return LatticeOutcome::Budget,
            _ => {}
        }
        let expanded = self.searched.take().unwrap_or(0);
        Self::reset(&mut nodes);
        match self.search(&mut nodes, start, goal, 1, &limit, &guide) {
            Search::Found(keys, n) => {
                self.finish(ctx_min, &mut nodes, start, goal, keys, n + expanded)
            }
            Search::Separated { side, visited } => LatticeOutcome::Separated {
                side,
                size: visited as u64,
                unit: "lattice points",
                spacing: self.h,
            },
            Search::NoAnchor(side) => LatticeOutcome::NoAnchor { side },
            Search::Exhausted | Search::Budget => LatticeOutcome::Budget,
        }
    }

    /// Forgets the search state of every point touched (their clearances stay valid).
    fn reset(nodes: &mut Nodes) {
        for n in nodes.map.values_mut() {
            (n.g, n.parent, n.closed, n.flooded) = (f64::INFINITY, u64::MAX, false, false);
        }
    }

    /// The route from the lattice path `keys` (start anchor first).
    fn finish(
        &self,
        ctx_min: &CollisionContext,
        nodes: &mut Nodes,
        start: [f64; 3],
        goal: [f64; 3],
        keys: Vec<u64>,
        expanded: usize,
    ) -> LatticeOutcome {
        let mut pts = Vec::with_capacity(keys.len() + 2);
        let mut clear = Vec::with_capacity(keys.len() + 2);
        pts.push(start);
        clear.push(nodes.clear(keys[0]).unwrap_or(0.0));
        for &k in &keys {
            pts.push(self.point(k));
            clear.push(nodes.clear(k).unwrap_or(0.0));
        }
        pts.push(goal);
        clear.push(nodes.clear(*keys.last().expect("non-empty")).unwrap_or(0.0));
        self.centre(nodes, &mut pts, &mut clear);
        let (mut narrowest, mut nc) = (pts[1], f64::INFINITY);
        for j in 1..pts.len() - 1 {
            if clear[j] < nc {
                (narrowest, nc) = (pts[j], clear[j]);
            }
        }
        let points = self.simplify(ctx_min, &pts, &clear);
        LatticeOutcome::Found(HeadRoute {
            points,
            narrowest,
            narrowest_margin: nc - self.unit_r,
            expanded,
        })
    }
}

pub(super) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub(super) fn norm(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}
