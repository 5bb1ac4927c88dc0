//! One panel of a figure: a framed plot area with a title, axis names, ticks and an
//! optional legend, and the marks drawn in it in data coordinates.
//!
//! Two kinds: a *map* panel ([`Panel::new`]) keeps the same scale on both axes so
//! chains and walls keep their true proportions; a *chart* panel
//! ([`Panel::chart`]) scales each [`Axis`] on its own, linear or logarithmic, and
//! draws light grid lines to read values off.

use svg::node::element::{
    Circle, ClipPath, Definitions, Group, Line, LinearGradient, Polygon, Polyline, Rectangle, Stop,
};

use super::axis::{Axis, Ticks};
use super::style::{palette, size, stroke, text, text_width, Colour, Mark, RAMP_STOPS};

/// Room around the plot area for the title, tick labels and axis names (px).
#[derive(Clone, Copy, Debug)]
struct Margins {
    left: f64,
    right: f64,
    top: f64,
    bottom: f64,
}

impl Margins {
    const MAP: Margins = Margins {
        left: 46.0,
        right: 10.0,
        top: 24.0,
        bottom: 34.0,
    };
    /// Charts' tick labels are longer (`1000`, `-120`) than a map's metres.
    const CHART: Margins = Margins {
        left: 58.0,
        right: 14.0,
        top: 24.0,
        bottom: 36.0,
    };
}

/// Height of one legend row (px), in a panel's legend and the figure's.
pub(crate) const LEGEND_ROW: f64 = 16.0;

/// One panel: a rectangle of the figure showing a data region.
pub struct Panel {
    pub(crate) id: usize,
    px: (f64, f64, f64, f64),
    margins: Margins,
    x: Axis,
    y: Axis,
    /// Pixels per unit of each axis where it is uniform.
    scale: (f64, f64),
    /// A map panel: one tick step on both axes, no grid.
    equal: bool,
    title: String,
    body: Group,
    keys: Vec<(Mark, String, String)>,
    /// Pixel positions of the data drawn, to keep the legend off it.
    inked: Vec<(f64, f64)>,
}

impl Panel {
    /// A map panel at pixel rectangle `(x, y, w, h)` of its figure showing at least
    /// the data box `min..max` (widened on one axis to keep the scale equal).
    pub fn new(
        px: (f64, f64, f64, f64),
        min: (f64, f64),
        max: (f64, f64),
        title: &str,
        labels: (&str, &str),
    ) -> Self {
        let m = Margins::MAP;
        let iw = (px.2 - m.left - m.right).max(10.0);
        let ih = (px.3 - m.top - m.bottom).max(10.0);
        let (dw, dh) = ((max.0 - min.0).max(1e-6), (max.1 - min.1).max(1e-6));
        let scale = (iw / dw).min(ih / dh);
        // Centre the data box in the inner area.
        let (cx, cy) = ((min.0 + max.0) / 2.0, (min.1 + max.1) / 2.0);
        let (hw, hh) = (iw / scale / 2.0, ih / scale / 2.0);
        let x = Axis::linear(labels.0, (cx - hw, cx + hw));
        let y = Axis::linear(labels.1, (cy - hh, cy + hh));
        Self::with(px, m, x, y, true, title)
    }

    /// A chart panel at pixel rectangle `(x, y, w, h)` of its figure, each axis
    /// scaled to fill the plot area.
    pub fn chart(px: (f64, f64, f64, f64), x: Axis, y: Axis, title: &str) -> Self {
        Self::with(px, Margins::CHART, x, y, false, title)
    }

    fn with(
        px: (f64, f64, f64, f64),
        margins: Margins,
        x: Axis,
        y: Axis,
        equal: bool,
        title: &str,
    ) -> Self {
        let (iw, ih) = inner_size(px, margins);
        let scale = (iw / x.span(), ih / y.span());
        Self {
            id: 0,
            px,
            margins,
            x,
            y,
            scale,
            equal,
            title: title.to_string(),
            body: Group::new(),
            keys: Vec::new(),
            inked: Vec::new(),
        }
    }

    /// Pixel position of data point `(x, y)`.
    pub fn map(&self, x: f64, y: f64) -> (f64, f64) {
        (
            self.px.0
                + self.margins.left
                + (self.x.warp(x) - self.x.warp(self.x.min)) * self.scale.0,
            self.px.1
                + self.margins.top
                + (self.y.warp(self.y.max) - self.y.warp(y)) * self.scale.1,
        )
    }

    fn add(&mut self, node: impl Into<Box<dyn svg::Node>>) {
        let body = std::mem::take(&mut self.body);
        self.body = body.add(node);
    }

    /// Notes where data was drawn, for the legend's placement.
    fn ink(&mut self, at: (f64, f64)) {
        self.inked.push(at);
    }

    /// Adds an entry to the panel's legend, drawn in the corner of the plot area
    /// where it hides the least data.
    pub fn key(&mut self, colour: Colour, label: &str) {
        self.key_mark(Mark::Fill, colour, label);
    }

    /// Adds a legend entry marked as its data is drawn (a line, a ring, a dot).
    pub fn key_mark(&mut self, mark: Mark, colour: &str, label: &str) {
        self.keys
            .push((mark, colour.to_string(), label.to_string()));
    }

    /// A filled axis-aligned rectangle in data coordinates.
    pub fn rect(&mut self, min: (f64, f64), max: (f64, f64), fill: &str, opacity: f64) {
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

    /// A circle of data radius `r` (in units of the x axis).
    pub fn circle(&mut self, c: (f64, f64), r: f64, fill: &str, stroke: &str, opacity: f64) {
        self.disc(c, r, (fill, opacity), (stroke, stroke::HAIR));
    }

    /// A circle of data radius `r` with its fill (colour, opacity) and its rim
    /// (colour, width in pixels).
    fn disc(&mut self, c: (f64, f64), r: f64, fill: (&str, f64), rim: (&str, f64)) {
        let (x, y) = self.map(c.0, c.1);
        self.add(
            Circle::new()
                .set("cx", x)
                .set("cy", y)
                .set("r", (r * self.scale.0).max(1.0))
                .set("fill", fill.0)
                .set("fill-opacity", fill.1)
                .set("stroke", rim.0)
                .set("stroke-width", rim.1),
        );
    }

    /// A filled dot of `radius` pixels: a data point's marker.
    pub fn marker(&mut self, c: (f64, f64), radius: f64, colour: &str) {
        let (x, y) = self.map(c.0, c.1);
        self.ink((x, y));
        self.add(
            Circle::new()
                .set("cx", x)
                .set("cy", y)
                .set("r", radius)
                .set("fill", colour),
        );
    }

    /// A straight segment, `width` in pixels.
    pub fn line(&mut self, a: (f64, f64), b: (f64, f64), colour: &str, width: f64) {
        let (x1, y1) = self.map(a.0, a.1);
        let (x2, y2) = self.map(b.0, b.1);
        self.ink((x1, y1));
        self.ink((x2, y2));
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
    pub fn polyline(&mut self, pts: &[(f64, f64)], colour: &str, width: f64, dashed: bool) {
        let mapped: Vec<(f64, f64)> = pts.iter().map(|&(x, y)| self.map(x, y)).collect();
        let points: Vec<String> = mapped
            .iter()
            .map(|(u, v)| format!("{u:.2},{v:.2}"))
            .collect();
        self.inked.extend(mapped);
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
    pub fn arrow(&mut self, a: (f64, f64), dir: f64, len: f64, colour: &str) {
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

    /// A chain seen along one axis: its units (projected centres `body`, head first)
    /// as circles of data radius `r` filled with `fill` and rimmed with `rim`, joined
    /// by its links; the head's rim is dark so the chain's direction shows.
    pub fn chain(&mut self, body: &[(f64, f64)], r: f64, fill: &str, rim: &str) {
        for w in body.windows(2) {
            self.line(w[0], w[1], palette::INK, stroke::THIN);
        }
        for (i, &q) in body.iter().enumerate() {
            let edge = if i == 0 {
                (palette::INK, 1.6)
            } else {
                (rim, 1.4)
            };
            self.disc(q, r, (fill, 0.6), edge);
        }
    }

    /// A circle of data radius `r` drawn as its rim only: a region.
    pub fn ring(&mut self, c: (f64, f64), r: f64, colour: &str, dashed: bool) {
        let (x, y) = self.map(c.0, c.1);
        let mut ring = Circle::new()
            .set("cx", x)
            .set("cy", y)
            .set("r", (r * self.scale.0).max(2.0))
            .set("fill", "none")
            .set("stroke", colour)
            .set("stroke-width", 1.8);
        if dashed {
            ring = ring.set("stroke-dasharray", "5 3");
        }
        self.add(ring);
    }

    /// A square marker of half side `half` pixels centred at a data point.
    pub fn square(&mut self, c: (f64, f64), half: f64, colour: &str) {
        let (x, y) = self.map(c.0, c.1);
        self.ink((x, y));
        self.add(square(x, y, half, colour));
    }

    /// Text at a data point, `size` in pixels.
    pub fn text(&mut self, at: (f64, f64), s: &str, size: f64, colour: &str) {
        let (x, y) = self.map(at.0, at.1);
        self.add(text(x, y, s, size, colour, "middle"));
    }

    /// The plot area `(x, y, w, h)` in pixels.
    fn inner(&self) -> (f64, f64, f64, f64) {
        let (w, h) = inner_size(self.px, self.margins);
        (
            self.px.0 + self.margins.left,
            self.px.1 + self.margins.top,
            w,
            h,
        )
    }

    /// The finished panel: background, clipped body, frame, ticks, names, legend.
    pub(crate) fn finish(self) -> Group {
        let (ix, iy, iw, ih) = self.inner();
        let clip_id = format!("clip{}", self.id);
        let area = || {
            Rectangle::new()
                .set("x", ix)
                .set("y", iy)
                .set("width", iw)
                .set("height", ih)
        };
        let mut g = Group::new()
            .add(Definitions::new().add(ClipPath::new().set("id", clip_id.clone()).add(area())))
            .add(area().set("fill", "white"));
        if !self.equal {
            g = g.add(self.grid());
        }
        g = g
            .add(
                self.body
                    .clone()
                    .set("clip-path", format!("url(#{clip_id})")),
            )
            .add(area().set("fill", "none").set("stroke", palette::INK))
            .add(self.names())
            .add(self.ticks());
        if !self.keys.is_empty() {
            g = g.add(self.legend());
        }
        g
    }

    /// The panel's drawn data only, clipped to its plot area: a layer over the full
    /// panel drawn once (the frames of an animation).
    pub(crate) fn finish_overlay(self) -> Group {
        let (ix, iy, iw, ih) = self.inner();
        let clip_id = format!("overlay{}", self.id);
        Group::new()
            .add(
                Definitions::new().add(
                    ClipPath::new().set("id", clip_id.clone()).add(
                        Rectangle::new()
                            .set("x", ix)
                            .set("y", iy)
                            .set("width", iw)
                            .set("height", ih),
                    ),
                ),
            )
            .add(self.body.set("clip-path", format!("url(#{clip_id})")))
    }

    /// Title above the plot area, axis names below and to the left of it.
    fn names(&self) -> Group {
        let (x, y, _, h) = self.px;
        let (ix, iy, iw, ih) = self.inner();
        let (cx, cy) = (x + 11.0, iy + ih / 2.0);
        Group::new()
            .add(text(
                ix + iw / 2.0,
                y + 16.0,
                &self.title,
                size::PANEL_TITLE,
                palette::INK,
                "middle",
            ))
            .add(text(
                ix + iw / 2.0,
                y + h - 4.0,
                &self.x.label,
                size::LABEL,
                palette::INK,
                "middle",
            ))
            .add(
                text(cx, cy, &self.y.label, size::LABEL, palette::INK, "middle")
                    .set("transform", format!("rotate(-90 {cx} {cy})")),
            )
    }

    /// Labelled ticks on both axes: a map panel uses one step for both.
    fn tick_lists(&self) -> (Ticks, Ticks) {
        if self.equal {
            // One step on both axes where it gives each enough ticks; a short axis
            // (a corridor's width) gets a finer one of its own.
            use super::axis::{at_least, nice_step, TICK_SPACING};
            let step = nice_step(TICK_SPACING / self.scale.0);
            (
                at_least(self.x.min, self.x.max, step, 0.0),
                at_least(self.y.min, self.y.max, step, 0.0),
            )
        } else {
            let (_, _, iw, ih) = self.inner();
            (self.x.ticks(iw), self.y.ticks(ih))
        }
    }

    fn ticks(&self) -> Group {
        let (ix, iy, _, ih) = self.inner();
        let (xs, ys) = self.tick_lists();
        let mut g = Group::new();
        let tick = |x1, y1, x2, y2| hairline((x1, y1), (x2, y2), palette::INK);
        let bottom = iy + ih;
        for (v, label) in xs {
            let (u, _) = self.map(v, self.y.min);
            g = g.add(tick(u, bottom, u, bottom + 4.0)).add(text(
                u,
                bottom + 15.0,
                &label,
                size::TICK,
                palette::INK,
                "middle",
            ));
        }
        for (v, label) in ys {
            let (_, t) = self.map(self.x.min, v);
            g = g.add(tick(ix - 4.0, t, ix, t)).add(text(
                ix - 6.0,
                t + 3.5,
                &label,
                size::TICK,
                palette::INK,
                "end",
            ));
        }
        for v in self.y.minor_ticks() {
            let (_, t) = self.map(self.x.min, v);
            g = g.add(tick(ix - 2.5, t, ix, t));
        }
        g
    }

    /// Light lines at the ticks of a chart, under the data.
    fn grid(&self) -> Group {
        let (ix, iy, iw, ih) = self.inner();
        let (xs, ys) = self.tick_lists();
        let line = |x1, y1, x2, y2| hairline((x1, y1), (x2, y2), palette::GRID);
        let mut g = Group::new();
        for (v, _) in xs {
            let (u, _) = self.map(v, self.y.min);
            g = g.add(line(u, iy, u, iy + ih));
        }
        for (v, _) in ys {
            let (_, t) = self.map(self.x.min, v);
            g = g.add(line(ix, t, ix + iw, t));
        }
        g
    }

    /// The legend: a box of entries in columns, in the corner of the plot area that
    /// covers the fewest drawn points.
    fn legend(&self) -> Group {
        let (ix, iy, iw, ih) = self.inner();
        let per_column = (((0.5 * ih - 8.0) / LEGEND_ROW).floor() as usize).max(1);
        let columns = self.keys.len().div_ceil(per_column);
        let rows = self.keys.len().min(per_column);
        let widest = self
            .keys
            .iter()
            .map(|(m, _, l)| m.width() + 10.0 + text_width(l, size::LABEL))
            .fold(0.0, f64::max);
        let column_w = widest;
        let (w, h) = (
            8.0 + column_w * columns as f64,
            6.0 + LEGEND_ROW * rows as f64,
        );
        let pad = 6.0;
        let corners = [
            (ix + iw - w - pad, iy + pad),
            (ix + pad, iy + pad),
            (ix + iw - w - pad, iy + ih - h - pad),
            (ix + pad, iy + ih - h - pad),
        ];
        let covered = |&(x, y): &(f64, f64)| {
            self.inked
                .iter()
                .filter(|p| p.0 >= x && p.0 <= x + w && p.1 >= y && p.1 <= y + h)
                .count()
        };
        let (bx, by) = corners
            .iter()
            .min_by_key(|c| covered(c))
            .copied()
            .unwrap_or(corners[0]);
        let mut g = Group::new().add(
            Rectangle::new()
                .set("x", bx)
                .set("y", by)
                .set("width", w)
                .set("height", h)
                .set("fill", "white")
                .set("fill-opacity", 0.85)
                .set("stroke", palette::INK)
                .set("stroke-width", 0.6),
        );
        for (k, (mark, colour, label)) in self.keys.iter().enumerate() {
            let x = bx + 6.0 + column_w * (k / per_column) as f64;
            let y = by + 3.0 + LEGEND_ROW * (k % per_column + 1) as f64;
            g = g.add(swatch(x, y, mark, colour, label));
        }
        g
    }
}

/// One legend entry whose baseline row ends at pixel `y`: its mark in `colour` and
/// its label; the figure's legend and the panels' look the same.
pub(crate) fn swatch(x: f64, y: f64, mark: &Mark, colour: &str, label: &str) -> Group {
    let cy = y - 9.0;
    let ring = |dashed: bool| {
        let c = Circle::new()
            .set("cx", x + 5.0)
            .set("cy", cy)
            .set("r", 4.5)
            .set("fill", "none")
            .set("stroke", colour)
            .set("stroke-width", 1.8);
        if dashed {
            c.set("stroke-dasharray", "2.5 1.5")
        } else {
            c
        }
    };
    let line = |dashed: bool| {
        let l = hairline((x, cy), (x + 18.0, cy), colour).set("stroke-width", stroke::DATA);
        if dashed {
            l.set("stroke-dasharray", "6 4")
        } else {
            l
        }
    };
    let g = Group::new();
    let g = match mark {
        Mark::Fill => g.add(
            Rectangle::new()
                .set("x", x)
                .set("y", y - 14.0)
                .set("width", 10)
                .set("height", 10)
                .set("fill", colour),
        ),
        Mark::Square => g.add(square(x + 5.0, cy, 4.0, colour)),
        Mark::Line => g.add(line(false)),
        Mark::Dashed => g.add(line(true)),
        Mark::Ring => g.add(ring(false)),
        Mark::DashedRing => g.add(ring(true)),
        Mark::Dot => g.add(
            Circle::new()
                .set("cx", x + 5.0)
                .set("cy", cy)
                .set("r", 4.0)
                .set("fill", colour),
        ),
        Mark::Ramp { from, to } => ramp_bar(g, x, y, *from, *to),
    };
    g.add(text(
        x + mark.width(),
        y - 5.0,
        label,
        size::LABEL,
        palette::INK,
        "start",
    ))
}

/// The colour ramp as a bar with its two end values: the legend entry of colours
/// that stand for time.
fn ramp_bar(g: Group, x: f64, y: f64, from: f64, to: f64) -> Group {
    let n = RAMP_STOPS.len() - 1;
    let mut gradient = LinearGradient::new().set("id", "ramp");
    for k in 0..=n {
        let f = k as f64 / n as f64;
        gradient = gradient.add(
            Stop::new()
                .set("offset", f)
                .set("stop-color", super::style::ramp(f)),
        );
    }
    let decimals = if (to - from).abs() >= 10.0 { 0 } else { 1 };
    let (bx, bw) = (x + 26.0, 80.0);
    g.add(Definitions::new().add(gradient))
        .add(text(
            bx - 3.0,
            y - 5.0,
            &format!("{from:.decimals$}"),
            size::TICK,
            palette::INK,
            "end",
        ))
        .add(
            Rectangle::new()
                .set("x", bx)
                .set("y", y - 14.0)
                .set("width", bw)
                .set("height", 10)
                .set("fill", "url(#ramp)"),
        )
        .add(text(
            bx + bw + 3.0,
            y - 5.0,
            &format!("{to:.decimals$}"),
            size::TICK,
            palette::INK,
            "start",
        ))
}

/// A filled square of half side `h` pixels centred at pixel `(x, y)`.
fn square(x: f64, y: f64, h: f64, colour: &str) -> Rectangle {
    Rectangle::new()
        .set("x", x - h)
        .set("y", y - h)
        .set("width", 2.0 * h)
        .set("height", 2.0 * h)
        .set("fill", colour)
        .set("stroke", palette::INK)
        .set("stroke-width", 0.8)
}

/// A hairline between pixel positions `a` and `b`: ticks and grid lines.
fn hairline(a: (f64, f64), b: (f64, f64), colour: &str) -> Line {
    Line::new()
        .set("x1", a.0)
        .set("y1", a.1)
        .set("x2", b.0)
        .set("y2", b.1)
        .set("stroke", colour)
        .set("stroke-width", stroke::HAIR)
}

/// Width and height of the plot area of a panel of pixel rectangle `px`.
fn inner_size(px: (f64, f64, f64, f64), m: Margins) -> (f64, f64) {
    (
        (px.2 - m.left - m.right).max(10.0),
        (px.3 - m.top - m.bottom).max(10.0),
    )
}
