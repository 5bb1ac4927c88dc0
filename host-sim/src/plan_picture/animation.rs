//! The animation of a chain's motion: the plan's picture views, one frame per fixed
//! step of time, the chain at that time coloured by it and the head's path so far.
//!
//! A frame is drawn at `k * step` for `k = 0, 1, ...` and one more at the end, so an
//! animation of a motion lasting `T` has `ceil(T / step) + 1` frames; each shows for
//! [`FRAME_DELAY_CS`], the last for longer before the loop starts over.

use nalgebra::Point3;

use super::{bounds, goal_marks, views, View, TITLE_H};
use crate::map::grid::Grid;
use crate::picture::{palette, ramp, stroke, Animation, DrawError, Figure, Mark};
use crate::sim::Flight;
use crate::trajectory::Trajectory;

/// Most frames an animation may have: about a minute at 10 frames a second, a few
/// megabytes of GIF.
pub const MAX_FRAMES: usize = 600;

/// Frames an animation aims at when no step is given: 12 s at 10 frames a second.
const DEFAULT_FRAMES: usize = 120;

/// Hundredths of a second each frame shows.
pub const FRAME_DELAY_CS: u16 = 10;

/// Hundredths of a second the last frame shows.
const LAST_DELAY_CS: u16 = 150;

/// Width of an animation (px): half a slide, a README's column.
const WIDTH: f64 = 720.0;

/// Most points of the head's path drawn in a frame.
const PATH_POINTS: usize = 400;

/// What can go wrong making an animation.
#[derive(Debug, thiserror::Error)]
pub enum AnimationError {
    /// The time step between frames is not a positive number of seconds.
    #[error("frame step {0} s: must be a positive number of seconds")]
    Step(f64),
    /// The step gives more frames than allowed.
    #[error(
        "frame step {step} s: makes {frames} frames of a {duration:.2} s motion, more than \
         {MAX_FRAMES}; use a step of at least {least:.3} s"
    )]
    TooManyFrames {
        /// The step asked for (s).
        step: f64,
        /// The frames it would make.
        frames: usize,
        /// The motion's duration (s).
        duration: f64,
        /// The smallest step within the limit (s).
        least: f64,
    },
    /// The motion has no samples.
    #[error("nothing to animate: the motion has no samples")]
    Empty,
    /// Drawing or encoding failed.
    #[error(transparent)]
    Draw(#[from] DrawError),
}

/// A chain's motion: the unit centres (head first) at increasing times, and the
/// head's intended path drawn under it.
#[derive(Clone, Debug, Default)]
pub struct Motion {
    /// Sample times (s), increasing.
    pub times: Vec<f64>,
    /// Unit centres at every sample, head first (m).
    pub bodies: Vec<Vec<Point3<f64>>>,
    /// The head's intended path (the plan's, or the reference a flight tracked).
    pub planned: Vec<Point3<f64>>,
    /// Radius of a unit (m).
    pub unit_radius: f64,
}

impl Motion {
    /// The motion of a timed trajectory.
    pub fn of_trajectory(tr: &Trajectory) -> Self {
        let l = tr.params().link_length as f64;
        let bodies: Vec<Vec<Point3<f64>>> = tr
            .zetas()
            .iter()
            .map(|z| crate::collision::exact::positions_f64(l, [z[0], z[1], z[2]], &z[3..]))
            .collect();
        let planned = bodies.iter().map(|b| b[0]).collect();
        Self {
            times: tr.times().to_vec(),
            bodies,
            planned,
            unit_radius: tr.params().unit_radius as f64,
        }
    }

    /// The motion of a simulated flight; the head's reference is its intended path.
    pub fn of_flight(flight: &Flight) -> Self {
        let f = |p: [f32; 3]| Point3::from(p.map(f64::from));
        Self {
            times: flight.samples.iter().map(|s| s.t).collect(),
            bodies: flight
                .samples
                .iter()
                .map(|s| s.units.iter().map(|u| f(u.p)).collect())
                .collect(),
            planned: flight.samples.iter().map(|s| f(s.head_ref)).collect(),
            unit_radius: flight.params.unit_radius as f64,
        }
    }

    /// Time of the last sample (s).
    pub fn duration(&self) -> f64 {
        self.times.last().copied().unwrap_or(0.0)
    }

    /// The last sample at or before time `t`.
    fn at(&self, t: f64) -> usize {
        self.times
            .partition_point(|&s| s <= t + 1e-9)
            .saturating_sub(1)
    }
}

/// What an animation shows besides the motion, and its time step.
#[derive(Clone, Debug, Default)]
pub struct AnimationOptions {
    /// The figure's title.
    pub title: String,
    /// The goal and its tolerance (m).
    pub goal: Option<(Point3<f64>, f64)>,
    /// Time between frames (s); `None`: a step of 1, 2 or 5 times a power of ten
    /// (at least 0.1 s) giving at most about a hundred and twenty frames.
    pub step: Option<f64>,
    /// What the intended head path is called in the legend.
    pub planned_label: String,
}

/// The frames of a motion lasting `duration` at `step`: one at every multiple of the
/// step and one at the end.
pub fn frame_count(duration: f64, step: f64) -> usize {
    (duration / step - 1e-9).ceil().max(0.0) as usize + 1
}

/// The time step for `duration`: `step` checked, or the default.
fn frame_step(duration: f64, step: Option<f64>) -> Result<f64, AnimationError> {
    let step = match step {
        Some(s) if s.is_finite() && s > 0.0 => s,
        Some(s) => return Err(AnimationError::Step(s)),
        None => crate::picture::axis::nice_step(duration / DEFAULT_FRAMES as f64).max(0.1),
    };
    let frames = frame_count(duration, step);
    if frames > MAX_FRAMES {
        return Err(AnimationError::TooManyFrames {
            step,
            frames,
            duration,
            // One frame of room below the limit for rounding.
            least: duration / (MAX_FRAMES - 2) as f64,
        });
    }
    Ok(step)
}

/// An animation made: the GIF file's bytes, its frames and their time step.
#[derive(Clone, Debug)]
pub struct Gif {
    /// The file.
    pub bytes: Vec<u8>,
    /// Frames in it.
    pub frames: usize,
    /// Time between frames (s).
    pub step: f64,
}

/// The GIF of `motion` over `grid`.
pub fn animate(
    grid: &Grid,
    motion: &Motion,
    opts: &AnimationOptions,
) -> Result<Gif, AnimationError> {
    let (lo, hi) = bounds(motion.bodies.iter().flatten()).ok_or(AnimationError::Empty)?;
    let duration = motion.duration();
    let step = frame_step(duration, opts.step)?;
    let count = frame_count(duration, step);
    let (views, height) = views(grid, WIDTH);
    let mut bg = Figure::new(WIDTH, height, &opts.title);
    for view in &views {
        let mut p = view.with_obstacles(grid, lo, hi);
        let planned: Vec<(f64, f64)> = thin(&motion.planned, motion.planned.len())
            .map(|q| view.see(q))
            .collect();
        p.polyline(&planned, palette::INK, stroke::HAIR, true);
        if let Some(b) = motion.bodies.first() {
            p.square(view.see(&b[0]), 5.0, palette::START);
        }
        goal_marks(&mut p, view, opts.goal);
        bg.add(p);
    }
    legend(&mut bg, duration, opts);
    let (w, h) = bg.size();
    let anim = Animation::new(&bg, FRAME_DELAY_CS, LAST_DELAY_CS)?;
    let frame = |k: usize| {
        let t = (k as f64 * step).min(duration);
        overlay(&views, motion, t, (w, h))
    };
    Ok(Gif {
        bytes: anim.gif(count, &frame)?,
        frames: count,
        step,
    })
}

/// Every `len / PATH_POINTS`-th of the first `len` points, and the last of them.
fn thin(points: &[Point3<f64>], len: usize) -> impl Iterator<Item = &Point3<f64>> {
    let every = len.div_ceil(PATH_POINTS).max(1);
    points[..len]
        .iter()
        .step_by(every)
        .chain(points[..len].last())
}

/// The moving marks at time `t`: the head's path so far and the chain.
fn overlay(views: &[View], motion: &Motion, t: f64, (w, h): (f64, f64)) -> Figure {
    let i = motion.at(t);
    let fill = ramp(t / motion.duration().max(1e-9));
    let heads: Vec<Point3<f64>> = motion.bodies[..=i].iter().map(|b| b[0]).collect();
    let mut f = Figure::overlay(w, h);
    for view in views {
        let mut p = view.panel();
        let path: Vec<(f64, f64)> = thin(&heads, heads.len()).map(|q| view.see(q)).collect();
        p.polyline(&path, palette::PATH, stroke::DATA, false);
        let body: Vec<(f64, f64)> = motion.bodies[i].iter().map(|q| view.see(q)).collect();
        p.chain(&body, motion.unit_radius, &fill, &fill);
        f.add(p);
    }
    f.note(w - 12.0, TITLE_H - 8.0, &format!("t = {t:.1} s"));
    f
}

/// The animation's legend.
fn legend(fig: &mut Figure, duration: f64, opts: &AnimationOptions) {
    fig.legend_mark(
        Mark::Ramp {
            from: 0.0,
            to: duration,
        },
        palette::INK,
        "chain, coloured by time (s)",
    );
    fig.legend_mark(Mark::Line, palette::PATH, "head path so far");
    fig.legend_mark(Mark::Dashed, palette::INK, &opts.planned_label);
    fig.legend_mark(Mark::Square, palette::START, "start");
    if let Some((_, tol)) = opts.goal {
        fig.legend_mark(Mark::Dot, palette::GOAL, "goal");
        fig.legend_mark(
            Mark::DashedRing,
            palette::GOAL,
            &format!("goal region ({tol} m)"),
        );
    }
    fig.legend(palette::OBSTACLE, "occupied");
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_cover_the_motion_at_the_step() {
        assert_eq!(frame_count(10.0, 0.5), 21);
        assert_eq!(frame_count(10.1, 0.5), 22, "one more at the end");
        assert_eq!(frame_count(0.0, 0.5), 1);
        assert!(matches!(
            frame_step(10.0, Some(0.0)),
            Err(AnimationError::Step(_))
        ));
        assert!(matches!(
            frame_step(10.0, Some(-1.0)),
            Err(AnimationError::Step(_))
        ));
        assert!(matches!(
            frame_step(100.0, Some(0.01)),
            Err(AnimationError::TooManyFrames { frames: 10001, .. })
        ));
        let least = match frame_step(100.0, Some(0.01)) {
            Err(AnimationError::TooManyFrames { least, .. }) => least,
            _ => unreachable!(),
        };
        assert!(frame_count(100.0, least) <= MAX_FRAMES);
        for d in [0.0, 3.0, 60.0, 900.0] {
            let s = frame_step(d, None).unwrap();
            assert!(
                s >= 0.1 && frame_count(d, s) <= DEFAULT_FRAMES + 1,
                "{d} s: {s}"
            );
        }
    }

    #[test]
    fn motion_finds_the_sample_at_a_time() {
        let m = Motion {
            times: vec![0.0, 0.5, 1.0],
            bodies: vec![vec![Point3::origin()]; 3],
            ..Motion::default()
        };
        assert_eq!(m.at(0.0), 0);
        assert_eq!(m.at(0.7), 1);
        assert_eq!(m.at(5.0), 2);
    }
}
