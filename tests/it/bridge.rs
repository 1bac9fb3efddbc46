//! The suspension bridge of Guided Procedural Modeling, Fig. 9
//! (`lang-examples/bridge.lsy`): towers, a truss deck, and a main cable in a chain
//! of snapped guides whose hangers keep one horizontal spacing across the chain,
//! also after the cable guides are edited.

use crate::scene::{Layers, draw};
use crate::support::root;
use glam::DVec2;
use lsyc::frontend;
use lsyc::run::{self, Options};

const FILE: &str = "lang-examples/bridge.lsy";
/// The hanger spacing (the program's `DX`).
const DX: f64 = 20.0;
/// The cable runs this far under its guide's top edge (the program's `GAP`).
const GAP: f64 = 0.5;
/// The cable guides, left to right.
const CABLE: [&str; 12] = [
    "sideL1", "sideL2", "main1", "main2", "main3", "main4", "main5", "main6", "main7", "main8",
    "sideR2", "sideR1",
];

/// The hangers of a cable guide: its vertical segments, as (x, bottom, top).
fn hangers(layers: &Layers, guide: &str) -> Vec<(f64, f64, f64)> {
    layers
        .segments(guide)
        .iter()
        .filter(|(a, b)| (a.x - b.x).abs() < 1e-3 && (a.y - b.y).abs() > 2.0)
        .map(|(a, b)| (0.5 * (a.x + b.x), a.y.min(b.y), a.y.max(b.y)))
        .collect()
}

/// The height of a cable guide's top edge (from vertex 3 to vertex 2) at x.
fn top_at(outline: &[DVec2], x: f64) -> f64 {
    let (a, b) = (outline[3], outline[2]);
    a.y + (b.y - a.y) * (x - a.x) / (b.x - a.x)
}

/// Every cable guide holds hangers; each stands on the roadway (one unit above the
/// guide's bottom edge) and reaches the cable, GAP under the guide's top edge; and
/// over the whole chain consecutive hangers stand DX apart. Returns their x.
fn assert_hangers_keep_their_spacing(layers: &Layers, what: &str) -> Vec<f64> {
    let mut xs = Vec::new();
    for g in CABLE {
        let hs = hangers(layers, g);
        assert!(!hs.is_empty(), "{what}: no hanger in `{g}`");
        let outline = &layers.outlines[g];
        for &(x, bottom, top) in &hs {
            assert!(
                (bottom - 1.0).abs() < 0.02,
                "{what}: `{g}` at x = {x}: {bottom}"
            );
            let cable = top_at(outline, x) - GAP;
            assert!(
                (top - cable).abs() < 0.05,
                "{what}: the hanger of `{g}` at x = {x} ends at {top}, the cable is at {cable}"
            );
        }
        xs.extend(hs.iter().map(|h| h.0));
    }
    xs.sort_by(f64::total_cmp);
    for w in xs.windows(2) {
        assert!(
            (w[1] - w[0] - DX).abs() < 0.02,
            "{what}: hangers at x = {} and {}",
            w[0],
            w[1]
        );
    }
    xs
}

/// The lowest and the highest y of a guide's drawing.
fn height_range(layers: &Layers, guide: &str) -> (f64, f64) {
    layers
        .segments(guide)
        .iter()
        .flat_map(|(a, b)| [a.y, b.y])
        .fold((f64::MAX, f64::MIN), |(lo, hi), y| (lo.min(y), hi.max(y)))
}

#[test]
fn the_bridge_hangs_its_cable_on_hangers_at_one_spacing() {
    let (layers, stats) = draw(FILE, None);
    // The deck, two towers and the first cable guide are seeded; every other cable
    // guide is seeded by the message of the one on its left.
    assert_eq!(stats["systems"], 15);
    assert_eq!(stats["messages"], CABLE.len() - 1);
    let text = std::fs::read_to_string(root().join(FILE)).expect("bridge");
    let fe = frontend::run(&text, Vec::new(), &[]);
    let checked = fe.checked.as_ref().expect("checks");
    let r = run::run_scene(&fe.file, checked, None, &Options::default()).expect("runs");
    assert_eq!(r.scene.links.len(), CABLE.len() - 1);
    assert!(
        r.scene.links.iter().all(|l| l.used == 1),
        "every token used"
    );

    // Hangers from one end of the bridge to the other, DX apart, symmetric.
    let xs = assert_hangers_keep_their_spacing(&layers, "bridge");
    assert_eq!(xs.len(), 42);
    assert!((xs[0] + 410.0).abs() < 0.02 && (xs[41] - 410.0).abs() < 0.02);

    // The main cable: thick pieces between the hangers' tops, in every cable guide,
    // reaching the deck's ends and the towers' tops (y = 140, less GAP).
    let mut cable_top: f64 = f64::MIN;
    for g in CABLE {
        let (_, hi) = height_range(&layers, g);
        cable_top = cable_top.max(hi);
    }
    assert!((cable_top - (140.0 - GAP)).abs() < 0.02, "{cable_top}");

    // Each tower stands from the water to one unit under the cable's vertex.
    for t in ["towerL", "towerR"] {
        let (lo, hi) = height_range(&layers, t);
        assert!((lo + 59.0).abs() < 0.02, "`{t}` starts at {lo}");
        assert!((hi - 139.0).abs() < 0.02, "`{t}` ends at {hi}");
        assert!(layers.segments(t).len() > 60, "`{t}` is a lattice");
    }

    // The deck's truss runs from one end of its guide to the other, within it.
    let deck = layers.segments("deck");
    let (lo, hi) = deck
        .iter()
        .flat_map(|(a, b)| [a.x, b.x])
        .fold((f64::MAX, f64::MIN), |(l, h), x| (l.min(x), h.max(x)));
    assert!(lo < -418.0 && hi > 418.0, "the deck spans {lo} … {hi}");
    // Its diagonals meet the chords at the cross angle given to the seed (60°).
    let diagonals = deck
        .iter()
        .filter(|(a, b)| {
            let d = *b - *a;
            (d.y.abs().atan2(d.x.abs()).to_degrees() - 60.0).abs() < 0.1
        })
        .count();
    assert!(diagonals > 100, "{diagonals} diagonals at 60°");
}

/// Guided Procedural Modeling, Fig. 9b: moving cable guides changes the cable's
/// shape; the neighbours follow the shared vertices, and the hangers regrow at the
/// same spacing under the new cable.
#[test]
fn dragging_the_cable_regrows_the_hangers_at_the_same_spacing() {
    let (before, _) = draw(FILE, None);
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_lsyc"))
        .args([
            "edit",
            FILE,
            "--by",
            "main1.v2=0,-30",
            "--by",
            "main8.v3=0,-30",
            "--pin",
            "deck",
            "--pin",
            "towerL",
            "--pin",
            "towerR",
        ])
        .current_dir(root())
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let dir = tempfile::tempdir().expect("tempdir");
    let edited = dir.path().join("bridge.lsy");
    std::fs::write(&edited, &o.stdout).expect("write");
    let (after, stats) = draw(edited.to_str().expect("utf-8"), None);
    assert_eq!(stats["messages"], CABLE.len() - 1);

    // The dragged vertices are where they were asked to go, and the guide on the
    // other side of each shares it.
    let at = |g: &str, k: usize| after.outlines[g][k];
    assert_eq!(at("main1", 2), DVec2::new(-155.0, 62.0));
    assert_eq!(at("main2", 3), at("main1", 2));
    assert_eq!(at("main8", 3), DVec2::new(155.0, 62.0));
    assert_eq!(at("main7", 2), at("main8", 3));
    // Held: the deck and the towers, and with them the feet of the cable guides
    // and the cable's vertices on the towers.
    for g in ["deck", "towerL", "towerR", "sideL1", "sideR1"] {
        assert_eq!(before.outlines[g], after.outlines[g], "`{g}` moved");
    }

    let xs = assert_hangers_keep_their_spacing(&after, "edited");
    assert_eq!(xs.len(), 42);
    // Toward the dragged vertex the hangers are shorter than before.
    let lowest = |l: &Layers| {
        hangers(l, "main1")
            .iter()
            .map(|h| h.2)
            .fold(f64::MAX, f64::min)
    };
    assert!(lowest(&after) < lowest(&before) - 15.0);
}
