//! The one look of the project's pictures: colours, fonts, stroke widths and the
//! text element every label is made with.

use svg::node::element::Text;

/// A colour as an SVG colour string.
pub type Colour = &'static str;

/// Palette used across the project's pictures.
pub mod palette {
    use super::Colour;
    /// Occupied space.
    pub const OBSTACLE: Colour = "#5b5b66";
    /// Unknown space.
    pub const UNKNOWN: Colour = "#d9d4c7";
    /// The head's path.
    pub const PATH: Colour = "#1f77b4";
    /// Library (LSC) shapes.
    pub const LSC: Colour = "#2ca02c";
    /// Random (SRS) shapes.
    pub const SRS: Colour = "#d62728";
    /// The start configuration.
    pub const START: Colour = "#9467bd";
    /// The goal.
    pub const GOAL: Colour = "#ff7f0e";
    /// Sensor headings.
    pub const SENSOR: Colour = "#17becf";
    /// Follow-the-leader shapes.
    pub const FOLLOW: Colour = "#8c564b";
    /// Shape changes made smaller by refinement.
    pub const SHRUNK: Colour = "#bcbd22";
    /// Axis and text.
    pub const INK: Colour = "#222222";
    /// Grid lines of charts: light enough to read data over.
    pub const GRID: Colour = "#e4e4e4";
    /// The figure's background around the panels.
    pub const PAPER: Colour = "#fafafa";

    /// Colours of numbered series (chart curves, the links of a chain), in order;
    /// the same as the named colours above so charts and plan pictures match.
    pub const SERIES: [Colour; 10] = [
        PATH, GOAL, LSC, SRS, START, FOLLOW, "#e377c2", SENSOR, SHRUNK, OBSTACLE,
    ];

    /// The colour of series `k` (wrapping around [`SERIES`]).
    pub fn series(k: usize) -> Colour {
        SERIES[k % SERIES.len()]
    }
}

/// Stops of the colour ramp for time (or any order): viridis, its light yellow end
/// left out so that the last colour still shows on white.
pub const RAMP_STOPS: [(u8, u8, u8); 5] = [
    (0x44, 0x01, 0x54),
    (0x3b, 0x52, 0x8b),
    (0x21, 0x91, 0x8c),
    (0x5e, 0xc9, 0x62),
    (0xb5, 0xde, 0x2b),
];

/// The ramp's colour at `f` in `0..=1` (clamped), as `#rrggbb`.
pub fn ramp(f: f64) -> String {
    let f = if f.is_finite() {
        f.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let x = f * (RAMP_STOPS.len() - 1) as f64;
    let k = (x.floor() as usize).min(RAMP_STOPS.len() - 2);
    let w = x - k as f64;
    let (a, b) = (RAMP_STOPS[k], RAMP_STOPS[k + 1]);
    let mix = |p: u8, q: u8| (p as f64 + (q as f64 - p as f64) * w).round() as u8;
    format!(
        "#{:02x}{:02x}{:02x}",
        mix(a.0, b.0),
        mix(a.1, b.1),
        mix(a.2, b.2)
    )
}

/// How a legend entry is marked: as the thing it stands for is drawn.
#[derive(Clone, Debug, PartialEq)]
pub enum Mark {
    /// A filled square: an area (obstacles) or a fill colour.
    Fill,
    /// A line: a path or a curve.
    Line,
    /// A dashed line: a reference.
    Dashed,
    /// A circle's rim: what a rim colour means.
    Ring,
    /// A dashed circle: a region (the goal's).
    DashedRing,
    /// A dot: a point marker.
    Dot,
    /// A small square: the start marker.
    Square,
    /// The colour ramp from `from` to `to` (with its unit in the label).
    Ramp {
        /// The value at the ramp's first colour.
        from: f64,
        /// The value at its last colour.
        to: f64,
    },
}

impl Mark {
    /// Width (px) the mark takes before its label.
    pub(crate) fn width(&self) -> f64 {
        match self {
            Mark::Ramp { .. } => 150.0,
            Mark::Line | Mark::Dashed => 24.0,
            _ => 14.0,
        }
    }
}

/// Font families of every label (resvg finds DejaVu on the machines we use).
pub const FONT: &str = "DejaVu Sans, Arial, sans-serif";

/// Font sizes (px).
pub mod size {
    /// The figure's title.
    pub const FIGURE_TITLE: f64 = 15.0;
    /// A panel's title.
    pub const PANEL_TITLE: f64 = 13.0;
    /// Axis names and legend entries.
    pub const LABEL: f64 = 11.0;
    /// Tick labels.
    pub const TICK: f64 = 10.0;
}

/// Stroke widths (px).
pub mod stroke {
    /// A measured or planned path, a data curve.
    pub const DATA: f64 = 2.0;
    /// A reference drawn under the data, a chain's links.
    pub const THIN: f64 = 1.2;
    /// Frames, ticks, error bars.
    pub const HAIR: f64 = 1.0;
}

/// A text element at pixel `(x, y)` in the project's font; `anchor` is the SVG
/// `text-anchor` (`start`, `middle`, `end`).
pub fn text(x: f64, y: f64, s: &str, size: f64, colour: &str, anchor: &str) -> Text {
    Text::new(s)
        .set("x", x)
        .set("y", y)
        .set("font-family", FONT)
        .set("font-size", size)
        .set("fill", colour)
        .set("text-anchor", anchor)
}

/// Width (px) a label of `s` takes at `size`, roughly: for laying out legends.
pub fn text_width(s: &str, size: f64) -> f64 {
    0.59 * size * s.chars().count() as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ramp_runs_through_its_stops() {
        assert_eq!(ramp(0.0), "#440154");
        assert_eq!(ramp(1.0), "#b5de2b");
        assert_eq!(ramp(0.5), "#21918c");
        assert_eq!(ramp(-3.0), ramp(0.0));
        assert_eq!(ramp(f64::NAN), ramp(0.0));
        assert_ne!(ramp(0.3), ramp(0.31));
    }
}
