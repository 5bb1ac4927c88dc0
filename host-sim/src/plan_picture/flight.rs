//! The picture of a flight, drawn with the project's [`crate::picture`] figures:
//! head position against its reference over time, link pitch and yaw against
//! their references, and the flown chain seen from above over the map's obstacles.

use crate::picture::{palette, ramp, stroke, Axis, Figure, Mark, Panel};

use crate::map::Grid;
use crate::sim::{Flight, Sample};

/// At most this many points per time series (the flight is decimated evenly).
const MAX_POINTS: usize = 1500;

/// Snapshots of the chain the top view may show (those that overlap none drawn).
const CANDIDATES: usize = 60;

/// Size of the flight picture (px).
const WIDTH: f64 = 1200.0;
const HEIGHT: f64 = 900.0;

/// Room for the figure's title above the panels (px).
const TITLE_H: f64 = 28.0;

/// An obstacle footprint seen from above: `[x0, y0, x1, y1]` (m).
pub type Footprint = [f64; 4];

/// Colours of the head's x, y and z.
const AXIS_COLOURS: [&str; 3] = [palette::SRS, palette::LSC, palette::PATH];

/// The other units' flown paths in the top view: the head's colour, lighter.
const TRAIL: &str = "#9ec5e8";

/// The flight as an SVG document (1200 x 900): four panels. `obstacles` are drawn
/// in the top view; `title` heads the picture.
pub fn flight_svg(flight: &Flight, obstacles: &[Footprint], title: &str) -> String {
    let step = (flight.samples.len() / MAX_POINTS).max(1);
    let samples: Vec<&Sample> = flight.samples.iter().step_by(step).collect();
    let mut fig = Figure::new(WIDTH, HEIGHT, title);
    let cells = fig.cells(2, 2, TITLE_H, HEIGHT);
    fig.add(head_panel(cells[0], &samples));
    let n_links = flight.params.n().saturating_sub(1);
    fig.add(link_panel(cells[1], &samples, 0, "link pitch", n_links));
    fig.add(link_panel(cells[2], &samples, 1, "link yaw", n_links));
    fig.add(top_view(cells[3], flight, &samples, obstacles));
    fig.to_svg()
}

/// The time axis of `samples`.
fn time_axis(samples: &[&Sample]) -> Axis {
    let t_end = samples.last().map_or(1.0, |s| s.t).max(1e-3);
    Axis::linear("t (s)", (0.0, t_end))
}

/// (a) Head position against the reference.
fn head_panel(cell: (f64, f64, f64, f64), samples: &[&Sample]) -> Panel {
    let y = Axis::around(
        "position (m)",
        samples
            .iter()
            .flat_map(|s| (0..3).flat_map(move |i| [s.units[0].p[i] as f64, s.head_ref[i] as f64])),
    );
    let mut p = Panel::chart(
        cell,
        time_axis(samples),
        y,
        "head position (solid) and reference (dashed)",
    );
    for (i, name) in ["x", "y", "z"].iter().enumerate() {
        let flown: Vec<(f64, f64)> = samples
            .iter()
            .map(|s| (s.t, s.units[0].p[i] as f64))
            .collect();
        p.polyline(&flown, AXIS_COLOURS[i], stroke::DATA, false);
        p.key_mark(Mark::Line, AXIS_COLOURS[i], name);
    }
    // The reference goes over the flown curves: it stays visible where they agree.
    for i in 0..3 {
        let reference: Vec<(f64, f64)> = samples
            .iter()
            .map(|s| (s.t, s.head_ref[i] as f64))
            .collect();
        p.polyline(&reference, palette::INK, stroke::HAIR, true);
    }
    p.key_mark(Mark::Dashed, palette::INK, "reference");
    p
}

/// (b), (c) Link pitch (`which` 0) or yaw (1) against their references, in degrees.
fn link_panel(
    cell: (f64, f64, f64, f64),
    samples: &[&Sample],
    which: usize,
    name: &str,
    n_links: usize,
) -> Panel {
    let y = Axis::around(
        "angle (deg)",
        samples.iter().flat_map(|s| {
            s.links_meas
                .iter()
                .chain(s.links_ref.iter())
                .map(move |a| (a[which] as f64).to_degrees())
        }),
    );
    let mut p = Panel::chart(
        cell,
        time_axis(samples),
        y,
        &format!("{name} (solid) and reference (dashed)"),
    );
    let series = |k: usize, of: fn(&Sample) -> &Vec<[f32; 2]>| -> Vec<(f64, f64)> {
        samples
            .iter()
            .map(|s| (s.t, (of(s)[k][which] as f64).to_degrees()))
            .collect()
    };
    for k in 0..n_links {
        let colour = palette::series(k);
        p.polyline(&series(k, |s| &s.links_meas), colour, stroke::DATA, false);
        p.key_mark(Mark::Line, colour, &format!("link {}", k + 1));
    }
    for k in 0..n_links {
        p.polyline(
            &series(k, |s| &s.links_ref),
            palette::INK,
            stroke::HAIR,
            true,
        );
    }
    p.key_mark(Mark::Dashed, palette::INK, "reference");
    p
}

/// (d) Top view: obstacles, the reference head path, the flown units' paths and
/// snapshots of the chain, drawn as the plan pictures draw chains.
fn top_view(
    cell: (f64, f64, f64, f64),
    flight: &Flight,
    samples: &[&Sample],
    obstacles: &[Footprint],
) -> Panel {
    let ru = flight.params.unit_radius as f64;
    let at = |s: &Sample, i: usize| (s.units[i].p[0] as f64, s.units[i].p[1] as f64);
    let xs = crate::picture::axis::finite_range(
        samples
            .iter()
            .flat_map(|s| s.units.iter().map(|u| u.p[0] as f64)),
    );
    let ys = crate::picture::axis::finite_range(
        samples
            .iter()
            .flat_map(|s| s.units.iter().map(|u| u.p[1] as f64)),
    );
    let ((x0, x1), (y0, y1)) = (xs.unwrap_or((-1.0, 1.0)), ys.unwrap_or((-1.0, 1.0)));
    let pad = 2.0 * ru + 0.1;
    let mut p = Panel::new(
        cell,
        (x0 - pad, y0 - pad),
        (x1 + pad, y1 + pad),
        "flown chain, top view (obstacles in the flight's height band)",
        ("x (m)", "y (m)"),
    );
    for o in obstacles {
        p.rect((o[0], o[1]), (o[2], o[3]), palette::OBSTACLE, 0.6);
    }
    let reference: Vec<(f64, f64)> = samples
        .iter()
        .map(|s| (s.head_ref[0] as f64, s.head_ref[1] as f64))
        .collect();
    p.polyline(&reference, palette::INK, stroke::HAIR, true);
    for i in (1..flight.params.n()).rev() {
        let trail: Vec<(f64, f64)> = samples.iter().map(|s| at(s, i)).collect();
        p.polyline(&trail, TRAIL, stroke::HAIR, false);
    }
    let head: Vec<(f64, f64)> = samples.iter().map(|s| at(s, 0)).collect();
    p.polyline(&head, palette::PATH, stroke::DATA, false);
    // Snapshots as in the plan pictures: coloured by time, taken where they overlap
    // no snapshot already drawn (the start and the end first).
    let every = (flight.samples.len() / CANDIDATES).max(1);
    let mut picks: Vec<&Sample> = flight.samples.iter().step_by(every).collect();
    if let Some(last) = flight.samples.last() {
        if !std::ptr::eq(*picks.last().unwrap_or(&last), last) {
            picks.push(last);
        }
    }
    let bodies: Vec<Vec<(f64, f64)>> = picks
        .iter()
        .map(|s| (0..s.units.len()).map(|i| at(s, i)).collect())
        .collect();
    let n = picks.len();
    let order: Vec<usize> = [0, n.saturating_sub(1)]
        .into_iter()
        .chain(1..n.saturating_sub(1))
        .filter(|&i| i < n)
        .collect();
    let t_end = picks.last().map_or(1.0, |s| s.t).max(1e-9);
    for i in super::thinned(&bodies, &order, 2.0 * ru) {
        let fill = ramp(picks[i].t / t_end);
        p.chain(&bodies[i], ru, &fill, &fill);
    }
    p.key_mark(Mark::Line, palette::PATH, "head, flown");
    p.key_mark(Mark::Line, TRAIL, "other units, flown");
    p.key_mark(Mark::Dashed, palette::INK, "head reference");
    p.key_mark(
        Mark::Ramp {
            from: 0.0,
            to: t_end,
        },
        palette::INK,
        "chain at time (s)",
    );
    p.key(palette::OBSTACLE, "obstacle");
    p
}

/// Obstacles seen from above for pictures: every column of voxels with an obstacle
/// between heights `z_lo` and `z_hi` (m), merged into runs along x, as
/// `[x0, y0, x1, y1]` rectangles.
pub fn footprint(grid: &Grid, z_lo: f64, z_hi: f64) -> Vec<Footprint> {
    let r = grid.resolution();
    let o = grid.origin();
    let d = grid.dims();
    let k0 = ((z_lo / r).floor() as i64).max(o[2] as i64);
    let k1 = ((z_hi / r).floor() as i64).min(o[2] as i64 + d[2] as i64 - 1);
    let mut out = Vec::new();
    if k0 > k1 {
        return out;
    }
    for j in o[1]..o[1] + d[1] as i32 {
        let mut run: Option<i32> = None;
        for i in o[0]..=o[0] + d[0] as i32 {
            let occupied =
                i < o[0] + d[0] as i32 && (k0..=k1).any(|k| grid.is_obstacle([i, j, k as i32]));
            match (occupied, run) {
                (true, None) => run = Some(i),
                (false, Some(s)) => {
                    out.push([s as f64 * r, j as f64 * r, i as f64 * r, (j + 1) as f64 * r]);
                    run = None;
                }
                _ => {}
            }
        }
    }
    out
}
