//! Plane geometry on glam types, one of each: closest point on a segment,
//! segment crossing, ray hit, point in polygon, signed area, centroid, signed
//! angle, and the affine maps of the plane (`DAffine2`).
//!
//! Owns: the exact predicates ([`exact`]: orientation, where segments meet),
//! the tolerances that remain, each stated once here ([`ON_BOUNDARY`],
//! [`RAY_START`]), and the spatial indexes ([`index`]). Every function is
//! deterministic: the same input gives the same bits. Must not know guides,
//! elements, SVG or the language.
//!
//! Whether two segments meet, and whether a ray meets a segment, is decided
//! exactly (robust orientation tests with an exact fallback): segments that
//! cross at a vertex, touch, or overlap on one line meet; only the place where
//! they meet is rounded. The centre rule's point-in-polygon test keeps its
//! tolerance: a point within [`ON_BOUNDARY`] of an edge counts as inside.

pub mod exact;
pub mod index;

use glam::{DAffine2, DMat2, DVec2};

/// A point whose squared distance to a polygon edge is below this lies on the
/// boundary, which counts as inside.
pub const ON_BOUNDARY: f64 = 1e-18;
/// A ray does not hit what lies closer than this to its start.
pub const RAY_START: f64 = 1e-9;

/// The closest point of segment `a`–`b` to `p`.
pub fn closest_on_segment(p: DVec2, a: DVec2, b: DVec2) -> DVec2 {
    let ab = b - a;
    let len2 = ab.length_squared();
    if len2 == 0.0 {
        return a;
    }
    let t = ((p - a).dot(ab) / len2).clamp(0.0, 1.0);
    a + ab * t
}

/// Where the closed segment `p`–`q` first meets segment `a`–`b`: the
/// parameter along `p`–`q` (0 at p, 1 at q). Crossings, touches (also at
/// vertices) and collinear overlaps meet; the decision is exact
/// ([`exact::segment_hit`]).
pub fn crossing(p: DVec2, q: DVec2, a: DVec2, b: DVec2) -> Option<f64> {
    exact::segment_hit(p, q, a, b)
}

/// Distance along the ray from `p` in unit direction `dir` to segment `a`–`b`,
/// when it is beyond [`RAY_START`] (what the ray starts on does not count).
/// The decision is exact ([`exact::ray_segment_hit`]).
pub fn ray_hit(p: DVec2, dir: DVec2, a: DVec2, b: DVec2) -> Option<f64> {
    exact::ray_segment_hit(p, dir, a, b).filter(|&t| t > RAY_START)
}

/// Whether `p` lies inside the polygon (even–odd rule; the boundary, within
/// [`ON_BOUNDARY`], counts as inside).
pub fn inside(p: DVec2, poly: &[DVec2]) -> bool {
    let n = poly.len();
    let mut odd = false;
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        if (closest_on_segment(p, a, b) - p).length_squared() < ON_BOUNDARY {
            return true;
        }
        if (a.y > p.y) != (b.y > p.y) {
            let x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
            if x > p.x {
                odd = !odd;
            }
        }
    }
    odd
}

/// The signed angle in degrees from direction `from` to direction `to`
/// (positive counter-clockwise, i.e. a left turn).
pub fn signed_angle(from: DVec2, to: DVec2) -> f64 {
    from.perp_dot(to).atan2(from.dot(to)).to_degrees()
}

/// The distance between two points, as `hypot` computes it.
pub fn dist(a: DVec2, b: DVec2) -> f64 {
    (a.x - b.x).hypot(a.y - b.y)
}

/// The signed area of a closed polygon (positive when counter-clockwise, x
/// right, y up).
pub fn signed_area(points: &[DVec2]) -> f64 {
    let n = points.len();
    let mut s = 0.0;
    for i in 0..n {
        let (p, q) = (points[i], points[(i + 1) % n]);
        s += p.x * q.y - q.x * p.y;
    }
    0.5 * s
}

/// The mean of the points (the origin for none).
pub fn mean(points: &[DVec2]) -> DVec2 {
    let n = points.len();
    if n == 0 {
        return DVec2::ZERO;
    }
    DVec2::new(
        points.iter().map(|p| p.x).sum::<f64>() / n as f64,
        points.iter().map(|p| p.y).sum::<f64>() / n as f64,
    )
}

/// The area centroid of a polygon, or the mean of its vertices when its area is
/// (nearly) zero: below 10⁻⁹ of the square of its extent about the mean.
pub fn centroid(pts: &[DVec2]) -> DVec2 {
    let n = pts.len();
    if n == 0 {
        return DVec2::ZERO;
    }
    // Relative to the first vertex, for accuracy far from the origin.
    let o = pts[0];
    let mut a2 = 0.0;
    let mut c = DVec2::ZERO;
    for i in 0..n {
        let p = pts[i] - o;
        let q = pts[(i + 1) % n] - o;
        let cross = p.x * q.y - q.x * p.y;
        a2 += cross;
        c += (p + q) * cross;
    }
    let mean = mean(pts);
    let extent = pts.iter().map(|p| dist(*p, mean)).fold(0.0f64, f64::max);
    if a2.abs() <= 1e-9 * extent * extent {
        return mean;
    }
    o + c / (3.0 * a2)
}

/// The least-squares affine map taking `from` to `to` (a translation when the
/// points are collinear).
pub fn affine_fit(from: &[DVec2], to: &[DVec2]) -> DAffine2 {
    let n = from.len().min(to.len()).max(1) as f64;
    let mean = |ps: &[DVec2]| ps.iter().fold(DVec2::ZERO, |s, p| s + *p) / n;
    let (mp, mq) = (mean(from), mean(to));
    // Row-major sums Σ d dᵀ and Σ e dᵀ.
    let (mut pp, mut qp) = ([0.0; 4], [0.0; 4]);
    for (p, q) in from.iter().zip(to) {
        let (d, e) = (*p - mp, *q - mq);
        pp = [
            pp[0] + d.x * d.x,
            pp[1] + d.x * d.y,
            pp[2] + d.y * d.x,
            pp[3] + d.y * d.y,
        ];
        qp = [
            qp[0] + e.x * d.x,
            qp[1] + e.x * d.y,
            qp[2] + e.y * d.x,
            qp[3] + e.y * d.y,
        ];
    }
    let det = pp[0] * pp[3] - pp[1] * pp[2];
    let scale = (pp[0] + pp[3]).max(f64::MIN_POSITIVE);
    let a = if det.abs() <= 1e-12 * scale * scale {
        [1.0, 0.0, 0.0, 1.0]
    } else {
        let inv = [pp[3] / det, -pp[1] / det, -pp[2] / det, pp[0] / det];
        [
            qp[0] * inv[0] + qp[1] * inv[2],
            qp[0] * inv[1] + qp[1] * inv[3],
            qp[2] * inv[0] + qp[3] * inv[2],
            qp[2] * inv[1] + qp[3] * inv[3],
        ]
    };
    let t = DVec2::new(
        mq.x - (a[0] * mp.x + a[1] * mp.y),
        mq.y - (a[2] * mp.x + a[3] * mp.y),
    );
    DAffine2::from_mat2_translation(DMat2::from_cols_array(&[a[0], a[2], a[1], a[3]]), t)
}

/// The angle (degrees, counter-clockwise) of the rotation closest to the linear
/// part of `m`.
pub fn rotation_degrees(m: &DAffine2) -> f64 {
    let (x, y) = (m.matrix2.x_axis, m.matrix2.y_axis);
    (x.y - y.x).atan2(x.x + y.y).to_degrees()
}

/// `p` rotated counter-clockwise by the angle whose (sine, cosine) is
/// `sin_cos` and scaled by `k`, both about `c`.
pub fn rotate_scale_about(p: DVec2, c: DVec2, sin_cos: (f64, f64), k: f64) -> DVec2 {
    let (sin, cos) = sin_cos;
    let d = p - c;
    DVec2::new(
        c.x + k * (cos * d.x - sin * d.y),
        c.y + k * (sin * d.x + cos * d.y),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn basics() {
        let a = DVec2::new(0.0, 0.0);
        let b = DVec2::new(10.0, 0.0);
        assert_eq!(
            closest_on_segment(DVec2::new(3.0, 4.0), a, b),
            DVec2::new(3.0, 0.0)
        );
        assert_eq!(
            crossing(DVec2::new(5.0, -1.0), DVec2::new(5.0, 1.0), a, b),
            Some(0.5)
        );
        assert_eq!(
            crossing(DVec2::new(5.0, 1.0), DVec2::new(5.0, 2.0), a, b),
            None
        );
        assert_eq!(
            ray_hit(DVec2::new(5.0, 3.0), DVec2::new(0.0, -1.0), a, b),
            Some(3.0)
        );
        let square = [a, b, DVec2::new(10.0, 10.0), DVec2::new(0.0, 10.0)];
        assert!(inside(DVec2::new(5.0, 5.0), &square));
        assert!(!inside(DVec2::new(15.0, 5.0), &square));
        assert!(
            inside(DVec2::new(10.0, 5.0), &square),
            "the boundary is inside"
        );
        assert!((signed_angle(DVec2::Y, DVec2::NEG_X) - 90.0).abs() < 1e-12);
        assert!((signed_angle(DVec2::Y, DVec2::X) + 90.0).abs() < 1e-12);
        assert_eq!(signed_area(&square), 100.0);
        assert_eq!(centroid(&square), DVec2::new(5.0, 5.0));
        // A degenerate polygon: the mean of its vertices.
        let line = [a, DVec2::new(2.0, 0.0), DVec2::new(4.0, 0.0)];
        assert_eq!(centroid(&line), DVec2::new(2.0, 0.0));
    }

    #[test]
    fn affine_fit_recovers_a_similarity() {
        let from = [
            DVec2::new(0.0, 0.0),
            DVec2::new(4.0, 0.0),
            DVec2::new(4.0, 2.0),
            DVec2::new(0.0, 3.0),
        ];
        let m = DAffine2::from_scale_angle_translation(
            DVec2::splat(2.0),
            30f64.to_radians(),
            DVec2::new(7.0, -1.0),
        );
        let to: Vec<DVec2> = from.iter().map(|&p| m.transform_point2(p)).collect();
        let fit = affine_fit(&from, &to);
        let q = fit.transform_point2(DVec2::ONE);
        assert!((q - m.transform_point2(DVec2::ONE)).length() < 1e-9);
        assert!((rotation_degrees(&fit) - 30.0).abs() < 1e-9);
        // Collinear points: a translation.
        let line = [DVec2::ZERO, DVec2::X, DVec2::new(2.0, 0.0)];
        let moved: Vec<DVec2> = line.iter().map(|&p| p + DVec2::Y).collect();
        let fit = affine_fit(&line, &moved);
        assert_eq!(fit.matrix2, DMat2::IDENTITY);
        assert_eq!(fit.translation, DVec2::Y);
    }
}
