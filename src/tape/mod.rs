//! Models run from their tapes, with no compiler: `generated/<model>.tape.json` holds the same
//! straight-line program as `generated/<model>.rs`, and [`TapeModel`] evaluates it.
//!
//! A tape is data, never code. [`parse`] refuses, with a [`TapeError`] naming the file and what
//! is wrong, a tape that is not one, is of another format version, whose body does not match
//! its digest (truncated or edited by hand), whose info is inconsistent or gives an output more
//! than [`MAX_LENGTH`] numbers, or whose programs name an unknown operation, a register not yet
//! written, an argument the method does not have or an index past the length the info gives it.
//! A tape that passes cannot make the evaluator index out of bounds. The format is described in
//! `docs/tape.md`.

mod check;
mod eval;
pub mod format;
pub mod info;

pub use check::MAX_LENGTH;
pub use eval::TapeModel;
pub use format::{FORMAT, VERSION};

use check::{FAST_PATH, METHODS, PARTIALS, REQUIRED};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// The command that regenerates the tapes of a project.
pub const REGENERATE: &str =
    "cargo derive (or rodcube derive, in a binary built with the feature `derive`)";

/// Why a tape was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TapeError {
    /// The file could not be read.
    #[error("{file}: cannot read the tape: {message}")]
    Io {
        /// The file.
        file: String,
        /// The system's reason.
        message: String,
    },
    /// Not JSON of a tape's shape.
    #[error("{file}:{line}:{column}: not a rodcube tape: {message}")]
    Syntax {
        /// The file.
        file: String,
        /// Line of the error (from 1).
        line: usize,
        /// Column of the error (from 1).
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// Its `format` field is not [`FORMAT`].
    #[error("{file}: `format` is {found:?}, not {FORMAT:?}: not a rodcube tape")]
    Format {
        /// The file.
        file: String,
        /// The format it names.
        found: String,
    },
    /// Written by another version of the format.
    #[error(
        "{file}: tape format version {found}, but this rodcube reads version {VERSION}; \
         regenerate it from its spec with {REGENERATE}"
    )]
    Version {
        /// The file.
        file: String,
        /// Its version.
        found: u32,
    },
    /// The body does not match its digest.
    #[error(
        "{file}: the body's digest is {found}, not the {expected} the tape records: the tape \
         was truncated or edited by hand; regenerate it with {REGENERATE}"
    )]
    Digest {
        /// The file.
        file: String,
        /// The digest it records.
        expected: String,
        /// The body's.
        found: String,
    },
    /// The model's info is inconsistent.
    #[error("{file}: `body.info`: {message}")]
    Info {
        /// The file.
        file: String,
        /// What is wrong.
        message: String,
    },
    /// A method's program is refused.
    #[error("{file}: method `{method}`: {message}")]
    Method {
        /// The file.
        file: String,
        /// The method.
        method: String,
        /// What is wrong.
        message: String,
    },
}

/// The arguments and the outputs of a method a tape may hold, by its name in the trait, in
/// the trait's order (`None` for a name that is not one): what the derivation's compiler binds
/// a generated method's parameters to.
pub fn signature(method: &str) -> Option<(Vec<format::Arg>, Vec<format::Arg>)> {
    let s = METHODS.iter().find(|s| s.name == method)?;
    Some((s.inputs().collect(), s.outputs().collect()))
}

/// The name of every method a tape may hold, in the trait's order.
pub fn method_names() -> impl Iterator<Item = &'static str> {
    METHODS.iter().map(|s| s.name)
}

/// Reads, checks and prepares a tape from its text; `file` names it in errors.
pub fn parse(text: &str, file: &str) -> Result<TapeModel, TapeError> {
    let f = || file.to_string();
    let tape: format::TapeFile = serde_json::from_str(text).map_err(|e| TapeError::Syntax {
        file: f(),
        line: e.line(),
        column: e.column(),
        message: e.to_string(),
    })?;
    if tape.format != FORMAT {
        return Err(TapeError::Format {
            file: f(),
            found: tape.format,
        });
    }
    if tape.version != VERSION {
        return Err(TapeError::Version {
            file: f(),
            found: tape.version,
        });
    }
    let found = tape.body.digest();
    if found != tape.body_digest {
        return Err(TapeError::Digest {
            file: f(),
            expected: tape.body_digest,
            found,
        });
    }
    let info_error = |message: String| TapeError::Info { file: f(), message };
    let info = &tape.body.info;
    info.check().map_err(info_error)?;
    check::lengths(info).map_err(info_error)?;
    if info.name != tape.model {
        return Err(info_error(format!(
            "names the model `{}`, the tape `{}`",
            info.name, tape.model
        )));
    }
    let method_error = |method: &str, message: String| TapeError::Method {
        file: f(),
        method: method.to_string(),
        message,
    };
    let mut programs: Vec<Option<check::Program>> = vec![None; METHODS.len()];
    for function in &tape.body.functions {
        let Some(s) = METHODS.iter().find(|s| s.name == function.name) else {
            return Err(method_error(&function.name, "no such method".into()));
        };
        if s.reduction && info.reduction.is_none() {
            return Err(method_error(
                s.name,
                "a fast path's method in a model without one".into(),
            ));
        }
        let slot = &mut programs[s.method as usize];
        if slot.is_some() {
            return Err(method_error(s.name, "given twice".into()));
        }
        *slot = Some(check::program(function, s, info).map_err(|m| method_error(s.name, m))?);
    }
    let has = |m: check::Method| programs[m as usize].is_some();
    let missing = |m: check::Method| method_error(METHODS[m as usize].name, "missing".into());
    for &m in REQUIRED {
        if !has(m) {
            return Err(missing(m));
        }
    }
    if info.reduction.is_some() {
        for &m in FAST_PATH {
            if !has(m) {
                return Err(missing(m));
            }
        }
        if PARTIALS.iter().any(|&m| has(m))
            && let Some(&m) = PARTIALS.iter().find(|&&m| !has(m))
        {
            return Err(missing(m));
        }
    }
    if has(check::Method::TangentRows) != has(check::Method::InitialTangents) {
        let m = if has(check::Method::TangentRows) {
            check::Method::InitialTangents
        } else {
            check::Method::TangentRows
        };
        return Err(missing(m));
    }
    Ok(TapeModel {
        info: interned_info(info, &found),
        programs,
        digest: found,
        source: file.to_string(),
        spec: (tape.spec, tape.spec_digest),
    })
}

/// The `'static` info of a model, made once per distinct tape body.
fn interned_info(info: &info::Info, digest: &str) -> &'static crate::model::ModelInfo {
    static INFOS: Mutex<Vec<(String, &'static crate::model::ModelInfo)>> = Mutex::new(Vec::new());
    let mut infos = INFOS.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((_, i)) = infos.iter().find(|(d, _)| d == digest) {
        return i;
    }
    let leaked = info.leak();
    infos.push((digest.to_string(), leaked));
    leaked
}

/// A model loaded once per distinct tape (by its body's digest and source), so that a program
/// that loads the same tapes again does not grow.
fn interned(model: TapeModel) -> &'static TapeModel {
    static MODELS: Mutex<Vec<&'static TapeModel>> = Mutex::new(Vec::new());
    let mut models = MODELS.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(m) = (models.iter()).find(|m| m.digest == model.digest && m.source == model.source)
    {
        return m;
    }
    let leaked: &'static TapeModel = Box::leak(Box::new(model));
    models.push(leaked);
    leaked
}

/// Reads a tape file: [`parse`] of its text, kept for the program's life.
pub fn load_file(path: &Path) -> Result<&'static TapeModel, TapeError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| TapeError::Io {
        file: file.clone(),
        message: e.to_string(),
    })?;
    parse(&text, &file).map(interned)
}

/// Reads a tape from text, kept for the program's life (the embedded tapes of the compiled
/// models, a tape just derived in memory).
pub fn load_text(text: &str, file: &str) -> Result<&'static TapeModel, TapeError> {
    parse(text, file).map(interned)
}

/// The tape files of a directory (`*.tape.json`), sorted by name.
pub fn files_in(dir: &Path) -> Result<Vec<PathBuf>, TapeError> {
    let entries = std::fs::read_dir(dir).map_err(|e| TapeError::Io {
        file: dir.display().to_string(),
        message: e.to_string(),
    })?;
    let mut out: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.to_string_lossy().ends_with(".tape.json") && p.is_file())
        .collect();
    out.sort();
    Ok(out)
}

/// What a tape's header says, read without checking its body.
#[derive(Debug, Clone, PartialEq, Eq, serde::Deserialize)]
pub struct Header {
    /// The model.
    pub model: String,
    /// The spec, relative to the project root.
    pub spec: String,
    /// The spec's digest when it was derived.
    pub spec_digest: String,
    /// The body's digest, as recorded.
    pub body_digest: String,
}

/// The header of a tape (its body skipped, not checked).
pub fn header(text: &str, file: &str) -> Result<Header, TapeError> {
    serde_json::from_str(text).map_err(|e| TapeError::Syntax {
        file: file.to_string(),
        line: e.line(),
        column: e.column(),
        message: e.to_string(),
    })
}

/// Whether the spec a tape was derived from has changed since: `Some(spec path)` when the spec
/// (`spec`, relative to `root`) exists and its text's digest differs from `recorded`.
pub fn stale_spec(spec: &str, recorded: &str, root: &Path) -> Option<PathBuf> {
    let path = root.join(spec);
    let text = std::fs::read_to_string(&path).ok()?;
    (format::digest(&text) != recorded).then_some(path)
}
