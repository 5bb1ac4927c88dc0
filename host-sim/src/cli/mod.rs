//! The `arc` command line: one module per subcommand, each with its clap `Args` and a
//! `run` function. Exit codes: 0 success, 1 the job found no solution (no plan, a
//! failed verification or flight), 2 bad input (arguments, files).

use std::ffi::OsString;
use std::fmt;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

mod bench;
pub mod common;
mod map;
mod plan;
mod sim;
mod tables;
mod verify;

/// What went wrong, and which exit code it earns.
#[derive(Debug)]
pub struct CliError {
    /// 1: no solution; 2: bad input.
    pub code: u8,
    /// One line naming the problem (file, field, value).
    pub message: String,
}

impl CliError {
    /// Bad input: exit code 2.
    pub fn input(message: impl Into<String>) -> Self {
        Self {
            code: 2,
            message: message.into(),
        }
    }
    /// The job ran but found no solution: exit code 1.
    pub fn failed(message: impl Into<String>) -> Self {
        Self {
            code: 1,
            message: message.into(),
        }
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for CliError {}

/// Result of a subcommand.
pub type CliResult = Result<(), CliError>;

/// The Aerial Robotic Chain: plan, verify, fly and benchmark.
#[derive(Parser, Debug)]
#[command(name = "arc", version, about)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Build or inspect shape tables (LSC + SRS + G_SRS, postcard, CRC-checked).
    #[command(
        subcommand,
        after_help = "Example:\n  arc tables build --units 6 --out n6.arct"
    )]
    Tables(tables::TablesCommand),
    /// Draw the shape library (LSC) in top and side view.
    #[command(after_help = "Example:\n  arc shapes --units 6 --out lsc.svg")]
    Shapes(tables::ShapesArgs),
    /// Plan a collision-free motion with shape changes (the ARCplanner).
    #[command(
        after_help = "Example:\n  arc plan --scenario window --units 5 --out window.json --picture window.svg"
    )]
    Plan(Box<plan::PlanArgs>),
    /// Check a plan exactly against a map (docs/model.md), independent of the planner.
    #[command(after_help = "Example:\n  arc verify --scenario window --plan window.json")]
    Verify(verify::VerifyArgs),
    /// Maps: export built-in scenarios as OctoMap files, inspect and draw maps.
    #[command(subcommand, after_help = "Example:\n  arc map info maps/geb079.bt")]
    Map(map::MapCommand),
    /// Benchmarks: the paper's Tables 1-3, scaling studies, full-state PRM plans.
    #[command(subcommand, after_help = "Example:\n  arc bench paper --quick")]
    Bench(bench::BenchCommand),
    /// Fly a plan: chain dynamics, head MPC, link SO(3) controllers, unit attitude loops.
    #[command(
        after_help = "Example:\n  arc sim --scenario window --plan window.json --picture flight.svg"
    )]
    Sim(sim::SimArgs),
}

/// Parses `args` (including the program name) and runs the command.
pub fn run<I, T>(args: I) -> CliResult
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    let cli = Cli::try_parse_from(args).map_err(|e| {
        // --help and --version are not errors.
        if matches!(
            e.kind(),
            clap::error::ErrorKind::DisplayHelp | clap::error::ErrorKind::DisplayVersion
        ) {
            let _ = e.print();
            return CliError {
                code: 0,
                message: String::new(),
            };
        }
        CliError::input(e.render().to_string().trim_end().to_string())
    });
    let cli = match cli {
        Ok(c) => c,
        Err(e) if e.code == 0 => return Ok(()),
        Err(e) => return Err(e),
    };
    match cli.command {
        Command::Tables(c) => tables::run(c),
        Command::Shapes(a) => tables::run_shapes(a),
        Command::Plan(a) => plan::run(*a),
        Command::Verify(a) => verify::run(a),
        Command::Map(c) => map::run(c),
        Command::Bench(c) => bench::run(c),
        Command::Sim(a) => sim::run(a),
    }
}

/// Entry point of the `arc` binary.
pub fn main() -> ExitCode {
    match run(std::env::args_os()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("arc: {}", e.message);
            ExitCode::from(e.code)
        }
    }
}
