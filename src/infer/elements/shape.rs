//! Element similarity and inverse instancing: elements equal up to position,
//! rotation and uniform scale become one kind, with a representative and one
//! frame (position, rotation, scale) per instance.
//!
//! Owns: the canonical description of an outline (arc-length centroid, RMS
//! radius, angular harmonics m_l = mean((r/ρ)·e^{ilθ}) along the outline), the
//! candidate rotations they give (the first clearly non-zero harmonic l fixes
//! the rotation up to 360°/l), the verified alignment that decides (mean
//! distance from each outline's samples to the other outline, both ways), the
//! rotational symmetry order of a kind, and a consistent choice of orientation
//! for symmetric kinds (each instance takes the variant closest to an already
//! placed neighbour, so rings and grids of squares or stars get frames that
//! turn smoothly). Replaces the paper's curvature voting with mean shift: the
//! harmonics give the same transform in O(samples) and the alignment check
//! keeps its guarantee. Must not know about rules.

use super::read::Element;
use super::{Budget, TooMuchWork};
use crate::infer::svg::Seg;
use glam::DVec2;
use rayon::prelude::*;
use std::collections::HashMap;
use std::f64::consts::{PI, TAU};

/// Samples per outline for the alignment check.
const SAMPLES: usize = 48;
/// The most element-to-kind comparisons of instancing (each element is
/// compared with the kinds found before it until one fits, so a drawing of n
/// elements all unlike each other needs n²/2): the work limit of instancing.
pub const MAX_COMPARISONS: u64 = 15_000_000;
/// Harmonics in the description.
const HARMONICS: usize = 12;
/// A harmonic at least this strong fixes the rotation.
const SIGNIFICANT: f64 = 0.06;
/// How far apart two descriptions may be and still be compared by alignment.
const DESCRIPTOR_GAP: f64 = 0.12;

/// The description of an outline.
#[derive(Clone, Debug)]
pub struct Shape {
    pub centroid: DVec2,
    /// RMS distance of the outline from its centroid (> 0).
    pub radius: f64,
    /// Points spread evenly along the outline, relative to the centroid.
    pub samples: Vec<DVec2>,
    /// The outline's polylines, relative to the centroid.
    pub outline: Vec<Vec<DVec2>>,
    /// m_1 … m_HARMONICS as complex numbers (x real, y imaginary).
    pub harmonics: Vec<DVec2>,
    /// Perimeter over radius.
    pub perimeter: f64,
}

fn cmul(a: DVec2, b: DVec2) -> DVec2 {
    DVec2::new(a.x * b.x - a.y * b.y, a.x * b.y + a.y * b.x)
}

/// Turns `v` counter-clockwise by `a` radians.
pub fn rotate(v: DVec2, a: f64) -> DVec2 {
    let (s, c) = a.sin_cos();
    DVec2::new(c * v.x - s * v.y, s * v.x + c * v.y)
}

/// `a` wrapped into (−π, π].
pub fn wrap(a: f64) -> f64 {
    let mut r = a.rem_euclid(TAU);
    if r > PI {
        r -= TAU;
    }
    r
}

impl Shape {
    /// Describes an element's outline; `None` when it has no length.
    pub fn of(outline: &[Vec<DVec2>]) -> Option<Shape> {
        let pieces = || {
            outline
                .iter()
                .flat_map(|l| l.windows(2).map(|w| (w[0], w[1])))
        };
        let length: f64 = pieces().map(|(a, b)| a.distance(b)).sum();
        if !(length > 0.0 && length.is_finite()) {
            return None;
        }
        let centroid = pieces()
            .map(|(a, b)| (a + b) * 0.5 * a.distance(b))
            .sum::<DVec2>()
            / length;
        // Midpoint rule on quarters of each piece.
        let mut r2 = 0.0;
        let mut acc = vec![DVec2::ZERO; HARMONICS];
        let mut mean_r = 0.0;
        for (a, b) in pieces() {
            let len = a.distance(b);
            for q in 0..4 {
                let t = (q as f64 + 0.5) / 4.0;
                let z = a.lerp(b, t) - centroid;
                let w = len / 4.0;
                let r = z.length();
                r2 += r * r * w;
                mean_r += r * w;
                if r > 0.0 {
                    let u = z / r;
                    let mut p = u;
                    for m in acc.iter_mut() {
                        *m += p * (r * w);
                        p = cmul(p, u);
                    }
                }
            }
        }
        let radius = (r2 / length).sqrt();
        if radius.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return None;
        }
        let norm = (mean_r).max(f64::MIN_POSITIVE);
        let harmonics = acc.into_iter().map(|m| m / norm).collect();
        let rel: Vec<Vec<DVec2>> = outline
            .iter()
            .map(|l| l.iter().map(|p| *p - centroid).collect())
            .collect();
        let samples = resample(&rel, length, SAMPLES);
        Some(Shape {
            centroid,
            radius,
            samples,
            outline: rel,
            harmonics,
            perimeter: length / radius,
        })
    }

    /// How different two descriptions are (0 for equal shapes), invariant
    /// under rotation, scale and translation.
    fn gap(&self, other: &Shape) -> f64 {
        let h: f64 = self
            .harmonics
            .iter()
            .zip(&other.harmonics)
            .map(|(a, b)| (a.length() - b.length()).powi(2))
            .sum::<f64>()
            .sqrt();
        h + ((self.perimeter - other.perimeter) / self.perimeter).abs()
    }

    /// Whether the outline can be `k`-fold symmetric: every harmonic whose
    /// order is not a multiple of `k` is too weak to fix a rotation (a
    /// star of five points pulled out of true turns into itself by a third
    /// of a turn within the tolerance, but its fifth harmonic says it is
    /// not 3-fold).
    fn turns_alike(&self, k: usize) -> bool {
        self.harmonics
            .iter()
            .enumerate()
            .all(|(i, m)| (i + 1) % k == 0 || m.length() < SIGNIFICANT)
    }

    /// The first harmonic strong enough to fix a rotation.
    fn order(&self) -> Option<usize> {
        self.harmonics
            .iter()
            .position(|m| m.length() >= SIGNIFICANT)
            .map(|i| i + 1)
    }

    /// Mean distance between this outline mapped by (rotation `a`, scale `s`)
    /// and `other`, both ways, relative to `other`'s radius.
    fn misfit(&self, a: f64, s: f64, other: &Shape, limit: f64) -> f64 {
        let map = |p: DVec2| rotate(p, a) * s;
        let budget = limit * other.radius * (2 * SAMPLES) as f64;
        let mut sum = 0.0;
        for p in &self.samples {
            sum += distance_to(map(*p), &other.outline, |q| q);
            if sum > budget {
                return f64::INFINITY;
            }
        }
        for p in &other.samples {
            sum += distance_to(*p, &self.outline, map);
            if sum > budget {
                return f64::INFINITY;
            }
        }
        sum / (2 * SAMPLES) as f64 / other.radius
    }

    /// The rotations (radians) that map this shape onto `other` within
    /// `tolerance`, best first; empty when they are not alike.
    pub fn align(&self, other: &Shape, tolerance: f64) -> Vec<(f64, f64)> {
        if self.gap(other) > DESCRIPTOR_GAP + 2.0 * tolerance {
            return Vec::new();
        }
        let s = other.radius / self.radius;
        let candidates: Vec<f64> = match self.order() {
            Some(l) => {
                let (a, b) = (self.harmonics[l - 1], other.harmonics[l - 1]);
                if b.length() < SIGNIFICANT * 0.5 {
                    return Vec::new();
                }
                let base = (b.y.atan2(b.x) - a.y.atan2(a.x)) / l as f64;
                (0..l)
                    .map(|j| wrap(base + TAU * j as f64 / l as f64))
                    .collect()
            }
            // Round shapes: no harmonic says how they are turned.
            None => vec![0.0],
        };
        let mut fits: Vec<(f64, f64)> = candidates
            .into_iter()
            .map(|a| (a, self.misfit(a, s, other, tolerance)))
            .filter(|(_, e)| *e <= tolerance)
            .collect();
        fits.sort_by(|x, y| x.1.total_cmp(&y.1).then(x.0.abs().total_cmp(&y.0.abs())));
        fits
    }
}

/// `n` points spread evenly by arc length over the polylines.
fn resample(lines: &[Vec<DVec2>], length: f64, n: usize) -> Vec<DVec2> {
    let step = length / n as f64;
    let mut out = Vec::with_capacity(n);
    let mut next = step * 0.5;
    let mut walked = 0.0;
    for l in lines {
        for w in l.windows(2) {
            let len = w[0].distance(w[1]);
            while next <= walked + len && out.len() < n {
                let t = if len > 0.0 {
                    (next - walked) / len
                } else {
                    0.0
                };
                out.push(w[0].lerp(w[1], t));
                next += step;
            }
            walked += len;
        }
    }
    while out.len() < n {
        out.push(
            lines
                .last()
                .and_then(|l| l.last())
                .copied()
                .unwrap_or_default(),
        );
    }
    out
}

/// Distance from `p` to the polylines, each point mapped by `map`.
fn distance_to(p: DVec2, lines: &[Vec<DVec2>], map: impl Fn(DVec2) -> DVec2) -> f64 {
    let mut best = f64::INFINITY;
    for l in lines {
        let mut prev: Option<DVec2> = None;
        for q in l {
            let q = map(*q);
            if let Some(a) = prev {
                let ab = q - a;
                let t = if ab.length_squared() > 0.0 {
                    ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                best = best.min(p.distance_squared(a + ab * t));
            }
            prev = Some(q);
        }
    }
    best.sqrt()
}

/// One kind of element: its representative, symmetry and local frame.
#[derive(Clone, Debug)]
pub struct Kind {
    /// Index of the representative in the element list.
    pub representative: usize,
    /// Rotational symmetry order: 1 for none, k for k-fold, 0 for round.
    pub symmetry: usize,
    /// The kind's local frame on its representative, in the world: the
    /// element's path is written in this frame. The drawing's own frame when
    /// it gives one (`given`); else at the centroid, unturned, until
    /// `origin` and `pivot` find where a person would put it.
    pub frame: Frame,
    /// The drawing placed every instance of this kind through a transform
    /// (`<use>`, a transformed group): the frames are the transforms'.
    pub given: bool,
    /// The representative's outline as this kind draws it, in the world
    /// (mirrored for a mirror kind).
    pub subpaths: Vec<Vec<Seg>>,
    /// `Some(k)`: this kind is kind `k` mirrored (x negated in `k`'s local
    /// frame), found with `--reflect`; it shares `k`'s representative.
    pub mirror_of: Option<usize>,
}

/// Where an instance of a kind sits: its representative's frame mapped there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    pub pos: DVec2,
    /// Counter-clockwise rotation from the representative, radians.
    pub rot: f64,
    pub scale: f64,
}

impl Frame {
    pub const IDENTITY: Frame = Frame {
        pos: DVec2::ZERO,
        rot: 0.0,
        scale: 1.0,
    };

    /// Maps a point of the representative's local frame into the world.
    pub fn apply(&self, p: DVec2) -> DVec2 {
        self.pos + rotate(p, self.rot) * self.scale
    }

    /// Maps a world point into this frame.
    pub fn local(&self, p: DVec2) -> DVec2 {
        rotate(p - self.pos, -self.rot) / self.scale
    }

    /// The frame `local` (given in this frame's coordinates) in the world.
    pub fn then(&self, local: &Frame) -> Frame {
        Frame {
            pos: self.apply(local.pos),
            rot: wrap(self.rot + local.rot),
            scale: self.scale * local.scale,
        }
    }

    /// The frame this one is `local` of: `inverse` with `x.then(self) = id`.
    pub fn inverse(&self) -> Frame {
        Frame {
            pos: -rotate(self.pos, -self.rot) / self.scale,
            rot: wrap(-self.rot),
            scale: 1.0 / self.scale,
        }
    }

    /// The mean of frames (rotations averaged around the first's).
    pub fn mean(frames: &[Frame]) -> Option<Frame> {
        let first = frames.first()?;
        let n = frames.len() as f64;
        Some(Frame {
            pos: frames.iter().map(|f| f.pos).sum::<DVec2>() / n,
            rot: wrap(first.rot + frames.iter().map(|f| wrap(f.rot - first.rot)).sum::<f64>() / n),
            scale: (frames.iter().map(|f| f.scale.ln()).sum::<f64>() / n).exp(),
        })
    }

    /// The frame of a drawing's map `m` (a similarity) for the path read
    /// with its x and y multiplied by `flip` (each ±1): `m` after `flip`,
    /// which must not mirror.
    fn of_map(m: &[f64; 6], flip: DVec2) -> Frame {
        let [a, _, tx, c, _, ty] = *m;
        let (a, c) = (a * flip.x, c * flip.x);
        Frame {
            pos: DVec2::new(tx, ty),
            rot: c.atan2(a),
            scale: (a * a + c * c).sqrt(),
        }
    }
}

/// The kinds of a drawing, and each element's kind and frame.
#[derive(Clone, Debug)]
pub struct Instancing {
    pub kinds: Vec<Kind>,
    pub shapes: Vec<Shape>,
    /// Per element: its kind and frame.
    pub of: Vec<(usize, Frame)>,
}

impl Instancing {
    /// Round kinds the drawing does not frame, each instance turned to head
    /// (turtle heading: its local +y) as `facing` says; `None` when there
    /// are none. A disc has no heading of its own, and a spiral of discs
    /// steps and turns alike at every disc only if each heads the way the
    /// spiral runs, a ring of discs only if each heads out of the ring.
    pub fn turned_round(&self, facing: Facing, within: f64) -> Option<Instancing> {
        let mut out = self.clone();
        let mut any = false;
        let radii: Vec<f64> = self.shapes.iter().map(|sh| sh.radius).collect();
        for (k, kind) in self.kinds.iter().enumerate() {
            let folded = kind.symmetry > 1 && facing == Facing::Fork;
            if (kind.symmetry != 0 && !folded) || kind.given {
                continue;
            }
            let members: Vec<usize> = (0..self.of.len()).filter(|&i| self.of[i].0 == k).collect();
            if members.len() < 3 {
                continue;
            }
            let points: Vec<DVec2> = members.iter().map(|&i| self.of[i].1.pos).collect();
            let heads = match facing {
                Facing::Path => along_path(&points),
                Facing::Fork => match toward_forks(&members, &self.of, &radii, (within, folded)) {
                    Some(heads) => heads,
                    None => continue,
                },
                _ => {
                    let index = crate::geometry::index::PointGrid::new(&points);
                    let mean = points.iter().sum::<DVec2>() / points.len() as f64;
                    (0..points.len())
                        .map(|a| {
                            let from = match facing {
                                Facing::Neighbour => {
                                    index.nearest(points[a], 2).into_iter().find(|&b| b != a)
                                }
                                _ => None,
                            };
                            heading(points[a] - from.map_or(mean, |b| points[b]))
                        })
                        .collect()
                }
            };
            if folded {
                out.fold_toward(kind, &members, &heads);
                any = true;
                continue;
            }
            for (&i, head) in members.iter().zip(heads) {
                if let Some(rot) = head {
                    out.turn_about_centre(i, rot - out.of[i].1.rot);
                }
            }
            out.kinds[k].frame.rot = out.of[kind.representative].1.rot;
            out.kinds[k].frame.pos = out.of[kind.representative].1.pos;
            any = true;
        }
        any.then_some(out)
    }

    /// For a k-fold kind, each member's variant (its frame turned about
    /// its centre by a k-th of a turn) that heads it as the kind's
    /// representative (or first member with a heading) heads relative to
    /// its own: a 2-fold stem of a tree then points along its branch, not
    /// back down it.
    fn fold_toward(&mut self, kind: &Kind, members: &[usize], heads: &[Option<f64>]) {
        let step = TAU / kind.symmetry as f64;
        let first = members
            .iter()
            .position(|&i| i == kind.representative)
            .filter(|&a| heads[a].is_some())
            .or_else(|| heads.iter().position(Option::is_some));
        let Some(phi) = first.and_then(|a| Some(wrap(self.of[members[a]].1.rot - heads[a]?)))
        else {
            return;
        };
        for (&i, head) in members.iter().zip(heads) {
            let Some(h) = head else {
                continue;
            };
            let turn = (wrap(h + phi - self.of[i].1.rot) / step).round() * step;
            self.turn_about_centre(i, turn);
        }
    }

    /// Element `i`'s frame turned by `turn` about the element's centre: a
    /// frame off the centre keeps its place in the element's own frame.
    fn turn_about_centre(&mut self, i: usize, turn: f64) {
        let f = &mut self.of[i].1;
        let c = self.shapes[i].centroid;
        f.pos = c + rotate(f.pos - c, turn);
        f.rot = wrap(f.rot + turn);
    }

    /// Moves kind `k`'s local frame by `change` (given in the old local
    /// frame), and every instance's frame with it.
    pub fn reframe(&mut self, k: usize, change: &Frame) {
        self.kinds[k].frame = self.kinds[k].frame.then(change);
        for (kk, f) in self.of.iter_mut() {
            if *kk == k {
                *f = f.then(change);
            }
        }
    }
}

/// Which way a round element is turned to head (`Instancing::turned_round`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Facing {
    /// Away from its nearest neighbour of its kind.
    Neighbour,
    /// Away from the mean place of its kind.
    Out,
    /// The way the path through its kind runs (`along_path`).
    Path,
    /// Towards the place its stem reaches (`toward_forks`).
    Fork,
}

/// The turtle heading (local +y) along `d`; `None` for no direction.
fn heading(d: DVec2) -> Option<f64> {
    (d.length_squared() > 0.0).then(|| (-d.x).atan2(d.y))
}

/// Headings of round stems (the elements `members` of one kind, among
/// all elements `of`, each of outline radius `radii`) towards where each
/// one ends: a disc at the base of a stem hides its heading, but every
/// stem of a branching reaches its children a distance proportional to its
/// own size away, so the distance over scale shared by the most stems
/// (within `within`, relative) says which of the places near each stem
/// (its 16 nearest) is its tip (`most_shared`). Smaller stems of its kind
/// are counted first, then elements of any kind. A place nearer than
/// 10⁻³ of its scale (with `within` over 1 %: within its own outline) is
/// a concentric sibling, not a child. The last stems are turned by
/// `tips_by_turn`. `None` for a stem nothing heads; no headings at all
/// when fewer than two stems share a ratio with smaller stems and fewer
/// than half (or 3) with any places, or (`deep`: for a kind that shows a
/// heading up to a k-th of a turn, which a ring or row reads as well)
/// when no stem's child has children of its own at that ratio.
fn toward_forks(
    members: &[usize],
    of: &[(usize, Frame)],
    radii: &[f64],
    (within, deep): (f64, bool),
) -> Option<Vec<Option<f64>>> {
    const NEAR: usize = 16;
    // A place this near a stem is its concentric sibling: within its own
    // outline when placed by hand (`within` over 1 %).
    let apart = |i: usize, s: f64| {
        if within > 0.01 { radii[i] } else { 1e-3 * s }
    };
    let all: Vec<DVec2> = of.iter().map(|(_, f)| f.pos).collect();
    let index = crate::geometry::index::PointGrid::new(&all);
    let points: Vec<DVec2> = members.iter().map(|&i| all[i]).collect();
    let member: std::collections::HashMap<usize, usize> =
        members.iter().enumerate().map(|(a, &i)| (i, a)).collect();
    // (distance / scale, stem, place) for each stem's nearby places: the
    // smaller stems of its kind first, then places of any kind.
    let near = |stems_only: bool| {
        let mut ratios: Vec<(f64, usize, usize)> = Vec::new();
        for (a, &i) in members.iter().enumerate() {
            let (kind, s, p) = (of[i].0, of[i].1.scale, all[i]);
            for b in index.nearest(p, NEAR) {
                let d = (all[b] - p).length();
                let smaller = of[b].0 == kind && of[b].1.scale < s * (1.0 - within / 2.0);
                let child = smaller || (of[b].0 != kind && !stems_only);
                if s > 0.0 && d > apart(i, s) && child {
                    ratios.push((d / s, a, b));
                }
            }
        }
        ratios.sort_by(|x, y| x.0.total_cmp(&y.0));
        let ((count, chained), low) =
            most_shared(&ratios, points.len(), within, |b| member.get(&b).copied());
        (ratios, count, chained, low)
    };
    let (mut ratios, mut count, chained, mut low) = near(true);
    if deep && (count < 2 || chained == 0) {
        return None;
    }
    if count < 2 {
        (ratios, count, _, low) = near(false);
        if count < 3 || 2 * count < points.len() {
            return None;
        }
    }
    let high = low * (1.0 + within);
    let mid = (low + high) / 2.0;
    let mut heads: Vec<Option<f64>> = vec![None; points.len()];
    // Each stem's parent: the stem whose tip it sits at.
    let mut parent: Vec<Option<usize>> = vec![None; points.len()];
    let groups = concentric(members, of, &all, within, mid);
    // The window's places, per stem.
    let mut reached: Vec<Vec<(f64, usize)>> = vec![Vec::new(); points.len()];
    for &(r, a, b) in ratios.iter().filter(|x| x.0 >= low && x.0 <= high) {
        reached[a].push((r, b));
    }
    for group in &groups {
        // The distinct places the group's stems reach, nearest the
        // window's middle first: concentric stems of one size are alike,
        // so each takes its own tip in turn; a stem alone takes the
        // nearest, and every place in the window is a child of it.
        let s = of[members[group[0]]].1.scale;
        let mut tips: Vec<(f64, DVec2, Vec<usize>)> = Vec::new();
        for &(r, b) in group.iter().flat_map(|&a| &reached[a]) {
            let off = (r - mid).abs();
            match tips
                .iter_mut()
                .find(|(_, t, _)| (*t - all[b]).length() < within * mid * s)
            {
                Some((o, _, at)) => {
                    *o = o.min(off);
                    at.push(b);
                }
                None => tips.push((off, all[b], vec![b])),
            }
        }
        if group.len() > 1 {
            tips.sort_by(|x, y| x.1.x.total_cmp(&y.1.x).then(x.1.y.total_cmp(&y.1.y)));
        } else {
            tips.sort_by(|x, y| x.0.total_cmp(&y.0));
        }
        for (k, (_, tip, at)) in tips.iter().enumerate() {
            let a = group[k.min(group.len() - 1)];
            if k < group.len() {
                heads[a] = heading(*tip - points[a]);
            }
            for b in at {
                if let Some(&c) = member.get(b) {
                    parent[c] = Some(a);
                }
            }
        }
    }
    // A stem whose centre is off its base reaches each side's child at
    // its own ratio: the next fullest window gives the other side's
    // parents (the headings stay the first window's).
    let rest: Vec<(f64, usize, usize)> = ratios
        .iter()
        .filter(|x| {
            (x.0 < low || x.0 > high) && member.get(&x.2).is_some_and(|&c| parent[c].is_none())
        })
        .copied()
        .collect();
    let ((others, _), low2) = most_shared(&rest, points.len(), within, |b| member.get(&b).copied());
    if others >= 2 {
        for &(_, a, b) in rest
            .iter()
            .filter(|x| x.0 >= low2 && x.0 <= low2 * (1.0 + within))
        {
            if let Some(&c) = member.get(&b) {
                parent[c].get_or_insert(a);
            }
        }
    }
    tips_by_turn(
        members,
        of,
        &all,
        &groups,
        &parent,
        (mid, within),
        &mut heads,
    );
    Some(heads)
}

/// The stems of `members` (by index) grouped where they are concentric
/// and of one size (within `within` of a stem's `reach` times its scale),
/// in order.
fn concentric(
    members: &[usize],
    of: &[(usize, Frame)],
    all: &[DVec2],
    within: f64,
    reach: f64,
) -> Vec<Vec<usize>> {
    let points: Vec<DVec2> = members.iter().map(|&i| all[i]).collect();
    let index = crate::geometry::index::PointGrid::new(&points);
    let mut group = vec![usize::MAX; points.len()];
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for a in 0..points.len() {
        if group[a] != usize::MAX {
            continue;
        }
        let s = of[members[a]].1.scale;
        let alike = |b: usize| {
            let t = of[members[b]].1.scale;
            (points[b] - points[a]).length() < within * reach * s
                && (t / s - 1.0).abs() < within / 2.0
        };
        let mut g = vec![a];
        for b in index.nearest(points[a], 8) {
            if b != a && group[b] == usize::MAX && alike(b) {
                g.push(b);
            }
        }
        g.sort_unstable();
        for &b in &g {
            group[b] = groups.len();
        }
        groups.push(g);
    }
    groups
}

/// The window of `ratios` (sorted, each with its stem of `n` and a
/// place) within `within` of its first that holds the most distinct
/// stems: their count, how many of its places are stems of the window
/// themselves, and the window's first ratio. Of windows as full,
/// the one whose places are most often stems of the window themselves: a
/// stem's children have children of their own at the same ratio, its
/// smaller sibling (as far from it, and as often) has none.
fn most_shared(
    ratios: &[(f64, usize, usize)],
    n: usize,
    within: f64,
    stem_of: impl Fn(usize) -> Option<usize>,
) -> ((usize, usize), f64) {
    // A window slid over the sorted ratios: per stem, its entries in the
    // window and the entries whose place it is; `chained` counts entries
    // whose place is a stem with entries of its own.
    let mut own = vec![0usize; n];
    let mut pointed = vec![0usize; n];
    let (mut count, mut chained) = (0usize, 0usize);
    let mut best = ((0, 0), 0.0);
    let mut end = 0;
    for (w, &(r, _, _)) in ratios.iter().enumerate() {
        while end < ratios.len() && ratios[end].0 <= r * (1.0 + within) {
            let (_, a, b) = ratios[end];
            own[a] += 1;
            if own[a] == 1 {
                count += 1;
                chained += pointed[a];
            }
            if let Some(c) = stem_of(b) {
                pointed[c] += 1;
                chained += usize::from(own[c] > 0);
            }
            end += 1;
        }
        if (count, chained) > best.0 {
            best = ((count, chained), r);
        }
        // The window's first entry leaves before the next window.
        let (_, a, b) = ratios[w];
        if let Some(c) = stem_of(b) {
            pointed[c] -= 1;
            chained -= usize::from(own[c] > 0);
        }
        own[a] -= 1;
        if own[a] == 0 {
            count -= 1;
            chained -= pointed[a];
        }
    }
    best
}

/// Headings for the last stems of a branching (`toward_forks`), whose
/// children are of another kind and sit anywhere near their tip: each
/// turns from its parent as a stem of its size turns from its parent
/// where both headings are known. Of the turns its scale allows, the stems
/// of a concentric group take those whose tip, `reach` times the stem's
/// scale ahead, is nearest an element of another kind, one each.
fn tips_by_turn(
    members: &[usize],
    of: &[(usize, Frame)],
    all: &[DVec2],
    groups: &[Vec<usize>],
    parent: &[Option<usize>],
    (reach, within): (f64, f64),
    heads: &mut [Option<f64>],
) {
    let scale = |a: usize| of[members[a]].1.scale;
    // (scale over the parent's, turn from the parent) where both are known.
    let mut turns: Vec<(f64, f64)> = Vec::new();
    for a in 0..members.len() {
        let (Some(p), Some(h)) = (parent[a], heads[a]) else {
            continue;
        };
        let Some(from) = heads[p] else {
            continue;
        };
        let t = (scale(a) / scale(p), wrap(h - from));
        let new = |u: &(f64, f64)| {
            (u.0 / t.0 - 1.0).abs() > within || wrap(u.1 - t.1).abs() > 2.0 * within
        };
        if turns.iter().all(new) {
            turns.push(t);
        }
    }
    let kind = members.first().map(|&i| of[i].0);
    let others: Vec<DVec2> = (0..of.len())
        .filter(|&i| Some(of[i].0) != kind)
        .map(|i| all[i])
        .collect();
    if turns.is_empty() || others.is_empty() {
        return;
    }
    let index = crate::geometry::index::PointGrid::new(&others);
    for group in groups {
        let a = group[0];
        let (None, Some(p)) = (heads[a], parent[a]) else {
            continue;
        };
        let Some(from) = heads[p] else {
            continue;
        };
        let ratio = scale(a) / scale(p);
        let at = all[members[a]];
        let gap = |h: f64| {
            let tip = at + rotate(DVec2::Y, h) * reach * scale(a);
            index
                .nearest(tip, 1)
                .first()
                .map_or(f64::INFINITY, |&o| (others[o] - tip).length())
        };
        let mut allowed: Vec<(f64, f64)> = turns
            .iter()
            .filter(|(r, _)| (r / ratio - 1.0).abs() < within)
            .map(|&(_, t)| (gap(wrap(from + t)), wrap(from + t)))
            .collect();
        allowed.sort_by(|x, y| x.0.total_cmp(&y.0));
        for (&b, &(_, h)) in group.iter().zip(&allowed) {
            heads[b] = Some(h);
        }
    }
}

/// Headings along the nearest-neighbour tree of `points` read from one of
/// its ends: each point heads the way it was reached (away from its parent),
/// the end itself as the turning of the three steps after it continues
/// (a chain of discs whose turn changes step by step reads as a turtle
/// walking it, the same change at every step). `None` where a point
/// coincides with its parent.
fn along_path(points: &[DVec2]) -> Vec<Option<f64>> {
    const NEIGHBOURS: usize = 6;
    let n = points.len();
    let mut next: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (a, b) in nearest_first(points, NEIGHBOURS) {
        next[a].push(b);
        next[b].push(a);
    }
    // Breadth first from `root`: each point's parent, and the last reached.
    let walk = |root: usize| {
        let mut parent = vec![usize::MAX; n];
        let mut queue = std::collections::VecDeque::from([root]);
        parent[root] = root;
        let mut last = root;
        while let Some(v) = queue.pop_front() {
            last = v;
            for &w in &next[v] {
                if parent[w] == usize::MAX {
                    parent[w] = v;
                    queue.push_back(w);
                }
            }
        }
        (parent, last)
    };
    let (_, end) = walk(0);
    let (parent, _) = walk(end);
    let mut heads: Vec<Option<f64>> = (0..n)
        .map(|v| match parent[v] {
            p if p == v || p == usize::MAX => None,
            p => heading(points[v] - points[p]),
        })
        .collect();
    // The end heads as the turning continued backwards: with h1, h2, h3
    // the headings of the three points after it, h0 = h1 − (2(h2 − h1) −
    // (h3 − h2)).
    let only = |v: usize| match next[v].as_slice() {
        [w] => Some(*w),
        [a, b] if parent[*a] == v && parent[*b] != v => Some(*a),
        [a, b] if parent[*b] == v && parent[*a] != v => Some(*b),
        _ => None,
    };
    let chain = only(end).and_then(|c1| {
        let c2 = only(c1)?;
        let c3 = only(c2)?;
        Some((heads[c1]?, heads[c2]?, heads[c3]?))
    });
    heads[end] = match chain {
        Some((h1, h2, h3)) => Some(wrap(h1 - (2.0 * wrap(h2 - h1) - wrap(h3 - h2)))),
        None => next[end].first().and_then(|&c| heads[c]),
    };
    heads
}

/// Subpaths with every point mapped by `f`.
pub fn map_subpaths(subpaths: &[Vec<Seg>], f: impl Fn(DVec2) -> DVec2) -> Vec<Vec<Seg>> {
    subpaths
        .iter()
        .map(|sub| sub.iter().map(|s| map_seg(s, &f)).collect())
        .collect()
}

/// A segment with its points mapped by `f`.
pub fn map_seg(s: &Seg, f: impl Fn(DVec2) -> DVec2) -> Seg {
    match *s {
        Seg::Move(p) => Seg::Move(f(p)),
        Seg::Line(p) => Seg::Line(f(p)),
        Seg::Quad(c, p) => Seg::Quad(f(c), f(p)),
        Seg::Cubic(a, b, p) => Seg::Cubic(f(a), f(b), f(p)),
        Seg::Close => Seg::Close,
    }
}

/// The shape mirrored about the y axis of `frame`, with its outline.
fn mirrored(sh: &Shape, subpaths: &[Vec<Seg>], frame: &Frame) -> Option<(Shape, Vec<Vec<Seg>>)> {
    let flip = |p: DVec2| {
        let q = frame.local(p);
        frame.apply(DVec2::new(-q.x, q.y))
    };
    let lines: Vec<Vec<DVec2>> = sh
        .outline
        .iter()
        .map(|l| l.iter().map(|p| flip(sh.centroid + *p)).collect())
        .collect();
    Some((Shape::of(&lines)?, map_subpaths(subpaths, flip)))
}

/// The frame of an element that is a kind's shape `rep` turned by `a` and
/// scaled by `s`, when the kind's local frame is `frame`; `sh` is the
/// element's shape.
fn placed_frame(frame: &Frame, rep: &Shape, sh: &Shape, a: f64, s: f64) -> Frame {
    Frame {
        pos: sh.centroid + rotate(frame.pos - rep.centroid, a) * s,
        rot: wrap(frame.rot + a),
        scale: frame.scale * s,
    }
}

/// How far a drawing's map may be from a similarity (relative to its
/// scale) for its frame to be taken: lsyc writes matrices to 5 decimals.
const SIMILARITY: f64 = 1e-3;

/// A group of elements that draw one definition through similarities,
/// mirrored alike.
struct Given {
    /// In document order.
    members: Vec<usize>,
    /// How the definition's path is read (x and y multiplied by ±1): y
    /// flipped when the drawing mirrors it (a y-down drawing read y up).
    flip: DVec2,
    /// The group of the same definition drawn the other way round, read as
    /// its mirror image (x negated), when this one came later.
    mirror_of: Option<usize>,
}

/// The groups of elements that draw one definition through similarities:
/// the drawing gives their frames. A group counts when its members are
/// placed differently, or, for a single element, when its map is not the
/// one most elements share (the document's own).
fn given_groups(elements: &[Element]) -> Vec<Given> {
    let mut groups: Vec<Given> = Vec::new();
    let mut index: HashMap<(u64, bool), usize> = HashMap::new();
    for (i, e) in elements.iter().enumerate() {
        if !e.placed.is_similarity(SIMILARITY) {
            continue;
        }
        let mirrors = e.placed.det() < 0.0;
        let g = match index.get(&(e.placed.key, mirrors)) {
            Some(&g) => g,
            None => {
                let twin = index.get(&(e.placed.key, !mirrors)).copied();
                let y = if mirrors { -1.0 } else { 1.0 };
                let flip = match twin {
                    // The twin's reading, x negated.
                    Some(t) => DVec2::new(-groups[t].flip.x, groups[t].flip.y),
                    None => DVec2::new(1.0, y),
                };
                index.insert((e.placed.key, mirrors), groups.len());
                groups.push(Given {
                    members: Vec::new(),
                    flip,
                    mirror_of: twin,
                });
                groups.len() - 1
            }
        };
        groups[g].members.push(i);
    }
    let bits = |m: &[f64; 6]| m.map(|v| (v as f32).to_bits());
    let mut maps: Vec<[u32; 6]> = elements.iter().map(|e| bits(&e.placed.map)).collect();
    maps.sort_unstable();
    let document = maps
        .chunk_by(|a, b| a == b)
        .max_by_key(|c| c.len())
        .map(|c| c[0]);
    let counts: Vec<bool> = groups
        .iter()
        .map(|g| {
            let first = bits(&elements[g.members[0]].placed.map);
            if g.members.len() >= 2 {
                g.members
                    .iter()
                    .any(|&i| bits(&elements[i].placed.map) != first)
            } else {
                Some(first) != document || elements.len() == 1
            }
        })
        .collect();
    // Renumber the twins of the groups kept.
    let mut new = vec![None; groups.len()];
    let mut kept = 0;
    for (g, keep) in counts.iter().enumerate() {
        if *keep {
            new[g] = Some(kept);
            kept += 1;
        }
    }
    groups
        .into_iter()
        .zip(counts)
        .filter(|(_, keep)| *keep)
        .map(|(mut g, _)| {
            g.mirror_of = g.mirror_of.and_then(|t| new[t]);
            g
        })
        .collect()
}

/// Groups elements into kinds. `tolerance` is the largest mean misfit,
/// relative to the element's radius, of two alike elements.
pub fn instancing(
    elements: &[Element],
    tolerance: f64,
    reflect: bool,
) -> Result<Instancing, TooMuchWork> {
    let mut budget = Budget::new("comparisons of element outlines", MAX_COMPARISONS);
    let shapes: Vec<Shape> = elements
        .par_iter()
        .map(|e| {
            Shape::of(&e.outline).unwrap_or_else(|| {
                // A point-like element: describe it by its box.
                let c = (e.min + e.max) * 0.5;
                Shape {
                    centroid: c,
                    radius: 1e-9,
                    samples: vec![DVec2::ZERO; SAMPLES],
                    outline: vec![vec![DVec2::ZERO, DVec2::ZERO]],
                    harmonics: vec![DVec2::ZERO; HARMONICS],
                    perimeter: 0.0,
                }
            })
        })
        .collect();
    let mut kinds: Vec<Kind> = Vec::new();
    // Each kind's representative outline (mirrored for a mirror kind).
    let mut kind_shapes: Vec<Shape> = Vec::new();
    let mut of: Vec<Option<(usize, Frame)>> = vec![None; elements.len()];
    // Choices of frame for instances of symmetric kinds.
    let mut choices: Vec<Vec<Frame>> = vec![Vec::new(); elements.len()];
    // Whether each kind has a mirror kind.
    let mut mirrored_by: Vec<bool> = Vec::new();
    let symmetry_of = |sh: &Shape| match sh.order() {
        None => 0,
        Some(_) => match sh.align(sh, tolerance).len() {
            k if k > 1 && sh.turns_alike(k) => k,
            _ => 1,
        },
    };
    // Kinds whose frames the drawing gives (a group's kind is its index).
    for g in given_groups(elements) {
        let rep = g.members[0];
        let sh = &shapes[rep];
        let symmetry = symmetry_of(sh);
        let k = kinds.len();
        for &i in &g.members {
            let f = Frame::of_map(&elements[i].placed.map, g.flip);
            of[i] = Some((k, f));
            // A symmetric element may be turned about its centroid.
            let c = shapes[i].centroid;
            choices[i] = (0..symmetry.max(1))
                .map(|j| {
                    let a = TAU * j as f64 / symmetry.max(1) as f64;
                    Frame {
                        pos: c + rotate(f.pos - c, a),
                        rot: wrap(f.rot + a),
                        scale: f.scale,
                    }
                })
                .collect();
        }
        // The representative of a symmetric kind turned least: its
        // neighbours follow it (`orient_symmetric`).
        let least = choices[rep]
            .iter()
            .copied()
            .min_by(|a, b| a.rot.abs().total_cmp(&b.rot.abs()))
            .unwrap_or(Frame::IDENTITY);
        of[rep] = Some((k, least));
        kinds.push(Kind {
            representative: rep,
            symmetry,
            frame: least,
            given: true,
            subpaths: elements[rep].subpaths.clone(),
            mirror_of: g.mirror_of.filter(|_| reflect),
        });
        kind_shapes.push(sh.clone());
        mirrored_by.push(false);
        if let Some(t) = g.mirror_of.filter(|_| reflect) {
            mirrored_by[t] = true;
        }
    }
    for (i, e) in elements.iter().enumerate() {
        if of[i].is_some() {
            continue;
        }
        let sh = &shapes[i];
        let mut found = None;
        for (k, kind) in kinds.iter().enumerate() {
            let r = &elements[kind.representative];
            if r.style.key() != e.style.key() || r.subpaths.len() != e.subpaths.len() {
                continue;
            }
            budget.spend(1)?;
            let fits = kind_shapes[k].align(sh, tolerance);
            if !fits.is_empty() {
                found = Some((k, fits));
                break;
            }
        }
        if found.is_none() && reflect {
            // A mirror image of a kind that has no mirror kind yet.
            for k in 0..kinds.len() {
                let r = &elements[kinds[k].representative];
                if kinds[k].mirror_of.is_some()
                    || mirrored_by[k]
                    || r.style.key() != e.style.key()
                    || r.subpaths.len() != e.subpaths.len()
                {
                    continue;
                }
                let Some((m, subpaths)) =
                    mirrored(&kind_shapes[k], &kinds[k].subpaths, &kinds[k].frame)
                else {
                    continue;
                };
                budget.spend(1)?;
                let fits = m.align(sh, tolerance);
                if !fits.is_empty() {
                    kinds.push(Kind {
                        mirror_of: Some(k),
                        subpaths,
                        given: false,
                        ..kinds[k].clone()
                    });
                    mirrored_by[k] = true;
                    mirrored_by.push(false);
                    kind_shapes.push(m);
                    found = Some((kinds.len() - 1, fits));
                    break;
                }
            }
        }
        match found {
            Some((k, fits)) => {
                let rep = &kind_shapes[k];
                let best = fits[0].1;
                let s = sh.radius / rep.radius;
                let variants: Vec<Frame> = fits
                    .iter()
                    .filter(|f| f.1 <= best + tolerance * 0.5)
                    .map(|f| placed_frame(&kinds[k].frame, rep, sh, f.0, s))
                    .collect();
                of[i] = Some((k, variants[0]));
                choices[i] = variants;
            }
            None => {
                mirrored_by.push(false);
                let frame = Frame {
                    pos: sh.centroid,
                    rot: 0.0,
                    scale: 1.0,
                };
                kinds.push(Kind {
                    representative: i,
                    symmetry: symmetry_of(sh),
                    frame,
                    given: false,
                    subpaths: e.subpaths.clone(),
                    mirror_of: None,
                });
                kind_shapes.push(sh.clone());
                of[i] = Some((kinds.len() - 1, frame));
                choices[i] = vec![frame];
            }
        }
    }
    let mut of: Vec<(usize, Frame)> = of.into_iter().flatten().collect();
    orient_symmetric(&kinds, &shapes, &mut of, &choices);
    Ok(Instancing { kinds, shapes, of })
}

/// Chooses, for instances of symmetric kinds, the variant of frame whose
/// rotation is closest to its nearest already placed neighbour of the same
/// kind (`nearest_first`), so orientations vary smoothly along a ring. Round kinds the drawing does not place keep
/// the drawing's axes.
fn orient_symmetric(
    kinds: &[Kind],
    shapes: &[Shape],
    of: &mut [(usize, Frame)],
    choices: &[Vec<Frame>],
) {
    const NEIGHBOURS: usize = 6;
    for (k, kind) in kinds.iter().enumerate() {
        if kind.symmetry == 1 {
            continue;
        }
        let members: Vec<usize> = (0..of.len()).filter(|&i| of[i].0 == k).collect();
        if kind.symmetry == 0 {
            if !kind.given {
                // No orientation to choose: the local frame sits where it
                // sits on the representative, unturned.
                let rep = &shapes[kind.representative];
                for &i in &members {
                    let f = &mut of[i].1;
                    let s = f.scale / kind.frame.scale;
                    f.pos = shapes[i].centroid + (kind.frame.pos - rep.centroid) * s;
                    f.rot = kind.frame.rot;
                }
            }
            continue;
        }
        let points: Vec<DVec2> = members.iter().map(|&i| of[i].1.pos).collect();
        for (from, b) in nearest_first(&points, NEIGHBOURS) {
            let rot = of[members[from]].1.rot;
            let i = members[b];
            if let Some(best) = choices[i]
                .iter()
                .copied()
                .min_by(|x, y| wrap(x.rot - rot).abs().total_cmp(&wrap(y.rot - rot).abs()))
            {
                of[i].1 = best;
            }
        }
    }
}

/// The points in the order a nearest-neighbour tree reaches them (Prim's
/// order over each point's `k` nearest): each point after the first of its
/// group as (the reached point it is nearest to, the point). Each point
/// follows its nearest placed neighbour, not the group's first point, so
/// orientations follow a ring or a row step by step.
fn nearest_first(points: &[DVec2], k: usize) -> Vec<(usize, usize)> {
    use std::cmp::Reverse;
    use std::collections::BinaryHeap;
    let index = crate::geometry::index::PointGrid::new(points);
    let mut placed = vec![false; points.len()];
    let mut order = Vec::new();
    // (distance's bits, from, to): non-negative floats order as their bits.
    let mut heap: BinaryHeap<Reverse<(u64, usize, usize)>> = BinaryHeap::new();
    let reach = |a: usize, heap: &mut BinaryHeap<Reverse<(u64, usize, usize)>>| {
        for b in index.nearest(points[a], k + 1) {
            if b != a {
                heap.push(Reverse((points[a].distance(points[b]).to_bits(), a, b)));
            }
        }
    };
    for start in 0..points.len() {
        if placed[start] {
            continue;
        }
        placed[start] = true;
        reach(start, &mut heap);
        while let Some(Reverse((_, a, b))) = heap.pop() {
            if placed[b] {
                continue;
            }
            placed[b] = true;
            order.push((a, b));
            reach(b, &mut heap);
        }
    }
    order
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tree of discs (kind 0), two children at each stem's tip turned
    /// +30° and −40° and scaled 0.7 and 0.5, leaves (kind 1) at the last
    /// stems' tips: each element with the heading it was drawn with.
    fn disc_tree() -> (Vec<(usize, Frame)>, Vec<f64>) {
        fn grow(f: Frame, depth: usize, of: &mut Vec<(usize, Frame)>, heads: &mut Vec<f64>) {
            of.push((usize::from(depth == 0), Frame { rot: 0.0, ..f }));
            heads.push(f.rot);
            if depth == 0 {
                return;
            }
            let tip = f.pos + rotate(DVec2::Y, f.rot) * 10.0 * f.scale;
            for (turn, scale) in [(30f64, 0.7), (-40f64, 0.5)] {
                let child = Frame {
                    pos: tip,
                    rot: wrap(f.rot + turn.to_radians()),
                    scale: f.scale * scale,
                };
                grow(child, depth - 1, of, heads);
            }
        }
        let (mut of, mut heads) = (Vec::new(), Vec::new());
        grow(Frame::IDENTITY, 3, &mut of, &mut heads);
        (of, heads)
    }

    #[test]
    fn round_stems_head_towards_their_tips() {
        let (of, truth) = disc_tree();
        let members: Vec<usize> = (0..of.len()).filter(|&i| of[i].0 == 0).collect();
        assert_eq!(members.len(), 7);
        let heads = toward_forks(&members, &of, &vec![1.0; of.len()], (0.01, false))
            .expect("a fork reading");
        for (&i, h) in members.iter().zip(heads) {
            let h = h.expect("every stem heads somewhere");
            assert!(
                wrap(h - truth[i]).abs() < 1e-9,
                "stem {i}: {h} for {}",
                truth[i]
            );
        }
    }

    fn poly(points: &[(f64, f64)], f: Frame) -> Vec<Vec<DVec2>> {
        let mut l: Vec<DVec2> = points
            .iter()
            .map(|&(x, y)| f.apply(DVec2::new(x, y)))
            .collect();
        l.push(l[0]);
        vec![l]
    }

    const ARROW: [(f64, f64); 7] = [
        (0.0, 3.0),
        (2.0, 1.0),
        (1.0, 1.0),
        (1.0, -3.0),
        (-1.0, -3.0),
        (-1.0, 1.0),
        (-2.0, 1.0),
    ];

    #[test]
    fn rotated_scaled_copies_align() {
        let id = Frame {
            pos: DVec2::ZERO,
            rot: 0.0,
            scale: 1.0,
        };
        let f = Frame {
            pos: DVec2::new(10.0, -4.0),
            rot: 0.7,
            scale: 2.5,
        };
        let a = Shape::of(&poly(&ARROW, id)).unwrap();
        let b = Shape::of(&poly(&ARROW, f)).unwrap();
        let fits = a.align(&b, 0.02);
        assert_eq!(fits.len(), 1, "{fits:?}");
        assert!((fits[0].0 - 0.7).abs() < 1e-6, "{fits:?}");
        assert!((b.radius / a.radius - 2.5).abs() < 1e-9);
        // A different shape does not align.
        let sq = Shape::of(&poly(&[(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)], id)).unwrap();
        assert!(a.align(&sq, 0.02).is_empty());
        // A square has four rotations onto itself.
        assert_eq!(sq.align(&sq, 0.02).len(), 4);
    }

    #[test]
    fn a_star_pulled_out_of_true_is_not_three_fold() {
        let id = Frame::IDENTITY;
        // Public Icons' star (Unlicense): five points, not quite regular.
        let star = [
            (41.504, 39.537),
            (60.062, 0.0),
            (78.618, 39.538),
            (120.115, 45.877),
            (90.088, 76.653),
            (97.176, 120.107),
            (60.061, 99.593),
            (22.946, 120.107),
            (30.035, 76.653),
            (0.01, 45.878),
        ];
        let sh = Shape::of(&poly(&star, id)).unwrap();
        assert!(!sh.turns_alike(3), "{:?}", sh.harmonics);
        let regular: Vec<(f64, f64)> = (0..10)
            .map(|i| {
                let r = if i % 2 == 0 { 50.0 } else { 20.0 };
                let a = (36.0 * i as f64).to_radians();
                (r * a.sin(), r * a.cos())
            })
            .collect();
        let sh = Shape::of(&poly(&regular, id)).unwrap();
        assert!(sh.turns_alike(5));
        assert_eq!(sh.align(&sh, 0.02).len(), 5);
    }
}
