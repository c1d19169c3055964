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

/// How a sweep point's `(n, a/ell)` become a model's parameters: `m2 = n m1`,
/// `a = (a/ell) ell`, the others fixed.
struct Mapping {
    base: Vec<f64>,
    m1: usize,
    m2: usize,
    ell: usize,
    a: usize,
}

impl Mapping {
    fn new(m: &dyn Model, fixed: Option<&Bound<'_, PyDict>>) -> PyResult<Mapping> {
        let info = m.info();
        let index = |name: &str| {
            info.parameters
                .iter()
                .position(|p| p.name == name)
                .ok_or_else(|| {
                    error(format!(
                        "a sweep over n = m2/m1 and a/ell needs the parameters m1, m2, ell and a; \
                         model `{}` has no `{name}`",
                        info.name
                    ))
                })
        };
        let (m1, m2, ell, a) = (index("m1")?, index("m2")?, index("ell")?, index("a")?);
        // Dimensionless by default: m1 = ell = g = 1, every other parameter given.
        let mut base: Vec<Option<f64>> = info.parameters.iter().map(|_| None).collect();
        for name in ["m1", "ell", "g"] {
            if let Some(i) = info.parameters.iter().position(|p| p.name == name) {
                base[i] = Some(1.0);
            }
        }
        if let Some(dict) = fixed {
            for (key, value) in dict.iter() {
                let name: String = key.extract()?;
                let i = index(&name)?;
                if i == m2 || i == a {
                    return Err(error(format!(
                        "`{name}` is set by the sweep's n and a_over_ell"
                    )));
                }
                base[i] = Some(
                    value
                        .extract()
                        .map_err(|_| error(format!("parameter `{name}` must be a number")))?,
                );
            }
        }
        let mut values = Vec::with_capacity(base.len());
        for (i, v) in base.iter().enumerate() {
            match v {
                Some(v) => values.push(*v),
                None if i == m2 || i == a => values.push(0.0),
                None => {
                    return Err(error(format!(
                        "model `{}` needs parameter `{}` fixed for the sweep",
                        info.name, info.parameters[i].name
                    )));
                }
            }
        }
        Ok(Mapping {
            base: values,
            m1,
            m2,
            ell,
            a,
        })
    }

    fn point(&self, p: &mut [f64], n: f64, a_over_ell: f64) {
        p[self.m2] = n * p[self.m1];
        p[self.a] = a_over_ell * p[self.ell];
    }
}

/// Points per parallel task.
const CHUNK: usize = 4096;

/// Separation angle and time over arrays of `n = m2/m1` and `a/ell` (same length), in
/// parallel with the GIL released. Other parameters are `m1 = ell = g = 1` unless given; a
/// point that has no solution (no separation, refused values) is NaN in both arrays.
#[pyfunction]
#[pyo3(signature = (n, a_over_ell, model="rod_cube", **fixed))]
fn sweep<'py>(
    py: Python<'py>,
    n: PyReadonlyArray1<'py, f64>,
    a_over_ell: PyReadonlyArray1<'py, f64>,
    model: &str,
    fixed: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let m = find(model)?;
    LeanSolver::new(m).map_err(error)?;
    let mapping = Mapping::new(m, fixed)?;
    let ns = n.as_array();
    let rs = a_over_ell.as_array();
    if ns.len() != rs.len() {
        return Err(error(format!(
            "n has {} values and a_over_ell {}; they must have as many",
            ns.len(),
            rs.len()
        )));
    }
    let points: Vec<(f64, f64)> = ns.iter().copied().zip(rs.iter().copied()).collect();
    let mut angle = vec![f64::NAN; points.len()];
    let mut time = vec![f64::NAN; points.len()];
    py.detach(|| {
        (
            points.par_chunks(CHUNK),
            angle.par_chunks_mut(CHUNK),
            time.par_chunks_mut(CHUNK),
        )
            .into_par_iter()
            .for_each(|(chunk, angles, times)| {
                let Ok(mut solver) = LeanSolver::new(m) else {
                    return;
                };
                let mut p = mapping.base.clone();
                for (k, &(n, r)) in chunk.iter().enumerate() {
                    mapping.point(&mut p, n, r);
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
