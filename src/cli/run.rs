//! `lsyc run FILE`: derive, draw, and write SVG, PNG, OBJ or text.

use super::overwrite::{self, Clash, Inputs, Made};
use super::{Reporter, check::overrides};

mod outputs;
use lsyc::derive::Limits;
use lsyc::diagnostic::{Code, Diagnostic};
use lsyc::run::{self, Format, Options, OutputError, Stats};
use lsyc::{frontend, source};
use outputs::{parse_view, picture};
use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::time::Instant;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// The .lsy program to run.
    pub file: PathBuf,

    /// Derivation steps, 0 to 1000000 (default: the program's `derive`).
    #[arg(short = 'n', long = "steps", value_name = "STEPS", allow_negative_numbers = true, value_parser = parse_steps)]
    pub steps: Option<u32>,

    /// Output file; its extension picks the format: .svg .png .obj (+ .mtl) .glb
    /// .txt, or .apng (every step, animated); `-o -` writes to stdout (SVG
    /// unless --format says otherwise).
    #[arg(short = 'o', long = "output", value_name = "OUT")]
    pub output: Option<PathBuf>,

    /// The output format when the extension cannot say (`-o -`): svg, png, obj or txt.
    #[arg(long, value_name = "FORMAT", requires = "output")]
    pub format: Option<String>,

    /// Camera of 3D programs in SVG and PNG, in degrees (default 30,20).
    #[arg(long, value_name = "AZIMUTH,ELEVATION", value_parser = parse_view, allow_hyphen_values = true)]
    pub view: Option<[f64; 2]>,

    /// Write every derivation step: -o DIR/NAME.EXT gives DIR/NAME-000.EXT (the
    /// axiom) to NAME-NNN.EXT, all in the final step's view box.
    #[arg(long)]
    pub frames: bool,

    /// Print statistics as one JSON object on stdout (on stderr when the drawing
    /// itself goes to stdout with `-o -`).
    #[arg(long)]
    pub stats: bool,

    /// Override a constant: -D NAME=VALUE (repeatable).
    #[arg(short = 'D', value_name = "NAME=VALUE")]
    pub define: Vec<String>,

    /// Seed of the random choices (same seed, same output).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,

    /// Which lsystem of the file to run (default: the first).
    #[arg(long, value_name = "NAME")]
    pub system: Option<String>,

    /// PNG size in pixels (the longer side).
    #[arg(long, default_value_t = 1024, value_parser = clap::value_parser!(u32).range(16..=16384))]
    pub size: u32,

    /// PNG background: a colour name, #rrggbb, or `none` for transparent.
    #[arg(long, default_value = "white")]
    pub background: String,

    /// Stop with an error before a step would hold more modules than this.
    #[arg(long, default_value_t = Limits::default().max_modules)]
    pub max_modules: usize,

    /// Stop with an error before a step would need more memory than this (MiB).
    #[arg(long, value_name = "MIB", default_value_t = Limits::default().max_bytes >> 20)]
    pub max_memory: usize,

    /// Worker threads for derivation, from 1 to four times the cores (default:
    /// all cores); more is a usage error. Output does not depend on it.
    #[arg(long, value_name = "N", value_parser = parse_threads)]
    pub threads: Option<usize>,

    /// Print the compiled bytecode of every rule and exit.
    #[arg(long)]
    pub disasm: bool,

    /// For a scene: also draw the guides' outlines and the links (SVG and PNG;
    /// OBJ and text hold only what the systems draw).
    #[arg(long)]
    pub guides: bool,

    /// For a scene: say per guide how it was seeded, its steps, what was kept and clipped, and its links' tokens.
    #[arg(long)]
    pub explain: bool,

    /// Which scene of the file to run (default: the first); `--system` runs one
    /// lsystem on its own instead.
    #[arg(long, value_name = "NAME")]
    pub scene: Option<String>,

    /// Draw element NAME as the drawing in an SVG file instead (centred and scaled
    /// to the element's size, in the drawing's colours); repeatable.
    #[arg(long = "element", value_name = "NAME=FILE.svg")]
    pub elements: Vec<String>,

    /// Replace a file beside the output that lsyc did not write (an OBJ's
    /// .mtl, a frame of --frames): without it that is a usage error. Never
    /// allows writing over a file the command reads (the program, an
    /// --element drawing).
    #[arg(long)]
    pub force: bool,
}

/// `-n STEPS`: a whole number within derive's own limit, with derive's message.
fn parse_steps(text: &str) -> Result<u32, String> {
    let max = lsyc::derive::MAX_STEPS;
    text.trim()
        .parse::<u32>()
        .ok()
        .filter(|&n| n <= max)
        .ok_or_else(|| {
            format!("the number of derivation steps must be a whole number from 0 to {max}")
        })
}

/// `--threads N`: 1 to four times the cores (a thread pool of 100,000 would
/// exhaust the system before deriving anything).
fn parse_threads(text: &str) -> Result<usize, String> {
    let cores = std::thread::available_parallelism().map_or(1, std::num::NonZero::get);
    let max = cores * 4;
    text.trim()
        .parse::<usize>()
        .ok()
        .filter(|n| (1..=max).contains(n))
        .ok_or_else(|| {
            format!("the number of threads must be a whole number from 1 to {max} (four times the {cores} cores)")
        })
}

pub fn run(args: &Args, reporter: &Reporter) -> u8 {
    match run_inner(args, reporter) {
        Ok(()) => 0,
        Err(status) => status,
    }
}

/// `run` with the exit status of a failure as the error, so each step can `?`.
fn run_inner(args: &Args, reporter: &Reporter) -> Result<(), u8> {
    let ovr = overrides(&args.define).map_err(|d| {
        reporter.emit(&[d], "<command line>", "");
        2
    })?;
    let format = output_format(args, reporter)?;
    check_outputs(args, format, reporter)?;
    let background = background(args, reporter)?;
    if let Some(n) = args.threads {
        // Only the first call in a process can set the global pool; later
        // calls are harmless. A pool the system cannot start is said, and
        // the default pool does the work.
        if let Err(e) = rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
        {
            reporter.warning(&format!(
                "cannot start {n} threads ({e}); using the default"
            ));
        }
    }
    let (src, fe) = load(args, &ovr, reporter)?;
    let checked = fe.checked.as_ref().ok_or(1u8)?;
    let has_scene = fe
        .file
        .items
        .stmts
        .iter()
        .any(|i| matches!(i.node, lsyc::ast::Item::Scene(_)));
    let opts = Options {
        steps: args.steps,
        seed: args.seed,
        limits: Limits {
            max_modules: args.max_modules,
            max_bytes: args.max_memory.saturating_mul(1 << 20),
            cancel: None,
        },
        system: args.system.clone(),
        base_dir: args
            .file
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
            .map(std::path::Path::to_path_buf),
    };
    if has_scene && args.system.is_none() && !args.disasm {
        return match run_scene(
            args, reporter, &src, &fe.file, checked, &opts, format, background,
        ) {
            0 => Ok(()),
            status => Err(status),
        };
    }
    if args.disasm {
        let prog =
            lsyc::compile::compile(&fe.file, checked, opts.system.as_deref()).map_err(|e| {
                reporter.emit(&[e.diagnostic()], &src.name, &src.text);
                1u8
            })?;
        return if reporter.stdout(prog.disassemble().as_bytes()) {
            Ok(())
        } else {
            Err(1)
        };
    }
    run_system(args, reporter, &src, &fe, &opts, format, background)
}

/// Whether an output path means stdout (`-o -`).
fn is_stdout(path: &std::path::Path) -> bool {
    path.as_os_str() == "-"
}

/// The output format, from the output file's extension (or `--format`, which
/// `-o -` needs).
fn output_format(args: &Args, reporter: &Reporter) -> Result<Option<Format>, u8> {
    let Some(p) = &args.output else {
        return Ok(None);
    };
    if let Some(format) = requested_format(args, p, reporter)? {
        return Ok(Some(format));
    }
    Format::from_path(p).map(Some).ok_or_else(|| {
        reporter.error(
            &format!("cannot tell the output format of `{}`", p.display()),
            Some("use a file ending in .svg, .png, .obj or .txt"),
        );
        2
    })
}

/// The format `--format` names, SVG for `-o -` without it, or `None` to go by
/// the extension; a usage error if `--format` names no format, disagrees with
/// the file's extension, or asks for a PNG on a terminal.
fn requested_format(
    args: &Args,
    p: &std::path::Path,
    reporter: &Reporter,
) -> Result<Option<Format>, u8> {
    let named = match &args.format {
        None => None,
        Some(f) => {
            // The format of a file with that extension.
            let format = Format::from_path(std::path::Path::new(&format!("out.{f}")));
            if format.is_none() {
                reporter.error(
                    &format!("`--format {f}` is not an output format"),
                    Some("the formats are svg, png, obj and txt"),
                );
                return Err(2);
            }
            format
        }
    };
    if is_stdout(p) {
        let format = named.unwrap_or(Format::Svg);
        if format == Format::Png && std::io::stdout().is_terminal() {
            reporter.error(
                "a PNG is not written to a terminal",
                Some("redirect it (`-o - --format png > out.png`) or name a file: -o out.png"),
            );
            return Err(2);
        }
        return Ok(Some(format));
    }
    if let (Some(named), Some(by_name)) = (named, Format::from_path(p))
        && named != by_name
    {
        reporter.error(
            &format!(
                "`--format {}` disagrees with the extension of `{}`",
                args.format.as_deref().unwrap_or_default(),
                p.display()
            ),
            Some("leave out --format, or give the file the format's extension"),
        );
        return Err(2);
    }
    Ok(named)
}

/// The PNG background as RGBA.
fn background(args: &Args, reporter: &Reporter) -> Result<[u8; 4], u8> {
    if args.background == "none" {
        return Ok([0, 0, 0, 0]);
    }
    match lsyc::render::png::parse_color(&args.background) {
        Some([r, g, b]) => Ok([r, g, b, 255]),
        None => {
            reporter.error(
                &format!("`{}` is not a colour", args.background),
                Some("write a colour as #rrggbb, #rrggbbaa or a name such as white or none"),
            );
            Err(2)
        }
    }
}

/// Reads and checks the program (its diagnostics reported), with the
/// `--element` replacements applied.
fn load(
    args: &Args,
    ovr: &[lsyc::check::Override],
    reporter: &Reporter,
) -> Result<(source::Source, frontend::Frontend), u8> {
    let src = super::read_program(&args.file, reporter).ok_or(1u8)?;
    let mut fe = frontend::run_seeded(&src.text, src.diagnostics.clone(), ovr, args.seed);
    reporter.emit(&fe.diagnostics, &src.name, &src.text);
    if fe.has_errors() {
        return Err(1);
    }
    for spec in &args.elements {
        let Some((name, file)) = spec.split_once('=') else {
            reporter.error(
                &format!("--element {spec}: not of the form NAME=FILE.svg"),
                Some("e.g. --element A=leaf.svg"),
            );
            return Err(2);
        };
        let data = read_element(file, reporter)?;
        if let Err(why) = lsyc::infer::elements::replace_element(&mut fe.file, name, &data) {
            reporter.error(&format!("--element {spec}: {why}"), None);
            return Err(1);
        }
    }
    Ok((src, fe))
}

/// Reads an `--element` drawing, up to the size inference reads.
fn read_element(file: &str, reporter: &Reporter) -> Result<Vec<u8>, u8> {
    let limit = lsyc::infer::MAX_SVG_BYTES;
    if std::fs::metadata(file).is_ok_and(|m| m.len() > limit as u64) {
        reporter.error(
            &format!(
                "`{file}` is larger than {} MiB; lsyc reads drawings of up to that",
                limit >> 20
            ),
            None,
        );
        return Err(1);
    }
    std::fs::read(file).map_err(|e| {
        reporter.error(&format!("cannot read `{file}`: {e}"), None);
        1u8
    })
}

/// Derives one lsystem, draws it (to a file with `-o`) and reports the summary.
fn run_system(
    args: &Args,
    reporter: &Reporter,
    src: &source::Source,
    fe: &frontend::Frontend,
    opts: &Options,
    format: Option<Format>,
    background: [u8; 4],
) -> Result<(), u8> {
    let checked = fe.checked.as_ref().ok_or(1u8)?;
    let fail = |d: lsyc::diagnostic::Diagnostic| {
        reporter.emit(&[d], &src.name, &src.text);
        1u8
    };
    let bar = progress_bar(args.steps);
    let on_step = |step: u32, modules: usize| {
        if let Some(b) = &bar {
            b.set_position(step as u64);
            b.set_message(format!("{modules} modules"));
        }
    };
    let derived = run::derive(&fe.file, checked, opts, &on_step);
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let mut derived = derived.map_err(fail)?;
    let start = Instant::now();
    let drawn = match (format, &args.output) {
        (Some(format), Some(path)) => {
            let picture = picture(args, background);
            outputs::write(args, reporter, src, &mut derived, format, path, &picture)?
        }
        _ => run::measure(&derived, args.seed).map_err(fail)?.0,
    };
    let stats = Stats::new(&derived, &drawn, start.elapsed().as_secs_f64() * 1000.0);
    let wrote = report_stats(args, &stats, reporter)?;
    reporter.info(&format!(
        "{}: {}, {}, {}, {} after {} (derive {:.0} ms, draw {:.0} ms){wrote}",
        stats.system,
        count(stats.modules, "module"),
        count(stats.segments, "segment"),
        count(stats.elements, "element"),
        count(stats.polygons, "polygon"),
        count(stats.steps, "step"),
        stats.derive_ms,
        stats.interpret_ms
    ));
    Ok(())
}

/// Writes an output file atomically with `fill`; on failure reports why (a
/// runtime diagnostic or an IO error naming the file) and returns `None`. The
/// file is left untouched unless `fill` succeeds.
fn write_file<T>(
    path: &std::path::Path,
    reporter: &Reporter,
    src: &source::Source,
    fill: impl FnOnce(&mut dyn Write) -> Result<T, OutputError>,
) -> Option<T> {
    let mut result = None;
    let mut failed = None;
    let fill_or_fail = |w: &mut dyn Write| match fill(w) {
        Ok(v) => {
            result = Some(v);
            Ok(())
        }
        Err(OutputError::Io(e)) => Err(e),
        Err(OutputError::Diagnostic(d)) => {
            failed = Some(d);
            Err(std::io::Error::other("stopped by an error"))
        }
    };
    let written = if is_stdout(path) {
        // All or nothing on stdout too: the bytes go out once the drawing is complete.
        let mut bytes = Vec::new();
        fill_or_fail(&mut bytes).and_then(|()| {
            let mut out = std::io::stdout().lock();
            out.write_all(&bytes).and_then(|()| out.flush())
        })
    } else {
        source::write_atomic_with(path, fill_or_fail)
    };
    if let Some(d) = failed {
        reporter.emit(&[d], &src.name, &src.text);
        return None;
    }
    if let Err(e) = written {
        reporter.emit(
            &[Diagnostic::error(
                Code::WriteOutput,
                format!("cannot write `{}`: {e}", output_name(path)),
            )],
            &src.name,
            &src.text,
        );
        return None;
    }
    result
}

/// Prints `--stats` as one JSON object: on stdout, or on stderr when stdout
/// carries the drawing (`-o -`). Returns the end of the summary line: where
/// the output went, or how to write one; exit status 1 if stdout failed.
fn report_stats(
    args: &Args,
    stats: &impl serde::Serialize,
    reporter: &Reporter,
) -> Result<String, u8> {
    let on_stdout = args.output.as_deref().is_some_and(is_stdout);
    if args.stats
        && let Ok(s) = serde_json::to_string(stats)
    {
        if on_stdout {
            reporter.stderr(&format!("{s}\n"));
        } else if !reporter.stdout(format!("{s}\n").as_bytes()) {
            return Err(1);
        }
    }
    Ok(match &args.output {
        Some(_) if args.frames => ", wrote its frames".to_string(),
        Some(p) if is_stdout(p) => ", wrote it to stdout".to_string(),
        Some(p) => format!(", wrote {}", p.display()),
        None => {
            let stem = args
                .file
                .file_stem()
                .map_or("out".into(), |s| s.to_string_lossy());
            format!("; no output written, add -o {stem}.svg to draw it")
        }
    })
}

/// "1 polygon", "2 polygons", "3 queries".
fn count(n: impl std::fmt::Display, what: &str) -> String {
    let n = n.to_string();
    match (n.as_str(), what.strip_suffix('y')) {
        ("1", _) => format!("1 {what}"),
        (_, Some(stem)) => format!("{n} {stem}ies"),
        _ => format!("{n} {what}s"),
    }
}

/// How the summary names an output: `stdout` for `-o -`.
fn output_name(p: &std::path::Path) -> String {
    if is_stdout(p) {
        "stdout".to_string()
    } else {
        p.display().to_string()
    }
}

/// The files this run reads: the program and the `--element` drawings.
fn inputs(args: &Args) -> Inputs {
    let mut inputs = Inputs::default();
    inputs.add(&args.file, "the program");
    for spec in &args.elements {
        if let Some((name, file)) = spec.split_once('=') {
            inputs.add(
                std::path::Path::new(file),
                format!("the drawing of `--element {name}`"),
            );
        }
    }
    inputs
}

/// Checks the output and its `.mtl` before anything is derived (frames are
/// checked once their number is known, `outputs::check_frames`).
fn check_outputs(args: &Args, format: Option<Format>, reporter: &Reporter) -> Result<(), u8> {
    let Some(path) = args.output.as_deref().filter(|p| !is_stdout(p)) else {
        return Ok(());
    };
    if args.frames && format != Some(Format::Apng) {
        return Ok(());
    }
    let inputs = inputs(args);
    let mut checks = vec![(path.to_path_buf(), "the output".to_string(), Made::Named)];
    if format == Some(Format::Obj) {
        let role = format!("the materials of `{}`", path.display());
        checks.push((outputs::mtl_path(path), role, Made::Beside));
    }
    for (p, role, made) in checks {
        overwrite::check(&p, &role, made, &inputs, args.force).map_err(|c| refuse(&c, reporter))?;
    }
    Ok(())
}

/// Reports a file this run may not write: a usage error.
fn refuse(clash: &Clash, reporter: &Reporter) -> u8 {
    reporter.error(&clash.to_string(), Some(clash.help()));
    2
}

fn progress_bar(steps: Option<u32>) -> Option<indicatif::ProgressBar> {
    if !std::io::stderr().is_terminal() {
        return None;
    }
    // Without `-n` the step count is the program's `derive`, known only once it
    // is compiled: the bar then counts steps without a total.
    let (len, template) = match steps {
        Some(n) => (u64::from(n), "deriving {bar:30} step {pos}/{len} {msg}"),
        None => (0, "deriving step {pos} {msg}"),
    };
    let bar = indicatif::ProgressBar::new(len);
    if let Ok(style) = indicatif::ProgressStyle::with_template(template) {
        bar.set_style(style);
    }
    Some(bar)
}

#[allow(clippy::too_many_arguments)]
fn run_scene(
    args: &Args,
    reporter: &Reporter,
    src: &source::Source,
    file: &lsyc::ast::File,
    checked: &lsyc::check::Checked,
    opts: &Options,
    format: Option<Format>,
    background: [u8; 4],
) -> u8 {
    let r = match run::run_scene(file, checked, args.scene.as_deref(), opts) {
        Ok(r) => r,
        Err(d) => {
            reporter.emit(&[d], &src.name, &src.text);
            return 1;
        }
    };
    let cfg = lsyc::env::Config::new(opts.seed, opts.limits, opts.steps);
    reporter.emit(
        &lsyc::env::explain::warnings(&r.scene, &r.outcome, cfg),
        &src.name,
        &src.text,
    );
    if args.explain {
        match lsyc::env::explain::explain(&r.scene, &r.outcome, cfg) {
            Ok(rep) => reporter.stderr(&lsyc::env::explain::render(&r.scene, &rep)),
            Err(d) => reporter.emit(&[d], &src.name, &src.text),
        }
    }
    let picture = picture(args, background);
    let stats = match &args.output {
        Some(path) => match outputs::write_scene(args, reporter, src, &r, format, path, picture) {
            Some(s) => s,
            None => {
                return if args.frames || format == Some(Format::Apng) {
                    2
                } else {
                    1
                };
            }
        },
        None => match run::write_scene(&r, None, picture, args.seed, false, &mut std::io::sink()) {
            Ok(s) => s,
            Err(OutputError::Diagnostic(d)) => {
                reporter.emit(&[d], &src.name, &src.text);
                return 1;
            }
            Err(OutputError::Io(e)) => {
                reporter.error(&e.to_string(), None);
                return 1;
            }
        },
    };
    let wrote = match report_stats(args, &stats, reporter) {
        Ok(w) => w,
        Err(status) => return status,
    };
    reporter.info(&format!(
        "scene {}: {}, {}, {}, {}, {}, {}, {} after {}{wrote}",
        stats.scene,
        count(stats.systems, "system"),
        count(stats.modules, "module"),
        count(stats.segments, "segment"),
        count(stats.elements, "element"),
        count(stats.polygons, "polygon"),
        count(stats.queries, "query"),
        count(stats.messages, "message"),
        count(stats.steps, "step")
    ));
    0
}
