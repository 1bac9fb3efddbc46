//! Strokes of a sketch: every path, line, polyline or polygon of an SVG, in
//! document order, as a polyline in world coordinates.
//!
//! Owns: reading SVG with usvg (which turns shapes into paths and resolves
//! `<g transform>`, `<use>` and the viewBox), applying each path's absolute
//! transform, flattening curves into points, turning the SVG's y-down user
//! space into the language's y-up world (x, −y), and the stroke width in the
//! same units. Each subpath is a stroke. Must not decide what a stroke means.

use super::svg::{self, Refusal};
use glam::DVec2;
use usvg::tiny_skia_path::{PathSegment, Point, Transform};

/// Points per flattened curve segment.
const CURVE_STEPS: usize = 12;

/// One stroke of the sketch.
#[derive(Clone, Debug)]
pub struct Stroke {
    /// 1-based position among all subpaths of the document, for messages.
    pub number: usize,
    /// The SVG `id` of the element it came from (may be empty).
    pub id: String,
    /// Which subpath of that element (0 for the first).
    pub subpath: usize,
    /// The points, world coordinates (y up), no two consecutive equal.
    pub points: Vec<DVec2>,
    /// Stroke width in world units, if the element has a stroke.
    pub width: Option<f64>,
}

impl Stroke {
    /// How a person finds the stroke in the SVG: "stroke 4 (the path with id `b3`)".
    pub fn describe(&self) -> String {
        let what = if self.id.is_empty() {
            "a path without an id".to_string()
        } else {
            format!("the path with id `{}`", self.id)
        };
        if self.subpath > 0 {
            format!(
                "stroke {} (subpath {} of {what})",
                self.number,
                self.subpath + 1
            )
        } else {
            format!("stroke {} ({what})", self.number)
        }
    }

    pub fn length(&self) -> f64 {
        self.points.windows(2).map(|w| w[0].distance(w[1])).sum()
    }
}

/// The most points (curves flattened) all strokes of a sketch may have together.
pub const MAX_POINTS: usize = 1_000_000;

/// Reads the strokes of an SVG document, at most `max_strokes + 1` of them
/// (so that the caller can tell there are too many without reading them
/// all). Subpaths with no length are skipped (their numbers are not reused).
/// The error says why the document is not read, for a message.
pub fn read(data: &[u8], max_strokes: usize) -> Result<Vec<Stroke>, Refusal> {
    let tree = svg::parse(data)?;
    let mut r = Reader {
        out: Vec::new(),
        number: 0,
        points: 0,
        max_strokes,
    };
    let user = user_space(data, &tree);
    for (p, t) in super::svg::paths(&tree) {
        if !r.path(p, user.pre_concat(t))? {
            break;
        }
    }
    Ok(r.out)
}

fn too_many_points() -> Refusal {
    Refusal::TooMany {
        what: "points (curves flattened)",
        limit: MAX_POINTS,
    }
}

/// The strokes read so far and what they cost.
struct Reader {
    out: Vec<Stroke>,
    number: usize,
    points: usize,
    max_strokes: usize,
}

impl Reader {
    /// Adds the strokes of `path`, whose coordinates `t` maps to the
    /// document's user space; `false` once there are more than enough.
    fn path(&mut self, path: &usvg::Path, t: Transform) -> Result<bool, Refusal> {
        // A width scales with the transform's mean scale factor.
        let scale = f64::from((t.sx * t.sy - t.kx * t.ky).abs()).sqrt();
        let width = path
            .stroke()
            .map(|s| f64::from(s.width().get()) * scale)
            .filter(|w| w.is_finite() && *w > 0.0);
        // The path's own points are fewer than its flattened ones: too many
        // is refused before its subpaths are built.
        if self.points.saturating_add(path.data().points().len()) > MAX_POINTS {
            return Err(too_many_points());
        }
        for (k, sub) in subpaths(path, t).into_iter().enumerate() {
            self.number += 1;
            let points = flatten(&sub);
            if points.len() < 2 {
                continue;
            }
            self.points += points.len();
            if self.points > MAX_POINTS {
                return Err(too_many_points());
            }
            self.out.push(Stroke {
                number: self.number,
                id: path.id().to_string(),
                subpath: k,
                points,
                width,
            });
            if self.out.len() > self.max_strokes {
                return Ok(false);
            }
        }
        Ok(true)
    }
}

/// The map from usvg's coordinates back to the document's user space: usvg
/// puts the root `viewBox` (and a root `transform`) into one group around the
/// content, which the paths' transforms include; lsyc works in user units so that
/// what it draws back lies on the input.
pub fn user_space(data: &[u8], tree: &usvg::Tree) -> Transform {
    let root_group = || match tree.root().children() {
        [usvg::Node::Group(g)] if g.id().is_empty() => g.transform().invert(),
        _ => None,
    };
    let Ok(text) = std::str::from_utf8(data) else {
        return Transform::identity();
    };
    let Ok(doc) = usvg::roxmltree::Document::parse(text) else {
        return Transform::identity();
    };
    let svg = doc.root_element();
    let size = tree.size();
    let moved = svg.attribute("transform").is_some()
        || svg.attribute("viewBox").is_some_and(|v| {
            v.parse::<svgtypes::ViewBox>().is_ok_and(|b| {
                b.x != 0.0
                    || b.y != 0.0
                    || (b.w - f64::from(size.width())).abs() > 1e-9
                    || (b.h - f64::from(size.height())).abs() > 1e-9
            })
        });
    if moved {
        root_group().unwrap_or_default()
    } else {
        Transform::identity()
    }
}

/// One segment of a subpath in world coordinates (y up); each starts where the
/// previous one ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Seg {
    Move(DVec2),
    Line(DVec2),
    Quad(DVec2, DVec2),
    Cubic(DVec2, DVec2, DVec2),
    Close,
}

/// The subpaths of a path in world coordinates (`t`, the map from its own
/// coordinates to the document's user space, applied, and y flipped up),
/// exactly: curves stay curves. A subpath whose points are not all finite is
/// dropped.
pub fn subpaths(path: &usvg::Path, t: Transform) -> Vec<Vec<Seg>> {
    let map = |mut p: Point| {
        t.map_point(&mut p);
        DVec2::new(f64::from(p.x), -f64::from(p.y))
    };
    let mut out: Vec<Vec<Seg>> = Vec::new();
    let mut current: Vec<Seg> = Vec::new();
    for seg in path.data().segments() {
        let s = match seg {
            PathSegment::MoveTo(p) => {
                if !current.is_empty() {
                    out.push(std::mem::take(&mut current));
                }
                Seg::Move(map(p))
            }
            PathSegment::LineTo(p) => Seg::Line(map(p)),
            PathSegment::QuadTo(c, p) => Seg::Quad(map(c), map(p)),
            PathSegment::CubicTo(c1, c2, p) => Seg::Cubic(map(c1), map(c2), map(p)),
            PathSegment::Close => Seg::Close,
        };
        current.push(s);
    }
    if !current.is_empty() {
        out.push(current);
    }
    out.retain(|sub| {
        sub.iter()
            .all(|s| seg_points(s).iter().all(|p| p.is_finite()))
    });
    out
}

/// The points a segment names (controls, then its end).
pub fn seg_points(s: &Seg) -> Vec<DVec2> {
    match *s {
        Seg::Move(p) | Seg::Line(p) => vec![p],
        Seg::Quad(c, p) => vec![c, p],
        Seg::Cubic(a, b, p) => vec![a, b, p],
        Seg::Close => Vec::new(),
    }
}

/// A subpath as a polyline: curves flattened into `CURVE_STEPS` pieces, no two
/// consecutive points equal; a closed subpath ends where it started.
pub fn flatten(sub: &[Seg]) -> Vec<DVec2> {
    let pt = |p: DVec2| kurbo::Point::new(p.x, p.y);
    let mut bez = kurbo::BezPath::new();
    // A subpath that does not begin with a move starts at the origin, which is
    // not one of its points.
    let implicit = !matches!(sub.first(), Some(Seg::Move(_)) | None);
    if implicit {
        bez.move_to(pt(DVec2::ZERO));
    }
    for s in sub {
        match *s {
            Seg::Move(p) => bez.move_to(pt(p)),
            Seg::Line(p) => bez.line_to(pt(p)),
            Seg::Quad(c, p) => bez.quad_to(pt(c), pt(p)),
            Seg::Cubic(c1, c2, p) => bez.curve_to(pt(c1), pt(c2), pt(p)),
            Seg::Close => bez.close_path(),
        }
    }
    // The one flattener, with inference's finer count; then no repeated
    // points, and a closed subpath ends at its start.
    let mut points = Vec::new();
    for (i, line) in crate::path::flatten_steps(&bez, CURVE_STEPS)
        .into_iter()
        .enumerate()
    {
        let first = line.points.first().copied();
        let skip = usize::from(i == 0 && implicit);
        for &p in &line.points[skip..] {
            push(&mut points, p);
        }
        if let (true, Some(f)) = (line.closed, first) {
            push(&mut points, f);
        }
    }
    points
}

/// Appends `p` unless it repeats the last point.
fn push(points: &mut Vec<DVec2>, q: DVec2) {
    if points.last().is_none_or(|l| l.distance(q) > 1e-9) {
        points.push(q);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shapes_transforms_and_curves() {
        let svg = r#"<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100">
            <path id="a" d="M10 90 L10 50" stroke="black" stroke-width="4" fill="none"/>
            <g transform="translate(5 0) scale(2)">
                <polyline id="b" points="5 25 10 20 15 10" stroke="black" fill="none"/>
            </g>
            <line x1="0" y1="0" x2="0" y2="0" stroke="black"/>
            <path d="M0 0 C10 0 10 10 20 10 M30 30 L40 40" stroke="black"/>
        </svg>"#;
        let s = read(svg.as_bytes(), 100).expect("reads");
        assert_eq!(s.len(), 4, "{s:?}");
        assert_eq!(
            s[0].points,
            vec![DVec2::new(10.0, -90.0), DVec2::new(10.0, -50.0)]
        );
        assert_eq!(s[0].width, Some(4.0));
        assert_eq!(s[1].id, "b");
        assert_eq!(s[1].points[0], DVec2::new(15.0, -50.0));
        assert_eq!(s[1].points[2], DVec2::new(35.0, -20.0));
        assert_eq!(s[1].width, Some(2.0));
        // The zero-length line is skipped, but keeps its number.
        assert_eq!(s[2].number, 4);
        assert_eq!(s[2].points.len(), CURVE_STEPS + 1);
        assert_eq!(s[3].subpath, 1);
        assert_eq!(
            s[3].describe(),
            "stroke 5 (subpath 2 of a path without an id)"
        );
    }

    #[test]
    fn not_svg_is_an_error() {
        assert!(read(b"hello", 100).is_err());
        assert!(read(b"<svg", 100).is_err());
    }
}
