//! The mass-spring system of guide editing and its solver.
//!
//! Owns: particles, springs and the minimisation that moves the free particles
//! once some are pinned at targets. Knows nothing about the AST.
//!
//! The model (Guided Procedural Modeling, §4.2): particles with mass, springs at
//! their rest length. Dragged particles are constraints. The free particles take
//! the positions that minimise
//!
//! ```text
//! E(x) = ½ Σ_springs k (|x_a − x_b| − L)²  +  ½ w Σ_free |x − x⁰|²
//! ```
//!
//! The second term is the inertia of one backward-Euler step of length h from rest
//! (w = m/h²): it keeps a particle where it was unless a spring pulls it, so the
//! guides not connected to a dragged vertex stay exactly where they are, and a
//! connected guide follows as a near-rigid body when w is small beside k.
//!
//! The solver starts the free particles at the harmonic extension of the pinned
//! displacements, then runs Newton's method on E: each step solved by
//! Jacobi-preconditioned conjugate gradients truncated at negative curvature, no
//! step longer than half the shortest spring (a guide must not jump into its
//! mirror image, which has the same spring energy), and a backtracking (Armijo)
//! line search. Every loop runs in a fixed
//! order, so the result is the same bit for bit on every run. Only the particles
//! connected through springs to a pinned particle are variables; with nothing
//! pinned nothing is touched, and a system whose pinned particles sit where they
//! were has zero gradient and is returned unchanged.

pub use crate::geometry::dist;
use glam::DVec2;
use std::collections::{BTreeMap, HashMap};

/// A spring between two particles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spring {
    pub a: usize,
    pub b: usize,
    /// The rest length.
    pub rest: f64,
    /// The stiffness k.
    pub k: f64,
}

/// Particles at rest and the springs between them.
#[derive(Clone, Debug, Default)]
pub struct System {
    /// Rest positions x⁰.
    pub rest: Vec<DVec2>,
    pub springs: Vec<Spring>,
    /// The spring joining each pair (a < b), by index.
    index: HashMap<(usize, usize), usize>,
}

/// How the solver runs.
#[derive(Clone, Copy, Debug)]
pub struct Params {
    /// The inertia weight w = m/h² relative to a unit spring stiffness.
    pub inertia: f64,
    /// At most this many Newton iterations.
    pub max_iterations: usize,
    /// Stop when no free particle moves more than `tolerance × size` in an iteration.
    pub tolerance: f64,
    /// The scale of the scene (its bounding-box diagonal), for the tolerance.
    pub size: f64,
}

impl Default for Params {
    fn default() -> Params {
        Params {
            inertia: 0.001,
            max_iterations: 500,
            tolerance: 1e-10,
            size: 1.0,
        }
    }
}

/// The positions the solver found and how it got there.
#[derive(Clone, Debug, PartialEq)]
pub struct Solution {
    pub positions: Vec<DVec2>,
    /// Newton iterations run.
    pub iterations: usize,
    /// Whether the tolerance was reached before `max_iterations`.
    pub converged: bool,
    /// How many particles were free variables.
    pub free: usize,
}

impl System {
    /// Adds a spring at the current distance of `a` and `b`; a spring already
    /// joining the pair keeps the larger stiffness.
    pub fn add_spring(&mut self, a: usize, b: usize, k: f64) {
        if a == b {
            return;
        }
        let (a, b) = if a < b { (a, b) } else { (b, a) };
        if let Some(&i) = self.index.get(&(a, b)) {
            self.springs[i].k = self.springs[i].k.max(k);
            return;
        }
        let rest = dist(self.rest[a], self.rest[b]);
        self.index.insert((a, b), self.springs.len());
        self.springs.push(Spring { a, b, rest, k });
    }

    /// The variables: the free particles reached through springs from a pinned
    /// one, in index order (`free`), and each particle's index among them
    /// (`var`, `usize::MAX` for the others).
    fn variables(&self, pins: &BTreeMap<usize, DVec2>) -> (Vec<usize>, Vec<usize>) {
        let n = self.rest.len();
        let mut adj: Vec<Vec<usize>> = vec![Vec::new(); n];
        for s in &self.springs {
            adj[s.a].push(s.b);
            adj[s.b].push(s.a);
        }
        let mut reached = vec![false; n];
        let mut stack: Vec<usize> = pins.keys().copied().filter(|&i| i < n).collect();
        for &i in &stack {
            reached[i] = true;
        }
        while let Some(i) = stack.pop() {
            for &j in &adj[i] {
                if !reached[j] {
                    reached[j] = true;
                    stack.push(j);
                }
            }
        }
        // var[i] = the index of particle i among the variables.
        let mut var = vec![usize::MAX; n];
        let mut free = Vec::new();
        for i in 0..n {
            if reached[i] && !pins.contains_key(&i) {
                var[i] = free.len();
                free.push(i);
            }
        }
        (var, free)
    }

    /// Moves the pinned particles to their targets and relaxes the free ones.
    pub fn solve(&self, pins: &BTreeMap<usize, DVec2>, params: &Params) -> Solution {
        let n = self.rest.len();
        let mut x = self.rest.clone();
        for (&i, &t) in pins {
            if i < n {
                x[i] = t;
            }
        }
        let (var, free) = self.variables(pins);
        let springs: Vec<Spring> = self
            .springs
            .iter()
            .copied()
            .filter(|s| var[s.a] != usize::MAX || var[s.b] != usize::MAX)
            .collect();
        let mut sol = Solution {
            positions: x,
            iterations: 0,
            converged: true,
            free: free.len(),
        };
        if free.is_empty() {
            return sol;
        }
        let problem = Problem {
            rest: &self.rest,
            springs: &springs,
            var: &var,
            free: &free,
            w: params.inertia,
            size: params.size.max(f64::MIN_POSITIVE),
        };
        let step_tol = params.tolerance * problem.size;
        // No Newton step moves a particle further than half the shortest spring,
        // so that a guide cannot jump through itself into its mirror image.
        let cap = springs
            .iter()
            .map(|s| 0.5 * s.rest)
            .filter(|r| *r > 1e-9 * problem.size)
            .fold(f64::INFINITY, f64::min);
        sol.converged = false;
        let x = &mut sol.positions;
        problem.initial_guess(x);
        for it in 0..params.max_iterations {
            let g = problem.gradient(x);
            if g.iter().all(|v| *v == 0.0) {
                sol.iterations = it;
                sol.converged = true;
                return sol;
            }
            let h = problem.hessian(x);
            let p = h.solve_neg(&g);
            let slope: f64 = g.iter().zip(&p).map(|(a, b)| a * b).sum();
            if slope.is_nan() || slope >= 0.0 {
                // Not a descent direction (only rounding can do this): done.
                sol.iterations = it;
                sol.converged = true;
                return sol;
            }
            let e0 = problem.energy(x);
            let longest = (0..free.len())
                .map(|v| p[2 * v].hypot(p[2 * v + 1]))
                .fold(0.0f64, f64::max);
            let mut alpha = if longest > cap { cap / longest } else { 1.0 };
            let mut trial = x.clone();
            let mut accepted = false;
            for _ in 0..40 {
                for (v, &i) in free.iter().enumerate() {
                    trial[i] = DVec2::new(x[i].x + alpha * p[2 * v], x[i].y + alpha * p[2 * v + 1]);
                }
                if problem.energy(&trial) <= e0 + 1e-4 * alpha * slope {
                    accepted = true;
                    break;
                }
                alpha *= 0.5;
            }
            sol.iterations = it + 1;
            if !accepted {
                // No step lowers the energy: at the minimum up to rounding, unless
                // the gradient is still large (numbers out of range).
                let kmax = springs.iter().fold(params.inertia, |m, s| m.max(s.k));
                let gmax = g.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                sol.converged = gmax <= 1e-8 * kmax * problem.size;
                return sol;
            }
            let moved = p.iter().fold(0.0f64, |m, v| m.max((alpha * v).abs()));
            std::mem::swap(x, &mut trial);
            if moved <= step_tol {
                sol.converged = true;
                return sol;
            }
        }
        sol
    }
}

struct Problem<'a> {
    rest: &'a [DVec2],
    springs: &'a [Spring],
    var: &'a [usize],
    free: &'a [usize],
    w: f64,
    size: f64,
}

impl Problem<'_> {
    fn energy(&self, x: &[DVec2]) -> f64 {
        let mut e = 0.0;
        for s in self.springs {
            let d = dist(x[s.a], x[s.b]) - s.rest;
            e += 0.5 * s.k * d * d;
        }
        for &i in self.free {
            let d = dist(x[i], self.rest[i]);
            e += 0.5 * self.w * d * d;
        }
        e
    }

    /// Starts the free particles at the harmonic extension of the pinned
    /// particles' displacements: (w I + Σ k L) u = pinned neighbours' pull, the
    /// springs treated as isotropic. A translation carries a guide hanging from a
    /// dragged vertex along; a local drag fades with distance. Nothing pinned
    /// away from its rest position gives u = 0 exactly.
    fn initial_guess(&self, x: &mut [DVec2]) {
        let m = self.free.len();
        let mut diag = vec![[self.w, 0.0, 0.0, self.w]; m];
        let mut off = Vec::new();
        let mut rhs = vec![0.0; 2 * m];
        for s in self.springs {
            let (va, vb) = (self.var[s.a], self.var[s.b]);
            let block = [s.k, 0.0, 0.0, s.k];
            for v in [va, vb] {
                if v != usize::MAX {
                    diag[v][0] += s.k;
                    diag[v][3] += s.k;
                }
            }
            let pull = |v: usize, other: usize, rhs: &mut [f64]| {
                rhs[2 * v] += s.k * (x[other].x - self.rest[other].x);
                rhs[2 * v + 1] += s.k * (x[other].y - self.rest[other].y);
            };
            match (va != usize::MAX, vb != usize::MAX) {
                (true, true) => off.push((va, vb, block)),
                (true, false) => pull(va, s.b, &mut rhs),
                (false, true) => pull(vb, s.a, &mut rhs),
                (false, false) => {}
            }
        }
        let neg: Vec<f64> = rhs.iter().map(|v| -v).collect();
        let u = Hessian { diag, off }.solve_neg(&neg);
        for (v, &i) in self.free.iter().enumerate() {
            x[i] = DVec2::new(self.rest[i].x + u[2 * v], self.rest[i].y + u[2 * v + 1]);
        }
    }

    /// The unit direction from b to a and the length, or `None` when they coincide.
    fn direction(&self, x: &[DVec2], s: &Spring) -> (Option<DVec2>, f64) {
        let d = x[s.a] - x[s.b];
        let l = d.x.hypot(d.y);
        if l <= 1e-12 * self.size {
            (None, l)
        } else {
            (Some(d / l), l)
        }
    }

    fn gradient(&self, x: &[DVec2]) -> Vec<f64> {
        let mut g = vec![0.0; 2 * self.free.len()];
        for (v, &i) in self.free.iter().enumerate() {
            g[2 * v] = self.w * (x[i].x - self.rest[i].x);
            g[2 * v + 1] = self.w * (x[i].y - self.rest[i].y);
        }
        for s in self.springs {
            let (Some(n), l) = self.direction(x, s) else {
                continue;
            };
            let f = s.k * (l - s.rest);
            if f == 0.0 {
                continue;
            }
            let va = self.var[s.a];
            let vb = self.var[s.b];
            if va != usize::MAX {
                g[2 * va] += f * n.x;
                g[2 * va + 1] += f * n.y;
            }
            if vb != usize::MAX {
                g[2 * vb] -= f * n.x;
                g[2 * vb + 1] -= f * n.y;
            }
        }
        g
    }

    fn hessian(&self, x: &[DVec2]) -> Hessian {
        let m = self.free.len();
        let mut diag = vec![[self.w, 0.0, 0.0, self.w]; m];
        let mut off = Vec::new();
        for s in self.springs {
            // k [n nᵀ + (1 − L/l)(I − n nᵀ)]: the spring's exact Hessian (indefinite
            // when compressed; conjugate gradients stop at negative curvature).
            let block = match self.direction(x, s) {
                (Some(n), l) => {
                    let t = 1.0 - s.rest / l;
                    let nn = [n.x * n.x, n.x * n.y, n.y * n.x, n.y * n.y];
                    [
                        s.k * (nn[0] + t * (1.0 - nn[0])),
                        s.k * (nn[1] * (1.0 - t)),
                        s.k * (nn[2] * (1.0 - t)),
                        s.k * (nn[3] + t * (1.0 - nn[3])),
                    ]
                }
                (None, _) => [s.k, 0.0, 0.0, s.k],
            };
            let va = self.var[s.a];
            let vb = self.var[s.b];
            for v in [va, vb] {
                if v != usize::MAX {
                    for (d, b) in diag[v].iter_mut().zip(block) {
                        *d += b;
                    }
                }
            }
            if va != usize::MAX && vb != usize::MAX {
                off.push((va, vb, block));
            }
        }
        Hessian { diag, off }
    }
}

/// A sparse symmetric 2×2-block matrix: diagonal blocks, and off-diagonal blocks
/// stored once as −block at (a, b) and (b, a).
struct Hessian {
    diag: Vec<[f64; 4]>,
    off: Vec<(usize, usize, [f64; 4])>,
}

impl Hessian {
    fn mul(&self, v: &[f64], out: &mut [f64]) {
        for (i, d) in self.diag.iter().enumerate() {
            out[2 * i] = d[0] * v[2 * i] + d[1] * v[2 * i + 1];
            out[2 * i + 1] = d[2] * v[2 * i] + d[3] * v[2 * i + 1];
        }
        for &(a, b, k) in &self.off {
            out[2 * a] -= k[0] * v[2 * b] + k[1] * v[2 * b + 1];
            out[2 * a + 1] -= k[2] * v[2 * b] + k[3] * v[2 * b + 1];
            out[2 * b] -= k[0] * v[2 * a] + k[1] * v[2 * a + 1];
            out[2 * b + 1] -= k[2] * v[2 * a] + k[3] * v[2 * a + 1];
        }
    }

    /// Solves H p = −g by preconditioned conjugate gradients, truncated at a
    /// direction of negative curvature (Newton–CG): p is always a descent direction.
    fn solve_neg(&self, g: &[f64]) -> Vec<f64> {
        let len = g.len();
        let inv: Vec<f64> = (0..len)
            .map(|j| {
                let d = self.diag[j / 2][if j % 2 == 0 { 0 } else { 3 }];
                if d > 0.0 { 1.0 / d } else { 1.0 }
            })
            .collect();
        let mut p = vec![0.0; len];
        let mut r: Vec<f64> = g.iter().map(|v| -v).collect();
        let mut z: Vec<f64> = r.iter().zip(&inv).map(|(a, b)| a * b).collect();
        let mut d = z.clone();
        let mut rz: f64 = r.iter().zip(&z).map(|(a, b)| a * b).sum();
        let r0: f64 = r.iter().map(|v| v * v).sum::<f64>().sqrt();
        let mut hd = vec![0.0; len];
        for _ in 0..(4 * len + 50) {
            self.mul(&d, &mut hd);
            let dhd: f64 = d.iter().zip(&hd).map(|(a, b)| a * b).sum();
            if dhd.is_nan() || dhd <= 0.0 {
                // Negative curvature: keep the descent direction found so far
                // (the preconditioned gradient when nothing was found yet).
                if p.iter().all(|v| *v == 0.0) {
                    p.clone_from(&d);
                }
                break;
            }
            let alpha = rz / dhd;
            for j in 0..len {
                p[j] += alpha * d[j];
                r[j] -= alpha * hd[j];
            }
            let rn: f64 = r.iter().map(|v| v * v).sum::<f64>().sqrt();
            if rn <= 1e-13 * r0 {
                break;
            }
            for j in 0..len {
                z[j] = r[j] * inv[j];
            }
            let rz_new: f64 = r.iter().zip(&z).map(|(a, b)| a * b).sum();
            let beta = rz_new / rz;
            rz = rz_new;
            for j in 0..len {
                d[j] = z[j] + beta * d[j];
            }
        }
        p
    }
}

/// The springs that make a polygon of `n` vertices rigid-ish, as pairs of vertex
/// indices: its edges; for n ≤ 6 every diagonal; above, the diagonals to the
/// vertex after next (i, i+2) and to the opposite vertex (i, i+n/2).
pub fn polygon_springs(n: usize) -> Vec<(usize, usize, bool)> {
    let mut out: Vec<(usize, usize, bool)> = Vec::new();
    let mut push = |a: usize, b: usize, edge: bool| {
        let (a, b) = if a < b { (a, b) } else { (b, a) };
        if a != b && !out.iter().any(|&(x, y, _)| x == a && y == b) {
            out.push((a, b, edge));
        }
    };
    for i in 0..n {
        push(i, (i + 1) % n, true);
    }
    if n <= 6 {
        for i in 0..n {
            for j in i + 2..n {
                push(i, j, false);
            }
        }
    } else {
        for i in 0..n {
            push(i, (i + 2) % n, false);
        }
        for i in 0..n {
            push(i, (i + n / 2) % n, false);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A point.
    fn pt(x: f64, y: f64) -> DVec2 {
        DVec2::new(x, y)
    }

    fn square(sys: &mut System, at: DVec2, side: f64) -> Vec<usize> {
        let base = sys.rest.len();
        sys.rest.extend([
            at,
            pt(at.x + side, at.y),
            pt(at.x + side, at.y + side),
            pt(at.x, at.y + side),
        ]);
        for (a, b, _) in polygon_springs(4) {
            sys.add_spring(base + a, base + b, 1.0);
        }
        (base..base + 4).collect()
    }

    fn params() -> Params {
        Params {
            size: 100.0,
            ..Params::default()
        }
    }

    #[test]
    fn nothing_dragged_stays_exactly_at_rest() {
        let mut sys = System::default();
        square(&mut sys, pt(0.0, 0.0), 10.0);
        square(&mut sys, pt(10.0, 0.0), 7.3);
        let sol = sys.solve(&BTreeMap::new(), &params());
        assert_eq!(sol.positions, sys.rest);
        assert_eq!(sol.free, 0);
        // Pinned where they are: the gradient is zero, nothing moves by a bit.
        let pins: BTreeMap<usize, DVec2> = [(0, sys.rest[0]), (5, sys.rest[5])].into();
        let sol = sys.solve(&pins, &params());
        assert_eq!(sol.positions, sys.rest);
        assert!(sol.converged);
        assert_eq!(sol.iterations, 0);
    }

    #[test]
    fn dragged_vertex_lands_exactly_on_its_target() {
        let mut sys = System::default();
        square(&mut sys, pt(0.0, 0.0), 10.0);
        let target = pt(3.162_277_660_168_379_5, -27.182_818_284);
        let sol = sys.solve(&[(2, target)].into(), &params());
        assert_eq!(sol.positions[2], target);
        assert!(sol.converged);
    }

    #[test]
    fn a_rigid_guide_keeps_its_edge_lengths_when_dragged_by_one_vertex() {
        let mut sys = System::default();
        square(&mut sys, pt(0.0, 0.0), 10.0);
        let sol = sys.solve(&[(2, pt(40.0, 25.0))].into(), &params());
        assert!(sol.converged);
        for s in &sys.springs {
            let l = dist(sol.positions[s.a], sol.positions[s.b]);
            assert!(
                (l - s.rest).abs() < 0.02 * s.rest,
                "spring {}-{}: {l} vs {}",
                s.a,
                s.b,
                s.rest
            );
        }
        // It followed: every vertex moved most of the way.
        for i in 0..4 {
            let d = [
                sol.positions[i].x - sys.rest[i].x,
                sol.positions[i].y - sys.rest[i].y,
            ];
            assert!(d[0] > 20.0 && d[1] > 10.0, "vertex {i} moved by {d:?}");
        }
    }

    #[test]
    fn shared_particles_move_together_and_unconnected_stay() {
        // Two squares sharing an edge (particles 1 and 2 of the first), and a third
        // square far away with no spring to them.
        let mut sys = System::default();
        square(&mut sys, pt(0.0, 0.0), 10.0);
        let base = sys.rest.len();
        sys.rest.extend([pt(20.0, 0.0), pt(20.0, 10.0)]);
        let second = [1, base, base + 1, 2];
        for (a, b, _) in polygon_springs(4) {
            sys.add_spring(second[a], second[b], 1.0);
        }
        let far = square(&mut sys, pt(100.0, 100.0), 5.0);
        let pins: BTreeMap<usize, DVec2> = [(0, pt(0.0, -5.0)), (3, pt(0.0, 5.0))].into();
        let sol = sys.solve(&pins, &params());
        // The second square moved with the first through the shared particles.
        for i in [1, 2, base, base + 1] {
            assert!(
                (sol.positions[i].y - sys.rest[i].y + 5.0).abs() < 0.5,
                "particle {i}: {:?}",
                sol.positions[i]
            );
        }
        for i in far {
            assert_eq!(sol.positions[i], sys.rest[i]);
        }
    }

    #[test]
    fn stiff_springs_hold_their_length_better() {
        let mut soft = System::default();
        square(&mut soft, pt(0.0, 0.0), 10.0);
        let mut stiff = soft.clone();
        stiff.add_spring(0, 1, 100.0);
        // Pull vertices 1 and 2 apart from 0 and 3.
        let pins: BTreeMap<usize, DVec2> =
            [(0, pt(0.0, 0.0)), (3, pt(0.0, 10.0)), (2, pt(16.0, 10.0))].into();
        let a = soft.solve(&pins, &params());
        let b = stiff.solve(&pins, &params());
        let ea = (dist(a.positions[0], a.positions[1]) - 10.0).abs();
        let eb = (dist(b.positions[0], b.positions[1]) - 10.0).abs();
        assert!(eb < ea / 10.0, "stiff {eb} vs soft {ea}");
    }

    #[test]
    fn deterministic() {
        let mut sys = System::default();
        square(&mut sys, pt(0.0, 0.0), 10.0);
        square(&mut sys, pt(10.0, 0.0), 10.0);
        sys.add_spring(1, 4, 1.0);
        sys.add_spring(2, 7, 1.0);
        let pins: BTreeMap<usize, DVec2> = [(0, pt(-3.0, 7.5)), (6, pt(30.0, 30.0))].into();
        let a = sys.solve(&pins, &params());
        for _ in 0..5 {
            let b = sys.solve(&pins, &params());
            let bits = |s: &Solution| -> Vec<u64> {
                s.positions
                    .iter()
                    .flat_map(|p| [p.x.to_bits(), p.y.to_bits()])
                    .collect()
            };
            assert_eq!(bits(&a), bits(&b));
        }
    }

    /// The rank of the rigidity matrix is 2n − 3 for a rigid framework.
    fn rigidity_rank(pts: &[DVec2], bars: &[(usize, usize, bool)]) -> usize {
        let cols = 2 * pts.len();
        let mut m: Vec<Vec<f64>> = bars
            .iter()
            .map(|&(a, b, _)| {
                let mut row = vec![0.0; cols];
                let d = [pts[a].x - pts[b].x, pts[a].y - pts[b].y];
                row[2 * a] = d[0];
                row[2 * a + 1] = d[1];
                row[2 * b] = -d[0];
                row[2 * b + 1] = -d[1];
                row
            })
            .collect();
        let mut rank = 0;
        for c in 0..cols {
            let Some(p) = (rank..m.len()).max_by(|&i, &j| m[i][c].abs().total_cmp(&m[j][c].abs()))
            else {
                break;
            };
            if m[p][c].abs() < 1e-9 {
                continue;
            }
            m.swap(rank, p);
            let pivot = m[rank].clone();
            for (i, row) in m.iter_mut().enumerate() {
                if i != rank {
                    let f = row[c] / pivot[c];
                    for (x, y) in row.iter_mut().zip(&pivot) {
                        *x -= f * y;
                    }
                }
            }
            rank += 1;
        }
        rank
    }

    #[test]
    fn polygon_springs_make_polygons_rigid() {
        for n in 3..=24 {
            // A slightly irregular convex polygon (regular ones can be special).
            let pts: Vec<DVec2> = (0..n)
                .map(|i| {
                    let a = i as f64 / n as f64 * std::f64::consts::TAU;
                    let r = 10.0 + (i * 7 % 5) as f64 * 0.37;
                    pt(r * a.cos(), r * a.sin())
                })
                .collect();
            let bars = polygon_springs(n);
            assert_eq!(rigidity_rank(&pts, &bars), 2 * n - 3, "n = {n}");
            assert_eq!(bars.iter().filter(|b| b.2).count(), n, "n = {n}: edges");
        }
    }
}
