//! Fitting a structure to every instance it draws: the parameters of a rule's
//! transforms and the start frame of each copy, by least squares.
//!
//! Owns: the generic fit behind `--symmetrize` (the paper's Fig. 10) and the
//! t(m) = t0 + tΔ·m of linear sequences. A *model* gives, for parameters p,
//! the frame of every member relative to its copy's start; each copy's start
//! is then found in closed form (a Procrustes fit of the members' positions,
//! blended with their rotations, scale from their scales), and p by damped
//! Gauss–Newton on what is left (variable projection), with one robust
//! reweighting so that a stray member pulls less. The standard errors of p
//! say which round values the members support; `nice_angle` and `nice`
//! snap to them. Must not choose rules or know turtle commands.

use crate::infer::elements::shape::{Frame, rotate, wrap};
use glam::DVec2;

/// A placed instance a structure draws: which copy (group) it belongs to,
/// where it is, its radius (which turns its rotation and scale errors into
/// lengths until the fit knows better), the standard error of its rotation
/// when a fit placed it (else 0), and whether its rotation is relative to a
/// representative that may itself be turned (`tilted`: the fit's tilt
/// parameter is added to its rotation).
#[derive(Clone, Copy, Debug)]
pub(super) struct Member {
    pub group: usize,
    pub frame: Frame,
    pub lever: f64,
    pub rot_se: f64,
    pub pos_se: f64,
    pub tilted: bool,
}

/// The frames of all members (in order) relative to their group's start,
/// for parameters `p`.
pub(super) type Model<'a> = dyn Fn(&[f64], &mut Vec<Frame>) + 'a;

/// A fit of a model to members.
pub(super) struct Fit<'a> {
    members: &'a [Member],
    groups: usize,
    model: &'a Model<'a>,
    /// Robust weight of each member's residuals.
    weight: Vec<f64>,
    /// The weights of a rotation and of a log scale residual, as lengths:
    /// each member's radius at first, then the ratio of the noise in
    /// positions to the noise in rotations (scales) the fit finds.
    rot_unit: Option<f64>,
    scale_unit: Option<f64>,
    /// The index in p of the tilt of `tilted` members' rotations.
    tilt: Option<usize>,
    /// The noise of a coordinate of a position, once estimated.
    noise: Option<f64>,
}

/// What a fit found for parameters p.
pub(super) struct Solution {
    /// Each group's start frame.
    pub starts: Vec<Frame>,
    /// Standard error of each start's rotation, radians.
    pub rot_se: Vec<f64>,
    /// Standard error of a coordinate of each start's position.
    pub pos_se: Vec<f64>,
    /// Where each member is drawn (without the tilt).
    pub drawn: Vec<Frame>,
    /// The variance of a coordinate of a member's position about the fit,
    /// or infinite when the members leave no degrees of freedom.
    pub sigma2: f64,
    /// The root mean square of the members' rotations about the fit, radians.
    pub rot_rms: f64,
}

/// Gauss–Newton iterations at most.
const ITERATIONS: usize = 30;

fn identity() -> Frame {
    Frame {
        pos: DVec2::ZERO,
        rot: 0.0,
        scale: 1.0,
    }
}

fn cross(a: DVec2, b: DVec2) -> f64 {
    a.x * b.y - a.y * b.x
}

impl<'a> Fit<'a> {
    pub(super) fn new(
        members: &'a [Member],
        groups: usize,
        model: &'a Model<'a>,
        tilt: Option<usize>,
    ) -> Fit<'a> {
        Fit {
            members,
            groups,
            model,
            weight: vec![1.0; members.len()],
            rot_unit: None,
            scale_unit: None,
            tilt,
            noise: None,
        }
    }

    fn templates(&self, p: &[f64]) -> Vec<Frame> {
        let mut out = Vec::with_capacity(self.members.len());
        (self.model)(p, &mut out);
        out.resize(self.members.len(), identity());
        out
    }

    /// The weights (as lengths) of member `i`'s rotation and log scale.
    fn units(&self, i: usize) -> (f64, f64) {
        let m = &self.members[i];
        (
            self.rot_unit.unwrap_or(m.lever),
            self.scale_unit.unwrap_or(m.lever),
        )
    }

    /// The rotation member `i` has relative to its template, tilt removed.
    fn tilt_of(&self, i: usize, p: &[f64]) -> f64 {
        match self.tilt {
            Some(k) if self.members[i].tilted => p.get(k).copied().unwrap_or(0.0),
            _ => 0.0,
        }
    }

    /// The start frame of each group that fits its members best for
    /// templates `tm`, and the curvature of the fit in the start's rotation.
    fn starts(&self, tm: &[Frame], p: &[f64]) -> (Vec<Frame>, Vec<f64>) {
        let g = self.groups;
        // Scale: the weighted mean log ratio.
        let mut ls = vec![(0.0, 0.0, 0.0, 0usize); g];
        for (i, m) in self.members.iter().enumerate() {
            let r = (m.frame.scale / tm[i].scale).ln();
            let w = (self.units(i).1 * self.weight[i]).powi(2);
            let s = &mut ls[m.group];
            s.0 += w * r;
            s.1 += w;
            s.2 += r;
            s.3 += 1;
        }
        let scale: Vec<f64> = ls
            .iter()
            .map(|&(wr, w, r, n)| {
                let v = if w > 1e-300 {
                    wr / w
                } else {
                    r / n.max(1) as f64
                };
                if v.is_finite() { v.exp() } else { 1.0 }
            })
            .collect();
        // Centroids of the observed and template positions.
        let mut cen = vec![(DVec2::ZERO, DVec2::ZERO, 0.0); g];
        for (i, m) in self.members.iter().enumerate() {
            let w = self.weight[i].powi(2);
            let c = &mut cen[m.group];
            c.0 += m.frame.pos * w;
            c.1 += tm[i].pos * scale[m.group] * w;
            c.2 += w;
        }
        for c in &mut cen {
            let w = c.2.max(1e-300);
            c.0 /= w;
            c.1 /= w;
        }
        // Rotation from positions (Procrustes) ...
        let mut cd = vec![(0.0, 0.0); g];
        for (i, m) in self.members.iter().enumerate() {
            let c = &cen[m.group];
            let w = self.weight[i].powi(2);
            let q = tm[i].pos * scale[m.group] - c.1;
            let p = m.frame.pos - c.0;
            cd[m.group].0 += w * cross(q, p);
            cd[m.group].1 += w * q.dot(p);
        }
        // ... blended with the members' rotations, around a reference angle.
        let reference: Vec<f64> = (0..g)
            .map(|k| {
                let (c, d) = cd[k];
                if c.hypot(d) > 1e-12 {
                    c.atan2(d)
                } else {
                    f64::NAN
                }
            })
            .collect();
        let mut first: Vec<Option<f64>> = vec![None; g];
        let mut rs = vec![(0.0, 0.0); g];
        for (i, m) in self.members.iter().enumerate() {
            let r = wrap(m.frame.rot - tm[i].rot - self.tilt_of(i, p));
            let k = m.group;
            let base = if reference[k].is_nan() {
                *first[k].get_or_insert(r)
            } else {
                reference[k]
            };
            let w = (self.units(i).0 * self.weight[i]).powi(2);
            rs[k].0 += w * wrap(r - base);
            rs[k].1 += w;
        }
        let mut starts = Vec::with_capacity(g);
        let mut stiff = Vec::with_capacity(g);
        for k in 0..g {
            let stiffness = cd[k].0.hypot(cd[k].1);
            let (base, pos_part) = if reference[k].is_nan() {
                (first[k].unwrap_or(0.0), 0.0)
            } else {
                (reference[k], stiffness)
            };
            let total = pos_part + rs[k].1;
            let rot = if total > 1e-300 {
                wrap(base + rs[k].0 / total)
            } else {
                wrap(base)
            };
            let pos = cen[k].0 - rotate(cen[k].1, rot);
            starts.push(Frame {
                pos,
                rot,
                scale: scale[k],
            });
            stiff.push(total);
        }
        (starts, stiff)
    }

    /// The residuals for parameters `p` (four per member), with the starts.
    fn residuals(&self, p: &[f64], out: &mut Vec<f64>) -> (Vec<Frame>, Vec<f64>) {
        let tm = self.templates(p);
        let (starts, stiff) = self.starts(&tm, p);
        out.clear();
        for (i, m) in self.members.iter().enumerate() {
            let want = starts[m.group].then(&tm[i]);
            let w = self.weight[i];
            let (ru, su) = self.units(i);
            let d = m.frame.pos - want.pos;
            out.push(d.x * w);
            out.push(d.y * w);
            out.push(wrap(m.frame.rot - want.rot - self.tilt_of(i, p)) * ru * w);
            out.push((m.frame.scale / want.scale).ln() * su * w);
        }
        for r in out.iter_mut() {
            if !r.is_finite() {
                *r = 1e150;
            }
        }
        (starts, stiff)
    }
    fn energy(&self, p: &[f64]) -> f64 {
        let mut r = Vec::new();
        self.residuals(p, &mut r);
        r.iter().map(|v| v * v).sum()
    }

    /// The residuals' Jacobian in the free parameters (column-major).
    fn jacobian(&self, p: &[f64], free: &[usize], r0: &[f64]) -> Vec<Vec<f64>> {
        let mut r = Vec::new();
        free.iter()
            .map(|&j| {
                let h = 1e-7 * (1.0 + p[j].abs());
                let mut q = p.to_vec();
                q[j] += h;
                self.residuals(&q, &mut r);
                r.iter().zip(r0).map(|(a, b)| (a - b) / h).collect()
            })
            .collect()
    }

    /// Improves the free parameters `free` of `p` (damped Gauss–Newton).
    pub(super) fn solve(&self, p: &mut [f64], free: &[usize]) {
        if free.is_empty() {
            return;
        }
        let mut r0 = Vec::new();
        self.residuals(p, &mut r0);
        let mut e0: f64 = r0.iter().map(|v| v * v).sum();
        let mut lambda = 1e-3;
        for _ in 0..ITERATIONS {
            let jac = self.jacobian(p, free, &r0);
            let n = free.len();
            let mut a = vec![vec![0.0; n]; n];
            let mut g = vec![0.0; n];
            for x in 0..n {
                for y in x..n {
                    let v: f64 = jac[x].iter().zip(&jac[y]).map(|(a, b)| a * b).sum();
                    a[x][y] = v;
                    a[y][x] = v;
                }
                g[x] = -jac[x].iter().zip(&r0).map(|(a, b)| a * b).sum::<f64>();
            }
            let mut better = false;
            for _ in 0..10 {
                let mut m = a.clone();
                for (k, row) in m.iter_mut().enumerate() {
                    row[k] += lambda * row[k] + 1e-12;
                }
                let Some(step) = solve_linear(m, g.clone()) else {
                    lambda *= 10.0;
                    continue;
                };
                let mut q = p.to_vec();
                for (k, &j) in free.iter().enumerate() {
                    q[j] += step[k];
                }
                let e = self.energy(&q);
                if e.is_finite() && e < e0 {
                    let gain = e0 - e;
                    p.copy_from_slice(&q);
                    self.residuals(p, &mut r0);
                    e0 = e;
                    lambda = (lambda / 3.0).max(1e-9);
                    better = gain > 1e-14 * (1.0 + e0);
                    break;
                }
                lambda *= 4.0;
            }
            if !better {
                break;
            }
        }
    }

    /// Fits the free parameters; then weighs rotations and scales by how
    /// noisy they are next to positions and fits again; then fits once more
    /// with members far off down-weighted (Huber weights at 2.5 robust
    /// deviations).
    pub(super) fn solve_robust(&mut self, p: &mut [f64], free: &[usize]) {
        self.solve(p, free);
        let tm = self.templates(p);
        let (starts, _) = self.starts(&tm, p);
        let n = self.members.len() as f64;
        let (mut pos2, mut rot2, mut scale2, mut size) = (0.0, 0.0, 0.0, 0.0);
        let (mut prior_rot, mut prior_pos) = (0.0, 0.0);
        for (i, m) in self.members.iter().enumerate() {
            let want = starts[m.group].then(&tm[i]);
            pos2 += m.frame.pos.distance_squared(want.pos);
            rot2 += wrap(m.frame.rot - want.rot - self.tilt_of(i, p)).powi(2);
            scale2 += (m.frame.scale / want.scale).ln().powi(2);
            size += m.lever;
            prior_rot += m.rot_se.powi(2);
            prior_pos += m.pos_se.powi(2);
        }
        let size = (size / n.max(1.0)).max(1e-12);
        // Variances with the numbers each kind of residual leaves free:
        // positions two per member less three per start and the
        // parameters; rotations and scales one per member less one per
        // start and one more. Members placed by fits are at least as
        // uncertain as those fits say.
        let g = self.groups as f64;
        let pos = (pos2 / (2.0 * n - 3.0 * g - free.len() as f64).max(1.0))
            .max(prior_pos / n.max(1.0))
            .sqrt()
            .max(size * 1e-9);
        self.noise = Some(pos);
        let rot = (rot2 / (n - g - 1.0).max(1.0))
            .max(prior_rot / n.max(1.0))
            .sqrt();
        let scale = (scale2 / (n - g - 1.0).max(1.0)).sqrt();
        // Noise ratios within a millionfold of the members' size.
        let unit = |sd: f64| (pos / sd.max(1e-12)).clamp(size * 1e-3, size * 1e3);
        self.rot_unit = Some(unit(rot));
        self.scale_unit = Some(unit(scale));
        self.solve(p, free);
        let mut r = Vec::new();
        self.residuals(p, &mut r);
        let norms: Vec<f64> = r
            .chunks(4)
            .map(|c| c.iter().map(|v| v * v).sum::<f64>().sqrt())
            .collect();
        let mut sorted = norms.clone();
        sorted.sort_by(f64::total_cmp);
        let median = sorted.get(sorted.len() / 2).copied().unwrap_or(0.0);
        let cut = 2.5 * 1.4826 * median;
        if cut.is_nan() || cut <= 1e-12 {
            return;
        }
        let mut changed = false;
        for (w, n) in self.weight.iter_mut().zip(&norms) {
            if *n > cut {
                *w = cut / n;
                changed = true;
            }
        }
        if changed {
            self.solve(p, free);
        }
    }

    /// The starts for `p`, and the standard errors of the free parameters
    /// (infinite where the members do not determine one).
    pub(super) fn result(&self, p: &[f64], free: &[usize]) -> (Solution, Vec<f64>) {
        let mut r = Vec::new();
        let (starts, stiff) = self.residuals(p, &mut r);
        let tm = self.templates(p);
        let drawn: Vec<Frame> = self
            .members
            .iter()
            .zip(&tm)
            .map(|(m, t)| starts[m.group].then(t))
            .collect();
        let n = self.members.len().max(1) as f64;
        let (mut pos2, mut rot2) = (0.0, 0.0);
        for (i, (m, d)) in self.members.iter().zip(&drawn).enumerate() {
            pos2 += m.frame.pos.distance_squared(d.pos);
            rot2 += wrap(m.frame.rot - d.rot - self.tilt_of(i, p)).powi(2);
        }
        let rot_rms = (rot2 / n).sqrt();
        // Two coordinates per member; each start takes two, and its rotation one.
        let pos_dof = 2 * self.members.len() as i64 - 3 * self.groups as i64;
        let pos_sigma2 = if pos_dof > 0 {
            pos2 / pos_dof as f64
        } else {
            f64::INFINITY
        };
        let energy: f64 = r.iter().map(|v| v * v).sum();
        // Each member gives four numbers; each start takes four, each free parameter one.
        let dof = 4 * self.members.len() as i64 - 4 * self.groups as i64 - free.len() as i64;
        let prior = self.noise.map_or(0.0, |n| n * n);
        let sigma2 = if dof > 0 {
            (energy / dof as f64).max(prior)
        } else if prior > 0.0 {
            prior
        } else {
            f64::INFINITY
        };
        let rot_se: Vec<f64> = stiff
            .iter()
            .map(|&k| {
                if k > 1e-300 {
                    (sigma2 / k).sqrt()
                } else {
                    f64::INFINITY
                }
            })
            .collect();
        // A start's position: the members' mean, less their mean template
        // offset turned by the start's rotation.
        let mut mean = vec![(DVec2::ZERO, 0.0f64); self.groups];
        for (m, t) in self.members.iter().zip(&tm) {
            let s = starts[m.group].scale;
            mean[m.group].0 += t.pos * s;
            mean[m.group].1 += 1.0;
        }
        let pos_var = pos_sigma2.max(prior);
        let pos_se = mean
            .iter()
            .zip(&rot_se)
            .map(|(&(q, n), &r)| {
                let q = q / n.max(1.0);
                (pos_var / n.max(1.0) + q.length_squared() * r * r).sqrt()
            })
            .collect();
        let mut se = vec![f64::INFINITY; free.len()];
        if !free.is_empty() && sigma2.is_finite() {
            let jac = self.jacobian(p, free, &r);
            let n = free.len();
            let mut a = vec![vec![0.0; n]; n];
            for x in 0..n {
                for y in 0..n {
                    a[x][y] = jac[x].iter().zip(&jac[y]).map(|(a, b)| a * b).sum();
                }
            }
            for (k, s) in se.iter_mut().enumerate() {
                let mut e = vec![0.0; n];
                e[k] = 1.0;
                if let Some(col) = solve_linear(a.clone(), e) {
                    let v = col[k] * sigma2;
                    if v.is_finite() && v >= 0.0 {
                        *s = v.sqrt();
                    }
                }
            }
        }
        (
            Solution {
                starts,
                rot_se,
                pos_se,
                drawn,
                sigma2: pos_sigma2,
                rot_rms,
            },
            se,
        )
    }
}

/// Solves `a x = b` (Gaussian elimination with partial pivoting); `None`
/// when `a` is singular.
pub(super) fn solve_linear(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Option<Vec<f64>> {
    let n = b.len();
    let scale = a
        .iter()
        .flatten()
        .fold(0.0f64, |m, v| m.max(v.abs()))
        .max(1e-300);
    for col in 0..n {
        let pivot = (col..n).max_by(|&x, &y| a[x][col].abs().total_cmp(&a[y][col].abs()))?;
        let size = a[pivot][col].abs();
        if size.is_nan() || size <= scale * 1e-14 {
            return None;
        }
        a.swap(col, pivot);
        b.swap(col, pivot);
        let (top, below) = a.split_at_mut(col + 1);
        let top = &top[col];
        for (k, row) in below.iter_mut().enumerate() {
            let f = row[col] / top[col];
            for (x, y) in row[col..].iter_mut().zip(&top[col..]) {
                *x -= f * y;
            }
            b[col + 1 + k] -= f * b[col];
        }
    }
    let mut x = vec![0.0; n];
    for row in (0..n).rev() {
        let s: f64 = (row + 1..n).map(|k| a[row][k] * x[k]).sum();
        x[row] = (b[row] - s) / a[row][row];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// The roundest angle (radians) within `allow` of `v`: a multiple of 90°,
/// 45°, 30°, 15°, 10°, 5°, 1°, 0.5° or 0.1°, else `v`.
pub(super) fn nice_angle(v: f64, allow: f64) -> f64 {
    let deg = v.to_degrees();
    let allow = allow.to_degrees();
    for k in [90.0, 45.0, 30.0, 15.0, 10.0, 5.0, 1.0, 0.5, 0.1] {
        let r = (deg / k).round() * k;
        if (r - deg).abs() <= allow {
            return wrap((r + 0.0).to_radians());
        }
    }
    v
}

/// The shortest decimal within `allow` of `v` (at most 6 decimals).
pub(super) fn nice(v: f64, allow: f64) -> f64 {
    for digits in 0..=6 {
        let k = 10f64.powi(digits);
        let r = (v * k).round() / k;
        if (r - v).abs() <= allow {
            return r + 0.0;
        }
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_noisy_row_fits_its_step() {
        // Five members 10 apart along x, heading up, with small noise.
        let noise = [0.1, -0.2, 0.05, 0.15, -0.1];
        let members: Vec<Member> = (0..5)
            .map(|k| Member {
                group: 0,
                frame: Frame {
                    pos: DVec2::new(3.0 + 10.0 * k as f64, 1.0 + noise[k]),
                    rot: 0.01 * noise[(k + 2) % 5],
                    scale: 1.0,
                },
                lever: 1.0,
                rot_se: 0.0,
                pos_se: 0.0,
                tilted: false,
            })
            .collect();
        let model = |p: &[f64], out: &mut Vec<Frame>| {
            out.clear();
            for k in 0..5 {
                out.push(Frame {
                    pos: DVec2::new(p[0] * k as f64, 0.0),
                    rot: 0.0,
                    scale: 1.0,
                });
            }
        };
        let mut fit = Fit::new(&members, 1, &model, None);
        let mut p = [9.0];
        fit.solve_robust(&mut p, &[0]);
        assert!((p[0] - 10.0).abs() < 0.05, "{p:?}");
        let (sol, se) = fit.result(&p, &[0]);
        assert!(se[0] < 0.1, "{se:?}");
        assert!((sol.starts[0].pos - DVec2::new(3.0, 1.0)).length() < 0.2);
        assert_eq!(nice(p[0], 3.0 * se[0]), 10.0);
    }

    #[test]
    fn round_angles_win() {
        assert_eq!(
            nice_angle(89.4f64.to_radians(), 1f64.to_radians()),
            90f64.to_radians()
        );
        let v = 8.5f64.to_radians();
        assert_eq!(nice_angle(v, 1e-6), v);
        assert_eq!(nice(20.7063, 0.05), 20.7);
    }
}
