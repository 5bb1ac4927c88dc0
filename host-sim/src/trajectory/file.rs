//! The trajectory file: JSON, `"format": "arc-trajectory/1"`, and a CSV form of its
//! samples (docs/model.md, "Trajectories").
//!
//! Numbers are written as the shortest decimal that reads back as the same `f64`, so
//! a checker reads exactly the samples that were checked when they were made.

use std::fmt::Write as _;
use std::path::Path;

use aerial_chain_core::ChainParams;
use serde::{Deserialize, Serialize};

use super::{ChainSection, FormatError, Limits, MapSection, Plan, Trajectory};
use crate::collision::exact::positions_f64;
use crate::fsutil;

/// The format tag every trajectory file carries.
pub const FORMAT: &str = "arc-trajectory/1";

/// How far a recorded unit position or attitude may lie from the one `zeta` gives.
const RECORD_TOLERANCE: f64 = 1e-6;

/// One sample: time, configuration, and every unit's position and attitude.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SampleRow {
    /// Time since the start (s).
    pub t: f64,
    /// The configuration (angles continuous, not wrapped to a turn).
    pub zeta: Vec<f64>,
    /// Every unit centre (m, world frame), head first.
    pub p: Vec<[f64; 3]>,
    /// Every unit's heading as a unit quaternion `[w, x, y, z]` (body to world): a
    /// rotation about z by the head's yaw; tilt is the controller's.
    pub q: Vec<[f64; 4]>,
}

/// Summary numbers of a trajectory (free-form for readers).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TrajectoryStats {
    /// Flight time (s): the last sample's time.
    pub duration_s: f64,
    /// The same plan flown stopping at every waypoint (s).
    pub stop_go_s: f64,
    /// Length of the head's path (m).
    pub head_path_m: f64,
    /// Places where two edges meet.
    pub corners: usize,
    /// Corners flown blended.
    pub blended: usize,
    /// Corners flown as one move with the edge before them (merged edges, and turns of
    /// the head yaw alone flown during the edges before them).
    #[serde(default)]
    pub merged: usize,
}

/// A trajectory as stored in the file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrajectoryFile {
    /// Always [`FORMAT`].
    pub format: String,
    /// The chain (as in a plan).
    pub chain: ChainSection,
    /// The map assumptions (as in the plan it was made from).
    pub map: MapSection,
    /// The limits it was made within (a record: a checker takes its own).
    pub limits: Limits,
    /// Sample spacing (s).
    pub dt: f64,
    /// Summary numbers.
    #[serde(default)]
    pub stats: TrajectoryStats,
    /// The samples, in time order.
    pub samples: Vec<SampleRow>,
}

/// Why a trajectory file (or a flight file, `sim::FlightFile`) cannot be read, used or
/// written.
#[derive(Debug, thiserror::Error)]
pub enum FileError {
    /// The file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        source: std::io::Error,
    },
    /// Not JSON of the file's shape, or a rule of the format broken; the text says
    /// which, and names the field and value.
    #[error("{path}: {what}")]
    Invalid {
        /// The file.
        path: String,
        /// What is wrong.
        what: String,
    },
}

impl FileError {
    /// Reads the file at `path` (`-`: standard input) and gives its text and name to
    /// `parse`; a file that cannot be read is [`FileError::Io`].
    pub(crate) fn read<T>(
        path: &Path,
        parse: impl FnOnce(&str, &str) -> Result<T, FileError>,
    ) -> Result<T, FileError> {
        let name = fsutil::input_name(path);
        match fsutil::read_input(path) {
            Ok(text) => parse(&text, &name),
            Err(source) => Err(FileError::Io { path: name, source }),
        }
    }

    /// What a file `name` that breaks its format is, given what is wrong.
    pub(crate) fn invalid(name: &str) -> impl FnOnce(String) -> FileError + '_ {
        |what| FileError::Invalid {
            path: name.to_string(),
            what,
        }
    }
}

/// A rule of the `arc-trajectory/1` format that needs no map, broken: each names the
/// field and the value at fault.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SampleError {
    /// Another format or version.
    #[error("format = {0:?}, expected {FORMAT:?}")]
    Format(String),
    /// The chain or map section, as a plan file's rules have it.
    #[error(transparent)]
    Section(#[from] FormatError),
    /// A trajectory without samples.
    #[error("samples is empty")]
    NoSamples,
    /// A time or a `zeta` that is not finite, or a `zeta` of the wrong length.
    #[error(
        "samples[{index}]: t and zeta must be finite, zeta {expected} numbers for N = {units}"
    )]
    Zeta {
        /// The sample.
        index: usize,
        /// Numbers a configuration of this chain has (`2N + 2`).
        expected: usize,
        /// The chain's units.
        units: usize,
    },
    /// Unit positions or attitudes not one per unit.
    #[error("samples[{index}]: p and q must have {units} entries")]
    Entries {
        /// The sample.
        index: usize,
        /// The chain's units.
        units: usize,
    },
    /// A recorded unit position that is not where `zeta` puts the unit.
    #[error("samples[{index}].p[{unit}] is not where zeta puts unit {}", unit + 1)]
    Position {
        /// The sample.
        index: usize,
        /// The unit (0-based).
        unit: usize,
    },
    /// A recorded unit attitude that is not the head's yaw.
    #[error("samples[{index}].q[{unit}] is not the head's yaw zeta[3] = {yaw}")]
    Attitude {
        /// The sample.
        index: usize,
        /// The unit (0-based).
        unit: usize,
        /// The head's yaw in the sample (rad).
        yaw: f64,
    },
}

/// Quaternion `[w, x, y, z]` of a rotation by `yaw` about z.
fn yaw_quaternion(yaw: f64) -> [f64; 4] {
    [(yaw / 2.0).cos(), 0.0, 0.0, (yaw / 2.0).sin()]
}

impl TrajectoryFile {
    /// The file of `trajectory`, made from `plan` (whose map section it keeps).
    pub fn new(trajectory: &Trajectory, plan: &Plan) -> Self {
        let params = trajectory.params();
        let l = params.link_length as f64;
        let samples = trajectory
            .times()
            .iter()
            .zip(trajectory.zetas())
            .map(|(t, z)| SampleRow {
                t: *t,
                zeta: z.clone(),
                p: positions_f64(l, [z[0], z[1], z[2]], &z[3..])
                    .into_iter()
                    .map(Into::into)
                    .collect(),
                q: vec![yaw_quaternion(z[3]); params.n()],
            })
            .collect();
        Self {
            format: FORMAT.into(),
            chain: ChainSection::from_params(params),
            map: plan.map.clone(),
            limits: trajectory.settings().limits,
            dt: trajectory.settings().dt,
            stats: TrajectoryStats {
                duration_s: trajectory.duration(),
                stop_go_s: trajectory.stop_go_duration(),
                head_path_m: trajectory.head_path_m(),
                corners: trajectory.corners(),
                blended: trajectory.blended(),
                merged: trajectory.merged(),
            },
            samples,
        }
    }

    /// Sample times.
    pub fn times(&self) -> Vec<f64> {
        self.samples.iter().map(|s| s.t).collect()
    }

    /// `zeta` of every sample.
    pub fn zetas(&self) -> Vec<Vec<f64>> {
        self.samples.iter().map(|s| s.zeta.clone()).collect()
    }

    /// Reads and checks a trajectory file (`-`: standard input).
    pub fn read(path: &Path) -> Result<Self, FileError> {
        FileError::read(path, Self::parse)
    }

    /// Parses and checks a trajectory's text; `name` names it in errors.
    pub fn parse(text: &str, name: &str) -> Result<Self, FileError> {
        fsutil::parse_checked(text, FORMAT, Self::check).map_err(FileError::invalid(name))
    }

    /// Checks the format's rules that need no map: the tag, the chain, at least one
    /// sample, every `zeta` of the chain's length and finite, and the recorded unit
    /// positions and attitudes those `zeta` give (within 1e-6). Time order and the
    /// motion itself are [`super::check_samples`]'s.
    pub fn check(&self) -> Result<ChainParams, SampleError> {
        if self.format != FORMAT {
            return Err(SampleError::Format(self.format.clone()));
        }
        let params = self.chain.to_params()?;
        if !(self.map.resolution.is_finite() && self.map.resolution > 0.0) {
            return Err(FormatError::Resolution(self.map.resolution).into());
        }
        if self.samples.is_empty() {
            return Err(SampleError::NoSamples);
        }
        let n = params.n();
        let l = params.link_length as f64;
        for (i, s) in self.samples.iter().enumerate() {
            let z = &s.zeta;
            if z.len() != 2 * n + 2 || z.iter().chain([&s.t]).any(|v| !v.is_finite()) {
                return Err(SampleError::Zeta {
                    index: i,
                    expected: 2 * n + 2,
                    units: n,
                });
            }
            if s.p.len() != n || s.q.len() != n {
                return Err(SampleError::Entries { index: i, units: n });
            }
            let p = positions_f64(l, [z[0], z[1], z[2]], &z[3..]);
            let q = yaw_quaternion(z[3]);
            for (u, pu) in p.iter().enumerate() {
                let dp = (0..3)
                    .map(|k| (pu[k] - s.p[u][k]).abs())
                    .fold(0.0, f64::max);
                // q and -q are the same attitude.
                let dq = |sign: f64| {
                    (0..4)
                        .map(|k| (q[k] - sign * s.q[u][k]).abs())
                        .fold(0.0, f64::max)
                };
                if dp.is_nan() || dp > RECORD_TOLERANCE {
                    return Err(SampleError::Position { index: i, unit: u });
                }
                let off = dq(1.0).min(dq(-1.0));
                if off.is_nan() || off > RECORD_TOLERANCE {
                    return Err(SampleError::Attitude {
                        index: i,
                        unit: u,
                        yaw: z[3],
                    });
                }
            }
        }
        Ok(params)
    }

    /// The samples as CSV: a header, then one row per sample: `t`, `zeta`, and every
    /// unit's `x, y, z, qw, qx, qy, qz`.
    pub fn to_csv(&self) -> String {
        let n = self.chain.units as usize;
        let mut out = String::from("t,x1,y1,z1,psi1_r");
        for k in 1..n {
            let _ = write!(out, ",theta{k},psi{k}");
        }
        for u in 1..=n {
            for c in ["x", "y", "z", "qw", "qx", "qy", "qz"] {
                let _ = write!(out, ",u{u}_{c}");
            }
        }
        out.push('\n');
        for s in &self.samples {
            let _ = write!(out, "{}", s.t);
            for v in &s.zeta {
                let _ = write!(out, ",{v}");
            }
            for (p, q) in s.p.iter().zip(&s.q) {
                for v in p.iter().chain(q) {
                    let _ = write!(out, ",{v}");
                }
            }
            out.push('\n');
        }
        out
    }

    /// Writes the file atomically (`-`: standard output): CSV when the name ends in
    /// `.csv`, else JSON.
    pub fn write(&self, path: &Path) -> Result<(), FileError> {
        let csv = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("csv"));
        let text = if csv {
            self.to_csv()
        } else {
            let mut t = serde_json::to_string(self).expect("a trajectory always serialises");
            t.push('\n');
            t
        };
        fsutil::write_output(path, text.as_bytes()).map_err(|source| FileError::Io {
            path: fsutil::output_name(path),
            source,
        })
    }
}
