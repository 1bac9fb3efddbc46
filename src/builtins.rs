//! The functions expressions may call, shared by the checker and the evaluator.
//!
//! Owns: names, arities and meaning of built-in functions. Angles are in degrees,
//! as everywhere in the language. Random functions are listed here but drawn by
//! the engine from its seeded generator; `eval` does not evaluate them.

/// One built-in function.
#[derive(Clone, Copy, Debug)]
pub struct Builtin {
    pub name: &'static str,
    pub arity: usize,
    /// Drawn from the run's seeded generator; not a constant.
    pub random: bool,
    pub doc: &'static str,
}

const fn f(name: &'static str, arity: usize, doc: &'static str) -> Builtin {
    Builtin {
        name,
        arity,
        random: false,
        doc,
    }
}

const fn r(name: &'static str, arity: usize, doc: &'static str) -> Builtin {
    Builtin {
        name,
        arity,
        random: true,
        doc,
    }
}

pub const BUILTINS: &[Builtin] = &[
    f("sin", 1, "sine of an angle in degrees"),
    f("cos", 1, "cosine of an angle in degrees"),
    f("tan", 1, "tangent of an angle in degrees"),
    f("asin", 1, "arc sine, in degrees"),
    f("acos", 1, "arc cosine, in degrees"),
    f("atan", 1, "arc tangent, in degrees"),
    f("atan2", 2, "atan2(y, x), in degrees"),
    f("sqrt", 1, "square root"),
    f("abs", 1, "absolute value"),
    f("sign", 1, "-1, 0 or 1"),
    f("floor", 1, "largest integer not above"),
    f("ceil", 1, "smallest integer not below"),
    f("round", 1, "nearest integer, halves away from zero"),
    f("exp", 1, "e to the power"),
    f("log", 1, "natural logarithm"),
    f("pow", 2, "pow(x, y) = x^y"),
    f("min", 2, "the smaller of two"),
    f("max", 2, "the larger of two"),
    f("clamp", 3, "clamp(x, lo, hi)"),
    r("rand", 0, "uniform in [0, 1)"),
    r("uniform", 2, "uniform(a, b): uniform in [a, b)"),
    r("normal", 2, "normal(mean, sd): Gaussian"),
];

pub fn lookup(name: &str) -> Option<&'static Builtin> {
    BUILTINS.iter().find(|b| b.name == name)
}

/// Evaluates a deterministic built-in; `None` for random ones or a wrong arity.
pub fn eval(name: &str, args: &[f64]) -> Option<f64> {
    let deg = std::f64::consts::PI / 180.0;
    Some(match (name, args) {
        ("sin", [x]) => (x * deg).sin(),
        ("cos", [x]) => (x * deg).cos(),
        ("tan", [x]) => (x * deg).tan(),
        ("asin", [x]) => x.asin() / deg,
        ("acos", [x]) => x.acos() / deg,
        ("atan", [x]) => x.atan() / deg,
        ("atan2", [y, x]) => y.atan2(*x) / deg,
        ("sqrt", [x]) => x.sqrt(),
        ("abs", [x]) => x.abs(),
        ("sign", [x]) => {
            if *x > 0.0 {
                1.0
            } else if *x < 0.0 {
                -1.0
            } else {
                0.0
            }
        }
        ("floor", [x]) => x.floor(),
        ("ceil", [x]) => x.ceil(),
        ("round", [x]) => x.round(),
        ("exp", [x]) => x.exp(),
        ("log", [x]) => x.ln(),
        ("pow", [x, y]) => x.powf(*y),
        ("min", [x, y]) => x.min(*y),
        ("max", [x, y]) => x.max(*y),
        ("clamp", [x, lo, hi]) => x.max(*lo).min(*hi),
        _ => return None,
    })
}
