//! Strokes of a sketch: every path, line, polyline or polygon of an SVG, in
//! document order, as a polyline in world coordinates.
//!
//! Owns: the strokes of a sketch read through `svg` (which reads the document
//! safely and gives each path's subpaths in the language's y-up world, curves
//! flattened): one stroke per subpath, numbered in document order for
//! messages, with its element's id and its stroke width in world units, and
//! the limits on strokes and points. Must not decide what a stroke means.

use crate::infer::svg::{self, Refusal, flatten, subpaths, user_space};
use glam::DVec2;
use usvg::Transform;

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
    for (p, t) in svg::paths(&tree) {
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
        assert_eq!(s[2].points.len(), svg::CURVE_STEPS + 1);
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
