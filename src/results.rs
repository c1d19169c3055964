//! The results of a run: scalars, series, checks and the work done, ready for any report.

use serde::Serialize;
use std::collections::BTreeMap;

/// A scalar result with its unit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Scalar {
    /// Value in SI units (radians for angles).
    pub value: f64,
    /// Unit (`rad`, `s`, `N`, `m/s`, ...).
    pub unit: &'static str,
    /// What it is, for people.
    pub meaning: String,
}

/// A result that is a word rather than a number (e.g. why a contact ended).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Label {
    /// The word.
    pub value: String,
    /// What it is and which words it can be.
    pub meaning: String,
}

/// One column of a series.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Column {
    /// Column name (`t`, `theta`, `x`, ...).
    pub name: String,
    /// Unit of the values.
    pub unit: &'static str,
    /// The values, one per sample.
    pub values: Vec<f64>,
}

/// A table of samples that share their first column (usually time).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Series {
    /// Columns, all of the same length.
    pub columns: Vec<Column>,
}

/// A monitored assumption or conservation law.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Check {
    /// Whether it held.
    pub passed: bool,
    /// How much room was left (the smallest monitor value, or tolerance minus drift);
    /// negative when it failed.
    pub margin: f64,
    /// What was checked and against what.
    pub meaning: String,
}

/// What a run computed, to prove that a scene gets only what it asks for.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct Work {
    /// Evaluations of the separation polynomial (or its derivative).
    pub polynomial_evals: u64,
    /// Evaluations of a quadrature integrand.
    pub integrand_evals: u64,
    /// Accepted and rejected steps of any ODE integration.
    pub ode_steps: u64,
    /// Names of the phases simulated (`rod_cube`, `free_rod`, ...).
    pub phases: Vec<String>,
}

/// Everything one scene produced.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct RunResults {
    /// Model name.
    pub model: String,
    /// The parameters used, by name.
    pub parameters: BTreeMap<String, f64>,
    /// Scalar results by key.
    pub results: BTreeMap<String, Scalar>,
    /// Word-valued results by key (written under `results` in JSON, beside the scalars).
    #[serde(skip)]
    pub labels: BTreeMap<String, Label>,
    /// Series by quantity name (`theta_series`, `tip_trajectory`, ...).
    pub series: BTreeMap<String, Series>,
    /// Checks by name.
    pub checks: BTreeMap<String, Check>,
    /// Work counters.
    pub work: Work,
    /// Why a wanted quantity has no value, by its key (e.g. `separation_angle`: no separation
    /// before the floor). A quantity is either in `results`/`series` or explained here.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub notes: BTreeMap<String, String>,
}
