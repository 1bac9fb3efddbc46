//! Comments back onto the tree: every comment the lexer set aside becomes a
//! leading, trailing or end-of-block comment of a statement-like node.
//!
//! Owns: where comments live in the AST and the blank-line policy shared with
//! `fmt`. Rule: a comment before a node on its own line leads it; a comment after a
//! node on the node's last line trails it; a comment written inside a statement is
//! moved before that statement (its text is never lost); a comment before `}` stays
//! at the end of the block.

use crate::ast::{Block, File, Item, Node, SceneStmt};
use crate::lexer::Comment;

pub fn attach(file: &mut File, mut comments: Vec<Comment>, src: &str) {
    comments.sort_by_key(|c| c.span.start);
    attach_block(&mut file.items, comments, src);
}

/// Nodes that may hold blocks of their own.
pub trait Nested {
    /// Takes the comments written inside this node; returns those it cannot place.
    fn take_inner(&mut self, comments: Vec<Comment>, src: &str) -> Vec<Comment>;

    /// Whether a blank line always separates this node from its neighbours.
    fn wants_space(&self) -> bool {
        false
    }
}

impl Nested for Item {
    fn take_inner(&mut self, comments: Vec<Comment>, src: &str) -> Vec<Comment> {
        match self {
            Item::Lsystem(l) => attach_block(&mut l.body, comments, src),
            Item::Element(e) => attach_block(&mut e.props, comments, src),
            Item::Palette(p) => attach_block(&mut p.body, comments, src),
            Item::Scene(s) => attach_block(&mut s.body, comments, src),
            _ => return comments,
        }
        Vec::new()
    }

    fn wants_space(&self) -> bool {
        matches!(self, Item::Lsystem(_) | Item::Scene(_))
    }
}

impl Nested for SceneStmt {
    fn take_inner(&mut self, comments: Vec<Comment>, src: &str) -> Vec<Comment> {
        match self {
            SceneStmt::Guide(g) => attach_block(&mut g.body, comments, src),
            SceneStmt::Link(l) => attach_block(&mut l.body, comments, src),
            SceneStmt::Error => return comments,
        }
        Vec::new()
    }

    fn wants_space(&self) -> bool {
        matches!(self, SceneStmt::Guide(_))
    }
}

macro_rules! leaf {
    ($($t:ty),*) => {$(
        impl Nested for $t {
            fn take_inner(&mut self, comments: Vec<Comment>, _: &str) -> Vec<Comment> {
                comments
            }
        }
    )*};
}
leaf!(
    crate::ast::Stmt,
    crate::ast::Prop,
    crate::ast::PaletteEntry,
    crate::ast::GuideStmt,
    crate::ast::LinkStmt
);

/// Whether the printer puts a blank line between `prev` and `next`, given what the
/// source had. The parser stores the answer so that `parse(fmt(x)) == parse(x)`.
pub fn blank_between<T: Nested>(prev: &T, next: &T, in_source: bool) -> bool {
    in_source || prev.wants_space() || next.wants_space()
}

fn attach_block<T: Nested>(block: &mut Block<T>, comments: Vec<Comment>, src: &str) {
    let stmts = &mut block.stmts;
    let mut inner: Vec<Vec<Comment>> = vec![Vec::new(); stmts.len()];
    for c in comments {
        let idx = stmts.partition_point(|n| n.span.end <= c.span.start);
        if idx < stmts.len() && stmts[idx].span.start <= c.span.start {
            inner[idx].push(c);
            continue;
        }
        if idx > 0 {
            let prev = &mut stmts[idx - 1];
            let same_line = !src
                .get(prev.span.end as usize..c.span.start as usize)
                .unwrap_or("\n")
                .contains('\n');
            if same_line && prev.trivia.trailing.is_none() {
                prev.trivia.trailing = Some(c);
                continue;
            }
        }
        match stmts.get_mut(idx) {
            Some(next) => next.trivia.leading.push(c),
            None => block.end_comments.push(c),
        }
    }
    // Every nested block is visited, comments or not, so its blank lines are kept.
    for (node, comments) in stmts.iter_mut().zip(inner) {
        let rest = node.node.take_inner(comments, src);
        node.trivia.leading.extend(rest);
    }
    set_blank_lines(stmts, src);
}

fn set_blank_lines<T: Nested>(stmts: &mut [Node<T>], src: &str) {
    for node in stmts.iter_mut() {
        // A blank line after the comments written before the node.
        let last = node
            .trivia
            .leading
            .iter()
            .filter(|c| c.span.end <= node.span.start)
            .map(|c| c.span.end)
            .max();
        node.trivia.blank_after_leading = last.is_some_and(|end| {
            src.get(end as usize..node.span.start as usize)
                .is_some_and(|gap| gap.matches('\n').count() >= 2)
        });
    }
    for i in 0..stmts.len() {
        if i == 0 {
            stmts[i].trivia.blank_before = false;
            continue;
        }
        let prev = &stmts[i - 1];
        let gap_start = prev
            .trivia
            .trailing
            .as_ref()
            .map_or(prev.span.end, |c| c.span.end.max(prev.span.end));
        let next = &stmts[i];
        let gap_end = next
            .trivia
            .leading
            .iter()
            .map(|c| c.span.start)
            .chain(std::iter::once(next.span.start))
            .min()
            .unwrap_or(next.span.start)
            .max(gap_start);
        let gap = src.get(gap_start as usize..gap_end as usize).unwrap_or("");
        let in_source = gap.matches('\n').count() >= 2;
        let blank = blank_between(&prev.node, &next.node, in_source);
        stmts[i].trivia.blank_before = blank;
    }
}
