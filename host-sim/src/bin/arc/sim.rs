//! `arc sim`: fly a plan with the chain's dynamics and control stack, on a map.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use clap::Args;

use super::checks;
use super::common::{looser_assumption, read_plan, MapArgs, MotionArgs, MotionFile, Report};
use super::trajectory::{read_trajectory, TimingArgs};
use super::{CliError, CliResult};
use aerial_chain::flying::{self, FlyError, FlyOptions, Timed, Timing};
use aerial_chain::map::Grid;
use aerial_chain::plan_file::Plan;
use aerial_chain::plan_picture::{flight_svg, footprint};
use aerial_chain::sim::MapClearance;
use aerial_chain::sim::Reference;
use aerial_chain::sim::V3;
use aerial_chain::sim::{simulate_reference, FlightFile, Gust, Progress, SimConfig};

/// `arc sim`
#[derive(Args, Debug)]
#[command(
    after_help = "Example:\n  arc sim --scenario window --plan window.json --picture flight.svg"
)]
pub struct SimArgs {
    #[command(flatten)]
    map: MapArgs,
    #[command(flatten)]
    motion: MotionArgs,
    /// Write the flight (report and recorded states) as JSON; `-` writes it to
    /// standard output.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Write plots of the flight (.svg or .png), or an animation of it (.gif, one
    /// frame per --frame-step).
    #[arg(long)]
    picture: Option<PathBuf>,
    /// Seconds of flight between an animation's frames [default: 0.1 s or more, for
    /// at most about 120 frames].
    #[arg(long, allow_hyphen_values = true)]
    frame_step: Option<f64>,
    /// Physics and control rate (Hz, at least 500).
    #[arg(long, default_value_t = 500.0)]
    rate: f64,
    /// How the plan is timed: by default a trajectory that blends through corners
    /// where that is admissible (as `arc trajectory`); `--no-blend` stops at every
    /// waypoint.
    #[command(flatten)]
    timing: TimingArgs,
    /// Distance of the head from the plan's last waypoint that counts as arrived (m).
    #[arg(long, default_value_t = 0.1)]
    goal_tol: f64,
    /// Longest time after the plan's end to arrive (s).
    #[arg(long, default_value_t = 10.0)]
    settle_time: f64,
    /// A gust `START,DURATION,FX,FY,FZ` (s, s, N) on every unit; repeatable.
    #[arg(long, allow_hyphen_values = true)]
    gust: Vec<String>,
    /// Keep one recorded step in this many in the JSON output.
    #[arg(long, default_value_t = 10)]
    record_every: usize,
    /// Write the map the units' depth sensors saw along the flight (.bt, OctoMap's
    /// fusion; docs/maps.md, "Sensing").
    #[arg(long)]
    map_out: Option<PathBuf>,
    /// Scans per second of every unit's sensor, with --map-out (Hz).
    #[arg(long, default_value_t = aerial_chain::sensing::survey::DEFAULT_RATE_HZ)]
    sensor_rate: f64,
}

fn parse_gust(s: &str) -> Result<Gust, CliError> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|e| CliError::input(format!("--gust {s:?}: {e}")))?;
    if v.len() != 5 || v.iter().any(|x| !x.is_finite()) || v[1] <= 0.0 {
        return Err(CliError::input(format!(
            "--gust {s:?}: expected START,DURATION,FX,FY,FZ with a positive duration"
        )));
    }
    Ok(Gust {
        start: v[0],
        duration: v[1],
        unit: None,
        force: V3::new(v[2], v[3], v[4]),
    })
}

/// Runs `job` with a progress bar on standard error while it flies, when standard
/// error is a terminal (a log file gets no bar).
fn with_progress<T>(job: impl FnOnce(&Progress) -> T) -> T {
    let progress = Progress::default();
    if !std::io::stderr().is_terminal() {
        return job(&progress);
    }
    /// Stops the bar however the job ends (a panic included), so the scope can join it.
    struct Finish<'a>(&'a AtomicBool);
    impl Drop for Finish<'_> {
        fn drop(&mut self) {
            self.0.store(true, Ordering::Relaxed);
        }
    }
    let finished = AtomicBool::new(false);
    std::thread::scope(|s| {
        s.spawn(|| {
            let bar = indicatif::ProgressBar::new(0);
            bar.set_style(
                indicatif::ProgressStyle::with_template(
                    "flying [{bar:40}] {percent}% of the longest flight ({eta})",
                )
                .expect("static template")
                .progress_chars("=> "),
            );
            while !finished.load(Ordering::Relaxed) {
                bar.set_length(progress.total.load(Ordering::Relaxed));
                bar.set_position(progress.done.load(Ordering::Relaxed));
                std::thread::sleep(Duration::from_millis(100));
            }
            bar.finish_and_clear();
        });
        let _finish = Finish(&finished);
        job(&progress)
    })
}

/// Checks every option before any work (docs/promises.md); the flight's length
/// against the memory budget is checked once the plan is timed.
fn check(a: &SimArgs) -> Result<(), CliError> {
    if !(a.rate.is_finite() && (500.0..=20_000.0).contains(&a.rate)) {
        return Err(checks::bad("--rate", a.rate, "between 500 and 20000 Hz"));
    }
    a.timing.settings()?;
    checks::positive("--goal-tol", a.goal_tol)?;
    checks::positive("--settle-time", a.settle_time)?;
    if a.record_every == 0 {
        return Err(checks::bad("--record-every", 0, "at least 1"));
    }
    checks::sensor_rate(a.sensor_rate)?;
    if let Some(p) = &a.map_out {
        let bt = p.extension().is_some_and(|e| e.eq_ignore_ascii_case("bt"));
        if !bt {
            return Err(CliError::input(format!(
                "--map-out {}: the seen map is written as an OctoMap .bt file",
                p.display()
            )));
        }
    }
    super::picture::check(a.picture.as_ref(), a.frame_step)
}

/// Runs `arc sim`: exit 0 only when the chain reaches the plan's goal without touching
/// the map or itself.
pub fn run(a: SimArgs) -> CliResult {
    check(&a)?;
    let options = FlyOptions {
        sim: sim_config(&a)?,
        timing: a.timing.settings()?,
    };
    // As the flight will be configured: the timing's limits in the simulation's.
    let cfg = options.sim_config();
    cfg.validate()
        .map_err(|e| CliError::input(format!("simulation settings: {e}")))?;
    // With `--out -` the flight is standard output; the report goes to standard error.
    let report = Report::new(a.out.as_deref().unwrap_or(Path::new("")));
    let say = |args: std::fmt::Arguments<'_>| report.line(args);
    let (plan_name, waypoints, params, looser, loaded, motion) = match a.motion.file()? {
        MotionFile::Plan(path) => {
            let (plan, name, params) = read_plan(path)?;
            // The flight is judged under the user's assumption about unknown space,
            // never the plan's: a plan made with looser assumptions fails (docs/model.md).
            let looser = looser_assumption(&plan, &a.map);
            let loaded = a.map.load()?;
            let timed = timed(&options, &plan, &name, &loaded.grid, &say)?;
            let count = plan.waypoints.len();
            (
                name,
                count,
                params,
                looser,
                loaded,
                Motion::Plan(Box::new((plan, timed))),
            )
        }
        MotionFile::Trajectory(path) => {
            let (file, name, params) = read_trajectory(path)?;
            let looser = (!file.map.unknown_is_occupied && !a.map.unknown_free).then(|| {
                "the trajectory was made with unknown space free; fly it with --unknown-free"
                    .to_string()
            });
            let loaded = a.map.load()?;
            let r = Reference::from_samples(params.n(), &file.times(), &file.zetas())
                .map_err(|e| CliError::input(format!("{name}: {e}")))?;
            say(format_args!(
                "  timing: the trajectory's own, {:.2} s",
                r.duration()
            ));
            (
                name,
                file.samples.len(),
                params,
                looser,
                loaded,
                Motion::Trajectory(r),
            )
        }
    };
    let grid = &loaded.grid;
    let flight = with_progress(|progress| match &motion {
        Motion::Plan(p) => flying::fly_timed(&p.0, &p.1, grid, &options, progress),
        Motion::Trajectory(r) => {
            let obstacles = MapClearance::new(grid, &params);
            simulate_reference(&params, r, &cfg, Some(&obstacles), progress).map_err(Into::into)
        }
    })
    .map_err(|e| CliError::input(format!("{plan_name}: {e}")))?;
    let r = &flight.report;
    say_report(&say, &plan_name, waypoints, r);
    if let Some(path) = &a.out {
        write_flight(path, &a, &plan_name, &flight)?;
        if !crate::fsutil::is_stdio(path) {
            say(format_args!("  wrote {}", path.display()));
        }
    }
    if let Some(path) = &a.map_out {
        write_seen_map(path, &a, &loaded.grid, &params, &flight, &say)?;
    }
    if let Some(path) = a
        .picture
        .as_ref()
        .filter(|p| super::picture::is_animation(p))
    {
        let opts = aerial_chain::plan_picture::AnimationOptions {
            title: format!("arc sim: {plan_name} on {}", a.map.name()),
            goal: flight
                .samples
                .last()
                .map(|s| (s.head_ref.map(f64::from).into(), a.goal_tol)),
            step: a.frame_step,
            planned_label: "head reference".into(),
        };
        let motion = aerial_chain::plan_picture::Motion::of_flight(&flight);
        let (frames, step) = super::picture::write_animation(path, &loaded.grid, &motion, &opts)?;
        say(format_args!(
            "  wrote {} ({frames} frames, one per {step} s of flight)",
            path.display()
        ));
    } else if let Some(path) = &a.picture {
        draw_flight(
            path,
            &flight,
            &loaded.grid,
            &params,
            &format!("arc sim: {plan_name} on {}", a.map.name()),
        )?;
        say(format_args!("  wrote {}", path.display()));
    }
    if let Some(why) = looser {
        return Err(CliError::failed(format!("{plan_name}: {why}")));
    }
    if r.success() {
        return Ok(());
    }
    Err(CliError::failed(format!(
        "{plan_name}: {}",
        why_failed(r, cfg.settle_time)
    )))
}

/// What is flown: a plan as `arc sim` times it, or a trajectory file's motion.
enum Motion {
    Plan(Box<(Plan, Timed)>),
    Trajectory(Reference),
}

/// The plan timed for its flight (`flying::time`): the trajectory made from it and
/// checked exactly on the map, unless `--no-blend` asks for the stop at every
/// waypoint; a plan that is not admissible as a trajectory is flown stopping at every
/// waypoint, and the report says why.
fn timed(
    options: &FlyOptions,
    plan: &Plan,
    plan_name: &str,
    grid: &Grid,
    say: &dyn Fn(std::fmt::Arguments<'_>),
) -> Result<Timed, CliError> {
    let timed = flying::time(plan, grid, options).map_err(|e| match e {
        FlyError::Trajectory(e) => super::trajectory::refused(e, plan_name),
        e => CliError::input(format!("{plan_name}: {e}")),
    })?;
    match &timed.timing {
        Timing::Trajectory(tr) => say(format_args!(
            "  timing: trajectory of {:.2} s ({:.2} s stopping at every waypoint), {} of {} corners blended, {} corners merged",
            tr.duration(),
            tr.stop_go_duration(),
            tr.blended(),
            tr.corners(),
            tr.merged()
        )),
        Timing::StopAtWaypoints(Some(v)) => say(format_args!(
            "  timing: stopping at every waypoint: the plan is not admissible as a trajectory ({v})"
        )),
        Timing::StopAtWaypoints(None) => say(format_args!(
            "  timing: stopping at every waypoint (--no-blend)"
        )),
    }
    Ok(timed)
}

/// The simulation settings from the command line (its limits are the timing's,
/// [`FlyOptions::sim_config`]).
fn sim_config(a: &SimArgs) -> Result<SimConfig, CliError> {
    let gusts = a
        .gust
        .iter()
        .map(|g| parse_gust(g))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(SimConfig {
        rate: a.rate,
        goal_tolerance: a.goal_tol,
        settle_time: a.settle_time,
        gusts,
        ..Default::default()
    })
}

/// The flight's report, one line per measure.
fn say_report(
    say: &dyn Fn(std::fmt::Arguments<'_>),
    plan_name: &str,
    waypoints: usize,
    r: &aerial_chain::sim::FlightReport,
) {
    say(format_args!(
        "{}: N = {}, {} waypoints, plan {:.2} s, flown {:.2} s at {} Hz ({:.1}x real time, MPC {} solves, {} fallbacks)",
        plan_name,
        r.units,
        waypoints,
        r.planned_duration,
        r.simulated_time,
        r.rate_hz,
        r.realtime_factor,
        r.mpc_solves,
        r.mpc_failures
    ));
    match r.time_to_complete {
        Some(t) => say(format_args!("  reached the goal at {t:.2} s")),
        None => say(format_args!("  did not reach the goal")),
    }
    say(format_args!(
        "  head tracking error: RMS {:.4} m, max {:.4} m",
        r.head_rms, r.head_max
    ));
    say(format_args!(
        "  link angle error:    RMS {:.3} deg, max {:.3} deg",
        r.link_rms_deg, r.link_max_deg
    ));
    match (r.min_clearance, &r.min_clearance_at, r.min_clearance_time) {
        (Some(c), Some(at), Some(t)) => say(format_args!(
            "  minimum clearance to the map: {c:.4} m at {t:.2} s ({at})"
        )),
        _ => say(format_args!("  minimum clearance to the map: not measured")),
    }
    say(format_args!(
        "  smallest gap inside the chain: {:.4} m",
        r.min_self_gap
    ));
    say(format_args!(
        "  joint-limit excursions: pitch {:.3} deg, bend {:.3} deg, {:.3} s beyond",
        r.limits.max_pitch_excess_deg, r.limits.max_bend_excess_deg, r.limits.time_beyond
    ));
}

/// Writes the map the units' sensors saw along `flight` (`--map-out`), and says what
/// it holds.
fn write_seen_map(
    path: &Path,
    a: &SimArgs,
    grid: &aerial_chain::map::Grid,
    params: &aerial_chain_core::ChainParams,
    flight: &aerial_chain::sim::Flight,
    say: &dyn Fn(std::fmt::Arguments<'_>),
) -> CliResult {
    let survey = aerial_chain::sensing::Survey {
        rate_hz: a.sensor_rate,
        ..Default::default()
    };
    let free = params.unit_radius as f64 + aerial_chain::collision::DEFAULT_CLEARANCE;
    let (seen, stats) = survey
        .fly(grid, &flight.samples, free)
        .map_err(|e| CliError::input(format!("--sensor-rate {}: {e}", a.sensor_rate)))?;
    seen.write_bt(path)
        .map_err(|e| CliError::input(format!("{}: {e}", path.display())))?;
    say(format_args!(
        "  seen map {}: {} voxels known from {} scans ({} rays) at {} Hz",
        path.display(),
        stats.known,
        stats.scans,
        stats.rays,
        a.sensor_rate
    ));
    Ok(())
}

/// Writes the flight (`arc-sim/1` JSON, every `--record-every`-th sample).
fn write_flight(
    path: &Path,
    a: &SimArgs,
    plan_name: &str,
    flight: &aerial_chain::sim::Flight,
) -> Result<(), CliError> {
    FlightFile::new(flight, plan_name, &a.map.name(), a.record_every)
        .write(path)
        .map_err(|e| CliError::input(e.to_string()))
}

/// Draws the flight over the map's footprint in the height band the chain flew.
fn draw_flight(
    path: &Path,
    flight: &aerial_chain::sim::Flight,
    grid: &aerial_chain::map::Grid,
    params: &aerial_chain_core::ChainParams,
    title: &str,
) -> Result<(), CliError> {
    let zs = flight
        .samples
        .iter()
        .flat_map(|s| s.units.iter().map(|u| u.p[2] as f64));
    let (lo, hi) = zs.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), z| {
        (l.min(z), h.max(z))
    });
    let band = params.unit_radius as f64;
    let obs = footprint(grid, lo - band, hi + band);
    let svg = flight_svg(flight, &obs, title);
    aerial_chain::picture::save_svg(&svg, path).map_err(|e| CliError::input(e.to_string()))
}

/// Why a flight that ran is not a success.
fn why_failed(r: &aerial_chain::sim::FlightReport, settle_time: f64) -> String {
    if r.diverged {
        "the flight diverged".to_string()
    } else if r.contact {
        format!(
            "the chain touched the map ({})",
            r.min_clearance_at.clone().unwrap_or_default()
        )
    } else if r.self_contact {
        "the chain touched itself".to_string()
    } else {
        format!(
            "the chain did not reach the goal within {:.1} s of the plan's end",
            settle_time
        )
    }
}
