//! `simulate()`: a plan flown by the chain's dynamics and control stack (`arc sim`),
//! and the recorded `Flight` as NumPy arrays.

use numpy::ndarray::{Array1, Array2, Array3};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3};
use pyo3::prelude::*;

use aerial_chain::flying::{fly, FlyOptions};
use aerial_chain::sim::{BodySample, FlightReport, Progress, Sample, SimConfig};
use aerial_chain::trajectory::{Limits, Settings};

use crate::map::Map;
use crate::plan::Plan;
use crate::{err, json_to_py, SimError};

/// A flight: the chain's states every `record_every`-th step of the simulation, and
/// its report. Arrays are indexed by sample first (`T` samples), then by unit.
#[pyclass(module = "aerial_chain", frozen)]
pub struct Flight {
    /// The chain flown.
    pub(crate) params: aerial_chain_core::ChainParams,
    /// The recorded samples.
    pub(crate) samples: Vec<Sample>,
    /// The summary of the whole flight.
    pub(crate) report: FlightReport,
    /// One simulation step in this many is recorded.
    pub(crate) record_every: usize,
}

impl Flight {
    /// One array of `(T, N, K)` from `K` numbers of every unit of every sample.
    fn per_unit<'py, const K: usize>(
        &self,
        py: Python<'py>,
        field: impl Fn(&BodySample) -> [f32; K],
    ) -> Bound<'py, PyArray3<f64>> {
        let n = self.report.units;
        let v: Vec<f64> = self
            .samples
            .iter()
            .flat_map(|s| s.units.iter().flat_map(&field).map(f64::from))
            .collect();
        Array3::from_shape_vec((self.samples.len(), n, K), v)
            .expect("N units per sample")
            .into_pyarray(py)
    }

    /// One array of `(T, K)` from `K` numbers of every sample.
    fn per_sample<'py, const K: usize>(
        &self,
        py: Python<'py>,
        field: impl Fn(&Sample) -> [f32; K],
    ) -> Bound<'py, PyArray2<f64>> {
        let v: Vec<f64> = self
            .samples
            .iter()
            .flat_map(&field)
            .map(f64::from)
            .collect();
        Array2::from_shape_vec((self.samples.len(), K), v)
            .expect("K numbers per sample")
            .into_pyarray(py)
    }
}

#[pymethods]
impl Flight {
    /// Time of every sample, a `(T,)` array (s).
    #[getter]
    fn t<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        Array1::from_iter(self.samples.iter().map(|s| s.t)).into_pyarray(py)
    }

    /// Every unit's centre, a `(T, N, 3)` array (m, head first).
    #[getter]
    fn unit_positions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f64>> {
        self.per_unit(py, |b| b.p)
    }

    /// Every unit's full rigid-body state, a `(T, N, 13)` array: position (m), attitude
    /// quaternion `[w, x, y, z]`, velocity (m/s), angular velocity in the world frame
    /// (rad/s).
    #[getter]
    fn unit_states<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f64>> {
        self.per_unit(py, |b| {
            let mut x = [0.0; 13];
            for (slot, v) in x
                .iter_mut()
                .zip(b.p.iter().chain(&b.q).chain(&b.v).chain(&b.w))
            {
                *slot = *v;
            }
            x
        })
    }

    /// The reference head position the controller tracked, a `(T, 3)` array (m).
    #[getter]
    fn head_reference<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.per_sample(py, |s| s.head_ref)
    }

    /// The summary (`arc sim --out`'s `report`): time to complete, tracking errors,
    /// clearance to the map, joint-limit excursions, ...
    #[getter]
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.report)
    }

    /// True when the chain reached the plan's goal without touching the map or itself.
    #[getter]
    fn success(&self) -> bool {
        self.report.success()
    }

    fn __len__(&self) -> usize {
        self.samples.len()
    }

    fn __repr__(&self) -> String {
        format!(
            "Flight(N = {}, {} samples over {:.2} s, {})",
            self.report.units,
            self.samples.len(),
            self.report.simulated_time,
            if self.report.success() {
                "arrived without contact"
            } else {
                "did not succeed"
            }
        )
    }
}

/// Flies `plan` on `map` with the chain's dynamics and control stack as `arc sim` does
/// (the library's `aerial_chain::flying::fly`, same defaults): along the plan's
/// blended trajectory, or stopping at every waypoint where the plan is not admissible
/// as one or `blend=False` asks for it; `rate` (Hz), largest unit `speed` (m/s), head
/// `accel` (m/s^2), link `angular_rate` (rad/s), head `yaw_rate` (rad/s; `None`:
/// `arc sim`'s 45 deg/s), arrival within `goal_tol` (m) and `settle_time` (s) of the plan's
/// end. Keeps one step in `record_every`. Raises `SimError` for settings outside their
/// limits or a plan the simulation cannot fly; a flight that fails is no error
/// (`Flight.success`, `Flight.report`).
#[pyfunction]
#[pyo3(signature = (
    map, plan, rate = 500.0, speed = 0.5, accel = 0.5, angular_rate = 0.4,
    yaw_rate = None, goal_tol = 0.1, settle_time = 10.0,
    record_every = 10, blend = true
))]
#[allow(clippy::too_many_arguments)] // Python keyword arguments, each with a default.
pub fn simulate(
    py: Python<'_>,
    map: &Map,
    plan: &Plan,
    rate: f64,
    speed: f64,
    accel: f64,
    angular_rate: f64,
    yaw_rate: Option<f64>,
    goal_tol: f64,
    settle_time: f64,
    record_every: usize,
    blend: bool,
) -> PyResult<Flight> {
    if record_every == 0 {
        return Err(err::<SimError>("record_every = 0: at least 1"));
    }
    let sim = SimConfig {
        rate,
        goal_tolerance: goal_tol,
        settle_time,
        ..SimConfig::default()
    };
    let limits = Limits {
        speed,
        accel,
        angular_rate,
        yaw_rate: yaw_rate.unwrap_or(aerial_chain::trajectory::DEFAULT_YAW_RATE),
        ..Limits::default()
    };
    let options = FlyOptions {
        sim,
        timing: Settings {
            limits,
            blend,
            ..Settings::default()
        },
    };
    // Settings first, with the words of `arc sim`, before any trajectory is made.
    options
        .sim_config()
        .validate()
        .map_err(|e| err::<SimError>(format!("simulation settings: {e}")))?;
    let (flight, _) = py
        .detach(|| fly(&plan.plan, &map.grid, &options, &Progress::default()))
        .map_err(err::<SimError>)?;
    Ok(Flight {
        params: flight.params,
        samples: flight.samples.into_iter().step_by(record_every).collect(),
        report: flight.report,
        record_every,
    })
}
