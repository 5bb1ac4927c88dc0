//! Pictures for people: figures of one or more panels in metric coordinates (top
//! and side views), written as SVG (built with the `svg` crate) or PNG (the same
//! SVG rasterised by `resvg`, text with the system's fonts).
//!
//! A [`Panel`] maps data coordinates (metres) to pixels with equal scale on both
//! axes, so chains and walls keep their true proportions.

use std::path::Path;

use svg::node::element::{
    Circle, ClipPath, Definitions, Group, Line, Polygon, Polyline, Rectangle, Text,
};
use svg::Document;

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
}

const MARGIN_LEFT: f64 = 46.0;
const MARGIN_BOTTOM: f64 = 34.0;
const MARGIN_TOP: f64 = 24.0;
const MARGIN_RIGHT: f64 = 10.0;

/// One chart: a rectangle of the figure showing a metric region.
pub struct Panel {
    id: usize,
    px: (f64, f64, f64, f64),
    min: (f64, f64),
    max: (f64, f64),
    scale: f64,
    title: String,
    labels: (String, String),
    body: Group,
}

impl Panel {
    /// A panel at pixel rectangle `(x, y, w, h)` of its figure showing at least the
    /// data box `min..max` (widened on one axis to keep the scale equal).
    pub fn new(
        px: (f64, f64, f64, f64),
        min: (f64, f64),
        max: (f64, f64),
        title: &str,
        labels: (&str, &str),
    ) -> Self {
        let iw = (px.2 - MARGIN_LEFT - MARGIN_RIGHT).max(10.0);
        let ih = (px.3 - MARGIN_TOP - MARGIN_BOTTOM).max(10.0);
        let (dw, dh) = ((max.0 - min.0).max(1e-6), (max.1 - min.1).max(1e-6));
        let scale = (iw / dw).min(ih / dh);
        // Centre the data box in the inner area.
        let (cx, cy) = ((min.0 + max.0) / 2.0, (min.1 + max.1) / 2.0);
        let (hw, hh) = (iw / scale / 2.0, ih / scale / 2.0);
        Self {
            id: 0,
            px,
            min: (cx - hw, cy - hh),
            max: (cx + hw, cy + hh),
            scale,
            title: title.to_string(),
            labels: (labels.0.to_string(), labels.1.to_string()),
            body: Group::new(),
        }
    }

    /// Pixel position of data point `(x, y)`.
    pub fn map(&self, x: f64, y: f64) -> (f64, f64) {
        (
            self.px.0 + MARGIN_LEFT + (x - self.min.0) * self.scale,
            self.px.1 + MARGIN_TOP + (self.max.1 - y) * self.scale,
        )
    }

    fn add(&mut self, node: impl Into<Box<dyn svg::Node>>) {
        let body = std::mem::take(&mut self.body);
        self.body = body.add(node);
    }

    /// A filled axis-aligned rectangle in data coordinates.
    pub fn rect(&mut self, min: (f64, f64), max: (f64, f64), fill: Colour, opacity: f64) {
        let (x0, y1) = self.map(min.0, min.1);
        let (x1, y0) = self.map(max.0, max.1);
        self.add(
            Rectangle::new()
                .set("x", x0)
                .set("y", y0)
                .set("width", (x1 - x0).max(0.3))
                .set("height", (y1 - y0).max(0.3))
                .set("fill", fill)
                .set("fill-opacity", opacity)
                .set("shape-rendering", "crispEdges"),
        );
    }

    /// A circle of data radius `r`.
    pub fn circle(&mut self, c: (f64, f64), r: f64, fill: Colour, stroke: Colour, opacity: f64) {
        let (x, y) = self.map(c.0, c.1);
        self.add(
            Circle::new()
                .set("cx", x)
                .set("cy", y)
                .set("r", (r * self.scale).max(1.0))
                .set("fill", fill)
                .set("fill-opacity", opacity)
                .set("stroke", stroke)
                .set("stroke-width", 1.0),
        );
    }

    /// A straight segment, `width` in pixels.
    pub fn line(&mut self, a: (f64, f64), b: (f64, f64), colour: Colour, width: f64) {
        let (x1, y1) = self.map(a.0, a.1);
        let (x2, y2) = self.map(b.0, b.1);
        self.add(
            Line::new()
                .set("x1", x1)
                .set("y1", y1)
                .set("x2", x2)
                .set("y2", y2)
                .set("stroke", colour)
                .set("stroke-width", width)
                .set("stroke-linecap", "round"),
        );
    }

    /// A polyline through data points, `width` in pixels; `dashed` for references.
    pub fn polyline(&mut self, pts: &[(f64, f64)], colour: Colour, width: f64, dashed: bool) {
        let points: Vec<String> = pts
            .iter()
            .map(|&(x, y)| {
                let (u, v) = self.map(x, y);
                format!("{u:.2},{v:.2}")
            })
            .collect();
        let mut p = Polyline::new()
            .set("points", points.join(" "))
            .set("fill", "none")
            .set("stroke", colour)
            .set("stroke-width", width)
            .set("stroke-linejoin", "round");
        if dashed {
            p = p.set("stroke-dasharray", "6 4");
        }
        self.add(p);
    }

    /// An arrow from `a` of data length `len` at angle `dir` (rad, from +x).
    pub fn arrow(&mut self, a: (f64, f64), dir: f64, len: f64, colour: Colour) {
        let b = (a.0 + len * dir.cos(), a.1 + len * dir.sin());
        self.line(a, b, colour, 1.5);
        let head = 0.35 * len;
        let pts: Vec<String> = [(b.0, b.1), (dir + 2.7, head), (dir - 2.7, head)]
            .iter()
            .enumerate()
            .map(|(i, &(p, q))| {
                let (x, y) = if i == 0 {
                    (p, q)
                } else {
                    (b.0 + q * p.cos(), b.1 + q * p.sin())
                };
                let (u, v) = self.map(x, y);
                format!("{u:.2},{v:.2}")
            })
            .collect();
        self.add(
            Polygon::new()
                .set("points", pts.join(" "))
                .set("fill", colour),
        );
    }

    /// Text at a data point, `size` in pixels.
    pub fn text(&mut self, at: (f64, f64), s: &str, size: f64, colour: Colour) {
        let (x, y) = self.map(at.0, at.1);
        self.add(text(x, y, s, size, colour, "middle"));
    }

    /// The finished panel: frame, ticks, labels and the clipped body.
    fn finish(self) -> Group {
        let (x, y, w, h) = self.px;
        let (ix, iy) = (x + MARGIN_LEFT, y + MARGIN_TOP);
        let (iw, ih) = (
            w - MARGIN_LEFT - MARGIN_RIGHT,
            h - MARGIN_TOP - MARGIN_BOTTOM,
        );
        let clip_id = format!("clip{}", self.id);
        let clip = ClipPath::new().set("id", clip_id.clone()).add(
            Rectangle::new()
                .set("x", ix)
                .set("y", iy)
                .set("width", iw)
                .set("height", ih),
        );
        let mut g = Group::new()
            .add(Definitions::new().add(clip))
            .add(
                Rectangle::new()
                    .set("x", ix)
                    .set("y", iy)
                    .set("width", iw)
                    .set("height", ih)
                    .set("fill", "white"),
            )
            .add(
                self.body
                    .clone()
                    .set("clip-path", format!("url(#{clip_id})")),
            )
            .add(
                Rectangle::new()
                    .set("x", ix)
                    .set("y", iy)
                    .set("width", iw)
                    .set("height", ih)
                    .set("fill", "none")
                    .set("stroke", palette::INK),
            )
            .add(text(
                ix + iw / 2.0,
                y + 16.0,
                &self.title,
                13.0,
                palette::INK,
                "middle",
            ))
            .add(text(
                ix + iw / 2.0,
                y + h - 4.0,
                &self.labels.0,
                11.0,
                palette::INK,
                "middle",
            ))
            .add(
                text(
                    x + 11.0,
                    iy + ih / 2.0,
                    &self.labels.1,
                    11.0,
                    palette::INK,
                    "middle",
                )
                .set(
                    "transform",
                    format!("rotate(-90 {} {})", x + 11.0, iy + ih / 2.0),
                ),
            );
        let step = nice_step((self.max.0 - self.min.0).max(self.max.1 - self.min.1) / 6.0);
        for v in ticks(self.min.0, self.max.0, step) {
            let (u, _) = self.map(v, self.min.1);
            g = g
                .add(
                    Line::new()
                        .set("x1", u)
                        .set("y1", iy + ih)
                        .set("x2", u)
                        .set("y2", iy + ih + 4.0)
                        .set("stroke", palette::INK),
                )
                .add(text(
                    u,
                    iy + ih + 15.0,
                    &fmt_tick(v, step),
                    10.0,
                    palette::INK,
                    "middle",
                ));
        }
        for v in ticks(self.min.1, self.max.1, step) {
            let (_, t) = self.map(self.min.0, v);
            g = g
                .add(
                    Line::new()
                        .set("x1", ix - 4.0)
                        .set("y1", t)
                        .set("x2", ix)
                        .set("y2", t)
                        .set("stroke", palette::INK),
                )
                .add(text(
                    ix - 6.0,
                    t + 3.5,
                    &fmt_tick(v, step),
                    10.0,
                    palette::INK,
                    "end",
                ));
        }
        g
    }
}

fn text(x: f64, y: f64, s: &str, size: f64, colour: Colour, anchor: &str) -> Text {
    Text::new(s)
        .set("x", x)
        .set("y", y)
        .set("font-family", "DejaVu Sans, Arial, sans-serif")
        .set("font-size", size)
        .set("fill", colour)
        .set("text-anchor", anchor)
}

/// 1, 2 or 5 times a power of ten, at least `raw`.
fn nice_step(raw: f64) -> f64 {
    let raw = raw.max(1e-9);
    let p = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * p)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * p)
}

fn ticks(lo: f64, hi: f64, step: f64) -> impl Iterator<Item = f64> {
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    (first..=last).map(move |i| i as f64 * step)
}

fn fmt_tick(v: f64, step: f64) -> String {
    if step >= 1.0 {
        format!("{v:.0}")
    } else if step >= 0.1 {
        format!("{v:.1}")
    } else {
        format!("{v:.2}")
    }
}

/// Height of one extra row of legend entries (px).
const LEGEND_ROW: f64 = 16.0;

/// A figure of panels, with a title and an optional legend.
pub struct Figure {
    width: f64,
    height: f64,
    title: String,
    panels: Vec<Group>,
    legend: Vec<(Colour, String)>,
}

impl Figure {
    /// An empty figure of `width` x `height` pixels.
    pub fn new(width: f64, height: f64, title: &str) -> Self {
        Self {
            width,
            height,
            title: title.to_string(),
            panels: Vec::new(),
            legend: Vec::new(),
        }
    }

    /// Adds a finished panel.
    pub fn add(&mut self, mut panel: Panel) {
        panel.id = self.panels.len();
        self.panels.push(panel.finish());
    }

    /// Adds a legend entry.
    pub fn legend(&mut self, colour: Colour, label: &str) {
        self.legend.push((colour, label.to_string()));
    }

    /// Where each legend entry goes: `(x, row)`, wrapping onto a new row where an
    /// entry would run past the figure's right edge.
    fn legend_layout(&self) -> Vec<(f64, usize)> {
        let (mut x, mut row) = (10.0, 0);
        let mut out = Vec::with_capacity(self.legend.len());
        for (_, label) in &self.legend {
            let w = 24.0 + 6.5 * label.len() as f64;
            if x > 10.0 && x + w > self.width - 10.0 {
                (x, row) = (10.0, row + 1);
            }
            out.push((x, row));
            x += w;
        }
        out
    }

    /// The SVG document. Extra legend rows add to the figure's height.
    pub fn to_svg(&self) -> String {
        let layout = self.legend_layout();
        let extra_rows = layout.last().map_or(0, |l| l.1);
        let height = self.height + LEGEND_ROW * extra_rows as f64;
        let mut doc = Document::new()
            .set("viewBox", (0.0, 0.0, self.width, height))
            .set("width", self.width)
            .set("height", height)
            .add(
                Rectangle::new()
                    .set("width", "100%")
                    .set("height", "100%")
                    .set("fill", "#fafafa"),
            )
            .add(
                text(
                    self.width / 2.0,
                    18.0,
                    &self.title,
                    15.0,
                    palette::INK,
                    "middle",
                )
                .set("font-weight", "bold"),
            );
        for g in &self.panels {
            doc = doc.add(g.clone());
        }
        for ((c, label), &(x, row)) in self.legend.iter().zip(&layout) {
            let y = self.height + LEGEND_ROW * row as f64;
            doc = doc
                .add(
                    Rectangle::new()
                        .set("x", x)
                        .set("y", y - 14.0)
                        .set("width", 10)
                        .set("height", 10)
                        .set("fill", *c),
                )
                .add(text(x + 14.0, y - 5.0, label, 11.0, palette::INK, "start"));
        }
        doc.to_string()
    }

    /// Writes the figure atomically: SVG, or PNG when the path ends in `.png`.
    pub fn save(&self, path: &Path) -> Result<(), String> {
        save_svg(&self.to_svg(), path)
    }
}

/// The formats a picture can be written in, by the output's extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PictureFormat {
    /// Scalable vector graphics.
    Svg,
    /// A raster image, rendered from the SVG.
    Png,
}

impl PictureFormat {
    /// Every supported format and its extension; a new format is one more row.
    const ALL: [(&'static str, PictureFormat); 2] =
        [("svg", PictureFormat::Svg), ("png", PictureFormat::Png)];

    /// The format of `path` by its extension (any case).
    pub fn of(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        Self::ALL.iter().find(|(e, _)| *e == ext).map(|&(_, f)| f)
    }

    /// The supported extensions, for messages: `.svg or .png`.
    pub fn extensions() -> String {
        let names: Vec<String> = Self::ALL.iter().map(|(e, _)| format!(".{e}")).collect();
        names.join(" or ")
    }
}

/// Writes `svg` to `path` in the format its extension names, atomically.
pub fn save_svg(svg: &str, path: &Path) -> Result<(), String> {
    let bytes = match PictureFormat::of(path) {
        Some(PictureFormat::Svg) => svg.as_bytes().to_vec(),
        Some(PictureFormat::Png) => rasterise(svg)?,
        None => {
            return Err(format!(
                "{}: a picture must end in {}",
                path.display(),
                PictureFormat::extensions()
            ))
        }
    };
    crate::fsutil::write_atomic(path, &bytes).map_err(|e| format!("{}: {e}", path.display()))
}

/// SVG text to PNG bytes.
pub fn rasterise(svg: &str) -> Result<Vec<u8>, String> {
    use resvg::{tiny_skia, usvg};
    let mut opt = usvg::Options::default();
    opt.fontdb_mut().load_system_fonts();
    let tree = usvg::Tree::from_str(svg, &opt).map_err(|e| format!("picture: {e}"))?;
    let size = tree.size().to_int_size();
    let mut pixmap = tiny_skia::Pixmap::new(size.width(), size.height())
        .ok_or_else(|| "picture: empty size".to_string())?;
    resvg::render(&tree, tiny_skia::Transform::default(), &mut pixmap.as_mut());
    pixmap.encode_png().map_err(|e| format!("picture: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn figure() -> Figure {
        let mut f = Figure::new(400.0, 300.0, "test");
        let mut p = Panel::new(
            (0.0, 20.0, 400.0, 260.0),
            (-1.0, -1.0),
            (1.0, 1.0),
            "top",
            ("x (m)", "y (m)"),
        );
        p.circle((0.0, 0.0), 0.2, palette::LSC, palette::INK, 0.5);
        p.rect((0.5, 0.5), (0.7, 0.9), palette::OBSTACLE, 1.0);
        p.arrow((0.0, 0.0), 0.5, 0.3, palette::SENSOR);
        f.add(p);
        f.legend(palette::LSC, "LSC");
        f
    }

    #[test]
    fn equal_scale_and_orientation() {
        let p = Panel::new(
            (0.0, 0.0, 300.0, 200.0),
            (0.0, 0.0),
            (10.0, 1.0),
            "",
            ("", ""),
        );
        let (a, b) = (p.map(0.0, 0.0), p.map(1.0, 1.0));
        assert!(
            ((b.0 - a.0) - (a.1 - b.1)).abs() < 1e-9,
            "same pixels per metre on both axes, y up"
        );
    }

    #[test]
    fn svg_and_png_are_written() {
        let dir = tempfile::tempdir().unwrap();
        let f = figure();
        f.save(&dir.path().join("a.svg")).unwrap();
        let svg = std::fs::read_to_string(dir.path().join("a.svg")).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("circle"));
        f.save(&dir.path().join("a.png")).unwrap();
        let png = std::fs::read(dir.path().join("a.png")).unwrap();
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
        assert!(f
            .save(&dir.path().join("a.gif"))
            .unwrap_err()
            .contains(".svg or .png"));
    }
}
