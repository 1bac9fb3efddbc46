//! Fuzzes `lsyc infer --skeleton SKETCH.svg` as the command line runs it:
//! SVG bytes → strokes → the tree → productions → the program, in 2D and
//! 3D. Any input must give a program or an error, never a panic; a program
//! must parse and be canonical.
#![no_main]

use libfuzzer_sys::fuzz_target;
use lsyc::infer::sketch::{self, Options};
use lsyc::{fmt, parser};

fuzz_target!(|data: &[u8]| {
    // The last byte picks 2D or 3D, so that both emitters are reached.
    let three_d = data.last().is_some_and(|b| b & 1 == 1);
    let opts = Options {
        three_d,
        ..Options::default()
    };
    let Ok(inferred) = sketch::from_svg(data, "fuzz.svg", &opts) else {
        return;
    };
    let parsed = parser::parse(&inferred.text);
    assert!(
        !parsed.diagnostics.iter().any(|d| d.is_error()),
        "the inferred program does not parse:\n{}",
        inferred.text
    );
    assert_eq!(fmt::format_file(&parsed.file), inferred.text);
});
