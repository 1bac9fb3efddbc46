//! Reading a line drawing as turtle moves.
//!
//! Owns: what a line drawing is (every visible shape stroked, unfilled and
//! made of straight segments; see `docs/language.md`), its polylines in
//! document order in world coordinates (y up), and their reading as turtle
//! steps: the step length (every segment a whole number of steps), the angle
//! δ (every turn a whole number of δ), the start frame, and the tree of
//! steps (`turtle::Builder`). Must not search grammars.

use super::turtle::{Angles, Builder, Kind, Tree, Unfit};
use crate::infer::strokes::{self, Seg};
use crate::infer::svg;
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
    let user = strokes::user_space(data, &tree);
    let mut out: Vec<Vec<DVec2>> = Vec::new();
    let mut points = 0usize;
    for (path, t) in svg::paths(&tree) {
        if !path.is_visible() {
            continue;
        }
        if path.fill().is_some() {
            return Err(NotLines::Shapes("a filled shape"));
        }
        if path.stroke().is_none() {
            continue;
        }
        points = points.saturating_add(path.data().points().len());
        if points > MAX_POINTS {
            return Err(NotLines::Shapes("too many points"));
        }
        for sub in strokes::subpaths(path, user.pre_concat(t)) {
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
    // Every segment a whole number of steps, within a tenth of a step.
    let mut step = shortest / f64::from(split.max(1));
    let mut step_error = 0.0;
    for _ in 0..2 {
        let mut total = 0usize;
        let mut sum = 0.0;
        let (mut rr, mut res) = (0.0, 0.0);
        for &len in &lengths {
            let u = len / step;
            let r = u.round();
            if r < 1.0 || (u - r).abs() > 0.1 {
                return Err(NotLines::Steps(format!(
                    "a segment of length {} is not a whole number of steps of {}",
                    crate::number::source(crate::infer::art::emit::nice(len, len * 1e-4)),
                    crate::number::source(crate::infer::art::emit::nice(step, step * 1e-4))
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
            sum += len;
        }
        step = sum / total as f64;
        step_error = (res / (lengths.len().max(2) - 1) as f64).sqrt() / rr.sqrt();
    }
    let origin = segments[0].0;
    let mut b = Builder::new();
    // Where each drawn step starts (world coordinates), by node.
    let mut starts: Vec<(u32, DVec2)> = Vec::new();
    for (&(a, e), &len) in segments.iter().zip(&lengths) {
        let n = (len / step).round().max(1.0) as usize;
        let (wa, we) = (a, e);
        let (a, e) = ((a - origin) / step, (e - origin) / step);
        for k in 0..n {
            let p = a.lerp(e, k as f64 / n as f64);
            let q = a.lerp(e, (k + 1) as f64 / n as f64);
            b.push(p, q).map_err(|_| {
                NotLines::Steps("a segment starts away from the drawing by a gap that is not a whole number of steps".into())
            })?;
            starts.push((b.raw.len() as u32 - 1, wa.lerp(we, k as f64 / n as f64)));
        }
    }
    let (angles, delta_error) = find_delta(&b)?;
    let tree = b.tree(&angles).map_err(|e| match e {
        Unfit::Turn => NotLines::Steps(format!(
            "its turns are not all multiples of one angle ({} degrees)",
            angles.delta
        )),
        Unfit::Jump => NotLines::Steps("a gap that is not a whole number of steps".into()),
    })?;
    let (start, heading, frame_error) = fit_frame(&b, &tree, &angles, step, &starts);
    Ok(Reading {
        steps: tree.draws(),
        tree,
        angles,
        step,
        step_error,
        start,
        heading,
        frame_error,
        segments,
        delta_error,
    })
}

/// The start point and heading that put the turtle's steps (of `step`,
/// turning by the tree's whole turns) best on the drawing: the heading is
/// the mean of every step's own heading less its turns, the start the mean
/// offset of every step's start. Also how uncertain they are: (degrees,
/// user units).
fn fit_frame(
    b: &Builder,
    tree: &Tree,
    angles: &Angles,
    step: f64,
    starts: &[(u32, DVec2)],
) -> (DVec2, f64, (f64, f64)) {
    let n = tree.nodes.len();
    // Each node's heading in whole turns from the first node's.
    let mut k = vec![0i64; n];
    for (i, nd) in tree.nodes.iter().enumerate() {
        k[i] = match nd.parent {
            super::turtle::ROOT => i64::from(nd.turn),
            p => k[p as usize] + i64::from(nd.turn),
        };
    }
    let base = b.raw[0].angle;
    let delta = angles.delta.to_radians();
    // Circular mean of each step's offset from the first step's heading.
    let (mut sx, mut sy) = (0.0, 0.0);
    let mut offsets = Vec::with_capacity(n);
    for (i, r) in b.raw.iter().enumerate() {
        let o = wrap(r.angle - base - k[i] as f64 * delta);
        offsets.push(o);
        sx += o.cos();
        sy += o.sin();
    }
    let mean = sy.atan2(sx);
    let spread = (offsets.iter().map(|o| wrap(o - mean).powi(2)).sum::<f64>()
        / (n.max(2) - 1) as f64)
        .sqrt()
        / (n as f64).sqrt();
    let theta = base + mean;
    // The model's points (in steps, from the start) and their offsets.
    let mut ends = vec![DVec2::ZERO; n];
    let mut from = vec![DVec2::ZERO; n];
    for (i, nd) in tree.nodes.iter().enumerate() {
        let s = match nd.parent {
            super::turtle::ROOT => DVec2::ZERO,
            p => ends[p as usize],
        };
        let a = theta + k[i] as f64 * delta;
        from[i] = s;
        ends[i] = s + DVec2::new(a.cos(), a.sin());
    }
    let mut sum = DVec2::ZERO;
    for &(i, w) in starts {
        sum += w - from[i as usize] * step;
    }
    let t = sum / starts.len().max(1) as f64;
    let scatter = (starts
        .iter()
        .map(|&(i, w)| (w - from[i as usize] * step - t).length_squared())
        .sum::<f64>()
        / starts.len().max(1) as f64)
        .sqrt()
        / (starts.len() as f64).sqrt();
    let heading = super::turtle::wrap_degrees(theta.to_degrees() - 90.0);
    (t, heading, (spread.to_degrees(), scatter))
}

/// An angle in radians wrapped to (−π, π].
fn wrap(a: f64) -> f64 {
    super::turtle::wrap_degrees(a.to_degrees()).to_radians()
}

/// δ: the largest angle of which every turn is a whole multiple, refined by
/// least squares; exactly 360/m when that fits as well.
fn find_delta(b: &Builder) -> Result<(Angles, f64), NotLines> {
    let turns: Vec<f64> = (1..b.raw.len())
        .map(|i| b.turn_radians(i).to_degrees().abs())
        .collect();
    let nonzero: Vec<f64> = turns.iter().copied().filter(|t| *t > 1.5).collect();
    let Some(smallest) = nonzero.iter().copied().reduce(f64::min) else {
        // Straight lines only: any angle will do.
        return Ok((Angles::new(90.0, Some(4), 1.0), 0.0));
    };
    let tol_of = |d: f64| (0.15 * d).clamp(0.75, 4.0);
    let mut found = None;
    for q in 1..=6 {
        let d = smallest / f64::from(q);
        if d < MIN_DELTA {
            break;
        }
        let tol = tol_of(d);
        if turns.iter().all(|t| (t - (t / d).round() * d).abs() <= tol) {
            found = Some(d);
            break;
        }
    }
    let Some(d0) = found else {
        return Err(NotLines::Steps(
            "its turns are not multiples of one angle".into(),
        ));
    };
    // Least squares over the turns that are not straight on.
    let (mut kk, mut kt, mut n) = (0.0, 0.0, 0.0);
    for &t in &nonzero {
        let k = (t / d0).round();
        kk += k * k;
        kt += k * t;
        n += 1.0;
    }
    let delta = kt / kk;
    let resid: f64 = nonzero
        .iter()
        .map(|&t| {
            let k = (t / d0).round();
            (t - k * delta).powi(2)
        })
        .sum();
    let error = if n > 1.0 {
        (resid / (n - 1.0)).sqrt() / kk.sqrt()
    } else {
        tol_of(d0) / 3.0
    };
    let m = (360.0 / delta).round();
    let exact = 360.0 / m;
    let (delta, period) = if m >= 2.0 && (exact - delta).abs() <= (4.0 * error).max(1e-6 * delta) {
        (exact, Some(m as i32))
    } else {
        (delta, None)
    };
    Ok((Angles::new(delta, period, tol_of(delta)), error))
}

/// Whether a tree draws at all.
pub fn draws(tree: &Tree) -> bool {
    tree.nodes.iter().any(|n| n.kind == Kind::Draw)
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
}
