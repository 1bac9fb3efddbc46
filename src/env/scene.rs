//! The scene model: guides (polygons that host a compiled system, with their
//! seeds) and links between guide edges (with tokens), built from a checked
//! file (`build`), and where a seed starts its turtle (`seed_state`).
//!
//! Owns: what a scene is and how it is read from the AST. Must not run,
//! answer queries or draw: those read the model (`engine`, `query`, `clip`)
//! and this module imports nothing else from `env`.

use crate::ast::{self, File, GuideStmt, Item, LinkStmt, SceneStmt};
use crate::check::Checked;
use crate::compile::{self, CompileError, Program};
use crate::diagnostic::{Code, Diagnostic};
use crate::span::Span;
use crate::turtle::State;
use glam::{DVec2, DVec3};
use std::collections::HashMap;

#[derive(Clone)]
pub struct Guide {
    pub name: String,
    /// Where the guide's name is written (for diagnostics about it).
    pub span: Span,
    pub polygon: Vec<DVec2>,
    /// Index into `Scene::programs`.
    pub program: usize,
    pub seeds: Vec<Seed>,
}

#[derive(Clone, Debug)]
pub struct Seed {
    pub at: DVec2,
    /// Degrees, 0 = +y, counter-clockwise positive.
    pub heading: f64,
    pub args: Vec<f64>,
}

#[derive(Clone)]
pub struct Link {
    /// From `link` to the end of its far edge reference (for diagnostics).
    pub span: Span,
    pub from: (usize, usize),
    pub to: (usize, usize),
    pub tokens: u32,
    pub used: u32,
    pub heading: f64,
    /// `heading continue;`: the seeded system keeps the heading of the segment
    /// that crossed (`heading` is then unused).
    pub continues: bool,
    /// `aim middle;`: `?D_L` in the start guide measures to the middle of this
    /// link's edge, not to its closest point.
    pub aim_middle: bool,
    /// `take v;`: only a `?X` whose second parameter (the first after Δ) is `v`
    /// takes this link's tokens.
    pub take: Option<f64>,
}

#[derive(Clone)]
pub struct Scene {
    pub name: String,
    pub guides: Vec<Guide>,
    pub links: Vec<Link>,
    pub programs: Vec<Program>,
}

/// The value the checker computed for an expression of the scene (it reports
/// every one it cannot compute, so a checked file has them all).
fn value(e: &ast::Expr, checked: &Checked) -> f64 {
    checked.value_of(e).unwrap_or(0.0)
}

/// Why a checked file's scene could not be built.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SceneError {
    #[error("the file has no scene")]
    NoScene,
    #[error("there is no scene `{0}`")]
    UnknownScene(String),
    #[error("guide `{0}` has no system")]
    NoSystem(String),
    #[error("no guide `{0}`")]
    UnknownGuide(String),
    #[error(transparent)]
    Compile(#[from] CompileError),
}

impl SceneError {
    /// The error as a diagnostic. The checker reports all but `Compile`'s
    /// limits first, so these are rare after a clean check.
    pub fn diagnostic(&self) -> Diagnostic {
        match self {
            SceneError::Compile(e) => e.diagnostic(),
            SceneError::UnknownGuide(_) => Diagnostic::error(Code::UnknownGuide, self.to_string()),
            _ => Diagnostic::error(Code::UnknownSystem, self.to_string()),
        }
    }
}

/// Builds the scene called `name` (or the first) of a checked file.
pub fn build(file: &File, checked: &Checked, name: Option<&str>) -> Result<Scene, SceneError> {
    let scene = pick(file, name)?;
    let (guides, programs, index) = guides(file, checked, scene)?;
    let links = links(checked, scene, &index)?;
    Ok(Scene {
        name: scene.name.name.clone(),
        guides,
        links,
        programs,
    })
}

/// The scene called `name` of a file, or its first.
fn pick<'a>(file: &'a File, name: Option<&str>) -> Result<&'a ast::Scene, SceneError> {
    let scenes: Vec<&ast::Scene> = file
        .items
        .stmts
        .iter()
        .filter_map(|i| match &i.node {
            Item::Scene(s) => Some(s),
            _ => None,
        })
        .collect();
    match name {
        Some(n) => scenes
            .iter()
            .find(|s| s.name.name == n)
            .copied()
            .ok_or_else(|| SceneError::UnknownScene(n.to_string())),
        None => scenes.first().copied().ok_or(SceneError::NoScene),
    }
}

/// A scene's guides in order, the programs of their systems (each system
/// compiled once) and the guides' indices by name.
type Guides = (Vec<Guide>, Vec<Program>, HashMap<String, usize>);

/// The guides of a scene, with their compiled systems.
fn guides(file: &File, checked: &Checked, scene: &ast::Scene) -> Result<Guides, SceneError> {
    let mut programs: Vec<Program> = Vec::new();
    let mut by_system: HashMap<String, usize> = HashMap::new();
    let mut guides = Vec::new();
    let mut index: HashMap<String, usize> = HashMap::new();
    for st in &scene.body.stmts {
        let SceneStmt::Guide(g) = &st.node else {
            continue;
        };
        let (polygon, system, seeds) = guide_settings(g, checked);
        let system = system.ok_or_else(|| SceneError::NoSystem(g.name.name.clone()))?;
        let program = match by_system.get(&system) {
            Some(&p) => p,
            None => {
                programs.push(compile::compile(file, checked, Some(&system))?);
                by_system.insert(system, programs.len() - 1);
                programs.len() - 1
            }
        };
        index.insert(g.name.name.clone(), guides.len());
        guides.push(Guide {
            name: g.name.name.clone(),
            span: g.name.span,
            polygon,
            program,
            seeds,
        });
    }
    Ok((guides, programs, index))
}

/// A guide's polygon, the name of its system (the last given) and its seeds.
fn guide_settings(g: &ast::Guide, checked: &Checked) -> (Vec<DVec2>, Option<String>, Vec<Seed>) {
    let mut polygon = Vec::new();
    let mut system = None;
    let mut seeds = Vec::new();
    for gs in &g.body.stmts {
        match &gs.node {
            GuideStmt::Polygon(pts) => {
                polygon = pts
                    .iter()
                    .map(|p| DVec2::new(value(&p.x, checked), value(&p.y, checked)))
                    .collect();
            }
            GuideStmt::System(s) => system = Some(s.name.clone()),
            GuideStmt::Seed(s) => seeds.push(Seed {
                at: DVec2::new(value(&s.at.x, checked), value(&s.at.y, checked)),
                heading: s.heading.as_ref().map_or(0.0, |h| value(h, checked)),
                args: s.args.iter().flatten().map(|a| value(a, checked)).collect(),
            }),
            GuideStmt::Error => {}
        }
    }
    (polygon, system, seeds)
}

/// The links of a scene, between the guides of `index`.
fn links(
    checked: &Checked,
    scene: &ast::Scene,
    index: &HashMap<String, usize>,
) -> Result<Vec<Link>, SceneError> {
    let mut links = Vec::new();
    for st in &scene.body.stmts {
        let SceneStmt::Link(l) = &st.node else {
            continue;
        };
        let end = |r: &ast::EdgeRef| -> Result<(usize, usize), SceneError> {
            let g = *index
                .get(&r.guide.name)
                .ok_or_else(|| SceneError::UnknownGuide(r.guide.name.clone()))?;
            Ok((g, value(&r.index, checked) as usize))
        };
        let (mut tokens, mut heading) = (0u32, 0.0);
        let (mut continues, mut aim_middle, mut take) = (false, false, None);
        for ls in &l.body.stmts {
            match &ls.node {
                LinkStmt::Tokens(e) => tokens = value(e, checked) as u32,
                LinkStmt::Heading(e) if link_word(e) == Some("continue") => continues = true,
                LinkStmt::Heading(e) => heading = value(e, checked),
                LinkStmt::Setting(k, e) => match k.name.as_str() {
                    "aim" => aim_middle = link_word(e) == Some("middle"),
                    "take" => take = Some(value(e, checked)),
                    _ => {}
                },
                LinkStmt::Error => {}
            }
        }
        links.push(Link {
            span: Span {
                start: st.span.start,
                end: l.to.span.end,
            },
            from: end(&l.from)?,
            to: end(&l.to)?,
            tokens,
            used: 0,
            heading,
            continues,
            aim_middle,
            take,
        });
    }
    Ok(links)
}

/// The turtle state of a seed: at its point, heading rotated `deg` from +y.
pub fn seed_state(at: DVec2, deg: f64) -> State {
    let (s, c) = deg.to_radians().sin_cos();
    let h = DVec3::new(-s, c, 0.0);
    State {
        pos: at.extend(0.0),
        h,
        l: DVec3::Z.cross(h),
        u: DVec3::Z,
        ..State::default()
    }
}

/// A link setting's value written as a bare word (`heading continue;`, `aim
/// middle;`), as the checker reads it.
fn link_word(e: &ast::Expr) -> Option<&str> {
    match &e.kind {
        ast::ExprKind::Var(n) => Some(n.as_str()),
        _ => None,
    }
}
