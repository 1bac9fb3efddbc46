//! The first step of an edit: reading the scene to edit from the AST.
//!
//! Owns: choosing the scene, reading each guide's polygon to numbers (literals,
//! constants and deterministic functions of them), checking that every
//! operation names a guide and vertex that exist, and the scene's size. Must
//! not build springs or change the AST.

use super::{EditError, Op, VertexRef};
use crate::ast::{Expr, ExprKind, File, GuideStmt, Item, Scene, SceneStmt, UnOp};
use crate::check::{Checked, suggest};
use glam::DVec2;

/// A guide as the edit sees it.
pub(super) struct GuideInfo {
    pub name: String,
    /// The index of the guide statement in the scene body.
    pub stmt: usize,
    /// Source values of the polygon's vertices.
    pub points: Vec<DVec2>,
    /// The particle of each vertex.
    pub particles: Vec<usize>,
}

/// The scenes of `file` with their item index, in source order.
pub(super) fn scenes(file: &File) -> Vec<(usize, &Scene)> {
    file.items
        .stmts
        .iter()
        .enumerate()
        .filter_map(|(i, it)| match &it.node {
            Item::Scene(s) => Some((i, s)),
            _ => None,
        })
        .collect()
}

/// The scene named `name`, or the first.
pub(super) fn choose<'a>(
    scenes: &[(usize, &'a Scene)],
    name: Option<&str>,
) -> Result<(usize, &'a Scene), EditError> {
    let Some(&first) = scenes.first() else {
        return Err(EditError::Input(
            "the program has no scene: `lsyc edit` moves the guides of a `scene`".to_string(),
        ));
    };
    let Some(name) = name else {
        return Ok(first);
    };
    if let Some(&found) = scenes.iter().find(|(_, s)| s.name.name == name) {
        return Ok(found);
    }
    let names = scenes.iter().map(|(_, s)| s.name.name.as_str());
    let hint = suggest(name, names.clone())
        .map(|s| format!("did you mean `{s}`?"))
        .unwrap_or_else(|| format!("the scenes are {}", quoted(names)));
    Err(EditError::Usage(
        format!("there is no scene `{name}`"),
        Some(hint),
    ))
}

fn quoted<'a>(names: impl Iterator<Item = &'a str>) -> String {
    names
        .map(|n| format!("`{n}`"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The guides of the scene with a polygon, their vertices as numbers.
pub(super) fn collect_guides(sc: &Scene, checked: &Checked) -> Result<Vec<GuideInfo>, EditError> {
    let mut guides = Vec::new();
    for (stmt, st) in sc.body.stmts.iter().enumerate() {
        let SceneStmt::Guide(g) = &st.node else {
            continue;
        };
        if guides.iter().any(|x: &GuideInfo| x.name == g.name.name) {
            continue; // a duplicate (the checker reports it)
        }
        let Some(pts) = g.body.stmts.iter().find_map(|s| match &s.node {
            GuideStmt::Polygon(p) => Some(p),
            _ => None,
        }) else {
            continue;
        };
        let mut points = Vec::with_capacity(pts.len());
        for (k, pt) in pts.iter().enumerate() {
            let mut xy = DVec2::ZERO;
            for (axis, e) in [&pt.x, &pt.y].into_iter().enumerate() {
                xy[axis] = const_value(e, checked).filter(|v| v.is_finite()).ok_or_else(|| {
                    EditError::Input(format!(
                        "guide `{}`: the {} coordinate of v{k}, `{}`, has no value known before derivation",
                        g.name.name,
                        ["x", "y"][axis],
                        crate::fmt::format_expr(e)
                    ))
                })?;
            }
            points.push(xy);
        }
        guides.push(GuideInfo {
            name: g.name.name.clone(),
            stmt,
            points,
            particles: Vec::new(),
        });
    }
    Ok(guides)
}

/// Checks that every guide and vertex the operations name exists in `sc`.
pub(super) fn validate(
    ops: &[Op],
    sc: &Scene,
    guides: &[GuideInfo],
    scenes: &[(usize, &Scene)],
) -> Result<(), EditError> {
    for op in ops {
        for name in op.guides() {
            if !guides.iter().any(|g| g.name == name) {
                return Err(no_guide(name, sc, guides, scenes));
            }
        }
        let pinned = match op {
            Op::Pin(g, Some(k)) => Some(VertexRef {
                guide: g.clone(),
                index: *k,
            }),
            _ => None,
        };
        for v in op.vertices().into_iter().chain(pinned.as_ref()) {
            let n = guides
                .iter()
                .find(|g| g.name == v.guide)
                .map_or(0, |g| g.points.len());
            if v.index >= n {
                return Err(EditError::Usage(
                    format!(
                        "guide `{}` has {n} vertices, numbered v0 to v{}: there is no `{v}`",
                        v.guide,
                        n.saturating_sub(1)
                    ),
                    Some(
                        "vertex K is the K-th point of the guide's `polygon`, counting from 0"
                            .to_string(),
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// The error for a guide `name` that `sc` does not have, with a hint.
fn no_guide(name: &str, sc: &Scene, guides: &[GuideInfo], scenes: &[(usize, &Scene)]) -> EditError {
    let elsewhere = scenes.iter().find(|(_, s)| {
        s.name.name != sc.name.name
            && s.body
                .stmts
                .iter()
                .any(|st| matches!(&st.node, SceneStmt::Guide(g) if g.name.name == name))
    });
    let hint = if let Some((_, s)) = elsewhere {
        Some(format!(
            "`{name}` is a guide of scene `{}`; choose it with --scene {}",
            s.name.name, s.name.name
        ))
    } else if let Some(s) = suggest(name, guides.iter().map(|g| g.name.as_str())) {
        Some(format!("did you mean `{s}`?"))
    } else if guides.is_empty() {
        None
    } else {
        Some(format!(
            "the guides are {}",
            quoted(guides.iter().map(|g| g.name.as_str()))
        ))
    };
    EditError::Usage(
        format!("there is no guide `{name}` in scene `{}`", sc.name.name),
        hint,
    )
}

/// The value of a number literal (`3`, `-2.5`), or `None` for any other expression.
pub(super) fn literal(e: &Expr) -> Option<f64> {
    match &e.kind {
        ExprKind::Num(v) => Some(*v),
        ExprKind::Unary(UnOp::Neg, a) => literal(a).map(|v| -v),
        _ => None,
    }
}

/// The value of a constant expression (literals, constants, deterministic functions).
pub(super) fn const_value(e: &Expr, checked: &Checked) -> Option<f64> {
    literal(e).or_else(|| checked.value_of(e))
}

/// The diagonal of the bounding box of every guide vertex (1 if there is none).
pub(super) fn scene_size(guides: &[GuideInfo]) -> f64 {
    let mut lo = DVec2::INFINITY;
    let mut hi = DVec2::NEG_INFINITY;
    for p in guides.iter().flat_map(|g| &g.points) {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let d = (hi.x - lo.x).hypot(hi.y - lo.y);
    if d.is_finite() && d > 0.0 { d } else { 1.0 }
}
