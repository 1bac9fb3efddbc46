//! Transformation spaces: the transform between two placed things as a point
//! (α, d, s, β), nearest neighbours in the plane, and clustering.
//!
//! Owns: the paper's transform T = +(α) f(d) *(s) +(β) between two frames
//! (α the turn from the first frame's heading to the second's origin, d the
//! distance in the first frame's scale, s the scale ratio, β the remaining
//! turn), a uniform grid for nearest neighbours (so only nearby pairs are
//! compared, not all n²), and a clustering that replaces the paper's mean shift:
//! points are visited densest first and join the nearest cluster centre within
//! the tolerance box, else start one (one flat-kernel mean-shift step from every
//! point, found through a hash grid, so it runs in linear time). Must not know
//! what the points mean for rules.

use super::shape::{Frame, rotate, wrap};
use glam::DVec2;
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// A fast hasher for grid cells (small integer keys that lsyc computes, so no
/// defence against chosen keys is needed beyond the mixing): the Fx hash
/// of rustc. Iteration order of the maps is never used.
#[derive(Clone, Copy, Default)]
pub(crate) struct CellHasher(u64);

impl Hasher for CellHasher {
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut word = [0u8; 8];
            word[..chunk.len()].copy_from_slice(chunk);
            self.write_u64(u64::from_le_bytes(word));
        }
    }

    fn write_u64(&mut self, n: u64) {
        self.0 = (self.0.rotate_left(5) ^ n).wrapping_mul(0xf135_7aea_2e62_a9c5);
    }

    fn write_i64(&mut self, n: i64) {
        self.write_u64(n as u64);
    }

    fn write_usize(&mut self, n: usize) {
        self.write_u64(n as u64);
    }

    fn finish(&self) -> u64 {
        self.0.rotate_left(26)
    }
}

/// A map keyed by small numbers lsyc computes (cells, instance indices).
pub(crate) type CellMap<K, V> = HashMap<K, V, BuildHasherDefault<CellHasher>>;

/// A transform from one frame to another, as turtle commands
/// `+(alpha) f(d) *(s) +(beta)` (angles in radians).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tr {
    pub alpha: f64,
    pub d: f64,
    pub s: f64,
    pub beta: f64,
}

/// Below this distance (relative to the first frame's size) two origins
/// coincide and α is taken as 0.
const COINCIDE: f64 = 1e-6;

impl Tr {
    pub const IDENTITY: Tr = Tr {
        alpha: 0.0,
        d: 0.0,
        s: 1.0,
        beta: 0.0,
    };

    /// The transform that takes the turtle from frame `a` to frame `b`;
    /// `size` is a length in `a`'s units under which origins coincide.
    pub fn between(a: &Frame, b: &Frame, size: f64) -> Tr {
        let v = b.pos - a.pos;
        let d = v.length() / a.scale;
        let s = b.scale / a.scale;
        let turn = wrap(b.rot - a.rot);
        if d <= size * COINCIDE {
            return Tr {
                alpha: 0.0,
                d: 0.0,
                s,
                beta: turn,
            };
        }
        let heading = (-v.x).atan2(v.y);
        let alpha = wrap(heading - a.rot);
        Tr {
            alpha,
            d,
            s,
            beta: wrap(turn - alpha),
        }
    }

    /// The frame reached from `a` by this transform.
    pub fn apply(&self, a: &Frame) -> Frame {
        let dir = rotate(DVec2::Y, a.rot + self.alpha);
        Frame {
            pos: a.pos + dir * self.d * a.scale,
            rot: wrap(a.rot + self.alpha + self.beta),
            scale: a.scale * self.s,
        }
    }
}

/// A point of a transformation space in tolerance units: α/tol, ln d/tol,
/// ln s/tol, β/tol. Angles wrap with period `turn` (2π over the angle tolerance).
pub type Point = [f64; 4];

/// The clusters of `points`: a label per point and the centres. `turn` is the
/// period of the two angle coordinates (0 or less: no wrapping).
///
/// Points share their cell's neighbourhood: the occupied cells around each
/// distinct cell are found once (not 3⁴ look-ups per point), and a point's
/// density and candidate centres come from them.
pub fn cluster(points: &[Point], turn: f64) -> (Vec<usize>, Vec<Point>) {
    let key = |p: &Point| -> [i64; 4] { [0, 1, 2, 3].map(|k| p[k].floor() as i64) };
    let cells_per_turn = if turn > 0.0 { turn.floor() as i64 } else { 0 };
    let wrap_key = |mut k: [i64; 4]| {
        if cells_per_turn > 0 {
            k[0] = k[0].rem_euclid(cells_per_turn);
            k[3] = k[3].rem_euclid(cells_per_turn);
        }
        k
    };
    let diff = |a: f64, b: f64, angle: bool| {
        let d = a - b;
        if angle && turn > 0.0 {
            d - turn * (d / turn).round()
        } else {
            d
        }
    };
    let close =
        |a: &Point, b: &Point| (0..4).all(|k| diff(a[k], b[k], k == 0 || k == 3).abs() <= 1.0);
    // The 3⁴ cells around a cell; with fewer than three cells per turn some
    // wrap onto each other and are counted once.
    let offsets: Vec<[i64; 4]> = (0..81)
        .map(|i: i64| [i / 27 % 3 - 1, i / 9 % 3 - 1, i / 3 % 3 - 1, i % 3 - 1])
        .collect();
    let distinct = cells_per_turn == 0 || cells_per_turn >= 3;
    let neighbours = |k: [i64; 4]| {
        let mut out: Vec<[i64; 4]> = offsets
            .iter()
            .map(|o| wrap_key([0, 1, 2, 3].map(|i| k[i].saturating_add(o[i]))))
            .collect();
        if !distinct {
            out.sort_unstable();
            out.dedup();
        }
        out
    };
    // Occupied cells (wrapped keys), numbered, with their number of points;
    // and the distinct (unwrapped) keys of the points, numbered.
    let mut cell_of: CellMap<[i64; 4], usize> = CellMap::default();
    let mut occupancy: Vec<usize> = Vec::new();
    let mut key_of: CellMap<[i64; 4], usize> = CellMap::default();
    let mut keys: Vec<[i64; 4]> = Vec::new();
    let at: Vec<usize> = points
        .iter()
        .map(|p| {
            let k = key(p);
            let c = *cell_of.entry(wrap_key(k)).or_insert_with(|| {
                occupancy.push(0);
                occupancy.len() - 1
            });
            occupancy[c] += 1;
            *key_of.entry(k).or_insert_with(|| {
                keys.push(k);
                keys.len() - 1
            })
        })
        .collect();
    // Per distinct key: the occupied cells of the 3⁴ around it.
    let around: Vec<Vec<usize>> = keys
        .iter()
        .map(|&k| {
            neighbours(k)
                .iter()
                .filter_map(|n| cell_of.get(n).copied())
                .collect()
        })
        .collect();
    // Points in the 3⁴ cells around each point's own: one flat-kernel
    // estimate of density, linear in the number of points.
    let key_density: Vec<usize> = around
        .iter()
        .map(|cells| cells.iter().map(|&c| occupancy[c]).sum())
        .collect();
    let density = |i: usize| key_density[at[i]];
    let mut order: Vec<usize> = (0..points.len()).collect();
    order.sort_by(|&a, &b| density(b).cmp(&density(a)).then(a.cmp(&b)));
    // Centres by the cell of their leader (always an occupied cell).
    let mut leaders: Vec<Vec<usize>> = vec![Vec::new(); occupancy.len()];
    let mut centres: Vec<Point> = Vec::new();
    let mut label = vec![0; points.len()];
    for i in order {
        let p = &points[i];
        let mut best: Option<(f64, usize)> = None;
        for &cell in &around[at[i]] {
            for &c in &leaders[cell] {
                if close(p, &centres[c]) {
                    let d: f64 = (0..4)
                        .map(|k| diff(p[k], centres[c][k], k == 0 || k == 3).powi(2))
                        .sum();
                    if best.is_none_or(|(bd, bc)| d < bd || (d == bd && c < bc)) {
                        best = Some((d, c));
                    }
                }
            }
        }
        match best {
            Some((_, c)) => label[i] = c,
            None => {
                label[i] = centres.len();
                leaders[cell_of[&wrap_key(key(p))]].push(centres.len());
                centres.push(*p);
            }
        }
    }
    // Centres as the means of their members (angles relative to the leader).
    let mut sums = vec![([0.0; 4], 0usize); centres.len()];
    for (i, p) in points.iter().enumerate() {
        let c = label[i];
        for k in 0..4 {
            sums[c].0[k] += diff(p[k], centres[c][k], k == 0 || k == 3);
        }
        sums[c].1 += 1;
    }
    for (c, (s, n)) in sums.iter().enumerate() {
        for k in 0..4 {
            centres[c][k] += s[k] / *n as f64;
        }
    }
    (label, centres)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transforms_compose_back() {
        let a = Frame {
            pos: DVec2::new(3.0, 4.0),
            rot: 0.3,
            scale: 2.0,
        };
        let b = Frame {
            pos: DVec2::new(-5.0, 9.0),
            rot: -1.2,
            scale: 0.5,
        };
        let t = Tr::between(&a, &b, 1.0);
        let c = t.apply(&a);
        assert!(c.pos.distance(b.pos) < 1e-9, "{c:?}");
        assert!(wrap(c.rot - b.rot).abs() < 1e-12);
        assert!((c.scale - b.scale).abs() < 1e-12);
        assert!((t.s - 0.25).abs() < 1e-12);
    }

    #[test]
    fn clusters_wrap_around_the_turn() {
        let turn = 360.0;
        let pts = vec![
            [179.6, 0.0, 0.0, 0.0],
            [-179.8 + 360.0, 0.0, 0.0, 0.0],
            [0.2 - 0.5, 0.1, 0.0, 0.0],
            [10.0, 0.0, 0.0, 0.0],
            [359.9, 0.0, 0.0, 0.3],
        ];
        let (label, centres) = cluster(&pts, turn);
        assert_eq!(label[0], label[1]);
        assert_eq!(label[2], label[4]);
        assert_ne!(label[0], label[2]);
        assert_ne!(label[3], label[0]);
        assert_eq!(centres.len(), 3);
    }
}
