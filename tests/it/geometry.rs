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
    for q in points(20, 6) {
        assert_eq!(grid.nearest(q), env.nearest(q));
        assert_eq!(grid.ray(q, DVec2::X, 1e9), env.ray(q, DVec2::X, 1e9));
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
