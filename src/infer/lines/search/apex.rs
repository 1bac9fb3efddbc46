//! Plants whose apices draw (the binary tree `G -> F[+G]-G`, `F -> FF`):
//! node rewriting where the rewritten letter draws a step when it is not
//! rewritten any more, at the tip of every branch.
//!
//! Such a drawing less its tips (every step nothing continues from) is the
//! drawing of the same grammar with a letter X that draws nothing, when every
//! copy of the letter ends its branch (nothing but turns follows it before
//! `]` or the end of its successor). So the node-rewriting search runs on
//! the drawing less its tips, and each grammar it proposes whose X ends its
//! branches is proposed with X drawing (named G), once it matches the whole
//! drawing.

use super::{Limits, Proposals, Sink, node_rewriting};
use crate::infer::lines::grammar::{Action, Grammar, Outcome, Sym, matches};
use crate::infer::lines::turtle::{Angles, Kind, Node, ROOT, Tree};

/// The grammars with drawing apices proposed for `tree`.
pub(super) fn apex_plants(
    tree: &Tree,
    angles: &Angles,
    limits: &Limits,
    sink: &mut Sink<'_>,
    out: &mut Proposals,
) {
    let Some(inner) = without_tips(tree) else {
        return;
    };
    let mut found = Proposals::default();
    let mut keep = |g: Grammar, found: &mut Proposals| found.grammars.push(g);
    node_rewriting(&inner, angles, limits, &mut keep, &mut found);
    out.timed_out |= found.timed_out;
    let work = 64 * tree.nodes.len() as u64 + 100_000;
    for g in found.grammars {
        if limits.late() {
            out.timed_out = true;
            return;
        }
        let Some(apex) = drawing_apex(&g) else {
            continue;
        };
        if matches(&apex, tree, angles, work, limits.deadline) == Outcome::Same {
            sink(apex, out);
        }
    }
}

/// `tree` less the steps nothing continues from, when it branches, draws
/// every step and keeps at least two; `None` otherwise.
fn without_tips(tree: &Tree) -> Option<Tree> {
    let nodes = &tree.nodes;
    if nodes.iter().any(|n| n.kind != Kind::Draw) {
        return None;
    }
    let mut kids = vec![0u32; nodes.len()];
    for n in nodes {
        if n.parent != ROOT {
            *kids.get_mut(n.parent as usize)? += 1;
        }
    }
    if !kids.iter().any(|&k| k >= 2) {
        return None;
    }
    // New index of each kept node.
    let mut index = vec![ROOT; nodes.len()];
    let mut kept: Vec<Node> = Vec::new();
    for (i, n) in nodes.iter().enumerate() {
        if kids[i] == 0 {
            continue;
        }
        index[i] = kept.len() as u32;
        let parent = if n.parent == ROOT {
            ROOT
        } else {
            index[n.parent as usize]
        };
        kept.push(Node { parent, ..*n });
    }
    (kept.len() >= 2).then_some(Tree::of(kept))
}

/// `g` (F, and X drawing nothing) with X drawing a step, named G, when
/// every X of its successor and axiom ends its branch; `None` otherwise.
fn drawing_apex(g: &Grammar) -> Option<Grammar> {
    let x = g
        .letters
        .iter()
        .position(|l| l.action == Action::Nothing && l.rule.is_some())?;
    if g.letters
        .iter()
        .filter(|l| l.action == Action::Nothing)
        .count()
        != 1
    {
        return None;
    }
    let ends_branches = |w: &[Sym]| {
        w.iter().enumerate().all(|(i, &s)| {
            s != Sym::Letter(x as u8)
                || w[i + 1..]
                    .iter()
                    .find(|s| !matches!(s, Sym::Plus | Sym::Minus))
                    .is_none_or(|&s| s == Sym::Pop)
        })
    };
    let rule = g.letters[x].rule.as_deref()?;
    if !ends_branches(rule) || !ends_branches(&g.axiom) || halves(g, x, rule) {
        return None;
    }
    let mut out = g.clone();
    out.letters[x].action = Action::Draw;
    out.letters[x].name = 'G';
    Some(out)
}

/// Whether X's successor `w` less its X's draws k steps on one line, as
/// many as F's successor has: then X drawing nothing one level deeper at
/// half the step draws the same (ABOP's `X -> F[+X]F[-X]+X`, whose last
/// level's `F[+X]F[-X]+X` draws `FF`), and that is the grammar written.
fn halves(g: &Grammar, x: usize, w: &[Sym]) -> bool {
    let k = g
        .letters
        .iter()
        .find(|l| l.action == Action::Draw && l.rule.is_some() && !std::ptr::eq(*l, &g.letters[x]))
        .and_then(|l| l.rule.as_ref())
        .map_or(1, Vec::len);
    let (mut depth, mut heading, mut steps) = (0i32, 0i32, 0usize);
    let mut first: Option<i32> = None;
    for &s in w {
        match s {
            Sym::Push => depth += 1,
            Sym::Pop => depth -= 1,
            Sym::Plus if depth == 0 => heading += 1,
            Sym::Minus if depth == 0 => heading -= 1,
            Sym::Letter(l) if l as usize != x => {
                if depth > 0 || first.is_some_and(|h| h != heading) {
                    return false;
                }
                first = Some(heading);
                steps += 1;
            }
            _ => {}
        }
    }
    steps == k
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::infer::lines::grammar::Letter as L;

    #[test]
    fn tips_are_cut_and_apices_draw() {
        use Sym::*;
        // F[+X]-X with F -> FF, X ending both its branches.
        let (f, x) = (Letter(0), Letter(1));
        let g = Grammar {
            letters: vec![
                L {
                    name: 'F',
                    action: Action::Draw,
                    rule: Some(vec![f, f]),
                },
                L {
                    name: 'X',
                    action: Action::Nothing,
                    rule: Some(vec![f, Push, Plus, x, Pop, Minus, x]),
                },
            ],
            axiom: vec![x],
            depth: 3,
        };
        let apex = drawing_apex(&g).expect("X ends its branches");
        assert_eq!(apex.describe(), "axiom G; F -> FF; G -> F[+G]-G; derive 3");
        // ABOP's plant d less its X's draws FF: X one level deeper at half
        // the step draws the same, and is what is written.
        let mut d = g.clone();
        d.letters[1].rule = Some(vec![f, Push, Plus, x, Pop, f, Push, Minus, x, Pop, Plus, x]);
        assert!(drawing_apex(&d).is_none());
        let mut inner = g.clone();
        inner.letters[1].rule = Some(vec![f, Push, Plus, x, Pop, x, f]);
        assert!(drawing_apex(&inner).is_none());
        // A fork of two steps and a step before it: the tips go.
        let node = |parent, turn| Node {
            parent,
            turn,
            kind: Kind::Draw,
        };
        let t = Tree::of(vec![node(ROOT, 0), node(0, 0), node(1, 1), node(1, -1)]);
        assert_eq!(
            without_tips(&t),
            Some(Tree::of(vec![node(ROOT, 0), node(0, 0)]))
        );
    }
}
