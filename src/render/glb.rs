//! Binary glTF 2.0 (`.glb`) output: the mesh that the OBJ writer builds
//! (tubes, polygons, elements), kept in memory and written as one GLB file.
//!
//! Owns: the glTF document (through `gltf-json`) and the GLB container. One
//! node per object (the lsystem, or each guide of a scene) with one mesh; one
//! primitive per colour, each with POSITION (min and max given), NORMAL and
//! 32-bit indices; one material per palette colour used (PBR base colour,
//! linear RGB, double-sided because polygons and elements are single faces).
//! Polygon faces are split into triangles by ear clipping. Must not build
//! geometry: that is `render::obj::MeshBuilder`'s.

use super::obj::MeshTarget;
use glam::{DVec2, DVec3};
use gltf_json as json;
use json::validation::{Checked::Valid, USize64};
use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::io::{self, Write};

/// Faces with more corners than this are split as a fan (ear clipping costs
/// the square of the corners).
const MAX_EAR_CLIPPED: usize = 1024;

/// One colour's triangles of an object, with their own vertex numbering.
#[derive(Default)]
struct Primitive {
    /// (vertex, normal) pairs of the builder to this primitive's vertex index.
    index: HashMap<(u64, u64), u32>,
    corners: Vec<(u64, u64)>,
    triangles: Vec<u32>,
}

/// A named part of the drawing: the lsystem, or a guide of a scene.
struct Object {
    name: String,
    primitives: BTreeMap<u32, Primitive>,
}

/// The mesh as glTF wants it, gathered from a `MeshBuilder`.
#[derive(Default)]
pub struct GlbMesh {
    positions: Vec<DVec3>,
    normals: Vec<DVec3>,
    objects: Vec<Object>,
    color: u32,
    /// Too many vertices for 32-bit indices: writing fails.
    overflow: bool,
    /// Bytes the mesh may hold in memory (0: no bound), and about how many
    /// it holds; past the bound nothing more is kept and writing fails.
    budget: usize,
    held: usize,
    over_budget: bool,
    palette: super::Palette,
}

/// About how many bytes of memory a position or normal, a distinct corner
/// (its map entry and list item) and a triangle take.
const VECTOR_BYTES: usize = 24;
const CORNER_BYTES: usize = 56;
const TRIANGLE_BYTES: usize = 12;

impl GlbMesh {
    pub fn new() -> GlbMesh {
        GlbMesh::default()
    }

    /// A mesh that holds at most about `max_bytes` in memory (the run's
    /// `--max-memory`): glTF is written at the end, not streamed like OBJ.
    pub fn with_budget(max_bytes: usize) -> GlbMesh {
        GlbMesh {
            budget: max_bytes,
            ..GlbMesh::default()
        }
    }

    /// Counts `bytes` more; false (and nothing more is kept) past the budget.
    fn hold(&mut self, bytes: usize) -> bool {
        self.held = self.held.saturating_add(bytes);
        if self.budget > 0 && self.held > self.budget {
            self.over_budget = true;
        }
        !self.over_budget
    }

    fn corner(&mut self, c: (u64, u64)) -> Option<u32> {
        if self.objects.is_empty() {
            self.object("lsyc");
        }
        let color = self.color;
        let object = self.objects.last_mut()?;
        let prim = object.primitives.entry(color).or_default();
        if let Some(&i) = prim.index.get(&c) {
            return Some(i);
        }
        if self.over_budget {
            return None;
        }
        let Ok(i) = u32::try_from(prim.corners.len()) else {
            self.overflow = true;
            return None;
        };
        prim.index.insert(c, i);
        prim.corners.push(c);
        self.hold(CORNER_BYTES);
        Some(i)
    }

    fn triangle(&mut self, a: (u64, u64), b: (u64, u64), c: (u64, u64)) {
        let (Some(a), Some(b), Some(c)) = (self.corner(a), self.corner(b), self.corner(c)) else {
            return;
        };
        if !self.hold(TRIANGLE_BYTES) {
            return;
        }
        if let Some(prim) = self
            .objects
            .last_mut()
            .and_then(|o| o.primitives.get_mut(&self.color))
        {
            prim.triangles.extend_from_slice(&[a, b, c]);
        }
    }

    fn position(&self, v: u64) -> DVec3 {
        self.positions
            .get((v as usize).wrapping_sub(1))
            .copied()
            .unwrap_or(DVec3::ZERO)
    }

    /// Writes the GLB file.
    pub fn write(self, out: &mut dyn Write) -> io::Result<()> {
        if self.over_budget {
            return Err(io::Error::other(format!(
                "the glTF mesh needs more than {} MiB of memory (--max-memory); \
                 write OBJ, which streams, or draw fewer steps",
                self.budget >> 20
            )));
        }
        if self.overflow {
            return Err(io::Error::other(
                "the mesh has more vertices of one colour than glTF's 32-bit indices can number",
            ));
        }
        let (root, bin) = self.document();
        let mut json = root
            .to_vec()
            .map_err(|e| io::Error::other(format!("glTF JSON: {e}")))?;
        while json.len() % 4 != 0 {
            json.push(b' ');
        }
        let mut bin = bin;
        while bin.len() % 4 != 0 {
            bin.push(0);
        }
        let bin_chunk = if bin.is_empty() { 0 } else { 8 + bin.len() };
        let total = 12 + 8 + json.len() + bin_chunk;
        let total = u32::try_from(total)
            .map_err(|_| io::Error::other("the mesh is larger than a GLB file can hold (4 GiB)"))?;
        let mut head = Vec::with_capacity(28);
        head.extend_from_slice(b"glTF");
        head.extend_from_slice(&2u32.to_le_bytes());
        head.extend_from_slice(&total.to_le_bytes());
        head.extend_from_slice(&(json.len() as u32).to_le_bytes());
        head.extend_from_slice(b"JSON");
        out.write_all(&head)?;
        out.write_all(&json)?;
        if !bin.is_empty() {
            out.write_all(&(bin.len() as u32).to_le_bytes())?;
            out.write_all(b"BIN\0")?;
            out.write_all(&bin)?;
        }
        out.flush()
    }

    /// The glTF document and its binary buffer.
    fn document(&self) -> (json::Root, Vec<u8>) {
        let mut root = json::Root {
            asset: json::Asset {
                generator: Some(super::mark::GLTF_GENERATOR.to_string()),
                ..Default::default()
            },
            ..Default::default()
        };
        let colors: BTreeSet<u32> = self
            .objects
            .iter()
            .flat_map(|o| o.primitives.keys().copied())
            .collect();
        let materials: BTreeMap<u32, json::Index<json::Material>> = colors
            .iter()
            .map(|&c| (c, root.push(material(c, &self.palette))))
            .collect();
        let mut bin = Vec::new();
        let buffer = json::Index::<json::Buffer>::new(0);
        let mut nodes = Vec::new();
        for object in &self.objects {
            let mut primitives = Vec::new();
            for (color, prim) in &object.primitives {
                if prim.triangles.is_empty() {
                    continue;
                }
                let positions: Vec<[f32; 3]> = prim
                    .corners
                    .iter()
                    .map(|&(v, _)| self.position(v).as_vec3().to_array())
                    .collect();
                let normals: Vec<[f32; 3]> = prim
                    .corners
                    .iter()
                    .map(|&(_, n)| unit(self.normals.get((n as usize).wrapping_sub(1))))
                    .collect();
                let (min, max) = extent(&positions);
                let p = vec3_accessor(&mut root, &mut bin, buffer, &positions, Some((min, max)));
                let n = vec3_accessor(&mut root, &mut bin, buffer, &normals, None);
                let i = index_accessor(&mut root, &mut bin, buffer, &prim.triangles);
                let mut attributes = BTreeMap::new();
                attributes.insert(Valid(json::mesh::Semantic::Positions), p);
                attributes.insert(Valid(json::mesh::Semantic::Normals), n);
                primitives.push(json::mesh::Primitive {
                    attributes,
                    extensions: None,
                    extras: Default::default(),
                    indices: Some(i),
                    material: materials.get(color).copied(),
                    mode: Valid(json::mesh::Mode::Triangles),
                    targets: None,
                });
            }
            let mesh = (!primitives.is_empty()).then(|| {
                root.push(json::Mesh {
                    extensions: None,
                    extras: Default::default(),
                    name: Some(object.name.clone()),
                    primitives,
                    weights: None,
                })
            });
            nodes.push(root.push(json::Node {
                mesh,
                name: Some(object.name.clone()),
                ..Default::default()
            }));
        }
        if !bin.is_empty() {
            root.push(json::Buffer {
                byte_length: USize64::from(bin.len()),
                extensions: None,
                extras: Default::default(),
                name: None,
                uri: None,
            });
        }
        let scene = root.push(json::Scene {
            extensions: None,
            extras: Default::default(),
            name: None,
            nodes,
        });
        root.scene = Some(scene);
        (root, bin)
    }
}

impl MeshTarget for GlbMesh {
    fn vertex(&mut self, p: DVec3) {
        // Vertices keep their numbers even past the budget (faces refer to
        // them); only their values are dropped.
        if self.hold(VECTOR_BYTES) {
            self.positions.push(p);
        }
    }

    fn normal(&mut self, n: DVec3) {
        if self.hold(VECTOR_BYTES) {
            self.normals.push(n);
        }
    }

    fn face(&mut self, corners: &[(u64, u64)]) {
        match corners.len() {
            0..=2 => {}
            3 => self.triangle(corners[0], corners[1], corners[2]),
            _ => {
                let pts: Vec<DVec3> = corners.iter().map(|&(v, _)| self.position(v)).collect();
                for [a, b, c] in triangulate(&pts) {
                    self.triangle(corners[a], corners[b], corners[c]);
                }
            }
        }
    }

    fn material(&mut self, color: u32) {
        self.color = color;
    }

    fn palette(&mut self, palette: &super::Palette) {
        self.palette = palette.clone();
    }

    fn object(&mut self, name: &str) {
        self.objects.push(Object {
            name: name.to_string(),
            primitives: BTreeMap::new(),
        });
    }
}

/// The material of palette colour `c`.
fn material(c: u32, palette: &super::Palette) -> json::Material {
    let [r, g, b] = palette.linear(c);
    let mut m = json::Material {
        name: Some(palette.material(c)),
        double_sided: true,
        ..Default::default()
    };
    m.pbr_metallic_roughness.base_color_factor =
        json::material::PbrBaseColorFactor([r as f32, g as f32, b as f32, 1.0]);
    m.pbr_metallic_roughness.metallic_factor = json::material::StrengthFactor(0.0);
    m.pbr_metallic_roughness.roughness_factor = json::material::StrengthFactor(0.9);
    m
}

/// A unit normal in f32 (glTF checks the length); +z for a missing or zero one.
fn unit(n: Option<&DVec3>) -> [f32; 3] {
    n.and_then(|n| n.try_normalize())
        .map_or([0.0, 0.0, 1.0], |n| n.as_vec3().normalize().to_array())
}

fn extent(points: &[[f32; 3]]) -> ([f32; 3], [f32; 3]) {
    let mut min = [f32::INFINITY; 3];
    let mut max = [f32::NEG_INFINITY; 3];
    for p in points {
        for k in 0..3 {
            min[k] = min[k].min(p[k]);
            max[k] = max[k].max(p[k]);
        }
    }
    (min, max)
}

/// Appends `bytes` to the buffer as one buffer view (offsets stay 4-aligned:
/// every item is a multiple of 4 bytes).
fn view(
    root: &mut json::Root,
    bin: &mut Vec<u8>,
    buffer: json::Index<json::Buffer>,
    bytes: &[u8],
    target: json::buffer::Target,
) -> json::Index<json::buffer::View> {
    let offset = bin.len();
    bin.extend_from_slice(bytes);
    root.push(json::buffer::View {
        buffer,
        byte_length: USize64::from(bytes.len()),
        byte_offset: Some(USize64::from(offset)),
        byte_stride: None,
        name: None,
        target: Some(Valid(target)),
        extensions: None,
        extras: Default::default(),
    })
}

fn vec3_accessor(
    root: &mut json::Root,
    bin: &mut Vec<u8>,
    buffer: json::Index<json::Buffer>,
    items: &[[f32; 3]],
    bounds: Option<([f32; 3], [f32; 3])>,
) -> json::Index<json::Accessor> {
    let bytes: Vec<u8> = items
        .iter()
        .flat_map(|p| p.iter().flat_map(|x| x.to_le_bytes()))
        .collect();
    let v = view(root, bin, buffer, &bytes, json::buffer::Target::ArrayBuffer);
    let value =
        |a: [f32; 3]| json::Value::from(a.iter().map(|&x| f64::from(x)).collect::<Vec<_>>());
    root.push(json::Accessor {
        buffer_view: Some(v),
        byte_offset: None,
        count: USize64::from(items.len()),
        component_type: Valid(json::accessor::GenericComponentType(
            json::accessor::ComponentType::F32,
        )),
        extensions: None,
        extras: Default::default(),
        type_: Valid(json::accessor::Type::Vec3),
        min: bounds.map(|b| value(b.0)),
        max: bounds.map(|b| value(b.1)),
        name: None,
        normalized: false,
        sparse: None,
    })
}

fn index_accessor(
    root: &mut json::Root,
    bin: &mut Vec<u8>,
    buffer: json::Index<json::Buffer>,
    indices: &[u32],
) -> json::Index<json::Accessor> {
    let bytes: Vec<u8> = indices.iter().flat_map(|i| i.to_le_bytes()).collect();
    let v = view(
        root,
        bin,
        buffer,
        &bytes,
        json::buffer::Target::ElementArrayBuffer,
    );
    root.push(json::Accessor {
        buffer_view: Some(v),
        byte_offset: None,
        count: USize64::from(indices.len()),
        component_type: Valid(json::accessor::GenericComponentType(
            json::accessor::ComponentType::U32,
        )),
        extensions: None,
        extras: Default::default(),
        type_: Valid(json::accessor::Type::Scalar),
        min: None,
        max: None,
        name: None,
        normalized: false,
        sparse: None,
    })
}

/// Triangles (corner indices, in the face's own turning order) covering a
/// simple planar polygon: a fan when it is convex, ear clipping otherwise.
pub fn triangulate(points: &[DVec3]) -> Vec<[usize; 3]> {
    let n = points.len();
    if n < 3 {
        return Vec::new();
    }
    let fan = || (1..n - 1).map(|i| [0, i, i + 1]).collect::<Vec<_>>();
    // The polygon in its own plane, counter-clockwise.
    let mut normal = DVec3::ZERO;
    for i in 0..n {
        normal += points[i].cross(points[(i + 1) % n]);
    }
    let Some(normal) = normal.try_normalize() else {
        return fan();
    };
    let u = normal.any_orthonormal_vector();
    let w = normal.cross(u);
    let flat: Vec<DVec2> = points
        .iter()
        .map(|p| DVec2::new(p.dot(u), p.dot(w)))
        .collect();
    let turn = |a: usize, b: usize, c: usize| (flat[b] - flat[a]).perp_dot(flat[c] - flat[b]);
    if n > MAX_EAR_CLIPPED || (0..n).all(|i| turn(i, (i + 1) % n, (i + 2) % n) >= 0.0) {
        return fan();
    }
    let mut left: Vec<usize> = (0..n).collect();
    let mut out = Vec::with_capacity(n - 2);
    while left.len() > 3 {
        let m = left.len();
        let ear = (0..m).find(|&i| {
            let (a, b, c) = (left[(i + m - 1) % m], left[i], left[(i + 1) % m]);
            turn(a, b, c) > 0.0
                && left.iter().all(|&p| {
                    p == a || p == b || p == c || !inside(flat[p], flat[a], flat[b], flat[c])
                })
        });
        let Some(i) = ear else {
            // Not simple (or rounding): the rest as a fan.
            for k in 1..left.len() - 1 {
                out.push([left[0], left[k], left[k + 1]]);
            }
            return out;
        };
        let m = left.len();
        out.push([left[(i + m - 1) % m], left[i], left[(i + 1) % m]]);
        left.remove(i);
    }
    out.push([left[0], left[1], left[2]]);
    out
}

/// Whether `p` lies in the counter-clockwise triangle a b c (edges included).
fn inside(p: DVec2, a: DVec2, b: DVec2, c: DVec2) -> bool {
    (b - a).perp_dot(p - a) >= 0.0
        && (c - b).perp_dot(p - b) >= 0.0
        && (a - c).perp_dot(p - c) >= 0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area(points: &[DVec3], tris: &[[usize; 3]]) -> f64 {
        tris.iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| points[i]);
                0.5 * (b - a).cross(c - a).length()
            })
            .sum()
    }

    #[test]
    fn concave_polygon_is_ear_clipped_to_its_own_area() {
        // An L shape of area 3, clockwise start at a reflex-sensitive corner.
        let pts: Vec<DVec3> = [(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)]
            .iter()
            .map(|&(x, y)| DVec3::new(x as f64, y as f64, 1.0))
            .collect();
        let tris = triangulate(&pts);
        assert_eq!(tris.len(), 4);
        assert!((area(&pts, &tris) - 3.0).abs() < 1e-12);
        // Same orientation as the polygon: every normal along +z.
        for t in &tris {
            let [a, b, c] = t.map(|i| pts[i]);
            assert!((b - a).cross(c - a).z > 0.0);
        }
    }

    #[test]
    fn convex_polygon_is_a_fan() {
        let pts: Vec<DVec3> = (0..6)
            .map(|i| {
                let t = i as f64 * std::f64::consts::TAU / 6.0;
                DVec3::new(t.cos(), 0.0, t.sin())
            })
            .collect();
        assert_eq!(
            triangulate(&pts),
            vec![[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 5]]
        );
    }
}
