//! Forward kinematics of the chain (paper Eq. 2, docs/model.md):
//! `p_{i+1} = p_i - l * [cos(psi_i) cos(theta_i), sin(psi_i) cos(theta_i), -sin(theta_i)]`.
//!
//! The recurrence is written once, generic over the scalar ([`KinematicsScalar`]): the
//! units run it in `f32`, the host's exact checks and simulation in `f64`.

use nalgebra::{ComplexField, RealField, Vector3};

use crate::params::{ChainParams, MAX_LINKS, MAX_UNITS};
use crate::shape::{Config, Shape};

/// Unit centres of a chain, head first; only the first N entries are meaningful.
pub type Points = [Vector3<f32>; MAX_UNITS];

/// A scalar the forward kinematics runs in, with the sine and cosine it uses.
pub trait KinematicsScalar: RealField + Copy {
    /// `(sin x, cos x)`.
    fn sincos(self) -> (Self, Self);
}

impl KinematicsScalar for f32 {
    /// libm's `sincosf`, so that every unit and the host compute the same bits.
    #[inline]
    fn sincos(self) -> (f32, f32) {
        libm::sincosf(self)
    }
}

impl KinematicsScalar for f64 {
    /// nalgebra's `sin_cos`: on the host (with `std`) exactly `(x.sin(), x.cos())`.
    fn sincos(self) -> (f64, f64) {
        ComplexField::sin_cos(self)
    }
}

/// Generic form of [`link_direction`]:
/// `d = [cos yaw cos pitch, sin yaw cos pitch, -sin pitch]`.
#[inline]
pub fn link_direction_of<T: KinematicsScalar>(pitch: T, yaw: T) -> Vector3<T> {
    let (st, ct) = pitch.sincos();
    let (sp, cp) = yaw.sincos();
    Vector3::new(cp * ct, sp * ct, -st)
}

/// Unit vector along link `k` from its front unit towards its back unit is the
/// NEGATIVE of this direction: `d = [cos psi cos theta, sin psi cos theta, -sin theta]`.
pub fn link_direction(pitch: f32, yaw: f32) -> Vector3<f32> {
    link_direction_of(pitch, yaw)
}

/// Every link's direction (see [`link_direction`]); only the first N-1 are meaningful.
pub fn directions(shape: &Shape) -> [Vector3<f32>; MAX_LINKS] {
    let mut d = [Vector3::zeros(); MAX_LINKS];
    for (k, v) in d.iter_mut().enumerate().take(shape.links()) {
        *v = link_direction(shape.pitch(k), shape.yaw(k));
    }
    d
}

/// The chain recurrence `out[0] = head`, `out[k + 1] = out[k] - link_length * dirs[k]`,
/// for as many links as `dirs` yields and `out` holds. Returns the number of unit
/// centres written.
#[inline]
pub fn chain_from_directions<T: KinematicsScalar>(
    link_length: T,
    head: Vector3<T>,
    dirs: impl IntoIterator<Item = Vector3<T>>,
    out: &mut [Vector3<T>],
) -> usize {
    let Some(first) = out.first_mut() else {
        return 0;
    };
    *first = head;
    let mut written = 1;
    for d in dirs {
        if written == out.len() {
            break;
        }
        out[written] = out[written - 1] - d * link_length;
        written += 1;
    }
    written
}

/// Unit centres from the head position and the shape angles `eta` (`2N - 1` numbers,
/// docs/model.md's order: head yaw, then each link's pitch and yaw; the head yaw is not
/// read), head first, written into `out`. Returns the number of unit centres written:
/// `N`, or fewer when `out` is shorter.
#[inline]
pub fn positions_into<T: KinematicsScalar>(
    link_length: T,
    head: Vector3<T>,
    eta: &[T],
    out: &mut [Vector3<T>],
) -> usize {
    let links = eta.len().saturating_sub(1) / 2;
    let dirs = (0..links).map(|k| link_direction_of(eta[1 + 2 * k], eta[2 + 2 * k]));
    chain_from_directions(link_length, head, dirs, out)
}

/// Unit centres relative to the head (`offsets[0]` is zero).
pub fn offsets(params: &ChainParams, shape: &Shape) -> Points {
    let mut p = [Vector3::zeros(); MAX_UNITS];
    positions_into(
        params.link_length,
        Vector3::zeros(),
        shape.as_slice(),
        &mut p,
    );
    p
}

/// Unit centres relative to the head from the first `links` link directions.
pub fn offsets_from(
    params: &ChainParams,
    dirs: &[Vector3<f32>; MAX_LINKS],
    links: usize,
) -> Points {
    let mut p = [Vector3::zeros(); MAX_UNITS];
    chain_from_directions(
        params.link_length,
        Vector3::zeros(),
        dirs.iter().take(links).copied(),
        &mut p,
    );
    p
}

/// Unit centres in the world frame.
pub fn positions(params: &ChainParams, config: &Config) -> Points {
    let head = Vector3::from(config.xi);
    let mut p = offsets(params, &config.shape);
    for q in p.iter_mut().take(config.shape.units()) {
        *q += head;
    }
    p
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::angle::deg;

    fn close(a: Vector3<f32>, b: [f32; 3]) -> bool {
        (a - Vector3::from(b)).norm() < 1e-5
    }

    #[test]
    fn zero_angles_trail_along_minus_x() {
        let p = ChainParams::new(3);
        let c = Config {
            xi: [1.0, 2.0, 3.0],
            shape: Shape::line(3, 0.0),
        };
        let q = positions(&p, &c);
        assert!(close(q[0], [1.0, 2.0, 3.0]));
        assert!(close(q[1], [0.5, 2.0, 3.0]));
        assert!(close(q[2], [0.0, 2.0, 3.0]));
    }

    #[test]
    fn hand_computed_pitch_and_yaw() {
        let p = ChainParams::new(3);
        // Link 1: yaw 90 deg -> back unit at -y. Link 2: pitch 30 deg, yaw 0 ->
        // back unit behind along -x and ABOVE (z grows by l sin 30 = 0.25).
        let s = Shape::from_slice(3, &[0.0, 0.0, deg(90.0), deg(30.0), 0.0]).unwrap();
        let q = offsets(&p, &s);
        assert!(close(q[1], [0.0, -0.5, 0.0]));
        let c30 = 0.5 * libm::cosf(deg(30.0));
        assert!(close(q[2], [-c30, -0.5, 0.25]));
    }

    proptest::proptest! {
        /// Rotating a shape about the head moves no unit relative to another, and
        /// turns every unit about the head by exactly the rotation.
        #[test]
        fn rotation_preserves_distances_between_units(
            eta in proptest::collection::vec(-3.0f32..3.0, 11),
            d in -7.0f32..7.0,
        ) {
            let p = ChainParams::new(6);
            let s = Shape::from_slice(6, &eta).unwrap();
            let (a, b) = (offsets(&p, &s), offsets(&p, &s.rotated(d)));
            for i in 0..6 {
                for j in 0..6 {
                    proptest::prop_assert!(((a[i] - a[j]).norm() - (b[i] - b[j]).norm()).abs() < 1e-4);
                }
                let (c, sn) = (libm::cosf(d), libm::sinf(d));
                let turned = Vector3::new(c * a[i].x - sn * a[i].y, sn * a[i].x + c * a[i].y, a[i].z);
                proptest::prop_assert!((turned - b[i]).norm() < 1e-4);
            }
        }
    }

    #[test]
    fn links_keep_their_length() {
        let p = ChainParams::new(16);
        let mut s = Shape::line(16, 0.0);
        for k in 0..15 {
            s.set_link(k, 0.1 * k as f32 - 0.7, 0.37 * k as f32);
        }
        let q = offsets(&p, &s);
        for k in 0..15 {
            assert!(((q[k] - q[k + 1]).norm() - 0.5).abs() < 1e-5);
        }
    }
}
