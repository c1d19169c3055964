//! A model bound to one validated parameter set: the values `p`, the prepared constants `k`,
//! and typed helpers around the raw [`Model`] calls. [`Bound`] offers the full-state functions
//! every model has; [`System`] is a bound model with a fast path ([`Reduction`]) and derefs to
//! its [`Bound`].
//!
//! Architecture invariant: a [`Bound`] (and so a [`System`]) only exists for parameters that passed every check
//! (all present, finite, positive where declared, every requirement margin `> 0`, every
//! prepared constant finite), so the solvers never see a NaN that came from the input.
//!
//! Architecture invariant: no method here panics on any argument. The raw [`Model`] functions
//! index their slices unchecked (their contract is the lengths [`ModelInfo`] gives); every
//! method here that passes a [`State`] or a slice to one checks its length against the model
//! first ([`SystemError::Length`]), and refuses a value that is not finite where the model's
//! formulas would carry it into the result ([`SystemError::NotFiniteInput`]). A [`State`]'s
//! coordinates and velocities always have one length ([`State::new`] also refuses non-finite
//! values), so one comparison checks it. The checks cost a comparison per call; the per-point
//! solver's route never comes through here.
//!
//! Files: `state.rs` ([`State`], [`Points`]), `bound.rs` ([`Bound`]), `fast.rs` ([`System`]),
//! `parameters.rs` (the one validation of a parameter set); this file, [`SystemError`].
//!
//! [`Model`]: crate::model::Model
//! [`ModelInfo`]: crate::model::ModelInfo
//! [`Reduction`]: crate::model::Reduction

mod bound;
mod fast;
mod parameters;
mod state;

pub use bound::Bound;
pub use fast::System;
pub use parameters::{
    check_parameters, check_restitutions, check_value, failed_requirements, ordered_values,
    prepare_constants, restitutions,
};
pub use state::{Points, State};

/// Why a parameter set was refused for a model.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SystemError {
    /// A parameter the model declares was not given.
    #[error("model `{model}` needs parameter `{name}`, which was not given")]
    MissingParameter {
        /// Model name.
        model: &'static str,
        /// The missing parameter.
        name: &'static str,
    },
    /// A parameter the model does not declare was given.
    #[error("model `{model}` has no parameter `{name}` (given {value}); it takes: {known}")]
    UnknownParameter {
        /// Model name.
        model: &'static str,
        /// The unknown name.
        name: String,
        /// Its value.
        value: f64,
        /// The parameters the model takes, comma-separated.
        known: String,
    },
    /// The same parameter was given twice.
    #[error("parameter `{name}` of model `{model}` given twice ({first} and {second})")]
    DuplicateParameter {
        /// Model name.
        model: &'static str,
        /// The repeated name.
        name: String,
        /// First value.
        first: f64,
        /// Second value.
        second: f64,
    },
    /// Ordered values whose count does not match the model's parameter list.
    #[error("model `{model}` takes {expected} parameters, got {got} values")]
    WrongCount {
        /// Model name.
        model: &'static str,
        /// Parameters declared.
        expected: usize,
        /// Values given.
        got: usize,
    },
    /// NaN or infinite.
    #[error("parameter `{name}` of model `{model}` is {value}, not a finite number")]
    NotFinite {
        /// Model name.
        model: &'static str,
        /// Parameter name.
        name: &'static str,
        /// The value.
        value: f64,
    },
    /// Zero or negative where the model declares the parameter positive.
    #[error("parameter `{name}` of model `{model}` is {value}; it must be strictly positive")]
    NotPositive {
        /// Model name.
        model: &'static str,
        /// Parameter name.
        name: &'static str,
        /// The value.
        value: f64,
    },
    /// A friction coefficient below zero.
    #[error(
        "parameter `{name}` of model `{model}` is {value}; it is the coefficient of friction `{friction}` and must not be negative"
    )]
    NegativeFriction {
        /// Model name.
        model: &'static str,
        /// Parameter name.
        name: &'static str,
        /// The friction it is the coefficient of.
        friction: &'static str,
        /// The value.
        value: f64,
    },
    /// A requirement margin was not strictly positive (e.g. `a >= ell`).
    #[error(
        "model `{model}` requirement `{name}` ({meaning}) fails: margin {margin:e} <= 0 with {parameters}"
    )]
    Requirement {
        /// Model name.
        model: &'static str,
        /// Requirement name.
        name: &'static str,
        /// What it demands.
        meaning: &'static str,
        /// The margin (`<= 0` or NaN).
        margin: f64,
        /// The parameters, `name = value` comma-separated.
        parameters: String,
    },
    /// A contact's coefficient of restitution (from the parameters) outside `[0, 1]`.
    #[error(
        "model `{model}`: contact `{contact}` has restitution {value} with {parameters}, outside [0, 1] (0: the bodies stay together, 1: no energy is lost)"
    )]
    Restitution {
        /// Model name.
        model: &'static str,
        /// The contact.
        contact: &'static str,
        /// Its coefficient.
        value: f64,
        /// The parameters, `name = value` comma-separated.
        parameters: String,
    },
    /// The model has no fast path (a [`System`] needs one; use a [`Bound`]).
    #[error("model `{model}` has no reduced fast path ({why}); it is solved by integration")]
    NoReduction {
        /// Model name.
        model: &'static str,
        /// Why, from the derivation.
        why: &'static str,
    },
    /// The model has no partial derivatives of its dynamics ([`crate::model::Model::tangents`]):
    /// a fast phase, or a hand-written model.
    #[error("model `{model}` has no partial derivatives of its dynamics (tangents)")]
    NoTangents {
        /// Model name.
        model: &'static str,
    },
    /// A model whose `reduced_index` names none of its coordinates (a malformed generated
    /// model).
    #[error("model `{model}` names coordinate {index} as its reduced one but has {coordinates}")]
    ReducedIndex {
        /// Model name.
        model: &'static str,
        /// Its `reduced_index`.
        index: usize,
        /// How many coordinates it has.
        coordinates: usize,
    },
    /// A model without a reduced coordinate asked for something measured in it (an angle, the
    /// fast path).
    #[error("model `{model}` has no reduced coordinate (its spec names none)")]
    NoReducedCoordinate {
        /// Model name.
        model: &'static str,
    },
    /// A model without an end angle asked where its motion ends.
    #[error(
        "model `{model}` has no end angle (its spec names none): its motion ends at a given time"
    )]
    NoEndAngle {
        /// Model name.
        model: &'static str,
    },
    /// A model without a falling point asked for it.
    #[error("model `{model}` has no falling point (its spec names none)")]
    NoFallingPoint {
        /// Model name.
        model: &'static str,
    },
    /// A state's coordinates and velocities of different lengths ([`State::new`]).
    #[error("a state needs as many velocities as coordinates: q has {q} values, qd {qd}")]
    StateShape {
        /// Values in `q`.
        q: usize,
        /// Values in `qd`.
        qd: usize,
    },
    /// A state, or a slice passed with one, whose length is not the model's.
    #[error("model `{model}` takes {expected} values in `{what}`, got {got}")]
    Length {
        /// Model name.
        model: &'static str,
        /// Which argument (`state`, `qdd`, `forces`).
        what: &'static str,
        /// Values the model takes.
        expected: usize,
        /// Values given.
        got: usize,
    },
    /// A value given to a model's function that is NaN or infinite.
    #[error("`{what}[{index}]` is {value}, not a finite number")]
    NotFiniteInput {
        /// Which argument (`q`, `qd`, `qdd`, `forces`, `delta`, ...).
        what: &'static str,
        /// Its index (0 for a scalar).
        index: usize,
        /// The value.
        value: f64,
    },
    /// `Model::prepare` produced a non-finite constant (a bug in the model or an extreme input).
    #[error(
        "model `{model}` prepared a non-finite constant k[{index}] = {value} from {parameters}"
    )]
    BadConstant {
        /// Model name.
        model: &'static str,
        /// Index in `k`.
        index: usize,
        /// The value.
        value: f64,
        /// The parameters, `name = value` comma-separated.
        parameters: String,
    },
}
