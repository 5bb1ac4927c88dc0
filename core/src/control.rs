//! The geometric SO(3) attitude controller of Lee, Leok and McClamroch (2010),
//! "Geometric tracking control of a quadrotor UAV on SE(3)", in `f32`, and the rigid-body
//! attitude integrator it is tested against. The SO(3) math it needs lives in
//! [`crate::so3`] and is re-exported here.
//!
//! The same controller serves two bodies of the chain:
//! - a unit's attitude: the desired attitude comes from a thrust direction and a yaw
//!   ([`desired_attitude`]) or from roll, pitch and yaw ([`from_euler_zyx`]);
//! - a link's direction: the desired attitude comes from the planned link pitch and
//!   yaw ([`link_attitude`]); its body x axis is docs/model.md's link direction
//!   `d = [cos psi cos theta, sin psi cos theta, -sin theta]`. A link cannot be twisted
//!   about its own axis by forces at its ends, so a link controller usually sets the
//!   x components of both gains to zero.
//!
//! Controller ([`AttitudeController::control`]), with `R` body-to-world and `W` the
//! body rate in the body frame:
//! ```text
//! e_R = 1/2 vee(R_d^T R - R^T R_d)
//! e_W = W - R^T R_d W_d
//! M   = -k_R e_R - k_W e_W + W x J W - J (hat(W) R^T R_d W_d - R^T R_d dW_d)
//! ```
//! then saturated by scaling the whole vector until every component is within its
//! limit (the direction of `M` is kept).
//!
//! The antipode: when `R` is rotated by exactly 180 degrees from `R_d`,
//! `R_d^T R` is symmetric and `e_R = 0`, so the plain controller sits on an unstable
//! equilibrium (Lee et al.'s "almost global" region is `Psi < 2`). This module keeps
//! the attitude error from vanishing on the far side: when `Psi > 1` (more than 90
//! degrees away) and `|e_R|` is below [`AttitudeController::antipode_min_error`], `e_R`
//! is stretched along its own direction to that length; at the antipode itself, where
//! it has no direction, the rotation axis of `R_d^T R` is used. The stretched error
//! still points along the shortest rotation's axis, so it still turns the body the
//! short way home; near the goal (`Psi <= 1`) the controller is exactly Lee's. Setting
//! the field to 0 gives the plain controller (whose antipode is an unstable
//! equilibrium that any perturbation leaves; both behaviours are tested).
//!
//! [`step_attitude`] integrates a rigid body's attitude under a moment (RK4 on the
//! rates, exponential map on SO(3), re-orthonormalised): the firmware's on-board model
//! and the tests' plant.
//!
//! Everything is plain data and pure functions; no input makes anything here panic or
//! return NaN: non-finite or degenerate inputs fall back to documented values.

use crate::so3::{all_finite3, rotation_axis, TINY};
// Re-exported so a controller's user needs one import for the controller and the
// rotations it is fed.
pub use crate::so3::{
    attitude_error, attitude_error_function, desired_attitude, direction_angles, euler_zyx,
    exp_so3, from_euler_zyx, hat, is_rotation, link_angles, link_attitude, orthonormalize,
    rate_error, rot_x, rot_y, rot_z, rotation_angle, vee, Mat3, Vec3,
};

/// Diagonal gains of the attitude controller (body axes x, y, z).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AttitudeGains {
    /// Attitude gain `k_R` (N m per unit of `e_R`).
    pub k_r: Vec3,
    /// Rate gain `k_W` (N m s / rad).
    pub k_w: Vec3,
}

impl AttitudeGains {
    /// Gains giving each axis of a body with principal inertia `inertia_diag` the
    /// small-angle closed loop of natural frequency `omega` (rad/s) and damping ratio
    /// `zeta`: `k_R = J omega^2`, `k_W = 2 zeta omega J`.
    pub fn from_bandwidth(inertia_diag: Vec3, omega: Vec3, zeta: f32) -> Self {
        let k_r = inertia_diag.component_mul(&omega.component_mul(&omega));
        let k_w = inertia_diag.component_mul(&omega) * (2.0 * zeta);
        Self { k_r, k_w }
    }
}

/// The state of a rigid body's attitude.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AttitudeState {
    /// Rotation body-to-world.
    pub r: Mat3,
    /// Angular velocity in the body frame (rad/s).
    pub w: Vec3,
}

impl AttitudeState {
    /// At rest with attitude `r`.
    pub fn at_rest(r: Mat3) -> Self {
        Self {
            r,
            w: Vec3::zeros(),
        }
    }
}

impl Default for AttitudeState {
    fn default() -> Self {
        Self::at_rest(Mat3::identity())
    }
}

/// What the attitude controller tracks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AttitudeSetpoint {
    /// Desired attitude `R_d` (body-to-world).
    pub r_d: Mat3,
    /// Desired angular velocity `W_d` in the desired body frame (rad/s).
    pub w_d: Vec3,
    /// Desired angular acceleration `dW_d` in the desired body frame (rad/s^2).
    pub dw_d: Vec3,
}

impl AttitudeSetpoint {
    /// Hold attitude `r_d` (zero desired rate and acceleration).
    pub fn hold(r_d: Mat3) -> Self {
        Self {
            r_d,
            w_d: Vec3::zeros(),
            dw_d: Vec3::zeros(),
        }
    }
}

/// The geometric attitude controller's parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AttitudeController {
    /// Gains.
    pub gains: AttitudeGains,
    /// Inertia `J` of the body in its body frame (kg m^2).
    pub inertia: Mat3,
    /// Largest absolute moment about each body axis (N m); the output is scaled down
    /// as a whole until it fits. Non-positive or non-finite components disable the
    /// limit on that axis.
    pub max_moment: Vec3,
    /// Smallest length of `e_R` on the far side (`Psi > 1`); see the module
    /// documentation on the antipode. 0 disables the stretch (plain Lee et al.).
    pub antipode_min_error: f32,
}

/// The controller's output and the errors it saw.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AttitudeOutput {
    /// Moment to apply in the body frame (N m), saturated.
    pub moment: Vec3,
    /// Attitude error `e_R` as used (after the antipode stretch).
    pub e_r: Vec3,
    /// Rate error `e_W`.
    pub e_w: Vec3,
    /// The attitude error function `Psi` in `[0, 2]`.
    pub psi: f32,
    /// Whether the moment was scaled down to fit `max_moment`.
    pub saturated: bool,
    /// False when an input was not finite; the moment is then zero.
    pub valid: bool,
}

impl AttitudeController {
    /// The default antipode stretch: `|e_R| >= 0.25` whenever more than 90 degrees
    /// away (that is, the plain controller's error below about 165.5 degrees).
    pub const DEFAULT_ANTIPODE_MIN_ERROR: f32 = 0.25;

    /// A controller with the default antipode handling.
    pub fn new(gains: AttitudeGains, inertia: Mat3, max_moment: Vec3) -> Self {
        Self {
            gains,
            inertia,
            max_moment,
            antipode_min_error: Self::DEFAULT_ANTIPODE_MIN_ERROR,
        }
    }

    /// One controller step: the moment for `state` tracking `sp` (see the module
    /// documentation for the law). Non-finite inputs give a zero moment with
    /// `valid = false`.
    pub fn control(&self, state: &AttitudeState, sp: &AttitudeSetpoint) -> AttitudeOutput {
        let r = &state.r;
        let w = &state.w;
        let rt_rd = r.transpose() * sp.r_d;
        let e = sp.r_d.transpose() * r;
        let mut e_r = 0.5
            * Vec3::new(
                e[(2, 1)] - e[(1, 2)],
                e[(0, 2)] - e[(2, 0)],
                e[(1, 0)] - e[(0, 1)],
            );
        let psi = 0.5 * (3.0 - e.trace());
        let m = self.antipode_min_error;
        if m > 0.0 && psi > 1.0 {
            let n = e_r.norm();
            if n < m {
                e_r = if n > TINY {
                    e_r * (m / n)
                } else {
                    rotation_axis(&e) * m
                };
            }
        }
        let wd_body = rt_rd * sp.w_d;
        let dwd_body = rt_rd * sp.dw_d;
        let e_w = w - wd_body;
        let j = &self.inertia;
        let mut moment = -self.gains.k_r.component_mul(&e_r) - self.gains.k_w.component_mul(&e_w)
            + w.cross(&(j * w))
            - j * (w.cross(&wd_body) - dwd_body);
        let valid = all_finite3(&moment) && psi.is_finite();
        if !valid {
            return AttitudeOutput {
                moment: Vec3::zeros(),
                e_r: Vec3::zeros(),
                e_w: Vec3::zeros(),
                psi: 0.0,
                saturated: false,
                valid: false,
            };
        }
        let mut scale = 1.0f32;
        for k in 0..3 {
            let lim = self.max_moment[k];
            let a = libm::fabsf(moment[k]);
            if lim.is_finite() && lim > 0.0 && a > lim {
                scale = scale.min(lim / a);
            }
        }
        let saturated = scale < 1.0;
        if saturated {
            moment *= scale;
        }
        AttitudeOutput {
            moment,
            e_r,
            e_w,
            psi: psi.clamp(0.0, 2.0),
            saturated,
            valid,
        }
    }
}

/// One step of length `dt` of a rigid body's attitude under a body moment `moment`
/// held constant over the step: Euler's equations `J dW = M - W x J W` by classical
/// RK4, the attitude by the exponential map of the RK4-weighted mean rate
/// (`R' = R exp(dt * W_mean)`, second order in the rotation), then re-orthonormalised.
///
/// A singular or non-finite inertia, a non-finite moment or a non-positive or
/// non-finite `dt` returns `state` unchanged (re-orthonormalised).
pub fn step_attitude(
    state: &AttitudeState,
    moment: &Vec3,
    inertia: &Mat3,
    dt: f32,
) -> AttitudeState {
    let r = orthonormalize(&state.r);
    let unchanged = AttitudeState {
        r,
        w: if all_finite3(&state.w) {
            state.w
        } else {
            Vec3::zeros()
        },
    };
    if !(dt.is_finite() && dt > 0.0 && all_finite3(moment) && all_finite3(&state.w)) {
        return unchanged;
    }
    let Some(j_inv) = inertia.try_inverse() else {
        return unchanged;
    };
    if !j_inv.iter().all(|v| v.is_finite()) {
        return unchanged;
    }
    let acc = |w: &Vec3| -> Vec3 { j_inv * (moment - w.cross(&(inertia * w))) };
    let w1 = state.w;
    let a1 = acc(&w1);
    let w2 = w1 + a1 * (0.5 * dt);
    let a2 = acc(&w2);
    let w3 = w1 + a2 * (0.5 * dt);
    let a3 = acc(&w3);
    let w4 = w1 + a3 * dt;
    let a4 = acc(&w4);
    let w_new = w1 + (a1 + 2.0 * a2 + 2.0 * a3 + a4) * (dt / 6.0);
    let w_mean = (w1 + 2.0 * w2 + 2.0 * w3 + w4) * (1.0 / 6.0);
    let r_new = orthonormalize(&(r * exp_so3(&(w_mean * dt))));
    if !all_finite3(&w_new) {
        return unchanged;
    }
    AttitudeState { r: r_new, w: w_new }
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::f32::consts::PI;
    use proptest::prelude::*;

    /// A unit-sized quadrotor: inertia, gains (15 rad/s, damping 0.9), moment limits.
    fn unit_controller() -> AttitudeController {
        let jd = Vec3::new(0.0082, 0.0082, 0.0149);
        let gains = AttitudeGains::from_bandwidth(jd, Vec3::new(15.0, 15.0, 8.0), 0.9);
        AttitudeController::new(gains, Mat3::from_diagonal(&jd), Vec3::new(1.0, 1.0, 0.15))
    }

    fn close(a: &Mat3, b: &Mat3, tol: f32) -> bool {
        (a - b).iter().all(|v| libm::fabsf(*v) <= tol)
    }

    fn axis_angle(axis: Vec3, angle: f32) -> Mat3 {
        exp_so3(&(axis.normalize() * angle))
    }

    /// Flies `c` from `s` towards `sp` for `seconds` at 1 kHz; returns the final state
    /// and the largest Psi after `settle` seconds.
    fn fly(
        c: &AttitudeController,
        mut s: AttitudeState,
        sp: &AttitudeSetpoint,
        seconds: f32,
    ) -> AttitudeState {
        let dt = 1e-3;
        let steps = (seconds / dt) as usize;
        for _ in 0..steps {
            let out = c.control(&s, sp);
            assert!(out.valid);
            s = step_attitude(&s, &out.moment, &c.inertia, dt);
            assert!(s.r.iter().all(|v| v.is_finite()) && all_finite3(&s.w));
        }
        s
    }

    #[test]
    fn zero_moment_at_zero_error() {
        let c = unit_controller();
        let r = from_euler_zyx(0.3, -0.2, 1.0);
        let out = c.control(&AttitudeState::at_rest(r), &AttitudeSetpoint::hold(r));
        assert!(out.valid && !out.saturated);
        assert!(out.moment.norm() < 1e-6, "{:?}", out.moment);
        assert!(out.e_r.norm() < 1e-6 && out.e_w.norm() < 1e-6 && out.psi.abs() < 1e-6);
    }

    #[test]
    fn tracking_a_rotating_setpoint_at_zero_error_gives_only_the_feedforward() {
        let c = unit_controller();
        let r = from_euler_zyx(0.1, 0.2, 0.3);
        let w = Vec3::new(0.5, -0.3, 1.0);
        let dw = Vec3::new(0.2, 0.1, -0.4);
        let out = c.control(
            &AttitudeState { r, w },
            &AttitudeSetpoint {
                r_d: r,
                w_d: w,
                dw_d: dw,
            },
        );
        let expected = w.cross(&(c.inertia * w)) + c.inertia * dw;
        assert!((out.moment - expected).norm() < 1e-6);
    }

    #[test]
    fn small_errors_push_back() {
        // A small roll error to the right gives a negative roll moment.
        let c = unit_controller();
        let out = c.control(
            &AttitudeState::at_rest(rot_x(0.1)),
            &AttitudeSetpoint::hold(Mat3::identity()),
        );
        assert!(out.moment.x < 0.0 && out.moment.y.abs() < 1e-6 && out.moment.z.abs() < 1e-6);
        assert!((out.psi - (1.0 - libm::cosf(0.1))).abs() < 1e-5);
    }

    #[test]
    fn saturation_keeps_the_direction() {
        let c = unit_controller();
        let out = c.control(
            &AttitudeState::at_rest(axis_angle(Vec3::new(1.0, 1.0, 1.0), 1.5)),
            &AttitudeSetpoint::hold(Mat3::identity()),
        );
        assert!(out.saturated);
        for k in 0..3 {
            assert!(out.moment[k].abs() <= c.max_moment[k] * (1.0 + 1e-5));
        }
        let raw = -c.gains.k_r.component_mul(&out.e_r);
        assert!(raw.normalize().dot(&out.moment.normalize()) > 1.0 - 1e-5);
    }

    #[test]
    fn the_integrator_keeps_a_free_body_on_so3_and_conserves_momentum() {
        let j = Mat3::from_diagonal(&Vec3::new(0.01, 0.02, 0.03));
        let mut s = AttitudeState {
            r: Mat3::identity(),
            w: Vec3::new(0.1, 3.0, 0.1),
        };
        let l0 = s.r * (j * s.w);
        let e0 = 0.5 * s.w.dot(&(j * s.w));
        for _ in 0..5000 {
            s = step_attitude(&s, &Vec3::zeros(), &j, 1e-3);
        }
        assert!(is_rotation(&s.r, 1e-5));
        let l1 = s.r * (j * s.w);
        assert!(
            (l1 - l0).norm() < 1e-3 * l0.norm(),
            "angular momentum drift {:?} -> {:?}",
            l0,
            l1
        );
        assert!((0.5 * s.w.dot(&(j * s.w)) - e0).abs() < 1e-3 * e0);
        // Constant rate about a principal axis: angle = rate * time.
        let mut s = AttitudeState {
            r: Mat3::identity(),
            w: Vec3::new(0.0, 0.0, 1.0),
        };
        for _ in 0..1000 {
            s = step_attitude(&s, &Vec3::zeros(), &j, 1e-3);
        }
        assert!(close(&s.r, &rot_z(1.0), 1e-4));
    }

    #[test]
    fn converges_from_a_large_error_with_and_without_saturation() {
        let mut c = unit_controller();
        let r_d = from_euler_zyx(0.1, -0.2, 0.5);
        let start = AttitudeState {
            r: axis_angle(Vec3::new(0.3, -0.8, 0.5), 2.5) * r_d,
            w: Vec3::new(1.0, -2.0, 0.5),
        };
        let end = fly(&c, start, &AttitudeSetpoint::hold(r_d), 4.0);
        assert!(attitude_error_function(&end.r, &r_d) < 1e-6 && end.w.norm() < 1e-3);
        c.max_moment = Vec3::zeros(); // no limit
        let end = fly(&c, start, &AttitudeSetpoint::hold(r_d), 4.0);
        assert!(attitude_error_function(&end.r, &r_d) < 1e-6 && end.w.norm() < 1e-3);
    }

    #[test]
    fn tracks_a_moving_setpoint() {
        // Desired attitude spinning about a tilted axis with constant rate; the body
        // starts far away and must lock on.
        let c = unit_controller();
        let w_d = Vec3::new(0.4, -0.3, 1.5);
        let dt = 1e-3;
        let mut s = AttitudeState::at_rest(rot_y(1.0));
        let mut r_d = Mat3::identity();
        for _ in 0..4000 {
            let out = c.control(
                &s,
                &AttitudeSetpoint {
                    r_d,
                    w_d,
                    dw_d: Vec3::zeros(),
                },
            );
            s = step_attitude(&s, &out.moment, &c.inertia, dt);
            r_d = orthonormalize(&(r_d * exp_so3(&(w_d * dt))));
        }
        assert!(attitude_error_function(&s.r, &r_d) < 1e-5);
        assert!(rate_error(&s.r, &s.w, &r_d, &w_d).norm() < 1e-2);
    }

    #[test]
    fn the_antipode_is_left_by_default() {
        // Exactly 180 degrees away, at rest: plain e_R is zero; the stretch still turns
        // the body home.
        let c = unit_controller();
        for axis in [Vec3::x(), Vec3::y(), Vec3::z(), Vec3::new(1.0, -2.0, 0.5)] {
            let r_d = from_euler_zyx(0.2, 0.1, -1.0);
            let r = r_d * axis_angle(axis, PI);
            assert!(
                attitude_error(&r, &r_d).norm() < 1e-5,
                "plain e_R vanishes at the antipode"
            );
            let out = c.control(&AttitudeState::at_rest(r), &AttitudeSetpoint::hold(r_d));
            assert!(out.valid && out.moment.norm() > 1e-3 && out.psi > 1.99);
            let end = fly(
                &c,
                AttitudeState::at_rest(r),
                &AttitudeSetpoint::hold(r_d),
                4.0,
            );
            assert!(
                attitude_error_function(&end.r, &r_d) < 1e-6,
                "axis {axis:?}"
            );
        }
    }

    #[test]
    fn the_plain_controller_sits_at_the_antipode_but_leaves_it_when_perturbed() {
        let mut c = unit_controller();
        c.antipode_min_error = 0.0;
        let r_d = Mat3::identity();
        let r = rot_x(PI);
        let out = c.control(&AttitudeState::at_rest(r), &AttitudeSetpoint::hold(r_d));
        assert!(
            out.moment.norm() < 1e-5,
            "unstable equilibrium: {:?}",
            out.moment
        );
        // A milliradian off, it converges (slowly at first: |e_R| ~ 1e-3).
        let r = rot_x(PI - 1e-3) * rot_y(1e-3);
        let end = fly(
            &c,
            AttitudeState::at_rest(r),
            &AttitudeSetpoint::hold(r_d),
            6.0,
        );
        assert!(attitude_error_function(&end.r, &r_d) < 1e-6);
    }

    #[test]
    fn the_stretch_does_not_change_the_near_side() {
        let c = unit_controller();
        let mut plain = c;
        plain.antipode_min_error = 0.0;
        let r = axis_angle(Vec3::new(1.0, 2.0, 3.0), 1.5); // < 90 degrees
        let sp = AttitudeSetpoint::hold(Mat3::identity());
        assert_eq!(
            c.control(&AttitudeState::at_rest(r), &sp),
            plain.control(&AttitudeState::at_rest(r), &sp)
        );
    }

    #[test]
    fn no_nan_in_the_controller_and_integrator() {
        let nan = f32::NAN;
        // Controller and integrator with NaN inputs: zero moment, flagged; state kept.
        let c = unit_controller();
        let bad = AttitudeState {
            r: Mat3::identity(),
            w: Vec3::new(nan, 0.0, 0.0),
        };
        let out = c.control(&bad, &AttitudeSetpoint::hold(Mat3::identity()));
        assert!(!out.valid && out.moment == Vec3::zeros());
        let s = step_attitude(
            &AttitudeState::default(),
            &Vec3::new(nan, 0.0, 0.0),
            &c.inertia,
            1e-3,
        );
        assert_eq!(s, AttitudeState::default());
        let s = step_attitude(&AttitudeState::default(), &Vec3::x(), &Mat3::zeros(), 1e-3);
        assert_eq!(s, AttitudeState::default());
        let s = step_attitude(&AttitudeState::default(), &Vec3::x(), &c.inertia, -1.0);
        assert_eq!(s, AttitudeState::default());
    }

    #[test]
    fn nearly_orthonormal_input_is_handled() {
        // 1 % scale and shear errors: the controller's output from the raw matrix is
        // finite and close to the projected one's.
        let (_, noisy) = crate::so3::tests::noisy_rotation();
        let p = orthonormalize(&noisy);
        let c = unit_controller();
        let sp = AttitudeSetpoint::hold(Mat3::identity());
        let a = c.control(&AttitudeState::at_rest(noisy), &sp);
        let b = c.control(&AttitudeState::at_rest(p), &sp);
        assert!(a.valid && (a.moment - b.moment).norm() < 0.05 * b.moment.norm().max(1e-3));
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]

        /// From any attitude up to 179 degrees away, with a small initial rate, the
        /// saturated controller brings the body home.
        #[test]
        fn converges_from_random_attitudes(
            ax in -1.0f32..1.0, ay in -1.0f32..1.0, az in -1.0f32..1.0,
            angle_deg in 0.0f32..179.0,
            wx in -1.0f32..1.0, wy in -1.0f32..1.0, wz in -1.0f32..1.0,
            roll in -0.5f32..0.5, pitch in -0.5f32..0.5, yaw in -3.1f32..3.1,
        ) {
            let axis = Vec3::new(ax, ay, az);
            prop_assume!(axis.norm() > 0.1);
            let c = unit_controller();
            let r_d = from_euler_zyx(roll, pitch, yaw);
            let start = AttitudeState { r: r_d * axis_angle(axis, angle_deg.to_radians()), w: Vec3::new(wx, wy, wz) };
            let end = fly(&c, start, &AttitudeSetpoint::hold(r_d), 4.0);
            let psi = attitude_error_function(&end.r, &r_d);
            prop_assert!(psi < 1e-6, "Psi = {psi}");
            prop_assert!(end.w.norm() < 1e-3);
        }

        /// The same without the antipode stretch (plain Lee et al.), up to 179 degrees.
        #[test]
        fn plain_controller_converges_up_to_179_degrees(
            ax in -1.0f32..1.0, ay in -1.0f32..1.0, az in -1.0f32..1.0,
            angle_deg in 90.0f32..179.0,
        ) {
            let axis = Vec3::new(ax, ay, az);
            prop_assume!(axis.norm() > 0.1);
            let mut c = unit_controller();
            c.antipode_min_error = 0.0;
            let end = fly(&c, AttitudeState::at_rest(axis_angle(axis, angle_deg.to_radians())), &AttitudeSetpoint::hold(Mat3::identity()), 5.0);
            prop_assert!(attitude_error_function(&end.r, &Mat3::identity()) < 1e-6);
        }

    }
}
