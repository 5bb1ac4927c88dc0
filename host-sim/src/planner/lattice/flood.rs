//! Breadth-first floods over the unit lattice: beside the A*, they prove that start
//! and goal lie in separate free regions when one side's region runs out.

use std::collections::VecDeque;

use super::nodes::{Node, Nodes};
use super::HeadLattice;

/// A breadth-first flood over the unit lattice, one point per step.
pub(super) struct Flood {
    pub(super) queue: VecDeque<u64>,
    pub(super) count: usize,
    pub(super) active: bool,
    /// Record parents (the flood from the start, after the A*).
    parents: bool,
}

impl Flood {
    /// A flood from `seeds`, marking `flooded`.
    pub(super) fn new(nodes: &mut Nodes, seeds: &[u64], active: bool) -> Self {
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
    pub(super) fn new_mark(nodes: &mut Nodes, seeds: &[u64]) -> Self {
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
    pub(super) fn step(
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
