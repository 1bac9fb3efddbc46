//! Wavefront OBJ output: a streaming `turtle::Sink` that writes segments as
//! closed tubes, polygons `{ . }` as faces and elements as flat outlines.
//!
//! Owns: the 3D mesh form of a drawing. Segments become generalized cylinders
//! (the sources' "generalized cylinders with spherical joints"): a chain of
//! segments, each starting exactly where the previous one ended, is one
//! watertight tube whose rings are carried along by parallel transport (no
//! twist) and mitred in the bisecting plane at every joint; each tube is closed
//! by a cap at both ends, and a low-poly sphere fills the joint where a new tube
//! starts at a point another tube already reached (branches, sharp turns,
//! continuations after `]`). Polygons and elements are single n-gon faces with
//! one normal. Output is streamed: only the open chains (at most
//! `MAX_OPEN_CHAINS`) and a bounded memory of joint positions are kept.
//! Colours `'(c)` become `usemtl lsyc_color<c>` switches (no `.mtl` is written).
//! Must not know the turtle's rules or any other output format.
//!
//! Parts: this file (options, the writer's buffer and faces), `tube` (tubes,
//! caps, mitres and spherical joints), `outline` (element outlines, read through
//! `crate::path`); numbers are printed by `crate::number`.

mod outline;
#[cfg(test)]
mod tests;
mod tube;

pub use outline::{ElementOutline, outline_from_path};

use crate::compile::Program;
use crate::number::{write_significant, write_uint};
use crate::turtle::Sink;
use glam::DVec3;
use std::collections::{HashMap, VecDeque};
use std::io::{self, Write};
use tube::{Chain, Joint};

/// Chains whose end may still be continued (after a `]`); older ones are closed.
pub const MAX_OPEN_CHAINS: usize = 64;
/// Joint positions remembered to place spheres where branches start.
pub const MAX_JOINTS: usize = 1 << 16;
/// Turns sharper than this (cosine of 100°) are not mitred: the chain is closed
/// and the next tube starts with a spherical joint.
const MITRE_MIN_COS: f64 = -0.173_648_177_666_930_3;
/// A mitre may reach back at most this fraction of either segment's length.
const MITRE_MAX_REACH: f64 = 0.45;
/// The most vertices per ring.
pub const MAX_SIDES: usize = 256;
/// Relative resolution of written coordinates (7 significant digits), with
/// a margin: shorter segments and thinner tubes would collapse.
const RESOLUTION: f64 = 1e-5;
/// Output is assembled in a buffer of this size before it is written.
const BUFFER: usize = 1 << 16;

/// How the mesh is built.
#[derive(Clone, Debug)]
pub struct ObjOptions {
    /// Vertices per tube ring (clamped to 3..=`MAX_SIDES`).
    pub sides: usize,
    /// Tube radius for hairlines (width 0).
    pub default_radius: f64,
    /// The outline of every element, by element index.
    pub elements: Vec<ElementOutline>,
}

impl Default for ObjOptions {
    fn default() -> ObjOptions {
        ObjOptions {
            sides: 8,
            default_radius: 0.05,
            elements: Vec::new(),
        }
    }
}

impl ObjOptions {
    /// Options for a program: its elements' outlines (an element whose path has
    /// no area gets an empty outline and is not drawn) and hairlines a twentieth
    /// of the step thick.
    pub fn for_program(prog: &Program) -> ObjOptions {
        let step = prog.step.abs();
        ObjOptions {
            default_radius: if step.is_finite() && step > 0.0 {
                step * 0.025
            } else {
                0.05
            },
            elements: prog
                .elements
                .iter()
                .map(|e| outline_from_path(&e.path).unwrap_or_default())
                .collect(),
            ..ObjOptions::default()
        }
    }
}

/// What was written, for the closing comment.
#[derive(Clone, Copy, Debug, Default)]
struct Counts {
    tubes: u64,
    spheres: u64,
    polygons: u64,
    elements: u64,
    faces: u64,
}

/// A streaming OBJ writer. Call [`ObjWriter::finish`] to close the open tubes
/// and flush; dropping it without `finish` leaves the output incomplete.
pub struct ObjWriter<W: Write> {
    out: W,
    /// Text not yet written to `out`.
    buf: Vec<u8>,
    /// The first write error; nothing is written after it.
    error: Option<io::Error>,
    sides: usize,
    /// cos, sin of the ring angles.
    ring_angles: Vec<(f64, f64)>,
    default_radius: f64,
    /// Element outlines, cleaned and counter-clockwise.
    elements: Vec<Vec<glam::DVec2>>,
    /// Open chains, the most recently extended last.
    open: Vec<Chain>,
    joints: HashMap<[u64; 3], Joint>,
    joint_order: VecDeque<[u64; 3]>,
    /// Vertices and normals written so far (the last index).
    v: u64,
    vn: u64,
    material: u32,
    counts: Counts,
}

impl<W: Write> ObjWriter<W> {
    pub fn new(out: W, options: ObjOptions) -> Self {
        let sides = options.sides.clamp(3, MAX_SIDES);
        let ring_angles = (0..sides)
            .map(|i| {
                let t = std::f64::consts::TAU * i as f64 / sides as f64;
                (t.cos(), t.sin())
            })
            .collect();
        let default_radius = if options.default_radius.is_finite() && options.default_radius > 0.0 {
            options.default_radius
        } else {
            ObjOptions::default().default_radius
        };
        let elements = options
            .elements
            .into_iter()
            .map(ElementOutline::oriented)
            .collect();
        let mut w = ObjWriter {
            out,
            buf: Vec::with_capacity(BUFFER + 256),
            error: None,
            sides,
            ring_angles,
            default_radius,
            elements,
            open: Vec::new(),
            joints: HashMap::new(),
            joint_order: VecDeque::new(),
            v: 0,
            vn: 0,
            material: 0,
            counts: Counts::default(),
        };
        w.text(&format!(
            "# lsyc OBJ: segments as closed tubes ({sides} sides), polygons and elements as faces\n"
        ));
        w
    }

    /// Closes the open tubes, writes a closing comment with counts and flushes.
    /// Reports the first IO error of any earlier write.
    pub fn finish(mut self) -> io::Result<W> {
        for chain in std::mem::take(&mut self.open) {
            self.close(chain);
        }
        let (c, v) = (self.counts, self.v);
        self.text(&format!(
            "# {} tubes, {} spheres, {} polygons, {} elements; {v} vertices, {} faces\n",
            c.tubes, c.spheres, c.polygons, c.elements, c.faces
        ));
        self.drain();
        if let Some(e) = self.error.take() {
            return Err(e);
        }
        self.out.flush()?;
        Ok(self.out)
    }

    /// Writes the buffer out (or drops it after an error).
    fn drain(&mut self) {
        if self.error.is_none()
            && let Err(e) = self.out.write_all(&self.buf)
        {
            self.error = Some(e);
        }
        self.buf.clear();
    }

    /// Ends a line; writes the buffer out when it is full.
    fn end_line(&mut self) {
        self.buf.push(b'\n');
        if self.buf.len() >= BUFFER {
            self.drain();
        }
    }

    fn text(&mut self, t: &str) {
        self.buf.extend_from_slice(t.as_bytes());
        if self.buf.len() >= BUFFER {
            self.drain();
        }
    }

    fn triple(&mut self, tag: &[u8], p: DVec3) {
        self.buf.extend_from_slice(tag);
        for x in [p.x, p.y, p.z] {
            self.buf.push(b' ');
            write_significant(&mut self.buf, x);
        }
        self.end_line();
    }

    fn vertex(&mut self, p: DVec3) -> u64 {
        self.triple(b"v", p);
        self.v += 1;
        self.v
    }

    fn normal(&mut self, n: DVec3) -> u64 {
        self.triple(b"vn", n);
        self.vn += 1;
        self.vn
    }

    /// A corner ` v//vn` of a face line.
    fn corner(&mut self, (v, n): (u64, u64)) {
        self.buf.push(b' ');
        write_uint(&mut self.buf, v);
        self.buf.extend_from_slice(b"//");
        write_uint(&mut self.buf, n);
    }

    /// A triangle of (vertex, normal) pairs, counter-clockwise seen from outside.
    fn tri(&mut self, a: (u64, u64), b: (u64, u64), c: (u64, u64)) {
        self.buf.push(b'f');
        self.corner(a);
        self.corner(b);
        self.corner(c);
        self.end_line();
        self.counts.faces += 1;
    }

    fn material(&mut self, color: u32) {
        if color != self.material {
            self.material = color;
            self.text(&format!("usemtl lsyc_color{color}\n"));
        }
    }
}

impl<W: Write> Sink for ObjWriter<W> {
    fn segment(&mut self, a: DVec3, b: DVec3, width: f64, color: u32) {
        if !(a.is_finite() && b.is_finite()) {
            return;
        }
        // Lengths and radii below what the written digits resolve would give
        // faces of zero area: such segments only move their chain's end, and
        // radii are at least that resolution.
        let resolution = RESOLUTION * a.abs().max(b.abs()).max_element().max(1e-9);
        let len = (b - a).length();
        if len <= resolution {
            if let Some(c) = self.open.iter_mut().rev().find(|c| c.end == a) {
                c.end = b;
                let r = c.radius;
                self.remember(b, r);
            }
            return;
        }
        let dir = (b - a) / len;
        if !(len.is_finite() && dir.is_finite() && dir.is_normalized()) {
            return;
        }
        let r = self.radius(width).max(resolution);
        if let Some(i) = self.open.iter().rposition(|c| c.end == a) {
            let chain = self.open.remove(i);
            if Self::can_mitre(&chain, dir, len, r) {
                let next = self.mitre(chain, b, dir, len, r, color);
                self.open.push(next);
                self.remember(b, r);
                return;
            }
            self.close(chain);
        }
        self.start(a, b, dir, len, r, color);
        self.remember(b, r);
    }

    fn polygon(&mut self, points: &[DVec3], color: u32) {
        let mut pts: Vec<DVec3> = Vec::with_capacity(points.len());
        for &p in points {
            if !p.is_finite() {
                return;
            }
            if pts.last() != Some(&p) {
                pts.push(p);
            }
        }
        while pts.len() > 1 && pts.first() == pts.last() {
            pts.pop();
        }
        if pts.len() >= 3 && self.face(&pts, None, color) {
            self.counts.polygons += 1;
        }
    }

    fn element(&mut self, index: u16, at: DVec3, h: DVec3, l: DVec3, scale: f64, color: u32) {
        let Some(outline) = self.elements.get(index as usize) else {
            return;
        };
        if outline.len() < 3 || !(at.is_finite() && scale.is_finite()) || scale == 0.0 {
            return;
        }
        let Some(normal) = h.cross(l).try_normalize() else {
            return;
        };
        let pts: Vec<DVec3> = outline
            .iter()
            .map(|p| at + (-l * p.x + h * p.y) * scale)
            .collect();
        if pts.iter().all(|p| p.is_finite()) && self.face(&pts, Some(normal), color) {
            self.counts.elements += 1;
        }
    }
}

impl<W: Write> ObjWriter<W> {
    /// One n-gon face with a single normal (by default the polygon's own, by
    /// Newell's method). Nothing is written for a face whose area the written
    /// digits would not resolve.
    fn face(&mut self, pts: &[DVec3], normal: Option<DVec3>, color: u32) -> bool {
        let mut area = DVec3::ZERO;
        let mut extent: f64 = 1e-9;
        for (i, &p) in pts.iter().enumerate() {
            let q = pts[(i + 1) % pts.len()];
            area += p.cross(q);
            extent = extent.max(p.abs().max_element());
        }
        let resolution = RESOLUTION * extent;
        let Some(own) = area.try_normalize() else {
            return false;
        };
        if 0.5 * area.length() <= resolution * resolution {
            return false;
        }
        let normal = normal.unwrap_or(own);
        self.material(color);
        let first = self.v + 1;
        for &p in pts {
            self.vertex(p);
        }
        let n = self.normal(normal);
        self.buf.push(b'f');
        for k in 0..pts.len() as u64 {
            self.corner((first + k, n));
        }
        self.end_line();
        self.counts.faces += 1;
        true
    }
}
