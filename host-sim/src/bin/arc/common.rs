//! Arguments and loading shared by the commands that work on a map.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use aerial_chain_core::lsc::{library, LscKind};
use aerial_chain_core::params::ParamError;
use aerial_chain_core::{ChainParams, Shape};
use clap::Args;

use super::{checks, CliError};
use aerial_chain::collision::CollisionContext;
use aerial_chain::map::DistanceField;
use aerial_chain::map::Grid;
use aerial_chain::map::OcTree;
use aerial_chain::plan_file::{MapSection, MapSource, Plan};
use aerial_chain::planner::Query;
use aerial_chain::problem::scenarios::{self, Scenario};

/// Chain geometry options shared by every command that makes a chain.
#[derive(Args, Debug, Clone)]
pub struct ChainArgs {
    /// Number of units N (2..=16).
    #[arg(long, short = 'n')]
    pub units: Option<u8>,
    /// Link length l (m).
    #[arg(long, default_value_t = aerial_chain_core::ChainParams::DEFAULT_LINK_LENGTH)]
    pub link_length: f32,
    /// Unit collision sphere radius r_u (m).
    #[arg(long, default_value_t = aerial_chain_core::ChainParams::DEFAULT_UNIT_RADIUS)]
    pub unit_radius: f32,
    /// Link capsule radius r_l (m).
    #[arg(long, default_value_t = aerial_chain_core::ChainParams::DEFAULT_LINK_RADIUS)]
    pub link_radius: f32,
    /// Pitch limit theta_max (degrees).
    #[arg(long, default_value_t = 60.0)]
    pub theta_max_deg: f32,
    /// Bend limit beta_max (degrees).
    #[arg(long, default_value_t = 120.0)]
    pub beta_max_deg: f32,
}

impl ChainArgs {
    /// Validated chain parameters, with `default_units` when `--units` is absent.
    pub fn params(&self, default_units: u8) -> Result<aerial_chain_core::ChainParams, CliError> {
        let units = self.units.unwrap_or(default_units);
        if self.link_length.is_nan() || self.link_length > checks::MAX_LINK_LENGTH_M {
            return Err(checks::bad(
                "--link-length",
                self.link_length,
                &format!(
                    "a positive length up to {} m (the core's f32 geometry keeps \
                     sub-millimetre precision up to there)",
                    checks::MAX_LINK_LENGTH_M
                ),
            ));
        }
        aerial_chain_core::ChainParams {
            units,
            link_length: self.link_length,
            unit_radius: self.unit_radius,
            link_radius: self.link_radius,
            theta_max: aerial_chain_core::angle::deg(self.theta_max_deg),
            beta_max: aerial_chain_core::angle::deg(self.beta_max_deg),
        }
        .validate()
        .map_err(|e| self.param_error(units, e))
    }

    /// The flag behind a chain parameter the core refused, its value and its limit.
    fn param_error(&self, units: u8, e: ParamError) -> CliError {
        match e {
            ParamError::UnitsOutOfRange => checks::bad("--units", units, "between 2 and 16"),
            ParamError::LinkLength => {
                checks::bad("--link-length", self.link_length, "a positive length (m)")
            }
            ParamError::UnitRadius => {
                checks::bad("--unit-radius", self.unit_radius, "a positive length (m)")
            }
            ParamError::LinkRadius => checks::bad(
                "--link-radius",
                self.link_radius,
                &format!("positive and below --unit-radius {}", self.unit_radius),
            ),
            ParamError::UnitsOverlap => checks::bad(
                "--unit-radius",
                self.unit_radius,
                &format!(
                    "below half of --link-length {} (neighbouring units would overlap)",
                    self.link_length
                ),
            ),
            ParamError::ThetaMax => {
                checks::bad("--theta-max-deg", self.theta_max_deg, "in (0, 90) degrees")
            }
            ParamError::BetaMax => {
                checks::bad("--beta-max-deg", self.beta_max_deg, "in (0, 180] degrees")
            }
        }
    }
}

/// Where the map comes from: an OctoMap file or a built-in scenario (one of the two;
/// a missing map names both).
#[derive(Args, Debug, Clone)]
#[command(group(clap::ArgGroup::new("map_source").required(true).args(["map", "scenario"])))]
pub struct MapArgs {
    /// OctoMap binary tree (.bt) to work on.
    #[arg(long, conflicts_with = "scenario")]
    pub map: Option<PathBuf>,
    /// Built-in scenario: window, maze, silos, corridor, corridor:LENGTH, a family instance
    /// (passage:, forest:, slot:, pipe: or shaft:KEY=VALUE,...) or the large generated maps
    /// campus, campus:RES, hall and hall:RES.
    #[arg(long)]
    pub scenario: Option<String>,
    /// Treat unknown space as free (the default treats it as occupied).
    #[arg(long)]
    pub unknown_free: bool,
}

/// Why a plan cannot be trusted under the user's assumptions: it was made with
/// unknown space free, and the user did not say `--unknown-free`. The checker's
/// assumptions come from the person running it, never from the file under test.
pub fn looser_assumption(plan: &aerial_chain::plan_file::Plan, map: &MapArgs) -> Option<String> {
    (!plan.map.unknown_is_occupied && !map.unknown_free).then(|| {
        "the plan was made with unknown space free (map.unknown_is_occupied: false), \
         but it is checked with unknown space occupied; give --unknown-free to check it \
         under the plan's assumption"
            .to_string()
    })
}

/// A loaded map, and the scenario it came from if any.
pub struct LoadedMap {
    /// The occupancy grid (with the user's unknown-space choice applied).
    pub grid: Grid,
    /// The scenario, when the map is a built-in one.
    pub scenario: Option<Scenario>,
    /// Which map this is, as plans record it (file name and hash, or scenario).
    pub source: MapSource,
}

impl MapArgs {
    /// Loads the map: the file is read and checked, or the scenario generated.
    pub fn load(&self) -> Result<LoadedMap, CliError> {
        if let Some(name) = &self.scenario {
            let sc = scenarios::build(name)
                .map_err(|e| CliError::input(format!("--scenario {name}: {e}")))?;
            let mut grid = sc.grid.clone();
            grid.set_unknown_is_occupied(!self.unknown_free);
            return Ok(LoadedMap {
                grid,
                scenario: Some(sc),
                source: MapSource::scenario(name),
            });
        }
        let path = self
            .map
            .as_ref()
            .ok_or_else(|| CliError::input("give --map FILE.bt or --scenario NAME"))?;
        // Read once: the bytes give both the tree and the hash a plan records.
        let bytes = std::fs::read(path).map_err(|e| {
            CliError::input(format!("{}: cannot read the file: {e}", path.display()))
        })?;
        let tree = OcTree::from_bt_bytes(&bytes, &path.display().to_string())
            .map_err(|e| CliError::input(e.to_string()))?;
        let grid = Grid::from_octree(&tree, !self.unknown_free)
            .map_err(|e| CliError::input(format!("{}: {e}", path.display())))?;
        Ok(LoadedMap {
            grid,
            scenario: None,
            source: MapSource::file(path, &bytes),
        })
    }

    /// The map's name for messages and titles.
    pub fn name(&self) -> String {
        match (&self.scenario, &self.map) {
            (Some(s), _) => format!("scenario {s}"),
            (None, Some(p)) => p.display().to_string(),
            (None, None) => "map".into(),
        }
    }
}

impl LoadedMap {
    /// The collision context of the chain `params` with `clearance` on this map; its
    /// distance field keeps the grid.
    pub fn into_context(
        self,
        params: ChainParams,
        clearance: f64,
    ) -> Result<CollisionContext, CliError> {
        let field = Arc::new(DistanceField::new(self.grid));
        CollisionContext::new(field, params, clearance).map_err(|e| CliError::input(e.to_string()))
    }
}

/// Where a command's report lines go: standard output, unless that carries the
/// command's data (`--out -`); then standard error, so the data stays clean.
pub struct Report {
    to_stderr: bool,
}

impl Report {
    /// The report of a command that writes its data to `out`.
    pub fn new(out: &std::path::Path) -> Self {
        Self {
            to_stderr: crate::fsutil::is_stdio(out),
        }
    }

    /// Prints one line.
    pub fn line(&self, args: std::fmt::Arguments<'_>) {
        if self.to_stderr {
            eprintln!("{args}");
        } else {
            println!("{args}");
        }
    }
}

/// A planning problem from the command line: the map, the chain, the query and how
/// close to the goal the head must end.
#[derive(Args, Debug, Clone)]
pub struct ProblemArgs {
    #[command(flatten)]
    pub map: MapArgs,
    #[command(flatten)]
    pub chain: ChainArgs,
    #[command(flatten)]
    pub query: QueryArgs,
    /// Goal tolerance for the head (m).
    #[arg(long, default_value_t = 0.3)]
    pub goal_tol: f64,
}

impl ProblemArgs {
    /// Loads the map, then resolves the chain and the query on it
    /// ([`QueryArgs::resolve`]).
    pub fn load(&self) -> Result<(LoadedMap, ChainParams, Query), CliError> {
        let loaded = self.map.load()?;
        let (params, query) =
            self.query
                .resolve(&self.chain, loaded.scenario.as_ref(), self.goal_tol)?;
        Ok((loaded, params, query))
    }

    /// Loads the problem ([`Self::load`]) for a planner: the collision context at
    /// `clearance` (the map inside it), the chain, the query, and the map as plans
    /// record it.
    pub fn context(
        &self,
        clearance: f64,
    ) -> Result<(CollisionContext, ChainParams, Query, MapSection), CliError> {
        let (loaded, params, query) = self.load()?;
        let map = MapSection::of(&loaded.grid).with_source(loaded.source.clone());
        let ctx = loaded.into_context(params, clearance)?;
        Ok((ctx, params, query, map))
    }
}

/// Writes `plan` to `out` and opens the report that follows it with a line naming the
/// file, then `solved`, the map, the chain size and the number of waypoints, then
/// `details`.
pub fn write_plan(
    plan: &Plan,
    out: &Path,
    solved: &str,
    map: &MapArgs,
    details: &str,
) -> Result<Report, CliError> {
    plan.write(out)
        .map_err(|e| CliError::input(e.to_string()))?;
    // With `--out -` the plan is standard output; the report goes to standard error.
    let report = Report::new(out);
    report.line(format_args!(
        "{}: {solved} {} with N = {}: {} waypoints, {details}",
        crate::fsutil::output_name(out),
        map.name(),
        plan.chain.units,
        plan.waypoints.len()
    ));
    Ok(report)
}

/// Where a query starts and ends; a scenario supplies what is not given.
#[derive(Args, Debug, Clone)]
pub struct QueryArgs {
    /// Head start position x,y,z (m); a scenario has its own.
    #[arg(long, value_parser = parse_point, allow_hyphen_values = true)]
    pub start: Option<[f64; 3]>,
    /// Start yaw (degrees); a scenario has its own.
    #[arg(long, allow_hyphen_values = true)]
    pub start_yaw_deg: Option<f64>,
    /// Start shape: a library name (LI, SE, SM, SV, CA, PN) turned to the start yaw.
    #[arg(long, default_value = "LI")]
    pub start_shape: String,
    /// Head goal position x,y,z (m); a scenario has its own.
    #[arg(long, value_parser = parse_point, allow_hyphen_values = true)]
    pub goal: Option<[f64; 3]>,
}

impl QueryArgs {
    /// The chain (validated) and the query to within `goal_tol` of the goal, with the
    /// scenario's chain size, start, yaw and goal where not given.
    pub fn resolve(
        &self,
        chain: &ChainArgs,
        sc: Option<&Scenario>,
        goal_tol: f64,
    ) -> Result<(ChainParams, Query), CliError> {
        let units = chain
            .units
            .or(sc.map(|s| s.default_units))
            .ok_or_else(|| CliError::input("--units is required with --map"))?;
        let params = chain.params(units)?;
        let start = self
            .start
            .or(sc.map(|s| s.start.into()))
            .ok_or_else(|| CliError::input("--start is required with --map"))?;
        let goal = self
            .goal
            .or(sc.map(|s| s.goal.into()))
            .ok_or_else(|| CliError::input("--goal is required with --map"))?;
        if let Some(d) = self.start_yaw_deg {
            // The shape holds angles as f32.
            if !(d.to_radians() as f32).is_finite() {
                return Err(checks::bad(
                    "--start-yaw-deg",
                    d,
                    "a finite angle (degrees)",
                ));
            }
        }
        let yaw = self
            .start_yaw_deg
            .map(f64::to_radians)
            .or(sc.map(|s| s.start_yaw))
            .unwrap_or(0.0);
        let shape = start_shape(&params, &self.start_shape, yaw as f32)?;
        let query = Query {
            start: start.into(),
            start_shape: shape,
            goal: goal.into(),
            goal_tol,
        };
        Ok((params, query))
    }
}

/// The start shape: a library shape turned so the head looks along `yaw`.
pub fn start_shape(params: &ChainParams, name: &str, yaw: f32) -> Result<Shape, CliError> {
    let kind = LscKind::from_name(name).ok_or_else(|| {
        CliError::input(format!(
            "--start-shape {name}: not one of LI SE SM SV CA PN"
        ))
    })?;
    let lib = library(params);
    let e = lib.get(kind).ok_or_else(|| {
        CliError::input(format!(
            "--start-shape {name}: not in the library for N = {}",
            params.units
        ))
    })?;
    Ok(e.shape
        .rotated(aerial_chain_core::angle::diff(e.shape.head_yaw(), yaw)))
}

/// The motion `arc sim` flies and `arc verify` checks: a plan, or a trajectory in its
/// place. Exactly one of the two is given.
#[derive(Args, Debug)]
#[group(required = true, multiple = false)]
pub struct MotionArgs {
    /// The plan (JSON, arc-plan/1); `-` reads it from standard input.
    #[arg(long)]
    plan: Option<PathBuf>,
    /// A trajectory instead of a plan (JSON, arc-trajectory/1), taken with its own
    /// timing (the chain moves linearly between its samples); `-` reads it from
    /// standard input.
    #[arg(long)]
    trajectory: Option<PathBuf>,
}

/// The file given to [`MotionArgs`].
pub enum MotionFile<'a> {
    /// A plan (arc-plan/1).
    Plan(&'a Path),
    /// A trajectory (arc-trajectory/1).
    Trajectory(&'a Path),
}

impl MotionArgs {
    /// The one file given (clap refuses both and neither).
    pub fn file(&self) -> Result<MotionFile<'_>, CliError> {
        match (&self.plan, &self.trajectory) {
            (Some(p), None) => Ok(MotionFile::Plan(p)),
            (None, Some(t)) => Ok(MotionFile::Trajectory(t)),
            _ => Err(CliError::input("give --plan or --trajectory")),
        }
    }
}

/// Reads a plan file (`-`: standard input) and checks it: the plan, its name for
/// messages, and its chain's parameters.
pub fn read_plan(
    path: &std::path::Path,
) -> Result<(aerial_chain::plan_file::Plan, String, ChainParams), CliError> {
    let plan =
        aerial_chain::plan_file::Plan::read(path).map_err(|e| CliError::input(e.to_string()))?;
    let name = crate::fsutil::input_name(path);
    let params = plan
        .check()
        .map_err(|e| CliError::input(format!("{name}: {e}")))?;
    Ok((plan, name, params))
}

/// Parses `x,y,z`.
pub fn parse_point(s: &str) -> Result<[f64; 3], String> {
    let v: Vec<&str> = s.split(',').map(str::trim).collect();
    if v.len() != 3 {
        return Err(format!("expected x,y,z (three numbers), got {s:?}"));
    }
    let mut p = [0.0; 3];
    for (slot, t) in p.iter_mut().zip(&v) {
        *slot = t
            .parse::<f64>()
            .map_err(|_| format!("{t:?} in {s:?} is not a number"))?;
        if !slot.is_finite() {
            return Err(format!("{t:?} in {s:?} is not finite"));
        }
    }
    Ok(p)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_parse_or_say_why() {
        assert_eq!(parse_point("1, -2.5,3").unwrap(), [1.0, -2.5, 3.0]);
        assert!(parse_point("1,2").unwrap_err().contains("three numbers"));
        assert!(parse_point("1,x,2").unwrap_err().contains("\"x\""));
        assert!(parse_point("1,inf,2").unwrap_err().contains("not finite"));
    }
}

/// The yaw and shape a plan must end in (`arc plan`, `arc verify`).
#[derive(Args, Debug, Clone)]
pub struct GoalPoseArgs {
    /// The head's yaw at the goal (degrees): the plan ends in it.
    #[arg(long, allow_hyphen_values = true)]
    pub goal_yaw_deg: Option<f64>,
    /// The shape at the goal: a library name (LI, SE, SM, SV, CA, PN) or 2N - 1 angles
    /// `a,b,...` (rad: head yaw, then every link's pitch and yaw); without
    /// --goal-yaw-deg it matches at any heading.
    #[arg(long)]
    pub goal_shape: Option<String>,
}

impl GoalPoseArgs {
    /// The pose for the chain `params`, each flag checked.
    pub fn pose(&self, params: &ChainParams) -> Result<aerial_chain::goal::GoalPose, CliError> {
        if let Some(y) = self.goal_yaw_deg {
            if !(y.is_finite() && y.abs() <= 360.0) {
                return Err(super::checks::bad(
                    "--goal-yaw-deg",
                    y,
                    "degrees within [-360, 360]",
                ));
            }
        }
        let shape = match &self.goal_shape {
            Some(text) => Some(
                aerial_chain::goal::parse_shape(params, text)
                    .map_err(|e| CliError::input(format!("--goal-shape {text}: {e}")))?,
            ),
            None => None,
        };
        Ok(aerial_chain::goal::GoalPose {
            yaw: self.goal_yaw_deg.map(|y| y.to_radians() as f32),
            shape,
        })
    }
}
