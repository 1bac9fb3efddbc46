//! Guide editing by a mass-spring system (`lsyc edit`): drag guide vertices,
//! translate, rotate or scale guides, relax the rest, write the new polygons back.
//!
//! Owns: the edit operations and their argument syntax (here), and the three
//! steps of an edit: reading the scene's guides from the AST (`parse`), turning
//! them into particles and springs and relaxing them (`solve`, on `spring`), and
//! writing the solved positions back into the AST (`write`) so that
//! `fmt::format_file` prints the program with its comments and layout. Must not
//! print or touch files: the command line does that.
//!
//! What the system is made of (Guided Procedural Modeling, §4.2):
//! - every guide vertex is a particle; vertices of different guides closer than
//!   [`SNAP`] × the scene size are one particle (snapped guides share it);
//! - every polygon edge is a spring of stiffness [`K_EDGE`], and diagonals make
//!   each polygon rigid-ish (all of them up to 6 vertices; above, each vertex to
//!   the one after next and to the opposite one), stiffness [`K_DIAGONAL`];
//! - an edge that carries a link (either end) is a stiff spring, [`K_LINK`], so
//!   linked edges keep their length; `--stiff A.vI=B.vJ` adds a spring of
//!   stiffness [`K_STIFF`] between any two vertices, as the paper's user-chosen
//!   stiff springs between guides;
//! - dragged vertices (and `--pin`ned ones) are constraints, the others relax.
//!
//! Written back: a coordinate changes only if its value, rounded to the scene's
//! precision, changed. The precision is 10^⌊log10(size / 1000)⌋ (size: the
//! bounding-box diagonal of the scene's guides), or finer when a number given on
//! the command line has more decimals, so a dragged vertex lands exactly where it
//! was asked to. A coordinate written as an expression (`(w, 0)`) is kept while
//! its vertex stays; when it moves it is replaced by the number (reported in
//! [`Outcome::replaced`]).

mod parse;
mod solve;
pub mod spring;
mod write;

use crate::ast::File;
use crate::check::Checked;
use crate::number::decimals;
use glam::DVec2;

/// Stiffness of a polygon edge.
pub const K_EDGE: f64 = 1.0;
/// Stiffness of a diagonal spring.
pub const K_DIAGONAL: f64 = 1.0;
/// Stiffness of an edge that carries a link.
pub const K_LINK: f64 = 100.0;
/// Stiffness of a `--stiff` spring.
pub const K_STIFF: f64 = 100.0;
/// The inertia weight w = m/h² of every particle (relative to `K_EDGE`).
pub const INERTIA: f64 = 0.001;
/// Vertices closer than this fraction of the scene size are one particle.
pub const SNAP: f64 = 1e-4;

/// `GUIDE.vK`: vertex K (from 0) of a guide's polygon.
#[derive(Clone, Debug, PartialEq)]
pub struct VertexRef {
    pub guide: String,
    pub index: usize,
}

impl std::fmt::Display for VertexRef {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}.v{}", self.guide, self.index)
    }
}

/// One edit operation, as given on the command line.
#[derive(Clone, Debug, PartialEq)]
pub enum Op {
    /// `--move GUIDE.vK=X,Y`: the vertex goes to (X, Y).
    Move(VertexRef, DVec2),
    /// `--by GUIDE.vK=DX,DY`: the vertex moves by (DX, DY).
    By(VertexRef, DVec2),
    /// `--translate GUIDE=DX,DY`
    Translate(String, DVec2),
    /// `--rotate GUIDE=DEG`: counter-clockwise about the guide's centroid.
    Rotate(String, f64),
    /// `--scale GUIDE=K`: about the guide's centroid.
    Scale(String, f64),
    /// `--pin GUIDE.vK` or `--pin GUIDE`: held where it is.
    Pin(String, Option<usize>),
    /// `--stiff A.vI=B.vJ`: a stiff spring between two vertices.
    Stiff(VertexRef, VertexRef),
}

impl Op {
    /// The decimals the numbers of this operation were written with (for the
    /// precision of the output).
    fn decimals(&self) -> usize {
        match self {
            Op::Move(_, p) | Op::By(_, p) | Op::Translate(_, p) => decimals(p.x).max(decimals(p.y)),
            _ => 0,
        }
    }

    fn guides(&self) -> Vec<&str> {
        match self {
            Op::Move(v, _) | Op::By(v, _) => vec![&v.guide],
            Op::Translate(g, _) | Op::Rotate(g, _) | Op::Scale(g, _) | Op::Pin(g, _) => vec![g],
            Op::Stiff(a, b) => vec![&a.guide, &b.guide],
        }
    }

    fn vertices(&self) -> Vec<&VertexRef> {
        match self {
            Op::Move(v, _) | Op::By(v, _) => vec![v],
            Op::Stiff(a, b) => vec![a, b],
            _ => Vec::new(),
        }
    }
}

fn number(s: &str, what: &str) -> Result<f64, String> {
    let t = s.trim();
    match t.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(format!("`{t}` is not a number ({what})")),
    }
}

fn pair(s: &str, what: &str) -> Result<DVec2, String> {
    let Some((a, b)) = s.split_once(',') else {
        return Err(format!("`{s}` is not two numbers `X,Y` ({what})"));
    };
    Ok(DVec2::new(number(a, what)?, number(b, what)?))
}

fn guide_name(s: &str, form: &str) -> Result<String, String> {
    let t = s.trim();
    let ok = t
        .chars()
        .next()
        .is_some_and(|c| c.is_alphabetic() || c == '_')
        && t.chars().all(|c| c.is_alphanumeric() || c == '_');
    if ok {
        Ok(t.to_string())
    } else {
        Err(format!("`{t}` is not a guide name; write {form}"))
    }
}

/// Parses `GUIDE.vK`.
pub fn parse_vertex(s: &str) -> Result<VertexRef, String> {
    let form = "GUIDE.vK, e.g. trunk.v2";
    let Some((g, k)) = s.trim().rsplit_once('.') else {
        return Err(format!("`{s}` names no vertex; write {form}"));
    };
    let digits = k.strip_prefix('v').unwrap_or("");
    if digits.is_empty() || !digits.chars().all(|c| c.is_ascii_digit()) {
        return Err(format!(
            "`{k}` is not a vertex; vertices are v0, v1, …; write {form}"
        ));
    }
    let index = digits
        .parse::<usize>()
        .map_err(|_| format!("`{k}` is not a vertex number"))?;
    Ok(VertexRef {
        guide: guide_name(g, form)?,
        index,
    })
}

fn split_eq<'a>(s: &'a str, form: &str) -> Result<(&'a str, &'a str), String> {
    s.split_once('=')
        .ok_or_else(|| format!("`{s}` has no `=`; write {form}"))
}

/// Parses the value of `--move`: `GUIDE.vK=X,Y`.
pub fn parse_move(s: &str) -> Result<Op, String> {
    let (v, p) = split_eq(s, "GUIDE.vK=X,Y, e.g. trunk.v2=40,310")?;
    Ok(Op::Move(parse_vertex(v)?, pair(p, "the target X,Y")?))
}

/// Parses the value of `--by`: `GUIDE.vK=DX,DY`.
pub fn parse_by(s: &str) -> Result<Op, String> {
    let (v, p) = split_eq(s, "GUIDE.vK=DX,DY, e.g. trunk.v2=10,0")?;
    Ok(Op::By(parse_vertex(v)?, pair(p, "the offset DX,DY")?))
}

/// Parses the value of `--translate`: `GUIDE=DX,DY`.
pub fn parse_translate(s: &str) -> Result<Op, String> {
    let form = "GUIDE=DX,DY, e.g. crown=10,-5";
    let (g, p) = split_eq(s, form)?;
    Ok(Op::Translate(
        guide_name(g, form)?,
        pair(p, "the offset DX,DY")?,
    ))
}

/// Parses the value of `--rotate`: `GUIDE=DEG`.
pub fn parse_rotate(s: &str) -> Result<Op, String> {
    let form = "GUIDE=DEG, e.g. crown=15";
    let (g, a) = split_eq(s, form)?;
    Ok(Op::Rotate(
        guide_name(g, form)?,
        number(a, "the angle in degrees")?,
    ))
}

/// Parses the value of `--scale`: `GUIDE=K` with K > 0.
pub fn parse_scale(s: &str) -> Result<Op, String> {
    let form = "GUIDE=K, e.g. crown=1.5";
    let (g, k) = split_eq(s, form)?;
    let k = number(k, "the scale factor")?;
    if k <= 0.0 {
        return Err(format!("a scale factor must be positive, not {k}"));
    }
    Ok(Op::Scale(guide_name(g, form)?, k))
}

/// Parses the value of `--pin`: `GUIDE.vK` or `GUIDE`.
pub fn parse_pin(s: &str) -> Result<Op, String> {
    if s.contains('.') {
        let v = parse_vertex(s)?;
        Ok(Op::Pin(v.guide, Some(v.index)))
    } else {
        Ok(Op::Pin(
            guide_name(s, "GUIDE or GUIDE.vK, e.g. trunk or trunk.v0")?,
            None,
        ))
    }
}

/// Parses the value of `--stiff`: `A.vI=B.vJ`.
pub fn parse_stiff(s: &str) -> Result<Op, String> {
    let (a, b) = split_eq(s, "A.vI=B.vJ, e.g. trunk.v2=crown.v0")?;
    Ok(Op::Stiff(parse_vertex(a)?, parse_vertex(b)?))
}

/// Why an edit could not be made.
#[derive(Clone, Debug, PartialEq)]
pub enum EditError {
    /// A problem in the program (exit 1).
    Input(String),
    /// A problem in the arguments (exit 2), with an optional hint.
    Usage(String, Option<String>),
}

/// Choices beyond the operations.
#[derive(Clone, Debug, Default)]
pub struct Options {
    /// The scene to edit (default: the first of the file).
    pub scene: Option<String>,
    /// Carry the seeds of a moved guide along (position and heading), by the
    /// affine map that best fits the guide's old vertices to its new ones.
    pub move_seeds: bool,
}

/// What an edit did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Outcome {
    /// The scene edited.
    pub scene: String,
    /// Guides whose polygon changed, in source order, with how many vertices moved.
    pub changed: Vec<(String, usize)>,
    /// Coordinates written as expressions that were replaced by numbers.
    pub replaced: Vec<String>,
    pub particles: usize,
    pub springs: usize,
    /// Particles that relaxed (connected to a dragged one, not dragged).
    pub free: usize,
    pub iterations: usize,
    pub converged: bool,
    /// Decimals the coordinates are written with.
    pub decimals: usize,
    /// Seeds carried along with their guides (`--move-seeds`).
    pub seeds_moved: usize,
    /// Things a person should know (seeds left outside their moved guide).
    pub warnings: Vec<String>,
}

/// Applies `ops` to a scene of `file` (the one named `scene`, or the first) and
/// writes the changed polygons into `file`. `checked` gives the constants'
/// values; the file must have checked without errors.
pub fn edit(
    file: &mut File,
    checked: &Checked,
    ops: &[Op],
    options: &Options,
) -> Result<Outcome, EditError> {
    // Parse: the scene and its guides.
    let scenes = parse::scenes(file);
    let (item, sc) = parse::choose(&scenes, options.scene.as_deref())?;
    let mut guides = parse::collect_guides(sc, checked)?;
    parse::validate(ops, sc, &guides, &scenes)?;
    let size = parse::scene_size(&guides);

    // Solve: particles, springs, targets, relaxation.
    let sys = solve::particles(&mut guides, size);
    let springs = solve::build(sys, &guides, sc, checked, ops);
    let pins = solve::targets(ops, &springs, &guides, sc)?;
    let sol = solve::solve(&springs.sys, &pins, size);
    let base = (-(size / 1000.0).log10().floor()).clamp(0.0, 12.0) as usize;
    let places = ops.iter().map(Op::decimals).fold(base, usize::max);
    let mut outcome = Outcome {
        scene: sc.name.name.clone(),
        particles: springs.sys.rest.len(),
        springs: springs.sys.springs.len(),
        free: sol.free,
        iterations: sol.iterations,
        converged: sol.converged,
        decimals: places,
        ..Outcome::default()
    };

    // Write back.
    let solved = write::Solved {
        guides: &guides,
        rest: &springs.sys.rest,
        positions: &sol.positions,
        places,
        checked,
        options,
    };
    write::write_back(file, item, &solved, &mut outcome)?;
    Ok(outcome)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frontend;

    const SCENE: &str = "\
const w = 10;
lsystem A { axiom F; }
scene S {
    guide a { polygon (0, 0) (w, 0) (w, 10) (0, 10); system A; } // a
    guide b { polygon (10, 0) (20, 0) (20, 10) (10, 10); system A; } // snapped to a
    guide c { polygon (50, 50) (60, 50) (55, 60); system A; } // alone
    link a.edge(3) -> c.edge(0) { tokens 1; }
}
";

    fn run(text: &str, ops: &[Op]) -> Result<(String, Outcome), EditError> {
        let fe = frontend::run(text, Vec::new(), &[]);
        assert!(!fe.has_errors(), "{:?}", fe.diagnostics);
        let checked = fe.checked.as_ref().expect("checked");
        let mut file = fe.file.clone();
        let out = edit(&mut file, checked, ops, &Options::default())?;
        Ok((crate::fmt::format_file(&file), out))
    }

    fn polygon_line<'a>(text: &'a str, guide: &str) -> &'a str {
        let mut lines = text
            .lines()
            .skip_while(|l| !l.contains(&format!("guide {guide} ")));
        lines.find(|l| l.contains("polygon")).unwrap_or("")
    }

    #[test]
    fn no_operation_leaves_the_program_as_fmt_prints_it() {
        let (out, o) = run(SCENE, &[]).expect("edits");
        let fe = frontend::run(SCENE, Vec::new(), &[]);
        assert_eq!(out, crate::fmt::format_file(&fe.file));
        assert!(o.changed.is_empty());
        assert_eq!(o.free, 0);
    }

    #[test]
    fn snapped_guides_share_particles_and_move_together() {
        // a.v1 = b.v0 and a.v2 = b.v3 are one particle each.
        let ops = [parse_move("a.v1=12,0").expect("parses")];
        let (out, o) = run(SCENE, &ops).expect("edits");
        assert_eq!(o.particles, 4 + 2 + 3);
        let a = polygon_line(&out, "a");
        let b = polygon_line(&out, "b");
        assert!(a.contains("(12, 0)"), "{a}");
        assert!(b.contains("polygon (12, 0)"), "{b}");
        // The alone guide is untouched, byte for byte.
        assert_eq!(
            polygon_line(&out, "c").trim(),
            "polygon (50, 50) (60, 50) (55, 60);"
        );
        assert_eq!(
            o.changed.iter().map(|c| c.0.as_str()).collect::<Vec<_>>(),
            ["a", "b"]
        );
    }

    #[test]
    fn expressions_stay_unless_their_coordinate_moves() {
        let ops = [
            parse_by("a.v0=0,-2").expect("parses"),
            parse_by("a.v1=0,-2").expect("parses"),
            parse_pin("a.v2").expect("parses"),
            parse_pin("a.v3").expect("parses"),
        ];
        let (out, o) = run(SCENE, &ops).expect("edits");
        let a = polygon_line(&out, "a");
        // x of v1 did not change: `w` stays; its y is now -2.
        assert!(a.contains("(w, -2)"), "{a}");
        assert!(o.replaced.is_empty(), "{:?}", o.replaced);
        let ops = [parse_translate("a=1,0").expect("parses")];
        let (out, o) = run(SCENE, &ops).expect("edits");
        assert!(polygon_line(&out, "a").contains("(11, 0)"), "{out}");
        assert_eq!(o.replaced.len(), 2, "{:?}", o.replaced);
    }

    #[test]
    fn rotate_and_scale_about_the_centroid() {
        let ops = [parse_rotate("c=180").expect("parses")];
        let (_, o) = run(SCENE, &ops).expect("edits");
        assert_eq!(o.changed, [("c".to_string(), 3)]);
        let ops = [parse_scale("a=2").expect("parses")];
        let (out, _) = run(SCENE, &ops).expect("edits");
        assert!(
            polygon_line(&out, "a").contains("polygon (-5, -5) (15, -5) (15, 15) (-5, 15)"),
            "{out}"
        );
    }

    #[test]
    fn errors_name_the_guide_and_the_vertex() {
        let e = run(SCENE, &[parse_move("aa.v0=1,1").expect("parses")]).unwrap_err();
        assert!(
            matches!(&e, EditError::Usage(m, Some(h)) if m.contains("`aa`") && h.contains("`a`")),
            "{e:?}"
        );
        let e = run(SCENE, &[parse_move("c.v3=1,1").expect("parses")]).unwrap_err();
        assert!(
            matches!(&e, EditError::Usage(m, _) if m.contains("v0 to v2") && m.contains("c.v3")),
            "{e:?}"
        );
        let huge = parse_scale("c=1e300").expect("parses");
        let e = run(SCENE, &[huge.clone(), huge]).unwrap_err();
        assert!(
            matches!(&e, EditError::Usage(m, _) if m.contains("beyond the range")),
            "{e:?}"
        );
        let e = run("lsystem A { axiom F; }", &[]).unwrap_err();
        assert!(matches!(e, EditError::Input(_)), "{e:?}");
    }

    #[test]
    fn seeds_follow_their_guide_only_when_asked() {
        let text = "lsystem A { axiom F; }\nscene S { guide g { polygon (0, 0) (10, 0) (10, 10) (0, 10); system A; seed (5, 1); } }\n";
        let ops = [parse_rotate("g=90").expect("parses")];
        let (out, o) = run(text, &ops).expect("edits");
        assert!(out.contains("seed (5, 1);"), "{out}");
        assert_eq!(o.seeds_moved, 0);
        // (5, 1) rotated by 90° about (5, 5) is (9, 5), inside: no warning.
        assert!(o.warnings.is_empty(), "{:?}", o.warnings);
        let fe = frontend::run(text, Vec::new(), &[]);
        let mut file = fe.file.clone();
        let checked = fe.checked.as_ref().expect("checked");
        let options = Options {
            move_seeds: true,
            ..Options::default()
        };
        let o = edit(&mut file, checked, &ops, &options).expect("edits");
        let out = crate::fmt::format_file(&file);
        assert!(out.contains("seed (9, 5) heading 90;"), "{out}");
        assert_eq!(o.seeds_moved, 1);
        // Translated away without --move-seeds: a warning.
        let (_, o) = run(text, &[parse_translate("g=100,0").expect("parses")]).expect("edits");
        assert_eq!(o.warnings.len(), 1, "{:?}", o.warnings);
    }

    fn points(line: &str) -> Vec<DVec2> {
        line.trim()
            .trim_start_matches("polygon")
            .trim_end_matches(';')
            .split(')')
            .filter_map(|p| {
                let (x, y) = p.trim().trim_start_matches('(').split_once(',')?;
                Some(DVec2::new(x.trim().parse().ok()?, y.trim().parse().ok()?))
            })
            .collect()
    }

    #[test]
    fn linked_edges_keep_their_length() {
        // p and q are the same square; q's edge 0 carries a link.
        let text = "lsystem A { axiom F; }\nscene S {\n\
            guide p { polygon (0, 0) (10, 0) (10, 10) (0, 10); system A; }\n\
            guide q { polygon (20, 0) (30, 0) (30, 10) (20, 10); system A; }\n\
            guide r { polygon (50, 50) (60, 50) (55, 60); system A; }\n\
            link q.edge(0) -> r.edge(1) { tokens 1; }\n}\n";
        let ops: Vec<Op> = ["p", "q"]
            .iter()
            .flat_map(|g| {
                [
                    parse_pin(&format!("{g}.v0")),
                    parse_pin(&format!("{g}.v3")),
                    parse_by(&format!("{g}.v2=4,0")),
                ]
            })
            .collect::<Result<_, _>>()
            .expect("parses");
        let (out, _) = run(text, &ops).expect("edits");
        let edge0 = |g: &str| {
            let pts = points(polygon_line(&out, g));
            assert_eq!(pts.len(), 4, "{out}");
            spring::dist(pts[0], pts[1])
        };
        let (free, linked) = (edge0("p") - 10.0, edge0("q") - 10.0);
        assert!(free.abs() > 0.1, "{out}");
        assert!(
            linked.abs() < free.abs() / 10.0,
            "linked {linked} vs free {free}\n{out}"
        );
    }

    #[test]
    fn snapping_has_a_tolerance_relative_to_the_scene() {
        // b's first vertex is 10⁻⁵ of the scene away from a's second: one particle.
        let near = "lsystem A { axiom F; }\nscene S {\n\
            guide a { polygon (0, 0) (10, 0) (5, 8); system A; }\n\
            guide b { polygon (10.001, 0) (20, 0) (15, 8); system A; }\n}\n";
        let (_, o) = run(near, &[]).expect("edits");
        assert_eq!(o.particles, 5);
        let (out, o) = run(near, &[parse_by("a.v1=0,1").expect("parses")]).expect("edits");
        assert_eq!(o.changed.len(), 2, "{out}");
        // 1% of the scene apart: two particles, b stays.
        let far = near.replace("10.001", "10.2");
        let (out, o) = run(&far, &[parse_by("a.v1=0,1").expect("parses")]).expect("edits");
        assert_eq!(o.particles, 6);
        assert_eq!(o.changed, [("a".to_string(), 3)], "{out}");
    }

    #[test]
    fn the_scene_is_chosen_by_name() {
        let text = "lsystem A { axiom F; }\n\
            scene One { guide a { polygon (0, 0) (1, 0) (0, 1); system A; } }\n\
            scene Two { guide b { polygon (0, 0) (1, 0) (0, 1); system A; } }\n";
        let e = run(text, &[parse_translate("b=1,0").expect("parses")]).unwrap_err();
        assert!(
            matches!(&e, EditError::Usage(_, Some(h)) if h.contains("--scene Two")),
            "{e:?}"
        );
        let fe = frontend::run(text, Vec::new(), &[]);
        let mut file = fe.file.clone();
        let options = Options {
            scene: Some("Two".to_string()),
            ..Options::default()
        };
        let checked = fe.checked.as_ref().expect("checked");
        let ops = [parse_translate("b=1,0").expect("parses")];
        let o = edit(&mut file, checked, &ops, &options).expect("edits");
        assert_eq!(o.scene, "Two");
        assert_eq!(o.changed, [("b".to_string(), 3)]);
    }

    #[test]
    fn a_guide_hanging_from_a_shared_vertex_follows_without_flipping() {
        // The palm's layout: the crown shares one vertex with the trunk's top; the
        // linked edges are stiff.
        let text = "lsystem A { axiom F; }\nscene S {\n\
            guide trunk { polygon (0, 0) (30, 0) (30, 300) (0, 300); system A; }\n\
            guide crown { polygon (0, 300) (40, 300) (-30, 470) (-170, 380); system A; }\n\
            link trunk.edge(2) -> crown.edge(0) { tokens 1; }\n\
            link crown.edge(2) -> trunk.edge(3) { tokens 0; }\n}\n";
        let area = crate::geometry::signed_area;
        for deg in ["-10", "10", "-45", "90"] {
            let ops = [parse_rotate(&format!("crown={deg}")).expect("parses")];
            let (out, o) = run(text, &ops).expect("edits");
            assert!(o.converged, "{deg}: {o:?}");
            let trunk = points(polygon_line(&out, "trunk"));
            assert!((area(&trunk) - 9000.0).abs() < 200.0, "{deg}: {out}");
            for k in 0..4 {
                let l = spring::dist(trunk[k], trunk[(k + 1) % 4]);
                let want = if k % 2 == 0 { 30.0 } else { 300.0 };
                assert!(
                    (l - want).abs() < 0.05 * want,
                    "{deg}: edge {k} is {l}\n{out}"
                );
            }
        }
    }

    #[test]
    fn argument_syntax() {
        assert_eq!(
            parse_move("trunk.v2=40,-310.5"),
            Ok(Op::Move(
                VertexRef {
                    guide: "trunk".into(),
                    index: 2
                },
                DVec2::new(40.0, -310.5)
            ))
        );
        assert_eq!(parse_pin("trunk"), Ok(Op::Pin("trunk".into(), None)));
        assert_eq!(parse_pin("trunk.v1"), Ok(Op::Pin("trunk".into(), Some(1))));
        for bad in [
            "trunk=1,2",
            "trunk.2=1,2",
            "trunk.v2",
            "trunk.v2=1",
            "trunk.v2=a,1",
            "trunk.v2=inf,1",
            ".v2=1,1",
            "tr unk.v2=1,1",
            "trunk.v-1=1,1",
        ] {
            assert!(parse_move(bad).is_err(), "{bad}");
        }
        assert!(parse_scale("a=0").is_err());
        assert!(parse_scale("a=-1").is_err());
        assert!(parse_rotate("a=NaN").is_err());
        assert!(parse_stiff("a.v0=b").is_err());
    }
}
