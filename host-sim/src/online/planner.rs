//! [`OnlinePlanner`]: plans as the map grows, committing pieces that end at rest in
//! space known free (see the module docs of `crate::online`).

use std::time::{Duration, Instant};

use aerial_chain_core::{ChainParams, Shape};
use nalgebra::Point3;

use super::belief::{Belief, Fused};
use super::look;
use super::record::{Outcome, ReplanRecord, Trigger};
use super::route::{self, Found, Radii, Route};
use super::settings::{check_settings, OnlineError, OnlineSettings};
use crate::collision::FK_TOLERANCE;
use crate::goal::GoalPose;
use crate::map::Grid;
use crate::plan_file::{MapSection, Plan};
use crate::planner::Query;
use crate::planning::{plan, Request};
use crate::sensing::{DepthSensor, PointCloud};
use crate::tables::ShapeTables;
use crate::trajectory::{splice, splice_lead, Joint, Reference, Trajectory};

/// A committed piece: its plan, timed and checked on the map of its commit.
#[derive(Clone, Debug)]
pub struct Piece {
    /// Its plan (`arc-plan/1`), from where the committed motion ended.
    pub plan: Plan,
    /// Its trajectory, from rest to rest.
    pub trajectory: Trajectory,
    /// The map it was planned and checked on (unknown space occupied), when the
    /// planner keeps them ([`OnlinePlanner::keep_maps`]).
    pub map: Option<Grid>,
    /// When it was joined onto the motion before it in flight, without a stop: the
    /// joint, in simulated time, checked on the map of its commit.
    pub joint: Option<Joint>,
}

/// The plan stat that marks a turn in place toward the route (look before moving).
const TURN_TO_LOOK: &str = "turn_to_look";
/// The plan stat that marks a turn in place toward the chain's unseen hull.
const LOOK_AT_HULL: &str = "look_at_hull";

impl Piece {
    /// Whether the piece is a turn in place to look (toward the route, or at the
    /// chain's unseen hull), not a motion toward the goal.
    pub fn is_look(&self) -> bool {
        [TURN_TO_LOOK, LOOK_AT_HULL]
            .iter()
            .any(|why| self.plan.stats.contains_key(*why))
    }
}

/// Plans a chain's motion toward a goal while the map grows (see the module docs).
pub struct OnlinePlanner {
    params: ChainParams,
    tables: ShapeTables,
    settings: OnlineSettings,
    belief: Belief,
    goal: Point3<f64>,
    goal_tol: f64,
    radii: Radii,
    sensor: DepthSensor,
    end: Vec<f64>,
    pieces: Vec<Piece>,
    route: Option<Route>,
    scratch: route::Scratch,
    seen_at_last: usize,
    route_at: f64,
    reached: bool,
    failures: u32,
    failed_on: Option<usize>,
    keep_maps: bool,
    records: Vec<ReplanRecord>,
    looked_at_hull: bool,
    /// The route direction the chain last turned to look along from where it rests
    /// (`None` once it moves, or after a look at its hull).
    looked_along: Option<f32>,
    searches: usize,
    committed: Reference,
    effective: f64,
    tick: f64,
}

impl OnlinePlanner {
    /// A planner for the chain `params` (with its shape `tables`) starting at rest in
    /// configuration `start` (`zeta`), toward `goal` (head within `goal_tol`), in the
    /// box of `bounds` (its contents are not read), knowing `prior` if given. The start
    /// must be valid with the clearance of `settings` (every body grown by it, on the
    /// true map), and free as far as `settings.start_free` says: that space counts as
    /// seen free ([`super::StartFree`]). The
    /// units' `sensor` (every unit's the same) decides where the chain turns to look:
    /// along its route, and at the unseen part of its own hull before it moves.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        params: ChainParams,
        tables: ShapeTables,
        start: &[f64],
        goal: Point3<f64>,
        goal_tol: f64,
        bounds: &Grid,
        prior: Option<&Grid>,
        settings: OnlineSettings,
        sensor: &DepthSensor,
    ) -> Result<Self, OnlineError> {
        check_settings(&settings)?;
        sensor.validate()?;
        if let Some(p) = prior {
            if p.resolution() != bounds.resolution() {
                return Err(OnlineError::Map(format!(
                    "the known map's resolution {} m is not the world's {} m",
                    p.resolution(),
                    bounds.resolution()
                )));
            }
        }
        let mut belief = Belief::new(bounds, prior).map_err(|e| OnlineError::Map(e.to_string()))?;
        belief.mark_clear(&start_free_space(&params, start, &settings))?;
        let grown = params.unit_radius as f64 + settings.plan.clearance + FK_TOLERANCE;
        let l = params.link_length as f64;
        let limits = settings.trajectory.limits.to_reference();
        let committed = Reference::new(params.n(), l, &[as_written(start)], &limits)
            .map_err(|e| OnlineError::Map(format!("the start: {e}")))?;
        Ok(Self {
            params,
            tables,
            radii: Radii::new(grown, bounds.resolution()),
            settings,
            belief,
            goal,
            goal_tol,
            sensor: sensor.clone(),
            end: as_written(start),
            pieces: Vec::new(),
            route: None,
            scratch: route::Scratch::default(),
            seen_at_last: usize::MAX,
            route_at: f64::NEG_INFINITY,
            reached: false,
            failures: 0,
            failed_on: None,
            keep_maps: false,
            records: Vec::new(),
            looked_at_hull: false,
            looked_along: None,
            searches: 0,
            committed,
            effective: 0.0,
            tick: 0.0,
        })
    }

    /// Holds the chain at rest at its start for the first `seconds` of simulated time
    /// (a simulation that settles the chain in trim first): no piece starts earlier.
    /// Only before the first piece.
    pub fn hold_at_start(&mut self, seconds: f64) {
        if self.pieces.is_empty() {
            self.committed = self.committed.with_start_hold(seconds);
        }
    }

    /// Keeps the map every piece was committed on (for an audit of the pieces; each
    /// costs a copy of the box).
    pub fn keep_maps(&mut self, keep: bool) {
        self.keep_maps = keep;
    }

    /// Fuses one sensor's cloud (world frame, from the sensor's origin).
    pub fn observe(&mut self, cloud: &PointCloud, max_range: f64) -> Result<Fused, OnlineError> {
        Ok(self.belief.fuse(cloud, max_range)?)
    }

    /// Marks the space the flown bodies fill as seen free: the balls of `radius`
    /// (`r_u` plus the clearance) about the unit centres `centres`.
    pub fn observe_flown(
        &mut self,
        centres: &[Point3<f64>],
        radius: f64,
    ) -> Result<Fused, OnlineError> {
        Ok(self.belief.mark_flown(centres, radius)?)
    }

    /// Whether what was seen since the route was searched cuts it.
    pub fn route_cut(&self) -> bool {
        self.route
            .as_ref()
            .is_some_and(|r| !r.holds(self.belief.route_field()))
    }

    /// The replan due at simulated time `now` for a client that observes every
    /// `period` s (its sensor period), if any: the next piece when the committed motion
    /// ends within its lead ([`Self::commit_lead`]), a deadline and a period
    /// ([`Trigger::CommitShort`]), else the route when what was seen cut it
    /// ([`Trigger::RouteCut`]) or its period elapsed ([`Trigger::Period`]). None once
    /// the committed motion ends at the goal.
    pub fn due(&self, now: f64, period: f64) -> Option<Trigger> {
        if self.reached {
            return None;
        }
        let remaining = self.committed.duration() - now;
        if remaining < self.commit_lead() + self.settings.deadline_s + period {
            Some(Trigger::CommitShort)
        } else if self.route_cut() {
            Some(Trigger::RouteCut)
        } else if now - self.route_at >= self.settings.route_period_s {
            Some(Trigger::Period)
        } else {
            None
        }
    }

    /// When the route was last searched (simulated s).
    pub fn route_searched_at(&self) -> f64 {
        self.route_at
    }

    /// Replans at simulated time `now` for `trigger`: searches the route again when
    /// something was seen since, and with [`Trigger::Start`] or
    /// [`Trigger::CommitShort`] commits the next piece.
    pub fn replan(&mut self, now: f64, trigger: Trigger) -> ReplanRecord {
        let began = Instant::now();
        let changed = self.belief.changed();
        let fresh = changed != self.seen_at_last;
        let voxels_changed = if self.seen_at_last == usize::MAX {
            changed
        } else {
            changed - self.seen_at_last
        };
        let commit = matches!(trigger, Trigger::Start | Trigger::CommitShort);
        // A due piece is tried whatever was seen, unless the last try failed on exactly
        // what is known now and its retries are spent; a route is searched again only
        // when something was seen.
        let idle = match commit {
            true => self.failed_on == Some(changed) && !self.retry_due(),
            false => !fresh && self.route.is_some(),
        };
        let pieces = self.pieces.len();
        let (outcome, committed_m) = if self.reached {
            (Outcome::Reached, 0.0)
        } else if idle {
            self.route_at = now;
            (Outcome::NothingNew, 0.0)
        } else {
            self.seen_at_last = changed;
            // A piece follows the route it has while that route holds; the route is
            // searched again when cut, and at its period.
            let holds = self
                .route
                .as_ref()
                .is_some_and(|r| r.holds(self.belief.route_field()));
            let stale = now - self.route_at >= self.settings.route_period_s;
            let searched = match commit && holds && !stale {
                true => Ok(()),
                false => {
                    self.route_at = now;
                    self.search()
                }
            };
            match searched {
                Err(why) => (Outcome::Sealed(why), 0.0),
                Ok(()) if !commit => (Outcome::Rerouted, 0.0),
                Ok(()) => self.commit(began),
            }
        };
        match outcome {
            Outcome::NoRoom => {
                self.failures += 1;
                self.failed_on = Some(changed);
            }
            Outcome::Committed | Outcome::Looked => {
                self.failures = 0;
                self.failed_on = None;
            }
            _ => {}
        }
        let joined = self.pieces.len() > pieces;
        let joined_moving = joined && self.join(now, began);
        // A committed piece is flown from the end of the wall time its join measured.
        let wall_s = match joined {
            true => self.effective - now,
            false => began.elapsed().as_secs_f64(),
        };
        let record = ReplanRecord {
            t: now,
            trigger,
            outcome,
            wall_s,
            voxels_changed,
            committed_m,
            route_m: self.route.as_ref().map_or(0.0, Route::length),
            joined_moving,
        };
        self.records.push(record.clone());
        record
    }

    /// Joins the piece just committed onto the committed motion: in flight when the
    /// join takes effect before the chain begins to slow down for the motion's end and
    /// its new part passes the exact check on the map of the commit
    /// ([`crate::trajectory::splice()`]), else from rest after the motion ends; either
    /// way no earlier than the end of this replan, begun at simulated time `now`: the
    /// wall time up to this decision passes first (what is left, the join itself, is a
    /// copy). Sets when the result may be flown; returns whether it joined in flight.
    fn join(&mut self, now: f64, began: Instant) -> bool {
        let Some(last) = self.pieces.len().checked_sub(1) else {
            return false;
        };
        let next = self.pieces[last].trajectory.reference();
        let grid = self.belief.commit_field().grid();
        let settings = &self.settings.trajectory;
        let spliced = splice(&self.committed, next, &self.params, grid, settings, now);
        let ready = now + began.elapsed().as_secs_f64();
        self.effective = ready;
        let adopted = self.next_tick(ready);
        match spliced {
            Ok(s) if adopted <= s.joint.take_by => {
                self.committed = s.reference;
                self.pieces[last].joint = Some(s.joint);
                true
            }
            _ => {
                let at = ready.max(self.committed.duration());
                // A piece is planned from the committed end, as a plan file writes it,
                // so it starts there: `then` cannot refuse it.
                self.committed = self
                    .committed
                    .then(at, next)
                    .expect("a piece starts where the committed motion ends");
                false
            }
        }
    }

    /// Why the chain can get no further, when it cannot, at simulated time `now`: the
    /// committed motion has ended, the due piece was tried on exactly what is known now
    /// with every retry spent (three, each with twice the deadline before;
    /// after looking along the route and at the hull where it rests), and the replans
    /// since, due again, found nothing new for a route period (`route_period_s`, so
    /// that a voxel the hovering units' sensors see late is not missed). The world
    /// stands still and the chain rests, so its sensors will see nothing new either: no
    /// later replan can change the answer. `None` otherwise.
    pub fn stuck(&self, now: f64) -> Option<String> {
        let last = self.records.last()?;
        let idle = last.trigger == Trigger::CommitShort && last.outcome == Outcome::NothingNew;
        let spent =
            self.failures > 0 && !self.retry_due() && self.failed_on == Some(self.belief.changed());
        if self.reached || now < self.committed.duration() || !(idle && spent) {
            return None;
        }
        // The last failed try, among the records (they are searched only here).
        let failed = self
            .records
            .iter()
            .rev()
            .find(|r| r.outcome == Outcome::NoRoom)?;
        if now - failed.t < self.settings.route_period_s {
            return None;
        }
        let at = head(&self.end);
        let route = self.route.as_ref()?;
        let leaves = route.points[self.known_prefix(route)];
        Some(format!(
            "no piece from where the chain rests (head at [{:.2}, {:.2}, {:.2}]) on what its \
             sensors have seen: {} tries failed (deadlines up to {:.2} s), and the sensors \
             saw nothing new there since; the route to the goal ({:.2} m) leaves known \
             space {:.2} m from the head, at [{:.2}, {:.2}, {:.2}]",
            at.x,
            at.y,
            at.z,
            self.failures,
            self.deadline(),
            route.length(),
            (leaves - at).norm(),
            leaves.x,
            leaves.y,
            leaves.z,
        ))
    }

    /// The committed motion in simulated time, from the start: every piece joined.
    /// The chain flies it from [`Self::effective_from`] on.
    pub fn committed(&self) -> &Reference {
        &self.committed
    }

    /// When the committed motion as it is now may be flown (simulated s): the end of
    /// the replan that last changed it, whose wall time passes first. Up to then it is
    /// the motion committed before.
    pub fn effective_from(&self) -> f64 {
        self.effective
    }

    /// How long before the committed motion ends the next piece is due (s): long
    /// enough to join any piece found within the deadline in flight, before the chain
    /// begins to slow down for the end ([`crate::trajectory::splice_lead`]). Zero after
    /// a turn to look (the next piece waits for what it shows) or when the motion ends
    /// at rest.
    pub fn commit_lead(&self) -> f64 {
        let look = self.pieces.last().is_some_and(Piece::is_look);
        let last = self.committed.segments().last();
        let limits = &self.settings.trajectory.limits;
        match last {
            Some(s) if !look && self.settings.trajectory.blend && !s.is_hold() => {
                splice_lead(s, limits)
            }
            _ => 0.0,
        }
    }

    /// Adopts a changed committed motion at the follower's next tick of `period` s
    /// (a simulator's physics step, a controller's period; 0: at once), on a clock
    /// whose ticks are the multiples of `period` from 0: a piece is joined in flight
    /// only when that tick comes before the chain begins to slow down, so that the
    /// follower never switches to a motion that differs from the one it flies.
    pub fn follow_at_ticks(&mut self, period: f64) {
        self.tick = period.max(0.0);
    }

    /// The follower's first tick at or after `t` (s).
    fn next_tick(&self, t: f64) -> f64 {
        match self.tick > 0.0 {
            true => (t / self.tick - TICK_GUARD).ceil() * self.tick,
            false => t,
        }
    }

    /// Most times a commit that found no piece is tried again, each with twice the
    /// deadline before, while nothing new is seen: a piece that needs more search than
    /// one deadline gives is found while the chain waits (up to 8 deadlines).
    const RETRIES: u32 = 3;

    /// Whether a commit that found no piece is to be tried again with a longer deadline.
    fn retry_due(&self) -> bool {
        (1..=Self::RETRIES).contains(&self.failures)
    }

    /// The wall time this commit may take: the deadline, doubled for every failed try
    /// since the last piece ([`Self::RETRIES`] at most).
    fn deadline(&self) -> f64 {
        self.settings.deadline_s * f64::from(1u32 << self.failures.min(Self::RETRIES))
    }

    /// Searches the route from the committed motion's end; `Err` with the reason when
    /// the goal is out of reach.
    fn search(&mut self) -> Result<(), String> {
        let from = head(&self.end);
        let found = route::search(
            &mut self.scratch,
            self.belief.route_field(),
            from,
            self.goal,
            self.goal_tol,
            self.radii,
        );
        match found {
            Found::Route(r) => {
                self.route = Some(r);
                Ok(())
            }
            Found::Sealed { reached } => {
                self.route = None;
                Err(format!(
                    "no route for the head's sphere reaches within {} m of the goal {:?} even \
                     with unknown space free: the {reached} voxels reachable from the chain at \
                     {:.3} m of clearance hold no way there",
                    self.goal_tol,
                    [self.goal.x, self.goal.y, self.goal.z],
                    self.radii.proof
                ))
            }
        }
    }

    /// Commits the next piece along the route: to the goal when the route is known
    /// free to its end, else to the farthest route point whose head sphere is known
    /// free, or nearer; first a turn to look along the route when it leaves the view.
    fn commit(&mut self, began: Instant) -> (Outcome, f64) {
        let route = self.route.clone().expect("searched");
        let known = self.known_prefix(&route);
        let last = route.points.len() - 1;
        // Look before moving: where the route leaves the sensors' middle view, a piece
        // planned now would be squeezed into what they saw elsewhere. A route known to
        // the goal (a map known before the flight, space seen before) has nothing left
        // to show.
        if known < last && self.turn_to_look(&route) {
            return (Outcome::Looked, 0.0);
        }
        // Any motion along the chain passes through its hull: where part of it is
        // unseen, no piece that moves a unit through that part can be found, so the
        // chain looks at it first, once where it rests, rather than spend the deadline
        // finding nothing.
        if !self.looked_at_hull && self.look_at_hull() {
            return (Outcome::Looked, 0.0);
        }
        let mut candidates: Vec<usize> = [1.0, 2.0 / 3.0, 1.0 / 3.0]
            .iter()
            .map(|f| ((known as f64) * f).round() as usize)
            .filter(|&k| k > 0)
            .collect();
        candidates.dedup();
        let r_v = self.belief.route_field().grid().resolution();
        let count = candidates.len();
        // A piece found ends the search, so its timing may use what is left of the
        // whole deadline, not only its own share of it: cut short, a trajectory gives
        // way everywhere and flies the piece stop and go.
        let until = began.checked_add(Duration::from_secs_f64(self.deadline()));
        for (tried, k) in candidates.into_iter().enumerate() {
            let final_piece = k == last;
            let (goal, tol) = match final_piece {
                true => (self.goal, self.goal_tol),
                false => (route.points[k], r_v),
            };
            if !final_piece && (goal - head(&self.end)).norm() < 2.0 * r_v {
                continue;
            }
            // The time left, shared by the candidates left: a far piece that cannot be
            // found quickly leaves time for a nearer one.
            let left = self.deadline() - began.elapsed().as_secs_f64();
            let deadline = left / (count - tried) as f64;
            if deadline <= 0.0 {
                break;
            }
            let look = (!final_piece).then(|| self.look_yaw(&route, k));
            if let Some(piece) = self.plan_piece(goal, tol, look, deadline, until) {
                let m = piece.trajectory.head_path_m();
                self.push(piece);
                self.looked_at_hull = false;
                self.looked_along = None;
                self.reached = final_piece;
                // The route goes on from where the piece ended (within a voxel of
                // route point `k`).
                if let Some(r) = self.route.as_mut() {
                    r.points.drain(..k.min(r.points.len() - 1));
                }
                return (Outcome::Committed, m);
            }
        }
        // The route and the hull were looked at above: the chain waits to see more.
        (Outcome::NoRoom, 0.0)
    }

    /// Index of the last route point up to which every point is known as far as the
    /// route asks ([`Self::known`]; the first points, within a voxel of the head, are
    /// the head's own).
    fn known_prefix(&self, route: &Route) -> usize {
        let start = head(&self.end);
        let r_v = self.belief.commit_field().grid().resolution();
        let mut last = 0;
        for (k, p) in route.points.iter().enumerate().skip(1) {
            let own = (p - start).norm() <= r_v;
            if self.known(p) {
                last = k;
            } else if !own {
                break;
            }
        }
        last
    }

    /// Whether route point `p` (a voxel centre) is known as far as the route asks: its
    /// head sphere (the route radius) is known free, or no unknown voxel is nearer to
    /// it than the nearest seen obstacle. The second is a narrow place the route passes
    /// (a route point may keep less than the route radius, down to the proof radius),
    /// seen whole: asking it for the route radius would ask for room a seen wall takes,
    /// and no piece could end beyond it.
    fn known(&self, p: &Point3<f64>) -> bool {
        let commit = self.belief.commit_field();
        if commit.clearance(*p) > self.radii.route {
            return true;
        }
        // Both fields hold the bound of the same voxel by the same rule, so equal
        // distances to the same seen obstacle compare equal.
        let i = commit.grid().lattice_index(*p);
        commit.voxel_clearance(i) >= self.belief.route_field().voxel_clearance(i)
    }

    /// The head yaw that looks from route point `k` along the route: toward the point
    /// one sensor reach ahead (a link length at least).
    fn look_yaw(&self, route: &Route, k: usize) -> f32 {
        let ahead = (self.params.link_length as f64).max(1.0);
        route
            .heading(k, ahead)
            .map_or(self.end[3] as f32, |yaw| yaw as f32)
    }

    /// Plans a piece from the committed end to within `tol` of `goal`, on the map with
    /// unknown space occupied; where `look` lies out of the sensors' middle view, the
    /// piece ends by turning the head yaw to it (a head yaw moves no body); searched
    /// within `deadline` (s), then timed (its blends until `until`) and checked on
    /// that map.
    fn plan_piece(
        &mut self,
        goal: Point3<f64>,
        tol: f64,
        look: Option<f32>,
        deadline: f64,
        until: Option<Instant>,
    ) -> Option<Piece> {
        self.searches += 1;
        let shape = Shape::from_slice(self.params.units, &eta(&self.end)).ok()?;
        let mut query = Query::new(head(&self.end), shape, goal);
        query.goal_tol = tol;
        let field = self.belief.commit_field().clone();
        let request = Request {
            map: MapSection::of(field.grid()),
            field,
            params: self.params,
            query,
            pose: GoalPose::default(),
        };
        let mut options = self.settings.plan.clone();
        options.time_limit_s = Some(deadline);
        let mut plan = plan(&request, Some(self.tables.clone()), &options)
            .ok()?
            .plan;
        if let Some(look) = look {
            let end = plan.waypoints.last()?.zeta.clone();
            if self.turn_needed(end[3] as f32, look) {
                plan.waypoints.push(crate::plan_file::Waypoint {
                    zeta: turned(&end, look),
                    goal: None,
                    hold_s: None,
                });
            }
        }
        self.timed(plan, request.grid(), until)
    }

    /// `plan` as a piece: timed (its blending rounds stopped at `deadline`) and checked
    /// exactly on `grid` (the map with unknown space occupied), which the piece keeps
    /// when the planner keeps maps.
    fn timed(&self, plan: Plan, grid: &Grid, deadline: Option<Instant>) -> Option<Piece> {
        let settings = &self.settings.trajectory;
        let trajectory = crate::trajectory::build_until(&plan, grid, settings, deadline).ok()?;
        let map = self.keep_maps.then(|| grid.clone());
        Some(Piece {
            plan,
            trajectory,
            map,
            joint: None,
        })
    }

    /// Whether a head yaw of `yaw` should turn to `look`: when `look` lies more than a
    /// quarter of the horizontal field of view off it, the route ahead would leave the
    /// middle half of the head's sensor's view (the others' look along it unless
    /// splayed to its sides).
    fn turn_needed(&self, yaw: f32, look: f32) -> bool {
        let d = crate::collision::verify::wrap((look - yaw) as f64);
        d.abs() > self.sensor.fov_h_deg.to_radians() / 4.0
    }

    /// Commits a turn in place of the head yaw to look along the route
    /// ([`Self::look_from_rest`]), when the route leaves the sensors' middle view. A
    /// head yaw moves no body, so the turn is always valid. Once turned, the chain looks
    /// again from the same rest only when the route has moved out of the middle of the
    /// view it looked along.
    fn turn_to_look(&mut self, route: &Route) -> bool {
        let (along, to) = self.look_from_rest(route);
        let from = self.looked_along.unwrap_or(self.end[3] as f32);
        if !self.turn_needed(from, along) || !self.commit_turn(to, TURN_TO_LOOK) {
            return false;
        }
        self.looked_along = Some(along);
        true
    }

    /// How a chain resting at the committed end looks along `route`: the route's
    /// direction toward the point one chain length ahead (the stretch its body flies
    /// into first; a link length at least), and the head yaw to turn to, that direction
    /// turned toward the side of the route the chain's body lies on by a quarter of the
    /// horizontal view times the sine of the angle from the route to the body (the
    /// whole quarter for a body across the route, none for one trailing straight
    /// behind). The route stays in the middle half of the view, and the sensors see the
    /// side the tail swings through as the head moves on, which a piece planned now
    /// needs free (sensors look along the head yaw, so the body's side is the one a look
    /// straight along the route leaves unseen).
    fn look_from_rest(&self, route: &Route) -> (f32, f32) {
        let l = self.params.link_length as f64;
        let chain = l * (self.params.n() - 1) as f64;
        let Some(along) = route.heading(0, chain.max(l)) else {
            let yaw = self.end[3] as f32;
            return (yaw, yaw);
        };
        let centres = unit_centres(&self.params, &self.end);
        let body = centres
            .iter()
            .map(|c| c.coords)
            .sum::<nalgebra::Vector3<f64>>()
            / centres.len() as f64
            - head(&self.end).coords;
        // The sine of the angle from the route to the body: +-1 for a body across the
        // route, 0 for one trailing straight behind the head (or lying ahead).
        let (sin, cos) = along.sin_cos();
        let across = (cos * body.y - sin * body.x) / body.xy().norm().max(1e-9);
        let quarter = self.sensor.fov_h_deg.to_radians() / 4.0;
        (along as f32, (along + across * quarter) as f32)
    }

    /// Commits a turn of the head yaw toward where the units' sensors see most of the
    /// unseen part of the chain's hull (the module docs of `look` say why), when some
    /// heading sees any of it (false when all of it is seen or no heading sees any);
    /// marks the hull looked at until the chain moves.
    fn look_at_hull(&mut self) -> bool {
        self.looked_at_hull = true;
        let centres = unit_centres(&self.params, &self.end);
        let reach = self.params.unit_radius as f64 + self.settings.plan.clearance;
        let unseen = look::unseen_hull(&self.belief, &centres, reach);
        let Some(yaw) = look::best_view(&self.sensor, &centres, self.end[3], &unseen) else {
            return false;
        };
        // Turned away from the route: the next look along it is judged from here.
        let turned = self.commit_turn(yaw as f32, LOOK_AT_HULL);
        if turned {
            self.looked_along = None;
        }
        turned
    }

    /// Commits a turn of the head yaw to `yaw` in place (a head yaw moves no body, so
    /// the turn is valid wherever the chain rests), its plan marked `why`.
    fn commit_turn(&mut self, yaw: f32, why: &str) -> bool {
        let to = turned(&self.end, yaw);
        let field = self.belief.commit_field().clone();
        let map = MapSection::of(field.grid());
        let mut plan = Plan::from_zetas(&self.params, map, vec![self.end.clone(), to]);
        plan.stats.insert(why.into(), true.into());
        let Some(piece) = self.timed(plan, field.grid(), None) else {
            return false;
        };
        self.push(piece);
        true
    }

    /// Appends a piece: the committed motion now ends where it ends.
    fn push(&mut self, piece: Piece) {
        if let Some(last) = piece.plan.waypoints.last() {
            self.end.clone_from(&last.zeta);
        }
        self.pieces.push(piece);
    }

    /// The committed pieces, in order.
    pub fn pieces(&self) -> &[Piece] {
        &self.pieces
    }

    /// How many pieces were searched (every candidate end of every commit, found or
    /// not): a commit that only turns to look searches none.
    pub fn pieces_searched(&self) -> usize {
        self.searches
    }

    /// The configuration where the committed motion ends (at rest).
    pub fn committed_end(&self) -> &[f64] {
        &self.end
    }

    /// Whether the committed motion ends at the goal.
    pub fn reached(&self) -> bool {
        self.reached
    }

    /// The current route, if one was found.
    pub fn route(&self) -> Option<&Route> {
        self.route.as_ref()
    }

    /// Every replan so far.
    pub fn records(&self) -> &[ReplanRecord] {
        &self.records
    }

    /// How it plans.
    pub fn settings(&self) -> &OnlineSettings {
        &self.settings
    }

    /// What the planner believes of the world.
    pub fn belief(&self) -> &Belief {
        &self.belief
    }

    /// The committed pieces joined into one plan on the map `map` describes: each
    /// piece's waypoints after its first, which is where the one before it ends.
    pub fn joined_plan(&self, start: &[f64], map: MapSection) -> Plan {
        let mut zetas = vec![as_written(start)];
        for piece in &self.pieces {
            for w in piece.plan.waypoints.iter().skip(1) {
                zetas.push(w.zeta.clone());
            }
        }
        let mut plan = Plan::from_zetas(&self.params, map, zetas);
        plan.stats.insert("pieces".into(), self.pieces.len().into());
        plan
    }
}

/// Floating-point guard of a tick count: a time that is a whole number of ticks up to
/// rounding counts as that tick. Not tuning.
const TICK_GUARD: f64 = 1e-9;

/// Head position of configuration `zeta`.
pub(super) fn head(zeta: &[f64]) -> Point3<f64> {
    Point3::new(zeta[0], zeta[1], zeta[2])
}

/// Configuration `zeta` with its angles as a plan file writes them (the shortest
/// decimal of their `f32`), as every piece's waypoints hold them.
fn as_written(zeta: &[f64]) -> Vec<f64> {
    let mut out = zeta.to_vec();
    for a in &mut out[3..] {
        *a = crate::plan_file::f32_decimal(*a as f32);
    }
    out
}

/// Configuration `zeta` with its head yaw turned to `yaw` the short way round.
fn turned(zeta: &[f64], yaw: f32) -> Vec<f64> {
    let mut to = zeta.to_vec();
    // As a plan file writes angles (the shortest decimal of an `f32`), so that the next
    // piece, planned from this shape, starts exactly here.
    let yaw = zeta[3] + crate::collision::verify::wrap(yaw as f64 - zeta[3]);
    to[3] = crate::plan_file::f32_decimal(yaw as f32);
    to
}

/// The shape of configuration `zeta`, as the chain's `f32` angles.
fn eta(zeta: &[f64]) -> Vec<f32> {
    zeta[3..].iter().map(|&v| v as f32).collect()
}

/// The unit centres of configuration `zeta`, head first.
fn unit_centres(params: &ChainParams, zeta: &[f64]) -> Vec<Point3<f64>> {
    let head = crate::sim::V3::new(zeta[0], zeta[1], zeta[2]);
    crate::sim::dynamics::unit_positions(params.link_length as f64, head, &zeta[3..])
        .into_iter()
        .map(Point3::from)
        .collect()
}

/// The space the start `zeta` is taken to prove free ([`super::StartFree`]): its bodies
/// as far as `settings.start_free` reaches about the links, grown by the clearance and
/// twice the FK tolerance (the start is checked valid within one of it).
pub(super) fn start_free_space(
    params: &ChainParams,
    zeta: &[f64],
    settings: &OnlineSettings,
) -> Vec<(Point3<f64>, Point3<f64>, f64)> {
    let link_reach = settings
        .start_free
        .link_reach(params.unit_radius as f64, params.link_radius as f64);
    let grow = settings.plan.clearance + 2.0 * FK_TOLERANCE;
    bodies(params, zeta, link_reach, grow)
}

/// The chain's bodies in configuration `zeta`, each as a segment and a radius grown
/// by `grow`: a ball of `r_u` per unit, a capsule of `link_reach` per link.
fn bodies(
    params: &ChainParams,
    zeta: &[f64],
    link_reach: f64,
    grow: f64,
) -> Vec<(Point3<f64>, Point3<f64>, f64)> {
    let centres = unit_centres(params, zeta);
    let r_u = params.unit_radius as f64 + grow;
    let r_l = link_reach + grow;
    let mut out: Vec<_> = centres.iter().map(|c| (*c, *c, r_u)).collect();
    out.extend(centres.windows(2).map(|w| (w[0], w[1], r_l)));
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::Cell;
    use crate::online::tests::chain;
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};

    /// A planner for a straight chain of 3 units, its head at (`x`, 1.05, 1.05) and its
    /// body trailing along -x, in a 4 x 2 x 2 m box at 0.1 m, seen free but for one
    /// occupied voxel centred at (2.05, 1.05, 1.05) and one unseen voxel centred at
    /// (3.05, 1.05, 1.05).
    fn planner_at(x: f64) -> OnlinePlanner {
        let (params, tables) = chain(3);
        let bounds = Grid::new(0.1, [0, 0, 0], [40, 20, 20], Cell::Free, true).unwrap();
        let mut prior = bounds.clone();
        prior.set([20, 10, 10], Cell::Occupied);
        prior.set([30, 10, 10], Cell::Unknown);
        let start = crate::plan_file::Waypoint::new([x, 1.05, 1.05], &Shape::line(3, 0.0)).zeta;
        let goal = Point3::new(3.55, 1.05, 1.05);
        OnlinePlanner::new(
            params,
            tables,
            &start,
            goal,
            0.3,
            &bounds,
            Some(&prior),
            OnlineSettings::default(),
            &DepthSensor::default(),
        )
        .unwrap()
    }

    #[test]
    fn a_route_point_beside_a_seen_wall_is_known_and_one_beside_unseen_space_is_not() {
        let p = planner_at(1.05);
        // Both keep 0.15 m to a voxel's face, less than the route radius (0.2 m).
        let by_wall = Point3::new(2.25, 1.05, 1.05);
        let by_unseen = Point3::new(3.25, 1.05, 1.05);
        let field = p.belief.commit_field();
        for q in [by_wall, by_unseen] {
            assert!(field.clearance(q) < p.radii.route, "{q:?}");
        }
        assert!(p.known(&by_wall), "a narrow place seen whole");
        assert!(!p.known(&by_unseen), "unseen space within the route radius");
        assert!(p.known(&Point3::new(1.55, 0.45, 1.05)), "room to spare");
    }

    /// A route from the head's voxel at (1.55, 1.05, 1.05) at `deg` degrees, 0.8 m long.
    fn route_at(deg: f64) -> Route {
        let (s, c) = deg.to_radians().sin_cos();
        let points = (0..=8)
            .map(|i| Point3::new(1.55 + 0.1 * i as f64 * c, 1.05 + 0.1 * i as f64 * s, 1.05))
            .collect();
        Route {
            points,
            radius: 0.2,
        }
    }

    #[test]
    fn a_look_from_rest_turns_toward_the_side_the_body_lies_on() {
        let p = planner_at(1.55);
        let quarter = DepthSensor::default().fov_h_deg.to_radians() / 4.0;
        let close = |a: f32, b: f64| (a as f64 - b).abs() < 1e-6;
        // The straight chain trails behind its head along -x.
        let (along, to) = p.look_from_rest(&route_at(0.0));
        assert!(
            close(along, 0.0) && close(to, 0.0),
            "{along} {to}: straight behind"
        );
        // Across a route to the left (+y) the body lies on its left, behind a route to
        // the right on its right: the look turns a quarter of the view toward it.
        let (along, to) = p.look_from_rest(&route_at(90.0));
        assert!(
            close(along, FRAC_PI_2) && close(to, FRAC_PI_2 + quarter),
            "{along} {to}"
        );
        let (along, to) = p.look_from_rest(&route_at(-90.0));
        assert!(
            close(along, -FRAC_PI_2) && close(to, -FRAC_PI_2 - quarter),
            "{along} {to}"
        );
        // Half across (45 degrees): half the turn, by the sine.
        let (_, to) = p.look_from_rest(&route_at(45.0));
        assert!(close(to, FRAC_PI_4 + quarter * FRAC_PI_4.sin()), "{to}");
    }

    #[test]
    fn a_chain_that_looked_looks_again_only_when_the_route_leaves_the_view_it_looked_along() {
        let mut p = planner_at(1.55);
        assert!(
            !p.turn_to_look(&route_at(10.0)),
            "in the middle of the view"
        );
        assert!(p.turn_to_look(&route_at(90.0)));
        assert_eq!(p.pieces().len(), 1);
        // Turned past the route toward the body, it is still in the middle of the view
        // looked along, also when the route moves a little.
        assert!(!p.turn_to_look(&route_at(90.0)));
        assert!(!p.turn_to_look(&route_at(80.0)));
        assert_eq!(p.pieces().len(), 1);
        assert!(p.turn_to_look(&route_at(150.0)), "out of that view");
        assert_eq!(p.pieces().len(), 2);
    }
}
