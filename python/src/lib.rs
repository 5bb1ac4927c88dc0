//! # aerial_chain for Python
//!
//! The Python module `aerial_chain._native` (re-exported by the package `aerial_chain`):
//! the library `aerial_chain`'s public face, wrapped for Python with PyO3.
//!
//! - `map::Map`: an OctoMap `.bt` file or a built-in scenario;
//! - `plan::plan` (the ARCplanner with the defaults of `arc plan`, through the
//!   library's facade `aerial_chain::planning::plan`), `plan::Plan` (the `arc-plan/1`
//!   file), `plan::verify` (the exact verifier of docs/model.md);
//! - `sim::simulate` and `sim::Flight`, the chain flown by its control stack as `arc
//!   sim` flies it (`aerial_chain::flying::fly`);
//! - `explore::explore` and `explore::Exploration`, the chain flown into the unknown
//!   as `arc explore` flies it (`aerial_chain::online::explore`);
//! - `online::OnlinePlanner`, its planner one replan at a time, for a robot's own loop;
//! - `export::export`, a plan or flight as a ROS 2 bag or MAVLink setpoints.
//!
//! Configurations and flights come out as NumPy arrays. Bad input raises one of the
//! exceptions below, all subclasses of `ArcError`, itself a `ValueError`, with the
//! message the command line would print (the file, field or argument, and the value).

#![deny(missing_docs)]

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

mod explore;
mod export;
mod map;
mod online;
mod plan;
mod sim;

pyo3::create_exception!(
    aerial_chain,
    ArcError,
    PyValueError,
    "Base of the errors of aerial_chain: bad input, or an answer that is no (a ValueError)."
);
pyo3::create_exception!(
    aerial_chain,
    MapError,
    ArcError,
    "A map that cannot be loaded: a missing or malformed .bt file, an unknown scenario."
);
pyo3::create_exception!(
    aerial_chain,
    PlanError,
    ArcError,
    "Planning refused or failed: bad chain or query, no plan found; or a bad plan file."
);
pyo3::create_exception!(
    aerial_chain,
    VerifyError,
    ArcError,
    "The exact verifier found the plan INVALID on the map (the message says where)."
);
pyo3::create_exception!(
    aerial_chain,
    ExportError,
    ArcError,
    "An export that cannot be made: an output name that is no .mcap or .tlog, options outside their limits."
);
pyo3::create_exception!(
    aerial_chain,
    ExploreError,
    ArcError,
    "An exploration that cannot run: sensor or planner settings outside their limits, a start whose hull is not free."
);
pyo3::create_exception!(
    aerial_chain,
    SimError,
    ArcError,
    "The simulation cannot fly the plan: settings outside their limits, a plan it cannot time."
);

/// `E` as a Python exception of type `T`, with `E`'s message.
pub(crate) fn err<T: pyo3::PyTypeInfo>(e: impl std::fmt::Display) -> PyErr {
    PyErr::new::<T, _>(e.to_string())
}

/// Points as a `(K, 3)` NumPy array, one row per point.
pub(crate) fn points_array<'py>(
    py: Python<'py>,
    points: impl IntoIterator<Item = [f64; 3]>,
) -> Bound<'py, numpy::PyArray2<f64>> {
    use numpy::IntoPyArray;
    let flat: Vec<f64> = points.into_iter().flatten().collect();
    numpy::ndarray::Array2::from_shape_vec((flat.len() / 3, 3), flat)
        .expect("three numbers per point")
        .into_pyarray(py)
}

/// A JSON value (serde) as the Python object `json.loads` makes of it.
pub(crate) fn json_to_py<'py>(
    py: Python<'py>,
    value: &impl serde::Serialize,
) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(value).map_err(err::<PyValueError>)?;
    py.import("json")?.call_method1("loads", (text,))
}

/// The extension module.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("ArcError", py.get_type::<ArcError>())?;
    m.add("MapError", py.get_type::<MapError>())?;
    m.add("PlanError", py.get_type::<PlanError>())?;
    m.add("VerifyError", py.get_type::<VerifyError>())?;
    m.add("SimError", py.get_type::<SimError>())?;
    m.add("ExportError", py.get_type::<ExportError>())?;
    m.add("ExploreError", py.get_type::<ExploreError>())?;
    m.add(
        "DEFAULT_CLEARANCE",
        aerial_chain::collision::DEFAULT_CLEARANCE,
    )?;
    m.add(
        "SCENARIOS",
        aerial_chain::problem::scenarios::NAMES.to_vec(),
    )?;
    m.add_class::<map::Map>()?;
    m.add_class::<plan::Plan>()?;
    m.add_class::<plan::VerifyReport>()?;
    m.add_class::<sim::Flight>()?;
    m.add_class::<explore::Exploration>()?;
    m.add_class::<online::OnlinePlanner>()?;
    m.add_function(wrap_pyfunction!(plan::plan, m)?)?;
    m.add_function(wrap_pyfunction!(plan::verify, m)?)?;
    m.add_function(wrap_pyfunction!(sim::simulate, m)?)?;
    m.add_function(wrap_pyfunction!(explore::explore, m)?)?;
    m.add_function(wrap_pyfunction!(export::export, m)?)?;
    Ok(())
}
