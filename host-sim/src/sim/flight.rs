//! Flying a plan: the simulation loop, the recorded flight and its report.
//!
//! Physics and every controller loop run at [`SimConfig::rate`] (default 500 Hz);
//! the head MPC is re-solved every [`ControllerConfig::mpc_period`]. Every body's
//! state is recorded at every step. The flight ends when the chain has stayed at the
//! goal (head within [`SimConfig::goal_tolerance`], every link within
//! [`SimConfig::angle_tolerance`] of the final shape) for [`SimConfig::settle_hold`]
//! after the reference has ended, or [`SimConfig::settle_time`] after the reference
//! has ended, or when it diverges.

use std::sync::atomic::{AtomicU64, Ordering};

use aerial_chain_core::ChainParams;
use nalgebra::UnitQuaternion;
use serde::{Deserialize, Serialize};

use super::controller::ControlOutput;
use super::controller::ControllerConfig;
use super::dynamics::{BodyState, DynamicsError, V3};
use super::model::ChainModel;
use super::run::FlightRun;
use super::{all_positive, SettingsError};
use crate::trajectory::reference::{RefPoint, Reference, ReferenceError, ReferenceLimits};

/// A disturbance force held on units for a while.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gust {
    /// Start time (s).
    pub start: f64,
    /// Duration (s).
    pub duration: f64,
    /// The unit (0-based) it acts on; `None`: every unit.
    pub unit: Option<usize>,
    /// Force on each affected unit (world, N).
    pub force: V3,
}

/// Everything a simulation run needs besides the plan.
#[derive(Clone, Debug, PartialEq)]
pub struct SimConfig {
    /// Physics and control rate (Hz), at least 500.
    pub rate: f64,
    /// The control stack.
    pub controller: ControllerConfig,
    /// How the plan's edges are timed.
    pub limits: ReferenceLimits,
    /// Longest time after the reference ends to reach and hold the goal (s).
    pub settle_time: f64,
    /// How long the chain must stay at the goal to count as arrived (s).
    pub settle_hold: f64,
    /// Distance of the head from the last waypoint's head that counts as arrived (m).
    pub goal_tolerance: f64,
    /// Angle of every link from its final direction that counts as arrived (rad).
    pub angle_tolerance: f64,
    /// A flight whose head strays farther than this from its reference diverged (m).
    pub divergence: f64,
    /// Disturbances.
    pub gusts: Vec<Gust>,
    /// Fly at least this long (s), e.g. to watch a hover or a gust after the plan ends.
    pub min_time: f64,
}

impl Default for SimConfig {
    fn default() -> Self {
        Self {
            rate: 500.0,
            controller: ControllerConfig::default(),
            limits: ReferenceLimits::default(),
            settle_time: 10.0,
            settle_hold: 1.0,
            goal_tolerance: 0.1,
            angle_tolerance: 5f64.to_radians(),
            divergence: 3.0,
            gusts: Vec::new(),
            min_time: 0.0,
        }
    }
}

impl SimConfig {
    /// The sum of the gusts acting on unit `i` at time `t` (world, N).
    pub(super) fn gust_force(&self, i: usize, t: f64) -> V3 {
        self.gusts
            .iter()
            .filter(|g| t >= g.start && t < g.start + g.duration && g.unit.is_none_or(|u| u == i))
            .map(|g| g.force)
            .sum()
    }

    /// Checks the numbers.
    pub fn validate(&self) -> Result<(), SettingsError> {
        if !(self.rate.is_finite() && (500.0..=20_000.0).contains(&self.rate)) {
            return Err(SettingsError::Rate(self.rate));
        }
        let arrival = [
            self.settle_time,
            self.settle_hold,
            self.goal_tolerance,
            self.angle_tolerance,
        ];
        SettingsError::check(
            all_positive(&arrival) && all_positive(&[self.divergence]),
            "settle times, tolerances and the divergence bound must be positive",
        )?;
        SettingsError::check(
            (0.0..=3600.0).contains(&self.min_time),
            "minimum flight time must lie in [0, 3600] s",
        )?;
        for g in &self.gusts {
            let finite = g.start.is_finite() && g.force.iter().all(|v| v.is_finite());
            SettingsError::check(
                finite && all_positive(&[g.duration]),
                "gusts need a finite start, a positive duration and a finite force",
            )?;
        }
        self.controller.validate()?;
        Ok(self.limits.validate()?)
    }
}

/// The map side of a flight: the exact clearance of the flown chain.
pub trait Obstacles {
    /// The smallest (distance to an obstacle - body radius) over every unit sphere and
    /// link capsule of the chain with unit centres `units` (m; `<= 0` is contact),
    /// and a description of the body and obstacle concerned.
    fn clearance(&self, units: &[V3]) -> (f64, String);
    /// Largest motion of any unit centre between two clearance checks (m), whatever
    /// the clearance (it keeps the map's bounds checked as often as docs/model.md
    /// samples edges).
    fn check_spacing(&self) -> f64;
}

/// The reported minimum clearance is the minimum over every physics step to within
/// this (m); contact (clearance `<= 0`) is never missed.
pub const CLEARANCE_TOLERANCE: f64 = 1e-4;

/// Most bytes a flight may record (every step is kept): 1 GiB.
pub const MAX_RECORDED_BYTES: f64 = (1u64 << 30) as f64;

/// Bytes one recorded step of an `n`-unit chain takes, about.
pub(crate) fn sample_bytes(n: usize) -> f64 {
    let per_unit = std::mem::size_of::<BodySample>() + 4 + 12;
    let per_link = std::mem::size_of::<BodySample>() + 16;
    (std::mem::size_of::<Sample>() + n * per_unit + n * per_link) as f64
}

/// Checks that recording a flight of up to `t_max` s fits [`MAX_RECORDED_BYTES`].
fn check_budget(n: usize, t_ref: f64, cfg: &SimConfig) -> Result<usize, SimError> {
    let t_max = t_ref.max(cfg.min_time) + cfg.settle_time;
    let steps = (t_max * cfg.rate).ceil() + 1.0;
    let bytes = steps * sample_bytes(n);
    if bytes.is_nan() || bytes > MAX_RECORDED_BYTES {
        return Err(SimError::Budget(format!(
            "the flight may last {t_max:.3e} s (the plan {t_ref:.3e} s at --speed {} m/s, \
             then --settle-time {} s), {steps:.3e} steps at --rate {} Hz; recording them \
             needs {:.3e} GiB, over the budget of 1 GiB",
            cfg.limits.speed,
            cfg.settle_time,
            cfg.rate,
            bytes / MAX_RECORDED_BYTES
        )));
    }
    Ok(steps as usize)
}

/// A recorded body state, compact (`f32`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct BodySample {
    /// Position (m).
    pub p: [f32; 3],
    /// Attitude quaternion `[w, x, y, z]`.
    pub q: [f32; 4],
    /// Velocity (m/s).
    pub v: [f32; 3],
    /// Angular velocity, world frame (rad/s).
    pub w: [f32; 3],
}

impl BodySample {
    fn new(s: &BodyState) -> Self {
        let q = UnitQuaternion::from_matrix(&s.r);
        let f = |v: &V3| [v.x as f32, v.y as f32, v.z as f32];
        Self {
            p: f(&s.p),
            q: [q.w as f32, q.i as f32, q.j as f32, q.k as f32],
            v: f(&s.v),
            w: f(&s.w),
        }
    }
}

/// Everything recorded at one step.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Sample {
    /// Time (s).
    pub t: f64,
    /// Every unit, head first.
    pub units: Vec<BodySample>,
    /// Every link.
    pub links: Vec<BodySample>,
    /// Reference head position (m).
    pub head_ref: [f32; 3],
    /// Reference `(pitch, yaw)` of every link (rad).
    pub links_ref: Vec<[f32; 2]>,
    /// Measured `(pitch, yaw)` of every link (rad).
    pub links_meas: Vec<[f32; 2]>,
    /// Commanded thrust of every unit (N).
    pub thrust: Vec<f32>,
    /// Commanded `[roll, pitch, yaw]` of every unit (rad).
    pub attitude_cmd: Vec<[f32; 3]>,
    /// Commanded head acceleration (m/s^2).
    pub head_accel: [f32; 3],
}

/// Joint-limit excursions of the flown chain.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct LimitExcursions {
    /// Largest `|theta_i| - theta_max` seen, if positive (deg).
    pub max_pitch_excess_deg: f64,
    /// Largest bend - `beta_max` seen, if positive (deg).
    pub max_bend_excess_deg: f64,
    /// Time during which some limit was exceeded (s).
    pub time_beyond: f64,
}

/// The flight's summary.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FlightReport {
    /// Number of units.
    pub units: usize,
    /// Physics and control rate (Hz).
    pub rate_hz: f64,
    /// When the reference ends (s).
    pub planned_duration: f64,
    /// When the chain arrived at the goal and stayed (s), if it did.
    pub time_to_complete: Option<f64>,
    /// Whether it arrived.
    pub reached_goal: bool,
    /// Simulated time (s).
    pub simulated_time: f64,
    /// RMS of the head's distance to its reference (m).
    pub head_rms: f64,
    /// Largest head distance to its reference (m).
    pub head_max: f64,
    /// RMS over time and links of the angle between each link and its reference (deg).
    pub link_rms_deg: f64,
    /// Largest such angle (deg).
    pub link_max_deg: f64,
    /// Smallest exact clearance of the flown chain to the map (m), when a map was given.
    pub min_clearance: Option<f64>,
    /// Where the smallest clearance was found.
    pub min_clearance_at: Option<String>,
    /// Time of the smallest clearance (s).
    pub min_clearance_time: Option<f64>,
    /// Whether any body touched the map.
    pub contact: bool,
    /// Smallest gap between bodies of the chain that share no joint (m).
    pub min_self_gap: f64,
    /// Whether the chain touched itself.
    pub self_contact: bool,
    /// Joint-limit excursions.
    pub limits: LimitExcursions,
    /// MPC solves and failures (fallback to a PD law).
    pub mpc_solves: usize,
    /// MPC solves that failed.
    pub mpc_failures: usize,
    /// Whether the flight diverged (left the reference by more than the bound).
    pub diverged: bool,
    /// Wall-clock seconds spent.
    pub wall_seconds: f64,
    /// Simulated seconds per wall-clock second.
    pub realtime_factor: f64,
}

impl FlightReport {
    /// Whether the flight succeeded: arrived, no contact with the map or itself, did
    /// not diverge.
    pub fn success(&self) -> bool {
        self.reached_goal && !self.contact && !self.self_contact && !self.diverged
    }
}

/// A simulated flight.
#[derive(Clone, Debug)]
pub struct Flight {
    /// The chain.
    pub params: ChainParams,
    /// The timed reference flown.
    pub reference: Reference,
    /// Every step.
    pub samples: Vec<Sample>,
    /// The summary.
    pub report: FlightReport,
}

/// Why a flight could not be run at all (a flight that runs and fails is a
/// [`Flight`] whose report says so).
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// The configuration is invalid.
    #[error("simulation settings: {0}")]
    Config(#[from] SettingsError),
    /// The plan cannot be flown (edge kinds, sizes).
    #[error("plan: {0}")]
    Plan(#[from] ReferenceError),
    /// The control stack cannot be built.
    #[error(transparent)]
    Controller(#[from] super::mpc::MpcError),
    /// The flight would record more than `MAX_RECORDED_BYTES`.
    #[error("{0}")]
    Budget(String),
    /// The dynamics cannot be built.
    #[error(transparent)]
    Dynamics(#[from] DynamicsError),
}

/// Flies the plan `waypoints` (`zeta` vectors) of chain `params` with the default
/// bodies of [`ChainModel::new`], checking clearance against `obstacles` if given.
pub fn simulate(
    params: &ChainParams,
    waypoints: &[Vec<f64>],
    cfg: &SimConfig,
    obstacles: Option<&dyn Obstacles>,
) -> Result<Flight, SimError> {
    simulate_model(ChainModel::new(*params), waypoints, cfg, obstacles)
}

/// How far a running simulation is, read by another thread for a progress display.
#[derive(Debug, Default)]
pub struct Progress {
    /// Steps simulated so far.
    pub done: AtomicU64,
    /// Most steps the run can take; 0 until the run has timed its reference.
    pub total: AtomicU64,
}

/// [`simulate`], reporting its progress in `progress` as it goes.
pub fn simulate_with_progress(
    params: &ChainParams,
    waypoints: &[Vec<f64>],
    cfg: &SimConfig,
    obstacles: Option<&dyn Obstacles>,
    progress: &Progress,
) -> Result<Flight, SimError> {
    let model = ChainModel::new(*params);
    let reference = Reference::new(model.units(), model.link_length(), waypoints, &cfg.limits)?;
    fly(model, reference, cfg, obstacles, progress)
}

/// Flies a timed `reference` (a trajectory, see `crate::trajectory`) as it is: its
/// timing replaces the limits of `cfg`, except that `cfg.limits.start_hold` seconds at
/// rest come first.
pub fn simulate_reference(
    params: &ChainParams,
    reference: &Reference,
    cfg: &SimConfig,
    obstacles: Option<&dyn Obstacles>,
    progress: &Progress,
) -> Result<Flight, SimError> {
    cfg.validate()?;
    if reference.units() != params.n() {
        return Err(SimError::Plan(ReferenceError::Waypoint {
            index: 0,
            dim: 2 * params.n() + 2,
        }));
    }
    let timed = reference.with_start_hold(cfg.limits.start_hold);
    fly(ChainModel::new(*params), timed, cfg, obstacles, progress)
}

/// [`simulate`] with explicit bodies.
pub fn simulate_model(
    model: ChainModel,
    waypoints: &[Vec<f64>],
    cfg: &SimConfig,
    obstacles: Option<&dyn Obstacles>,
) -> Result<Flight, SimError> {
    cfg.validate()?;
    let reference = Reference::new(model.units(), model.link_length(), waypoints, &cfg.limits)?;
    fly(model, reference, cfg, obstacles, &Progress::default())
}

/// The simulation loop behind [`simulate_model`] and [`simulate_with_progress`].
fn fly(
    model: ChainModel,
    reference: Reference,
    cfg: &SimConfig,
    obstacles: Option<&dyn Obstacles>,
    progress: &Progress,
) -> Result<Flight, SimError> {
    let t_ref = reference.duration();
    let mut run = FlightRun::start(model, reference, cfg, obstacles, 0)?;
    let steps = check_budget(model.units(), t_ref, cfg)?;
    run.reserve(steps);
    progress.total.store(steps as u64, Ordering::Relaxed);
    let end = loop {
        progress.done.store(run.steps() as u64, Ordering::Relaxed);
        if let Some(end) = run.advance(true) {
            break end;
        }
    };
    Ok(run.finish(end))
}

impl Sample {
    /// The record of one step.
    pub(super) fn record(
        t: f64,
        units: &[BodyState],
        links: &[BodyState],
        r: &RefPoint,
        out: &ControlOutput,
    ) -> Self {
        let v32 = |v: &V3| [v.x as f32, v.y as f32, v.z as f32];
        Self {
            t,
            units: units.iter().map(BodySample::new).collect(),
            links: links.iter().map(BodySample::new).collect(),
            head_ref: v32(&r.p),
            links_ref: r
                .links
                .iter()
                .map(|l| [l.pitch as f32, l.yaw as f32])
                .collect(),
            links_meas: out
                .link_angles
                .iter()
                .map(|&(p, y)| [p as f32, y as f32])
                .collect(),
            thrust: out.commands.iter().map(|c| c.thrust as f32).collect(),
            attitude_cmd: out
                .attitude_cmd
                .iter()
                .map(|a| [a[0] as f32, a[1] as f32, a[2] as f32])
                .collect(),
            head_accel: v32(&out.head_accel),
        }
    }
}
