//! Reading an SVG document safely, for every reader of drawings
//! (`sketch::strokes`, `elements::read`, `lines::read`): the checks a drawing
//! passes before usvg sees it, the usvg options, the walk over its paths, and
//! each path's subpaths in the language's world.
//!
//! Owns: refusing what would make usvg (or lsyc after it) run out of memory,
//! stack or time on a hostile file: compressed data (usvg inflates it without
//! a bound), a file over 64 MiB, entities that expand without bound, too many
//! attributes on one element (the XML parser compares each with all before
//! it), numbers beyond 32-bit floats (the raw text's pass, `scan`, before any
//! parser), too many XML nodes, elements nested too deep, `<use>` elements
//! that draw themselves or expand to too many elements (a "billion laughs"
//! of `<use>`s), and images (never loaded: an `href` may name any file, even
//! a device). The checks are one pass over the XML, iterative and linear in
//! its size. Also owns the map back to the document's user space (so that
//! what lsyc draws lies on the input), turning the SVG's y-down user space
//! into the language's y-up world (x, −y), subpaths as segments (`Seg`) and
//! flattening them into points. Must not decide what an element means.

pub mod scan;

use glam::DVec2;
use std::collections::HashMap;
use thiserror::Error;
use usvg::roxmltree;
use usvg::tiny_skia_path::{PathSegment, Point, Transform};

/// The most XML nodes (elements, text, comments) a document may have.
pub const MAX_XML_NODES: u32 = 2_000_000;
/// The deepest nesting of elements, a `<use>` counting as the parent of
/// what it draws (usvg refuses 1,024 levels with a less helpful message).
pub const MAX_NESTING: usize = 1_000;
/// The most elements a document may draw once every `<use>` is expanded
/// (usvg's own bound).
pub const MAX_EXPANDED: u64 = 1_000_000;
/// Points per flattened curve segment.
pub const CURVE_STEPS: usize = 12;

/// Why a document is not read. The messages say what to change; the file
/// name is added by whoever reports it.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum Refusal {
    /// usvg's (or the XML parser's) reason.
    #[error("{0}")]
    NotSvg(String),
    #[error("it is compressed (SVGZ); lsyc reads plain SVG text: decompress it first (gunzip)")]
    Compressed,
    #[error(
        "it has more than {MAX_XML_NODES} XML nodes; lsyc reads drawings of up to {MAX_XML_NODES}"
    )]
    TooManyNodes,
    #[error(
        "its elements are nested more than {MAX_NESTING} levels deep (groups, and `<use>` with what it draws); lsyc reads drawings nested up to {MAX_NESTING} levels"
    )]
    TooDeep,
    #[error(
        "it draws more than {MAX_EXPANDED} elements once its `<use>` elements are expanded; lsyc reads drawings of up to {MAX_EXPANDED}"
    )]
    TooBig,
    #[error(
        "{what} draws{} which contains it (directly or through other `<use>` elements), so it would draw itself without end",
        target_note(id)
    )]
    UseCycle { what: String, id: String },
    /// Grouping the subpaths of paths into elements compared too many boxes.
    #[error(
        "its paths have subpaths that overlap in crowds: grouping them into elements would compare more than {limit} pairs of boxes (split or simplify those paths)"
    )]
    Crowded { limit: u64 },
    /// A limit of the reader: `what` is counted while reading.
    #[error("it has more than {limit} {what}; lsyc infers from drawings of up to {limit} {what}")]
    TooMany { what: &'static str, limit: usize },
    #[error("it is larger than {limit_mib} MiB; lsyc reads drawings of up to {limit_mib} MiB")]
    TooLarge { limit_mib: usize },
    #[error(
        "{at}: its DOCTYPE's entities expand to more than {limit_mib} MiB of text, or refer to each other too deeply; lsyc reads drawings whose entities stay within that (write the text out, or drop the entities)"
    )]
    EntityExpansion { at: Place, limit_mib: u64 },
    #[error(
        "{at}: `<{tag}>` has more than {limit} attributes; lsyc reads elements with up to {limit}"
    )]
    TooManyAttributes {
        at: Place,
        tag: String,
        limit: usize,
    },
    /// `number`: the number as written, and where (`` 1e308 in `d` of `<path>` ``).
    #[error(
        "{at}: the number {number} is beyond ±3.4e38, the largest coordinate lsyc reads (scale the drawing down)"
    )]
    NumberTooLarge { at: Place, number: String },
}

/// A place in a drawing's text, for messages.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Place {
    pub line: usize,
    pub column: usize,
}

impl std::fmt::Display for Place {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "line {}, column {}", self.line, self.column)
    }
}

fn target_note(id: &str) -> String {
    if id.is_empty() {
        " an element".to_string()
    } else {
        format!(" the element with id `{id}`,")
    }
}

/// The usvg options of both readers: no fonts, and images never loaded (a
/// drawing's images are skipped anyway, and an `href` may name any file).
pub fn options() -> usvg::Options<'static> {
    usvg::Options {
        image_href_resolver: usvg::ImageHrefResolver {
            resolve_data: Box::new(|_, _, _| None),
            resolve_string: Box::new(|_, _| None),
        },
        ..usvg::Options::default()
    }
}

/// Checks `data` and parses it with usvg.
pub fn parse(data: &[u8]) -> Result<usvg::Tree, Refusal> {
    check(data)?;
    usvg::Tree::from_data(data, &options()).map_err(|e| Refusal::NotSvg(e.to_string()))
}

/// The checks before usvg. A document that is not XML passes: usvg then
/// says why it cannot read it, in its own words.
pub fn check(data: &[u8]) -> Result<(), Refusal> {
    if data.starts_with(&[0x1f, 0x8b]) {
        return Err(Refusal::Compressed);
    }
    if data.len() > scan::MAX_BYTES {
        return Err(Refusal::TooLarge {
            limit_mib: scan::MAX_BYTES >> 20,
        });
    }
    let Ok(text) = std::str::from_utf8(data) else {
        return Ok(());
    };
    scan::scan(text)?;
    let opts = roxmltree::ParsingOptions {
        allow_dtd: true,
        nodes_limit: MAX_XML_NODES,
        ..roxmltree::ParsingOptions::default()
    };
    let doc = match roxmltree::Document::parse_with_options(text, opts) {
        Ok(doc) => doc,
        Err(roxmltree::Error::NodesLimitReached) => return Err(Refusal::TooManyNodes),
        Err(_) => return Ok(()),
    };
    expansion(&doc)
}

/// The element a `<use>` draws (its `href`, or else its `xlink:href`, `#id`).
fn use_target<'a, 'input>(
    node: roxmltree::Node<'a, 'input>,
    ids: &HashMap<&'a str, roxmltree::Node<'a, 'input>>,
) -> Option<roxmltree::Node<'a, 'input>> {
    let href = node
        .attributes()
        .find(|a| a.name() == "href" && a.namespace().is_none())
        .or_else(|| node.attributes().find(|a| a.name() == "href"))?;
    let id = href.value().trim().strip_prefix('#')?;
    ids.get(id.trim()).copied()
}

/// Walks the document as usvg will expand it (a `<use>`'s target is one
/// more child of the `<use>`), depth first with an explicit stack, and
/// finds the deepest nesting, the number of elements drawn and any cycle.
/// Each element is visited once: sizes and depths of shared targets are
/// remembered, so a `<use>` bomb costs no more than its text.
fn expansion(doc: &roxmltree::Document) -> Result<(), Refusal> {
    let mut ids: HashMap<&str, roxmltree::Node> = HashMap::new();
    let mut slots = 0;
    for n in doc.descendants() {
        slots = slots.max(n.id().get_usize() + 1);
        if n.is_element()
            && let Some(id) = n.attribute("id")
        {
            ids.entry(id).or_insert(n);
        }
    }
    #[derive(Clone, Copy, PartialEq)]
    enum State {
        New,
        Open,
        Done { size: u64, depth: usize },
    }
    let mut state = vec![State::New; slots];
    fn successors<'a, 'input>(
        n: roxmltree::Node<'a, 'input>,
        ids: &HashMap<&'a str, roxmltree::Node<'a, 'input>>,
    ) -> Vec<roxmltree::Node<'a, 'input>> {
        let mut out: Vec<roxmltree::Node> = n.children().filter(|c| c.is_element()).collect();
        if n.tag_name().name() == "use"
            && let Some(t) = use_target(n, ids)
        {
            out.push(t);
        }
        out
    }
    for root in doc.descendants().filter(|n| n.is_element()) {
        if state[root.id().get_usize()] != State::New {
            continue;
        }
        // (node, its successors, how many of them are done)
        let mut stack = vec![(root, successors(root, &ids), 0usize)];
        state[root.id().get_usize()] = State::Open;
        while let Some((node, next, k)) = stack.last_mut() {
            if let Some(&child) = next.get(*k) {
                *k += 1;
                match state[child.id().get_usize()] {
                    State::New => {
                        state[child.id().get_usize()] = State::Open;
                        let s = successors(child, &ids);
                        stack.push((child, s, 0));
                    }
                    State::Open => {
                        let what = match node.attribute("id") {
                            Some(id) => {
                                format!("the `<{}>` with id `{id}`", node.tag_name().name())
                            }
                            None => format!("a `<{}>`", node.tag_name().name()),
                        };
                        return Err(Refusal::UseCycle {
                            what,
                            id: child.attribute("id").unwrap_or("").to_string(),
                        });
                    }
                    State::Done { .. } => {}
                }
                continue;
            }
            let mut size = 1u64;
            let mut depth = 0usize;
            for c in next.iter() {
                if let State::Done { size: s, depth: d } = state[c.id().get_usize()] {
                    size = size.saturating_add(s);
                    depth = depth.max(d);
                }
            }
            let depth = depth + 1;
            if depth > MAX_NESTING {
                return Err(Refusal::TooDeep);
            }
            if size > MAX_EXPANDED {
                return Err(Refusal::TooBig);
            }
            state[node.id().get_usize()] = State::Done { size, depth };
            stack.pop();
        }
    }
    Ok(())
}

/// The paths of a parsed drawing, groups depth first in document order, each
/// with its transform (usvg's user space to the path's own coordinates),
/// with an explicit stack (the walk never recurses, however deep the
/// groups). Every reader (strokes, elements, lines) walks drawings through this.
/// The transform composes the groups' own transforms: usvg 0.49's
/// `abs_transform` applies a `<use>`'s transform twice when it draws a
/// `<symbol>` (linebender/resvg#1056).
pub fn paths(tree: &usvg::Tree) -> impl Iterator<Item = (&usvg::Path, Transform)> + '_ {
    let mut stack = vec![(tree.root().children().iter(), Transform::identity())];
    std::iter::from_fn(move || {
        while let Some((top, t)) = stack.last_mut() {
            let t = *t;
            match top.next() {
                None => {
                    stack.pop();
                }
                Some(usvg::Node::Group(g)) => {
                    stack.push((g.children().iter(), t.pre_concat(g.transform())))
                }
                Some(usvg::Node::Path(p)) => return Some((p.as_ref(), t)),
                Some(usvg::Node::Image(_) | usvg::Node::Text(_)) => {}
            }
        }
        None
    })
}

/// The map from usvg's coordinates back to the document's user space: usvg
/// puts the root `viewBox` (and a root `transform`) into one group around the
/// content, which the paths' transforms include; lsyc works in user units so that
/// what it draws back lies on the input.
pub fn user_space(data: &[u8], tree: &usvg::Tree) -> Transform {
    let root_group = || match tree.root().children() {
        [usvg::Node::Group(g)] if g.id().is_empty() => g.transform().invert(),
        _ => None,
    };
    let Ok(text) = std::str::from_utf8(data) else {
        return Transform::identity();
    };
    let Ok(doc) = usvg::roxmltree::Document::parse(text) else {
        return Transform::identity();
    };
    let svg = doc.root_element();
    let size = tree.size();
    let moved = svg.attribute("transform").is_some()
        || svg.attribute("viewBox").is_some_and(|v| {
            v.parse::<svgtypes::ViewBox>().is_ok_and(|b| {
                b.x != 0.0
                    || b.y != 0.0
                    || (b.w - f64::from(size.width())).abs() > 1e-9
                    || (b.h - f64::from(size.height())).abs() > 1e-9
            })
        });
    if moved {
        root_group().unwrap_or_default()
    } else {
        Transform::identity()
    }
}

/// One segment of a subpath in world coordinates (y up); each starts where the
/// previous one ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Seg {
    Move(DVec2),
    Line(DVec2),
    Quad(DVec2, DVec2),
    Cubic(DVec2, DVec2, DVec2),
    Close,
}

/// The subpaths of a path in world coordinates (`t`, the map from its own
/// coordinates to the document's user space, applied, and y flipped up),
/// exactly: curves stay curves. A subpath whose points are not all finite is
/// dropped.
pub fn subpaths(path: &usvg::Path, t: Transform) -> Vec<Vec<Seg>> {
    let map = |mut p: Point| {
        t.map_point(&mut p);
        DVec2::new(f64::from(p.x), -f64::from(p.y))
    };
    let mut out: Vec<Vec<Seg>> = Vec::new();
    let mut current: Vec<Seg> = Vec::new();
    for seg in path.data().segments() {
        let s = match seg {
            PathSegment::MoveTo(p) => {
                if !current.is_empty() {
                    out.push(std::mem::take(&mut current));
                }
                Seg::Move(map(p))
            }
            PathSegment::LineTo(p) => Seg::Line(map(p)),
            PathSegment::QuadTo(c, p) => Seg::Quad(map(c), map(p)),
            PathSegment::CubicTo(c1, c2, p) => Seg::Cubic(map(c1), map(c2), map(p)),
            PathSegment::Close => Seg::Close,
        };
        current.push(s);
    }
    if !current.is_empty() {
        out.push(current);
    }
    out.retain(|sub| {
        sub.iter()
            .all(|s| seg_points(s).iter().all(|p| p.is_finite()))
    });
    out
}

/// The points a segment names (controls, then its end).
pub fn seg_points(s: &Seg) -> Vec<DVec2> {
    match *s {
        Seg::Move(p) | Seg::Line(p) => vec![p],
        Seg::Quad(c, p) => vec![c, p],
        Seg::Cubic(a, b, p) => vec![a, b, p],
        Seg::Close => Vec::new(),
    }
}

/// A subpath as a polyline: curves flattened into `CURVE_STEPS` pieces, no two
/// consecutive points equal; a closed subpath ends where it started.
pub fn flatten(sub: &[Seg]) -> Vec<DVec2> {
    let pt = |p: DVec2| kurbo::Point::new(p.x, p.y);
    let mut bez = kurbo::BezPath::new();
    // A subpath that does not begin with a move starts at the origin, which is
    // not one of its points.
    let implicit = !matches!(sub.first(), Some(Seg::Move(_)) | None);
    if implicit {
        bez.move_to(pt(DVec2::ZERO));
    }
    for s in sub {
        match *s {
            Seg::Move(p) => bez.move_to(pt(p)),
            Seg::Line(p) => bez.line_to(pt(p)),
            Seg::Quad(c, p) => bez.quad_to(pt(c), pt(p)),
            Seg::Cubic(c1, c2, p) => bez.curve_to(pt(c1), pt(c2), pt(p)),
            Seg::Close => bez.close_path(),
        }
    }
    // The one flattener, with inference's finer count; then no repeated
    // points, and a closed subpath ends at its start.
    let mut points = Vec::new();
    for (i, line) in crate::path::flatten_steps(&bez, CURVE_STEPS)
        .into_iter()
        .enumerate()
    {
        let first = line.points.first().copied();
        let skip = usize::from(i == 0 && implicit);
        for &p in &line.points[skip..] {
            push(&mut points, p);
        }
        if let (true, Some(f)) = (line.closed, first) {
            push(&mut points, f);
        }
    }
    points
}

/// Appends `p` unless it repeats the last point.
fn push(points: &mut Vec<DVec2>, q: DVec2) {
    if points.last().is_none_or(|l| l.distance(q) > 1e-9) {
        points.push(q);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEAD: &str =
        r#"<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink">"#;

    #[test]
    fn plain_drawings_pass() {
        let svg = format!(
            r##"{HEAD}<defs><path id="p" d="M0 0L1 1"/></defs><use href="#p"/><use xlink:href="#p"/><g><use href="#p"/></g></svg>"##
        );
        assert_eq!(check(svg.as_bytes()), Ok(()));
        assert_eq!(check(b"not xml"), Ok(()));
        assert_eq!(check(&[0xff, 0xfe]), Ok(()));
    }

    #[test]
    fn cycles_depth_and_bombs_are_refused() {
        let cycle = format!(
            r##"{HEAD}<g id="a"><use href="#b"/></g><g id="b"><use xlink:href="#a"/></g></svg>"##
        );
        assert!(matches!(
            check(cycle.as_bytes()),
            Err(Refusal::UseCycle { .. })
        ));
        let own = format!(r##"{HEAD}<g id="a"><use href="#a"/></g></svg>"##);
        assert!(matches!(
            check(own.as_bytes()),
            Err(Refusal::UseCycle { .. })
        ));
        let deep = format!("{HEAD}{}{}</svg>", "<g>".repeat(5000), "</g>".repeat(5000));
        assert_eq!(check(deep.as_bytes()), Err(Refusal::TooDeep));
        let mut bomb = format!(r#"{HEAD}<defs><path id="l0" d="M0 0L1 1"/>"#);
        for k in 1..10 {
            bomb.push_str(&format!(r#"<g id="l{k}">"#));
            for _ in 0..10 {
                bomb.push_str(&format!(r##"<use href="#l{}"/>"##, k - 1));
            }
            bomb.push_str("</g>");
        }
        bomb.push_str(r##"</defs><use href="#l9"/></svg>"##);
        assert_eq!(check(bomb.as_bytes()), Err(Refusal::TooBig));
        assert_eq!(check(&[0x1f, 0x8b, 8, 0]), Err(Refusal::Compressed));
    }
}
