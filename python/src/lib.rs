//! Python bindings of rodcube (PyO3, abi3, NumPy), the compiled module `rodcube._rodcube`:
//! `solve` runs the planner for one parameter point, `sweep_flat` the per-point solver over
//! flat NumPy arrays (with each point's exact sensitivities if asked) in parallel with the GIL
//! released (the package's `sweep`, in
//! `rodcube/__init__.py`, broadcasts its arguments into them), `models` and `parameters` list
//! the registry, and `load_models` adds to it the models of a directory of tapes (derived
//! models run with no compiler), which every function then finds by name. Errors are
//! `rodcube.RodcubeError` (a `ValueError`) with the library's own messages; a point that fails
//! in a sweep keeps its error's message. `notebook.rs` gives the
//! notebook helpers (`derivation`, `run`) the embedded derivations and scene runs.

use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use rayon::prelude::*;
use rodcube::axes::{AxisError, Mapping};
use rodcube::model::{Model, ModelInfo};
use rodcube::plan::{self, Parameters, Request};
use rodcube::quantity::Quantity;
use rodcube::report::prose;
use rodcube::results::Note;
use rodcube::solve::fast::lean::LeanSolver;
use rodcube::solve::fast::sensitivity::SensitivityWork;
use rodcube::sweep::{Points, planned};

mod notebook;

create_exception!(
    rodcube,
    RodcubeError,
    PyValueError,
    "A request rodcube refused or could not solve; the message says why."
);

fn error(message: impl std::fmt::Display) -> PyErr {
    RodcubeError::new_err(message.to_string())
}

fn find(model: &str) -> PyResult<&'static dyn Model> {
    rodcube::models::find(model).ok_or_else(|| {
        let names: Vec<&str> = rodcube::models::all()
            .iter()
            .map(|m| m.info().name)
            .collect();
        error(format!(
            "no model `{model}`; there are: {}",
            names.join(", ")
        ))
    })
}

/// The names of the registered models.
#[pyfunction]
fn models() -> Vec<&'static str> {
    rodcube::models::all()
        .iter()
        .map(|m| m.info().name)
        .collect()
}

/// Loads every tape (`*.tape.json`, as `rodcube derive --tapes-into DIR SPEC` or `cargo derive`
/// writes them) of the directory `path` into the registry, so that `solve`, `sweep`, `run` and
/// `parameters` find its models by name, and returns their names, sorted: a model not compiled
/// into the package is added; a tape of a compiled model whose program differs (its spec
/// derived again) takes its place; a tape that holds a compiled model's own program is checked
/// and the compiled code kept. Each tape is checked before anything runs: one refused raises
/// `RodcubeError` with the loader's message, which names the file, and nothing of the
/// directory is loaded then.
#[pyfunction]
fn load_models(py: Python<'_>, path: std::path::PathBuf) -> PyResult<Vec<String>> {
    let loaded = py.detach(|| rodcube::models::load(&path)).map_err(error)?;
    let mut names: Vec<String> = (loaded.models.iter())
        .map(|m| m.info().name.to_string())
        .chain(loaded.same_as_compiled)
        .collect();
    names.sort();
    Ok(names)
}

/// The parameters of a model, in order: `(name, unit, meaning)`.
#[pyfunction]
fn parameters(model: &str) -> PyResult<Vec<(&'static str, &'static str, &'static str)>> {
    let info = find(model)?.info();
    Ok(info
        .parameters
        .iter()
        .map(|p| (p.name, p.unit, p.meaning))
        .collect())
}

/// Solves one parameter point and returns what `want` names: scalars as floats, words as
/// strings, series as dicts of NumPy arrays by column, `checks` as dicts, `impacts` as a list
/// of dicts, and `notes` (why a wanted quantity has no value, how the motion ended) when there
/// are any. `until` (s from release) carries the motion on through impacts to that time.
/// With `sensitivities` wanted, `sensitivities` maps `d(<result>)/d(<parameter>)` and
/// `elasticity(<result>;<parameter>)` (the keys of results.json) to their values and
/// `sensitivity_units` the same keys to their units; a sensitivity that does not exist is
/// absent, and `notes` says why.
#[pyfunction]
#[pyo3(signature = (model, want=None, tolerance=None, samples=None, until=None, **parameters))]
fn solve<'py>(
    py: Python<'py>,
    model: &str,
    want: Option<Vec<String>>,
    tolerance: Option<f64>,
    samples: Option<usize>,
    until: Option<f64>,
    parameters: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let m = find(model)?;
    let info = m.info();
    let want = want.unwrap_or_else(|| vec!["separation_angle".into(), "separation_time".into()]);
    let quantities = want
        .iter()
        .map(|w| Quantity::parse(w, info).map_err(error))
        .collect::<PyResult<Vec<_>>>()?;
    let mut named = Vec::new();
    if let Some(dict) = parameters {
        for (key, value) in dict.iter() {
            let name: String = key.extract()?;
            let value: f64 = value
                .extract()
                .map_err(|_| error(format!("parameter `{name}` must be a number")))?;
            named.push((name, value));
        }
    }
    let mut request = Request::new(m, Parameters::Named(named)).with_want(&quantities);
    if let Some(t) = tolerance {
        request = request.with_tolerance(t);
    }
    if let Some(s) = samples {
        request = request.with_samples(s);
    }
    request = request.with_until(until);
    let results = py.detach(|| plan::run(&request)).map_err(error)?;
    let out = PyDict::new(py);
    for (key, scalar) in &results.results {
        out.set_item(key, scalar.value)?;
    }
    for (key, label) in &results.labels {
        out.set_item(key, rodcube::report::prose::label(&label.value))?;
    }
    for (key, series) in &results.series {
        let columns = PyDict::new(py);
        for c in &series.columns {
            columns.set_item(&c.name, c.values.clone().into_pyarray(py))?;
        }
        out.set_item(key, columns)?;
    }
    if !results.checks.is_empty() {
        let checks = PyDict::new(py);
        for (name, check) in &results.checks {
            let c = PyDict::new(py);
            c.set_item("passed", check.passed)?;
            c.set_item("margin", check.margin)?;
            c.set_item("meaning", rodcube::report::prose::check_meaning(check))?;
            checks.set_item(name, c)?;
        }
        out.set_item("checks", checks)?;
    }
    if let Some(impacts) = &results.impacts {
        let list = PyList::empty(py);
        for record in impacts {
            let entry = PyDict::new(py);
            entry.set_item("time", record.time)?;
            entry.set_item("closing", &record.closing)?;
            entry.set_item("contacts", record.contacts.clone())?;
            entry.set_item("energy_lost", record.energy_lost)?;
            entry.set_item("normal_energy_lost", record.normal_energy_lost)?;
            entry.set_item("friction_energy_lost", record.friction_energy_lost)?;
            entry.set_item("zeno_limit", record.zeno_limit)?;
            let per_contact = PyList::empty(py);
            for c in &record.per_contact {
                let d = PyDict::new(py);
                d.set_item("contact", &c.contact)?;
                d.set_item("normal_velocity_before", c.normal_velocity_before)?;
                d.set_item("normal_velocity_after", c.normal_velocity_after)?;
                d.set_item("impulse", c.impulse)?;
                d.set_item("tangential_impulse", c.tangential_impulse)?;
                d.set_item("velocity_unit", c.velocity_unit)?;
                d.set_item("impulse_unit", c.impulse_unit)?;
                per_contact.append(d)?;
            }
            entry.set_item("per_contact", per_contact)?;
            list.append(entry)?;
        }
        out.set_item("impacts", list)?;
    }
    if !results.sensitivities.is_empty() {
        let (values, units) = (PyDict::new(py), PyDict::new(py));
        for (key, sensitivity) in &results.sensitivities {
            values.set_item(key, sensitivity.value)?;
            units.set_item(key, &sensitivity.unit)?;
        }
        out.set_item("sensitivities", values)?;
        out.set_item("sensitivity_units", units)?;
    }
    if !results.notes.is_empty() {
        let notes: std::collections::BTreeMap<&str, String> = (results.notes.iter())
            .map(|(key, n)| (key.as_str(), rodcube::report::prose::note(n)))
            .collect();
        out.set_item("notes", notes)?;
    }
    Ok(out)
}

/// Points per parallel task.
const CHUNK: usize = 4096;

/// Refuses `defaults` that name no parameter of the model.
fn check_defaults(info: &'static ModelInfo, defaults: &[(String, f64)]) -> PyResult<()> {
    if let Some((name, _)) = defaults
        .iter()
        .find(|(name, _)| !info.parameters.iter().any(|p| p.name == *name))
    {
        let names: Vec<&str> = info.parameters.iter().map(|p| p.name).collect();
        return Err(error(format!(
            "defaults: model `{}` has no parameter `{name}`; its parameters are {}",
            info.name,
            names.join(", ")
        )));
    }
    Ok(())
}

/// What [`sweep_flat`] returns: separation angle and time (NaN where a point failed), whether
/// each point succeeded, every failure as `(flat index, message)` in index order, and, when
/// sensitivities were asked for, `(name, values)` for `d(separation_angle)/d(<p>)` then
/// `d(separation_time)/d(<p>)` for every parameter `p` in the model's order.
type Flat<'py> = (
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<bool>>,
    Failures,
    Vec<(String, Bound<'py, PyArray1<f64>>)>,
);

/// Failed points: `(flat index, message)`.
type Failures = Vec<(usize, String)>;

/// The sweep over flat arrays, one per axis and all of one length (the Python `sweep`
/// broadcasts and reshapes): separation angle and time by the per-point solver, in parallel
/// with the GIL released. `fixed` are keyword values; `defaults` give parameters that neither
/// an axis nor `fixed` sets. A parameter that nothing sets is an error naming it: no value is
/// ever assumed. A point that fails is NaN, `False` in the mask, and its error's message.
/// With `sensitivities`, each point's exact sensitivities by `LeanSolver::sensitivities` too:
/// where they do not exist the point is `False` in the mask (its angle and time kept), its
/// sensitivities NaN, and the message says why.
#[pyfunction]
#[pyo3(signature = (model, axes, columns, fixed, defaults, sensitivities=false))]
fn sweep_flat<'py>(
    py: Python<'py>,
    model: &str,
    axes: Vec<String>,
    columns: Vec<PyReadonlyArray1<'py, f64>>,
    fixed: Vec<(String, f64)>,
    defaults: Vec<(String, f64)>,
    sensitivities: bool,
) -> PyResult<Flat<'py>> {
    let m = find(model)?;
    let info = m.info();
    LeanSolver::new(m).map_err(error)?;
    let points = flat_points(axes, &columns)?;
    let axis_names: Vec<&str> = points.names.iter().map(String::as_str).collect();
    let mapping = full_mapping(info, &axis_names, &fixed, &defaults)?;
    let (dims, len) = (points.names.len(), points.len());
    let points = points.values;
    let mut angle = vec![f64::NAN; len];
    let mut time = vec![f64::NAN; len];
    let mut ok = vec![false; len];
    let width = if sensitivities {
        2 * info.parameters.len()
    } else {
        0
    };
    let chunks: Vec<(Failures, Vec<f64>)> = py.detach(|| {
        (
            points.par_chunks(CHUNK * dims),
            angle.par_chunks_mut(CHUNK),
            time.par_chunks_mut(CHUNK),
            ok.par_chunks_mut(CHUNK),
        )
            .into_par_iter()
            .enumerate()
            .map(|(c, (chunk, angles, times, oks))| {
                let mut out = Chunk {
                    first: c * CHUNK,
                    angles,
                    times,
                    oks,
                    errors: Vec::new(),
                    sens: vec![f64::NAN; width * (chunk.len() / dims)],
                };
                out.solve(m, &mapping, chunk, dims, width > 0);
                (out.errors, out.sens)
            })
            .collect()
    });
    let mut errors = Vec::new();
    let mut sens = Vec::with_capacity(width * len);
    for (e, s) in chunks {
        errors.extend(e);
        sens.extend(s);
    }
    let names = (["separation_angle", "separation_time"].iter())
        .flat_map(|of| (info.parameters.iter()).map(move |p| format!("d({of})/d({})", p.name)));
    let sens_columns = names
        .take(width)
        .enumerate()
        .map(|(j, name)| {
            let column: Vec<f64> = (0..len).map(|k| sens[k * width + j]).collect();
            (name, column.into_pyarray(py))
        })
        .collect();
    Ok((
        angle.into_pyarray(py),
        time.into_pyarray(py),
        ok.into_pyarray(py),
        errors,
        sens_columns,
    ))
}

/// The points of flat columns, one per axis and all of one length (the Python `sweep`
/// broadcasts and reshapes), point after point.
fn flat_points(axes: Vec<String>, columns: &[PyReadonlyArray1<'_, f64>]) -> PyResult<Points> {
    if axes.is_empty() || axes.len() != columns.len() {
        return Err(error(format!(
            "give one column per axis and at least one axis: {} axes, {} columns",
            axes.len(),
            columns.len()
        )));
    }
    let columns: Vec<Vec<f64>> = columns.iter().map(|c| c.as_array().to_vec()).collect();
    let len = columns[0].len();
    if let Some((name, c)) = axes.iter().zip(&columns).find(|(_, c)| c.len() != len) {
        return Err(error(format!(
            "axis `{}` has {len} values and `{name}` {}; they must have as many",
            axes[0],
            c.len()
        )));
    }
    Ok(Points {
        names: axes,
        values: (0..len)
            .flat_map(|k| columns.iter().map(move |c| c[k]))
            .collect(),
        lines: Vec::new(),
    })
}

/// The wanted quantities of a sweep through the planner and their scalar results.
fn sweep_wanted(model: &'static dyn Model, want: &[String]) -> PyResult<planned::Wanted> {
    planned::wanted(model, want).map_err(error)
}

/// The scalar results `sweep(model=model, want=want, ...)` returns: `(key, unit)` in order,
/// whatever the points.
#[pyfunction]
fn sweep_results(model: &str, want: Vec<String>) -> PyResult<Vec<(String, &'static str)>> {
    let wanted = sweep_wanted(find(model)?, &want)?;
    Ok((wanted.columns.into_iter())
        .map(|c| (c.key, c.unit))
        .collect())
}

/// What [`sweep_planned`] returns: `(key, values)` per scalar result (NaN where a point has
/// none), whether each point has a value of every wanted quantity, and `(flat index,
/// message)` for every point that has not, in index order.
type PlannedFlat<'py> = (
    Vec<(String, Bound<'py, PyArray1<f64>>)>,
    Bound<'py, PyArray1<bool>>,
    Failures,
);

/// The sweep of any model's wanted scalar results over flat arrays through the planner
/// (`rodcube::sweep::planned`), in parallel with the GIL released. Every parameter needs a
/// value, as in [`sweep_flat`]. A point the model refuses or cannot solve is NaN, `False`
/// and its message; one where a wanted quantity has no value keeps the others, `False` and
/// the note why.
#[pyfunction]
#[pyo3(signature = (model, want, axes, columns, fixed, defaults, tolerance=None, until=None))]
#[allow(clippy::too_many_arguments)]
fn sweep_planned<'py>(
    py: Python<'py>,
    model: &str,
    want: Vec<String>,
    axes: Vec<String>,
    columns: Vec<PyReadonlyArray1<'py, f64>>,
    fixed: Vec<(String, f64)>,
    defaults: Vec<(String, f64)>,
    tolerance: Option<f64>,
    until: Option<f64>,
) -> PyResult<PlannedFlat<'py>> {
    let m = find(model)?;
    let wanted = sweep_wanted(m, &want)?;
    let points = flat_points(axes, &columns)?;
    let axis_names: Vec<&str> = points.names.iter().map(String::as_str).collect();
    let mapping = full_mapping(m.info(), &axis_names, &fixed, &defaults)?;
    let settings = planned::Settings {
        tolerance: tolerance.unwrap_or(plan::DEFAULT_TOLERANCE),
        until,
    };
    let out = py
        .detach(|| planned::run(m, &mapping, &points, &wanted, settings))
        .map_err(error)?;
    let (width, len) = (wanted.columns.len(), points.len());
    let results = (wanted.columns.into_iter().enumerate())
        .map(|(j, c)| {
            let column: Vec<f64> = (0..len).map(|k| out.values[k * width + j]).collect();
            (c.key, column.into_pyarray(py))
        })
        .collect();
    Ok((results, out.ok.into_pyarray(py), out.errors))
}

/// The mapping from axes to parameters once every parameter has a value: an axis, a keyword
/// value (`fixed`) or `defaults`. A parameter that nothing sets is an error naming it (the
/// library's [`AxisError::Missing`], with how to give it from Python).
fn full_mapping(
    info: &'static ModelInfo,
    axis_names: &[&str],
    fixed: &[(String, f64)],
    defaults: &[(String, f64)],
) -> PyResult<Mapping> {
    check_defaults(info, defaults)?;
    let mut values: Vec<(&str, f64)> = fixed.iter().map(|(n, v)| (n.as_str(), *v)).collect();
    // Refused axes or keyword values first, by name; then `defaults` give what nothing set.
    let unset = match Mapping::new(info, axis_names, &values) {
        Err(AxisError::Missing { unset, .. }) => unset,
        other => return other.map_err(error),
    };
    values.extend(unset.iter().filter_map(|u| {
        (defaults.iter())
            .find(|(name, _)| name == u.parameter.name)
            .map(|(name, v)| (name.as_str(), *v))
    }));
    Mapping::new(info, axis_names, &values).map_err(|e| match &e {
        AxisError::Missing { unset, .. } => {
            let first = unset.first().map_or("g", |u| u.parameter.name);
            error(format!(
                "{e}\ngive each as a keyword ({first}=...), on an axis, or in defaults={{\"{first}\": ...}}"
            ))
        }
        _ => error(e),
    })
}

/// One parallel task's share of the sweep's outputs.
struct Chunk<'a> {
    /// The flat index of its first point.
    first: usize,
    angles: &'a mut [f64],
    times: &'a mut [f64],
    oks: &'a mut [bool],
    errors: Failures,
    /// Per point, `d theta_sep/dp` then `d t_sep/dp` (NaN where there are none).
    sens: Vec<f64>,
}

impl Chunk<'_> {
    /// Solves the chunk's points (`dims` values each), with their sensitivities if `sens`.
    fn solve(
        &mut self,
        m: &'static dyn Model,
        mapping: &Mapping,
        chunk: &[f64],
        dims: usize,
        sens: bool,
    ) {
        let mut solver = match LeanSolver::new(m) {
            Ok(solver) => solver,
            Err(e) => {
                let message = e.to_string();
                let first = self.first;
                (self.errors).extend((0..self.oks.len()).map(|k| (first + k, message.clone())));
                return;
            }
        };
        let np = m.info().parameters.len();
        let mut p = vec![0.0; np];
        let mut work = SensitivityWork::default();
        for (k, point) in chunk.chunks(dims).enumerate() {
            mapping.fill(point, &mut p);
            let out = match solver.solve(&p) {
                Ok(out) => out,
                Err(e) => {
                    self.errors.push((self.first + k, e.to_string()));
                    continue;
                }
            };
            self.angles[k] = out.separation_angle;
            self.times[k] = out.separation_time;
            self.oks[k] = true;
            if !sens {
                continue;
            }
            let (a, t) = self.sens[2 * np * k..2 * np * (k + 1)].split_at_mut(np);
            let missing = match solver.sensitivities(&p, &out, &mut work, a, t) {
                Ok(Ok(())) => continue,
                Ok(Err(gap)) => prose::note(&Note::NoSensitivity(gap)),
                Err(e) => e.to_string(),
            };
            // Whatever part was written before the gap is no number.
            a.fill(f64::NAN);
            t.fill(f64::NAN);
            self.oks[k] = false;
            self.errors.push((self.first + k, missing));
        }
    }
}

/// The compiled half of the `rodcube` package.
#[pymodule]
fn _rodcube(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(models, m)?)?;
    m.add_function(wrap_pyfunction!(load_models, m)?)?;
    m.add_function(wrap_pyfunction!(parameters, m)?)?;
    m.add_function(wrap_pyfunction!(solve, m)?)?;
    m.add_function(wrap_pyfunction!(sweep_flat, m)?)?;
    m.add_function(wrap_pyfunction!(sweep_planned, m)?)?;
    m.add_function(wrap_pyfunction!(sweep_results, m)?)?;
    m.add_function(wrap_pyfunction!(notebook::derivation_models, m)?)?;
    m.add_function(wrap_pyfunction!(notebook::derivation_sources, m)?)?;
    m.add_function(wrap_pyfunction!(notebook::run_scene, m)?)?;
    m.add_function(wrap_pyfunction!(notebook::format_number, m)?)?;
    m.add_function(wrap_pyfunction!(notebook::result_order, m)?)?;
    m.add("RodcubeError", m.py().get_type::<RodcubeError>())?;
    Ok(())
}
