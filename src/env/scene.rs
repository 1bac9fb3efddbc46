//! A scene at run time: guides with their compiled systems, links with tokens,
//! and the loop that derives every active L-system, interprets it, answers its
//! query modules from the guide's geometry, and turns `?X` crossings of linked
//! edges into messages that seed the end guide's system.

use super::geometry::{closest_on_segment, crossing, inside, ray_hit, signed_angle};
use super::index::Grid;
use crate::ast::{File, GuideStmt, Item, LinkStmt, SceneStmt};
use crate::check::Checked;
use crate::compile::{self, ExprCompiler, Program};
use crate::derive::{self, Limits, ModString};
use crate::diagnostic::{Code, Diagnostic};
use crate::query::QUERIES;
use crate::run::runtime_diagnostic;
use crate::turtle::{self, Sink, State};
use glam::{DVec2, DVec3};
use rayon::prelude::*;
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
}

fn value(e: &crate::ast::Expr, checked: &Checked) -> f64 {
    ExprCompiler::fold_const(e, checked).unwrap_or(0.0)
}

/// Builds the scene called `name` (or the first) of a checked file.
pub fn build(file: &File, checked: &Checked, name: Option<&str>) -> Result<Scene, String> {
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
            .ok_or_else(|| format!("there is no scene `{n}`"))?,
        None => *scenes.first().ok_or("the file has no scene")?,
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
        let system = system.ok_or_else(|| format!("guide `{}` has no system", g.name.name))?;
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
        let end = |r: &crate::ast::EdgeRef| -> Result<(usize, usize), String> {
            let g = *index
                .get(&r.guide.name)
                .ok_or_else(|| format!("no guide `{}`", r.guide.name))?;
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
struct Probe {
    segments: Vec<(DVec2, DVec2)>,
    queries: Vec<(usize, u8, State)>,
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

/// Runs a scene to the end: until no system is still deriving.
pub fn run(
    scene: &mut Scene,
    seed: u64,
    limits: Limits,
    max_steps: Option<u32>,
) -> Result<Outcome, Diagnostic> {
    let mut instances = Vec::new();
    for (gi, g) in scene.guides.iter().enumerate() {
        let prog = &scene.programs[g.program];
        for s in &g.seeds {
            let string =
                derive::axiom(prog, &s.args, seed).map_err(|e| runtime_diagnostic(&e, prog))?;
            instances.push(Instance {
                guide: gi,
                start: seed_state(s.at, s.heading),
                string,
                steps: 0,
            });
        }
    }
    let mut out = Outcome {
        instances,
        steps: 0,
        queries: 0,
        messages: 0,
    };
    answer(scene, &mut out, seed)?;
    let cap = max_steps.unwrap_or(MAX_SCENE_STEPS).min(MAX_SCENE_STEPS);
    for step in 1..=cap {
        let mut any = false;
        for inst in out.instances.iter_mut() {
            let prog = &scene.programs[scene.guides[inst.guide].program];
            if inst.steps >= prog.derive {
                continue;
            }
            inst.steps += 1;
            any = true;
            inst.string = derive::step(prog, &inst.string, inst.steps, seed, limits)
                .map_err(|e| runtime_diagnostic(&e, prog))?;
        }
        if !any {
            break;
        }
        out.steps = step;
        answer(scene, &mut out, seed)?;
    }
    Ok(out)
}

/// Interprets every instance and writes the environment's answers into its
/// query modules; crossings of linked edges with free tokens send messages.
/// A system seeded by a message has its queries answered before it derives.
fn answer(scene: &mut Scene, out: &mut Outcome, seed: u64) -> Result<(), Diagnostic> {
    let mut from = 0;
    loop {
        let before = out.instances.len();
        answer_from(scene, out, seed, from)?;
        if out.instances.len() == before {
            return Ok(());
        }
        from = before;
    }
}

/// Answers the queries of instances `from..` (all instances' geometry counts).
/// Instances are interpreted and answered in parallel; answers and messages
/// are gathered in instance order, so the thread count changes nothing.
fn answer_from(
    scene: &mut Scene,
    out: &mut Outcome,
    seed: u64,
    from: usize,
) -> Result<(), Diagnostic> {
    let sc: &Scene = scene;
    let probes: Vec<Result<Probe, Diagnostic>> = out
        .instances
        .par_iter()
        .map(|inst| {
            let prog = &sc.programs[sc.guides[inst.guide].program];
            let mut probe = Probe::default();
            turtle::interpret_from(prog, &inst.string, seed, inst.start, &mut probe)
                .map_err(|e| runtime_diagnostic(&e, prog))?;
            Ok(probe)
        })
        .collect();
    let probes = probes.into_iter().collect::<Result<Vec<_>, _>>()?;
    // Everything drawn in each guide, for element queries and collisions.
    let mut drawn: Vec<Vec<(DVec2, DVec2)>> = vec![Vec::new(); sc.guides.len()];
    for (inst, probe) in out.instances.iter().zip(&probes) {
        drawn[inst.guide].extend_from_slice(&probe.segments);
    }
    // A spatial index per guide that has questions about its drawing; it also
    // covers the asking points.
    let mut asked: Vec<Vec<DVec2>> = vec![Vec::new(); sc.guides.len()];
    for (k, probe) in probes.iter().enumerate().skip(from) {
        let gi = out.instances[k].guide;
        for (_, kind, st) in &probe.queries {
            if matches!(QUERIES[*kind as usize].name, "?X" | "?D_A" | "?N_A") {
                asked[gi].push(st.pos.truncate());
            }
        }
    }
    let grids: Vec<Option<Grid>> = drawn
        .par_iter()
        .zip(asked.par_iter())
        .map(|(d, a)| (!a.is_empty()).then(|| Grid::new(d, a)))
        .collect();
    type Answered = (Vec<(usize, usize, Answer)>, Vec<(usize, DVec2, Vec<f64>)>);
    let answered: Vec<Answered> = out.instances[from..]
        .par_iter()
        .zip(probes[from..].par_iter())
        .map(|(inst, probe)| {
            let gi = inst.guide;
            let prog = &sc.programs[sc.guides[gi].program];
            let offsets = param_offsets(prog, &inst.string);
            let mut answers = Vec::with_capacity(probe.queries.len());
            let mut spawned = Vec::new();
            for &(module, kind, state) in &probe.queries {
                let q = &QUERIES[kind as usize];
                let at = offsets[module] as usize;
                let arity = prog.symbols.arity(inst.string.syms[module]);
                let own = &inst.string.params[at..at + arity];
                let grid = grids[gi].as_ref();
                let ans = match q.name {
                    "?X" => {
                        let delta = own.get(q.outputs.len()).copied().unwrap_or(0.0);
                        let (ans, msg) = collide(sc, grid, gi, &state, delta);
                        if let Some((link, point)) = msg {
                            // A message passes all of ?X's pass-through parameters, Δ first.
                            let pass = own
                                .get(q.outputs.len()..)
                                .map_or(Vec::new(), <[f64]>::to_vec);
                            spawned.push((link, point, pass));
                        }
                        ans
                    }
                    name => query(sc, grid, gi, name, &state),
                };
                answers.push((at, arity, ans));
            }
            (answers, spawned)
        })
        .collect();
    let mut spawned = Vec::new();
    for (inst, (answers, sp)) in out.instances[from..].iter_mut().zip(answered) {
        for (at, arity, ans) in answers {
            out.queries += 1;
            let own = &mut inst.string.params[at..at + arity];
            for (slot, v) in own.iter_mut().zip(ans.values()) {
                *slot = *v;
            }
        }
        spawned.extend(sp);
    }
    for (link, point, pass) in spawned {
        let l = &mut scene.links[link];
        if l.used >= l.tokens {
            continue;
        }
        l.used += 1;
        let (tg, te) = l.to;
        let heading = l.heading;
        let poly = &scene.guides[tg].polygon;
        let (a, b) = (poly[te % poly.len()], poly[(te + 1) % poly.len()]);
        let at = closest_on_segment(point, a, b);
        let prog = &scene.programs[scene.guides[tg].program];
        let mut args = pass;
        args.resize(prog.params.len(), 0.0);
        let string = derive::axiom(prog, &args, seed).map_err(|e| runtime_diagnostic(&e, prog))?;
        out.messages += 1;
        out.instances.push(Instance {
            guide: tg,
            start: seed_state(at, heading),
            string,
            steps: 0,
        });
    }
    Ok(())
}

fn param_offsets(prog: &Program, s: &ModString) -> Vec<u32> {
    let mut off = Vec::with_capacity(s.len());
    let mut p = 0u32;
    for &x in &s.syms {
        off.push(p);
        p += prog.symbols.arity(x) as u32;
    }
    off
}

/// The outputs of one query module (at most four numbers).
#[derive(Clone, Copy)]
struct Answer {
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

    fn values(&self) -> &[f64] {
        &self.values[..self.len]
    }
}

fn found(b: bool) -> f64 {
    f64::from(u8::from(b))
}

/// Answers ?P ?H ?D_* ?N_* for a turtle in guide `gi`; `grid` indexes what is
/// drawn in the guide (None when nothing asks about it).
fn query(scene: &Scene, grid: Option<&Grid>, gi: usize, name: &str, st: &State) -> Answer {
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
    match name {
        "?P" => Answer::new(&[st.pos.x, st.pos.y, st.pos.z]),
        "?H" => Answer::new(&[st.h.x, st.h.y, st.h.z]),
        "?D_L" => nearest(&link_edges()),
        "?D_G" => nearest(&guide_edges()),
        "?D_A" => match grid.and_then(|g| g.nearest(p)) {
            Some((d, c, i)) => closest(d, c, i),
            None => Answer::new(&[0.0; 4]),
        },
        "?N_L" => ahead(first_ahead(&link_edges())),
        "?N_G" => ahead(first_ahead(&guide_edges())),
        "?N_A" => {
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
        _ => Answer::new(&[found(false)]),
    }
}

/// ?X: does the next element of length `delta` leave the guide or hit an
/// element? Returns the answer (found, id) and, for a linked edge, the link
/// and the crossing point.
fn collide(
    scene: &Scene,
    grid: Option<&Grid>,
    gi: usize,
    st: &State,
    delta: f64,
) -> (Answer, Option<(usize, DVec2)>) {
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
    if let Some((t, edge)) = best {
        let point = p + (q - p) * t;
        let link = scene
            .links
            .iter()
            .position(|l| l.from == (gi, edge) && l.used < l.tokens);
        return (Answer::new(&[1.0, edge as f64]), link.map(|l| (l, point)));
    }
    if let Some(i) = grid.and_then(|g| g.first_crossing(p, q)) {
        return (Answer::new(&[1.0, (poly.len() + i) as f64]), None);
    }
    (Answer::new(&[0.0, 0.0]), None)
}

/// Forwards to `inner` only what lies inside the guide by the centre rule: a
/// segment or element whose centre is outside its guide is removed.
pub struct Clip<'a> {
    pub polygon: &'a [DVec2],
    pub inner: &'a mut dyn Sink,
    pub kept: u64,
    pub removed: u64,
}

impl Sink for Clip<'_> {
    fn segment(&mut self, a: DVec3, b: DVec3, w: f64, c: u32) {
        if inside(((a + b) * 0.5).truncate(), self.polygon) {
            self.kept += 1;
            self.inner.segment(a, b, w, c);
        } else {
            self.removed += 1;
        }
    }
    fn polygon(&mut self, pts: &[DVec3], c: u32) {
        let centre = pts.iter().fold(DVec3::ZERO, |s, &p| s + p) / pts.len().max(1) as f64;
        if inside(centre.truncate(), self.polygon) {
            self.inner.polygon(pts, c);
        }
    }
    fn element(&mut self, i: u16, at: DVec3, h: DVec3, l: DVec3, s: f64, c: u32) {
        if inside((at + h * (0.5 * s)).truncate(), self.polygon) {
            self.kept += 1;
            self.inner.element(i, at, h, l, s, c);
        } else {
            self.removed += 1;
        }
    }
}

/// A problem building the scene, as a diagnostic.
pub fn build_error(msg: String) -> Diagnostic {
    Diagnostic::error(Code::UnknownSystem, msg)
}
