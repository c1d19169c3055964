//! Sweep axes for any model: how the coordinates of a sweep's points, named by the model's own
//! parameters (`m2`, `R`) or by ratios of two of them (`a_over_ell`, and `n` for `m2_over_m1`),
//! become its parameter vector. The command line's `rodcube sweep` and the Python package's
//! `sweep` both use it. Every parameter takes its value from an axis or from a value given:
//! none is assumed, a parameter that nothing sets is [`AxisError::Missing`].

use crate::model::{ModelInfo, ParamInfo};

/// What one axis sets.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// A parameter (index into [`ModelInfo::parameters`]) takes the axis value.
    Parameter(usize),
    /// `numerator = value * denominator` (indices into [`ModelInfo::parameters`]): the axis is
    /// the dimensionless ratio of two parameters of the same unit.
    Ratio {
        /// The parameter set from the ratio.
        numerator: usize,
        /// The parameter it is measured against (fixed, or set by a parameter axis).
        denominator: usize,
    },
}

/// Why axes or fixed values do not fit a model.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AxisError {
    /// A name that is neither a parameter nor a ratio of two.
    #[error(
        "model `{model}` has no parameter or ratio `{name}`; an axis is a parameter ({parameters}), a ratio `p_over_q` of two of them{mass_ratio}"
    )]
    Unknown {
        /// Model name.
        model: &'static str,
        /// The name given.
        name: String,
        /// The model's parameters, comma-separated.
        parameters: String,
        /// `, or n = m2/m1` where the model has both masses.
        mass_ratio: &'static str,
    },
    /// A ratio of parameters with different units.
    #[error(
        "`{name}` is not dimensionless: `{numerator}` is in {numerator_unit} and `{denominator}` in {denominator_unit}"
    )]
    Units {
        /// The ratio's name.
        name: String,
        /// Its numerator.
        numerator: &'static str,
        /// The numerator's unit.
        numerator_unit: &'static str,
        /// Its denominator.
        denominator: &'static str,
        /// The denominator's unit.
        denominator_unit: &'static str,
    },
    /// A parameter set by two axes, or by an axis and a fixed value.
    #[error("parameter `{parameter}` is set twice: by {first} and by {second}")]
    SetTwice {
        /// The parameter.
        parameter: &'static str,
        /// What set it first.
        first: String,
        /// What set it again.
        second: String,
    },
    /// A ratio measured against a parameter that is itself set by a ratio.
    #[error(
        "`{name}` is measured against `{denominator}`, which the ratio `{other}` sets; give `{denominator}` a value or a parameter axis"
    )]
    Chained {
        /// The ratio.
        name: String,
        /// Its denominator.
        denominator: &'static str,
        /// The ratio that sets the denominator.
        other: String,
    },
    /// A fixed value for a name that is not a parameter.
    #[error("model `{model}` has no parameter `{name}` to set; its parameters are {parameters}")]
    NotAParameter {
        /// Model name.
        model: &'static str,
        /// The name given.
        name: String,
        /// The model's parameters, comma-separated.
        parameters: String,
    },
    /// A fixed value that is not a finite number.
    #[error("`{name}` = {value} is not a finite number")]
    NotFinite {
        /// The parameter.
        name: &'static str,
        /// The value.
        value: f64,
    },
    /// Parameters that neither an axis nor a value sets (no value is ever assumed).
    #[error("{}", missing_text(model, unset))]
    Missing {
        /// Model name.
        model: &'static str,
        /// Each parameter without a value, in the model's order.
        unset: Vec<Unset>,
    },
}

/// A parameter that neither an axis nor a value sets.
#[derive(Debug, Clone, PartialEq)]
pub struct Unset {
    /// The parameter (its name, unit and meaning).
    pub parameter: ParamInfo,
    /// The ratio axes measured against it (`a_over_ell` against `ell`).
    pub against: Vec<String>,
}

/// `model `rod_cube`: no value for 2 parameters (rodcube assumes none):`, then one line per
/// parameter with its unit, its meaning and the ratio axes measured against it.
fn missing_text(model: &str, unset: &[Unset]) -> String {
    let mut text = format!(
        "model `{model}`: no value for {} parameter{} (rodcube assumes none):",
        unset.len(),
        if unset.len() == 1 { "" } else { "s" }
    );
    for u in unset {
        let p = &u.parameter;
        text.push_str(&format!("\n  {} [{}]: {}", p.name, p.unit, p.meaning));
        if !u.against.is_empty() {
            let axes: Vec<String> = u.against.iter().map(|a| format!("`{a}`")).collect();
            text.push_str(&format!(
                "; the axis {} is measured against it",
                axes.join(", ")
            ));
        }
    }
    text
}

/// Where each parameter's value comes from.
#[derive(Debug, Clone, PartialEq)]
enum Source {
    /// A value given.
    Fixed(f64),
    /// Axis `k`.
    Axis(usize),
}

/// How a sweep's points become parameter vectors for one model.
#[derive(Debug, Clone)]
pub struct Mapping {
    info: &'static ModelInfo,
    names: Vec<String>,
    targets: Vec<Target>,
    sources: Vec<Source>,
    base: Vec<f64>,
}

/// The ratio name `n` stands for, where the model has both masses.
const MASS_RATIO: (&str, &str, &str) = ("n", "m2", "m1");

/// Resolves an axis name against a model: a parameter, `p_over_q`, or `n` (`m2_over_m1`).
pub fn resolve(name: &str, info: &'static ModelInfo) -> Result<Target, AxisError> {
    let index = |p: &str| info.parameters.iter().position(|q| q.name == p);
    if let Some(i) = index(name) {
        return Ok(Target::Parameter(i));
    }
    let ratio = if name == MASS_RATIO.0 {
        index(MASS_RATIO.1).zip(index(MASS_RATIO.2))
    } else {
        // Every split at `_over_`: parameter names may contain underscores.
        name.match_indices("_over_")
            .find_map(|(at, sep)| index(&name[..at]).zip(index(&name[at + sep.len()..])))
    };
    let Some((numerator, denominator)) = ratio.filter(|(n, d)| n != d) else {
        let has_masses = index(MASS_RATIO.1).is_some() && index(MASS_RATIO.2).is_some();
        return Err(AxisError::Unknown {
            model: info.name,
            name: name.to_string(),
            parameters: parameter_list(info),
            mass_ratio: if has_masses { ", or n = m2/m1" } else { "" },
        });
    };
    let (pn, pd) = (&info.parameters[numerator], &info.parameters[denominator]);
    if pn.unit != pd.unit {
        return Err(AxisError::Units {
            name: name.to_string(),
            numerator: pn.name,
            numerator_unit: pn.unit,
            denominator: pd.name,
            denominator_unit: pd.unit,
        });
    }
    Ok(Target::Ratio {
        numerator,
        denominator,
    })
}

/// The model's parameter names, comma-separated.
fn parameter_list(info: &ModelInfo) -> String {
    info.parameters
        .iter()
        .map(|p| p.name)
        .collect::<Vec<_>>()
        .join(", ")
}

impl Mapping {
    /// Axes by name (in the order of a point's coordinates) and fixed values by parameter
    /// name. Every parameter needs one or the other: the others are [`AxisError::Missing`],
    /// checked after everything else, so its list is complete when nothing else is wrong.
    pub fn new(
        info: &'static ModelInfo,
        axes: &[&str],
        fixed: &[(&str, f64)],
    ) -> Result<Mapping, AxisError> {
        let np = info.parameters.len();
        let mut setter: Vec<Option<String>> = vec![None; np];
        let mut claim = |i: usize, by: String| match &setter[i] {
            Some(first) => Err(AxisError::SetTwice {
                parameter: info.parameters[i].name,
                first: first.clone(),
                second: by,
            }),
            None => {
                setter[i] = Some(by);
                Ok(())
            }
        };
        let mut sources: Vec<Option<Source>> = vec![None; np];
        let mut targets = Vec::with_capacity(axes.len());
        for (k, name) in axes.iter().enumerate() {
            let target = resolve(name, info)?;
            let set = match target {
                Target::Parameter(i) | Target::Ratio { numerator: i, .. } => i,
            };
            claim(set, format!("the axis `{name}`"))?;
            sources[set] = Some(Source::Axis(k));
            targets.push(target);
        }
        for &(name, value) in fixed {
            let Some(i) = info.parameters.iter().position(|p| p.name == name) else {
                return Err(AxisError::NotAParameter {
                    model: info.name,
                    name: name.to_string(),
                    parameters: parameter_list(info),
                });
            };
            if !value.is_finite() {
                return Err(AxisError::NotFinite {
                    name: info.parameters[i].name,
                    value,
                });
            }
            claim(i, format!("the value `{name} = {value}`"))?;
            sources[i] = Some(Source::Fixed(value));
        }
        for (k, target) in targets.iter().enumerate() {
            if let Target::Ratio { denominator, .. } = *target
                && let Some(Source::Axis(j)) = sources[denominator]
                && matches!(targets[j], Target::Ratio { .. })
            {
                return Err(AxisError::Chained {
                    name: axes[k].to_string(),
                    denominator: info.parameters[denominator].name,
                    other: axes[j].to_string(),
                });
            }
        }
        let sources = complete(info, axes, &targets, sources)?;
        let base = sources
            .iter()
            .map(|s| match s {
                Source::Fixed(value) => *value,
                Source::Axis(_) => f64::NAN,
            })
            .collect();
        Ok(Mapping {
            info,
            names: axes.iter().map(|s| s.to_string()).collect(),
            targets,
            sources,
            base,
        })
    }

    /// The model.
    pub fn info(&self) -> &'static ModelInfo {
        self.info
    }

    /// The axes' names, in the order of a point's coordinates.
    pub fn axis_names(&self) -> &[String] {
        &self.names
    }

    /// Fills the parameter vector `p` (one entry per parameter) for a point with one
    /// coordinate per axis: parameter axes first, then ratios against the values set.
    pub fn fill(&self, point: &[f64], p: &mut [f64]) {
        p.copy_from_slice(&self.base);
        for (target, &v) in self.targets.iter().zip(point) {
            if let Target::Parameter(i) = *target {
                p[i] = v;
            }
        }
        for (target, &v) in self.targets.iter().zip(point) {
            if let Target::Ratio {
                numerator,
                denominator,
            } = *target
            {
                p[numerator] = v * p[denominator];
            }
        }
    }

    /// One line saying how every parameter is set: `m1 = 1, m2 = n * m1, ell = 1,
    /// a = a_over_ell * ell, g = 9.81`.
    pub fn describe(&self) -> String {
        let parts: Vec<String> = self
            .info
            .parameters
            .iter()
            .zip(&self.sources)
            .map(|(p, s)| match s {
                Source::Fixed(value) => format!("{} = {value}", p.name),
                Source::Axis(k) => match self.targets[*k] {
                    Target::Parameter(_) => format!("{} = {}", p.name, self.names[*k]),
                    Target::Ratio { denominator, .. } => format!(
                        "{} = {} * {}",
                        p.name, self.names[*k], self.info.parameters[denominator].name
                    ),
                },
            })
            .collect();
        parts.join(", ")
    }
}

/// Every parameter's source, or [`AxisError::Missing`] naming those without one.
fn complete(
    info: &'static ModelInfo,
    axes: &[&str],
    targets: &[Target],
    sources: Vec<Option<Source>>,
) -> Result<Vec<Source>, AxisError> {
    let unset: Vec<Unset> = (info.parameters.iter().enumerate())
        .filter(|&(i, _)| sources[i].is_none())
        .map(|(i, p)| Unset {
            parameter: *p,
            against: (axes.iter().zip(targets))
                .filter(
                    |(_, t)| matches!(t, Target::Ratio { denominator, .. } if *denominator == i),
                )
                .map(|(name, _)| name.to_string())
                .collect(),
        })
        .collect();
    if !unset.is_empty() {
        return Err(AxisError::Missing {
            model: info.name,
            unset,
        });
    }
    Ok(sources.into_iter().flatten().collect())
}
