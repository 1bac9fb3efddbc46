//! The 3D mesh of a drawing, written as Wavefront OBJ (and, through
//! `crate::render::glb`, as glTF): a streaming `turtle::Sink` that builds
//! segments as closed tubes, polygons `{ . }` as faces and elements as flat
//! outlines.
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
//! Colours `'(c)` become materials named `lsyc_color<c>` (`usemtl` switches,
//! and the `.mtl` library of [`write_mtl`]).
//!
//! The mesh is built once, by [`MeshBuilder`], and sent to a [`MeshTarget`]:
//! [`ObjText`] prints it as OBJ text; `crate::render::glb` keeps it in buffers
//! for binary glTF. Anything the builder makes reaches both formats.
//! Must not know the turtle's rules or any other output format.
//!
//! Parts: this file (options, the builder and its faces), `text` (OBJ and MTL
//! text), `tube` (tubes, caps, mitres and spherical joints), `outline` (element
//! outlines, read through `crate::path`); numbers are printed by `crate::number`.

mod outline;
#[cfg(test)]
mod tests;
mod text;
mod tube;

pub use outline::{ElementOutline, outline_from_path};
pub use text::{MATERIAL_PREFIX, ObjText, material_name, write_mtl, write_mtl_with};

use crate::compile::Program;
use crate::organ::Solid;
use crate::turtle::Sink;
use glam::DVec3;
use std::collections::{BTreeSet, HashMap, VecDeque};
use std::io::{self, Write};
use std::sync::Arc;
use tube::{Chain, Joint};

/// Where the built mesh goes. Vertices and normals are numbered from 1, each
/// in the order they arrive; faces refer to them by these numbers.
pub trait MeshTarget {
    fn vertex(&mut self, p: DVec3);
    /// A unit normal.
    fn normal(&mut self, n: DVec3);
    /// A face of (vertex, normal) corners, counter-clockwise seen from outside.
    /// Tube faces are convex; polygon and element faces are simple polygons,
    /// possibly concave.
    fn face(&mut self, corners: &[(u64, u64)]);
    /// The colour of the faces that follow.
    fn material(&mut self, color: u32);
    /// Faces that follow belong to a new object called `name` (an lsystem, a
    /// scene's guide).
    fn object(&mut self, name: &str);
    /// The colours and material names of the faces' colours.
    fn palette(&mut self, _palette: &crate::render::Palette) {}
    /// A remark for a reader of the file (OBJ comments; ignored elsewhere).
    fn comment(&mut self, _text: &str) {}
}

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

/// How the mesh is built.
#[derive(Clone, Debug)]
pub struct ObjOptions {
    /// Vertices per tube ring (clamped to 3..=`MAX_SIDES`).
    pub sides: usize,
    /// Tube radius for hairlines (width 0).
    pub default_radius: f64,
    /// The outline of every element, by element index.
    pub elements: Vec<ElementOutline>,
    /// The 3D organ of every element that is one, by element index.
    pub solids: Vec<Option<Arc<Solid>>>,
    /// The contour of every element that declares one, by element index.
    pub contours: Vec<Option<Arc<Vec<glam::DVec2>>>>,
    /// The colours and their material names.
    pub palette: crate::render::Palette,
}

impl Default for ObjOptions {
    fn default() -> ObjOptions {
        ObjOptions {
            sides: 8,
            default_radius: 0.05,
            elements: Vec::new(),
            solids: Vec::new(),
            contours: Vec::new(),
            palette: crate::render::Palette::default(),
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
            solids: prog.elements.iter().map(|e| e.solid.clone()).collect(),
            contours: prog.elements.iter().map(|e| e.contour.clone()).collect(),
            palette: crate::render::Palette::of(prog),
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

/// Builds the mesh of a drawing into a [`MeshTarget`], streaming. Call
/// [`MeshBuilder::into_target`] (or `finish` on an [`ObjWriter`]) to close
/// the open tubes; without it the mesh is incomplete.
pub struct MeshBuilder<T: MeshTarget> {
    out: T,
    sides: usize,
    /// cos, sin of the ring angles.
    ring_angles: Vec<(f64, f64)>,
    default_radius: f64,
    /// Element outlines, cleaned and counter-clockwise.
    elements: Vec<Vec<glam::DVec2>>,
    /// 3D organs by element index.
    solids: Vec<Option<Arc<Solid>>>,
    /// Ring profiles: 0 the circle, element index + 1 a contour; each vertex
    /// as (offset x, offset y, normal x, normal y) in units of the radius.
    profiles: Vec<Arc<Vec<[f64; 4]>>>,
    /// The profile of the segments that follow.
    profile: usize,
    /// Open chains, the most recently extended last.
    open: Vec<Chain>,
    joints: HashMap<[u64; 3], Joint>,
    joint_order: VecDeque<[u64; 3]>,
    /// Vertices and normals written so far (the last index).
    v: u64,
    vn: u64,
    /// The current colour (`None` before the first face).
    material: Option<u32>,
    /// Every colour a face used.
    used: BTreeSet<u32>,
    counts: Counts,
}

/// A streaming OBJ writer: the mesh builder printing OBJ text.
pub type ObjWriter<W> = MeshBuilder<ObjText<W>>;

impl<W: Write> MeshBuilder<ObjText<W>> {
    /// An OBJ writer to `out`.
    pub fn new(out: W, options: ObjOptions) -> Self {
        Self::with_target(ObjText::new(out), options)
    }

    /// Like `new`, with a `mtllib` line naming the material library (written
    /// by [`write_mtl`] from [`MeshBuilder::colors`]).
    pub fn with_mtllib(out: W, options: ObjOptions, mtllib: &str) -> Self {
        let mut text = ObjText::new(out);
        text.mtllib(mtllib);
        Self::with_target(text, options)
    }

    /// Closes the open tubes, writes a closing comment with counts and flushes.
    /// Reports the first IO error of any earlier write.
    pub fn finish(self) -> io::Result<W> {
        self.into_target().finish()
    }
}

impl<T: MeshTarget> MeshBuilder<T> {
    pub fn with_target(mut out: T, options: ObjOptions) -> Self {
        out.palette(&options.palette);
        let sides = options.sides.clamp(3, MAX_SIDES);
        let ring_angles: Vec<(f64, f64)> = (0..sides)
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
        let circle: Vec<[f64; 4]> = ring_angles.iter().map(|&(c, s)| [c, s, c, s]).collect();
        let mut profiles = vec![Arc::new(circle.clone())];
        for c in &options.contours {
            profiles.push(Arc::new(
                c.as_deref()
                    .map_or_else(|| circle.clone(), |c| tube::profile(c)),
            ));
        }
        let mut w = MeshBuilder {
            out,
            sides,
            ring_angles,
            default_radius,
            elements,
            solids: options.solids,
            profiles,
            profile: 0,
            open: Vec::new(),
            joints: HashMap::new(),
            joint_order: VecDeque::new(),
            v: 0,
            vn: 0,
            material: None,
            used: BTreeSet::new(),
            counts: Counts::default(),
        };
        w.out.comment(&format!(
            "lsyc OBJ: segments as closed tubes ({sides} sides), polygons and elements as faces"
        ));
        w
    }

    /// Closes the open tubes and writes a closing comment with counts; gives
    /// back the target.
    pub fn into_target(mut self) -> T {
        self.close_open();
        let (c, v) = (self.counts, self.v);
        self.out.comment(&format!(
            "{} tubes, {} spheres, {} polygons, {} elements; {v} vertices, {} faces",
            c.tubes, c.spheres, c.polygons, c.elements, c.faces
        ));
        self.out
    }

    /// Every colour a face used so far, in order.
    pub fn colors(&self) -> Vec<u32> {
        self.used.iter().copied().collect()
    }

    /// Starts a new object called `name`: the open tubes are closed first, so
    /// that everything drawn before belongs to the previous object.
    pub fn object(&mut self, name: &str) {
        self.close_open();
        self.out.object(name);
    }

    fn close_open(&mut self) {
        for chain in std::mem::take(&mut self.open) {
            self.close(chain);
        }
    }

    fn vertex(&mut self, p: DVec3) -> u64 {
        self.out.vertex(p);
        self.v += 1;
        self.v
    }

    fn normal(&mut self, n: DVec3) -> u64 {
        self.out.normal(n);
        self.vn += 1;
        self.vn
    }

    /// A triangle of (vertex, normal) pairs, counter-clockwise seen from outside.
    fn tri(&mut self, a: (u64, u64), b: (u64, u64), c: (u64, u64)) {
        self.out.face(&[a, b, c]);
        self.counts.faces += 1;
    }

    fn material(&mut self, color: u32) {
        if self.material != Some(color) {
            self.material = Some(color);
            self.used.insert(color);
            self.out.material(color);
        }
    }
}

impl<T: MeshTarget> Sink for MeshBuilder<T> {
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
            if chain.profile == self.profile && Self::can_mitre(&chain, dir, len, r) {
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

    fn contour(&mut self, element: Option<u16>) {
        self.profile = element.map_or(0, |e| e as usize + 1);
        if self.profile >= self.profiles.len() {
            self.profile = 0;
        }
    }

    fn element(&mut self, index: u16, at: DVec3, h: DVec3, l: DVec3, scale: f64, color: u32) {
        if let Some(Some(solid)) = self.solids.get(index as usize) {
            let solid = Arc::clone(solid);
            if self.organ(&solid, (at, h, l, scale), color) {
                self.counts.elements += 1;
            }
            return;
        }
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

impl<T: MeshTarget> MeshBuilder<T> {
    /// A 3D organ's triangles placed in the turtle's frame (U = H × L): points
    /// scaled, normals turned with the frame. A negative scale mirrors the
    /// organ through its origin, so its normals and windings turn over.
    fn organ(&mut self, solid: &Solid, frame: (DVec3, DVec3, DVec3, f64), color: u32) -> bool {
        let (at, h, l, scale) = frame;
        let u = h.cross(l);
        if solid.triangles.is_empty() || !(at.is_finite() && scale.is_finite()) || scale == 0.0 {
            return false;
        }
        let world = |p: DVec3| at + (-l * p.x + h * p.y + u * p.z) * scale;
        if !solid.points.iter().all(|&p| world(p).is_finite()) {
            return false;
        }
        self.material(color);
        let (v0, n0) = (self.v, self.vn);
        for &p in &solid.points {
            self.vertex(world(p));
        }
        let flip = if scale < 0.0 { -1.0 } else { 1.0 };
        for &n in &solid.normals {
            let w = (-l * n.x + h * n.y + u * n.z) * flip;
            self.normal(w.try_normalize().unwrap_or(h));
        }
        // Triangles the written digits would not resolve (a patch's collapsed
        // edge, a tiny scale) are left out, as `face` leaves such faces out.
        let extent = solid
            .points
            .iter()
            .fold(1e-9f64, |m, &p| m.max(world(p).abs().max_element()));
        let resolution = RESOLUTION * extent;
        for t in &solid.triangles {
            let [a, b, c] = t.map(|(p, _)| world(solid.points[p as usize]));
            if 0.5 * (b - a).cross(c - a).length() <= resolution * resolution {
                continue;
            }
            let c = t.map(|(p, n)| (v0 + u64::from(p) + 1, n0 + u64::from(n) + 1));
            if scale < 0.0 {
                self.tri(c[0], c[2], c[1]);
            } else {
                self.tri(c[0], c[1], c[2]);
            }
        }
        true
    }

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
        let corners: Vec<(u64, u64)> = (0..pts.len() as u64).map(|k| (first + k, n)).collect();
        self.out.face(&corners);
        self.counts.faces += 1;
        true
    }
}
