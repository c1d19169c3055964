//! The derivation tool (cargo feature `derive`): model specs in `derivations/*.yaml` are
//! derived by Symbolica and rendered through `templates/` into `generated/`.
//!
//! The modules form layers, bottom-up; each imports only the layers below it and, within the
//! stages, only earlier stages (no module imports a later one, no two import each other):
//!
//! 1. shared by every stage, below them all: [`types`] (what the stages hand each other, the
//!    presentation's results included, and the layer's errors: [`types::StepError`] of a step,
//!    [`types::DeriveError`] placed at a spec field), [`cas`] (the only module that calls
//!    Symbolica), [`algebra`] (trigonometric rewriting and polynomial helpers) and
//!    [`positivity`] (proofs that a push stays positive over a phase);
//! 2. the stages of the derivation proper, a file each: [`read`] (the spec's expressions) →
//!    [`setup`] → [`lagrangian`] → [`equations`] → [`constraints`] → [`reduction`] →
//!    [`partials`] → [`forces`] → [`tangents`] (the general model's, for the forward
//!    sensitivities); [`mechanics`] runs them in that order for each phase of a spec;
//! 3. presentation: [`present`] (forms checked equal), then [`steps`] and [`dimensionless`];
//! 4. emission: [`emit`] (its `latex`, `lower` (straight-line Rust) and `method` beneath flat
//!    template contexts) → tera → rustfmt → `generated/`;
//! 5. this module, which runs the derivation, the presentation and the emission of each spec.
//!
//! Every Symbolica call runs on one dedicated thread ([`on_cas_thread`]). In check mode
//! nothing is written; stale files are reported.

pub mod algebra;
pub mod cas;
pub mod constraints;
pub mod dimensionless;
pub mod emit;
pub mod equations;
pub mod forces;
pub mod lagrangian;
pub mod mechanics;
pub mod partials;
pub mod positivity;
pub mod present;
pub mod read;
pub mod reduction;
pub mod setup;
pub mod steps;
pub mod tangents;
pub mod types;

// Spec parsing and expressions need no Symbolica: they live in the runtime crate.
pub use crate::spec::{self, expr};

use crate::yaml::{At, Step, locate_nearest};
use mechanics::{Derivation, FieldStep};
use spec::{Checked, SpecError};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::mpsc::{Sender, channel};
use std::sync::{Mutex, OnceLock};
use std::time::{Duration, Instant};

/// What `rodcube derive` should do.
#[derive(Debug, Clone)]
pub struct Options {
    /// Project root (holds `derivations/`, `templates/`, `generated/`).
    pub root: PathBuf,
    /// Specs to derive; empty means every `derivations/*.yaml`.
    pub specs: Vec<PathBuf>,
    /// Compare only: write nothing, report files that regenerating would change.
    pub check: bool,
    /// Overwrite generated files even if they were edited by hand since the tool wrote them.
    pub force: bool,
}

/// What happened, file by file.
#[derive(Debug, Clone, Default)]
pub struct Outcome {
    /// Files written (write mode) because their content changed.
    pub written: Vec<PathBuf>,
    /// Files that regenerating would change (check mode).
    pub stale: Vec<PathBuf>,
    /// Files already up to date.
    pub unchanged: Vec<PathBuf>,
    /// Time spent in the symbolic derivation of each model.
    pub timings: Vec<(String, Duration)>,
}

/// Errors of the derivation tool.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A spec is invalid (syntax, schema, symbols, or a derivation step it makes impossible).
    #[error("{0}")]
    Spec(#[from] SpecError),
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// A template failed to render.
    #[error("template {template}: {message}")]
    Template {
        /// Template file.
        template: String,
        /// The cause.
        message: String,
    },
    /// rustfmt failed on generated code.
    #[error("rustfmt failed on generated code for {model}: {message}")]
    Rustfmt {
        /// Model name.
        model: String,
        /// The cause.
        message: String,
    },
    /// Generated files were edited by hand since the tool wrote them; nothing was written.
    #[error(
        "refusing to overwrite generated files edited by hand: {}; move your edits into the spec \
         or a template, or pass --force to discard them",
        .0.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", ")
    )]
    HandEdited(Vec<PathBuf>),
    /// The Symbolica worker thread died.
    #[error("the symbolic derivation stopped unexpectedly: {0}")]
    Worker(String),
}

type Job = Box<dyn FnOnce() + Send>;

thread_local! {
    /// Whether this thread is the Symbolica worker.
    static ON_WORKER: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// An error, not a wait without end, for a job on the Symbolica worker that queues another job
/// and waits for it (the worker runs one job at a time, so the second would never start).
fn off_worker() -> Result<(), Error> {
    if ON_WORKER.with(std::cell::Cell::get) {
        return Err(Error::Worker(
            "a job on the Symbolica thread waited on another job there (a bug)".into(),
        ));
    }
    Ok(())
}

/// Runs `f` on the one thread of this process that may call Symbolica, and waits for it.
///
/// Restricted Symbolica aborts the process when a second thread touches it, so every symbolic
/// computation in rodcube goes through here; callers on any thread are safe.
pub fn on_cas_thread<R: Send + 'static>(
    f: impl FnOnce() -> R + Send + 'static,
) -> Result<R, Error> {
    off_worker()?;
    static WORKER: OnceLock<Mutex<Sender<Job>>> = OnceLock::new();
    let sender = WORKER.get_or_init(|| {
        let (tx, rx) = channel::<Job>();
        let spawned = std::thread::Builder::new()
            .name("symbolica".into())
            .spawn(move || {
                // Restricted Symbolica also aborts when a second *process* uses it at the
                // same time: hold a lock file while this worker lives, waiting for any other.
                let _lock = cas_process_lock();
                ON_WORKER.with(|w| w.set(true));
                for job in rx {
                    // A panicking job must not take the worker down with it.
                    let _ = std::panic::catch_unwind(std::panic::AssertUnwindSafe(job));
                }
            });
        if spawned.is_err() {
            // The sender's receiver is gone; every call below reports the failure.
        }
        Mutex::new(tx)
    });
    let (tx, rx) = channel();
    let job: Job = Box::new(move || {
        let _ = tx.send(f());
    });
    sender
        .lock()
        .map_err(|_| Error::Worker("worker lock poisoned".into()))?
        .send(job)
        .map_err(|_| Error::Worker("the worker thread could not start".into()))?;
    rx.recv().map_err(|_| {
        Error::Worker("the derivation panicked (a bug: please report the spec)".into())
    })
}

/// The lock file that serialises Symbolica between processes.
pub fn lock_path() -> PathBuf {
    std::env::temp_dir().join("rodcube-symbolica.lock")
}

/// Takes the inter-process Symbolica lock, waiting (with a note on stderr) while another
/// process holds it. Returns `None` only if the lock file cannot be opened at all.
fn cas_process_lock() -> Option<std::fs::File> {
    let path = lock_path();
    let file = std::fs::OpenOptions::new()
        .create(true)
        .truncate(false)
        .write(true)
        .open(&path)
        .ok()?;
    if file.try_lock().is_err() {
        eprintln!(
            "rodcube: another process is using Symbolica (lock {}); waiting for it to finish",
            path.display()
        );
        file.lock().ok()?;
    }
    Some(file)
}

/// The spec files of a project, sorted by name.
pub fn spec_files(root: &Path) -> Result<Vec<PathBuf>, Error> {
    let dir = root.join("derivations");
    let entries = std::fs::read_dir(&dir).map_err(|source| Error::Io {
        path: dir.clone(),
        source,
    })?;
    let mut out: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "yaml" || x == "yml"))
        .collect();
    out.sort();
    Ok(out)
}

/// A derivation's error placed in its spec file (read again for the position); an error
/// reading the file is that error.
fn to_spec_error(checked: &Checked, err: mechanics::DeriveError) -> Error {
    let text = match std::fs::read_to_string(&checked.file) {
        Ok(text) => text,
        Err(source) => {
            return Error::Io {
                path: checked.file.clone(),
                source,
            };
        }
    };
    let steps: Vec<Step<'_>> = err
        .field
        .iter()
        .map(|s| match s {
            FieldStep::Key(k) => Step::Key(k.as_str()),
            FieldStep::Index(i) => Step::Index(*i),
        })
        .collect();
    let (mark, source_line) = locate_nearest(&text, &steps, At::Key);
    let field = err
        .field
        .iter()
        .map(|s| match s {
            FieldStep::Key(k) => format!(".{k}"),
            FieldStep::Index(i) => format!("[{i}]"),
        })
        .collect::<String>()
        .trim_start_matches('.')
        .to_string();
    Error::Spec(SpecError {
        file: checked.file.clone(),
        line: mark.line,
        column: mark.column,
        field,
        message: err.message,
        source_line,
        width: mark.width,
    })
}

/// One spec through every stage: the derivation proper ([`mechanics::derive`]: read → setup →
/// Lagrangian → equations → constraints → reduction → forces, for each phase), then its
/// presentation ([`dimensionless::derive`], [`steps::derive`], and `sin^2 + cos^2 = 1` applied
/// to what the generated code and records print, [`present::with_identities`]).
fn derive_and_present(c: &Checked) -> Result<Vec<Derivation>, mechanics::DeriveError> {
    let mut phases = mechanics::derive(c)?;
    for d in &mut phases {
        d.dimensionless = dimensionless::derive(&c.spec, d)?;
        d.steps = Some(steps::derive(d));
        present::with_identities(d)?;
    }
    Ok(phases)
}

/// Derives checked specs on the Symbolica thread: each spec's phases, with the time it took.
pub fn derive_all(checked: &[Checked]) -> Result<Vec<(Vec<Derivation>, Duration)>, Error> {
    let mut out = Vec::with_capacity(checked.len());
    derive_each(checked, |_, phases, took| {
        out.push((phases, took));
        Ok(())
    })?;
    Ok(out)
}

/// Derives checked specs on the Symbolica thread and hands each spec's phases (with the time
/// it took) to `each`, on this thread and in order, as soon as that spec is derived: what
/// `each` does (lowering, templates, rustfmt) overlaps the next spec's derivation. The first
/// error, of a derivation or of `each`, stops both.
pub fn derive_each(
    checked: &[Checked],
    mut each: impl FnMut(usize, Vec<Derivation>, Duration) -> Result<(), Error>,
) -> Result<(), Error> {
    off_worker()?;
    let owned: Vec<Checked> = checked.to_vec();
    let (tx, rx) = channel();
    std::thread::scope(|scope| {
        // Waits on the Symbolica thread's whole job, which sends each spec's result as it goes.
        let waiter = scope.spawn(move || {
            on_cas_thread(move || {
                for c in &owned {
                    let start = Instant::now();
                    let result = derive_and_present(c)
                        .map(|d| (d, start.elapsed()))
                        .map_err(|e| to_spec_error(c, e));
                    let failed = result.is_err();
                    // The receiver gone (`each` failed) or this spec failed: nothing more to do.
                    if tx.send(result).is_err() || failed {
                        break;
                    }
                }
            })
        });
        let mut outcome = Ok(());
        for (i, result) in rx.iter().enumerate() {
            if let Err(e) = result.and_then(|(phases, took)| each(i, phases, took)) {
                outcome = Err(e);
                break;
            }
        }
        drop(rx);
        let finished = waiter
            .join()
            .map_err(|_| Error::Worker("the derivation's waiting thread panicked".into()))
            .and_then(|r| r);
        outcome.and(finished)
    })
}

/// How long each spec took to derive, by model name.
pub type Timings = Vec<(String, Duration)>;

/// A rendered output file.
#[derive(Debug, Clone)]
pub struct Rendered {
    /// Path relative to the project root.
    pub path: PathBuf,
    /// Full content.
    pub text: String,
}

fn render(root: &Path, template: &str, context: &impl serde::Serialize) -> Result<String, Error> {
    let path = root.join("templates").join(template);
    let source = std::fs::read_to_string(&path).map_err(|source| Error::Io {
        path: path.clone(),
        source,
    })?;
    render_source(template, &source, context)
}

/// The model template as this program was built with it: what [`tapes`] renders, so that a
/// spec derives in any directory.
const MODEL_TEMPLATE: &str = include_str!("../../templates/model.rs.tera");

fn render_source(
    template: &str,
    source: &str,
    context: &impl serde::Serialize,
) -> Result<String, Error> {
    let mut tera = tera::Tera::default();
    tera.autoescape_on(Vec::<&str>::new());
    let terr = |e: tera::Error| Error::Template {
        template: template.into(),
        message: format!("{e:?}"),
    };
    tera.add_raw_template(template, source).map_err(terr)?;
    let ctx = tera::Context::from_serialize(context).map_err(terr)?;
    tera.render(template, &ctx).map_err(terr)
}

fn rustfmt(model: &str, text: &str) -> Result<String, Error> {
    use std::io::Write;
    use std::process::{Command, Stdio};
    let err = |message: String| Error::Rustfmt {
        model: model.into(),
        message,
    };
    let mut child = Command::new("rustfmt")
        .args(["--edition", "2024", "--emit", "stdout", "--quiet"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| err(format!("cannot start rustfmt: {e}")))?;
    if let Some(mut stdin) = child.stdin.take() {
        stdin
            .write_all(text.as_bytes())
            .map_err(|e| err(e.to_string()))?;
    }
    let out = child.wait_with_output().map_err(|e| err(e.to_string()))?;
    if !out.status.success() {
        return Err(err(String::from_utf8_lossy(&out.stderr).into_owned()));
    }
    String::from_utf8(out.stdout).map_err(|e| err(e.to_string()))
}

/// Formats the Rust files among `files` (their text as rendered) in one run of rustfmt: one
/// process start for every model rather than one each (rustfmt's start costs more than its
/// formatting of a model). Each text is written to a directory of its own (no configuration
/// file there) and read back from rustfmt's `--emit stdout`: rustfmt writes no file, so the
/// directory goes as quickly as it came (files rustfmt rewrote in place took a tenth of a
/// second to remove, longer than their formatting after rustfmt's start).
fn rustfmt_rust_files(files: &mut [Rendered]) -> Result<(), Error> {
    use std::sync::atomic::{AtomicUsize, Ordering};
    static RUN: AtomicUsize = AtomicUsize::new(0);
    let rust: Vec<usize> = (0..files.len())
        .filter(|&i| files[i].path.extension().is_some_and(|x| x == "rs"))
        .collect();
    if rust.is_empty() {
        return Ok(());
    }
    let models = (rust.iter())
        .filter_map(|&i| files[i].path.file_stem())
        .map(|s| s.to_string_lossy().into_owned())
        .collect::<Vec<_>>()
        .join(", ");
    let err = |message: String| Error::Rustfmt {
        model: models.clone(),
        message,
    };
    let dir = std::env::temp_dir().join(format!(
        "rodcube-rustfmt-{}-{}",
        std::process::id(),
        RUN.fetch_add(1, Ordering::Relaxed)
    ));
    let io = |path: &Path, source: std::io::Error| Error::Io {
        path: path.to_path_buf(),
        source,
    };
    std::fs::create_dir_all(&dir).map_err(|e| io(&dir, e))?;
    let result = (|| {
        // The directory as rustfmt names it (absolute, links resolved).
        let dir = std::fs::canonicalize(&dir).map_err(|e| io(&dir, e))?;
        let mut paths = Vec::with_capacity(rust.len());
        for (k, &i) in rust.iter().enumerate() {
            let path = dir.join(format!("{k}.rs"));
            std::fs::write(&path, &files[i].text).map_err(|e| io(&path, e))?;
            paths.push(path);
        }
        let formatted = rustfmt_to_stdout(&paths).map_err(err)?;
        for (text, &i) in formatted.into_iter().zip(&rust) {
            files[i].text = text;
        }
        Ok(())
    })();
    // The directory is this run's own; failing to remove it loses nothing but space.
    let _ = std::fs::remove_dir_all(&dir);
    result
}

/// The files at `paths` (absolute) as rustfmt formats them, in order: one run of
/// `rustfmt --emit stdout`, whose output is each file's text after the line `<path>:` and an
/// empty line. Output that does not hold every file, in order, is an error.
fn rustfmt_to_stdout(paths: &[PathBuf]) -> Result<Vec<String>, String> {
    use std::process::{Command, Stdio};
    let Some((first, others)) = paths.split_first() else {
        return Ok(Vec::new());
    };
    let out = Command::new("rustfmt")
        .args(["--edition", "2024", "--emit", "stdout"])
        .args(paths)
        .stdin(Stdio::null())
        .output()
        .map_err(|e| format!("cannot start rustfmt: {e}"))?;
    if !out.status.success() {
        return Err(String::from_utf8_lossy(&out.stderr).into_owned());
    }
    let text = String::from_utf8(out.stdout).map_err(|e| e.to_string())?;
    let header = |p: &PathBuf| format!("{}:\n\n", p.display());
    let mut rest = (text.strip_prefix(&header(first)))
        .ok_or_else(|| format!("rustfmt's output does not start with `{}`", first.display()))?;
    let mut formatted = Vec::with_capacity(paths.len());
    for next in others {
        let at = rest
            .find(&format!("\n{}", header(next)))
            .ok_or_else(|| format!("rustfmt's output has no `{}`", next.display()))?;
        formatted.push(rest[..=at].to_string());
        rest = &rest[at + 1 + header(next).len()..];
    }
    formatted.push(rest.to_string());
    Ok(formatted)
}

/// The fast phases of a system (its derived phases that have a fast path), as every model of
/// the system lists them.
fn fast_phases(phases: &[Derivation]) -> Vec<emit::PhaseEntry> {
    (phases.iter())
        .filter_map(|d| {
            let r = d.reduction.as_ref().ok()?;
            Some(emit::PhaseEntry {
                closed: d.plan.closed.clone(),
                model: d.name.clone(),
                release: !d.plan.start_params,
                separation_degree: r.separation().map_or(0, |s| s.coefficients.len() - 1),
            })
        })
        .collect()
}

/// An emitter's refusal of a model, reported against its spec file.
fn refused(c: &Checked, model: &str, error: mechanics::StepError) -> Error {
    Error::Spec(SpecError {
        file: c.file.clone(),
        line: 0,
        column: 0,
        field: String::new(),
        message: format!("model `{model}`: {error}"),
        source_line: String::new(),
        width: 0,
    })
}

/// The Rust of one derived phase as the template renders it (before rustfmt), and its tape,
/// compiled from that Rust (formatting changes no operation).
fn rust_and_tape(
    template: &str,
    c: &Checked,
    d: &Derivation,
    phases: &[emit::PhaseEntry],
) -> Result<(String, crate::tape::format::TapeFile), Error> {
    let ctx = emit::rust_context(c, d, phases).map_err(|e| refused(c, &d.name, e))?;
    let raw = render_source("model.rs.tera", template, &ctx)?;
    let origin = emit::tape::Origin {
        model: &d.name,
        spec: &emit::spec_path(c),
        spec_text: &c.text,
    };
    let tape = emit::tape::compile(&raw, &origin)
        .map_err(|m| refused(c, &d.name, mechanics::StepError::Tape(m)))?;
    Ok((raw, tape))
}

/// The Rust (not yet formatted), LaTeX, JSON and tape files of one derived phase.
fn render_phase(
    root: &Path,
    c: &Checked,
    d: &Derivation,
    phases: &[emit::PhaseEntry],
) -> Result<Vec<Rendered>, Error> {
    let path = root.join("templates").join("model.rs.tera");
    let template = std::fs::read_to_string(&path).map_err(|source| Error::Io { path, source })?;
    // Formatted with the other models' Rust ([`rustfmt_rust_files`]).
    let (rust, tape) = rust_and_tape(&template, c, d, phases)?;
    let tex_ctx = emit::tex_context(c, d).map_err(|e| refused(c, &d.name, e))?;
    let tex = render(root, "model.tex.tera", &tex_ctx)?;
    let json = emit::json_record(c, d, &tex_ctx)
        .and_then(|record| serde_json::to_string_pretty(&record))
        .map_err(|e| Error::Template {
            template: "json record".into(),
            message: e.to_string(),
        })?
        + "\n";
    Ok(vec![
        Rendered {
            path: PathBuf::from(format!("generated/{}.rs", d.name)),
            text: rust,
        },
        Rendered {
            path: PathBuf::from(format!("generated/{}.tex", d.name)),
            text: tex,
        },
        Rendered {
            path: PathBuf::from(format!("generated/{}.json", d.name)),
            text: json,
        },
        Rendered {
            path: PathBuf::from(format!("generated/{}.tape.json", d.name)),
            text: crate::tape::format::render(&tape),
        },
    ])
}

/// The tapes of one spec's models (`<model>.tape.json`, text), derived in memory with the
/// template built into this program: no file is read but the spec (and the specs beside it,
/// whose symbols are declared first in the same order as `cargo derive` declares them, so the
/// programs are the ones it would write) and none is written. What `rodcube run --spec` runs.
pub fn tapes(spec_path: &Path) -> Result<Vec<Rendered>, Error> {
    let c = spec::load(spec_path)?;
    let mut siblings: Vec<Checked> = Vec::new();
    if let Some(dir) = spec_path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .or(Some(Path::new(".")))
    {
        let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
            .map(|e| e.filter_map(|e| e.ok().map(|e| e.path())).collect())
            .unwrap_or_default();
        files.retain(|p| p.extension().is_some_and(|x| x == "yaml" || x == "yml"));
        files.sort();
        // A sibling that is not a valid spec (a scene, say) declares nothing.
        siblings.extend(files.iter().filter_map(|p| spec::load(p).ok()));
    }
    let specs: Vec<&spec::Spec> = siblings.iter().chain([&c]).map(|c| &c.spec).collect();
    let symbols = mechanics::canonical_symbols(&specs);
    on_cas_thread(move || cas::declare(&symbols))?;
    let mut out = Vec::new();
    for (phases, _) in derive_all(std::slice::from_ref(&c))? {
        let fast = fast_phases(&phases);
        for d in &phases {
            let (_, tape) = rust_and_tape(MODEL_TEMPLATE, &c, d, &fast)?;
            out.push(Rendered {
                path: PathBuf::from(format!("{}.tape.json", d.name)),
                text: crate::tape::format::render(&tape),
            });
        }
    }
    Ok(out)
}

/// Derives and renders every output file for the selected specs plus the registry.
pub fn render_all(root: &Path, specs: &[PathBuf]) -> Result<(Vec<Rendered>, Timings), Error> {
    let all_files = spec_files(root)?;
    let all: Vec<Checked> = all_files
        .iter()
        .map(|p| spec::load(p))
        .collect::<Result<_, _>>()?;
    let selected: Vec<Checked> = if specs.is_empty() {
        all.clone()
    } else {
        specs
            .iter()
            .map(|p| spec::load(p))
            .collect::<Result<_, _>>()?
    };
    // Every symbol of every spec first, in one order: the output then does not depend on
    // which specs were selected (Symbolica orders terms by when a symbol was first defined).
    let every: Vec<&spec::Spec> = all.iter().chain(&selected).map(|c| &c.spec).collect();
    let symbols = mechanics::canonical_symbols(&every);
    on_cas_thread(move || cas::declare(&symbols))?;
    let mut out = Vec::new();
    let mut timings = Vec::new();
    derive_each(&selected, |i, phases, took| {
        let c =
            (selected.get(i)).ok_or_else(|| Error::Worker(format!("no spec {i} was asked for")))?;
        timings.push((c.spec.name.clone(), took));
        let fast = fast_phases(&phases);
        for d in &phases {
            out.extend(render_phase(root, c, d, &fast)?);
        }
        Ok(())
    })?;
    // The registry lists only models whose Rust file exists once this run has written: those
    // rendered now and, when only some specs were given, those generated before (recorded in
    // the manifest). A spec that has not derived is never named, so the crate still builds.
    let mut names: Vec<String> = out
        .iter()
        .filter_map(|f| model_of(&f.path.to_string_lossy()).map(str::to_string))
        .collect();
    if !specs.is_empty() {
        let recorded = kept_rows(root, read_manifest(root)?);
        names.extend(
            recorded
                .keys()
                .filter_map(|p| model_of(p))
                .map(str::to_string),
        );
    }
    names.sort();
    names.dedup();
    let models: Vec<serde_json::Value> = names
        .iter()
        .map(|n| serde_json::json!({"name": n, "type_name": emit::type_name(n)}))
        .collect();
    let reg = render(
        root,
        "registry.rs.tera",
        &serde_json::json!({"command": emit::COMMAND, "models": models}),
    )?;
    // The registry names its models' files (`pub mod x;`), which rustfmt given files would
    // format again: it is formatted apart, while the models are.
    let reg = std::thread::scope(|scope| {
        let registry = scope.spawn(|| rustfmt("registry", &reg));
        let models = rustfmt_rust_files(&mut out);
        let registry = (registry.join())
            .map_err(|_| Error::Worker("the registry's rustfmt thread panicked".into()))?;
        models.and(registry)
    })?;
    out.push(Rendered {
        path: PathBuf::from("generated/mod.rs"),
        text: reg,
    });
    Ok((out, timings))
}

/// The manifest of digests of the generated files, as the tool last wrote them.
pub const MANIFEST: &str = "generated/manifest.txt";

/// FNV-1a 64-bit digest of a text (stable across platforms and Rust versions): the one a tape
/// records of its spec and body, here of each generated file.
pub use crate::tape::format::digest;

/// The manifest of `files` as about to be written, keeping the rows of `kept` (other files
/// already generated) except where `files` gives a new digest; sorted by path.
fn manifest_text(files: &[Rendered], kept: BTreeMap<String, String>) -> String {
    let mut out = format!(
        "# Generated by `{}`; do not edit by hand.\n# FNV-1a digests of the generated files as \
         the tool wrote them: a file whose digest differs was edited by hand.\n",
        emit::COMMAND
    );
    let mut rows = kept;
    for f in files {
        rows.insert(f.path.display().to_string(), digest(&f.text));
    }
    for (path, d) in rows {
        out.push_str(&format!("{d}  {path}\n"));
    }
    out
}

/// The rows of the manifest (path → digest); none if there is no manifest yet. Lines that are
/// not `<digest>  <path>` are skipped.
fn read_manifest(root: &Path) -> Result<BTreeMap<String, String>, Error> {
    let path = root.join(MANIFEST);
    let text = match std::fs::read_to_string(&path) {
        Ok(text) => text,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(BTreeMap::new()),
        Err(source) => return Err(Error::Io { path, source }),
    };
    Ok(text
        .lines()
        .filter(|l| !l.starts_with('#'))
        .filter_map(|l| {
            l.split_once("  ")
                .map(|(d, p)| (p.to_string(), d.to_string()))
        })
        .collect())
}

/// The manifest rows that still describe a generated file: a plain file name in `generated/`
/// (not the manifest itself) that exists.
fn kept_rows(root: &Path, rows: BTreeMap<String, String>) -> BTreeMap<String, String> {
    rows.into_iter()
        .filter(|(path, _)| {
            path.as_str() != MANIFEST
                && path
                    .strip_prefix("generated/")
                    .is_some_and(|name| crate::io::check_name(name).is_ok())
                && root.join(path).is_file()
        })
        .collect()
}

/// The model whose Rust file is `path` (`generated/<model>.rs`, not the registry `mod.rs`).
fn model_of(path: &str) -> Option<&str> {
    path.strip_prefix("generated/")
        .and_then(|p| p.strip_suffix(".rs"))
        .filter(|name| *name != "mod" && spec::is_identifier(name))
}

/// The current content of an output, or `None` when there is none to compare (no file, or a
/// directory in the way, which the write then reports).
fn current_content(path: &Path) -> Result<Option<Vec<u8>>, Error> {
    match std::fs::read(path) {
        Ok(bytes) => Ok(Some(bytes)),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound || path.is_dir() => Ok(None),
        Err(source) => Err(Error::Io {
            path: path.to_path_buf(),
            source,
        }),
    }
}

/// A failed write of the output files as this module's error.
fn write_error(e: crate::io::Error, dir: &Path) -> Error {
    match e {
        crate::io::Error::Write { path, source } | crate::io::Error::CreateDir { path, source } => {
            Error::Io { path, source }
        }
        other => Error::Io {
            path: dir.to_path_buf(),
            source: std::io::Error::other(other.to_string()),
        },
    }
}

/// Regenerates (or, with `check`, compares) the outputs. Without `force`, a generated file
/// that was edited by hand (its digest differs from the manifest's) is never overwritten.
///
/// The write is all or nothing: every derivation and rendering happens first, then the
/// changed files and the manifest are written together by [`crate::io::write_all_atomic`], so
/// on any error `generated/` is left exactly as it was. The manifest is rewritten on every
/// write; when only some specs are given, the rows of the other generated files are kept.
pub fn run(opts: &Options) -> Result<Outcome, Error> {
    let (mut files, timings) = render_all(&opts.root, &opts.specs)?;
    let recorded = read_manifest(&opts.root)?;
    let kept = if opts.specs.is_empty() {
        BTreeMap::new()
    } else {
        kept_rows(&opts.root, recorded.clone())
    };
    let manifest = manifest_text(&files, kept);
    files.push(Rendered {
        path: PathBuf::from(MANIFEST),
        text: manifest,
    });
    let mut outcome = Outcome {
        timings,
        ..Outcome::default()
    };
    let mut to_write = Vec::new();
    let mut edited = Vec::new();
    for f in files {
        let current = current_content(&opts.root.join(&f.path))?;
        if current.as_deref() == Some(f.text.as_bytes()) {
            outcome.unchanged.push(f.path);
            continue;
        }
        if opts.check {
            outcome.stale.push(f.path);
            continue;
        }
        let key = f.path.display().to_string();
        // A file the tool wrote has the recorded digest (and is UTF-8).
        let hand_edited = |cur: &[u8]| {
            recorded
                .get(&key)
                .is_some_and(|d| std::str::from_utf8(cur).map_or(true, |text| *d != digest(text)))
        };
        if let Some(cur) = &current
            && key != MANIFEST
            && hand_edited(cur)
            && !opts.force
        {
            edited.push(f.path.clone());
        }
        to_write.push(f);
    }
    if !edited.is_empty() {
        return Err(Error::HandEdited(edited));
    }
    let targets: Vec<(PathBuf, &[u8])> = to_write
        .iter()
        .map(|f| (opts.root.join(&f.path), f.text.as_bytes()))
        .collect();
    crate::io::write_all_atomic(&targets)
        .map_err(|e| write_error(e, &opts.root.join("generated")))?;
    outcome.written = to_write.into_iter().map(|f| f.path).collect();
    Ok(outcome)
}
