//! The last step of an edit: writing the solved positions back into the AST.
//!
//! Owns: which coordinates change (only those whose value, rounded to the
//! scene's precision, changed), replacing a moved expression by its number,
//! carrying seeds along (`--move-seeds`) by the affine map that best fits a
//! guide's old vertices to its new ones, and the warnings about seeds left
//! outside. Must not solve or print anything.

use super::parse::{GuideInfo, const_value, literal};
use super::{EditError, Options, Outcome};
use crate::ast::{Expr, ExprKind, File, Guide, GuideStmt, Item, SceneStmt};
use crate::check::Checked;
use crate::geometry::{affine_fit, inside, rotation_degrees};
use crate::number::round;
use glam::{DAffine2, DVec2};

/// What the write-back needs besides the file.
pub(super) struct Solved<'a> {
    pub guides: &'a [GuideInfo],
    /// Particle positions before and after.
    pub rest: &'a [DVec2],
    pub positions: &'a [DVec2],
    /// Decimals of the written coordinates.
    pub places: usize,
    pub checked: &'a Checked,
    pub options: &'a Options,
}

/// Writes the moved polygons (and seeds) of the scene at `item` into `file`.
pub(super) fn write_back(
    file: &mut File,
    item: usize,
    s: &Solved,
    outcome: &mut Outcome,
) -> Result<(), EditError> {
    let Item::Scene(scene) = &mut file.items.stmts[item].node else {
        return Err(EditError::Input("the scene disappeared".to_string()));
    };
    for g in s.guides {
        let SceneStmt::Guide(guide) = &mut scene.body.stmts[g.stmt].node else {
            continue;
        };
        let new: Vec<DVec2> = g.particles.iter().map(|&p| s.positions[p]).collect();
        let moved = polygon(guide, g, &new, s, outcome);
        if moved == 0 {
            continue;
        }
        outcome.changed.push((g.name.clone(), moved));
        seeds(guide, g, &new, s, outcome);
    }
    Ok(())
}

/// Writes the guide's moved vertices; returns how many moved.
fn polygon(
    guide: &mut Guide,
    g: &GuideInfo,
    new: &[DVec2],
    s: &Solved,
    outcome: &mut Outcome,
) -> usize {
    let Some(pts) = guide
        .body
        .stmts
        .iter_mut()
        .find_map(|st| match &mut st.node {
            GuideStmt::Polygon(pts) => Some(pts),
            _ => None,
        })
    else {
        return 0;
    };
    let mut moved = 0;
    for (k, pt) in pts.iter_mut().enumerate() {
        if new[k] == s.rest[g.particles[k]] {
            continue;
        }
        let mut any = false;
        for (axis, e) in [&mut pt.x, &mut pt.y].into_iter().enumerate() {
            let what = format!("{}.v{k} {}", g.name, ["x", "y"][axis]);
            any |= write_number(e, new[k][axis], g.points[k][axis], s.places, &what, outcome);
        }
        moved += usize::from(any);
    }
    moved
}

/// Carries the guide's seeds along (`--move-seeds`), or warns about those the
/// moved polygon left outside.
fn seeds(guide: &mut Guide, g: &GuideInfo, new: &[DVec2], s: &Solved, outcome: &mut Outcome) {
    let fit = affine_fit(&g.points, new);
    for (si, st) in guide.body.stmts.iter_mut().enumerate() {
        let GuideStmt::Seed(seed) = &mut st.node else {
            continue;
        };
        let (Some(x), Some(y)) = (
            const_value(&seed.at.x, s.checked),
            const_value(&seed.at.y, s.checked),
        ) else {
            continue;
        };
        if s.options.move_seeds {
            let name = format!("{}'s seed {}", g.name, si);
            move_seed(seed, DVec2::new(x, y), &fit, &name, s, outcome);
            outcome.seeds_moved += 1;
        } else if !inside(DVec2::new(x, y), new) {
            outcome.warnings.push(format!(
                "the seed at ({}, {}) of guide `{}` is outside its moved polygon; --move-seeds carries seeds with their guides",
                crate::fmt::format_number(x),
                crate::fmt::format_number(y),
                g.name
            ));
        }
    }
}

/// Moves one seed by `fit`, its heading turned by the fit's rotation.
fn move_seed(
    seed: &mut crate::ast::Seed,
    at: DVec2,
    fit: &DAffine2,
    name: &str,
    s: &Solved,
    outcome: &mut Outcome,
) {
    let to = fit.transform_point2(at);
    let places = s.places;
    write_number(
        &mut seed.at.x,
        to.x,
        at.x,
        places,
        &format!("{name} x"),
        outcome,
    );
    write_number(
        &mut seed.at.y,
        to.y,
        at.y,
        places,
        &format!("{name} y"),
        outcome,
    );
    let turn = rotation_degrees(fit);
    let old = seed
        .heading
        .as_ref()
        .and_then(|h| const_value(h, s.checked))
        .unwrap_or(0.0);
    let places = places.max(1);
    if round(turn, places) == 0.0 {
        return;
    }
    match &mut seed.heading {
        Some(h) => {
            write_number(
                h,
                old + turn,
                old,
                places,
                &format!("{name} heading"),
                outcome,
            );
        }
        None => seed.heading = Some(Expr::num(round(old + turn, places))),
    }
}

/// Writes `new` (rounded) into the coordinate `e` whose value was `old`, if the
/// rounded values differ; notes an expression replaced by a number. Returns
/// whether it wrote.
fn write_number(
    e: &mut Expr,
    new: f64,
    old: f64,
    places: usize,
    what: &str,
    outcome: &mut Outcome,
) -> bool {
    let v = round(new, places);
    if v == round(old, places) {
        return false;
    }
    if literal(e).is_none() {
        outcome.replaced.push(format!(
            "{what}: `{}` is now {}",
            crate::fmt::format_expr(e),
            crate::fmt::format_number(v)
        ));
    }
    *e = Expr {
        kind: ExprKind::Num(v),
        span: e.span,
    };
    true
}
