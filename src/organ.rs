//! 3D organs and branch contours: the geometry of elements declared with
//! `sphere`, `disk`, `mesh`, `patch` or `contour` instead of a flat `path`.
//!
//! Owns: tessellating spheres, disks and bicubic Bézier patches into triangle
//! meshes, reading Wavefront OBJ text into one, and turning contour path data
//! into a closed profile. Every mesh is in the element's local frame: x along
//! −L, y along H, z along U (the frame the turtle places it in).
//! Must not read files (the caller hands over text) or know output formats.

use glam::{DVec2, DVec3};

/// A triangle mesh in an element's local frame. A corner is (point index,
/// normal index); normals are unit length; triangles are counter-clockwise
/// seen from the side their normals point to.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Solid {
    pub points: Vec<DVec3>,
    pub normals: Vec<DVec3>,
    pub triangles: Vec<[(u32, u32); 3]>,
}

impl Solid {
    /// [min, max] of the points.
    pub fn bounds(&self) -> Option<(DVec3, DVec3)> {
        let first = *self.points.first()?;
        Some(
            self.points
                .iter()
                .fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p))),
        )
    }

    fn push(&mut self, p: DVec3, n: DVec3) -> u32 {
        self.points.push(p);
        self.normals.push(n.try_normalize().unwrap_or(DVec3::Y));
        (self.points.len() - 1) as u32
    }

    fn tri(&mut self, a: u32, b: u32, c: u32) {
        self.triangles.push([(a, a), (b, b), (c, c)]);
    }
}

/// Bands from pole to pole and vertices around of a sphere organ.
const SPHERE_BANDS: usize = 6;
const SPHERE_AROUND: usize = 12;
/// Vertices around a disk.
const DISK_AROUND: usize = 24;
/// Grid cells along each side of a tessellated patch.
const PATCH_CELLS: usize = 8;
/// The most triangles a mesh file may hold.
pub const MAX_MESH_TRIANGLES: usize = 1_000_000;

/// A sphere of radius `r` centred on the turtle (cpfg's `@O`).
pub fn sphere(r: f64) -> Solid {
    let mut s = Solid::default();
    let north = s.push(DVec3::Y * r, DVec3::Y);
    let mut rings = Vec::new();
    for j in 1..SPHERE_BANDS {
        let phi = std::f64::consts::PI * j as f64 / SPHERE_BANDS as f64;
        let (sp, cp) = phi.sin_cos();
        let ring: Vec<u32> = (0..SPHERE_AROUND)
            .map(|i| {
                let t = std::f64::consts::TAU * i as f64 / SPHERE_AROUND as f64;
                let d = DVec3::new(sp * t.cos(), cp, -sp * t.sin());
                s.push(d * r, d)
            })
            .collect();
        rings.push(ring);
    }
    let south = s.push(DVec3::NEG_Y * r, DVec3::NEG_Y);
    let k = SPHERE_AROUND;
    for i in 0..k {
        let j = (i + 1) % k;
        s.tri(north, rings[0][i], rings[0][j]);
        for b in 0..rings.len() - 1 {
            let (a, c) = (&rings[b], &rings[b + 1]);
            let (ai, aj, ci, cj) = (a[i], a[j], c[i], c[j]);
            s.tri(ai, ci, cj);
            s.tri(ai, cj, aj);
        }
        let last = &rings[rings.len() - 1];
        let (li, lj) = (last[i], last[j]);
        s.tri(south, lj, li);
    }
    s
}

/// A disk of radius `r` centred on the turtle, across the heading: it lies in
/// the L–U plane and faces along H (cpfg's `@o`).
pub fn disk(r: f64) -> Solid {
    let mut s = Solid::default();
    let c = s.push(DVec3::ZERO, DVec3::Y);
    let rim: Vec<u32> = (0..DISK_AROUND)
        .map(|i| {
            let t = std::f64::consts::TAU * i as f64 / DISK_AROUND as f64;
            s.push(DVec3::new(t.cos() * r, 0.0, -t.sin() * r), DVec3::Y)
        })
        .collect();
    for i in 0..DISK_AROUND {
        s.tri(c, rim[i], rim[(i + 1) % DISK_AROUND]);
    }
    s
}

/// Reads the numbers of a `patch` property: whitespace or commas between them.
pub fn patch_numbers(text: &str) -> Result<Vec<f64>, String> {
    text.split(|c: char| c.is_whitespace() || c == ',')
        .filter(|w| !w.is_empty())
        .map(|w| {
            w.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| format!("`{w}` is not a number"))
        })
        .collect()
}

/// Bicubic Bézier patches (cpfg's `~` surfaces): every 48 numbers are the 16
/// control points (x y z) of one patch, row by row (u along a row, v from row
/// to row), tessellated into a grid with the surface's own normals.
pub fn patches(numbers: &[f64]) -> Solid {
    let mut s = Solid::default();
    for ctrl in numbers.chunks_exact(48) {
        let p: Vec<DVec3> = ctrl
            .chunks_exact(3)
            .map(|c| DVec3::new(c[0], c[1], c[2]))
            .collect();
        let n = PATCH_CELLS;
        let first = s.points.len() as u32;
        for j in 0..=n {
            for i in 0..=n {
                let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                let (pt, du, dv) = bezier_patch(&p, u, v);
                let normal = du
                    .cross(dv)
                    .try_normalize()
                    .or_else(|| {
                        // At a collapsed edge, step inside the patch.
                        let (_, du, dv) =
                            bezier_patch(&p, u.clamp(0.01, 0.99), v.clamp(0.01, 0.99));
                        du.cross(dv).try_normalize()
                    })
                    .unwrap_or(DVec3::Z);
                s.push(pt, normal);
            }
        }
        let at = |i: usize, j: usize| first + (j * (n + 1) + i) as u32;
        for j in 0..n {
            for i in 0..n {
                s.tri(at(i, j), at(i + 1, j), at(i + 1, j + 1));
                s.tri(at(i, j), at(i + 1, j + 1), at(i, j + 1));
            }
        }
    }
    s
}

/// The cubic Bernstein weights and their derivatives at `t`.
fn bernstein(t: f64) -> ([f64; 4], [f64; 4]) {
    let m = 1.0 - t;
    (
        [m * m * m, 3.0 * t * m * m, 3.0 * t * t * m, t * t * t],
        [
            -3.0 * m * m,
            3.0 * m * m - 6.0 * t * m,
            6.0 * t * m - 3.0 * t * t,
            3.0 * t * t,
        ],
    )
}

/// A point of the patch and its partial derivatives along u and v.
fn bezier_patch(p: &[DVec3], u: f64, v: f64) -> (DVec3, DVec3, DVec3) {
    let (bu, du) = bernstein(u);
    let (bv, dv) = bernstein(v);
    let (mut pt, mut pu, mut pv) = (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
    for j in 0..4 {
        for i in 0..4 {
            let c = p[j * 4 + i];
            pt += c * (bu[i] * bv[j]);
            pu += c * (du[i] * bv[j]);
            pv += c * (bu[i] * dv[j]);
        }
    }
    (pt, pu, pv)
}

/// Why a mesh file does not read: the line (1-based) and what is wrong.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshError {
    pub line: usize,
    pub message: String,
}

/// Reads Wavefront OBJ text: `v`, `vn` and `f` lines (corners `v`, `v/t`,
/// `v//n`, `v/t/n`, negative indices counting back); other lines are skipped.
/// Faces of more than three corners are split into fans; corners without a
/// normal take their face's.
pub fn parse_obj(text: &str) -> Result<Solid, MeshError> {
    let mut s = Solid::default();
    let mut normals: Vec<DVec3> = Vec::new();
    // Each face: its line, and its corners (vertex, normal if given).
    type Face = (usize, Vec<(u32, Option<u32>)>);
    let mut faces: Vec<Face> = Vec::new();
    for (k, line) in text.lines().enumerate() {
        let line_no = k + 1;
        let err = |message: String| MeshError {
            line: line_no,
            message,
        };
        let mut words = line.split_whitespace();
        let Some(tag) = words.next() else { continue };
        let nums = |words: std::str::SplitWhitespace| -> Result<DVec3, MeshError> {
            let v: Vec<f64> = words
                .take(3)
                .map(|w| w.parse::<f64>().ok().filter(|v| v.is_finite()))
                .collect::<Option<_>>()
                .ok_or_else(|| {
                    err(format!(
                        "`{}` has a coordinate that is not a number",
                        line.trim()
                    ))
                })?;
            if v.len() < 3 {
                return Err(err(format!("`{}` needs three coordinates", line.trim())));
            }
            Ok(DVec3::new(v[0], v[1], v[2]))
        };
        match tag {
            "v" => s.points.push(nums(words)?),
            "vn" => normals.push(nums(words)?.try_normalize().unwrap_or(DVec3::Y)),
            "f" => {
                let mut corners = Vec::new();
                for w in words {
                    let mut parts = w.split('/');
                    let index = |part: Option<&str>,
                                 count: usize|
                     -> Result<Option<u32>, MeshError> {
                        let Some(t) = part.filter(|t| !t.is_empty()) else {
                            return Ok(None);
                        };
                        let i: i64 = t
                            .parse()
                            .map_err(|_| err(format!("`{w}` is not a face corner")))?;
                        let resolved = if i < 0 { count as i64 + i } else { i - 1 };
                        if i == 0 || resolved < 0 || resolved >= count as i64 {
                            return Err(err(format!(
                                "the index {i} in `{w}` is out of range (there are {count} so far)"
                            )));
                        }
                        Ok(Some(resolved as u32))
                    };
                    let v = index(parts.next(), s.points.len())?
                        .ok_or_else(|| err(format!("`{w}` has no vertex index")))?;
                    let _texture = parts.next();
                    let n = index(parts.next(), normals.len())?;
                    corners.push((v, n));
                }
                if corners.len() < 3 {
                    return Err(err("a face needs at least three corners".to_string()));
                }
                faces.push((line_no, corners));
            }
            _ => {}
        }
    }
    if faces.is_empty() {
        return Err(MeshError {
            line: text.lines().count().max(1),
            message: "the file has no faces (`f` lines)".to_string(),
        });
    }
    s.normals = normals;
    for (line, corners) in faces {
        let p = |c: &(u32, Option<u32>)| s.points[c.0 as usize];
        let mut area = DVec3::ZERO;
        for i in 0..corners.len() {
            area += p(&corners[i]).cross(p(&corners[(i + 1) % corners.len()]));
        }
        let own = area.try_normalize().unwrap_or(DVec3::Y);
        let mut face_normal = None;
        let mut resolved = Vec::with_capacity(corners.len());
        for c in &corners {
            let n = match c.1 {
                Some(n) => n,
                None => *face_normal.get_or_insert_with(|| {
                    s.normals.push(own);
                    (s.normals.len() - 1) as u32
                }),
            };
            resolved.push((c.0, n));
        }
        for i in 1..resolved.len() - 1 {
            s.triangles
                .push([resolved[0], resolved[i], resolved[i + 1]]);
            if s.triangles.len() > MAX_MESH_TRIANGLES {
                return Err(MeshError {
                    line,
                    message: format!("more than {MAX_MESH_TRIANGLES} triangles"),
                });
            }
        }
    }
    Ok(s)
}

/// The most points a contour keeps (after flattening its curves).
pub const MAX_CONTOUR_POINTS: usize = 256;

/// A branch contour from SVG path data: the first subpath, flattened, without
/// a repeated closing point, counter-clockwise. `Err` says why it is no contour.
pub fn contour_from_path(d: &str) -> Result<Vec<DVec2>, String> {
    let path = crate::path::parse(d).map_err(|e| e.to_string())?;
    let mut pts: Vec<DVec2> = Vec::new();
    // Only the first subpath: later moves end it.
    let mut moves = 0;
    kurbo::flatten(path.iter(), 0.01, |el| match el {
        kurbo::PathEl::MoveTo(p) => {
            moves += 1;
            if moves == 1 {
                pts.push(DVec2::new(p.x, p.y));
            }
        }
        kurbo::PathEl::LineTo(p) if moves == 1 && pts.len() <= MAX_CONTOUR_POINTS => {
            let q = DVec2::new(p.x, p.y);
            if pts.last() != Some(&q) {
                pts.push(q);
            }
        }
        _ => {}
    });
    while pts.len() > 1 && pts.first() == pts.last() {
        pts.pop();
    }
    if pts.len() > MAX_CONTOUR_POINTS {
        return Err(format!("more than {MAX_CONTOUR_POINTS} points"));
    }
    if pts.len() < 3 {
        return Err("a contour needs at least three points".to_string());
    }
    let area: f64 = (0..pts.len())
        .map(|i| pts[i].perp_dot(pts[(i + 1) % pts.len()]))
        .sum::<f64>()
        * 0.5;
    if area.abs() <= 1e-12 || area.is_nan() {
        return Err("the contour encloses no area".to_string());
    }
    if area < 0.0 {
        pts.reverse();
    }
    Ok(pts)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn valid(s: &Solid) {
        assert!(!s.triangles.is_empty());
        for t in &s.triangles {
            for &(p, n) in t {
                assert!((p as usize) < s.points.len());
                assert!((n as usize) < s.normals.len());
            }
        }
        for n in &s.normals {
            assert!((n.length() - 1.0).abs() < 1e-9, "{n}");
        }
    }

    #[test]
    fn shapes_are_valid_meshes() {
        valid(&sphere(2.0));
        valid(&disk(1.0));
        let flat: Vec<f64> = (0..16)
            .flat_map(|k| [(k % 4) as f64, (k / 4) as f64, 0.0])
            .collect();
        let p = patches(&flat);
        valid(&p);
        // A flat patch in the x–y plane faces +z.
        assert!(p.normals.iter().all(|n| (n.z - 1.0).abs() < 1e-9));
        let (lo, hi) = sphere(2.0).bounds().unwrap();
        assert!(
            (lo + DVec3::splat(2.0)).length() < 1e-9 && (hi - DVec3::splat(2.0)).length() < 1e-9
        );
    }

    #[test]
    fn obj_text_reads_with_fans_and_negative_indices() {
        let s = parse_obj("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf -4 -3 -2 -1\n").unwrap();
        valid(&s);
        assert_eq!(s.triangles.len(), 2);
        assert_eq!(s.normals, vec![DVec3::Z]);
        let e = parse_obj("v 0 0 0\nf 1 2 3\n").unwrap_err();
        assert_eq!(e.line, 2);
        assert!(parse_obj("v 0 0 x\n").is_err());
        assert!(parse_obj("v 0 0 0\n").is_err());
    }

    #[test]
    fn contours_are_counter_clockwise() {
        let c = contour_from_path("M0 0 L0 1 L1 0 Z").unwrap();
        assert_eq!(c.len(), 3);
        let area: f64 = (0..3).map(|i| c[i].perp_dot(c[(i + 1) % 3])).sum();
        assert!(area > 0.0);
        assert!(contour_from_path("M0 0 L1 1").is_err());
    }
}
