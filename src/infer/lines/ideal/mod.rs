//! A noisy line drawing redrawn as the turtle meant it: every step of the
//! stroke graph, in the paths' order, one step long along a multiple of δ.
//!
//! A jittered or hand-traced drawing in turtle order fails the exact
//! reading (its turns are not whole multiples of one angle, its pieces not
//! whole numbers of steps). One step alone often does not say which
//! multiple of δ it turns (at 22.5°, two vertices a fifth of a step off
//! turn a step by half a δ), but the walk does: the turtle's vertices lie
//! on its lattice, and a step read one δ wrong leaves every later vertex of
//! the walk off the drawing's. So each path is decoded as a whole, by a
//! beam over the lattice points the walk may reach:
//!
//! - roughly first, for every δ = 360/m (m ≤ 36): the walk's shape over
//!   its last few steps against the drawing's (the frame, the drawing's
//!   scale, turn and place, is only roughly known yet: a little off, it
//!   moves far vertices far and near ones little), the frame then fitted
//!   to the walk;
//! - closely for the likeliest δ: every vertex against the drawing's, in a
//!   frame fitted again as the walk goes (near its start a rough frame errs
//!   little), then once more in the frame fitted to all of it; the rough
//!   walk stays when it says the drawing in fewer bits. A step that no way
//!   keeps within the bound (both its vertices off, each its own way)
//!   takes the nearest ways, unbounded, rather than end the walk.
//!
//! A path that starts where no path came before starts across a gap from
//! where the last one ended: the turtle moved there by whole steps (`f`),
//! so its start is the lattice point that one or two straight runs of
//! moves from that end reach nearest the start as drawn (the likeliest by
//! the same bits: its offset, each run's way and length), in the frame
//! fitted again to the walk so far (a gap of a hundred steps is read as
//! well as the frame's scale is known). A gap no such runs explain keeps
//! its drawn start.
//!
//! The steps cut from one drawn segment go its one way: its points between
//! the drawn ends were not drawn and carry their ends' noise, so reading
//! them one by one would bend a straight segment.
//!
//! A walk's cost in the beam is in bits: its offsets from the drawing (a
//! normal spread of the drawing's noise) and its turns, each said after
//! the walk's turns so far (an adaptive code over their sizes). On a fine
//! lattice many walks stay as near a noisy drawing as the turtle's; the
//! turtle's turns are few kinds, and a walk that follows the noise pays
//! for its turns.
//!
//! δ is the one whose walk is the shortest to say with the drawing's
//! offsets from it (its turns' LZ78 phrases and the offsets' spread): a
//! finer lattice fits the noise a little better but its walk repeats
//! itself less, as a coarser one's fits worse. LZ78 is a loose measure of
//! a grammar's size, so the two shortest redrawings are given back, and
//! the grammar search tells them apart. Before that the small subtrees
//! at a branching walk's ends are read again as its other subtrees say
//! (`agree`). A vertex keeps the position
//! it got first, so a branch starts where its parent passed and a curve
//! that comes back to a vertex must come back to its lattice point. The
//! redrawing is refused when a vertex of it lies more than half a step
//! from the drawing's. It is read and searched as a clean drawing, and the
//! program must draw it exactly.
//!
//! Owns: the redrawing. Must not search grammars.

mod agree;

use super::graph::Graph;
use super::synth;
use glam::DVec2;
use std::collections::HashSet;
use std::f64::consts::TAU;

/// How noisy (in steps) a drawing must be to be redrawn: a clean one is
/// read as it is.
pub const NOISY: f64 = 0.005;

/// The most steps of δ a full turn is tried at.
const MOST: u32 = 36;
/// Walks kept per step (after those at one lattice point are merged).
const BEAM: usize = 128;
/// The same for a rough walk (merged only where their last steps agree).
const ROUGH_BEAM: usize = 64;
/// Steps back a rough walk's shape is compared with the drawing's over.
const WINDOW: usize = 4;
/// Steps of a long drawing every δ is walked over roughly (its start);
/// the `LIKELY` likeliest δ are then walked over all of it.
const PREFIX: usize = 256;
/// See `PREFIX`.
const LIKELY: usize = 8;
/// Redrawings given back, the likeliest first: a finer δ whose walk
/// follows the noise may say the drawing in fewer bits than the turtle's
/// (its walk's turns are said by their LZ78 phrases, a loose bound on a
/// grammar's), and only the grammar search can tell them apart.
const ALTERNATIVES: usize = 2;
/// Turns of the frame (parts of δ) a rough walk starts from: the
/// drawing's mean direction says little of it at a small δ under noise.
const PHASES: u32 = 2;
/// The δ walked closely, the likeliest after a rough walk.
const SHORTLIST: usize = 4;
/// Offsets (steps) that say nothing of δ: a lattice finer than the
/// drawing's gains nothing by fitting its rounding (a δ such as 25.7°,
/// not a whole part of a full turn, is as near 360/14 as a finer one).
const FINEST: f64 = 0.08;
/// Steps between fits of the frame as a walk goes.
const REFIT: usize = 16;

/// The graph's steps in order, each one step long along a multiple of δ,
/// as polylines placed where they fit the drawing best (a similarity,
/// least squares over the vertices): the likeliest `ALTERNATIVES`
/// redrawings, none when the drawing is not noisy, when no δ that divides
/// a full turn walks it, or when a vertex of every redrawing lies more
/// than half a step from the drawing's.
pub fn redrawn(g: &Graph) -> Vec<Vec<Vec<DVec2>>> {
    if g.noise < NOISY || g.order.is_empty() {
        return Vec::new();
    }
    let paths = paths(g);
    // Every δ walked roughly over the drawing's first steps, the likeliest
    // roughly over all of it, the likeliest of those closely.
    let start = prefix(&paths, PREFIX);
    let mut likely: Vec<(f64, u32, f64)> = (2..=MOST)
        .filter_map(|m| {
            let lattice = Lattice::new(m);
            let phase = synth::phase(g, 360.0 / f64::from(m)).unwrap_or(0.0);
            (0..PHASES)
                .filter_map(|j| {
                    let phase = phase + f64::from(j) * lattice.delta / f64::from(PHASES);
                    Some((rough(g, &start, &lattice, phase)?.bits, m, phase))
                })
                .min_by(|a, b| a.0.total_cmp(&b.0))
        })
        .collect();
    likely.sort_by(|a, b| a.0.total_cmp(&b.0));
    if g.order.len() > PREFIX {
        likely.truncate(LIKELY);
    }
    let mut rough: Vec<(Lattice, Walked)> = likely
        .into_iter()
        .filter_map(|(_, m, phase)| {
            let lattice = Lattice::new(m);
            let w = rough(g, &paths, &lattice, phase)?;
            Some((lattice, w))
        })
        .collect();
    rough.sort_by(|a, b| a.1.bits.total_cmp(&b.1.bits));
    rough.truncate(SHORTLIST);
    let mut walks: Vec<Walked> = rough
        .into_iter()
        .filter_map(|(lattice, w)| {
            let w = agree::agreed(g, &paths, &lattice, close(g, &paths, &lattice, w)?);
            Walked::new(g, &paths, &lattice, w.at)
        })
        .collect();
    walks.sort_by(|a, b| a.bits.total_cmp(&b.bits));
    walks
        .iter()
        .filter_map(|w| placed(g, &paths, w))
        .take(ALTERNATIVES)
        .collect()
}

/// The walk `w` placed where it fits the drawing best, as polylines;
/// `None` when a vertex of it lies more than half a step from the
/// drawing's.
fn placed(g: &Graph, paths: &[Vec<u32>], w: &Walked) -> Option<Vec<Vec<DVec2>>> {
    let pairs: Vec<(DVec2, DVec2)> =
        w.at.iter()
            .enumerate()
            .filter_map(|(v, l)| l.map(|l| (l, g.points[v])))
            .collect();
    let place = Similarity::fit(&pairs)?;
    let worst = pairs
        .iter()
        .map(|&(l, p)| place.apply(l).distance(p))
        .fold(0.0, f64::max);
    if worst > 0.5 * g.step {
        return None;
    }
    Some(
        paths
            .iter()
            .map(|l| {
                l.iter()
                    .filter_map(|&v| w.at[v as usize])
                    .map(|l| place.apply(l))
                    .collect()
            })
            .collect(),
    )
}

/// The spread (steps) a walk's offsets from the drawing are costed at:
/// the drawing's noise, but not below a twentieth of a step.
fn sigma(g: &Graph) -> f64 {
    g.noise.max(0.05)
}

/// The first `n` steps of `paths` (all of them when there are fewer).
fn prefix(paths: &[Vec<u32>], mut n: usize) -> Vec<Vec<u32>> {
    let mut out = Vec::new();
    for p in paths {
        if n == 0 {
            break;
        }
        let take = (p.len() - 1).min(n);
        out.push(p[..=take].to_vec());
        n -= take;
    }
    out
}

/// The graph's steps in order as paths of vertices (a new path wherever a
/// step does not start where the last ended).
fn paths(g: &Graph) -> Vec<Vec<u32>> {
    let mut out: Vec<Vec<u32>> = Vec::new();
    let mut last = u32::MAX;
    for &(a, b) in &g.order {
        if a != last {
            out.push(vec![a]);
        }
        if let Some(l) = out.last_mut() {
            l.push(b);
        }
        last = b;
    }
    out
}

/// A walk of the drawing on a lattice.
#[derive(Clone)]
struct Walked {
    /// Each vertex's lattice point (in steps).
    at: Vec<Option<DVec2>>,
    /// From the drawing to the lattice.
    frame: Similarity,
    /// How long the walk and the drawing's offsets from it are to say.
    bits: f64,
}

/// The drawing walked roughly on `lattice` (its shape followed step by
/// step, the frame fitted to the walk), or `None` when no walk stays near
/// it.
fn rough(g: &Graph, paths: &[Vec<u32>], lattice: &Lattice, phase: f64) -> Option<Walked> {
    let origin = g.points[*paths.first()?.first()? as usize];
    let mut pass = Pass {
        lattice,
        world: &g.points,
        graph: g,
        frame: Similarity {
            from: origin,
            turn: DVec2::new((-phase).cos(), (-phase).sin()) / g.step,
            to: DVec2::ZERO,
        },
        window: WINDOW,
        bound: 1.0,
        refit: false,
        beam: ROUGH_BEAM,
        sigma: sigma(g),
    };
    let at = pass.walk(paths, &[])?;
    Walked::new(g, paths, lattice, at)
}

/// The rough walk `w` walked again with every vertex where the drawing has
/// it: in a frame fitted as the walk goes (near its start a rough frame
/// errs little), then once more in the frame fitted to all of it.
fn close(g: &Graph, paths: &[Vec<u32>], lattice: &Lattice, mut w: Walked) -> Option<Walked> {
    let mut pass = Pass {
        lattice,
        world: &g.points,
        graph: g,
        frame: w.frame,
        window: 0,
        // A few times the drawing's own noise.
        bound: (3.5 * g.noise).clamp(0.35, 1.0),
        refit: true,
        beam: BEAM,
        sigma: sigma(g),
    };
    // The rough walk when it says the drawing in fewer bits (a close pass
    // too may read a step one δ off) or no close walk stays near it.
    let rough = w.clone();
    for refit in [true, false] {
        pass.refit = refit;
        let Some(closer) = pass
            .walk(paths, &w.at)
            .and_then(|at| Walked::new(g, paths, lattice, at))
        else {
            return Some(rough);
        };
        w = closer;
        pass.frame = w.frame;
    }
    Some(if rough.bits < w.bits { rough } else { w })
}

impl Walked {
    /// The walk `at`, the frame that fits it best, and its description's
    /// length: its turns (LZ78 phrases, each an earlier phrase and a turn)
    /// and the drawing's offsets from it (a normal spread of their root
    /// mean square per coordinate, in bits less a constant).
    fn new(
        g: &Graph,
        paths: &[Vec<u32>],
        lattice: &Lattice,
        at: Vec<Option<DVec2>>,
    ) -> Option<Walked> {
        let frame = fit_to(&g.points, &at)?;
        let (mut sum, mut n) = (0.0, 0.0);
        for (v, l) in at.iter().enumerate() {
            if let Some(l) = l {
                sum += frame.apply(g.points[v]).distance_squared(*l);
                n += 1.0;
            }
        }
        let phrases = phrases(&turns(paths, &at, lattice));
        let m = lattice.units.len() as f64;
        let rms = (sum / n).sqrt().max(FINEST);
        let bits = phrases * ((phrases + 1.0).log2() + m.log2()) + 2.0 * n * rms.log2();
        Some(Walked { at, frame, bits })
    }
}

/// The turns (0..m) of the walk `at`, path by path.
fn turns(paths: &[Vec<u32>], at: &[Option<DVec2>], lattice: &Lattice) -> Vec<i64> {
    let m = lattice.units.len() as i64;
    let mut out = Vec::new();
    for path in paths {
        let ways: Vec<i64> = path
            .windows(2)
            .filter_map(|w| Some(lattice.nearest(at[w[1] as usize]? - at[w[0] as usize]?)))
            .collect();
        out.extend(ways.windows(2).map(|w| (w[1] - w[0]).rem_euclid(m)));
    }
    out
}

/// How many phrases the LZ78 parse of `s` has (a repetitive sequence has
/// few: how much a walk's turns say beyond their grammar).
fn phrases(s: &[i64]) -> f64 {
    let mut seen: HashSet<&[i64]> = HashSet::new();
    let (mut start, mut count) = (0, 0.0);
    for end in 1..=s.len() {
        if seen.insert(&s[start..end]) {
            count += 1.0;
            start = end;
        }
    }
    count + (start < s.len()) as u8 as f64
}

/// The similarity that puts the drawing's vertices (`world`) nearest their
/// lattice points (`at`).
fn fit_to(world: &[DVec2], at: &[Option<DVec2>]) -> Option<Similarity> {
    let pairs: Vec<(DVec2, DVec2)> = at
        .iter()
        .zip(world)
        .filter_map(|(l, &p)| l.map(|l| (p, l)))
        .collect();
    Similarity::fit(&pairs)
}

/// The unit steps of δ = 360/m.
struct Lattice {
    units: Vec<DVec2>,
    delta: f64,
}

impl Lattice {
    fn new(m: u32) -> Lattice {
        let delta = TAU / f64::from(m);
        let units = (0..m)
            .map(|k| {
                let a = f64::from(k) * delta;
                DVec2::new(a.cos(), a.sin())
            })
            .collect();
        Lattice { units, delta }
    }

    /// The multiple of δ nearest the way of `d`.
    fn nearest(&self, d: DVec2) -> i64 {
        (d.y.atan2(d.x) / self.delta).round() as i64
    }

    /// The sum of one or two straight runs of whole unit steps (`k·u`, or
    /// `k·u + l·v`) likeliest to be the gap `g` as drawn, within half a
    /// step of it: its offset from `g` costs d²/2σ² nats, each run the
    /// bits to say its way and its length.
    fn runs(&self, g: DVec2, sigma: f64) -> Option<DVec2> {
        let m = self.units.len();
        let way = (m as f64).log2();
        let length = |k: f64| 2.0 * (k + 1.0).log2() + 1.0;
        let mut best: Option<(f64, DVec2)> = None;
        let mut offer = |p: DVec2, bits: f64| {
            let d = p.distance(g);
            if d > 0.5 {
                return;
            }
            let cost = d * d / (2.0 * sigma * sigma) / std::f64::consts::LN_2 + bits;
            if best.is_none_or(|(c, _)| cost < c) {
                best = Some((cost, p));
            }
        };
        for (i, &u) in self.units.iter().enumerate() {
            let k = g.dot(u).round();
            if k >= 1.0 {
                offer(u * k, way + length(k));
            }
            for &v in &self.units[i + 1..] {
                let det = u.perp_dot(v);
                if det.abs() < 1e-9 {
                    continue;
                }
                let (a, b) = (g.perp_dot(v) / det, u.perp_dot(g) / det);
                for a in [a.floor(), a.ceil()] {
                    for b in [b.floor(), b.ceil()] {
                        if a >= 1.0 && b >= 1.0 {
                            offer(u * a + v * b, 2.0 * way + length(a) + length(b));
                        }
                    }
                }
            }
        }
        best.map(|(_, p)| p)
    }
}

/// A walk in the beam: its cost so far (bits), its last point in the
/// arena, the way (multiple of δ) of its last step and the count of its
/// turns so far.
#[derive(Clone, Copy)]
struct Head {
    cost: f64,
    at: u32,
    way: i64,
    turns: Turns,
}

/// A walk's turns so far, counted by size (0, ±1, ±2, ±3, more).
#[derive(Clone, Copy, Default)]
struct Turns([u16; TURN_KINDS]);

/// The kinds of turn a walk's turns are counted by.
const TURN_KINDS: usize = 8;

impl Turns {
    fn kind(turn: i64) -> usize {
        match turn {
            -3..=3 => (turn + 3) as usize,
            _ => TURN_KINDS - 1,
        }
    }

    /// Bits to say a turn of kind `k` after these (an adaptive code: a
    /// walk whose turns are few kinds says them in fewer bits).
    fn bits(&self, k: usize) -> f64 {
        let total: f64 = self.0.iter().map(|&c| f64::from(c)).sum();
        let p = (f64::from(self.0[k]) + 0.5) / (total + 0.5 * TURN_KINDS as f64);
        -p.log2()
    }

    fn with(mut self, k: usize) -> Turns {
        self.0[k] = self.0[k].saturating_add(1);
        self
    }
}

/// A step a walk may take: its cost, point, parent in the arena, way and
/// turns.
#[derive(Clone, Copy)]
struct Step {
    cost: f64,
    p: DVec2,
    parent: u32,
    way: i64,
    turns: Turns,
}

/// One decoding of the drawing's paths on a lattice.
struct Pass<'a> {
    lattice: &'a Lattice,
    /// The drawing's vertices (user units).
    world: &'a [DVec2],
    /// The drawing's stroke graph (which steps one drawn segment holds).
    graph: &'a Graph,
    /// From the drawing to the lattice.
    frame: Similarity,
    /// Steps back over which a walk's shape is compared with the
    /// drawing's; 0: its every vertex with the drawing's.
    window: usize,
    /// How far (steps) a walk may stray and be kept.
    bound: f64,
    /// Whether the frame is fitted again as a path goes (every pass fits
    /// it again at the start of a path after a gap, see `walk`).
    refit: bool,
    /// Walks kept per step.
    beam: usize,
    /// The drawing's noise (steps): an offset `d` costs d²/2σ² nats, a
    /// turn the bits to say it after the walk's turns so far.
    sigma: f64,
}

impl Pass<'_> {
    fn seen(&self, v: u32) -> DVec2 {
        self.frame.apply(self.world[v as usize])
    }

    /// Each path walked on the lattice from where it starts (a vertex
    /// placed before; after a gap, where runs of moves from the last
    /// path's end reach (`gap_end`); else where `prior` placed it, or the
    /// drawing's own point), each step among the three multiples of δ
    /// nearest the step as drawn (and the way back to the drawing), the
    /// walks that stay within `bound` kept, the nearest chosen.
    fn walk(&mut self, paths: &[Vec<u32>], prior: &[Option<DVec2>]) -> Option<Vec<Option<DVec2>>> {
        let mut at: Vec<Option<DVec2>> = vec![None; self.world.len()];
        let mut next: Vec<Step> = Vec::new();
        // Where the last path ended, on the lattice.
        let mut last: Option<DVec2> = None;
        // Vertices placed, and placed when the frame was last fitted.
        let (mut placed, mut fitted) = (0usize, 0usize);
        for path in paths {
            let first = path[0] as usize;
            let start = match at[first] {
                Some(p) => p,
                None => {
                    // A long gap is read in steps of the frame: fitted
                    // again to the walk so far as it grows by a quarter.
                    if placed >= 8 && 4 * placed >= 5 * fitted {
                        if let Some(f) = fit_to(self.world, &at) {
                            self.frame = f;
                        }
                        fitted = placed;
                    }
                    last.and_then(|p| self.gap_end(p, path[0]))
                        .or(prior.get(first).copied().flatten())
                        .unwrap_or_else(|| self.seen(path[0]))
                }
            };
            // Each walk's points, back to the path's start.
            let mut arena: Vec<(DVec2, u32)> = vec![(start, u32::MAX)];
            let mut beam = vec![Head {
                cost: 0.0,
                at: 0,
                way: i64::MIN,
                turns: Turns::default(),
            }];
            for i in 1..path.len() {
                if self.refit && i % REFIT == 0 {
                    let best = beam.iter().min_by(|a, b| a.cost.total_cmp(&b.cost))?;
                    let mut so_far = at.clone();
                    place(&mut so_far, &path[..=i - 1], &arena, best.at);
                    self.frame = fit_to(self.world, &so_far)?;
                }
                next.clear();
                let drawn = self
                    .lattice
                    .nearest(self.seen(path[i]) - self.seen(path[i - 1]));
                // Steps cut from one drawn segment go its one way.
                let along =
                    |a: u32, b: u32| self.graph.edge(a, b).map(|e| self.graph.piece[e as usize]);
                let straight = i >= 2
                    && along(path[i - 2], path[i - 1])
                        .is_some_and(|e| along(path[i - 1], path[i]) == Some(e));
                for h in &beam {
                    self.steps(path, (i, straight), drawn, &at, &arena, *h, &mut next);
                }
                if next.is_empty() && self.window == 0 {
                    // No way stays within the bound (a step between two
                    // vertices each off the other way): the nearest ways,
                    // unbounded, rather than no walk.
                    let bound = std::mem::replace(&mut self.bound, f64::INFINITY);
                    for h in &beam {
                        self.steps(path, (i, straight), drawn, &at, &arena, *h, &mut next);
                    }
                    self.bound = bound;
                }
                if next.is_empty() {
                    return None;
                }
                beam = keep(&mut next, &mut arena, self.window.max(1), self.beam);
            }
            let best = beam.iter().min_by(|a, b| a.cost.total_cmp(&b.cost))?;
            placed += place(&mut at, path, &arena, best.at);
            last = at[*path.last()? as usize];
        }
        Some(at)
    }

    /// Where a path that starts at vertex `v`, placed nowhere yet, starts on
    /// the lattice: the turtle moved there from where the last path ended
    /// (its lattice point `p`), by one or two straight runs of whole steps
    /// (`f`s, a turn between them), the likeliest of those near the
    /// vertex as drawn; `None` when none is near it (a gap no short run of
    /// moves explains). The gap is read from `p`, not from where the last
    /// path ended as drawn: the frame is fitted to the walk, and the noise
    /// of that end would add to the start's.
    fn gap_end(&self, p: DVec2, v: u32) -> Option<DVec2> {
        Some(p + self.lattice.runs(self.seen(v) - p, self.sigma)?)
    }

    /// The steps walk `h` may take to vertex `i` of `path`, into `next`
    /// (`drawn`: the multiple of δ nearest the step as drawn).
    #[allow(clippy::too_many_arguments)]
    fn steps(
        &self,
        path: &[u32],
        (i, straight): (usize, bool),
        drawn: i64,
        at: &[Option<DVec2>],
        arena: &[(DVec2, u32)],
        h: Head,
        next: &mut Vec<Step>,
    ) {
        let b = path[i];
        let (from, seen) = (arena[h.at as usize].0, self.seen(b));
        let m = self.lattice.units.len() as i64;
        let mut tried = [i64::MAX; 6];
        // A walk compared by shape has no way back to take.
        let ways = if straight && h.way != i64::MIN {
            &[h.way][..]
        } else if self.window > 0 {
            &[drawn, drawn - 1, drawn + 1][..]
        } else {
            let back = self.lattice.nearest(seen - from);
            &[drawn, drawn - 1, drawn + 1, back, back - 1, back + 1][..]
        };
        for (j, k) in ways.iter().map(|k| k.rem_euclid(m)).enumerate() {
            if tried.contains(&k) {
                continue;
            }
            tried[j] = k;
            let p = from + self.lattice.units[k as usize];
            // A vertex placed before is where the walk must come back to.
            if at[b as usize].is_some_and(|q| q.distance(p) > 1e-6) {
                continue;
            }
            let off = if self.window > 0 {
                let w = self.window.min(i);
                let before = back_by(arena, h.at, w - 1);
                (p - before).distance(seen - self.seen(path[i - w]))
            } else {
                p.distance(seen)
            };
            if off <= self.bound {
                let (turn, turns) = if h.way == i64::MIN {
                    (0.0, h.turns)
                } else {
                    let t = (k - h.way + m / 2).rem_euclid(m) - m / 2;
                    let kind = Turns::kind(t);
                    (h.turns.bits(kind), h.turns.with(kind))
                };
                let nats = off * off / (2.0 * self.sigma * self.sigma);
                next.push(Step {
                    cost: h.cost + nats / std::f64::consts::LN_2 + turn,
                    p,
                    parent: h.at,
                    way: k,
                    turns,
                });
            }
        }
    }
}

/// Places `path`'s vertices where the walk ending at arena entry `h` has
/// them (a vertex placed before keeps its place); how many were new.
fn place(at: &mut [Option<DVec2>], path: &[u32], arena: &[(DVec2, u32)], mut h: u32) -> usize {
    let mut points = Vec::with_capacity(path.len());
    while h != u32::MAX {
        points.push(arena[h as usize].0);
        h = arena[h as usize].1;
    }
    let mut new = 0;
    for (&v, p) in path.iter().zip(points.into_iter().rev()) {
        if at[v as usize].is_none() {
            at[v as usize] = Some(p);
            new += 1;
        }
    }
    new
}

/// The walk's point `n` steps before arena entry `h`.
fn back_by(arena: &[(DVec2, u32)], mut h: u32, n: usize) -> DVec2 {
    for _ in 0..n {
        h = arena[h as usize].1;
    }
    arena[h as usize].0
}

/// The cheapest walk to each place in `next` (its point and the
/// `depth − 1` before it: walks alike there cost alike from there on),
/// the `beam` cheapest of them, entered in the arena.
fn keep(next: &mut [Step], arena: &mut Vec<(DVec2, u32)>, depth: usize, beam: usize) -> Vec<Head> {
    let keyed: Vec<(u64, Step)> = next
        .iter()
        .map(|&s| {
            let mut key = 0u64;
            let mut q = (s.p, s.parent);
            for _ in 0..depth {
                key = mix(mix(key, micro(q.0.x)), micro(q.0.y));
                if q.1 == u32::MAX {
                    break;
                }
                q = arena[q.1 as usize];
            }
            (key, s)
        })
        .collect();
    // The cheapest of each key, in an open-addressed table.
    let size = (2 * keyed.len()).next_power_of_two();
    let mut table: Vec<u32> = vec![u32::MAX; size];
    let mut kept: Vec<(u64, Step)> = Vec::with_capacity(keyed.len());
    for k in keyed {
        let mut slot = (k.0 as usize) & (size - 1);
        loop {
            match table[slot] {
                u32::MAX => {
                    table[slot] = kept.len() as u32;
                    kept.push(k);
                    break;
                }
                j if kept[j as usize].0 == k.0 => {
                    let old = &mut kept[j as usize];
                    if k.1
                        .cost
                        .total_cmp(&old.1.cost)
                        .then(k.1.parent.cmp(&old.1.parent))
                        .is_lt()
                    {
                        *old = k;
                    }
                    break;
                }
                _ => slot = (slot + 1) & (size - 1),
            }
        }
    }
    let mut keyed = kept;
    let by_cost =
        |a: &(u64, Step), b: &(u64, Step)| a.1.cost.total_cmp(&b.1.cost).then(a.0.cmp(&b.0));
    if keyed.len() > beam {
        keyed.select_nth_unstable_by(beam, by_cost);
        keyed.truncate(beam);
    }
    keyed.sort_unstable_by(by_cost);
    keyed
        .into_iter()
        .map(|(_, s)| {
            arena.push((s.p, s.parent));
            Head {
                cost: s.cost,
                at: arena.len() as u32 - 1,
                way: s.way,
                turns: s.turns,
            }
        })
        .collect()
}

/// A coordinate in millionths of a step, rounded (a lattice point reached
/// by two walks differs by rounding alone).
fn micro(x: f64) -> u64 {
    (x * 1e6 + 0.5f64.copysign(x)) as i64 as u64
}

/// `key` and `x` mixed into one hash (a multiply and a rotation).
fn mix(key: u64, x: u64) -> u64 {
    (key ^ x)
        .wrapping_mul(0x9E37_79B9_7F4A_7C15)
        .rotate_left(29)
}

/// The similarity z ↦ to + turn·(z − from), `turn` a complex number (a
/// turn and a scale).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Similarity {
    from: DVec2,
    turn: DVec2,
    to: DVec2,
}

impl Similarity {
    pub(crate) fn apply(&self, p: DVec2) -> DVec2 {
        let (z, s) = (p - self.from, self.turn);
        DVec2::new(s.x * z.x - s.y * z.y, s.x * z.y + s.y * z.x) + self.to
    }

    /// The similarity that puts the first of each pair nearest the second,
    /// least squares.
    pub(crate) fn fit(pairs: &[(DVec2, DVec2)]) -> Option<Similarity> {
        let n = pairs.len() as f64;
        if n < 2.0 {
            return None;
        }
        let (cz, cw) = pairs
            .iter()
            .fold((DVec2::ZERO, DVec2::ZERO), |(a, b), (z, w)| {
                (a + *z, b + *w)
            });
        let (cz, cw) = (cz / n, cw / n);
        let (mut num, mut den) = (DVec2::ZERO, 0.0);
        for (z, w) in pairs {
            let (z, w) = (*z - cz, *w - cw);
            num += DVec2::new(w.x * z.x + w.y * z.y, w.y * z.x - w.x * z.y);
            den += z.length_squared();
        }
        (den > 0.0).then(|| Similarity {
            from: cz,
            turn: num / den,
            to: cw,
        })
    }

    /// The turn, radians (from +x towards +y).
    pub(crate) fn angle(&self) -> f64 {
        self.turn.y.atan2(self.turn.x)
    }

    /// The scale.
    pub(crate) fn scale(&self) -> f64 {
        self.turn.length()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `F -> F+F-F` at 22.5° to `depth`, from the origin heading up: its
    /// vertices.
    fn curve(depth: u32) -> Vec<DVec2> {
        let mut s = String::from("F");
        for _ in 0..depth {
            s = s.replace('F', "F+F-F");
        }
        let (mut at, mut heading) = (DVec2::ZERO, 90.0f64);
        let mut out = vec![at];
        for c in s.chars() {
            match c {
                '+' => heading += 22.5,
                '-' => heading -= 22.5,
                _ => {
                    at += DVec2::new(heading.to_radians().cos(), heading.to_radians().sin());
                    out.push(at);
                }
            }
        }
        out
    }

    /// The turns between the steps of `line`, in tenths of a degree.
    fn turns(line: &[DVec2]) -> Vec<i64> {
        line.windows(3)
            .map(|w| {
                let (a, b) = (w[1] - w[0], w[2] - w[1]);
                (a.perp_dot(b).atan2(a.dot(b)).to_degrees() * 10.0).round() as i64
            })
            .collect()
    }

    #[test]
    fn a_curve_jittered_by_a_seventh_of_a_step_at_22_5_degrees_is_walked_as_drawn() {
        let clean = curve(5);
        // Every vertex moved by up to 0.15 of a step (a fixed sequence);
        // one-step directions are then misread by rounding alone.
        let mut rng = crate::geometry::index::Lcg(12345);
        let mut unit = || rng.next();
        let noisy: Vec<DVec2> = clean
            .iter()
            .map(|&p| {
                let (r, a) = (0.15 * unit().sqrt(), unit() * TAU);
                (p + DVec2::new(a.cos(), a.sin()) * r) * 10.0
            })
            .collect();
        let misread = clean
            .windows(2)
            .zip(noisy.windows(2))
            .filter(|(c, n)| {
                let (c, n) = (c[1] - c[0], n[1] - n[0]);
                (c.angle_to(n).to_degrees().abs()) > 11.25
            })
            .count();
        assert!(misread > 0, "the jitter misreads some steps on their own");
        let g = super::super::graph::build(&[noisy], 1).expect("a stroke graph");
        let walk = redrawn(&g).into_iter().next().expect("a redrawing");
        assert_eq!(walk.len(), 1);
        assert_eq!(turns(&walk[0]), turns(&clean));
    }

    /// `X -> FF[-X]F[--FX][-X]F-X`, `F -> FF` at 20° to `depth`, drawn as
    /// a turtle draws it: one polyline per stroke, a straight run one
    /// segment, a branch a new polyline from where it starts.
    fn plant(depth: u32) -> Vec<Vec<DVec2>> {
        let mut s = String::from("X");
        for _ in 0..depth {
            s = s
                .chars()
                .map(|c| match c {
                    'X' => "FF[-X]F[--FX][-X]F-X".to_string(),
                    'F' => "FF".to_string(),
                    c => c.to_string(),
                })
                .collect();
        }
        let (mut at, mut heading) = (DVec2::ZERO, 90.0f64);
        let mut stack = Vec::new();
        let mut lines: Vec<Vec<DVec2>> = vec![vec![at]];
        let mut last_heading = f64::NAN;
        for c in s.chars() {
            match c {
                '+' => heading += 20.0,
                '-' => heading -= 20.0,
                '[' => stack.push((at, heading)),
                ']' => {
                    (at, heading) = stack.pop().expect("balanced");
                    lines.push(vec![at]);
                    last_heading = f64::NAN;
                }
                'F' => {
                    at += DVec2::new(heading.to_radians().cos(), heading.to_radians().sin());
                    let line = lines.last_mut().expect("a line");
                    if heading == last_heading {
                        *line.last_mut().expect("a point") = at;
                    } else {
                        line.push(at);
                    }
                    last_heading = heading;
                }
                _ => {}
            }
        }
        lines.retain(|l| l.len() > 1);
        lines
    }

    #[test]
    fn a_plant_jittered_by_a_fifth_of_a_step_is_walked_as_drawn_to_its_tips() {
        let clean = plant(3);
        // Every drawn point moved by up to a fifth of a step (one point,
        // one move), in a fixed sequence.
        let mut rng = crate::geometry::index::Lcg(7);
        let mut unit = || rng.next();
        let mut moved: std::collections::HashMap<[i64; 2], DVec2> = Default::default();
        let noisy: Vec<Vec<DVec2>> = clean
            .iter()
            .map(|l| {
                l.iter()
                    .map(|&p| {
                        let key = [(p.x * 1e6).round() as i64, (p.y * 1e6).round() as i64];
                        let by = *moved.entry(key).or_insert_with(|| {
                            let (r, a) = (0.2 * unit().sqrt(), unit() * TAU);
                            DVec2::new(a.cos(), a.sin()) * r
                        });
                        (p + by) * 10.0
                    })
                    .collect()
            })
            .collect();
        let g = super::super::graph::build(&noisy, 1).expect("a stroke graph");
        let walk = redrawn(&g).into_iter().next().expect("a redrawing");
        // Every step of the redrawing is a step of the plant, the same way
        // (a tip read one δ off turns by 20°).
        let steps = |lines: &[Vec<DVec2>], scale: f64| -> Vec<(DVec2, DVec2)> {
            lines
                .iter()
                .flat_map(|l| l.windows(2).map(|w| (w[0], w[1])))
                .flat_map(|(a, b)| {
                    let n = (a.distance(b) / scale).round().max(1.0) as usize;
                    (0..n).map(move |k| {
                        let (p, q) = (
                            a.lerp(b, k as f64 / n as f64),
                            a.lerp(b, (k + 1) as f64 / n as f64),
                        );
                        ((p + q) / (2.0 * scale), (q - p) / scale)
                    })
                })
                .collect()
        };
        let truth = steps(&clean, 1.0);
        let read = steps(&walk, g.step);
        assert_eq!(read.len(), truth.len());
        let off = read
            .iter()
            .filter(|(mid, way)| {
                let m = *mid * g.step / 10.0;
                !truth
                    .iter()
                    .any(|(tm, tw)| tm.distance(m) < 0.3 && tw.angle_to(*way).abs() < 0.05)
            })
            .count();
        assert_eq!(off, 0, "steps of the redrawing not in the plant");
    }

    #[test]
    fn a_gap_is_read_as_the_likeliest_runs_of_moves_near_it() {
        let square = Lattice::new(4);
        // Three steps right and two up, each end a fifth of a step off.
        let run = square.runs(DVec2::new(3.15, 1.88), 0.1).expect("two runs");
        assert!(run.distance(DVec2::new(3.0, 2.0)) < 1e-9, "{run}");
        // Seven steps along one way.
        let run = square.runs(DVec2::new(-0.1, -7.2), 0.1).expect("one run");
        assert!(run.distance(DVec2::new(0.0, -7.0)) < 1e-9, "{run}");
        // Halfway between lattice points: no run of moves ends there.
        assert_eq!(square.runs(DVec2::new(2.5, 0.5), 0.1), None);
        // At 60°: two steps one way and three the next, off by a fifth.
        let hex = Lattice::new(6);
        let truth = hex.units[0] * 2.0 + hex.units[1] * 3.0;
        let run = hex
            .runs(truth + DVec2::new(0.12, -0.15), 0.1)
            .expect("two runs");
        assert!(run.distance(truth) < 1e-9, "{run}");
    }
}
