//! Drawing a system's string for its queries and index, and drawing it again
//! after a derivation step by reusing the last drawing where the string did
//! not change.
//!
//! A step rewrites only the modules that have rules (here *active*); the
//! others are copied. A drawing keeps, at every run of active modules, the
//! turtle (state, stack) before and after it and how many segments and
//! queries were drawn up to there (`Mark`). The next string is aligned with
//! the last one: every run of inactive modules between two active runs must
//! appear again, in order, equal module for module (parameters bit for bit).
//! A copied run entered with the turtle it was entered with last time draws
//! what it drew then, so its segments and queries are copied and the turtle
//! is set to the one after it; otherwise the run is drawn, until a `]` pops a
//! state the two drawings share (then the rest of the run is copied). What
//! the rules produced is drawn anew. The result is always what drawing the
//! whole string gives: an alignment that is not the derivation's own only
//! means that less is copied. Programs with interpretation rules or `cut` are
//! drawn whole, and so are strings whose inactive runs are short on average
//! (`RUN_WORTH_COPYING`): checking and copying a run costs more than drawing
//! a few modules.
//!
//! A string can be drawn from a turtle other than the system's start (the
//! state and stack a piece of a longer string starts with: `Resume`): the engine keeps the start of a system's
//! string that holds no active module, and its segments, for good
//! (`Sketch::split_front`), and draws only what follows.
//!
//! Owns: `Sketch` (a drawing and its marks), `draw`, `redraw` and splitting
//! off a drawing's front. Must not answer queries or index segments.

use super::query::Probe;
use crate::compile::{Program, Sym};
use crate::derive::ModString;
use crate::turtle::{State, Stepper};
use glam::DVec2;

/// The turtle where a string starts: `None` for the system's start state, or
/// the state and stack a piece of a longer string starts with.
pub(crate) type Resume<'a> = Option<(&'a State, &'a [State])>;

fn stepper<'p>(prog: &'p Program, start: State, at: Resume) -> Stepper<'p> {
    let mut st = Stepper::new(prog, start);
    if let Some((state, stack)) = at {
        st.state = *state;
        st.stack = stack.to_vec();
    }
    st
}

/// A piece of a drawn span (`cut`): modules, parameters and segments.
pub(crate) enum Cut {
    /// Modules that no step changes and that are drawn from a turtle
    /// nothing before them can change: their segments are final.
    Kept {
        modules: std::ops::Range<usize>,
        params: std::ops::Range<usize>,
        segments: Vec<(DVec2, DVec2)>,
    },
    /// The rest, with its drawing, from the turtle it starts with (`None`:
    /// the span's own start).
    Live {
        modules: std::ops::Range<usize>,
        params: std::ops::Range<usize>,
        entry: Option<(State, Vec<State>)>,
        sketch: Box<Sketch>,
    },
}

/// The fewest modules a kept piece holds, unless it ends the span (pieces
/// kept are never merged: a few large ones are cheaper than many small).
const MIN_KEPT: usize = 16;

/// The fewest modules per run of active modules a string must hold on
/// average for `redraw` to copy its runs rather than draw it whole.
const RUN_WORTH_COPYING: usize = 32;

/// The turtle at one place of the string, and what was drawn before it.
#[derive(Clone, Copy)]
struct Snap {
    state: State,
    /// Its stack, in the drawing's `Stacks`.
    stack: StackAt,
    /// A polygon was open (the turtle cannot be set to this place).
    polygon: bool,
    segs: usize,
    queries: usize,
}

/// Where a stack is in a drawing's `Stacks`: (first state, depth).
type StackAt = (usize, usize);

/// The stacks of a drawing's snaps, one after another; a snap with the same
/// stack as the one added before shares it.
#[derive(Default)]
struct Stacks {
    states: Vec<State>,
    last: Option<StackAt>,
}

impl Stacks {
    fn get(&self, (at, n): StackAt) -> &[State] {
        &self.states[at..at + n]
    }

    fn add(&mut self, stack: &[State]) -> StackAt {
        if let Some(r) = self.last
            && r.1 == stack.len()
            && shared(self.get(r), stack) == stack.len()
        {
            return r;
        }
        let r = (self.states.len(), stack.len());
        self.states.extend_from_slice(stack);
        self.last = Some(r);
        r
    }

    /// `x` of the drawing with `stacks`, its stack added here.
    fn adopt(&mut self, stacks: &Stacks, mut x: Snap) -> Snap {
        x.stack = self.add(stacks.get(x.stack));
        x
    }
}

/// A run of active modules: where it is (modules and parameters) and the
/// turtle before and after it.
struct Mark {
    start: usize,
    end: usize,
    pstart: usize,
    pend: usize,
    before: Snap,
    after: Snap,
}

/// A system's drawing: its segments (and elements' axes), the query modules
/// met, and its marks (`None`: the next string is drawn whole).
pub(crate) struct Sketch {
    pub(crate) drawn: Probe,
    marks: Option<Vec<Mark>>,
    /// The turtle after the last module (with marks only).
    end: Option<Snap>,
    /// The stacks of the marks and `end`.
    stacks: Stacks,
    /// The segment list of the drawing before, emptied: the next redraw
    /// fills it instead of allocating a list as large.
    spare: Vec<(glam::DVec2, glam::DVec2)>,
}

impl Sketch {
    /// A drawing made otherwise, without marks.
    pub(crate) fn whole(drawn: Probe) -> Sketch {
        Sketch {
            drawn,
            marks: None,
            end: None,
            stacks: Stacks::default(),
            spare: Vec::new(),
        }
    }
}

/// Whether the modules of `sym` may be rewritten by a step.
fn active(prog: &Program, sym: Sym) -> bool {
    let i = sym as usize;
    prog.rules.get(i).is_some_and(|r| !r.is_empty())
        || prog.decompose.get(i).is_some_and(|r| !r.is_empty())
        || matches!(
            prog.symbols.info[i].action,
            crate::compile::Action::Cut | crate::compile::Action::Query(_)
        )
}

/// Whether a program's drawings can be redrawn in part (`draw` and `redraw`
/// serve it). With `cut`, a step removes modules without rules, and their
/// runs would be searched for in vain.
pub(crate) fn redrawable(prog: &Program) -> bool {
    prog.interpret.iter().all(|r| r.is_empty()) && !prog.has_cut
}

fn same_state(a: &State, b: &State) -> bool {
    let v = |s: &State| {
        [
            s.pos.x,
            s.pos.y,
            s.pos.z,
            s.h.x,
            s.h.y,
            s.h.z,
            s.l.x,
            s.l.y,
            s.l.z,
            s.u.x,
            s.u.y,
            s.u.z,
            s.scale,
            s.width,
            s.elasticity,
        ]
        .map(f64::to_bits)
    };
    v(a) == v(b) && a.color == b.color && a.contour == b.contour
}

/// How many states at the bottom of two stacks are the same.
fn shared(a: &[State], b: &[State]) -> usize {
    a.iter()
        .zip(b)
        .take_while(|(x, y)| same_state(x, y))
        .count()
}

/// Cuts the drawing in `slot` of span `s` (drawn from `start`, or from `at`)
/// into pieces kept for good and live pieces, taking it; `None` (and the
/// drawing left in `slot`) when nothing is to be kept. A module's turtle is *fixed* when no active module comes
/// before it outside a branch closed before it (an active module before may
/// move the turtle once rewritten; a `]` restores what its `[` saved). A run
/// of inactive modules that starts with a fixed turtle, outside a polygon,
/// and ends outside a polygon is kept when it holds `MIN_KEPT` modules or
/// ends the span. What remains between kept runs is live, each live piece
/// starting from a fixed turtle.
pub(crate) fn cut(
    prog: &Program,
    s: &ModString,
    slot: &mut Option<Sketch>,
    start: State,
    at: Resume,
) -> Option<Vec<Cut>> {
    let d = slot.as_ref()?;
    let marks = d.marks.as_deref()?;
    let end = d.end.as_ref()?;
    // The stacks of the snaps drawn again below (`Kept::snap_a`).
    let mut redrawn = Stacks::default();
    // Where the turtle is fixed again after each run of active modules
    // (`None`: not before the next run), by the branches' nesting.
    let mut fixed_from: Vec<Option<usize>> = Vec::with_capacity(marks.len());
    let mut cur = true;
    let mut saved: Vec<bool> = Vec::new();
    let mut poisoned = false;
    let mut mi = 0;
    let mut i = 0;
    while i < s.len() {
        if let Some(m) = marks.get(mi)
            && m.start == i
        {
            for &x in &s.syms[m.start..m.end] {
                let action = prog.symbols.info[x as usize].action;
                poisoned |= matches!(
                    action,
                    crate::compile::Action::Push | crate::compile::Action::Pop
                );
            }
            cur = false;
            i = m.end;
            mi += 1;
            fixed_from.push(None);
            continue;
        }
        match prog.symbols.info[s.syms[i] as usize].action {
            crate::compile::Action::Push => saved.push(cur),
            crate::compile::Action::Pop => cur = saved.pop().unwrap_or(true),
            _ => {}
        }
        i += 1;
        if cur
            && !poisoned
            && let Some(f @ None) = fixed_from.last_mut()
        {
            *f = Some(i);
        }
    }
    // A run to keep: modules `a..b`; at `a` and `b` its parameters and the
    // segments and queries drawn before, the turtle at `a` when it is not a
    // mark's (for a live piece ending there) and the turtle after it.
    struct Kept {
        a: usize,
        pa: usize,
        sa: usize,
        qa: usize,
        snap_a: Option<Snap>,
        b: usize,
        pb: usize,
        sb: usize,
        qb: usize,
        exit: (State, Vec<State>),
    }
    let mut runs: Vec<Kept> = Vec::new();
    for k in 0..=marks.len() {
        let (b, at_b) = match marks.get(k) {
            Some(m) => (m.start, &m.before),
            None => (s.len(), end),
        };
        // Where the run to keep would start: only a run worth keeping is
        // looked at further.
        let a = if k == 0 {
            0
        } else {
            match fixed_from[k - 1] {
                Some(a) => a,
                None => continue,
            }
        };
        let enough = b - a >= MIN_KEPT || (b == s.len() && b > a);
        if a >= b || !enough || at_b.polygon {
            continue;
        }
        let (a, pa, sa, qa, snap_a) = if k == 0 {
            (0, 0, 0, 0, None)
        } else {
            let prev = &marks[k - 1];
            if a == prev.end {
                (a, prev.pend, prev.after.segs, prev.after.queries, None)
            } else {
                // Draw up to `a` again for its turtle and segment count.
                if prev.after.polygon {
                    continue;
                }
                let mut st = stepper(
                    prog,
                    start,
                    Some((&prev.after.state, d.stacks.get(prev.after.stack))),
                );
                let pa = prev.pend
                    + s.syms[prev.end..a]
                        .iter()
                        .map(|&x| prog.symbols.arity(x))
                        .sum::<usize>();
                let mut scratch = Probe::default();
                st.run(
                    &mut scratch,
                    &s.syms[prev.end..a],
                    &s.params[prev.pend..pa],
                    prev.end,
                    None,
                );
                let mut snap_a = snap(&st, &scratch, redrawn.add(&st.stack));
                snap_a.segs += prev.after.segs;
                snap_a.queries += prev.after.queries;
                (a, pa, snap_a.segs, snap_a.queries, Some(snap_a))
            }
        };
        let open = snap_a.as_ref().is_some_and(|x| x.polygon);
        if !open && at_b.queries == qa {
            runs.push(Kept {
                a,
                pa,
                sa,
                qa,
                snap_a,
                b,
                pb: pa
                    + s.syms[a..b]
                        .iter()
                        .map(|&x| prog.symbols.arity(x))
                        .sum::<usize>(),
                sb: at_b.segs,
                qb: at_b.queries,
                exit: (at_b.state, d.stacks.get(at_b.stack).to_vec()),
            });
        }
    }
    if runs.is_empty() {
        return None;
    }
    let Some(Sketch {
        drawn,
        marks,
        end,
        stacks,
        ..
    }) = slot.take()
    else {
        unreachable!("looked at above")
    };
    let (Some(marks), Some(end)) = (marks, end) else {
        unreachable!("checked above")
    };
    let mut marks = marks.into_iter().peekable();
    let mut out = Vec::with_capacity(2 * runs.len() + 1);
    let mut from = (0, 0, 0, 0);
    let mut entry: Option<(State, Vec<State>)> = at.map(|(a, b)| (*a, b.to_vec()));
    // A live piece from `from` to `to`, given its drawing (queries at
    // their modules in the span).
    let mut live = |from: (usize, usize, usize, usize),
                    to: (usize, usize, usize, usize),
                    snap_a: Option<Snap>,
                    entry: Option<(State, Vec<State>)>,
                    mut drawn: Probe|
     -> Cut {
        let (c, pc, sc, qc) = from;
        let (a, pa, sa, qa) = to;
        let rebase = |mut x: Snap| {
            x.segs -= sc;
            x.queries -= qc;
            x
        };
        let mut inside = Vec::new();
        while let Some(m) = marks.next_if(|m| m.start < a) {
            inside.push(m);
        }
        // Marks serve only to copy runs at the next redraw: a piece that
        // will be drawn whole keeps none.
        let mut own = Stacks::default();
        let copies = a - c >= RUN_WORTH_COPYING * (inside.len() + 1);
        let marked = copies.then(|| {
            let last_after = inside.last().map(|m| m.after);
            let inside: Vec<Mark> = inside
                .into_iter()
                .map(|m| Mark {
                    start: m.start - c,
                    end: m.end - c,
                    pstart: m.pstart - pc,
                    pend: m.pend - pc,
                    before: rebase(own.adopt(&stacks, m.before)),
                    after: rebase(own.adopt(&stacks, m.after)),
                })
                .collect();
            let end_at = match snap_a {
                Some(x) => own.adopt(&redrawn, x),
                None if a == s.len() => own.adopt(&stacks, end),
                None => own.adopt(&stacks, last_after.expect("a live piece ends after a mark")),
            };
            (inside, rebase(end_at))
        });
        debug_assert_eq!(
            (drawn.segments.len(), drawn.queries.len()),
            (sa - sc, qa - qc)
        );
        drawn.queries.iter_mut().for_each(|q| q.0 -= c);
        Cut::Live {
            modules: c..a,
            params: pc..pa,
            entry,
            sketch: Box::new(Sketch {
                drawn,
                end: marked.as_ref().map(|m| m.1),
                marks: marked.map(|m| m.0),
                stacks: own,
                spare: Vec::new(),
            }),
        }
    };
    for r in runs {
        if r.a > from.0 {
            let part = Probe {
                segments: drawn.segments[from.2..r.sa].to_vec(),
                queries: drawn.queries[from.3..r.qa].to_vec(),
            };
            out.push(live(
                from,
                (r.a, r.pa, r.sa, r.qa),
                r.snap_a,
                entry.take(),
                part,
            ));
        }
        out.push(Cut::Kept {
            modules: r.a..r.b,
            params: r.pa..r.pb,
            segments: drawn.segments[r.sa..r.sb].to_vec(),
        });
        from = (r.b, r.pb, r.sb, r.qb);
        entry = Some(r.exit);
    }
    if from.0 < s.len() {
        let to = (
            s.len(),
            s.params.len(),
            drawn.segments.len(),
            drawn.queries.len(),
        );
        // The last piece keeps the drawing's lists.
        let mut rest = drawn;
        rest.segments.drain(..from.2);
        rest.queries.drain(..from.3);
        out.push(live(from, to, None, entry, rest));
    }
    Some(out)
}

/// Draws a span whole, from the turtle `start` (or where it was reached:
/// `at`), as `turtle::interpret_from` does (segments, elements' axes,
/// queries), with marks when the program has no interpretation rules.
pub(crate) fn draw(prog: &Program, s: &ModString, start: State, at: Resume) -> Sketch {
    draw_in(prog, s, start, at, Sketch::whole(Probe::default()))
}

/// `draw`, in the lists of the drawing `old` (emptied, not read).
fn draw_in(prog: &Program, s: &ModString, start: State, at: Resume, old: Sketch) -> Sketch {
    let mut st = stepper(prog, start, at);
    let mut out = old.drawn;
    out.segments.clear();
    out.queries.clear();
    let mut marks = old.marks.unwrap_or_default();
    marks.clear();
    let mut stacks = old.stacks;
    stacks.states.clear();
    stacks.last = None;
    fresh(
        prog,
        &mut st,
        &mut out,
        &mut marks,
        &mut stacks,
        s,
        0,
        s.len(),
        0,
    );
    let marks = keep(marks, s.len());
    Sketch {
        end: marks
            .as_ref()
            .map(|_| snap(&st, &out, stacks.add(&st.stack))),
        drawn: out,
        marks,
        stacks,
        spare: Vec::new(),
    }
}

/// Marks are kept when their stacks are not much more than the string.
fn keep(marks: Vec<Mark>, len: usize) -> Option<Vec<Mark>> {
    let held: usize = marks
        .iter()
        .map(|m| 2 + m.before.stack.1 + m.after.stack.1)
        .sum();
    (held <= len / 2 + 4096).then_some(marks)
}

/// The turtle of `st` (its stack at `stack`) and what `out` holds.
fn snap(st: &Stepper, out: &Probe, stack: StackAt) -> Snap {
    Snap {
        state: st.state,
        stack,
        polygon: st.in_polygon(),
        segs: out.segments.len(),
        queries: out.queries.len(),
    }
}

/// Draws modules `from..to` of `s` (parameters from `p`), marking its runs of
/// active modules.
#[allow(clippy::too_many_arguments)]
fn fresh(
    prog: &Program,
    st: &mut Stepper,
    out: &mut Probe,
    marks: &mut Vec<Mark>,
    stacks: &mut Stacks,
    s: &ModString,
    from: usize,
    to: usize,
    mut p: usize,
) {
    // Without interpretation rules only `[` and `]` change the stack: after
    // a run without them it is the one last added to `stacks` (`known`).
    let plain = redrawable(prog);
    let mut known: Option<StackAt> = None;
    let mut snap_at = |st: &Stepper, out: &Probe, known: &mut Option<StackAt>| {
        snap(st, out, *known.get_or_insert_with(|| stacks.add(&st.stack)))
    };
    let mut i = from;
    while i < to {
        let is_active = active(prog, s.syms[i]);
        let (mut j, mut q, mut brackets) = (i, p, false);
        while j < to && (j == i || active(prog, s.syms[j]) == is_active) {
            let x = s.syms[j];
            q += prog.symbols.arity(x);
            brackets |= matches!(
                prog.symbols.info[x as usize].action,
                crate::compile::Action::Push | crate::compile::Action::Pop
            );
            j += 1;
        }
        let before = is_active.then(|| snap_at(st, out, &mut known));
        st.run(out, &s.syms[i..j], &s.params[p..q], i, None);
        if brackets || !plain {
            known = None;
        }
        if let Some(before) = before {
            marks.push(Mark {
                start: i,
                end: j,
                pstart: p,
                pend: q,
                before,
                after: snap_at(st, out, &mut known),
            });
        }
        i = j;
        p = q;
    }
}

/// A run of inactive modules of the last string and where it is in the new
/// one: modules `old..old + len` (parameters from `pold`, `plen` of them) at
/// `new` (parameters from `pnew`).
#[derive(Clone, Copy)]
struct Run {
    old: usize,
    pold: usize,
    len: usize,
    plen: usize,
    new: usize,
    pnew: usize,
}

fn equal_at(
    a: &ModString,
    ai: usize,
    pa: usize,
    b: &ModString,
    bi: usize,
    pb: usize,
    r: Run,
) -> bool {
    a.syms[ai..ai + r.len] == b.syms[bi..bi + r.len]
        && a.params[pa..pa + r.plen]
            .iter()
            .zip(&b.params[pb..pb + r.plen])
            .all(|(x, y)| x.to_bits() == y.to_bits())
}

/// Places the inactive runs of `old` (between its marks) in `new`: the first
/// at the start, the last at the end, the others each at its first place
/// after the one before. `None` when they do not all fit.
fn align(prog: &Program, old: &ModString, marks: &[Mark], new: &ModString) -> Option<Vec<Run>> {
    let mut runs = Vec::with_capacity(marks.len() + 1);
    let (mut o, mut po) = (0, 0);
    for m in marks {
        runs.push(Run {
            old: o,
            pold: po,
            len: m.start - o,
            plen: m.pstart - po,
            new: 0,
            pnew: 0,
        });
        (o, po) = (m.end, m.pend);
    }
    runs.push(Run {
        old: o,
        pold: po,
        len: old.len() - o,
        plen: old.params.len() - po,
        new: 0,
        pnew: 0,
    });
    let last = runs.len() - 1;
    let (mut k, mut pk) = (0usize, 0usize);
    for (ri, r) in runs.iter_mut().enumerate() {
        if ri == last {
            // The last run ends the string.
            let at = new.len().checked_sub(r.len)?;
            let pat = new.params.len().checked_sub(r.plen)?;
            if at < k || pat < pk || !equal_at(old, r.old, r.pold, new, at, pat, *r) {
                return None;
            }
            r.new = at;
            r.pnew = pat;
            break;
        }
        if ri == 0 {
            if r.len > new.len() || r.plen > new.params.len() {
                return None;
            }
            if !equal_at(old, r.old, r.pold, new, 0, 0, *r) {
                return None;
            }
        } else {
            loop {
                if k + r.len > new.len() || pk + r.plen > new.params.len() {
                    return None;
                }
                if (r.len == 0 || new.syms[k] == old.syms[r.old])
                    && equal_at(old, r.old, r.pold, new, k, pk, *r)
                {
                    break;
                }
                pk += prog.symbols.arity(new.syms[k]);
                k += 1;
            }
        }
        r.new = k;
        r.pnew = pk;
        k += r.len;
        pk += r.plen;
    }
    Some(runs)
}

/// Draws `new`, the span derived from `old` (drawn as `last`), from the
/// turtle `start` (or where the spans start: `at`); see the module note.
pub(crate) fn redraw(
    prog: &Program,
    old: &ModString,
    last: Sketch,
    new: &ModString,
    start: State,
    at: Resume,
) -> Sketch {
    // Copying a run costs more than drawing a few modules: a string whose
    // runs of inactive modules are short on average is drawn whole.
    let marks = last.marks.as_ref().map_or(0, Vec::len);
    if old.len() < RUN_WORTH_COPYING * (marks + 1) {
        return draw_in(prog, new, start, at, last);
    }
    copy_runs(prog, old, last, new, start, at)
}

/// `redraw`, copying every run it can.
fn copy_runs(
    prog: &Program,
    old: &ModString,
    mut last: Sketch,
    new: &ModString,
    start: State,
    at: Resume,
) -> Sketch {
    if !redrawable(prog) {
        return draw(prog, new, start, at);
    }
    let Some(marks) = last.marks.as_deref() else {
        return draw(prog, new, start, at);
    };
    let Some(runs) = align(prog, old, marks, new) else {
        return draw(prog, new, start, at);
    };
    let drawn = &last.drawn;
    let mut st = stepper(prog, start, at);
    let begin = Snap {
        state: st.state,
        stack: (0, 0),
        polygon: false,
        segs: 0,
        queries: 0,
    };
    // The stepper's stack: the one `at` gives.
    let begin_stack: &[State] = at.map_or(&[], |(_, stack)| stack);
    let mut stacks = Stacks::default();
    let mut segments = std::mem::take(&mut last.spare);
    segments.reserve(drawn.segments.len() + drawn.segments.len() / 8);
    let mut out = Probe {
        segments,
        queries: Vec::with_capacity(drawn.queries.len() + drawn.queries.len() / 8),
    };
    let mut next = Vec::with_capacity(marks.len() + marks.len() / 4);
    let (mut k, mut pk) = (0usize, 0usize);
    for (ri, r) in runs.iter().enumerate() {
        // What the rules produced before this run: drawn anew.
        fresh(
            prog,
            &mut st,
            &mut out,
            &mut next,
            &mut stacks,
            new,
            k,
            r.new,
            pk,
        );
        let (entry, entry_stack, exit) = match ri {
            0 => (&begin, begin_stack, marks.first()),
            _ => {
                let m = &marks[ri - 1].after;
                (m, last.stacks.get(m.stack), marks.get(ri))
            }
        };
        // Segments and queries the last drawing made in this run from where
        // the two drawings agree (`skip` modules in, `segs` and `queries`
        // drawn by then).
        let agree = if same_state(&st.state, &entry.state)
            && shared(&st.stack, entry_stack) == entry_stack.len()
            && st.stack.len() == entry_stack.len()
            && !st.in_polygon()
            && !entry.polygon
        {
            Some((0, 0, 0))
        } else {
            let depth = shared(&st.stack, entry_stack);
            let below = (st.stack.len() == entry_stack.len()
                && !st.in_polygon()
                && !entry.polygon
                && depth > 0)
                .then_some(depth);
            let (s0, q0) = (out.segments.len(), out.queries.len());
            let end = r.pnew + r.plen;
            let done = st.run(
                &mut out,
                &new.syms[r.new..r.new + r.len],
                &new.params[r.pnew..end],
                r.new,
                below,
            );
            (done < r.len).then(|| (done, out.segments.len() - s0, out.queries.len() - q0))
        };
        match (agree, exit) {
            (Some((_, segs, queries)), exit) if exit.is_none_or(|m| !m.before.polygon) => {
                let (s_end, q_end) = exit
                    .map_or((drawn.segments.len(), drawn.queries.len()), |m| {
                        (m.before.segs, m.before.queries)
                    });
                out.segments
                    .extend_from_slice(&drawn.segments[entry.segs + segs..s_end]);
                let shift = r.new as isize - r.old as isize;
                out.queries.extend(
                    drawn.queries[entry.queries + queries..q_end]
                        .iter()
                        .map(|&(m, kind, state)| ((m as isize + shift) as usize, kind, state)),
                );
                if let Some(m) = exit {
                    st.state = m.before.state;
                    st.stack.clear();
                    st.stack.extend_from_slice(last.stacks.get(m.before.stack));
                }
            }
            (Some((skip, _, _)), _) => {
                // The turtle cannot be set inside a polygon: draw the rest.
                let from = r.new + skip;
                let pfrom = r.pnew
                    + new.syms[r.new..from]
                        .iter()
                        .map(|&x| prog.symbols.arity(x))
                        .sum::<usize>();
                st.run(
                    &mut out,
                    &new.syms[from..r.new + r.len],
                    &new.params[pfrom..r.pnew + r.plen],
                    from,
                    None,
                );
            }
            (None, _) => {}
        }
        k = r.new + r.len;
        pk = r.pnew + r.plen;
    }
    let marks = keep(next, new.len());
    let mut spare = std::mem::take(&mut last.drawn.segments);
    spare.clear();
    Sketch {
        end: marks
            .as_ref()
            .map(|_| snap(&st, &out, stacks.add(&st.stack))),
        drawn: out,
        marks,
        stacks,
        spare,
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::derive::{self, Limits};
    use crate::turtle::State;

    pub(crate) fn program(text: &str) -> Program {
        let fe = crate::frontend::run(text, vec![], &[]);
        assert!(!fe.has_errors(), "{:?}", fe.diagnostics);
        let checked = fe.checked.as_ref().expect("checked");
        crate::compile::compile(&fe.file, checked, None).expect("compiles")
    }

    /// Segments and queries (module, kind, position), bit for bit.
    pub(crate) type Bits = (Vec<[u64; 4]>, Vec<(usize, u8, [u64; 3])>);

    pub(crate) fn bits(p: &Probe) -> Bits {
        (
            p.segments
                .iter()
                .map(|(a, b)| [a.x, a.y, b.x, b.y].map(f64::to_bits))
                .collect(),
            p.queries
                .iter()
                .map(|(m, k, s)| (*m, *k, s.pos.to_array().map(f64::to_bits)))
                .collect(),
        )
    }

    /// Test programs: tips that grow and stop inside branches, polygons,
    /// stochastic rules and a query, branches that end with turns and widths
    /// kept on the stack.
    pub(crate) const PROGRAMS: [&str; 4] = [
        // Tips that grow inside branches, turn by their parameter, and stop
        // at random: most of the string stays.
        "lsystem A { derive 40; axiom [X(0)][+(90) X(1)] F X(2); \
         X(k) : k < 30 -> F(1) +(k * 3) [-(45) Y(k)] F(2) X(k + 1); \
         X(k) -> ; Y(k) : k % 3 == 0 -> F(1) Y(k + 1); Y(k) -> F(0.5); }",
        // Polygons opened before a tip and closed after it; a tip inside a
        // polygon; branches inside the polygon.
        "lsystem B { derive 9; axiom A {. f(1) . [B] . B . } C; \
         A -> F(1) [+(30) A] A; B -> f(1) . +(10) B; C -> F(1) [-(5) C] C; }",
        // Stochastic rules and a queried tip (?P).
        "lsystem C { derive 30; axiom ?P X; \
         ?P(x, y, _) -> F(1) ?P; \
         X -> (1) F(1) [+(20) X] X; X -> (1) F(1) [-(20) X]; X -> (2) F(1) X; }",
        // Branches that end, turns and widths kept on the stack.
        "lsystem D { derive 30; axiom X(0); \
         X(k) : k < 25 -> F(1) [+(40) !(2) Y(3)] -(3) X(k + 1); X(k) -> F(2); \
         Y(n) : n > 0 -> F(1) -(10) Y(n - 1); Y(n) -> ; }",
    ];

    /// Derives each program step by step; every step's redraw (as `redraw`
    /// chooses, and copying every run it can) must equal a whole drawing of
    /// the string (segments bit for bit, queries with their modules), and
    /// the redraws must have copied most of the drawing.
    #[test]
    fn a_redraw_is_the_whole_drawing() {
        let mut copied = 0;
        for text in PROGRAMS {
            let prog = program(text);
            let start = State::default();
            let mut s = derive::axiom(&prog, &[], 7).expect("axiom");
            let mut sketch = draw(&prog, &s, start, None);
            for step in 1..=prog.derive {
                let next = derive::step(&prog, &s, step, 7, Limits::default()).expect("step");
                let whole = draw(&prog, &next, start, None);
                let before = sketch.drawn.segments.len();
                let (old, new) = (&s, &next);
                // As `redraw` chooses, and copying every run it can.
                let chosen = redraw(&prog, old, draw(&prog, old, start, None), new, start, None);
                assert_eq!(
                    bits(&chosen.drawn),
                    bits(&whole.drawn),
                    "{text} step {step}"
                );
                sketch = copy_runs(&prog, old, sketch, new, start, None);
                assert_eq!(
                    bits(&sketch.drawn),
                    bits(&whole.drawn),
                    "{text} step {step}"
                );
                copied += before.min(sketch.drawn.segments.len());
                s = next;
            }
            assert!(sketch.drawn.segments.len() > 20, "{text}");
        }
        assert!(copied > 1000, "{copied}");
    }
}
