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

use crate::compile::Program;
use crate::turtle::Sink;
use glam::{DQuat, DVec3};
use std::collections::{HashMap, VecDeque};
use std::io::{self, Write};

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
/// Line pieces per curve when flattening element paths.
const CURVE_STEPS: usize = 8;
/// Relative resolution of written coordinates (7 significant digits), with
/// a margin: shorter segments and thinner tubes would collapse.
const RESOLUTION: f64 = 1e-5;
/// Output is assembled in a buffer of this size before it is written.
const BUFFER: usize = 1 << 16;

/// A flattened closed outline in an element's local frame (x right, y forward).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ElementOutline {
    pub points: Vec<[f64; 2]>,
}

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

/// Flattens SVG path data into the outline of its largest closed subpath (by
/// area); curves become `CURVE_STEPS` pieces each, arcs are converted to curves.
/// Parsing stops at the first error, as SVG renderers do. `None` when no subpath
/// encloses any area (an open stroke, empty or unparsable data).
pub fn outline_from_path(d: &str) -> Option<ElementOutline> {
    use svgtypes::SimplePathSegment as S;
    let mut best: Option<(f64, Vec<[f64; 2]>)> = None;
    let mut cur: Vec<[f64; 2]> = Vec::new();
    let mut last = [0.0, 0.0];
    let mut flush = |cur: &mut Vec<[f64; 2]>| {
        let pts = clean_outline(std::mem::take(cur));
        let area = signed_area(&pts).abs();
        if pts.len() >= 3 && area > 0.0 && best.as_ref().is_none_or(|b| area > b.0) {
            best = Some((area, pts));
        }
    };
    for seg in svgtypes::SimplifyingPathParser::from(d) {
        let Ok(seg) = seg else { break };
        match seg {
            S::MoveTo { x, y } => {
                flush(&mut cur);
                last = [x, y];
                cur.push(last);
            }
            S::LineTo { x, y } => {
                last = [x, y];
                cur.push(last);
            }
            S::CurveTo {
                x1,
                y1,
                x2,
                y2,
                x,
                y,
            } => {
                let p0 = last;
                for k in 1..=CURVE_STEPS {
                    let t = k as f64 / CURVE_STEPS as f64;
                    let u = 1.0 - t;
                    let (a, b, c, e) = (u * u * u, 3.0 * u * u * t, 3.0 * u * t * t, t * t * t);
                    cur.push([
                        a * p0[0] + b * x1 + c * x2 + e * x,
                        a * p0[1] + b * y1 + c * y2 + e * y,
                    ]);
                }
                last = [x, y];
            }
            S::Quadratic { x1, y1, x, y } => {
                let p0 = last;
                for k in 1..=CURVE_STEPS {
                    let t = k as f64 / CURVE_STEPS as f64;
                    let u = 1.0 - t;
                    let (a, b, c) = (u * u, 2.0 * u * t, t * t);
                    cur.push([a * p0[0] + b * x1 + c * x, a * p0[1] + b * y1 + c * y]);
                }
                last = [x, y];
            }
            S::ClosePath => {
                flush(&mut cur);
                // The parser reports the implicit MoveTo of a following segment.
            }
        }
    }
    flush(&mut cur);
    best.map(|(_, points)| ElementOutline { points })
}

/// Drops non-finite points, repeated consecutive points and a closing repeat.
fn clean_outline(points: Vec<[f64; 2]>) -> Vec<[f64; 2]> {
    let mut out: Vec<[f64; 2]> = Vec::with_capacity(points.len());
    for p in points {
        if p[0].is_finite() && p[1].is_finite() && out.last() != Some(&p) {
            out.push(p);
        }
    }
    while out.len() > 1 && out.first() == out.last() {
        out.pop();
    }
    out
}

/// The signed area (positive when counter-clockwise, x right, y up).
fn signed_area(points: &[[f64; 2]]) -> f64 {
    let n = points.len();
    let mut s = 0.0;
    for i in 0..n {
        let (p, q) = (points[i], points[(i + 1) % n]);
        s += p[0] * q[1] - q[0] * p[1];
    }
    0.5 * s
}

/// First vertex and first normal index (1-based) of a ring of `sides` vertices.
#[derive(Clone, Copy, Debug)]
struct Ring {
    v: u64,
    n: u64,
}

/// A tube whose last segment's end ring is not written yet: the next segment
/// decides whether it becomes a mitred joint or an end with a cap.
#[derive(Clone, Copy, Debug)]
struct Chain {
    /// End of the last segment.
    end: DVec3,
    /// Unit direction and length of the last segment.
    dir: DVec3,
    len: f64,
    /// Unit vector perpendicular to `dir`: where ring vertex 0 lies.
    n: DVec3,
    radius: f64,
    color: u32,
    /// The ring at the start of the last segment.
    ring: Ring,
}

/// A remembered point that a tube reached.
#[derive(Clone, Copy, Debug)]
struct Joint {
    /// The thickest tube radius seen here.
    radius: f64,
    /// The largest sphere already written here (0 when none).
    sphere: f64,
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
    elements: Vec<Vec<[f64; 2]>>,
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
            .map(|e| {
                let mut pts = clean_outline(e.points);
                let area = signed_area(&pts);
                if area < 0.0 {
                    pts.reverse();
                }
                if pts.len() < 3 || area == 0.0 {
                    pts.clear();
                }
                pts
            })
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
            push_number(&mut self.buf, x);
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
        push_int(&mut self.buf, v);
        put(&mut self.buf, b"//");
        push_int(&mut self.buf, n);
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

    fn radius(&self, width: f64) -> f64 {
        let r = width * 0.5;
        if r.is_finite() && r > 0.0 {
            r
        } else {
            self.default_radius
        }
    }

    /// Writes a ring: vertex i at `point(i)`, normal i `normal(i)`.
    fn ring(
        &mut self,
        point: impl Fn(DVec3) -> DVec3,
        normal: impl Fn(DVec3) -> DVec3,
        n: DVec3,
        dir: DVec3,
    ) -> Ring {
        let b = dir.cross(n);
        let first_v = self.v + 1;
        let first_n = self.vn + 1;
        for i in 0..self.sides {
            let (c, s) = self.ring_angles[i];
            self.vertex(point(n * c + b * s));
        }
        for i in 0..self.sides {
            let (c, s) = self.ring_angles[i];
            let radial = n * c + b * s;
            self.normal(normal(radial).try_normalize().unwrap_or(radial));
        }
        Ring {
            v: first_v,
            n: first_n,
        }
    }

    /// The side of a tube between two rings (`a` behind `b`): one quad per side
    /// (planar unless the radius changes).
    fn side(&mut self, a: Ring, b: Ring) {
        let k = self.sides as u64;
        for i in 0..k {
            let j = (i + 1) % k;
            self.buf.push(b'f');
            self.corner((a.v + i, a.n + i));
            self.corner((a.v + j, a.n + j));
            self.corner((b.v + j, b.n + j));
            self.corner((b.v + i, b.n + i));
            self.end_line();
            self.counts.faces += 1;
        }
    }

    /// A fan from a centre vertex; `outward` is the cap's normal, `reverse` for
    /// the start cap (whose normal points against the ring's direction).
    fn cap(&mut self, ring: Ring, centre: DVec3, outward: DVec3, reverse: bool) {
        let c = self.vertex(centre);
        let cn = self.normal(outward);
        let k = self.sides as u64;
        for i in 0..k {
            let j = (i + 1) % k;
            let (p, q) = ((ring.v + i, cn), (ring.v + j, cn));
            if reverse {
                self.tri((c, cn), q, p);
            } else {
                self.tri((c, cn), p, q);
            }
        }
    }

    /// A UV sphere (`sides` around, at least 2 bands), closed on its own.
    fn sphere(&mut self, centre: DVec3, r: f64) {
        let lon = self.sides as u64;
        let lat = (self.sides / 2).max(2);
        let north = centre + DVec3::Z * r;
        let np = (self.vertex(north), self.normal(DVec3::Z));
        let first = (self.v + 1, self.vn + 1);
        for j in 1..lat {
            let phi = std::f64::consts::PI * j as f64 / lat as f64;
            let (sp, cp) = phi.sin_cos();
            for i in 0..self.sides {
                let (c, s) = self.ring_angles[i];
                let d = DVec3::new(sp * c, sp * s, cp);
                self.vertex(centre + d * r);
                self.normal(d);
            }
        }
        let sp = (
            self.vertex(centre - DVec3::Z * r),
            self.normal(DVec3::NEG_Z),
        );
        // Vertices and normals are counted separately: both index the same way.
        let at = |j: u64, i: u64| {
            let k = (j - 1) * lon + i % lon;
            (first.0 + k, first.1 + k)
        };
        let bands = lat as u64;
        for i in 0..lon {
            self.tri(np, at(1, i), at(1, i + 1));
        }
        for j in 1..bands - 1 {
            for i in 0..lon {
                self.tri(at(j, i), at(j + 1, i), at(j + 1, i + 1));
                self.tri(at(j, i), at(j + 1, i + 1), at(j, i + 1));
            }
        }
        for i in 0..lon {
            self.tri(sp, at(bands - 1, i + 1), at(bands - 1, i));
        }
        self.counts.spheres += 1;
    }

    /// Writes the end ring and cap of a chain.
    fn close(&mut self, chain: Chain) {
        self.material(chain.color);
        let (end, r) = (chain.end, chain.radius);
        let ring = self.ring(|v| end + v * r, |v| v, chain.n, chain.dir);
        self.side(chain.ring, ring);
        self.cap(ring, end, chain.dir, false);
        self.counts.tubes += 1;
    }

    /// Whether the joint between `chain` and a segment along `dir` of length
    /// `len` and radius `r` can be mitred without the tube folding.
    fn can_mitre(chain: &Chain, dir: DVec3, len: f64, r: f64) -> bool {
        let c = chain.dir.dot(dir).clamp(-1.0, 1.0);
        if c < MITRE_MIN_COS {
            return false;
        }
        let tan_half = ((1.0 - c) / (1.0 + c)).sqrt();
        let reach = 0.5 * (chain.radius + r) * tan_half;
        reach <= MITRE_MAX_REACH * chain.len.min(len)
    }

    /// Writes the mitred joint ring of `chain` and the side of its last
    /// segment; the result continues along the new segment.
    fn mitre(&mut self, chain: Chain, b: DVec3, dir: DVec3, len: f64, r: f64, color: u32) -> Chain {
        self.material(chain.color);
        let d0 = chain.dir;
        let m = (d0 + dir).try_normalize().unwrap_or(d0);
        let cos_half = d0.dot(m).max(1e-9);
        let rot = DQuat::from_rotation_arc(d0, dir);
        let rj = 0.5 * (chain.radius + r);
        let p = chain.end;
        let ring = self.ring(
            |v| p + v * rj - d0 * (rj * v.dot(m) / cos_half),
            |v| v + rot * v,
            chain.n,
            d0,
        );
        self.side(chain.ring, ring);
        let n = rot * chain.n;
        let n = (n - dir * dir.dot(n))
            .try_normalize()
            .unwrap_or_else(|| perpendicular(dir));
        Chain {
            end: b,
            dir,
            len,
            n,
            radius: r,
            color,
            ring,
        }
    }

    /// Remembers that a tube of radius `r` reached `p`.
    fn remember(&mut self, p: DVec3, r: f64) {
        let k = key(p);
        if let Some(j) = self.joints.get_mut(&k) {
            j.radius = j.radius.max(r);
            return;
        }
        if self.joint_order.len() >= MAX_JOINTS
            && let Some(old) = self.joint_order.pop_front()
        {
            self.joints.remove(&old);
        }
        self.joints.insert(
            k,
            Joint {
                radius: r,
                sphere: 0.0,
            },
        );
        self.joint_order.push_back(k);
    }

    /// Starts a tube at `a` (a sphere first when a tube already reached `a`).
    fn start(&mut self, a: DVec3, b: DVec3, dir: DVec3, len: f64, r: f64, color: u32) {
        self.material(color);
        let k = key(a);
        let sphere = match self.joints.get_mut(&k) {
            Some(j) => {
                let s = j.radius.max(r);
                if s > j.sphere * (1.0 + 1e-9) {
                    j.sphere = s;
                    Some(s)
                } else {
                    None
                }
            }
            None => None,
        };
        if let Some(s) = sphere {
            self.sphere(a, s);
        }
        self.remember(a, r);
        let n = perpendicular(dir);
        let ring = self.ring(|v| a + v * r, |v| v, n, dir);
        self.cap(ring, a, -dir, true);
        self.open.push(Chain {
            end: b,
            dir,
            len,
            n,
            radius: r,
            color,
            ring,
        });
        if self.open.len() > MAX_OPEN_CHAINS {
            let oldest = self.open.remove(0);
            self.close(oldest);
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
            .map(|&[x, y]| at + (-l * x + h * y) * scale)
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

/// Appends a few bytes (cheaper than a `memmove` call for short slices).
fn put(buf: &mut Vec<u8>, bytes: &[u8]) {
    for &b in bytes {
        buf.push(b);
    }
}

/// Appends a decimal integer.
fn push_int(buf: &mut Vec<u8>, mut n: u64) {
    const PAIRS: &[u8; 200] = b"0001020304050607080910111213141516171819\
        2021222324252627282930313233343536373839\
        4041424344454647484950515253545556575859\
        6061626364656667686970717273747576777879\
        8081828384858687888990919293949596979899";
    let mut digits = [0u8; 20];
    let mut i = digits.len();
    while n >= 100 {
        let r = (n % 100) as usize * 2;
        n /= 100;
        i -= 2;
        digits[i..i + 2].copy_from_slice(&PAIRS[r..r + 2]);
    }
    if n >= 10 {
        let r = n as usize * 2;
        i -= 2;
        digits[i..i + 2].copy_from_slice(&PAIRS[r..r + 2]);
    } else {
        i -= 1;
        digits[i] = b'0' + n as u8;
    }
    put(buf, &digits[i..]);
}

/// Powers of ten exactly representable as `f64`.
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// `a / 10^(e − 6)` rounded (a > 0): the 7 significant digits of `a` when its
/// decimal exponent is `e`.
fn mantissa(a: f64, e: i32) -> u64 {
    let k = 6 - e;
    let p = POW10
        .get(k.unsigned_abs() as usize)
        .copied()
        .unwrap_or_else(|| 10f64.powi(k.abs()));
    (if k >= 0 { a * p } else { a / p } + 0.5) as u64
}

/// Appends a number with 7 significant digits (about single precision), in
/// plain decimal notation without exponent, trailing zeros or negative zero.
/// Deterministic: the same `f64` always gives the same text.
fn push_number(buf: &mut Vec<u8>, x: f64) {
    let a = x.abs();
    if !(1e-15..1e22).contains(&a) {
        // Zero (and rounding noise around it), non-finite (never written), or
        // beyond the usual range.
        if a < 1e-15 || !a.is_finite() {
            buf.push(b'0');
        } else {
            let _ = write!(buf, "{}", x as f32);
        }
        return;
    }
    // The decimal exponent from the binary one (78913 / 2^18 ≈ log10 2), then
    // corrected: the estimate may be one off, and rounding may carry to 10^7.
    let e2 = ((a.to_bits() >> 52) & 0x7ff) as i32 - 1023;
    let mut e = (e2 * 78913) >> 18;
    let mut m = mantissa(a, e);
    for _ in 0..3 {
        if m >= 10_000_000 {
            e += 1;
        } else if m < 1_000_000 {
            e -= 1;
        } else {
            break;
        }
        m = mantissa(a, e);
    }
    let mut mi = m.clamp(1_000_000, 9_999_999);
    if x < 0.0 {
        buf.push(b'-');
    }
    let mut digits = [0u8; 7];
    for d in digits.iter_mut().rev() {
        *d = b'0' + (mi % 10) as u8;
        mi /= 10;
    }
    let used = digits.iter().rposition(|&d| d != b'0').map_or(1, |i| i + 1);
    if e >= 6 {
        put(buf, &digits);
        buf.extend(std::iter::repeat_n(b'0', (e - 6) as usize));
    } else if e >= 0 {
        let int = e as usize + 1;
        put(buf, &digits[..int]);
        if used > int {
            buf.push(b'.');
            put(buf, &digits[int..used]);
        }
    } else {
        buf.extend_from_slice(b"0.");
        buf.extend(std::iter::repeat_n(b'0', (-e - 1) as usize));
        put(buf, &digits[..used]);
    }
}

/// The exact position as a map key (−0 and +0 are the same point).
fn key(p: DVec3) -> [u64; 3] {
    [
        (p.x + 0.0).to_bits(),
        (p.y + 0.0).to_bits(),
        (p.z + 0.0).to_bits(),
    ]
}

/// A unit vector perpendicular to the unit vector `d`, chosen deterministically.
fn perpendicular(d: DVec3) -> DVec3 {
    // The axis least aligned with d.
    let a = d.abs();
    let axis = if a.x <= a.y && a.x <= a.z {
        DVec3::X
    } else if a.y <= a.z {
        DVec3::Y
    } else {
        DVec3::Z
    };
    (axis - d * d.dot(axis)).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    /// A parsed OBJ file: positions, normals, faces as 0-based (vertex, normal).
    #[derive(Debug, Default)]
    struct Mesh {
        v: Vec<DVec3>,
        vn: Vec<DVec3>,
        faces: Vec<Vec<(usize, usize)>>,
        tubes: usize,
        spheres: usize,
    }

    fn parse(text: &str) -> Mesh {
        let mut m = Mesh::default();
        for line in text.lines() {
            let mut it = line.split_whitespace();
            match it.next() {
                Some("v") | Some("vn") => {
                    let xs: Vec<f64> = it.map(|x| x.parse().expect("number")).collect();
                    assert_eq!(xs.len(), 3, "{line}");
                    let p = DVec3::new(xs[0], xs[1], xs[2]);
                    if line.starts_with("vn") {
                        m.vn.push(p)
                    } else {
                        m.v.push(p)
                    }
                }
                Some("f") => {
                    let face: Vec<(usize, usize)> = it
                        .map(|c| {
                            let (v, n) = c.split_once("//").expect("v//vn");
                            let v: usize = v.parse().expect("index");
                            let n: usize = n.parse().expect("index");
                            assert!(v >= 1 && v <= m.v.len(), "vertex {v} of {}", m.v.len());
                            assert!(n >= 1 && n <= m.vn.len(), "normal {n} of {}", m.vn.len());
                            (v - 1, n - 1)
                        })
                        .collect();
                    m.faces.push(face);
                }
                Some("#") => {
                    let words: Vec<&str> = line.split_whitespace().collect();
                    if words.get(2) == Some(&"tubes,") {
                        m.tubes = words[1].parse().expect("count");
                        m.spheres = words[3].parse().expect("count");
                    }
                }
                Some("usemtl") | None => {}
                Some(other) => panic!("unexpected line kind {other}"),
            }
        }
        m
    }

    fn write(f: impl FnOnce(&mut ObjWriter<Vec<u8>>)) -> String {
        write_with(ObjOptions::default(), f)
    }

    fn write_with(options: ObjOptions, f: impl FnOnce(&mut ObjWriter<Vec<u8>>)) -> String {
        let mut w = ObjWriter::new(Vec::new(), options);
        f(&mut w);
        String::from_utf8(w.finish().expect("write to a Vec")).expect("utf-8")
    }

    /// Faces have ≥ 3 distinct vertices, no zero area; normals are unit length.
    fn check_valid(m: &Mesh) {
        for n in &m.vn {
            assert!((n.length() - 1.0).abs() < 1e-5, "normal {n} not unit");
        }
        for face in &m.faces {
            assert!(face.len() >= 3);
            let mut vs: Vec<usize> = face.iter().map(|c| c.0).collect();
            vs.sort_unstable();
            vs.dedup();
            assert_eq!(vs.len(), face.len(), "repeated vertex in {face:?}");
            assert!(area(m, face) > 1e-12, "degenerate face {face:?}");
        }
    }

    fn area(m: &Mesh, face: &[(usize, usize)]) -> f64 {
        let p0 = m.v[face[0].0];
        let mut a = DVec3::ZERO;
        for w in face[1..].windows(2) {
            a += (m.v[w[0].0] - p0).cross(m.v[w[1].0] - p0);
        }
        0.5 * a.length()
    }

    /// Every edge is used by exactly two faces, once in each direction: closed
    /// and consistently oriented.
    fn check_closed(m: &Mesh) {
        let mut directed: BTreeMap<(usize, usize), usize> = BTreeMap::new();
        for face in &m.faces {
            for k in 0..face.len() {
                let e = (face[k].0, face[(k + 1) % face.len()].0);
                *directed.entry(e).or_default() += 1;
            }
        }
        for (&(a, b), &count) in &directed {
            assert_eq!(count, 1, "edge {a}->{b} used {count} times");
            assert_eq!(directed.get(&(b, a)), Some(&1), "edge {a}-{b} is open");
        }
    }

    /// Each triangle's winding agrees with the normals it references.
    fn check_normals_agree(m: &Mesh) {
        for face in &m.faces {
            let mut g = DVec3::ZERO;
            for k in 0..face.len() {
                g += m.v[face[k].0].cross(m.v[face[(k + 1) % face.len()].0]);
            }
            for c in face {
                assert!(g.dot(m.vn[c.1]) > 0.0, "face {face:?} against its normals");
            }
        }
    }

    /// The enclosed volume (positive when faces point outward).
    fn volume(m: &Mesh) -> f64 {
        let mut v = 0.0;
        for face in &m.faces {
            let p0 = m.v[face[0].0];
            for w in face[1..].windows(2) {
                v += p0.dot(m.v[w[0].0].cross(m.v[w[1].0])) / 6.0;
            }
        }
        v
    }

    /// Connected parts (by shared vertices).
    fn parts(m: &Mesh) -> usize {
        let mut parent: Vec<usize> = (0..m.v.len()).collect();
        fn root(p: &mut [usize], mut i: usize) -> usize {
            while p[i] != i {
                p[i] = p[p[i]];
                i = p[i];
            }
            i
        }
        for face in &m.faces {
            let a = root(&mut parent, face[0].0);
            for c in &face[1..] {
                let b = root(&mut parent, c.0);
                parent[b] = a;
            }
        }
        let used: std::collections::BTreeSet<usize> =
            m.faces.iter().flatten().map(|c| c.0).collect();
        let roots: std::collections::BTreeSet<usize> =
            used.into_iter().map(|i| root(&mut parent, i)).collect();
        roots.len()
    }

    fn check_solid(m: &Mesh) {
        check_valid(m);
        check_closed(m);
        check_normals_agree(m);
        assert!(m.faces.is_empty() || volume(m) > 0.0);
    }

    /// Area of the regular octagon of radius r.
    fn octagon(r: f64) -> f64 {
        2.0 * std::f64::consts::SQRT_2 * r * r
    }

    fn v3(x: f64, y: f64, z: f64) -> DVec3 {
        DVec3::new(x, y, z)
    }

    #[test]
    fn single_segment_is_a_closed_tube() {
        let text = write(|w| w.segment(DVec3::ZERO, v3(0.0, 2.0, 0.0), 0.5, 0));
        let m = parse(&text);
        check_solid(&m);
        assert_eq!((m.tubes, m.spheres, parts(&m)), (1, 0, 1));
        // Two rings and two cap centres; sides, two caps.
        assert_eq!(m.v.len(), 2 * 8 + 2);
        assert_eq!(m.faces.len(), 8 + 16);
        assert!((volume(&m) - octagon(0.25) * 2.0).abs() < 1e-5);
        assert!(text.starts_with("# lsyc OBJ"));
    }

    #[test]
    fn hairline_uses_default_radius() {
        let opts = ObjOptions {
            default_radius: 0.1,
            ..ObjOptions::default()
        };
        let m = parse(&write_with(opts, |w| {
            w.segment(DVec3::ZERO, v3(1.0, 0.0, 0.0), 0.0, 0)
        }));
        check_solid(&m);
        assert!((volume(&m) - octagon(0.1)).abs() < 1e-6);
    }

    #[test]
    fn chain_with_turns_is_one_watertight_tube() {
        let p0 = DVec3::ZERO;
        let p1 = v3(0.0, 1.0, 0.0);
        let p2 = p1 + v3(-(30f64.to_radians().sin()), 30f64.to_radians().cos(), 0.0);
        let p3 = p2 + v3(0.3, 0.5, 0.8).normalize() * 1.5;
        let p4 = p3 + v3(1.0, 0.0, 0.0);
        let text = write(|w| {
            w.segment(p0, p1, 0.2, 0);
            w.segment(p1, p2, 0.2, 0);
            w.segment(p2, p3, 0.2, 0);
            w.segment(p3, p4, 0.2, 0);
        });
        let m = parse(&text);
        check_solid(&m);
        assert_eq!((m.tubes, m.spheres, parts(&m)), (1, 0, 1));
        // Mitres of a centrally symmetric section keep the volume: area × length.
        assert!(
            (volume(&m) - octagon(0.1) * 4.5).abs() < 1e-4,
            "{}",
            volume(&m)
        );
        // Joint rings are shared: 5 rings + 2 centres.
        assert_eq!(m.v.len(), 5 * 8 + 2);
    }

    #[test]
    fn parallel_transport_does_not_twist() {
        // A helix-like chain: ring vertex 0 stays on the same side of the tube.
        let text = write(|w| {
            let mut p = DVec3::ZERO;
            for k in 0..40 {
                let t = k as f64 * 0.3;
                let q = p + v3(t.cos(), t.sin(), 0.4).normalize() * 0.5;
                w.segment(p, q, 0.1, 0);
                p = q;
            }
        });
        let m = parse(&text);
        check_solid(&m);
        assert_eq!(m.tubes, 1);
        // Between consecutive rings, vertex i keeps its radial direction seen
        // along the segment (no twist). The start ring comes first, then the
        // start cap's centre, then one ring per joint.
        let ring = |r: usize, i: usize| {
            if r == 0 {
                m.v[i]
            } else {
                m.v[9 + (r - 1) * 8 + i]
            }
        };
        let centre = |r: usize| (0..8).map(|i| ring(r, i)).sum::<DVec3>() / 8.0;
        for r in 0..40 {
            let d = (centre(r + 1) - centre(r)).normalize();
            let radial = |r: usize, i: usize| {
                let v = ring(r, i) - centre(r);
                (v - d * d.dot(v)).normalize()
            };
            for i in 0..8 {
                let c = radial(r, i).dot(radial(r + 1, i));
                assert!(c > 0.9999, "ring {r} vertex {i}: {c}");
            }
        }
    }

    #[test]
    fn branch_starts_a_new_tube_with_a_sphere() {
        // F[+F]F: the branch continues the first tube; the main axis after `]`
        // starts at the joint, closed by its own caps and a sphere.
        let p = v3(0.0, 1.0, 0.0);
        let text = write(|w| {
            w.segment(DVec3::ZERO, p, 0.2, 0);
            w.segment(p, p + v3(-0.5, 0.866, 0.0), 0.1, 1);
            w.segment(p, p + v3(0.0, 1.0, 0.0), 0.2, 0);
        });
        let m = parse(&text);
        check_solid(&m);
        assert_eq!((m.tubes, m.spheres, parts(&m)), (2, 1, 3));
        assert!(text.contains("usemtl lsyc_color1\n"));
        // The sphere has the trunk's radius, centred at the joint.
        let far =
            m.v.iter()
                .filter(|v| (v.distance(p) - 0.1).abs() < 1e-6)
                .count();
        assert!(far >= 8 * 3 + 2);
    }

    #[test]
    fn fan_of_branches_gets_one_sphere() {
        let text = write(|w| {
            for k in 0..5 {
                let a = k as f64;
                w.segment(DVec3::ZERO, v3(a.cos(), a.sin(), 0.0), 0.1, 0);
            }
        });
        let m = parse(&text);
        check_solid(&m);
        assert_eq!((m.tubes, m.spheres, parts(&m)), (5, 1, 6));
    }

    #[test]
    fn continuation_after_pop_joins_its_chain() {
        // F[+fF]F: the chain ending at p is still open when the axis continues.
        let p = v3(0.0, 1.0, 0.0);
        let text = write(|w| {
            w.segment(DVec3::ZERO, p, 0.2, 0);
            w.segment(v3(-1.0, 2.0, 0.0), v3(-1.0, 3.0, 0.0), 0.2, 0);
            w.segment(p, v3(0.2, 2.0, 0.0), 0.2, 0);
        });
        let m = parse(&text);
        check_solid(&m);
        assert_eq!((m.tubes, m.spheres, parts(&m)), (2, 0, 2));
    }

    #[test]
    fn sharp_turn_closes_the_chain_with_a_sphere() {
        // F|F: a reversal cannot be mitred.
        let text = write(|w| {
            w.segment(DVec3::ZERO, v3(0.0, 1.0, 0.0), 0.2, 0);
            w.segment(v3(0.0, 1.0, 0.0), v3(0.0, 0.5, 0.0), 0.2, 0);
            // A turn fine in angle but too sharp for such short segments.
            w.segment(v3(0.0, 0.5, 0.0), v3(0.05, 0.45, 0.0), 0.2, 0);
        });
        let m = parse(&text);
        check_solid(&m);
        assert_eq!((m.tubes, m.spheres, parts(&m)), (3, 2, 5));
    }

    #[test]
    fn degenerate_segments_are_skipped() {
        let p = v3(0.0, 1.0, 0.0);
        let text = write(|w| {
            w.segment(DVec3::ZERO, DVec3::ZERO, 1.0, 0);
            w.segment(DVec3::ZERO, p, 0.1, 0);
            w.segment(p, p, 0.1, 0);
            w.segment(p, v3(0.0, 2.0, 0.0), 0.1, 0);
            w.segment(p, v3(f64::NAN, 0.0, 0.0), 0.1, 0);
            w.segment(p, v3(f64::INFINITY, 0.0, 0.0), 0.1, 0);
            w.segment(v3(0.0, 2.0, 0.0), v3(0.0, 3.0, 0.0), f64::INFINITY, 0);
        });
        let m = parse(&text);
        check_solid(&m);
        assert_eq!((m.tubes, m.spheres), (1, 0));
        assert!(m.v.iter().all(|v| v.is_finite()));
    }

    #[test]
    fn tiny_segments_and_radii_give_no_degenerate_faces() {
        let p = v3(1000.0, 0.0, 0.0);
        let text = write(|w| {
            w.segment(DVec3::ZERO, p, 0.5, 0);
            // Too short to show: the chain just ends a little further.
            w.segment(p, p + v3(1e-9, 1e-9, 0.0), 0.5, 0);
            w.segment(p + v3(1e-9, 1e-9, 0.0), v3(1000.0, 10.0, 0.0), 0.5, 0);
            // A tube thinner than the digits resolve at this distance.
            w.segment(v3(0.0, 1000.0, 0.0), v3(10.0, 1000.0, 0.0), 1e-9, 0);
            // Tiny everything near the origin.
            w.segment(DVec3::ZERO, v3(1e-20, 0.0, 0.0), 1e-30, 0);
        });
        let m = parse(&text);
        check_solid(&m);
        assert_eq!((m.tubes, m.spheres), (2, 0));
    }

    #[test]
    fn many_open_chains_stay_closed() {
        let text = write(|w| {
            for k in 0..200 {
                let x = k as f64;
                w.segment(v3(x, 0.0, 0.0), v3(x, 1.0, 0.0), 0.2, 0);
            }
            // Continue an early chain (closed by now) and a recent one.
            w.segment(v3(0.0, 1.0, 0.0), v3(0.0, 2.0, 0.0), 0.2, 0);
            w.segment(v3(199.0, 1.0, 0.0), v3(199.0, 2.0, 0.0), 0.2, 0);
        });
        let m = parse(&text);
        check_solid(&m);
        assert_eq!((m.tubes, m.spheres), (201, 1));
    }

    /// A pseudo-random bracketed 3D walk with varying widths and angles.
    fn random_walk(w: &mut ObjWriter<Vec<u8>>, n: usize, seed: u64) {
        random_walk_sink(w, n, seed)
    }

    fn random_walk_sink(w: &mut dyn Sink, n: usize, seed: u64) {
        let mut s = seed;
        let mut rnd = move || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut pos, mut h, mut l) = (DVec3::ZERO, DVec3::Y, DVec3::NEG_X);
        let mut width = 0.2;
        let mut stack = Vec::new();
        for _ in 0..n {
            let x = rnd();
            if x < 0.15 {
                stack.push((pos, h, l, width));
                width *= 0.8;
            } else if x < 0.3 {
                if let Some(st) = stack.pop() {
                    (pos, h, l, width) = st;
                }
            } else if x < 0.4 {
                pos += h * (0.2 + rnd());
            } else if x < 0.7 {
                let q = DQuat::from_axis_angle(h.cross(l), (rnd() - 0.5) * 4.0);
                let r = DQuat::from_axis_angle(l, (rnd() - 0.5) * 2.0);
                h = (r * q * h).normalize();
                l = (r * q * l).normalize();
            } else {
                let q = pos + h * (0.3 + rnd());
                w.segment(pos, q, width, (rnd() * 3.0) as u32);
                pos = q;
            }
        }
    }

    #[test]
    fn random_bracketed_walks_are_closed() {
        for seed in 0..20 {
            let m = parse(&write(|w| random_walk(w, 400, seed)));
            check_solid(&m);
            assert!(m.tubes > 0);
        }
    }

    /// A manual speed check (not a benchmark target):
    /// `cargo test --release --lib throughput -- --ignored --nocapture`.
    #[test]
    fn numbers_have_seven_significant_digits() {
        let text = |x: f64| {
            let mut b = Vec::new();
            push_number(&mut b, x);
            String::from_utf8(b).expect("ascii")
        };
        for (x, t) in [
            (0.0, "0"),
            (-0.0, "0"),
            (1.0, "1"),
            (-2.5, "-2.5"),
            (0.1, "0.1"),
            (0.1 + 0.2, "0.3"),
            (100.0, "100"),
            (1e-3, "0.001"),
            (6.123233995736766e-17, "0"),
            (1234567.8, "1234568"),
            (123456789.0, "123456800"),
            (9999999.6, "10000000"),
            (0.99999996, "1"),
            (std::f64::consts::PI, "3.141593"),
            (-0.000123456789, "-0.0001234568"),
        ] {
            assert_eq!(text(x), t, "{x}");
        }
        assert_eq!(text(f64::NAN), "0");
        let mut s = 12345u64;
        for _ in 0..100_000 {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let x = f64::from_bits((s >> 2) & !(0x7ff << 52) | (((s >> 54) % 60 + 1000) << 52));
            let x = if s & 1 == 0 { x } else { -x };
            let t = text(x);
            let back: f64 = t.parse().expect("a number");
            assert!((back - x).abs() <= 5.0000001e-7 * x.abs(), "{x} as {t}");
            assert!(!t.contains('e') && !t.ends_with('.'), "{t}");
            if t.contains('.') {
                assert!(!t.ends_with('0'), "{t}");
            }
        }
    }

    #[test]
    fn output_is_deterministic() {
        let a = write(|w| random_walk(w, 500, 7));
        let b = write(|w| random_walk(w, 500, 7));
        assert_eq!(a, b);
    }

    #[test]
    fn polygon_becomes_one_face_with_its_normal() {
        let pts = [
            DVec3::ZERO,
            v3(1.0, 0.0, 0.0),
            v3(1.0, 0.0, 0.0),
            v3(1.0, 1.0, 0.0),
            v3(0.5, 0.3, 0.0),
            v3(0.0, 1.0, 0.0),
            DVec3::ZERO,
        ];
        let m = parse(&write(|w| {
            w.polygon(&pts, 2);
            // Collinear, too small and too short polygons draw nothing.
            w.polygon(&[DVec3::ZERO, v3(1.0, 0.0, 0.0), v3(2.0, 0.0, 0.0)], 0);
            let far = v3(1e6, 0.0, 0.0);
            w.polygon(
                &[far, far + v3(1e-3, 0.0, 0.0), far + v3(0.0, 1e-3, 0.0)],
                0,
            );
            w.polygon(&[DVec3::ZERO, v3(1.0, 0.0, 0.0)], 0);
        }));
        check_valid(&m);
        assert_eq!(m.faces.len(), 1);
        assert_eq!(m.faces[0].len(), 5);
        assert!(m.vn[m.faces[0][0].1].distance(DVec3::Z) < 1e-6);
    }

    #[test]
    fn element_outline_is_placed_in_the_turtle_frame() {
        let leaf = "M0 0 C6 4 7 14 1 20 C-3 14 -5 9 -2 6 L-4 3 Z";
        let outline = outline_from_path(leaf).expect("a leaf has area");
        assert!(outline.points.len() > 10);
        let opts = ObjOptions {
            elements: vec![
                ElementOutline {
                    // Clockwise: reoriented to face U.
                    points: vec![[0.0, 0.0], [-1.0, 1.0], [0.0, 2.0], [1.0, 1.0]],
                },
                outline,
                ElementOutline::default(),
            ],
            ..ObjOptions::default()
        };
        // Heading +x, left +y (so U = +z, local +x is −y), scale 2, at (5, 0, 0).
        let m = parse(&write_with(opts, |w| {
            w.element(0, v3(5.0, 0.0, 0.0), DVec3::X, DVec3::Y, 2.0, 0);
            w.element(1, DVec3::ZERO, DVec3::Y, DVec3::NEG_X, 0.1, 0);
            w.element(2, DVec3::ZERO, DVec3::Y, DVec3::NEG_X, 1.0, 0);
            w.element(9, DVec3::ZERO, DVec3::Y, DVec3::NEG_X, 1.0, 0);
        }));
        check_valid(&m);
        assert_eq!(m.faces.len(), 2);
        let first: Vec<DVec3> = m.faces[0].iter().map(|c| m.v[c.0]).collect();
        for p in [
            v3(5.0, 0.0, 0.0),
            v3(7.0, 2.0, 0.0),
            v3(9.0, 0.0, 0.0),
            v3(7.0, -2.0, 0.0),
        ] {
            assert!(first.iter().any(|q| q.distance(p) < 1e-6), "{p} missing");
        }
        for face in &m.faces {
            assert!(m.vn[face[0].1].distance(DVec3::Z) < 1e-6);
            // Counter-clockwise about the normal.
            let mut a = DVec3::ZERO;
            for k in 0..face.len() {
                a += m.v[face[k].0].cross(m.v[face[(k + 1) % face.len()].0]);
            }
            assert!(a.z > 0.0);
        }
    }

    #[test]
    fn outlines_from_paths() {
        assert_eq!(outline_from_path("M0 0 L0 10"), None);
        assert_eq!(outline_from_path(""), None);
        assert_eq!(outline_from_path("not a path"), None);
        let square = outline_from_path("M0 0 H2 V2 H0 Z").expect("square");
        assert_eq!(
            square.points,
            vec![[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]]
        );
        // The largest subpath wins; parsing stops at an error.
        let two = outline_from_path("M0 0 h1 v1 h-1 z M5 5 h3 v3 h-3 z M0 0 L x").expect("two");
        assert_eq!(two.points[0], [5.0, 5.0]);
        let arc = outline_from_path("M0 0 A5 5 0 0 1 10 0 Z").expect("arc");
        assert!(arc.points.len() > 4);
    }

    #[test]
    fn write_errors_are_reported_by_finish() {
        struct Full(usize);
        impl Write for Full {
            fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
                if self.0 < buf.len() {
                    return Err(io::Error::other("disk full"));
                }
                self.0 -= buf.len();
                Ok(buf.len())
            }
            fn flush(&mut self) -> io::Result<()> {
                Ok(())
            }
        }
        let mut w = ObjWriter::new(Full(1000), ObjOptions::default());
        for k in 0..10_000 {
            let y = k as f64;
            w.segment(v3(0.0, y, 0.0), v3(0.0, y + 1.0, 0.0), 0.1, 0);
        }
        let err = w.finish().err().expect("the error");
        assert_eq!(err.to_string(), "disk full");
    }

    /// Forwards only segments.
    struct Tubes(ObjWriter<Vec<u8>>);

    impl Sink for Tubes {
        fn segment(&mut self, a: DVec3, b: DVec3, width: f64, color: u32) {
            self.0.segment(a, b, width, color);
        }
        fn polygon(&mut self, _: &[DVec3], _: u32) {}
        fn element(&mut self, _: u16, _: DVec3, _: DVec3, _: DVec3, _: f64, _: u32) {}
    }

    /// Every gallery program, through the real turtle, gives closed solids.
    #[test]
    fn gallery_programs_are_closed() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("lang-examples");
        let mut entries: Vec<_> = std::fs::read_dir(&dir)
            .expect("lang-examples")
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "lsy"))
            .collect();
        entries.sort();
        let mut checked = 0;
        for path in entries {
            let text = std::fs::read_to_string(&path).expect("read");
            let front = crate::frontend::run(&text, Vec::new(), &[]);
            let Some(c) = front.checked.as_ref().filter(|_| !front.has_errors()) else {
                continue;
            };
            let Ok(prog) = crate::compile::compile(&front.file, c, None) else {
                continue;
            };
            let Ok(mut s) = crate::derive::axiom(&prog, &[], 1) else {
                continue;
            };
            // The default steps, as long as the string stays small.
            for k in 1..=prog.derive {
                match crate::derive::step(&prog, &s, k, 1, Default::default()) {
                    Ok(next) if next.len() <= 800 => s = next,
                    _ => break,
                }
            }
            let name = path.display();
            // Everything: valid indices and faces.
            let mut w = ObjWriter::new(Vec::new(), ObjOptions::for_program(&prog));
            let drawn = crate::turtle::interpret(&prog, &s, 1, &mut w).expect("interpret");
            let m = parse(&String::from_utf8(w.finish().expect("write")).expect("utf-8"));
            check_valid(&m);
            assert!(drawn.segments == 0 || m.tubes > 0, "{name}");
            // The tubes alone (polygons and elements are open sheets): closed.
            let mut t = Tubes(ObjWriter::new(Vec::new(), ObjOptions::for_program(&prog)));
            crate::turtle::interpret(&prog, &s, 1, &mut t).expect("interpret");
            let m = parse(&String::from_utf8(t.0.finish().expect("write")).expect("utf-8"));
            check_solid(&m);
            checked += 1;
        }
        assert!(checked > 10, "only {checked} gallery programs ran");
    }
}
