//! [`Bound`]: a model bound to validated parameters and its prepared constants, with the
//! full-state functions every model has, each checking its arguments before it calls
//! the generated code.

use super::SystemError;
use super::parameters::{
    check_parameters, describe, ordered_values, prepare_constants, restitutions,
};
use super::state::{Points, State, finite, zeroed};
use crate::model::{Model, ModelInfo, TangentPoint};
use std::collections::BTreeMap;

/// A model with a validated parameter set and its prepared constants.
#[derive(Clone)]
pub struct Bound<'m> {
    model: &'m dyn Model,
    /// `model.info()`, read by every evaluation (kept to spare the call through the trait
    /// object).
    info: &'static ModelInfo,
    /// `info.reduced_index` with the coordinate it names, looked up once when bound (a model
    /// whose `reduced_index` names no coordinate is refused: [`SystemError::ReducedIndex`]);
    /// none for a system without a reduced coordinate.
    reduced: Option<(usize, &'static str)>,
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
        let reduced = match info.reduced_index {
            Some(index) => Some((
                index,
                (info.coordinates.get(index).copied()).ok_or(SystemError::ReducedIndex {
                    model: info.name,
                    index,
                    coordinates: info.coordinates.len(),
                })?,
            )),
            None => None,
        };
        let mut margins = vec![0.0; info.requirements.len()];
        check_parameters(model, p, &mut margins)?;
        let restitutions = restitutions(model, p)?;
        let mut k = vec![0.0; info.n_constants];
        prepare_constants(model, p, &mut k)?;
        Ok(Bound {
            model,
            info,
            reduced,
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
    /// `coordinates[reduced_index]`; none for a system without one.
    pub fn reduced_coordinate(&self) -> Option<&'static str> {
        self.reduced.map(|(_, name)| name)
    }

    /// The index and name of the reduced coordinate, for what is measured in it (an angle's
    /// series or result, the fast path): [`SystemError::NoReducedCoordinate`] for a system
    /// without one.
    pub fn reduced(&self) -> Result<(usize, &'static str), SystemError> {
        self.reduced
            .ok_or(SystemError::NoReducedCoordinate { model: self.name() })
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

    /// The angle where the motion ends (rod on the floor): [`SystemError::NoEndAngle`] for a
    /// motion with no end of its own (it runs to a given end time).
    pub fn end_angle(&self) -> Result<f64, SystemError> {
        (self.info().end_angle).ok_or(SystemError::NoEndAngle { model: self.name() })
    }

    /// The index in [`ModelInfo::points`] of the point whose fall is the reference and whose
    /// height tells a landing: [`SystemError::NoFallingPoint`] for a system that names none.
    pub fn falling_point(&self) -> Result<usize, SystemError> {
        (self.info().falling_point_index).ok_or(SystemError::NoFallingPoint { model: self.name() })
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

    /// The number of rows of [`Self::tangents_into`]: `n + 3 m + 2 nf`.
    pub fn tangent_rows(&self) -> usize {
        let info = self.info();
        self.n_coordinates() + 3 * info.contacts.len() + 2 * info.frictions.len()
    }

    /// The partial derivatives of the dynamics' rows over `[q, qd, p]` at a state with its
    /// accelerations, contact forces and friction forces held fixed
    /// ([`Tangents::tangent_rows`](crate::model::Tangents::tangent_rows) gives the rows), row-major with
    /// `2 n + np` columns, into `out` (resized).
    pub fn tangents_into(
        &self,
        state: &State,
        qdd: &[f64],
        forces: &[f64],
        fr: &[f64],
        out: &mut Vec<f64>,
    ) -> Result<(), SystemError> {
        self.check_state(state)?;
        let info = self.info();
        let Some(tangents) = self.model.tangents() else {
            return Err(SystemError::NoTangents { model: info.name });
        };
        self.check_length("qdd", self.n_coordinates(), qdd.len())?;
        self.check_length("forces", info.contacts.len(), forces.len())?;
        self.check_length("fr", info.frictions.len(), fr.len())?;
        finite("qdd", qdd)?;
        finite("forces", forces)?;
        finite("fr", fr)?;
        let cols = 2 * self.n_coordinates() + info.parameters.len();
        zeroed(out, self.tangent_rows() * cols);
        let at = TangentPoint {
            q: &state.q,
            qd: &state.qd,
            qdd,
            forces,
            friction: fr,
        };
        tangents.tangent_rows(&self.k, &at, out);
        Ok(())
    }

    /// `d(initial state)/dp`: `2 n` rows (`q`, then `qd`) over the parameters, row-major.
    pub fn initial_tangents(&self) -> Result<Vec<f64>, SystemError> {
        let info = self.info();
        let Some(tangents) = self.model.tangents() else {
            return Err(SystemError::NoTangents { model: info.name });
        };
        let mut out = vec![0.0; 2 * self.n_coordinates() * info.parameters.len()];
        tangents.initial_tangents(&self.k, &mut out);
        Ok(out)
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
