//! The functions expressions may call, shared by the checker and the evaluator.
//!
//! Owns: names, arities and meaning of built-in functions. Angles are in degrees,
//! as everywhere in the language. Random functions are listed here but drawn by
//! the VM from its seeded generator. Calls are resolved to an index into
//! `BUILTINS` when compiled; nothing matches a function by name at run time.

/// One built-in function.
#[derive(Clone, Copy, Debug)]
pub struct Builtin {
    pub name: &'static str,
    pub arity: usize,
    /// Drawn from the run's seeded generator; not a constant.
    pub random: bool,
    pub doc: &'static str,
    /// The function itself, over exactly `arity` arguments (NaN for random
    /// ones: the VM draws those from its generator instead).
    pub eval: fn(&[f64]) -> f64,
}

const DEG: f64 = std::f64::consts::PI / 180.0;

/// Argument `i`, or NaN when a caller passed too few (the VM never does).
fn arg(args: &[f64], i: usize) -> f64 {
    args.get(i).copied().unwrap_or(f64::NAN)
}

const fn f(
    name: &'static str,
    arity: usize,
    doc: &'static str,
    eval: fn(&[f64]) -> f64,
) -> Builtin {
    Builtin {
        name,
        arity,
        random: false,
        doc,
        eval,
    }
}

const fn r(name: &'static str, arity: usize, doc: &'static str) -> Builtin {
    Builtin {
        name,
        arity,
        random: true,
        doc,
        eval: |_| f64::NAN,
    }
}

pub const BUILTINS: &[Builtin] = &[
    f("sin", 1, "sine of an angle in degrees", |a| {
        (arg(a, 0) * DEG).sin()
    }),
    f("cos", 1, "cosine of an angle in degrees", |a| {
        (arg(a, 0) * DEG).cos()
    }),
    f("tan", 1, "tangent of an angle in degrees", |a| {
        (arg(a, 0) * DEG).tan()
    }),
    f("asin", 1, "arc sine, in degrees", |a| {
        arg(a, 0).asin() / DEG
    }),
    f("acos", 1, "arc cosine, in degrees", |a| {
        arg(a, 0).acos() / DEG
    }),
    f("atan", 1, "arc tangent, in degrees", |a| {
        arg(a, 0).atan() / DEG
    }),
    f("atan2", 2, "atan2(y, x), in degrees", |a| {
        arg(a, 0).atan2(arg(a, 1)) / DEG
    }),
    f("sqrt", 1, "square root", |a| arg(a, 0).sqrt()),
    f("abs", 1, "absolute value", |a| arg(a, 0).abs()),
    f("sign", 1, "-1, 0 or 1", |a| {
        let x = arg(a, 0);
        if x > 0.0 {
            1.0
        } else if x < 0.0 {
            -1.0
        } else {
            0.0
        }
    }),
    f("floor", 1, "largest integer not above", |a| {
        arg(a, 0).floor()
    }),
    f("ceil", 1, "smallest integer not below", |a| {
        arg(a, 0).ceil()
    }),
    f("round", 1, "nearest integer, halves away from zero", |a| {
        arg(a, 0).round()
    }),
    f("exp", 1, "e to the power", |a| arg(a, 0).exp()),
    f("log", 1, "natural logarithm", |a| arg(a, 0).ln()),
    f("pow", 2, "pow(x, y) = x^y", |a| arg(a, 0).powf(arg(a, 1))),
    f("min", 2, "the smaller of two", |a| arg(a, 0).min(arg(a, 1))),
    f("max", 2, "the larger of two", |a| arg(a, 0).max(arg(a, 1))),
    f("clamp", 3, "clamp(x, lo, hi)", |a| {
        arg(a, 0).max(arg(a, 1)).min(arg(a, 2))
    }),
    r("rand", 0, "uniform in [0, 1)"),
    r("uniform", 2, "uniform(a, b): uniform in [a, b)"),
    r("normal", 2, "normal(mean, sd): Gaussian"),
];

/// The built-in called `name`.
pub fn lookup(name: &str) -> Option<&'static Builtin> {
    BUILTINS.iter().find(|b| b.name == name)
}

/// The index of the built-in called `name` in `BUILTINS` (what `Op::Call` holds).
pub fn index(name: &str) -> Option<u8> {
    BUILTINS
        .iter()
        .position(|b| b.name == name)
        .and_then(|i| u8::try_from(i).ok())
}
