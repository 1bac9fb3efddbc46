//! Reading a line drawing as turtle moves.
//!
//! Owns: what a line drawing is (every visible shape stroked, unfilled and
//! made of straight segments; see `docs/language.md`), its polylines in
//! document order in world coordinates (y up), and their reading as turtle
//! steps: the step length (every segment a whole number of steps), the angle
//! δ (every turn a whole number of δ), the start frame, and the tree of
//! steps (`turtle::Builder`). Must not search grammars.

use super::turtle::{Angles, Builder, Kind, Tree, Unfit};
use crate::infer::svg::{self, Seg};
use glam::DVec2;

/// The most points a line drawing may have (as `infer ART.svg` reads).
pub const MAX_POINTS: usize = 4_000_000;
/// The most steps a drawing may have once its segments are cut into steps.
pub const MAX_STEPS: usize = 1_000_000;
/// Coordinates beyond this are not read (usvg works in 32-bit floats).
pub const MAX_COORDINATE: f64 = 1.0e7;
/// The smallest δ read, degrees.
pub const MIN_DELTA: f64 = 3.0;

/// Why a drawing is not read as a line drawing (for a note).
#[derive(Clone, Debug, PartialEq)]
pub enum NotLines {
    /// Not a line drawing at all: a filled shape, a curve, nothing stroked.
    Shapes(&'static str),
    /// A line drawing that does not read as turtle steps; the reason.
    Steps(String),
}

/// The polylines of a line drawing, document order, world coordinates.
pub fn polylines(data: &[u8]) -> Result<Vec<Vec<DVec2>>, NotLines> {
    let tree = svg::parse(data).map_err(|_| NotLines::Shapes("not an SVG lsyc reads"))?;
    let user = svg::user_space(data, &tree);
    let mut out: Vec<Vec<DVec2>> = Vec::new();
    let mut points = 0usize;
    for (path, t) in svg::paths(&tree) {
        if !path.is_visible() {
            continue;
        }
        if path.stroke().is_none() {
            if path.fill().is_some() {
                return Err(NotLines::Shapes("a filled shape"));
            }
            continue;
        }
        // A fill of no area (a `<line>`, a path back and forth) paints nothing.
        if path.fill().is_some() && filled_area(path) > 0.0 {
            return Err(NotLines::Shapes("a filled shape"));
        }
        points = points.saturating_add(path.data().points().len());
        if points > MAX_POINTS {
            return Err(NotLines::Shapes("too many points"));
        }
        for sub in svg::subpaths(path, user.pre_concat(t)) {
            let mut line: Vec<DVec2> = Vec::new();
            let mut first = None;
            for s in sub {
                let p = match s {
                    Seg::Move(p) | Seg::Line(p) => p,
                    Seg::Close => match first {
                        Some(p) => p,
                        None => continue,
                    },
                    Seg::Quad(..) | Seg::Cubic(..) => return Err(NotLines::Shapes("a curve")),
                };
                if !(p.is_finite() && p.x.abs() <= MAX_COORDINATE && p.y.abs() <= MAX_COORDINATE) {
                    return Err(NotLines::Shapes("coordinates out of range"));
                }
                first.get_or_insert(p);
                if line
                    .last()
                    .is_none_or(|q| q.distance(p) > 1e-9 * (1.0 + p.abs().max_element()))
                {
                    line.push(p);
                }
            }
            if line.len() >= 2 {
                out.push(line);
            }
        }
    }
    if out.is_empty() {
        return Err(NotLines::Shapes("no stroked segments"));
    }
    Ok(out)
}

/// The area a path's fill covers (the sum of its subpaths' absolute
/// areas, in its own coordinates), 0 within rounding.
fn filled_area(path: &usvg::Path) -> f64 {
    let pts = path.data().points();
    let (lo, hi) = pts.iter().fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| {
            let q = DVec2::new(f64::from(p.x), f64::from(p.y));
            (lo.min(q), hi.max(q))
        },
    );
    let size = (hi - lo).max_element();
    let mut total = 0.0;
    for sub in svg::subpaths(path, usvg::Transform::identity()) {
        let ring: Vec<DVec2> = sub
            .iter()
            .filter_map(|s| match *s {
                Seg::Move(p) | Seg::Line(p) => Some(p),
                Seg::Quad(_, p) | Seg::Cubic(_, _, p) => Some(p),
                Seg::Close => None,
            })
            .collect();
        let mut a = 0.0;
        for (i, p) in ring.iter().enumerate() {
            let q = ring[(i + 1) % ring.len()];
            a += p.perp_dot(q);
        }
        total += a.abs() / 2.0;
    }
    if total <= 1e-9 * size * size {
        0.0
    } else {
        total
    }
}

/// A line drawing read as turtle steps.
#[derive(Clone, Debug)]
pub struct Reading {
    pub tree: Tree,
    pub angles: Angles,
    /// The step length, user units.
    pub step: f64,
    /// Where the first step starts, world coordinates.
    pub start: DVec2,
    /// The first step's heading, degrees counter-clockwise from +y.
    pub heading: f64,
    /// The segments of the drawing, world coordinates, as read.
    pub segments: Vec<(DVec2, DVec2)>,
    /// Drawn steps.
    pub steps: usize,
    /// How uncertain δ is (degrees), from the spread of the turns.
    pub delta_error: f64,
    /// How uncertain the step length is (user units).
    pub step_error: f64,
    /// How uncertain the start frame is: (heading in degrees, start point
    /// in user units).
    pub frame_error: (f64, f64),
}

/// Reads `lines` as turtle steps, each segment `split` steps per shortest
/// segment (1: the shortest segment is one step; 2: half of it).
pub fn reading(lines: &[Vec<DVec2>], split: u32) -> Result<Reading, NotLines> {
    let segments: Vec<(DVec2, DVec2)> = lines
        .iter()
        .flat_map(|l| l.windows(2).map(|w| (w[0], w[1])))
        .collect();
    let lengths: Vec<f64> = segments.iter().map(|(a, b)| a.distance(*b)).collect();
    let shortest = lengths.iter().copied().fold(f64::INFINITY, f64::min);
    if !(shortest.is_finite() && shortest > 0.0) {
        return Err(NotLines::Steps("no segment has a length".into()));
    }
    // The step: first from the shortest segment, then from ever longer ones
    // (a long segment's length pins the step down better than a short one's,
    // once it is known how many steps it has).
    let mut step = shortest / f64::from(split.max(1));
    let longest = lengths.iter().copied().fold(0.0, f64::max);
    let mut limit = 4.0;
    loop {
        let (mut sum, mut units) = (0.0, 0.0);
        for &len in &lengths {
            let u = len / step;
            if u <= limit + 0.5 {
                sum += len;
                units += u.round().max(1.0);
            }
        }
        if units > 0.0 {
            step = sum / units;
        }
        if longest / step <= limit {
            break;
        }
        limit *= 4.0;
    }
    // Every segment a whole number of steps, within a fifth of a step.
    let (mut total, mut rr, mut res) = (0usize, 0.0, 0.0);
    for &len in &lengths {
        let u = len / step;
        let r = u.round();
        if r < 1.0 || (u - r).abs() > 0.2 {
            return Err(NotLines::Steps(format!(
                "a segment of length {} is not a whole number of steps of {}",
                crate::number::source(crate::infer::program::nice(len, len * 1e-4)),
                crate::number::source(crate::infer::program::nice(step, step * 1e-4))
            )));
        }
        rr += r * r;
        res += (len - r * step).powi(2);
        total = total.saturating_add(r as usize);
        if total > MAX_STEPS {
            return Err(NotLines::Steps(format!(
                "more than {MAX_STEPS} steps of equal length"
            )));
        }
    }
    let step_error = (res / (lengths.len().max(2) - 1) as f64).sqrt() / rr.sqrt();
    let (mut b, mut steps) = build(&segments, &lengths, step, None)?;
    // δ roughly, from the turns; the headings in whole turns of it (a
    // loose reading: a turn between two short segments carries the noise
    // of both); δ and the first heading by least squares; then each step's
    // heading read again against its parent's fitted heading, which
    // carries no noise.
    let unfit = |e: Unfit| match e {
        Unfit::Turn => NotLines::Steps("its turns are not all multiples of one angle".into()),
        Unfit::Jump => NotLines::Steps("a gap that is not a whole number of steps".into()),
        Unfit::TooLarge => NotLines::Steps("too many steps".into()),
    };
    let coarse = find_delta(&b, &steps.edge_of)?;
    // A long gap in several directions may come near a whole number of
    // steps: read with δ known, it is a jump.
    let d = coarse.delta.to_radians();
    let off = |i: usize| {
        let t = b.turn_radians(i) / d;
        (t - t.round()).abs() * coarse.delta > coarse.tolerance
    };
    if (1..b.raw.len()).any(|i| b.raw[i].kind == Kind::Move && off(i)) {
        (b, steps) = build(
            &segments,
            &lengths,
            step,
            Some((d, coarse.tolerance.to_radians())),
        )?;
    }
    let Steps { starts, firsts, .. } = steps;
    let loose = Angles::new(coarse.delta, None, 0.5 * coarse.delta + 1e-9);
    let first = headings(&b.tree(&loose).map_err(unfit)?);
    // Read again with the fitted δ: a curve that winds round and round
    // turns by hundreds of δ in all, and the rough δ's error with them.
    let (fitted, theta, _) = refine(&coarse, &segments, &firsts, &first);
    let (k, mut tree) = requantize(&b, theta, &fitted).map_err(unfit)?;
    let (angles, theta, delta_error) = refine(&coarse, &segments, &firsts, &k);
    for n in &mut tree.nodes {
        n.turn = angles.norm(n.turn);
    }
    let headings = k;
    let (start, heading_error, start_error) = fit_start(
        &tree, &headings, theta, &angles, step, &starts, &segments, &firsts,
    );
    Ok(Reading {
        steps: tree.draws(),
        tree,
        angles,
        step,
        step_error,
        start,
        heading: super::turtle::wrap_degrees(theta.to_degrees() - 90.0),
        frame_error: (heading_error, start_error),
        segments,
        delta_error,
    })
}

/// The drawn steps of a reading: where each starts, by node (world
/// coordinates), the first node of each segment, the segment of each node
/// (moves: none).
struct Steps {
    starts: Vec<(u32, DVec2)>,
    firsts: Vec<u32>,
    edge_of: Vec<u32>,
}

/// `segments` cut into steps of `step` and pushed into a builder; gaps off
/// the `lattice` (δ and its tolerance, radians) are jumps.
fn build(
    segments: &[(DVec2, DVec2)],
    lengths: &[f64],
    step: f64,
    lattice: Option<(f64, f64)>,
) -> Result<(Builder, Steps), NotLines> {
    let origin = segments[0].0;
    let mut b = Builder::new();
    b.lattice = lattice;
    let mut starts: Vec<(u32, DVec2)> = Vec::new();
    let mut firsts: Vec<u32> = Vec::with_capacity(segments.len());
    let mut edge_of: Vec<u32> = Vec::new();
    for (edge, (&(a, e), &len)) in segments.iter().zip(lengths).enumerate() {
        let n = (len / step).round().max(1.0) as usize;
        let (wa, we) = (a, e);
        let (a, e) = ((a - origin) / step, (e - origin) / step);
        for k in 0..n {
            let p = a.lerp(e, k as f64 / n as f64);
            let q = a.lerp(e, (k + 1) as f64 / n as f64);
            b.push(p, q).map_err(|e| match e {
                Unfit::TooLarge => NotLines::Steps(format!(
                    "more than {} steps and moves (gaps of whole steps)",
                    super::turtle::MAX_NODES
                )),
                _ => NotLines::Steps("a segment starts away from the drawing by a gap that is not a whole number of steps".into()),
            })?;
            let id = b.raw.len() as u32 - 1;
            edge_of.resize(id as usize, u32::MAX);
            edge_of.push(edge as u32);
            if k == 0 {
                firsts.push(id);
            }
            starts.push((id, wa.lerp(we, k as f64 / n as f64)));
        }
    }
    Ok((
        b,
        Steps {
            starts,
            firsts,
            edge_of,
        },
    ))
}

/// Each node's heading in whole turns of δ from the first node's.
fn headings(tree: &Tree) -> Vec<i64> {
    let mut k = vec![0i64; tree.nodes.len()];
    for (i, nd) in tree.nodes.iter().enumerate() {
        k[i] = match nd.parent {
            super::turtle::ROOT => i64::from(nd.turn),
            p => k[p as usize] + i64::from(nd.turn),
        };
    }
    k
}

/// δ and the first heading (radians from +x) by least squares over the
/// segments' directions, each weighted by its length squared (a long
/// segment's direction is known better); δ exactly 360/m when that is
/// within four standard errors. Also δ's standard error, degrees.
fn refine(
    coarse: &Angles,
    segments: &[(DVec2, DVec2)],
    firsts: &[u32],
    k: &[i64],
) -> (Angles, f64, f64) {
    let d0 = coarse.delta.to_radians();
    let dir = |s: &(DVec2, DVec2)| (s.1 - s.0).y.atan2((s.1 - s.0).x);
    let reference = dir(&segments[0]);
    let (mut sw, mut sk, mut skk, mut sr, mut skr) = (0.0, 0.0, 0.0, 0.0, 0.0);
    let mut rows = Vec::with_capacity(segments.len());
    for (s, &f) in segments.iter().zip(firsts) {
        let w = (s.1 - s.0).length_squared();
        let kk = k[f as usize] as f64;
        let r = wrap(dir(s) - reference - kk * d0);
        rows.push((w, kk, r));
        sw += w;
        sk += w * kk;
        skk += w * kk * kk;
        sr += w * r;
        skr += w * kk * r;
    }
    let det = sw * skk - sk * sk;
    let (a, b, err) = if det > 1e-12 * sw * sw.max(1.0) && rows.len() > 2 {
        let b = (sw * skr - sk * sr) / det;
        let a = (sr - b * sk) / sw;
        let ss: f64 = rows
            .iter()
            .map(|&(w, kk, r)| w * (r - a - b * kk).powi(2))
            .sum();
        let s2 = ss / (rows.len() - 2) as f64;
        (a, b, (s2 * sw / det).sqrt().to_degrees())
    } else {
        (sr / sw.max(1e-300), 0.0, coarse.tolerance / 3.0)
    };
    let _ = a;
    let delta = (d0 + b).to_degrees();
    // The first heading for a δ (the weighted mean offset), and how far the
    // segments are from it (weighted mean square).
    let fit = |delta: f64| {
        let d = delta.to_radians();
        let offset =
            |s: &(DVec2, DVec2), f: u32| wrap(dir(s) - reference - k[f as usize] as f64 * d);
        let (mut sx, mut sy, mut sw) = (0.0, 0.0, 0.0);
        for (s, &f) in segments.iter().zip(firsts) {
            let w = (s.1 - s.0).length_squared();
            let o = offset(s, f);
            sx += w * o.cos();
            sy += w * o.sin();
            sw += w;
        }
        let mean = sy.atan2(sx);
        let ss: f64 = segments
            .iter()
            .zip(firsts)
            .map(|(s, &f)| (s.1 - s.0).length_squared() * wrap(offset(s, f) - mean).powi(2))
            .sum();
        (reference + mean, ss / sw.max(1e-300))
    };
    // δ as a person would have written it: 360/m or the shortest decimal
    // within three standard errors, whichever is shorter when both fit the
    // segments as well (25.7 rather than 360/14 = 25.714286; 60 rather than
    // a 60.01 that rounding in the drawing suggests; 22.5 = 360/16).
    let written = crate::infer::program::nice(delta, (3.0 * err).max(1e-6));
    let m = (360.0 / delta).round();
    let exact = 360.0 / m;
    let decimals = |v: f64| crate::number::decimals(crate::infer::program::nice(v, 1e-9));
    let periodic = if m >= 2.0 && (exact - delta).abs() <= 0.02 * exact {
        let (_, rw) = fit(written);
        let (_, re) = fit(exact);
        let close = |a: f64, b: f64| a <= 1.1 * b + 1e-18;
        if (written - exact).abs() <= 1e-9 * exact {
            true
        } else if decimals(exact) <= decimals(written) {
            close(re, rw)
        } else {
            !close(rw, re)
        }
    } else {
        false
    };
    let angles = if periodic {
        Angles::new(exact, Some(m as i32), coarse.tolerance)
    } else {
        Angles::new(written, None, coarse.tolerance)
    };
    let (theta, _) = fit(angles.delta);
    (angles, theta, err)
}

/// The start point of the turtle's steps, with the heading's and the
/// start's standard errors (degrees, user units).
#[allow(clippy::too_many_arguments)]
fn fit_start(
    tree: &Tree,
    k: &[i64],
    theta: f64,
    angles: &Angles,
    step: f64,
    starts: &[(u32, DVec2)],
    segments: &[(DVec2, DVec2)],
    firsts: &[u32],
) -> (DVec2, f64, f64) {
    let n = tree.nodes.len();
    let delta = angles.delta.to_radians();
    let mut ends = vec![DVec2::ZERO; n];
    let mut from = vec![DVec2::ZERO; n];
    for (i, nd) in tree.nodes.iter().enumerate() {
        let s = match nd.parent {
            super::turtle::ROOT => DVec2::ZERO,
            p => ends[p as usize],
        };
        let a = theta + k[i] as f64 * delta;
        let u = DVec2::new(a.cos(), a.sin());
        from[i] = s;
        ends[i] = match tree.jumps.get(&(i as u32)) {
            Some(j) => s + u * j.x + u.perp() * j.y,
            None => s + u,
        };
    }
    // The first step's own start: the mean offset would be pulled off by
    // the slightest error of the step or of δ, over a large drawing.
    let count = starts.len().max(1) as f64;
    let t = starts.first().map_or(DVec2::ZERO, |&(_, w)| w);
    let scatter = (starts
        .iter()
        .map(|&(i, w)| (w - from[i as usize] * step - t).length_squared())
        .sum::<f64>()
        / count)
        .sqrt()
        / count.sqrt();
    // The heading's error: the spread of the segments' directions about
    // the model's, weighted by length.
    let (mut sw, mut ss) = (0.0, 0.0);
    for (s, &f) in segments.iter().zip(firsts) {
        let v = s.1 - s.0;
        let w = v.length_squared();
        let model = theta + k[f as usize] as f64 * delta;
        ss += w * wrap(v.y.atan2(v.x) - model).powi(2);
        sw += w;
    }
    let heading_error = if sw > 0.0 {
        (ss / sw / segments.len() as f64).sqrt().to_degrees()
    } else {
        0.0
    };
    (t, heading_error, scatter)
}

/// An angle in radians wrapped to (−π, π].
fn wrap(a: f64) -> f64 {
    super::turtle::wrap_degrees(a.to_degrees()).to_radians()
}

/// Each node's heading in whole turns of δ, read against its parent's
/// fitted heading (the first heading `theta` plus its turns), and the tree
/// of those turns.
fn requantize(b: &Builder, theta: f64, angles: &Angles) -> Result<(Vec<i64>, Tree), Unfit> {
    let d = angles.delta.to_radians();
    let tol = 0.35 * d;
    let mut k = vec![0i64; b.raw.len()];
    let mut nodes = Vec::with_capacity(b.raw.len());
    for (i, r) in b.raw.iter().enumerate() {
        let from = if r.parent == super::turtle::ROOT {
            0
        } else {
            k[r.parent as usize]
        };
        let t = wrap(r.angle - theta - from as f64 * d);
        let q = (t / d).round();
        if (t - q * d).abs() > tol {
            return Err(Unfit::Turn);
        }
        k[i] = from + q as i64;
        let turn = if i == 0 {
            0
        } else if r.parent == super::turtle::ROOT {
            k[i] - k[0]
        } else {
            q as i64
        };
        nodes.push(super::turtle::Node {
            parent: r.parent,
            turn: turn.clamp(-1_000_000, 1_000_000) as i32,
            kind: r.kind,
        });
    }
    // Jumps in their parents' fitted frames: a step's own direction, read
    // from its two ends, is off by more than a long jump can bear.
    let jumps = b
        .jumps
        .keys()
        .filter_map(|&i| {
            let p = b.raw[i as usize].parent as usize;
            Some((i, b.landing(i, theta + k[p] as f64 * d)?))
        })
        .collect();
    Ok((k, Tree { nodes, jumps }))
}

/// δ roughly: the turns between steps of different segments (in one
/// segment they are 0 by construction) fall into clusters (near 0, near δ,
/// near 2δ, …, each as wide as the drawing's noise), the peaks of their
/// histogram; δ is the smallest peak away from 0, or a part of it when the
/// other peaks are not its multiples.
fn find_delta(b: &Builder, edge_of: &[u32]) -> Result<Angles, NotLines> {
    use super::turtle::ROOT;
    // A step turns from the drawn step before it, across any gap: a gap's
    // own direction is where the next stroke happens to start (a long gap
    // in several directions may come near a whole number of steps, at any
    // angle). Gaps' directions count only when drawn steps never turn.
    let drawn_before = |i: usize| {
        let mut p = b.raw[i].parent;
        while p != ROOT && b.raw[p as usize].kind != Kind::Draw {
            p = b.raw[p as usize].parent;
        }
        p
    };
    let mut drawn = Vec::new();
    let mut all = Vec::new();
    for i in 1..b.raw.len() {
        let p = b.raw[i].parent;
        if p != ROOT && edge_of.get(i) == edge_of.get(p as usize) && edge_of[i] != u32::MAX {
            continue;
        }
        all.push(b.turn_radians(i).to_degrees().abs());
        if b.raw[i].kind == Kind::Draw {
            let from = match drawn_before(i) {
                ROOT => b.raw[0].angle,
                a => b.raw[a as usize].angle,
            };
            drawn.push(super::turtle::wrap_degrees((b.raw[i].angle - from).to_degrees()).abs());
        }
    }
    if drawn.iter().any(|t| *t >= 1.25) {
        delta_from_turns(&drawn)
    } else {
        delta_from_turns(&all)
    }
}

/// δ roughly from turns (degrees, any sign): see `find_delta`.
pub(super) fn delta_from_turns(turns: &[f64]) -> Result<Angles, NotLines> {
    let turns: Vec<f64> = turns.iter().map(|t| t.abs()).collect();
    // A histogram of quarter degrees, smoothed over a degree each way; its
    // lumps (runs of bins that are not empty) are the clusters, as wide as
    // the drawing's noise. The lump from 0 is the straight turns; lumps of
    // a stray turn or two do not count.
    const BINS: usize = 4 * 181;
    let mut hist = vec![0.0f64; BINS];
    for &t in &turns {
        let b = ((t * 4.0).round() as usize).min(BINS - 1);
        hist[b] += 1.0;
    }
    let smooth: Vec<f64> = (0..BINS)
        .map(|i| {
            (i.saturating_sub(4)..(i + 5).min(BINS))
                .map(|j| hist[j])
                .sum()
        })
        .collect();
    // Counted among the turns that turn: a spiral of ten corners and two
    // thousand straight steps has no stray turn.
    let turning = turns.iter().filter(|t| **t >= 1.25).count();
    let enough = if turning < 20 {
        1.0
    } else {
        (turning as f64 / 200.0).max(2.0)
    };
    let mut significant: Vec<f64> = Vec::new();
    let mut stray: Vec<f64> = Vec::new();
    let mut i = 0;
    while i < BINS {
        if smooth[i] == 0.0 {
            i += 1;
            continue;
        }
        let start = i;
        while i < BINS && smooth[i] > 0.0 {
            i += 1;
        }
        let (lo, hi) = (start as f64 / 4.0 - 1.25, i as f64 / 4.0);
        let lump: Vec<f64> = turns
            .iter()
            .copied()
            .filter(|t| *t >= lo && *t < hi)
            .collect();
        if start == 0 || lump.is_empty() {
            continue;
        }
        let mean = lump.iter().sum::<f64>() / lump.len() as f64;
        if (lump.len() as f64) < enough {
            stray.extend(lump);
            continue;
        }
        significant.push(mean);
    }
    let Some(&smallest) = significant.first() else {
        // Straight lines only: any angle will do.
        return Ok(Angles::new(90.0, Some(4), 1.0));
    };
    let tol_of = |d: f64| (0.15 * d).clamp(0.75, 4.0);
    let mut found = None;
    for q in 1..=6 {
        let d = smallest / f64::from(q);
        if d < MIN_DELTA {
            break;
        }
        let tol = (0.2 * d).max(0.75);
        if significant
            .iter()
            .all(|t| (t - (t / d).round() * d).abs() <= tol)
        {
            found = Some(d);
            break;
        }
    }
    let Some(d0) = found else {
        return Err(NotLines::Steps(
            "its turns are not multiples of one angle".into(),
        ));
    };
    let d0 = finer_for_strays(&turns, d0, &stray);
    Ok(Angles::new(d0, None, tol_of(d0)))
}

/// δ or a half, third or quarter of it, when the turns too few to count
/// as a cluster are all multiples of that within the drawing's own noise
/// (a square's corners at 90° among 900 turns of ±60°: δ is 30°); δ when
/// they fit it or nothing finer, or the drawing is too noisy to tell
/// (stray turns of a noisy drawing).
fn finer_for_strays(turns: &[f64], d0: f64, stray: &[f64]) -> f64 {
    // How far the turns that turn lie from multiples of δ (those near one).
    let noise = turns
        .iter()
        .filter(|t| **t >= 0.5 * d0)
        .map(|t| (t - (t / d0).round() * d0).abs())
        .filter(|e| *e <= 0.2 * d0)
        .fold(0.0f64, f64::max);
    let off = |d: f64| {
        stray
            .iter()
            .map(|t| (t - (t / d).round() * d).abs())
            .fold(0.0f64, f64::max)
    };
    let tight = (3.0 * noise).max(1e-3);
    if stray.is_empty() || off(d0) <= tight {
        return d0;
    }
    (2..=4)
        .map(|q| d0 / f64::from(q))
        .take_while(|&d| d >= MIN_DELTA)
        // Where a stray turn would fit by chance once in 18 or more (a noisy
        // drawing), they say nothing.
        .find(|&d| tight <= d / 36.0 && off(d) <= tight)
        .unwrap_or(d0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lines(svg: &str) -> Result<Vec<Vec<DVec2>>, NotLines> {
        polylines(svg.as_bytes())
    }

    #[test]
    fn what_a_line_drawing_is() {
        let head = r#"<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 10 10">"#;
        let ok = format!(
            r#"{head}<path d="M0 0 L0 2 L1 2" stroke="black" fill="none"/><polyline points="0,0 3,0" stroke="red" fill="none"/></svg>"#
        );
        let l = lines(&ok).expect("lines");
        assert_eq!(l.len(), 2);
        assert_eq!(
            l[0],
            vec![DVec2::ZERO, DVec2::new(0.0, -2.0), DVec2::new(1.0, -2.0)]
        );
        let filled = format!(r#"{head}<rect width="2" height="2"/></svg>"#);
        assert_eq!(lines(&filled), Err(NotLines::Shapes("a filled shape")));
        let curve = format!(r#"{head}<path d="M0 0 Q1 1 2 0" stroke="black" fill="none"/></svg>"#);
        assert_eq!(lines(&curve), Err(NotLines::Shapes("a curve")));
    }

    #[test]
    fn steps_and_delta() {
        // F-F-F-F with two steps per side, scaled by 3 and turned by 30°.
        let r = 30f64.to_radians();
        let rot = |p: DVec2| {
            3.0 * DVec2::new(p.x * r.cos() - p.y * r.sin(), p.x * r.sin() + p.y * r.cos())
        };
        let square = [(0.0, 0.0), (0.0, 2.0), (2.0, 2.0), (2.0, 0.0), (0.0, 0.0)];
        let line: Vec<DVec2> = square.iter().map(|&(x, y)| rot(DVec2::new(x, y))).collect();
        let rd = reading(&[line], 1).expect("reads");
        assert!((rd.step - 6.0).abs() < 1e-9);
        assert_eq!(rd.tree.nodes.len(), 4);
        assert_eq!(rd.angles.period, Some(4));
        let turns: Vec<i32> = rd.tree.nodes.iter().map(|n| n.turn).collect();
        assert_eq!(turns, [0, -1, -1, -1]);
        assert!((rd.heading - 30.0).abs() < 1e-9);
        let rd2 = reading(&[rd.segments.iter().flat_map(|s| [s.0]).collect()], 2).expect("reads");
        assert_eq!(rd2.tree.nodes.len(), 6);
    }

    /// A spiral of few corners and many straight steps, one path a step
    /// (`X -> X-FF`, `F -> FF`): its corners are not stray turns.
    #[test]
    fn few_corners_among_many_steps() {
        let (mut p, mut heading) = (DVec2::ZERO, 90f64);
        let mut paths = Vec::new();
        for side in 0..10 {
            for _ in 0..(2usize << side) {
                let q = p + DVec2::from_angle(heading.to_radians());
                paths.push(vec![p, q]);
                p = q;
            }
            heading -= 60.0;
        }
        let rd = reading(&paths, 1).expect("reads");
        assert_eq!(rd.steps, 2046);
        assert!((rd.angles.delta - 60.0).abs() < 1e-6, "{}", rd.angles.delta);
    }

    /// A curve that winds round and round (turns of 2, 4, 2 and 5 times
    /// 22.5°, 64 steps: some 200 δ in all), every vertex a hundredth of a
    /// step off: the rough δ's error, times 200, would be a turn.
    #[test]
    fn a_winding_curve_is_read_with_its_fitted_delta() {
        let (mut p, mut heading) = (DVec2::ZERO, 90f64);
        let mut line = vec![p];
        let mut rng = crate::geometry::index::Lcg(3);
        let mut unit = || rng.next();
        for i in 0..64 {
            p += DVec2::from_angle(heading.to_radians());
            heading += 22.5 * [2.0, 4.0, 2.0, 5.0][i % 4];
            let (r, a) = (0.01 * unit().sqrt(), unit() * std::f64::consts::TAU);
            line.push((p + DVec2::from_angle(a) * r) * 5.4);
        }
        let rd = reading(&[line], 1).expect("reads");
        assert_eq!(rd.steps, 64);
        assert!((rd.angles.delta - 22.5).abs() < 1e-6, "{}", rd.angles.delta);
    }
}
