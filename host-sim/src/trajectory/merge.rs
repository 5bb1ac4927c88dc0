//! Merged edges: a translation and the shape change beside it flown at once, as one
//! straight move in `zeta` (head and shape together), where that is admissible.
//!
//! A shape change limited by the angular rate leaves most of the speed budget unused,
//! and a translation uses none of the angular budget: flown together they take
//! `max((len + w) / speed, max_angle / angular_rate)` instead of the sum of both, where
//! `len` is the head's travel and `w` the fastest any unit moves per unit of the shape
//! change's progress (a unit's velocity is the head's plus the shape's part, so its
//! speed is at most `r (len + w)` at rate `r`). `w` is measured along the shape change
//! and made an upper bound by the largest change of velocity between measurements.

use super::build::max_angle;
use crate::collision::exact::positions_f64;
use crate::sim::reference::{Segment, SegmentKind};
use crate::sim::ReferenceLimits;

/// Measurements along a shape change for its fastest unit.
const SPEED_SAMPLES: usize = 128;

/// What the rate of an edge depends on.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Demand {
    /// Head travel (m).
    len: f64,
    /// Upper bound on the fastest unit's speed from the shape part, per unit progress (m).
    sweep: f64,
    /// Largest change of any angle (rad).
    angle: f64,
}

impl Demand {
    /// The demand of one edge of a chain with links of length `l`.
    pub(super) fn of(e: &Segment, l: f64) -> Self {
        let d = &e.delta;
        Self {
            len: (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt(),
            sweep: match e.kind {
                SegmentKind::ShapeChange => shape_speed(l, &e.from[3..], &d[3..]),
                _ => 0.0,
            },
            angle: max_angle(d),
        }
    }

    /// Two edges at once.
    fn plus(self, o: Self) -> Self {
        Self {
            len: self.len + o.len,
            sweep: self.sweep + o.sweep,
            angle: self.angle.max(o.angle),
        }
    }

    /// The largest rate of progress within the speed and angular-rate limits.
    pub(super) fn max_rate(&self, lim: &ReferenceLimits) -> f64 {
        let mut r = f64::INFINITY;
        if self.len + self.sweep > 0.0 {
            r = r.min(lim.speed / (self.len + self.sweep));
        }
        if self.angle > 0.0 {
            r = r.min(lim.angular_rate / self.angle);
        }
        r
    }
}

/// An upper bound on the speed of any unit, per unit of progress, while the shape moves
/// linearly from `eta` by `d_eta` with the head fixed: the largest chord speed between
/// `SPEED_SAMPLES` measurements, plus the most a velocity can change between two of them
/// (a link direction's second derivative is at most `(|dtheta| + |dpsi|)^2`); never more
/// than the bound `l * sum_k sqrt(dtheta_k^2 + dpsi_k^2)`.
pub(super) fn shape_speed(l: f64, eta: &[f64], d_eta: &[f64]) -> f64 {
    let links = (eta.len() - 1) / 2;
    let at = |s: f64| {
        let e: Vec<f64> = eta.iter().zip(d_eta).map(|(a, d)| a + s * d).collect();
        positions_f64(l, [0.0; 3], &e)
    };
    let n = SPEED_SAMPLES as f64;
    let mut best = 0.0f64;
    let mut before = at(0.0);
    for j in 1..=SPEED_SAMPLES {
        let now = at(j as f64 / n);
        for (p, q) in before.iter().zip(&now) {
            let v = ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt();
            best = best.max(v * n);
        }
        before = now;
    }
    let (mut curve, mut bound) = (0.0, 0.0);
    for k in 0..links {
        let (dt, dp) = (d_eta[1 + 2 * k], d_eta[2 + 2 * k]);
        curve += (dt.abs() + dp.abs()).powi(2);
        bound += (dt * dt + dp * dp).sqrt();
    }
    (best + l * curve / n).min(l * bound)
}

/// The edges with merged pairs joined: each motion, and the edge it starts with.
/// `merged[k]`: edge `k` is flown together with edge `k - 1`.
pub(super) fn assemble(
    edges: &[Segment],
    demands: &[Demand],
    merged: &[bool],
    lim: &ReferenceLimits,
) -> (Vec<Segment>, Vec<usize>, Vec<f64>) {
    let (mut motions, mut firsts, mut rates) = (Vec::new(), Vec::new(), Vec::new());
    let mut k = 0;
    while k < edges.len() {
        let mut e = edges[k].clone();
        let mut demand = demands[k];
        if k + 1 < edges.len() && merged[k + 1] {
            e.delta
                .iter_mut()
                .zip(&edges[k + 1].delta)
                .for_each(|(a, b)| *a += b);
            e.kind = SegmentKind::ShapeChange;
            e.to_waypoint = edges[k + 1].to_waypoint;
            demand = demand.plus(demands[k + 1]);
        }
        motions.push(e);
        firsts.push(k);
        rates.push(demand.max_rate(lim));
        k += if k + 1 < edges.len() && merged[k + 1] {
            2
        } else {
            1
        };
    }
    (motions, firsts, rates)
}

/// The pairs worth trying, left to right: a translation next to a shape change, each
/// edge in at most one pair.
pub(super) fn candidates(edges: &[Segment], on: bool) -> Vec<bool> {
    let mut merged = vec![false; edges.len()];
    if !on {
        return merged;
    }
    for k in 1..edges.len() {
        let pair = (edges[k - 1].kind, edges[k].kind);
        let mixed = matches!(
            pair,
            (SegmentKind::Translation, SegmentKind::ShapeChange)
                | (SegmentKind::ShapeChange, SegmentKind::Translation)
        );
        if mixed && !merged[k - 1] {
            merged[k] = true;
        }
    }
    merged
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shape_speed_bounds_every_unit_and_is_tight_for_a_rotation() {
        // The whole chain turned about the head: the tail (3 links out) moves 3 l per
        // radian, and the bound says so.
        let (l, eta, d) = (0.5, [0.0; 7], [0.5, 0.0, 0.5, 0.0, 0.5, 0.0, 0.5]);
        let w = shape_speed(l, &eta, &d);
        assert!(
            w >= 3.0 * l * 0.5 - 1e-12 && w <= 3.0 * l * 0.5 * 1.01,
            "{w}"
        );
        // Links turning against each other: the measured speed is well below the bound.
        let d = [0.0, 0.0, 0.6, 0.0, -0.6, 0.0, 0.6];
        let w = shape_speed(l, &eta, &d);
        assert!(w < 0.8 * l * 1.8, "{w}");
        // Fine measurement never under the truth.
        let fine = |s: f64| {
            positions_f64(
                l,
                [0.0; 3],
                &[0.0, 0.0, 0.6 * s, 0.0, -0.6 * s, 0.0, 0.6 * s],
            )
        };
        let h = 1e-6;
        for j in 0..1000 {
            let s = j as f64 / 1000.0;
            let (a, b) = (fine(s), fine(s + h));
            for (p, q) in a.iter().zip(&b) {
                let v = ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2))
                    .sqrt()
                    / h;
                assert!(v <= w + 1e-6);
            }
        }
    }
}
