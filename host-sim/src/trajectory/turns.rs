//! Turns of the head yaw flown while the chain moves.
//!
//! The head yaw is the heading every unit holds about its own centre; it moves no body
//! (docs/model.md, "Trajectories"). So an edge that turns only the head yaw (a turn to
//! a goal's yaw, or to look along a route) need not wait for the motion before it to
//! end: it is spread over the edges before it, each taking a share of the turn in
//! proportion to its time at its cruise, so that at their cruises the yaw turns at one
//! rate while the chain moves along the plan's own path. It takes as many of those
//! edges as its own time at the yaw rate needs, back to an edge that turns the yaw
//! itself or to the start of the plan (of a mission's leg); where they are shorter
//! than that, it takes them all and they slow to its rate. Only with blends: without
//! them, or when a deadline stops the generator's rounds, the chain stops at every
//! waypoint, the turn's first among them.

use super::merge::Demand;
use super::reference::{Segment, SegmentKind};
use crate::collision::verify::STAY_TOLERANCE;
use crate::trajectory::ReferenceLimits;

/// Whether edge `e` turns the head yaw and changes nothing else.
fn turns_only(e: &Segment) -> bool {
    e.kind == SegmentKind::ShapeChange
        && e.delta[3].abs() > STAY_TOLERANCE
        && e.delta[4..].iter().all(|d| d.abs() <= STAY_TOLERANCE)
}

/// Whether a turn after edge `e` may run during it: it turns no yaw of its own. (The
/// generator's edges all move: `Reference::new` leaves out those that change nothing.)
fn carries(e: &Segment) -> bool {
    e.delta[3].abs() <= STAY_TOLERANCE
}

/// Time (s) edge `e` takes at the largest rate the generator times it at within
/// `limits` (`super::merge::Demand`), ramps left out.
fn cruise(e: &Segment, l: f64, limits: &ReferenceLimits) -> f64 {
    1.0 / Demand::of(e, l).max_rate(limits)
}

/// `edges` (a plan's, in order, each as [`super::Reference::new`] times it alone) with
/// every turn of the head yaw alone spread over the edges before it, as the module docs
/// say; and how many turns were spread. The last edge that takes a turn ends where the
/// turn ended (its waypoint); every edge's start follows from the ones before it.
pub(super) fn spread(
    edges: Vec<Segment>,
    l: f64,
    limits: &ReferenceLimits,
) -> (Vec<Segment>, usize) {
    let mut out: Vec<Segment> = Vec::with_capacity(edges.len());
    let mut spread = 0;
    for e in edges {
        if !turns_only(&e) {
            out.push(e);
            continue;
        }
        let need = cruise(&e, l, limits);
        // The edges that take the turn, walking back from the one before it.
        let mut first = out.len();
        let mut times = Vec::new();
        let mut total = 0.0;
        while first > 0 && total < need && carries(&out[first - 1]) {
            first -= 1;
            let t = cruise(&out[first], l, limits);
            total += t;
            times.push(t);
        }
        if times.is_empty() {
            out.push(e);
            continue;
        }
        for (s, t) in out[first..].iter_mut().zip(times.iter().rev()) {
            let share = t / total;
            s.delta
                .iter_mut()
                .zip(&e.delta)
                .for_each(|(d, c)| *d += share * c);
        }
        for k in first + 1..out.len() {
            let from: Vec<f64> = out[k - 1]
                .from
                .iter()
                .zip(&out[k - 1].delta)
                .map(|(a, d)| a + d)
                .collect();
            out[k].from = from;
        }
        if let Some(last) = out.last_mut() {
            last.to_waypoint = e.to_waypoint;
        }
        spread += 1;
    }
    (out, spread)
}

#[cfg(test)]
mod tests {
    use aerial_chain_core::{ChainParams, Shape};

    use super::*;
    use crate::trajectory::tests::{assert_respects_limits, built, plan, room};
    use crate::trajectory::{build, build_until, Reference, Settings};

    /// A straight chain of 3 units along x, its head yaw turned to `yaw` (its links stay).
    fn line(yaw: f32) -> Shape {
        let mut eta = Shape::line(3, 0.0).as_slice().to_vec();
        eta[0] = yaw;
        Shape::from_slice(3, &eta).unwrap()
    }

    /// The generator's limits: no hold at the start.
    fn limits() -> ReferenceLimits {
        Settings::default().limits.to_reference()
    }

    /// A straight chain's plan: from (2, 2, 1) along x to `x`, then its head yaw turned
    /// from 0 to `yaw` in place.
    fn move_then_turn(x: f64, yaw: f32) -> [([f64; 3], Shape); 3] {
        let (a, b) = (line(0.0), line(yaw));
        [([2.0, 2.0, 1.0], a), ([x, 2.0, 1.0], a), ([x, 2.0, 1.0], b)]
    }

    fn edges(points: &[([f64; 3], Shape)]) -> Vec<Segment> {
        let p = plan(&ChainParams::new(3), points);
        let zetas: Vec<Vec<f64>> = p.waypoints.iter().map(|w| w.zeta.clone()).collect();
        Reference::new(3, 0.5, &zetas, &limits())
            .unwrap()
            .segments()
            .to_vec()
    }

    #[test]
    fn a_turn_takes_as_many_edges_before_it_as_its_time_needs_in_proportion_to_theirs() {
        let lim = limits();
        let (a, b) = (line(0.0), line(0.2));
        // 0.2 rad needs 0.25 s at the yaw rate: the 1 m before it (2 s) carries it all.
        let short = [
            ([1.0, 1.0, 1.0], a),
            ([2.0, 1.0, 1.0], a),
            ([3.0, 1.0, 1.0], a),
        ];
        let mut pts = short.to_vec();
        pts.push(([3.0, 1.0, 1.0], b));
        let (out, n) = spread(edges(&pts), 0.5, &lim);
        assert_eq!((out.len(), n), (2, 1));
        assert_eq!(out[0].delta[3], 0.0);
        assert!((out[1].delta[3] - 0.2).abs() < 1e-6);
        assert_eq!(out[1].to_waypoint, 3);
        // 1 rad needs 1.27 s: 0.1 m (0.2 s) is too short, so 1 m (2 s) shares it.
        let c = line(1.0);
        let pts = [
            ([1.0, 1.0, 1.0], a),
            ([2.0, 1.0, 1.0], a),
            ([2.1, 1.0, 1.0], a),
            ([2.1, 1.0, 1.0], c),
        ];
        let (out, n) = spread(edges(&pts), 0.5, &lim);
        assert_eq!((out.len(), n), (2, 1));
        let turn = 1.0f32 as f64;
        assert!((out[0].delta[3] - turn * 2.0 / 2.2).abs() < 1e-9);
        assert!((out[1].delta[3] - turn * 0.2 / 2.2).abs() < 1e-9);
        assert!((out[1].from[3] - out[0].delta[3]).abs() < 1e-12);
        for e in &out {
            assert_eq!(e.delta[4..], [0.0; 4]);
        }
    }

    #[test]
    fn a_turn_at_the_start_or_after_a_turn_of_the_yaw_stays_its_own_edge() {
        let lim = limits();
        let (a, b) = (line(0.0), line(0.8));
        // Nothing moves before it.
        let (out, n) = spread(
            edges(&[([1.0, 1.0, 1.0], a), ([1.0, 1.0, 1.0], b)]),
            0.5,
            &lim,
        );
        assert_eq!((out.len(), n), (1, 0));
        // The chain turned about its head (the yaw with it) just before.
        let r = Shape::line(3, 0.0).rotated(0.6);
        let mut turned = r.as_slice().to_vec();
        turned[0] += 0.5;
        let t = Shape::from_slice(3, &turned).unwrap();
        let pts = [
            ([1.0, 1.0, 1.0], a),
            ([1.0, 1.0, 1.0], r),
            ([1.0, 1.0, 1.0], t),
        ];
        let (out, n) = spread(edges(&pts), 0.5, &lim);
        assert_eq!((out.len(), n), (2, 0));
    }

    #[test]
    fn a_turn_at_the_end_costs_no_time_and_leaves_the_chain_on_the_plan_s_path() {
        let params = ChainParams::new(3);
        let grid = room();
        let turning = move_then_turn(3.5, 1.5);
        let straight = &turning[..2];
        let alone = built(&plan(&params, straight), &grid);
        let tr = built(&plan(&params, &turning), &grid);
        // The turn alone would add 1.9 s at the yaw rate; 1.5 m take 3 s.
        assert!((tr.duration() - alone.duration()).abs() < 1e-9);
        assert!(tr.stop_go_duration() > alone.stop_go_duration() + 1.9);
        for (z, y) in tr.zetas().iter().zip(alone.zetas()) {
            assert_eq!(z[..3], y[..3]);
        }
        let end = tr.zetas().last().unwrap();
        assert!((end[3] - 1.5f32 as f64).abs() < 1e-9);
        assert_respects_limits(&grid, &tr);
        assert_eq!((tr.corners(), tr.merged()), (1, 1));
    }

    #[test]
    fn without_blends_or_past_a_deadline_the_chain_rests_before_the_turn() {
        let params = ChainParams::new(3);
        let grid = room();
        let p = plan(&params, &move_then_turn(3.5, 1.5));
        let stop = Settings {
            blend: false,
            ..Settings::default()
        };
        let now = Some(std::time::Instant::now());
        let timed = [
            build(&p, &grid, &stop).unwrap(),
            build_until(&p, &grid, &Settings::default(), now).unwrap(),
        ];
        for tr in timed {
            assert_eq!(tr.merged(), 0);
            assert!((tr.duration() - tr.stop_go_duration()).abs() <= 2.0 * stop.dt);
            // Resting at the translation's end, the yaw not yet turned.
            let rest = tr.zetas().iter().any(|z| z[..4] == [3.5, 2.0, 1.0, 0.0]);
            assert!(rest, "no sample rests at the waypoint before the turn");
        }
    }

    #[test]
    fn a_shape_change_before_a_turn_carries_it_at_the_rate_it_is_timed_at() {
        let params = ChainParams::new(3);
        let grid = room();
        let mut eta = Shape::line(3, 0.0).as_slice().to_vec();
        eta[4] = 0.5; // the second link's yaw
        let bent = Shape::from_slice(3, &eta).unwrap();
        let mut turned = eta.clone();
        turned[0] = 0.4;
        let turned = Shape::from_slice(3, &turned).unwrap();
        let pts = [
            ([2.5, 2.0, 1.0], line(0.0)),
            ([2.5, 2.0, 1.0], bent),
            ([2.5, 2.0, 1.0], turned),
        ];
        let (out, n) = spread(edges(&pts), 0.5, &limits());
        assert_eq!((out.len(), n), (1, 1));
        assert!((out[0].delta[3] - 0.4).abs() < 1e-9);
        let tr = built(&plan(&params, &pts), &grid);
        let alone = built(&plan(&params, &pts[..2]), &grid);
        assert!(
            (tr.duration() - alone.duration()).abs() < 1e-9,
            "0.4 rad fit in the bend"
        );
        assert_respects_limits(&grid, &tr);
    }

    #[test]
    fn a_turn_longer_than_the_motion_before_it_slows_that_motion_to_its_rate() {
        let params = ChainParams::new(3);
        let grid = room();
        let pts = move_then_turn(2.3, 3.0);
        let tr = built(&plan(&params, &pts), &grid);
        let turn = built(&plan(&params, &pts[1..]), &grid);
        let step = built(&plan(&params, &pts[..2]), &grid);
        assert!(tr.duration() >= turn.duration() - 1e-9);
        assert!(tr.duration() < turn.duration() + step.duration() - 1.0);
        assert_respects_limits(&grid, &tr);
        let end = tr.zetas().last().unwrap();
        assert_eq!(end[..3], [2.3, 2.0, 1.0]);
    }
}
