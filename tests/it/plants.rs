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
