//! How often line-drawing inference gives back random programs (issue 32):
//! the large run of `tests/it/lines_random.rs`, in release.
//!
//! `cargo bench --bench lines_rate -- [--per-class N] [--first SEED]
//! [--class CLASS]… [--variant VARIANT]… [--threads N] [--show] [--write DIR]`
//!
//! Programs of each class (seeds SEED..SEED+N, default 0..200) are drawn
//! by the tests' independent drawer in each variant and inferred; the table
//! gives exact/total (same grammar up to renaming) per class and variant,
//! the median and largest time per inference, the failures by kind, and
//! how the programs were sampled. Each failure is one line on stdout:
//! `FAIL class seed variant kind: detail | program | found`. `--show`
//! prints each case's program text and the inferred one; `--write DIR`
//! writes each drawing (`CLASS-SEED-VARIANT.svg`, for `lsyc infer`) and
//! program (`CLASS-SEED.lsy`) into DIR. `--threads N` infers N programs at
//! once (the counts do not change unless the time budget is reached; the
//! times per inference then include the threads' contention).
//!
//! Classes: edge-1 edge-2 edge-3 node bracketed moves. Variants: clean
//! rotated jittered split shuffled noisy.

#[path = "../tests/it/lines_gen/mod.rs"]
mod lines_gen;
#[path = "../tests/it/pool.rs"]
mod pool;
#[path = "../tests/it/rng.rs"]
#[allow(dead_code)]
mod rng;

use lines_gen::draw::Variant;
use lines_gen::programs::Class;
use std::time::Instant;

fn main() {
    let mut per_class = 200u64;
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
    let run = lines_gen::Run {
        classes: &classes,
        variants: &variants,
        first,
        per_class,
        budget: None,
        threads,
    };
    let table = lines_gen::run(&run, &mut |case, v, o| {
        if let Some(dir) = &write {
            let name = format!("{}-{}-{}.svg", case.class.name(), case.seed, v.name());
            std::fs::write(dir.join(name), case.svg(v)).expect("writes the drawing");
            let name = format!("{}-{}.lsy", case.class.name(), case.seed);
            std::fs::write(dir.join(name), case.program.text()).expect("writes the program");
        }
        if show {
            println!(
                "== {} seed {} {}: {}\n{}",
                case.class.name(),
                case.seed,
                v.name(),
                if o.exact { "exact" } else { "not exact" },
                case.program.text()
            );
            if let Some(t) = &o.text {
                println!("{t}");
            }
        }
        if let Some(f) = &o.fail {
            println!(
                "FAIL {} {} {} {}: {} | {} | found {}",
                case.class.name(),
                case.seed,
                v.name(),
                f.kind(),
                f.detail(),
                case.program.describe(),
                o.found.as_deref().unwrap_or("-")
            );
        }
    });
    println!("\n{}", table.render());
    println!(
        "{} programs per class from seed {first}, {:.1} s",
        per_class,
        start.elapsed().as_secs_f64()
    );
}
