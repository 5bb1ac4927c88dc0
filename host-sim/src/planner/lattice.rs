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

use std::cmp::Ordering;
use std::collections::{BinaryHeap, HashMap, HashSet, VecDeque};

use std::hash::{BuildHasherDefault, Hasher};

use crate::collision::exact::point_box_distance;
use crate::collision::{CollisionContext, FK_TOLERANCE};
use crate::map::distance::DistanceField;

/// A fast hasher for packed lattice keys (a multiplicative mix; keys are not hostile).
#[derive(Default, Clone, Copy)]
pub struct KeyHasher(u64);

impl Hasher for KeyHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0.rotate_left(8) ^ b as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        }
    }
    fn write_u64(&mut self, v: u64) {
        let x = (v ^ (v >> 31)).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        self.0 = x ^ (x >> 29);
    }
}

type KeyMap<V> = HashMap<u64, V, BuildHasherDefault<KeyHasher>>;
type KeySet = HashSet<u64, BuildHasherDefault<KeyHasher>>;

/// Bits per axis in a packed lattice key.
const AXIS_BITS: u32 = 21;
const AXIS_MASK: u64 = (1 << AXIS_BITS) - 1;

/// Surcharge (per metre) for stepping where the clearance is below the preferred one.
const NARROW_SURCHARGE: f64 = 4.0;
/// Clearance above the preferred radius at which the step penalty vanishes (m).
const CLEARANCE_REF: f64 = 0.5;
/// Inflation of the A* heuristic (weighted A*): routes within this factor of the
/// cheapest, found with far fewer expansions.
const HEURISTIC_WEIGHT: f64 = 2.5;
/// Longest step (lattice spacings) in open space.
const MAX_JUMP: f64 = 16.0;
/// A string-pulled segment keeps the clearance of the points it replaces up to this
/// much above the preferred radius (m).
const KEEP_CAP: f64 = 0.3;

/// How the lattice search ended.
#[derive(Clone, Debug, PartialEq)]
pub enum LatticeOutcome {
    /// A route from the start to the goal.
    Found(HeadRoute),
    /// Start and goal are in separate free regions of the lattice: no route exists for
    /// the head's sphere at the smallest clearance.
    Separated {
        /// Which side's region was flooded completely ("start" or "goal").
        side: &'static str,
        /// Lattice points visited.
        visited: usize,
    },
    /// No free lattice point next to the start (or the goal): the lattice cannot say.
    NoAnchor {
        /// "start" or "goal".
        side: &'static str,
    },
    /// The search visited its budget of lattice points without an answer.
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

/// How one strided search ended.
enum Search {
    Found(Vec<u64>, usize),
    Separated {
        side: &'static str,
        visited: usize,
    },
    NoAnchor(&'static str),
    /// The A* ran dry over a sub-lattice that proves nothing.
    Exhausted,
    Budget,
}

/// A breadth-first flood over the unit lattice, one point per step.
struct Flood {
    queue: VecDeque<u64>,
    count: usize,
    active: bool,
    /// Record parents (the flood from the start, after the A*).
    parents: bool,
}

impl Flood {
    /// A flood from `seeds`, marking `flooded`.
    fn new(nodes: &mut Nodes, seeds: &[u64], active: bool) -> Self {
        for &q in seeds {
            nodes.get(q).flooded = true;
        }
        Self {
            queue: seeds.iter().copied().collect(),
            count: seeds.len(),
            active,
            parents: false,
        }
    }

    /// A flood from `seeds`, marking `closed` (after the A*: every mark is reset).
    fn new_mark(nodes: &mut Nodes, seeds: &[u64]) -> Self {
        for n in nodes.map.values_mut() {
            (n.closed, n.parent) = (false, u64::MAX);
        }
        for &q in seeds {
            nodes.get(q).closed = true;
        }
        Self {
            queue: seeds.iter().copied().collect(),
            count: seeds.len(),
            active: true,
            parents: true,
        }
    }

    /// Expands one point: `Some(true)` while points remain, `Some(false)` when the
    /// region is exhausted.
    fn step(
        &mut self,
        lat: &HeadLattice,
        nodes: &mut Nodes,
        offs: &[[i64; 3]; 26],
        mark: impl Fn(&mut Node) -> &mut bool,
    ) -> Option<bool> {
        let Some(q) = self.queue.pop_front() else {
            return Some(false);
        };
        let iq = HeadLattice::unpack(q);
        for o in offs {
            let Some(n) = lat.pack([iq[0] + o[0], iq[1] + o[1], iq[2] + o[2]]) else {
                continue;
            };
            let nn = nodes.get(n);
            if nn.clear.is_nan() {
                continue;
            }
            let m = mark(nn);
            if !*m {
                *m = true;
                if self.parents {
                    nn.parent = q;
                }
                self.count += 1;
                self.queue.push_back(n);
            }
        }
        Some(true)
    }
}

/// When a search gives up: lattice points touched, or the query's deadline.
struct Limit {
    budget: usize,
    deadline: Option<std::time::Instant>,
}

impl Limit {
    /// Whether to give up with `touched` points touched after `work` steps (the clock
    /// is read once every 1024 steps).
    fn reached(&self, touched: usize, work: usize) -> bool {
        touched > self.budget
            || (work.is_multiple_of(1024)
                && self.deadline.is_some_and(|d| std::time::Instant::now() > d))
    }
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
    /// Expansions of the last strided search.
    searched: std::cell::Cell<Option<usize>>,
}

/// Open-list entry, lowest `f` first.
#[derive(PartialEq)]
struct Open {
    f: f64,
    k: u64,
}
impl Eq for Open {}
impl Ord for Open {
    fn cmp(&self, o: &Self) -> Ordering {
        o.f.total_cmp(&self.f).then_with(|| o.k.cmp(&self.k))
    }
}
impl PartialOrd for Open {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

/// The 26 neighbour offsets.
fn offsets26() -> [[i64; 3]; 26] {
    let mut o = [[0i64; 3]; 26];
    let mut n = 0;
    for dz in -1..=1 {
        for dy in -1..=1 {
            for dx in -1..=1 {
                if (dx, dy, dz) != (0, 0, 0) {
                    o[n] = [dx, dy, dz];
                    n += 1;
                }
            }
        }
    }
    o
}

/// The exact distance from `p` to the nearest obstacle voxel cube of the field's grid,
/// when it is above `stop` and below `cap`; otherwise some value `<= stop` (the first
/// cube found within `stop`) or `>= cap`. The voxels are visited in rings around the
/// one holding `p`, nearest first, so a blocked point is settled after a few.
pub fn exact_clearance(field: &DistanceField, p: [f64; 3], stop: f64, cap: f64) -> f64 {
    let g = field.grid();
    let r = g.resolution();
    let c0 = g.lattice_index(p);
    let rings = (cap / r).ceil() as i32 + 1;
    let mut best = cap;
    for k in 0..=rings {
        // Every cube of ring k is at least (k - 1) r away.
        if (k - 1) as f64 * r >= best {
            break;
        }
        for dz in -k..=k {
            for dy in -k..=k {
                for dx in -k..=k {
                    if dx.abs().max(dy.abs()).max(dz.abs()) != k {
                        continue;
                    }
                    let i = [c0[0] + dx, c0[1] + dy, c0[2] + dz];
                    if !g.is_obstacle(i) {
                        continue;
                    }
                    let c = g.voxel_center(i);
                    let d = point_box_distance(
                        p,
                        [c[0] - r / 2.0, c[1] - r / 2.0, c[2] - r / 2.0],
                        [c[0] + r / 2.0, c[1] + r / 2.0, c[2] + r / 2.0],
                    );
                    if d < best {
                        best = d;
                        if d <= stop {
                            return d;
                        }
                    }
                }
            }
        }
    }
    best
}

/// What a query knows about one lattice point.
#[derive(Clone, Copy)]
struct Node {
    /// Clearance (m) when free at `r_min`, NaN when blocked.
    clear: f32,
    /// A* cost so far (infinite: not reached).
    g: f64,
    /// A* parent (`u64::MAX`: none).
    parent: u64,
    /// Expanded by the A* (or reached by the flood from the start).
    closed: bool,
    /// Reached by the flood from the goal.
    flooded: bool,
}

/// Per-query state of the lattice points touched.
struct Nodes<'a> {
    lat: &'a HeadLattice,
    field: &'a DistanceField,
    map: KeyMap<Node>,
}

impl Nodes<'_> {
    /// The point's record, its clearance computed on first touch.
    fn get(&mut self, k: u64) -> &mut Node {
        let (lat, field) = (self.lat, self.field);
        self.map.entry(k).or_insert_with(|| {
            let c = lat.point_clearance(field, lat.point(k));
            Node {
                clear: c.map_or(f32::NAN, |v| v as f32),
                g: f64::INFINITY,
                parent: u64::MAX,
                closed: false,
                flooded: false,
            }
        })
    }

    /// The point's clearance when free.
    fn clear(&mut self, k: u64) -> Option<f64> {
        let c = self.get(k).clear;
        (!c.is_nan()).then_some(c as f64)
    }
}

impl HeadLattice {
    /// The lattice of `ctx`'s map for the head's sphere: it must be free at clearance
    /// `clearance_min`, and prefers `ctx`'s clearance.
    pub fn new(ctx: &CollisionContext, clearance_min: f64, weight: f64) -> Self {
        let g = ctx.field().grid();
        let (lo, hi) = g.bounds();
        let h = g.resolution() / 2.0;
        let dims = g.dims();
        let unit_r = ctx.params().unit_radius as f64;
        let pref = ctx.clearance_margin();
        Self {
            lo,
            hi,
            h,
            n: dims.map(|d| 2 * d as i64),
            unit_r,
            r_min: unit_r + clearance_min.min(pref) + FK_TOLERANCE,
            r_pref: unit_r + pref + FK_TOLERANCE,
            weight,
            budget: 60_000_000,
            searched: std::cell::Cell::new(None),
        }
    }

    /// Radius (m) of the sphere that must be free at lattice points: `r_u` plus the
    /// smallest clearance (plus the FK tolerance).
    pub fn radius_min(&self) -> f64 {
        self.r_min
    }

    /// Lattice spacing `h` (m).
    pub fn spacing(&self) -> f64 {
        self.h
    }

    fn pack(&self, i: [i64; 3]) -> Option<u64> {
        if (0..3).all(|a| i[a] >= 0 && i[a] <= self.n[a])
            && self.n.iter().all(|&n| n < (1 << AXIS_BITS))
        {
            Some(i[0] as u64 | (i[1] as u64) << AXIS_BITS | (i[2] as u64) << (2 * AXIS_BITS))
        } else {
            None
        }
    }

    fn unpack(k: u64) -> [i64; 3] {
        [
            (k & AXIS_MASK) as i64,
            ((k >> AXIS_BITS) & AXIS_MASK) as i64,
            ((k >> (2 * AXIS_BITS)) & AXIS_MASK) as i64,
        ]
    }

    /// Position of lattice point `k`.
    fn point(&self, k: u64) -> [f64; 3] {
        let i = Self::unpack(k);
        [0, 1, 2].map(|a| self.lo[a] + i[a] as f64 * self.h)
    }

    /// The clearance at `p` (a proven lower bound from the field where that decides,
    /// the exact distance to the obstacle cubes otherwise) when the sphere of radius
    /// `r_min` is free there and `p` is inside the box; `None` otherwise.
    pub fn point_clearance(&self, field: &DistanceField, p: [f64; 3]) -> Option<f64> {
        let inside =
            (0..3).all(|a| p[a] >= self.lo[a] + FK_TOLERANCE && p[a] <= self.hi[a] - FK_TOLERANCE);
        if !inside {
            return None;
        }
        let c = field.clearance(p);
        if c > self.r_min {
            return Some(c);
        }
        // The field's bound is below the true distance by at most r_v sqrt(3)
        // (map::distance): far below the radius, the exact test cannot pass.
        let r_v = field.grid().resolution();
        if c + r_v * 3f64.sqrt() < self.r_min {
            return None;
        }
        let e = exact_clearance(field, p, self.r_min, self.r_pref + self.h);
        (e > self.r_min).then_some(e)
    }

    /// Whether the sphere of radius `r_min` is free at `p` (exact test).
    pub fn is_free(&self, field: &DistanceField, p: [f64; 3]) -> bool {
        self.point_clearance(field, p).is_some()
    }

    /// Step cost factor for entering a point of clearance `c`.
    fn factor(&self, c: f64) -> f64 {
        let mut f = 1.0 + self.weight * (1.0 - (c - self.unit_r) / CLEARANCE_REF).max(0.0);
        if c <= self.r_pref {
            // Below the preferred clearance: the more so the narrower, so routes
            // through tight openings keep to their middle.
            let span = (self.r_pref - self.r_min).max(1e-6);
            f += NARROW_SURCHARGE * (0.5 + (self.r_pref - c) / span);
        }
        f
    }

    /// Free points of the stride-`stride` sub-lattice near `p` (within two of its
    /// spacings), nearest first. Stride 2 is the lattice of voxel centres (odd indices).
    fn anchors(&self, nodes: &mut Nodes, p: [f64; 3], stride: i64) -> Vec<u64> {
        if stride == 2 {
            // Voxel centres one unit step from an anchor of the whole lattice, so
            // that a route over the centres is one over the whole lattice too.
            let mut out: Vec<(f64, u64)> = Vec::new();
            for a in self.anchors(nodes, p, 1) {
                let i = Self::unpack(a);
                for dz in -1..=1 {
                    for dy in -1..=1 {
                        for dx in -1..=1 {
                            let j = [i[0] + dx, i[1] + dy, i[2] + dz];
                            if j.iter().any(|v| v % 2 == 0) {
                                continue;
                            }
                            let Some(k) = self.pack(j) else { continue };
                            if nodes.clear(k).is_some() && !out.iter().any(|x| x.1 == k) {
                                out.push((dist(p, self.point(k)), k));
                            }
                        }
                    }
                }
            }
            out.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            return out.into_iter().map(|x| x.1).collect();
        }
        let off = stride - 1;
        let base = [0, 1, 2].map(|a| {
            let q = (p[a] - self.lo[a]) / self.h;
            ((q - off as f64) / stride as f64).round() as i64 * stride + off
        });
        let reach = 2.0 * stride as f64 * self.h * 1.0001;
        let mut found: Vec<(f64, u64)> = Vec::new();
        for dz in -2..=2 {
            for dy in -2..=2 {
                for dx in -2..=2 {
                    let i = [
                        base[0] + stride * dx,
                        base[1] + stride * dy,
                        base[2] + stride * dz,
                    ];
                    let Some(k) = self.pack(i) else {
                        continue;
                    };
                    let d = dist(p, self.point(k));
                    if d <= reach && nodes.clear(k).is_some() {
                        found.push((d, k));
                    }
                }
            }
        }
        found.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        found.into_iter().map(|x| x.1).collect()
    }

    /// Searches a lattice route from `start` to `goal` and pulls it taut with
    /// `ctx_min`'s conservative head-segment check (`ctx_min`: the smallest clearance).
    ///
    /// First over the voxel centres (an eighth of the points), which finds a route in
    /// all but the tightest passages; then, when that fails, over the whole half-cell
    /// lattice, with the floods that prove a failure.
    pub fn route(
        &self,
        ctx_min: &CollisionContext,
        start: [f64; 3],
        goal: [f64; 3],
    ) -> LatticeOutcome {
        self.route_within(ctx_min, start, goal, self.budget, None)
    }

    /// [`Self::route`], giving up ([`LatticeOutcome::Budget`]) once `budget` lattice
    /// points have been touched or `deadline` has passed (the query's time limit).
    pub fn route_within(
        &self,
        ctx_min: &CollisionContext,
        start: [f64; 3],
        goal: [f64; 3],
        budget: usize,
        deadline: Option<std::time::Instant>,
    ) -> LatticeOutcome {
        let limit = Limit { budget, deadline };
        let field = ctx_min.field();
        let mut nodes = Nodes {
            lat: self,
            field,
            map: KeyMap::default(),
        };
        let mut expanded = 0;
        match self.search(&mut nodes, start, goal, 2, &limit) {
            Search::Found(keys, n) => {
                return self.finish(ctx_min, &mut nodes, start, goal, keys, n)
            }
            Search::Budget => return LatticeOutcome::Budget,
            _ => {}
        }
        if let Some(n) = self.searched.take() {
            expanded = n;
        }
        // The clearances stay valid; the search state does not.
        for n in nodes.map.values_mut() {
            (n.g, n.parent, n.closed, n.flooded) = (f64::INFINITY, u64::MAX, false, false);
        }
        match self.search(&mut nodes, start, goal, 1, &limit) {
            Search::Found(keys, n) => {
                self.finish(ctx_min, &mut nodes, start, goal, keys, n + expanded)
            }
            Search::Separated { side, visited } => LatticeOutcome::Separated { side, visited },
            Search::NoAnchor(side) => LatticeOutcome::NoAnchor { side },
            Search::Exhausted | Search::Budget => LatticeOutcome::Budget,
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

    /// Moves the path's points where it is narrower than the preferred radius across
    /// the path, up the exact clearance, to the middle of the passage (a few lattice
    /// steps at most): the A*'s cost leans that way, but a weighted A* stops at the
    /// first route it finds.
    fn centre(&self, nodes: &mut Nodes, pts: &mut [[f64; 3]], clear: &mut [f64]) {
        let field = nodes.field;
        let cap = self.r_pref + 4.0 * self.h;
        let exact = |p: [f64; 3]| exact_clearance(field, p, 0.0, cap);
        let offs = offsets26();
        for j in 1..pts.len().saturating_sub(1) {
            if clear[j] >= self.r_pref + 2.0 * self.h {
                continue;
            }
            let d = sub(pts[j + 1], pts[j - 1]);
            let dn = norm(d).max(1e-12);
            let base = [0, 1, 2].map(|a| ((pts[j][a] - self.lo[a]) / self.h).round() as i64);
            let Some(mut cur) = self.pack(base) else {
                continue;
            };
            let mut best = exact(self.point(cur));
            for _ in 0..8 {
                let i = Self::unpack(cur);
                let mut next = None;
                for o in &offs {
                    let on = norm([o[0] as f64, o[1] as f64, o[2] as f64]);
                    let along =
                        (o[0] as f64 * d[0] + o[1] as f64 * d[1] + o[2] as f64 * d[2]) / (on * dn);
                    if along.abs() > 0.35 {
                        continue;
                    }
                    let Some(n) = self.pack([i[0] + o[0], i[1] + o[1], i[2] + o[2]]) else {
                        continue;
                    };
                    if nodes.clear(n).is_none() {
                        continue;
                    }
                    let e = exact(self.point(n));
                    if e > best + 1e-9 && next.is_none_or(|(_, b)| e > b) {
                        next = Some((n, e));
                    }
                }
                match next {
                    Some((n, e)) => (cur, best) = (n, e),
                    None => break,
                }
            }
            pts[j] = self.point(cur);
            clear[j] = best;
        }
    }

    /// One A* over the stride-`stride` sub-lattice. With stride 1, a flood from the
    /// goal runs beside it (one expansion each), and when the A* runs dry a flood from
    /// the start confirms it (the A* takes long steps in open space, so its running dry
    /// alone proves nothing): either flood exhausting its region without meeting the
    /// other side proves the two are separate.
    fn search(
        &self,
        nodes: &mut Nodes,
        start: [f64; 3],
        goal: [f64; 3],
        stride: i64,
        limit: &Limit,
    ) -> Search {
        let starts = self.anchors(nodes, start, stride);
        if starts.is_empty() {
            return Search::NoAnchor("start");
        }
        let goals = self.anchors(nodes, goal, stride);
        if goals.is_empty() {
            return Search::NoAnchor("goal");
        }
        let proving = stride == 1;
        let is_goal: KeySet = goals.iter().copied().collect();
        let offs = offsets26();
        let mut open = BinaryHeap::new();
        for &s in &starts {
            let c = dist(start, self.point(s));
            let n = nodes.get(s);
            if c < n.g {
                n.g = c;
                open.push(Open {
                    f: c + HEURISTIC_WEIGHT * dist(self.point(s), goal),
                    k: s,
                });
            }
        }
        let mut flood = Flood::new(nodes, &goals, proving);
        let mut expanded = 0usize;
        let found = loop {
            let Some(Open { k, .. }) = open.pop() else {
                self.searched.set(Some(expanded));
                if !proving {
                    return Search::Exhausted;
                }
                // Confirm with a flood from the start.
                let mut from_start = Flood::new_mark(nodes, &starts);
                loop {
                    match from_start.step(self, nodes, &offs, |n| &mut n.closed) {
                        Some(true) => {}
                        Some(false) => {
                            return Search::Separated {
                                side: "start",
                                visited: from_start.count,
                            }
                        }
                        None => return Search::Budget,
                    }
                    if let Some(&g) = goals.iter().find(|&&g| nodes.get(g).closed) {
                        // The long steps missed a way the flood found: take the
                        // flood's path.
                        return Search::Found(self.path_to(nodes, g), expanded);
                    }
                    if limit.reached(nodes.map.len(), from_start.count) {
                        return Search::Budget;
                    }
                }
            };
            let node = nodes.get(k);
            if node.closed {
                continue;
            }
            node.closed = true;
            let (gk, ck) = (node.g, node.clear as f64);
            expanded += 1;
            if is_goal.contains(&k) {
                break k;
            }
            if limit.reached(nodes.map.len(), expanded) {
                return Search::Budget;
            }
            let i = Self::unpack(k);
            let pk = self.point(k);
            // Unit steps; in open space only longer ones, which the clearance at `k`
            // proves free (the sphere moves less than `ck - r_min`).
            let room = ((ck - self.r_min) / (stride as f64 * self.h * 3f64.sqrt())).floor();
            let step = stride
                * if room >= 2.0 {
                    room.min(MAX_JUMP) as i64
                } else {
                    1
                };
            for o in &offs {
                let Some(n) =
                    self.pack([i[0] + step * o[0], i[1] + step * o[1], i[2] + step * o[2]])
                else {
                    continue;
                };
                if step == 2 {
                    // A step over one point of the whole lattice: that point must be
                    // free too (longer steps are covered by the clearance at `k`).
                    let mid = self.pack([i[0] + o[0], i[1] + o[1], i[2] + o[2]]);
                    if mid.is_none_or(|m| nodes.clear(m).is_none()) {
                        continue;
                    }
                }
                let nn = nodes.get(n);
                if nn.closed || nn.clear.is_nan() {
                    continue;
                }
                let pn = self.point(n);
                let c = (nn.clear as f64).min(ck);
                let ng = gk + dist(pk, pn) * self.factor(c);
                if ng < nn.g {
                    nn.g = ng;
                    nn.parent = k;
                    open.push(Open {
                        f: ng + HEURISTIC_WEIGHT * dist(pn, goal),
                        k: n,
                    });
                }
            }
            if flood.active {
                match flood.step(self, nodes, &offs, |n| &mut n.flooded) {
                    Some(true) => {}
                    Some(false) => {
                        if !starts.iter().any(|&s| nodes.get(s).flooded) {
                            return Search::Separated {
                                side: "goal",
                                visited: flood.count,
                            };
                        }
                        flood.active = false;
                    }
                    None => flood.active = false,
                }
            }
        };
        self.searched.set(Some(expanded));
        Search::Found(self.path_to(nodes, found), expanded)
    }

    /// The path of parents from a seed to `k`, the seed first.
    fn path_to(&self, nodes: &mut Nodes, k: u64) -> Vec<u64> {
        let mut keys = vec![k];
        loop {
            let p = nodes.get(*keys.last().expect("non-empty")).parent;
            if p == u64::MAX {
                break;
            }
            keys.push(p);
        }
        keys.reverse();
        keys
    }

    /// Pulls a lattice path taut: from each kept point, the farthest later point that
    /// one segment reaches, where the head's sphere can fly the segment (conservative,
    /// at the smallest clearance) and the segment keeps at least the smallest clearance
    /// of the points it replaces (capped at the preferred radius plus `KEEP_CAP`).
    pub fn simplify(
        &self,
        ctx_min: &CollisionContext,
        pts: &[[f64; 3]],
        clear: &[f64],
    ) -> Vec<[f64; 3]> {
        let field = ctx_min.field();
        let ok = |i: usize, j: usize| -> bool {
            if j == i + 1 {
                return true;
            }
            let need = clear[i..=j]
                .iter()
                .copied()
                .fold(f64::INFINITY, f64::min)
                .min(self.r_pref + KEEP_CAP);
            if !ctx_min.is_head_segment_free(pts[i], pts[j]) {
                return false;
            }
            let len = dist(pts[i], pts[j]);
            let n = (len / self.h).ceil().max(1.0) as usize;
            (0..=n).all(|s| {
                let t = s as f64 / n as f64;
                let p = [0, 1, 2].map(|a| pts[i][a] + t * (pts[j][a] - pts[i][a]));
                field.clearance(p) + 1e-3 >= need
            })
        };
        let mut out = vec![pts[0]];
        let mut i = 0;
        let last = pts.len() - 1;
        while i < last {
            // Gallop, then bisect, for the farthest reachable point.
            let mut good = i + 1;
            let mut step = 1;
            let mut bad = None;
            while good < last {
                let j = (i + 2 * step).min(last);
                if ok(i, j) {
                    good = j;
                    step *= 2;
                } else {
                    bad = Some(j);
                    break;
                }
            }
            if let Some(mut b) = bad {
                while b - good > 1 {
                    let m = (good + b) / 2;
                    if ok(i, m) {
                        good = m;
                    } else {
                        b = m;
                    }
                }
            }
            out.push(pts[good]);
            i = good;
        }
        out
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn norm(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

/// Euclidean distance (m).
fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use aerial_chain_core::ChainParams;
    use proptest::prelude::*;

    use super::*;
    use crate::map::grid::{Cell, Grid};

    /// A closed box of `dims` voxels at `res`, free inside a one-voxel shell.
    fn boxed(res: f64, dims: [usize; 3]) -> Grid {
        let mut g = Grid::new(res, [0; 3], dims, Cell::Occupied, true).unwrap();
        let e = 1e-6;
        let hi = dims.map(|d| (d - 1) as f64 * res - e);
        g.fill_box([res + e; 3], hi, Cell::Free);
        g
    }

    fn ctx(g: Grid, clearance: f64) -> CollisionContext {
        let field = Arc::new(DistanceField::new(g));
        CollisionContext::new(field, ChainParams::new(4), clearance).unwrap()
    }

    /// A wall across x at voxel column `wx` with the voxels `hole` (y, z ranges) open.
    fn wall_with_hole(g: &mut Grid, wx: i32, ys: std::ops::Range<i32>, zs: std::ops::Range<i32>) {
        let [_, ny, nz] = g.dims();
        for z in 0..nz as i32 {
            for y in 0..ny as i32 {
                if !(ys.contains(&y) && zs.contains(&z)) {
                    g.set([wx, y, z], Cell::Occupied);
                }
            }
        }
    }

    #[test]
    fn a_passage_one_voxel_wide_is_found_where_uniform_samples_miss_it() {
        // 0.35 m voxels: a one-voxel hole leaves the head's centre (r 0.15 m, no
        // clearance) a 0.05 m x 0.05 m x 0.35 m tube in a 7 x 7 x 3.5 m box.
        let res = 0.35;
        let mut g = boxed(res, [20, 20, 10]);
        wall_with_hole(&mut g, 10, 10..11, 5..6);
        let c = ctx(g, 0.0);
        let lat = HeadLattice::new(&c, 0.0, 2.0);
        let (a, b) = ([1.5, 1.5, 1.5], [5.5, 5.5, 1.5]);
        let LatticeOutcome::Found(r) = lat.route(&c, a, b) else {
            panic!("no route");
        };
        // The route passes the hole's centre (10.5, 10.5, 5.5) voxels.
        let hole = [10.5 * res, 10.5 * res, 5.5 * res];
        assert!(dist(r.narrowest, hole) < 1e-6, "{:?}", r.narrowest);
        assert!(r.narrowest_margin > 0.0);
        // Every route point keeps the head's sphere free by the exact test.
        for &p in &r.points {
            assert!(exact_clearance(c.field(), p, 0.0, 1.0) > 0.15, "{p:?}");
        }
        // The uniform roadmap of the same size misses it: 1500 samples, not one in
        // the tube (deterministic seed).
        let mut rng = <rand_pcg::Pcg64 as rand::SeedableRng>::seed_from_u64(1);
        let map =
            super::super::roadmap::Roadmap::build(&c, 1500, (1.5, 30), (2.0, 1.0), &mut rng, None);
        let in_tube = (0..map.vertex_count())
            .filter(|&v| {
                let p = map.point(v);
                (p[0] - hole[0]).abs() < res / 2.0
                    && (p[1] - hole[1]).abs() < 0.03
                    && (p[2] - hole[2]).abs() < 0.03
            })
            .count();
        assert_eq!(in_tube, 0);
    }

    #[test]
    fn a_gap_two_voxels_wide_is_found_on_its_face_centred_line() {
        // 0.2 m voxels, a 2 x 2 voxel hole (0.4 m): the head (0.15 m) fits only
        // near the hole's centre, which is on voxel faces, not on voxel centres.
        let res = 0.2;
        let mut g = boxed(res, [30, 20, 15]);
        wall_with_hole(&mut g, 15, 9..11, 7..9);
        let c = ctx(g, 0.0);
        let lat = HeadLattice::new(&c, 0.0, 2.0);
        let (a, b) = ([1.0, 2.0, 1.5], [5.0, 2.0, 1.5]);
        let centre = [2.0, 2.0, 1.6];
        // No voxel centre in the hole is free.
        for y in [9.5, 10.5] {
            for z in [7.5, 8.5] {
                assert!(!lat.is_free(c.field(), [15.5 * res, y * res, z * res]));
            }
        }
        assert!(lat.is_free(c.field(), [15.5 * res, centre[1], centre[2]]));
        let LatticeOutcome::Found(r) = lat.route(&c, a, b) else {
            panic!("no route");
        };
        assert!(
            (r.narrowest[1] - centre[1]).abs() < 1e-6 && (r.narrowest[2] - centre[2]).abs() < 1e-6
        );
        assert!(
            (r.narrowest_margin - 0.05).abs() < 1e-6,
            "{}",
            r.narrowest_margin
        );
    }

    #[test]
    fn a_wall_without_an_opening_separates_the_regions() {
        let mut g = boxed(0.2, [30, 20, 15]);
        wall_with_hole(&mut g, 15, 0..0, 0..0);
        let c = ctx(g, 0.05);
        let lat = HeadLattice::new(&c, 0.0, 2.0);
        match lat.route(&c, [1.0, 2.0, 1.5], [5.0, 2.0, 1.5]) {
            LatticeOutcome::Separated { .. } => {}
            other => panic!("{other:?}"),
        }
    }

    /// Reference: a breadth-first flood over the whole lattice with the same exact
    /// test, from the start's anchors to the goal's.
    fn flood_connects(
        lat: &HeadLattice,
        c: &CollisionContext,
        a: [f64; 3],
        b: [f64; 3],
    ) -> Option<bool> {
        let mut nodes = Nodes {
            lat,
            field: c.field(),
            map: KeyMap::default(),
        };
        let starts = lat.anchors(&mut nodes, a, 1);
        let goals: KeySet = lat.anchors(&mut nodes, b, 1).into_iter().collect();
        if starts.is_empty() || goals.is_empty() {
            return None;
        }
        let mut seen: KeySet = starts.iter().copied().collect();
        let mut queue: VecDeque<u64> = starts.into_iter().collect();
        while let Some(q) = queue.pop_front() {
            if goals.contains(&q) {
                return Some(true);
            }
            let i = HeadLattice::unpack(q);
            for o in offsets26() {
                if let Some(n) = lat.pack([i[0] + o[0], i[1] + o[1], i[2] + o[2]]) {
                    if lat.is_free(c.field(), lat.point(n)) && seen.insert(n) {
                        queue.push_back(n);
                    }
                }
            }
        }
        Some(false)
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

        /// The search finds a route exactly when the flood connects start and goal.
        #[test]
        fn route_exactly_when_the_flood_connects(
            seed in 0u64..1_000_000,
            density in 0.05f64..0.35,
            res in prop::sample::select(vec![0.1f64, 0.15, 0.2]),
        ) {
            use rand::{Rng, SeedableRng};
            let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
            let dims = [14, 10, 8];
            let mut g = boxed(res, dims);
            for z in 1..dims[2] as i32 - 1 {
                for y in 1..dims[1] as i32 - 1 {
                    for x in 1..dims[0] as i32 - 1 {
                        if rng.gen_bool(density) {
                            g.set([x, y, z], Cell::Occupied);
                        }
                    }
                }
            }
            let c = ctx(g, 0.0);
            let lat = HeadLattice::new(&c, 0.0, 2.0);
            let (lo, hi) = c.field().grid().bounds();
            let pick = |rng: &mut rand_pcg::Pcg64| {
                [0, 1, 2].map(|k| rng.gen_range(lo[k] + 0.2..hi[k] - 0.2))
            };
            let (a, b) = (pick(&mut rng), pick(&mut rng));
            let reference = flood_connects(&lat, &c, a, b);
            let got = lat.route(&c, a, b);
            match (reference, &got) {
                (None, LatticeOutcome::NoAnchor { .. }) => {}
                (Some(true), LatticeOutcome::Found(r)) => {
                    prop_assert_eq!(r.points[0], a);
                    prop_assert_eq!(*r.points.last().unwrap(), b);
                }
                (Some(false), LatticeOutcome::Separated { .. }) => {}
                (r, g) => prop_assert!(false, "flood {:?}, search {:?}", r, g),
            }
        }
    }
}
