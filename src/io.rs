//! Output files: atomic writes into one output directory, with names checked before they
//! become paths so that nothing is written outside it, and [`write_all_atomic`], which writes a
//! set of files all or nothing (the derivation tool's `generated/` and its manifest).
//!
//! Architecture invariant: every file the CLI writes goes through [`OutDir::write`], which
//! writes a temporary file in the same directory and renames it over the target. A reader sees
//! the old file or the new one, never half of one; on any error the temporary file is removed.

use std::fs::{self, File, OpenOptions};
use std::io::{self, Write};
use std::path::{Component, Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Longest file name accepted (bytes), well under every file system's limit.
pub const MAX_NAME_LEN: usize = 128;

/// Why an output could not be written.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A name that is not a plain file name (it would escape the output directory, or is
    /// hidden, empty, too long or has unusual characters).
    #[error("refusing output name {name:?}: {reason}")]
    BadName {
        /// The name as given.
        name: String,
        /// Why it was refused.
        reason: &'static str,
    },
    /// The output directory could not be created.
    #[error("cannot create the output directory {}: {source}", path.display())]
    CreateDir {
        /// The directory.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: io::Error,
    },
    /// Writing, syncing or renaming failed; no partial file was left.
    #[error("cannot write {}: {source}", path.display())]
    Write {
        /// The target file.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: io::Error,
    },
}

/// Checks that `name` is a plain file name safe to join to the output directory: ASCII
/// letters, digits, `_`, `-` and `.`, not starting with `.` (so not `.`, `..` or hidden), no
/// separators, at most [`MAX_NAME_LEN`] bytes.
pub fn check_name(name: &str) -> Result<(), Error> {
    let bad = |reason| {
        Err(Error::BadName {
            name: name.to_string(),
            reason,
        })
    };
    if name.is_empty() {
        return bad("it is empty");
    }
    if name.len() > MAX_NAME_LEN {
        return bad("it is too long");
    }
    if name.contains(['/', '\\']) {
        return bad("it contains a path separator and could leave the output directory");
    }
    if name.starts_with('.') {
        return bad("it starts with `.` (a parent, current or hidden entry)");
    }
    if !name
        .chars()
        .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.'))
    {
        return bad("only ASCII letters, digits, `_`, `-` and `.` are allowed");
    }
    Ok(())
}

/// The directory all outputs of one run go to.
#[derive(Debug, Clone)]
pub struct OutDir {
    root: PathBuf,
}

impl OutDir {
    /// Creates the directory (and its parents) if needed.
    pub fn create(root: impl AsRef<Path>) -> Result<OutDir, Error> {
        let root = root.as_ref().to_path_buf();
        fs::create_dir_all(&root).map_err(|source| Error::CreateDir {
            path: root.clone(),
            source,
        })?;
        Ok(OutDir { root })
    }

    /// The directory.
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// The path of output `name` inside the directory, after [`check_name`]; the result is
    /// always a direct child of [`OutDir::root`].
    pub fn path_of(&self, name: &str) -> Result<PathBuf, Error> {
        check_name(name)?;
        let mut parts = Path::new(name).components();
        match (parts.next(), parts.next()) {
            (Some(Component::Normal(_)), None) => Ok(self.root.join(name)),
            _ => Err(Error::BadName {
                name: name.to_string(),
                reason: "it is not a single path component",
            }),
        }
    }

    /// Writes `contents` to output `name` atomically; returns the path written.
    pub fn write(&self, name: &str, contents: &[u8]) -> Result<PathBuf, Error> {
        let path = self.path_of(name)?;
        write_atomic(&path, contents)?;
        Ok(path)
    }
}

/// Writes `contents` to `path` atomically (see [`write_atomic_with`]).
pub fn write_atomic(path: &Path, contents: &[u8]) -> Result<(), Error> {
    write_atomic_with(path, |w| w.write_all(contents))
}

/// Writes `path` atomically: `fill` writes into a new temporary file in the same directory,
/// which is flushed to disk and renamed over `path`. If `fill`, the sync or the rename fails,
/// the temporary file is removed and `path` is left as it was.
pub fn write_atomic_with(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> Result<(), Error> {
    let fail = |source| Error::Write {
        path: path.to_path_buf(),
        source,
    };
    let tmp = write_temporary(path, fill).map_err(fail)?;
    if let Err(e) = fs::rename(&tmp, path) {
        let _ = fs::remove_file(&tmp);
        return Err(fail(e));
    }
    sync_parent(path);
    Ok(())
}

/// Writes several files as one change: every target holds its new contents, or (on an error)
/// every target is as it was.
///
/// First each file's new contents go to a temporary file beside its target (flushed to disk),
/// and each target's old contents are kept in memory; if any of that fails, the temporaries
/// are removed and no target was touched. Only then are the temporaries renamed over their
/// targets, in the order given. If a rename fails, the remaining temporaries are removed and
/// the targets already replaced get their old contents back (a target that did not exist is
/// removed again); the error names the file whose rename failed, and says so if restoring
/// failed too. A target that is a directory is not refused up front: no rename can replace
/// it, so it fails there like any other rename. Other targets that are not regular files
/// (symbolic links, devices) are refused before anything is written.
pub fn write_all_atomic<P: AsRef<Path>, C: AsRef<[u8]>>(files: &[(P, C)]) -> Result<(), Error> {
    let fail = |path: &Path, source| Error::Write {
        path: path.to_path_buf(),
        source,
    };
    // Staged files: (temporary, target, the target's old contents if it was a file).
    let mut staged: Vec<(PathBuf, &Path, Option<Vec<u8>>)> = Vec::with_capacity(files.len());
    for (path, contents) in files {
        let path = path.as_ref();
        let prepared = old_contents(path).and_then(|old| {
            write_temporary(path, |w| w.write_all(contents.as_ref())).map(|tmp| (tmp, old))
        });
        match prepared {
            Ok((tmp, old)) => staged.push((tmp, path, old)),
            Err(source) => {
                for (tmp, ..) in &staged {
                    let _ = fs::remove_file(tmp);
                }
                return Err(fail(path, source));
            }
        }
    }
    for (i, (tmp, path, _)) in staged.iter().enumerate() {
        if let Err(source) = fs::rename(tmp, path) {
            for (tmp, ..) in &staged[i..] {
                let _ = fs::remove_file(tmp);
            }
            let unrestored = restore(&staged[..i]);
            if unrestored.is_empty() {
                return Err(fail(path, source));
            }
            let message = format!(
                "{source}; restoring the files already replaced failed too: {}",
                unrestored.join("; ")
            );
            return Err(fail(path, io::Error::new(source.kind(), message)));
        }
    }
    let mut synced: Vec<&Path> = Vec::new();
    for (_, path, _) in &staged {
        let dir = path.parent().unwrap_or(Path::new(""));
        if !synced.contains(&dir) {
            synced.push(dir);
            sync_parent(path);
        }
    }
    Ok(())
}

/// The contents of `path` before a transaction replaces it: `None` if there is no file to keep
/// (it does not exist, or it is a directory, which no rename can replace).
fn old_contents(path: &Path) -> io::Result<Option<Vec<u8>>> {
    match fs::symlink_metadata(path) {
        Err(e) if e.kind() == io::ErrorKind::NotFound => Ok(None),
        Err(e) => Err(e),
        Ok(meta) if meta.is_dir() => Ok(None),
        Ok(meta) if meta.is_file() => fs::read(path).map(Some),
        Ok(_) => Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            "not a regular file; refusing to replace it",
        )),
    }
}

/// Puts back the old contents of targets already renamed over, last first; returns what could
/// not be restored.
fn restore(replaced: &[(PathBuf, &Path, Option<Vec<u8>>)]) -> Vec<String> {
    let mut failed = Vec::new();
    for (_, path, old) in replaced.iter().rev() {
        let restored = match old {
            Some(bytes) => write_atomic(path, bytes).map_err(|e| e.to_string()),
            None => match fs::remove_file(path) {
                Err(e) if e.kind() != io::ErrorKind::NotFound => {
                    Err(format!("{}: {e}", path.display()))
                }
                _ => Ok(()),
            },
        };
        if let Err(e) = restored {
            failed.push(e);
        }
    }
    failed
}

/// A new temporary file beside `path` holding what `fill` writes, flushed to disk; on any error
/// it is removed again.
fn write_temporary(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> io::Result<PathBuf> {
    let (tmp, mut file) = create_temporary(path)?;
    let written = (|| {
        let mut w = io::BufWriter::new(&mut file);
        fill(&mut w)?;
        w.flush()?;
        drop(w);
        file.sync_all()
    })();
    drop(file);
    match written {
        Ok(()) => Ok(tmp),
        Err(e) => {
            let _ = fs::remove_file(&tmp);
            Err(e)
        }
    }
}

/// Makes renames in `path`'s directory durable; failing here leaves complete files either way.
fn sync_parent(path: &Path) {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty())
        && let Ok(d) = File::open(dir)
    {
        let _ = d.sync_all();
    }
}

/// A new, exclusively created temporary file beside `path`: `.<name>.<pid>.<n>.tmp`.
fn create_temporary(path: &Path) -> io::Result<(PathBuf, File)> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let name = path
        .file_name()
        .ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, "the path has no file name"))?;
    let dir = path.parent().unwrap_or(Path::new(""));
    loop {
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let mut tmp_name = std::ffi::OsString::from(".");
        tmp_name.push(name);
        tmp_name.push(format!(".{}.{n}.tmp", std::process::id()));
        let tmp = dir.join(tmp_name);
        match OpenOptions::new().write(true).create_new(true).open(&tmp) {
            Ok(f) => return Ok((tmp, f)),
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(e),
        }
    }
}
