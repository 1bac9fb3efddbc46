//! Productions of a branching structure, after Hegde & Rathi (§4.3): the initial
//! set P, pre-reduction, the reduction table R and the reduced recursive P.
//!
//! Owns: the numbering of branches (the root is `r`; internal branches get ids
//! in level order, left to right; branches without children are the terminal
//! `t`), equivalence of productions, similarity of sub-structures, and the
//! choice of representatives. Works on the shape of a tree only (children lists);
//! must not know geometry, SVG or the language.
//!
//! Reading of the paper where it leaves room, fixed by its Figure 2 tables:
//! - pre-reduction keeps the *last* production (in P order) of each class of
//!   equivalent ones and repeats until no two productions are equal;
//! - two branches are similar when they have as many children and their
//!   children are pairwise similar, stopping (similar) as soon as either side is
//!   a terminal;
//! - R(x) holds the branches similar to x on the *nearest lower level* that has
//!   any (levels count from the root, 0);
//! - reduction replaces x by the leftmost entry of R(x), transitively; a
//!   terminal left in a surviving production becomes `r`; productions no longer
//!   reachable from `r` are dropped.

use std::collections::HashMap;
use std::fmt;

/// One entry of a successor: an internal branch id (0 is `r`) or a terminal.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Child {
    Id(usize),
    T,
}

impl fmt::Display for Child {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Child::Id(0) => write!(f, "r"),
            Child::Id(k) => write!(f, "{k}"),
            Child::T => write!(f, "t"),
        }
    }
}

/// `id -> {succ}`: a parent branch and its children, left to right.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Production {
    pub id: usize,
    pub succ: Vec<Child>,
}

impl fmt::Display for Production {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} -> {{", Child::Id(self.id))?;
        for (k, c) in self.succ.iter().enumerate() {
            if k > 0 {
                write!(f, ", ")?;
            }
            write!(f, "{c}")?;
        }
        write!(f, "}}")
    }
}

/// Everything the extraction finds, table by table.
#[derive(Clone, Debug, Default)]
pub struct Analysis {
    /// For each branch (tree node), its id, or `None` for a terminal.
    pub id_of: Vec<Option<usize>>,
    /// For each id, the branch it names.
    pub branch_of: Vec<usize>,
    /// For each id, its level (the root is 0).
    pub level: Vec<usize>,
    /// P as scanned: level order, left to right.
    pub initial: Vec<Production>,
    /// P after pre-reduction.
    pub pre_reduced: Vec<Production>,
    /// The reduction table R: an id and the similar ids on the nearest lower level.
    pub similar: Vec<(usize, Vec<usize>)>,
    /// P after reduction: recursive, starting at `r`.
    pub reduced: Vec<Production>,
}

impl Analysis {
    /// Runs the whole extraction on a tree given as children lists (node 0 is
    /// the root; each list ordered left to right). Nodes unreachable from the
    /// root are ignored.
    pub fn new(children: &[Vec<usize>]) -> Analysis {
        let mut a = Analysis {
            id_of: vec![None; children.len()],
            ..Analysis::default()
        };
        if children.is_empty() || children[0].is_empty() {
            return a;
        }
        // Level order, left to right; internal branches get ids as they come.
        let mut queue = std::collections::VecDeque::from([(0usize, 0usize)]);
        let mut seen = vec![false; children.len()];
        seen[0] = true;
        while let Some((b, lvl)) = queue.pop_front() {
            if !children[b].is_empty() {
                a.id_of[b] = Some(a.branch_of.len());
                a.branch_of.push(b);
                a.level.push(lvl);
            }
            for &c in &children[b] {
                if c < children.len() && !seen[c] {
                    seen[c] = true;
                    queue.push_back((c, lvl + 1));
                }
            }
        }
        a.initial = a
            .branch_of
            .iter()
            .enumerate()
            .map(|(id, &b)| Production {
                id,
                succ: children[b]
                    .iter()
                    .map(|&c| {
                        a.id_of
                            .get(c)
                            .copied()
                            .flatten()
                            .map_or(Child::T, Child::Id)
                    })
                    .collect(),
            })
            .collect();
        a.pre_reduced = pre_reduce(&a.initial);
        a.similar = reduction_table(&a.pre_reduced, &a.level);
        a.reduced = reduce(&a.pre_reduced, &a.similar, a.branch_of.len());
        a
    }
}

/// Merges equivalent productions (equal successors) into the last of each class,
/// renaming in all successors, until no two are equal.
pub fn pre_reduce(initial: &[Production]) -> Vec<Production> {
    let mut prods = initial.to_vec();
    loop {
        let mut last: HashMap<&[Child], usize> = HashMap::new();
        for p in &prods {
            last.insert(&p.succ, p.id);
        }
        let rename: HashMap<usize, usize> = prods
            .iter()
            .filter_map(|p| {
                let keep = last.get(p.succ.as_slice()).copied()?;
                (keep != p.id).then_some((p.id, keep))
            })
            .collect();
        if rename.is_empty() {
            return prods;
        }
        prods.retain(|p| !rename.contains_key(&p.id));
        for p in &mut prods {
            for c in &mut p.succ {
                if let Child::Id(k) = c
                    && let Some(&to) = rename.get(k)
                {
                    *c = Child::Id(to);
                }
            }
        }
    }
}

/// Whether two branches have the same sequel-context until either reaches a
/// terminal. Iterative, so that deep sketches cannot overflow the stack.
fn similar(a: usize, b: usize, succ: &HashMap<usize, &[Child]>) -> bool {
    let mut stack = vec![(a, b)];
    while let Some((x, y)) = stack.pop() {
        if x == y {
            continue;
        }
        let (Some(sx), Some(sy)) = (succ.get(&x), succ.get(&y)) else {
            continue;
        };
        if sx.len() != sy.len() {
            return false;
        }
        for (p, q) in sx.iter().zip(sy.iter()) {
            if let (Child::Id(p), Child::Id(q)) = (p, q) {
                stack.push((*p, *q));
            }
        }
    }
    true
}

/// The table R: for each production but the root's (in P order), the similar
/// ids on the nearest lower level that has any, left to right.
pub fn reduction_table(prods: &[Production], level: &[usize]) -> Vec<(usize, Vec<usize>)> {
    let succ: HashMap<usize, &[Child]> = prods.iter().map(|p| (p.id, p.succ.as_slice())).collect();
    let mut by_level: Vec<Vec<usize>> = Vec::new();
    for p in prods {
        let lvl = level.get(p.id).copied().unwrap_or(0);
        if by_level.len() <= lvl {
            by_level.resize(lvl + 1, Vec::new());
        }
        by_level[lvl].push(p.id);
    }
    let mut table = Vec::new();
    for p in prods.iter().filter(|p| p.id != 0) {
        let own = level.get(p.id).copied().unwrap_or(0);
        for ids in by_level.iter().take(own).rev() {
            let found: Vec<usize> = ids
                .iter()
                .copied()
                .filter(|&q| similar(p.id, q, &succ))
                .collect();
            if !found.is_empty() {
                table.push((p.id, found));
                break;
            }
        }
    }
    table
}

/// Reduces P by R: each id in R is replaced by its leftmost entry (followed
/// transitively; entries are always on lower levels, so this ends), terminals by
/// `r`. Returns the productions reachable from `r`, in P order.
pub fn reduce(prods: &[Production], table: &[(usize, Vec<usize>)], ids: usize) -> Vec<Production> {
    let direct: HashMap<usize, usize> = table
        .iter()
        .filter_map(|(x, r)| r.first().map(|&y| (*x, y)))
        .collect();
    let resolve = |mut x: usize| {
        // Bounded walk: each step goes to a lower level.
        for _ in 0..=ids {
            match direct.get(&x) {
                Some(&y) => x = y,
                None => break,
            }
        }
        x
    };
    let mapped: Vec<Production> = prods
        .iter()
        .filter(|p| !direct.contains_key(&p.id))
        .map(|p| Production {
            id: p.id,
            succ: p
                .succ
                .iter()
                .map(|c| match c {
                    Child::Id(k) => Child::Id(resolve(*k)),
                    Child::T => Child::Id(0),
                })
                .collect(),
        })
        .collect();
    // Keep what `r` reaches.
    let by_id: HashMap<usize, &Production> = mapped.iter().map(|p| (p.id, p)).collect();
    let mut reach = vec![false; ids];
    let mut stack = vec![0usize];
    while let Some(x) = stack.pop() {
        if x >= ids || reach[x] {
            continue;
        }
        reach[x] = true;
        if let Some(p) = by_id.get(&x) {
            stack.extend(p.succ.iter().filter_map(|c| match c {
                Child::Id(k) => Some(*k),
                Child::T => None,
            }));
        }
    }
    mapped.into_iter().filter(|p| reach[p.id]).collect()
}

/// Formats a table as one production per line.
pub fn show(prods: &[Production]) -> String {
    prods.iter().map(|p| format!("{p}\n")).collect()
}

/// Formats R as `x: {a, b}` lines.
pub fn show_table(table: &[(usize, Vec<usize>)]) -> String {
    table
        .iter()
        .map(|(x, r)| {
            let r: Vec<String> = r.iter().map(|&k| Child::Id(k).to_string()).collect();
            format!("{}: {{{}}}\n", Child::Id(*x), r.join(", "))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The branching structure of the paper's Figure 2, rebuilt from its text:
    /// r's children are 1 and 2; 1's are 3 and 4; 2's are 5, 6, 7; 3's are 8
    /// and 9; 4 has two terminals; 5's are 10 and 11; 6's are 12, 13, 14;
    /// 7, 8, 10, 11, 12 and 14 have two terminals; 9 and 13 have three.
    fn figure_2() -> Vec<Vec<usize>> {
        // Nodes 0..=14 are r and the internal branches 1..=14; terminals follow.
        let mut children: Vec<Vec<usize>> = vec![
            vec![1, 2],
            vec![3, 4],
            vec![5, 6, 7],
            vec![8, 9],
            vec![],
            vec![10, 11],
            vec![12, 13, 14],
            vec![],
            vec![],
            vec![],
            vec![],
            vec![],
            vec![],
            vec![],
            vec![],
        ];
        let terminals = [
            (4, 2),
            (7, 2),
            (8, 2),
            (9, 3),
            (10, 2),
            (11, 2),
            (12, 2),
            (13, 3),
            (14, 2),
        ];
        for (parent, n) in terminals {
            for _ in 0..n {
                let t = children.len();
                children.push(Vec::new());
                children[parent].push(t);
            }
        }
        children
    }

    #[test]
    fn figure_2_initial_productions() {
        let a = Analysis::new(&figure_2());
        // Ids follow the figure's numbers.
        assert_eq!(a.branch_of, (0..=14).collect::<Vec<_>>());
        assert_eq!(
            show(&a.initial),
            "r -> {1, 2}\n1 -> {3, 4}\n2 -> {5, 6, 7}\n3 -> {8, 9}\n4 -> {t, t}\n\
             5 -> {10, 11}\n6 -> {12, 13, 14}\n7 -> {t, t}\n8 -> {t, t}\n9 -> {t, t, t}\n\
             10 -> {t, t}\n11 -> {t, t}\n12 -> {t, t}\n13 -> {t, t, t}\n14 -> {t, t}\n"
        );
    }

    #[test]
    fn figure_2_pre_reduction() {
        let a = Analysis::new(&figure_2());
        assert_eq!(
            show(&a.pre_reduced),
            "r -> {1, 2}\n1 -> {3, 14}\n2 -> {5, 6, 14}\n3 -> {14, 13}\n5 -> {14, 14}\n\
             6 -> {14, 13, 14}\n13 -> {t, t, t}\n14 -> {t, t}\n"
        );
    }

    #[test]
    fn figure_2_reduction_table() {
        let a = Analysis::new(&figure_2());
        assert_eq!(
            show_table(&a.similar),
            "3: {r}\n5: {1}\n6: {2}\n13: {6}\n14: {3, 5}\n"
        );
    }

    #[test]
    fn figure_2_after_reduction() {
        let a = Analysis::new(&figure_2());
        assert_eq!(
            show(&a.reduced),
            "r -> {1, 2}\n1 -> {r, r}\n2 -> {1, 2, r}\n"
        );
    }

    #[test]
    fn balanced_binary_tree_becomes_one_rule() {
        // r(1(t, t), 2(t, t))
        let children = vec![
            vec![1, 2],
            vec![3, 4],
            vec![5, 6],
            vec![],
            vec![],
            vec![],
            vec![],
        ];
        let a = Analysis::new(&children);
        assert_eq!(show(&a.pre_reduced), "r -> {2, 2}\n2 -> {t, t}\n");
        assert_eq!(show_table(&a.similar), "2: {r}\n");
        assert_eq!(show(&a.reduced), "r -> {r, r}\n");
    }

    #[test]
    fn a_single_stroke_has_no_productions() {
        let a = Analysis::new(&[vec![]]);
        assert!(a.initial.is_empty() && a.reduced.is_empty());
        assert_eq!(a.id_of, vec![None]);
    }

    #[test]
    fn a_root_with_terminals_only_recurses() {
        let a = Analysis::new(&[vec![1, 2, 3], vec![], vec![], vec![]]);
        assert_eq!(show(&a.initial), "r -> {t, t, t}\n");
        assert_eq!(show(&a.reduced), "r -> {r, r, r}\n");
    }
}
