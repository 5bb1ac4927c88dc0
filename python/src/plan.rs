//! Planning, plans and their exact check: `plan()` runs the ARCplanner with the
//! defaults of `arc plan`, `Plan` is an `arc-plan/1` file, `verify()` is `arc verify`.

use std::path::PathBuf;
use std::sync::Arc;

use nalgebra::Vector3;
use numpy::ndarray::{Array2, Array3};
use numpy::{IntoPyArray, PyArray2, PyArray3};
use pyo3::prelude::*;

use aerial_chain::collision::{verify_plan, EdgeKind, DEFAULT_CLEARANCE};
use aerial_chain::goal::{parse_shape, GoalPose};
use aerial_chain::map::DistanceField;
use aerial_chain::mission::Mission;
use aerial_chain::plan_file::MapSection;
use aerial_chain::planner::{Query, Settings};
use aerial_chain::planning::{
    self, PlanOptions, PlanningError, Request, DEFAULT_TIME_LIMIT_S, MAX_TIME_LIMIT_S,
};
use aerial_chain_core::kinematics::positions_into;
use aerial_chain_core::{ChainParams, Shape, MAX_UNITS};

use crate::map::Map;
use crate::{err, json_to_py, PlanError, VerifyError};

/// A plan: waypoints of the chain (`arc-plan/1`, docs/model.md "Plans"), the start
/// first; consecutive waypoints are edges (a translation or a shape change).
///
/// `Plan.read(path)`, `Plan.from_json(text)`, or made by `plan()`.
#[pyclass(module = "aerial_chain", frozen)]
pub struct Plan {
    /// The plan as the library holds it (checked).
    pub(crate) plan: aerial_chain::plan_file::Plan,
    /// Its chain.
    pub(crate) params: ChainParams,
}

impl Plan {
    /// Wraps a plan after checking the format rules that need no map.
    pub(crate) fn checked(plan: aerial_chain::plan_file::Plan) -> PyResult<Self> {
        let params = plan.check().map_err(err::<PlanError>)?;
        Ok(Plan { plan, params })
    }
}

#[pymethods]
impl Plan {
    /// Reads and checks a plan file. Raises `PlanError` naming the file and the field.
    #[staticmethod]
    fn read(path: PathBuf) -> PyResult<Self> {
        Self::checked(aerial_chain::plan_file::Plan::read(&path).map_err(err::<PlanError>)?)
    }

    /// Parses and checks a plan's JSON text.
    #[staticmethod]
    #[pyo3(signature = (text, name = "<plan>"))]
    fn from_json(text: &str, name: &str) -> PyResult<Self> {
        Self::checked(aerial_chain::plan_file::Plan::parse(text, name).map_err(err::<PlanError>)?)
    }

    /// Writes the plan file (pretty JSON, atomically).
    fn write(&self, path: PathBuf) -> PyResult<()> {
        self.plan.write(&path).map_err(err::<PlanError>)
    }

    /// The plan as JSON text.
    fn to_json(&self) -> String {
        serde_json::to_string_pretty(&self.plan).expect("a plan always serialises")
    }

    /// Number of units N.
    #[getter]
    fn units(&self) -> usize {
        self.params.n()
    }

    /// The chain section: units, link_length, unit_radius, link_radius, theta_max,
    /// beta_max (m, rad).
    #[getter]
    fn chain<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.plan.chain)
    }

    /// The map section: resolution, unknown_is_occupied and the map's source.
    #[getter]
    fn map<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.plan.map)
    }

    /// The planner's statistics (counts, timings in seconds, quality).
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.plan.stats)
    }

    /// Every waypoint's configuration zeta, a `(W, 2N + 2)` array:
    /// `[x1, y1, z1, psi1_r, theta_1, psi_1, ..., theta_{N-1}, psi_{N-1}]` (m, rad).
    #[getter]
    fn waypoints<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let dim = 2 * self.params.n() + 2;
        let zeta: Vec<f64> = self
            .plan
            .waypoints
            .iter()
            .flat_map(|w| w.zeta.clone())
            .collect();
        Array2::from_shape_vec((self.plan.waypoints.len(), dim), zeta)
            .expect("checked plan: 2N + 2 numbers per waypoint")
            .into_pyarray(py)
    }

    /// The head position of every waypoint, a `(W, 3)` array (m).
    #[getter]
    fn heads<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let xi: Vec<f64> = self.plan.waypoints.iter().flat_map(|w| w.xi()).collect();
        Array2::from_shape_vec((self.plan.waypoints.len(), 3), xi)
            .expect("three numbers per head")
            .into_pyarray(py)
    }

    /// Every unit's centre at every waypoint, a `(W, N, 3)` array (m, head first), by
    /// the core's forward kinematics in double precision (as the verifier computes them).
    fn unit_positions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f64>> {
        let n = self.params.n();
        let l = f64::from(self.params.link_length);
        let mut out = Vec::with_capacity(self.plan.waypoints.len() * n * 3);
        let mut units = [Vector3::<f64>::zeros(); MAX_UNITS];
        for w in &self.plan.waypoints {
            positions_into(l, Vector3::from(w.xi()), w.eta(), &mut units);
            out.extend(units[..n].iter().flat_map(|p| [p.x, p.y, p.z]));
        }
        Array3::from_shape_vec((self.plan.waypoints.len(), n, 3), out)
            .expect("N units of three numbers per waypoint")
            .into_pyarray(py)
    }

    fn __len__(&self) -> usize {
        self.plan.waypoints.len()
    }

    fn __repr__(&self) -> String {
        format!(
            "Plan(N = {}, {} waypoints, map {})",
            self.params.n(),
            self.plan.waypoints.len(),
            self.plan.map.source
        )
    }
}

/// What the exact verifier found (`arc verify`).
#[pyclass(module = "aerial_chain", frozen, get_all)]
pub struct VerifyReport {
    /// True when every waypoint and every sample of every edge is valid, the plan was
    /// checked under its own assumption about unknown space or a stricter one, and it
    /// starts and ends where asked.
    ok: bool,
    /// Why the plan is INVALID (`None` when valid).
    violation: Option<String>,
    /// Configurations tested.
    samples: usize,
    /// Smallest clearance of any body to the map over the valid samples (m).
    min_clearance: f64,
    /// Where that clearance was found.
    min_clearance_at: Option<String>,
    /// The kind of every edge: `translation`, `shape_change`, `stay` or `both`.
    edges: Vec<&'static str>,
    /// Remarks: another map than the plan's, a different unknown-space assumption.
    notes: Vec<String>,
}

#[pymethods]
impl VerifyReport {
    fn __repr__(&self) -> String {
        match &self.violation {
            None => format!(
                "VerifyReport(VALID, {} samples, min clearance {:.4} m)",
                self.samples, self.min_clearance
            ),
            Some(v) => format!("VerifyReport(INVALID: {v})"),
        }
    }
}

/// The first thing that makes `plan` INVALID on `map` beyond the exact test: a looser
/// assumption about unknown space, a start or an end elsewhere than asked.
fn query_violation(
    map: &Map,
    plan: &aerial_chain::plan_file::Plan,
    start: Option<[f64; 3]>,
    goal: Option<[f64; 3]>,
    goal_tol: f64,
) -> Option<String> {
    if !plan.map.unknown_is_occupied && map.grid.unknown_is_occupied() {
        return Some(
            "the plan was made with unknown space free, but the map takes it as occupied; \
             load the map with unknown_free=True to check it under the plan's assumption"
                .into(),
        );
    }
    let dist = |a: [f64; 3], b: [f64; 3]| (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f64>().sqrt();
    let first = plan.waypoints[0].xi();
    let last = plan.waypoints[plan.waypoints.len() - 1].xi();
    let sc = map.scenario.as_ref();
    if let Some(s) = start.or(sc.map(|s| s.start.coords.into())) {
        if dist(first, s) > 1e-6 {
            return Some(format!("waypoint 0 head {first:?} is not the start {s:?}"));
        }
    }
    if let Some(g) = goal.or(sc.map(|s| s.goal.coords.into())) {
        let d = dist(last, g);
        if d.is_nan() || d > goal_tol {
            return Some(format!(
                "last head {last:?} is {d:.3} m from the goal {g:?} (tolerance {goal_tol} m)"
            ));
        }
    }
    None
}

/// Checks `plan` on `map` with the exact verifier of docs/model.md (`arc verify`):
/// every waypoint and every sampled configuration of every edge, then that it starts at
/// `start` and ends within `goal_tol` of `goal` (a scenario's own when not given).
/// Raises `VerifyError` saying why when the plan is INVALID, unless `strict=False`:
/// then the report says it (`ok`, `violation`).
#[pyfunction]
#[pyo3(signature = (map, plan, start = None, goal = None, goal_tol = 0.3, strict = true))]
pub fn verify(
    py: Python<'_>,
    map: &Map,
    plan: &Plan,
    start: Option<[f64; 3]>,
    goal: Option<[f64; 3]>,
    goal_tol: f64,
    strict: bool,
) -> PyResult<VerifyReport> {
    if !(goal_tol.is_finite() && goal_tol >= 0.0) {
        return Err(err::<VerifyError>(format!(
            "goal_tol = {goal_tol}: a length of at least 0 m"
        )));
    }
    let r = py.detach(|| verify_plan(&map.grid, &plan.plan));
    let violation = match &r.violation {
        Some(v) => Some(v.to_string()),
        None if !r.ok => Some("INVALID".to_string()),
        None => query_violation(map, &plan.plan, start, goal, goal_tol),
    };
    if let (true, Some(v)) = (strict, &violation) {
        return Err(err::<VerifyError>(format!("{}: INVALID: {v}", map.name)));
    }
    let kind = |e: &EdgeKind| match e {
        EdgeKind::Stay => "stay",
        EdgeKind::Translation => "translation",
        EdgeKind::ShapeChange => "shape_change",
        EdgeKind::Both => "both",
    };
    Ok(VerifyReport {
        ok: violation.is_none(),
        violation,
        samples: r.samples,
        min_clearance: r.min_clearance,
        min_clearance_at: r
            .min_clearance_at
            .map(|(site, body)| format!("{body} at {site}")),
        edges: r.edges.iter().map(kind).collect(),
        notes: r.notes,
    })
}

/// The chain of `units` units with the docs/model.md defaults, or `PlanError`.
pub(crate) fn chain(units: i64) -> PyResult<ChainParams> {
    let n = u8::try_from(units)
        .ok()
        .filter(|n| (2..=MAX_UNITS as u8).contains(n))
        .ok_or_else(|| err::<PlanError>(format!("units = {units} is outside 2..=16")))?;
    ChainParams::new(n)
        .validate()
        .map_err(|e| err::<PlanError>(format!("units = {units}: {e}")))
}

/// What the caller of `plan()` gave of the query; the rest comes from the scenario.
pub(crate) struct Asked {
    pub(crate) start: Option<[f64; 3]>,
    pub(crate) goal: Option<[f64; 3]>,
    pub(crate) start_yaw: Option<f64>,
    pub(crate) start_shape: Option<Vec<f32>>,
    pub(crate) goal_tol: f64,
}

/// The chain of `units` units (default: the scenario's) and the query `asked` on
/// `map`, as `explore()` and `OnlinePlanner` take them.
pub(crate) fn chain_and_query(
    map: &Map,
    units: Option<i64>,
    asked: Asked,
) -> PyResult<(ChainParams, Query)> {
    let units = units
        .or(map.scenario.as_ref().map(|s| i64::from(s.default_units)))
        .ok_or_else(|| err::<PlanError>("units is required with a map file"))?;
    let params = chain(units)?;
    let query = query(map, &params, asked)?;
    Ok((params, query))
}

/// The query: the scenario's start, yaw, goal where not given; the start shape as
/// given (2N - 1 angles) or the straight line behind the head at the start yaw.
pub(crate) fn query(map: &Map, params: &ChainParams, asked: Asked) -> PyResult<Query> {
    let Asked {
        start,
        goal,
        start_yaw,
        start_shape,
        goal_tol,
    } = asked;
    let sc = map.scenario.as_ref();
    let need = |what: &str| err::<PlanError>(format!("{what} is required with a map file"));
    let start = start
        .or(sc.map(|s| s.start.coords.into()))
        .ok_or_else(|| need("start"))?;
    let goal = goal
        .or(sc.map(|s| s.goal.coords.into()))
        .ok_or_else(|| need("goal"))?;
    let yaw = start_yaw.or(sc.map(|s| s.start_yaw)).unwrap_or(0.0) as f32;
    if !yaw.is_finite() {
        return Err(err::<PlanError>(format!(
            "start_yaw = {yaw}: a finite angle (rad)"
        )));
    }
    if !(goal_tol.is_finite() && goal_tol >= 0.0) {
        return Err(err::<PlanError>(format!(
            "goal_tol = {goal_tol}: a length of at least 0 m"
        )));
    }
    let shape = match start_shape {
        Some(eta) => Shape::from_slice(params.units, &eta).map_err(|e| {
            err::<PlanError>(format!(
                "start_shape ({} angles): {e:?}; expected {} finite angles for N = {}",
                eta.len(),
                2 * params.n() - 1,
                params.n()
            ))
        })?,
        None => Shape::line(params.units, yaw),
    };
    Ok(Query {
        start: start.into(),
        start_shape: shape,
        goal: goal.into(),
        goal_tol,
    })
}

/// Plans on `map` with the ARCplanner and the defaults of `arc plan` (the library's
/// facade `aerial_chain::planning::plan`: shape tables of `srs` random shapes,
/// `Settings::default()`, post-processing on, a time limit of 60 s), for a chain of
/// `units` (default: the scenario's). `start`, `goal` (m) and `start_yaw` (rad)
/// default to the scenario's; `start_shape` is 2N - 1 angles (default: straight
/// behind the head); `time_limit=None` plans without a limit. `goal_yaw` (rad) and
/// `goal_shape` (a library name such as `"PN"`, or 2N - 1 angles) end the plan in that
/// configuration (docs/model.md, "Goal configurations"); `mission`, the path of an
/// `arc-mission/1` file, plans through its goals instead of to `goal`.
/// Raises `PlanError` for bad input and when no plan is found (the message says why).
#[pyfunction]
#[pyo3(signature = (
    map, units = None, start = None, goal = None, start_yaw = None, start_shape = None,
    goal_tol = 0.3, seed = 1, srs = 500, srs_seed = 1, clearance = DEFAULT_CLEARANCE,
    time_limit = Some(DEFAULT_TIME_LIMIT_S), smooth = true, goal_yaw = None,
    goal_shape = None, mission = None
))]
#[allow(clippy::too_many_arguments)] // Python keyword arguments, each with a default.
pub fn plan(
    py: Python<'_>,
    map: &Map,
    units: Option<i64>,
    start: Option<[f64; 3]>,
    goal: Option<[f64; 3]>,
    start_yaw: Option<f64>,
    start_shape: Option<Vec<f32>>,
    goal_tol: f64,
    seed: u64,
    srs: usize,
    srs_seed: u64,
    clearance: f64,
    time_limit: Option<f64>,
    smooth: bool,
    goal_yaw: Option<f64>,
    goal_shape: Option<Bound<'_, PyAny>>,
    mission: Option<PathBuf>,
) -> PyResult<Plan> {
    let mission = match &mission {
        Some(p) => Some(Mission::read(p).map_err(err::<PlanError>)?),
        None => None,
    };
    let units = units
        .or(mission.as_ref().and_then(|m| m.units).map(i64::from))
        .or(map.scenario.as_ref().map(|s| i64::from(s.default_units)))
        .ok_or_else(|| err::<PlanError>("units is required with a map file"))?;
    let params = chain(units)?;
    let goal = match &mission {
        Some(m) => Some(m.goals[0].position),
        None => goal,
    };
    let asked = Asked {
        start,
        goal,
        start_yaw,
        start_shape,
        goal_tol,
    };
    let query = query(map, &params, asked)?;
    let options = PlanOptions {
        planner: Settings {
            seed,
            ..Settings::default()
        },
        refine: Default::default(),
        clearance,
        no_smooth: !smooth,
        time_limit_s: time_limit,
        srs,
        srs_seed,
        trajectory: None,
    };
    // Only a given limit can be refused.
    let limit = time_limit.unwrap_or(DEFAULT_TIME_LIMIT_S);
    options.termination().map_err(|_| {
        err::<PlanError>(format!(
            "time_limit = {limit}: a positive time (s), at most {MAX_TIME_LIMIT_S:e}"
        ))
    })?;
    let pose = goal_pose(&params, goal_yaw, goal_shape)?;
    let mut request = Request {
        field: Arc::new(DistanceField::new(map.grid.clone())),
        params,
        query,
        pose,
        map: MapSection::of(&map.grid).with_source(map.source.clone()),
    };
    if let Some(m) = &mission {
        if let Some((at, shape)) = m.start_of(&params).map_err(err::<PlanError>)? {
            request.query.start = at;
            request.query.start_shape = shape;
        }
        let planned = py.detach(|| planning::plan_mission(&request, m, None, &options));
        let planned = planned.map_err(|e| err::<PlanError>(format!("{}: {e}", map.name)))?;
        return Plan::checked(planned.plan);
    }
    let planned = py.detach(|| planning::plan(&request, None, &options));
    let planned = planned.map_err(|e| match e {
        PlanningError::NoPlan(_) => err::<PlanError>(format!("{}: {e}", map.name)),
        e => err::<PlanError>(e.to_string()),
    })?;
    Plan::checked(planned.plan)
}

/// The goal's yaw and shape from `plan()`'s `goal_yaw` (rad) and `goal_shape` (a
/// library name or a sequence of 2N - 1 angles).
fn goal_pose(
    params: &ChainParams,
    yaw: Option<f64>,
    shape: Option<Bound<'_, PyAny>>,
) -> PyResult<GoalPose> {
    if let Some(y) = yaw.filter(|y| !y.is_finite()) {
        return Err(err::<PlanError>(format!(
            "goal_yaw = {y}: a finite angle (rad)"
        )));
    }
    let shape = match shape {
        None => None,
        Some(s) => {
            let text = match s.extract::<String>() {
                Ok(name) => name,
                Err(_) => s
                    .extract::<Vec<f64>>()
                    .map_err(|_| {
                        err::<PlanError>("goal_shape: a library name or a list of angles")
                    })?
                    .iter()
                    .map(f64::to_string)
                    .collect::<Vec<_>>()
                    .join(","),
            };
            Some(
                parse_shape(params, &text)
                    .map_err(|e| err::<PlanError>(format!("goal_shape: {e}")))?,
            )
        }
    };
    Ok(GoalPose {
        yaw: yaw.map(|y| y as f32),
        shape,
    })
}
