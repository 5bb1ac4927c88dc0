//! A coarse distance-to-goal that guides the lattice A* around walls.
//!
//! With the straight-line distance as its heuristic, the A* floods every "basin" that
//! faces the goal across a wall: a 6 m x 19 m x 10 m room whose door is on the far
//! side costs hundreds of thousands of expansions. Here a Dijkstra search from the goal
//! over a COARSE grid of blocks (edge `b` >= 0.4 m, at most about 250 000 blocks
//! over the map's box) gives each block its distance to the goal around the walls the
//! coarse grid sees, and the A* uses that distance as its heuristic.
//!
//! A block is passable when the distance field proves its centre free for the head's
//! sphere. Neighbouring centres are `b` to `b sqrt(3)` apart, so the coarse grid cannot
//! step through an axis-aligned wall (two centres that keep the sphere's radius on both
//! sides of a wall are at least `2 r_u` plus the wall apart across it), but it misses
//! openings narrower than about `b` plus the sphere: through those, the guide knows no
//! way and the A* falls back on what it knows (below). The guide is a heuristic only:
//! it never decides whether a route exists, and every route is still the lattice's.
//!
//! The Dijkstra stops as soon as the blocks around the start are settled; a block not
//! settled then is at least that far from the goal. Where a block is not passable (next
//! to walls, in doors), the best of its neighbours stands in for it.

use super::{dist, HeadLattice};
use crate::map::distance::DistanceField;

/// Smallest block edge (m).
const MIN_BLOCK: f64 = 0.4;
/// Most blocks over the map's box (the block edge grows to stay below).
const MAX_BLOCKS: f64 = 250_000.0;
/// Step costs are counted in eighths of a block.
const EIGHTHS: f64 = 8.0;
/// Buckets of the queue: more than the longest step's cost.
const BUCKETS: usize = 16;

/// Coarse distances to one goal.
pub(super) struct Guide {
    lo: [f64; 3],
    b: f64,
    n: [usize; 3],
    /// Distance to the goal per block (m); infinite where not settled or blocked.
    dist: Vec<f32>,
    /// The Dijkstra's radius when it stopped: every unsettled block is this far at least.
    reach: f64,
    goal: [f64; 3],
}

impl Guide {
    /// The coarse distances from `goal` over `field`'s box, for the sphere of radius
    /// `radius`, searched until the blocks around `start` are settled.
    pub(super) fn new(
        lat: &HeadLattice,
        field: &DistanceField,
        start: [f64; 3],
        goal: [f64; 3],
    ) -> Self {
        let (lo, hi) = (lat.lo, lat.hi);
        let volume: f64 = (0..3).map(|a| hi[a] - lo[a]).product();
        let b = MIN_BLOCK.max((volume / MAX_BLOCKS).cbrt());
        let n = [0, 1, 2].map(|a| (((hi[a] - lo[a]) / b).ceil() as usize).max(1));
        let mut guide = Self {
            lo,
            b,
            n,
            dist: vec![f32::INFINITY; n[0] * n[1] * n[2]],
            reach: 0.0,
            goal,
        };
        guide.search(lat, field, start);
        guide
    }

    fn block_of(&self, p: [f64; 3]) -> [usize; 3] {
        [0, 1, 2]
            .map(|a| (((p[a] - self.lo[a]) / self.b).floor().max(0.0) as usize).min(self.n[a] - 1))
    }

    fn index(&self, i: [usize; 3]) -> usize {
        i[0] + self.n[0] * (i[1] + self.n[1] * i[2])
    }

    fn centre(&self, i: [usize; 3]) -> [f64; 3] {
        [0, 1, 2].map(|a| self.lo[a] + (i[a] as f64 + 0.5) * self.b)
    }

    /// The 26 steps to neighbouring blocks and their costs (eighths of a block).
    fn steps(&self) -> Vec<([isize; 3], u32)> {
        (0..27)
            .filter(|&c| c != 13)
            .map(|c| {
                let o = [c % 3, (c / 3) % 3, c / 9].map(|v| v as isize - 1);
                let len = [0, 8, 11, 13][(o[0].abs() + o[1].abs() + o[2].abs()) as usize];
                (o, len)
            })
            .collect()
    }

    fn unindex(&self, k: usize) -> [usize; 3] {
        [
            k % self.n[0],
            (k / self.n[0]) % self.n[1],
            k / (self.n[0] * self.n[1]),
        ]
    }

    /// The 27 blocks around `i` (itself included) inside the grid.
    fn around(&self, i: [usize; 3]) -> impl Iterator<Item = [usize; 3]> + '_ {
        (0..27).filter_map(move |c| {
            let o = [c % 3, (c / 3) % 3, c / 9].map(|v| v as i64 - 1);
            let j = [0, 1, 2].map(|a| i[a] as i64 + o[a]);
            (0..3)
                .all(|a| j[a] >= 0 && j[a] < self.n[a] as i64)
                .then(|| j.map(|v| v as usize))
        })
    }

    /// Dijkstra from the goal's blocks until every passable block around the start is
    /// settled (or nothing is left), with a bucket queue: steps cost 8, 11 or 13
    /// eighths of a block (the axis, face and space diagonals, rounded down), so every
    /// bucket is settled in order and no heap is needed.
    fn search(&mut self, lat: &HeadLattice, field: &DistanceField, start: [f64; 3]) {
        let mut passable = vec![0u8; self.dist.len()]; // 0 unknown, 1 yes, 2 no
        let mut is_passable = |g: &Self, k: usize| {
            if passable[k] == 0 {
                let c = g.centre(g.unindex(k));
                let free = lat.inside(c) && field.clearance(c) > lat.r_min;
                passable[k] = if free { 1 } else { 2 };
            }
            passable[k] == 1
        };
        let mut cost = vec![u32::MAX; self.dist.len()];
        let mut buckets: Vec<Vec<u32>> = vec![Vec::new(); BUCKETS];
        let goal_block = self.block_of(self.goal);
        let mut queued = 0usize;
        for j in self.around(goal_block).collect::<Vec<_>>() {
            let k = self.index(j);
            if is_passable(self, k) {
                let c = (dist(self.centre(j), self.goal) / self.b * EIGHTHS) as u32;
                cost[k] = c;
                buckets[c as usize % BUCKETS].push(k as u32);
                queued += 1;
            }
        }
        let targets: Vec<usize> = self
            .around(self.block_of(start))
            .map(|j| self.index(j))
            .collect::<Vec<_>>()
            .into_iter()
            .filter(|&k| is_passable(self, k))
            .collect();
        let mut remaining = targets.len();
        let steps = self.steps();
        let mut level = cost.iter().copied().min().unwrap_or(0);
        let mut settled = vec![false; self.dist.len()];
        'outer: while queued > 0 {
            let bucket = std::mem::take(&mut buckets[level as usize % BUCKETS]);
            for k in bucket {
                queued -= 1;
                let k = k as usize;
                if settled[k] || cost[k] != level {
                    continue;
                }
                settled[k] = true;
                self.dist[k] = level as f32 / EIGHTHS as f32 * self.b as f32;
                self.reach = self.dist[k] as f64;
                if targets.contains(&k) {
                    remaining -= 1;
                    if remaining == 0 {
                        break 'outer;
                    }
                }
                let i = self.unindex(k);
                for &(o, len) in &steps {
                    let j = [0, 1, 2].map(|a| i[a].wrapping_add_signed(o[a]));
                    if (0..3).any(|a| j[a] >= self.n[a]) {
                        continue;
                    }
                    let kj = self.index(j);
                    let nc = level + len;
                    if settled[kj] || nc >= cost[kj] || !is_passable(self, kj) {
                        continue;
                    }
                    cost[kj] = nc;
                    buckets[nc as usize % BUCKETS].push(kj as u32);
                    queued += 1;
                }
            }
            level += 1;
        }
    }

    /// The heuristic at `p`: its block's distance to the goal (or the best of the
    /// neighbouring blocks' where its own is not known) less the slack of a block,
    /// never below the straight-line distance.
    pub(super) fn estimate(&self, p: [f64; 3]) -> f64 {
        let straight = dist(p, self.goal);
        let i = self.block_of(p);
        let own = self.dist[self.index(i)];
        let coarse = if own.is_finite() {
            own as f64
        } else {
            let best = self
                .around(i)
                .map(|j| self.dist[self.index(j)])
                .fold(f32::INFINITY, f32::min);
            if best.is_finite() {
                best as f64
            } else {
                self.reach
            }
        };
        straight.max(coarse - self.b * 3f64.sqrt())
    }
}
