//! The tubes of the OBJ mesh: rings carried along a chain of segments by
//! parallel transport, mitred joints, caps, and the low-poly spheres at joints
//! where a new tube starts.
//!
//! Owns: the geometry of generalized cylinders and where joints are
//! remembered. Must not know the turtle, element outlines or number printing
//! (the builder's `vertex`, `normal` and `tri` send them on).

use super::{MAX_JOINTS, MAX_OPEN_CHAINS, MITRE_MAX_REACH, MITRE_MIN_COS, MeshBuilder, MeshTarget};
use glam::{DQuat, DVec3};

/// First vertex and first normal index (1-based) of a ring of `sides` vertices.
#[derive(Clone, Copy, Debug)]
pub(super) struct Ring {
    pub(super) v: u64,
    pub(super) n: u64,
    /// Vertices (and normals) in the ring.
    pub(super) k: u64,
}

/// A tube whose last segment's end ring is not written yet: the next segment
/// decides whether it becomes a mitred joint or an end with a cap.
#[derive(Clone, Copy, Debug)]
pub(super) struct Chain {
    /// End of the last segment.
    pub(super) end: DVec3,
    /// Unit direction and length of the last segment.
    pub(super) dir: DVec3,
    pub(super) len: f64,
    /// Unit vector perpendicular to `dir`: where ring vertex 0 lies.
    pub(super) n: DVec3,
    pub(super) radius: f64,
    pub(super) color: u32,
    /// The ring profile (the builder's `profiles`).
    pub(super) profile: usize,
    /// The ring at the start of the last segment.
    pub(super) ring: Ring,
}

/// A remembered point that a tube reached.
#[derive(Clone, Copy, Debug)]
pub(super) struct Joint {
    /// The thickest tube radius seen here.
    pub(super) radius: f64,
    /// The largest sphere already written here (0 when none).
    pub(super) sphere: f64,
}

impl<T: MeshTarget> MeshBuilder<T> {
    pub(super) fn radius(&self, width: f64) -> f64 {
        let r = width * 0.5;
        if r.is_finite() && r > 0.0 {
            r
        } else {
            self.default_radius
        }
    }

    /// Writes a ring of `profile`: vertex i at `point(offset i)`, normal i
    /// `normal(normal i)`, offsets and normals in the plane across `dir`
    /// spanned by `n` and `dir × n`.
    fn ring(
        &mut self,
        profile: usize,
        point: impl Fn(DVec3) -> DVec3,
        normal: impl Fn(DVec3) -> DVec3,
        n: DVec3,
        dir: DVec3,
    ) -> Ring {
        let b = dir.cross(n);
        let first_v = self.v + 1;
        let first_n = self.vn + 1;
        let prof = std::sync::Arc::clone(&self.profiles[profile]);
        for &[x, y, _, _] in prof.iter() {
            self.vertex(point(n * x + b * y));
        }
        for &[_, _, nx, ny] in prof.iter() {
            let radial = n * nx + b * ny;
            self.normal(normal(radial).try_normalize().unwrap_or(radial));
        }
        Ring {
            v: first_v,
            n: first_n,
            k: prof.len() as u64,
        }
    }

    /// The side of a tube between two rings (`a` behind `b`): one quad per side
    /// (planar unless the radius changes).
    fn side(&mut self, a: Ring, b: Ring) {
        let k = a.k.min(b.k);
        for i in 0..k {
            let j = (i + 1) % k;
            self.out.face(&[
                (a.v + i, a.n + i),
                (a.v + j, a.n + j),
                (b.v + j, b.n + j),
                (b.v + i, b.n + i),
            ]);
            self.counts.faces += 1;
        }
    }

    /// A fan from a centre vertex; `outward` is the cap's normal, `reverse` for
    /// the start cap (whose normal points against the ring's direction).
    fn cap(&mut self, ring: Ring, centre: DVec3, outward: DVec3, reverse: bool) {
        let c = self.vertex(centre);
        let cn = self.normal(outward);
        let k = ring.k;
        for i in 0..k {
            let j = (i + 1) % k;
            let (p, q) = ((ring.v + i, cn), (ring.v + j, cn));
            if reverse {
                self.tri((c, cn), q, p);
            } else {
                self.tri((c, cn), p, q);
            }
        }
    }

    /// A UV sphere (`sides` around, at least 2 bands), closed on its own.
    fn sphere(&mut self, centre: DVec3, r: f64) {
        let lon = self.sides as u64;
        let lat = (self.sides / 2).max(2);
        let north = centre + DVec3::Z * r;
        let np = (self.vertex(north), self.normal(DVec3::Z));
        let first = (self.v + 1, self.vn + 1);
        for j in 1..lat {
            let phi = std::f64::consts::PI * j as f64 / lat as f64;
            let (sp, cp) = phi.sin_cos();
            for i in 0..self.sides {
                let (c, s) = self.ring_angles[i];
                let d = DVec3::new(sp * c, sp * s, cp);
                self.vertex(centre + d * r);
                self.normal(d);
            }
        }
        let sp = (
            self.vertex(centre - DVec3::Z * r),
            self.normal(DVec3::NEG_Z),
        );
        // Vertices and normals are counted separately: both index the same way.
        let at = |j: u64, i: u64| {
            let k = (j - 1) * lon + i % lon;
            (first.0 + k, first.1 + k)
        };
        let bands = lat as u64;
        for i in 0..lon {
            self.tri(np, at(1, i), at(1, i + 1));
        }
        for j in 1..bands - 1 {
            for i in 0..lon {
                self.tri(at(j, i), at(j + 1, i), at(j + 1, i + 1));
                self.tri(at(j, i), at(j + 1, i + 1), at(j, i + 1));
            }
        }
        for i in 0..lon {
            self.tri(sp, at(bands - 1, i + 1), at(bands - 1, i));
        }
        self.counts.spheres += 1;
    }

    /// Writes the end ring and cap of a chain.
    pub(super) fn close(&mut self, chain: Chain) {
        self.material(chain.color);
        let (end, r) = (chain.end, chain.radius);
        let ring = self.ring(chain.profile, |v| end + v * r, |v| v, chain.n, chain.dir);
        self.side(chain.ring, ring);
        self.cap(ring, end, chain.dir, false);
        self.counts.tubes += 1;
    }

    /// Whether the joint between `chain` and a segment along `dir` of length
    /// `len` and radius `r` can be mitred without the tube folding.
    pub(super) fn can_mitre(chain: &Chain, dir: DVec3, len: f64, r: f64) -> bool {
        let c = chain.dir.dot(dir).clamp(-1.0, 1.0);
        if c < MITRE_MIN_COS {
            return false;
        }
        let tan_half = ((1.0 - c) / (1.0 + c)).sqrt();
        let reach = 0.5 * (chain.radius + r) * tan_half;
        reach <= MITRE_MAX_REACH * chain.len.min(len)
    }

    /// Writes the mitred joint ring of `chain` and the side of its last
    /// segment; the result continues along the new segment.
    pub(super) fn mitre(
        &mut self,
        chain: Chain,
        b: DVec3,
        dir: DVec3,
        len: f64,
        r: f64,
        color: u32,
    ) -> Chain {
        self.material(chain.color);
        let d0 = chain.dir;
        let m = (d0 + dir).try_normalize().unwrap_or(d0);
        let cos_half = d0.dot(m).max(1e-9);
        let rot = DQuat::from_rotation_arc(d0, dir);
        let rj = 0.5 * (chain.radius + r);
        let p = chain.end;
        let ring = self.ring(
            chain.profile,
            |v| p + v * rj - d0 * (rj * v.dot(m) / cos_half),
            |v| v + rot * v,
            chain.n,
            d0,
        );
        self.side(chain.ring, ring);
        let n = rot * chain.n;
        let n = (n - dir * dir.dot(n))
            .try_normalize()
            .unwrap_or_else(|| perpendicular(dir));
        Chain {
            end: b,
            dir,
            len,
            n,
            radius: r,
            color,
            profile: chain.profile,
            ring,
        }
    }

    /// Remembers that a tube of radius `r` reached `p`.
    pub(super) fn remember(&mut self, p: DVec3, r: f64) {
        let k = key(p);
        if let Some(j) = self.joints.get_mut(&k) {
            j.radius = j.radius.max(r);
            return;
        }
        if self.joint_order.len() >= MAX_JOINTS
            && let Some(old) = self.joint_order.pop_front()
        {
            self.joints.remove(&old);
        }
        self.joints.insert(
            k,
            Joint {
                radius: r,
                sphere: 0.0,
            },
        );
        self.joint_order.push_back(k);
    }

    /// Starts a tube at `a` (a sphere first when a tube already reached `a`).
    pub(super) fn start(&mut self, a: DVec3, b: DVec3, dir: DVec3, len: f64, r: f64, color: u32) {
        self.material(color);
        let k = key(a);
        let sphere = match self.joints.get_mut(&k) {
            Some(j) => {
                let s = j.radius.max(r);
                if s > j.sphere * (1.0 + 1e-9) {
                    j.sphere = s;
                    Some(s)
                } else {
                    None
                }
            }
            None => None,
        };
        if let Some(s) = sphere {
            self.sphere(a, s);
        }
        self.remember(a, r);
        let n = perpendicular(dir);
        let profile = self.profile;
        let ring = self.ring(profile, |v| a + v * r, |v| v, n, dir);
        self.cap(ring, a, -dir, true);
        self.open.push(Chain {
            end: b,
            dir,
            len,
            n,
            radius: r,
            color,
            profile,
            ring,
        });
        if self.open.len() > MAX_OPEN_CHAINS {
            let oldest = self.open.remove(0);
            self.close(oldest);
        }
    }
}

/// A ring profile from a counter-clockwise contour: each point with the unit
/// normal of its corner (the mean of its two edges' outward normals).
pub(super) fn profile(c: &[glam::DVec2]) -> Vec<[f64; 4]> {
    let k = c.len();
    (0..k)
        .map(|i| {
            let outward = |a: glam::DVec2, b: glam::DVec2| {
                let e = b - a;
                glam::DVec2::new(e.y, -e.x).normalize_or_zero()
            };
            let n = outward(c[(i + k - 1) % k], c[i]) + outward(c[i], c[(i + 1) % k]);
            let n = n
                .try_normalize()
                .unwrap_or(c[i].normalize_or(glam::DVec2::X));
            [c[i].x, c[i].y, n.x, n.y]
        })
        .collect()
}

/// The exact position as a map key (−0 and +0 are the same point).
fn key(p: DVec3) -> [u64; 3] {
    [
        (p.x + 0.0).to_bits(),
        (p.y + 0.0).to_bits(),
        (p.z + 0.0).to_bits(),
    ]
}

/// A unit vector perpendicular to the unit vector `d`, chosen deterministically.
fn perpendicular(d: DVec3) -> DVec3 {
    // The axis least aligned with d.
    let a = d.abs();
    let axis = if a.x <= a.y && a.x <= a.z {
        DVec3::X
    } else if a.y <= a.z {
        DVec3::Y
    } else {
        DVec3::Z
    };
    (axis - d * d.dot(axis)).normalize()
}
