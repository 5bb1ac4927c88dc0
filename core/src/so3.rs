//! The SO(3) math of the attitude controller, in `f32`: hat and vee, elementary
//! rotations and zyx Euler angles, the exponential map, the projection of a nearly
//! orthonormal matrix back onto SO(3), the attitude and rate errors of Lee, Leok and
//! McClamroch (2010), and the desired attitudes of a unit (from a thrust direction and
//! a yaw) and of a link (from its pitch and yaw).
//!
//! Rotation matrices are body-to-world. Everything is plain data and pure functions;
//! no input makes anything here panic or return NaN: non-finite or degenerate inputs
//! fall back to documented values.

use nalgebra::{Matrix3, Vector3};

/// A 3x3 `f32` matrix (rotation matrices are body-to-world).
pub type Mat3 = Matrix3<f32>;
/// A 3-vector of `f32`.
pub type Vec3 = Vector3<f32>;

/// Below this, a norm counts as zero.
pub(crate) const TINY: f32 = 1e-6;

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

/// Whether every component of `v` is finite.
pub(crate) fn all_finite3(v: &Vec3) -> bool {
    v.x.is_finite() && v.y.is_finite() && v.z.is_finite()
}

/// `v` scaled to unit length, or `None` when its norm is below [`TINY`] or not finite.
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
pub(crate) fn rotation_axis(e: &Mat3) -> Vec3 {
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
pub(crate) mod tests {
    use super::*;
    use proptest::prelude::*;

    fn close(a: &Mat3, b: &Mat3, tol: f32) -> bool {
        (a - b).iter().all(|v| libm::fabsf(*v) <= tol)
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
        assert_eq!(exp_so3(&Vec3::new(inf, 0.0, 0.0)), Mat3::identity());
    }

    /// A rotation and the same with 1 % scale and shear errors (the controller's tests
    /// feed it too).
    pub(crate) fn noisy_rotation() -> (Mat3, Mat3) {
        let r = from_euler_zyx(0.4, -0.3, 1.1);
        let noise = Mat3::new(
            0.01, -0.005, 0.008, 0.004, -0.01, 0.002, -0.006, 0.003, 0.009,
        );
        (r, r + noise)
    }

    #[test]
    fn nearly_orthonormal_input_is_projected_close_to_the_rotation() {
        let (r, noisy) = noisy_rotation();
        let p = orthonormalize(&noisy);
        assert!(is_rotation(&p, 1e-5));
        assert!(rotation_angle(&(p.transpose() * r)) < 0.02);
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]

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
