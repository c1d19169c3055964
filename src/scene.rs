//! Scenes: the YAML files that name a model, its parameters and the quantities wanted, validated
//! against the model with errors that name the file, line, column and field.
//!
//! ```yaml
//! model: rod_cube
//! parameters: {m1: 1.0, m2: 3.0, ell: 1.0, a: 0.25, g: 9.81}   # SI units
//! want: [separation_angle, separation_time, theta_series]
//! tolerance: 1.0e-12        # relative, optional
//! samples: 1000             # points in each series, optional
//! until: 0.6                # s: go on through impacts to this time, optional
//! ```
//!
//! Loading runs in three passes over the text, each with exact positions ([`crate::yaml`]):
//! 1. every node is read: YAML syntax errors, duplicate keys and tags, at the parser's marks;
//! 2. typed deserialization with `deny_unknown_fields` (unknown keys, wrong types, missing keys),
//!    each a typed error at the parser's mark with the field serde was in;
//! 3. semantic checks against the model's [`ModelInfo`], placed by looking the field's path up
//!    in the document's tree of spanned nodes, at its key or its value, whatever the layout
//!    (block or flow, quoted keys, anchors).
//!
//! Semantic checks do not stop at the first problem: every diagnostic is collected and they
//! are reported in file order. A [`Diagnostic`] shows as a one-line `file:line:column: field:
//! message` ([`Diagnostic::headline`]) or, rendered by annotate-snippets, rustc-style with the
//! line and the token underlined.

use crate::model::{Model, ModelInfo, RequirementInfo};
use crate::plan::PlanError;
use crate::quantity::Quantity;
use crate::results::RunResults;
use crate::spec::expr::Expr;
use crate::system::{SystemError, check_value, failed_requirements};
use crate::yaml::{At, Document, Mark, Problem, ReadError, excerpt, parse_path};
use annotate_snippets::{Level, Origin, Renderer};
use serde::Deserialize;
use std::collections::{BTreeMap, HashSet};
use std::fmt;
use std::path::{Path, PathBuf};

/// The planner's defaults and tolerance range are the scene's: one source of truth.
pub use crate::plan::{DEFAULT_SAMPLES, DEFAULT_TOLERANCE, TOLERANCE_RANGE};
/// Accepted number of points per series (inclusive).
pub const SAMPLES_RANGE: (usize, usize) = (2, 1_000_000);
/// The keys a scene may have, in the order they are documented.
pub const KEYS: &[&str] = &[
    "model",
    "parameters",
    "want",
    "tolerance",
    "samples",
    "until",
];

/// A validated scene, ready for the planner.
pub struct Scene {
    /// The file it was read from (as given, for messages).
    pub file: PathBuf,
    /// The model to run.
    pub model: &'static dyn Model,
    /// Parameter values in the order of [`ModelInfo::parameters`] (SI units).
    pub parameters: Vec<f64>,
    /// The quantities wanted, in the order of the file, each once.
    pub want: Vec<Quantity>,
    /// Relative tolerance.
    pub tolerance: f64,
    /// Points in each series.
    pub samples: usize,
    /// The time the motion goes on to through impacts (s from release); `None` ends it at its
    /// first landing.
    pub until: Option<f64>,
    /// The scene's text, kept to locate errors found later (e.g. by the planner).
    source: String,
}

impl fmt::Debug for Scene {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Scene")
            .field("file", &self.file)
            .field("model", &self.info().name)
            .field("parameters", &self.parameter_map())
            .field("want", &self.want)
            .field("tolerance", &self.tolerance)
            .field("samples", &self.samples)
            .field("until", &self.until)
            .finish()
    }
}

/// What kind of problem a [`Diagnostic`] reports; each has a stable code for messages.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Kind {
    /// The file could not be read (missing, unreadable, not UTF-8).
    Read,
    /// Not valid YAML, a duplicate key, or an empty file.
    Syntax,
    /// A key that scenes do not have.
    UnknownKey,
    /// A value of the wrong type, or a required key missing.
    Structure,
    /// A model that is not in the registry.
    UnknownModel,
    /// A `want` entry that no model quantity matches.
    UnknownQuantity,
    /// A quantity this model cannot provide (e.g. separation without a contact).
    UnavailableQuantity,
    /// A `want` entry listed twice.
    DuplicateQuantity,
    /// A parameter of the model that the scene does not give.
    MissingParameter,
    /// A parameter the model does not have.
    UnknownParameter,
    /// A parameter that must be strictly positive and is not.
    NotPositive,
    /// A friction coefficient below zero.
    NegativeFriction,
    /// NaN or an infinity (`.nan`, `.inf`).
    NotFinite,
    /// `tolerance` or `samples` outside its range, or an empty `want`.
    OutOfRange,
    /// A requirement of the model on its parameters (e.g. `a < ell`) fails.
    Requirement,
}

impl Kind {
    /// Stable short code, shown as `error[code]`.
    pub fn code(self) -> &'static str {
        match self {
            Kind::Read => "read",
            Kind::Syntax => "syntax",
            Kind::UnknownKey => "unknown-key",
            Kind::Structure => "structure",
            Kind::UnknownModel => "unknown-model",
            Kind::UnknownQuantity => "unknown-quantity",
            Kind::UnavailableQuantity => "unavailable-quantity",
            Kind::DuplicateQuantity => "duplicate-quantity",
            Kind::MissingParameter => "missing-parameter",
            Kind::UnknownParameter => "unknown-parameter",
            Kind::NotPositive => "not-positive",
            Kind::NegativeFriction => "negative-friction",
            Kind::NotFinite => "not-finite",
            Kind::OutOfRange => "out-of-range",
            Kind::Requirement => "requirement",
        }
    }
}

/// One problem in a scene, with its place.
#[derive(Debug, Clone, PartialEq)]
pub struct Diagnostic {
    /// The scene file, as given.
    pub file: PathBuf,
    /// 1-based line; 0 when the problem has no place in the text (e.g. unreadable file).
    pub line: usize,
    /// 1-based column in characters; 0 when `line` is 0.
    pub column: usize,
    /// The field, as a path: `parameters.m1`, `want[2]`, `tolerance`; empty when none applies.
    pub field: String,
    /// What kind of problem.
    pub kind: Kind,
    /// The message, without the place.
    pub message: String,
    /// The text of line `line` (for the snippet), empty when `line` is 0.
    pub source_line: String,
    /// Characters of `source_line` from `column` that the problem covers (the token there);
    /// 0 when `line` is 0.
    pub width: usize,
}

impl Diagnostic {
    /// `file:line:column` (or just `file` without a place).
    pub fn place(&self) -> String {
        if self.line == 0 {
            self.file.display().to_string()
        } else {
            format!("{}:{}:{}", self.file.display(), self.line, self.column)
        }
    }

    /// One line: `file:line:column: field: message`.
    pub fn headline(&self) -> String {
        if self.field.is_empty() {
            format!("{}: {}", self.place(), self.message)
        } else {
            format!("{}: {}: {}", self.place(), self.field, self.message)
        }
    }
}

impl fmt::Display for Diagnostic {
    /// rustc-style, by annotate-snippets: `error[code]: field: message`,
    /// `--> file:line:column`, the line and the token underlined.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let title = if self.field.is_empty() {
            self.message.clone()
        } else {
            format!("{}: {}", self.field, self.message)
        };
        let file = self.file.display().to_string();
        let title = Level::ERROR.primary_title(title).id(self.kind.code());
        let group = if self.line == 0 {
            title.element(Origin::path(file))
        } else {
            title.element(excerpt(&self.source_line, self.line, self.column, self.width).path(file))
        };
        // No terminal is narrower than a scene line is worth showing whole.
        let renderer = Renderer::plain().term_width(usize::from(u16::MAX));
        f.write_str(&renderer.render(&[group]))
    }
}

/// Everything wrong with a scene (at least one diagnostic), in file order.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneError {
    /// The problems found, sorted by line and column.
    pub diagnostics: Vec<Diagnostic>,
}

impl SceneError {
    fn one(d: Diagnostic) -> Self {
        SceneError {
            diagnostics: vec![d],
        }
    }

    /// Whether any diagnostic is of this kind.
    pub fn has(&self, kind: Kind) -> bool {
        self.diagnostics.iter().any(|d| d.kind == kind)
    }
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, d) in self.diagnostics.iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
                writeln!(f)?;
            }
            write!(f, "{d}")?;
        }
        if self.diagnostics.len() > 1 {
            write!(f, "\n\n{} errors in this scene", self.diagnostics.len())?;
        }
        Ok(())
    }
}

impl std::error::Error for SceneError {}

/// Where a scene comes from: a file, or YAML text named in messages as if it were `file`.
#[derive(Debug, Clone, Copy)]
pub enum Source<'a> {
    /// A scene file, read by [`Scene::load`].
    File(&'a Path),
    /// Scene text, validated by [`Scene::parse`]; `file` names it in messages (`<scene>`,
    /// `<yaml>`, or the file it was built from).
    Text {
        /// The YAML text.
        text: &'a str,
        /// Its name in messages.
        file: &'a Path,
    },
}

/// Why a scene gave no results: the scene itself, every problem placed at its file, line,
/// column and field (planner refusals of its values included), or the solve.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RunError {
    /// The scene is invalid, or the planner refused one of its values (placed at its field by
    /// the same rules as the loader's).
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// The solve failed; `error` says why, `file` is the scene's.
    #[error("solving {} failed: {error}", file.display())]
    Solve {
        /// The scene's file, as given.
        file: PathBuf,
        /// The planner's error.
        error: PlanError,
    },
}

/// Reads the scene of `source` against the registry ([`crate::models::all`]) and runs it
/// ([`Scene::run`]): the one path from a scene to its results of the command line's
/// `rodcube run`, the C interface's `rodcube_run_scene` and the Python package's `run`.
pub fn run(source: Source<'_>) -> Result<(Scene, RunResults), RunError> {
    let scene = Scene::read(source)?;
    let results = scene.run()?;
    Ok((scene, results))
}

/// The scene's keys as written, before any check against a model.
#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a mapping of scene keys")]
struct Raw {
    model: String,
    parameters: BTreeMap<String, f64>,
    want: Vec<String>,
    #[serde(default)]
    tolerance: Option<f64>,
    #[serde(default)]
    samples: Option<i64>,
    #[serde(default)]
    until: Option<f64>,
}

impl Scene {
    /// Reads and validates a scene file against the generated models ([`crate::models::all`]).
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        Scene::load_with(path, crate::models::all())
    }

    /// Reads and validates a scene file against `registry`.
    pub fn load_with(path: &Path, registry: &[&'static dyn Model]) -> Result<Scene, SceneError> {
        let text = std::fs::read(path)
            .map_err(|e| e.to_string())
            .and_then(|bytes| String::from_utf8(bytes).map_err(|e| format!("not UTF-8 text ({e})")))
            .map_err(|why| {
                SceneError::one(Diagnostic {
                    file: path.to_path_buf(),
                    line: 0,
                    column: 0,
                    field: String::new(),
                    kind: Kind::Read,
                    message: format!("cannot read the scene: {why}"),
                    source_line: String::new(),
                    width: 0,
                })
            })?;
        Scene::parse(&text, path, registry)
    }

    /// Reads and validates the scene of `source` against the registry
    /// ([`crate::models::all`]).
    pub fn read(source: Source<'_>) -> Result<Scene, SceneError> {
        match source {
            Source::File(path) => Scene::load(path),
            Source::Text { text, file } => Scene::parse(text, file, crate::models::all()),
        }
    }

    /// Validates scene text; `file` is only used in messages.
    pub fn parse(
        text: &str,
        file: &Path,
        registry: &[&'static dyn Model],
    ) -> Result<Scene, SceneError> {
        if text.lines().all(|l| {
            let t = l.trim();
            t.is_empty() || t.starts_with('#') || t == "---"
        }) {
            let ctx = Ctx {
                doc: Document::index(text),
                file,
            };
            return Err(SceneError::one(ctx.at(
                Kind::Syntax,
                Mark::START,
                "",
                format!("the scene is empty; it needs the keys {}", KEYS.join(", ")),
            )));
        }
        // Pass 1: syntax, duplicate keys and tags.
        let doc = Document::parse(text).map_err(|e| {
            let ctx = Ctx {
                doc: Document::index(text),
                file,
            };
            SceneError::one(ctx.read_error(e))
        })?;
        let ctx = Ctx { doc, file };
        // Pass 2: keys and types.
        let raw: Raw = ctx
            .doc
            .deserialize()
            .map_err(|e| SceneError::one(ctx.read_error(e)))?;
        // Pass 3: against the model.
        ctx.validate(raw, registry)
    }

    /// The model's static description.
    pub fn info(&self) -> &'static ModelInfo {
        self.model.info()
    }

    /// The planner's request for this scene: its model, parameters, wanted quantities,
    /// tolerance, samples and end time.
    pub fn request(&self) -> crate::plan::Request<'static> {
        crate::plan::Request::new(self.model, self.parameters.clone())
            .with_want(&self.want)
            .with_tolerance(self.tolerance)
            .with_samples(self.samples)
            .with_until(self.until)
    }

    /// Solves the scene ([`crate::plan::run`] on its [`Scene::request`]). A planner error
    /// about the scene's own values is placed at its field in the file, as the loader places
    /// its own ([`RunError::Scene`]); any other is [`RunError::Solve`].
    pub fn run(&self) -> Result<RunResults, RunError> {
        crate::plan::run(&self.request()).map_err(|error| match self.plan_error(&error) {
            Some(placed) => RunError::Scene(placed),
            None => RunError::Solve {
                file: self.file.clone(),
                error,
            },
        })
    }

    /// Parameters by name.
    pub fn parameter_map(&self) -> BTreeMap<String, f64> {
        self.info()
            .parameters
            .iter()
            .zip(&self.parameters)
            .map(|(p, v)| (p.name.to_string(), *v))
            .collect()
    }

    /// A parameter's value by name.
    pub fn parameter(&self, name: &str) -> Option<f64> {
        let i = self.info().parameters.iter().position(|p| p.name == name)?;
        self.parameters.get(i).copied()
    }

    /// The file name without extension (`paper` for `scenes/paper.yaml`).
    pub fn stem(&self) -> Option<&str> {
        self.file.file_stem().and_then(|s| s.to_str())
    }

    /// An error placed at a field of this scene (`parameters.a`, `want[1]`, `model`), for
    /// problems found after loading, e.g. by the planner. A field that is not in the file is
    /// placed at its nearest ancestor that is.
    pub fn error_at(&self, field: &str, kind: Kind, message: impl Into<String>) -> SceneError {
        SceneError::one(self.ctx().diag(kind, field, At::Key, message.into()))
    }

    /// An error about some parameters (e.g. a failed requirement reported by the planner),
    /// placed at the first of `names` that the scene gives, in file order.
    pub fn error_at_parameters(
        &self,
        names: &[&str],
        kind: Kind,
        message: impl Into<String>,
    ) -> SceneError {
        let ctx = self.ctx();
        let field = ctx.first_in_file(names.iter().map(|n| format!("parameters.{n}")));
        SceneError::one(ctx.diag(kind, &field, At::Key, message.into()))
    }

    /// A failed requirement of this scene's model (named `name`), placed at the first in the
    /// file of the parameters its margin reads ([`RequirementInfo::parameters`]).
    pub fn requirement_error(&self, name: &str, message: impl Into<String>) -> SceneError {
        let info = self.info();
        let involved = (info.requirements.iter())
            .find(|r| r.name == name)
            .map(|r| requirement_parameters(r, info))
            .unwrap_or_default();
        self.error_at_parameters(&involved, Kind::Requirement, message)
    }

    /// A planner error about this scene's own values, placed at its field in the file
    /// (parameters, wanted quantities, tolerance, end time, samples); `None` for the errors
    /// of the solve itself. The scene was validated against the same rules, so these are rare.
    fn plan_error(&self, error: &PlanError) -> Option<SceneError> {
        let message = error.to_string();
        let at = |field: String, kind| Some(self.error_at(&field, kind, message.clone()));
        match error {
            PlanError::System(SystemError::Requirement { name, .. }) => {
                Some(self.requirement_error(name, message.clone()))
            }
            PlanError::System(SystemError::NotFinite { name, .. }) => {
                at(format!("parameters.{name}"), Kind::NotFinite)
            }
            PlanError::System(SystemError::NotPositive { name, .. }) => {
                at(format!("parameters.{name}"), Kind::NotPositive)
            }
            PlanError::System(SystemError::MissingParameter { name, .. }) => {
                at(format!("parameters.{name}"), Kind::MissingParameter)
            }
            PlanError::System(SystemError::UnknownParameter { name, .. }) => {
                at(format!("parameters.{name}"), Kind::UnknownParameter)
            }
            PlanError::Unavailable { .. } => at("want".into(), Kind::UnavailableQuantity),
            PlanError::BadTolerance { .. } => at("tolerance".into(), Kind::OutOfRange),
            PlanError::BadUntil { .. } => at("until".into(), Kind::OutOfRange),
            PlanError::TooFewSamples { .. } | PlanError::TooManySamples { .. } => {
                at("samples".into(), Kind::OutOfRange)
            }
            _ => None,
        }
    }

    /// The scene's text, read again to place an error found after loading (errors are rare).
    fn ctx(&self) -> Ctx<'_> {
        Ctx {
            doc: Document::index(&self.source),
            file: &self.file,
        }
    }
}

/// The document being validated and its file name.
struct Ctx<'a> {
    doc: Document<'a>,
    file: &'a Path,
}

impl Ctx<'_> {
    fn at(&self, kind: Kind, mark: Mark, field: &str, message: String) -> Diagnostic {
        Diagnostic {
            file: self.file.to_path_buf(),
            line: mark.line,
            column: mark.column,
            field: field.to_string(),
            kind,
            message,
            source_line: self.doc.line_text(mark.line).to_string(),
            width: mark.width,
        }
    }

    /// A diagnostic at `field` (a path such as `parameters.m1`), or at its nearest ancestor
    /// found in the text, or at the start of the document.
    fn diag(&self, kind: Kind, field: &str, at: At, message: String) -> Diagnostic {
        let mark = self.doc.locate_nearest(&parse_path(field), at);
        self.at(kind, mark, field, message)
    }

    /// The field among `fields` that comes first in the file (the first one if none is found).
    fn first_in_file(&self, fields: impl Iterator<Item = String>) -> String {
        let fields: Vec<String> = fields.collect();
        fields
            .iter()
            .filter_map(|f| {
                let mark = self.doc.locate(&parse_path(f), At::Key)?;
                Some(((mark.line, mark.column), f))
            })
            .min()
            .map(|(_, f)| f.clone())
            .or_else(|| fields.first().cloned())
            .unwrap_or_default()
    }

    /// A pass-1 or pass-2 error (YAML syntax, duplicate key, tag; unknown key, wrong type,
    /// missing key) as a diagnostic at the parser's mark, named by the field serde was in.
    fn read_error(&self, e: ReadError) -> Diagnostic {
        let field = e.field();
        let (kind, message) = match &e.problem {
            Problem::Syntax => (Kind::Syntax, format!("invalid YAML: {}", e.message)),
            Problem::DuplicateKey(key) => (Kind::Syntax, format!("duplicate key `{key}`")),
            Problem::Tag(tag) => (
                Kind::Syntax,
                format!("invalid YAML: YAML tags (here `{tag}`) are not used in scenes"),
            ),
            Problem::UnknownField(key) => (
                Kind::UnknownKey,
                format!(
                    "unknown key `{key}`; a scene has the keys {}",
                    KEYS.join(", ")
                ),
            ),
            Problem::MissingField(key) => (
                Kind::Structure,
                format!("the required key `{key}` is missing"),
            ),
            // Only the document itself has no path: it is not a mapping.
            Problem::Type if field.is_empty() => {
                let keys = KEYS.join(", ");
                let message = match self.doc.shape(&[]) {
                    Some(shape) => {
                        format!("a scene is a mapping of scene keys ({keys}), not {shape}")
                    }
                    None => format!("a scene is a mapping of scene keys ({keys}): {}", e.message),
                };
                (Kind::Structure, message)
            }
            Problem::Type => (Kind::Structure, e.message.clone()),
        };
        self.at(kind, e.mark, &field, message)
    }

    /// The scene in stages: settings, the model, what is wanted, the parameters and, once
    /// those are valid, the model's requirements; every problem found is reported together.
    fn validate(&self, raw: Raw, registry: &[&'static dyn Model]) -> Result<Scene, SceneError> {
        let mut out: Vec<Diagnostic> = Vec::new();
        let (tolerance, samples) = self.settings(&raw, &mut out);
        let until = self.until(&raw, &mut out);
        let Some(model) = self.model(&raw, registry, &mut out) else {
            return Err(finish(out));
        };
        self.needs_until(&raw, model.info(), &mut out);
        let want = self.wanted(&raw, model.info(), &mut out);
        let values = self.parameter_values(&raw, model.info(), &mut out);
        if let Some(values) = &values {
            self.requirements(model, values, &mut out);
            self.restitutions(model, values, &mut out);
        }
        if !out.is_empty() {
            return Err(finish(out));
        }
        let Some(parameters) = values else {
            // Every parameter that is missing or invalid has its diagnostic.
            return Err(finish(out));
        };
        Ok(Scene {
            file: self.file.to_path_buf(),
            model,
            parameters,
            want,
            tolerance,
            samples,
            until,
            source: self.doc.text().to_string(),
        })
    }

    /// `tolerance` and `samples`, which do not depend on the model (their defaults where
    /// absent; a value out of range is reported and its default kept for the other checks).
    fn settings(&self, raw: &Raw, out: &mut Vec<Diagnostic>) -> (f64, usize) {
        // tolerance and samples do not depend on the model.
        let tolerance = raw.tolerance.unwrap_or(DEFAULT_TOLERANCE);
        if !tolerance.is_finite() {
            out.push(self.diag(
                Kind::NotFinite,
                "tolerance",
                At::Value,
                format!("must be a finite number, not {}", show(tolerance)),
            ));
        } else if !(TOLERANCE_RANGE.0..=TOLERANCE_RANGE.1).contains(&tolerance) {
            out.push(self.diag(
                Kind::OutOfRange,
                "tolerance",
                At::Value,
                format!(
                    "must be between {:e} and {:e} (relative), not {}",
                    TOLERANCE_RANGE.0,
                    TOLERANCE_RANGE.1,
                    show(tolerance)
                ),
            ));
        }
        let samples = raw.samples.unwrap_or(DEFAULT_SAMPLES as i64);
        let samples = match usize::try_from(samples) {
            Ok(s) if (SAMPLES_RANGE.0..=SAMPLES_RANGE.1).contains(&s) => s,
            _ => {
                out.push(self.diag(
                    Kind::OutOfRange,
                    "samples",
                    At::Value,
                    format!(
                        "must be between {} and {} points, not {samples}",
                        SAMPLES_RANGE.0, SAMPLES_RANGE.1
                    ),
                ));
                DEFAULT_SAMPLES
            }
        };

        (tolerance, samples)
    }

    /// `until`: a positive finite time, or absent.
    fn until(&self, raw: &Raw, out: &mut Vec<Diagnostic>) -> Option<f64> {
        let until = raw.until?;
        let (kind, why) = if !until.is_finite() {
            (Kind::NotFinite, "a finite number")
        } else if until <= 0.0 {
            (Kind::OutOfRange, "a positive time")
        } else {
            return Some(until);
        };
        out.push(self.diag(
            kind,
            "until",
            At::Value,
            format!(
                "must be {why} in seconds from release (how long the motion goes on), not {}",
                show(until)
            ),
        ));
        None
    }

    /// The scene's model: a system in the registry (a phase model is refused, naming its
    /// system).
    fn model(
        &self,
        raw: &Raw,
        registry: &[&'static dyn Model],
        out: &mut Vec<Diagnostic>,
    ) -> Option<&'static dyn Model> {
        let systems = || -> Vec<&str> {
            (registry.iter().map(|m| m.info()))
                .filter(|i| i.is_general())
                .map(|i| i.name)
                .collect()
        };
        let Some(model) = registry
            .iter()
            .copied()
            .find(|m| m.info().name == raw.model)
        else {
            let names = systems();
            let available = if names.is_empty() {
                "none (no model has been generated yet)".to_string()
            } else {
                names.join(", ")
            };
            out.push(self.diag(
                Kind::UnknownModel,
                "model",
                At::Value,
                format!(
                    "unknown model `{}`; available models: {available}",
                    raw.model
                ),
            ));
            return None;
        };
        let info = model.info();
        if !info.is_general() {
            out.push(self.diag(
                Kind::UnknownModel,
                "model",
                At::Value,
                format!(
                    "model `{}` is a phase of the system `{}`, which decides its phases itself: \
                     write `model: {}`; the systems are: {}",
                    info.name,
                    info.system,
                    info.system,
                    systems().join(", ")
                ),
            ));
            return None;
        }

        Some(model)
    }

    /// A system with no end angle has no end of its own: its scene must give `until` (the
    /// diagnostic names `until` at the `model` line, as the key is absent).
    fn needs_until(&self, raw: &Raw, info: &ModelInfo, out: &mut Vec<Diagnostic>) {
        if info.end_angle.is_none() && raw.until.is_none() {
            let mark = self.doc.locate_nearest(&parse_path("model"), At::Value);
            out.push(self.at(
                Kind::Structure,
                mark,
                "until",
                format!(
                    "model `{}` has no end angle, so its motion has no end of its own: give \
                     `until: <seconds>`, the time to run it to",
                    info.name
                ),
            ));
        }
    }

    /// The quantities of `want`, each known, available from the model and named once.
    fn wanted(&self, raw: &Raw, info: &ModelInfo, out: &mut Vec<Diagnostic>) -> Vec<Quantity> {
        let mut want = Vec::new();
        if raw.want.is_empty() {
            out.push(self.diag(
                Kind::OutOfRange,
                "want",
                At::Value,
                format!(
                    "nothing is wanted; model `{}` offers: {}",
                    info.name,
                    Quantity::names(info).join(", ")
                ),
            ));
        }
        let mut seen = HashSet::new();
        for (i, name) in raw.want.iter().enumerate() {
            let field = format!("want[{i}]");
            match Quantity::parse(name, info) {
                Err(unknown) => out.push(self.diag(
                    Kind::UnknownQuantity,
                    &field,
                    At::Value,
                    unknown.to_string(),
                )),
                Ok(q) if !q.available(info) => out.push(self.diag(
                    Kind::UnavailableQuantity,
                    &field,
                    At::Value,
                    format!(
                        "model `{}` cannot provide `{name}`: {}; it offers: {}",
                        info.name,
                        unavailable_reason(q, info),
                        Quantity::names(info).join(", ")
                    ),
                )),
                Ok(q) if !seen.insert(q) => out.push(self.diag(
                    Kind::DuplicateQuantity,
                    &field,
                    At::Value,
                    format!("`{name}` is wanted more than once"),
                )),
                Ok(q) => want.push(q),
            }
        }
        self.sensitivities_of_something(raw, &want, out);
        want
    }

    /// `sensitivities` are of the separation angle and time, the contact ends, the floor
    /// impact and the impacts' times: wanted without any of them, they would be of nothing the
    /// scene computes.
    fn sensitivities_of_something(&self, raw: &Raw, want: &[Quantity], out: &mut Vec<Diagnostic>) {
        let of = [
            Quantity::SeparationAngle,
            Quantity::SeparationTime,
            Quantity::ContactEnd,
            Quantity::FloorImpact,
            Quantity::Impacts,
        ];
        if !want.contains(&Quantity::Sensitivities) || want.iter().any(|q| of.contains(q)) {
            return;
        }
        if let Some(i) = raw.want.iter().position(|w| w == "sensitivities") {
            out.push(
                self.diag(
                    Kind::UnavailableQuantity,
                    &format!("want[{i}]"),
                    At::Value,
                    "`sensitivities` are of the separation angle and time, the contact ends, \
                 the floor impact and the impacts' times, and this scene wants none of them: add \
                 `separation_angle`, `separation_time`, `contact_end`, `floor_impact` or \
                 `impacts` to `want`"
                        .into(),
                ),
            );
        }
    }

    /// The parameter values in the model's order, each checked by [`check_value`]; `None`
    /// when one is missing or invalid (each reported).
    fn parameter_values(
        &self,
        raw: &Raw,
        info: &'static ModelInfo,
        out: &mut Vec<Diagnostic>,
    ) -> Option<Vec<f64>> {
        let expected: Vec<&str> = info.parameters.iter().map(|p| p.name).collect();
        for name in raw.parameters.keys() {
            if !expected.contains(&name.as_str()) {
                out.push(self.diag(
                    Kind::UnknownParameter,
                    &format!("parameters.{name}"),
                    At::Key,
                    format!(
                        "model `{}` has no parameter `{name}`; its parameters are {}",
                        info.name,
                        expected.join(", ")
                    ),
                ));
            }
        }
        let mut values = Vec::with_capacity(info.parameters.len());
        let mut all_good = true;
        for (i, p) in info.parameters.iter().enumerate() {
            let field = format!("parameters.{}", p.name);
            let Some(&v) = raw.parameters.get(p.name) else {
                all_good = false;
                out.push(self.diag(
                    Kind::MissingParameter,
                    &field,
                    At::Key,
                    format!(
                        "missing parameter `{}` ({}, in {})",
                        p.name, p.meaning, p.unit
                    ),
                ));
                continue;
            };
            // The one value check ([`check_value`]); the scene renders its verdict.
            let check = check_value(info, i, v);
            all_good &= check.is_ok();
            match check {
                Ok(()) => {}
                Err(SystemError::NegativeFriction { friction, .. }) => out.push(self.diag(
                    Kind::NegativeFriction,
                    &field,
                    At::Value,
                    format!(
                        "`{}` ({}) is the coefficient of friction `{}` and must not be negative, not {}",
                        p.name,
                        p.meaning,
                        friction,
                        show(v)
                    ),
                )),
                Err(SystemError::NotPositive { .. }) => out.push(self.diag(
                    Kind::NotPositive,
                    &field,
                    At::Value,
                    format!(
                        "`{}` ({}) must be positive, not {}",
                        p.name,
                        p.meaning,
                        show(v)
                    ),
                )),
                Err(_) => out.push(self.diag(
                    Kind::NotFinite,
                    &field,
                    At::Value,
                    format!("`{}` must be a finite number, not {}", p.name, show(v)),
                )),
            }
            values.push(v);
        }

        all_good.then_some(values)
    }

    /// Each contact's coefficient of restitution from valid parameters, in `[0, 1]`; a failure
    /// is placed at the first of the parameters in the file.
    fn restitutions(&self, model: &dyn Model, values: &[f64], out: &mut Vec<Diagnostic>) {
        let info = model.info();
        if let Err(e) = crate::system::restitutions(model, values) {
            // At the first in the file of the parameters its contact's restitution reads.
            let involved = match &e {
                SystemError::Restitution { contact, .. } => (info.contacts.iter())
                    .find(|c| c.name == *contact)
                    .map(|c| expression_parameters(c.restitution, info))
                    .unwrap_or_default(),
                _ => Vec::new(),
            };
            let field = self.first_in_file(involved.iter().map(|n| format!("parameters.{n}")));
            let field = if field.is_empty() {
                "parameters".to_string()
            } else {
                field
            };
            out.push(self.diag(Kind::OutOfRange, &field, At::Key, e.to_string()));
        }
    }

    /// The model's requirements on valid parameters, each failure placed at the first of its
    /// parameters in the file.
    fn requirements(&self, model: &dyn Model, values: &[f64], out: &mut Vec<Diagnostic>) {
        let info = model.info();
        if !info.requirements.is_empty() {
            let mut margins = vec![0.0; info.requirements.len()];
            // `values` holds one value per parameter (`parameter_values`) and `margins` one
            // entry per requirement, so a refusal here would be a bug: it is reported, not
            // dropped.
            let failed = match failed_requirements(model, values, &mut margins) {
                Ok(failed) => failed,
                Err(e) => {
                    out.push(self.diag(
                        Kind::Requirement,
                        "parameters",
                        At::Key,
                        format!("the requirements could not be checked: {e}"),
                    ));
                    return;
                }
            };
            for (r, margin) in failed {
                {
                    let involved = requirement_parameters(r, info);
                    let field =
                        self.first_in_file(involved.iter().map(|n| format!("parameters.{n}")));
                    let field = if field.is_empty() {
                        "parameters".to_string()
                    } else {
                        field
                    };
                    let list = if involved.is_empty() {
                        String::new()
                    } else {
                        format!(" (involves {})", involved.join(", "))
                    };
                    out.push(self.diag(
                        Kind::Requirement,
                        &field,
                        At::Key,
                        format!(
                            "requirement `{}` fails: {}; margin {}{list}",
                            r.name,
                            r.meaning,
                            show(margin)
                        ),
                    ));
                }
            }
        }
    }
}

/// Sorts diagnostics into file order.
fn finish(mut out: Vec<Diagnostic>) -> SceneError {
    out.sort_by_key(|d| (d.line, d.column));
    SceneError { diagnostics: out }
}

/// Why a model cannot provide a quantity it knows by name.
fn unavailable_reason(q: Quantity, info: &ModelInfo) -> &'static str {
    match q {
        Quantity::FloorImpact => "it has no end angle (its spec names none)",
        Quantity::PointMassFallTime => "it has no falling point (its spec names none)",
        Quantity::ThetaSeries
        | Quantity::Sensitivities
        | Quantity::ContactEnd
        | Quantity::SeparationAngle
        | Quantity::SeparationTime
            if info.reduced_index.is_none() =>
        {
            "it has no reduced coordinate (its spec names none) to measure it in"
        }
        Quantity::LinearisedSeparationAngle => {
            "it has no fast phase at release whose separation is a polynomial root"
        }
        Quantity::ContactTimeToFloor | Quantity::CrossCheck => {
            "it has no fast phase that starts at release"
        }
        Quantity::ContactEnd => "it has no contact",
        _ => "its first contact is not a unilateral contact",
    }
}

/// The names of the parameters a requirement's margin reads, in model order.
fn requirement_parameters(r: &RequirementInfo, info: &ModelInfo) -> Vec<&'static str> {
    (r.parameters.iter())
        .filter_map(|&i| info.parameters.get(i).map(|p| p.name))
        .collect()
}

/// The parameters an expression of the model's spec reads (a contact's restitution), in model
/// order; none where the text does not parse (the model's own code evaluates it).
fn expression_parameters(text: &str, info: &ModelInfo) -> Vec<&'static str> {
    let Ok(e) = Expr::parse(text) else {
        return Vec::new();
    };
    let read = e.symbols();
    (info.parameters.iter())
        .map(|p| p.name)
        .filter(|n| read.contains(*n))
        .collect()
}

/// A number as a scene would write it (`.nan`, `.inf`, `-1`).
fn show(v: f64) -> String {
    if v.is_nan() {
        ".nan".into()
    } else if v.is_infinite() {
        if v > 0.0 {
            ".inf".into()
        } else {
            "-.inf".into()
        }
    } else {
        format!("{v}")
    }
}
