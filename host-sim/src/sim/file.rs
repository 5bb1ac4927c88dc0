//! The flight file `arc-sim/1` (docs/model.md, "Flights"): what `arc sim --out` writes,
//! and what `arc view` and `arc export` read back.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::flight::{Flight, FlightReport, Sample};
use crate::fsutil;
use crate::plan_file::ChainSection;
use crate::trajectory::FileError;

/// The format tag of a flight file.
pub const FORMAT: &str = "arc-sim/1";

/// A recorded flight as a file: its report and every `record_every`-th sample.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FlightFile {
    /// `"arc-sim/1"`.
    pub format: String,
    /// The plan or trajectory flown, as named on the command line.
    pub plan: String,
    /// The map flown in, as named on the command line.
    pub map: String,
    /// The chain flown (optional: flights written before it was recorded lack it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub chain: Option<ChainSection>,
    /// The flight's summary.
    pub report: FlightReport,
    /// One simulation step in this many is recorded.
    pub record_every: usize,
    /// The recorded samples, in time order.
    pub samples: Vec<Sample>,
    /// The record of an exploration (`arc explore`: `"format": "arc-explore/1"`,
    /// docs/model.md "Explorations"), kept as JSON so that the flight format does not
    /// depend on the planner that made it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub explore: Option<serde_json::Value>,
}

impl FlightFile {
    /// The file of `flight`, keeping one sample in `record_every` (at least 1).
    pub fn new(flight: &Flight, plan: &str, map: &str, record_every: usize) -> Self {
        let every = record_every.max(1);
        Self {
            format: FORMAT.into(),
            plan: plan.into(),
            map: map.into(),
            chain: Some(ChainSection::from_params(&flight.params)),
            report: flight.report.clone(),
            record_every: every,
            samples: flight.samples.iter().step_by(every).cloned().collect(),
            explore: None,
        }
    }

    /// Reads and checks a flight file (`-`: standard input).
    pub fn read(path: &Path) -> Result<Self, FileError> {
        FileError::read(path, Self::parse)
    }

    /// Parses and checks a flight's text; `name` names it in errors.
    pub fn parse(text: &str, name: &str) -> Result<Self, FileError> {
        fsutil::parse_checked(text, FORMAT, Self::check).map_err(FileError::invalid(name))
    }

    /// Writes the file as JSON, atomically (`-`: standard output).
    pub fn write(&self, path: &Path) -> Result<(), FileError> {
        let io = |source| FileError::Io {
            path: fsutil::output_name(path),
            source,
        };
        let text = serde_json::to_string(self).map_err(|e| io(e.into()))?;
        fsutil::write_output(path, text.as_bytes()).map_err(io)
    }

    /// The format's rules that need no map: the tag, at least one sample, times
    /// finite and strictly increasing, every sample with `report.units` units (and
    /// the chain's, when recorded) and finite states.
    pub fn check(&self) -> Result<(), String> {
        if self.format != FORMAT {
            return Err(format!("format = {:?}, expected {FORMAT:?}", self.format));
        }
        if self.samples.is_empty() {
            return Err("samples is empty".into());
        }
        let units = self.report.units;
        if let Some(c) = &self.chain {
            c.to_params().map_err(|e| e.to_string())?;
            if c.units as usize != units {
                return Err(format!(
                    "chain.units = {} but report.units = {units}",
                    c.units
                ));
            }
        }
        let mut last = f64::NEG_INFINITY;
        for (i, s) in self.samples.iter().enumerate() {
            if !(s.t.is_finite() && s.t > last) {
                return Err(format!(
                    "samples[{i}].t = {} is not a finite time after the sample before",
                    s.t
                ));
            }
            last = s.t;
            check_sample(i, s, units)?;
        }
        Ok(())
    }
}

/// One sample's rules: `units` bodies with finite states, and a command per unit
/// where commands are recorded.
fn check_sample(i: usize, s: &Sample, units: usize) -> Result<(), String> {
    if s.units.len() != units {
        return Err(format!(
            "samples[{i}].units has {} bodies, expected report.units = {units}",
            s.units.len()
        ));
    }
    for (field, n) in [
        ("thrust", s.thrust.len()),
        ("attitude_cmd", s.attitude_cmd.len()),
    ] {
        if n != 0 && n != units {
            return Err(format!(
                "samples[{i}].{field} has {n} entries, expected 0 or one per unit ({units})"
            ));
        }
    }
    let finite = |v: &[f32]| v.iter().all(|x| x.is_finite());
    for (u, b) in s.units.iter().enumerate() {
        if !(finite(&b.p) && finite(&b.q) && finite(&b.v) && finite(&b.w)) {
            return Err(format!(
                "samples[{i}].units[{u}] has a number that is not finite"
            ));
        }
    }
    let commands_finite = finite(&s.thrust) && s.attitude_cmd.iter().all(|a| finite(a.as_slice()));
    if !commands_finite {
        return Err(format!("samples[{i}] has a command that is not finite"));
    }
    Ok(())
}
