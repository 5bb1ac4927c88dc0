//! Why the full-state PRM gives no plan, or cannot be asked.

use crate::planner::{Failure, QueryError};

/// Why a query has no answer, or cannot be asked.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PrmError {
    /// Settings out of range.
    #[error("settings: {0}")]
    BadSettings(String),
    /// The start configuration is not valid (or not of this chain).
    #[error("start is invalid: {0}")]
    StartInvalid(String),
    /// The goal cannot hold the head.
    #[error("goal is invalid: {0}")]
    GoalInvalid(String),
    /// The roadmap has no collision-free path (too few vertices for this problem).
    #[error("no path in the roadmap ({vertices} vertices) after {iterations} lazy searches")]
    NoPath {
        /// Roadmap vertices.
        vertices: usize,
        /// A* searches made.
        iterations: usize,
    },
    /// The time limit stopped the query.
    #[error("time limit reached after {iterations} lazy searches")]
    TimeLimit {
        /// A* searches made.
        iterations: usize,
    },
}

impl From<QueryError> for PrmError {
    fn from(e: QueryError) -> Self {
        match e {
            QueryError::Start(why) => PrmError::StartInvalid(why),
            QueryError::Goal(why) => PrmError::GoalInvalid(why),
        }
    }
}

impl Failure for PrmError {
    fn outcome(&self) -> &'static str {
        match self {
            PrmError::TimeLimit { .. } => "time_limit",
            PrmError::NoPath { .. } => "no_path",
            PrmError::StartInvalid(_) => "start_invalid",
            PrmError::GoalInvalid(_) => "goal_invalid",
            PrmError::BadSettings(_) => "error",
        }
    }
}
