//! What the studio's page asks for and what it gets back, without HTTP: run a
//! source to an SVG drawing with its diagnostics and statistics, drag a guide
//! vertex (mass-spring relaxation, then the incremental scene runner), write a
//! constant's value into the source, show the derived string of a step.
//!
//! Owns: the requests and replies (serde), and calling the library the way the
//! command line does (`lsyc run -o x.svg --guides` for a drawing, `lsyc edit`'s
//! solver and writer for a drag, `lsyc fmt`'s printer for every source it
//! writes). Must not touch files or sockets: `server` does that.

use crate::ast::{ExprKind, File, Item};
use crate::check::{Checked, Override, Value};
use crate::diagnostic::{self, Diagnostic, Format};
use crate::env::{self, Runner};
use crate::run::{self, Options, OutputError, Picture, SceneRun};
use crate::{edit, fmt, frontend};
use serde::{Deserialize, Serialize};
use serde_json::Value as Json;
use std::collections::BTreeMap;
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
    /// The module limit (the server's `--max-modules`; [`MAX_MODULES`] when
    /// absent). Not the page's to choose.
    #[serde(skip)]
    pub max_modules: Option<usize>,
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
                ..crate::derive::Limits::default()
            },
            ..Options::default()
        }
    }

    fn frontend(&self) -> frontend::Frontend {
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
    /// The source as `lsyc fmt` prints it (a drag or a slider writes this).
    pub formatted: Option<String>,
    /// Which guides a drag recomputed (the others came from the cache).
    pub recomputed: Vec<String>,
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
        draw_system(&fe.file, checked, p, p.step)
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
            draw_system(&fe.file, checked, p, Some(k - 1)).map(|(svg, _)| svg)
        };
        reply.previous_svg = previous.ok();
    }
    stats["check_ms"] = Json::from(check_ms);
    stats["total_ms"] = Json::from(ms(start));
    reply.ok = true;
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
) -> Result<(String, Json), Diagnostic> {
    let derived = run::derive(file, checked, &p.options(steps), &|_, _| {})?;
    let start = Instant::now();
    let mut out = Vec::new();
    let drawn = run::write_output(
        &derived,
        run::Format::Svg,
        Picture::default(),
        p.seed,
        &mut out,
    )
    .map_err(output_diagnostic)?;
    let stats = run::Stats::new(&derived, &drawn, ms(start));
    Ok((
        String::from_utf8_lossy(&out).into_owned(),
        serde_json::to_value(stats).unwrap_or_default(),
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
    let (svg, stats) = scene_svg(&r, p.seed)?;
    Ok((svg, stats, outlines(&r.scene)))
}

fn scene_svg(r: &SceneRun, seed: u64) -> Result<(String, Json), Diagnostic> {
    let mut out = Vec::new();
    let stats = run::write_scene(
        r,
        Some(run::Format::Svg),
        Picture::default(),
        seed,
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
#[derive(Clone, Debug, Deserialize)]
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
}

/// A scene being dragged: the program as it was when the drag began, and the
/// incremental runner that keeps every guide's result until its inputs change.
pub struct DragSession {
    base: Program,
    file: File,
    checked: Checked,
    runner: Runner,
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
        })
    }

    /// Whether this session was started from `p` (same text, constants, seed, step).
    pub fn matches(&self, p: &Program) -> bool {
        self.base == *p
    }

    /// Moves the vertex, relaxes the guides, reruns what changed and draws.
    pub fn drag(&mut self, d: &Drag, name: &str) -> Result<RunReply, String> {
        let start = Instant::now();
        let mut ops = vec![edit::Op::Move(
            edit::parse_vertex(&d.vertex)?,
            glam::DVec2::new(d.x, d.y),
        )];
        for pin in &d.pins {
            ops.push(edit::parse_pin(pin)?);
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
        let outcome = self.runner.run().map_err(|d| d.message)?;
        let placeholder = env::Scene {
            name: String::new(),
            guides: Vec::new(),
            links: Vec::new(),
            programs: Vec::new(),
        };
        let r = SceneRun {
            scene: std::mem::replace(&mut self.runner.scene, placeholder),
            outcome,
            derive_ms: ms(start) - solved_ms,
            limits: self.runner.cfg.limits,
        };
        let drawn = scene_svg(&r, self.base.seed);
        let guides = outlines(&r.scene);
        self.runner.scene = r.scene;
        let (svg, mut stats) = drawn.map_err(|d| d.message)?;
        let round = |v: f64| (v * 1e3).round() / 1e3;
        stats["solve_ms"] = Json::from(round(springs_ms));
        stats["check_ms"] = Json::from(round(check_ms));
        stats["total_ms"] = Json::from(ms(start));
        let recomputed = self
            .runner
            .scene
            .guides
            .iter()
            .zip(&self.runner.recomputed)
            .filter(|(_, r)| **r)
            .map(|(g, _)| g.name.clone())
            .collect();
        Ok(RunReply {
            ok: true,
            svg: Some(svg),
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
