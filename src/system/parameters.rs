//! The one validation of a parameter set, used by [`Bound`](super::Bound), the per-point
//! solver and the scene loader alike: names to positions, each value, the requirements, the
//! restitutions and the prepared constants.

use super::SystemError;
use crate::model::{Model, ModelInfo, parameters_pass};
use std::fmt::Write as _;

/// Named parameter values (any order, each exactly once) put into `out` in the model's order
/// (`out` holds one entry per parameter): the one place names become positions, for
/// [`Bound`](super::Bound), the per-point solver and the C interface.
pub fn ordered_values<S: AsRef<str>>(
    info: &'static ModelInfo,
    params: &[(S, f64)],
    out: &mut [f64],
) -> Result<(), SystemError> {
    let n = info.parameters.len();
    if out.len() != n {
        return Err(SystemError::WrongCount {
            model: info.name,
            expected: n,
            got: out.len(),
        });
    }
    let mut seen = vec![false; n];
    for (name, value) in params {
        let name = name.as_ref();
        let Some(i) = info.parameters.iter().position(|p| p.name == name) else {
            return Err(SystemError::UnknownParameter {
                model: info.name,
                name: name.to_string(),
                value: *value,
                known: info
                    .parameters
                    .iter()
                    .map(|p| p.name)
                    .collect::<Vec<_>>()
                    .join(", "),
            });
        };
        if seen[i] {
            return Err(SystemError::DuplicateParameter {
                model: info.name,
                name: name.to_string(),
                first: out[i],
                second: *value,
            });
        }
        seen[i] = true;
        out[i] = *value;
    }
    match seen.iter().position(|s| !s) {
        Some(i) => Err(SystemError::MissingParameter {
            model: info.name,
            name: info.parameters[i].name,
        }),
        None => Ok(()),
    }
}

/// The one check of a single parameter value (index `i` of [`ModelInfo::parameters`]): finite,
/// positive where declared so, and not negative when it is a coefficient of friction.
/// [`check_parameters`], the per-point solver and the scene loader all use it.
pub fn check_value(info: &'static ModelInfo, i: usize, value: f64) -> Result<(), SystemError> {
    let Some(param) = info.parameters.get(i) else {
        return Err(SystemError::WrongCount {
            model: info.name,
            expected: info.parameters.len(),
            got: i + 1,
        });
    };
    let model = info.name;
    let name = param.name;
    if !value.is_finite() {
        return Err(SystemError::NotFinite { model, name, value });
    }
    if value < 0.0
        && let Some(f) = info.frictions.iter().find(|f| f.coefficient_index == i)
    {
        return Err(SystemError::NegativeFriction {
            model,
            name,
            friction: f.name,
            value,
        });
    }
    if param.positive && value <= 0.0 {
        return Err(SystemError::NotPositive { model, name, value });
    }
    Ok(())
}

/// The requirements of [`ModelInfo::requirements`] that `p` fails, with their margins
/// (`margins` is scratch of one entry per requirement; `p` must hold finite values, one per
/// parameter). Counts that are not the model's are an error, not a verdict.
pub fn failed_requirements<'a>(
    model: &dyn Model,
    p: &[f64],
    margins: &'a mut [f64],
) -> Result<impl Iterator<Item = (&'static crate::model::RequirementInfo, f64)> + 'a, SystemError> {
    let info = model.info();
    check_count(info, p)?;
    if margins.len() != info.requirements.len() {
        return Err(SystemError::Length {
            model: info.name,
            what: "margins",
            expected: info.requirements.len(),
            got: margins.len(),
        });
    }
    model.requirements(p, margins);
    Ok(info
        .requirements
        .iter()
        .zip(margins.iter())
        .filter(|(_, m)| m.is_nan() || **m <= 0.0)
        .map(|(r, m)| (r, *m)))
}

/// `p` holds one value per parameter of the model, or [`SystemError::WrongCount`].
fn check_count(info: &'static ModelInfo, p: &[f64]) -> Result<(), SystemError> {
    if p.len() == info.parameters.len() {
        Ok(())
    } else {
        Err(SystemError::WrongCount {
            model: info.name,
            expected: info.parameters.len(),
            got: p.len(),
        })
    }
}

/// Each contact's coefficient of restitution for parameters `p` that passed
/// [`check_parameters`] ([`Model::restitutions`]), every one checked to lie in `[0, 1]`.
pub fn restitutions(model: &dyn Model, p: &[f64]) -> Result<Vec<f64>, SystemError> {
    let info = model.info();
    check_count(info, p)?;
    let mut out = vec![0.0; info.contacts.len()];
    model.restitutions(p, &mut out);
    check_restitutions(info, &out, || describe(info, p))?;
    Ok(out)
}

/// The one check of coefficients of restitution (one per contact, each in `[0, 1]`);
/// `parameters` says where they came from, for the message.
pub fn check_restitutions(
    info: &ModelInfo,
    values: &[f64],
    parameters: impl FnOnce() -> String,
) -> Result<(), SystemError> {
    match (info.contacts.iter().zip(values)).find(|(_, e)| !(0.0..=1.0).contains(*e)) {
        Some((c, &value)) => Err(SystemError::Restitution {
            model: info.name,
            contact: c.name,
            value,
            parameters: parameters(),
        }),
        None => Ok(()),
    }
}

/// The one validation of a model's parameter values, in the order of
/// [`ModelInfo::parameters`]: their count, each value ([`check_value`]) and the model's
/// requirements (`margins`: scratch of one entry per requirement). Used by
/// [`Bound`](super::Bound) and by the per-point solver, so both refuse exactly the same
/// points.
pub fn check_parameters(
    model: &dyn Model,
    p: &[f64],
    margins: &mut [f64],
) -> Result<(), SystemError> {
    // Finite and positive values pass every value check; the detailed checks and the messages
    // are out of line, on the rare path.
    if parameters_pass(model, p, margins) {
        return Ok(());
    }
    parameters_refused(model, p, margins)
}

/// [`check_parameters`]' verdict on parameters that did not pass its quick tests: the first
/// failure by name, or `Ok` (a value that is zero or negative where that is allowed).
#[cold]
#[inline(never)]
fn parameters_refused(
    model: &dyn Model,
    p: &[f64],
    margins: &mut [f64],
) -> Result<(), SystemError> {
    let info = model.info();
    if p.len() != info.parameters.len() || margins.len() != info.requirements.len() {
        return Err(SystemError::WrongCount {
            model: info.name,
            expected: info.parameters.len(),
            got: p.len(),
        });
    }
    for (i, &value) in p.iter().enumerate() {
        check_value(info, i, value)?;
    }
    if let Some((req, margin)) = failed_requirements(model, p, margins)?.next() {
        return Err(SystemError::Requirement {
            model: info.name,
            name: req.name,
            meaning: req.meaning,
            margin,
            parameters: describe(info, p),
        });
    }
    Ok(())
}

/// Prepares the model's constants `k` (of length [`ModelInfo::n_constants`]) from checked
/// parameters and refuses any that is not finite.
pub fn prepare_constants(model: &dyn Model, p: &[f64], k: &mut [f64]) -> Result<(), SystemError> {
    let info = model.info();
    check_count(info, p)?;
    if k.len() != info.n_constants {
        return Err(SystemError::Length {
            model: info.name,
            what: "k",
            expected: info.n_constants,
            got: k.len(),
        });
    }
    model.prepare(p, k);
    // A branch-free scan first (it vectorises); the index only on failure.
    if k.iter().fold(true, |ok, v| ok & (v.abs() < f64::INFINITY)) {
        return Ok(());
    }
    match k.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        Some((index, &value)) => Err(SystemError::BadConstant {
            model: info.name,
            index,
            value,
            parameters: describe(info, p),
        }),
        None => Ok(()),
    }
}

/// `name = value` pairs for messages.
pub(super) fn describe(info: &ModelInfo, p: &[f64]) -> String {
    let mut out = String::new();
    for (i, (param, v)) in info.parameters.iter().zip(p).enumerate() {
        if i > 0 {
            out.push_str(", ");
        }
        let _ = write!(out, "{} = {v}", param.name);
    }
    out
}
