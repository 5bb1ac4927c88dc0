//! Joining a piece onto a motion in flight: no stop at the joint, every limit and the
//! map kept (checked by the tests' own reading of the limits), the same motion up to
//! where the join must take effect, and refusals named.

use aerial_chain_core::{ChainParams, Shape};

use super::*;
use crate::map::Cell;
use crate::trajectory::tests::{assert_samples_respect_limits, built, plan, room};
use crate::trajectory::Trajectory;

/// A piece of a chain of 3 through the heads `heads`, the chain along x behind it.
fn path(params: &ChainParams, grid: &Grid, heads: &[[f64; 3]]) -> Trajectory {
    let s = Shape::line(3, 0.0);
    let points: Vec<([f64; 3], Shape)> = heads.iter().map(|h| (*h, s)).collect();
    built(&plan(params, &points), grid)
}

/// A piece of a chain of 3 from head `from` to head `to`, the chain along x behind it.
fn piece(params: &ChainParams, grid: &Grid, from: [f64; 3], to: [f64; 3]) -> Trajectory {
    path(params, grid, &[from, to])
}

/// Two pieces along x, the second going straight on from where the first ends.
fn straight_on(params: &ChainParams, grid: &Grid) -> (Trajectory, Trajectory) {
    (
        piece(params, grid, [1.5, 1.0, 1.0], [2.3, 1.0, 1.0]),
        piece(params, grid, [2.3, 1.0, 1.0], [3.5, 1.0, 1.0]),
    )
}

/// A metre along x from [1.5, 1, 1], then a piece through the heads `heads` from its
/// end.
fn a_metre_then(params: &ChainParams, grid: &Grid, heads: &[[f64; 3]]) -> (Trajectory, Trajectory) {
    let a = piece(params, grid, [1.5, 1.0, 1.0], [2.5, 1.0, 1.0]);
    (a, path(params, grid, heads))
}

/// Every limit of `s` and the map of `grid` kept by `r` at its samples every `s.dt`
/// (the trajectory's own sampling), by the tests' own reading of the limits.
fn assert_joined_respects_limits(grid: &Grid, params: &ChainParams, s: &Settings, r: &Reference) {
    let (t, z) = crate::trajectory::build::sample(r, s.dt).unwrap();
    assert_samples_respect_limits(grid, params, &s.limits, &t, &z);
}

/// The head's speed of `r` at `t` (m/s).
fn head_speed(r: &Reference, t: f64) -> f64 {
    r.sample(t).v.norm()
}

#[test]
fn a_piece_joined_straight_on_keeps_cruising_through_the_joint() {
    let (params, grid, s) = (ChainParams::new(3), room(), Settings::default());
    let (a, b) = straight_on(&params, &grid);
    let j = splice(a.reference(), b.reference(), &params, &grid, &s, 0.0).unwrap();
    let joined = &j.reference;
    // Two ramps of 1.5 s (0.5 m/s at 0.5 m/s^2) are saved: half of each.
    let stopped = a.reference().duration() + b.reference().duration();
    assert!(
        joined.duration() <= stopped - 1.4,
        "{} vs {stopped}",
        joined.duration()
    );
    let v = head_speed(joined, a.reference().duration());
    assert!(
        v >= 0.99 * s.limits.speed,
        "the head at {v} m/s at the joint"
    );
    for k in 0..=((j.joint.take_by / s.dt) as usize) {
        let t = k as f64 * s.dt;
        assert!(joined.agrees_at(a.reference(), t), "differs at {t} s");
    }
    let end = b.reference().end();
    assert!(joined
        .end()
        .iter()
        .zip(end)
        .all(|(x, y)| (x - y).abs() < 1e-9));
    assert_joined_respects_limits(&grid, &params, &s, joined);
}

/// Head along +x, then up: the tail rounds the joint's corner below a voxel that the
/// pieces' own paths pass at 5 mm (as `tests::corner`).
fn corner_pieces(params: &ChainParams, grid: &Grid) -> (Trajectory, Trajectory) {
    (
        piece(params, grid, [1.6, 1.0, 1.045], [2.955, 1.0, 1.045]),
        piece(params, grid, [2.955, 1.0, 1.045], [2.955, 1.0, 1.8]),
    )
}

#[test]
fn a_corner_at_the_joint_is_rounded_only_where_it_keeps_off_the_map() {
    let (params, s) = (ChainParams::new(3), Settings::default());
    let free = room();
    let (a, b) = corner_pieces(&params, &free);
    let j = splice(a.reference(), b.reference(), &params, &free, &s, 0.0).unwrap();
    // A right angle changes the velocity by sqrt(2) of the cruise: the joint's ramp is
    // longer than the ramp to rest, so the chain slows down earlier than it would stop.
    let rest_ramp = a.reference().segments().last().unwrap().scaling.ramp_down;
    assert!(j.joint.take_by < a.reference().duration() - rest_ramp);
    assert!(
        j.joint.blend.0 < a.reference().duration() && a.reference().duration() < j.joint.blend.1
    );
    assert_joined_respects_limits(&free, &params, &s, &j.reference);
    let mut blocked = room();
    blocked.fill_box([1.71, 0.51, 1.21], [1.79, 1.49, 1.29], Cell::Occupied);
    let (a, b) = corner_pieces(&params, &blocked);
    let refused = splice(a.reference(), b.reference(), &params, &blocked, &s, 0.0);
    assert!(
        matches!(refused, Err(NoSplice::Inadmissible(_))),
        "{refused:?}"
    );
}

#[test]
fn a_short_piece_is_slowed_to_join_and_never_joins_slower_than_a_stop() {
    let (params, grid, s) = (ChainParams::new(3), room(), Settings::default());
    let a = piece(&params, &grid, [1.5, 1.0, 1.0], [2.5, 1.0, 1.0]);
    let b = piece(&params, &grid, [2.5, 1.0, 1.0], [2.5, 1.3, 1.0]);
    let j = splice(a.reference(), b.reference(), &params, &grid, &s, 0.0).unwrap();
    let (before, after) = (
        b.reference().segments()[0].scaling.rate,
        j.reference.segments(),
    );
    let joined_b = after.last().unwrap();
    assert!(
        joined_b.scaling.rate < before,
        "0.3 m cannot take the joint's ramp at its own cruise"
    );
    let stopped = a.reference().duration() + b.reference().duration();
    assert!(j.reference.duration() <= stopped);
    assert_joined_respects_limits(&grid, &params, &s, &j.reference);
}

#[test]
fn joins_that_cannot_be_made_are_refused_by_name() {
    let (params, grid, s) = (ChainParams::new(3), room(), Settings::default());
    let (a, b) = straight_on(&params, &grid);
    let (ra, rb) = (a.reference(), b.reference());
    let j = splice(ra, rb, &params, &grid, &s, 0.0).unwrap();
    let late = splice(ra, rb, &params, &grid, &s, j.joint.take_by + 0.01);
    assert!(matches!(late, Err(NoSplice::TooLate { .. })), "{late:?}");
    let unblended = Settings { blend: false, ..s };
    let off = splice(ra, rb, &params, &grid, &unblended, 0.0);
    assert_eq!(off.unwrap_err(), NoSplice::Unblended);
    // A motion that has come to rest and waits there, and a piece that waits first.
    let still = Reference::new(3, 0.5, &[ra.end().to_vec()], &s.limits.to_reference()).unwrap();
    let waiting = ra.then(ra.duration() + 1.0, &still).unwrap();
    let rested = splice(&waiting, rb, &params, &grid, &s, 0.0);
    assert_eq!(rested.unwrap_err(), NoSplice::AtRest);
    let held = rb.with_start_hold(1.0);
    let holds = splice(ra, &held, &params, &grid, &s, 0.0);
    assert_eq!(holds.unwrap_err(), NoSplice::PieceAtRest);
}

#[test]
fn the_rest_of_a_piece_is_flown_as_timed_after_its_joint() {
    let (params, grid, s) = (ChainParams::new(3), room(), Settings::default());
    let (a, b) = a_metre_then(
        &params,
        &grid,
        &[[2.5, 1.0, 1.0], [3.0, 1.0, 1.0], [3.0, 2.0, 1.0]],
    );
    assert!(
        b.reference().segments().len() >= 2,
        "a piece of two motions"
    );
    let j = splice(a.reference(), b.reference(), &params, &grid, &s, 0.0).unwrap();
    // After the joint the piece's own motion, shifted by one time.
    assert_own_motion_from_until(b.reference(), &j, s.dt);
    assert_joined_respects_limits(&grid, &params, &s, &j.reference);
}

/// From `j`'s `until` on, the joined motion is `piece`'s own shifted by one time, at
/// every `dt`.
fn assert_own_motion_from_until(piece: &Reference, j: &Splice, dt: f64) {
    let shift = j.reference.duration() - piece.duration();
    let own_from = j.joint.until - shift;
    let n = ((piece.duration() - own_from) / dt) as usize;
    for k in 0..=n {
        let t = own_from + k as f64 * dt;
        let (x, y) = (piece.zeta(t), j.reference.zeta(t + shift));
        let d = x
            .iter()
            .zip(&y)
            .map(|(p, q)| (p - q).abs())
            .fold(0.0, f64::max);
        assert!(d < 1e-9, "the piece's motion differs by {d} at {t} s of it");
    }
}

#[test]
fn a_short_first_motion_that_blends_into_the_next_is_slowed_and_that_corner_timed_anew() {
    let (params, grid, s) = (ChainParams::new(3), room(), Settings::default());
    // 0.2 m across, then on along x: at its own cruise the first motion cannot take
    // the joint's ramp, and it blends into the next, whose rate stays.
    let (a, b) = a_metre_then(
        &params,
        &grid,
        &[[2.5, 1.0, 1.0], [2.5, 1.2, 1.0], [3.5, 1.2, 1.0]],
    );
    let own = b.reference().segments();
    assert_eq!(own.len(), 2, "two motions");
    assert!(own[1].t0 < own[0].duration, "blended in the piece");
    let j = splice(a.reference(), b.reference(), &params, &grid, &s, 0.0).unwrap();
    let joined = j.reference.segments();
    let (jb, jc) = (&joined[joined.len() - 2], &joined[joined.len() - 1]);
    assert!(
        jb.scaling.rate < own[0].scaling.rate,
        "the first motion slowed"
    );
    assert_eq!(
        jc.scaling.rate, own[1].scaling.rate,
        "the next one's cruise kept"
    );
    assert!(jc.t0 < jb.t0 + jb.duration, "and still blended");
    // Both corners lie within the blend, where the bodies keep the clearance.
    assert_eq!(j.joint.blend, (jb.t0, jb.t0 + jb.duration));
    let stopped = a.reference().duration() + b.reference().duration();
    assert!(j.reference.duration() < stopped, "a stop saved");
    // From `until` on, the piece's own motion, shifted.
    assert_own_motion_from_until(b.reference(), &j, s.dt);
    assert_joined_respects_limits(&grid, &params, &s, &j.reference);
}

#[test]
fn a_joint_whose_ramps_cannot_fit_or_that_would_be_slower_is_refused() {
    let (params, grid, s) = (ChainParams::new(3), room(), Settings::default());
    // The piece's first motion, 0.3 m, blends into a next one that goes on almost
    // straight: slowed to take the joint's ramp, it would leave that next motion a
    // ramp up nearly from rest, which does not fit it at its own rate.
    let (a, b) = a_metre_then(
        &params,
        &grid,
        &[[2.5, 1.0, 1.0], [2.5, 1.3, 1.0], [2.55, 1.6, 1.0]],
    );
    assert_eq!(b.reference().segments().len(), 2, "two motions");
    let no_fit = splice(a.reference(), b.reference(), &params, &grid, &s, 0.0);
    assert_eq!(no_fit.unwrap_err(), NoSplice::RampsDoNotFit);
    // Turning straight back for 2.3 m: the joint's ramp fits the motion before it only
    // at a third of the speed, which costs more than the stop saves.
    let a = piece(&params, &grid, [2.5, 1.0, 1.0], [3.5, 1.0, 1.0]);
    let back = piece(&params, &grid, [3.5, 1.0, 1.0], [1.2, 1.0, 1.0]);
    let slower = splice(a.reference(), back.reference(), &params, &grid, &s, 0.0);
    assert_eq!(slower.unwrap_err(), NoSplice::Slower);
    // A piece that starts elsewhere is not joined.
    let elsewhere = piece(&params, &grid, [2.5, 1.0, 1.0], [3.0, 1.0, 1.0]);
    let refused = splice(
        a.reference(),
        elsewhere.reference(),
        &params,
        &grid,
        &s,
        0.0,
    );
    assert_eq!(refused.unwrap_err(), NoSplice::Elsewhere);
}

#[test]
fn a_joint_beside_a_wall_the_pieces_keep_close_keeps_what_they_keep() {
    let (params, s) = (ChainParams::new(3), Settings::default());
    // The bodies pass the wall's face at 3 cm, less than the 5 cm margin.
    let mut grid = room();
    grid.fill_box([0.51, 1.21, 0.51], [3.49, 1.29, 1.49], Cell::Occupied);
    let a = piece(&params, &grid, [1.5, 1.02, 1.0], [2.3, 1.02, 1.0]);
    let b = piece(&params, &grid, [2.3, 1.02, 1.0], [3.3, 1.02, 1.0]);
    let j = splice(a.reference(), b.reference(), &params, &grid, &s, 0.0).unwrap();
    let (t, z) = crate::trajectory::build::sample(&j.reference, s.dt).unwrap();
    let rep = crate::trajectory::check_samples(&grid, &params, &s.limits, &t, &z, 1.0);
    assert!(rep.ok, "{:?}", rep.violation);
    assert!(
        (rep.min_clearance - 0.03).abs() < 1e-6,
        "{}",
        rep.min_clearance
    );
    // Rounding a corner closer to a voxel than the pieces pass it is still refused:
    // the pieces keep 3.5 cm, the rounded joint would lift the tail to 1.5 cm.
    let mut blocked = room();
    blocked.fill_box([1.61, 0.51, 1.21], [1.69, 1.49, 1.29], Cell::Occupied);
    let a = piece(&params, &blocked, [1.6, 1.0, 1.015], [2.955, 1.0, 1.015]);
    let b = piece(&params, &blocked, [2.955, 1.0, 1.015], [2.955, 1.0, 1.8]);
    let refused = splice(a.reference(), b.reference(), &params, &blocked, &s, 0.0);
    assert!(
        matches!(&refused, Err(NoSplice::Inadmissible(v)) if matches!(v.problem, crate::trajectory::Problem::Clearance { .. })),
        "{refused:?}"
    );
}
