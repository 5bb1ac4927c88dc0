//! Angle wrapping. docs/model.md wraps every angle difference to `(-pi, pi]`.

use core::f32::consts::{PI, TAU};

/// Wraps `a` to `(-pi, pi]`. Non-finite input comes back unchanged (NaN stays NaN),
/// so callers' validity checks still see it.
pub fn wrap(a: f32) -> f32 {
    // Already in range: `remainderf` would give `a` itself (its quotient rounds to
    // 0, exactly), so the costly call is left out.
    if a > -PI && a <= PI {
        return a;
    }
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

    /// What `wrap` leaves out for an angle already in range: `remainderf` of it is
    /// itself, to the bit, so skipping the call changes nothing.
    #[test]
    fn remainder_of_an_angle_in_range_is_itself() {
        let edges = [
            PI,
            -PI + 1e-7,
            f32::MIN_POSITIVE,
            -0.0,
            0.0,
            1e-30,
            -3.1415925,
        ];
        for a in edges {
            assert_eq!(libm::remainderf(a, TAU).to_bits(), a.to_bits(), "{a}");
        }
        // Every 1009th f32 in (-pi, pi].
        let (lo, hi) = ((-PI).to_bits(), PI.to_bits());
        for bits in (0..=hi)
            .step_by(1009)
            .chain((0x8000_0000..lo).step_by(1009))
        {
            let a = f32::from_bits(bits);
            assert_eq!(libm::remainderf(a, TAU).to_bits(), a.to_bits(), "{a}");
        }
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
