//! The registry of models: every model compiled in from `generated/`, found without hand
//! edits, and the models loaded from tapes at run time (`generated/<model>.tape.json`, no
//! compiler needed), which [`load`] adds or puts in place of a compiled model.

/// The generated models as types, one module per model: `generated::rod_cube::RodCube`
/// names the paper's model (a unit struct implementing [`Model`]), for programs that want
/// the compiler to check the name rather than [`find`] at run time.
// A force polynomial's accessor matches on the contact even where one contact has a
// polynomial (the same layout for every model).
#[allow(clippy::single_match)]
#[path = "../generated/mod.rs"]
pub mod generated;

use crate::model::Model;
use crate::tape::{self, TapeError, TapeModel};
use std::path::{Path, PathBuf};
use std::sync::{Arc, RwLock};

/// Where a model of the registry comes from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Provenance {
    /// Compiled into this program from `generated/`.
    Compiled,
    /// Run from a tape.
    Tape {
        /// The tape's file (`<embedded>/<model>.tape.json` for a compiled model's own).
        file: String,
        /// Why the tape and not compiled code.
        why: TapeRoute,
    },
}

/// Why a model runs from its tape.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TapeRoute {
    /// Asked for ([`interpret_compiled`], `rodcube run --interpreted`).
    Asked,
    /// No model of its name is compiled in.
    NotCompiled,
    /// A model of its name is compiled in, but from another program (the spec was changed and
    /// derived again since this program was built).
    DiffersFromCompiled,
    /// Derived from its spec for this run (`rodcube run --spec`); the file is the spec.
    DerivedNow,
}

/// A model's entry in the registry.
#[derive(Clone)]
pub struct Entry {
    /// The model.
    pub model: &'static dyn Model,
    /// Where it comes from.
    pub provenance: Provenance,
    /// The spec it was derived from, where that file has changed since (its tape records the
    /// spec's digest): the path it was found at.
    pub stale_spec: Option<PathBuf>,
    /// The text of the tape it runs from, as it was read (`None` where it runs compiled code,
    /// whose tape is [`embedded_tape`]).
    pub tape: Option<Arc<str>>,
}

struct Registry {
    models: &'static [&'static dyn Model],
    entries: Vec<Entry>,
}

static CURRENT: RwLock<Option<Registry>> = RwLock::new(None);

/// The models compiled into this program, in the order of their specs.
pub fn compiled() -> &'static [&'static dyn Model] {
    generated::MODELS
}

/// Every model: the compiled ones, with those loaded from tapes added or in their place.
pub fn all() -> &'static [&'static dyn Model] {
    let current = CURRENT.read().unwrap_or_else(|e| e.into_inner());
    current.as_ref().map_or(generated::MODELS, |r| r.models)
}

/// The model with this name, if there is one.
pub fn find(name: &str) -> Option<&'static dyn Model> {
    all().iter().copied().find(|m| m.info().name == name)
}

/// The registry's entry of a model: where it comes from and whether its spec changed since it
/// was derived (`None` for a name that is not a model).
pub fn entry(name: &str) -> Option<Entry> {
    let current = CURRENT.read().unwrap_or_else(|e| e.into_inner());
    if let Some(e) =
        (current.as_ref()).and_then(|r| r.entries.iter().find(|e| e.model.info().name == name))
    {
        return Some(e.clone());
    }
    find(name).map(|model| Entry {
        model,
        provenance: Provenance::Compiled,
        stale_spec: None,
        tape: None,
    })
}

/// The tape of a model of the registry, the model as data (what an FMU carries): the text it
/// was loaded from where it runs from a tape, the tape built into the program where it runs
/// compiled code (the same program); `None` for a name that is not a model.
pub fn tape_text(name: &str) -> Option<Arc<str>> {
    let e = entry(name)?;
    e.tape.or_else(|| embedded_tape(name).map(Arc::from))
}

/// The tape of a compiled model, as the program embeds it.
pub fn embedded_tape(name: &str) -> Option<&'static str> {
    generated::TAPES
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, text)| *text)
}

/// Puts `entries` into the registry, each in the place of a model of its name or after them.
fn install(entries: Vec<Entry>) {
    let mut current = CURRENT.write().unwrap_or_else(|e| e.into_inner());
    let registry = current.get_or_insert_with(|| Registry {
        models: generated::MODELS,
        entries: Vec::new(),
    });
    let mut models: Vec<&'static dyn Model> = registry.models.to_vec();
    for e in entries {
        let name = e.model.info().name;
        match models.iter().position(|m| m.info().name == name) {
            Some(i) => models[i] = e.model,
            None => models.push(e.model),
        }
        registry.entries.retain(|x| x.model.info().name != name);
        registry.entries.push(e);
    }
    // One small list per change, kept for the program's life: `all` hands out `'static`
    // slices.
    registry.models = Box::leak(models.into_boxed_slice());
}

/// Runs every compiled model from its embedded tape instead (`rodcube run --interpreted`):
/// the same program, evaluated rather than compiled, so every result is equal to the bit.
pub fn interpret_compiled() -> Result<(), TapeError> {
    let mut entries = Vec::new();
    for (name, text) in generated::TAPES {
        let file = format!("<embedded>/{name}.tape.json");
        let model: &'static TapeModel = tape::load_text(text, &file)?;
        entries.push(Entry {
            model,
            provenance: Provenance::Tape {
                file,
                why: TapeRoute::Asked,
            },
            stale_spec: None,
            tape: Some(Arc::from(*text)),
        });
    }
    install(entries);
    Ok(())
}

/// What [`load`] found in a directory.
#[derive(Clone, Default)]
pub struct Loaded {
    /// The models now run from the directory's tapes.
    pub models: Vec<&'static dyn Model>,
    /// The tapes of compiled models that hold the same program (the compiled code is kept).
    pub same_as_compiled: Vec<String>,
}

/// Loads every tape of a directory (`*.tape.json`, e.g. a project's `generated/`) into the
/// registry: a model not compiled in is added; one whose compiled code is another program
/// than its tape (its spec derived again since this program was built) runs from the tape; one
/// whose tape holds the compiled program keeps the compiled code. Where the tape's spec exists
/// beside the directory (`<dir>/../<spec>`) and has changed since it was derived, the entry
/// says so ([`Entry::stale_spec`]). Any tape the loader refuses fails the whole load, naming
/// it; nothing is installed then.
pub fn load(dir: &Path) -> Result<Loaded, TapeError> {
    load_from(dir, None)
}

/// [`load`] of the tapes just derived from `spec` into `dir` (`rodcube run --spec`): their
/// entries name the spec, as models derived for this run.
pub fn load_derived(dir: &Path, spec: &Path) -> Result<Loaded, TapeError> {
    load_from(dir, Some(spec))
}

fn load_from(dir: &Path, derived_from: Option<&Path>) -> Result<Loaded, TapeError> {
    let root = dir.parent().unwrap_or(Path::new("."));
    let mut entries = Vec::new();
    let mut loaded = Loaded::default();
    for path in tape::files_in(dir)? {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(&path).map_err(|e| TapeError::Io {
            file: file.clone(),
            message: e.to_string(),
        })?;
        let head = tape::header(&text, &file)?;
        let stale_spec = match derived_from {
            Some(_) => None,
            None => tape::stale_spec(&head.spec, &head.spec_digest, root),
        };
        let compiled = compiled()
            .iter()
            .copied()
            .find(|m| m.info().name == head.model);
        let embedded = embedded_tape(&head.model)
            .map(|t| tape::header(t, "<embedded>"))
            .transpose()?;
        // A compiled model's own program: the compiled code is kept (the tape is still checked).
        if let (Some(model), Some(own)) = (compiled, &embedded)
            && own.body_digest == head.body_digest
        {
            if text != embedded_tape(&head.model).unwrap_or_default() {
                tape::load_text(&text, &file)?;
            }
            if stale_spec.is_some() {
                // The model now in the registry stays (its compiled code, or its tape where
                // `interpret_compiled` put it there); only the note is added.
                let current = entry(&head.model);
                entries.push(Entry {
                    model: current.as_ref().map_or(model, |e| e.model),
                    tape: current.as_ref().and_then(|e| e.tape.clone()),
                    provenance: current.map_or(Provenance::Compiled, |e| e.provenance),
                    stale_spec,
                });
            }
            loaded.same_as_compiled.push(head.model);
            continue;
        }
        let model: &'static TapeModel = tape::load_text(&text, &file)?;
        let (file, why) = match (derived_from, compiled) {
            (Some(spec), _) => (spec.display().to_string(), TapeRoute::DerivedNow),
            (None, Some(_)) => (file, TapeRoute::DiffersFromCompiled),
            (None, None) => (file, TapeRoute::NotCompiled),
        };
        loaded.models.push(model);
        entries.push(Entry {
            model,
            provenance: Provenance::Tape { file, why },
            stale_spec,
            tape: Some(Arc::from(text)),
        });
    }
    install(entries);
    Ok(loaded)
}

/// The directories a program looks for tapes in, in order of precedence (the first that has a
/// model's tape wins): `--models DIR` where given, then `generated/` under the current
/// directory where it exists.
pub fn search_path(models: Option<&Path>) -> Vec<PathBuf> {
    let mut dirs = Vec::new();
    if let Some(d) = models {
        dirs.push(d.to_path_buf());
    }
    let local = PathBuf::from("generated");
    if local.is_dir() && models.is_none_or(|d| d != local) {
        dirs.push(local);
    }
    dirs
}

/// Loads the tapes of [`search_path`], the lowest precedence first so that the first directory
/// wins.
pub fn load_search_path(models: Option<&Path>) -> Result<(), TapeError> {
    for dir in search_path(models).iter().rev() {
        load(dir)?;
    }
    Ok(())
}
