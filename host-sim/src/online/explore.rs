//! Flying into the unknown in simulation: the true map is read only by the units'
//! simulated sensors; an [`OnlinePlanner`] plans from what they saw; the chain's
//! dynamics fly what it commits (a [`FlightRun`] that follows the committed motion).
//!
//! # The loop
//! At every physics step the unit centres that moved half a voxel since they were last
//! marked mark the balls of `r_u` plus the clearance about them as seen free. Every
//! `1 / rate_hz` s every unit's sensor scans the truth from the unit's flown pose (tilt
//! included) and the clouds are fused; then the planner replans when one is due: the
//! next piece when the committed motion ends within a deadline plus a sensor period
//! ([`Trigger::CommitShort`]; its lead is [`OnlinePlanner::commit_lead`]), else the
//! route when a scan cut it or its period elapsed. A replan's measured wall time
//! passes in the simulation before its piece is used: from then on the flight follows
//! the planner's committed motion, the piece joined in flight or after the motion's
//! end (the chain rests there meanwhile).

use std::collections::HashMap;
use std::time::Instant;

use aerial_chain_core::ChainParams;
use nalgebra::Point3;
use serde::{Deserialize, Serialize};

use super::belief::Belief;
use super::planner::OnlinePlanner;
use super::record::{Outcome, ReplanRecord, Trigger};
use super::settings::{OnlineError, OnlineSettings, StartFree};
use crate::collision::{verify::verify_plan, CollisionContext, FK_TOLERANCE};
use crate::flying::FlyOptions;
use crate::map::{Cell, DistanceField, Grid};
use crate::plan_file::{MapSection, Plan};
use crate::sensing::{raycast, OccupancyMap, PointCloud, Survey, SurveyError, UnitPose};
use crate::sim::{ChainModel, Flight, FlightEnd, FlightRun, MapClearance, SimError};
use crate::tables::ShapeTables;

/// Everything an exploration needs besides the maps, the chain and the query.
#[derive(Clone, Debug, Default)]
pub struct ExploreSettings {
    /// The units' sensors and their rate.
    pub survey: Survey,
    /// How the online planner plans.
    pub online: OnlineSettings,
    /// How the chain is flown (physics, control, arrival); its timing settings time the
    /// pieces too (they replace `online.trajectory`).
    pub fly: FlyOptions,
    /// Simulated seconds before the run gives up.
    pub time_limit_s: f64,
    /// Keep the map of every commit and check every piece on it by the exact test.
    pub audit: bool,
}

/// How an exploration ended.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum ExploreEnd {
    /// The chain reached the goal and settled there.
    Reached {
        /// When it arrived and stayed (simulated s).
        t: f64,
    },
    /// The goal is out of reach.
    Sealed {
        /// When that was proven (simulated s).
        t: f64,
        /// Why.
        why: String,
    },
    /// The chain can get no further: it rests where no piece is found on what its
    /// sensors see, every retry spent, and they see nothing new
    /// ([`OnlinePlanner::stuck`]); while the world and the chain stand still, no later
    /// replan could change that.
    Stuck {
        /// When that was found (simulated s).
        t: f64,
        /// Where the chain rests and what it tried.
        why: String,
    },
    /// The time budget ran out.
    TimeLimit {
        /// The budget (simulated s).
        t: f64,
        /// What was tried.
        tried: String,
    },
    /// The flight failed: it diverged, or did not settle at the goal.
    FlightFailed {
        /// Simulated time (s).
        t: f64,
        /// What happened.
        why: String,
    },
}

impl ExploreEnd {
    /// Whether the goal was reached.
    pub fn reached(&self) -> bool {
        matches!(self, Self::Reached { .. })
    }

    /// How it ended, in a few words with the time (`arc explore`'s report line).
    pub fn headline(&self) -> String {
        match self {
            Self::Reached { t } => format!("reached the goal at {t:.2} s"),
            Self::Sealed { t, .. } => format!("found the goal out of reach at {t:.2} s"),
            Self::Stuck { t, .. } => format!("got stuck at {t:.2} s"),
            Self::TimeLimit { t, .. } => format!("ran out of time at {t:.0} s"),
            Self::FlightFailed { t, .. } => format!("failed in flight at {t:.2} s"),
        }
    }
}

/// What the sensors did.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SensingStats {
    /// Clouds fused (one per unit per sensor time).
    pub scans: usize,
    /// Rays cast.
    pub rays: usize,
    /// Voxels the seen map knows at the end.
    pub known: usize,
    /// Time to update both distance fields after each cloud that changed a voxel (s).
    pub update_s: Vec<f64>,
}

/// An exploration's result.
#[derive(Debug)]
pub struct Exploration {
    /// The flight, step by step (its report against the true map).
    pub flight: Flight,
    /// How it ended.
    pub end: ExploreEnd,
    /// Every replan.
    pub replans: Vec<ReplanRecord>,
    /// The committed pieces joined into one plan (on the true map's section).
    pub plan: Plan,
    /// Pieces committed.
    pub pieces: usize,
    /// The seen map at the end.
    pub seen: OccupancyMap,
    /// What the sensors did.
    pub sensing: SensingStats,
    /// With `audit`: per piece, the exact test's first violation on the map it was
    /// committed on (unknown space occupied), `None` when valid.
    pub audit: Option<Vec<Option<String>>>,
    /// Simulated time the chain spent turning in place to look (s): the durations of
    /// the committed pieces that only turn the head yaw ([`super::Piece::is_look`]).
    pub looking_s: f64,
    /// Time to build both fields (the commit and the route field) from scratch on the
    /// final seen map (s; the median of five builds), with `audit`: what an update of
    /// both is compared with.
    pub rebuild_s: Option<f64>,
    /// What the start was taken to leave free.
    pub start_free: StartFree,
    /// The joints flown without a stop, in order: one for every piece joined onto the
    /// committed motion in flight.
    pub joints: Vec<crate::trajectory::Joint>,
    /// The seen map's occupied voxels at the end, each with when it was first seen
    /// occupied: the map as it grew.
    pub seen_occupied: SeenOccupied,
}

/// The occupied voxels of a seen map inside the world's box, each with the simulated
/// time it was first seen occupied (0 for a voxel known before the flight), in the
/// order they were seen: what `arc view` draws of the map as it grew (docs/model.md,
/// "Explorations").
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SeenOccupied {
    /// The voxel edge (m): voxel `[i, j, k]` is the cube from `[i, j, k]` times it.
    pub resolution: f64,
    /// Lattice indices, ordered by `t` (ties by index).
    pub voxels: Vec<[i32; 3]>,
    /// When each was first seen occupied (s, to the millisecond).
    pub t: Vec<f64>,
}

impl SeenOccupied {
    /// The occupied voxels of `seen` that `first` times (when each was first seen
    /// occupied: every voxel inside the world's box that ever was).
    pub fn of(seen: &OccupancyMap, first: &HashMap<[i32; 3], f64>) -> Self {
        let mut timed: Vec<(f64, [i32; 3])> = seen
            .voxels()
            .filter(|(_, cell)| *cell == Cell::Occupied)
            .filter_map(|(v, _)| first.get(&v).map(|t| ((t * 1e3).round() / 1e3, v)))
            .collect();
        timed.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        Self {
            resolution: seen.resolution(),
            voxels: timed.iter().map(|(_, v)| *v).collect(),
            t: timed.iter().map(|(t, _)| *t).collect(),
        }
    }
}

/// The record of an exploration kept in its flight file (docs/model.md,
/// "Explorations").
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ExploreRecord {
    /// `"arc-explore/1"`.
    pub format: String,
    /// How it ended.
    pub end: ExploreEnd,
    /// Pieces committed.
    pub pieces: usize,
    /// What the start was taken to leave free (a record written before this field
    /// existed took the bodies).
    #[serde(default = "bodies")]
    pub start_free: StartFree,
    /// Figures over the whole run.
    pub summary: ExploreSummary,
    /// Every replan, in order.
    pub replans: Vec<ReplanRecord>,
    /// The seen map's occupied voxels with when each was first seen occupied (a
    /// record written before 2026-11-29 has none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seen_occupied: Option<SeenOccupied>,
}

/// What a record without `start_free` took as free at the start.
fn bodies() -> StartFree {
    StartFree::Bodies
}

/// An exploration's figures.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ExploreSummary {
    /// Replans.
    pub replans: usize,
    /// Median, 95th percentile and largest replan wall time (s).
    pub latency_median_s: f64,
    /// 95th percentile replan wall time (s).
    pub latency_p95_s: f64,
    /// Largest replan wall time (s).
    pub latency_max_s: f64,
    /// Largest wall time of a replan that found nothing new (s).
    pub nothing_new_max_s: f64,
    /// Clouds fused.
    pub scans: usize,
    /// Voxels known at the end.
    pub known: usize,
    /// Median time to update both distance fields after one cloud (s).
    pub update_median_s: f64,
}

/// The format tag of an exploration's record.
pub const RECORD_FORMAT: &str = "arc-explore/1";

impl Exploration {
    /// The record kept in the flight file.
    pub fn record(&self) -> ExploreRecord {
        let mut lat: Vec<f64> = self.replans.iter().map(|r| r.wall_s).collect();
        lat.sort_by(f64::total_cmp);
        let mut upd = self.sensing.update_s.clone();
        upd.sort_by(f64::total_cmp);
        let nothing_new_max_s = self
            .replans
            .iter()
            .filter(|r| r.outcome == Outcome::NothingNew)
            .map(|r| r.wall_s)
            .fold(0.0, f64::max);
        ExploreRecord {
            format: RECORD_FORMAT.into(),
            end: self.end.clone(),
            pieces: self.pieces,
            start_free: self.start_free,
            summary: ExploreSummary {
                replans: self.replans.len(),
                latency_median_s: quantile(&lat, 0.5),
                latency_p95_s: quantile(&lat, 0.95),
                latency_max_s: lat.last().copied().unwrap_or(0.0),
                nothing_new_max_s,
                scans: self.sensing.scans,
                known: self.sensing.known,
                update_median_s: quantile(&upd, 0.5),
            },
            replans: self.replans.clone(),
            seen_occupied: Some(self.seen_occupied.clone()),
        }
    }
}

/// The `q` quantile of sorted `v` (nearest rank; 0 when empty).
pub fn quantile(v: &[f64], q: f64) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let k = ((q * v.len() as f64).ceil() as usize).clamp(1, v.len());
    v[k - 1]
}

/// Why an exploration cannot run.
#[derive(Debug, thiserror::Error)]
pub enum ExploreError {
    /// Bad sensor settings.
    #[error("sensor: {0}")]
    Survey(#[from] SurveyError),
    /// The planner refused its inputs.
    #[error(transparent)]
    Online(#[from] OnlineError),
    /// The simulation refused its inputs.
    #[error(transparent)]
    Sim(#[from] SimError),
    /// The start is not valid on the true map with the clearance.
    #[error("the start is not valid on the world map with the clearance {clearance} m: {why}")]
    Start {
        /// The clearance (m).
        clearance: f64,
        /// Why.
        why: String,
    },
    /// The space the start is taken to prove free (the chain's hull by default)
    /// holds an obstacle of the world.
    #[error(
        "the start's hull is not free on the world map: the obstacle voxel at {voxel:.3?} lies \
         {distance:.4} m from the chain's core, within the {reach:.4} m taken as free about it \
         (start_free = hull: r_u plus the clearance about every unit and link); start farther \
         from obstacles, or take only the grown bodies as free (--start-free bodies)"
    )]
    StartHull {
        /// The radius taken as free about that body's core (m).
        reach: f64,
        /// The obstacle voxel's centre (m).
        voxel: [f64; 3],
        /// Its distance from the body's core (m).
        distance: f64,
    },
    /// The flight could record more than the memory budget.
    #[error("--time-limit: {0}")]
    Budget(String),
    /// A time limit that is not a positive number of seconds.
    #[error("time limit {0} s must be a positive number of simulated seconds, at most 86400")]
    TimeLimit(f64),
}

/// Flies the chain `params` from rest in configuration `start` (`zeta`) toward
/// `goal` (head within `goal_tol`) through `truth`, knowing only `prior` (if given)
/// and what its sensors see (see the module docs).
#[allow(clippy::too_many_arguments)]
pub fn explore(
    truth: &Grid,
    params: ChainParams,
    tables: ShapeTables,
    start: &[f64],
    goal: Point3<f64>,
    goal_tol: f64,
    prior: Option<&Grid>,
    settings: &ExploreSettings,
) -> Result<Exploration, ExploreError> {
    settings.survey.validate()?;
    if !(settings.time_limit_s > 0.0 && settings.time_limit_s <= 86_400.0) {
        return Err(ExploreError::TimeLimit(settings.time_limit_s));
    }
    check_budget(&params, settings)?;
    // Pieces are timed as the flight times motion: one set of timing settings.
    let mut online = settings.online.clone();
    online.trajectory = settings.fly.timing;
    check_start(truth, &params, start, &online)?;
    let mut planner = OnlinePlanner::new(
        params,
        tables,
        start,
        goal,
        goal_tol,
        truth,
        prior,
        online,
        &settings.survey.sensor,
    )?;
    planner.keep_maps(settings.audit);
    let cfg = settings.fly.sim_config();
    planner.hold_at_start(cfg.limits.start_hold);
    // The flight adopts a changed motion at its next physics step.
    planner.follow_at_ticks(1.0 / cfg.rate);
    let rest = planner.committed().clone();
    let obstacles = MapClearance::new(truth, &params);
    let run = FlightRun::start(ChainModel::new(params), rest, &cfg, Some(&obstacles), 0)?;
    // What a map known before the flight holds was seen before it.
    let occupied_at = planner
        .belief()
        .seen()
        .voxels()
        .filter(|(_, cell)| *cell == Cell::Occupied)
        .map(|(v, _)| (v, 0.0))
        .collect();
    let mut lp = Loop {
        truth,
        settings,
        planner,
        run,
        flown_radius: params.unit_radius as f64 + settings.online.plan.clearance,
        marked: Vec::new(),
        next_scan: 0.0,
        pending: None,
        sensing: SensingStats::default(),
        goal,
        occupied_at,
    };
    let end = lp.fly()?;
    lp.finish(end, start)
}

/// Refuses a run whose flight could record more than `sim::MAX_RECORDED_BYTES`:
/// every physics step up to the time limit and the settling after it.
fn check_budget(params: &ChainParams, settings: &ExploreSettings) -> Result<(), ExploreError> {
    let cfg = settings.fly.sim_config();
    let steps = ((settings.time_limit_s + cfg.settle_time) * cfg.rate).ceil() + 1.0;
    let bytes = steps * crate::sim::flight::sample_bytes(params.n());
    if bytes > crate::sim::flight::MAX_RECORDED_BYTES {
        return Err(ExploreError::Budget(format!(
            "a flight of up to {:.0} simulated s at {} Hz records {steps:.3e} steps of N = {}, \
             {:.2} GiB, over the budget of 1 GiB: lower the time limit",
            settings.time_limit_s + cfg.settle_time,
            cfg.rate,
            params.n(),
            bytes / crate::sim::flight::MAX_RECORDED_BYTES
        )));
    }
    Ok(())
}

/// Refuses a start that is not valid on the truth with the clearance (grown by the
/// FK tolerance), or where the space the planner takes as seen free about it
/// (`settings.start_free`, when it is the hull) holds an obstacle of the truth.
fn check_start(
    truth: &Grid,
    params: &ChainParams,
    start: &[f64],
    settings: &OnlineSettings,
) -> Result<(), ExploreError> {
    let clearance = settings.plan.clearance;
    let field = std::sync::Arc::new(DistanceField::new(truth.clone()));
    let bad = |why: String| ExploreError::Start { clearance, why };
    let ctx = CollisionContext::new(field, *params, clearance + FK_TOLERANCE)
        .map_err(|e| bad(e.to_string()))?;
    let eta: Vec<f32> = start[3..].iter().map(|&v| v as f32).collect();
    let shape = aerial_chain_core::Shape::from_slice(params.units, &eta)
        .map_err(|e| bad(format!("{e:?}")))?;
    ctx.check_config(super::planner::head(start), &shape)
        .map_err(|e| bad(e.to_string()))?;
    // A valid start proves its grown bodies free; the hull is the user's word, checked
    // here on the world so that the simulated belief never holds what is false.
    if settings.start_free != StartFree::Hull {
        return Ok(());
    }
    for (a, b, r) in super::planner::start_free_space(params, start, settings) {
        if let Some(hit) = crate::collision::exact::nearest_obstacle(truth, a, b, r) {
            return Err(ExploreError::StartHull {
                reach: r,
                voxel: hit.voxel.into(),
                distance: hit.distance,
            });
        }
    }
    Ok(())
}

/// The simulation loop's state.
struct Loop<'a> {
    truth: &'a Grid,
    settings: &'a ExploreSettings,
    planner: OnlinePlanner,
    run: FlightRun<'a>,
    flown_radius: f64,
    marked: Vec<Point3<f64>>,
    next_scan: f64,
    /// When the planner's committed motion, changed by a replan, may be flown.
    pending: Option<f64>,
    sensing: SensingStats,
    goal: Point3<f64>,
    /// When each voxel was first seen occupied (simulated s).
    occupied_at: HashMap<[i32; 3], f64>,
}

impl Loop<'_> {
    /// Steps until the flight ends or the run does; returns how the run ended.
    fn fly(&mut self) -> Result<ExploreEnd, ExploreError> {
        let period = 1.0 / self.settings.survey.rate_hz;
        let mut first = true;
        loop {
            let t = self.run.time();
            self.mark_flown()?;
            if t + 1e-9 >= self.next_scan {
                self.scan()?;
                self.next_scan += period;
                let trigger = if first {
                    Some(Trigger::Start)
                } else {
                    self.due(t, period)
                };
                first = false;
                if let Some(trigger) = trigger {
                    if let Some(end) = self.replan(t, trigger) {
                        return Ok(end);
                    }
                }
            }
            self.join_pending(t).map_err(SimError::from)?;
            if t >= self.settings.time_limit_s {
                return Ok(ExploreEnd::TimeLimit {
                    t: self.settings.time_limit_s,
                    tried: self.tried(),
                });
            }
            let finite = self.pending.is_none() && self.planner.reached();
            if let Some(end) = self.run.advance(finite) {
                return Ok(flight_end(end, self.run.time()));
            }
        }
    }

    /// The replan due at `t`, if any: none while a committed piece waits for its
    /// replan's wall time.
    fn due(&self, t: f64, period: f64) -> Option<Trigger> {
        match self.pending {
            Some(_) => None,
            None => self.planner.due(t, period),
        }
    }

    /// Replans; a committed piece waits for the replan's wall time. `Some` ends the run.
    fn replan(&mut self, t: f64, trigger: Trigger) -> Option<ExploreEnd> {
        let before = self.planner.pieces().len();
        let record = self.planner.replan(t, trigger);
        if let Outcome::Sealed(why) = record.outcome {
            return Some(ExploreEnd::Sealed { t, why });
        }
        if let Some(why) = self.planner.stuck(t) {
            return Some(ExploreEnd::Stuck { t, why });
        }
        if self.planner.pieces().len() > before {
            self.pending = Some(self.planner.effective_from());
        }
        None
    }

    /// Flies the planner's committed motion once its replan's time has passed.
    fn join_pending(&mut self, t: f64) -> Result<(), crate::sim::ReferenceError> {
        match self.pending {
            Some(ready) if t >= ready => {
                self.pending = None;
                self.run.follow(self.planner.committed().clone())
            }
            _ => Ok(()),
        }
    }

    /// Marks the balls about the unit centres that moved half a voxel since last.
    fn mark_flown(&mut self) -> Result<(), ExploreError> {
        let half = self.truth.resolution() / 2.0;
        let units = self.run.units();
        let mut moved = Vec::new();
        for (i, u) in units.iter().enumerate() {
            let p = Point3::from(u.p);
            match self.marked.get_mut(i) {
                Some(m) if (p - *m).norm() < half => {}
                Some(m) => {
                    *m = p;
                    moved.push(p);
                }
                None => {
                    self.marked.push(p);
                    moved.push(p);
                }
            }
        }
        if !moved.is_empty() {
            self.planner.observe_flown(&moved, self.flown_radius)?;
        }
        Ok(())
    }

    /// Every unit's sensor scans the truth from the unit's flown pose.
    fn scan(&mut self) -> Result<(), ExploreError> {
        let rig = &self.settings.survey.sensor;
        for (i, u) in self.run.units().iter().enumerate() {
            let sensor = &rig.for_unit(i);
            let q = nalgebra::UnitQuaternion::from_matrix(&u.r);
            let attitude = [q.w, q.i, q.j, q.k];
            let pose = UnitPose::new([u.p.x, u.p.y, u.p.z], attitude)
                .map_err(|e| ExploreError::Survey(e.into()))?;
            let scan = raycast::scan(self.truth, sensor, &pose);
            self.sensing.rays += scan.rays.len();
            let cloud = PointCloud::from_scan(&scan, self.truth.resolution());
            let fused = self.planner.observe(&cloud, scan.max_range)?;
            let t = self.run.time();
            for v in &fused.occupied {
                self.occupied_at.entry(*v).or_insert(t);
            }
            self.sensing.scans += 1;
            if fused.voxels > 0 {
                self.sensing.update_s.push(fused.update_s);
            }
        }
        Ok(())
    }

    /// What was tried, for a run out of time.
    fn tried(&self) -> String {
        let records = self.planner.records();
        let pieces = self.planner.pieces();
        let looks = pieces.iter().filter(|p| p.is_look()).count();
        let end = super::planner::head(self.planner.committed_end());
        let left = self.planner.route().map_or(f64::NAN, |r| r.length());
        format!(
            "{} replans, {} pieces committed ({looks} of them turns to look), the committed \
             motion ends {:.2} m from the goal (route {left:.2} m from there), {} voxels seen",
            records.len(),
            pieces.len(),
            (end - self.goal).norm(),
            self.planner.belief().seen().known()
        )
    }

    /// The result: the flight ended now as `end`.
    fn finish(self, end: ExploreEnd, start: &[f64]) -> Result<Exploration, ExploreError> {
        let flight_end = FlightEnd {
            completed: match &end {
                ExploreEnd::Reached { t } => Some(*t),
                _ => None,
            },
            diverged: matches!(&end, ExploreEnd::FlightFailed { why, .. } if why.contains("diverged")),
        };
        let flight = self.run.finish(flight_end);
        let planner = self.planner;
        let plan = planner.joined_plan(start, MapSection::of(self.truth));
        let audit = self.settings.audit.then(|| {
            let timing = &self.settings.fly.timing;
            planner
                .pieces()
                .iter()
                .map(|p| {
                    let map = p.map.as_ref().expect("kept with audit");
                    let plan = verify_plan(map, &p.plan).violation.map(|v| v.to_string());
                    plan.or_else(|| audit_joint(planner.committed(), p, map, timing))
                })
                .collect()
        });
        let rebuild_s = self.settings.audit.then(|| rebuild_time(planner.belief()));
        let looking_s = planner
            .pieces()
            .iter()
            .filter(|p| p.is_look())
            // From +0: a float sum of nothing is -0, which prints as "-0.00".
            .fold(0.0, |sum, p| sum + p.trajectory.duration());
        let mut sensing = self.sensing;
        sensing.known = planner.belief().seen().known();
        let seen_occupied = SeenOccupied::of(planner.belief().seen(), &self.occupied_at);
        Ok(Exploration {
            flight,
            end,
            replans: planner.records().to_vec(),
            plan,
            pieces: planner.pieces().len(),
            seen: planner.belief().seen().clone(),
            sensing,
            audit,
            looking_s,
            rebuild_s,
            start_free: planner.settings().start_free,
            joints: planner.pieces().iter().filter_map(|p| p.joint).collect(),
            seen_occupied,
        })
    }
}

/// The check's first violation, on `map`, of the committed motion `reference` at the
/// joint where `piece` was joined in flight, if it was: sampled again from the motion
/// as it stands at the end (every piece joined), which is what was flown or would be.
fn audit_joint(
    reference: &crate::sim::Reference,
    piece: &super::Piece,
    map: &Grid,
    timing: &crate::trajectory::Settings,
) -> Option<String> {
    let joint = piece.joint.as_ref()?;
    let params = piece.trajectory.params();
    crate::trajectory::check_joint(reference, params, map, timing, joint)
        .err()
        .map(|v| format!("the joint in flight: {v}"))
}

/// Rebuilds of the audit: the median of this many is compared with the median update,
/// so that one slow or fast build (a page fault, a busy core) does not make the ratio.
const REBUILDS: usize = 5;

/// Median time to build both fields (the commit and the route field) from scratch on
/// `belief`'s grids (s), over [`REBUILDS`] builds.
fn rebuild_time(belief: &Belief) -> f64 {
    let grids = [belief.commit_field().grid(), belief.route_field().grid()];
    let mut times: Vec<f64> = (0..REBUILDS)
        .map(|_| {
            grids
                .map(|g| {
                    let grid = g.clone();
                    let began = Instant::now();
                    let field = DistanceField::new(grid);
                    let s = began.elapsed().as_secs_f64();
                    drop(field);
                    s
                })
                .iter()
                .sum()
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[REBUILDS / 2]
}

/// How a flight that ended by itself ended.
fn flight_end(end: FlightEnd, t: f64) -> ExploreEnd {
    match end.completed {
        Some(at) => ExploreEnd::Reached { t: at },
        None if end.diverged => ExploreEnd::FlightFailed {
            t,
            why: "the flight diverged from its reference".into(),
        },
        None => ExploreEnd::FlightFailed {
            t,
            why: "the chain did not settle at the goal".into(),
        },
    }
}
