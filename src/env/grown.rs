//! A running system's string and drawing in pieces: pieces *kept* for good
//! (modules that no step changes, drawn from a turtle nothing before them can
//! change, so their segments are final) and *live* pieces, each derived and
//! drawn from the turtle it starts with at every step. A step's work is then
//! proportional to the live pieces, not to the whole string: a street that
//! has stopped is neither derived, nor drawn, nor indexed again.
//!
//! A live piece is cut after it is drawn (`redraw::cut`). The pieces in order
//! are always the system's string, derived as `derive::step` derives it (by
//! `derive::step_piece`, with each piece's place in the string), and their
//! drawings in order are always the drawing of the whole string. Programs that
//! cannot be stepped piece by piece, or drawn in part, or whose queries do not
//! read what is drawn are kept as one live piece (`Grown::splits`).
//!
//! Owns: the pieces, their places, deriving and drawing them, and cutting
//! them. Must not answer queries or index segments (that is `engine`).

use super::redraw::{self, Cut, Sketch};
use crate::compile::Program;
use crate::derive::{self, DeriveError, Limits, ModString, Place, Plan};
use crate::turtle::State;
use glam::DVec2;
use rayon::prelude::*;

/// A piece of a system's string.
pub(crate) enum Piece {
    Kept(Kept),
    Live(Box<LivePiece>),
}

/// Pieces kept for good, one after another (neighbours are merged, so that
/// the pieces of a string stay about twice its live pieces).
pub(crate) struct Kept {
    pub(crate) parts: Vec<KeptPart>,
    /// Each part's number and segment count, in order (what numbering the
    /// segments at each step reads).
    pub(crate) ids: Vec<(u32, u32)>,
    /// Some part is not in the guide's index yet.
    pub(crate) pending: bool,
    modules: usize,
    params: usize,
}

/// One piece as it was kept.
pub(crate) struct KeptPart {
    /// Its number in its guide (the keys of its segments in the index).
    pub(crate) id: usize,
    string: ModString,
    pub(crate) segments: Vec<(DVec2, DVec2)>,
    /// The box of its segments (an empty box for none).
    bounds: (DVec2, DVec2),
    /// Whether the guide's index holds its segments.
    pub(crate) indexed: bool,
}

/// A piece derived and drawn at each step.
pub(crate) struct LivePiece {
    /// Its number in its guide (the keys of its segments in the index).
    pub(crate) id: usize,
    pub(crate) string: ModString,
    /// The turtle it is drawn from (`None`: the system's start).
    entry: Option<(State, Vec<State>)>,
    /// Its drawing (`None`: to be drawn).
    pub(crate) drawing: Option<Sketch>,
    /// While it is to be drawn again, its last string and drawing (`redraw`
    /// reuses them).
    prev: Option<(ModString, Sketch)>,
    /// Drawn since it was last cut.
    uncut: bool,
}

impl Piece {
    fn live(
        id: usize,
        string: ModString,
        entry: Option<(State, Vec<State>)>,
        drawing: Option<Sketch>,
    ) -> Piece {
        Piece::Live(Box::new(LivePiece {
            id,
            string,
            entry,
            drawing,
            prev: None,
            uncut: false,
        }))
    }

    fn modules(&self) -> usize {
        match self {
            Piece::Kept(k) => k.modules,
            Piece::Live(l) => l.string.len(),
        }
    }

    fn params(&self) -> usize {
        match self {
            Piece::Kept(k) => k.params,
            Piece::Live(l) => l.string.params.len(),
        }
    }
}

/// A system's string in pieces; see the module note.
pub(crate) struct Grown {
    pub(crate) pieces: Vec<Piece>,
}

impl Grown {
    /// The string as one live piece numbered `id`.
    pub(crate) fn new(string: ModString, id: usize) -> Grown {
        Grown {
            pieces: vec![Piece::live(id, string, None, None)],
        }
    }

    /// Whether a program's strings are cut into pieces: stepped piece by
    /// piece, drawn in part, and its queries read what is drawn (otherwise its
    /// string stays one live piece).
    pub(crate) fn splits(prog: &Program, reads_drawing: bool) -> bool {
        derive::piecewise(prog) && redraw::redrawable(prog) && reads_drawing
    }

    /// Modules in the string.
    pub(crate) fn len(&self) -> usize {
        self.pieces.iter().map(Piece::modules).sum()
    }

    /// The whole string.
    pub(crate) fn string(&self) -> ModString {
        let mut s = ModString {
            syms: Vec::with_capacity(self.len()),
            params: Vec::with_capacity(self.pieces.iter().map(Piece::params).sum()),
        };
        let mut add = |x: &ModString| {
            s.syms.extend_from_slice(&x.syms);
            s.params.extend_from_slice(&x.params);
        };
        for p in &self.pieces {
            match p {
                Piece::Kept(k) => k.parts.iter().for_each(|x| add(&x.string)),
                Piece::Live(l) => add(&l.string),
            }
        }
        s
    }

    /// Every live piece: (its place in the pieces, its first module's place
    /// in the string, the piece).
    pub(crate) fn live(&self) -> impl Iterator<Item = (usize, usize, &LivePiece)> {
        let mut origin = 0;
        self.pieces.iter().enumerate().filter_map(move |(i, p)| {
            let at = origin;
            origin += p.modules();
            match p {
                Piece::Live(l) => Some((i, at, &**l)),
                Piece::Kept(_) => None,
            }
        })
    }

    fn live_mut(&mut self) -> impl Iterator<Item = &mut LivePiece> {
        self.pieces.iter_mut().filter_map(|p| match p {
            Piece::Live(l) => Some(&mut **l),
            Piece::Kept(_) => None,
        })
    }

    /// Piece `i`, if live.
    pub(crate) fn live_piece(&self, i: usize) -> Option<&LivePiece> {
        match &self.pieces[i] {
            Piece::Live(l) => Some(l),
            Piece::Kept(_) => None,
        }
    }

    /// The drawing of live piece `i`, if drawn.
    pub(crate) fn drawing(&self, i: usize) -> Option<&Sketch> {
        match &self.pieces[i] {
            Piece::Live(l) => l.drawing.as_ref(),
            Piece::Kept(_) => None,
        }
    }

    /// Whether every live piece is drawn.
    pub(crate) fn drawn(&self) -> bool {
        self.live().all(|(_, _, l)| l.drawing.is_some())
    }

    /// Drops the drawings (the string is to be drawn again).
    pub(crate) fn forget(&mut self) {
        for l in self.live_mut() {
            l.drawing = None;
        }
    }

    /// The segments with an end within `tol` of `p` (and maybe others; all
    /// of them for an infinite `tol`), in the order of the string.
    pub(crate) fn segments_near(
        &self,
        p: DVec2,
        tol: f64,
    ) -> impl Iterator<Item = &(DVec2, DVec2)> {
        let near = move |(lo, hi): (DVec2, DVec2)| {
            lo.x - tol <= p.x && p.x <= hi.x + tol && lo.y - tol <= p.y && p.y <= hi.y + tol
        };
        self.pieces
            .iter()
            .flat_map(move |piece| -> Box<dyn Iterator<Item = &(DVec2, DVec2)>> {
                match piece {
                    Piece::Kept(k) => Box::new(
                        k.parts
                            .iter()
                            .filter(move |x| near(x.bounds))
                            .flat_map(|x| &x.segments),
                    ),
                    Piece::Live(l) => Box::new(l.drawing.iter().flat_map(|d| &d.drawn.segments)),
                }
            })
    }

    /// Whether the live pieces hold only modules for which `inert` holds.
    pub(crate) fn all(&self, inert: impl Fn(crate::compile::Sym) -> bool) -> bool {
        self.live()
            .all(|(_, _, p)| p.string.syms.iter().all(|&x| inert(x)))
    }

    /// Derives every live piece once (step `step_no`); whether the string
    /// changed.
    pub(crate) fn derive(
        &mut self,
        prog: &Program,
        plan: &Plan,
        step_no: u32,
        seed: u64,
        limits: Limits,
    ) -> Result<bool, DeriveError> {
        if let [Piece::Live(l)] = &mut self.pieces[..] {
            let next = derive::step(prog, &l.string, step_no, seed, limits)?;
            return Ok(l.replace(next));
        }
        let modules = self.len();
        let params: usize = self.pieces.iter().map(Piece::params).sum();
        let mut origin = 0;
        let mut jobs: Vec<(Place, &mut LivePiece)> = Vec::new();
        for p in &mut self.pieces {
            let at = Place {
                origin,
                other_modules: modules - p.modules(),
                other_params: params - p.params(),
            };
            origin += p.modules();
            if let Piece::Live(l) = p {
                jobs.push((at, l));
            }
        }
        // The pieces in parallel (a system alone in its guide is most of
        // its guide's work); the first error in order is reported.
        let done: Vec<Result<bool, DeriveError>> = jobs
            .into_par_iter()
            .map(|(at, l)| {
                derive::step_piece(prog, plan, &l.string, at, step_no, seed, limits)
                    .map(|next| l.replace(next))
            })
            .collect();
        let mut changed = false;
        let mut failed = None;
        for r in done {
            match r {
                Ok(c) => changed |= c,
                Err(e) => {
                    failed = Some(e);
                    break;
                }
            }
        }
        match failed {
            None => Ok(changed),
            // The message of stepping the whole string.
            Some(e) => match derive::step(prog, &self.string(), step_no, seed, limits) {
                Err(whole) => Err(whole),
                Ok(_) => Err(e),
            },
        }
    }

    /// Draws every live piece not drawn, from the system's start `start`,
    /// reusing its last drawing where it can.
    pub(crate) fn draw(&mut self, prog: &Program, start: State) {
        let jobs: Vec<&mut LivePiece> = self.live_mut().filter(|l| l.drawing.is_none()).collect();
        jobs.into_par_iter().for_each(|l| {
            let at = l.entry.as_ref().map(|(a, b)| (a, &b[..]));
            let new = &l.string;
            l.drawing = Some(match l.prev.take() {
                Some((old, d)) => redraw::redraw(prog, &old, d, new, start, at),
                None => redraw::draw(prog, new, start, at),
            });
            l.uncut = true;
        });
    }

    /// Cuts the live pieces drawn since they were last cut (see
    /// `redraw::cut`), numbering new pieces from `next_id` on, and merges
    /// neighbouring kept pieces.
    pub(crate) fn cut(&mut self, prog: &Program, start: State, next_id: &mut usize) {
        let jobs: Vec<(usize, &mut LivePiece)> = self
            .pieces
            .iter_mut()
            .enumerate()
            .filter_map(|(i, p)| match p {
                Piece::Live(l) if l.uncut && l.prev.is_none() => Some((i, &mut **l)),
                _ => None,
            })
            .collect();
        let cuts: Vec<(usize, Vec<Cut>, ModString)> = jobs
            .into_par_iter()
            .filter_map(|(i, l)| {
                l.uncut = false;
                let at = l.entry.as_ref().map(|(a, b)| (a, &b[..]));
                let c = redraw::cut(prog, &l.string, &mut l.drawing, start, at)?;
                Some((i, c, std::mem::take(&mut l.string)))
            })
            .collect();
        if cuts.is_empty() {
            return;
        }
        let old = std::mem::take(&mut self.pieces);
        let mut out: Vec<Piece> = Vec::with_capacity(old.len() + 2 * cuts.len());
        let mut cuts = cuts.into_iter().peekable();
        for (i, p) in old.into_iter().enumerate() {
            if cuts.peek().is_none_or(|c| c.0 != i) {
                push(&mut out, p);
                continue;
            }
            let Some((_, pieces, mut string)) = cuts.next() else {
                continue;
            };
            let n = pieces.len();
            for (k, c) in pieces.into_iter().enumerate() {
                let id = *next_id;
                *next_id += 1;
                push(
                    &mut out,
                    match c {
                        Cut::Kept {
                            modules,
                            params,
                            segments,
                        } => Piece::Kept(Kept {
                            modules: modules.len(),
                            params: params.len(),
                            ids: vec![(id as u32, segments.len() as u32)],
                            pending: true,
                            parts: vec![KeptPart {
                                id,
                                string: slice(&string, modules, params),
                                bounds: bounds(&segments),
                                segments,
                                indexed: false,
                            }],
                        }),
                        Cut::Live {
                            modules,
                            params,
                            entry,
                            sketch,
                        } => {
                            // The last piece keeps the string's lists.
                            let own = if k + 1 == n {
                                let mut own = std::mem::take(&mut string);
                                own.syms.drain(..modules.start);
                                own.params.drain(..params.start);
                                own
                            } else {
                                slice(&string, modules, params)
                            };
                            Piece::live(id, own, entry, Some(*sketch))
                        }
                    },
                );
            }
        }
        self.pieces = out;
    }

    /// The parameters of live piece `i`.
    pub(crate) fn params_mut(&mut self, i: usize) -> &mut [f64] {
        match &mut self.pieces[i] {
            Piece::Live(l) => &mut l.string.params,
            Piece::Kept(_) => &mut [],
        }
    }

    /// Draws the whole string as one piece with `f` (programs that are not
    /// cut: `splits` is false).
    pub(crate) fn draw_whole(&mut self, f: impl FnOnce(&ModString) -> Sketch) {
        if let [Piece::Live(l)] = &mut self.pieces[..] {
            l.prev = None;
            l.drawing = Some(f(&l.string));
        }
    }
}

/// Adds `p` after the pieces `out`, merged into the last if both are kept.
fn push(out: &mut Vec<Piece>, p: Piece) {
    match (out.last_mut(), p) {
        (Some(Piece::Kept(a)), Piece::Kept(b)) => {
            a.modules += b.modules;
            a.params += b.params;
            a.parts.extend(b.parts);
            a.ids.extend(b.ids);
            a.pending |= b.pending;
        }
        (_, p) => out.push(p),
    }
}

impl LivePiece {
    /// Replaces the piece's string by `next` (the last drawing kept for
    /// `redraw`); whether it changed. An unchanged string draws the same: its
    /// drawing stays.
    fn replace(&mut self, next: ModString) -> bool {
        if next == self.string {
            return false;
        }
        let old = std::mem::replace(&mut self.string, next);
        if let Some(d) = self.drawing.take() {
            self.prev = Some((old, d));
        }
        true
    }
}

/// The box of some segments (an empty box, min above max, for none).
fn bounds(segs: &[(DVec2, DVec2)]) -> (DVec2, DVec2) {
    segs.iter().fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), s| (lo.min(s.0).min(s.1), hi.max(s.0).max(s.1)),
    )
}

fn slice(
    s: &ModString,
    modules: std::ops::Range<usize>,
    params: std::ops::Range<usize>,
) -> ModString {
    ModString {
        syms: s.syms[modules].to_vec(),
        params: s.params[params].to_vec(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::env::query::Probe;
    use crate::env::redraw::tests::{PROGRAMS, bits, program};

    /// Grows each test program step by step in pieces, cut after every step;
    /// the pieces' string must be the whole string `derive::step` makes, and
    /// their drawings in order (kept segments, then each live piece's) the
    /// whole drawing, bit for bit, with the queries at their modules.
    #[test]
    fn pieces_are_the_whole_string_and_drawing() {
        let mut kept = 0;
        for text in PROGRAMS {
            let prog = program(text);
            assert!(Grown::splits(&prog, true), "{text}");
            let plan = Plan::new(&prog);
            let start = State::default();
            let mut s = derive::axiom(&prog, &[], 7).expect("axiom");
            let mut grown = Grown::new(s.clone(), 0);
            let mut next_id = 1;
            grown.draw(&prog, start);
            grown.cut(&prog, start, &mut next_id);
            for step in 1..=prog.derive {
                s = derive::step(&prog, &s, step, 7, Limits::default()).expect("step");
                grown
                    .derive(&prog, &plan, step, 7, Limits::default())
                    .expect("pieces");
                assert_eq!(grown.string(), s, "{text} step {step}");
                grown.draw(&prog, start);
                let whole = redraw::draw(&prog, &s, start, None);
                let mut queries = Vec::new();
                for (i, origin, _) in grown.live() {
                    let d = grown.drawing(i).expect("drawn");
                    queries.extend(
                        d.drawn
                            .queries
                            .iter()
                            .map(|&(m, k, st)| (origin + m, k, st)),
                    );
                }
                let pieces = Probe {
                    segments: grown
                        .segments_near(DVec2::ZERO, f64::INFINITY)
                        .copied()
                        .collect(),
                    queries,
                };
                assert_eq!(bits(&pieces), bits(&whole.drawn), "{text} step {step}");
                grown.cut(&prog, start, &mut next_id);
                assert_eq!(grown.string(), s, "{text} step {step}, cut");
            }
            kept += grown
                .pieces
                .iter()
                .filter_map(|p| match p {
                    Piece::Kept(k) => Some(k.parts.iter().map(|x| x.segments.len()).sum::<usize>()),
                    Piece::Live(_) => None,
                })
                .sum::<usize>();
        }
        // Most of what was drawn ended in kept pieces.
        assert!(kept > 300, "{kept}");
    }
}
