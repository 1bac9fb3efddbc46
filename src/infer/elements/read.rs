//! The elements of a drawing: every connected drawable of an SVG, in document
//! order, with its exact outline in world coordinates and its style.
//!
//! Owns: what counts as one element (a path, or each group of its subpaths
//! whose bounding boxes overlap: separate shapes in one path are separate
//! elements, a ring's hole stays with its ring), the style key that keeps
//! differently painted shapes apart, and what is skipped (text, images,
//! shapes with no extent), with warnings. usvg resolves groups, `<use>`,
//! transforms and turns rects, circles, ellipses, lines, polylines and
//! polygons into paths. Must not decide which elements are alike.

use crate::infer::svg::{self, Refusal, Seg};
use glam::DVec2;
use usvg::tiny_skia_path::{PathVerb, Transform};

/// Coordinates beyond this (in user units) are refused: usvg works in 32-bit
/// floats, which cannot place such points precisely.
pub const MAX_COORDINATE: f64 = 1.0e7;

/// How an element is painted; elements with different styles never share a kind.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Style {
    /// `#rrggbb`, or `None` for no fill.
    pub fill: Option<String>,
    /// `#rrggbb`, or `None` for no stroke.
    pub stroke: Option<String>,
    /// Stroke width in world units.
    pub width: Option<f64>,
}

impl Style {
    /// The part of the style that must match for two elements to be alike
    /// (widths scale with the element, so they are compared relatively later).
    pub fn key(&self) -> (Option<&str>, Option<&str>) {
        (self.fill.as_deref(), self.stroke.as_deref())
    }
}

/// One element of the drawing.
#[derive(Clone, Debug)]
pub struct Element {
    /// 1-based position in the document, for messages.
    pub number: usize,
    /// The SVG `id` of the shape it came from (may be empty).
    pub id: String,
    /// Its subpaths, exactly, in world coordinates (y up).
    pub subpaths: Vec<Vec<Seg>>,
    /// The subpaths flattened to polylines.
    pub outline: Vec<Vec<DVec2>>,
    pub style: Style,
    pub min: DVec2,
    pub max: DVec2,
    /// The map from the element's own path coordinates to the world, and
    /// which definition it draws: the frame the drawing gives it.
    pub placed: Placed,
}

/// How the drawing placed an element: the affine map from its path's own
/// coordinates to the world (x ↦ (m0·x + m1·y + m2, m3·x + m4·y + m5)), and
/// a key of the path data in those coordinates (with the element's place
/// among the shapes of its path), equal for elements that draw one
/// definition, such as the `<use>`s of one `<path>` or `<symbol>`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placed {
    pub map: [f64; 6],
    pub key: u64,
}

impl Placed {
    /// The map's determinant (negative for a mirror image).
    pub fn det(&self) -> f64 {
        self.map[0] * self.map[4] - self.map[1] * self.map[3]
    }

    /// Whether the map is a similarity (rotation, uniform scale, perhaps a
    /// reflection, and translation), within `tol` of its scale.
    pub fn is_similarity(&self, tol: f64) -> bool {
        let [a, b, _, c, d, _] = self.map;
        let scale = self.det().abs().sqrt();
        if !(scale.is_finite() && scale > 0.0) {
            return false;
        }
        let t = tol * scale;
        if self.det() > 0.0 {
            (a - d).abs() <= t && (b + c).abs() <= t
        } else {
            (a + d).abs() <= t && (b - c).abs() <= t
        }
    }
}

/// The elements of a drawing and what was left out.
#[derive(Debug, Default)]
pub struct Drawing {
    pub elements: Vec<Element>,
    /// One line per skipped thing, for warnings.
    pub skipped: Vec<String>,
    /// The largest coordinate magnitude met.
    pub largest: f64,
}

/// The most subpaths a drawing may have (each path's subpaths are grouped
/// into elements by their boxes).
pub const MAX_SUBPATHS: usize = 2 * super::MAX_ELEMENTS;
/// The most points (curves flattened) all elements may have together.
pub const MAX_POINTS: usize = 4_000_000;
/// The most pairs of subpath boxes compared while grouping subpaths (a sweep
/// compares only boxes that meet along one axis, so a drawing needs this
/// many only if its subpaths overlap each other in crowds).
pub const MAX_BOX_TESTS: u64 = 100_000_000;

/// Reads the elements of an SVG document. The error says why the document
/// is not read, for a message.
pub fn read(data: &[u8]) -> Result<Drawing, Refusal> {
    let tree = svg::parse(data)?;
    from_tree(data, &tree)
}

/// [`read`], from the tree `svg::parse` made of `data` (for a caller that
/// has parsed the document already).
pub fn from_tree(data: &[u8], tree: &usvg::Tree) -> Result<Drawing, Refusal> {
    let mut d = Drawing::default();
    let mut work = Work::default();
    let user = svg::user_space(data, tree);
    // Images and text are reported from the document (see `skipped_in_xml`).
    for (p, t) in svg::paths(tree) {
        path_elements(p, user.pre_concat(t), &mut d, &mut work)?;
    }
    d.skipped.extend(skipped_in_xml(data));
    Ok(d)
}

/// What reading has cost so far, against the limits.
#[derive(Default)]
struct Work {
    subpaths: usize,
    points: usize,
    box_tests: u64,
}

impl Work {
    fn subpaths(&mut self, n: usize) -> Result<(), Refusal> {
        count(&mut self.subpaths, n, MAX_SUBPATHS, "subpaths")
    }

    fn points(&mut self, n: usize) -> Result<(), Refusal> {
        count(&mut self.points, n, MAX_POINTS, "points (curves flattened)")
    }
}

/// Adds `n` to a running count; a refusal once it passes `limit`.
fn count(total: &mut usize, n: usize, limit: usize, what: &'static str) -> Result<(), Refusal> {
    *total = total.saturating_add(n);
    if *total > limit {
        return Err(Refusal::TooMany { what, limit });
    }
    Ok(())
}

/// Text, images and shapes with no size, found in the document itself (usvg
/// drops text without fonts and empty shapes without a word).
fn skipped_in_xml(data: &[u8]) -> Vec<String> {
    let Ok(text) = std::str::from_utf8(data) else {
        return Vec::new();
    };
    let Ok(doc) = usvg::roxmltree::Document::parse(text) else {
        return Vec::new();
    };
    let num = |n: &usvg::roxmltree::Node, a: &str| {
        n.attribute(a).map(|v| {
            v.trim()
                .trim_end_matches("px")
                .parse::<f64>()
                .unwrap_or(f64::NAN)
        })
    };
    // Whether each node is inside a definition (document order visits a
    // parent before its children).
    let slots = doc
        .descendants()
        .map(|n| n.id().get_usize() + 1)
        .max()
        .unwrap_or(0);
    let mut hidden = vec![false; slots];
    let mut out = Vec::new();
    for n in doc.descendants().filter(|n| n.is_element()) {
        let inside = n.parent_element().is_some_and(|p| {
            hidden[p.id().get_usize()]
                || matches!(
                    p.tag_name().name(),
                    "defs" | "symbol" | "clipPath" | "mask" | "pattern" | "marker"
                )
        });
        hidden[n.id().get_usize()] = inside;
        if inside {
            continue;
        }
        let id = id_note(n.attribute("id").unwrap_or(""));
        let zero = |v: Option<f64>| v.is_some_and(|x| x == 0.0);
        match n.tag_name().name() {
            "text" => out.push(format!("a text{id}")),
            "image" => out.push(format!("an image{id}")),
            "rect" if zero(num(&n, "width")) || zero(num(&n, "height")) => {
                out.push(format!("an empty rect{id}"))
            }
            "circle" if zero(num(&n, "r")) => out.push(format!("an empty circle{id}")),
            "ellipse" if zero(num(&n, "rx")) || zero(num(&n, "ry")) => {
                out.push(format!("an empty ellipse{id}"))
            }
            "path" if n.attribute("d").is_none_or(|d| d.trim().is_empty()) => {
                out.push(format!("an empty path{id}"))
            }
            _ => {}
        }
    }
    out
}

fn id_note(id: &str) -> String {
    if id.is_empty() {
        String::new()
    } else {
        format!(" (id `{id}`)")
    }
}

fn color(paint: &usvg::Paint) -> String {
    match paint {
        usvg::Paint::Color(c) => format!("#{:02x}{:02x}{:02x}", c.red, c.green, c.blue),
        // Gradients and patterns are drawn back as a neutral grey.
        _ => "#808080".to_string(),
    }
}

fn bounds(points: impl IntoIterator<Item = DVec2>) -> (DVec2, DVec2) {
    points.into_iter().fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(p), hi.max(p)),
    )
}

fn overlaps(a: &(DVec2, DVec2), b: &(DVec2, DVec2)) -> bool {
    a.0.x <= b.1.x && b.0.x <= a.1.x && a.0.y <= b.1.y && b.0.y <= a.1.y
}

/// The elements of `path`, whose coordinates `t` maps to the document's
/// user space.
fn path_elements(
    path: &usvg::Path,
    t: Transform,
    d: &mut Drawing,
    work: &mut Work,
) -> Result<(), Refusal> {
    if !path.is_visible() {
        return Ok(());
    }
    // The path's own points are fewer than its flattened ones, and its
    // moves count its subpaths: too many is refused before they are built.
    let data = path.data();
    work.points(data.points().len())?;
    let moves = data
        .verbs()
        .iter()
        .filter(|v| **v == PathVerb::Move)
        .count();
    if work.subpaths.saturating_add(moves) > MAX_SUBPATHS {
        return work.subpaths(moves);
    }
    let scale = f64::from((t.sx * t.sy - t.kx * t.ky).abs()).sqrt();
    // World coordinates flip y.
    let map = [t.sx, t.kx, t.tx, -t.ky, -t.sy, -t.ty].map(f64::from);
    let data_key = {
        use std::hash::Hash;
        let mut h = std::hash::DefaultHasher::new();
        data.verbs().len().hash(&mut h);
        for v in data.verbs() {
            (*v as u8).hash(&mut h);
        }
        for p in data.points() {
            (p.x.to_bits(), p.y.to_bits()).hash(&mut h);
        }
        h
    };
    let style = Style {
        fill: path.fill().map(|f| color(f.paint())),
        stroke: path.stroke().map(|s| color(s.paint())),
        width: path
            .stroke()
            .map(|s| f64::from(s.width().get()) * scale)
            .filter(|w| w.is_finite() && *w > 0.0),
    };
    let subs = svg::subpaths(path, t);
    work.subpaths(subs.len())?;
    // Each subpath with its polyline and box.
    type Part = (Vec<Seg>, Vec<DVec2>, (DVec2, DVec2));
    let mut parts: Vec<Part> = Vec::new();
    for sub in subs {
        let flat = svg::flatten(&sub);
        work.points(flat.len())?;
        for p in &flat {
            d.largest = d.largest.max(p.x.abs()).max(p.y.abs());
        }
        if flat.len() < 2 {
            continue;
        }
        let b = bounds(flat.iter().copied());
        parts.push((sub, flat, b));
    }
    if parts.is_empty() {
        return Ok(());
    }
    let boxes: Vec<(DVec2, DVec2)> = parts.iter().map(|p| p.2).collect();
    for (part, members) in overlapping(&boxes, &mut work.box_tests)?
        .into_iter()
        .enumerate()
    {
        let key = {
            use std::hash::{Hash, Hasher};
            let mut h = data_key.clone();
            part.hash(&mut h);
            members.hash(&mut h);
            h.finish()
        };
        let mut subpaths = Vec::new();
        let mut outline = Vec::new();
        for &i in &members {
            subpaths.push(parts[i].0.clone());
            outline.push(parts[i].1.clone());
        }
        let (min, max) = bounds(outline.iter().flatten().copied());
        d.elements.push(Element {
            number: d.elements.len() + 1,
            id: path.id().to_string(),
            subpaths,
            outline,
            style: style.clone(),
            min,
            max,
            placed: Placed { map, key },
        });
    }
    Ok(())
}

/// The groups of `boxes` that overlap, directly or through others (a hole
/// with its ring): each group's members in order, the groups in the order of
/// their first members. A sweep along the axis on which the boxes are
/// shorter compares only boxes that meet on it, and drops a box from the
/// sweep once a later one covers it across the sweep (any box that meets the
/// dropped one meets the later one too, which is in the same group);
/// `tests` counts the comparisons against `MAX_BOX_TESTS`.
fn overlapping(boxes: &[(DVec2, DVec2)], tests: &mut u64) -> Result<Vec<Vec<usize>>, Refusal> {
    let n = boxes.len();
    // Sweep along x unless the boxes are longer in x than in y, in total.
    let (wide, tall) = boxes.iter().fold((0.0, 0.0), |(w, t), b| {
        (w + (b.1.x - b.0.x), t + (b.1.y - b.0.y))
    });
    let (along, across) = if wide <= tall { (0, 1) } else { (1, 0) };
    let lo = |i: usize, axis: usize| boxes[i].0[axis];
    let hi = |i: usize, axis: usize| boxes[i].1[axis];
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| lo(a, along).total_cmp(&lo(b, along)).then(a.cmp(&b)));
    let mut group: Vec<usize> = (0..n).collect();
    fn find(g: &mut [usize], mut i: usize) -> usize {
        while g[i] != i {
            g[i] = g[g[i]];
            i = g[i];
        }
        i
    }
    let mut active: Vec<usize> = Vec::new();
    for &i in &order {
        active.retain(|&j| hi(j, along) >= lo(i, along));
        *tests += active.len() as u64;
        if *tests > MAX_BOX_TESTS {
            return Err(Refusal::Crowded {
                limit: MAX_BOX_TESTS,
            });
        }
        for &j in &active {
            if overlaps(&boxes[i], &boxes[j]) {
                let (a, b) = (find(&mut group, i), find(&mut group, j));
                if a != b {
                    group[a.max(b)] = a.min(b);
                }
            }
        }
        // Covered across the sweep and ending no later: `i` stands for it.
        active.retain(|&j| {
            !(lo(i, across) <= lo(j, across)
                && hi(j, across) <= hi(i, across)
                && hi(j, along) <= hi(i, along))
        });
        active.push(i);
    }
    let mut order: Vec<usize> = Vec::new();
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); n];
    for i in 0..n {
        let r = find(&mut group, i);
        if members[r].is_empty() {
            order.push(r);
        }
        members[r].push(i);
    }
    Ok(order
        .into_iter()
        .map(|r| std::mem::take(&mut members[r]))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn separate_subpaths_split_and_holes_stay() {
        let svg = r##"<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100">
            <path d="M0 0 H10 V10 H0 Z M20 0 H30 V10 H20 Z" fill="#ff0000"/>
            <path id="ring" d="M50 50 m-10 0 a10 10 0 1 0 20 0 a10 10 0 1 0 -20 0 M50 50 m-4 0 a4 4 0 1 0 8 0 a4 4 0 1 0 -8 0" fill="black" fill-rule="evenodd"/>
            <text x="0" y="90">hi</text>
            <rect x="1" y="1" width="5" height="5" stroke="blue" fill="none" stroke-width="2"/>
        </svg>"##;
        let d = read(svg.as_bytes()).expect("reads");
        assert_eq!(d.elements.len(), 4, "{:?}", d.elements);
        assert_eq!(d.elements[0].style.fill.as_deref(), Some("#ff0000"));
        assert_eq!(d.elements[0].max, DVec2::new(10.0, 0.0));
        assert_eq!(d.elements[1].min, DVec2::new(20.0, -10.0));
        assert_eq!(d.elements[2].id, "ring");
        assert_eq!(d.elements[2].subpaths.len(), 2);
        assert_eq!(d.elements[3].style.stroke.as_deref(), Some("#0000ff"));
        assert_eq!(d.elements[3].style.fill, None);
        assert_eq!(d.elements[3].style.width, Some(2.0));
        assert_eq!(d.skipped.len(), 1, "{:?}", d.skipped);
    }
}
