//! Settings files (docs/model.md, "Settings files"): the tuning of a plan in one JSON
//! object with a section per settings type, read by `arc plan --settings` and `arc
//! explore --settings`. The `online` section is the online planner's, read with the
//! others by `online::ExploreSettingsFile` and skipped here.
//!
//! ```json
//! {"planner": {"vertices": 3000}, "refine": {"widen": {"budget": 300}},
//!  "trajectory": {"dt": 0.01}, "online": {"route_period_s": 0.5}}
//! ```
//!
//! Every section and every field may be left out and then takes its default; a key
//! that names no setting is refused (with its path, so that a misspelt key is never
//! silently ignored), and so is a value outside its range (with the field and the
//! value). docs/settings.md lists every field with its default and what it trades.

use serde::{Deserialize, Serialize};
use serde_json::Value;

use crate::planner::{RefineSettings, SettingError, Settings};

/// The sections of a settings file.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SettingsFile {
    /// The search's settings ([`Settings`]), flags of `arc plan` included.
    pub planner: Settings,
    /// Post-processing's tuning ([`RefineSettings`]).
    pub refine: RefineSettings,
    /// How a plan is timed into a trajectory (`crate::trajectory::Settings`), when one
    /// is made.
    pub trajectory: crate::trajectory::Settings,
}

/// The section of a settings file that holds the online planner's own settings: read
/// by the online planner's file type, skipped by [`SettingsFile::parse`].
pub const ONLINE_SECTION: &str = "online";

/// Why a settings file cannot be used: each names the file.
#[derive(Debug, thiserror::Error)]
pub enum SettingsFileError {
    /// The file is not JSON, or a value has the wrong type.
    #[error("{file}: {message}")]
    Format {
        /// The file's name.
        file: String,
        /// What is wrong, where.
        message: String,
    },
    /// A key that names no setting.
    #[error("{file}: unknown key `{key}` (known here: {known})")]
    UnknownKey {
        /// The file's name.
        file: String,
        /// The key's path, sections and fields joined by dots.
        key: String,
        /// The keys known where it stands.
        known: String,
    },
    /// A setting outside its range.
    #[error("{file}: {source}")]
    Value {
        /// The file's name.
        file: String,
        /// The field, its value and its range.
        source: SettingError,
    },
}

impl SettingsFile {
    /// Reads the settings in `text` (the file `file`, for messages), and checks them.
    pub fn parse(text: &str, file: &str) -> Result<Self, SettingsFileError> {
        let format = |message: String| SettingsFileError::Format {
            file: file.to_string(),
            message,
        };
        let mut value: Value = serde_json::from_str(text).map_err(|e| format(e.to_string()))?;
        let known = serde_json::to_value(Self::default()).expect("settings serialize");
        let Some(sections) = value.as_object_mut() else {
            return Err(format("a settings file is one JSON object".into()));
        };
        sections.remove(ONLINE_SECTION);
        if let Some((key, known)) = unknown_key(&value, &known, "") {
            return Err(SettingsFileError::UnknownKey {
                file: file.to_string(),
                key,
                known,
            });
        }
        let settings: Self = serde_json::from_value(value).map_err(|e| format(e.to_string()))?;
        settings
            .validate()
            .map_err(|source| SettingsFileError::Value {
                file: file.to_string(),
                source,
            })?;
        Ok(settings)
    }

    /// Checks every tuning setting of the sections: the planner's without a flag,
    /// post-processing's, the trajectory's. (The planner's flag-backed fields are
    /// checked where `arc plan` reads them, together with its flags.)
    pub fn validate(&self) -> Result<(), SettingError> {
        self.planner.validate_tuning()?;
        self.refine.validate()?;
        use crate::trajectory::TrajectoryError as E;
        self.trajectory.validate().map_err(|e| match e {
            E::Limit { name, value } => {
                let limit = [
                    "speed",
                    "accel",
                    "angular_rate",
                    "angular_accel",
                    "yaw_rate",
                    "yaw_accel",
                ]
                .contains(&name);
                let field = match limit {
                    true => format!("trajectory.limits.{name}"),
                    false => format!("trajectory.{name}"),
                };
                SettingError::new(&field, value, "a positive number")
            }
            E::Dt(v) => SettingError::new("trajectory.dt", v, "in (0, 0.1] s"),
            e => SettingError::new("trajectory", e, "valid"),
        })?;
        Ok(())
    }
}

/// The first key of `value` (an object, at `path`) that `known` (the defaults, as
/// JSON) does not have, with the keys known there; objects are searched within.
pub(crate) fn unknown_key(value: &Value, known: &Value, path: &str) -> Option<(String, String)> {
    let (Value::Object(v), Value::Object(k)) = (value, known) else {
        return None;
    };
    for (key, inner) in v {
        let here = match path {
            "" => key.clone(),
            p => format!("{p}.{key}"),
        };
        match k.get(key) {
            None => {
                let names: Vec<&str> = k.keys().map(String::as_str).collect();
                return Some((here, names.join(", ")));
            }
            Some(kv) => {
                if let Some(found) = unknown_key(inner, kv, &here) {
                    return Some(found);
                }
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_defaults_round_trip_and_a_file_may_name_only_some_fields() {
        let d = SettingsFile::default();
        let text = serde_json::to_string_pretty(&d).unwrap();
        assert_eq!(SettingsFile::parse(&text, "d.json").unwrap(), d);
        assert_eq!(SettingsFile::parse("{}", "e.json").unwrap(), d);
        let some = SettingsFile::parse(
            r#"{"planner": {"vertices": 700, "lattice": {"heuristic_weight": 3.0}},
                "refine": {"widen": {"budget": 10}}, "trajectory": {"dt": 0.01},
                "online": {"anything": "skipped here"}}"#,
            "s.json",
        )
        .unwrap();
        assert_eq!(some.planner.vertices, 700);
        assert_eq!(some.planner.lattice.heuristic_weight, 3.0);
        assert_eq!(some.planner.lattice.budget, d.planner.lattice.budget);
        assert_eq!(some.refine.widen.budget, 10);
        assert_eq!(some.refine.widen.centred, d.refine.widen.centred);
        assert_eq!(some.trajectory.dt, 0.01);
        let back = serde_json::to_string(&some).unwrap();
        assert_eq!(SettingsFile::parse(&back, "s.json").unwrap(), some);
    }

    #[test]
    fn an_unknown_key_is_refused_with_its_path_and_the_file() {
        let e = SettingsFile::parse(r#"{"refine": {"widen": {"budgte": 3}}}"#, "t.json")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("t.json: unknown key `refine.widen.budgte`"),
            "{e}"
        );
        assert!(e.contains("budget"), "{e}");
        let e = SettingsFile::parse(r#"{"plannr": {}}"#, "t.json").unwrap_err();
        assert!(e.to_string().contains("`plannr`"), "{e}");
        let e = SettingsFile::parse("[1]", "t.json").unwrap_err();
        assert!(e.to_string().starts_with("t.json: "), "{e}");
    }

    #[test]
    fn docs_settings_md_lists_every_setting() {
        let doc = include_str!("../../../docs/settings.md");
        let mut keys = Vec::new();
        let known = serde_json::to_value(SettingsFile::default()).unwrap();
        fn walk(v: &Value, path: &str, out: &mut Vec<String>) {
            match v {
                Value::Object(m) if path != "trajectory.limits" => {
                    for (k, inner) in m {
                        let here = match path {
                            "" => k.clone(),
                            p => format!("{p}.{k}"),
                        };
                        walk(inner, &here, out);
                    }
                }
                _ => out.push(path.to_string()),
            }
        }
        walk(&known, "", &mut keys);
        assert!(keys.len() > 80, "{}", keys.len());
        for k in keys {
            assert!(
                doc.contains(&format!("| `{k}` |")),
                "docs/settings.md lacks {k}"
            );
        }
    }

    #[test]
    fn a_value_out_of_range_is_refused_with_its_field_and_value() {
        for (text, field, value) in [
            (
                r#"{"refine": {"widen": {"centred": 1.5}}}"#,
                "refine.widen.centred",
                "1.5",
            ),
            (
                r#"{"refine": {"check_budget": 0}}"#,
                "refine.check_budget",
                "0",
            ),
            (
                r#"{"planner": {"lattice": {"heuristic_weight": 0.5}}}"#,
                "planner.lattice.heuristic_weight",
                "0.5",
            ),
            (r#"{"trajectory": {"max_run": 0}}"#, "max_run", "0"),
            (
                r#"{"refine": {"thread": {"grid_steps": 5000}}}"#,
                "grid_steps",
                "5000",
            ),
        ] {
            let e = SettingsFile::parse(text, "v.json").unwrap_err().to_string();
            assert!(e.starts_with("v.json: "), "{e}");
            assert!(e.contains(field) && e.contains(value), "{text}: {e}");
        }
        let e = SettingsFile::parse(r#"{"refine": {"check_budget": -1}}"#, "v.json");
        assert!(e.unwrap_err().to_string().starts_with("v.json: "));
    }
}
