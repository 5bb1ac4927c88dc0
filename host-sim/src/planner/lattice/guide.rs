//! A coarse distance-to-goal that guides the lattice A* around walls.
//!
//! With the straight-line distance as its heuristic, the A* floods every "basin" that
//! faces the goal across a wall: a 6 m x 19 m x 10 m room whose door is on the far
//! side costs hundreds of thousands of expansions. Here a Dijkstra search from the goal
//! over the coarse graph of the labelled regions ([`super::regions::CoarseGraph`]:
//! connected pieces of free space in blocks of 0.4 m or more, joined where their
//! voxels touch) gives each piece its distance to the goal around the walls, and its
//! next piece on the way there. The heuristic at a lattice point is the straight line
//! to the centre of its piece's next piece plus that piece's distance: it points
//! through the doors, and it is never below the straight line to the goal.
//!
//! The guide is a heuristic only: it never decides whether a route exists, and every
//! route is still the lattice's. The Dijkstra stops as soon as the pieces around the
//! start are settled. When it never reaches them (the relaxed voxels join what the
//! lattice keeps apart, or the anchors lie outside every piece), the guide steps
//! aside and the A* falls back on the straight-line distance.

use std::collections::BinaryHeap;

use super::regions::Regions;
use super::search::Open;
use super::{dist, HeadLattice};

/// Coarse distances to one goal.
pub(super) struct Guide<'a> {
    lat: &'a HeadLattice,
    /// The labelled regions (`None`: the straight-line guide, before they exist).
    regions: Option<&'a Regions>,
    /// Distance to the goal per node (m); infinite where not settled.
    dist: Vec<f32>,
    /// The next node towards the goal (`u32::MAX`: the goal itself is next).
    next: Vec<u32>,
    /// Whether the nodes around the start were reached.
    connected: bool,
    /// The Dijkstra's radius when it stopped: unsettled nodes are at least this far.
    reach: f64,
    goal: [f64; 3],
    /// What the A* multiplies the estimate by (the lattice's `heuristic_weight`).
    weight: f64,
}

impl<'a> Guide<'a> {
    /// The coarse distances from the goal's anchors (`goals`, lattice keys) until the
    /// start's (`starts`) are settled.
    pub(super) fn new(
        lat: &'a HeadLattice,
        regions: &'a Regions,
        starts: &[u64],
        goals: &[u64],
        goal: [f64; 3],
    ) -> Self {
        let nodes = regions.coarse().centre.len();
        let mut guide = Self {
            lat,
            regions: Some(regions),
            dist: vec![f32::INFINITY; nodes],
            next: vec![u32::MAX; nodes],
            connected: false,
            reach: 0.0,
            goal,
            weight: lat.tuning.heuristic_weight,
        };
        guide.search(starts, goals);
        guide
    }

    /// A guide that knows nothing but the straight line to `goal`.
    pub(super) fn straight(lat: &'a HeadLattice, goal: [f64; 3]) -> Self {
        Self {
            lat,
            regions: None,
            dist: Vec::new(),
            next: Vec::new(),
            connected: false,
            reach: 0.0,
            goal,
            weight: lat.tuning.heuristic_weight,
        }
    }

    /// The guide with the estimate weighted by `weight` instead.
    pub(super) fn weighted(mut self, weight: f64) -> Self {
        self.weight = weight;
        self
    }

    /// The A*'s heuristic at lattice point `k` (at `p`): the weighted estimate.
    pub(super) fn heuristic(&self, k: u64, p: [f64; 3]) -> f64 {
        self.weight * self.estimate(k, p)
    }

    fn node(&self, k: u64) -> Option<u32> {
        self.regions?.node_of(self.lat.voxel_of(k))
    }

    /// Dijkstra from the goal's nodes until every node of the start's anchors is
    /// settled (or nothing is left).
    fn search(&mut self, starts: &[u64], goals: &[u64]) {
        let Some(coarse) = self.regions.map(Regions::coarse) else {
            return;
        };
        let mut targets: Vec<u32> = starts.iter().filter_map(|&k| self.node(k)).collect();
        targets.sort_unstable();
        targets.dedup();
        if targets.is_empty() {
            return;
        }
        let mut cost = vec![f32::INFINITY; self.dist.len()];
        let mut heap = BinaryHeap::new();
        for &k in goals {
            if let Some(n) = self.node(k) {
                let d = dist(coarse.centre[n as usize], self.goal) as f32;
                if d < cost[n as usize] {
                    cost[n as usize] = d;
                    heap.push(Open {
                        f: d as f64,
                        k: n as u64,
                    });
                }
            }
        }
        let mut remaining = targets.len();
        while let Some(Open { f, k }) = heap.pop() {
            let (d, k) = (f as f32, k as usize);
            if self.dist[k].is_finite() {
                continue;
            }
            self.dist[k] = d;
            self.reach = d as f64;
            if targets.binary_search(&(k as u32)).is_ok() {
                remaining -= 1;
                if remaining == 0 {
                    self.connected = true;
                    return;
                }
            }
            let edges = coarse.edge_start[k] as usize..coarse.edge_start[k + 1] as usize;
            for &(j, len) in &coarse.edges[edges] {
                let nd = d + len;
                if self.dist[j as usize].is_infinite() && nd < cost[j as usize] {
                    cost[j as usize] = nd;
                    self.next[j as usize] = k as u32;
                    heap.push(Open {
                        f: nd as f64,
                        k: j as u64,
                    });
                }
            }
        }
    }

    /// The heuristic at lattice point `k` (position `p`): the straight line to the
    /// centre of the next node towards the goal plus that node's distance (or the
    /// straight line to the goal from a goal node), never below the straight line.
    pub(super) fn estimate(&self, k: u64, p: [f64; 3]) -> f64 {
        let straight = dist(p, self.goal);
        if !self.connected {
            return straight;
        }
        let Some(n) = self.node(k) else {
            return straight;
        };
        let n = n as usize;
        if self.dist[n].is_infinite() {
            return straight.max(self.reach);
        }
        let via = match self.next[n] {
            u32::MAX => straight,
            m => {
                let Some(regions) = self.regions else {
                    return straight;
                };
                let c = regions.coarse().centre[m as usize];
                dist(p, c) + self.dist[m as usize] as f64
            }
        };
        via.max(straight)
    }
}
