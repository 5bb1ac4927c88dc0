//! Charts of the benchmark studies (time and success against a size), drawn with
//! the project's [`aerial_chain::picture`] figures so they look like the other pictures.

use aerial_chain::picture::{palette, stroke, Axis, Colour, Figure, Mark, Panel};

use super::{Spread, Summary};

/// One curve: (x, median, q1, q3) points; points without a value are skipped.
pub struct Curve {
    /// Legend label.
    pub label: String,
    /// Colour.
    pub colour: Colour,
    /// Points.
    pub points: Vec<(f64, f64, f64, f64)>,
}

/// One chart of the figure; its x values are counts or sizes (ticks at whole numbers).
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

/// Radius of a data point's marker (px).
const MARKER: f64 = 3.0;

fn x_range(chart: &Chart) -> (f64, f64) {
    let xs = chart
        .curves
        .iter()
        .flat_map(|c| c.points.iter().map(|p| p.0));
    match aerial_chain::picture::finite_range(xs) {
        Some((lo, hi)) if hi > lo => {
            let pad = 0.04 * (hi - lo);
            (lo - pad, hi + pad)
        }
        Some((lo, _)) => (lo - 1.0, lo + 1.0),
        None => (0.0, 1.0),
    }
}

/// `chart` drawn in the figure's pixel rectangle `cell`: each curve as a line
/// through its medians with a marker at each, and its interquartile range as a
/// vertical bar.
fn panel(cell: (f64, f64, f64, f64), chart: &Chart) -> Panel {
    let x = Axis::linear(&chart.x_label, x_range(chart)).whole();
    let y = if chart.log_y {
        Axis::log(&chart.y_label, chart.y_range)
    } else {
        Axis::linear(&chart.y_label, chart.y_range)
    };
    let shown = |v: f64| v.is_finite() && (!chart.log_y || v > 0.0);
    let mut p = Panel::chart(cell, x, y, &chart.title);
    for curve in &chart.curves {
        let points: Vec<&(f64, f64, f64, f64)> =
            curve.points.iter().filter(|q| shown(q.1)).collect();
        for q in points
            .iter()
            .filter(|q| shown(q.2) && shown(q.3) && q.2 != q.3)
        {
            p.line((q.0, q.2), (q.0, q.3), curve.colour, stroke::HAIR);
        }
        let medians: Vec<(f64, f64)> = points.iter().map(|q| (q.0, q.1)).collect();
        p.polyline(&medians, curve.colour, stroke::DATA, false);
        for &m in &medians {
            p.marker(m, MARKER, curve.colour);
        }
        p.key_mark(Mark::Line, curve.colour, &curve.label);
    }
    p
}

/// A grid of charts (`rows` x `cols`, row-major) as an SVG document of `size` pixels.
pub fn svg(charts: &[Chart], rows: usize, cols: usize, size: (u32, u32)) -> String {
    let (w, h) = (size.0 as f64, size.1 as f64);
    let mut fig = Figure::new(w, h, "");
    for (cell, chart) in fig.cells(rows, cols, 0.0, h).into_iter().zip(charts) {
        fig.add(panel(cell, chart));
    }
    fig.to_svg()
}

/// Dots of a time chart: the points, their colour and their key.
pub type Dots<'a> = (&'a [(f64, f64)], Colour, &'a str);

/// A chart of one time (s) against another, both from 0 (labels and largest values
/// `x`, `y`), as an SVG document: the dashed line `y = x` keyed `same`, the dashed
/// target `y = target.0 x` keyed `target.1`, and the points of every one of `dots`.
pub fn times_svg(
    title: &str,
    x: (&str, f64),
    y: (&str, f64),
    same: &str,
    target: (f64, &str),
    dots: &[Dots],
) -> String {
    let mut fig = Figure::new(900.0, 600.0, "");
    let cell = fig.cells(1, 1, 0.0, 600.0)[0];
    let (x_axis, y_axis) = (Axis::linear(x.0, (0.0, x.1)), Axis::linear(y.0, (0.0, y.1)));
    let mut p = Panel::chart(cell, x_axis, y_axis, title);
    let xmax = x.1;
    p.polyline(
        &[(0.0, 0.0), (xmax, xmax)],
        palette::INK,
        stroke::HAIR,
        true,
    );
    p.key_mark(Mark::Dashed, palette::INK, same);
    let (slope, target_key) = target;
    let target_line = [(0.0, 0.0), (xmax, slope * xmax)];
    p.polyline(&target_line, palette::GOAL, stroke::DATA, true);
    p.key_mark(Mark::Dashed, palette::GOAL, target_key);
    for &(points, colour, key) in dots {
        for &q in points {
            p.marker(q, MARKER, colour);
        }
        p.key_mark(Mark::Dot, colour, key);
    }
    fig.add(p);
    fig.to_svg()
}

/// `(x, median, q1, q3)` in ms of the times `spread` picks from each of `sums`, by `x`.
fn spread_ms(
    sums: &[&Summary],
    x: impl Fn(&Summary) -> f64,
    spread: impl Fn(&Summary) -> &Spread,
) -> Vec<(f64, f64, f64, f64)> {
    sums.iter()
        .map(|s| {
            let t = spread(s);
            (x(s), t.median * 1e3, t.q1 * 1e3, t.q3 * 1e3)
        })
        .collect()
}

/// `(x, median, q1, q3)` of the successful runs' query times (ms) of `sums`, by `x`.
pub fn planning_ms(sums: &[&Summary], x: impl Fn(&Summary) -> f64) -> Vec<(f64, f64, f64, f64)> {
    spread_ms(sums, x, |s| &s.planning)
}

/// `(x, median, q1, q3)` of the roadmap build times (ms) of `sums`, by `x`.
pub fn roadmap_ms(sums: &[&Summary], x: impl Fn(&Summary) -> f64) -> Vec<(f64, f64, f64, f64)> {
    spread_ms(sums, x, |s| &s.roadmap)
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
    use aerial_chain::picture::palette;

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
                    colour: palette::PATH,
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
        let s = svg(&charts, 1, 2, (800, 400));
        assert!(s.starts_with("<svg"));
        assert!(s.contains("</svg>"));
        assert!(s.contains("DejaVu Sans") && !s.contains("font-family=\"sans-serif\""));
        assert!(!s.contains("NaN"), "gaps are skipped, not drawn");
    }
}
