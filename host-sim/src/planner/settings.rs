//! The ARC planner's parameters: shape sources, shape preference and the numbers
//! of its roadmap, head lattice and online construction (the search's tuning;
//! post-processing's is [`super::RefineSettings`]). docs/settings.md lists every field
//! with its default and what it trades.

use serde::{Deserialize, Serialize};

/// The defaults of the numbers below, one per field (each documented on its field).
mod defaults {
    pub const R_T: f64 = 1.5;
    pub const FOLLOW_STEP: f64 = 0.1;
    pub const CLEARANCE_WEIGHT: f64 = 2.0;
    pub const GIVE_WAY_SHARE: f64 = 0.9;
    pub const BACKTRACK_AFTER: usize = 4;
    pub const NARROW_SURCHARGE: f64 = 4.0;
    pub const CLEARANCE_REF: f64 = 0.5;
    pub const HEURISTIC_WEIGHT: f64 = 2.5;
    pub const MAX_JUMP: f64 = 16.0;
    pub const QUICK_BUDGET: usize = 10_000;
    pub const BUDGET: usize = 60_000_000;
    pub const KEEP_CAP: f64 = 0.3;
    pub const CENTRE_REACH: f64 = 4.0;
    pub const ACROSS: f64 = 0.35;
    pub const MIN_BLOCK: f64 = 0.4;
}

/// Which shape sources the planner may use (the paper's ablation).
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum Mode {
    /// Library and random shapes (the full ARCplanner).
    Both,
    /// Library shapes only.
    Lsc,
    /// Random shapes only (plus yaw rotations of the current shape).
    Srs,
}

/// What the planner prefers when several shapes fit.
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    clap::ValueEnum,
    serde::Serialize,
    serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum Preference {
    /// Keep the shape as long as it fits; cheapest change otherwise.
    #[default]
    Least,
    /// Fly the sensor-coverage polygon PN wherever it fits (the silo demo).
    Coverage,
}

/// Planner parameters (the search's); those above `give_way_share` have a command-line
/// flag. In a file (serde), a field left out takes its default.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Settings {
    /// Head roadmap vertices `M_VT`.
    /// More: the uniform roadmap finds ways through more of the map, for setup time and
    /// memory (the lattice route comes first and needs none).
    pub vertices: usize,
    /// Head roadmap connection radius `r_T` (m); on the quick route's own roadmap,
    /// how near start and goal must lie to be joined straight beside the route.
    /// Larger: longer head edges and more neighbours, for more checks per edge.
    pub r_t: f64,
    /// Most neighbours a vertex takes (the nearest within `r_T`).
    /// More: shorter head paths, for memory and edges to check.
    pub max_neighbours: usize,
    /// Discrete headings per library shape and rotations of the current shape.
    /// More: more shapes fit a narrow edge, for candidates to check.
    pub n_psi: usize,
    /// `G_Val` connection radius `d_c` (`C_T` metric); `None`: the roadmap radius
    /// `aerial_chain_core::srs::default_r_s` for the chain and the SRS size.
    /// Larger: more random shapes connect in `G_Val`, for a slower SRSConnect.
    pub d_c: Option<f32>,
    /// Shape sources.
    /// `lsc` or `srs` alone is the paper's ablation: fewer shapes, fewer plans.
    pub mode: Mode,
    /// Shape preference.
    /// `coverage` trades shape changes for sensor coverage.
    pub prefer: Preference,
    /// Seed of the uniform roadmap's sampler (unused by a query that flies the
    /// lattice's head route alone).
    /// Another seed: another roadmap, another plan where the roadmap is used.
    pub seed: u64,
    /// Replans (dropped head edges) allowed without progress (the chain reaching a
    /// vertex farther along its way than before) before the roadmap grows.
    /// More: more tries on the same roadmap before it grows, for time.
    pub max_replans: usize,
    /// Times a failing query may double the roadmap and try again.
    /// More: harder queries solved, for up to `2^max_growth` times the roadmap.
    pub max_growth: usize,
    /// How strongly head paths avoid passing close to obstacles (0: shortest paths,
    /// as in the paper); see `super::roadmap::Roadmap::build`.
    /// Higher: head paths farther from walls, longer.
    pub clearance_weight: f64,
    /// Step (m) of follow-the-leader motion (`super::follow`), tried after the library
    /// and before SRSConnect; 0 turns it off (the paper's planner).
    /// Smaller: long chains pass tighter bends, for more steps and checks.
    pub follow_step: f64,
    /// Smallest clearance margin (m) the planner may give way to where a passage is
    /// narrower than the context's (preferred) clearance; 0 is docs/model.md's exact
    /// contract. Values above the preferred clearance are taken as it.
    /// Higher: never closer to walls, fewer passages passed.
    pub clearance_min: f64,
    /// Search a head route over the half-cell lattice of the map (`super::lattice`) and add
    /// it to the roadmap before each query; off: the paper's uniform roadmap only.
    /// Off: the paper's planner, slower and weaker in narrow passages.
    pub head_lattice: bool,
    /// Where a query edge cannot pass at the preferred clearance, the search first
    /// gives way to this share of the head's own margin along the edge (rounded down to
    /// a millimetre), then to `clearance_min`. Higher: more clearance kept, more edges
    /// that need the second step.
    pub give_way_share: f64,
    /// Failed connections at one vertex before the online construction backs up a
    /// vertex along its path. Lower: gives up on a vertex sooner (fewer checks there,
    /// more replans).
    pub backtrack_after: usize,
    /// The head lattice's search (`planner::lattice`).
    pub lattice: LatticeSettings,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            vertices: 1500,
            r_t: defaults::R_T,
            max_neighbours: 30,
            n_psi: 8,
            d_c: None,
            mode: Mode::Both,
            prefer: Preference::Least,
            seed: 1,
            max_replans: 200,
            max_growth: 3,
            clearance_weight: defaults::CLEARANCE_WEIGHT,
            follow_step: defaults::FOLLOW_STEP,
            clearance_min: 0.0,
            head_lattice: true,
            give_way_share: defaults::GIVE_WAY_SHARE,
            backtrack_after: defaults::BACKTRACK_AFTER,
            lattice: LatticeSettings::default(),
        }
    }
}

/// The head lattice's tuning: the cost of its steps, its weighted A*, its budgets and
/// how its route is pulled taut (`planner::lattice`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LatticeSettings {
    /// Surcharge (per metre) for stepping where the clearance is below the preferred
    /// one. Higher: routes keep out of narrow stretches longer, for length.
    pub narrow_surcharge: f64,
    /// Clearance above the preferred radius (m) at which the step penalty of
    /// `clearance_weight` vanishes. Larger: routes keep farther from walls.
    pub clearance_ref: f64,
    /// Inflation of the A* heuristic (weighted A*): routes within this factor of the
    /// cheapest, found with far fewer expansions. Lower: cheaper routes, more time.
    pub heuristic_weight: f64,
    /// Longest step (lattice spacings) in open space. Longer: fewer expansions in open
    /// space, routes that hug fewer cells.
    pub max_jump: f64,
    /// Lattice points the first, straight-line-guided search may touch before the
    /// coarse guide is built. Higher: more queries answered without the guide.
    pub quick_budget: usize,
    /// Lattice points one search may touch.
    /// More: routes found in larger maps, for time and memory (a few tens of bytes a
    /// point).
    pub budget: usize,
    /// A string-pulled segment keeps the clearance of the points it replaces up to this
    /// much above the preferred radius (m). Higher: routes pulled less taut, kept wider.
    pub keep_cap: f64,
    /// Clearance (lattice spacings above the preferred radius) up to which a route
    /// point is centred, and the cap of what centring measures.
    /// Larger: route points centred in wider passages, for exact measurements.
    pub centre_reach: f64,
    /// A route point is centred along lattice directions whose cosine with the route
    /// is at most this (about 70 degrees and more from it).
    pub across: f64,
    /// Smallest block (m) of the free-region labelling; maps of more than 100 000 such
    /// blocks are labelled in larger ones. Smaller: finer regions, more memory.
    pub min_block: f64,
}

impl Default for LatticeSettings {
    fn default() -> Self {
        Self {
            narrow_surcharge: defaults::NARROW_SURCHARGE,
            clearance_ref: defaults::CLEARANCE_REF,
            heuristic_weight: defaults::HEURISTIC_WEIGHT,
            max_jump: defaults::MAX_JUMP,
            quick_budget: defaults::QUICK_BUDGET,
            budget: defaults::BUDGET,
            keep_cap: defaults::KEEP_CAP,
            centre_reach: defaults::CENTRE_REACH,
            across: defaults::ACROSS,
            min_block: defaults::MIN_BLOCK,
        }
    }
}

/// Largest length (m) or factor a tuning setting may give: beyond any map. The bounds
/// here are the settings' contract (what a file may ask), not tuning.
pub(crate) const MAX_REACH: f64 = 1e4;

/// Largest budget (checks, measurements, lattice points) a setting may give: far beyond
/// the defaults, small enough that no counter overflows.
pub(crate) const MAX_BUDGET: f64 = 1e9;

/// Largest count of rounds, candidates or grid steps a setting may give: each runs
/// without a budget of its own, so this bounds its time.
pub(crate) const MAX_ROUNDS: f64 = 1e3;

/// A setting outside its range: its field (a dotted path such as
/// `refine.widen.budget`), its value and what it must be.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{field} = {value}: must be {want}")]
pub struct SettingError {
    /// The field's path.
    pub field: String,
    /// Its value.
    pub value: String,
    /// What it must be.
    pub want: String,
}

impl SettingError {
    /// The error for `field` holding `value`, which must be `want`.
    pub fn new(field: &str, value: impl std::fmt::Display, want: &str) -> Self {
        Self {
            field: field.to_string(),
            value: value.to_string(),
            want: want.to_string(),
        }
    }
}

/// `value` of `field` is a finite number in `[lo, hi]`.
pub(crate) fn check(field: &str, value: f64, lo: f64, hi: f64) -> Result<(), SettingError> {
    match value.is_finite() && (lo..=hi).contains(&value) {
        true => Ok(()),
        false => Err(SettingError::new(
            field,
            value,
            &format!("a number from {lo} to {hi}"),
        )),
    }
}

/// `value` of `field` is a finite number above 0, at most [`MAX_REACH`].
pub(crate) fn positive(field: &str, value: f64) -> Result<(), SettingError> {
    match value.is_finite() && value > 0.0 && value <= MAX_REACH {
        true => Ok(()),
        false => Err(SettingError::new(
            field,
            value,
            &format!("a positive number, at most {MAX_REACH}"),
        )),
    }
}

impl Settings {
    /// Checks the fields without a command-line flag (those with one are checked where
    /// they are read, naming the flag); the error names the field (`planner.` and its
    /// path) and its value.
    pub fn validate_tuning(&self) -> Result<(), SettingError> {
        check("planner.give_way_share", self.give_way_share, 0.0, 1.0)?;
        check(
            "planner.backtrack_after",
            self.backtrack_after as f64,
            1.0,
            MAX_BUDGET,
        )?;
        let l = &self.lattice;
        check(
            "planner.lattice.narrow_surcharge",
            l.narrow_surcharge,
            0.0,
            MAX_REACH,
        )?;
        positive("planner.lattice.clearance_ref", l.clearance_ref)?;
        check(
            "planner.lattice.heuristic_weight",
            l.heuristic_weight,
            1.0,
            MAX_REACH,
        )?;
        check("planner.lattice.max_jump", l.max_jump, 1.0, MAX_ROUNDS)?;
        check(
            "planner.lattice.quick_budget",
            l.quick_budget as f64,
            0.0,
            MAX_BUDGET,
        )?;
        check("planner.lattice.budget", l.budget as f64, 1.0, MAX_BUDGET)?;
        check("planner.lattice.keep_cap", l.keep_cap, 0.0, MAX_REACH)?;
        check(
            "planner.lattice.centre_reach",
            l.centre_reach,
            0.0,
            MAX_ROUNDS,
        )?;
        check("planner.lattice.across", l.across, 0.0, 1.0)?;
        positive("planner.lattice.min_block", l.min_block)?;
        Ok(())
    }
}
