//! Sweeps of any model and any of its scalar results through the planner: at every point the
//! wanted quantities' scalar results (`contact_end_time`, `floor_impact_time`, ...: the keys
//! of results.json), in parallel (rayon). The columns follow from the model and the wanted
//! quantities alone ([`Quantity::scalar_keys`]), never from the points, so that a sweep cut
//! into blocks (a cluster's) has the same columns in every block. The Python package's
//! `sweep(want=...)` runs it; `rodcube sweep --want` takes its quantities with [`wanted`] and
//! computes its extra columns with [`solve_point`], beside the separation.

use super::{CHUNK, Points, SweepError};
use crate::axes::Mapping;
use crate::model::{Model, ModelInfo};
use crate::plan::{self, Request};
use crate::quantity::{Quantity, ScalarKey};
use crate::report::prose;
use rayon::prelude::*;

/// The wanted quantities of a sweep and the scalar results they give, in order.
#[derive(Debug, Clone, PartialEq)]
pub struct Wanted {
    /// The quantities, without duplicates, in the order asked.
    pub quantities: Vec<Quantity>,
    /// Their scalar results: one column each, the quantities' in turn.
    pub columns: Vec<ScalarKey>,
}

impl Wanted {
    /// The columns of `quantities` (resolved, available, without duplicates).
    pub fn of(info: &ModelInfo, quantities: &[Quantity]) -> Wanted {
        Wanted {
            quantities: quantities.to_vec(),
            columns: (quantities.iter())
                .flat_map(|q| q.scalar_keys(info))
                .collect(),
        }
    }
}

/// The scalar quantities a model offers (those a sweep takes), by name.
pub fn scalar_quantities(model: &dyn Model) -> Vec<String> {
    let info = model.info();
    (Quantity::all(info).iter())
        .filter(|q| !q.scalar_keys(info).is_empty())
        .map(|q| q.name(info))
        .collect()
}

/// Resolves wanted names to quantities with scalar results: a name that is no quantity (a
/// result's key, say) or one that gives no number per point is refused with what to ask.
pub fn wanted(model: &dyn Model, names: &[String]) -> Result<Wanted, SweepError> {
    let info = model.info();
    let offers = || scalar_quantities(model).join(", ");
    if names.is_empty() {
        return Err(SweepError::Want(format!(
            "want at least one quantity; model `{}` offers: {}",
            info.name,
            offers()
        )));
    }
    let mut quantities = Vec::new();
    for name in names {
        let q = Quantity::parse(name, info).map_err(|e| {
            // A result's key rather than its quantity's name: say which quantity gives it.
            let of = (Quantity::all(info).into_iter())
                .find(|q| q.scalar_keys(info).iter().any(|k| k.key == *name));
            match of {
                Some(q) => SweepError::Want(format!(
                    "`{name}` is a result of the quantity `{}`: want that",
                    q.name(info)
                )),
                None => SweepError::UnknownQuantity(e),
            }
        })?;
        if !q.available(info) {
            return Err(SweepError::Want(format!(
                "model `{}` cannot provide `{name}`; it offers: {}",
                info.name,
                offers()
            )));
        }
        if q.scalar_keys(info).is_empty() {
            return Err(SweepError::Want(format!(
                "`{name}` is a series, a list or a set of checks, not a number per point; model `{}` sweeps: {}",
                info.name,
                offers()
            )));
        }
        if !quantities.contains(&q) {
            quantities.push(q);
        }
    }
    Ok(Wanted::of(info, &quantities))
}

/// How every point is solved.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// Relative tolerance of every result.
    pub tolerance: f64,
    /// The time (s from release) the motion goes on to through impacts; `None` ends it at its
    /// first landing.
    pub until: Option<f64>,
}

impl Settings {
    /// The request for one point.
    fn request<'m>(&self, model: &'m dyn Model, p: &[f64], want: &Wanted) -> Request<'m> {
        Request::new(model, p.to_vec())
            .with_want(&want.quantities)
            .with_tolerance(self.tolerance)
            .with_until(self.until)
    }
}

/// The results of a planned sweep, one row per point in the order given.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Planned {
    /// `Wanted::columns.len()` values per point, row after row; NaN where a point has none.
    pub values: Vec<f64>,
    /// Whether each point has a value of every wanted quantity ([`solve_point`]).
    pub ok: Vec<bool>,
    /// `(index, reason)` for every point that has not, in index order.
    pub errors: Vec<(usize, String)>,
}

/// One chunk's rows, mask and failures.
type ChunkRows = (Vec<f64>, Vec<bool>, Vec<(usize, String)>);

/// Solves every point through the planner in parallel (rayon). What does not depend on the point (the model is a system offering the quantities,
/// the tolerance, `until`) is checked once first; a point the model refuses or cannot solve
/// is NaN, `false` and its reason.
pub fn run(
    model: &'static dyn Model,
    mapping: &Mapping,
    points: &Points,
    want: &Wanted,
    settings: Settings,
) -> Result<Planned, SweepError> {
    let np = model.info().parameters.len();
    settings
        .request(model, &vec![0.0; np], want)
        .check()
        .map_err(|e| SweepError::Want(e.to_string()))?;
    let dims = points.names.len().max(1);
    let width = want.columns.len();
    let chunks: Vec<ChunkRows> = (points.values.par_chunks(CHUNK * dims).enumerate())
        .map(|(c, chunk)| {
            let n = chunk.len() / dims;
            let mut rows = vec![f64::NAN; n * width];
            let mut ok = vec![false; n];
            let mut errors = Vec::new();
            let mut p = vec![0.0; np];
            for (i, point) in chunk.chunks(dims).enumerate() {
                mapping.fill(point, &mut p);
                let row = &mut rows[i * width..(i + 1) * width];
                match solve_point(model, &p, want, settings, row) {
                    Ok(()) => ok[i] = true,
                    Err(e) => errors.push((c * CHUNK + i, e)),
                }
            }
            (rows, ok, errors)
        })
        .collect();
    let mut out = Planned::default();
    for (rows, ok, errors) in chunks {
        out.values.extend(rows);
        out.ok.extend(ok);
        out.errors.extend(errors);
    }
    Ok(out)
}

/// One point's wanted results into `row` (one value per column of `want`, left as they are
/// where there is none). An error where the planner fails or a wanted quantity has no value:
/// the planner's message, or the note of each quantity without one. A contact's own end that
/// has none (a floor contact that holds to the end) is no error: the quantity has its value.
pub fn solve_point(
    model: &dyn Model,
    p: &[f64],
    want: &Wanted,
    settings: Settings,
    row: &mut [f64],
) -> Result<(), String> {
    let results = plan::run(&settings.request(model, p, want)).map_err(|e| e.to_string())?;
    let mut missing: Vec<String> = Vec::new();
    for (column, value) in want.columns.iter().zip(row.iter_mut()) {
        match results.results.get(&column.key) {
            Some(scalar) => *value = scalar.value,
            None if column.per_contact => {}
            None => {
                let why = match results.notes.get(&column.note) {
                    Some(note) => format!("`{}`: {}", column.note, prose::note(note)),
                    None => format!("`{}`: no value", column.key),
                };
                if !missing.contains(&why) {
                    missing.push(why);
                }
            }
        }
    }
    if missing.is_empty() {
        Ok(())
    } else {
        Err(missing.join("; "))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::results::RunResults;
    use crate::scene::Scene;
    use std::collections::BTreeSet;

    /// Every scalar quantity of every shipped scene's model, run through the planner at the
    /// scene's point: the results it writes are exactly the declared columns, less those whose
    /// note says why they have none.
    #[test]
    fn every_shipped_scene_gives_exactly_the_declared_scalar_results() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
        let (mut scenes, mut solved) = (0, 0);
        for entry in std::fs::read_dir(&dir).expect("scenes/") {
            let path = entry.expect("a directory entry").path();
            let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            for name in scalar_quantities(scene.model) {
                let want = wanted(scene.model, &[name]).expect("wanted");
                let request = Request::new(scene.model, scene.parameters.clone())
                    .with_want(&want.quantities)
                    .with_tolerance(scene.tolerance)
                    .with_until(scene.until);
                // A quantity the scene's point cannot give (a quadrature that misses the
                // scene's tolerance, say) writes no result at all.
                if let Ok(results) = plan::run(&request) {
                    declared_and_given(&path, &want, &results);
                    solved += 1;
                }
            }
            scenes += 1;
        }
        assert!(scenes >= 10, "{scenes} scenes in {}", dir.display());
        assert!(
            solved >= 4 * scenes,
            "{solved} quantities solved in {scenes} scenes"
        );
    }

    /// The results are exactly `want`'s columns, less those whose note says why they have none.
    fn declared_and_given(path: &std::path::Path, want: &Wanted, results: &RunResults) {
        {
            let declared: BTreeSet<&str> = want.columns.iter().map(|c| c.key.as_str()).collect();
            for key in results.results.keys() {
                assert!(
                    declared.contains(key.as_str()),
                    "{path:?}: `{key}` undeclared"
                );
            }
            for column in &want.columns {
                assert!(
                    results.results.contains_key(&column.key)
                        || results.notes.contains_key(&column.note),
                    "{path:?}: `{}` neither given nor explained under `{}`",
                    column.key,
                    column.note
                );
                if let Some(s) = results.results.get(&column.key) {
                    assert_eq!(s.unit, column.unit, "{path:?}: `{}`", column.key);
                }
            }
        }
    }

    /// More points than a chunk, some refused: each row is the planner's at that point alone,
    /// in order, and each refused point is `false` with the planner's own message.
    #[test]
    fn a_sweep_over_chunks_is_its_points_solved_one_by_one() {
        let model = crate::models::find("rod_cube").expect("rod_cube is compiled in");
        let info = model.info();
        let fixed = [("m1", 1.0), ("ell", 1.0), ("a", 0.25), ("g", 9.81)];
        let mapping = Mapping::new(info, &["n"], &fixed).expect("mapping");
        let n = CHUNK + 7;
        let values: Vec<f64> = (0..n)
            .map(|k| match k {
                3 | 2050 => -1.0,
                _ => 0.5 + 8.0 * k as f64 / n as f64,
            })
            .collect();
        let points = Points {
            names: vec!["n".into()],
            values: values.clone(),
            lines: Vec::new(),
        };
        let names = ["contact_end".to_string(), "separation_time".to_string()];
        let want = wanted(model, &names).expect("wanted");
        let settings = Settings {
            tolerance: 1e-12,
            until: None,
        };
        let out = run(model, &mapping, &points, &want, settings).expect("the sweep runs");
        let width = want.columns.len();
        assert_eq!(out.values.len(), n * width);
        let failed: Vec<usize> = out.errors.iter().map(|e| e.0).take(4).collect();
        assert_eq!(failed, [3, 2050], "{:?}", out.errors.first());
        let mut p = vec![0.0; info.parameters.len()];
        for (k, v) in values.iter().enumerate() {
            mapping.fill(&[*v], &mut p);
            let request = Request::new(model, p.clone())
                .with_want(&want.quantities)
                .with_tolerance(1e-12);
            let row = &out.values[k * width..(k + 1) * width];
            match plan::run(&request) {
                Ok(results) => {
                    assert!(out.ok[k], "point {k}");
                    for (column, value) in want.columns.iter().zip(row) {
                        // NaN where a contact holds: none of its own end.
                        let expected =
                            (results.results.get(&column.key)).map_or(f64::NAN, |s| s.value);
                        assert!(expected.is_finite() || column.per_contact, "{}", column.key);
                        assert_eq!(value.to_bits(), expected.to_bits(), "{}", column.key);
                    }
                }
                Err(e) => {
                    assert!(!out.ok[k] && row.iter().all(|v| v.is_nan()), "point {k}");
                    let message = &out.errors.iter().find(|f| f.0 == k).expect("listed").1;
                    assert_eq!(*message, e.to_string());
                }
            }
        }
    }

    #[test]
    fn what_is_no_number_per_point_is_refused_with_what_to_ask() {
        let model = crate::models::find("rod_cube_friction").expect("compiled in");
        let ask = |name: &str| wanted(model, &[name.to_string()]).unwrap_err().to_string();
        let by_key = ask("contact_end_time");
        assert!(
            by_key.contains("result of the quantity `contact_end`"),
            "{by_key}"
        );
        let series = ask("theta_series");
        assert!(series.contains("not a number per point"), "{series}");
        assert!(series.contains("floor_impact"), "{series}");
        assert!(ask("speed").contains("unknown quantity `speed`"));
        let none = wanted(model, &[]).unwrap_err().to_string();
        assert!(none.contains("at least one"), "{none}");
        let w = wanted(model, &["contact_end".into(), "contact_end".into()]).expect("wanted");
        assert_eq!(w.quantities, [Quantity::ContactEnd]);
        assert!(
            w.columns
                .iter()
                .any(|c| c.key == "contact_end_friction_work")
        );
    }
}
