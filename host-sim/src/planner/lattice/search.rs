//! The A* over a strided sub-lattice from the start's anchors to the goal's, with
//! the floods ([`super::flood`]) that prove a failure.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use super::flood::Flood;
use super::guide::Guide;
use super::nodes::{KeySet, Nodes};
use super::{dist, HeadLattice};

/// Rounding allowance of a reach in lattice spacings (a ten-thousandth): a point at
/// exactly two strides is kept whatever the rounding of its coordinates. Not tuning.
const REACH_ROUNDING: f64 = 1.0001;

/// How one strided search ended.
pub(super) enum Search {
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

/// When a search gives up: lattice points touched, or the query's deadline.
pub(super) struct Limit {
    pub(super) budget: usize,
    pub(super) deadline: Option<std::time::Instant>,
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

/// Open-list entry, lowest `f` first (ties: the lower key).
#[derive(PartialEq)]
pub(super) struct Open {
    pub(super) f: f64,
    pub(super) k: u64,
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
pub(in crate::planner) fn offsets26() -> [[i64; 3]; 26] {
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

impl HeadLattice {
    /// Free points of the stride-`stride` sub-lattice near `p` (within two of its
    /// spacings), nearest first. Stride 2 is the lattice of voxel centres (odd indices).
    pub(super) fn anchors(&self, nodes: &mut Nodes, p: [f64; 3], stride: i64) -> Vec<u64> {
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
        let reach = 2.0 * stride as f64 * self.h * REACH_ROUNDING;
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

    /// One A* over the stride-`stride` sub-lattice, its heuristic `guide`'s. With
    /// stride 1, a flood from the goal runs beside it (one expansion each), and when
    /// the A* runs dry a flood from the start confirms it (the A* takes long steps in
    /// open space, so its running dry alone proves nothing): either flood exhausting
    /// its region without meeting the other side proves the two are separate.
    pub(super) fn search(
        &self,
        nodes: &mut Nodes,
        start: [f64; 3],
        goal: [f64; 3],
        stride: i64,
        limit: &Limit,
        guide: &Guide<'_>,
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
                    f: c + guide.heuristic(s, self.point(s)),
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
                return self.flood_from_start(nodes, (&starts, &goals), limit, expanded);
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
                    room.min(self.tuning.max_jump) as i64
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
                        f: ng + guide.heuristic(n, pn),
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

    /// After the stride-1 A* ran dry: a flood from the start confirms that the goal is
    /// in another region ([`Search::Separated`]), or finds the way the A*'s long steps
    /// missed.
    fn flood_from_start(
        &self,
        nodes: &mut Nodes,
        (starts, goals): (&[u64], &[u64]),
        limit: &Limit,
        expanded: usize,
    ) -> Search {
        let offs = offsets26();
        let mut from_start = Flood::new_mark(nodes, starts);
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
                // The long steps missed a way the flood found: take the flood's path.
                return Search::Found(self.path_to(nodes, g), expanded);
            }
            if limit.reached(nodes.map.len(), from_start.count) {
                return Search::Budget;
            }
        }
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
}
