//! Turtle strings of a line drawing: unit segments in drawing order become a
//! tree of turtle moves, the form in which a drawing and a candidate
//! grammar's derivation are compared.
//!
//! Owns: the one `Builder` that turns segments (where each starts and ends)
//! into nodes (which earlier node each continues from: the previous one when
//! it starts where that one ended, else the latest point of the current
//! branch it starts on, a `]`; else a gap of whole steps, `f`), the `Angles`
//! that make turns whole multiples of δ, and the `Tree` both sides are
//! compared in. The input and every candidate go through the same builder,
//! so two drawings have equal trees exactly when they draw the same
//! segments in the same order. Must not know SVG or grammars.

use glam::DVec2;
use std::collections::HashMap;

/// The parent of a node drawn from the drawing's start point.
pub const ROOT: u32 = u32::MAX;

/// How close two points (in steps) must be to be one point.
pub const TOUCH: f64 = 0.3;

/// Points of the branch this much nearer than others (in steps) win a pop.
const SAME: f64 = 0.05;

/// The most points of the branch looked at per cell (the latest).
pub const PER_CELL: usize = 64;

/// How far a gap may be from a whole number of steps.
pub const GAP: f64 = 0.15;

/// The shortest gap, in steps, read as a jump: a nearer start is a stroke
/// that missed the drawing (noise), not moves.
pub const MIN_JUMP: f64 = 0.75;

/// The longest gap, in steps, read as moves (`f`).
pub const MAX_GAP: f64 = 100_000.0;

/// The most nodes (steps and moves) a builder makes.
pub const MAX_NODES: usize = 2_000_000;

/// What a node does.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Kind {
    /// A drawn step, `F`.
    Draw,
    /// A step without drawing, `f`.
    Move,
    /// A gap that is not one straight run of whole steps (moves in several
    /// directions, `-f--ff+`): where it lands, in `Tree::jumps`.
    Jump,
}

/// One step of the turtle: which node it continues from (`ROOT`: the start
/// point), by how many turns of δ from that node's heading (the first node's
/// own turn is 0: its heading is the drawing's start frame; other nodes from
/// the start point turn from the first node's heading), and what it does.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Node {
    pub parent: u32,
    pub turn: i32,
    pub kind: Kind,
}

/// A drawing as turtle steps in drawing order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Tree {
    pub nodes: Vec<Node>,
    /// Where each `Jump` node lands from its parent's end, in steps, in
    /// the parent's frame: (along its heading, to its left).
    pub jumps: HashMap<u32, DVec2>,
}

impl Tree {
    /// A tree of steps and straight moves only.
    pub fn of(nodes: Vec<Node>) -> Tree {
        Tree {
            nodes,
            jumps: HashMap::new(),
        }
    }
}

impl Tree {
    pub fn draws(&self) -> usize {
        self.nodes.iter().filter(|n| n.kind == Kind::Draw).count()
    }
}

/// The angle δ of a drawing and how turns are counted.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Angles {
    /// δ in degrees.
    pub delta: f64,
    /// `Some(m)` when m·δ = 360°: turns count modulo m.
    pub period: Option<i32>,
    /// How far (degrees) a turn may be from a multiple of δ.
    pub tolerance: f64,
}

impl Angles {
    pub fn new(delta: f64, period: Option<i32>, tolerance: f64) -> Angles {
        Angles {
            delta,
            period,
            tolerance,
        }
    }

    /// A count of turns in its canonical form: modulo the period, in
    /// (−m/2, m/2].
    pub fn norm(&self, k: i32) -> i32 {
        match self.period {
            Some(m) if m > 0 => {
                let r = k.rem_euclid(m);
                if 2 * r > m { r - m } else { r }
            }
            _ => k,
        }
    }

    /// The turn from heading `from` to heading `to` (radians) in whole δ,
    /// or `None` when it is not near a multiple.
    pub fn turns(&self, from: f64, to: f64) -> Option<i32> {
        let t = wrap_degrees((to - from).to_degrees());
        let k = (t / self.delta).round();
        if !k.is_finite() || k.abs() > 1e6 || (t - k * self.delta).abs() > self.tolerance {
            return None;
        }
        Some(self.norm(k as i32))
    }
}

/// An angle in degrees wrapped to (−180, 180].
pub fn wrap_degrees(a: f64) -> f64 {
    let r = a.rem_euclid(360.0);
    if r > 180.0 { r - 360.0 } else { r }
}

/// A node as the builder finds it, before its turn is counted.
#[derive(Clone, Copy, Debug)]
pub struct Raw {
    pub parent: u32,
    /// Heading, radians from +x.
    pub angle: f64,
    pub kind: Kind,
}

/// Why segments do not read as turtle steps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unfit {
    /// A segment starts off the drawing so far, not a whole number of steps away.
    Jump,
    /// A turn that is not a multiple of δ.
    Turn,
    /// More than `MAX_NODES` steps and moves.
    TooLarge,
}

/// Segments to nodes; see the module note. Coordinates are in steps.
pub struct Builder {
    pub raw: Vec<Raw>,
    /// The current branch: (node, where it ends), the start point first.
    chain: Vec<(u32, DVec2)>,
    /// Cell of a chain point to its places in `chain` (increasing).
    cells: HashMap<(i64, i64), Vec<u32>>,
    /// Each jump as drawn (in steps, not turned to its parent's frame).
    pub jumps: HashMap<u32, DVec2>,
    /// δ and how far a turn may be from a multiple of it (radians), when
    /// known: a straight gap of whole steps in a direction off it is a jump.
    pub lattice: Option<(f64, f64)>,
}

const CELL: f64 = 0.5;

fn cell(p: DVec2) -> (i64, i64) {
    ((p.x / CELL).floor() as i64, (p.y / CELL).floor() as i64)
}

impl Default for Builder {
    fn default() -> Self {
        Self::new()
    }
}

impl Builder {
    pub fn new() -> Builder {
        Builder {
            raw: Vec::new(),
            chain: Vec::new(),
            cells: HashMap::new(),
            jumps: HashMap::new(),
            lattice: None,
        }
    }

    fn enter(&mut self, node: u32, end: DVec2) {
        let at = self.chain.len() as u32;
        self.chain.push((node, end));
        self.cells.entry(cell(end)).or_default().push(at);
    }

    /// Leaves the chain's places after `keep`.
    fn truncate(&mut self, keep: usize) {
        while self.chain.len() > keep + 1 {
            if let Some((_, end)) = self.chain.pop()
                && let Some(v) = self.cells.get_mut(&cell(end))
            {
                v.pop();
            }
        }
    }

    /// The place of the chain nearest `p`, within `TOUCH`; of places as
    /// near (within `SAME`), the latest.
    fn find(&self, p: DVec2) -> Option<usize> {
        let (cx, cy) = cell(p);
        let mut best: Option<(f64, u32)> = None;
        for dx in -1..=1 {
            for dy in -1..=1 {
                if let Some(v) = self.cells.get(&(cx + dx, cy + dy)) {
                    // The latest few: a drawing that passes one point a
                    // thousand times must not cost a thousand per step.
                    for &at in v.iter().rev().take(PER_CELL) {
                        let d = self.chain[at as usize].1.distance(p);
                        if d > TOUCH {
                            continue;
                        }
                        best = match best {
                            None => Some((d, at)),
                            Some((bd, _)) if d < bd - SAME => Some((d, at)),
                            Some((bd, b)) if d <= bd + SAME && at > b => Some((d.min(bd), at)),
                            keep => keep,
                        };
                    }
                }
            }
        }
        best.map(|(_, b)| b as usize)
    }

    /// Adds the drawn step from `a` to `b` (and the moves before it, if it
    /// starts at a gap).
    pub fn push(&mut self, a: DVec2, b: DVec2) -> Result<(), Unfit> {
        if self.chain.is_empty() {
            self.enter(ROOT, a);
        }
        // The nearest point of the branch (the current end when it is as
        // near: the step continues).
        let top = self.chain.len() - 1;
        let from = if let Some(at) = self.find(a) {
            at
        } else {
            let (node, end) = self.chain[top];
            let g = a - end;
            let len = g.length();
            let steps = len.round();
            let straight =
                steps >= 1.0 && (len - steps).abs() <= GAP && self.on_lattice(node, g.y.atan2(g.x));
            if len > MAX_GAP || (!straight && (node == ROOT || len < MIN_JUMP)) {
                return Err(Unfit::Jump);
            }
            if self.raw.len() + steps as usize >= MAX_NODES {
                return Err(Unfit::TooLarge);
            }
            if !straight {
                self.jump(node, g, a);
                return self.push(a, b);
            }
            let angle = g.y.atan2(g.x);
            let mut parent = node;
            for k in 1..=steps as u32 {
                let id = self.raw.len() as u32;
                self.raw.push(Raw {
                    parent,
                    angle,
                    kind: Kind::Move,
                });
                self.enter(id, end + g * (f64::from(k) / steps));
                parent = id;
            }
            self.chain.len() - 1
        };
        if self.raw.len() >= MAX_NODES {
            return Err(Unfit::TooLarge);
        }
        self.truncate(from);
        let parent = self.chain[from].0;
        let d = b - a;
        let id = self.raw.len() as u32;
        self.raw.push(Raw {
            parent,
            angle: d.y.atan2(d.x),
            kind: Kind::Draw,
        });
        self.enter(id, b);
        Ok(())
    }

    /// Whether heading `angle` turns from `node`'s by a multiple of δ (any
    /// heading while δ is not known).
    fn on_lattice(&self, node: u32, angle: f64) -> bool {
        let Some((delta, tolerance)) = self.lattice else {
            return true;
        };
        let from = match node {
            ROOT => return true,
            n => self.raw[n as usize].angle,
        };
        let t = wrap_degrees((angle - from).to_degrees()).to_radians();
        (t - (t / delta).round() * delta).abs() <= tolerance
    }

    /// A jump by `g` from the end of `node` (the chain's last), landing at `at`.
    fn jump(&mut self, node: u32, g: DVec2, at: DVec2) {
        let angle = self.raw[node as usize].angle;
        let id = self.raw.len() as u32;
        self.raw.push(Raw {
            parent: node,
            angle,
            kind: Kind::Jump,
        });
        self.jumps.insert(id, g);
        self.enter(id, at);
    }

    /// Where jump `i` lands in the frame of its parent heading `angle`
    /// (radians from +x): along that heading, and to its left.
    pub fn landing(&self, i: u32, angle: f64) -> Option<DVec2> {
        let g = self.jumps.get(&i)?;
        let (sin, cos) = angle.sin_cos();
        Some(DVec2::new(g.x * cos + g.y * sin, g.y * cos - g.x * sin))
    }

    /// The turn of raw node `i` from its parent's heading (the first node's
    /// for nodes from the start point), in radians, wrapped.
    pub fn turn_radians(&self, i: usize) -> f64 {
        let r = self.raw[i];
        let from = if r.parent == ROOT {
            self.raw[0].angle
        } else {
            self.raw[r.parent as usize].angle
        };
        wrap_degrees((r.angle - from).to_degrees()).to_radians()
    }

    /// Raw node `i` as a node, its turn counted in δ.
    pub fn node(&self, i: usize, angles: &Angles) -> Result<Node, Unfit> {
        let r = self.raw[i];
        let turn = if i == 0 {
            0
        } else {
            let from = if r.parent == ROOT {
                self.raw[0].angle
            } else {
                self.raw[r.parent as usize].angle
            };
            angles.turns(from, r.angle).ok_or(Unfit::Turn)?
        };
        Ok(Node {
            parent: r.parent,
            turn,
            kind: r.kind,
        })
    }

    /// All nodes, turns counted in δ.
    pub fn tree(&self, angles: &Angles) -> Result<Tree, Unfit> {
        let nodes = (0..self.raw.len())
            .map(|i| self.node(i, angles))
            .collect::<Result<Vec<_>, _>>()?;
        let jumps = self
            .jumps
            .keys()
            .filter_map(|&i| Some((i, self.landing(i, self.raw[i as usize].angle)?)))
            .collect();
        Ok(Tree { nodes, jumps })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    type Seg = ((f64, f64), (f64, f64));

    fn tree(segs: &[Seg]) -> Tree {
        let mut b = Builder::new();
        for &((ax, ay), (bx, by)) in segs {
            b.push(DVec2::new(ax, ay), DVec2::new(bx, by))
                .expect("fits");
        }
        b.tree(&Angles::new(90.0, Some(4), 1.0)).expect("turns")
    }

    #[test]
    fn branches_pop_to_the_latest_point_of_the_branch() {
        // F[+F]F[-F]F on the square lattice, drawn as the turtle goes.
        let t = tree(&[
            ((0.0, 0.0), (0.0, 1.0)),
            ((0.0, 1.0), (-1.0, 1.0)),
            ((0.0, 1.0), (0.0, 2.0)),
            ((0.0, 2.0), (1.0, 2.0)),
            ((0.0, 2.0), (0.0, 3.0)),
        ]);
        let parents: Vec<u32> = t.nodes.iter().map(|n| n.parent).collect();
        let turns: Vec<i32> = t.nodes.iter().map(|n| n.turn).collect();
        assert_eq!(parents, [ROOT, 0, 0, 2, 2]);
        assert_eq!(turns, [0, 1, 0, -1, 0]);
    }

    #[test]
    fn gaps_of_whole_steps_are_moves() {
        let t = tree(&[((0.0, 0.0), (0.0, 1.0)), ((1.0, 1.0), (1.0, 2.0))]);
        let kinds: Vec<Kind> = t.nodes.iter().map(|n| n.kind).collect();
        assert_eq!(kinds, [Kind::Draw, Kind::Move, Kind::Draw]);
        assert_eq!(t.nodes[1].turn, -1);
        assert_eq!(t.nodes[2].turn, 1);
        let mut b = Builder::new();
        b.push(DVec2::ZERO, DVec2::Y).expect("first");
        // Nearer than a jump: a stroke that missed the drawing.
        assert_eq!(
            b.push(DVec2::new(0.5, 0.5), DVec2::new(0.5, 1.5)),
            Err(Unfit::Jump)
        );
        // Not a straight run of whole steps: a jump, and where it lands
        // (half a step back, a step and a half to the right).
        assert_eq!(b.push(DVec2::new(1.5, 0.5), DVec2::new(1.5, 1.5)), Ok(()));
        let t = b.tree(&Angles::new(90.0, Some(4), 1.0)).expect("turns");
        let kinds: Vec<Kind> = t.nodes.iter().map(|n| n.kind).collect();
        assert_eq!(kinds, [Kind::Draw, Kind::Jump, Kind::Draw]);
        let at = t.jumps[&1];
        assert!(at.distance(DVec2::new(-0.5, -1.5)) < 1e-12, "{at}");
    }

    #[test]
    fn turns_count_modulo_the_period() {
        let a = Angles::new(90.0, Some(4), 1.0);
        assert_eq!(a.norm(3), -1);
        assert_eq!(a.norm(2), 2);
        assert_eq!(a.norm(-2), 2);
        assert_eq!(a.turns(0.0, std::f64::consts::PI), Some(2));
        let b = Angles::new(25.7, None, 1.0);
        assert_eq!(b.turns(0.0, 51.4f64.to_radians()), Some(2));
        assert_eq!(b.turns(0.0, 40f64.to_radians()), None);
    }
}
