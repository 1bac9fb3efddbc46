//! Scenes: query answers on hand-checked geometry, the centre rule, messages
//! over links, termination, and the SVG layers.

use crate::support::root;
use glam::DVec2;
use lsyc::env::engine::Instance;
use lsyc::frontend;
use lsyc::geometry::{closest_on_segment, inside};
use lsyc::run::{self, Options, SceneRun};
use std::collections::HashMap;

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
    // An element is kept by the centre of its outline, placed and scaled as drawn:
    // a leaf 10 long whose centre is 5 up its axis and 2 to its right.
    let text = "
element Leaf { path \"M0 0 L4 5 L0 10 Z\"; }
lsystem Grow { derive 0; axiom LEAF; }
scene S {
    guide g { polygon (0, 0) (10, 0) (10, 10) (0, 10); system Grow; seed AT heading HEADING; }
}";
    let kept = |leaf: &str, at: &str, heading: &str| {
        let program = text
            .replace("LEAF", leaf)
            .replace("AT", at)
            .replace("HEADING", heading);
        let r = run_scene(&program);
        run::write_scene(&r, None, Default::default(), 0, false, &mut std::io::sink())
            .unwrap_or_else(|_| panic!("draws"))
            .elements
    };
    // Up from (5, 2): the centre (7, 7) is inside; scaled by 2, (9, 12) is not.
    assert_eq!(kept("Leaf", "(5, 2)", "0"), 1);
    assert_eq!(kept("*(2) Leaf", "(5, 2)", "0"), 0);
    // Its right side counts: up from (9, 2) the centre is (11, 7), out; from
    // (1, 2) it is (3, 7), in.
    assert_eq!(kept("Leaf", "(9, 2)", "0"), 0);
    assert_eq!(kept("Leaf", "(1, 2)", "0"), 1);
    // Turned left (the axis along -x, its right side up): from (8, 9) the centre
    // is (3, 11), out; from (8, 1) it is (3, 3), in.
    assert_eq!(kept("Leaf", "(8, 9)", "90"), 0);
    assert_eq!(kept("Leaf", "(8, 1)", "90"), 1);
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

/// A scene's SVG writes every system in the pass that finds the picture's
/// bounds, with the decimals the guides' outlines ask for. A kept segment
/// that reaches far beyond its small guide changes them: what was written is
/// written again with the right ones.
#[test]
fn a_scene_svg_reaching_far_beyond_its_guides_has_the_right_numbers() {
    let second = 0.2;
    for reach in [0.4, 500.0] {
        // The first F reaches `reach` both sides of the guide's middle (its
        // centre is inside: kept); the second is within the guide.
        let text = format!(
            "lsystem Far {{ derive 0; axiom +(90) f({reach}) -(180) F({}) -(180) f({reach}) -(90) F({second}); }}
scene S {{
    guide a {{ polygon (0, 0) (1, 0) (1, 1) (0, 1); system Far; seed (0.5, 0.5) heading 0; }}
    guide b {{ polygon (2, 0) (3, 0) (3, 1) (2, 1); system Far; seed (2.5, 0.25) heading 0; }}
}}",
            2.0 * reach
        );
        let r = run_scene(&text);
        let mut svg = Vec::new();
        run::write_scene(
            &r,
            Some(lsyc::run::Format::Svg),
            Default::default(),
            0,
            false,
            &mut svg,
        )
        .unwrap_or_else(|_| panic!("writes"));
        let layers = read_layers(&String::from_utf8(svg).expect("utf-8"));
        for (guide, at) in [("a", DVec2::new(0.5, 0.5)), ("b", DVec2::new(2.5, 0.25))] {
            let mut ends: Vec<[f64; 2]> = layers
                .segments(guide)
                .iter()
                .flat_map(|&(p, q)| [p - at, q - at])
                .map(|d| [d.x, d.y])
                .collect();
            ends.sort_by(|x, y| x.partial_cmp(y).expect("numbers"));
            ends.dedup();
            // From (-reach, 0) to (reach, 0), then up from the middle.
            let want = [[-reach, 0.0], [0.0, 0.0], [0.0, second], [reach, 0.0]];
            assert_eq!(ends.len(), want.len(), "{guide} at {reach}: {ends:?}");
            for (e, w) in ends.iter().zip(want) {
                let tol = 1e-3 * (1.0 + reach);
                assert!(
                    (e[0] - w[0]).abs() < tol && (e[1] - w[1]).abs() < tol,
                    "{guide} at {reach}: {e:?}, not {w:?}"
                );
            }
        }
    }
}

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

/// An edge that starts several links fans out: one crossing uses a free token of
/// each and seeds every end guide, each at the crossing point projected onto its
/// own end edge, with its own link's heading; a link without a free token sends
/// nothing.
#[test]
fn a_crossing_of_an_edge_with_several_links_seeds_each_end_guide() {
    let text = LINKED.replace("TOKENS", "1");
    let text = text.replace(
        "    link a.edge(2)",
        "    guide c { polygon (0, 10) (10, 10) (4, 30) (0, 30); system Side; }
    guide e { polygon (0, 10) (10, 10) (10, 30); system Side; }
    link a.edge(2) -> c.edge(0) { tokens 1; heading -45; }
    link a.edge(2) -> e.edge(0) { tokens 0; }
    link a.edge(2)",
    );
    let r = run_scene(&text);
    assert_eq!(r.outcome.messages, 2);
    let mut seeded: Vec<&Instance> = r.outcome.instances.iter().skip(1).collect();
    seeded.sort_by_key(|i| i.guide);
    // Guides b and c, not e (its link has no token).
    let guides: Vec<usize> = seeded.iter().map(|i| i.guide).collect();
    assert_eq!(guides, vec![1, 2]);
    for inst in &seeded {
        assert!(
            (inst.start.pos - glam::DVec3::new(5.0, 10.0, 0.0)).length() < 1e-9,
            "{:?}",
            inst.start.pos
        );
        assert_eq!(params_of(&r, inst, 0), vec![7.0]);
    }
    let h = std::f64::consts::FRAC_1_SQRT_2;
    assert!((seeded[0].start.h - glam::DVec3::new(-1.0, 0.0, 0.0)).length() < 1e-12);
    assert!((seeded[1].start.h - glam::DVec3::new(h, h, 0.0)).length() < 1e-12);
    let used: Vec<u32> = r.scene.links.iter().map(|l| l.used).collect();
    assert_eq!(used, vec![1, 0, 1]);
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
    // Two messages up the trunk, then one to each of the eight leaves.
    assert_eq!(a.outcome.messages, 10);
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
    for guide in ["trunk1", "trunk2", "trunk3", "frond1", "frond8"] {
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
    assert_eq!(stats["messages"], 10);
    assert_eq!(stats["systems"], 11);
    assert!(stats["queries"].as_u64().unwrap_or(0) > 10);
    usvg::Tree::from_str(&svg, &usvg::Options::default()).expect("usvg reads it");
}

/// What the SVG of a scene drew, read back from its layers: per guide, the
/// segments of its paths, the centres of its elements and of its polygons, and
/// its outline (all in the scene's coordinates, +y up).
#[derive(Default)]
pub(crate) struct Layers {
    pub(crate) outlines: HashMap<String, Vec<DVec2>>,
    pub(crate) segments: HashMap<String, Vec<(DVec2, DVec2)>>,
    pub(crate) centres: HashMap<String, Vec<DVec2>>,
    /// Per guide, the axis (base to tip, unit) of each element it printed.
    pub(crate) axes: HashMap<String, Vec<DVec2>>,
}

impl Layers {
    pub(crate) fn segments(&self, guide: &str) -> &[(DVec2, DVec2)] {
        self.segments.get(guide).map_or(&[], Vec::as_slice)
    }
}

fn attr<'a>(line: &'a str, name: &str) -> Option<&'a str> {
    let key = format!(" {name}=\"");
    let at = line.find(&key)? + key.len();
    line[at..].split('"').next()
}

fn numbers(s: &str) -> Vec<f64> {
    s.split(|c: char| c.is_whitespace() || c == ',')
        .filter(|t| !t.is_empty())
        .map(|t| t.parse::<f64>().unwrap_or_else(|_| panic!("a number: {t}")))
        .collect()
}

/// SVG points (y down) back to the scene's coordinates.
fn points(s: &str) -> Vec<DVec2> {
    numbers(s)
        .chunks(2)
        .map(|p| DVec2::new(p[0], -p[1]))
        .collect()
}

fn read_layers(svg: &str) -> Layers {
    let mut layers = Layers::default();
    let mut guide: Option<String> = None;
    // The local centre of every element defined, by its id.
    let mut local: HashMap<String, DVec2> = HashMap::new();
    for line in svg.lines() {
        if line.starts_with("<path id=") {
            let id = attr(line, "id").expect("id").to_string();
            let d = attr(line, "d").expect("path data");
            local.insert(id, lsyc::env::clip::outline_centre(d));
            continue;
        }
        if line.starts_with("<g class=\"guide-content\"") {
            guide = attr(line, "data-guide").map(str::to_string);
            continue;
        }
        if line.starts_with("<polygon class=\"guide\"") {
            let name = attr(line, "data-guide").expect("named").to_string();
            layers
                .outlines
                .insert(name, points(attr(line, "points").expect("points")));
            continue;
        }
        let Some(g) = guide.clone() else {
            continue;
        };
        if line == "</g>" {
            guide = None;
        } else if line.starts_with("<path") {
            // M x y l dx dy dx dy …: one absolute start, then relative steps.
            let d = attr(line, "d").expect("path data");
            let (start, steps) = d[1..].split_once('l').expect("M … l …");
            let mut at = points(start)[0];
            let segs = layers.segments.entry(g).or_default();
            for step in points(steps) {
                segs.push((at, at + step));
                at += step;
            }
        } else if line.starts_with("<use") {
            // matrix(a b c d e f): the base at (e, f), the element's axis (c, d);
            // its centre is where the matrix puts the outline's local centre.
            let t = attr(line, "transform").expect("transform");
            let m = numbers(&t["matrix(".len()..t.len() - 1]);
            let id = attr(line, "href").expect("href").trim_start_matches('#');
            let c = local[id];
            let centre = DVec2::new(
                m[0] * c.x + m[2] * c.y + m[4],
                -(m[1] * c.x + m[3] * c.y + m[5]),
            );
            layers.centres.entry(g.clone()).or_default().push(centre);
            let axis = DVec2::new(m[2], -m[3]).normalize_or_zero();
            layers.axes.entry(g).or_default().push(axis);
        } else if line.starts_with("<polygon") {
            let pts = points(attr(line, "points").expect("points"));
            let c = pts.iter().fold(DVec2::ZERO, |s, &p| s + p) / pts.len() as f64;
            layers.centres.entry(g).or_default().push(c);
        }
    }
    layers
}

/// Runs `lsyc run FILE --scene NAME -o OUT.svg --guides --stats` (FILE relative
/// to the repository, or absolute).
pub(crate) fn draw(file: &str, scene: Option<&str>) -> (Layers, serde_json::Value) {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("scene.svg");
    let mut args = vec![
        "run".to_string(),
        root().join(file).to_str().expect("utf-8").to_string(),
        "-o".to_string(),
        out.to_str().expect("utf-8").to_string(),
        "--guides".to_string(),
        "--stats".to_string(),
    ];
    if let Some(s) = scene {
        args.extend(["--scene".to_string(), s.to_string()]);
    }
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_lsyc"))
        .args(&args)
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let svg = std::fs::read_to_string(&out).expect("svg");
    let stats = serde_json::from_slice(&o.stdout).expect("json");
    (read_layers(&svg), stats)
}

/// Inside the polygon, or within the rounding of the SVG's numbers of it.
fn inside_or_on(p: DVec2, poly: &[DVec2]) -> bool {
    let n = poly.len();
    inside(p, poly)
        || (0..n).any(|i| (closest_on_segment(p, poly[i], poly[(i + 1) % n]) - p).length() < 0.02)
}

/// The scenes of a program, by name, in the order written.
fn scene_names(text: &str) -> Vec<String> {
    text.lines()
        .filter_map(|l| l.strip_prefix("scene "))
        .filter_map(|l| l.split_whitespace().next())
        .map(str::to_string)
        .collect()
}

/// Each drawn segment has its middle, and each element and polygon its centre,
/// inside the guide that drew it.
pub(crate) fn assert_centre_rule(layers: &Layers, what: &str) {
    for (guide, segs) in &layers.segments {
        let poly = &layers.outlines[guide];
        for (a, b) in segs {
            let m = (*a + *b) * 0.5;
            assert!(
                inside_or_on(m, poly),
                "{what}: the segment {a} – {b} of `{guide}` has its middle outside"
            );
        }
    }
    for (guide, centres) in &layers.centres {
        let poly = &layers.outlines[guide];
        for c in centres {
            assert!(
                inside_or_on(*c, poly),
                "{what}: an element of `{guide}` has its centre {c} outside"
            );
        }
    }
}

/// Every scene of every gallery file keeps the centre rule.
#[test]
fn the_centre_rule_holds_in_every_gallery_scene() {
    let mut scenes = 0;
    for path in crate::support::lsy_files(&["lang-examples"]) {
        let text = crate::support::read_text(&path);
        let file = crate::support::rel(&path);
        for name in scene_names(&text) {
            scenes += 1;
            let (layers, stats) = draw(&file, Some(&name));
            let drawn: usize = layers.segments.values().map(Vec::len).sum();
            assert!(drawn > 0, "{file} {name}: nothing drawn");
            assert!(stats["segments"].as_u64().unwrap_or(0) > 0, "{file} {name}");
            assert_centre_rule(&layers, &format!("{file} {name}"));
        }
    }
    assert!(scenes >= 2, "{scenes} scenes");
}

/// The guides of each scene of a program that hold an explicit seed.
fn seeded_guides(text: &str) -> HashMap<String, Vec<String>> {
    let mut out: HashMap<String, Vec<String>> = HashMap::new();
    let (mut scene, mut guide) = (String::new(), String::new());
    for line in text.lines().map(str::trim) {
        if let Some(rest) = line.strip_prefix("scene ") {
            scene = rest.split_whitespace().next().unwrap_or("").to_string();
            out.entry(scene.clone()).or_default();
        } else if let Some(rest) = line.strip_prefix("guide ") {
            guide = rest.split_whitespace().next().unwrap_or("").to_string();
        } else if line.starts_with("seed ") {
            out.entry(scene.clone()).or_default().push(guide.clone());
        }
    }
    out
}

/// `lsyc edit` works on every gallery scene: dragging a vertex of one guide (the
/// first by name that holds no seed), with the seeded guides pinned as the roots
/// of the model, gives a program that checks, runs, still grows in every guide
/// that grew before, and keeps the centre rule.
#[test]
fn every_gallery_scene_can_be_edited() {
    let dir = tempfile::tempdir().expect("tempdir");
    for path in crate::support::lsy_files(&["lang-examples"]) {
        let text = crate::support::read_text(&path);
        let file = crate::support::rel(&path);
        let seeded = seeded_guides(&text);
        for name in scene_names(&text) {
            let (before, _) = draw(&file, Some(&name));
            let mut guides: Vec<&String> = before.outlines.keys().collect();
            guides.sort();
            let pinned = &seeded[&name];
            let moved = guides
                .iter()
                .find(|g| !pinned.contains(g))
                .unwrap_or(&guides[0]);
            let mut args = vec!["edit".to_string(), file.clone(), "--scene".to_string()];
            args.push(name.clone());
            args.extend(["--by".to_string(), format!("{moved}.v0=4,3")]);
            for g in pinned.iter().filter(|g| g != moved) {
                args.extend(["--pin".to_string(), g.clone()]);
            }
            let o = std::process::Command::new(env!("CARGO_BIN_EXE_lsyc"))
                .args(&args)
                .current_dir(root())
                .output()
                .expect("runs");
            let what = args[1..].join(" ");
            assert!(
                o.status.success(),
                "lsyc {what}: {}",
                String::from_utf8_lossy(&o.stderr)
            );
            let edited = dir.path().join(format!("{name}.lsy"));
            std::fs::write(&edited, &o.stdout).expect("write");
            let (after, _) = draw(edited.to_str().expect("utf-8"), Some(&name));
            assert_ne!(
                before.outlines[*moved], after.outlines[*moved],
                "lsyc {what}: `{moved}` did not change"
            );
            for (g, segs) in &before.segments {
                assert!(
                    segs.is_empty() || !after.segments(g).is_empty(),
                    "lsyc {what}: nothing grows in `{g}` any more"
                );
            }
            assert_centre_rule(&after, &format!("lsyc {what}"));
        }
    }
}

#[test]
fn the_spiral_sends_branches_that_grow_lateral_spirals() {
    let (layers, stats) = draw("lang-examples/spiral.lsy", None);
    // One message per lateral guide, each seeding a spiral there.
    assert_eq!(stats["messages"], 4);
    assert_eq!(stats["systems"], 5);
    let main = layers.segments("main");
    assert!(main.len() > 500, "{} segments in main", main.len());
    for lateral in ["ne", "nw", "sw", "se"] {
        let segs = layers.segments(lateral);
        assert!(segs.len() > 150, "{lateral}: {} segments", segs.len());
        // A spiral winds: its heading turns through more than two full turns.
        let mut turned = 0.0;
        for w in segs.windows(2) {
            let (u, v) = (w[0].1 - w[0].0, w[1].1 - w[1].0);
            turned += u.perp_dot(v).atan2(u.dot(v));
        }
        assert!(
            turned > 4.0 * std::f64::consts::PI,
            "{lateral}: turned {turned} rad"
        );
    }
    // The main spiral stays inside its octagon; every branch reaches its link.
    let r = run_scene(
        &std::fs::read_to_string(root().join("lang-examples/spiral.lsy")).expect("spiral"),
    );
    for l in &r.scene.links {
        assert_eq!(l.used, 1, "every link's token is used");
    }
}

#[test]
fn the_dinosaur_grows_from_the_legs_through_every_guide() {
    let (layers, stats) = draw("lang-examples/dinosaur.lsy", None);
    // Four legs seed the body; the body the neck and the tail; then guide by guide
    // to the head and the tip of the tail: every link's one token is used.
    assert_eq!(stats["messages"], 11);
    let r = run_scene(
        &std::fs::read_to_string(root().join("lang-examples/dinosaur.lsy")).expect("dinosaur"),
    );
    assert!(r.scene.links.iter().all(|l| l.used == 1));
    for g in &r.scene.guides {
        assert!(
            !layers.segments(&g.name).is_empty(),
            "nothing grew in `{}`",
            g.name
        );
    }
    // Leafy where the paper puts leaves: the body, the head and the tail's tip.
    for (guide, least) in [("body", 300), ("head", 20), ("tip", 20)] {
        let n = layers.centres.get(guide).map_or(0, Vec::len);
        assert!(n >= least, "{guide}: {n} leaves");
    }
    // A stem goes up each leg from the ground to the body (y = 100).
    for leg in ["leg1", "leg2", "leg3", "leg4"] {
        let top = layers
            .segments(leg)
            .iter()
            .map(|(a, b)| a.y.max(b.y))
            .fold(f64::MIN, f64::max);
        assert!(top > 95.0, "{leg}: the stem ends at y = {top}");
    }
}

#[test]
fn the_guided_tree_grows_from_the_trunk_through_the_limbs_into_the_crown() {
    let (layers, stats) = draw("lang-examples/tree.lsy", None);
    // The trunk seeds four limbs and the top; each limb its cluster.
    assert_eq!(stats["messages"], 9);
    assert_eq!(stats["systems"], 10);
    // About as many elements as the paper's tree (15,000).
    let elements = stats["segments"].as_u64().expect("segments")
        + stats["elements"].as_u64().expect("elements");
    assert!((10_000..20_000).contains(&elements), "{elements} elements");
    for (g, outline) in &layers.outlines {
        let segs = layers.segments(g);
        assert!(segs.len() >= 10, "`{g}`: {} segments", segs.len());
        let leaves = layers.centres.get(g).map_or(0, Vec::len);
        if g == "trunk" || g.starts_with("limb") {
            assert_eq!(leaves, 0, "`{g}` is bare wood");
        } else {
            assert!(leaves >= 100, "`{g}`: {leaves} leaves");
        }
        // A limb runs from its base to the far end of its guide.
        if g.starts_with("limb") {
            let far = |p: DVec2| p.x.abs();
            let reach = segs.iter().map(|(_, b)| far(*b)).fold(0.0, f64::max);
            let end = outline.iter().map(|p| far(*p)).fold(0.0, f64::max);
            assert!(reach > end - 15.0, "`{g}` reaches {reach} of {end}");
        }
    }
}

#[test]
fn the_single_tree_fills_its_guide_and_its_leaves_hang() {
    let (layers, stats) = draw("lang-examples/tree.lsy", Some("Single"));
    assert_eq!(stats["systems"], 1);
    assert_eq!(stats["messages"], 0);
    let outline = &layers.outlines["tree"];
    let segs = layers.segments("tree");
    // The crown takes the guide's shape: it spans most of the guide's width.
    let span = |xs: &mut dyn Iterator<Item = f64>| {
        let (lo, hi) = xs.fold((f64::MAX, f64::MIN), |(l, h), x| (l.min(x), h.max(x)));
        hi - lo
    };
    let guide_width = span(&mut outline.iter().map(|p| p.x));
    let crown_width = span(&mut segs.iter().flat_map(|(a, b)| [a.x, b.x]));
    assert!(
        crown_width > 0.8 * guide_width,
        "the crown is {crown_width} wide in a guide {guide_width} wide"
    );
    // Leaves only far enough from the root (13 segments of 7 up a straight trunk
    // of 7 segments: none below the trunk's top).
    let centres = &layers.centres["tree"];
    assert!(centres.len() > 1000, "{} leaves", centres.len());
    assert!(centres.iter().all(|c| c.y > 50.0));
    // Leaves bend downward: far more of them point down than the shoots that carry
    // them, which all grow upward or sideways from the trunk.
    let axes = &layers.axes["tree"];
    let down = axes.iter().filter(|a| a.y < 0.0).count() as f64 / axes.len() as f64;
    let shoots_down = segs.iter().filter(|(a, b)| b.y < a.y).count() as f64 / segs.len() as f64;
    assert!(
        down > shoots_down + 0.2,
        "{down:.2} of the leaves point down, {shoots_down:.2} of the segments"
    );
}

/// The paper's Fig. 1 b–c: scaling two clusters up (the trunk held) re-grows
/// them larger; every message still arrives.
#[test]
fn scaling_clusters_of_the_guided_tree_grows_them_larger() {
    let (before, _) = draw("lang-examples/tree.lsy", None);
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_lsyc"))
        .args([
            "edit",
            "lang-examples/tree.lsy",
            "--pin",
            "trunk",
            "--scale",
            "clusterR2=1.3",
            "--scale",
            "clusterL2=1.3",
        ])
        .current_dir(root())
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let dir = tempfile::tempdir().expect("tempdir");
    let edited = dir.path().join("tree.lsy");
    std::fs::write(&edited, &o.stdout).expect("write");
    let (after, stats) = draw(edited.to_str().expect("utf-8"), None);
    assert_eq!(stats["messages"], 9);
    assert_eq!(before.outlines["trunk"], after.outlines["trunk"], "pinned");
    // The clusters grow over a larger area (their shoots are as long as before,
    // but fewer of them stop at the edge).
    let extent = |segs: &[(DVec2, DVec2)]| {
        let pts = segs.iter().flat_map(|(a, b)| [*a, *b]);
        let (lo, hi) = pts.fold((DVec2::MAX, DVec2::MIN), |(l, h), p| (l.min(p), h.max(p)));
        hi - lo
    };
    for g in ["clusterR2", "clusterL2"] {
        let (b, a) = (extent(before.segments(g)), extent(after.segments(g)));
        assert!(
            a.x > 1.1 * b.x && a.y > 1.1 * b.y,
            "`{g}`: {b} across, then {a}"
        );
    }
    assert_centre_rule(&after, "the edited tree");
}
