//! How often element inference gives back random designs (issue 33): the
//! large run of `tests/it/elements_random.rs`, in release.
//!
//! `cargo bench --bench elements_rate -- [--per-class N] [--first SEED]
//! [--class CLASS]… [--variant VARIANT]… [--threads N] [--show] [--write DIR]`
//!
//! Designs of each class (seeds SEED..SEED+N, default 0..100) are written by
//! the tests' own SVG writer in each variant and inferred; the table gives
//! exact/total (redrawn) per class and variant, the median program size over
//! the SVG's, the time per inference and the failures by kind. Each failure
//! is one line on stdout: `FAIL class seed variant kind: detail | design`.
//! `--show` prints each inferred program; `--write DIR` writes each drawing
//! (`CLASS-SEED-VARIANT.svg`) and program (`…-VARIANT.lsy`) into DIR.
//!
//! Classes: row ring spiral period grid linear tree. Variants: use plain
//! prim shuffled jittered.

#[path = "../tests/it/elements_gen/mod.rs"]
mod elements_gen;
#[path = "../tests/it/pool.rs"]
mod pool;
#[path = "../tests/it/rng.rs"]
#[allow(dead_code)]
mod rng;

use elements_gen::draw::Variant;
use elements_gen::programs::Class;
use std::time::Instant;

fn main() {
    let mut per_class = 100u64;
    let mut first = 0u64;
    let mut classes = Vec::new();
    let mut variants = Vec::new();
    let mut show = false;
    let mut threads = 1usize;
    let mut write: Option<std::path::PathBuf> = None;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = |what: &str| args.next().unwrap_or_else(|| panic!("{a} needs {what}"));
        match a.as_str() {
            "--per-class" => per_class = value("a number").parse().expect("--per-class N"),
            "--first" => first = value("a seed").parse().expect("--first SEED"),
            "--class" => {
                let v = value("a class");
                classes.push(Class::parse(&v).unwrap_or_else(|| panic!("no class {v}")));
            }
            "--variant" => {
                let v = value("a variant");
                variants.push(Variant::parse(&v).unwrap_or_else(|| panic!("no variant {v}")));
            }
            "--threads" => threads = value("a number").parse().expect("--threads N"),
            "--show" => show = true,
            "--write" => write = Some(value("a folder").into()),
            // What cargo bench passes on.
            "--bench" => {}
            other => panic!("unknown argument {other}"),
        }
    }
    if classes.is_empty() {
        classes = Class::ALL.to_vec();
    }
    if variants.is_empty() {
        variants = Variant::ALL.to_vec();
    }
    let start = Instant::now();
    let run = elements_gen::Run {
        classes: &classes,
        variants: &variants,
        first,
        per_class,
        threads,
    };
    let table = elements_gen::run(&run, &mut |case, v, o| {
        let name = format!("{}-{}-{}", case.class.name(), case.seed, v.name());
        if let Some(dir) = &write {
            std::fs::write(dir.join(format!("{name}.svg")), case.svg(v)).expect("writes");
            std::fs::write(dir.join(format!("{name}.lsy")), &o.program).expect("writes");
        }
        if show {
            let verdict = match (o.exact, o.clean) {
                (true, true) => "exact",
                (true, false) => "exact, numbers blurred",
                _ => "not exact",
            };
            let noise = o.noise.map_or(String::new(), |(i, p)| {
                format!(" (copies off the clean design: drawing {i:.3}, program {p:.3})")
            });
            println!(
                "== {name}: {verdict}{noise}\n{}\n{}",
                case.design.text, o.program
            );
        }
        if let Some(f) = &o.fail {
            println!(
                "FAIL {name} {}: {} | {}",
                f.kind, f.detail, case.design.text
            );
        }
    });
    println!("\n{}", table.render());
    println!(
        "{per_class} designs per class from seed {first}, {:.1} s",
        start.elapsed().as_secs_f64()
    );
}
