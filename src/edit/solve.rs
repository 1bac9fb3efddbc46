//! The second step of an edit: the mass-spring system of the scene's guides,
//! the targets the operations set, and the solve.
//!
//! Owns: snapping vertices of different guides into shared particles (through
//! the crate's point index), the springs (edges, diagonals, linked edges,
//! `--stiff` pairs), turning operations into pinned targets, and running
//! `spring::System::solve`. Must not read or change the AST beyond the link
//! statements whose edges it stiffens.

use super::parse::{GuideInfo, const_value};
use super::spring::{Params, Solution, System, polygon_springs};
use super::{EditError, INERTIA, K_DIAGONAL, K_EDGE, K_LINK, K_STIFF, Op, SNAP, VertexRef};
use crate::ast::{Scene, SceneStmt};
use crate::check::Checked;
use crate::geometry::{centroid, index::PointGrid, rotate_scale_about};
use glam::DVec2;
use std::collections::{BTreeMap, HashMap};

/// The system of a scene, ready to solve.
pub(super) struct Springs<'g> {
    pub sys: System,
    /// Guide index by name.
    pub by_name: HashMap<&'g str, usize>,
}

/// The particles of the guides' vertices (filling each guide's `particles`),
/// snapped across guides within [`SNAP`] × `size`.
pub(super) fn particles(guides: &mut [GuideInfo], size: f64) -> System {
    let mut sys = System::default();
    snap(guides, SNAP * size, &mut sys);
    sys
}

/// Adds the springs to the particles `sys`.
pub(super) fn build<'g>(
    mut sys: System,
    guides: &'g [GuideInfo],
    sc: &Scene,
    checked: &Checked,
    ops: &[Op],
) -> Springs<'g> {
    for g in guides {
        for (a, b, is_edge) in polygon_springs(g.particles.len()) {
            let k = if is_edge { K_EDGE } else { K_DIAGONAL };
            sys.add_spring(g.particles[a], g.particles[b], k);
        }
    }
    let by_name: HashMap<&str, usize> = guides
        .iter()
        .enumerate()
        .map(|(i, g)| (g.name.as_str(), i))
        .collect();
    for st in &sc.body.stmts {
        let SceneStmt::Link(l) = &st.node else {
            continue;
        };
        for end in [&l.from, &l.to] {
            let Some(&gi) = by_name.get(end.guide.name.as_str()) else {
                continue;
            };
            let g = &guides[gi];
            let n = g.particles.len();
            if let Some(e) = const_value(&end.index, checked)
                && e >= 0.0
                && e.fract() == 0.0
                && (e as usize) < n
            {
                let e = e as usize;
                sys.add_spring(g.particles[e], g.particles[(e + 1) % n], K_LINK);
            }
        }
    }
    let particle = |v: &VertexRef| guides[by_name[v.guide.as_str()]].particles[v.index];
    for op in ops {
        if let Op::Stiff(a, b) = op {
            sys.add_spring(particle(a), particle(b), K_STIFF);
        }
    }
    Springs { sys, by_name }
}

/// Vertices within `tol` of an earlier particle join the earliest such one;
/// the others become new particles.
fn snap(guides: &mut [GuideInfo], tol: f64, sys: &mut System) {
    let all: Vec<DVec2> = guides.iter().flat_map(|g| g.points.clone()).collect();
    let grid = PointGrid::with_cell(&all, tol);
    // The particle each vertex started, if it started one.
    let mut started: Vec<Option<usize>> = vec![None; all.len()];
    let mut j = 0;
    for g in guides {
        for &p in &g.points {
            let found = grid
                .within(p, tol)
                .into_iter()
                .filter(|&i| i < j)
                .filter_map(|i| started[i])
                .min();
            let id = found.unwrap_or_else(|| {
                sys.rest.push(p);
                started[j] = Some(sys.rest.len() - 1);
                sys.rest.len() - 1
            });
            g.particles.push(id);
            j += 1;
        }
    }
}

/// The target of every particle an operation moves or pins, the operations
/// applied in the order given.
pub(super) fn targets(
    ops: &[Op],
    springs: &Springs,
    guides: &[GuideInfo],
    sc: &Scene,
) -> Result<BTreeMap<usize, DVec2>, EditError> {
    let (sys, by_name) = (&springs.sys, &springs.by_name);
    let mut pins: BTreeMap<usize, DVec2> = BTreeMap::new();
    let current =
        |pins: &BTreeMap<usize, DVec2>, p: usize| pins.get(&p).copied().unwrap_or(sys.rest[p]);
    let guide_particles = |g: &str| {
        let mut ps = guides[by_name[g]].particles.clone();
        ps.sort_unstable();
        ps.dedup();
        ps
    };
    let particle = |v: &VertexRef| guides[by_name[v.guide.as_str()]].particles[v.index];
    for op in ops {
        match op {
            Op::Move(v, to) => {
                pins.insert(particle(v), *to);
            }
            Op::By(v, d) => {
                let p = particle(v);
                pins.insert(p, current(&pins, p) + *d);
            }
            Op::Translate(g, d) => {
                for p in guide_particles(g) {
                    pins.insert(p, current(&pins, p) + *d);
                }
            }
            Op::Rotate(g, _) | Op::Scale(g, _) => {
                let now: Vec<DVec2> = guides[by_name[g.as_str()]]
                    .particles
                    .iter()
                    .map(|&p| current(&pins, p))
                    .collect();
                let c = centroid(&now);
                let sin_cos = match op {
                    Op::Rotate(_, deg) => deg.to_radians().sin_cos(),
                    _ => (0.0, 1.0),
                };
                let k = if let Op::Scale(_, k) = op { *k } else { 1.0 };
                for p in guide_particles(g) {
                    pins.insert(p, rotate_scale_about(current(&pins, p), c, sin_cos, k));
                }
            }
            Op::Pin(g, v) => {
                let ps = match v {
                    Some(k) => vec![guides[by_name[g.as_str()]].particles[*k]],
                    None => guide_particles(g),
                };
                for p in ps {
                    pins.insert(p, current(&pins, p));
                }
            }
            Op::Stiff(..) => {}
        }
    }
    finite(&pins, guides, sc)?;
    Ok(pins)
}

/// An error naming the first target beyond the range of numbers, if any.
fn finite(
    pins: &BTreeMap<usize, DVec2>,
    guides: &[GuideInfo],
    sc: &Scene,
) -> Result<(), EditError> {
    let Some((&p, t)) = pins.iter().find(|(_, t)| !t.is_finite()) else {
        return Ok(());
    };
    let (g, k) = guides
        .iter()
        .find_map(|g| {
            g.particles
                .iter()
                .position(|&q| q == p)
                .map(|k| (&g.name, k))
        })
        .map_or((&sc.name.name, 0), |(g, k)| (g, k));
    Err(EditError::Usage(
        format!(
            "the operations move {g}.v{k} to ({}, {}), beyond the range of numbers",
            t.x, t.y
        ),
        None,
    ))
}

/// Relaxes the free particles with the targets `pins` held.
pub(super) fn solve(sys: &System, pins: &BTreeMap<usize, DVec2>, size: f64) -> Solution {
    let params = Params {
        inertia: INERTIA,
        size,
        ..Params::default()
    };
    sys.solve(pins, &params)
}
