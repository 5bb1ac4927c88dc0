//! Why the facade gives no plan: bad input (options, query, tables) apart from a
//! query that ran and found none.

use crate::collision::ContextError;
use crate::planner::PlanError;
use crate::tables::TablesError;

/// Why [`super::plan`] gives no plan. [`Self::is_input`] tells bad input (the
/// command line's exit 2) from a query that ran and found no plan (exit 1).
#[derive(Debug, thiserror::Error)]
pub enum PlanningError {
    /// The time limit is no positive number of seconds within the largest.
    #[error(
        "time limit {0} s: a positive number of seconds, at most {max:e}",
        max = super::MAX_TIME_LIMIT_S
    )]
    TimeLimit(f64),
    /// The chain or the clearance cannot make a collision context.
    #[error("clearance = {clearance}: {source}")]
    Context {
        /// The clearance asked (m).
        clearance: f64,
        /// Why.
        source: ContextError,
    },
    /// The shape tables could not be built.
    #[error("shape tables of {srs} random shapes: {source}")]
    Tables {
        /// Random shapes asked.
        srs: usize,
        /// Why.
        source: TablesError,
    },
    /// The planner refuses the query or the tables: tables of another chain, a
    /// start or a goal that is not valid.
    #[error(transparent)]
    Refused(PlanError),
    /// The query ran and found no plan ([`NoPlan`] says why and what was tried).
    #[error(transparent)]
    NoPlan(Box<NoPlan>),
    /// A mission's goal that cannot be used for the chain (bad input); the text names
    /// the field.
    #[error("{0}")]
    Mission(String),
    /// A tuning setting outside its range (the field and its value).
    #[error("setting {0}")]
    Setting(#[from] crate::planner::SettingError),
    /// The goal's yaw and shape give no valid configuration at the goal (bad input).
    #[error("the goal configuration ({pose}) is not valid at ({x:.3}, {y:.3}, {z:.3}): {why}", x = at[0], y = at[1], z = at[2])]
    GoalPose {
        /// The pose in words.
        pose: String,
        /// The goal's head position.
        at: [f64; 3],
        /// Why, by the exact test (at the best heading tried).
        why: String,
    },
    /// The route reached the goal, but no checked shape change takes the chain into
    /// the goal's yaw and shape there.
    #[error("no plan: the head reached ({x:.3}, {y:.3}, {z:.3}), but no checked shape change (direct, or through one library or random shape) takes the chain into the goal configuration ({pose}) there", x = at[0], y = at[1], z = at[2])]
    PoseUnreachable {
        /// The pose in words.
        pose: String,
        /// Where the head's route ended.
        at: [f64; 3],
    },
}

impl PlanningError {
    /// Whether the input is at fault (options, tables, query), rather than the query
    /// having no plan.
    pub fn is_input(&self) -> bool {
        !matches!(
            self,
            PlanningError::NoPlan(_) | PlanningError::PoseUnreachable { .. }
        )
    }
}

/// A query that ran and found no plan: why, and what it tried for how long.
#[derive(Debug, thiserror::Error)]
#[error(
    "no plan: {error} (after {:.1} ms of planning; setup {:.1} ms){}",
    planning_s * 1e3,
    setup_s * 1e3,
    tried_note(self)
)]
pub struct NoPlan {
    /// The planner's reason.
    pub error: PlanError,
    /// Time from the query's start to the failure (s).
    pub planning_s: f64,
    /// Setup before the query (context, tables, planner) (s).
    pub setup_s: f64,
    /// The time limit in force (s), if any.
    pub time_limit_s: Option<f64>,
    /// Vertices of the uniform head roadmap when the query gave up (0: none built).
    pub roadmap_vertices: usize,
    /// Full-chain collision checks the query made.
    pub collision_checks: u64,
}

/// For a query stopped by its time limit: what it tried and how far it got, and how
/// to give it longer.
fn tried_note(n: &NoPlan) -> String {
    if !matches!(n.error, PlanError::TimeLimit { .. }) {
        return String::new();
    }
    let limit = n
        .time_limit_s
        .map_or("no".to_string(), |t| format!("the {t} s"));
    let roadmap = match n.roadmap_vertices {
        0 => "the lattice's head route (no uniform head roadmap built)".to_string(),
        v => format!("a head roadmap of {v} vertices"),
    };
    format!(
        "; {limit} time limit stopped it after trying {roadmap} with {} collision checks; \
         a longer limit (--time-limit, default {} s) may find a plan",
        n.collision_checks,
        super::DEFAULT_TIME_LIMIT_S
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_time_limit_says_what_was_tried_and_other_failures_do_not() {
        // The same query stopped by its time limit, and refused for its goal.
        let no_plan = |error, planning_s, collision_checks| NoPlan {
            error,
            planning_s,
            setup_s: 0.5,
            time_limit_s: Some(60.0),
            roadmap_vertices: 1500,
            collision_checks,
        };
        let n = no_plan(PlanError::TimeLimit { replans: 3 }, 60.0, 12345);
        let s = PlanningError::NoPlan(Box::new(n)).to_string();
        assert!(
            s.starts_with("no plan: time limit reached after 3 replans"),
            "{s}"
        );
        for part in [
            "the 60 s time limit",
            "1500 vertices",
            "12345 collision checks",
        ] {
            assert!(s.contains(part), "{s}");
        }
        let n = no_plan(PlanError::Unreachable { tol: 0.3 }, 1.0, 1);
        let e = PlanningError::NoPlan(Box::new(n));
        assert!(!e.is_input());
        assert!(!e.to_string().contains("time limit"), "{e}");
    }
}
