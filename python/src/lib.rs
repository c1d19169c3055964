//! Python bindings of rodcube (PyO3, abi3, NumPy): `solve` runs the planner for one parameter
//! point, `sweep` the per-point solver over NumPy arrays in parallel with the GIL released,
//! `models` and `parameters` list the registry. Errors are `rodcube.RodcubeError` (a
//! `ValueError`) with the library's own messages.

use numpy::{IntoPyArray, PyReadonlyArray1};
use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
use rodcube::axes::Mapping;
use rodcube::model::Model;
use rodcube::plan::{self, Parameters, Request};
use rodcube::quantity::Quantity;
use rodcube::solve::lean::LeanSolver;

create_exception!(
    _rodcube,
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
/// strings, series as dicts of NumPy arrays by column, `checks` as dicts, and `notes` (why a
/// wanted quantity has no value) when there are any.
#[pyfunction]
#[pyo3(signature = (model, want=None, tolerance=None, samples=None, **parameters))]
fn solve<'py>(
    py: Python<'py>,
    model: &str,
    want: Option<Vec<String>>,
    tolerance: Option<f64>,
    samples: Option<usize>,
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
    let results = py.detach(|| plan::run(&request)).map_err(error)?;
    let out = PyDict::new(py);
    for (key, scalar) in &results.results {
        out.set_item(key, scalar.value)?;
    }
    for (key, label) in &results.labels {
        out.set_item(key, &label.value)?;
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
            c.set_item("meaning", &check.meaning)?;
            checks.set_item(name, c)?;
        }
        out.set_item("checks", checks)?;
    }
    if !results.notes.is_empty() {
        out.set_item("notes", results.notes.clone())?;
    }
    Ok(out)
}

/// Points per parallel task.
const CHUNK: usize = 4096;

/// The sweep's axes in order: `n`, `a_over_ell`, then the `axes` dict's entries; all of one
/// length.
fn sweep_axes(
    n: Option<PyReadonlyArray1<'_, f64>>,
    a_over_ell: Option<PyReadonlyArray1<'_, f64>>,
    axes: Option<&Bound<'_, PyDict>>,
) -> PyResult<(Vec<String>, Vec<Vec<f64>>)> {
    let mut names = Vec::new();
    let mut columns: Vec<Vec<f64>> = Vec::new();
    for (name, values) in [("n", n), ("a_over_ell", a_over_ell)] {
        if let Some(v) = values {
            names.push(name.to_string());
            columns.push(v.as_array().to_vec());
        }
    }
    if let Some(dict) = axes {
        for (key, value) in dict.iter() {
            names.push(key.extract()?);
            columns.push(value.extract().map_err(|_| {
                error(format!("axis `{key}` must be a 1-D array or a sequence of numbers"))
            })?);
        }
    }
    let Some(first) = columns.first() else {
        return Err(error(
            "give the axes: n, a_over_ell, or axes={name: values} (a parameter or a ratio p_over_q)",
        ));
    };
    let len = first.len();
    if let Some((name, c)) = names.iter().zip(&columns).find(|(_, c)| c.len() != len) {
        return Err(error(format!(
            "axis `{}` has {len} values and `{name}` {}; they must have as many",
            names[0],
            c.len()
        )));
    }
    Ok((names, columns))
}

/// Separation angle and time over arrays of axis values (all of one length), in parallel with
/// the GIL released. Axes are `n = m2/m1`, `a_over_ell`, or any parameter or ratio `p_over_q`
/// of two parameters in `axes`; other parameters are 1 unless given as keywords. A point that
/// has no solution (no separation, refused values) is NaN in both arrays.
#[pyfunction]
#[pyo3(signature = (n=None, a_over_ell=None, model="rod_cube", axes=None, **fixed))]
fn sweep<'py>(
    py: Python<'py>,
    n: Option<PyReadonlyArray1<'py, f64>>,
    a_over_ell: Option<PyReadonlyArray1<'py, f64>>,
    model: &str,
    axes: Option<&Bound<'py, PyDict>>,
    fixed: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let m = find(model)?;
    LeanSolver::new(m).map_err(error)?;
    let (names, columns) = sweep_axes(n, a_over_ell, axes)?;
    let mut values: Vec<(String, f64)> = Vec::new();
    if let Some(dict) = fixed {
        for (key, value) in dict.iter() {
            let name: String = key.extract()?;
            let v = value
                .extract()
                .map_err(|_| error(format!("parameter `{name}` must be a number")))?;
            values.push((name, v));
        }
    }
    let axis_names: Vec<&str> = names.iter().map(String::as_str).collect();
    let fixed_ref: Vec<(&str, f64)> = values.iter().map(|(n, v)| (n.as_str(), *v)).collect();
    let mapping = Mapping::new(m.info(), &axis_names, &fixed_ref).map_err(error)?;
    let len = columns[0].len();
    let dims = columns.len();
    let points: Vec<f64> = (0..len)
        .flat_map(|k| columns.iter().map(move |c| c[k]))
        .collect();
    let mut angle = vec![f64::NAN; len];
    let mut time = vec![f64::NAN; len];
    py.detach(|| {
        (
            points.par_chunks(CHUNK * dims),
            angle.par_chunks_mut(CHUNK),
            time.par_chunks_mut(CHUNK),
        )
            .into_par_iter()
            .for_each(|(chunk, angles, times)| {
                let Ok(mut solver) = LeanSolver::new(m) else {
                    return;
                };
                let mut p = vec![0.0; m.info().parameters.len()];
                for (k, point) in chunk.chunks(dims).enumerate() {
                    mapping.fill(point, &mut p);
                    if let Ok(out) = solver.solve(&p) {
                        angles[k] = out.separation_angle;
                        times[k] = out.separation_time;
                    }
                }
            });
    });
    let out = PyDict::new(py);
    out.set_item("separation_angle", angle.into_pyarray(py))?;
    out.set_item("separation_time", time.into_pyarray(py))?;
    Ok(out)
}

/// The compiled half of the `rodcube` package.
#[pymodule]
fn _rodcube(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(models, m)?)?;
    m.add_function(wrap_pyfunction!(parameters, m)?)?;
    m.add_function(wrap_pyfunction!(solve, m)?)?;
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    m.add("RodcubeError", m.py().get_type::<RodcubeError>())?;
    Ok(())
}
