//! Plan files: JSON, `"format": "arc-plan/1"` (docs/model.md, "Files").
//!
//! Values are `f64` in the file; shapes come from the `f32` core and are widened
//! exactly, head positions are kept in `f64` so a start given on the command line
//! is reproduced to the last digit.

use std::path::Path;

use arc_core::{ChainParams, Shape};
use serde::{Deserialize, Serialize};

/// The format tag every plan carries.
pub const FORMAT: &str = "arc-plan/1";

/// The chain a plan was made for.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ChainSection {
    /// Number of units N.
    pub units: u32,
    /// Link length l (m).
    pub link_length: f64,
    /// Unit sphere radius r_u (m).
    pub unit_radius: f64,
    /// Link capsule radius r_l (m).
    pub link_radius: f64,
    /// Pitch limit (rad).
    pub theta_max: f64,
    /// Bend limit (rad).
    pub beta_max: f64,
}

/// The map assumptions of a plan.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct MapSection {
    /// Voxel edge r_v (m).
    pub resolution: f64,
    /// Whether unknown space was treated as occupied.
    pub unknown_is_occupied: bool,
}

/// One waypoint: a full configuration zeta (2N + 2 numbers).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Waypoint {
    /// `[x1, y1, z1, psi1_r, theta_1, psi_1, ..., theta_{N-1}, psi_{N-1}]`.
    pub zeta: Vec<f64>,
}

/// Where a planner's time went (seconds); the only part of a plan that differs
/// between two runs with the same seed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Timing {
    /// Roadmap build.
    pub roadmap_s: f64,
    /// The query.
    pub planning_s: f64,
    /// Of the query, full-chain collision checks.
    pub collision_s: f64,
    /// Name of the rest of the query in the file (`shape_search_s`, `search_s`).
    pub rest: &'static str,
}

impl Timing {
    fn to_json(self) -> serde_json::Value {
        let mut m = serde_json::Map::new();
        m.insert("roadmap_build_s".into(), self.roadmap_s.into());
        m.insert("planning_s".into(), self.planning_s.into());
        m.insert("collision_checks_s".into(), self.collision_s.into());
        let rest = (self.planning_s - self.collision_s).max(0.0);
        m.insert(self.rest.into(), rest.into());
        serde_json::Value::Object(m)
    }
}

/// A plan as stored in the file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Plan {
    /// Always [`FORMAT`].
    pub format: String,
    /// The chain.
    pub chain: ChainSection,
    /// The map assumptions.
    pub map: MapSection,
    /// Waypoint 0 is the start; consecutive waypoints are edges.
    pub waypoints: Vec<Waypoint>,
    /// Free-form statistics (timings in seconds, counts).
    #[serde(default)]
    pub stats: serde_json::Map<String, serde_json::Value>,
}

/// Why a plan file cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum PlanError {
    /// The file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        source: std::io::Error,
    },
    /// The file is not valid JSON of the plan's shape.
    #[error("{path}: not an arc-plan/1 JSON file: {source}")]
    Json {
        /// The file.
        path: String,
        /// The cause.
        source: serde_json::Error,
    },
    /// The content breaks the format's rules.
    #[error("{path}: {what}")]
    Invalid {
        /// The file.
        path: String,
        /// The field and value at fault.
        what: String,
    },
}

impl ChainSection {
    /// The section describing `p`.
    pub fn from_params(p: &ChainParams) -> Self {
        Self {
            units: p.units as u32,
            link_length: p.link_length as f64,
            unit_radius: p.unit_radius as f64,
            link_radius: p.link_radius as f64,
            theta_max: p.theta_max as f64,
            beta_max: p.beta_max as f64,
        }
    }

    /// The core parameters, validated.
    pub fn to_params(&self) -> Result<ChainParams, String> {
        if !(2..=16).contains(&self.units) {
            return Err(format!("chain.units = {} is outside 2..=16", self.units));
        }
        ChainParams {
            units: self.units as u8,
            link_length: self.link_length as f32,
            unit_radius: self.unit_radius as f32,
            link_radius: self.link_radius as f32,
            theta_max: self.theta_max as f32,
            beta_max: self.beta_max as f32,
        }
        .validate()
        .map_err(|e| format!("chain: {e}"))
    }
}

impl Waypoint {
    /// A waypoint from a head position and a shape.
    pub fn new(xi: [f64; 3], shape: &Shape) -> Self {
        let mut zeta = xi.to_vec();
        zeta.extend(shape.as_slice().iter().map(|&a| a as f64));
        Self { zeta }
    }

    /// The head position.
    pub fn xi(&self) -> [f64; 3] {
        [self.zeta[0], self.zeta[1], self.zeta[2]]
    }

    /// The shape part eta.
    pub fn eta(&self) -> &[f64] {
        &self.zeta[3..]
    }
}

impl Plan {
    /// A plan through `steps` (head position and shape, the start first) for chain
    /// `params` on a map of `resolution` m, with `counts` and `timing` as its
    /// statistics.
    pub fn from_steps<'a>(
        params: &ChainParams,
        (resolution, unknown_is_occupied): (f64, bool),
        steps: impl IntoIterator<Item = ([f64; 3], &'a Shape)>,
        counts: &[(&str, u64)],
        timing: &Timing,
    ) -> Self {
        let mut stats: serde_json::Map<_, _> = counts
            .iter()
            .map(|&(k, v)| (k.to_string(), serde_json::Value::from(v)))
            .collect();
        stats.insert("timing".into(), timing.to_json());
        Plan {
            format: FORMAT.into(),
            chain: ChainSection::from_params(params),
            map: MapSection {
                resolution,
                unknown_is_occupied,
            },
            waypoints: steps
                .into_iter()
                .map(|(xi, shape)| Waypoint::new(xi, shape))
                .collect(),
            stats,
        }
    }

    /// Reads and checks a plan file: format tag, chain parameters, every waypoint's
    /// length and finiteness.
    pub fn read(path: &Path) -> Result<Self, PlanError> {
        let name = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|source| PlanError::Io {
            path: name.clone(),
            source,
        })?;
        Self::parse(&text, &name)
    }

    /// Parses and checks a plan's text (as [`Self::read`]); `name` names it in errors.
    pub fn parse(text: &str, name: &str) -> Result<Self, PlanError> {
        let plan: Plan = serde_json::from_str(text).map_err(|source| PlanError::Json {
            path: name.to_string(),
            source,
        })?;
        plan.check().map_err(|what| PlanError::Invalid {
            path: name.to_string(),
            what,
        })?;
        Ok(plan)
    }

    /// Checks the format rules that do not need a map.
    pub fn check(&self) -> Result<ChainParams, String> {
        if self.format != FORMAT {
            return Err(format!("format = {:?}, expected {FORMAT:?}", self.format));
        }
        let params = self.chain.to_params()?;
        if !(self.map.resolution.is_finite() && self.map.resolution > 0.0) {
            return Err(format!(
                "map.resolution = {} must be a positive number",
                self.map.resolution
            ));
        }
        if self.waypoints.is_empty() {
            return Err("waypoints is empty".into());
        }
        let dim = 2 * params.n() + 2;
        for (i, w) in self.waypoints.iter().enumerate() {
            if w.zeta.len() != dim {
                return Err(format!(
                    "waypoints[{i}].zeta has {} numbers, expected {dim} for N = {}",
                    w.zeta.len(),
                    params.n()
                ));
            }
            if let Some(j) = w.zeta.iter().position(|v| !v.is_finite()) {
                return Err(format!("waypoints[{i}].zeta[{j}] is not a finite number"));
            }
        }
        Ok(params)
    }

    /// Writes the plan as pretty JSON, atomically.
    pub fn write(&self, path: &Path) -> Result<(), PlanError> {
        let text = serde_json::to_string_pretty(self).expect("a plan always serialises");
        crate::fsutil::write_atomic(path, text.as_bytes()).map_err(|source| PlanError::Io {
            path: path.display().to_string(),
            source,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Plan {
        let p = ChainParams::new(3);
        Plan {
            format: FORMAT.into(),
            chain: ChainSection::from_params(&p),
            map: MapSection {
                resolution: 0.1,
                unknown_is_occupied: true,
            },
            waypoints: vec![Waypoint::new([1.0, 2.0, 3.0], &Shape::line(3, 0.0))],
            stats: Default::default(),
        }
    }

    #[test]
    fn round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.json");
        let plan = sample();
        plan.write(&path).unwrap();
        assert_eq!(Plan::read(&path).unwrap(), plan);
    }

    #[test]
    fn bad_plans_are_named() {
        let mut plan = sample();
        plan.waypoints[0].zeta.pop();
        assert!(plan
            .check()
            .unwrap_err()
            .contains("waypoints[0].zeta has 7 numbers"));
        let mut plan = sample();
        plan.format = "x".into();
        assert!(plan.check().unwrap_err().contains("format"));
        let mut plan = sample();
        plan.chain.units = 40;
        assert!(plan.check().unwrap_err().contains("chain.units = 40"));
    }
}
