//! The picture of a plan: top and side views with the obstacles near the flight,
//! the head's path, the chain drawn at the start, at every shape change (library
//! shapes and random shapes in different colours) and at the end.

use nalgebra::Point3;

use crate::collision::exact::positions_f64;
use crate::map::grid::Grid;
use crate::picture::{palette, Colour, Figure, Panel};
use crate::plan_file::Plan;

/// Obstacles of `grid` projected along axis `drop` over the band `lo..hi` of that
/// axis, as merged rectangles in the two remaining axes `(u, v)`, each with the
/// share of the band that is occupied (so an opening in a wall shows lighter).
type Rect = ((f64, f64), (f64, f64), f64);

fn projected(grid: &Grid, u: usize, v: usize, drop: usize, lo: f64, hi: f64) -> Vec<Rect> {
    let (o, d, r) = (grid.origin(), grid.dims(), grid.resolution());
    let band = |i: usize| {
        let c = (o[drop] as f64 + i as f64 + 0.5) * r;
        c >= lo - r && c <= hi + r
    };
    let layers: Vec<usize> = (0..d[drop]).filter(|&i| band(i)).collect();
    // Share of the band occupied, in quarters (0 = free).
    let level = |i: usize, j: usize| -> usize {
        let hits = layers
            .iter()
            .filter(|&&k| {
                let mut idx = [0i32; 3];
                idx[u] = o[u] + i as i32;
                idx[v] = o[v] + j as i32;
                idx[drop] = o[drop] + k as i32;
                grid.is_obstacle(idx)
            })
            .count();
        if hits == 0 {
            0
        } else {
            1 + (3 * hits) / layers.len().max(1)
        }
    };
    let mut rects = Vec::new();
    for j in 0..d[v] {
        let mut run: Option<(usize, usize)> = None;
        for i in 0..=d[u] {
            let lv = if i < d[u] { level(i, j) } else { 0 };
            match run {
                Some((_, l)) if l == lv => {}
                _ => {
                    if let Some((s, l)) = run.filter(|&(_, l)| l > 0) {
                        let x0 = (o[u] as f64 + s as f64) * r;
                        let x1 = (o[u] as f64 + i as f64) * r;
                        let y0 = (o[v] as f64 + j as f64) * r;
                        rects.push(((x0, y0), (x1, y0 + r), l as f64 / 4.0));
                    }
                    run = Some((i, lv));
                }
            }
        }
    }
    rects
}

/// The figure for `plan` on `grid`; `goal` marks the goal.
pub fn draw(grid: &Grid, plan: &Plan, title: &str, goal: Option<[f64; 3]>) -> Figure {
    let params = plan.check().ok();
    let l = params.map(|p| p.link_length as f64).unwrap_or(0.5);
    let ru = params.map(|p| p.unit_radius as f64).unwrap_or(0.15);
    let heads: Vec<[f64; 3]> = plan.waypoints.iter().map(|w| w.xi()).collect();
    let bodies: Vec<Vec<Point3<f64>>> = plan
        .waypoints
        .iter()
        .map(|w| positions_f64(l, w.xi(), w.eta()))
        .collect();
    let (lo, hi) = grid.bounds();
    let (mut blo, mut bhi) = ([f64::MAX; 3], [f64::MIN; 3]);
    for p in bodies.iter().flatten() {
        for k in 0..3 {
            blo[k] = blo[k].min(p[k]);
            bhi[k] = bhi[k].max(p[k]);
        }
    }
    if bodies.is_empty() {
        (blo, bhi) = (lo, hi);
    }
    let sources: Vec<String> = plan
        .stats
        .get("waypoint_sources")
        .and_then(|v| v.as_array())
        .map(|a| {
            a.iter()
                .map(|s| s.as_str().unwrap_or("").to_string())
                .collect()
        })
        .unwrap_or_default();
    let width = 1100.0;
    let (sx, sy, sz) = (hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
    let top_h = (width * sy / sx).clamp(220.0, 700.0) + 60.0;
    let side_h = (width * sz / sx).clamp(160.0, 400.0) + 60.0;
    let mut fig = Figure::new(width, top_h + side_h + 50.0, title);
    let views = [
        (
            (0usize, 1usize, 2usize),
            "top view (x-y), obstacles at flight height",
            "y (m)",
            26.0,
            top_h,
        ),
        (
            (0, 2, 1),
            "side view (x-z), obstacles near the flight",
            "z (m)",
            26.0 + top_h,
            side_h,
        ),
    ];
    for ((u, v, drop), name, label, y, h) in views {
        let mut p = Panel::new(
            (0.0, y, width, h),
            (lo[u], lo[v]),
            (hi[u], hi[v]),
            name,
            ("x (m)", label),
        );
        for (a, b, share) in projected(grid, u, v, drop, blo[drop], bhi[drop]) {
            p.rect(a, b, palette::OBSTACLE, 0.25 + 0.7 * share);
        }
        let pts: Vec<(f64, f64)> = heads.iter().map(|q| (q[u], q[v])).collect();
        p.polyline(&pts, palette::PATH, 2.0, false);
        // Follow-the-leader changes come every 0.1 m: draw about FOLLOW_DRAWN of them.
        let total = sources.iter().filter(|s| *s == "follow").count();
        let every = total.div_ceil(FOLLOW_DRAWN).max(1);
        let mut follows = 0usize;
        for (i, body) in bodies.iter().enumerate() {
            let src = sources.get(i).map(String::as_str).unwrap_or("");
            let follow = src == "follow";
            if follow {
                follows += 1;
            }
            let colour: Option<Colour> = if i == 0 {
                Some(palette::START)
            } else if i + 1 == bodies.len() {
                Some(palette::GOAL)
            } else if src.starts_with("LSC") {
                Some(palette::LSC)
            } else if src.starts_with("SRS") {
                Some(palette::SRS)
            } else if src == "rotation" {
                Some(palette::SENSOR)
            } else if src == "shrunk" {
                Some(palette::SHRUNK)
            } else if follow && follows.is_multiple_of(every) {
                Some(palette::FOLLOW)
            } else {
                None
            };
            if let Some(c) = colour {
                chain(&mut p, body, u, v, ru, c);
            }
        }
        if let Some(g) = goal {
            p.circle((g[u], g[v]), 0.08, palette::GOAL, palette::INK, 1.0);
        }
        fig.add(p);
    }
    fig.legend(palette::PATH, "head path");
    fig.legend(palette::START, "start");
    fig.legend(palette::LSC, "library shape (LSC)");
    fig.legend(palette::SRS, "random shape (SRS)");
    fig.legend(palette::SENSOR, "yaw rotation");
    fig.legend(palette::FOLLOW, "follow-the-leader (some)");
    fig.legend(palette::SHRUNK, "shape change made smaller by refinement");
    fig.legend(palette::GOAL, "end");
    fig.legend(
        palette::OBSTACLE,
        "occupied (lighter: partly, over the flight band)",
    );
    fig
}

/// How many follow-the-leader shapes a picture shows, evenly spread over the plan.
const FOLLOW_DRAWN: usize = 4;

fn chain(p: &mut Panel, body: &[Point3<f64>], u: usize, v: usize, r: f64, c: Colour) {
    let projected: Vec<(f64, f64)> = body.iter().map(|q| (q[u], q[v])).collect();
    p.chain(&projected, r, c);
}
