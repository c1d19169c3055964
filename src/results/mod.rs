//! The results of a run as plain data: scalars, series, checks, notes, the drawing of the
//! motion and the work done, ready for any report (which writes every sentence).

use crate::model::ModelInfo;
use crate::quantity::Quantity;
use serde::Serialize;
use std::collections::BTreeMap;

mod decisions;
mod drawing;
mod ends;
mod meanings;
mod notes;

pub use decisions::{ContactSet, Holding, Indeterminacy, Mode, Sign};
pub use drawing::{Drawing, DrawnPhase, DrawnSample, Pose};
pub use ends::{ContactId, EndCause};
pub use meanings::Meaning;
pub use notes::{
    CROSS_CHECK_APART, END_UNRESOLVED, Halt, Held, Note, SensitivityGap, TapeReason, Unlanded,
    UntilNote, Zeno,
};

/// A scalar result with its unit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Scalar {
    /// Value in SI units (radians for angles).
    pub value: f64,
    /// Unit (`rad`, `s`, `N`, `m/s`, ...).
    pub unit: &'static str,
    /// What it is (`report::prose::meaning` says it in words: results.json's `meaning`).
    #[serde(skip)]
    pub meaning: Meaning,
}

/// A result that is a word rather than a number (e.g. why a contact ended).
#[derive(Debug, Clone, PartialEq)]
pub struct Label {
    /// The word, or the words and times it is made of (`report::prose::label` writes it).
    pub value: LabelValue,
    /// What it is and which words it can be (`report::prose::meaning` says it in words).
    pub meaning: Meaning,
}

/// What a [`Label`] says.
#[derive(Debug, Clone, PartialEq)]
pub enum LabelValue {
    /// Why a contact ended (the report writes it as one word: `force`, `edge`, ...).
    Cause(EndCause),
    /// The active sets over a span, in order: each stretch's start and its closed contacts
    /// and friction modes in words.
    Stretches(Vec<Stretch>),
}

/// One stretch of a motion with one active set.
#[derive(Debug, Clone, PartialEq)]
pub struct Stretch {
    /// Its start (s from release).
    pub from: f64,
    /// Its closed contacts and friction modes.
    pub set: ContactSet,
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

/// What a [`Check`] tests.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CheckKind {
    /// A physical assumption of the model (a spec's `monitors`): its smallest value over the
    /// samples must stay `>= 0` (up to rounding). `value` is that smallest value, in `unit`.
    Monitor,
    /// A conservation law along a path that does not have it built in (an integrated phase,
    /// the ODE cross-check): the largest relative drift, `value`, must stay `<= limit`.
    Drift,
    /// A conservation law that the path has by construction (the reduced path takes
    /// `theta_dot` from the energy integral and the cyclic velocities from the conserved
    /// momenta): what is left to test is that the generated energy and momentum functions
    /// agree with the reduced motion, to rounding. `value` is the relative difference, which
    /// must stay `<= limit`.
    Identity,
}

/// A monitored assumption or conservation law.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Check {
    /// Whether it held.
    pub passed: bool,
    /// What is tested, and so how `value` and `limit` read.
    pub kind: CheckKind,
    /// The phase the check ran on (`report::prose::check_phase` names it: results.json's
    /// `phase`).
    #[serde(skip)]
    pub phase: CheckPhase,
    /// Position in the order the phases happen (the report sorts by it).
    pub order: usize,
    /// What was measured: a monitor's smallest value (in `unit`), or a relative drift.
    pub value: f64,
    /// The bound: `value >= limit` for a monitor (its limit is minus the rounding allowance,
    /// `-tolerance` times the monitor's scale along the motion), `value <= limit` otherwise.
    pub limit: f64,
    /// Unit of `value` and `margin` (`1` for relative drifts; empty when the spec gives none).
    pub unit: String,
    /// How much room was left, in `unit`: `value - limit` for a monitor, `limit - value` for a
    /// drift; negative when it failed.
    pub margin: f64,
    /// Time from release (s) where a monitor took its smallest value.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub at_time: Option<f64>,
    /// How many samples or states it looked at.
    pub samples: usize,
    /// What was checked, with the names and numbers its sentence gives (`report::prose`
    /// writes the sentence, results.json's `meaning`).
    #[serde(skip)]
    pub subject: CheckSubject,
}

/// Where a [`Check`] ran.
#[derive(Debug, Clone, PartialEq)]
pub enum CheckPhase {
    /// A phase of the motion, by its labels (`rod_cube`; for an integrated phase its model
    /// and each stretch's closed contacts, joined by ` then `).
    Phase(String),
    /// An impact: its number in the run (from 1) and its time (s from release).
    Impact {
        /// Its number, from 1.
        number: usize,
        /// Its time (s from release).
        t: f64,
    },
    /// The ODE cross-check: the system's general model integrated without reduction.
    OdeCrossCheck {
        /// The general model.
        model: String,
    },
}

/// What a [`Check`] is about: the quantity tested, named, with the numbers that scale it.
/// The check's own `samples`, `kind` and `limit` (the tolerance of a drift) complete it.
#[derive(Debug, Clone, PartialEq)]
pub enum CheckSubject {
    /// A spec's monitor over a phase's samples.
    Monitor {
        /// The model sampled.
        model: String,
        /// The monitor's name.
        monitor: String,
        /// The monitor's meaning, as its spec gives it.
        meaning: String,
    },
    /// A closed unilateral contact's force over a phase's samples.
    Pushes {
        /// The model sampled.
        model: String,
        /// The contact.
        contact: String,
    },
    /// The gap of a contact the integrator holds closed, relative to the system's length.
    Gap {
        /// The model integrated.
        model: String,
        /// The contact.
        contact: String,
        /// The system's length (m).
        length: f64,
    },
    /// The total energy along a path (with friction, the balance: energy lost = work of
    /// friction), beyond its rounding, relative to its scale.
    Energy {
        /// The model of the path.
        model: String,
        /// Whether it is the balance with the work of friction.
        friction: bool,
        /// What rounding alone leaves in the energy (J), not counted as drift.
        rounding: f64,
        /// The scale: the largest kinetic energy plus the potential's range (J).
        scale: f64,
    },
    /// A conserved combination of cyclic momenta along a path.
    Momentum {
        /// The model of the path.
        model: String,
        /// Its name (`momentum_x`, `momentum_x_x2`).
        name: String,
        /// The scale its drift is relative to.
        scale: f64,
    },
    /// The energy an impact took out: its impulses' loss against the drop of the total energy.
    Impact {
        /// The loss by the impulses (J).
        energy_lost: f64,
        /// The kinetic energy before (J), the scale.
        kinetic_before: f64,
    },
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
    /// Right-hand sides evaluated by any ODE integration.
    pub ode_evaluations: u64,
    /// Names of the phases simulated (`rod_cube`, `free_rod`, ...).
    pub phases: Vec<String>,
}

/// One contact's part in an impact.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ContactImpulse {
    /// The contact's name.
    pub contact: String,
    /// Its normal velocity before the impact (negative: approaching).
    pub normal_velocity_before: f64,
    /// Its normal velocity after (zero: it stays closed; positive: it separates).
    pub normal_velocity_after: f64,
    /// The impulse it took (`>= 0` for a unilateral contact).
    pub impulse: f64,
    /// The tangential impulse of its friction (zero without one, or where it does not act),
    /// positive along its slip direction.
    pub tangential_impulse: f64,
    /// The unit of the normal velocities (`m/s`, or `rad/s` for an angular gap).
    pub velocity_unit: &'static str,
    /// The unit of the impulse (`N s`, or `N m s`).
    pub impulse_unit: &'static str,
}

/// An impact: where a contact closed with an approach velocity, the impulses at every contact
/// that took part and the kinetic energy they took out.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ImpactRecord {
    /// Time from release (s); for the impact that closed a converging (Zeno) sequence of
    /// bounces, the sequence's accumulation time.
    pub time: f64,
    /// The contact whose gap closed.
    pub closing: String,
    /// The contacts that took part (the closing one and those closed or touching then).
    pub contacts: Vec<String>,
    /// Per contact that took part, in the order of `contacts`.
    pub per_contact: Vec<ContactImpulse>,
    /// Kinetic energy lost (J), from the impulses: `normal_energy_lost + friction_energy_lost`.
    pub energy_lost: f64,
    /// The normal impulses' part of it (J): `-sum P (v- + v+) / 2`.
    pub normal_energy_lost: f64,
    /// The tangential (friction) impulses' part of it (J): `-sum P_t (s- + s+) / 2`, `s` the
    /// slip velocities.
    pub friction_energy_lost: f64,
    /// Whether this impact closed a converging (Zeno) sequence of bounces, made plastic and
    /// listed at the sequence's accumulation time (its impulses and energy are those of the
    /// last bounce resolved, made plastic: the whole sequence's energy lost).
    pub zeno_limit: bool,
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
    /// Written in JSON (when not empty) as `notes: {key: sentence}`, the sentences by
    /// `report::prose`.
    #[serde(skip)]
    pub notes: BTreeMap<String, Note>,
    /// The impacts of the motion in order, when `impacts` was wanted (written under `results`
    /// in JSON as `impacts: {value: [...], meaning}`).
    #[serde(skip)]
    pub impacts: Option<Vec<ImpactRecord>>,
    /// The bodies' poses over every phase the run solved, from which the report computes the
    /// animation in `motion.svg`; present when a trajectory was wanted. Not part of
    /// results.json.
    #[serde(skip)]
    pub drawing: Option<Drawing>,
    /// The sensitivities `d(<result>)/d(<parameter>)` and elasticities
    /// `(p/x) dx/dp` of the wanted results, by key, when `sensitivities` was wanted (written
    /// in JSON as `sensitivities: {key: {value, unit, meaning}}`).
    #[serde(skip)]
    pub sensitivities: BTreeMap<String, Sensitivity>,
}

/// How a result moves with a parameter: `d(of)/d(parameter)`, or the elasticity
/// `(parameter/of) d(of)/d(parameter)`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Sensitivity {
    /// The value, in `unit`.
    pub value: f64,
    /// The result's unit over the parameter's (`rad/kg`, `s^3/m`); `1` for an elasticity.
    pub unit: String,
    /// The result's key (`separation_angle`).
    #[serde(skip)]
    pub of: String,
    /// The parameter.
    #[serde(skip)]
    pub parameter: String,
    /// Whether this is the elasticity rather than the derivative.
    #[serde(skip)]
    pub elasticity: bool,
    /// Whether it comes from the motion integrated with its forward sensitivities (its
    /// integration's tolerance bounds its error) rather than from the fast path's closed-form
    /// partial derivatives.
    #[serde(skip)]
    pub integrated: bool,
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

    /// Why a wanted quantity has no value, if it has none (`report::prose::note` says it in
    /// words).
    pub fn note(&self, quantity: Quantity, info: &ModelInfo) -> Option<&Note> {
        self.notes.get(&quantity.name(info))
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

/// `v` with `sig` significant digits, for people: plain between 0.001 and 10^6, otherwise in
/// engineering notation (the exponent a multiple of 3, as the SI prefixes: `251.1e-15`,
/// `3.5e9`); trailing zeros dropped, never an `e0`.
pub fn format_number(v: f64, sig: usize) -> String {
    if !v.is_finite() {
        return format!("{v}");
    }
    if v == 0.0 {
        return "0".into();
    }
    let sig = sig.max(1);
    // Rounded once, by the standard library; then only the decimal point moves.
    let scientific = format!("{:.*e}", sig - 1, v.abs());
    let Some((mantissa, exponent)) = scientific.split_once('e') else {
        return scientific;
    };
    let Ok(exponent) = exponent.parse::<i32>() else {
        return scientific;
    };
    let digits: String = mantissa.chars().filter(char::is_ascii_digit).collect();
    let sign = if v < 0.0 { "-" } else { "" };
    let (point, shown_exponent) = if (-3..6).contains(&exponent) {
        (exponent, 0)
    } else {
        let shift = exponent.rem_euclid(3);
        (shift, exponent - shift)
    };
    // Digits with the decimal point after position `point + 1` (zeros padded either side).
    let body = if point < 0 {
        format!("0.{}{digits}", "0".repeat((-point - 1) as usize))
    } else {
        let int_len = point as usize + 1;
        let padded = format!("{digits:0<int_len$}");
        let (int, frac) = padded.split_at(int_len);
        if frac.is_empty() {
            int.to_string()
        } else {
            format!("{int}.{frac}")
        }
    };
    let body = if body.contains('.') {
        body.trim_end_matches('0').trim_end_matches('.')
    } else {
        &body
    };
    if shown_exponent == 0 {
        format!("{sign}{body}")
    } else {
        format!("{sign}{body}e{shown_exponent}")
    }
}
