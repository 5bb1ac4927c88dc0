//! Missions (docs/model.md, "Missions"): a start, then an ordered list of goals, each a
//! head position with a tolerance and optionally a yaw, a shape, a hold and the shape
//! preference of the leg that reaches it. The file is JSON, `"format": "arc-mission/1"`.

use std::path::Path;

use aerial_chain_core::lsc::LscKind;
use aerial_chain_core::{ChainParams, Shape};
use nalgebra::Point3;
use serde::{Deserialize, Serialize};

use crate::fsutil;
use crate::goal::{parse_shape, GoalPose};
use crate::planner::{Preference, Query};

/// The format tag of a mission file.
pub const FORMAT: &str = "arc-mission/1";
/// Most goals a mission holds: far beyond an inspection flight, and a bound on the
/// legs planned.
pub const MAX_GOALS: usize = 1000;
/// Longest hold at a goal (s): an hour.
pub const MAX_HOLD_S: f64 = 3600.0;

/// A shape as a file names it: a library name or the angles of `eta` (rad).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum ShapeSpec {
    /// A library shape (LI, SE, SM, SV, CA, PN).
    Name(String),
    /// `eta`: head yaw, then every link's pitch and yaw (rad).
    Angles(Vec<f64>),
}

impl ShapeSpec {
    /// The shape for the chain `params`.
    pub fn shape(&self, params: &ChainParams) -> Result<Shape, String> {
        let text = match self {
            ShapeSpec::Name(n) => n.clone(),
            ShapeSpec::Angles(a) => a
                .iter()
                .map(|v| v.to_string())
                .collect::<Vec<_>>()
                .join(","),
        };
        parse_shape(params, &text).map_err(|e| e.to_string())
    }

    /// The name of a library shape, for messages.
    pub fn name(&self) -> Option<&str> {
        match self {
            ShapeSpec::Name(n) => Some(n),
            ShapeSpec::Angles(_) => None,
        }
    }
}

/// Where a mission starts.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MissionStart {
    /// The head's position (m).
    pub position: [f64; 3],
    /// The head's yaw (rad); default 0.
    #[serde(default)]
    pub yaw: f64,
    /// The start shape, turned to the yaw; default LI.
    #[serde(default)]
    pub shape: Option<ShapeSpec>,
}

/// One goal.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MissionGoal {
    /// The head's position (m).
    pub position: [f64; 3],
    /// How close the head must come (m); default the planner's 0.3.
    #[serde(default = "default_tolerance")]
    pub tolerance: f64,
    /// The head's yaw (rad), if asked for.
    #[serde(default)]
    pub yaw: Option<f64>,
    /// The shape, if asked for (any heading unless `yaw` is given).
    #[serde(default)]
    pub shape: Option<ShapeSpec>,
    /// How long the chain rests at the goal (s); default 0.
    #[serde(default)]
    pub hold_s: f64,
    /// The shape preference of the leg to this goal; default `least`.
    #[serde(default)]
    pub prefer: Preference,
}

fn default_tolerance() -> f64 {
    Query::DEFAULT_GOAL_TOL
}

/// A mission file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Mission {
    /// `"arc-mission/1"`.
    pub format: String,
    /// The chain's units; with a scenario, default the scenario's.
    #[serde(default)]
    pub units: Option<u8>,
    /// The start; with a scenario, default the scenario's start, yaw and LI.
    #[serde(default)]
    pub start: Option<MissionStart>,
    /// The goals, in order.
    pub goals: Vec<MissionGoal>,
}

/// A mission file that cannot be read or breaks a rule: the file, the field, the value.
#[derive(Debug, thiserror::Error)]
#[error("{path}: {what}")]
pub struct MissionError {
    /// The file.
    pub path: String,
    /// What is wrong, naming the field.
    pub what: String,
}

impl Mission {
    /// Reads and checks a mission file (`-`: standard input).
    pub fn read(path: &Path) -> Result<Self, MissionError> {
        let name = fsutil::input_name(path);
        let text = fsutil::read_input(path).map_err(|e| MissionError {
            path: name.clone(),
            what: e.to_string(),
        })?;
        Self::parse(&text, &name)
    }

    /// Parses and checks a mission's text; `name` names it in errors.
    pub fn parse(text: &str, name: &str) -> Result<Self, MissionError> {
        fsutil::parse_checked(text, FORMAT, Self::check).map_err(|what| MissionError {
            path: name.to_string(),
            what,
        })
    }

    /// The rules that need no map nor chain.
    pub fn check(&self) -> Result<(), String> {
        if self.format != FORMAT {
            return Err(format!("format = {:?}, expected {FORMAT:?}", self.format));
        }
        if self.goals.is_empty() || self.goals.len() > MAX_GOALS {
            return Err(format!(
                "goals has {} entries: 1 to {MAX_GOALS}",
                self.goals.len()
            ));
        }
        let finite = |p: &[f64; 3]| p.iter().all(|v| v.is_finite());
        if let Some(s) = &self.start {
            if !finite(&s.position) || !s.yaw.is_finite() {
                return Err("start: position and yaw must be finite numbers".into());
            }
        }
        for (k, g) in self.goals.iter().enumerate() {
            if !finite(&g.position) {
                return Err(format!(
                    "goals[{k}].position has a number that is not finite"
                ));
            }
            if !(g.tolerance >= 0.0 && g.tolerance <= 1e4) {
                return Err(format!(
                    "goals[{k}].tolerance = {} must be from 0 to 1e4 m",
                    g.tolerance
                ));
            }
            if let Some(y) = g.yaw.filter(|y| !y.is_finite()) {
                return Err(format!("goals[{k}].yaw = {y} is not a finite number"));
            }
            if !(g.hold_s >= 0.0 && g.hold_s <= MAX_HOLD_S) {
                return Err(format!(
                    "goals[{k}].hold_s = {} must be from 0 to {MAX_HOLD_S} s",
                    g.hold_s
                ));
            }
        }
        Ok(())
    }

    /// Goal `k`'s yaw and shape for the chain `params`.
    pub fn pose(&self, k: usize, params: &ChainParams) -> Result<GoalPose, String> {
        let g = &self.goals[k];
        let shape = match &g.shape {
            Some(s) => Some(
                s.shape(params)
                    .map_err(|e| format!("goals[{k}].shape: {e}"))?,
            ),
            None => None,
        };
        Ok(GoalPose {
            yaw: g.yaw.map(|y| y as f32),
            shape,
        })
    }

    /// The start's head position and shape for the chain `params`, where the file
    /// gives a start.
    pub fn start_of(&self, params: &ChainParams) -> Result<Option<(Point3<f64>, Shape)>, String> {
        let Some(s) = &self.start else {
            return Ok(None);
        };
        let shape = match &s.shape {
            Some(spec) => spec
                .shape(params)
                .map_err(|e| format!("start.shape: {e}"))?,
            None => {
                aerial_chain_core::lsc::generate(params, LscKind::Li)
                    .map_err(|v| format!("start: LI is not valid for this chain ({v:?})"))?
                    .shape
            }
        };
        let turned = shape.rotated(s.yaw as f32 - shape.head_yaw());
        Ok(Some((s.position.into(), turned)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_mission_reads_with_defaults_and_bad_fields_are_named() {
        let m = Mission::parse(
            r#"{"format": "arc-mission/1", "goals": [
                {"position": [1, 2, 3]},
                {"position": [4, 5, 6], "yaw": 1.5, "shape": "PN", "hold_s": 2, "prefer": "coverage"},
                {"position": [4, 5, 6], "shape": [0, 0, 0, 0, 0]}]}"#,
            "m.json",
        )
        .unwrap();
        assert_eq!(m.goals[0].tolerance, 0.3);
        assert_eq!(m.goals[1].prefer, Preference::Coverage);
        let p = ChainParams::new(3);
        assert!(m.pose(2, &p).unwrap().shape.is_some());
        assert!(m.pose(1, &p).is_err(), "PN is not in N = 3's library");
        for (text, words) in [
            (
                r#"{"format": "arc-mission/2", "goals": [{"position": [0,0,0]}]}"#,
                "format",
            ),
            (r#"{"format": "arc-mission/1", "goals": []}"#, "goals has 0"),
            (
                r#"{"format": "arc-mission/1", "goals": [{"position": [0,0,0], "hold_s": -1}]}"#,
                "goals[0].hold_s",
            ),
            (
                r#"{"format": "arc-mission/1", "goals": [{"position": [0,0,0], "tolerence": 1}]}"#,
                "tolerence",
            ),
            (
                r#"{"format": "arc-mission/1", "goals": [{"position": [0,0,0], "prefer": "most"}]}"#,
                "most",
            ),
        ] {
            let e = Mission::parse(text, "m.json").unwrap_err().to_string();
            assert!(e.starts_with("m.json: ") && e.contains(words), "{e}");
        }
    }
}
