//! Reading a program from disk: size limit, directories, UTF-8.
//!
//! Owns: turning a path into text plus the diagnostics about the file itself.

use crate::diagnostic::{Code, Diagnostic};
use std::path::Path;

/// The largest source file lsyc reads.
pub const MAX_SOURCE_BYTES: u64 = 64 * 1024 * 1024;

/// A loaded source text. `text` is lossy where the bytes were not UTF-8; such a
/// file always carries an E0101 diagnostic.
pub struct Source {
    pub name: String,
    pub text: String,
    pub diagnostics: Vec<Diagnostic>,
}

/// Reads a file, or explains why it cannot be read.
pub fn read(path: &Path) -> Result<Source, Diagnostic> {
    let name = path.display().to_string();
    let meta = std::fs::metadata(path).map_err(|e| cannot_read(&name, &e))?;
    if meta.is_dir() {
        return Err(Diagnostic::error(
            Code::ReadFile,
            format!("cannot read `{name}`: it is a directory"),
        )
        .help("give the path of a .lsy file"));
    }
    if meta.len() > MAX_SOURCE_BYTES {
        return Err(Diagnostic::error(
            Code::FileTooLarge,
            format!(
                "`{name}` is {} MiB; lsyc reads programs up to {} MiB",
                meta.len() / (1024 * 1024),
                MAX_SOURCE_BYTES / (1024 * 1024)
            ),
        ));
    }
    let bytes = std::fs::read(path).map_err(|e| cannot_read(&name, &e))?;
    Ok(from_bytes(name, &bytes))
}

pub fn from_bytes(name: String, bytes: &[u8]) -> Source {
    let (text, bad) = crate::parser::decode(bytes);
    Source {
        name,
        text,
        diagnostics: bad.into_iter().collect(),
    }
}

fn cannot_read(name: &str, e: &std::io::Error) -> Diagnostic {
    let why = match e.kind() {
        std::io::ErrorKind::NotFound => "no such file".to_string(),
        std::io::ErrorKind::PermissionDenied => "permission denied".to_string(),
        _ => e.to_string(),
    };
    Diagnostic::error(Code::ReadFile, format!("cannot read `{name}`: {why}"))
}

/// Writes `contents` to `path` atomically: a temporary file beside it, then a rename.
pub fn write_atomic(path: &Path, contents: &[u8]) -> std::io::Result<()> {
    write_atomic_with(path, |w| w.write_all(contents))
}

/// Streams into a temporary file beside `path` and renames it over `path` only
/// when `fill` succeeds; on failure nothing is left behind and `path` is untouched.
///
/// Only a regular file (or a new one) is replaced that way. A symbolic link is
/// followed, so the link stays and its target gets the new contents; a device,
/// pipe or socket (`-o /dev/null`, `-o /dev/stdout`, a FIFO) is written in place,
/// since renaming over it would replace the device with a plain file.
pub fn write_atomic_with(
    path: &Path,
    fill: impl FnOnce(&mut dyn std::io::Write) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let resolved;
    let path = match std::fs::symlink_metadata(path) {
        Ok(meta) if meta.file_type().is_symlink() => match std::fs::canonicalize(path) {
            Ok(target) => {
                resolved = target;
                resolved.as_path()
            }
            // A dangling link: writing through it creates its target.
            Err(_) => return write_in_place(path, fill),
        },
        _ => path,
    };
    if let Ok(meta) = std::fs::metadata(path)
        && !meta.is_file()
    {
        return write_in_place(path, fill);
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => std::path::PathBuf::from("."),
    };
    let file_name = path
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".to_string());
    let tmp = dir.join(format!(".{file_name}.lsyc-{}.tmp", std::process::id()));
    let result = (|| {
        let f = std::fs::File::create(&tmp)?;
        let mut w = std::io::BufWriter::with_capacity(1 << 20, f);
        fill(&mut w)?;
        let f = w.into_inner().map_err(|e| e.into_error())?;
        f.sync_all()?;
        if let Ok(meta) = std::fs::metadata(path) {
            std::fs::set_permissions(&tmp, meta.permissions())?;
        }
        std::fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Writes into `path` as it is (a device, a pipe, a dangling link), for the
/// outputs that cannot be replaced by a rename.
fn write_in_place(
    path: &Path,
    fill: impl FnOnce(&mut dyn std::io::Write) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let f = std::fs::OpenOptions::new()
        .write(true)
        .create(true)
        .truncate(true)
        .open(path)?;
    let mut w = std::io::BufWriter::with_capacity(1 << 16, f);
    fill(&mut w)?;
    std::io::Write::flush(&mut w)
}
