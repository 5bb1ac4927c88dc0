//! What the online planner records of every replan: why it ran ([`Trigger`]), what it
//! did ([`Outcome`]), and how long it took ([`ReplanRecord`]; docs/model.md,
//! "Explorations").

use serde::{Deserialize, Serialize};

/// Why a replan ran.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Trigger {
    /// The first plan, at the start.
    Start,
    /// A new observation cut the route.
    RouteCut,
    /// The route's period elapsed.
    Period,
    /// The committed motion ends soon: the next piece is due.
    CommitShort,
}

/// What a replan did.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "kind", content = "why")]
pub enum Outcome {
    /// A piece was committed.
    Committed,
    /// A turn in place was committed, to look along the route.
    Looked,
    /// The route was searched again; nothing was committed (none was due).
    Rerouted,
    /// Nothing to do: nothing was seen since the route was searched, or a due piece
    /// was tried on exactly what is known now and its retries are spent.
    NothingNew,
    /// The route leaves known space too soon for a piece: the chain waits to see more.
    NoRoom,
    /// The committed motion already ends at the goal.
    Reached,
    /// The goal cannot be reached: the reason.
    Sealed(String),
}

/// The record of one replan.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReplanRecord {
    /// Simulated time when it began (s).
    pub t: f64,
    /// Why it ran.
    pub trigger: Trigger,
    /// What it did.
    pub outcome: Outcome,
    /// Wall time it took (s).
    pub wall_s: f64,
    /// Voxels inside the box whose state changed since the previous replan.
    pub voxels_changed: usize,
    /// Head path of the piece committed (m; 0 when none).
    pub committed_m: f64,
    /// Length of the route to the goal (m; 0 when none).
    pub route_m: f64,
    /// Whether the piece committed was joined onto the committed motion in flight,
    /// without a stop (false when none was, and in records written before joins).
    #[serde(default)]
    pub joined_moving: bool,
}
