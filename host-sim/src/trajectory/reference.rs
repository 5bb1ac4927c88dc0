//! Reference generation from a plan: every edge timed within speed, acceleration and
//! angular-rate limits. Each edge accelerates along a smooth ramp (the speed follows
//! a smoothstep, so acceleration is continuous and zero at both ends of the ramp),
//! cruises at the limit, and ramps down, so that position, velocity and acceleration
//! (and the link angles, rates and angular accelerations) are continuous and the
//! chain is at rest at every waypoint. Short edges never reach the cruise.
//!
//! Edges follow docs/model.md "Motion between two configurations": a translation
//! moves the head along the straight segment with the shape fixed; a shape change
//! moves every angle of `eta` linearly along its shortest signed difference with the
//! head fixed. An edge that changes both is refused.

use nalgebra::{Point3, Vector3};

use crate::collision::exact::positions_f64;
use crate::collision::verify::{zeta_delta, STAY_TOLERANCE};

/// A vector in `f64` (m, m/s, m/s^2).
type V3 = Vector3<f64>;

/// Timing limits outside their range: the rule that does not hold.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct LimitsError(pub &'static str);

/// `Ok` where the rule holds, else the rule `why` as the error.
fn rule(holds: bool, why: &'static str) -> Result<(), LimitsError> {
    match holds {
        true => Ok(()),
        false => Err(LimitsError(why)),
    }
}

/// Peak acceleration of a smoothstep speed ramp, per unit of cruise rate over ramp
/// time: `max d/dx (3x^2 - 2x^3) = 1.5`.
const RAMP_PEAK_ACCEL: f64 = 1.5;

/// Default largest rate of any link angle (rad/s, about 23 degrees/s): what the
/// defaults of `arc sim` and `arc trajectory` fly. Faster: shorter flights, larger
/// link torques.
const DEFAULT_ANGULAR_RATE: f64 = 0.4;

/// Default largest rate of the head yaw (rad/s): 45 degrees/s, PX4's default yaw rate
/// in autonomous flight (`MPC_YAWRAUTO_MAX`). The head yaw is the heading every unit
/// holds, each about its own centre, which the links' spherical joints leave free: it
/// moves no body, so it is limited by the units' yaw authority, not the links'.
/// Faster: shorter turns to look, larger yaw moments.
pub const DEFAULT_YAW_RATE: f64 = DEFAULT_YAW_RATE_DEG.to_radians();

/// [`DEFAULT_YAW_RATE`] in degrees/s, as PX4 and `--yaw-rate-deg` give it.
pub const DEFAULT_YAW_RATE_DEG: f64 = 45.0;

/// Default largest angular acceleration of the head yaw (rad/s^2): 60 degrees/s^2,
/// PX4's default in autonomous flight (`MPC_YAWRAUTO_ACC`); a unit's yaw moment gives
/// about ten times that (`sim::UnitModel`).
pub const DEFAULT_YAW_ACCEL: f64 = DEFAULT_YAW_ACCEL_DEG.to_radians();

/// [`DEFAULT_YAW_ACCEL`] in degrees/s^2, as PX4 and `--yaw-accel-deg` give it.
pub const DEFAULT_YAW_ACCEL_DEG: f64 = 60.0;

/// The time per unit of progress (s) that the angle limits ask of a change `d_eta` of
/// the shape angles (head yaw first): the largest `|d_j| / limit_j`, with `yaw` the
/// head yaw's limit and `link` every link angle's (rates or accelerations alike).
pub(crate) fn angle_demand(d_eta: impl IntoIterator<Item = f64>, yaw: f64, link: f64) -> f64 {
    d_eta.into_iter().enumerate().fold(0.0f64, |m, (j, d)| {
        let limit = if j == 0 { yaw } else { link };
        m.max(d.abs() / limit)
    })
}

/// Largest difference (m or rad) between one reference's end and the next one's start
/// that still joins them: far below what the controllers resolve, above the rounding
/// of a plan written to a file and read back.
const JOIN_TOLERANCE: f64 = 1e-6;

/// Whether configurations `a` and `b` (`zeta`) are one: every number within the join
/// tolerance, angles up to whole turns.
pub(crate) fn same_configuration(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len()
        && a.iter().zip(b).enumerate().all(|(j, (x, y))| {
            let d = match j >= 3 {
                true => crate::collision::verify::wrap(x - y),
                false => x - y,
            };
            d.abs() <= JOIN_TOLERANCE
        })
}

/// Why a plan's waypoints cannot be timed into a reference.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ReferenceError {
    /// The timing limits are invalid.
    #[error(transparent)]
    Limits(#[from] LimitsError),
    /// No waypoints at all.
    #[error("the plan has no waypoints")]
    NoWaypoints,
    /// A waypoint of the wrong length or with a number that is not finite.
    #[error("waypoint {index} is not {dim} finite numbers")]
    Waypoint {
        /// Its index.
        index: usize,
        /// The length a configuration of this chain has.
        dim: usize,
    },
    /// An edge that moves the head and changes the shape at once.
    #[error(
        "edge {from} -> {to} changes both the head position and the shape (docs/model.md allows one kind per edge)",
        to = from + 1
    )]
    MixedEdge {
        /// The index of the edge's first waypoint.
        from: usize,
    },
    /// A motion appended where it does not start, or before the motion it follows
    /// ends.
    #[error("a motion appended at {at} s must start where the motion ending at {end} s ends, at rest, no earlier")]
    Join {
        /// When it was to start (s).
        at: f64,
        /// When the motion it follows ends (s).
        end: f64,
    },
}

/// The limits every edge is timed within.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReferenceLimits {
    /// Largest speed of any unit centre (m/s).
    pub speed: f64,
    /// Largest acceleration of the head on a translation (m/s^2).
    pub accel: f64,
    /// Largest rate of any link angle of `eta`, pitch or yaw (rad/s).
    pub angular_rate: f64,
    /// Largest angular acceleration of any link angle of `eta` (rad/s^2).
    pub angular_accel: f64,
    /// Largest rate of the head yaw (rad/s).
    pub yaw_rate: f64,
    /// Largest angular acceleration of the head yaw (rad/s^2).
    pub yaw_accel: f64,
    /// Time at rest at the start before the first edge (s).
    pub start_hold: f64,
}

impl Default for ReferenceLimits {
    fn default() -> Self {
        Self {
            speed: 0.5,
            accel: 0.5,
            angular_rate: DEFAULT_ANGULAR_RATE,
            angular_accel: 0.5,
            yaw_rate: DEFAULT_YAW_RATE,
            yaw_accel: DEFAULT_YAW_ACCEL,
            start_hold: 1.0,
        }
    }
}

impl ReferenceLimits {
    /// Checks that every limit is finite and positive (the hold may be zero).
    pub fn validate(&self) -> Result<(), LimitsError> {
        let positive = [
            self.speed,
            self.accel,
            self.angular_rate,
            self.angular_accel,
            self.yaw_rate,
            self.yaw_accel,
        ]
        .iter()
        .all(|v| v.is_finite() && *v > 0.0);
        rule(
            positive,
            "speed, acceleration and angular limits must be positive",
        )?;
        let hold = self.start_hold.is_finite() && self.start_hold >= 0.0;
        rule(hold, "start hold must be a non-negative number of seconds")
    }
}

/// The largest rate of progress (1/s) along a segment of `kind` that changes `zeta` by
/// `delta` within the speed and angular-rate `limits` (0 for a hold).
pub(crate) fn max_rate(
    kind: SegmentKind,
    link_length: f64,
    delta: &[f64],
    limits: &ReferenceLimits,
) -> f64 {
    match kind {
        SegmentKind::Hold => 0.0,
        SegmentKind::Translation => limits.speed / V3::new(delta[0], delta[1], delta[2]).norm(),
        SegmentKind::ShapeChange => {
            // Unit i moves at most at l * sum_{k<i} |d(dir_k)/ds| * ds/dt, and a link
            // direction moves at most at sqrt(dtheta^2 + dpsi^2).
            let sweep: f64 = (0..(delta.len() - 4) / 2)
                .map(|k| (delta[4 + 2 * k].powi(2) + delta[5 + 2 * k].powi(2)).sqrt())
                .sum::<f64>()
                * link_length;
            let d_eta = delta[3..].iter().copied();
            let angles = angle_demand(d_eta, limits.yaw_rate, limits.angular_rate);
            (1.0 / angles).min(limits.speed / sweep)
        }
    }
}

/// The kind of a timed segment.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SegmentKind {
    /// At rest (the start hold, or an edge that changes nothing).
    Hold,
    /// Only the head moves.
    Translation,
    /// Only the shape changes.
    ShapeChange,
}

/// One timed edge.
#[derive(Clone, Debug, PartialEq)]
pub struct Segment {
    /// What moves.
    pub kind: SegmentKind,
    /// Start time (s).
    pub t0: f64,
    /// Duration (s).
    pub duration: f64,
    /// Start configuration `zeta` (angles as in the plan).
    pub from: Vec<f64>,
    /// Change of every coordinate of `zeta` over the segment (angles: shortest signed
    /// difference).
    pub delta: Vec<f64>,
    /// Index of the waypoint the segment ends at (an edge that carries a turn of the
    /// head yaw after it, `super::turns`, ends where the turn ends).
    pub to_waypoint: usize,
    /// How the segment's progress from 0 to 1 runs in time.
    pub scaling: Scaling,
}

/// Progress `s` from 0 to 1 along a segment: a smoothstep speed ramp up to the cruise
/// rate, the cruise, and a smoothstep ramp down (as long as the ramp up unless the
/// segment is blended with the next, see `crate::trajectory`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Scaling {
    /// Cruise rate of `s` (1/s).
    pub rate: f64,
    /// Duration of the ramp up (s).
    pub ramp: f64,
    /// Duration of the ramp down (s).
    pub ramp_down: f64,
    /// Duration of the whole segment (s).
    pub duration: f64,
}

impl Scaling {
    /// The fastest scaling whose rate stays within `max_rate` and whose acceleration
    /// stays within `max_accel` (both for `s`, per second).
    pub fn fastest(max_rate: f64, max_accel: f64) -> Self {
        // A ramp to rate r takes t_r = 1.5 r / a and covers r t_r / 2; two of them
        // must fit in the segment (r t_r <= 1), else the rate is what they allow.
        let full = RAMP_PEAK_ACCEL * max_rate * max_rate / max_accel;
        let rate = if full <= 1.0 {
            max_rate
        } else {
            (max_accel / RAMP_PEAK_ACCEL).sqrt()
        };
        let ramp = RAMP_PEAK_ACCEL * rate / max_accel;
        Self::with_ramps(rate, ramp, ramp)
    }

    /// Cruise at `rate` with ramps of the given lengths (s); they must fit:
    /// `rate * (up + down) / 2 <= 1`.
    pub fn with_ramps(rate: f64, up: f64, down: f64) -> Self {
        Self {
            rate,
            ramp: up,
            ramp_down: down,
            duration: 1.0 / rate + (up + down) / 2.0,
        }
    }

    /// `(s, ds/dt, d2s/dt2)` at time `t` into the segment.
    pub fn at(&self, t: f64) -> (f64, f64, f64) {
        if self.duration <= 0.0 || t >= self.duration {
            return (1.0, 0.0, 0.0);
        }
        if t <= 0.0 {
            return (0.0, 0.0, 0.0);
        }
        if t > self.duration - self.ramp_down {
            let (s, ds, dds) = self.ramp_up(self.ramp_down, self.duration - t);
            return (1.0 - s, ds, -dds);
        }
        if t < self.ramp {
            return self.ramp_up(self.ramp, t);
        }
        let s = self.rate * self.ramp / 2.0 + self.rate * (t - self.ramp);
        (s, self.rate, 0.0)
    }

    /// A ramp of length `ramp` from rest: speed `rate * (3x^2 - 2x^3)` with
    /// `x = t / ramp`.
    fn ramp_up(&self, ramp: f64, t: f64) -> (f64, f64, f64) {
        let x = t / ramp;
        let s = self.rate * ramp * (x * x * x - 0.5 * x * x * x * x);
        let ds = self.rate * x * x * (3.0 - 2.0 * x);
        let dds = self.rate / ramp * 6.0 * x * (1.0 - x);
        (s, ds, dds)
    }
}

/// The reference of one link at one time.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LinkRef {
    /// Pitch theta (rad).
    pub pitch: f64,
    /// Yaw psi (rad).
    pub yaw: f64,
    /// Pitch rate (rad/s).
    pub pitch_rate: f64,
    /// Yaw rate (rad/s).
    pub yaw_rate: f64,
    /// Pitch acceleration (rad/s^2).
    pub pitch_acc: f64,
    /// Yaw acceleration (rad/s^2).
    pub yaw_acc: f64,
}

/// The reference at one time.
#[derive(Clone, Debug, PartialEq)]
pub struct RefPoint {
    /// Head position (m).
    pub p: V3,
    /// Head velocity (m/s).
    pub v: V3,
    /// Head acceleration (m/s^2).
    pub a: V3,
    /// Head yaw psi1_r (rad).
    pub head_yaw: f64,
    /// Head yaw rate (rad/s).
    pub head_yaw_rate: f64,
    /// Every link.
    pub links: Vec<LinkRef>,
}

/// The timed reference of a whole plan.
#[derive(Clone, Debug, PartialEq)]
pub struct Reference {
    units: usize,
    segments: Vec<Segment>,
    end: Vec<f64>,
    duration: f64,
}

impl Segment {
    /// Where it ends: `from` plus `delta` (angles continuous).
    pub fn to(&self) -> Vec<f64> {
        self.from
            .iter()
            .zip(&self.delta)
            .map(|(a, d)| a + d)
            .collect()
    }

    /// Whether the chain rests through it.
    pub fn is_hold(&self) -> bool {
        self.kind == SegmentKind::Hold
    }

    /// `(s, ds/dt, d2s/dt2)` at time `t` into the segment; a hold stays at 0.
    fn progress(&self, t: f64) -> (f64, f64, f64) {
        match self.kind {
            SegmentKind::Hold => (0.0, 0.0, 0.0),
            _ => self.scaling.at(t),
        }
    }
}

impl Reference {
    /// Times the plan's waypoints (`zeta` vectors of `2N + 2` numbers) within `limits`
    /// for a chain of `units` units with link length `link_length`.
    pub fn new(
        units: usize,
        link_length: f64,
        waypoints: &[Vec<f64>],
        limits: &ReferenceLimits,
    ) -> Result<Self, ReferenceError> {
        limits.validate()?;
        let dim = 2 * units + 2;
        if waypoints.is_empty() {
            return Err(ReferenceError::NoWaypoints);
        }
        for (i, w) in waypoints.iter().enumerate() {
            if w.len() != dim || w.iter().any(|v| !v.is_finite()) {
                return Err(ReferenceError::Waypoint { index: i, dim });
            }
        }
        let mut segments = Vec::new();
        let mut t = 0.0;
        if limits.start_hold > 0.0 {
            segments.push(Segment {
                kind: SegmentKind::Hold,
                t0: 0.0,
                duration: limits.start_hold,
                from: waypoints[0].clone(),
                delta: vec![0.0; dim],
                to_waypoint: 0,
                scaling: Scaling::default(),
            });
            t = limits.start_hold;
        }
        for (i, pair) in waypoints.windows(2).enumerate() {
            let (a, b) = (&pair[0], &pair[1]);
            let mut delta = zeta_delta(a, b);
            let moves_head = delta[..3].iter().any(|d| d.abs() > STAY_TOLERANCE);
            let moves_shape = delta[3..].iter().any(|d| d.abs() > STAY_TOLERANCE);
            let (kind, scaling) = match (moves_head, moves_shape) {
                (true, true) => return Err(ReferenceError::MixedEdge { from: i }),
                (false, false) => {
                    delta.iter_mut().for_each(|d| *d = 0.0);
                    (SegmentKind::Hold, Scaling::default())
                }
                (true, false) => {
                    delta[3..].iter_mut().for_each(|d| *d = 0.0);
                    let len = V3::new(delta[0], delta[1], delta[2]).norm();
                    let rate = max_rate(SegmentKind::Translation, link_length, &delta, limits);
                    let scaling = Scaling::fastest(rate, limits.accel / len);
                    (SegmentKind::Translation, scaling)
                }
                (false, true) => {
                    delta[..3].iter_mut().for_each(|d| *d = 0.0);
                    let rate = max_rate(SegmentKind::ShapeChange, link_length, &delta, limits);
                    let d_eta = delta[3..].iter().copied();
                    let accel = angle_demand(d_eta, limits.yaw_accel, limits.angular_accel);
                    let scaling = Scaling::fastest(rate, 1.0 / accel);
                    (SegmentKind::ShapeChange, scaling)
                }
            };
            if scaling.duration > 0.0 {
                segments.push(Segment {
                    kind,
                    t0: t,
                    duration: scaling.duration,
                    from: a.clone(),
                    delta,
                    to_waypoint: i + 1,
                    scaling,
                });
                t += scaling.duration;
            }
        }
        let mut end = waypoints[waypoints.len() - 1].clone();
        // The end as reached by following the segments (angles unwrapped consistently).
        if let Some(last) = segments.last() {
            end = last
                .from
                .iter()
                .zip(&last.delta)
                .map(|(a, d)| a + d)
                .collect();
        }
        Ok(Self {
            units,
            segments,
            end,
            duration: t,
        })
    }

    /// Number of units.
    pub fn units(&self) -> usize {
        self.units
    }

    /// Time when the last edge ends (s).
    pub fn duration(&self) -> f64 {
        self.duration
    }

    /// The timed segments.
    pub fn segments(&self) -> &[Segment] {
        &self.segments
    }

    /// The final configuration `zeta`.
    pub fn end(&self) -> &[f64] {
        &self.end
    }

    /// The configuration `zeta` at time `t` (the end after the last edge).
    pub fn zeta(&self, t: f64) -> Vec<f64> {
        self.state(t).0
    }

    /// The segments that shape the motion at time `t`, oldest first: the latest one
    /// started and every earlier one still moving (two where a blend overlaps them).
    /// Empty after the end.
    fn active(&self, t: f64) -> &[Segment] {
        if t >= self.duration {
            return &[];
        }
        let last = self.segments.partition_point(|s| s.t0 <= t);
        if last == 0 {
            return &self.segments[..1.min(self.segments.len())];
        }
        let mut first = last - 1;
        while first > 0 && t < self.segments[first - 1].t0 + self.segments[first - 1].duration {
            first -= 1;
        }
        &self.segments[first..last]
    }

    /// `zeta` and its first and second time derivatives at `t`: the oldest active
    /// segment's start plus the progress of every active one.
    fn state(&self, t: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let active = self.active(t);
        let n = self.end.len();
        let Some(first) = active.first() else {
            return (self.end.clone(), vec![0.0; n], vec![0.0; n]);
        };
        let (mut z, mut dz, mut ddz) = (first.from.clone(), vec![0.0; n], vec![0.0; n]);
        for seg in active {
            let (s, ds, dds) = seg.progress(t - seg.t0);
            for (j, d) in seg.delta.iter().enumerate() {
                z[j] += s * d;
                dz[j] += ds * d;
                ddz[j] += dds * d;
            }
        }
        (z, dz, ddz)
    }

    /// A reference from timed segments that may overlap (a blend), each starting no
    /// earlier than the one before it; every segment's start is re-based on the end of
    /// the one before it, so that angles run on without jumps of a full turn.
    pub(crate) fn from_segments(units: usize, start: &[f64], mut segments: Vec<Segment>) -> Self {
        let mut at = start.to_vec();
        let mut duration = 0.0f64;
        for seg in &mut segments {
            seg.from.clone_from(&at);
            at.iter_mut().zip(&seg.delta).for_each(|(a, d)| *a += d);
            duration = duration.max(seg.t0 + seg.duration);
        }
        Self {
            units,
            segments,
            end: at,
            duration,
        }
    }

    /// A reference that moves linearly in `zeta` between timed samples (a trajectory
    /// file's, docs/model.md "Trajectories"; angles along their shortest signed
    /// difference): the velocity is constant over each interval, the acceleration zero.
    /// Times must increase; they are counted from the first sample.
    pub fn from_samples(
        units: usize,
        times: &[f64],
        zetas: &[Vec<f64>],
    ) -> Result<Self, ReferenceError> {
        let dim = 2 * units + 2;
        let (Some(first), Some(&t0)) = (zetas.first(), times.first()) else {
            return Err(ReferenceError::NoWaypoints);
        };
        for (i, z) in zetas.iter().enumerate() {
            let later = i == 0
                || times
                    .get(i)
                    .zip(times.get(i - 1))
                    .is_some_and(|(a, b)| a > b);
            if z.len() != dim || z.iter().any(|v| !v.is_finite()) || !later {
                return Err(ReferenceError::Waypoint { index: i, dim });
            }
        }
        let segments = zetas
            .windows(2)
            .zip(times.windows(2))
            .enumerate()
            .map(|(i, (z, t))| {
                let delta = zeta_delta(&z[0], &z[1]);
                let h = t[1] - t[0];
                Segment {
                    kind: SegmentKind::Translation,
                    t0: t[0] - t0,
                    duration: h,
                    from: z[0].clone(),
                    delta,
                    to_waypoint: i + 1,
                    scaling: Scaling::with_ramps(1.0 / h, 0.0, 0.0),
                }
            })
            .collect();
        Ok(Self::from_segments(units, first, segments))
    }

    /// The same motion after `hold` seconds at rest at its start.
    pub fn with_start_hold(&self, hold: f64) -> Self {
        if hold <= 0.0 {
            return self.clone();
        }
        let start = self.segments.first().map_or(&self.end, |s| &s.from);
        let mut segments = vec![Segment {
            kind: SegmentKind::Hold,
            t0: 0.0,
            duration: hold,
            from: start.clone(),
            delta: vec![0.0; self.end.len()],
            to_waypoint: 0,
            scaling: Scaling::default(),
        }];
        segments.extend(self.segments.iter().cloned().map(|mut s| {
            s.t0 += hold;
            s
        }));
        Self {
            units: self.units,
            segments,
            end: self.end.clone(),
            duration: self.duration + hold,
        }
    }

    /// This motion, then `next` from time `at` (s): the chain rests at this motion's
    /// end until `at`, and `next` must start there (every number within 1e-6, angles
    /// up to whole turns: they run on without a jump). Refuses another chain, an `at`
    /// before this motion's end, or a `next` that starts elsewhere.
    pub fn then(&self, at: f64, next: &Reference) -> Result<Reference, ReferenceError> {
        let start = next.segments.first().map_or(&next.end, |s| &s.from);
        let joined = next.units == self.units
            && at.is_finite()
            && at >= self.duration
            && same_configuration(start, &self.end);
        if !joined {
            return Err(ReferenceError::Join {
                at,
                end: self.duration,
            });
        }
        let mut segments = self.segments.clone();
        if at > self.duration {
            segments.push(Segment {
                kind: SegmentKind::Hold,
                t0: self.duration,
                duration: at - self.duration,
                from: self.end.clone(),
                delta: vec![0.0; self.end.len()],
                to_waypoint: 0,
                scaling: Scaling::default(),
            });
        }
        segments.extend(next.segments.iter().cloned().map(|mut s| {
            s.t0 += at;
            s
        }));
        let first = self.segments.first().map_or(&self.end, |s| &s.from);
        let mut joined = Self::from_segments(self.units, first, segments);
        joined.duration = joined.duration.max(at);
        Ok(joined)
    }

    /// Whether `other`, a reference of the same chain, is where this one is at time `t`
    /// (every number of `zeta` within the join tolerance, angles up to whole turns):
    /// what a reference that replaces this one in flight must be.
    pub fn agrees_at(&self, other: &Reference, t: f64) -> bool {
        other.units == self.units && same_configuration(&self.zeta(t), &other.zeta(t))
    }

    /// The reference at time `t` (clamped to `[0, duration]`: at rest before and after).
    pub fn sample(&self, t: f64) -> RefPoint {
        let (z, dz, ddz) = self.state(t);
        let links = (0..self.units - 1)
            .map(|k| LinkRef {
                pitch: z[4 + 2 * k],
                yaw: z[5 + 2 * k],
                pitch_rate: dz[4 + 2 * k],
                yaw_rate: dz[5 + 2 * k],
                pitch_acc: ddz[4 + 2 * k],
                yaw_acc: ddz[5 + 2 * k],
            })
            .collect();
        RefPoint {
            p: V3::new(z[0], z[1], z[2]),
            v: V3::new(dz[0], dz[1], dz[2]),
            a: V3::new(ddz[0], ddz[1], ddz[2]),
            head_yaw: z[3],
            head_yaw_rate: dz[3],
            links,
        }
    }

    /// Unit centres of the reference at time `t`.
    pub fn unit_positions(&self, link_length: f64, t: f64) -> Vec<V3> {
        let z = self.zeta(t);
        positions_f64(link_length, Point3::new(z[0], z[1], z[2]), &z[3..])
            .into_iter()
            .map(|p| p.coords)
            .collect()
    }
}

#[cfg(test)]
#[path = "reference_tests.rs"]
mod tests;
