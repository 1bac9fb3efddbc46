//! PNG output through tiny-skia: anti-aliased strokes, filled polygons and
//! elements, fitted into a square-ish image of `--size` pixels.

use super::{Bounds, View, parse_hex};
use crate::compile::ElementDef;
use crate::turtle::Sink;
use glam::{DVec2, DVec3};
use tiny_skia::{
    Color, FillRule, LineCap, LineJoin, Paint, PathBuilder, Pixmap, Stroke, Transform,
};

/// Segments batched into one path before it is stroked.
const BATCH: usize = 4096;
/// The outline of an organ's facet, in pixels (SVG: the same, non-scaling).
pub const FACET_SEAM: f32 = 0.6;
/// Stroke widths (in pixels) batched at once for one colour.
const WIDTHS: usize = 16;

/// The segments of one colour and one stroke width not yet stroked: opaque
/// strokes of one colour may be painted in any order, so segments of that
/// colour are grouped by width and each group is stroked as one path (a tree
/// whose widths change at every branch would otherwise set up one stroke per
/// segment).
struct Batch {
    width: f32,
    path: PathBuilder,
    len: usize,
    last: Option<(f32, f32)>,
}

/// An element ready to paint: its outline, fill, and optional stroke colour
/// with the stroke's width in pixels (the element's `width`, as SVG draws it).
/// (`fill "none"`: no fill, as in SVG).
type Painted = (tiny_skia::Path, Option<[u8; 3]>, Option<([u8; 3], f32)>);

pub struct PngWriter {
    pixmap: Pixmap,
    view: View,
    min: DVec2,
    max: DVec2,
    k: f64,
    off: DVec2,
    elements: Vec<Option<Painted>>,
    /// Open batches, all of colour `color`.
    batches: Vec<Batch>,
    color: u32,
    /// Each element's 3D organ and `fill`, if it is one.
    organs: Vec<Option<(std::sync::Arc<crate::organ::Solid>, Option<String>)>>,
    palette: super::Palette,
}

/// A colour name or `#rrggbb`.
pub fn parse_color(s: &str) -> Option<[u8; 3]> {
    if let Some(rgb) = parse_hex(s) {
        return Some(rgb);
    }
    s.parse::<svgtypes::Color>()
        .ok()
        .map(|c| [c.red, c.green, c.blue])
}

/// An element's outline as tiny-skia draws it; `None` for bad or empty data.
fn element_path(d: &str) -> Option<tiny_skia::Path> {
    use kurbo::PathEl as E;
    let f = |p: kurbo::Point| (p.x as f32, p.y as f32);
    let mut pb = PathBuilder::new();
    for el in crate::path::parse(d).ok()?.elements() {
        match *el {
            E::MoveTo(a) => pb.move_to(f(a).0, f(a).1),
            E::LineTo(a) => pb.line_to(f(a).0, f(a).1),
            E::CurveTo(a, b, c) => {
                let ((ax, ay), (bx, by), (cx, cy)) = (f(a), f(b), f(c));
                pb.cubic_to(ax, ay, bx, by, cx, cy)
            }
            E::QuadTo(a, b) => {
                let ((ax, ay), (bx, by)) = (f(a), f(b));
                pb.quad_to(ax, ay, bx, by)
            }
            E::ClosePath => pb.close(),
        }
    }
    pb.finish()
}

impl PngWriter {
    /// An image of at most `size` pixels on its longer side.
    pub fn new(
        size: u32,
        background: [u8; 4],
        view: View,
        bounds: &Bounds,
        elements: &[ElementDef],
    ) -> Option<PngWriter> {
        let (min, max) = bounds.framed(0.03);
        let ext = max - min;
        let (w, h) = if ext.x >= ext.y {
            (size, ((size as f64) * ext.y / ext.x).ceil().max(1.0) as u32)
        } else {
            (((size as f64) * ext.x / ext.y).ceil().max(1.0) as u32, size)
        };
        let mut pixmap = Pixmap::new(w.max(1), h.max(1))?;
        pixmap.fill(Color::from_rgba8(
            background[0],
            background[1],
            background[2],
            background[3],
        ));
        let k = (w as f64 / ext.x).min(h as f64 / ext.y);
        let off = DVec2::new((w as f64 - ext.x * k) / 2.0, (h as f64 - ext.y * k) / 2.0);
        let organs = elements
            .iter()
            .map(|e| e.solid.clone().map(|s| (s, e.fill.clone())))
            .collect();
        let elements = elements
            .iter()
            .map(|e| {
                // The SVG writer's defaults: fill #3f7f3a, no stroke, width 1.
                let fill = match e.fill.as_deref() {
                    None => Some([63, 127, 58]),
                    Some(f) => parse_color(f),
                };
                let width = e.width.unwrap_or(1.0) as f32;
                let stroke = e
                    .stroke
                    .as_deref()
                    .and_then(parse_color)
                    .filter(|_| width > 0.0)
                    .map(|c| (c, width));
                element_path(&e.path).map(|p| (p, fill, stroke))
            })
            .collect();
        Some(PngWriter {
            pixmap,
            view,
            min,
            max,
            k,
            off,
            elements,
            batches: Vec::new(),
            color: 0,
            organs,
            palette: super::Palette::default(),
        })
    }

    fn px(&self, p: DVec3) -> (f32, f32) {
        let q = self.view.project(p);
        (
            ((q.x - self.min.x) * self.k + self.off.x) as f32,
            ((self.max.y - q.y) * self.k + self.off.y) as f32,
        )
    }

    /// Paints `'(c)` colours from `palette` (the built-in one by default).
    pub fn with_palette(mut self, palette: super::Palette) -> Self {
        self.palette = palette;
        self
    }

    /// The stroke width in pixels of a segment `width` wide (hairlines 1.2).
    fn stroke_px(&self, width: f64) -> f32 {
        if width > 0.0 {
            (width * self.k).max(0.6) as f32
        } else {
            1.2
        }
    }

    /// Strokes every open batch.
    fn flush(&mut self) {
        for b in std::mem::take(&mut self.batches) {
            self.stroke_batch(b);
        }
    }

    fn stroke_batch(&mut self, b: Batch) {
        if b.len == 0 {
            return;
        }
        let Some(path) = b.path.finish() else { return };
        let rgb = self.palette.rgb(self.color);
        let mut paint = Paint::default();
        paint.set_color_rgba8(rgb[0], rgb[1], rgb[2], 255);
        paint.anti_alias = true;
        let stroke = Stroke {
            width: b.width,
            line_cap: LineCap::Round,
            line_join: LineJoin::Round,
            ..Stroke::default()
        };
        self.pixmap
            .stroke_path(&path, &paint, &stroke, Transform::identity(), None);
    }

    /// Paints an organ's facets: each filled, and outlined in its own colour
    /// by a thin line so that neighbouring triangles leave no seam.
    fn paint_facets(&mut self, facets: &[super::Facet]) {
        let stroke = Stroke {
            width: FACET_SEAM,
            line_join: LineJoin::Round,
            ..Stroke::default()
        };
        for f in facets {
            let mut pb = PathBuilder::new();
            for (i, &q) in f.points.iter().enumerate() {
                let x = ((q.x - self.min.x) * self.k + self.off.x) as f32;
                let y = ((self.max.y - q.y) * self.k + self.off.y) as f32;
                if i == 0 {
                    pb.move_to(x, y);
                } else {
                    pb.line_to(x, y);
                }
            }
            pb.close();
            let Some(path) = pb.finish() else { continue };
            let mut paint = Paint {
                anti_alias: true,
                ..Paint::default()
            };
            paint.set_color_rgba8(f.rgb[0], f.rgb[1], f.rgb[2], 255);
            self.pixmap.fill_path(
                &path,
                &paint,
                FillRule::Winding,
                Transform::identity(),
                None,
            );
            self.pixmap
                .stroke_path(&path, &paint, &stroke, Transform::identity(), None);
        }
    }

    /// Finishes drawing and encodes the image.
    pub fn finish(self) -> Result<Vec<u8>, String> {
        let (width, height, rgba) = self.finish_rgba();
        let mut data = Vec::new();
        let mut encoder = encoder(&mut data, width, height).map_err(|e| e.to_string())?;
        encoder
            .write_image_data(&rgba)
            .and_then(|()| encoder.finish())
            .map_err(|e| e.to_string())?;
        Ok(data)
    }

    /// The picture's width, height and RGBA pixels (not premultiplied), for
    /// an animation's frame.
    pub fn finish_rgba(mut self) -> (u32, u32, Vec<u8>) {
        self.flush();
        let (w, h) = (self.pixmap.width(), self.pixmap.height());
        (w, h, self.pixmap.take_demultiplied())
    }
}

/// A PNG encoder for 8-bit RGBA pixels (not premultiplied) whose header
/// carries lsyc's mark (`mark::PNG_SOFTWARE`); animations set their frames
/// before writing the header.
pub fn png_encoder<W: std::io::Write>(out: W, width: u32, height: u32) -> png::Encoder<'static, W> {
    let mut e = png::Encoder::new(out, width, height);
    e.set_color(png::ColorType::Rgba);
    e.set_depth(png::BitDepth::Eight);
    let (keyword, text) = super::mark::PNG_SOFTWARE;
    // A Latin-1 keyword of 1 to 79 characters: never refused.
    let _ = e.add_text_chunk(keyword.to_string(), text.to_string());
    e
}

/// `png_encoder` with its header written.
fn encoder<W: std::io::Write>(
    out: W,
    width: u32,
    height: u32,
) -> Result<png::Writer<W>, png::EncodingError> {
    png_encoder(out, width, height).write_header()
}

impl Sink for PngWriter {
    fn segment(&mut self, a: DVec3, b: DVec3, width: f64, color: u32) {
        if self.color != color {
            self.flush();
            self.color = color;
        }
        let px = self.stroke_px(width);
        let i = match self.batches.iter().position(|b| b.width == px) {
            Some(i) => i,
            None => {
                if self.batches.len() >= WIDTHS {
                    let b = self.batches.remove(0);
                    self.stroke_batch(b);
                }
                self.batches.push(Batch {
                    width: px,
                    path: PathBuilder::new(),
                    len: 0,
                    last: None,
                });
                self.batches.len() - 1
            }
        };
        if self.batches[i].len >= BATCH {
            let full = std::mem::replace(
                &mut self.batches[i],
                Batch {
                    width: px,
                    path: PathBuilder::new(),
                    len: 0,
                    last: None,
                },
            );
            self.stroke_batch(full);
        }
        let start = self.px(a);
        let end = self.px(b);
        let batch = &mut self.batches[i];
        if batch.last != Some(start) {
            batch.path.move_to(start.0, start.1);
        }
        batch.path.line_to(end.0, end.1);
        batch.last = Some(end);
        batch.len += 1;
    }

    fn polygon(&mut self, points: &[DVec3], color: u32) {
        self.flush();
        let mut pb = PathBuilder::new();
        for (i, &p) in points.iter().enumerate() {
            let (x, y) = self.px(p);
            if i == 0 {
                pb.move_to(x, y);
            } else {
                pb.line_to(x, y);
            }
        }
        pb.close();
        if let Some(path) = pb.finish() {
            let rgb = self.palette.rgb(color);
            let mut paint = Paint::default();
            paint.set_color_rgba8(rgb[0], rgb[1], rgb[2], 255);
            paint.anti_alias = true;
            self.pixmap.fill_path(
                &path,
                &paint,
                FillRule::EvenOdd,
                Transform::identity(),
                None,
            );
        }
    }

    fn element(&mut self, index: u16, at: DVec3, h: DVec3, l: DVec3, scale: f64, color: u32) {
        self.flush();
        if let Some(Some((solid, fill))) = self.organs.get(index as usize) {
            let base = super::organ_color(fill.as_deref(), color, &self.palette);
            let facets = super::organ_facets(solid, (at, h, l, scale), &self.view, base);
            self.paint_facets(&facets);
            return;
        }
        let Some(Some((path, fill, stroke))) = self.elements.get(index as usize) else {
            return;
        };
        // Local (x, y) → world at + scale (−l x + h y) → pixels (y down).
        let o = self.view.project(at);
        let ex = self.view.project_dir(-l * scale);
        let ey = self.view.project_dir(h * scale);
        let k = self.k;
        let t = Transform::from_row(
            (ex.x * k) as f32,
            (-ex.y * k) as f32,
            (ey.x * k) as f32,
            (-ey.y * k) as f32,
            ((o.x - self.min.x) * k + self.off.x) as f32,
            ((self.max.y - o.y) * k + self.off.y) as f32,
        );
        let mut paint = Paint {
            anti_alias: true,
            ..Paint::default()
        };
        let path = path.clone();
        if let Some(fill) = fill {
            paint.set_color_rgba8(fill[0], fill[1], fill[2], 255);
            self.pixmap
                .fill_path(&path, &paint, FillRule::Winding, t, None);
        }
        if let Some((s, width)) = *stroke {
            paint.set_color_rgba8(s[0], s[1], s[2], 255);
            let stroke = Stroke {
                width,
                ..Stroke::default()
            };
            // A width in pixels: stroke the transformed path.
            if let Some(p) = path.transform(t) {
                self.pixmap
                    .stroke_path(&p, &paint, &stroke, Transform::identity(), None);
            }
        }
    }
}
