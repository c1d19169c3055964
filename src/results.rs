//! The results of a run: scalars, series, checks and the work done, ready for any report.

use crate::model::ModelInfo;
use crate::quantity::Quantity;
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

impl RunResults {
    /// A scalar result by its quantity (`None` when it was not wanted, or has no value: then
    /// [`RunResults::note`] says why). Only quantities that do not depend on the model's names
    /// are scalars: the separation angle and time, the linearised angle, the contact time to
    /// the floor and the point mass's fall time.
    pub fn scalar(&self, quantity: Quantity) -> Option<&Scalar> {
        self.results.get(quantity.fixed_name()?)
    }

    /// A scalar result by its key in `results` (`floor_impact_time`, say: the quantities that
    /// give several scalars name each).
    pub fn get(&self, key: &str) -> Option<&Scalar> {
        self.results.get(key)
    }

    /// A scalar's value by its quantity.
    pub fn value(&self, quantity: Quantity) -> Option<f64> {
        self.scalar(quantity).map(|s| s.value)
    }

    /// The separation angle (rad), if it was wanted and the contact ended by its force.
    pub fn separation_angle(&self) -> Option<f64> {
        self.value(Quantity::SeparationAngle)
    }

    /// The time from release to separation (s), if it was wanted and the contact ended.
    pub fn separation_time(&self) -> Option<f64> {
        self.value(Quantity::SeparationTime)
    }

    /// A series by its quantity, resolved against the model that made it (`None` when it was
    /// not wanted, has no samples, or the quantity is not the model's).
    pub fn series_of(&self, quantity: Quantity, info: &ModelInfo) -> Option<&Series> {
        if !quantity.available(info) || info.name != self.model {
            return None;
        }
        self.series.get(&quantity.name(info))
    }

    /// Why a wanted quantity has no value, if it has none.
    pub fn note(&self, quantity: Quantity, info: &ModelInfo) -> Option<&str> {
        self.notes.get(&quantity.name(info)).map(String::as_str)
    }
}

impl Series {
    /// A column by name (`t`, `theta`, ...).
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.columns
            .iter()
            .find(|c| c.name == name)
            .map(|c| c.values.as_slice())
    }
}
