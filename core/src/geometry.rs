//! Distances between points and segments, the primitives of the collision tests.

use nalgebra::Vector3;

/// Distance from point `p` to the segment `a b`.
pub fn point_segment_distance(p: &Vector3<f32>, a: &Vector3<f32>, b: &Vector3<f32>) -> f32 {
    libm::sqrtf(point_segment_distance_squared(p, a, b))
}

/// Squared distance from point `p` to the segment `a b` (no square root).
pub fn point_segment_distance_squared(p: &Vector3<f32>, a: &Vector3<f32>, b: &Vector3<f32>) -> f32 {
    let ab = b - a;
    let len2 = ab.norm_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(&ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + ab * t - p).norm_squared()
}

/// Smallest distance between segments `p1 q1` and `p2 q2` (closest points by
/// clamped parameters, robust to parallel and degenerate segments).
pub fn segment_segment_distance(
    p1: &Vector3<f32>,
    q1: &Vector3<f32>,
    p2: &Vector3<f32>,
    q2: &Vector3<f32>,
) -> f32 {
    let d1 = q1 - p1;
    let d2 = q2 - p2;
    let r = p1 - p2;
    let a = d1.norm_squared();
    let e = d2.norm_squared();
    let f = d2.dot(&r);
    const EPS: f32 = 1e-12;
    let (s, t) = if a <= EPS && e <= EPS {
        (0.0, 0.0)
    } else if a <= EPS {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(&r);
        if e <= EPS {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(&d2);
            let denom = a * e - b * b;
            let mut s = if denom > EPS {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t = (b * s + f) / e;
            if t < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            }
            (s, t)
        }
    };
    ((p1 + d1 * s) - (p2 + d2 * t)).norm()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn known_cases() {
        // A point and its distance to the segment from (-1, 0, 0) to (1, 0, 0).
        let (a, b) = (Vector3::new(-1.0, 0.0, 0.0), Vector3::new(1.0, 0.0, 0.0));
        for (p, want) in [([0.0, 1.0, 0.0], 1.0), ([3.0, 0.0, 0.0], 2.0)] {
            let d = point_segment_distance(&p.into(), &a, &b);
            assert!((d - want).abs() < 1e-6, "{p:?}: {d}");
        }
        // Two segments and their distance: crossing one unit apart in z; parallel and
        // overlapping; degenerate (both points).
        let cases: [([[f32; 3]; 4], f32); 3] = [
            (
                [[-1., 0., 0.], [1., 0., 0.], [0., -1., 1.], [0., 1., 1.]],
                1.0,
            ),
            (
                [[0., 0., 0.], [2., 0., 0.], [1., 0.5, 0.], [3., 0.5, 0.]],
                0.5,
            ),
            ([[0.; 3], [0.; 3], [0., 3., 4.], [0., 3., 4.]], 5.0),
        ];
        for ([p1, q1, p2, q2], want) in cases {
            let d = segment_segment_distance(&p1.into(), &q1.into(), &p2.into(), &q2.into());
            assert!(
                (d - want).abs() < 1e-6,
                "{p1:?}-{q1:?} to {p2:?}-{q2:?}: {d}"
            );
        }
    }

    proptest! {
        /// The closed form never exceeds a dense brute-force sampling, and is close to it.
        #[test]
        fn segment_distance_matches_brute_force(c in proptest::array::uniform12(-2.0f32..2.0)) {
            let (p1, q1, p2, q2) = (Vector3::new(c[0], c[1], c[2]), Vector3::new(c[3], c[4], c[5]), Vector3::new(c[6], c[7], c[8]), Vector3::new(c[9], c[10], c[11]));
            let d = segment_segment_distance(&p1, &q1, &p2, &q2);
            let mut best = f32::MAX;
            for i in 0..=200 {
                let a = p1 + (q1 - p1) * (i as f32 / 200.0);
                best = best.min(point_segment_distance(&a, &p2, &q2));
            }
            prop_assert!(d <= best + 1e-4);
            prop_assert!(best - d < 0.03);
        }
    }
}
