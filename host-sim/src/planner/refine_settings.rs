//! Post-processing's tuning ([`RefineSettings`]): what refinement, shortening,
//! carrying, widening and threading try, how much they may spend, and when their
//! results are taken (docs/postprocessing.md describes the stages, docs/settings.md
//! lists every field with its default). None of these changes docs/model.md: every
//! result still passes the search's checks; they trade plan quality against time.
//!
//! The defaults are today's plans (the behaviour snapshot holds them). Where a default
//! was fitted on a few scenarios, its doc says which.

use serde::{Deserialize, Serialize};

use super::settings::{check, positive, SettingError, MAX_BUDGET, MAX_REACH, MAX_ROUNDS};

/// The defaults, one per field (each documented on its field).
mod defaults {
    pub const CHECK_BUDGET: u64 = 20_000;
    pub const KEEP_SLACK: f64 = 0.005;
    pub const KEEP_GAIN: f64 = 0.025;
    pub const KEEP_MOTION: f64 = 1.02;
    pub const PARTIAL_SHARES: [f32; 3] = [0.25, 0.5, 0.75];
    pub const SHORTEN_SAVING: f64 = 1e-4;
    pub const SHORTEN_PASSES: usize = 4;

    pub const WIDEN_BUDGET: usize = 150;
    pub const WIDEN_STEPS: [f64; 3] = [0.4, 0.15, 0.05];
    pub const WIDEN_DIRECTIONS: usize = 3;
    pub const WIDEN_MAX_SPLITS: usize = 2;
    pub const WIDEN_CENTRED: f64 = 0.93;
    pub const WIDEN_SAME_PINCH: f64 = 0.15;
    pub const WIDEN_PLATEAU: f64 = 0.003;
    pub const WIDEN_GAIN: f64 = 1e-4;
    pub const WIDEN_SEPARATE: f64 = 0.8;
    pub const WIDEN_OTHER_CANDIDATES: usize = 3;
    pub const WIDEN_TARGET_SHARE: f64 = 0.9;
    pub const WIDEN_SPLIT_MARGIN: f64 = 0.25;
    pub const WIDEN_PROBE_SHIFTS: [f64; 7] = [0.0, 0.05, -0.05, 0.1, -0.1, 0.2, -0.2];

    pub const THREAD_OPENING: f64 = 0.9;
    pub const THREAD_GAIN: f64 = 0.01;
    pub const THREAD_SHARE: f64 = 0.8;
    pub const THREAD_MOTION: f64 = std::f64::consts::FRAC_PI_4;
    pub const THREAD_IN_PINCH: f64 = 0.5;
    pub const THREAD_OFF_TRACK: f64 = 0.1;
    pub const THREAD_MIN_STEP: f64 = 0.04;
    pub const THREAD_ESCAPE: f64 = 1.0;
    pub const THREAD_ALIGNED: f32 = 0.52;
    pub const THREAD_ALIGN_SHARES: [f32; 3] = [1.0, 0.75, 0.5];
    pub const THREAD_TUNNEL: f64 = 0.4;
    pub const THREAD_TUNNEL_ENDS: f64 = 0.8;
    pub const THREAD_TUNNEL_ALIGNED: f64 = 0.9;
    pub const THREAD_MAX_STEPS: usize = 40_000;
    pub const THREAD_BAND_ROUNDS: usize = 40;
    pub const THREAD_EASE_ROUNDS: usize = 100;
    pub const THREAD_JOIN_REACH: usize = 200;
    pub const THREAD_ALONGSIDE: f64 = 1.0;
    pub const THREAD_MEASURE_SLACK: f64 = 0.01;
    pub const THREAD_AXIS_REACH: f64 = 4.0;
    pub const THREAD_AXIS_ROUNDS: usize = 3;
    pub const THREAD_NARROWEST_REACH: i32 = 20;
    pub const THREAD_GRID_STEP_DEG: f64 = 5.0;
    pub const THREAD_GRID_STEPS: i32 = 16;
    pub const THREAD_MAX_PITCH_DEG: f64 = 85.0;
    pub const THREAD_CONE_DEG: f64 = 80.0;
    pub const THREAD_CENTRE_STEPS: [f64; 5] = [0.4, 0.2, 0.1, 0.05, 0.025];
    pub const THREAD_CENTRE_ROUNDS: usize = 12;

    pub const CARRY_MIN_CHANGES: usize = 3;
    pub const CARRY_HEADINGS: usize = 8;
    pub const CARRY_SEARCH_POINTS: usize = 25_000;
    pub const CARRY_TOTAL_POINTS: usize = 80_000;
    pub const CARRY_TUBE: f64 = 1.0;
    pub const CARRY_SPACINGS: [f64; 2] = [2.0, 1.0];
    pub const CARRY_GREED: f64 = 2.0;
    pub const CARRY_FIT_SPACING: f64 = 0.3;
    pub const CARRY_SAVING: f64 = 1e-3;
    pub const CARRY_DETOUR_M: f64 = 1.0;
    pub const CARRY_DETOUR_SHARE: f64 = 1.25;
}

use defaults as d;

/// Most directions widening may try per step: the lattice's axis and face-diagonal
/// directions (6 + 12). A bound of the setting, not tuning.
const LATTICE_DIRECTIONS: f64 = 18.0;

/// Most headings per library shape (one a degree).
const MAX_HEADINGS: f64 = 360.0;

/// A right angle (degrees): the steepest direction and the coarsest grid step.
const RIGHT_ANGLE_DEG: f64 = 90.0;

/// A half turn (degrees): the widest cone.
const HALF_TURN_DEG: f64 = 180.0;

/// Post-processing's tuning (see the module docs). In a file (serde), a field left out
/// takes its default.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RefineSettings {
    /// Collision checks refinement and shortening may spend on one plan. More: longer
    /// plans refined to their end, for time (a check costs a few microseconds); what
    /// is left when it runs out stays as the search made it.
    pub check_budget: u64,
    /// How much of the widened plan's clearance the later stages may give back (m):
    /// the checks are conservative, so a margin exactly at the plan's clearance could
    /// refuse the plan's own edges. Less: more clearance kept, fewer shortcuts.
    pub keep_slack: f64,
    /// A widened margin less than this (m) above the search's is not kept through the
    /// later stages: it would refuse shortcuts for next to no clearance.
    pub keep_gain: f64,
    /// The plan that keeps a widened passage's margin is taken unless it asks for more
    /// than this factor of the shape motion of the plan that does not. Higher: more
    /// clearance, more shape motion.
    pub keep_motion: f64,
    /// Shares of the way from one shape to the next tried for a smaller change
    /// (refinement, ascending; shortening tries them descending). More shares: smaller
    /// changes found, more checks.
    pub partial_shares: [f32; 3],
    /// Shortening (`planner::shorten`).
    pub shorten: ShortenSettings,
    /// Widening (`planner::widen`).
    pub widen: WidenSettings,
    /// Threading (`planner::thread`), also tried by the search on a lattice route.
    pub thread: ThreadSettings,
    /// Carrying (`planner::carry`).
    pub carry: CarrySettings,
}

impl Default for RefineSettings {
    fn default() -> Self {
        Self {
            check_budget: d::CHECK_BUDGET,
            keep_slack: d::KEEP_SLACK,
            keep_gain: d::KEEP_GAIN,
            keep_motion: d::KEEP_MOTION,
            partial_shares: d::PARTIAL_SHARES,
            shorten: ShortenSettings::default(),
            widen: WidenSettings::default(),
            thread: ThreadSettings::default(),
            carry: CarrySettings::default(),
        }
    }
}

/// Shortening's tuning.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ShortenSettings {
    /// Motion (rad) a replacement must save to be taken: below it a change is
    /// rounding. Higher: fewer, larger replacements.
    pub saving: f64,
    /// Passes over the plan's runs (each after the first acts only where a neighbour
    /// changed, so they converge in a few). More: maybe less motion, more checks.
    pub max_passes: usize,
}

impl Default for ShortenSettings {
    fn default() -> Self {
        Self {
            saving: d::SHORTEN_SAVING,
            max_passes: d::SHORTEN_PASSES,
        }
    }
}

/// Widening's tuning (clearances at or above `planner::WIDEN_CAP` are wide enough).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct WidenSettings {
    /// Edge measurements widening may spend on one plan. More: more passages widened,
    /// for time.
    pub budget: usize,
    /// Step lengths tried, in map resolutions, largest first. Larger: faster moves,
    /// coarser final positions.
    pub steps: [f64; 3],
    /// Directions tried per step: the clearance's gradient, then the nearest axis and
    /// face-diagonal directions that also widen. More: more moves found, more
    /// measurements.
    pub directions: usize,
    /// Translations widening may split into three, per plan. More: narrow stretches
    /// of long translations widened, more waypoints.
    pub max_splits: usize,
    /// An edge whose narrowest unit keeps this share of what its passage's middle
    /// would is wide enough. The passages issue asks for 0.9; above 0.93 the budget
    /// went on millimetres (0.97 kept the same openings on the 200 instances of `arc
    /// bench robust`, in 10 % more time).
    pub centred: f64,
    /// Narrowest samples nearer than this (m) are at the same pinch: where one edge's
    /// moves could not widen it, the edges this near that keep at most `plateau` more
    /// are given up too (on the robust instances of `arc bench flight` they were tried
    /// a dozen times each and almost never widened). Larger: less time, fewer edges
    /// widened.
    pub same_pinch: f64,
    /// See `same_pinch` (m).
    /// Larger: more edges given up with a stuck one.
    pub plateau: f64,
    /// Smallest gain (m) that counts as widening.
    /// Larger: fewer, larger moves; smaller: more moves for millimetres.
    pub gain: f64,
    /// Samples farther apart than this (m) may lie in two passages: the second pass
    /// looks for the other passage of an edge judged by its narrowest sample.
    /// Smaller: more samples taken as a passage of their own, for measurements.
    pub separate: f64,
    /// Samples of another passage looked at per edge, narrowest first, each at least
    /// `separate` from the ones before (a long tunnel holds several).
    /// More: more passages of a long edge widened, for measurements.
    pub other_candidates: usize,
    /// Share of a passage's middle clearance widening aims at, up to the cap: a door
    /// 0.85 m wide leaves a unit 0.275 m in its middle, and 0.9 of that is the cap.
    /// Higher: wider passages count (those up to `2 (cap / target_share + r_u)`), for
    /// traces.
    pub target_share: f64,
    /// Largest share of a translation kept on either side of the stretch a split moves
    /// (the stretch is widened by two resolutions, up to this share).
    /// Larger: longer stretches left unmoved at a split's ends.
    pub split_margin: f64,
    /// Shifts (m) along the edge at which a unit's passage is probed for its middle
    /// (none first): a unit about to enter an opening is narrowest in front of it, and
    /// the cross-section lies a little further along. Fitted on the 0.05 m maps of the
    /// passages family (1, 2 and 4 voxels there). Not scaled with the resolution: the
    /// rule that stands for (1, 2, 4 voxels) changes plans on the 0.1 m built-in
    /// scenarios (`maze` N = 5 in the behaviour snapshot), and half that (0.5, 1, 2
    /// voxels, the same on 0.1 m maps) would change the family's. More or larger
    /// shifts: passages found where a unit meets them obliquely, more sphere traces.
    pub probe_shifts: [f64; 7],
}

impl Default for WidenSettings {
    fn default() -> Self {
        Self {
            budget: d::WIDEN_BUDGET,
            steps: d::WIDEN_STEPS,
            directions: d::WIDEN_DIRECTIONS,
            max_splits: d::WIDEN_MAX_SPLITS,
            centred: d::WIDEN_CENTRED,
            same_pinch: d::WIDEN_SAME_PINCH,
            plateau: d::WIDEN_PLATEAU,
            gain: d::WIDEN_GAIN,
            separate: d::WIDEN_SEPARATE,
            other_candidates: d::WIDEN_OTHER_CANDIDATES,
            target_share: d::WIDEN_TARGET_SHARE,
            split_margin: d::WIDEN_SPLIT_MARGIN,
            probe_shifts: d::WIDEN_PROBE_SHIFTS,
        }
    }
}

/// Threading's tuning. The gates (`opening`, `gain`, `share`, `motion`) were fitted on
/// the passages family, `maze` and `corridor`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ThreadSettings {
    /// The search threads a lattice route whose narrowest pinch middle keeps less than
    /// this share of `planner::WIDEN_CAP` (an oblique window); wider pinches are left
    /// to the search. Higher: more routes threaded by the search.
    pub opening: f64,
    /// A threaded plan is taken when its worst pinch keeps at least this much larger a
    /// share of the pinch middle's clearance than the other plan, at least `share`, for
    /// at most `motion` more shape motion per link. Higher: fewer plans threaded.
    pub gain: f64,
    /// The share of a pinch middle's clearance a threaded plan must keep at every
    /// pinch: where threading cannot pass every pinch nearly as well as its middle
    /// (`maze` and `corridor` reach 0.4-0.7) it is not worth its motion. Higher: fewer
    /// plans threaded, each nearer the middles.
    pub share: f64,
    /// The shape motion (rad per link) a threaded plan may add to the other plan's: an
    /// eighth of a turn, the price of lining the chain up with an opening. Larger:
    /// plans threaded for more shape motion.
    pub motion: f64,
    /// For the step length, a unit is inside a pinch where its distance to the map is
    /// under its radius plus this share of the pinch width (`planner::WIDEN_CAP`).
    /// Larger: steps shortened farther from a pinch, for more steps.
    pub in_pinch: f64,
    /// How far (share of the resolution) a translation may carry a unit in a pinch
    /// off its track: a tenth of a 0.5 m opening's 0.1 m. Smaller: exacter tracks,
    /// more steps.
    pub off_track: f64,
    /// Shortest step (share of the resolution): a unit that cannot stay on its track
    /// within this is left to the checks.
    /// Smaller: tracks kept in sharper turns, for more steps.
    pub min_step: f64,
    /// A ray that runs this far (m) from a pinch's middle has left the pinch.
    /// Longer: only longer free lines count, a narrower cone about the axis.
    pub escape: f64,
    /// A start whose front link points within this (rad, 30 degrees) of the route is
    /// slid along it as it lies; else it is turned first.
    /// Larger: fewer starts turned before they slide, more trailing bodies.
    pub aligned: f32,
    /// Shares of the turn tried to align the start, the first that passes taken.
    /// More shares: a turn found in tighter rooms, for checks.
    pub align_shares: [f32; 3],
    /// A pinch at least this long (m) is a tunnel: its axis runs through the middles of
    /// its ends.
    /// Shorter: more pinches treated as tunnels.
    pub tunnel: f64,
    /// Where a tunnel's end cross-sections are taken: this share of the way out to
    /// either end.
    /// Nearer 1: the axis through cross-sections nearer the ends, steadier in straight
    /// tunnels.
    pub tunnel_ends: f64,
    /// A tunnel's axis is kept when its direction's cosine with the first guess is
    /// above this.
    /// Lower: tunnel axes kept that turn farther from the first guess.
    pub tunnel_aligned: f64,
    /// Steps a threaded plan may have (it gives up beyond).
    /// More: longer routes threaded, for memory and checks.
    pub max_steps: usize,
    /// How far back (and on) along the route, in route samples (half resolutions), a
    /// pinch's axis may be joined to the route.
    /// More: axes joined farther along the route, for head checks.
    pub join_reach: usize,
    /// A unit within this distance (m) of a pinch's axis, between its ends, passes the
    /// pinch (where the threaded plan is measured against the middle).
    /// Larger: more units measured against a pinch's middle.
    pub alongside: f64,
    /// Measured clearances are capped this far (m) above the pinch width, so that a
    /// unit at the cap still counts.
    /// Larger: more units measured exactly, for time.
    pub measure_slack: f64,
    /// How far (m) out along a pinch's axis its ends are looked for.
    /// Longer: longer pinches found whole, for distance queries.
    pub axis_reach: f64,
    /// Rounds of centring, finding the narrowest point and turning the axis.
    /// More: a truer axis in skewed openings, for time.
    pub axis_rounds: usize,
    /// Half resolutions either way along the axis searched for its narrowest point.
    /// More: the narrowest point found farther from the route's, for queries.
    pub narrowest_reach: i32,
    /// Spacing (degrees) of the grid of directions a pinch's axis is averaged over.
    /// Smaller: a finer mean direction, for many more rays.
    pub grid_step_deg: f64,
    /// Grid steps either side of the first guess, in yaw and in pitch.
    /// More: a wider grid (with `grid_step_deg`), for rays.
    pub grid_steps: i32,
    /// Directions steeper than this (degrees) are left out of the grid.
    /// Lower: steep openings averaged over fewer directions.
    pub max_pitch_deg: f64,
    /// Directions more than this (degrees) from the first guess are left out.
    /// Wider: axes turn farther from the route's heading.
    pub cone_deg: f64,
    /// Steps (shares of the resolution) of the gradient ascent that centres a point in
    /// its pinch, largest first.
    /// Smaller last step: a point nearer the middle, for distance queries.
    pub centre_steps: [f64; 5],
    /// Most ascent steps at each step length.
    /// More: farther moves at each step length, for queries.
    pub centre_rounds: usize,
    /// Rounds of the elastic band that a route the chain cannot follow is pulled into
    /// (each moves every sample half way to its neighbours' middle and away from the
    /// map). More: smoother routes that keep farther from corners, for queries.
    pub band_rounds: usize,
    /// Rounds of each kind (out from the map, then lower bending energy) at each of
    /// the three levels of the easing that opens the bends of a route the chain
    /// follows (`planner::ease`; the bending rounds end sooner once they settle).
    /// Fitted on `maze` N = 8, whose flights took 48.9 and 51.1 s at 100 rounds and
    /// 47.9 and 51.5 s at 300 (easing the search's route). More: wider bends on long
    /// routes, for queries.
    pub ease_rounds: usize,
}

impl Default for ThreadSettings {
    fn default() -> Self {
        Self {
            opening: d::THREAD_OPENING,
            gain: d::THREAD_GAIN,
            share: d::THREAD_SHARE,
            motion: d::THREAD_MOTION,
            in_pinch: d::THREAD_IN_PINCH,
            off_track: d::THREAD_OFF_TRACK,
            min_step: d::THREAD_MIN_STEP,
            escape: d::THREAD_ESCAPE,
            aligned: d::THREAD_ALIGNED,
            align_shares: d::THREAD_ALIGN_SHARES,
            tunnel: d::THREAD_TUNNEL,
            tunnel_ends: d::THREAD_TUNNEL_ENDS,
            tunnel_aligned: d::THREAD_TUNNEL_ALIGNED,
            max_steps: d::THREAD_MAX_STEPS,
            join_reach: d::THREAD_JOIN_REACH,
            alongside: d::THREAD_ALONGSIDE,
            measure_slack: d::THREAD_MEASURE_SLACK,
            axis_reach: d::THREAD_AXIS_REACH,
            axis_rounds: d::THREAD_AXIS_ROUNDS,
            narrowest_reach: d::THREAD_NARROWEST_REACH,
            grid_step_deg: d::THREAD_GRID_STEP_DEG,
            grid_steps: d::THREAD_GRID_STEPS,
            max_pitch_deg: d::THREAD_MAX_PITCH_DEG,
            cone_deg: d::THREAD_CONE_DEG,
            centre_steps: d::THREAD_CENTRE_STEPS,
            centre_rounds: d::THREAD_CENTRE_ROUNDS,
            band_rounds: d::THREAD_BAND_ROUNDS,
            ease_rounds: d::THREAD_EASE_ROUNDS,
        }
    }
}

/// Carrying's tuning.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CarrySettings {
    /// Plans with fewer shape changes are left as they are (carrying replaces changes
    /// by at most two, and shortening already makes one or two as small as they go).
    pub min_changes: usize,
    /// Headings tried per library shape. More: more candidates, more time.
    pub headings: usize,
    /// Placements one shape's search may check.
    /// More: longer detours found, for time.
    pub search_points: usize,
    /// Placements all shapes' searches together may check.
    /// More: more candidates searched, for time.
    pub total_points: usize,
    /// The search keeps within this distance (m) of its guide.
    /// Wider: routes farther from the plan's, for placements.
    pub tube: f64,
    /// Lattice spacings tried, in map resolutions: coarse, then fine.
    /// Finer: tighter gaps passed, for placements.
    pub spacings: [f64; 2],
    /// Weight of the guide's estimate in the search: above 1 the search heads along the
    /// guide and checks fewer points, for a path that may be longer.
    pub greed: f64,
    /// The fit is tested at route points at least this far apart (m).
    /// Smaller: fewer candidates pass the fit test only to fail the search, for checks.
    pub fit_spacing: f64,
    /// Motion (rad) carrying must save to be taken.
    /// Larger: only larger savings are carried.
    pub saving: f64,
    /// A carried plan's head path may be at most `detour_m + detour_share` times the
    /// plan's (m): a long detour costs more flight than the changes it saves.
    pub detour_m: f64,
    /// See `detour_m`.
    /// Larger: longer detours accepted.
    pub detour_share: f64,
}

impl Default for CarrySettings {
    fn default() -> Self {
        Self {
            min_changes: d::CARRY_MIN_CHANGES,
            headings: d::CARRY_HEADINGS,
            search_points: d::CARRY_SEARCH_POINTS,
            total_points: d::CARRY_TOTAL_POINTS,
            tube: d::CARRY_TUBE,
            spacings: d::CARRY_SPACINGS,
            greed: d::CARRY_GREED,
            fit_spacing: d::CARRY_FIT_SPACING,
            saving: d::CARRY_SAVING,
            detour_m: d::CARRY_DETOUR_M,
            detour_share: d::CARRY_DETOUR_SHARE,
        }
    }
}

impl RefineSettings {
    /// Checks every field against its range; the error names the field (`refine.` and
    /// its path) and its value.
    pub fn validate(&self) -> Result<(), SettingError> {
        let name = |f: &str| format!("refine.{f}");
        let budget = |f: &str, v: usize| check(&name(f), v as f64, 1.0, MAX_BUDGET);
        let rounds = |f: &str, v: f64| check(&name(f), v, 0.0, MAX_ROUNDS);
        let share = |f: &str, v: f64| check(&name(f), v, 0.0, 1.0);
        let length = |f: &str, v: f64| check(&name(f), v, 0.0, MAX_REACH);
        let factor = |f: &str, v: f64| check(&name(f), v, 1.0, MAX_REACH);
        let positive = |f: &str, v: f64| positive(&name(f), v);
        check(
            &name("check_budget"),
            self.check_budget as f64,
            1.0,
            MAX_BUDGET,
        )?;
        length("keep_slack", self.keep_slack)?;
        length("keep_gain", self.keep_gain)?;
        factor("keep_motion", self.keep_motion)?;
        for v in self.partial_shares {
            share("partial_shares", v as f64)?;
        }
        length("shorten.saving", self.shorten.saving)?;
        rounds("shorten.max_passes", self.shorten.max_passes as f64)?;
        let w = &self.widen;
        budget("widen.budget", w.budget)?;
        for v in w.steps {
            positive("widen.steps", v)?;
        }
        check(
            &name("widen.directions"),
            w.directions as f64,
            1.0,
            LATTICE_DIRECTIONS,
        )?;
        rounds("widen.max_splits", w.max_splits as f64)?;
        share("widen.centred", w.centred)?;
        length("widen.same_pinch", w.same_pinch)?;
        length("widen.plateau", w.plateau)?;
        positive("widen.gain", w.gain)?;
        length("widen.separate", w.separate)?;
        rounds("widen.other_candidates", w.other_candidates as f64)?;
        positive("widen.target_share", w.target_share)?;
        share("widen.target_share", w.target_share)?;
        positive("widen.split_margin", w.split_margin)?;
        check(&name("widen.split_margin"), w.split_margin, 0.0, 0.5)?;
        for v in w.probe_shifts {
            check(&name("widen.probe_shifts"), v, -MAX_REACH, MAX_REACH)?;
        }
        let t = &self.thread;
        length("thread.opening", t.opening)?;
        length("thread.gain", t.gain)?;
        share("thread.share", t.share)?;
        length("thread.motion", t.motion)?;
        length("thread.in_pinch", t.in_pinch)?;
        positive("thread.off_track", t.off_track)?;
        positive("thread.min_step", t.min_step)?;
        positive("thread.escape", t.escape)?;
        check(
            &name("thread.aligned"),
            t.aligned as f64,
            0.0,
            std::f64::consts::PI,
        )?;
        for v in t.align_shares {
            share("thread.align_shares", v as f64)?;
        }
        length("thread.tunnel", t.tunnel)?;
        share("thread.tunnel_ends", t.tunnel_ends)?;
        share("thread.tunnel_aligned", t.tunnel_aligned)?;
        budget("thread.max_steps", t.max_steps)?;
        budget("thread.join_reach", t.join_reach)?;
        length("thread.alongside", t.alongside)?;
        length("thread.measure_slack", t.measure_slack)?;
        positive("thread.axis_reach", t.axis_reach)?;
        rounds("thread.axis_rounds", t.axis_rounds as f64)?;
        rounds("thread.narrowest_reach", t.narrowest_reach as f64)?;
        positive("thread.grid_step_deg", t.grid_step_deg)?;
        check(
            &name("thread.grid_step_deg"),
            t.grid_step_deg,
            0.0,
            RIGHT_ANGLE_DEG,
        )?;
        rounds("thread.grid_steps", t.grid_steps as f64)?;
        check(
            &name("thread.max_pitch_deg"),
            t.max_pitch_deg,
            0.0,
            RIGHT_ANGLE_DEG,
        )?;
        check(&name("thread.cone_deg"), t.cone_deg, 0.0, HALF_TURN_DEG)?;
        for v in t.centre_steps {
            positive("thread.centre_steps", v)?;
        }
        rounds("thread.centre_rounds", t.centre_rounds as f64)?;
        rounds("thread.band_rounds", t.band_rounds as f64)?;
        rounds("thread.ease_rounds", t.ease_rounds as f64)?;
        let c = &self.carry;
        check(
            &name("carry.min_changes"),
            c.min_changes as f64,
            0.0,
            MAX_BUDGET,
        )?;
        check(
            &name("carry.headings"),
            c.headings as f64,
            1.0,
            MAX_HEADINGS,
        )?;
        budget("carry.search_points", c.search_points)?;
        budget("carry.total_points", c.total_points)?;
        length("carry.tube", c.tube)?;
        for v in c.spacings {
            positive("carry.spacings", v)?;
        }
        factor("carry.greed", c.greed)?;
        positive("carry.fit_spacing", c.fit_spacing)?;
        length("carry.saving", c.saving)?;
        length("carry.detour_m", c.detour_m)?;
        factor("carry.detour_share", c.detour_share)?;
        Ok(())
    }
}
