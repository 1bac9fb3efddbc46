//! Output formats, chosen by the file extension: SVG, PNG, OBJ (with MTL), glTF binary and text.
//!
//! Owns: the view (2D programs are drawn in the x–y plane; 3D programs are
//! projected from an oblique camera, `--view`), the colour palette of `'(c)`, and the
//! fitting of drawings into a viewport. Each format is a `turtle::Sink` or a
//! writer of the module string; none of them derives.

pub mod glb;
pub mod mark;
pub mod obj;
pub mod png;
pub mod svg;
pub mod txt;

use crate::turtle::Sink;
use glam::{DMat3, DVec2, DVec3};

/// The colours of `'(0)`, `'(1)`, …; indices wrap around. Index 0 is ink; 1–7
/// go from bark through darker to lighter greens, so that a bare `'` (the next
/// colour) moves a plant from wood to leaf as in ABOP; 8–11 are flower colours.
pub const PALETTE: &[&str] = &[
    "#263238", "#4e342e", "#6d4c41", "#33691e", "#558b2f", "#689f38", "#7cb342", "#9ccc65",
    "#c62828", "#f9a825", "#1565c0", "#6a1b9a",
];

pub fn palette(i: u32) -> &'static str {
    PALETTE[i as usize % PALETTE.len()]
}

/// RGB of a palette entry.
pub fn palette_rgb(i: u32) -> [u8; 3] {
    parse_hex(palette(i)).unwrap_or([0, 0, 0])
}

/// A palette entry in linear RGB, 0–1 (what glTF's base colour and the MTL
/// `Kd` hold): the sRGB transfer function undone.
pub fn palette_linear(i: u32) -> [f64; 3] {
    palette_rgb(i).map(|c| {
        let s = f64::from(c) / 255.0;
        if s <= 0.04045 {
            s / 12.92
        } else {
            ((s + 0.055) / 1.055).powf(2.4)
        }
    })
}

/// The colours of a drawing: the program's `palette` where it gives an index,
/// the built-in [`PALETTE`] elsewhere; and the material name of each colour
/// in OBJ, MTL and glTF (the palette's name, else `lsyc_color<c>`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Palette {
    colors: Vec<crate::compile::PaletteColor>,
}

impl Palette {
    /// The palette of a program (the built-in one when it has none).
    pub fn of(prog: &crate::compile::Program) -> Palette {
        Palette {
            colors: prog.palette.clone(),
        }
    }

    fn own(&self, i: u32) -> Option<&crate::compile::PaletteColor> {
        self.colors
            .binary_search_by_key(&i, |c| c.index)
            .ok()
            .map(|k| &self.colors[k])
    }

    pub fn rgb(&self, i: u32) -> [u8; 3] {
        self.own(i).map_or_else(|| palette_rgb(i), |c| c.rgb)
    }

    /// `#rrggbb`.
    pub fn hex(&self, i: u32) -> String {
        hex(self.rgb(i))
    }

    /// In linear RGB, 0–1 (glTF's base colour, the MTL `Kd`).
    pub fn linear(&self, i: u32) -> [f64; 3] {
        self.rgb(i).map(|c| {
            let s = f64::from(c) / 255.0;
            if s <= 0.04045 {
                s / 12.92
            } else {
                ((s + 0.055) / 1.055).powf(2.4)
            }
        })
    }

    /// The material name of colour `i`.
    pub fn material(&self, i: u32) -> String {
        self.own(i)
            .and_then(|c| c.name.clone())
            .unwrap_or_else(|| obj::material_name(i))
    }
}

/// `#rrggbb` to RGB.
pub fn parse_hex(s: &str) -> Option<[u8; 3]> {
    let h = s.strip_prefix('#')?;
    if h.len() != 6 {
        return None;
    }
    let v = u32::from_str_radix(h, 16).ok()?;
    Some([(v >> 16) as u8, (v >> 8) as u8, v as u8])
}

/// The default camera of 3D programs: azimuth and elevation in degrees.
pub const DEFAULT_VIEW: [f64; 2] = [30.0, 20.0];

/// How 3D points become 2D drawing coordinates (+y up).
#[derive(Clone, Copy, Debug)]
pub struct View {
    m: DMat3,
}

impl View {
    /// The x–y plane for 2D programs; for 3D programs an oblique view (turned
    /// 30° about the vertical, tilted 20°) so that depth shows.
    pub fn new(is_3d: bool) -> View {
        if is_3d {
            View::oblique(DEFAULT_VIEW[0], DEFAULT_VIEW[1])
        } else {
            View { m: DMat3::IDENTITY }
        }
    }

    /// A 3D program seen from `azimuth` degrees about the vertical (+y) axis
    /// and `elevation` degrees above the horizon: the camera of `--view`.
    /// `new(true)` is `oblique(30, 20)`.
    pub fn oblique(azimuth: f64, elevation: f64) -> View {
        let yaw = DMat3::from_rotation_y(azimuth.to_radians());
        let tilt = DMat3::from_rotation_x(elevation.to_radians());
        View { m: tilt * yaw }
    }

    pub fn project(&self, p: DVec3) -> DVec2 {
        let q = self.m * p;
        DVec2::new(q.x, q.y)
    }

    pub fn project_dir(&self, v: DVec3) -> DVec2 {
        self.project(v)
    }

    /// How far toward the viewer `p` is (larger is nearer).
    pub fn depth(&self, p: DVec3) -> f64 {
        (self.m * p).z
    }

    /// A direction in camera space (x right, y up, z toward the viewer).
    pub fn camera_dir(&self, v: DVec3) -> DVec3 {
        self.m * v
    }
}

/// One triangle of a 3D organ as a picture paints it: projected corners and a
/// flat-shaded colour.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Facet {
    pub points: [DVec2; 3],
    pub rgb: [u8; 3],
}

/// The light of organ pictures, in camera space: from the upper left, in front.
const LIGHT: DVec3 = DVec3::new(-0.372_104_203, 0.558_156_305, 0.744_208_407);

/// The facets of an organ placed at `at` with frame H, L (U = H × L) and
/// `scale`, as `view` sees them, in painter's order (farthest first, by each
/// triangle's centroid); each is `base` shaded by the angle between its normal
/// and the light (both sides lit alike). The SVG and PNG writers paint exactly
/// these, so the two pictures agree.
pub fn organ_facets(
    solid: &crate::organ::Solid,
    frame: (DVec3, DVec3, DVec3, f64),
    view: &View,
    base: [u8; 3],
) -> Vec<Facet> {
    let (at, h, l, scale) = frame;
    let u = h.cross(l);
    let world = |p: DVec3| at + (-l * p.x + h * p.y + u * p.z) * scale;
    let mut out: Vec<(f64, Facet)> = Vec::with_capacity(solid.triangles.len());
    for t in &solid.triangles {
        let ps = t.map(|(p, _)| world(solid.points[p as usize]));
        if !ps.iter().all(|p| p.is_finite()) {
            continue;
        }
        let n: DVec3 = t.iter().map(|&(_, n)| solid.normals[n as usize]).sum();
        let n = view.camera_dir(-l * n.x + h * n.y + u * n.z);
        let lit = n.try_normalize().map_or(1.0, |n| n.dot(LIGHT).abs());
        let k = 0.45 + 0.55 * lit;
        let rgb = base.map(|c| (f64::from(c) * k).round().clamp(0.0, 255.0) as u8);
        let depth = ps.iter().map(|&p| view.depth(p)).sum::<f64>() / 3.0;
        out.push((
            depth,
            Facet {
                points: ps.map(|p| view.project(p)),
                rgb,
            },
        ));
    }
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    out.into_iter().map(|(_, f)| f).collect()
}

/// The colour an organ is painted in: its element's `fill`, else the turtle's.
pub fn organ_color(fill: Option<&str>, color: u32, palette: &Palette) -> [u8; 3] {
    fill.and_then(png::parse_color)
        .unwrap_or_else(|| palette.rgb(color))
}

/// `#rrggbb` of RGB.
pub fn hex(rgb: [u8; 3]) -> String {
    format!("#{:02x}{:02x}{:02x}", rgb[0], rgb[1], rgb[2])
}

/// Bounds of drawn geometry as seen by a view.
#[derive(Clone, Copy, Debug)]
pub struct Bounds {
    pub min: DVec2,
    pub max: DVec2,
    pub any: bool,
}

impl Default for Bounds {
    fn default() -> Bounds {
        Bounds {
            min: DVec2::splat(f64::INFINITY),
            max: DVec2::splat(f64::NEG_INFINITY),
            any: false,
        }
    }
}

impl Bounds {
    pub fn add(&mut self, p: DVec2) {
        if p.is_finite() {
            self.min = self.min.min(p);
            self.max = self.max.max(p);
            self.any = true;
        }
    }

    /// A non-degenerate box with a margin, or a unit box around the origin.
    pub fn framed(&self, margin: f64) -> (DVec2, DVec2) {
        if !self.any {
            return (DVec2::splat(-1.0), DVec2::splat(1.0));
        }
        let size = (self.max - self.min).max(DVec2::splat(1e-9));
        let extent = size.x.max(size.y);
        let pad = DVec2::splat(extent * margin);
        let mut min = self.min - pad;
        let mut max = self.max + pad;
        // Lines of zero extent in one direction still get some room.
        for k in 0..2 {
            if max[k] - min[k] < extent * 0.02 {
                min[k] -= extent * 0.01;
                max[k] += extent * 0.01;
            }
        }
        (min, max)
    }
}

/// Collects the projected bounds of everything drawn, elements included.
pub struct BoundsSink<'a> {
    pub view: View,
    pub bounds: Bounds,
    /// Each element's box in its own frame (`turtle::element_box`).
    pub element_boxes: &'a [Option<(DVec3, DVec3)>],
}

impl Sink for BoundsSink<'_> {
    fn segment(&mut self, a: DVec3, b: DVec3, _: f64, _: u32) {
        self.bounds.add(self.view.project(a));
        self.bounds.add(self.view.project(b));
    }

    fn polygon(&mut self, points: &[DVec3], _: u32) {
        for &p in points {
            self.bounds.add(self.view.project(p));
        }
    }

    fn element(&mut self, index: u16, at: DVec3, h: DVec3, l: DVec3, scale: f64, _: u32) {
        let Some(&Some(b)) = self.element_boxes.get(index as usize) else {
            self.bounds.add(self.view.project(at));
            return;
        };
        let u = h.cross(l);
        for c in crate::turtle::corners(b) {
            let p = at + (-l * c.x + h * c.y + u * c.z) * scale;
            self.bounds.add(self.view.project(p));
        }
    }
}

/// The bounding box of SVG path data in its own coordinates (control points
/// included), if it reads and has points.
pub fn path_bounds(d: &str) -> Option<[f64; 4]> {
    crate::path::control_bounds(&crate::path::parse(d).ok()?)
}
