//! The turtle: a derived module string to geometry, sent to a `Sink`.
//!
//! Owns: the turtle conventions of the contract (start at the origin heading +y;
//! `+` turns left, counter-clockwise seen from +z; `&` pitches H toward −U; `\`
//! rolls L toward U; `|` is 180° about U; `$` rolls L horizontal), scale `*`,
//! width `!`, colour `'`, polygons `{ . }`, element printing, and interpretation
//! (homomorphism) rules. Every rotation is right-handed about its axis
//! (+ about U, & about L, \ about H), so 2D and 3D programs agree.
//! Must not know output formats: it only calls the sink.

use crate::compile::{Action, Program, Sym};
use crate::derive::{DeriveError, Limits, ModString};
use crate::vm::{Random, VmError};
use glam::DVec3;

/// How deep interpretation rules may expand into each other.
pub const MAX_INTERPRET_DEPTH: usize = 64;

/// The most modules interpretation rules may expand one module of the string
/// into (a leaf, a flower: tens to thousands). The whole drawing is bounded by
/// the module limit as well.
pub const MAX_EXPANSION: usize = 1_000_000;

/// Where the geometry goes.
pub trait Sink {
    /// A drawn segment from `a` to `b`. `width` 0 is a hairline.
    fn segment(&mut self, a: DVec3, b: DVec3, width: f64, color: u32);
    /// A filled polygon.
    fn polygon(&mut self, points: &[DVec3], color: u32);
    /// Element `index` printed at `at`, its local +y along `h`, its local −x along
    /// `l` (so local +x is −l), scaled by `scale`.
    fn element(&mut self, index: u16, at: DVec3, h: DVec3, l: DVec3, scale: f64, color: u32);
    /// The branch contour of the segments that follow: the element `Some(i)`
    /// (declared with `contour`) or `None` for the circle. Only meshes listen.
    fn contour(&mut self, _element: Option<u16>) {}
    /// Query module number `module` of the string (kind: index into
    /// `query::QUERIES`) met with the turtle in `state`. Only the environment
    /// of a scene listens.
    fn query(&mut self, _module: usize, _kind: u8, _state: &State) {}
}

/// Sends everything drawn to two sinks, the first first.
pub struct Tee<'a>(pub &'a mut dyn Sink, pub &'a mut dyn Sink);

impl Sink for Tee<'_> {
    fn segment(&mut self, a: DVec3, b: DVec3, width: f64, color: u32) {
        self.0.segment(a, b, width, color);
        self.1.segment(a, b, width, color);
    }
    fn polygon(&mut self, points: &[DVec3], color: u32) {
        self.0.polygon(points, color);
        self.1.polygon(points, color);
    }
    fn element(&mut self, index: u16, at: DVec3, h: DVec3, l: DVec3, scale: f64, color: u32) {
        self.0.element(index, at, h, l, scale, color);
        self.1.element(index, at, h, l, scale, color);
    }
    fn contour(&mut self, element: Option<u16>) {
        self.0.contour(element);
        self.1.contour(element);
    }
    fn query(&mut self, module: usize, kind: u8, state: &State) {
        self.0.query(module, kind, state);
        self.1.query(module, kind, state);
    }
}

/// The turtle's state, saved by `[` and restored by `]`.
#[derive(Clone, Copy, Debug)]
pub struct State {
    pub pos: DVec3,
    pub h: DVec3,
    pub l: DVec3,
    pub u: DVec3,
    pub scale: f64,
    pub width: f64,
    pub color: u32,
    /// The elasticity e of tropism: after each `F` the heading turns toward
    /// the lsystem's tropism vector T by e·|H × T| radians.
    pub elasticity: f64,
    /// The branch contour: 0 for the circle, element index + 1 otherwise.
    pub contour: u16,
}

impl Default for State {
    fn default() -> State {
        State {
            pos: DVec3::ZERO,
            h: DVec3::Y,
            l: DVec3::NEG_X,
            u: DVec3::Z,
            scale: 1.0,
            width: 0.0,
            color: 0,
            elasticity: 0.0,
            contour: 0,
        }
    }
}

/// The tropism vector T of programs that set an elasticity without a
/// `tropism` statement: down, against the turtle's start heading.
pub const DEFAULT_TROPISM: [f64; 3] = [0.0, -1.0, 0.0];

/// The sine and cosine of the last angle turned by: most turns of a program are
/// by the same angle, so most need no trigonometry.
#[derive(Clone, Copy, Debug)]
struct Trig {
    deg: f64,
    sin: f64,
    cos: f64,
}

impl Trig {
    fn of(&mut self, deg: f64) -> (f64, f64) {
        // Bit for bit: the cache gives what `sin_cos` gives for this very
        // angle (for −0 too), whatever turned before.
        if deg.to_bits() != self.deg.to_bits() {
            let (s, c) = deg.to_radians().sin_cos();
            *self = Trig {
                deg,
                sin: s,
                cos: c,
            };
        }
        (self.sin, self.cos)
    }
}

/// Rotates `a` toward `b` by the angle with sine `s` and cosine `c` (a, b orthonormal).
fn turn(a: DVec3, b: DVec3, (s, c): (f64, f64)) -> (DVec3, DVec3) {
    (a * c + b * s, b * c - a * s)
}

fn neg((s, c): (f64, f64)) -> (f64, f64) {
    (-s, c)
}

impl State {
    fn apply(
        &mut self,
        action: Action,
        arg: Option<f64>,
        (angle, step, palette_last): (f64, f64, Option<u32>),
        trig: &mut Trig,
    ) {
        let a = arg.unwrap_or(angle);
        let mut sc = || trig.of(a);
        match action {
            // Right-handed about U: H toward L (counter-clockwise seen from +z).
            Action::TurnLeft => (self.h, self.l) = turn(self.h, self.l, sc()),
            Action::TurnRight => (self.h, self.l) = turn(self.h, self.l, neg(sc())),
            // Right-handed about L: H toward −U.
            Action::PitchDown => (self.h, self.u) = turn(self.h, self.u, neg(sc())),
            Action::PitchUp => (self.h, self.u) = turn(self.h, self.u, sc()),
            // Right-handed about H: L toward U.
            Action::RollLeft => (self.l, self.u) = turn(self.l, self.u, sc()),
            Action::RollRight => (self.l, self.u) = turn(self.l, self.u, neg(sc())),
            Action::TurnAround => {
                self.h = -self.h;
                self.l = -self.l;
            }
            Action::RollHorizontal => {
                // L perpendicular to "up" (+y, against gravity) and to H.
                let l = DVec3::Y.cross(self.h);
                if l.length_squared() > 1e-18 {
                    self.l = l.normalize();
                    self.u = self.h.cross(self.l);
                }
            }
            Action::Scale => self.scale *= arg.unwrap_or(1.0),
            Action::Width => {
                self.width = match arg {
                    Some(w) => w.max(0.0),
                    None => self.width * 0.7,
                }
            }
            Action::Color => {
                self.color = match arg {
                    Some(c) => c.max(0.0) as u32,
                    None => match palette_last {
                        // With a palette: the next colour, up to its last index.
                        Some(last) => (self.color + 1).min(last.max(self.color)),
                        // ABOP's bare `'` steps toward leaves: from ink or bark
                        // straight to the first green (3), then along the greens to 7.
                        None => (self.color + 1).clamp(3, 7),
                    },
                }
            }
            Action::Draw | Action::Move => {
                self.pos += self.h * (arg.unwrap_or(step) * self.scale);
            }
            _ => {}
        }
    }

    /// Bends the frame toward `t` (ABOP §2.2): a rotation by e·|H × T| radians
    /// about H × T, which turns H toward T.
    pub fn bend(&mut self, t: DVec3) {
        let axis = self.h.cross(t);
        let len = axis.length();
        if self.elasticity == 0.0 || len < 1e-12 {
            return;
        }
        let q = glam::DQuat::from_axis_angle(axis / len, self.elasticity * len);
        self.h = (q * self.h).normalize();
        self.l = (q * self.l).normalize();
        self.u = self.h.cross(self.l);
    }
}

/// The settings the turtle's moves read: default angle and step, and the
/// last index of the program's palette (bare `'` stops there).
fn settings(prog: &Program) -> (f64, f64, Option<u32>) {
    (prog.angle, prog.step, prog.palette.last().map(|c| c.index))
}

/// What was drawn.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Drawn {
    pub segments: u64,
    pub elements: u64,
    pub polygons: u64,
    /// [min x, min y, max x, max y] of drawn geometry (segments, polygon points,
    /// element outlines by their control points); `None` when nothing was drawn.
    pub bbox: Option<[f64; 4]>,
}

impl Drawn {
    /// Adds the counts and box of `other` (what was drawn after, or beside).
    pub fn add(&mut self, other: &Drawn) {
        self.segments += other.segments;
        self.elements += other.elements;
        self.polygons += other.polygons;
        if let Some(b) = other.bbox {
            let t = self.bbox.get_or_insert(b);
            *t = [
                t[0].min(b[0]),
                t[1].min(b[1]),
                t[2].max(b[2]),
                t[3].max(b[3]),
            ];
        }
    }

    fn grow(&mut self, p: DVec3) {
        let b = self.bbox.get_or_insert([p.x, p.y, p.x, p.y]);
        b[0] = b[0].min(p.x);
        b[1] = b[1].min(p.y);
        b[2] = b[2].max(p.x);
        b[3] = b[3].max(p.y);
    }
}

/// Interprets a derived string. Interpretation rules are applied as the turtle
/// meets their modules (random choices keyed by `seed` and position).
pub fn interpret(
    prog: &Program,
    s: &ModString,
    seed: u64,
    sink: &mut dyn Sink,
) -> Result<Drawn, DeriveError> {
    interpret_from(prog, s, seed, State::default(), sink)
}

/// Interprets from a given start state (a seed's position and heading), with
/// the default limits.
pub fn interpret_from(
    prog: &Program,
    s: &ModString,
    seed: u64,
    start: State,
    sink: &mut dyn Sink,
) -> Result<Drawn, DeriveError> {
    interpret_limited(prog, s, seed, start, Limits::default(), sink)
}

/// Interprets from a start state. The modules interpretation rules expand into
/// count against `limits.max_modules`, with the string's own: a rule that
/// doubles at every level cannot run for hours.
pub fn interpret_limited(
    prog: &Program,
    s: &ModString,
    seed: u64,
    start: State,
    limits: Limits,
    sink: &mut dyn Sink,
) -> Result<Drawn, DeriveError> {
    run(prog, s, seed, start, limits, sink, &[])
}

/// Interprets as `interpret_limited` for the query modules only: a branch
/// `[ … ]` of the string that holds no query module (and no module whose
/// interpretation rules make one) is passed over, as its state ends where
/// it began. The sink is asked about every query module with the state
/// `interpret_limited` has there; it is given only part of the drawing, and
/// the counts are of that part. (An environment's system whose drawing no
/// query reads needs no more between its steps.)
pub fn interpret_queries(
    prog: &Program,
    s: &ModString,
    seed: u64,
    start: State,
    limits: Limits,
    sink: &mut dyn Sink,
) -> Result<Drawn, DeriveError> {
    let skip = quiet_branches(prog, s);
    run(prog, s, seed, start, limits, sink, &skip)
}

/// The outermost branches of `s` that ask nothing, in order: where each
/// opens, the module after its `]` and the parameter that one starts at.
/// None when an interpretation rule makes a bracket or rewrites one (then the
/// string's brackets need not be the turtle's).
fn quiet_branches(prog: &Program, s: &ModString) -> Vec<(u32, u32, u32)> {
    let info = &prog.symbols.info;
    let rules = |x: usize| prog.interpret.get(x).map_or(&[][..], Vec::as_slice);
    let bracket = |x: usize| matches!(info[x].action, Action::Push | Action::Pop);
    // Per symbol: whether interpreting it meets a query module (its own rules'
    // successors, to any depth), or a bracket.
    let mut asks: Vec<bool> = info
        .iter()
        .map(|i| matches!(i.action, Action::Query(_)))
        .collect();
    let mut brackets: Vec<bool> = (0..info.len())
        .map(|x| bracket(x) && !rules(x).is_empty())
        .collect();
    loop {
        let mut changed = false;
        for x in 0..info.len() {
            for e in rules(x).iter().flat_map(|r| &r.succ) {
                let y = e.sym as usize;
                let (a, b) = (asks[y], brackets[y] || bracket(y));
                if (a && !asks[x]) || (b && !brackets[x]) {
                    asks[x] |= a;
                    brackets[x] |= b;
                    changed = true;
                }
            }
        }
        if !changed {
            break;
        }
    }
    let mut out: Vec<(u32, u32, u32)> = Vec::new();
    if brackets.iter().any(|b| *b) {
        return out;
    }
    // Open branches: where each opened and whether it asks.
    let mut open: Vec<(u32, bool)> = Vec::new();
    let mut p = 0u32;
    for (i, &sym) in s.syms.iter().enumerate() {
        let x = sym as usize;
        p += prog.symbols.arity(sym) as u32;
        match info[x].action {
            Action::Push => open.push((i as u32, false)),
            Action::Pop => {
                if let Some((at, asked)) = open.pop() {
                    if asked {
                        if let Some(outer) = open.last_mut() {
                            outer.1 = true;
                        }
                    } else {
                        // The quiet branches inside it closed after it opened.
                        while out.last().is_some_and(|b| b.0 > at) {
                            out.pop();
                        }
                        out.push((at, i as u32 + 1, p));
                    }
                }
            }
            _ if asks[x] => {
                if let Some(inner) = open.last_mut() {
                    inner.1 = true;
                }
            }
            _ => {}
        }
    }
    out
}

/// How many modules the turtle interprets between looks at `Limits::cancel`.
const CANCEL_EVERY: usize = 1 << 14;

fn run(
    prog: &Program,
    s: &ModString,
    seed: u64,
    start: State,
    limits: Limits,
    sink: &mut dyn Sink,
    skip: &[(u32, u32, u32)],
) -> Result<Drawn, DeriveError> {
    let mut start = start;
    if let Some((_, e)) = prog.tropism {
        start.elasticity = e;
    }
    let tropism = DVec3::from(prog.tropism.map_or(DEFAULT_TROPISM, |t| t.0));
    let mut t = Turtle {
        tropism,
        expanded: s.len(),
        max_modules: limits.max_modules,
        expanded_here: 0,
        prog,
        sink,
        state: start,
        module_index: 0,
        stack: Vec::new(),
        polygons: Vec::new(),
        drawn: Drawn::default(),
        seed,
        stack_vm: Vec::new(),
        trig: Trig {
            deg: 0.0,
            sin: 0.0,
            cos: 1.0,
        },
        cands: Vec::new(),
        element_boxes: prog.elements.iter().map(element_box).collect(),
    };
    let has_interp = prog.interpret.iter().any(|r| !r.is_empty());
    let mut p = 0usize;
    let mut i = 0usize;
    // The next branch to pass over.
    let mut next = 0usize;
    while i < s.syms.len() {
        if let Some(&(_, end, params_end)) = skip.get(next).filter(|b| b.0 as usize == i) {
            // A branch that asks nothing: its state ends where it began.
            i = end as usize;
            p = params_end as usize;
            next += 1;
            continue;
        }
        if i.is_multiple_of(CANCEL_EVERY)
            && limits
                .cancel
                .is_some_and(|c| c.load(std::sync::atomic::Ordering::Relaxed))
        {
            return Err(DeriveError::Cancelled { step: u32::MAX });
        }
        let sym = s.syms[i];
        let n = prog.symbols.arity(sym);
        let params = &s.params[p..p + n];
        p += n;
        t.module_index = i;
        if has_interp && !prog.interpret[sym as usize].is_empty() {
            // A query drawn by an interpretation rule is still answered where it stands.
            if let Action::Query(kind) = prog.symbols.info[sym as usize].action {
                let st = t.state;
                t.sink.query(i, kind, &st);
            }
            t.expanded_here = 0;
            t.expand(sym, params, i as u64, 0)?;
        } else {
            t.module(sym, params);
        }
        i += 1;
    }
    Ok(t.drawn)
}

/// The turtle of `interpret`, driven a run of modules at a time by a caller
/// that keeps the sink and may set the turtle's state and stack between runs
/// (the environment redraws only what changed in a string). Only for programs
/// without interpretation rules; the drawing is the one `interpret_from` makes
/// when the runs cover the string in order.
pub struct Stepper<'p> {
    prog: &'p Program,
    tropism: DVec3,
    pub state: State,
    pub stack: Vec<State>,
    polygons: Vec<Vec<DVec3>>,
    trig: Trig,
}

impl<'p> Stepper<'p> {
    /// A turtle at `start`, as `interpret_from` starts it.
    pub fn new(prog: &'p Program, start: State) -> Stepper<'p> {
        let mut state = start;
        if let Some((_, e)) = prog.tropism {
            state.elasticity = e;
        }
        Stepper {
            prog,
            tropism: DVec3::from(prog.tropism.map_or(DEFAULT_TROPISM, |t| t.0)),
            state,
            stack: Vec::new(),
            polygons: Vec::new(),
            trig: Trig {
                deg: 0.0,
                sin: 0.0,
                cos: 1.0,
            },
        }
    }

    /// Whether a polygon is open (`{` without its `}`).
    pub fn in_polygon(&self) -> bool {
        !self.polygons.is_empty()
    }

    /// Interprets `syms` (module `first` of the string onwards; `params` are
    /// theirs, in order) into `sink`. With `below = Some(d)` it stops after
    /// the first `]` that leaves fewer than `d` states on the stack, outside
    /// any polygon. Returns how many modules it interpreted.
    pub fn run(
        &mut self,
        sink: &mut dyn Sink,
        syms: &[Sym],
        params: &[f64],
        first: usize,
        below: Option<usize>,
    ) -> usize {
        let mut t = Turtle {
            prog: self.prog,
            tropism: self.tropism,
            sink,
            state: self.state,
            stack: std::mem::take(&mut self.stack),
            polygons: std::mem::take(&mut self.polygons),
            drawn: Drawn::default(),
            seed: 0,
            stack_vm: Vec::new(),
            trig: self.trig,
            cands: Vec::new(),
            module_index: first,
            expanded: 0,
            max_modules: usize::MAX,
            expanded_here: 0,
            element_boxes: Vec::new(),
        };
        let mut p = 0;
        let mut done = syms.len();
        for (k, &sym) in syms.iter().enumerate() {
            let n = t.prog.symbols.arity(sym);
            t.module_index = first + k;
            t.module(sym, &params[p..p + n]);
            p += n;
            if let Some(d) = below
                && t.stack.len() < d
                && t.polygons.is_empty()
                && t.prog.symbols.info[sym as usize].action == Action::Pop
            {
                done = k + 1;
                break;
            }
        }
        self.state = t.state;
        self.stack = t.stack;
        self.polygons = t.polygons;
        self.trig = t.trig;
        done
    }
}

struct Turtle<'a> {
    prog: &'a Program,
    /// The tropism vector T.
    tropism: DVec3,
    sink: &'a mut dyn Sink,
    state: State,
    stack: Vec<State>,
    polygons: Vec<Vec<DVec3>>,
    drawn: Drawn,
    seed: u64,
    stack_vm: Vec<f64>,
    trig: Trig,
    /// Candidates of a stochastic interpretation rule (reused).
    cands: Vec<(usize, f64)>,
    /// Index of the module being interpreted (for query answers).
    module_index: usize,
    /// Modules interpreted so far, expansions included, and the most allowed.
    expanded: usize,
    max_modules: usize,
    /// Modules the current module of the string has expanded into.
    expanded_here: usize,
    /// Each element's box in its own frame, for `Drawn::bbox`.
    element_boxes: Vec<Option<(DVec3, DVec3)>>,
}

/// An element's box in its own frame (x along −L, y along H, z along U): its
/// outline's control points, or its organ's mesh.
pub fn element_box(e: &crate::compile::ElementDef) -> Option<(DVec3, DVec3)> {
    if let Some(solid) = &e.solid {
        return solid.bounds();
    }
    let b = crate::path::control_bounds(&crate::path::parse(&e.path).ok()?)?;
    Some((DVec3::new(b[0], b[1], 0.0), DVec3::new(b[2], b[3], 0.0)))
}

/// The eight corners of a box.
pub fn corners((lo, hi): (DVec3, DVec3)) -> [DVec3; 8] {
    std::array::from_fn(|k| {
        DVec3::new(
            if k & 1 == 0 { lo.x } else { hi.x },
            if k & 2 == 0 { lo.y } else { hi.y },
            if k & 4 == 0 { lo.z } else { hi.z },
        )
    })
}

impl Turtle<'_> {
    /// Applies the first matching interpretation rule of `sym` and interprets its
    /// successor in place of the module.
    fn expand(
        &mut self,
        sym: Sym,
        params: &[f64],
        position: u64,
        depth: usize,
    ) -> Result<(), DeriveError> {
        if depth >= MAX_INTERPRET_DEPTH {
            return Err(DeriveError::InterpretTooDeep {
                module: self.prog.symbols.info[sym as usize]
                    .name
                    .text()
                    .into_owned(),
                depth,
            });
        }
        let prog = self.prog;
        let vm = |error: VmError| DeriveError::Vm {
            step: u32::MAX,
            error,
        };
        let mut rng = Random::new(self.seed ^ 0x1e7e_3b1d, u32::MAX - depth as u32, position);
        let mut chosen = None;
        let rules = &prog.interpret[sym as usize];
        let mut k = 0;
        // Interpretation rules have no context: conditions and weights only.
        while k < rules.len() && chosen.is_none() {
            let group = rules[k].group;
            let end = k + rules[k..].iter().take_while(|r| r.group == group).count();
            let mut cands = std::mem::take(&mut self.cands);
            cands.clear();
            for (idx, r) in rules[k..end].iter().enumerate() {
                let ok = match r.cond {
                    Some(c) => {
                        prog.chunk
                            .eval(c, params, &mut rng, &mut self.stack_vm)
                            .map_err(vm)?
                            != 0.0
                    }
                    None => true,
                };
                if !ok {
                    continue;
                }
                let w = match r.weight {
                    Some(c) => prog
                        .chunk
                        .eval(c, params, &mut rng, &mut self.stack_vm)
                        .map_err(vm)?,
                    None => 1.0,
                };
                if r.weight.is_none() {
                    cands.push((k + idx, 1.0));
                    break;
                }
                if w > 0.0 {
                    cands.push((k + idx, w));
                }
            }
            if let Some(pick) = rng.pick(&cands) {
                chosen = Some(&rules[pick]);
            }
            self.cands = cands;
            k = end;
        }
        let Some(rule) = chosen else {
            self.module(sym, params);
            return Ok(());
        };
        self.expanded = self.expanded.saturating_add(rule.succ.len());
        self.expanded_here = self.expanded_here.saturating_add(rule.succ.len());
        if self.expanded > self.max_modules || self.expanded_here > MAX_EXPANSION {
            let one = self.expanded_here > MAX_EXPANSION;
            return Err(DeriveError::TooMuchDrawing {
                limit: if one { MAX_EXPANSION } else { self.max_modules },
                module: one.then(|| {
                    self.prog.symbols.info[sym as usize]
                        .name
                        .text()
                        .into_owned()
                }),
            });
        }
        for e in &rule.succ {
            // Up to 16 parameters live on the stack; more go to the heap.
            let mut small = [0.0f64; 16];
            let mut big = Vec::new();
            let args: &mut [f64] = if e.args.len() <= small.len() {
                &mut small[..e.args.len()]
            } else {
                big.resize(e.args.len(), 0.0);
                &mut big
            };
            for (slot, code) in args.iter_mut().zip(&e.args) {
                *slot = prog
                    .chunk
                    .eval(*code, params, &mut rng, &mut self.stack_vm)
                    .map_err(vm)?;
            }
            if prog.interpret[e.sym as usize].is_empty() {
                self.module(e.sym, args);
            } else {
                self.expand(e.sym, args, position, depth + 1)?;
            }
        }
        Ok(())
    }

    fn module(&mut self, sym: Sym, params: &[f64]) {
        let prog = self.prog;
        let action = prog.symbols.info[sym as usize].action;
        let arg = params.first().copied();
        match action {
            Action::Draw | Action::Move => {
                let from = self.state.pos;
                self.state
                    .apply(action, arg, settings(prog), &mut self.trig);
                let to = self.state.pos;
                if action == Action::Draw {
                    self.state.bend(self.tropism);
                }
                if let Some(poly) = self.polygons.last_mut() {
                    if poly.is_empty() {
                        poly.push(from);
                    }
                    poly.push(to);
                } else if action == Action::Draw {
                    self.drawn.segments += 1;
                    self.drawn.grow(from);
                    self.drawn.grow(to);
                    self.sink
                        .segment(from, to, self.state.width, self.state.color);
                }
            }
            Action::Push => self.stack.push(self.state),
            Action::Pop => {
                if let Some(s) = self.stack.pop() {
                    let contour = self.state.contour;
                    self.state = s;
                    if s.contour != contour {
                        self.sink.contour(s.contour.checked_sub(1));
                    }
                }
            }
            Action::PolygonStart => self.polygons.push(Vec::new()),
            Action::Vertex => {
                let p = self.state.pos;
                if let Some(poly) = self.polygons.last_mut()
                    && poly.last() != Some(&p)
                {
                    poly.push(p);
                }
            }
            Action::PolygonEnd => {
                if let Some(mut poly) = self.polygons.pop() {
                    if poly.len() > 1 && poly.first() == poly.last() {
                        poly.pop();
                    }
                    if poly.len() >= 3 {
                        self.drawn.polygons += 1;
                        for &p in &poly {
                            self.drawn.grow(p);
                        }
                        self.sink.polygon(&poly, self.state.color);
                    }
                }
            }
            Action::Element(i)
                if prog
                    .elements
                    .get(i as usize)
                    .is_some_and(|e| e.is_contour()) =>
            {
                // Selects the contour of the branches that follow (until `]`).
                if self.state.contour != i + 1 {
                    self.state.contour = i + 1;
                    self.sink.contour(Some(i));
                }
            }
            Action::Element(i) => {
                self.drawn.elements += 1;
                let st = self.state;
                self.drawn.grow(st.pos);
                if let Some(&Some(b)) = self.element_boxes.get(i as usize) {
                    // The element's box, placed as the sinks place the element.
                    let u = st.h.cross(st.l);
                    for c in corners(b) {
                        self.drawn
                            .grow(st.pos + (-st.l * c.x + st.h * c.y + u * c.z) * st.scale);
                    }
                }
                self.sink.element(i, st.pos, st.h, st.l, st.scale, st.color);
            }
            Action::Query(kind) => {
                let st = self.state;
                self.sink.query(self.module_index, kind, &st);
            }
            Action::Elasticity => {
                self.state.elasticity = arg.unwrap_or(prog.tropism.map_or(0.0, |t| t.1));
            }
            Action::None | Action::Cut => {}
            other => self.state.apply(other, arg, settings(prog), &mut self.trig),
        }
    }
}

/// Whether the program holds a turtle query (`?P ?H ?U ?L`).
pub fn has_turtle_queries(prog: &Program) -> bool {
    prog.symbols.info.iter().any(|i| match i.action {
        Action::Query(k) => crate::query::QUERIES[k as usize].kind.is_turtle(),
        _ => false,
    })
}

/// Records the turtle's state at each query module of the string itself.
struct Answers {
    at: Vec<(usize, u8, State)>,
}

impl Sink for Answers {
    fn segment(&mut self, _: DVec3, _: DVec3, _: f64, _: u32) {}
    fn polygon(&mut self, _: &[DVec3], _: u32) {}
    fn element(&mut self, _: u16, _: DVec3, _: DVec3, _: DVec3, _: f64, _: u32) {}
    fn query(&mut self, module: usize, kind: u8, state: &State) {
        if crate::query::QUERIES[kind as usize].kind.is_turtle() {
            self.at.push((module, kind, *state));
        }
    }
}

/// Answers the turtle queries of `s` as cpfg does: the string is interpreted
/// and each `?P ?H ?U ?L` receives the position or the frame vector the turtle
/// has where it stands. A query that an interpretation rule produces (not in the
/// string itself) is not answered.
pub fn answer_queries(
    prog: &Program,
    s: &mut ModString,
    seed: u64,
    limits: Limits,
) -> Result<(), DeriveError> {
    let mut sink = Answers { at: Vec::new() };
    interpret_limited(prog, s, seed, State::default(), limits, &mut sink)?;
    if sink.at.is_empty() {
        return Ok(());
    }
    let mut offset = Vec::with_capacity(s.len());
    let mut p = 0;
    for &x in &s.syms {
        offset.push(p);
        p += prog.symbols.arity(x);
    }
    for (i, kind, st) in sink.at {
        let sym = s.syms[i] as usize;
        // Only the module itself: an interpretation rule may have met one.
        if prog.symbols.info[sym].action != Action::Query(kind) || prog.symbols.arity(s.syms[i]) < 3
        {
            continue;
        }
        let v = match crate::query::QUERIES[kind as usize].kind {
            crate::query::QueryKind::Position => st.pos,
            crate::query::QueryKind::Heading => st.h,
            crate::query::QueryKind::Up => st.u,
            _ => st.l,
        };
        s.params[offset[i]..offset[i] + 3].copy_from_slice(&[v.x, v.y, v.z]);
    }
    Ok(())
}

/// Derives as `derive::derive` does, and answers the turtle queries of the
/// string after each step (and on the start string) when the program has any.
pub fn derive(
    prog: &Program,
    start: ModString,
    steps: u32,
    seed: u64,
    limits: Limits,
    progress: &(dyn Fn(u32, usize) + Sync),
) -> Result<ModString, DeriveError> {
    if !has_turtle_queries(prog) {
        return crate::derive::derive(prog, start, steps, seed, limits, progress);
    }
    crate::derive::derive_with(prog, start, steps, seed, limits, progress, &mut |s, _| {
        answer_queries(prog, s, seed, limits)
    })
}

/// A sink that only counts (for `--stats` without output, and tests).
pub struct Discard;

impl Sink for Discard {
    fn segment(&mut self, _: DVec3, _: DVec3, _: f64, _: u32) {}
    fn polygon(&mut self, _: &[DVec3], _: u32) {}
    fn element(&mut self, _: u16, _: DVec3, _: DVec3, _: DVec3, _: f64, _: u32) {}
}
