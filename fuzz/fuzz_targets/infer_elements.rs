//! Fuzzes `lsyc infer ART.svg` as the command line runs it: SVG bytes → the
//! reader (usvg behind lsyc's own checks) → instancing → rules → the
//! program. Any input must give a program or an error, never a panic; a
//! program must parse and be canonical.
#![no_main]

use libfuzzer_sys::fuzz_target;
use lsyc::infer::elements::{self, Options};
use lsyc::{fmt, parser};

fuzz_target!(|data: &[u8]| {
    let Ok(inferred) = elements::from_svg(data, "fuzz.svg", &Options::default(), &mut |_| {})
    else {
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
