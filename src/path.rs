//! SVG path data, one of each: the parser of an element's `path "…"` (and of
//! any `d` attribute) into a kurbo `BezPath`, with one error that says what is
//! wrong and where, and the flattener of curves into polylines.
//!
//! Owns: reading path data (svgtypes' grammar, made absolute and simple: H/V
//! become lines, S/T explicit curves, arcs cubic curves, as usvg reads them),
//! the flattening rule ([`CURVE_STEPS`] equal parameter steps per curve), the
//! control-point bounds, and the largest closed outline of a path. Every
//! consumer (checker, SVG/PNG/OBJ output, the scene's centre rule) reads path
//! data through [`parse`], so bad data is one error everywhere, never a panic
//! and never a partial drawing. Must not draw, write or know elements.
//!
//! kurbo's own `BezPath::from_svg` is not used to read: its errors carry no
//! position, and its arcs are not the ones usvg (and so `lsyc infer`) draws.

use glam::DVec2;
use kurbo::{BezPath, PathEl, Point};

/// Line pieces per curve (cubic or quadratic) when flattening.
pub const CURVE_STEPS: usize = 8;

/// Why path data could not be read: svgtypes' message (which names the
/// character position) and the byte offset in the data where it went wrong.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{message}")]
pub struct PathError {
    pub message: String,
    /// Byte offset in the path data of the offending character, when known.
    pub offset: Option<usize>,
}

impl PathError {
    fn new(e: svgtypes::Error, d: &str) -> PathError {
        // svgtypes counts characters from 1.
        let at = match &e {
            svgtypes::Error::UnexpectedData(p)
            | svgtypes::Error::InvalidNumber(p)
            | svgtypes::Error::InvalidChar(_, p)
            | svgtypes::Error::InvalidString(_, p) => Some(*p),
            _ => None,
        };
        PathError {
            message: e.to_string(),
            offset: at.and_then(|p| d.char_indices().nth(p.saturating_sub(1)).map(|(b, _)| b)),
        }
    }
}

/// Reads path data into absolute moves, lines, quadratic and cubic curves and
/// closes (each subpath starts with a move).
pub fn parse(d: &str) -> Result<BezPath, PathError> {
    use svgtypes::SimplePathSegment as S;
    let p = |x: f64, y: f64| Point::new(x, y);
    let mut path = BezPath::new();
    for seg in svgtypes::SimplifyingPathParser::from(d) {
        // `push`, not `line_to` and the like: those assert a leading move,
        // which the parser guarantees but bad data must never test.
        path.push(match seg.map_err(|e| PathError::new(e, d))? {
            S::MoveTo { x, y } => PathEl::MoveTo(p(x, y)),
            S::LineTo { x, y } => PathEl::LineTo(p(x, y)),
            S::CurveTo {
                x1,
                y1,
                x2,
                y2,
                x,
                y,
            } => PathEl::CurveTo(p(x1, y1), p(x2, y2), p(x, y)),
            S::Quadratic { x1, y1, x, y } => PathEl::QuadTo(p(x1, y1), p(x, y)),
            S::ClosePath => PathEl::ClosePath,
        });
    }
    Ok(path)
}

fn v(p: Point) -> DVec2 {
    DVec2::new(p.x, p.y)
}

/// The box [minx, miny, maxx, maxy] of every point of the path, control points
/// included, if it has any.
pub fn control_bounds(path: &BezPath) -> Option<[f64; 4]> {
    let mut b = [
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    let mut any = false;
    for el in path.elements() {
        let pts: &[Point] = match el {
            PathEl::MoveTo(a) | PathEl::LineTo(a) => std::slice::from_ref(a),
            PathEl::QuadTo(a, c) => &[*a, *c],
            PathEl::CurveTo(a, c, e) => &[*a, *c, *e],
            PathEl::ClosePath => &[],
        };
        for q in pts {
            any = true;
            b[0] = b[0].min(q.x);
            b[1] = b[1].min(q.y);
            b[2] = b[2].max(q.x);
            b[3] = b[3].max(q.y);
        }
    }
    any.then_some(b)
}

/// One flattened subpath: its points from the move on, and whether a close
/// ended it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Polyline {
    pub points: Vec<DVec2>,
    pub closed: bool,
}

/// The subpaths of `path` as polylines: each curve becomes [`CURVE_STEPS`]
/// pieces of equal parameter steps (its end point included).
pub fn flatten(path: &BezPath) -> Vec<Polyline> {
    flatten_steps(path, CURVE_STEPS)
}

/// [`flatten`] with `steps` pieces a curve (at least one): the same rule and
/// arithmetic, for a caller that has its own count (inference reads drawings
/// with 12).
pub fn flatten_steps(path: &BezPath, steps: usize) -> Vec<Polyline> {
    let mut out: Vec<Polyline> = Vec::new();
    let mut cur = Polyline::default();
    let mut last = DVec2::ZERO;
    let mut start = DVec2::ZERO;
    let mut reopen = false;
    let n = steps.max(1);
    let steps = (1..=n).map(|k| k as f64 / n as f64);
    for el in path.elements() {
        if reopen && !matches!(el, PathEl::MoveTo(_) | PathEl::ClosePath) {
            cur.points.push(start);
        }
        reopen = false;
        match *el {
            PathEl::MoveTo(a) => {
                out.push(std::mem::take(&mut cur));
                last = v(a);
                start = last;
                cur.points.push(last);
            }
            PathEl::LineTo(a) => {
                last = v(a);
                cur.points.push(last);
            }
            PathEl::QuadTo(a, b) => {
                let (p0, p1, p2) = (last, v(a), v(b));
                for t in steps.clone() {
                    let u = 1.0 - t;
                    let (a, b, c) = (u * u, 2.0 * u * t, t * t);
                    cur.points.push(DVec2::new(
                        a * p0.x + b * p1.x + c * p2.x,
                        a * p0.y + b * p1.y + c * p2.y,
                    ));
                }
                last = p2;
            }
            PathEl::CurveTo(a, b, c) => {
                let (p0, p1, p2, p3) = (last, v(a), v(b), v(c));
                for t in steps.clone() {
                    let u = 1.0 - t;
                    let (a, b, c, e) = (u * u * u, 3.0 * u * u * t, 3.0 * u * t * t, t * t * t);
                    cur.points.push(DVec2::new(
                        a * p0.x + b * p1.x + c * p2.x + e * p3.x,
                        a * p0.y + b * p1.y + c * p2.y + e * p3.y,
                    ));
                }
                last = p3;
            }
            PathEl::ClosePath => {
                cur.closed = true;
                out.push(std::mem::take(&mut cur));
                // As in SVG: what follows a close without a move starts a new
                // subpath at the closed one's start.
                last = start;
                reopen = true;
            }
        }
    }
    out.push(cur);
    out.retain(|p| !p.points.is_empty());
    out
}

/// The outline of the subpath of `d` that encloses the most area (every
/// subpath taken as closed), cleaned: no non-finite points, no repeated
/// consecutive points, no closing repeat. `None` when no subpath encloses any
/// area (an open stroke, empty or bad data).
pub fn largest_outline(d: &str) -> Option<Vec<DVec2>> {
    let mut best: Option<(f64, Vec<DVec2>)> = None;
    for sub in flatten(&parse(d).ok()?) {
        let pts = clean_outline(sub.points);
        let area = crate::geometry::signed_area(&pts).abs();
        if pts.len() >= 3 && area > 0.0 && best.as_ref().is_none_or(|b| area > b.0) {
            best = Some((area, pts));
        }
    }
    best.map(|(_, pts)| pts)
}

/// Drops non-finite points, repeated consecutive points and a closing repeat.
pub fn clean_outline(points: Vec<DVec2>) -> Vec<DVec2> {
    let mut out: Vec<DVec2> = Vec::with_capacity(points.len());
    for p in points {
        if p.is_finite() && out.last() != Some(&p) {
            out.push(p);
        }
    }
    while out.len() > 1 && out.first() == out.last() {
        out.pop();
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_say_what_and_where() {
        let e = parse("M0 0 L10 x").unwrap_err();
        assert_eq!(e.offset, Some(9), "{e:?}");
        assert!(e.to_string().contains("position 10"), "{e}");
        let e = parse("M0 0 é 1").unwrap_err();
        assert_eq!(e.offset, Some(5), "{e:?}");
        assert!(parse("").is_ok_and(|p| p.elements().is_empty()));
    }

    #[test]
    fn flattening_and_bounds() {
        let p = parse("M0 0 C0 10 10 10 10 0 Z m 1 1 h 2").expect("reads");
        let subs = flatten(&p);
        assert_eq!(subs.len(), 2);
        assert_eq!(subs[0].points.len(), 1 + CURVE_STEPS);
        assert!(subs[0].closed && !subs[1].closed);
        assert_eq!(subs[1].points, [DVec2::new(1.0, 1.0), DVec2::new(3.0, 1.0)]);
        assert_eq!(control_bounds(&p), Some([0.0, 0.0, 10.0, 10.0]));
        let o = largest_outline("M0 0 L4 0 L4 4 L0 0 M0 0 L1 0 L1 1 Z").expect("area");
        assert_eq!(o.len(), 3);
        assert_eq!(largest_outline("M0 0 L5 5"), None);
        assert_eq!(largest_outline("M0 0 L5 x"), None);
        assert_eq!(flatten_steps(&p, 12)[0].points.len(), 13);
        assert_eq!(flatten_steps(&p, CURVE_STEPS), subs);
    }

    #[test]
    fn a_subpath_after_a_close_starts_where_the_closed_one_started() {
        let p = parse("M1 1 L5 1 L5 5 Z L9 1").expect("reads");
        let subs = flatten(&p);
        assert_eq!(subs.len(), 2);
        assert_eq!(subs[1].points, [DVec2::new(1.0, 1.0), DVec2::new(9.0, 1.0)]);
        assert!(!subs[1].closed);
    }
}
