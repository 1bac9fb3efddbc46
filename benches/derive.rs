//! Derivation speed and memory, lsyc against the peer crate `symbios` (1.5.1),
//! side by side on the same systems:
//!
//! - `koch_1_9b`: the D0L Koch curve of ABOP fig. 1.9b (`F -> FF-F-F-F-FF`,
//!   axiom `F-F-F-F`) to depth 8;
//! - `monopodial_2_6`: the parametric monopodial tree of ABOP fig. 2.6 to depth 20;
//! - `row_of_trees`: the parametric row of trees of ABOP §1.10.3
//!   (`F(x) -> F(x*p)+F(x*h)--F(x*h)+F(x*q)`, axiom `F(1)`) to depth 11. Each
//!   step multiplies the `F`s by four, so depth 11 (9.8 M modules, 4.2 M
//!   parameters) is the size of the tree at depth 20; depth 19 would be 2.7·10¹¹.
//!
//! lsyc runs from the gallery programs in `lang-examples/` (the row of trees from
//! the program text below); symbios gets the same rules in its own syntax. Before timing, both engines derive each system once
//! and the two strings are compared module by module (symbol names, and parameter
//! values for the tree), so the throughput figures count the same work.
//!
//! Throughput is the final string's length divided by the time of the whole
//! derivation (all steps from the axiom). lsyc is timed on rayon's default pool
//! (all cores) and on a one-thread pool; symbios is single-threaded.
//!
//! Memory: a counting global allocator records the peak heap of one derivation
//! (everything each engine holds at once: both generations, chunk buffers, …),
//! printed with the live size of the result, as bytes per final module.
//!
//! Results are dropped outside the timed region for both engines
//! (`BatchSize::PerIteration`).
//!
//! `cargo bench --bench derive`.

use criterion::{BatchSize, Criterion, SamplingMode, Throughput, criterion_group};
use lsyc::compile::{self, Program};
use lsyc::derive::{self, Limits, ModString};
use std::alloc::{GlobalAlloc, Layout, System as SysAlloc};
use std::hint::black_box;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// The system allocator, counting bytes in use and their peak.
struct Counting;

static IN_USE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

fn grew(n: usize) {
    let now = IN_USE.fetch_add(n, Ordering::Relaxed) + n;
    PEAK.fetch_max(now, Ordering::Relaxed);
}

// SAFETY: every call is forwarded unchanged to the system allocator; the
// counters only observe sizes.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: same contract as the caller's.
        let p = unsafe { SysAlloc.alloc(layout) };
        if !p.is_null() {
            grew(layout.size());
        }
        p
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        // SAFETY: same contract as the caller's.
        let p = unsafe { SysAlloc.alloc_zeroed(layout) };
        if !p.is_null() {
            grew(layout.size());
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { SysAlloc.dealloc(ptr, layout) };
        IN_USE.fetch_sub(layout.size(), Ordering::Relaxed);
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: same contract as the caller's.
        let p = unsafe { SysAlloc.realloc(ptr, layout, new_size) };
        if !p.is_null() {
            IN_USE.fetch_sub(layout.size(), Ordering::Relaxed);
            grew(new_size);
        }
        p
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Runs `f` and returns its result with the peak heap growth while it ran.
fn peak_during<T>(f: impl FnOnce() -> T) -> (T, usize) {
    let base = IN_USE.load(Ordering::Relaxed);
    PEAK.store(base, Ordering::Relaxed);
    let out = f();
    (out, PEAK.load(Ordering::Relaxed) - base)
}

const KOCH_DEPTH: u32 = 8;
const TREE_DEPTH: u32 = 20;
const ROW_DEPTH: u32 = 11;

/// The row of trees of ABOP §1.10.3, in lsyc.
const ROW_OF_TREES: &str = "
const c = 1;
const p = 0.3;
const q = c - p;
const h = (p * q) ^ 0.5;

lsystem RowOfTrees {
    angle 86;
    axiom F(1);
    F(x) -> F(x * p) + F(x * h) - - F(x * h) + F(x * q);
}
";

// ---------------------------------------------------------------- lsyc

fn lsyc_program(file: &str) -> Program {
    let path = format!("{}/lang-examples/{file}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).expect("gallery program");
    lsyc_program_text(&path, &text)
}

fn lsyc_program_text(path: &str, text: &str) -> Program {
    let fe = lsyc::frontend::run(text, vec![], &[]);
    assert!(!fe.has_errors(), "{path}: {:?}", fe.diagnostics);
    let checked = fe.checked.as_ref().expect("checked");
    compile::compile(&fe.file, checked, None).expect("compiles")
}

fn lsyc_derive(prog: &Program, depth: u32) -> ModString {
    let start = derive::axiom(prog, &[], 0).expect("axiom");
    derive::derive(prog, start, depth, 0, Limits::default(), &|_, _| {}).expect("derives")
}

// ---------------------------------------------------------------- symbios

/// Room for the largest string here (symbios stops at 1 M modules by default).
const SYMBIOS_CAPACITY: usize = 1 << 30;

fn symbios_koch() -> symbios::System {
    let mut sys = symbios::System::new();
    sys.max_capacity = SYMBIOS_CAPACITY;
    // symbios reads a run of letters as one name: modules are separated by spaces.
    sys.add_rule("F -> F F - F - F - F - F F").unwrap();
    sys.set_axiom("F - F - F - F").unwrap();
    sys
}

fn symbios_tree() -> symbios::System {
    let mut sys = symbios::System::new();
    sys.max_capacity = SYMBIOS_CAPACITY;
    // The constants of fig. 2.6a, as in lang-examples/monopodial-tree.lsy.
    for d in [
        "#define r1 0.9",
        "#define r2 0.6",
        "#define a0 45",
        "#define a2 45",
        "#define d 137.5",
        "#define wr 0.707",
    ] {
        sys.add_directive(d).unwrap();
    }
    sys.add_rule("A(l,w) -> !(w) F(l) [ &(a0) B(l*r2, w*wr) ] /(d) A(l*r1, w*wr)")
        .unwrap();
    sys.add_rule("B(l,w) -> !(w) F(l) [ -(a2) $ C(l*r2, w*wr) ] C(l*r1, w*wr)")
        .unwrap();
    sys.add_rule("C(l,w) -> !(w) F(l) [ +(a2) $ B(l*r2, w*wr) ] B(l*r1, w*wr)")
        .unwrap();
    // The gallery program's axiom (the book's A(1, 10) with lengths scaled by 100).
    sys.set_axiom("A(100, 10)").unwrap();
    sys
}

fn symbios_row() -> symbios::System {
    let mut sys = symbios::System::new();
    sys.max_capacity = SYMBIOS_CAPACITY;
    // The constants as lsyc computes them (q = c - p, h = (p q)^0.5), printed
    // exactly.
    let (p, q) = (0.3f64, 1.0f64 - 0.3);
    let h = (p * q).powf(0.5);
    for d in [
        format!("#define p {p:?}"),
        format!("#define q {q:?}"),
        format!("#define h {h:?}"),
    ] {
        sys.add_directive(&d).unwrap();
    }
    sys.add_rule("F(x) -> F(x*p) + F(x*h) - - F(x*h) + F(x*q)")
        .unwrap();
    sys.set_axiom("F(1)").unwrap();
    sys
}

fn symbios_derive(mut sys: symbios::System, depth: u32) -> symbios::System {
    sys.derive(depth as usize).expect("symbios derives");
    sys
}

/// Bytes the symbios string holds: one `ModuleData` per module (24 bytes:
/// symbol u16, param_len u16, param_start u32, birth_time f64, two u32
/// topology links; `const _: () = assert!(size_of::<ModuleData>() == 24)` in
/// symbios-1.5.1/src/core/mod.rs) plus 8 bytes per parameter.
fn symbios_live_bytes(sys: &symbios::System) -> (usize, usize) {
    let st = &sys.state;
    let params: usize = (0..st.len())
        .map(|i| st.get_view(i).map_or(0, |v| v.params.len()))
        .sum();
    (st.len() * 24 + params * 8, params)
}

// ---------------------------------------------------------------- checks

/// Asserts that both engines derived the same string (names, and parameters to
/// a relative 1e-9), and returns its length.
fn same_string(prog: &Program, ours: &ModString, sys: &symbios::System) -> usize {
    let st = &sys.state;
    assert_eq!(ours.len(), st.len(), "module counts differ");
    let mut p = 0;
    for (i, &sym) in ours.syms.iter().enumerate() {
        let view = st.get_view(i).unwrap();
        let name = prog.symbols.info[sym as usize].name.text();
        let theirs = sys.interner.resolve(view.sym).unwrap();
        assert_eq!(name, theirs, "module {i}");
        let n = prog.symbols.arity(sym);
        let params = &ours.params[p..p + n];
        p += n;
        assert_eq!(params.len(), view.params.len(), "module {i} ({name}) arity");
        for (a, b) in params.iter().zip(view.params) {
            assert!(
                (a - b).abs() <= 1e-9 * a.abs().max(b.abs()).max(1.0),
                "module {i} ({name}): {a} vs {b}"
            );
        }
    }
    ours.len()
}

/// Derives once with each engine, checks the strings are equal, prints sizes
/// and times; returns the module count.
fn verify_and_report(
    title: &str,
    prog: &Program,
    depth: u32,
    make: fn() -> symbios::System,
) -> usize {
    let t = Instant::now();
    let (ours, our_peak) = peak_during(|| lsyc_derive(prog, depth));
    let our_time = t.elapsed();
    let sys = make();
    let t = Instant::now();
    let (sys, their_peak) = peak_during(|| symbios_derive(sys, depth));
    let their_time = t.elapsed();
    let n = same_string(prog, &ours, &sys);
    let (their_live, their_params) = symbios_live_bytes(&sys);
    let per = |b: usize| b as f64 / n as f64;
    let rate = |d: Duration| n as f64 / d.as_secs_f64() / 1e6;
    eprintln!();
    eprintln!(
        "{title}, depth {depth}: {n} modules, {} parameters",
        ours.params.len()
    );
    assert_eq!(ours.params.len(), their_params);
    eprintln!(
        "  lsyc    {:>6.1} M modules/s (one run)  live {:>6.2} B/module  peak heap {:>6.2} B/module",
        rate(our_time),
        per(ours.bytes()),
        per(our_peak),
    );
    eprintln!(
        "  symbios {:>6.1} M modules/s (one run)  live {:>6.2} B/module  peak heap {:>6.2} B/module",
        rate(their_time),
        per(their_live),
        per(their_peak),
    );
    n
}

// ---------------------------------------------------------------- benches

fn compare(
    c: &mut Criterion,
    name: &str,
    prog: Program,
    depth: u32,
    make: fn() -> symbios::System,
) {
    let n = verify_and_report(name, &prog, depth, make);
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("thread pool");

    let mut g = c.benchmark_group(name);
    g.sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(8))
        .throughput(Throughput::Elements(n as u64));
    g.bench_function(
        format!("lsyc/{}-threads", rayon::current_num_threads()),
        |b| {
            b.iter_batched(
                || (),
                |()| lsyc_derive(&prog, black_box(depth)),
                BatchSize::PerIteration,
            )
        },
    );
    g.bench_function("lsyc/1-thread", |b| {
        b.iter_batched(
            || (),
            |()| one.install(|| lsyc_derive(&prog, black_box(depth))),
            BatchSize::PerIteration,
        )
    });
    g.bench_function("symbios", |b| {
        b.iter_batched(
            make,
            |sys| symbios_derive(sys, black_box(depth)),
            BatchSize::PerIteration,
        )
    });
    g.finish();
}

fn koch(c: &mut Criterion) {
    let prog = lsyc_program("koch-curve-b.lsy");
    compare(c, "koch_1_9b", prog, KOCH_DEPTH, symbios_koch);
}

fn monopodial(c: &mut Criterion) {
    compare(
        c,
        "monopodial_2_6",
        lsyc_program("monopodial-tree.lsy"),
        TREE_DEPTH,
        symbios_tree,
    );
}

fn row_of_trees(c: &mut Criterion) {
    compare(
        c,
        "row_of_trees",
        lsyc_program_text("row of trees", ROW_OF_TREES),
        ROW_DEPTH,
        symbios_row,
    );
}

criterion_group!(benches, koch, monopodial, row_of_trees);

fn main() {
    eprintln!(
        "machine: {} threads, {}",
        std::thread::available_parallelism().map_or(0, |n| n.get()),
        std::fs::read_to_string("/proc/cpuinfo")
            .ok()
            .and_then(|s| {
                s.lines()
                    .find(|l| l.starts_with("model name"))
                    .and_then(|l| l.split(':').nth(1))
                    .map(|m| m.trim().to_string())
            })
            .unwrap_or_else(|| "unknown CPU".into())
    );
    benches();
    Criterion::default().configure_from_args().final_summary();
}
