//! `Map`: an occupancy grid from an OctoMap `.bt` file or a built-in scenario, with the
//! scenario's start, goal and chain size when it is one.

use std::path::PathBuf;

use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::prelude::*;

use aerial_chain::map::{Grid, OcTree};
use aerial_chain::plan_file::MapSource;
use aerial_chain::problem::scenarios::{self, Scenario};
use aerial_chain::sensing::{raycast, PointCloud, UnitPose};

use crate::{err, points_array, ExploreError, MapError};

/// A map to plan, verify and fly on: an occupancy grid (OctoMap `.bt` file or built-in
/// scenario) and whether unknown space counts as occupied.
///
/// `Map.from_file(path, unknown_free=False)` or `Map.scenario(name, unknown_free=False)`.
#[pyclass(module = "aerial_chain", frozen)]
pub struct Map {
    /// The grid, with the unknown-space choice applied.
    pub(crate) grid: Grid,
    /// The scenario, when the map is a built-in one (its start, goal, chain size).
    pub(crate) scenario: Option<Scenario>,
    /// Which map this is, as plans record it.
    pub(crate) source: MapSource,
    /// The map's name for messages.
    pub(crate) name: String,
}

#[pymethods]
impl Map {
    /// Reads an OctoMap binary tree (`.bt`). Unknown space is occupied unless
    /// `unknown_free`. Raises `MapError` naming the file when it cannot be read.
    #[staticmethod]
    #[pyo3(signature = (path, unknown_free = false))]
    fn from_file(py: Python<'_>, path: PathBuf, unknown_free: bool) -> PyResult<Self> {
        py.detach(|| {
            let name = path.display().to_string();
            let bytes = std::fs::read(&path)
                .map_err(|e| err::<MapError>(format!("{name}: cannot read the file: {e}")))?;
            let tree = OcTree::from_bt_bytes(&bytes, &name).map_err(err::<MapError>)?;
            let grid = Grid::from_octree(&tree, !unknown_free)
                .map_err(|e| err::<MapError>(format!("{name}: {e}")))?;
            Ok(Map {
                grid,
                scenario: None,
                source: MapSource::file(&path, &bytes),
                name,
            })
        })
    }

    /// A built-in scenario: `window`, `maze`, `silos`, `corridor`, `corridor:LENGTH`, a
    /// family instance (`passage:`, `forest:`, `slot:`, `pipe:` or `shaft:KEY=VALUE,...`)
    /// or a large generated map (`campus`, `hall`). Raises `MapError` for an unknown name.
    #[staticmethod]
    #[pyo3(signature = (name, unknown_free = false))]
    fn scenario(py: Python<'_>, name: &str, unknown_free: bool) -> PyResult<Self> {
        py.detach(|| {
            let sc = scenarios::build(name)
                .map_err(|e| err::<MapError>(format!("scenario {name}: {e}")))?;
            let mut grid = sc.grid.clone();
            grid.set_unknown_is_occupied(!unknown_free);
            Ok(Map {
                grid,
                scenario: Some(sc),
                source: MapSource::scenario(name),
                name: format!("scenario {name}"),
            })
        })
    }

    /// The map's name: the file or `scenario NAME`.
    #[getter]
    fn name(&self) -> &str {
        &self.name
    }

    /// Voxel edge (m).
    #[getter]
    fn resolution(&self) -> f64 {
        self.grid.resolution()
    }

    /// Whether unknown space counts as occupied.
    #[getter]
    fn unknown_is_occupied(&self) -> bool {
        self.grid.unknown_is_occupied()
    }

    /// The grid's metric bounds: `(lo, hi)`, two arrays of 3 (m).
    #[getter]
    fn bounds<'py>(
        &self,
        py: Python<'py>,
    ) -> (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>) {
        let (lo, hi) = self.grid.bounds();
        let array = |p: nalgebra::Point3<f64>| p.coords.as_slice().to_vec().into_pyarray(py);
        (array(lo), array(hi))
    }

    /// The scenario's head start (array of 3, m); `None` for a map file.
    #[getter]
    fn start<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<f64>>> {
        self.scenario
            .as_ref()
            .map(|s| s.start.coords.as_slice().to_vec().into_pyarray(py))
    }

    /// The scenario's head goal (array of 3, m); `None` for a map file.
    #[getter]
    fn goal<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<f64>>> {
        self.scenario
            .as_ref()
            .map(|s| s.goal.coords.as_slice().to_vec().into_pyarray(py))
    }

    /// The scenario's start yaw (rad); `None` for a map file.
    #[getter]
    fn start_yaw(&self) -> Option<f64> {
        self.scenario.as_ref().map(|s| s.start_yaw)
    }

    /// The number of units the scenario is made for; `None` for a map file.
    #[getter]
    fn default_units(&self) -> Option<u8> {
        self.scenario.as_ref().map(|s| s.default_units)
    }

    /// Centres of the voxels known to be occupied, an `(K, 3)` array (m); with
    /// `z_range=(lo, hi)` only those whose centre lies in that height band.
    #[pyo3(signature = (z_range = None))]
    fn occupied_voxels<'py>(
        &self,
        py: Python<'py>,
        z_range: Option<(f64, f64)>,
    ) -> Bound<'py, PyArray2<f64>> {
        let (lo, hi) = z_range.unwrap_or((f64::NEG_INFINITY, f64::INFINITY));
        let centres = self
            .grid
            .known_voxels()
            .filter(|&(_, occupied)| occupied)
            .map(|(i, _)| self.grid.voxel_center(i))
            .filter(|c| (lo..=hi).contains(&c[2]))
            .map(|c| [c.x, c.y, c.z]);
        points_array(py, centres)
    }

    /// What one unit's depth sensor measures in this map (the truth, exactly, as `arc
    /// explore`'s simulated sensors cast it): the unit at `position` (m), level with
    /// head yaw `yaw` (rad), or at `attitude` (a unit quaternion `[w, x, y, z]`, tilt
    /// included) when given; `sensor` a dict of docs/maps.md "Sensing" fields (left
    /// out: the default camera), turned by its splay for unit index `unit` (0: the
    /// head). Returns `(origin, points, max_range)`: the sensor's origin, its cloud as
    /// an (M, 3) array (a return moved into the voxel it hit, a ray without a return as
    /// a point at twice the range, a too-close ray nothing) and its range, the
    /// arguments of `OnlinePlanner.observe`. Raises `ExploreError` for bad settings.
    #[pyo3(signature = (position, yaw = 0.0, attitude = None, sensor = None, unit = 0))]
    #[allow(clippy::type_complexity)] // Two NumPy arrays and a number.
    fn scan<'py>(
        &self,
        py: Python<'py>,
        position: [f64; 3],
        yaw: f64,
        attitude: Option<[f64; 4]>,
        sensor: Option<Bound<'py, PyAny>>,
        unit: usize,
    ) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray2<f64>>, f64)> {
        let sensor = crate::explore::sensor_from(py, sensor)?;
        sensor
            .validate()
            .map_err(|e| err::<ExploreError>(format!("sensor: {e}")))?;
        if !yaw.is_finite() {
            return Err(err::<ExploreError>(format!(
                "yaw = {yaw}: a finite angle (rad)"
            )));
        }
        let pose = match attitude {
            Some(q) => UnitPose::new(position, q),
            None => UnitPose::new(position, [1.0, 0.0, 0.0, 0.0])
                .map(|p| UnitPose::level(p.position, yaw)),
        }
        .map_err(err::<ExploreError>)?;
        let sensor = sensor.for_unit(unit);
        let cloud = py.detach(|| {
            let scan = raycast::scan(&self.grid, &sensor, &pose);
            PointCloud::from_scan(&scan, self.grid.resolution())
        });
        let points = cloud.points.iter().map(|p| p.map(f64::from));
        let origin = cloud.origin.map(f64::from).to_vec().into_pyarray(py);
        Ok((origin, points_array(py, points), sensor.max_range))
    }

    fn __repr__(&self) -> String {
        let [x, y, z] = self.grid.dims();
        format!(
            "Map({}, resolution {} m, {x} x {y} x {z} voxels, unknown space {})",
            self.name,
            self.grid.resolution(),
            if self.grid.unknown_is_occupied() {
                "occupied"
            } else {
                "free"
            }
        )
    }
}
