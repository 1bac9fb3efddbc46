//! Running a scene: the Open L-system loop over every seeded system, tokens
//! that are reserved, used or released, messages, and the incremental rerun.
//!
//! Owns: the entry `run` and what a run produces (`Instance`, `Outcome`,
//! `GuideRun`, `Message`, `TokenEvent`); grouping guides into *units* (guides
//! that reach each other through links with tokens; a unit runs as one),
//! running units in link order so that every unit knows the messages it
//! receives, the derive → interpret → answer loop of one unit, the token
//! states of Guided Procedural Modeling §3.3.2, and the cache of unit results
//! keyed on everything a unit reads (its guides' polygons, programs, seeds and
//! links, and its incoming messages), so that `Runner::run` after an edit
//! recomputes only the changed guides and those downstream of them whose
//! incoming messages changed. Must not build scenes (`scene`), compute a query
//! answer itself (`query`) or clip drawings (`clip`); in `env` only `explain`
//! imports it.
//!
//! One step of a unit, for step t ≥ 1:
//! 1. every system with steps left derives once;
//! 2. systems are interpreted, and each reservation made at step t − 1 is
//!    settled: if the reserving system now draws a segment from where its `?X`
//!    stood across the linked edge, the token is *used* and a message sent;
//!    otherwise it is *released* (free again);
//! 3. messages of step t (from this unit and from units before it) seed the
//!    end guides' systems, in the order of the sending guide, then sending order;
//! 4. the query modules of systems that derived at t or were just seeded are
//!    answered; a `?X` whose segment would cross an edge holding a link with a
//!    free token *reserves* it (systems with steps left only; first come, in
//!    instance then string order).
//!
//! Seeds start at step 0 (answered before the first derivation). A unit ends
//! when none of its systems derives and no message is still to come.

use super::grown::{Grown, Piece};
use super::index::{Grid, Layers, key};
use super::query::{Answer, Probe, collide, edge_meet, inward, query};
use super::redraw::Sketch;
use super::scene::{Link, Scene, seed_state};
use crate::derive::{self, Limits, ModString};
use crate::diagnostic::Diagnostic;
use crate::geometry::closest_on_segment;
use crate::query::{QUERIES, QueryKind};
use crate::turtle;
use crate::turtle::State;
use glam::DVec2;
use rayon::prelude::*;
use std::collections::HashMap;

/// The most derivation steps a scene runs, whatever its systems say.
pub const MAX_SCENE_STEPS: u32 = 100_000;

/// One running L-system: a seed in a guide and its string.
#[derive(Clone)]
pub struct Instance {
    pub guide: usize,
    pub start: State,
    pub string: ModString,
    pub steps: u32,
    /// The scene step at which it was seeded (0 for explicit seeds).
    pub seeded: u32,
    /// The link whose message seeded it (`None` for an explicit seed).
    pub via: Option<usize>,
    /// The scene step at which its string last changed.
    pub changed: u32,
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

/// Runs a scene to the end: until no system is still deriving (see the
/// module note for the order of events). The links' `used` counts are filled
/// in.
pub fn run(
    scene: &mut Scene,
    seed: u64,
    limits: Limits,
    max_steps: Option<u32>,
) -> Result<Outcome, Diagnostic> {
    let cfg = Config::new(seed, limits, max_steps);
    let (out, _) = execute(scene, cfg, &[], &mut Cache::default())?;
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

/// A message over a link, sent at `step` by guide `from_guide`.
#[derive(Clone, Debug, PartialEq)]
pub struct Message {
    pub step: u32,
    pub link: usize,
    pub from_guide: usize,
    /// Its place in the sending guide's messages.
    pub seq: usize,
    /// Where the crossing segment met the start edge.
    pub at: DVec2,
    /// The direction of the crossing segment (for `heading continue`).
    pub dir: DVec2,
    /// The pass-through parameters of the `?X` that reserved the token (Δ first).
    pub pass: Vec<f64>,
}

/// What happened to a token.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Token {
    /// A free token was taken by a `?X` that would cross its edge.
    Reserved,
    /// The reserving system crossed the edge: the message was sent.
    Used,
    /// The reserving system did not cross: the token is free again.
    Released,
}

/// One change of a token's state.
#[derive(Clone, Debug, PartialEq)]
pub struct TokenEvent {
    pub step: u32,
    pub link: usize,
    pub token: Token,
    /// The reserving system (index in its guide's systems) and its `?X` module
    /// (position in the string when it reserved).
    pub instance: usize,
    pub module: usize,
}

/// One guide's share of a run.
#[derive(Clone, Default)]
pub struct GuideRun {
    /// Its systems: explicit seeds first, then those seeded by messages.
    pub instances: Vec<Instance>,
    pub sent: Vec<Message>,
    /// Token events of the links starting at this guide.
    pub tokens: Vec<TokenEvent>,
    /// Derivation steps performed (of all its systems).
    pub derivations: u64,
    pub queries: u64,
    /// The last step at which one of its systems derived.
    pub last_step: u32,
}

/// What a run does not read from the scene.
#[derive(Clone, Copy, Debug)]
pub struct Config {
    pub seed: u64,
    pub limits: Limits,
    /// The most steps (`MAX_SCENE_STEPS` at most).
    pub cap: u32,
}

impl Config {
    /// The configuration of `run`: at most `max_steps` (and `MAX_SCENE_STEPS`).
    pub fn new(seed: u64, limits: Limits, max_steps: Option<u32>) -> Config {
        Config {
            seed,
            limits,
            cap: max_steps.unwrap_or(MAX_SCENE_STEPS).min(MAX_SCENE_STEPS),
        }
    }
}

/// Unit results by their guides, with the key they were computed from.
#[derive(Default)]
pub struct Cache {
    units: HashMap<Vec<usize>, (Vec<u64>, Vec<GuideRun>)>,
}

/// A reservation waiting for the next step.
struct Reservation {
    link: usize,
    instance: usize,
    module: usize,
    /// Where the reserving turtle stood, and its heading.
    from: DVec2,
    dir: DVec2,
    pass: Vec<f64>,
}

/// A unit's guide while it runs.
struct Live {
    guide: usize,
    run: GuideRun,
    /// Each system's string and drawing, in pieces (the instances' strings
    /// are written from them when the unit ends).
    grown: Vec<Grown>,
    /// Pieces are numbered in the guide as they are made.
    next_piece: usize,
    /// One grid over the segments of all its systems' drawings: the kept
    /// pieces' segments (indexed once, when a piece is kept) and the live
    /// pieces' as its live part, replaced at each step; keys are (piece,
    /// place in it), so a query asks one index however many systems the
    /// guide holds.
    index: Grid,
    /// Per piece: the id of its first segment (segments numbered in the
    /// order of the systems and their strings; see `Layers`).
    offsets: Vec<usize>,
    /// A system was drawn since `index` was made.
    redrawn: bool,
    /// Answer this system's queries in this step.
    fresh: Vec<bool>,
    /// The system's string holds only modules without rules (no query, no
    /// cut): deriving it changes nothing any more, so it is not done.
    settled: Vec<bool>,
    reserved: Vec<Reservation>,
}

/// The units of a scene (guides joined both ways by links with tokens), in an
/// order where every unit comes after the units that send it messages.
pub fn units(scene: &Scene) -> Vec<Vec<usize>> {
    let n = scene.guides.len();
    let mut out_edges = vec![Vec::new(); n];
    let mut in_edges = vec![Vec::new(); n];
    for l in scene.links.iter().filter(|l| l.tokens > 0) {
        if l.from.0 < n && l.to.0 < n {
            out_edges[l.from.0].push(l.to.0);
            in_edges[l.to.0].push(l.from.0);
        }
    }
    // Kosaraju, without recursion: finishing order on the graph, then
    // components on the reversed graph in reverse finishing order (which comes
    // out in topological order of the components).
    let mut seen = vec![false; n];
    let mut finished = Vec::with_capacity(n);
    for s in 0..n {
        if seen[s] {
            continue;
        }
        seen[s] = true;
        let mut stack = vec![(s, 0usize)];
        while let Some((v, i)) = stack.pop() {
            if i < out_edges[v].len() {
                stack.push((v, i + 1));
                let w = out_edges[v][i];
                if !seen[w] {
                    seen[w] = true;
                    stack.push((w, 0));
                }
            } else {
                finished.push(v);
            }
        }
    }
    let mut comp = vec![usize::MAX; n];
    let mut units = Vec::new();
    for &s in finished.iter().rev() {
        if comp[s] != usize::MAX {
            continue;
        }
        let id = units.len();
        let mut members = vec![s];
        comp[s] = id;
        let mut k = 0;
        while k < members.len() {
            let v = members[k];
            k += 1;
            for &w in &in_edges[v] {
                if comp[w] == usize::MAX {
                    comp[w] = id;
                    members.push(w);
                }
            }
        }
        members.sort_unstable();
        units.push(members);
    }
    units
}

/// Runs every unit of the scene, reusing cached unit results whose key is
/// unchanged. `revs` are revision numbers of the programs (part of the key).
/// Returns the outcome and, per guide, whether it was computed afresh.
pub fn execute(
    scene: &Scene,
    cfg: Config,
    revs: &[u64],
    cache: &mut Cache,
) -> Result<(Outcome, Vec<bool>), Diagnostic> {
    let n = scene.guides.len();
    let units = units(scene);
    let (unit_of, level) = levels(scene, &units);
    let mut sent: Vec<Vec<Message>> = vec![Vec::new(); n];
    let mut fresh = vec![false; n];
    let mut keep = HashMap::new();
    let top = level.iter().copied().max().unwrap_or(0);
    for lv in 0..=top {
        let mut jobs = Vec::new();
        for (u, unit) in units.iter().enumerate().filter(|(u, _)| level[*u] == lv) {
            let inbox = inbox(scene, &unit_of, u, &sent);
            let key = unit_key(scene, cfg, revs, unit, &inbox);
            let cached = match cache.units.remove(unit) {
                Some((k, r)) if k == key => Some(r),
                _ => None,
            };
            jobs.push((unit, inbox, key, cached));
        }
        let results: Vec<Result<(bool, Vec<GuideRun>), Diagnostic>> = jobs
            .par_iter_mut()
            .map(|(unit, inbox, _, cached)| match cached.take() {
                Some(r) => Ok((false, r)),
                None => run_unit(scene, cfg, unit, inbox).map(|r| (true, r)),
            })
            .collect();
        for ((unit, _, key, _), result) in jobs.into_iter().zip(results) {
            let (computed, result) = result?;
            for (&g, r) in unit.iter().zip(&result) {
                fresh[g] = computed;
                sent[g] = r.sent.clone();
            }
            keep.insert(unit.clone(), (key, result));
        }
    }
    let out = outcome(n, &keep);
    cache.units = keep;
    Ok((out, fresh))
}

/// Per guide its unit, and per unit its level: a unit runs after every unit
/// that sends it messages; the units of one level run in parallel.
fn levels(scene: &Scene, units: &[Vec<usize>]) -> (Vec<usize>, Vec<usize>) {
    let n = scene.guides.len();
    let mut unit_of = vec![0; n];
    for (u, members) in units.iter().enumerate() {
        for &g in members {
            unit_of[g] = u;
        }
    }
    let mut level = vec![0usize; units.len()];
    for u in 0..units.len() {
        for l in scene
            .links
            .iter()
            .filter(|l| l.tokens > 0 && l.from.0 < n && l.to.0 < n)
        {
            let (a, b) = (unit_of[l.from.0], unit_of[l.to.0]);
            if b == u && a != u {
                level[u] = level[u].max(level[a] + 1);
            }
        }
    }
    (unit_of, level)
}

/// The messages into unit `u` from the units before it (`sent`, per guide),
/// by step, sending guide and sending order.
fn inbox(scene: &Scene, unit_of: &[usize], u: usize, sent: &[Vec<Message>]) -> Vec<Message> {
    let n = scene.guides.len();
    let mut inbox: Vec<Message> = scene
        .links
        .iter()
        .enumerate()
        .filter(|(_, l)| {
            l.to.0 < n && unit_of[l.to.0] == u && l.from.0 < n && unit_of[l.from.0] != u
        })
        .flat_map(|(li, l)| sent[l.from.0].iter().filter(move |m| m.link == li).cloned())
        .collect();
    inbox.sort_by_key(|m| (m.step, m.from_guide, m.seq));
    inbox
}

/// The outcome of a run from the results of its units, in guide order.
fn outcome(n: usize, keep: &HashMap<Vec<usize>, (Vec<u64>, Vec<GuideRun>)>) -> Outcome {
    let mut runs: Vec<Option<&GuideRun>> = vec![None; n];
    for (unit, (_, result)) in keep {
        for (&g, r) in unit.iter().zip(result) {
            runs[g] = Some(r);
        }
    }
    let mut out = Outcome {
        instances: Vec::new(),
        steps: 0,
        queries: 0,
        messages: 0,
        guides: Vec::with_capacity(n),
    };
    for r in runs.into_iter().flatten() {
        out.steps = out.steps.max(r.last_step);
        out.queries += r.queries;
        out.messages += r.sent.len() as u64;
        out.instances.extend(r.instances.iter().cloned());
        out.guides.push(GuideRun {
            instances: Vec::new(),
            sent: r.sent.clone(),
            tokens: r.tokens.clone(),
            ..*r
        });
    }
    out
}

/// Everything a unit's run reads, as numbers: equal keys, equal results.
fn unit_key(
    scene: &Scene,
    cfg: Config,
    revs: &[u64],
    unit: &[usize],
    inbox: &[Message],
) -> Vec<u64> {
    let mut k = vec![
        cfg.seed,
        u64::from(cfg.cap),
        cfg.limits.max_modules as u64,
        cfg.limits.max_bytes as u64,
    ];
    let pt = |k: &mut Vec<u64>, p: DVec2| k.extend([p.x.to_bits(), p.y.to_bits()]);
    for &g in unit {
        let guide = &scene.guides[g];
        k.extend([g as u64, guide.polygon.len() as u64]);
        for &p in &guide.polygon {
            pt(&mut k, p);
        }
        k.extend([
            guide.program as u64,
            revs.get(guide.program).copied().unwrap_or(0),
            guide.seeds.len() as u64,
        ]);
        for s in &guide.seeds {
            pt(&mut k, s.at);
            k.extend([s.heading.to_bits(), s.args.len() as u64]);
            k.extend(s.args.iter().map(|a| a.to_bits()));
        }
    }
    for (i, l) in scene.links.iter().enumerate() {
        let from = unit.binary_search(&l.from.0).is_ok();
        let to = unit.binary_search(&l.to.0).is_ok();
        if from || to {
            k.extend([
                i as u64,
                l.from.0 as u64,
                l.from.1 as u64,
                l.to.0 as u64,
                l.to.1 as u64,
                u64::from(l.tokens),
                l.heading.to_bits(),
                u64::from(l.continues),
                u64::from(l.aim_middle),
                l.take.map_or(u64::MAX, f64::to_bits),
            ]);
        }
    }
    for m in inbox {
        k.extend([
            u64::from(m.step),
            m.link as u64,
            m.from_guide as u64,
            m.seq as u64,
        ]);
        pt(&mut k, m.at);
        pt(&mut k, m.dir);
        k.push(m.pass.len() as u64);
        k.extend(m.pass.iter().map(|a| a.to_bits()));
    }
    k
}

/// Runs one unit to its end, receiving `inbox` (sorted by step, sender, order).
fn run_unit(
    scene: &Scene,
    cfg: Config,
    unit: &[usize],
    inbox: &[Message],
) -> Result<Vec<GuideRun>, Diagnostic> {
    let mut live = start(scene, cfg, unit)?;
    let plans: Vec<derive::Plan> = scene.programs.iter().map(derive::Plan::new).collect();
    let mut used = vec![0u32; scene.links.len()];
    answer(scene, cfg, &mut live, &used, 0)?;
    let mut next = 0; // the first message of `inbox` not yet delivered
    let mut t = 1;
    while t <= cfg.cap {
        let any = derive_all(scene, cfg, &plans, &mut live, t)?;
        if !any {
            // Idle: wait for the next message from outside, if any.
            match inbox.get(next) {
                None => break,
                Some(m) if m.step > t => {
                    t = m.step;
                    continue;
                }
                Some(_) => {}
            }
        }
        interpret(scene, cfg, &mut live)?;
        let mut outgoing = Vec::new();
        for l in &mut live {
            settle(scene, l, &mut used, t, &mut outgoing);
        }
        for m in &arriving(scene, unit, inbox, &mut next, outgoing, t) {
            deliver(scene, cfg, unit, &mut live, m)?;
        }
        answer(scene, cfg, &mut live, &used, t)?;
        t += 1;
    }
    if t > MAX_SCENE_STEPS && (growing(scene, &live).is_some() || next < inbox.len()) {
        return Err(never_settles(scene, unit, &live));
    }
    release_all(&mut live, t.min(cfg.cap));
    Ok(live
        .into_iter()
        .map(|mut l| {
            for (inst, grown) in l.run.instances.iter_mut().zip(&l.grown) {
                inst.string = grown.string();
            }
            l.run
        })
        .collect())
}

/// The guides of a unit with their explicit seeds' systems.
fn start(scene: &Scene, cfg: Config, unit: &[usize]) -> Result<Vec<Live>, Diagnostic> {
    let mut live: Vec<Live> = Vec::with_capacity(unit.len());
    for &g in unit {
        let guide = &scene.guides[g];
        let prog = &scene.programs[guide.program];
        let mut l = Live {
            guide: g,
            run: GuideRun::default(),
            grown: Vec::new(),
            next_piece: 0,
            index: Grid::default(),
            offsets: Vec::new(),
            redrawn: false,
            fresh: Vec::new(),
            settled: Vec::new(),
            reserved: Vec::new(),
        };
        for s in &guide.seeds {
            let string = derive::axiom(prog, &s.args, cfg.seed).map_err(|e| e.diagnostic(prog))?;
            l.add(Instance {
                guide: g,
                start: seed_state(s.at, s.heading),
                string,
                steps: 0,
                seeded: 0,
                via: None,
                changed: 0,
            });
        }
        live.push(l);
    }
    Ok(live)
}

/// This step's messages into the unit: from outside (`inbox` from `next`
/// on, which moves past them), then from inside (`outgoing`), ordered by
/// sending guide and sending order.
fn arriving(
    scene: &Scene,
    unit: &[usize],
    inbox: &[Message],
    next: &mut usize,
    outgoing: Vec<Message>,
    t: u32,
) -> Vec<Message> {
    let mut arriving: Vec<Message> = Vec::new();
    while *next < inbox.len() && inbox[*next].step <= t {
        if inbox[*next].step == t {
            arriving.push(inbox[*next].clone());
        }
        *next += 1;
    }
    arriving.extend(
        outgoing
            .into_iter()
            .filter(|m| unit.binary_search(&scene.links[m.link].to.0).is_ok()),
    );
    arriving.sort_by_key(|m| (m.from_guide, m.seq));
    arriving
}

/// The first guide of a unit with a system that still derives and still
/// changes (not settled), or `None`.
fn growing(scene: &Scene, live: &[Live]) -> Option<usize> {
    live.iter()
        .find(|l| {
            let prog = &scene.programs[scene.guides[l.guide].program];
            l.run
                .instances
                .iter()
                .zip(&l.settled)
                .any(|(inst, settled)| inst.steps < prog.derive && !settled)
        })
        .map(|l| l.guide)
}

/// The error of a unit still growing (or with messages still to deliver)
/// when the scene has run `MAX_SCENE_STEPS`: it names the guide, and a link
/// that feeds the unit's messages back into it, where there is one (a
/// guide linked to itself, or guides linked in a circle).
fn never_settles(scene: &Scene, unit: &[usize], live: &[Live]) -> Diagnostic {
    let g = growing(scene, live).unwrap_or(unit[0]);
    let guide = &scene.guides[g];
    let within = |x: usize| unit.binary_search(&x).is_ok();
    let sent = |i: usize| {
        live.iter()
            .flat_map(|l| &l.run.sent)
            .filter(|m| m.link == i)
            .count()
    };
    // The link inside the unit that carried the most messages back into it.
    let circle = (0..scene.links.len())
        .filter(|&i| within(scene.links[i].from.0) && within(scene.links[i].to.0))
        .map(|i| (sent(i), i))
        .filter(|&(n, _)| n > 0)
        .max()
        .map(|(n, i)| (n, &scene.links[i]));
    let mut d = Diagnostic::error(
        crate::diagnostic::Code::SceneNeverSettles,
        format!(
            "guide `{}` is still growing after {MAX_SCENE_STEPS} steps, the most a scene runs",
            guide.name
        ),
    )
    .primary(guide.span, "still growing here");
    if let Some((sent, l)) = circle {
        let name = |(g, e): (usize, usize)| format!("{}.edge({e})", scene.guides[g].name);
        let what = if l.from.0 == l.to.0 {
            "links the guide to itself"
        } else {
            "closes a circle of links"
        };
        d = d.secondary(
            l.span,
            format!(
                "`{} -> {}` {what}: each crossing seeds the growth again ({sent} message{} so far)",
                name(l.from),
                name(l.to),
                if sent == 1 { "" } else { "s" }
            ),
        );
    }
    d.help("let the systems end within the scene (a smaller `derive`, a rule that stops growing), give the links fewer tokens, or run fewer steps with -n")
}

/// Reservations nobody will settle: the tokens are free again at `step`.
fn release_all(live: &mut [Live], step: u32) {
    for l in live {
        for r in std::mem::take(&mut l.reserved) {
            l.run.tokens.push(TokenEvent {
                step,
                link: r.link,
                token: Token::Released,
                instance: r.instance,
                module: r.module,
            });
        }
    }
}

impl Live {
    fn add(&mut self, inst: Instance) {
        self.grown
            .push(Grown::new(inst.string.clone(), self.next_piece));
        self.next_piece += 1;
        self.run.instances.push(inst);
        self.fresh.push(true);
        self.settled.push(false);
    }
}

/// Derives every system with steps left, once (step `t`, each program by
/// its plan in `plans`); whether any did.
fn derive_all(
    scene: &Scene,
    cfg: Config,
    plans: &[derive::Plan],
    live: &mut [Live],
    t: u32,
) -> Result<bool, Diagnostic> {
    type Job<'a> = (&'a mut Instance, &'a mut Grown, &'a mut bool, &'a mut bool);
    let mut jobs: Vec<Job> = Vec::new();
    let mut any = false;
    for l in live.iter_mut() {
        let prog = &scene.programs[scene.guides[l.guide].program];
        let mut n = 0;
        for (((inst, grown), fresh), settled) in l
            .run
            .instances
            .iter_mut()
            .zip(&mut l.grown)
            .zip(&mut l.fresh)
            .zip(&mut l.settled)
        {
            if inst.steps < prog.derive {
                n += 1;
                if *settled {
                    inst.steps += 1;
                } else {
                    jobs.push((inst, grown, fresh, settled));
                }
            }
        }
        if n > 0 {
            any = true;
            l.run.derivations += n;
            l.run.last_step = t;
        }
    }
    let results: Vec<Result<(), Diagnostic>> = jobs
        .into_par_iter()
        .map(|(inst, grown, fresh, settled)| {
            let program = scene.guides[inst.guide].program;
            let prog = &scene.programs[program];
            inst.steps += 1;
            let changed = grown
                .derive(prog, &plans[program], inst.steps, cfg.seed, cfg.limits)
                .map_err(|e| e.diagnostic(prog))?;
            if changed {
                inst.changed = t;
            }
            *fresh = true;
            *settled = grown.all(|x| inert(prog, x));
            Ok(())
        })
        .collect();
    results.into_iter().collect::<Result<(), _>>()?;
    let modules: usize = live.iter().flat_map(|l| &l.grown).map(Grown::len).sum();
    if modules > cfg.limits.max_modules {
        return Err(Diagnostic::error(
            crate::diagnostic::Code::TooManyModules,
            format!(
                "step {t} of the scene would hold {modules} modules in all its systems, more than the limit of {}",
                cfg.limits.max_modules
            ),
        )
        .help("derive fewer steps with -n, give the links fewer tokens, or raise the limit with --max-modules"));
    }
    Ok(any)
}

/// Interprets every system whose string changed since it was last interpreted.
fn interpret(scene: &Scene, cfg: Config, live: &mut [Live]) -> Result<(), Diagnostic> {
    let mut jobs = Vec::new();
    for l in live.iter_mut() {
        for (inst, grown) in l.run.instances.iter().zip(&mut l.grown) {
            if !grown.drawn() {
                l.redrawn = true;
                jobs.push((inst, grown));
            }
        }
    }
    let results: Vec<Result<(), Diagnostic>> = jobs
        .into_par_iter()
        .map(|(inst, grown)| {
            let prog = &scene.programs[scene.guides[inst.guide].program];
            // Only ?D_E, ?N_E and ?X read what a guide's systems drew (and
            // settling a reservation, which only ?X makes): a program that
            // asks none of them needs only the turtle at its query modules,
            // and its guide's index stays empty.
            let reads = reads_drawing(prog);
            if reads && super::redraw::redrawable(prog) {
                grown.draw(prog, inst.start);
                return Ok(());
            }
            let interpret = if reads {
                turtle::interpret_limited
            } else {
                turtle::interpret_queries
            };
            let mut result = Ok(());
            grown.draw_whole(|s| {
                let mut p = Probe::default();
                if let Err(e) = interpret(prog, s, cfg.seed, inst.start, cfg.limits, &mut p) {
                    result = Err(e.diagnostic(prog));
                }
                if !reads {
                    p.segments.clear();
                }
                Sketch::whole(p)
            });
            result
        })
        .collect();
    results.into_iter().collect()
}

/// Brings each guide's index up to its systems' drawings (all drawn): first
/// the live pieces are cut and the segments of the pieces kept indexed for
/// good, then the live pieces' segments become the index's live part.
fn reindex(scene: &Scene, live: &mut [Live]) {
    live.par_iter_mut().filter(|l| l.redrawn).for_each(|l| {
        let prog = &scene.programs[scene.guides[l.guide].program];
        if Grown::splits(prog, reads_drawing(prog)) {
            for (inst, grown) in l.run.instances.iter().zip(&mut l.grown) {
                grown.cut(prog, inst.start, &mut l.next_piece);
            }
        }
        // Number the segments: per piece, the id of its first.
        l.offsets.resize(l.next_piece, 0);
        let mut off = 0;
        for p in l.grown.iter().flat_map(|g| &g.pieces) {
            match p {
                Piece::Kept(k) => {
                    for &(id, n) in &k.ids {
                        l.offsets[id as usize] = off;
                        off += n as usize;
                    }
                }
                Piece::Live(x) => {
                    l.offsets[x.id] = off;
                    off += x.drawing.as_ref().map_or(0, |d| d.drawn.segments.len());
                }
            }
        }
        let (mut segs, mut keys) = (Vec::new(), Vec::new());
        for p in l.grown.iter_mut().flat_map(|g| &mut g.pieces) {
            let Piece::Kept(k) = p else { continue };
            if !std::mem::replace(&mut k.pending, false) {
                continue;
            }
            for x in k.parts.iter_mut().filter(|x| !x.indexed) {
                keys.extend((0..x.segments.len()).map(|i| key(x.id, i)));
                segs.extend_from_slice(&x.segments);
                x.indexed = true;
            }
        }
        l.index.push(&segs, keys);
        let grown = &l.grown;
        l.index.set_live_with(|segs, keys| {
            for p in grown.iter().flat_map(|g| &g.pieces) {
                if let Piece::Live(x) = p
                    && let Some(d) = &x.drawing
                {
                    keys.extend((0..d.drawn.segments.len()).map(|i| key(x.id, i)));
                    segs.extend_from_slice(&d.drawn.segments);
                }
            }
        });
        l.redrawn = false;
    });
}

/// Settles the reservations of guide `l` made in the step before `t`.
fn settle(scene: &Scene, l: &mut Live, used: &mut [u32], t: u32, out: &mut Vec<Message>) {
    for r in std::mem::take(&mut l.reserved) {
        let link = &scene.links[r.link];
        let poly = &scene.guides[l.guide].polygon;
        let e = link.from.1 % poly.len();
        let inward = inward(poly);
        let tol = 1e-6 * (1.0 + r.from.abs().max_element());
        // Of the segments drawn from where the ?X stood across the edge, the one
        // closest to its heading (the first of equals): several branches may
        // start at one point.
        let mut hit: Option<(f64, DVec2, DVec2)> = None;
        for &(s0, s1) in l.grown[r.instance].segments_near(r.from, tol) {
            if (s0 - r.from).length() > tol {
                continue;
            }
            if let Some(c) = edge_meet(poly, inward, e, s0, s1) {
                let along = (s1 - s0).normalize_or_zero().dot(r.dir);
                if hit.is_none_or(|(best, _, _)| along > best) {
                    hit = Some((along, s0 + (s1 - s0) * c, s1 - s0));
                }
            }
        }
        let hit = hit.map(|h| (h.1, h.2));
        let token = if hit.is_some() {
            Token::Used
        } else {
            Token::Released
        };
        l.run.tokens.push(TokenEvent {
            step: t,
            link: r.link,
            token,
            instance: r.instance,
            module: r.module,
        });
        if let Some((at, dir)) = hit {
            used[r.link] += 1;
            let m = Message {
                step: t,
                link: r.link,
                from_guide: l.guide,
                seq: l.run.sent.len(),
                at,
                dir,
                pass: r.pass,
            };
            l.run.sent.push(m.clone());
            out.push(m);
        }
    }
}

/// Seeds the end guide's system with a message.
fn deliver(
    scene: &Scene,
    cfg: Config,
    unit: &[usize],
    live: &mut [Live],
    m: &Message,
) -> Result<(), Diagnostic> {
    let link = &scene.links[m.link];
    let (tg, te) = link.to;
    let Ok(k) = unit.binary_search(&tg) else {
        return Ok(());
    };
    let poly = &scene.guides[tg].polygon;
    let (a, b) = (poly[te % poly.len()], poly[(te + 1) % poly.len()]);
    let at = closest_on_segment(m.at, a, b);
    // `heading continue`: the heading of the crossing segment (0 = +y,
    // counter-clockwise positive).
    let heading = if link.continues && m.dir.length_squared() > 0.0 {
        (-m.dir.x).atan2(m.dir.y).to_degrees()
    } else {
        link.heading
    };
    let prog = &scene.programs[scene.guides[tg].program];
    let mut args = m.pass.clone();
    args.resize(prog.params.len(), 0.0);
    let string = derive::axiom(prog, &args, cfg.seed).map_err(|e| e.diagnostic(prog))?;
    live[k].add(Instance {
        guide: tg,
        start: seed_state(at, heading),
        string,
        steps: 0,
        seeded: m.step,
        via: Some(m.link),
        changed: m.step,
    });
    Ok(())
}

/// A `?X` whose segment would cross a guide edge: its place and parameters.
struct Crossing {
    module: usize,
    edge: usize,
    from: DVec2,
    dir: DVec2,
    pass: Vec<f64>,
}

/// Answers the queries of the fresh systems (derived at `t` or just seeded)
/// and makes reservations.
fn answer(
    scene: &Scene,
    cfg: Config,
    live: &mut [Live],
    used: &[u32],
    t: u32,
) -> Result<(), Diagnostic> {
    interpret(scene, cfg, live)?;
    reindex(scene, live);
    let layers = layers(live);
    // Piece by piece in parallel, then system by system in order.
    let mut answered: Vec<(usize, usize, Answers)> = fresh_drawings(live)
        .into_par_iter()
        .map(|(li, k, pi, origin)| {
            let a = answer_piece(scene, &live[li], &layers[li], k, pi, origin);
            (li, k, a)
        })
        .collect();
    answered.dedup_by(|b, a| {
        let same = (a.0, a.1) == (b.0, b.1);
        if same {
            a.2.0.append(&mut b.2.0);
            a.2.1.append(&mut b.2.1);
        }
        same
    });
    for (li, k, (answers, crossings)) in answered {
        let l = &mut live[li];
        // A system that will not draw again makes no reservation.
        if write_answers(scene, l, k, answers) {
            reserve(scene, l, k, crossings, used, t);
        }
    }
    for l in live.iter_mut() {
        l.fresh.iter_mut().for_each(|f| *f = false);
    }
    Ok(())
}

/// Per guide: the index of its systems' drawings.
fn layers(live: &[Live]) -> Vec<Layers<'_>> {
    live.iter()
        .map(|l| Layers {
            grid: Some(&l.index),
            offsets: &l.offsets,
        })
        .collect()
}

/// The live pieces of the fresh systems that met query modules: (guide in
/// the unit, system in the guide, piece, its first module's place in the
/// string), in order.
fn fresh_drawings(live: &[Live]) -> Vec<(usize, usize, usize, usize)> {
    let mut jobs = Vec::new();
    for (li, l) in live.iter().enumerate() {
        for (k, (g, &f)) in l.grown.iter().zip(&l.fresh).enumerate() {
            if !f {
                continue;
            }
            for (pi, origin, _) in g.live() {
                if g.drawing(pi).is_some_and(|d| !d.drawn.queries.is_empty()) {
                    jobs.push((li, k, pi, origin));
                }
            }
        }
    }
    jobs
}

/// A system's answers, each with its piece, where its parameters start in
/// the piece and how many they are, and the `?X` that would cross a guide
/// edge.
type Answers = (Vec<(usize, usize, usize, Answer)>, Vec<Crossing>);

/// Answers every query module that live piece `pi` of system `k` of guide
/// `l` (its first module at `origin` in the string) met in its drawing, in
/// the order of its string.
fn answer_piece(
    scene: &Scene,
    l: &Live,
    layers: &Layers,
    k: usize,
    pi: usize,
    origin: usize,
) -> Answers {
    let gi = l.guide;
    let grown = &l.grown[k];
    let prog = &scene.programs[scene.guides[gi].program];
    let grid = Some(layers);
    let mut answers = Vec::new();
    let mut crossings = Vec::new();
    if let (Some(drawing), Some(piece)) = (grown.drawing(pi), grown.live_piece(pi)) {
        // The queries come in the order of their modules: their parameters'
        // place is counted on from the last one's (from the start, were one
        // ever before the last).
        let (mut next, mut at) = (0, 0);
        for &(m, kind, state) in &drawing.drawn.queries {
            let q = &QUERIES[kind as usize];
            if m < next {
                (next, at) = (0, 0);
            }
            at += piece.string.syms[next..m]
                .iter()
                .map(|&x| prog.symbols.arity(x))
                .sum::<usize>();
            next = m;
            let arity = prog.symbols.arity(piece.string.syms[m]);
            let own = &piece.string.params[at..at + arity];
            let ans = match q.kind {
                QueryKind::Collision => {
                    let delta = own.get(q.outputs.len()).copied().unwrap_or(0.0);
                    let (ans, edge) = collide(scene, grid, gi, &state, delta);
                    if let Some(edge) = edge {
                        crossings.push(Crossing {
                            module: origin + m,
                            edge,
                            from: state.pos.truncate(),
                            dir: state.h.truncate().normalize_or_zero(),
                            pass: own
                                .get(q.outputs.len()..)
                                .map_or(Vec::new(), <[f64]>::to_vec),
                        });
                    }
                    ans
                }
                kind => query(scene, grid, gi, kind, &state),
            };
            answers.push((pi, at, arity, ans));
        }
    }
    (answers, crossings)
}

/// Writes the answers into system `k`'s string (its drawing is dropped when
/// it may read them); whether the system will draw again (and so may reserve).
fn write_answers(
    scene: &Scene,
    l: &mut Live,
    k: usize,
    answers: Vec<(usize, usize, usize, Answer)>,
) -> bool {
    let prog = &scene.programs[scene.guides[l.guide].program];
    l.run.queries += answers.len() as u64;
    let grown = &mut l.grown[k];
    for (piece, at, arity, ans) in answers {
        for (slot, v) in grown.params_mut(piece)[at..at + arity]
            .iter_mut()
            .zip(ans.values())
        {
            *slot = *v;
        }
    }
    if queries_interpreted(prog) {
        // Its drawing may read the answers: draw it again when needed.
        grown.forget();
    }
    l.run.instances[k].steps < prog.derive
}

/// Reserves, for each crossing of system `k`, a free token of every link
/// that starts at the crossed edge.
fn reserve(scene: &Scene, l: &mut Live, k: usize, crossings: Vec<Crossing>, used: &[u32], t: u32) {
    for c in crossings {
        // Every link that starts at the crossed edge and has a free token (an
        // edge may fan out to several guides), in scene order.
        let free: Vec<usize> = (0..scene.links.len())
            .filter(|&i| {
                let link = &scene.links[i];
                link.from == (l.guide, c.edge)
                    && link.take.is_none_or(|v| c.pass.get(1) == Some(&v))
                    && used[i] as usize + l.reserved.iter().filter(|r| r.link == i).count()
                        < link.tokens as usize
            })
            .collect();
        for link in free {
            l.run.tokens.push(TokenEvent {
                step: t,
                link,
                token: Token::Reserved,
                instance: k,
                module: c.module,
            });
            l.reserved.push(Reservation {
                link,
                instance: k,
                module: c.module,
                from: c.from,
                dir: c.dir,
                pass: c.pass.clone(),
            });
        }
    }
}

/// Whether module `sym` never changes: no rules, not a query, not `cut`.
fn inert(prog: &crate::compile::Program, sym: crate::compile::Sym) -> bool {
    prog.rules.get(sym as usize).is_none_or(|r| r.is_empty())
        && !matches!(
            prog.symbols.info[sym as usize].action,
            crate::compile::Action::Query(_) | crate::compile::Action::Cut
        )
}

/// Whether a query module of the program reads the segments its guide's
/// systems drew (?D_E, ?N_E, ?X).
fn reads_drawing(prog: &crate::compile::Program) -> bool {
    prog.symbols.info.iter().any(|info| match info.action {
        crate::compile::Action::Query(k) => matches!(
            QUERIES[k as usize].kind,
            QueryKind::DistanceElement | QueryKind::AheadElement | QueryKind::Collision
        ),
        _ => false,
    })
}

/// Whether an interpretation rule rewrites a query module (then a system's
/// drawing may depend on its answers).
fn queries_interpreted(prog: &crate::compile::Program) -> bool {
    prog.symbols.info.iter().enumerate().any(|(i, info)| {
        matches!(info.action, crate::compile::Action::Query(_))
            && prog.interpret.get(i).is_some_and(|r| !r.is_empty())
    })
}

/// A scene with its cache: `run` recomputes only what changed since the last
/// run (guides whose polygon, seeds, program or links changed, and the guides
/// downstream whose incoming messages changed).
pub struct Runner {
    pub scene: Scene,
    pub cfg: Config,
    /// Revision of each program; `replace_program` bumps it.
    revs: Vec<u64>,
    cache: Cache,
    /// Derivation steps performed per guide, over all runs.
    pub derivations: Vec<u64>,
    /// Per guide: whether the last run computed it afresh.
    pub recomputed: Vec<bool>,
}

impl Runner {
    pub fn new(scene: Scene, cfg: Config) -> Runner {
        let n = scene.guides.len();
        let p = scene.programs.len();
        Runner {
            scene,
            cfg,
            revs: vec![0; p],
            cache: Cache::default(),
            derivations: vec![0; n],
            recomputed: vec![false; n],
        }
    }

    /// Replaces program `i` (its guides rerun at the next `run`).
    pub fn replace_program(&mut self, i: usize, prog: crate::compile::Program) {
        if let Some(p) = self.scene.programs.get_mut(i) {
            *p = prog;
            self.revs[i] += 1;
        }
    }

    /// Runs the scene, reusing every unit whose inputs did not change.
    pub fn run(&mut self) -> Result<Outcome, Diagnostic> {
        let (out, fresh) = execute(&self.scene, self.cfg, &self.revs, &mut self.cache)?;
        self.derivations.resize(self.scene.guides.len(), 0);
        for (g, r) in out.guides.iter().enumerate() {
            if fresh[g] {
                self.derivations[g] += r.derivations;
            }
        }
        for (l, link) in self.scene.links.iter_mut().enumerate() {
            link.used = out
                .guides
                .iter()
                .flat_map(|r| &r.tokens)
                .filter(|e| e.link == l && e.token == Token::Used)
                .count() as u32;
        }
        self.recomputed = fresh;
        Ok(out)
    }
}
