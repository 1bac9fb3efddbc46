//! Exact predicates of the plane: the orientation of three points and what
//! follows from it, where two closed segments meet (at a crossing, at a vertex,
//! touching, or overlapping on one line) and where a ray meets a segment.
//!
//! Owns: the orientation test (`orient`) with its floating-point filter and
//! exact fallback, and the meeting tests built only on it and on exact
//! comparisons of coordinates (`segment_hit`, `ray_segment_hit`). Whether two
//! segments meet is decided exactly; only the *place* where they meet (the
//! parameter along the first segment) is rounded. Must not know guides, links or
//! drawings.
//!
//! The orientation is exact for coordinates of magnitude below 2⁵⁰⁰ that are
//! zero or above 2⁻⁵⁰⁰ (far beyond what a drawing may hold): the determinant is
//! first computed in floating point with Shewchuk's error bound, and only when
//! the bound cannot certify its sign is it summed exactly as an expansion of
//! error-free products and sums.

use glam::DVec2;
use std::cmp::Ordering;

/// Shewchuk's bound on the error of the floating-point orientation:
/// (3 + 16ε)ε with ε = 2⁻⁵³.
const ORIENT_BOUND: f64 = (3.0 + 16.0 * f64::EPSILON / 2.0) * (f64::EPSILON / 2.0);

/// `a * b` as an exact sum of two numbers (the product and its rounding error).
fn two_product(a: f64, b: f64) -> [f64; 2] {
    let x = a * b;
    [x, a.mul_add(b, -x)]
}

/// `a + b` as an exact sum of two numbers (Knuth's two-sum).
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let x = a + b;
    let bv = x - a;
    let av = x - bv;
    (x, (a - av) + (b - bv))
}

/// The sign of the exact sum of `terms`: they are summed into a nonoverlapping
/// expansion (Shewchuk's grow-expansion), whose largest nonzero component has
/// the sign of the sum.
fn exact_sign(terms: &[f64]) -> Ordering {
    let mut e = [0.0f64; 12];
    let mut n = 0;
    for &t in terms {
        let mut q = t;
        for c in e.iter_mut().take(n) {
            let (s, r) = two_sum(q, *c);
            *c = r;
            q = s;
        }
        e[n] = q;
        n += 1;
    }
    e[..n]
        .iter()
        .rev()
        .find(|c| **c != 0.0)
        .map_or(Ordering::Equal, |c| c.total_cmp(&0.0))
}

/// The orientation of `c` relative to the directed line `a`→`b`: `Greater`
/// when `c` lies to its left (counter-clockwise, x right, y up), `Less` to its
/// right, `Equal` when the three points are collinear. Exact (see the module
/// note).
pub fn orient(a: DVec2, b: DVec2, c: DVec2) -> Ordering {
    let left = (a.x - c.x) * (b.y - c.y);
    let right = (a.y - c.y) * (b.x - c.x);
    let det = left - right;
    let bound = ORIENT_BOUND * (left.abs() + right.abs());
    if det > bound {
        return Ordering::Greater;
    }
    if -det > bound {
        return Ordering::Less;
    }
    // Collinear points on a lattice (streets along one line) land here: when
    // the four differences are exact, the determinant is the difference of two
    // exact products, an expansion of four terms.
    let (acx, e1) = two_sum(a.x, -c.x);
    let (bcy, e2) = two_sum(b.y, -c.y);
    let (acy, e3) = two_sum(a.y, -c.y);
    let (bcx, e4) = two_sum(b.x, -c.x);
    if e1 == 0.0 && e2 == 0.0 && e3 == 0.0 && e4 == 0.0 {
        let [l, le] = two_product(acx, bcy);
        let [r, re] = two_product(acy, bcx);
        return exact_sign(&[le, l, -re, -r]);
    }
    orient_expanded(a, b, c)
}

/// The sign of the full expansion
/// ax·by − ax·cy − cx·by − ay·bx + ay·cx + cy·bx, each product exact in two parts.
fn orient_expanded(a: DVec2, b: DVec2, c: DVec2) -> Ordering {
    let mut terms = [0.0; 12];
    let products = [
        (a.x, b.y),
        (-a.x, c.y),
        (-c.x, b.y),
        (-a.y, b.x),
        (a.y, c.x),
        (c.y, b.x),
    ];
    for (k, (u, v)) in products.into_iter().enumerate() {
        let [x, y] = two_product(u, v);
        terms[2 * k] = y;
        terms[2 * k + 1] = x;
    }
    exact_sign(&terms)
}

/// Whether `c` lies on the closed segment `a`–`b` (exactly).
pub fn on_segment(a: DVec2, b: DVec2, c: DVec2) -> bool {
    orient(a, b, c) == Ordering::Equal && within(a, b, c)
}

/// For `c` on the line through `a` and `b`: whether it lies between them
/// (inclusive), by exact comparisons of coordinates.
fn within(a: DVec2, b: DVec2, c: DVec2) -> bool {
    a.x.min(b.x) <= c.x && c.x <= a.x.max(b.x) && a.y.min(b.y) <= c.y && c.y <= a.y.max(b.y)
}

/// The parameter of the projection of `c` on the line `p`→`q` (0 at p, 1 at q),
/// clamped to [0, 1].
fn param(p: DVec2, q: DVec2, c: DVec2) -> f64 {
    let r = q - p;
    let len2 = r.length_squared();
    if len2 == 0.0 {
        return 0.0;
    }
    ((c - p).dot(r) / len2).clamp(0.0, 1.0)
}

/// Where the closed segments `p`–`q` and `a`–`b` first meet, going from `p`
/// to `q`: the parameter along `p`–`q` (0 at p, 1 at q). Segments that touch (an
/// end on the other segment, or a vertex on a vertex) meet; collinear segments
/// that overlap meet where the overlap begins. Whether they meet is exact;
/// the parameter is rounded (and for a proper crossing computed from the
/// lines, clamped to [0, 1]).
pub fn segment_hit(p: DVec2, q: DVec2, a: DVec2, b: DVec2) -> Option<f64> {
    // Boxes apart: they cannot meet (exact comparisons, the cheap filter).
    if p.x.max(q.x) < a.x.min(b.x)
        || a.x.max(b.x) < p.x.min(q.x)
        || p.y.max(q.y) < a.y.min(b.y)
        || a.y.max(b.y) < p.y.min(q.y)
    {
        return None;
    }
    let o1 = orient(p, q, a);
    let o2 = orient(p, q, b);
    if o1 == o2 && o1 != Ordering::Equal {
        return None; // a and b strictly on one side of p–q
    }
    let o3 = orient(a, b, p);
    let o4 = orient(a, b, q);
    if o3 == o4 && o3 != Ordering::Equal {
        return None; // p and q strictly on one side of a–b
    }
    if o1 == Ordering::Equal && o2 == Ordering::Equal {
        // All four on one line (or a degenerate segment): the first point of
        // p–q that lies on a–b.
        let mut best: Option<f64> = None;
        let mut take = |t: f64| best = Some(best.map_or(t, |b: f64| b.min(t)));
        if p == q {
            // A point: it meets a–b if it lies on it.
            return on_segment(a, b, p).then_some(0.0);
        }
        if within(a, b, p) {
            take(0.0);
        }
        if within(a, b, q) {
            take(1.0);
        }
        if within(p, q, a) {
            take(param(p, q, a));
        }
        if within(p, q, b) {
            take(param(p, q, b));
        }
        return best;
    }
    // Not all collinear, and the sides alternate (or touch): they meet at one
    // point. Name it exactly where it is a given point.
    if o3 == Ordering::Equal {
        // p lies on the line a–b, and the segments meet: p is on a–b.
        if within(a, b, p) {
            return Some(0.0);
        }
    }
    if o1 == Ordering::Equal && within(p, q, a) {
        return Some(param(p, q, a));
    }
    if o2 == Ordering::Equal && within(p, q, b) {
        return Some(param(p, q, b));
    }
    if o4 == Ordering::Equal && within(a, b, q) {
        return Some(1.0);
    }
    if o1 == Ordering::Equal
        || o2 == Ordering::Equal
        || o3 == Ordering::Equal
        || o4 == Ordering::Equal
    {
        // A collinear end outside the other segment: they do not meet.
        return None;
    }
    // A proper crossing.
    let r = q - p;
    let s = b - a;
    let denom = r.perp_dot(s);
    Some(((a - p).perp_dot(s) / denom).clamp(0.0, 1.0))
}

/// Where the ray from `p` through `p + dir` first meets the closed segment
/// `a`–`b`: the distance along the ray in units of `dir` (0 when `p` lies on
/// the segment). Whether it meets is exact for the ray through the rounded
/// point `p + dir`; the distance is rounded.
pub fn ray_segment_hit(p: DVec2, dir: DVec2, a: DVec2, b: DVec2) -> Option<f64> {
    let q = p + dir;
    if q == p {
        return None;
    }
    let oa = orient(p, q, a);
    let ob = orient(p, q, b);
    if oa == ob && oa != Ordering::Equal {
        return None;
    }
    let along = |c: DVec2| (c - p).dot(dir) / dir.length_squared();
    if oa == Ordering::Equal && ob == Ordering::Equal {
        // On the ray's line: the nearest point of a–b ahead of p.
        if on_segment(a, b, p) {
            return Some(0.0);
        }
        let (ta, tb) = (along(a), along(b));
        let t = ta.min(tb);
        return (t >= 0.0).then_some(t);
    }
    if oa == Ordering::Equal {
        let t = along(a);
        return (t >= 0.0).then_some(t);
    }
    if ob == Ordering::Equal {
        let t = along(b);
        return (t >= 0.0).then_some(t);
    }
    // a and b strictly on opposite sides of the ray's line: the ray meets the
    // segment's line at t = ((a − p) × s) / (dir × s), where the numerator has
    // the sign of orient(a, b, p) and the denominator that of orient(p, q, b).
    let side = orient(a, b, p);
    if side == Ordering::Equal {
        return Some(0.0);
    }
    if side != ob {
        return None;
    }
    let s = b - a;
    Some(((a - p).perp_dot(s) / dir.perp_dot(s)).max(0.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orientation_of_nearly_collinear_points_is_exact() {
        // Points on the line y = x, one ulp off: floating point says 0.
        let a = DVec2::new(0.5, 0.5);
        let b = DVec2::new(12.0, 12.0);
        let c = DVec2::new(24.0, 24.0 + 24.0 * f64::EPSILON);
        assert_eq!(orient(a, b, c), Ordering::Greater);
        assert_eq!(orient(a, b, DVec2::new(24.0, 24.0)), Ordering::Equal);
        let c = DVec2::new(0.1, 0.1);
        assert_eq!(orient(a, b, c), Ordering::Equal);
    }

    #[test]
    fn every_stage_agrees_with_the_full_expansion() {
        let mut r = crate::geometry::index::Lcg(5);
        let mut stages = [0usize; 3];
        for k in 0..20_000 {
            // Lattice points (exact differences), points a few ulps off a
            // line, and points far apart in magnitude.
            let pt = |r: &mut crate::geometry::index::Lcg| match k % 3 {
                0 => DVec2::new(
                    (r.next() * 8.0).floor() * 4.0,
                    (r.next() * 8.0).floor() * 4.0,
                ),
                1 => DVec2::splat(r.next() * 100.0) + DVec2::new(0.0, r.next() * 1e-13),
                _ => DVec2::new(r.next() * 1e12, (r.next() - 0.5) * 1e-6),
            };
            let (a, b, c) = (pt(&mut r), pt(&mut r), pt(&mut r));
            let o = orient(a, b, c);
            assert_eq!(o, orient_expanded(a, b, c), "{a} {b} {c}");
            stages[k % 3] += usize::from(o == Ordering::Equal);
        }
        // Collinear triples were met, on the lattice and off it.
        assert!(stages[0] > 100 && stages[1] > 10, "{stages:?}");
    }
}
