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
use std::time::Instant;

use aerial_chain_core::control::{desired_attitude, Vec3};
use aerial_chain_core::kinematics::Points;
use aerial_chain_core::validity::visit_pairs;
use aerial_chain_core::{ChainParams, MAX_UNITS};
use nalgebra::{UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

use super::controller::ControlOutput;
use super::controller::{ChainController, ControllerConfig};
use super::dynamics::{Actuator, BodyState, ChainDynamics, DynamicsError, V3};
use super::model::ChainModel;
use super::reference::{RefPoint, Reference, ReferenceError, ReferenceLimits};
use super::{all_positive, SettingsError};

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
    fn gust_force(&self, i: usize, t: f64) -> V3 {
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
        self.limits.validate()
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

/// Decides when the clearance must be measured again, and keeps the minimum.
///
/// Why skipping is safe: every point of the chain's bodies moves no farther than its
/// farthest unit centre (a link is the segment between two centres, and a point of a
/// segment moves by a convex combination of its ends' motions), and the distance to
/// the map changes no faster than the point moves. So at any step the clearance is at
/// least the last measured one minus the largest centre motion since; a step is
/// skipped only when that floor is above both 0 and the minimum so far less
/// [`CLEARANCE_TOLERANCE`].
#[derive(Default)]
struct ClearanceWatch {
    /// Unit centres and clearance at the last measurement.
    last: Option<(Vec<V3>, f64)>,
    /// Smallest clearance, where, and when.
    min: Option<(f64, String, f64)>,
}

impl ClearanceWatch {
    /// Measures the clearance of `centres` at time `t` if it could be a new minimum
    /// or a contact.
    fn observe(&mut self, obs: &dyn Obstacles, centres: Vec<V3>, t: f64) {
        if let Some((prev, c)) = &self.last {
            let moved = prev
                .iter()
                .zip(&centres)
                .map(|(a, b)| (a - b).norm())
                .fold(0.0, f64::max);
            let floor = c - moved;
            let min = self.min.as_ref().map_or(f64::INFINITY, |m| m.0);
            if moved < obs.check_spacing() && floor > (min - CLEARANCE_TOLERANCE).max(0.0) {
                return;
            }
        }
        let (c, at) = obs.clearance(&centres);
        if self.min.as_ref().is_none_or(|m| c < m.0) {
            self.min = Some((c, at, t));
        }
        self.last = Some((centres, c));
    }
}

/// Bytes one recorded step of an `n`-unit chain takes, about.
fn sample_bytes(n: usize) -> f64 {
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

/// Angle between two unit vectors (rad), robust near 0 and pi.
fn angle_between(a: &V3, b: &V3) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
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
    cfg.validate()?;
    model.validate()?;
    let params = model.params;
    let n = model.units();
    let start = &reference.zeta(0.0);
    let mut dynamics = ChainDynamics::new(
        model,
        V3::new(start[0], start[1], start[2]),
        &start[3..],
        1.0 / cfg.rate,
    )?;
    let mut controller = start_in_trim(model, cfg, &mut dynamics, &reference)?;
    let goal = Goal::of(&reference, n);
    let t_ref = reference.duration();
    let steps = check_budget(n, t_ref, cfg)?;
    progress.total.store(steps as u64, Ordering::Relaxed);

    let wall = Instant::now();
    let mut tally = Tally::new(&params, steps);
    let end = run_steps(
        &mut dynamics,
        &mut controller,
        &reference,
        &goal,
        cfg,
        obstacles,
        progress,
        &mut tally,
    );
    let wall_seconds = wall.elapsed().as_secs_f64();
    let report = tally.report(n, cfg, t_ref, end, controller.mpc_counts(), wall_seconds);
    Ok(Flight {
        params,
        reference,
        samples: tally.samples,
        report,
    })
}

/// Puts the chain in trim: each unit tilted as the controller wants it at rest and its
/// motors already producing what it asks (a chain hovering in its start
/// configuration). Returns a fresh controller to fly with.
fn start_in_trim(
    model: ChainModel,
    cfg: &SimConfig,
    dynamics: &mut ChainDynamics,
    reference: &Reference,
) -> Result<ChainController, SimError> {
    let new_controller = || ChainController::new(model, cfg.controller);
    let first = new_controller()?.step(0.0, &dynamics.unit_states(), reference);
    for (i, f) in first.forces.iter().enumerate() {
        let r = desired_attitude(
            &Vec3::new(f.x as f32, f.y as f32, f.z as f32),
            first.attitude_cmd[i][2] as f32,
        );
        dynamics.set_unit_attitude(i, &r.map(|x| x as f64));
    }
    let trim = new_controller()?.step(0.0, &dynamics.unit_states(), reference);
    let act: Vec<Actuator> = trim
        .commands
        .iter()
        .map(|c| Actuator {
            thrust: c.thrust,
            moment: c.moment,
        })
        .collect();
    dynamics.set_actuators(&act);
    Ok(new_controller()?)
}

/// Where the flight should end: the last waypoint's head and link directions.
struct Goal {
    head: V3,
    link_dirs: Vec<V3>,
}

impl Goal {
    fn of(reference: &Reference, n: usize) -> Self {
        let end = reference.end();
        Self {
            head: V3::new(end[0], end[1], end[2]),
            link_dirs: (0..n - 1)
                .map(|k| super::dynamics::link_direction(end[4 + 2 * k], end[5 + 2 * k]))
                .collect(),
        }
    }
}

/// How the stepping loop ended.
struct LoopEnd {
    completed: Option<f64>,
    diverged: bool,
}

/// Steps physics and control until the chain has settled at the goal, diverged, or
/// run out of time, recording every step into `tally`.
#[allow(clippy::too_many_arguments)]
fn run_steps(
    dynamics: &mut ChainDynamics,
    controller: &mut ChainController,
    reference: &Reference,
    goal: &Goal,
    cfg: &SimConfig,
    obstacles: Option<&dyn Obstacles>,
    progress: &Progress,
    tally: &mut Tally,
) -> LoopEnd {
    let dt = 1.0 / cfg.rate;
    let t_ref = reference.duration();
    let t_max = t_ref.max(cfg.min_time) + cfg.settle_time;
    let mut at_goal_since: Option<f64> = None;
    let mut step = 0usize;
    loop {
        let t = step as f64 * dt;
        progress.done.store(step as u64, Ordering::Relaxed);
        let units = dynamics.unit_states();
        let out = controller.step(t, &units, reference);
        let r = reference.sample(t);
        let (e_head, at_goal) = tally.observe(&units, &r, goal, cfg);
        if let Some(obs) = obstacles {
            tally
                .watch
                .observe(obs, units.iter().map(|u| u.p).collect(), t);
        }
        tally
            .samples
            .push(Sample::record(t, &units, &dynamics.link_states(), &r, &out));
        if at_goal && t >= t_ref - cfg.settle_hold {
            let since = *at_goal_since.get_or_insert(t);
            if t >= t_ref.max(cfg.min_time) && t - since >= cfg.settle_hold {
                return LoopEnd {
                    completed: Some(since),
                    diverged: false,
                };
            }
        } else {
            at_goal_since = None;
        }
        let finite = units.iter().all(|u| u.p.iter().all(|v| v.is_finite()));
        if e_head > cfg.divergence || !finite {
            return LoopEnd {
                completed: None,
                diverged: true,
            };
        }
        if t >= t_max {
            return LoopEnd {
                completed: None,
                diverged: false,
            };
        }
        for i in 0..units.len() {
            dynamics.set_external_force(i, cfg.gust_force(i, t));
        }
        if !dynamics.step(&out.commands) {
            return LoopEnd {
                completed: None,
                diverged: true,
            };
        }
        step += 1;
    }
}

/// What the loop accumulates: tracking errors, limit excursions, self and map
/// clearance, and the recorded samples.
struct Tally {
    params: ChainParams,
    samples: Vec<Sample>,
    head_sq: f64,
    head_max: f64,
    link_sq: f64,
    link_max: f64,
    link_count: usize,
    limits: LimitExcursions,
    watch: ClearanceWatch,
    min_self_gap: f64,
}

impl Tally {
    fn new(params: &ChainParams, steps: usize) -> Self {
        Self {
            params: *params,
            samples: Vec::with_capacity(steps),
            head_sq: 0.0,
            head_max: 0.0,
            link_sq: 0.0,
            link_max: 0.0,
            link_count: 0,
            limits: LimitExcursions::default(),
            watch: ClearanceWatch::default(),
            min_self_gap: f64::INFINITY,
        }
    }

    /// Tracking errors, limits and self-contact of one step; returns the head's
    /// tracking error and whether the chain is at the goal.
    fn observe(
        &mut self,
        units: &[BodyState],
        r: &RefPoint,
        goal: &Goal,
        cfg: &SimConfig,
    ) -> (f64, bool) {
        let n = units.len();
        let e_head = (units[0].p - r.p).norm();
        self.head_sq += e_head * e_head;
        self.head_max = self.head_max.max(e_head);
        let dirs: Vec<V3> = (0..n - 1)
            .map(|k| (units[k].p - units[k + 1].p).normalize())
            .collect();
        let mut at_goal = (units[0].p - goal.head).norm() <= cfg.goal_tolerance;
        for (k, dir) in dirs.iter().enumerate() {
            let lr = &r.links[k];
            let e = angle_between(dir, &super::dynamics::link_direction(lr.pitch, lr.yaw));
            self.link_sq += e * e;
            self.link_count += 1;
            self.link_max = self.link_max.max(e);
            at_goal &= angle_between(dir, &goal.link_dirs[k]) <= cfg.angle_tolerance;
        }
        self.observe_limits(&dirs, 1.0 / cfg.rate);
        self.observe_self_gap(units);
        (e_head, at_goal)
    }

    /// Pitch and bend beyond the chain's limits.
    fn observe_limits(&mut self, dirs: &[V3], dt: f64) {
        let theta_max = self.params.theta_max as f64;
        let beta_max = self.params.beta_max as f64;
        let limits = &mut self.limits;
        let mut beyond = false;
        for k in 0..dirs.len() {
            let pitch = (-dirs[k].z).clamp(-1.0, 1.0).asin();
            let ex = pitch.abs() - theta_max;
            if ex > 0.0 {
                beyond = true;
                limits.max_pitch_excess_deg = limits.max_pitch_excess_deg.max(ex.to_degrees());
            }
            if k + 1 < dirs.len() {
                let ex = angle_between(&dirs[k], &dirs[k + 1]) - beta_max;
                if ex > 0.0 {
                    beyond = true;
                    limits.max_bend_excess_deg = limits.max_bend_excess_deg.max(ex.to_degrees());
                }
            }
        }
        if beyond {
            limits.time_beyond += dt;
        }
    }

    /// Self-contact of the flown chain (core's exact pair test, relative positions).
    fn observe_self_gap(&mut self, units: &[BodyState]) {
        let mut pts: Points = [Vector3::zeros(); MAX_UNITS];
        for (i, u) in units.iter().enumerate() {
            let d = u.p - units[0].p;
            pts[i] = Vector3::new(d.x as f32, d.y as f32, d.z as f32);
        }
        let min_self_gap = &mut self.min_self_gap;
        visit_pairs(&self.params, units.len(), &pts, |_, _, gap| {
            *min_self_gap = min_self_gap.min(gap as f64);
            true
        });
    }

    fn report(
        &self,
        n: usize,
        cfg: &SimConfig,
        t_ref: f64,
        end: LoopEnd,
        (mpc_solves, mpc_failures): (usize, usize),
        wall_seconds: f64,
    ) -> FlightReport {
        let count = self.samples.len().max(1) as f64;
        let simulated_time = self.samples.last().map_or(0.0, |s| s.t);
        let min_clear = self.watch.min.as_ref();
        FlightReport {
            units: n,
            rate_hz: cfg.rate,
            planned_duration: t_ref,
            time_to_complete: end.completed,
            reached_goal: end.completed.is_some(),
            simulated_time,
            head_rms: (self.head_sq / count).sqrt(),
            head_max: self.head_max,
            link_rms_deg: (self.link_sq / self.link_count.max(1) as f64)
                .sqrt()
                .to_degrees(),
            link_max_deg: self.link_max.to_degrees(),
            min_clearance: min_clear.map(|m| m.0),
            min_clearance_at: min_clear.map(|m| m.1.clone()),
            min_clearance_time: min_clear.map(|m| m.2),
            contact: min_clear.is_some_and(|m| m.0 <= 0.0),
            min_self_gap: self.min_self_gap,
            self_contact: self.min_self_gap <= 0.0,
            limits: self.limits,
            mpc_solves,
            mpc_failures,
            diverged: end.diverged,
            wall_seconds,
            realtime_factor: if wall_seconds > 0.0 {
                simulated_time / wall_seconds
            } else {
                f64::INFINITY
            },
        }
    }
}

impl Sample {
    /// The record of one step.
    fn record(
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
