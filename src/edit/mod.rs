//! Guide editing by a mass-spring system (`lsyc edit`): drag guide vertices,
//! translate, rotate or scale guides, relax the rest, write the new polygons back.
//!
//! Owns: the edit operations and their argument syntax, turning a scene's guides
//! into particles and springs (`spring`), and writing the solved positions back
//! into the AST so that `fmt::format_file` prints the program with its comments
//! and layout. Must not print or touch files: the command line does that.
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

pub mod spring;

use crate::ast::{Expr, ExprKind, File, GuideStmt, Item, Scene, SceneStmt, UnOp};
use crate::check::{Checked, suggest};
use spring::{P2, Params, System, polygon_springs};
use std::collections::{BTreeMap, HashMap};

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
    Move(VertexRef, P2),
    /// `--by GUIDE.vK=DX,DY`: the vertex moves by (DX, DY).
    By(VertexRef, P2),
    /// `--translate GUIDE=DX,DY`
    Translate(String, P2),
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
            Op::Move(_, p) | Op::By(_, p) | Op::Translate(_, p) => {
                decimals(p[0]).max(decimals(p[1]))
            }
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

/// The fewest decimals (up to 12) that write `v` exactly.
fn decimals(v: f64) -> usize {
    (0..=12)
        .find(|&d| format!("{v:.d$}").parse::<f64>() == Ok(v))
        .unwrap_or(12)
}

fn number(s: &str, what: &str) -> Result<f64, String> {
    let t = s.trim();
    match t.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(format!("`{t}` is not a number ({what})")),
    }
}

fn pair(s: &str, what: &str) -> Result<P2, String> {
    let Some((a, b)) = s.split_once(',') else {
        return Err(format!("`{s}` is not two numbers `X,Y` ({what})"));
    };
    Ok([number(a, what)?, number(b, what)?])
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

struct GuideInfo {
    name: String,
    /// The index of the guide statement in the scene body.
    stmt: usize,
    /// Source values of the polygon's vertices.
    points: Vec<P2>,
    /// The particle of each vertex.
    particles: Vec<usize>,
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
    let scene = options.scene.as_deref();
    let scenes: Vec<(usize, &Scene)> = file
        .items
        .stmts
        .iter()
        .enumerate()
        .filter_map(|(i, it)| match &it.node {
            Item::Scene(s) => Some((i, s)),
            _ => None,
        })
        .collect();
    if scenes.is_empty() {
        return Err(EditError::Input(
            "the program has no scene: `lsyc edit` moves the guides of a `scene`".to_string(),
        ));
    }
    let (item, sc) = match scene {
        Some(name) => match scenes.iter().find(|(_, s)| s.name.name == name) {
            Some(&found) => found,
            None => {
                let names = scenes.iter().map(|(_, s)| s.name.name.as_str());
                let hint = suggest(name, names.clone())
                    .map(|s| format!("did you mean `{s}`?"))
                    .unwrap_or_else(|| {
                        format!(
                            "the scenes are {}",
                            names
                                .map(|n| format!("`{n}`"))
                                .collect::<Vec<_>>()
                                .join(", ")
                        )
                    });
                return Err(EditError::Usage(
                    format!("there is no scene `{name}`"),
                    Some(hint),
                ));
            }
        },
        None => scenes[0],
    };
    let mut guides = collect_guides(sc, checked)?;
    validate(ops, sc, &guides, &scenes)?;

    // Particles, snapped across guides.
    let size = scene_size(&guides);
    let tol = SNAP * size;
    let mut sys = System::default();
    let mut grid: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
    let cell = |p: P2| ((p[0] / tol).floor() as i64, (p[1] / tol).floor() as i64);
    for g in &mut guides {
        for &p in &g.points {
            let (cx, cy) = cell(p);
            let mut found: Option<usize> = None;
            for dx in -1..=1 {
                for dy in -1..=1 {
                    for &q in grid.get(&(cx + dx, cy + dy)).into_iter().flatten() {
                        if spring::dist(sys.rest[q], p) <= tol && found.is_none_or(|f| q < f) {
                            found = Some(q);
                        }
                    }
                }
            }
            let id = found.unwrap_or_else(|| {
                sys.rest.push(p);
                let id = sys.rest.len() - 1;
                grid.entry((cx, cy)).or_default().push(id);
                id
            });
            g.particles.push(id);
        }
    }
    // Springs: edges and diagonals, stiff linked edges, the user's stiff pairs.
    for g in &guides {
        for (a, b, is_edge) in polygon_springs(g.particles.len()) {
            let k = if is_edge { K_EDGE } else { K_DIAGONAL };
            sys.add_spring(g.particles[a], g.particles[b], k);
        }
    }
    let by_name: HashMap<&str, usize> = guides
        .iter()
        .enumerate()
        .map(|(i, g)| (g.name.as_str(), i))
        .collect();
    for st in &sc.body.stmts {
        let SceneStmt::Link(l) = &st.node else {
            continue;
        };
        for end in [&l.from, &l.to] {
            let Some(&gi) = by_name.get(end.guide.name.as_str()) else {
                continue;
            };
            let g = &guides[gi];
            let n = g.particles.len();
            if let Some(e) = const_value(&end.index, checked)
                && e >= 0.0
                && e.fract() == 0.0
                && (e as usize) < n
            {
                let e = e as usize;
                sys.add_spring(g.particles[e], g.particles[(e + 1) % n], K_LINK);
            }
        }
    }
    let particle = |v: &VertexRef| guides[by_name[v.guide.as_str()]].particles[v.index];
    for op in ops {
        if let Op::Stiff(a, b) = op {
            sys.add_spring(particle(a), particle(b), K_STIFF);
        }
    }

    // Targets, in the order the operations were given.
    let mut pins: BTreeMap<usize, P2> = BTreeMap::new();
    for op in ops {
        let current =
            |pins: &BTreeMap<usize, P2>, p: usize| pins.get(&p).copied().unwrap_or(sys.rest[p]);
        let guide_particles = |g: &str| {
            let mut ps = guides[by_name[g]].particles.clone();
            ps.sort_unstable();
            ps.dedup();
            ps
        };
        match op {
            Op::Move(v, to) => {
                pins.insert(particle(v), *to);
            }
            Op::By(v, d) => {
                let p = particle(v);
                let c = current(&pins, p);
                pins.insert(p, [c[0] + d[0], c[1] + d[1]]);
            }
            Op::Translate(g, d) => {
                for p in guide_particles(g) {
                    let c = current(&pins, p);
                    pins.insert(p, [c[0] + d[0], c[1] + d[1]]);
                }
            }
            Op::Rotate(g, _) | Op::Scale(g, _) => {
                let gi = by_name[g.as_str()];
                let now: Vec<P2> = guides[gi]
                    .particles
                    .iter()
                    .map(|&p| current(&pins, p))
                    .collect();
                let c = centroid(&now);
                let (sin, cos) = match op {
                    Op::Rotate(_, deg) => deg.to_radians().sin_cos(),
                    _ => (0.0, 1.0),
                };
                let k = if let Op::Scale(_, k) = op { *k } else { 1.0 };
                for p in guide_particles(g) {
                    let q = current(&pins, p);
                    let d = [q[0] - c[0], q[1] - c[1]];
                    pins.insert(
                        p,
                        [
                            c[0] + k * (cos * d[0] - sin * d[1]),
                            c[1] + k * (sin * d[0] + cos * d[1]),
                        ],
                    );
                }
            }
            Op::Pin(g, v) => {
                let ps = match v {
                    Some(k) => vec![guides[by_name[g.as_str()]].particles[*k]],
                    None => guide_particles(g),
                };
                for p in ps {
                    let c = current(&pins, p);
                    pins.insert(p, c);
                }
            }
            Op::Stiff(..) => {}
        }
    }

    if let Some((&p, t)) = pins
        .iter()
        .find(|(_, t)| !(t[0].is_finite() && t[1].is_finite()))
    {
        let (g, k) = guides
            .iter()
            .find_map(|g| {
                g.particles
                    .iter()
                    .position(|&q| q == p)
                    .map(|k| (&g.name, k))
            })
            .map_or((&sc.name.name, 0), |(g, k)| (g, k));
        return Err(EditError::Usage(
            format!(
                "the operations move {g}.v{k} to ({}, {}), beyond the range of numbers",
                t[0], t[1]
            ),
            None,
        ));
    }
    let params = Params {
        inertia: INERTIA,
        size,
        ..Params::default()
    };
    let sol = sys.solve(&pins, &params);
    let base = (-(size / 1000.0).log10().floor()).clamp(0.0, 12.0) as usize;
    let places = ops.iter().map(Op::decimals).fold(base, usize::max);
    let mut outcome = Outcome {
        scene: sc.name.name.clone(),
        particles: sys.rest.len(),
        springs: sys.springs.len(),
        free: sol.free,
        iterations: sol.iterations,
        converged: sol.converged,
        decimals: places,
        ..Outcome::default()
    };

    // Write back.
    let Item::Scene(scene_mut) = &mut file.items.stmts[item].node else {
        return Err(EditError::Input("the scene disappeared".to_string()));
    };
    for g in &guides {
        let SceneStmt::Guide(guide) = &mut scene_mut.body.stmts[g.stmt].node else {
            continue;
        };
        let Some(pts) = guide.body.stmts.iter_mut().find_map(|s| match &mut s.node {
            GuideStmt::Polygon(pts) => Some(pts),
            _ => None,
        }) else {
            continue;
        };
        let new: Vec<P2> = g.particles.iter().map(|&p| sol.positions[p]).collect();
        let mut moved = 0;
        for (k, pt) in pts.iter_mut().enumerate() {
            if new[k] == sys.rest[g.particles[k]] {
                continue;
            }
            let mut any = false;
            for (axis, e) in [&mut pt.x, &mut pt.y].into_iter().enumerate() {
                let what = format!("{}.v{k} {}", g.name, ["x", "y"][axis]);
                any |= write_number(
                    e,
                    new[k][axis],
                    g.points[k][axis],
                    places,
                    &what,
                    &mut outcome,
                );
            }
            moved += usize::from(any);
        }
        if moved == 0 {
            continue;
        }
        outcome.changed.push((g.name.clone(), moved));
        let fit = affine_fit(&g.points, &new);
        for (si, st) in guide.body.stmts.iter_mut().enumerate() {
            let GuideStmt::Seed(seed) = &mut st.node else {
                continue;
            };
            let (Some(x), Some(y)) = (
                const_value(&seed.at.x, checked),
                const_value(&seed.at.y, checked),
            ) else {
                continue;
            };
            let to = fit.apply([x, y]);
            if options.move_seeds {
                let name = format!("{}'s seed {}", g.name, si);
                write_number(
                    &mut seed.at.x,
                    to[0],
                    x,
                    places,
                    &format!("{name} x"),
                    &mut outcome,
                );
                write_number(
                    &mut seed.at.y,
                    to[1],
                    y,
                    places,
                    &format!("{name} y"),
                    &mut outcome,
                );
                let turn = fit.rotation_degrees();
                let old = seed
                    .heading
                    .as_ref()
                    .and_then(|h| const_value(h, checked))
                    .unwrap_or(0.0);
                let places = places.max(1);
                if round(turn, places) != 0.0 {
                    match &mut seed.heading {
                        Some(h) => {
                            write_number(
                                h,
                                old + turn,
                                old,
                                places,
                                &format!("{name} heading"),
                                &mut outcome,
                            );
                        }
                        None => seed.heading = Some(Expr::num(round(old + turn, places))),
                    }
                }
                outcome.seeds_moved += 1;
            } else if !inside(&new, [x, y]) {
                outcome.warnings.push(format!(
                    "the seed at ({}, {}) of guide `{}` is outside its moved polygon; --move-seeds carries seeds with their guides",
                    crate::fmt::format_number(x),
                    crate::fmt::format_number(y),
                    g.name
                ));
            }
        }
    }
    Ok(outcome)
}

fn collect_guides(sc: &Scene, checked: &Checked) -> Result<Vec<GuideInfo>, EditError> {
    let mut guides = Vec::new();
    for (stmt, st) in sc.body.stmts.iter().enumerate() {
        let SceneStmt::Guide(g) = &st.node else {
            continue;
        };
        if guides.iter().any(|x: &GuideInfo| x.name == g.name.name) {
            continue; // a duplicate (the checker reports it)
        }
        let Some(pts) = g.body.stmts.iter().find_map(|s| match &s.node {
            GuideStmt::Polygon(p) => Some(p),
            _ => None,
        }) else {
            continue;
        };
        let mut points = Vec::with_capacity(pts.len());
        for (k, pt) in pts.iter().enumerate() {
            let mut xy = [0.0; 2];
            for (axis, e) in [&pt.x, &pt.y].into_iter().enumerate() {
                xy[axis] = const_value(e, checked).filter(|v| v.is_finite()).ok_or_else(|| {
                    EditError::Input(format!(
                        "guide `{}`: the {} coordinate of v{k}, `{}`, has no value known before derivation",
                        g.name.name,
                        ["x", "y"][axis],
                        crate::fmt::format_expr(e)
                    ))
                })?;
            }
            points.push(xy);
        }
        guides.push(GuideInfo {
            name: g.name.name.clone(),
            stmt,
            points,
            particles: Vec::new(),
        });
    }
    Ok(guides)
}

fn validate(
    ops: &[Op],
    sc: &Scene,
    guides: &[GuideInfo],
    scenes: &[(usize, &Scene)],
) -> Result<(), EditError> {
    for op in ops {
        for name in op.guides() {
            if guides.iter().any(|g| g.name == name) {
                continue;
            }
            let elsewhere = scenes.iter().find(|(_, s)| {
                s.name.name != sc.name.name
                    && s.body
                        .stmts
                        .iter()
                        .any(|st| matches!(&st.node, SceneStmt::Guide(g) if g.name.name == name))
            });
            let hint = if let Some((_, s)) = elsewhere {
                Some(format!(
                    "`{name}` is a guide of scene `{}`; choose it with --scene {}",
                    s.name.name, s.name.name
                ))
            } else if let Some(s) = suggest(name, guides.iter().map(|g| g.name.as_str())) {
                Some(format!("did you mean `{s}`?"))
            } else if guides.is_empty() {
                None
            } else {
                Some(format!(
                    "the guides are {}",
                    guides
                        .iter()
                        .map(|g| format!("`{}`", g.name))
                        .collect::<Vec<_>>()
                        .join(", ")
                ))
            };
            return Err(EditError::Usage(
                format!("there is no guide `{name}` in scene `{}`", sc.name.name),
                hint,
            ));
        }
        for v in op.vertices().into_iter().chain(
            match op {
                Op::Pin(g, Some(k)) => Some(VertexRef {
                    guide: g.clone(),
                    index: *k,
                }),
                _ => None,
            }
            .as_ref(),
        ) {
            let n = guides
                .iter()
                .find(|g| g.name == v.guide)
                .map_or(0, |g| g.points.len());
            if v.index >= n {
                return Err(EditError::Usage(
                    format!(
                        "guide `{}` has {n} vertices, numbered v0 to v{}: there is no `{v}`",
                        v.guide,
                        n.saturating_sub(1)
                    ),
                    Some(
                        "vertex K is the K-th point of the guide's `polygon`, counting from 0"
                            .to_string(),
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Writes `new` (rounded) into the coordinate `e` whose value was `old`, if the
/// rounded values differ; notes an expression replaced by a number. Returns
/// whether it wrote.
fn write_number(
    e: &mut Expr,
    new: f64,
    old: f64,
    places: usize,
    what: &str,
    outcome: &mut Outcome,
) -> bool {
    let v = round(new, places);
    if v == round(old, places) {
        return false;
    }
    if literal(e).is_none() {
        outcome.replaced.push(format!(
            "{what}: `{}` is now {}",
            crate::fmt::format_expr(e),
            crate::fmt::format_number(v)
        ));
    }
    *e = Expr {
        kind: ExprKind::Num(v),
        span: e.span,
    };
    true
}

/// An affine map of the plane: x ↦ A x + t.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Affine {
    /// Row-major 2×2 matrix.
    pub a: [f64; 4],
    pub t: P2,
}

impl Affine {
    pub fn apply(&self, p: P2) -> P2 {
        [
            self.a[0] * p[0] + self.a[1] * p[1] + self.t[0],
            self.a[2] * p[0] + self.a[3] * p[1] + self.t[1],
        ]
    }

    /// The angle (degrees, counter-clockwise) of the rotation closest to A.
    pub fn rotation_degrees(&self) -> f64 {
        (self.a[2] - self.a[1])
            .atan2(self.a[0] + self.a[3])
            .to_degrees()
    }
}

/// The least-squares affine map taking `from` to `to` (a translation when the
/// points are collinear).
pub fn affine_fit(from: &[P2], to: &[P2]) -> Affine {
    let n = from.len().min(to.len()).max(1) as f64;
    let mean = |ps: &[P2]| {
        let s = ps
            .iter()
            .fold([0.0, 0.0], |s, p| [s[0] + p[0], s[1] + p[1]]);
        [s[0] / n, s[1] / n]
    };
    let (mp, mq) = (mean(from), mean(to));
    let (mut pp, mut qp) = ([0.0; 4], [0.0; 4]);
    for (p, q) in from.iter().zip(to) {
        let d = [p[0] - mp[0], p[1] - mp[1]];
        let e = [q[0] - mq[0], q[1] - mq[1]];
        pp = [
            pp[0] + d[0] * d[0],
            pp[1] + d[0] * d[1],
            pp[2] + d[1] * d[0],
            pp[3] + d[1] * d[1],
        ];
        qp = [
            qp[0] + e[0] * d[0],
            qp[1] + e[0] * d[1],
            qp[2] + e[1] * d[0],
            qp[3] + e[1] * d[1],
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
    let t = [
        mq[0] - (a[0] * mp[0] + a[1] * mp[1]),
        mq[1] - (a[2] * mp[0] + a[3] * mp[1]),
    ];
    Affine { a, t }
}

/// Whether `p` is inside the polygon (even-odd rule; the boundary counts as inside).
fn inside(poly: &[P2], p: P2) -> bool {
    let n = poly.len();
    let mut odd = false;
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        let cross = (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]);
        let within = p[0] >= a[0].min(b[0])
            && p[0] <= a[0].max(b[0])
            && p[1] >= a[1].min(b[1])
            && p[1] <= a[1].max(b[1]);
        let len = spring::dist(a, b);
        if within && cross.abs() <= 1e-9 * len * len.max(1.0) {
            return true;
        }
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if p[0] < x {
                odd = !odd;
            }
        }
    }
    odd
}

/// The value of a number literal (`3`, `-2.5`), or `None` for any other expression.
fn literal(e: &Expr) -> Option<f64> {
    match &e.kind {
        ExprKind::Num(v) => Some(*v),
        ExprKind::Unary(UnOp::Neg, a) => literal(a).map(|v| -v),
        _ => None,
    }
}

/// The value of a constant expression (literals, constants, deterministic functions).
fn const_value(e: &Expr, checked: &Checked) -> Option<f64> {
    literal(e).or_else(|| checked.value_of(e))
}

/// The diagonal of the bounding box of every guide vertex (1 if there is none).
fn scene_size(guides: &[GuideInfo]) -> f64 {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in guides.iter().flat_map(|g| &g.points) {
        for a in 0..2 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    let d = (hi[0] - lo[0]).hypot(hi[1] - lo[1]);
    if d.is_finite() && d > 0.0 { d } else { 1.0 }
}

/// The area centroid of a polygon, or the mean of its vertices when its area is
/// (nearly) zero.
pub fn centroid(pts: &[P2]) -> P2 {
    let n = pts.len();
    if n == 0 {
        return [0.0, 0.0];
    }
    // Relative to the first vertex, for accuracy far from the origin.
    let o = pts[0];
    let mut a2 = 0.0;
    let mut c = [0.0, 0.0];
    for i in 0..n {
        let p = [pts[i][0] - o[0], pts[i][1] - o[1]];
        let q = [pts[(i + 1) % n][0] - o[0], pts[(i + 1) % n][1] - o[1]];
        let cross = p[0] * q[1] - q[0] * p[1];
        a2 += cross;
        c[0] += (p[0] + q[0]) * cross;
        c[1] += (p[1] + q[1]) * cross;
    }
    let mean = [
        pts.iter().map(|p| p[0]).sum::<f64>() / n as f64,
        pts.iter().map(|p| p[1]).sum::<f64>() / n as f64,
    ];
    let extent = pts
        .iter()
        .map(|p| spring::dist(*p, mean))
        .fold(0.0f64, f64::max);
    if a2.abs() <= 1e-9 * extent * extent {
        return mean;
    }
    [o[0] + c[0] / (3.0 * a2), o[1] + c[1] / (3.0 * a2)]
}

/// `v` rounded to `places` decimals, as the nearest double to the decimal.
fn round(v: f64, places: usize) -> f64 {
    let r = format!("{v:.places$}").parse::<f64>().unwrap_or(v);
    if r == 0.0 { 0.0 } else { r }
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
        assert_eq!(
            centroid(&[[0.0, 0.0], [4.0, 0.0], [4.0, 2.0], [0.0, 2.0]]),
            [2.0, 1.0]
        );
        // A degenerate polygon: the mean of its vertices.
        assert_eq!(centroid(&[[0.0, 0.0], [2.0, 0.0], [4.0, 0.0]]), [2.0, 0.0]);
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

    #[test]
    fn affine_fit_recovers_a_similarity() {
        let from = [[0.0, 0.0], [4.0, 0.0], [4.0, 2.0], [0.0, 3.0]];
        let (s, c) = 30f64.to_radians().sin_cos();
        let map = |p: P2| {
            [
                2.0 * (c * p[0] - s * p[1]) + 7.0,
                2.0 * (s * p[0] + c * p[1]) - 1.0,
            ]
        };
        let to: Vec<P2> = from.iter().map(|&p| map(p)).collect();
        let fit = affine_fit(&from, &to);
        let q = fit.apply([1.0, 1.0]);
        let want = map([1.0, 1.0]);
        assert!((q[0] - want[0]).abs() < 1e-9 && (q[1] - want[1]).abs() < 1e-9);
        assert!((fit.rotation_degrees() - 30.0).abs() < 1e-9);
        assert!(inside(&from, [1.0, 1.0]));
        assert!(inside(&from, [4.0, 1.0]));
        assert!(!inside(&from, [5.0, 1.0]));
    }

    fn points(line: &str) -> Vec<P2> {
        line.trim()
            .trim_start_matches("polygon")
            .trim_end_matches(';')
            .split(')')
            .filter_map(|p| {
                let (x, y) = p.trim().trim_start_matches('(').split_once(',')?;
                Some([x.trim().parse().ok()?, y.trim().parse().ok()?])
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
        let area = |pts: &[P2]| {
            (0..pts.len())
                .map(|i| {
                    let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
                    a[0] * b[1] - b[0] * a[1]
                })
                .sum::<f64>()
                / 2.0
        };
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
                [40.0, -310.5]
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
        assert_eq!(decimals(12.345), 3);
        assert_eq!(decimals(40.0), 0);
        assert_eq!(round(0.1 + 0.2, 3), 0.3);
        assert_eq!(round(-0.0001, 2).to_bits(), 0.0f64.to_bits());
    }
}
