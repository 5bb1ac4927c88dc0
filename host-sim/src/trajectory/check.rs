//! The exact check of a sampled trajectory (docs/model.md, "Trajectories"), which knows
//! nothing of how the samples were made.
//!
//! Between two consecutive samples the chain moves linearly in `zeta` (angles along
//! their shortest signed difference): head and shape at once, so the interval is
//! sampled by the bound of both: the head moves `|d xi|` and a link direction at most
//! `sqrt(dtheta^2 + dpsi^2)` on the unit sphere, so no point of the chain moves more
//! than `|d xi| + l * sum_k sqrt(dtheta_k^2 + dpsi_k^2)` over the interval, and the
//! interval is cut into pieces of at most `r_v / 4` of that. Every configuration so
//! sampled must pass the exact test ([`crate::collision`]'s `check_config_exact`).
//!
//! Limits are checked on differences of the samples: a unit's speed over an interval
//! is its displacement over the interval's time, and the head's (or an angle's)
//! acceleration at a sample is the second divided difference of its neighbours. Both are
//! averages of the true derivative, so a smooth motion within a limit passes exactly.
//!
//! The intervals are checked in runs of [`CHUNK`] side by side (rayon), and the runs'
//! findings are put together in order up to the first problem: the report is the one a
//! check from the first sample to the last would make.

use std::sync::atomic::{AtomicUsize, Ordering};

use aerial_chain_core::validity::Body;
use aerial_chain_core::ChainParams;
use nalgebra::Point3;
use rayon::prelude::*;

use super::Limits;
use crate::collision::exact::{check_config_exact, positions_f64, ExactViolation};
use crate::collision::verify::{wrap, zeta_delta, MAX_INTERVALS};
use crate::map::Grid;

/// Intervals between samples checked as one run (see the module docs): some tens of
/// configurations, enough work to outweigh handing it to another thread.
const CHUNK: usize = 32;

/// A limit holds when the measured value is at most `limit * (1 + LIMIT_TOLERANCE)`:
/// room for the rounding of differences, far below any real excess.
pub const LIMIT_TOLERANCE: f64 = 1e-6;

/// What is wrong at one place of a trajectory.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum Problem {
    /// A sample of the wrong length or with a number that is not finite.
    #[error("zeta is not {dim} finite numbers")]
    Sample {
        /// The length a configuration of this chain has.
        dim: usize,
    },
    /// Time that does not increase.
    #[error("time {t} does not increase over the sample before ({before})")]
    Time {
        /// This sample's time (s).
        t: f64,
        /// The time before (s).
        before: f64,
    },
    /// A unit faster than the speed limit.
    #[error("unit {unit} moves at {value:.6} m/s, above the limit {limit} m/s")]
    Speed {
        /// The unit (1 is the head).
        unit: usize,
        /// Its speed (m/s).
        value: f64,
        /// The limit (m/s).
        limit: f64,
    },
    /// The head accelerating beyond the limit.
    #[error("the head accelerates at {value:.6} m/s^2, above the limit {limit} m/s^2")]
    Accel {
        /// Its acceleration (m/s^2).
        value: f64,
        /// The limit (m/s^2).
        limit: f64,
    },
    /// An angle turning faster than the angular-rate limit.
    #[error("{angle} turns at {value:.6} rad/s, above the limit {limit} rad/s")]
    AngularRate {
        /// The angle's name (`psi1_r`, `theta2`, ...).
        angle: String,
        /// Its rate (rad/s).
        value: f64,
        /// The limit (rad/s).
        limit: f64,
    },
    /// An angle accelerating beyond the limit.
    #[error("{angle} accelerates at {value:.6} rad/s^2, above the limit {limit} rad/s^2")]
    AngularAccel {
        /// The angle's name.
        angle: String,
        /// Its angular acceleration (rad/s^2).
        value: f64,
        /// The limit (rad/s^2).
        limit: f64,
    },
    /// An interval so long it would need more than `MAX_INTERVALS` configurations.
    #[error("the chain moves so far between two samples that {0} configurations would be needed")]
    TooFar(usize),
    /// A configuration that fails the exact test (limits, self-collision, map, bounds).
    #[error("{0}")]
    Invalid(ExactViolation),
    /// A valid configuration closer to the map than the generator asks of a blend (never
    /// raised by [`check_samples`]: the contract asks for validity only).
    #[error(
        "{body} keeps {clearance:.4} m from the map, less than the {required} m a blend keeps"
    )]
    Clearance {
        /// The body.
        body: Body,
        /// Its clearance (m).
        clearance: f64,
        /// The clearance asked for there (m).
        required: f64,
    },
}

/// The first problem of a trajectory, and where.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("at t = {t:.3} s (sample {sample}, {fraction:.3} of the way to the next): {problem}")]
pub struct Violation {
    /// The sample (the interval's first sample for problems between samples).
    pub sample: usize,
    /// Its time (s).
    pub t: f64,
    /// Fraction of the interval to the next sample where the problem is (0 at a sample).
    pub fraction: f64,
    /// What.
    pub problem: Problem,
}

/// The largest value of every limited quantity over a trajectory.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Peaks {
    /// Largest unit speed (m/s).
    pub speed: f64,
    /// Largest head acceleration (m/s^2).
    pub accel: f64,
    /// Largest link angle rate (rad/s).
    pub angular_rate: f64,
    /// Largest link angular acceleration (rad/s^2).
    pub angular_accel: f64,
    /// Largest head yaw rate (rad/s).
    pub yaw_rate: f64,
    /// Largest head yaw acceleration (rad/s^2).
    pub yaw_accel: f64,
}

impl Peaks {
    /// The peak of angle `j` of `zeta` (3: the head yaw) as rate and acceleration.
    fn of_angle(&mut self, j: usize) -> (&mut f64, &mut f64) {
        match j {
            3 => (&mut self.yaw_rate, &mut self.yaw_accel),
            _ => (&mut self.angular_rate, &mut self.angular_accel),
        }
    }
}

/// The rate and acceleration limits of angle `j` of `zeta` (3: the head yaw).
fn angle_limits(lim: &Limits, j: usize) -> (f64, f64) {
    match j {
        3 => (lim.yaw_rate, lim.yaw_accel),
        _ => (lim.angular_rate, lim.angular_accel),
    }
}

/// What [`check_samples`] found.
#[derive(Clone, Debug, PartialEq)]
pub struct CheckReport {
    /// True when every limit holds and every sampled configuration is valid.
    pub ok: bool,
    /// Configurations tested exactly.
    pub configurations: usize,
    /// Smallest clearance of any body to the map over the tested configurations (m),
    /// capped at the horizon.
    pub min_clearance: f64,
    /// When and which body.
    pub min_clearance_at: Option<(f64, Body)>,
    /// The largest values of the limited quantities (up to the first violation).
    pub peaks: Peaks,
    /// The first problem, if any (the check stops there).
    pub violation: Option<Violation>,
}

/// The name of `zeta[j]` for messages (`j >= 3`).
fn angle_name(j: usize) -> String {
    match j {
        3 => "psi1_r".into(),
        _ if j.is_multiple_of(2) => format!("theta{}", (j - 2) / 2),
        _ => format!("psi{}", (j - 3) / 2),
    }
}

/// Checks the samples `zetas` at `times` of a trajectory of chain `params` on `grid`:
/// every limit at every sample and every configuration between samples, as described
/// in the module documentation. `horizon` caps the clearance search (m). Stops at the
/// first problem.
pub fn check_samples(
    grid: &Grid,
    params: &ChainParams,
    limits: &Limits,
    times: &[f64],
    zetas: &[Vec<f64>],
    horizon: f64,
) -> CheckReport {
    check_with_margin(grid, params, limits, (times, zetas), horizon, &|_| 0.0)
}

/// The smallest clearance from the map (capped at `horizon`) of any body over the
/// straight move in `zeta` from `z0` to `z1`, sampled as the check samples an interval;
/// 0 where a configuration on it is not valid. What a plan's own edge keeps, which a
/// blend or merge replacing it need not exceed.
pub(super) fn move_clearance(
    grid: &Grid,
    params: &ChainParams,
    (z0, z1): (&[f64], &[f64]),
    horizon: f64,
) -> f64 {
    // Only the configurations are asked for: no rate between them is a limit's.
    let unbounded = Limits {
        speed: f64::INFINITY,
        accel: f64::INFINITY,
        angular_rate: f64::INFINITY,
        angular_accel: f64::INFINITY,
        yaw_rate: f64::INFINITY,
        yaw_accel: f64::INFINITY,
    };
    let mut c = Checker {
        grid,
        params,
        limits: &unbounded,
        horizon,
        required: &|_| 0.0,
        run: usize::MAX,
        rep: CheckReport::empty(horizon),
    };
    let valid = c.configuration(z0, 0.0).is_ok() && c.interval(z0, z1, 0.0, 1.0).is_ok();
    if valid {
        c.rep.min_clearance
    } else {
        0.0
    }
}

/// [`check_samples`], and every configuration at time `t` must also keep
/// `required(t)` from the map (the generator's own rule for blends; `horizon` must be at
/// least as large).
pub(super) fn check_with_margin(
    grid: &Grid,
    params: &ChainParams,
    limits: &Limits,
    (times, zetas): (&[f64], &[Vec<f64>]),
    horizon: f64,
    required: &(dyn Fn(f64) -> f64 + Sync),
) -> CheckReport {
    check_in_runs(
        grid,
        params,
        limits,
        (times, zetas),
        (horizon, required),
        CHUNK,
    )
}

/// [`check_with_margin`] with the intervals checked in runs of `run` (a check in one
/// run for `usize::MAX`: what the runs' report must equal).
fn check_in_runs(
    grid: &Grid,
    params: &ChainParams,
    limits: &Limits,
    (times, zetas): (&[f64], &[Vec<f64>]),
    (horizon, required): (f64, &(dyn Fn(f64) -> f64 + Sync)),
    run: usize,
) -> CheckReport {
    let mut c = Checker {
        grid,
        params,
        limits,
        horizon,
        required,
        run,
        rep: CheckReport::empty(horizon),
    };
    if let Err(v) = c.run(times, zetas) {
        c.rep.violation = Some(v);
    }
    c.rep.ok = c.rep.violation.is_none();
    c.rep
}

impl CheckReport {
    /// The report of a check that has tested nothing yet.
    fn empty(horizon: f64) -> Self {
        Self {
            ok: false,
            configurations: 0,
            min_clearance: horizon.max(0.0),
            min_clearance_at: None,
            peaks: Peaks::default(),
            violation: None,
        }
    }

    /// Adds what a check of the samples after these found (up to its first problem).
    fn extend(&mut self, later: Self) {
        self.configurations += later.configurations;
        if let Some(at) = later.min_clearance_at {
            if self.min_clearance_at.is_none() || later.min_clearance < self.min_clearance {
                self.min_clearance = later.min_clearance;
                self.min_clearance_at = Some(at);
            }
        }
        let (p, q) = (&mut self.peaks, later.peaks);
        p.speed = p.speed.max(q.speed);
        p.accel = p.accel.max(q.accel);
        p.angular_rate = p.angular_rate.max(q.angular_rate);
        p.angular_accel = p.angular_accel.max(q.angular_accel);
        p.yaw_rate = p.yaw_rate.max(q.yaw_rate);
        p.yaw_accel = p.yaw_accel.max(q.yaw_accel);
    }
}

/// The state of one check.
struct Checker<'a> {
    grid: &'a Grid,
    params: &'a ChainParams,
    limits: &'a Limits,
    horizon: f64,
    required: &'a (dyn Fn(f64) -> f64 + Sync),
    /// Intervals per run.
    run: usize,
    rep: CheckReport,
}

impl Checker<'_> {
    fn run(&mut self, times: &[f64], zetas: &[Vec<f64>]) -> Result<(), Violation> {
        let dim = 2 * self.params.n() + 2;
        let at = |sample: usize, problem: Problem| Violation {
            sample,
            t: times.get(sample).copied().unwrap_or(f64::NAN),
            fraction: 0.0,
            problem,
        };
        if times.len() != zetas.len() {
            return Err(at(times.len().min(zetas.len()), Problem::Sample { dim }));
        }
        for (j, z) in zetas.iter().enumerate() {
            if z.len() != dim || z.iter().any(|v| !v.is_finite()) || !times[j].is_finite() {
                return Err(at(j, Problem::Sample { dim }));
            }
            if j > 0 && times[j] <= times[j - 1] {
                let problem = Problem::Time {
                    t: times[j],
                    before: times[j - 1],
                };
                return Err(at(j, problem));
            }
        }
        if let (Some(z), Some(&t)) = (zetas.first(), times.first()) {
            self.configuration(z, t).map_err(|p| at(0, p))?;
        }
        let intervals = zetas.len().saturating_sub(1);
        // The first run that found a problem: runs after it need not finish.
        let first_bad = AtomicUsize::new(usize::MAX);
        let runs: Vec<(CheckReport, Result<(), Violation>)> = (0..intervals.div_ceil(self.run))
            .into_par_iter()
            .map(|c| {
                let mut run = Checker {
                    rep: CheckReport::empty(self.horizon),
                    ..*self
                };
                let span = c * self.run..(c * self.run).saturating_add(self.run).min(intervals);
                let found = run.intervals(times, zetas, span, &|| {
                    first_bad.load(Ordering::Relaxed) < c
                });
                if found.is_err() {
                    first_bad.fetch_min(c, Ordering::Relaxed);
                }
                (run.rep, found)
            })
            .collect();
        for (rep, found) in runs {
            self.rep.extend(rep);
            found?;
        }
        Ok(())
    }

    /// The intervals `span` (from sample `j` to `j + 1` for `j` in it): limits and
    /// configurations, up to the first problem. Stops early, with no problem, once
    /// `abandon` says a problem was found before the span.
    fn intervals(
        &mut self,
        times: &[f64],
        zetas: &[Vec<f64>],
        span: std::ops::Range<usize>,
        abandon: &dyn Fn() -> bool,
    ) -> Result<(), Violation> {
        let at = |sample: usize, problem: Problem| Violation {
            sample,
            t: times[sample],
            fraction: 0.0,
            problem,
        };
        let l = self.params.link_length as f64;
        let units = |z: &[f64]| positions_f64(l, [z[0], z[1], z[2]], &z[3..]);
        let mut here = units(&zetas[span.start]);
        for j in span {
            if abandon() {
                return Ok(());
            }
            let next = units(&zetas[j + 1]);
            let dt = times[j + 1] - times[j];
            self.rates(&here, &next, &zetas[j], &zetas[j + 1], dt)
                .map_err(|p| at(j, p))?;
            if j > 0 {
                self.accelerations(&times[j - 1..j + 2], &zetas[j - 1..j + 2])
                    .map_err(|p| at(j, p))?;
            }
            self.interval(&zetas[j], &zetas[j + 1], times[j], dt)
                .map_err(|(fraction, problem)| Violation {
                    fraction,
                    ..at(j, problem)
                })?;
            here = next;
        }
        Ok(())
    }

    /// Tests one configuration exactly and keeps its clearance.
    fn configuration(&mut self, z: &[f64], t: f64) -> Result<(), Problem> {
        self.rep.configurations += 1;
        let head = [z[0], z[1], z[2]];
        let c = check_config_exact(self.grid, self.params, head, &z[3..], self.horizon)
            .map_err(Problem::Invalid)?;
        if self.rep.min_clearance_at.is_none() || c.clearance < self.rep.min_clearance {
            self.rep.min_clearance = c.clearance;
            self.rep.min_clearance_at = Some((t, c.body));
        }
        let required = (self.required)(t);
        if c.clearance < required {
            return Err(Problem::Clearance {
                body: c.body,
                clearance: c.clearance,
                required,
            });
        }
        Ok(())
    }

    /// Unit speeds and angle rates over one interval.
    fn rates(
        &mut self,
        p0: &[Point3<f64>],
        p1: &[Point3<f64>],
        z0: &[f64],
        z1: &[f64],
        dt: f64,
    ) -> Result<(), Problem> {
        let lim = self.limits;
        for (i, (a, b)) in p0.iter().zip(p1).enumerate() {
            let v = dist(a, b) / dt;
            self.rep.peaks.speed = self.rep.peaks.speed.max(v);
            if exceeds(v, lim.speed) {
                return Err(Problem::Speed {
                    unit: i + 1,
                    value: v,
                    limit: lim.speed,
                });
            }
        }
        for j in 3..z0.len() {
            let w = wrap(z1[j] - z0[j]).abs() / dt;
            let peak = self.rep.peaks.of_angle(j).0;
            *peak = peak.max(w);
            let limit = angle_limits(lim, j).0;
            if exceeds(w, limit) {
                return Err(Problem::AngularRate {
                    angle: angle_name(j),
                    value: w,
                    limit,
                });
            }
        }
        Ok(())
    }

    /// Head and angle accelerations at the middle of three samples.
    fn accelerations(&mut self, t: &[f64], z: &[Vec<f64>]) -> Result<(), Problem> {
        let (h0, h1, span) = (t[1] - t[0], t[2] - t[1], t[2] - t[0]);
        let second = |d0: f64, d1: f64| 2.0 * (d1 / h1 - d0 / h0) / span;
        let head = (0..3)
            .map(|k| second(z[1][k] - z[0][k], z[2][k] - z[1][k]).powi(2))
            .sum::<f64>()
            .sqrt();
        self.rep.peaks.accel = self.rep.peaks.accel.max(head);
        if exceeds(head, self.limits.accel) {
            return Err(Problem::Accel {
                value: head,
                limit: self.limits.accel,
            });
        }
        let (z0, z1, z2) = (&z[0], &z[1], &z[2]);
        for (j, ((a0, a1), a2)) in z0.iter().zip(z1).zip(z2).enumerate().skip(3) {
            let a = second(wrap(a1 - a0), wrap(a2 - a1)).abs();
            let peak = self.rep.peaks.of_angle(j).1;
            *peak = peak.max(a);
            let limit = angle_limits(self.limits, j).1;
            if exceeds(a, limit) {
                return Err(Problem::AngularAccel {
                    angle: angle_name(j),
                    value: a,
                    limit,
                });
            }
        }
        Ok(())
    }

    /// Every configuration of the interval `z0 -> z1` at the `r_v / 4` rule, its end
    /// included; the error carries the fraction of the interval.
    fn interval(&mut self, z0: &[f64], z1: &[f64], t0: f64, dt: f64) -> Result<(), (f64, Problem)> {
        let d = zeta_delta(z0, z1);
        let head = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        let links = (0..(z0.len() - 4) / 2)
            .map(|k| (d[4 + 2 * k].powi(2) + d[5 + 2 * k].powi(2)).sqrt())
            .sum::<f64>();
        let travel = head + self.params.link_length as f64 * links;
        let pieces = ((travel / (self.grid.resolution() / crate::collision::SAMPLES_PER_VOXEL))
            .ceil() as usize)
            .max(1);
        if pieces > MAX_INTERVALS {
            return Err((0.0, Problem::TooFar(pieces)));
        }
        let mut z = z0.to_vec();
        for i in 1..=pieces {
            let f = i as f64 / pieces as f64;
            if i == pieces {
                z.copy_from_slice(z1);
            } else {
                z.iter_mut()
                    .zip(z0.iter().zip(&d))
                    .for_each(|(v, (a, dj))| *v = a + f * dj);
            }
            self.configuration(&z, t0 + f * dt).map_err(|p| (f, p))?;
        }
        Ok(())
    }
}

/// Whether `value` is above `limit` by more than the tolerance.
fn exceeds(value: f64, limit: f64) -> bool {
    value > limit * (1.0 + LIMIT_TOLERANCE)
}

fn dist(a: &Point3<f64>, b: &Point3<f64>) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::Cell;

    /// A straight chain of 3 flying along a corridor 1 m wide, 0.15 m past a pillar
    /// (at t = 7.5 s), for `n` samples 0.1 s apart; sample `bump` (if any) jumps 5 cm
    /// sideways, faster than the speed limit.
    fn flight(n: usize, bump: Option<usize>) -> (Vec<f64>, Vec<Vec<f64>>) {
        let times: Vec<f64> = (0..n).map(|j| j as f64 * 0.1).collect();
        let zetas = (0..n)
            .map(|j| {
                let y = if Some(j) == bump { 0.55 } else { 0.5 };
                let mut z = vec![1.5 + 0.02 * j as f64, y, 1.0];
                z.extend([0.0; 5]);
                z
            })
            .collect();
        (times, zetas)
    }

    fn corridor() -> Grid {
        let mut g = Grid::new(0.05, [0, 0, 0], [140, 20, 40], Cell::Free, true).unwrap();
        g.fill_box([3.0, 0.0, 0.0], [3.1, 0.2, 2.0], Cell::Occupied);
        g
    }

    /// The report of runs side by side is the report of one run from the first sample
    /// to the last: for a valid flight, and for flights whose first problem lies in a
    /// later run while runs after it find others (too fast from sample 40 on; too
    /// near the pillar for a margin of 0.2 m after 6 s).
    #[test]
    fn runs_side_by_side_report_what_one_run_does() {
        let (grid, params) = (corridor(), ChainParams::new(3));
        let limits = Limits::default();
        let none = |_: f64| 0.0;
        let near = |t: f64| if t > 6.0 { 0.2 } else { 0.0 };
        let mut cases = vec![
            flight(200, None),
            flight(200, Some(70)),
            flight(200, Some(150)),
        ];
        // Too fast from sample 40 on: every run after it finds a problem too.
        let (mut t, z) = flight(200, None);
        t.iter_mut()
            .skip(40)
            .for_each(|x| *x = 4.0 + (*x - 4.0) * 0.01);
        cases.push((t, z));
        for (k, (t, z)) in cases.iter().enumerate() {
            for required in [&none as &(dyn Fn(f64) -> f64 + Sync), &near] {
                let side = (0.3, required);
                let one = check_in_runs(&grid, &params, &limits, (t, z), side, usize::MAX);
                for run in [1, 7, CHUNK] {
                    let runs = check_in_runs(&grid, &params, &limits, (t, z), side, run);
                    assert_eq!(runs, one, "case {k}, runs of {run}");
                }
                assert!(one.configurations > 0);
                let valid = k == 0 && std::ptr::eq(required, &none as &_);
                assert_eq!(one.ok, valid, "case {k}: {:?}", one.violation);
            }
        }
    }
}
