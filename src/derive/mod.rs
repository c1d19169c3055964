//! The derivation tool (cargo feature `derive`): model specs in `derivations/*.yaml` are
//! derived by Symbolica and rendered through `templates/` into `generated/`.
//!
//! Data flows one way: [`spec`] (YAML, checked) → [`mechanics`] (Symbolica, on one dedicated
//! thread) → [`emit`] (flat template contexts, [`lower`]ed to straight-line Rust) → tera →
//! rustfmt → `generated/`. In check mode nothing is written; stale files are reported.

pub mod cas;
pub mod emit;
pub mod lower;
pub mod mechanics;

// Spec parsing and expressions need no Symbolica: they live in the runtime crate.
pub use crate::spec::{self, expr};

use crate::yaml_marks::{At, Step, locate_nearest};
use mechanics::{Derivation, FieldStep};
use spec::{Checked, SpecError};
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

/// Runs `f` on the one thread of this process that may call Symbolica, and waits for it.
///
/// Restricted Symbolica aborts the process when a second thread touches it, so every symbolic
/// computation in rodcube goes through here; callers on any thread are safe.
pub fn on_cas_thread<R: Send + 'static>(
    f: impl FnOnce() -> R + Send + 'static,
) -> Result<R, Error> {
    static WORKER: OnceLock<Mutex<Sender<Job>>> = OnceLock::new();
    let sender = WORKER.get_or_init(|| {
        let (tx, rx) = channel::<Job>();
        let spawned = std::thread::Builder::new()
            .name("symbolica".into())
            .spawn(move || {
                // Restricted Symbolica also aborts when a second *process* uses it at the
                // same time: hold a lock file while this worker lives, waiting for any other.
                let _lock = cas_process_lock();
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

fn to_spec_error(checked: &Checked, err: mechanics::DeriveError) -> SpecError {
    let text = std::fs::read_to_string(&checked.file).unwrap_or_default();
    let steps: Vec<Step<'_>> = err
        .field
        .iter()
        .map(|s| match s {
            FieldStep::Key(k) => Step::Key(k.as_str()),
            FieldStep::Index(i) => Step::Index(*i),
        })
        .collect();
    let (line, column) = locate_nearest(&text, &steps, At::Key);
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
    SpecError {
        file: checked.file.clone(),
        line,
        column,
        field,
        message: err.message,
    }
}

/// Derives checked specs on the Symbolica thread.
pub fn derive_all(checked: &[Checked]) -> Result<Vec<(Derivation, Duration)>, Error> {
    let owned: Vec<Checked> = checked.to_vec();
    let results = on_cas_thread(move || {
        owned
            .iter()
            .map(|c| {
                let start = Instant::now();
                mechanics::derive(c)
                    .map(|d| (d, start.elapsed()))
                    .map_err(|e| to_spec_error(c, e))
            })
            .collect::<Vec<_>>()
    })?;
    results
        .into_iter()
        .map(|r| r.map_err(Error::from))
        .collect()
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
    let mut tera = tera::Tera::default();
    tera.autoescape_on(Vec::<&str>::new());
    let terr = |e: tera::Error| Error::Template {
        template: template.into(),
        message: format!("{e:?}"),
    };
    tera.add_raw_template(template, &source).map_err(terr)?;
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
    // Phase links need every spec's parameter order.
    let lookup = |name: &str| -> Option<Vec<String>> {
        all.iter()
            .chain(selected.iter())
            .find(|c| c.spec.name == name)
            .map(|c| c.spec.parameters.iter().map(|p| p.name.clone()).collect())
    };
    for c in &selected {
        if let Some(after) = &c.spec.after_separation
            && lookup(&after.model).is_none()
        {
            let text = std::fs::read_to_string(&c.file).unwrap_or_default();
            let path = [Step::Key("after_separation"), Step::Key("model")];
            let (line, column) = locate_nearest(&text, &path, At::Value);
            return Err(SpecError {
                file: c.file.clone(),
                line,
                column,
                field: "after_separation.model".into(),
                message: format!(
                    "no spec in derivations/ defines a model named `{}`",
                    after.model
                ),
            }
            .into());
        }
    }
    let derived = derive_all(&selected)?;
    let mut out = Vec::new();
    let mut timings = Vec::new();
    for (c, (d, took)) in selected.iter().zip(derived) {
        timings.push((c.spec.name.clone(), took));
        let next = c
            .spec
            .after_separation
            .as_ref()
            .and_then(|a| lookup(&a.model));
        let ctx = emit::rust_context(c, &d, next.as_deref()).map_err(|message| {
            let text = std::fs::read_to_string(&c.file).unwrap_or_default();
            let path = [Step::Key("after_separation")];
            let (line, column) = locate_nearest(&text, &path, At::Key);
            Error::Spec(SpecError {
                file: c.file.clone(),
                line,
                column,
                field: "after_separation".into(),
                message,
            })
        })?;
        let rust = rustfmt(&c.spec.name, &render(root, "model.rs.tera", &ctx)?)?;
        out.push(Rendered {
            path: PathBuf::from(format!("generated/{}.rs", c.spec.name)),
            text: rust,
        });
        let tex = render(root, "model.tex.tera", &emit::tex_context(c, &d))?;
        out.push(Rendered {
            path: PathBuf::from(format!("generated/{}.tex", c.spec.name)),
            text: tex,
        });
        let json =
            serde_json::to_string_pretty(&emit::json_record(c, &d)).unwrap_or_default() + "\n";
        out.push(Rendered {
            path: PathBuf::from(format!("generated/{}.json", c.spec.name)),
            text: json,
        });
    }
    // The registry lists every spec in derivations/ (and any named outside it).
    let mut names: Vec<(String, String)> = all
        .iter()
        .chain(selected.iter())
        .map(|c| (c.spec.name.clone(), emit::type_name(&c.spec.name)))
        .collect();
    names.sort();
    names.dedup();
    let models: Vec<serde_json::Value> = names
        .iter()
        .map(|(n, t)| serde_json::json!({"name": n, "type_name": t}))
        .collect();
    let reg = render(
        root,
        "registry.rs.tera",
        &serde_json::json!({"command": emit::COMMAND, "models": models}),
    )?;
    out.push(Rendered {
        path: PathBuf::from("generated/mod.rs"),
        text: rustfmt("registry", &reg)?,
    });
    Ok((out, timings))
}

/// The manifest of digests of the generated files, as the tool last wrote them.
pub const MANIFEST: &str = "generated/manifest.txt";

/// FNV-1a 64-bit digest of a text (stable across platforms and Rust versions).
pub fn digest(text: &str) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in text.bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    format!("{h:016x}")
}

fn manifest_text(files: &[Rendered]) -> String {
    let mut out = format!(
        "# Generated by `{}`; do not edit by hand.\n# FNV-1a digests of the generated files as \
         the tool wrote them: a file whose digest differs was edited by hand.\n",
        emit::COMMAND
    );
    let mut rows: Vec<(String, String)> = files
        .iter()
        .map(|f| (f.path.display().to_string(), digest(&f.text)))
        .collect();
    rows.sort();
    for (path, d) in rows {
        out.push_str(&format!("{d}  {path}\n"));
    }
    out
}

fn read_manifest(root: &Path) -> std::collections::BTreeMap<String, String> {
    std::fs::read_to_string(root.join(MANIFEST))
        .unwrap_or_default()
        .lines()
        .filter(|l| !l.starts_with('#'))
        .filter_map(|l| {
            l.split_once("  ")
                .map(|(d, p)| (p.to_string(), d.to_string()))
        })
        .collect()
}

/// Regenerates (or, with `check`, compares) the outputs. Without `force`, a generated file
/// that was edited by hand (its digest differs from the manifest's) is never overwritten.
pub fn run(opts: &Options) -> Result<Outcome, Error> {
    let (mut files, timings) = render_all(&opts.root, &opts.specs)?;
    if opts.specs.is_empty() {
        let manifest = manifest_text(&files);
        files.push(Rendered {
            path: PathBuf::from(MANIFEST),
            text: manifest,
        });
    }
    let recorded = read_manifest(&opts.root);
    let mut outcome = Outcome {
        timings,
        ..Outcome::default()
    };
    let mut to_write = Vec::new();
    let mut edited = Vec::new();
    for f in files {
        let path = opts.root.join(&f.path);
        let current = std::fs::read_to_string(&path).ok();
        if current.as_deref() == Some(f.text.as_str()) {
            outcome.unchanged.push(f.path);
            continue;
        }
        if opts.check {
            outcome.stale.push(f.path);
            continue;
        }
        let key = f.path.display().to_string();
        if let Some(cur) = &current
            && key != MANIFEST
            && recorded.get(&key).is_some_and(|d| *d != digest(cur))
            && !opts.force
        {
            edited.push(f.path.clone());
        }
        to_write.push(f);
    }
    if !edited.is_empty() {
        return Err(Error::HandEdited(edited));
    }
    for f in to_write {
        let path = opts.root.join(&f.path);
        crate::io::write_atomic(&path, f.text.as_bytes()).map_err(|e| Error::Io {
            path: path.clone(),
            source: std::io::Error::other(e.to_string()),
        })?;
        outcome.written.push(f.path);
    }
    Ok(outcome)
}
