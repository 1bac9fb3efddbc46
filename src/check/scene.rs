//! Checks of `element` items (properties, SVG path data) and `scene` items
//! (guides, polygons, systems, seeds, links).

use super::expr::{Env, Ty, plural};
use super::{Checker, duplicate, suggest};
use crate::ast::{EdgeRef, Element, GuideStmt, LinkStmt, Palette, PropValue, Scene, SceneStmt};
use crate::diagnostic::{Code, Diagnostic};
use crate::span::Span;
use std::collections::HashMap;

const PROPS: &[(&str, bool)] = &[
    ("path", true),
    ("fill", true),
    ("stroke", true),
    ("width", false),
    ("sphere", false),
    ("disk", false),
    ("mesh", true),
    ("patch", true),
    ("contour", true),
];

/// The properties that give an element its shape: exactly one of them.
const SHAPES: &[&str] = &["path", "sphere", "disk", "mesh", "patch", "contour"];

/// A guide's `system`: where it is named, and its lsystem's parameter count
/// when that lsystem exists.
type SystemRef = Option<(Span, Option<usize>)>;

impl<'a> Checker<'a> {
    pub(super) fn element(&mut self, e: &'a Element) {
        let mut seen: HashMap<&str, Span> = HashMap::new();
        for p in &e.props.stmts {
            let key = p.node.key.name.as_str();
            if key.is_empty() {
                continue; // a property the parser skipped
            }
            let Some(&(_, wants_string)) = PROPS.iter().find(|(k, _)| *k == key) else {
                let mut d = Diagnostic::error(
                    Code::UnknownProperty,
                    format!("elements have no property `{key}`"),
                )
                .primary(p.node.key.span, "unknown property");
                let synonym = match key {
                    "color" | "colour" => Some("fill"),
                    "d" | "data" => Some("path"),
                    "stroke_width" | "thickness" => Some("width"),
                    _ => None,
                };
                if let Some(s) = synonym.or_else(|| suggest(key, PROPS.iter().map(|(k, _)| *k))) {
                    d = d.did_you_mean(p.node.key.span, s);
                } else {
                    d = d.note("the properties are path, sphere, disk, mesh, patch, contour, fill, stroke and width");
                }
                self.diags.push(d);
                continue;
            };
            if let Some(first) = seen.get(key) {
                self.diags.push(
                    Diagnostic::error(Code::DuplicateSetting, format!("`{key}` is given twice"))
                        .primary(p.node.key.span, "given again here")
                        .secondary(*first, "first given here")
                        .help("keep one of them"),
                );
                continue;
            }
            if SHAPES.contains(&key)
                && let Some((other, span)) = seen
                    .iter()
                    .find(|(k, _)| SHAPES.contains(k))
                    .map(|(k, s)| (*k, *s))
            {
                self.diags.push(
                    Diagnostic::error(
                        Code::TwoShapes,
                        format!("element `{}` has both `{other}` and `{key}`", e.name.name),
                    )
                    .primary(p.node.key.span, "a second shape")
                    .secondary(span, "the first shape")
                    .help("declare one element per shape, and print them one after the other"),
                );
            }
            seen.insert(key, p.node.key.span);
            match (&p.node.value, wants_string) {
                (PropValue::Str(s, span), true) => match key {
                    "path" => self.path_data(s, *span),
                    "contour" => {
                        self.path_data(s, *span);
                        if crate::path::parse(s).is_ok()
                            && let Err(why) = crate::organ::contour_from_path(s)
                        {
                            self.diags.push(
                                Diagnostic::error(Code::BadOrgan, "this path is not a contour")
                                    .primary(*span, why)
                                    .help("a contour is one closed outline around the branch's axis, e.g. \"M1 0 L0 1 L-1 0 L0 -1 Z\""),
                            );
                        }
                    }
                    "patch" => match crate::organ::patch_numbers(s) {
                        Err(why) => self.diags.push(
                            Diagnostic::error(Code::BadOrgan, "patch data that is not numbers")
                                .primary(*span, why)
                                .help("write the 16 control points of each patch as x y z numbers"),
                        ),
                        Ok(n) if n.is_empty() || n.len() % 48 != 0 => self.diags.push(
                            Diagnostic::error(
                                Code::BadOrgan,
                                format!(
                                    "a patch needs 48 numbers (16 points x y z); this has {}",
                                    n.len()
                                ),
                            )
                            .primary(*span, "not a whole number of patches")
                            .help("each bicubic patch is 4 rows of 4 control points, 48 numbers"),
                        ),
                        Ok(_) => {}
                    },
                    "mesh" => {
                        if s.trim().is_empty() {
                            self.diags.push(
                                Diagnostic::error(Code::BadOrgan, "the mesh file is not named")
                                    .primary(*span, "an empty file name")
                                    .help(
                                        "name an OBJ file beside the program: mesh \"leaf.obj\";",
                                    ),
                            );
                        }
                    }
                    _ => {
                        if s.parse::<svgtypes::Color>().is_err() && s != "none" {
                            self.diags.push(
                                Diagnostic::error(Code::PropertyKind, format!("`{s}` is not a colour"))
                                    .primary(*span, "not an SVG colour")
                                    .help("use a name such as \"green\", \"#3a7\" or \"rgb(40, 120, 60)\""),
                            );
                        }
                    }
                },
                (PropValue::Expr(x), false) if key != "width" => {
                    if let Some(v) = self.const_num(x, "a radius")
                        && (v <= 0.0 || v.is_nan())
                    {
                        self.diags.push(
                            Diagnostic::error(
                                Code::BadOrgan,
                                format!("a {key}'s radius must be positive"),
                            )
                            .primary(x.span, format!("this is {v}")),
                        );
                    }
                }
                (PropValue::Expr(x), false) => {
                    if let Some(v) = self.const_num(x, "the width")
                        && v < 0.0
                    {
                        self.diags.push(
                            Diagnostic::error(Code::OutOfRange, "a width must be zero or positive")
                                .primary(x.span, format!("this is {v}")),
                        );
                    }
                }
                (PropValue::Expr(x), true) => self.diags.push(
                    Diagnostic::error(Code::PropertyKind, format!("`{key}` takes a string"))
                        .primary(x.span, "not a string")
                        .help(format!("write it in quotes: {key} \"…\";")),
                ),
                (PropValue::Str(_, span), false) => self.diags.push(
                    Diagnostic::error(Code::PropertyKind, format!("`{key}` takes a number"))
                        .primary(*span, "a string")
                        .help(format!("write a number: {key} 1.5;")),
                ),
            }
        }
        if !SHAPES.iter().any(|k| seen.contains_key(k)) {
            self.diags.push(
                Diagnostic::error(
                    Code::MissingPath,
                    format!("element `{}` has no shape", e.name.name),
                )
                .primary(e.name.span, "an element draws a shape")
                .help(
                    "add `path \"M0 0 L0 10\";` (local frame: base at the origin, pointing +y), \
                     or a 3D organ: `sphere 1;`, `disk 1;`, `patch \"…\";`, `mesh \"leaf.obj\";`",
                ),
            );
        }
    }

    /// A palette's entries: whole indices 0–255, each once; SVG colours;
    /// material names each once.
    pub(super) fn palette(&mut self, p: &'a Palette) {
        let mut indices: HashMap<i64, Span> = HashMap::new();
        let mut names: HashMap<&str, Span> = HashMap::new();
        for n in &p.body.stmts {
            let e = &n.node;
            if matches!(e.index.kind, crate::ast::ExprKind::Error) {
                continue;
            }
            if let Some(v) = self.const_num(&e.index, "a colour index") {
                if !(v.fract() == 0.0 && (0.0..=255.0).contains(&v)) {
                    self.diags.push(
                        Diagnostic::error(
                            Code::OutOfRange,
                            "a colour index is a whole number from 0 to 255",
                        )
                        .primary(e.index.span, format!("this is {v}")),
                    );
                } else if let Some(first) = indices.insert(v as i64, e.index.span) {
                    self.diags.push(
                        Diagnostic::error(
                            Code::DuplicateSetting,
                            format!("colour {v} is given twice"),
                        )
                        .primary(e.index.span, "given again here")
                        .secondary(first, "first given here")
                        .help("keep one of them"),
                    );
                }
            }
            if e.color.parse::<svgtypes::Color>().is_err() {
                self.diags.push(
                    Diagnostic::error(Code::PropertyKind, format!("`{}` is not a colour", e.color))
                        .primary(e.color_span, "not an SVG colour")
                        .help("use a name such as \"green\", \"#3a7\" or \"rgb(40, 120, 60)\""),
                );
            }
            if let Some(name) = &e.name
                && let Some(first) = names.insert(&name.name, name.span)
            {
                self.diags
                    .push(duplicate("material", &name.name, name.span, first));
            }
        }
    }

    fn path_data(&mut self, s: &str, span: Span) {
        match crate::path::parse(s) {
            Err(e) => {
                // The string starts after its quote; escapes shift the source.
                let place = e
                    .offset
                    .and_then(|b| Some((b, s.get(b..)?.chars().next()?)))
                    .filter(|_| !s.contains('\\'))
                    .map_or(span, |(b, c)| {
                        let start = span.start as usize + 1 + b;
                        Span::new(start, start + c.len_utf8())
                    });
                self.diags.push(
                    Diagnostic::error(Code::InvalidPath, "invalid SVG path data")
                        .primary(place, e.to_string())
                        .help("path data is SVG's `d` attribute: commands M L H V C S Q T A Z with numbers"),
                );
            }
            Ok(path) if path.elements().is_empty() => self.diags.push(
                Diagnostic::error(Code::InvalidPath, "the path is empty")
                    .primary(span, "no drawing commands")
                    .help("start with a move, e.g. \"M0 0 L0 10\""),
            ),
            Ok(_) => {}
        }
    }

    pub(super) fn scene(&mut self, s: &'a Scene) {
        // Guides first, so links may refer to guides declared after them.
        let mut guides: HashMap<&str, (Span, Option<usize>)> = HashMap::new();
        for st in &s.body.stmts {
            let SceneStmt::Guide(g) = &st.node else {
                continue;
            };
            if let Some((first, _)) = guides.get(g.name.name.as_str()) {
                self.diags
                    .push(duplicate("guide", &g.name.name, g.name.span, *first));
                continue;
            }
            let (polygon, system) = self.guide_settings(g);
            self.seeds(g, system);
            self.guide_complete(g, polygon.is_some(), system.is_some());
            guides.insert(
                &g.name.name,
                (polygon.map_or(g.name.span, |p| p.0), polygon.map(|p| p.1)),
            );
        }
        for st in &s.body.stmts {
            if let SceneStmt::Link(l) = &st.node {
                self.link(l, &guides);
            }
        }
    }

    /// A guide's polygon (its span and vertex count) and system (its span and
    /// parameter count, when the lsystem exists).
    fn guide_settings(&mut self, g: &'a crate::ast::Guide) -> (Option<(Span, usize)>, SystemRef) {
        let mut polygon: Option<(Span, usize)> = None;
        let mut system: SystemRef = None;
        for gs in &g.body.stmts {
            match &gs.node {
                GuideStmt::Polygon(pts) => {
                    if let Some((first, _)) = polygon {
                        self.setting_twice("polygon", gs.span, first);
                        continue;
                    }
                    for p in pts {
                        self.const_num(&p.x, "a polygon coordinate");
                        self.const_num(&p.y, "a polygon coordinate");
                    }
                    if pts.len() < 3 {
                        self.diags.push(
                            Diagnostic::error(
                                Code::PolygonTooSmall,
                                format!(
                                    "a guide polygon needs at least 3 vertices, this one has {}",
                                    pts.len()
                                ),
                            )
                            .primary(gs.span, "too few vertices")
                            .help("list the corners in order: polygon (0, 0) (10, 0) (10, 10);"),
                        );
                    }
                    polygon = Some((gs.span, pts.len()));
                }
                GuideStmt::System(name) => {
                    if let Some((first, _)) = system {
                        self.setting_twice("system", gs.span, first);
                        continue;
                    }
                    let params = match self.systems.get(name.name.as_str()) {
                        Some(&(_, n)) => {
                            self.used_systems.insert(name.name.clone());
                            Some(n)
                        }
                        None => {
                            let mut d = Diagnostic::error(
                                Code::UnknownSystem,
                                format!("there is no lsystem `{}`", name.name),
                            )
                            .primary(name.span, "not defined in this file");
                            if let Some(sg) = suggest(&name.name, self.systems.keys().copied()) {
                                d = d.did_you_mean(name.span, sg);
                            }
                            self.diags.push(d);
                            None
                        }
                    };
                    system = Some((name.span, params));
                }
                GuideStmt::Seed(_) | GuideStmt::Error => {}
            }
        }
        (polygon, system)
    }

    /// A guide's seeds, now that its system's parameters are known.
    fn seeds(&mut self, g: &'a crate::ast::Guide, system: SystemRef) {
        for gs in &g.body.stmts {
            let GuideStmt::Seed(seed) = &gs.node else {
                continue;
            };
            self.const_num(&seed.at.x, "a seed coordinate");
            self.const_num(&seed.at.y, "a seed coordinate");
            if let Some(h) = &seed.heading {
                self.const_num(h, "a seed heading");
            }
            let given = seed.args.as_ref().map_or(0, Vec::len);
            for a in seed.args.iter().flatten() {
                if self.expect(a, &Env::new(), Ty::Num) == Ty::Num {
                    self.record_value(a);
                }
            }
            if let Some((sys_span, Some(want))) = system
                && given != want
            {
                self.diags.push(
                        Diagnostic::error(
                            Code::SeedArguments,
                            format!("this seed passes {given} value{}, but the guide's lsystem takes {want}", plural(given)),
                        )
                        .primary(gs.span, format!("{given} passed"))
                        .secondary(sys_span, format!("this lsystem has {want} parameter{}", plural(want)))
                        .help(if want == 0 {
                            "remove `with (…)`".to_string()
                        } else {
                            format!("pass them with `with (…)`: {want} value{}", plural(want))
                        }),
                    );
            }
        }
    }

    fn guide_complete(&mut self, g: &crate::ast::Guide, has_polygon: bool, has_system: bool) {
        let mut missing = Vec::new();
        if !has_polygon {
            missing.push("a `polygon`");
        }
        if !has_system {
            missing.push("a `system`");
        }
        if !missing.is_empty() {
            self.diags.push(
                Diagnostic::error(
                    Code::GuideIncomplete,
                    format!("guide `{}` has no {}", g.name.name, missing.join(" and no ").trim_start_matches("a ")),
                )
                .primary(g.name.span, format!("needs {}", missing.join(" and ")))
                .help("a guide is a polygon hosting one lsystem: `polygon (0, 0) (10, 0) (10, 10); system Name;`"),
            );
        }
    }

    fn link(&mut self, l: &crate::ast::Link, guides: &HashMap<&str, (Span, Option<usize>)>) {
        self.edge_ref(&l.from, guides);
        self.edge_ref(&l.to, guides);
        let mut seen: HashMap<&str, Span> = HashMap::new();
        for ls in &l.body.stmts {
            let (key, e) = match &ls.node {
                LinkStmt::Tokens(e) => ("tokens", e),
                LinkStmt::Heading(e) => ("heading", e),
                LinkStmt::Setting(k, e) => (k.name.as_str(), e),
                LinkStmt::Error => continue,
            };
            if let LinkStmt::Setting(k, _) = &ls.node
                && !LINK_SETTINGS.contains(&key)
            {
                self.diags.push(
                    Diagnostic::error(Code::LinkSetting, format!("a link has no setting `{key}`"))
                        .primary(k.span, "not a link setting")
                        .help("a link takes `tokens n;`, `heading a;` or `heading continue;`, `aim middle;` and `take v;`"),
                );
                continue;
            }
            if let Some(first) = seen.get(key) {
                self.setting_twice(key, ls.span, *first);
                continue;
            }
            seen.insert(key, ls.span);
            match key {
                "tokens" => {
                    self.const_int(e, "a token count", 0.0, 1e9);
                }
                "heading" if link_word(e) == Some("continue") => {}
                "aim" => {
                    if !matches!(link_word(e), Some("middle" | "closest")) {
                        self.diags.push(
                            Diagnostic::error(
                                Code::LinkSetting,
                                "`aim` takes `middle` or `closest`",
                            )
                            .primary(e.span, "not `middle` or `closest`"),
                        );
                    }
                }
                "take" => {
                    self.const_num(e, "a link's `take` value");
                }
                _ => {
                    self.const_num(e, "a link heading");
                }
            }
        }
    }

    fn setting_twice(&mut self, key: &str, span: Span, first: Span) {
        self.diags.push(
            Diagnostic::error(Code::DuplicateSetting, format!("`{key}` is given twice"))
                .primary(span, "given again here")
                .secondary(first, "first given here")
                .help("keep one of them"),
        );
    }

    fn edge_ref(&mut self, r: &EdgeRef, guides: &HashMap<&str, (Span, Option<usize>)>) {
        let Some(&(gspan, edges)) = guides.get(r.guide.name.as_str()) else {
            let mut d = Diagnostic::error(
                Code::UnknownGuide,
                format!("there is no guide `{}` in this scene", r.guide.name),
            )
            .primary(r.guide.span, "unknown guide");
            if let Some(s) = suggest(&r.guide.name, guides.keys().copied()) {
                d = d.did_you_mean(r.guide.span, s);
            }
            self.diags.push(d);
            return;
        };
        let Some(n) = edges else {
            self.const_num(&r.index, "an edge index");
            return;
        };
        let Some(i) = self.const_int(&r.index, "an edge index", 0.0, 1e9) else {
            return;
        };
        if i as usize >= n {
            self.diags.push(
                Diagnostic::error(
                    Code::EdgeOutOfRange,
                    format!(
                        "guide `{}` has {n} edges, numbered 0 to {}",
                        r.guide.name,
                        n.saturating_sub(1)
                    ),
                )
                .primary(r.index.span, format!("edge {i} does not exist"))
                .secondary(gspan, format!("its polygon has {n} vertices"))
                .note("edge i joins vertex i to vertex i + 1; the last edge closes the polygon"),
            );
        }
    }
}

/// The named settings a link takes besides `tokens` and `heading`.
const LINK_SETTINGS: &[&str] = &["aim", "take"];

/// A link setting's value written as a bare word (`continue`, `middle`); in
/// these places a word is never read as a constant.
fn link_word(e: &crate::ast::Expr) -> Option<&str> {
    match &e.kind {
        crate::ast::ExprKind::Var(n) => Some(n.as_str()),
        _ => None,
    }
}
