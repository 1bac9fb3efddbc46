//! The grammar search: D0L systems whose derivation could draw a tree of
//! turtle steps, proposed from the drawing's own self-similarity.
//!
//! Two families, each read off the drawing rather than enumerated blindly:
//!
//! - **Edge rewriting** (Koch curves, dragon, Gosper curves, the arrowhead,
//!   bracketed plants such as `F -> F[+F]F[-F]F`): every drawn letter becomes
//!   a block of the same number of steps, consecutive in drawing order. For
//!   a block size b, the drawing is cut into blocks; one or two shapes of
//!   block (the one or two drawing letters' successors) must recur; each
//!   block becomes one step of the drawing one derivation earlier, with its
//!   turn less the successors' leading and trailing turns (tried over all
//!   values); and again, until what is left is the axiom. The blocks of the
//!   earlier drawing name the letters inside each successor. Gaps (`f`)
//!   rewrite to a fixed number of moves.
//! - **Node rewriting** (`X -> F[+X]F[-X]+X`, `F -> FF`): the counts of steps
//!   follow f(j+1) = k·f(j) + β·x(j), x(j+1) = α·x(j); for each solution the
//!   drawing of X one and two steps down is found nested at the place of
//!   the first X of the successor, and the drawing two steps down is parsed
//!   into runs of k^1 steps (F) and copies of the drawing one step down (X).
//! - **Drawing apices** (`apex`: `G -> F[+G]-G`, `F -> FF`): node rewriting
//!   on the drawing less its tips, the node letter then drawing a step at
//!   each; only when no candidate above draws the drawing.
//! - **Two node letters** (`pair`: Hilbert, Peano, Moore), for a drawing that
//!   is one path and only when no candidate of fewer letters draws it.
//!
//! Owns: proposing candidates, within the work limits of `Limits`. Must not
//! accept one: `grammar::matches` and the library's own derivation do.

use super::grammar::{Action, Grammar, Letter, Outcome, Sym, matches, turn_syms};
use super::turtle::{Angles, Kind, Node, ROOT, Tree};
use std::collections::{HashMap, HashSet};
use std::time::Instant;

mod apex;
mod moves;
mod pair;

/// How far the search goes.
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    /// Largest number of drawn steps per successor (edge rewriting).
    pub max_block: usize,
    /// Largest number of moves per successor of `f`.
    pub max_moves: usize,
    /// Largest number of X in a node-rewriting successor.
    pub max_x: usize,
    /// Largest number of F in a node-rewriting successor.
    pub max_f: usize,
    /// Most candidates proposed by each family (edge, node rewriting).
    pub max_candidates: usize,
    /// Largest axiom, in steps.
    pub max_axiom: usize,
    /// When to stop proposing.
    pub deadline: Option<Instant>,
}

impl Default for Limits {
    fn default() -> Limits {
        Limits {
            max_block: 64,
            max_moves: 16,
            max_x: 9,
            max_f: 24,
            max_candidates: 2_000,
            max_axiom: 256,
            deadline: None,
        }
    }
}

impl Limits {
    fn late(&self) -> bool {
        self.deadline.is_some_and(|d| Instant::now() >= d)
    }
}

/// What the search proposes, and whether it ran out of time.
#[derive(Debug, Default)]
pub struct Proposals {
    pub grammars: Vec<Grammar>,
    pub timed_out: bool,
}

/// Candidates for `tree`, cheapest first (see `Grammar::cost`), no two alike.
/// Each family proposes up to `max_candidates`.
pub fn propose(tree: &Tree, angles: &Angles, limits: &Limits) -> Proposals {
    let mut out = Proposals::default();
    if tree.nodes.len() < 2 {
        return out;
    }
    let mut seen = HashSet::new();
    let mut room = limits.max_candidates;
    // A turtle with no brackets and no moves draws each step after the
    // last: a drawing that branches needs a grammar that branches.
    let branches = branches(tree);
    let can_draw = |g: &Grammar| !branches || g.pushes() || g.moves();
    let mut add = |g: Grammar, out: &mut Proposals| {
        if room > 0 && can_draw(&g) && seen.insert(g.clone()) {
            room -= 1;
            out.grammars.push(g);
        }
    };
    // Gaps of several legs: only the family that reads them.
    if !tree.jumps.is_empty() {
        moves::moves(tree, angles, limits, &mut add, &mut out);
        cheapest_first(&mut out);
        return out;
    }
    edge_rewriting(tree, angles, limits, &mut add, &mut out);
    let mut seen = out.grammars.iter().cloned().collect::<HashSet<_>>();
    let mut room = limits.max_candidates;
    let mut add = |g: Grammar, out: &mut Proposals| {
        if room > 0 && can_draw(&g) && seen.insert(g.clone()) {
            room -= 1;
            out.grammars.push(g);
        }
    };
    node_rewriting(tree, angles, limits, &mut add, &mut out);
    // Two node letters only where one letter draws nothing of it: their
    // search is the costliest, and a grammar of fewer letters is smaller.
    let work = 64 * tree.nodes.len() as u64 + 100_000;
    let drawn = |g: &Grammar| matches(g, tree, angles, work, limits.deadline) == Outcome::Same;
    // Each candidate is matched once; the apices' are matched before they
    // are proposed.
    let mut any_drawn = out.grammars.iter().any(drawn);
    if !any_drawn {
        let before = out.grammars.len();
        apex::apex_plants(tree, angles, limits, &mut add, &mut out);
        any_drawn = out.grammars.len() > before;
    }
    if !any_drawn {
        let before = out.grammars.len();
        pair::node_pairs(tree, angles, limits, &mut add, &mut out);
        // Straight gaps the edge search did not place: moves in several
        // directions that happen to line up.
        if tree.nodes.iter().any(|n| n.kind == Kind::Move)
            && !out.grammars[before..].iter().any(drawn)
        {
            moves::moves(tree, angles, limits, &mut add, &mut out);
        }
    }
    cheapest_first(&mut out);
    out
}

/// Whether some step of `tree` has two steps after it (or the start two).
fn branches(tree: &Tree) -> bool {
    let mut seen = HashSet::with_capacity(tree.nodes.len());
    tree.nodes.iter().any(|n| !seen.insert(n.parent))
}

fn cheapest_first(out: &mut Proposals) {
    out.grammars.sort_by_cached_key(|g| {
        let (size, rule_size, rules, text) = g.cost();
        (size, rule_size, rules, turned_ends(g), text)
    });
}

/// How many successors start or end with a turn: of candidates as large,
/// the one with the fewest (`F[+X]F[-X]+X`, not `+F[X]F[--X]X`; a shift of
/// turns around every copy of a letter that level n cannot see).
fn turned_ends(g: &Grammar) -> usize {
    let turn = |s: Option<&Sym>| matches!(s, Some(Sym::Plus | Sym::Minus));
    g.letters
        .iter()
        .filter_map(|l| l.rule.as_ref())
        .map(|r| usize::from(turn(r.first())) + usize::from(turn(r.last())))
        .sum()
}

type Sink<'a> = dyn FnMut(Grammar, &mut Proposals) + 'a;

// ------------------------------------------------------------ edge rewriting

/// Where a step of a block continues from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum From {
    /// Step `k` of the same block.
    Local(u32),
    /// Outside the block: where the block starts.
    Start,
}

/// One step of a block's shape. The first step's turn is 0 (it depends on
/// the neighbours); steps from the block's start turn from the first step.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
struct Step {
    kind: Kind,
    from: From,
    turn: i32,
}

/// A successor found as a recurring block shape.
#[derive(Clone, Debug)]
struct Shape {
    kind: Kind,
    steps: Vec<Step>,
    /// The step where the next letter's block continues (the successor's end).
    exit: Option<u32>,
    /// The letter of each step (shape indices), once a lower level shows them.
    letters: Option<Vec<u8>>,
}

/// A letter not known yet (the top level's steps).
const UNKNOWN: u8 = u8::MAX;

/// A drawing at one derivation step, its steps' letters as shape indices.
#[derive(Clone, Debug)]
struct Level {
    nodes: Vec<Node>,
    letters: Vec<u8>,
}

/// A level cut into blocks.
struct Cut {
    /// First step of each block.
    starts: Vec<u32>,
    /// Shape of each block.
    shapes: Vec<u8>,
    /// Block of each step.
    block_of: Vec<u32>,
}

/// Block sizes: `b` drawn steps and `c` moves per drawn letter's block,
/// `s` moves per move's block (0: no moves at all).
#[derive(Clone, Copy, Debug)]
struct Sizes {
    b: usize,
    c: usize,
    s: usize,
}

const MOVE_SHAPE_LIMIT: usize = 1;
/// Drawing letters (shapes of drawn blocks) at most.
const MAX_LETTERS: usize = 2;

/// Cuts `nodes` into blocks of `sizes`; new shapes are added to `shapes`
/// only when `grow`. `None` when the level does not cut.
fn cut(
    nodes: &[Node],
    sizes: Sizes,
    angles: &Angles,
    shapes: &mut Vec<Shape>,
    grow: bool,
) -> Option<Cut> {
    let n = nodes.len();
    let mut starts = Vec::new();
    let mut kinds = Vec::new();
    let mut block_of = vec![0u32; n];
    let mut i = 0usize;
    let mut steps: Vec<Step> = Vec::new();
    while i < n {
        let first = nodes[i];
        let len = match first.kind {
            Kind::Draw => sizes.b + sizes.c,
            Kind::Move | Kind::Jump => sizes.s,
        };
        if len == 0 || i + len > n {
            return None;
        }
        shape_into(nodes, i, len, angles, &mut steps)?;
        let draws = steps.iter().filter(|st| st.kind == Kind::Draw).count();
        let moves = len - draws;
        let block = starts.len() as u32;
        block_of[i..i + len].fill(block);
        let fits = match first.kind {
            Kind::Draw => draws == sizes.b && moves == sizes.c,
            Kind::Move | Kind::Jump => moves == sizes.s,
        };
        if !fits {
            return None;
        }
        let shape = match shapes
            .iter()
            .position(|s| s.kind == first.kind && s.steps == steps)
        {
            Some(k) => k,
            None => {
                if !grow {
                    return None;
                }
                let same_kind = shapes.iter().filter(|s| s.kind == first.kind).count();
                let limit = match first.kind {
                    Kind::Draw => MAX_LETTERS,
                    Kind::Move | Kind::Jump => MOVE_SHAPE_LIMIT,
                };
                if same_kind >= limit {
                    return None;
                }
                if first.kind == Kind::Move
                    && !steps
                        .iter()
                        .enumerate()
                        .skip(1)
                        .all(|(j, s)| s.from == From::Local(j as u32 - 1) && s.turn == 0)
                {
                    return None;
                }
                shapes.push(Shape {
                    kind: first.kind,
                    steps: steps.clone(),
                    exit: None,
                    letters: None,
                });
                shapes.len() - 1
            }
        };
        starts.push(i as u32);
        kinds.push(shape as u8);
        i += len;
    }
    Some(Cut {
        starts,
        shapes: kinds,
        block_of,
    })
}

/// Records where each shape's successor ends (the step the next block
/// continues from); `false` if two blocks of one shape disagree.
fn exits(nodes: &[Node], cut: &Cut, shapes: &mut [Shape]) -> bool {
    for &start in &cut.starts {
        let first = nodes[start as usize];
        if first.parent == ROOT {
            continue;
        }
        let pb = cut.block_of[first.parent as usize] as usize;
        let local = first.parent - cut.starts[pb];
        let shape = &mut shapes[cut.shapes[pb] as usize];
        if shape.kind == Kind::Move && local as usize + 1 != shape.steps.len() {
            return false;
        }
        match shape.exit {
            None => shape.exit = Some(local),
            Some(e) if e == local => {}
            Some(_) => return false,
        }
    }
    true
}

/// Records each shape's letters from a cut level; `false` on disagreement.
fn letters(level: &Level, cut: &Cut, shapes: &mut [Shape]) -> bool {
    for (b, &start) in cut.starts.iter().enumerate() {
        let shape = &mut shapes[cut.shapes[b] as usize];
        let len = shape.steps.len();
        let got = &level.letters[start as usize..start as usize + len];
        if got.contains(&UNKNOWN) {
            continue;
        }
        match &shape.letters {
            None => shape.letters = Some(got.to_vec()),
            Some(l) if l[..] == got[..] => {}
            Some(_) => return false,
        }
    }
    true
}

/// Leading and trailing turns of each shape's successor.
#[derive(Clone, Debug)]
struct Ends {
    lead: Vec<i32>,
    tail: Vec<i32>,
}

/// The level one derivation step earlier: one step per block.
fn collapse(level: &Level, cut: &Cut, shapes: &[Shape], ends: &Ends, angles: &Angles) -> Level {
    let mut nodes = Vec::with_capacity(cut.starts.len());
    let first_shape = cut.shapes.first().copied().unwrap_or(0) as usize;
    for (b, &start) in cut.starts.iter().enumerate() {
        let first = level.nodes[start as usize];
        let shape = cut.shapes[b] as usize;
        let (parent, turn) = if first.parent == ROOT {
            let t = if b == 0 {
                0
            } else {
                first.turn - ends.lead[shape] + ends.lead[first_shape]
            };
            (ROOT, t)
        } else {
            let pb = cut.block_of[first.parent as usize];
            let ps = cut.shapes[pb as usize] as usize;
            (pb, first.turn - ends.tail[ps] - ends.lead[shape])
        };
        nodes.push(Node {
            parent,
            turn: angles.norm(turn),
            kind: shapes[shape].kind,
        });
    }
    Level {
        nodes,
        letters: cut.shapes.clone(),
    }
}

/// The turn counts tried for a successor's leading or trailing turns.
fn turn_range(angles: &Angles) -> Vec<i32> {
    match angles.period {
        Some(m) if m <= 12 => (0..m).map(|k| angles.norm(k)).collect(),
        Some(_) | None => vec![0, 1, -1, 2, -2],
    }
}

/// Every way to choose leading and trailing turns: the first drawing
/// letter's leading turn is 0 unless moves are rewritten (then only sums of
/// a tail and a lead are seen, and one of them may be fixed).
fn all_ends(shapes: &[Shape], angles: &Angles) -> Vec<Ends> {
    let range = turn_range(angles);
    let moves = shapes.iter().any(|s| s.kind == Kind::Move);
    // (shape, whether its leading turn): sums of a tail and a lead are all
    // the drawing shows, so the first letter's lead is 0 unless moves
    // (whose ends are 0) tell leads and tails apart.
    let mut free: Vec<(usize, bool)> = Vec::new();
    for (k, s) in shapes.iter().enumerate() {
        if s.kind != Kind::Draw {
            continue;
        }
        if moves || k != 0 {
            free.push((k, true));
        }
        free.push((k, false));
    }
    let mut out = Vec::new();
    let total = range.len().pow(free.len() as u32);
    for mut code in 0..total {
        let mut e = Ends {
            lead: vec![0; shapes.len()],
            tail: vec![0; shapes.len()],
        };
        for &(k, lead) in &free {
            let v = range[code % range.len()];
            code /= range.len();
            if lead {
                e.lead[k] = v;
            } else {
                e.tail[k] = v;
            }
        }
        out.push(e);
    }
    out
}

/// A successor from a shape: its steps as a bracketed string that ends at
/// the exit, then the trailing turns.
fn successor(
    shape: &Shape,
    lead: i32,
    tail: i32,
    sym: &dyn Fn(u8, Kind) -> Sym,
    angles: &Angles,
) -> Option<Vec<Sym>> {
    let n = shape.steps.len();
    let letters = shape.letters.clone().unwrap_or_else(|| vec![UNKNOWN; n]);
    let mut kids: Vec<Vec<u32>> = vec![Vec::new(); n + 1];
    let start = n as u32;
    for (j, s) in shape.steps.iter().enumerate() {
        match s.from {
            From::Start => kids[n].push(j as u32),
            From::Local(p) => kids[p as usize].push(j as u32),
        }
    }
    let exit = shape.exit.unwrap_or_else(|| {
        // The end of the chain of last children.
        let mut at = start;
        while let Some(&c) = kids[at as usize].last() {
            at = c;
        }
        at
    });
    if exit >= start {
        return None;
    }
    // The main path: from the start to the exit.
    let mut main = vec![false; n + 1];
    main[n] = true;
    let mut at = exit;
    loop {
        main[at as usize] = true;
        match shape.steps[at as usize].from {
            From::Start => break,
            From::Local(p) => at = p,
        }
    }
    let turn = |j: u32| {
        let s = shape.steps[j as usize];
        if j == 0 {
            lead
        } else if s.from == From::Start {
            s.turn + lead
        } else {
            s.turn
        }
    };
    let mut out = write_tree(
        &kids,
        Some(&main),
        &turn,
        &|j| sym(letters[j as usize], shape.steps[j as usize].kind),
        angles,
    )?;
    out.extend(turn_syms(tail, angles));
    Some(out)
}

/// Writes a tree of steps as a bracketed string: `kids[n]` are the children
/// of the start; a child is bracketed unless it is the last (or, given
/// `main`, unless it is on the main path, which must then be the last).
/// Iterative: trees may be deep.
fn write_tree(
    kids: &[Vec<u32>],
    main: Option<&[bool]>,
    turn: &dyn Fn(u32) -> i32,
    sym: &dyn Fn(u32) -> Sym,
    angles: &Angles,
) -> Option<Vec<Sym>> {
    let root = kids.len() - 1;
    let mut out = Vec::new();
    // (node, next child, opened with a bracket)
    let mut stack: Vec<(usize, usize, bool)> = vec![(root, 0, false)];
    while let Some(top) = stack.last_mut() {
        let (node, next) = (top.0, top.1);
        if next < kids[node].len() {
            top.1 += 1;
            let c = kids[node][next] as usize;
            let last = next + 1 == kids[node].len();
            let bracket = match main {
                Some(m) if m[node] => {
                    if m[c] && !last {
                        return None;
                    }
                    !m[c]
                }
                _ => !last,
            };
            if bracket {
                out.push(Sym::Push);
            }
            out.extend(turn_syms(turn(c as u32), angles));
            out.push(sym(c as u32));
            stack.push((c, 0, bracket));
        } else {
            let (_, _, bracket) = stack.pop()?;
            if bracket {
                out.push(Sym::Pop);
            }
        }
    }
    Some(out)
}

fn edge_rewriting(
    tree: &Tree,
    angles: &Angles,
    limits: &Limits,
    sink: &mut Sink<'_>,
    out: &mut Proposals,
) {
    let nodes = &tree.nodes;
    let draws = nodes.iter().filter(|n| n.kind == Kind::Draw).count();
    let moves = nodes.len() - draws;
    let top = Level {
        nodes: nodes.clone(),
        letters: vec![UNKNOWN; nodes.len()],
    };
    for b in 2..=limits.max_block.min(draws) {
        if draws % b != 0 {
            continue;
        }
        let size_options: Vec<Sizes> = if moves == 0 {
            vec![Sizes { b, c: 0, s: 0 }]
        } else {
            let mut v = Vec::new();
            let up = draws / b;
            for c in 0..=b.min(limits.max_moves * 4) {
                let rest = moves as i64 - (c * up) as i64;
                if rest < 0 {
                    break;
                }
                for s in 1..=limits.max_moves {
                    if (rest as usize).is_multiple_of(s) {
                        v.push(Sizes { b, c, s });
                    }
                }
            }
            v
        };
        for sizes in size_options {
            if limits.late() {
                out.timed_out = true;
                return;
            }
            let mut shapes = Vec::new();
            let Some(c0) = cut(&top.nodes, sizes, angles, &mut shapes, true) else {
                continue;
            };
            if !exits(&top.nodes, &c0, &mut shapes) {
                continue;
            }
            for ends in all_ends(&shapes, angles) {
                if limits.late() {
                    out.timed_out = true;
                    return;
                }
                let mut sh = shapes.clone();
                let mut level = collapse(&top, &c0, &sh, &ends, angles);
                let mut depth = 1u32;
                loop {
                    let mut trial = sh.clone();
                    let Some(c) = cut(&level.nodes, sizes, angles, &mut trial, false) else {
                        break;
                    };
                    if !exits(&level.nodes, &c, &mut trial) || !letters(&level, &c, &mut trial) {
                        break;
                    }
                    sh = trial;
                    level = collapse(&level, &c, &sh, &ends, angles);
                    depth += 1;
                }
                if level.nodes.len() > limits.max_axiom {
                    continue;
                }
                for g in edge_grammars(&level, &sh, &ends, depth, angles) {
                    sink(g, out);
                }
            }
        }
    }
}

/// Letter names of drawing shapes: `F` alone, `L` and `R` for two.
fn draw_names(count: usize) -> Vec<char> {
    if count <= 1 {
        vec!['F']
    } else {
        vec!['L', 'R']
    }
}

/// Grammars from a collapsed edge-rewriting hierarchy; a shape whose
/// letters no lower level showed gets each plausible guess.
fn edge_grammars(
    axiom: &Level,
    shapes: &[Shape],
    ends: &Ends,
    depth: u32,
    angles: &Angles,
) -> Vec<Grammar> {
    let draw: Vec<usize> = (0..shapes.len())
        .filter(|&k| shapes[k].kind == Kind::Draw)
        .collect();
    let mv: Option<usize> = (0..shapes.len()).find(|&k| shapes[k].kind == Kind::Move);
    let names = draw_names(draw.len());
    // Shape index to letter index: drawing shapes first, then `f`.
    let mut index = vec![0u8; shapes.len()];
    for (i, &k) in draw.iter().enumerate() {
        index[k] = i as u8;
    }
    let f_index = draw.len() as u8;
    if let Some(k) = mv {
        index[k] = f_index;
    }
    let has_moves = mv.is_some()
        || shapes
            .iter()
            .any(|s| s.steps.iter().any(|t| t.kind == Kind::Move))
        || axiom.nodes.iter().any(|n| n.kind == Kind::Move);
    // Letter guesses for shapes whose letters are unknown.
    let known: Vec<Option<Vec<u8>>> = shapes.iter().map(|s| s.letters.clone()).collect();
    let mut variants: Vec<Vec<Option<Vec<u8>>>> = vec![known.clone()];
    if draw.len() == 2 && draw.iter().any(|&k| known[k].is_none()) {
        let other = |k: usize| draw.iter().copied().find(|&j| j != k).unwrap_or(k);
        let mut same = known.clone();
        let mut swapped = known.clone();
        for &k in &draw {
            if known[k].is_none()
                && let Some(l) = &known[other(k)]
            {
                same[k] = Some(l.clone());
                swapped[k] = Some(
                    l.iter()
                        .map(|&x| {
                            if x == k as u8 {
                                other(k) as u8
                            } else if x == other(k) as u8 {
                                k as u8
                            } else {
                                x
                            }
                        })
                        .collect(),
                );
            }
        }
        variants = vec![same, swapped];
    }
    let mut out = Vec::new();
    'variant: for letters in variants {
        let sym = |shape: u8, kind: Kind| -> Sym {
            match kind {
                Kind::Move | Kind::Jump => Sym::Letter(f_index),
                Kind::Draw => {
                    if shape == UNKNOWN || shape as usize >= index.len() {
                        Sym::Letter(0)
                    } else {
                        Sym::Letter(index[shape as usize])
                    }
                }
            }
        };
        let mut grammar_letters = Vec::new();
        for (i, &k) in draw.iter().enumerate() {
            let mut sh = shapes[k].clone();
            sh.letters = letters[k].clone();
            if sh.letters.is_none() && draw.len() > 1 {
                continue 'variant;
            }
            let Some(rule) = successor(&sh, ends.lead[k], ends.tail[k], &sym, angles) else {
                continue 'variant;
            };
            grammar_letters.push(Letter {
                name: names[i],
                action: Action::Draw,
                rule: Some(rule),
            });
        }
        if has_moves {
            let rule = mv.map(|k| shapes[k].steps.len()).filter(|&s| s > 1);
            grammar_letters.push(Letter {
                name: 'f',
                action: Action::Move,
                rule: rule.map(|s| vec![Sym::Letter(f_index); s]),
            });
        }
        // The axiom: the last level, drawn from the start.
        let n = axiom.nodes.len();
        let mut kids: Vec<Vec<u32>> = vec![Vec::new(); n + 1];
        for (j, nd) in axiom.nodes.iter().enumerate() {
            if nd.parent == ROOT {
                kids[n].push(j as u32);
            } else {
                kids[nd.parent as usize].push(j as u32);
            }
        }
        let turn = |j: u32| axiom.nodes[j as usize].turn;
        let letter = |j: u32| sym(axiom.letters[j as usize], axiom.nodes[j as usize].kind);
        let Some(ax) = write_tree(&kids, None, &turn, &letter, angles) else {
            continue;
        };
        out.push(Grammar {
            letters: grammar_letters,
            axiom: ax,
            depth,
        });
    }
    out
}

// ------------------------------------------------------------ node rewriting

/// The shape of a drawn copy of X one step down: its steps' sources and turns.
fn shape_of(nodes: &[Node], start: usize, len: usize, angles: &Angles) -> Option<Vec<Step>> {
    let mut out = Vec::with_capacity(len);
    shape_into(nodes, start, len, angles, &mut out)?;
    Some(out)
}

/// `shape_of` into a reused buffer (cleared first).
fn shape_into(
    nodes: &[Node],
    start: usize,
    len: usize,
    angles: &Angles,
    out: &mut Vec<Step>,
) -> Option<()> {
    out.clear();
    let first = nodes.get(start)?;
    for j in start..start + len {
        let nd = nodes.get(j)?;
        let local = nd.parent != ROOT && nd.parent as usize >= start;
        let (from, turn) = if j == start {
            (From::Start, 0)
        } else if local {
            (From::Local(nd.parent - start as u32), nd.turn)
        } else if nd.parent == first.parent {
            (From::Start, angles.norm(nd.turn - first.turn))
        } else {
            return None;
        };
        out.push(Step {
            kind: nd.kind,
            from,
            turn,
        });
    }
    Some(())
}

/// Whether `nodes[start..start + shape.len()]` has `shape` (as `shape_of`
/// would find it), without building it.
fn has_shape(nodes: &[Node], start: usize, shape: &[Step], angles: &Angles) -> bool {
    let Some(first) = nodes.get(start) else {
        return false;
    };
    for (j, want) in shape.iter().enumerate() {
        let Some(nd) = nodes.get(start + j) else {
            return false;
        };
        let local = nd.parent != ROOT && nd.parent as usize >= start;
        let (from, turn) = if j == 0 {
            (From::Start, 0)
        } else if local {
            (From::Local(nd.parent - start as u32), nd.turn)
        } else if nd.parent == first.parent {
            (From::Start, angles.norm(nd.turn - first.turn))
        } else {
            return false;
        };
        if nd.kind != want.kind || from != want.from || turn != want.turn {
            return false;
        }
    }
    true
}

/// Whether `nodes[start..start + k]` is a straight run from outside.
fn straight(nodes: &[Node], start: usize, k: usize) -> bool {
    (start + 1..start + k).all(|j| {
        nodes
            .get(j)
            .is_some_and(|n| n.parent as usize == j - 1 && n.turn == 0)
    }) && nodes
        .get(start)
        .is_some_and(|n| n.parent == ROOT || (n.parent as usize) < start)
}

/// A block of the drawing two steps down: F (a run of k steps) or X (a copy
/// of the drawing one step down).
#[derive(Clone, Copy, Debug)]
struct Piece {
    x: bool,
    start: usize,
}

struct NodeHypothesis {
    k: usize,
    alpha: usize,
    beta: usize,
    depth: u32,
    /// Copies of X and F's in the axiom (1 and 0: the axiom `X`); a
    /// longer axiom starts with X (`XF-XF-XF`).
    axiom: (usize, usize),
    /// Steps X draws at `depth`.
    x_steps: usize,
}

/// The most X's, and F's beyond one per X, in an axiom other than `X`.
const AXIOM_XS: usize = 16;

/// What a drawing is cut into: runs of `f_len` straight steps (`fs` of
/// them) and `xs` copies of X of `x_len` steps each, copy first at piece
/// `p`.
struct Spec {
    f_len: usize,
    x_len: usize,
    fs: usize,
    xs: usize,
    p: usize,
}

fn node_rewriting(
    tree: &Tree,
    angles: &Angles,
    limits: &Limits,
    sink: &mut Sink<'_>,
    out: &mut Proposals,
) {
    let nodes = &tree.nodes;
    if nodes.iter().any(|n| n.kind != Kind::Draw) {
        return;
    }
    let total = nodes.len() as u128;
    let (mut hyps, mut longer) = (Vec::new(), Vec::new());
    for k in 1..=3usize {
        for alpha in 1..=limits.max_x {
            for beta in 1..=limits.max_f {
                let (mut f, mut x) = (0u128, 1u128);
                for depth in 1..=64u32 {
                    f = k as u128 * f + beta as u128 * x;
                    x *= alpha as u128;
                    if f > total {
                        break;
                    }
                    if depth < 2 {
                        continue;
                    }
                    let h = |axiom| NodeHypothesis {
                        k,
                        alpha,
                        beta,
                        depth,
                        axiom,
                        x_steps: f as usize,
                    };
                    if f == total {
                        hyps.push(h((1, 0)));
                    } else if k > 1 || alpha > 1 {
                        longer.extend(axioms(total, f, (k as u128).pow(depth)).map(h));
                    }
                }
            }
        }
    }
    // The axiom X first: longer axioms multiply the hypotheses.
    hyps.extend(longer);
    for h in hyps {
        if limits.late() {
            out.timed_out = true;
            return;
        }
        // A longer axiom: the drawing cut into copies of X and runs of F
        // once for the hypothesis.
        let parses = match h.axiom {
            (1, 0) => Vec::new(),
            _ => axiom_parses(nodes, &h, h.x_steps, angles),
        };
        if h.axiom != (1, 0) && parses.is_empty() {
            continue;
        }
        let mut axiom_of = HashMap::new();
        // f(1), f(2): drawn steps of X one and two steps down.
        let f1 = h.beta;
        let f2 = h.k * h.beta + h.beta * h.alpha;
        for p in 0..=h.beta {
            if limits.late() {
                out.timed_out = true;
                return;
            }
            // Offsets of the nested copies: D(n-1) starts after p runs of k^(n-1).
            let mut off = 0usize;
            let mut ok = true;
            for j in (3..=h.depth).rev() {
                let run = (h.k as u128).pow(j - 1) * p as u128;
                if run > nodes.len() as u128 {
                    ok = false;
                    break;
                }
                off += run as usize;
            }
            let s2 = off;
            let s1 = s2 + p * h.k;
            if !ok || s2 + f2 > nodes.len() || s1 + f1 > s2 + f2 {
                continue;
            }
            let Some(d1) = shape_of(nodes, s1, f1, angles) else {
                continue;
            };
            // The copy of X three steps down, when the drawing is deeper:
            // it tells the turns a copy starts and ends with (which the
            // parse two steps down tries over their range) at little cost.
            let three = (h.depth > 3).then(|| {
                let s3 = s2 - h.k * h.k * p;
                let f3 = h.k * f2 + h.beta * h.alpha * h.alpha;
                copy_of(nodes, s3, f3, angles)
            });
            let spec = Spec {
                f_len: h.k,
                x_len: h.beta,
                fs: h.beta,
                xs: h.alpha,
                p,
            };
            for pieces in parse_pieces(nodes, s2, f2, &spec, &d1, angles) {
                for mut g in node_grammar(nodes, s2, f2, &h, &pieces, angles) {
                    let deeper = match &three {
                        None => true,
                        Some(None) => false,
                        Some(Some(t)) => {
                            let g3 = Grammar {
                                depth: 3,
                                ..g.clone()
                            };
                            matches(&g3, t, angles, 64 * t.nodes.len() as u64 + 1_000, None)
                                == Outcome::Same
                        }
                    };
                    if !deeper {
                        continue;
                    }
                    if h.axiom != (1, 0) {
                        if limits.late() {
                            out.timed_out = true;
                            return;
                        }
                        // The axiom depends on X's rule alone.
                        let Some(w) = g.letters.get(1).and_then(|l| l.rule.clone()) else {
                            continue;
                        };
                        let axiom = axiom_of
                            .entry(w)
                            .or_insert_with_key(|w| node_axiom(&parses, &h, w, angles));
                        let Some(axiom) = axiom.clone() else {
                            continue;
                        };
                        g.axiom = axiom;
                    }
                    sink(g, out);
                }
            }
        }
    }
}

/// Steps `start..start + len` as a drawing of their own (its first step's
/// turn 0, steps from outside it from where it starts), or `None` when they
/// do not start from one place.
fn copy_of(nodes: &[Node], start: usize, len: usize, angles: &Angles) -> Option<Tree> {
    let first = *nodes.get(start)?;
    let inside = |p: u32| p != ROOT && (start..start + len).contains(&(p as usize));
    let part = nodes.get(start..start + len)?;
    let mut out = Vec::with_capacity(len);
    for (i, nd) in part.iter().enumerate() {
        out.push(if inside(nd.parent) {
            Node {
                parent: nd.parent - start as u32,
                ..*nd
            }
        } else if nd.parent == first.parent {
            Node {
                parent: ROOT,
                turn: if i == 0 {
                    0
                } else {
                    angles.norm(nd.turn - first.turn)
                },
                kind: nd.kind,
            }
        } else {
            return None;
        });
    }
    Some(Tree::of(out))
}

/// The ways (at most a few) to cut steps `start..start + len` into runs of
/// F and copies of X as `spec` says, the first `p` pieces runs and the next
/// a copy.
fn parse_pieces(
    nodes: &[Node],
    start: usize,
    len: usize,
    spec: &Spec,
    copy: &[Step],
    angles: &Angles,
) -> Vec<Vec<Piece>> {
    const MAX_PARSES: usize = 16;
    let end = start + len;
    let p = spec.p;
    let mut found = Vec::new();
    // Depth-first over choices, with an explicit stack of (pieces so far, next choice).
    let mut stack: Vec<(Vec<Piece>, usize, usize, u8)> = vec![(Vec::new(), start, 0, 0)];
    let mut work = 0usize;
    while let Some((pieces, at, fs, choice)) = stack.pop() {
        work += 1;
        if work > 10_000 || found.len() >= MAX_PARSES {
            break;
        }
        if at == end {
            if fs == spec.fs && pieces.len() == spec.fs + spec.xs {
                found.push(pieces);
            }
            continue;
        }
        let xs = pieces.len() - fs;
        // Choice 0: a run of F; choice 1: a copy of X.
        if choice == 0 {
            stack.push((pieces.clone(), at, fs, 1));
            let must_x = pieces.len() == p;
            if fs < spec.fs && !must_x && at + spec.f_len <= end && straight(nodes, at, spec.f_len)
            {
                let mut next = pieces;
                next.push(Piece {
                    x: false,
                    start: at,
                });
                stack.push((next, at + spec.f_len, fs + 1, 0));
            }
        } else {
            let must_f = pieces.len() < p;
            if xs < spec.xs
                && !must_f
                && at + spec.x_len <= end
                && has_shape(nodes, at, copy, angles)
            {
                let mut next = pieces;
                next.push(Piece { x: true, start: at });
                stack.push((next, at + spec.x_len, fs, 0));
            }
        }
    }
    found
}

/// The node-rewriting grammars of a parse of the drawing two steps down.
/// A copy of X one step down starts turned by the successor's turns before
/// its first F outside brackets (`t_lead`), and is left from its exit, the
/// last such F, turned by the turns after it (`t_end`): a drawing shows
/// each only inside the turn of a piece that starts a copy or continues
/// from one (`X -> F++X-F+F+`), so both are tried over the turn range, and
/// the successor gets the leading and trailing turns that make them so.
fn node_grammar(
    nodes: &[Node],
    s2: usize,
    f2: usize,
    h: &NodeHypothesis,
    pieces: &[Piece],
    angles: &Angles,
) -> Vec<Grammar> {
    let Some(parse) = node_tree(nodes, s2, f2, (h.k, h.beta), pieces, angles) else {
        return Vec::new();
    };
    let (f, x) = (0u8, 1u8);
    let sym = |j: u32| Sym::Letter(if pieces[j as usize].x { x } else { f });
    let range = |needed: bool| if needed { turn_range(angles) } else { vec![0] };
    let lead_seen = pieces.iter().skip(1).any(|p| p.x);
    let mut shifts: Vec<(i32, i32)> = range(lead_seen)
        .into_iter()
        .flat_map(|l| range(parse.exit.is_some()).into_iter().map(move |e| (l, e)))
        .collect();
    shifts.sort_by_key(|&(l, e)| (l.abs() + e.abs(), l.abs(), -l, -e));
    let mut out = Vec::new();
    for (t_lead, t_end) in shifts {
        {
            let turn = |j: u32| {
                let j = j as usize;
                if j == 0 {
                    return 0;
                }
                let lead = if pieces[j].x { t_lead } else { 0 };
                let end = if parse.after_x[j] { t_end } else { 0 };
                angles.norm(parse.turns[j] - lead - end)
            };
            let Some(body) = write_tree(&parse.kids, None, &turn, &sym, angles) else {
                continue;
            };
            // X draws nothing one step down: the successor's own turns.
            let Some(LevelEnds { turns: ends, .. }) = level_ends(&body, 1, 1) else {
                continue;
            };
            if parse.exit.is_some_and(|e| e != ends.last) {
                continue;
            }
            // Leading and trailing turns only where a copy shows them.
            let mut succ = if lead_seen {
                turn_syms(t_lead - ends.before, angles)
            } else {
                Vec::new()
            };
            succ.extend(body);
            if parse.exit.is_some() {
                succ.extend(turn_syms(t_end - ends.after, angles));
            }
            out.push(Grammar {
                letters: vec![
                    Letter {
                        name: 'F',
                        action: Action::Draw,
                        rule: (h.k > 1).then(|| vec![Sym::Letter(f); h.k]),
                    },
                    Letter {
                        name: 'X',
                        action: Action::Nothing,
                        rule: Some(succ),
                    },
                ],
                axiom: vec![Sym::Letter(x)],
                depth: h.depth,
            });
        }
    }
    out
}

/// The two-down parse as a tree of pieces: each piece's children, its turn
/// (from its parent's heading as drawn), whether it continues from a copy
/// of X, and where in a copy of X the turtle leaves it (when some piece
/// continues from one).
struct NodeTree {
    kids: Vec<Vec<u32>>,
    turns: Vec<i32>,
    after_x: Vec<bool>,
    exit: Option<usize>,
}

fn node_tree(
    nodes: &[Node],
    s2: usize,
    f2: usize,
    (f_len, x_len): (usize, usize),
    pieces: &[Piece],
    angles: &Angles,
) -> Option<NodeTree> {
    let n = pieces.len();
    let len = |p: &Piece| if p.x { x_len } else { f_len };
    // Which piece each step is in.
    let piece_of = |j: usize| {
        pieces
            .iter()
            .rposition(|p| p.start <= j && j < p.start + len(p))
    };
    let mut t = NodeTree {
        kids: vec![Vec::new(); n + 1],
        turns: vec![0i32; n],
        after_x: vec![false; n],
        exit: None,
    };
    let first = nodes[s2];
    for (i, p) in pieces.iter().enumerate() {
        let nd = nodes[p.start];
        let outside =
            nd.parent == ROOT || (nd.parent as usize) < s2 || nd.parent as usize >= s2 + f2;
        if outside {
            if nd.parent != first.parent {
                return None;
            }
            t.kids[n].push(i as u32);
            t.turns[i] = if i == 0 {
                0
            } else {
                angles.norm(nd.turn - first.turn)
            };
            continue;
        }
        let q = piece_of(nd.parent as usize)?;
        let qp = &pieces[q];
        let at = nd.parent as usize - qp.start;
        if qp.x {
            // Every copy of X is left from the same step.
            if t.exit.is_some_and(|e| e != at) {
                return None;
            }
            t.exit = Some(at);
            t.after_x[i] = true;
        } else if at != len(qp) - 1 {
            // Only the end of a run of F continues.
            return None;
        }
        t.kids[q].push(i as u32);
        t.turns[i] = nd.turn;
    }
    Some(t)
}

/// The axioms of `c` X's and `e` F's that draw `total` steps at a depth
/// where X draws `f` and F draws `kn` (see `AXIOM_XS`), the copies of X
/// at least half the drawing.
fn axioms(total: u128, f: u128, kn: u128) -> impl Iterator<Item = (usize, usize)> {
    (1..=AXIOM_XS).filter_map(move |c| {
        let rest = total.checked_sub(c as u128 * f)?;
        let e = rest / kn.max(1);
        (e * kn == rest && 2 * c as u128 * f >= total && e as usize <= c + 1)
            .then_some((c, e as usize))
    })
}

/// The ways to cut a drawing that holds several copies of X (`XF-XF-XF`)
/// into copies of X at depth n (as the first one, which starts the
/// drawing) and runs of F (k^n steps each): what every X rule of the
/// hypothesis shares.
fn axiom_parses(
    nodes: &[Node],
    h: &NodeHypothesis,
    x_len: usize,
    angles: &Angles,
) -> Vec<(Vec<Piece>, NodeTree)> {
    let (c, e) = h.axiom;
    let Some(f_len) = h.k.checked_pow(h.depth) else {
        return Vec::new();
    };
    let spec = Spec {
        f_len,
        x_len,
        fs: e,
        xs: c,
        p: 0,
    };
    let Some(copy) = shape_of(nodes, 0, x_len, angles) else {
        return Vec::new();
    };
    parse_pieces(nodes, 0, nodes.len(), &spec, &copy, angles)
        .into_iter()
        .filter_map(|pieces| {
            let t = node_tree(nodes, 0, nodes.len(), (f_len, x_len), &pieces, angles)?;
            Some((pieces, t))
        })
        .collect()
}

/// The axiom for X's rule `w` over one of `parses`: the turns between
/// the pieces less the turns a copy of X starts and ends with.
fn node_axiom(
    parses: &[(Vec<Piece>, NodeTree)],
    h: &NodeHypothesis,
    w: &[Sym],
    angles: &Angles,
) -> Option<Vec<Sym>> {
    let ends = level_ends(w, h.k, h.depth)?;
    let (f, x) = (0u8, 1u8);
    for (pieces, t) in parses {
        if t.exit.is_some_and(|at| at != ends.turns.last) {
            continue;
        }
        let turn = |j: u32| {
            let j = j as usize;
            if j == 0 {
                return 0;
            }
            let lead = if pieces[j].x { ends.turns.before } else { 0 };
            let end = if t.after_x[j] { ends.turns.after } else { 0 };
            angles.norm(t.turns[j] - lead - end)
        };
        let sym = |j: u32| Sym::Letter(if pieces[j as usize].x { x } else { f });
        if let Some(axiom) = write_tree(&t.kids, None, &turn, &sym, angles) {
            return Some(axiom);
        }
    }
    None
}

/// X derived `depth` times from successor `w` (F -> F^k): the steps it
/// draws and its turns outside brackets before its first step and after its
/// last, and which step is the last.
struct LevelEnds {
    steps: usize,
    turns: OuterTurns,
}

fn level_ends(w: &[Sym], k: usize, depth: u32) -> Option<LevelEnds> {
    let (f, x) = (0u8, 1u8);
    // Level 0: X draws nothing.
    let mut below = LevelEnds {
        steps: 0,
        turns: OuterTurns {
            before: 0,
            after: 0,
            last: 0,
        },
    };
    for j in 1..=depth {
        let run = k.checked_pow(j - 1)?;
        let (mut depth_b, mut steps) = (0usize, 0usize);
        let (mut before, mut after, mut last) = (0i32, 0i32, None);
        for s in w {
            let (draws, lead, exit, end) = match *s {
                Sym::Push => {
                    depth_b += 1;
                    continue;
                }
                Sym::Pop => {
                    depth_b = depth_b.checked_sub(1)?;
                    continue;
                }
                Sym::Plus | Sym::Minus => {
                    let t = if *s == Sym::Plus { 1 } else { -1 };
                    if depth_b == 0 {
                        if last.is_none() {
                            before += t;
                        } else {
                            after += t;
                        }
                    }
                    continue;
                }
                Sym::Letter(l) if l == f => (run, 0, run - 1, 0),
                Sym::Letter(l) if l == x => (
                    below.steps,
                    below.turns.before,
                    below.turns.last,
                    below.turns.after,
                ),
                Sym::Letter(_) => continue,
            };
            if draws > 0 && depth_b == 0 {
                if last.is_none() {
                    before += lead;
                }
                last = Some(steps + exit);
                after = end;
            }
            steps = steps.checked_add(draws)?;
        }
        below = LevelEnds {
            steps,
            turns: OuterTurns {
                before,
                after,
                last: last?,
            },
        };
    }
    Some(below)
}

/// Turns outside brackets before the first drawn step and after the last,
/// and which step (counted among every step, in order) is that last one.
struct OuterTurns {
    before: i32,
    after: i32,
    last: usize,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::infer::lines::grammar::{Outcome, matches};
    use crate::infer::lines::turtle::Builder;
    use glam::DVec2;

    /// Draws a grammar with the builder, as a drawing would be read.
    pub(super) fn draw(g: &Grammar, angles: &Angles) -> Tree {
        let mut frames: Vec<(&[Sym], usize, u32)> = vec![(&g.axiom[..], 0, g.depth)];
        let (mut h, mut pos) = (0i32, DVec2::ZERO);
        let mut saved = Vec::new();
        let mut b = Builder::new();
        b.lattice = Some((angles.delta.to_radians(), angles.tolerance.to_radians()));
        while let Some(top) = frames.last_mut() {
            let (syms, i, d) = (top.0, top.1, top.2);
            if i >= syms.len() {
                frames.pop();
                continue;
            }
            top.1 += 1;
            match syms[i] {
                Sym::Plus => h += 1,
                Sym::Minus => h -= 1,
                Sym::Push => saved.push((h, pos)),
                Sym::Pop => (h, pos) = saved.pop().expect("balanced"),
                Sym::Letter(k) => {
                    let l = &g.letters[k as usize];
                    if d > 0
                        && let Some(rule) = &l.rule
                    {
                        frames.push((rule, 0, d - 1));
                        continue;
                    }
                    let a = (90.0 + angles.delta * f64::from(h)).to_radians();
                    let next = pos + DVec2::new(a.cos(), a.sin());
                    match l.action {
                        Action::Draw => b.push(pos, next).expect("fits"),
                        Action::Move => {}
                        Action::Nothing => continue,
                    }
                    pos = next;
                }
            }
        }
        b.tree(angles).expect("turns")
    }

    fn parse(text: &str, letters: &[(char, Action)]) -> Vec<Sym> {
        text.chars()
            .map(|c| match c {
                '+' => Sym::Plus,
                '-' => Sym::Minus,
                '[' => Sym::Push,
                ']' => Sym::Pop,
                c => Sym::Letter(letters.iter().position(|l| l.0 == c).expect("letter") as u8),
            })
            .collect()
    }

    pub(super) fn grammar(axiom: &str, rules: &[(char, Action, &str)], depth: u32) -> Grammar {
        let ls: Vec<(char, Action)> = rules.iter().map(|r| (r.0, r.1)).collect();
        Grammar {
            letters: rules
                .iter()
                .map(|r| Letter {
                    name: r.0,
                    action: r.1,
                    rule: (!r.2.is_empty()).then(|| parse(r.2, &ls)),
                })
                .collect(),
            axiom: parse(axiom, &ls),
            depth,
        }
    }

    fn finds(g: &Grammar, angles: &Angles) -> Grammar {
        let tree = draw(g, angles);
        let p = propose(&tree, angles, &Limits::default());
        p.grammars
            .into_iter()
            .find(|c| matches(c, &tree, angles, 10_000_000, None) == Outcome::Same)
            .unwrap_or_else(|| panic!("nothing draws {}", g.describe()))
    }

    #[test]
    fn koch_island() {
        let a = Angles::new(90.0, Some(4), 1.0);
        let g = grammar("F-F-F-F", &[('F', Action::Draw, "F-F+F+FF-F-F+F")], 2);
        assert_eq!(finds(&g, &a).describe(), g.describe());
    }

    #[test]
    fn dragon_and_arrowhead() {
        let a = Angles::new(90.0, Some(4), 1.0);
        let g = grammar(
            "L",
            &[('L', Action::Draw, "L+R+"), ('R', Action::Draw, "-L-R")],
            6,
        );
        // The smaller L -> L+R, R -> L-R draws the same dragon.
        assert_eq!(
            finds(&g, &a).describe(),
            "axiom L; L -> L+R; R -> L-R; derive 6"
        );
        let a = Angles::new(60.0, Some(6), 1.0);
        let g = grammar(
            "R",
            &[('L', Action::Draw, "R+L+R"), ('R', Action::Draw, "L-R-L")],
            4,
        );
        let found = finds(&g, &a);
        assert_eq!(found.rule_size(), g.rule_size(), "{}", found.describe());
    }

    #[test]
    fn bracketed_plants() {
        let a = Angles::new(25.7, None, 1.0);
        let g = grammar("F", &[('F', Action::Draw, "F[+F]F[-F]F")], 3);
        assert_eq!(finds(&g, &a).describe(), g.describe());
        let a = Angles::new(22.5, Some(16), 1.0);
        let g = grammar("F", &[('F', Action::Draw, "FF-[-F+F+F]+[+F-F-F]")], 3);
        assert!(finds(&g, &a).rule_size() <= g.rule_size());
        let a = Angles::new(20.0, Some(18), 1.0);
        let g = grammar(
            "X",
            &[
                ('X', Action::Nothing, "F[+X]F[-X]+X"),
                ('F', Action::Draw, "FF"),
            ],
            4,
        );
        let found = finds(&g, &a);
        assert!(found.rule_size() <= g.rule_size(), "{}", found.describe());
    }

    /// A plant whose trunk runs straight for 64 steps: grammars with no
    /// brackets that draw its first straight run (`X -> FFFFFX` at depth
    /// 63) are not proposed, so the proposals' room goes to the plant's.
    #[test]
    fn a_drawing_that_branches_gets_grammars_that_branch() {
        let a = Angles::new(45.0, Some(8), 1.0);
        let g = grammar(
            "X",
            &[
                ('F', Action::Draw, "FF"),
                ('X', Action::Nothing, "FF[+FX]FF"),
            ],
            6,
        );
        let tree = draw(&g, &a);
        let p = propose(&tree, &a, &Limits::default());
        assert!(p.grammars.iter().all(Grammar::pushes));
        assert_eq!(finds(&g, &a).describe(), g.describe());
    }

    /// Node letters whose copy the turtle goes on from, with turns before
    /// the successor's first F and after its last (seven X's, one F).
    #[test]
    fn node_letters_that_continue() {
        let a = Angles::new(120.0, Some(3), 1.0);
        let g = grammar(
            "X",
            &[('X', Action::Nothing, "FFX+F-X"), ('F', Action::Draw, "FF")],
            5,
        );
        assert_eq!(
            finds(&g, &a).describe(),
            "axiom X; F -> FF; X -> FFX+F-X; derive 5"
        );
        let a = Angles::new(36.0, Some(10), 1.0);
        let g = grammar(
            "X",
            &[
                ('X', Action::Nothing, "X-X--X++X++X+FX--X"),
                ('F', Action::Draw, ""),
            ],
            4,
        );
        let found = finds(&g, &a);
        assert_eq!(found.rule_size(), g.rule_size(), "{}", found.describe());
        assert_eq!(found.letters.len(), 2, "{}", found.describe());
    }

    /// Two node letters: Hilbert's curve, and a pair that is not one
    /// letter's mirror.
    #[test]
    fn two_node_letters() {
        let a = Angles::new(90.0, Some(4), 1.0);
        let g = grammar(
            "X",
            &[
                ('X', Action::Nothing, "+YF-XFX-FY+"),
                ('Y', Action::Nothing, "-XF+YFY+FX-"),
                ('F', Action::Draw, ""),
            ],
            4,
        );
        let found = finds(&g, &a);
        assert_eq!(found.letters.len(), 3, "{}", found.describe());
        assert!(found.rule_size() <= g.rule_size(), "{}", found.describe());
        let a = Angles::new(60.0, Some(6), 1.0);
        let g = grammar(
            "X",
            &[
                ('X', Action::Nothing, "XF+YF-X"),
                ('Y', Action::Nothing, "F-YF++X"),
                ('F', Action::Draw, "FF"),
            ],
            4,
        );
        let found = finds(&g, &a);
        assert!(found.rule_size() <= g.rule_size(), "{}", found.describe());
        // Moore's curve: an axiom of four copies.
        let a = Angles::new(90.0, Some(4), 1.0);
        let g = grammar(
            "LFL+F+LFL",
            &[
                ('L', Action::Nothing, "-RF+LFL+FR-"),
                ('R', Action::Nothing, "+LF-RFR-FL+"),
                ('F', Action::Draw, ""),
            ],
            3,
        );
        let found = finds(&g, &a);
        assert_eq!(found.letters.len(), 3, "{}", found.describe());
        assert!(found.rule_size() <= g.rule_size(), "{}", found.describe());
    }

    /// Axioms of several copies of X and runs of F (`XF-XF-XF`), the turns
    /// between them less the turns a copy starts and ends with.
    #[test]
    fn node_axioms_of_copies() {
        let a = Angles::new(30.0, Some(12), 1.0);
        let g = grammar(
            "XF----XF----XF",
            &[
                ('X', Action::Nothing, "F-F++X+XX--X"),
                ('F', Action::Draw, "FF"),
            ],
            3,
        );
        assert_eq!(
            finds(&g, &a).describe(),
            "axiom XF----XF----XF; F -> FF; X -> F-F++X+XX--X; derive 3"
        );
        let a = Angles::new(90.0, Some(4), 1.0);
        let g = grammar(
            "XF+XF+XF+XF",
            &[
                ('X', Action::Nothing, "-F+XF+X-"),
                ('F', Action::Draw, "FF"),
            ],
            3,
        );
        // The same drawing by a smaller rule, its turns moved to the axiom.
        assert_eq!(
            finds(&g, &a).describe(),
            "axiom X+FX+FX+FX+F; F -> FF; X -> FX+FX-; derive 3"
        );
    }
}
