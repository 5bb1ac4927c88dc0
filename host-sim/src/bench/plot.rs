//! Line charts of the scaling study (plotters, SVG; PNG through the project's rasteriser).

use plotters::prelude::*;

use super::Summary;

/// One curve: (x, median, q1, q3) points; points without a value are skipped.
pub struct Curve {
    /// Legend label.
    pub label: String,
    /// Colour.
    pub colour: RGBColor,
    /// Points.
    pub points: Vec<(f64, f64, f64, f64)>,
}

/// One chart of the figure.
pub struct Chart {
    /// Title.
    pub title: String,
    /// X axis label.
    pub x_label: String,
    /// Y axis label.
    pub y_label: String,
    /// Log scale on y.
    pub log_y: bool,
    /// Y range.
    pub y_range: (f64, f64),
    /// Curves.
    pub curves: Vec<Curve>,
}

fn x_range(charts: &Chart) -> (f64, f64) {
    let xs = charts
        .curves
        .iter()
        .flat_map(|c| c.points.iter().map(|p| p.0));
    let (lo, hi) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
        (a.min(x), b.max(x))
    });
    if lo.is_finite() && hi > lo {
        let pad = 0.04 * (hi - lo);
        (lo - pad, hi + pad)
    } else if lo.is_finite() {
        (lo - 1.0, lo + 1.0)
    } else {
        (0.0, 1.0)
    }
}

fn draw_one<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    c: &Chart,
) -> Result<(), String> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| format!("plot: {e}");
    let (x0, x1) = x_range(c);
    let mut b = ChartBuilder::on(area);
    b.caption(&c.title, ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60);
    let ok = |p: &(f64, f64, f64, f64)| p.1.is_finite() && (!c.log_y || p.1 > 0.0);
    macro_rules! body {
        ($chart:expr) => {{
            let mut ch = $chart;
            let whole = |x: &f64| format!("{x:.0}");
            ch.configure_mesh()
                .light_line_style(WHITE)
                .x_label_formatter(&whole)
                .x_desc(c.x_label.as_str())
                .y_desc(c.y_label.as_str())
                .draw()
                .map_err(err)?;
            for cu in &c.curves {
                let col = cu.colour;
                let pts: Vec<(f64, f64)> = cu
                    .points
                    .iter()
                    .filter(|p| ok(p))
                    .map(|p| (p.0, p.1))
                    .collect();
                ch.draw_series(LineSeries::new(pts.clone(), col.stroke_width(2)))
                    .map_err(err)?
                    .label(cu.label.as_str())
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], col.stroke_width(2))
                    });
                ch.draw_series(pts.iter().map(|&p| Circle::new(p, 3, col.filled())))
                    .map_err(err)?;
                // Interquartile range as vertical bars.
                ch.draw_series(
                    cu.points
                        .iter()
                        .filter(|p| ok(p) && p.2.is_finite() && p.3.is_finite())
                        .filter(|p| !c.log_y || p.2 > 0.0)
                        .map(|p| {
                            PathElement::new(vec![(p.0, p.2), (p.0, p.3)], col.stroke_width(1))
                        }),
                )
                .map_err(err)?;
            }
            ch.configure_series_labels()
                .background_style(WHITE.mix(0.8))
                .border_style(BLACK)
                .position(SeriesLabelPosition::UpperLeft)
                .draw()
                .map_err(err)?;
        }};
    }
    if c.log_y {
        body!(b
            .build_cartesian_2d(x0..x1, (c.y_range.0..c.y_range.1).log_scale())
            .map_err(err)?);
    } else {
        body!(b
            .build_cartesian_2d(x0..x1, c.y_range.0..c.y_range.1)
            .map_err(err)?);
    }
    Ok(())
}

/// A grid of charts (`rows` x `cols`, row-major) as an SVG document.
pub fn svg(charts: &[Chart], rows: usize, cols: usize, size: (u32, u32)) -> Result<String, String> {
    let mut buf = String::new();
    {
        let root = SVGBackend::with_string(&mut buf, size).into_drawing_area();
        root.fill(&WHITE).map_err(|e| format!("plot: {e}"))?;
        let areas = root.split_evenly((rows.max(1), cols.max(1)));
        for (a, c) in areas.iter().zip(charts) {
            draw_one(a, c)?;
        }
        root.present().map_err(|e| format!("plot: {e}"))?;
    }
    // The rasteriser maps the generic "sans-serif" to Arial, which may be missing: name
    // the fonts the project's pictures use first.
    Ok(buf.replace(
        "font-family=\"sans-serif\"",
        "font-family=\"DejaVu Sans, Arial, sans-serif\"",
    ))
}

/// `(x, median, q1, q3)` of the successful runs' query times (ms) of `sums`, by `x`.
pub fn planning_ms(sums: &[&Summary], x: impl Fn(&Summary) -> f64) -> Vec<(f64, f64, f64, f64)> {
    sums.iter()
        .map(|s| {
            (
                x(s),
                s.planning.median * 1e3,
                s.planning.q1 * 1e3,
                s.planning.q3 * 1e3,
            )
        })
        .collect()
}

/// `(x, median, q1, q3)` of the roadmap build times (ms) of `sums`, by `x`.
pub fn roadmap_ms(sums: &[&Summary], x: impl Fn(&Summary) -> f64) -> Vec<(f64, f64, f64, f64)> {
    sums.iter()
        .map(|s| {
            (
                x(s),
                s.roadmap.median * 1e3,
                s.roadmap.q1 * 1e3,
                s.roadmap.q3 * 1e3,
            )
        })
        .collect()
}

/// `(x, success %, -, -)` of `sums`, by `x`.
pub fn success_pct(sums: &[&Summary], x: impl Fn(&Summary) -> f64) -> Vec<(f64, f64, f64, f64)> {
    sums.iter()
        .map(|s| (x(s), 100.0 * s.success_rate(), f64::NAN, f64::NAN))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_an_svg_even_with_gaps() {
        let charts = vec![
            Chart {
                title: "t".into(),
                x_label: "N".into(),
                y_label: "ms".into(),
                log_y: true,
                y_range: (0.1, 1e5),
                curves: vec![Curve {
                    label: "a".into(),
                    colour: BLUE,
                    points: vec![
                        (3.0, 10.0, 5.0, 20.0),
                        (4.0, f64::NAN, f64::NAN, f64::NAN),
                        (5.0, 0.0, 0.0, 1.0),
                    ],
                }],
            },
            Chart {
                title: "s".into(),
                x_label: "N".into(),
                y_label: "%".into(),
                log_y: false,
                y_range: (0.0, 105.0),
                curves: vec![],
            },
        ];
        let s = svg(&charts, 1, 2, (800, 400)).unwrap();
        assert!(s.starts_with("<svg"));
        assert!(s.contains("</svg>"));
        assert!(s.contains("DejaVu Sans") && !s.contains("font-family=\"sans-serif\""));
    }
}
