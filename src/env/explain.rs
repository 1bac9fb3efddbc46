//! Scenes that explain themselves: what each guide did in a run (`explain`,
//! `GuideReport`, `render`), and the warnings a run that went quietly wrong
//! deserves (`warnings`): a guide never seeded while the link to it kept its
//! tokens, a system stopped by `derive` while it still had queries to answer
//! (with the steps it would have needed), and growth that leaves its guide and
//! comes back in.
//!
//! Owns: reading a finished run (`Outcome`) against its scene. Reruns a scene
//! only to measure the steps a system would have needed. Must not change how a
//! scene runs (that is `engine`).

use super::clip::{Clip, element_centres};
use super::engine::{Config, Instance, Outcome, Token, execute};
use super::scene::Scene;
use crate::compile::{Action, Program};
use crate::diagnostic::{Code, Diagnostic};
use crate::geometry::{closest_on_segment, inside};
use crate::turtle::{self, Discard, Sink};
use glam::{DVec2, DVec3};
use rayon::prelude::*;
use std::collections::HashMap;
use std::fmt::Write;

/// How one system of a guide started.
#[derive(Clone, Debug, PartialEq)]
pub struct Seeding {
    /// The scene step (0 for an explicit seed).
    pub step: u32,
    /// The link whose message seeded it, or `None` for an explicit seed.
    pub via: Option<usize>,
    pub at: DVec2,
}

/// The tokens of one link that starts at a guide.
#[derive(Clone, Debug, PartialEq)]
pub struct LinkTokens {
    pub link: usize,
    pub tokens: u32,
    pub used: u32,
    /// Reservations that ended released (the reserving system drew nothing
    /// across the edge).
    pub released: u32,
}

/// One guide's share of a run.
#[derive(Clone, Debug, PartialEq)]
pub struct GuideReport {
    pub guide: usize,
    pub name: String,
    pub system: String,
    pub seedings: Vec<Seeding>,
    /// Derivation steps of all its systems, and the last step one derived.
    pub derivations: u64,
    pub last_step: u32,
    /// What the centre rule kept (segments, elements) and clipped.
    pub segments: u64,
    pub elements: u64,
    pub clipped: u64,
    pub tokens: Vec<LinkTokens>,
}

/// Records every segment in drawing order.
#[derive(Default)]
struct Trace {
    segs: Vec<(DVec2, DVec2)>,
}

impl Sink for Trace {
    fn segment(&mut self, a: DVec3, b: DVec3, _: f64, _: u32) {
        self.segs.push((a.truncate(), b.truncate()));
    }
    fn polygon(&mut self, _: &[DVec3], _: u32) {}
    fn element(&mut self, _: u16, _: DVec3, _: DVec3, _: DVec3, _: f64, _: u32) {}
}

fn program<'a>(scene: &'a Scene, inst: &Instance) -> &'a Program {
    &scene.programs[scene.guides[inst.guide].program]
}

/// Per guide, what its systems did in the run `out` of `scene` (interpreting
/// every system once more, through the centre rule, to count what is kept).
pub fn explain(scene: &Scene, out: &Outcome, cfg: Config) -> Result<Vec<GuideReport>, Diagnostic> {
    let mut reports: Vec<GuideReport> = scene
        .guides
        .iter()
        .enumerate()
        .map(|(g, guide)| GuideReport {
            guide: g,
            name: guide.name.clone(),
            system: scene.programs[guide.program].name.clone(),
            seedings: Vec::new(),
            derivations: out.guides.get(g).map_or(0, |r| r.derivations),
            last_step: out.guides.get(g).map_or(0, |r| r.last_step),
            segments: 0,
            elements: 0,
            clipped: 0,
            tokens: Vec::new(),
        })
        .collect();
    let centres: Vec<Vec<DVec2>> = scene.programs.iter().map(element_centres).collect();
    for inst in &out.instances {
        let r = &mut reports[inst.guide];
        r.seedings.push(Seeding {
            step: inst.seeded,
            via: inst.via,
            at: inst.start.pos.truncate(),
        });
        let prog = program(scene, inst);
        let mut discard = Discard;
        let mut clip = Clip::new(
            &scene.guides[inst.guide].polygon,
            &centres[scene.guides[inst.guide].program],
            &mut discard,
        );
        turtle::interpret_limited(
            prog,
            &inst.string,
            cfg.seed,
            inst.start,
            cfg.limits,
            &mut clip,
        )
        .map_err(|e| e.diagnostic(prog))?;
        r.segments += clip.kept.segments;
        r.elements += clip.kept.elements;
        r.clipped += clip.removed;
    }
    for (i, l) in scene.links.iter().enumerate() {
        let events = out.guides.get(l.from.0).map_or(&[][..], |r| &r.tokens[..]);
        let count = |t: Token| {
            events
                .iter()
                .filter(|e| e.link == i && e.token == t)
                .count() as u32
        };
        reports[l.from.0].tokens.push(LinkTokens {
            link: i,
            tokens: l.tokens,
            used: count(Token::Used),
            released: count(Token::Released),
        });
    }
    Ok(reports)
}

/// A link as written: `trunk.edge(2) -> crown.edge(0)`.
pub fn link_name(scene: &Scene, i: usize) -> String {
    let l = &scene.links[i];
    let g = |k: usize| scene.guides.get(k).map_or("?", |g| g.name.as_str());
    format!(
        "{}.edge({}) -> {}.edge({})",
        g(l.from.0),
        l.from.1,
        g(l.to.0),
        l.to.1
    )
}

fn num(v: f64) -> String {
    crate::number::source((v * 100.0).round() / 100.0)
}

/// The reports as text, one block per guide.
pub fn render(scene: &Scene, reports: &[GuideReport]) -> String {
    let mut s = String::new();
    for r in reports {
        let _ = writeln!(s, "guide {} (lsystem {}):", r.name, r.system);
        if r.seedings.is_empty() {
            let _ = writeln!(s, "  never seeded");
        }
        for x in &r.seedings {
            let how = match x.via {
                None => "explicit seed".to_string(),
                Some(l) => format!("message over link {l} ({})", link_name(scene, l)),
            };
            let _ = writeln!(
                s,
                "  seeded at step {} by {how} at ({}, {})",
                x.step,
                num(x.at.x),
                num(x.at.y)
            );
        }
        let _ = writeln!(
            s,
            "  {} derivation steps, the last at step {}; kept {} segments and {} elements, clipped {}",
            r.derivations, r.last_step, r.segments, r.elements, r.clipped
        );
        for t in &r.tokens {
            let _ = writeln!(
                s,
                "  link {} ({}): {} of {} tokens used{}",
                t.link,
                link_name(scene, t.link),
                t.used,
                t.tokens,
                if t.released > 0 {
                    format!(", {} reservations released", t.released)
                } else {
                    String::new()
                }
            );
        }
    }
    s
}

/// Whether a string still holds a query module that a rule rewrites: the
/// system wanted to go on.
fn pending(prog: &Program, inst: &Instance) -> bool {
    inst.string.syms.iter().any(|&x| {
        matches!(prog.symbols.info[x as usize].action, Action::Query(_))
            && prog.rules.get(x as usize).is_some_and(|r| !r.is_empty())
    })
}

/// The most steps a rerun gives a system cut short, to find how many it needs.
const PROBE_STEPS: u32 = 2000;

/// The most modules (all systems together) of a run whose systems cut short
/// are rerun to find how many steps they need.
const PROBE_MODULES: usize = 200_000;

/// The warnings a finished run deserves (see the module note), in scene order.
pub fn warnings(scene: &Scene, out: &Outcome, cfg: Config) -> Vec<Diagnostic> {
    let mut diags = Vec::new();
    cut_short(scene, out, cfg, &mut diags);
    never_seeded(scene, out, &mut diags);
    comes_back(scene, out, cfg, &mut diags);
    diags
}

/// Systems that `derive` stopped while they still had queries to answer.
fn cut_short(scene: &Scene, out: &Outcome, cfg: Config, diags: &mut Vec<Diagnostic>) {
    let short: Vec<(usize, usize)> = index_in_guide(out)
        .into_iter()
        .filter(|&(k, _)| {
            let inst = &out.instances[k];
            let prog = program(scene, inst);
            inst.steps >= prog.derive && pending(prog, inst)
        })
        .collect();
    if short.is_empty() {
        return;
    }
    // Rerun with more steps for the programs cut short, to see when each
    // system would have finished; not for a large scene, where the rerun
    // would cost several times the run (the warning then gives no count).
    let modules: usize = out.instances.iter().map(|i| i.string.syms.len()).sum();
    let mut more = scene.clone();
    for &(k, _) in &short {
        let p = scene.guides[out.instances[k].guide].program;
        let d = scene.programs[p].derive;
        more.programs[p].derive = d.max(PROBE_STEPS.min(d.saturating_mul(20).max(200)));
    }
    let probe = (modules <= PROBE_MODULES)
        .then(|| execute(&more, cfg, &[], &mut Default::default()).ok())
        .flatten()
        .map(|r| r.0);
    let mut told = vec![false; scene.programs.len()];
    for (k, nth) in short {
        let inst = &out.instances[k];
        let p = scene.guides[inst.guide].program;
        if std::mem::replace(&mut told[p], true) {
            continue;
        }
        let prog = &scene.programs[p];
        let guide = &scene.guides[inst.guide];
        let again = probe.as_ref().and_then(|o| {
            let mut n = 0;
            o.instances.iter().find(|i| {
                let hit = i.guide == inst.guide && n == nth;
                n += usize::from(i.guide == inst.guide);
                hit
            })
        });
        let need = again.map(|i| {
            let done = !pending(&more.programs[p], i);
            (
                done,
                i.changed.saturating_sub(i.seeded),
                more.programs[p].derive,
            )
        });
        let mut d = Diagnostic::warning(
            Code::DeriveRanOut,
            format!(
                "lsystem `{}` in guide `{}` stopped after `derive {}` steps with query modules still to answer",
                prog.name, guide.name, prog.derive
            ),
        )
        .primary(prog.name_span, "its `derive` ran out here")
        .secondary(guide.span, "the guide it grew in");
        d = match need {
            Some((true, n, _)) => d.help(format!(
                "it finishes after {n} steps: write `derive {n};` (each segment a query steers takes two steps: the query, then the segment)"
            )),
            Some((false, _, m)) => d.help(format!(
                "it still had queries after {m} steps: its growth may not end by itself"
            )),
            None => d.help(
                "raise its `derive` (each segment a query steers takes two steps: the query, then the segment)",
            ),
        };
        diags.push(d);
    }
}

/// Per instance of the outcome: (its index, its place among its guide's).
fn index_in_guide(out: &Outcome) -> Vec<(usize, usize)> {
    let mut seen: HashMap<usize, usize> = HashMap::new();
    out.instances
        .iter()
        .enumerate()
        .map(|(k, i)| {
            let n = seen.entry(i.guide).or_default();
            *n += 1;
            (k, *n - 1)
        })
        .collect()
}

/// Guides never seeded although a link to them kept free tokens.
fn never_seeded(scene: &Scene, out: &Outcome, diags: &mut Vec<Diagnostic>) {
    let mut seeded = vec![false; scene.guides.len()];
    for i in &out.instances {
        seeded[i.guide] = true;
    }
    let mut told = vec![false; scene.guides.len()];
    for (li, l) in scene.links.iter().enumerate() {
        let to = l.to.0;
        if l.tokens == 0 || seeded[to] || l.used >= l.tokens || told[to] {
            continue;
        }
        told[to] = true;
        let from = &scene.guides[l.from.0];
        let events = out.guides.get(l.from.0).map_or(&[][..], |r| &r.tokens[..]);
        let released = events
            .iter()
            .filter(|e| e.link == li && e.token == Token::Released)
            .count();
        // How close the sending guide's drawing came to the linked edge.
        let poly = &from.polygon;
        let (a, b) = (
            poly[l.from.1 % poly.len()],
            poly[(l.from.1 + 1) % poly.len()],
        );
        let mut closest: Option<f64> = None;
        for inst in out.instances.iter().filter(|i| i.guide == l.from.0) {
            let mut t = Trace::default();
            let prog = program(scene, inst);
            if turtle::interpret_limited(
                prog,
                &inst.string,
                0,
                inst.start,
                Default::default(),
                &mut t,
            )
            .is_ok()
            {
                for (p, q) in t.segs {
                    for x in [p, q] {
                        let d = (closest_on_segment(x, a, b) - x).length();
                        closest = Some(closest.map_or(d, |c: f64| c.min(d)));
                    }
                }
            }
        }
        let mut d = Diagnostic::warning(
            Code::NeverSeeded,
            format!(
                "guide `{}` was never seeded: link {} kept {} of its {} tokens",
                scene.guides[to].name,
                link_name(scene, li),
                l.tokens - l.used,
                l.tokens
            ),
        )
        .primary(l.span, "no message went over this link")
        .secondary(scene.guides[to].span, "never seeded");
        d = if released > 0 {
            d.note(format!(
                "a `?X` of `{}` reserved a token {released} time(s), but the next step drew no segment from there across the edge, so the token was released",
                from.name
            ))
        } else {
            match closest {
                Some(c) => d.note(format!(
                    "no `?X` of guide `{}` tested a segment across edge {}; its drawing came within {} of the edge",
                    from.name,
                    l.from.1,
                    num(c)
                )),
                None => d.note(format!("guide `{}` drew nothing", from.name)),
            }
        };
        diags.push(d.help(
            "a token is taken when a `?X(Δ)` whose segment would cross the linked edge is followed by a segment drawn across it (`F`, not `f`); steer to the edge with `?D_L` and check that `derive` leaves enough steps",
        ));
    }
}

/// Growth that leaves its guide (segments the centre rule removes) and comes
/// back in along the same path: the guide's edge did not stop it.
fn comes_back(scene: &Scene, out: &Outcome, cfg: Config, diags: &mut Vec<Diagnostic>) {
    #[derive(Clone, Copy, PartialEq)]
    enum Path {
        Inside,
        Outside,
        Left,
    }
    // Where each system's growth comes back in, and how many of its segments
    // lie outside (systems in parallel; the first system of a guide that
    // comes back is told).
    let found: Vec<Option<(DVec2, usize)>> = out
        .instances
        .par_iter()
        .map(|inst| {
            let poly = &scene.guides[inst.guide].polygon;
            let mut t = Trace::default();
            let prog = program(scene, inst);
            turtle::interpret_limited(prog, &inst.string, cfg.seed, inst.start, cfg.limits, &mut t)
                .ok()?;
            let ins: Vec<bool> = t
                .segs
                .iter()
                .map(|(p, q)| inside((*p + *q) * 0.5, poly))
                .collect();
            let outside = ins.iter().filter(|&&x| !x).count();
            if outside == 0 {
                // Nothing left the guide: nothing came back.
                return None;
            }
            let key = |p: DVec2| (p.x.to_bits(), p.y.to_bits());
            let mut at: HashMap<(u64, u64), Path> = HashMap::new();
            let mut back: Option<DVec2> = None;
            for ((p, q), &ins) in t.segs.iter().zip(&ins) {
                let before = at.get(&key(*p)).copied();
                let now = match (ins, before) {
                    (true, Some(Path::Left)) => {
                        back.get_or_insert(*p);
                        Path::Inside
                    }
                    (true, _) => Path::Inside,
                    (false, Some(Path::Inside | Path::Left)) => Path::Left,
                    (false, _) => Path::Outside,
                };
                at.insert(key(*q), now);
            }
            back.map(|p| (p, outside))
        })
        .collect();
    let mut told = vec![false; scene.guides.len()];
    for (inst, found) in out.instances.iter().zip(found) {
        if told[inst.guide] {
            continue;
        }
        if let Some((p, outside)) = found {
            told[inst.guide] = true;
            let guide = &scene.guides[inst.guide];
            diags.push(
                Diagnostic::warning(
                    Code::LeavesAndComesBack,
                    format!(
                        "growth in guide `{}` leaves the guide and comes back in at ({}, {})",
                        guide.name,
                        num(p.x),
                        num(p.y)
                    ),
                )
                .primary(guide.span, "the growth crossed this guide's edge and went on")
                .note(format!(
                    "{outside} segment(s) of the system seeded at ({}, {}) lie outside and are not drawn (the centre rule); the path continues inside",
                    num(inst.start.pos.x),
                    num(inst.start.pos.y)
                ))
                .help("test each segment with `?X(Δ)` before drawing it and stop (`cut`) when it hits the guide's edge"),
            );
        }
    }
}
