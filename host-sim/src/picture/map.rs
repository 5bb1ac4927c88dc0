//! Pictures of maps for people: a top view (occupancy projected over a height band)
//! and a few horizontal slices, with the scenario's start chain, route and goal when
//! there is one. Drawn with the project's [`crate::picture`] module (SVG, or PNG
//! rasterised from it).

use crate::picture::{palette, Figure, Mark, Panel};

use crate::map::grid::{Cell, Grid};
use crate::problem::scenarios::Scenario;

/// What to draw.
#[derive(Clone, Debug, PartialEq)]
pub struct MapPictureOptions {
    /// Height band `(min, max)` of the top view (m); `None`: the middle half of the box.
    pub band: Option<(f64, f64)>,
    /// Heights of the horizontal slices (m); empty: three, at a quarter, half and three
    /// quarters of the box's height.
    pub slices: Vec<f64>,
    /// Title of the figure.
    pub title: String,
}

/// How a column or a cell is drawn: 0 free (not drawn), 1 unknown, 2 occupied.
fn class(c: Cell) -> u8 {
    match c {
        Cell::Free => 0,
        Cell::Unknown => 1,
        Cell::Occupied => 2,
    }
}

/// Draws a 2D class image (`nx * ny`, x fastest) into `panel`, merging equal runs into
/// rectangles (runs along x, stacked along y while identical) to keep the SVG small.
fn draw_classes(panel: &mut Panel, grid: &Grid, img: &[u8], nx: usize, ny: usize) {
    let r = grid.resolution();
    let o = grid.origin();
    let x0 = o[0] as f64 * r;
    let y0 = o[1] as f64 * r;
    // Open rectangles: (x start, x end, class) -> y start.
    let mut open: Vec<(usize, usize, u8, usize)> = Vec::new();
    let flush = |panel: &mut Panel, (a, b, c, ys): (usize, usize, u8, usize), ye: usize| {
        let colour = if c == 2 {
            palette::OBSTACLE
        } else {
            palette::UNKNOWN
        };
        // Overlap the next row a little so anti-aliasing leaves no seams between rows.
        let top = y0 + ye as f64 * r + 0.15 * r;
        panel.rect(
            (x0 + a as f64 * r, y0 + ys as f64 * r),
            (x0 + b as f64 * r, top),
            colour,
            1.0,
        );
    };
    for y in 0..=ny {
        let mut runs: Vec<(usize, usize, u8)> = Vec::new();
        if y < ny {
            let row = &img[y * nx..(y + 1) * nx];
            let mut x = 0;
            while x < nx {
                let c = row[x];
                let s = x;
                while x < nx && row[x] == c {
                    x += 1;
                }
                if c != 0 {
                    runs.push((s, x, c));
                }
            }
        }
        let mut next_open = Vec::new();
        for rect in open.drain(..) {
            if runs.contains(&(rect.0, rect.1, rect.2)) {
                next_open.push(rect);
            } else {
                flush(panel, rect, y);
            }
        }
        for run in runs {
            if !next_open.iter().any(|o| (o.0, o.1, o.2) == run) {
                next_open.push((run.0, run.1, run.2, y));
            }
        }
        open = next_open;
    }
}

/// Local z index of the voxel layer containing height `z`, clamped into the grid.
fn layer(grid: &Grid, z: f64) -> usize {
    let i = (z / grid.resolution()).floor() as i64 - grid.origin()[2] as i64;
    i.clamp(0, grid.dims()[2] as i64 - 1) as usize
}

/// The figure for `grid`, with `scenario`'s start, route and goal drawn when given.
pub fn map_figure(grid: &Grid, scenario: Option<&Scenario>, opts: &MapPictureOptions) -> Figure {
    let [nx, ny, nz] = grid.dims();
    let (lo, hi) = grid.bounds();
    let h = hi[2] - lo[2];
    let band = opts.band.unwrap_or((lo[2] + 0.25 * h, hi[2] - 0.25 * h));
    let (z0, z1) = (layer(grid, band.0), layer(grid, band.1.max(band.0)));
    let slices: Vec<f64> = if opts.slices.is_empty() {
        [0.25, 0.5, 0.75].iter().map(|f| lo[2] + f * h).collect()
    } else {
        opts.slices.clone()
    };
    let o = grid.origin();
    let cell = |x: usize, y: usize, z: usize| {
        grid.cell([o[0] + x as i32, o[1] + y as i32, o[2] + z as i32])
    };
    // Top view: occupied if any voxel in the band is occupied, else unknown if any is.
    let mut top = vec![0u8; nx * ny];
    for y in 0..ny {
        for x in 0..nx {
            top[y * nx + x] = (z0..=z1).map(|z| class(cell(x, y, z))).max().unwrap_or(0);
        }
    }
    let (dx, dy) = (hi[0] - lo[0], hi[1] - lo[1]);
    let width = 1000.0;
    let stacked = dx > 2.0 * dy;
    let panel_h = |w: f64| ((w - 56.0) * dy / dx + 58.0).clamp(110.0, 720.0);
    let (top_h, slice_w) = (
        panel_h(width),
        if stacked {
            width
        } else {
            width / slices.len().max(1) as f64
        },
    );
    let slice_h = panel_h(slice_w);
    let height = 30.0
        + top_h
        + if stacked {
            slice_h * slices.len() as f64
        } else {
            slice_h
        }
        + 22.0;
    let mut fig = Figure::new(width, height, &opts.title);
    let labels = ("x (m)", "y (m)");
    let mut p = Panel::new(
        (0.0, 30.0, width, top_h),
        (lo[0], lo[1]),
        (hi[0], hi[1]),
        &format!(
            "top view, occupancy over z = {:.2} .. {:.2} m",
            band.0, band.1
        ),
        labels,
    );
    draw_classes(&mut p, grid, &top, nx, ny);
    if let Some(s) = scenario {
        let route: Vec<(f64, f64)> = s.route.iter().map(|q| (q[0], q[1])).collect();
        p.polyline(&route, palette::PATH, 1.5, true);
        let l = aerial_chain_core::ChainParams::DEFAULT_LINK_LENGTH as f64;
        let r = aerial_chain_core::ChainParams::DEFAULT_UNIT_RADIUS as f64;
        let (c, sn) = (s.start_yaw.cos(), s.start_yaw.sin());
        let pts: Vec<(f64, f64)> = (0..s.default_units)
            .map(|k| {
                (
                    s.start[0] - c * l * k as f64,
                    s.start[1] - sn * l * k as f64,
                )
            })
            .collect();
        p.polyline(&pts, palette::START, 2.0, false);
        for q in &pts {
            p.circle(*q, r, palette::START, palette::INK, 0.5);
        }
        p.circle((s.goal[0], s.goal[1]), r, palette::GOAL, palette::INK, 0.8);
        p.text((s.start[0], s.start[1] + 0.45), "start", 11.0, palette::INK);
        p.text((s.goal[0], s.goal[1] + 0.45), "goal", 11.0, palette::INK);
    }
    fig.add(p);
    for (k, &z) in slices.iter().enumerate() {
        let lz = layer(grid, z);
        let mut img = vec![0u8; nx * ny];
        for y in 0..ny {
            for x in 0..nx {
                img[y * nx + x] = class(cell(x, y, lz));
            }
        }
        let zc = (o[2] as f64 + lz as f64 + 0.5) * grid.resolution();
        let px = if stacked {
            (0.0, 30.0 + top_h + slice_h * k as f64, width, slice_h)
        } else {
            (slice_w * k as f64, 30.0 + top_h, slice_w, slice_h)
        };
        let mut p = Panel::new(
            px,
            (lo[0], lo[1]),
            (hi[0], hi[1]),
            &format!("slice z = {zc:.2} m"),
            labels,
        );
        draw_classes(&mut p, grid, &img, nx, ny);
        fig.add(p);
    }
    let _ = nz;
    fig.legend(palette::OBSTACLE, "occupied");
    fig.legend(palette::UNKNOWN, "unknown");
    if scenario.is_some() {
        fig.legend(palette::START, "start chain");
        fig.legend_mark(Mark::Dot, palette::GOAL, "goal");
        fig.legend_mark(Mark::Dashed, palette::PATH, "a route");
    }
    fig
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pictures_of_every_scenario() {
        for name in crate::problem::scenarios::NAMES {
            let s = crate::problem::scenarios::build(name).unwrap();
            let opts = MapPictureOptions {
                band: None,
                slices: Vec::new(),
                title: s.name.clone(),
            };
            let svg = map_figure(&s.grid, Some(&s), &opts).to_svg();
            assert!(svg.starts_with("<svg"), "{name}");
            // Runs merge: the SVG stays small.
            assert!(svg.len() < 400_000, "{name}: {} bytes", svg.len());
        }
    }
}
