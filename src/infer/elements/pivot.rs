//! Where a kind's local frame goes when the drawing does not say: the
//! origin and heading a person would give the element, chosen by the
//! simplicity of the rules they make.
//!
//! Owns: the candidates for a kind's origin — where the pen went down (the
//! path's start), where an open stroke ends, the two ends of the principal
//! axis, and the centroid — and for its heading: the one that makes the
//! dominant repetition a plain `f(step) +(angle)` (no turn before the step),
//! the one with no turn after it, and "standing up" (from the origin towards
//! the centroid, or along the principal axis). Each candidate is scored on
//! the transform that repeats most between neighbours of the kind (the
//! largest cluster of their transforms): fewest turns that are not zero,
//! then the fewest digits its numbers need, then the order above (the pen's
//! start first, standing up first). Kinds whose frames the drawing gives,
//! mirror kinds and symmetric kinds' origins (their centre) are left alone;
//! a kind whose origin `origin` found (the point a changing turn pivots
//! about) keeps it and only turns. Must not decide rules.

use super::rules::Tolerance;
use super::shape::{Frame, Instancing, wrap};
use super::space::{Point, Tr, cluster};
use crate::geometry::index::PointGrid;
use crate::infer::svg::Seg;
use glam::DVec2;

/// Neighbours of the same kind compared per instance.
const NEIGHBOURS: usize = 2;

/// Chooses the local frame of each kind the drawing gives none;
/// `fixed[k]`: kind `k`'s origin is already found (only its heading is
/// chosen).
pub fn choose(inst: &mut Instancing, fixed: &[bool], tol: Tolerance) {
    for k in 0..inst.kinds.len() {
        let kind = &inst.kinds[k];
        if kind.given || kind.mirror_of.is_some() {
            continue;
        }
        let members: Vec<usize> = (0..inst.of.len()).filter(|&i| inst.of[i].0 == k).collect();
        let frame = kind.frame;
        let sh = &inst.shapes[kind.representative];
        let outline: Vec<DVec2> = sh
            .samples
            .iter()
            .map(|p| frame.local(sh.centroid + *p))
            .collect();
        let lines: Vec<Vec<DVec2>> = sh
            .outline
            .iter()
            .map(|l| l.iter().map(|p| frame.local(sh.centroid + *p)).collect())
            .collect();
        let centroid = frame.local(sh.centroid);
        let origins = if kind.symmetry != 1 {
            vec![DVec2::ZERO]
        } else if fixed.get(k).copied().unwrap_or(false) {
            // The pivot found, or a candidate within the noise of it.
            let near = sh.radius / frame.scale * 0.02;
            let mut near: Vec<DVec2> = origins(&kind.subpaths, &frame, &lines, &outline, centroid)
                .into_iter()
                .filter(|o| o.length() <= near)
                .collect();
            near.push(DVec2::ZERO);
            near
        } else {
            origins(&kind.subpaths, &frame, &lines, &outline, centroid)
        };
        // Neighbours by centroid, which no choice of frame moves, each pair
        // in the drawing's order (a grammar draws a parent before its
        // children and a sequence from its start).
        let centres: Vec<DVec2> = members.iter().map(|&i| inst.shapes[i].centroid).collect();
        let grid = PointGrid::new(&centres);
        let mut pairs: Vec<(usize, usize)> = Vec::new();
        for (a, c) in centres.iter().enumerate() {
            for b in grid.nearest(*c, NEIGHBOURS + 1) {
                if a < b {
                    pairs.push((members[a], members[b]));
                } else if b < a && !grid.nearest(centres[b], NEIGHBOURS + 1).contains(&a) {
                    pairs.push((members[b], members[a]));
                }
            }
        }
        let changing = fixed.get(k).copied().unwrap_or(false);
        let mut best: Option<(Score, Frame)> = None;
        for (n, &o) in origins.iter().enumerate() {
            let change = Frame {
                pos: o,
                ..Frame::IDENTITY
            };
            // A symmetric element stands as drawn.
            let up = if kind.symmetry == 1 {
                standing(o, centroid, &outline)
            } else {
                0.0
            };
            let mut headings = vec![up];
            let repeated = if changing {
                // A changing turn: the transforms agree but for the turn
                // that changes; the heading takes the other one to zero.
                let before = repeated(inst, &pairs, &change, sh.radius, tol, Some(0));
                let after = repeated(inst, &pairs, &change, sh.radius, tol, Some(3));
                let size = |r: &[(Tr, usize)]| r.first().map_or(0, |c| c.1);
                if size(&before) >= size(&after) {
                    headings.extend(before.iter().map(|(t, _)| -t.beta));
                    before
                } else {
                    headings.extend(after.iter().map(|(t, _)| t.alpha));
                    after
                }
            } else {
                let r = repeated(inst, &pairs, &change, sh.radius, tol, None);
                for (t, _) in &r {
                    headings.push(t.alpha);
                    headings.push(-t.beta);
                }
                r
            };
            for (h, &phi) in headings.iter().enumerate() {
                let (mut turns, mut digits_) = (0, 0);
                for (t, _) in &repeated {
                    let (a, b) = (wrap(t.alpha - phi), wrap(t.beta + phi));
                    // The turn that changes counts as one, whatever its start.
                    turns += usize::from(a.abs() > tol.angle) + usize::from(b.abs() > tol.angle);
                    digits_ += angle_digits(a)
                        + angle_digits(b)
                        + digits(t.d, t.d.abs() * 5e-4)
                        + digits(t.s, 5e-4);
                }
                let score = (turns, digits_, n, h);
                let candidate = Frame {
                    pos: o,
                    rot: phi,
                    scale: 1.0,
                };
                if best.as_ref().is_none_or(|(s, _)| score < *s) {
                    best = Some((score, candidate));
                }
            }
        }
        if let Some((_, change)) = best {
            inst.reframe(k, &change);
        }
    }
}

/// Turns not zero, digits the numbers need, the origin's and the heading's
/// places in their lists of candidates.
type Score = (usize, usize, usize, usize);

/// The origins to try, in the kind's current local frame: the path's start,
/// an open stroke's end, where the principal axis crosses the outline
/// (`lines`), the outline's extremes along it, the centroid.
fn origins(
    subpaths: &[Vec<Seg>],
    frame: &Frame,
    lines: &[Vec<DVec2>],
    outline: &[DVec2],
    centroid: DVec2,
) -> Vec<DVec2> {
    let mut out = Vec::new();
    let first = subpaths.first().and_then(|s| s.first());
    if let Some(Seg::Move(p)) = first {
        out.push(frame.local(*p));
    }
    if let Some(last) = subpaths.last()
        && !matches!(last.last(), Some(Seg::Close))
        && let Some(p) = last.last().and_then(end_point)
    {
        out.push(frame.local(p));
    }
    let axis = principal_axis(outline, centroid);
    // Where the axis through the centroid leaves the outline: the base and
    // the tip of a leaf.
    let normal = axis.perp();
    let mut crossings: Vec<f64> = Vec::new();
    for line in lines {
        for w in line.windows(2) {
            let (a, b) = ((w[0] - centroid).dot(normal), (w[1] - centroid).dot(normal));
            if (a <= 0.0) != (b <= 0.0) {
                let p = w[0].lerp(w[1], a / (a - b));
                crossings.push((p - centroid).dot(axis));
            }
        }
    }
    let lo = crossings.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = crossings.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    for t in [lo, hi] {
        if t.is_finite() {
            out.push(centroid + axis * t);
        }
    }
    let along = |p: &DVec2| (*p - centroid).dot(axis);
    if let (Some(lo), Some(hi)) = (
        outline.iter().min_by(|a, b| along(a).total_cmp(&along(b))),
        outline.iter().max_by(|a, b| along(a).total_cmp(&along(b))),
    ) {
        out.push(*lo);
        out.push(*hi);
    }
    out.push(centroid);
    out
}

fn end_point(s: &Seg) -> Option<DVec2> {
    match *s {
        Seg::Move(p) | Seg::Line(p) | Seg::Quad(_, p) | Seg::Cubic(_, _, p) => Some(p),
        Seg::Close => None,
    }
}

/// The direction of largest spread of `points` about `centroid`.
fn principal_axis(points: &[DVec2], centroid: DVec2) -> DVec2 {
    let (mut xx, mut xy, mut yy) = (0.0, 0.0, 0.0);
    for p in points {
        let d = *p - centroid;
        xx += d.x * d.x;
        xy += d.x * d.y;
        yy += d.y * d.y;
    }
    let angle = 0.5 * (2.0 * xy).atan2(xx - yy);
    DVec2::new(angle.cos(), angle.sin())
}

/// The heading (turn from the frame's +y) of an element standing on `o`:
/// towards the centroid, or along the principal axis when `o` is the
/// centroid (towards the side farther from the path's start).
fn standing(o: DVec2, centroid: DVec2, outline: &[DVec2]) -> f64 {
    let spread = outline
        .iter()
        .map(|p| p.distance(centroid))
        .fold(0.0, f64::max)
        .max(1e-12);
    let v = if o.distance(centroid) > 0.1 * spread {
        centroid - o
    } else {
        let axis = principal_axis(outline, centroid);
        match outline.first() {
            Some(start) if (*start - centroid).dot(axis) > 0.0 => -axis,
            _ => axis,
        }
    };
    heading_of(v)
}

/// The turn from +y to `v`, counter-clockwise.
fn heading_of(v: DVec2) -> f64 {
    (-v.x).atan2(v.y)
}

/// The transforms that repeat between neighbouring instances when each
/// frame moves by `change`: the means of the largest cluster of their
/// transforms and of the next when it is at least half as large (a
/// branching's second child), each with its size, if the largest has at
/// least two. `ignore`: the coordinate (0 the turn before the step, 3 the
/// one after) that may change along a sequence.
fn repeated(
    inst: &Instancing,
    pairs: &[(usize, usize)],
    change: &Frame,
    radius: f64,
    tol: Tolerance,
    ignore: Option<usize>,
) -> Vec<(Tr, usize)> {
    let trs: Vec<Tr> = pairs
        .iter()
        .map(|&(i, j)| {
            let (a, b) = (inst.of[i].1.then(change), inst.of[j].1.then(change));
            Tr::between(&a, &b, radius)
        })
        .collect();
    let points: Vec<Point> = trs
        .iter()
        .map(|t| {
            let mut p = [
                t.alpha / tol.angle,
                t.d.max(1e-12).ln() / tol.distance,
                t.s.ln() / tol.scale,
                t.beta / tol.angle,
            ];
            if let Some(i) = ignore {
                p[i] = 0.0;
            }
            p
        })
        .collect();
    let (label, centres) = cluster(&points, std::f64::consts::TAU / tol.angle);
    let mut count = vec![0usize; centres.len()];
    for l in &label {
        count[*l] += 1;
    }
    let mut order: Vec<usize> = (0..centres.len()).collect();
    order.sort_by(|&a, &b| count[b].cmp(&count[a]).then(a.cmp(&b)));
    let Some(&top) = order.first() else {
        return Vec::new();
    };
    if count[top] < 2 {
        return Vec::new();
    }
    order
        .iter()
        .take(2)
        .filter(|&&c| count[c] * 2 >= count[top])
        .map(|&c| {
            let members: Vec<&Tr> = trs
                .iter()
                .zip(&label)
                .filter(|(_, l)| **l == c)
                .map(|(t, _)| t)
                .collect();
            let n = members.len() as f64;
            let first = members[0];
            let mean_angle = |f: fn(&Tr) -> f64| {
                wrap(f(first) + members.iter().map(|t| wrap(f(t) - f(first))).sum::<f64>() / n)
            };
            let t = Tr {
                alpha: mean_angle(|t| t.alpha),
                d: members.iter().map(|t| t.d).sum::<f64>() / n,
                s: members.iter().map(|t| t.s).sum::<f64>() / n,
                beta: mean_angle(|t| t.beta),
            };
            (t, members.len())
        })
        .collect()
}

/// Decimals an angle (radians) needs in degrees, to a hundredth of a degree.
fn angle_digits(a: f64) -> usize {
    digits(a.to_degrees(), 0.01)
}

/// The fewest decimals that keep `v` within `tol`, and its integer digits.
fn digits(v: f64, tol: f64) -> usize {
    let whole = v.abs().max(1.0).log10().floor() as usize + 1;
    let decimals = (0..=6)
        .find(|&d| {
            let k = 10f64.powi(d);
            ((v * k).round() / k - v).abs() <= tol.max(1e-12)
        })
        .unwrap_or(6) as usize;
    if v.abs() <= tol { 0 } else { whole + decimals }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn digits_count_what_a_number_needs() {
        assert_eq!(digits(0.0, 0.01), 0);
        assert_eq!(digits(12.0, 0.01), 2);
        assert_eq!(digits(12.5, 0.01), 3);
        assert_eq!(digits(20.7055, 0.001), 5);
        assert_eq!(angle_digits(std::f64::consts::FRAC_PI_2), 2);
        // Heading of +x is a right turn.
        assert!((heading_of(DVec2::X) + std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        assert!(
            (super::super::shape::rotate(DVec2::Y, heading_of(DVec2::new(-1.0, 1.0)))
                - DVec2::new(-1.0, 1.0).normalize())
            .length()
                < 1e-12
        );
    }
}
