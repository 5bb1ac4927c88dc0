//! Merged edges: consecutive edges flown at once, as one straight move in `zeta` (head
//! and shape together), where that is admissible.
//!
//! A shape change limited by the angular rate leaves most of the speed budget unused,
//! and a translation uses none of the angular budget: flown together they take
//! `max(w / speed, angles)` instead of the sum of both, where `angles` is the largest
//! change of an angle over its rate limit (`reference::angle_demand`) and `w` is
//! the fastest any unit moves per unit of the merged motion's progress (head and shape
//! together), measured along the motion and made an upper bound by the largest change
//! of velocity between measurements.
//!
//! Two kinds of merge are tried: a *run*, many short edges whose waypoints lie within
//! `Settings::run_tolerance` of the straight move through them (follow-the-leader steps, a
//! chain bending around its head's track a little at a time: flown edge by edge, every
//! step would start and end a link's turn, and the ramps between such short edges
//! bring the chain almost to rest); and a *pair*, a translation with the shape change
//! beside it.

use crate::collision::exact::positions_f64;
use crate::trajectory::reference::{angle_demand, Segment, SegmentKind};
use crate::trajectory::ReferenceLimits;

/// Measurements along a shape change for its fastest unit.
///
/// Tuning left a constant: the bound adds the most a velocity can change between two
/// measurements, so it holds at any count; more measurements make it tighter (faster
/// merged shape changes) for time. `motion_speed` is shared with the demands' cache,
/// which holds no settings.
const SPEED_SAMPLES: usize = 128;

/// What the rate of a motion depends on.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Demand {
    /// Upper bound on the fastest unit's speed per unit of progress (m).
    speed: f64,
    /// The head yaw's change (rad).
    yaw: f64,
    /// Largest change of any link angle (rad).
    link_angle: f64,
}

impl Demand {
    /// The demand of one motion (an edge, or merged edges) of a chain with links of
    /// length `l`.
    pub(super) fn of(e: &Segment, l: f64) -> Self {
        let d = &e.delta;
        Self {
            speed: match e.kind {
                SegmentKind::ShapeChange => motion_speed(l, &d[..3], &e.from[3..], &d[3..]),
                _ => head_length(d),
            },
            yaw: d[3].abs(),
            link_angle: d[4..].iter().fold(0.0f64, |m, a| m.max(a.abs())),
        }
    }

    /// The largest rate of progress within the speed and angular-rate limits.
    pub(super) fn max_rate(&self, lim: &ReferenceLimits) -> f64 {
        let mut r = f64::INFINITY;
        if self.speed > 0.0 {
            r = r.min(lim.speed / self.speed);
        }
        // No angle change asks for no time: 1 / 0 is no bound.
        let angles = [self.yaw, self.link_angle];
        r = r.min(1.0 / angle_demand(angles, lim.yaw_rate, lim.angular_rate));
        r
    }
}

/// An upper bound on the speed of any unit, per unit of progress, while the head moves
/// by `d_head` and the shape from `eta` by `d_eta`, both linearly: the largest chord
/// speed between `SPEED_SAMPLES` measurements, plus the most a velocity can change
/// between two of them (the head's part is constant; a link direction's second
/// derivative is at most `(|dtheta| + |dpsi|)^2`); never more than the bound
/// `|d_head| + l * sum_k sqrt(dtheta_k^2 + dpsi_k^2)`. Measured on the whole motion,
/// not as the head's speed plus the shape's: a chain following its head moves every
/// unit about as fast as the head, where the sum would count it twice.
pub(super) fn motion_speed(l: f64, d_head: &[f64], eta: &[f64], d_eta: &[f64]) -> f64 {
    let links = (eta.len() - 1) / 2;
    let at = |s: f64| {
        let e: Vec<f64> = eta.iter().zip(d_eta).map(|(a, d)| a + s * d).collect();
        positions_f64(l, [s * d_head[0], s * d_head[1], s * d_head[2]], &e)
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
    (best + l * curve / n).min(head_length(d_head) + l * bound)
}

/// The head's displacement (m) over a change `d` of `zeta` (or of the head alone).
pub(super) fn head_length(d: &[f64]) -> f64 {
    (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
}

/// Whether the straight move from the start of `run` to its end passes every inner
/// waypoint within `s.run_tolerance` (`s.step_run_tolerance` for short steps): each
/// unit's distance from where the plan has it, where the move has the head as far
/// along as the plan has it there. Where the head
/// moves, only the waypoints that end a translation are compared: a follow-the-leader
/// step changes shape, then translates, and its straight version moves both at once,
/// so the waypoint between the two is off any straight line by the step itself.
pub(super) fn straight(run: &[Segment], l: f64, s: &super::Settings) -> bool {
    let dim = run[0].delta.len();
    let angles = |d: &[f64]| d[3..].iter().map(|a| a.abs()).sum::<f64>();
    let head_total: f64 = run.iter().map(|e| head_length(&e.delta)).sum();
    let angle_total: f64 = run.iter().map(|e| angles(&e.delta)).sum();
    let start = &run[0].from;
    let whole: Vec<f64> = (0..dim)
        .map(|i| run.iter().map(|e| e.delta[i]).sum())
        .collect();
    let mut at = start.clone();
    let (mut head_done, mut angle_done) = (0.0, 0.0);
    let longest = run
        .iter()
        .map(|e| head_length(&e.delta))
        .fold(0.0f64, f64::max);
    let tol = match longest > 0.0 && longest <= s.short_step {
        true => s.step_run_tolerance,
        false => s.run_tolerance,
    };
    for e in &run[..run.len() - 1] {
        at.iter_mut().zip(&e.delta).for_each(|(a, d)| *a += d);
        head_done += head_length(&e.delta);
        angle_done += angles(&e.delta);
        let share = if head_total > 0.0 {
            if e.kind != SegmentKind::Translation {
                continue;
            }
            head_done / head_total
        } else if angle_total > 0.0 {
            angle_done / angle_total
        } else {
            continue;
        };
        let line: Vec<f64> = start
            .iter()
            .zip(&whole)
            .map(|(a, d)| a + share * d)
            .collect();
        let plan = positions_f64(l, [at[0], at[1], at[2]], &at[3..]);
        let moved = positions_f64(l, [line[0], line[1], line[2]], &line[3..]);
        let off = plan.iter().zip(&moved).any(|(p, q)| {
            (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2) > tol * tol
        });
        if off {
            return false;
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn motion_speed_bounds_every_unit_and_is_tight_for_a_rotation() {
        // The whole chain turned about the head: the tail (3 links out) moves 3 l per
        // radian, and the bound says so.
        let (l, eta, d) = (0.5, [0.0; 7], [0.5, 0.0, 0.5, 0.0, 0.5, 0.0, 0.5]);
        let w = motion_speed(l, &[0.0; 3], &eta, &d);
        assert!(
            w >= 3.0 * l * 0.5 - 1e-12 && w <= 3.0 * l * 0.5 * 1.01,
            "{w}"
        );
        // Links turning against each other: the measured speed is well below the bound.
        let d = [0.0, 0.0, 0.6, 0.0, -0.6, 0.0, 0.6];
        let w = motion_speed(l, &[0.0; 3], &eta, &d);
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
