//! `arc tables build|inspect` and `arc shapes` (being written).
use clap::{Args, Subcommand};

use super::{CliError, CliResult};

/// `arc tables ...`
#[derive(Subcommand, Debug)]
pub enum TablesCommand {}

/// `arc shapes ...`
#[derive(Args, Debug)]
pub struct ShapesArgs {}

pub fn run(c: TablesCommand) -> CliResult {
    match c {}
}

pub fn run_shapes(_a: ShapesArgs) -> CliResult {
    Err(CliError::input("not yet"))
}
