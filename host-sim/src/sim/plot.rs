//! SVG plots of a flight (plotters, SVG backend only): head position against its
//! reference over time, link pitch and yaw against their references, and the flown
//! chain seen from above over the map's obstacles.

use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use super::flight::Flight;

/// At most this many points per time series (the flight is decimated evenly).
const MAX_POINTS: usize = 1500;

/// Font families, as the project's other pictures use them (resvg finds DejaVu).
const FONT: &str = "DejaVu Sans, Arial, sans-serif";

/// An obstacle footprint seen from above: `[x0, y0, x1, y1]` (m).
pub type Footprint = [f64; 4];

fn err<E: std::fmt::Display>(e: E) -> String {
    format!("plot: {e}")
}

fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return (-1.0, 1.0);
    }
    let pad = ((hi - lo) * 0.08).max(0.05);
    (lo - pad, hi + pad)
}

const AXIS: [RGBColor; 3] = [
    RGBColor(200, 40, 40),
    RGBColor(30, 140, 40),
    RGBColor(40, 70, 200),
];

/// The charts here: time or metres on both axes.
type Chart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// A chart on `area` in the project's style: caption, margins, fonts, mesh, axis names.
fn chart<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, plotters::coord::Shift>,
    caption: &str,
    (x, y): (std::ops::Range<f64>, std::ops::Range<f64>),
    (x_desc, y_desc): (&str, &str),
) -> Result<Chart<'a, DB>, String> {
    let mut c = ChartBuilder::on(area)
        .caption(caption, (FONT, 16))
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(50)
        .build_cartesian_2d(x, y)
        .map_err(err)?;
    c.configure_mesh()
        .label_style((FONT, 12))
        .axis_desc_style((FONT, 13))
        .x_desc(x_desc)
        .y_desc(y_desc)
        .draw()
        .map_err(err)?;
    Ok(c)
}

/// The legend box of `c`'s labelled series.
fn legend<'a, DB: DrawingBackend + 'a>(c: &mut Chart<'a, DB>) -> Result<(), String> {
    c.configure_series_labels()
        .label_font((FONT, 12))
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(err)
}

fn link_color(k: usize) -> RGBColor {
    const P: [RGBColor; 8] = [
        RGBColor(31, 119, 180),
        RGBColor(255, 127, 14),
        RGBColor(44, 160, 44),
        RGBColor(214, 39, 40),
        RGBColor(148, 103, 189),
        RGBColor(140, 86, 75),
        RGBColor(227, 119, 194),
        RGBColor(23, 190, 207),
    ];
    P[k % P.len()]
}

/// The flight as an SVG document (1200 x 900): four panels. `obstacles` are drawn
/// in the top view; `title` heads the picture.
pub fn flight_svg(flight: &Flight, obstacles: &[Footprint], title: &str) -> Result<String, String> {
    let mut out = String::new();
    {
        let root = SVGBackend::with_string(&mut out, (1200, 900)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let root = root.titled(title, (FONT, 22)).map_err(err)?;
        let panels = root.split_evenly((2, 2));
        let step = (flight.samples.len() / MAX_POINTS).max(1);
        let samples: Vec<_> = flight.samples.iter().step_by(step).collect();
        let t_end = samples.last().map_or(1.0, |s| s.t).max(1e-3);
        let n_links = flight.params.n() - 1;

        // (a) Head position against the reference.
        let (lo, hi) = range(samples.iter().flat_map(|s| {
            (0..3).flat_map(move |i| [s.units[0].p[i] as f64, s.head_ref[i] as f64])
        }));
        let mut c = chart(
            &panels[0],
            "head position (solid) and reference (thin black)",
            (0.0..t_end, lo..hi),
            ("t (s)", "m"),
        )?;
        for (i, name) in ["x", "y", "z"].iter().enumerate() {
            c.draw_series(LineSeries::new(
                samples.iter().map(|s| (s.t, s.head_ref[i] as f64)),
                BLACK.stroke_width(1),
            ))
            .map_err(err)?;
            c.draw_series(LineSeries::new(
                samples.iter().map(|s| (s.t, s.units[0].p[i] as f64)),
                AXIS[i].stroke_width(2),
            ))
            .map_err(err)?
            .label(*name)
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 16, y)], AXIS[i].stroke_width(2))
            });
        }
        legend(&mut c)?;

        // (b), (c) Link pitch and yaw against their references (degrees).
        for (panel, which, name) in [(1usize, 0usize, "link pitch"), (2, 1, "link yaw")] {
            let (lo, hi) = range(samples.iter().flat_map(|s| {
                s.links_meas
                    .iter()
                    .chain(s.links_ref.iter())
                    .map(move |a| (a[which] as f64).to_degrees())
            }));
            let mut c = chart(
                &panels[panel],
                &format!("{name} (solid) and reference (thin black), deg"),
                (0.0..t_end, lo..hi),
                ("t (s)", "deg"),
            )?;
            for k in 0..n_links {
                c.draw_series(LineSeries::new(
                    samples
                        .iter()
                        .map(|s| (s.t, (s.links_ref[k][which] as f64).to_degrees())),
                    BLACK.stroke_width(1),
                ))
                .map_err(err)?;
                let col = link_color(k);
                c.draw_series(LineSeries::new(
                    samples
                        .iter()
                        .map(|s| (s.t, (s.links_meas[k][which] as f64).to_degrees())),
                    col.stroke_width(2),
                ))
                .map_err(err)?
                .label(format!("link {}", k + 1))
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 16, y)], col.stroke_width(2))
                });
            }
            legend(&mut c)?;
        }

        // (d) Top view: obstacles, the reference head path, the flown units' paths and
        // snapshots of the chain.
        let xs = samples
            .iter()
            .flat_map(|s| s.units.iter().map(|u| u.p[0] as f64));
        let ys = samples
            .iter()
            .flat_map(|s| s.units.iter().map(|u| u.p[1] as f64));
        let (mut x0, mut x1) = range(xs);
        let (mut y0, mut y1) = range(ys);
        // Equal scales: grow the shorter side.
        let (w, h) = (x1 - x0, y1 - y0);
        if w > h {
            let g = 0.5 * (w - h);
            y0 -= g;
            y1 += g;
        } else {
            let g = 0.5 * (h - w);
            x0 -= g;
            x1 += g;
        }
        let mut c = chart(
            &panels[3],
            "flown chain, top view (grey: obstacles in the flight's height band)",
            (x0..x1, y0..y1),
            ("x (m)", "y (m)"),
        )?;
        let visible = obstacles
            .iter()
            .filter(|o| o[2] >= x0 && o[0] <= x1 && o[3] >= y0 && o[1] <= y1);
        c.draw_series(visible.map(|o| {
            Rectangle::new(
                [(o[0].max(x0), o[1].max(y0)), (o[2].min(x1), o[3].min(y1))],
                RGBColor(170, 170, 170).filled(),
            )
        }))
        .map_err(err)?;
        c.draw_series(LineSeries::new(
            samples
                .iter()
                .map(|s| (s.head_ref[0] as f64, s.head_ref[1] as f64)),
            BLACK.stroke_width(1),
        ))
        .map_err(err)?;
        for i in (1..flight.params.n()).rev() {
            c.draw_series(LineSeries::new(
                samples
                    .iter()
                    .map(|s| (s.units[i].p[0] as f64, s.units[i].p[1] as f64)),
                RGBColor(120, 160, 220).stroke_width(1),
            ))
            .map_err(err)?;
        }
        c.draw_series(LineSeries::new(
            samples
                .iter()
                .map(|s| (s.units[0].p[0] as f64, s.units[0].p[1] as f64)),
            AXIS[0].stroke_width(2),
        ))
        .map_err(err)?;
        let snapshots = 12usize;
        let every = (flight.samples.len() / snapshots).max(1);
        for s in flight
            .samples
            .iter()
            .step_by(every)
            .chain(flight.samples.last())
        {
            let pts: Vec<(f64, f64)> = s
                .units
                .iter()
                .map(|u| (u.p[0] as f64, u.p[1] as f64))
                .collect();
            c.draw_series(std::iter::once(PathElement::new(
                pts.clone(),
                RGBColor(20, 20, 20).stroke_width(2),
            )))
            .map_err(err)?;
            c.draw_series(pts.iter().enumerate().map(|(i, &p)| {
                let col = if i == 0 {
                    AXIS[0]
                } else {
                    RGBColor(20, 20, 20)
                };
                Circle::new(p, 3, col.filled())
            }))
            .map_err(err)?;
        }
        root.present().map_err(err)?;
    }
    Ok(out)
}
