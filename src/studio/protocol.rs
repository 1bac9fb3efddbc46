//! What the studio's page asks for and what it gets back, without HTTP: run a
//! source to an SVG drawing with its diagnostics and statistics, drag a guide
//! vertex (mass-spring relaxation, then the incremental scene runner), write a
//! constant's value into the source, show the derived string of a step.
//!
//! Owns: the requests and replies (serde), and calling the library the way the
//! command line does (`lsyc run -o x.svg --guides` for a drawing, `lsyc edit`'s
//! solver and writer for a drag, `lsyc fmt`'s printer for every source it
//! writes). Must not touch files or sockets: `server` does that.

use super::layers::{LayerCache, Style};
use crate::ast::{ExprKind, File, Item};
use crate::check::{Checked, Override, Value};
use crate::diagnostic::{self, Diagnostic, Format};
use crate::env::{self, Runner};
use crate::lsp::analysis::Analysis;
use crate::run::{self, Options, OutputError, Picture, SceneRun};
use crate::{edit, fmt, frontend};
use serde::{Deserialize, Serialize};
use serde_json::Value as Json;
use std::collections::BTreeMap;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

/// The most bytes of a derived string the page is sent.
pub const STRING_LIMIT: usize = 200_000;

/// The studio's default module limit (`lsyc studio --max-modules`): far below
/// `lsyc run`'s, because every drawing goes to a browser as SVG and a run
/// holds the worker until it ends; a step beyond it is error E0903.
pub const MAX_MODULES: usize = 2_000_000;

/// What every request that runs the program carries.
#[derive(Clone, Debug, Default, Deserialize, PartialEq)]
pub struct Program {
    /// The program's text as the editor holds it.
    pub source: String,
    /// Constant overrides (`-D NAME=VALUE`), as the sliders set them.
    #[serde(default)]
    pub defines: BTreeMap<String, f64>,
    #[serde(default)]
    pub seed: u64,
    /// Derivation steps (`-n`); the program's `derive` when absent.
    #[serde(default)]
    pub step: Option<u32>,
    /// The camera of a 3D program (`--view AZ,EL`, degrees); the default
    /// view when absent.
    #[serde(default)]
    pub view: Option<[f64; 2]>,
    /// The module limit (the server's `--max-modules`; [`MAX_MODULES`] when
    /// absent). Not the page's to choose.
    #[serde(skip)]
    pub max_modules: Option<usize>,
    /// Set by the server when a newer request replaces this one: the
    /// derivation stops at its next step (error E0912). Not the page's.
    #[serde(skip)]
    pub cancel: Cancel,
}

/// A flag that stops a run between derivation steps (`derive::Limits::cancel`).
/// Two programs are the same whatever their flags.
#[derive(Clone, Copy, Debug, Default)]
pub struct Cancel(pub Option<&'static AtomicBool>);

impl PartialEq for Cancel {
    fn eq(&self, _: &Cancel) -> bool {
        true
    }
}

impl Program {
    fn overrides(&self) -> Vec<Override> {
        self.defines
            .iter()
            .map(|(name, v)| Override {
                name: name.clone(),
                value: fmt::format_number(*v),
            })
            .collect()
    }

    fn options(&self, steps: Option<u32>) -> Options {
        Options {
            steps,
            seed: self.seed,
            limits: crate::derive::Limits {
                max_modules: self.max_modules.unwrap_or(MAX_MODULES),
                cancel: self.cancel.0,
                ..crate::derive::Limits::default()
            },
            ..Options::default()
        }
    }

    fn picture(&self) -> Picture {
        Picture {
            view: self.view.filter(|v| v.iter().all(|a| a.is_finite())),
            ..Picture::default()
        }
    }

    /// Parses and checks the source, unless it is too large to run here.
    fn frontend(&self) -> frontend::Frontend {
        if let Some(d) = crate::lsp::analysis::too_large(&self.source) {
            return frontend::Frontend {
                file: File::default(),
                diagnostics: vec![d],
                checked: None,
            };
        }
        frontend::run_seeded(&self.source, Vec::new(), &self.overrides(), self.seed)
    }
}

/// A slider's constant: a numeric `const` with its value in the source.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct Constant {
    pub name: String,
    pub value: f64,
    /// Whether the source writes it as a plain number (an expression such as
    /// `2 * PI` is replaced by the number when a slider writes it).
    pub literal: bool,
}

/// A guide's outline, for the page's handles.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct GuideOutline {
    pub name: String,
    pub points: Vec<[f64; 2]>,
}

/// The reply to a run.
#[derive(Clone, Debug, Default, Serialize)]
pub struct RunReply {
    /// Whether the program ran to a drawing.
    pub ok: bool,
    /// The drawing, as `lsyc run -o x.svg --guides` writes it.
    pub svg: Option<String>,
    /// With an explicit step k ≥ 1: the drawing of step k − 1 (in the same
    /// coordinates), so that the page can mark what the last step added.
    pub previous_svg: Option<String>,
    /// Diagnostics as `--error-format json` writes them, each with `from` and
    /// `to`: its primary span in UTF-16 units (the editor's positions).
    pub diagnostics: Vec<Json>,
    /// `--stats` of the run, plus `check_ms` and `total_ms`.
    pub stats: Option<Json>,
    pub constants: Vec<Constant>,
    pub guides: Vec<GuideOutline>,
    pub is_scene: bool,
    /// Whether the program draws in 3D (then the page orbits its view).
    pub is_3d: bool,
    /// The source as `lsyc fmt` prints it (a drag or a slider writes this).
    pub formatted: Option<String>,
    /// Which guides a drag recomputed (the others came from the cache).
    pub recomputed: Vec<String>,
    /// A scene's drawing: a hash of each guide's layer
    /// (`<g class="guide-content" data-guide=…>`), by guide, so that the page
    /// can say which layers it already shows.
    pub layers: BTreeMap<String, String>,
    /// Instead of `svg` (a drag whose request said which layers the page
    /// has): the drawing's head, the layers that differ, and its tail.
    pub patch: Option<Patch>,
}

/// A scene's drawing as the layers that changed: `head`, then every guide's
/// layer in order (the page keeps the ones not sent), then `tail`, put
/// together, are byte for byte the SVG `lsyc run -o x.svg --guides` writes.
#[derive(Clone, Debug, Default, Serialize, PartialEq)]
pub struct Patch {
    /// Up to the first layer: the `<svg>` element with its view box, the
    /// group of shared styles, the elements' `<defs>`.
    pub head: String,
    /// Every layer in drawing order: its guide and, if the page does not
    /// have it yet, its text.
    pub layers: Vec<(String, Option<String>)>,
    /// After the last layer: the guide outlines, the links, the closing tags.
    pub tail: String,
}

/// The opening of a guide's layer in a scene's SVG.
const LAYER_START: &str = "<g class=\"guide-content\" data-guide=\"";

/// A scene's SVG in parts: its head, its layers (guide, text), its tail.
pub type Layers<'a> = (&'a str, Vec<(&'a str, &'a str)>, &'a str);

/// A scene's SVG split into its head, its layers (the guide's name as the
/// SVG writes it, XML-escaped, and the layer's text) and its tail; `None` if
/// the text is not in that shape.
pub fn split_layers(svg: &str) -> Option<Layers<'_>> {
    let first = svg.find(LAYER_START)?;
    let mut layers = Vec::new();
    let mut at = first;
    while svg[at..].starts_with(LAYER_START) {
        let name_start = at + LAYER_START.len();
        let name_end = name_start + svg[name_start..].find('"')?;
        // A layer holds paths and `<use>`s only: it ends at the next `</g>`.
        let end = at + svg[at..].find("</g>\n")? + "</g>\n".len();
        layers.push((&svg[name_start..name_end], &svg[at..end]));
        at = end;
    }
    Some((&svg[..first], layers, &svg[at..]))
}

/// A stable hash of bytes (FNV-1a, 64 bits) as hex.
pub fn hash(bytes: &[u8]) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in bytes {
        h ^= u64::from(*b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    format!("{h:016x}")
}

/// The hash of every layer of a scene's SVG, by guide.
fn layer_hashes(svg: &str) -> BTreeMap<String, String> {
    split_layers(svg).map_or_else(BTreeMap::new, |(_, layers, _)| {
        layers
            .into_iter()
            .map(|(name, text)| (name.to_string(), hash(text.as_bytes())))
            .collect()
    })
}

/// Diagnostics as the CLI's JSON lines, with UTF-16 positions for the editor.
pub fn diagnostics_json(diags: &[Diagnostic], name: &str, source: &str) -> Vec<Json> {
    let text = diagnostic::render(diags, name, source, Format::Json);
    text.lines()
        .filter_map(|l| serde_json::from_str::<Json>(l).ok())
        .zip(diags)
        .map(|(mut j, d)| {
            let span = d.labels.iter().find(|l| l.primary).map(|l| l.span);
            let (from, to) = span.map_or((0, 0), |s| {
                (
                    utf16_offset(source, s.start as usize),
                    utf16_offset(source, s.end as usize),
                )
            });
            j["from"] = Json::from(from);
            j["to"] = Json::from(to);
            j
        })
        .collect()
}

/// The UTF-16 offset of byte `offset` of `text` (clamped to the text).
pub fn utf16_offset(text: &str, offset: usize) -> usize {
    let mut o = offset.min(text.len());
    while !text.is_char_boundary(o) {
        o -= 1;
    }
    text[..o].chars().map(char::len_utf16).sum()
}

/// Whether the file holds a scene (then it runs as `lsyc run` runs a scene).
fn has_scene(file: &File) -> bool {
    file.items
        .stmts
        .iter()
        .any(|i| matches!(i.node, Item::Scene(_)))
}

/// The numeric constants of a checked file, in source order.
pub fn constants(file: &File, checked: &Checked) -> Vec<Constant> {
    file.items
        .stmts
        .iter()
        .filter_map(|i| match &i.node {
            Item::Const(c) => Some(c),
            _ => None,
        })
        .filter_map(|c| {
            let k = checked.consts.get(&c.name.name)?;
            match k.value {
                Value::Num(v) if !k.random && v.is_finite() => Some(Constant {
                    name: c.name.name.clone(),
                    value: v,
                    literal: matches!(c.value.kind, ExprKind::Num(_)),
                }),
                _ => None,
            }
        })
        .collect()
}

fn outlines(scene: &env::Scene) -> Vec<GuideOutline> {
    scene
        .guides
        .iter()
        .map(|g| GuideOutline {
            name: g.name.clone(),
            points: g.polygon.iter().map(|p| [p.x, p.y]).collect(),
        })
        .collect()
}

fn ms(since: Instant) -> f64 {
    (since.elapsed().as_secs_f64() * 1e6).round() / 1e3
}

/// Checks and runs `p` to an SVG drawing, as `lsyc run -o x.svg --guides`.
pub fn run(p: &Program, name: &str) -> RunReply {
    let start = Instant::now();
    let fe = p.frontend();
    let check_ms = ms(start);
    let mut reply = RunReply {
        diagnostics: diagnostics_json(&fe.diagnostics, name, &p.source),
        is_scene: has_scene(&fe.file),
        ..RunReply::default()
    };
    let Some(checked) = fe.checked.as_ref().filter(|_| !fe.has_errors()) else {
        return reply;
    };
    reply.constants = constants(&fe.file, checked);
    let drawn = if reply.is_scene {
        draw_scene(&fe.file, checked, p, p.step).map(|(svg, stats, guides)| {
            reply.guides = guides;
            (svg, stats)
        })
    } else {
        draw_system(&fe.file, checked, p, p.step).map(|(svg, stats, is_3d)| {
            reply.is_3d = is_3d;
            (svg, stats)
        })
    };
    let (svg, mut stats) = match drawn {
        Ok(v) => v,
        Err(d) => {
            reply
                .diagnostics
                .extend(diagnostics_json(&[d], name, &p.source));
            return reply;
        }
    };
    if let Some(k) = p.step.filter(|k| *k >= 1) {
        let previous = if reply.is_scene {
            draw_scene(&fe.file, checked, p, Some(k - 1)).map(|(svg, ..)| svg)
        } else {
            draw_system(&fe.file, checked, p, Some(k - 1)).map(|(svg, ..)| svg)
        };
        reply.previous_svg = previous.ok();
    }
    stats["check_ms"] = Json::from(check_ms);
    stats["total_ms"] = Json::from(ms(start));
    reply.ok = true;
    if reply.is_scene {
        reply.layers = layer_hashes(&svg);
    }
    reply.svg = Some(svg);
    reply.stats = Some(stats);
    reply
}

/// One lsystem to SVG: `run::derive` then `run::write_output`.
fn draw_system(
    file: &File,
    checked: &Checked,
    p: &Program,
    steps: Option<u32>,
) -> Result<(String, Json, bool), Diagnostic> {
    let derived = run::derive(file, checked, &p.options(steps), &|_, _| {})?;
    let start = Instant::now();
    let mut out = Vec::new();
    let drawn = run::write_output(&derived, run::Format::Svg, p.picture(), p.seed, &mut out)
        .map_err(output_diagnostic)?;
    let stats = run::Stats::new(&derived, &drawn, ms(start));
    Ok((
        String::from_utf8_lossy(&out).into_owned(),
        serde_json::to_value(stats).unwrap_or_default(),
        derived.prog.is_3d,
    ))
}

fn output_diagnostic(e: OutputError) -> Diagnostic {
    match e {
        OutputError::Diagnostic(d) => d,
        OutputError::Io(e) => Diagnostic::error(
            crate::diagnostic::Code::WriteOutput,
            format!("cannot draw: {e}"),
        ),
    }
}

/// A scene to SVG with its guides: `run::run_scene` then `run::write_scene`.
fn draw_scene(
    file: &File,
    checked: &Checked,
    p: &Program,
    steps: Option<u32>,
) -> Result<(String, Json, Vec<GuideOutline>), Diagnostic> {
    let r = run::run_scene(file, checked, None, &p.options(steps))?;
    let (svg, stats) = scene_svg(&r, p)?;
    Ok((svg, stats, outlines(&r.scene)))
}

fn scene_svg(r: &SceneRun, p: &Program) -> Result<(String, Json), Diagnostic> {
    let mut out = Vec::new();
    let stats = run::write_scene(
        r,
        Some(run::Format::Svg),
        p.picture(),
        p.seed,
        true,
        &mut out,
    )
    .map_err(output_diagnostic)?;
    Ok((
        String::from_utf8_lossy(&out).into_owned(),
        serde_json::to_value(stats).unwrap_or_default(),
    ))
}

/// Writes `value` as constant `name`'s value into the source, through the
/// formatter (comments kept). `None` if the source does not check or has no
/// such constant.
pub fn set_constant(source: &str, name: &str, value: f64) -> Option<String> {
    if crate::lsp::analysis::too_large(source).is_some() {
        return None;
    }
    let fe = frontend::run(source, Vec::new(), &[]);
    if fe.has_errors() || !value.is_finite() {
        return None;
    }
    let mut file = fe.file;
    let mut found = false;
    for item in &mut file.items.stmts {
        if let Item::Const(c) = &mut item.node
            && c.name.name == name
        {
            c.value.kind = ExprKind::Num(value);
            found = true;
        }
    }
    found.then(|| fmt::format_file(&file))
}

/// The derived string at the program's step (all systems of a scene, each
/// under its guide's name), cut at [`STRING_LIMIT`] bytes.
pub fn derived_string(p: &Program) -> Result<(String, bool), Vec<Json>> {
    let fe = p.frontend();
    let fail = |d: &[Diagnostic]| diagnostics_json(d, "", &p.source);
    let Some(checked) = fe.checked.as_ref().filter(|_| !fe.has_errors()) else {
        return Err(fail(&fe.diagnostics));
    };
    let mut out = Vec::new();
    if has_scene(&fe.file) {
        let r =
            run::run_scene(&fe.file, checked, None, &p.options(p.step)).map_err(|d| fail(&[d]))?;
        for inst in &r.outcome.instances {
            let g = &r.scene.guides[inst.guide];
            out.extend_from_slice(format!("// {}\n", g.name).as_bytes());
            let _ = crate::render::txt::write(&mut out, &r.scene.programs[g.program], &inst.string);
            if out.len() > STRING_LIMIT {
                break;
            }
        }
    } else {
        let d = run::derive(&fe.file, checked, &p.options(p.step), &|_, _| {})
            .map_err(|d| fail(&[d]))?;
        let _ = crate::render::txt::write(&mut out, &d.prog, &d.string);
    }
    let cut = out.len() > STRING_LIMIT;
    out.truncate(STRING_LIMIT);
    Ok((String::from_utf8_lossy(&out).into_owned(), cut))
}

/// A drag of one guide vertex.
#[derive(Clone, Debug, Default, Deserialize)]
pub struct Drag {
    #[serde(flatten)]
    pub program: Program,
    /// `GUIDE.vN`
    pub vertex: String,
    pub x: f64,
    pub y: f64,
    /// Pinned vertices (`GUIDE.vN`) or guides (`GUIDE`), held while the rest relaxes.
    #[serde(default)]
    pub pins: Vec<String>,
    /// Stiff springs between two vertices (`A.vI=B.vJ`, as `--stiff`).
    #[serde(default)]
    pub stiff: Vec<String>,
    /// The layers the page shows (guide → hash, as `RunReply::layers`):
    /// when given, the reply is a `patch` that leaves out the ones unchanged.
    #[serde(default)]
    pub have: Option<BTreeMap<String, String>>,
}

/// A scene being dragged: the program as it was when the drag began, and the
/// incremental runner that keeps every guide's result until its inputs change.
pub struct DragSession {
    base: Program,
    file: File,
    checked: Checked,
    runner: Runner,
    /// Every guide's drawing, kept while its systems do not change.
    layers: LayerCache,
}

impl DragSession {
    /// Starts a drag of the scene in `p` (its first scene).
    pub fn new(p: &Program) -> Result<DragSession, String> {
        let fe = p.frontend();
        let checked = match fe.checked {
            Some(c) if !c.has_errors() && !fe.diagnostics.iter().any(Diagnostic::is_error) => c,
            _ => return Err("the program has errors; fix them before dragging".to_string()),
        };
        let scene = env::build(&fe.file, &checked, None).map_err(|e| e.to_string())?;
        let opts = p.options(p.step);
        let cfg = env::Config {
            seed: p.seed,
            limits: opts.limits,
            cap: p
                .step
                .unwrap_or(env::MAX_SCENE_STEPS)
                .min(env::MAX_SCENE_STEPS),
        };
        Ok(DragSession {
            base: p.clone(),
            file: fe.file,
            checked,
            runner: Runner::new(scene, cfg),
            layers: LayerCache::default(),
        })
    }

    /// Whether this session was started from `p` (same text, constants, seed, step).
    pub fn matches(&self, p: &Program) -> bool {
        self.base == *p
    }

    /// Moves the vertex, relaxes the guides, reruns what changed and draws.
    pub fn drag(&mut self, d: &Drag, name: &str) -> Result<RunReply, String> {
        let start = Instant::now();
        // This move's stop flag (the worker running it), not the first move's.
        self.runner.cfg.limits.cancel = d.program.cancel.0;
        let mut ops = vec![edit::Op::Move(
            edit::parse_vertex(&d.vertex)?,
            glam::DVec2::new(d.x, d.y),
        )];
        for pin in &d.pins {
            ops.push(edit::parse_pin(pin)?);
        }
        for pair in &d.stiff {
            ops.push(edit::parse_stiff(pair)?);
        }
        let mut file = self.file.clone();
        // Seeds go along with their guides (`--move-seeds`): a plant stays
        // rooted in the guide a person drags.
        let options = edit::Options {
            scene: None,
            move_seeds: true,
        };
        edit::edit(&mut file, &self.checked, &ops, &options).map_err(|e| match e {
            edit::EditError::Input(m) | edit::EditError::Usage(m, _) => m,
        })?;
        let springs_ms = ms(start);
        let text = fmt::format_file(&file);
        let moved = Program {
            source: text.clone(),
            ..self.base.clone()
        };
        let fe = moved.frontend();
        let checked = fe
            .checked
            .as_ref()
            .filter(|_| !fe.has_errors())
            .ok_or_else(|| "the moved guides do not check".to_string())?;
        let scene = env::build(&fe.file, checked, None).map_err(|e| e.to_string())?;
        for (g, new) in self.runner.scene.guides.iter_mut().zip(scene.guides) {
            g.polygon = new.polygon;
            g.seeds = new.seeds;
        }
        let solved_ms = ms(start);
        let check_ms = solved_ms - springs_ms;
        let outcome = match self.runner.run() {
            Ok(o) => o,
            Err(d) => {
                self.layers.clear();
                return Err(d.message);
            }
        };
        let derive_ms = ms(start) - solved_ms;
        let scene = &self.runner.scene;
        let style = Style {
            seed: self.base.seed,
            limits: self.runner.cfg.limits,
            view: self
                .base
                .picture()
                .view(scene.programs.iter().any(|p| p.is_3d)),
        };
        let drawing =
            match self
                .layers
                .draw(scene, &outcome, &self.runner.recomputed, style, derive_ms)
            {
                Ok(d) => d,
                Err(d) => {
                    self.layers.clear();
                    return Err(d.message);
                }
            };
        let guides = outlines(scene);
        let mut stats = serde_json::to_value(&drawing.stats).unwrap_or_default();
        let round = |v: f64| (v * 1e3).round() / 1e3;
        stats["solve_ms"] = Json::from(round(springs_ms));
        stats["check_ms"] = Json::from(round(check_ms));
        let recomputed = scene
            .guides
            .iter()
            .zip(&self.runner.recomputed)
            .filter(|(_, r)| **r)
            .map(|(g, _)| g.name.clone())
            .collect();
        let layers: BTreeMap<String, String> = drawing
            .layers
            .iter()
            .map(|(name, _, hash)| (name.clone(), hash.to_string()))
            .collect();
        let (svg, patch) = match d.have.as_ref().filter(|_| !drawing.layers.is_empty()) {
            Some(have) => (
                None,
                Some(Patch {
                    head: drawing.head.clone(),
                    layers: drawing
                        .layers
                        .iter()
                        .map(|(name, text, hash)| {
                            let kept = have.get(name).is_some_and(|h| h == hash);
                            (name.clone(), (!kept).then(|| text.to_string()))
                        })
                        .collect(),
                    tail: drawing.tail.clone(),
                }),
            ),
            None => (Some(drawing.svg()), None),
        };
        stats["total_ms"] = Json::from(ms(start));
        Ok(RunReply {
            ok: true,
            svg,
            patch,
            layers,
            diagnostics: diagnostics_json(&fe.diagnostics, name, &text),
            stats: Some(stats),
            constants: constants(&fe.file, checked),
            guides,
            is_scene: true,
            formatted: Some(text),
            recomputed,
            ..RunReply::default()
        })
    }
}

/// The formats the page can export the drawing to (`lsyc run -o x.EXT`).
pub fn export_format(ext: &str) -> Option<(run::Format, &'static str)> {
    Some(match ext {
        "svg" => (run::Format::Svg, "image/svg+xml"),
        "png" => (run::Format::Png, "image/png"),
        "obj" => (run::Format::Obj, "text/plain"),
        "glb" => (run::Format::Glb, "model/gltf-binary"),
        _ => return None,
    })
}

/// The program drawn as `lsyc run -o x.EXT` writes it (a scene with its
/// guides, as `--guides`, in SVG and PNG), or what is wrong.
pub fn export(p: &Program, ext: &str) -> Result<Vec<u8>, String> {
    let (format, _) = export_format(ext).ok_or_else(|| format!("cannot export to .{ext}"))?;
    let fe = p.frontend();
    let Some(checked) = fe.checked.as_ref().filter(|_| !fe.has_errors()) else {
        return Err("the program has errors; fix them before exporting".to_string());
    };
    let mut out = Vec::new();
    let failed = |e: OutputError| output_diagnostic(e).message;
    if has_scene(&fe.file) {
        let r =
            run::run_scene(&fe.file, checked, None, &p.options(p.step)).map_err(|d| d.message)?;
        run::write_scene(&r, Some(format), p.picture(), p.seed, true, &mut out).map_err(failed)?;
    } else {
        let d = run::derive(&fe.file, checked, &p.options(p.step), &|_, _| {})
            .map_err(|d| d.message)?;
        run::write_output(&d, format, p.picture(), p.seed, &mut out).map_err(failed)?;
    }
    Ok(out)
}

/// The byte offset of UTF-16 offset `at` of `text` (clamped to the text).
pub fn byte_offset(text: &str, at: usize) -> usize {
    let mut units = 0;
    for (i, c) in text.char_indices() {
        if units >= at {
            return i;
        }
        units += c.len_utf16();
    }
    text.len()
}

/// The language server's hover at UTF-16 offset `at` (`lsyc lsp`'s own
/// answer): its Markdown text and the span it is about, in UTF-16 units.
pub fn hover(source: &str, at: usize) -> Option<Json> {
    hover_in(&Analysis::new(source.to_string()), at)
}

/// [`hover`] in an analysis already made (the server shares one between the
/// questions about one text).
pub fn hover_in(a: &Analysis, at: usize) -> Option<Json> {
    let source = a.text.as_str();
    let h = crate::lsp::hover::hover(a, byte_offset(source, at))?;
    let text = match h.contents {
        lsp_types::HoverContents::Markup(m) => m.value,
        lsp_types::HoverContents::Scalar(lsp_types::MarkedString::String(s)) => s,
        lsp_types::HoverContents::Scalar(lsp_types::MarkedString::LanguageString(l)) => l.value,
        lsp_types::HoverContents::Array(_) => return None,
    };
    let (from, to) = h.range.map_or((at, at), |r| {
        (
            utf16_offset(source, a.offset(r.start)),
            utf16_offset(source, a.offset(r.end)),
        )
    });
    Some(serde_json::json!({ "text": text, "from": from, "to": to }))
}

/// The language server's completions at UTF-16 offset `at` (`lsyc lsp`'s
/// own list): label, kind, detail, documentation, the text to insert and
/// the span it replaces (UTF-16 units).
pub fn complete(source: &str, at: usize) -> Vec<Json> {
    complete_in(&Analysis::new(source.to_string()), at)
}

/// [`complete`] in an analysis already made.
pub fn complete_in(a: &Analysis, at: usize) -> Vec<Json> {
    let source = a.text.as_str();
    crate::lsp::complete::complete(a, byte_offset(source, at))
        .into_iter()
        .map(|c| {
            let (insert, from, to) = match &c.text_edit {
                Some(lsp_types::CompletionTextEdit::Edit(e)) => (
                    e.new_text.clone(),
                    utf16_offset(source, a.offset(e.range.start)),
                    utf16_offset(source, a.offset(e.range.end)),
                ),
                _ => (
                    c.insert_text.clone().unwrap_or_else(|| c.label.clone()),
                    at,
                    at,
                ),
            };
            let doc = match &c.documentation {
                Some(lsp_types::Documentation::String(s)) => s.clone(),
                Some(lsp_types::Documentation::MarkupContent(m)) => m.value.clone(),
                None => String::new(),
            };
            serde_json::json!({
                "label": c.label,
                "kind": c.kind.map(|k| format!("{k:?}").to_lowercase()),
                "detail": c.detail,
                "doc": doc,
                "insert": insert,
                "sort": c.sort_text,
                "from": from,
                "to": to,
            })
        })
        .collect()
}
