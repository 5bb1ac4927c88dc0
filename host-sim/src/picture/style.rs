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
pub fn text(x: f64, y: f64, s: &str, size: f64, colour: Colour, anchor: &str) -> Text {
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
