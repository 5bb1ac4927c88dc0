//! `arc export`: a plan, trajectory or flight as a ROS 2 bag (`.mcap`) or as per-unit
//! MAVLink offboard setpoints (`.tlog`) (docs/model.md, "Exports").

use std::path::PathBuf;
use std::time::Instant;

use clap::{Args, ValueEnum};

use super::checks;
use super::common::{read_plan, MapArgs, Report};
use super::trajectory::{make, read_trajectory, TimingArgs};
use super::{CliError, CliResult};
use aerial_chain::export::{
    export, Autopilot, ExportOptions, Format, Holds, Motion, TlogOptions, DEFAULT_RATE_HZ,
    MAX_HOLD_S, MAX_RATE_HZ, MIN_RATE_HZ, PX4_MIN_HOLD_S, SENDER_SYSTEM,
};
use aerial_chain::sim::FlightFile;
use aerial_chain::trajectory::TrajectoryFile;

/// The autopilot a `.tlog`'s mode switch is written for.
#[derive(Clone, Copy, Debug, ValueEnum)]
enum AutopilotArg {
    /// PX4: OFFBOARD.
    Px4,
    /// ArduPilot Copter: GUIDED.
    Ardupilot,
}

/// The motion to export: one of a plan, a trajectory or a flight.
#[derive(Args, Debug)]
#[group(required = true, multiple = false)]
struct SourceArgs {
    /// A plan (arc-plan/1), timed as `arc trajectory` times it; `-` reads standard
    /// input.
    #[arg(long)]
    plan: Option<PathBuf>,
    /// A trajectory (arc-trajectory/1); `-` reads standard input.
    #[arg(long)]
    trajectory: Option<PathBuf>,
    /// A flight (arc-sim/1, `arc sim --out`); `-` reads standard input.
    #[arg(long)]
    flight: Option<PathBuf>,
}

/// `arc export`
#[derive(Args, Debug)]
#[command(after_help = "Examples:\n  \
    arc export --scenario window --plan window.json --to window.mcap\n  \
    arc export --scenario window --plan window.json --to window.tlog --arm")]
pub struct ExportArgs {
    #[command(flatten)]
    source: SourceArgs,
    #[command(flatten)]
    map: MapArgs,
    /// The output: `.mcap` (ROS 2 bag) or `.tlog` (MAVLink 2 telemetry log).
    #[arg(long)]
    to: PathBuf,
    /// Rate of the streamed messages (Hz): TF and markers in a bag, setpoints in a
    /// log; above 2 (PX4 leaves offboard below it) and at most 1000.
    #[arg(long, default_value_t = DEFAULT_RATE_HZ)]
    rate: f64,
    /// System id of unit 1 in a `.tlog`; unit i is SYSID_BASE + i - 1.
    #[arg(long, default_value_t = 1)]
    sysid_base: u8,
    /// Seconds of the start's setpoints before the motion in a `.tlog`.
    #[arg(long, default_value_t = PX4_MIN_HOLD_S)]
    hold_s: f64,
    /// Write the switch to offboard and arming after the hold (needs --hold-s >= 1).
    #[arg(long)]
    arm: bool,
    /// The autopilot the mode switch is for.
    #[arg(long, value_enum, default_value_t = AutopilotArg::Px4)]
    autopilot: AutopilotArg,
    /// How a plan is timed (as `arc trajectory`).
    #[command(flatten)]
    timing: TimingArgs,
}

/// The motion of the source, on `grid` where a plan must be timed; and its name.
fn motion(a: &ExportArgs, grid: &aerial_chain::map::Grid) -> Result<(Motion, String), CliError> {
    let s = &a.source;
    let (m, name) = match (&s.plan, &s.trajectory, &s.flight) {
        (Some(p), None, None) => {
            let settings = a.timing.settings()?;
            let (plan, name, _) = read_plan(p)?;
            let tr = make(&plan, &name, grid, &settings)?;
            (
                Motion::of_trajectory(&TrajectoryFile::new(&tr, &plan), a.rate),
                name,
            )
        }
        (None, Some(t), None) => {
            let (file, name, _) = read_trajectory(t)?;
            (Motion::of_trajectory(&file, a.rate), name)
        }
        (None, None, Some(f)) => {
            let name = crate::fsutil::input_name(f);
            let file = FlightFile::read(f).map_err(|e| CliError::input(e.to_string()))?;
            (Motion::of_flight(&file, a.rate), name)
        }
        _ => {
            return Err(CliError::input(
                "give one of --plan, --trajectory, --flight",
            ))
        }
    };
    let m = m.map_err(|e| CliError::input(format!("{name}: {e}")))?;
    Ok((m, name))
}

/// Checks every option before any work.
fn check(a: &ExportArgs) -> CliResult {
    Format::of_path(&a.to).map_err(|e| CliError::input(format!("--to {e}")))?;
    if !(a.rate > MIN_RATE_HZ && a.rate <= MAX_RATE_HZ) {
        return Err(checks::bad(
            "--rate",
            a.rate,
            &format!(
                "above {MIN_RATE_HZ} Hz (PX4 leaves offboard below it) and at most {MAX_RATE_HZ} Hz"
            ),
        ));
    }
    if !(a.hold_s >= 0.0 && a.hold_s <= MAX_HOLD_S) {
        return Err(checks::bad(
            "--hold-s",
            a.hold_s,
            &format!("a number of seconds from 0 to {MAX_HOLD_S}"),
        ));
    }
    if a.arm && a.hold_s < PX4_MIN_HOLD_S {
        return Err(checks::bad(
            "--hold-s",
            a.hold_s,
            &format!(
                "at least {PX4_MIN_HOLD_S} s with --arm: PX4 switches to offboard only after \
                 setpoints have streamed that long"
            ),
        ));
    }
    a.timing.settings()?;
    Ok(())
}

/// Checks that every unit of a chain of `units` gets a system id below the sender's.
fn check_sysids(base: u8, units: usize) -> CliResult {
    let last = base as usize + units - 1;
    if base == 0 || last >= SENDER_SYSTEM as usize {
        return Err(checks::bad(
            "--sysid-base",
            base,
            &format!(
                "from 1 to {} for {units} units (their ids must lie below {SENDER_SYSTEM}, the sender's)",
                SENDER_SYSTEM as usize - units
            ),
        ));
    }
    Ok(())
}

/// Runs `arc export`.
pub fn run(a: ExportArgs) -> CliResult {
    check(&a)?;
    let began = Instant::now();
    let loaded = a.map.load()?;
    let (motion, name) = motion(&a, &loaded.grid)?;
    check_sysids(a.sysid_base, motion.units())?;
    let options = ExportOptions {
        tlog: TlogOptions {
            sysid_base: a.sysid_base,
            hold: a.hold_s,
            arm: a.arm,
            autopilot: match a.autopilot {
                AutopilotArg::Px4 => Autopilot::Px4,
                AutopilotArg::Ardupilot => Autopilot::ArduPilot,
            },
            ..TlogOptions::default()
        },
    };
    let written = export(&motion, Some(&loaded.grid), &a.to, &options)
        .map_err(|e| CliError::input(e.to_string()))?;
    let report = Report::new(&a.to);
    report.line(format_args!(
        "exported {name} to {}: N = {}, {:.2} s at {} Hz, {} messages, {} bytes, in {:.0} ms",
        a.to.display(),
        motion.units(),
        motion.duration() - motion.ticks[0].t,
        a.rate,
        written.holds.messages(),
        written.bytes,
        began.elapsed().as_secs_f64() * 1e3
    ));
    if let Holds::Bag(bag) = &written.holds {
        let topics: Vec<String> = bag
            .topics
            .iter()
            .map(|(t, n)| format!("{t} ({n})"))
            .collect();
        report.line(format_args!("  topics: {}", topics.join(", ")));
    }
    if let Holds::Tlog(s) = &written.holds {
        report.line(format_args!(
            "  {} heartbeats, {} position setpoints, {} attitude setpoints, {} commands; units are systems {}..={}",
            s.heartbeats,
            s.position_targets,
            s.attitude_targets,
            s.commands,
            a.sysid_base,
            a.sysid_base as usize + motion.units() - 1
        ));
    }
    Ok(())
}
