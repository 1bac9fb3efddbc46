//! Moves in several directions (`F -> F-f++F-f`, `f -> ff`): one drawing
//! letter whose successor ends on its own line k steps on, heading as it
//! started, and `f -> f^k`, so that every level is the one before scaled
//! by k, each step replaced by the successor's drawn steps.
//!
//! Such a drawing leaves gaps of several legs between its strokes (`-f` at
//! the end of one successor, `-ff++` of the one around it), which the
//! reading keeps as jumps (`Kind::Jump`): where the next stroke starts, not
//! the legs, which level n cannot tell apart (any legs that land there draw
//! every level alike, all moves scaling together). So the successor is read
//! off the drawing's strokes: the first b of them are one successor's steps
//! (its inner gaps as they are); the first step of each of the next blocks
//! of b is where the successor puts its j-th step one level up, scaled by
//! k, plus the successor's lead gap turned as that step is. Solving for the
//! lead gap, for each k and each lead turn, gives the whole successor (its
//! last gap closes it on its line), the axiom from the top blocks, and the
//! gaps as the fewest moves that land there.
//!
//! Owns: proposing such grammars, each matched before it is proposed.

use super::{Limits, Proposals, Sink};
use crate::infer::lines::grammar::{Action, Grammar, Letter, Outcome, Sym, first_step, matches};
use crate::infer::lines::turtle::{Angles, Kind, ROOT, Tree};
use glam::{DMat2, DVec2};

/// The largest k of `f -> f^k`.
const MAX_SCALE: u32 = 8;
/// The most moves in one gap.
const MAX_LEGS: usize = 10;
/// How far (in steps) a position may be from where a candidate puts it.
const NEAR: f64 = 0.3;
/// The most partial gaps looked at while finding one gap's legs.
const LEG_WORK: usize = 20_000;
/// The most candidates matched against the drawing.
const MAX_MATCHED: usize = 100;

/// Headings as whole turns of δ (heading 0 is +y, turns anticlockwise).
struct Lattice {
    m: i32,
    delta: f64,
}

impl Lattice {
    fn rot(&self, h: i32, v: DVec2) -> DVec2 {
        DMat2::from_angle((self.delta * f64::from(h)).to_radians()) * v
    }

    fn unit(&self, h: i32) -> DVec2 {
        self.rot(h, DVec2::Y)
    }

    /// A turn of `k` as the fewest symbols.
    fn turn(&self, k: i32) -> Vec<Sym> {
        let mut k = k.rem_euclid(self.m);
        if 2 * k > self.m {
            k -= self.m;
        }
        let sym = if k > 0 { Sym::Plus } else { Sym::Minus };
        vec![sym; k.unsigned_abs() as usize]
    }

    /// The fewest moves (headings from 0) that add up to `d`, within
    /// `NEAR`; `None` beyond `MAX_LEGS` moves or `LEG_WORK`.
    fn legs(&self, d: DVec2) -> Option<Vec<i32>> {
        if d.length() <= NEAR {
            return Some(Vec::new());
        }
        let units: Vec<DVec2> = (0..self.m).map(|h| self.unit(h)).collect();
        let mut work = 0usize;
        let least = (d.length() - NEAR).ceil().max(1.0) as usize;
        for total in least..=MAX_LEGS {
            let mut legs = Vec::with_capacity(total);
            if self.fill(d, total, 0, &units, &mut legs, &mut work) {
                return Some(legs);
            }
            if work > LEG_WORK {
                return None;
            }
        }
        None
    }

    /// Depth-first: `left` more moves, headings from `from` up (the order
    /// of moves does not change where they land).
    fn fill(
        &self,
        d: DVec2,
        left: usize,
        from: i32,
        units: &[DVec2],
        legs: &mut Vec<i32>,
        work: &mut usize,
    ) -> bool {
        *work += 1;
        if left == 0 {
            return d.length() <= NEAR;
        }
        if d.length() > left as f64 + NEAR || *work > LEG_WORK {
            return false;
        }
        for h in from..self.m {
            legs.push(h);
            if self.fill(d - units[h as usize], left - 1, h, units, legs, work) {
                return true;
            }
            legs.pop();
        }
        false
    }

    /// A gap as symbols: moves that land at `d` (from heading 0), then the
    /// turn to heading `t`.
    fn gap(&self, d: DVec2, t: i32, f: u8) -> Option<Vec<Sym>> {
        let mut out = Vec::new();
        let mut at = 0;
        for h in self.legs(d)? {
            out.extend(self.turn(h - at));
            out.push(Sym::Letter(f));
            at = h;
        }
        out.extend(self.turn(t - at));
        Some(out)
    }
}

/// Each drawn step's start and heading, from the first step's (the origin,
/// heading 0); `None` for a tree this does not read.
fn strokes(tree: &Tree, lat: &Lattice) -> Option<Vec<(DVec2, i32)>> {
    let n = tree.nodes.len();
    let mut heading = vec![0i32; n];
    let mut end = vec![DVec2::ZERO; n];
    let mut out = Vec::new();
    for (i, node) in tree.nodes.iter().enumerate() {
        let (start, from) = if node.parent == ROOT {
            (DVec2::ZERO, 0)
        } else {
            let p = node.parent as usize;
            (*end.get(p)?, heading[p])
        };
        let h = from + node.turn;
        heading[i] = h;
        end[i] = match node.kind {
            Kind::Draw | Kind::Move => start + lat.unit(h),
            Kind::Jump => {
                let j = *tree.jumps.get(&(i as u32))?;
                start + lat.unit(h) * j.x + lat.unit(h).perp() * j.y
            }
        };
        if node.kind == Kind::Draw {
            out.push((start, h));
        }
    }
    Some(out)
}

/// What the candidates of one drawing share.
struct Search<'a> {
    tree: &'a Tree,
    angles: &'a Angles,
    limits: &'a Limits,
    lat: Lattice,
    strokes: Vec<(DVec2, i32)>,
    matched: usize,
}

/// The grammars with moves in several directions proposed for `tree`.
pub(super) fn moves(
    tree: &Tree,
    angles: &Angles,
    limits: &Limits,
    sink: &mut Sink<'_>,
    out: &mut Proposals,
) {
    let Some(m) = angles.period.filter(|&m| m > 0) else {
        return;
    };
    if tree.nodes.iter().all(|n| n.kind == Kind::Draw) {
        return;
    }
    let lat = Lattice {
        m,
        delta: angles.delta,
    };
    let Some(strokes) = strokes(tree, &lat) else {
        return;
    };
    let mut s = Search {
        tree,
        angles,
        limits,
        lat,
        strokes,
        matched: 0,
    };
    let n = s.strokes.len();
    for b in 2..=limits.max_block.min(n) {
        // Two levels at least: the blocks of one successor one level up.
        let (mut size, mut depth) = (b * b, 2u32);
        while size <= n {
            if n.is_multiple_of(size) && n / size <= limits.max_axiom {
                if limits.late() || s.matched >= MAX_MATCHED {
                    out.timed_out |= limits.late();
                    return;
                }
                s.blocks(b, size, depth, sink, out);
            }
            let Some(next) = size.checked_mul(b) else {
                break;
            };
            size = next;
            depth += 1;
        }
    }
}

impl Search<'_> {
    /// Successors of `b` steps drawn `depth` levels down, each axiom
    /// letter drawing `size` steps.
    fn blocks(
        &mut self,
        b: usize,
        size: usize,
        depth: u32,
        sink: &mut Sink<'_>,
        out: &mut Proposals,
    ) {
        let lat = &self.lat;
        let st = &self.strokes;
        let (p, h): (Vec<DVec2>, Vec<i32>) = st[..b].iter().copied().unzip();
        // One level up the successor's steps turn as its own steps do.
        if (1..b).any(|j| (st[j * b].1 - h[j]).rem_euclid(lat.m) != 0) {
            return;
        }
        // The inner gaps, as drawn.
        let mut inner = Vec::with_capacity(b);
        for j in 1..b {
            let end = p[j - 1] + lat.unit(h[j - 1]);
            let d = lat.rot(-h[j - 1], p[j] - end);
            let Some(gap) = lat.gap(d, h[j] - h[j - 1], 1) else {
                return;
            };
            inner.push(gap);
        }
        for k in 2..=MAX_SCALE {
            for lead in 0..lat.m {
                for v in self.leads(b, k, lead) {
                    let Some(g) = self.grammar(&inner, (b, size, depth), k, lead, v) else {
                        continue;
                    };
                    self.matched += 1;
                    let work = 64 * self.tree.nodes.len() as u64 + 100_000;
                    if matches(&g, self.tree, self.angles, work, self.limits.deadline)
                        == Outcome::Same
                    {
                        sink(g, out);
                    }
                    if self.matched >= MAX_MATCHED || self.limits.late() {
                        return;
                    }
                }
            }
        }
    }

    /// The lead gaps (where the successor's first step starts, in the
    /// drawing's frame) that put the first steps of the next blocks where
    /// they are drawn, for scale `k` and lead turn `lead`.
    fn leads(&self, b: usize, k: u32, lead: i32) -> Vec<DVec2> {
        let lat = &self.lat;
        let st = &self.strokes;
        let k = f64::from(k);
        // Block j starts at k·R(−lead)·p_j + (R(h_j) − I)·v.
        let eq: Vec<(DMat2, DVec2)> = (1..b)
            .map(|j| {
                let a = DMat2::from_angle((lat.delta * f64::from(st[j].1)).to_radians())
                    - DMat2::IDENTITY;
                (a, st[j * b].0 - lat.rot(-lead, st[j].0) * k)
            })
            .collect();
        let (mut ata, mut atb) = (DMat2::ZERO, DVec2::ZERO);
        for (a, r) in &eq {
            ata += a.transpose() * *a;
            atb += a.transpose() * *r;
        }
        let tries: Vec<DVec2> = if ata.determinant().abs() > 1e-6 {
            vec![ata.inverse() * atb]
        } else {
            // Every step heads the same way: the lead gap does not show
            // here; none, or one move.
            std::iter::once(DVec2::ZERO)
                .chain((0..lat.m).map(|h| lat.unit(h)))
                .collect()
        };
        tries
            .into_iter()
            .filter(|v| eq.iter().all(|(a, r)| (*a * *v - *r).length() <= NEAR))
            .collect()
    }

    /// The grammar of successor steps as the first block's, inner gaps
    /// `inner`, scale `k`, lead turn `lead` and lead gap `v` (drawing's
    /// frame); `None` when a gap is not a few moves.
    fn grammar(
        &self,
        inner: &[Vec<Sym>],
        (b, size, depth): (usize, usize, u32),
        k: u32,
        lead: i32,
        v: DVec2,
    ) -> Option<Grammar> {
        let lat = &self.lat;
        let st = &self.strokes;
        // In the successor's frame: the lead gap, the steps, the close.
        let v0 = lat.rot(lead, v);
        let mut w = lat.gap(v0, lead, 1)?;
        for gap in std::iter::once(&Vec::new()).chain(inner) {
            w.extend_from_slice(gap);
            w.push(Sym::Letter(0));
        }
        let (pl, hl) = st[b - 1];
        let end = v0 + lat.rot(lead, pl + lat.unit(hl));
        let heading = lead + hl;
        let close = lat.rot(-heading, lat.unit(0) * f64::from(k) - end);
        w.extend(lat.gap(close, -heading, 1)?);
        let mut g = Grammar {
            letters: vec![
                Letter {
                    name: 'F',
                    action: Action::Draw,
                    rule: Some(w),
                },
                Letter {
                    name: 'f',
                    action: Action::Move,
                    rule: Some(vec![Sym::Letter(1); k as usize]),
                },
            ],
            axiom: vec![Sym::Letter(0)],
            depth,
        };
        g.axiom = self.axiom(&g, size, k.checked_pow(depth)?)?;
        Some(g)
    }

    /// The axiom: a letter per top block of `size` steps, placed where its
    /// first step is drawn, each letter drawing `span` steps straight on.
    fn axiom(&self, g: &Grammar, size: usize, span: u32) -> Option<Vec<Sym>> {
        let lat = &self.lat;
        let angles = Angles::new(lat.delta, Some(lat.m), self.angles.tolerance);
        let (q, hq) = first_step(g, &angles, 64 * self.tree.nodes.len() as u64 + 100_000)?;
        let mut axiom = vec![Sym::Letter(0)];
        let mut last: Option<(DVec2, i32)> = None;
        for block in self.strokes.chunks(size) {
            let (s, h) = block[0];
            let heading = h - hq;
            let at = s - lat.rot(heading, q);
            if let Some((from, fh)) = last {
                let end = from + lat.unit(fh) * f64::from(span);
                let d = lat.rot(-fh, at - end) / f64::from(span);
                axiom.extend(lat.gap(d, heading - fh, 1)?);
                axiom.push(Sym::Letter(0));
            }
            last = Some((at, heading));
        }
        Some(axiom)
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{draw, grammar};
    use super::*;
    use crate::infer::lines::grammar::Action;

    /// The grammars `moves` proposes for the drawing of `g`, as text.
    fn proposed(g: &Grammar, angles: &Angles) -> Vec<Grammar> {
        let tree = draw(g, angles);
        let mut out = Proposals::default();
        let mut keep = |g: Grammar, out: &mut Proposals| out.grammars.push(g);
        moves(&tree, angles, &Limits::default(), &mut keep, &mut out);
        out.grammars
    }

    #[test]
    fn gaps_of_several_legs_give_back_their_grammar() {
        // `-f` ends each successor, `-ff++` the one around it: a gap of two
        // legs between strokes, read as one jump.
        let angles = Angles::new(90.0, Some(4), 1.0);
        let g = grammar(
            "F",
            &[('F', Action::Draw, "F-f++F-f"), ('f', Action::Move, "ff")],
            6,
        );
        let tree = draw(&g, &angles);
        assert!(!tree.jumps.is_empty(), "the drawing has no jump");
        let found = proposed(&g, &angles);
        assert!(found.contains(&g), "{found:?}");
    }

    #[test]
    fn a_lead_gap_and_a_polygon_axiom_come_back() {
        // The successor starts with a gap (`f-F`), and three letters in a
        // triangle make the axiom.
        let angles = Angles::new(60.0, Some(6), 1.0);
        let g = grammar(
            "F++F++F",
            &[('F', Action::Draw, "f-F++F-f"), ('f', Action::Move, "fff")],
            3,
        );
        let tree = draw(&g, &angles);
        let found = proposed(&g, &angles);
        assert!(!found.is_empty(), "nothing proposed");
        // Any legs that land where the gaps do draw every level alike: the
        // grammar found draws this level and the next.
        for f in &found[..1] {
            let mut next = f.clone();
            next.depth += 1;
            let mut truth = g.clone();
            truth.depth += 1;
            let work = 1 << 24;
            assert_eq!(matches(f, &tree, &angles, work, None), Outcome::Same);
            assert_eq!(
                matches(&next, &draw(&truth, &angles), &angles, work, None),
                Outcome::Same,
                "{f:?}"
            );
        }
    }

    #[test]
    fn legs_are_the_fewest_moves() {
        let lat = Lattice { m: 4, delta: 90.0 };
        let legs = lat.legs(DVec2::new(-2.0, 1.0)).expect("lands");
        assert_eq!(legs.len(), 3);
        let lat = Lattice { m: 6, delta: 60.0 };
        assert_eq!(lat.legs(DVec2::ZERO), Some(Vec::new()));
        assert!(lat.legs(DVec2::new(0.5, 0.5)).is_none());
    }
}
