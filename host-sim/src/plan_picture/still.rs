//! The still picture of a plan: the head path and the chain at a choice of waypoints
//! in top and side views, coloured by time along the plan.
//!
//! A plan has far more waypoints than a picture can show (follow-the-leader motion
//! adds one every 0.1 m), so each view draws the chain only where it overlaps no chain
//! already drawn: the start and the end first, then the shape changes, then the other
//! waypoints, in order. The fill of a chain is its time on the colour ramp, its rim the
//! source of its shape change.

use nalgebra::Point3;

use super::{bounds, goal_marks, views};
use crate::collision::exact::positions_f64;
use crate::map::grid::Grid;
use crate::picture::{palette, ramp, stroke, Colour, Figure, Mark};
use crate::plan_file::Plan;
use crate::trajectory::Trajectory;

/// What the picture of a plan shows besides the plan.
#[derive(Clone, Debug, Default)]
pub struct PictureOptions {
    /// The figure's title.
    pub title: String,
    /// The goal and its tolerance (m), marked as a point and a region.
    pub goal: Option<(Point3<f64>, f64)>,
    /// The time of every waypoint (s), for the colour ramp ([`waypoint_times`]);
    /// without them the ramp runs over the waypoints' order.
    pub times: Option<Vec<f64>>,
}

/// Length of the pieces a long edge of the head path is coloured in (m).
const PIECE_M: f64 = 0.25;

/// Width of a plan's picture (px).
const WIDTH: f64 = 1100.0;

/// The time at which `trajectory` (made from `plan`) passes each waypoint
/// ([`Trajectory::waypoint_times`]).
pub fn waypoint_times(plan: &Plan, trajectory: &Trajectory) -> Vec<f64> {
    trajectory.waypoint_times(plan)
}

/// What a waypoint's shape came from, as the picture shows it: a rim colour and
/// its legend label; `None` for a pure translation (rim as the fill).
fn source(label: &str) -> Option<(Colour, &'static str)> {
    let s = if label.starts_with("LSC") {
        (palette::LSC, "shape change: library (LSC)")
    } else if label.starts_with("SRS") {
        (palette::SRS, "shape change: random (SRS)")
    } else {
        match label {
            "rotation" => (palette::SENSOR, "yaw rotation"),
            "follow" => (palette::FOLLOW, "follow-the-leader step"),
            "shrunk" => (palette::SHRUNK, "shape change made smaller by refinement"),
            "sampled" => (palette::START, "sampled shape"),
            _ => return None,
        }
    };
    Some(s)
}

/// The figure for `plan` on `grid`.
pub fn draw(grid: &Grid, plan: &Plan, opts: &PictureOptions) -> Figure {
    let params = plan.check().ok();
    let l = params.map(|p| p.link_length as f64).unwrap_or(0.5);
    let ru = params.map(|p| p.unit_radius as f64).unwrap_or(0.15);
    let heads: Vec<Point3<f64>> = plan.waypoints.iter().map(|w| w.xi().into()).collect();
    let bodies: Vec<Vec<Point3<f64>>> = plan
        .waypoints
        .iter()
        .map(|w| positions_f64(l, w.xi(), w.eta()))
        .collect();
    let (blo, bhi) = bounds(bodies.iter().flatten()).unwrap_or_else(|| grid.bounds());
    let labels: Vec<String> = plan
        .stats
        .get("waypoint_sources")
        .and_then(|v| v.as_array())
        .map(|a| {
            a.iter()
                .map(|s| s.as_str().unwrap_or("").to_string())
                .collect()
        })
        .unwrap_or_default();
    let n = bodies.len();
    let (times, ramp_label) = match &opts.times {
        Some(t) if t.len() == n => (t.clone(), "time along the plan (s)"),
        _ => (
            (0..n).map(|i| i as f64).collect(),
            "waypoint, in order along the plan",
        ),
    };
    let t_end = times.last().copied().unwrap_or(0.0).max(1e-9);
    let colour = |i: usize| ramp(times[i] / t_end);
    let sources: Vec<Option<(Colour, &str)>> = (0..n)
        .map(|i| source(labels.get(i).map_or("", String::as_str)))
        .collect();
    let (views, height) = views(grid, WIDTH);
    let mut fig = Figure::new(WIDTH, height, &opts.title);
    let mut drawn = Vec::new();
    for view in &views {
        let mut p = view.with_obstacles(grid, blo, bhi);
        // The head path in the colour of its time, a long edge in pieces of about
        // PIECE_M whose times are interpolated between its waypoints'.
        for i in 1..n {
            let (a, b) = (heads[i - 1], heads[i]);
            let len = (0..3).map(|k| (b[k] - a[k]).powi(2)).sum::<f64>().sqrt();
            let pieces = ((len / PIECE_M).ceil() as usize).clamp(1, 64);
            let at = |f: f64| Point3::from(std::array::from_fn(|k| a[k] + f * (b[k] - a[k])));
            for j in 0..pieces {
                let (f0, f1) = (j as f64 / pieces as f64, (j + 1) as f64 / pieces as f64);
                let t = times[i - 1] + (f0 + f1) / 2.0 * (times[i] - times[i - 1]);
                p.line(
                    view.see(&at(f0)),
                    view.see(&at(f1)),
                    &ramp(t / t_end),
                    stroke::DATA,
                );
            }
        }
        let seen: Vec<Vec<(f64, f64)>> = bodies
            .iter()
            .map(|b| b.iter().map(|q| view.see(q)).collect())
            .collect();
        for i in thinned(&seen, &priority(&sources), 2.0 * ru) {
            drawn.push(i);
            let fill = colour(i);
            let rim = sources[i].map_or(fill.as_str(), |s| s.0);
            p.chain(&seen[i], ru, &fill, rim);
        }
        if let Some(s) = heads.first() {
            p.square(view.see(s), 5.0, palette::START);
        }
        goal_marks(&mut p, view, opts.goal);
        fig.add(p);
    }
    // The legend names the rims of the chains drawn, not of every waypoint.
    let shown: Vec<Option<(Colour, &str)>> = drawn.iter().map(|&i| sources[i]).collect();
    legend(&mut fig, ramp_label, times[0], t_end, &shown, opts.goal);
    fig
}

/// The order in which waypoints may claim room in a view: the start, the end, the
/// shape changes, then the rest.
fn priority(sources: &[Option<(Colour, &str)>]) -> Vec<usize> {
    let n = sources.len();
    let mut order: Vec<usize> = [0, n.saturating_sub(1)]
        .into_iter()
        .filter(|&i| i < n)
        .collect();
    order.dedup();
    let inner = 1..n.saturating_sub(1);
    order.extend(inner.clone().filter(|&i| sources[i].is_some()));
    order.extend(inner.filter(|&i| sources[i].is_none()));
    order
}

/// The waypoints whose chains are drawn, in time order: the first two of `order` (the
/// start and the end) always, every other if none of its units comes within `gap` of
/// a unit or a link's midpoint of a chain already taken, nor any of its links'
/// midpoints within `gap` of such a unit.
pub(crate) fn thinned(seen: &[Vec<(f64, f64)>], order: &[usize], gap: f64) -> Vec<usize> {
    let mids = |b: &[(f64, f64)]| -> Vec<(f64, f64)> {
        b.windows(2)
            .map(|w| ((w[0].0 + w[1].0) / 2.0, (w[0].1 + w[1].1) / 2.0))
            .collect()
    };
    let near = |ps: &[(f64, f64)], qs: &[(f64, f64)]| {
        ps.iter()
            .any(|p| qs.iter().any(|q| (p.0 - q.0).hypot(p.1 - q.1) < gap))
    };
    let mut units: Vec<(f64, f64)> = Vec::new();
    let mut links: Vec<(f64, f64)> = Vec::new();
    let mut chosen = Vec::new();
    for &i in order {
        let (u, m) = (&seen[i], mids(&seen[i]));
        let clear = !near(u, &units) && !near(u, &links) && !near(&m, &units);
        if clear || chosen.len() < 2 {
            units.extend_from_slice(u);
            links.extend(m);
            chosen.push(i);
        }
    }
    chosen.sort_unstable();
    chosen
}

/// Every mark of the picture in its legend: the time ramp, the path, start and goal,
/// the shape-change sources present, the obstacles.
fn legend(
    fig: &mut Figure,
    ramp_label: &str,
    t0: f64,
    t_end: f64,
    sources: &[Option<(Colour, &str)>],
    goal: Option<(Point3<f64>, f64)>,
) {
    fig.legend_mark(
        Mark::Ramp {
            from: t0,
            to: t_end,
        },
        palette::INK,
        ramp_label,
    );
    fig.legend_mark(Mark::Line, &ramp(0.5), "head path (coloured by time)");
    fig.legend_mark(Mark::Square, palette::START, "start");
    if let Some((_, tol)) = goal {
        fig.legend_mark(Mark::Dot, palette::GOAL, "goal");
        fig.legend_mark(
            Mark::DashedRing,
            palette::GOAL,
            &format!("goal region ({tol} m)"),
        );
    }
    let mut seen: Vec<(Colour, &str)> = Vec::new();
    for s in sources.iter().flatten() {
        if !seen.contains(s) {
            seen.push(*s);
        }
    }
    for (c, label) in seen {
        fig.legend_mark(Mark::Ring, c, &format!("rim: {label}"));
    }
    fig.legend(
        palette::OBSTACLE,
        "occupied (lighter: partly, over the flight band)",
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thinned_chains_never_overlap_and_keep_start_and_end() {
        // Twenty chains of three units stepping 0.1 m along x: only every few fit.
        let seen: Vec<Vec<(f64, f64)>> = (0..20)
            .map(|i| {
                let x = 0.1 * i as f64;
                vec![(x, 0.0), (x - 0.15, 0.0), (x - 0.3, 0.0)]
            })
            .collect();
        let sources = vec![None; 20];
        let chosen = thinned(&seen, &priority(&sources), 0.3);
        assert_eq!(chosen.first(), Some(&0));
        assert_eq!(chosen.last(), Some(&19));
        for (a, &i) in chosen.iter().enumerate() {
            for &j in &chosen[a + 1..] {
                for p in &seen[i] {
                    for q in &seen[j] {
                        assert!((p.0 - q.0).hypot(p.1 - q.1) >= 0.3 - 1e-9, "{i} and {j}");
                    }
                }
            }
        }
        assert!(chosen.len() >= 3, "{chosen:?}");
        // The end overlaps the start: both are still drawn, nothing else that overlaps.
        let ring = vec![
            vec![(0.0, 0.0), (0.5, 0.0)],
            vec![(0.1, 0.0)],
            vec![(0.2, 0.0)],
        ];
        assert_eq!(thinned(&ring, &[0, 1, 2], 0.3), [0, 1]);
    }

    #[test]
    fn shape_changes_claim_room_before_translations() {
        let mut sources: Vec<Option<(Colour, &str)>> = vec![None; 6];
        sources[4] = source("LSC:PN");
        assert_eq!(priority(&sources), [0, 5, 4, 1, 2, 3]);
        assert_eq!(source("translate"), None);
        assert_eq!(source("SRS:3:turned").unwrap().0, palette::SRS);
    }
}
