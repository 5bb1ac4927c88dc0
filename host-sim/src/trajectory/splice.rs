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
//! rate is lowered until its ramps fit too, when `b` ends at rest (nothing after it
//! depends on its rate), but never so far that `b` would end later than after a stop
//! at the joint. Up to the time where either `a`'s old or its new ramp down begins,
//! the joined motion is the committed one, so it can replace it while the chain flies
//! there ([`Joint::take_by`]). From then until the piece's motion is timed as its own
//! again ([`Joint::until`]) it is new: those samples are checked exactly on the map
//! given (the online planner's: unknown space occupied), and wherever the motion
//! leaves both pieces' paths (the overlap) every body keeps the trajectory settings'
//! clearance from the map, or what the two motions keep there where that is less, as a
//! blend of one plan does.

use aerial_chain_core::ChainParams;

use super::build::{ramp_length, FIT_UNDERSHOOT};
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
    /// of the piece's first ramp up as joined and as timed alone, or the end of its
    /// first motion where that was slowed down. From `take_by` to here the motion is
    /// new, and checked ([`check_joint`]).
    pub until: f64,
    /// When the joined motion leaves both pieces' paths and when it is back on the
    /// piece's: the blend of the corner at the joint, where every body keeps the
    /// trajectory's clearance.
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
    /// The joined motion would reach the end of the piece's first motion later than a
    /// stop at the joint would (the piece's first motion slowed down too much to fit).
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
    let (sa, sb) = (&a.scaling, &b.scaling);
    let (rate, ramp) = fit(a, b, next, settings).ok_or(NoSplice::RampsDoNotFit)?;
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
    let b_new = retimed(
        b,
        a_end - ramp,
        Scaling::with_ramps(rate, ramp, sb.ramp_down),
    );
    // Stopping at the joint, `b` would end no earlier than this.
    let stopped_end = current.duration() + b.duration;
    if b_new.t0 + b_new.duration > stopped_end {
        return Err(NoSplice::Slower);
    }
    // The piece's later segments keep their times relative to the end of `b`.
    let shift = (b_new.t0 + b_new.duration) - (b.t0 + b.duration);
    let mut joined: Vec<Segment> = segments[..segments.len() - 1].to_vec();
    joined.push(a_new);
    // `b` is timed as in the piece (shifted) once both its ramps up are over; where
    // it cruises slower than after a stop, only after its end.
    let new_to = match rate < sb.rate {
        true => b_new.t0 + b_new.duration,
        false => (b_new.t0 + ramp).max(shift + sb.ramp),
    };
    let blend = (b_new.t0, a_end);
    joined.push(b_new);
    joined.extend(next.segments()[1..].iter().cloned().map(|mut s| {
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

/// The cruise rate of `b` and the joint's ramp: the ramp that changes the velocity
/// from `a`'s cruise to `b`'s within the limits, `b`'s rate lowered until both
/// segments' ramps fit (as `super::build` fits a plan's), in at most
/// `settings.fit_rounds` rounds. `b`'s rate is lowered only when `b` ends at rest, so
/// that nothing after it depends on it; `None` when they do not fit.
fn fit(a: &Segment, b: &Segment, next: &Reference, settings: &Settings) -> Option<(f64, f64)> {
    let (sa, sb) = (&a.scaling, &b.scaling);
    let b_end = b.t0 + b.duration;
    let b_rests = next.segments().get(1).is_none_or(|c| c.t0 >= b_end);
    let mut rate = sb.rate;
    for _ in 0..settings.fit_rounds {
        let change: Vec<f64> = (a.delta.iter().zip(&b.delta))
            .map(|(da, db)| rate * db - sa.rate * da)
            .collect();
        let ramp = ramp_length(&settings.limits, &change);
        let excess = (sa.rate * (sa.ramp + ramp) / 2.0).max(rate * (ramp + sb.ramp_down) / 2.0);
        if excess <= 1.0 {
            return Some((rate, ramp));
        }
        if !b_rests {
            return None;
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
