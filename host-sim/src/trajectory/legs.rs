//! A mission's plan timed leg by leg (docs/model.md, "Missions"): the plan is cut at
//! the waypoints that reach a goal, each leg is timed and blended on its own (so no
//! blend or merge passes a goal, and the chain comes to rest on it), and the legs are
//! joined with the goal's hold between them, every leg starting on a sample time.

use super::build::{sample, Trajectory};
use super::stages::Stages;
use super::{Plan, Settings, TrajectoryError};
use crate::trajectory::reference::{Reference, Scaling, Segment, SegmentKind};

/// One leg: the waypoints `from..=to` of the plan, and the hold at its end.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Leg {
    pub from: usize,
    pub to: usize,
    pub hold_s: f64,
}

impl Leg {
    /// The leg as a plan of its own (its waypoints, the plan's chain and map).
    pub fn plan(&self, whole: &Plan) -> Plan {
        let mut waypoints = whole.waypoints[self.from..=self.to].to_vec();
        for w in &mut waypoints {
            w.goal = None;
            w.hold_s = None;
        }
        Plan {
            format: whole.format.clone(),
            chain: whole.chain,
            map: whole.map.clone(),
            waypoints,
            stats: serde_json::Map::new(),
        }
    }
}

/// The legs of `plan`: cut at every inner waypoint that reaches a goal; each ends with
/// its last waypoint's hold (0 where none is asked).
pub(super) fn legs(plan: &Plan) -> Vec<Leg> {
    let last = plan.waypoints.len() - 1;
    let hold = |i: usize| plan.waypoints[i].hold_s.unwrap_or(0.0);
    let mut out = Vec::new();
    let mut from = 0;
    for (i, w) in plan.waypoints.iter().enumerate() {
        if i > from && (i == last || w.goal.is_some()) {
            out.push(Leg {
                from,
                to: i,
                hold_s: hold(i),
            });
            from = i;
        }
    }
    if out.is_empty() {
        out.push(Leg {
            from: 0,
            to: last,
            hold_s: hold(last),
        });
    }
    out
}

/// A segment where the chain rests at `at` (waypoint `to_waypoint`) from `t0` for
/// `duration` s.
fn hold(t0: f64, duration: f64, at: &[f64], to_waypoint: usize) -> Segment {
    Segment {
        kind: SegmentKind::Hold,
        t0,
        duration,
        from: at.to_vec(),
        delta: vec![0.0; at.len()],
        to_waypoint,
        scaling: Scaling::default(),
    }
}

/// The timed legs joined into the trajectory of `plan`: each leg's segments shifted to
/// start on the first sample time after the hold that ends the leg before it.
pub(super) fn join(
    plan: &Plan,
    settings: &Settings,
    timed: &[(Trajectory, &Leg)],
) -> Result<Trajectory, TrajectoryError> {
    let dt = settings.dt;
    let mut segments = Vec::new();
    let (mut offset, mut stop_go, mut head_path) = (0.0, 0.0, 0.0);
    let (mut corners, mut blended, mut merged) = (0, 0, 0);
    let mut stages = Stages::default();
    for (tr, leg) in timed {
        for s in tr.reference.segments() {
            let mut s = s.clone();
            s.t0 += offset;
            s.to_waypoint += leg.from;
            segments.push(s);
        }
        let end = offset + tr.reference.duration();
        if leg.hold_s > 0.0 {
            segments.push(hold(end, leg.hold_s, tr.reference.end(), leg.to));
        }
        // The next leg starts from rest on a sample time, as an unblended edge does.
        offset = ((end + leg.hold_s) / dt - super::TICK_GUARD).ceil() * dt;
        stop_go += tr.stop_go + leg.hold_s;
        head_path += tr.head_path;
        corners += tr.corners;
        blended += tr.blended;
        merged += tr.merged;
        stages.add(&tr.stages);
    }
    let first = &timed[0].0;
    let start = &plan.waypoints[0].zeta;
    let reference = Reference::from_segments(first.params.n(), start, segments);
    let (times, zetas) = sample(&reference, dt)?;
    Ok(Trajectory {
        params: first.params,
        settings: *settings,
        reference,
        times,
        zetas,
        corners: corners + timed.len() - 1,
        blended,
        merged,
        stop_go,
        head_path,
        stages,
        cut_short: timed.iter().any(|(tr, _)| tr.cut_short),
    })
}
