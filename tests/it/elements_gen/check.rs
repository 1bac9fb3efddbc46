//! The check: a design's drawing is inferred, and counts as **exact** when
//! the program `lsyc run` draws (a) puts every copy back where the design
//! put it, and (b) *predicts*: run with each of its counts (`const …_N`)
//! one larger, it draws the design's next (every repetition once more, a
//! tree one level deeper). A program that lists the copies, or splits one
//! repetition in two, redraws but does not predict. Both drawings are read
//! by lsyc's reader, and copies are compared outline to outline.

use super::draw::{self, Variant};
use super::programs::{self, Class, Design, Place};
use super::rng::Rng;
use glam::DVec2;
use lsyc::infer::{self, Outcome as Inferred};
use std::collections::BTreeMap;
use std::process::Command;
use std::time::Instant;

/// One random design.
pub struct Case {
    pub class: Class,
    pub seed: u64,
    pub design: Design,
}

impl Case {
    pub fn new(class: Class, seed: u64) -> Case {
        Case {
            class,
            seed,
            design: programs::design(class, seed),
        }
    }

    /// The drawing in `variant` (the same for a case and variant every time).
    pub fn svg(&self, variant: Variant) -> String {
        let mut rng = Rng::of(&[0x5E1, self.class as u64, self.seed, variant as u64]);
        let d = &self.design;
        draw::svg(&d.shapes, &d.level, variant, self.step(), &mut rng)
    }

    /// The copies as plain paths at 6 decimals, in the design's order.
    fn truth(&self, places: &[Place]) -> String {
        let mut out = String::from("<svg xmlns=\"http://www.w3.org/2000/svg\">\n");
        for p in places {
            out.push_str(&draw::plain(&self.design.shapes[p.kind], p, 6));
        }
        out + "</svg>\n"
    }

    /// Whether `drawn` holds the design's copies, as `variant` draws them
    /// (within the hand placement's jitter).
    #[allow(dead_code)]
    pub fn holds(&self, drawn: &[u8], variant: Variant) -> Result<(), String> {
        same(
            self.truth(&self.design.level).as_bytes(),
            drawn,
            self.slack(variant),
        )
    }

    /// How far a copy may be off in `variant`, beyond the tolerance of
    /// `same_copies`: the hand placement's jitter (1 % of the step, 1°).
    fn slack(&self, variant: Variant) -> f64 {
        if variant == Variant::Jittered {
            0.02 * self.step()
        } else {
            0.0
        }
    }

    /// The distance between neighbouring copies, about.
    fn step(&self) -> f64 {
        let l = &self.design.level;
        let mut d: Vec<f64> = l
            .iter()
            .map(|a| {
                l.iter()
                    .filter(|b| b.at != a.at)
                    .map(|b| a.at.distance(b.at))
                    .fold(f64::INFINITY, f64::min)
            })
            .filter(|d| d.is_finite())
            .collect();
        d.sort_by(f64::total_cmp);
        d.get(d.len() / 2).copied().unwrap_or(1.0)
    }
}

/// Why a drawing did not come back exact.
#[derive(Clone, Debug)]
pub struct Fail {
    pub kind: &'static str,
    pub detail: String,
}

/// What one inference gave.
#[derive(Clone, Debug)]
pub struct Outcome {
    pub exact: bool,
    pub redraws: bool,
    pub fail: Option<Fail>,
    pub ms: f64,
    /// The program's size over the SVG's.
    pub ratio: f64,
    /// Exact, and no number of the program (but its elements' outlines)
    /// is a short decimal blurred by the drawing's rounding (`15.0003`,
    /// `0.99998`, `-0.001`).
    pub clean: bool,
    pub program: String,
    /// A jittered drawing whose program draws as many copies: how far the
    /// drawing's copies are from the clean design's, and the program's
    /// (mean outline distance): `--symmetrize` regularizes when the second
    /// is no more than the first.
    pub noise: Option<(f64, f64)>,
}

/// Infers `case` drawn in `variant` and checks the program.
pub fn check(case: &Case, variant: Variant) -> Outcome {
    let svg = case.svg(variant);
    let start = Instant::now();
    let program = infer_program(&svg, variant == Variant::Jittered);
    let ms = start.elapsed().as_secs_f64() * 1e3;
    let mut o = Outcome {
        exact: false,
        redraws: false,
        fail: None,
        ms,
        ratio: 0.0,
        clean: false,
        program: String::new(),
        noise: None,
    };
    let program = match program {
        Ok(p) => p,
        Err(f) => {
            o.fail = Some(f);
            return o;
        }
    };
    o.ratio = program.len() as f64 / svg.len() as f64;
    let blurred = blurred(&program);
    let slack = case.slack(variant);
    let judged = judge(case, &program, slack, variant == Variant::Shuffled);
    o.redraws = judged.0;
    o.fail = judged.1;
    o.exact = o.fail.is_none();
    o.clean = o.exact && blurred.is_empty();
    if variant == Variant::Jittered {
        o.noise = noise(case, svg.as_bytes(), &program);
    }
    o.program = program;
    o
}

/// (Redraws, why it is not exact.) `rigid`: the drawing does not say where
/// the design starts (its copies are in random order), so a next moved
/// rigidly predicts as well (a row extended at its other end), and so does
/// a sequence extended at its other end (`Design::before`), moved rigidly.
fn judge(case: &Case, program: &str, slack: f64, rigid: bool) -> (bool, Option<Fail>) {
    let fail = |kind, detail| Some(Fail { kind, detail });
    let level = case.truth(&case.design.level);
    let drawn = match run(program, &[]) {
        Ok(d) => d,
        Err(e) => return (false, fail("run", e)),
    };
    if let Err(e) = same(level.as_bytes(), &drawn, slack) {
        return (false, fail("redraw", e));
    }
    let counts = counts(program);
    if counts.is_empty() {
        return (
            true,
            fail("no count", "the program has no `const …_N`".into()),
        );
    }
    let defines: Vec<String> = counts
        .iter()
        .map(|(n, v)| format!("{n}={}", v + 1))
        .collect();
    let next = case.truth(&case.design.next);
    let before = case.truth(&case.design.before);
    let from_start = |d: &[u8]| {
        rigid
            && !case.design.before.is_empty()
            && congruent(before.as_bytes(), d, slack, rigid).is_ok()
    };
    match run(program, &defines) {
        Ok(d) if from_start(&d) => (true, None),
        Ok(d) => match congruent(next.as_bytes(), &d, slack, rigid) {
            Ok(()) => (true, None),
            Err(e) => (true, fail("predict", format!("{}: {e}", defines.join(" ")))),
        },
        Err(e) => (true, fail("predict", e)),
    }
}

/// The program inferred from `svg` (element inference as `lsyc infer`
/// runs it, with `--symmetrize` if asked).
fn infer_program(svg: &str, symmetrize: bool) -> Result<String, Fail> {
    let mut opts = infer::Options::default();
    opts.elements.symmetrize = symmetrize;
    let fail = |kind, detail: String| Fail { kind, detail };
    match infer::from_svg(svg.as_bytes(), "design.svg", &opts, &mut |_| {}) {
        Inferred::Lines(_) => Err(fail("lines", "read as a line drawing".into())),
        Inferred::Elements { elements, .. } => match elements {
            Ok(inf) => Ok(inf.text),
            Err(e) => Err(fail("error", e.to_string())),
        },
    }
}

/// The numbers of a program, outside its elements' outlines, that lie
/// within 0.005 % (or 0.0005) of a short decimal without being it: what the
/// drawing's rounding left in a number a person writes. A short decimal has
/// at most two places and three significant digits (`15`, `0.25`, `22.5`;
/// not `66.48` or `111.33`, which a measured number of three places, such
/// as a chord or where the design starts, is near by chance alone).
pub fn blurred(program: &str) -> Vec<String> {
    let mut out = Vec::new();
    for line in program.lines() {
        let line = line.trim();
        if line.starts_with("//") || line.starts_with("element") || line.starts_with("path") {
            continue;
        }
        let mut token = String::new();
        for ch in line.chars().chain(std::iter::once(' ')) {
            if ch.is_ascii_digit() || ch == '.' || (ch == '-' && token.is_empty()) {
                token.push(ch);
                continue;
            }
            if let Ok(v) = token.parse::<f64>() {
                let short = (v * 100.0).round() / 100.0;
                let near = (v - short).abs() <= (5e-5 * short.abs()).max(5e-4);
                let digits = format!("{short}")
                    .chars()
                    .filter(char::is_ascii_digit)
                    .collect::<String>();
                let significant = digits.trim_start_matches('0').trim_end_matches('0').len();
                if near && v != short && significant <= 3 {
                    out.push(token.clone());
                }
            }
            token.clear();
        }
    }
    out
}

/// `const NAME_N = K;` of a program: its counts.
fn counts(program: &str) -> Vec<(String, i64)> {
    program
        .lines()
        .filter_map(|l| {
            let rest = l.trim().strip_prefix("const ")?.strip_suffix(';')?;
            let (name, value) = rest.split_once(" = ")?;
            let value: i64 = value.trim().parse().ok()?;
            name.ends_with("_N").then(|| (name.to_string(), value))
        })
        .collect()
}

/// The SVG `lsyc run` draws from `program` with `defines` (`NAME=VALUE`).
fn run(program: &str, defines: &[String]) -> Result<Vec<u8>, String> {
    let dir = tempfile::tempdir().map_err(|e| e.to_string())?;
    let prog = dir.path().join("design.lsy");
    let out = dir.path().join("design.svg");
    std::fs::write(&prog, program).map_err(|e| e.to_string())?;
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_lsyc"));
    cmd.arg("run").arg(&prog).arg("-o").arg(&out);
    for d in defines {
        cmd.arg("-D").arg(d);
    }
    let done = cmd.output().map_err(|e| e.to_string())?;
    if !done.status.success() {
        return Err(String::from_utf8_lossy(&done.stderr).trim().to_string());
    }
    std::fs::read(&out).map_err(|e| e.to_string())
}

/// A copy as read back: its box centre, its box diagonal and its outline.
struct Copy {
    centre: DVec2,
    size: f64,
    outline: Vec<Vec<DVec2>>,
}

impl Copy {
    /// Turned by `turn` radians about `from`, then moved from `from` to `to`.
    fn moved(&self, from: DVec2, turn: f64, to: DVec2) -> Copy {
        let r = DVec2::from_angle(turn);
        let put = |p: DVec2| to + r.rotate(p - from);
        Copy {
            centre: put(self.centre),
            size: self.size,
            outline: self
                .outline
                .iter()
                .map(|l| l.iter().map(|&p| put(p)).collect())
                .collect(),
        }
    }
}

fn copies(svg: &[u8]) -> Result<Vec<Copy>, String> {
    let d = lsyc::infer::elements::read::read(svg).map_err(|e| format!("{e:?}"))?;
    Ok(d.elements
        .into_iter()
        .map(|e| Copy {
            centre: (e.min + e.max) / 2.0,
            size: (e.max - e.min).length(),
            outline: e.outline,
        })
        .collect())
}

/// How far the copies of `drawing` and of what `program` draws are from
/// the clean design's, each a mean over the design's copies; `None` unless
/// both hold as many copies as the design.
fn noise(case: &Case, drawing: &[u8], program: &str) -> Option<(f64, f64)> {
    let truth = copies(case.truth(&case.design.level).as_bytes()).ok()?;
    let input = mean_off(&truth, &copies(drawing).ok()?)?;
    let output = mean_off(&truth, &copies(&run(program, &[]).ok()?).ok()?)?;
    Some((input, output))
}

/// The mean over `t`'s copies of the outline distance to the nearest of
/// `d`'s (as `same_copies` finds it); `None` for another count.
fn mean_off(t: &[Copy], d: &[Copy]) -> Option<f64> {
    if t.len() != d.len() || t.is_empty() {
        return None;
    }
    let sum: f64 = t
        .iter()
        .map(|c| {
            let mut near: Vec<&Copy> = d.iter().collect();
            near.sort_by(|a, b| {
                a.centre
                    .distance(c.centre)
                    .total_cmp(&b.centre.distance(c.centre))
            });
            near.iter()
                .take(4)
                .map(|n| hausdorff(&c.outline, &n.outline).max(hausdorff(&n.outline, &c.outline)))
                .fold(f64::INFINITY, f64::min)
        })
        .sum();
    Some(sum / t.len() as f64)
}

/// Whether `drawn` holds the copies of `truth` (see `same_copies`).
fn same(truth: &[u8], drawn: &[u8], slack: f64) -> Result<(), String> {
    same_copies(&copies(truth)?, &copies(drawn)?, slack)
}

/// Whether `drawn` holds the copies of `truth`, or (if `rigid`) of `truth`
/// turned and moved: a turn about the copies' mean centre that takes the
/// copy farthest from it to a drawn copy as far from theirs.
fn congruent(truth: &[u8], drawn: &[u8], slack: f64, rigid: bool) -> Result<(), String> {
    let (t, d) = (copies(truth)?, copies(drawn)?);
    let first = same_copies(&t, &d, slack);
    if first.is_ok() || !rigid || t.len() != d.len() || t.is_empty() {
        return first;
    }
    let mean = |cs: &[Copy]| cs.iter().map(|c| c.centre).sum::<DVec2>() / cs.len() as f64;
    let (ct, cd) = (mean(&t), mean(&d));
    let far = |c: &&Copy| c.centre.distance(ct);
    let Some(a) = t.iter().max_by(|x, y| far(x).total_cmp(&far(y))) else {
        return first;
    };
    let reach = a.centre.distance(ct);
    let tol = 0.05 * a.size + 1e-3 * reach + slack;
    for c in d
        .iter()
        .filter(|c| (c.centre.distance(cd) - reach).abs() <= tol)
    {
        let turn = (c.centre - cd).to_angle() - (a.centre - ct).to_angle();
        let moved: Vec<Copy> = t.iter().map(|x| x.moved(ct, turn, cd)).collect();
        if same_copies(&moved, &d, slack).is_ok() {
            return Ok(());
        }
    }
    first
}

/// Whether `d` holds the copies of `t`, each within 2 % of its size or
/// 0.1 % of the drawing's diagonal, whichever is more (plus `slack`), of a
/// drawn copy, and no more.
fn same_copies(t: &[Copy], d: &[Copy], slack: f64) -> Result<(), String> {
    if t.len() != d.len() {
        return Err(format!("{} copies drawn for {}", d.len(), t.len()));
    }
    let (lo, hi) = t.iter().flat_map(|c| c.outline.iter().flatten()).fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    let diagonal = (hi - lo).length();
    for (i, c) in t.iter().enumerate() {
        let tol = (0.02 * c.size).max(1e-3 * diagonal) + slack;
        // The nearest of the few drawn copies centred nearest (copies may
        // overlap: a tree's two branches start at one point).
        let mut near: Vec<&Copy> = d.iter().collect();
        near.sort_by(|a, b| {
            a.centre
                .distance(c.centre)
                .total_cmp(&b.centre.distance(c.centre))
        });
        let off = near
            .iter()
            .take(4)
            .map(|n| hausdorff(&c.outline, &n.outline).max(hausdorff(&n.outline, &c.outline)))
            .fold(f64::INFINITY, f64::min);
        if off > tol {
            return Err(format!(
                "copy {} at ({:.2}, {:.2}) is {off:.3} off (tolerance {tol:.3})",
                i + 1,
                c.centre.x,
                c.centre.y
            ));
        }
    }
    Ok(())
}

/// The farthest any vertex of `a` is from the polylines of `b`.
fn hausdorff(a: &[Vec<DVec2>], b: &[Vec<DVec2>]) -> f64 {
    a.iter()
        .flatten()
        .map(|&p| {
            b.iter()
                .flat_map(|l| l.windows(2))
                .map(|w| to_segment(p, w[0], w[1]))
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max)
}

fn to_segment(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    let ab = b - a;
    let t = if ab.length_squared() > 0.0 {
        ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    p.distance(a + ab * t)
}

/// One class and variant's counts.
#[derive(Clone, Debug, Default)]
pub struct Cell {
    pub total: usize,
    pub exact: usize,
    pub redraws: usize,
    pub ms: Vec<f64>,
    pub ratios: Vec<f64>,
    pub clean: usize,
    /// Jittered drawings measured (`Outcome::noise`), those whose program
    /// is no farther from the clean design than the drawing, and each
    /// program's distance over the drawing's.
    pub measured: usize,
    pub closer: usize,
    pub shrink: Vec<f64>,
    /// Failure kind → (seed, detail).
    pub fails: BTreeMap<&'static str, Vec<(u64, String)>>,
}

/// The results of a run.
#[derive(Clone, Debug, Default)]
pub struct Table {
    pub cells: BTreeMap<(Class, Variant), Cell>,
}

impl Table {
    pub fn add(&mut self, case: &Case, variant: Variant, o: &Outcome) {
        let c = self.cells.entry((case.class, variant)).or_default();
        c.total += 1;
        c.exact += usize::from(o.exact);
        c.redraws += usize::from(o.redraws);
        c.ms.push(o.ms);
        c.ratios.push(o.ratio);
        c.clean += usize::from(o.clean);
        if let Some((input, output)) = o.noise {
            c.measured += 1;
            c.closer += usize::from(output <= input);
            c.shrink.push(output / input.max(1e-12));
        }
        if let Some(f) = &o.fail {
            c.fails
                .entry(f.kind)
                .or_default()
                .push((case.seed, f.detail.clone()));
        }
    }

    pub fn get(&self, class: Class, variant: Variant) -> Cell {
        self.cells
            .get(&(class, variant))
            .cloned()
            .unwrap_or_default()
    }

    /// The table: class × variant → exact/total (redrawn), then the median
    /// program size over SVG size, timings and failure kinds.
    pub fn render(&self) -> String {
        let classes: Vec<Class> = Class::ALL
            .into_iter()
            .filter(|c| self.cells.keys().any(|(k, _)| k == c))
            .collect();
        let variants: Vec<Variant> = Variant::ALL
            .into_iter()
            .filter(|v| self.cells.keys().any(|(_, k)| k == v))
            .collect();
        let grid = |title: &str, f: &dyn Fn(&Cell) -> String| {
            let mut out = format!("{title}\n{:<8}", "class");
            for v in &variants {
                out.push_str(&format!("{:>20}", v.name()));
            }
            out.push('\n');
            for &c in &classes {
                out.push_str(&format!("{:<8}", c.name()));
                for &v in &variants {
                    out.push_str(&format!("{:>20}", f(&self.get(c, v))));
                }
                out.push('\n');
            }
            out
        };
        let median = |xs: &[f64]| {
            let mut xs = xs.to_vec();
            xs.sort_by(f64::total_cmp);
            xs.get(xs.len() / 2).copied().unwrap_or(0.0)
        };
        let mut out = grid("exact/total (redrawn, exact with clean numbers)", &|c| {
            format!("{}/{} ({}, {})", c.exact, c.total, c.redraws, c.clean)
        });
        out += &grid("\nprogram size / SVG size, median", &|c| {
            format!("{:.2}", median(&c.ratios))
        });
        out += &grid("\nms per inference: median / max", &|c| {
            let max = c.ms.iter().copied().fold(0.0, f64::max);
            format!("{:.0} / {max:.0}", median(&c.ms))
        });
        if variants.contains(&Variant::Jittered) {
            out.push_str("\n--symmetrize on jittered drawings: programs no farther from the clean design than the drawing / measured, median program distance / drawing distance\n");
            for &c in &classes {
                let cell = self.get(c, Variant::Jittered);
                out.push_str(&format!(
                    "{:<8}{:>8}/{:<4}{:>8.2}\n",
                    c.name(),
                    cell.closer,
                    cell.measured,
                    median(&cell.shrink)
                ));
            }
        }
        out.push_str("\nfailures by kind\n");
        for ((c, v), cell) in &self.cells {
            for (kind, seeds) in &cell.fails {
                let list: Vec<String> = seeds.iter().take(12).map(|s| s.0.to_string()).collect();
                out.push_str(&format!(
                    "{:<8}{:<10}{kind:<10}{:>4}  seeds {}\n",
                    c.name(),
                    v.name(),
                    seeds.len(),
                    list.join(" ")
                ));
            }
        }
        out
    }
}
