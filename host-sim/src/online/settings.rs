//! How the online planner plans ([`OnlineSettings`]), and why it cannot
//! ([`OnlineError`]).

use serde::{Deserialize, Serialize};

use crate::planner::SettingError;
use crate::planning::{
    unknown_key, PlanOptions, PlanningError, SettingsFile, SettingsFileError, ONLINE_SECTION,
};
use crate::sensing::occupancy::FusionError;

/// Wall time a replan may take by default (s): the built-in scenarios' pieces through
/// their narrow places are found within it on 2 cores (docs/online.md).
pub const DEFAULT_DEADLINE_S: f64 = 0.3;

/// Period of the route's replans by default (s); [`OnlineSettings::route_period_s`]
/// says what it trades.
pub const DEFAULT_ROUTE_PERIOD_S: f64 = 1.0;

/// Longest deadline (s): a replan longer than this leaves the chain waiting at rest
/// for a minute; the settings' contract, not tuning.
const MAX_DEADLINE_S: f64 = 60.0;

/// Longest route period (s): an hour, beyond any flight the simulator records.
const MAX_ROUTE_PERIOD_S: f64 = 3600.0;

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
    /// get, shared among the targets it tries, and what is left of it the found
    /// piece's timing. Longer finds pieces through harder places; shorter keeps the
    /// chain from waiting for its next piece. Default 0.3 s.
    pub deadline_s: f64,
    /// Period of the route's replans when nothing cuts it (s): how soon a shortcut
    /// that sensing opened is taken; also how long a chain at rest that finds no piece
    /// waits for something new before it is stuck ([`super::OnlinePlanner::stuck`]).
    /// Default [`DEFAULT_ROUTE_PERIOD_S`].
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
            route_period_s: DEFAULT_ROUTE_PERIOD_S,
            start_free: StartFree::default(),
        }
    }
}

impl OnlineSettings {
    /// The online settings a settings file gives (docs/model.md, "Settings files"):
    /// its planner, post-processing and trajectory sections for every piece, its
    /// `online` section for the rest; the planner's clearance stays `clearance`, a flag
    /// of its own.
    pub fn from_file(file: &ExploreSettingsFile, clearance: f64) -> Self {
        let d = Self::default();
        let sections = &file.sections;
        Self {
            plan: PlanOptions {
                planner: sections.planner.clone(),
                refine: sections.refine.clone(),
                clearance,
                ..d.plan
            },
            trajectory: sections.trajectory,
            deadline_s: file.online.deadline_s,
            route_period_s: file.online.route_period_s,
            start_free: file.online.start_free,
        }
    }
}

/// A settings file as the online planner reads it (`arc explore --settings`): the
/// sections every plan reads, and the `online` section.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ExploreSettingsFile {
    /// The planner, post-processing and trajectory sections.
    pub sections: SettingsFile,
    /// The `online` section.
    pub online: OnlineSection,
}

impl ExploreSettingsFile {
    /// Reads the settings in `text` (the file `file`, for messages) and checks them,
    /// as [`SettingsFile::parse`] does, the `online` section included.
    pub fn parse(text: &str, file: &str) -> Result<Self, SettingsFileError> {
        let sections = SettingsFile::parse(text, file)?;
        let format = |message: String| SettingsFileError::Format {
            file: file.to_string(),
            message,
        };
        let value: serde_json::Value =
            serde_json::from_str(text).map_err(|e| format(e.to_string()))?;
        let online = match value.get(ONLINE_SECTION) {
            None => OnlineSection::default(),
            Some(v) => {
                let known =
                    serde_json::to_value(OnlineSection::default()).expect("the section serializes");
                if !v.is_object() {
                    return Err(format(format!("{ONLINE_SECTION}: a JSON object")));
                }
                if let Some((key, known)) = unknown_key(v, &known, ONLINE_SECTION) {
                    return Err(SettingsFileError::UnknownKey {
                        file: file.to_string(),
                        key,
                        known,
                    });
                }
                let section: OnlineSection = serde_json::from_value(v.clone())
                    .map_err(|e| format(format!("{ONLINE_SECTION}: {e}")))?;
                section
                    .validate()
                    .map_err(|source| SettingsFileError::Value {
                        file: file.to_string(),
                        source,
                    })?;
                section
            }
        };
        Ok(Self { sections, online })
    }
}

/// A settings file's `online` section: the online planner's settings that are not
/// how a piece is planned or timed (those are the file's other sections). Fields as
/// [`OnlineSettings`]'s, with the same defaults.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct OnlineSection {
    /// [`OnlineSettings::deadline_s`].
    pub deadline_s: f64,
    /// [`OnlineSettings::route_period_s`].
    pub route_period_s: f64,
    /// [`OnlineSettings::start_free`].
    pub start_free: StartFree,
}

impl Default for OnlineSection {
    fn default() -> Self {
        let d = OnlineSettings::default();
        Self {
            deadline_s: d.deadline_s,
            route_period_s: d.route_period_s,
            start_free: d.start_free,
        }
    }
}

impl OnlineSection {
    /// Checks every field; the error names it as a file does (`online.deadline_s`).
    pub fn validate(&self) -> Result<(), SettingError> {
        check_times(self.deadline_s, self.route_period_s).map_err(|e| match e {
            OnlineError::Setting { field, value, rule } => {
                SettingError::new(&format!("online.{field}"), value, rule)
            }
            e => SettingError::new("online", e, "valid"),
        })
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

/// Refuses a deadline or a route period outside its range.
fn check_times(deadline_s: f64, route_period_s: f64) -> Result<(), OnlineError> {
    let positive = |field, value: f64, limit: f64, rule| {
        if value.is_finite() && value > 0.0 && value <= limit {
            Ok(())
        } else {
            Err(OnlineError::Setting { field, value, rule })
        }
    };
    positive(
        "deadline_s",
        deadline_s,
        MAX_DEADLINE_S,
        "a positive number of seconds, at most 60",
    )?;
    positive(
        "route_period_s",
        route_period_s,
        MAX_ROUTE_PERIOD_S,
        "a positive number of seconds, at most 3600",
    )
}

/// Refuses settings outside their ranges.
pub(super) fn check_settings(s: &OnlineSettings) -> Result<(), OnlineError> {
    check_times(s.deadline_s, s.route_period_s)?;
    s.plan.termination().map_err(OnlineError::Planning)?;
    s.trajectory
        .validate()
        .map_err(|e| OnlineError::Map(format!("trajectory settings: {e}")))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_settings_file_gives_the_online_section_and_the_pieces_sections() {
        let d = ExploreSettingsFile::parse("{}", "e.json").unwrap();
        assert_eq!(d, ExploreSettingsFile::default());
        let f = ExploreSettingsFile::parse(
            r#"{"planner": {"vertices": 700}, "trajectory": {"dt": 0.01},
                "online": {"start_free": "bodies", "route_period_s": 0.5}}"#,
            "s.json",
        )
        .unwrap();
        assert_eq!(f.online.start_free, StartFree::Bodies);
        assert_eq!(f.online.deadline_s, DEFAULT_DEADLINE_S);
        let s = OnlineSettings::from_file(&f, 0.07);
        assert_eq!(s.plan.planner.vertices, 700);
        assert_eq!((s.plan.clearance, s.trajectory.dt), (0.07, 0.01));
        assert_eq!((s.route_period_s, s.start_free), (0.5, StartFree::Bodies));
    }

    #[test]
    fn docs_settings_md_lists_every_online_setting() {
        let doc = include_str!("../../../docs/settings.md");
        let known = serde_json::to_value(OnlineSection::default()).unwrap();
        let keys = known.as_object().unwrap().keys();
        assert_eq!(keys.len(), 3);
        for k in keys {
            let row = format!("| `online.{k}` |");
            assert!(doc.contains(&row), "docs/settings.md lacks online.{k}");
        }
    }

    #[test]
    fn a_bad_online_section_is_refused_naming_the_file_and_the_key() {
        for (text, says) in [
            (
                r#"{"online": {"deadline": 1}}"#,
                "t.json: unknown key `online.deadline`",
            ),
            (
                r#"{"online": {"deadline_s": 0}}"#,
                "t.json: online.deadline_s = 0",
            ),
            (
                r#"{"online": {"route_period_s": 1e9}}"#,
                "t.json: online.route_period_s = 1000000000",
            ),
            (
                r#"{"online": {"start_free": "all"}}"#,
                "t.json: online: unknown variant",
            ),
            (r#"{"online": 3}"#, "t.json: online: a JSON object"),
            (
                r#"{"refine": {"widen": {"budgte": 3}}}"#,
                "refine.widen.budgte",
            ),
        ] {
            let e = ExploreSettingsFile::parse(text, "t.json")
                .unwrap_err()
                .to_string();
            assert!(e.contains(says), "{text}: {e}");
        }
    }
}
