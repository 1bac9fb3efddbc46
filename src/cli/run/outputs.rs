//! The outputs of `lsyc run -o`: one file, an OBJ with its `.mtl`, growth
//! frames (`--frames`), an animated PNG, and the `--view` camera.
//!
//! Owns: file names beside the output (`X.mtl`, `NAME-000.EXT`), writing each
//! atomically, and the progress shown while writing (a bar of frames, a
//! spinner for one big file; neither when stderr is not a terminal). Drawing is the library's
//! (`lsyc::run`).

use super::{Args, Reporter, write_file};
use crate::cli::overwrite::{self, Made};
use lsyc::run::{self, Derived, Format, OutputError, Picture, SceneRun, SceneStats, Written};
use lsyc::source;
use lsyc::turtle::Drawn;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};

/// `--view AZIMUTH,ELEVATION`: two finite numbers of degrees, the elevation
/// within ±90.
pub fn parse_view(s: &str) -> Result<[f64; 2], String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let [az, el] = parts[..] else {
        return Err(format!(
            "`{s}` is not AZIMUTH,ELEVATION: write two numbers of degrees, e.g. --view 30,20"
        ));
    };
    let number = |t: &str, what: &str| {
        t.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| {
                format!("the {what} `{t}` is not a number of degrees (e.g. --view 30,20)")
            })
    };
    let (az, el) = (number(az, "azimuth")?, number(el, "elevation")?);
    if !(-90.0..=90.0).contains(&el) {
        return Err(format!("the elevation {el} is beyond ±90 degrees"));
    }
    Ok([az, el])
}

/// The output settings of the command line.
pub fn picture(args: &Args, background: [u8; 4]) -> Picture {
    let mtllib = args
        .output
        .as_deref()
        .filter(|p| Format::from_path(p) == Some(Format::Obj))
        .and_then(|p| {
            mtl_path(p)
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
        });
    Picture {
        size: args.size,
        background,
        view: args.view,
        mtllib,
        ..Picture::default()
    }
}

/// `X.mtl` beside `X.obj`.
pub fn mtl_path(obj: &Path) -> PathBuf {
    obj.with_extension("mtl")
}

/// Frame `k` of `last`: `DIR/NAME-007.EXT` (three digits or more, so that
/// the names sort in step order).
fn frame_path(path: &Path, k: u32, last: u32) -> PathBuf {
    let width = last.to_string().len().max(3);
    let stem = path
        .file_stem()
        .map_or(String::new(), |s| s.to_string_lossy().into_owned());
    let name = match path.extension() {
        Some(ext) => format!("{stem}-{k:0width$}.{}", ext.to_string_lossy()),
        None => format!("{stem}-{k:0width$}"),
    };
    path.with_file_name(name)
}

/// Writes the `.mtl` of an OBJ's materials atomically; false after reporting
/// why it failed.
fn write_mtl(
    obj: &Path,
    materials: &[u32],
    palette: &lsyc::render::Palette,
    reporter: &Reporter,
    src: &source::Source,
) -> bool {
    write_file(&mtl_path(obj), reporter, src, |w| {
        lsyc::render::obj::write_mtl_with(w, materials, palette).map_err(OutputError::Io)
    })
    .is_some()
}

/// A progress bar of `len` frames on stderr; none when stderr is not a terminal.
fn frames_bar(len: u32) -> Option<indicatif::ProgressBar> {
    if !std::io::stderr().is_terminal() {
        return None;
    }
    let bar = indicatif::ProgressBar::new(u64::from(len));
    if let Ok(style) =
        indicatif::ProgressStyle::with_template("drawing {bar:30} frame {pos}/{len} {msg}")
    {
        bar.set_style(style);
    }
    Some(bar)
}

/// A spinner with the elapsed time while `path` is written (big drawings
/// take seconds); none when stderr is not a terminal.
fn writing_spinner(path: &Path) -> Option<indicatif::ProgressBar> {
    if !std::io::stderr().is_terminal() {
        return None;
    }
    let bar = indicatif::ProgressBar::new_spinner();
    if let Ok(style) = indicatif::ProgressStyle::with_template("{spinner} writing {msg} {elapsed}")
    {
        bar.set_style(style);
    }
    bar.set_message(path.display().to_string());
    bar.enable_steady_tick(std::time::Duration::from_millis(120));
    Some(bar)
}

/// Writes one lsystem's output(s) to `path`; reports failures and returns
/// the exit status (1 an error in the input or the file, 2 a usage error).
pub fn write(
    args: &Args,
    reporter: &Reporter,
    src: &source::Source,
    derived: &mut Derived,
    format: Format,
    path: &Path,
    picture: &Picture,
) -> Result<Drawn, u8> {
    if format == Format::Apng {
        if args.frames {
            reporter.error(
                "--frames writes one file per step; an .apng already holds every step",
                Some("drop --frames, or write frames as .png or .svg"),
            );
            return Err(2);
        }
        let bar = frames_bar(derived.steps + 1);
        let progress = |k: u32| {
            if let Some(b) = &bar {
                b.set_position(u64::from(k) + 1);
            }
        };
        let written = write_file(path, reporter, src, |w| {
            run::write_animation(derived, picture, args.seed, &progress, w)
        });
        if let Some(b) = &bar {
            b.finish_and_clear();
        }
        return written.map(|w| w.drawn).ok_or(1);
    }
    if !args.frames {
        let spinner = writing_spinner(path);
        let written = write_one(reporter, src, derived, format, path, picture, args.seed);
        if let Some(s) = spinner {
            s.finish_and_clear();
        }
        return written.map(|w| w.drawn);
    }
    let last = derived.steps;
    check_frames(args, format, path, last, reporter)?;
    let bar = frames_bar(last + 1);
    let mut failed = false;
    let mut drawn = Drawn::default();
    let result = run::each_step(derived, picture, args.seed, &mut |step, framed| {
        let frame = frame_path(path, step.steps, last);
        let mut framed = framed.clone();
        if framed.mtllib.is_some() {
            framed.mtllib = mtl_path(&frame)
                .file_name()
                .map(|n| n.to_string_lossy().into_owned());
        }
        match write_one(reporter, src, step, format, &frame, &framed, args.seed) {
            Ok(w) => drawn = w.drawn,
            Err(_) => {
                failed = true;
                return Err(OutputError::Io(std::io::Error::other("reported")));
            }
        }
        if let Some(b) = &bar {
            b.set_position(u64::from(step.steps) + 1);
            b.set_message(frame.display().to_string());
        }
        Ok(())
    });
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    match result {
        Ok(()) => {
            reporter.note(&format!(
                "wrote {} frames, {} to {}",
                last + 1,
                frame_path(path, 0, last).display(),
                frame_path(path, last, last).display()
            ));
            Ok(drawn)
        }
        Err(_) if failed => Err(1),
        Err(OutputError::Diagnostic(d)) => {
            reporter.emit(&[d], &src.name, &src.text);
            Err(1)
        }
        Err(OutputError::Io(e)) => {
            reporter.error(&e.to_string(), None);
            Err(1)
        }
    }
}

/// Checks every frame's file (and `.mtl`) before the first is written: none
/// is an input, none is somebody else's file (unless `--force`).
fn check_frames(
    args: &Args,
    format: Format,
    path: &Path,
    last: u32,
    reporter: &Reporter,
) -> Result<(), u8> {
    let inputs = super::inputs(args);
    for k in 0..=last {
        let frame = frame_path(path, k, last);
        let role = format!("frame {k} of `-o {}`", path.display());
        overwrite::check(&frame, &role, Made::Beside, &inputs, args.force)
            .map_err(|c| super::refuse(&c, reporter))?;
        if format == Format::Obj {
            let role = format!("the materials of frame {k} of `-o {}`", path.display());
            overwrite::check(&mtl_path(&frame), &role, Made::Beside, &inputs, args.force)
                .map_err(|c| super::refuse(&c, reporter))?;
        }
    }
    Ok(())
}

/// One output file (and its `.mtl` for an OBJ).
fn write_one(
    reporter: &Reporter,
    src: &source::Source,
    d: &Derived,
    format: Format,
    path: &Path,
    picture: &Picture,
    seed: u64,
) -> Result<Written, u8> {
    let written = write_file(path, reporter, src, |w| {
        run::write_output_full(d, format, picture, seed, w)
    })
    .ok_or(1u8)?;
    if format == Format::Obj
        && !write_mtl(path, &written.materials, &written.palette, reporter, src)
    {
        return Err(1);
    }
    Ok(written)
}

/// Writes a scene's output to `path` (and its `.mtl` for an OBJ); `None`
/// after reporting why it failed.
pub fn write_scene(
    args: &Args,
    reporter: &Reporter,
    src: &source::Source,
    r: &SceneRun,
    format: Option<Format>,
    path: &Path,
    picture: Picture,
) -> Option<SceneStats> {
    if args.frames || format == Some(Format::Apng) {
        reporter.error(
            "growth frames and animations are drawn for one lsystem, not yet for a scene",
            Some("run one lsystem with --system NAME, or draw the scene's steps with -n"),
        );
        return None;
    }
    let spinner = writing_spinner(path);
    let stats = write_file(path, reporter, src, |w| {
        run::write_scene(r, format, picture, args.seed, args.guides, w)
    });
    if let Some(s) = spinner {
        s.finish_and_clear();
    }
    let stats = stats?;
    if format == Some(Format::Obj)
        && !write_mtl(
            path,
            &stats.materials,
            &lsyc::render::Palette::default(),
            reporter,
            src,
        )
    {
        return None;
    }
    Some(stats)
}
