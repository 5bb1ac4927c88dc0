//! Angle wrapping. docs/model.md wraps every angle difference to `(-pi, pi]`.

use core::f32::consts::{PI, TAU};

/// Wraps `a` to `(-pi, pi]`. Non-finite input comes back unchanged (NaN stays NaN),
/// so callers' validity checks still see it.
pub fn wrap(a: f32) -> f32 {
    if !a.is_finite() {
        return a;
    }
    let mut w = libm::remainderf(a, TAU); // in [-pi, pi]
    if w <= -PI {
        w += TAU;
    }
    w
}

/// Shortest signed difference `to - from`, wrapped to `(-pi, pi]`.
pub fn diff(from: f32, to: f32) -> f32 {
    wrap(to - from)
}

/// Degrees to radians, for human-facing parameters.
pub fn deg(d: f32) -> f32 {
    d * (PI / 180.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn wraps_to_half_open_interval() {
        assert_eq!(wrap(PI), PI);
        assert!((wrap(-PI) - PI).abs() < 1e-6);
        assert!((wrap(3.0 * PI / 2.0) + PI / 2.0).abs() < 1e-6);
        assert_eq!(wrap(0.0), 0.0);
        assert!(wrap(f32::NAN).is_nan());
    }

    #[test]
    fn diff_takes_the_short_way_round() {
        assert!((diff(deg(170.0), deg(-170.0)) - deg(20.0)).abs() < 1e-5);
        assert!((diff(deg(-170.0), deg(170.0)) + deg(20.0)).abs() < 1e-5);
    }

    proptest! {
        #[test]
        fn wrap_lands_in_range_and_keeps_the_angle(a in -100.0f32..100.0) {
            let w = wrap(a);
            prop_assert!(w > -PI - 1e-6 && w <= PI + 1e-6);
            prop_assert!((libm::sinf(w) - libm::sinf(a)).abs() < 1e-3);
            prop_assert!((libm::cosf(w) - libm::cosf(a)).abs() < 1e-3);
        }
    }
}
