//! The generator: a plan's edges timed with smooth ramps, consecutive edges blended
//! where the blend is admissible.
//!
//! Edge `k` advances its progress `s` from 0 to 1: a smoothstep ramp up of length
//! `U_k`, a cruise at rate `r_k`, a smoothstep ramp down of length `W_k`; it lasts
//! `D_k = 1/r_k + (U_k + W_k)/2`. At a corner that is not blended, edge `k` ramps down
//! to rest, and edge `k + 1` starts from rest after it on the next sample time. At a
//! blended corner the two ramps have one length `R` and overlap exactly: edge `k + 1`
//! starts `R` before edge `k` ends, so the chain moves by the sum of both and the
//! velocity passes from one edge's cruise to the other's. During the overlap every rate
//! is a convex mix of the two cruises (one ramps down as the other ramps up), so speeds
//! and angle rates stay within their limits; the acceleration is `S'(x)/R` times the
//! change of velocity, so `R = 1.5 * max(|dV_head| / accel, max_j |d omega_j| /
//! angular_accel_j)` keeps it within its limits (`angular_accel_j` is the head yaw's
//! own limit for the head yaw, `angular_accel` for every link angle). A ramp from or
//! to rest is the same rule with the other velocity zero. The ramps of an edge must
//! fit (`r (U + W) / 2 <= 1`): where they do not, the edge's cruise is lowered until
//! they do.
//!
//! Before that, consecutive edges may be merged into one motion, straight in `zeta`,
//! that moves head and shape at once (`super::group`, `super::merge`): a run of short
//! edges that already lie nearly on a line in `zeta`, or a shape change and (part of)
//! the translation beside it.
//!
//! What a blend or a merge can break is the chain's validity (the map, self-collision,
//! the bend limit) and the clearance the planner kept: the sampled trajectory is checked
//! exactly ([`super::check_samples`]), and where the motion is not the plan's own every
//! body must also keep `Settings::clearance` from the map, or as much as the plan's own
//! edges there keep where that is less (a piece committed beside unknown space keeps
//! millimetres less than the margin, and no blend of it could keep the margin). A
//! blended corner where the check fails is unblended, else a merged motion there gives
//! way a step (a run is halved, a pair flies less of its translation or comes apart),
//! and the timing is redone, until the whole passes. Without blends the chain is on
//! the plan's own edges, resting on a sample at every waypoint, so only a plan that is
//! itself inadmissible fails.
//!
//! With blends, a turn of the head yaw alone first runs during the edges before it
//! (`super::turns`): the yaw moves no body, so the bodies still move as the plan's
//! edges move them.
//!
//! A deadline ([`build_until`]) bounds the rounds: a round that begins after it gives
//! way everywhere at once (no blend, no merge: the plan's own edges, stop and go) and is
//! the last, so what is kept is a trajectory as valid as the plan, less smooth.

use std::collections::HashSet;
use std::ops::Range;
use std::time::Instant;

use aerial_chain_core::ChainParams;

use super::check::{check_with_margin, move_clearance, Problem, Violation};
use super::stages::{Stage, Stages};
use super::{group, merge};
use super::{Plan, Settings, TrajectoryError, MAX_SAMPLES};
use crate::map::Grid;
use crate::trajectory::reference::{angle_demand, Reference, Scaling, Segment};

/// Peak of the smoothstep's derivative: a ramp of length `R` that changes a rate by
/// `dv` accelerates by at most `1.5 dv / R`. Derived (the smoothstep `3t^2 - 2t^3` has
/// the largest slope 1.5, at its middle), not tuning.
const RAMP_PEAK: f64 = 1.5;

/// Each round of fitting lowers an edge's rate this much below what fits it exactly, so
/// that rounding cannot keep the fit from ending. A numerical guard, not tuning.
pub(super) const FIT_UNDERSHOOT: f64 = 1.001;

/// A timed trajectory: its samples, and the analytic motion they were taken from.
#[derive(Clone, Debug)]
pub struct Trajectory {
    pub(super) params: ChainParams,
    pub(super) settings: Settings,
    pub(super) reference: Reference,
    pub(super) times: Vec<f64>,
    pub(super) zetas: Vec<Vec<f64>>,
    pub(super) corners: usize,
    pub(super) blended: usize,
    pub(super) merged: usize,
    pub(super) stop_go: f64,
    pub(super) head_path: f64,
    pub(super) stages: Stages,
    pub(super) cut_short: bool,
}

impl Trajectory {
    /// The chain.
    pub fn params(&self) -> &ChainParams {
        &self.params
    }
    /// The settings it was made with.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }
    /// The analytic motion (what `arc sim` flies): `zeta` and its derivatives at any time.
    pub fn reference(&self) -> &Reference {
        &self.reference
    }
    /// Sample times (s): the multiples of the sample spacing from 0.
    pub fn times(&self) -> &[f64] {
        &self.times
    }
    /// `zeta` at every sample (angles continuous, not wrapped).
    pub fn zetas(&self) -> &[Vec<f64>] {
        &self.zetas
    }
    /// Time of the last sample, where the chain rests at the plan's end (s).
    pub fn duration(&self) -> f64 {
        self.times.last().copied().unwrap_or(0.0)
    }
    /// Places where two edges meet (edges that change nothing left out).
    pub fn corners(&self) -> usize {
        self.corners
    }
    /// Corners flown blended (the next edge ramping up as the one before ramps down).
    pub fn blended(&self) -> usize {
        self.blended
    }
    /// Edges flown in one move with the edge before them (a merged pair counts one, a
    /// run of `k` edges `k - 1`, a turn of the head yaw alone flown during the edges
    /// before it one).
    pub fn merged(&self) -> usize {
        self.merged
    }
    /// The duration when the chain stops at every waypoint, as `arc sim` timed plans (s).
    pub fn stop_go_duration(&self) -> f64 {
        self.stop_go
    }
    /// Length of the head's path (m).
    pub fn head_path_m(&self) -> f64 {
        self.head_path
    }

    /// Whether the deadline ([`build_until`]) stopped the rounds: the plan timed stop
    /// and go, without the blends and merges that more rounds might have kept.
    pub fn cut_short(&self) -> bool {
        self.cut_short
    }

    /// What each stage of the generator did over its rounds (`super::stages`).
    pub fn stages(&self) -> &Stages {
        &self.stages
    }
}

/// Times `plan` within `settings` and blends its corners where the blended motion is
/// admissible on `grid` (whose choice about unknown space is the one checked). Fails when
/// the plan breaks its format, cannot be timed, or is not admissible even without blends.
///
/// A mission's plan (waypoints that reach goals, docs/model.md "Missions") is timed
/// leg by leg: every leg ends at rest on its goal, the chain holds there for the goal's
/// `hold_s`, and the next leg starts on the next sample time.
pub fn build(plan: &Plan, grid: &Grid, settings: &Settings) -> Result<Trajectory, TrajectoryError> {
    build_until(plan, grid, settings, None)
}

/// [`build`] that stops giving way at `deadline` (none: no deadline): a round that
/// begins after it times the plan stop and go (no blend, no merge) and is the last
/// ([`Trajectory::cut_short`]). Its work after the deadline is that round's timing and
/// one exact check of its samples. Below the deadline the result is [`build`]'s.
pub fn build_until(
    plan: &Plan,
    grid: &Grid,
    settings: &Settings,
    deadline: Option<Instant>,
) -> Result<Trajectory, TrajectoryError> {
    plan.check()?;
    settings.validate()?;
    let legs = super::legs::legs(plan);
    if legs.len() == 1 && legs[0].hold_s == 0.0 {
        return build_leg(plan, grid, settings, deadline);
    }
    let mut timed = Vec::with_capacity(legs.len());
    for leg in &legs {
        timed.push((build_leg(&leg.plan(plan), grid, settings, deadline)?, leg));
    }
    super::legs::join(plan, settings, &timed)
}

/// [`build_until`] of one leg: a plan whose goals, if any, are at its ends.
fn build_leg(
    plan: &Plan,
    grid: &Grid,
    settings: &Settings,
    deadline: Option<Instant>,
) -> Result<Trajectory, TrajectoryError> {
    let params = plan.check()?;
    let waypoints: Vec<Vec<f64>> = plan.waypoints.iter().map(|w| w.zeta.clone()).collect();
    let l = params.link_length as f64;
    let limits = settings.limits.to_reference();
    let timed = Reference::new(params.n(), l, &waypoints, &limits)?;
    let corners = timed.segments().len().saturating_sub(1);
    // The plan's own edges, and (with blends) its turns of the head yaw alone flown
    // during the edges before them.
    let own: Vec<Segment> = timed.segments().to_vec();
    let (mut edges, mut turns) = match settings.blend {
        true => super::turns::spread(own.clone(), l, &limits),
        false => (own.clone(), 0),
    };
    let stop_go = timed.duration();
    let steps = (stop_go / settings.dt).ceil() as usize + edges.len() + 1;
    if steps > MAX_SAMPLES {
        return Err(TrajectoryError::TooLong(steps));
    }
    let head_path = edges.iter().map(|s| merge::head_length(&s.delta)).sum();
    let mut demands = group::Demands::new();
    let mut grouping = group::Grouping::new(&edges, l, settings.blend, settings);
    // The places where a motion starts whose blend with the one before was undone.
    let mut unblended: HashSet<u64> = HashSet::new();
    // What the last round checked: its segments, and the first sample it found wrong.
    let mut last: Option<(Vec<Segment>, usize)> = None;
    let mut stages = Stages::default();
    // What the plan's own edges keep from the map, measured where a blend needs it.
    let margin = settings.clearance;
    let mut kept = Kept::new(&edges, margin);
    // Set by the first round that begins after the deadline: it gives way everywhere.
    let mut cut_short = false;
    // Each round runs the stages in `Stage::ROUND`'s order.
    loop {
        if !cut_short && deadline.is_some_and(|d| Instant::now() >= d) {
            cut_short = true;
            (edges, turns) = (own.clone(), 0);
            kept = Kept::new(&edges, margin);
            demands.clear();
            grouping = group::Grouping::new(&edges, l, false, settings);
        }
        let motions = stages.run(Stage::Group, || {
            let m = grouping.assemble(&edges, &mut demands, &limits, l);
            let n = m.segments.len() as u64;
            (m, n)
        });
        let starts: Vec<f64> = grouping.starts().collect();
        let mut blend_m: Vec<bool> = starts
            .iter()
            .enumerate()
            .map(|(m, p)| {
                m > 0 && settings.blend && !cut_short && !unblended.contains(&p.to_bits())
            })
            .collect();
        let timing = Timing {
            settings,
            edges: &motions.segments,
            max_rates: motions.rates,
        };
        let segments = stages.run(Stage::Fit, || timing.segments(&mut blend_m));
        for (m, (p, b)) in starts.iter().zip(&blend_m).enumerate() {
            if m > 0 && !b {
                unblended.insert(p.to_bits());
            }
        }
        let merged_m = motions.merged;
        let reference = Reference::from_segments(params.n(), &waypoints[0], segments);
        let (times, zetas) = sample(&reference, settings.dt)?;
        let spans: Vec<_> = grouping.edge_spans().collect();
        let windows = windows(
            reference.segments(),
            (&blend_m, &merged_m),
            &spans,
            settings.dt,
        );
        let needs: Vec<f64> = windows.iter().map(|w| kept.need(&w.edges)).collect();
        let required = |t: f64| {
            let inside = windows.iter().zip(&needs).filter(|(w, _)| w.holds(t));
            inside
                .map(|(_, need)| *need)
                .reduce(f64::min)
                .unwrap_or(0.0)
        };
        // Samples before the first segment that changed passed last round's check.
        let from = last.as_ref().map_or(0, |(before, bad)| {
            resume_at(before, reference.segments(), settings.dt).min(bad.saturating_sub(2))
        });
        let lim = &settings.limits;
        let part = (&times[from..], &zetas[from..]);
        let rep = stages.run(Stage::Check, || {
            let rep = check_with_margin(grid, &params, lim, part, margin, &required);
            let n = rep.configurations as u64;
            (rep, n)
        });
        let Some(mut v) = rep.violation else {
            // Corners of the plan flown blended: a motion that starts where an edge does.
            let blended = starts
                .iter()
                .zip(&blend_m)
                .filter(|(p, b)| **b && p.fract() == 0.0)
                .count();
            return Ok(Trajectory {
                params,
                settings: *settings,
                reference,
                times,
                zetas,
                corners,
                blended,
                merged: grouping.merged_corners() + turns,
                stop_go,
                head_path,
                stages,
                cut_short,
            });
        };
        v.sample += from;
        let segs = reference.segments();
        last = Some((segs.to_vec(), v.sample));
        let gave_way = stages.run(Stage::GiveWay, || {
            // A blend short of the margin may keep what the plan's own edges keep
            // there: those edges are measured before anything gives way.
            if matches!(v.problem, Problem::Clearance { .. }) {
                let t = at(&v, settings.dt);
                let near = windows.iter().filter(|w| w.holds(t));
                let edges: Vec<usize> = near.flat_map(|w| w.edges.clone()).collect();
                if kept.measure(&edges, grid, &params) {
                    return (true, 0);
                }
            }
            if let Some(m) = corner_near(segs, &blend_m, &v, settings.dt) {
                unblended.insert(starts[m].to_bits());
            } else if let Some(m) = merged_near(segs, &merged_m, &v, settings.dt) {
                // A run is halved, a pair flies less of its translation or comes apart.
                grouping.undo(m, &edges);
            } else {
                return (false, 0);
            }
            (true, 1)
        });
        if !gave_way {
            return Err(TrajectoryError::Inadmissible(v));
        }
    }
}

/// A time where the motion is not the plan's own, and the plan's edges it replaces.
struct Window {
    /// From when to when (s).
    time: (f64, f64),
    /// The edges (indices into the plan's edges as timed) whose path it leaves.
    edges: Range<usize>,
}

impl Window {
    fn holds(&self, t: f64) -> bool {
        self.time.0 <= t && t <= self.time.1
    }
}

/// The times (one sample either side) where the motion is not the plan's own: the
/// overlap of every blended corner (the edges of both motions) and every merged motion
/// (its edges); `spans` are the edges each motion flies.
fn windows(
    segments: &[Segment],
    (blend, merged): (&[bool], &[bool]),
    spans: &[Range<usize>],
    dt: f64,
) -> Vec<Window> {
    let end = |s: &Segment| s.t0 + s.duration;
    let mut w = Vec::new();
    for (m, s) in segments.iter().enumerate() {
        if blend[m] && m > 0 {
            w.push(Window {
                time: (s.t0 - dt, end(&segments[m - 1]) + dt),
                edges: spans[m - 1].start..spans[m].end,
            });
        }
        if merged[m] {
            w.push(Window {
                time: (s.t0 - dt, end(s) + dt),
                edges: spans[m].clone(),
            });
        }
    }
    w
}

/// The clearance from the map each of the plan's edges keeps, capped at the margin,
/// measured only where a blend or merge fell short of the margin (most plans' blends
/// never do). A motion that is not the plan's own keeps the margin, or what the edges
/// it replaces keep where that is less: it comes no closer to the map than the plan
/// there, nor closer than the margin where the plan keeps it.
struct Kept {
    /// Each edge's start and end configuration.
    moves: Vec<(Vec<f64>, Vec<f64>)>,
    /// Each edge's clearance once measured.
    clearance: Vec<Option<f64>>,
    margin: f64,
}

impl Kept {
    fn new(edges: &[Segment], margin: f64) -> Self {
        Self {
            moves: edges.iter().map(|s| (s.from.clone(), s.to())).collect(),
            clearance: vec![None; edges.len()],
            margin,
        }
    }

    /// What a motion replacing `edges` must keep: the margin, or less where an edge
    /// measured keeps less.
    fn need(&self, edges: &Range<usize>) -> f64 {
        let measured = edges
            .clone()
            .filter_map(|k| self.clearance.get(k).copied().flatten());
        measured.fold(self.margin, f64::min)
    }

    /// Measures those of `edges` not measured yet; whether there were any.
    fn measure(&mut self, edges: &[usize], grid: &Grid, params: &ChainParams) -> bool {
        let mut any = false;
        for &k in edges {
            if k >= self.clearance.len() || self.clearance[k].is_some() {
                continue;
            }
            let (a, b) = &self.moves[k];
            self.clearance[k] = Some(move_clearance(grid, params, (a, b), self.margin));
            any = true;
        }
        any
    }
}

/// The sample from which a trajectory of `now` segments must be checked again when one
/// of `before` segments passed up to there: two samples before the first segment that
/// differs (the acceleration at a sample looks one back).
fn resume_at(before: &[Segment], now: &[Segment], dt: f64) -> usize {
    let first = before.iter().zip(now).position(|(a, b)| a != b);
    let t = match first {
        Some(i) => now[i].t0.min(before[i].t0),
        None if before.len() == now.len() => return usize::MAX,
        None => now.get(before.len()).map_or(0.0, |s| s.t0),
    };
    ((t / dt).floor().max(0.0) as usize).saturating_sub(2)
}

/// When `v` happened: its interval's start plus its share of the sample spacing.
fn at(v: &Violation, dt: f64) -> f64 {
    v.t + v.fraction * dt
}

/// The merged motion whose time (two samples either side) holds `v`, the last if
/// several.
fn merged_near(segments: &[Segment], merged: &[bool], v: &Violation, dt: f64) -> Option<usize> {
    let (pad, t) = (2.0 * dt, at(v, dt));
    (0..segments.len()).rev().find(|&m| {
        merged[m] && t >= segments[m].t0 - pad && t <= segments[m].t0 + segments[m].duration + pad
    })
}

/// The samples of `r`: every multiple of `dt` up to the first at or after its end (an
/// unblended edge starts on one, so the chain is sampled at rest at its waypoint).
/// Blends are timed by the limits, not by the plan's stop-and-go length, so the
/// budget is checked here again, before the samples are made.
pub(super) fn sample(r: &Reference, dt: f64) -> Result<(Vec<f64>, Vec<Vec<f64>>), TrajectoryError> {
    let last = ((r.duration() / dt) - super::TICK_GUARD).ceil().max(0.0);
    // `max` has made a NaN duration 0; `as` saturates an infinite one.
    if last >= MAX_SAMPLES as f64 {
        return Err(TrajectoryError::TooLong(last as usize));
    }
    Ok((0..=last as usize)
        .map(|j| {
            let t = j as f64 * dt;
            (t, r.zeta(t))
        })
        .unzip())
}

/// The blended corner whose overlap (two samples either side) holds `v`.
fn corner_near(segments: &[Segment], blend: &[bool], v: &Violation, dt: f64) -> Option<usize> {
    let (pad, t) = (2.0 * dt, at(v, dt));
    (1..segments.len()).find(|&k| {
        let prev = &segments[k - 1];
        blend[k] && t >= segments[k].t0 - pad && t <= prev.t0 + prev.duration + pad
    })
}

/// The length of a ramp that changes the rate of `zeta` by `change` (per coordinate)
/// within the acceleration limits: the head's by its norm, every angle by its own limit.
pub(super) fn ramp_length(limits: &super::Limits, change: &[f64]) -> f64 {
    let head = change.iter().take(3).map(|d| d * d).sum::<f64>().sqrt();
    let d_omega = change.iter().skip(3).copied();
    let angles = angle_demand(d_omega, limits.yaw_accel, limits.angular_accel);
    RAMP_PEAK * (head / limits.accel).max(angles)
}

/// The length of a ramp that takes the chain from cruising along segment `from` at
/// its rate to cruising along `to` at its (`None`: at rest) within `limits`.
pub(super) fn ramp_between(
    limits: &super::Limits,
    from: Option<(&Segment, f64)>,
    to: Option<(&Segment, f64)>,
) -> f64 {
    let v = |e: Option<(&Segment, f64)>, j: usize| e.map_or(0.0, |(s, r)| r * s.delta[j]);
    let dim = from.or(to).map_or(0, |(s, _)| s.delta.len());
    let change: Vec<f64> = (0..dim).map(|j| v(to, j) - v(from, j)).collect();
    ramp_length(limits, &change)
}

/// What timing the edges needs.
struct Timing<'a> {
    settings: &'a Settings,
    edges: &'a [Segment],
    max_rates: Vec<f64>,
}

impl Timing<'_> {
    /// The length of a ramp that takes the chain from cruising along `from` to
    /// cruising along `to` (`None`: at rest) within the acceleration limits.
    fn ramp(&self, from: Option<(&Segment, f64)>, to: Option<(&Segment, f64)>) -> f64 {
        ramp_between(&self.settings.limits, from, to)
    }

    /// Ramps up and down of every edge at cruise rates `rates`.
    fn ramps(&self, rates: &[f64], blend: &[bool]) -> (Vec<f64>, Vec<f64>) {
        let m = self.edges.len();
        let at = |k: usize| Some((&self.edges[k], rates[k]));
        let up: Vec<f64> = (0..m)
            .map(|k| match blend[k] {
                true => self.ramp(at(k - 1), at(k)),
                false => self.ramp(None, at(k)),
            })
            .collect();
        let down = (0..m)
            .map(|k| match k + 1 < m && blend[k + 1] {
                true => up[k + 1],
                false => self.ramp(at(k), None),
            })
            .collect();
        (up, down)
    }

    /// The timed segments: cruise rates lowered until every edge's ramps fit (an edge
    /// that never fits is unblended on both sides, which always fits), then laid out;
    /// and the rounds of fitting that took.
    fn segments(&self, blend: &mut [bool]) -> (Vec<Segment>, u64) {
        let m = self.edges.len();
        let mut rates = self.max_rates.clone();
        let mut rounds = 0;
        let (up, down) = loop {
            let mut fitted = false;
            for _ in 0..self.settings.fit_rounds {
                rounds += 1;
                let (up, down) = self.ramps(&rates, blend);
                let mut all = true;
                for k in 0..m {
                    let excess = rates[k] * (up[k] + down[k]) / 2.0;
                    if excess > 1.0 {
                        rates[k] /= excess.sqrt() * FIT_UNDERSHOOT;
                        all = false;
                    }
                }
                if all {
                    fitted = true;
                    break;
                }
            }
            let (up, down) = self.ramps(&rates, blend);
            if fitted {
                break (up, down);
            }
            for k in 0..m {
                if rates[k] * (up[k] + down[k]) / 2.0 > 1.0 {
                    blend[k] = false;
                    if k + 1 < m {
                        blend[k + 1] = false;
                    }
                }
            }
        };
        let dt = self.settings.dt;
        let mut end = 0.0f64;
        let mut out: Vec<Segment> = Vec::with_capacity(m);
        for k in 0..m {
            let scaling = Scaling::with_ramps(rates[k], up[k], down[k]);
            let t0 = match blend[k] {
                true => end - up[k],
                false => ((end / dt) - super::TICK_GUARD).ceil().max(0.0) * dt,
            };
            end = t0 + scaling.duration;
            out.push(Segment {
                t0,
                duration: scaling.duration,
                scaling,
                ..self.edges[k].clone()
            });
        }
        (out, rounds)
    }
}
