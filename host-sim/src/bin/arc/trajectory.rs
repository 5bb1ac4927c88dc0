//! `arc trajectory`: a plan timed into a trajectory that blends through its corners;
//! the limit flags shared with `arc plan --trajectory`, `arc sim` and `arc verify
//! --trajectory`.

use std::path::{Path, PathBuf};

use aerial_chain_core::ChainParams;
use clap::Args;

use super::checks;
use super::common::{read_plan, MapArgs, Report};
use super::{CliError, CliResult};
use aerial_chain::map::Grid;
use aerial_chain::plan_file::Plan;
use aerial_chain::trajectory::{
    self, Limits, Settings, Trajectory, TrajectoryError, TrajectoryFile,
};

/// The limits a trajectory keeps (docs/model.md, "Trajectories"); `arc sim`'s defaults.
#[derive(Args, Debug, Clone)]
pub struct LimitArgs {
    /// Largest speed of any unit (m/s).
    #[arg(long, default_value_t = 0.5)]
    pub speed: f64,
    /// Largest head acceleration (m/s^2).
    #[arg(long, default_value_t = 0.5)]
    pub accel: f64,
    /// Largest rate of any link angle, pitch or yaw (degrees/s).
    #[arg(long, default_value_t = 0.4f64.to_degrees())]
    pub angular_rate_deg: f64,
    /// Largest angular acceleration of any link angle (degrees/s^2).
    #[arg(long, default_value_t = 0.5f64.to_degrees())]
    pub angular_accel_deg: f64,
    /// Largest rate of the head yaw, the heading every unit holds (degrees/s; PX4's
    /// MPC_YAWRAUTO_MAX).
    #[arg(long, default_value_t = trajectory::DEFAULT_YAW_RATE_DEG)]
    pub yaw_rate_deg: f64,
    /// Largest angular acceleration of the head yaw (degrees/s^2; PX4's
    /// MPC_YAWRAUTO_ACC).
    #[arg(long, default_value_t = trajectory::DEFAULT_YAW_ACCEL_DEG)]
    pub yaw_accel_deg: f64,
}

impl LimitArgs {
    /// The limits, each checked.
    pub fn limits(&self) -> Result<Limits, CliError> {
        checks::positive("--speed", self.speed)?;
        checks::positive("--accel", self.accel)?;
        checks::positive("--angular-rate-deg", self.angular_rate_deg)?;
        checks::positive("--angular-accel-deg", self.angular_accel_deg)?;
        checks::positive("--yaw-rate-deg", self.yaw_rate_deg)?;
        checks::positive("--yaw-accel-deg", self.yaw_accel_deg)?;
        Ok(Limits {
            speed: self.speed,
            accel: self.accel,
            angular_rate: self.angular_rate_deg.to_radians(),
            angular_accel: self.angular_accel_deg.to_radians(),
            yaw_rate: self.yaw_rate_deg.to_radians(),
            yaw_accel: self.yaw_accel_deg.to_radians(),
        })
    }
}

/// How a trajectory is made from a plan: limits, sample spacing, blends.
#[derive(Args, Debug, Clone)]
pub struct TimingArgs {
    #[command(flatten)]
    pub limits: LimitArgs,
    /// Time between trajectory samples (s), in (0, 0.1].
    #[arg(long, default_value_t = trajectory::DEFAULT_DT)]
    pub dt: f64,
    /// Stop at every waypoint instead of blending through corners.
    #[arg(long)]
    pub no_blend: bool,
}

impl TimingArgs {
    /// The settings, each checked.
    pub fn settings(&self) -> Result<Settings, CliError> {
        let limits = self.limits.limits()?;
        if !(self.dt.is_finite() && self.dt > 0.0 && self.dt <= 0.1) {
            return Err(checks::bad("--dt", self.dt, "in (0, 0.1] s"));
        }
        Ok(Settings {
            limits,
            dt: self.dt,
            blend: !self.no_blend,
            ..Settings::default()
        })
    }
}

/// `arc trajectory`
#[derive(Args, Debug)]
#[command(
    after_help = "Example:\n  arc trajectory --scenario window --plan window.json --out window-t.json"
)]
pub struct TrajectoryArgs {
    #[command(flatten)]
    map: MapArgs,
    /// The plan (JSON, arc-plan/1); `-` reads it from standard input.
    #[arg(long)]
    plan: PathBuf,
    /// Output trajectory: CSV when the name ends in .csv, else JSON
    /// (arc-trajectory/1); `-` writes JSON to standard output.
    #[arg(long)]
    out: PathBuf,
    #[command(flatten)]
    timing: TimingArgs,
}

/// Makes the trajectory of `plan` on `grid`; `name` names the plan in errors.
pub fn make(
    plan: &Plan,
    name: &str,
    grid: &Grid,
    settings: &Settings,
) -> Result<Trajectory, CliError> {
    trajectory::build(plan, grid, settings).map_err(|e| refused(e, name))
}

/// Why a trajectory of the plan `name` could not be made, with its exit code: an
/// inadmissible plan is a "no" (1), everything else bad input (2).
pub fn refused(e: TrajectoryError, name: &str) -> CliError {
    match e {
        TrajectoryError::Inadmissible(_) => CliError::failed(format!("{name}: {e}")),
        TrajectoryError::TooLong(_) => CliError::input(format!(
            "{name}: {e}, the memory budget; the length follows from the plan, --speed, \
             --accel, --angular-rate-deg, --angular-accel-deg, --yaw-rate-deg, \
             --yaw-accel-deg and --dt"
        )),
        _ => CliError::input(format!("{name}: {e}")),
    }
}

/// Writes `tr` (made from `plan`) to `out` and says what it is.
pub fn write(tr: &Trajectory, plan: &Plan, out: &Path, report: &Report) -> CliResult {
    TrajectoryFile::new(tr, plan)
        .write(out)
        .map_err(|e| CliError::input(e.to_string()))?;
    report.line(format_args!(
        "  trajectory {}: {:.2} s ({:.2} s stopping at every waypoint), {} of {} corners blended, {} corners merged, head path {:.2} m, {} samples",
        crate::fsutil::output_name(out),
        tr.duration(),
        tr.stop_go_duration(),
        tr.blended(),
        tr.corners(),
        tr.merged(),
        tr.head_path_m(),
        tr.times().len()
    ));
    let stages: Vec<String> = tr
        .stages()
        .reports()
        .iter()
        .map(|r| {
            format!(
                "{} {:.1} ms, {} rounds, {} {}",
                r.stage.name(),
                r.time_s * 1e3,
                r.rounds,
                r.used,
                r.stage.unit()
            )
        })
        .collect();
    report.line(format_args!(
        "  trajectory stages (each round in this order): {}",
        stages.join("; ")
    ));
    if tr.cut_short() {
        report.line(format_args!(
            "  trajectory: the time limit stopped the blending rounds; the plan is flown stop and go"
        ));
    }
    Ok(())
}

/// Reads a trajectory file (`-`: standard input) and checks its format: the file, its
/// name for messages, its chain.
pub fn read_trajectory(path: &Path) -> Result<(TrajectoryFile, String, ChainParams), CliError> {
    let name = crate::fsutil::input_name(path);
    let text =
        crate::fsutil::read_input(path).map_err(|e| CliError::input(format!("{name}: {e}")))?;
    let file = TrajectoryFile::parse(&text, &name).map_err(|e| CliError::input(e.to_string()))?;
    let params = file
        .check()
        .map_err(|e| CliError::input(format!("{name}: {e}")))?;
    Ok((file, name, params))
}

/// Runs `arc trajectory`.
pub fn run(a: TrajectoryArgs) -> CliResult {
    let settings = a.timing.settings()?;
    let (plan, name, _) = read_plan(&a.plan)?;
    let loaded = a.map.load()?;
    let tr = make(&plan, &name, &loaded.grid, &settings)?;
    write(&tr, &plan, &a.out, &Report::new(&a.out))
}
