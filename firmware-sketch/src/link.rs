//! The link this unit leads: its on-board rigid-body model and its attitude loop.
//!
//! Unit `i` (1-based) is the front end of link `i`, which joins unit `i` to
//! unit `i + 1`; the tail unit `N` leads no link and tracks link `N - 1`, the
//! one it trails. A shape command therefore gives each unit one direction to
//! reach: the pitch `theta` and yaw `psi` of its link in the world frame
//! (docs/model.md), i.e. the desired attitude `R_d = Rz(psi) Ry(theta)` whose
//! body x axis is the link direction (`aerial_chain_core::control::link_attitude`).
//!
//! The loop is the core's Lee-Leok-McClamroch SO(3) controller
//! (`aerial_chain_core::control::AttitudeController`) at [`DT`] against the core's f32
//! rigid-body integrator (`aerial_chain_core::control::step_attitude`), standing in for
//! the real link. Forces at a link's two ends cannot twist it about its own
//! axis, so the twist axis (body x) gets no attitude gain, only rate damping;
//! the error that counts is the angle between the link's direction and the
//! target direction.

use aerial_chain_core::control::{
    link_angles, link_attitude, step_attitude, AttitudeController, AttitudeGains, AttitudeOutput,
    AttitudeSetpoint, AttitudeState, Mat3, Vec3,
};

/// Control period: 500 Hz.
pub const DT: f32 = 0.002;
/// Mass of one unit (kg), used for the link's inertia.
const UNIT_MASS: f32 = 1.0;
/// Each unit's own moment of inertia about any axis (kg m^2).
const UNIT_INERTIA: f32 = 0.01;
/// Closed-loop natural frequency of the pitch and yaw axes (rad/s).
const BANDWIDTH: f32 = 5.0;
/// Closed-loop damping ratio.
const DAMPING: f32 = 1.0;
/// Largest moment the two units' thrust differences put on the link about its
/// pitch and yaw axes (N m), and the small twist moment (N m).
const MAX_MOMENT: Vec3 = Vec3::new(0.2, 2.0, 2.0);

/// The link's attitude loop: model state and controller.
pub struct LinkLoop {
    /// The rigid-body state of the on-board model.
    state: AttitudeState,
    /// The geometric attitude controller.
    controller: AttitudeController,
}

impl LinkLoop {
    /// A loop for a link of length `link_length` (m) that starts at rest
    /// pointing along `(pitch, yaw)` (rad).
    pub fn new(link_length: f32, pitch: f32, yaw: f32) -> Self {
        // Two point-mass units at the link's ends plus their own inertia.
        let half = 0.5 * link_length;
        let across = 2.0 * UNIT_MASS * half * half + 2.0 * UNIT_INERTIA;
        let inertia_diag = Vec3::new(2.0 * UNIT_INERTIA, across, across);
        let mut gains = AttitudeGains::from_bandwidth(
            inertia_diag,
            Vec3::new(0.0, BANDWIDTH, BANDWIDTH),
            DAMPING,
        );
        // No attitude gain about the twist axis; damp the twist rate only.
        gains.k_w.x = 2.0 * DAMPING * BANDWIDTH * inertia_diag.x;
        Self {
            state: AttitudeState::at_rest(link_attitude(pitch, yaw)),
            controller: AttitudeController::new(
                gains,
                Mat3::from_diagonal(&inertia_diag),
                MAX_MOMENT,
            ),
        }
    }

    /// One control period: controller, then the model integrated over [`DT`].
    pub fn step(&mut self, sp: &AttitudeSetpoint) -> AttitudeOutput {
        let out = self.controller.control(&self.state, sp);
        self.state = step_attitude(&self.state, &out.moment, &self.controller.inertia, DT);
        out
    }

    /// The link's current `(pitch, yaw)` (rad).
    pub fn angles(&self) -> (f32, f32) {
        link_angles(&self.state.r)
    }

    /// Angle between the link's direction and the direction `(pitch, yaw)` (rad).
    pub fn direction_error(&self, pitch: f32, yaw: f32) -> f32 {
        let d: Vec3 = self.state.r.column(0).into_owned();
        let t: Vec3 = link_attitude(pitch, yaw).column(0).into_owned();
        libm::atan2f(d.cross(&t).norm(), d.dot(&t))
    }

    /// The link's turn rate: its angular velocity without the twist (rad/s).
    pub fn turn_rate(&self) -> f32 {
        let w = self.state.w;
        libm::sqrtf(w.y * w.y + w.z * w.z)
    }
}

/// The setpoint of a direction `(pitch, yaw)` moving at `(pitch_rate, yaw_rate)`:
/// `R_d = Rz(yaw) Ry(pitch)` and its body rate
/// `W_d = R_d^T (yaw_rate e_z + pitch_rate Rz(yaw) e_y)
///      = (-sin(pitch) yaw_rate, pitch_rate, cos(pitch) yaw_rate)`.
pub fn setpoint(pitch: f32, yaw: f32, pitch_rate: f32, yaw_rate: f32) -> AttitudeSetpoint {
    let (s, c) = libm::sincosf(pitch);
    AttitudeSetpoint {
        r_d: link_attitude(pitch, yaw),
        w_d: Vec3::new(-s * yaw_rate, pitch_rate, c * yaw_rate),
        dw_d: Vec3::zeros(),
    }
}
