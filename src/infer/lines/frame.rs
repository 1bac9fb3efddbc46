//! Where a grammar's drawing lies on the drawing: the similarity (start
//! point, heading, step) fitted to every drawn step at once.
//!
//! The reading knows the first step's heading from the steps' own
//! directions, each a step long: over a drawing ten thousand steps across,
//! its error of a thousandth of a degree puts the far end a fifth of a step
//! off. Once a grammar draws the drawing step for step, its steps are where
//! the drawing's are, so the least-squares similarity between the two sets
//! of points pins heading and step down by the whole drawing's length.
//!
//! Owns: that fit. Must not search or emit.

use super::grammar::{self, Grammar};
use super::read::Reading;
use super::turtle::Angles;
use glam::DVec2;
use std::ops::ControlFlow;

/// The fitted frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fit {
    /// The turtle's heading, degrees anticlockwise from +y.
    pub heading: f64,
    /// Where the turtle starts, world coordinates.
    pub start: DVec2,
    /// The step, user units.
    pub step: f64,
    /// How far across the drawing is, in steps.
    pub extent: f64,
}

/// How far (in steps, root mean square) the drawing's steps may lie from
/// the fitted ones: beyond it the steps do not pair up (a redrawing of a
/// noisy drawing read in another order) and the reading's frame stands.
const SPREAD: f64 = 0.25;

/// The similarity from `g`'s derivation (from the origin, heading +y, steps
/// of 1, turning by `delta` degrees as written) onto the drawing's steps,
/// paired in drawing order; `None` when they do not pair up or `work`
/// symbols do not derive them.
pub fn fit(g: &Grammar, delta: f64, r: &Reading, work: u64) -> Option<Fit> {
    let model = starts(g, delta, work, r.steps)?;
    let world = drawn_starts(r);
    if model.len() != world.len() || model.len() < 2 {
        return None;
    }
    let n = model.len() as f64;
    let mm = model.iter().sum::<DVec2>() / n;
    let wm = world.iter().sum::<DVec2>() / n;
    // z = Σ (w − w̄)·conj(m − m̄) / Σ |m − m̄|², complex numbers.
    let (mut num, mut den) = (DVec2::ZERO, 0.0);
    for (m, w) in model.iter().zip(&world) {
        let (m, w) = (*m - mm, *w - wm);
        num += DVec2::new(w.x * m.x + w.y * m.y, w.y * m.x - w.x * m.y);
        den += m.length_squared();
    }
    if den <= 0.0 {
        return None;
    }
    let z = num / den;
    let step = z.length();
    if !(step.is_finite() && step > 0.0) {
        return None;
    }
    let times = |m: DVec2| DVec2::new(z.x * m.x - z.y * m.y, z.x * m.y + z.y * m.x);
    let start = wm - times(mm);
    let spread = (model
        .iter()
        .zip(&world)
        .map(|(m, w)| (start + times(*m)).distance_squared(*w))
        .sum::<f64>()
        / n)
        .sqrt()
        / step;
    if spread > SPREAD {
        return None;
    }
    let (lo, hi) = world.iter().fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    Some(Fit {
        heading: z.y.atan2(z.x).to_degrees(),
        start,
        step,
        extent: ((hi - lo).length() / step).max(1.0),
    })
}

/// Where each drawn step of the reading starts (world coordinates), in
/// drawing order: each segment cut into whole steps.
fn drawn_starts(r: &Reading) -> Vec<DVec2> {
    let mut out = Vec::with_capacity(r.steps);
    for &(a, b) in &r.segments {
        let n = (a.distance(b) / r.step).round().max(1.0) as usize;
        out.extend((0..n).map(|k| a.lerp(b, k as f64 / n as f64)));
    }
    out
}

/// Where each drawn step of `g` starts, from the origin heading +y with
/// steps of 1; `None` beyond `work` symbols or `most` steps.
fn starts(g: &Grammar, delta: f64, work: u64, most: usize) -> Option<Vec<DVec2>> {
    let mut out = Vec::new();
    let mut more = false;
    let angles = Angles::new(delta, None, 0.0);
    grammar::each_step(g, &angles, work, |pos, _| {
        if out.len() >= most {
            more = true;
            return ControlFlow::Break(());
        }
        out.push(pos);
        ControlFlow::Continue(())
    })?;
    (!more).then_some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::infer::lines::grammar::{Action, Letter, Sym};

    #[test]
    fn the_frame_comes_from_every_step() {
        // The Koch curve F -> F+F--F+F at 60°, depth 4, drawn turned by
        // 10.123456° and scaled by 3.21 from (5, 7), its points rounded to
        // a thousandth as a file would hold them.
        let koch = Grammar {
            letters: vec![Letter {
                name: 'F',
                action: Action::Draw,
                rule: Some(vec![
                    Sym::Letter(0),
                    Sym::Plus,
                    Sym::Letter(0),
                    Sym::Minus,
                    Sym::Minus,
                    Sym::Letter(0),
                    Sym::Plus,
                    Sym::Letter(0),
                ]),
            }],
            axiom: vec![Sym::Letter(0)],
            depth: 4,
        };
        let model = starts(&koch, 60.0, 1 << 20, 1 << 20).expect("derives");
        let (turn, scale, at) = (10.123456f64.to_radians(), 3.21, DVec2::new(5.0, 7.0));
        let place = |m: DVec2| {
            let p = at + DVec2::from_angle(turn).rotate(m) * scale;
            (p * 1000.0).round() / 1000.0
        };
        // The curve's last step heads as its first (+y): its end closes it.
        let mut line: Vec<DVec2> = model.iter().map(|m| place(*m)).collect();
        line.push(place(model[model.len() - 1] + DVec2::Y));
        let r = crate::infer::lines::read::reading(&[line], 1).expect("reads");
        let fit = fit(&koch, 60.0, &r, 1 << 20).expect("fits");
        assert!((fit.step - scale).abs() < 1e-5, "{fit:?}");
        assert!((fit.heading - 10.123456).abs() < 1e-4, "{fit:?}");
        assert!(fit.start.distance(at) < 1e-3, "{fit:?}");
    }
}
