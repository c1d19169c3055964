//! `rodcube fmu`: writes `<model>.fmu` (an FMI 2.0 co-simulation FMU) from a system, the start
//! values of a scene and the shared library with the feature `fmi` (`librodcube.so`, which the
//! build of `rodcube` leaves beside it or in `deps/` there: [`default_binary`]), which it checks for
//! the FMI 2.0 entry points before zipping. The model travels as data: the tapes of the system
//! and of its fast phases go into the FMU's `resources/`, so the library is the same for every
//! model, one derived a minute ago included. The archive is made in memory and written
//! atomically, so a failure leaves no partial `.fmu`.

use super::zip::{self, TooLarge};
use super::{
    Defaults, DescriptionError, FMI2_FUNCTIONS, RESOURCES, Resources, guid, model_description,
};
use crate::io::{self, OutDir};
use crate::model::Model;
use crate::scene::{Scene, SceneError};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// How to build the shared library an FMU needs (its name, `librodcube.so`, in the target
/// directory's `release/`): the main build, whose default features include `fmi` and whose
/// library is also a `cdylib` (Cargo.toml's `[lib]`).
pub const BUILD_LIBRARY: &str = "cargo build --release";

/// The library's file name as cargo writes it.
pub const LIBRARY_NAME: &str = "librodcube.so";

/// The scenes of `scenes/`, built in: the start values of a model's FMU come from the first
/// that names it (the paper's first), unless a scene is given.
const SCENES: &[(&str, &str)] = &[
    ("scenes/paper.yaml", include_str!("../../scenes/paper.yaml")),
    (
        "scenes/angle_only.yaml",
        include_str!("../../scenes/angle_only.yaml"),
    ),
    (
        "scenes/block_tipping.yaml",
        include_str!("../../scenes/block_tipping.yaml"),
    ),
    (
        "scenes/bounce.yaml",
        include_str!("../../scenes/bounce.yaml"),
    ),
    (
        "scenes/cylinder.yaml",
        include_str!("../../scenes/cylinder.yaml"),
    ),
    (
        "scenes/fixed_cylinder.yaml",
        include_str!("../../scenes/fixed_cylinder.yaml"),
    ),
    (
        "scenes/friction.yaml",
        include_str!("../../scenes/friction.yaml"),
    ),
    (
        "scenes/hinged.yaml",
        include_str!("../../scenes/hinged.yaml"),
    ),
    (
        "scenes/hinged_cylinder.yaml",
        include_str!("../../scenes/hinged_cylinder.yaml"),
    ),
    (
        "scenes/hinged_spring.yaml",
        include_str!("../../scenes/hinged_spring.yaml"),
    ),
    (
        "scenes/ladder.yaml",
        include_str!("../../scenes/ladder.yaml"),
    ),
    (
        "scenes/ladder_friction.yaml",
        include_str!("../../scenes/ladder_friction.yaml"),
    ),
    (
        "scenes/liftoff.yaml",
        include_str!("../../scenes/liftoff.yaml"),
    ),
    (
        "scenes/spring.yaml",
        include_str!("../../scenes/spring.yaml"),
    ),
];

/// Why an FMU was not written.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    /// No model of that name.
    #[error("no model `{name}`; the systems are: {systems}")]
    UnknownModel {
        /// The name asked.
        name: String,
        /// The systems, comma-separated.
        systems: String,
    },
    /// A fast phase was named: an FMU is of a system.
    #[error("model `{name}` is a phase of the system `{system}`: export `{system}`")]
    NotASystem {
        /// The phase.
        name: &'static str,
        /// Its system.
        system: &'static str,
    },
    /// The scene names another model.
    #[error("the scene {} is of `{scene}`, not `{model}`", file.display())]
    SceneModel {
        /// The scene's file.
        file: PathBuf,
        /// Its model.
        scene: &'static str,
        /// The model exported.
        model: &'static str,
    },
    /// No built-in scene names the model and none was given.
    #[error("no scene in scenes/ is of `{model}`: give its start values with --scene FILE")]
    NoScene {
        /// The model.
        model: &'static str,
    },
    /// A built-in scene was refused (a broken build).
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// The shared library could not be read.
    #[error(
        "cannot read the FMU's shared library {}: {error}; build it with `{BUILD_LIBRARY}` (it lands in the target directory's release/{LIBRARY_NAME}) or pass --binary FILE",
        path.display()
    )]
    Binary {
        /// Where it was looked for.
        path: PathBuf,
        /// The error.
        error: std::io::Error,
    },
    /// The shared library lacks FMI 2.0 entry points (built without the feature `fmi`).
    #[error(
        "{} has no {missing}: it was built without the feature `fmi`; build it with `{BUILD_LIBRARY}`",
        path.display()
    )]
    NotFmi {
        /// The library.
        path: PathBuf,
        /// The first entry point missing.
        missing: &'static str,
    },
    /// A fast phase of the system is not in the registry, so its tape cannot go into the FMU.
    #[error(
        "the system `{system}` has the fast phase `{phase}`, which is not loaded: put its tape \
         ({phase}.tape.json, derived with the system's) in the --models directory"
    )]
    NoTape {
        /// The system.
        system: &'static str,
        /// The phase.
        phase: &'static str,
    },
    /// A model's name cannot name files and a C identifier (a tape written by hand).
    #[error(
        "the model `{name}` is not named by an identifier (letters, digits and `_`, not first a \
         digit): it cannot name the FMU's model identifier and files"
    )]
    ModelName {
        /// The name.
        name: &'static str,
    },
    /// The model description could not be made.
    #[error(transparent)]
    Description(#[from] DescriptionError),
    /// The resources could not be written as JSON.
    #[error("cannot write the FMU's resources: {0}")]
    Json(serde_json::Error),
    /// The archive would be too large.
    #[error("{0}")]
    TooLarge(TooLarge),
    /// The output directory or the file could not be written (nothing partial was left).
    #[error(transparent)]
    Output(#[from] io::Error),
}

/// The system named `name` in `registry`.
pub fn find_system(
    name: &str,
    registry: &[&'static dyn Model],
) -> Result<&'static dyn Model, ExportError> {
    let model = registry.iter().copied().find(|m| m.info().name == name);
    let Some(model) = model else {
        let systems: Vec<&str> = (registry.iter().map(|m| m.info()))
            .filter(|i| i.is_general())
            .map(|i| i.name)
            .collect();
        return Err(ExportError::UnknownModel {
            name: name.to_string(),
            systems: systems.join(", "),
        });
    };
    let info = model.info();
    if !info.is_general() {
        return Err(ExportError::NotASystem {
            name: info.name,
            system: info.system,
        });
    }
    Ok(model)
}

/// The defaults of `model`'s FMU from `scene` (its parameters, tolerance and end time), or
/// from the first built-in scene of the model when `scene` is `None`.
pub fn defaults(model: &'static dyn Model, scene: Option<&Scene>) -> Result<Defaults, ExportError> {
    let name = model.info().name;
    let builtin;
    let scene = match scene {
        Some(s) => s,
        None => {
            let mut found = None;
            for (file, text) in SCENES {
                let s = Scene::parse(text, Path::new(file), crate::models::all())?;
                if s.info().name == name {
                    found = Some(s);
                    break;
                }
            }
            builtin = found.ok_or(ExportError::NoScene { model: name })?;
            &builtin
        }
    };
    if scene.info().name != name {
        return Err(ExportError::SceneModel {
            file: scene.file.clone(),
            scene: scene.info().name,
            model: name,
        });
    }
    Ok(Defaults {
        start: scene.parameters.clone(),
        tolerance: scene.tolerance,
        stop: scene.until,
        source: format!("the parameters of {}", scene.file.display()),
    })
}

/// Where `rodcube fmu` looks for the shared library when none is given: beside the running
/// executable, where `cargo build` writes both, and in `deps/` there, where cargo leaves the
/// library when it built it only for the binary (`cargo run`, `cargo test`: it copies up
/// only what was asked for); the newer of the two that exist (the other may be left from an
/// older build), else the first, which the error names.
pub fn default_binary() -> Option<PathBuf> {
    let exe = std::env::current_exe().ok()?;
    let dir = exe.parent()?;
    let candidates = [dir.join(LIBRARY_NAME), dir.join("deps").join(LIBRARY_NAME)];
    let modified = |p: &PathBuf| std::fs::metadata(p).and_then(|m| m.modified()).ok();
    let newest = (candidates.iter())
        .filter_map(|p| Some((modified(p)?, p)))
        .max_by_key(|(t, _)| *t)
        .map(|(_, p)| p.clone());
    let [first, _] = candidates;
    Some(newest.unwrap_or(first))
}

/// The shared library at `path`, checked to export every FMI 2.0 co-simulation function.
pub fn read_binary(path: &Path) -> Result<Vec<u8>, ExportError> {
    let bytes = std::fs::read(path).map_err(|error| ExportError::Binary {
        path: path.to_path_buf(),
        error,
    })?;
    let names = fmi2_names(&bytes);
    if let Some(missing) = FMI2_FUNCTIONS
        .iter()
        .find(|f| !names.contains(f.as_bytes()))
    {
        return Err(ExportError::NotFmi {
            path: path.to_path_buf(),
            missing,
        });
    }
    Ok(bytes)
}

/// Every NUL-terminated name starting `fmi2` in `bytes` (the dynamic symbol table's names
/// among them).
fn fmi2_names(bytes: &[u8]) -> BTreeSet<&[u8]> {
    let mut out = BTreeSet::new();
    let mut i = 0;
    while let Some(at) = bytes[i..].windows(4).position(|w| w == b"fmi2") {
        let start = i + at;
        let len = bytes[start..].iter().position(|&b| b == 0);
        let end = len.map_or(bytes.len(), |n| start + n);
        out.insert(&bytes[start..end]);
        i = start + 4;
    }
    out
}

/// One model's tape, as the FMU carries it.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelTape {
    /// The model.
    pub model: &'static str,
    /// The tape's text.
    pub text: Arc<str>,
}

impl ModelTape {
    /// Its file in the FMU: `resources/<model>.tape.json`.
    pub fn entry(&self) -> String {
        format!("resources/{}.tape.json", self.model)
    }
}

/// The tapes an FMU of `model`'s system carries: the system's, then each fast phase's
/// ([`crate::model::ModelInfo::phases`]), each as [`crate::models::tape_text`] gives it (the
/// tape a model was loaded from, or a compiled model's own), so the library needs none of them
/// compiled in.
pub fn tapes(model: &'static dyn Model) -> Result<Vec<ModelTape>, ExportError> {
    let info = model.info();
    let mut names = vec![info.name];
    for p in info.phases {
        if !names.contains(&p.model) {
            names.push(p.model);
        }
    }
    let mut out = Vec::with_capacity(names.len());
    for name in names {
        if !crate::spec::is_identifier(name) {
            return Err(ExportError::ModelName { name });
        }
        let text = crate::models::tape_text(name).ok_or(ExportError::NoTape {
            system: info.name,
            phase: name,
        })?;
        out.push(ModelTape { model: name, text });
    }
    Ok(out)
}

/// Writes `<model>.fmu` into `out`: its model description with `defaults`, `binary` as
/// `binaries/linux64/<model>.so`, the start values in `resources/rodcube.json` and the models'
/// `tapes` as `resources/<model>.tape.json` (which the library loads at `fmi2Instantiate`).
/// Returns the file written.
pub fn write_fmu(
    model: &'static dyn Model,
    defaults: &Defaults,
    tapes: &[ModelTape],
    binary: &[u8],
    out: &OutDir,
) -> Result<PathBuf, ExportError> {
    let info = model.info();
    let description = model_description(info, defaults)?;
    let library = format!("binaries/linux64/{}.so", info.name);
    let resources = Resources {
        model: info.name.to_string(),
        guid: guid(info)?,
        start: defaults.start.clone(),
    };
    let resources = serde_json::to_string_pretty(&resources).map_err(ExportError::Json)?;
    let resources_entry = format!("resources/{RESOURCES}");
    let tape_entries: Vec<String> = tapes.iter().map(ModelTape::entry).collect();
    let mut entries: Vec<(&str, &[u8])> = vec![
        ("modelDescription.xml", description.as_bytes()),
        (&library, binary),
        (&resources_entry, resources.as_bytes()),
    ];
    for (name, t) in tape_entries.iter().zip(tapes) {
        entries.push((name, t.text.as_bytes()));
    }
    let archive = zip::archive(&entries).map_err(ExportError::TooLarge)?;
    Ok(out.write(&format!("{}.fmu", info.name), &archive)?)
}
