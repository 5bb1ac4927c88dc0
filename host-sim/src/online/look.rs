//! Where the chain looks before it moves from a rest: at the unseen part of its own
//! hull.
//!
//! Any motion along the chain takes each unit through the space between it and its
//! neighbours (follow-the-leader takes the tail through the waist between it and the
//! unit ahead). The chain's own space covers the balls of `r_u` plus the clearance about
//! its units, not that waist; sensors looking along the head's yaw see a waist from two
//! units behind it, 0.75 m on, but the waist ahead of the last unit only from the last
//! unit itself, 0.25 m on, where a depth camera's vertical view (58 degrees: 0.14 m each
//! side of its axis) is narrower than a unit. So a straight chain at rest looking along
//! itself cannot move its tail forward, and no piece would be found. Turning the head yaw
//! (which moves no body; every unit holds it, so every sensor turns) to where the units'
//! sensors see most of the unseen hull lets them see it: looking back along the chain,
//! the unit two ahead of the last sees that waist. A prediction by the sensors' view
//! alone (nothing in the way counts); the scans say what was seen.

use nalgebra::Point3;

use super::belief::Belief;
use crate::collision::exact::point_segment_distance;
use crate::map::{Cell, FACE_NEIGHBOURS};
use crate::sensing::{DepthSensor, UnitPose};

/// The unknown voxels at the edge of what is known in the chain's hull: inside the box,
/// next to a voxel seen free, with their centres within `reach` of a link (the segment
/// between two unit centres) of the chain whose unit centres are `centres`. Their
/// centres (W).
pub(super) fn unseen_hull(
    belief: &Belief,
    centres: &[Point3<f64>],
    reach: f64,
) -> Vec<Point3<f64>> {
    let grid = belief.commit_field().grid();
    let res = grid.resolution();
    let seen = belief.seen();
    let links: Vec<(Point3<f64>, Point3<f64>)> = match centres {
        [one] => vec![(*one, *one)],
        _ => centres.windows(2).map(|w| (w[0], w[1])).collect(),
    };
    let centre = |i: [i32; 3]| Point3::from(i.map(|k| (f64::from(k) + 0.5) * res));
    let near = |p: &Point3<f64>| {
        links
            .iter()
            .any(|(a, b)| point_segment_distance(*p, *a, *b) <= reach)
    };
    let frontier = |i: [i32; 3]| {
        FACE_NEIGHBOURS.iter().any(|d| {
            let j = [i[0] + d[0], i[1] + d[1], i[2] + d[2]];
            seen.state(j) == Cell::Free
        })
    };
    let lo = |k: usize| centres.iter().map(|c| c[k]).fold(f64::INFINITY, f64::min) - reach;
    let hi = |k: usize| {
        centres
            .iter()
            .map(|c| c[k])
            .fold(f64::NEG_INFINITY, f64::max)
            + reach
    };
    let index = |v: f64| (v / res).floor() as i32;
    let mut out = Vec::new();
    for z in index(lo(2))..=index(hi(2)) {
        for y in index(lo(1))..=index(hi(1)) {
            for x in index(lo(0))..=index(hi(0)) {
                let i = [x, y, z];
                let p = centre(i);
                if grid.local(i).is_some()
                    && seen.state(i) == Cell::Unknown
                    && near(&p)
                    && frontier(i)
                {
                    out.push(p);
                }
            }
        }
    }
    out
}

/// The head yaw, turned from `yaw` by a multiple of a step of at most half the
/// horizontal field of view (an even number of steps round the circle, so that looking
/// straight back along the chain is one), from which the sensors of the units at
/// `centres` (level, holding that yaw, each unit's own: [`DepthSensor::for_unit`]) see
/// the most of `unseen`; the smaller turn on a tie. `None` when no such yaw sees any of
/// it.
pub(super) fn best_view(
    sensor: &DepthSensor,
    centres: &[Point3<f64>],
    yaw: f64,
    unseen: &[Point3<f64>],
) -> Option<f64> {
    use std::f64::consts::TAU;
    let turns = 2 * (TAU / sensor.fov_h_deg.to_radians()).ceil().max(1.0) as usize;
    let step = TAU / turns as f64;
    let sensors: Vec<DepthSensor> = (0..centres.len()).map(|i| sensor.for_unit(i)).collect();
    let seen_from = |heading: f64| {
        let poses: Vec<UnitPose> = centres
            .iter()
            .map(|c| UnitPose::level(*c, heading))
            .collect();
        unseen
            .iter()
            .filter(|p| {
                let mut views = sensors.iter().zip(&poses);
                views.any(|(s, pose)| s.in_view(pose, p))
            })
            .count()
    };
    // Turns ordered by size, left before right: the first of the most seen is the
    // smallest.
    let mut best: Option<(usize, f64)> = None;
    for k in 1..=turns / 2 {
        for sign in [1.0, -1.0] {
            let turn = sign * k as f64 * step;
            if sign < 0.0 && 2 * k == turns {
                continue; // the half turn, already tried
            }
            let n = seen_from(yaw + turn);
            if n > 0 && best.is_none_or(|(m, _)| n > m) {
                best = Some((n, yaw + turn));
            }
        }
    }
    best.map(|(_, heading)| heading)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::Grid;

    /// A straight chain of `n` units along -x from `(2, 1, 1)`, in a 4 x 2 x 2 m box at
    /// 0.05 m, with the chain's own space (balls of 0.2 m) seen free.
    fn chain_at_rest(n: usize) -> (Belief, Vec<Point3<f64>>) {
        let bounds = Grid::new(0.05, [0, 0, 0], [80, 40, 40], Cell::Unknown, true).unwrap();
        let mut belief = Belief::new(&bounds, None).unwrap();
        let centres: Vec<Point3<f64>> = (0..n)
            .map(|i| Point3::new(2.0 - 0.5 * i as f64, 1.0, 1.0))
            .collect();
        belief.mark_flown(&centres, 0.2).unwrap();
        (belief, centres)
    }

    #[test]
    fn the_waists_between_units_are_the_unseen_hull() {
        let (belief, centres) = chain_at_rest(4);
        let unseen = unseen_hull(&belief, &centres, 0.2);
        assert!(!unseen.is_empty());
        for p in &unseen {
            // Outside every unit's ball (a voxel half inside it is not seen free),
            // within reach of the chain's axis.
            assert!(centres
                .iter()
                .all(|c| (p - c).norm() > 0.2 - 0.05 * 3f64.sqrt()));
            assert!(((p.y - 1.0).powi(2) + (p.z - 1.0).powi(2)).sqrt() <= 0.2);
            assert!(p.x > 0.5 - 0.2 && p.x < 2.0 + 0.2, "{p}");
        }
        // Every waist, above and below the axis between two units, holds some of it
        // (the edge of what is seen: the waist's inside is unknown too, next to
        // nothing seen).
        for w in centres.windows(2) {
            let mid = nalgebra::center(&w[0], &w[1]);
            for side in [1.0, -1.0] {
                assert!(
                    unseen
                        .iter()
                        .any(|p| (p.x - mid.x).abs() < 0.2 && side * (p.z - mid.z) > 0.1),
                    "{mid} {side}"
                );
            }
        }
    }

    #[test]
    fn a_chain_looking_along_itself_turns_round_to_see_its_last_waist() {
        let (belief, centres) = chain_at_rest(4);
        // The waist ahead of the last unit alone, as sensors looking along the chain
        // leave it (they see the others from two units behind).
        let last_waist: Vec<_> = unseen_hull(&belief, &centres, 0.2)
            .into_iter()
            .filter(|p| p.x < 1.0)
            .collect();
        assert!(!last_waist.is_empty());
        let sensor = DepthSensor::default();
        let yaw = best_view(&sensor, &centres, 0.0, &last_waist).expect("a view");
        // Looking back along the chain (+-180 degrees, or the nearest turns that see
        // the waist from two units ahead of it).
        let turned = crate::collision::verify::wrap(yaw).abs();
        assert!(turned > 2.5, "turned {turned} rad");
        // From there the sensors see all of it; looking along the chain, not all.
        assert!(last_waist.iter().all(|p| seen(&sensor, &centres, yaw, p)));
        assert!(!last_waist.iter().all(|p| seen(&sensor, &centres, 0.0, p)));
    }

    /// Whether some unit at `centres` holding `yaw` has `p` in its own sensor's view.
    fn seen(sensor: &DepthSensor, centres: &[Point3<f64>], yaw: f64, p: &Point3<f64>) -> bool {
        let mut units = centres.iter().enumerate();
        units.any(|(i, c)| sensor.for_unit(i).in_view(&UnitPose::level(*c, yaw), p))
    }

    #[test]
    fn splayed_sensors_are_counted_by_their_own_views() {
        let (_, centres) = chain_at_rest(3);
        // Level, 69 degrees to the left of the middle unit's heading and 45 of the last
        // one's: in unit 1's view when splayed to the left, in no view with every
        // sensor looking along the chain.
        let left = [Point3::new(1.8, 1.8, 1.0)];
        let ahead = DepthSensor::default();
        let splayed = DepthSensor {
            splay_deg: 43.5,
            ..DepthSensor::default()
        };
        assert!(seen(&splayed, &centres, 0.0, &left[0]));
        assert!(!seen(&ahead, &centres, 0.0, &left[0]));
        // The rig looking ahead turns left to see it; every heading best_view picks
        // sees it by the units' own views.
        let turn = best_view(&ahead, &centres, 0.0, &left).expect("a view");
        assert!(
            turn > 0.0 && seen(&ahead, &centres, turn, &left[0]),
            "{turn}"
        );
        let turn = best_view(&splayed, &centres, 0.0, &left).expect("a view");
        assert!(seen(&splayed, &centres, turn, &left[0]), "{turn}");
    }

    #[test]
    fn nothing_to_see_is_no_view() {
        let (_, centres) = chain_at_rest(3);
        assert_eq!(best_view(&DepthSensor::default(), &centres, 0.0, &[]), None);
        // A point no sensor reaches from any heading: far above the chain.
        let above = [Point3::new(1.5, 1.0, 1.0 + 6.0)];
        assert_eq!(
            best_view(&DepthSensor::default(), &centres, 0.0, &above),
            None
        );
    }
}
