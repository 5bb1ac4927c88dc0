//! Flying a plan as `arc sim` flies it: along the plan's blended trajectory
//! (`trajectory::build`), or stopping at every waypoint where the plan is not
//! admissible as a trajectory or stopping is asked for; the chain rests
//! `SimConfig::limits.start_hold` at the start first.
//!
//! [`time`] gives the motion that will be flown (its clock is the one `arc view`
//! shows), [`fly_timed`] flies it, [`fly`] does both. `sim::simulate` is the other way
//! to fly a plan: stopping at every waypoint, always.

use aerial_chain_core::ChainParams;

use crate::map::Grid;
use crate::plan_file::{FormatError, Plan};
use crate::sim::{
    simulate_reference, simulate_with_progress, Flight, MapClearance, Progress, Reference,
    SimConfig, SimError,
};
use crate::trajectory::{self, ReferenceLimits, Trajectory, TrajectoryError, Violation};

/// How to fly a plan: `arc sim`'s settings, with its defaults (`Default`).
#[derive(Clone, Debug, Default)]
pub struct FlyOptions {
    /// Physics, control, arrival and gusts. Its `limits.start_hold` is the rest at
    /// the start; its other limits are replaced by `timing.limits`, so that one set of
    /// limits times the plan whichever way it is flown.
    pub sim: SimConfig,
    /// How the plan is timed: the trajectory's limits, sample spacing and clearance;
    /// `blend: false` stops at every waypoint (`arc sim --no-blend`).
    pub timing: trajectory::Settings,
}

impl FlyOptions {
    /// The simulation settings flown: `sim` with the limits of `timing`.
    pub fn sim_config(&self) -> SimConfig {
        let mut cfg = self.sim.clone();
        cfg.limits = ReferenceLimits {
            start_hold: cfg.limits.start_hold,
            ..self.timing.limits.to_reference()
        };
        cfg
    }
}

/// How a plan is timed for its flight.
#[derive(Clone, Debug)]
pub enum Timing {
    /// Along its trajectory, blended where admissible.
    Trajectory(Box<Trajectory>),
    /// Stopping at every waypoint: asked for (`None`), or because the plan is not
    /// admissible as a trajectory (the first place it fails).
    StopAtWaypoints(Option<Box<Violation>>),
}

/// The motion a plan is flown along.
#[derive(Clone, Debug)]
pub struct Timed {
    /// How it was timed.
    pub timing: Timing,
    /// The motion flown, the rest at the start included: its duration is the flight
    /// report's `planned_duration`.
    pub reference: Reference,
    /// The rest at the start (s).
    pub start_hold: f64,
}

/// Why a plan cannot be flown.
#[derive(Debug, thiserror::Error)]
pub enum FlyError {
    /// The plan breaks its format.
    #[error("plan: {0}")]
    Plan(#[from] FormatError),
    /// The trajectory cannot be made (limits, sample spacing, length), other than
    /// for being inadmissible (then the chain stops at every waypoint).
    #[error(transparent)]
    Trajectory(TrajectoryError),
    /// The simulation cannot fly it: settings outside their limits, a plan it cannot
    /// time stopping at every waypoint, its budget, the dynamics.
    #[error(transparent)]
    Sim(#[from] SimError),
}

/// Times `plan` on `grid` as [`fly`] will fly it (see the module docs).
pub fn time(plan: &Plan, grid: &Grid, options: &FlyOptions) -> Result<Timed, FlyError> {
    let params = plan.check()?;
    let cfg = options.sim_config();
    cfg.validate().map_err(SimError::from)?;
    if options.timing.blend {
        match trajectory::build(plan, grid, &options.timing) {
            Ok(tr) => return Ok(Timed::along(tr, options)),
            Err(TrajectoryError::Inadmissible(v)) => {
                return stop_at_waypoints(plan, &params, &cfg, Some(Box::new(v)));
            }
            Err(e) => return Err(FlyError::Trajectory(e)),
        }
    }
    stop_at_waypoints(plan, &params, &cfg, None)
}

/// The plan timed stopping at every waypoint within the limits of `cfg`.
fn stop_at_waypoints(
    plan: &Plan,
    params: &ChainParams,
    cfg: &SimConfig,
    why: Option<Box<Violation>>,
) -> Result<Timed, FlyError> {
    let l = params.link_length as f64;
    let reference =
        Reference::new(params.n(), l, &waypoints(plan), &cfg.limits).map_err(SimError::from)?;
    Ok(Timed {
        timing: Timing::StopAtWaypoints(why),
        reference,
        start_hold: cfg.limits.start_hold,
    })
}

/// The `zeta` of every waypoint.
fn waypoints(plan: &Plan) -> Vec<Vec<f64>> {
    plan.waypoints.iter().map(|w| w.zeta.clone()).collect()
}

/// Flies `plan`, timed as `timed` ([`time`]), on `grid` with the settings of
/// `options`, measuring its clearance to the map; `progress` tells another thread
/// how far it is.
pub fn fly_timed(
    plan: &Plan,
    timed: &Timed,
    grid: &Grid,
    options: &FlyOptions,
    progress: &Progress,
) -> Result<Flight, FlyError> {
    let params = plan.check()?;
    let cfg = options.sim_config();
    let obstacles = MapClearance::new(grid, &params);
    let flight = match &timed.timing {
        // The trajectory's own motion, after the rest at the start.
        Timing::Trajectory(tr) => {
            simulate_reference(&params, tr.reference(), &cfg, Some(&obstacles), progress)
        }
        Timing::StopAtWaypoints(_) => {
            cfg.validate().map_err(SimError::from)?;
            let w = waypoints(plan);
            simulate_with_progress(&params, &w, &cfg, Some(&obstacles), progress)
        }
    };
    Ok(flight?)
}

/// Flies `plan` on `grid` as `arc sim` does: [`time`], then [`fly_timed`].
pub fn fly(
    plan: &Plan,
    grid: &Grid,
    options: &FlyOptions,
    progress: &Progress,
) -> Result<(Flight, Timed), FlyError> {
    let timed = time(plan, grid, options)?;
    let flight = fly_timed(plan, &timed, grid, options, progress)?;
    Ok((flight, timed))
}

impl Timed {
    /// The motion flown along `tr`, a trajectory of the plan already made with
    /// `options.timing` (as [`time`] makes it): after the start hold of `options`.
    pub fn along(tr: Trajectory, options: &FlyOptions) -> Self {
        let hold = options.sim.limits.start_hold;
        Self {
            reference: tr.reference().with_start_hold(hold),
            timing: Timing::Trajectory(Box::new(tr)),
            start_hold: hold,
        }
    }

    /// When the flight reaches each of `plan`'s waypoints and when it leaves it (s,
    /// the rest at the start included): the clock of `arc view`. Stopping at every
    /// waypoint, the times of its timed edges; along a trajectory, the time of the
    /// trajectory's sample nearest each waypoint (to its sample spacing), with the
    /// chain leaving each waypoint as it reaches it (a blend never rests), and the
    /// last reached when the motion ends.
    pub fn waypoint_times(&self, plan: &Plan) -> (Vec<f64>, Vec<f64>) {
        let n = plan.waypoints.len();
        let mut t = vec![0.0; n];
        let mut leave = vec![0.0; n];
        match &self.timing {
            Timing::StopAtWaypoints(_) => {
                for s in self.reference.segments() {
                    if s.to_waypoint > 0 {
                        t[s.to_waypoint] = s.t0 + s.duration;
                        leave[s.to_waypoint - 1] = s.t0;
                    }
                }
            }
            Timing::Trajectory(tr) => {
                let hold = self.start_hold;
                let at = tr.waypoint_times(plan);
                for i in 1..n {
                    t[i] = hold + at[i];
                    leave[i] = t[i];
                }
                leave[0] = hold;
            }
        }
        if let (Some(last), Some(end)) = (t.last_mut(), leave.last_mut()) {
            if matches!(self.timing, Timing::Trajectory(_)) {
                *last = self.reference.duration();
            }
            *end = *last;
        }
        (t, leave)
    }
}

#[cfg(test)]
mod tests;
