//! [`System`]: a bound model with a fast path, the motion as a function of the angle fallen.

use super::SystemError;
use super::bound::Bound;
use super::state::{State, finite_scalar};
use crate::model::{Model, Reduced, Reduction, ReductionInfo};
use std::collections::BTreeMap;

/// A bound model with a fast path: the motion as a function of the angle fallen.
#[derive(Clone)]
pub struct System<'m> {
    bound: Bound<'m>,
    reduction: &'m dyn Reduction,
    layout: &'static ReductionInfo,
    /// The angle where the fall ends (the spec's `end_angle`, which a fast path has).
    end_angle: f64,
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

    /// The fast path of a bound model, or [`SystemError::NoReduction`] (also for a model
    /// whose info lists a fast path without the reduced coordinate and end angle it falls in).
    pub fn reduce(bound: Bound<'m>) -> Result<Self, SystemError> {
        let info = bound.info();
        let ends = (info.reduced_index).and(info.end_angle);
        match (bound.model().reduction(), &info.reduction, ends) {
            (Some(_), Some(_), None) => Err(SystemError::NoReduction {
                model: info.name,
                why: "its info gives no reduced coordinate and end angle for the fast path",
            }),
            (Some(reduction), Some(layout), Some(end_angle)) => {
                let mut fall = vec![0.0; layout.fall_degree.map_or(0, |d| d + 1)];
                if !fall.is_empty() {
                    reduction.fall_polynomial(bound.k(), &mut fall);
                }
                Ok(System {
                    bound,
                    reduction,
                    layout,
                    end_angle,
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

    /// The angle where the fall ends (rod on the floor).
    pub fn end_angle(&self) -> f64 {
        self.end_angle
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

    /// Every contact's force at `delta`, in the order of
    /// [`ModelInfo::contacts`](crate::model::ModelInfo::contacts) (zero for a contact open in
    /// the phase); as [`System::reduced`] for `delta` outside the phase.
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
