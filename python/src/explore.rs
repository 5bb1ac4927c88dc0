//! `explore()`: the chain flown into the unknown as `arc explore` flies it (the library's
//! `aerial_chain::online::explore`): the map is read only by the units' simulated
//! sensors, the online planner plans from what they saw, the simulated chain flies what
//! it commits. The result is an `Exploration`: the flight, the committed pieces as one
//! plan, the record of every replan and the map the sensors drew.

use std::path::PathBuf;
use std::sync::atomic::AtomicUsize;

use aerial_chain_core::ChainParams;
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::prelude::*;

use aerial_chain::flying::FlyOptions;
use aerial_chain::online::{self, ExploreEnd, ExploreError as Refused, ExploreSettings};
use aerial_chain::plan_file::{ChainSection, MapSection, Waypoint};
use aerial_chain::planning::PlanOptions;
use aerial_chain::sensing::{DepthSensor, OccupancyMap, Survey};
use aerial_chain::sim::{FlightFile, FLIGHT_FORMAT};
use aerial_chain::tables::ShapeTables;

use crate::map::Map;
use crate::plan::{chain_and_query, Asked, Plan};
use crate::sim::Flight;
use crate::{err, json_to_py, points_array, ExploreError, SimError};

/// What `explore()` returns: how the run ended, the flight, the committed pieces joined
/// into one plan, the record of every replan (as `arc explore --out` writes it under
/// `explore`) and the map the sensors drew.
#[pyclass(module = "aerial_chain", frozen)]
pub struct Exploration {
    /// How the run ended.
    end: ExploreEnd,
    /// The flight (every step the simulation recorded, one in `record_every`).
    flight: Py<Flight>,
    /// The committed pieces joined into one plan.
    plan: Py<Plan>,
    /// The record of the replans (docs/model.md, "Explorations").
    record: online::ExploreRecord,
    /// The map the sensors drew.
    seen: OccupancyMap,
    /// The world's name, as the flight file records it.
    map_name: String,
}

#[pymethods]
impl Exploration {
    /// True when the chain reached the goal and settled there.
    #[getter]
    fn reached(&self) -> bool {
        self.end.reached()
    }

    /// How the run ended: a dict with `kind` (`reached`, `sealed`, `stuck`,
    /// `time_limit` or `flight_failed`), the simulated time `t` and, but for `reached`,
    /// why.
    #[getter]
    fn end<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.end)
    }

    /// The flight: the chain's states and its report against the true map.
    #[getter]
    fn flight(&self, py: Python<'_>) -> Py<Flight> {
        self.flight.clone_ref(py)
    }

    /// The committed pieces joined into one plan (`arc explore --plan-out`).
    #[getter]
    fn plan(&self, py: Python<'_>) -> Py<Plan> {
        self.plan.clone_ref(py)
    }

    /// Every replan, in order: dicts of the simulated time `t`, the `trigger`, the
    /// `outcome`, the wall time `wall_s`, `voxels_changed`, `committed_m`, `route_m` and
    /// `joined_moving` (docs/model.md, "Explorations").
    #[getter]
    fn replans<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.record.replans)
    }

    /// The summary `arc explore` prints: replans, pieces, replan latency (median, p95,
    /// max, s), field updates, voxels seen.
    #[getter]
    fn summary<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.record.summary)
    }

    /// The map as it grew: `(centres, t)`, the centres (m) of the seen map's occupied
    /// voxels at the end, an `(K, 3)` array in the order they were seen, and the
    /// simulated time each was first seen occupied, an array of `K` (s).
    #[getter]
    #[allow(clippy::type_complexity)] // A pair of NumPy arrays.
    fn seen_growth<'py>(
        &self,
        py: Python<'py>,
    ) -> (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<f64>>) {
        let grew = self.record.seen_occupied.clone().unwrap_or_default();
        let r = grew.resolution;
        let centres = grew
            .voxels
            .iter()
            .map(|v| v.map(|i| (f64::from(i) + 0.5) * r));
        (points_array(py, centres), grew.t.into_pyarray(py))
    }

    /// Voxels of the seen map that are known (free or occupied) at the end.
    #[getter]
    fn voxels_seen(&self) -> usize {
        self.seen.known()
    }

    /// Writes the map the sensors drew as an OctoMap binary tree (`.bt`, as `arc
    /// explore --map-out` writes it). Raises `ExploreError` naming the file.
    fn write_seen(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        py.detach(|| self.seen.write_bt(&path))
            .map_err(|e| err::<ExploreError>(format!("{}: {e}", path.display())))
    }

    /// Writes the flight with the record of every replan (`arc-sim/1`, as `arc explore
    /// --out` writes it; `arc view` shows it). Raises `ExploreError` naming the file.
    fn write(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let flight = self.flight.get();
        let record = serde_json::to_value(&self.record).map_err(err::<ExploreError>)?;
        let file = FlightFile {
            format: FLIGHT_FORMAT.into(),
            plan: "arc explore".into(),
            map: self.map_name.clone(),
            chain: Some(ChainSection::from_params(&flight.params)),
            report: flight.report.clone(),
            record_every: flight.record_every,
            samples: flight.samples.clone(),
            explore: Some(record),
        };
        py.detach(|| file.write(&path))
            .map_err(|e| err::<ExploreError>(format!("{}: {e}", path.display())))
    }

    fn __repr__(&self) -> String {
        let end = self.end.headline();
        let s = &self.record.summary;
        format!(
            "Exploration({end}, {} replans, {} pieces, {} voxels seen)",
            s.replans,
            self.record.pieces,
            self.seen.known()
        )
    }
}

/// The sensor from `sensor`, a dict of the fields of docs/maps.md "Sensing"
/// (`fov_h_deg`, `fov_v_deg`, `min_range`, `max_range`, `resolution_deg`, `mount`,
/// `splay_deg`; left out: the default), as `arc explore --sensor` reads its file.
pub(crate) fn sensor_from(
    py: Python<'_>,
    sensor: Option<Bound<'_, PyAny>>,
) -> PyResult<DepthSensor> {
    let Some(sensor) = sensor else {
        return Ok(DepthSensor::default());
    };
    let text: String = py
        .import("json")?
        .call_method1("dumps", (sensor,))
        .and_then(|t| t.extract())
        .map_err(|e| err::<ExploreError>(format!("sensor: not a dict of numbers: {e}")))?;
    serde_json::from_str(&text).map_err(|e| err::<ExploreError>(format!("sensor: {e}")))
}

/// Flies a chain of `units` (default: the scenario's) into the unknown on `map` as `arc
/// explore` does, with its defaults: `map` is the truth that only the units' simulated
/// sensors read (every unit's `sensor`, a dict of docs/maps.md "Sensing" fields, at
/// `sensor_rate` Hz); the online planner replans from what they saw within `deadline`
/// wall seconds per replan and `clearance` (m); `start_free` is `"hull"` or `"bodies"`
/// (what the start is taken to leave free); `known`, a map of the same resolution whose
/// known voxels count as seen. `start`, `goal`, `start_yaw`, `start_shape` and
/// `goal_tol` as for `plan()`. The run ends when the chain reaches the goal, when the
/// goal is proven out of reach, or after `time_limit` simulated seconds: see
/// `Exploration.end`. Keeps one step in `record_every`. Raises `PlanError` for a bad
/// chain or query, `ExploreError` for bad sensor or planner settings or a start that is
/// not free, `SimError` when the simulation cannot run.
#[pyfunction]
#[pyo3(signature = (
    map, units = None, start = None, goal = None, start_yaw = None, start_shape = None,
    goal_tol = 0.3, time_limit = 600.0, deadline = online::DEFAULT_DEADLINE_S,
    clearance = aerial_chain::collision::DEFAULT_CLEARANCE, start_free = "hull",
    sensor = None, sensor_rate = aerial_chain::sensing::survey::DEFAULT_RATE_HZ,
    known = None, record_every = 10
))]
#[allow(clippy::too_many_arguments)] // Python keyword arguments, each with a default.
pub fn explore(
    py: Python<'_>,
    map: &Map,
    units: Option<i64>,
    start: Option<[f64; 3]>,
    goal: Option<[f64; 3]>,
    start_yaw: Option<f64>,
    start_shape: Option<Vec<f32>>,
    goal_tol: f64,
    time_limit: f64,
    deadline: f64,
    clearance: f64,
    start_free: &str,
    sensor: Option<Bound<'_, PyAny>>,
    sensor_rate: f64,
    known: Option<&Map>,
    record_every: usize,
) -> PyResult<Exploration> {
    let asked = Asked {
        start,
        goal,
        start_yaw,
        start_shape,
        goal_tol,
    };
    let (params, query) = chain_and_query(map, units, asked)?;
    let settings = settings(py, (deadline, clearance, start_free), sensor, sensor_rate)?;
    let settings = ExploreSettings {
        time_limit_s: time_limit,
        ..settings
    };
    if record_every == 0 {
        return Err(err::<ExploreError>("record_every = 0: at least 1"));
    }
    if let Some(k) = known.filter(|k| k.grid.resolution() != map.grid.resolution()) {
        return Err(err::<ExploreError>(format!(
            "known {}: resolution {} m, the map's is {} m",
            k.name,
            k.grid.resolution(),
            map.grid.resolution()
        )));
    }
    let start = Waypoint::new(query.start.into(), &query.start_shape).zeta;
    let run = py.detach(|| {
        let prior = known.map(|k| &k.grid);
        online::explore(
            &map.grid,
            params,
            arc_tables(params)?,
            &start,
            query.goal,
            query.goal_tol,
            prior,
            &settings,
        )
        .map_err(|e| match e {
            Refused::Sim(e) => err::<SimError>(e),
            e => err::<ExploreError>(e),
        })
    })?;
    exploration(py, run, map, record_every)
}

/// `arc plan`'s shape tables for the chain `params`, as `arc explore` builds them.
pub(crate) fn arc_tables(params: ChainParams) -> PyResult<ShapeTables> {
    let table_settings = PlanOptions::default().table_settings();
    ShapeTables::build(params, &table_settings, &AtomicUsize::new(0))
        .map_err(|e| err::<ExploreError>(format!("shape tables: {e}")))
}

/// The settings of `explore()`'s planner and sensors, checked with the words of `arc
/// explore`.
pub(crate) fn settings(
    py: Python<'_>,
    (deadline, clearance, start_free): (f64, f64, &str),
    sensor: Option<Bound<'_, PyAny>>,
    sensor_rate: f64,
) -> PyResult<ExploreSettings> {
    if !(deadline > 0.0 && deadline <= 60.0) {
        return Err(err::<ExploreError>(format!(
            "deadline = {deadline}: a positive number of seconds, at most 60"
        )));
    }
    if !(clearance.is_finite() && clearance >= 0.0) {
        return Err(err::<ExploreError>(format!(
            "clearance = {clearance}: a length of at least 0 m"
        )));
    }
    let start_free = match start_free {
        "hull" => online::StartFree::Hull,
        "bodies" => online::StartFree::Bodies,
        other => {
            return Err(err::<ExploreError>(format!(
                "start_free = {other:?}: \"hull\" or \"bodies\""
            )))
        }
    };
    let survey = Survey {
        sensor: sensor_from(py, sensor)?,
        rate_hz: sensor_rate,
    };
    survey
        .validate()
        .map_err(|e| err::<ExploreError>(format!("sensor: {e}")))?;
    let mut settings = ExploreSettings {
        survey,
        fly: FlyOptions::default(),
        ..ExploreSettings::default()
    };
    settings.online.deadline_s = deadline;
    settings.online.plan.clearance = clearance;
    settings.online.start_free = start_free;
    Ok(settings)
}

/// `run` as an `Exploration`: its flight and plan wrapped for Python.
fn exploration(
    py: Python<'_>,
    run: online::Exploration,
    map: &Map,
    record_every: usize,
) -> PyResult<Exploration> {
    let record = run.record();
    let mut plan = run.plan;
    plan.map = MapSection::of(&map.grid).with_source(map.source.clone());
    let flight = run.flight;
    let flight = Flight {
        params: flight.params,
        samples: flight.samples.into_iter().step_by(record_every).collect(),
        report: flight.report,
        record_every,
    };
    Ok(Exploration {
        end: run.end,
        flight: Py::new(py, flight)?,
        plan: Py::new(py, Plan::checked(plan)?)?,
        record,
        seen: run.seen,
        map_name: map.name.clone(),
    })
}
