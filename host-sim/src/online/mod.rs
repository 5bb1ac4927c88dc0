//! Flying into the unknown: planning while the map grows (docs/online.md).
//!
//! - [`belief`]: [`Belief`], the seen map (OctoMap's fusion) and two distance fields
//!   over the world's box that follow it voxel by voxel: unknown space occupied (what
//!   a piece is committed on) and free (what the route is searched on);
//! - [`route`]: the head's route to the goal with unknown space free, and the proof
//!   that the goal is out of reach;
//! - [`planner`]: [`OnlinePlanner`], the library's online planner: it observes point
//!   clouds in the world frame, replans under a deadline, and commits pieces that lie
//!   in space known free, pass the trajectory's exact check with unknown space
//!   occupied, and end at rest, joined into one committed motion;
//! - [`settings`]: [`OnlineSettings`] and [`OnlineError`]; [`record`]: what every
//!   replan records ([`ReplanRecord`]);
//! - [`mod@explore`]: [`explore()`], the simulator as a client: sensors read the true map,
//!   the chain's dynamics fly what is committed (`arc explore`).
//!
//! # The rule for what the chain may do
//! The route to the goal is searched with unknown space free (optimistic, as FASTER
//! does). What is committed is not: a piece goes from where the committed motion
//! ends, at rest, to the farthest route point whose head sphere is known free (or a
//! nearer one), planned by the ARCplanner on the map with unknown space occupied,
//! timed and checked there, and ends at rest; so the chain can always stop, in known
//! space. A piece committed before the chain begins to slow down for that rest is
//! joined onto the committed motion in flight, the corner at the joint blended and
//! checked on the map of the commit (`crate::trajectory::splice()`), so the chain does
//! not stop there. Where the route leaves the head's sensor's view the piece ends with
//! the head yaw (which every unit holds; the other units' sensors look along it, or to
//! its sides where `DepthSensor::splay_deg` turns them) turned along the route.

pub mod belief;
pub mod explore;
mod look;
pub mod planner;
pub mod record;
pub mod route;
pub mod settings;

pub use belief::{Belief, Fused};
pub use explore::{
    explore, quantile, Exploration, ExploreEnd, ExploreError, ExploreRecord, ExploreSettings,
    ExploreSummary, SeenOccupied, SensingStats, RECORD_FORMAT,
};
pub use planner::{OnlinePlanner, Piece};
pub use record::{Outcome, ReplanRecord, Trigger};
pub use route::{Radii, Route};
pub use settings::{
    ExploreSettingsFile, OnlineError, OnlineSection, OnlineSettings, StartFree, DEFAULT_DEADLINE_S,
    DEFAULT_ROUTE_PERIOD_S,
};

#[cfg(test)]
mod tests;
