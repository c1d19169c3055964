//! What the package's notebook helpers (`rodcube/_notebook.py`) need from Rust: a model's
//! derivation as the derivation tool wrote it (embedded at build time by `build.rs`, so an
//! installed wheel carries it), and a scene run as the `rodcube run` command runs it, returned
//! as `results.json`'s text and `motion.svg`'s (when the run drew the motion), and the command
//! line's number format. Scenes find the models `load_models` loaded from tapes too.

use pyo3::prelude::*;
use rodcube::models::{Entry, Provenance, TapeRoute};
use rodcube::report::{self, motion};
use rodcube::scene::Source;
use std::path::Path;

use crate::error;

include!(concat!(env!("OUT_DIR"), "/derivations.rs"));

/// The names of the models whose derivations the package carries, sorted.
#[pyfunction]
pub fn derivation_models() -> Vec<&'static str> {
    DERIVATIONS.iter().map(|(name, _, _)| *name).collect()
}

/// A model's derivation: `(LaTeX write-up, JSON record)`, the text of `generated/<model>.tex`
/// and `generated/<model>.json`. A model that runs from a tape `load_models` loaded has none
/// here (a tape holds the program, not the write-up; the one the package carries of a compiled
/// model of that name is of another program): an error naming its tape says so.
#[pyfunction]
pub fn derivation_sources(model: &str) -> PyResult<(&'static str, &'static str)> {
    if let Some(Entry {
        provenance: Provenance::Tape { file, why },
        ..
    }) = rodcube::models::entry(model)
        && why != TapeRoute::Asked
    {
        return Err(error(format!(
            "model `{model}` runs from its tape {file}, which holds its program but not its \
             derivation; the package carries the derivations of the models compiled into it \
             (`derivation_models()`); `cargo derive` writes a spec's derivation into \
             generated/<model>.tex"
        )));
    }
    DERIVATIONS
        .iter()
        .find(|(name, _, _)| *name == model)
        .map(|(_, tex, json)| (*tex, *json))
        .ok_or_else(|| {
            error(format!(
                "no model `{model}`; there are: {}",
                derivation_models().join(", ")
            ))
        })
}

/// A number as the command line's tables show it: `sig` significant digits, engineering
/// notation outside `1e-3 ..= 1e6` ([`rodcube::results::format_number`]).
#[pyfunction]
pub fn format_number(value: f64, sig: usize) -> String {
    rodcube::results::format_number(value, sig)
}

/// The quantities in the order of the vocabulary (the paper's order), which the command line's
/// results table follows (the rest alphabetically after them).
#[pyfunction]
pub fn result_order() -> Vec<&'static str> {
    rodcube::quantity::FIXED
        .iter()
        .map(|(name, _, _)| *name)
        .collect()
}

/// Runs a scene: the file at `path`, or else `text` (a YAML scene, named `name` in messages).
/// Returns `results.json`'s text and `motion.svg`'s (`None` unless the scene wants a
/// trajectory). The run is `rodcube run`'s ([`rodcube::scene::run`]), and so are the messages
/// of its errors (`RodcubeError`): a scene's problems with file, line, column and field, a
/// failed solve with the scene's file.
#[pyfunction]
#[pyo3(signature = (text, path, name))]
pub fn run_scene(
    py: Python<'_>,
    text: Option<&str>,
    path: Option<&str>,
    name: &str,
) -> PyResult<(String, Option<String>)> {
    let source = match (path, text) {
        (Some(path), _) => Source::File(Path::new(path)),
        (None, Some(text)) => Source::Text {
            text,
            file: Path::new(name),
        },
        (None, None) => return Err(error("give a scene: a path, YAML text or a dict")),
    };
    let (_, results) = py.detach(|| rodcube::scene::run(source)).map_err(error)?;
    let json = report::json::to_string(&results).map_err(error)?;
    let svg = (results.drawing.as_ref()).map(|d| motion::svg(&motion::Animation::build(d)));
    Ok((json, svg))
}
