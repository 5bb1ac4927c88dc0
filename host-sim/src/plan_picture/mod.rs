//! Pictures of a chain's motion on a map: top and side views with the obstacles near
//! the flight, as a still picture of a plan or as an animation of a plan or a flight.
//!
//! - here: the two views' layout, the obstacles they show and what both kinds share;
//! - `still`: [`draw`], the plan's picture: the head path and the chain at waypoints
//!   chosen so that no two drawn chains overlap, coloured by time;
//! - `animation`: [`animate`], one frame per fixed time step of a [`Motion`] (a timed
//!   trajectory or a flight);
//! - `flight`: [`flight_svg`], the plots of a simulated flight (`arc sim --picture`).

mod animation;
mod flight;
mod still;

pub use animation::{
    animate, frame_count, AnimationError, AnimationOptions, Gif, Motion, FRAME_DELAY_CS, MAX_FRAMES,
};
pub use flight::{flight_svg, footprint, Footprint};
pub(crate) use still::thinned;
pub use still::{draw, waypoint_times, PictureOptions};

use nalgebra::Point3;

use crate::map::grid::Grid;
use crate::picture::{palette, Panel};

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

/// One of the two views: the axes it shows, the one it looks along, its title and
/// where it sits in the figure.
#[derive(Clone, Debug)]
struct View {
    u: usize,
    v: usize,
    drop: usize,
    name: &'static str,
    label: &'static str,
    /// Pixel rectangle `(x, y, w, h)` in the figure.
    px: (f64, f64, f64, f64),
    /// The data box shown: the map's extent in `u` and `v`.
    min: (f64, f64),
    max: (f64, f64),
}

/// Room for the figure's title (px).
const TITLE_H: f64 = 26.0;

/// Room for one row of the figure's legend (px).
const LEGEND_H: f64 = 24.0;

/// The top and side views of `grid` in a figure `width` pixels wide, and the
/// figure's height (one legend row included; more rows add to it).
fn views(grid: &Grid, width: f64) -> (Vec<View>, f64) {
    let (lo, hi) = grid.bounds();
    let (sx, sy, sz) = (hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
    let plot_w = width - 60.0;
    let top_h = (plot_w * sy / sx).clamp(0.2 * width, 0.64 * width) + 60.0;
    let side_h = (plot_w * sz / sx).clamp(0.15 * width, 0.36 * width) + 60.0;
    let view = |(u, v, drop), name, label, y, h| View {
        u,
        v,
        drop,
        name,
        label,
        px: (0.0, y, width, h),
        min: (lo[u], lo[v]),
        max: (hi[u], hi[v]),
    };
    let views = vec![
        view(
            (0, 1, 2),
            "top view (x-y), obstacles at flight height",
            "y (m)",
            TITLE_H,
            top_h,
        ),
        view(
            (0, 2, 1),
            "side view (x-z), obstacles near the flight",
            "z (m)",
            TITLE_H + top_h,
            side_h,
        ),
    ];
    (views, TITLE_H + top_h + side_h + LEGEND_H)
}

impl View {
    /// An empty panel of this view (for the overlay of an animation's frame).
    fn panel(&self) -> Panel {
        Panel::new(
            self.px,
            self.min,
            self.max,
            self.name,
            ("x (m)", self.label),
        )
    }

    /// The panel with the obstacles of `grid` in the band `lo..hi` of the axis the
    /// view looks along.
    fn with_obstacles(&self, grid: &Grid, lo: Point3<f64>, hi: Point3<f64>) -> Panel {
        let mut p = self.panel();
        for (a, b, share) in projected(
            grid,
            self.u,
            self.v,
            self.drop,
            lo[self.drop],
            hi[self.drop],
        ) {
            p.rect(a, b, palette::OBSTACLE, 0.25 + 0.7 * share);
        }
        p
    }

    /// Point `q` seen in this view.
    fn see(&self, q: &Point3<f64>) -> (f64, f64) {
        (q[self.u], q[self.v])
    }
}

/// The box `(min, max)` around `points`; `None` when there are none.
fn bounds<'a>(points: impl Iterator<Item = &'a Point3<f64>>) -> Option<(Point3<f64>, Point3<f64>)> {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    lo[0].is_finite().then_some((lo.into(), hi.into()))
}

/// The goal's marks: the point and its region.
fn goal_marks(p: &mut Panel, view: &View, goal: Option<(Point3<f64>, f64)>) {
    if let Some((g, tol)) = goal {
        let at = view.see(&g);
        p.ring(at, tol, palette::GOAL, true);
        p.marker(at, 4.0, palette::GOAL);
    }
}
