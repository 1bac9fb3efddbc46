//! Choosing between programs inferred from one drawing read in different
//! ways (round kinds turned along the drawing's axes, along their
//! neighbours, out of their ring, along the path through them): the one
//! that writes the fewest numbers among those that put every element where
//! the drawing has it.
//!
//! Owns: a program's description length (`numbers`) and how far the
//! elements it draws are from the drawing's (`misfit`, by deriving and
//! drawing it as `lsyc run` does). Must not infer.

use crate::turtle::Sink;
use glam::{DVec2, DVec3};

/// How many numbers a program writes outside its comments and its
/// elements' outlines: its description length.
pub fn numbers(text: &str) -> usize {
    text.lines()
        .map(str::trim_start)
        .filter(|l| !l.starts_with("//") && !l.starts_with("element") && !l.starts_with("path"))
        .map(literals)
        .sum()
}

/// The number literals on a line: runs of digits and points not inside a
/// name (`P1_N` is a name, not the number 1).
fn literals(line: &str) -> usize {
    let chars: Vec<char> = line.chars().collect();
    let word: fn(char) -> bool = |c| c.is_alphanumeric() || c == '_';
    let (mut i, mut count) = (0, 0);
    while i < chars.len() {
        let run: fn(char) -> bool = if chars[i].is_ascii_digit() {
            count += 1;
            |c| c.is_ascii_digit() || c == '.'
        } else if word(chars[i]) {
            word
        } else {
            i += 1;
            continue;
        };
        while i < chars.len() && run(chars[i]) {
            i += 1;
        }
    }
    count
}

/// The mean distance from each of `places` (where the drawing's elements'
/// frames are) to the nearest element the program `text` draws; `None` if
/// it does not run or draws another number of elements.
pub fn misfit(text: &str, places: &[DVec2]) -> Option<f64> {
    let drawn = drawn(text)?;
    if drawn.len() != places.len() || places.is_empty() {
        return None;
    }
    let index = crate::geometry::index::PointGrid::new(&drawn);
    let sum: f64 = places
        .iter()
        .map(|&p| {
            let near = index.nearest(p, 1);
            near.first()
                .map_or(f64::INFINITY, |&i| p.distance(drawn[i]))
        })
        .sum();
    Some(sum / places.len() as f64)
}

/// Where the program `text` draws its elements (seed 0).
fn drawn(text: &str) -> Option<Vec<DVec2>> {
    let mut sink = Places::default();
    crate::infer::program::draw(text, 0, &mut sink)?;
    Some(sink.0)
}

#[derive(Default)]
struct Places(Vec<DVec2>);

impl Sink for Places {
    fn segment(&mut self, _a: DVec3, _b: DVec3, _width: f64, _color: u32) {}
    fn polygon(&mut self, _points: &[DVec3], _color: u32) {}
    fn element(&mut self, _i: u16, at: DVec3, _h: DVec3, _l: DVec3, _s: f64, _c: u32) {
        self.0.push(at.truncate());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_count_what_a_program_writes_not_its_comments_or_outlines() {
        let text = "// 3 rules\nelement A { path \"M0 0 L1 2 Z\"; }\nconst N = 12;\n\
                    lsystem S {\n    derive N + 1;\n    axiom f(2.5)+(90) A;\n}\n";
        assert_eq!(numbers(text), 4);
        let names = "lsystem S {\n    axiom P2(P2_N) f(0.5) Q1;\n}\n";
        assert_eq!(numbers(names), 1);
    }

    #[test]
    fn a_program_drawing_its_elements_elsewhere_misfits() {
        let text = "element A { path \"M0 0 L1 0 L0 1 Z\"; }\n\
                    lsystem S {\n    derive 0;\n    axiom A f(10) A;\n}\n";
        let here = [DVec2::ZERO, DVec2::new(0.0, 10.0)];
        assert_eq!(misfit(text, &here), Some(0.0));
        let there = [DVec2::ZERO, DVec2::new(0.0, 12.0)];
        assert_eq!(misfit(text, &there), Some(1.0));
        assert_eq!(misfit(text, &here[..1]), None);
    }
}
