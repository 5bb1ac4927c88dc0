//! A lattice path made a head route: points in narrow passages moved to the middle,
//! then the path pulled taut where the head's sphere can fly the segments.

use super::nodes::Nodes;
use super::{dist, norm, search::offsets26, sub, HeadLattice};
use crate::collision::point_clearance::exact_distance;
use crate::collision::CollisionContext;
use crate::planner::numeric::{DIV_GUARD, MILLIMETRE, TIE};
use crate::planner::plan_ops::farthest;

impl HeadLattice {
    /// Moves the path's points where it is narrower than the preferred radius across
    /// the path, up the exact clearance, to the middle of the passage (a few lattice
    /// steps at most): the A*'s cost leans that way, but a weighted A* stops at the
    /// first route it finds.
    pub(super) fn centre(&self, nodes: &mut Nodes, pts: &mut [[f64; 3]], clear: &mut [f64]) {
        let field = nodes.field;
        let cap = self.r_pref + self.tuning.centre_reach * self.h;
        let exact = |p: [f64; 3]| exact_distance(field, p.into(), cap);
        let offs = offsets26();
        for j in 1..pts.len().saturating_sub(1) {
            if clear[j] >= self.r_pref + 2.0 * self.h {
                continue;
            }
            let d = sub(pts[j + 1], pts[j - 1]);
            let dn = norm(d).max(DIV_GUARD);
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
                    if along.abs() > self.tuning.across {
                        continue;
                    }
                    let Some(n) = self.pack([i[0] + o[0], i[1] + o[1], i[2] + o[2]]) else {
                        continue;
                    };
                    if nodes.clear(n).is_none() {
                        continue;
                    }
                    let e = exact(self.point(n));
                    if e > best + TIE && next.is_none_or(|(_, b)| e > b) {
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

    /// Pulls a lattice path taut: from each kept point, the farthest later point that
    /// one segment reaches, where the head's sphere can fly the segment (conservative,
    /// at the smallest clearance) and the segment keeps at least the smallest clearance
    /// of the points it replaces (capped at the preferred radius plus `LatticeSettings::keep_cap`).
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
                .min(self.r_pref + self.tuning.keep_cap);
            if !ctx_min.is_head_segment_free(pts[i], pts[j]) {
                return false;
            }
            let len = dist(pts[i], pts[j]);
            let n = (len / self.h).ceil().max(1.0) as usize;
            (0..=n).all(|s| {
                let t = s as f64 / n as f64;
                let p = [0, 1, 2].map(|a| pts[i][a] + t * (pts[j][a] - pts[i][a]));
                field.clearance(p) + MILLIMETRE >= need
            })
        };
        let mut out = vec![pts[0]];
        let mut i = 0;
        let last = pts.len() - 1;
        while i < last {
            i = farthest(i, last, |j| ok(i, j)).expect("the next point is always reached");
            out.push(pts[i]);
        }
        out
    }
}
