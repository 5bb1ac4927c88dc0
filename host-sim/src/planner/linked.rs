//! Where no unit can hold a link: a proof that the chain cannot pass where its head's
//! sphere can.
//!
//! The free regions (`lattice::regions`) prove a query impossible when the head's
//! sphere cannot get through. A chain needs more: every unit holds at least one link,
//! `l` long, whose pitch is at most `theta_max`, with the unit at its other end as free
//! as itself. A vertical shaft a unit fits into but deeper than a tilted link can
//! leave (the neighbour of a unit half way down lies `l cos(theta_max)` aside, in the
//! rock) passes the head's sphere and no chain.
//!
//! # The rule
//! Call a voxel LINK-BLOCKED when no point of its closed cube can hold the centre of a
//! unit (radius `R`: `r_u` plus the smallest clearance and the checks' tolerance, the
//! regions' radius) with a free neighbour at
//! distance `l` in a direction whose pitch is at most `theta_max`. Every unit of a
//! chain of two or more always holds such a neighbour, so the head's centre never
//! enters a link-blocked voxel; as it moves, the voxels holding it change only to
//! 26-neighbours. So when the voxels that are NOT link-blocked split into 26-connected
//! regions with the start in one and every voxel within the goal tolerance in others,
//! no plan exists.
//!
//! # The certificate
//! A voxel is link-blocked when every point of it, and every point of the voxels its
//! neighbour could occupy, lies within `R` of an obstacle cube. Both come from one
//! test, WITHIN: every point of voxel `u` lies within `R` of an obstacle cube when the
//! centre of some obstacle voxel lies within `R` of `u`'s centre (a cube's farthest
//! point from another cube of the same size, `k` voxels away, is `r |k|` away: the
//! corners line up). The distance field stores `r G(n)` for the squared distance `n`
//! (voxel units) to the nearest obstacle centre, with `G` non-decreasing, so
//! `n <= (R / r)^2` holds whenever the stored value is below `r G(n* + 1)`: one
//! comparison per voxel (`Closure::within`). A stored value above `R + l` settles
//! the other way at once: a unit at the centre and one a level link away are free.
//!
//! The neighbour of a unit in voxel `v` lies in a voxel `v + k` for `k` in a STENCIL:
//! the offsets whose cube, grown by a voxel (the unit's own extent), meets the zone
//! `|x| = l, |x_z| <= l sin(theta_max)`. A voxel is link-blocked when it is WITHIN
//! itself (no free centre), or when every voxel of its stencil is (no free
//! neighbour). Every step only leaves out what could be free (the link's capsule, the
//! bend limits, the other units), so a voxel the test blocks is blocked; a voxel it
//! does not block may still be. The stencil is scanned level links first, so near
//! walls the first offsets settle it.
//!
//! A voxel's extent costs the test up to a voxel of margin on each side; on a map
//! coarser than a third of `R` (0.087-0.1 m scans against 0.15 m) that hides what the
//! test needs. There the map is cut finer (each voxel's cube into `scale^3`, to a third
//! of `R` or less) over a box around the route's narrowest point, the box counted free
//! outside, which only opens voxels; a voxel in the box is blocked when every one of
//! its fine voxels is ([`LinkFlood::new`]).
//!
//! # The flood
//! Only a route that crosses link-blocked voxels can be cut; the head route is checked
//! first (a route whose every voxel holds a link joins start and goal). Then the
//! voxels that may hold a link are flooded from both ends at once, in cells of about
//! a third of `R` (a cell is open when one of its voxels is; a cut thinner than a
//! cell only goes unseen), one cell from each side in turn, testing each as it is
//! reached: the side that runs out first is the proof (its size is reported); the
//! sides meeting means no proof. The flood stays in the grid (unit centres lie inside
//! the map's box).

use std::collections::VecDeque;
use std::time::Instant;

use nalgebra::Point3;

use crate::map::distance::{cube_distance_bound, DistanceField};
use crate::map::grid::{Cell, Grid};
use crate::planner::expired;
use crate::planner::numeric::{TIE, TINY};

/// Relative allowance for the field's rounding to `f32` (and of `r G` in `f64`).
const ROUND_REL: f64 = 1e-6;

/// Voxels of a refined cut, and cells of the flood, per unit radius: a voxel a third
/// of the radius or less loses at most `r sqrt(3) / 2` of it, which leaves the margins
/// the rule needs.
const CUTS_PER_RADIUS: f64 = 3.0;

/// Compass sectors of [`spread`] (a power of two: their order is bit-reversed).
const SECTORS: u8 = 16;

/// What the flood proved: the side whose region ran out, and the stretch of the head
/// route where no unit holds a link.
#[derive(Clone, Debug, PartialEq)]
pub struct LinkProof {
    /// "start" or "goal": whose region for a unit holding a link was measured whole.
    pub side: &'static str,
    /// Its size (flood cells).
    pub cells: u64,
    /// The cells' edge (m).
    pub cell_m: f64,
    /// First and last point of the head route in link-blocked voxels.
    pub stretch: (Point3<f64>, Point3<f64>),
}

/// The chain's measures the proof needs.
#[derive(Clone, Copy, Debug)]
pub struct LinkRule {
    /// Link length `l` (m).
    pub link: f64,
    /// Largest link pitch (rad).
    pub theta_max: f64,
    /// `r_u` plus the smallest clearance and the forward kinematics' tolerance: the
    /// least the planner's checks keep a unit's centre from the map (m).
    pub radius: f64,
}

/// The test CLOSED at one resolution (see the module docs): WITHIN's threshold and
/// the stencil.
#[derive(Clone, Debug)]
struct Closure {
    /// A stored bound below this proves `n <= n*`.
    below: f64,
    /// A stored bound above this (`R + l`) proves a voxel open: a unit at its centre and
    /// one a link away in any level direction are both free.
    open_above: f64,
    /// Made when first asked: with the planner for its map, at the first voxel the
    /// bound above cannot settle for a refined one (open space needs none).
    stencil: std::sync::OnceLock<Vec<[i32; 3]>>,
    r: f64,
    rule: LinkRule,
}

impl Closure {
    fn new(r: f64, rule: &LinkRule) -> Self {
        let n_star = ((rule.radius - TIE) / r).powi(2).floor().max(-1.0);
        let below = if n_star < 0.0 {
            0.0
        } else {
            r * cube_distance_bound(n_star as u64 + 1) * (1.0 - ROUND_REL)
        };
        Self {
            below,
            open_above: rule.radius + rule.link,
            stencil: std::sync::OnceLock::new(),
            r,
            rule: *rule,
        }
    }

    /// Every point of voxel `i` of `field` lies within the radius of an obstacle cube.
    /// Outside the grid, only where unknown space is occupied (it is an obstacle there).
    fn within(&self, field: &DistanceField, i: [i32; 3]) -> bool {
        let g = field.grid();
        match g.local(i) {
            Some(_) => field.voxel_clearance(i) < self.below,
            None => g.unknown_is_occupied(),
        }
    }

    /// The stencil, made at the first call.
    fn stencil(&self) -> &[[i32; 3]] {
        self.stencil.get_or_init(|| stencil(self.r, &self.rule))
    }

    /// No point of voxel `i` of `field` holds a unit with its link.
    fn closed(&self, field: &DistanceField, i: [i32; 3]) -> bool {
        if field.grid().local(i).is_some() && field.voxel_clearance(i) > self.open_above {
            return false;
        }
        self.within(field, i)
            || self
                .stencil()
                .iter()
                .all(|k| self.within(field, [i[0] + k[0], i[1] + k[1], i[2] + k[2]]))
    }
}

/// The map `scale` times finer over a box of its voxels (lattice indices `lo..hi`),
/// where a voxel is coarse against the radius: each voxel's obstacle is the same cube
/// cut into `scale^3`, and outside the box counts as free (which only opens voxels).
struct Fine {
    field: DistanceField,
    closure: Closure,
    scale: i32,
    lo: [i32; 3],
    hi: [i32; 3],
}

impl Fine {
    /// The box of `half` m around `at`, within `field`'s grid; `None` where it is empty.
    fn around(
        field: &DistanceField,
        rule: &LinkRule,
        scale: i32,
        at: [f64; 3],
        half: f64,
    ) -> Option<Self> {
        let g = field.grid();
        let (o, dims) = (g.origin(), g.dims());
        let lo = g.lattice_index(at.map(|c| c - half));
        let hi = g.lattice_index(at.map(|c| c + half));
        let lo = [0, 1, 2].map(|a| lo[a].max(o[a]));
        let hi = [0, 1, 2].map(|a| (hi[a] + 1).min(o[a] + dims[a] as i32));
        if (0..3).any(|a| lo[a] >= hi[a]) {
            return None;
        }
        let r = g.resolution() / f64::from(scale);
        let fine_dims = [0, 1, 2].map(|a| ((hi[a] - lo[a]) * scale) as usize);
        let mut fine = Grid::new(r, lo.map(|c| c * scale), fine_dims, Cell::Free, false).ok()?;
        for z in lo[2]..hi[2] {
            for y in lo[1]..hi[1] {
                for x in lo[0]..hi[0] {
                    if g.is_obstacle([x, y, z]) {
                        for j in finer([x, y, z], scale) {
                            fine.set(j, Cell::Occupied);
                        }
                    }
                }
            }
        }
        Some(Self {
            field: DistanceField::new(fine),
            closure: Closure::new(r, rule),
            scale,
            lo,
            hi,
        })
    }

    fn covers(&self, i: [i32; 3]) -> bool {
        (0..3).all(|a| (self.lo[a]..self.hi[a]).contains(&i[a]))
    }

    /// Every fine voxel of coarse voxel `i` is closed.
    fn closed(&self, i: [i32; 3]) -> bool {
        finer(i, self.scale).all(|j| self.closure.closed(&self.field, j))
    }
}

/// The `scale^3` voxels, `scale` times finer, that voxel `i` is cut into.
fn finer(i: [i32; 3], scale: i32) -> impl Iterator<Item = [i32; 3]> {
    (0..scale.pow(3)).map(move |k| {
        let d = [k % scale, (k / scale) % scale, k / (scale * scale)];
        [0, 1, 2].map(|a| i[a] * scale + d[a])
    })
}

/// The voxel offsets a unit's neighbour may lie in, level links first.
fn stencil(r: f64, rule: &LinkRule) -> Vec<[i32; 3]> {
    // A hair wider than the rule: the chain's own measures are `f32`.
    let (l, h) = (rule.link, rule.link * rule.theta_max.sin() + TINY);
    let m = (l / r).ceil() as i32 + 2;
    let mut out = Vec::new();
    for z in -m..=m {
        for y in -m..=m {
            for x in -m..=m {
                let k = [x, y, z];
                // The offset's cube grown by a voxel: `[k r - r, k r + r]` per axis,
                // clipped to the zone's heights.
                let lo = k.map(|c| (c - 1) as f64 * r);
                let hi = k.map(|c| (c + 1) as f64 * r);
                let (zlo, zhi) = (lo[2].max(-h), hi[2].min(h));
                if zlo > zhi {
                    continue;
                }
                let (lo, hi) = ([lo[0], lo[1], zlo], [hi[0], hi[1], zhi]);
                let near: f64 = (0..3)
                    .map(|a| (lo[a].max(0.0) - hi[a].min(0.0)).max(0.0).powi(2))
                    .sum::<f64>()
                    .sqrt();
                let far: f64 = (0..3)
                    .map(|a| lo[a].abs().max(hi[a].abs()).powi(2))
                    .sum::<f64>()
                    .sqrt();
                if near <= l + TINY && far >= l - TINY {
                    out.push(k);
                }
            }
        }
    }
    // Level links first; among them, directions spread round the compass early.
    out.sort_by_cached_key(|k| (k[2].abs(), spread(k), k[0].abs() + k[1].abs()));
    out
}

/// A key that interleaves compass directions: sixteen sectors in bit-reversed order.
fn spread(k: &[i32; 3]) -> u8 {
    let a = (k[1] as f64).atan2(k[0] as f64);
    let turn = (a + std::f64::consts::PI) / std::f64::consts::TAU;
    let sector = ((turn * SECTORS as f64) as u8).min(SECTORS - 1);
    sector.reverse_bits() >> (8 - SECTORS.trailing_zeros())
}

/// Most voxels a link may span for the rule to be asked: its stencil holds about
/// `27 (l / r)^2` offsets, made from `(2 l / r)^3` candidates and scanned for every
/// voxel it tests, so a map finer than this (4 mm voxels for a 0.5 m link) would pay
/// more for the proof than it saves.
pub const MAX_LINK_VOXELS: f64 = 128.0;

/// The rule for one map's resolution and one chain, made once for all queries.
#[derive(Clone, Debug)]
pub struct LinkCheck {
    rule: LinkRule,
    /// Whether the map is coarse enough for the rule ([`MAX_LINK_VOXELS`]).
    asked: bool,
    closure: Closure,
    /// How many times finer the map is cut where it is refined (1: never).
    scale: i32,
    /// Voxels per edge of the flood's cells.
    cell: usize,
}

impl LinkCheck {
    /// The chain's measures it was made for.
    pub fn rule(&self) -> &LinkRule {
        &self.rule
    }

    /// The rule at resolution `r` (m). Where a voxel is coarser than a third of the
    /// radius (its extent would hide the margins the rule needs), a refined flood cuts
    /// the map finer, to a third of the radius or less ([`LinkFlood::new`]). The flood
    /// runs in cells of about a third of the radius too: its cost follows the cells,
    /// and a cut thinner than a cell only goes unseen. On a map finer than
    /// [`MAX_LINK_VOXELS`] voxels a link, the rule is not asked.
    pub fn new(r: f64, rule: LinkRule) -> Self {
        let closure = Closure::new(r, &rule);
        let asked = rule.link / r <= MAX_LINK_VOXELS;
        if asked {
            closure.stencil();
        }
        Self {
            rule,
            asked,
            closure,
            scale: (CUTS_PER_RADIUS * r / rule.radius - TIE).ceil().max(1.0) as i32,
            cell: ((rule.radius / (CUTS_PER_RADIUS * r)).floor() as usize).max(1),
        }
    }
}

/// The proof for one field and chain ([`Self::separated`]).
pub struct LinkFlood<'a> {
    field: &'a DistanceField,
    check: &'a LinkCheck,
    /// Where the map may be cut finer: the head route's narrowest point, where its
    /// voxels are coarse against the radius.
    refine_at: Option<[f64; 3]>,
    /// The finer map, made at the first voxel that needs it ([`Self::fine`]).
    fine: std::cell::OnceCell<Option<Fine>>,
}

impl<'a> LinkFlood<'a> {
    /// The flood over `field` (at `check`'s resolution). With `refine_at` (the head
    /// route's narrowest point), where the voxels are coarse against the radius, the map
    /// is cut finer over the box around it that holds every voxel a unit within a link
    /// and a radius of it, and its link's other end, can touch (a cut across a
    /// passage lies about that near its narrowest point).
    pub fn new(
        field: &'a DistanceField,
        check: &'a LinkCheck,
        refine_at: Option<[f64; 3]>,
    ) -> Self {
        Self {
            field,
            check,
            refine_at: refine_at.filter(|_| check.scale > 1),
            fine: std::cell::OnceCell::new(),
        }
    }

    /// The finer map where it covers voxel `i` and could close it. A voxel whose centre
    /// keeps more than `R + l` and its half diagonal from the map holds a unit with a
    /// level link at every point, however finely cut: the map is cut (a distance field
    /// over the box) only when a voxel nearer the map asks.
    fn fine(&self, i: [i32; 3]) -> Option<&Fine> {
        let at = self.refine_at?;
        let g = self.field.grid();
        let r = g.resolution();
        let rule = &self.check.rule;
        let far = rule.radius + rule.link + r * 3f64.sqrt() / 2.0;
        if g.local(i).is_some() && self.field.voxel_clearance(i) > far {
            return None;
        }
        let half = 2.0 * (rule.link + rule.radius) + 2.0 * r;
        self.fine
            .get_or_init(|| Fine::around(self.field, rule, self.check.scale, at, half))
            .as_ref()
            .filter(|f| f.covers(i))
    }

    /// No point of voxel `i` holds a unit with its link (see the module docs).
    pub fn blocked(&self, i: [i32; 3]) -> bool {
        self.check.closure.closed(self.field, i) || self.fine(i).is_some_and(|f| f.closed(i))
    }

    /// No unit with its link holds the point `p`: its voxel is closed, or where the
    /// map is finer there, its fine voxel.
    fn blocked_at(&self, p: Point3<f64>) -> bool {
        let i = self.field.grid().lattice_index(p);
        self.check.closure.closed(self.field, i)
            || self
                .fine(i)
                .is_some_and(|f| f.closure.closed(&f.field, f.field.grid().lattice_index(p)))
    }

    /// The stretch of `route` (sampled every half voxel) in link-blocked voxels: its
    /// first and last sample there; `None` where every sample holds a link.
    fn blocked_stretch(&self, route: &[[f64; 3]]) -> Option<(Point3<f64>, Point3<f64>)> {
        let g = self.field.grid();
        let step = g.resolution() / 2.0;
        let mut stretch: Option<(Point3<f64>, Point3<f64>)> = None;
        for w in route.windows(2) {
            let (a, b) = (Point3::from(w[0]), Point3::from(w[1]));
            let n = ((b - a).norm() / step).ceil().max(1.0) as usize;
            for s in 0..=n {
                let p = a + (b - a) * (s as f64 / n as f64);
                if self.blocked_at(p) {
                    stretch = Some(stretch.map_or((p, p), |(first, _)| (first, p)));
                }
            }
        }
        stretch
    }

    /// Proves that no unit holding a link gets from `start` to within `tol` of `goal`,
    /// where the head `route` crosses link-blocked voxels; `None` where it does not,
    /// where the flood's sides meet, or when `deadline` passes.
    pub fn separated(
        &self,
        route: &[[f64; 3]],
        goal: [f64; 3],
        tol: f64,
        deadline: Option<Instant>,
    ) -> Option<LinkProof> {
        if !self.check.asked {
            return None;
        }
        let stretch = self.blocked_stretch(route)?;
        let g = self.field.grid();
        let start = g.lattice_index(*route.first()?);
        if self.blocked(start) {
            return None;
        }
        let mut flood = Flood::new(g.dims().map(|d| d.div_ceil(self.check.cell)))?;
        flood.seed(Side::Start, self.cell_of(g.local(start)?));
        for v in self.near_goal(goal, tol) {
            let c = self.cell_of(v);
            let state = flood.state(c);
            let asked = state == UNSEEN || state == Side::Start as u8;
            if asked && !self.blocked(g.index_of_local(v)) {
                if state == UNSEEN {
                    flood.seed(Side::Goal, c);
                } else {
                    // The goal's voxel is in the start's cell: nothing to cut.
                    return None;
                }
            }
        }
        let mut turn = 0usize;
        while !flood.empty(Side::Start) && !flood.empty(Side::Goal) {
            turn += 1;
            if turn.is_multiple_of(4096) && expired(deadline) {
                return None;
            }
            for side in [Side::Start, Side::Goal] {
                if self.expand(&mut flood, side) {
                    return None;
                }
            }
        }
        let side = if flood.empty(Side::Start) {
            Side::Start
        } else {
            Side::Goal
        };
        Some(LinkProof {
            side: side.name(),
            cells: flood.size[side as usize - 1],
            cell_m: self.check.cell as f64 * g.resolution(),
            stretch,
        })
    }

    /// The flood's cell holding local voxel `v`.
    fn cell_of(&self, v: [usize; 3]) -> [usize; 3] {
        v.map(|c| c / self.check.cell)
    }

    /// Some voxel of cell `c` may hold a unit with its link.
    fn passable(&self, c: [usize; 3]) -> bool {
        let g = self.field.grid();
        let dims = g.dims();
        let span = |a: usize| c[a] * self.check.cell..((c[a] + 1) * self.check.cell).min(dims[a]);
        span(2)
            .any(|z| span(1).any(|y| span(0).any(|x| !self.blocked(g.index_of_local([x, y, z])))))
    }

    /// Grid voxels (local) whose cube lies within `tol` of `goal`.
    fn near_goal(&self, goal: [f64; 3], tol: f64) -> Vec<[usize; 3]> {
        let g = self.field.grid();
        let r = g.resolution();
        let lo = g.lattice_index([goal[0] - tol, goal[1] - tol, goal[2] - tol]);
        let hi = g.lattice_index([goal[0] + tol, goal[1] + tol, goal[2] + tol]);
        let mut out = Vec::new();
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                for x in lo[0]..=hi[0] {
                    let c = g.voxel_center([x, y, z]);
                    let gap: f64 = (0..3)
                        .map(|a| ((c[a] - goal[a]).abs() - r / 2.0).max(0.0).powi(2))
                        .sum::<f64>()
                        .sqrt();
                    if let (true, Some(l)) = (gap <= tol, g.local([x, y, z])) {
                        out.push(l);
                    }
                }
            }
        }
        out
    }

    /// Takes one cell off `side`'s queue and adds its 26 neighbours that may hold a
    /// unit with its link; `true` where one belongs to the other side (the sides meet).
    fn expand(&self, flood: &mut Flood, side: Side) -> bool {
        let Some(v) = flood.pop(side) else {
            return false;
        };
        let dims = flood.dims;
        for dz in -1i64..=1 {
            for dy in -1i64..=1 {
                for dx in -1i64..=1 {
                    let n = [v[0] as i64 + dx, v[1] as i64 + dy, v[2] as i64 + dz];
                    if (0..3).any(|a| n[a] < 0 || n[a] >= dims[a] as i64) {
                        continue;
                    }
                    let n = n.map(|c| c as usize);
                    match flood.state(n) {
                        UNSEEN => {
                            if self.passable(n) {
                                flood.seed(side, n);
                            } else {
                                flood.set(n, BLOCKED);
                            }
                        }
                        s if s == side.other() as u8 => return true,
                        _ => {}
                    }
                }
            }
        }
        false
    }
}

/// Which end a flooded voxel was reached from.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Side {
    Start = 1,
    Goal = 2,
}

impl Side {
    fn other(self) -> Side {
        match self {
            Side::Start => Side::Goal,
            Side::Goal => Side::Start,
        }
    }

    fn name(self) -> &'static str {
        match self {
            Side::Start => "start",
            Side::Goal => "goal",
        }
    }
}

const UNSEEN: u8 = 0;
const BLOCKED: u8 = 3;

/// Two bits a cell (unseen, a side, link-blocked) and each side's queue of cells (by
/// linear index: four bytes a cell, where a queue may hold much of a large map).
struct Flood {
    dims: [usize; 3],
    bits: Vec<u64>,
    queue: [VecDeque<u32>; 2],
    size: [u64; 2],
}

impl Flood {
    /// A flood over `dims` cells; `None` beyond four-byte indices.
    fn new(dims: [usize; 3]) -> Option<Self> {
        let n = dims.iter().product::<usize>();
        if n > u32::MAX as usize {
            return None;
        }
        Some(Self {
            dims,
            bits: vec![0; n.div_ceil(32)],
            queue: [VecDeque::new(), VecDeque::new()],
            size: [0; 2],
        })
    }

    fn linear(&self, l: [usize; 3]) -> usize {
        l[0] + self.dims[0] * (l[1] + self.dims[1] * l[2])
    }

    fn slot(&self, l: [usize; 3]) -> (usize, u32) {
        let k = self.linear(l);
        (k / 32, (k % 32) as u32 * 2)
    }

    fn state(&self, l: [usize; 3]) -> u8 {
        let (w, s) = self.slot(l);
        ((self.bits[w] >> s) & 3) as u8
    }

    fn set(&mut self, l: [usize; 3], state: u8) {
        let (w, s) = self.slot(l);
        self.bits[w] = (self.bits[w] & !(3 << s)) | (u64::from(state) << s);
    }

    fn seed(&mut self, side: Side, l: [usize; 3]) {
        self.set(l, side as u8);
        let k = self.linear(l) as u32;
        self.queue[side as usize - 1].push_back(k);
        self.size[side as usize - 1] += 1;
    }

    fn pop(&mut self, side: Side) -> Option<[usize; 3]> {
        let k = self.queue[side as usize - 1].pop_front()? as usize;
        let (x, yz) = (k % self.dims[0], k / self.dims[0]);
        Some([x, yz % self.dims[1], yz / self.dims[1]])
    }

    fn empty(&self, side: Side) -> bool {
        self.queue[side as usize - 1].is_empty()
    }
}

#[cfg(test)]
#[path = "linked_tests.rs"]
mod tests;
