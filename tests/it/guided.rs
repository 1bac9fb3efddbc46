//! The scene engine beyond single answers: token states (free → reserved →
//! used, reserved → free), competing modules, and the incremental rerun that
//! recomputes only changed guides and those downstream.

use glam::{DVec2, DVec3};
use lsyc::env::engine::{Config, MAX_SCENE_STEPS, Outcome, Runner, Token, TokenEvent};
use lsyc::env::scene::Scene;
use lsyc::frontend;

fn build(text: &str) -> Scene {
    let fe = frontend::run(text, Vec::new(), &[]);
    assert!(
        !fe.has_errors(),
        "{}",
        crate::support::render_plain(&fe.diagnostics, "scene.lsy", text)
    );
    let checked = fe.checked.as_ref().expect("checked");
    lsyc::env::build(&fe.file, checked, None).expect("builds")
}

fn config() -> Config {
    Config {
        seed: 0,
        limits: Default::default(),
        cap: MAX_SCENE_STEPS,
    }
}

fn run(text: &str) -> (Scene, Outcome) {
    let mut scene = build(text);
    let out = lsyc::env::run(&mut scene, 0, Default::default(), None).expect("runs");
    (scene, out)
}

/// Token events of the links from guide `g`, as (step, link, event, module).
fn events(out: &Outcome, g: usize) -> Vec<(u32, usize, Token, usize)> {
    out.guides[g]
        .tokens
        .iter()
        .map(|e: &TokenEvent| (e.step, e.link, e.token, e.module))
        .collect()
}

/// A trunk grows up a 10 × 10 guide in steps of 4; the first ?X is 12 long and
/// would leave through the linked top edge, but the rule for it (k = 1)
/// replaces it by a shorter ?X that does not reach the edge.
const RETREAT: &str = "
lsystem Up {
    derive 20;
    axiom ?X(12, 1);
    ?X(found, _, d, k) : found && k == 1 -> ?X(4, 2);
    ?X(found, _, d, k) : found -> F(d) cut;
    ?X(_, _, d, k) -> F(d) ?X(d, k);
}
lsystem Side(d, v) { derive 0; axiom F(v); }
scene S {
    guide a { polygon (0, 0) (10, 0) (10, 10) (0, 10); system Up; seed (5, 0) heading 0; }
    guide b { polygon (0, 10) (10, 10) (10, 20) (0, 20); system Side; }
    link a.edge(2) -> b.edge(0) { tokens 1; heading 90; }
}
";

#[test]
fn a_token_is_reserved_then_released_then_reserved_and_used() {
    let (scene, out) = run(RETREAT);
    // Step 0: ?X(12) would cross the top edge: the free token is reserved.
    // Step 1: the module became ?X(4, 2) and drew nothing across: released.
    // Step 3: the ?X(4) standing at y = 8 would cross: reserved again.
    // Step 4: it became F(4) from y = 8 to 12, across the edge: used.
    assert_eq!(
        events(&out, 0),
        vec![
            (0, 0, Token::Reserved, 0),
            (1, 0, Token::Released, 0),
            (3, 0, Token::Reserved, 2),
            (4, 0, Token::Used, 2),
        ]
    );
    assert_eq!(out.messages, 1);
    assert_eq!(scene.links[0].used, 1);
    // The message went out when the segment crossed, at the crossing point,
    // with the parameters of the ?X that reserved it.
    let m = &out.guides[0].sent[0];
    assert_eq!((m.step, m.link, m.pass.clone()), (4, 0, vec![4.0, 2.0]));
    assert!((m.at - DVec2::new(5.0, 10.0)).length() < 1e-9, "{}", m.at);
    let seeded = out.instances.iter().find(|i| i.guide == 1).expect("seeded");
    assert!((seeded.start.pos - DVec3::new(5.0, 10.0, 0.0)).length() < 1e-9);
    assert_eq!(seeded.string.params, vec![2.0], "F(v) with v = 2");
}

#[test]
fn only_systems_with_steps_left_reserve() {
    // With derive 0 the ?X is answered at the system's last step: it will never
    // draw, so it reserves nothing. With derive 1 it reserves, then becomes a
    // ?X again instead of a segment: released.
    let text = |derive: u32| {
        format!(
            "lsystem Up {{ derive {derive}; axiom ?X(12); ?X(found, _, d) : found -> ?X(d); }}
             lsystem Side {{ derive 0; axiom F; }}
             scene S {{
                 guide a {{ polygon (0, 0) (10, 0) (10, 10) (0, 10); system Up; seed (5, 0) heading 0; }}
                 guide b {{ polygon (0, 10) (10, 10) (10, 20) (0, 20); system Side; }}
                 link a.edge(2) -> b.edge(0) {{ tokens 1; }}
             }}"
        )
    };
    let (_, out) = run(&text(0));
    assert_eq!(events(&out, 0), vec![]);
    let (scene, out) = run(&text(1));
    assert_eq!(
        events(&out, 0),
        vec![(0, 0, Token::Reserved, 0), (1, 0, Token::Released, 0)]
    );
    assert_eq!((out.messages, scene.links[0].used), (0, 0));
}

/// Two branches race for the tokens of one link.
const RACE: &str = "
lsystem Up {
    derive 5;
    axiom [-(10) ?X(12, 1)] [+(10) ?X(12, 2)];
    ?X(found, _, d, k) : found -> F(d) cut;
}
lsystem Side(d, k) { derive 0; axiom F(k); }
scene S {
    guide a { polygon (0, 0) (10, 0) (10, 10) (0, 10); system Up; seed (5, 0) heading 0; }
    guide b { polygon (-10, 10) (20, 10) (20, 20) (-10, 20); system Side; }
    link a.edge(2) -> b.edge(0) { tokens TOKENS; }
}
";

#[test]
fn competing_modules_take_tokens_in_string_order() {
    // One token: the first branch in the string reserves it, the second finds
    // none; both cross the edge, one message is sent, from the first.
    let (_, out) = run(&RACE.replace("TOKENS", "1"));
    assert_eq!(
        events(&out, 0),
        vec![(0, 0, Token::Reserved, 2), (1, 0, Token::Used, 2)]
    );
    assert_eq!(out.messages, 1);
    let seeded = out.instances.iter().find(|i| i.guide == 1).expect("seeded");
    assert_eq!(seeded.string.params, vec![1.0]);
    // Two tokens: both, in string order; the seeded systems follow it.
    let (_, out) = run(&RACE.replace("TOKENS", "2"));
    assert_eq!(
        events(&out, 0),
        vec![
            (0, 0, Token::Reserved, 2),
            (0, 0, Token::Reserved, 6),
            (1, 0, Token::Used, 2),
            (1, 0, Token::Used, 6),
        ]
    );
    let ks: Vec<f64> = out
        .instances
        .iter()
        .filter(|i| i.guide == 1)
        .map(|i| i.string.params[0])
        .collect();
    assert_eq!(ks, vec![1.0, 2.0]);
    // The crossing points lie on the edge, right (-10°) and left (+10°) of the middle.
    let xs: Vec<f64> = out.guides[0].sent.iter().map(|m| m.at.x).collect();
    assert!(
        xs[0] > 5.0 && xs[1] < 5.0 && out.guides[0].sent[0].at.y == 10.0,
        "{xs:?}"
    );
}

/// Three guides: `a` sends a message to `b`; `c` stands alone.
const THREE: &str = "
lsystem Up {
    derive 30;
    axiom ?X(2, 7);
    ?X(found, _, d, v) : found -> F(d) cut;
    ?X(_, _, d, v) -> F(d) ?X(d, v);
}
lsystem Side(d, v) {
    derive 10;
    axiom ?X(d, v);
    ?X(found, _, d, v) : found -> cut;
    ?X(_, _, d, v) -> F(d) ?X(d, v);
}
scene S {
    guide a { polygon (0, 0) (10, 0) (10, 10) (0, 10); system Up; seed (5, 0) heading 0; }
    guide b { polygon (0, 10) (10, 10) (10, 20) (0, 20); system Side; }
    guide c { polygon (30, 0) (40, 0) (40, 10) (30, 10); system Up; seed (35, 0) heading 0; }
    link a.edge(2) -> b.edge(0) { tokens 1; heading 90; }
}
";

/// Each system: guide, symbols, parameters, start.
type Systems = Vec<(usize, Vec<u16>, Vec<f64>, [f64; 3])>;

fn strings(out: &Outcome) -> Systems {
    out.instances
        .iter()
        .map(|i| {
            (
                i.guide,
                i.string.syms.clone(),
                i.string.params.clone(),
                i.start.pos.to_array(),
            )
        })
        .collect()
}

#[test]
fn a_rerun_recomputes_only_the_changed_guide_and_its_dependents() {
    let mut runner = Runner::new(build(THREE), config());
    let first = runner.run().expect("runs");
    assert_eq!(runner.recomputed, vec![true, true, true]);
    let work = runner.derivations.clone();
    assert!(work.iter().all(|&d| d > 0), "{work:?}");
    assert_eq!(first.messages, 1);

    // Nothing changed: nothing is recomputed, the outcome is the same.
    let again = runner.run().expect("runs");
    assert_eq!(runner.recomputed, vec![false, false, false]);
    assert_eq!(runner.derivations, work);
    assert_eq!(strings(&again), strings(&first));

    // Move the lone guide: only it runs again.
    runner.scene.guides[2].polygon[2].y = 8.0;
    runner.scene.guides[2].polygon[3].y = 8.0;
    let moved = runner.run().expect("runs");
    assert_eq!(runner.recomputed, vec![false, false, true]);
    assert_eq!(runner.derivations[..2], work[..2]);
    assert!(runner.derivations[2] > work[2]);
    // The same as running the edited scene from scratch.
    let mut fresh = build(THREE);
    fresh.guides[2].polygon = runner.scene.guides[2].polygon.clone();
    let scratch = lsyc::env::run(&mut fresh, 0, Default::default(), None).expect("runs");
    assert_eq!(strings(&moved), strings(&scratch));
    assert_ne!(strings(&moved), strings(&first), "c's trunk is shorter");

    // Move b's far edge: b runs again, a (upstream) does not.
    let work = runner.derivations.clone();
    runner.scene.guides[1].polygon[2].y = 14.0;
    runner.scene.guides[1].polygon[3].y = 14.0;
    runner.run().expect("runs");
    assert_eq!(runner.recomputed, vec![false, true, false]);
    assert_eq!(runner.derivations[0], work[0]);

    // Move a's linked edge down: a and b run again (b receives a message at
    // another step and place); c does not.
    let work = runner.derivations.clone();
    runner.scene.guides[0].polygon[2].y = 8.0;
    runner.scene.guides[0].polygon[3].y = 8.0;
    runner.scene.guides[1].polygon[0].y = 8.0;
    runner.scene.guides[1].polygon[1].y = 8.0;
    let out = runner.run().expect("runs");
    assert_eq!(runner.recomputed, vec![true, true, false]);
    assert_eq!(runner.derivations[2], work[2]);
    assert_eq!(out.guides[0].sent[0].at, DVec2::new(5.0, 8.0));

    // Change a without changing what it sends (a side edge moves a little):
    // a runs again, b receives the same message and is reused.
    runner.scene.guides[0].polygon[1].x = 11.0;
    runner.run().expect("runs");
    assert_eq!(runner.recomputed, vec![true, false, false]);
}

/// The urban layout (Fig. 7): streets leave the middle district through all
/// four linked edges and grow in every district; in the SVG, every drawn
/// segment has its middle inside the guide whose layer holds it.
#[test]
fn the_urban_layout_fills_every_district_and_keeps_the_centre_rule() {
    let text = crate::support::read_text(&crate::support::root().join("lang-examples/urban.lsy"));
    let fe = frontend::run(&text, Vec::new(), &[]);
    assert!(!fe.has_errors());
    let checked = fe.checked.as_ref().expect("checked");
    let opts = lsyc::run::Options::default();
    let r = lsyc::run::run_scene(&fe.file, checked, None, &opts).expect("runs");
    assert!(r.outcome.messages >= 12, "{} messages", r.outcome.messages);
    for (i, l) in r.scene.links.iter().enumerate() {
        assert!(l.used >= 2, "link {i} carried {} messages", l.used);
    }
    let mut svg = Vec::new();
    let stats = lsyc::run::write_scene(
        &r,
        Some(lsyc::run::Format::Svg),
        Default::default(),
        0,
        true,
        &mut svg,
    )
    .unwrap_or_else(|_| panic!("draws"));
    assert!(stats.segments > 4000, "{} segments", stats.segments);
    let svg = String::from_utf8(svg).expect("utf-8");
    // Read back each guide's layer: `<path d="M x y l dx dy …">`, y down.
    let attr = |line: &str, name: &str| -> Option<String> {
        let at = line.find(&format!(" {name}=\""))? + name.len() + 3;
        Some(line[at..].split('"').next()?.to_string())
    };
    let nums = |s: &str| -> Vec<DVec2> {
        let v: Vec<f64> = s
            .split(|c: char| c.is_whitespace() || c == ',')
            .filter(|t| !t.is_empty())
            .map(|t| t.parse().expect("a number"))
            .collect();
        v.chunks(2).map(|p| DVec2::new(p[0], -p[1])).collect()
    };
    let mut per_guide: std::collections::HashMap<String, usize> = Default::default();
    let mut guide: Option<usize> = None;
    for line in svg.lines() {
        if line.starts_with("<g class=\"guide-content\"") {
            let name = attr(line, "data-guide").expect("named");
            guide = r.scene.guides.iter().position(|g| g.name == name);
            continue;
        }
        if line == "</g>" {
            guide = None;
        }
        let (Some(g), true) = (guide, line.starts_with("<path")) else {
            continue;
        };
        let d = attr(line, "d").expect("path data");
        let (start, steps) = d[1..].split_once('l').expect("M … l …");
        let mut at = nums(start)[0];
        let poly = &r.scene.guides[g].polygon;
        for step in nums(steps) {
            let m = at + step * 0.5;
            let on_edge = (0..poly.len()).any(|i| {
                let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
                (lsyc::geometry::closest_on_segment(m, a, b) - m).length() < 0.02
            });
            assert!(
                lsyc::geometry::inside(m, poly) || on_edge,
                "a segment of `{}` ends at {} with its middle {m} outside",
                r.scene.guides[g].name,
                at + step
            );
            *per_guide.entry(r.scene.guides[g].name.clone()).or_default() += 1;
            at += step;
        }
    }
    for g in &r.scene.guides {
        assert!(
            per_guide.get(&g.name).copied().unwrap_or(0) > 100,
            "`{}` drew {:?} path steps",
            g.name,
            per_guide.get(&g.name)
        );
    }
}

/// `lsyc run SCENE -o out.obj / out.txt`: the palm as a mesh (clipped by the
/// centre rule like the pictures) and as text, one system per line after a
/// comment, each line an axiom again.
#[test]
fn scenes_write_obj_and_text() {
    let dir = tempfile::tempdir().expect("tempdir");
    let palm = crate::support::root().join("lang-examples/palm.lsy");
    let run = |ext: &str| -> String {
        let out = dir.path().join(format!("palm.{ext}"));
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_lsyc"))
            .args(["run", palm.to_str().expect("utf-8"), "-o"])
            .arg(&out)
            .output()
            .expect("runs");
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        std::fs::read_to_string(&out).expect("written")
    };
    let obj = run("obj");
    let vertices = obj.lines().filter(|l| l.starts_with("v ")).count();
    let faces: Vec<&str> = obj.lines().filter(|l| l.starts_with("f ")).collect();
    assert!(vertices > 100 && faces.len() > 100, "{vertices} vertices");
    for f in &faces {
        for idx in f.split_whitespace().skip(1) {
            let v: usize = idx
                .split('/')
                .next()
                .and_then(|x| x.parse().ok())
                .expect("index");
            assert!((1..=vertices).contains(&v), "{f}");
        }
    }
    let txt = run("txt");
    let lines: Vec<&str> = txt.lines().collect();
    assert_eq!(
        lines.len(),
        22,
        "eleven systems, each a comment and a string"
    );
    assert_eq!(
        lines[0],
        "// guide trunk1, lsystem Trunk, seeded at (0, 0) heading -18.4"
    );
    assert!(lines[2].starts_with("// guide trunk2, lsystem Trunk, seeded at ("));
    assert!(lines[6].starts_with("// guide frond1, lsystem Leaves, seeded at ("));
    for s in lines.iter().skip(1).step_by(2) {
        assert!(s.contains('F'), "{s}");
        let program =
            format!("element Blade {{ path \"M0 0 L1 1 Z\"; }}\nlsystem Again {{ axiom {s}; }}");
        let errs = crate::support::parse_errors(&program);
        assert!(errs.is_empty(), "{s}");
    }
}

/// ?D_A and ?N_A on hand-checked geometry: a turtle at (5, 7) in a 10 × 10
/// guide, above a drawn segment from (5, 2) to (5, 5) and a side one from
/// (7, 5) to (9, 5); ids of drawn segments follow the 4 guide edges.
#[test]
fn element_queries_answer_with_ids_after_the_guide_edges() {
    let text = "
lsystem Probe {
    derive 0;
    axiom F(3) [-(90) f(2) F(2)] f(2) ?D_A(1) -(90) f(2) -(90) ?N_A(1);
}
scene S {
    guide g { polygon (0, 0) (10, 0) (10, 10) (0, 10); system Probe; seed (5, 2) heading 0; }
}";
    let (scene, out) = run(text);
    let inst = &out.instances[0];
    let prog = &scene.programs[0];
    let params = |n: usize| -> Vec<f64> {
        let at: usize = inst.string.syms[..n]
            .iter()
            .map(|&s| prog.symbols.arity(s))
            .sum();
        inst.string.params[at..at + prog.symbols.arity(inst.string.syms[n])].to_vec()
    };
    // The trunk is 2 below, straight behind; it is drawn segment 0: id 4.
    let d = params(7);
    assert_eq!(
        (d[0], d[1], d[2].abs(), d[3]),
        (1.0, 2.0, 180.0, 4.0),
        "?D_A {d:?}"
    );
    // From (7, 7) looking down, the side segment (drawn segment 1) is 2 ahead.
    let n = params(11);
    assert_eq!(n[..3], [1.0, 2.0, 5.0], "?N_A {n:?}");
}

/// Units, systems and queries run in parallel; the drawing does not depend on
/// the number of threads.
#[test]
fn the_urban_layout_is_the_same_on_one_or_two_threads() {
    let dir = tempfile::tempdir().expect("tempdir");
    let urban = crate::support::root().join("lang-examples/urban.lsy");
    let draw = |threads: &str| -> Vec<u8> {
        let out = dir.path().join(format!("urban-{threads}.svg"));
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_lsyc"))
            .args(["run", urban.to_str().expect("utf-8"), "--threads", threads])
            .args(["--guides", "-o"])
            .arg(&out)
            .output()
            .expect("runs");
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        std::fs::read(&out).expect("written")
    };
    let one = draw("1");
    assert!(one.len() > 10_000);
    assert!(one == draw("2"), "the SVGs differ");
}

/// `--stats` of a scene counts what the centre rule keeps: segments and
/// elements apart, and the box of the kept geometry only.
#[test]
fn scene_stats_count_what_the_centre_rule_keeps() {
    let text = "
element Dot { path \"M-1 0 L1 0 L0 2 Z\"; }
lsystem Grow { derive 0; axiom F(4) [+(90) f(20) Dot] [-(90) F(30)] Dot; }
scene S {
    guide g { polygon (0, 0) (10, 0) (10, 10) (0, 10); system Grow; seed (5, 2) heading 0; }
}";
    let fe = frontend::run(text, Vec::new(), &[]);
    assert!(!fe.has_errors());
    let checked = fe.checked.as_ref().expect("checked");
    let r = lsyc::run::run_scene(&fe.file, checked, None, &Default::default()).expect("runs");
    let stats =
        lsyc::run::write_scene(&r, None, Default::default(), 0, false, &mut std::io::sink())
            .unwrap_or_else(|_| panic!("draws"));
    // Kept: F(4) from (5, 2) to (5, 6) and the Dot at (5, 6). Removed: the Dot
    // at (-15, 6) and the F(30) whose middle is at (20, 6).
    assert_eq!((stats.segments, stats.elements), (1, 1));
    assert_eq!(stats.bbox, Some([5.0, 2.0, 5.0, 6.0]));
}

/// The outputs of module `n` of system `k`, after the run.
fn outputs(scene: &Scene, out: &Outcome, k: usize, n: usize) -> Vec<f64> {
    let inst = &out.instances[k];
    let prog = &scene.programs[scene.guides[inst.guide].program];
    let at: usize = inst.string.syms[..n]
        .iter()
        .map(|&s| prog.symbols.arity(s))
        .sum();
    inst.string.params[at..at + prog.symbols.arity(inst.string.syms[n])].to_vec()
}

/// A stem growing straight up through the apex (5, 10) of a roof-shaped guide:
/// its last segment meets both roof edges at the apex. The crossing is credited
/// to the edge that starts a link (edge 3, not the lower-numbered edge 2), the
/// token is used, and nothing is drawn beyond the apex (no stem leaving and
/// coming back, no fork).
#[test]
fn a_stem_through_a_vertex_crosses_the_linked_edge() {
    let text = "
lsystem Up {
    derive 20;
    axiom ?X(3);
    ?X(found, _, d) : found -> F(d) cut;
    ?X(_, _, d) -> F(d) ?X(d);
}
lsystem Side(d) { derive 0; axiom F(d); }
scene S {
    guide a { polygon (0, 0) (10, 0) (10, 8) (5, 10) (0, 8); system Up; seed (5, 0) heading 0; }
    guide b { polygon (0, 8) (5, 10) (5, 20) (0, 20); system Side; }
    link a.edge(3) -> b.edge(0) { tokens 1; heading 0; }
}";
    let (scene, out) = run(text);
    assert_eq!(out.messages, 1);
    assert_eq!(scene.links[0].used, 1);
    assert_eq!(out.guides[0].sent[0].at, DVec2::new(5.0, 10.0));
    // Four segments up to y = 12 and nothing after them (the cut removed the
    // rest): one F per ?X, no fork.
    let inst = &out.instances[0];
    assert_eq!(inst.string.params, vec![3.0; 4]);
}

/// A segment drawn on the very line of a later ?X is seen: the ?X answers it
/// (id 4, the first drawn segment after the 4 guide edges) and not the guide's
/// top edge beyond it.
#[test]
fn x_sees_a_collinear_segment() {
    let text = "
lsystem Probe { derive 0; axiom [f(6) F(2)] ?X(10); }
scene S {
    guide g { polygon (0, 0) (10, 0) (10, 10) (0, 10); system Probe; seed (5, 1) heading 0; }
}";
    let (scene, out) = run(text);
    assert_eq!(outputs(&scene, &out, 0, 4), vec![1.0, 4.0, 10.0]);
}

/// A drawn segment nearer along the way than the guide's edge is what ?X
/// reports, and the linked edge behind it reserves no token.
#[test]
fn x_reports_the_nearest_hit_whether_edge_or_drawn_segment() {
    let text = "
lsystem Probe { derive 1; axiom [f(7) +(90) f(1) +(180) F(2)] ?X(12); }
lsystem Side { derive 0; axiom F; }
scene S {
    guide g { polygon (0, 0) (10, 0) (10, 10) (0, 10); system Probe; seed (5, 1) heading 0; }
    guide h { polygon (0, 10) (10, 10) (10, 20) (0, 20); system Side; }
    link g.edge(2) -> h.edge(0) { tokens 1; }
}";
    let (scene, out) = run(text);
    // The cross bar at y = 8 is nearer than the top edge at y = 10.
    assert_eq!(outputs(&scene, &out, 0, 7), vec![1.0, 4.0, 12.0]);
    assert_eq!(events(&out, 0), vec![]);
    // Without the bar, the top edge is hit and its token reserved.
    let (scene, out) = run(&text.replace("F(2)]", "f(2)]"));
    assert_eq!(outputs(&scene, &out, 0, 7), vec![1.0, 2.0, 12.0]);
    assert_eq!(events(&out, 0)[0].2, Token::Reserved);
}

/// The warnings of a scene run, rendered as `lsyc run` prints them, and the
/// per-guide explanation.
fn warnings_of(text: &str) -> (String, String) {
    let mut scene = build(text);
    let out = lsyc::env::run(&mut scene, 0, Default::default(), None).expect("runs");
    let cfg = Config::new(0, Default::default(), None);
    let diags = lsyc::env::explain::warnings(&scene, &out, cfg);
    let reports = lsyc::env::explain::explain(&scene, &out, cfg).expect("explains");
    (
        crate::support::render_plain(&diags, "scene.lsy", text),
        lsyc::env::explain::render(&scene, &reports),
    )
}

/// A stem that needs 21 steps (a query, then a segment, ten times, and the
/// last query) under `derive 10`: it stops half-way, the crown is never seeded,
/// and the run says both, with the steps it would need.
const SHORT: &str = "lsystem Stem {
    derive 10;
    axiom ?D_L(10);
    ?D_L(found, _, beta, _, D) : found -> +(beta * 0.5) ?X(D);
    ?D_L(_, _, _, _, _) -> ;
    ?X(found, _, D) : found -> F(D) cut;
    ?X(_, _, D) -> F(D) ?D_L(D);
}
lsystem Crown(D) { derive 1; axiom F(D); }
scene S {
    guide stem { polygon (-10, 0) (10, 0) (10, 100) (-10, 100); system Stem; seed (0, 0) heading 0; }
    guide crown { polygon (-10, 100) (10, 100) (30, 150) (-30, 150); system Crown; }
    link stem.edge(2) -> crown.edge(0) { tokens 1; heading 0; }
}
";

#[test]
fn a_run_cut_short_says_why_the_far_guide_stayed_empty() {
    let (warnings, explained) = warnings_of(SHORT);
    insta::assert_snapshot!("warnings_cut_short", warnings);
    insta::assert_snapshot!("explain_cut_short", explained);
    // With the steps the warning names, the crown grows and nothing warns.
    let need = warnings
        .split("write `derive ")
        .nth(1)
        .and_then(|s| s.split(';').next())
        .expect("a step count");
    let fixed = SHORT.replace("derive 10;", &format!("derive {need};"));
    let (warnings, explained) = warnings_of(&fixed);
    assert_eq!(warnings, "", "{warnings}");
    assert!(
        explained.contains("guide crown (lsystem Crown):\n  seeded at step"),
        "{explained}"
    );
}

#[test]
fn growth_that_leaves_its_guide_and_comes_back_is_reported() {
    let text = "lsystem Out { derive 0; axiom F(5) -(90) F(20) +(180) F(20) F(2); }
scene S {
    guide g { polygon (0, 0) (10, 0) (10, 10) (0, 10); system Out; seed (5, 1) heading 0; }
}
";
    let (warnings, _) = warnings_of(text);
    insta::assert_snapshot!("warnings_comes_back", warnings);
}

/// A stem whose every segment also starts a stray shoot at 60°: the link's
/// `take 1` lets only the stem's `?X(D, 1)` use the token (the shoots pass 0),
/// `aim middle` steers the stem to the middle of the top edge, and `heading
/// continue` seeds the crown with the heading of the segment that crossed.
const AIMED: &str = "lsystem Stem {
    derive 60;
    axiom ?D_L(10, 1);
    ?D_L(found, _, beta, _, D, k) : found -> +(beta * 0.5) ?X(D, k);
    ?D_L(_, _, _, _, _, _) -> ;
    ?X(found, _, D, _) : found -> F(D) cut;
    ?X(_, _, D, k) -> F(D) [+(60) ?X(D, 0)] ?D_L(D, k);
}
lsystem Crown(D, _) { derive 0; axiom F(D); }
scene S {
    guide stem { polygon (-10, 0) (10, 0) (10, 100) (-10, 100); system Stem; seed (-5, 0) heading 0; }
    guide crown { polygon (-10, 100) (10, 100) (30, 150) (-30, 150); system Crown; }
    link stem.edge(2) -> crown.edge(0) { tokens 1; heading continue; aim middle; take 1; }
}
";

#[test]
fn links_aim_take_and_continue() {
    let (scene, out) = run(AIMED);
    assert_eq!(out.messages, 1);
    // The stem (k = 1) took the token: the message carries (D, 1).
    let m = &out.guides[0].sent[0];
    assert_eq!(m.pass, vec![10.0, 1.0]);
    // Aiming at the middle (0, 100), it crossed near it.
    assert!(m.at.x.abs() < 2.0, "{}", m.at);
    // The crown starts with the crossing segment's heading.
    let crown = out.instances.iter().find(|i| i.guide == 1).expect("seeded");
    let h = crown.start.h.truncate();
    assert!((h - m.dir.normalize()).length() < 1e-9, "{h} {}", m.dir);
    assert!(scene.links[0].continues && scene.links[0].aim_middle);
    // Without `take 1`, a stray shoot (k = 0) reaches the edge first and
    // takes the token; without `aim middle`, the stem goes for the closest
    // point of the edge (straight up from where it stands, x = -5).
    let (_, out) = run(&AIMED.replace(" take 1;", ""));
    assert_eq!(out.guides[0].sent[0].pass, vec![10.0, 0.0]);
    let (_, out) = run(&AIMED.replace(" aim middle;", ""));
    assert!(
        out.guides[0].sent[0].at.x < -3.0,
        "{}",
        out.guides[0].sent[0].at
    );
}

/// The newcomer's scene: the stem-and-crown program of the reference's
/// "Scenes, guides and links", run as printed. The stem reaches the link at
/// the top of its guide, its crossing seeds the crown (which receives the
/// stem's Δ), the crown grows, and the run has nothing to warn about.
#[test]
fn the_references_stem_and_crown_work_as_printed() {
    let md = crate::support::read_text(&crate::support::root().join("docs/language.md"));
    let start = md
        .find("scene StemAndCrown")
        .expect("the scene is in the reference");
    let open = md[..start].rfind("```lsy\n").expect("its block") + "```lsy\n".len();
    let close = start + md[start..].find("```").expect("closed");
    let text = &md[open..close];
    let (scene, out) = run(text);
    assert_eq!(out.messages, 1);
    assert_eq!(scene.links[0].used, 1);
    let crown = out
        .instances
        .iter()
        .find(|i| i.guide == 1)
        .expect("crown seeded");
    assert_eq!(crown.via, Some(0));
    // The message crossed near the middle of the top edge, and the crown grew.
    assert!(
        out.guides[0].sent[0].at.x.abs() < 3.0,
        "{}",
        out.guides[0].sent[0].at
    );
    assert_eq!(out.guides[0].sent[0].pass, vec![10.0]);
    assert!(crown.string.len() > 100, "{}", crown.string.len());
    let (warnings, _) = warnings_of(text);
    assert_eq!(warnings, "");
}

/// `lsyc run --explain` prints the explanation after the run's warnings, on
/// stderr, and the run still succeeds.
#[test]
fn run_explain_on_the_command_line() {
    let dir = tempfile::tempdir().expect("tempdir");
    let file = dir.path().join("short.lsy");
    std::fs::write(&file, SHORT).expect("written");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_lsyc"))
        .arg("run")
        .arg(&file)
        .arg("--explain")
        .output()
        .expect("runs");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    let (w, x) = (
        err.find("warning[W0801]").expect("the warning"),
        err.find("guide crown (lsystem Crown):\n  never seeded")
            .expect("the explanation"),
    );
    assert!(w < x, "{err}");
    assert!(err.contains("write `derive 20;`"), "{err}");
}
