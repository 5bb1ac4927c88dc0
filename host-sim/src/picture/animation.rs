//! Animations: a still background figure and, per frame, an overlay of the data that
//! moves, written as an animated GIF (the `gif` crate of image-rs).
//!
//! The background is rasterised once and each frame's overlay drawn onto a copy, so a
//! frame costs only its moving marks. Every frame is quantised to one global palette
//! learnt from a few sample frames (NeuQuant, `color_quant`), and after the first only
//! the rectangle that changed is stored, with unchanged pixels transparent: a
//! hundred-frame animation of a chain stays within a few hundred kilobytes.

use std::collections::HashMap;
use std::path::Path;

use resvg::tiny_skia::Pixmap;

use super::{render, DrawError, Figure};

/// Index of the transparent colour: the palette's last entry, never a learnt colour.
const TRANSPARENT: u8 = 255;

/// Frames the global palette is learnt from, spread over the animation.
const PALETTE_SAMPLES: usize = 5;

/// An animation being made: its background and frame timing.
pub struct Animation {
    background: Pixmap,
    /// Hundredths of a second each frame shows.
    delay_cs: u16,
    /// Hundredths of a second the last frame shows before the loop starts over.
    last_delay_cs: u16,
}

impl Animation {
    /// An animation over `background`, each frame shown `delay_cs` hundredths of a
    /// second and the last `last_delay_cs`.
    pub fn new(background: &Figure, delay_cs: u16, last_delay_cs: u16) -> Result<Self, DrawError> {
        Ok(Self {
            background: render(&background.to_svg(), None)?,
            delay_cs: delay_cs.max(2),
            last_delay_cs: last_delay_cs.max(delay_cs).max(2),
        })
    }

    /// The pixels of one frame: the background with `overlay` drawn over it.
    fn frame(&self, overlay: &Figure) -> Result<Pixmap, DrawError> {
        render(&overlay.to_svg(), Some(&self.background))
    }

    /// The GIF of `frames` overlays, `count` of them (made lazily by `frame_at`, at
    /// most twice each: once for the palette's samples, once to encode).
    pub fn gif(
        &self,
        count: usize,
        frame_at: &dyn Fn(usize) -> Figure,
    ) -> Result<Vec<u8>, DrawError> {
        if count == 0 {
            return Err(DrawError::Empty);
        }
        let (w, h) = (self.background.width(), self.background.height());
        let (gw, gh) = (
            u16::try_from(w).map_err(|_| DrawError::TooLarge(w, h))?,
            u16::try_from(h).map_err(|_| DrawError::TooLarge(w, h))?,
        );
        let palette = self.palette(count, frame_at)?;
        let mut out = Vec::new();
        {
            let mut enc = gif::Encoder::new(&mut out, gw, gh, &palette.rgb)
                .map_err(|e| DrawError::Gif(e.to_string()))?;
            enc.set_repeat(gif::Repeat::Infinite)
                .map_err(|e| DrawError::Gif(e.to_string()))?;
            let mut lookup = HashMap::new();
            let mut previous: Option<Pixmap> = None;
            for k in 0..count {
                let pixels = self.frame(&frame_at(k))?;
                let mut frame = changed(&pixels, previous.as_ref(), |p| {
                    *lookup.entry(p).or_insert_with(|| palette.index_of(p))
                });
                frame.delay = if k + 1 == count {
                    self.last_delay_cs
                } else {
                    self.delay_cs
                };
                enc.write_frame(&frame)
                    .map_err(|e| DrawError::Gif(e.to_string()))?;
                previous = Some(pixels);
            }
        }
        Ok(out)
    }

    /// The global palette, learnt from frames spread over the animation.
    fn palette(
        &self,
        count: usize,
        frame_at: &dyn Fn(usize) -> Figure,
    ) -> Result<Palette, DrawError> {
        let mut samples = Vec::new();
        let picks = PALETTE_SAMPLES.min(count);
        for s in 0..picks {
            let k = if picks == 1 {
                0
            } else {
                s * (count - 1) / (picks - 1)
            };
            samples.extend_from_slice(self.frame(&frame_at(k))?.data());
        }
        let quant = color_quant::NeuQuant::new(10, TRANSPARENT as usize, &samples);
        let mut rgb = quant.color_map_rgb();
        rgb.resize(256 * 3, 0);
        Ok(Palette { quant, rgb })
    }

    /// Writes `gif` bytes to `path` atomically: an error leaves no file behind.
    pub fn save(bytes: &[u8], path: &Path) -> Result<(), DrawError> {
        crate::fsutil::write_atomic(path, bytes).map_err(|source| DrawError::Write {
            path: path.to_path_buf(),
            source,
        })
    }
}

/// The learnt colours and the GIF's colour table (256 entries, the last transparent).
struct Palette {
    quant: color_quant::NeuQuant,
    rgb: Vec<u8>,
}

impl Palette {
    /// The palette index nearest to pixel `p` (RGBA packed in a `u32`).
    fn index_of(&self, p: u32) -> u8 {
        let [r, g, b, _] = p.to_le_bytes();
        self.quant.index_of(&[r, g, b, 255]) as u8
    }
}

/// The frame that turns `previous` into `pixels`: the rectangle where they differ,
/// unchanged pixels in it transparent (the whole picture when there is no previous).
fn changed(
    pixels: &Pixmap,
    previous: Option<&Pixmap>,
    mut index_of: impl FnMut(u32) -> u8,
) -> gif::Frame<'static> {
    let w = pixels.width() as usize;
    let px = |pm: &Pixmap, i: usize| {
        let d = &pm.data()[4 * i..4 * i + 4];
        u32::from_le_bytes([d[0], d[1], d[2], d[3]])
    };
    let differs = |i: usize| previous.is_none_or(|p| px(p, i) != px(pixels, i));
    let (mut x0, mut y0, mut x1, mut y1) = (usize::MAX, usize::MAX, 0, 0);
    for i in 0..w * pixels.height() as usize {
        if differs(i) {
            let (x, y) = (i % w, i / w);
            (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x), y1.max(y));
        }
    }
    if x0 == usize::MAX {
        // Nothing changed: one transparent pixel carries the frame's delay.
        (x0, y0, x1, y1) = (0, 0, 0, 0);
    }
    let mut buffer = Vec::with_capacity((x1 - x0 + 1) * (y1 - y0 + 1));
    for y in y0..=y1 {
        for x in x0..=x1 {
            let i = y * w + x;
            buffer.push(if differs(i) {
                index_of(px(pixels, i))
            } else {
                TRANSPARENT
            });
        }
    }
    gif::Frame {
        left: x0 as u16,
        top: y0 as u16,
        width: (x1 - x0 + 1) as u16,
        height: (y1 - y0 + 1) as u16,
        buffer: buffer.into(),
        transparent: Some(TRANSPARENT),
        dispose: gif::DisposalMethod::Keep,
        ..gif::Frame::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::picture::{palette, Panel};

    fn panel() -> Panel {
        Panel::new(
            (0.0, 20.0, 200.0, 160.0),
            (0.0, 0.0),
            (4.0, 3.0),
            "p",
            ("x", "y"),
        )
    }

    #[test]
    fn frames_decode_with_their_delays_and_differ() {
        let mut bg = Figure::new(200.0, 200.0, "moving dot");
        let mut p = panel();
        p.rect((0.0, 0.0), (1.0, 1.0), palette::OBSTACLE, 1.0);
        bg.add(p);
        let frame = |k: usize| {
            let mut f = Figure::overlay(200.0, 200.0);
            let mut p = panel();
            p.marker((0.5 + k as f64, 2.0), 5.0, palette::PATH);
            f.add(p);
            f
        };
        let anim = Animation::new(&bg, 10, 100).unwrap();
        let bytes = anim.gif(3, &frame).unwrap();
        let mut opts = gif::DecodeOptions::new();
        opts.set_color_output(gif::ColorOutput::RGBA);
        let mut dec = opts.read_info(bytes.as_slice()).unwrap();
        let mut delays = Vec::new();
        let mut sizes = Vec::new();
        while let Some(f) = dec.read_next_frame().unwrap() {
            delays.push(f.delay);
            sizes.push((f.width, f.height));
        }
        assert_eq!(delays, [10, 10, 100]);
        assert_eq!(sizes[0], (200, 200), "the first frame is whole");
        assert!(
            sizes[1].0 < 200 && sizes[1].1 < 200,
            "later frames store only what changed: {sizes:?}"
        );
        assert!(anim.gif(0, &frame).is_err());
    }
}
