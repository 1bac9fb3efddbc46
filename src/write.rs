//! Writing files so that nothing is lost: a crash, a full disk, two writers at
//! once or an interrupt leave the old file or the new one, never a mix, never
//! a stray temporary file.
//!
//! Owns: `replace`, the one way lsyc writes a file (programs, drawings,
//! meshes, the studio's saves): a temporary file with a unique name in the
//! target's folder, filled, flushed, synced to disk, given the target's
//! permissions, then renamed over it; writers of one file in this process
//! take turns; a read-only file is refused, never replaced; the temporary
//! files of writes under way, so that an interrupt can remove them
//! (`remove_temp_files`). Must not print, install signal handlers (the CLI
//! does) or decide which paths a command may write (the CLI's output rules).

use std::collections::{HashMap, HashSet};
use std::fs::{self, File, Permissions};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use tempfile::NamedTempFile;
use thiserror::Error;

/// Why a file is not replaced although the disk would allow it.
#[derive(Debug, Error)]
pub enum Refused {
    /// The file has no write permission: replacing it by a rename would
    /// ignore what its owner said.
    #[error("it is read-only (make it writable first, e.g. `chmod u+w`, if it should change)")]
    ReadOnly,
    /// The process is being interrupted: no new temporary file is made.
    #[error("lsyc is being interrupted")]
    Interrupted,
}

impl From<Refused> for io::Error {
    fn from(r: Refused) -> io::Error {
        let kind = match r {
            Refused::ReadOnly => io::ErrorKind::PermissionDenied,
            Refused::Interrupted => io::ErrorKind::Interrupted,
        };
        io::Error::new(kind, r)
    }
}

/// Writes `contents` to `path` through `replace`.
pub fn replace_with_bytes(path: &Path, contents: &[u8]) -> io::Result<()> {
    replace(path, |w| w.write_all(contents))
}

/// Streams into a temporary file beside `path` and renames it over `path` only
/// when `fill` succeeds and the data is on disk; on failure nothing is left
/// behind and `path` is untouched.
///
/// Only a regular file (or a new one) is replaced that way. A symbolic link is
/// followed, so the link stays and its target gets the new contents; a device,
/// pipe or socket (`-o /dev/null`, `-o /dev/stdout`, a FIFO) is written in place,
/// since renaming over it would replace the device with a plain file.
pub fn replace(path: &Path, fill: impl FnOnce(&mut dyn Write) -> io::Result<()>) -> io::Result<()> {
    let target = match Target::of(path) {
        Target::InPlace(p) => return write_in_place(&p, fill),
        Target::File(p) => p,
    };
    in_turn(&target, || {
        let permissions = writable(&target)?;
        let (mut tmp, registered) = create_temp(&target)?;
        {
            let mut w = BufWriter::with_capacity(1 << 20, tmp.as_file_mut());
            fill(&mut w)?;
            w.flush()?;
        }
        tmp.as_file().sync_all()?;
        if let Some(p) = permissions {
            fs::set_permissions(tmp.path(), p)?;
        }
        persist(tmp, registered, &target)?;
        sync_folder(&target);
        Ok(())
    })
}

/// What a path is, for writing.
enum Target {
    /// A regular file, or one that does not exist yet: replaced.
    File(PathBuf),
    /// A device, pipe, socket or dangling link: written as it is.
    InPlace(PathBuf),
}

impl Target {
    fn of(path: &Path) -> Target {
        let file = match fs::symlink_metadata(path) {
            Ok(meta) if meta.file_type().is_symlink() => match fs::canonicalize(path) {
                Ok(target) => target,
                // A dangling link: writing through it creates its target.
                Err(_) => return Target::InPlace(path.to_path_buf()),
            },
            _ => path.to_path_buf(),
        };
        match fs::metadata(&file) {
            Ok(meta) if !meta.is_file() => Target::InPlace(file),
            _ => Target::File(file),
        }
    }
}

/// The permissions of an existing file that may be written (`None` for a new
/// file), or why it may not.
fn writable(path: &Path) -> io::Result<Option<Permissions>> {
    let meta = match fs::metadata(path) {
        Ok(m) => m,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(e),
    };
    if meta.permissions().readonly() {
        return Err(Refused::ReadOnly.into());
    }
    // Write bits for someone do not say that this user may write it (and an
    // administrator may open anything): opening it for writing, without
    // truncating, asks the system.
    match fs::OpenOptions::new().write(true).open(path) {
        Ok(_) => Ok(Some(meta.permissions())),
        Err(e) if e.kind() == io::ErrorKind::PermissionDenied => Err(Refused::ReadOnly.into()),
        Err(e) => Err(e),
    }
}

/// Makes a rename durable: the folder's entry is synced too (best effort; some
/// file systems cannot sync a folder).
fn sync_folder(path: &Path) {
    if let Ok(dir) = File::open(folder(path)) {
        let _ = dir.sync_all();
    }
}

/// The folder a file is in (`.` for a bare name).
fn folder(path: &Path) -> PathBuf {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// Writes into `path` as it is (a device, a pipe, a dangling link), for the
/// outputs that cannot be replaced by a rename.
fn write_in_place(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> io::Result<()> {
    let f = fs::OpenOptions::new()
        .write(true)
        .create(true)
        .truncate(true)
        .open(path)?;
    let mut w = BufWriter::with_capacity(1 << 16, f);
    fill(&mut w)?;
    w.flush()
}

/// The temporary files of writes under way; `closed` once an interrupt has
/// removed them.
#[derive(Default)]
struct Temps {
    paths: HashSet<PathBuf>,
    closed: bool,
}

static TEMPS: Mutex<Option<Temps>> = Mutex::new(None);

fn temps() -> MutexGuard<'static, Option<Temps>> {
    TEMPS.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Removes the temporary files of every write under way and refuses new ones,
/// for an interrupt (Ctrl-C) just before the process exits. Safe to call from
/// any thread; a write that finishes meanwhile either renamed its file first
/// or finds it gone.
pub fn remove_temp_files() {
    let mut guard = temps();
    let temps = guard.get_or_insert_with(Temps::default);
    temps.closed = true;
    for p in temps.paths.drain() {
        let _ = fs::remove_file(p);
    }
}

/// A temporary file's place in the registry, given up when dropped.
struct Registered(PathBuf);

impl Drop for Registered {
    fn drop(&mut self) {
        if let Some(t) = temps().as_mut() {
            t.paths.remove(&self.0);
        }
    }
}

/// A new temporary file beside `target`, named `.NAME.XXXXXX.lsyc.tmp`
/// (hidden, unique, and telling whose it is), registered for interrupts.
fn create_temp(target: &Path) -> io::Result<(NamedTempFile, Registered)> {
    let name = target
        .file_name()
        .map_or_else(|| "out".into(), |n| n.to_string_lossy().into_owned());
    let prefix = format!(".{name}.");
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(".lsyc.tmp");
    #[cfg(unix)]
    {
        // A new file gets the usual 0666 less the umask, not tempfile's 0600.
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(Permissions::from_mode(0o666));
    }
    let mut guard = temps();
    let temps = guard.get_or_insert_with(Temps::default);
    if temps.closed {
        return Err(Refused::Interrupted.into());
    }
    let file = builder
        .tempfile_in(folder(target))
        .map_err(|e| plain(e, target))?;
    temps.paths.insert(file.path().to_path_buf());
    let registered = Registered(file.path().to_path_buf());
    Ok((file, registered))
}

/// Why no temporary file could be made beside `target`, in the target's
/// terms (the tempfile crate's message names the temporary file, which the
/// user never saw).
fn plain(e: io::Error, target: &Path) -> io::Error {
    let dir = folder(target);
    let why = match e.kind() {
        io::ErrorKind::NotFound => format!("the folder `{}` does not exist", dir.display()),
        io::ErrorKind::PermissionDenied => {
            format!("the folder `{}` may not be written", dir.display())
        }
        _ => return e,
    };
    io::Error::new(e.kind(), why)
}

/// Renames the temporary file over `target`, under the registry's lock, so
/// that an interrupt removes it before or not at all. On failure the file is
/// dropped, which removes it.
fn persist(file: NamedTempFile, registered: Registered, target: &Path) -> io::Result<()> {
    let mut guard = temps();
    let temps = guard.get_or_insert_with(Temps::default);
    if temps.closed {
        return Err(Refused::Interrupted.into());
    }
    temps.paths.remove(&registered.0);
    let renamed = file.persist(target).map(drop).map_err(|e| e.error);
    drop(guard);
    drop(registered);
    renamed
}

/// The writers' turns: one lock per file being written (by its path with
/// the folder resolved), forgotten when no writer waits for it.
static TURNS: Mutex<Option<HashMap<PathBuf, Arc<Mutex<()>>>>> = Mutex::new(None);

fn turns() -> MutexGuard<'static, Option<HashMap<PathBuf, Arc<Mutex<()>>>>> {
    TURNS.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Runs `f` when no other writer in this process is writing `path`.
fn in_turn<T>(path: &Path, f: impl FnOnce() -> T) -> T {
    let key = identity(path);
    let lock = turns()
        .get_or_insert_with(HashMap::new)
        .entry(key.clone())
        .or_default()
        .clone();
    let result = {
        let _held = lock.lock().unwrap_or_else(PoisonError::into_inner);
        f()
    };
    let mut guard = turns();
    drop(lock);
    if let Some(map) = guard.as_mut()
        && map.get(&key).is_some_and(|l| Arc::strong_count(l) == 1)
    {
        map.remove(&key);
    }
    result
}

/// A file's name with its folder resolved, so that `a.lsy` and `./a.lsy`
/// take the same turns.
fn identity(path: &Path) -> PathBuf {
    let dir = fs::canonicalize(folder(path)).unwrap_or_else(|_| folder(path));
    match path.file_name() {
        Some(name) => dir.join(name),
        None => dir,
    }
}
