//! Plan files: JSON, `"format": "arc-plan/1"` (docs/model.md, "Plans").
//!
//! Values are `f64` in the file. Numbers that come from the `f32` core (shape angles,
//! chain parameters) are written as the shortest decimal that reads back as the same
//! `f32` (`0.15`, not `0.15000000596046448`); head positions are kept in `f64` so a
//! start given on the command line is reproduced to the last digit. A plan records
//! which map it was made for (file name and SHA-256, or the scenario).

use std::io::Read;
use std::path::Path;

use crate::collision::Verifiable;
use crate::map::grid::Grid;
use aerial_chain_core::{ChainParams, Shape};
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

/// The map assumptions of a plan, and which map it was made for.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MapSection {
    /// Voxel edge r_v (m).
    pub resolution: f64,
    /// Whether unknown space was treated as occupied.
    pub unknown_is_occupied: bool,
    /// Which map: optional fields, absent in plans written before they existed.
    #[serde(flatten)]
    pub source: MapSource,
}

/// Which map a plan was made for: a file (its name and the SHA-256 of its bytes) or a
/// built-in scenario. Informative: a checker tests a plan against the map it is given,
/// and says so when that map is not the one recorded here.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct MapSource {
    /// The map file's name, without its directory.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<String>,
    /// SHA-256 of the map file's bytes, 64 lowercase hex digits.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sha256: Option<String>,
    /// The built-in scenario's name (as given to `--scenario`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scenario: Option<String>,
}

impl MapSection {
    /// A section with no record of the map's source.
    pub fn new(resolution: f64, unknown_is_occupied: bool) -> Self {
        Self {
            resolution,
            unknown_is_occupied,
            source: MapSource::default(),
        }
    }

    /// The section of a plan made on `grid`, with no record of the map's source.
    pub fn of(grid: &Grid) -> Self {
        Self::new(grid.resolution(), grid.unknown_is_occupied())
    }

    /// This section, recording that the map came from `source`.
    pub fn with_source(self, source: MapSource) -> Self {
        Self { source, ..self }
    }
}

impl MapSource {
    /// The source of a map read from `path`, whose content is `bytes`.
    pub fn file(path: &Path, bytes: &[u8]) -> Self {
        use sha2::{Digest, Sha256};
        let digest = Sha256::digest(bytes);
        Self {
            file: path.file_name().map(|n| n.to_string_lossy().into_owned()),
            sha256: Some(digest.iter().map(|b| format!("{b:02x}")).collect()),
            scenario: None,
        }
    }

    /// The source of a built-in scenario.
    pub fn scenario(name: &str) -> Self {
        Self {
            scenario: Some(name.to_string()),
            ..Self::default()
        }
    }

    /// Whether both name a map and the maps differ: different file contents, different
    /// scenarios, or a file against a scenario. Unrecorded sources differ from nothing.
    pub fn differs_from(&self, other: &MapSource) -> bool {
        let recorded = |s: &MapSource| s.sha256.is_some() || s.scenario.is_some();
        recorded(self)
            && recorded(other)
            && (self.sha256 != other.sha256 || self.scenario != other.scenario)
    }
}

impl std::fmt::Display for MapSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match (&self.scenario, &self.file, &self.sha256) {
            (Some(s), _, _) => write!(f, "scenario {s}"),
            (None, file, Some(h)) => write!(
                f,
                "{} (sha256 {})",
                file.as_deref().unwrap_or("a map file"),
                &h[..h.len().min(12)]
            ),
            (None, Some(file), None) => f.write_str(file),
            (None, None, None) => f.write_str("an unrecorded map"),
        }
    }
}

/// `x` as the shortest decimal that reads back as the same `f32`, in an `f64`: what a
/// plan file stores for values that come from the `f32` core, so that `0.15f32` is
/// written `0.15` (its exact widening would be `0.15000000596046448`).
pub fn f32_decimal(x: f32) -> f64 {
    // Display prints the shortest round-trip representation; it always parses.
    x.to_string().parse().unwrap_or(f64::from(x))
}

/// One waypoint: a full configuration zeta (2N + 2 numbers), and, in a mission's
/// plan, the goal it reaches (docs/model.md, "Missions").
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Waypoint {
    /// `[x1, y1, z1, psi1_r, theta_1, psi_1, ..., theta_{N-1}, psi_{N-1}]`.
    pub zeta: Vec<f64>,
    /// The index of the mission goal reached here, if one is.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub goal: Option<usize>,
    /// How long the chain rests here (s), at a goal.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hold_s: Option<f64>,
}

/// Where a planner's time went (seconds): the part of a planner's statistics, and of a
/// plan, that differs between two runs with the same seed. Both planners' statistics
/// hold one.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Timings {
    /// Search structures built before or during the query: the roadmap (for the ARC
    /// planner, the labelled free regions and the uniform head roadmap, when the query
    /// needed them and they were not built before).
    pub roadmap_s: f64,
    /// The query.
    pub planning_s: f64,
    /// Of the query, full-chain collision checks.
    pub collision_s: f64,
}

impl Timings {
    /// The rest of the query: its time outside collision checks.
    pub fn rest_s(&self) -> f64 {
        (self.planning_s - self.collision_s).max(0.0)
    }

    /// The file's `stats.timing`, the rest of the query under the name `rest`.
    fn to_json(self, rest: &str) -> serde_json::Value {
        let mut m = serde_json::Map::new();
        m.insert("roadmap_build_s".into(), self.roadmap_s.into());
        m.insert("planning_s".into(), self.planning_s.into());
        m.insert("collision_checks_s".into(), self.collision_s.into());
        m.insert(rest.into(), self.rest_s().into());
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
    #[error("{path}: {what}")]
    Json {
        /// The file.
        path: String,
        /// What is wrong: the file's own format where it names another, else serde's
        /// error (`fsutil::not_of_format`).
        what: String,
    },
    /// The content breaks the format's rules.
    #[error("{path}: {what}")]
    Invalid {
        /// The file.
        path: String,
        /// The field and value at fault.
        what: FormatError,
    },
}

/// A rule of the plan format (docs/model.md, "Plans") that a plan breaks; each names
/// the field and the value at fault.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FormatError {
    /// Another format or version.
    #[error("format = {0:?}, expected {FORMAT:?}")]
    Format(String),
    /// A unit count outside 2..=16.
    #[error("chain.units = {0} is outside 2..=16")]
    Units(u32),
    /// Chain parameters that are no valid chain.
    #[error("chain: {0}")]
    Chain(aerial_chain_core::ParamError),
    /// A map resolution that is not a positive number.
    #[error("map.resolution = {0} must be a positive number")]
    Resolution(f64),
    /// A plan without waypoints.
    #[error("waypoints is empty")]
    NoWaypoints,
    /// A waypoint of the wrong length for the chain.
    #[error("waypoints[{index}].zeta has {got} numbers, expected {expected} for N = {units}")]
    ZetaLength {
        /// The waypoint.
        index: usize,
        /// Numbers it has.
        got: usize,
        /// Numbers a configuration of this chain has (`2N + 2`).
        expected: usize,
        /// The chain's units.
        units: usize,
    },
    /// A waypoint number that is not finite.
    #[error("waypoints[{index}].zeta[{at}] is not a finite number")]
    NotFinite {
        /// The waypoint.
        index: usize,
        /// The position of the number in `zeta`.
        at: usize,
    },
    /// A hold that is no number of seconds `>= 0`.
    #[error("waypoints[{index}].hold_s = {value} is not a number of seconds >= 0")]
    Hold {
        /// The waypoint.
        index: usize,
        /// The value.
        value: f64,
    },
    /// Goals marked out of order.
    #[error(
        "waypoints[{index}].goal = {goal} comes after goal {before}: goals are reached in order"
    )]
    GoalOrder {
        /// The waypoint.
        index: usize,
        /// Its goal.
        goal: usize,
        /// The goal marked before it.
        before: usize,
    },
}

impl ChainSection {
    /// The section describing `p`.
    pub fn from_params(p: &ChainParams) -> Self {
        Self {
            units: p.units as u32,
            link_length: f32_decimal(p.link_length),
            unit_radius: f32_decimal(p.unit_radius),
            link_radius: f32_decimal(p.link_radius),
            theta_max: f32_decimal(p.theta_max),
            beta_max: f32_decimal(p.beta_max),
        }
    }

    /// The core parameters, validated.
    pub fn to_params(&self) -> Result<ChainParams, FormatError> {
        if !(2..=16).contains(&self.units) {
            return Err(FormatError::Units(self.units));
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
        .map_err(FormatError::Chain)
    }
}

impl Waypoint {
    /// A waypoint from a head position and a shape.
    pub fn new(xi: [f64; 3], shape: &Shape) -> Self {
        let mut zeta = xi.to_vec();
        zeta.extend(shape.as_slice().iter().map(|&a| f32_decimal(a)));
        Self {
            zeta,
            goal: None,
            hold_s: None,
        }
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

/// A plan file as the exact verifier reads it (`crate::collision::verify_plan`).
impl Verifiable for Plan {
    fn chain(&self) -> Result<ChainParams, String> {
        self.check().map_err(|e| e.to_string())
    }

    fn configurations(&self) -> Vec<&[f64]> {
        self.waypoints.iter().map(|w| w.zeta.as_slice()).collect()
    }

    fn map_assumptions(&self) -> (f64, bool) {
        (self.map.resolution, self.map.unknown_is_occupied)
    }
}

impl Plan {
    /// A plan through `steps` (head position and shape, the start first) for chain
    /// `params` on the map `map` describes, with `counts` and `timings` as its
    /// statistics (the rest of the query named `rest`: `shape_search_s`, `search_s`).
    pub fn from_steps<'a>(
        params: &ChainParams,
        map: MapSection,
        steps: impl IntoIterator<Item = ([f64; 3], &'a Shape)>,
        counts: Vec<(String, u64)>,
        (timings, rest): (&Timings, &str),
    ) -> Self {
        let mut stats: serde_json::Map<_, _> = counts
            .into_iter()
            .map(|(k, v)| (k, serde_json::Value::from(v)))
            .collect();
        stats.insert("timing".into(), timings.to_json(rest));
        Plan {
            format: FORMAT.into(),
            chain: ChainSection::from_params(params),
            map,
            waypoints: steps
                .into_iter()
                .map(|(xi, shape)| Waypoint::new(xi, shape))
                .collect(),
            stats,
        }
    }

    /// A plan through the configurations `zetas` (the start first) for chain `params`
    /// on the map `map` describes, with no statistics.
    pub fn from_zetas(params: &ChainParams, map: MapSection, zetas: Vec<Vec<f64>>) -> Self {
        Plan {
            format: FORMAT.into(),
            chain: ChainSection::from_params(params),
            map,
            waypoints: zetas
                .into_iter()
                .map(|zeta| Waypoint {
                    zeta,
                    goal: None,
                    hold_s: None,
                })
                .collect(),
            stats: serde_json::Map::new(),
        }
    }

    /// Reads and checks a plan file (`-`: standard input): format tag, chain
    /// parameters, every waypoint's length and finiteness.
    pub fn read(path: &Path) -> Result<Self, PlanError> {
        let name = crate::fsutil::input_name(path);
        let mut text = String::new();
        let read = if crate::fsutil::is_stdio(path) {
            std::io::stdin().read_to_string(&mut text)
        } else {
            std::fs::File::open(path).and_then(|mut f| f.read_to_string(&mut text))
        };
        read.map_err(|source| PlanError::Io {
            path: name.clone(),
            source,
        })?;
        Self::parse(&text, &name)
    }

    /// Parses and checks a plan's text (as [`Self::read`]); `name` names it in errors.
    pub fn parse(text: &str, name: &str) -> Result<Self, PlanError> {
        let plan: Plan = serde_json::from_str(text).map_err(|e| PlanError::Json {
            path: name.to_string(),
            what: crate::fsutil::not_of_format(text, FORMAT, &e),
        })?;
        plan.check().map_err(|what| PlanError::Invalid {
            path: name.to_string(),
            what,
        })?;
        Ok(plan)
    }

    /// Checks the format rules that do not need a map.
    pub fn check(&self) -> Result<ChainParams, FormatError> {
        if self.format != FORMAT {
            return Err(FormatError::Format(self.format.clone()));
        }
        let params = self.chain.to_params()?;
        if !(self.map.resolution.is_finite() && self.map.resolution > 0.0) {
            return Err(FormatError::Resolution(self.map.resolution));
        }
        if self.waypoints.is_empty() {
            return Err(FormatError::NoWaypoints);
        }
        let dim = 2 * params.n() + 2;
        for (i, w) in self.waypoints.iter().enumerate() {
            if w.zeta.len() != dim {
                return Err(FormatError::ZetaLength {
                    index: i,
                    got: w.zeta.len(),
                    expected: dim,
                    units: params.n(),
                });
            }
            if let Some(j) = w.zeta.iter().position(|v| !v.is_finite()) {
                return Err(FormatError::NotFinite { index: i, at: j });
            }
            if let Some(h) = w.hold_s.filter(|h| !(h.is_finite() && *h >= 0.0)) {
                return Err(FormatError::Hold { index: i, value: h });
            }
        }
        self.check_goal_order()?;
        Ok(params)
    }

    /// Goals marked on waypoints come in increasing order.
    fn check_goal_order(&self) -> Result<(), FormatError> {
        let mut before: Option<usize> = None;
        for (index, w) in self.waypoints.iter().enumerate() {
            let Some(goal) = w.goal else { continue };
            if let Some(b) = before.filter(|b| goal <= *b) {
                return Err(FormatError::GoalOrder {
                    index,
                    goal,
                    before: b,
                });
            }
            before = Some(goal);
        }
        Ok(())
    }

    /// Writes the plan as pretty JSON, atomically (`-`: to standard output).
    pub fn write(&self, path: &Path) -> Result<(), PlanError> {
        let mut text = serde_json::to_string_pretty(self).expect("a plan always serialises");
        text.push('\n');
        crate::fsutil::write_output(path, text.as_bytes()).map_err(|source| PlanError::Io {
            path: crate::fsutil::output_name(path),
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
            map: MapSection::new(0.1, true),
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
    fn numbers_from_f32_carry_no_noise() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.json");
        let mut plan = sample();
        let shape = Shape::line(3, 0.1);
        plan.waypoints.push(Waypoint::new([1.0, 2.0, 3.0], &shape));
        plan.write(&path).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.contains("\"unit_radius\": 0.15,"), "{text}");
        assert!(text.contains("\"link_length\": 0.5,"), "{text}");
        // Every shape angle is the shortest decimal of its f32: at most 9 digits.
        for w in &plan.waypoints {
            for &v in w.eta() {
                assert_eq!(f32_decimal(v as f32), v);
                assert_eq!(v as f32, v as f32 as f64 as f32);
            }
        }
        assert!(text.contains("0.1,"), "{text}");
        assert!(!text.contains("0.100000001"), "{text}");
    }

    #[test]
    fn f32_decimals_read_back_as_the_same_f32() {
        // Readers narrow plan values to f32 (`as f32`): that must give the core's value.
        let mut s: u32 = 1;
        for _ in 0..1_000_000 {
            s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            let x = f32::from_bits(s);
            if x.is_finite() {
                assert_eq!(f32_decimal(x) as f32, x, "{x:e}");
            }
        }
        for x in [
            0.15f32,
            0.01,
            0.5,
            std::f32::consts::FRAC_PI_3,
            -std::f32::consts::PI,
            1e-8,
            0.0,
        ] {
            assert_eq!(f32_decimal(x) as f32, x);
        }
    }

    #[test]
    fn the_map_source_is_recorded_and_optional() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.json");
        let mut plan = sample();
        plan.map.source = MapSource::file(Path::new("maps/abc.bt"), b"abc");
        plan.write(&path).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.contains("\"file\": \"abc.bt\""), "{text}");
        // SHA-256("abc"), FIPS 180-2's first example.
        assert!(text.contains(
            "\"sha256\": \"ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad\""
        ));
        assert_eq!(Plan::read(&path).unwrap(), plan);
        // A plan without the fields (written before they existed) still reads.
        let old = text
            .lines()
            .filter(|l| !l.contains("\"file\"") && !l.contains("\"sha256\""))
            .collect::<Vec<_>>()
            .join("\n")
            .replace(
                "\"unknown_is_occupied\": true,",
                "\"unknown_is_occupied\": true",
            );
        std::fs::write(&path, old).unwrap();
        assert_eq!(Plan::read(&path).unwrap().map.source, MapSource::default());
        let window = MapSource::scenario("window");
        assert!(window.differs_from(&MapSource::scenario("maze")));
        assert!(window.differs_from(&plan.map.source));
        assert!(!window.differs_from(&MapSource::default()));
        assert!(!plan.map.source.differs_from(&plan.map.source.clone()));
    }

    #[test]
    fn bad_plans_are_named() {
        let mut plan = sample();
        plan.waypoints[0].zeta.pop();
        assert!(plan
            .check()
            .unwrap_err()
            .to_string()
            .contains("waypoints[0].zeta has 7 numbers"));
        let mut plan = sample();
        plan.format = "x".into();
        assert!(plan.check().unwrap_err().to_string().contains("format"));
        let mut plan = sample();
        plan.chain.units = 40;
        assert!(plan
            .check()
            .unwrap_err()
            .to_string()
            .contains("chain.units = 40"));
    }
}
