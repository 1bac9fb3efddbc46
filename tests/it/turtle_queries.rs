//! `turtle::interpret_queries` (what a scene's system needs between steps when
//! no query reads its drawing) meets every query module with the state
//! `turtle::interpret_limited` has there, over every lsystem of the gallery
//! at every step.

use crate::support::{lsy_files, rel};
use glam::DVec3;
use lsyc::ast::Item;
use lsyc::derive::{Limits, ModString};
use lsyc::run::{self, Options};
use lsyc::turtle::{self, Sink, State};

/// The query modules met, with the state there, and the segments drawn.
#[derive(Default)]
struct Calls {
    queries: Vec<(usize, u8, String)>,
    segments: u64,
}

impl Sink for Calls {
    fn segment(&mut self, _: DVec3, _: DVec3, _: f64, _: u32) {
        self.segments += 1;
    }
    fn polygon(&mut self, _: &[DVec3], _: u32) {}
    fn element(&mut self, _: u16, _: DVec3, _: DVec3, _: DVec3, _: f64, _: u32) {}
    fn query(&mut self, module: usize, kind: u8, state: &State) {
        // Debug prints every f64 so that it reads back the same (−0 too).
        self.queries.push((module, kind, format!("{state:?}")));
    }
}

/// Compares the two on one string; whether branches were passed over
/// before a query (something to compare).
fn compare(
    prog: &lsyc::compile::Program,
    string: &ModString,
    start: State,
    at: &str,
) -> Option<usize> {
    let limits = Limits::default();
    let mut all = Calls::default();
    let mut some = Calls::default();
    // Passing over a branch may pass over its error, not the other way round.
    turtle::interpret_limited(prog, string, 7, start, limits, &mut all).ok()?;
    let part = turtle::interpret_queries(prog, string, 7, start, limits, &mut some);
    assert!(part.is_ok(), "{at}");
    assert_eq!(all.queries, some.queries, "{at}");
    Some(usize::from(
        some.segments < all.segments && !all.queries.is_empty(),
    ))
}

#[test]
fn passing_over_quiet_branches_keeps_every_query_state() {
    let mut strings = 0;
    let mut queries = 0;
    // Strings where branches were passed over and queries came after them.
    let mut saved = 0;
    let mut count = |r: Option<usize>, n: usize| {
        if let Some(s) = r {
            strings += 1;
            saved += s;
            queries += n;
        }
    };
    for path in lsy_files(&["lang-examples"]) {
        let text = std::fs::read_to_string(&path).expect("reads");
        let fe = lsyc::frontend::run(&text, Vec::new(), &[]);
        let checked = fe.checked.as_ref().expect("checks");
        let (mut systems, mut scenes) = (Vec::new(), Vec::new());
        for item in &fe.file.items.stmts {
            match &item.node {
                Item::Lsystem(l) => systems.push(l.name.name.clone()),
                Item::Scene(s) => scenes.push(s.name.name.clone()),
                _ => {}
            }
        }
        // Every lsystem on its own, step by step (turtle queries answered).
        for name in systems {
            for steps in 0..=12 {
                let opts = Options {
                    steps: Some(steps),
                    system: Some(name.clone()),
                    ..Options::default()
                };
                let Ok(d) = run::derive(&fe.file, checked, &opts, &|_, _| {}) else {
                    break;
                };
                let start = State {
                    pos: DVec3::new(3.0, -2.0, 0.0),
                    ..State::default()
                };
                let at = format!("{} {name} step {steps}", rel(&path));
                let n = d.string.len();
                count(compare(&d.prog, &d.string, start, &at), n);
                if n > 50_000 {
                    break;
                }
            }
        }
        // Every scene stopped at several steps, while its systems grow.
        for name in scenes {
            for steps in [1, 3, 6, 10, 15, 20, 30, 45] {
                let opts = Options {
                    steps: Some(steps),
                    ..Options::default()
                };
                let Ok(r) = run::run_scene(&fe.file, checked, Some(&name), &opts) else {
                    continue;
                };
                for (k, inst) in r.outcome.instances.iter().enumerate() {
                    let prog = &r.scene.programs[r.scene.guides[inst.guide].program];
                    let at = format!("{} scene {name} step {steps} system {k}", rel(&path));
                    let n = inst.string.len();
                    count(compare(prog, &inst.string, inst.start, &at), n);
                }
            }
        }
    }
    assert!(
        strings > 500 && saved > 20,
        "{strings} strings, {queries} modules, {saved} with branches passed over"
    );
}
