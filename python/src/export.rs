//! `export()`: a plan (timed as `arc trajectory` times it) or a flight as a ROS 2 bag
//! (`.mcap`) or per-unit MAVLink setpoints (`.tlog`), as `arc export` writes them.

use std::path::PathBuf;

use pyo3::prelude::*;

use aerial_chain::export::{Autopilot, ExportOptions, Motion, TlogOptions};
use aerial_chain::plan_file::ChainSection;
use aerial_chain::sim::{FlightFile, FLIGHT_FORMAT};
use aerial_chain::trajectory::{self, TrajectoryFile};

use crate::map::Map;
use crate::plan::Plan;
use crate::sim::Flight;
use crate::{err, ExportError};

/// The motion of `source`, a `Plan` or a `Flight`, at `rate` Hz.
fn motion(map: &Map, source: &Bound<'_, PyAny>, rate: f64) -> PyResult<Motion> {
    if let Ok(plan) = source.cast::<Plan>() {
        let plan = &plan.get().plan;
        let tr = trajectory::build(plan, &map.grid, &trajectory::Settings::default())
            .map_err(|e| err::<ExportError>(format!("the plan: {e}")))?;
        return Motion::of_trajectory(&TrajectoryFile::new(&tr, plan), rate)
            .map_err(err::<ExportError>);
    }
    if let Ok(flight) = source.cast::<Flight>() {
        let f = flight.get();
        let file = FlightFile {
            format: FLIGHT_FORMAT.into(),
            plan: String::new(),
            map: map.name.clone(),
            chain: Some(ChainSection::from_params(&f.params)),
            report: f.report.clone(),
            record_every: f.record_every,
            samples: f.samples.clone(),
            explore: None,
        };
        return Motion::of_flight(&file, rate).map_err(err::<ExportError>);
    }
    Err(err::<ExportError>(format!(
        "source: expected a Plan or a Flight, got {}",
        source.get_type().name()?
    )))
}

/// Writes `source` (a `Plan`, timed with the trajectory defaults of `arc trajectory`,
/// or a `Flight`) to `path` as `arc export` does: a ROS 2 bag when `path` ends in
/// `.mcap` (with the map), MAVLink 2 setpoints when it ends in `.tlog`. `rate` (Hz) is
/// the rate of the streamed messages; `sysid_base`, `hold_s`, `arm` and `autopilot`
/// (`"px4"` or `"ardupilot"`) shape the `.tlog`. Returns the bytes written; raises
/// `ExportError` naming the problem.
#[pyfunction]
#[pyo3(signature = (
    map, source, path, rate = 50.0, sysid_base = 1, hold_s = 1.0, arm = false,
    autopilot = "px4"
))]
#[allow(clippy::too_many_arguments)] // Python keyword arguments, each with a default.
pub fn export(
    py: Python<'_>,
    map: &Map,
    source: &Bound<'_, PyAny>,
    path: PathBuf,
    rate: f64,
    sysid_base: u8,
    hold_s: f64,
    arm: bool,
    autopilot: &str,
) -> PyResult<usize> {
    let autopilot = match autopilot {
        "px4" => Autopilot::Px4,
        "ardupilot" => Autopilot::ArduPilot,
        other => {
            return Err(err::<ExportError>(format!(
                "autopilot = {other:?}: expected \"px4\" or \"ardupilot\""
            )))
        }
    };
    let motion = motion(map, source, rate)?;
    let options = ExportOptions {
        tlog: TlogOptions {
            sysid_base,
            hold: hold_s,
            arm,
            autopilot,
            ..TlogOptions::default()
        },
    };
    py.detach(|| aerial_chain::export::export(&motion, Some(&map.grid), &path, &options))
        .map(|w| w.bytes)
        .map_err(err::<ExportError>)
}
