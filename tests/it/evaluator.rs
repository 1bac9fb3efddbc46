//! One evaluator: the value the checker gives a constant is the value a run
//! computes for it, over every constant of every program in the repository,
//! for several seeds (random constants included).

use crate::support::{lsy_files, read_text, rel};
use lsyc::check::Value;
use lsyc::{compile, derive, frontend};

/// Each numeric constant, passed through an axiom, arrives in the derived
/// string with the value the checker computed.
#[test]
fn checked_constants_are_the_values_a_run_computes() {
    let mut compared = 0;
    let mut random = 0;
    for path in lsy_files(&["lang-examples", "tests/data/check/ok"]) {
        let text = read_text(&path);
        for seed in [0u64, 7, 12345] {
            let fe = frontend::run_seeded(&text, Vec::new(), &[], seed);
            let Some(checked) = fe.checked.as_ref().filter(|_| !fe.has_errors()) else {
                continue;
            };
            let names: Vec<(&String, f64, bool)> = checked
                .consts
                .iter()
                .filter_map(|(n, c)| match c.value {
                    Value::Num(v) => Some((n, v, c.random)),
                    Value::Bool(_) => None,
                })
                .collect();
            if names.is_empty() {
                continue;
            }
            let args: Vec<&str> = names.iter().map(|(n, _, _)| n.as_str()).collect();
            let probe = format!(
                "{text}\nmodule ZzProbe({});\nlsystem ZzProbeSystem {{ axiom ZzProbe({}); }}\n",
                (0..args.len())
                    .map(|i| format!("p{i}"))
                    .collect::<Vec<_>>()
                    .join(", "),
                args.join(", ")
            );
            let fe = frontend::run_seeded(&probe, Vec::new(), &[], seed);
            let checked = fe.checked.as_ref().expect("checked");
            let prog = compile::compile(&fe.file, checked, Some("ZzProbeSystem"))
                .unwrap_or_else(|e| panic!("{}: {e}", rel(&path)));
            let s = derive::axiom(&prog, &[], seed).expect("the axiom evaluates");
            assert_eq!(s.params.len(), names.len(), "{}", rel(&path));
            for ((name, want, is_random), got) in names.iter().zip(&s.params) {
                assert_eq!(
                    got.to_bits(),
                    want.to_bits(),
                    "{}: constant `{name}` is {want} to the checker but {got} in a run (seed {seed})",
                    rel(&path)
                );
                compared += 1;
                random += usize::from(*is_random);
            }
        }
    }
    assert!(compared > 30, "only {compared} constants compared");
    assert!(random > 0, "no random constant in the corpus");
}

/// A random constant is drawn once per run: the same seed gives the same
/// value, another seed another value, and every use sees the one value.
#[test]
fn a_random_constant_is_drawn_once_per_seed() {
    let text = "const r = rand();\nconst twice = r + r;\nlsystem A { axiom A(r, twice); }\n";
    let value = |seed: u64| {
        let fe = frontend::run_seeded(text, Vec::new(), &[], seed);
        let checked = fe.checked.expect("checked");
        let Value::Num(r) = checked.consts["r"].value else {
            panic!("r is a number")
        };
        let Value::Num(t) = checked.consts["twice"].value else {
            panic!("twice is a number")
        };
        assert!(checked.consts["r"].random && checked.consts["twice"].random);
        assert_eq!(t, r + r, "every use of `r` sees one value");
        r
    };
    assert_eq!(value(3).to_bits(), value(3).to_bits());
    assert_ne!(value(3).to_bits(), value(4).to_bits());
}
