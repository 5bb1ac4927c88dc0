//! How the online planner plans ([`OnlineSettings`]), and why it cannot
//! ([`OnlineError`]).

use serde::{Deserialize, Serialize};

use crate::planning::{PlanOptions, PlanningError};
use crate::sensing::occupancy::FusionError;

/// Wall time a replan may take by default (s): the built-in scenarios' pieces through
/// their narrow places are found within it on 2 cores (docs/online.md).
pub const DEFAULT_DEADLINE_S: f64 = 0.3;

/// How the online planner plans.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct OnlineSettings {
    /// How every piece is planned (`arc plan`'s options; its time limit is replaced
    /// by `deadline_s`, its trajectory settings by `trajectory`).
    pub plan: PlanOptions,
    /// How every piece is timed and checked.
    pub trajectory: crate::trajectory::Settings,
    /// Wall time a replan may take (s): what a piece's search and post-processing
    /// get. Longer finds pieces through harder places; shorter keeps the chain from
    /// waiting for its next piece. Default 0.3 s.
    pub deadline_s: f64,
    /// Period of the route's replans when nothing cuts it (s): how soon a shortcut
    /// that sensing opened is taken; also how long a chain at rest that finds no piece
    /// waits for something new before it is stuck ([`super::OnlinePlanner::stuck`]).
    /// Default 1 s.
    pub route_period_s: f64,
    /// What the start is taken to prove free (docs/online.md, "The start"). Default
    /// [`StartFree::Hull`].
    pub start_free: StartFree,
}

/// What an exploration takes as free about the chain at its start, before any sensor
/// has seen it. The sensors look along the units' heading, so part of the space a unit
/// passes as it moves along its link (the waist between two unit balls) may be seen by
/// no sensor until the chain turns to look at it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum StartFree {
    /// The chain's hull: every point within `r_u` plus the clearance of its unit
    /// centres and of its links, the space any unit passes as it moves along the
    /// chain. As exploration planners take a bubble about the robot as free at the
    /// start: the chain starts where that much room is free (the simulator checks it
    /// on the world). Lets the chain move along itself at once.
    #[default]
    Hull,
    /// Only the bodies grown by the clearance (unit balls of `r_u` plus it, link
    /// capsules of `r_l` plus it): what a valid start proves. For a start next to an
    /// obstacle; a chain that must move along itself first turns to look at its hull
    /// (a turn of up to half a circle and back).
    Bodies,
}

impl StartFree {
    /// The radius the start marks free about each link's axis, for a chain of unit
    /// radius `r_u` and link radius `r_l` (before the clearance).
    pub fn link_reach(self, r_u: f64, r_l: f64) -> f64 {
        match self {
            StartFree::Hull => r_u,
            StartFree::Bodies => r_l,
        }
    }
}

impl Default for OnlineSettings {
    fn default() -> Self {
        Self {
            plan: PlanOptions::default(),
            trajectory: crate::trajectory::Settings::default(),
            deadline_s: DEFAULT_DEADLINE_S,
            route_period_s: 1.0,
            start_free: StartFree::default(),
        }
    }
}

/// Why the online planner cannot start or go on.
#[derive(Debug, thiserror::Error)]
pub enum OnlineError {
    /// The box or the prior map cannot be used.
    #[error("map: {0}")]
    Map(String),
    /// A fusion argument was refused.
    #[error("sensing: {0}")]
    Fusion(#[from] FusionError),
    /// The units' sensor settings were refused.
    #[error("sensor: {0}")]
    Sensor(#[from] crate::sensing::SensorError),
    /// A planning input was refused (tables, settings).
    #[error("planning: {0}")]
    Planning(PlanningError),
    /// A setting outside its range.
    #[error("{field} = {value}: {rule}")]
    Setting {
        /// The setting.
        field: &'static str,
        /// Its value.
        value: f64,
        /// The rule it breaks.
        rule: &'static str,
    },
}

/// Refuses settings outside their ranges.
pub(super) fn check_settings(s: &OnlineSettings) -> Result<(), OnlineError> {
    let positive = |field, value: f64, limit: f64, rule| {
        if value.is_finite() && value > 0.0 && value <= limit {
            Ok(())
        } else {
            Err(OnlineError::Setting { field, value, rule })
        }
    };
    positive(
        "deadline_s",
        s.deadline_s,
        60.0,
        "a positive number of seconds, at most 60",
    )?;
    positive(
        "route_period_s",
        s.route_period_s,
        3600.0,
        "a positive number of seconds, at most 3600",
    )?;
    s.plan.termination().map_err(OnlineError::Planning)?;
    s.trajectory
        .validate()
        .map_err(|e| OnlineError::Map(format!("trajectory settings: {e}")))?;
    Ok(())
}
