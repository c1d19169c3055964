//! Output files: atomic writes into one output directory, with names checked before they
//! become paths so that nothing is written outside it.
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
    let (tmp, mut file) = create_temporary(path).map_err(fail)?;
    let written = (|| {
        let mut w = io::BufWriter::new(&mut file);
        fill(&mut w)?;
        w.flush()?;
        drop(w);
        file.sync_all()?;
        drop(file);
        fs::rename(&tmp, path)
    })();
    if let Err(e) = written {
        let _ = fs::remove_file(&tmp);
        return Err(fail(e));
    }
    // Make the rename itself durable; failing here leaves a complete file either way.
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty())
        && let Ok(d) = File::open(dir)
    {
        let _ = d.sync_all();
    }
    Ok(())
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
