//! A scene: guides with their compiled systems and links with tokens, built
//! from a checked file; the answers to query modules from a guide's geometry
//! (`query`, `collide`); and the centre rule (`Clip`). The loop that runs the
//! systems is in `engine`.

use super::engine::{self, Cache, Config, GuideRun, Token};
use super::geometry::{closest_on_segment, crossing, inside, ray_hit, signed_angle};
use super::index::Layers;
use crate::ast::{File, GuideStmt, Item, LinkStmt, SceneStmt};
use crate::check::Checked;
use crate::compile::{self, CompileError, Program};
use crate::derive::{Limits, ModString};
use crate::diagnostic::{Code, Diagnostic};
use crate::query::QueryKind;
use crate::turtle::{Drawn, Sink, State};
use glam::{DVec2, DVec3};
use std::collections::HashMap;

/// The most derivation steps a scene runs, whatever its systems say.
pub const MAX_SCENE_STEPS: u32 = 100_000;

pub struct Guide {
    pub name: String,
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

pub struct Link {
    pub from: (usize, usize),
    pub to: (usize, usize),
    pub tokens: u32,
    pub used: u32,
    pub heading: f64,
}

pub struct Scene {
    pub name: String,
    pub guides: Vec<Guide>,
    pub links: Vec<Link>,
    pub programs: Vec<Program>,
}

/// One running L-system: a seed in a guide and its string.
#[derive(Clone)]
pub struct Instance {
    pub guide: usize,
    pub start: State,
    pub string: ModString,
    pub steps: u32,
}

/// What a scene run produced.
pub struct Outcome {
    pub instances: Vec<Instance>,
    pub steps: u32,
    pub queries: u64,
    pub messages: u64,
    /// Per guide: its messages, token events and counts (its systems are in
    /// `instances`, not repeated here).
    pub guides: Vec<GuideRun>,
}

/// The value the checker computed for an expression of the scene (it reports
/// every one it cannot compute, so a checked file has them all).
fn value(e: &crate::ast::Expr, checked: &Checked) -> f64 {
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
    let scenes: Vec<&crate::ast::Scene> = file
        .items
        .stmts
        .iter()
        .filter_map(|i| match &i.node {
            Item::Scene(s) => Some(s),
            _ => None,
        })
        .collect();
    let scene = match name {
        Some(n) => scenes
            .iter()
            .find(|s| s.name.name == n)
            .copied()
            .ok_or_else(|| SceneError::UnknownScene(n.to_string()))?,
        None => *scenes.first().ok_or(SceneError::NoScene)?,
    };
    let mut programs: Vec<Program> = Vec::new();
    let mut by_system: HashMap<String, usize> = HashMap::new();
    let mut guides = Vec::new();
    let mut index: HashMap<String, usize> = HashMap::new();
    for st in &scene.body.stmts {
        let SceneStmt::Guide(g) = &st.node else {
            continue;
        };
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
            polygon,
            program,
            seeds,
        });
    }
    let mut links = Vec::new();
    for st in &scene.body.stmts {
        let SceneStmt::Link(l) = &st.node else {
            continue;
        };
        let end = |r: &crate::ast::EdgeRef| -> Result<(usize, usize), SceneError> {
            let g = *index
                .get(&r.guide.name)
                .ok_or_else(|| SceneError::UnknownGuide(r.guide.name.clone()))?;
            Ok((g, value(&r.index, checked) as usize))
        };
        let (mut tokens, mut heading) = (0u32, 0.0);
        for ls in &l.body.stmts {
            match &ls.node {
                LinkStmt::Tokens(e) => tokens = value(e, checked) as u32,
                LinkStmt::Heading(e) => heading = value(e, checked),
                LinkStmt::Error => {}
            }
        }
        links.push(Link {
            from: end(&l.from)?,
            to: end(&l.to)?,
            tokens,
            used: 0,
            heading,
        });
    }
    Ok(Scene {
        name: scene.name.name.clone(),
        guides,
        links,
        programs,
    })
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

/// Collects one instance's segments and query requests.
#[derive(Default)]
pub(crate) struct Probe {
    pub(crate) segments: Vec<(DVec2, DVec2)>,
    pub(crate) queries: Vec<(usize, u8, State)>,
}

impl Sink for Probe {
    fn segment(&mut self, a: DVec3, b: DVec3, _: f64, _: u32) {
        self.segments.push((a.truncate(), b.truncate()));
    }
    fn polygon(&mut self, _: &[DVec3], _: u32) {}
    fn element(&mut self, _: u16, at: DVec3, h: DVec3, _: DVec3, scale: f64, _: u32) {
        // An element occupies its base-to-tip axis for collisions.
        self.segments
            .push((at.truncate(), (at + h * scale).truncate()));
    }
    fn query(&mut self, module: usize, kind: u8, state: &State) {
        self.queries.push((module, kind, *state));
    }
}

fn edges(poly: &[DVec2]) -> impl Iterator<Item = (usize, DVec2, DVec2)> + '_ {
    (0..poly.len()).map(move |i| (i, poly[i], poly[(i + 1) % poly.len()]))
}

/// Runs a scene to the end: until no system is still deriving (see
/// `engine` for the order of events). The links' `used` counts are filled in.
pub fn run(
    scene: &mut Scene,
    seed: u64,
    limits: Limits,
    max_steps: Option<u32>,
) -> Result<Outcome, Diagnostic> {
    let cfg = Config {
        seed,
        limits,
        cap: max_steps.unwrap_or(MAX_SCENE_STEPS).min(MAX_SCENE_STEPS),
    };
    let (out, _) = engine::execute(scene, cfg, &[], &mut Cache::default())?;
    out.count_used(&mut scene.links);
    Ok(out)
}

impl Outcome {
    /// Writes into each link how many of its tokens were used.
    pub fn count_used(&self, links: &mut [Link]) {
        for l in links.iter_mut() {
            l.used = 0;
        }
        for e in self.guides.iter().flat_map(|g| &g.tokens) {
            if e.token == Token::Used
                && let Some(l) = links.get_mut(e.link)
            {
                l.used += 1;
            }
        }
    }
}

/// The outputs of one query module (at most four numbers).
#[derive(Clone, Copy)]
pub(crate) struct Answer {
    values: [f64; 4],
    len: usize,
}

impl Answer {
    fn new(v: &[f64]) -> Answer {
        let mut values = [0.0; 4];
        values[..v.len()].copy_from_slice(v);
        Answer {
            values,
            len: v.len(),
        }
    }

    pub(crate) fn values(&self) -> &[f64] {
        &self.values[..self.len]
    }
}

fn found(b: bool) -> f64 {
    f64::from(u8::from(b))
}

/// Answers ?P ?H ?D_* ?N_* for a turtle in guide `gi`; `grid` indexes what is
/// drawn in the guide (None when nothing asks about it).
pub(crate) fn query(
    scene: &Scene,
    grid: Option<&Layers>,
    gi: usize,
    kind: QueryKind,
    st: &State,
) -> Answer {
    let p = st.pos.truncate();
    let h = st.h.truncate();
    let dir = if h.length_squared() > 0.0 {
        h.normalize()
    } else {
        DVec2::Y
    };
    let poly = &scene.guides[gi].polygon;
    let link_edges = || -> Vec<(usize, DVec2, DVec2)> {
        scene
            .links
            .iter()
            .enumerate()
            .filter(|(_, l)| l.from.0 == gi)
            .map(|(i, l)| {
                let e = l.from.1 % poly.len().max(1);
                (i, poly[e], poly[(e + 1) % poly.len()])
            })
            .collect()
    };
    let closest = |d: f64, c: DVec2, id: usize| -> Answer {
        let beta = if d > 0.0 {
            signed_angle(dir, c - p)
        } else {
            0.0
        };
        Answer::new(&[1.0, d, beta, id as f64])
    };
    let nearest = |set: &[(usize, DVec2, DVec2)]| -> Answer {
        let best = set
            .iter()
            .map(|&(id, a, b)| {
                let c = closest_on_segment(p, a, b);
                ((c - p).length(), c, id)
            })
            .min_by(|x, y| x.0.total_cmp(&y.0));
        match best {
            Some((d, c, id)) => closest(d, c, id),
            None => Answer::new(&[0.0; 4]),
        }
    };
    let first_ahead = |set: &[(usize, DVec2, DVec2)]| -> Option<(f64, usize)> {
        set.iter()
            .filter_map(|&(id, a, b)| ray_hit(p, dir, a, b).map(|t| (t, id)))
            .min_by(|x, y| x.0.total_cmp(&y.0))
    };
    let ahead = |best: Option<(f64, usize)>| -> Answer {
        match best {
            Some((t, id)) => Answer::new(&[1.0, t, id as f64]),
            None => Answer::new(&[0.0; 3]),
        }
    };
    let guide_edges = || -> Vec<(usize, DVec2, DVec2)> { edges(poly).collect() };
    match kind {
        QueryKind::Position => Answer::new(&[st.pos.x, st.pos.y, st.pos.z]),
        QueryKind::Heading => Answer::new(&[st.h.x, st.h.y, st.h.z]),
        QueryKind::DistanceLink => nearest(&link_edges()),
        QueryKind::DistanceGuide => nearest(&guide_edges()),
        // Drawn segments have ids after the guide's edges, as for ?N_A and ?X.
        QueryKind::DistanceElement => match grid.and_then(|g| g.nearest(p)) {
            Some((d, c, i)) => closest(d, c, poly.len() + i),
            None => Answer::new(&[0.0; 4]),
        },
        QueryKind::AheadLink => ahead(first_ahead(&link_edges())),
        QueryKind::AheadGuide => ahead(first_ahead(&guide_edges())),
        QueryKind::AheadElement => {
            // Guide edges come first (ids 0..n), so they win ties.
            let edge = first_ahead(&guide_edges());
            let limit = edge.map_or(f64::INFINITY, |e| e.0);
            let element = grid
                .and_then(|g| g.ray(p, dir, limit))
                .map(|(t, i)| (t, poly.len() + i));
            ahead(match (edge, element) {
                (Some(e), Some(x)) if x.0.total_cmp(&e.0).is_lt() => Some(x),
                (Some(e), _) => Some(e),
                (None, x) => x,
            })
        }
        // Answered by `collide`, which also reports the edge crossed.
        QueryKind::Collision => Answer::new(&[found(false)]),
    }
}

/// ?X: does the next element of length `delta` leave the guide or hit an
/// element? Returns the answer (found, id) and the guide edge it would cross
/// (where a link may hold a token to reserve).
pub(crate) fn collide(
    scene: &Scene,
    grid: Option<&Layers>,
    gi: usize,
    st: &State,
    delta: f64,
) -> (Answer, Option<usize>) {
    let p = st.pos.truncate();
    let q = (st.pos + st.h * delta * st.scale).truncate();
    let poly = &scene.guides[gi].polygon;
    let mut best: Option<(f64, usize)> = None;
    for (i, a, b) in edges(poly) {
        if let Some(t) = crossing(p, q, a, b)
            && t > 1e-6
            && best.is_none_or(|(bt, _)| t < bt)
        {
            best = Some((t, i));
        }
    }
    if let Some((_, edge)) = best {
        return (Answer::new(&[1.0, edge as f64]), Some(edge));
    }
    if let Some(i) = grid.and_then(|g| g.first_crossing(p, q)) {
        return (Answer::new(&[1.0, (poly.len() + i) as f64]), None);
    }
    (Answer::new(&[0.0, 0.0]), None)
}

/// The centre of every element of `prog` in its local frame (`outline_centre`).
pub fn element_centres(prog: &Program) -> Vec<DVec2> {
    prog.elements
        .iter()
        .map(|e| outline_centre(&e.path))
        .collect()
}

/// The centre of an element's path data in its local frame (x right, y along the
/// heading): the middle of its outline's bounding box, or the origin for a path
/// that encloses nothing.
pub fn outline_centre(path: &str) -> DVec2 {
    crate::path::largest_outline(path)
        .and_then(|pts| {
            let first = *pts.first()?;
            let (lo, hi) = pts
                .iter()
                .fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p)));
            Some((lo + hi) * 0.5)
        })
        .unwrap_or(DVec2::ZERO)
}

/// Forwards to `inner` only what lies inside the guide by the centre rule: a
/// segment, element or polygon whose centre is outside its guide is removed (an
/// element's centre is that of its outline, placed and scaled as it is drawn).
/// `kept` counts what went through (and its bounding box, as the turtle's
/// `Drawn` has it: segment ends, polygon points, element origins).
pub struct Clip<'a> {
    pub polygon: &'a [DVec2],
    /// Per element index, its local centre (`element_centres`).
    pub centres: &'a [DVec2],
    pub inner: &'a mut dyn Sink,
    pub kept: Drawn,
    pub removed: u64,
}

impl<'a> Clip<'a> {
    pub fn new(polygon: &'a [DVec2], centres: &'a [DVec2], inner: &'a mut dyn Sink) -> Clip<'a> {
        Clip {
            polygon,
            centres,
            inner,
            kept: Drawn::default(),
            removed: 0,
        }
    }

    fn grow(&mut self, p: DVec3) {
        let b = self.kept.bbox.get_or_insert([p.x, p.y, p.x, p.y]);
        b[0] = b[0].min(p.x);
        b[1] = b[1].min(p.y);
        b[2] = b[2].max(p.x);
        b[3] = b[3].max(p.y);
    }
}

impl Sink for Clip<'_> {
    fn segment(&mut self, a: DVec3, b: DVec3, w: f64, c: u32) {
        if inside(((a + b) * 0.5).truncate(), self.polygon) {
            self.kept.segments += 1;
            self.grow(a);
            self.grow(b);
            self.inner.segment(a, b, w, c);
        } else {
            self.removed += 1;
        }
    }
    fn polygon(&mut self, pts: &[DVec3], c: u32) {
        let centre = pts.iter().fold(DVec3::ZERO, |s, &p| s + p) / pts.len().max(1) as f64;
        if inside(centre.truncate(), self.polygon) {
            self.kept.polygons += 1;
            for &p in pts {
                self.grow(p);
            }
            self.inner.polygon(pts, c);
        } else {
            self.removed += 1;
        }
    }
    fn element(&mut self, i: u16, at: DVec3, h: DVec3, l: DVec3, s: f64, c: u32) {
        let local = self.centres.get(i as usize).copied().unwrap_or(DVec2::ZERO);
        // Local +x is -l, local +y is h.
        let centre = at + (h * local.y - l * local.x) * s;
        if inside(centre.truncate(), self.polygon) {
            self.kept.elements += 1;
            self.grow(at);
            self.inner.element(i, at, h, l, s, c);
        } else {
            self.removed += 1;
        }
    }
}
