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

use crate::model::{Model, ModelInfo, Reduced, Reduction, ReductionInfo, parameters_pass};
use std::collections::BTreeMap;
use std::fmt::Write as _;

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

/// A full (unreduced) state: coordinates and velocities in the order of
/// [`ModelInfo::coordinates`].
///
/// Its coordinates and velocities always have the same length, and one built by
/// [`State::new`] (or [`Bound::state`], which also checks the length against a model) holds
/// finite values only. Which model a state belongs to is not part of it: every [`Bound`]
/// method that takes one checks its length against the model and returns
/// [`SystemError::Length`] otherwise.
#[derive(Debug, Clone, PartialEq)]
pub struct State {
    pub(crate) q: Vec<f64>,
    pub(crate) qd: Vec<f64>,
}

impl State {
    /// A state from its coordinates and velocities: as many of each, every value finite
    /// ([`SystemError::StateShape`], [`SystemError::NotFiniteInput`] otherwise).
    pub fn new(q: Vec<f64>, qd: Vec<f64>) -> Result<State, SystemError> {
        if q.len() != qd.len() {
            return Err(SystemError::StateShape {
                q: q.len(),
                qd: qd.len(),
            });
        }
        finite("q", &q)?;
        finite("qd", &qd)?;
        Ok(State { q, qd })
    }

    /// A state of `n` coordinates, all zero and at rest (filled by the model's functions).
    pub(crate) fn zeros(n: usize) -> State {
        State {
            q: vec![0.0; n],
            qd: vec![0.0; n],
        }
    }

    /// The coordinates.
    pub fn q(&self) -> &[f64] {
        &self.q
    }

    /// The velocities.
    pub fn qd(&self) -> &[f64] {
        &self.qd
    }

    /// The number of coordinates.
    pub fn len(&self) -> usize {
        self.q.len()
    }

    /// Whether the state has no coordinates.
    pub fn is_empty(&self) -> bool {
        self.q.is_empty()
    }

    /// The coordinates and velocities.
    pub fn into_parts(self) -> (Vec<f64>, Vec<f64>) {
        (self.q, self.qd)
    }
}

/// `Ok` when every value of `values` is finite, else the first that is not, named `what`.
fn finite(what: &'static str, values: &[f64]) -> Result<(), SystemError> {
    match values.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(index) => Err(SystemError::NotFiniteInput {
            what,
            index,
            value: values[index],
        }),
    }
}

/// Sets `buffer` to `len` zeros, keeping its allocation.
fn zeroed(buffer: &mut Vec<f64>, len: usize) {
    buffer.clear();
    buffer.resize(len, 0.0);
}

/// `Ok` when `value` is finite, else [`SystemError::NotFiniteInput`] naming it.
fn finite_scalar(what: &'static str, value: f64) -> Result<(), SystemError> {
    finite(what, &[value])
}

/// Positions and velocities of every named point of a model, in the order of
/// [`ModelInfo::points`].
#[derive(Debug, Clone, PartialEq)]
pub struct Points {
    /// Positions `[x, y]` (m).
    pub pos: Vec<[f64; 2]>,
    /// Velocities `[vx, vy]` (m/s).
    pub vel: Vec<[f64; 2]>,
}

/// A model with a validated parameter set and its prepared constants.
#[derive(Clone)]
pub struct Bound<'m> {
    model: &'m dyn Model,
    /// `model.info()`, read by every evaluation (kept to spare the call through the trait
    /// object).
    info: &'static ModelInfo,
    /// `info.coordinates[info.reduced_index]`, looked up once when bound (a model whose
    /// `reduced_index` names no coordinate is refused: [`SystemError::ReducedIndex`]).
    reduced_coordinate: &'static str,
    p: Vec<f64>,
    k: Vec<f64>,
    restitutions: Vec<f64>,
}

impl std::fmt::Debug for Bound<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Bound")
            .field("model", &self.info().name)
            .field("p", &self.p)
            .field("k", &self.k)
            .finish()
    }
}

impl<'m> Bound<'m> {
    /// Binds named parameter values (any order, each exactly once) to a model.
    pub fn new<S: AsRef<str>>(
        model: &'m dyn Model,
        params: &[(S, f64)],
    ) -> Result<Self, SystemError> {
        let mut p = vec![0.0; model.info().parameters.len()];
        ordered_values(model.info(), params, &mut p)?;
        Self::from_values(model, &p)
    }

    /// Binds a map of named parameter values to a model.
    pub fn from_map(
        model: &'m dyn Model,
        params: &BTreeMap<String, f64>,
    ) -> Result<Self, SystemError> {
        let pairs: Vec<(&str, f64)> = params.iter().map(|(k, v)| (k.as_str(), *v)).collect();
        Self::new(model, &pairs)
    }

    /// Binds parameter values given in the order of [`ModelInfo::parameters`], checked by
    /// [`check_parameters`] and prepared by [`prepare_constants`].
    pub fn from_values(model: &'m dyn Model, p: &[f64]) -> Result<Self, SystemError> {
        let info = model.info();
        let reduced_coordinate = (info.coordinates.get(info.reduced_index).copied()).ok_or(
            SystemError::ReducedIndex {
                model: info.name,
                index: info.reduced_index,
                coordinates: info.coordinates.len(),
            },
        )?;
        let mut margins = vec![0.0; info.requirements.len()];
        check_parameters(model, p, &mut margins)?;
        let restitutions = restitutions(model, p)?;
        let mut k = vec![0.0; info.n_constants];
        prepare_constants(model, p, &mut k)?;
        Ok(Bound {
            model,
            info,
            reduced_coordinate,
            p: p.to_vec(),
            k,
            restitutions,
        })
    }

    /// Each contact's coefficient of restitution, in `[0, 1]` (checked when bound), in the
    /// order of [`ModelInfo::contacts`].
    pub fn restitutions(&self) -> &[f64] {
        &self.restitutions
    }

    /// The name of the reduced coordinate (`theta`), the model's
    /// `coordinates[reduced_index]`.
    pub fn reduced_coordinate(&self) -> &'static str {
        self.reduced_coordinate
    }

    /// The model.
    pub fn model(&self) -> &'m dyn Model {
        self.model
    }

    /// The model's static description.
    pub fn info(&self) -> &'static ModelInfo {
        self.info
    }

    /// Model name.
    pub fn name(&self) -> &'static str {
        self.info().name
    }

    /// Parameter values in the model's order.
    pub fn p(&self) -> &[f64] {
        &self.p
    }

    /// Prepared constants.
    pub fn k(&self) -> &[f64] {
        &self.k
    }

    /// The value of a parameter by name.
    pub fn param(&self, name: &str) -> Option<f64> {
        self.info()
            .parameters
            .iter()
            .position(|p| p.name == name)
            .map(|i| self.p[i])
    }

    /// The parameters by name.
    pub fn parameter_map(&self) -> BTreeMap<String, f64> {
        self.info()
            .parameters
            .iter()
            .zip(&self.p)
            .map(|(p, v)| (p.name.to_string(), *v))
            .collect()
    }

    /// `name = value` pairs, comma-separated, for messages.
    pub fn describe(&self) -> String {
        describe(self.info(), &self.p)
    }

    /// Gravitational acceleration (m/s^2).
    pub fn gravity(&self) -> f64 {
        self.p[self.info().gravity_index]
    }

    /// The angle where the motion ends (rod on the floor).
    pub fn end_angle(&self) -> f64 {
        self.info().end_angle
    }

    /// Number of unreduced coordinates.
    pub fn n_coordinates(&self) -> usize {
        self.info().coordinates.len()
    }

    /// The state at release.
    pub fn initial_state(&self) -> State {
        let mut state = State::zeros(self.n_coordinates());
        self.model
            .initial_state(&self.k, &mut state.q, &mut state.qd);
        state
    }

    /// A state of this model: [`State::new`] with the length checked against the model's
    /// coordinates ([`SystemError::Length`]).
    pub fn state(&self, q: Vec<f64>, qd: Vec<f64>) -> Result<State, SystemError> {
        let state = State::new(q, qd)?;
        self.check_state(&state)?;
        Ok(state)
    }

    /// `Ok` when `state` has this model's number of coordinates, else
    /// [`SystemError::Length`]: the check every method here that takes a state makes first.
    #[inline]
    pub fn check_state(&self, state: &State) -> Result<(), SystemError> {
        self.check_length("state", self.n_coordinates(), state.len())
    }

    /// `Ok` when `got == expected`, else [`SystemError::Length`] naming `what`.
    #[inline]
    fn check_length(
        &self,
        what: &'static str,
        expected: usize,
        got: usize,
    ) -> Result<(), SystemError> {
        if got == expected {
            Ok(())
        } else {
            Err(SystemError::Length {
                model: self.name(),
                what,
                expected,
                got,
            })
        }
    }

    /// Positions and velocities of the named points.
    pub fn points(&self, state: &State) -> Result<Points, SystemError> {
        self.check_state(state)?;
        let m = self.info().points.len();
        let mut pts = Points {
            pos: vec![[0.0; 2]; m],
            vel: vec![[0.0; 2]; m],
        };
        self.model
            .points(&self.k, &state.q, &state.qd, &mut pts.pos, &mut pts.vel);
        Ok(pts)
    }

    /// Index of a named point.
    pub fn point_index(&self, name: &str) -> Option<usize> {
        self.info().points.iter().position(|p| p.name == name)
    }

    /// Total energy of a full state.
    pub fn energy(&self, state: &State) -> Result<f64, SystemError> {
        self.check_state(state)?;
        Ok(self.model.energy(&self.k, &state.q, &state.qd))
    }

    /// Momenta conjugate to the cyclic coordinates.
    pub fn momenta(&self, state: &State) -> Result<Vec<f64>, SystemError> {
        self.check_state(state)?;
        let mut out = vec![0.0; self.info().cyclic.len()];
        self.model.momenta(&self.k, &state.q, &state.qd, &mut out);
        Ok(out)
    }

    /// The mass matrix (row-major) and right-hand side of `M(q) qdd = F(q, qd)`.
    pub fn equations(&self, state: &State) -> Result<(Vec<f64>, Vec<f64>), SystemError> {
        let (mut mass, mut rhs) = (Vec::new(), Vec::new());
        self.equations_into(state, &mut mass, &mut rhs)?;
        Ok((mass, rhs))
    }

    /// [`Self::equations`] into buffers that keep their allocation from call to call (each
    /// resized to its length): the integrator's right-hand sides allocate nothing.
    pub fn equations_into(
        &self,
        state: &State,
        mass: &mut Vec<f64>,
        rhs: &mut Vec<f64>,
    ) -> Result<(), SystemError> {
        self.check_state(state)?;
        let n = self.n_coordinates();
        zeroed(mass, n * n);
        zeroed(rhs, n);
        self.model
            .equations(&self.k, &state.q, &state.qd, mass, rhs);
        Ok(())
    }

    /// Number of contacts of the system.
    pub fn n_contacts(&self) -> usize {
        self.info().contacts.len()
    }

    /// The forces of the contacts this model holds closed by elimination (one per contact;
    /// zero for the others) from a full state and its accelerations (one per coordinate, each
    /// finite).
    pub fn forces_full(&self, state: &State, qdd: &[f64]) -> Result<Vec<f64>, SystemError> {
        let mut out = Vec::new();
        self.forces_full_into(state, qdd, &mut out)?;
        Ok(out)
    }

    /// [`Self::forces_full`] into a buffer that keeps its allocation (resized to its length).
    pub fn forces_full_into(
        &self,
        state: &State,
        qdd: &[f64],
        out: &mut Vec<f64>,
    ) -> Result<(), SystemError> {
        self.check_state(state)?;
        self.check_length("qdd", self.n_coordinates(), qdd.len())?;
        finite("qdd", qdd)?;
        zeroed(out, self.n_contacts());
        // A model that eliminates no contact has no force in closed form.
        if self.info.contacts.iter().any(|c| c.closed) {
            self.model
                .forces_full(&self.k, &state.q, &state.qd, qdd, out);
        }
        Ok(())
    }

    /// Every contact's gap (zero for those this model holds closed).
    pub fn gaps(&self, state: &State) -> Result<Vec<f64>, SystemError> {
        self.check_state(state)?;
        let mut out = vec![0.0; self.n_contacts()];
        self.model.gaps(&self.k, &state.q, &mut out);
        Ok(out)
    }

    /// Every contact's constraint row `J = d gap / dq` (row-major, one row per contact) and
    /// bias `dJ/dt qd`: a contact's normal acceleration is `J qdd + bias`.
    pub fn constraints(&self, state: &State) -> Result<(Vec<f64>, Vec<f64>), SystemError> {
        let (mut jac, mut bias) = (Vec::new(), Vec::new());
        self.constraints_into(state, &mut jac, &mut bias)?;
        Ok((jac, bias))
    }

    /// [`Self::constraints`] into buffers that keep their allocation (each resized to its
    /// length).
    pub fn constraints_into(
        &self,
        state: &State,
        jac: &mut Vec<f64>,
        bias: &mut Vec<f64>,
    ) -> Result<(), SystemError> {
        self.check_state(state)?;
        let m = self.n_contacts();
        zeroed(jac, m * self.n_coordinates());
        zeroed(bias, m);
        self.model
            .constraints(&self.k, &state.q, &state.qd, jac, bias);
        Ok(())
    }

    /// Every contact's edge margin (`+inf` for a contact without an edge).
    pub fn edges(&self, state: &State) -> Result<Vec<f64>, SystemError> {
        self.check_state(state)?;
        let mut out = vec![0.0; self.n_contacts()];
        self.model.edges(&self.k, &state.q, &mut out);
        Ok(out)
    }

    /// The system's state (the general model's coordinates) this model's state stands for.
    pub fn to_full(&self, state: &State) -> Result<State, SystemError> {
        self.check_state(state)?;
        let mut full = State::zeros(self.info().system_coordinates.len());
        self.model
            .to_full(&self.k, &state.q, &state.qd, &mut full.q, &mut full.qd);
        Ok(full)
    }

    /// The frictions' slip-velocity Jacobian `J` (row-major, one row per friction) and the
    /// part of the slip acceleration free of `qdd`: `v = J qd`, `dv/dt = J qdd + bias`.
    pub fn friction(&self, state: &State) -> Result<(Vec<f64>, Vec<f64>), SystemError> {
        let (mut jac, mut bias) = (Vec::new(), Vec::new());
        self.friction_into(state, &mut jac, &mut bias)?;
        Ok((jac, bias))
    }

    /// [`Self::friction`] into buffers that keep their allocation (each resized to its length).
    pub fn friction_into(
        &self,
        state: &State,
        jac: &mut Vec<f64>,
        bias: &mut Vec<f64>,
    ) -> Result<(), SystemError> {
        self.check_state(state)?;
        let m = self.info().frictions.len();
        zeroed(jac, m * self.n_coordinates());
        zeroed(bias, m);
        if m > 0 {
            self.model.friction(&self.k, &state.q, &state.qd, jac, bias);
        }
        Ok(())
    }

    /// The friction coefficient of each friction.
    pub fn friction_coefficients(&self) -> Vec<f64> {
        self.friction_coefficient_values().collect()
    }

    /// The friction coefficient of each friction, in order, without collecting them.
    pub fn friction_coefficient_values(&self) -> impl Iterator<Item = f64> + '_ {
        (self.info().frictions.iter()).map(|f| self.p[f.coefficient_index])
    }

    /// Monitor values (each must stay `>= 0`) at a state with the contacts' forces there (one
    /// per contact, each finite).
    pub fn monitors_full(&self, state: &State, forces: &[f64]) -> Result<Vec<f64>, SystemError> {
        self.check_state(state)?;
        self.check_length("forces", self.n_contacts(), forces.len())?;
        finite("forces", forces)?;
        let mut out = vec![0.0; self.info().monitors.len()];
        self.model
            .monitors_full(&self.k, &state.q, &state.qd, forces, &mut out);
        Ok(out)
    }

    /// The drawing of a state: each body's pose `[x, y, angle]` (in the order of
    /// [`ModelInfo::bodies`]) and the numbers of every shape ([`ModelInfo::shapes`]).
    pub fn drawing(&self, state: &State) -> Result<(Vec<[f64; 3]>, Vec<f64>), SystemError> {
        self.check_state(state)?;
        let info = self.info();
        let mut poses = vec![[0.0; 3]; info.bodies.len()];
        let mut sizes = vec![0.0; info.drawing_sizes()];
        self.model
            .drawing(&self.k, &state.q, &mut poses, &mut sizes);
        Ok((poses, sizes))
    }

    /// A typical length of the system at a state: the largest distance of a named point from
    /// the origin (1 m for a model without points, or where that distance is not finite),
    /// against which gaps in metres are measured.
    pub fn length_scale(&self, state: &State) -> Result<f64, SystemError> {
        let pts = self.points(state)?;
        let reach = (pts.pos.iter())
            .map(|p| p[0].hypot(p[1]))
            .fold(0.0f64, f64::max);
        Ok(if reach > 0.0 && reach.is_finite() {
            reach
        } else {
            1.0
        })
    }
}

/// A bound model with a fast path: the motion as a function of the angle fallen.
#[derive(Clone)]
pub struct System<'m> {
    bound: Bound<'m>,
    reduction: &'m dyn Reduction,
    layout: &'static ReductionInfo,
    /// The fall polynomial's coefficients (empty without one).
    fall: Vec<f64>,
}

impl std::fmt::Debug for System<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.bound.fmt(f)
    }
}

impl<'m> std::ops::Deref for System<'m> {
    type Target = Bound<'m>;
    fn deref(&self) -> &Bound<'m> {
        &self.bound
    }
}

impl<'m> System<'m> {
    /// Binds named parameter values (any order, each exactly once) to a model with a fast path.
    pub fn new<S: AsRef<str>>(
        model: &'m dyn Model,
        params: &[(S, f64)],
    ) -> Result<Self, SystemError> {
        Self::reduce(Bound::new(model, params)?)
    }

    /// Binds a map of named parameter values to a model with a fast path.
    pub fn from_map(
        model: &'m dyn Model,
        params: &BTreeMap<String, f64>,
    ) -> Result<Self, SystemError> {
        Self::reduce(Bound::from_map(model, params)?)
    }

    /// Binds parameter values given in the model's order to a model with a fast path.
    pub fn from_values(model: &'m dyn Model, p: &[f64]) -> Result<Self, SystemError> {
        Self::reduce(Bound::from_values(model, p)?)
    }

    /// The fast path of a bound model, or [`SystemError::NoReduction`].
    pub fn reduce(bound: Bound<'m>) -> Result<Self, SystemError> {
        let info = bound.info();
        match (bound.model().reduction(), &info.reduction) {
            (Some(reduction), Some(layout)) => {
                let mut fall = vec![0.0; layout.fall_degree.map_or(0, |d| d + 1)];
                if !fall.is_empty() {
                    reduction.fall_polynomial(bound.k(), &mut fall);
                }
                Ok(System {
                    bound,
                    reduction,
                    layout,
                    fall,
                })
            }
            _ => Err(SystemError::NoReduction {
                model: info.name,
                why: info.route_note,
            }),
        }
    }

    /// The bound model underneath.
    pub fn bound(&self) -> &Bound<'m> {
        &self.bound
    }

    /// Where the fast path keeps its start in `k`.
    pub fn layout(&self) -> &'static ReductionInfo {
        self.layout
    }

    /// The fast path's functions.
    pub fn reduction(&self) -> &'m dyn Reduction {
        self.reduction
    }

    /// Initial reduced angle `theta_i` (rad).
    pub fn theta_initial(&self) -> f64 {
        self.k()[self.layout.k_theta_initial]
    }

    /// Initial reduced rate `theta_dot_i` (rad/s); zero for a release from rest.
    pub fn theta_dot_initial(&self) -> f64 {
        self.k()[self.layout.k_theta_dot_initial]
    }

    /// Whether the motion starts from rest (`theta_dot_i == 0`).
    pub fn starts_at_rest(&self) -> bool {
        self.theta_dot_initial() == 0.0
    }

    /// `theta_i - end_angle`: the angle fallen when the rod reaches the floor.
    pub fn delta_to_floor(&self) -> f64 {
        self.theta_initial() - self.end_angle()
    }

    /// Reduced state at `delta = theta_i - theta`. Any finite `delta` gives the model's
    /// formulas' values (outside the phase, `[0, delta_to_floor]`, `theta_dot_sq` may be
    /// negative: no motion reaches there); a `delta` that is not finite is
    /// [`SystemError::NotFiniteInput`].
    pub fn reduced(&self, delta: f64) -> Result<Reduced, SystemError> {
        finite_scalar("delta", delta)?;
        Ok(self.reduction.reduced(self.k(), delta))
    }

    /// Reduced state at an angle `theta` (loses the cancellation-free form near the start:
    /// prefer [`System::reduced`] with `delta`).
    pub fn reduced_at_theta(&self, theta: f64) -> Result<Reduced, SystemError> {
        finite_scalar("theta", theta)?;
        self.reduced(self.theta_initial() - theta)
    }

    /// Every contact's force at `delta`, in the order of [`ModelInfo::contacts`] (zero for a
    /// contact open in the phase); as [`System::reduced`] for `delta` outside the phase.
    pub fn forces(&self, delta: f64) -> Result<Vec<f64>, SystemError> {
        finite_scalar("delta", delta)?;
        let mut out = vec![0.0; self.info().contacts.len()];
        self.reduction.forces(self.k(), delta, &mut out);
        Ok(out)
    }

    /// Coefficients of contact `contact`'s force polynomial in `sin(theta)`, lowest degree
    /// first; `None` when its zero is no polynomial root.
    pub fn force_coefficients(&self, contact: usize) -> Option<Vec<f64>> {
        let degree = *self.layout.force_degrees.get(contact)?;
        if degree == 0 {
            return None;
        }
        let mut out = vec![0.0; degree + 1];
        self.reduction.force_polynomial(self.k(), contact, &mut out);
        Some(out)
    }

    /// Coefficients of the separation polynomial (the first contact's force polynomial), lowest
    /// degree first; empty when it has none.
    pub fn separation_coefficients(&self) -> Vec<f64> {
        self.force_coefficients(0).unwrap_or_default()
    }

    /// Coefficients of the fall polynomial in `sin(theta)`, lowest degree first (empty when the
    /// phase has none; see [`Reduction::fall_polynomial`]).
    pub fn fall_coefficients(&self) -> &[f64] {
        &self.fall
    }

    /// The full state on the reduced motion at phase time `t`, angle fallen `delta` and rate
    /// `theta_dot`; an argument that is not finite is [`SystemError::NotFiniteInput`].
    pub fn full_state(&self, t: f64, delta: f64, theta_dot: f64) -> Result<State, SystemError> {
        finite_scalar("t", t)?;
        finite_scalar("delta", delta)?;
        finite_scalar("theta_dot", theta_dot)?;
        let mut state = State::zeros(self.n_coordinates());
        self.reduction
            .full_state(self.k(), t, delta, theta_dot, &mut state.q, &mut state.qd);
        Ok(state)
    }
}

/// Named parameter values (any order, each exactly once) put into `out` in the model's order
/// (`out` holds one entry per parameter): the one place names become positions, for [`Bound`],
/// the per-point solver and the C interface.
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
) -> Result<impl Iterator<Item = (&'static crate::model::NamedInfo, f64)> + 'a, SystemError> {
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
/// requirements (`margins`: scratch of one entry per requirement). Used by [`Bound`] and by the
/// per-point solver, so both refuse exactly the same points.
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
fn describe(info: &ModelInfo, p: &[f64]) -> String {
    let mut out = String::new();
    for (i, (param, v)) in info.parameters.iter().zip(p).enumerate() {
        if i > 0 {
            out.push_str(", ");
        }
        let _ = write!(out, "{} = {v}", param.name);
    }
    out
}
