//! Which files a command may write: never one it reads, and never, beside
//! its output, a file that lsyc did not write itself.
//!
//! Owns: the rules, checked before anything is written (docs/outputs.md,
//! "Which files lsyc writes over"):
//! - no output (`-o`, an OBJ's `.mtl`, a frame of `--frames`) is a file the
//!   command reads (the program, an `--element` drawing, the drawing
//!   inferred from), whatever its name (links followed), even with
//!   `--force`;
//! - a file written beside the output (an `.mtl`, a frame) that exists,
//!   is not empty and does not carry lsyc's mark (`lsyc::render::mark`) is
//!   somebody else's: a usage error, unless `--force`;
//! - the file `-o` names is the user's choice: it is replaced (an earlier
//!   output, or any other file, as the shell's `>` would).
//!
//! Must not write or print: the command reports the refusal.

use std::path::Path;
#[cfg(not(unix))]
use std::path::PathBuf;
use thiserror::Error;

/// Why a command may not write a file. Exit status 2 (a usage error).
#[derive(Debug, Error, PartialEq)]
pub enum Clash {
    #[error("`{path}` ({role}) is {input}, which this command reads")]
    Input {
        role: String,
        path: String,
        input: String,
    },
    #[error("`{path}` ({role}) exists and was not written by lsyc")]
    NotOurs { role: String, path: String },
}

impl Clash {
    /// What to do about it.
    pub fn help(&self) -> &'static str {
        match self {
            Clash::Input { .. } => {
                "choose another output name: lsyc never writes over a file it reads (not even with --force)"
            }
            Clash::NotOurs { .. } => {
                "move that file away or choose another output name; --force replaces it"
            }
        }
    }
}

/// A file a command reads, by identity (device and inode on Unix, else the
/// resolved path), so that a link or another spelling of the path is the
/// same file.
#[derive(Clone, Debug, PartialEq, Eq)]
struct Identity {
    #[cfg(unix)]
    file: (u64, u64),
    #[cfg(not(unix))]
    file: PathBuf,
}

impl Identity {
    /// The identity of an existing file; `None` if there is none there.
    #[cfg(unix)]
    fn of(path: &Path) -> Option<Identity> {
        use std::os::unix::fs::MetadataExt;
        let meta = std::fs::metadata(path).ok()?;
        Some(Identity {
            file: (meta.dev(), meta.ino()),
        })
    }

    #[cfg(not(unix))]
    fn of(path: &Path) -> Option<Identity> {
        let file = std::fs::canonicalize(path).ok()?;
        Some(Identity { file })
    }
}

/// The files a command reads, each with how a message names it ("the
/// program", "the drawing of `--element Leaf`").
#[derive(Default)]
pub struct Inputs {
    files: Vec<(Identity, String)>,
}

impl Inputs {
    /// Adds `path` (if it exists) as `what`.
    pub fn add(&mut self, path: &Path, what: impl Into<String>) {
        if let Some(id) = Identity::of(path) {
            self.files.push((id, what.into()));
        }
    }

    fn find(&self, path: &Path) -> Option<&str> {
        let id = Identity::of(path)?;
        self.files
            .iter()
            .find(|(i, _)| *i == id)
            .map(|(_, w)| w.as_str())
    }
}

/// How an output came to be named.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Made {
    /// The file the user named (`-o`).
    Named,
    /// A file lsyc names beside it (an `.mtl`, a frame).
    Beside,
}

/// Checks that `path` may be written: `role` says what it is in a message
/// ("the output", "the materials of `tree.obj`", "frame 3").
pub fn check(
    path: &Path,
    role: &str,
    made: Made,
    inputs: &Inputs,
    force: bool,
) -> Result<(), Clash> {
    if let Some(input) = inputs.find(path) {
        return Err(Clash::Input {
            role: role.to_string(),
            path: path.display().to_string(),
            input: input.to_string(),
        });
    }
    let somebody_elses = made == Made::Beside
        && !force
        && std::fs::metadata(path).is_ok_and(|m| m.is_file())
        && !lsyc::render::mark::made_by_lsyc(path);
    if somebody_elses {
        return Err(Clash::NotOurs {
            role: role.to_string(),
            path: path.display().to_string(),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inputs_are_refused_under_any_name_and_sidecars_by_their_mark() {
        let dir = tempfile::tempdir().expect("tempdir");
        let program = dir.path().join("tree.lsy");
        std::fs::write(&program, "lsystem T { axiom F; }").expect("writes");
        let mut inputs = Inputs::default();
        inputs.add(&program, "the program");
        let other_name = dir.path().join(".").join("tree.lsy");
        assert!(matches!(
            check(&other_name, "the output", Made::Named, &inputs, true),
            Err(Clash::Input { .. })
        ));
        let mtl = dir.path().join("tree.mtl");
        std::fs::write(&mtl, "newmtl bark\n").expect("writes");
        assert!(matches!(
            check(&mtl, "the materials", Made::Beside, &inputs, false),
            Err(Clash::NotOurs { .. })
        ));
        assert_eq!(
            check(&mtl, "the materials", Made::Beside, &inputs, true),
            Ok(())
        );
        assert_eq!(
            check(&mtl, "the output", Made::Named, &inputs, false),
            Ok(())
        );
        let new = dir.path().join("new.mtl");
        assert_eq!(
            check(&new, "the materials", Made::Beside, &inputs, false),
            Ok(())
        );
    }
}
