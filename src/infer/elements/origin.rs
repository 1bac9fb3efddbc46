//! Where an element kind's local origin belongs, when the drawing says.
//!
//! Owns: moving a kind's origin from its centroid to the point the drawing
//! turns about. When a sequence turns by a changing angle, the transforms
//! between its neighbours differ by a rotation about one fixed point of the
//! element's frame (its "base": where the generating turtle stood). Each run of
//! three neighbours i → j → l votes that point, q = (I − R(Δ))⁻¹ u for the
//! similarity T_jl ∘ T_ij⁻¹ = (R(Δ), u) (and for T_ij⁻¹ ∘ T_jl, the same for a
//! changing turn after the step); a clear majority moves the kind's origin
//! there, so the paper's linear rules (d and s constant, α and β linear in m)
//! hold in the new frames. Must not decide rules.

use super::rules::Tolerance;
use super::shape::{Frame, Instancing, rotate, wrap};
use super::space::{Point, cluster};
use crate::geometry::index::PointGrid;
use glam::DVec2;

/// A similarity x ↦ t + s·R(θ)·x.
#[derive(Clone, Copy, Debug)]
struct Sim {
    t: DVec2,
    s: f64,
    theta: f64,
}

impl Sim {
    /// Frame `b` seen from frame `a`: maps b-local points to a-local points.
    fn between(a: &Frame, b: &Frame) -> Sim {
        Sim {
            t: rotate(b.pos - a.pos, -a.rot) / a.scale,
            s: b.scale / a.scale,
            theta: wrap(b.rot - a.rot),
        }
    }

    fn inverse(&self) -> Sim {
        Sim {
            t: -rotate(self.t, -self.theta) / self.s,
            s: 1.0 / self.s,
            theta: -self.theta,
        }
    }

    /// self ∘ other.
    fn then(&self, other: &Sim) -> Sim {
        Sim {
            t: self.t + rotate(other.t, self.theta) * self.s,
            s: self.s * other.s,
            theta: wrap(self.theta + other.theta),
        }
    }

    /// The fixed point and angle of a rotation (scale 1, angle not 0).
    fn pivot(&self, tol: Tolerance) -> Option<(DVec2, f64)> {
        if (self.s - 1.0).abs() > tol.scale || self.theta.abs() < 2.0 * tol.angle {
            return None;
        }
        // q = R q + t  ⇒  (I − R) q = t.
        let (sn, cs) = self.theta.sin_cos();
        let (a, b, c, d) = (1.0 - cs, sn, -sn, 1.0 - cs);
        let det = a * d - b * c;
        if det.abs() < 1e-12 {
            return None;
        }
        let q = DVec2::new(d * self.t.x - b * self.t.y, -c * self.t.x + a * self.t.y) / det;
        q.is_finite().then_some((q, self.theta))
    }
}

/// Moves `q` so that, in frames with their origin at `q`, the steps i → j and
/// j → l of each run are as equal as they can be.
fn refine(frames: &[Frame], runs: &[[usize; 3]], mut q: DVec2, radius: f64) -> DVec2 {
    let residuals = |q: DVec2| -> Vec<f64> {
        let at = |f: &Frame| f.pos + rotate(q, f.rot) * f.scale;
        runs.iter()
            .map(|&[i, j, l]| {
                let (a, b, c) = (at(&frames[i]), at(&frames[j]), at(&frames[l]));
                a.distance(b) / frames[i].scale - b.distance(c) / frames[j].scale
            })
            .collect()
    };
    let h = radius * 1e-4;
    for _ in 0..10 {
        let r = residuals(q);
        let rx = residuals(q + DVec2::new(h, 0.0));
        let ry = residuals(q + DVec2::new(0.0, h));
        // Normal equations of the 2-parameter linear least squares.
        let (mut a, mut b, mut c, mut gx, mut gy) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for k in 0..r.len() {
            let (jx, jy) = ((rx[k] - r[k]) / h, (ry[k] - r[k]) / h);
            a += jx * jx;
            b += jx * jy;
            c += jy * jy;
            gx += jx * r[k];
            gy += jy * r[k];
        }
        let det = a * c - b * b;
        if det.abs() < 1e-18 {
            break;
        }
        let step = DVec2::new(c * gx - b * gy, -b * gx + a * gy) / det;
        if !step.is_finite() || step.length() > radius {
            break;
        }
        q -= step;
        if step.length() < radius * 1e-7 {
            break;
        }
    }
    q
}

/// Neighbours looked at per instance: the two nearest, the ones a chain
/// passes through (a ring's farther members would vote for its centre).
const NEIGHBOURS: usize = 2;

/// Moves kinds' origins where runs of neighbours turn about one point, and
/// the instances' frames with them; says which kinds it moved.
pub fn find(inst: &mut Instancing, tol: Tolerance) -> Vec<bool> {
    let mut moved = vec![false; inst.kinds.len()];
    for (k, moved) in moved.iter_mut().enumerate() {
        if inst.kinds[k].given {
            continue;
        }
        let members: Vec<usize> = (0..inst.of.len()).filter(|&i| inst.of[i].0 == k).collect();
        if members.len() < 4 {
            continue;
        }
        let radius = inst.shapes[inst.kinds[k].representative].radius;
        let frames: Vec<Frame> = members.iter().map(|&i| inst.of[i].1).collect();
        let points: Vec<DVec2> = frames.iter().map(|f| f.pos).collect();
        let grid = PointGrid::new(&points);
        let cell = 0.02 * radius;
        let mut votes: Vec<(Point, Sim, [usize; 3])> = Vec::new();
        for j in 0..frames.len() {
            let near = grid.nearest(points[j], NEIGHBOURS + 1);
            for &i in &near {
                for &l in &near {
                    if i == j || l == j || i == l {
                        continue;
                    }
                    let tij = Sim::between(&frames[i], &frames[j]);
                    let tjl = Sim::between(&frames[j], &frames[l]);
                    let inv = tij.inverse();
                    for m in [tjl.then(&inv), inv.then(&tjl)] {
                        if let Some((q, delta)) = m.pivot(tol)
                            && q.length() < 20.0 * radius
                        {
                            votes.push((
                                [q.x / cell, q.y / cell, delta / tol.angle, 0.0],
                                m,
                                [i, j, l],
                            ));
                        }
                    }
                }
            }
        }
        if votes.is_empty() {
            continue;
        }
        let pts: Vec<Point> = votes.iter().map(|v| v.0).collect();
        let (label, centres) = cluster(&pts, 0.0);
        let mut count = vec![0usize; centres.len()];
        for l in &label {
            count[*l] += 1;
        }
        let Some(top) = (0..centres.len()).max_by(|&a, &b| count[a].cmp(&count[b]).then(b.cmp(&a)))
        else {
            continue;
        };
        // A run of n turns gives n − 2 votes; most runs of a kind must agree.
        if count[top] < 3 || count[top] * 3 < members.len() {
            continue;
        }
        // Least squares over the agreeing votes: Σ AᵀA q = Σ Aᵀ t with
        // A = I − R(Δ), so that larger turns (better conditioned) weigh more.
        let (mut m, mut b) = ([0.0f64; 4], DVec2::ZERO);
        for (v, _) in votes.iter().zip(&label).filter(|(_, l)| **l == top) {
            let (sn, cs) = v.1.theta.sin_cos();
            let a = [1.0 - cs, sn, -sn, 1.0 - cs];
            // AᵀA and Aᵀt for A = [[a0, a1], [a2, a3]].
            m[0] += a[0] * a[0] + a[2] * a[2];
            m[1] += a[0] * a[1] + a[2] * a[3];
            m[2] += a[1] * a[0] + a[3] * a[2];
            m[3] += a[1] * a[1] + a[3] * a[3];
            b.x += a[0] * v.1.t.x + a[2] * v.1.t.y;
            b.y += a[1] * v.1.t.x + a[3] * v.1.t.y;
        }
        let det = m[0] * m[3] - m[1] * m[2];
        if det.abs() < 1e-18 {
            continue;
        }
        let q = DVec2::new(m[3] * b.x - m[1] * b.y, -m[2] * b.x + m[0] * b.y) / det;
        if q.length() < 0.05 * radius {
            continue;
        }
        // Refine: the step of a linear sequence is constant in the right frame,
        // so minimise the differences of consecutive steps (Gauss–Newton).
        let runs: Vec<[usize; 3]> = votes
            .iter()
            .zip(&label)
            .filter(|(_, l)| **l == top)
            .map(|(v, _)| v.2)
            .collect();
        let q = refine(&frames, &runs, q, radius);
        inst.reframe(
            k,
            &Frame {
                pos: q,
                ..Frame::IDENTITY
            },
        );
        *moved = true;
    }
    moved
}
