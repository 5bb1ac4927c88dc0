//! Why the ARC planner gives no plan, or cannot be asked.

use nalgebra::Point3;

use super::{Failure, QueryError};

/// A point for messages: `(x, y, z)` to the millimetre.
pub(super) fn point(p: &(impl Copy + Into<Point3<f64>>)) -> String {
    let p: Point3<f64> = (*p).into();
    format!("({:.3}, {:.3}, {:.3})", p.x, p.y, p.z)
}

/// Why a query has no solution, or cannot be asked.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PlanError {
    /// The tables are for another chain than the map context.
    #[error("the shape tables are for N = {tables} units, the chain has N = {chain}")]
    TablesMismatch {
        /// Units in the tables.
        tables: u8,
        /// Units of the chain.
        chain: u8,
    },
    /// The start configuration is not valid.
    #[error("start is invalid: {0}")]
    StartInvalid(String),
    /// The goal cannot hold the head.
    #[error("goal is invalid: {0}")]
    GoalInvalid(String),
    /// The head cannot reach the goal in the roadmap at all.
    #[error("goal is not reachable by the head (no roadmap path from the start to within {tol} m of the goal)")]
    Unreachable {
        /// Goal tolerance (m).
        tol: f64,
    },
    /// The head could be routed, but the chain found no shape for some edge.
    #[error(
        "no shape fits head edge {} -> {} after {replans} replans{}",
        point(from),
        point(to),
        narrow_note(.narrowest)
    )]
    NoShape {
        /// The last edge tried.
        from: Point3<f64>,
        /// Its end.
        to: Point3<f64>,
        /// Replans made.
        replans: usize,
        /// The head route's narrowest point and the head's margin there (m), when the
        /// lattice found a route.
        narrowest: Option<(Point3<f64>, f64)>,
    },
    /// The head's sphere cannot get from the start to the goal at all: the lattice
    /// search flooded one side's free region without meeting the other.
    #[error("start and goal are in separate free regions for the head's sphere (radius {radius:.3} m, the smallest clearance included): the {side}'s region ({size} {unit} at {spacing:.3} m) does not reach the other")]
    Separated {
        /// Sphere radius tested (m).
        radius: f64,
        /// Which side's region was measured whole ("start" or "goal").
        side: &'static str,
        /// Its size, in `unit`s.
        size: u64,
        /// What `size` counts ("lattice points" or "voxels").
        unit: &'static str,
        /// Spacing of what was counted (m).
        spacing: f64,
    },
    /// The head's sphere gets through, but no unit of the chain holding its link does:
    /// on the head route's stretch `from -> to`, no point holds a unit whose link (of
    /// `link` m, pitch within `pitch_deg`) ends at a unit as free, and the voxels that
    /// do hold one leave start and goal apart (`super::linked`).
    #[error("no unit can hold its link ({link:.3} m, pitch within {pitch_deg:.0} degrees, units of radius {radius:.3} m with the smallest clearance) where the head route runs from {} to {}: the {side}'s region for a unit with its link ({size} cells of {spacing:.3} m) does not reach the other", point(from), point(to))]
    LinksCut {
        /// First point of the head route where no unit holds a link.
        from: Point3<f64>,
        /// Last such point.
        to: Point3<f64>,
        /// Link length (m).
        link: f64,
        /// Largest link pitch (degrees).
        pitch_deg: f64,
        /// Unit radius plus the smallest clearance (m).
        radius: f64,
        /// Which side's region was measured whole ("start" or "goal").
        side: &'static str,
        /// Its size (flood cells).
        size: u64,
        /// The cells' edge (m).
        spacing: f64,
    },
    /// The termination condition stopped the query.
    #[error("time limit reached after {replans} replans")]
    TimeLimit {
        /// Replans made.
        replans: usize,
    },
}

impl From<QueryError> for PlanError {
    fn from(e: QueryError) -> Self {
        match e {
            QueryError::Start(why) => PlanError::StartInvalid(why),
            QueryError::Goal(why) => PlanError::GoalInvalid(why),
        }
    }
}

/// The tail of [`PlanError::NoShape`]'s message: where the head route is narrowest.
fn narrow_note(n: &Option<(Point3<f64>, f64)>) -> String {
    match n {
        Some((p, m)) => format!(
            "; the head route is narrowest at ({:.3}, {:.3}, {:.3}), where the head keeps {:.3} m from the map",
            p[0], p[1], p[2], m
        ),
        None => String::new(),
    }
}

impl Failure for PlanError {
    fn outcome(&self) -> &'static str {
        match self {
            PlanError::TimeLimit { .. } => "time_limit",
            PlanError::NoShape { .. } => "no_shape",
            PlanError::Unreachable { .. } => "unreachable",
            PlanError::Separated { .. } => "separated",
            PlanError::LinksCut { .. } => "links_cut",
            PlanError::StartInvalid(_) => "start_invalid",
            PlanError::GoalInvalid(_) => "goal_invalid",
            PlanError::TablesMismatch { .. } => "error",
        }
    }
}
