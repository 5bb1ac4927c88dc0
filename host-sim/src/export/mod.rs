//! Exports for robot software: a plan's trajectory or a recorded flight as a ROS 2 bag
//! (MCAP) or as per-unit MAVLink offboard setpoints (`.tlog`) (docs/model.md,
//! "Exports").
//!
//! - `motion`: [`Motion`], every unit's state at the ticks of a rate, from a
//!   [`TrajectoryFile`] or a [`FlightFile`];
//! - `bag`: the MCAP file of ROS 2 messages;
//! - `ros2_msgs`: those messages, their CDR encoding and their `ros2msg` schemas;
//! - `tlog`: the MAVLink 2 telemetry log.
//!
//! ```
//! use aerial_chain::export::{export, ExportOptions, Motion};
//! use aerial_chain::trajectory::TrajectoryFile;
//! # use aerial_chain::plan_file::{ChainSection, MapSection, MapSource};
//! # use aerial_chain::trajectory::{Limits, SampleRow, TrajectoryStats, FORMAT};
//! # let chain = ChainSection::from_params(&aerial_chain_core::ChainParams::new(2));
//! # let sample = |t: f64, x: f64| SampleRow {
//! #     t, zeta: vec![x, 0.0, 1.0, 0.0, 0.0, 0.0],
//! #     p: vec![[x, 0.0, 1.0], [x - 0.5, 0.0, 1.0]], q: vec![[1.0, 0.0, 0.0, 0.0]; 2],
//! # };
//! # let file = TrajectoryFile {
//! #     format: FORMAT.into(), chain,
//! #     map: MapSection { resolution: 0.1, unknown_is_occupied: true, source: MapSource::default() },
//! #     limits: Limits::default(), dt: 0.5, stats: TrajectoryStats::default(),
//! #     samples: vec![sample(0.0, 0.0), sample(0.5, 0.1), sample(1.0, 0.2)],
//! # };
//! let motion = Motion::of_trajectory(&file, 50.0)?;
//! let dir = tempfile::tempdir()?;
//! let written = export(&motion, None, &dir.path().join("chain.mcap"), &ExportOptions::default())?;
//! assert!(written.bytes > 0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! [`TrajectoryFile`]: crate::trajectory::TrajectoryFile
//! [`FlightFile`]: crate::sim::FlightFile

mod bag;
mod motion;
pub mod ros2_msgs;
#[cfg(test)]
mod tests;
mod tlog;

use std::path::Path;

pub use bag::{BagSummary, FRAME};
pub use motion::{
    Command, Motion, Tick, UnitState, DEFAULT_RATE_HZ, MAX_RATE_HZ, MAX_UNIT_STATES, MIN_RATE_HZ,
};
pub use tlog::{
    attitude_ned, ned, Autopilot, TlogOptions, TlogSummary, MAX_HOLD_S, PX4_MIN_HOLD_S,
    SENDER_COMPONENT, SENDER_SYSTEM, TARGET_COMPONENT,
};

use crate::map::Grid;

/// Why an export cannot be made.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    /// The trajectory or flight breaks its format's rules.
    #[error("{0}")]
    Source(String),
    /// A rate outside `(MIN_RATE_HZ, MAX_RATE_HZ]`.
    #[error("rate {0} Hz must be above {MIN_RATE_HZ} Hz (PX4 leaves offboard below it) and at most {MAX_RATE_HZ} Hz")]
    Rate(f64),
    /// More unit states than an export holds.
    #[error("{ticks} ticks of {units} units at {rate} Hz: more than the {MAX_UNIT_STATES} unit states an export holds; lower the rate")]
    TooLong {
        /// Ticks the motion would need.
        ticks: usize,
        /// Units of the chain.
        units: usize,
        /// The rate asked for.
        rate: f64,
    },
    /// An option outside its limits; the text names it and its value.
    #[error("{0}")]
    Option(String),
    /// An output name whose ending names no export format.
    #[error("{0}: the output must end in .mcap (a ROS 2 bag) or .tlog (MAVLink)")]
    Format(String),
    /// The map cannot be put in the bag.
    #[error("the map: {0}")]
    Map(String),
    /// Encoding failed.
    #[error("{0}")]
    Encode(String),
    /// The file cannot be written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// Why.
        source: std::io::Error,
    },
}

/// The export formats, told apart by the output's ending.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// A ROS 2 bag, `.mcap`.
    Mcap,
    /// A MAVLink 2 telemetry log, `.tlog`.
    Tlog,
}

impl Format {
    /// The format of an output named `path`.
    pub fn of_path(path: &Path) -> Result<Self, ExportError> {
        crate::fsutil::by_extension(path, &[("mcap", Self::Mcap), ("tlog", Self::Tlog)])
            .ok_or_else(|| ExportError::Format(path.display().to_string()))
    }
}

/// Options of an export; the MCAP file takes none of its own.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ExportOptions {
    /// The `.tlog`'s options.
    pub tlog: TlogOptions,
}

/// What an export wrote.
#[derive(Clone, Debug, PartialEq)]
pub struct Written {
    /// Bytes written.
    pub bytes: usize,
    /// What the file holds, in its format.
    pub holds: Holds,
}

/// What an exported file holds, by its format.
#[derive(Clone, Debug, PartialEq)]
pub enum Holds {
    /// A ROS 2 bag, `.mcap`.
    Bag(BagSummary),
    /// A MAVLink 2 telemetry log, `.tlog`.
    Tlog(TlogSummary),
}

impl Holds {
    /// The messages it holds.
    pub fn messages(&self) -> usize {
        match self {
            Holds::Bag(b) => b.topics.iter().map(|(_, n)| n).sum(),
            Holds::Tlog(s) => s.heartbeats + s.position_targets + s.attitude_targets + s.commands,
        }
    }
}

/// The map as an OctoMap binary stream (`writeBinaryData`, what `octomap_msgs`
/// carries) and its resolution.
fn map_stream(grid: &Grid) -> Result<(Vec<u8>, f64), ExportError> {
    let tree = grid
        .to_octree()
        .map_err(|e| ExportError::Map(e.to_string()))?;
    Ok((tree.to_binary_stream(), tree.resolution()))
}

/// Writes `motion` to `path` in the format its ending names (`.mcap` with the map
/// when given, or `.tlog`), atomically: a reader never sees half a file, and a failed
/// export leaves no file.
pub fn export(
    motion: &Motion,
    map: Option<&Grid>,
    path: &Path,
    options: &ExportOptions,
) -> Result<Written, ExportError> {
    let (bytes, holds) = match Format::of_path(path)? {
        Format::Mcap => {
            let stream = map.map(map_stream).transpose()?;
            let (bytes, summary) = bag::bag(motion, stream.as_ref().map(|(s, r)| (&s[..], *r)))?;
            (bytes, Holds::Bag(summary))
        }
        Format::Tlog => {
            let (bytes, summary) = tlog::tlog(motion, &options.tlog)?;
            (bytes, Holds::Tlog(summary))
        }
    };
    crate::fsutil::write_atomic(path, &bytes).map_err(|source| ExportError::Io {
        path: path.display().to_string(),
        source,
    })?;
    Ok(Written {
        bytes: bytes.len(),
        holds,
    })
}
