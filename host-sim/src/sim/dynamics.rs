//! The chain's rigid multibody dynamics, on rapier3d's reduced-coordinate multibodies.
//!
//! Bodies: N units (mass, inertia; thrust along body z and body moments, both through a
//! first-order motor lag and clamped to the unit's limits) and N - 1 links (uniform
//! tubes), joined by spherical joints at the unit centres (paper assumption A1).
//! Gravity acts along -z; external disturbance forces can be put on each unit
//! (gusts). No colliders: contact with the map is measured, not simulated.
//!
//! Two formulations of the same mechanics ([`Formulation`]):
//! - [`Formulation::Lumped`] (the default): because every joint is at a unit's centre
//!   of mass, a unit's rotation is decoupled from the rest of the chain (joint forces
//!   act through its centre, so they exert no moment on it) and its centre moves with
//!   the joint point. So the multibody holds only the N - 1 links, each carrying the
//!   point mass of the unit at its back end (link 1 also the head), joined by
//!   spherical joints; each unit's thrust is applied at its joint point and each
//!   unit's attitude is integrated on its own by the core's rigid-body integrator
//!   ([`aerial_chain_core::control::step_attitude`]). Same equations of motion, half the
//!   multibody's degrees of freedom: 6 + 3(N - 2) instead of 6 + 6(N - 1), and the
//!   engine's dense mass-matrix work shrinks accordingly (about 4x for N = 6).
//! - [`Formulation::Full`]: every unit and every link a rapier body in one multibody
//!   tree, unit 1 (free-floating root) - link 1 - unit 2 - ... - unit N, with link
//!   `k`'s front end (local `+x l/2`) on unit `k` and its back end on unit `k + 1`.
//!   Kept as the reference the lumped model is tested against.
//!
//! In both, a link's body x axis is docs/model.md's link direction `d`. rapier3d works
//! in `f32` with glam types; this module converts at its boundary to the `f64`
//! nalgebra types the rest of the simulation uses.

use aerial_chain_core::control::{step_attitude, AttitudeState, Mat3, Vec3};
use aerial_chain_core::kinematics::{link_direction_of, positions_into};
use nalgebra::{Matrix3, Vector3};
use rapier3d::glamx::Vec3 as GVec3;
use rapier3d::prelude::{MultibodyJointHandle, PhysicsWorld, RigidBodyHandle};

use super::bodies::{
    build_full, build_lumped, from_glam, from_glam_rotation, to_glam, ChainBodies,
};
use super::model::ChainModel;

/// World-frame 3-vector in `f64`.
pub type V3 = Vector3<f64>;
/// 3x3 matrix in `f64` (rotations are body-to-world).
pub type M3 = Matrix3<f64>;

/// The state of one rigid body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyState {
    /// Centre of mass position in the world (m).
    pub p: V3,
    /// Velocity of the centre of mass in the world (m/s).
    pub v: V3,
    /// Rotation body-to-world.
    pub r: M3,
    /// Angular velocity in the world frame (rad/s).
    pub w: V3,
}

impl BodyState {
    /// Angular velocity in the body frame.
    pub fn w_body(&self) -> V3 {
        self.r.transpose() * self.w
    }
}

/// What a unit is asked to produce.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct UnitCommand {
    /// Collective thrust along body z (N).
    pub thrust: f64,
    /// Moment in the body frame (N m).
    pub moment: V3,
}

/// What a unit's motors produce now (after the lag and the limits).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Actuator {
    /// Collective thrust (N).
    pub thrust: f64,
    /// Body moment (N m).
    pub moment: V3,
}

/// Why the dynamics cannot be built.
#[derive(Debug, thiserror::Error)]
pub enum DynamicsError {
    /// The model's numbers are not physical.
    #[error("chain model: {0}")]
    Model(super::SettingsError),
    /// The start configuration does not fit the chain.
    #[error("start configuration: shape has {got} angles, expected {expected}")]
    ShapeLength {
        /// Angles given.
        got: usize,
        /// Angles of a shape of this chain (`2N - 1`).
        expected: usize,
    },
    /// The start configuration has a number that is not finite.
    #[error("start configuration: non-finite number")]
    NotFinite,
    /// A physics time step outside (0, 0.01] s.
    #[error("start configuration: time step {0} s must lie in (0, 0.01]")]
    TimeStep(f64),
    /// rapier refused a joint.
    #[error("the physics engine refused joint {0}")]
    Joint(usize),
}

/// How the chain's mechanics are put into the engine (see the module documentation).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Formulation {
    /// Links in the multibody carrying the units' masses; unit attitudes integrated
    /// separately (exact under assumption A1, about 4x faster for N = 6).
    #[default]
    Lumped,
    /// Every unit and link a body of the multibody.
    Full,
}

/// The simulated chain.
pub struct ChainDynamics {
    world: PhysicsWorld,
    formulation: Formulation,
    /// Full: the unit bodies.
    units: Vec<RigidBodyHandle>,
    /// Lumped: every unit's attitude (core `f32` integrator).
    unit_attitude: Vec<AttitudeState>,
    unit_inertia: Mat3,
    links: Vec<RigidBodyHandle>,
    /// Lumped: each link body's centre of mass on its axis (local x, m).
    link_com: Vec<f64>,
    _joints: Vec<MultibodyJointHandle>,
    actuators: Vec<Actuator>,
    external: Vec<V3>,
    model: ChainModel,
    dt: f64,
    time: f64,
}

/// Unit centres of a configuration (`f64` forward kinematics, docs/model.md Eq. 2).
pub fn unit_positions(l: f64, head: V3, eta: &[f64]) -> Vec<V3> {
    let mut p = vec![V3::zeros(); eta.len().saturating_sub(1) / 2 + 1];
    positions_into(l, head, eta, &mut p);
    p
}

/// docs/model.md's link direction `[cos psi cos theta, sin psi cos theta, -sin theta]`.
pub fn link_direction(pitch: f64, yaw: f64) -> V3 {
    link_direction_of(pitch, yaw)
}

/// `Rz(yaw) Ry(pitch)`: a link's attitude with body x along its direction.
pub fn link_rotation(pitch: f64, yaw: f64) -> M3 {
    let (sy, cy) = yaw.sin_cos();
    let (sp, cp) = pitch.sin_cos();
    M3::new(cy * cp, -sy, cy * sp, sy * cp, cy, sy * sp, -sp, 0.0, cp)
}

/// `Rz(yaw)`.
pub fn yaw_rotation(yaw: f64) -> M3 {
    let (s, c) = yaw.sin_cos();
    M3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

impl ChainDynamics {
    /// The chain at rest in the configuration `(head, eta)` (`eta` has `2N - 1`
    /// numbers: head yaw, then each link's pitch and yaw), every unit level with the
    /// head's yaw, integrated with time step `dt` (s), in the default formulation.
    pub fn new(model: ChainModel, head: V3, eta: &[f64], dt: f64) -> Result<Self, DynamicsError> {
        Self::with_formulation(model, head, eta, dt, Formulation::default())
    }

    /// [`ChainDynamics::new`] in a chosen formulation.
    pub fn with_formulation(
        model: ChainModel,
        head: V3,
        eta: &[f64],
        dt: f64,
        formulation: Formulation,
    ) -> Result<Self, DynamicsError> {
        model.validate().map_err(DynamicsError::Model)?;
        let n = model.units();
        if eta.len() != 2 * n - 1 {
            return Err(DynamicsError::ShapeLength {
                got: eta.len(),
                expected: 2 * n - 1,
            });
        }
        if !head.iter().chain(eta.iter()).all(|v| v.is_finite()) {
            return Err(DynamicsError::NotFinite);
        }
        if !(dt.is_finite() && dt > 0.0 && dt <= 0.01) {
            return Err(DynamicsError::TimeStep(dt));
        }
        let l = model.link_length();
        let mut world = PhysicsWorld::new();
        world.gravity = GVec3::new(0.0, 0.0, -(model.gravity as f32));
        world.integration_parameters.dt = dt as f32;
        // No contacts, limits or motors: the multibody needs no constraint iterations.
        world.integration_parameters.num_solver_iterations = 1;
        let p = unit_positions(l, head, eta);
        let r_unit = yaw_rotation(eta[0]);
        let ui = model.unit.inertia;
        let unit_inertia =
            Mat3::from_diagonal(&Vec3::new(ui[0] as f32, ui[1] as f32, ui[2] as f32));
        let link_rot: Vec<M3> = (0..n - 1)
            .map(|k| link_rotation(eta[1 + 2 * k], eta[2 + 2 * k]))
            .collect();
        let ChainBodies {
            units,
            links,
            joints,
            link_com,
        } = match formulation {
            Formulation::Full => build_full(&mut world, &model, &p, &r_unit, &link_rot)?,
            Formulation::Lumped => build_lumped(&mut world, &model, &p, &link_rot)?,
        };
        // rapier gives every multibody angular degree of freedom a default damping of
        // 0.1 N m s/rad: larger than a unit's own inertia can ignore (it would couple
        // a unit's spin to its links through the joint). The joints here are ideal.
        if let Some(&h) = joints.first() {
            if let Some((mb, _)) = world.multibody_joints.get_mut(h) {
                mb.damping_mut().fill(0.0);
            }
        }
        let r0 = Mat3::from_fn(|i, j| r_unit[(i, j)] as f32);
        let unit_attitude = match formulation {
            Formulation::Lumped => vec![AttitudeState::at_rest(r0); n],
            Formulation::Full => Vec::new(),
        };
        Ok(Self {
            world,
            formulation,
            units,
            unit_attitude,
            unit_inertia,
            links,
            link_com,
            _joints: joints,
            actuators: vec![Actuator::default(); n],
            external: vec![V3::zeros(); n],
            model,
            dt,
            time: 0.0,
        })
    }

    /// The formulation in use.
    pub fn formulation(&self) -> Formulation {
        self.formulation
    }

    /// The model simulated.
    pub fn model(&self) -> &ChainModel {
        &self.model
    }

    /// Simulated time (s).
    pub fn time(&self) -> f64 {
        self.time
    }

    /// The integration time step (s).
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// Sets every unit's produced thrust and moment at once (no lag), e.g. to start
    /// in hover.
    pub fn set_actuators(&mut self, act: &[Actuator]) {
        for (a, b) in self.actuators.iter_mut().zip(act) {
            *a = *b;
        }
    }

    /// Sets unit `i`'s attitude (body-to-world; re-orthonormalised), keeping its rate.
    /// Only the lumped formulation can (a full multibody's unit attitudes are joint
    /// coordinates); returns whether it was set.
    pub fn set_unit_attitude(&mut self, i: usize, r: &M3) -> bool {
        match (self.formulation, self.unit_attitude.get_mut(i)) {
            (Formulation::Lumped, Some(a)) if r.iter().all(|v| v.is_finite()) => {
                a.r = aerial_chain_core::control::orthonormalize(&Mat3::from_fn(|row, col| {
                    r[(row, col)] as f32
                }));
                true
            }
            _ => false,
        }
    }

    /// What each unit's motors produce now.
    pub fn actuators(&self) -> &[Actuator] {
        &self.actuators
    }

    /// Sets the external force (world frame, N) acting on unit `i`'s centre from now
    /// on (a gust; zero to remove it). Out-of-range `i` is ignored.
    pub fn set_external_force(&mut self, i: usize, f: V3) {
        if let Some(e) = self.external.get_mut(i) {
            *e = if f.iter().all(|v| v.is_finite()) {
                f
            } else {
                V3::zeros()
            };
        }
    }

    /// Which link body carries unit `i` in the lumped formulation, and where (local x).
    fn carrier(&self, i: usize) -> (RigidBodyHandle, f32) {
        let half = (0.5 * self.model.link_length()) as f32;
        if i == 0 {
            (self.links[0], half)
        } else {
            (self.links[i - 1], -half)
        }
    }

    /// State of unit `i` (0-based; unit 0 is the head).
    pub fn unit(&self, i: usize) -> BodyState {
        match self.formulation {
            Formulation::Full => self.state(self.units[i]),
            Formulation::Lumped => {
                let (h, x) = self.carrier(i);
                let b = &self.world.bodies[h];
                let pt = b.position().transform_point(GVec3::new(x, 0.0, 0.0));
                let a = &self.unit_attitude[i];
                let r = M3::from_fn(|r, c| a.r[(r, c)] as f64);
                let w_body = V3::new(a.w.x as f64, a.w.y as f64, a.w.z as f64);
                BodyState {
                    p: from_glam(pt),
                    v: from_glam(b.velocity_at_point(pt)),
                    r,
                    w: r * w_body,
                }
            }
        }
    }

    /// State of link `k` (0-based); its position is the link's midpoint.
    pub fn link(&self, k: usize) -> BodyState {
        self.state(self.links[k])
    }

    /// States of all units, head first.
    pub fn unit_states(&self) -> Vec<BodyState> {
        (0..self.model.units()).map(|i| self.unit(i)).collect()
    }

    /// States of all links.
    pub fn link_states(&self) -> Vec<BodyState> {
        self.links.iter().map(|&h| self.state(h)).collect()
    }

    fn state(&self, h: RigidBodyHandle) -> BodyState {
        let b = &self.world.bodies[h];
        let origin = b.translation();
        BodyState {
            p: from_glam(origin),
            v: from_glam(b.velocity_at_point(origin)),
            r: from_glam_rotation(b.rotation()),
            w: from_glam(b.angvel()),
        }
    }

    /// Advances by one time step with the units commanded by `commands` (missing
    /// entries count as zero thrust). Commands are clamped to the unit's limits and
    /// pass through the motors' first-order lag; non-finite commands count as zero.
    /// Returns false (and stops advancing) once the state has stopped being finite.
    pub fn step(&mut self, commands: &[UnitCommand]) -> bool {
        let u = self.model.unit;
        let alpha = 1.0 - (-self.dt / u.motor_time_constant).exp();
        for (i, a) in self.actuators.iter_mut().enumerate() {
            let c = commands.get(i).copied().unwrap_or_default();
            let thrust = if c.thrust.is_finite() {
                c.thrust.clamp(u.thrust_min, u.thrust_max)
            } else {
                u.thrust_min
            };
            let mut m = if c.moment.iter().all(|v| v.is_finite()) {
                c.moment
            } else {
                V3::zeros()
            };
            for k in 0..3 {
                m[k] = m[k].clamp(-u.max_moment[k], u.max_moment[k]);
            }
            a.thrust += alpha * (thrust - a.thrust);
            a.moment += alpha * (m - a.moment);
        }
        match self.formulation {
            Formulation::Full => {
                for (i, &h) in self.units.iter().enumerate() {
                    let a = self.actuators[i];
                    let b = &mut self.world.bodies[h];
                    let r = from_glam_rotation(b.rotation());
                    let force = r * V3::new(0.0, 0.0, a.thrust) + self.external[i];
                    let torque = r * a.moment;
                    b.reset_forces(false);
                    b.reset_torques(false);
                    b.add_force(to_glam(&force), false);
                    b.add_torque(to_glam(&torque), false);
                }
            }
            Formulation::Lumped => {
                for &h in &self.links {
                    let b = &mut self.world.bodies[h];
                    b.reset_forces(false);
                    b.reset_torques(false);
                }
                let dt = self.dt as f32;
                for i in 0..self.model.units() {
                    let a = self.actuators[i];
                    let att = self.unit_attitude[i];
                    let r = M3::from_fn(|r, c| att.r[(r, c)] as f64);
                    let force = r * V3::new(0.0, 0.0, a.thrust) + self.external[i];
                    let (h, x) = self.carrier(i);
                    let k_of = |i: usize| i.saturating_sub(1);
                    let b = &mut self.world.bodies[h];
                    // The moment about the centre of mass computed here from the pose
                    // (rapier's own world centre of mass is only refreshed inside a step).
                    let pose = *b.position();
                    let arm = pose.transform_vector(GVec3::new(
                        x - self.link_com[k_of(i)] as f32,
                        0.0,
                        0.0,
                    ));
                    let f = to_glam(&force);
                    b.add_force(f, false);
                    b.add_torque(arm.cross(f), false);
                    let m = Vec3::new(a.moment.x as f32, a.moment.y as f32, a.moment.z as f32);
                    self.unit_attitude[i] = step_attitude(&att, &m, &self.unit_inertia, dt);
                }
            }
        }
        self.world.step();
        self.time += self.dt;
        self.is_finite()
    }

    /// Whether every body's state is finite.
    pub fn is_finite(&self) -> bool {
        self.unit_attitude
            .iter()
            .all(|a| a.r.iter().all(|v| v.is_finite()) && a.w.iter().all(|v| v.is_finite()))
            && self.units.iter().chain(self.links.iter()).all(|&h| {
                let b = &self.world.bodies[h];
                b.translation().is_finite()
                    && b.linvel().is_finite()
                    && b.angvel().is_finite()
                    && b.rotation().is_finite()
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use aerial_chain_core::ChainParams;

    fn hover(model: &ChainModel) -> Vec<Actuator> {
        // Each unit carries itself and half of each adjacent link.
        let n = model.units();
        (0..n)
            .map(|i| {
                let links = if i == 0 || i == n - 1 { 1.0 } else { 2.0 };
                Actuator {
                    thrust: (model.unit.mass + 0.5 * links * model.link.mass) * model.gravity,
                    moment: V3::zeros(),
                }
            })
            .collect()
    }

    #[test]
    fn builds_the_chain_where_the_kinematics_put_it() {
        let model = ChainModel::new(ChainParams::new(4));
        let eta = [0.3, 0.1, 0.2, -0.2, -0.4, 0.0, 0.9];
        let mut d = ChainDynamics::new(model, V3::new(1.0, 2.0, 3.0), &eta, 0.002).unwrap();
        let p = unit_positions(0.5, V3::new(1.0, 2.0, 3.0), &eta);
        // Before and after a step (the multibody re-places its bodies from its joint
        // coordinates, which must describe the start configuration).
        for step in 0..2 {
            for (i, pi) in p.iter().enumerate() {
                assert!((d.unit(i).p - pi).norm() < 1e-4, "step {step} unit {i}");
                assert!((d.unit(i).r - yaw_rotation(0.3)).norm() < 1e-5);
            }
            for k in 0..3 {
                let x = d.link(k).r.column(0).into_owned();
                assert!(
                    (x - link_direction(eta[1 + 2 * k], eta[2 + 2 * k])).norm() < 1e-4,
                    "step {step} link {k}"
                );
            }
            d.step(&[]);
        }
    }

    #[test]
    fn free_fall_keeps_the_links_and_falls_at_g() {
        let model = ChainModel::new(ChainParams::new(3));
        let eta = [0.0, 0.3, 0.5, -0.3, -0.5];
        let mut d = ChainDynamics::new(model, V3::new(0.0, 0.0, 10.0), &eta, 0.002).unwrap();
        let zero = vec![UnitCommand::default(); 3];
        for _ in 0..500 {
            assert!(d.step(&zero));
        }
        // Thrust is clamped to thrust_min: acceleration (sum thrust_min - m g) / m.
        let m = model.total_mass();
        let a = (3.0 * model.unit.thrust_min - m * model.gravity) / m;
        // The centre of mass of all bodies (the links sag relative to the units, so
        // the units' mean alone would not do).
        let com = |d: &ChainDynamics| {
            let mu = model.unit.mass;
            let ml = model.link.mass;
            let su: V3 = d.unit_states().iter().map(|s| s.p * mu).sum();
            let sl: V3 = d.link_states().iter().map(|s| s.p * ml).sum();
            (su + sl) / m
        };
        let start = ChainDynamics::new(model, V3::new(0.0, 0.0, 10.0), &eta, 0.002).unwrap();
        let fallen = com(&d) - com(&start);
        // thrust_min is reached through the motor lag from 0, and symplectic Euler
        // lags by a dt: allow a little slack.
        assert!((fallen.z - 0.5 * a * 1.0).abs() < 0.02, "fell {}", fallen.z);
        assert!(fallen.x.abs() < 1e-4 && fallen.y.abs() < 1e-4);
        let s = d.unit_states();
        for k in 0..2 {
            assert!(
                ((s[k].p - s[k + 1].p).norm() - 0.5).abs() < 1e-3,
                "link {k} stretched"
            );
        }
    }

    #[test]
    fn hover_thrust_holds_the_chain() {
        let model = ChainModel::new(ChainParams::new(5));
        let eta = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        let mut d = ChainDynamics::new(model, V3::new(0.0, 0.0, 2.0), &eta, 0.002).unwrap();
        let h = hover(&model);
        d.set_actuators(&h);
        let cmd: Vec<UnitCommand> = h
            .iter()
            .map(|a| UnitCommand {
                thrust: a.thrust,
                moment: V3::zeros(),
            })
            .collect();
        for _ in 0..1000 {
            assert!(d.step(&cmd));
        }
        for (i, s) in d.unit_states().iter().enumerate() {
            assert!(
                (s.p - unit_positions(0.5, V3::new(0.0, 0.0, 2.0), &eta)[i]).norm() < 1e-3,
                "unit {i} drifted to {:?}",
                s.p
            );
        }
    }

    #[test]
    fn a_moment_turns_only_its_unit() {
        // Joints at the unit centres: a unit's moment cannot move the chain.
        let model = ChainModel::new(ChainParams::new(3));
        let eta = [0.0; 5];
        let mut d = ChainDynamics::new(model, V3::new(0.0, 0.0, 2.0), &eta, 0.002).unwrap();
        let h = hover(&model);
        d.set_actuators(&h);
        let mut cmd: Vec<UnitCommand> = h
            .iter()
            .map(|a| UnitCommand {
                thrust: a.thrust,
                moment: V3::zeros(),
            })
            .collect();
        cmd[1].moment = V3::new(0.0, 0.0, 0.01);
        for _ in 0..250 {
            d.step(&cmd);
        }
        let s = d.unit_states();
        assert!(s[1].w.z > 0.1, "unit 2 spins: {:?}", s[1].w);
        assert!(s[0].w.norm() < 1e-3 && s[2].w.norm() < 1e-3);
        assert!((s[1].p - V3::new(-0.5, 0.0, 2.0)).norm() < 1e-3);
    }

    #[test]
    fn lumped_and_full_formulations_agree() {
        // The same open-loop commands (uneven thrusts, moments that tilt the units) on
        // both formulations: the unit centres and attitudes must match.
        let model = ChainModel::new(ChainParams::new(4));
        let eta = [0.2, 0.1, 0.3, -0.2, -0.2, 0.0, 0.6];
        let head = V3::new(0.0, 0.0, 3.0);
        let mut a =
            ChainDynamics::with_formulation(model, head, &eta, 0.002, Formulation::Lumped).unwrap();
        let mut b =
            ChainDynamics::with_formulation(model, head, &eta, 0.002, Formulation::Full).unwrap();
        let h = hover(&model);
        for step in 0..500 {
            let t = step as f64 * 0.002;
            let cmd: Vec<UnitCommand> = h
                .iter()
                .enumerate()
                .map(|(i, x)| UnitCommand {
                    thrust: x.thrust * (1.0 + 0.1 * (3.0 * t + i as f64).sin()),
                    moment: V3::new(0.002 * (i as f64 - 1.5), 0.003 * (2.0 * t).cos(), 0.001),
                })
                .collect();
            a.step(&cmd);
            b.step(&cmd);
        }
        for i in 0..4 {
            let (sa, sb) = (a.unit(i), b.unit(i));
            assert!(
                (sa.p - sb.p).norm() < 2e-3,
                "unit {i}: {:?} vs {:?}",
                sa.p,
                sb.p
            );
            assert!((sa.v - sb.v).norm() < 5e-3, "unit {i} velocity");
            assert!((sa.r - sb.r).norm() < 2e-3, "unit {i} attitude");
            assert!((sa.w - sb.w).norm() < 5e-3, "unit {i} rate");
        }
        assert!((a.unit(0).p - head).norm() > 0.05, "the chain did move");
    }
}
