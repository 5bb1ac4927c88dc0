//! The cost to transition `C_T` between two shapes (paper Eq. 3).
//!
//! `C_T(c1, c2) = sqrt(N dpsi1_r^2 + sum_i (N - i) (dpsi_i^2 + dtheta_i^2))`, with each
//! difference wrapped to `(-pi, pi]`. Links near the head weigh more: turning them
//! swings every unit behind them.

use crate::angle::diff;
use crate::shape::Shape;

/// `C_T` between two shapes of the same chain.
pub fn transition_cost(a: &Shape, b: &Shape) -> f32 {
    libm::sqrtf(transition_cost_sq(a, b))
}

/// `C_T^2`, for comparisons without the square root.
pub fn transition_cost_sq(a: &Shape, b: &Shape) -> f32 {
    transition_cost_sq_within(a, b, f32::INFINITY).unwrap_or(f32::INFINITY)
}

/// `C_T^2` when it is at most `bound`, else `None`, found without summing every
/// term: the terms are never negative, so once a partial sum exceeds `bound` the
/// whole does. The terms are added in the same order as [`transition_cost_sq`], so a
/// value returned is bit for bit the same. Heaviest terms come first (head, then
/// links from the head), which is what makes nearest-neighbour searches fast.
pub fn transition_cost_sq_within(a: &Shape, b: &Shape, bound: f32) -> Option<f32> {
    let n = a.units() as f32;
    let dh = diff(a.head_yaw(), b.head_yaw());
    let mut sum = n * dh * dh;
    for k in 0..a.links() {
        if sum > bound {
            return None;
        }
        let w = n - (k as f32 + 1.0); // link i = k + 1 weighs N - i
        let dp = diff(a.pitch(k), b.pitch(k));
        let dy = diff(a.yaw(k), b.yaw(k));
        sum += w * (dp * dp + dy * dy);
    }
    (sum <= bound).then_some(sum)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn hand_computed() {
        // N = 3: sqrt(3 * 0.1^2 + 2 * (0.2^2 + 0.3^2) + 1 * (0^2 + 0.4^2))
        let a = Shape::from_slice(3, &[0.0; 5]).unwrap();
        let b = Shape::from_slice(3, &[0.1, 0.2, 0.3, 0.0, 0.4]).unwrap();
        let expect = libm::sqrtf(3.0 * 0.01 + 2.0 * (0.04 + 0.09) + 0.16);
        assert!((transition_cost(&a, &b) - expect).abs() < 1e-6);
        assert_eq!(transition_cost(&a, &a), 0.0);
    }

    proptest! {
        #[test]
        fn the_bounded_cost_is_the_cost_or_none(v in proptest::array::uniform7(-3.0f32..3.0), w in proptest::array::uniform7(-3.0f32..3.0), bound in 0.0f32..40.0) {
            let a = Shape::from_slice(4, &v).unwrap();
            let b = Shape::from_slice(4, &w).unwrap();
            let full = transition_cost_sq(&a, &b);
            let within = transition_cost_sq_within(&a, &b, bound);
            prop_assert_eq!(within, (full <= bound).then_some(full));
        }

        #[test]
        fn symmetric_and_invariant_to_full_turns(v in proptest::array::uniform7(-3.0f32..3.0), w in proptest::array::uniform7(-3.0f32..3.0)) {
            let a = Shape::from_slice(4, &v).unwrap();
            let b = Shape::from_slice(4, &w).unwrap();
            prop_assert!((transition_cost(&a, &b) - transition_cost(&b, &a)).abs() < 1e-4);
            let mut turned = w;
            turned[0] += core::f32::consts::TAU;
            let c = Shape::from_slice(4, &turned).unwrap();
            prop_assert!((transition_cost(&a, &b) - transition_cost(&a, &c)).abs() < 1e-3);
        }
    }
}
