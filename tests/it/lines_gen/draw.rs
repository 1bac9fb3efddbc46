//! An independent drawer: its own rewriting and its own turtle (not
//! lsyc's), and its own SVG writer, in the variants a drawing comes in.
//!
//! The turtle starts at the origin heading +y; a step is 1 long; `+` turns
//! counter-clockwise by δ. Headings are whole numbers of δ, so that steps
//! along the same heading are the same vector (from a table when 360/δ is
//! whole).

use super::programs::Program;
use super::rng::Rng;
use glam::DVec2;
use std::collections::HashMap;

/// The string at depth `n`, by this module's own rewriting.
pub fn derive(p: &Program, n: u32) -> Vec<u8> {
    let mut table: Vec<Option<&[u8]>> = vec![None; 128];
    for (c, w) in &p.rules {
        table[*c as usize] = Some(w.as_bytes());
    }
    let mut s = p.axiom.as_bytes().to_vec();
    for _ in 0..n {
        let mut next = Vec::with_capacity(s.len() * 2);
        for &c in &s {
            match table[c as usize & 127] {
                Some(w) => next.extend_from_slice(w),
                None => next.push(c),
            }
        }
        s = next;
    }
    s
}

/// Unit vectors of headings k·δ from +y.
struct Headings {
    delta: f64,
    table: Vec<DVec2>,
}

impl Headings {
    fn new(delta: f64) -> Headings {
        let m = 360.0 / delta;
        let table = if (m - m.round()).abs() < 1e-9 {
            (0..m.round() as i64).map(|k| unit(delta, k)).collect()
        } else {
            Vec::new()
        };
        Headings { delta, table }
    }

    fn get(&self, k: i64) -> DVec2 {
        if self.table.is_empty() {
            unit(self.delta, k)
        } else {
            self.table[k.rem_euclid(self.table.len() as i64) as usize]
        }
    }

    /// Whether two headings are the same direction.
    fn same(&self, a: i64, b: i64) -> bool {
        if self.table.is_empty() {
            a == b
        } else {
            (a - b).rem_euclid(self.table.len() as i64) == 0
        }
    }
}

fn unit(delta: f64, k: i64) -> DVec2 {
    let a = (90.0 + delta * k as f64).to_radians();
    DVec2::new(a.cos(), a.sin())
}

/// Where the successor `w` ends when drawn from the origin heading +y: a
/// whole number of steps straight ahead, heading +y again (`None`
/// otherwise).
pub fn span(w: &str, delta: f64) -> Option<usize> {
    let h = Headings::new(delta);
    let (mut pos, mut k) = (DVec2::ZERO, 0i64);
    for c in w.chars() {
        match c {
            '+' => k += 1,
            '-' => k -= 1,
            'F' | 'f' => pos += h.get(k),
            _ => {}
        }
    }
    let along = pos.y.round();
    (h.same(k, 0) && pos.x.abs() < 1e-9 && (pos.y - along).abs() < 1e-9 && along >= 1.0)
        .then_some(along as usize)
}

/// Where the successor `w` ends, drawn from the origin heading +y with
/// steps and moves of 1 (branches come back where they started).
pub fn chord(w: &str, delta: f64) -> DVec2 {
    let h = Headings::new(delta);
    let (mut pos, mut k) = (DVec2::ZERO, 0i64);
    let mut stack = Vec::new();
    for c in w.chars() {
        match c {
            '+' => k += 1,
            '-' => k -= 1,
            '[' => stack.push((pos, k)),
            ']' => (pos, k) = stack.pop().unwrap_or((pos, k)),
            'F' | 'G' | 'H' | 'f' => pos += h.get(k),
            _ => {}
        }
    }
    pos
}

/// A drawing: strokes (polylines in drawing order, a new one after `]`
/// and after a move, collinear steps merged) and its unit steps.
#[derive(Clone, Debug, Default)]
pub struct Drawing {
    pub strokes: Vec<Vec<DVec2>>,
    pub steps: Vec<(DVec2, DVec2)>,
}

/// Draws the string `s` of `p`.
pub fn draw(p: &Program, s: &[u8]) -> Drawing {
    let h = Headings::new(p.angle);
    let mut draws = [false; 128];
    for &d in &p.draws {
        draws[d as usize] = true;
    }
    let mut out = Drawing::default();
    let (mut pos, mut k) = (DVec2::ZERO, 0i64);
    let mut stack = Vec::new();
    // The current stroke and the heading of its last step.
    let mut pen: Option<(Vec<DVec2>, i64)> = None;
    let lift = |pen: &mut Option<(Vec<DVec2>, i64)>, out: &mut Drawing| {
        if let Some((line, _)) = pen.take() {
            out.strokes.push(line);
        }
    };
    for &c in s {
        match c {
            b'+' => k += 1,
            b'-' => k -= 1,
            b'[' => stack.push((pos, k)),
            b']' => {
                (pos, k) = stack.pop().expect("balanced brackets");
                lift(&mut pen, &mut out);
            }
            b'f' => {
                pos += h.get(k);
                lift(&mut pen, &mut out);
            }
            c if draws[c as usize & 127] => {
                let next = pos + h.get(k);
                out.steps.push((pos, next));
                match &mut pen {
                    Some((line, last)) if h.same(*last, k) => {
                        *line.last_mut().expect("a stroke has points") = next;
                    }
                    Some((line, last)) => {
                        line.push(next);
                        *last = k;
                    }
                    None => pen = Some((vec![pos, next], k)),
                }
                pos = next;
            }
            _ => {}
        }
    }
    lift(&mut pen, &mut out);
    out
}

/// A unit step as a key: its ends rounded to 10⁻⁶ of a step, in order.
pub fn unit_key(a: DVec2, b: DVec2) -> [i64; 4] {
    let r = |p: DVec2| [(p.x * 1e6).round() as i64, (p.y * 1e6).round() as i64];
    let (ra, rb) = (r(a), r(b));
    if ra <= rb {
        [ra[0], ra[1], rb[0], rb[1]]
    } else {
        [rb[0], rb[1], ra[0], ra[1]]
    }
}

// ------------------------------------------------------------ SVG

/// How a drawing is written.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Variant {
    /// As drawn: one polyline per stroke, step 1, 6 decimals.
    Clean,
    /// Turned, scaled (0.5–20) and moved; 4 decimals.
    Rotated,
    /// Rotated, then every vertex moved by up to 0.2 % of the bounding
    /// box's diagonal (uniform in a disc; a vertex shared by strokes moves
    /// once); 3 decimals.
    Jittered,
    /// Rotated, one `<path>` per unit step.
    Split,
    /// Split, the paths in random order, about half of them reversed.
    Shuffled,
    /// Jittered, but by at most a fifth of a step: the noise of a careful
    /// tracing, which leaves every step and turn readable (0.2 % of the
    /// diagonal is more than that for most drawings of a few hundred steps
    /// across, up to a whole step). Last, so that the other variants'
    /// random draws stay as they were.
    Noisy,
}

impl Variant {
    pub const ALL: [Variant; 6] = [
        Variant::Clean,
        Variant::Rotated,
        Variant::Jittered,
        Variant::Split,
        Variant::Shuffled,
        Variant::Noisy,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Variant::Clean => "clean",
            Variant::Rotated => "rotated",
            Variant::Jittered => "jittered",
            Variant::Split => "split",
            Variant::Shuffled => "shuffled",
            Variant::Noisy => "noisy",
        }
    }

    /// (The bench's `--variant`.)
    #[allow(dead_code)]
    pub fn parse(s: &str) -> Option<Variant> {
        Variant::ALL.into_iter().find(|v| v.name() == s)
    }
}

/// A similarity: turn (degrees, counter-clockwise), scale, then shift.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    pub turn: f64,
    pub scale: f64,
    pub shift: DVec2,
}

impl Transform {
    pub const IDENTITY: Transform = Transform {
        turn: 0.0,
        scale: 1.0,
        shift: DVec2::ZERO,
    };

    pub fn random(rng: &mut Rng) -> Transform {
        Transform {
            turn: rng.unit() * 360.0,
            scale: 0.5 + rng.unit() * 19.5,
            shift: DVec2::new(rng.unit() * 1000.0 - 500.0, rng.unit() * 1000.0 - 500.0),
        }
    }

    pub fn apply(&self, p: DVec2) -> DVec2 {
        let (s, c) = self.turn.to_radians().sin_cos();
        DVec2::new(p.x * c - p.y * s, p.x * s + p.y * c) * self.scale + self.shift
    }
}

/// A number with at most `decimals` decimals, no trailing zeros.
fn num(v: f64, decimals: usize) -> String {
    let s = format!("{v:.decimals$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    };
    if s == "-0" { "0".to_string() } else { s }
}

/// A point in SVG user space (y down).
fn point(p: DVec2, decimals: usize) -> String {
    format!("{},{}", num(p.x, decimals), num(-p.y, decimals))
}

const HEAD: &str = "<svg xmlns=\"http://www.w3.org/2000/svg\">\n";
const STYLE: &str = "fill=\"none\" stroke=\"black\"";

/// The drawing `d` as SVG in `variant`, placed by `t` (not for `Clean`,
/// which is written as drawn); `rng` draws the jitter and the shuffle.
pub fn svg(d: &Drawing, variant: Variant, t: &Transform, rng: &mut Rng) -> String {
    let mut out = String::from(HEAD);
    match variant {
        Variant::Clean | Variant::Rotated | Variant::Jittered | Variant::Noisy => {
            let (t, decimals) = match variant {
                Variant::Clean => (Transform::IDENTITY, 6),
                Variant::Rotated => (*t, 4),
                _ => (*t, 3),
            };
            let mut strokes: Vec<Vec<DVec2>> = d
                .strokes
                .iter()
                .map(|l| l.iter().map(|&p| t.apply(p)).collect())
                .collect();
            match variant {
                Variant::Jittered => jitter(&mut strokes, &d.strokes, f64::INFINITY, rng),
                // A step is `t.scale` long.
                Variant::Noisy => jitter(&mut strokes, &d.strokes, t.scale / 5.0, rng),
                _ => {}
            }
            for l in &strokes {
                let pts: Vec<String> = l.iter().map(|&p| point(p, decimals)).collect();
                out.push_str(&format!(
                    "<polyline points=\"{}\" {STYLE}/>\n",
                    pts.join(" ")
                ));
            }
        }
        Variant::Split | Variant::Shuffled => {
            let mut steps: Vec<(DVec2, DVec2)> = d
                .steps
                .iter()
                .map(|&(a, b)| (t.apply(a), t.apply(b)))
                .collect();
            if variant == Variant::Shuffled {
                rng.shuffle(&mut steps);
                for s in &mut steps {
                    if rng.chance(0.5) {
                        *s = (s.1, s.0);
                    }
                }
            }
            for (a, b) in steps {
                out.push_str(&format!(
                    "<path d=\"M{} L{}\" {STYLE}/>\n",
                    point(a, 4).replace(',', " "),
                    point(b, 4).replace(',', " ")
                ));
            }
        }
    }
    out.push_str("</svg>\n");
    out
}

/// Moves every vertex of `strokes` by up to 0.2 % of their bounding box's
/// diagonal or `most`, whichever is less, uniform in a disc; vertices at the
/// same place in the drawing (`clean`, unit steps) move together.
fn jitter(strokes: &mut [Vec<DVec2>], clean: &[Vec<DVec2>], most: f64, rng: &mut Rng) {
    let (lo, hi) = strokes.iter().flatten().fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    let radius = (0.002 * (hi - lo).length()).min(most);
    let mut moved: HashMap<[i64; 2], DVec2> = HashMap::new();
    for (line, orig) in strokes.iter_mut().zip(clean) {
        for (p, o) in line.iter_mut().zip(orig) {
            let key = [(o.x * 1e6).round() as i64, (o.y * 1e6).round() as i64];
            let by = *moved.entry(key).or_insert_with(|| {
                let r = radius * rng.unit().sqrt();
                let a = rng.unit() * std::f64::consts::TAU;
                DVec2::new(a.cos(), a.sin()) * r
            });
            *p += by;
        }
    }
}
