//! A design written as SVG the ways drawings arrive: copies of one
//! definition (`<use>`), plain paths with the placement worked into their
//! coordinates, SVG primitives with a `transform`, plain paths in random
//! order, and plain paths each placed a little off (a hand placement).
//! Written here, never by lsyc's writer.

use super::programs::{Place, Shape};
use super::rng::Rng;
use glam::DVec2;

/// How a design is written.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Variant {
    /// One `<path>` per kind in `<defs>`, each copy a `<use>` with a
    /// `matrix(…)` (4 decimals), as vector editors export clones.
    Use,
    /// One `<path>` per copy, its coordinates placed (3 decimals).
    Plain,
    /// One SVG primitive per copy (`<rect>`, `<ellipse>`, `<circle>`,
    /// `<polygon>`) in the kind's own coordinates, with a `transform` of
    /// `translate`, `rotate` and `scale` (only those that do something).
    Prim,
    /// `Plain`, the copies in random order.
    Shuffled,
    /// `Plain`, each copy moved by up to 1 % of the design's step and
    /// turned by up to 1° (placed by hand); inferred with `--symmetrize`.
    Jittered,
}

impl Variant {
    pub const ALL: [Variant; 5] = [
        Variant::Use,
        Variant::Plain,
        Variant::Prim,
        Variant::Shuffled,
        Variant::Jittered,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Variant::Use => "use",
            Variant::Plain => "plain",
            Variant::Prim => "prim",
            Variant::Shuffled => "shuffled",
            Variant::Jittered => "jittered",
        }
    }

    /// (The bench's `--variant`.)
    #[allow(dead_code)]
    pub fn parse(s: &str) -> Option<Variant> {
        Variant::ALL.into_iter().find(|v| v.name() == s)
    }
}

const HEAD: &str = "<svg xmlns=\"http://www.w3.org/2000/svg\" \
                    xmlns:xlink=\"http://www.w3.org/1999/xlink\">\n";

/// The copies `places` of `shapes` as SVG in `variant`; `rng` draws the
/// order and the hand placement; `step` is the design's step (for the
/// jitter).
pub fn svg(
    shapes: &[Shape],
    places: &[Place],
    variant: Variant,
    step: f64,
    rng: &mut Rng,
) -> String {
    let mut places = places.to_vec();
    match variant {
        Variant::Shuffled => rng.shuffle(&mut places),
        Variant::Jittered => jitter(&mut places, step, rng),
        _ => {}
    }
    let mut out = String::from(HEAD);
    match variant {
        Variant::Use => {
            out.push_str("<defs>\n");
            for (k, s) in shapes.iter().enumerate() {
                out.push_str(&format!("<path id=\"k{k}\" d=\"{}\"/>\n", path(s, None, 4)));
            }
            out.push_str("</defs>\n");
            for p in &places {
                let m = p.matrix().map(|v| num(v, 4)).join(" ");
                out.push_str(&format!(
                    "<use xlink:href=\"#k{}\" transform=\"matrix({m})\"/>\n",
                    p.kind
                ));
            }
        }
        Variant::Prim => {
            for p in &places {
                out.push_str(&primitive(&shapes[p.kind], p));
            }
        }
        _ => {
            for p in &places {
                out.push_str(&plain(&shapes[p.kind], p, 3));
            }
        }
    }
    out.push_str("</svg>\n");
    out
}

/// One copy as a plain path with `decimals` decimals (also the truth the
/// check compares with, at 6).
pub fn plain(shape: &Shape, p: &Place, decimals: usize) -> String {
    format!("<path d=\"{}\"/>\n", path(shape, Some(p), decimals))
}

/// Moves each copy by up to 1 % of `step` (uniform in a disc) and turns
/// it by up to 1°.
fn jitter(places: &mut [Place], step: f64, rng: &mut Rng) {
    for p in places {
        let r = 0.01 * step * rng.unit().sqrt();
        let a = rng.unit() * std::f64::consts::TAU;
        p.at += DVec2::new(a.cos(), a.sin()) * r;
        p.turn += rng.unit() * 2.0 - 1.0;
    }
}

/// Path data of `shape`, placed by `p` (or in its own coordinates).
fn path(shape: &Shape, p: Option<&Place>, decimals: usize) -> String {
    let put = |q: DVec2| {
        let q = p.map_or(q, |p| p.apply(q));
        format!("{} {}", num(q.x, decimals), num(q.y, decimals))
    };
    match shape {
        Shape::Polygon(pts) => polygon(pts, put),
        Shape::Rect { w, h } => polygon(&rect(*w, *h), put),
        Shape::Ellipse { rx, ry } => ellipse(DVec2::new(*rx, 0.0), *rx, *ry, put),
        Shape::Circle { r } => ellipse(DVec2::ZERO, *r, *r, put),
    }
}

fn rect(w: f64, h: f64) -> [DVec2; 4] {
    [
        DVec2::new(0.0, -h / 2.0),
        DVec2::new(w, -h / 2.0),
        DVec2::new(w, h / 2.0),
        DVec2::new(0.0, h / 2.0),
    ]
}

fn polygon(pts: &[DVec2], put: impl Fn(DVec2) -> String) -> String {
    let body: Vec<String> = pts.iter().map(|&q| put(q)).collect();
    format!("M{}Z", body.join(" L"))
}

/// An ellipse as four cubic Béziers (exact under any affine placement).
fn ellipse(c: DVec2, rx: f64, ry: f64, put: impl Fn(DVec2) -> String) -> String {
    const K: f64 = 0.552_284_749_831;
    let (x, y) = (DVec2::new(rx, 0.0), DVec2::new(0.0, ry));
    let mut d = format!("M{}", put(c + x));
    for (a, b) in [(x, y), (y, -x), (-x, -y), (-y, x)] {
        d.push_str(&format!(
            " C{} {} {}",
            put(c + a + b * K),
            put(c + b + a * K),
            put(c + b)
        ));
    }
    d + "Z"
}

/// One copy as an SVG primitive with a `transform`.
fn primitive(shape: &Shape, p: &Place) -> String {
    let t = transform(p);
    match shape {
        Shape::Polygon(pts) => {
            let pts: Vec<String> = pts
                .iter()
                .map(|q| format!("{},{}", num(q.x, 3), num(q.y, 3)))
                .collect();
            format!("<polygon points=\"{}\"{t}/>\n", pts.join(" "))
        }
        Shape::Rect { w, h } => format!(
            "<rect x=\"0\" y=\"{}\" width=\"{}\" height=\"{}\"{t}/>\n",
            num(-h / 2.0, 3),
            num(*w, 3),
            num(*h, 3)
        ),
        Shape::Ellipse { rx, ry } => format!(
            "<ellipse cx=\"{}\" cy=\"0\" rx=\"{}\" ry=\"{}\"{t}/>\n",
            num(*rx, 3),
            num(*rx, 3),
            num(*ry, 3)
        ),
        Shape::Circle { r } => format!("<circle cx=\"0\" cy=\"0\" r=\"{}\"{t}/>\n", num(*r, 3)),
    }
}

/// ` transform="translate(…) rotate(…) scale(…)"`, leaving out what does
/// nothing.
fn transform(p: &Place) -> String {
    let mut parts = Vec::new();
    if p.at != DVec2::ZERO {
        parts.push(format!("translate({} {})", num(p.at.x, 3), num(p.at.y, 3)));
    }
    let turn = p.turn.rem_euclid(360.0);
    if num(turn, 3) != "0" && num(turn, 3) != "360" {
        parts.push(format!("rotate({})", num(turn, 3)));
    }
    if num(p.scale, 4) != "1" {
        parts.push(format!("scale({})", num(p.scale, 4)));
    }
    if parts.is_empty() {
        String::new()
    } else {
        format!(" transform=\"{}\"", parts.join(" "))
    }
}

/// A number with at most `decimals` decimals, no trailing zeros.
pub fn num(v: f64, decimals: usize) -> String {
    let s = format!("{v:.decimals$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    };
    if s == "-0" { "0".to_string() } else { s }
}
