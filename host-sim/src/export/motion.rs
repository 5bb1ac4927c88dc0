//! The motion an export writes: every unit's state at the ticks of a fixed rate, read
//! from a timed trajectory or from a recorded flight (docs/model.md, "Exports").
//!
//! A trajectory moves linearly in `zeta` between its samples (docs/model.md,
//! "Trajectories"), so a unit's position at any time is paper Eq. 2 of the
//! interpolated `zeta`, exactly; velocities and accelerations are divided differences
//! of the samples, as the trajectory's own limits are measured. A flight records each
//! body's position, attitude, velocity and angular velocity; between two records they
//! are interpolated (the attitude by slerp) and the acceleration is the divided
//! difference of the recorded velocities. Commands (attitude and thrust) are held from
//! the last record, as a controller holds its last command.

use nalgebra::{Point3, Quaternion, UnitQuaternion, Vector3};

use super::ExportError;
use crate::collision::exact::positions_f64;
use crate::plan_file::ChainSection;
use crate::sim::{BodySample, FlightFile};
use crate::trajectory::TrajectoryFile;

/// Lowest rate (Hz) of the exported stream: PX4 leaves offboard mode when setpoints
/// come slower than 2 Hz, so the stream must be faster than that.
pub const MIN_RATE_HZ: f64 = 2.0;
/// Highest rate (Hz): more than a flight controller takes, and a bound on the memory
/// an export of a long motion needs.
pub const MAX_RATE_HZ: f64 = 1000.0;
/// The rate of the exported stream by default (Hz): a trajectory's default sample
/// rate (`trajectory::DEFAULT_DT` = 0.02 s), so every exported state is a sample.
pub const DEFAULT_RATE_HZ: f64 = 50.0;
/// Most unit states an export holds, ticks times units: the bound on its memory (a bag
/// takes about 400 bytes a unit state, so about 0.8 GB; 1.8 hours of a 6-unit chain at
/// 50 Hz).
pub const MAX_UNIT_STATES: usize = 2_000_000;

/// Times closer than this (s) are the same time: far below any sample step, far above
/// the rounding of sums of steps.
const SAME_TIME_S: f64 = 1e-9;

/// One unit's state at a tick, in the world frame W (docs/model.md).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UnitState {
    /// Unit centre (m).
    pub p: Point3<f64>,
    /// Attitude, rotating the unit's body frame (x forward, z up) into W.
    pub q: UnitQuaternion<f64>,
    /// Velocity (m/s).
    pub v: Vector3<f64>,
    /// Acceleration (m/s^2).
    pub a: Vector3<f64>,
    /// Angular velocity in W (rad/s).
    pub w: Vector3<f64>,
    /// Angular acceleration in W (rad/s^2).
    pub alpha: Vector3<f64>,
}

/// What a unit's controller was commanded at a tick (flights only).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Command {
    /// Commanded attitude, body frame into W.
    pub attitude: UnitQuaternion<f64>,
    /// Commanded thrust (N).
    pub thrust: f64,
}

/// The chain at one tick.
#[derive(Clone, Debug, PartialEq)]
pub struct Tick {
    /// Time on the source's clock (s): the trajectory's, or the flight's.
    pub t: f64,
    /// Every unit, head first.
    pub units: Vec<UnitState>,
    /// Every unit's command, where the source recorded them.
    pub commands: Option<Vec<Command>>,
}

/// A motion ready to export: the chain and its state at every tick.
#[derive(Clone, Debug, PartialEq)]
pub struct Motion {
    /// The chain (sizes for markers; the unit count).
    pub chain: ChainSection,
    /// The ticks, `k / rate` for `k = 0, 1, ...` and the source's last time.
    pub ticks: Vec<Tick>,
    /// The rate of the ticks (Hz).
    pub rate: f64,
}

impl Motion {
    /// The motion of a trajectory file at `rate` Hz.
    pub fn of_trajectory(file: &TrajectoryFile, rate: f64) -> Result<Self, ExportError> {
        let params = file
            .check()
            .map_err(|e| ExportError::Source(e.to_string()))?;
        let times: Vec<f64> = file.samples.iter().map(|s| s.t).collect();
        check_times(&times)?;
        let knots = TrajectoryKnots::new(file, params.link_length as f64);
        let ticks = tick_times(&times, rate, file.chain.units as usize)?
            .into_iter()
            .map(|(t, j, f)| knots.at(t, j, f))
            .collect();
        Ok(Self {
            chain: file.chain,
            ticks,
            rate,
        })
    }

    /// The motion of a recorded flight at `rate` Hz. A flight that does not record
    /// its chain is taken to be of the default chain's sizes with its unit count.
    pub fn of_flight(file: &FlightFile, rate: f64) -> Result<Self, ExportError> {
        file.check().map_err(ExportError::Source)?;
        let times: Vec<f64> = file.samples.iter().map(|s| s.t).collect();
        check_times(&times)?;
        let chain = match file.chain {
            Some(c) => c,
            None => default_chain(file.report.units)?,
        };
        let knots = FlightKnots::new(file);
        let ticks = tick_times(&times, rate, file.report.units)?
            .into_iter()
            .map(|(t, j, f)| knots.at(t, j, f))
            .collect();
        Ok(Self { chain, ticks, rate })
    }

    /// Number of units.
    pub fn units(&self) -> usize {
        self.chain.units as usize
    }

    /// The time of the last tick (s).
    pub fn duration(&self) -> f64 {
        self.ticks.last().map_or(0.0, |t| t.t)
    }
}

/// The default chain's sizes with `units` units.
fn default_chain(units: usize) -> Result<ChainSection, ExportError> {
    let n = u32::try_from(units)
        .ok()
        .filter(|n| (2..=aerial_chain_core::MAX_UNITS as u32).contains(n))
        .ok_or_else(|| ExportError::Source(format!("report.units = {units} is outside 2..=16")))?;
    Ok(ChainSection::from_params(
        &aerial_chain_core::ChainParams::new(n as u8),
    ))
}

/// Checks that the source's times start at a finite time and increase.
fn check_times(times: &[f64]) -> Result<(), ExportError> {
    let increasing = times.windows(2).all(|w| w[1] > w[0]);
    match times.first() {
        Some(t) if t.is_finite() && increasing => Ok(()),
        _ => Err(ExportError::Source(
            "sample times must be finite and strictly increasing".into(),
        )),
    }
}

/// The ticks of `rate` Hz over the source's times: `(t, j, f)` with `t` on the
/// source's clock, `j` the sample at or before it and `f` the fraction of the way to
/// the next. The first tick is the first sample, then every `1 / rate` s after it, and
/// the last sample is always a tick (a motion ends where its source ends). The ticks
/// of `units` units must fit [`MAX_UNIT_STATES`].
fn tick_times(
    times: &[f64],
    rate: f64,
    units: usize,
) -> Result<Vec<(f64, usize, f64)>, ExportError> {
    if !(rate > MIN_RATE_HZ && rate <= MAX_RATE_HZ) {
        return Err(ExportError::Rate(rate));
    }
    let (t0, end) = (times[0], times[times.len() - 1]);
    // `as` saturates: an absurd duration is refused, not wrapped.
    let count = ((end - t0) * rate).floor() as usize + 1;
    if count.saturating_mul(units.max(1)) > MAX_UNIT_STATES {
        return Err(ExportError::TooLong {
            ticks: count,
            units,
            rate,
        });
    }
    // A tick within a nanosecond of a sample is that sample (a flight recorded at the
    // rate has times that are multiples of its step only to within rounding), and one
    // within a nanosecond of the end is the end itself.
    let mut out: Vec<(f64, usize, f64)> = Vec::with_capacity(count + 1);
    let mut j = 0;
    for k in 0..count {
        let t = t0 + k as f64 / rate;
        if t >= end - SAME_TIME_S {
            break;
        }
        while j + 2 < times.len() && times[j + 1] <= t + SAME_TIME_S {
            j += 1;
        }
        let f = ((t - times[j]) / (times[j + 1] - times[j])).clamp(0.0, 1.0);
        out.push((t, j, f));
    }
    out.push((end, times.len() - 1, 0.0));
    Ok(out)
}

/// `a + f (b - a)`.
fn lerp(a: &Vector3<f64>, b: &Vector3<f64>, f: f64) -> Vector3<f64> {
    a + (b - a) * f
}

/// Divided differences of a sequence sampled at `times`: the first derivative by
/// central differences (one-sided at the ends), as `arc verify --trajectory` measures
/// rates between samples.
fn first_differences(times: &[f64], x: &[Vector3<f64>]) -> Vec<Vector3<f64>> {
    let n = x.len();
    (0..n)
        .map(|j| {
            let (a, b) = (j.saturating_sub(1), (j + 1).min(n - 1));
            if a == b {
                Vector3::zeros()
            } else {
                (x[b] - x[a]) / (times[b] - times[a])
            }
        })
        .collect()
}

/// The second divided difference at every inner sample (docs/model.md's acceleration
/// of a trajectory), zero at the two ends.
fn second_differences(times: &[f64], x: &[Vector3<f64>]) -> Vec<Vector3<f64>> {
    let n = x.len();
    (0..n)
        .map(|j| {
            if j == 0 || j + 1 >= n {
                return Vector3::zeros();
            }
            let (h0, h1) = (times[j] - times[j - 1], times[j + 1] - times[j]);
            let d = (x[j + 1] - x[j]) / h1 - (x[j] - x[j - 1]) / h0;
            d * 2.0 / (times[j + 1] - times[j - 1])
        })
        .collect()
}

/// Per-unit series (`[unit][sample]`) of some vector of every sample.
fn per_unit<T>(samples: usize, units: usize, f: impl Fn(usize, usize) -> T) -> Vec<Vec<T>> {
    (0..units)
        .map(|u| (0..samples).map(|j| f(j, u)).collect())
        .collect()
}

/// A trajectory's samples and the derivatives of every unit's motion at them.
struct TrajectoryKnots<'a> {
    file: &'a TrajectoryFile,
    link_length: f64,
    /// `[unit][sample]`: velocity, acceleration.
    v: Vec<Vec<Vector3<f64>>>,
    a: Vec<Vec<Vector3<f64>>>,
    /// Per sample: the head yaw's rate and acceleration (every unit holds it).
    yaw_rate: Vec<f64>,
    yaw_accel: Vec<f64>,
}

impl<'a> TrajectoryKnots<'a> {
    fn new(file: &'a TrajectoryFile, link_length: f64) -> Self {
        let times: Vec<f64> = file.samples.iter().map(|s| s.t).collect();
        let units = file.chain.units as usize;
        let n = times.len();
        let p = per_unit(n, units, |j, u| Vector3::from(file.samples[j].p[u]));
        let v = p.iter().map(|x| first_differences(&times, x)).collect();
        let a = p.iter().map(|x| second_differences(&times, x)).collect();
        let yaw: Vec<Vector3<f64>> = file
            .samples
            .iter()
            .map(|s| Vector3::new(s.zeta[3], 0.0, 0.0))
            .collect();
        let yaw_rate = first_differences(&times, &yaw)
            .iter()
            .map(|d| d.x)
            .collect();
        let yaw_accel = second_differences(&times, &yaw)
            .iter()
            .map(|d| d.x)
            .collect();
        Self {
            file,
            link_length,
            v,
            a,
            yaw_rate,
            yaw_accel,
        }
    }

    /// The chain at time `t`, a fraction `f` of the way from sample `j` to the next:
    /// `zeta` interpolated (its angles are continuous along a trajectory), every unit
    /// placed by paper Eq. 2, holding the head's yaw.
    fn at(&self, t: f64, j: usize, f: f64) -> Tick {
        let s = &self.file.samples;
        let k = (j + 1).min(s.len() - 1);
        let zeta: Vec<f64> = s[j]
            .zeta
            .iter()
            .zip(&s[k].zeta)
            .map(|(a, b)| a + f * (b - a))
            .collect();
        let positions = positions_f64(self.link_length, [zeta[0], zeta[1], zeta[2]], &zeta[3..]);
        let q = UnitQuaternion::from_euler_angles(0.0, 0.0, zeta[3]);
        let yaw_rate = self.yaw_rate[j] + f * (self.yaw_rate[k] - self.yaw_rate[j]);
        let yaw_accel = self.yaw_accel[j] + f * (self.yaw_accel[k] - self.yaw_accel[j]);
        let units = positions
            .into_iter()
            .enumerate()
            .map(|(u, p)| UnitState {
                p,
                q,
                v: lerp(&self.v[u][j], &self.v[u][k], f),
                a: lerp(&self.a[u][j], &self.a[u][k], f),
                w: Vector3::new(0.0, 0.0, yaw_rate),
                alpha: Vector3::new(0.0, 0.0, yaw_accel),
            })
            .collect();
        Tick {
            t,
            units,
            commands: None,
        }
    }
}

/// A flight's records and the accelerations of every body at them.
struct FlightKnots<'a> {
    file: &'a FlightFile,
    /// `[unit][sample]`: acceleration, angular acceleration.
    a: Vec<Vec<Vector3<f64>>>,
    alpha: Vec<Vec<Vector3<f64>>>,
}

/// A recorded `f32` triple as a vector.
fn v3(x: &[f32; 3]) -> Vector3<f64> {
    Vector3::new(x[0] as f64, x[1] as f64, x[2] as f64)
}

/// A recorded attitude `[w, x, y, z]`, normalised.
fn attitude(b: &BodySample) -> UnitQuaternion<f64> {
    let [w, x, y, z] = b.q.map(|c| c as f64);
    UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z))
}

impl<'a> FlightKnots<'a> {
    fn new(file: &'a FlightFile) -> Self {
        let times: Vec<f64> = file.samples.iter().map(|s| s.t).collect();
        let n = times.len();
        let units = file.report.units;
        let v = per_unit(n, units, |j, u| v3(&file.samples[j].units[u].v));
        let w = per_unit(n, units, |j, u| v3(&file.samples[j].units[u].w));
        Self {
            file,
            a: v.iter().map(|x| first_differences(&times, x)).collect(),
            alpha: w.iter().map(|x| first_differences(&times, x)).collect(),
        }
    }

    /// The chain at time `t`, a fraction `f` of the way from record `j` to the next.
    fn at(&self, t: f64, j: usize, f: f64) -> Tick {
        let s = &self.file.samples;
        let k = (j + 1).min(s.len() - 1);
        let units = (0..self.file.report.units)
            .map(|u| {
                let (b0, b1) = (&s[j].units[u], &s[k].units[u]);
                UnitState {
                    p: Point3::from(lerp(&v3(&b0.p), &v3(&b1.p), f)),
                    q: attitude(b0).slerp(&attitude(b1), f),
                    v: lerp(&v3(&b0.v), &v3(&b1.v), f),
                    a: lerp(&self.a[u][j], &self.a[u][k], f),
                    w: lerp(&v3(&b0.w), &v3(&b1.w), f),
                    alpha: lerp(&self.alpha[u][j], &self.alpha[u][k], f),
                }
            })
            .collect();
        Tick {
            t,
            units,
            commands: commands(&s[j]),
        }
    }
}

/// The commands of a record, where it holds them: the attitude from its
/// `[roll, pitch, yaw]` (Rz(yaw) Ry(pitch) Rx(roll), docs/simulation.md) and thrust.
fn commands(s: &crate::sim::Sample) -> Option<Vec<Command>> {
    if s.thrust.is_empty() || s.attitude_cmd.len() != s.thrust.len() {
        return None;
    }
    let list = s
        .attitude_cmd
        .iter()
        .zip(&s.thrust)
        .map(|(rpy, &thrust)| Command {
            attitude: UnitQuaternion::from_euler_angles(
                rpy[0] as f64,
                rpy[1] as f64,
                rpy[2] as f64,
            ),
            thrust: thrust as f64,
        })
        .collect();
    Some(list)
}
