//! Forward sensitivities of the integrated route: `S = dy/dp`, the derivatives of the state
//! `y = [q, qd]` in every parameter, integrated with the motion, and the derivatives of the
//! times of its events.
//!
//! Along a stretch with one active set, `qdd(q, qd, p)` is the contact system's solution
//! ([`contacts::dynamics()`]); differentiated along a direction `xi = (dq, dqd, dp)`, it is the
//! same system with the partial derivatives of its rows as right-hand side
//! ([`contacts::tangent_into`], the rows' partials generated symbolically:
//! [`Model::tangents`](crate::model::Model::tangents)). Column `j` of `S` then obeys
//! `d/dt S_q = S_qd`, `d/dt S_qd = d qdd` along `xi = (S_q, S_qd, e_j)`. The columns ride along
//! on the integrator's steps without steering them
//! ([`OdeOptions::controlled`](crate::solve::integrated::ode::OdeOptions::controlled)): the state,
//! its steps and its events are those of the integration without sensitivities, bit for bit.
//!
//! An event `g(y, p) = 0` ends a stretch at `t_e`; the implicit-function theorem gives
//! `dt_e/dp = -(g_y S + g_p) / (dg/dt)`, `dg/dt` being `g`'s derivative along the motion (the
//! direction `(qd, qdd, 0)`). Where the state's derivative jumps there (the next stretch's
//! active set accelerates differently), `S` jumps by `(f- - f+) dt_e/dp`: only `S_qd` changes,
//! by `(qdd- - qdd+) dt_e/dp`, the velocities being continuous.

use crate::model::ModelInfo;
use crate::solve::SolveError;
use crate::solve::integrated::contacts::{self, Active, DynamicsWork, Tangent, TangentAt};
use crate::system::{Bound, State, SystemError};

/// What an event function measures, for its time's derivatives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Measured {
    /// A contact's force.
    Force(usize),
    /// A contact's gap.
    Gap(usize),
    /// A contact's edge margin.
    Edge(usize),
    /// A coordinate (less a constant: the reduced angle above its end angle).
    Coordinate(usize),
    /// A friction's slip velocity.
    Slip(usize),
    /// A stuck friction's margin `mu N - |f|`.
    Stuck(usize),
    /// The clock: a run that ends at a given time, whatever the parameters.
    Clock,
}

/// An event whose time has no derivative: its function's rate along the motion is zero (or
/// not finite) there, a grazing crossing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grazing {
    /// The rate `dg/dt`.
    pub rate: f64,
}

/// `dt_e/dp` of an event for every parameter, or the grazing that leaves it none.
pub type EventTimes = Result<Vec<f64>, Grazing>;

/// The forward sensitivities of one model: sizes and buffers.
#[derive(Debug, Clone)]
pub struct Forward {
    n: usize,
    np: usize,
    tan: Vec<f64>,
    xi: Vec<f64>,
    out: Tangent,
}

impl Forward {
    /// For `sys`'s model, which must have [`Model::tangents`](crate::model::Model::tangents).
    pub fn new(sys: &Bound) -> Result<Forward, SolveError> {
        let info = sys.info();
        if sys.model().tangents().is_none() {
            return Err(SystemError::NoTangents { model: info.name }.into());
        }
        Ok(Forward {
            n: sys.n_coordinates(),
            np: info.parameters.len(),
            tan: Vec::new(),
            xi: Vec::new(),
            out: Tangent::default(),
        })
    }

    /// The number of values of `S`: `2 n` per parameter, column by column (`S_q`, then
    /// `S_qd`).
    pub fn len(&self) -> usize {
        2 * self.n * self.np
    }

    /// Whether `S` has no value (a model without parameters).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// `S` at release, from the initial state's derivatives.
    pub fn initial(&self, sys: &Bound) -> Result<Vec<f64>, SolveError> {
        let rows = sys.initial_tangents()?;
        let (two_n, np) = (2 * self.n, self.np);
        let mut s = vec![0.0; self.len()];
        for j in 0..np {
            for r in 0..two_n {
                s[j * two_n + r] = rows[r * np + j];
            }
        }
        Ok(s)
    }

    /// The directions `(S_q, S_qd, e_j)` of every parameter, and with `rate` (the state and
    /// its accelerations) the motion's own `(qd, qdd, 0)` last.
    fn directions(&mut self, s: &[f64], rate: Option<(&State, &[f64])>) {
        let (n, np) = (self.n, self.np);
        let cols = 2 * n + np;
        self.xi.clear();
        self.xi
            .resize((np + usize::from(rate.is_some())) * cols, 0.0);
        for (j, x) in self.xi.chunks_exact_mut(cols).enumerate() {
            match rate {
                Some((state, qdd)) if j == np => {
                    x[..n].copy_from_slice(&state.qd);
                    x[n..2 * n].copy_from_slice(qdd);
                }
                _ => {
                    x[..2 * n].copy_from_slice(&s[j * 2 * n..(j + 1) * 2 * n]);
                    x[2 * n + j] = 1.0;
                }
            }
        }
    }

    /// `dS/dt` into `ds` at `state` (time `t`, active set `active`), whose dynamics `work`
    /// holds from the last [`contacts::dynamics_into`].
    pub fn rhs(
        &mut self,
        sys: &Bound,
        at: (&State, f64, &Active),
        work: &mut DynamicsWork,
        s: &[f64],
        ds: &mut [f64],
    ) -> Result<(), SolveError> {
        let (state, t, active) = at;
        let d = &work.out;
        sys.tangents_into(state, &d.qdd, &d.forces, &d.fr, &mut self.tan)?;
        self.directions(s, None);
        let at = TangentAt {
            state,
            t,
            active,
            tan: &self.tan,
        };
        contacts::tangent_into(sys, at, work, &self.xi, &mut self.out)?;
        let n = self.n;
        for j in 0..self.np {
            let (col, dcol) = (&s[j * 2 * n..(j + 1) * 2 * n], &mut ds[j * 2 * n..]);
            dcol[..n].copy_from_slice(&col[n..]);
            dcol[n..2 * n].copy_from_slice(&self.out.qdd[j * n..(j + 1) * n]);
        }
        Ok(())
    }

    /// `dt_e/dp` of an event measuring `what` at `state` (time `t`, active set `active` before
    /// the event), with `S` there, or why it has none; also the accelerations there, for the
    /// jump ([`jump`]).
    pub fn event_times(
        &mut self,
        sys: &Bound,
        at: (&State, f64, &Active),
        work: &mut DynamicsWork,
        s: &[f64],
        what: Measured,
    ) -> Result<(EventTimes, Vec<f64>), SolveError> {
        let (state, t, active) = at;
        contacts::dynamics_into(sys, state, active, t, work)?;
        let qdd = work.out.qdd.clone();
        if what == Measured::Clock {
            return Ok((Ok(vec![0.0; self.np]), qdd));
        }
        let d = &work.out;
        sys.tangents_into(state, &d.qdd, &d.forces, &d.fr, &mut self.tan)?;
        let (forces, fr) = (d.forces.clone(), d.fr.clone());
        self.directions(s, Some((state, &qdd)));
        let at = TangentAt {
            state,
            t,
            active,
            tan: &self.tan,
        };
        contacts::tangent_into(sys, at, work, &self.xi, &mut self.out)?;
        let info = sys.info();
        let values = Along {
            info,
            n: self.n,
            np: self.np,
            xi: &self.xi,
            out: &self.out,
            forces: &forces,
            fr: &fr,
            mu: sys.friction_coefficients(),
        };
        let rate = values.along(self.np, what);
        if rate == 0.0 || !rate.is_finite() {
            return Ok((Err(Grazing { rate }), qdd));
        }
        let dt = (0..self.np)
            .map(|j| -values.along(j, what) / rate)
            .collect();
        Ok((Ok(dt), qdd))
    }
}

/// The derivatives of the event functions along the directions of one solve.
struct Along<'a> {
    info: &'static ModelInfo,
    n: usize,
    np: usize,
    xi: &'a [f64],
    out: &'a Tangent,
    forces: &'a [f64],
    fr: &'a [f64],
    mu: Vec<f64>,
}

impl Along<'_> {
    /// `what`'s derivative along direction `d`.
    fn along(&self, d: usize, what: Measured) -> f64 {
        let (n, m, nf) = (self.n, self.info.contacts.len(), self.info.frictions.len());
        let rows = n + 3 * m + 2 * nf;
        let cols = 2 * n + self.np;
        let row = |r: usize| self.out.rows[d * rows + r];
        match what {
            Measured::Force(i) => self.out.forces[d * m + i],
            Measured::Gap(i) => row(n + m + nf + i),
            Measured::Edge(i) => row(n + 2 * m + nf + i),
            Measured::Coordinate(r) => self.xi[d * cols + r],
            Measured::Slip(j) => row(n + 3 * m + nf + j),
            Measured::Stuck(j) => {
                let friction = &self.info.frictions[j];
                let c = friction.contact_index;
                let dmu = self.xi[d * cols + 2 * n + friction.coefficient_index];
                dmu * self.forces[c] + self.mu[j] * self.out.forces[d * m + c]
                    - self.fr[j].signum() * self.out.fr[d * nf + j]
            }
            Measured::Clock => 0.0,
        }
    }
}

/// `S` across an event at which the accelerations jump from `qdd_before` to `qdd_after`:
/// `S_qd += (qdd- - qdd+) dt_e/dp`, column by column.
pub fn jump(s: &mut [f64], qdd_before: &[f64], qdd_after: &[f64], dt: &[f64]) {
    let n = qdd_before.len();
    for (col, dt) in s.chunks_exact_mut(2 * n).zip(dt) {
        for ((v, a), b) in col[n..].iter_mut().zip(qdd_before).zip(qdd_after) {
            *v += (a - b) * dt;
        }
    }
}
