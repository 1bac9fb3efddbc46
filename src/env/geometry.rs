//! Plane geometry for the environment: distances, ray casts, crossings, and
//! point-in-polygon, on guide edges and drawn segments (x–y plane).

use glam::DVec2;

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

/// Where segment `p`–`q` crosses segment `a`–`b`: the parameter along `p`–`q`
/// (0 at p, 1 at q), if they cross.
pub fn crossing(p: DVec2, q: DVec2, a: DVec2, b: DVec2) -> Option<f64> {
    let r = q - p;
    let s = b - a;
    let denom = r.perp_dot(s);
    if denom.abs() < 1e-12 {
        return None;
    }
    let t = (a - p).perp_dot(s) / denom;
    let u = (a - p).perp_dot(r) / denom;
    ((0.0..=1.0).contains(&t) && (0.0..=1.0).contains(&u)).then_some(t)
}

/// Distance along the ray from `p` in unit direction `dir` to segment `a`–`b`.
pub fn ray_hit(p: DVec2, dir: DVec2, a: DVec2, b: DVec2) -> Option<f64> {
    let s = b - a;
    let denom = dir.perp_dot(s);
    if denom.abs() < 1e-12 {
        return None;
    }
    let t = (a - p).perp_dot(s) / denom;
    let u = (a - p).perp_dot(dir) / denom;
    (t > 1e-9 && (0.0..=1.0).contains(&u)).then_some(t)
}

/// Whether `p` lies inside the polygon (even–odd rule; the boundary counts as inside).
pub fn inside(p: DVec2, poly: &[DVec2]) -> bool {
    let n = poly.len();
    let mut odd = false;
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        if (closest_on_segment(p, a, b) - p).length_squared() < 1e-18 {
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
    }
}
