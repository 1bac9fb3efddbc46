//! Reading a program from disk: size limit, directories, UTF-8 (writing is
//! `crate::write`'s; `write_atomic` here is its short name).
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

/// Writes `contents` to `path` atomically (see `crate::write::replace`).
pub fn write_atomic(path: &Path, contents: &[u8]) -> std::io::Result<()> {
    crate::write::replace_with_bytes(path, contents)
}

/// Streams into `path` atomically (see `crate::write::replace`).
pub fn write_atomic_with(
    path: &Path,
    fill: impl FnOnce(&mut dyn std::io::Write) -> std::io::Result<()>,
) -> std::io::Result<()> {
    crate::write::replace(path, fill)
}
