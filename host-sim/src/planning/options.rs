//! The one options type of the facade: everything `arc plan`'s flags decide about
//! a plan, with `arc plan`'s defaults.

use std::time::Duration;

use serde::{Deserialize, Serialize};

use super::PlanningError;
use crate::collision::DEFAULT_CLEARANCE;
use crate::planner::{RefineSettings, Settings, Termination};
use crate::tables::TableSettings;

/// The time limit of `arc plan` and of [`super::plan`] unless one is given (s):
/// long enough for every built-in scenario and the large maps (seconds), short
/// enough that a query with no plan ends for a user who gave no limit.
pub const DEFAULT_TIME_LIMIT_S: f64 = 60.0;

/// The largest time limit (s): beyond it a limit means nothing (docs/promises.md).
pub const MAX_TIME_LIMIT_S: f64 = 1e6;

/// How to plan: `arc plan`'s flags, with its defaults (`Default`). In a file (serde,
/// e.g. JSON), a field left out takes its default.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PlanOptions {
    /// The planner's parameters (roadmap, shape sources, follow step, ...): the
    /// search's tuning.
    pub planner: Settings,
    /// Post-processing's tuning (and threading's, which the search uses too).
    pub refine: RefineSettings,
    /// Clearance margin added to every body's radius (m): plans keep this far from
    /// walls (`--clearance`).
    pub clearance: f64,
    /// Keep the plan as the search made it, without post-processing (`--no-smooth`).
    pub no_smooth: bool,
    /// Give up after this many seconds of search and post-processing (setup not
    /// counted); `None`: no limit. Default [`DEFAULT_TIME_LIMIT_S`].
    pub time_limit_s: Option<f64>,
    /// Random shapes `N_SRS` of the shape tables, when they are built here (`--srs`).
    pub srs: usize,
    /// Seed of the random shapes, when the tables are built here (`--srs-seed`).
    pub srs_seed: u64,
    /// Also time the plan into a trajectory with these settings (`--trajectory`);
    /// `None`: no trajectory.
    pub trajectory: Option<crate::trajectory::Settings>,
}

impl Default for PlanOptions {
    fn default() -> Self {
        let tables = TableSettings::default();
        Self {
            planner: Settings::default(),
            refine: RefineSettings::default(),
            clearance: DEFAULT_CLEARANCE,
            no_smooth: false,
            time_limit_s: Some(DEFAULT_TIME_LIMIT_S),
            srs: tables.srs,
            srs_seed: tables.seed,
            trajectory: None,
        }
    }
}

impl PlanOptions {
    /// The termination condition of the time limit, or why the limit is not one:
    /// a positive number of seconds, at most [`MAX_TIME_LIMIT_S`].
    pub fn termination(&self) -> Result<Termination, PlanningError> {
        let Some(t) = self.time_limit_s else {
            return Ok(Termination::default());
        };
        if !(t.is_finite() && t > 0.0 && t <= MAX_TIME_LIMIT_S) {
            return Err(PlanningError::TimeLimit(t));
        }
        Ok(Termination {
            time_limit: Some(Duration::from_secs_f64(t)),
        })
    }

    /// Checks the tuning settings (those without a flag of `arc plan`: the planner's
    /// lattice and construction tuning, post-processing's, and the trajectory's when
    /// one is asked for); the error names the field and its value.
    pub fn validate_tuning(&self) -> Result<(), PlanningError> {
        self.planner.validate_tuning()?;
        self.refine.validate()?;
        Ok(())
    }

    /// The settings of shape tables built for these options.
    pub fn table_settings(&self) -> TableSettings {
        TableSettings {
            srs: self.srs,
            seed: self.srs_seed,
            ..TableSettings::default()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_arc_plans_and_a_file_may_name_only_some_fields() {
        let o = PlanOptions::default();
        assert_eq!(o.time_limit_s, Some(60.0));
        assert_eq!(o.planner, Settings::default());
        let read: PlanOptions =
            serde_json::from_str(r#"{"clearance": 0.1, "planner": {"seed": 7}}"#).unwrap();
        assert_eq!(read.clearance, 0.1);
        assert_eq!(read.planner.seed, 7);
        assert_eq!(read.planner.vertices, o.planner.vertices);
        assert_eq!(read.time_limit_s, Some(60.0));
        let none: PlanOptions = serde_json::from_str(r#"{"time_limit_s": null}"#).unwrap();
        assert_eq!(none.termination().unwrap().time_limit, None);
        let back: PlanOptions = serde_json::from_str(&serde_json::to_string(&o).unwrap()).unwrap();
        assert_eq!(back, o);
        assert!(serde_json::from_str::<PlanOptions>(r#"{"clearence": 0.1}"#).is_err());
    }

    #[test]
    fn a_time_limit_that_is_no_positive_number_is_refused() {
        for t in [0.0, -1.0, f64::NAN, f64::INFINITY, 2e6] {
            let o = PlanOptions {
                time_limit_s: Some(t),
                ..PlanOptions::default()
            };
            let e = o.termination().unwrap_err();
            assert!(e.is_input(), "{e}");
        }
    }
}
