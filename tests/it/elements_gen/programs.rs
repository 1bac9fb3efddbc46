//! Random element designs by class: the shapes of their kinds, and where
//! each copy goes (its placement), at the design's own count and at the
//! next (every repetition once more, a tree one level deeper). The
//! placements are worked out here by a turtle of this file's own, never by
//! lsyc.
//!
//! Every number a design holds is one a person writes (counts, steps of
//! whole units, angles such as 30 or 22.5, ratios such as 0.8), so that a
//! program inferred from its drawing can be held to them.

use super::rng::Rng;
use glam::DVec2;

/// A class of designs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Class {
    /// Copies along a straight line.
    Row,
    /// Copies around a centre, each turned with its place.
    Ring,
    /// Each copy stepped, turned and scaled from the one before.
    Spiral,
    /// A row whose kinds repeat with a period of two or three.
    Period,
    /// Rows of copies, stacked: two nested repetitions.
    Grid,
    /// A row whose step, or a sequence whose turn, changes by the same
    /// amount at every copy, written t0 + tΔ·m as the counter m falls
    /// (S0's Fig. 5).
    Linear,
    /// A binary branching of stems, each branch turned and scaled, with a
    /// leaf of another kind at every tip.
    Tree,
}

impl Class {
    pub const ALL: [Class; 7] = [
        Class::Row,
        Class::Ring,
        Class::Spiral,
        Class::Period,
        Class::Grid,
        Class::Linear,
        Class::Tree,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Class::Row => "row",
            Class::Ring => "ring",
            Class::Spiral => "spiral",
            Class::Period => "period",
            Class::Grid => "grid",
            Class::Linear => "linear",
            Class::Tree => "tree",
        }
    }

    /// (The bench's `--class`.)
    #[allow(dead_code)]
    pub fn parse(s: &str) -> Option<Class> {
        Class::ALL.into_iter().find(|c| c.name() == s)
    }
}

/// The outline of a kind, in its own coordinates (SVG user units, y down):
/// its base at the origin, pointing along +x.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// A closed polygon.
    Polygon(Vec<DVec2>),
    /// `w` × `h`, from the base along +x, centred on the x axis.
    Rect { w: f64, h: f64 },
    /// Radii `rx` (along x) and `ry`, centred at (`rx`, 0).
    Ellipse { rx: f64, ry: f64 },
    /// Radius `r`, centred at the origin.
    Circle { r: f64 },
}

/// Where one copy of a kind goes: moved to `at`, turned by `turn` degrees
/// (SVG's `rotate`) and scaled by `scale`, in that order outwards.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Place {
    pub kind: usize,
    pub at: DVec2,
    pub turn: f64,
    pub scale: f64,
}

impl Place {
    /// The affine map `[a, b, c, d, e, f]` of SVG's `matrix(…)`.
    pub fn matrix(&self) -> [f64; 6] {
        let (s, c) = self.turn.to_radians().sin_cos();
        let k = self.scale;
        [k * c, k * s, -k * s, k * c, self.at.x, self.at.y]
    }

    pub fn apply(&self, p: DVec2) -> DVec2 {
        let [a, b, c, d, e, f] = self.matrix();
        DVec2::new(a * p.x + c * p.y + e, b * p.x + d * p.y + f)
    }
}

/// A random design: its kinds, its copies and the copies of its next.
#[derive(Clone, Debug)]
pub struct Design {
    pub shapes: Vec<Shape>,
    pub level: Vec<Place>,
    pub next: Vec<Place>,
    /// For a sequence (rows, spirals, linear changes): the design extended
    /// at its other end instead, as a reading from its other end predicts
    /// (empty for the other classes).
    pub before: Vec<Place>,
    /// The design as a person would write it, for failure reports.
    pub text: String,
}

/// The design of `class` for `seed`.
pub fn design(class: Class, seed: u64) -> Design {
    let mut rng = Rng::of(&[0xE1E, class as u64, seed]);
    let kinds = match class {
        Class::Period => 2 + usize::from(rng.chance(0.4)),
        Class::Tree => 2,
        _ => 1,
    };
    let shapes = (0..kinds).map(|_| shape(&mut rng)).collect::<Vec<_>>();
    let shapes = distinct(shapes, &mut rng);
    let mut plan = Plan::random(class, &mut rng);
    if class == Class::Period {
        plan.second = kinds;
    }
    Design {
        level: plan.places(0),
        next: plan.places(1),
        before: plan.before(),
        text: plan.text(),
        shapes,
    }
}

/// Shapes redrawn until no two are alike.
fn distinct(mut shapes: Vec<Shape>, rng: &mut Rng) -> Vec<Shape> {
    for i in 1..shapes.len() {
        while shapes[..i].iter().any(|s| alike(s, &shapes[i])) {
            shapes[i] = shape(rng);
        }
    }
    shapes
}

fn alike(a: &Shape, b: &Shape) -> bool {
    std::mem::discriminant(a) == std::mem::discriminant(b)
}

/// A shape about 4–8 units across.
fn shape(rng: &mut Rng) -> Shape {
    let size = f64::from(rng.range(4, 8));
    match rng.below(5) {
        0 => Shape::Rect {
            w: size,
            h: f64::from(rng.range(2, 3)),
        },
        1 => Shape::Ellipse {
            rx: size / 2.0,
            ry: f64::from(rng.range(1, 2)),
        },
        2 => Shape::Circle { r: size / 2.0 },
        _ => Shape::Polygon(leaf(size, rng)),
    }
}

/// An asymmetric leaf: a base at the origin, a tip at (`size`, 0), a few
/// points on either side at whole or half units.
fn leaf(size: f64, rng: &mut Rng) -> Vec<DVec2> {
    let half = |rng: &mut Rng| f64::from(rng.range(2, 6)) / 2.0;
    let mut pts = vec![DVec2::ZERO];
    pts.push(DVec2::new((size / 3.0).round(), -half(rng)));
    pts.push(DVec2::new((2.0 * size / 3.0).round(), -half(rng)));
    pts.push(DVec2::new(size, 0.0));
    pts.push(DVec2::new((size / 2.0).round(), half(rng) + 0.5));
    pts
}

/// The numbers of a design.
#[derive(Clone, Debug)]
struct Plan {
    class: Class,
    /// Copies (or periods, or columns, or levels below the first).
    count: usize,
    /// Rows of a grid; kinds of a period.
    second: usize,
    step: f64,
    /// A grid's row step; a linear row's change of step.
    step2: f64,
    turn: f64,
    /// A linear sequence's change of turn; a tree's second branch's turn.
    turn2: f64,
    scale: f64,
    /// A tree's second branch's scale.
    scale2: f64,
    /// Where the first copy goes and which way the design runs.
    origin: DVec2,
    heading: f64,
    /// A ring's copies lie along it (90) or point out of it (0).
    face: f64,
}

const HEADINGS: [f64; 6] = [0.0, 30.0, 45.0, 90.0, -60.0, 180.0];

impl Plan {
    fn random(class: Class, rng: &mut Rng) -> Plan {
        let mut p = Plan {
            class,
            count: 0,
            second: 0,
            step: f64::from(rng.range(2, 5) * 5),
            step2: 0.0,
            turn: 0.0,
            turn2: 0.0,
            scale: 1.0,
            scale2: 1.0,
            origin: DVec2::new(f64::from(rng.range(-20, 20)), f64::from(rng.range(-20, 20))),
            heading: rng.pick(&HEADINGS),
            face: 0.0,
        };
        match class {
            Class::Row => p.count = rng.range(4, 12) as usize,
            Class::Ring => {
                p.count = rng.pick(&[5, 6, 8, 9, 10, 12, 15, 18, 20, 24]);
                p.step = f64::from(rng.range(3, 8) * 10);
                p.face = rng.pick(&[0.0, 90.0]);
            }
            Class::Spiral => {
                p.count = rng.range(10, 20) as usize;
                p.step = f64::from(rng.range(8, 14));
                p.turn = rng.pick(&[10.0, 15.0, 20.0, 25.0, 30.0]);
                p.scale = rng.pick(&[1.05, 1.08, 1.1, 0.95, 0.9]);
            }
            Class::Period => {
                p.count = rng.range(3, 6) as usize;
                p.step = f64::from(rng.range(2, 4) * 5);
            }
            Class::Grid => {
                p.count = rng.range(3, 8) as usize;
                p.second = rng.range(2, 6) as usize;
                p.step2 = f64::from(rng.range(2, 5) * 5);
            }
            Class::Linear => {
                p.count = rng.range(6, 14) as usize;
                let sign = if rng.chance(0.5) { 1.0 } else { -1.0 };
                if rng.chance(0.5) {
                    // Steps that shrink (tΔ > 0: the first is longest) or
                    // grow, all longer than 5 even with one more copy.
                    p.step2 = sign * f64::from(rng.range(1, 3));
                    p.step = if sign > 0.0 {
                        f64::from(rng.range(2, 3) * 5)
                    } else {
                        5.0 * ((p.step2.abs() * (p.count + 1) as f64) / 5.0).ceil() + 5.0
                    };
                } else {
                    p.step = f64::from(rng.range(10, 16));
                    p.turn = rng.pick(&[0.0, 5.0, 10.0]);
                    p.turn2 = sign * rng.pick(&[2.0, 3.0, 5.0]);
                }
            }
            Class::Tree => {
                p.count = rng.range(2, 4) as usize;
                p.step = f64::from(rng.range(3, 6) * 10);
                p.turn = rng.pick(&[20.0, 25.0, 30.0, 45.0]);
                p.turn2 = -rng.pick(&[20.0, 30.0, 40.0, 45.0]);
                p.scale = rng.pick(&[0.6, 0.7, 0.75, 0.8]);
                p.scale2 = rng.pick(&[0.5, 0.6, 0.7]);
                p.heading = -90.0;
            }
        }
        p
    }

    /// The copies, with every count `more` larger.
    fn places(&self, more: usize) -> Vec<Place> {
        let n = self.count + more;
        match self.class {
            Class::Row | Class::Spiral | Class::Linear => self.sequence(n),
            Class::Ring => self.ring(n),
            Class::Period => self.period(n),
            Class::Grid => self.grid(n, self.second + more),
            Class::Tree => {
                let mut out = Vec::new();
                self.tree(n, Turtle::new(self.origin, self.heading), &mut out);
                out
            }
        }
    }

    /// The design with one more copy at its other end: before its first
    /// (rows and spirals), or after its last with the counter run down to
    /// 0 (linear changes: read from the last copy, the change runs the
    /// other way and one more copy comes at that end).
    fn before(&self) -> Vec<Place> {
        if self.class == Class::Linear {
            let mut out = self.sequence(self.count);
            let mut t = Turtle::new(self.origin, self.heading);
            for k in 0..self.count {
                let m = (self.count - 1 - k) as f64;
                t.forward(self.step + self.step2 * m);
                t.scale *= self.scale;
                t.heading += self.turn + self.turn2 * m;
            }
            out.push(t.place(0));
            return out;
        }
        if !matches!(self.class, Class::Row | Class::Spiral) {
            return Vec::new();
        }
        // The turtle one step before the first copy.
        let heading = self.heading - self.turn;
        let scale = 1.0 / self.scale;
        let at = self.origin - dir(heading) * self.step * scale;
        let mut t = Turtle { at, heading, scale };
        let mut out = Vec::new();
        for _ in 0..=self.count {
            out.push(t.place(0));
            t.forward(self.step);
            t.scale *= self.scale;
            t.heading += self.turn;
        }
        out
    }

    /// `n` copies, each stepped from the one before by t(m) = t0 + tΔ·m as
    /// the counter m falls from n − 1 to 1 (the paper's linear form, which
    /// a constant t is too): one more copy puts a new first step before
    /// the others.
    fn sequence(&self, n: usize) -> Vec<Place> {
        let mut t = Turtle::new(self.origin, self.heading);
        let mut out = Vec::new();
        for k in 0..n {
            out.push(t.place(0));
            let m = (n - 1 - k) as f64;
            t.forward(self.step + self.step2 * m);
            t.scale *= self.scale;
            t.heading += self.turn + self.turn2 * m;
        }
        out
    }

    fn ring(&self, n: usize) -> Vec<Place> {
        let apart = 360.0 / self.count as f64;
        (0..n)
            .map(|k| {
                let a = self.heading + apart * k as f64;
                Place {
                    kind: 0,
                    at: self.origin + dir(a) * self.step,
                    turn: a + self.face,
                    scale: 1.0,
                }
            })
            .collect()
    }

    fn period(&self, n: usize) -> Vec<Place> {
        let mut t = Turtle::new(self.origin, self.heading);
        let mut out = Vec::new();
        for _ in 0..n {
            for kind in 0..self.second.max(2) {
                out.push(t.place(kind));
                t.forward(self.step);
            }
        }
        out
    }

    fn grid(&self, cols: usize, rows: usize) -> Vec<Place> {
        let across = dir(self.heading + 90.0) * self.step2;
        let mut out = Vec::new();
        for j in 0..rows {
            let mut t = Turtle::new(self.origin + across * j as f64, self.heading);
            for _ in 0..cols {
                out.push(t.place(0));
                t.forward(self.step);
            }
        }
        out
    }

    /// A stem (kind 0) and two branches at its tip, or a leaf (kind 1).
    fn tree(&self, levels: usize, mut t: Turtle, out: &mut Vec<Place>) {
        if levels == 0 {
            out.push(t.place(1));
            return;
        }
        out.push(t.place(0));
        t.forward(self.step);
        for (turn, scale) in [(self.turn, self.scale), (self.turn2, self.scale2)] {
            let mut b = t;
            b.heading += turn;
            b.scale *= scale;
            self.tree(levels - 1, b, out);
        }
    }

    fn text(&self) -> String {
        format!(
            "{} count {} second {} step {} step2 {} turn {} turn2 {} scale {} scale2 {} \
             heading {} face {} origin ({}, {})",
            self.class.name(),
            self.count,
            self.second,
            self.step,
            self.step2,
            self.turn,
            self.turn2,
            self.scale,
            self.scale2,
            self.heading,
            self.face,
            self.origin.x,
            self.origin.y
        )
    }
}

/// The unit vector at `deg` degrees (SVG user space).
fn dir(deg: f64) -> DVec2 {
    let (s, c) = deg.to_radians().sin_cos();
    DVec2::new(c, s)
}

/// This file's turtle: where it is, which way it heads, how large it draws.
#[derive(Clone, Copy, Debug)]
struct Turtle {
    at: DVec2,
    heading: f64,
    scale: f64,
}

impl Turtle {
    fn new(at: DVec2, heading: f64) -> Turtle {
        Turtle {
            at,
            heading,
            scale: 1.0,
        }
    }

    fn forward(&mut self, d: f64) {
        self.at += dir(self.heading) * d * self.scale;
    }

    fn place(&self, kind: usize) -> Place {
        Place {
            kind,
            at: self.at,
            turn: self.heading,
            scale: self.scale,
        }
    }
}
