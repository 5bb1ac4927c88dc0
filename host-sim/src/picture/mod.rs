//! Pictures for people, in one look: plan pictures, map pictures, flight plots and
//! benchmark charts are all [`Figure`]s of [`Panel`]s, written as SVG (built with
//! the `svg` crate) or PNG (the same SVG rasterised by `resvg`, text with the
//! system's fonts).
//!
//! - `style`: colours, fonts and stroke widths;
//! - `axis`: chart axes (linear or logarithmic) and their ticks;
//! - `panel`: one framed plot area, map (equal scale) or chart (free scales);
//! - here: the figure (title, panels, legend) and writing it out.

use std::path::{Path, PathBuf};

use svg::node::element::Rectangle;
use svg::Document;

mod animation;
pub(crate) mod axis;
mod map;
pub(crate) mod panel;
pub(crate) mod style;

pub use animation::Animation;
pub use axis::{finite_range, Axis};
pub use map::{map_figure, MapPictureOptions};
pub use panel::Panel;
pub use style::{palette, ramp, stroke, Colour, Mark};

use panel::{swatch, LEGEND_ROW};
use style::{size, text};

/// What can go wrong writing a picture.
#[derive(Debug, thiserror::Error)]
pub enum DrawError {
    /// The output's extension names no supported format.
    #[error("{}: a picture must end in {}", path.display(), PictureFormat::extensions())]
    Format {
        /// The output asked for.
        path: PathBuf,
    },
    /// The SVG could not be read back for rasterising.
    #[error("picture: {0}")]
    Svg(#[from] resvg::usvg::Error),
    /// The picture has no pixels.
    #[error("picture: empty size")]
    Empty,
    /// The PNG encoder failed.
    #[error("picture: {0}")]
    Png(String),
    /// The GIF encoder failed.
    #[error("animation: {0}")]
    Gif(String),
    /// The picture is larger than a GIF can hold (65535 pixels a side).
    #[error("animation: {0} x {1} pixels is larger than a GIF can hold")]
    TooLarge(u32, u32),
    /// The file could not be written.
    #[error("{}: {source}", path.display())]
    Write {
        /// The output.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
}

/// A figure of panels, with a title and an optional legend.
pub struct Figure {
    width: f64,
    height: f64,
    title: String,
    panels: Vec<svg::node::element::Group>,
    legend: Vec<(Mark, String, String)>,
    /// Only the panels' data, on a transparent ground: a layer over a full figure.
    overlay: bool,
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
            overlay: false,
        }
    }

    /// An empty layer of `width` x `height` pixels to draw over a figure of that size
    /// whose panels it repeats: only the data drawn in its panels shows, on a
    /// transparent ground (no title, frames, ticks or legend).
    pub fn overlay(width: f64, height: f64) -> Self {
        Self {
            overlay: true,
            ..Self::new(width, height, "")
        }
    }

    /// Width and height in pixels, extra legend rows counted.
    pub fn size(&self) -> (f64, f64) {
        let extra_rows = self.legend_layout().last().map_or(0, |l| l.1);
        (self.width, self.height + LEGEND_ROW * extra_rows as f64)
    }

    /// Adds a finished panel.
    pub fn add(&mut self, mut panel: Panel) {
        panel.id = self.panels.len();
        let group = if self.overlay {
            panel.finish_overlay()
        } else {
            panel.finish()
        };
        self.panels.push(group);
    }

    /// Pixel rectangles `(x, y, w, h)` of a `rows` x `cols` grid of panels (row by
    /// row) filling the figure's width between heights `top` and `bottom`.
    pub fn cells(
        &self,
        rows: usize,
        cols: usize,
        top: f64,
        bottom: f64,
    ) -> Vec<(f64, f64, f64, f64)> {
        let (rows, cols) = (rows.max(1), cols.max(1));
        let w = self.width / cols as f64;
        let h = (bottom - top) / rows as f64;
        (0..rows * cols)
            .map(|k| ((k % cols) as f64 * w, top + (k / cols) as f64 * h, w, h))
            .collect()
    }

    /// Adds a line of text whose right end is at pixel `(x, y)`, over the panels.
    pub fn note(&mut self, x: f64, y: f64, s: &str) {
        let t = text(x, y, s, size::PANEL_TITLE, palette::INK, "end");
        self.panels.push(svg::node::element::Group::new().add(t));
    }

    /// Adds a legend entry marked with a filled square.
    pub fn legend(&mut self, colour: Colour, label: &str) {
        self.legend_mark(Mark::Fill, colour, label);
    }

    /// Adds a legend entry marked as its data is drawn (a line, a ring, the ramp).
    pub fn legend_mark(&mut self, mark: Mark, colour: &str, label: &str) {
        self.legend
            .push((mark, colour.to_string(), label.to_string()));
    }

    /// Where each legend entry goes: `(x, row)`, wrapping onto a new row where an
    /// entry would run past the figure's right edge.
    fn legend_layout(&self) -> Vec<(f64, usize)> {
        let (mut x, mut row) = (10.0, 0);
        let mut out = Vec::with_capacity(self.legend.len());
        for (mark, _, label) in &self.legend {
            let w = mark.width() + 12.0 + style::text_width(label, size::LABEL);
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
        let (_, height) = self.size();
        let mut doc = Document::new()
            .set("viewBox", (0.0, 0.0, self.width, height))
            .set("width", self.width)
            .set("height", height);
        if self.overlay {
            for g in &self.panels {
                doc = doc.add(g.clone());
            }
            return doc.to_string();
        }
        doc = doc.add(
            Rectangle::new()
                .set("width", "100%")
                .set("height", "100%")
                .set("fill", palette::PAPER),
        );
        if !self.title.is_empty() {
            doc = doc.add(
                text(
                    self.width / 2.0,
                    18.0,
                    &self.title,
                    size::FIGURE_TITLE,
                    palette::INK,
                    "middle",
                )
                .set("font-weight", "bold"),
            );
        }
        for g in &self.panels {
            doc = doc.add(g.clone());
        }
        for ((mark, c, label), &(x, row)) in self.legend.iter().zip(&layout) {
            let y = self.height + LEGEND_ROW * row as f64;
            doc = doc.add(swatch(x, y, mark, c, label));
        }
        doc.to_string()
    }

    /// Writes the figure atomically: SVG, or PNG when the path ends in `.png`.
    pub fn save(&self, path: &Path) -> Result<(), DrawError> {
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
        crate::fsutil::by_extension(path, &Self::ALL)
    }

    /// The supported extensions, for messages: `.svg or .png`.
    pub fn extensions() -> String {
        let names: Vec<String> = Self::ALL.iter().map(|(e, _)| format!(".{e}")).collect();
        names.join(" or ")
    }
}

/// Writes `svg` to `path` in the format its extension names, atomically.
pub fn save_svg(svg: &str, path: &Path) -> Result<(), DrawError> {
    let bytes = match PictureFormat::of(path) {
        Some(PictureFormat::Svg) => svg.as_bytes().to_vec(),
        Some(PictureFormat::Png) => rasterise(svg)?,
        None => {
            return Err(DrawError::Format {
                path: path.to_path_buf(),
            })
        }
    };
    crate::fsutil::write_atomic(path, &bytes).map_err(|source| DrawError::Write {
        path: path.to_path_buf(),
        source,
    })
}

/// SVG text to PNG bytes.
pub fn rasterise(svg: &str) -> Result<Vec<u8>, DrawError> {
    render(svg, None)?
        .encode_png()
        .map_err(|e| DrawError::Png(e.to_string()))
}

/// SVG text drawn into pixels: onto a copy of `base` when given (its size kept), else
/// onto a transparent pixmap of the SVG's size.
pub(crate) fn render(
    svg: &str,
    base: Option<&resvg::tiny_skia::Pixmap>,
) -> Result<resvg::tiny_skia::Pixmap, DrawError> {
    use resvg::{tiny_skia, usvg};
    let mut opt = usvg::Options::default();
    opt.fontdb_mut().load_system_fonts();
    let tree = usvg::Tree::from_str(svg, &opt)?;
    let mut pixmap = match base {
        Some(b) => b.clone(),
        None => {
            let size = tree.size().to_int_size();
            tiny_skia::Pixmap::new(size.width(), size.height()).ok_or(DrawError::Empty)?
        }
    };
    resvg::render(&tree, tiny_skia::Transform::default(), &mut pixmap.as_mut());
    Ok(pixmap)
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
            .to_string()
            .contains(".svg or .png"));
    }
}
