//! Scenes: query answers on hand-checked geometry, the centre rule, messages
//! over links, termination, and the SVG layers.

use crate::support::root;
use lsyc::env::scene::Instance;
use lsyc::frontend;
use lsyc::run::{self, Options, SceneRun};

fn run_scene(text: &str) -> SceneRun {
    let fe = frontend::run(text, Vec::new(), &[]);
    assert!(
        !fe.has_errors(),
        "{}",
        crate::support::render_plain(&fe.diagnostics, "scene.lsy", text)
    );
    let checked = fe.checked.as_ref().expect("checked");
    run::run_scene(&fe.file, checked, None, &Options::default()).expect("runs")
}

/// The parameters of the `n`-th module of an instance.
fn params_of(r: &SceneRun, inst: &Instance, n: usize) -> Vec<f64> {
    let prog = &r.scene.programs[r.scene.guides[inst.guide].program];
    let mut p = 0;
    for (k, &s) in inst.string.syms.iter().enumerate() {
        let a = prog.symbols.arity(s);
        if k == n {
            return inst.string.params[p..p + a].to_vec();
        }
        p += a;
    }
    Vec::new()
}

const BOX: &str = "
lsystem Probe {
    derive 0;
    axiom ?P ?H ?D_G(1) ?N_G(1) ?X(10) ?X(3);
}
scene S {
    guide g {
        polygon (0, 0) (10, 0) (10, 10) (0, 10);
        system Probe;
        seed (5, 2) heading 0;
    }
}
";

#[test]
fn queries_answer_from_the_guide_geometry() {
    let r = run_scene(BOX);
    let inst = &r.outcome.instances[0];
    assert_eq!(params_of(&r, inst, 0), vec![5.0, 2.0, 0.0], "?P");
    let h = params_of(&r, inst, 1);
    assert!(
        (h[0]).abs() < 1e-12 && (h[1] - 1.0).abs() < 1e-12,
        "?H {h:?}"
    );
    // The closest guide edge is the bottom one (edge 0), 2 below, straight behind.
    let d = params_of(&r, inst, 2);
    assert_eq!(d[0], 1.0);
    assert!(
        (d[1] - 2.0).abs() < 1e-12 && (d[2].abs() - 180.0).abs() < 1e-9 && d[3] == 0.0,
        "?D_G {d:?}"
    );
    assert_eq!(d[4], 1.0, "pass-through kept");
    // Straight ahead the top edge (edge 2) is 8 away.
    let n = params_of(&r, inst, 3);
    assert_eq!(n[..3], [1.0, 8.0, 2.0], "?N_G {n:?}");
    // A step of 10 leaves the guide through edge 2; a step of 3 does not.
    assert_eq!(params_of(&r, inst, 4)[..2], [1.0, 2.0], "?X(10)");
    assert_eq!(params_of(&r, inst, 5)[..2], [0.0, 0.0], "?X(3)");
    assert_eq!(r.outcome.queries, 6);
}

#[test]
fn the_centre_rule_clips_what_leaves_the_guide() {
    let text = "
lsystem Grow { derive 0; axiom F(4) [+(90) F(20)] F(20); }
scene S {
    guide g { polygon (0, 0) (10, 0) (10, 10) (0, 10); system Grow; seed (5, 2) heading 0; }
}";
    let r = run_scene(text);
    let stats = run::write_scene(&r, None, Default::default(), 0, false, &mut std::io::sink())
        .unwrap_or_else(|_| panic!("draws"));
    // F(4) is inside; the branch F(20) to the left has its centre at x = -5 (out);
    // the last F(20) from y = 6 to 26 has its centre at y = 16 (out).
    assert_eq!(stats.segments, 1);
}

const LINKED: &str = "
lsystem Up {
    derive 20;
    axiom ?X(2, 7);
    ?X(found, _, d, v) : found -> F(d) cut;
    ?X(_, _, d, v) -> F(d) ?X(d, v);
}
lsystem Side(d, v) {
    derive 0;
    axiom F(v);
}
scene S {
    guide a { polygon (0, 0) (10, 0) (10, 10) (0, 10); system Up; seed (5, 0) heading 0; }
    guide b { polygon (0, 10) (10, 10) (10, 20) (0, 20); system Side; }
    link a.edge(2) -> b.edge(0) { tokens TOKENS; heading 90; }
}
";

#[test]
fn a_crossing_sends_a_message_that_seeds_the_end_guide() {
    let r = run_scene(&LINKED.replace("TOKENS", "1"));
    assert_eq!(r.outcome.messages, 1);
    assert_eq!(r.outcome.instances.len(), 2);
    let seeded = &r.outcome.instances[1];
    assert_eq!(seeded.guide, 1);
    // Seeded where the trunk crossed the shared edge, heading 90° (to the left).
    assert!(
        (seeded.start.pos - glam::DVec3::new(5.0, 10.0, 0.0)).length() < 1e-9,
        "{:?}",
        seeded.start.pos
    );
    assert!((seeded.start.h - glam::DVec3::new(-1.0, 0.0, 0.0)).length() < 1e-12);
    // ?X's pass-through parameters (d, v) = (2, 7) became the system's parameters.
    assert_eq!(params_of(&r, seeded, 0), vec![7.0]);
    assert_eq!(r.scene.links[0].used, 1, "the token is used");
    // Without a token, no message.
    let r = run_scene(&LINKED.replace("TOKENS", "0"));
    assert_eq!(r.outcome.messages, 0);
    assert_eq!(r.outcome.instances.len(), 1);
}

#[test]
fn scenes_end_and_repeat() {
    let text = std::fs::read_to_string(root().join("lang-examples/palm.lsy")).expect("palm");
    let a = run_scene(&text);
    let b = run_scene(&text);
    assert!(
        a.outcome.steps < 200,
        "the palm ends: {} steps",
        a.outcome.steps
    );
    assert_eq!(a.outcome.messages, 1);
    let strings = |r: &SceneRun| {
        r.outcome
            .instances
            .iter()
            .map(|i| i.string.clone())
            .collect::<Vec<_>>()
    };
    assert_eq!(strings(&a), strings(&b));
}

#[test]
fn svg_layers_per_guide() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("palm.svg");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_lsyc"))
        .args([
            "run",
            root()
                .join("lang-examples/palm.lsy")
                .to_str()
                .expect("utf-8"),
            "-o",
            out.to_str().expect("utf-8"),
            "--guides",
            "--stats",
        ])
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let svg = std::fs::read_to_string(&out).expect("svg");
    for guide in ["trunk", "crown"] {
        assert!(
            svg.contains(&format!(
                "<g class=\"guide-content\" data-guide=\"{guide}\">"
            )),
            "{guide}"
        );
        assert!(
            svg.contains(&format!("<polygon class=\"guide\" data-guide=\"{guide}\"")),
            "{guide}"
        );
    }
    assert!(svg.contains("<line class=\"link\""));
    let stats: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json");
    assert_eq!(stats["messages"], 1);
    assert!(stats["queries"].as_u64().unwrap_or(0) > 10);
    usvg::Tree::from_str(&svg, &usvg::Options::default()).expect("usvg reads it");
}

#[test]
fn the_spiral_turns_away_from_walls_and_stays_inside() {
    let text = std::fs::read_to_string(root().join("lang-examples/spiral.lsy")).expect("spiral");
    let r = run_scene(&text);
    let stats = run::write_scene(&r, None, Default::default(), 0, false, &mut std::io::sink())
        .unwrap_or_else(|_| panic!("draws"));
    assert!(stats.segments > 500, "{} segments", stats.segments);
    let b = stats.bbox.expect("drawn");
    // Every segment stays well inside the 400 × 300 guide: it turned before each wall.
    assert!(
        b[0] > 0.0 && b[1] >= 0.0 && b[2] < 400.0 && b[3] < 300.0,
        "{b:?}"
    );
    assert!(
        b[2] - b[0] > 300.0 && b[3] - b[1] > 200.0,
        "it goes round the guide: {b:?}"
    );
}
