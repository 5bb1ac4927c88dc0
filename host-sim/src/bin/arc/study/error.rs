//! Why a benchmark could not run, as a type the command line maps onto its exit codes.

use std::path::PathBuf;

use aerial_chain::collision::ContextError;
use aerial_chain::problem::ProblemError;
use aerial_chain_core::ParamError;

use crate::{exit, CliError};

/// What stops a study before or while its runs go (a run whose planner fails is a
/// result, not an error).
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// A scenario that cannot be built.
    #[error(transparent)]
    Scenario(#[from] ProblemError),
    /// A `window-wide:W` whose opening is not a number in range.
    #[error("{name}: {why}")]
    WideWindow {
        /// The scenario name as given.
        name: String,
        /// What is wrong with the opening.
        why: String,
    },
    /// A scenario a run names that was not built for it.
    #[error("scenario {0} not built")]
    NotBuilt(String),
    /// A chain size the core refuses.
    #[error("N = {units}: {why}")]
    Chain {
        /// The chain size.
        units: u8,
        /// Why (the core's errors are `no_std`: no `std::error::Error` source).
        why: ParamError,
    },
    /// Shape tables that cannot be built for a chain.
    #[error("shape tables of N = {units}: {why}")]
    Tables {
        /// The chain size.
        units: u8,
        /// Why.
        why: String,
    },
    /// A query the facade refuses as bad input (its start or goal, its options).
    #[error("{scenario}: {why}")]
    Refused {
        /// The scenario.
        scenario: String,
        /// Why.
        why: String,
    },
    /// A collision context that cannot be made.
    #[error(transparent)]
    Context(#[from] ContextError),
    /// No library shape fits near the scenario's start for a long chain.
    #[error("no library shape of N = {units} fits within 1.5 m of {scenario}'s start")]
    NoFittingStart {
        /// The chain size.
        units: u8,
        /// The scenario.
        scenario: String,
    },
    /// The worker threads could not be started.
    #[error("thread pool: {0}")]
    ThreadPool(#[from] rayon::ThreadPoolBuildError),
    /// The progress display's template does not parse.
    #[error("{0}")]
    Progress(#[from] indicatif::style::TemplateError),
    /// An output file or its directory cannot be written.
    #[error("{}: {source}", path.display())]
    Write {
        /// The file or directory.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
}

impl StudyError {
    /// The code of [`exit`] this error ends `arc` with: every one of them is bad input
    /// (a name, a size or an output the study cannot use) or a machine that cannot
    /// start the study, which the table counts as bad input too.
    pub fn exit_code(&self) -> u8 {
        match self {
            StudyError::Scenario(_)
            | StudyError::WideWindow { .. }
            | StudyError::NotBuilt(_)
            | StudyError::Chain { .. }
            | StudyError::Tables { .. }
            | StudyError::Refused { .. }
            | StudyError::Context(_)
            | StudyError::NoFittingStart { .. }
            | StudyError::ThreadPool(_)
            | StudyError::Progress(_)
            | StudyError::Write { .. } => exit::BAD_INPUT,
        }
    }
}

impl From<StudyError> for CliError {
    fn from(e: StudyError) -> Self {
        CliError {
            code: e.exit_code(),
            message: e.to_string(),
        }
    }
}
