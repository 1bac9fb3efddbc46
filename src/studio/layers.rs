//! A dragged scene's drawing, kept guide by guide: only the layers of the
//! guides a move recomputed are drawn again.
//!
//! Owns: the cache of each guide's drawing (what the centre rule kept of its
//! systems, recorded once; its bounds; its layer's SVG text and hash) and
//! putting a scene's SVG together from it. The SVG is the one `lsyc run -o
//! x.svg --guides` writes (`run::write_scene`): the same clip (`env::Clip`),
//! the same bounds (`render::BoundsSink`), the same writer
//! (`render::svg::SvgWriter`), called in the same order; a test compares the
//! two byte for byte. What `write_scene` does twice for every guide (a pass
//! for the bounds, a pass that writes) is done here once for a guide whose
//! systems changed, and not at all for the others.

use crate::compile::ElementDef;
use crate::diagnostic::Diagnostic;
use crate::env::{self, Clip, Outcome};
use crate::render::svg::{SvgWriter, xml};
use crate::render::{Bounds, BoundsSink, View};
use crate::run::{MAX_COORDINATE, SceneStats};
use crate::turtle::{self, Drawn, Sink};
use glam::{DVec2, DVec3};
use std::time::Instant;

/// One call the clip made to its sink.
#[derive(Clone, Copy)]
enum Op {
    Segment(DVec3, DVec3, f64, u32),
    /// A polygon: its points in `Recording::points`, from, to, and its colour.
    Polygon(u32, u32, u32),
    Element(u16, DVec3, DVec3, DVec3, f64, u32),
}

/// What a guide's systems drew, as the centre rule kept it, in drawing order.
#[derive(Default)]
struct Recording {
    ops: Vec<Op>,
    points: Vec<DVec3>,
}

impl Sink for Recording {
    fn segment(&mut self, a: DVec3, b: DVec3, width: f64, color: u32) {
        self.ops.push(Op::Segment(a, b, width, color));
    }

    fn polygon(&mut self, points: &[DVec3], color: u32) {
        let from = self.points.len() as u32;
        self.points.extend_from_slice(points);
        self.ops
            .push(Op::Polygon(from, self.points.len() as u32, color));
    }

    fn element(&mut self, index: u16, at: DVec3, h: DVec3, l: DVec3, scale: f64, color: u32) {
        self.ops.push(Op::Element(index, at, h, l, scale, color));
    }
}

impl Recording {
    /// Makes the recorded calls again, in order.
    fn replay(&self, sink: &mut dyn Sink) {
        for op in &self.ops {
            match *op {
                Op::Segment(a, b, w, c) => sink.segment(a, b, w, c),
                Op::Polygon(from, to, c) => {
                    sink.polygon(&self.points[from as usize..to as usize], c);
                }
                Op::Element(i, at, h, l, s, c) => sink.element(i, at, h, l, s, c),
            }
        }
    }
}

/// A guide's drawing.
struct Layer {
    recording: Recording,
    /// The counts and box of what it kept (summed over its systems).
    kept: Drawn,
    /// Its bounds in the view.
    bounds: Bounds,
    /// Its layer's text, for the decimals it was written with, and its hash.
    text: Option<(usize, String, String)>,
}

/// A scene's drawing as the page gets it.
pub struct Drawing<'a> {
    /// Up to the first layer.
    pub head: String,
    /// Every layer in drawing order: the guide's name as the SVG writes it
    /// (XML-escaped), its text and its hash.
    pub layers: Vec<(String, &'a str, &'a str)>,
    /// After the last layer.
    pub tail: String,
    /// `--stats`, as `run::write_scene` gives them.
    pub stats: SceneStats,
}

impl Drawing<'_> {
    /// The whole SVG.
    pub fn svg(&self) -> String {
        let len = self.head.len()
            + self.tail.len()
            + self.layers.iter().map(|(_, t, _)| t.len()).sum::<usize>();
        let mut s = String::with_capacity(len);
        s.push_str(&self.head);
        for (_, text, _) in &self.layers {
            s.push_str(text);
        }
        s.push_str(&self.tail);
        s
    }
}

/// Every guide's drawing, kept from move to move.
#[derive(Default)]
pub struct LayerCache {
    layers: Vec<Option<Layer>>,
}

/// What the page draws and how: the seed, the run's limits, the view.
#[derive(Clone, Copy)]
pub struct Style {
    pub seed: u64,
    pub limits: crate::derive::Limits,
    pub view: View,
}

impl LayerCache {
    /// Forgets every drawing (after a run that failed: the runner's cache
    /// and these may no longer agree).
    pub fn clear(&mut self) {
        self.layers.clear();
    }

    /// Draws `outcome`, the run of `scene`: the guides in `recomputed` (and
    /// any not drawn yet) afresh, the others from the cache.
    pub fn draw<'a>(
        &'a mut self,
        scene: &env::Scene,
        outcome: &Outcome,
        recomputed: &[bool],
        style: Style,
        derive_ms: f64,
    ) -> Result<Drawing<'a>, Diagnostic> {
        let start = Instant::now();
        let n = scene.guides.len();
        self.layers.resize_with(n, || None);
        for (g, fresh) in recomputed.iter().enumerate().take(n) {
            if *fresh {
                self.layers[g] = None;
            }
        }
        // Elements are items of the file, the same for every system.
        let elements: &[ElementDef] = scene.programs.first().map_or(&[], |p| &p.elements);
        let boxes: Vec<_> = elements.iter().map(turtle::element_box).collect();
        let centres: Vec<Vec<DVec2>> = scene.programs.iter().map(env::element_centres).collect();
        let mut by_guide: Vec<Vec<&env::Instance>> = vec![Vec::new(); n];
        for inst in &outcome.instances {
            if let Some(v) = by_guide.get_mut(inst.guide) {
                v.push(inst);
            }
        }
        let mut jobs: Vec<(usize, &mut Option<Layer>)> = self
            .layers
            .iter_mut()
            .enumerate()
            .filter(|(_, l)| l.is_none())
            .collect();
        let record = |g: usize| -> Result<Layer, Diagnostic> {
            let guide = &scene.guides[g];
            let prog = &scene.programs[guide.program];
            let mut recording = Recording::default();
            let mut kept = Drawn::default();
            for inst in &by_guide[g] {
                let mut clip = Clip::new(&guide.polygon, &centres[guide.program], &mut recording);
                turtle::interpret_limited(
                    prog,
                    &inst.string,
                    style.seed,
                    inst.start,
                    style.limits,
                    &mut clip,
                )
                .map_err(|e| e.diagnostic(prog))?;
                kept.add(&clip.kept);
            }
            let mut sink = BoundsSink {
                view: style.view,
                bounds: Bounds::default(),
                element_boxes: &boxes,
            };
            recording.replay(&mut sink);
            Ok(Layer {
                recording,
                kept,
                bounds: sink.bounds,
                text: None,
            })
        };
        let drawn: Vec<Result<(), Diagnostic>> = {
            use rayon::prelude::*;
            jobs.par_iter_mut()
                .map(|(g, slot)| {
                    **slot = Some(record(*g)?);
                    Ok(())
                })
                .collect()
        };
        drawn.into_iter().collect::<Result<(), _>>()?;
        let layers: Vec<&mut Layer> = self.layers.iter_mut().flatten().collect();
        // The bounds of the whole drawing: every guide's, then the outlines.
        let mut bounds = Bounds::default();
        let mut total = Drawn::default();
        for l in &layers {
            if l.bounds.any {
                bounds.add(l.bounds.min);
                bounds.add(l.bounds.max);
            }
            total.add(&l.kept);
        }
        for g in &scene.guides {
            for p in &g.polygon {
                bounds.add(style.view.project(p.extend(0.0)));
            }
        }
        if bounds.any {
            let far = [bounds.min.x, bounds.min.y, bounds.max.x, bounds.max.y]
                .into_iter()
                .map(f64::abs)
                .fold(
                    0.0,
                    |m: f64, v| if v.is_nan() { f64::INFINITY } else { m.max(v) },
                );
            if far > MAX_COORDINATE {
                return Err(Diagnostic::error(
                    crate::diagnostic::Code::DrawingTooLarge,
                    format!(
                        "the drawing reaches the coordinate {far:e}, beyond ±{MAX_COORDINATE:e}"
                    ),
                ));
            }
        }
        let used = vec![true; elements.len()];
        let written = |e: std::io::Error| {
            Diagnostic::error(
                crate::diagnostic::Code::WriteOutput,
                format!("cannot draw: {e}"),
            )
        };
        let mut w =
            SvgWriter::new(Vec::new(), style.view, &bounds, elements, &used).map_err(written)?;
        let decimals = w.decimals();
        let head = String::from_utf8(std::mem::take(w.get_mut()))
            .map_err(std::io::Error::other)
            .map_err(written)?;
        // The layers not yet written with these decimals, each by a writer
        // of its own, in parallel.
        {
            use rayon::prelude::*;
            let mut to_write: Vec<(&str, &mut Layer)> = scene
                .guides
                .iter()
                .map(|g| g.name.as_str())
                .zip(layers)
                .filter(|(_, l)| l.text.as_ref().is_none_or(|(d, ..)| *d != decimals))
                .collect();
            let results: Vec<Result<(), Diagnostic>> = to_write
                .par_iter_mut()
                .map(|(name, l)| {
                    let text = write_layer(l, name, style.view, &bounds, elements, &used)
                        .map_err(written)?;
                    let hash = super::protocol::hash(text.as_bytes());
                    l.text = Some((decimals, text, hash));
                    Ok(())
                })
                .collect();
            results.into_iter().collect::<Result<(), _>>()?;
        }
        // The tail: outlines, links, the closing tags.
        let names: Vec<&str> = scene.guides.iter().map(|g| g.name.as_str()).collect();
        for g in &scene.guides {
            let outline: Vec<DVec3> = g.polygon.iter().map(|p| p.extend(0.0)).collect();
            w.guide_outline(&g.name, &outline);
        }
        for l in &scene.links {
            w.link_line(
                names[l.from.0],
                names[l.to.0],
                edge_mid(scene, l.from),
                edge_mid(scene, l.to),
            );
        }
        let tail = String::from_utf8(w.finish().map_err(written)?)
            .map_err(std::io::Error::other)
            .map_err(written)?;
        let round = |v: f64| (v * 1000.0).round() / 1000.0 + 0.0;
        let stats = SceneStats {
            scene: scene.name.clone(),
            modules: outcome.instances.iter().map(|i| i.string.len()).sum(),
            segments: total.segments,
            elements: total.elements,
            polygons: total.polygons,
            bbox: total.bbox.map(|b| b.map(round)),
            steps: outcome.steps,
            systems: outcome.instances.len(),
            queries: outcome.queries,
            messages: outcome.messages,
            derive_ms: round(derive_ms),
            interpret_ms: round(start.elapsed().as_secs_f64() * 1000.0),
            materials: Vec::new(),
        };
        let layers = scene
            .guides
            .iter()
            .zip(&self.layers)
            .filter_map(|(g, l)| {
                let (_, text, hash) = l.as_ref()?.text.as_ref()?;
                Some((xml(&g.name), text.as_str(), hash.as_str()))
            })
            .collect();
        Ok(Drawing {
            head,
            layers,
            tail,
            stats,
        })
    }
}

/// A guide's layer, as the writer of the whole drawing writes it.
fn write_layer(
    l: &Layer,
    name: &str,
    view: View,
    bounds: &Bounds,
    elements: &[ElementDef],
    used: &[bool],
) -> std::io::Result<String> {
    let mut w = SvgWriter::new(Vec::new(), view, bounds, elements, used)?;
    w.get_mut().clear();
    w.begin_guide(name);
    l.recording.replay(&mut w);
    w.end_guide();
    let bytes = std::mem::take(w.get_mut());
    String::from_utf8(bytes).map_err(std::io::Error::other)
}

/// The middle of edge `e` of guide `g`, where a link's line ends.
fn edge_mid(scene: &env::Scene, (g, e): (usize, usize)) -> DVec3 {
    let poly = &scene.guides[g].polygon;
    let n = poly.len().max(1);
    ((poly[e % n] + poly[(e + 1) % n]) * 0.5).extend(0.0)
}
