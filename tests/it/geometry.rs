//! The shared geometry, path and number modules through the public API: one
//! answer per question, whatever the caller.

use glam::DVec2;
use lsyc::geometry::index::{PointGrid, SegmentGrid};
use lsyc::geometry::{centroid, crossing, dist, inside, signed_area};
use lsyc::{number, path};

/// A tiny deterministic generator for test geometry.
fn points(n: usize, mut s: u64) -> Vec<DVec2> {
    let mut next = move || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n)
        .map(|_| DVec2::new(next() * 100.0, next() * 40.0))
        .collect()
}

#[test]
fn polygon_predicates_on_a_square() {
    let square = [DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y].map(|p| p * 10.0);
    for p in points(200, 3) {
        let p = p * 0.15 - DVec2::splat(1.0);
        // Away from the boundary the answer is plain; on it, the tolerance decides.
        let margin = p.x.min(p.y).min(10.0 - p.x).min(10.0 - p.y);
        if margin.abs() > 1e-6 {
            assert_eq!(inside(p, &square), margin > 0.0, "{p}");
        }
    }
    assert_eq!(signed_area(&square), 100.0);
    assert_eq!(centroid(&square), DVec2::splat(5.0));
    // Touching ends cross; parallel segments do not.
    let (a, b) = (DVec2::ZERO, DVec2::new(10.0, 0.0));
    assert_eq!(
        crossing(DVec2::new(10.0, -1.0), DVec2::new(10.0, 1.0), a, b),
        Some(0.5)
    );
    assert_eq!(crossing(DVec2::Y, DVec2::new(10.0, 1.0), a, b), None);
}

#[test]
fn point_index_answers_as_a_scan() {
    let pts = points(500, 11);
    let grid = PointGrid::new(&pts);
    for q in points(50, 12) {
        let mut scan: Vec<usize> = (0..pts.len()).collect();
        scan.sort_by(|&i, &j| {
            let (a, b) = (pts[i].distance_squared(q), pts[j].distance_squared(q));
            a.total_cmp(&b).then(i.cmp(&j))
        });
        assert_eq!(grid.nearest(q, 7), scan[..7]);
        let near: Vec<usize> = (0..pts.len()).filter(|&i| dist(pts[i], q) <= 3.0).collect();
        assert_eq!(grid.within(q, 3.0), near);
    }
}

#[test]
fn segment_index_is_the_environments() {
    let pts = points(80, 5);
    let segs: Vec<(DVec2, DVec2)> = pts.chunks(2).map(|c| (c[0], c[1])).collect();
    let grid = SegmentGrid::new(segs.clone());
    let env = lsyc::env::index::Grid::new(segs);
    let id = |k: u64| k;
    for q in points(20, 6) {
        let near = env.nearest(q, &id).map(|(d, c, i)| (d, c, i as usize));
        assert_eq!(grid.nearest(q), near);
        let ray = env.ray(q, DVec2::X, 1e9, &id).map(|(t, i)| (t, i as usize));
        assert_eq!(grid.ray(q, DVec2::X, 1e9), ray);
    }
}

#[test]
fn bad_path_data_is_one_error_with_a_place() {
    for (d, at) in [("M0 0 L10 x", 9), ("M0 0 Lé", 6), ("M0 0 Q1 1", 9)] {
        let e = path::parse(d).expect_err(d);
        assert!(e.offset.is_none_or(|o| o == at), "{d}: {e:?}");
        assert!(!e.to_string().is_empty());
    }
    assert!(path::parse("M0 0 h2 v2 z").is_ok());
    // Everything that reads element paths agrees that bad data draws nothing.
    for d in ["M0 0 L10 x", "", "Z", "M"] {
        assert_eq!(lsyc::render::path_bounds(d), None, "{d}");
        assert_eq!(path::largest_outline(d), None, "{d}");
        assert_eq!(lsyc::env::clip::outline_centre(d), DVec2::ZERO, "{d}");
        assert_eq!(lsyc::render::obj::outline_from_path(d), None, "{d}");
    }
}

#[test]
fn numbers_read_back() {
    for v in [0.1 + 0.2, 1e-7, -3.0, 1.5e20, 12345.678] {
        assert_eq!(number::source(v).parse::<f64>().ok(), Some(v));
        let mut b = Vec::new();
        number::write_significant(&mut b, v);
        let back: f64 = String::from_utf8(b)
            .expect("ascii")
            .parse()
            .expect("a number");
        assert!((back - v).abs() <= 5.0000001e-7 * v.abs());
    }
}

/// An exact reference on integer points (`i128`): the orientation, where two
/// closed segments first meet (a rational parameter, as f64 at the end), and
/// where a ray first meets a segment.
mod reference {
    pub type P = (i64, i64);

    fn sub(a: P, b: P) -> (i128, i128) {
        (
            i128::from(a.0) - i128::from(b.0),
            i128::from(a.1) - i128::from(b.1),
        )
    }
    fn cross(u: (i128, i128), v: (i128, i128)) -> i128 {
        u.0 * v.1 - u.1 * v.0
    }
    fn dot(u: (i128, i128), v: (i128, i128)) -> i128 {
        u.0 * v.0 + u.1 * v.1
    }

    pub fn orient(a: P, b: P, c: P) -> std::cmp::Ordering {
        cross(sub(a, c), sub(b, c)).cmp(&0)
    }

    fn between(x: i128, lo: i128, hi: i128) -> bool {
        lo.min(hi) <= x && x <= lo.max(hi)
    }

    /// Whether `c` lies on the closed segment a–b.
    fn on(a: P, b: P, c: P) -> bool {
        cross(sub(b, a), sub(c, a)) == 0
            && between(i128::from(c.0), i128::from(a.0), i128::from(b.0))
            && between(i128::from(c.1), i128::from(a.1), i128::from(b.1))
    }

    pub fn segment_hit(p: P, q: P, a: P, b: P) -> Option<f64> {
        let r = sub(q, p);
        let s = sub(b, a);
        let ap = sub(a, p);
        let den = cross(r, s);
        if den != 0 {
            let (mut tn, mut un, mut d) = (cross(ap, s), cross(ap, r), den);
            if d < 0 {
                (tn, un, d) = (-tn, -un, -d);
            }
            return (0 <= tn && tn <= d && 0 <= un && un <= d).then(|| tn as f64 / d as f64);
        }
        if r == (0, 0) {
            return on(a, b, p).then_some(0.0);
        }
        if cross(ap, r) != 0 {
            return None; // parallel, on different lines
        }
        // Collinear: the overlap of [ta, tb] with [0, |r|²], from its start.
        let rr = dot(r, r);
        let ta = dot(ap, r);
        let tb = dot(sub(b, p), r);
        let (lo, hi) = (ta.min(tb), ta.max(tb));
        if hi < 0 || lo > rr {
            return None;
        }
        Some(lo.max(0) as f64 / rr as f64)
    }

    /// The ray from p along d (in units of d).
    pub fn ray_hit(p: P, d: P, a: P, b: P) -> Option<f64> {
        let d = (i128::from(d.0), i128::from(d.1));
        let s = sub(b, a);
        let ap = sub(a, p);
        let den = cross(d, s);
        if den != 0 {
            let (mut tn, mut un, mut e) = (cross(ap, s), cross(ap, d), den);
            if e < 0 {
                (tn, un, e) = (-tn, -un, -e);
            }
            return (0 <= tn && 0 <= un && un <= e).then(|| tn as f64 / e as f64);
        }
        if cross(ap, d) != 0 {
            return None;
        }
        if on(a, b, p) {
            return Some(0.0);
        }
        let dd = dot(d, d);
        let t = dot(ap, d).min(dot(sub(b, p), d));
        (t >= 0).then(|| t as f64 / dd as f64)
    }
}

/// Random points on an integer grid, with many on each other's lines: the
/// vertices and edges of segments drawn before, and points one unit off them.
struct Gen(u64);
impl Gen {
    fn next(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        self.0 >> 33
    }
    fn int(&mut self, n: i64) -> i64 {
        (self.next() % (2 * n as u64 + 1)) as i64 - n
    }
    /// A point: free, a vertex of `near`, on the line of `near` (between its
    /// ends or beyond), or one unit off such a point.
    fn point(&mut self, range: i64, near: &[reference::P]) -> reference::P {
        let pick = self.next() % 6;
        if near.len() < 2 || pick < 2 {
            return (self.int(range), self.int(range));
        }
        let (a, b) = (near[0], near[1]);
        match pick {
            2 => a,
            3 => b,
            _ => {
                // a + k (b − a) / m for a divisor m of both coordinates' steps.
                let g = gcd((b.0 - a.0).unsigned_abs(), (b.1 - a.1).unsigned_abs()).max(1) as i64;
                let k = self.int(2 * g);
                let c = (a.0 + k * (b.0 - a.0) / g, a.1 + k * (b.1 - a.1) / g);
                if pick == 5 {
                    (c.0 + self.int(1), c.1 + self.int(1))
                } else {
                    c
                }
            }
        }
    }
}

fn gcd(a: u64, b: u64) -> u64 {
    if b == 0 { a } else { gcd(b, a % b) }
}

/// Integer points as floats, scaled by a power of two and shifted (exactly).
fn float(p: reference::P, scale: f64, shift: f64) -> DVec2 {
    DVec2::new(p.0 as f64 * scale + shift, p.1 as f64 * scale + shift)
}

/// The exact predicates against the integer reference: on a small grid (where
/// vertices, touches and collinear overlaps are common) and on a huge one
/// (where floating point alone gets the orientation of nearly collinear points
/// wrong), every answer agrees: whether segments meet exactly, where within
/// rounding.
#[test]
fn exact_predicates_agree_with_an_integer_reference() {
    use lsyc::geometry::exact::{orient, ray_segment_hit, segment_hit};
    let mut g = Gen(17);
    let mut seen = [0usize; 4]; // meets, misses, collinear meets, touches at an end
    for (range, scale, shift) in [
        (6, 1.0, 0.0),
        (40, 0.125, 3.0),
        (1 << 40, 1.0, 0.0),
        (1 << 30, 1.0 / 1024.0, 1024.0),
    ] {
        for _ in 0..20_000 {
            let a = g.point(range, &[]);
            let b = g.point(range, &[a]);
            let p = g.point(range, &[a, b]);
            let q = g.point(range, &[p, a]);
            let (fa, fb, fp, fq) = (
                float(a, scale, shift),
                float(b, scale, shift),
                float(p, scale, shift),
                float(q, scale, shift),
            );
            assert_eq!(
                orient(fa, fb, fp),
                reference::orient(a, b, p),
                "{a:?} {b:?} {p:?}"
            );
            let want = reference::segment_hit(p, q, a, b);
            let got = segment_hit(fp, fq, fa, fb);
            assert_eq!(
                got.is_some(),
                want.is_some(),
                "{p:?}-{q:?} and {a:?}-{b:?}: {got:?}"
            );
            if let (Some(x), Some(y)) = (got, want) {
                // The place is rounded: within the conditioning of the
                // parameter, |a − p| |s| / |r × s| (large for nearly parallel
                // lines and for a short p–q far from a–b's ends).
                let (r, s) = (fq - fp, fb - fa);
                let reach = (fa - fp).length() + (fb - fp).length() + r.length();
                let cond = reach * s.length() / r.perp_dot(s).abs().max(1e-300);
                let tol = 1e-9 + 1e-14 * cond.min(1e300);
                assert!(
                    (x - y).abs() <= tol,
                    "{p:?}-{q:?} and {a:?}-{b:?}: {x} vs {y}"
                );
                let collinear =
                    reference::orient(p, q, a).is_eq() && reference::orient(p, q, b).is_eq();
                seen[if collinear { 2 } else { 0 }] += 1;
                if [a, b].contains(&p) || [a, b].contains(&q) {
                    seen[3] += 1;
                }
            } else {
                seen[1] += 1;
            }
            // The ray from p toward q (in units of q − p).
            if p != q && scale == 1.0 {
                let d = (q.0 - p.0, q.1 - p.1);
                let want = reference::ray_hit(p, d, a, b);
                let got = ray_segment_hit(fp, fq - fp, fa, fb);
                assert_eq!(
                    got.is_some(),
                    want.is_some(),
                    "ray {p:?} {d:?} and {a:?}-{b:?}"
                );
                if let (Some(x), Some(y)) = (got, want) {
                    let s = fb - fa;
                    let dir = fq - fp;
                    // |a − p| |s| / |dir × s|: the numerator cancels too.
                    let reach = (fa - fp).length() + (fb - fp).length();
                    let cond = reach * s.length() / dir.perp_dot(s).abs().max(1e-300);
                    let tol = 1e-9 * (1.0 + y) + 1e-14 * cond.min(1e300);
                    assert!((x - y).abs() <= tol, "{x} vs {y}");
                }
            }
        }
    }
    // Every kind of case came up often.
    assert!(seen.iter().all(|&n| n > 500), "{seen:?}");
}

/// Hand-checked meetings: through a vertex, touching, collinear overlaps.
#[test]
fn segments_meet_at_vertices_touches_and_overlaps() {
    use lsyc::geometry::exact::segment_hit;
    let v = |x: f64, y: f64| DVec2::new(x, y);
    // A stem going up through the apex (5, 10) of a roof: it meets both edges
    // there, at a third of the way.
    let (p, q) = (v(5.0, 9.0), v(5.0, 12.0));
    assert_eq!(
        segment_hit(p, q, v(10.0, 8.0), v(5.0, 10.0)),
        Some(1.0 / 3.0)
    );
    assert_eq!(
        segment_hit(p, q, v(5.0, 10.0), v(0.0, 8.0)),
        Some(1.0 / 3.0)
    );
    // Ending exactly on an edge; starting on it.
    assert_eq!(
        segment_hit(v(1.0, 0.0), v(1.0, 2.0), v(0.0, 2.0), v(4.0, 2.0)),
        Some(1.0)
    );
    assert_eq!(
        segment_hit(v(1.0, 2.0), v(1.0, 5.0), v(0.0, 2.0), v(4.0, 2.0)),
        Some(0.0)
    );
    // Collinear: overlapping from the middle, containing, touching end to end,
    // apart.
    let (a, b) = (v(0.0, 4.0), v(0.0, 6.0));
    assert_eq!(segment_hit(v(0.0, 0.0), v(0.0, 10.0), a, b), Some(0.4));
    assert_eq!(segment_hit(v(0.0, 5.0), v(0.0, 10.0), a, b), Some(0.0));
    assert_eq!(segment_hit(v(0.0, 6.0), v(0.0, 10.0), a, b), Some(0.0));
    assert_eq!(segment_hit(v(0.0, 7.0), v(0.0, 10.0), a, b), None);
    assert_eq!(segment_hit(v(0.0, 10.0), v(0.0, 0.0), a, b), Some(0.4));
    // Nearly collinear, a hair apart: floating point alone would call it a
    // meeting.
    let far = 1e15;
    assert_eq!(
        segment_hit(
            v(0.0, 0.0),
            v(far, far),
            v(1.0, 1.0 + 1.0 / 1024.0),
            v(far, far + 1.0)
        ),
        None
    );
}
