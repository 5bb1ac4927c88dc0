//! `OnlinePlanner`: the online planner one replan at a time, for a robot's own loop
//! (the library's `aerial_chain::online::OnlinePlanner`). The caller feeds it what the
//! units' sensors saw and where the bodies flew, asks which replan is due, replans,
//! and flies the committed motion. `explore()` runs the same planner in a whole
//! simulated run.

use std::path::PathBuf;

use nalgebra::Point3;
use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;

use aerial_chain::online::{self, Trigger};
use aerial_chain::plan_file::{MapSection, Waypoint};
use aerial_chain::sensing::survey::DEFAULT_RATE_HZ;
use aerial_chain::sensing::PointCloud;

use crate::explore::{arc_tables, settings};
use crate::map::Map;
use crate::plan::{chain_and_query, Asked, Plan};
use crate::{err, json_to_py, points_array, ExploreError};

/// The online planner of a chain flying into the unknown (docs/online.md): what is
/// committed always lies in space seen free and ends at rest; the route to the goal
/// is searched with unknown space free. Times are the caller's clock (s), the one its
/// committed motion is timed in; points are in the world frame of `map`.
#[pyclass(module = "aerial_chain")]
pub struct OnlinePlanner {
    inner: online::OnlinePlanner,
    /// The start configuration, as the joined plan begins.
    start: Vec<f64>,
    /// The map's section, as the joined plan records it.
    map: MapSection,
    /// The radius marked free about a flown unit centre (m): `r_u` plus the clearance.
    flown_radius: f64,
}

/// Most samples `committed` returns: the trajectory module's bound on one motion.
const MAX_SAMPLES: usize = aerial_chain::trajectory::MAX_SAMPLES;

/// `points` as an (M, 3) array of floats, or why not (naming `what`).
fn rows<'py>(py: Python<'py>, points: &Bound<'py, PyAny>, what: &str) -> PyResult<Vec<[f64; 3]>> {
    let array = py
        .import("numpy")?
        .call_method1("asarray", (points, "float64"))
        .map_err(|e| err::<ExploreError>(format!("{what}: not an array of numbers: {e}")))?;
    let array: PyReadonlyArray2<f64> = array
        .extract()
        .map_err(|_| err::<ExploreError>(format!("{what}: an array of shape (M, 3)")))?;
    let view = array.as_array();
    if view.ncols() != 3 {
        return Err(err::<ExploreError>(format!(
            "{what}: shape {:?}, an array of shape (M, 3)",
            view.shape()
        )));
    }
    let rows: Vec<[f64; 3]> = view
        .rows()
        .into_iter()
        .map(|r| [r[0], r[1], r[2]])
        .collect();
    if let Some(bad) = rows.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
        return Err(err::<ExploreError>(format!(
            "{what}: row {bad} is {:?}, not finite",
            rows[bad]
        )));
    }
    Ok(rows)
}

/// A trigger's name (`"start"`, `"route_cut"`, `"period"`, `"commit_short"`).
fn trigger(name: &str) -> PyResult<Trigger> {
    serde_json::from_value(serde_json::Value::String(name.into())).map_err(|_| {
        err::<ExploreError>(format!(
            "trigger = {name:?}: \"start\", \"route_cut\", \"period\" or \"commit_short\""
        ))
    })
}

/// A simulated time: finite and not negative.
fn time(name: &str, t: f64) -> PyResult<f64> {
    match t.is_finite() && t >= 0.0 {
        true => Ok(t),
        false => Err(err::<ExploreError>(format!(
            "{name} = {t}: a time of at least 0 s"
        ))),
    }
}

#[pymethods]
impl OnlinePlanner {
    /// A planner for a chain of `units` (default: the scenario's) in the box of `map`,
    /// whose contents are not read: nothing is known at first but `known` (a map of the
    /// same resolution whose known voxels count as seen) and the start's own space
    /// (`start_free`, `"hull"` or `"bodies"`). `start`, `goal`, `start_yaw`,
    /// `start_shape` and `goal_tol` as for `plan()`; `deadline` (wall s per replan),
    /// `clearance` (m) and `sensor` (a dict of docs/maps.md "Sensing" fields: where
    /// the chain turns to look) as for `explore()`. Raises `PlanError` for a bad chain
    /// or query, `ExploreError` for bad settings.
    #[new]
    #[pyo3(signature = (
        map, units = None, start = None, goal = None, start_yaw = None, start_shape = None,
        goal_tol = 0.3, deadline = online::DEFAULT_DEADLINE_S,
        clearance = aerial_chain::collision::DEFAULT_CLEARANCE, start_free = "hull",
        sensor = None, known = None
    ))]
    #[allow(clippy::too_many_arguments)] // Python keyword arguments, each with a default.
    fn new(
        py: Python<'_>,
        map: &Map,
        units: Option<i64>,
        start: Option<[f64; 3]>,
        goal: Option<[f64; 3]>,
        start_yaw: Option<f64>,
        start_shape: Option<Vec<f32>>,
        goal_tol: f64,
        deadline: f64,
        clearance: f64,
        start_free: &str,
        sensor: Option<Bound<'_, PyAny>>,
        known: Option<&Map>,
    ) -> PyResult<Self> {
        let asked = Asked {
            start,
            goal,
            start_yaw,
            start_shape,
            goal_tol,
        };
        let (params, query) = chain_and_query(map, units, asked)?;
        let s = settings(
            py,
            (deadline, clearance, start_free),
            sensor,
            DEFAULT_RATE_HZ,
        )?;
        let start = Waypoint::new(query.start.into(), &query.start_shape).zeta;
        let inner = py.detach(|| {
            online::OnlinePlanner::new(
                params,
                arc_tables(params)?,
                &start,
                query.goal,
                query.goal_tol,
                &map.grid,
                known.map(|k| &k.grid),
                s.online.clone(),
                &s.survey.sensor,
            )
            .map_err(err::<ExploreError>)
        })?;
        Ok(Self {
            inner,
            start,
            map: MapSection::of(&map.grid).with_source(map.source.clone()),
            flown_radius: f64::from(params.unit_radius) + s.online.plan.clearance,
        })
    }

    /// Fuses one sensor's cloud as OctoMap's `insertPointCloud` does: `origin` the
    /// sensor's position, `points` an (M, 3) array of returns in the world frame, a
    /// ray without a return given as a point beyond `max_range` (m), which clears up to
    /// it. Returns how many voxels changed state. Raises `ExploreError` for points that
    /// are not finite or a range that is not positive.
    fn observe(
        &mut self,
        py: Python<'_>,
        origin: [f64; 3],
        points: Bound<'_, PyAny>,
        max_range: f64,
    ) -> PyResult<usize> {
        let points = rows(py, &points, "points")?;
        if origin.iter().any(|c| !c.is_finite()) {
            return Err(err::<ExploreError>(format!(
                "origin = {origin:?}: not finite"
            )));
        }
        let f32s = |p: [f64; 3]| p.map(|c| c as f32);
        let cloud = PointCloud {
            origin: f32s(origin),
            points: points.into_iter().map(f32s).collect(),
        };
        let fused = py.detach(|| self.inner.observe(&cloud, max_range));
        Ok(fused.map_err(err::<ExploreError>)?.voxels)
    }

    /// Marks the space the flown bodies fill as seen free: the balls of `r_u` plus the
    /// clearance about the unit centres `centres` (an (N, 3) array, where the units
    /// are now). Returns how many voxels changed state.
    fn observe_flown(&mut self, py: Python<'_>, centres: Bound<'_, PyAny>) -> PyResult<usize> {
        let centres: Vec<Point3<f64>> = rows(py, &centres, "centres")?
            .into_iter()
            .map(Point3::from)
            .collect();
        let fused = self.inner.observe_flown(&centres, self.flown_radius);
        Ok(fused.map_err(err::<ExploreError>)?.voxels)
    }

    /// The replan due at time `now` for a caller that observes every `period` s, if
    /// any: `"commit_short"` (the next piece), `"route_cut"` or `"period"` (the route);
    /// `None` when none is due or the committed motion ends at the goal. The first
    /// replan is the caller's, with `"start"`.
    #[pyo3(signature = (now, period = 1.0 / DEFAULT_RATE_HZ))]
    fn due(&self, now: f64, period: f64) -> PyResult<Option<String>> {
        let now = time("now", now)?;
        if !(period.is_finite() && period > 0.0) {
            return Err(err::<ExploreError>(format!(
                "period = {period}: a positive time (s)"
            )));
        }
        Ok(self.inner.due(now, period).map(|t| {
            serde_json::to_value(t)
                .ok()
                .and_then(|v| v.as_str().map(String::from))
                .unwrap_or_default()
        }))
    }

    /// Replans at time `now` for `trigger` (`"start"`, `"route_cut"`, `"period"` or
    /// `"commit_short"`; `"start"` and `"commit_short"` commit the next piece) within
    /// the deadline, and returns its record: a dict of `t`, `trigger`, `outcome`,
    /// `wall_s`, `voxels_changed`, `committed_m`, `route_m` and `joined_moving`
    /// (docs/model.md, "Explorations"). The committed motion changes from
    /// `effective_from` on.
    fn replan<'py>(
        &mut self,
        py: Python<'py>,
        now: f64,
        trigger: &str,
    ) -> PyResult<Bound<'py, PyAny>> {
        let now = time("now", now)?;
        let trigger = self::trigger(trigger)?;
        let record = py.detach(|| self.inner.replan(now, trigger));
        json_to_py(py, &record)
    }

    /// The committed motion sampled every `dt` s from time 0 to its end (the last
    /// sample at the end): `(t, zeta)`, arrays of shape (K,) and (K, 2N + 2). The chain
    /// flies it from `effective_from` on and rests at its end.
    #[pyo3(signature = (dt = 0.02))]
    #[allow(clippy::type_complexity)] // A pair of NumPy arrays.
    fn committed<'py>(
        &self,
        py: Python<'py>,
        dt: f64,
    ) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray2<f64>>)> {
        if !(dt.is_finite() && dt > 0.0 && dt <= 1.0) {
            return Err(err::<ExploreError>(format!(
                "dt = {dt}: a time step in (0, 1] s"
            )));
        }
        let reference = self.inner.committed();
        let end = reference.duration();
        let steps = (end / dt).ceil();
        if steps > MAX_SAMPLES as f64 {
            return Err(err::<ExploreError>(format!(
                "dt = {dt}: {steps} samples of the {end:.1} s committed motion, more than \
                 {MAX_SAMPLES}; sample it more coarsely or with at(t)"
            )));
        }
        let steps = steps as usize;
        let times: Vec<f64> = (0..=steps).map(|k| (k as f64 * dt).min(end)).collect();
        let width = reference.end().len();
        let mut zetas = Array2::<f64>::zeros((times.len(), width));
        for (k, &t) in times.iter().enumerate() {
            for (j, v) in reference.zeta(t).into_iter().enumerate() {
                zetas[[k, j]] = v;
            }
        }
        Ok((Array1::from(times).into_pyarray(py), zetas.into_pyarray(py)))
    }

    /// The committed configuration zeta at time `t` (an array of 2N + 2): where the
    /// chain is to be then; the end of the committed motion after it ends.
    fn at<'py>(&self, py: Python<'py>, t: f64) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let t = time("t", t)?;
        Ok(self.inner.committed().zeta(t).into_pyarray(py))
    }

    /// Makes a changed committed motion take effect on the follower's ticks of
    /// `period` s (the multiples of it from 0; 0: at once), so that a piece is joined
    /// in flight only where the follower has not yet flown past the join.
    fn follow_at_ticks(&mut self, period: f64) -> PyResult<()> {
        if !(period.is_finite() && period >= 0.0) {
            return Err(err::<ExploreError>(format!(
                "period = {period}: a time of at least 0 s"
            )));
        }
        self.inner.follow_at_ticks(period);
        Ok(())
    }

    /// When the committed motion as it is now may be flown (s): the end of the replan
    /// that last changed it.
    #[getter]
    fn effective_from(&self) -> f64 {
        self.inner.effective_from()
    }

    /// When the committed motion ends, at rest (s).
    #[getter]
    fn committed_until(&self) -> f64 {
        self.inner.committed().duration()
    }

    /// True once the committed motion ends at the goal.
    #[getter]
    fn reached(&self) -> bool {
        self.inner.reached()
    }

    /// Why the chain can get no further at time `now`, or `None` (docs/online.md,
    /// "When it replans").
    fn stuck(&self, now: f64) -> PyResult<Option<String>> {
        Ok(self.inner.stuck(time("now", now)?))
    }

    /// The route to the goal as last searched (unknown space free): an (P, 3) array of
    /// head positions, or `None` before one was found.
    #[getter]
    fn route<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray2<f64>>> {
        let route = self.inner.route()?;
        Some(points_array(
            py,
            route.points.iter().map(|p| [p.x, p.y, p.z]),
        ))
    }

    /// Pieces committed so far (turns to look included).
    #[getter]
    fn pieces(&self) -> usize {
        self.inner.pieces().len()
    }

    /// Every replan so far, as `replan` returned them.
    #[getter]
    fn replans<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.inner.records())
    }

    /// Voxels of the seen map that are known (free or occupied).
    #[getter]
    fn voxels_seen(&self) -> usize {
        self.inner.belief().seen().known()
    }

    /// The committed pieces joined into one plan (`arc explore --plan-out`), for
    /// `verify()` and `simulate()`.
    fn plan(&self) -> PyResult<Plan> {
        Plan::checked(self.inner.joined_plan(&self.start, self.map.clone()))
    }

    /// Writes the seen map as an OctoMap binary tree (`.bt`). Raises `ExploreError`
    /// naming the file.
    fn write_seen(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        py.detach(|| self.inner.belief().seen().write_bt(&path))
            .map_err(|e| err::<ExploreError>(format!("{}: {e}", path.display())))
    }

    fn __repr__(&self) -> String {
        format!(
            "OnlinePlanner({} replans, {} pieces, committed until {:.2} s, {} voxels seen{})",
            self.inner.records().len(),
            self.inner.pieces().len(),
            self.inner.committed().duration(),
            self.inner.belief().seen().known(),
            if self.inner.reached() {
                ", reaches the goal"
            } else {
                ""
            }
        )
    }
}
