//! The OBJ writer's tests: meshes parsed back and checked closed, oriented
//! and deterministic.

use super::*;
use glam::{DQuat, DVec2};
use std::collections::BTreeMap;

/// A parsed OBJ file: positions, normals, faces as 0-based (vertex, normal).
#[derive(Debug, Default)]
struct Mesh {
    v: Vec<DVec3>,
    vn: Vec<DVec3>,
    faces: Vec<Vec<(usize, usize)>>,
    tubes: usize,
    spheres: usize,
}

fn parse(text: &str) -> Mesh {
    let mut m = Mesh::default();
    for line in text.lines() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") | Some("vn") => {
                let xs: Vec<f64> = it.map(|x| x.parse().expect("number")).collect();
                assert_eq!(xs.len(), 3, "{line}");
                let p = DVec3::new(xs[0], xs[1], xs[2]);
                if line.starts_with("vn") {
                    m.vn.push(p)
                } else {
                    m.v.push(p)
                }
            }
            Some("f") => {
                let face: Vec<(usize, usize)> = it
                    .map(|c| {
                        let (v, n) = c.split_once("//").expect("v//vn");
                        let v: usize = v.parse().expect("index");
                        let n: usize = n.parse().expect("index");
                        assert!(v >= 1 && v <= m.v.len(), "vertex {v} of {}", m.v.len());
                        assert!(n >= 1 && n <= m.vn.len(), "normal {n} of {}", m.vn.len());
                        (v - 1, n - 1)
                    })
                    .collect();
                m.faces.push(face);
            }
            Some("#") => {
                let words: Vec<&str> = line.split_whitespace().collect();
                if words.get(2) == Some(&"tubes,") {
                    m.tubes = words[1].parse().expect("count");
                    m.spheres = words[3].parse().expect("count");
                }
            }
            Some("usemtl") | Some("o") | Some("mtllib") | None => {}
            Some(other) => panic!("unexpected line kind {other}"),
        }
    }
    m
}

fn write(f: impl FnOnce(&mut ObjWriter<Vec<u8>>)) -> String {
    write_with(ObjOptions::default(), f)
}

fn write_with(options: ObjOptions, f: impl FnOnce(&mut ObjWriter<Vec<u8>>)) -> String {
    let mut w = ObjWriter::new(Vec::new(), options);
    f(&mut w);
    String::from_utf8(w.finish().expect("write to a Vec")).expect("utf-8")
}

/// Faces have ≥ 3 distinct vertices, no zero area; normals are unit length.
fn check_valid(m: &Mesh) {
    for n in &m.vn {
        assert!((n.length() - 1.0).abs() < 1e-5, "normal {n} not unit");
    }
    for face in &m.faces {
        assert!(face.len() >= 3);
        let mut vs: Vec<usize> = face.iter().map(|c| c.0).collect();
        vs.sort_unstable();
        vs.dedup();
        assert_eq!(vs.len(), face.len(), "repeated vertex in {face:?}");
        assert!(area(m, face) > 1e-12, "degenerate face {face:?}");
    }
}

fn area(m: &Mesh, face: &[(usize, usize)]) -> f64 {
    let p0 = m.v[face[0].0];
    let mut a = DVec3::ZERO;
    for w in face[1..].windows(2) {
        a += (m.v[w[0].0] - p0).cross(m.v[w[1].0] - p0);
    }
    0.5 * a.length()
}

/// Every edge is used by exactly two faces, once in each direction: closed
/// and consistently oriented.
fn check_closed(m: &Mesh) {
    let mut directed: BTreeMap<(usize, usize), usize> = BTreeMap::new();
    for face in &m.faces {
        for k in 0..face.len() {
            let e = (face[k].0, face[(k + 1) % face.len()].0);
            *directed.entry(e).or_default() += 1;
        }
    }
    for (&(a, b), &count) in &directed {
        assert_eq!(count, 1, "edge {a}->{b} used {count} times");
        assert_eq!(directed.get(&(b, a)), Some(&1), "edge {a}-{b} is open");
    }
}

/// Each triangle's winding agrees with the normals it references.
fn check_normals_agree(m: &Mesh) {
    for face in &m.faces {
        let mut g = DVec3::ZERO;
        for k in 0..face.len() {
            g += m.v[face[k].0].cross(m.v[face[(k + 1) % face.len()].0]);
        }
        for c in face {
            assert!(g.dot(m.vn[c.1]) > 0.0, "face {face:?} against its normals");
        }
    }
}

/// The enclosed volume (positive when faces point outward).
fn volume(m: &Mesh) -> f64 {
    let mut v = 0.0;
    for face in &m.faces {
        let p0 = m.v[face[0].0];
        for w in face[1..].windows(2) {
            v += p0.dot(m.v[w[0].0].cross(m.v[w[1].0])) / 6.0;
        }
    }
    v
}

/// Connected parts (by shared vertices).
fn parts(m: &Mesh) -> usize {
    let mut parent: Vec<usize> = (0..m.v.len()).collect();
    fn root(p: &mut [usize], mut i: usize) -> usize {
        while p[i] != i {
            p[i] = p[p[i]];
            i = p[i];
        }
        i
    }
    for face in &m.faces {
        let a = root(&mut parent, face[0].0);
        for c in &face[1..] {
            let b = root(&mut parent, c.0);
            parent[b] = a;
        }
    }
    let used: std::collections::BTreeSet<usize> = m.faces.iter().flatten().map(|c| c.0).collect();
    let roots: std::collections::BTreeSet<usize> =
        used.into_iter().map(|i| root(&mut parent, i)).collect();
    roots.len()
}

fn check_solid(m: &Mesh) {
    check_valid(m);
    check_closed(m);
    check_normals_agree(m);
    assert!(m.faces.is_empty() || volume(m) > 0.0);
}

/// Area of the regular octagon of radius r.
fn octagon(r: f64) -> f64 {
    2.0 * std::f64::consts::SQRT_2 * r * r
}

fn v3(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x, y, z)
}

#[test]
fn single_segment_is_a_closed_tube() {
    let text = write(|w| w.segment(DVec3::ZERO, v3(0.0, 2.0, 0.0), 0.5, 0));
    let m = parse(&text);
    check_solid(&m);
    assert_eq!((m.tubes, m.spheres, parts(&m)), (1, 0, 1));
    // Two rings and two cap centres; sides, two caps.
    assert_eq!(m.v.len(), 2 * 8 + 2);
    assert_eq!(m.faces.len(), 8 + 16);
    assert!((volume(&m) - octagon(0.25) * 2.0).abs() < 1e-5);
    assert!(text.starts_with("# lsyc OBJ"));
}

#[test]
fn hairline_uses_default_radius() {
    let opts = ObjOptions {
        default_radius: 0.1,
        ..ObjOptions::default()
    };
    let m = parse(&write_with(opts, |w| {
        w.segment(DVec3::ZERO, v3(1.0, 0.0, 0.0), 0.0, 0)
    }));
    check_solid(&m);
    assert!((volume(&m) - octagon(0.1)).abs() < 1e-6);
}

#[test]
fn chain_with_turns_is_one_watertight_tube() {
    let p0 = DVec3::ZERO;
    let p1 = v3(0.0, 1.0, 0.0);
    let p2 = p1 + v3(-(30f64.to_radians().sin()), 30f64.to_radians().cos(), 0.0);
    let p3 = p2 + v3(0.3, 0.5, 0.8).normalize() * 1.5;
    let p4 = p3 + v3(1.0, 0.0, 0.0);
    let text = write(|w| {
        w.segment(p0, p1, 0.2, 0);
        w.segment(p1, p2, 0.2, 0);
        w.segment(p2, p3, 0.2, 0);
        w.segment(p3, p4, 0.2, 0);
    });
    let m = parse(&text);
    check_solid(&m);
    assert_eq!((m.tubes, m.spheres, parts(&m)), (1, 0, 1));
    // Mitres of a centrally symmetric section keep the volume: area × length.
    assert!(
        (volume(&m) - octagon(0.1) * 4.5).abs() < 1e-4,
        "{}",
        volume(&m)
    );
    // Joint rings are shared: 5 rings + 2 centres.
    assert_eq!(m.v.len(), 5 * 8 + 2);
}

#[test]
fn parallel_transport_does_not_twist() {
    // A helix-like chain: ring vertex 0 stays on the same side of the tube.
    let text = write(|w| {
        let mut p = DVec3::ZERO;
        for k in 0..40 {
            let t = k as f64 * 0.3;
            let q = p + v3(t.cos(), t.sin(), 0.4).normalize() * 0.5;
            w.segment(p, q, 0.1, 0);
            p = q;
        }
    });
    let m = parse(&text);
    check_solid(&m);
    assert_eq!(m.tubes, 1);
    // Between consecutive rings, vertex i keeps its radial direction seen
    // along the segment (no twist). The start ring comes first, then the
    // start cap's centre, then one ring per joint.
    let ring = |r: usize, i: usize| {
        if r == 0 {
            m.v[i]
        } else {
            m.v[9 + (r - 1) * 8 + i]
        }
    };
    let centre = |r: usize| (0..8).map(|i| ring(r, i)).sum::<DVec3>() / 8.0;
    for r in 0..40 {
        let d = (centre(r + 1) - centre(r)).normalize();
        let radial = |r: usize, i: usize| {
            let v = ring(r, i) - centre(r);
            (v - d * d.dot(v)).normalize()
        };
        for i in 0..8 {
            let c = radial(r, i).dot(radial(r + 1, i));
            assert!(c > 0.9999, "ring {r} vertex {i}: {c}");
        }
    }
}

#[test]
fn branch_starts_a_new_tube_with_a_sphere() {
    // F[+F]F: the branch continues the first tube; the main axis after `]`
    // starts at the joint, closed by its own caps and a sphere.
    let p = v3(0.0, 1.0, 0.0);
    let text = write(|w| {
        w.segment(DVec3::ZERO, p, 0.2, 0);
        w.segment(p, p + v3(-0.5, 0.866, 0.0), 0.1, 1);
        w.segment(p, p + v3(0.0, 1.0, 0.0), 0.2, 0);
    });
    let m = parse(&text);
    check_solid(&m);
    assert_eq!((m.tubes, m.spheres, parts(&m)), (2, 1, 3));
    assert!(text.contains("usemtl lsyc_color1\n"));
    // The sphere has the trunk's radius, centred at the joint.
    let far =
        m.v.iter()
            .filter(|v| (v.distance(p) - 0.1).abs() < 1e-6)
            .count();
    assert!(far >= 8 * 3 + 2);
}

#[test]
fn fan_of_branches_gets_one_sphere() {
    let text = write(|w| {
        for k in 0..5 {
            let a = k as f64;
            w.segment(DVec3::ZERO, v3(a.cos(), a.sin(), 0.0), 0.1, 0);
        }
    });
    let m = parse(&text);
    check_solid(&m);
    assert_eq!((m.tubes, m.spheres, parts(&m)), (5, 1, 6));
}

#[test]
fn continuation_after_pop_joins_its_chain() {
    // F[+fF]F: the chain ending at p is still open when the axis continues.
    let p = v3(0.0, 1.0, 0.0);
    let text = write(|w| {
        w.segment(DVec3::ZERO, p, 0.2, 0);
        w.segment(v3(-1.0, 2.0, 0.0), v3(-1.0, 3.0, 0.0), 0.2, 0);
        w.segment(p, v3(0.2, 2.0, 0.0), 0.2, 0);
    });
    let m = parse(&text);
    check_solid(&m);
    assert_eq!((m.tubes, m.spheres, parts(&m)), (2, 0, 2));
}

#[test]
fn sharp_turn_closes_the_chain_with_a_sphere() {
    // F|F: a reversal cannot be mitred.
    let text = write(|w| {
        w.segment(DVec3::ZERO, v3(0.0, 1.0, 0.0), 0.2, 0);
        w.segment(v3(0.0, 1.0, 0.0), v3(0.0, 0.5, 0.0), 0.2, 0);
        // A turn fine in angle but too sharp for such short segments.
        w.segment(v3(0.0, 0.5, 0.0), v3(0.05, 0.45, 0.0), 0.2, 0);
    });
    let m = parse(&text);
    check_solid(&m);
    assert_eq!((m.tubes, m.spheres, parts(&m)), (3, 2, 5));
}

#[test]
fn degenerate_segments_are_skipped() {
    let p = v3(0.0, 1.0, 0.0);
    let text = write(|w| {
        w.segment(DVec3::ZERO, DVec3::ZERO, 1.0, 0);
        w.segment(DVec3::ZERO, p, 0.1, 0);
        w.segment(p, p, 0.1, 0);
        w.segment(p, v3(0.0, 2.0, 0.0), 0.1, 0);
        w.segment(p, v3(f64::NAN, 0.0, 0.0), 0.1, 0);
        w.segment(p, v3(f64::INFINITY, 0.0, 0.0), 0.1, 0);
        w.segment(v3(0.0, 2.0, 0.0), v3(0.0, 3.0, 0.0), f64::INFINITY, 0);
    });
    let m = parse(&text);
    check_solid(&m);
    assert_eq!((m.tubes, m.spheres), (1, 0));
    assert!(m.v.iter().all(|v| v.is_finite()));
}

#[test]
fn tiny_segments_and_radii_give_no_degenerate_faces() {
    let p = v3(1000.0, 0.0, 0.0);
    let text = write(|w| {
        w.segment(DVec3::ZERO, p, 0.5, 0);
        // Too short to show: the chain just ends a little further.
        w.segment(p, p + v3(1e-9, 1e-9, 0.0), 0.5, 0);
        w.segment(p + v3(1e-9, 1e-9, 0.0), v3(1000.0, 10.0, 0.0), 0.5, 0);
        // A tube thinner than the digits resolve at this distance.
        w.segment(v3(0.0, 1000.0, 0.0), v3(10.0, 1000.0, 0.0), 1e-9, 0);
        // Tiny everything near the origin.
        w.segment(DVec3::ZERO, v3(1e-20, 0.0, 0.0), 1e-30, 0);
    });
    let m = parse(&text);
    check_solid(&m);
    assert_eq!((m.tubes, m.spheres), (2, 0));
}

#[test]
fn many_open_chains_stay_closed() {
    let text = write(|w| {
        for k in 0..200 {
            let x = k as f64;
            w.segment(v3(x, 0.0, 0.0), v3(x, 1.0, 0.0), 0.2, 0);
        }
        // Continue an early chain (closed by now) and a recent one.
        w.segment(v3(0.0, 1.0, 0.0), v3(0.0, 2.0, 0.0), 0.2, 0);
        w.segment(v3(199.0, 1.0, 0.0), v3(199.0, 2.0, 0.0), 0.2, 0);
    });
    let m = parse(&text);
    check_solid(&m);
    assert_eq!((m.tubes, m.spheres), (201, 1));
}

/// A pseudo-random bracketed 3D walk with varying widths and angles.
fn random_walk(w: &mut ObjWriter<Vec<u8>>, n: usize, seed: u64) {
    random_walk_sink(w, n, seed)
}

fn random_walk_sink(w: &mut dyn Sink, n: usize, seed: u64) {
    let mut s = seed;
    let mut rnd = move || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let (mut pos, mut h, mut l) = (DVec3::ZERO, DVec3::Y, DVec3::NEG_X);
    let mut width = 0.2;
    let mut stack = Vec::new();
    for _ in 0..n {
        let x = rnd();
        if x < 0.15 {
            stack.push((pos, h, l, width));
            width *= 0.8;
        } else if x < 0.3 {
            if let Some(st) = stack.pop() {
                (pos, h, l, width) = st;
            }
        } else if x < 0.4 {
            pos += h * (0.2 + rnd());
        } else if x < 0.7 {
            let q = DQuat::from_axis_angle(h.cross(l), (rnd() - 0.5) * 4.0);
            let r = DQuat::from_axis_angle(l, (rnd() - 0.5) * 2.0);
            h = (r * q * h).normalize();
            l = (r * q * l).normalize();
        } else {
            let q = pos + h * (0.3 + rnd());
            w.segment(pos, q, width, (rnd() * 3.0) as u32);
            pos = q;
        }
    }
}

#[test]
fn random_bracketed_walks_are_closed() {
    for seed in 0..20 {
        let m = parse(&write(|w| random_walk(w, 400, seed)));
        check_solid(&m);
        assert!(m.tubes > 0);
    }
}

#[test]
fn output_is_deterministic() {
    let a = write(|w| random_walk(w, 500, 7));
    let b = write(|w| random_walk(w, 500, 7));
    assert_eq!(a, b);
}

#[test]
fn polygon_becomes_one_face_with_its_normal() {
    let pts = [
        DVec3::ZERO,
        v3(1.0, 0.0, 0.0),
        v3(1.0, 0.0, 0.0),
        v3(1.0, 1.0, 0.0),
        v3(0.5, 0.3, 0.0),
        v3(0.0, 1.0, 0.0),
        DVec3::ZERO,
    ];
    let m = parse(&write(|w| {
        w.polygon(&pts, 2);
        // Collinear, too small and too short polygons draw nothing.
        w.polygon(&[DVec3::ZERO, v3(1.0, 0.0, 0.0), v3(2.0, 0.0, 0.0)], 0);
        let far = v3(1e6, 0.0, 0.0);
        w.polygon(
            &[far, far + v3(1e-3, 0.0, 0.0), far + v3(0.0, 1e-3, 0.0)],
            0,
        );
        w.polygon(&[DVec3::ZERO, v3(1.0, 0.0, 0.0)], 0);
    }));
    check_valid(&m);
    assert_eq!(m.faces.len(), 1);
    assert_eq!(m.faces[0].len(), 5);
    assert!(m.vn[m.faces[0][0].1].distance(DVec3::Z) < 1e-6);
}

#[test]
fn element_outline_is_placed_in_the_turtle_frame() {
    let leaf = "M0 0 C6 4 7 14 1 20 C-3 14 -5 9 -2 6 L-4 3 Z";
    let outline = outline_from_path(leaf).expect("a leaf has area");
    assert!(outline.points.len() > 10);
    let opts = ObjOptions {
        elements: vec![
            ElementOutline {
                // Clockwise: reoriented to face U.
                points: [(0.0, 0.0), (-1.0, 1.0), (0.0, 2.0), (1.0, 1.0)]
                    .map(|(x, y)| DVec2::new(x, y))
                    .to_vec(),
            },
            outline,
            ElementOutline::default(),
        ],
        ..ObjOptions::default()
    };
    // Heading +x, left +y (so U = +z, local +x is −y), scale 2, at (5, 0, 0).
    let m = parse(&write_with(opts, |w| {
        w.element(0, v3(5.0, 0.0, 0.0), DVec3::X, DVec3::Y, 2.0, 0);
        w.element(1, DVec3::ZERO, DVec3::Y, DVec3::NEG_X, 0.1, 0);
        w.element(2, DVec3::ZERO, DVec3::Y, DVec3::NEG_X, 1.0, 0);
        w.element(9, DVec3::ZERO, DVec3::Y, DVec3::NEG_X, 1.0, 0);
    }));
    check_valid(&m);
    assert_eq!(m.faces.len(), 2);
    let first: Vec<DVec3> = m.faces[0].iter().map(|c| m.v[c.0]).collect();
    for p in [
        v3(5.0, 0.0, 0.0),
        v3(7.0, 2.0, 0.0),
        v3(9.0, 0.0, 0.0),
        v3(7.0, -2.0, 0.0),
    ] {
        assert!(first.iter().any(|q| q.distance(p) < 1e-6), "{p} missing");
    }
    for face in &m.faces {
        assert!(m.vn[face[0].1].distance(DVec3::Z) < 1e-6);
        // Counter-clockwise about the normal.
        let mut a = DVec3::ZERO;
        for k in 0..face.len() {
            a += m.v[face[k].0].cross(m.v[face[(k + 1) % face.len()].0]);
        }
        assert!(a.z > 0.0);
    }
}

#[test]
fn outlines_from_paths() {
    assert_eq!(outline_from_path("M0 0 L0 10"), None);
    assert_eq!(outline_from_path(""), None);
    assert_eq!(outline_from_path("not a path"), None);
    let square = outline_from_path("M0 0 H2 V2 H0 Z").expect("square");
    assert_eq!(
        square.points,
        [(0.0, 0.0), (2.0, 0.0), (2.0, 2.0), (0.0, 2.0)].map(|(x, y)| DVec2::new(x, y))
    );
    // The largest subpath wins; bad data is no outline at all.
    let two = outline_from_path("M0 0 h1 v1 h-1 z M5 5 h3 v3 h-3 z").expect("two");
    assert_eq!(two.points[0], DVec2::new(5.0, 5.0));
    assert_eq!(
        outline_from_path("M0 0 h1 v1 h-1 z M5 5 h3 v3 h-3 z M0 0 L x"),
        None
    );
    let arc = outline_from_path("M0 0 A5 5 0 0 1 10 0 Z").expect("arc");
    assert!(arc.points.len() > 4);
}

#[test]
fn write_errors_are_reported_by_finish() {
    struct Full(usize);
    impl Write for Full {
        fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
            if self.0 < buf.len() {
                return Err(io::Error::other("disk full"));
            }
            self.0 -= buf.len();
            Ok(buf.len())
        }
        fn flush(&mut self) -> io::Result<()> {
            Ok(())
        }
    }
    let mut w = ObjWriter::new(Full(1000), ObjOptions::default());
    for k in 0..10_000 {
        let y = k as f64;
        w.segment(v3(0.0, y, 0.0), v3(0.0, y + 1.0, 0.0), 0.1, 0);
    }
    let err = w.finish().err().expect("the error");
    assert_eq!(err.to_string(), "disk full");
}

/// Forwards only segments.
struct Tubes(ObjWriter<Vec<u8>>);

impl Sink for Tubes {
    fn segment(&mut self, a: DVec3, b: DVec3, width: f64, color: u32) {
        self.0.segment(a, b, width, color);
    }
    fn polygon(&mut self, _: &[DVec3], _: u32) {}
    fn element(&mut self, _: u16, _: DVec3, _: DVec3, _: DVec3, _: f64, _: u32) {}
}

/// Every gallery program, through the real turtle, gives closed solids.
#[test]
fn gallery_programs_are_closed() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("lang-examples");
    let mut entries: Vec<_> = std::fs::read_dir(&dir)
        .expect("lang-examples")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "lsy"))
        .collect();
    entries.sort();
    let mut checked = 0;
    for path in entries {
        let text = std::fs::read_to_string(&path).expect("read");
        let front = crate::frontend::run(&text, Vec::new(), &[]);
        let Some(c) = front.checked.as_ref().filter(|_| !front.has_errors()) else {
            continue;
        };
        let Ok(prog) = crate::compile::compile(&front.file, c, None) else {
            continue;
        };
        let Ok(mut s) = crate::derive::axiom(&prog, &[], 1) else {
            continue;
        };
        // The default steps, as long as the string stays small.
        for k in 1..=prog.derive {
            match crate::derive::step(&prog, &s, k, 1, Default::default()) {
                Ok(next) if next.len() <= 800 => s = next,
                _ => break,
            }
        }
        let name = path.display();
        // Everything: valid indices and faces.
        let mut w = ObjWriter::new(Vec::new(), ObjOptions::for_program(&prog));
        let drawn = crate::turtle::interpret(&prog, &s, 1, &mut w).expect("interpret");
        let m = parse(&String::from_utf8(w.finish().expect("write")).expect("utf-8"));
        check_valid(&m);
        assert!(drawn.segments == 0 || m.tubes > 0, "{name}");
        // The tubes alone (polygons and elements are open sheets): closed.
        let mut t = Tubes(ObjWriter::new(Vec::new(), ObjOptions::for_program(&prog)));
        crate::turtle::interpret(&prog, &s, 1, &mut t).expect("interpret");
        let m = parse(&String::from_utf8(t.0.finish().expect("write")).expect("utf-8"));
        check_solid(&m);
        checked += 1;
    }
    assert!(checked > 10, "only {checked} gallery programs ran");
}
