//! Running a checked program: compile, derive, interpret, write an output.
//!
//! Owns: the order of the execution phases, their timings for `--stats`, and the
//! diagnostics of runtime failures (each with the step and the source span of
//! the expression that failed). The CLI and the tests call this; it does no
//! argument parsing and writes only to the writers it is given.

use crate::ast::File;
use crate::check::Checked;
use crate::compile::{self, Action, Program};
use crate::derive::{self, Limits, ModString};
use crate::diagnostic::{Code, Diagnostic};
use crate::render::{self, Bounds, BoundsSink, View};
use crate::turtle::{self, Drawn};
use rayon::prelude::*;
use serde::Serialize;
use std::io::Write;
use std::time::Instant;

#[derive(Clone, Debug, Default)]
pub struct Options {
    /// Derivation steps; the program's `derive` when `None`.
    pub steps: Option<u32>,
    pub seed: u64,
    pub limits: Limits,
    /// The lsystem to run; the first one when `None`.
    pub system: Option<String>,
    /// The program's directory, where `mesh` files are found (the current
    /// directory when `None`).
    pub base_dir: Option<std::path::PathBuf>,
}

/// A derived program.
pub struct Derived {
    pub prog: Program,
    pub string: ModString,
    pub steps: u32,
    pub derive_ms: f64,
    /// The limits of the run, which interpretation honours too.
    pub limits: Limits,
}

impl Derived {
    /// Interprets the derived string into `sink`, within the run's limits.
    pub fn interpret(&self, seed: u64, sink: &mut dyn turtle::Sink) -> Result<Drawn, Diagnostic> {
        turtle::interpret_limited(
            &self.prog,
            &self.string,
            seed,
            turtle::State::default(),
            self.limits,
            sink,
        )
        .map_err(|e| e.diagnostic(&self.prog))
    }
}

/// Compiles and derives. `progress(step, modules)` is called after each step.
pub fn derive(
    file: &File,
    checked: &Checked,
    opts: &Options,
    progress: &(dyn Fn(u32, usize) + Sync),
) -> Result<Derived, Diagnostic> {
    let prog =
        compile::compile(file, checked, opts.system.as_deref()).map_err(|e| e.diagnostic())?;
    let mut prog = prog;
    load_meshes(&mut prog, opts.base_dir.as_deref())?;
    let steps = opts.steps.unwrap_or(prog.derive);
    let start = Instant::now();
    let args = vec![0.0; prog.params.len()];
    let result = derive::axiom(&prog, &args, opts.seed)
        .and_then(|a| turtle::derive(&prog, a, steps, opts.seed, opts.limits, progress));
    let string = result.map_err(|e| e.diagnostic(&prog))?;
    Ok(Derived {
        prog,
        string,
        steps,
        derive_ms: start.elapsed().as_secs_f64() * 1000.0,
        limits: opts.limits,
    })
}

/// The largest mesh file read.
const MAX_MESH_BYTES: usize = 64 << 20;

/// A mesh file's bytes, at most one more than [`MAX_MESH_BYTES`]: a device
/// or a FIFO (`mesh "/dev/zero"`) is refused before it is read, and a file
/// that grows while it is read is not read to its end.
fn read_mesh(path: &std::path::Path) -> std::io::Result<Vec<u8>> {
    use std::io::Read;
    // Asked before opening: opening a FIFO waits for a writer.
    if !std::fs::metadata(path)?.is_file() {
        return Err(std::io::Error::other("it is not a regular file"));
    }
    let file = std::fs::File::open(path)?;
    let mut text = Vec::new();
    file.take(MAX_MESH_BYTES as u64 + 1)
        .read_to_end(&mut text)?;
    Ok(text)
}

/// Reads the OBJ file of every `mesh` element the program uses; an error
/// points at the file's name in the source.
pub fn load_meshes(prog: &mut Program, base: Option<&std::path::Path>) -> Result<(), Diagnostic> {
    for e in &mut prog.elements {
        let Some((file, span)) = e.mesh.clone() else {
            continue;
        };
        let path = base.map_or_else(|| std::path::PathBuf::from(&file), |b| b.join(&file));
        let fail = |what: String| {
            Diagnostic::error(Code::MeshFile, format!("the mesh `{file}` {what}"))
                .primary(span, "this mesh file")
                .note("a mesh is Wavefront OBJ text (`v`, `vn` and `f` lines), found relative to the program's directory")
        };
        let text = read_mesh(&path).map_err(|err| fail(format!("cannot be read: {err}")))?;
        if text.len() > MAX_MESH_BYTES {
            return Err(fail("is larger than 64 MiB".to_string()));
        }
        let text = String::from_utf8(text).map_err(|_| fail("is not UTF-8 text".to_string()))?;
        let solid = crate::organ::parse_obj(&text)
            .map_err(|m| fail(format!("does not read, line {}: {}", m.line, m.message)))?;
        e.solid = Some(std::sync::Arc::new(solid));
    }
    Ok(())
}

/// The output formats, by file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Svg,
    Png,
    /// Wavefront OBJ; its material library (`.mtl`) is written beside it from
    /// [`Written::materials`].
    Obj,
    /// Binary glTF 2.0.
    Glb,
    Txt,
    /// An animated PNG of every derivation step (one lsystem).
    Apng,
}

impl Format {
    pub fn from_path(path: &std::path::Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        Some(match ext.as_str() {
            "svg" => Format::Svg,
            "png" => Format::Png,
            "obj" => Format::Obj,
            "glb" => Format::Glb,
            "txt" => Format::Txt,
            "apng" => Format::Apng,
            _ => return None,
        })
    }
}

/// Settings of the output formats.
#[derive(Clone, Debug)]
pub struct Picture {
    pub size: u32,
    pub background: [u8; 4],
    /// The camera of 3D programs in SVG and PNG: azimuth and elevation in
    /// degrees (`None`: the default view, 30, 20).
    pub view: Option<[f64; 2]>,
    /// Draw into this view box instead of fitting the drawing (growth frames
    /// all use the final step's).
    pub bounds: Option<Bounds>,
    /// The material library an OBJ names in its `mtllib` line.
    pub mtllib: Option<String>,
    /// Time each frame of an animation is shown, in milliseconds.
    pub frame_ms: u16,
}

impl Default for Picture {
    fn default() -> Picture {
        Picture {
            size: 1024,
            background: [255, 255, 255, 255],
            view: None,
            bounds: None,
            mtllib: None,
            frame_ms: 400,
        }
    }
}

impl Picture {
    /// The view of a program (3D or not) under these settings.
    pub fn view(&self, is_3d: bool) -> View {
        match self.view {
            Some([azimuth, elevation]) if is_3d => View::oblique(azimuth, elevation),
            _ => View::new(is_3d),
        }
    }
}

/// What writing an output gives back.
#[derive(Clone, Debug, Default)]
pub struct Written {
    pub drawn: Drawn,
    /// The colours the mesh used (OBJ: the materials its `.mtl` must define).
    pub materials: Vec<u32>,
    /// Their colours and material names.
    pub palette: render::Palette,
}

/// Local bounding boxes of the program's elements (for fitting the view).
fn element_boxes(prog: &Program) -> Vec<Option<(glam::DVec3, glam::DVec3)>> {
    prog.elements.iter().map(turtle::element_box).collect()
}

/// Draws without output: the counts and bounding box (in the default view).
pub fn measure(d: &Derived, seed: u64) -> Result<(Drawn, Bounds), Diagnostic> {
    measure_in(d, seed, View::new(d.prog.is_3d))
}

/// Draws without output: the counts and bounding box as `view` sees them.
pub fn measure_in(d: &Derived, seed: u64, view: View) -> Result<(Drawn, Bounds), Diagnostic> {
    let boxes = element_boxes(&d.prog);
    let mut sink = BoundsSink {
        view,
        bounds: Bounds::default(),
        element_boxes: &boxes,
    };
    let drawn = d.interpret(seed, &mut sink)?;
    check_extent(&sink.bounds, &d.prog)?;
    Ok((drawn, sink.bounds))
}

/// The largest coordinate a drawing may reach: the writers place points in
/// fixed point with up to nine decimals in 64-bit integers, and viewers work
/// in 32-bit floats.
pub const MAX_COORDINATE: f64 = 1e9;

/// An error if the drawing reaches coordinates the writers cannot place.
fn check_extent(b: &Bounds, prog: &Program) -> Result<(), Diagnostic> {
    if !b.any {
        return Ok(());
    }
    check_corners([b.min.x, b.min.y, b.max.x, b.max.y], prog)
}

/// `check_extent` on a bounding box [minx, miny, maxx, maxy].
fn check_corners(corners: [f64; 4], prog: &Program) -> Result<(), Diagnostic> {
    let far = corners.into_iter().map(f64::abs).fold(0.0, |m: f64, v| {
        if v.is_nan() { f64::INFINITY } else { m.max(v) }
    });
    if far <= MAX_COORDINATE {
        return Ok(());
    }
    Err(Diagnostic::error(
        Code::DrawingTooLarge,
        format!("the drawing reaches the coordinate {far:e}, beyond ±{MAX_COORDINATE:e}"),
    )
    .primary(
        prog.name_span,
        "this lsystem draws that far from the origin",
    )
    .help("use smaller lengths, fewer steps, or a scale `*(k)` below 1"))
}

/// Why writing an output failed.
pub enum OutputError {
    Diagnostic(Diagnostic),
    Io(std::io::Error),
}

impl From<std::io::Error> for OutputError {
    fn from(e: std::io::Error) -> Self {
        OutputError::Io(e)
    }
}

/// Writes `d` in `format` to `out`; returns what was drawn.
pub fn write_output(
    d: &Derived,
    format: Format,
    picture: Picture,
    seed: u64,
    out: &mut dyn Write,
) -> Result<Drawn, OutputError> {
    write_output_full(d, format, &picture, seed, out).map(|w| w.drawn)
}

/// The view box of a picture: the one given, or the drawing's own.
fn picture_bounds(
    d: &Derived,
    picture: &Picture,
    seed: u64,
    view: View,
) -> Result<Bounds, OutputError> {
    let (_, own) = measure_in(d, seed, view).map_err(OutputError::Diagnostic)?;
    Ok(picture.bounds.unwrap_or(own))
}

/// Writes `d` in `format` to `out`; returns what was drawn and the materials used.
pub fn write_output_full(
    d: &Derived,
    format: Format,
    picture: &Picture,
    seed: u64,
    out: &mut dyn Write,
) -> Result<Written, OutputError> {
    let view = picture.view(d.prog.is_3d);
    let drawn = match format {
        Format::Txt => {
            render::txt::write(out, &d.prog, &d.string)?;
            let (drawn, _) = measure(d, seed).map_err(OutputError::Diagnostic)?;
            drawn
        }
        Format::Svg => {
            let bounds = picture_bounds(d, picture, seed, view)?;
            let used: Vec<bool> = (0..d.prog.elements.len())
                .map(|i| {
                    d.prog
                        .symbols
                        .info
                        .iter()
                        .any(|s| s.action == Action::Element(i as u16))
                })
                .collect();
            let mut w = render::svg::SvgWriter::new(out, view, &bounds, &d.prog.elements, &used)?
                .with_palette(render::Palette::of(&d.prog));
            let drawn = d.interpret(seed, &mut w).map_err(OutputError::Diagnostic)?;
            w.finish()?;
            drawn
        }
        Format::Png => {
            let (drawn, w) = draw_png(d, picture, seed, view)?;
            let bytes = w.finish().map_err(std::io::Error::other)?;
            out.write_all(&bytes)?;
            drawn
        }
        Format::Obj => {
            // One pass: the extent comes from what was drawn, checked before the
            // mesh is finished (the file is written only if this succeeds).
            let options = render::obj::ObjOptions::for_program(&d.prog);
            let mut w = match &picture.mtllib {
                Some(lib) => render::obj::ObjWriter::with_mtllib(out, options, lib),
                None => render::obj::ObjWriter::new(out, options),
            };
            w.object(&d.prog.name);
            let drawn = d.interpret(seed, &mut w).map_err(OutputError::Diagnostic)?;
            if let Some(b) = drawn.bbox {
                check_corners(b, &d.prog).map_err(OutputError::Diagnostic)?;
            }
            let materials = w.colors();
            w.finish()?;
            return Ok(Written {
                drawn,
                materials,
                palette: render::Palette::of(&d.prog),
            });
        }
        Format::Glb => {
            let options = render::obj::ObjOptions::for_program(&d.prog);
            let glb = render::glb::GlbMesh::with_budget(d.limits.max_bytes);
            let mut w = render::obj::MeshBuilder::with_target(glb, options);
            w.object(&d.prog.name);
            let drawn = d.interpret(seed, &mut w).map_err(OutputError::Diagnostic)?;
            if let Some(b) = drawn.bbox {
                check_corners(b, &d.prog).map_err(OutputError::Diagnostic)?;
            }
            let materials = w.colors();
            w.into_target().write(out)?;
            return Ok(Written {
                drawn,
                materials,
                palette: render::Palette::of(&d.prog),
            });
        }
        Format::Apng => {
            return Err(OutputError::Io(std::io::Error::other(
                "an animated PNG is written from the derivation's steps (write_animation)",
            )));
        }
    };
    Ok(Written {
        drawn,
        materials: Vec::new(),
        palette: render::Palette::default(),
    })
}

/// Draws `d` into a PNG canvas (not yet encoded).
fn draw_png(
    d: &Derived,
    picture: &Picture,
    seed: u64,
    view: View,
) -> Result<(Drawn, render::png::PngWriter), OutputError> {
    let bounds = picture_bounds(d, picture, seed, view)?;
    let mut w = render::png::PngWriter::new(
        picture.size,
        picture.background,
        view,
        &bounds,
        &d.prog.elements,
    )
    .ok_or_else(|| std::io::Error::other("the image size is not possible"))?
    .with_palette(render::Palette::of(&d.prog));
    let drawn = d.interpret(seed, &mut w).map_err(OutputError::Diagnostic)?;
    Ok((drawn, w))
}

/// Growth, step by step: `d` (derived to its final step) is taken back to
/// its axiom, then derived again one step at a time; `frame` sees step 0 (the
/// axiom), 1, … up to `d.steps`, each in the final step's view box (returned
/// by the first call's `Picture::bounds`). Afterwards `d` holds its final
/// string again. Step `k` equals a run of `-n k`: the same steps, seeds and
/// limits.
pub fn each_step(
    d: &mut Derived,
    picture: &Picture,
    seed: u64,
    frame: &mut dyn FnMut(&Derived, &Picture) -> Result<(), OutputError>,
) -> Result<(), OutputError> {
    let view = picture.view(d.prog.is_3d);
    let (_, bounds) = measure_in(d, seed, view).map_err(OutputError::Diagnostic)?;
    let framed = Picture {
        bounds: Some(picture.bounds.unwrap_or(bounds)),
        ..picture.clone()
    };
    let last = d.steps;
    let args = vec![0.0; d.prog.params.len()];
    let axiom = derive::axiom(&d.prog, &args, seed).map_err(|e| e.diagnostic(&d.prog));
    let mut s = axiom.map_err(OutputError::Diagnostic)?;
    let final_string = std::mem::take(&mut d.string);
    let mut result = Ok(());
    for k in 0..=last {
        if k > 0 {
            match derive::step(&d.prog, &s, k, seed, d.limits) {
                Ok(next) => s = next,
                Err(e) => {
                    result = Err(OutputError::Diagnostic(e.diagnostic(&d.prog)));
                    break;
                }
            }
        }
        d.string = std::mem::take(&mut s);
        d.steps = k;
        let r = frame(d, &framed);
        s = std::mem::take(&mut d.string);
        if r.is_err() {
            result = r;
            break;
        }
    }
    d.string = final_string;
    d.steps = last;
    result
}

/// An animated PNG of every step of `d`'s growth (`each_step`), each frame
/// shown `picture.frame_ms`, the last one twice as long; it plays forever.
pub fn write_animation(
    d: &mut Derived,
    picture: &Picture,
    seed: u64,
    progress: &dyn Fn(u32),
    out: &mut dyn Write,
) -> Result<Written, OutputError> {
    let frames = d.steps + 1;
    let mut encoder: Option<png::Writer<&mut dyn Write>> = None;
    let mut size = (0, 0);
    let mut out = Some(out);
    let mut drawn = Drawn::default();
    let png_error = |e: png::EncodingError| OutputError::Io(std::io::Error::other(e.to_string()));
    let last = d.steps;
    each_step(d, picture, seed, &mut |step, framed| {
        let view = framed.view(step.prog.is_3d);
        let (frame_drawn, w) = draw_png(step, framed, seed, view)?;
        drawn = frame_drawn;
        let (width, height, rgba) = w.finish_rgba();
        if encoder.is_none() {
            size = (width, height);
            let Some(out) = out.take() else {
                return Err(std::io::Error::other("the output is gone").into());
            };
            let mut e = render::png::png_encoder(out, width, height);
            e.set_animated(frames, 0).map_err(png_error)?;
            encoder = Some(e.write_header().map_err(png_error)?);
        }
        if (width, height) != size {
            return Err(std::io::Error::other("frames of different sizes").into());
        }
        if let Some(wr) = encoder.as_mut() {
            let ms = if step.steps == last {
                picture.frame_ms.saturating_mul(2)
            } else {
                picture.frame_ms
            };
            wr.set_frame_delay(ms, 1000).map_err(png_error)?;
            wr.write_image_data(&rgba).map_err(png_error)?;
        }
        progress(step.steps);
        Ok(())
    })?;
    if let Some(wr) = encoder {
        wr.finish().map_err(png_error)?;
    }
    Ok(Written {
        drawn,
        materials: Vec::new(),
        palette: render::Palette::default(),
    })
}

/// The `--stats` object of the contract.
#[derive(Serialize)]
pub struct Stats {
    pub system: String,
    pub modules: usize,
    pub segments: u64,
    pub elements: u64,
    pub polygons: u64,
    pub bbox: Option<[f64; 4]>,
    pub steps: u32,
    pub derive_ms: f64,
    pub interpret_ms: f64,
    pub bytes_per_module: f64,
}

impl Stats {
    pub fn new(d: &Derived, drawn: &Drawn, interpret_ms: f64) -> Stats {
        // `+ 0.0` turns -0 into 0.
        let round = |v: f64| (v * 1000.0).round() / 1000.0 + 0.0;
        Stats {
            system: d.prog.name.clone(),
            modules: d.string.len(),
            segments: drawn.segments,
            elements: drawn.elements,
            polygons: drawn.polygons,
            bbox: drawn.bbox.map(|b| b.map(round)),
            steps: d.steps,
            derive_ms: round(d.derive_ms),
            interpret_ms: round(interpret_ms),
            bytes_per_module: round(d.string.bytes() as f64 / d.string.len().max(1) as f64),
        }
    }
}

/// A scene after its run, ready to draw.
pub struct SceneRun {
    pub scene: crate::env::Scene,
    pub outcome: crate::env::Outcome,
    pub derive_ms: f64,
    /// The run's limits, which drawing honours too.
    pub limits: Limits,
}

impl SceneRun {
    /// Interprets one system of the scene into `sink`, within the run's limits.
    fn interpret(
        &self,
        inst: &crate::env::Instance,
        seed: u64,
        sink: &mut dyn crate::turtle::Sink,
    ) -> Result<Drawn, Diagnostic> {
        let prog = &self.scene.programs[self.scene.guides[inst.guide].program];
        turtle::interpret_limited(prog, &inst.string, seed, inst.start, self.limits, sink)
            .map_err(|e| e.diagnostic(prog))
    }
}

/// Builds and runs the scene called `name` (or the first one).
pub fn run_scene(
    file: &File,
    checked: &Checked,
    name: Option<&str>,
    opts: &Options,
) -> Result<SceneRun, Diagnostic> {
    let mut scene = crate::env::build(file, checked, name).map_err(|e| e.diagnostic())?;
    let start = Instant::now();
    let outcome = crate::env::run(&mut scene, opts.seed, opts.limits, opts.steps)?;
    Ok(SceneRun {
        scene,
        outcome,
        derive_ms: start.elapsed().as_secs_f64() * 1000.0,
        limits: opts.limits,
    })
}

/// The local centres of every program's elements (for the centre rule), by program.
fn program_centres(scene: &crate::env::scene::Scene) -> Vec<Vec<glam::DVec2>> {
    scene
        .programs
        .iter()
        .map(crate::env::clip::element_centres)
        .collect()
}

/// Draws every instance of a scene into `sink`, each clipped to its guide by
/// the centre rule.
fn draw_scene(
    r: &SceneRun,
    seed: u64,
    sink: &mut dyn crate::turtle::Sink,
) -> Result<Drawn, Diagnostic> {
    let mut total = Drawn::default();
    let centres = program_centres(&r.scene);
    for (gi, g) in r.scene.guides.iter().enumerate() {
        for inst in r.outcome.instances.iter().filter(|i| i.guide == gi) {
            // Counts and bounds of what the centre rule keeps.
            let mut clip = crate::env::clip::Clip::new(&g.polygon, &centres[g.program], &mut *sink);
            r.interpret(inst, seed, &mut clip)?;
            total.add(&clip.kept);
        }
    }
    Ok(total)
}

/// An SVG writer into memory: a part of a drawing, or its template.
type SvgPart = render::svg::SvgWriter<Vec<u8>>;

/// What `draw_scene` into a `BoundsSink` gives (counts, and the bounds of
/// the view), with the systems drawn in parallel: sums, minima and maxima
/// do not depend on the order. With `svg`, each system is also written into
/// a part of that writer in the same pass (per system, in the scene's order).
fn scene_bounds(
    r: &SceneRun,
    seed: u64,
    view: View,
    boxes: &[Option<(glam::DVec3, glam::DVec3)>],
    svg: Option<&SvgPart>,
) -> Result<(Drawn, Bounds, Vec<Option<SvgPart>>), Diagnostic> {
    let centres = program_centres(&r.scene);
    type Each = Result<(Drawn, Bounds), Diagnostic>;
    let (each, parts): (Vec<Each>, Vec<_>) = r
        .outcome
        .instances
        .par_iter()
        .map(|inst| {
            let g = &r.scene.guides[inst.guide];
            let mut sink = BoundsSink {
                view,
                bounds: Bounds::default(),
                element_boxes: boxes,
            };
            let mut part = svg.map(|w| w.part());
            let mut discard = turtle::Discard;
            let written: &mut dyn turtle::Sink = match &mut part {
                Some(part) => part,
                None => &mut discard,
            };
            let mut both = turtle::Tee(&mut sink, written);
            let mut clip = crate::env::clip::Clip::new(&g.polygon, &centres[g.program], &mut both);
            let drawn = r.interpret(inst, seed, &mut clip).map(|_| clip.kept);
            (drawn.map(|kept| (kept, sink.bounds)), part)
        })
        .unzip();
    let (mut total, mut bounds) = (Drawn::default(), Bounds::default());
    // In the order `draw_scene` meets them (the first error is its).
    for gi in 0..r.scene.guides.len() {
        for (inst, x) in r.outcome.instances.iter().zip(&each) {
            if inst.guide != gi {
                continue;
            }
            let (d, b) = x.clone()?;
            total.add(&d);
            if b.any {
                bounds.add(b.min);
                bounds.add(b.max);
            }
        }
    }
    Ok((total, bounds, parts))
}

/// The `--stats` of a scene: the contract's fields plus answered queries and messages.
#[derive(Serialize)]
pub struct SceneStats {
    pub scene: String,
    pub modules: usize,
    pub segments: u64,
    pub elements: u64,
    pub polygons: u64,
    pub bbox: Option<[f64; 4]>,
    pub steps: u32,
    pub systems: usize,
    pub queries: u64,
    pub messages: u64,
    pub derive_ms: f64,
    pub interpret_ms: f64,
    /// The colours the mesh used (OBJ: the materials of its `.mtl`).
    #[serde(skip)]
    pub materials: Vec<u32>,
}

/// What the scene writers share: the view, the elements and the bounds of
/// everything drawn (guide outlines included).
struct SceneFrame<'a> {
    view: View,
    elements: &'a [crate::compile::ElementDef],
    bounds: Bounds,
}

impl SceneFrame<'_> {
    fn outline(g: &crate::env::scene::Guide) -> Vec<glam::DVec3> {
        g.polygon.iter().map(|p| p.extend(0.0)).collect()
    }

    fn edge_mid(r: &SceneRun, (g, e): (usize, usize)) -> glam::DVec3 {
        let poly = &r.scene.guides[g].polygon;
        let n = poly.len().max(1);
        ((poly[e % n] + poly[(e + 1) % n]) * 0.5).extend(0.0)
    }
}

/// Writes a scene in `format` to `out` (`guides`: draw outlines and links too).
pub fn write_scene(
    r: &SceneRun,
    format: Option<Format>,
    picture: Picture,
    seed: u64,
    guides: bool,
    out: &mut dyn Write,
) -> Result<SceneStats, OutputError> {
    let start = Instant::now();
    let view = picture.view(r.scene.programs.iter().any(|p| p.is_3d));
    // Elements are items of the file, the same for every system of the scene.
    let elements: &[crate::compile::ElementDef] =
        r.scene.programs.first().map_or(&[], |p| &p.elements);
    let boxes: Vec<_> = r.scene.programs.first().map_or(Vec::new(), element_boxes);
    // SVG numbers have as many decimals as the picture's size asks; the
    // guides' outlines are in the picture, and a drawing kept by the centre
    // rule seldom reaches far beyond them. So every system is written once
    // with the decimals the outlines give, in the pass that finds the
    // bounds, and written again only when the bounds ask for others.
    let mut outlines = Bounds::default();
    for g in &r.scene.guides {
        for p in &g.polygon {
            outlines.add(view.project(p.extend(0.0)));
        }
    }
    let guess = (format == Some(Format::Svg))
        .then(|| scene_svg_writer(Vec::new(), &outlines, view, elements))
        .transpose()?;
    let (drawn, mut bounds, parts) =
        scene_bounds(r, seed, view, &boxes, guess.as_ref()).map_err(OutputError::Diagnostic)?;
    if outlines.any {
        bounds.add(outlines.min);
        bounds.add(outlines.max);
    }
    if let Some(first) = r.scene.programs.first() {
        check_extent(&bounds, first).map_err(OutputError::Diagnostic)?;
    }
    let frame = SceneFrame {
        view,
        elements,
        bounds,
    };
    let mut materials = Vec::new();
    match format {
        Some(Format::Svg) => {
            let w = scene_svg_writer(out, &frame.bounds, frame.view, frame.elements)?;
            let parts = guess.filter(|g| g.same_numbers(&w)).map(|_| parts);
            scene_svg(r, seed, guides, w, parts)?
        }
        Some(Format::Png) => scene_png(r, &frame, picture, seed, guides, out)?,
        Some(Format::Obj) => {
            let options = scene_mesh_options(r);
            let mut w = match &picture.mtllib {
                Some(lib) => render::obj::ObjWriter::with_mtllib(out, options, lib),
                None => render::obj::ObjWriter::new(out, options),
            };
            scene_mesh(r, seed, &mut w)?;
            materials = w.colors();
            w.finish()?;
        }
        Some(Format::Glb) => {
            let glb = render::glb::GlbMesh::with_budget(r.limits.max_bytes);
            let mut w = render::obj::MeshBuilder::with_target(glb, scene_mesh_options(r));
            scene_mesh(r, seed, &mut w)?;
            materials = w.colors();
            w.into_target().write(out)?;
        }
        Some(Format::Txt) => scene_txt(r, out)?,
        Some(Format::Apng) => {
            return Err(OutputError::Io(std::io::Error::other(
                "a scene has no animated output yet: write its steps with `-n`",
            )));
        }
        None => {}
    }
    let round = |v: f64| (v * 1000.0).round() / 1000.0 + 0.0;
    Ok(SceneStats {
        scene: r.scene.name.clone(),
        modules: r.outcome.instances.iter().map(|i| i.string.len()).sum(),
        segments: drawn.segments,
        elements: drawn.elements,
        polygons: drawn.polygons,
        bbox: drawn.bbox.map(|b| b.map(round)),
        steps: r.outcome.steps,
        systems: r.outcome.instances.len(),
        queries: r.outcome.queries,
        messages: r.outcome.messages,
        derive_ms: round(r.derive_ms),
        interpret_ms: round(start.elapsed().as_secs_f64() * 1000.0),
        materials,
    })
}

/// The SVG writer of a scene whose drawing has the (projected) `bounds`.
fn scene_svg_writer<W: Write>(
    out: W,
    bounds: &Bounds,
    view: View,
    elements: &[crate::compile::ElementDef],
) -> std::io::Result<render::svg::SvgWriter<W>> {
    let used = vec![true; elements.len()];
    render::svg::SvgWriter::new(out, view, bounds, elements, &used)
}

/// A scene as SVG into `w` (made by `scene_svg_writer`): one layer per
/// guide, then outlines and links. `parts`, when given, are the systems
/// already written into parts of a writer with the same numbers, one per
/// system in the scene's order.
fn scene_svg<W: Write>(
    r: &SceneRun,
    seed: u64,
    guides: bool,
    mut w: render::svg::SvgWriter<W>,
    mut parts: Option<Vec<Option<SvgPart>>>,
) -> Result<(), OutputError> {
    let centres = program_centres(&r.scene);
    let names: Vec<&str> = r.scene.guides.iter().map(|g| g.name.as_str()).collect();
    for (gi, g) in r.scene.guides.iter().enumerate() {
        w.begin_guide(names[gi]);
        let (insts, mut made): (Vec<&crate::env::Instance>, Vec<_>) = r
            .outcome
            .instances
            .iter()
            .enumerate()
            .filter(|(_, i)| i.guide == gi)
            .map(|(k, i)| (i, parts.as_mut().and_then(|p| p[k].take())))
            .unzip();
        // Each system written on its own in parallel (unless it was in the
        // bounds' pass), then in order (the bytes one writer would write).
        let template = w.part();
        let parts: Vec<Result<_, Diagnostic>> = insts
            .par_iter()
            .zip(made.par_iter_mut())
            .map(|(inst, made)| {
                if let Some(part) = made.take() {
                    return Ok(part);
                }
                let mut part = template.part();
                let mut clip =
                    crate::env::clip::Clip::new(&g.polygon, &centres[g.program], &mut part);
                r.interpret(inst, seed, &mut clip)?;
                Ok(part)
            })
            .collect();
        for (inst, part) in insts.iter().zip(parts) {
            if !w.append(part.map_err(OutputError::Diagnostic)?) {
                // It goes on with the path open before it: written again here.
                let mut clip = crate::env::clip::Clip::new(&g.polygon, &centres[g.program], &mut w);
                r.interpret(inst, seed, &mut clip)
                    .map_err(OutputError::Diagnostic)?;
            }
        }
        w.end_guide();
    }
    if guides {
        for g in &r.scene.guides {
            w.guide_outline(&g.name, &SceneFrame::outline(g));
        }
        for l in &r.scene.links {
            w.link_line(
                names[l.from.0],
                names[l.to.0],
                SceneFrame::edge_mid(r, l.from),
                SceneFrame::edge_mid(r, l.to),
            );
        }
    }
    w.finish()?;
    Ok(())
}

/// A scene as PNG; with `guides`, the outlines and links drawn as hairlines
/// in the colours SVG gives them (palette 10 and 8).
fn scene_png(
    r: &SceneRun,
    frame: &SceneFrame,
    picture: Picture,
    seed: u64,
    guides: bool,
    out: &mut dyn Write,
) -> Result<(), OutputError> {
    let mut w = render::png::PngWriter::new(
        picture.size,
        picture.background,
        frame.view,
        &frame.bounds,
        frame.elements,
    )
    .ok_or_else(|| std::io::Error::other("the image size is not possible"))?;
    draw_scene(r, seed, &mut w).map_err(OutputError::Diagnostic)?;
    if guides {
        for g in &r.scene.guides {
            let pts = SceneFrame::outline(g);
            for i in 0..pts.len() {
                crate::turtle::Sink::segment(&mut w, pts[i], pts[(i + 1) % pts.len()], 0.0, 10);
            }
        }
        for l in &r.scene.links {
            let (a, b) = (
                SceneFrame::edge_mid(r, l.from),
                SceneFrame::edge_mid(r, l.to),
            );
            crate::turtle::Sink::segment(&mut w, a, b, 0.0, 8);
        }
    }
    let bytes = w.finish().map_err(std::io::Error::other)?;
    out.write_all(&bytes)?;
    Ok(())
}

/// How a scene's mesh is built: tubes sized by the first system's step.
fn scene_mesh_options(r: &SceneRun) -> render::obj::ObjOptions {
    r.scene
        .programs
        .first()
        .map(render::obj::ObjOptions::for_program)
        .unwrap_or_default()
}

/// A scene as one mesh (OBJ or glTF): one object per guide, named for it,
/// holding that guide's systems through the centre rule.
fn scene_mesh<T: render::obj::MeshTarget>(
    r: &SceneRun,
    seed: u64,
    w: &mut render::obj::MeshBuilder<T>,
) -> Result<(), OutputError> {
    let centres = program_centres(&r.scene);
    for (gi, g) in r.scene.guides.iter().enumerate() {
        w.object(&g.name);
        for inst in r.outcome.instances.iter().filter(|i| i.guide == gi) {
            let mut clip = crate::env::clip::Clip::new(&g.polygon, &centres[g.program], &mut *w);
            r.interpret(inst, seed, &mut clip)
                .map_err(OutputError::Diagnostic)?;
        }
    }
    Ok(())
}

/// A scene as text: every system's string in the language's syntax.
fn scene_txt(r: &SceneRun, out: &mut dyn Write) -> Result<(), OutputError> {
    // Every system's string in the language's syntax, after a comment
    // saying where it grew; each line reads back as an axiom.
    for inst in &r.outcome.instances {
        let g = &r.scene.guides[inst.guide];
        let prog = &r.scene.programs[g.program];
        let h = inst.start.h;
        let heading = (-h.x).atan2(h.y).to_degrees();
        let round = |v: f64| (v * 1000.0).round() / 1000.0 + 0.0;
        writeln!(
            out,
            "// guide {}, lsystem {}, seeded at ({}, {}) heading {}",
            g.name,
            prog.name,
            round(inst.start.pos.x),
            round(inst.start.pos.y),
            round(heading)
        )?;
        render::txt::write(out, prog, &inst.string)?;
    }
    Ok(())
}
