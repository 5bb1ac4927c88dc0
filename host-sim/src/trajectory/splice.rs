//! Joining a trajectory onto a motion in flight without a stop at the joint: the online
//! planner's next piece starts where the committed motion ends at rest, and if it is
//! committed before the chain begins to slow down for that rest, the two are flown as
//! one motion, the corner between them blended as [`super::build`] blends a plan's
//! corners (docs/online.md, "Pieces joined in flight").
//!
//! The committed motion's last segment `a` ramps down to rest over `W_a`; the piece's
//! first segment `b` ramps up from rest over `U_b`. Joined, both ramps take the one
//! length `R` that changes the velocity from `a`'s cruise to `b`'s within the limits
//! (`super::build`'s rule), and `b` starts `R` before `a` ends. `a` is in flight, so its
//! cruise rate stays and its ramps must fit (`r (U + W) / 2 <= 1`) as they are; `b`'s
//! rate is lowered until its ramps fit too. Where `b` blends into the piece's next
//! segment `c`, their corner is timed again for `b`'s new rate, and `c`, whose cruise
//! rate stays (so nothing after it changes), must fit the new ramp up. Never so far
//! that the segments timed anew would end later than after a stop at the joint. Up
//! to the time where either `a`'s old or its new ramp down begins,
//! the joined motion is the committed one, so it can replace it while the chain flies
//! there ([`Joint::take_by`]). From then until the piece's motion is timed as its own
//! again ([`Joint::until`]) it is new: those samples are checked exactly on the map
//! given (the online planner's: unknown space occupied), and wherever the motion
//! leaves both pieces' paths (the overlaps: at the joint, and at `b`'s corner with `c`
//! where that was timed again) every body keeps the trajectory settings' clearance
//! from the map, or what the motions there keep on their own where that is less, as a
//! blend of one plan does.

use aerial_chain_core::ChainParams;

use super::build::{ramp_between, ramp_length, FIT_UNDERSHOOT};
use super::check::{check_with_margin, move_clearance, Problem, Violation};
use super::reference::{same_configuration, Reference, Scaling, Segment};
use super::Settings;
use crate::map::Grid;

/// A joined motion.
#[derive(Clone, Debug)]
pub struct Splice {
    /// The committed motion, then the piece without a stop between them.
    pub reference: Reference,
    /// Where and when it differs from the two motions flown one after the other.
    pub joint: Joint,
}

/// A joint flown without a stop, in the joined motion's time (s).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Joint {
    /// Latest time at which the joined motion may replace the committed motion: until
    /// then the two are the same motion.
    pub take_by: f64,
    /// When the joined motion is the piece's own again, shifted in time: the later end
    /// of the ramp up of the last of the piece's motions timed anew (its first, or the
    /// next where their corner was timed again) as joined and as timed alone, or the
    /// end of its first motion where that was slowed down and ends at rest. From
    /// `take_by` to here the motion is new, and checked ([`check_joint`]).
    pub until: f64,
    /// When the joined motion leaves both pieces' paths and when it is back on the
    /// piece's: the blend of the corner at the joint (through the piece's first corner
    /// where that was timed again), where every body keeps the trajectory's
    /// clearance.
    pub blend: (f64, f64),
}

/// Why a piece cannot be joined in flight (it then starts from rest after the
/// committed motion ends).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum NoSplice {
    /// The trajectory settings do not blend.
    #[error("the trajectory settings do not blend corners")]
    Unblended,
    /// The committed motion does not end in a motion (it is at rest, or holds).
    #[error("the committed motion ends at rest")]
    AtRest,
    /// The piece does not start with a motion from time 0.
    #[error("the piece does not start with a motion")]
    PieceAtRest,
    /// The piece does not start where the committed motion ends.
    #[error("the piece does not start where the committed motion ends")]
    Elsewhere,
    /// The ramps of the joint would not fit their segments at their cruise rates.
    #[error("the ramps of the joint do not fit its segments")]
    RampsDoNotFit,
    /// The committed motion begins to slow down before the join could take effect.
    #[error("the committed motion slows down at {take_by:.3} s, before {not_before:.3} s")]
    TooLate {
        /// When it must have taken effect (s).
        take_by: f64,
        /// The earliest it can (s).
        not_before: f64,
    },
    /// The joined motion would reach the end of the piece's motions timed anew (its
    /// first, and the next where their corner was timed again) later than a stop at
    /// the joint would (the piece's first motion slowed down too much to fit).
    #[error("the joined motion is slower than a stop at the joint")]
    Slower,
    /// The joined motion fails the exact check or the blend's clearance.
    #[error("the joined motion is not admissible: {0}")]
    Inadmissible(Violation),
}

/// Joins `next` (which starts at rest where `current` ends) onto `current`, the motion
/// of chain `params` in flight, without a stop (see the module docs), if the join can
/// take effect at `not_before` (s) or later and the new part of the motion passes the
/// exact check on `grid` within `settings`.
pub fn splice(
    current: &Reference,
    next: &Reference,
    params: &ChainParams,
    grid: &Grid,
    settings: &Settings,
    not_before: f64,
) -> Result<Splice, NoSplice> {
    if !settings.blend {
        return Err(NoSplice::Unblended);
    }
    let segments = current.segments();
    let (Some(a), Some(b)) = (segments.last(), next.segments().first()) else {
        return Err(match segments.is_empty() {
            true => NoSplice::AtRest,
            false => NoSplice::PieceAtRest,
        });
    };
    if a.is_hold() || a.t0 + a.duration < current.duration() {
        return Err(NoSplice::AtRest);
    }
    if b.is_hold() || b.t0 != 0.0 {
        return Err(NoSplice::PieceAtRest);
    }
    if !same_configuration(&b.from, current.end()) {
        return Err(NoSplice::Elsewhere);
    }
    let sa = &a.scaling;
    let fitted = fit(a, b, next, settings).ok_or(NoSplice::RampsDoNotFit)?;
    let ramp = fitted.ramp;
    // The cruise of `a` ends where its ramp down begins: the old one or the new one.
    let take_by = a.t0 + 1.0 / sa.rate + (sa.ramp - sa.ramp_down.max(ramp)) / 2.0;
    if take_by < not_before {
        return Err(NoSplice::TooLate {
            take_by,
            not_before,
        });
    }
    let a_new = retimed(a, a.t0, Scaling::with_ramps(sa.rate, sa.ramp, ramp));
    let a_end = a_new.t0 + a_new.duration;
    let new = timed_anew(next, a_end, &fitted);
    let (old, last) = (&next.segments()[new.len() - 1], &new[new.len() - 1]);
    let (old_end, last_end) = (old.t0 + old.duration, last.t0 + last.duration);
    // Stopping at the joint, the segments timed anew would end no earlier than this.
    if last_end > current.duration() + old_end {
        return Err(NoSplice::Slower);
    }
    // The piece's later segments keep their times relative to the end of the last
    // one timed anew, which is timed as in the piece (shifted) once both its ramps up
    // are over; where it cruises slower than in the piece, only after its end.
    let shift = last_end - old_end;
    let new_to = match last.scaling.rate < old.scaling.rate {
        true => last_end,
        false => (last.t0 + last.scaling.ramp).max(shift + old.t0 + old.scaling.ramp),
    };
    // Where the motion leaves both pieces' paths: the joint's corner, and `b`'s
    // corner with the next segment where that was timed anew.
    let b_new = &new[0];
    let blend = match fitted.then {
        None => (b_new.t0, a_end),
        Some(_) => (b_new.t0, b_new.t0 + b_new.duration),
    };
    let count = new.len();
    let mut joined: Vec<Segment> = segments[..segments.len() - 1].to_vec();
    joined.push(a_new);
    joined.extend(new);
    joined.extend(next.segments()[count..].iter().cloned().map(|mut s| {
        s.t0 += shift;
        s
    }));
    let first = segments.first().map_or(current.end(), |s| &s.from).to_vec();
    let reference = Reference::from_segments(current.units(), &first, joined);
    let joint = Joint {
        take_by,
        until: new_to,
        blend,
    };
    check_joint(&reference, params, grid, settings, &joint).map_err(NoSplice::Inadmissible)?;
    Ok(Splice { reference, joint })
}

/// The piece `next`'s first segments timed anew for a joint whose ramp ends at
/// `a_end` (s) as `fit` has it: its first segment `b` at the fitted rate, starting the
/// joint's ramp before `a_end`; and where `b`'s corner with the next segment was timed
/// again, that segment too, its cruise kept and its ramp up the corner's new one.
fn timed_anew(next: &Reference, a_end: f64, fit: &Fit) -> Vec<Segment> {
    let b = &next.segments()[0];
    let down = fit.then.unwrap_or(b.scaling.ramp_down);
    let scaling = Scaling::with_ramps(fit.rate, fit.ramp, down);
    let b_new = retimed(b, a_end - fit.ramp, scaling);
    let b_end = b_new.t0 + b_new.duration;
    let mut new = vec![b_new];
    if let Some(up) = fit.then {
        let c = &next.segments()[1];
        let scaling = Scaling::with_ramps(c.scaling.rate, up, c.scaling.ramp_down);
        new.push(retimed(c, b_end - up, scaling));
    }
    new
}

/// How a joint fits: `b`'s cruise rate, the joint's ramp, and where `b` was slowed
/// and blends into the piece's next motion, the ramp of that corner timed anew.
struct Fit {
    rate: f64,
    ramp: f64,
    then: Option<f64>,
}

/// The cruise rate of `b` and the joint's ramp: the ramp that changes the velocity
/// from `a`'s cruise to `b`'s within the limits, `b`'s rate lowered until both
/// segments' ramps fit (as `super::build` fits a plan's), in at most
/// `settings.fit_rounds` rounds. Where `b` blends into the piece's next motion `c`,
/// slowing `b` changes that corner too: its ramp is taken again for `b`'s new rate,
/// and it must fit `c` at `c`'s own rate, so that nothing after `c` changes. `None`
/// when they do not fit.
fn fit(a: &Segment, b: &Segment, next: &Reference, settings: &Settings) -> Option<Fit> {
    let (sa, sb) = (&a.scaling, &b.scaling);
    let b_end = b.t0 + b.duration;
    let c = next.segments().get(1).filter(|c| c.t0 < b_end);
    let lim = &settings.limits;
    let mut rate = sb.rate;
    for _ in 0..settings.fit_rounds {
        let ramp = ramp_between(lim, Some((a, sa.rate)), Some((b, rate)));
        // `b`'s corner with `c` as the piece timed it, or again for a slowed `b`.
        let then = c
            .filter(|_| rate < sb.rate)
            .map(|c| ramp_between(lim, Some((b, rate)), Some((c, c.scaling.rate))));
        let down = then.unwrap_or(sb.ramp_down);
        let c_excess = match (c, then) {
            (Some(c), Some(up)) => c.scaling.rate * (up + c.scaling.ramp_down) / 2.0,
            _ => 0.0,
        };
        let excess = (sa.rate * (sa.ramp + ramp) / 2.0)
            .max(rate * (ramp + down) / 2.0)
            .max(c_excess);
        if excess <= 1.0 {
            return Some(Fit { rate, ramp, then });
        }
        rate /= excess.sqrt() * FIT_UNDERSHOOT;
    }
    None
}

/// How long before the end of a motion whose last segment is `last` (moving, ending at
/// rest) a piece must be joined so that any piece can be: `(W + R) / 2` with `W` its
/// ramp down and `R` the longest joint ramp. A piece's first motion moves the head at
/// most at the speed limit and every angle at most at its rate limit, so its ramp from
/// rest is at most `R_0`, that of all of them at once; the joint's velocity change is at
/// most `last`'s to rest plus that, so `R <= W + R_0`, and the lead is `W + R_0 / 2`.
pub fn lead(last: &Segment, limits: &super::Limits) -> f64 {
    let full = [limits.speed, 0.0, 0.0, limits.yaw_rate, limits.angular_rate];
    last.scaling.ramp_down + ramp_length(limits, &full) / 2.0
}

/// Segment `s` started at `t0` with `scaling`.
fn retimed(s: &Segment, t0: f64, scaling: Scaling) -> Segment {
    Segment {
        t0,
        duration: scaling.duration,
        scaling,
        ..s.clone()
    }
}

/// Checks the new part of `reference` at `joint` exactly on `grid`: from `take_by` to
/// `until` (a sample beyond each), sampled every `settings.dt`, within the limits;
/// within the blend (a sample either side) every body keeps `settings.clearance` from
/// the map, or what the motions the blend joins keep on their own where that is less.
/// What a join is checked by, and what an audit of a flown motion checks again.
pub fn check_joint(
    reference: &Reference,
    params: &ChainParams,
    grid: &Grid,
    settings: &Settings,
    joint: &Joint,
) -> Result<(), Violation> {
    let (dt, blend) = (settings.dt, joint.blend);
    let start = (joint.take_by - dt).max(0.0);
    // The span is a few ramps long: far below the samples' budget.
    let count = ((joint.until + dt - start) / dt).ceil().max(0.0) as usize + 1;
    let times: Vec<f64> = (0..count).map(|j| start + j as f64 * dt).collect();
    let zetas: Vec<Vec<f64>> = times.iter().map(|&t| reference.zeta(t)).collect();
    let margin = settings.clearance;
    let check = |need: f64| {
        let required = |t: f64| match blend.0 - dt <= t && t <= blend.1 + dt {
            true => need,
            false => 0.0,
        };
        let lim = &settings.limits;
        check_with_margin(grid, params, lim, (&times, &zetas), margin, &required).violation
    };
    match check(margin) {
        // Short of the margin, the blend may keep what the two pieces' own motions
        // there keep (a blend of one plan's rule).
        Some(v) if matches!(v.problem, Problem::Clearance { .. }) => {
            match check(blended_kept(reference, params, grid, blend, margin)) {
                Some(v) => Err(v),
                None => Ok(()),
            }
        }
        Some(v) => Err(v),
        None => Ok(()),
    }
}

/// The smallest clearance (capped at `margin`) of the straight moves of `reference`
/// whose time overlaps `blend`: what the motions the blend joins keep on their own.
fn blended_kept(
    reference: &Reference,
    params: &ChainParams,
    grid: &Grid,
    blend: (f64, f64),
    margin: f64,
) -> f64 {
    let overlaps = |s: &&Segment| s.t0 <= blend.1 && blend.0 <= s.t0 + s.duration;
    let kept = |s: &Segment| move_clearance(grid, params, (&s.from, &s.to()), margin);
    let segments = reference.segments().iter().filter(overlaps);
    segments.map(kept).fold(margin, f64::min)
}

#[cfg(test)]
#[path = "splice_tests.rs"]
mod tests;
