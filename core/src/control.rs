//! The geometric SO(3) attitude controller of Lee, Leok and McClamroch (2010),
//! "Geometric tracking control of a quadrotor UAV on SE(3)", in `f32`, and the small
//! SO(3) math it needs.
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

use nalgebra::{Matrix3, Vector3};

/// A 3x3 `f32` matrix (rotation matrices are body-to-world).
pub type Mat3 = Matrix3<f32>;
/// A 3-vector of `f32`.
pub type Vec3 = Vector3<f32>;

/// Below this, a norm counts as zero.
const TINY: f32 = 1e-6;

/// The skew-symmetric matrix of `v`: `hat(v) u = v x u`.
pub fn hat(v: &Vec3) -> Mat3 {
    Mat3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// The inverse of [`hat`]: the vector of a skew-symmetric matrix (reads the entries
/// `(2,1)`, `(0,2)`, `(1,0)`).
pub fn vee(m: &Mat3) -> Vec3 {
    Vec3::new(m[(2, 1)], m[(0, 2)], m[(1, 0)])
}

/// Rotation by `a` about the world x axis.
pub fn rot_x(a: f32) -> Mat3 {
    let (s, c) = libm::sincosf(a);
    Mat3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
}

/// Rotation by `a` about the y axis.
pub fn rot_y(a: f32) -> Mat3 {
    let (s, c) = libm::sincosf(a);
    Mat3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)
}

/// Rotation by `a` about the z axis.
pub fn rot_z(a: f32) -> Mat3 {
    let (s, c) = libm::sincosf(a);
    Mat3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

/// `R = Rz(yaw) Ry(pitch) Rx(roll)` (zyx Euler angles, docs/model.md's order).
pub fn from_euler_zyx(roll: f32, pitch: f32, yaw: f32) -> Mat3 {
    rot_z(yaw) * rot_y(pitch) * rot_x(roll)
}

/// The zyx Euler angles `[roll, pitch, yaw]` of `r` (inverse of [`from_euler_zyx`];
/// pitch in `[-pi/2, pi/2]`).
pub fn euler_zyx(r: &Mat3) -> [f32; 3] {
    let pitch = -libm::asinf(r[(2, 0)].clamp(-1.0, 1.0));
    let roll = libm::atan2f(r[(2, 1)], r[(2, 2)]);
    let yaw = libm::atan2f(r[(1, 0)], r[(0, 0)]);
    [roll, pitch, yaw]
}

/// The exponential map: rotation by `|w|` about `w` (Rodrigues' formula, with Taylor
/// coefficients near zero). A non-finite `w` gives the identity.
pub fn exp_so3(w: &Vec3) -> Mat3 {
    if !all_finite3(w) {
        return Mat3::identity();
    }
    let t2 = w.norm_squared();
    let (a, b) = if t2 < 1e-6 {
        // sin t / t and (1 - cos t) / t^2 to O(t^4).
        (1.0 - t2 / 6.0, 0.5 - t2 / 24.0)
    } else {
        let t = libm::sqrtf(t2);
        let (s, c) = libm::sincosf(t);
        (s / t, (1.0 - c) / t2)
    };
    let k = hat(w);
    Mat3::identity() + k * a + k * k * b
}

/// The rotation angle of `r` in `[0, pi]` (from its trace).
pub fn rotation_angle(r: &Mat3) -> f32 {
    libm::acosf(((r.trace() - 1.0) * 0.5).clamp(-1.0, 1.0))
}

/// Whether `r` is a rotation within `tol`: every entry of `r^T r - I` and `det r - 1`
/// within `tol` (and every entry finite).
pub fn is_rotation(r: &Mat3, tol: f32) -> bool {
    if !r.iter().all(|v| v.is_finite()) {
        return false;
    }
    let e = r.transpose() * r - Mat3::identity();
    e.iter().all(|v| libm::fabsf(*v) <= tol) && libm::fabsf(r.determinant() - 1.0) <= tol
}

/// Projects a nearly orthonormal matrix back onto SO(3).
///
/// Symmetric split of the first two columns' orthogonality error (the DCM
/// renormalisation of Premerlani and Bizard), normalisation, an exact Gram-Schmidt
/// finish, and the third column as their cross product (so the result is always a
/// proper rotation, even for a reflection). For a matrix within a few percent of a
/// rotation the result is within second order of the polar projection. A matrix with a
/// non-finite entry gives the identity; degenerate first columns fall back to the
/// nearest usable axis.
pub fn orthonormalize(r: &Mat3) -> Mat3 {
    if !r.iter().all(|v| v.is_finite()) {
        return Mat3::identity();
    }
    let x0: Vec3 = r.column(0).into_owned();
    let y0: Vec3 = r.column(1).into_owned();
    let err = x0.dot(&y0);
    let x1 = x0 - y0 * (0.5 * err);
    let y1 = y0 - x0 * (0.5 * err);
    let x = match normalized(&x1) {
        Some(x) => x,
        None => match normalized(&y1.cross(&r.column(2).into_owned())) {
            Some(x) => x,
            None => Vec3::x(),
        },
    };
    // Gram-Schmidt twice ("twice is enough"): one pass loses orthogonality when y1 is
    // nearly parallel to x; below 1e-4 of its length the remainder is noise.
    let y2 = y1 - x * x.dot(&y1);
    let y = if y2.norm() > 1e-4 * y1.norm() {
        normalized(&y2).unwrap_or_else(|| any_perpendicular(&x))
    } else {
        any_perpendicular(&x)
    };
    let y = normalized(&(y - x * x.dot(&y))).unwrap_or_else(|| any_perpendicular(&x));
    let z = x.cross(&y);
    Mat3::from_columns(&[x, y, z])
}

/// The attitude error `e_R = 1/2 vee(R_d^T R - R^T R_d)` (body frame).
pub fn attitude_error(r: &Mat3, r_d: &Mat3) -> Vec3 {
    let e = r_d.transpose() * r;
    0.5 * Vec3::new(
        e[(2, 1)] - e[(1, 2)],
        e[(0, 2)] - e[(2, 0)],
        e[(1, 0)] - e[(0, 1)],
    )
}

/// The rate error `e_W = W - R^T R_d W_d` (body frame).
pub fn rate_error(r: &Mat3, w: &Vec3, r_d: &Mat3, w_d: &Vec3) -> Vec3 {
    w - r.transpose() * (r_d * w_d)
}

/// The attitude error function `Psi = 1/2 tr(I - R_d^T R)`, in `[0, 2]` for
/// rotations: `1 - cos(angle between R and R_d)`.
pub fn attitude_error_function(r: &Mat3, r_d: &Mat3) -> f32 {
    // tr(R_d^T R) = sum of the elementwise product.
    let tr = r_d.component_mul(r).sum();
    0.5 * (3.0 - tr)
}

/// A desired attitude whose body z axis is the thrust direction `thrust` and whose
/// zyx yaw is `yaw`: the result is exactly `Rz(yaw) Ry(pitch) Rx(roll)` for some roll
/// and pitch (the body x axis is kept perpendicular to the heading's left vector
/// `[-sin yaw, cos yaw, 0]`, as PX4 does).
///
/// Degenerate inputs never give NaN: a zero or non-finite `thrust` means "level"
/// (`+z`), a non-finite `yaw` means 0, and a thrust along the left vector (a 90 degree
/// roll, where yaw is undefined) keeps the body y axis in the heading's vertical plane
/// instead.
pub fn desired_attitude(thrust: &Vec3, yaw: f32) -> Mat3 {
    let z = if all_finite3(thrust) {
        normalized(thrust).unwrap_or_else(Vec3::z)
    } else {
        Vec3::z()
    };
    let yaw = if yaw.is_finite() { yaw } else { 0.0 };
    let (s, c) = libm::sincosf(yaw);
    let left = Vec3::new(-s, c, 0.0);
    let x = match normalized(&left.cross(&z)) {
        Some(x) if left.cross(&z).norm() > 1e-3 => x,
        _ => {
            // z is (anti)parallel to `left`: take y in the plane of the heading and z.
            let heading = Vec3::new(c, s, 0.0);
            let y = normalized(&z.cross(&heading)).unwrap_or_else(|| any_perpendicular(&z));
            y.cross(&z)
        }
    };
    let y = z.cross(&x);
    Mat3::from_columns(&[x, y, z])
}

/// The desired attitude of a link with pitch `pitch` and yaw `yaw`:
/// `Rz(yaw) Ry(pitch)`, whose body x axis is docs/model.md's link direction
/// `[cos yaw cos pitch, sin yaw cos pitch, -sin pitch]` (pointing from the link's back
/// unit to its front unit; see `kinematics::link_direction`). Non-finite angles count
/// as 0.
pub fn link_attitude(pitch: f32, yaw: f32) -> Mat3 {
    let p = if pitch.is_finite() { pitch } else { 0.0 };
    let y = if yaw.is_finite() { yaw } else { 0.0 };
    rot_z(y) * rot_y(p)
}

/// The link pitch and yaw `(theta, psi)` of a body whose x axis is the link direction
/// (inverse of [`link_attitude`] up to the twist about the axis). Straight up or down
/// the yaw is undefined and reported as 0.
pub fn link_angles(r: &Mat3) -> (f32, f32) {
    direction_angles(&r.column(0).into_owned())
}

/// The pitch and yaw `(theta, psi)` of a direction `d` in docs/model.md's convention
/// `d = [cos psi cos theta, sin psi cos theta, -sin theta]` (`d` need not be unit).
/// A zero or non-finite `d` gives `(0, 0)`.
pub fn direction_angles(d: &Vec3) -> (f32, f32) {
    let Some(d) = normalized(d) else {
        return (0.0, 0.0);
    };
    let pitch = -libm::asinf(d.z.clamp(-1.0, 1.0));
    let h = d.x * d.x + d.y * d.y;
    let yaw = if h > 1e-12 {
        libm::atan2f(d.y, d.x)
    } else {
        0.0
    };
    (pitch, yaw)
}

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

fn all_finite3(v: &Vec3) -> bool {
    v.x.is_finite() && v.y.is_finite() && v.z.is_finite()
}

fn normalized(v: &Vec3) -> Option<Vec3> {
    let n = v.norm();
    if n > TINY && n.is_finite() {
        Some(v / n)
    } else {
        None
    }
}

/// A unit vector perpendicular to the unit vector `v`.
fn any_perpendicular(v: &Vec3) -> Vec3 {
    // Cross with the world axis least aligned with v.
    let a = if libm::fabsf(v.x) <= libm::fabsf(v.y) && libm::fabsf(v.x) <= libm::fabsf(v.z) {
        Vec3::x()
    } else if libm::fabsf(v.y) <= libm::fabsf(v.z) {
        Vec3::y()
    } else {
        Vec3::z()
    };
    normalized(&v.cross(&a)).unwrap_or_else(Vec3::x)
}

/// The unit rotation axis of a rotation `e` by (close to) 180 degrees: `e + I = 2 a a^T`,
/// so the column of `e + I` with the largest diagonal entry is along `a`.
fn rotation_axis(e: &Mat3) -> Vec3 {
    let s = e + Mat3::identity();
    let mut k = 0;
    for i in 1..3 {
        if s[(i, i)] > s[(k, k)] {
            k = i;
        }
    }
    normalized(&s.column(k).into_owned()).unwrap_or_else(Vec3::x)
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
    fn hat_and_vee_are_inverse_and_hat_is_the_cross_product() {
        let v = Vec3::new(0.3, -1.2, 2.5);
        let u = Vec3::new(-0.7, 0.1, 0.4);
        assert_eq!(vee(&hat(&v)), v);
        assert!((hat(&v) * u - v.cross(&u)).norm() < 1e-6);
    }

    #[test]
    fn euler_round_trip_and_link_attitude_matches_kinematics() {
        let r = from_euler_zyx(0.2, -0.4, 2.9);
        let [roll, pitch, yaw] = euler_zyx(&r);
        assert!(
            (roll - 0.2).abs() < 1e-5 && (pitch + 0.4).abs() < 1e-5 && (yaw - 2.9).abs() < 1e-5
        );
        for &(p, y) in &[(0.0, 0.0), (0.5, 1.0), (-1.0, -2.5), (1.2, 3.1)] {
            let rl = link_attitude(p, y);
            let d = crate::kinematics::link_direction(p, y);
            assert!((rl.column(0) - d).norm() < 1e-6);
            assert!(is_rotation(&rl, 1e-5));
            let (p2, y2) = link_angles(&rl);
            assert!((p2 - p).abs() < 1e-4 && crate::angle::diff(y, y2).abs() < 1e-4);
        }
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
    fn desired_attitude_is_a_rotation_with_the_right_thrust_and_yaw() {
        let t = Vec3::new(0.3, -0.2, 1.0);
        let r = desired_attitude(&(t * 9.0), 0.7);
        assert!(is_rotation(&r, 1e-5));
        assert!((r.column(2) - t.normalize()).norm() < 1e-6);
        assert!((euler_zyx(&r)[2] - 0.7).abs() < 1e-5);
        // Level thrust gives the pure yaw rotation.
        assert!(close(&desired_attitude(&Vec3::z(), 1.2), &rot_z(1.2), 1e-6));
    }

    #[test]
    fn no_nan_for_degenerate_inputs() {
        let nan = f32::NAN;
        let inf = f32::INFINITY;
        for (t, y) in [
            (Vec3::zeros(), 0.3),
            (Vec3::new(1e-12, 0.0, 0.0), 0.3),
            (Vec3::new(-0.0, 1.0, 0.0), 0.0), // thrust along the left vector
            (Vec3::new(0.0, -1.0, 0.0), 0.0), // and against it
            (Vec3::new(-libm::sinf(0.4), libm::cosf(0.4), 0.0), 0.4),
            (Vec3::new(1.0, 0.0, 0.0), 0.0),  // along the heading
            (Vec3::new(0.0, 0.0, -1.0), 2.0), // upside down
            (Vec3::new(nan, 0.0, 1.0), 0.0),
            (Vec3::new(inf, 0.0, 1.0), nan),
            (Vec3::new(1.0, 1.0, 1.0), inf),
        ] {
            let r = desired_attitude(&t, y);
            assert!(is_rotation(&r, 1e-5), "{t:?} {y}: {r:?}");
        }
        assert!(is_rotation(&link_attitude(nan, inf), 1e-6));
        assert_eq!(direction_angles(&Vec3::zeros()), (0.0, 0.0));
        assert_eq!(direction_angles(&Vec3::new(0.0, 0.0, -2.0)).1, 0.0);
        assert!(is_rotation(&orthonormalize(&Mat3::from_element(nan)), 1e-6));
        assert!(is_rotation(&orthonormalize(&Mat3::zeros()), 1e-6));
        assert!(is_rotation(
            &orthonormalize(&Mat3::from_diagonal(&Vec3::new(1.0, 1.0, -1.0))),
            1e-6
        ));
        assert!(is_rotation(
            &orthonormalize(&Mat3::new(1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)),
            1e-6
        ));
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
        assert_eq!(exp_so3(&Vec3::new(inf, 0.0, 0.0)), Mat3::identity());
    }

    #[test]
    fn nearly_orthonormal_input_is_handled() {
        // 1 % scale and shear errors: the projection is close to the true rotation and
        // the controller's output from the raw matrix is finite and close to the
        // projected one's.
        let r = from_euler_zyx(0.4, -0.3, 1.1);
        let noisy = r + Mat3::new(
            0.01, -0.005, 0.008, 0.004, -0.01, 0.002, -0.006, 0.003, 0.009,
        );
        let p = orthonormalize(&noisy);
        assert!(is_rotation(&p, 1e-5));
        assert!(rotation_angle(&(p.transpose() * r)) < 0.02);
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

        /// The projection onto SO(3) returns a rotation for any finite input, and
        /// leaves rotations alone.
        #[test]
        fn orthonormalize_gives_rotations(v in proptest::collection::vec(-2.0f32..2.0, 9), a in -3.0f32..3.0, b in -1.5f32..1.5) {
            let m = Mat3::from_iterator(v.into_iter());
            prop_assert!(is_rotation(&orthonormalize(&m), 1e-5));
            let r = from_euler_zyx(a, b, a * 0.5);
            prop_assert!(close(&orthonormalize(&r), &r, 1e-5));
        }

        /// The desired attitude is always a rotation whose z axis is the thrust.
        #[test]
        fn desired_attitude_is_always_a_rotation(tx in -5.0f32..5.0, ty in -5.0f32..5.0, tz in -5.0f32..5.0, yaw in -7.0f32..7.0) {
            let t = Vec3::new(tx, ty, tz);
            let r = desired_attitude(&t, yaw);
            prop_assert!(is_rotation(&r, 1e-5));
            if t.norm() > 1e-3 {
                prop_assert!((r.column(2) - t.normalize()).norm() < 1e-5);
            }
        }
    }
}
