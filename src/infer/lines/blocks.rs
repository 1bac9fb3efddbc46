//! Where a curve drawn by a one-letter D0L system starts and how deep it is
//! derived, read from the sequence of its turns alone.
//!
//! A curve derived n times by `F -> w` (m letters in w) from an axiom of a
//! letters has a·mⁿ steps, and cut into blocks of m steps from its start,
//! every block turns inside exactly as w does: the turns at the same place
//! in every block are equal. The turns between blocks are the curve one
//! level less deep (each shifted by the same amount, w's leading and
//! trailing turns), which is cut the same way, down to the axiom. A closed
//! curve whose steps came in any order has lost its start; this test finds
//! the few steps it could start at (a phase of every level) and the depth,
//! in time linear in its length, so that the grammar search follows the
//! curve from there instead of trying every step.
//!
//! Owns: the block test. Must not search grammars (`synth` does) or read
//! the drawing.

/// A place a curve may start and the depth its blocks show.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Start {
    /// Index of the first step in the curve's steps.
    pub at: usize,
    /// Levels of blocks above the axiom.
    pub depth: u32,
    /// Letters in the axiom.
    pub axiom: usize,
    /// Steps in a block (letters in the successor).
    pub block: usize,
}

/// How many starts are returned at most.
const MAX_STARTS: usize = 64;

/// Where a curve with these turns may start, deepest first. `turns[i]` is
/// the turn (in multiples of δ₀) before step `i`; for a closed curve
/// `turns[0]` is the turn from the last step to the first, and every
/// rotation is a possible start. An open curve starts at its first step
/// (read it backwards for the other end). Blocks have `2..=max_block`
/// steps; the axiom has at most `max_axiom` letters.
pub fn starts(turns: &[i32], closed: bool, max_block: usize, max_axiom: usize) -> Vec<Start> {
    let mut found: Vec<Start> = Vec::new();
    let index: Vec<usize> = (0..turns.len()).collect();
    for m in 2..=max_block.min(turns.len() / 2) {
        let mut level = Level {
            m,
            closed,
            max_axiom,
            found: &mut found,
        };
        level.descend(turns, &index, 0);
    }
    // Deepest first, then the smallest axiom, each start once.
    found.sort_by_key(|s| (std::cmp::Reverse(s.depth), s.axiom, s.at));
    let mut seen = std::collections::HashSet::new();
    found.retain(|s| seen.insert(s.at));
    found.truncate(MAX_STARTS);
    found
}

struct Level<'a> {
    m: usize,
    closed: bool,
    max_axiom: usize,
    found: &'a mut Vec<Start>,
}

impl Level<'_> {
    /// Cuts `turns` (the curve `depth` levels up, `index` its steps' indices
    /// in the curve) into blocks of m at every phase that fits, and goes up.
    fn descend(&mut self, turns: &[i32], index: &[usize], depth: u32) {
        if self.found.len() >= 4 * MAX_STARTS {
            return;
        }
        let n = turns.len();
        if depth >= 1 && n <= self.max_axiom {
            // The axiom: a closed one may start at any of its letters.
            let ats: Vec<usize> = if self.closed {
                index.to_vec()
            } else {
                vec![index[0]]
            };
            let (axiom, block) = (n, self.m);
            self.found.extend(ats.into_iter().map(|at| Start {
                at,
                depth,
                axiom,
                block,
            }));
        }
        let m = self.m;
        if n < m || !n.is_multiple_of(m) {
            return;
        }
        let phases = if self.closed { m } else { 1 };
        for p in 0..phases {
            if !blocks_agree(turns, p, m) {
                continue;
            }
            let up: Vec<i32> = (0..n / m).map(|j| turns[(p + j * m) % n]).collect();
            let at: Vec<usize> = (0..n / m).map(|j| index[(p + j * m) % n]).collect();
            self.descend(&up, &at, depth + 1);
        }
    }
}

/// Whether the blocks of `m` turns from `p` turn alike inside.
fn blocks_agree(turns: &[i32], p: usize, m: usize) -> bool {
    let n = turns.len();
    (1..m).all(|i| {
        let first = turns[(p + i) % n];
        (1..n / m).all(|j| turns[(p + j * m + i) % n] == first)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The turns of `F -> w` derived `n` times from `axiom` (`+`/`-` turn
    /// by one), before each step (the first one's closing turn, when the
    /// curve closes, is `close`).
    fn turns(axiom: &str, w: &str, n: u32, close: i32) -> Vec<i32> {
        let mut out = vec![close];
        out.extend(crate::infer::lines::levels::tests::turns(
            axiom,
            &[('F', w)],
            n,
        ));
        out
    }

    #[test]
    fn a_closed_curve_rotated_is_found_at_its_start() {
        // The quadratic Koch island, rotated by 37 steps.
        let t = turns("F-F-F-F", "F-F+F+FF-F-F+F", 2, -1);
        assert_eq!(t.len(), 256);
        let mut r = t.clone();
        r.rotate_left(37);
        let s = starts(&r, true, 12, 12);
        // Its start is 256 − 37 = 219; every start at depth 2 is a whole
        // number of blocks of 8 from it (the axiom's four-fold turn makes
        // every block at the top alike, so the search sorts those out).
        assert!(!s.is_empty());
        assert_eq!((s[0].depth, s[0].axiom, s[0].block), (2, 4, 8));
        assert!(s.iter().all(|s| (s.at + 37) % 8 == 0));
        assert!(s.iter().any(|s| s.at == 219));
    }

    #[test]
    fn an_open_curve_gives_its_depth() {
        let t = turns("F", "F-F+F", 5, 0);
        let s = starts(&t, false, 12, 12);
        assert_eq!(s.first().map(|s| (s.at, s.depth, s.block)), Some((0, 5, 3)));
    }

    #[test]
    fn turns_without_blocks_give_no_start() {
        let t: Vec<i32> = (0..96u64)
            .map(|i| ((i * i * 7919 + i * 31 + 3) % 5) as i32 - 2)
            .collect();
        assert!(starts(&t, true, 12, 12).is_empty());
    }
}
