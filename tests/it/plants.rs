//! Plants as cpfg and L-Py users model them: tropism (ABOP §2.2) checked against
//! numbers worked out by hand, turtle queries answered in every run,
//! `consider` and `decompose` on small strings, and the gallery's fig. 2.8 trees.

use crate::support::{read_text, render_plain, root};
use lsyc::frontend;
use lsyc::run::{self, Derived, Format, Options, Picture};

fn derive(text: &str, steps: Option<u32>) -> Result<Derived, String> {
    let fe = frontend::run(text, Vec::new(), &[]);
    let checked = fe
        .checked
        .as_ref()
        .filter(|_| !fe.has_errors())
        .ok_or_else(|| render_plain(&fe.diagnostics, "test.lsy", text))?;
    let opts = Options {
        steps,
        ..Options::default()
    };
    run::derive(&fe.file, checked, &opts, &|_, _| {})
        .map_err(|d| format!("{}: {}", d.code.as_str(), d.message))
}

fn txt(d: &Derived) -> String {
    let mut out = Vec::new();
    assert!(run::write_output(d, Format::Txt, Picture::default(), 0, &mut out).is_ok());
    String::from_utf8(out)
        .unwrap_or_default()
        .trim_end()
        .to_string()
}

/// The parameters of every query module of the derived string, in order.
fn answers(d: &Derived) -> Vec<(String, Vec<f64>)> {
    let mut out = Vec::new();
    let mut p = 0;
    for &s in &d.string.syms {
        let info = &d.prog.symbols.info[s as usize];
        let n = info.arity as usize;
        let name = info.name.text().into_owned();
        if name.starts_with('?') {
            out.push((name, d.string.params[p..p + n].to_vec()));
        }
        p += n;
    }
    out
}

fn close(got: &[f64], want: &[f64]) -> bool {
    got.len() >= want.len() && got.iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-9)
}

#[track_caller]
fn assert_answer(got: &(String, Vec<f64>), name: &str, want: &[f64]) {
    assert_eq!(got.0, name);
    assert!(
        close(&got.1, want),
        "{name}: got {:?}, want {want:?}",
        got.1
    );
}

#[test]
fn tropism_bends_the_heading_by_hand_numbers() {
    // T = (1, 0, 0), e = 0.5, H = (0, 1, 0): |H × T| = 1, so the first F turns H
    // by 0.5 rad toward +x: H = (sin 0.5, cos 0.5, 0). The second F starts there,
    // |H × T| = cos 0.5, so it turns by 0.5 cos 0.5 = 0.438791 rad more: H is at
    // 0.938791 rad from +y, and the turtle stands at (sin 0.5, 1 + cos 0.5, 0).
    let d = derive(
        "lsystem T { derive 0; tropism (1, 0, 0) 0.5; axiom F ?H ?P F ?H ?P; }",
        None,
    )
    .expect("derives");
    let a = answers(&d);
    assert_answer(&a[0], "?H", &[0.479425538604203, 0.8775825618903728, 0.0]);
    assert_answer(&a[1], "?P", &[0.0, 1.0, 0.0]);
    assert_answer(&a[2], "?H", &[0.8068446226327182, 0.5907637048166268, 0.0]);
    assert_answer(&a[3], "?P", &[0.479425538604203, 1.8775825618903728, 0.0]);
}

#[test]
fn tropism_bends_a_fig_2_8_branch() {
    // Fig. 2.8a's T = (0, −1, 0), e = 0.22. The trunk points against T: no bend.
    // A branch pitched down by a = 18.95° has |H × T| = sin a, so its first F
    // turns it by 0.22 sin a rad further down: b = 0.402183 rad from +y, in the
    // y–z plane (& pitches toward −U = −z). The branch ends at
    // (0, 200 + 50 cos a, −50 sin a).
    let d = derive(
        "lsystem T { derive 0; tropism (0, -1, 0) 0.22; axiom F(200) ?H &(18.95) F(50) ?H ?P; }",
        None,
    )
    .expect("derives");
    let a = answers(&d);
    assert_answer(&a[0], "?H", &[0.0, 1.0, 0.0]);
    assert_answer(&a[1], "?H", &[0.0, 0.9202085692634495, -0.391428395819868]);
    assert_answer(&a[2], "?P", &[0.0, 247.29011636741194, -16.237145499028966]);
}

#[test]
fn tropism_module_changes_the_elasticity_for_its_branch() {
    // `tropism(0)` stops the bending; a branch sets e = 0.5 again, and `]` gives
    // back the e of its parent.
    let d = derive(
        "lsystem T { derive 0; tropism (1, 0, 0) 0.5; axiom tropism(0) F ?H [tropism(0.5) F ?H] F ?H; }",
        None,
    )
    .expect("derives");
    let a = answers(&d);
    assert_answer(&a[0], "?H", &[0.0, 1.0, 0.0]);
    assert_answer(&a[1], "?H", &[0.479425538604203, 0.8775825618903728, 0.0]);
    assert_answer(&a[2], "?H", &[0.0, 1.0, 0.0]);
    // Without a `tropism` statement T points down (0, −1, 0); the heading points
    // up, against it, so nothing bends until the turtle turns.
    let d = derive(
        "lsystem T { derive 0; axiom tropism(0.5) +(90) F ?H; }",
        None,
    )
    .expect("derives");
    // H = (−1, 0, 0) after the turn; |H × T| = 1: H turns 0.5 rad toward −y.
    assert_answer(
        &answers(&d)[0],
        "?H",
        &[-0.8775825618903728, -0.479425538604203, 0.0],
    );
}

#[test]
fn turtle_queries_are_answered_in_every_run() {
    // ?U and ?L give the frame: U = +z, L = −x at the start; after &(90) the
    // heading points down −z and U has taken H's place, +y.
    let d = derive("lsystem Q { derive 0; axiom ?U ?L &(90) ?U ?H; }", None).expect("derives");
    let a = answers(&d);
    assert_answer(&a[0], "?U", &[0.0, 0.0, 1.0]);
    assert_answer(&a[1], "?L", &[-1.0, 0.0, 0.0]);
    assert_answer(&a[2], "?U", &[0.0, 1.0, 0.0]);
    assert_answer(&a[3], "?H", &[0.0, 0.0, -1.0]);
}

#[test]
fn growth_stops_at_a_height() {
    // The apex ?P(x, y, z, n) grows F(2) at 60° from the vertical while y < 5:
    // each step climbs 2 cos 60° = 1, so after five steps y = 5 and the apex is
    // removed. The shoot ends at (−2 sin 60° · 5, 5) = (−8.660254, 5).
    let text = "lsystem Stop {
        derive 20;
        axiom +(60) ?P(0);
        ?P(_, y, _, _) : y >= 5 -> ;
        ?P(_, _, _, n) -> F(2) ?P(n + 1);
    }";
    let d = derive(text, None).expect("derives");
    assert_eq!(txt(&d), "+(60) F(2) F(2) F(2) F(2) F(2)");
    // Four steps: the apex is still there, at y = 4.
    let d4 = derive(text, Some(4)).expect("derives");
    let a = answers(&d4);
    assert_eq!(a.len(), 1);
    assert_answer(&a[0], "?P", &[-4.0 * 3f64.sqrt(), 4.0, 0.0]);
    let (drawn, _) = run::measure(&d, 0).expect("draws");
    let bbox = drawn.bbox.expect("drawn");
    assert!((bbox[0] + 8.660254037844386).abs() < 1e-9, "{bbox:?}");
    assert!((bbox[3] - 5.0).abs() < 1e-9, "{bbox:?}");
}

#[test]
fn decomposition_runs_after_each_step_until_nothing_matches() {
    let text = "lsystem D {
        axiom A;
        A -> AB;
        decompose B -> CD;
        decompose C -> E;
    }";
    // Not on the axiom: decomposition follows a derivation step.
    assert_eq!(txt(&derive(text, Some(0)).expect("derives")), "A");
    // A B → A C D → A E D.
    assert_eq!(txt(&derive(text, Some(1)).expect("derives")), "AED");
    assert_eq!(txt(&derive(text, Some(2)).expect("derives")), "AEDED");
    // Conditions choose the rule, parameters flow through.
    let text = "lsystem D {
        axiom A(3);
        A(n) -> A(n);
        decompose A(n) : n > 0 -> F(n) A(n - 1);
    }";
    assert_eq!(
        txt(&derive(text, Some(1)).expect("derives")),
        "F(3) F(2) F(1) A(0)"
    );
}

#[test]
fn runaway_decomposition_is_an_error_naming_its_chain() {
    let text = "lsystem D {
        axiom X;
        X -> A;
        decompose A -> B;
        decompose B -> A;
    }";
    let Err(e) = derive(text, Some(1)) else {
        panic!("a runaway decomposition must fail")
    };
    assert!(e.starts_with("E0910"), "{e}");
    assert!(e.contains("`A` → `B` → `A`"), "{e}");
}

#[test]
fn consider_is_the_complement_of_ignore() {
    // B sees A through X and Y when only A and B are considered; without the
    // list the neighbour is Y and the rule does not fire.
    let with = "lsystem C { axiom A X Y B; consider A B; A < B -> C; }";
    assert_eq!(txt(&derive(with, Some(1)).expect("derives")), "AXYC");
    let ignore = "lsystem C { axiom A X Y B; ignore X Y; A < B -> C; }";
    assert_eq!(txt(&derive(ignore, Some(1)).expect("derives")), "AXYC");
    let neither = "lsystem C { axiom A X Y B; A < B -> C; }";
    assert_eq!(txt(&derive(neither, Some(1)).expect("derives")), "AXYB");
    // Brackets keep their meaning: a sibling branch is skipped, not considered.
    let branch = "lsystem C { axiom A[X B]Y B; consider A B; A < B -> C; }";
    assert_eq!(txt(&derive(branch, Some(1)).expect("derives")), "A[XC]YC");
}

#[test]
fn fig_2_8_trees_bend_as_their_tropism_says() {
    // The four trees share one L-system; tropism is what bends them. Tree d's T
    // leans toward −x: its crown's extent is on the −x side. Trees a and b
    // (T straight down) are close to symmetric about the trunk.
    for (name, lean) in [("a", false), ("b", false), ("c", false), ("d", true)] {
        let path = root().join(format!("lang-examples/tropism-tree-{name}.lsy"));
        let text = read_text(&path);
        assert!(text.contains("tropism ("), "{name}");
        let d = derive(&text, None).expect("derives");
        let (drawn, _) = run::measure(&d, 0).expect("draws");
        let [x0, _, x1, _] = drawn.bbox.expect("drawn");
        if lean {
            assert!(-x0 > 2.0 * x1, "tree {name}: {x0} .. {x1}");
        } else {
            assert!(
                -x0 < 2.0 * x1 && x1 < -2.0 * x0,
                "tree {name}: {x0} .. {x1}"
            );
        }
        // Without tropism the same tree is different: the statement does something.
        let flat = text.replace("tropism (", "// tropism (");
        let d0 = derive(&flat, None).expect("derives");
        let (drawn0, _) = run::measure(&d0, 0).expect("draws");
        assert_ne!(drawn0.bbox, drawn.bbox, "tree {name}");
    }
}

/// Renders `program` to SVG and PNG with the binary.
fn render_both(program: &str, dir: &std::path::Path, name: &str) -> (String, tiny_skia::Pixmap) {
    let src = dir.join(format!("{name}.lsy"));
    std::fs::write(&src, program).expect("writes");
    let mut outs = Vec::new();
    for ext in ["svg", "png"] {
        let out = dir.join(format!("{name}.{ext}"));
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_lsyc"))
            .args(["run", src.to_str().expect("utf-8"), "-o"])
            .arg(&out)
            .args(["--size", "200"])
            .output()
            .expect("lsyc runs");
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        outs.push(out);
    }
    let svg = std::fs::read_to_string(&outs[0]).expect("svg");
    let png = tiny_skia::Pixmap::decode_png(&std::fs::read(&outs[1]).expect("png")).expect("png");
    (svg, png)
}

/// The fill colour usvg reads for the element paths of an SVG (`None`: no fill).
fn svg_element_fills(svg: &str) -> Vec<Option<[u8; 3]>> {
    let tree = usvg::Tree::from_str(svg, &usvg::Options::default()).expect("usvg reads it");
    let mut out = Vec::new();
    fn walk(g: &usvg::Group, out: &mut Vec<Option<[u8; 3]>>) {
        for n in g.children() {
            match n {
                usvg::Node::Group(g) => walk(g, out),
                usvg::Node::Path(p) if p.stroke().is_none() || p.fill().is_some() => {
                    out.push(p.fill().and_then(|f| match f.paint() {
                        usvg::Paint::Color(c) => Some([c.red, c.green, c.blue]),
                        _ => None,
                    }))
                }
                usvg::Node::Path(_) => out.push(None),
                _ => {}
            }
        }
    }
    walk(tree.root(), &mut out);
    out
}

#[test]
fn png_and_svg_agree_on_element_fills() {
    // One square element fills the picture; the centre pixel of the PNG must
    // be the colour the SVG gives the element (or the background for "none").
    let dir = tempfile::tempdir().expect("tempdir");
    for (fill, stroke) in [
        ("fill \"#d03020\";", ""),
        ("fill \"none\";", "stroke \"#2040d0\"; width 2;"),
        ("", ""),
    ] {
        let program = format!(
            "element Sq {{ path \"M-5 0 L5 0 L5 10 L-5 10 Z\"; {fill} {stroke} }}\nlsystem S {{ axiom Sq; }}\n"
        );
        let (svg, png) = render_both(&program, dir.path(), "sq");
        let fills = svg_element_fills(&svg);
        assert_eq!(fills.len(), 1, "{fill}: {fills:?}\n{svg}");
        let c = png
            .pixel(png.width() / 2, png.height() / 2)
            .expect("centre");
        let got = [c.red(), c.green(), c.blue()];
        match fills[0] {
            Some(want) => assert_eq!(got, want, "{fill}: the PNG paints another colour"),
            None => assert!(
                got.iter().all(|&v| v > 230),
                "{fill}: the PNG fills an element the SVG leaves empty: {got:?}"
            ),
        }
    }
}

/// A mesh target that keeps everything, for checking a mesh's numbers.
#[derive(Default)]
struct Mesh {
    v: Vec<glam::DVec3>,
    vn: Vec<glam::DVec3>,
    faces: Vec<Vec<(u64, u64)>>,
}

impl lsyc::render::obj::MeshTarget for Mesh {
    fn vertex(&mut self, p: glam::DVec3) {
        self.v.push(p);
    }
    fn normal(&mut self, n: glam::DVec3) {
        self.vn.push(n);
    }
    fn face(&mut self, corners: &[(u64, u64)]) {
        self.faces.push(corners.to_vec());
    }
    fn material(&mut self, _: u32) {}
    fn object(&mut self, _: &str) {}
}

fn mesh_of(d: &Derived) -> Mesh {
    let options = lsyc::render::obj::ObjOptions::for_program(&d.prog);
    let mut b = lsyc::render::obj::MeshBuilder::with_target(Mesh::default(), options);
    d.interpret(0, &mut b).expect("draws");
    b.into_target()
}

/// Every face index in range, every normal of unit length.
#[track_caller]
fn assert_valid_mesh(m: &Mesh) {
    assert!(!m.faces.is_empty());
    for f in &m.faces {
        assert!(f.len() >= 3);
        for &(v, n) in f {
            assert!(
                v >= 1 && v as usize <= m.v.len(),
                "vertex {v} of {}",
                m.v.len()
            );
            assert!(
                n >= 1 && n as usize <= m.vn.len(),
                "normal {n} of {}",
                m.vn.len()
            );
        }
    }
    for n in &m.vn {
        assert!((n.length() - 1.0).abs() < 1e-9, "normal {n}");
    }
}

#[test]
fn organs_are_placed_in_the_turtle_frame() {
    // After F(2) the turtle stands at (0, 2, 0); +(90) turns H from +y to −x
    // (L from −x to −y), *(2) doubles the scale. The sphere of radius 1 is then
    // centred at (0, 2, 0) with radius 2, its local +y pole at (0,2,0) + 2H =
    // (−2, 2, 0); the disk of radius 1 lies across H: its rim at local +x
    // (along −L = +y) is at (0, 4, 0).
    let d = derive(
        "element B { sphere 1; }\nelement D { disk 1; }\nlsystem S { axiom F(2) +(90) *(2) B D; }\n",
        None,
    )
    .expect("derives");
    let m = mesh_of(&d);
    assert_valid_mesh(&m);
    let centre = glam::DVec3::new(0.0, 2.0, 0.0);
    let has = |p: glam::DVec3| m.v.iter().any(|v| (*v - p).length() < 1e-9);
    assert!(has(glam::DVec3::new(-2.0, 2.0, 0.0)), "the sphere's pole");
    assert!(
        has(glam::DVec3::new(2.0, 2.0, 0.0)),
        "the sphere's other pole"
    );
    assert!(has(glam::DVec3::new(0.0, 4.0, 0.0)), "the disk's rim");
    // Sphere vertices are 2 from the centre and their normals point outward.
    let on_sphere =
        m.v.iter()
            .filter(|v| ((**v - centre).length() - 2.0).abs() < 1e-9)
            .count();
    assert!(on_sphere >= 50, "{on_sphere} sphere vertices");
    for f in &m.faces {
        let p = m.v[f[0].0 as usize - 1];
        let n = m.vn[f[0].1 as usize - 1];
        if ((p - centre).length() - 2.0).abs() < 1e-9 && p.x.abs() > 1e-6 {
            assert!(n.dot(p - centre) > 0.0, "an inward normal at {p}");
        }
    }
    // The disk faces along H (−x).
    assert!(
        m.vn.iter()
            .any(|n| (*n - glam::DVec3::NEG_X).length() < 1e-9)
    );
    let (drawn, _) = run::measure(&d, 0).expect("measures");
    assert_eq!(drawn.elements, 2);
    let b = drawn.bbox.expect("a box");
    assert!(
        (b[0] + 2.0).abs() < 1e-9 && (b[3] - 4.0).abs() < 1e-9,
        "{b:?}"
    );
}

#[test]
fn contours_shape_the_tube_rings() {
    // A square contour of half-side 1 and width 2 (radius 1): the ring of
    // F(3) from the origin has its corners at (±1, y, ±1) in some rotation,
    // all √2 from the axis; without the contour the ring is a circle.
    let prog = "element Sq { contour \"M1 1 L-1 1 L-1 -1 L1 -1 Z\"; }\nlsystem S { axiom !(2) Sq F(3) [Sq] F(1); }\n";
    let d = derive(prog, None).expect("derives");
    let m = mesh_of(&d);
    assert_valid_mesh(&m);
    let off_axis: Vec<f64> =
        m.v.iter()
            .filter(|v| v.y.abs() < 1e-9)
            .map(|v| (v.x * v.x + v.z * v.z).sqrt())
            .filter(|r| *r > 1e-9)
            .collect();
    assert_eq!(off_axis.len(), 4, "a square ring: {off_axis:?}");
    assert!(off_axis.iter().all(|r| (r - 2f64.sqrt()).abs() < 1e-9));
    let circle = derive("lsystem S { axiom !(2) F(3); }\n", None).expect("derives");
    let m = mesh_of(&circle);
    let ring =
        m.v.iter()
            .filter(|v| v.y.abs() < 1e-9 && v.length() > 1e-9)
            .count();
    assert_eq!(ring, 8);
}

#[test]
fn patches_and_the_gallery_plant_are_valid_meshes() {
    let text = read_text(&root().join("lang-examples/flowering-plant.lsy"));
    let d = derive(&text, None).expect("derives");
    let m = mesh_of(&d);
    assert_valid_mesh(&m);
    let (drawn, _) = run::measure(&d, 0).expect("measures");
    assert!(drawn.elements > 20);
}

fn lsyc_in(dir: &std::path::Path, args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_lsyc"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("lsyc runs")
}

#[test]
fn mesh_files_are_read_beside_the_program() {
    let out = tempfile::tempdir().expect("tempdir");
    let data = root().join("tests/data/organs");
    let obj = out.path().join("m.obj");
    // Run from elsewhere: the mesh is found beside the program, not the cwd.
    let o = lsyc_in(
        out.path(),
        &[
            "run",
            data.join("mesh.lsy").to_str().expect("utf-8"),
            "-o",
            obj.to_str().expect("utf-8"),
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&obj).expect("obj");
    // The leaf's corner (0.5, 1, 0) at scale 3 after F(2): (1.5, 5, 0)
    // (local +x is −L, which is +x at the start).
    assert!(text.contains("v 1.5 5 0"), "{text}");
    for (file, want) in [
        ("mesh-missing.lsy", "mesh-missing.lsy:1:"),
        ("mesh-broken.lsy", "line 3"),
    ] {
        let o = lsyc_in(
            out.path(),
            &[
                "run",
                data.join(file).to_str().expect("utf-8"),
                "-o",
                obj.to_str().expect("utf-8"),
            ],
        );
        assert_eq!(o.status.code(), Some(1), "{file}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains("E0911") && err.contains(want), "{file}: {err}");
    }
}

/// The colours usvg reads on every painted path of an SVG (fills and strokes).
fn svg_colours(svg: &str) -> Vec<[u8; 3]> {
    let tree = usvg::Tree::from_str(svg, &usvg::Options::default()).expect("usvg reads it");
    let mut out = Vec::new();
    fn paint(p: &usvg::Paint, out: &mut Vec<[u8; 3]>) {
        if let usvg::Paint::Color(c) = p {
            out.push([c.red, c.green, c.blue]);
        }
    }
    fn walk(g: &usvg::Group, out: &mut Vec<[u8; 3]>) {
        for n in g.children() {
            match n {
                usvg::Node::Group(g) => walk(g, out),
                usvg::Node::Path(p) => {
                    if let Some(f) = p.fill() {
                        paint(f.paint(), out);
                    }
                    if let Some(s) = p.stroke() {
                        paint(s.paint(), out);
                    }
                }
                _ => {}
            }
        }
    }
    walk(tree.root(), &mut out);
    out.sort_unstable();
    out.dedup();
    out
}

#[test]
fn png_and_svg_agree_on_every_colour() {
    // Segments of two colours and widths, a polygon, a flat element with its
    // own fill and stroke, and a 3D organ (one flat-shaded colour: a disk):
    // every colour the SVG paints is painted, exactly, somewhere in the PNG.
    let dir = tempfile::tempdir().expect("tempdir");
    let program = "element Sq { path \"M-2 0 L2 0 L2 4 L-2 4 Z\"; fill \"#d03020\"; stroke \"#2040d0\"; width 3; }\n\
        element Dk { disk 3; fill \"#e0b000\"; }\n\
        lsystem S { axiom !(1) '(1) F(10) '(8) [+(90) F(8)] '(10) {. f(6) . -(90) f(6) . -(90) f(6) .} f(12) Sq f(10) Dk; }\n";
    let (svg, png) = render_both(program, dir.path(), "all");
    let want = svg_colours(&svg);
    assert!(want.len() >= 5, "{want:?}");
    let mut have = std::collections::BTreeSet::new();
    for p in png.pixels() {
        if p.alpha() == 255 {
            have.insert([p.red(), p.green(), p.blue()]);
        }
    }
    for c in &want {
        assert!(have.contains(c), "the SVG paints {c:?}, the PNG nowhere");
    }
}

#[test]
fn a_palette_states_the_colours_of_every_output() {
    // Colour 1 is the program's; 2 is not listed and keeps the built-in
    // colour; bare `'` steps from 1 to 2 and stops at the palette's last index.
    let program = "palette {\n    1 \"#102030\" bark;\n    2 \"#a0b0c0\";\n}\nlsystem S { axiom '(1) F ' +(90) F ' +(90) F; }\n";
    let d = derive(program, None).expect("derives");
    let mut svg = Vec::new();
    assert!(run::write_output(&d, Format::Svg, Picture::default(), 0, &mut svg).is_ok());
    let svg = String::from_utf8(svg).expect("utf-8");
    assert!(svg.contains("stroke=\"#102030\""), "{svg}");
    assert!(svg.contains("stroke=\"#a0b0c0\""), "{svg}");
    // The third segment: bare ' past the last index stays at 2.
    assert_eq!(svg.matches("stroke=\"#a0b0c0\"").count(), 1, "{svg}");
    let mut obj = Vec::new();
    let written = run::write_output_full(&d, Format::Obj, &Picture::default(), 0, &mut obj)
        .unwrap_or_else(|_| panic!("writes OBJ"));
    let obj = String::from_utf8(obj).expect("utf-8");
    assert!(obj.contains("usemtl bark"), "{obj}");
    assert!(obj.contains("usemtl lsyc_color2"), "{obj}");
    let mut mtl = Vec::new();
    lsyc::render::obj::write_mtl_with(&mut mtl, &written.materials, &written.palette).expect("mtl");
    let mtl = String::from_utf8(mtl).expect("utf-8");
    assert!(
        mtl.contains("newmtl bark") && mtl.contains("# #102030"),
        "{mtl}"
    );
    // Without a palette, bare ' gives ABOP's greens (3 and on).
    let plain = derive("lsystem S { axiom F ' F; }\n", None).expect("derives");
    let mut svg = Vec::new();
    assert!(run::write_output(&plain, Format::Svg, Picture::default(), 0, &mut svg).is_ok());
    let want = format!("stroke=\"{}\"", lsyc::render::palette(3));
    assert!(String::from_utf8(svg).expect("utf-8").contains(&want));
}
