//! When a trajectory passes its plan's waypoints: the clock of the still picture's
//! colour ramp and of `arc view`.

use super::{Plan, Trajectory};

impl Trajectory {
    /// The time at which this trajectory (made from `plan`) passes each waypoint: the
    /// first sample nearest to it (head position and shape angles, each angle weighed
    /// by the link length) after the previous one's; to the sample spacing.
    pub fn waypoint_times(&self, plan: &Plan) -> Vec<f64> {
        let (times, zetas) = (self.times(), self.zetas());
        let l = self.params().link_length as f64;
        let wrap = |a: f64| {
            (a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
        };
        let distance = |w: &[f64], z: &[f64]| -> f64 {
            let head: f64 = (0..3).map(|k| (w[k] - z[k]).powi(2)).sum();
            let shape: f64 = w[3..]
                .iter()
                .zip(&z[3..])
                .map(|(a, b)| (l * wrap(a - b)).powi(2))
                .sum();
            head + shape
        };
        let mut from = 0;
        plan.waypoints
            .iter()
            .map(|w| {
                let mut best = (f64::INFINITY, from);
                for (j, z) in zetas.iter().enumerate().skip(from) {
                    let d = distance(&w.zeta, z);
                    if d < best.0 {
                        best = (d, j);
                    }
                }
                from = best.1;
                times.get(from).copied().unwrap_or(0.0)
            })
            .collect()
    }
}
