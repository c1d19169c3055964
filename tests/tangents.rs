//! `Model::tangents` and `Model::initial_tangents` of every generated model that has them,
//! against fourth-order central differences of the model's own functions (`equations`,
//! `constraints`, `friction`, `gaps`, `edges`, `initial_state`; a parameter step prepares the
//! constants again), at random parameters near each system's scene and random states near its
//! initial state. Also: every general model has tangents, and no fast phase has them.

mod common;

use common::numbers::Uniform;

use rodcube::model::{Model, TangentPoint};
use rodcube::scene::Scene;
use rodcube::system::Bound;
use std::collections::BTreeMap;
use std::path::Path;

/// Parameters for the systems no scene in `scenes/` uses.
const UNSCENED: &[(&str, &[(&str, f64)])] = &[(
    "loaded_rod",
    &[
        ("m1", 1.0),
        ("m2", 3.0),
        ("m3", 0.5),
        ("ell", 1.0),
        ("a", 0.25),
        ("g", 9.81),
    ],
)];

/// Points of parameters, and states at each, per model.
const POINTS: usize = 3;
const STATES: usize = 3;

/// The parameters of each system's scene (the first scene of any of its models, by name), and
/// those of [`UNSCENED`].
fn scene_parameters() -> BTreeMap<String, BTreeMap<String, f64>> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut paths: Vec<_> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{dir:?}: {e}"))
        .map(|e| e.unwrap_or_else(|e| panic!("{dir:?}: {e}")).path())
        .filter(|p| p.extension().is_some_and(|x| x == "yaml"))
        .collect();
    paths.sort();
    let mut out = BTreeMap::new();
    for path in paths {
        let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{path:?}: {e:?}"));
        (out.entry(scene.info().system.to_string())).or_insert_with(|| scene.parameter_map());
    }
    for (system, values) in UNSCENED {
        let map = values.iter().map(|(n, v)| (n.to_string(), *v)).collect();
        out.entry(system.to_string()).or_insert(map);
    }
    out
}

/// The rows `Model::tangents` differentiates, from the model's own functions.
struct Rows<'a> {
    model: &'a dyn Model,
    qdd: &'a [f64],
    forces: &'a [f64],
    fr: &'a [f64],
}

impl Rows<'_> {
    /// The rows at `q`, `qd` with constants `k`.
    fn at(&self, k: &[f64], q: &[f64], qd: &[f64]) -> Vec<f64> {
        let info = self.model.info();
        let (n, m, nf) = (q.len(), info.contacts.len(), info.frictions.len());
        let (mut mass, mut rhs) = (vec![0.0; n * n], vec![0.0; n]);
        self.model.equations(k, q, qd, &mut mass, &mut rhs);
        let (mut jac, mut bias) = (vec![0.0; m * n], vec![0.0; m]);
        self.model.constraints(k, q, qd, &mut jac, &mut bias);
        let (mut tjac, mut tbias) = (vec![0.0; nf * n], vec![0.0; nf]);
        self.model.friction(k, q, qd, &mut tjac, &mut tbias);
        let (mut gaps, mut edges) = (vec![0.0; m], vec![0.0; m]);
        self.model.gaps(k, q, &mut gaps);
        self.model.edges(k, q, &mut edges);
        let dot = |row: &[f64], x: &[f64]| row.iter().zip(x).map(|(a, b)| a * b).sum::<f64>();
        let mut out = Vec::new();
        for i in 0..n {
            let contacts: f64 = (0..m).map(|c| jac[c * n + i] * self.forces[c]).sum();
            let slips: f64 = (0..nf).map(|f| tjac[f * n + i] * self.fr[f]).sum();
            out.push(dot(&mass[i * n..][..n], self.qdd) - rhs[i] - contacts - slips);
        }
        out.extend((0..m).map(|c| dot(&jac[c * n..][..n], self.qdd) + bias[c]));
        out.extend((0..nf).map(|f| dot(&tjac[f * n..][..n], self.qdd) + tbias[f]));
        out.extend(gaps);
        out.extend((0..m).map(|c| if info.contacts[c].edge { edges[c] } else { 0.0 }));
        out.extend((0..nf).map(|f| dot(&tjac[f * n..][..n], qd)));
        out
    }
}

/// Fourth-order central difference of `f` at `x` with step `h`, entry by entry.
fn central(h: f64, f: &mut dyn FnMut(f64) -> Vec<f64>) -> Vec<f64> {
    let (a, b, c, d) = (f(-2.0 * h), f(-h), f(h), f(2.0 * h));
    (0..a.len())
        .map(|i| (a[i] - 8.0 * b[i] + 8.0 * c[i] - d[i]) / (12.0 * h))
        .collect()
}

/// The step for a variable of value `x`.
fn step(x: f64) -> f64 {
    1e-4 * x.abs().max(0.1)
}

/// Asserts that `got` (row-major, `columns` per row) matches `want` (column by column), each
/// entry within `1e-6` of the magnitudes of both and of its row's values `values`.
fn compare(what: &str, got: &[f64], want: &[Vec<f64>], values: &[f64], columns: usize) {
    let mut worst = (0.0, String::new());
    for (col, fd) in want.iter().enumerate() {
        for (row, (&d, &v)) in fd.iter().zip(values).enumerate() {
            let a = got[row * columns + col];
            assert!(a.is_finite(), "{what}: entry ({row}, {col}) is {a}");
            let tol = 1e-6 * (a.abs() + d.abs()) + 1e-8 * (1.0 + v.abs());
            let ratio = (a - d).abs() / tol;
            if ratio > worst.0 {
                worst = (
                    ratio,
                    format!("({row}, {col}): tangent {a}, difference {d}"),
                );
            }
        }
    }
    assert!(worst.0 <= 1.0, "{what}: worst entry {}", worst.1);
}

/// A random parameter point near `base` that the model accepts.
fn parameters<'m>(
    model: &'m dyn Model,
    base: &BTreeMap<String, f64>,
    rng: &mut Uniform,
) -> Bound<'m> {
    let info = model.info();
    for _ in 0..100 {
        let p: Vec<f64> = (info.parameters.iter())
            .map(|p| {
                let value = base.get(p.name).copied();
                let value = value.unwrap_or_else(|| panic!("{}: no `{}`", info.name, p.name));
                value * rng.between(0.95, 1.05)
            })
            .collect();
        if let Ok(bound) = Bound::from_values(model, &p) {
            return bound;
        }
    }
    panic!("{}: no accepted parameters near {base:?}", info.name)
}

/// Checks `model`'s tangents and initial tangents at one parameter point.
fn check_point(model: &dyn Model, bound: &Bound, rng: &mut Uniform) {
    let info = model.info();
    let (n, m, nf, np) = (
        info.coordinates.len(),
        info.contacts.len(),
        info.frictions.len(),
        info.parameters.len(),
    );
    let (p, k) = (bound.p(), bound.k());
    let tangents = (model.tangents()).unwrap_or_else(|| panic!("{}: no tangents", info.name));
    let prepared = |p: &[f64]| {
        let mut k = vec![0.0; info.n_constants];
        model.prepare(p, &mut k);
        k
    };
    let moved = |x: &[f64], i: usize, by: f64| {
        let mut x = x.to_vec();
        x[i] += by;
        x
    };

    // The initial state's tangents over the parameters.
    let (mut q0, mut qd0) = (vec![0.0; n], vec![0.0; n]);
    model.initial_state(k, &mut q0, &mut qd0);
    let mut got = vec![f64::NAN; 2 * n * np];
    tangents.initial_tangents(k, &mut got);
    let want: Vec<Vec<f64>> = (0..np)
        .map(|j| {
            central(step(p[j]), &mut |by| {
                let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
                model.initial_state(&prepared(&moved(p, j, by)), &mut q, &mut qd);
                q.into_iter().chain(qd).collect()
            })
        })
        .collect();
    let values: Vec<f64> = q0.iter().chain(&qd0).copied().collect();
    compare(&format!("{} initial", info.name), &got, &want, &values, np);

    for s in 0..STATES {
        let q: Vec<f64> = q0.iter().map(|x| x + rng.between(-0.05, 0.05)).collect();
        let qd: Vec<f64> = (0..n).map(|_| rng.between(-1.0, 1.0)).collect();
        let qdd: Vec<f64> = (0..n).map(|_| rng.between(-5.0, 5.0)).collect();
        let forces: Vec<f64> = (0..m).map(|_| rng.between(-10.0, 10.0)).collect();
        let fr: Vec<f64> = (0..nf).map(|_| rng.between(-3.0, 3.0)).collect();
        let rows = Rows {
            model,
            qdd: &qdd,
            forces: &forces,
            fr: &fr,
        };
        let columns = 2 * n + np;
        let mut got = vec![f64::NAN; (n + 3 * m + 2 * nf) * columns];
        let at = TangentPoint {
            q: &q,
            qd: &qd,
            qdd: &qdd,
            forces: &forces,
            friction: &fr,
        };
        tangents.tangent_rows(k, &at, &mut got);
        let mut want: Vec<Vec<f64>> = Vec::new();
        for i in 0..n {
            want.push(central(step(q[i]), &mut |by| {
                rows.at(k, &moved(&q, i, by), &qd)
            }));
        }
        for i in 0..n {
            want.push(central(step(qd[i]), &mut |by| {
                rows.at(k, &q, &moved(&qd, i, by))
            }));
        }
        for j in 0..np {
            let mut f = |by| rows.at(&prepared(&moved(p, j, by)), &q, &qd);
            want.push(central(step(p[j]), &mut f));
        }
        let what = format!("{} state {s} at p = {p:?}", info.name);
        compare(&what, &got, &want, &rows.at(k, &q, &qd), columns);
    }
}

#[test]
fn every_general_model_has_tangents_and_no_fast_phase_has() {
    for model in rodcube::models::all() {
        let info = model.info();
        assert_eq!(
            model.tangents().is_some(),
            info.is_general(),
            "{}: tangents() must be there exactly for its system's general model",
            info.name
        );
    }
}

#[test]
fn tangents_match_central_differences_of_the_models_functions() {
    let scenes = scene_parameters();
    let mut rng = Uniform(0x9E37_79B9_7F4A_7C15);
    let mut checked = 0;
    for model in rodcube::models::all()
        .iter()
        .filter(|m| m.tangents().is_some())
    {
        let info = model.info();
        let base = (scenes.get(info.system))
            .unwrap_or_else(|| panic!("{}: no scene and no parameters in UNSCENED", info.name));
        for _ in 0..POINTS {
            let bound = parameters(*model, base, &mut rng);
            check_point(*model, &bound, &mut rng);
        }
        checked += 1;
    }
    assert!(checked >= 13, "only {checked} models have tangents");
}
