//! Choosing between programs inferred from one drawing read in different
//! ways (round kinds turned along the drawing's axes, along their
//! neighbours, out of their ring, along the path through them): the one
//! that writes the fewest numbers among those that put every element where
//! the drawing has it.
//!
//! Owns: a program's description length (`numbers`) and how far the
//! elements it draws are from the drawing's (`misfit`, by deriving and
//! drawing it as `lsyc run` does). Must not infer.

use crate::infer::svg::Seg;
use crate::turtle::Sink;
use glam::{DVec2, DVec3};

/// How many numbers a program writes outside its comments and its
/// elements' outlines: its description length.
pub fn numbers(text: &str) -> usize {
    text.lines()
        .map(str::trim_start)
        .filter(|l| !l.starts_with("//") && !l.starts_with("element") && !l.starts_with("path"))
        .map(literals)
        .sum()
}

/// The number literals on a line: runs of digits and points not inside a
/// name (`P1_N` is a name, not the number 1).
fn literals(line: &str) -> usize {
    let chars: Vec<char> = line.chars().collect();
    let word: fn(char) -> bool = |c| c.is_alphanumeric() || c == '_';
    let (mut i, mut count) = (0, 0);
    while i < chars.len() {
        let run: fn(char) -> bool = if chars[i].is_ascii_digit() {
            count += 1;
            |c| c.is_ascii_digit() || c == '.'
        } else if word(chars[i]) {
            word
        } else {
            i += 1;
            continue;
        };
        while i < chars.len() && run(chars[i]) {
            i += 1;
        }
    }
    count
}

/// The mean distance from each of `places` (the drawing's elements'
/// [`mean_point`]s) to the nearest element the program `text` draws
/// ([`drawn`]); `None` if it does not run or draws another number
/// of elements.
pub fn misfit(text: &str, places: &[DVec2]) -> Option<f64> {
    let drawn = drawn(text)?;
    if drawn.len() != places.len() || places.is_empty() {
        return None;
    }
    let index = crate::geometry::index::PointGrid::new(&drawn);
    let sum: f64 = places
        .iter()
        .map(|&p| {
            let near = index.nearest(p, 1);
            near.first()
                .map_or(f64::INFINITY, |&i| p.distance(drawn[i]))
        })
        .sum();
    Some(sum / places.len() as f64)
}

/// Where the program `text` draws its elements (seed 0): for each, the
/// mean of its outline's points (`path_centroid`), which moves with the
/// outline whichever frame a program gives the element's path.
pub fn drawn(text: &str) -> Option<Vec<DVec2>> {
    let prog = crate::infer::program::compiled(text)?;
    let means = prog
        .elements
        .iter()
        .map(|e| path_centroid(&e.path).unwrap_or(DVec2::ZERO))
        .collect();
    let mut sink = Places {
        means,
        at: Vec::new(),
    };
    crate::infer::program::draw_compiled(&prog, 0, &mut sink)?;
    Some(sink.at)
}

/// [`mean_point`] of SVG path data.
fn path_centroid(d: &str) -> Option<DVec2> {
    use kurbo::PathEl;
    let at = |p: kurbo::Point| DVec2::new(p.x, p.y);
    let path = crate::path::parse(d).ok()?;
    mean_point(path.elements().iter().map(|el| match *el {
        PathEl::MoveTo(a) => Seg::Move(at(a)),
        PathEl::LineTo(a) => Seg::Line(at(a)),
        PathEl::QuadTo(a, c) => Seg::Quad(at(a), at(c)),
        PathEl::CurveTo(a, c, e) => Seg::Cubic(at(a), at(c), at(e)),
        PathEl::ClosePath => Seg::Close,
    }))
}

/// The mean of an outline's points, control points included and each
/// subpath's closing point (its start again) left out: the same for an
/// outline written from any of its points, and the centre of a round one.
pub fn mean_point(segs: impl IntoIterator<Item = Seg>) -> Option<DVec2> {
    let mut points: Vec<DVec2> = Vec::new();
    let mut start = 0;
    for seg in segs {
        match seg {
            Seg::Move(_) => start = points.len(),
            Seg::Close if points.len() > start + 1 && points.last() == points.get(start) => {
                points.pop();
            }
            _ => {}
        }
        points.extend(crate::infer::svg::seg_points(&seg));
    }
    (!points.is_empty()).then(|| crate::geometry::mean(&points))
}

struct Places {
    /// Per element definition: its centroid in its own frame.
    means: Vec<DVec2>,
    at: Vec<DVec2>,
}

impl Sink for Places {
    fn segment(&mut self, _a: DVec3, _b: DVec3, _width: f64, _color: u32) {}
    fn polygon(&mut self, _points: &[DVec3], _color: u32) {}
    fn element(&mut self, i: u16, at: DVec3, h: DVec3, l: DVec3, s: f64, _c: u32) {
        let m = self.means.get(usize::from(i)).copied().unwrap_or_default();
        let p = at + (-l * m.x + h * m.y) * s;
        self.at.push(p.truncate());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_count_what_a_program_writes_not_its_comments_or_outlines() {
        let text = "// 3 rules\nelement A { path \"M0 0 L1 2 Z\"; }\nconst N = 12;\n\
                    lsystem S {\n    derive N + 1;\n    axiom f(2.5)+(90) A;\n}\n";
        assert_eq!(numbers(text), 4);
        let names = "lsystem S {\n    axiom P2(P2_N) f(0.5) Q1;\n}\n";
        assert_eq!(numbers(names), 1);
    }

    #[test]
    fn a_program_drawing_its_elements_elsewhere_misfits() {
        let text = "element A { path \"M0 0 L1 0 L0 1 Z\"; }\n\
                    lsystem S {\n    derive 0;\n    axiom A f(10) A;\n}\n";
        // Each element is where the mean of its outline's points is.
        let o = DVec2::splat(1.0 / 3.0);
        let here = [o, o + DVec2::new(0.0, 10.0)];
        assert!(misfit(text, &here).is_some_and(|m| m < 1e-12));
        let there = [o, o + DVec2::new(0.0, 12.0)];
        assert!(misfit(text, &there).is_some_and(|m| (m - 1.0).abs() < 1e-12));
        assert_eq!(misfit(text, &here[..1]), None);
    }

    #[test]
    fn an_outline_is_placed_by_its_points_whichever_it_starts_from() {
        let square = |start: usize, closing: bool| {
            let pts = [DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y];
            let mut segs = vec![Seg::Move(pts[start])];
            segs.extend((1..4).map(|k| Seg::Line(pts[(start + k) % 4])));
            if closing {
                segs.push(Seg::Line(pts[start]));
            }
            segs.push(Seg::Close);
            mean_point(segs)
        };
        let centre = Some(DVec2::splat(0.5));
        assert_eq!(square(0, false), centre);
        assert_eq!(square(2, true), centre);
        assert_eq!(path_centroid("M0 0 L1 0 L1 1 L0 1 L0 0 Z"), centre);
        assert_eq!(mean_point([]), None);
    }
}
