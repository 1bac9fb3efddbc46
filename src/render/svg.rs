//! SVG output, streamed: consecutive segments of one style become one `<path>`,
//! elements are `<use>`s of shared `<defs>`, +y points up, and the viewBox is
//! fitted to the drawing (found by a first, drawing-free pass of the turtle).

use super::{Bounds, View};
use crate::compile::ElementDef;
use crate::number::{write_decimals, write_fixed};
use crate::turtle::Sink;
use glam::{DVec2, DVec3};
use std::io::{self, Write};

/// A `<path>` being written: its style, and a pending straight run that later
/// collinear segments extend (a Koch curve's `FF` is one `l`).
struct Open {
    width: f64,
    color: u32,
    /// Where the last segment ended, exactly.
    end: DVec2,
    /// The last point written, in fixed-point units (relative moves are taken
    /// from the rounded point, so rounding never accumulates).
    written: (i64, i64),
    /// Direction of the pending run, if any.
    run: Option<DVec2>,
}

/// Writes SVG to `out` as the turtle draws.
pub struct SvgWriter<W: Write> {
    out: W,
    view: View,
    /// Decimal places for coordinates, from the drawing's size.
    decimals: usize,
    /// 10^decimals: coordinates are written as integers in these units.
    scale: f64,
    /// The open `<path>`.
    open: Option<Open>,
    buf: Vec<u8>,
    error: Option<io::Error>,
    /// Each element's 3D organ and `fill`, if it is one.
    organs: Vec<Option<(std::sync::Arc<crate::organ::Solid>, Option<String>)>>,
    palette: super::Palette,
    /// What was drawn first: `None` before anything, else the start, width
    /// and colour of a first segment (`Some(None)`: something else).
    first: Option<Option<(DVec2, f64, u32)>>,
}

impl<W: Write> SvgWriter<W> {
    /// Starts the document; `bounds` are the projected bounds of the drawing.
    pub fn new(
        mut out: W,
        view: View,
        bounds: &Bounds,
        elements: &[ElementDef],
        used: &[bool],
    ) -> io::Result<SvgWriter<W>> {
        let (min, max) = bounds.framed(0.02);
        let size = max - min;
        let extent = size.x.max(size.y);
        let decimals = (4.0 - extent.log10().floor()).clamp(0.0, 9.0) as usize;
        let hairline = extent / 700.0;
        let (w, h) = if size.x >= size.y {
            (800.0, 800.0 * size.y / size.x)
        } else {
            (800.0 * size.x / size.y, 800.0)
        };
        let num = |v: f64| {
            let mut b = Vec::new();
            write_decimals(&mut b, v, decimals);
            String::from_utf8(b).unwrap_or_default()
        };
        let mut head = String::new();
        head.push_str(super::mark::SVG_HEAD);
        head.push_str(&format!(
            "{} {} {} {}\" width=\"{:.0}\" height=\"{:.0}\">\n",
            num(min.x),
            num(-max.y),
            num(size.x),
            num(size.y),
            w.max(1.0),
            h.max(1.0)
        ));
        head.push_str(&format!(
            "<g fill=\"none\" stroke-linecap=\"round\" stroke-linejoin=\"round\" stroke-width=\"{}\">\n",
            num(hairline)
        ));
        if used.iter().any(|u| *u) {
            head.push_str("<defs>\n");
            for (i, e) in elements.iter().enumerate() {
                // Organs are written in place; contours draw nothing.
                if !used.get(i).copied().unwrap_or(false)
                    || e.solid.is_some()
                    || e.mesh.is_some()
                    || e.is_contour()
                {
                    continue;
                }
                let fill = e.fill.as_deref().unwrap_or("#3f7f3a");
                let stroke = e.stroke.as_deref().unwrap_or("none");
                head.push_str(&format!(
                    "<path id=\"e{i}\" class=\"element\" data-element=\"{}\" d=\"{}\" fill=\"{}\" stroke=\"{}\"{}/>\n",
                    xml(&e.name),
                    xml(&e.path),
                    xml(fill),
                    xml(stroke),
                    e.width.map_or(String::new(), |w| format!(" stroke-width=\"{w}\" vector-effect=\"non-scaling-stroke\""))
                ));
            }
            head.push_str("</defs>\n");
        }
        out.write_all(head.as_bytes())?;
        Ok(SvgWriter {
            out,
            view,
            decimals,
            scale: 10f64.powi(decimals as i32),
            open: None,
            buf: Vec::with_capacity(64),
            error: None,
            organs: elements
                .iter()
                .map(|e| e.solid.clone().map(|s| (s, e.fill.clone())))
                .collect(),
            palette: super::Palette::default(),
            first: None,
        })
    }

    /// A writer for a part of the drawing drawn on its own (on another
    /// thread): the same view, numbers, elements and palette, no path open,
    /// writing to memory. Its output goes into this writer with `append`.
    pub fn part(&self) -> SvgWriter<Vec<u8>> {
        SvgWriter {
            out: Vec::new(),
            view: self.view,
            decimals: self.decimals,
            scale: self.scale,
            open: None,
            buf: Vec::with_capacity(64),
            error: None,
            organs: self.organs.clone(),
            palette: self.palette.clone(),
            first: None,
        }
    }

    /// Whether `other`, made for the same view, writes numbers as this
    /// writer does (the same decimals): its parts can be appended here.
    pub fn same_numbers<V: Write>(&self, other: &SvgWriter<V>) -> bool {
        self.decimals == other.decimals
    }

    /// Writes `part` (from `part`) as if what it drew had been drawn into
    /// this writer; `false`, and nothing written, when its first segment
    /// would have gone on with this writer's open path (draw that part into
    /// this writer instead).
    pub fn append(&mut self, part: SvgWriter<Vec<u8>>) -> bool {
        let Some(first) = part.first else {
            return true;
        };
        if let (Some(open), Some((pa, width, color))) = (&self.open, first)
            && open.width == width
            && open.color == color
            && open.end == pa
        {
            return false;
        }
        // Whatever `part` drew first closed the path open here.
        self.close_path();
        self.write(&part.out);
        self.open = part.open;
        self.first.get_or_insert(first);
        true
    }

    /// Paints `'(c)` colours from `palette` (the built-in one by default).
    pub fn with_palette(mut self, palette: super::Palette) -> Self {
        self.palette = palette;
        self
    }

    fn write(&mut self, bytes: &[u8]) {
        if self.error.is_none()
            && let Err(e) = self.out.write_all(bytes)
        {
            self.error = Some(e);
        }
    }

    fn fixed(&self, p: DVec2) -> (i64, i64) {
        (
            (p.x * self.scale).round() as i64,
            (-p.y * self.scale).round() as i64,
        )
    }

    /// Writes the pending run of the open path.
    fn flush_run(&mut self) {
        let Some(open) = self.open.as_mut() else {
            return;
        };
        if open.run.take().is_none() {
            return;
        }
        let end = open.end;
        let (x, y) = (
            (end.x * self.scale).round() as i64,
            (-end.y * self.scale).round() as i64,
        );
        let (dx, dy) = (x - open.written.0, y - open.written.1);
        open.written = (x, y);
        let mut buf = std::mem::take(&mut self.buf);
        buf.clear();
        buf.push(b' ');
        write_fixed(&mut buf, dx, self.decimals);
        buf.push(b' ');
        write_fixed(&mut buf, dy, self.decimals);
        self.write(&buf);
        self.buf = buf;
    }

    fn close_path(&mut self) {
        self.flush_run();
        if self.open.take().is_some() {
            self.write(b"\"/>\n");
        }
    }

    /// Appends `x,y x,y …` (projected, y flipped) for a `points` attribute.
    fn write_points(&self, buf: &mut Vec<u8>, points: &[DVec3]) {
        for (i, &p) in points.iter().enumerate() {
            if i > 0 {
                buf.push(b' ');
            }
            let q = self.view.project(p);
            write_decimals(buf, q.x, self.decimals);
            buf.push(b',');
            write_decimals(buf, -q.y, self.decimals);
        }
    }

    /// Writes an organ's facets (painter's order) as one group of filled
    /// triangles, each outlined in its own colour as the PNG writer does.
    fn organ(&mut self, index: u16, facets: &[super::Facet]) {
        let mut buf = format!("<g class=\"organ\" data-element-index=\"{index}\" stroke-width=\"{}\" vector-effect=\"non-scaling-stroke\">\n", super::png::FACET_SEAM).into_bytes();
        for f in facets {
            let c = super::hex(f.rgb);
            buf.extend_from_slice(
                format!(
                    "<path fill=\"{c}\" stroke=\"{c}\" vector-effect=\"non-scaling-stroke\" d=\"M"
                )
                .as_bytes(),
            );
            for (i, q) in f.points.iter().enumerate() {
                if i > 0 {
                    buf.push(b'L');
                }
                write_decimals(&mut buf, q.x, self.decimals);
                buf.push(b' ');
                write_decimals(&mut buf, -q.y, self.decimals);
            }
            buf.extend_from_slice(b"Z\"/>\n");
        }
        buf.extend_from_slice(b"</g>\n");
        self.write(&buf);
    }

    /// Starts the layer of one guide's drawing.
    pub fn begin_guide(&mut self, name: &str) {
        self.close_path();
        let line = format!("<g class=\"guide-content\" data-guide=\"{}\">\n", xml(name));
        self.write(line.as_bytes());
    }

    /// Ends the layer started by `begin_guide`.
    pub fn end_guide(&mut self) {
        self.close_path();
        self.write(b"</g>\n");
    }

    /// Draws a guide's outline.
    pub fn guide_outline(&mut self, name: &str, points: &[DVec3]) {
        self.close_path();
        let mut buf = format!(
            "<polygon class=\"guide\" data-guide=\"{}\" fill=\"none\" stroke=\"#1565c0\" stroke-dasharray=\"4 3\" vector-effect=\"non-scaling-stroke\" points=\"",
            xml(name)
        )
        .into_bytes();
        self.write_points(&mut buf, points);
        buf.extend_from_slice(b"\"/>\n");
        self.write(&buf);
    }

    /// Draws a link from the middle of one edge to the middle of another.
    pub fn link_line(&mut self, from: &str, to: &str, a: DVec3, b: DVec3) {
        self.close_path();
        let (pa, pb) = (self.view.project(a), self.view.project(b));
        let mut buf = format!(
            "<line class=\"link\" data-from=\"{}\" data-to=\"{}\" stroke=\"#c62828\" vector-effect=\"non-scaling-stroke\" x1=\"",
            xml(from),
            xml(to)
        )
        .into_bytes();
        write_decimals(&mut buf, pa.x, self.decimals);
        buf.extend_from_slice(b"\" y1=\"");
        write_decimals(&mut buf, -pa.y, self.decimals);
        buf.extend_from_slice(b"\" x2=\"");
        write_decimals(&mut buf, pb.x, self.decimals);
        buf.extend_from_slice(b"\" y2=\"");
        write_decimals(&mut buf, -pb.y, self.decimals);
        buf.extend_from_slice(b"\"/>\n");
        self.write(&buf);
    }

    /// The decimal places of the coordinates (from the drawing's size).
    pub fn decimals(&self) -> usize {
        self.decimals
    }

    /// The output written so far. Between layers (after `SvgWriter::new`,
    /// `end_guide` or a guide outline) no path is open: everything drawn is
    /// in it, and what is taken out is a whole part of the document.
    pub fn get_mut(&mut self) -> &mut W {
        &mut self.out
    }

    /// Ends the document and returns the writer.
    pub fn finish(mut self) -> io::Result<W> {
        self.close_path();
        self.write(b"</g>\n</svg>\n");
        if let Some(e) = self.error.take() {
            return Err(e);
        }
        self.out.flush()?;
        Ok(self.out)
    }
}

impl<W: Write> Sink for SvgWriter<W> {
    fn segment(&mut self, a: DVec3, b: DVec3, width: f64, color: u32) {
        let pa = self.view.project(a);
        let pb = self.view.project(b);
        let d = pb - pa;
        self.first.get_or_insert(Some((pa, width, color)));
        if let Some(open) = self.open.as_mut()
            && open.width == width
            && open.color == color
            && open.end == pa
        {
            // Extend a collinear run; otherwise write it and start another.
            if let Some(dir) = open.run {
                let len = d.length();
                if len > 0.0 && dir.perp_dot(d / len).abs() < 1e-9 && dir.dot(d) > 0.0 {
                    open.end = pb;
                    return;
                }
            }
            self.flush_run();
            if let Some(open) = self.open.as_mut() {
                open.run = Some(d.normalize_or_zero());
                open.end = pb;
            }
            return;
        }
        self.close_path();
        let start = self.fixed(pa);
        let mut buf = std::mem::take(&mut self.buf);
        buf.clear();
        buf.extend_from_slice(b"<path stroke=\"");
        buf.extend_from_slice(self.palette.hex(color).as_bytes());
        buf.push(b'"');
        if width > 0.0 {
            buf.extend_from_slice(b" stroke-width=\"");
            write_decimals(&mut buf, width, self.decimals + 1);
            buf.push(b'"');
        }
        buf.extend_from_slice(b" d=\"M");
        write_fixed(&mut buf, start.0, self.decimals);
        buf.push(b' ');
        write_fixed(&mut buf, start.1, self.decimals);
        buf.push(b'l');
        self.write(&buf);
        self.buf = buf;
        self.open = Some(Open {
            width,
            color,
            end: pb,
            written: start,
            run: Some(d.normalize_or_zero()),
        });
    }

    fn polygon(&mut self, points: &[DVec3], color: u32) {
        self.first.get_or_insert(None);
        self.close_path();
        let mut buf = Vec::new();
        buf.extend_from_slice(b"<polygon fill=\"");
        buf.extend_from_slice(self.palette.hex(color).as_bytes());
        buf.extend_from_slice(b"\" stroke=\"none\" points=\"");
        self.write_points(&mut buf, points);
        buf.extend_from_slice(b"\"/>\n");
        self.write(&buf);
    }

    fn element(&mut self, index: u16, at: DVec3, h: DVec3, l: DVec3, scale: f64, color: u32) {
        self.first.get_or_insert(None);
        self.close_path();
        if let Some(Some((solid, fill))) = self.organs.get(index as usize) {
            let base = super::organ_color(fill.as_deref(), color, &self.palette);
            let facets = super::organ_facets(solid, (at, h, l, scale), &self.view, base);
            self.organ(index, &facets);
            return;
        }
        // Local (x, y) → world at + scale (−l x + h y), then flip y for SVG.
        let o = self.view.project(at);
        let ex = self.view.project_dir(-l * scale);
        let ey = self.view.project_dir(h * scale);
        let d = self.decimals + 3;
        let mut buf = Vec::new();
        buf.extend_from_slice(
            format!("<use href=\"#e{index}\" xlink:href=\"#e{index}\" transform=\"matrix(")
                .as_bytes(),
        );
        for (k, v) in [ex.x, -ex.y, ey.x, -ey.y, o.x, -o.y]
            .into_iter()
            .enumerate()
        {
            if k > 0 {
                buf.push(b' ');
            }
            write_decimals(&mut buf, v, if k < 4 { d } else { self.decimals });
        }
        buf.extend_from_slice(b")\"/>\n");
        self.write(&buf);
    }
}

/// Escapes text for an XML attribute.
pub fn xml(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('"', "&quot;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One "system": segments (from, to, colour) and maybe a polygon first.
    type Drawing = (bool, Vec<((f64, f64), (f64, f64), u32)>);

    fn draw(w: &mut impl Sink, d: &Drawing) {
        let p = |(x, y): (f64, f64)| DVec3::new(x, y, 0.0);
        if d.0 {
            w.polygon(&[p((0.0, 0.0)), p((1.0, 0.0)), p((0.0, 1.0))], 2);
        }
        for &(a, b, c) in &d.1 {
            w.segment(p(a), p(b), 0.0, c);
        }
    }

    /// Systems written in parts (on their own, then appended, or drawn
    /// again where a part goes on with the open path) make the bytes that
    /// one writer drawing them in order makes.
    #[test]
    fn parts_appended_are_the_bytes_of_one_writer() {
        let systems: Vec<Drawing> = vec![
            // A collinear run, left open.
            (
                false,
                vec![((0.0, 0.0), (1.0, 0.0), 1), ((1.0, 0.0), (2.0, 0.0), 1)],
            ),
            // Goes on from there, straight on: continues the open path.
            (
                false,
                vec![((2.0, 0.0), (3.0, 0.0), 1), ((3.0, 0.0), (3.0, 1.0), 1)],
            ),
            // Draws nothing.
            (false, vec![]),
            // Goes on from there in another colour: a new path.
            (false, vec![((3.0, 1.0), (4.0, 1.0), 3)]),
            // Starts elsewhere.
            (false, vec![((9.0, 9.0), (8.0, 9.0), 3)]),
            // A polygon first, then a segment where the path before ended.
            (true, vec![((8.0, 9.0), (7.0, 9.0), 3)]),
            // Goes on from there, turning.
            (false, vec![((7.0, 9.0), (7.0, 8.0), 3)]),
        ];
        let mut bounds = Bounds::default();
        bounds.add(DVec2::new(-1.0, -1.0));
        bounds.add(DVec2::new(10.0, 10.0));
        let view = View::new(false);
        let one = |out: Vec<u8>| SvgWriter::new(out, view, &bounds, &[], &[]).expect("writes");
        let mut whole = one(Vec::new());
        for s in &systems {
            draw(&mut whole, s);
        }
        let whole = whole.finish().expect("writes");
        let mut parts = one(Vec::new());
        let mut again = 0;
        for s in &systems {
            let mut part = parts.part();
            draw(&mut part, s);
            if !parts.append(part) {
                again += 1;
                draw(&mut parts, s);
            }
        }
        let parts = parts.finish().expect("writes");
        assert_eq!(
            String::from_utf8(parts).expect("utf-8"),
            String::from_utf8(whole).expect("utf-8")
        );
        // The parts that went on with an open path were drawn again.
        assert_eq!(again, 2);
    }
}
