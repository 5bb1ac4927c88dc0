//! The `arc` command line: one module per subcommand, each with its clap `Args` and a
//! `run` function. Every subcommand ends with a code of [`exit`], the one exit-code
//! table (docs/promises.md).

use std::ffi::OsString;
use std::fmt;
use std::process::ExitCode;

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};

mod bench;
mod checks;
mod common;
mod explore;
mod export;
// The library's own file helpers; it alone parses file formats, so the binary leaves
// `parse_checked` unused.
#[allow(dead_code)]
#[path = "../../fsutil.rs"]
mod fsutil;
mod map;
mod picture;
mod plan;
mod sim;
mod study;
mod tables;
mod trajectory;
mod verify;
mod view;

/// The exit-code table of every subcommand, the one place that defines it
/// (docs/promises.md repeats it for users).
pub mod exit {
    /// The job is done: a plan written, a plan verified, a flight that arrived.
    pub const DONE: u8 = 0;
    /// The job ran and the answer is no: no plan found, an invalid plan, a flight
    /// with contact or that did not arrive, a failed exact check.
    pub const FAILED: u8 = 1;
    /// Bad input: an argument out of its limits, an unreadable or malformed file, a
    /// start or goal that cannot be used, an output that cannot be written.
    pub const BAD_INPUT: u8 = 2;
}

/// What went wrong, and which exit code it earns.
#[derive(Debug)]
pub struct CliError {
    /// A code of [`exit`]: [`exit::FAILED`] or [`exit::BAD_INPUT`].
    pub code: u8,
    /// One line naming the problem (file, field, value).
    pub message: String,
}

impl CliError {
    /// Bad input: exit code 2.
    pub fn input(message: impl Into<String>) -> Self {
        Self {
            code: exit::BAD_INPUT,
            message: message.into(),
        }
    }
    /// The job ran but found no solution: exit code 1.
    pub fn failed(message: impl Into<String>) -> Self {
        Self {
            code: exit::FAILED,
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
    Shapes(tables::ShapesArgs),
    /// Plan a collision-free motion with shape changes (the ARCplanner).
    Plan(Box<plan::PlanArgs>),
    /// Check a plan or a trajectory exactly against a map (docs/model.md), independent
    /// of the planner.
    ///
    /// A trajectory is checked against the limits given here, not the ones it records.
    Verify(verify::VerifyArgs),
    /// Time a plan into a trajectory that blends through its corners (CSV or JSON).
    Trajectory(trajectory::TrajectoryArgs),
    /// Maps: export built-in scenarios as OctoMap files, inspect and draw maps.
    #[command(subcommand, after_help = "Example:\n  arc map info maps/geb079.bt")]
    Map(map::MapCommand),
    /// Benchmarks: the paper's Tables 1-3, scaling studies, full-state PRM plans.
    #[command(subcommand, after_help = "Example:\n  arc bench paper --quick")]
    Bench(bench::BenchCommand),
    /// Fly a plan: chain dynamics, head MPC, link SO(3) controllers, unit attitude loops.
    Sim(sim::SimArgs),
    /// Write one HTML page with a 3D view of a plan (and a flight) on its map.
    ///
    /// The page opens from disk in a browser, offline. Waypoint times are those `arc sim`
    /// flies with its default limits; a flight keeps its own times. `view.html#t=3.5`
    /// opens at 3.5 s.
    View(view::ViewArgs),
    /// Export a plan, trajectory or flight for robot software: a ROS 2 bag (.mcap) or
    /// per-unit MAVLink offboard setpoints (.tlog).
    Export(Box<export::ExportArgs>),
    /// Fly into the unknown: the units' sensors draw the map while the chain flies, and
    /// the online planner replans as it grows (the world map is read by the sensors only).
    Explore(Box<explore::ExploreArgs>),
}

/// The command line, where every option that takes a value takes a negative number
/// too: `--seed -1` is then refused by its own check, which names the flag, instead
/// of being read as an unknown option `-1`.
fn command() -> clap::Command {
    fn negatives(c: clap::Command) -> clap::Command {
        c.mut_args(|a| {
            if a.get_action().takes_values() {
                a.allow_negative_numbers(true)
            } else {
                a
            }
        })
        .mut_subcommands(negatives)
    }
    negatives(Cli::command())
}

/// Parses `args` (including the program name) and runs the command.
pub fn run<I, T>(args: I) -> CliResult
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    let cli = command()
        .try_get_matches_from(args)
        .and_then(|m| Cli::from_arg_matches(&m).map(|c| (c, m)))
        .map_err(|e| {
            // --help and --version are not errors.
            if matches!(
                e.kind(),
                clap::error::ErrorKind::DisplayHelp | clap::error::ErrorKind::DisplayVersion
            ) {
                let _ = e.print();
                return CliError {
                    code: exit::DONE,
                    message: String::new(),
                };
            }
            // One line: clap's first paragraph ("error: invalid value '-1' for '--seed
            // <SEED>': ..."), joined, without the usage and help after it.
            let text = e.render().to_string();
            let first: Vec<&str> = text
                .lines()
                .map(str::trim)
                .skip_while(|l| l.is_empty())
                .take_while(|l| !l.is_empty())
                .collect();
            CliError::input(first.join(" ").trim_start_matches("error: ").to_string())
        });
    let (cli, matches) = match cli {
        Ok(c) => c,
        Err(e) if e.code == exit::DONE => return Ok(()),
        Err(e) => return Err(e),
    };
    match cli.command {
        Command::Tables(c) => tables::run(c),
        Command::Shapes(a) => tables::run_shapes(a),
        Command::Plan(a) => plan::run(*a, &given(&matches, "plan")),
        Command::Verify(a) => verify::run(a),
        Command::Trajectory(a) => trajectory::run(a),
        Command::Map(c) => map::run(c),
        Command::Bench(c) => bench::run(c),
        Command::Sim(a) => sim::run(a),
        Command::View(a) => view::run(a),
        Command::Export(a) => export::run(*a),
        Command::Explore(a) => explore::run(*a, &given(&matches, "explore")),
    }
}

/// The ids of the arguments of subcommand `name` given on the command line, not left
/// at their defaults: where a settings file and a flag both set a value, the flag
/// wins (`arc plan --settings`, `arc explore --settings`).
fn given(m: &clap::ArgMatches, name: &str) -> plan::Given {
    let Some(sub) = m.subcommand_matches(name) else {
        return plan::Given::new();
    };
    sub.ids()
        .filter(|id| sub.value_source(id.as_str()) == Some(clap::parser::ValueSource::CommandLine))
        .map(|id| id.to_string())
        .collect()
}

/// Restores the default action of SIGPIPE, which Rust's runtime ignores: with it
/// ignored, a write to a closed pipe (`arc tables inspect T | head -1`) fails and
/// `println!` panics. With the default, `arc` ends quietly, as `cat` does.
fn quiet_on_closed_pipe() {
    #[cfg(unix)]
    // SAFETY: setting a signal's disposition to SIG_DFL has no preconditions, and no
    // other thread exists yet.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

/// Entry point of the `arc` binary.
fn main() -> ExitCode {
    quiet_on_closed_pipe();
    match run(std::env::args_os()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("arc: {}", e.message);
            ExitCode::from(e.code)
        }
    }
}
