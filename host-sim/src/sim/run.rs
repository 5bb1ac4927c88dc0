//! One flight, step by step: the chain's dynamics and control stack following a
//! reference, every step recorded and watched (tracking, limits, self and map
//! clearance). [`FlightRun`] is the loop behind `simulate` and its kin, and the
//! simulator of a chain whose reference grows while it flies (the online planner
//! replaces the reference ahead of the chain with [`FlightRun::follow`]).

use std::time::Instant;

use aerial_chain_core::control::{desired_attitude, Vec3};
use aerial_chain_core::kinematics::Points;
use aerial_chain_core::validity::visit_pairs;
use aerial_chain_core::{ChainParams, MAX_UNITS};
use nalgebra::Vector3;

use super::controller::ChainController;
use super::dynamics::{Actuator, BodyState, ChainDynamics, V3};
use super::flight::{
    Flight, FlightReport, LimitExcursions, Obstacles, Sample, SimConfig, SimError,
    CLEARANCE_TOLERANCE,
};
use super::model::ChainModel;
use crate::trajectory::reference::{RefPoint, Reference, ReferenceError};

/// A flight in progress: dynamics, controller, the reference they follow, and what
/// has been recorded.
pub struct FlightRun<'a> {
    model: ChainModel,
    dynamics: ChainDynamics,
    controller: ChainController,
    reference: Reference,
    goal: Goal,
    cfg: SimConfig,
    obstacles: Option<&'a dyn Obstacles>,
    tally: Tally,
    step: usize,
    at_goal_since: Option<f64>,
    wall: Instant,
}

impl<'a> FlightRun<'a> {
    /// The chain of `model` hovering in trim at the start of `reference`, to fly it
    /// with `cfg`, its clearance watched against `obstacles` if given; room is kept
    /// for `steps` recorded steps.
    pub fn start(
        model: ChainModel,
        reference: Reference,
        cfg: &SimConfig,
        obstacles: Option<&'a dyn Obstacles>,
        steps: usize,
    ) -> Result<Self, SimError> {
        cfg.validate()?;
        model.validate()?;
        let start = &reference.zeta(0.0);
        let mut dynamics = ChainDynamics::new(
            model,
            V3::new(start[0], start[1], start[2]),
            &start[3..],
            1.0 / cfg.rate,
        )?;
        let controller = start_in_trim(model, cfg, &mut dynamics, &reference)?;
        let goal = Goal::of(&reference, model.units());
        Ok(Self {
            model,
            dynamics,
            controller,
            reference,
            goal,
            cfg: cfg.clone(),
            obstacles,
            tally: Tally::new(&model.params, steps),
            step: 0,
            at_goal_since: None,
            wall: Instant::now(),
        })
    }

    /// Simulated time of the next step (s).
    pub fn time(&self) -> f64 {
        self.step as f64 / self.cfg.rate
    }

    /// Keeps room for `steps` more recorded steps.
    pub fn reserve(&mut self, steps: usize) {
        self.tally.samples.reserve(steps);
    }

    /// Steps taken.
    pub fn steps(&self) -> usize {
        self.step
    }

    /// The reference followed.
    pub fn reference(&self) -> &Reference {
        &self.reference
    }

    /// The bodies' current states, head first.
    pub fn units(&self) -> Vec<BodyState> {
        self.dynamics.unit_states()
    }

    /// The recorded steps.
    pub fn samples(&self) -> &[Sample] {
        &self.tally.samples
    }

    /// Follows `reference` from now on in place of the reference followed: the online
    /// planner's committed motion, which changes only ahead of the chain (a piece
    /// appended after its end, or joined onto its last motion before the chain begins
    /// to slow down). Refuses one that is not where the followed one is now.
    pub fn follow(&mut self, reference: Reference) -> Result<(), ReferenceError> {
        let t = self.time();
        if !self.reference.agrees_at(&reference, t) {
            return Err(ReferenceError::Join {
                at: t,
                end: self.reference.duration(),
            });
        }
        self.reference = reference;
        self.goal = Goal::of(&self.reference, self.model.units());
        Ok(())
    }

    /// Records the current step, then steps physics and control once. With `finite`,
    /// the flight ends when the chain has settled at the reference's end (after it),
    /// or [`SimConfig::settle_time`] after the reference's end; it always ends when
    /// it diverges. `Some` tells how it ended (the last step recorded, not stepped).
    pub fn advance(&mut self, finite: bool) -> Option<FlightEnd> {
        let cfg = &self.cfg;
        let dt = 1.0 / cfg.rate;
        let t_ref = self.reference.duration();
        let t = self.step as f64 * dt;
        let units = self.dynamics.unit_states();
        let out = self.controller.step(t, &units, &self.reference);
        let r = self.reference.sample(t);
        let (e_head, at_goal) = self.tally.observe(&units, &r, &self.goal, cfg);
        if let Some(obs) = self.obstacles {
            let centres = units.iter().map(|u| u.p).collect();
            self.tally.watch.observe(obs, centres, t);
        }
        let links = self.dynamics.link_states();
        self.tally
            .samples
            .push(Sample::record(t, &units, &links, &r, &out));
        if finite && at_goal && t >= t_ref - cfg.settle_hold {
            let since = *self.at_goal_since.get_or_insert(t);
            if t >= t_ref.max(cfg.min_time) && t - since >= cfg.settle_hold {
                return Some(FlightEnd {
                    completed: Some(since),
                    diverged: false,
                });
            }
        } else {
            self.at_goal_since = None;
        }
        let finite_state = units.iter().all(|u| u.p.iter().all(|v| v.is_finite()));
        if e_head > cfg.divergence || !finite_state {
            return Some(FlightEnd {
                completed: None,
                diverged: true,
            });
        }
        if finite && t >= t_ref.max(cfg.min_time) + cfg.settle_time {
            return Some(FlightEnd {
                completed: None,
                diverged: false,
            });
        }
        for i in 0..units.len() {
            self.dynamics.set_external_force(i, cfg.gust_force(i, t));
        }
        if !self.dynamics.step(&out.commands) {
            return Some(FlightEnd {
                completed: None,
                diverged: true,
            });
        }
        self.step += 1;
        None
    }

    /// The recorded flight, ended as `end` says.
    pub fn finish(self, end: FlightEnd) -> Flight {
        let wall_seconds = self.wall.elapsed().as_secs_f64();
        let n = self.model.units();
        let t_ref = self.reference.duration();
        let mpc = self.controller.mpc_counts();
        let report = self
            .tally
            .report(n, &self.cfg, t_ref, end, mpc, wall_seconds);
        Flight {
            params: self.model.params,
            reference: self.reference,
            samples: self.tally.samples,
            report,
        }
    }
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

/// How a flight ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlightEnd {
    /// When the chain arrived at the goal and stayed (s), if it did.
    pub completed: Option<f64>,
    /// Whether the flight diverged.
    pub diverged: bool,
}

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

/// What the loop accumulates: tracking errors, limit excursions, self and map
/// clearance, and the recorded samples.
pub(super) struct Tally {
    params: ChainParams,
    pub(super) samples: Vec<Sample>,
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
    pub(super) fn new(params: &ChainParams, steps: usize) -> Self {
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

    pub(super) fn report(
        &self,
        n: usize,
        cfg: &SimConfig,
        t_ref: f64,
        end: FlightEnd,
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

/// Angle between two unit vectors (rad), robust near 0 and pi.
fn angle_between(a: &V3, b: &V3) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}
