//! `--symmetrize` (the paper's Fig. 10): a repeated structure made regular.
//!
//! Owns: refitting a chosen rule to all its instances (`fit`) instead of
//! averaging neighbour transforms and starting each copy at its first
//! instance, then snapping each number of the transform to the roundest
//! value the instances support, in turn: the turn per step (to 360°/n for a
//! ring that closes), the scale, the turn before the step, the step, each
//! followed by a refit of what is still free; and the rotation of the
//! drawing's last instance (the axiom). A value moves at most three standard
//! errors, and never beyond the relaxed tolerance. Must not choose rules.

use super::fit::{Fit, Member, Solution, nice, nice_angle};
use super::{Inst, Tolerance};
use crate::infer::elements::shape::{Frame, rotate, wrap};
use crate::infer::elements::space::Tr;
use glam::DVec2;
use std::f64::consts::TAU;

/// How many standard errors an angle may move to become round.
const SUPPORT: f64 = 3.0;

/// How many standard errors a length or a scale may move to become round
/// (fewer: a ring's radius moves with its step, times the steps per radian).
const SUPPORT_LENGTH: f64 = 2.0;

/// The parameters of one transform: α, d, ln s and the whole turn θ = α + β.
fn params(t: &Tr) -> [f64; 4] {
    [t.alpha, t.d, t.s.max(1e-300).ln(), wrap(t.alpha + t.beta)]
}

fn transform(p: &[f64]) -> Tr {
    Tr {
        alpha: wrap(p[0]),
        d: p[1],
        s: p[2].exp(),
        beta: wrap(p[3] - p[0]),
    }
}

fn identity() -> Frame {
    Frame {
        pos: DVec2::ZERO,
        rot: 0.0,
        scale: 1.0,
    }
}

/// A regular structure: its transforms, each copy's start frame with the
/// standard error of its rotation, where each member is drawn (in the order
/// of the members), and the variance of a position about the fit.
#[derive(Debug)]
pub(super) struct Regular {
    pub t: Vec<Tr>,
    pub starts: Vec<Frame>,
    pub rot_se: Vec<f64>,
    pub pos_se: Vec<f64>,
    pub drawn: Vec<Frame>,
    pub sigma2: f64,
}

/// A member of a fit (`tilted`: see `Member`).
impl Regular {
    /// The structure, if every number of it is finite and every frame's
    /// scale positive (else the rule is kept as found).
    pub(super) fn checked(self) -> Option<Regular> {
        let frame = |f: &Frame| {
            f.pos.is_finite() && f.rot.is_finite() && f.scale.is_finite() && f.scale > 0.0
        };
        let tr = |t: &Tr| {
            t.alpha.is_finite() && t.d.is_finite() && t.s.is_finite() && t.beta.is_finite()
        };
        (self.t.iter().all(tr) && self.starts.iter().all(frame) && self.drawn.iter().all(frame))
            .then_some(self)
    }
}

fn member(insts: &[Inst], group: usize, i: usize, tilted: bool) -> Member {
    Member {
        group,
        frame: insts[i].frame,
        lever: insts[i].size() / 2.5,
        rot_se: insts[i].rot_se,
        pos_se: insts[i].pos_se,
        tilted,
    }
}

/// Whether the members are elements of the drawing, whose rotations are
/// relative to their kind's representative: one noisy sample, so a turn
/// between such a member and the structure is as uncertain as one
/// element's rotation (the outline is turned back by the kind's tilt).
fn elements(insts: &[Inst], members: impl IntoIterator<Item = usize>) -> bool {
    members
        .into_iter()
        .all(|i| matches!(insts[i].sym, super::Sym::Element(_)))
}

/// Chains drawn by `P(m) -> [A] T P(m - 1)` (pairs are chains of two).
pub(super) fn sequence(
    insts: &[Inst],
    chains: &[Vec<usize>],
    t: &Tr,
    tol: Tolerance,
) -> Option<Regular> {
    let rep = elements(insts, chains.iter().flatten().copied());
    let same = chains
        .iter()
        .all(|c| c.iter().all(|&i| insts[i].sym == insts[c[0]].sym));
    let members: Vec<Member> = chains
        .iter()
        .enumerate()
        .flat_map(|(g, c)| c.iter().map(move |&i| (g, i)))
        .map(|(g, i)| member(insts, g, i, rep && same))
        .collect();
    let lens: Vec<usize> = chains.iter().map(Vec::len).collect();
    let model = |p: &[f64], out: &mut Vec<Frame>| {
        let t = transform(p);
        out.clear();
        for &n in &lens {
            let mut f = identity();
            for _ in 0..n {
                out.push(f);
                f = t.apply(&f);
            }
        }
    };
    let longest = lens.iter().copied().max().unwrap_or(0);
    // The transform, and the tilt of the members' rotations.
    let mut p = params(t).to_vec();
    p.push(0.0);
    let sol = snap(
        &members,
        chains.len(),
        &model,
        &mut p,
        tol,
        Some(longest),
        Loose {
            rep,
            same,
            deep: false,
        },
    );
    Regular {
        t: vec![transform(&p)],
        starts: sol.starts,
        rot_se: sol.rot_se,
        pos_se: sol.pos_se,
        drawn: sol.drawn,
        sigma2: sol.sigma2,
    }
    .checked()
    .filter(|r| r.t.iter().all(|t| t.s > 0.0))
}

/// Complete trees drawn by `R(m) -> [A] [T R(m - 1)] [U R(m - 1)]…`, given
/// as (root, depth); `child` are the children of each node, one map per
/// transform of `ts`.
pub(super) fn branching(
    insts: &[Inst],
    trees: &[(usize, u32)],
    child: &[std::collections::HashMap<usize, usize>],
    ts: &[Tr],
    tol: Tolerance,
) -> Option<Regular> {
    // Members level by level, as the rule draws them.
    let rep = elements(insts, trees.iter().map(|t| t.0));
    let mut members = Vec::new();
    for (g, &(root, depth)) in trees.iter().enumerate() {
        let mut level = vec![root];
        members.push(member(insts, g, root, rep));
        for _ in 0..depth {
            level = level
                .iter()
                .flat_map(|v| child.iter().filter_map(move |c| c.get(v)))
                .copied()
                .collect();
            members.extend(level.iter().map(|&i| member(insts, g, i, rep)));
        }
    }
    let depths: Vec<u32> = trees.iter().map(|t| t.1).collect();
    let k = ts.len();
    let model = |p: &[f64], out: &mut Vec<Frame>| {
        let trs: Vec<Tr> = (0..k).map(|i| transform(&p[4 * i..4 * i + 4])).collect();
        out.clear();
        for &d in &depths {
            let mut level = vec![identity()];
            out.push(identity());
            for _ in 0..d {
                level = level
                    .iter()
                    .flat_map(|f| trs.iter().map(|t| t.apply(f)).collect::<Vec<_>>())
                    .collect();
                out.extend(level.iter().copied());
            }
        }
    };
    let mut p: Vec<f64> = ts.iter().flat_map(params).collect();
    p.push(0.0);
    let loose = Loose {
        rep,
        same: true,
        deep: true,
    };
    let sol = snap(&members, trees.len(), &model, &mut p, tol, None, loose);
    Regular {
        t: (0..k).map(|i| transform(&p[4 * i..4 * i + 4])).collect(),
        starts: sol.starts,
        rot_se: sol.rot_se,
        pos_se: sol.pos_se,
        drawn: sol.drawn,
        sigma2: sol.sigma2,
    }
    .checked()
    .filter(|r| r.t.iter().all(|t| t.s > 0.0))
}

/// Which turns are as uncertain as one element's rotation: `rep`, the
/// members are elements; `same`, of one kind (else the whole turn between
/// two kinds is too).
#[derive(Clone, Copy)]
struct Loose {
    rep: bool,
    same: bool,
    /// A tree: a turn is drawn again at every level below it, so it is
    /// only as uncertain as the fit says (an element's own rotation does
    /// not loosen it).
    deep: bool,
}

/// Fits `p` (one or more transforms, four numbers each, then the tilt) and
/// snaps them in turn; `ring`: the longest chain's length, to close a ring
/// of it. The tilt is fixed at 0 until the turns before the steps are
/// round; then it takes up what rounding them moved, so that the members'
/// positions, not their rotations, say where each copy lies (`Grammar::tilt`
/// turns the outline instead).
fn snap(
    members: &[Member],
    groups: usize,
    model: &dyn Fn(&[f64], &mut Vec<Frame>),
    p: &mut [f64],
    tol: Tolerance,
    ring: Option<usize>,
    loose: Loose,
) -> Solution {
    let slots = (p.len() - 1) / 4;
    let tilt = 4 * slots;
    let tilted = loose.rep && loose.same;
    let mut fit = Fit::new(members, groups, model, tilted.then_some(tilt));
    let mut free: Vec<usize> = (0..tilt).collect();
    fit.solve_robust(p, &free);
    // A chain whose next step would land on its first instance is a ring:
    // its turn is a whole fraction of a full turn, its scale 1.
    if let Some(n) = ring.filter(|&n| n >= 3) {
        let t = transform(&p[..4]);
        let end = (0..n).fold(identity(), |f, _| t.apply(&f));
        let laps = (n as f64 * p[3] / TAU).round();
        if laps != 0.0
            && end.pos.length() <= 2.0 * tol.distance * t.d.abs()
            && wrap(end.rot).abs() <= 2.0 * tol.angle
            && end.scale.ln().abs() <= 2.0 * tol.scale
        {
            p[3] = wrap(laps * TAU / n as f64);
            p[2] = 0.0;
            free.retain(|&j| j != 2 && j != 3);
            fit.solve(p, &free);
        }
    }
    // The members' size in their frames' units, and whether their positions
    // spread enough to say how each copy is turned (else the tilt is not
    // told apart from the copies' rotations).
    let size = members
        .iter()
        .map(|m| m.lever / m.frame.scale.max(1e-300))
        .sum::<f64>()
        / members.len().max(1) as f64;
    let spread = {
        let mut tm = Vec::new();
        model(p, &mut tm);
        tm.iter()
            .map(|t| t.pos.length() / t.scale.max(1e-300))
            .fold(0.0, f64::max)
    };
    // The whole turns first, then scales, the turns before the step, steps.
    for offset in [3, 2, 0, 1] {
        if offset == 1 && tilted && spread > 0.1 * size {
            free.push(tilt);
            fit.solve(p, &free);
        }
        for j in (offset..tilt).step_by(4) {
            let Some(k) = free.iter().position(|&f| f == j) else {
                continue;
            };
            let (sol, se) = fit.result(p, &free);
            let one = if loose.rep && !loose.deep && (offset == 0 || (offset == 3 && !loose.same)) {
                sol.rot_rms
            } else {
                0.0
            };
            let support = if offset == 0 || offset == 3 {
                SUPPORT
            } else {
                SUPPORT_LENGTH
            };
            let allow = support * se[k].hypot(one);
            p[j] = match offset {
                0 | 3 => nice_angle(p[j], allow.min(tol.angle)),
                2 => {
                    let s = p[j].exp();
                    nice(s, (allow * s).min(tol.scale * s)).max(1e-9).ln()
                }
                _ => nice(p[j], allow.min(tol.distance * p[j].abs().max(size))),
            };
            free.remove(k);
            fit.solve(p, &free);
        }
    }
    fit.result(p, &free).0
}

/// The axiom's frame made round. `straight`: the turn α of the axiom's
/// rule when it repeats along a straight line (its turn per step θ is 0):
/// then the line's direction turns to the roundest angle within three
/// standard errors `rot_se` (at most the angle tolerance) about `centre`, the
/// mean position of the elements it draws. (A ring's phase is left as
/// fitted: where its elements' origins lie on it depends on their outline.)
/// Then the frame moves so that `centre` lies on the roundest point within
/// three standard errors `pos_se`.
pub(super) fn axiom(
    frame: Frame,
    straight: Option<f64>,
    rot_se: f64,
    centre: DVec2,
    pos_se: f64,
    tol: Tolerance,
) -> Frame {
    let mut f = frame;
    let allow = (SUPPORT * rot_se).min(tol.angle);
    if let Some(alpha) = straight.filter(|_| allow > 0.0) {
        let dir = wrap(f.rot + alpha);
        let turn = wrap(nice_angle(dir, allow) - dir);
        f = Frame {
            pos: centre + rotate(f.pos - centre, turn),
            rot: wrap(f.rot + turn),
            scale: f.scale,
        };
    }
    let allow = SUPPORT_LENGTH * pos_se;
    if allow > 0.0 && allow.is_finite() {
        let to = DVec2::new(nice(centre.x, allow), nice(centre.y, allow));
        f.pos += to - centre;
    }
    f
}
